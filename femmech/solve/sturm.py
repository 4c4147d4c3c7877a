"""Sturm-sequence checks of ``K x = λ M x``: how many eigenvalues lie below a cut
(Sylvester's law of inertia, :func:`inertia_below`), where the cut above the last wanted
eigenvalue lies, and how many eigenvalues to return so that a cluster of equal ones is
not cut (:func:`_complete_cluster`).

Stage 1, solve (linear algebra): imports only :mod:`femmech.errors` and other
:mod:`femmech.solve` modules, never :mod:`femmech.fe` or higher.
"""

from __future__ import annotations

import numpy as np

from femmech.solve.factor import Factor
from femmech.solve.pencil import factorize


def inertia_below(K, M, cut: float, like=None) -> int | None:
    """Number of eigenvalues of ``K x = λ M x`` below ``cut`` (Sylvester's law of inertia).

    Counts negative pivots of a symmetric ``L D Lᵀ``-like factorisation of ``K - cut M``
    (:attr:`femmech.solve.factor.Factor.n_negative`: SuperLU in symmetric mode with diagonal
    pivoting, CHOLMOD's LDLᵀ, PARDISO's ``iparm(23)``). Returns None where the
    factorisation pivoted off the diagonal (or perturbed pivots), so that the count would
    not be the inertia. ``like``: a :class:`femmech.solve.factor.Factor` of a matrix of the same
    pattern (e.g. the shift-invert factor of ``K - σM``) whose fill-reducing ordering is
    reused (:meth:`~femmech.solve.factor.Factor.factorize_like`: no new ordering, no METIS).
    """
    A = K - cut * M
    try:
        if isinstance(like, Factor):
            lu = like.factorize_like(A, definite=False)
        else:
            lu = factorize(A, definite=False)
    except ValueError:
        return None
    return lu.n_negative


def _complete_cluster(omega2: np.ndarray, n_wanted: int, rtol: float = 1e-6) -> int:
    """Count to return so that a cluster of equal eigenvalues is not cut at ``n_wanted``.

    Equal means within ``rtol`` of the n-th eigenvalue, with a floor of ``1e-6`` times the
    largest computed one, so that rigid-body clusters (~0) and the dense solver's absolute
    round-off (~eps times the largest eigenvalue, up to ~1e-6 relative for the lowest modes
    of fine meshes) are covered. Scaling by the largest eigenvalue alone merged distinct low
    modes of pencils with a wide spectrum (returned 63 modes for 5).
    """
    n = n_wanted
    largest = np.abs(omega2).max()
    scale = max(abs(omega2[n_wanted - 1]), 1e-6 * largest, 1e-300)
    while n < len(omega2) and abs(omega2[n] - omega2[n - 1]) <= rtol * scale:
        n += 1
    return n


def _cut_above(lam: float, scale: float) -> float:
    """The Sturm cut just above ``lam``: 1e-6 of ``|lam|`` higher, at least 1e-12 of
    ``scale``."""
    return lam + 1e-6 * max(abs(lam), 1e-6 * scale)
