"""Shared pieces of the peer comparisons (benchmarks/run.py, ``--suite peers``).

Every target table compares femmech with the tool a user would run instead, on the same
matrices, in the same process, with the minimum and the median of ``repeats`` runs of each
side and the ratio of the minima (the minimum is the least disturbed run on a shared
machine; the median shows the spread). An *idle baseline* (:func:`idle_baseline`: a fixed
dense and sparse workload, timed before and after a table) tells how busy the machine was:
if the two baselines differ by more than ~20 %, the absolute times of that table are
suspect, the ratios much less so (both sides ran interleaved).

Models: grid space frames of steel hollow beams (benchmarks/solvers.py) at ~5k, ~24k and
~151k free DOFs (:func:`frame`) and a hexahedral steel block (:func:`solid`).
"""

from __future__ import annotations

import argparse
import gc
import statistics
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import femmech as fm
from femmech.fe.generators import grid_frame

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from solvers import BAY, SECTION, STEEL, solid_block  # noqa: E402  (sibling benchmark)

# name: (bays, subdivisions) of grid_frame; free DOFs in the comment
FRAMES = {
    "1k": ((2, 2, 2), 4),      # 1 080 (tiny: smoke test)
    "5k": ((3, 3, 3), 7),      # 5 472
    "24k": ((5, 5, 5), 8),     # 23 760
    "151k": ((9, 9, 9), 10),   # 151 200
}
SOLIDS = {"solid35k": (40, 16, 16)}  # 34 680 free DOFs, hexahedra, clamped at x = 0


def frame(name: str) -> fm.FEModel:
    """The grid space frame ``name`` of :data:`FRAMES`, supported at its base nodes."""
    bays, subdivisions = FRAMES[name]
    mesh = grid_frame(bays, tuple(BAY * b for b in bays), subdivisions)
    prop = fm.BeamProperty(SECTION, STEEL)
    return fm.build_model(mesh, dict.fromkeys(mesh.cell_sets, prop),
                          supports=[fm.Support("base")])


def solid(name: str = "solid35k") -> fm.FEModel:
    """The hexahedral steel block ``name`` of :data:`SOLIDS` (denser factors than frames)."""
    return solid_block(*SOLIDS[name])


@dataclass
class Timing:
    """Wall times (s) of repeated runs of one side; ``value`` is the last run's result."""

    times: list[float] = field(default_factory=list)
    value: object = None

    @property
    def min(self) -> float:
        return min(self.times)

    @property
    def median(self) -> float:
        return statistics.median(self.times)

    def cell(self, scale: float = 1.0, spec: str = ".3f") -> str:
        """``min / median`` formatted, times multiplied by ``scale`` (1e3 for ms)."""
        return f"{self.min * scale:{spec}} / {self.median * scale:{spec}}"


def repeat(func, repeats: int = 3, warmup: bool = False) -> Timing:
    """Run ``func()`` ``repeats`` times (after one untimed run if ``warmup``)."""
    if warmup:
        func()
    timing = Timing()
    for _ in range(repeats):
        gc.collect()
        start = time.perf_counter()
        timing.value = func()
        timing.times.append(time.perf_counter() - start)
    return timing


def interleaved(funcs: dict, repeats: int = 3, warmup: bool = False) -> dict[str, Timing]:
    """Time several sides round-robin (a, b, a, b, ...), so that a load change on the
    shared machine hits both sides alike. Returns {name: Timing}."""
    if warmup:
        for func in funcs.values():
            func()
    out = {name: Timing() for name in funcs}
    for _ in range(repeats):
        for name, func in funcs.items():
            gc.collect()
            start = time.perf_counter()
            out[name].value = func()
            out[name].times.append(time.perf_counter() - start)
    return out


def _baseline_work() -> None:
    rng = np.random.default_rng(0)
    A = rng.standard_normal((300, 300))
    scipy.linalg.eigh(A + A.T)
    n = 120  # 2D Laplacian, 14 400 unknowns, SuperLU
    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    L = (sp.kron(sp.eye(n), T) + sp.kron(T, sp.eye(n))).tocsc()
    spla.splu(L).solve(np.ones(n * n))


def idle_baseline(repeats: int = 5) -> Timing:
    """Time a fixed workload (a 300x300 dense eigh and a 14 400-unknown sparse LU and
    solve): its minimum is the machine's undisturbed speed, the median its load."""
    return repeat(_baseline_work, repeats, warmup=True)


def baseline_line(before: Timing, after: Timing) -> str:
    drift = after.median / before.median - 1
    return (f"idle baseline (fixed workload, ms min / median of 5): before"
            f" {before.cell(1e3, '.1f')}, after {after.cell(1e3, '.1f')}"
            f" ({drift:+.0%} median drift{'; machine load changed' if abs(drift) > 0.2 else ''})")


def table(title: str, header: list[str], rows: list[list[str]]) -> list[str]:
    """A fixed-width text table with a title line."""
    widths = [max(len(str(h)), *(len(str(r[i])) for r in rows)) if rows else len(str(h))
              for i, h in enumerate(header)]
    def line(cells):
        return "  ".join(str(c).rjust(w) for c, w in zip(cells, widths, strict=True))
    return [title, line(header), line(["-" * w for w in widths]), *map(line, rows), ""]


def verdict(ratio: float, target: float, at_most: bool = True) -> str:
    """'met' / 'missed' for a ratio against its target (<= target, or >= if not at_most)."""
    ok = ratio <= target if at_most else ratio >= target
    return "met" if ok else "MISSED"


def cli(main, sizes, doc: str) -> None:
    """The command line of a peer benchmark module: ``--size`` (a key of ``sizes``) and
    ``--repeats``; prints the table lines of ``main(size, repeats)``."""
    parser = argparse.ArgumentParser(description=doc.split("\n")[0])
    parser.add_argument("--size", choices=tuple(sizes), default="small")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    print("\n".join(main(args.size, args.repeats)[0]))
