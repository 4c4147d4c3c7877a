"""Files that are no regular files where femmech expects one: each hostile kind (a FIFO, a
symbolic link to /dev/zero, a directory, an oversized file, a symbolic link to a regular
file) in the place of each file femmech reads (a reduction cache entry's ``.npz``, its
manifest ``.json``, a superelement file given to ``Superelement.load``, an output folder's
manifest ``.femmech-run.json``).

A FIFO blocked the reader forever (open() waits for a writer), a link to /dev/zero ended in
MemoryError or an endless read. Now: the cache gives one CacheWarning naming the entry and
recomputes (and stores the result in place of a FIFO, link or oversized file, never
writing through a link); ``Superelement.load`` raises one FileFormatError line ``<path>:
not a readable superelement file: ...`` but reads a link to a regular file (the user named
it); an output folder whose manifest is no regular file (a link included) is refused with
one InputError line and left untouched. Every case runs in a subprocess with a timeout, so
that a regression fails instead of hanging the suite.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT = 60.0  # s: each case takes a few s (import, a small reduction); a hang runs into it

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo") or not Path("/dev/zero").exists(),
                                reason="needs POSIX FIFOs and /dev/zero")

KINDS = ["fifo", "zero", "directory", "oversized", "link"]
# The quick run (-m "not slow") keeps the two kinds that used to hang or exhaust memory;
# the full run (the README's test command) checks every kind.
CACHE_KINDS = [k if k in ("fifo", "zero") else pytest.param(k, marks=pytest.mark.slow)
               for k in KINDS]

HARNESS = r"""
import json, os, shutil, sys, warnings
from pathlib import Path
import femmech as fm
from femmech.errors import FemmechWarning, FileFormatError, InputError
from femmech.fe import generators, sections
from femmech.reduction.component_modes import craig_bampton
from femmech.reduction.superelement import Superelement

target, kind, tmp = sys.argv[1], sys.argv[2], Path(sys.argv[3])
CAPS = {"cache manifest": 1 << 20, "output manifest": 64 << 20}


def superelement():
    mesh = generators.grid_frame((1, 1, 1), (1.0, 1.0, 1.0), 2)
    prop = fm.BeamProperty(sections.circle(0.03), fm.Material(E=210e9, nu=0.3, rho=7850.0))
    model = fm.build_model(mesh, {g: prop for g in mesh.cell_sets},
                           supports=[fm.Support("base")])
    return craig_bampton(model, "top", n_modes=2)


def spoil(path, good):
    # put the hostile kind in the place of path; good: a valid regular copy elsewhere
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    elif os.path.lexists(path):
        path.unlink()
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "zero":
        os.symlink("/dev/zero", path)
    elif kind == "directory":
        path.mkdir()
    elif kind == "link":
        os.symlink(good, path)
    else:  # oversized: the valid bytes, then zeros up to one byte over the cap (sparse)
        shutil.copyfile(good, path)
        cap = CAPS.get(target, good.stat().st_size + (2 << 20))
        os.truncate(path, cap + 1)


result = {}
if target in ("cache entry", "cache manifest"):
    from femmech.scene.cache import cached_reduction, read_entry, write_entry
    from femmech.scene.cache_folder import entry_paths
    se, key, folder = superelement(), "ab" * 32, tmp / "cache"
    write_entry(folder, key, se, "frame")
    path = entry_paths(folder, key)[0 if target == "cache entry" else 1]
    good = tmp / ("good" + path.suffix)
    shutil.copyfile(path, good)
    shutil.copyfile(path, tmp / "reference")
    spoil(path, good)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        done = cached_reduction(folder, key, "frame", lambda: se, log=lambda line: None)
    result["status"] = done.status
    result["warnings"] = [f"{w.category.__name__}: {w.message}" for w in caught]
    result["regular_after"] = path.is_file() and not path.is_symlink()
    result["hit_after"] = read_entry(folder, key)[0] is not None
    result["good_unchanged"] = good.read_bytes() == (tmp / "reference").read_bytes()
elif target == "superelement file":
    se = superelement()
    good = se.save(tmp / "good.npz")
    path = tmp / "frame.npz"
    spoil(path, good)
    try:
        result["loaded"] = Superelement.load(path).n_reduced == se.n_reduced
    except FileFormatError as exc:
        result["error"] = f"FileFormatError: {exc}"
else:  # output manifest
    from femmech.output.folder import MANIFEST, staged_output
    out = tmp / "out"
    with staged_output(out) as stage:
        (stage / "report.html").write_text("r1")
    (out / "mine.txt").write_text("mine")
    good = tmp / "good.json"
    shutil.copyfile(out / MANIFEST, good)
    spoil(out / MANIFEST, good)
    try:
        with staged_output(out) as stage:
            (stage / "report.html").write_text("r2")
        result["ran"] = True
    except InputError as exc:
        result["error"] = f"InputError: {exc}"
    result["report"] = (out / "report.html").read_text()
    result["mine"] = (out / "mine.txt").read_text()
    result["siblings"] = sorted(p.name for p in tmp.iterdir() if ".femmech-" in p.name)
print(json.dumps(result))
"""


def _case(tmp_path: Path, target: str, kind: str) -> dict:
    """The harness's result for ``kind`` in the place of ``target`` (fails on a timeout)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    done = subprocess.run([sys.executable, "-c", HARNESS, target, kind, str(tmp_path)],
                          capture_output=True, text=True, timeout=TIMEOUT, env=env, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def _what_it_is(kind: str, tmp_path: Path, good: str, what: str) -> str:
    """The expected 'it is ...' part of the message for a hostile kind."""
    return {"fifo": f"it is a FIFO (named pipe), not a regular file; {what} must be a"
                    " regular file",
            "zero": "it is a symbolic link to /dev/zero, not a regular file; femmech does"
                    f" not follow links in the place of {what}",
            "directory": f"it is a directory, not a regular file; {what} must be a regular"
                         " file",
            "link": f"it is a symbolic link to {tmp_path / good}, not a regular file;"
                    f" femmech does not follow links in the place of {what}"}[kind]


@pytest.mark.parametrize("kind", CACHE_KINDS)
@pytest.mark.parametrize("target", ["cache entry", "cache manifest"])
def test_a_hostile_cache_file_warns_and_recomputes(tmp_path, target, kind):
    result = _case(tmp_path, target, kind)
    (message,) = result["warnings"]
    key = "ab" * 32
    path = tmp_path / "cache" / (key + (".npz" if target == "cache entry" else ".json"))
    assert message.startswith(f"CacheWarning: reduction cache {tmp_path / 'cache'}: entry"
                              f" {key[:12]} (frame): "), message
    if kind == "oversized" and target == "cache entry":
        assert "manifest says" in message, message
        assert "(appended to?)" in message
    elif kind == "oversized":
        assert (f"{path}: not a readable cache manifest: it has {(1 << 20) + 1} bytes, more"
                f" than a cache manifest may have ({1 << 20})") in message
    else:
        it_is = _what_it_is(kind, tmp_path, "good" + path.suffix, "a " + target)
        assert f"{path}: not a readable {target}: {it_is}" in message
    if kind == "directory":  # femmech does not remove a folder it did not make
        assert result["status"] == "unstored"
        assert message.endswith("; recomputed, not stored"), message
        assert "cannot store (IsADirectoryError" in message
    else:  # the FIFO, link or oversized file is replaced by a valid entry (not written through)
        assert result["status"] == "corrupt"
        assert message.endswith("; recomputed and stored"), message
        assert result["regular_after"]
        assert result["hit_after"]


def test_a_linked_cache_entry_is_replaced_not_written_through(tmp_path):
    """The rebuilt entry replaces the link; the file the link pointed to is unchanged."""
    result = _case(tmp_path, "cache entry", "link")
    assert result["status"] == "corrupt"
    assert result["good_unchanged"]
    assert result["regular_after"]


@pytest.mark.parametrize("kind", KINDS)
def test_load_refuses_what_is_no_regular_file_but_follows_a_link(tmp_path, kind):
    result = _case(tmp_path, "superelement file", kind)
    path = tmp_path / "frame.npz"
    head = f"FileFormatError: {path}: not a readable superelement file: "
    if kind == "link":  # a file the user names may be a link
        assert result == {"loaded": True}
    elif kind == "oversized":
        assert result["error"].startswith(head), result
    elif kind == "zero":  # followed: what it points to is named
        assert result["error"] == (head + "it is a character device (a symbolic link to"
                                   " /dev/zero), not a regular file; a superelement file must"
                                   " be a regular file")
    else:
        assert result["error"] == head + _what_it_is(kind, tmp_path, "", "a superelement file")


@pytest.mark.parametrize("kind", KINDS)
def test_an_output_folder_with_a_hostile_manifest_is_refused_untouched(tmp_path, kind):
    result = _case(tmp_path, "output manifest", kind)
    out = tmp_path / "out"
    manifest = out / ".femmech-run.json"
    if kind == "oversized":
        what = (f"{manifest}: not a readable output-folder manifest: it has {(64 << 20) + 1}"
                f" bytes, more than an output-folder manifest may have ({64 << 20})")
    else:
        what = (f"{manifest}: not a readable output-folder manifest: "
                + _what_it_is(kind, tmp_path, "good.json", "an output-folder manifest"))
    assert result["error"] == (f"InputError: --out {out}: the folder is not empty and was not"
                               f" written by femmech ({what}); give a new or empty folder"
                               " (femmech replaces the files of its previous run there, and"
                               " never touches others)")
    assert result["report"] == "r1"
    assert result["mine"] == "mine"
    assert result["siblings"] == []


def test_load_refuses_a_file_padded_far_beyond_its_members(tmp_path):
    """A valid superelement file with 2 MiB put before it (zipfile accepts leading data,
    as of self-extracting archives; more than ZIP_TAIL allows) is refused naming the
    sizes; the file as written loads."""
    import femmech as fm
    from femmech.fe import generators, sections
    from femmech.reduction.component_modes import craig_bampton
    from femmech.reduction.superelement import Superelement

    mesh = generators.grid_frame((1, 1, 1), (1.0, 1.0, 1.0), 2)
    prop = fm.BeamProperty(sections.circle(0.03), fm.Material(E=210e9, nu=0.3, rho=7850.0))
    model = fm.build_model(mesh, {g: prop for g in mesh.cell_sets},
                           supports=[fm.Support("base")])
    path = craig_bampton(model, "top", n_modes=2).save(tmp_path / "se.npz")
    assert Superelement.load(path).n_reduced > 0
    path.write_bytes(b"\0" * (2 << 20) + path.read_bytes())
    out = _run_load(path)
    assert out.startswith(f"FileFormatError: {path}: not a readable superelement file: the"
                          " file has ")
    assert "it holds data that is no member" in out


LOAD = """
import sys
from femmech.errors import FileFormatError
from femmech.reduction.superelement import Superelement
try:
    Superelement.load(sys.argv[1])
except FileFormatError as exc:
    print("FileFormatError:", exc)
"""


def _run_load(path: Path) -> str:
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    done = subprocess.run([sys.executable, "-c", LOAD, str(path)], capture_output=True,
                          text=True, timeout=TIMEOUT, env=env, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout.strip()
