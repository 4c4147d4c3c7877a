"""Reduction cache of scene runs: reuse, invalidation of exactly the affected entries,
detection of corrupted entries (issue 8). Asserted through the run log, never timing."""

import json
import os
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest

from femmech.cache import cached_reduction, entry_paths, read_entry, write_entry
from femmech.reduction import Superelement, guyan
from femmech.scene import Scene
from femmech.scene_run import run_scene

ROOT = Path(__file__).resolve().parent.parent

# Two reduced parts joined at the four top joints of the base (assembled superelements),
# with a cam mechanism on the rail's mid node and the base's top: a sweep needs both.
TWO_PARTS = """
[scene]
name = "two parts"

[materials.steel]
E = "210 GPa"
nu = 0.3
rho = "7850 kg/m^3"

[materials.aluminium]
E = "70 GPa"
nu = 0.33
rho = "2700 kg/m^3"

[parts.base.generator]
kind = "grid_frame"
bays = [1, 1, 1]
size = [1.0, 0.6, 0.8]
subdivisions = 2

[parts.base.sections]
beams_x = { section = "tube", outer_diameter = 0.06, inner_diameter = 0.05, material = "steel" }
beams_y = { section = "tube", outer_diameter = 0.06, inner_diameter = 0.05, material = "steel" }
columns = { section = "tube", outer_diameter = 0.08, inner_diameter = 0.07, material = "steel" }

[[parts.base.supports]]
nodes = "base"

[parts.base.reduction]
method = "craig_bampton"
n_modes = 4
interface = [{ nodes = "top" }]

[parts.rail.generator]
kind = "members"
joints = { a = [0.0, 0.0, 0.8], mid = [0.5, 0.0, 0.8], b = [1.0, 0.0, 0.8] }
members = [{ group = "rail", chain = ["a", "mid", "b"], divisions = 2 }]

[parts.rail.sections.rail]
section = "tube"
outer_diameter = "40 mm"
inner_diameter = "30 mm"
material = "aluminium"

[parts.rail.reduction]
method = "craig_bampton"
n_modes = 3
interface = [{ nodes = "a" }, { nodes = "b" }]

[mechanisms.cam]
model = "cam_follower"
options = { J = "J" }
parameters = { J = "1e-3 kg*m^2", m = "2 kg", c = "1e6 N/m", c_r = "5e3 N/m", b = 0, F = 0 }
position_functions.U = { kind = "slider_crank", r = "20 mm", l = "100 mm" }

[[mounts]]
mechanism = "cam"
part = "rail"
attachments = [
    { coordinate = "q_s", node = "mid", direction = "rx" },
    { coordinate = "y_c", node = "mid", direction = "uz" },
]

[analyses.sweep]
angles = { start = "0 deg", stop = "360 deg", n = 5 }
n_modes = 4
"""


def _scene(mutate=None):
    data = tomllib.loads(TWO_PARTS)
    if mutate is not None:
        mutate(data)
    return Scene.from_dict(data, ROOT, "two_parts.toml")


def _statuses(result) -> dict:
    """{'base': 'hit', 'rail': 'miss'} from the run log lines ``cache <status>: part 'x'``."""
    out = {}
    for line in result.log:
        if line.startswith("cache "):
            status = line.split(":")[0].removeprefix("cache ")
            part = line.split("'")[1]
            out[part] = {"corrupt, rebuilt": "corrupt"}.get(status, status)
    return out


@pytest.fixture(scope="module")
def first_run(tmp_path_factory):
    base = tmp_path_factory.mktemp("cache_runs")
    cache = base / "cache"
    result = run_scene(_scene(), base / "run1", cache_dir=cache)
    return base, cache, result


def _fresh_cache(first_run, tmp_path) -> Path:
    """A copy of the first run's cache, so tests do not disturb each other."""
    _, cache, _ = first_run
    copy = tmp_path / "cache"
    shutil.copytree(cache, copy)
    return copy


def test_first_run_misses_and_assembles(first_run):
    _, cache, result = first_run
    assert _statuses(result) == {"base": "miss", "rail": "miss"}
    assert sum(line.startswith("assembled part") for line in result.log) == 2
    assert len(list(cache.glob("*.npz"))) == len(list(cache.glob("*.json"))) == 2


def test_second_run_reuses_cache_with_identical_results(first_run, tmp_path):
    base, _, first = first_run
    cache = _fresh_cache(first_run, tmp_path)
    second = run_scene(_scene(), tmp_path / "run2", cache_dir=cache)
    assert _statuses(second) == {"base": "hit", "rail": "hit"}
    # nothing is assembled: the cached superelements carry all the sweep needs
    assert not any(line.startswith("assembled part") for line in second.log)
    # identical: the stored matrices are bit-exact (npz), the solves deterministic
    assert (tmp_path / "run2" / "results.json").read_bytes() == \
        (base / "run1" / "results.json").read_bytes()


def test_changing_a_material_invalidates_only_its_part(first_run, tmp_path):
    cache = _fresh_cache(first_run, tmp_path)
    scene = _scene(lambda d: d["materials"]["aluminium"].update(E="69 GPa"))
    result = run_scene(scene, tmp_path / "out", cache_dir=cache)
    assert _statuses(result) == {"base": "hit", "rail": "miss"}


def test_changing_the_mesh_invalidates_only_its_part(first_run, tmp_path):
    cache = _fresh_cache(first_run, tmp_path)
    scene = _scene(lambda d: d["parts"]["base"]["generator"].update(subdivisions=3))
    result = run_scene(scene, tmp_path / "out", cache_dir=cache)
    assert _statuses(result) == {"base": "miss", "rail": "hit"}
    # and the unchanged scene still finds both of its entries
    again = run_scene(_scene(), tmp_path / "again", cache_dir=cache)
    assert _statuses(again) == {"base": "hit", "rail": "hit"}


def test_mesh_file_content_is_the_key_not_its_name_or_time(tmp_path):
    mesh = tmp_path / "frame.msh"
    shutil.copy(ROOT / "meshes" / "machine_frame.msh", mesh)
    scene_text = (ROOT / "examples" / "frame_modes.toml").read_text().replace(
        "../meshes/machine_frame.msh", "frame.msh").replace(
        "[analyses.modes]\nn_modes = 12\nimages = 12\nvtu = true",
        "[parts.frame.reduction]\nmethod = \"craig_bampton\"\nn_modes = 6\ninterface ="
        " [{ nodes = \"motor\" }]\n\n[analyses.modes]\nn_modes = 4\nimages = 0\nvtu = false")
    (tmp_path / "frame.toml").write_text(scene_text)
    cache = tmp_path / "cache"

    def status(name):
        return _statuses(run_scene(tmp_path / "frame.toml", tmp_path / name, cache))["frame"]

    assert status("a") == "miss"
    os.utime(mesh, (1e9, 1e9))  # another modification time, same content
    assert status("b") == "hit"
    with open(mesh, "a") as stream:  # same mesh for meshio, other bytes: a new entry
        stream.write("$Comments\nedited\n$EndComments\n")
    assert status("c") == "miss"


def _flip(path: Path) -> None:
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))


CORRUPTIONS = {
    "flipped byte": lambda npz, manifest: _flip(npz),
    "truncated": lambda npz, manifest: npz.write_bytes(npz.read_bytes()[:200]),
    "manifest lost (interrupted write)": lambda npz, manifest: manifest.unlink(),
    "garbage manifest": lambda npz, manifest: manifest.write_text("{not json"),
    "superelement file lost": lambda npz, manifest: npz.unlink(),
}


@pytest.mark.parametrize("how", list(CORRUPTIONS))
def test_corrupted_entry_is_detected_and_rebuilt(first_run, tmp_path, how):
    base, _, first = first_run
    cache = _fresh_cache(first_run, tmp_path)
    rail_key = next(x for x in first.log if x.startswith("cache miss: part 'rail'"))
    rail_key = rail_key.split("(")[1][:12]
    npz = next(cache.glob(f"{rail_key}*.npz"))
    CORRUPTIONS[how](npz, npz.with_suffix(".json"))
    result = run_scene(_scene(), tmp_path / "out", cache_dir=cache)
    assert _statuses(result) == {"base": "hit", "rail": "corrupt"}
    line = next(x for x in result.log if x.startswith("cache corrupt, rebuilt: part 'rail'"))
    assert "reduced and stored" in line
    assert (tmp_path / "out" / "results.json").read_bytes() == \
        (base / "run1" / "results.json").read_bytes()
    # the rebuilt entry is trusted again
    again = run_scene(_scene(), tmp_path / "again", cache_dir=cache)
    assert _statuses(again) == {"base": "hit", "rail": "hit"}


# --- the cache functions on their own -----------------------------------------------------

@pytest.fixture(scope="module")
def superelement():
    from femmech.scene_build import part_mesh, part_model

    scene = _scene()
    part = scene.parts["rail"]
    return guyan(part_model(scene, part, part_mesh(scene, part)), ["a", "b"])


def test_cached_reduction_builds_once(tmp_path, superelement):
    calls, log = [], []

    def build():
        calls.append(1)
        return superelement

    first = cached_reduction(tmp_path, "k" * 64, "rail", build, log.append)
    second = cached_reduction(tmp_path, "k" * 64, "rail", build, log.append)
    off = cached_reduction(None, "k" * 64, "rail", build, log.append)
    assert (first.status, second.status, off.status) == ("miss", "hit", "off")
    assert len(calls) == 2
    assert [x.split(":")[0] for x in log] == ["cache miss", "cache hit", "cache off"]
    np.testing.assert_array_equal(second.superelement.K, superelement.K)
    manifest = json.loads(entry_paths(tmp_path, "k" * 64)[1].read_text())
    assert manifest["size"] == entry_paths(tmp_path, "k" * 64)[0].stat().st_size


def test_interrupted_write_leaves_no_trusted_entry(tmp_path, superelement, monkeypatch):
    # Superelement.save writes to a temporary file and renames it; an interruption while
    # writing leaves neither the data file nor a manifest, so the next run misses cleanly.
    def interrupted(stream, **arrays):
        stream.write(b"PK\x03\x04 partial")
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez_compressed", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_entry(tmp_path, "a" * 64, superelement, "rail")
    monkeypatch.undo()
    assert list(tmp_path.iterdir()) == []
    assert read_entry(tmp_path, "a" * 64) == (None, None)
    # data written but the manifest not yet (interrupted between the two renames)
    superelement.save(entry_paths(tmp_path, "b" * 64)[0])
    se, problem = read_entry(tmp_path, "b" * 64)
    assert se is None
    assert "no manifest" in problem
    assert isinstance(Superelement.load(entry_paths(tmp_path, "b" * 64)[0]), Superelement)
