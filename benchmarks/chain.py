"""Chain of N identical mechanisms: time vs N of the four eigen-methods at one drive angle.

A uniform main shaft (steel, d = 40 mm, 0.1 m per cell, ``chain(..., cells=True)``)
carries N follower units (cam hub 2e-3 kg m², follower 0.5 kg on 2e6 N/m, modified-sine
cam, stroke 30 mm), all in phase, its left end held by a drive coupling as stiff as one
shaft cell (a uniform "grounded-free" chain: every method applies). At the drive angle
φ = 60° (mid-rise, U' largest) the 10 lowest quasi-eigenfrequencies are computed,
side by side in one process, by

* ``assembled ARPACK``: the assembled sparse M, C (``Chain.sparse_matrices``) and
  scipy's ``eigsh`` (ARPACK, shift-invert at σ = -1 rad²/s², SuperLU factor of C - σM);
  the time includes the assembly;
* ``transfer``: :func:`femmech.chain.transfer.transfer_modes` (Wittrick–Williams count and
  bisection, rtol 1e-12), frequencies only, and ``transfer + vectors`` with the modes;
* ``cyclic``: :func:`femmech.chain.cyclic.cyclic_modes` (closed form per wave, all n
  roots, frequencies only);
* ``continuum``: :func:`femmech.chain.continuum.continuum_modes` (smeared model: its
  error is the model's, not round-off);
* ``dense eigh`` (reference): LAPACK on the assembled matrices, the 10 lowest
  (``subset_by_index``), while n <= DENSE_MAX; beyond it the reference is the transfer
  result.

Each time is the min and median of ``repeats`` runs after one warm-up run; errors are
max |f - f_ref| / f_ref over the 10 frequencies. The growth exponent p of time ~ N^p is
fitted (least squares in log-log) to each method's median times; the transfer method's
is the acceptance check (O(N): p ≈ 1).

Run: ``python benchmarks/chain.py [--sizes 10 30 100 300 1000 3000] [--repeats 3]``
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import time
from pathlib import Path

import numpy as np
import scipy
import scipy.linalg as sla
import scipy.sparse.linalg as spla

HERE = Path(__file__).resolve().parent
SIZES = (10, 30, 100, 300, 1000, 3000)
N_MODES = 10
PHI = np.radians(60.0)
DENSE_MAX = 2000
"""Largest assembled size n solved by dense eigh for the reference."""
SIGMA = -1.0
"""ARPACK shift, rad²/s² (below the lowest eigenvalue; C - σM is positive definite)."""


def build(n_units: int):
    """The benchmark chain with ``n_units`` units (see the module docstring)."""
    from femmech.chain import End, chain, follower_unit, torsion_segment
    from femmech.mechanisms import CamProfile, CamSegment, modified_sine

    cam = CamProfile((CamSegment(np.radians(120), 0.03, modified_sine()),
                      CamSegment(np.radians(60)),
                      CamSegment(np.radians(120), -0.03, modified_sine()),
                      CamSegment(np.radians(60))))
    unit = follower_unit(cam, 2e-3, 0.5, 2e6)
    k_cell = torsion_segment(0.1, 0.04)[0]
    return chain(unit, n_units, 0.1, 0.04, cells=True, left=End.elastic(k_cell))


def _arpack(ch, k):
    M, _, C = ch.sparse_matrices(PHI)
    lam = spla.eigsh(C.tocsc(), k=k, M=M.tocsc(), sigma=SIGMA, which="LM",
                     return_eigenvectors=False)
    return np.sqrt(np.sort(lam)) / (2 * np.pi)


def _dense(ch, k):
    M, _, C = ch.sparse_matrices(PHI)
    lam = sla.eigh(C.toarray(), M.toarray(), eigvals_only=True, subset_by_index=[0, k - 1])
    return np.sqrt(lam) / (2 * np.pi)


def methods() -> dict:
    """name -> f(chain, k) returning the k lowest frequencies (Hz), ascending."""
    from femmech.chain.continuum import continuum_modes
    from femmech.chain.cyclic import cyclic_modes
    from femmech.chain.transfer import transfer_modes

    return {
        "dense eigh": _dense,
        "assembled ARPACK": _arpack,
        "transfer": lambda ch, k: transfer_modes(ch, PHI, n_modes=k, vectors=False).freq_hz,
        "transfer + vectors": lambda ch, k: transfer_modes(ch, PHI, n_modes=k).freq_hz,
        "cyclic": lambda ch, k: cyclic_modes(ch, PHI, vectors=False).freq_hz[:k],
        "continuum": lambda ch, k: continuum_modes(ch, PHI, k, vectors=False, estimate=False,
                                                   warn=False).freq_hz,
    }


def _timed(fn, repeats: int):
    """(result, min s, median s) of ``repeats`` calls after one warm-up call."""
    result = fn()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return result, min(times), float(np.median(times))


def run(sizes=SIZES, repeats: int = 3, n_modes: int = N_MODES, skip=None) -> list:
    """One row per (N, method): time, error against the reference, reference name.

    ``skip(name, N) -> bool`` leaves out a method at a size (too slow)."""
    table = methods()
    rows = []
    for N in sizes:
        ch = build(N)
        found = {}
        for name, fn in table.items():
            if (name == "dense eigh" and ch.n > DENSE_MAX) or (skip and skip(name, N)):
                continue
            f, t_min, t_med = _timed(lambda fn=fn, ch=ch: fn(ch, n_modes), repeats)
            found[name] = (np.asarray(f, dtype=float), t_min, t_med)
        ref_name = "dense eigh" if "dense eigh" in found else "transfer"
        f_ref = found[ref_name][0]
        for name, (f, t_min, t_med) in found.items():
            err = np.nan if name == ref_name else float(np.max(np.abs(f / f_ref - 1)))
            rows.append({"N": N, "n": ch.n, "method": name, "min_s": t_min,
                         "median_s": t_med, "max_rel_error": err, "reference": ref_name,
                         "f_lowest_hz": float(f[0]), "f_highest_hz": float(f[-1])})
    return rows


def growth_exponents(rows) -> dict:
    """method -> fitted p of median time ~ N^p (at least 3 sizes; else absent)."""
    out = {}
    for name in dict.fromkeys(r["method"] for r in rows):
        pts = [(r["N"], r["median_s"]) for r in rows if r["method"] == name]
        if len(pts) >= 3:
            N, t = np.log(np.array(pts, dtype=float)).T
            out[name] = float(np.polyfit(N, t, 1)[0])
    return out


def _cpu() -> str:
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.partition(":")[2].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def header(load_start) -> list[str]:
    """Machine, versions and thread settings for the top of the table."""
    from femmech.solve import threads

    mem_gib = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    loads = [", ".join(f"{x:.1f}" for x in v) for v in (load_start, os.getloadavg())]
    return [
        f"benchmark: chain eigen-methods vs N, {datetime.datetime.now():%Y-%m-%d %H:%M}",
        f"machine: {_cpu()}, {os.cpu_count()} CPUs, {mem_gib:.0f} GiB RAM,"
        f" {platform.system()} {platform.release()}",
        f"load average (1, 5, 15 min): at start {loads[0]}; at end {loads[1]}",
        f"versions: python {platform.python_version()}, numpy {np.__version__},"
        f" scipy {scipy.__version__}",
        "solvers: dense = scipy.linalg.eigh (LAPACK, subset_by_index); ARPACK ="
        f" scipy.sparse.linalg.eigsh(sigma={SIGMA:g}, which='LM') with SuperLU",
        threads.describe(),
    ]


def report(rows, load_start, n_modes: int = N_MODES) -> str:
    lines = header(load_start)
    lines += ["", f"{n_modes} lowest quasi-eigenfrequencies at φ = {np.degrees(PHI):.0f}°;"
              " time: min / median of the repeats after a warm-up",
              f"{'N':>6s} {'n':>6s}  {'method':20s} {'min (s)':>10s} {'median (s)':>10s}"
              f" {'max rel. err':>12s}  reference   f1 … f{n_modes} (Hz)"]
    for r in rows:
        err = "(reference)" if np.isnan(r["max_rel_error"]) else f"{r['max_rel_error']:.2e}"
        lines.append(f"{r['N']:6d} {r['n']:6d}  {r['method']:20s} {r['min_s']:10.4f}"
                     f" {r['median_s']:10.4f} {err:>12s}  {r['reference']:10s}"
                     f"  {r['f_lowest_hz']:.4g} … {r['f_highest_hz']:.4g}")
    lines += ["", "growth exponent p of the median time ~ N^p (least squares, log-log):"]
    for name, p in growth_exponents(rows).items():
        note = "  <- O(N) shows as p ≈ 1" if name == "transfer" else ""
        lines.append(f"  {name:20s} p = {p:.2f}{note}")
    return "\n".join(lines)


def main(sizes=SIZES, repeats: int = 3, n_modes: int = N_MODES, out_file=None,
         echo: bool = True) -> list:
    """Run the benchmark, print and write the table; return the rows (dicts)."""
    load_start = os.getloadavg()
    rows = run(sizes, repeats, n_modes)
    text = report(rows, load_start, n_modes)
    if echo:
        print(text)
    if out_file is not None:
        Path(out_file).parent.mkdir(parents=True, exist_ok=True)
        Path(out_file).write_text(text + "\n")
    return rows


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=list(SIZES))
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    main(tuple(args.sizes), args.repeats, out_file=HERE / "results" / "chain.txt")
