"""Dense pencil solver: every small (frozen-angle, reduced, chain) eigenproblem of femmech.

Three forms, each for one pencil (n, n) or a stack of them (a, n, n):

* symmetric ``K x = λ M x`` (:func:`dense_symmetric`, :func:`symmetric_pencil`,
  :func:`shift_inverted_stack`): by default LAPACK on the shift-inverted pencil
  ``M x = μ (K - σ M) x`` (``sygvd`` for all pairs, ``sygvx`` for a few); the
  ``driver`` option keeps the other two routines callers use: ``"plain"`` (LAPACK
  ``sygvd``/``sygvx`` on ``K x = λ M x`` itself, :func:`scipy.linalg.eigh`) and
  ``"standard"`` (Cholesky ``M = L Lᵀ`` and the batched standard ``eigh`` of
  ``L⁻¹ K L⁻ᵀ``);
* unsymmetric ``C v = λ M v`` (:func:`unsymmetric_pencil`: QZ, :func:`scipy.linalg.eig`);
* damped ``(s² M + s B + C) v = 0`` (:func:`damped_pencil`: QZ of the first-order form
  ``[[0, I], [-C, -B]] z = s [[I, 0], [0, M]] z``).

Each caller gets the same LAPACK routine on the same matrices as before the solvers were
gathered here, so its numbers are unchanged.

Stage 1, solve (linear algebra): imports only :mod:`femmech.errors` and other
:mod:`femmech.solve` modules, never :mod:`femmech.fe` or higher.
"""

from __future__ import annotations

import functools

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from femmech.solve.pencil import default_shift
from femmech.solve.tolerances import INFINITE_MU_RTOL

ALL_PAIRS_FRACTION = 1 / 7
""":func:`dense_symmetric` computes all n eigenpairs (LAPACK ``sygvd``, divide and
conquer) when at least this fraction of them is wanted, otherwise only the wanted ones
(``sygvx``); the crossover is measured in benchmarks/README.md (reduced_sweep)."""

SYMMETRIC_DRIVERS = ("shift-invert", "plain", "standard")
"""Routines of :func:`symmetric_pencil` (see the module docstring)."""


class PencilError(np.linalg.LinAlgError):
    """A LAPACK routine of the shift-inverted pencil failed (``info != 0``: ``K - σM`` not
    positive definite, no convergence) or the pencil has infinite eigenvalues."""


def dense_symmetric(K, M, n_modes: int | None = None, sigma: float | None = None):
    """All (or the lowest ``n_modes``) eigenpairs of a dense symmetric pencil, ascending.

    Solves the shift-inverted pencil ``M x = μ (K - σ M) x``, ``λ = σ + 1/μ`` with
    σ < 0 (default :func:`~.pencil.default_shift`) by LAPACK, like shift-invert Lanczos: the
    lowest modes (largest μ) come out with relative accuracy ~eps however wide the
    spectrum (``eigh(K, M)`` resolves them only to ~eps·λ_max), K may be singular
    (rigid-body modes) and M may be singular (massless DOFs: μ = 0, infinite λ, dropped).
    Vectors are mass-normalised (``XᵀMX = I``). K, M (n, n) dense or sparse; the driver
    follows :data:`ALL_PAIRS_FRACTION`. Returns λ (q,) rad²/s² and X (n, q).
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
    finite = mu > INFINITE_MU_RTOL * max(np.abs(mu).max(), 1e-300)
    omega2 = sigma + 1.0 / mu[finite]
    X = X[:, finite] / np.sqrt(mu[finite])  # Xᵀ(K - σM)X = I gives XᵀMX = diag(μ)
    order = np.argsort(omega2)
    return omega2[order], X[:, order]


def symmetric_pencil(K, M, n_modes: int | None = None, driver: str = "shift-invert"):
    """The lowest ``n_modes`` (default all) eigenpairs of symmetric ``K x = λ M x``.

    K, M (n, n) or stacks (a, n, n); returns λ (q,) or (a, q), rad²/s², ascending, and X
    (n, q) or (a, n, q). ``driver`` (:data:`SYMMETRIC_DRIVERS`): ``"shift-invert"``
    (:func:`dense_symmetric`: the lowest modes accurate however wide the spectrum, M may be
    singular), ``"plain"`` (:func:`scipy.linalg.eigh` of ``(K, M)``, ``subset_by_index``
    for a subset; M positive definite) or ``"standard"`` (``M = L Lᵀ``, batched
    :func:`numpy.linalg.eigh` of the symmetrised ``L⁻¹ K L⁻ᵀ``, all pairs; M positive
    definite, raises :class:`numpy.linalg.LinAlgError` otherwise). Vectors are
    M-normalised by the routine.
    """
    if driver not in SYMMETRIC_DRIVERS:
        raise ValueError(f"driver must be one of {', '.join(SYMMETRIC_DRIVERS)},"
                         f" got {driver!r}")
    if driver == "standard":
        stack = np.asarray(M).ndim == 3
        M3, K3 = (np.asarray(A, dtype=float) if stack else np.asarray(A, dtype=float)[None]
                  for A in (M, K))  # one pencil as a stack of one
        L = np.linalg.cholesky(M3)
        lam, W = np.linalg.eigh(standard_form(M3, K3, L))
        X = np.linalg.solve(np.swapaxes(L, 1, 2), W)
        if n_modes is not None:
            lam, X = lam[:, :n_modes], X[:, :, :n_modes]
        return (lam, X) if stack else (lam[0], X[0])

    def one(Ki, Mi):
        if driver == "shift-invert":
            return dense_symmetric(Ki, Mi, n_modes)
        if n_modes is None:
            return sla.eigh(Ki, Mi)
        k = min(int(n_modes), Mi.shape[0])
        return sla.eigh(Ki, Mi, subset_by_index=[0, k - 1])

    return _each(one, K, M)


def standard_form(M, K, L=None) -> np.ndarray:
    """``L⁻¹ K L⁻ᵀ`` (symmetrised) with ``M = L Lᵀ``: the standard form of ``K v = λ M v``,
    batched (a, n, n); ``L`` the Cholesky factors if already formed."""
    L = np.linalg.cholesky(M) if L is None else L
    X = np.linalg.solve(L, K)  # L⁻¹ K
    A = np.linalg.solve(L, np.swapaxes(X, 1, 2))  # L⁻¹ K L⁻ᵀ
    return 0.5 * (A + np.swapaxes(A, 1, 2))


def unsymmetric_pencil(C, M):
    """All eigenpairs of ``C v = λ M v`` by QZ (:func:`scipy.linalg.eig`), unsorted.

    C, M (n, n) or stacks (a, n, n); returns λ (n,) or (a, n) complex (infinite where M is
    singular) and V (n, n) or (a, n, n) complex, LAPACK's normalisation."""
    return _each(sla.eig, C, M)


def damped_pencil(M, B, C):
    """All roots s of ``(s² M + s B + C) v = 0`` by QZ of the first-order form.

    ``[[0, I], [-C, -B]] z = s [[I, 0], [0, M]] z`` with ``z = [v; s v]``. M, B, C (n, n) or
    stacks (a, n, n); returns s (2n,) or (a, 2n) complex, 1/s, and Z (2n, 2n) or
    (a, 2n, 2n) (its first n rows are the mode shapes v)."""

    def one(Mi, Bi, Ci):
        n = Mi.shape[0]
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-Ci, -Bi]])
        E = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), Mi]])
        return sla.eig(A, E)

    return _each(one, M, B, C)


def shift_inverted_stack(Mf, Af, wanted: int):
    """The ``wanted`` largest μ of ``M x = μ A x`` (A = K - σM) and their vectors, per pencil.

    ``Mf``, ``Af`` (a, n, n): C-contiguous stacks of the transposes of M and A (``Mf[i].T``
    is M[i], Fortran order, so LAPACK reads them without a copy; both are overwritten).
    The routine follows :data:`ALL_PAIRS_FRACTION` as in :func:`dense_symmetric`
    (:func:`sygvd_largest` or :func:`sygvx_largest`), the same calls and bits. Returns μ
    (a, wanted) ascending and X (a, n, wanted); raises :class:`PencilError` where LAPACK
    fails.
    """
    k, n = Mf.shape[:2]
    mu, X = np.empty((k, wanted)), np.empty((k, n, wanted))
    solve = sygvd_largest if wanted >= ALL_PAIRS_FRACTION * n else sygvx_largest
    for i in range(k):
        mu[i], X[i] = solve(Mf[i].T, Af[i].T, wanted)
    return mu, X


def sygvd_largest(M, A, wanted: int):
    """The ``wanted`` largest μ of ``M x = μ A x`` and their vectors by LAPACK ``sygvd``,
    as :func:`dense_symmetric` calls it (M, A (n, n) overwritten); :class:`PencilError`
    where LAPACK fails."""
    mu, X, info = sla.lapack.dsygvd(M, A, uplo="L", overwrite_a=1, overwrite_b=1)
    if info:
        raise PencilError(f"sygvd info {info}")
    return mu[-wanted:], X[:, -wanted:]


def sygvx_largest(M, A, wanted: int):
    """As :func:`sygvd_largest` by ``sygvx`` (range 'I'), the call of
    :func:`scipy.linalg.eigh` with ``subset_by_index`` (same workspace, hence the same
    blocking and bits)."""
    n = len(M)
    mu, X, m, _, info = sla.lapack.dsygvx(M, A, uplo="L", jobz="V", range="I", il=n - wanted + 1,
                                          iu=n, lwork=sygvx_lwork(n), overwrite_a=1,
                                          overwrite_b=1)
    if info or m != wanted:
        raise PencilError(f"sygvx info {info}")
    return mu[:m], X[:, :m]


@functools.cache
def sygvx_lwork(n: int) -> int:
    """Workspace of ``sygvx`` for order n as :func:`scipy.linalg.eigh` queries it (LAPACK's
    optimal size from ``dsygvx_lwork``, rounded down to an integer as scipy does)."""
    lwork, info = sla.lapack.dsygvx_lwork(n, uplo="L")
    if info:
        raise PencilError(f"sygvx workspace query info {info}")
    return int(lwork.real if np.iscomplexobj(lwork) else lwork)


def _each(solve, *arrays):
    """``solve`` of one pencil, or of each pencil of a stack (a, n, n) stacked."""
    if np.asarray(arrays[0]).ndim != 3:
        return solve(*arrays)
    out = [solve(*parts) for parts in zip(*arrays, strict=True)]
    return tuple(np.array([o[j] for o in out]) for j in range(len(out[0])))
