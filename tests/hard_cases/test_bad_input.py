"""Hard case 10: bad input, property-based with hypothesis.

Random corruptions of a valid model (meshes with beams, shells and solids; materials;
sections; lumped items; build_model arguments) must give a ValueError or TypeError that
names the offending item, raised by femmech's own checks, never a traceback from deep
inside numpy or scipy and never a silently wrong model.

Mesh files are untrusted input too: a damaged or oversized file gives a
ValueError naming the file. Scene files are fuzzed in tests/test_scene_fuzz.py (and at
length by benchmarks/fuzz_scenes.py).
"""

import traceback
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import femmech as fm
from femmech.fe import sections

PACKAGE = str(Path(fm.__file__).resolve().parent)
STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0, name="steel")
FUZZ = settings(max_examples=60, deadline=None, database=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow])


def assert_clean(exc: BaseException, *names) -> None:
    """The error is a ValueError/TypeError raised in femmech (its innermost frame lies in
    the package, so a numpy/scipy error inside was caught and translated) and names every
    item of ``names`` (node or element numbers, group, parameter or property names; a
    tuple is a list of alternatives)."""
    assert isinstance(exc, (ValueError, TypeError)), repr(exc)
    frames = traceback.extract_tb(exc.__traceback__)
    assert str(Path(frames[-1].filename).resolve()).startswith(PACKAGE), frames[-1]
    message = str(exc)
    for name in names:
        options = name if isinstance(name, tuple) else (name,)
        assert any(str(o) in message for o in options), (name, message)


def raises_clean(call, *names):
    with pytest.raises((ValueError, TypeError)) as info:
        call()
    assert_clean(info.value, *names)
    return info.value


# --- a valid base: a small frame with a shell panel and a solid block ---------------------

def base_arrays():
    """Points (12, 3), line cells (beams), quad cells (shell panel), tetra cells (block)."""
    frame = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                      [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float)
    block = np.array([[2, 0, 0], [3, 0, 0], [2, 1, 0], [2, 0, 1]], dtype=float)
    points = np.vstack([frame, block])
    lines = np.array([[0, 4], [1, 5], [2, 6], [3, 7], [4, 5], [5, 6], [6, 7], [7, 4],
                      [1, 8]])
    quads = np.array([[0, 1, 5, 4], [1, 2, 6, 5]])
    tetra = np.array([[8, 9, 10, 11]])
    return points, lines, quads, tetra


def build(points=None, lines=None, quads=None, tetra=None, beams=None, shells=None,
          solids=None, **kwargs):
    """build_model of the base with any part replaced (beams on "frame", shells on
    "panel", solids on "block", base nodes 0-3 and 9-11 supported)."""
    p, li, q, te = base_arrays()
    p = p if points is None else points
    li = li if lines is None else lines
    q = q if quads is None else quads
    te = te if tetra is None else tetra
    mesh = fm.Mesh(p, {"line": li, "quad": q, "tetra": te},
                   {"frame": {"line": np.arange(len(np.atleast_2d(li)))},
                    "panel": {"quad": np.arange(len(np.atleast_2d(q)))},
                    "block": {"tetra": np.arange(len(np.atleast_2d(te)))}},
                   {"base": [0, 1, 2, 3, 9, 10, 11]})
    beams = {"frame": fm.BeamProperty(sections.circle(0.03), STEEL)} if beams is None else beams
    shells = {"panel": fm.ShellProperty(0.005, STEEL)} if shells is None else shells
    solids = {"block": fm.SolidProperty(STEEL)} if solids is None else solids
    kwargs.setdefault("supports", [fm.Support("base")])
    return fm.build_model(mesh, beams, shells=shells, solids=solids, **kwargs)


def test_the_base_model_is_valid():
    model = build()
    result = fm.modes(model, n_modes=6)
    assert np.isfinite(result.freq_hz).all()
    assert result.freq_hz.min() > 0


# --- mesh corruptions ---------------------------------------------------------------------

@FUZZ
@given(node=st.integers(0, 11), component=st.integers(0, 2),
       value=st.sampled_from([np.nan, np.inf, -np.inf]))
def test_non_finite_coordinate_names_the_node(node, component, value):
    points = base_arrays()[0]
    points[node, component] = value
    raises_clean(lambda: build(points=points), f"node {node}")


@FUZZ
@given(element=st.integers(0, 8), end=st.integers(0, 1))
def test_duplicate_node_names_both_nodes(element, end):
    """A copy of a node, used by one element: two nodes at one place that nothing joins
    (a naive model would silently cut the structure there)."""
    points, lines, quads, tetra = base_arrays()
    original = int(lines[element, end])
    points = np.vstack([points, points[original]])
    lines = lines.copy()
    lines[element, end] = len(points) - 1
    still_used = original in np.concatenate([lines.ravel(), quads.ravel(), tetra.ravel()])
    names = ([f"nodes {original} and {len(points) - 1} coincide"] if still_used
             else [f"node {original}", "not used"])  # the copy took its only element
    raises_clean(lambda: build(points=points, lines=lines), *names)


@FUZZ
@given(kind=st.sampled_from(["line", "quad", "tetra"]), data=st.data())
def test_out_of_range_connectivity_names_cell_and_node(kind, data):
    arrays = dict(zip(("line", "quad", "tetra"), base_arrays()[1:], strict=True))
    cells = arrays[kind].copy()
    e = data.draw(st.integers(0, len(cells) - 1))
    k = data.draw(st.integers(0, cells.shape[1] - 1))
    bad = data.draw(st.one_of(st.integers(12, 10**6), st.integers(-10**6, -1)))
    cells[e, k] = bad
    key = {"line": "lines", "quad": "quads", "tetra": "tetra"}[kind]
    raises_clean(lambda: build(**{key: cells}), f"{kind} cell {e}", f"node {bad}")


@FUZZ
@given(element=st.integers(0, 8))
def test_zero_length_beam_names_the_element(element):
    lines = base_arrays()[1].copy()
    lines[element, 1] = lines[element, 0]
    raises_clean(lambda: build(lines=lines), f"element {element}", "zero length")


@FUZZ
@given(corner=st.integers(0, 3), element=st.integers(0, 1),
       kind=st.sampled_from(["collapsed", "bowtie"]))
def test_degenerate_or_crossed_shell_names_the_element(corner, element, kind):
    """A quad with a repeated node (a collapsed quad: its Jacobian is positive at the
    Gauss points, so before this issue it was accepted silently) or crossed diagonals."""
    quads = base_arrays()[2].copy()
    if kind == "collapsed":
        quads[element, corner] = quads[element, (corner + 1) % 4]
    else:
        quads[element, [corner, (corner + 1) % 4]] = quads[element, [(corner + 1) % 4, corner]]
    raises_clean(lambda: build(quads=quads), (f"element {element}", f"quad cell {element}"))


@FUZZ
@given(i=st.integers(0, 3), j=st.integers(0, 3))
def test_inverted_or_degenerate_solid_names_the_element(i, j):
    tetra = base_arrays()[3].copy()
    if i == j:
        tetra[0, i] = tetra[0, (i + 1) % 4]  # a repeated node: zero volume
    else:
        tetra[0, [i, j]] = tetra[0, [j, i]]  # swapped: negative volume
    raises_clean(lambda: build(tetra=tetra), ("tetra element 0", "tetra cell 0"))


@FUZZ
@given(shape=st.sampled_from([(12,), (12, 4), (12, 1), (3, 12), (12, 3, 1)]))
def test_wrong_shaped_points(shape):
    raises_clean(lambda: fm.Mesh(np.zeros(shape), {}), "points")


@FUZZ
@given(kind=st.sampled_from(["line", "quad", "tetra"]), extra=st.integers(1, 3))
def test_wrong_shaped_cells(kind, extra):
    nodes = {"line": 2, "quad": 4, "tetra": 4}[kind]
    cells = np.zeros((2, nodes + extra), dtype=int)
    raises_clean(lambda: fm.Mesh(base_arrays()[0], {kind: cells}), f"{kind} cells")


@FUZZ
@given(value=st.sampled_from([0.5, 1.0, 2.0]), where=st.sampled_from(["cells", "cell set",
                                                                       "node set"]))
def test_non_integer_indices_are_rejected_not_truncated(value, where):
    """Float indices, even integral-valued ones, are rejected: truncating 0.5 to 0 (as
    ``astype(int)`` does, and femmech did for groups before this issue) builds a model
    of other elements or nodes than the user meant."""
    points, lines, _, _ = base_arrays()
    if where == "cells":
        bad = lines.astype(float)
        bad[0, 0] = value
        call = lambda: fm.Mesh(points, {"line": bad})  # noqa: E731
        names = ("line",)
    elif where == "cell set":
        call = lambda: fm.Mesh(points, {"line": lines}, {"g": {"line": [0.0, value]}})  # noqa: E731
        names = ("cell set 'g'",)
    else:
        call = lambda: fm.Mesh(points, {"line": lines}, {}, {"g": [value]})  # noqa: E731
        names = ("node set 'g'",)
    raises_clean(call, *names)


@FUZZ
@given(points=st.sampled_from([[["a", "b", "c"]], [[1 + 1j, 0, 0]], [[0, 0], [1, 2, 3]],
                               None, "points"]))
def test_points_that_are_not_real_numbers(points):
    """Strings, complex numbers (a cast would drop the imaginary part silently), ragged
    lists and None."""
    raises_clean(lambda: fm.Mesh(points, {}), "points")


# --- build_model arguments ----------------------------------------------------------------

GROUP = st.text(alphabet="abcdefghijklmnopqrstuvwxyz_", min_size=1, max_size=8).filter(
    lambda s: s not in ("frame", "panel", "block", "base"))


@FUZZ
@given(name=GROUP, where=st.sampled_from(["beams", "shells", "solids", "support", "mass",
                                          "spring", "rigid link", "interface"]))
def test_unknown_group_is_named_with_the_known_ones(name, where):
    if where == "beams":
        call = lambda: build(beams={name: fm.BeamProperty(sections.circle(0.03), STEEL)})  # noqa: E731
    elif where == "shells":
        call = lambda: build(shells={name: fm.ShellProperty(0.005, STEEL)})  # noqa: E731
    elif where == "solids":
        call = lambda: build(solids={name: fm.SolidProperty(STEEL)})  # noqa: E731
    elif where == "support":
        call = lambda: build(supports=[fm.Support(name)])  # noqa: E731
    elif where == "mass":
        call = lambda: build(masses=[fm.PointMass(name, 1.0)])  # noqa: E731
    elif where == "spring":
        call = lambda: build(springs=[fm.Spring(4, name, 1e5)])  # noqa: E731
    elif where == "rigid link":
        call = lambda: build(rigid_links=[fm.RigidLink(4, name)])  # noqa: E731
    else:
        from femmech.reduction.component_modes import guyan

        call = lambda: guyan(build(), [name])  # noqa: E731
    raises_clean(call, repr(name))


@FUZZ
@given(item=st.sampled_from(["supports", "masses", "springs", "rigid_links"]))
def test_single_item_instead_of_a_list(item):
    single = {"supports": fm.Support("base"), "masses": fm.PointMass(4, 1.0),
              "springs": fm.Spring(4, None, 1e5), "rigid_links": fm.RigidLink(4, [5])}[item]
    raises_clean(lambda: build(**{item: single}), item)


# --- materials, sections, properties, lumped items ---------------------------------------

BAD_NUMBERS = st.sampled_from([0.0, -1.0, -1e9, np.nan, np.inf, -np.inf])
NOT_NUMBERS = st.sampled_from(["210e9", None, [1.0, 2.0], np.array([1.0]), 1j, True])


@FUZZ
@given(key=st.sampled_from(["E", "rho", "nu", "G"]), value=st.one_of(BAD_NUMBERS, NOT_NUMBERS))
def test_bad_material_constant_names_material_and_key(key, value):
    args = {"E": 210e9, "rho": 7850.0, "nu": 0.3, "name": "st37"}
    if key == "G":
        del args["nu"]
    if key == "rho" and isinstance(value, float) and value == 0.0:
        value = -1.0  # a massless material (rho = 0) is allowed
    if key == "nu" and isinstance(value, float) and value == 0.0:
        value = 0.5  # nu = 0 is allowed; 0.5 (incompressible) is not
    args[key] = value
    if key == "G" and value is None:
        args["G"] = 0.0
    raises_clean(lambda: fm.Material(**args), "st37", key)


@FUZZ
@given(factory=st.sampled_from(["circle", "tube", "rectangle", "rectangular_hollow",
                                "i_section", "general"]),
       position=st.integers(0, 3), value=st.one_of(BAD_NUMBERS, NOT_NUMBERS))
def test_bad_section_dimension_names_the_dimension(factory, position, value):
    good = {"circle": [0.05], "tube": [0.05, 0.04], "rectangle": [0.05, 0.08],
            "rectangular_hollow": [0.06, 0.08, 0.004], "i_section": [0.2, 0.1, 0.006, 0.01],
            "general": [1e-3, 1e-6, 2e-6, 1e-6]}[factory]
    position %= len(good)
    if factory == "tube" and position == 1 and isinstance(value, float) and value == 0.0:
        value = 0.06  # inner diameter 0 is a solid circle; >= outer is the error
    args = list(good)
    args[position] = value
    error = raises_clean(lambda: getattr(sections, factory)(*args, name="S1"))
    assert "S1" in str(error) or factory in str(error)


@FUZZ
@given(value=st.one_of(BAD_NUMBERS, NOT_NUMBERS))
def test_bad_shell_thickness(value):
    raises_clean(lambda: fm.ShellProperty(value, STEEL), "thickness")


@FUZZ
@given(mass=st.one_of(st.sampled_from([-1.0, np.nan, np.inf]), NOT_NUMBERS))
def test_bad_point_mass(mass):
    raises_clean(lambda: build(masses=[fm.PointMass(4, mass)]), "point mass at 4")


@FUZZ
@given(stiffness=st.sampled_from([-1e5, np.nan, "1e5", [1.0, 2.0], [[1, 2], [3, 4]],
                                  np.diag([1e5, 1e5, 1e5, 1.0, 1.0, -1.0])]))
def test_bad_spring(stiffness):
    raises_clean(lambda: build(springs=[fm.Spring(4, None, stiffness)]), "spring 4-None")


# --- random corruption of any entry: a clean error or a sound model -----------------------

# a moved node may land next to another (near nodes), far away (extent: units) or split
# the model: reporting that with a ModelWarning is as clean as refusing
@pytest.mark.filterwarnings("ignore::femmech.errors.ModelWarning")
@settings(max_examples=80, deadline=None, database=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_random_corruption_gives_a_clean_error_or_a_sound_model(data):
    """Overwrite one random entry of the points or of a connectivity array with a random
    value (finite or not, in or out of range). Either build_model refuses with a clean
    error, or the model is sound: symmetric K and M, finite positive frequencies."""
    arrays = list(base_arrays())
    which = data.draw(st.integers(0, 3))
    target = arrays[which] = arrays[which].copy()
    index = tuple(data.draw(st.integers(0, s - 1)) for s in target.shape)
    if which == 0:
        target[index] = data.draw(st.one_of(
            st.floats(allow_nan=True, allow_infinity=True, width=64),
            st.floats(-3.0, 3.0)))
    else:
        target[index] = data.draw(st.integers(-3, 14))
    try:
        model = build(*arrays)
    except (ValueError, TypeError) as exc:
        assert_clean(exc)
        return
    K, M = model.K_free, model.M_free
    # bound: K, M symmetric by construction: asymmetry is round-off, ~n eps of the largest entry
    assert abs(K - K.T).max() <= 1e-9 * abs(K).max()
    assert abs(M - M.T).max() <= 1e-9 * abs(M).max()
    try:
        result = fm.modes(model, n_modes=4)
    except (ValueError, TypeError) as exc:  # e.g. an element turned inside out by a node
        assert_clean(exc)
        return
    assert np.isfinite(result.freq_hz).all()
    assert np.all(result.freq_hz > 0)


# --- mesh files: damaged or oversized files give a ValueError naming the file ------------

MESH = Path(__file__).resolve().parents[2] / "meshes" / "machine_frame.msh"


def test_mesh_file_size_and_counts_are_bounded(tmp_path, monkeypatch):
    import femmech.fe.mesh_io

    monkeypatch.setattr(femmech.fe.mesh_io, "MAX_MESH_FILE_BYTES", 1000)
    with pytest.raises(ValueError, match=r"machine_frame.msh: file of \d+ bytes; at most 1000"
                                         r" \(limit MAX_MESH_FILE_BYTES\)"):
        fm.read_mesh(MESH)
    monkeypatch.undo()
    monkeypatch.setattr(femmech.fe.mesh_io, "MAX_NODES", 100)
    with pytest.raises(ValueError, match=r"machine_frame.msh: 188 nodes and \d+ cells; at most"
                                         r" 100 and"):
        fm.read_mesh(MESH)


@settings(max_examples=40, deadline=None, database=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_damaged_mesh_file_gives_a_clean_error_or_a_mesh(tmp_path, capsys, data):
    """Bytes of a Gmsh file overwritten, dropped or digits changed: read_mesh returns a
    Mesh (the damage hit a number or a comment) or raises a ValueError naming the file;
    meshio's own messages do not leak to the terminal."""
    raw = bytearray(MESH.read_bytes())
    at = data.draw(st.integers(0, len(raw) - 1))
    how = data.draw(st.sampled_from(["byte", "digit", "cut", "minus"]))
    if how == "byte":
        raw[at] = data.draw(st.integers(0, 255))
    elif how == "digit":
        raw[at:at + 1] = data.draw(st.sampled_from([b"9", b"99999999999", b"0", b""]))
    elif how == "cut":
        del raw[at:]
    else:
        raw[at:at] = b"-"
    path = tmp_path / "damaged.msh"
    path.write_bytes(bytes(raw))
    try:
        result = fm.read_mesh(path)
    except ValueError as exc:
        result = str(exc)
    if isinstance(result, str):
        assert result.startswith(f"{path}: "), result
    else:
        assert isinstance(result, fm.Mesh)
    assert capsys.readouterr() == ("", "")
