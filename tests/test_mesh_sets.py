"""The meshes users already have: node and element sets of Abaqus decks,
Nastran bulk data, VTU and MED files as node and cell sets; names that do not exist listed
with a "did you mean"; interfaces on solid nodes; the x-z orientation convention.

The decks in tests/data describe one structure, two portal frames joined at the top
(x 0..2 m, y 0..1 m, z 0..1 m; columns of two elements, beams along x of two, along y of
one; the Nastran deck adds a roof plate of two quads). The same structure is written
below as arrays, node and element numbers in file order, so that a model built from a file
must equal the model built from the arrays bit for bit: the same numbers go through the same
operations in the same order.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import meshio
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

import femmech as fm
from femmech.analysis.modes import superelement_modes
from femmech.errors import FemmechWarning, FileFormatError
from femmech.fe import sections
from femmech.fe.mesh_io import from_meshio
from femmech.reduction import interface_dofs
from femmech.reduction.component_modes import craig_bampton

DATA = Path(__file__).resolve().parent / "data"
STEEL = fm.Material(210e9, 7850, 0.3, name="steel")

# node numbers of the decks, in file order -> index
NUMBERS = [1, 2, 3, 4, 11, 12, 13, 14, 21, 22, 23, 24, 31, 32]
POINTS = np.array([[0, 0, 0], [2, 0, 0], [0, 1, 0], [2, 1, 0], [0, 0, .5], [2, 0, .5],
                   [0, 1, .5], [2, 1, .5], [0, 0, 1], [2, 0, 1], [0, 1, 1], [2, 1, 1],
                   [1, 0, 1], [1, 1, 1]], dtype=float)
_ELEMENTS = [(1, 11), (11, 21), (2, 12), (12, 22), (3, 13), (13, 23), (4, 14), (14, 24),
             (21, 31), (31, 22), (23, 32), (32, 24), (21, 23), (22, 24)]
LINES = np.array([[NUMBERS.index(a), NUMBERS.index(b)] for a, b in _ELEMENTS])
QUADS = np.array([[NUMBERS.index(n) for n in q] for q in ((21, 31, 32, 23), (31, 22, 24, 32))])
COLUMNS, BEAMS_X, BEAMS_Y = np.arange(8), np.arange(8, 12), np.arange(12, 14)
BASE, TOP, MIDS = np.arange(4), np.arange(8, 12), np.array([12, 13])

BEAMS = {"columns": fm.BeamProperty(sections.rectangle(0.05, 0.08), STEEL, (0.0, 1.0, 0.0)),
         "beams_x": fm.BeamProperty(sections.tube(0.03, 0.025), STEEL),
         "beams_y": fm.BeamProperty(sections.circle(0.02), STEEL)}


def _renamed(names: dict) -> dict:
    """BEAMS under the group names of a file."""
    return {names[k]: v for k, v in BEAMS.items()}


def _reduced(model, interface):
    se = craig_bampton(model, interface, n_modes=6)
    return se, superelement_modes(se, n_modes=10).freq_hz


def _assert_same(model_a, model_b, interface_a, interface_b):
    """Identical matrices and identical Craig-Bampton frequencies (bit for bit)."""
    for a, b in ((model_a.K, model_b.K), (model_a.M, model_b.M), (model_a.T, model_b.T)):
        assert_array_equal(a.toarray(), b.toarray())
    se_a, f_a = _reduced(model_a, interface_a)
    se_b, f_b = _reduced(model_b, interface_b)
    assert_array_equal(se_a.interface_dofs, se_b.interface_dofs)
    assert_array_equal(se_a.K, se_b.K)
    assert_array_equal(f_a, f_b)
    assert f_a[0] > 1.0  # a supported frame: no rigid-body modes
    return f_a


# --- Abaqus ------------------------------------------------------------------------------

def test_abaqus_deck_sets_as_the_deck_means_them():
    mesh = fm.read_mesh(DATA / "portal_frame.inp")
    assert_array_equal(mesh.points, POINTS)
    assert_array_equal(mesh.cells["line"], LINES)
    cells = {k: v["line"] for k, v in mesh.cell_sets.items()}
    assert sorted(cells) == ["BEAMS_X", "Beams_Y", "COLUMNS", "FRAME", "ODD_COLUMNS"]
    assert_array_equal(cells["COLUMNS"], COLUMNS)  # *ELEMENT, ELSET=
    assert_array_equal(cells["BEAMS_X"], BEAMS_X)  # GENERATE over a block without ELSET=
    assert_array_equal(cells["Beams_Y"], BEAMS_Y)  # a later block
    assert_array_equal(cells["FRAME"], np.arange(14))  # names, two on a line, case-blind
    assert_array_equal(cells["ODD_COLUMNS"], [0, 2, 4, 6])  # a list over two lines
    nodes = mesh.node_sets
    assert_array_equal(nodes["ALL_NODES"], np.arange(14))  # *NODE, NSET=
    assert_array_equal(nodes["BASE"], BASE)  # defined twice (BASE, base): joined
    assert_array_equal(nodes["TOP"], TOP)  # GENERATE with two numbers (step 1)
    assert_array_equal(nodes["INTERFACE"], np.r_[TOP, MIDS])  # names 'top', 'Mids'
    assert_array_equal(nodes["COLUMN_NODES"], np.arange(12))  # *NSET, ELSET=COLUMNS
    assert_array_equal(nodes["TIP_MASS"], [12])


def test_meshio_alone_loses_abaqus_sets():
    # why femmech reads the sets itself: meshio 5.3 stops at GENERATE with two numbers,
    # and with three numbers it reads a set of set names as empty
    with pytest.raises(meshio.ReadError, match=r"\[21 24\]"):
        meshio.abaqus.read(DATA / "portal_frame.inp")
    text = (DATA / "portal_frame.inp").read_text().replace("21, 24\n", "21, 24, 1\n")
    raw = meshio.abaqus.read(_write(text, "fixed.inp"))
    assert raw.point_sets["INTERFACE"].size == 0
    assert fm.read_mesh(_write(text, "fixed.inp")).node_sets["INTERFACE"].size == 6


def _write(text: str, name: str) -> Path:
    import tempfile
    path = Path(tempfile.mkdtemp()) / name
    path.write_text(text)
    return path


def test_abaqus_model_and_reduction_by_set_name_equal_those_from_arrays():
    mesh = fm.read_mesh(DATA / "portal_frame.inp")
    from_file = fm.build_model(mesh, _renamed({"columns": "COLUMNS", "beams_x": "BEAMS_X",
                                               "beams_y": "Beams_Y"}),
                               supports=[fm.Support("BASE")],
                               masses=[fm.PointMass("TIP_MASS", 5.0)])
    arrays = fm.Mesh.from_lines(POINTS, LINES, {"columns": COLUMNS, "beams_x": BEAMS_X,
                                                "beams_y": BEAMS_Y})
    from_arrays = fm.build_model(arrays, BEAMS, supports=[fm.Support(BASE)],
                                 masses=[fm.PointMass(12, 5.0)])
    f = _assert_same(from_file, from_arrays, ["INTERFACE"], [np.r_[TOP, MIDS]])
    assert len(f) == 10


def test_abaqus_cae_deck_with_part_and_assembly_sets():
    mesh = fm.read_mesh(DATA / "cae_bracket.inp")
    assert_allclose(mesh.points[:, 0], [0, 0.5, 1, 1, 1], rtol=0, atol=0)
    # the part's Set-1 and the assembly's Set-1 are different sets in Abaqus
    assert_array_equal(mesh.node_sets["Set-1"], [4])
    assert_array_equal(mesh.node_sets["Part-1-1.Set-1"], [0])
    assert_array_equal(mesh.node_sets["both_ends"], [0, 4])
    assert_array_equal(mesh.cell_sets["Set-1"]["line"], [0, 1])  # only a part element set
    assert_array_equal(mesh.cell_sets["arm"]["line"], [2, 3])
    prop = fm.BeamProperty(sections.rectangle(0.02, 0.04), STEEL, (0.0, 1.0, 0.0))
    model = fm.build_model(mesh, {"_PickedSet3": prop}, supports=[fm.Support("fixed")])
    assert model.n_free == 6 * 4
    assert_array_equal(interface_dofs(model, ["Set-1"]), np.arange(24, 30))


def _deck(replace=None, append="", name="portal_frame.inp") -> Path:
    text = (DATA / name).read_text()
    for old, new in (replace or {}).items():
        assert old in text
        text = text.replace(old, new)
    return _write(text + append, name)


@pytest.mark.parametrize(("replace", "append", "match"), [
    (None, "*Node\n 99, 5., 5., 5.\n",
     r"portal_frame\.inp: line \d+: a second \*NODE block: meshio 5 keeps only the last"),
    ({"*Step\n": "*Include, input=other.inp\n*Step\n"}, "", r"\*INCLUDE is not supported"),
    ({"*Step\n": "*System\n0., 0., 0., 1., 0., 0.\n*Step\n"}, "", r"\*SYSTEM is not supported"),
    (None, "*Nset, nset=HUGE, generate\n1, 2000000000, 1\n",
     r"node set 'HUGE' \(line \d+\): GENERATE range 1, 2000000000, 1 spans 2000000000"
     r" numbers, more than the deck's 14 nodes"),
    (None, "*Nset, nset=BACK, generate\n24, 21\n", "is empty or backwards"),
    (None, "*Nset, nset=X\nTOPP\n",
     r"node set 'X' \(line \d+\) lists 'TOPP', which is no node set of the deck; did you"
     r" mean 'TOP'\?"),
    (None, "*Nset, nset=A\nB\n*Nset, nset=B\nA\n", "list each other"),
    (None, "*Nset, nset=X\n1, 999\n", "node set 'X' .* lists node 999, which the deck does"
     " not define"),
    (None, "*Elset, elset=Y\n101, 999\n", "element set 'Y' .* lists element 999"),
    ({" 11, 0.0, 0.0, 0.5": "  4, 9.0, 9.0, 9.0\n 11, 0.0, 0.0, 0.5"}, "",
     "node 4 is defined twice"),
    ({"107, 4, 14": "107, 4, 15"}, "", "an element lists node 15, which the .NODE block does"
     " not define"),
    (None, "*Nset, nset=Z\n1, 2.5\n", r"line \d+: expected an integer, got '2\.5'"),
    (None, "*Element, type=C3D4H\n 900, 1, 2, 3, 4\n", "an element type meshio 5 does not read"),
])
def test_abaqus_deck_errors_name_the_file_line_and_set(replace, append, match):
    with pytest.raises(FileFormatError, match=match):
        fm.read_mesh(_deck(replace, append))


@pytest.mark.parametrize(("placement", "ok"), [("", True), (" 0., 0., 0.\n", True),
                                                (" 1., 0., 0.\n", False)])
def test_abaqus_instance_placement(placement, ok):
    path = _deck({"*Instance, name=Part-1-1, part=Part-1\n":
                  "*Instance, name=Part-1-1, part=Part-1\n" + placement}, name="cae_bracket.inp")
    if ok:
        assert fm.read_mesh(path).n_nodes == 5
    else:
        with pytest.raises(FileFormatError, match="instance 'Part-1-1' is moved or rotated"):
            fm.read_mesh(path)


# --- Nastran -----------------------------------------------------------------------------

DECK_NOT_CARRIED = r"cards not carried into the model: PBARL x3, EIGRL x1, MAT1 x1, PSHELL x1"
"""The cards of portal_frame.bdf that femmech does not read (properties: given per group)."""


def test_nastran_bulk_data_sets_and_property_groups():
    with pytest.warns(fm.ModelWarning, match=DECK_NOT_CARRIED):
        mesh = fm.read_mesh(DATA / "portal_frame.bdf")
    assert_array_equal(mesh.points, POINTS)
    assert_array_equal(mesh.cells["line"], LINES)
    assert_array_equal(mesh.cells["quad"], QUADS)
    cells = mesh.cell_sets
    assert_array_equal(cells["PID1"]["line"], COLUMNS)
    assert_array_equal(cells["PID2"]["line"], BEAMS_X)
    assert_array_equal(cells["PID3"]["line"], BEAMS_Y)
    assert_array_equal(cells["PID10"]["quad"], [0, 1])
    assert_array_equal(cells["SET5"]["line"], COLUMNS)  # SET3 ELEM, free field, THRU
    assert_array_equal(cells["SET6"]["line"], np.r_[BEAMS_X, BEAMS_Y])  # SET3 PROP 2 3
    assert_array_equal(cells["SET8"]["line"], BEAMS_Y)  # SET1 of element numbers
    nodes = mesh.node_sets
    assert_array_equal(nodes["SPC1"], BASE)  # SPC1 1 123456 1 THRU 4
    assert_array_equal(nodes["SET10"], np.r_[TOP, MIDS])  # SET1, THRU, continuation line
    assert_array_equal(nodes["SET11"], TOP)  # SET1* large field with continuation
    assert_array_equal(nodes["SET7"], [12])  # SET3 GRID
    assert "SET99" not in nodes  # a case control SET is not bulk data


def test_nastran_model_with_shells_equals_model_from_arrays():
    with pytest.warns(fm.ModelWarning, match=DECK_NOT_CARRIED):
        mesh = fm.read_mesh(DATA / "portal_frame.bdf")
    roof = fm.ShellProperty(0.004, STEEL)
    from_file = fm.build_model(mesh, _renamed({"columns": "PID1", "beams_x": "PID2",
                                               "beams_y": "PID3"}),
                               shells={"PID10": roof}, supports=[fm.Support("SPC1")])
    arrays = fm.Mesh(POINTS, {"line": LINES, "quad": QUADS},
                     {"columns": {"line": COLUMNS}, "beams_x": {"line": BEAMS_X},
                      "beams_y": {"line": BEAMS_Y}, "roof": {"quad": np.arange(2)}})
    from_arrays = fm.build_model(arrays, BEAMS, shells={"roof": roof},
                                 supports=[fm.Support(BASE)])
    _assert_same(from_file, from_arrays, ["SET10"], [np.r_[TOP, MIDS]])


def _bulk(old: str, new: str) -> Path:
    return _deck({old: new}, name="portal_frame.bdf")


@pytest.mark.parametrize(("old", "new", "match"), [
    ("GRID    2               2.0", "GRID    2       5       2.0",
     "GRIDs are given in coordinate system CP = 5; meshio reads coordinates as basic"),
    ("SET3    7       GRID    31", "SET3    7       GRID    99",
     r"SET3 \(line \d+\) lists GRID 99, which the file does not define"),
    ("SET3    7       GRID    31", "SET3    7       FACE    31", "DES 'FACE'; expected GRID"),
    ("SET3,6,PROP,2,3", "SET3,6,PROP,2,4", "lists property 4, which no element has"),
    ("SPC1    1       123456  1       THRU    4", "SPC1    1       123456  4       THRU    1",
     "range 4 THRU 1 is backwards"),
    ("SET1    8       301     302", "SET1    8       301     x", "ID must be an integer"),
])
def test_nastran_errors_name_the_card_and_line(old, new, match):
    with pytest.raises(FileFormatError, match=match):
        fm.read_mesh(_bulk(old, new))


# --- VTU, MED, names ---------------------------------------------------------------------

def test_vtu_point_and_cell_sets_with_dashes_in_names(tmp_path):
    # meshio stores sets as one integer array named by the names joined with the first
    # character of - _ # + / that no name holds: here '_' (Abaqus-like names 'Set-1')
    sets = {"Set-1": [COLUMNS], "Set-2": [np.r_[BEAMS_X, BEAMS_Y]]}
    points = {"Base-nodes": BASE, "Top-nodes": np.r_[TOP, MIDS, 4, 5, 6, 7]}
    path = tmp_path / "frame.vtu"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        meshio.write(path, meshio.Mesh(POINTS, [("line", LINES)], cell_sets=sets,
                                       point_sets=points))
    mesh = fm.read_mesh(path)
    assert_array_equal(mesh.cell_sets["Set-1"]["line"], COLUMNS)
    assert_array_equal(mesh.cell_sets["Set-2"]["line"], np.r_[BEAMS_X, BEAMS_Y])
    assert_array_equal(mesh.node_sets["Base-nodes"], BASE)
    assert_array_equal(mesh.node_sets["Top-nodes"], np.arange(4, 14))


def test_med_families_become_groups():
    # MED (needs h5py to read a file): each point or cell carries a family number, and a
    # family lists the groups it belongs to (family 2 is in two groups)
    raw = meshio.Mesh(POINTS, [("line", LINES)],
                      point_data={"point_tags": np.r_[[1] * 4, [0] * 4, [2] * 6]},
                      cell_data={"cell_tags": [np.r_[[-1] * 8, [-2] * 6]]})
    raw.point_tags = {1: ["base"], 2: ["top", "interface"]}
    raw.cell_tags = {-1: ["columns"], -2: ["beams"]}
    mesh = from_meshio(raw)
    assert_array_equal(mesh.node_sets["base"], BASE)
    assert_array_equal(mesh.node_sets["interface"], np.arange(8, 14))
    assert_array_equal(mesh.node_sets["top"], np.arange(8, 14))
    assert_array_equal(mesh.cell_sets["columns"]["line"], COLUMNS)
    assert_array_equal(mesh.cell_sets["beams"]["line"], np.arange(8, 14))


def test_medit_references_become_groups(tmp_path):
    # Medit (.mesh, mmg, TetGen) numbers regions of cells and points ("references")
    refs = np.r_[[1] * 8, [2] * 6]
    path = tmp_path / "frame.mesh"
    meshio.write(path, meshio.Mesh(POINTS, [("line", LINES)],
                                   point_data={"medit:ref": np.r_[[7] * 4, [0] * 10]},
                                   cell_data={"medit:ref": [refs]}))
    mesh = fm.read_mesh(path)
    assert_array_equal(mesh.cell_sets["ref1"]["line"], COLUMNS)
    assert_array_equal(mesh.cell_sets["ref2"]["line"], np.arange(8, 14))
    assert_array_equal(mesh.node_sets["ref7"], BASE)


def test_names_cleaned_and_collisions_renamed_with_a_warning():
    raw = meshio.Mesh(POINTS, [("line", LINES)],
                      point_sets={' "tip" ': np.array([13]), "tip": np.array([12]),
                                  "a\nb": np.array([0])})
    with pytest.warns(FemmechWarning, match=r"two node sets are named 'tip'.*renamed tip~2"):
        mesh = from_meshio(raw)
    assert_array_equal(mesh.node_sets["tip"], [13])
    assert_array_equal(mesh.node_sets["tip~2"], [12])
    assert "a?b" in mesh.node_sets  # a line break would break one-line messages


@pytest.mark.parametrize(("point_sets", "cell_sets", "match"), [
    ({"p": np.array([20])}, {}, "node set 'p' references node 20, but the mesh has 14"),
    ({"p": np.array([0.5])}, {}, "node set 'p': indices must be integers"),
    ({}, {"c": [np.array([14])]}, "cell set 'c' references line cell 14 of a block of 14"),
    ({}, {"c": [np.array([0]), np.array([0])]}, "cell set 'c' gives 2 index arrays for the 1"),
    ({"": np.array([0])}, {}, "a set has an empty name"),
])
def test_bad_sets_raise_file_format_errors_naming_the_set(point_sets, cell_sets, match):
    raw = meshio.Mesh(POINTS, [("line", LINES)])
    raw.point_sets, raw.cell_sets = point_sets, cell_sets
    with pytest.raises(FileFormatError, match=match):
        from_meshio(raw)


# --- missing names -----------------------------------------------------------------------

@pytest.fixture(scope="module")
def deck_mesh():
    return fm.read_mesh(DATA / "portal_frame.inp")


def _build(mesh, beams=None, **kwargs):
    beams = beams or _renamed({"columns": "COLUMNS", "beams_x": "BEAMS_X",
                               "beams_y": "Beams_Y"})
    return fm.build_model(mesh, beams, **kwargs)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"supports": [fm.Support("base")]},
     r"support: unknown group 'base'; the mesh has \[.*'BASE'.*\]; did you mean 'BASE'\?"),
    ({"masses": [fm.PointMass("tip-mass", 1.0)]},
     r"point mass: unknown group 'tip-mass'; .*did you mean 'TIP_MASS'\?"),
    ({"rigid_links": [fm.RigidLink("MID", "TOP")]}, r"unknown group 'MID'.*did you mean"),
    ({"beams": {"Columns": BEAMS["columns"]}},
     r"beam property for unknown group 'Columns'; the mesh has cell sets \['BEAMS_X',"
     r" 'Beams_Y', 'COLUMNS', 'FRAME', 'ODD_COLUMNS'\]; did you mean 'COLUMNS'\?"),
    ({"beams": {"TOP": BEAMS["columns"]}}, r"'TOP' is a node set; elements are named by cell"),
])
def test_missing_names_are_listed_with_a_suggestion(deck_mesh, kwargs, match):
    with pytest.raises(ValueError, match=match):
        _build(deck_mesh, **kwargs)


def test_missing_interface_name_is_listed_with_a_suggestion(deck_mesh):
    model = _build(deck_mesh, supports=[fm.Support("BASE")])
    with pytest.raises(ValueError, match=r"interface: unknown group 'interfce'.*did you mean"
                                         r" 'INTERFACE'\?"):
        craig_bampton(model, ["interfce"], n_modes=2)


def test_long_name_lists_are_cut():
    names = {f"set{k:03d}": [k] for k in range(60)}
    mesh = fm.Mesh.from_lines(np.c_[np.arange(61.0), np.zeros((61, 2))],
                              np.c_[np.arange(60), np.arange(1, 61)], node_sets=names)
    with pytest.raises(ValueError, match=r"'set038'\] and 21 more; did you mean 'set0\d1'\?"):
        mesh.nodes_of("set1")


def test_scene_with_an_abaqus_deck_names_sets_and_suggests(tmp_path):
    from femmech.errors import SceneError
    from femmech.scene.build import part_model, prepare
    from femmech.scene.load import Scene

    data = {"scene": {"name": "deck"},
            "materials": {"steel": {"E": 210e9, "nu": 0.3, "rho": 7850.0}},
            "parts": {"frame": {
                "mesh": str(DATA / "portal_frame.inp"),
                "sections": {
                    "COLUMNS": {"section": "rectangle", "width": 0.05, "height": 0.08,
                                "material": "steel", "orientation": [1, 0, 0],
                                "orientation_plane": "xz"},
                    "BEAMS_X": {"section": "circle", "diameter": 0.02, "material": "steel"},
                    "Beams_Y": {"section": "circle", "diameter": 0.02, "material": "steel"}},
                "supports": [{"nodes": "BASE"}],
                "reduction": {"method": "craig_bampton", "n_modes": 4,
                              "interface": [{"nodes": "INTERFACE"}]}}},
            "analyses": {"modes": {"n_modes": 3, "images": 0, "vtu": False}}}
    prepared = prepare(Scene.from_dict(data, tmp_path, "deck.toml"))
    model = part_model(prepared.scene, prepared.scene.parts["frame"],
                       prepared.meshes["frame"])
    # the scene's orientation_plane reaches the model: a column from z = 0 up (local x =
    # +z) with its vector (1, 0, 0) in the x-z plane has local z = +x, local y = z × x = -y
    assert_array_equal(model.beams.frames[0], [[0, 0, 1], [0, -1, 0], [1, 0, 0]])
    data["parts"]["frame"]["supports"] = [{"nodes": "Base"}]
    with pytest.raises(SceneError, match=r"\[parts\.frame\.supports\[0\]\] nodes: unknown group"
                                         r" 'Base'.*did you mean 'BASE'\?"):
        prepare(Scene.from_dict(data, tmp_path, "deck.toml"))
    data["parts"]["frame"]["supports"] = [{"nodes": "BASE"}]
    data["parts"]["frame"]["sections"]["Beams_y"] = data["parts"]["frame"]["sections"].pop(
        "Beams_Y")
    with pytest.raises(SceneError, match=r"group 'Beams_y' is not a cell group of the mesh;"
                                         r" expected one of .*; did you mean 'Beams_Y'\?"):
        prepare(Scene.from_dict(data, tmp_path, "deck.toml"))


# --- interfaces on solid nodes -----------------------------------------------------------

def _solid_bar():
    """Two hexahedra along x (2 x 1 x 1 m); root face x = 0 supported, tip face x = 2."""
    grid = np.array([(i, j, k) for k in range(2) for j in range(2) for i in range(3)], float)
    node = {tuple(p): n for n, p in enumerate(grid.astype(int).tolist())}
    hexes = [[node[(i + a, b, c)] for a, b, c in ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
                                                   (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1))]
             for i in range(2)]
    mesh = fm.Mesh(grid, {"hexahedron": np.array(hexes)}, {"bar": {"hexahedron": [0, 1]}},
                   {"root": np.flatnonzero(grid[:, 0] == 0),
                    "tip": np.flatnonzero(grid[:, 0] == 2)})
    return fm.build_model(mesh, solids={"bar": fm.SolidProperty(STEEL)},
                          supports=[fm.Support("root", "translations")])


@pytest.mark.parametrize("interface", [["tip"], [("tip", "all")], "tip",
                                       [("tip", "translations")]])
def test_interface_on_solid_nodes_takes_their_translations(interface):
    model = _solid_bar()
    tip = model.mesh.node_sets["tip"]
    expected = (6 * tip[:, None] + np.arange(3)).ravel()
    assert_array_equal(interface_dofs(model, interface), np.sort(expected))
    se = craig_bampton(model, interface, n_modes=2)
    assert se.n_interface == 12


def test_interface_naming_rotations_of_solid_nodes_says_what_to_write():
    model = _solid_bar()
    match = (r"interface 'tip': node \d+ rx is a rotation of a node that only solid elements"
             r" use; solids have no rotational stiffness.*\('tip', 'translations'\)")
    with pytest.raises(ValueError, match=match):
        interface_dofs(model, [("tip", ["ux", "rx"])])


# --- orientation_plane -------------------------------------------------------------------

def _skew_model(orientation, plane, points=None):
    points = np.array([[0.0, 0, 0], [1.0, 0.7, 0.4], [1.8, 1.0, 1.1]]) if points is None \
        else points
    prop = fm.BeamProperty(sections.rectangle(0.03, 0.07), STEEL, orientation,
                           orientation_plane=plane)
    lines = [[k, k + 1] for k in range(len(points) - 1)]
    mesh = fm.Mesh.from_lines(points, lines, node_sets={"root": [0]})
    return fm.build_model(mesh, {"all": prop}, supports=[fm.Support("root")])


def test_xz_vector_gives_the_beam_of_the_equivalent_xy_vector():
    # the same physical beam: an x-z vector w and the x-y vector y = z × x it implies
    w = np.array([0.2, -0.3, 1.0])
    xz = _skew_model(w, "xz")
    ex = xz.beams.frames[:, 0, :]
    ez = w - (ex @ w)[:, None] * ex
    ez /= np.linalg.norm(ez, axis=1)[:, None]
    ys = np.cross(ez, ex)
    # one vector per element is needed (the two elements are not parallel): compare element
    # by element with single-element models
    for e, y in enumerate(ys):
        pts = xz.mesh.points[xz.beams.cells[e]]
        a, b = _skew_model(w, "xz", pts), _skew_model(y, "xy", pts)
        # identical up to round-off of y's second normalisation (|y| = 1 ± 1 ulp), so the
        # tolerance is a few ulp of the largest stiffness entry
        for ka, kb in ((a.K, b.K), (a.M, b.M)):
            assert_allclose(ka.toarray(), kb.toarray(), rtol=0, atol=8 * np.finfo(float).eps
                            * abs(kb).max())
        fa, fb = fm.modes(a, n_modes=6).freq_hz, fm.modes(b, n_modes=6).freq_hz
        # bound: matrices equal to a few ulp; dense eigh (6 DOFs): eps λ_max/λ_1 = 8.7e-13 in λ,
        # 4.3e-13 in f (roundoff.largest_eigenvalue; measured 0)
        assert_allclose(fa, fb, rtol=1e-12)


def test_axis_aligned_vectors_give_identical_matrices():
    # along x with w = ẑ (x-z) and v = ŷ (x-y) the frames are exactly (x, y, z): bitwise equal
    points = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0]])
    a, b = _skew_model((0, 0, 1), "xz", points), _skew_model((0, 1, 0), "xy", points)
    assert_array_equal(a.K.toarray(), b.K.toarray())
    assert_array_equal(fm.modes(a, n_modes=6).freq_hz, fm.modes(b, n_modes=6).freq_hz)
    # the same vector in the other plane turns the section by 90° (Iy and Iz swap): the
    # frequencies of a cantilever stay (both bending planes), its stiffness does not
    c = _skew_model((0, 0, 1), "xy", points)
    assert not np.allclose(c.K.toarray(), a.K.toarray(), rtol=1e-3, atol=0)


def test_xz_frame_against_a_hand_computed_frame():
    # beam from (0,0,0) to (1,1,0): x = (1,1,0)/√2; w = (1,0,1) in the x-z plane: its part
    # normal to x is w - (w·x)x = (1,0,1) - (1/√2)(1,1,0)/√2 = (0.5,-0.5,1), length √1.5,
    # so z = (0.5,-0.5,1)/√1.5 and y = z × x = (1,1,0)/√2 × ... = (-1, 1, 1)/√3
    model = _skew_model((1, 0, 1), "xz", np.array([[0.0, 0, 0], [1, 1, 0], [2, 2, 0]]))
    s2, s3, s6 = np.sqrt(2), np.sqrt(3), np.sqrt(6)
    expected = [[1 / s2, 1 / s2, 0], [-1 / s3, 1 / s3, 1 / s3], [1 / s6, -1 / s6, 2 / s6]]
    assert_allclose(model.beams.frames[0], expected, rtol=0, atol=4 * np.finfo(float).eps)
    assert_allclose(model.beams.frames[1], expected, rtol=0, atol=4 * np.finfo(float).eps)


@pytest.mark.parametrize(("orientation", "plane", "match"), [
    ((1, 1, 0), "xz", r"beams\['all'\]: orientation vector \[1\.0, 1\.0, 0\.0\]"
                      r" \(orientation_plane 'xz'\) is parallel to the axis"),
    ((0, 0, 1), "yz", r"orientation_plane must be 'xy' or 'xz', got 'yz'"),
])
def test_orientation_plane_errors(orientation, plane, match):
    with pytest.raises(ValueError, match=match):
        _skew_model(orientation, plane, np.array([[0.0, 0, 0], [1, 1, 0], [2, 2, 0]]))


def test_scene_orientation_plane_is_checked():
    from femmech.errors import SceneError
    from femmech.scene.load import Scene

    data = {"scene": {"name": "x"}, "materials": {"steel": {"E": 2e11, "nu": 0.3, "rho": 7850}},
            "parts": {"frame": {"generator": {"kind": "grid_frame", "bays": [1, 1, 1],
                                              "size": [1, 1, 1]},
                                "sections": {"beams_x": {
                                    "section": "circle", "diameter": 0.02, "material": "steel",
                                    "orientation": [0, 0, 1], "orientation_plane": "zx"}}}},
            "analyses": {"modes": {"n_modes": 2}}}
    with pytest.raises(SceneError, match=r"orientation_plane: expected one of \['xy', 'xz'\],"
                                         r" got 'zx'"):
        Scene.from_dict(data, ".", "x.toml")


# --- local axes image --------------------------------------------------------------------

def test_local_axes_image(tmp_path, deck_mesh):
    from PIL import Image

    from femmech.output.local_axes import plot_local_axes

    model = _build(deck_mesh, supports=[fm.Support("BASE")])
    path = plot_local_axes(model, tmp_path / "axes.png", window_size=(400, 300))
    with Image.open(path) as img:
        assert img.size == (400, 300)
        rgb = np.asarray(img.convert("RGB"), dtype=int)
    # the three axis colours are drawn (red x, green y, blue z dominate some pixels)
    red = (rgb[..., 0] > 150) & (rgb[..., 1] < 90) & (rgb[..., 2] < 90)
    green = (rgb[..., 1] > 120) & (rgb[..., 0] < 100) & (rgb[..., 2] < 100)
    blue = (rgb[..., 2] > 150) & (rgb[..., 0] < 90)
    assert red.sum() > 20
    assert green.sum() > 20
    assert blue.sum() > 20
    with pytest.raises(ValueError, match=r"unknown beam group 'columns'.*did you mean"
                                         r" 'COLUMNS'\?"):
        plot_local_axes(model, tmp_path / "x.png", elements="columns")
