"""The smeared continuum: sympy derivation, uniform limit against the cyclic closed form
(dispersion error μ²/24), phased chains against the assembled model, the error table."""

import numpy as np
import pytest
import scipy.linalg as sl
import sympy as sp

from femmech.chain import End, chain, follower_unit, torsion_segment
from femmech.chain.continuum import continuum_error_table, continuum_modes, mode_wave_numbers, smear
from femmech.chain.cyclic import cyclic_modes, wave_numbers
from femmech.mechanisms import cam_program

J_HUB, MASS, STIFF = 2e-3, 0.5, 2e5
K_SHAFT = torsion_segment(0.25, 0.04)[0]
PHI_RISE, PHI_DWELL = np.radians(60.0), np.radians(150.0)
F_FOLLOWER = np.sqrt(STIFF / MASS) / (2 * np.pi)


@pytest.fixture(scope="module")
def unit():
    cam = cam_program(0.03, rise=120, dwell_top=60, return_=120, dwell_bottom=60,
                      law="modified_sine")
    return follower_unit(cam, J_HUB, MASS, STIFF)


def assembled_freq(ch, phi):
    lam = sl.eigh(ch.C(phi), ch.M(phi), eigvals_only=True)
    return np.sqrt(np.clip(lam, 0, None)) / (2 * np.pi)


# ------------------------------------------------------------------------------- sympy


def test_continuum_is_the_long_wave_limit_symbolic():
    mu, k, a, beta, x = sp.symbols("mu k a beta x", positive=True)
    # GJ θ'' with GJ = k a, θ = cos(βx), β = μ/a: −k a β² θ per length = −k μ² θ / a per cell
    GJ = k * a
    theta = sp.cos(beta * x)
    assert sp.simplify((GJ * sp.diff(theta, x, 2) * a).subs(beta, mu / a)
                       + k * mu**2 * theta.subs(beta, mu / a)) == 0
    # discrete 2k(1 − cos μ) = k μ² − k μ⁴/12 + O(μ⁶): the continuum's error term k μ⁴/12
    series = sp.series(2 * k * (1 - sp.cos(mu)), mu, 0, 7).removeO()
    assert sp.expand(k * mu**2 - series - k * mu**4 / 12) == sp.expand(-k * mu**6 / 360)
    # shaft-like mode ω ∝ √κ: f_cont/f_disc − 1 = μ²/24 + O(μ⁴)
    ratio = sp.series(sp.sqrt(mu**2 / (2 * (1 - sp.cos(mu)))) - 1, mu, 0, 4).removeO()
    assert sp.simplify(ratio - mu**2 / 24) == 0


def test_end_conditions_symbolic():
    mu, s, g = sp.symbols("mu s g", positive=True)
    # cell form: Θ = cos(μ s − α), tan α = (g − 1 + cos μ)/sin μ meets Θ(−1) = (1 − g) Θ(0)
    alpha = sp.atan((g - 1 + sp.cos(mu)) / sp.sin(mu))
    Th = sp.cos(mu * s - alpha)
    res = sp.expand_trig(Th.subs(s, -1) - (1 - g) * Th.subs(s, 0))
    res = sp.simplify(res.rewrite(sp.cos))
    for gv, mv in ((0.3, 0.7), (1.7, 2.5), (0.0, 1.1), (1.0, 0.4)):
        # bound: float evaluation of an exact sympy identity: ~1e-16
        assert abs(float(res.subs({g: gv, mu: mv}))) < 1e-14
    # g = 0 → Θ = cos(μ(s + ½)) (Θ' = 0 half a cell out); g = 1 → sin(μ(s + 1)) (clamp)
    for gv, shape in ((0, sp.cos(mu * (s + sp.Rational(1, 2)))), (1, sp.sin(mu * (s + 1)))):
        for mv in (0.3, 1.2, 2.9):
            d = (Th - shape).subs({g: gv, mu: mv})
            # bound: as above
            assert all(abs(float(d.subs(s, sv))) < 1e-14 for sv in (0, 1, 3.5))
    # shaft form: Θ = cos(μ x̃ − α), tan α = g/μ meets GJ Θ'(0) = k_g Θ(0), x̃ = x/a
    xt = sp.symbols("xt")
    Th2 = sp.cos(mu * xt - sp.atan(g / mu))
    assert sp.simplify((sp.diff(Th2, xt) - g * Th2).subs(xt, 0)) == 0


# -------------------------------------------------------------- wave numbers and ends


@pytest.mark.parametrize(("gl", "gr"), [(0.3, 0.0), (1.7, 0.5), (0.0, 0.01), (2.0, 1.0)])
def test_cell_ends_reproduce_the_chain_wave_numbers(gl, gr):
    # the root finder's μ_j give exactly the path Laplacian's eigenvalues 2 − 2 cos μ
    for N in (3, 10, 40):
        labels, mu = mode_wave_numbers(N, gl, gr, N)
        L = 2 * np.eye(N) - np.eye(N, k=1) - np.eye(N, k=-1)
        L[0, 0], L[-1, -1] = 1 + gl, 1 + gr
        assert mu.size == N
        assert labels[0] == 1
        # bound: eigvalsh of a small Laplacian: ~N eps
        assert np.allclose(2 - 2 * np.cos(mu), np.linalg.eigvalsh(L), atol=1e-13)


def test_closed_forms_and_shaft_ends():
    for case, g in (("free-free", (0, 0)), ("grounded-free", (1, 0)),
                    ("grounded-grounded", (1, 1))):
        # bound: closed forms vs brentq (xtol 1e-15)
        assert np.allclose(mode_wave_numbers(9, *g, 9)[1], wave_numbers(9, case)[1],
                           rtol=1e-15)
    # shaft form: μ N − atan(g_L/μ) − atan(g_R/μ) = lπ, root l in [lπ/N, (l+1)π/N)
    labels, mu = mode_wave_numbers(12, 0.8, 0.0, 5, ends="shaft")
    h = mu * 12 - np.arctan(0.8 / mu)
    # bound: brentq xtol 1e-15 on μ; the residual h(μ) to ~1e-13
    assert np.allclose(h, np.pi * np.arange(5), atol=1e-12)
    assert labels.tolist() == [1, 2, 3, 4, 5]


# ------------------------------------------------------------ uniform limit vs cyclic


@pytest.mark.parametrize("case", ["free-free", "grounded-free", "grounded-grounded"])
def test_dwell_shaft_branch_error_is_the_dispersion_error(unit, case):
    # U' = 0: the shaft branch is λ = κ/J' exactly, so f_cont/f_disc − 1 = √(μ²/(2 − 2cos μ)) − 1
    # ≈ μ²/24; measured against μ²/24 within 10 % for μ ≤ 1 (next term +μ⁴/640 ≤ 4 %)
    ends = {"free-free": (End(), End()), "grounded-free": (End.elastic(K_SHAFT), End()),
            "grounded-grounded": (End.elastic(K_SHAFT), End.elastic(K_SHAFT))}[case]
    ch = chain(unit, 40, 0.25, 0.04, cells=True, left=ends[0], right=ends[1])
    cy = cyclic_modes(ch, PHI_DWELL, vectors=False)
    co = continuum_modes(ch, PHI_DWELL, ch.n, vectors=False, estimate=False, warn=False)
    labels, mu = wave_numbers(40, case)
    # bound: the dwell root c/m: eigh ~1e-15 on the 2×2 problem
    shaft = ~np.isclose(cy.freq_hz, F_FOLLOWER, rtol=1e-9)
    checked = 0
    for j, m_ in zip(labels, mu, strict=True):
        if not 0.05 < m_ <= 1.0:
            continue
        fd = cy.freq_hz[(cy.label == j) & shaft]
        # bound: as above
        fc = co.freq_hz[(co.label == j) & ~np.isclose(co.freq_hz, F_FOLLOWER, rtol=1e-9)]
        err = fc[0] / fd[0] - 1
        assert err == pytest.approx(np.sqrt(m_**2 / (2 - 2 * np.cos(m_))) - 1, rel=1e-9)
        assert err == pytest.approx(m_**2 / 24, rel=0.10)
        checked += 1
    assert checked >= 10


def test_rise_error_follows_first_order_perturbation(unit):
    # coupled shaft/follower (mid-rise): δf/f ≈ w_a² k μ⁴ / (24 λ) (Hellmann–Feynman,
    # dλ/dκ = w_a² for M'-normalised w, δκ = k μ⁴/12); checked within 10 % for μ ≤ 0.8
    from femmech.chain.cyclic import unit_branches
    N = 40
    ch = chain(unit, N, 0.25, 0.04, cells=True)
    cy = cyclic_modes(ch, PHI_RISE, vectors=False)
    co = continuum_modes(ch, PHI_RISE, ch.n, vectors=False, estimate=False, warn=False)
    c = smear(ch, PHI_RISE)
    Mp = c.M.copy()
    Mp[0, 0] += c.node_inertia
    labels, mu = wave_numbers(N, "free-free")
    sel = (mu > 0.05) & (mu <= 0.8)
    lam, W = unit_branches(Mp, c.C, 2 * c.k * (1 - np.cos(mu[sel])), 0)
    est = W[:, 0, :] ** 2 * c.k * mu[sel, None] ** 4 / (24 * lam)   # (K, 2)
    for row, j in enumerate(labels[sel]):
        fd = np.sort(cy.freq_hz[cy.label == j])
        fc = np.sort(co.freq_hz[co.label == j])
        err = fc / fd - 1
        big = est[row] > 1e-5   # the follower-like branch's error is O(1e-6): skip it
        assert np.allclose(err[big], est[row][big], rtol=0.10)


def test_uniform_continuum_vectors_are_the_chain_shapes(unit):
    # cell ends: the continuum's node shapes are the chain's wave vectors, so its modes
    # match the assembled ones (MAC ≈ 1) for low waves
    ch = chain(unit, 20, 0.25, 0.04, cells=True, left=End.elastic(0.4 * K_SHAFT))
    M, C = ch.M(PHI_RISE), ch.C(PHI_RISE)
    lam, V = sl.eigh(C, M)
    co = continuum_modes(ch, PHI_RISE, 8, estimate=False, warn=False)
    # bound: normalised with the same M: ~1e-15
    assert np.allclose(np.einsum("ik,ij,jk->k", co.vectors, M, co.vectors), 1, rtol=1e-12)
    mac = (co.vectors.T @ M @ V) ** 2          # (8, n), V M-normalised
    assert np.all(mac.max(axis=1) > 0.999)
    assert np.array_equal(np.argmax(mac, axis=1), np.arange(8))
    assert np.array_equal(co.label[:1], [1])


# ------------------------------------------------------------------- phased chains


@pytest.mark.parametrize("N", [40, 100])
@pytest.mark.parametrize("phases", ["spread", "random"])
def test_phased_chain_low_modes_against_assembled(unit, N, phases):
    # Smearing with the mean M̄(φ) = mean_u M_u(φ + δ_u). Measured (free–free, φ = 0 and
    # 1 rad, N = 40, 100): modes below half the follower frequency within 0.6 %; near the
    # follower cluster a few % (the mean m U' coupling ≈ 0 when phases are spread, while
    # each unit's own U' is not) — bound asserted: 1 % for f < f_follower / 2.
    checked = 0
    rng = np.random.default_rng(7)
    ph = (2 * np.pi * np.arange(N) / N if phases == "spread"
          else rng.uniform(0, 2 * np.pi, N))
    for left in (End(), End.elastic(0.5 * K_SHAFT)):
        ch = chain(unit, N, 0.25, 0.04, cells=True, phases=ph, left=left)
        for phi in (0.0, 1.0):
            f = assembled_freq(ch, phi)
            co = continuum_modes(ch, phi, ch.n, vectors=False, estimate=False,
                                 warn=False)
            low = (f > 1.0) & (f < 0.5 * F_FOLLOWER)
            checked += low.sum()
            assert np.all(np.abs(co.freq_hz[low] / f[low] - 1) < 0.01)
    assert checked >= 2


def test_shaft_ends_grounded_error_is_order_one_over_n(unit):
    # ends="shaft" puts the spring half a cell further out than the chain does: μ shifts by
    # O(μ/N); the lowest mode of a chain grounded at one end stays within 1/N relative
    for N in (20, 80):
        ch = chain(unit, N, 0.25, 0.04, cells=True, left=End.elastic(K_SHAFT))
        f = assembled_freq(ch, PHI_DWELL)
        co = continuum_modes(ch, PHI_DWELL, 3, ends="shaft", vectors=False, estimate=False,
                             warn=False)
        assert abs(co.freq_hz[0] / f[0] - 1) < 1.0 / N
        cell = continuum_modes(ch, PHI_DWELL, 3, vectors=False)
        assert abs(cell.freq_hz[0] / f[0] - 1) < 1e-3   # cell ends: dispersion only


# -------------------------------------------------------------------- errors, table


def test_continuum_refuses_what_it_cannot_smear(unit):
    with pytest.raises(ValueError, match="carries no unit"):
        continuum_modes(chain(unit, 5, 0.25, 0.04, cells=True, end_length=0.1), 0.0, 3)
    with pytest.raises(ValueError, match="node inertia 1 is"):
        continuum_modes(chain(unit, 5, 0.25, 0.04), 0.0, 3)
    with pytest.raises(ValueError, match="clamped"):
        continuum_modes(chain(unit, 5, 0.25, 0.04, cells=True, left=End.fixed()), 0.0, 3)
    with pytest.raises(ValueError, match="localised"):
        continuum_modes(chain(unit, 5, 0.25, 0.04, cells=True,
                              left=End.elastic(3 * K_SHAFT)), 0.0, 3)
    with pytest.raises(ValueError, match="n_modes"):
        continuum_modes(chain(unit, 5, 0.25, 0.04, cells=True), 0.0, 11)


def test_error_table(unit):
    t = continuum_error_table(unit, n_values=(5, 10, 40), modes=(1, 2, 5, 10),
                              phi=PHI_RISE)
    assert t.error.shape == (3, 4, 2)
    assert np.isnan(t.error[0, 2:]).all()
    assert np.isnan(t.error[1, 3]).all()
    a = np.abs(t.error)
    worst = np.where(np.isnan(a).all(2), np.nan, np.nan_to_num(a).max(2))
    # the worst branch is the shaft-like one: at most the pure-shaft dispersion error
    # √(μ²/(2 − 2 cos μ)) − 1 (≈ μ²/24; coupling to the follower only lowers it)
    ok = ~np.isnan(worst)
    mu = t.mu[ok]
    # bound: float rounding of the dispersion bound
    assert np.all(worst[ok] <= (np.sqrt(mu**2 / (2 - 2 * np.cos(mu))) - 1) * (1 + 1e-9))
    assert np.all(worst[ok] >= 0.5 * mu**2 / 24)
    assert "| 40 |" in t.markdown()
    assert "–" in t.markdown()
