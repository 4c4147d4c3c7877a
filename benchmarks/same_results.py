"""Check that two revisions of femmech compute the same results, to the bit.

A change that only moves code (a package restructure) must not change a
single number. This script runs every example scene (``examples/*.toml``, through the
CLI) and every example script (``examples/*.py --out``) once with the working tree and
once with a git revision (checked out into a temporary worktree, imported through
``PYTHONPATH``), each in its own process with every library on one thread (so that the
order of floating-point sums is the same), and compares what they wrote:

* data files (``.csv``, ``.json``, ``.vtu``, ``.xdmf``, ``.h5``, ``.npz``) byte for
  byte, except the run manifest ``.femmech-run.json`` (it holds the time of the run);
* text files (``.txt``) and what each script printed, with durations (``12.3 ms``,
  ``0.5 s``: :data:`DURATION`) and the output folder's path replaced by placeholders;
* the arrays of :data:`PROBE`: the solver paths the examples do not take (every installed
  sparse backend, the dense path, bands, free-free, LOBPCG, Craig-Bampton with and
  without residual vectors, Guyan), through the public API only, so that the same code
  runs on both revisions.

Images and the HTML report are not compared: the report states run times and versions.

Usage::

    python benchmarks/same_results.py --against 9b9c9e1     # working tree vs a revision
    python benchmarks/same_results.py --collect DIR          # only write this tree's results

Prints one line per compared file and exits 1 if anything differs.
"""

from __future__ import annotations

import argparse
import filecmp
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DATA_SUFFIXES = {".csv", ".json", ".vtu", ".xdmf", ".h5", ".npz"}
TEXT_SUFFIXES = {".txt", ".stdout"}
SKIP_NAMES = {".femmech-run.json"}
DURATION = re.compile(r"\d+(\.\d*)?(e[-+]?\d+)?\s*(ms|s|min)\b")
ONE_THREAD = {"FEMMECH_THREADS": "1", "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
              "MKL_NUM_THREADS": "1"}


PROBE = """
import sys
import numpy as np
import femmech as fm
from femmech import generators, sections
from femmech.reduction import craig_bampton, guyan
out = {}
mesh = generators.grid_frame((3, 2, 2), (3.0, 2.0, 2.0), subdivisions=3)
steel = fm.Material(E=210e9, nu=0.3, rho=7850.0)
beam = fm.BeamProperty(sections.rectangular_hollow(0.1, 0.1, 0.005), steel)
free = fm.build_model(mesh, {name: beam for name in mesh.cell_sets})
base = np.flatnonzero(mesh.points[:, 2] == 0.0)
held = fm.build_model(mesh, {name: beam for name in mesh.cell_sets}, supports=[fm.Support(base)])
for name, A in (("K", held.K), ("M", held.M)):
    out[name + "_data"], out[name + "_indices"] = A.data, A.indices
for solver in ("superlu", "cholmod", "pardiso"):
    try:
        r = fm.modes(held, n_modes=12, solver=solver)
    except ImportError:
        continue
    out[f"{solver}_omega2"], out[f"{solver}_shapes"] = r.omega2, r.shapes
out["band"] = fm.modes(held, band_hz=(10.0, 60.0)).omega2
out["free"] = fm.modes(free, n_modes=10).omega2
out["lobpcg"] = fm.modes(held, n_modes=6, method="lobpcg").omega2
top = np.flatnonzero(mesh.points[:, 2] == mesh.points[:, 2].max())[:2]
for name, se in (("cb", craig_bampton(held, top, n_modes=15)),
                 ("cb_residual", craig_bampton(held, top, f_max_hz=80.0, residual_vectors=True)),
                 ("guyan", guyan(held, top))):
    out[name + "_K"], out[name + "_M"] = se.K, se.M
np.savez(sys.argv[1], **out)
"""
"""Solver paths through the public API (``femmech`` top level and its ``generators`` and
``sections``, ``femmech.reduction``); written to ``probe.npz`` and compared byte for byte."""


def _env(tree: Path, cache: Path) -> dict[str, str]:
    env = dict(os.environ, **ONE_THREAD)
    env["PYTHONPATH"] = str(tree)
    env["FEMMECH_CACHE_DIR"] = str(cache)
    env["MPLBACKEND"] = "Agg"
    return env


def collect(tree: Path, out: Path) -> None:
    """Run the examples of ``tree`` with the femmech of ``tree``; write into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as cache:
        env = _env(tree, Path(cache))
        check = subprocess.run([sys.executable, "-c", "import femmech; print(femmech.__file__)"],
                               env=env, cwd=tree, capture_output=True, text=True, check=True)
        if not Path(check.stdout.strip()).is_relative_to(tree):
            raise SystemExit(f"femmech imported from {check.stdout.strip()}, not from {tree}")
        probe = subprocess.run([sys.executable, "-c", PROBE, str(out / "probe.npz")], env=env,
                               cwd=tree, capture_output=True, text=True)
        print(f"  ran probe: exit {probe.returncode}", flush=True)
        if probe.returncode:
            (out / "probe.stdout").write_text(probe.stderr)
        for scene in sorted((tree / "examples").glob("*.toml")):
            _run([sys.executable, "-m", "femmech", "run", str(scene), "--allow-code",
                  "--out", str(out / f"scene_{scene.stem}"), "-q"], env, tree,
                 out / f"scene_{scene.stem}.stdout")
        for script in sorted((tree / "examples").glob("*.py")):
            _run([sys.executable, str(script), "--out", str(out / f"script_{script.stem}")],
                 env, tree, out / f"script_{script.stem}.stdout")


def _run(command, env, cwd, stdout_file: Path) -> None:
    result = subprocess.run(command, env=env, cwd=cwd, capture_output=True, text=True)
    text = result.stdout.replace(str(stdout_file.parent), "<out>")
    stdout_file.write_text(f"exit {result.returncode}\n{text}")
    print(f"  ran {Path(command[1] if command[1] != '-m' else command[4]).name}: "
          f"exit {result.returncode}", flush=True)


def compare(reference: Path, candidate: Path) -> int:
    """Print one line per data file; return the number of differences."""
    names = {p.relative_to(reference) for p in reference.rglob("*") if _compared(p)}
    names |= {p.relative_to(candidate) for p in candidate.rglob("*") if _compared(p)}
    differences = 0
    for name in sorted(names):
        a, b = reference / name, candidate / name
        if not a.exists() or not b.exists():
            verdict = "only in " + ("candidate" if b.exists() else "reference")
        else:
            verdict = "identical" if _same(a, b) else "DIFFERENT"
        differences += verdict != "identical"
        print(f"{verdict:>20}  {name}")
    return differences


def _same(a: Path, b: Path) -> bool:
    if a.suffix not in TEXT_SUFFIXES:
        return filecmp.cmp(a, b, shallow=False)
    return _normalised(a) == _normalised(b)


def _normalised(path: Path) -> str:
    """Text with durations replaced (they differ from run to run)."""
    return DURATION.sub("<duration>", path.read_text(encoding="utf-8", errors="replace"))


def _compared(path: Path) -> bool:
    return (path.is_file() and path.name not in SKIP_NAMES
            and path.suffix in DATA_SUFFIXES | TEXT_SUFFIXES)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", metavar="REV", help="git revision to compare with")
    parser.add_argument("--collect", metavar="DIR", type=Path,
                        help="only write this tree's results into DIR")
    parser.add_argument("--keep", metavar="DIR", type=Path,
                        help="write both result folders here instead of a temporary folder")
    args = parser.parse_args(argv)
    if args.collect:
        collect(ROOT, args.collect)
        return 0
    if not args.against:
        parser.error("give --against REV or --collect DIR")
    with tempfile.TemporaryDirectory() as tmp:
        base = args.keep or Path(tmp)
        worktree = Path(tmp) / "reference_tree"
        subprocess.run(["git", "worktree", "add", "--detach", str(worktree), args.against],
                       cwd=ROOT, check=True, capture_output=True)
        try:
            print(f"reference: {args.against}")
            collect(worktree, base / "reference")
            print("candidate: working tree")
            collect(ROOT, base / "candidate")
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(worktree)], cwd=ROOT,
                           check=False, capture_output=True)
        differences = compare(base / "reference", base / "candidate")
    print(f"{differences} difference(s)")
    return 1 if differences else 0


if __name__ == "__main__":
    sys.exit(main())
