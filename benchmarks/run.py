"""Benchmark suites: femmech against its peers, femmech's own stages against their targets.

One table file per entry.

Usage::

    python benchmarks/run.py [--suite peers|components] [--size tiny|small|medium|large]
                             [--repeats N] [--only NAME ...] [--out DIR] [--blas-threads N]

The default suite ``peers`` prints one table per performance target, each with femmech and
the tool a user would run instead on the same matrices in the same process (min / median
of ``--repeats`` interleaved runs per side, the ratio of the minima, the error of each side,
a verdict against the target, and an idle baseline before and after; benchmarks/peers.py):

- ``t1_eigensolve``: ``fm.modes(model, 20)`` (Sturm-checked) vs scipy ``eigsh`` with each
  installed factorisation (peer_eigensolve.py);
- ``t2_craig_bampton``: Craig-Bampton (n_b = 48, 30 modes + residual vectors) vs one full
  20-mode eigensolve (peer_craig_bampton.py);
- ``t3_interface``: interface reduction of ~1 000-DOF interfaces vs one full solve, with
  the coupled-frequency error against plain Craig-Bampton (peer_interface.py);
- ``t4_sweep``: the reduced coupled sweep per angle, tracked, vs bare LAPACK generalized
  eigensolves of the same pencils (peer_sweep.py);
- ``t5_monodromy``: a stability-chart point (monodromy with error control) vs
  ``solve_ivp`` DOP853 at the same accuracy of the spectral radius (peer_monodromy.py);
- ``t6_end_to_end``: reduction + 360-angle coupled sweep + error estimate vs 360 full
  coupled ARPACK solves (peer_end_to_end.py);
- ``t6_memory``: peak memory of reducing a ~1M-DOF MITC4 shell box, in a child process
  (peer_memory.py; no peer: the 8 GB target is absolute);
- ``t7_exudyn``: Craig-Bampton vs Exudyn's Hurty-Craig-Bampton (peer_exudyn.py).

The ``components`` suite times femmech's own stages against their targets (below). The
old suite names ``issue10`` (= ``components``) and ``issue24`` (= ``peers``) still work,
with a deprecation message.

Runs the entries below one after the other in this process, prints a table per entry and
writes it to ``benchmarks/results/<name>.txt`` (atomically). Every table starts with the
same header: machine (CPU, cores, memory, load average at start and end of the entry),
library versions (numpy, scipy, scikit-fem, femmech, MKL/PARDISO, scikit-sparse, exudyn)
and the solver and thread settings (:mod:`femmech.solve.direct`, :mod:`femmech.solve.threads`).

Entries of the ``components`` suite (each reuses the ``main`` of a benchmark module in this folder):

- ``assembly``: ``build_model`` split into element matrices, COO → CSR, Tᵀ K T, and its
  ratio to one 20-mode eigensolve of the same frame (frame_modes.py);
- ``eigensolve``: full 20-mode eigensolve per installed sparse solver (solvers.py);
- ``craig_bampton``: Craig-Bampton reduction split into factorisation, constraint modes,
  fixed-interface modes and projection, against a full eigensolve (craig_bampton.py);
- ``reduced_sweep``: reduced coupled sweep over 360 and 3600 angles, r <= 100
  (coupled_sweep.py without the full solves);
- ``coupled``: full coupled vs reduced coupled per angle, with the error (coupled_sweep.py);
- ``exudyn_hcb``: femmech's Craig-Bampton against Exudyn's Hurty-Craig-Bampton on the same
  K, M and interface (exudyn_hcb.py; reported as not installed without ``exudyn``);
- ``scale``: the shell/beam machine bed built, Craig-Bampton reduced, coupled with four
  cams and swept over 360 angles, with time and peak memory per phase and one full coupled
  check (scale.py: 1 788 / 61 008 / 242 952 / 969 720 DOFs for tiny / small / medium /
  large).

Sizes: ``tiny`` (smoke test, seconds), ``small`` (~20k-DOF frames, a few minutes),
``medium`` (20k and 150k-DOF frames, the 59k-free-DOF shell bed in the eigensolve entry),
``large`` (adds the 1M-DOF frame to the assembly entry, the solid block to the eigensolve
entry and the 1M-DOF machine bed to the scale entry).
"""

from __future__ import annotations

import argparse
import datetime
import importlib
import importlib.metadata
import os
import platform
import sys
import time
import traceback
import warnings
from contextlib import nullcontext
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy
from threadpoolctl import threadpool_limits

import femmech as fm
from femmech.output.export import atomic_path
from femmech.solve import direct, threads
from femmech.solve.pardiso import mkl_version

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def _sibling(name: str):
    """The benchmark module ``name`` of this folder (not a same-named module loaded before,
    e.g. examples/frame_modes.py); siblings import each other by these names."""
    module = sys.modules.get(name)
    if module is None or Path(getattr(module, "__file__", "") or "").resolve() \
            != HERE / f"{name}.py":
        sys.modules.pop(name, None)
        module = importlib.import_module(name)
    return module


frame_modes = _sibling("frame_modes")  # first: solvers.py imports from it
solver_bench = _sibling("solvers")
craig_bampton = _sibling("craig_bampton")
exudyn_hcb = _sibling("exudyn_hcb")
coupled_sweep = _sibling("coupled_sweep")
scale = _sibling("scale")

RESULTS = HERE / "results"
SIZES = ("tiny", "small", "medium", "large")
ASSEMBLY_TARGET = 0.2  # target: assembly <= 20 % of one full eigensolve
SWEEP_TARGET_S = 0.5  # target: 360 angles with vectors, r <= 100, <= 0.5 s
# Craig-Bampton bases beside the default (f_max 400 Hz + residual vectors) in `coupled`:
# (f_max_hz, residual_vectors); the band's highest mode is ~160 Hz (12 cams)
REDUCTION_VARIANTS = ((400.0, True), (400.0, False), (100.0, False))


# --- header ---------------------------------------------------------------------------

def _version(dist: str) -> str:
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return "not installed"


def _cpu() -> tuple[str, int]:
    """(CPU model name, physical cores) from /proc/cpuinfo (platform fallbacks)."""
    name, cores = platform.processor() or platform.machine(), set()
    try:
        with open("/proc/cpuinfo") as fh:
            block = {}
            for line in list(fh) + [""]:
                if not line.strip():
                    if "core id" in block:
                        cores.add((block.get("physical id"), block["core id"]))
                    block = {}
                    continue
                key, _, value = line.partition(":")
                block[key.strip()] = value.strip()
                if key.strip() == "model name":
                    name = value.strip()
    except OSError:
        pass
    return name, len(cores) or os.cpu_count() or 1


def header(name: str, size: str, load_start, blas_threads) -> list[str]:
    """Machine, versions, solver and thread settings, for the top of every table."""
    cpu, cores = _cpu()
    mem_gib = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else "?"
    loads = [", ".join(f"{x:.1f}" for x in v) for v in (load_start, os.getloadavg())]
    pardiso = mkl_version() if "pardiso" in direct.available() else None
    exudyn = exudyn_hcb.exudyn_version()
    env = ", ".join(f"{k}={os.environ[k]}" for k in (
        "FEMMECH_THREADS", "FEMMECH_SOLVER", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS",
        "MKL_NUM_THREADS") if k in os.environ) or "no thread/solver variables set"
    auto_large = direct.resolve("auto", direct.AUTO_MIN_SIZE)
    auto_small = direct.resolve("auto", direct.AUTO_MIN_SIZE - 1)
    return [
        f"benchmark: {name} (suite size {size}), {datetime.datetime.now():%Y-%m-%d %H:%M}",
        f"machine: {cpu}, {cores} cores / {os.cpu_count()} CPUs ({usable} usable),"
        f" {mem_gib:.0f} GiB RAM, {platform.system()} {platform.release()}",
        f"load average (1, 5, 15 min): at start {loads[0]}; at end {loads[1]}"
        " (a shared machine: times scale with the load, ratios are from one process)",
        f"versions: python {platform.python_version()}, numpy {np.__version__}, scipy"
        f" {scipy.__version__}, scikit-fem {_version('scikit-fem')}, femmech"
        f" {getattr(fm, '__version__', _version('femmech'))}, mkl {_version('mkl')}"
        f" (PARDISO {'available' if pardiso else 'not available'}), scikit-sparse"
        f" {_version('scikit-sparse')}, exudyn {exudyn or 'not installed'}",
        f"solvers: installed {', '.join(direct.available())}; default"
        f" '{direct.default_solver()}' ('auto' takes {auto_large} from"
        f" {direct.AUTO_MIN_SIZE:,} unknowns, {auto_small} below); "
        + "; ".join(f"{k}: {v}" for k, v in direct.versions().items()),
        threads.describe(),
        f"suite BLAS limit: {blas_threads or 'none (--blas-threads)'}; environment: {env}",
        ""]


# --- entries --------------------------------------------------------------------------

def _fmt(value, spec, missing="-"):
    return missing if value is None else format(value, spec)


def entry_assembly(size):
    cases = {"tiny": (["tiny"], ["tiny"]), "small": (["20k"], []),
             "medium": (["20k", "150k"], []),
             "large": (["150k", "large"], ["100k-elements"])}[size]
    rows = frame_modes.main(cases=cases, references=False, out_file=None, echo=False)
    modal = [r for r in rows if r["table"] == "modes"]
    for r in modal:
        r["build_over_eigen"] = r["build_s"] / r["eigen_s"]
    lines = frame_modes.format_tables(rows)
    lines += frame_modes._table(
        f"Assembly vs one full eigensolve (target: build_model <= {ASSEMBLY_TARGET:.0%} of"
        " femmech.modes(20))",
        ["case", "free DOFs", "build_model s", "eigen s", "build / eigen"],
        [[r["case"], f"{r['free_dofs']:,}", f"{r['build_s']:.3f}", f"{r['eigen_s']:.3f}",
          f"{r['build_over_eigen']:.2f}"] for r in modal])
    return lines, rows


def entry_eigensolve(size):
    sizes = {"tiny": ("tiny",), "small": ("20k",), "medium": ("20k", "150k", "shell"),
             "large": ("20k", "150k", "shell", "solid")}[size]
    rows = solver_bench.main(sizes=sizes, out_file=None, echo=False)
    return solver_bench.format_tables(rows), rows


def _frames(size):
    return {"tiny": ("tiny",), "small": ("20k",)}.get(size, ("20k", "150k"))


def entry_craig_bampton(size):
    rows = craig_bampton.main(sizes=_frames(size), out_file=None, echo=False)
    return craig_bampton.format_tables(rows), rows


def _band(n_cams):
    """Modes followed on the textile shaft: the lowest, the cluster of the N cam followers'
    modes (equal cams in phase: within 0.1 % of each other) and the next one. A count that
    cuts the cluster made the full reference solve stall (ARPACK, > 10 min at 20k DOFs)."""
    return n_cams + 2


def entry_reduced_sweep(size):
    n_cams, angles = (4, (36, 360)) if size == "tiny" else (12, (360, 3600))
    rows = []
    for n_angles in angles:
        for vectors in (True, False):
            row = coupled_sweep.main(n_cams=n_cams, n_angles=n_angles, n_check=0,
                                     n_modes=_band(n_cams), keep_vectors=vectors)
            rows.append(row)
    lines = [[str(r["n_cams"]), str(r["n_reduced"]), f"{r['n_angles']:,}",
              "yes" if r["keep_vectors"] else "no", str(r["n_modes"]), f"{r['sweep_s']:.3f}",
              f"{r['sweep_per_angle_ms']:.3f}"] for r in rows]
    table = frame_modes._table(
        "Reduced coupled sweep (textile shaft with N cams, Craig-Bampton + residual vectors,"
        f" N + 2 modes tracked, solve-phase BLAS threads {threads.settings().solve or 'all'})",
        ["cams N", "coordinates r", "angles", "vectors", "modes", "sweep s", "ms/angle"], lines)
    return table + [f"target: 360 angles with vectors, r <= 100, <= {SWEEP_TARGET_S}"
                    " s", ""], rows


def entry_coupled(size):
    # (cams, FE elements between cams, checked angles): FE free DOFs ~ 12 (N + 1) P
    plans = {"tiny": [(4, 2, 2)], "small": [(12, 128, 5)],
             "medium": [(12, 128, 5), (12, 960, 3)], "large": [(12, 128, 5), (12, 960, 5)]}
    n_angles = 36 if size == "tiny" else 360
    rows = [coupled_sweep.main(n_cams=n, n_angles=n_angles, n_check=k, per_spacing=p,
                               n_modes=_band(n), keep_vectors=True, n_arpack=1,
                               variants=REDUCTION_VARIANTS)
            for n, p, k in plans[size]]
    lines = []
    for r in rows:
        per = r["per_angle"]
        for a, phi in enumerate(per["phi"]):
            full_ms = 1e3 * per["full_s"][a]
            lines.append([f"{r['fe_free_dofs']:,}", str(r["n_full"]), str(r["n_reduced"]),
                          f"{np.rad2deg(phi):.1f}", f"{full_ms:.1f}",
                          f"{r['sweep_per_angle_ms']:.3f}",
                          f"{full_ms / r['sweep_per_angle_ms']:.0f}x",
                          f"{per['max_rel_error'][a]:.1e}", f"{per['min_mac'][a]:.8f}"])
    table = frame_modes._table(
        "Full coupled (sparse shift-invert Lanczos + Sturm) vs reduced coupled (sweep, per"
        " angle), textile shaft with 12 cams (4 on tiny)",
        ["FE free DOFs", "full n", "reduced r", "angle deg", "full ms", "reduced ms/angle",
         "speedup", "max |df|/f", "min MAC"], lines)
    notes = [f"reduced ms/angle: the tracked sweep over {n_angles} angles with vectors,"
             f" divided by the angles; errors and MAC (by order) over the {rows[0]['n_modes']}"
             " lowest modes (the lowest, the N cam followers' cluster, the next one);"
             " target: >= 10 000x at ~150k DOFs with <= 1e-3 error.",
             *(f"FE {r['fe_free_dofs']:,} free DOFs: build {r['build_s']:.2f} s (reduction"
               f" {r['reduction_s']:.2f} s), mean full {r['full_per_angle_ms']:.1f} ms,"
               f" speedup {r['speedup']:.0f}x, max error {r['max_rel_error']:.1e}"
               for r in rows), ""]
    table += frame_modes._table(
        "Reference: full coupled solve by scipy eigsh (ARPACK, shift-invert at"
        " femmech's shift on the same backend, tol 0) vs femmech's full solve, one angle",
        ["FE free DOFs", "full n", "angle deg", "femmech full s", "ARPACK s", "ARPACK solves",
         "max |dλ|/λ", "reduced ms/angle", "speedup vs ARPACK"],
        [[f"{r['fe_free_dofs']:,}", str(r["n_full"]), f"{np.rad2deg(a['phi']):.1f}",
          f"{a['femmech_s']:.2f}", f"{a['arpack_s']:.2f}", str(a["arpack_solves"]),
          f"{a['max_rel_diff']:.1e}", f"{r['sweep_per_angle_ms']:.3f}",
          f"{1e3 * a['arpack_s'] / r['sweep_per_angle_ms']:.0f}x"]
         for r in rows for a in r["arpack"]])
    table += frame_modes._table(
        "Speed against error of the reduced model: Craig-Bampton bases of the same machine"
        " (the rows above: f_max 400 Hz + residual vectors); ms/angle of the 360-angle sweep"
        " with vectors, tracked and untracked (the per-angle solves alone); speedup = mean"
        " full coupled solve (femmech) / reduced ms",
        ["FE free DOFs", "f_max Hz", "res. vectors", "r", "reduce s", "tracked ms",
         "untracked ms", "speedup tracked", "speedup untracked", "max |df|/f"],
        [[f"{r['fe_free_dofs']:,}", f"{v['f_max_hz']:g}",
          "yes" if v["residual_vectors"] else "no", str(v["n_reduced"]),
          f"{v['reduction_s']:.2f}", f"{v['tracked_ms']:.3f}", f"{v['untracked_ms']:.3f}",
          f"{r['full_per_angle_ms'] / v['tracked_ms']:.0f}x",
          f"{r['full_per_angle_ms'] / v['untracked_ms']:.0f}x", f"{v['max_rel_error']:.1e}"]
         for r in rows for v in r["variants"]])
    for r in rows:  # arrays -> lists, for the caller's checks
        r["per_angle"] = {k: np.asarray(v).tolist() for k, v in r["per_angle"].items()}
    return table + notes, rows


def entry_exudyn_hcb(size):
    if exudyn_hcb.exudyn_version() is None:
        return exudyn_hcb.not_installed_lines(), []
    rows = exudyn_hcb.main(sizes=_frames(size), out_file=None, echo=False)
    lines = exudyn_hcb.format_tables(rows)
    for case in dict.fromkeys(r["case"] for r in rows):
        pair = [r for r in rows if r["case"] == case]
        best = min(r["exudyn_s"] for r in pair) / min(r["femmech_s"] for r in pair)
        lines.append(f"{case}: best Exudyn time / best femmech time (over the thread"
                     f" settings) = {best:.1f}x (target: >= 2x at ~20k, >= 5x at"
                     " ~150k DOFs)")
    return lines + [""], rows


def entry_scale(size):
    row = scale.main(size, n_check=1, out_file=None, echo=False)
    return scale.format_report(row, header=False) + [""], [row]


PEER_TARGETS = {  # one table per target, femmech beside the peer a user would run
    "t1_eigensolve": "peer_eigensolve",
    "t2_craig_bampton": "peer_craig_bampton",
    "t3_interface": "peer_interface",
    "t4_sweep": "peer_sweep",
    "t5_monodromy": "peer_monodromy",
    "t6_end_to_end": "peer_end_to_end",
    "t6_memory": "peer_memory",
    "t7_exudyn": "peer_exudyn",
}
REPEATS = 3  # min / median of this many runs per side (--repeats)


def _peer_entry(module_name: str):
    def entry(size):
        return _sibling(module_name).main(size, repeats=REPEATS)
    entry.__name__ = f"entry_{module_name}"
    return entry


PEERS = {name: _peer_entry(module) for name, module in PEER_TARGETS.items()}

COMPONENTS = {
    "assembly": entry_assembly,
    "eigensolve": entry_eigensolve,
    "craig_bampton": entry_craig_bampton,
    "reduced_sweep": entry_reduced_sweep,
    "coupled": entry_coupled,
    "exudyn_hcb": entry_exudyn_hcb,
    "scale": entry_scale,
}
SUITES = {"peers": PEERS, "components": COMPONENTS}
SUITE_ALIASES = {"issue10": "components", "issue24": "peers"}
"""Old suite names → current ones (deprecated; they still run, with a message)."""
ENTRIES = {**PEERS, **COMPONENTS}


def suite_name(suite: str) -> str:
    """The current name of ``suite``; an old name gives a DeprecationWarning naming the
    new one."""
    if suite in SUITE_ALIASES:
        new = SUITE_ALIASES[suite]
        warnings.warn(f"benchmark suite {suite!r} is deprecated; use {new!r}"
                      f" (--suite {new})", DeprecationWarning, stacklevel=3)
        return new
    return suite


# --- runner ---------------------------------------------------------------------------

@dataclass
class Result:
    """One entry's table text, its rows (dicts of numbers), wall time (s) and error."""

    name: str
    text: str
    rows: list = field(default_factory=list)
    seconds: float = 0.0
    error: str | None = None


def run_entry(name: str, size: str, blas_threads: int | None = None) -> Result:
    """Run one entry; an exception is caught and reported in the table (``error``)."""
    load_start = os.getloadavg()
    start = time.perf_counter()
    rows, error = [], None
    limit = threadpool_limits(blas_threads) if blas_threads else nullcontext()
    try:
        with limit:
            lines, rows = ENTRIES[name](size)
    except Exception as exc:  # noqa: BLE001  (the suite goes on; the table says why)
        error = f"{type(exc).__name__}: {exc}"
        lines = [f"FAILED: {error}", "", *traceback.format_exc().splitlines()]
    seconds = time.perf_counter() - start
    text = "\n".join(header(name, size, load_start, blas_threads) + lines
                     + [f"entry wall time: {seconds:.1f} s"])
    return Result(name, text, rows, seconds, error)


def main(size: str = "small", only=None, out_dir=RESULTS, echo=True,
         blas_threads: int | None = None, suite: str = "peers",
         repeats: int = REPEATS) -> dict[str, Result]:
    """Run ``suite`` (``only``: any subset of ENTRIES instead) at ``size``, each peer side
    ``repeats`` times; write one file per entry."""
    global REPEATS
    if size not in SIZES:
        raise ValueError(f"unknown size {size!r}; choose from {list(SIZES)}")
    suite = suite_name(suite)
    if suite not in SUITES:
        raise ValueError(f"unknown suite {suite!r}; choose from {list(SUITES)}")
    if repeats < 1:
        raise ValueError(f"repeats must be >= 1, got {repeats}")
    REPEATS = repeats
    names = list(SUITES[suite]) if not only else list(only)
    unknown = [n for n in names if n not in ENTRIES]
    if unknown:
        raise ValueError(f"unknown benchmarks {unknown}; choose from {list(ENTRIES)}")
    if out_dir is not None:
        Path(out_dir).mkdir(parents=True, exist_ok=True)
    results = {}
    for name in names:
        if echo:
            print(f"... {name} ({size})", file=sys.stderr, flush=True)
        result = run_entry(name, size, blas_threads)
        results[name] = result
        if echo:
            print(result.text + "\n", flush=True)
        if out_dir is not None:
            with atomic_path(Path(out_dir) / f"{name}.txt") as tmp:
                tmp.write_text(result.text + "\n")
    return results


def _cli(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--suite", choices=(*SUITES, *SUITE_ALIASES), default="peers",
                        help="peers: femmech against its peers, one table per target"
                        " (default); components: femmech's own stages against their"
                        " targets (issue10 and issue24: deprecated old names)")
    parser.add_argument("--size", choices=SIZES, default="small")
    parser.add_argument("--repeats", type=int, default=REPEATS,
                        help="runs per side of each peer comparison (min / median)")
    parser.add_argument("--only", nargs="+", metavar="NAME", choices=list(ENTRIES),
                        help=f"run only these entries ({', '.join(ENTRIES)})")
    parser.add_argument("--out", type=Path, default=RESULTS, help="folder of the table files")
    parser.add_argument("--blas-threads", type=int, default=None,
                        help="limit every BLAS/OpenMP library to N threads for the whole run")
    args = parser.parse_args(argv)
    if args.suite in SUITE_ALIASES:
        new = SUITE_ALIASES[args.suite]
        print(f"note: --suite {args.suite} is deprecated; use --suite {new}", file=sys.stderr)
        args.suite = new
    results = main(args.size, args.only, args.out, blas_threads=args.blas_threads,
                   suite=args.suite, repeats=args.repeats)
    failed = [name for name, r in results.items() if r.error]
    if failed:
        print(f"failed: {', '.join(failed)}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(_cli())
