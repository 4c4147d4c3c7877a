"""Synthesis of a chain against the drive harmonics (femmech.chain.synthesis)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy

from femmech.chain import Chain, End, chain, follower_unit
from femmech.chain.synthesis import (
    Parameter,
    band_distance,
    frequency_bands,
    frozen_eigen,
    harmonic_bands,
    ks_margin,
    margin_sensitivities,
    resonance_margin,
    synthesise,
)
from femmech.mechanisms.motion_laws import CamProfile, CamSegment, cycloidal

TWO_PI = 2 * np.pi


class Disc:
    """A one-coordinate unit: rotary inertia J0 (1 + eps cos ψ) (kg m²), no stiffness."""

    n = 1

    def __init__(self, J0: float, eps: float = 0.0):
        self.J0, self.eps = J0, eps

    def M(self, phi):
        phi = np.asarray(phi, dtype=float)
        return (self.J0 * (1 + self.eps * np.cos(phi)))[..., None, None]

    def B(self, phi, Omega):
        return np.zeros(np.shape(phi) + (1, 1))

    def C(self, phi, Omega=0.0, Omega_dot=0.0):
        return np.zeros(np.shape(phi) + (1, 1))


def one_dof(k: float, J: float, eps: float = 0.0) -> Chain:
    """One node (inertia J/2) on a ground spring k (N m/rad), carrying a Disc of J/2."""
    return Chain(Disc(J / 2, eps), np.array([J / 2]), np.zeros(0), np.array([0]),
                 np.array([0.0]), ground=np.array([k]))


CAM = CamProfile((CamSegment(np.pi / 2, 0.01, cycloidal()), CamSegment(np.pi / 2),
                  CamSegment(np.pi / 2, -0.01, cycloidal()), CamSegment(np.pi / 2)))


def build(values: dict) -> Chain:
    """N = 5 followers (0.5 kg on c N/m) on a 30 mm shaft, elastic coupling 1e4 N m/rad
    with a flywheel J (kg m²), phased 72° apart."""
    unit = follower_unit(CAM, 1e-3, values.get("m", 0.5), values["c"])
    return chain(unit, 5, 0.2, 0.03, left=End.elastic(1e4, values["J"]),
                 phases=np.arange(5) * TWO_PI / 5)


SPEED, K = (1200.0, 1500.0), 4  # bands 20-25, 40-50, 60-75, 80-100 Hz
PARAMS = [Parameter("J", 0.02, 0.2, 0.05, log=True), Parameter("c", 1e5, 4e5, 2e5, log=True)]


# --- the margin on hand-built cases ------------------------------------------------------

def test_one_dof_margin_below_band():
    # f = √(k/J)/2π = 9 Hz; 600-900 rpm: band 1 = [10, 15] Hz, d = 1 - 9/10 = 0.1
    J = 0.1
    k = J * (TWO_PI * 9.0) ** 2
    m = resonance_margin(one_dof(k, J), (600, 900), 3)
    assert m.value == pytest.approx(0.1, rel=1e-12)  # bound: round-off of one 1x1 eigh
    assert (m.harmonic, m.branch, m.side) == (1, 0, "below")
    assert m.band_hz == pytest.approx((10.0, 15.0))


def test_one_dof_margin_inside_and_above():
    J = 0.1
    inside = resonance_margin(one_dof(J * (TWO_PI * 12.0) ** 2, J), (600, 900), 2)
    # bound: one 1x1 eigh and two divisions: a few eps
    assert inside.value == pytest.approx(-0.2, rel=1e-12)  # max(1 - 12/10, 12/15 - 1)
    assert inside.side == "inside"
    above = resonance_margin(one_dof(J * (TWO_PI * 32.0) ** 2, J), (600, 900), 2)
    # bound: one 1x1 eigh and a division: a few eps
    assert above.value == pytest.approx(32 / 30 - 1, rel=1e-12)  # band 2 = [20, 30] Hz
    assert (above.harmonic, above.side) == (2, "above")


def test_margin_critical_angle_of_varying_inertia():
    # J(φ) = J/2 + J/2 (1 + 0.5 cos φ): f lowest where J largest, at φ = 0; above band 2
    J, eps = 0.1, 0.5
    k = J * (TWO_PI * 32.0) ** 2
    m = resonance_margin(one_dof(k, J, eps), (600, 900), 2, n_angles=72)
    f_min = np.sqrt(k / (J * (1 + eps / 2))) / TWO_PI
    assert m.angle == 0.0
    # bound: 2x2 eigh at the minimum of f(φ) (closed form): ~eps·cond(M)
    assert m.frequency_hz == pytest.approx(f_min, rel=1e-12)
    assert m.value == pytest.approx(f_min / 30 - 1, rel=1e-12)


def test_band_distance_and_bands():
    lo, hi = harmonic_bands((600, 900), 3)
    np.testing.assert_allclose(lo, [10, 20, 30])
    np.testing.assert_allclose(hi, [15, 30, 45])
    d = band_distance([9.5, 10.0, 15.0, 47.25], lo, hi)
    np.testing.assert_allclose(d[:, 0], [0.05, 0.0, 0.0, 2.15])
    assert d[3, 2] == pytest.approx(0.05)  # 47.25 = 1.05 × 45: on the widened edge


@pytest.mark.parametrize("bad", [(900, 600), (0, 600), (600,), "fast"])
def test_bad_speed_range(bad):
    with pytest.raises(ValueError, match="speed_rpm"):
        harmonic_bands(bad, 3)


# --- formulas, checked with sympy --------------------------------------------------------

def test_ks_formula_sympy():
    """KS = -(1/ρ) ln Σ 1/(e^{ρa} + e^{ρb}) and its f-derivative as ks_margin computes."""
    f1, f2, rho = sympy.symbols("f1 f2 rho", positive=True)
    lo, hi = [10, 20], [15, 30]
    terms = [1 / (sympy.exp(rho * (1 - f / lo[k])) + sympy.exp(rho * (f / hi[k] - 1)))
             for f in (f1, f2) for k in range(2)]
    ks = -sympy.log(sum(terms)) / rho
    point = {f1: sympy.Rational(93, 10), f2: sympy.Rational(161, 10), rho: 40}
    value, grad = ks_margin(np.array([[9.3, 16.1]]), np.array(lo, float),
                            np.array(hi, float), 40.0)
    # bound: the KS function of two numbers against sympy: a few eps of exp/log
    assert value == pytest.approx(float(ks.subs(point)), rel=1e-12)
    exact = [float(sympy.diff(ks, f).subs(point)) for f in (f1, f2)]
    # bound: analytic derivative vs sympy: round-off ~1e-14
    np.testing.assert_allclose(grad[0], exact, rtol=1e-10)
    # the nested form: exp(-ρ smoothmax(a, b)) = 1/(e^{ρa} + e^{ρb})
    a, b = sympy.symbols("a b", real=True)
    smax = sympy.log(sympy.exp(rho * a) + sympy.exp(rho * b)) / rho
    assert sympy.simplify(sympy.exp(-rho * smax) - 1 / (sympy.exp(rho * a)
                                                        + sympy.exp(rho * b))) == 0


def test_fox_kapoor_sympy():
    """dλ/dp = vᵀ (dC/dp − λ dM/dp) v (M-normalised v) for a 2×2 pencil with p in M and C."""
    p, lam = sympy.symbols("p lambda", positive=True)
    M = sympy.Matrix([[2 + p, p / 3], [p / 3, 1]])
    C = sympy.Matrix([[5 + p**2, -2], [-2, 3 * p]])
    roots = sympy.solve((C - lam * M).det(), lam)
    p0 = sympy.Rational(7, 10)
    exact = sorted(float(sympy.diff(r, p).subs(p, p0)) for r in roots)
    Mn, Cn = (np.array(A.subs(p, p0), dtype=float) for A in (M, C))
    dM, dC = (np.array(A.diff(p).subs(p, p0), dtype=float) for A in (M, C))
    w, V = frozen_eigen(Mn[None], Cn[None])
    fk = [V[0, :, i] @ (dC - w[0, i] * dM) @ V[0, :, i] for i in range(2)]
    by_root = sorted(zip((float(r.subs(p, p0)) for r in roots), exact, strict=True))
    # bound: eigh vs sympy roots: ~1e-15
    np.testing.assert_allclose(w[0], [r for r, _ in by_root], rtol=1e-12)
    # bound: Fox–Kapoor vs sympy: ~1e-13
    np.testing.assert_allclose(fk, [d for _, d in by_root], rtol=1e-10)


def test_one_dof_frequency_sympy():
    """The 1-DOF chain's eigenvalue is k/J: det(k - λ J) = 0."""
    k, J, lam = sympy.symbols("k J lambda", positive=True)
    assert sympy.solve(k - lam * J, lam) == [k / J]
    bands = frequency_bands(one_dof(400.0, 0.25))
    # bound: eigh of a 1×1 problem: exact to ~1e-16
    np.testing.assert_allclose(bands.freq_hz, np.sqrt(400 / 0.25) / TWO_PI, rtol=1e-13)


# --- matrices and gradients ---------------------------------------------------------------

def _ks(values, rho=200.0):
    return margin_sensitivities(build, PARAMS, values, SPEED, K, n_angles=24, rho=rho)


@pytest.mark.parametrize("values", [{"J": 0.05, "c": 2e5}, {"J": 0.12, "c": 1.3e5}])
def test_gradient_against_finite_differences(values):
    _, grad, _ = _ks(values)
    for name in ("J", "c"):
        h = 1e-4 * values[name]
        up, down = dict(values), dict(values)
        up[name] += h
        down[name] -= h
        fd = (_ks(up)[0] - _ks(down)[0]) / (2 * h)
        # central difference error O(h²) ~ 1e-8 relative; matrix differences 1e-6 steps
        assert grad[name] == pytest.approx(fd, rel=1e-5)


def test_gradient_through_a_cluster_of_repeated_eigenvalues():
    """In-phase identical followers: their modes form a cluster (4 equal eigenvalues at
    every angle); the aggregate's derivative is still the FD one."""
    def in_phase(v):
        return chain(follower_unit(CAM, 1e-3, 0.5, v["c"]), 5, 0.2, 0.03,
                     left=End.elastic(1e4, v["J"]))
    f = frequency_bands(in_phase({"J": 0.05, "c": 2e5}), n_angles=6).freq_hz[0]
    # bound: a repeated root from identical units in phase: eigh splits it by ~1e-13
    assert np.ptp(f[1:5]) < 1e-9 * f[1]  # the cluster is there
    values = {"J": 0.05, "c": 2.1e5}  # f cluster ≈ 103 Hz: KS dominated by it (band 4)
    ks, grad, _ = margin_sensitivities(in_phase, PARAMS, values, SPEED, K, n_angles=12)
    h = 1e-4 * values["c"]
    fd = (margin_sensitivities(in_phase, PARAMS, {**values, "c": values["c"] + h}, SPEED,
                               K, n_angles=12)[0]
          - margin_sensitivities(in_phase, PARAMS, {**values, "c": values["c"] - h},
                                 SPEED, K, n_angles=12)[0]) / (2 * h)
    assert grad["c"] == pytest.approx(fd, rel=1e-5)
    assert abs(grad["c"]) > 0  # the cluster term matters


# --- synthesis ---------------------------------------------------------------------------

def test_synthesis_moves_frequencies_out_of_the_bands():
    before = resonance_margin(build({"J": 0.05, "c": 2e5}), SPEED, K)
    assert before.value < 0  # f1 ≈ 67 Hz inside band 3 (60-75 Hz)
    res = synthesise(build, PARAMS, SPEED, K, margin=0.05, starts=4, n_angles=36)
    assert res.margin_before.value < 0
    assert res.feasible
    assert res.margin_after.value >= 0.05
    assert res.margin_check.value >= 0.05 - 1e-3  # between samples: 4x finer grid
    assert res.before == {"J": 0.05, "c": 2e5}
    assert 0.02 <= res.after["J"] <= 0.2
    assert 1e5 <= res.after["c"] <= 4e5
    assert res.builds > res.evaluations > 0
    assert len(res.starts) == 4
    # closest design: margin not far above the requirement (ρ sharpened to 16 × 200)
    assert res.margin_after.value < 0.07
    assert res.bands_after.freq_hz.shape == (36, build(res.after).n)


def test_infeasible_case_is_reported():
    # the shaft diameter hardly moves f1 (set by the coupling): no design meets 5 %
    def by_diameter(v):
        return chain(follower_unit(CAM, 1e-3, 0.5, 2e5), 5, 0.2, v["d"],
                     left=End.elastic(1e4, 0.05), phases=np.arange(5) * TWO_PI / 5)
    res = synthesise(by_diameter, [Parameter("d", 0.025, 0.04, 0.03)], SPEED, K,
                     margin=0.05, starts=3, n_angles=24)
    assert not res.feasible
    assert res.margin_after.value < 0.05
    assert res.margin_after.value >= res.margin_before.value  # the best found is kept
    assert all(not s.feasible for s in res.starts)
    assert "CANNOT" in res.summary()


def test_discrete_choice_is_enumerated():
    params = [Parameter.choice("c", (2e5, 3e5), start=2e5),
              Parameter("J", 0.05, 0.05), Parameter("m", 0.5, 0.5)]
    res = synthesise(build, params, SPEED, K, margin=0.0, n_angles=12)
    assert [s.stage for s in res.starts] == ["fixed", "fixed"]
    margins = [resonance_margin(build({"J": 0.05, "c": c}), SPEED, K, n_angles=12).value
               for c in (2e5, 3e5)]
    assert res.after["c"] == (2e5, 3e5)[int(np.argmax(margins))]


def test_parameter_errors():
    with pytest.raises(ValueError, match="'d'.*lower <= upper"):
        Parameter("d", 2.0, 1.0)
    with pytest.raises(ValueError, match="outside"):
        Parameter("d", 1.0, 2.0, start=3.0)
    with pytest.raises(ValueError, match="log scale"):
        Parameter("c", 0.0, 1.0, log=True)
    with pytest.raises(ValueError, match="unique"):
        synthesise(build, [PARAMS[0], PARAMS[0]], SPEED, K)
    with pytest.raises(ValueError, match="method"):
        synthesise(build, PARAMS, SPEED, K, method="best")
