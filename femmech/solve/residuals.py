"""Computed eigenpairs of ``K x = λ M x``: mass normalisation with a fixed sign, relative
residuals, and the limit above which a residual is reported (the larger of
:data:`RESIDUAL_TOL` and its round-off level).

Stage 1, solve (linear algebra): imports only :mod:`femmech.errors` and other
:mod:`femmech.solve` modules, never :mod:`femmech.fe` or higher.
"""

from __future__ import annotations

import numpy as np


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
    num, den = residual_terms(K, M, omega2, vectors, floor)
    return num / np.where(den > 0, den, 1.0)


def residual_terms(K, M, omega2, vectors, floor: float):
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


MAX_NAMED = 5
"""Modes named in one residual warning; the others are counted."""


def residual_message(residual, limits, omega2) -> str | None:
    """The warning text for modes whose relative residual exceeds its limit, or None.

    Names each such mode by its number (1-based, in the order computed) and frequency,
    the worst (largest residual / limit) first, e.g. ``"eigen solve: mode 3 (f = 12.5
    Hz): relative residual 2.1e-05 exceeds 1.0e-06; ..."``.

    Parameters
    ----------
    residual, limits : ndarray (n_modes,)
        :func:`residuals` and :func:`residual_limits`.
    omega2 : ndarray (n_modes,), rad²/s²
        Eigenvalues (negative round-off of rigid-body modes shows as f = 0 Hz).
    """
    residual, limits = np.asarray(residual, dtype=float), np.asarray(limits, dtype=float)
    over = np.flatnonzero(residual > limits)
    if not over.size:
        return None
    ratio = np.divide(residual[over], limits[over], out=np.full(over.size, np.inf),
                      where=limits[over] > 0)
    over = over[np.argsort(-ratio, kind="stable")]
    freq = np.sqrt(np.clip(np.asarray(omega2, dtype=float), 0.0, None)) / (2 * np.pi)
    named = [f"mode {k + 1} (f = {freq[k]:.4g} Hz): relative residual {residual[k]:.2e}"
             f" exceeds {limits[k]:.1e}" for k in over[:MAX_NAMED]]
    more = f"; and {over.size - MAX_NAMED} more modes" if over.size > MAX_NAMED else ""
    return ("eigen solve: " + "; ".join(named) + more
            + " (limit: 1e-6, or 100 times the residual's round-off level)")


