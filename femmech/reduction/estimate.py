"""Stage 3: a-posteriori error estimate of a superelement's reduced frequencies.

Estimates how far the eigenfrequencies of a reduced model lie above those of the full
model from the residuals of the reduced eigenpairs on the interior DOFs, reusing the
``K_ii`` factorisation of the reduction (no solve of the full model).

Imports :mod:`femmech.fe`, :mod:`femmech.solve` and its own package.
"""

from __future__ import annotations

import numpy as np

from femmech.fe.model import FEModel
from femmech.reduction.superelement import Superelement
from femmech.solve.pencil import factorize


def frequency_error_estimates(model: FEModel, se: Superelement, omega2: np.ndarray,
                              q: np.ndarray) -> np.ndarray:
    """A-posteriori relative frequency errors of reduced eigenpairs, without a full solve.

    For a Ritz pair (λ̃, x = T q) with mass-normalised x, the residual
    ``r = K x - λ̃ M x`` vanishes on the interface in the reduced sense
    (``r_b = -Ψᵀ r_i``), so ``K⁻¹ r = [0; K_ii⁻¹ r_i]`` and the eigenvalue error is
    estimated by ``λ̃ - λ ≈ rᵀ (K - λ M)⁻¹ r ≈ r_iᵀ K_ii⁻¹ r_i`` (exact to first order
    in λ / ω²_truncated). The relative frequency error is half the relative eigenvalue
    error. Reuses the K_ii factorisation of the reduction.

    Parameters
    ----------
    model : FEModel
        The model that was reduced.
    se : Superelement
    omega2 : ndarray (n_modes,)
        Reduced eigenvalues, rad²/s².
    q : ndarray (n_r, n_modes)
        Reduced eigenvectors, mass-normalised with ``se.M``.

    Returns
    -------
    ndarray (n_modes,)
        Estimated ``(f_reduced - f_full) / f_full``; 0 for rigid-body modes (λ̃ ≈ 0).
    """
    lu = se.interior_factor
    K, M = model.K_free.tocsr(), model.M_free.tocsr()
    interior = se.free_interior
    if lu is None:
        lu = factorize(K[interior][:, interior])
    u = se.expand_free(q)
    r = (K[interior] @ u) - (M[interior] @ u) * omega2
    eta = np.einsum("ij,ij->j", r, lu.solve(r))
    scale = np.abs(se.K).max() / max(np.abs(se.M).max(), 1e-300)
    rigid = np.abs(omega2) <= 1e-12 * scale
    return np.where(rigid, 0.0, 0.5 * eta / np.where(rigid, 1.0, omega2))
