"""Sparse symmetric eigen solver with shift-invert, Sturm-sequence checks and a dense path.

Solves ``K x = λ M x`` (``λ = ω²``, rad²/s²) for symmetric positive semi-definite K and M.
K may be singular (free-free structures): the shift σ is chosen below zero so that
``K - σ M`` is regular and never a singular K is factorised. M may be singular
(massless DOFs): their infinite eigenvalues are never returned.
"""

from __future__ import annotations

import contextlib
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from femmech.errors import FemmechWarning
from femmech.solve import direct, threads

MAX_DEFLATIONS = 10
"""Deflated Lanczos restarts allowed to complete a set that the Sturm count shows short."""

DENSE_BELOW = 400
"""Systems with fewer DOFs than this are solved with dense LAPACK (``scipy.linalg.eigh``)."""

RIGID_TOL = 1e-12
"""Eigenvalues with ``|ω²| <= RIGID_TOL * scale`` are rigid-body modes (scale: a typical
element eigenvalue, e.g. :func:`femmech.analysis.modes.model_eigenvalue_scale`). Computed
rigid-body eigenvalues are ~1e-17 of the scale, of either sign (also on free shells at
span/thickness 1e4, whose lowest elastic eigenvalue is 3e-10 of it); elastic modes of
1e-12 of the scale are ~1e-6 of the typical element frequency."""


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
        ``"dense"`` (LAPACK) or ``"arpack"``: sparse shift-invert Lanczos (the lowest
        modes by femmech's block Lanczos, :func:`_block_lanczos`; bands by ARPACK; the
        name is kept for the results and tests that select on it).
    sigma : float
        Shift used, rad²/s².
    residual : ndarray (n_modes,)
        ``‖K x - λ M x‖ / (max(|λ|, |σ₀|) ‖M x‖)`` with σ₀ = :func:`default_shift`.
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


def eigenvalue_scale(K, M) -> float:
    """Typical eigenvalue magnitude ``median(diag K / diag M)`` over DOFs with mass, rad²/s².

    A pencil without any DOF that has both stiffness and mass (a rigid body: K vanishes on
    every DOF with mass) has only zero finite eigenvalues; any positive scale will do for
    it, and 1.0 is returned.
    """
    dk = np.asarray(K.diagonal(), dtype=float)
    dm = np.asarray(M.diagonal(), dtype=float)
    if not (dm > 0).any():
        raise ValueError("the mass matrix has no positive diagonal entry: nothing can vibrate")
    ok = (dm > 0) & (dk > 0)
    if not ok.any():
        return 1.0
    return float(np.median(dk[ok] / dm[ok]))


def factorize(A, pivot_threshold: float = 0.0, definite: bool | None = None,
              solver: str | None = None) -> direct.Factor:
    """Sparse factorisation of a symmetric matrix, with ``solve`` and ``n_negative``.

    Goes through :func:`femmech.solve.direct.factorize` (``solver`` default: ``"auto"``, the
    fastest installed backend, SuperLU for small systems). SuperLU runs in symmetric
    mode: a symmetric fill-reducing ordering (minimum degree on ``Aᵀ + A``) and diagonal
    pivots keep the factors' symmetric structure; on a 120k-DOF space frame this is 14x
    less fill and 70x faster than SuperLU's default partial pivoting (benchmarks).
    ``pivot_threshold = 0`` is stable for positive definite A (shift below the spectrum);
    for an indefinite A (shift inside the spectrum) pass e.g. 0.01 so that SuperLU rejects
    small diagonal pivots. ``definite`` tells the other backends whether A is positive
    definite (True: Cholesky), may be indefinite (False: LDLᵀ) or unknown (None: try).

    Raises ValueError with the hint "singular" when A cannot be factorised.
    """
    return direct.factorize(A, solver=solver, definite=definite,
                             pivot_threshold=pivot_threshold)


def inertia_below(K, M, cut: float, like=None) -> int | None:
    """Number of eigenvalues of ``K x = λ M x`` below ``cut`` (Sylvester's law of inertia).

    Counts negative pivots of a symmetric ``L D Lᵀ``-like factorisation of ``K - cut M``
    (:attr:`femmech.solve.direct.Factor.n_negative`: SuperLU in symmetric mode with diagonal
    pivoting, CHOLMOD's LDLᵀ, PARDISO's ``iparm(23)``). Returns None where the
    factorisation pivoted off the diagonal (or perturbed pivots), so that the count would
    not be the inertia. ``like``: a :class:`femmech.solve.direct.Factor` of a matrix of the same
    pattern (e.g. the shift-invert factor of ``K - σM``) whose fill-reducing ordering is
    reused (:meth:`~femmech.solve.direct.Factor.factorize_like`: no new ordering, no METIS).
    """
    A = K - cut * M
    try:
        if isinstance(like, direct.Factor):
            lu = like.factorize_like(A, definite=False)
        else:
            lu = factorize(A, definite=False)
    except ValueError:
        return None
    return lu.n_negative


def normalize_modes(vectors: np.ndarray, M) -> np.ndarray:
    """Mass-normalise columns and make the largest-magnitude entry of each positive.

    Entries within 1e-6 of the largest magnitude count as ties and the last of them (the
    highest DOF index) decides: symmetric structures have pairs of equal and opposite
    largest entries, and picking the larger by round-off flipped a plate's mode (and its
    reference picture, tests/images/plate_mode1.png) when only the shift changed.
    """
    norms = np.sqrt(np.einsum("ij,ij->j", vectors, M @ vectors))
    vectors = vectors / norms
    magnitude = np.abs(vectors)
    near = magnitude >= (1 - 1e-6) * magnitude.max(axis=0)
    rows = len(near) - 1 - np.argmax(near[::-1], axis=0)
    signs = np.sign(vectors[rows, np.arange(vectors.shape[1])])
    return vectors * np.where(signs == 0, 1.0, signs)


def residuals(K, M, omega2, vectors, floor: float) -> np.ndarray:
    """Relative residuals ``‖K x - λ M x‖ / (max(|λ|, floor) ‖M x‖)`` per column.

    ``floor`` (rad²/s², e.g. ``|σ|``) keeps the measure meaningful for rigid-body modes.
    """
    num, den = _residual_terms(K, M, omega2, vectors, floor)
    return num / np.where(den > 0, den, 1.0)


def _residual_terms(K, M, omega2, vectors, floor: float):
    """Numerator ‖K x - λ M x‖ and denominator max(|λ|, floor) ‖M x‖ per column."""
    Kx = K @ vectors
    Mx = M @ vectors
    num = np.linalg.norm(Kx - Mx * omega2, axis=0)
    return num, np.maximum(np.abs(omega2), floor) * np.linalg.norm(Mx, axis=0)


RESIDUAL_TOL = 1e-6
"""Relative residual above which a computed mode is reported (when round-off allows it)."""


def residual_limits(K, vectors, den) -> np.ndarray:
    """Per column, the larger of :data:`RESIDUAL_TOL` and the round-off level of a residual.

    Forming ``K x`` alone carries an error of about eps ‖K‖∞ ‖x‖ (Higham, Accuracy and
    Stability of Numerical Algorithms, 2002, sect. 3.5), so the relative residual of
    :func:`residuals` can not fall below ~eps ‖K‖∞ ‖x‖ / den on any BLAS, with den =
    max(|λ|, floor) ‖M x‖ its denominator (n_modes,); 100 times that is the limit (the
    low modes of stiff-contrast pencils and fine slender-beam meshes, eps λ_max / λ_1 ~
    1e-7 … 1e-4, whose residuals otherwise cross a fixed 1e-6 on one BLAS kernel and
    not on another).
    """
    k_norm = float(abs(K).sum(axis=1).max()) if K.shape[0] else 0.0
    x_norm = np.linalg.norm(vectors, axis=0)
    roundoff = 100 * np.finfo(float).eps * k_norm * x_norm / np.where(den > 0, den, np.inf)
    return np.maximum(RESIDUAL_TOL, roundoff)


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


ALL_PAIRS_FRACTION = 1 / 7
""":func:`dense_symmetric` computes all n eigenpairs (LAPACK ``sygvd``, divide and
conquer) when at least this fraction of them is wanted, otherwise only the wanted ones
(``sygvx``). Crossover measured between n/8 and n/6 at 76-322 coordinates (frozen-angle
solves of the textile shaft's sweep): 21 of 76 pairs took 0.6 ms instead of 0.9 ms."""


def dense_symmetric(K, M, n_modes: int | None = None, sigma: float | None = None):
    """All (or the lowest ``n_modes``) eigenpairs of a dense symmetric pencil, ascending.

    Solves the shift-inverted pencil ``M x = μ (K - σ M) x``, ``λ = σ + 1/μ`` with
    σ < 0 (default :func:`default_shift`) by LAPACK, like shift-invert Lanczos: the
    lowest modes (largest μ) come out with relative accuracy ~eps however wide the
    spectrum (``eigh(K, M)`` resolves them only to ~eps·λ_max), K may be singular
    (rigid-body modes) and M may be singular (massless DOFs: μ = 0, infinite λ, dropped).
    Vectors are mass-normalised (``XᵀMX = I``). K, M (n, n) dense or sparse; the driver
    follows :data:`ALL_PAIRS_FRACTION`.
    """
    Kd = K.toarray() if sp.issparse(K) else np.asarray(K, dtype=float)
    Md = M.toarray() if sp.issparse(M) else np.asarray(M, dtype=float)
    n = len(Md)
    sigma = default_shift(Kd, Md) if sigma is None else sigma
    wanted = n if n_modes is None else min(n_modes, n)
    not_definite = "K - sigma*M is not positive definite: some DOF has neither stiffness nor mass"
    if wanted >= ALL_PAIRS_FRACTION * n:
        mu, X, info = sla.lapack.dsygvd(Md, Kd - sigma * Md, uplo="L", overwrite_b=1)
        if info > n:
            raise ValueError(not_definite)
        if info:
            raise np.linalg.LinAlgError(f"LAPACK sygvd did not converge (info {info})")
        mu, X = mu[n - wanted:], X[:, n - wanted:]
    else:
        try:
            mu, X = sla.eigh(Md, Kd - sigma * Md, subset_by_index=[n - wanted, n - 1],
                             check_finite=False, overwrite_b=True)
        except np.linalg.LinAlgError as exc:
            raise ValueError(not_definite) from exc
    finite = mu > 1e-12 * max(np.abs(mu).max(), 1e-300)
    omega2 = sigma + 1.0 / mu[finite]
    X = X[:, finite] / np.sqrt(mu[finite])  # Xᵀ(K - σM)X = I gives XᵀMX = diag(μ)
    order = np.argsort(omega2)
    return omega2[order], X[:, order]


def _arpack(K, M, k, sigma, lu, deflate=None):
    """``k`` eigenpairs nearest ``sigma`` by shift-invert Lanczos (ARPACK).

    ``deflate`` (n, m), M-orthonormal eigenvectors already found, is projected out of the
    start vector and of every operator application (``P (K - σM)⁻¹`` with
    ``P = I - X Xᵀ M``), so the run finds further members of a repeated eigenvalue that a
    single Krylov sequence cannot see.

    The Krylov space of ``(K - σM)⁻¹ M`` has at most as many dimensions as M has DOFs
    with mass (a singular M: massless DOFs), less the deflated vectors; ARPACK's
    basis size ``ncv`` (and k below it) is capped there, where the default
    ``max(2k + 1, 20)`` made ARPACK stop with "could not build an Arnoldi factorization".
    """
    n = K.shape[0]
    krylov = _n_mass(M) - (0 if deflate is None else deflate.shape[1])
    k = min(k, krylov - 1)
    if k < 1:
        raise ValueError(f"no further finite eigenvalue: only {_n_mass(M)} of the {n} DOFs"
                         " carry mass")
    ncv = min(n, max(2 * k + 1, 20), krylov)
    v0 = np.random.default_rng(12345).standard_normal(n)
    solve = lu.solve
    if deflate is not None and deflate.shape[1]:
        MX = M @ deflate

        def solve(v):
            y = lu.solve(v)
            return y - deflate @ (MX.T @ y)

        v0 = v0 - deflate @ (MX.T @ v0)
    op = spla.LinearOperator((n, n), matvec=solve, dtype=float)
    with threads.solve_phase():  # a loop of solves: 1 BLAS thread (femmech.solve.threads)
        omega2, X = spla.eigsh(sp.csr_matrix(K), k=k, M=sp.csr_matrix(M), sigma=sigma,
                               which="LM", OPinv=op, v0=v0, ncv=ncv)
    if krylov + (0 if deflate is None else deflate.shape[1]) < n:
        X = _purify(X, omega2, sigma, M, solve)
    order = np.argsort(omega2)
    return omega2[order], X[:, order]


LANCZOS_TOL = 1e-12
"""Convergence of :func:`_block_lanczos`: ``‖S x - θ x‖_M <= LANCZOS_TOL |θ|`` for every
wanted Ritz pair of ``S = (K - σM)⁻¹ M``. Eigenvalue errors go like the square of this
(measured 5e-15 relative on 24k and 151k-DOF frames against ARPACK at machine
precision); the relative residuals ``‖K x - λ M x‖ / (λ ‖M x‖)`` come out 10-300 times
larger (they weigh the stiff directions): 1e-10 to 6e-10 on those frames."""

GUARD_TOL = 1e-6
"""Convergence of the guard pairs of :func:`_block_lanczos` (computed beyond the wanted
ones only to see whether the last wanted eigenvalue is repeated): their eigenvalues are
then accurate to ~1e-12, far below the 1e-6 of a cluster (:func:`_complete_cluster`)."""

BLOCK_SIZE = 2
"""Block size of :func:`_block_lanczos`. b >= 2 finds both members of a double
eigenvalue (symmetric structures) in one run, where single-vector Lanczos finds the
second only late, from round-off (a 24k-DOF frame: a 20-mode run with b = 1 returned
the 21st eigenvalue 5 % too high). Larger blocks need more vectors for the same modes
(21 modes of that frame: 86, 116 and 184 vectors for b = 2, 4, 8), and the
orthogonalisation, which grows with the square of the basis, costs more than the
block solves save (CHOLMOD solves 4 right-hand sides in ~2 times the time of one)."""

REORTHOGONALIZE_BELOW = 0.5
"""A second classical Gram-Schmidt pass runs for a block in which a vector kept less than
this fraction of its M-norm in the first (DGKS criterion; measured on a 24k-DOF frame:
most vectors keep 0.3-0.5 against the whole basis). With 0.01 (one pass nearly always)
the loss of orthogonality stalled the Ritz residuals at ~2e-11 relative, above
:data:`LANCZOS_TOL`."""

SEMI_ORTHOGONAL = float(np.sqrt(np.finfo(float).eps))
"""Partial reorthogonalisation (H. D. Simon, "The Lanczos algorithm with partial
reorthogonalization", Math. Comp. 42 (1984) 115-142; block form: R. G. Grimes, J. G.
Lewis, H. D. Simon, SIAM J. Matrix Anal. Appl. 15 (1994) 228-272): a new block is
orthogonalised against the whole basis only when the estimated loss of M-orthogonality
exceeds this (then it and the next block are). Semi-orthogonality keeps the Ritz values
as accurate as full reorthogonalisation: on a 151k-DOF frame 15 of 43 blocks were
reorthogonalised, the iteration took 1.6 s against 2.4 s with every block, with the
same eigenvalues to 1e-14."""

PROBES = 4
"""Random combinations of the Lanczos basis whose M-inner products with each new block
measure the loss of orthogonality that the recurrence of :data:`SEMI_ORTHOGONAL` does not
model: solves of an ill-conditioned ``K - σM`` (a 1e16 N/m connector on 1e3 N/m mounts)
lose it faster than ~eps |S| per step, and a run without them returned a mode with a
relative residual of 1e-4."""

MAX_BASIS_BYTES = 4 * 1024**3
"""Memory of the Lanczos basis (V and MV); beyond it the basis is restarted (thick
restart): 268 vectors at 1M DOFs, no restart for 20-40 modes up to ~1M DOFs."""

MAX_SOLVES_PER_MODE = 40
"""Cap of :func:`_block_lanczos`: after ``MAX_SOLVES_PER_MODE k + 400`` solved vectors
without convergence (normal runs take 3-5 per mode) it gives up and ARPACK takes over
(:func:`_lowest_pairs`); a safeguard against a basis that restarts without progress."""

_EPS = float(np.finfo(float).eps)


class _NotConvergedError(RuntimeError):
    """:func:`_block_lanczos` reached :data:`MAX_SOLVES_PER_MODE`."""


FAR_SHIFT = 100.0
"""A default shift σ < 0 counts as too far below the wanted eigenvalues when
``-σ > FAR_SHIFT λ_1`` for the Ritz estimate λ_1 of the lowest eigenvalue after 2k
Lanczos vectors: then the wanted θ = 1/(λ - σ) crowd together and Lanczos (and ARPACK)
converge slowly. The default shift ``-1e-6 λ_max`` of a model with very stiff parts can
be that far: the full textile shaft (150k DOFs, stiff cam contacts) had σ = -2.8e9 rad²/s²
for eigenvalues of 4e5-5e6; block Lanczos had not converged after 1 122 solves (31 s)
and ARPACK took 35 s more, while at σ = -2.8e6 the whole solve took 1.6 s.
:func:`_sparse_lowest` then moves the shift to ``-max(λ_1, 1e-3 |σ|)`` and factorises
once more: the bound keeps the condition of ``K - σM`` (~λ_max/|σ|) below ~1e9. Models
with rigid-body modes (a Ritz value ~0) keep the default shift, whose distance from 0
is what makes their solves accurate (a free thin shell moved to -λ_1 had rigid-mode
residuals of 1.5e-6); frames and shells of the benchmarks have -σ / λ_1 = 0.2-1."""


class _FarShiftError(RuntimeError):
    """:func:`_block_lanczos` found σ far below the wanted eigenvalues; ``shift`` is a
    better one (rad²/s²)."""

    def __init__(self, shift: float):
        super().__init__(f"shift far from the wanted eigenvalues; try {shift:.6g}")
        self.shift = shift


def _lowest_pairs(K, M, k, sigma, lu, deflate=None, n_wanted=None, far_check=False):
    """``k`` eigenpairs nearest σ: block Lanczos, ARPACK where it does not converge.
    ``far_check``: raise :class:`_FarShiftError` where σ is too far (:data:`FAR_SHIFT`)."""
    try:
        return _block_lanczos(K, M, k, sigma, lu, deflate=deflate, n_wanted=n_wanted,
                              far_check=far_check)
    except _NotConvergedError as exc:
        warnings.warn(f"{exc}; falling back to ARPACK", FemmechWarning, stacklevel=3)
        return _arpack(K, M, k, sigma, lu, deflate=deflate)


def _block_lanczos(K, M, k, sigma, lu, deflate=None, block=BLOCK_SIZE, tol=LANCZOS_TOL,
                   max_dim=None, seed=12345, n_wanted=None, partial=True, far_check=False):
    """``k`` eigenpairs nearest ``sigma`` by block Lanczos on ``S = (K - σM)⁻¹ M``.

    Each new block is M-orthonormalised against the previous two (block three-term
    recurrence) and, by partial reorthogonalisation (:data:`SEMI_ORTHOGONAL`), against the
    whole basis only when the estimated loss of orthogonality requires it: passes over
    the basis are memory-bound (at 151k DOFs and 90 vectors one costs about as much as
    five solves). Rayleigh-Ritz on the projected operator ``T = VᵀMSV`` (block
    tridiagonal; ``λ = σ + 1/θ``, as accurate as shift-invert ARPACK), convergence from
    the Ritz residuals ``‖S x - θ x‖_M = ‖B y_last‖`` of the recurrence. When the basis
    reaches ``max_dim`` vectors (default ``max(5k + 2b, 100)`` within
    :data:`MAX_BASIS_BYTES`) it is restarted with the best ``k + b`` Ritz vectors and the
    next block (thick restart) and continues with full reorthogonalisation of every block
    (as with ``partial=False``, and after a block lost rank). The start block is ``S R``
    for a random R, so every basis vector lies in the range of S (no components that M
    does not see). ``deflate`` (n, m): M-orthonormal eigenvectors projected out of the
    operator, as in :func:`_arpack`.

    ``n_wanted``: only the ``n_wanted`` pairs nearest σ (and the rest of a cluster cut at
    the last of them) must reach ``tol``; the others of the k, guards that show whether the
    last wanted eigenvalue is repeated, stop at :data:`GUARD_TOL`. Default: all k.

    Returns ``omega2`` (ascending) and the Ritz vectors X (M-orthonormal).
    """
    n = K.shape[0]
    n_defl = 0 if deflate is None else deflate.shape[1]
    krylov = _n_mass(M) - n_defl
    k = min(k, krylov)
    if k < 1:
        raise ValueError(f"no further finite eigenvalue: only {_n_mass(M)} of the {n} DOFs"
                         " carry mass")
    n_wanted = k if n_wanted is None else min(n_wanted, k)
    block = max(1, min(block, k))
    if max_dim is None:
        max_dim = min(max(5 * k + 2 * block, 100), MAX_BASIS_BYTES // (16 * n) - block)
    max_dim = max(min(max_dim, krylov), min(k + 2 * block, krylov))
    keep = min(k + block, max_dim - block)  # Ritz vectors kept at a thick restart
    rng = np.random.default_rng(seed)

    if n_defl:
        MX = M @ deflate

        def project(Y):
            return Y - deflate @ (MX.T @ Y)

        def operator(MY):
            return project(lu.solve(MY))
    else:
        def project(Y):
            return Y

        def operator(MY):
            return lu.solve(MY)

    if sp.issparse(M):
        M = M.tocsr()

    def m_times(W):
        """M W as an F-ordered block: column by column (scipy's multi-vector CSR product
        took 6.2 ms for two columns of 151k, two single products 2.6 ms, and it returns C
        order, which made later in-place updates of F-ordered blocks 17x slower)."""
        if not sp.issparse(M):
            return np.asfortranarray(M @ W)
        out = np.empty(W.shape, order="F")
        for col in range(W.shape[1]):
            out[:, col] = M @ W[:, col]
        return out

    V = np.empty((n, max_dim + block), order="F")  # columns contiguous: BLAS on V[:, :m]
    MV = np.empty((n, max_dim + block), order="F")
    H = np.zeros((max_dim + block, max_dim + block))

    def orthogonalize(W, lo, hi, passes=3):
        """Classical Gram-Schmidt of W against V[:, lo:hi]; a further pass where one
        cancelled more than :data:`REORTHOGONALIZE_BELOW`. Returns (W, MW, C)."""
        C = np.zeros((hi - lo, W.shape[1]))
        MW = None
        for _ in range(passes if hi > lo else 0):
            with _streaming(hi - lo):
                c = MV[:, lo:hi].T @ W
                W = W - V[:, lo:hi] @ c
            C += c
            MW = m_times(W)
            kept = np.diag(W.T @ MW)
            # M-norm² before the pass = kept + |c|² (Pythagoras; exact for M-orthonormal V)
            if np.all(kept >= REORTHOGONALIZE_BELOW**2 * (kept + (c * c).sum(axis=0))):
                break
        return W, (m_times(W) if MW is None else MW), C

    work = np.empty((n, block), order="F")  # products V c, updated in place: the loop
    # allocates few vectors (a first touch of fresh memory costs ~1 ms per MB on the
    # project's VM; temporaries served by mmap made a 24k-DOF solve 1.8x slower)

    def orthogonalize_local(W, lo, hi):
        """Two classical Gram-Schmidt passes of W (overwritten) against the last blocks
        V[:, lo:hi], then one product with M. Returns (W, MW, C, WᵀMW). (A second pass
        only where DGKS asks for it would run on 43 of 43 blocks of the 151k-DOF frame:
        the recurrence cancels more than 3/4 of every new block's M-norm squared.)"""
        part = work[:, :W.shape[1]]
        C = np.zeros((hi - lo, W.shape[1]))
        for _ in range(2):
            c = MV[:, lo:hi].T @ W
            np.matmul(V[:, lo:hi], c, out=part)
            W -= part
            C += c
        MW = m_times(W)
        return W, MW, C, W.T @ MW

    def normalize(W, MW, C, room, at=None, gram=None):
        """M-orthonormal basis Q of W (M-orthogonal to the basis): (Q, MQ, R), W = Q R.

        Directions that keep less than 1e-12 of the block's M-norm before the
        orthogonalisation (coefficients C) are numerically in span(V) and dropped (R loses
        rows), as are directions beyond ``room`` (M has no more rank). ``at``: write Q and
        MQ into the basis at column ``at`` (views are returned).
        """
        gram = W.T @ MW if gram is None else gram
        d, U = np.linalg.eigh(0.5 * (gram + gram.T))
        d, U = d[::-1], U[:, ::-1]
        size = np.sqrt(np.maximum(d, 0.0))
        before = np.sqrt(float(np.einsum("ij,ij->", C, C)) + max(d[0], 0.0)) if d.size else 0
        ok = (size > 1e-12 * before) & (np.cumsum(np.ones(len(d))) <= room)
        factor = U[:, ok] / size[ok]
        R = (U[:, ok] * size[ok]).T
        if at is None:
            return W @ factor, MW @ factor, R
        q = factor.shape[1]
        np.matmul(W, factor, out=V[:, at:at + q])
        np.matmul(MW, factor, out=MV[:, at:at + q])
        return V[:, at:at + q], MV[:, at:at + q], R

    def fresh(count, m):
        """``count`` new random directions S r, M-orthonormal to V[:, :m]."""
        W = project(operator(m_times(project(rng.standard_normal((n, count))))))
        W, MW, C = orthogonalize(W, 0, m)
        return normalize(W, MW, C, krylov - m)[:2]

    def converged(theta, est):
        if len(theta) < k:
            return False
        lam = np.sort(sigma + 1.0 / theta[:k])
        tight = _complete_cluster(lam, n_wanted) if n_wanted < k else k
        limit = np.where(np.arange(k) < tight, tol, max(tol, GUARD_TOL))
        return bool(np.all(est[:k] <= limit * np.abs(theta[:k])))

    # partial reorthogonalisation: omega[i] estimates V_iᵀ M V_j for the blocks i <= j of
    # the current block j (omega_prev: of block j - 1); Grimes-Lewis-Simon recurrence
    omega = np.zeros((max_dim // block + 2, block, block))
    omega[0] = np.eye(block)
    omega_prev = np.zeros_like(omega)
    norm_t = 0.0
    force = False
    with threads.solve_phase():  # a loop of solves and thin products: 1 BLAS thread
        Q, MQ = fresh(block, 0)
        m = Q.shape[1]
        V[:, :m], MV[:, :m] = Q, MQ
        weights = rng.standard_normal((m, PROBES))
        probe_m, probe_n = MQ @ weights, (weights * weights).sum(axis=0)  # M P, |P|²_M
        probe_w = np.empty_like(probe_m)
        j0 = 0
        # near an exhausted Krylov space (few DOFs with mass) the local recurrence cannot
        # tell new directions from old ones: reorthogonalise fully there
        partial = partial and m == block and max_dim < krylov
        solved, max_solved = m, MAX_SOLVES_PER_MODE * k + 400
        while True:
            if solved > max_solved:
                raise _NotConvergedError(f"block Lanczos: {k} eigenpairs near σ = {sigma:.6g}"
                                    f" not converged after {solved} solves")
            SQ = operator(MV[:, j0:m])
            solved += m - j0
            b = 0
            local = None
            if partial:  # local orthogonalisation against the blocks j - 1 and j
                j, lo = j0 // block, max(0, j0 - block)
                W, MW, C, gram = orthogonalize_local(SQ, lo, m)  # SQ overwritten
                local = (lo, C)
                Q, MQ, R = normalize(W, MW, C, krylov - m, at=m, gram=gram)
                if Q.shape[1] == block:
                    A = 0.5 * (C[-block:] + C[-block:].T)
                    B = H[j0:m, lo:j0]  # coefficient of block j in S V_{j-1} (empty: j = 0)
                    norm_t = max(norm_t, np.abs(A).sum(1).max() + np.abs(R).sum(0).max()
                                 + np.abs(B).sum(1).max(initial=0.0))
                    r_inv = np.linalg.inv(R)
                    new = np.zeros_like(omega)
                    if j:  # V_iᵀ M V_{j+1} for i < j
                        diag = np.stack([H[i * block:(i + 1) * block, i * block:(i + 1) * block]
                                         for i in range(j)])
                        down = np.stack([H[(i + 1) * block:(i + 2) * block,
                                           i * block:(i + 1) * block] for i in range(j)])
                        up = np.concatenate([np.zeros((1, block, block)), down[:-1]])
                        below = np.concatenate([np.zeros((1, block, block)), omega[:j - 1]])
                        est = (up @ below + diag @ omega[:j]
                               + np.transpose(down, (0, 2, 1)) @ omega[1:j + 1]
                               - omega[:j] @ A - omega_prev[:j] @ B.T) @ r_inv
                        noise = _EPS * norm_t * np.linalg.norm(r_inv, 2) * np.sqrt(block)
                        new[:j] = est + np.where(est >= 0, noise, -noise)
                    # the estimates assume solves accurate to ~eps |S|; an ill-conditioned
                    # K - σM (stiff connectors on soft mounts) loses orthogonality faster:
                    # random combinations of the basis measure it (RMS over the blocks)
                    seen = np.abs(probe_m.T @ Q).max() / np.sqrt(probe_n.min()) * np.sqrt(j + 1)
                    if force or max(np.abs(new[:j]).max(initial=0.0), seen) > SEMI_ORTHOGONAL:
                        Wq, MWq, c = orthogonalize(Q, 0, m, passes=1)
                        Q2, MQ2, fix = normalize(Wq, MWq, c, krylov - m)
                        if Q2.shape[1] == block:
                            Q, MQ, R = Q2, MQ2, fix @ R
                            new[:j + 1] = _EPS
                            force = not force  # this block and the next one
                        else:
                            Q = Q2
                    if Q.shape[1] == block:
                        new[j] = _EPS
                        omega_prev, omega = omega, new
                        omega[j + 1] = np.eye(block)
                        weights = rng.standard_normal((block, PROBES))
                        probe_m += np.matmul(MQ, weights, out=probe_w)
                        probe_n += (weights * weights).sum(axis=0)
                        H[j0:m, j0:m] = A
                        b = block
                if not b:
                    partial = False  # a block lost rank: full reorthogonalisation from here
            if not partial:
                W, MW, C = orthogonalize(SQ, 0, m)
                if local is not None:  # SQ was locally orthogonalised in place first
                    C[local[0]:m] += local[1]
                Q, MQ, R = normalize(W, MW, C, krylov - m)
                b = Q.shape[1]
                H[:m, j0:m] = C
            H[m:m + b, j0:m] = R
            H[j0:m, m:m + b] = R.T
            theta, Y = np.linalg.eigh(0.5 * (H[:m, :m] + H[:m, :m].T))
            order = np.argsort(-np.abs(theta))  # nearest σ first
            theta, Y = theta[order], Y[:, order]
            est = np.linalg.norm(R @ Y[j0:m, :], axis=0) if b else np.zeros(m)
            if far_check and m >= 2 * k + 2 * block:  # once: is σ far from the wanted?
                far_check = False
                lam = sigma + 1.0 / theta[:k]
                low = lam.min()  # no rigid-body modes (|λ| ~ 0) and no negative ones
                if sigma < 0 and low > 1e-6 * -sigma and -sigma > FAR_SHIFT * low:
                    raise _FarShiftError(-max(low, 1e-3 * -sigma))
            if converged(theta, est) or (b == 0 and m >= krylov):
                break
            if b < block and m + b < krylov:  # Krylov space (nearly) invariant: widen it
                partial = False
                V[:, m:m + b], MV[:, m:m + b] = Q, MQ
                Z, MZ = fresh(min(block - b, krylov - m - b), m + b)
                Q, MQ = np.hstack([V[:, m:m + b], Z]), np.hstack([MV[:, m:m + b], MZ])
            if m + Q.shape[1] > max_dim:  # thick restart: best Ritz vectors + next block
                partial = False
                p = keep
                with _streaming(m):
                    U, MU = V[:, :m] @ Y[:, :p], MV[:, :m] @ Y[:, :p]
                # re-M-orthonormalise (a semi-orthogonal basis gives Ritz vectors
                # orthogonal to ~1e-8 only): U' = U L⁻ᵀ, S U' = U' Lᵀ Θ L⁻ᵀ + Q R Y L⁻ᵀ
                chol = np.linalg.cholesky(0.5 * (U.T @ MU + MU.T @ U))
                inv_t = np.linalg.inv(chol).T
                V[:, :p], MV[:, :p] = U @ inv_t, MU @ inv_t
                H[:] = 0.0
                H[:p, :p] = chol.T @ (theta[:p, None] * inv_t)
                H[:p, :p] = 0.5 * (H[:p, :p] + H[:p, :p].T)
                coupling = (R @ Y[j0:m, :p]) @ inv_t
                H[p:p + coupling.shape[0], :p] = coupling
                m = p
                c = MV[:, :m].T @ Q  # Q against the new basis (round-off level)
                Q, MQ = Q - V[:, :m] @ c, MQ - MV[:, :m] @ c
            b = Q.shape[1]
            if not np.may_share_memory(Q, V):  # (normalize wrote it there already)
                V[:, m:m + b], MV[:, m:m + b] = Q, MQ
            j0, m = m, m + b
    k = min(k, len(theta))
    order = np.argsort(1.0 / theta[:k])  # ascending λ = σ + 1/θ, ordered before the
    omega2 = sigma + 1.0 / theta[:k][order]  # product (columns of an n x k result)
    with _streaming(m):
        X = V[:, :m] @ Y[:, :k][:, order]
    if n_defl:
        X = project(X)
    if krylov + n_defl < n:
        X = _purify(X, omega2, sigma, M, operator)
    return omega2, X


STREAM_COLUMNS = 16
"""Products with at least this many basis columns run under
:func:`femmech.solve.threads.gemm_phase` (all threads) inside Lanczos' one-thread loop."""


def _streaming(columns: int):
    return threads.gemm_phase() if columns >= STREAM_COLUMNS else contextlib.nullcontext()


def _purify(X, omega2, sigma, M, solve):
    """One operator step ``x ← (λ - σ) (K - σM)⁻¹ M x`` for a singular M (massless DOFs).

    Lanczos vectors are M-orthonormal, and M does not see components in its null space:
    the computed eigenvectors carry such components unchecked (measured residuals of 1e46
    and more on a lumped-mass beam). One step of the operator removes them and leaves
    true eigenvectors unchanged (B. Nour-Omid, B. N. Parlett, T. Ericsson, P. S. Jensen,
    "How to implement the spectral transformation", Math. Comp. 48 (1987) 663-673).
    """
    return solve(M @ X) * (omega2 - sigma)


def _merge(omega2, X, more_omega2, more_X):
    omega2 = np.concatenate([omega2, more_omega2])
    order = np.argsort(omega2)
    return omega2[order], np.hstack([X, more_X])[:, order]


def default_shift(K, M, scale: float | None = None) -> float:
    """Shift below zero, ``-1e-6`` times ``scale`` (default :func:`eigenvalue_scale`)."""
    return -1e-6 * (eigenvalue_scale(K, M) if scale is None else scale)


def _n_mass(M) -> int:
    """DOFs with positive mass diagonal: an upper bound of rank(M) (M is semi-definite, so a
    zero diagonal entry is a zero row) and of the number of finite eigenvalues."""
    return int(np.count_nonzero(np.asarray(M.diagonal()) > 0))


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
        Shift; default :func:`default_shift` (n_modes) or the band centre (band).
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
        :func:`eigenvalue_scale`. Give it when the diagonal of K does not show it, e.g.
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
    _check_request(n, _n_mass(M), n_modes, band, sigma, factor, scale)
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
                _complete_cluster(omega2, n_modes) == wanted:
            omega2, X = dense_symmetric(K, M, sigma=shift)  # a cluster fills the subset
        omega2, X = _select(omega2, X, n_modes, band)
        method = "dense"
    elif n_modes is not None:
        omega2, X, count, cut, shift = _sparse_lowest(K, M, n_modes, shift, factor, check,
                                                      scale, movable=sigma is None)
        method = "arpack"
    elif band[0] == -np.inf and (sigma is None or factor is None and sigma < 0):
        omega2, X, count, cut, shift = _sparse_from_zero(K, M, band[1], shift, check, scale,
                                                         movable=sigma is None)
        method = "arpack"
    else:
        omega2, X, shift = _sparse_band(K, M, band, sigma, factor)
        method = "arpack"
    X = normalize_modes(X, M)
    num, den = _residual_terms(K, M, omega2, X, 1e-6 * scale)
    res = num / np.where(den > 0, den, 1.0)
    limits = residual_limits(K, X, den)
    if res.size and (res > limits).any():
        k = int(np.argmax(res / limits))
        warnings.warn(f"eigen solve: relative residual {res[k]:.2e} of mode {k + 1} exceeds"
                      f" {limits[k]:.1e} (1e-6, or 100 times its round-off level)",
                      FemmechWarning, stacklevel=2)
    if method == "dense":
        count, cut = None, None
    solver = None if method == "dense" else (
        direct.resolve(None, n) if factor is None else getattr(factor, "name", "user"))
    return EigenResult(omega2, X, method, shift, res, count, cut, solver=solver)


def _cut_above(lam: float, scale: float) -> float:
    return lam + 1e-6 * max(abs(lam), 1e-6 * scale)


def _select(omega2, X, n_modes, band):
    if band is not None:
        keep = (omega2 >= band[0]) & (omega2 <= band[1])
        return omega2[keep], X[:, keep]
    count = _complete_cluster(omega2, min(n_modes, len(omega2)))
    return omega2[:count], X[:, :count]


def _sparse_lowest(K, M, n_modes, sigma, factor=None, check=True, scale=None,
                   movable=False):
    """Lowest ``n_modes`` eigenpairs (plus the rest of a cut cluster), Sturm-checked.

    Returns ``omega2, X, sturm_count, cut, sigma``. ``movable``: σ is the default shift and
    may be moved nearer the wanted eigenvalues where it is far from them
    (:data:`FAR_SHIFT`; one more factorisation). Where the Sturm count shows that a repeated
    eigenvalue has more members than Lanczos found, deflated runs add the missing ones.
    The count factorises ``K - cut M`` with the fill-reducing ordering of the shift's
    factorisation (:meth:`femmech.solve.direct.Factor.factorize_like`).
    """
    n = K.shape[0]
    scale = eigenvalue_scale(K, M) if scale is None else scale
    lu = factorize(K - sigma * M, definite=None if sigma < 0 else False) \
        if factor is None else factor
    guard = max(4, n_modes // 5)
    limit = min(n - 2, _n_mass(M) - 1)  # below the Krylov dimension (and ARPACK's k < n - 1)
    while True:
        k = min(n_modes + guard, limit)
        if k < n_modes:
            raise ValueError(f"{n_modes} modes of a {n}-DOF system with {_n_mass(M)} DOFs with"
                             " mass: use the dense path (raise dense_below) or ask for fewer"
                             " modes")
        try:
            omega2, X = _lowest_pairs(K, M, k, sigma, lu, n_wanted=n_modes, far_check=movable)
        except _FarShiftError as far:
            sigma, movable = far.shift, False  # (the same ordering: no new analysis)
            lu = lu.factorize_like(K - sigma * M, definite=None if sigma < 0 else False)
            continue
        count = _complete_cluster(omega2, n_modes)
        if count < k or k == limit:
            break
        guard *= 2  # a cluster of repeated eigenvalues fills all computed modes
    if not check:
        return omega2[:count], X[:, :count], None, None, sigma
    for _ in range(MAX_DEFLATIONS):
        # every computed eigenvalue up to the cut counts: where the cut (a relative 1e-6
        # above the last wanted one, or the absolute floor of the scale) passes further
        # computed ones, they are part of the verified set
        cut = _cut_above(omega2[count - 1], scale)
        inside = int(np.count_nonzero(omega2 <= cut))
        below = inertia_below(K, M, cut, like=lu)
        if below is None:
            return omega2[:count], X[:, :count], None, cut, sigma
        if below == inside:
            return omega2[:inside], X[:, :inside], below, cut, sigma
        if below < inside:
            raise RuntimeError(f"Sturm check: {below} eigenvalues lie below {cut:.6g} rad²/s²"
                               f" but the solver returned {inside}")
        # eigenvalues below the cut were missed (members of a cluster): find them with the
        # found ones deflated, then count again (the cut moves down if lower ones appear)
        extra = min(below - inside + guard, n - 2 - inside)
        omega2, X = _merge(omega2[:inside], X[:, :inside],
                           *_lowest_pairs(K, M, extra, sigma, lu, deflate=X[:, :inside]))
        count = _complete_cluster(omega2, min(n_modes, omega2.size))
    raise RuntimeError(f"Sturm check: eigenvalues below {cut:.6g} rad²/s² still missing after"
                       f" {MAX_DEFLATIONS} deflated restarts; try another sigma")


def _sparse_from_zero(K, M, hi, sigma, check, scale, movable):
    """All eigenpairs with ``λ <= hi`` of a positive semi-definite pencil (a band from 0).

    The Sturm count below ``hi`` gives their number n; they are the n lowest, found by
    :func:`_sparse_lowest` with the shift σ < 0 of the lowest-modes path, so that a
    singular K (rigid-body modes, computed λ of either sign) is never factorised, and
    Sturm-checked there (the count reuses the ordering of the factorisation of
    ``K - σM``). Returns ``omega2, X, sturm_count, cut, sigma``.
    """
    lu = factorize(K - sigma * M, definite=None if sigma < 0 else False)
    n_below = inertia_below(K, M, hi, like=lu)
    if n_below is None:
        raise RuntimeError("band search needs a Sturm count, which failed for this pencil;"
                           " ask for n_modes instead")
    if n_below == 0:
        return np.empty(0), np.empty((K.shape[0], 0)), 0, hi, sigma
    omega2, X, count, cut, sigma = _sparse_lowest(K, M, n_below, sigma, lu, check, scale,
                                                  movable=movable)
    keep = omega2 <= hi
    if np.count_nonzero(keep) != n_below:
        raise RuntimeError(f"band search found {np.count_nonzero(keep)} of {n_below}"
                           f" eigenvalues (Sturm count) below {hi:.6g} rad²/s²")
    return omega2[keep], X[:, keep], count, cut, sigma


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
        omega2, X = _merge(omega2, X, *_arpack(K, M, k, shift, lu, deflate=X))
        keep = (omega2 >= lo) & (omega2 <= hi)
        omega2, X = omega2[keep], X[:, keep]
        if omega2.size >= count:
            break
    if omega2.size != count:
        raise RuntimeError(f"band search found {omega2.size} of {count} eigenvalues"
                           f" (Sturm count) in [{lo:.6g}, {hi:.6g}] rad²/s²")
    return omega2, X, shift
