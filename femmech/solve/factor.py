"""The interface of a sparse direct factorisation of a symmetric matrix: :class:`Factor`.

``solve`` (vector or block right-hand sides), the inertia count ``n_negative``,
``pivots``, ``refactor`` and ``factorize_like``; the backends :mod:`.superlu`,
:mod:`.cholmod` and :mod:`.pardiso` implement it, :func:`femmech.solve.direct.factorize`
picks one. Also the checks the backends share (square input, the "singular" error).

Stage 1, solve (linear algebra): imports only :mod:`femmech.errors` and other
:mod:`femmech.solve` modules, never :mod:`femmech.fe` or higher.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


class Factor:
    """A factorised symmetric matrix A (n × n).

    Attributes
    ----------
    name : str
        Backend (``"superlu"``, ``"cholmod"`` or ``"pardiso"``).
    n : int
        Order of A.
    definite : bool
        True if A was found positive definite (Cholesky / SPD mode succeeded, or no
        negative pivot).
    timings : dict[str, float]
        Seconds of the last ``analyse`` (symbolic) and ``factorise`` (numeric) phases.
    """

    name = "?"

    def __init__(self, n: int, order=None):
        self.n = n
        # a given elimination order: the backend factorises P A Pᵀ in natural order
        self._order = None if order is None else np.asarray(order)
        self._definite = False
        self.timings = {"analyse": 0.0, "factorise": 0.0}

    @property
    def definite(self) -> bool:
        """True if A was found positive definite (no negative pivot)."""
        return self._definite

    def solve(self, b) -> np.ndarray:
        """``A⁻¹ b`` for b of shape (n,) or (n, k); same shape as b."""
        b = np.asarray(b, dtype=float)
        if b.ndim not in (1, 2) or b.shape[0] != self.n:
            raise ValueError(f"right-hand side of shape {b.shape} for a {self.n}x{self.n}"
                             " factor: expected (n,) or (n, k)")
        if b.size == 0:
            return np.zeros(b.shape)
        if self._order is None:
            return self._solve(b)
        x = np.empty_like(b)
        x[self._order] = self._solve(np.ascontiguousarray(b[self._order]))
        return x

    def _in_order(self, A):
        """A as CSC, permuted to ``P A Pᵀ`` where an elimination order was given."""
        A = sp.csc_matrix(A, dtype=float)
        return A if self._order is None else A[self._order][:, self._order].tocsc()

    def _rows(self, rows):
        """Rows of A for rows of the (permuted) factorised matrix."""
        return rows if self._order is None else self._order[rows]

    def _same_order(self, A, what: str):
        """A as a square sparse matrix of this factor's order (ValueError otherwise)."""
        A = square_matrix(A)
        if A.shape[0] != self.n:
            raise ValueError(f"{what}: matrix of order {A.shape[0]}, factor of order {self.n}")
        return A

    @property
    def n_negative(self) -> int | None:
        """Number of negative eigenvalues of A (negative pivots); None if the pivoting
        does not allow the count (off-diagonal pivots, perturbed pivots)."""
        raise NotImplementedError

    def pivots(self) -> tuple[np.ndarray, np.ndarray]:
        """Diagonal pivots in elimination order and the index of A's row of each, (n,)×2.

        For positive definite A every pivot lies in ``[λ_min(A), A_jj]``; a pivot of
        round-off size relative to its diagonal entry marks a (numerically) singular A.
        """
        raise NotImplementedError

    def refactor(self, A) -> Factor:
        """Factorise new values ``A`` of the same sparsity pattern in place; returns self."""
        raise NotImplementedError

    def factorize_like(self, A, definite: bool | None = None) -> Factor:
        """A new factorisation of ``A`` (same order, e.g. ``K - cut M`` after ``K - σM``)
        with this factor's fill-reducing ordering, so that no ordering is computed again.

        This factor stays valid. SuperLU and CHOLMOD factorise the permuted matrix in
        natural order (SuperLU with diagonal pivots, CHOLMOD with LDLᵀ for
        ``definite=False``, so that :attr:`n_negative` is the inertia); PARDISO takes the ordering
        as a user permutation (``iparm(5) = 1``: the symbolic analysis runs without METIS,
        0.11 s instead of 0.35 s on a 151k-DOF frame). ``definite`` as in
        :func:`femmech.solve.direct.factorize`.
        """
        return self._like(self._same_order(A, "factorize_like"), definite)

    def _like(self, A, definite):
        raise NotImplementedError

    def __reduce__(self):
        # a factorisation is a cache of its process (library handles, native memory):
        # it unpickles as None, and the receiver factorises again where it needs one
        return (_dropped, ())

    def __repr__(self) -> str:
        kind = "definite" if self.definite else "indefinite"
        return f"<Factor {self.name} n={self.n} {kind}>"


def _dropped():
    return None


def square_matrix(A, what="A"):
    A = A if sp.issparse(A) else sp.csc_matrix(np.asarray(A, dtype=float))
    if A.ndim != 2 or A.shape[0] != A.shape[1]:
        raise ValueError(f"{what} must be a square matrix, got shape {A.shape}")
    return A


def singular_error(exc) -> ValueError:
    return ValueError(f"matrix is singular and cannot be factorised ({exc})")
