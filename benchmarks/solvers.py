"""Benchmark: full 20-mode eigen solve with each installed sparse direct solver.

For each model (grid space frames of ~20k and ~150k DOFs, optionally the 59k-DOF shell
machine bed of scale.py and a hexahedral solid block of ~35k DOFs, where the factors are
much denser) and each backend of
:mod:`femmech.solve.direct` (SuperLU always; CHOLMOD and MKL PARDISO when installed):

- *unit*: the cost model of a 20-mode shift-invert solve, measured on its own: symbolic
  analysis + numeric factorisation of ``K - σM`` + 55 single-vector solves (one thread
  during the solves, as in ARPACK's loop);
- *eigen*: ``femmech.modes(model, 20, solver=...)``, split into the shift factorisation,
  the Lanczos iteration (block Lanczos; "solves" counts the solve calls, a block of two
  vectors being one call) and the Sturm check (an indefinite
  factorisation of ``K - cut M``), with its peak memory;
- *ARPACK*: the algorithm whose cost the unit models, on the same backend: scipy's
  ``eigsh`` (k = 20, default ncv = 41, tol = 0) in shift-invert mode at the same σ with
  this backend's factor as ``OPinv`` (one thread during its loop), no Sturm check; its
  time with the factorisation and the number of solves it made;
- *ratio*: eigen time / the unit time of the fastest backend on that model
  (target: <= 1.3), the same without the Sturm check, and ARPACK's time over that unit;
- *agreement*: the largest relative difference of the frequencies from the first
  backend's (SuperLU).

Thread settings (:func:`femmech.solve.threads.describe`), library versions and the machine are
printed with the tables.

Usage::

    python benchmarks/solvers.py [--sizes 20k,150k,solid] [--solvers superlu,pardiso]

Results are printed and written to ``benchmarks/results/solvers.txt``.
"""

from __future__ import annotations

import argparse
import gc
import importlib.util
import sys
import time
from pathlib import Path

import numpy as np

import femmech as fm
import femmech.solve.eigen
import femmech.solve.pencil
from femmech.fe import sections
from femmech.fe.generators import grid_frame
from femmech.solve import direct, threads

sys.path.insert(0, str(Path(__file__).resolve().parent))
from frame_modes import (  # noqa: E402  (sibling benchmark: shared measurement helpers)
    PhaseTimer,
    _table,
    counted_eigsh,
    machine_info,
    peak_memory,
    publish,
)

N_MODES = 20
N_SOLVES = 55
STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)
SECTION = sections.rectangular_hollow(0.08, 0.08, 0.005)
BAY = 0.5  # m

# name: (kind, size parameters)
MODELS = {
    "tiny": ("frame", ((2, 2, 2), 4)),        # 1 080 free DOFs (smoke test)
    "20k": ("frame", ((5, 5, 5), 8)),         # 23 760 free DOFs
    "150k": ("frame", ((9, 9, 9), 10)),       # 151 200 free DOFs
    "shell": ("shell", 6),                    # 58 692 free DOFs, machine bed (scale.py)
    "solid": ("solid", (40, 16, 16)),         # 34 680 free DOFs, hexahedra
}


def build(name):
    kind, params = MODELS[name]
    if kind == "frame":
        bays, subdivisions = params
        mesh = grid_frame(bays, tuple(BAY * b for b in bays), subdivisions)
        prop = fm.BeamProperty(SECTION, STEEL)
        return fm.build_model(mesh, dict.fromkeys(mesh.cell_sets, prop),
                              supports=[fm.Support("base")])
    if kind == "shell":  # MITC4 plates with beam stiffeners: denser factors than frames
        spec = importlib.util.spec_from_file_location("_scale_bed", Path(__file__).parent
                                                      / "scale.py")
        bed = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(bed)
        return bed.build(*bed.machine_bed(params))
    return solid_block(*params)


def solid_block(nx, ny, nz):
    """Steel block 1 x 0.4 x 0.4 m of nx x ny x nz hexahedra, clamped at x = 0."""
    xs, ys, zs = np.linspace(0, 1, nx + 1), np.linspace(0, 0.4, ny + 1), \
        np.linspace(0, 0.4, nz + 1)
    grid = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), axis=-1).reshape(-1, 3)
    index = np.arange(grid.shape[0]).reshape(nx + 1, ny + 1, nz + 1)
    c = index[:-1, :-1, :-1].ravel()
    sy, sz = nz + 1, 1
    sx = (ny + 1) * (nz + 1)
    hexa = np.column_stack([c, c + sx, c + sx + sy, c + sy,
                            c + sz, c + sx + sz, c + sx + sy + sz, c + sy + sz])
    mesh = fm.Mesh(grid, {"hexahedron": hexa}, {"solid": {"hexahedron": np.arange(len(hexa))}})
    root = np.flatnonzero(grid[:, 0] < 1e-12)
    return fm.build_model(mesh, solids={"solid": fm.SolidProperty(STEEL)},
                          supports=[fm.Support(root, "translations")])


def unit_cost(model, name, sigma):
    """(analyse s, factorise s, seconds of N_SOLVES single-vector solves)."""
    A = (model.K_free - sigma * model.M_free).tocsc()
    factor = direct.factorize(A, name, definite=True)
    b = np.random.default_rng(7).standard_normal(A.shape[0])
    with threads.solve_phase():
        start = time.perf_counter()
        for _ in range(N_SOLVES):
            factor.solve(b)
        seconds = time.perf_counter() - start
    timings = dict(factor.timings)
    del factor, A
    gc.collect()
    return timings["analyse"], timings["factorise"], seconds


def _counting_factorize(counter, original):
    def factorize(*args, **kwargs):
        factor = original(*args, **kwargs)
        solve = factor.solve

        def counted(b):
            counter[0] += 1
            counter[1] += 1 if np.ndim(b) == 1 else np.shape(b)[1]
            return solve(b)
        factor.solve = counted
        return factor
    return factorize


def eigen_solve(model, name, check=True):
    """``fm.modes(model, 20, solver=name)`` with phases timed and solves counted."""
    timer = PhaseTimer()
    row = {}
    counter = [0, 0]  # solve calls, vectors solved
    original = femmech.solve.eigen.factorize
    targets = [(femmech.solve.eigen, "inertia_below", "sturm"),
               (femmech.solve.eigen, "lowest_pairs", "arpack")]
    femmech.solve.eigen.factorize = _counting_factorize(counter, original)
    try:
        with timer.patched(targets + [(femmech.solve.eigen, "factorize", "factor")]), \
                peak_memory(row, "peak_mb"):
            start = time.perf_counter()
            result = fm.modes(model, n_modes=N_MODES, solver=name, check=check)
            row["eigen_s"] = time.perf_counter() - start
    finally:
        femmech.solve.eigen.factorize = original
    row.update({f"{k}_s": timer.seconds.get(k, 0.0) for k in ("factor", "arpack", "sturm")})
    row.update(solves=counter[0], vectors_solved=counter[1], omega2=result.omega2,
               n_modes=result.n_modes, sturm_count=result.sturm_count, solver=result.solver,
               sigma=result.sigma, max_residual=float(result.residual.max()))
    return row


def arpack_solve(model, name, sigma):
    """(seconds, solves, ω²) of scipy's ``eigsh`` for N_MODES pairs near σ, shift-invert
    with this backend's factor of ``K - σM`` (factorisation included), tol = 0."""
    K, M = model.K_free, model.M_free
    start = time.perf_counter()
    factor = direct.factorize((K - sigma * M).tocsc(), name, definite=True)
    omega2, solves = counted_eigsh(K, M, N_MODES, sigma, factor)
    return time.perf_counter() - start, solves, omega2


def model_rows(case, names):
    model = build(case)
    n = model.n_free
    sigma = femmech.solve.pencil.default_shift(model.K_free, model.M_free)
    rows = []
    for name in names:
        analyse, factorise, solve_s = unit_cost(model, name, sigma)
        row = {"table": "solvers", "case": case, "free_dofs": n, "solver": name,
               "analyse_s": analyse, "factorise_s": factorise, "solves_s": solve_s,
               "unit_s": analyse + factorise + solve_s}
        row.update(eigen_solve(model, name))
        row["eigen_nocheck_s"] = eigen_solve(model, name, check=False)["eigen_s"]
        row["arpack_eigsh_s"], row["arpack_solves"], arpack_omega2 = arpack_solve(model, name,
                                                                                   sigma)
        m = min(len(arpack_omega2), len(row["omega2"]))
        row["arpack_max_diff"] = float(np.max(np.abs(arpack_omega2[:m] - row["omega2"][:m])
                                              / np.abs(row["omega2"][:m])))
        rows.append(row)
        gc.collect()
    fastest = min(r["unit_s"] for r in rows)
    ref = rows[0]["omega2"]
    for r in rows:
        r["fastest_unit_s"] = fastest
        r["ratio"] = r["eigen_s"] / fastest
        r["ratio_nocheck"] = r["eigen_nocheck_s"] / fastest
        r["ratio_arpack"] = r["arpack_eigsh_s"] / fastest
        m = min(len(ref), len(r["omega2"]))
        f, f_ref = np.sqrt(np.abs(r["omega2"][:m])), np.sqrt(np.abs(ref[:m]))
        r["max_freq_diff"] = float(np.max(np.abs(f - f_ref) / f_ref))
        r["f1_hz"] = float(f[0] / (2 * np.pi))
    return rows


def format_tables(rows) -> list[str]:
    lines = [[r["case"], f"{r['free_dofs']:,}", r["solver"], f"{r['analyse_s']:.3f}",
              f"{r['factorise_s']:.3f}", f"{r['solves_s']:.3f}", f"{r['unit_s']:.3f}",
              f"{r['factor_s']:.2f}", f"{r['arpack_s']:.2f}", str(r["solves"]),
              f"{r['sturm_s']:.2f}", f"{r['eigen_s']:.2f}", f"{r['peak_mb']:.0f}",
              f"{r['ratio']:.2f}", f"{r['ratio_nocheck']:.2f}",
              f"{r['sturm_count']}/{r['n_modes']}", f"{r['max_freq_diff']:.1e}"]
             for r in rows]
    arpack = [[r["case"], f"{r['free_dofs']:,}", r["solver"], f"{r['unit_s']:.3f}",
               f"{r['eigen_nocheck_s']:.2f}", str(r["vectors_solved"]),
               f"{r['ratio_nocheck']:.2f}", f"{r['arpack_eigsh_s']:.2f}",
               str(r["arpack_solves"]), f"{r['ratio_arpack']:.2f}",
               f"{r['arpack_max_diff']:.1e}"] for r in rows]
    return _table(f"Full {N_MODES}-mode eigen solve per sparse solver (unit = analyse +"
                  f" factorise + {N_SOLVES} solves; ratio = eigen s / fastest unit s)",
                  ["case", "free DOFs", "solver", "analyse s", "factor s",
                   f"{N_SOLVES} solves s", "unit s", "eig:factor s", "eig:Lanczos s",
                   "solves", "eig:Sturm s", "eigen s", "peak MB", "ratio",
                   "ratio no Sturm", "Sturm", "max |df|/f"], lines) + _table(
        f"The unit's reference algorithm: scipy eigsh (ARPACK, k = {N_MODES}, shift-invert on"
        " the same factor, no Sturm check) against femmech.modes(check=False); ratios over"
        " the fastest unit",
        ["case", "free DOFs", "solver", "unit s", "femmech s", "vectors solved",
         "femmech ratio", "eigsh s", "eigsh solves", "eigsh ratio", "max |dλ|/λ"], arpack)


def header() -> list[str]:
    versions = direct.versions()
    return machine_info() + [threads.describe(),
                             "solvers: " + "; ".join(f"{k}: {v}" for k, v in versions.items()),
                             f"auto picks: {direct.resolve('auto', 10**6)} (SuperLU below"
                             f" {direct.AUTO_MIN_SIZE} unknowns)"]


def main(sizes=("20k", "150k"), names=None,
         out_file=Path(__file__).parent / "results" / "solvers.txt", echo=True):
    """Run for ``sizes`` (keys of MODELS) and backends ``names`` (default: installed).

    Returns one dict per (model, solver) with the timings (s), peak memory (MB), ratios
    and frequency agreement shown in the table.
    """
    unknown = [s for s in sizes if s not in MODELS]
    if unknown:
        raise ValueError(f"unknown sizes {unknown}; choose from {list(MODELS)}")
    names = list(direct.available()[::-1] if names is None else names)
    if "superlu" in names:  # the reference of the frequency agreement goes first
        names.remove("superlu")
        names.insert(0, "superlu")
    for name in names:
        direct.resolve(name)
    rows = []
    for case in sizes:
        rows += model_rows(case, names)
        if echo:
            print(f"... {case} done", file=sys.stderr, flush=True)
    publish("\n".join(header() + [""] + format_tables(rows)), out_file, echo)
    for r in rows:
        r.pop("omega2")
    return rows


def _cli(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="20k,150k", help=f"subset of {','.join(MODELS)}")
    parser.add_argument("--solvers", default=None,
                        help=f"subset of {','.join(direct.BACKENDS)} (default: installed)")
    args = parser.parse_args(argv)
    names = None if args.solvers is None else [s.strip() for s in args.solvers.split(",")]
    main(tuple(s.strip() for s in args.sizes.split(",") if s.strip()), names)


if __name__ == "__main__":
    _cli()
