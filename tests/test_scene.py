"""Scene files: validation with one-line errors naming the location, units, and the
mapping of scenes onto the Python API (issue 8)."""

import copy
import importlib.util
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

import femmech as fm
from femmech.errors import SceneError
from femmech.generators import members_frame
from femmech.scene import Scene, load_scene
from femmech.scene_build import part_model, prepare
from femmech.units import ANGLE, INERTIA, PRESSURE, ROT_STIFFNESS, SPEED, quantity

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"

SMALL = """
[scene]
name = "small frame"

[materials.steel]
E = "210 GPa"
nu = 0.3
rho = "7850 kg/m^3"

[parts.frame.generator]
kind = "grid_frame"
bays = [1, 1, 1]
size = ["1 m", "0.5 m", "0.8 m"]
subdivisions = 2

[parts.frame.sections.beams_x]
section = "rectangular_hollow"
width = "60 mm"
height = "60 mm"
wall = "4 mm"
material = "steel"

[parts.frame.sections.beams_y]
section = "tube"
outer_diameter = "50 mm"
inner_diameter = "40 mm"
material = "steel"

[parts.frame.sections.columns]
section = "i_section"
height = "100 mm"
width = "100 mm"
web = "6 mm"
flange = "10 mm"
material = "steel"

[[parts.frame.supports]]
nodes = "base"

[[parts.frame.masses]]
node = 4
mass = "20 kg"
inertia = ["0.1 kg*m^2", "0.1 kg*m^2", "0.1 kg*m^2"]

[parts.frame.reduction]
method = "craig_bampton"
n_modes = 4
interface = [{ nodes = "top", dofs = ["uz"] }]

[analyses.modes]
n_modes = 4
images = 0
vtu = false
"""


def _load(name):
    spec = importlib.util.spec_from_file_location(f"scene_test_{name}", EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def small_dict():
    return tomllib.loads(SMALL)


def _error(data, file="bad.toml") -> str:
    with pytest.raises(SceneError) as info:
        prepare(Scene.from_dict(data, EXAMPLES, file))
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{file}: ")
    return message


# --- units -------------------------------------------------------------------------------

@pytest.mark.parametrize(("text", "kind", "si"), [
    ("210 GPa", PRESSURE, 210e9),                # 1 GPa = 1e9 Pa (SI prefix)
    ("4 kg*m^2", INERTIA, 4.0),
    ("4 kg m2", INERTIA, 4.0),
    ("2e4 N*m/rad", ROT_STIFFNESS, 2e4),
    ("1200 rpm", SPEED, 1200 * 2 * np.pi / 60),  # 1 rpm = 2π/60 rad/s
    ("90 deg", ANGLE, np.pi / 2),
    (0.25, ANGLE, 0.25),                         # plain numbers are SI
])
def test_quantities_convert_to_si(text, kind, si):
    # exact factors: the only error is one rounding per multiplication
    assert_allclose(quantity(text, kind), si, rtol=4 * np.finfo(float).eps)


@pytest.mark.parametrize(("text", "kind", "fragment"), [
    ("210 kg", PRESSURE, "unit 'kg' is a mass"),
    ("20 Hz", SPEED, "unit 'Hz' is a frequency"),   # Hz vs rad/s would be off by 2π
    ("3 furlong", PRESSURE, "unknown unit 'furlong'"),
    ("fast", SPEED, "expected an angular speed"),
])
def test_wrong_units_are_rejected(text, kind, fragment):
    with pytest.raises(ValueError, match=fragment):
        quantity(text, kind)


# --- the shipped scenes ------------------------------------------------------------------

@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.toml")), ids=lambda p: p.stem)
def test_shipped_scenes_are_valid(path):
    prepared = prepare(load_scene(path))
    assert prepared.scene.analyses is not None
    assert set(prepared.keys) == {n for n, p in prepared.scene.parts.items() if p.reduction}


def test_from_dict_equals_load_scene(tmp_path):
    (tmp_path / "small.toml").write_text(SMALL)
    assert load_scene(tmp_path / "small.toml") == Scene.from_dict(small_dict(), tmp_path,
                                                                   "small.toml")


def test_frame_scene_builds_the_example_model():
    # the scene and examples/frame_modes.py describe the same machine: same K and M
    scene = load_scene(EXAMPLES / "frame_modes.toml")
    prepared = prepare(scene)
    model = part_model(scene, scene.parts["frame"], prepared.meshes["frame"])
    reference = _load("frame_modes").build()
    # unit strings ("100 mm", "210 GPa") become the example's SI floats up to one rounding,
    # so the matrices agree to round-off of the assembly
    for A, B in ((model.K_free, reference.K_free), (model.M_free, reference.M_free)):
        assert abs(A - B).max() <= 1e-12 * abs(B).max()
    assert_allclose(fm.modes(model, n_modes=6).freq_hz, fm.modes(reference, n_modes=6).freq_hz,
                    rtol=1e-9)


def test_members_generator_reproduces_the_press_frame_mesh():
    # examples/press_frame.py builds its C-frame mesh by hand; the generator must give the
    # same points, cells and groups (same numbering) from the scene's joints and chains
    press = _load("press_frame")
    reference = press.frame_mesh()
    members = [{"group": g, "chain": chain, "element_size": press.ELEMENT_SIZE}
               for g, (chain, _, _) in press.MEMBERS.items()]
    mesh = members_frame(press.JOINTS, members, {"feet": ["column_foot", "leg_foot"]})
    assert_array_equal(mesh.points, reference.points)
    assert_array_equal(mesh.cells["line"], reference.cells["line"])
    for name in reference.cell_sets:
        assert_array_equal(mesh.cell_sets[name]["line"], reference.cell_sets[name]["line"])
    for name in reference.node_sets:
        assert_array_equal(mesh.node_sets[name], reference.node_sets[name])


# --- bad scenes: one line naming file, location and expectation ---------------------------

def _set(path, value):
    def mutate(d):
        *head, last = path
        for key in head:
            d = d[key]
        if value is _DELETE:
            del d[last]
        else:
            d[last] = value
    return mutate


_DELETE = object()
BAD = [
    ("unknown key", _set(("parts", "frame", "sections", "columns", "colour"), "red"),
     "[parts.frame.sections.columns] colour: unknown key; expected one of"),
    ("unknown top-level key", _set(("part",), {}), "part: unknown key; expected one of"),
    ("bad choice", _set(("parts", "frame", "sections", "columns", "section"), "foo"),
     "[parts.frame.sections.columns] section: expected one of ['circle', 'general',"),
    ("missing key", _set(("materials", "steel", "rho"), _DELETE),
     "[materials.steel] rho: missing (required)"),
    ("missing mesh file", _set(("parts", "frame"), {"mesh": "no_such.msh", "sections": {}}),
     "[parts.frame] mesh: file not found:"),
    ("wrong type", _set(("analyses", "modes", "n_modes"), 2.5),
     "[analyses.modes] n_modes: expected an integer, got 2.5"),
    ("wrong type: bool", _set(("materials", "steel", "E"), True),
     "[materials.steel] E: expected a pressure or modulus"),
    ("wrong unit", _set(("materials", "steel", "E"), "210 kg"),
     "[materials.steel] E: expected a pressure or modulus (a number in SI units or a string"
     " like '210 GPa'), got '210 kg' (unit 'kg' is a mass)"),
    ("unknown unit", _set(("parts", "frame", "masses", 0, "mass"), "20 stone"),
     "[parts.frame.masses[0]] mass: expected a mass"),
    ("unknown material", _set(("parts", "frame", "sections", "columns", "material"), "wood"),
     "[parts.frame.sections.columns] material: expected one of the [materials] ['steel'],"
     " got 'wood'"),
    ("unknown group", _set(("parts", "frame", "sections", "posts"),
                           {"section": "circle", "diameter": 0.1, "material": "steel"}),
     "[parts.frame.sections.posts]: group 'posts' is not a cell group of the mesh; expected"
     " one of ['beams_x', 'beams_y', 'columns']"),
    ("unknown support group", _set(("parts", "frame", "supports", 0, "nodes"), "feet"),
     "[parts.frame.supports[0]] nodes: unknown group 'feet'; the mesh has"),
    ("interface on a nonexistent node",
     _set(("parts", "frame", "reduction", "interface"), [{"nodes": 999, "dofs": "uz"}]),
     "[parts.frame.reduction.interface[0]] nodes: node 999 does not exist (the mesh has"),
    ("interface on a nonexistent group",
     _set(("parts", "frame", "reduction", "interface"), [{"nodes": "roof", "dofs": "uz"}]),
     "[parts.frame.reduction.interface[0]] nodes: unknown group 'roof'"),
    ("bad component", _set(("parts", "frame", "reduction", "interface"),
                           [{"nodes": "top", "dofs": "uq"}]),
     "[parts.frame.reduction.interface[0]] dofs: unknown DOF component 'uq'"),
    ("mass on a nonexistent node", _set(("parts", "frame", "masses", 0, "node"), 10_000),
     "[parts.frame.masses[0]] node: node 10000 does not exist"),
    ("two mode selections", _set(("parts", "frame", "reduction", "f_max_hz"), "100 Hz"),
     "[parts.frame.reduction]: craig_bampton needs exactly one of n_modes, cutoff_hz and"),
    ("no analyses", _set(("analyses",), {}), "[analyses]: no analyses requested"),
]


@pytest.mark.parametrize(("mutate", "expected"), [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_scene_gives_one_line_error_naming_the_location(mutate, expected):
    data = small_dict()
    mutate(data)
    assert expected in _error(data)


MACHINE = """
[mechanisms.cam]
model = "cam_follower"
parameters = { m = "2 kg", c = "1e6 N/m", c_r = "5e3 N/m", b = 0, F = 0 }
position_functions.U = { kind = "slider_crank", r = "20 mm", l = "100 mm" }

[[mounts]]
mechanism = "cam"
attachments = [{ coordinate = "y_c", node = 4, direction = "uz" }]
"""


@pytest.mark.parametrize(("path", "value", "expected"), [
    (("mounts", 0, "attachments", 0, "coordinate"), "y_x",
     "[mounts[0].attachments[0]] coordinate: expected one of the coordinates ['q_s', 'y_c',"
     " 'y_f', 'q'] of mechanism 'cam', got 'y_x'"),
    (("mounts", 0, "attachments", 0, "node"), 500,
     "[mounts[0].attachments[0]] node: node 500 does not exist"),
    (("mounts", 0, "mechanism"), "crank",
     "[mounts[0]] mechanism: expected one of the [mechanisms] ['cam'], got 'crank'"),
    (("mechanisms", "cam", "parameters", "m"), "2 m",
     "[mechanisms.cam.parameters] m: expected a mass"),
    (("mechanisms", "cam", "parameters", "k"), 1.0,
     "[mechanisms.cam] parameters: unknown parameters ['k']"),
    (("mechanisms", "cam", "model"), "crank",
     "[mechanisms.cam] model: expected one of ['cam_follower', 'processing_machine',"),
    (("mechanisms", "cam", "position_functions", "U", "l"), "10 mm",
     "[mechanisms.cam.position_functions.U]: coupler length l = 0.01 must exceed"),
])
def test_bad_machine_gives_one_line_error(path, value, expected):
    data = small_dict()
    data.update(tomllib.loads(MACHINE))
    _set(path, value)(data)
    assert expected in _error(data)


def test_invalid_toml_and_missing_scene(tmp_path):
    bad = tmp_path / "broken.toml"
    bad.write_text("[scene\nname = 1\n")
    with pytest.raises(SceneError, match=r"^broken.toml: not valid TOML \("):
        load_scene(bad)
    with pytest.raises(SceneError, match="scene file not found"):
        load_scene(tmp_path / "missing.toml")


# --- robustness: random corruptions of a valid scene ------------------------------------

def _leaves(data, path=()):
    """Paths to all values of a nested dict/list structure."""
    items = data.items() if isinstance(data, dict) else enumerate(data)
    for key, value in items:
        yield path + (key,)
        if isinstance(value, (dict, list)):
            yield from _leaves(value, path + (key,))


def fuzz_dict():
    data = small_dict()
    data.update(tomllib.loads(MACHINE))
    return data


PATHS = list(_leaves(fuzz_dict()))
JUNK = st.one_of(st.none(), st.booleans(), st.integers(-5, 10**6), st.floats(allow_nan=True),
                 st.text(max_size=8), st.sampled_from(["1 GPa", "3 kg", "90 deg", "top", "base"]),
                 st.lists(st.integers(-1, 3), max_size=4), st.just({"x": 1}))


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(PATHS), JUNK, st.sampled_from(["replace", "delete", "extra"]))
def test_corrupted_scene_is_valid_or_one_line_scene_error(path, junk, how):
    # Any single corruption either still describes a valid scene or gives a SceneError of
    # one line that starts with the file name: never another exception or a traceback.
    data = copy.deepcopy(fuzz_dict())
    target = data
    for key in path[:-1]:
        target = target[key]
    if how == "delete":
        del target[path[-1]]
    elif how == "extra" and isinstance(target, dict):
        target["unexpected_key"] = junk
    else:
        target[path[-1]] = None if junk is None else junk
        if junk is None:
            del target[path[-1]]
    message = "fuzz.toml: valid"
    try:
        prepare(Scene.from_dict(data, EXAMPLES, "fuzz.toml"))
    except SceneError as exc:
        message = str(exc)
    assert "\n" not in message
    assert message.startswith("fuzz.toml: ")
