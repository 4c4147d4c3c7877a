"""Sturm-sequence checks of ``K x = λ M x``: how many eigenvalues lie below a cut
(Sylvester's law of inertia, :func:`inertia_below`), where the cut above the last wanted
eigenvalue lies, how many eigenvalues to return so that a cluster of equal ones is
not cut (:func:`complete_cluster`), and whether approximate eigenvalues sit at their
claimed positions in the spectrum (:func:`confirm_indices`).

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


def complete_cluster(omega2: np.ndarray, n_wanted: int, rtol: float = 1e-6) -> int:
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


def cut_above(lam: float, scale: float) -> float:
    """The Sturm cut just above ``lam``: 1e-6 of ``|lam|`` higher, at least 1e-12 of
    ``scale``."""
    return lam + 1e-6 * max(abs(lam), 1e-6 * scale)


def confirm_indices(K, M, lower: np.ndarray, upper: np.ndarray, index: np.ndarray,
                    distinct: bool = False) -> tuple[np.ndarray, int]:
    """Whether the ``index``-th eigenvalue of ``K x = λ M x`` lies above ``lower``, by counts.

    For approximate eigenvalues with claimed positions ``index`` (1-based, counted from
    the lowest eigenvalue, rigid-body ones included) and error intervals
    ``[lower, upper]`` (rad²/s²), the ``index``-th eigenvalue ``λ_index`` is at least
    ``lower`` exactly when fewer than ``index`` eigenvalues lie below ``lower``
    (:func:`inertia_below`). The upper end is not counted: for a Rayleigh-Ritz (Galerkin)
    approximation ``λ_index <= upper`` holds by the Poincaré separation theorem; it only
    groups the counts.

    One count at a cut ``c`` that gives ``m`` decides every entry with ``lower <= c`` and
    ``m < index`` (confirmed: ``λ_index >= c >= lower``) and every entry with
    ``lower >= c`` and ``m >= index`` (not confirmed). The cuts are chosen so that they
    are shared: first one per group of intervals with a common point (at the group's
    highest ``lower``; several modes of a cluster or of a coarse reduction), then one at
    ``lower`` of each entry still undecided. Each count is one indefinite factorisation
    of ``K - c M`` (the first one's fill-reducing ordering is reused,
    :meth:`~femmech.solve.factor.Factor.factorize_like`); well-separated, tight intervals
    need one count each. ``lower <= 0`` is confirmed without a count (K is positive
    semi-definite). An entry whose count cannot be made (off-diagonal pivots) stays
    unconfirmed.

    ``distinct=True`` takes each interval to hold an eigenvalue of its own (what an
    error bound of each approximation asserts) and starts with one count just above the
    highest interval: if it finds exactly ``max(index)`` eigenvalues, entry k is confirmed
    wherever its ``lower`` is not above that of a higher entry (if ``λ_k`` were below it,
    the ``max(index) - k + 1`` entries from k up would need distinct eigenvalues among
    the ``max(index) - k`` above ``λ_k``). Well-separated accurate approximations then
    cost one count in all; where the count finds more (a missed eigenvalue) the
    per-entry counts above decide.

    Parameters
    ----------
    K, M : sparse (n, n)
    lower, upper : ndarray (m,)
        Interval ends, rad²/s² (``lower <= upper``).
    index : ndarray (m,) of int
        Claimed 1-based position of each approximate eigenvalue in the spectrum.

    distinct : bool
        Start with the one count above all intervals (see above).

    Returns
    -------
    confirmed : ndarray (m,) of bool
    n_counts : int
        Number of factorisations made.
    """
    lower = np.asarray(lower, dtype=float)
    upper = np.maximum(np.asarray(upper, dtype=float), lower)
    index = np.asarray(index, dtype=int)
    status = np.where(lower <= 0.0, 1, 0)  # 1 confirmed, -1 not confirmed, 0 undecided
    like, failed, n_counts = None, set(), 0

    def count(cut: float) -> int | None:
        nonlocal like, n_counts
        n_counts += 1
        A = K - cut * M
        try:
            lu = like.factorize_like(A, definite=False) if like is not None else \
                factorize(A, definite=False)
        except ValueError:
            lu = None
        m = None if lu is None else lu.n_negative
        if m is None:
            failed.add(cut)
            return None
        like = like if like is not None else lu
        open_ = status == 0
        status[open_ & (lower <= cut) & (m < index)] = 1
        status[open_ & (lower >= cut) & (m >= index)] = -1
        return m

    if distinct and np.any(status == 0):
        top = float(upper.max())
        if count(cut_above(top, abs(top))) == int(index.max()):
            order = np.argsort(index, kind="stable")
            above = np.minimum.accumulate(lower[order][::-1])[::-1]  # min over j >= k
            status[order[(status[order] == 0) & (lower[order] <= above)]] = 1

    for group in _common_point_groups(lower, upper, np.flatnonzero(status == 0)):
        group = group[status[group] == 0]
        if group.size:
            count(float(lower[group].max()))
    for j in np.argsort(index, kind="stable"):
        if status[j] == 0 and float(lower[j]) not in failed:
            count(float(lower[j]))
        if status[j] == 0:  # no count at its own lower end could be made
            status[j] = -1
    return status > 0, n_counts


def _common_point_groups(lower, upper, open_) -> list[np.ndarray]:
    """Runs of consecutive intervals (in order of ``lower``) that share a point."""
    groups, current, top, bottom = [], [], -np.inf, np.inf
    for j in open_[np.argsort(lower[open_], kind="stable")]:
        if current and max(top, lower[j]) > min(bottom, upper[j]):
            groups.append(np.array(current))
            current, top, bottom = [], -np.inf, np.inf
        current.append(j)
        top, bottom = max(top, lower[j]), min(bottom, upper[j])
    if current:
        groups.append(np.array(current))
    return groups


