"""Benchmark: wall and CPU time of ``femmech check`` against ``femmech run`` per scene.

Each command runs in a fresh interpreter (``python -m femmech ...``), as a user starts it,
so the times include every import. Per scene it prints, for ``check`` and ``run``
(``--no-cache -q`` into a temporary folder), the min / median wall time and the CPU time
(user + system of the child, from ``resource.getrusage``) over ``--repeats`` interleaved
runs, the load average before and after (a busy machine inflates wall times: compare
CPU), and the imports of ``check`` that took longest (``python -X importtime``,
cumulative, top ``--top``).

``check`` validates a scene without computing: it must import neither the rendering stack
(pyvista, vtk, matplotlib) nor the solvers' front ends (tests/test_cli.py,
``test_check_imports_no_rendering_and_no_solver``, checks that structurally; the times
are measured only here).

Usage::

    python benchmarks/check_time.py [--scenes examples/press_frame.toml ...] [--repeats N]
                                    [--top N] [--no-run]

Results are printed and written to ``benchmarks/results/check_time.txt``.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SCENES = ("examples/press_frame.toml", "examples/frame_modes.toml")


def timed(argv: list[str]) -> tuple[float, float]:
    """(wall s, CPU s of the child) of one command run from the repository root."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed ({done.returncode}): {done.stderr.strip()}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def top_imports(scene: str, n: int) -> list[tuple[float, str]]:
    """The ``n`` imports of ``femmech check scene`` with the largest cumulative time (s)."""
    done = subprocess.run([sys.executable, "-X", "importtime", "-m", "femmech", "check", scene],
                          cwd=ROOT, capture_output=True, text=True, check=True)
    rows = []
    for line in done.stderr.splitlines():
        if not line.startswith("import time:") or "cumulative" in line:
            continue
        _, cumulative, name = line.split("|")
        depth = (len(name) - len(name.lstrip())) // 2
        if depth <= 1:  # the top-level imports and what they import directly
            rows.append((int(cumulative) * 1e-6, name.rstrip()))
    return sorted(rows, reverse=True)[:n]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", default=list(DEFAULT_SCENES))
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--top", type=int, default=12)
    parser.add_argument("--no-run", action="store_true", help="time only check")
    args = parser.parse_args(argv)
    lines = [f"femmech check vs run, fresh interpreter each, {args.repeats} repeats;"
             f" load average at start {os.getloadavg()[0]:.2f}"]
    lines.append(f"{'scene':>28}  {'command':>7}  {'wall s min / median':>20}"
                 f"  {'CPU s min / median':>19}")
    with tempfile.TemporaryDirectory() as tmp:
        for scene in args.scenes:
            commands = {"check": [sys.executable, "-m", "femmech", "check", scene]}
            if not args.no_run:
                commands["run"] = [sys.executable, "-m", "femmech", "run", scene, "--out",
                                   str(Path(tmp) / Path(scene).stem), "--no-cache", "-q"]
            times = {name: [] for name in commands}
            for _ in range(args.repeats):  # interleaved: a load change hits both alike
                for name, command in commands.items():
                    times[name].append(timed(command))
            for name, measured in times.items():
                wall, cpu = zip(*measured, strict=True)
                lines.append(f"{Path(scene).name:>28}  {name:>7}  {min(wall):9.2f} /"
                             f" {statistics.median(wall):8.2f}  {min(cpu):8.2f} /"
                             f" {statistics.median(cpu):8.2f}")
            lines.append("  top imports of check (cumulative s): " + ", ".join(
                f"{name.strip()} {t:.2f}" for t, name in top_imports(scene, args.top)))
    lines.append(f"load average at end {os.getloadavg()[0]:.2f}")
    text = "\n".join(lines)
    print(text)
    out = ROOT / "benchmarks" / "results"
    out.mkdir(exist_ok=True)
    (out / "check_time.txt").write_text(text + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
