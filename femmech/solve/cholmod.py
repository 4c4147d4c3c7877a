"""CHOLMOD backend of :mod:`femmech.solve.direct` (scikit-sparse's ``sksparse.cholmod``).

Supernodal/simplicial LLᵀ for positive definite A, simplicial LDLᵀ (no pivoting,
inertia from D) otherwise. ``refactor`` reuses the analysis (``cholesky_inplace``).
scikit-sparse is imported when a factor is made, so this module loads without it.

Stage 1, solve (linear algebra): imports only :mod:`femmech.errors` and other
:mod:`femmech.solve` modules, never :mod:`femmech.fe` or higher.
"""

from __future__ import annotations

import time

import numpy as np

from femmech.solve import threads
from femmech.solve.factor import Factor, singular_error, square_matrix


class CholmodFactor(Factor):
    """CHOLMOD (scikit-sparse): LLᵀ for positive definite A, simplicial LDLᵀ otherwise."""

    name = "cholmod"

    def __init__(self, A, definite: bool | None = None, order=None):
        from sksparse import cholmod
        self._cholmod = cholmod
        A = square_matrix(A)
        super().__init__(A.shape[0], order)
        self._want = definite
        A = self._in_order(A)
        if definite is False:
            self._analyse(A, "simplicial")
            self._numeric(A)
            return
        self._analyse(A, "auto")
        try:
            self._numeric(A)
        except ValueError:
            if definite:
                raise
            self._analyse(A, "simplicial")  # LLᵀ failed: indefinite, LDLᵀ keeps the count
            self._numeric(A)

    def _analyse(self, A, mode):
        start = time.perf_counter()
        with threads.factor_phase():
            self._f = self._cholmod.analyze(A, mode=mode, ordering_method="default"
                                            if self._order is None else "natural")
        self._mode = mode
        self.timings = {"analyse": time.perf_counter() - start, "factorise": 0.0}

    def _numeric(self, A):
        start = time.perf_counter()
        try:
            with threads.factor_phase():
                self._f.cholesky_inplace(A)
        except self._cholmod.CholmodNotPositiveDefiniteError as exc:
            if self._mode == "simplicial" and self._want is not True:
                raise singular_error(exc) from exc  # an LDLᵀ stops only on a zero pivot
            raise ValueError(f"matrix is not positive definite ({exc})") from exc
        self.timings["factorise"] = time.perf_counter() - start
        d = self._f.D()
        if not np.all(np.isfinite(d)) or not np.all(d != 0):
            raise singular_error("zero or non-finite pivot")
        self._d = d
        self._definite = bool(np.all(d > 0))
        if self._want and not self.definite:
            raise ValueError(f"matrix is not positive definite ({self.n_negative} negative"
                             " pivots)")

    def _solve(self, b):
        return self._f.solve_A(b)

    @property
    def n_negative(self):
        return int(np.count_nonzero(self._d < 0))

    def pivots(self):
        return self._d.copy(), self._rows(np.asarray(self._f.P()).copy())

    def _like(self, A, definite):
        return CholmodFactor(A, definite, order=self.pivots()[1])

    def refactor(self, A):
        A = self._in_order(self._same_order(A, "refactor"))
        try:
            self._numeric(A)
        except ValueError:
            if self._mode == "simplicial" or self._want:
                raise
            self._analyse(A, "simplicial")  # new values no longer positive definite
            self._numeric(A)
        return self
