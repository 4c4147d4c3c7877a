"""Sparse symmetric eigen solver with shift-invert, Sturm-sequence checks and a dense path.

Solves ``K x = λ M x`` (``λ = ω²``, rad²/s²) for symmetric positive semi-definite K and M.
K may be singular (free-free structures): the shift σ is chosen below zero so that
``K - σ M`` is regular and never a singular K is factorised. M may be singular
(massless DOFs): their infinite eigenvalues are never returned.

This module is the driver (:func:`solve_symmetric`, its result :class:`EigenResult`): it
checks the request, takes the dense path (:mod:`.dense`) for small systems and otherwise
one of the sparse paths, the lowest modes (ARPACK, :mod:`.arpack`, below
:data:`ARPACK_BELOW` DOFs, else block Lanczos, :mod:`.lanczos`), a band from zero, or a
band (ARPACK), all verified by Sturm counts (:mod:`.sturm`);
it normalises the modes and checks their residuals (:mod:`.residuals`).

Stage 1, solve (linear algebra): imports only :mod:`femmech.errors` and other
:mod:`femmech.solve` modules, never :mod:`femmech.fe` or higher.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy.sparse.linalg import ArpackNoConvergence

from femmech.errors import FemmechWarning
from femmech.solve import direct, tolerances
from femmech.solve.arpack import arpack
from femmech.solve.dense import dense_symmetric
from femmech.solve.lanczos import FarShiftError, lowest_pairs
from femmech.solve.pencil import default_shift, eigenvalue_scale, factorize, n_mass
from femmech.solve.residuals import (
    normalize_modes,
    residual_limits,
    residual_message,
    residual_terms,
)
from femmech.solve.sturm import complete_cluster, cut_above, inertia_below

MAX_DEFLATIONS = 10
"""Deflated Lanczos restarts allowed to complete a set that the Sturm count shows short."""

DENSE_BELOW = tolerances.DENSE_BELOW
"""Systems with fewer DOFs than this are solved with dense LAPACK
(:func:`~.dense.dense_symmetric`; :data:`femmech.solve.tolerances.DENSE_BELOW`)."""

ARPACK_BELOW = 30_000
"""Below this many DOFs, :func:`_sparse_lowest` with the Sturm check runs ARPACK for the
wanted pairs and :data:`ARPACK_GUARD` more, instead of block Lanczos with
``max(4, n/5)`` guard pairs: the count just above the last wanted eigenvalue shows
whether a member of a repeated eigenvalue is missing, and deflated block-Lanczos runs add
it, so fewer guards are needed. ARPACK's Fortran loop costs less per step than the Python
block-Lanczos loop where a solve is cheap. Measured (``fm.modes(model, 20)``, check
included, min of 4-7 interleaved runs in one process; benchmarks/peer_eigensolve.py
models): 5k-DOF frame 27.3 ms against 36.3 ms (block Lanczos), 24k frame 229 ms against
244 ms, but 35k P2-tetrahedron solid 4.53 s against 3.77 s and 151k frame 2.51 s against
2.08 s (expensive solves: block Lanczos solves two right-hand sides at once and needs
fewer of them)."""

ARPACK_GUARD = 1
"""Pairs beyond the wanted ones in that ARPACK run. A repeated last wanted eigenvalue
(the 20th of the symmetric 24k frame is double) is then found in the same run: with none
the count found it missing and a deflated run took the 20-mode solve from 229 ms to
367 ms. ARPACK's cost is not monotonic in k (restarts): on the 5k frame 26.3, 27.3, 36.6
and 33.7 ms for 0, 1, 2 and 3 guards; on the 24k frame 367, 229, 210, 218 ms."""

ARPACK_MAXITER = 10
"""Restarts allowed to that ARPACK run; without convergence the block-Lanczos path takes
over (it also moves a shift far below the wanted eigenvalues,
:data:`~.lanczos.FAR_SHIFT`). 20 modes of the 5k frame took 2-3 restarts with
σ/λ₁ = -0.05 … -5, 4 with σ/λ₁ = -50 and 11 with -500."""

RIGID_TOL = tolerances.RIGID_TOL
"""Eigenvalues with ``|ω²| <= RIGID_TOL * scale`` are rigid-body modes
(:data:`femmech.solve.tolerances.RIGID_TOL`, which says why 1e-12; scale: a typical
element eigenvalue, e.g. :func:`femmech.analysis.modes.model_eigenvalue_scale`)."""


@dataclass(frozen=True)
class EigenResult:
    """Eigenpairs of ``K x = λ M x``.

    Attributes
    ----------
    omega2 : ndarray (n_modes,)
        Eigenvalues λ = ω², rad²/s², ascending.
    vectors : ndarray (n_dof, n_modes)
        Mass-normalised (``XᵀMX = I``); sign fixed so the entry of largest magnitude is
        positive.
    method : str
        The algorithm that computed the pairs: ``"dense"`` (LAPACK,
        :func:`~.dense.dense_symmetric`), ``"arpack"`` (ARPACK shift-invert Lanczos: the
        lowest modes below :data:`ARPACK_BELOW` DOFs with the Sturm check, and bands away
        from zero), ``"block-lanczos"`` (femmech's block shift-invert Lanczos, the lowest
        modes otherwise; where it does not converge it falls back to ARPACK with a
        warning) or ``"sturm"`` (a band from zero that the Sturm count shows empty:
        nothing to compute).
    sigma : float
        Shift used, rad²/s².
    residual : ndarray (n_modes,)
        ``‖K x - λ M x‖ / (max(|λ|, |σ₀|) ‖M x‖)`` with
        σ₀ = :func:`~.pencil.default_shift`.
    sturm_count : int or None
        Number of eigenvalues below ``cut`` from the inertia of ``K - cut M``; it equals
        the number of returned eigenvalues below ``cut`` when nothing was missed.
    cut : float or None
        The bound (rad²/s²) of the Sturm check.
    solver : str or None
        Sparse direct solver of the shift-invert factorisation (``"superlu"``,
        ``"cholmod"``, ``"pardiso"``, see :mod:`femmech.solve.direct`); None on the dense path.
    """

    omega2: np.ndarray
    vectors: np.ndarray
    method: str
    sigma: float
    residual: np.ndarray
    sturm_count: int | None = None
    cut: float | None = None
    solver: str | None = None


def _check_request(n, n_mass, n_modes, band, sigma, factor, scale):
    """ValueError/TypeError naming the bad argument of :func:`solve_symmetric`."""
    if (n_modes is None) == (band is None):
        raise ValueError("give exactly one of n_modes and band")
    if n_modes is not None:
        if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)):
            raise TypeError(f"n_modes must be an integer, got {n_modes!r}")
        if not 0 < n_modes <= n:
            raise ValueError(f"n_modes must lie in 1..{n} (the number of free DOFs),"
                             f" got {n_modes}")
        if n_modes > n_mass:
            raise ValueError(f"n_modes={n_modes}, but only {n_mass} of the {n} DOFs carry"
                             " mass: massless DOFs have infinite eigenvalues, which are"
                             f" never returned; ask for at most {n_mass} modes")
    if band is not None and not (np.isfinite(band).all() and band[0] < band[1]):
        raise ValueError(f"band must be finite (low, high) with low < high, got {band}")
    if sigma is not None and not np.isfinite(sigma):
        raise ValueError(f"sigma must be a finite shift, got {sigma}")
    if scale is not None and not (np.isfinite(scale) and scale > 0):
        raise ValueError(f"scale must be a positive eigenvalue magnitude, got {scale}")
    if factor is not None and sigma is None:
        raise ValueError("a reused factorisation needs the shift sigma it was made with")


def solve_symmetric(K, M, n_modes: int | None = None, band: tuple[float, float] | None = None,
                    sigma: float | None = None, dense_below: int = DENSE_BELOW,
                    check: bool = True, factor=None, scale: float | None = None,
                    rigid_tol: float | None = None) -> EigenResult:
    """Lowest eigenpairs, or all eigenpairs in a band, of ``K x = λ M x``.

    Parameters
    ----------
    K, M : sparse or ndarray (n, n)
        Symmetric stiffness (positive semi-definite) and mass (positive semi-definite).
    n_modes : int, optional
        Number of lowest eigenpairs. If the n-th eigenvalue is repeated, the whole
        cluster is returned, so a degenerate subspace is never cut.
    band : (float, float), optional
        ``(λ_lo, λ_hi)`` in rad²/s²; all eigenpairs with ``λ_lo <= λ <= λ_hi``. A band
        from ``λ_lo <= rigid_tol`` (e.g. 0) holds every rigid-body mode, also those whose
        computed λ is round-off below zero: it returns all eigenpairs up to
        ``max(λ_hi, rigid_tol)`` (K is positive semi-definite), on the sparse path by the
        lowest-modes search with a shift below zero (no factorisation of a singular K).
    sigma : float, optional
        Shift; default :func:`~.pencil.default_shift` (n_modes) or the band centre (band).
    dense_below : int
        Use dense LAPACK below this size.
    check : bool
        Verify by a Sturm-sequence count that no eigenvalue was missed (one extra
        factorisation of ``K - cut M`` on the ordering of the shift's factorisation);
        members of a repeated eigenvalue that Lanczos missed are then found by deflated
        restarts. Band searches always count.
    factor : object with ``solve``, optional
        A factorisation of ``K - sigma M`` to reuse (``sigma`` must then be given), e.g.
        the ``K_ii`` factorisation of a Craig-Bampton reduction with ``sigma = 0``.
    scale : float, optional
        Typical eigenvalue magnitude, rad²/s², for the default shift (``-1e-6 scale``),
        the floor of the relative residuals and the Sturm cut; default
        :func:`~.pencil.eigenvalue_scale`. Give it when the diagonal of K does not show it, e.g.
        a K that is round-off only (a rigid body assembled from stiff elements).
    rigid_tol : float, optional
        Eigenvalues with ``|λ| <= rigid_tol`` (rad²/s²) are zero (rigid-body modes);
        default ``RIGID_TOL * scale`` (:data:`RIGID_TOL`).

    Returns
    -------
    EigenResult

    Raises
    ------
    ValueError, TypeError
        Naming the argument: both or neither of n_modes and band, n_modes not an integer
        in 1..n or above the number of DOFs with mass, a band or shift that is not finite.
    """
    n = K.shape[0]
    _check_request(n, n_mass(M), n_modes, band, sigma, factor, scale)
    scale = eigenvalue_scale(K, M) if scale is None else float(scale)
    shift = -1e-6 * scale if sigma is None else float(sigma)
    zero = RIGID_TOL * scale if rigid_tol is None else float(rigid_tol)
    if band is not None and band[0] <= zero:  # from 0: rigid modes of ω² ~ -eps too
        band = (-np.inf, max(float(band[1]), zero))
    count, cut = None, None
    if n < dense_below:
        wanted = None if band is not None else n_modes + max(4, n_modes // 5)
        omega2, X = dense_symmetric(K, M, wanted, sigma=shift)
        if wanted is not None and omega2.size == wanted and wanted < n and \
                complete_cluster(omega2, n_modes) == wanted:
            omega2, X = dense_symmetric(K, M, sigma=shift)  # a cluster fills the subset
        omega2, X = _select(omega2, X, n_modes, band)
        method = "dense"
    elif n_modes is not None:
        omega2, X, count, cut, shift, method = _sparse_lowest(K, M, n_modes, shift, factor,
                                                              check, scale,
                                                              movable=sigma is None)
    elif band[0] == -np.inf and (sigma is None or sigma < 0 or factor is not None
                                 and sigma == 0):
        omega2, X, count, cut, shift, method = _sparse_from_zero(
            K, M, band[1], shift, check, scale, movable=sigma is None, factor=factor)
    else:
        omega2, X, shift = _sparse_band(K, M, band, sigma, factor)
        method = "arpack"
    X = normalize_modes(X, M)
    num, den = residual_terms(K, M, omega2, X, 1e-6 * scale)
    res = num / np.where(den > 0, den, 1.0)
    limits = residual_limits(K, X, den)
    message = residual_message(res, limits, omega2)
    if message:
        warnings.warn(message, FemmechWarning, stacklevel=2)
    if method == "dense":
        count, cut = None, None
    solver = None if method == "dense" else (
        direct.resolve(None, n) if factor is None else getattr(factor, "name", "user"))
    return EigenResult(omega2, X, method, shift, res, count, cut, solver=solver)


def sturm_verified(K, M, omega2: np.ndarray, scale: float | None = None) -> tuple[int, int]:
    """Sturm check of eigenvalues computed with ``check=False``, made afterwards.

    Counts the eigenvalues of ``K x = λ M x`` below the cut just above ``omega2[-1]``
    (the cut of :func:`solve_symmetric`'s own check) from a new factorisation of
    ``K - cut M``. Returns ``(count, found)``: the count (-1 where the factorisation
    pivoted off the diagonal, so that no count exists) and how many of ``omega2`` lie
    below the cut; they agree when nothing was missed. For callers that free the
    shift-invert factorisation before the count, so that two factorisations are never
    held at once (:func:`femmech.reduction.component_modes.craig_bampton` on large models).

    Parameters
    ----------
    K, M : sparse (n, n)
    omega2 : ndarray (k,)
        The eigenvalues found, rad²/s².
    scale : float, optional
        Typical eigenvalue magnitude, rad²/s² (default :func:`~.pencil.eigenvalue_scale`).
    """
    omega2 = np.sort(np.asarray(omega2, dtype=float))
    scale = eigenvalue_scale(K, M) if scale is None else float(scale)
    cut = cut_above(omega2[-1], scale)
    below = inertia_below(K, M, cut)
    return (-1 if below is None else int(below)), int(np.count_nonzero(omega2 <= cut))


def _select(omega2, X, n_modes, band):
    if band is not None:
        keep = (omega2 >= band[0]) & (omega2 <= band[1])
        return omega2[keep], X[:, keep]
    count = complete_cluster(omega2, min(n_modes, len(omega2)))
    return omega2[:count], X[:, :count]


def _merge(omega2, X, more_omega2, more_X):
    omega2 = np.concatenate([omega2, more_omega2])
    order = np.argsort(omega2)
    return omega2[order], np.hstack([X, more_X])[:, order]


def _sparse_lowest(K, M, n_modes, sigma, factor=None, check=True, scale=None,
                   movable=False):
    """Lowest ``n_modes`` eigenpairs (plus the rest of a cut cluster), Sturm-checked.

    Returns ``omega2, X, sturm_count, cut, sigma, method`` (:func:`_algorithm`).
    ``movable``: σ is the default shift and may be moved nearer the wanted eigenvalues
    where it is far from them (:data:`~.lanczos.FAR_SHIFT`; one more factorisation).
    Where the Sturm count shows that a repeated eigenvalue has more members than Lanczos
    found, deflated runs add the missing ones.
    The count factorises ``K - cut M`` with the fill-reducing ordering of the shift's
    factorisation (:meth:`femmech.solve.factor.Factor.factorize_like`).
    """
    n = K.shape[0]
    scale = eigenvalue_scale(K, M) if scale is None else scale
    lu = factorize(K - sigma * M, definite=None if sigma < 0 else False) \
        if factor is None else factor
    guard = max(4, n_modes // 5)
    limit = min(n - 2, n_mass(M) - 1)  # below the Krylov dimension (and ARPACK's k < n - 1)
    guarded = True  # block Lanczos with guard pairs; False: ARPACK, the count guards
    if check and n < ARPACK_BELOW and n_modes + ARPACK_GUARD <= limit:
        try:
            omega2, X = arpack(K, M, n_modes + ARPACK_GUARD, sigma, lu,
                                maxiter=ARPACK_MAXITER)
            count, guarded = complete_cluster(omega2, n_modes), False
        except ArpackNoConvergence:
            pass  # (a shift far from the wanted eigenvalues): block Lanczos
    if guarded:
        omega2, X, count, sigma, lu, guard = _guarded_lanczos(K, M, n_modes, sigma, lu,
                                                              movable, guard, limit)
    if not check:
        return omega2[:count], X[:, :count], None, None, sigma, _algorithm(guarded)
    for _ in range(MAX_DEFLATIONS):
        # every computed eigenvalue up to the cut counts: where the cut (a relative 1e-6
        # above the last wanted one, or the absolute floor of the scale) passes further
        # computed ones, they are part of the verified set
        cut = cut_above(omega2[count - 1], scale)
        inside = int(np.count_nonzero(omega2 <= cut))
        below = inertia_below(K, M, cut, like=lu)
        if below is None and not guarded:  # no count: the guards must see a cluster
            guarded = True
            omega2, X, count, sigma, lu, guard = _guarded_lanczos(K, M, n_modes, sigma, lu,
                                                                  movable, guard, limit)
            cut = cut_above(omega2[count - 1], scale)
        if below is None:
            return omega2[:count], X[:, :count], None, cut, sigma, _algorithm(guarded)
        if below == inside:
            return omega2[:inside], X[:, :inside], below, cut, sigma, _algorithm(guarded)
        if below < inside:
            raise RuntimeError(f"Sturm check: {below} eigenvalues lie below {cut:.6g} rad²/s²"
                               f" but the solver returned {inside}")
        # eigenvalues below the cut were missed (members of a cluster): find them with the
        # found ones deflated, then count again (the cut moves down if lower ones appear)
        extra = min(below - inside + guard, n - 2 - inside)
        omega2, X = _merge(omega2[:inside], X[:, :inside],
                           *lowest_pairs(K, M, extra, sigma, lu, deflate=X[:, :inside]))
        count = complete_cluster(omega2, min(n_modes, omega2.size))
    raise RuntimeError(f"Sturm check: eigenvalues below {cut:.6g} rad²/s² still missing after"
                       f" {MAX_DEFLATIONS} deflated restarts; try another sigma")


def _algorithm(guarded: bool) -> str:
    """:attr:`EigenResult.method` of :func:`_sparse_lowest`: block Lanczos computed the pairs
    (``guarded``), or ARPACK with the Sturm count as the guard."""
    return "block-lanczos" if guarded else "arpack"


def _guarded_lanczos(K, M, n_modes, sigma, lu, movable, guard, limit):
    """The ``n_modes`` lowest pairs by block Lanczos with ``guard`` more (doubled while a
    cluster fills all computed ones), moving a far default shift (``movable``). Returns
    ``omega2, X, count`` (the wanted ones and the rest of a cut cluster), ``sigma``, the
    factor ``lu`` of ``K - σM`` and the last guard."""
    n = K.shape[0]
    while True:
        k = min(n_modes + guard, limit)
        if k < n_modes:
            raise ValueError(f"{n_modes} modes of a {n}-DOF system with {n_mass(M)} DOFs with"
                             " mass: use the dense path (raise dense_below) or ask for fewer"
                             " modes")
        try:
            omega2, X = lowest_pairs(K, M, k, sigma, lu, n_wanted=n_modes, far_check=movable)
        except FarShiftError as far:
            sigma, movable = far.shift, False  # (the same ordering: no new analysis)
            lu = lu.factorize_like(K - sigma * M, definite=None if sigma < 0 else False)
            continue
        count = complete_cluster(omega2, n_modes)
        if count < k or k == limit:
            return omega2, X, count, sigma, lu, guard
        guard *= 2  # a cluster of repeated eigenvalues fills all computed modes


def _sparse_from_zero(K, M, hi, sigma, check, scale, movable, factor=None):
    """All eigenpairs with ``λ <= hi`` of a positive semi-definite pencil (a band from 0).

    The Sturm count below ``hi`` gives their number n; they are the n lowest, found by
    :func:`_sparse_lowest` with the shift σ < 0 of the lowest-modes path, so that a
    singular K (rigid-body modes, computed λ of either sign) is never factorised, or with
    a given ``factor`` of ``K - σM`` (σ <= 0: the ``K_ii`` of a Craig-Bampton reduction at
    σ = 0), and Sturm-checked there (the count reuses the ordering of the factorisation of
    ``K - σM``). Returns ``omega2, X, sturm_count, cut, sigma, method`` (``"sturm"`` where the
    count shows the band empty). (With a factor this path
    replaced ARPACK at the given shift (:func:`_sparse_band`) for the fixed-interface modes
    up to 176 Hz of the 150k-DOF rails frame of benchmarks/peer_interface.py, 25 modes:
    2.2 s with block Lanczos against 2.7-3.1 s with ARPACK, the same eigenvalues to
    3.4e-15.)
    """
    lu = factorize(K - sigma * M, definite=None if sigma < 0 else False) \
        if factor is None else factor
    n_below = inertia_below(K, M, hi, like=lu)
    if n_below is None:
        raise RuntimeError("band search needs a Sturm count, which failed for this pencil;"
                           " ask for n_modes instead")
    if n_below == 0:
        return np.empty(0), np.empty((K.shape[0], 0)), 0, hi, sigma, "sturm"
    omega2, X, count, cut, sigma, method = _sparse_lowest(K, M, n_below, sigma, lu, check,
                                                          scale,
                                                  movable=movable)
    keep = omega2 <= hi
    if np.count_nonzero(keep) != n_below:
        raise RuntimeError(f"band search found {np.count_nonzero(keep)} of {n_below}"
                           f" eigenvalues (Sturm count) below {hi:.6g} rad²/s²")
    return omega2[keep], X[:, keep], count, cut, sigma, method


def _sparse_band(K, M, band, sigma, factor=None):
    """All eigenpairs in ``band``: Sturm counts fix how many, deflation finds them all."""
    lo, hi = band
    n = K.shape[0]
    below_hi = inertia_below(K, M, hi, like=factor)
    below_lo = inertia_below(K, M, lo, like=factor) if lo > default_shift(K, M) else 0
    shift = 0.5 * (lo + hi) if sigma is None else float(sigma)
    if below_hi is None or below_lo is None:
        raise RuntimeError("band search needs a Sturm count, which failed for this pencil;"
                           " ask for n_modes instead")
    count = below_hi - below_lo
    if count == 0:
        return np.empty(0), np.empty((n, 0)), shift
    if count + 2 >= n - 1:
        raise ValueError(f"the band holds {count} of {n} eigenvalues: use the dense path")
    lu = factorize(K - shift * M, pivot_threshold=0.01, definite=False) \
        if factor is None else factor
    omega2, X = np.empty(0), np.empty((n, 0))
    for _ in range(MAX_DEFLATIONS):
        k = min(count - omega2.size + 2, n - 2 - omega2.size)
        omega2, X = _merge(omega2, X, *arpack(K, M, k, shift, lu, deflate=X))
        keep = (omega2 >= lo) & (omega2 <= hi)
        omega2, X = omega2[keep], X[:, keep]
        if omega2.size >= count:
            break
    if omega2.size != count:
        raise RuntimeError(f"band search found {omega2.size} of {count} eigenvalues"
                           f" (Sturm count) in [{lo:.6g}, {hi:.6g}] rad²/s²")
    return omega2, X, shift


def __getattr__(name: str):
    """Names this module had before the restructures, from their new places
    (docs/architecture.md, "Moved names")."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "ALL_PAIRS_FRACTION": "femmech.solve.dense.ALL_PAIRS_FRACTION",
        "BLOCK_SIZE": "femmech.solve.lanczos.BLOCK_SIZE",
        "FAR_SHIFT": "femmech.solve.lanczos.FAR_SHIFT",
        "GUARD_TOL": "femmech.solve.lanczos.GUARD_TOL",
        "LANCZOS_TOL": "femmech.solve.lanczos.LANCZOS_TOL",
        "MAX_BASIS_BYTES": "femmech.solve.lanczos.MAX_BASIS_BYTES",
        "MAX_SOLVES_PER_MODE": "femmech.solve.lanczos.MAX_SOLVES_PER_MODE",
        "PROBES": "femmech.solve.lanczos.PROBES",
        "REORTHOGONALIZE_BELOW": "femmech.solve.lanczos.REORTHOGONALIZE_BELOW",
        "RESIDUAL_TOL": "femmech.solve.residuals.RESIDUAL_TOL",
        "SEMI_ORTHOGONAL": "femmech.solve.lanczos.SEMI_ORTHOGONAL",
        "STREAM_COLUMNS": "femmech.solve.lanczos.STREAM_COLUMNS",
        "residuals": "femmech.solve.residuals.residuals",
    })
