"""Identical units on a uniform shaft: the chain splits into one small problem per wave.

A chain is *uniform* when every node carries a unit, all units run at the same phase,
all shaft springs ``k`` (N m/rad) and all node inertias ``J`` (kg m²) are equal (build it
with ``chain(..., cells=True)``), no node is clamped and each end is free or held by a
ground spring equal to ``k`` (a clamped node one spacing beyond the end). Then, with the
coordinates ordered node by node, the frozen matrices are Kronecker products

    M = I_N ⊗ (M_u + J e_a e_aᵀ),      C = I_N ⊗ C_u + k L ⊗ e_a e_aᵀ,

``M_u(φ + δ), C_u`` the unit's (m, m) matrices (``M_u[a, a]`` already holds the unit's own
hub inertia and m U'²; ``J`` is the shaft's cell plus station inertia), ``e_a`` the unit
coordinate that is the node rotation and ``L`` the (N, N) path-graph Laplacian with the
end terms. ``L = V diag(2 − 2 cos μ_j) Vᵀ`` with orthonormal V:

    free–free        μ_j = jπ/N,          j = 0 … N−1,  v_i ∝ cos(μ_j (i + ½))
    grounded–free    μ_j = (2j−1)π/(2N+1), j = 1 … N,   v_i ∝ sin(μ_j (i + 1))
    grounded–both    μ_j = jπ/(N+1),      j = 1 … N,    v_i ∝ sin(μ_j (i + 1))

(a free end at the right mirrors ``i → N−1−i``). The wave basis ``T = V ⊗ I_m`` makes both
matrices block diagonal (``Tᵀ M T = I ⊗ M'``, ``Tᵀ C T = blockdiag(C_u + κ_j e_a e_aᵀ)``),
so the chain's n = N m eigenvalues are those of N small problems

    (C_u + κ_j e_a e_aᵀ) w = λ (M_u + J e_a e_aᵀ) w,    κ_j = 2k(1 − cos μ_j),

one Cholesky of the common M' and one batched ``eigh`` for all j (O(N m³)). The mode of
(j, w) is ``v_j ⊗ w``, M-normalised when w is M'-normalised.

Clusters. κ enters as a positive rank-one term, so the r-th eigenvalue λ_r(κ) of the small
problem never decreases with κ (Courant–Fischer): branch r fills the *pass band*
[λ_r(κ_min), λ_r(κ_max)] with exactly N roots (κ_min, κ_max: first and last wave). Between
branches lie *stop bands*: λ_r(κ) ≤ λ_r(∞) ≤ λ_{r+1}(0), λ_r(∞) the unit's eigenvalues with
its node held (``e_a`` removed), λ_{r+1}(0) those on a rigid, unsprung shaft. For the
follower unit (hub J_h, follower m on spring c, cam U) with ``J_r = J + J_h`` and
``J_t = J_r + m U'²``, ``det(C' − λM') = m J_r λ² − (κ m + c J_t) λ + κ c``; its value at
the decoupled follower frequency c/m is −c²U'² and at the coupled one c J_t/(m J_r) it is
−κ c m U'²/J_r: both are ≤ 0, so *no root lies between them* (a stop band of relative
width m U'²/J_r); one branch's N roots pile up just below c/m (roots with
κ_j ≫ c U'² sit within a relative c U'²/κ_j of it), the other starts at the coupled
frequency. The N follower-like modes are therefore a cluster of nearly repeated roots
whose spread is set by m U'² against J and k; in a dwell (U' = 0) they coincide exactly
(N-fold root √(c/m)). :func:`pass_bands` gives the band edges.

Stage 6 (chain): numpy; imports the chain model and result type only.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import eigh

from femmech.chain.results import ChainModes

END_CASES = ("free-free", "grounded-free", "free-grounded", "grounded-grounded")
"""The end conditions of a uniform chain (left–right); "grounded" = ground spring k."""


def _close(a, b, rtol: float) -> bool:
    return bool(abs(a - b) <= rtol * max(abs(a), abs(b)))


def uniformity_problem(chain, rtol: float = 1e-12) -> str | None:
    """The first reason the chain is not uniform (module docstring), or None."""
    N = chain.n_nodes
    if chain.clamped.any():
        return f"node {int(np.flatnonzero(chain.clamped)[0])} is clamped"
    bare = np.setdiff1d(np.arange(N), chain.unit_node)
    if bare.size:
        return f"node {int(bare[0])} carries no unit (every node needs one)"
    d = chain.phase
    for u in range(1, d.size):
        if abs(d[u] - d[0]) > rtol * max(1.0, abs(d[0])):
            return f"unit {u} has phase {d[u]:.6g} rad, unit 0 has {d[0]:.6g} rad"
    J = chain.node_inertia
    for i in range(1, N):
        if not _close(J[i], J[0], rtol):
            return (f"node {i} has inertia {J[i]:.6g} kg m², node 0 has {J[0]:.6g} kg m²"
                    " (build with chain(..., cells=True), no end inertias)")
    k = chain.spring
    for i in range(1, k.size):
        if not _close(k[i], k[0], rtol):
            return f"spring {i} is {k[i]:.6g} N m/rad, spring 0 is {k[0]:.6g} N m/rad"
    g = chain.ground
    inner = np.flatnonzero(g[1:-1]) + 1
    if inner.size:
        return f"node {int(inner[0])} has a ground spring (only the end nodes may)"
    if N > 1:
        for side, value in (("left", g[0]), ("right", g[-1])):
            if value != 0 and not _close(value, k[0], rtol):
                return (f"{side} ground spring is {value:.6g} N m/rad; a uniform chain"
                        f" needs 0 or the shaft spring {k[0]:.6g} N m/rad")
    return None


def is_uniform(chain, rtol: float = 1e-12) -> bool:
    """True when :func:`cyclic_modes` applies (see the module docstring)."""
    return uniformity_problem(chain, rtol) is None


def end_case(chain) -> str:
    """One of :data:`END_CASES` for a uniform chain (N = 1: "free-free" or
    "grounded-free" by whether the node has a ground spring)."""
    left, right = chain.ground[0] > 0, chain.ground[-1] > 0
    if chain.n_nodes == 1:
        return "grounded-free" if left else "free-free"
    return f"{'grounded' if left else 'free'}-{'grounded' if right else 'free'}"


def wave_numbers(n_nodes: int, case: str) -> tuple[np.ndarray, np.ndarray]:
    """Labels j and wave numbers μ_j (rad per spacing) of the path Laplacian, (N,) each."""
    N = int(n_nodes)
    if case == "free-free":
        j = np.arange(N)
        return j, j * np.pi / N
    j = np.arange(1, N + 1)
    if case in ("grounded-free", "free-grounded"):
        return j, (2 * j - 1) * np.pi / (2 * N + 1)
    if case == "grounded-grounded":
        return j, j * np.pi / (N + 1)
    raise ValueError(f"unknown end case {case!r}; known: {', '.join(END_CASES)}")


def wave_vectors(n_nodes: int, case: str) -> np.ndarray:
    """Orthonormal eigenvectors of the path Laplacian, (N, N): column j for wave j."""
    _, mu = wave_numbers(n_nodes, case)
    i = np.arange(n_nodes)[:, None]
    if case == "free-free":
        V = np.cos(mu * (i + 0.5))
    elif case == "free-grounded":
        V = np.sin(mu * (n_nodes - i))
    else:
        V = np.sin(mu * (i + 1))
    return V / np.linalg.norm(V, axis=0)


def laplacian(n_nodes: int, case: str) -> np.ndarray:
    """The (N, N) path-graph Laplacian with the end terms of ``case`` (unit springs)."""
    N = int(n_nodes)
    L = 2 * np.eye(N) - np.eye(N, k=1) - np.eye(N, k=-1)
    L[0, 0] -= 1.0                      # one neighbour at each end ...
    L[-1, -1] -= 1.0
    L[0, 0] += case.startswith("grounded")   # ... plus the ground spring k
    L[-1, -1] += case.endswith("-grounded")
    return L


def symmetric_unit_matrices(chain, phi, Omega: float = 0.0, Omega_dot: float = 0.0):
    """(M_u, C_u) of every unit at φ, (n_units, m, m); ValueError for an unsymmetric C."""
    Mu, _, Cu = chain.unit_matrices(float(phi), Omega, Omega_dot)
    asym = np.abs(Cu - np.swapaxes(Cu, -1, -2)).max()
    if asym > 1e-12 * max(np.abs(Cu).max(), 1e-300):
        raise ValueError(f"the units' stiffness C(φ, Ω = {Omega}, Ω̇ = {Omega_dot}) is"
                         f" unsymmetric (max |C − Cᵀ| = {asym:.3g}); the wave and"
                         " continuum methods need the symmetric frozen problem (Ω = 0)"
                         " — use the assembled model")
    return Mu, Cu


def unit_branches(Mp: np.ndarray, Cu: np.ndarray, kappa, attach: int):
    """Eigenpairs of ``(C_u + κ e_a e_aᵀ) w = λ M' w`` for every κ.

    Parameters
    ----------
    Mp, Cu : ndarray (m, m)
        Symmetric unit mass (with the node inertia added at ``attach``) and stiffness.
    kappa : array_like (K,)
        Shaft stiffness per wave, N m/rad.

    Returns
    -------
    lam : ndarray (K, m)
        Eigenvalues ascending per κ, (rad/s)².
    W : ndarray (K, m, m)
        M'-normalised eigenvectors, ``W[j, :, r]`` for ``lam[j, r]``.
    """
    kappa = np.asarray(kappa, dtype=float).reshape(-1)
    Lc = np.linalg.cholesky(Mp)
    Li = np.linalg.inv(Lc)
    A0 = Li @ Cu @ Li.T
    z = Li[:, attach]
    A = A0 + kappa[:, None, None] * np.outer(z, z)
    lam, Y = np.linalg.eigh(0.5 * (A + np.swapaxes(A, -1, -2)))
    return lam, np.einsum("ij,kjr->kir", Li.T, Y)


def frequencies(lam: np.ndarray, where: str) -> np.ndarray:
    """f = √λ / 2π (Hz); round-off negatives → 0, real negatives raise ValueError."""
    lam = np.asarray(lam, dtype=float)
    floor = -1e-9 * max(np.abs(lam).max(), 1e-300)
    if lam.min(initial=0.0) < floor:
        raise ValueError(f"{where}: quasi-eigenvalue λ = {lam.min():.6g} (rad/s)² < 0, the"
                         " frozen chain is statically unstable there (no real frequency)")
    return np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi)


def _uniform_parts(chain, phi, Omega, Omega_dot):
    problem = uniformity_problem(chain)
    if problem is not None:
        raise ValueError(f"chain is not uniform: {problem}; cyclic_modes needs identical"
                         " cells (use transfer_modes or assembled_modes)")
    Mu, Cu = symmetric_unit_matrices(chain, phi, Omega, Omega_dot)
    Mp = Mu[0].copy()
    Mp[chain.attach, chain.attach] += chain.node_inertia[0]
    case = end_case(chain)
    labels, mu = wave_numbers(chain.n_nodes, case)
    if chain.n_nodes == 1:
        kappa = np.array([chain.ground[0]])
    else:
        kappa = 2 * chain.spring[0] * (1 - np.cos(mu))
    return Mp, Cu[0], case, labels, kappa


def expand(chain, shapes: np.ndarray, W: np.ndarray) -> np.ndarray:
    """Assembled mode vectors (n, K·m) from node shapes (N, K) and unit vectors (K, m, m).

    Column ``j·m + r`` is the node shape j times the unit vector ``W[j, :, r]``.
    """
    K, m = W.shape[0], W.shape[1]
    nodes = shapes[chain.unit_node]                     # (n_units, K)
    out = np.zeros((chain.n, K * m))
    vals = nodes[:, :, None, None] * W[None]            # (n_units, K, m(coord), m(r))
    vals = np.swapaxes(vals, 2, 3).reshape(chain.n_units, K * m, m)
    for c in range(m):
        out[chain.unit_dofs[:, c]] = vals[:, :, c]
    return out


def cyclic_modes(chain, phi: float, *, Omega: float = 0.0, Omega_dot: float = 0.0,
                 vectors: bool = True) -> ChainModes:
    """All n = N m quasi-eigenfrequencies of a uniform chain in closed form per wave.

    Parameters
    ----------
    chain : Chain
        Uniform (see :func:`is_uniform`; otherwise ValueError naming what is not).
    phi : float
        Drive angle, rad.
    Omega, Omega_dot : float
        Speed (rad/s) and acceleration (rad/s²) for C; the problem must stay symmetric.
    vectors : bool
        Also return the (n, n) M-normalised modes ``v_j ⊗ w``.

    Returns
    -------
    ChainModes
        ``method="cyclic"``, ``label`` = wave number j of each root (μ_j of
        :func:`wave_numbers`), frequencies ascending in Hz.
    """
    Mp, Cu, case, labels, kappa = _uniform_parts(chain, phi, Omega, Omega_dot)
    lam, W = unit_branches(Mp, Cu, kappa, chain.attach)
    order = np.argsort(lam.reshape(-1), kind="stable")
    freq = frequencies(lam.reshape(-1)[order], f"cyclic chain at φ = {phi:.6g} rad")
    label = np.repeat(labels, Mp.shape[0])[order]
    vec = None
    if vectors:
        shapes = (np.ones((1, 1)) if chain.n_nodes == 1
                  else wave_vectors(chain.n_nodes, case))
        vec = expand(chain, shapes, W)[:, order]
    return ChainModes(freq, vec, "cyclic", label=label)


def pass_bands(chain, phi: float, *, Omega: float = 0.0, Omega_dot: float = 0.0):
    """Band edges of each branch of a uniform chain (module docstring: clusters).

    Returns
    -------
    bands : ndarray (m, 2)
        Branch r holds exactly N roots, all in ``[bands[r, 0], bands[r, 1]]`` (Hz): the
        branch at the first wave (j = 0, or 1 with a grounded end) and at the last.
    gaps : ndarray (m - 1, 2)
        Stop bands ``[f_r(node held), f_{r+1}(rigid unsprung shaft)]`` (Hz) that no
        root enters, whatever N; for the follower unit: decoupled √(c/m) and coupled
        √(c J_t / (m J_r)) follower frequencies over 2π.
    """
    Mp, Cu, _, _, kappa = _uniform_parts(chain, phi, Omega, Omega_dot)
    lam = unit_branches(Mp, Cu, kappa[[0, -1]], chain.attach)[0]
    bands = frequencies(lam.T, "pass_bands")
    a = chain.attach
    keep = [i for i in range(Mp.shape[0]) if i != a]
    if not keep:
        return bands, np.zeros((0, 2))
    held = eigh(Cu[np.ix_(keep, keep)], Mp[np.ix_(keep, keep)], eigvals_only=True)
    free = unit_branches(Mp, Cu, [0.0], a)[0][0]
    gaps = np.column_stack([frequencies(held, "stop band"), frequencies(free[1:], "stop band")])
    return bands, gaps
