"""Benchmark: assembly and 20-mode eigen solve of shell models, 10k to 1M DOFs.

Models are welded box girders: a rectangular steel tube of four 5 mm plates,
0.4 m wide (y), 0.6 m high (z) and 2.0 m long (x), meshed with structured flat quads
(MITC4 bending + QM6 membrane + drilling, :mod:`femmech.fe.elements.shell`) by
:func:`box_girder` below, ``n`` quads per 0.2 m, and clamped at both ends (all DOFs of
the two end rings fixed). Sizes: ``10 n (10 n + 1)`` nodes, 6 DOFs each: n = 4, 13, 41
give 9 840, 102 180 and 1 011 060 DOFs. For each model the benchmark prints

- build: element matrices (``shell_matrices``), COO → CSR assembly of K and M,
  ``Tᵀ K T`` + ``Tᵀ M T`` (re-timed on their own), the total ``build_model`` time and
  its peak memory;
- modes: the 20 lowest modes by :func:`femmech.modes` (factorisation, ARPACK, Sturm
  check), peak memory, f1..f3, the largest relative residual and the Sturm count;
- reference, side by side in the same process: dense LAPACK
  (``scipy.linalg.eigh(K, M, subset_by_index=[0, 19])``, small model: the accuracy
  reference) and ``scipy.sparse.linalg.eigsh(K, 20, M, sigma=σ)`` with scipy's default
  SuperLU (COLAMD, partial pivoting; small and medium models: the speed reference).

Phases are timed and peak memory measured with the helpers of ``frame_modes.py``
(wrappers around the library's own functions for the duration of the call; the
high-water mark ``VmHWM`` reset through ``/proc/self/clear_refs``).

Usage::

    python benchmarks/shell_modes.py [--sizes small,medium,large] [--with-slow-reference]

Results are printed and written to ``benchmarks/results/shell_modes.txt``.
"""

from __future__ import annotations

import argparse
import dataclasses
import gc
import importlib.util
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np

import femmech as fm
import femmech.fe.model
import femmech.solve.eigen
from femmech.fe.elements import registry

HERE = Path(__file__).resolve().parent
N_MODES = 20
STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)
THICKNESS = 0.005  # m
BOX = (2.0, 0.4, 0.6)  # length (x), width (y), height (z), m
CELL = 0.2  # m: n quads per CELL
SIZES = {"tiny": 1, "small": 4, "medium": 13, "large": 41}
DENSE_REFERENCE_DOFS = 12_000
SLOW_REFERENCE_DOFS = 200_000


def _frame_helpers():
    """The measurement helpers of benchmarks/frame_modes.py (one implementation)."""
    spec = importlib.util.spec_from_file_location("_frame_modes_helpers", HERE / "frame_modes.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


fmb = _frame_helpers()


@contextmanager
def _timed_element(timer, kind: str, key: str):
    """Time the registered element matrices of ``kind`` (femmech.fe.elements.registry)
    under ``key`` of ``timer`` while the block runs."""
    entry = registry.ELEMENTS[kind]
    registry.ELEMENTS[kind] = dataclasses.replace(entry,
                                                  matrices=timer._wrap(entry.matrices, key))
    try:
        yield
    finally:
        registry.ELEMENTS[kind] = entry


def box_girder(n: int, box=BOX, cell=CELL) -> fm.Mesh:
    """Structured quad mesh of a rectangular tube (four walls), open at both ends.

    Parameters
    ----------
    n : int
        Quads per ``cell`` metres along every edge.
    box : (float, float, float)
        Length (x), width (y) and height (z), m; multiples of ``cell``.

    Returns
    -------
    Mesh
        ``10 n (10 n + 1)`` nodes for the default box: rings of the cross-section
        perimeter (counter-clockwise seen from +x), repeated along x. Quads in the cell
        set ``"walls"``; node sets ``"end_0"`` (x = 0) and ``"end_1"`` (x = length).
    """
    length, width, height = box
    nl, nw, nh = (round(d / cell * n) for d in (length, width, height))
    corners = np.array([[0, 0], [width, 0], [width, height], [0, height], [0, 0]])
    counts = [nw, nh, nw, nh]
    ring = np.vstack([c0 + np.outer(np.arange(k) / k, c1 - c0)
                      for c0, c1, k in zip(corners[:-1], corners[1:], counts, strict=True)])
    p = len(ring)  # perimeter nodes
    x = np.linspace(0.0, length, nl + 1)
    points = np.column_stack([np.repeat(x, p), np.tile(ring[:, 0], nl + 1),
                              np.tile(ring[:, 1], nl + 1)])
    i = np.arange(nl)[:, None]
    j = np.arange(p)[None, :]
    a, b = i * p + j, i * p + (j + 1) % p
    quads = np.stack([a, a + p, b + p, b], axis=-1).reshape(-1, 4)
    return fm.Mesh(points, {"quad": quads}, {"walls": {"quad": np.arange(len(quads))}},
                   {"end_0": np.arange(p), "end_1": nl * p + np.arange(p)})


def build(mesh):
    """``build_model`` with its phases timed; returns (model, row fields)."""
    timer = fmb.PhaseTimer()
    row = {}
    targets = [(femmech.fe.model, "assemble", "coo_csr")]
    with fmb.peak_memory(row, "build_peak_mb"), timer.patched(targets), \
            _timed_element(timer, "quad", "element"):
        start = time.perf_counter()
        model = fm.build_model(mesh, shells={"walls": fm.ShellProperty(THICKNESS, STEEL)},
                               supports=[fm.Support("end_0"), fm.Support("end_1")])
        row["build_s"] = time.perf_counter() - start
    timer.require("element", "coo_csr")
    start = time.perf_counter()  # the same products as build_model, re-timed on their own
    Tt = model.T.T.tocsr()
    (Tt @ model.K @ model.T).tocsr(), (Tt @ model.M @ model.T).tocsr()
    row["tkt_s"] = time.perf_counter() - start
    row["element_s"] = timer.seconds["element"]
    row["coo_csr_s"] = timer.seconds["coo_csr"]
    row["other_build_s"] = row["build_s"] - row["element_s"] - row["coo_csr_s"] - row["tkt_s"]
    row.update(dofs=model.n_dof, free_dofs=model.n_free, elements=len(mesh.cells["quad"]))
    return model, row


def modes_case(name, with_slow, history):
    n = SIZES[name]
    model, row = build(box_girder(n))
    row.update(table="modes", case=name, n=n)
    row.update(fmb.solve(model))
    solvers = (["dense"] if model.n_free <= DENSE_REFERENCE_DOFS else []) + ["eigsh"]
    row["references"] = [_reference(model, row, s, with_slow, history) for s in solvers]
    for key in ("omega2", "freq_hz"):
        row.pop(key)
    return row


def _reference(model, solved, solver, with_slow, history):
    n = model.n_free
    if solver == "eigsh" and n > SLOW_REFERENCE_DOFS and not with_slow:
        label = "eigsh, default SuperLU (COLAMD, partial pivoting)"
        return {"reference": label, "ref_s": None,
                "ref_note": fmb._skip_note(n, history, " (--with-slow-reference)")}
    return fmb._reference(model, solved, solver, with_slow, history)


def format_tables(rows) -> list[str]:
    """Build, modes and reference tables (the frame benchmark's layout)."""
    out = fmb.format_tables(rows)
    return [line.replace("Build (build_model: element matrices,",
                         "Build (build_model: shell element matrices,") for line in out]


def main(sizes=("small", "medium", "large"), with_slow_reference=False,
         out_file=HERE / "results" / "shell_modes.txt", echo=True):
    """Run the benchmark for ``sizes`` (keys of SIZES); return one dict per model.

    Rows carry ``"case"``, ``"n"``, the timings (s), peak memory (MB), frequencies (Hz),
    residuals, Sturm count and the references' errors, as in the printed tables.
    """
    unknown = [s for s in sizes if s not in SIZES]
    if unknown:
        raise ValueError(f"unknown sizes {unknown}; choose from {list(SIZES)}")
    rows, history = [], []
    for name in sizes:
        rows.append(modes_case(name, with_slow_reference, history))
        gc.collect()
        if echo:
            print(f"... {name} done", file=sys.stderr, flush=True)
    header = fmb.machine_info() + [
        f"models: box girder {BOX[0]} x {BOX[1]} x {BOX[2]} m, t = {THICKNESS * 1e3:g} mm"
        " steel, MITC4 quads, clamped at both ends; n quads per 0.2 m"]
    fmb.publish("\n".join(header + [""] + format_tables(rows)), out_file, echo)
    return rows


def _cli(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="small,medium,large",
                        help=f"comma-separated subset of {','.join(SIZES)}")
    parser.add_argument("--with-slow-reference", action="store_true",
                        help="also run scipy's default eigsh above"
                             f" {SLOW_REFERENCE_DOFS:,} free DOFs (the 1M-DOF model)")
    parser.add_argument("--out", default=str(HERE / "results" / "shell_modes.txt"),
                        help="result file")
    args = parser.parse_args(argv)
    main(tuple(s.strip() for s in args.sizes.split(",") if s.strip()),
         with_slow_reference=args.with_slow_reference, out_file=Path(args.out))


if __name__ == "__main__":
    _cli()
