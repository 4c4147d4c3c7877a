"""Cyclic (wave) decomposition of uniform chains: sympy proofs, closed form vs assembled,
clusters of nearly repeated roots, uniformity errors."""

import numpy as np
import pytest
import scipy.linalg as sl
import sympy as sp

from femmech.chain import End, chain, follower_unit, torsion_segment
from femmech.chain.cyclic import (
    cyclic_modes,
    end_case,
    is_uniform,
    laplacian,
    pass_bands,
    uniformity_problem,
    wave_numbers,
    wave_vectors,
)
from femmech.mechanisms import cam_program

J_HUB, MASS, STIFF = 2e-3, 0.5, 2e5
K_SHAFT = torsion_segment(0.25, 0.04)[0]   # 40 mm steel shaft, 0.25 m spacing
PHI_RISE = np.radians(60.0)   # mid-rise of a 120° modified-sine rise: |U'| largest
PHI_DWELL = np.radians(150.0)  # top dwell: U' = 0

ENDS = {"free-free": (End(), End()),
        "grounded-free": (End.elastic(K_SHAFT), End()),
        "free-grounded": (End(), End.elastic(K_SHAFT)),
        "grounded-grounded": (End.elastic(K_SHAFT), End.elastic(K_SHAFT))}


@pytest.fixture(scope="module")
def unit():
    cam = cam_program(0.03, rise=120, dwell_top=60, return_=120, dwell_bottom=60,
                      law="modified_sine")
    return follower_unit(cam, J_HUB, MASS, STIFF)


def uniform(unit, N, case="free-free", **kw):
    left, right = ENDS[case]
    return chain(unit, N, 0.25, 0.04, cells=True, left=left, right=right, **kw)


def assembled_freq(ch, phi):
    """Reference: dense generalized eigh of the assembled frozen chain (LAPACK)."""
    lam = sl.eigh(ch.C(phi), ch.M(phi), eigvals_only=True)
    return np.sqrt(np.clip(lam, 0, None)) / (2 * np.pi)


# ---------------------------------------------------------------- sympy: the derivation


def _symbolic_laplacian(N, case):
    L = sp.zeros(N, N)
    for i in range(N - 1):
        L[i, i] += 1
        L[i + 1, i + 1] += 1
        L[i, i + 1] = L[i + 1, i] = -1
    if case.startswith("grounded"):
        L[0, 0] += 1
    if case.endswith("-grounded"):
        L[N - 1, N - 1] += 1
    return L


def _symbolic_waves(N, case):
    """(μ_j, v_j) of the module docstring, exact sympy."""
    out = []
    if case == "free-free":
        for j in range(N):
            mu = sp.pi * j / N
            out.append((mu, sp.Matrix([sp.cos(mu * (i + sp.Rational(1, 2)))
                                       for i in range(N)])))
    else:
        for j in range(1, N + 1):
            mu = (sp.pi * (2 * j - 1) / (2 * N + 1) if case == "grounded-free"
                  else sp.pi * j / (N + 1))
            out.append((mu, sp.Matrix([sp.sin(mu * (i + 1)) for i in range(N)])))
    return out


@pytest.mark.parametrize("N", [3, 4])
@pytest.mark.parametrize("case", ["free-free", "grounded-free", "grounded-grounded"])
def test_laplacian_eigenpairs_symbolic(N, case):
    # L v_j = 2(1 − cos μ_j) v_j exactly, for the three end cases
    L = _symbolic_laplacian(N, case)
    for mu, v in _symbolic_waves(N, case):
        residual = (L * v - 2 * (1 - sp.cos(mu)) * v).applyfunc(
            lambda e: sp.nsimplify(sp.simplify(sp.expand_trig(e)), rational=False))
        # bound: 30-digit evaluation of an identity that is exactly zero
        assert all(abs(complex(sp.N(e, 30))) < 1e-25 for e in residual)


def test_laplacian_stencil_and_ends_for_symbolic_n():
    # interior rows for any N: −v(i−1) + 2 v(i) − v(i+1) = 2(1 − cos μ) v(i) for v = cos(μ s + c)
    mu, s, c = sp.symbols("mu s c")
    v = sp.cos(mu * s + c)
    stencil = -v.subs(s, s - 1) + 2 * v - v.subs(s, s + 1) - 2 * (1 - sp.cos(mu)) * v
    assert sp.simplify(sp.expand_trig(sp.expand(stencil))) == 0
    # free end: ghost v(−1) = v(0) for cos(μ(s + ½)); v(N) = v(N−1) when μ = jπ/N
    w = sp.cos(mu * (s + sp.Rational(1, 2)))
    assert sp.simplify(w.subs(s, -1) - w.subs(s, 0)) == 0
    for n in (1, 3, 4):
        for jj in range(n):
            assert sp.simplify((w.subs(s, n) - w.subs(s, n - 1)).subs(mu, jj * sp.pi / n)) == 0
    # ground spring k at the left = clamped ghost: sin(μ(s + 1)) vanishes at s = −1
    z = sp.sin(mu * (s + 1))
    assert z.subs(s, -1) == 0
    # free right end with the grounded left: sin(μ(N + 1)) = sin(μN) at μ = (2j−1)π/(2N+1)
    for n in (1, 2, 5):
        for jj in range(1, n + 1):
            m_ = sp.pi * (2 * jj - 1) / (2 * n + 1)
            assert sp.simplify(sp.sin(m_ * (n + 1)) - sp.sin(m_ * n)) == 0


@pytest.mark.parametrize("N", [3, 4])
@pytest.mark.parametrize("case", ["free-free", "grounded-free", "grounded-grounded"])
def test_wave_basis_block_diagonalises_assembled_matrices(N, case):
    # M = I ⊗ (M_u + J e eᵀ), C = I ⊗ C_u + k L ⊗ e eᵀ; with T = V ⊗ I_2 (V the waves):
    # Tᵀ C T = blockdiag(|v_j|² (C_u + 2k(1 − cos μ_j) e eᵀ)), Tᵀ M T = blockdiag(|v_j|² M')
    m11, m12, m22, c11, c12, c22, J, k = sp.symbols("m11 m12 m22 c11 c12 c22 J k")
    Mu = sp.Matrix([[m11 + J, m12], [m12, m22]])
    Cu = sp.Matrix([[c11, c12], [c12, c22]])
    E = sp.Matrix([[1, 0], [0, 0]])
    L = _symbolic_laplacian(N, case)
    M = sp.kronecker_product(sp.eye(N), Mu)
    C = sp.kronecker_product(sp.eye(N), Cu) + k * sp.kronecker_product(L, E)
    waves = _symbolic_waves(N, case)
    V = sp.Matrix.hstack(*[v for _, v in waves])
    T = sp.kronecker_product(V, sp.eye(2))
    for A, blocks in ((M, [Mu] * N),
                      (C, [Cu + 2 * k * (1 - sp.cos(mu)) * E for mu, _ in waves])):
        D = T.T * A * T
        expect = sp.diag(*[(v.T * v)[0] * B for (_, v), B in zip(waves, blocks, strict=True)])
        diff = (D - expect).applyfunc(lambda e: sp.simplify(sp.expand_trig(e)))
        # every entry is linear in the symbols with trig-number coefficients (cos(π/7) …
        # that simplify cannot always cancel): each coefficient evaluated to 50 digits
        syms = (m11, m12, m22, c11, c12, c22, J, k)
        coeffs = [sp.expand(e).coeff(x) for e in diff for x in syms] + [
            sp.expand(e).subs(dict.fromkeys(syms, 0)) for e in diff]
        # bound: 50-digit evaluation of exact zeros
        assert max(abs(sp.N(q, 50)) for q in coeffs) < 1e-40


def test_follower_quadratic_and_stop_band_symbolic():
    # det(C' − λ M') for the follower unit: m J_r λ² − (κ m + c J_t) λ + κ c, J_t = J_r + m U'²;
    # its value is −c² U'² at λ = c/m and −κ c m U'²/J_r at λ = c J_t/(m J_r): both ≤ 0, so
    # the two decoupled/coupled follower frequencies bound a stop band (no root inside)
    lam, m, c, Jr, U1, kap = sp.symbols("lambda m c J_r U1 kappa", positive=True)
    Jt = Jr + m * U1**2
    Mp = sp.Matrix([[Jt, m * U1], [m * U1, m]])
    Cp = sp.Matrix([[kap, 0], [0, c]])
    p = sp.expand((Cp - lam * Mp).det())
    assert sp.simplify(p - (m * Jr * lam**2 - (kap * m + c * Jt) * lam + kap * c)) == 0
    assert sp.simplify(p.subs(lam, c / m) + c**2 * U1**2) == 0
    assert sp.simplify(p.subs(lam, c * Jt / (m * Jr)) + kap * c * m * U1**2 / Jr) == 0
    # both roots increase with κ: dλ/dκ = −p_κ / p_λ = (c − λ m)/p_λ, and p_λ < 0 below c/m
    # (lower root) while c − λm < 0 above c J_t/(m J_r) > c/m (upper root, p_λ > 0)
    assert sp.simplify(sp.diff(p, kap) - (c - lam * m)) == 0


# --------------------------------------------------------------- numerics vs assembled


def test_wave_helpers_match_the_laplacian():
    for N in (1, 2, 7):
        for case in ("free-free", "grounded-free", "free-grounded", "grounded-grounded"):
            if N == 1 and case != "free-free":
                continue
            _, mu = wave_numbers(N, case)
            V = wave_vectors(N, case)
            L = laplacian(N, case)
            # bound: eigh of an (N, N) Laplacian: ~N eps
            assert np.allclose(V.T @ V, np.eye(N), atol=1e-13)
            # bound: as above
            assert np.allclose(L @ V, V * (2 - 2 * np.cos(mu)), atol=1e-13)


@pytest.mark.parametrize("N", [1, 2, 7, 50])
@pytest.mark.parametrize("case", ["free-free", "grounded-free", "free-grounded",
                                  "grounded-grounded"])
@pytest.mark.parametrize("phi", [PHI_RISE, 0.3])
def test_cyclic_equals_assembled(unit, N, case, phi):
    ch = uniform(unit, N, case)
    assert is_uniform(ch)
    got = cyclic_modes(ch, phi)
    ref = assembled_freq(ch, phi)
    assert got.method == "cyclic"
    assert got.freq_hz.shape == (ch.n,)
    # 1e-10 relative (brief); the rigid mode (free–free) in λ: LAPACK leaves it at
    # ~1e-16 λ_max, i.e. f ~ 1e-8 f_max, so zero is checked as λ < 1e-13 λ_max
    # bound: rigid roots: eigh's ±eps·λ_max
    rigid = ref**2 < 1e-13 * ref.max() ** 2
    # bound: eigh of the small problem vs of the assembled chain: both ~1e-13
    assert np.allclose(got.freq_hz[~rigid], ref[~rigid], rtol=1e-10, atol=0)
    # bound: as above (rigid)
    assert np.all(got.freq_hz[rigid] ** 2 < 1e-13 * ref.max() ** 2)
    assert rigid.sum() == (case == "free-free")
    M, C = ch.M(phi), ch.C(phi)
    V = got.vectors
    # bound: orthonormality after one Cholesky and eigh: ~1e-14
    assert np.allclose(V.T @ M @ V, np.eye(ch.n), atol=1e-12)
    # bound: residual ~eps·‖C‖ · n
    assert np.allclose(C @ V, M @ V * got.omega2, atol=1e-10 * np.abs(C).max())
    # every wave number appears m = 2 times
    assert np.all(np.bincount(got.label - got.label.min()) == 2)


def test_n1_single_node_uses_its_ground_spring(unit):
    ch = chain(unit, 1, 0.25, 0.04, left=End.elastic(3e4), right=End.elastic(2e4))
    assert end_case(ch) == "grounded-free"
    # bound: the same 1-node problem in closed form: ~1e-15
    assert np.allclose(cyclic_modes(ch, PHI_RISE).freq_hz, assembled_freq(ch, PHI_RISE),
                       rtol=1e-12)


def test_symmetric_problem_required(unit):
    ch = uniform(unit, 3)
    # Ω ≠ 0 in a rise: C(φ, Ω) of Table 5.1 case 1 gets the unsymmetric m U' U''' Ω² term
    with pytest.raises(ValueError, match="unsymmetric"):
        cyclic_modes(ch, PHI_RISE, Omega=10.0)


# ------------------------------------------------------------------------- clusters


@pytest.mark.parametrize("N", [7, 50])
@pytest.mark.parametrize("case", ["free-free", "grounded-free", "grounded-grounded"])
def test_every_branch_fills_its_pass_band_with_n_roots(unit, N, case):
    ch = uniform(unit, N, case)
    bands, gaps = pass_bands(ch, PHI_RISE)
    f = assembled_freq(ch, PHI_RISE)
    # bound: band edges from a 2×2 eigh: ~1e-15 relative
    tol = 1e-10 * f.max()
    for lo, hi in bands:
        assert np.count_nonzero((f >= lo - tol) & (f <= hi + tol)) == N
    # the stop band between the decoupled √(c/m) and the coupled √(c J_t/(m J_r)) stays empty
    (g_lo, g_hi), = gaps
    Jr = ch.node_inertia[0] + J_HUB
    U1 = ch.unit.M(PHI_RISE)[0, 1] / MASS
    Jt = Jr + MASS * U1**2
    # bound: closed forms √(k/m)/(2π) evaluated in two orders: a few eps
    assert g_lo == pytest.approx(np.sqrt(STIFF / MASS) / (2 * np.pi), rel=1e-13)
    assert g_hi == pytest.approx(np.sqrt(STIFF * Jt / (MASS * Jr)) / (2 * np.pi), rel=1e-13)
    assert not np.any((f > g_lo + tol) & (f < g_hi - tol))


def test_follower_cluster_is_tight_for_a_long_chain(unit):
    # N = 50, stiff shaft: the roots of waves with κ_j ≫ c U'² sit within c U'²/κ_j
    # (relative, in λ) below c/m — a cluster of nearly repeated roots
    N = 50
    ch = uniform(unit, N)
    got = cyclic_modes(ch, PHI_RISE, vectors=False)
    U1 = ch.unit.M(PHI_RISE)[0, 1] / MASS
    lam_f = STIFF / MASS
    _, mu = wave_numbers(N, "free-free")
    kappa = 2 * K_SHAFT * (1 - np.cos(mu))
    lower = np.array([got.omega2[got.label == j].min() for j in range(N)])
    far = kappa > 100 * STIFF * U1**2
    assert far.sum() > 30
    # one Newton step of det(C' − λM') = 0 from λ = c/m (test_follower_quadratic…):
    # 1 − λ m/c ≈ c U'² / (κ − c (J_r − m U'²)/m); the neglected Newton term is
    # O(dev²), so 1 % of the deviation itself is a safe tolerance
    dev = 1 - lower[far] / lam_f
    Jr = ch.node_inertia[0] + J_HUB
    est = STIFF * U1**2 / (kappa[far] - STIFF * (Jr - MASS * U1**2) / MASS)
    assert np.allclose(dev, est, rtol=0.01)
    spread = np.ptp(np.sqrt(lower[far])) / np.sqrt(lam_f)
    assert spread < 0.01   # > 30 roots inside 1 % of the follower frequency


def test_dwell_gives_an_exactly_repeated_follower_root(unit):
    # U' = 0: the follower decouples; √(c/m) is an N-fold root
    ch = uniform(unit, 7)
    got = cyclic_modes(ch, PHI_DWELL, vectors=False)
    f_f = np.sqrt(STIFF / MASS) / (2 * np.pi)
    # bound: a dwell root is exactly c/m: eigh ~1e-15 on the 2×2 problem
    assert np.count_nonzero(np.isclose(got.freq_hz, f_f, rtol=1e-12)) == 7
    ref = assembled_freq(ch, PHI_DWELL)
    # bound: eigh vs eigh: ~1e-13
    assert np.allclose(got.freq_hz[1:], ref[1:], rtol=1e-10, atol=0)


# ------------------------------------------------------------------- uniformity errors


def test_not_uniform_names_the_first_difference(unit):
    ph = np.zeros(5)
    ph[3] = 0.5
    with pytest.raises(ValueError, match=r"unit 3 has phase 0.5 rad, unit 0 has 0 rad"):
        cyclic_modes(uniform(unit, 5, phases=ph), 0.1)
    assert not is_uniform(chain(unit, 5, 0.25, 0.04))   # cells=False: end nodes lighter
    assert "node 1 has inertia" in uniformity_problem(chain(unit, 5, 0.25, 0.04))
    ch = chain(unit, 4, 0.25, 0.04, cells=True, left=End.elastic(1e3))
    assert "left ground spring is 1000" in uniformity_problem(ch)
    ch = chain(unit, 4, 0.25, 0.04, cells=True, end_length=0.1)
    assert "carries no unit" in uniformity_problem(ch)
    ch = chain(unit, 4, 0.25, 0.04, cells=True, right=End.fixed())
    assert uniformity_problem(ch) == "node 3 is clamped"
    ch = chain(unit, 4, 0.25, 0.04, cells=True, left=End.flywheel(0.1))
    assert "node 1 has inertia" in uniformity_problem(ch)
