"""Quasi-eigenfrequencies of a frozen chain by transfer matrices (stabilised) with the
Wittrick–Williams count, and the assembled reference.

At a frequency ω (λ = ω², rad²/s²) each unit u (frozen matrices M_u, C_u at φ + δ_u,
coordinates ``attach`` = a and internal i) is condensed exactly onto its node
(dynamic stiffness, D_u = C_u − λ M_u):

    d_u(λ) = D_aa − D_ai D_ii⁻¹ D_ia = C_aa − λ M_aa − Σ_r (α_r − λ β_r)² / (μ_r − λ),

with (μ_r, Φ_r) the internal eigenpairs (C_ii Φ = M_ii Φ diag μ, Φᵀ M_ii Φ = I) and
α = Φᵀ C_ia, β = Φᵀ M_ia. Node i then has the dynamic stiffness
``a_i(λ) = g_i + k_{i-1} + k_i − λ J_i + d_u(λ)`` and the condensed shaft is the
tridiagonal K(λ) (off-diagonals −k_i). With the torque T_i = k_i (θ_{i+1} − θ_i) in
segment i and a'_i = a_i − k_{i-1} − k_i, the Holzer–Myklestad transfer is

    [θ, T]_{i} (right of node i) = P_i [θ, T]_{i-1},  P_i = [[1, 0], [a'_i, 1]],
    [θ, T]_{i+1} (left) = F_i [θ, T]_i,               F_i = [[1, 1/k_i], [0, 1]],

and its product from a free end (θ_0 = 1, T = 0) gives at the far end the torque
T_end = det K(λ) / Π k_i, which overflows for large N. The stabilised (Riccati) form
propagates the impedance z_i = T_i / θ_i instead: z_i = a'_i + k_{i-1} z_{i-1} /
(k_{i-1} + z_{i-1}), and z_i = p_i − k_i where p_i are the pivots of the LDLᵀ of K(λ),
p_0 = a_0, p_i = a_i − k_{i-1}² / p_{i-1} (``tests/chain/test_transfer.py`` checks both
identities symbolically). The Wittrick–Williams count (Wittrick & Williams, Q. J. Mech.
Appl. Math. 24 (1971) 263) of eigenvalues strictly below λ is

    J(λ) = J0(λ) + s{K(λ)},

J0 the number of internal eigenvalues μ_r below λ (all units, also those on clamped
nodes), s{K} the number of negative pivots (Sylvester's law of inertia applied to the
block elimination of the internal coordinates of C − λM); the pivots are evaluated in the
Riccati form p_i = z_i + k_i, which combines springs only in series and so keeps the
digits of a soft spring next to a stiff one. Roots are isolated and refined by
multisection on J (vectorised over all brackets; O(N) per frequency); a bracket whose
count jump stays k > 1 at the tolerance is a k-fold root (e.g. identical followers in a
dwell, U' = 0, decoupled at μ = c/m).

Stage 6 (chain): imports solve and analysis (reference solves), numpy and scipy.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from femmech.chain.results import ChainModes
from femmech.errors import ConvergenceWarning
from femmech.solve import dense, threads, tolerances

SYMMETRY_RTOL = tolerances.SYMMETRY_RTOL
"""A unit's C counts as symmetric when ``max|C − Cᵀ| <= SYMMETRY_RTOL · max|C|``
(:data:`femmech.solve.tolerances.SYMMETRY_RTOL`)."""

REPEATED_RTOL = 1e-9
"""Roots closer than this (relative) get their vectors together (block inverse iteration
on the assembled matrices, Rayleigh–Ritz in the block): a k-fold root's eigenspace."""

SHIFT_RTOL = 1e-13
"""Relative offset of the inverse-iteration shift from the root (keeps C − σM regular;
below the root's own accuracy, so one step gains |λ − σ| / gap ≲ 1e-12 / 1e-9)."""

CLOSE_RTOL = 1e-5
"""Vectors of roots closer than this (relative, chained) are improved together by
Rayleigh–Ritz in their span (their errors lie mostly along each other)."""

RITZ_MAX = 32
"""Largest group of close roots improved together (larger groups are split at their
largest gaps)."""

ROUNDOFF_RESIDUAL = 1e-14
"""Inverse iteration stops when ‖C v − ρ M v‖ / ‖C v‖ (ρ: Rayleigh quotient or Ritz
value) is below this or below the round-off of evaluating it (:func:`_residual`): a
vector mixed with a root δ (relative) away has a residual ~δ × the mixing, so roots
1e-9 apart need ~1e-15 for vectors to ~1e-6. A vector of the condensed (tridiagonal)
path that misses it is recomputed by block inverse iteration on the assembled matrices
(near a pole μ of a unit, x = −D_ii⁻¹ D_ia θ loses the digits of μ − λ)."""


MULTISECTION = 64
"""Most count points per bracket and pass of the root search (fewer when there are more
than 4 brackets: a pass evaluates about 4 × MULTISECTION frequencies at most per bracket
group, so few brackets converge in few passes over the N nodes)."""

ZERO_RTOL = tolerances.CHAIN_ZERO_RTOL
"""Roots with |λ| below this times the chain's eigenvalue scale (:func:`_eigenvalue_scale`:
the trace ratio of C and M over the node rotations) are zero (rigid-body); the count's
round-off near λ = 0 is about 1e-16 of that scale. Roots reported as zero are checked
(:data:`ZERO_CHECK`); :data:`femmech.solve.tolerances.CHAIN_ZERO_RTOL`."""

DENSE_MAX = tolerances.DENSE_BELOW
"""``assembled_modes(solver="auto")`` uses dense LAPACK below this many coordinates (and
for all modes), sparse shift-invert above: the cut-over of
:data:`femmech.solve.tolerances.DENSE_BELOW`. Measured, 10 lowest modes of a fixed-free
phased follower chain (one BLAS thread): n = 199 dense 8.6 ms / sparse 12.7 ms, n = 399
63 / 57 ms, n = 999 324 / 17 ms, n = 1999 1.7 s / 11.5 ms (150x)."""

SOLVERS = ("auto", "dense", "sparse")
"""Solvers of :func:`assembled_modes`."""

MASS_RTOL = 1e-12
"""Directions of a Ritz basis with ``vᵀ M v`` below this times the largest are massless
(dropped: their eigenvalue is infinite)."""

ZERO_CHECK = 1e-12
"""A root reported as zero (rigid-body) must have a vector with
``‖C v‖ <= ZERO_CHECK ‖|C| |v|‖``: C annihilates it up to round-off (a rigid rotation
computed by inverse iteration gives ~1e-16; a soft but elastic mode gives λ m / k of its
nodes, 1.4e-10 for the 0.048 Hz root of a follower unit without hub inertia). Roots that
fail are flagged unconverged."""

STURM_CHECK_MAX = tolerances.STURM_CHECK_MAX
"""``transfer_modes(verify=None)`` checks the Wittrick–Williams count against the
assembled model's Sturm count (an LDLᵀ of C − σM, :func:`femmech.solve.sturm.inertia_below`)
up to this many coordinates (a few sparse factorisations, ~1 ms each at n = 400)."""

OPERATIONS = {"pivot_steps": 0}
"""Running total of pivot-recurrence steps (node × frequency) of :func:`count_below` and
the root search: a machine-independent cost measure (tests check O(N))."""


@dataclass(frozen=True)
class _Frozen:
    """The chain at one drive angle, condensed for the count (free nodes in order)."""

    J: np.ndarray        # (nf,) node inertia, kg m²
    base: np.ndarray     # (nf,) ground + adjacent springs, N m/rad
    ground: np.ndarray   # (nf,) ground springs, N m/rad
    k_left: np.ndarray   # (nf,) spring to the left / right neighbour (0 at the ends)
    k_right: np.ndarray
    couple: np.ndarray   # (nf,) spring to the previous free node (0: segment start)
    unit_row: np.ndarray  # (nuf,) free-node index of each unit on a free node
    unit_free: np.ndarray  # (nuf,) unit index of those units
    caa: np.ndarray      # (n_units,) C_aa
    maa: np.ndarray      # (n_units,) M_aa
    alpha: np.ndarray    # (n_units, m-1) Φᵀ C_ia
    beta: np.ndarray     # (n_units, m-1) Φᵀ M_ia
    mu: np.ndarray       # (n_units, m-1) internal eigenvalues, rad²/s²
    Phi: np.ndarray      # (n_units, m-1, m-1) internal modes, M_ii-normalised
    mu_sorted: np.ndarray  # all μ, ascending
    scale: float         # typical eigenvalue, rad²/s²
    M: sp.csr_matrix     # assembled (n, n)
    C: sp.csr_matrix
    abs_m: sp.csr_matrix    # |M|, |C| (round-off bounds of residuals)
    abs_c: sp.csr_matrix


def _frozen(chain, phi: float, Omega: float = 0.0) -> _Frozen:
    """Condense the chain at drive angle φ (rad) and speed Ω (rad/s)."""
    Mu, _, Cu = chain.unit_matrices(float(phi), Omega)
    _check_symmetric(Cu, Omega)
    free = ~chain.clamped
    k = np.concatenate([[0.0], chain.spring, [0.0]])
    base = (chain.ground + k[:-1] + k[1:])[free]
    prev_free = np.concatenate([[False], free[:-1]])
    couple = np.where(prev_free, k[:-1], 0.0)[free]
    free_index = np.cumsum(free) - 1
    on_free = free[chain.unit_node]
    a = chain.attach
    inner = np.array([i for i in range(chain.m) if i != a], dtype=int)
    mu, Phi, alpha, beta = internal_modes(Mu, Cu, a, inner)
    M, _, C = chain.sparse_matrices(float(phi), Omega)
    J = chain.node_inertia[free]
    maa, caa = Mu[:, a, a], Cu[:, a, a]
    scale = _eigenvalue_scale(J, base, maa, caa, free_index[chain.unit_node[on_free]],
                              np.flatnonzero(on_free), mu)
    return _Frozen(J, base, chain.ground[free], k[:-1][free], k[1:][free], couple,
                   free_index[chain.unit_node[on_free]], np.flatnonzero(on_free), caa, maa,
                   alpha, beta, mu, Phi, np.sort(mu.ravel()), scale, M, C, abs(M), abs(C))


def _eigenvalue_scale(J, base, maa, caa, unit_row, unit_free, mu) -> float:
    """Typical eigenvalue of the frozen chain, rad²/s²: the ratio of the traces of the
    assembled C and M over the node rotations, ``Σ_i (g_i + k_{i-1} + k_i + |C_aa|) /
    Σ_i (J_i + M_aa)`` (N m/rad over kg m², the same units on every node, so the units'
    internal coordinates do not enter).

    A ratio of sums, not the largest ratio of any node or unit: a unit whose M_aa is tiny
    but not zero (no hub inertia, U' ≈ 0) has C_aa / M_aa of any size (3.5e21 for
    U' = 6e-13) and would set the rigid-body threshold :data:`ZERO_RTOL` × scale above
    real roots. A rigid-body root perturbed by round-off δ in the springs moves by
    Σ δ_i / Σ m_i, so this ratio is also the right measure of where zero ends. Without
    any node mass, the largest internal eigenvalue (or 1) is taken."""
    stiff, mass = np.abs(base), J.astype(float).copy()
    stiff[unit_row] += np.abs(caa[unit_free])
    mass[unit_row] += np.maximum(maa[unit_free], 0.0)
    if mass.sum() > 0 and stiff.sum() > 0:
        return float(stiff.sum() / mass.sum())
    return float(max(np.abs(mu).max(initial=0.0), 1.0))


def _check_symmetric(Cu, Omega) -> None:
    asym = np.abs(Cu - np.swapaxes(Cu, -1, -2)).max(axis=(-1, -2))
    size = np.abs(Cu).max(axis=(-1, -2))
    bad = np.flatnonzero(asym > SYMMETRY_RTOL * np.maximum(size, 1e-300))
    if bad.size:
        u = int(bad[0])
        raise ValueError(f"the frozen stiffness C(φ + δ_u, Ω = {Omega}) of unit {u} is"
                         f" unsymmetric (max|C − Cᵀ| = {asym[u]:.3g}): the transfer method"
                         " needs a symmetric C; use Ω = 0 or assembled_modes")


def internal_modes(Mu, Cu, a, inner):
    """Internal eigenpairs of every unit with its attach coordinate fixed: μ (n_units,
    m-1), Φ (n_units, m-1, m-1) M_ii-normalised, and the modal couplings α = Φᵀ C_ia,
    β = Φᵀ M_ia."""
    n_units = Mu.shape[0]
    if inner.size == 0:
        empty = np.zeros((n_units, 0))
        return empty, np.zeros((n_units, 0, 0)), empty, empty
    Mii = Mu[:, inner[:, None], inner]
    Cii = Cu[:, inner[:, None], inner]
    try:
        L = np.linalg.cholesky(Mii)
    except np.linalg.LinAlgError:
        raise ValueError("a unit's internal mass matrix M_ii is not positive definite"
                         " (massless internal coordinate): the transfer method needs"
                         " mass on every internal coordinate") from None
    Linv = np.linalg.inv(L)
    A = Linv @ Cii @ np.swapaxes(Linv, -1, -2)
    mu, W = np.linalg.eigh(0.5 * (A + np.swapaxes(A, -1, -2)))
    Phi = np.swapaxes(Linv, -1, -2) @ W  # (n_units, m-1, m-1), columns M_ii-normalised
    alpha = np.einsum("urs,ur->us", Phi, Cu[:, inner, a])
    beta = np.einsum("urs,ur->us", Phi, Mu[:, inner, a])
    return mu, Phi, alpha, beta


def _unit_stiffness(fz: _Frozen, lam: np.ndarray) -> np.ndarray:
    """d_u(λ) of the units on free nodes: (nuf, L) for λ (L,)."""
    u = fz.unit_free
    d = fz.caa[u, None] - lam * fz.maa[u, None]
    if fz.mu.shape[1]:
        g = fz.alpha[u, :, None] - lam * fz.beta[u, :, None]
        gap = fz.mu[u, :, None] - lam
        with np.errstate(divide="ignore", invalid="ignore"):
            term = np.where(g == 0, 0.0, g * g / gap)
        d = d - term.sum(axis=1)
    return d


def _pivots_negative(fz: _Frozen, lam: np.ndarray) -> np.ndarray:
    """s{K(λ)}: number of negative LDLᵀ pivots of the condensed shaft, for λ (L,).

    Computed in the Riccati (impedance) form z_i = a'_i + k_{i-1} z_{i-1} / p_{i-1},
    p_i = z_i + k_i (a'_i: the node's own dynamic stiffness, without the shaft springs):
    the springs enter only in series combinations, so a soft spring next to a stiff one
    keeps its digits (the pivot form a_i − k²/p subtracts two numbers of the stiff size).
    """
    own = fz.ground[:, None] - fz.J[:, None] * lam
    if fz.unit_row.size:
        own[fz.unit_row] += _unit_stiffness(fz, lam)
    pivmin = np.finfo(float).tiny / np.finfo(float).eps
    neg = np.zeros(lam.shape, dtype=int)
    z = p = np.ones(lam.shape)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for i in range(own.shape[0]):
            kl = fz.k_left[i]
            if fz.couple[i]:
                z = own[i] + kl * (z / p)
            else:  # first node of a piece: the left spring (if any) goes to ground
                z = own[i] + kl
            p = z + fz.k_right[i]
            p[p == 0] = pivmin
            neg += p < 0
    OPERATIONS["pivot_steps"] += own.size
    return neg


def _count(fz: _Frozen, lam: np.ndarray) -> np.ndarray:
    """Wittrick–Williams J(λ) (λ (L,) rad²/s²): eigenvalues strictly below λ."""
    lam = np.asarray(lam, dtype=float)
    j0 = np.searchsorted(fz.mu_sorted, lam, side="left")
    return j0 + _pivots_negative(fz, lam)


def count_below(chain, phi: float, freq_hz, Omega: float = 0.0) -> np.ndarray:
    """Number of quasi-eigenfrequencies of the frozen chain below ``freq_hz``.

    Wittrick–Williams count J(λ) = J0(λ) + s{K(λ)} at λ = (2π f)², exact (it equals the
    number of eigenvalues of C(φ, Ω) v = λ M(φ) v below λ), O(N) per frequency.

    Parameters
    ----------
    chain : Chain
    phi : float
        Drive angle, rad.
    freq_hz : array_like, any shape
        Frequencies, Hz (negative values count eigenvalues below −(2π f)²).
    Omega : float
        Drive speed, rad/s, in C(φ, Ω) (must leave C symmetric).

    Returns
    -------
    ndarray of int, the shape of ``freq_hz``
    """
    f = np.asarray(freq_hz, dtype=float)
    lam = np.sign(f) * (2 * np.pi * f) ** 2
    return _count(_frozen(chain, phi, Omega), lam.reshape(-1)).reshape(f.shape)


@dataclass
class _Roots:
    lam: list
    count: list
    conv: list
    j0_jump: list
    mult: list


def _bisect(fz, lo, hi, nlo, nhi, wanted, rtol, zero, max_iter=400) -> _Roots:
    """All roots in brackets (lo, hi] (arrays) with counts nlo, nhi, up to the
    ``wanted``-th (by count), by vectorised multisection on J (q points per bracket, q
    larger while the brackets are few: one pass over the nodes serves all), to a
    relative width rtol;
    brackets inside [−zero, zero] (rigid-body roots; the count there is round-off) stop."""
    out = _Roots([], [], [], [], [])

    def emit(lo, hi, nlo, nhi, converged):
        mid = 0.5 * (lo + hi)
        jump = (np.searchsorted(fz.mu_sorted, hi, side="left")
                - np.searchsorted(fz.mu_sorted, lo, side="left"))
        for x, c, j, k in zip(mid, nlo, jump, np.minimum(nhi, wanted) - nlo, strict=True):
            out.lam += [x] * k
            out.count += [c] * k
            out.conv += [converged] * k
            out.j0_jump += [j] * k
            out.mult += [k] * k

    for _ in range(max_iter):
        done = ((hi - lo) <= rtol * np.maximum(np.abs(lo), np.abs(hi))) | (
            (lo >= -zero) & (hi <= zero))
        emit(lo[done], hi[done], nlo[done], nhi[done], True)
        lo, hi, nlo, nhi = lo[~done], hi[~done], nlo[~done], nhi[~done]
        if lo.size == 0:
            break
        q = max(1, min(MULTISECTION, MULTISECTION * 4 // lo.size))  # points per bracket
        t = np.arange(q + 2) / (q + 1)
        edges = lo[:, None] + (hi - lo)[:, None] * t
        edges[:, -1] = hi
        inner = _count(fz, edges[:, 1:-1].ravel()).reshape(lo.size, q)
        counts = np.concatenate([nlo[:, None], inner, nhi[:, None]], axis=1)
        counts = np.clip(np.maximum.accumulate(counts, axis=1), nlo[:, None], nhi[:, None])
        b, j = np.nonzero((counts[:, 1:] > counts[:, :-1]) & (counts[:, :-1] < wanted))
        lo, hi, nlo, nhi = edges[b, j], edges[b, j + 1], counts[b, j], counts[b, j + 1]
    emit(lo, hi, nlo, nhi, False)
    return out


def _search_range(fz, n_modes, f_max, n_total):
    """(lo, hi, J(lo), J(hi), wanted): a bracket holding every wanted root."""
    lo = -1e-9 * fz.scale
    for _ in range(200):
        if _count(fz, np.array([lo]))[0] == 0:
            break
        lo *= 4.0
    else:
        raise ValueError("no lower bound of the eigenvalues found (C − λM indefinite for"
                         " every λ tried)")
    if f_max is not None:
        hi = (2 * np.pi * float(f_max)) ** 2
        if hi <= lo:
            return lo, lo, 0, 0, 0
        nhi = int(_count(fz, np.array([hi]))[0])
        wanted = nhi if n_modes is None else min(nhi, int(n_modes))
        return lo, hi, 0, nhi, wanted
    hi = 1e-8 * fz.scale
    for _ in range(200):
        nhi = int(_count(fz, np.array([hi]))[0])
        if nhi >= n_modes:
            return lo, hi, 0, nhi, int(n_modes)
        hi *= 4.0
    raise ValueError(f"n_modes = {n_modes}: the chain has only {nhi} finite"
                     f" eigenvalues (of {n_total} coordinates; massless coordinates have"
                     " infinite ones)")


def transfer_modes(chain, phi: float, n_modes: int | None = None, f_max: float | None = None,
                   rtol: float = 1e-12, vectors: bool = True, Omega: float = 0.0,
                   verify: bool | None = None) -> ChainModes:
    """Quasi-eigenfrequencies (and modes) of the frozen chain by stabilised transfer
    matrices with the Wittrick–Williams count: no root is missed.

    Parameters
    ----------
    chain : Chain
    phi : float
        Drive angle, rad.
    n_modes : int, optional
        The n lowest roots (repeated roots counted by multiplicity).
    f_max : float, optional
        All roots below f_max, Hz (with n_modes too: at most n_modes of them).
    rtol : float
        Relative width of the final bracket of each root in λ = ω². Roots with
        ``|λ| <= ZERO_RTOL`` times the chain's eigenvalue scale (rigid-body roots,
        where the count is round-off) stop there and are reported as 0 (checked).
    vectors : bool
        Compute the modes (assembled coordinates, M-normalised, M-orthogonal within
        repeated roots).
    Omega : float
        Drive speed, rad/s, in C(φ, Ω) (C must stay symmetric; default 0).
    verify : bool, optional
        Check the Wittrick–Williams count against the Sturm count of the assembled model
        (LDLᵀ of C − σM) below the lowest root, just above the highest and around zero;
        default: for chains of up to :data:`STURM_CHECK_MAX` coordinates. Roots reported
        as zero are always checked (C v ≈ 0, :data:`ZERO_CHECK`).

    Returns
    -------
    ChainModes
        ``method="transfer"``; ``count`` = J just below each root's bracket (shared by
        the copies of a repeated root); ``converged`` False where the bisection stopped
        before ``rtol`` or a check failed (then a ConvergenceWarning says which). Roots
        λ < 0 (divergence) have negative ``freq_hz`` = −√|λ| / 2π.
    """
    if n_modes is None and f_max is None:
        raise ValueError("give n_modes (the lowest roots) or f_max (all roots below it, Hz)")
    if n_modes is not None and (int(n_modes) != n_modes or n_modes < 1):
        raise ValueError(f"n_modes must be a positive integer, got {n_modes!r}")
    fz = _frozen(chain, phi, Omega)
    lo, hi, nlo, nhi, wanted = _search_range(fz, n_modes, f_max, chain.n)
    zero = ZERO_RTOL * fz.scale
    roots = _bisect(fz, np.array([lo]), np.array([hi]), np.array([nlo]), np.array([nhi]),
                    wanted, rtol, zero)
    lam = np.array(roots.lam, dtype=float)
    order = np.argsort(lam, kind="stable")
    lam = np.where(np.abs(lam[order]) <= zero, 0.0, lam[order])
    V = None
    if vectors:
        with threads.solve_phase():  # many small dense products: one BLAS thread
            V = _vectors(chain, fz, lam, np.array(roots.j0_jump)[order])
    conv = np.array(roots.conv, dtype=bool)[order]
    verify = chain.n <= STURM_CHECK_MAX if verify is None else bool(verify)
    conv = _verified(fz, lam, conv, V, lo, zero, verify, phi)
    freq = np.sign(lam) * np.sqrt(np.abs(lam)) / (2 * np.pi)
    return ChainModes(freq, V, "transfer", None, np.array(roots.count, dtype=int)[order],
                      conv)


def _verified(fz: _Frozen, lam, conv, V, lo, zero, sturm, phi) -> np.ndarray:
    """``conv`` with the roots that fail a check set False (ConvergenceWarning): roots
    reported as zero need a vector that C annihilates (:data:`ZERO_CHECK`); with
    ``sturm`` the count J(σ) must equal the assembled Sturm count at σ = ``lo`` (below
    every root), just above the highest root and at ±``zero``."""
    conv = conv.copy()
    problems = []
    at_zero = np.flatnonzero(lam == 0.0)
    if at_zero.size:
        V0 = (V[:, at_zero] if V is not None else _Banded(
            fz.M, fz.C, fz.abs_m, fz.abs_c).block_inverse_iteration(lam[at_zero], fz.scale))
        ratio = (np.linalg.norm(fz.C @ V0, axis=0)
                 / np.maximum(np.linalg.norm(fz.abs_c @ np.abs(V0), axis=0), 1e-300))
        if ratio.max() > ZERO_CHECK:
            conv[at_zero] = False
            problems.append(f"{at_zero.size} root(s) reported as 0 are not rigid-body"
                            f" (‖C v‖ / ‖|C| |v|‖ = {ratio.max():.2g} > {ZERO_CHECK:g})")
    if sturm and lam.size:
        top = float(lam[-1]) + max(1e-6 * abs(float(lam[-1])), 2.0 * zero)
        cuts = np.unique([lo, top] + ([-zero, zero] if at_zero.size else []))
        bad = _count_mismatch(fz, cuts)
        if bad:  # a root within round-off of a cut: both counts are right; move the cut
            bad = [b for b in bad if all(_count_mismatch(fz, np.array([b[0] + shift])) for
                                         shift in (-3e-7 * abs(b[0]) - zero,
                                                   3e-7 * abs(b[0]) + zero))]
        if bad:
            conv[:] = False
            c, a, b = bad[0]
            problems.append(f"the count below λ = {c:.6g} rad²/s² is {a}, the assembled"
                            f" model's Sturm count {b}")
    if problems:
        warnings.warn(f"transfer_modes at φ = {float(phi):.6g} rad: roots not verified: "
                      + "; ".join(problems) + " (flagged converged=False)",
                      ConvergenceWarning, stacklevel=3)
    return conv


def _count_mismatch(fz: _Frozen, cuts) -> list:
    """(cut, J(cut), assembled Sturm count) where the two differ (no Sturm count: no
    mismatch)."""
    mine = _count(fz, cuts)
    theirs = _sturm_counts(fz.M, fz.C, cuts)
    return [(c, a, b) for c, a, b in zip(cuts, mine, theirs, strict=True)
            if b is not None and a != b]


def _sturm_counts(M, C, cuts) -> list:
    """Eigenvalues of the assembled C v = λ M v below each cut (Sylvester's law of inertia
    of C − σM: sparse LDLᵀ, or dense eigenvalues of C − σM up to 400 coordinates where
    the sparse factorisation pivoted off the diagonal); None where neither applies."""
    from femmech.solve.sturm import inertia_below

    Cc, Mc = C.tocsc(), M.tocsc()
    out = []
    for cut in cuts:
        count = inertia_below(Cc, Mc, float(cut))
        if count is None and C.shape[0] <= 400:
            A = (C - float(cut) * M).toarray()
            count = int(np.count_nonzero(np.linalg.eigvalsh(0.5 * (A + A.T)) < 0))
        out.append(count)
    return out


def _vectors(chain, fz: _Frozen, lam: np.ndarray, j0_jump: np.ndarray) -> np.ndarray:
    """Modes at the roots: isolated roots of K(λ) by tridiagonal inverse iteration and
    recovery of the internal coordinates; repeated roots, internal (J0) roots and vectors
    whose residual fails by block inverse iteration on the assembled matrices."""
    V = np.zeros((chain.n, lam.size))
    banded = _Banded(fz.M, fz.C, fz.abs_m, fz.abs_c)
    for g in _groups(lam, REPEATED_RTOL, fz.scale):
        if g.size == 1 and j0_jump[g[0]] == 0 and fz.J.size:
            v = _condensed_vector(chain, fz, lam[g[0]])
            if v is not None and _residual(fz, v, lam[g[0]]) <= 1.0:
                V[:, g] = v[:, None]
                continue
        V[:, g] = banded.block_inverse_iteration(lam[g], fz.scale)
    for group in _groups(lam, CLOSE_RTOL, fz.scale):
        for g in _split_at_gaps(group, lam, RITZ_MAX):
            if g.size > 1:  # Rayleigh–Ritz among close roots: M-orthogonal, errors O(res²)
                V[:, g] = _rayleigh_ritz(V[:, g], fz.M, fz.C)
    return V


def _split_at_gaps(g, lam, size: int) -> list:
    """Split the index group g (ascending roots) at its largest relative gaps into
    pieces of at most ``size`` (keeps the Rayleigh–Ritz cost O(n size²) per piece)."""
    if g.size <= size:
        return [g]
    gaps = np.diff(lam[g]) / np.maximum(np.abs(lam[g][1:]), 1e-300)
    cut = int(np.argmax(gaps)) + 1
    return _split_at_gaps(g[:cut], lam, size) + _split_at_gaps(g[cut:], lam, size)


def _rayleigh_ritz(X, M, C) -> np.ndarray:
    """Ritz vectors (M-normalised, ascending) of C v = λ M v in span(X)."""
    return _normalise(_ritz(np.linalg.qr(X)[0], M, C)[1], M)


def _ritz(X, M, C):
    """Ritz pairs ``(θ (b',), Y (n, b'))`` of C v = λ M v in span(X) (X (n, b)
    orthonormal), M-orthonormal, ascending. Directions of span(X) without mass (massless
    coordinates: infinite eigenvalues; M may be singular) are condensed statically
    within the span (their infinite Ritz values dropped), so b' <= b."""
    Mp, Cp = X.T @ (M @ X), X.T @ (C @ X)
    Mp, Cp = 0.5 * (Mp + Mp.T), 0.5 * (Cp + Cp.T)
    w, Q = np.linalg.eigh(Mp)
    keep = w > MASS_RTOL * max(float(w.max(initial=0.0)), 1e-300)
    if keep.all():  # the usual case: Cholesky of Mp, as accurate as it gets
        theta, Y = dense.symmetric_pencil(Cp, Mp, driver="plain")
        return theta, X @ Y
    B, N = Q[:, keep] / np.sqrt(w[keep]), Q[:, ~keep]
    Cnn, Cnb = N.T @ Cp @ N, N.T @ Cp @ B
    B = B - N @ np.linalg.lstsq(Cnn, Cnb, rcond=None)[0]  # massless part follows statically
    theta, Y = dense.symmetric_pencil(B.T @ Cp @ B, B.T @ Mp @ B, driver="plain")
    return theta, X @ (B @ Y)


def _groups(lam, rtol, scale):
    """Index groups of roots closer than rtol (relative, floor 1e-9 scale)."""
    if lam.size == 0:
        return []
    size = np.maximum(np.abs(lam[1:]), 1e-9 * scale)
    cuts = np.flatnonzero(np.diff(lam) > rtol * size) + 1
    return np.split(np.arange(lam.size), cuts)


def _residual(fz, v, lam=None) -> float:
    """Residual of v at its Rayleigh quotient ρ (λ is not used: ρ is far more accurate
    for a converged v, and a residual at the root λ could not show a mixture of roots
    closer than |λ − λ_true| / ‖...‖) relative to what round-off allows:
    ``‖C v − ρ M v‖ / (ROUNDOFF_RESIDUAL · max(‖C v‖, |ρ| ‖M v‖) + 8 ε ‖|C| |v| +
    |ρ| |M| |v|‖)`` (the second term: the error of evaluating C v − ρ M v itself, which
    dominates for the low modes of long chains); <= 1 means converged."""
    rho = float(v @ (fz.C @ v)) / float(v @ (fz.M @ v))
    return float(_residual_ratio(fz.M, fz.C, v[:, None], np.array([rho]), fz.abs_m,
                                 fz.abs_c)[0])


def _residual_ratio(M, C, V, lam, abs_m=None, abs_c=None) -> np.ndarray:
    """:func:`_residual` for the columns of V (n, k) and λ (k,); abs_m, abs_c: |M|, |C|."""
    CV, MV = C @ V, (M @ V) * lam
    aV = np.abs(V)
    abs_m, abs_c = (abs(M) if abs_m is None else abs_m), (abs(C) if abs_c is None else abs_c)
    floor = abs_c @ aV + (abs_m @ aV) * np.abs(lam)
    den = (ROUNDOFF_RESIDUAL * np.maximum(np.linalg.norm(CV, axis=0), np.linalg.norm(MV, axis=0))
           + 8 * np.finfo(float).eps * np.linalg.norm(floor, axis=0))
    return np.linalg.norm(CV - MV, axis=0) / np.maximum(den, 1e-300)


def _shift(lam, scale):
    return lam + SHIFT_RTOL * max(abs(lam), 1e-6 * scale)


def _condensed_vector(chain, fz: _Frozen, lam: float, max_steps: int = 6):
    """Mode of an isolated root of K(λ): node rotations by inverse iteration with the
    tridiagonal K(σ), σ next to λ (O(N) per step, until the residual is at round-off),
    internal coordinates x = −D_ii⁻¹ D_ia θ; M-normalised. None if the solve fails."""
    sigma = _shift(lam, fz.scale)
    diag = fz.base - fz.J * sigma
    if fz.unit_row.size:
        diag[fz.unit_row] += _unit_stiffness(fz, np.array([sigma]))[:, 0]
    nf = diag.size
    ab = np.zeros((3, nf))
    ab[0, 1:] = -fz.couple[1:]
    ab[1] = diag
    ab[2, :-1] = -fz.couple[1:]
    theta = np.ones(nf) + 0.01 * np.cos(np.arange(nf))
    free_nodes = chain.node_dof[~chain.clamped]
    v = None
    for _ in range(max_steps):
        try:
            theta = sla.solve_banded((1, 1), ab, theta, check_finite=False)
        except (np.linalg.LinAlgError, ValueError):
            return v
        theta /= np.abs(theta).max()
        if not np.all(np.isfinite(theta)):
            return v
        v = np.zeros(chain.n)
        v[free_nodes] = theta
        if fz.mu.shape[1] and fz.unit_row.size:
            v = _internal_from_rotation(chain, fz, lam, theta, v)
        v = _normalise(v[:, None], fz.M)[:, 0]
        if _residual(fz, v, lam) <= 1.0:
            break
    return v


def _internal_from_rotation(chain, fz, lam, theta, v):
    """x_u = −D_ii⁻¹ D_ia θ_u = −Φ (μ − λ)⁻¹ (α − λ β) θ_u for the units on free nodes."""
    u = fz.unit_free
    g = (fz.alpha[u] - lam * fz.beta[u]) * theta[fz.unit_row, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        q = np.where(g == 0, 0.0, g / (fz.mu[u] - lam))
    x = -np.einsum("urs,us->ur", fz.Phi[u], q)
    inner = [i for i in range(chain.m) if i != chain.attach]
    v[chain.unit_dofs[u][:, inner]] = x
    return v


def _normalise(V, M):
    norms = np.sqrt(np.abs(np.einsum("ij,ij->j", V, M @ V)))
    V = V / np.where(norms > 0, norms, 1.0)
    big = np.argmax(np.abs(V), axis=0)
    sign = np.sign(V[big, np.arange(V.shape[1])])
    return V * np.where(sign == 0, 1.0, sign)


class _Banded:
    """C − σM of the assembled chain in LAPACK band storage (coordinates node by node,
    so the bandwidth is about the unit size) for block inverse iteration."""

    def __init__(self, M, C, abs_m, abs_c):
        self.M, self.C, self.abs_m, self.abs_c = M, C, abs_m, abs_c
        A = (abs_m + abs_c).tocoo()
        self.width = int(np.abs(A.row - A.col).max(initial=0))
        self.n = M.shape[0]
        self.bM, self.bC = self._band(M), self._band(C)

    def _band(self, A):
        A = A.tocoo()
        w = self.width
        out = np.zeros((2 * w + 1, self.n))
        np.add.at(out, (w + A.row - A.col, A.col), A.data)
        return out

    def block_inverse_iteration(self, lam, scale, max_steps: int = 30) -> np.ndarray:
        """M-orthonormal basis (n, k) of the eigenspace of the k (close or repeated)
        roots ``lam``: block inverse iteration at σ next to them with max(2, k) guard
        vectors and Rayleigh–Ritz, until the residuals of the k Ritz vectors nearest σ
        are at round-off (at most ``max_steps``; one banded LU of C − σM)."""
        k = lam.size
        b = min(2 * k + 2, self.n)
        sigma = _shift(float(lam.mean()), scale)
        solve = self._factor(sigma, scale)
        X = np.random.default_rng(12345).standard_normal((self.n, b))
        for _ in range(max_steps):
            X = np.linalg.qr(solve(self.M @ X))[0]  # steps amplify the cluster ~1e12
            theta, X = _ritz(X, self.M, self.C)
            pick = np.sort(np.argsort(np.abs(theta - sigma), kind="stable")[:k])
            if np.all(_residual_ratio(self.M, self.C, X[:, pick], theta[pick], self.abs_m,
                                      self.abs_c) <= 1.0):
                break
        return _normalise(X[:, pick], self.M)

    def _factor(self, sigma, scale):
        """``solve(B)`` with the banded LU (LAPACK gbtrf) of C − σM; σ is moved off an
        exactly singular matrix."""
        w = self.width
        for attempt in range(4):
            ab = np.zeros((3 * w + 1, self.n))
            ab[w:] = self.bC - sigma * self.bM
            lu, piv, info = sla.lapack.dgbtrf(ab, w, w)
            if info == 0:
                break
            sigma = _shift(sigma, scale * 10.0 ** (3 * attempt + 3))

        def solve(B):
            X, info = sla.lapack.dgbtrs(lu, w, w, B, piv)
            return X

        return solve


def assembled_modes(chain, phi: float, n_modes: int | None = None,
                    f_max: float | None = None, Omega: float = 0.0,
                    solver: str = "auto") -> ChainModes:
    """Reference: quasi-modes of the assembled chain ``C(φ, Ω) v = λ M(φ) v``.

    ``solver="dense"``: LAPACK ``scipy.linalg.eigh`` of the dense matrices (every mode;
    M must be positive definite); ``"sparse"``: shift-invert Lanczos with a Sturm check
    (:func:`femmech.solve.eigen.solve_symmetric`; n_modes or f_max needed; massless
    coordinates allowed); ``"auto"`` (default): dense below :data:`DENSE_MAX`
    coordinates or when every mode is asked for, else sparse. An unsymmetric C (Ω ≠ 0
    with U''' terms) is solved densely by QZ (:func:`femmech.analysis.sweep.frozen_modes`):
    frequencies ``Re √λ / 2π``.

    Parameters
    ----------
    chain : Chain
    phi : float
        Drive angle, rad.
    n_modes : int, optional
        The n lowest modes; with neither n_modes nor f_max, all of them (dense only).
    f_max : float, optional
        All modes below f_max, Hz.
    Omega : float
        Drive speed, rad/s.
    solver : {"auto", "dense", "sparse"}
        See above (:data:`SOLVERS`).

    Returns
    -------
    ChainModes
        ``method="assembled"``, vectors (n, k) M-normalised; λ < 0 gives negative
        ``freq_hz`` = −√|λ| / 2π.
    """
    if solver not in SOLVERS:
        raise ValueError(f"solver must be one of {', '.join(SOLVERS)}, got {solver!r}")
    if n_modes is not None and (int(n_modes) != n_modes or n_modes < 1):
        raise ValueError(f"n_modes must be a positive integer, got {n_modes!r}")
    M, _, C = chain.sparse_matrices(float(phi), Omega)
    n = chain.n
    lam_max = None if f_max is None else (2 * np.pi * float(f_max)) ** 2
    asym = abs(C - C.T).max() if n else 0.0
    if asym > SYMMETRY_RTOL * max(abs(C).max(), 1e-300):
        return _assembled_unsymmetric(M, C, n_modes, lam_max)
    if solver == "auto":
        every = n_modes is None and f_max is None
        solver = "dense" if n < DENSE_MAX or every else "sparse"
    with threads.solve_phase():
        if solver == "dense":
            lam, V = _dense_pairs(M.toarray(), C.toarray(), n_modes, lam_max)
        else:
            lam, V = _sparse_pairs(M, C, n_modes, lam_max)
    freq = np.sign(lam) * np.sqrt(np.abs(lam)) / (2 * np.pi)
    return ChainModes(freq, _normalise(V, M), "assembled")


def _dense_pairs(M, C, n_modes, lam_max):
    if n_modes is not None:
        k = min(int(n_modes), M.shape[0])
        lam, V = dense.symmetric_pencil(C, M, k, driver="plain")
    else:
        lam, V = dense.symmetric_pencil(C, M, driver="plain")
    if lam_max is not None:
        keep = lam < lam_max
        lam, V = lam[keep], V[:, keep]
    return lam, V


def _sparse_pairs(M, C, n_modes, lam_max):
    from femmech.solve.eigen import solve_symmetric

    if lam_max is not None:
        res = solve_symmetric(C.tocsc(), M.tocsc(), band=(0.0, lam_max), dense_below=0)
        lam, V = res.omega2, res.vectors
        keep = lam < lam_max
        lam, V = lam[keep], V[:, keep]
        if n_modes is not None:
            lam, V = lam[:n_modes], V[:, :n_modes]
        return lam, V
    if n_modes is None:
        raise ValueError("the sparse solver needs n_modes or f_max (every mode of the"
                         " chain: solver='dense')")
    res = solve_symmetric(C.tocsc(), M.tocsc(), n_modes=int(n_modes), dense_below=0)
    return res.omega2[:n_modes], res.vectors[:, :n_modes]


def _assembled_unsymmetric(M, C, n_modes, lam_max) -> ChainModes:
    from femmech.analysis.sweep import frozen_modes

    k = M.shape[0] if n_modes is None else min(int(n_modes), M.shape[0])
    lam, freq, _, V, _ = frozen_modes(M.toarray(), None, C.toarray(), k)
    keep = np.ones(freq.size, bool) if lam_max is None else lam.real < lam_max
    V = V[:, keep]
    if np.abs(V.imag).max(initial=0.0) <= 1e-12 * np.abs(V).max(initial=1.0):
        V = V.real
    return ChainModes(freq[keep], V, "assembled")
