"""Superelement files and reduction cache entries that are no regular files.

A FIFO blocked ``Superelement.load`` forever (open() waits for a writer) and a symbolic
link to /dev/zero ended in MemoryError; each is now one FileFormatError line naming the
file. Every load runs in a subprocess with a timeout, so that a regression fails instead
of hanging the suite.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT = 60.0  # s: the loads below take well under 1 s; a hang runs into it

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs POSIX FIFOs")

LOAD = """
import sys
from femmech.errors import FileFormatError
from femmech.reduction.superelement import Superelement
try:
    Superelement.load(sys.argv[1])
except FileFormatError as exc:
    print("FileFormatError:", exc)
"""

CACHE = """
import sys, warnings
from femmech.scene.cache import read_entry
print("reason:", read_entry(sys.argv[1], sys.argv[2])[1])
"""


def _run(code: str, *args) -> str:
    """stdout of ``code`` run with femmech from this checkout (fails on a timeout)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    done = subprocess.run([sys.executable, "-c", code, *map(str, args)], capture_output=True,
                          text=True, timeout=TIMEOUT, env=env, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout.strip()


@pytest.mark.parametrize(("make", "kind"), [
    (os.mkfifo, "a FIFO (named pipe)"),
    (lambda p: os.symlink("/dev/zero", p), "a character device (a symbolic link to /dev/zero)"),
    (os.mkdir, "a directory"),
])
def test_load_refuses_what_is_no_regular_file(tmp_path, make, kind):
    if "zero" in kind and not Path("/dev/zero").exists():
        pytest.skip("no /dev/zero")
    path = tmp_path / "frame.npz"
    make(path)
    out = _run(LOAD, path)
    assert out == (f"FileFormatError: {path}: not a readable superelement file: it is {kind},"
                   " not a regular file; a superelement file must be a regular file")


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
    out = _run(LOAD, path)
    assert out.startswith(f"FileFormatError: {path}: not a readable superelement file: the"
                          " file has ")
    assert "it holds data that is no member" in out


@pytest.mark.parametrize("which", ["manifest", "data"])
def test_the_cache_refuses_a_fifo_entry(tmp_path, which):
    """A cache entry whose manifest or data file is a FIFO is reported as unreadable
    (the cache then rebuilds), not waited for."""
    from femmech.scene.cache_folder import entry_paths

    key = "ab" * 32
    data, manifest = entry_paths(tmp_path, key)
    if which == "manifest":
        data.write_bytes(b"x")
        os.mkfifo(manifest)
        expected = (f"reason: unreadable manifest (FileFormatError: {manifest}: not a"
                    " readable cache manifest: it is a FIFO")
    else:
        os.mkfifo(data)
        manifest.write_text(json.dumps({"key": key, "size": 0, "sha256": "0" * 64}))
        expected = (f"reason: not a valid superelement file (FileFormatError: {data}: not a"
                    " readable cache entry: it is a FIFO")
    out = _run(CACHE, tmp_path, key)
    assert out.startswith(expected), out


def test_the_cache_refuses_a_manifest_linked_to_dev_zero(tmp_path):
    if not Path("/dev/zero").exists():
        pytest.skip("no /dev/zero")
    from femmech.scene.cache_folder import entry_paths

    key = "cd" * 32
    data, manifest = entry_paths(tmp_path, key)
    data.write_bytes(b"x")
    os.symlink("/dev/zero", manifest)
    out = _run(CACHE, tmp_path, key)
    assert out.startswith(f"reason: unreadable manifest (FileFormatError: {manifest}: not a"
                          " readable cache manifest: it is a character device (a symbolic"
                          " link to /dev/zero)"), out
