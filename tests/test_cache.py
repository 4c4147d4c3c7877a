"""Reduction cache of scene runs: reuse, invalidation of exactly the affected entries,
detection of corrupted entries; a cache that never breaks a run: unreadable,
unwritable, full, corrupt or foreign, shared by processes, size-limited.
Asserted through the run log and the warnings, never timing."""

import errno
import json
import multiprocessing
import os
import re
import shutil
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest
from filelock import FileLock

import femmech
import femmech.reduction as reduction
import femmech.scene.cache as cache_module
import femmech.scene.cache_folder as cache_folder
from femmech.errors import CacheWarning
from femmech.reduction.component_modes import guyan
from femmech.reduction.superelement import Superelement
from femmech.scene.build import reduction_key_data, sha256_key
from femmech.scene.cache import cached_reduction, read_entry, write_entry
from femmech.scene.cache_folder import (
    STALE_AGE,
    cache_info,
    cache_max_bytes,
    clear_cache,
    entry_paths,
    format_cache_info,
    lock_path,
    remove_stale_temporaries,
)
from femmech.scene.load import Scene
from femmech.scene.run import run_scene

ROOT = Path(__file__).resolve().parent.parent

# Two reduced parts joined at the four top joints of the base (assembled superelements),
# with a cam mechanism on the rail's mid node (on the rail's interface: mechanisms mount
# at interface nodes only) and the base's top: a sweep needs both.
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
interface = [{ nodes = "a" }, { nodes = "b" }, { nodes = "mid" }]  # mid: the cam's node

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
        found = re.match(r"cache (hit|miss|corrupt, rebuilt|not stored|off): part '(\w+)'",
                         line)
        if found:
            out[found[2]] = {"corrupt, rebuilt": "corrupt", "not stored": "unstored"}.get(
                found[1], found[1])
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
    # the CacheWarning, logged by the run (scene_run.logged_warnings): folder, entry, problem
    warning = next(x for x in result.log if x.startswith("warning:"))
    assert f"reduction cache {cache}: entry {rail_key}" in warning
    assert "recomputed and stored" in warning
    assert (tmp_path / "out" / "results.json").read_bytes() == \
        (base / "run1" / "results.json").read_bytes()
    # the rebuilt entry is trusted again
    again = run_scene(_scene(), tmp_path / "again", cache_dir=cache)
    assert _statuses(again) == {"base": "hit", "rail": "hit"}


# --- the cache functions on their own -----------------------------------------------------

@pytest.fixture(scope="module")
def superelement():
    from femmech.scene.build import part_mesh, part_model

    scene = _scene()
    part = scene.parts["rail"]
    return guyan(part_model(scene, part, part_mesh(scene, part)), ["a", "b"])


def test_cached_reduction_builds_once(tmp_path, superelement):
    calls, log = [], []

    def build():
        calls.append(1)
        return superelement

    first = cached_reduction(tmp_path, "c" * 64, "rail", build, log.append)
    second = cached_reduction(tmp_path, "c" * 64, "rail", build, log.append)
    off = cached_reduction(None, "c" * 64, "rail", build, log.append)
    assert (first.status, second.status, off.status) == ("miss", "hit", "off")
    assert len(calls) == 2
    assert [x.split(":")[0] for x in log] == ["cache miss", "cache hit", "cache off"]
    np.testing.assert_array_equal(second.superelement.K, superelement.K)
    manifest = json.loads(entry_paths(tmp_path, "c" * 64)[1].read_text())
    assert manifest["size"] == entry_paths(tmp_path, "c" * 64)[0].stat().st_size


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


# --- a cache that never breaks a run ---------------------------------------------

KEY = "d" * 64


def _key(i: int) -> str:
    return f"{i:064x}"


def _builder(se, calls=None):
    def build():
        if calls is not None:
            calls.append(1)
        return se
    return build


def _same(se, other) -> None:
    # bit-exact: the cache stores the arrays losslessly (npz), or returns the built object
    np.testing.assert_array_equal(se.K, other.K)
    np.testing.assert_array_equal(se.M, other.M)
    np.testing.assert_array_equal(se.interface_dofs, other.interface_dofs)


def _leftovers(folder: Path) -> list[str]:
    """Temporary files and entry parts in ``folder`` (lock files are expected to stay)."""
    return sorted(p.name for p in folder.iterdir() if p.suffix != ".lock")


class _DeniedLock:
    """A FileLock whose lock file cannot be created (read-only folder)."""

    def __init__(self, path, timeout=-1):
        self.path = path

    def acquire(self):
        raise PermissionError(errno.EACCES, "Permission denied", str(self.path))


def _read_only(monkeypatch) -> None:
    """Every write to the cache fails as in a read-only folder (we run as root, so chmod
    would not stop the writes)."""
    def denied(self, path):
        raise PermissionError(errno.EACCES, "Permission denied", str(path))

    monkeypatch.setattr(cache_module, "FileLock", _DeniedLock)
    monkeypatch.setattr(cache_folder, "FileLock", _DeniedLock)
    monkeypatch.setattr(Superelement, "save", denied)


def test_read_only_cache_is_read_and_never_written(tmp_path, superelement, monkeypatch):
    cached_reduction(tmp_path, KEY, "rail", _builder(superelement), print)
    _read_only(monkeypatch)
    calls = []
    with pytest.warns(CacheWarning, match=r"reduction cache .*: entry dddddddddddd \(rail\):"
                                         r" cannot lock, going on without \(PermissionError"):
        hit = cached_reduction(tmp_path, KEY, "rail", _builder(superelement, calls), print)
    assert (hit.status, calls) == ("hit", [])
    _same(hit.superelement, superelement)
    log = []
    with pytest.warns(CacheWarning, match=r"cannot store \(PermissionError.*recomputed, not"
                                         " stored"):
        got = cached_reduction(tmp_path, _key(1), "rail", _builder(superelement, calls),
                               log.append)
    assert (got.status, calls) == ("unstored", [1])
    assert got.superelement is superelement
    assert log[0].startswith("cache not stored: rail (")
    assert _leftovers(tmp_path) == [f"{KEY}.json", f"{KEY}.npz"]


@pytest.mark.parametrize("where", ["parent is a file", "folder is a file"])
def test_cache_path_that_is_a_file(tmp_path, superelement, where):
    (tmp_path / "file").write_text("not a folder")
    folder = tmp_path / "file" / "cache" if where == "parent is a file" else tmp_path / "file"
    with pytest.warns(CacheWarning, match=f"reduction cache {re.escape(str(folder))}: .*"
                                          "cannot create the folder"):
        got = cached_reduction(folder, KEY, "rail", _builder(superelement), print)
    assert got.status == "unstored"
    assert got.superelement is superelement
    assert [p.name for p in tmp_path.iterdir()] == ["file"]


def _full_disk_in_data(monkeypatch):
    def full(stream, **arrays):
        stream.write(b"PK\x03\x04 partial")
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(np, "savez_compressed", full)


def _full_disk_in_manifest(monkeypatch):
    def full(self, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(self))

    monkeypatch.setattr(Path, "write_text", full)


@pytest.mark.parametrize("fail", [_full_disk_in_data, _full_disk_in_manifest])
def test_full_disk_leaves_no_half_entry_and_no_temporaries(tmp_path, superelement,
                                                           monkeypatch, fail):
    fail(monkeypatch)
    with pytest.warns(CacheWarning, match=r"cannot store \(OSError: \[Errno 28\] No space"):
        got = cached_reduction(tmp_path, KEY, "rail", _builder(superelement), print)
    monkeypatch.undo()
    assert got.status == "unstored"
    _same(got.superelement, superelement)
    assert _leftovers(tmp_path) == []
    assert cached_reduction(tmp_path, KEY, "rail", _builder(superelement), print).status == \
        "miss"


def _manifest_for(data_path: Path, key: str) -> None:
    """A manifest that vouches for whatever ``data_path`` holds (size and SHA-256 right)."""
    manifest = {"key": key, "size": data_path.stat().st_size,
                "sha256": cache_module.sha256_file(data_path)}
    data_path.with_suffix(".json").write_text(json.dumps(manifest))


def _foreign_manifest(folder, data_path, manifest_path):
    other = _key(7)
    shutil.copy(data_path, folder / f"{other}.npz")
    _manifest_for(folder / f"{other}.npz", other)
    shutil.copy(folder / f"{other}.json", manifest_path)  # names key 7, not KEY


def _garbage(folder, data_path, manifest_path):
    data_path.write_bytes(os.urandom(3000))
    _manifest_for(data_path, KEY)


def _other_npz(folder, data_path, manifest_path):
    with open(data_path, "wb") as stream:  # a valid npz, but no superelement
        np.savez(stream, K=np.eye(3), meta=np.array("{}"))
    _manifest_for(data_path, KEY)


FOREIGN = {"manifest of another key": (_foreign_manifest, "manifest of another entry"),
           "garbage bytes": (_garbage, "not a valid superelement file"),
           "valid npz of something else": (_other_npz, "not a valid superelement file")}


@pytest.mark.parametrize("how", list(FOREIGN))
def test_foreign_or_corrupt_entry_is_rebuilt(tmp_path, superelement, how):
    spoil, reason = FOREIGN[how]
    cached_reduction(tmp_path, KEY, "rail", _builder(superelement), print)
    spoil(tmp_path, *entry_paths(tmp_path, KEY))
    calls = []
    with pytest.warns(CacheWarning, match=f"entry {KEY[:12]} \\(rail\\): {reason}"):
        got = cached_reduction(tmp_path, KEY, "rail", _builder(superelement, calls), print)
    assert (got.status, calls) == ("corrupt", [1])
    _same(got.superelement, superelement)
    again = cached_reduction(tmp_path, KEY, "rail", _builder(superelement, calls), print)
    assert (again.status, calls) == ("hit", [1])
    _same(again.superelement, superelement)


def test_temporaries_of_a_killed_run_are_removed(tmp_path, superelement):
    # the names Superelement.save (mkstemp) and atomic_path give their temporary files
    killed = [tmp_path / f".{_key(1)}.npz.x7kq_2ab.npz",
              tmp_path / f".{_key(1)}.0a1b2c3d4e5f.tmp.json"]
    writing = tmp_path / f".{_key(2)}.npz.busy0001.npz"  # a write in progress elsewhere
    hung = tmp_path / f".{_key(3)}.npz.hung0001.npz"  # its writer holds the lock for hours
    foreign = [tmp_path / "notes.txt", tmp_path / ".hidden"]
    for path in (*killed, writing, hung, *foreign):
        path.write_bytes(b"partial")
    old = time.time() - 2 * STALE_AGE
    os.utime(hung, (old, old))
    other_process = [FileLock(lock_path(tmp_path, k)) for k in (_key(2), _key(3))]
    for lock in other_process:
        lock.acquire()
    try:
        assert cache_info(tmp_path).stale_temporaries == 3
        got = cached_reduction(tmp_path, KEY, "rail", _builder(superelement), print)
    finally:
        for lock in other_process:
            lock.release()
    assert got.status == "miss"
    assert all(p.exists() for p in (writing, *foreign))
    assert not any(p.exists() for p in (*killed, hung))
    assert remove_stale_temporaries(tmp_path) == 1  # the writer has gone
    assert not writing.exists()


def test_lock_timeout_builds_without_storing(tmp_path, superelement):
    holder = FileLock(lock_path(tmp_path, KEY))
    holder.acquire()
    try:
        with pytest.warns(CacheWarning, match=r"held by another process for more than 0.2 s"):
            got = cached_reduction(tmp_path, KEY, "rail", _builder(superelement), print,
                                   lock_timeout=0.2)
    finally:
        holder.release()
    assert got.status == "unstored"
    assert got.superelement is superelement
    assert _leftovers(tmp_path) == []


def _two_process_worker(folder: str, source: str, marker: str, index: int):
    """Ask for KEY once both workers are ready; the build counts itself in ``marker``."""
    Path(folder, f"ready-{index}").touch()
    deadline = time.monotonic() + 60
    while len(list(Path(folder).glob("ready-*"))) < 2 and time.monotonic() < deadline:
        time.sleep(0.01)

    def build():
        with open(marker, "a") as stream:
            stream.write(f"{index}\n")
        time.sleep(0.5)  # long enough for the other worker to arrive and wait
        return Superelement.load(source)

    got = cached_reduction(Path(folder) / "cache", KEY, "rail", build, lambda line: None)
    return got.status, got.superelement.K, got.superelement.M


def test_two_processes_build_once(tmp_path, superelement):
    source = superelement.save(tmp_path / "source.npz")
    marker = tmp_path / "builds.txt"
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        results = pool.starmap(_two_process_worker,
                               [(str(tmp_path), str(source), str(marker), i) for i in (0, 1)])
    assert len(marker.read_text().split()) == 1
    assert sorted(status for status, _, _ in results) == ["hit", "miss"]
    for _, K, M in results:
        np.testing.assert_array_equal(K, superelement.K)
        np.testing.assert_array_equal(M, superelement.M)


def test_least_recently_used_entries_are_evicted(tmp_path, superelement):
    for i in (1, 2, 3):
        cached_reduction(tmp_path, _key(i), "rail", _builder(superelement), print)
        os.utime(entry_paths(tmp_path, _key(i))[1], (1000.0 * i, 1000.0 * i))
    size = cache_info(tmp_path).total_bytes // 3
    assert cached_reduction(tmp_path, _key(1), "rail", _builder(superelement), print
                            ).status == "hit"  # entry 1 is now the most recently used
    log = []
    cached_reduction(tmp_path, _key(4), "rail", _builder(superelement), log.append,
                     max_bytes=int(2.5 * size))
    assert log[1].startswith("cache evicted: 2 least recently used entries")
    assert sorted(p.stem for p in tmp_path.glob("*.json")) == [_key(1), _key(4)]
    # the entry just written stays, whatever the limit
    cached_reduction(tmp_path, _key(5), "rail", _builder(superelement), print, max_bytes=0)
    assert [p.stem for p in tmp_path.glob("*.npz")] == [_key(5)]
    assert cache_info(tmp_path, max_bytes=0).entries == 1


def test_cache_info_and_clear(tmp_path, superelement, monkeypatch):
    monkeypatch.setenv("FEMMECH_CACHE_MAX_BYTES", "1G")
    for i in (1, 2):
        cached_reduction(tmp_path, _key(i), "rail", _builder(superelement), print)
    superelement.save(entry_paths(tmp_path, _key(3))[0])  # no manifest: interrupted
    (tmp_path / f".{_key(4)}.npz.x7kq_2ab.npz").write_bytes(b"partial")  # killed run
    (tmp_path / "notes.txt").write_text("mine")
    (tmp_path / "sub").mkdir()
    info = cache_info(tmp_path)
    sizes = sum(p.stat().st_size for p in tmp_path.iterdir()
                if p.suffix in (".npz", ".json") and not p.name.startswith("."))
    assert (info.entries, info.incomplete, info.stale_temporaries, info.foreign_files) == \
        (2, 1, 1, 2)
    assert (info.total_bytes, info.max_bytes) == (sizes, 1024**3)
    assert info.oldest_use <= info.newest_use
    text = format_cache_info(info)
    assert text.splitlines()[0] == f"reduction cache {tmp_path}"
    for part in ("2 entries", "of 1.0 GiB", "1 incomplete", "1 temporary", "2 other files"):
        assert part in text
    in_use = FileLock(lock_path(tmp_path, _key(2)))
    in_use.acquire()
    try:
        removed = clear_cache(tmp_path)
    finally:
        in_use.release()
    assert removed == 2 + 1 + 1 + 1  # entry 1 + its lock, the incomplete one, the temporary
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["notes.txt", "sub", f"{_key(2)}.npz", f"{_key(2)}.json", f"{_key(2)}.lock"])
    assert clear_cache(tmp_path) == 3
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt", "sub"]
    assert cache_info(tmp_path / "none").entries == 0


@pytest.mark.parametrize(("text", "expected"), [("123", 123), ("500M", 500 * 1024**2),
                                                ("2GiB", 2 * 1024**3), ("", 2 * 1024**3)])
def test_size_limit_from_the_environment(monkeypatch, text, expected):
    monkeypatch.setenv("FEMMECH_CACHE_MAX_BYTES", text)
    assert cache_max_bytes() == expected
    assert cache_max_bytes(10) == 10


def test_unreadable_size_limit_warns_and_uses_the_default(monkeypatch):
    monkeypatch.setenv("FEMMECH_CACHE_MAX_BYTES", "lots")
    with pytest.warns(CacheWarning, match="FEMMECH_CACHE_MAX_BYTES='lots'"):
        assert cache_max_bytes() == cache_folder.DEFAULT_MAX_BYTES


# --- the key: every setting that changes a reduction ----------------------------------------

def _rail(d):
    return d["parts"]["rail"]


KEY_CHANGES = {
    "material E": lambda d: d["materials"]["aluminium"].update(E="69 GPa"),
    "material rho": lambda d: d["materials"]["aluminium"].update(rho="2600 kg/m^3"),
    "material nu": lambda d: d["materials"]["aluminium"].update(nu=0.32),
    "section size": lambda d: _rail(d)["sections"]["rail"].update(outer_diameter="41 mm"),
    "section shape": lambda d: _rail(d)["sections"].update(
        rail={"section": "circle", "diameter": "40 mm", "material": "aluminium"}),
    "section material": lambda d: _rail(d)["sections"]["rail"].update(material="steel"),
    "section orientation": lambda d: _rail(d)["sections"]["rail"].update(
        orientation=[0.0, 1.0, 0.0]),
    "shear": lambda d: _rail(d)["sections"]["rail"].update(shear=False),
    "rotary inertia": lambda d: _rail(d)["sections"]["rail"].update(rotary_inertia=False),
    "joint position": lambda d: _rail(d)["generator"]["joints"].update(mid=[0.4, 0.0, 0.8]),
    "divisions": lambda d: _rail(d)["generator"]["members"][0].update(divisions=3),
    "merge_nodes": lambda d: _rail(d).update(merge_nodes="1 mm"),
    "edge_node_groups": lambda d: _rail(d).update(edge_node_groups=["rail"]),
    "support": lambda d: _rail(d).update(supports=[{"nodes": "mid", "dofs": ["ux"]}]),
    "point mass": lambda d: _rail(d).update(masses=[{"node": "mid", "mass": "1 kg"}]),
    "spring": lambda d: _rail(d).update(springs=[{"node_a": "mid", "stiffness": "1e6 N/m"}]),
    "rigid link": lambda d: _rail(d).update(rigid_links=[{"master": "a", "slaves": "mid"}]),
    "interface nodes": lambda d: _rail(d)["reduction"]["interface"].append({"nodes": "mid"}),
    "interface dofs": lambda d: _rail(d)["reduction"]["interface"][0].update(
        dofs=["ux", "uy", "uz"]),
    "n_modes": lambda d: _rail(d)["reduction"].update(n_modes=2),
    "cutoff_hz": lambda d: _rail(d)["reduction"].update(n_modes=None, cutoff_hz=500.0),
    "f_max_hz": lambda d: _rail(d)["reduction"].update(n_modes=None, f_max_hz=500.0),
    "residual vectors": lambda d: _rail(d)["reduction"].update(residual_vectors=False),
    "method": lambda d: _rail(d)["reduction"].update(method="guyan", n_modes=None,
                                                    residual_vectors=False),
}

KEY_KEEPS = {
    "scene name": lambda d: d["scene"].update(name="renamed"),
    "material not used": lambda d: d["materials"]["steel"].update(E="200 GPa"),
    "another part": lambda d: d["parts"]["base"]["generator"].update(subdivisions=3),
    "analyses": lambda d: d["analyses"]["sweep"].update(n_modes=3),
    "mechanism": lambda d: d["mechanisms"]["cam"]["parameters"].update(m="3 kg"),
}


def _rail_key(mutate=None, f_max_hz=None) -> str:
    def change(d):
        if mutate is not None:
            mutate(d)
        reduction = _rail(d)["reduction"]
        for name in [k for k, v in reduction.items() if v is None]:
            del reduction[name]

    scene = _scene(change)
    return sha256_key(reduction_key_data(scene, scene.parts["rail"], f_max_hz))


@pytest.mark.parametrize("change", list(KEY_CHANGES))
def test_every_reduction_setting_changes_the_key(change):
    assert _rail_key(KEY_CHANGES[change]) != _rail_key()


@pytest.mark.parametrize("change", list(KEY_KEEPS))
def test_settings_outside_the_reduction_keep_the_key(change):
    assert _rail_key(KEY_KEEPS[change]) == _rail_key()


def test_key_includes_version_format_and_the_size_override():
    data = reduction_key_data(_scene(), _scene().parts["rail"])
    assert data["femmech"] == femmech.__version__
    assert data["format"] == reduction.FORMAT_VERSION
    assert data["cutoff_factor"] == reduction.CUTOFF_FACTOR
    assert _rail_key(f_max_hz=100.0) != _rail_key(f_max_hz=200.0) != _rail_key()
    # the part's name is not part of its key: the same part under another name is a hit
    renamed = _scene(lambda d: d["parts"].update(guide=d["parts"]["rail"]))
    assert sha256_key(reduction_key_data(renamed, renamed.parts["guide"])) == _rail_key()
