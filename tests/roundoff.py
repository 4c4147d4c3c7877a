"""Round-off scales of the tests' reference problems.

A tolerance at round-off level must follow from the problem, not from what one BLAS kernel
(or thread count) happened to give: summation order differs between OpenBLAS kernels
(Haswell, SkylakeX, Zen, ...) and thread counts, so a result that is 4e-14 on one machine
may be 2e-12 on another. The scales used (as in scipy's ``_get_test_tolerance`` and the
LAPACK Users' Guide, ch. 4.7 and 4.8):

* a backward-stable symmetric eigensolver (dense LAPACK on the Cholesky-reduced pencil,
  shift-inverted Lanczos or ARPACK on a backward-stable factorisation) returns
  eigenvalues of a pencil perturbed by ~eps ‖K‖ (M-weighted), so each eigenvalue
  moves by ~eps λ_max (Weyl): absolute error ``eps λ_max``, relative error
  ``eps λ_max / λ_k``, largest for the lowest modes;
* eigenvectors (subspaces) of a group separated by ``gap`` from the rest move by
  ~eps λ_max / gap (Davis-Kahan);
* a linear solve ``A x = b`` has relative forward error ~eps cond(A).

Convention: a test tolerance below 1e-8 carries a comment ``# bound: ...`` on its line or
on one of the 3 lines above, naming the solver tolerance or round-off bound (one of the
above, or ~n eps·scale for values zero by construction) that justifies it;
``test_tolerance_bounds.py`` enforces it (docs/accuracy.md).

Imported as a top-level module, like ``hard_cases/hard_models.py``: ``tests/conftest.py``
puts this folder on ``sys.path`` (pytest's ``prepend`` import mode).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

EPS = np.finfo(float).eps
DENSE_BELOW = 50
"""Pencils below this size get λ_max from dense LAPACK, larger ones from ARPACK."""


def largest_eigenvalue(K, M) -> float:
    """λ_max of the pencil ``K φ = λ M φ`` (rad²/s² for FE matrices): the round-off scale.

    ARPACK in regular mode (needs M positive definite), converged to 1e-6 relative, which
    is ample for a tolerance (30 ms at 1 500 DOFs); dense LAPACK below
    :data:`DENSE_BELOW` DOFs and for a singular M (massless DOFs: infinite eigenvalues,
    of which the largest finite one is returned).
    """
    n = K.shape[0]
    if n >= DENSE_BELOW:
        try:
            return float(spla.eigsh(sp.csc_matrix(K), k=1, M=sp.csc_matrix(M), which="LA",
                                    tol=1e-6, v0=np.ones(n), return_eigenvectors=False)[0])
        except RuntimeError:  # M singular: splu of M fails
            pass
    Kd = K.toarray() if sp.issparse(K) else np.asarray(K, dtype=float)
    Md = M.toarray() if sp.issparse(M) else np.asarray(M, dtype=float)
    lam = sla.eig(Kd, Md, right=False)
    return float(np.max(np.abs(lam[np.isfinite(lam)])))


def eigenvalue_atol(K, M, factor: float = 10.0) -> float:
    """Absolute round-off of the eigenvalues of ``(K, M)``: ``factor · eps · λ_max``.

    ``factor`` 10 covers the constants of the backward error (a few eps per entry of
    the reduced or factorised pencil) without reaching truncation errors.
    """
    return factor * EPS * largest_eigenvalue(K, M)


def scaled_condition(A) -> float:
    """cond₂ of ``D A D``, ``D = diag(A)^-1/2``, for a symmetric positive definite ``A``.

    The round-off scale of badly scaled pencils (thin shells: rotations with inertia
    ρt³/12 beside translations): a perturbation that is small relative to each entry's own
    scale, as from a Cholesky or LDLᵀ factorisation, moves the eigenvalues of a definite
    pencil by ~eps cond₂(D A D) relative (Demmel and Veselić, Jacobi's method is more
    accurate than QR, SIAM J. Matrix Anal. Appl. 13(4), 1992, section 2), which can be
    orders of magnitude below eps λ_max / λ. Dense: for matrices of up to a few
    thousand rows.
    """
    A = A.toarray() if sp.issparse(A) else np.asarray(A, dtype=float)
    d = 1.0 / np.sqrt(np.diag(A))
    ev = np.linalg.eigvalsh(d[:, None] * A * d[None, :])
    return float(ev[-1] / ev[0])


def eigenvalue_rtol(lam, lam_max: float, factor: float = 10.0) -> np.ndarray:
    """Relative round-off of each eigenvalue ``lam`` (ascending, positive) of a pencil with
    largest eigenvalue ``lam_max``: ``factor · eps · (λ_max / λ_k + λ_k / λ_1)``.

    The first term is the backward error of any stable solver (absolute eps λ_max, see the
    module docstring). The second is that of shift-inverted Lanczos (ARPACK, femmech's
    block Lanczos, σ ≲ λ_1): it resolves θ = 1 / (λ - σ) to ~eps θ_1 absolute, so λ_k to
    ~eps λ_k / λ_1 relative, which dominates for the highest of many computed modes.
    """
    lam = np.abs(np.asarray(lam, dtype=float))
    return factor * EPS * (lam_max / lam + lam / lam[0])
