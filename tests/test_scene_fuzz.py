"""Scene fuzzing: any corruption of a scene is valid or one clean line.

The oracle: reading a scene and :func:`femmech.scene.build.prepare` (what ``femmech
check`` runs) either succeed or raise an :class:`~femmech.errors.InputError` (a
SceneError, a UserCodeError, ...) whose message is one line starting with the scene file
name. Any other exception (OverflowError, IndexError, MemoryError, RecursionError, a
TypeError from deep inside numpy) fails the test.

Two families of corruption: hypothesis strategies over the scene schema (values of the
right and the wrong type, boundary numbers, huge integers, NaN and infinities, empty and
long strings and lists, unicode, nested tables; deleted, extra and misspelt keys) and
byte-level mutations of the TOML text (bit flips, truncation, inserted, deleted and
duplicated bytes, a byte-order mark, CRLF). The long run over every shipped scene, in
worker processes with a time limit, is ``benchmarks/fuzz_scenes.py``.
"""

import copy
import importlib.util
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from femmech.errors import InputError
from femmech.scene.build import prepare
from femmech.scene.load import Scene, load_scene

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
FUZZ = settings(max_examples=100, deadline=None, database=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow])


def _benchmark():
    spec = importlib.util.spec_from_file_location("fuzz_scenes",
                                                  ROOT / "benchmarks" / "fuzz_scenes.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


bench = _benchmark()  # TOML writer and byte mutations shared with the long run

BASE = """
[materials.steel]
E = "210 GPa"
nu = 0.3
rho = "7850 kg/m^3"

[parts.frame.generator]
kind = "members"
joints.a = [0, 0, 0]
joints.b = [0, 0, 1]
joints.c = [1, 0, 1]
joints.d = [1, 0, 0]
node_sets.feet = ["a", "d"]
members = [{ group = "posts", chain = ["a", "b"], divisions = 3 },
           { group = "posts", chain = ["d", "c"], divisions = 3 },
           { group = "beam", chain = ["b", "c"], element_size = "0.25 m" }]

[parts.frame.sections.posts]
section = "tube"
outer_diameter = "60 mm"
inner_diameter = "50 mm"
material = "steel"

[parts.frame.sections.beam]
section = "rectangular_hollow"
width = "80 mm"
height = "120 mm"
wall = "5 mm"
material = "steel"
orientation = [0, 1, 0]

[[parts.frame.supports]]
nodes = "feet"

[[parts.frame.masses]]
node = "c"
mass = "20 kg"
inertia = ["0.1 kg*m^2", "0.1 kg*m^2", "0.1 kg*m^2"]

[[parts.frame.springs]]
node_a = "b"
stiffness = ["1e5 N/m", "1e5 N/m", 0, 0, 0, "1e3 N*m/rad"]

[parts.frame.reduction]
method = "craig_bampton"
n_modes = 4
interface = [{ nodes = "b", dofs = ["ux", "uz"] }, { nodes = "c", dofs = "uz" }]

[mechanisms.cam]
model = "cam_follower"
parameters = { m = "2 kg", c = "1e6 N/m", c_r = "5e3 N/m", b = 0, F = 0 }
position_functions.U = { kind = "slider_crank", r = "20 mm", l = "100 mm" }

[[mounts]]
mechanism = "cam"
attachments = [{ coordinate = "y_c", node = "b", direction = "uz" },
               { coordinate = "y_f", node = "c", direction = "uz", stiffness = "1e7 N/m" }]

[analyses.modes]
n_modes = 4
images = 0
vtu = false

[analyses.sweep]
angles = { start = "0 deg", stop = "360 deg", n = 13 }
n_modes = 3
speeds = ["0 rpm", "600 rpm"]
"""
"""A small machine touching most of the schema: members generator, two section shapes,
lumped items, a reduction, a built-in mechanism with a position function, a mount."""


def base_dict() -> dict:
    return tomllib.loads(BASE)


PATHS = list(bench.paths(base_dict()))
TABLES = [p for p in PATHS if isinstance(bench._value(base_dict(), p), dict)]


def outcome(read, file: str) -> str:
    """Run ``read`` (→ Scene) and prepare; "valid" or the clean one-line error message."""
    try:
        prepare(read())
    except InputError as exc:
        message = str(exc)
        assert "\n" not in message, message
        assert len(message.splitlines()) == 1, message
        assert message.startswith(f"{file}: "), message
        return message
    return "valid"


def test_the_base_scene_is_valid():
    assert outcome(lambda: Scene.from_dict(base_dict(), EXAMPLES, "fuzz.toml"),
                   "fuzz.toml") == "valid"


# --- strategies over the schema ----------------------------------------------------------

UNITS = ["m", "mm", "kg", "GPa", "N/m", "N*m/rad", "deg", "rpm", "Hz", "s", "kg*m^2", "m^9",
         "furlong", "", "1/s", "rad/s", "m/", "^2"]
NUMBERS = st.one_of(
    st.sampled_from([0, -1, 1, 2, 3, 10**9, 10**18, 2**63, 10**30, -10**30, 10**400]),
    st.integers(-10, 10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 1e-300, 1e300, 5e-324, 0.5]))
QUANTITIES = st.builds(lambda n, u: f"{n} {u}".strip(),
                       st.one_of(st.integers(-10**40, 10**40), st.floats()),
                       st.sampled_from(UNITS))
STRINGS = st.one_of(st.text(max_size=12), st.sampled_from(
    ["", " ", "top", "base", "feet", "b", "all", "uz", "steel", "tube", "cam", "craig_bampton",
     "members", "x" * 20_000, "é∂\u2028\n\r", "1" * 500 + " m", "y_c"]), QUANTITIES)
LEAVES = st.one_of(st.none(), st.booleans(), NUMBERS, STRINGS)
VALUES = st.recursive(
    LEAVES, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                    st.dictionaries(st.sampled_from(
                                        ["a", "kind", "nodes", "n", "start", "stop", "x"]),
                                        inner, max_size=3)),
    max_leaves=6)
ACTIONS = ("replace", "delete", "extra", "rename", "duplicate")


def corrupt(data: dict, path: tuple, value, action: str) -> dict:
    """One corruption of ``data`` at ``path`` (see ACTIONS)."""
    data = copy.deepcopy(data)
    parent, last = bench._parent(data, path), path[-1]
    if action == "delete" or (action == "replace" and value is None):
        del parent[last]
    elif action == "replace":
        parent[last] = value
    elif action == "extra" and isinstance(parent, dict):
        parent[f"{last}_" if isinstance(last, str) else "extra"] = value
    elif action == "rename" and isinstance(parent, dict):
        parent[str(last)[:-1] or "_"] = parent.pop(last)
    elif action == "duplicate" and isinstance(parent[last], list):
        parent[last] = parent[last] * 3
    return data


@FUZZ
@given(st.sampled_from(PATHS), VALUES, st.sampled_from(ACTIONS))
def test_schema_corruption_is_valid_or_one_line_error(path, value, action):
    data = corrupt(base_dict(), path, value, action)
    outcome(lambda: Scene.from_dict(data, EXAMPLES, "fuzz.toml"), "fuzz.toml")


@FUZZ
@given(st.sampled_from(TABLES), st.text(min_size=1, max_size=20), VALUES)
def test_any_extra_key_is_unknown_or_valid(table, key, value):
    # a key of any spelling (unicode, control characters, quotes) in any table: named in
    # the message on one line
    data = base_dict()
    bench._value(data, table)[key] = 0 if value is None else value
    outcome(lambda: Scene.from_dict(data, EXAMPLES, "fuzz.toml"), "fuzz.toml")


# --- byte-level mutations of the text -----------------------------------------------------

@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz")


@FUZZ
@given(st.sampled_from(bench.BYTES[:-1]), st.integers(0, 2**32 - 1))
def test_byte_mutation_is_valid_or_one_line_error(folder, kind, seed):
    import random

    text = bench.mutate_bytes(BASE.encode(), kind, random.Random(seed))
    path = folder / "fuzz.toml"
    path.write_bytes(text)
    outcome(lambda: load_scene(path), "fuzz.toml")


@FUZZ
@given(st.integers(0, len(BASE)), st.binary(min_size=1, max_size=6),
       st.sampled_from(["insert", "replace"]))
def test_inserted_bytes_are_valid_or_one_line_error(folder, at, data, how):
    raw = BASE.encode()
    text = raw[:at] + data + raw[at + (len(data) if how == "replace" else 0):]
    path = folder / "fuzz.toml"
    path.write_bytes(text)
    outcome(lambda: load_scene(path), "fuzz.toml")


@pytest.mark.parametrize("depth", [20, 500, 5000])
def test_deep_nesting_is_one_line_error(folder, depth):
    # tomllib recurses once per level of nested arrays and inline tables (RecursionError
    # beyond ~1000); the scene reader refuses anything deeper than MAX_DEPTH
    path = folder / "deep.toml"
    path.write_text(BASE + "[scene]\nname = " + "[" * depth + "]" * depth + "\n")
    message = outcome(lambda: load_scene(path), "deep.toml")
    assert "nested" in message


def test_toml_writer_round_trips_the_base():
    assert tomllib.loads(bench.to_toml(base_dict())) == base_dict()
