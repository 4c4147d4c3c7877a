"""Transfer matrices with the Wittrick–Williams count against the assembled chain."""

import numpy as np
import pytest
import scipy.linalg as sla
import sympy as smp

from femmech.chain import Chain, End, chain, follower_unit
from femmech.chain import transfer as tr
from femmech.chain.results import ChainModes
from femmech.chain.transfer import assembled_modes, count_below, transfer_modes
from femmech.mechanisms import CamProfile, CamSegment, modified_sine

STROKE = 0.03
J_HUB, MASS, STIFF = 2e-3, 0.5, 2e5  # kg m², kg, N/m: follower frequency √(c/m)/2π = 100.66 Hz
SPACING, DIAMETER = 0.25, 0.04  # m; steel shaft: k = 8.1e4 N m/rad per spacing


def cam() -> CamProfile:
    """Modified-sine rise 0–120°, dwell to 180°, return to 300°, dwell to 360°; 30 mm."""
    return CamProfile((CamSegment(np.radians(120), STROKE, modified_sine()),
                       CamSegment(np.radians(60)),
                       CamSegment(np.radians(120), -STROKE, modified_sine()),
                       CamSegment(np.radians(60))))


UNIT = follower_unit(cam(), J_HUB, MASS, STIFF)


def phased(n, left=None, right=None, end_length=None, spread=1.7):
    """n units with phases spread over 1.7 turns: some in rise, return and both dwells;
    ends free unless given."""
    phases = spread * 2 * np.pi * np.arange(n) / n
    return chain(UNIT, n, SPACING, DIAMETER, phases=phases, left=left or End(),
                 right=right or End(), end_length=end_length)


def dense_eigenvalues(ch, phi):
    M, _, C = ch.sparse_matrices(phi)
    return sla.eigh(C.toarray(), M.toarray(), eigvals_only=True)


# --- the formulas (symbolic) ---------------------------------------------------------------

@pytest.mark.parametrize("n", [3, 4])
def test_transfer_product_is_determinant_and_riccati_is_ldl(n):
    # Holzer/Myklestad: [θ, T] across node i: P_i = [[1, 0], [a'_i, 1]] (a'_i = a_i − k_{i-1}
    # − k_i, the node's own dynamic stiffness), across segment i: F_i = [[1, 1/k_i], [0, 1]]
    # with T_i = k_i (θ_{i+1} − θ_i). From a free end (θ, T) = (1, 0), the end torque is
    # det K / Π k_i; the impedance z_i = T_i/θ_i obeys the Riccati recursion and equals
    # p_i − k_i, p_i the LDLᵀ pivots of K(λ).
    a = smp.symbols(f"a0:{n}")
    k = smp.symbols(f"k0:{n - 1}", positive=True)
    K = smp.zeros(n, n)
    for i in range(n):
        K[i, i] = a[i]
    for i in range(n - 1):
        K[i, i + 1] = K[i + 1, i] = -k[i]
    kk = (0,) + k + (0,)
    own = [a[i] - kk[i] - kk[i + 1] for i in range(n)]
    state = smp.Matrix([1, 0])
    for i in range(n):
        state = smp.Matrix([[1, 0], [own[i], 1]]) * state
        if i < n - 1:
            state = smp.Matrix([[1, 1 / k[i]], [0, 1]]) * state
    assert smp.simplify(state[1] - K.det() / smp.prod(k)) == 0
    pivots = [a[0]]
    for i in range(1, n):
        pivots.append(a[i] - k[i - 1] ** 2 / pivots[-1])
    assert smp.simplify(smp.prod(pivots) - K.det()) == 0
    z = own[0]
    for i in range(1, n):
        assert smp.simplify(z - (pivots[i - 1] - kk[i])) == 0
        z = own[i] + k[i - 1] * z / (k[i - 1] + z)
    assert smp.simplify(z - pivots[-1]) == 0  # no spring beyond the last node


def test_condensed_unit_stiffness_formula():
    # d(λ) = D_aa − D_ai D_ii⁻¹ D_ia (exact condensation) equals the modal form
    # C_aa − λ M_aa − Σ_r (α_r − λ β_r)² / (μ_r − λ) with M_ii-normalised internal modes;
    # here for the follower unit M = [[J + m U'², m U'], [m U', m]], C = diag(C11, c).
    lam, J, m, c, u1, c11 = smp.symbols("lambda J m c u1 C11")
    M = smp.Matrix([[J + m * u1**2, m * u1], [m * u1, m]])
    C = smp.Matrix([[c11, 0], [0, c]])
    D = C - lam * M
    exact = D[0, 0] - D[0, 1] ** 2 / D[1, 1]
    phi_r = 1 / smp.sqrt(m)  # internal mode, M_ii-normalised; μ = c/m
    alpha, beta = phi_r * C[1, 0], phi_r * M[1, 0]
    modal = C[0, 0] - lam * M[0, 0] - (alpha - lam * beta) ** 2 / (c / m - lam)
    assert smp.simplify(exact - modal) == 0


def test_condensed_stiffness_numbers_match_formula():
    ch = phased(3)
    fz = tr._frozen(ch, 0.4)
    lam = np.array([1e4, 3.9e5, 4.1e5])
    Mu, _, Cu = ch.unit_matrices(0.4)
    D = Cu[:, None] - lam[:, None, None] * Mu[:, None]  # (units, L, 2, 2)
    exact = D[..., 0, 0] - D[..., 0, 1] ** 2 / D[..., 1, 1]
    # modal sum against direct elimination: same numbers to round-off (~1e-12 here,
    # the terms are ~1e3 times the result near μ)
    # bound: modal sum vs direct elimination, terms ~1e3 × the result near μ: ~1e-13
    assert np.allclose(tr._unit_stiffness(fz, lam), exact, rtol=1e-10, atol=0)


# --- agreement with the assembled model ----------------------------------------------------

CASES = {
    "N2-free": lambda: phased(2),
    "N5-fixed": lambda: phased(5, left=End.fixed()),
    "N20-elastic-flywheel-stubs": lambda: phased(20, left=End.elastic(1e4, 0.05),
                                                 right=End.flywheel(0.3), end_length=0.1),
    "N200-fixed-fixed": lambda: phased(200, left=End.fixed(), right=End.fixed()),
    "N20-nonuniform": lambda: _nonuniform(20),
}


def _nonuniform(n, ratio=10.0, seed=3):
    """Random node inertias and springs (spread `ratio`), units on every other node,
    a clamped middle node (splits the shaft) and a ground spring."""
    rng = np.random.default_rng(seed)
    nodes = 2 * n
    J = 5e-3 * ratio ** rng.uniform(0, 1, nodes)
    k = 8e4 * ratio ** rng.uniform(-1, 1, nodes - 1)
    ground = np.zeros(nodes)
    ground[-1] = 2e3
    clamped = np.zeros(nodes, bool)
    clamped[n + 1] = True
    units = np.arange(0, nodes, 2)
    return Chain(UNIT, J, k, units, rng.uniform(0, 2 * np.pi, units.size), ground, clamped)


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.parametrize("phi_deg", [0.0, 150.0, 237.0])
def test_transfer_agrees_with_assembled(name, phi_deg):
    ch = CASES[name]()
    phi = np.radians(phi_deg)
    lam = dense_eigenvalues(ch, phi)
    modes = transfer_modes(ch, phi, f_max=1.0001 * np.sqrt(lam[-1]) / (2 * np.pi))
    assert isinstance(modes, ChainModes)
    assert modes.method == "transfer"
    assert modes.converged.all()
    assert len(modes) == ch.n
    got = modes.omega2
    # bound: rigid λ = 0 ± eps λ_max (roundoff.py), far below the elastic ones
    elastic = lam > 1e-9 * lam[-1]  # free-free chains: one rigid mode, λ = 0 ± round-off
    assert np.all(got[~elastic] == 0.0)
    # bisection to rtol 1e-12 on the exact count; eigh's own error ~1e-13 relative
    rel = np.abs(got[elastic] - lam[elastic]) / lam[elastic]
    # bound: bisection rtol 1e-12 on λ; eigh ~eps·λ_max/λ ≤ 1e-11 on these roots
    assert rel.max() <= 1e-9
    V = modes.vectors
    M, _, C = ch.sparse_matrices(phi)
    res = (np.linalg.norm(C @ V[:, elastic] - (M @ V[:, elastic]) * got[elastic], axis=0)
           / np.linalg.norm(C @ V[:, elastic], axis=0))
    # round-off level: |δλ|/λ ≤ 1e-12 from the bracket, inverse iteration to 1e-12
    # bound: inverse iteration to ROUNDOFF_RESIDUAL 1e-14 plus |δλ|/λ ≤ 1e-12
    assert res.max() <= 5e-12
    # M-orthonormal; close roots (relative gaps down to 1e-8 in the follower cluster)
    # are Rayleigh–Ritz-ed together, so the Gram matrix is I to ~1e-8..1e-7 (measured
    # 1.1e-7 on 2 BLAS threads, N = 200 fixed-fixed). bound: vectors of roots iterated
    # apart lose orthogonality by residual / relative gap (Davis–Kahan) <= 5e-12 / 1e-8
    # = 5e-4; the joint Ritz step keeps it far below; 1e-6 catches a lost Ritz step
    assert np.abs(V.T @ (M @ V) - np.eye(V.shape[1])).max() <= 1e-6


def test_assembled_modes_reference_paths():
    ch = phased(30, left=End.fixed())
    dense = assembled_modes(ch, 0.7, n_modes=12)
    band = assembled_modes(ch, 0.7, f_max=dense.freq_hz[-1] * (1 + 1e-9))
    # bound: the same dense eigh (subset vs band selection): identical to ~1 ulp
    assert np.allclose(dense.freq_hz, band.freq_hz, rtol=1e-12)
    assert dense.vectors.shape == (ch.n, 12)
    big = phased(1100, left=End.fixed())  # n = 2199 > DENSE_MAX: sparse shift-invert
    sparse = assembled_modes(big, 0.7, n_modes=6)
    mine = transfer_modes(big, 0.7, n_modes=6, vectors=False)
    # Lanczos with residual ≤ 1e-6 relative (femmech.solve); eigenvalues converge quadratically
    # bound: Lanczos residual ≤ 1e-6 -> λ to ~1e-12 (quadratic); bisection 1e-12
    assert np.allclose(sparse.freq_hz, mine.freq_hz, rtol=1e-9)


# --- the count ------------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["N20-elastic-flywheel-stubs", "N20-nonuniform"])
def test_count_equals_assembled_count(name):
    ch = CASES[name]()
    phi = 0.9
    lam = dense_eigenvalues(ch, phi)
    f = np.sqrt(np.abs(lam)) / (2 * np.pi)
    # probes: a grid, just below/above every eigenvalue (relative 1e-9: inside the
    # follower cluster, whose distinct gaps are ≥ 1e-7 here) and between distinct
    # neighbours (units in a dwell give exactly repeated roots: eigh splits them by
    # round-off, a probe between those copies has no defined count)
    apart = np.diff(f) > 1e-8 * f[1:]
    probes = np.concatenate([np.linspace(0.1, 1.2 * f[-1], 400), f * (1 - 1e-9),
                             f * (1 + 1e-9), 0.5 * (f[1:] + f[:-1])[apart]])
    want = np.searchsorted(lam, np.sign(probes) * (2 * np.pi * probes) ** 2, side="left")
    assert np.array_equal(count_below(ch, phi, probes), want)


def test_no_missed_root_in_a_band():
    ch = phased(40, left=End.elastic(2e4), right=End.flywheel(0.2))
    phi = 2.0
    lam = dense_eigenvalues(ch, phi)
    f = np.sqrt(lam) / (2 * np.pi)
    band = (f > 95) & (f < 110)  # the crowded band around the follower frequency 100.66 Hz
    modes = transfer_modes(ch, phi, f_max=110.0, vectors=False)
    assert len(modes) == np.count_nonzero(f < 110)
    # bound: bisection rtol 1e-12 on λ; eigh ~eps·λ_max/λ ≤ 1e-11 on these roots
    assert np.allclose(modes.freq_hz[modes.freq_hz > 95], f[band], rtol=1e-10)
    lowest = transfer_modes(ch, phi, n_modes=7, vectors=False)
    # bound: bisection rtol 1e-12 on λ; eigh ~eps·λ_max/λ ≤ 1e-11 on these roots
    assert np.allclose(lowest.freq_hz, f[:7], rtol=1e-10)
    assert np.array_equal(lowest.count, np.arange(7))  # simple roots: J below root i = i


def test_repeated_follower_root_in_dwell():
    # all units in the top dwell (U' = 0): every follower decouples exactly and the
    # frozen chain has an N-fold root λ = c/m (counted by J0, not by K(λ))
    n = 12
    ch = chain(UNIT, n, SPACING, DIAMETER, phases=0.0, left=End.fixed())
    phi = np.radians(150.0)
    modes = transfer_modes(ch, phi, n_modes=ch.n)  # 2n − 1: the clamped node is gone
    lam = dense_eigenvalues(ch, phi)
    # bound: bisection rtol 1e-12 on λ; eigh ~eps·λ_max/λ ≤ 1e-11 on these roots
    assert np.allclose(modes.omega2, lam, rtol=1e-11)
    # bound: a dwell root is exactly c/m; bisection rtol 1e-12 (f: 5e-13)
    at = np.flatnonzero(np.abs(modes.omega2 / (STIFF / MASS) - 1) < 1e-12)
    assert at.size == n
    assert np.all(modes.count[at] == modes.count[at[0]])  # one bracket, jump n
    V = modes.vectors[:, at]
    M, _, C = ch.sparse_matrices(phi)
    follower = ch.unit_dofs[:, 1]
    # bound: decoupled followers: shaft rotations 0 up to block inverse iteration round-off ~1e-15
    assert np.abs(V[ch.node_dof[ch.node_dof >= 0]]).max() <= 1e-12  # shaft at rest
    # bound: Löwdin/Ritz M-orthonormalisation to round-off ~1e-15
    assert np.allclose(V.T @ (M @ V), np.eye(n), atol=1e-12)
    assert np.linalg.matrix_rank(V[follower], tol=1e-8) == n  # spans all followers
    # bound: residual at round-off (ROUNDOFF_RESIDUAL 1e-14)
    assert np.linalg.norm(C @ V - (M @ V) * (STIFF / MASS)) <= 1e-12 * np.linalg.norm(C @ V)


def test_huge_stiffness_contrast():
    # spring ratio 1e8 between neighbouring segments (stiff couplings next to soft ones).
    # Reference: det(C − λM) = 0 in 40-digit arithmetic with the shaft diagonal summed
    # exactly from the springs; in double precision the assembled diagonal k_{i-1} + k_i
    # rounds the soft spring away to ~1e-8 (eigh differs from it by that much), the
    # Riccati form combines springs in series only and keeps every digit
    mp = pytest.importorskip("mpmath")
    n = 12
    k = np.full(n - 1, 8e4)
    k[::3] *= 1e4
    k[1::3] /= 1e4
    units = np.arange(0, n, 2)
    ch = Chain(UNIT, np.full(n, 3e-3), k, units, np.linspace(0, 4, units.size))
    modes = transfer_modes(ch, 1.1, n_modes=4, vectors=False)
    assert modes.freq_hz[0] == 0.0  # free-free: the rigid-body root
    M, _, C = ch.sparse_matrices(1.1)
    with mp.workdps(40):
        Cm, Mm = mp.matrix(C.toarray().tolist()), mp.matrix(M.toarray().tolist())
        Cu = ch.unit_matrices(1.1)[2]
        for i in range(n):
            own = mp.mpf(Cu[units.tolist().index(i), 0, 0]) if i in units else 0
            Cm[ch.node_dof[i], ch.node_dof[i]] = (own + (mp.mpf(k[i - 1]) if i else 0)
                                                  + (mp.mpf(k[i]) if i < n - 1 else 0))
        exact = [float(mp.findroot(lambda x: mp.det(Cm - x * Mm), mp.mpf(lam)))
                 for lam in modes.omega2[1:]]
    # bound: 40-digit reference; bisection rtol 1e-12 on λ
    assert np.allclose(modes.omega2[1:], exact, rtol=1e-12, atol=0)
    lam = dense_eigenvalues(ch, 1.1)
    # eigh: within its own bound, ~eps λ_max absolute
    # bound: eigh's absolute error ~eps·λ_max plus the bisection's 1e-12
    assert np.all(np.abs(modes.omega2[1:] - lam[1:4]) <= 1e-9 * lam[1:4] + 100 * np.finfo(
        float).eps * lam[-1])


def test_large_chain_is_order_n():
    # the count costs one pass over the N nodes per frequency: pivot steps per root and
    # node stay the same from N = 100 to 1000 (bisection depth ~ log(1/rtol), constant)
    per = {}
    for n in (100, 1000):
        ch = phased(n, left=End.fixed())
        tr.OPERATIONS["pivot_steps"] = 0
        modes = transfer_modes(ch, 0.3, n_modes=8, vectors=False)
        assert modes.converged.all()
        assert len(modes) == 8
        per[n] = tr.OPERATIONS["pivot_steps"] / (8 * n)
    assert per[1000] <= 2.0 * per[100]
    ch = phased(1000, left=End.fixed())
    modes = transfer_modes(ch, 0.3, n_modes=8)
    M, _, C = ch.sparse_matrices(0.3)
    # round-off level: the residual of evaluating C v − λ M v itself (cancellation in the
    # low modes of a long shaft, ε ‖|C| |v|‖ ≈ 5e-11 ‖C v‖ here) plus |δλ| ‖M v‖ ≤ 1e-12
    assert np.all(tr._residual_ratio(M, C, modes.vectors, modes.omega2) <= 1.0)


def test_refuses_unsymmetric_stiffness():
    class Skew:
        n = 2

        def M(self, phi):
            return np.broadcast_to(np.eye(2), np.shape(phi) + (2, 2))

        def B(self, phi, Omega):
            return np.zeros(np.shape(phi) + (2, 2))

        def C(self, phi, Omega, Omega_dot=0.0):
            return np.broadcast_to(np.array([[1.0, 0.5 * Omega], [0.0, 1.0]]),
                                   np.shape(phi) + (2, 2))

    ch = Chain(Skew(), np.ones(3), np.ones(2), np.array([1]), np.zeros(1))
    assert len(transfer_modes(ch, 0.0, f_max=10.0)) == 4  # Ω = 0: symmetric
    with pytest.raises(ValueError, match="Ω = 2.0"):
        transfer_modes(ch, 0.0, f_max=10.0, Omega=2.0)
    ref = assembled_modes(ch, 0.0, Omega=2.0)  # the reference solves it (QZ)
    assert len(ref) == 4


def test_requests_and_repr():
    ch = phased(4)
    with pytest.raises(ValueError, match="give n_modes"):
        transfer_modes(ch, 0.0)
    with pytest.raises(ValueError, match="only"):
        transfer_modes(ch, 0.0, n_modes=ch.n + 1)
    modes = transfer_modes(ch, 0.0, n_modes=3)
    text = repr(modes)
    assert "transfer: 3 roots" in text
    assert "UNCONVERGED" not in text
    bad = ChainModes(modes.freq_hz, None, "transfer", converged=[True, False, True])
    assert "UNCONVERGED roots [1]" in repr(bad)


def test_negative_root_divergence():
    # a large process force against a concave cam flank (F U'' < 0) makes C indefinite:
    # the frozen chain has λ < 0 (divergence), found by lowering the count's bracket
    unit = follower_unit(cam(), J_HUB, MASS, STIFF, force=-2e6)
    ch = chain(unit, 5, SPACING, DIAMETER, phases=np.linspace(0, 1, 5),
               left=End.elastic(1e3))
    lam = dense_eigenvalues(ch, 0.3)
    assert lam[0] < 0  # the reference agrees there is one
    modes = transfer_modes(ch, 0.3, n_modes=4)
    assert modes.freq_hz[0] < 0
    # bound: bisection rtol 1e-12 on λ; eigh ~eps·λ_max/λ ≤ 1e-11 on these roots
    assert np.allclose(modes.omega2, lam[:4], rtol=1e-10)
    assert count_below(ch, 0.3, 0.0) == 1
