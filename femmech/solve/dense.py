"""Dense path of the eigen solver: all (or the lowest) eigenpairs of a small symmetric
pencil by LAPACK on the shift-inverted pencil (:func:`dense_symmetric`).

Stage 1, solve (linear algebra): imports only :mod:`femmech.errors` and other
:mod:`femmech.solve` modules, never :mod:`femmech.fe` or higher.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from femmech.solve.pencil import default_shift

ALL_PAIRS_FRACTION = 1 / 7
""":func:`dense_symmetric` computes all n eigenpairs (LAPACK ``sygvd``, divide and
conquer) when at least this fraction of them is wanted, otherwise only the wanted ones
(``sygvx``). Crossover measured between n/8 and n/6 at 76-322 coordinates (frozen-angle
solves of the textile shaft's sweep): 21 of 76 pairs took 0.6 ms instead of 0.9 ms."""


def dense_symmetric(K, M, n_modes: int | None = None, sigma: float | None = None):
    """All (or the lowest ``n_modes``) eigenpairs of a dense symmetric pencil, ascending.

    Solves the shift-inverted pencil ``M x = μ (K - σ M) x``, ``λ = σ + 1/μ`` with
    σ < 0 (default :func:`~.pencil.default_shift`) by LAPACK, like shift-invert Lanczos: the
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
