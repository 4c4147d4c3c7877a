"""The impedance smearing of the continuum (:mod:`.continuum`): the units' exact dynamic
stiffness on their nodes, averaged over the units, and the continuum's roots and vectors
from it.

Each unit u is condensed exactly onto its node (as in :mod:`.transfer`):
d_u(λ) = C_aa − λ M_aa − Σ_r (α_r − λ β_r)² / (μ_r − λ) (N m/rad). Its mean
d̄(λ) = (1/N) Σ_u d_u(λ) does not depend on the units' internal coordinates; the
continuum's roots of wave j (shaft stiffness κ_j = k μ_j²) solve κ_j − λ J + d̄(λ) = 0.

Stage 6 (chain): numpy; imports the chain's cyclic helpers and the transfer method's
unit condensation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femmech.chain.cyclic import symmetric_unit_matrices

POLE_RTOL = 1e-10
"""Internal eigenvalues μ of different units closer than this (relative) are one pole of
the smeared dynamic stiffness."""

@dataclass(frozen=True)
class _Impedance:
    """The units' exact condensation onto their nodes at one drive angle (coordinate-free):
    d_u(λ) = C_aa − λ M_aa − Σ_r (α_r − λβ_r)² / (μ_r − λ), averaged over the units."""

    caa: np.ndarray   # (U,)
    maa: np.ndarray   # (U,)
    alpha: np.ndarray  # (U, m-1)
    beta: np.ndarray   # (U, m-1)
    mu: np.ndarray     # (U, m-1)
    poles: np.ndarray  # distinct coupled internal eigenvalues, ascending
    free_poles: np.ndarray  # internal eigenvalues no unit couples to its node

    def mean(self, lam: np.ndarray) -> np.ndarray:
        """d̄(λ) = (1/N) Σ_u d_u(λ), N m/rad, for λ (L,)."""
        d = self.caa.mean() - lam * self.maa.mean()
        if self.mu.shape[1]:
            g = self.alpha[:, :, None] - lam * self.beta[:, :, None]
            with np.errstate(divide="ignore", invalid="ignore"):
                term = np.where(g == 0, 0.0, g * g / (self.mu[:, :, None] - lam))
            d = d - term.sum(axis=(0, 1)) / self.caa.size
        return d


def chain_impedance(chain, phi, Omega, Omega_dot) -> _Impedance:
    from femmech.chain.transfer import internal_modes

    Mu, Cu = symmetric_unit_matrices(chain, phi, Omega, Omega_dot)
    a = chain.attach
    inner = np.array([i for i in range(chain.m) if i != a], dtype=int)
    mu, _, alpha, beta = internal_modes(Mu, Cu, a, inner)
    residue = np.abs(alpha - mu * beta)
    size = float((np.abs(alpha) + np.abs(mu * beta)).max(initial=0.0))
    coupled = residue > 1e-12 * max(size, 1e-300)
    poles = _distinct(mu[coupled])
    free = _distinct(mu[~coupled])
    if poles.size and free.size:
        near = np.min(np.abs(free[:, None] - poles), axis=1) <= POLE_RTOL * np.abs(free)
        free = free[~near]
    return _Impedance(Cu[:, a, a], Mu[:, a, a], alpha, beta, mu, poles, free)


def _distinct(values) -> np.ndarray:
    v = np.sort(np.asarray(values, dtype=float).ravel())
    if v.size == 0:
        return v
    keep = np.concatenate([[True], np.diff(v) > POLE_RTOL * np.maximum(np.abs(v[1:]), 1e-300)])
    return v[keep]


def impedance_roots(imp: _Impedance, kappa: np.ndarray, J: float) -> tuple:
    """Roots of h_j(λ) = κ_j − λ J + d̄(λ) = 0 for every κ_j (rad²/s²): one in each
    interval between neighbouring poles of d̄ and below the lowest / above the highest
    (h decreases strictly between poles: dh/dλ = −J − mean_u vᵀ M_u v), plus the
    decoupled internal eigenvalues (a root for every κ). Returns (λ (K·P,), wave index
    (K·P,)), by vectorised bisection to round-off."""
    kappa = np.asarray(kappa, dtype=float)
    P = imp.poles
    scale = max(float(np.abs(kappa).max(initial=0.0)) / max(J + imp.maa.mean(), 1e-300),
                float(np.abs(P).max(initial=0.0)), 1.0)

    def h(lam, k):
        return k - lam * J + imp.mean(lam)

    lo = -scale
    for _ in range(200):
        if np.all(h(np.full(kappa.size, lo), kappa) > 0):
            break
        lo *= 4.0
    hi = 2.0 * max(scale, float(P.max(initial=0.0)))
    for _ in range(200):
        if np.all(h(np.full(kappa.size, hi), kappa) < 0):
            break
        hi *= 4.0
    eps = 1e-13
    gap = eps * np.maximum(np.abs(P), 1e-6 * scale)
    edges = np.concatenate([[lo], np.ravel(np.column_stack([P - gap, P + gap])), [hi]])
    a, b = edges[0::2], edges[1::2]  # intervals (a_i, b_i), P + 1 of them
    A = np.repeat(a[None, :], kappa.size, 0).ravel()
    B = np.repeat(b[None, :], kappa.size, 0).ravel()
    K = np.repeat(kappa[:, None], a.size, 1).ravel()
    wave = np.repeat(np.arange(kappa.size)[:, None], a.size, 1).ravel()
    for _ in range(200):
        mid = 0.5 * (A + B)
        up = h(mid, K) > 0
        A, B = np.where(up, mid, A), np.where(up, B, mid)
        if np.all(B - A <= 4 * np.finfo(float).eps * np.maximum(np.abs(A), np.abs(B))):
            break
    lam = 0.5 * (A + B)
    if imp.free_poles.size:
        lam = np.concatenate([lam, np.repeat(imp.free_poles[None, :], kappa.size, 0).ravel()])
        wave = np.concatenate([wave, np.repeat(np.arange(kappa.size)[:, None],
                                               imp.free_poles.size, 1).ravel()])
    return lam, wave


def impedance_vectors(chain, phi, lam, shapes, imp, Omega, Omega_dot) -> np.ndarray:
    """Assembled vectors of the impedance continuum: node rotations Θ_j(x_i), each unit's
    internal coordinates its exact response x_u = −D_ii⁻¹ D_ia Θ_j(x_u) at λ (for a
    decoupled internal root: the unit's internal mode, amplitude Θ_j(x_u), shaft at rest);
    M-normalised. ``shapes`` (N, K) one column per root."""
    Mu, Cu = symmetric_unit_matrices(chain, phi, Omega, Omega_dot)
    a = chain.attach
    inner = np.array([i for i in range(chain.m) if i != a], dtype=int)
    out = np.zeros((chain.n, lam.size))
    theta = shapes[chain.unit_node]  # (U, K)
    for k, x in enumerate(lam):
        D = Cu - x * Mu
        w = np.zeros((chain.n_units, chain.m))
        decoupled = imp.free_poles.size and np.any(
            np.abs(imp.free_poles - x) <= POLE_RTOL * abs(x))
        if inner.size and decoupled:
            Dii = D[:, inner[:, None], inner]
            _, vecs = np.linalg.eigh(Dii)  # null vector of D_ii: the internal mode
            w[:, inner] = vecs[:, :, 0]
        else:
            w[:, a] = 1.0
            if inner.size:
                rhs = D[:, inner, a][..., None]
                w[:, inner] = -np.linalg.solve(D[:, inner[:, None], inner], rhs)[..., 0]
        vals = theta[:, k, None] * w
        for c in range(chain.m):
            out[chain.unit_dofs[:, c], k] = vals[:, c]
    M = chain.sparse_matrices(float(phi))[0]
    return out / np.sqrt(np.einsum("ik,ik->k", out, M @ out))
