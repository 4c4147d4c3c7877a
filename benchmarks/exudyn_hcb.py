"""Benchmark: femmech's Craig-Bampton against Exudyn's Hurty-Craig-Bampton, same K, M, interface.

Exudyn (pip package ``exudyn``, :class:`exudyn.FEM.FEMinterface`) reduces a finite-element
model for its floating-frame bodies with ``ComputeHurtyCraigBamptonModes``. Both libraries
are given the same matrices: femmech's ``K_free`` and ``M_free`` (scipy CSR) of the
``grid_frame`` frames of benchmarks/solvers.py (``tiny`` 1 080, ``20k`` 23 760, ``150k``
151 200 free DOFs), and the same interface: all six DOFs of 8 top joints (n_b = 48, the
``8 joints`` interface of benchmarks/craig_bampton.py).

What each library reduces, and how the two are made the same reduction:

- Exudyn's HCB is written for solid meshes of 3-DOF ``Position`` nodes: boundary DOFs are
  ``3 node + (0, 1, 2)``. A beam node has six DOFs, so the free DOFs (6 per node in
  femmech's order ux, uy, uz, rx, ry, rz; the frame has no partially supported node) are
  handed to Exudyn as consecutive triples, two "position nodes" per beam node (the
  translations and the rotations, both at the node's coordinates), and each interface node
  becomes two boundary pseudo-nodes.
- Exudyn's recommended modes ``RBE2``/``RBE3`` condense each boundary node *list* into
  one rigid (RBE2) or averaged (RBE3) 6-DOF interface and drop the first list's rigid-body
  motion: a different and much smaller reduction. ``HCBstaticModeSelection.allBoundaryNodes``
  computes one static mode per boundary coordinate, the classical Craig-Bampton basis; with
  the same number of fixed-interface modes it spans the same space as femmech's
  ``craig_bampton(model, nodes, n_modes, residual_vectors=False)`` (femmech's interface is
  per DOF; here it is all six DOFs of each node, so the two coincide).
- Exudyn stores the basis V (n × (n_b + n_q), dense) in ``fem.modeBasis`` and leaves the
  projection to its reduced-order object; the benchmark forms ``Vᵀ K V`` and ``Vᵀ M V``
  (timed separately) so that both sides end with the reduced K, M.
- femmech may keep a few more fixed-interface modes than asked for, to complete a cluster
  of equal frequencies; Exudyn is asked for the same number as femmech kept.

Each library runs twice: with the BLAS/OpenMP threads as the process has them (femmech
applies its own per-phase limits, femmech.solve.threads) and inside ``threadpool_limits(1)``.
Exudyn factorises K_ii twice with scipy's default SuperLU (``factorized`` for the static
modes, ``eigsh(sigma=0)`` for the fixed-interface modes); femmech factorises once with the
solver ``auto`` picks. Agreement: the lowest 20 frequencies of the two reduced models
against each other, both against the full model's (``femmech.modes``), and the largest
sine of the principal angles between the two bases (M inner product).

Usage::

    python benchmarks/exudyn_hcb.py [--sizes 20k,150k] [--modes 30]

Results are printed and written to ``benchmarks/results/exudyn_hcb.txt``.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import importlib.metadata
import io
import sys
import time
from pathlib import Path

import numpy as np
import scipy.linalg as sla
from threadpoolctl import threadpool_limits

import femmech.reduction as reduction

sys.path.insert(0, str(Path(__file__).resolve().parent))
from craig_bampton import (  # noqa: E402  (sibling benchmark: models and helpers)
    FRAMES,
    N_FULL,
    N_MODES,
    full_solve,
    interface_nodes,
    max_error,
    reduced_frequencies,
)
from frame_modes import _table, machine_info, publish  # noqa: E402
from solvers import build as build_model  # noqa: E402

INTERFACE = "8 joints"
THREADS = (("default", None), ("1 thread", 1))


def exudyn_version() -> str | None:
    """Installed exudyn version, or None if it cannot be imported."""
    try:
        import exudyn.FEM  # noqa: F401
    except ImportError:
        return None
    return importlib.metadata.version("exudyn")


def pseudo_nodes(model, nodes) -> tuple[np.ndarray, np.ndarray]:
    """(positions (n_free / 3, 3) of the DOF triples, boundary pseudo-node indices).

    Raises ValueError if the free DOFs do not come in whole nodes (a partial support).
    """
    free = model.free
    per_node = free.reshape(-1, 6) if free.size % 6 == 0 else None
    if per_node is None or np.any(per_node != per_node[:, :1] + np.arange(6)) \
            or np.any(per_node[:, 0] % 6):
        raise ValueError("free DOFs are not whole 6-DOF nodes: Exudyn's 3-DOF node"
                         " numbering cannot represent this model")
    positions = model.mesh.points[free[::3] // 6]
    dofs = (6 * np.asarray(nodes)[:, None] + np.arange(6)).ravel()
    where = np.searchsorted(free, dofs)
    return positions, np.unique(where // 3)


def exudyn_hcb(model, nodes, n_modes: int) -> dict:
    """Exudyn's HCB (allBoundaryNodes) on K_free, M_free; basis, times and reduced K, M."""
    from exudyn import FEM

    positions, boundary = pseudo_nodes(model, nodes)
    gc.collect()
    start = time.perf_counter()
    fem = FEM.FEMinterface()
    fem.stiffnessMatrix = model.K_free.tocsr()
    fem.massMatrix = model.M_free.tocsr()
    fem.nodes = {"Position": positions}
    setup_s = time.perf_counter() - start
    start = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()):  # its progress output
        fem.ComputeHurtyCraigBamptonModes(
            boundaryNodesList=[boundary.tolist()], nEigenModes=n_modes, useSparseSolver=True,
            computationMode=FEM.HCBstaticModeSelection.allBoundaryNodes,
            timerTreshold=10**15)
    hcb_s = time.perf_counter() - start
    V = fem.modeBasis["matrix"]
    start = time.perf_counter()
    K = V.T @ (model.K_free @ V)
    M = V.T @ (model.M_free @ V)
    project_s = time.perf_counter() - start
    return {"V": V, "K": 0.5 * (K + K.T), "M": 0.5 * (M + M.T), "setup_s": setup_s,
            "hcb_s": hcb_s, "project_s": project_s, "total_s": setup_s + hcb_s + project_s,
            "n_b": 3 * boundary.size, "n_q": V.shape[1] - 3 * boundary.size}


def femmech_cb(model, nodes, n_modes: int) -> dict:
    """femmech's classical Craig-Bampton; basis on the free DOFs, times, reduced K, M."""
    gc.collect()
    start = time.perf_counter()
    se = reduction.craig_bampton(model, nodes.tolist(), n_modes=n_modes,
                                 residual_vectors=False)
    total_s = time.perf_counter() - start
    return {"se": se, "K": se.K, "M": se.M, "total_s": total_s, "timings": dict(se.timings),
            "n_b": se.n_interface, "n_q": se.n_modal}


def subspace_sine(A, B, M) -> float:
    """Largest sine of the principal angles between span(A) and span(B), M inner product."""
    def orthonormal(X):
        L = np.linalg.cholesky(X.T @ (M @ X))
        return sla.solve_triangular(L, X.T, lower=True).T  # X L⁻ᵀ: M-orthonormal columns
    QA, QB = orthonormal(A), orthonormal(B)
    R = QB - QA @ (QA.T @ (M @ QB))  # part of span(B) outside span(A): its M-singular
    gram = R.T @ (M @ R)             # values are the sines (accurate also when tiny)
    return float(np.sqrt(max(0.0, np.linalg.eigvalsh(0.5 * (gram + gram.T)).max())))


def model_rows(case: str, n_modes: int = N_MODES) -> list[dict]:
    model = build_model(case)
    nodes = interface_nodes(model.mesh, INTERFACE)
    full = full_solve(model)
    rows, bases = [], {}
    for label, limit in THREADS:
        with threadpool_limits(limit):
            ours = femmech_cb(model, nodes, n_modes)
            theirs = exudyn_hcb(model, nodes, ours["n_q"])
        f_ours, f_theirs = reduced_frequencies(ours["K"], ours["M"]), \
            reduced_frequencies(theirs["K"], theirs["M"])
        row = {"case": case, "free_dofs": model.n_free, "threads": label,
               "n_b": ours["n_b"], "n_q": ours["n_q"], "exudyn_n_b": theirs["n_b"],
               "exudyn_n_q": theirs["n_q"], "femmech_s": ours["total_s"],
               **{f"femmech_{k}_s": v for k, v in ours["timings"].items()},
               "exudyn_s": theirs["total_s"], "exudyn_hcb_s": theirs["hcb_s"],
               "exudyn_project_s": theirs["project_s"], "exudyn_setup_s": theirs["setup_s"],
               "full_eigen_s": full["eigen_s"], "solver": full["solver"],
               "f_femmech_hz": f_ours, "f_exudyn_hz": f_theirs,
               "diff": max_error(f_theirs, f_ours, N_FULL),
               "femmech_err10": max_error(f_ours, full["freq_hz"], 10),
               "femmech_err20": max_error(f_ours, full["freq_hz"], N_FULL),
               "exudyn_err10": max_error(f_theirs, full["freq_hz"], 10),
               "exudyn_err20": max_error(f_theirs, full["freq_hz"], N_FULL)}
        row["speedup"] = row["exudyn_s"] / row["femmech_s"]
        rows.append(row)
        bases = {"ours": ours["se"], "theirs": theirs["V"]}
        del ours, theirs
    se = bases["ours"]
    ours_V = se.expand_free(np.eye(se.n_reduced))
    sine = subspace_sine(ours_V, bases["theirs"], model.M_free)
    for row in rows:
        row["subspace_sine"] = sine
    return rows


def format_tables(rows) -> list[str]:
    lines = [[r["case"], f"{r['free_dofs']:,}", r["threads"], f"{r['n_b']}+{r['n_q']}",
              f"{r['exudyn_n_b']}+{r['exudyn_n_q']}", f"{r['femmech_factorisation_s']:.2f}",
              f"{r['femmech_constraint_modes_s']:.2f}",
              f"{r['femmech_fixed_interface_modes_s']:.2f}",
              f"{r['femmech_projection_s']:.2f}", f"{r['femmech_s']:.2f}",
              f"{r['exudyn_hcb_s']:.2f}", f"{r['exudyn_project_s']:.2f}", f"{r['exudyn_s']:.2f}",
              f"{r['speedup']:.1f}x", f"{r['full_eigen_s']:.2f}"] for r in rows]
    out = _table("Time: femmech craig_bampton (classical) vs Exudyn ComputeHurtyCraigBamptonModes"
                 " (allBoundaryNodes) + projection, same K_free, M_free and interface",
                 ["case", "free DOFs", "threads", "femmech n_b+n_q", "exudyn n_b+n_q",
                  "fm factor s", "fm constr s", "fm fixed-if s", "fm project s",
                  "femmech s", "exu HCB s", "exu project s", "exudyn s",
                  "exudyn / femmech", "full eig s"], lines)
    lines = [[r["case"], f"{r['free_dofs']:,}", r["threads"], f"{r['diff']:.1e}",
              f"{r['subspace_sine']:.1e}", f"{r['femmech_err10']:.1e}",
              f"{r['exudyn_err10']:.1e}", f"{r['femmech_err20']:.1e}",
              f"{r['exudyn_err20']:.1e}", f"{r['f_femmech_hz'][0]:.3f}",
              f"{r['f_exudyn_hz'][0]:.3f}"] for r in rows]
    out += _table(f"Agreement: lowest {N_FULL} frequencies of the two reduced models, and"
                  f" against the full model (femmech.modes, {N_FULL} modes)",
                  ["case", "free DOFs", "threads", "max |df|/f fm-exu", "basis sin angle",
                   "fm err f1-10", "exu err f1-10", "fm err f1-20", "exu err f1-20",
                   "fm f1 Hz", "exu f1 Hz"], lines)
    return out + [
        f"interface: all 6 DOFs of {INTERFACE} (corners and edge middles of the top face);"
        " Exudyn: 2 boundary pseudo-nodes (translations, rotations) per interface node;",
        "femmech s = craig_bampton total (phases fm ...); exudyn s = FEMinterface setup +"
        " ComputeHurtyCraigBamptonModes + V'KV, V'MV; threads: 'default' = as the process"
        " has them, '1 thread' = threadpool_limits(1);",
        "basis sin angle: largest sine of the principal angles between the two bases (M inner"
        " product); err = largest relative error against the full model's frequencies.", ""]


def not_installed_lines() -> list[str]:
    return ["exudyn: not installed (pip install exudyn; or pip install 'femmech[bench]'):"
            " femmech CB vs Exudyn HCB skipped", ""]


def main(sizes=("20k", "150k"), n_modes: int = N_MODES,
         out_file=Path(__file__).parent / "results" / "exudyn_hcb.txt", echo=True):
    """Run for the frame ``sizes``; one dict per (model, thread setting), [] without exudyn."""
    unknown = [s for s in sizes if s not in FRAMES]
    if unknown:
        raise ValueError(f"unknown sizes {unknown}; choose from {list(FRAMES)}")
    rows = []
    version = exudyn_version()
    if version is not None:
        for case in sizes:
            rows += model_rows(case, n_modes)
            gc.collect()
            if echo:
                print(f"... {case} done", file=sys.stderr, flush=True)
    if echo or out_file is not None:
        body = format_tables(rows) if version else not_installed_lines()
        publish("\n".join(machine_info() + [f"exudyn {version or 'not installed'}", ""] + body),
                out_file, echo)
    return rows


def _cli(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="20k,150k", help=f"subset of {','.join(FRAMES)}")
    parser.add_argument("--modes", type=int, default=N_MODES,
                        help="fixed-interface modes (default 30)")
    args = parser.parse_args(argv)
    main(tuple(s.strip() for s in args.sizes.split(",") if s.strip()), args.modes)


if __name__ == "__main__":
    _cli()
