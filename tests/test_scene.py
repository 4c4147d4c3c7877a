"""Scene files: validation with one-line errors naming the location, units, and the
mapping of scenes onto the Python API."""

import importlib.util
import tomllib
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

import femmech as fm
from femmech.errors import SceneError
from femmech.fe.generators import members_frame
from femmech.scene.build import part_model, prepare
from femmech.scene.load import Scene, load_scene
from femmech.scene.units import ANGLE, INERTIA, PRESSURE, ROT_STIFFNESS, SPEED, quantity

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
    prepared = prepare(load_scene(path), allow_code=True)  # textile_shaft runs its module
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
    # bound: unit strings ("100 mm", "210 GPa") become the example's SI floats up to one rounding,
    # so the matrices agree to round-off of the assembly
    for A, B in ((model.K_free, reference.K_free), (model.M_free, reference.M_free)):
        assert abs(A - B).max() <= 1e-12 * abs(B).max()
    # bound: unit strings converted with one rounding each: eigensolver round-off eps λ_max/λ
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
    ("unknown top-level key", _set(("part",), {}),
     "bad.toml: part: unknown key; did you mean 'parts'? expected one of"),
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
     "[mechanisms.cam] model: expected one of ['cam_follower', 'mobile_crane',"),
    (("mechanisms", "cam", "position_functions", "U", "l"), "10 mm",
     "[mechanisms.cam.position_functions.U] l: expected a coupler longer than r + |e| ="
     " 0.02 m (a fully rotating crank), got 0.01 m"),
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


def test_utf8_with_byte_order_mark_and_crlf_is_accepted(tmp_path):
    # editors on Windows save UTF-8 with a BOM and CRLF line ends; both are valid TOML
    # once the BOM is dropped (encoding "utf-8-sig")
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + SMALL.replace("\n", "\r\n").encode("utf-8"))
    assert load_scene(path) == Scene.from_dict(small_dict(), tmp_path, "bom.toml")


# --- unknown keys first, with a "did you mean" --------------------------------------------

# Each misspelt key would otherwise let another error fire first (a missing or defaulted
# key, a "give exactly one of"); the unknown key must be named instead.
TYPOS = [
    (("analyses", "modes"), "n_modes", "n_mode",
     "[analyses.modes] n_mode: unknown key; did you mean 'n_modes'?"),
    (("materials", "steel"), "rho", "rh0",
     "[materials.steel] rh0: unknown key; did you mean 'rho'?"),
    (("parts", "frame", "sections", "beams_x"), "material", "materal",
     "[parts.frame.sections.beams_x] materal: unknown key; did you mean 'material'?"),
    (("parts", "frame", "reduction"), "n_modes", "n_mode",
     "[parts.frame.reduction] n_mode: unknown key; did you mean 'n_modes'?"),
    (("parts", "frame", "generator"), "subdivisions", "subdivision",
     "[parts.frame.generator] subdivision: unknown key; did you mean 'subdivisions'?"),
    (("parts", "frame", "masses", 0), "node", "nodes",
     "[parts.frame.masses[0]] nodes: unknown key; did you mean 'node'?"),
    (("mounts", 0), "attachments", "attachment",
     "[mounts[0]] attachment: unknown key; did you mean 'attachments'?"),
    (("mounts", 0, "attachments", 0), "coordinate", "coordinates",
     "[mounts[0].attachments[0]] coordinates: unknown key; did you mean 'coordinate'?"),
    (("mechanisms", "cam"), "position_functions", "position_function",
     "[mechanisms.cam] position_function: unknown key; did you mean 'position_functions'?"),
    (("mechanisms", "cam", "position_functions", "U"), "r", "radius",
     "[mechanisms.cam.position_functions.U] radius: unknown key; expected one of"),
]


@pytest.mark.parametrize(("table", "key", "typo", "expected"), TYPOS,
                         ids=[t[2] + "@" + ".".join(map(str, t[0])) for t in TYPOS])
def test_misspelt_key_is_named_before_missing_ones(table, key, typo, expected):
    data = small_dict()
    data.update(tomllib.loads(MACHINE))
    target = data
    for k in table:
        target = target[k]
    target[typo] = target.pop(key)
    assert expected in _error(data)


@pytest.mark.parametrize(("path", "value", "expected"), [
    # keys that belong to another choice of the same table
    (("parts", "frame", "sections", "beams_y", "diameter"), "50 mm",
     "[parts.frame.sections.beams_y] diameter: unknown key for section = 'tube'; did you"
     " mean 'outer_diameter'? expected one of ['inner_diameter', 'material',"),
    (("parts", "frame", "generator", "joints"), {},
     "[parts.frame.generator] joints: unknown key for kind = 'grid_frame'; expected"),
    (("mechanisms", "cam", "options"), {"c_retrun": "c_r"},
     "[mechanisms.cam.options] c_retrun: unknown key; did you mean 'c_return'?"),
    (("analyses", "modes", "band_hz"), {"start": 1, "stop": 2, "num": 3},
     "[analyses.modes.band_hz] num: unknown key; expected one of ['n', 'start', 'stop']"),
])
def test_key_of_another_choice_is_unknown(path, value, expected):
    data = small_dict()
    data.update(tomllib.loads(MACHINE))
    _set(path, value)(data)
    assert expected in _error(data)


# --- values that do not fit together: caught when the scene is read --------------------

CONSISTENCY = [
    (("parts", "frame", "sections", "beams_y", "inner_diameter"), "50 mm",
     "[parts.frame.sections.beams_y] inner_diameter: expected less than outer_diameter"
     " (0.05 m), got 0.05 m"),
    (("parts", "frame", "sections", "beams_x", "wall"), "30 mm",
     "[parts.frame.sections.beams_x] wall: expected less than half the smaller of width and"
     " height (0.06 m), got 0.03 m"),
    (("parts", "frame", "sections", "columns", "flange"), "50 mm",
     "[parts.frame.sections.columns] flange: expected less than half the height"),
    (("parts", "frame", "sections", "columns", "web"), "100 mm",
     "[parts.frame.sections.columns] web: expected less than the width"),
    (("parts", "frame", "sections", "columns", "orientation"), [0, 0, 0],
     "[parts.frame.sections.columns] orientation: expected a non-zero vector"),
    (("parts", "frame", "masses", 0, "inertia"), [1, -1, 1],
     "[parts.frame.masses[0]] inertia: expected three values >= 0"),
    (("parts", "frame", "springs"), [{"node_a": 4, "node_b": 4, "stiffness": 1e5}],
     "[parts.frame.springs[0]] node_b: a spring joins two nodes; node_a and node_b are both 4"),
    (("parts", "frame", "interpolating_links"),
     [{"reference": 4, "patch": [0, 1, 2], "weights": [1, 1]}],
     "[parts.frame.interpolating_links[0]] weights: expected one weight per patch node (3)"),
    (("parts", "frame", "generator", "bays"), [0, 0, 0],
     "[parts.frame.generator] bays: expected three integers in 0..1000 (limit MAX_BAYS), not"
     " all zero"),
    (("analyses", "modes"), {"band_hz": ["200 Hz", "100 Hz"]},
     "[analyses.modes] band_hz: expected 0 <= low < high"),
    (("analyses", "modes"), {"band_hz": {"start": "2 Hz", "stop": "1 Hz", "n": 2}},
     "[analyses.modes.band_hz] stop: expected stop >= start"),
    (("mechanisms", "cam", "position_functions", "U"),
     {"kind": "cam", "segments": [{"beta": "180 deg"}, {"beta": "90 deg"}]},
     "[mechanisms.cam.position_functions.U] segments: the angles beta sum to 4.71238898038"
     " rad (270 deg), not one revolution"),
    (("mechanisms", "cam", "position_functions", "U"),
     {"kind": "cam", "segments": [{"beta": "180 deg", "lift": "10 mm", "law": "cycloidal"},
                                  {"beta": "180 deg", "lift": "-9 mm", "law": "cycloidal"}]},
     "[mechanisms.cam.position_functions.U] segments: the lifts sum to 0.001, not 0"),
    (("mechanisms", "cam", "position_functions", "U"),
     {"kind": "four_bar", "a": 1, "b": 1, "c": 1, "d": 3},
     "[mechanisms.cam.position_functions.U]: four-bar a=1, b=1, c=1, d=3 m: the crank cannot"
     " turn fully"),
    (("mechanisms", "cam", "position_functions", "U"),
     {"kind": "four_bar", "a": 1, "b": 3, "c": 3, "d": 3, "branch": 0},
     "[mechanisms.cam.position_functions.U] branch: expected +1 or -1, got 0"),
    (("mounts", 0, "attachments", 0, "direction"), [0, 0, 0, 0, 0, 0],
     "[mounts[0].attachments[0]] direction: expected six weights, not all zero"),
    (("mounts", 0, "attachments", 0, "direction"), "uw",
     "[mounts[0].attachments[0]] direction: expected a component name"),
    # found by benchmarks/fuzz_scenes.py: passed `check`, then failed in `run`
    (("mounts", 0, "attachments"), [{"coordinate": "y_c", "node": 4, "direction": "uz"},
                                    {"coordinate": "y_c", "node": 5, "direction": "ux"}],
     "[mounts[0].attachments[1]] coordinate: coordinate 'y_c' is attached twice in this"
     " mount"),
    (("parts", "frame", "rigid_links"), [{"master": 4, "slaves": [5, 6]},
                                         {"master": 7, "slaves": [6]}],
     "[parts.frame.rigid_links[1]] slaves: node 6 is already tied by rigid_links[0]; a node"
     " follows at most one rigid link"),
    (("analyses", "sweep"), {"speeds": ["100 rpm", "100.2 rpm", "100 rpm"]},
     "[analyses.sweep] speeds: two speeds round to 100 rpm; each curve of a sweep is"
     " labelled by its speed in whole rpm"),
]


@pytest.mark.parametrize(("path", "value", "expected"), CONSISTENCY,
                         ids=[c[2].split(":")[0] for c in CONSISTENCY])
def test_inconsistent_values_are_caught_when_read(path, value, expected):
    # Scene.from_dict alone (what `femmech check` starts with) must refuse them, naming
    # the key; before, several passed the reader and failed only when the model was built
    data = small_dict()
    data.update(tomllib.loads(MACHINE))
    _set(path, value)(data)
    with pytest.raises(SceneError) as info:
        Scene.from_dict(data, EXAMPLES, "bad.toml")
    assert expected in str(info.value)


def test_run_up_needs_a_forward_ramp():
    data = small_dict()
    data.update(tomllib.loads(MACHINE))
    data["analyses"] = {"response": {"kind": "run_up", "speed_start": "-100 rpm",
                                     "speed_end": "600 rpm", "duration": "1 s",
                                     "t_end": "1 s"}}
    assert "[analyses.response] speed_start: expected a value >= 0" in _error(data)


# --- resource guards: every size a scene can request is bounded before any allocation ----

LIMITS = [
    (("parts", "frame", "generator", "bays"), [1000, 1000, 1000],
     "[parts.frame.generator] bays: the mesh would have 1003003001 nodes; at most 10000000"
     " (limit MAX_NODES)"),
    (("parts", "frame", "generator", "subdivisions"), 10**12,
     "[parts.frame.generator] subdivisions: expected an integer <= 10000 (limit"
     " MAX_SUBDIVISIONS), got 1000000000000"),
    (("parts", "frame", "reduction", "n_modes"), 10**30,
     "[parts.frame.reduction] n_modes: expected an integer <= 2000 (limit MAX_MODES)"),
    (("analyses", "modes", "n_modes"), 2**63,
     "[analyses.modes] n_modes: expected an integer <= 2000 (limit MAX_MODES)"),
    (("analyses", "modes", "images"), 10**6,
     "[analyses.modes] images: expected an integer <= 100 (limit MAX_IMAGES)"),
    (("analyses", "modes"), {"band_hz": {"start": 0, "stop": 1, "n": 10**12}},
     "[analyses.modes.band_hz] n: expected an integer <= 100000"),
    (("materials", "steel", "E"), 10**400,
     "[materials.steel] E: expected a pressure or modulus (a number in SI units or a string"
     " like '210 GPa'), got 1000"),
    (("materials", "steel", "E"), "1e31 Pa",
     "[materials.steel] E: expected a magnitude of at most 1e+30 in SI units (limit"
     " MAX_MAGNITUDE)"),
    (("materials", "steel", "E"), "1 GPa^99",
     "[materials.steel] E: expected a pressure or modulus"),
    (("materials", "steel", "E"), "2" * 300 + " GPa",
     "[materials.steel] E: expected a pressure or modulus (a number in SI units or a string"
     " like '210 GPa'), got '2222"),
    (("scene", "description"), "x" * 20_000,
     "bad.toml: [scene.description]: string of 20000 characters; at most 10000"),
    (("parts", "frame", "supports"), [{"nodes": "base"}] * 100_001,
     "bad.toml: [parts.frame.supports]: list of 100001 entries; at most 100000"),
    (("parts", "frame", "masses", 0, "node"), 10**30,
     "[parts.frame.masses[0]] node: expected a node index >= 0 and <= 10000000 (limit"
     " MAX_NODES)"),
    (("parts", "fr\name"), {},
     "bad.toml: [parts]: key 'fr\\name': expected at most 200 printable characters"),
]


@pytest.mark.parametrize(("path", "value", "expected"), LIMITS,
                         ids=[lim[2].split(":")[0] + "=" + str(lim[1])[:12] for lim in LIMITS])
def test_absurd_sizes_are_refused_naming_key_and_limit(path, value, expected):
    data = small_dict()
    _set(path, value)(data)
    with pytest.raises(SceneError) as info:
        Scene.from_dict(data, EXAMPLES, "bad.toml")
    assert expected in str(info.value)
    assert len(str(info.value).splitlines()) == 1


def test_member_subdivisions_are_bounded():
    # a length in mm given as m, or a divisions count typed with extra zeros, would
    # allocate millions of nodes: refused per member and by the element length
    press = tomllib.loads((EXAMPLES / "press_frame.toml").read_text())
    member = press["parts"]["frame"]["generator"]["members"][0]
    member["element_size"] = "1e-9 m"
    message = _error(press)
    assert "[parts.frame.generator.members[0]] element_size: 6e+08 elements from" in message
    assert "at most 100000 per member (limit MAX_ELEMENTS_PER_MEMBER)" in message
    member["element_size"] = "0.1 mm"  # 6000 elements, each shorter than the near-node
    assert "element_size: elements of 0.0001 m from 'column_foot' to 'bed_root'; at least" \
        in _error(press)
    member["element_size"] = "0.1 m"
    member["chain"] = ["column_foot", "bed_root", "column_foot"]  # the same member twice
    assert "chain: joints 'bed_root' and 'column_foot' are already joined by members[0]" \
        in _error(press)


def test_scene_file_size_and_nesting_are_bounded(tmp_path, monkeypatch):
    import femmech.scene.load

    path = tmp_path / "big.toml"
    path.write_text(SMALL)
    monkeypatch.setattr(femmech.scene.load, "MAX_SCENE_BYTES", 100)
    with pytest.raises(SceneError, match=r"^big.toml: file of \d+ bytes; a scene has at most"
                                         r" 100 \(limit MAX_SCENE_BYTES\)$"):
        load_scene(path)
    data = small_dict()
    deep = 1
    for _ in range(40):
        deep = [deep]
    data["scene"]["description"] = deep
    with pytest.raises(SceneError, match=r"nested deeper than 16 levels$"):
        Scene.from_dict(data, EXAMPLES, "deep.toml")
