"""MKL PARDISO backend of :mod:`femmech.solve.direct`, through a ctypes binding of ``libmkl_rt``.

Loads ``libmkl_rt`` (pip package ``mkl``, or ``FEMMECH_MKL_RT``) once; SPD mode
(mtype 2, Cholesky) for positive definite A, symmetric indefinite mode (mtype -2,
Bunch-Kaufman pivoting within supernodes) otherwise, with the number of negative
eigenvalues from ``iparm(23)``. ``refactor`` runs phase 22 only. Wide blocks of
right-hand sides on sparse factors are solved column by column, split between
copies of the factor (:data:`PARALLEL_SOLVE_COLUMNS`).

Stage 1, solve (linear algebra): imports only :mod:`femmech.errors` and other
:mod:`femmech.solve` modules, never :mod:`femmech.fe` or higher.
"""

from __future__ import annotations

import ctypes
import importlib.metadata
import os
import time
import weakref
from concurrent.futures import ThreadPoolExecutor
from ctypes.util import find_library
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from femmech.solve import threads
from femmech.solve.factor import Factor, singular_error, square_matrix

_MKL = None

PARDISO_SOLVE_MODE = 1
"""iparm(25), the algorithm of the forward/backward substitution. With MKL's default (0)
one solve of a 20 000-unknown tridiagonal system took 16 ms, with 1 it took 1.1 ms
(MKL 2026.2, 2 threads, this 2-core machine under load); block solves of 200 right-hand
sides on a 24k-DOF frame took the same time with 0, 1 and 2."""

PARDISO_LOOP_FILL = 50
"""Factor nonzeros per row below which blocks of right-hand sides are solved one column
at a time: for such sparse factors (beam frames) PARDISO's multi-right-hand-side solve is
slower than a loop. 151k-DOF beam frame (factor 2.4M nonzeros, 16 per row; one thread):
2 columns took 39 ms against 2 x 5.4 ms one at a time, 16 columns 111 ms against 77 ms,
32 columns 185 against 155 ms, the 1 002 constraint modes of a rails interface 13.7 s
against 7.4 s. On shells the block solve wins: 59k-DOF shell frame (9.4M nonzeros, 161
per row) 2 columns 25 ms against 27 ms, 8 columns 53 ms against 106 ms, 28 columns
0.13 s against 0.39 s."""

PARALLEL_SOLVE_COLUMNS = 96
"""Blocks of at least this many right-hand sides on a sparse PARDISO factor (the column
loop of :data:`PARDISO_LOOP_FILL`) are split between concurrent solves on copies of the
factor, one per *factor* thread (:mod:`femmech.solve.threads`), each single-threaded. A loop
of single solves does not use the second core; two handles do: 128 columns of the
151k-DOF frame took 4.65 ms per column instead of 7.62 ms, with identical results. Each
copy is a second numeric factorisation on the same ordering (0.26 s there), made on first
use and kept with the factor, so the count pays off from about a hundred columns
(constraint modes and residual vectors of wide interfaces)."""

PARALLEL_SOLVE_MAX_BYTES = 2 * 1024**3
"""Factors larger than this (nonzeros x 8 bytes) are not copied for parallel solves."""

PARDISO_PERTURBATION = 13
"""iparm(10): pivots below 1e-13 ‖A‖ are perturbed (round-off level). A factorisation
with perturbed pivots is reported as singular (ValueError), like SuperLU's zero pivot:
neither its solves nor its inertia count could be trusted."""


def _mkl_library_candidates():
    env = os.environ.get("FEMMECH_MKL_RT")
    if env:
        yield env
    try:
        files = importlib.metadata.files("mkl") or []
    except importlib.metadata.PackageNotFoundError:
        files = []
    for f in files:
        if f.name.startswith("libmkl_rt.so") or f.name in ("libmkl_rt.dylib", "mkl_rt.2.dll"):
            yield str(Path(f.locate()).resolve())
    found = find_library("mkl_rt")
    if found:
        yield found


def mkl_library():
    """``libmkl_rt`` with ``pardiso`` prototyped (loaded once), or None if not installed."""
    global _MKL
    if _MKL is None:
        _MKL = False
        # Intel OpenMP threads spin 200 ms after each parallel region by default: under
        # load on 2 cores that stole the CPU from the next solve (up to 20x slower runs)
        os.environ.setdefault("KMP_BLOCKTIME", "0")
        for path in _mkl_library_candidates():
            try:
                lib = ctypes.CDLL(path)
                lib.pardiso  # noqa: B018 (symbol lookup)
            except (OSError, AttributeError):
                continue
            lib.MKL_Set_Interface_Layer(0)  # LP64: 32-bit integers, as prototyped below
            i32 = ctypes.POINTER(ctypes.c_int32)
            vp = ctypes.c_void_p
            lib.pardiso.argtypes = [vp, i32, i32, i32, i32, i32, vp, vp, vp, vp, i32, vp, i32,
                                    vp, vp, i32]
            lib.pardiso.restype = None
            lib.pardiso_getdiag.argtypes = [vp, vp, vp, i32, i32]
            lib.pardiso_getdiag.restype = None
            _MKL = lib
            threads.refresh()  # MKL's threads are limited from now on
            break
    return _MKL or None


def mkl_version() -> str | None:
    """MKL's version string, or None if MKL is not installed."""
    lib = mkl_library()
    if lib is None:
        return None
    buf = ctypes.create_string_buffer(256)
    lib.MKL_Get_Version_String(buf, 256)
    return buf.value.decode(errors="replace")


_PARDISO_ERRORS = {
    -1: "input inconsistent", -2: "not enough memory", -3: "reordering problem",
    -4: "zero pivot (numerically singular or, in SPD mode, not positive definite)",
    -5: "unclassified internal error", -6: "reordering failed", -7: "diagonal matrix problem",
    -8: "32-bit integer overflow", -9: "not enough memory for out-of-core",
    -10: "error opening out-of-core files", -11: "read/write error with out-of-core files",
}


def _upper_csr(A):
    """Upper triangle with every diagonal entry stored (PARDISO's symmetric input)."""
    A = square_matrix(A).tocoo()
    keep = A.row <= A.col
    n = A.shape[0]
    diag = np.arange(n)
    rows = np.concatenate([A.row[keep], diag])
    cols = np.concatenate([A.col[keep], diag])
    vals = np.concatenate([A.data[keep].astype(float), np.zeros(n)])
    U = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))  # sums duplicates, keeps zeros
    U.sort_indices()
    return U


def _release(lib, pt, mtype):
    """Free PARDISO's internal memory (phase -1)."""
    i = ctypes.c_int32
    one, zero, err = i(1), i(0), i(0)
    iparm = np.zeros(64, dtype=np.int32)
    dummy = np.zeros(1)
    idx = np.zeros(1, dtype=np.int32)
    lib.pardiso(pt.ctypes.data, ctypes.byref(one), ctypes.byref(one), ctypes.byref(i(mtype)),
                ctypes.byref(i(-1)), ctypes.byref(zero), dummy.ctypes.data, idx.ctypes.data,
                idx.ctypes.data, None, ctypes.byref(one), iparm.ctypes.data,
                ctypes.byref(zero), None, None, ctypes.byref(err))


class PardisoFactor(Factor):
    """MKL PARDISO: mtype 2 (SPD) for positive definite A, mtype -2 otherwise."""

    name = "pardiso"

    def __init__(self, A, definite: bool | None = None, perm=None):
        lib = mkl_library()
        if lib is None:
            raise ImportError("MKL PARDISO needs the pip package 'mkl' (femmech[fast])")
        self._lib = lib
        U = _upper_csr(A)
        super().__init__(U.shape[0])
        self._want = definite
        self._user_perm = None if perm is None else np.array(perm, dtype=np.int32)
        self._pattern = (U.indptr.astype(np.int32), U.indices.astype(np.int32))
        if definite is False:
            self._setup(-2, U)
            return
        try:
            self._setup(2, U)
        except ValueError:
            if definite:
                raise
            self._setup(-2, U)

    def _setup(self, mtype, U):
        if getattr(self, "_finalizer", None) is not None:
            self._finalizer()
        self.mtype = mtype
        self.pt = np.zeros(64, dtype=np.int64)
        user = self._user_perm is not None
        self.perm = self._user_perm.copy() if user else np.zeros(self.n, dtype=np.int32)
        self.iparm = np.zeros(64, dtype=np.int32)
        p = self.iparm
        p[0] = 1     # no defaults: the settings below
        p[1] = 2     # nested dissection ordering (METIS)
        p[4] = 1 if user else 2  # take the ordering from perm / return it in perm
        p[7] = 0     # iterative refinement: automatic (2 steps after perturbed pivots)
        p[9] = PARDISO_PERTURBATION if mtype == -2 else 13
        p[10] = 0    # no scaling (symmetric)
        p[12] = 0    # no weighted matching (symmetric)
        p[17] = -1   # report nnz of the factors in iparm(18)
        p[20] = 1    # Bunch-Kaufman 1x1 and 2x2 pivots (mtype -2)
        p[24] = PARDISO_SOLVE_MODE
        p[26] = 0    # no matrix checker
        p[27] = 0    # double precision
        p[34] = 1    # zero-based indices
        p[55] = 1    # enable pardiso_getdiag
        self._finalizer = weakref.finalize(self, _release, self._lib, self.pt, mtype)
        with threads.factor_phase():
            # phases 11 and 22 must see the same thread count (a 2-thread analysis with a
            # 1-thread factorisation gave wrong solutions or a segmentation fault), so the
            # count of the analysis is kept for every later factorisation of this handle
            self._threads = int(self._lib.MKL_Get_Max_Threads())
            start = time.perf_counter()
            self._call(11, U.data)
        self.timings = {"analyse": time.perf_counter() - start, "factorise": 0.0}
        self._numeric(U.data)

    def _call(self, phase, a, b=None, x=None):
        i = ctypes.c_int32
        err = i(0)
        if b is None:
            b = x = np.zeros(1)  # not read in phases 11 and 22
        nrhs = 1 if b.ndim == 1 else b.shape[1]
        ia, ja = self._pattern
        self._lib.pardiso(self.pt.ctypes.data, ctypes.byref(i(1)), ctypes.byref(i(1)),
                          ctypes.byref(i(self.mtype)), ctypes.byref(i(phase)),
                          ctypes.byref(i(self.n)), a.ctypes.data, ia.ctypes.data,
                          ja.ctypes.data, self.perm.ctypes.data, ctypes.byref(i(nrhs)),
                          self.iparm.ctypes.data,
                          ctypes.byref(i(0)), b.ctypes.data, x.ctypes.data, ctypes.byref(err))
        if err.value:
            what = _PARDISO_ERRORS.get(err.value, "unknown error")
            if err.value == -4 and self.mtype == 2:
                raise ValueError(f"matrix is not positive definite (PARDISO error -4: {what})")
            if err.value == -4:
                raise singular_error(f"PARDISO error -4: {what}")
            raise RuntimeError(f"PARDISO phase {phase} failed with error {err.value}: {what}")

    def _numeric(self, a):
        self._twins = []  # copies for parallel solves hold the old values
        start = time.perf_counter()
        self._a = np.ascontiguousarray(a, dtype=float)
        with threads.exactly(self._threads):
            self._call(22, self._a)
        self.timings["factorise"] = time.perf_counter() - start
        if self.iparm[13] > 0:  # perturbed pivots: A is singular to working precision
            raise singular_error(f"PARDISO perturbed {self.iparm[13]} pivots below"
                            f" 1e-{PARDISO_PERTURBATION} of the largest entry")
        self._definite = self.mtype == 2 or self.iparm[22] == 0

    def _solve(self, b):
        if b.ndim == 2 and self.iparm[17] < PARDISO_LOOP_FILL * self.n:
            b = np.asfortranarray(b)  # contiguous columns, solved in place one by one
            x = np.empty_like(b, order="F")
            workers = self._workers(b.shape[1])
            if workers == 1:
                self._columns(b, x, range(b.shape[1]))
                return x
            handles = [self, *self._copies(workers - 1)]
            with threads.exactly(1), ThreadPoolExecutor(workers) as pool:
                # ctypes releases the GIL during each solve; columns are disjoint
                list(pool.map(lambda k: handles[k]._columns(b, x, range(k, b.shape[1],
                                                                          workers)),
                              range(workers)))
            return x
        b = np.asfortranarray(b)
        x = np.zeros_like(b, order="F")
        self._call(33, self._a, b, x)
        return np.ascontiguousarray(x)

    def _columns(self, b, x, columns):
        for j in columns:
            self._call(33, self._a, b[:, j], x[:, j])

    def _workers(self, n_columns: int) -> int:
        """Concurrent solve streams for a block (:data:`PARALLEL_SOLVE_COLUMNS`)."""
        if n_columns < PARALLEL_SOLVE_COLUMNS or 8 * int(self.iparm[17]) > \
                PARALLEL_SOLVE_MAX_BYTES:
            return 1
        return max(1, min(threads.settings().factor or self._threads, n_columns))

    def _copies(self, count: int):
        """``count`` further handles with this factor's values and ordering."""
        while len(self._twins) < count:
            ia, ja = self._pattern
            U = sp.csr_matrix((self._a, ja, ia), shape=(self.n, self.n))
            self._twins.append(PardisoFactor(U, definite=self.mtype == 2, perm=self.perm))
        return self._twins[:count]

    @property
    def n_negative(self):
        return 0 if self.mtype == 2 else int(self.iparm[22])

    def pivots(self):
        df = np.zeros(self.n)
        da = np.zeros(self.n)
        err = ctypes.c_int32(0)
        self._lib.pardiso_getdiag(self.pt.ctypes.data, df.ctypes.data, da.ctypes.data,
                                  ctypes.byref(ctypes.c_int32(1)), ctypes.byref(err))
        if err.value:
            raise RuntimeError(f"pardiso_getdiag failed with error {err.value}")
        return df, self.perm.astype(np.int64)  # df is in elimination order (iparm(5) = 2)

    def refactor(self, A):
        U = _upper_csr(self._same_order(A, "refactor"))
        ia, ja = self._pattern
        if not (np.array_equal(U.indptr, ia) and np.array_equal(U.indices, ja)):
            raise ValueError("refactor: the sparsity pattern differs from the analysed one;"
                             " call factorize for a new pattern")
        try:
            self._numeric(U.data)
        except ValueError:
            if self.mtype == -2 or self._want:
                raise
            self._setup(-2, U)  # new values no longer positive definite
        return self

    def _like(self, A, definite):
        return PardisoFactor(A, definite, perm=self.perm)
