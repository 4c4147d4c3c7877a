"""Benchmark: assembly and 20-mode eigen solve of grid space frames, 10k to 1M DOFs.

Models are machine-frame-like grids of hollow-section steel members
(:func:`femmech.fe.generators.grid_frame`, bay 0.5 m, 80 x 80 x 5 mm box section), every
member subdivided into several Timoshenko elements, supported at the base joints (one
free-free variant). For each model the benchmark prints

- build: element matrices, COO → CSR assembly of K and M, ``Tᵀ K T`` and ``Tᵀ M T``,
  total ``build_model`` time and its peak memory;
- modes: the 20 lowest modes by :func:`femmech.modes` (factorisation, Lanczos, Sturm
  check), peak memory, f1..f3, the largest relative residual and the Sturm count;
- reference, side by side in the same process: the accuracy of femmech's frequencies
  against dense LAPACK (``scipy.linalg.eigh``, small model) or an independent
  ``scipy.sparse.linalg.eigsh(K, 20, M, sigma=σ)`` with scipy's default SuperLU
  (partial pivoting, COLAMD), whose time is also the speed reference;
- assembly reference: a per-element Python loop (femmech's element routine called per
  element, triplet lists, one COO → CSR) against the vectorised assembly.

The phases of ``build_model`` and ``modes`` are timed by wrapping the module functions
they call (``beam_matrices``, ``assemble``, ``factorize``, ``_arpack``,
``inertia_below``) for the duration of the call, so the timed code is the library's own
path; the benchmark fails if a wrapper was not reached. Peak memory is the high-water
mark of the resident set (``VmHWM``, reset through ``/proc/self/clear_refs``) above the
resident set at the start of the phase.

Usage::

    python benchmarks/frame_modes.py [--sizes small,medium,large] [--with-slow-reference]

Results are printed and written to ``benchmarks/results/frame_modes.txt``.
"""

from __future__ import annotations

import argparse
import ctypes
import gc
import os
import platform
import resource
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import scipy
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import femmech as fm
import femmech.fe.model
import femmech.solve.eigen
import femmech.solve.lanczos
import femmech.solve.pencil
import femmech.solve.threads
from femmech.fe import sections
from femmech.fe.dofs import element_dofs
from femmech.fe.elements.beam import beam_matrices
from femmech.fe.generators import grid_frame
from femmech.output.export import atomic_path

N_MODES = 20
BAY = 0.5  # m
SECTION = sections.rectangular_hollow(0.08, 0.08, 0.005)
STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)
GROUPS = ("beams_x", "beams_y", "columns")

# name: (bays, subdivisions, supported); free DOFs are 6 (nodes - base joints)
MODELS = {
    "tiny": ((2, 2, 2), 2, True),          # 486 DOFs (smoke test)
    "small": ((4, 4, 4), 6, True),         # 9 750 DOFs
    "medium": ((8, 8, 8), 10, True),       # 109 350 DOFs
    "medium-free": ((8, 8, 8), 10, False),
    "large": ((16, 16, 16), 12, True),     # 945 030 DOFs
    "20k": ((5, 5, 5), 8, True),           # 23 760 free DOFs (as in benchmarks/solvers.py)
    "150k": ((9, 9, 9), 10, True),         # 151 200 free DOFs (as in benchmarks/solvers.py)
}
# assembly reference (loop) cases: name: (bays, subdivisions, run the loop reference)
ASSEMBLY = {
    "tiny": ((2, 2, 2), 2, True),          # 108 elements
    "10k-elements": ((8, 8, 8), 5, True),  # 9 720 elements
    "100k-elements": ((16, 16, 16), 7, False),  # 97 104 elements
}
SIZE_CASES = {
    "tiny": (["tiny"], ["tiny"]),
    "small": (["small"], ["10k-elements"]),
    "medium": (["medium", "medium-free"], ["100k-elements"]),
    "large": (["large"], []),
}
SLOW_REFERENCE_DOFS = 200_000  # eigsh with default SuperLU above this only with the flag
DENSE_REFERENCE_DOFS = 12_000  # dense eigh up to this size


# --- measurement helpers -------------------------------------------------------------

class PhaseTimer:
    """Accumulate wall time of module functions while they are patched in."""

    def __init__(self):
        self.seconds = {}
        self.calls = {}
        self._active = 0

    @contextmanager
    def patched(self, targets):
        """Wrap ``(module, attribute, key)`` functions; nested calls count once (outer)."""
        saved = [(mod, name, getattr(mod, name)) for mod, name, _ in targets]
        for (mod, name, key), (_, _, func) in zip(targets, saved, strict=True):
            setattr(mod, name, self._wrap(func, key))
        try:
            yield self
        finally:
            for mod, name, func in saved:
                setattr(mod, name, func)

    def _wrap(self, func, key):
        def timed(*args, **kwargs):
            if self._active:
                return func(*args, **kwargs)
            self._active += 1
            start = time.perf_counter()
            try:
                return func(*args, **kwargs)
            finally:
                self._active -= 1
                self.seconds[key] = self.seconds.get(key, 0.0) + time.perf_counter() - start
                self.calls[key] = self.calls.get(key, 0) + 1
        return timed

    def require(self, *keys):
        """Fail loudly if a wrapped function was never reached (internals changed)."""
        missing = [k for k in keys if k not in self.calls]
        if missing:
            raise RuntimeError(f"benchmark wrappers not reached: {missing}; update the"
                               " benchmark to the library's internals")


def _status_kib(field: str) -> int:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    raise RuntimeError(f"{field} not in /proc/self/status")


@contextmanager
def peak_memory(out: dict, key: str):
    """Store in ``out[key]`` the peak resident memory (MB) above the start of the block."""
    gc.collect()
    _return_freed_memory()
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")  # reset the high-water mark VmHWM to the current RSS
        start, use_hwm = _status_kib("VmRSS"), True
    except OSError:  # no clear_refs: ru_maxrss is monotone, the delta is a lower bound
        start, use_hwm = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, False
    try:
        yield
    finally:
        peak = (_status_kib("VmHWM") if use_hwm
                else resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
        out[key] = max(peak - start, 0) / 1024.0


def _return_freed_memory():
    """Give the heap's free memory back to the system (glibc ``malloc_trim``).

    Called before each peak measurement (:func:`peak_memory`), so that memory an earlier
    phase freed and the allocator kept does not hide the next phase's allocations from
    the peak. The allocator otherwise keeps its defaults, as in a user's script: freed
    temporaries are reused within a phase. (Until stop 13 the benchmarks served every
    array above 128 KiB by mmap instead; the page faults of the temporaries then made
    the Lanczos loop of the 151k-DOF frame 1.6-1.9x slower than in a plain run.)
    """
    try:
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        pass


def blas_threads() -> str:
    """Threads of the OpenBLAS libraries loaded by numpy and scipy."""
    found = []
    with open("/proc/self/maps") as fh:
        libs = sorted({line.split()[-1] for line in fh if "openblas" in line.lower()})
    for path in libs:
        lib = ctypes.CDLL(path)
        for name in ("scipy_openblas_get_num_threads64_", "scipy_openblas_get_num_threads",
                     "openblas_get_num_threads64_", "openblas_get_num_threads"):
            if hasattr(lib, name):
                found.append(f"{Path(path).name.split('-')[0]}={getattr(lib, name)()}")
                break
    return ", ".join(found) or "unknown"


def machine_info() -> list[str]:
    cpu = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                if line.startswith("model name")), platform.processor())
    mem_gib = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    return [f"machine: {os.cpu_count()} CPUs ({cpu}), {mem_gib:.0f} GiB RAM, {platform.system()}",
            f"python {platform.python_version()}, numpy {np.__version__},"
            f" scipy {scipy.__version__}, femmech {getattr(fm, '__version__', 'dev')}",
            f"BLAS threads: {blas_threads()}"]


# --- models ---------------------------------------------------------------------------

def frame_mesh(bays, subdivisions):
    return grid_frame(bays, tuple(BAY * b for b in bays), subdivisions)


def build(mesh, supported: bool):
    """``build_model`` with its phases timed; returns (model, row fields)."""
    prop = fm.BeamProperty(SECTION, STEEL)
    supports = [fm.Support("base")] if supported else []
    timer = PhaseTimer()
    row = {}
    targets = [(femmech.fe.model, "beam_matrices", "element"),
               (femmech.fe.model, "assemble", "coo_csr")]
    with peak_memory(row, "build_peak_mb"), timer.patched(targets):
        start = time.perf_counter()
        model = fm.build_model(mesh, dict.fromkeys(GROUPS, prop), supports=supports)
        row["build_s"] = time.perf_counter() - start
    timer.require("element", "coo_csr")
    start = time.perf_counter()  # the same products as build_model, re-timed on their own
    Tt = model.T.T.tocsr()
    (Tt @ model.K @ model.T).tocsr(), (Tt @ model.M @ model.T).tocsr()
    row["tkt_s"] = time.perf_counter() - start
    row["element_s"] = timer.seconds["element"]
    row["coo_csr_s"] = timer.seconds["coo_csr"]
    row["other_build_s"] = row["build_s"] - row["element_s"] - row["coo_csr_s"] - row["tkt_s"]
    row.update(dofs=model.n_dof, free_dofs=model.n_free, elements=len(model.beams.cells))
    return model, row


def solve(model):
    """``fm.modes(model, 20)`` with factorisation, Lanczos and Sturm check timed."""
    timer = PhaseTimer()
    row = {}
    targets = [(femmech.solve.eigen, "inertia_below", "sturm"),
               (femmech.solve.eigen, "factorize", "factor"),
               (femmech.solve.eigen, "arpack", "arpack"),  # bands
               (femmech.solve.lanczos, "arpack", "arpack"),  # where block Lanczos gives up
               (femmech.solve.lanczos, "block_lanczos", "arpack")]  # lowest modes
    with peak_memory(row, "eigen_peak_mb"), timer.patched(targets):
        start = time.perf_counter()
        result = fm.modes(model, n_modes=N_MODES)
        row["eigen_s"] = time.perf_counter() - start
    if result.method == "arpack":
        timer.require("factor", "arpack", "sturm")
    for key in ("factor", "arpack", "sturm"):
        row[f"{key}_s"] = timer.seconds.get(key, 0.0)
    row["other_eigen_s"] = row["eigen_s"] - row["factor_s"] - row["arpack_s"] - row["sturm_s"]
    elastic = result.freq_hz[~result.rigid]
    row.update(method=result.method, n_modes=result.n_modes, n_rigid=int(result.rigid.sum()),
               f123_hz=elastic[:3].tolist(), max_residual=float(result.residual.max()),
               sturm_count=result.sturm_count, freq_hz=result.freq_hz, omega2=result.omega2,
               sigma=result.sigma)
    return row


# --- references -----------------------------------------------------------------------

def reference_frequencies(model, sigma, solver):
    """Lowest N_MODES ω² by an independent solver; returns (omega2, seconds)."""
    K, M = model.K_free, model.M_free
    start = time.perf_counter()
    if solver == "dense":
        omega2 = sla.eigh(K.toarray(), M.toarray(), subset_by_index=[0, N_MODES - 1],
                          eigvals_only=True)
    else:  # scipy default: splu with COLAMD and partial pivoting inside eigsh
        v0 = np.random.default_rng(1).standard_normal(K.shape[0])
        omega2 = np.sort(spla.eigsh(K.tocsc(), N_MODES, M.tocsc(), sigma=sigma, which="LM",
                                    v0=v0, return_eigenvectors=False))
    return omega2, time.perf_counter() - start


def counted_eigsh(K, M, k: int, sigma: float, factor, return_eigenvectors: bool = True):
    """scipy's ``eigsh`` (ARPACK), shift-invert at ``sigma`` (rad²/s²) with ``factor`` (a
    factorisation of ``K - σM`` with ``solve``) as ``OPinv``, tol = 0, a start vector of
    ones and one thread in its loop: the reference algorithm on a given factor.

    Returns the ``k`` eigenvalues ω² (rad²/s², ascending) and the number of solves ARPACK
    made. ``return_eigenvectors`` is passed to ``eigsh``.
    """
    n = K.shape[0]
    count = [0]

    def solve(x):
        count[0] += 1
        return factor.solve(x)

    op = spla.LinearOperator((n, n), matvec=solve, dtype=float)
    with femmech.solve.threads.solve_phase():
        result = spla.eigsh(K, k=k, M=M, sigma=sigma, which="LM", OPinv=op, v0=np.ones(n),
                            tol=0, return_eigenvectors=return_eigenvectors)
    omega2 = result[0] if return_eigenvectors else result
    return np.sort(omega2), count[0]


def frequency_error(omega2, omega2_ref, scale):
    """Max relative error of the elastic frequencies; rigid modes compared absolutely."""
    n = min(len(omega2), len(omega2_ref))
    a, b = omega2[:n], omega2_ref[:n]
    elastic = np.abs(b) > 1e-9 * scale
    f, f_ref = np.sqrt(np.clip(a[elastic], 0, None)), np.sqrt(b[elastic])
    rel = np.abs(f - f_ref) / f_ref
    rigid_ok = np.all(np.abs(a[~elastic]) <= 1e-9 * scale)
    return float(rel.max()) if rel.size else 0.0, bool(rigid_ok)


def reference_rows(model, solved, with_slow, timing_history):
    """Accuracy and speed references of one model (dense LAPACK where feasible, then eigsh)."""
    n = model.n_free
    solvers = (["dense"] if n <= DENSE_REFERENCE_DOFS else []) + ["eigsh"]
    return [_reference(model, solved, solver, with_slow, timing_history) for solver in solvers]


def _reference(model, solved, solver, with_slow, timing_history):
    n = model.n_free
    label = ("scipy.linalg.eigh (dense LAPACK)" if solver == "dense"
             else "eigsh, default SuperLU (COLAMD, partial pivoting)")
    row = {"reference": label, "ref_s": None, "ref_note": ""}
    if solver == "eigsh" and n > SLOW_REFERENCE_DOFS and not with_slow:
        row["ref_note"] = _skip_note(n, timing_history, " (--with-slow-reference)")
        return row
    omega2_ref, seconds = reference_frequencies(model, solved["sigma"], solver)
    if solver == "eigsh":
        timing_history.append((n, seconds))
    scale = femmech.solve.pencil.eigenvalue_scale(model.K_free, model.M_free)
    err, rigid_ok = frequency_error(solved["omega2"], omega2_ref, scale)
    row.update(ref_s=seconds, max_rel_err=err, rigid_ok=rigid_ok)
    return row


def _skip_note(n, history, hint):
    """Skip message with an n² extrapolation from the largest eigsh reference run."""
    if not history:
        return "skipped" + hint
    n0, t0 = max(history)
    return f"skipped (> {t0 * (n / n0) ** 2:.0f} s estimated){hint}"


def loop_assembly(mesh):
    """Reference: element routine per element in a Python loop, triplets, one COO → CSR."""
    prop_row = _property_arrays()
    lines = mesh.cells["line"]
    R_orient = femmech.fe.model._orientations(mesh, lines, np.zeros(len(lines), dtype=int),
                                           [fm.BeamProperty(SECTION, STEEL)])
    rows, cols, kv, mv = [], [], [], []
    for e in range(len(lines)):
        Ke, Me = beam_matrices(mesh.points, lines[e:e + 1], R_orient[e], *prop_row)
        dofs = np.concatenate([6 * lines[e, 0] + np.arange(6), 6 * lines[e, 1] + np.arange(6)])
        rows.append(np.repeat(dofs, 12))
        cols.append(np.tile(dofs, 12))
        kv.append(Ke[0].ravel())
        mv.append(Me[0].ravel())
    n = 6 * mesh.n_nodes
    ij = (np.concatenate(rows), np.concatenate(cols))
    K = sp.coo_matrix((np.concatenate(kv), ij), shape=(n, n)).tocsr()
    M = sp.coo_matrix((np.concatenate(mv), ij), shape=(n, n)).tocsr()
    K.sum_duplicates()
    M.sum_duplicates()
    return K, M


def vector_assembly(mesh):
    """The vectorised path of ``build_model`` (element matrices + one COO → CSR each)."""
    lines = mesh.cells["line"]
    orient = femmech.fe.model._orientations(mesh, lines, np.zeros(len(lines), dtype=int),
                                         [fm.BeamProperty(SECTION, STEEL)])
    Ke, Me = beam_matrices(mesh.points, lines, orient, *_property_arrays())
    edofs = element_dofs(lines)
    n = 6 * mesh.n_nodes
    return femmech.fe.model.assemble([(edofs, Ke)], n), femmech.fe.model.assemble([(edofs, Me)], n)


def _property_arrays():
    row = femmech.fe.model._property_row(fm.BeamProperty(SECTION, STEEL))
    E, G, rho, A, Iy, Iz, J, Ip, Asy, Asz, rot, _ = row
    return E, G, rho, A, Iy, Iz, J, Ip, Asy, Asz, bool(rot)


# --- cases ----------------------------------------------------------------------------

def assembly_case(name, references=True):
    """Loop reference against the vectorised assembly, and the full ``build_model``.

    ``references=False`` skips the per-element loop.
    """
    bays, subdivisions, with_loop = ASSEMBLY[name]
    with_loop = with_loop and references
    mesh = frame_mesh(bays, subdivisions)
    row = {"table": "assembly", "case": name, "elements": len(mesh.cells["line"]),
           "dofs": 6 * mesh.n_nodes}
    start = time.perf_counter()
    K, M = vector_assembly(mesh)
    row["vector_s"] = time.perf_counter() - start
    row["loop_s"] = row["speedup"] = row["max_diff"] = None
    if with_loop:
        start = time.perf_counter()
        K_loop, M_loop = loop_assembly(mesh)
        row["loop_s"] = time.perf_counter() - start
        row["speedup"] = row["loop_s"] / row["vector_s"]
        row["max_diff"] = max(abs(A - B).max() / abs(B).max()
                              for A, B in ((K, K_loop), (M, M_loop)))
    del K, M
    _, built = build(mesh, supported=True)
    row["build_s"] = built["build_s"]
    row["build_peak_mb"] = built["build_peak_mb"]
    return row


def modes_case(name, with_slow, history, references=True):
    bays, subdivisions, supported = MODELS[name]
    mesh = frame_mesh(bays, subdivisions)
    model, row = build(mesh, supported)
    row.update(table="modes", case=name, supported=supported)
    row.update(solve(model))
    row["references"] = (reference_rows(model, row, with_slow, history) if references
                         else [])
    for key in ("omega2", "freq_hz"):
        row.pop(key)
    return row


# --- output ---------------------------------------------------------------------------

def _fmt(value, spec):
    return "-" if value is None else format(value, spec)


def _table(title, header, lines):
    widths = [max(len(h), *(len(x[i]) for x in lines)) for i, h in enumerate(header)]
    out = [title, "  ".join(h.rjust(w) for h, w in zip(header, widths, strict=True))]
    out += ["  ".join(c.rjust(w) for c, w in zip(x, widths, strict=True)) for x in lines]
    return out + [""]


def format_tables(rows) -> list[str]:
    """Plain-text tables (build, modes, reference, assembly) of the benchmark rows."""
    out = []
    modal = [r for r in rows if r["table"] == "modes"]
    if modal:
        out += _table("Build (build_model: element matrices, COO->CSR of K and M, T'KT, T'MT)",
                      ["case", "DOFs", "free DOFs", "elements", "elem s", "COO->CSR s",
                       "T'KT s", "other s", "build s", "peak MB"],
                      [[r["case"], f"{r['dofs']:,}", f"{r['free_dofs']:,}",
                        f"{r['elements']:,}", f"{r['element_s']:.2f}", f"{r['coo_csr_s']:.2f}",
                        f"{r['tkt_s']:.2f}", f"{r['other_build_s']:.2f}",
                        f"{r['build_s']:.2f}", f"{r['build_peak_mb']:.0f}"] for r in modal])
        out += _table(f"Modes (femmech.modes, {N_MODES} lowest, shift-invert + Sturm check)",
                      ["case", "free DOFs", "factor s", "Lanczos s", "Sturm s", "other s",
                       "eigen s", "peak MB", "f1, f2, f3 Hz (elastic)", "max resid",
                       "Sturm count"],
                      [[r["case"], f"{r['free_dofs']:,}", f"{r['factor_s']:.2f}",
                        f"{r['arpack_s']:.2f}", f"{r['sturm_s']:.2f}",
                        f"{r['other_eigen_s']:.2f}", f"{r['eigen_s']:.2f}",
                        f"{r['eigen_peak_mb']:.0f}",
                        ", ".join(f"{f:.3f}" for f in r["f123_hz"]),
                        f"{r['max_residual']:.1e}", _sturm(r)] for r in modal])
        references = [line for r in modal for line in _reference_lines(r)]
        if references:
            out += _table("Reference (same process): independent solve of the same K_free,"
                          " M_free",
                          ["case", "free DOFs", "reference", "ref s", "femmech s", "speedup",
                           "max rel freq err"], references)
    asm = [r for r in rows if r["table"] == "assembly"]
    if asm:
        out += _table("Assembly of K and M: per-element Python loop vs vectorised"
                      " (+ full build_model)",
                      ["case", "elements", "DOFs", "loop s", "vectorised s", "speedup",
                       "max |dK|/max|K|", "build_model s", "peak MB"],
                      [[r["case"], f"{r['elements']:,}", f"{r['dofs']:,}",
                        _fmt(r["loop_s"], ".2f"), f"{r['vector_s']:.3f}",
                        _fmt(r["speedup"], ".0f"), _fmt(r["max_diff"], ".1e"),
                        f"{r['build_s']:.2f}", f"{r['build_peak_mb']:.0f}"] for r in asm])
    return out


def _sturm(r):
    if r["sturm_count"] is None:
        return f"- ({r['method']})"
    ok = "ok" if r["sturm_count"] == r["n_modes"] else "MISMATCH"
    return f"{r['sturm_count']}/{r['n_modes']} {ok}"


def _reference_lines(r):
    lines = []
    for ref in r["references"]:
        if ref["ref_s"] is None:
            lines.append([r["case"], f"{r['free_dofs']:,}", ref["reference"], ref["ref_note"],
                          f"{r['eigen_s']:.2f}", "-", "-"])
            continue
        err = f"{ref['max_rel_err']:.1e}"
        if r["n_rigid"]:
            err += f" (+{r['n_rigid']} rigid {'ok' if ref['rigid_ok'] else 'WRONG'})"
        lines.append([r["case"], f"{r['free_dofs']:,}", ref["reference"], f"{ref['ref_s']:.2f}",
                      f"{r['eigen_s']:.2f}", f"{ref['ref_s'] / r['eigen_s']:.1f}x", err])
    return lines


# --- entry points ---------------------------------------------------------------------

def main(sizes=("small", "medium", "large"), with_slow_reference=False,
         out_file=Path(__file__).parent / "results" / "frame_modes.txt", echo=True,
         cases=None, references=True):
    """Run the benchmark for ``sizes`` (keys of SIZE_CASES); return one dict per table row.

    Rows carry ``"table"`` (``"modes"`` or ``"assembly"``), ``"case"`` and the timings (s),
    peak memory (MB), frequencies (Hz), residuals and reference errors shown in the tables.
    ``cases = (modal names, assembly names)`` (keys of MODELS and ASSEMBLY) runs those
    instead of ``sizes``; ``references=False`` skips the independent reference solves and
    the per-element loop assembly (benchmarks/run.py's assembly entry).
    """
    if cases is not None:
        unknown = ([c for c in cases[0] if c not in MODELS]
                   + [c for c in cases[1] if c not in ASSEMBLY])
        if unknown:
            raise ValueError(f"unknown cases {unknown}; choose from {list(MODELS)} and"
                             f" {list(ASSEMBLY)}")
        plan = [tuple(cases)]
    else:
        unknown = [s for s in sizes if s not in SIZE_CASES]
        if unknown:
            raise ValueError(f"unknown sizes {unknown}; choose from {list(SIZE_CASES)}")
        plan = [SIZE_CASES[size] for size in sizes]
    rows, history = [], []
    for modal, assembly in plan:
        for name in assembly:
            rows.append(assembly_case(name, references))
            gc.collect()
        for name in modal:
            rows.append(modes_case(name, with_slow_reference, history, references))
            gc.collect()
            if echo:
                print(f"... {name} done", file=sys.stderr, flush=True)
    publish("\n".join(machine_info() + [""] + format_tables(rows)), out_file, echo)
    return rows


def write_report(out_file, text: str) -> Path:
    """Write a result table atomically (its folder is created if needed)."""
    out_file = Path(out_file)
    out_file.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(out_file) as tmp:
        tmp.write_text(text + "\n")
    return out_file


def publish(text: str, out_file=None, echo: bool = True) -> None:
    """Print a report (``echo``) and write it to ``out_file`` (None: not written)."""
    if echo:
        print(text)
    if out_file is not None:
        write_report(out_file, text)


def _cli(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="small,medium,large",
                        help=f"comma-separated subset of {','.join(SIZE_CASES)}")
    parser.add_argument("--with-slow-reference", action="store_true",
                        help="also run scipy's default eigsh above"
                             f" {SLOW_REFERENCE_DOFS:,} free DOFs (the 1M-DOF model)")
    args = parser.parse_args(argv)
    main(tuple(s.strip() for s in args.sizes.split(",") if s.strip()),
         with_slow_reference=args.with_slow_reference)


if __name__ == "__main__":
    _cli()
