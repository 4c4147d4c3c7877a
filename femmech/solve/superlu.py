"""SuperLU backend of :mod:`femmech.solve.direct`: scipy's SuperLU in symmetric mode.

Minimum degree on ``Aᵀ + A`` and diagonal pivots, so that the factors keep A's
symmetric structure and the negative pivots count A's negative eigenvalues; always
available. No separate symbolic phase: ``refactor`` factorises anew.

Stage 1, solve (linear algebra): imports only :mod:`femmech.errors` and other
:mod:`femmech.solve` modules, never :mod:`femmech.fe` or higher.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse.linalg as spla

from femmech.solve import threads
from femmech.solve.factor import Factor, singular_error, square_matrix


class SuperLUFactor(Factor):
    """SuperLU in symmetric mode. ``lu`` is the :class:`scipy.sparse.linalg.SuperLU`."""

    name = "superlu"

    def __init__(self, A, pivot_threshold: float = 0.0, order=None):
        A = square_matrix(A)
        super().__init__(A.shape[0], order)
        self.pivot_threshold = float(pivot_threshold)
        self._factor(A)

    def _factor(self, A):
        start = time.perf_counter()
        try:
            self.lu = spla.splu(self._in_order(A),
                                permc_spec="MMD_AT_PLUS_A" if self._order is None else "NATURAL",
                                diag_pivot_thresh=self.pivot_threshold,
                                options={"SymmetricMode": True})
        except RuntimeError as exc:
            raise singular_error(exc) from exc
        self.timings = {"analyse": 0.0, "factorise": time.perf_counter() - start}

    def _solve(self, b):
        return self.lu.solve(b)

    @property
    def n_negative(self):
        if not np.array_equal(self.lu.perm_r, self.lu.perm_c):
            return None
        return int(np.count_nonzero(self.lu.U.diagonal() < 0))

    @property
    def definite(self):
        return self.n_negative == 0

    def pivots(self):
        return self.lu.U.diagonal(), self._rows(np.argsort(self.lu.perm_c))

    def refactor(self, A):
        self._factor(self._same_order(A, "refactor"))  # SuperLU keeps no analysis to reuse
        return self

    def _like(self, A, definite):
        with threads.factor_phase():  # diagonal pivots: n_negative is the inertia
            return SuperLUFactor(A, 0.0, order=self.pivots()[1])

    def __getattr__(self, name):  # perm_c, perm_r, L, U, nnz of the SuperLU object
        if name == "lu":
            raise AttributeError(name)
        return getattr(self.lu, name)
