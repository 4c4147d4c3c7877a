"""Tests of motion laws, cam programmes, linkages and tabulated position functions."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from femmech.mechanisms import (
    CamProfile,
    CamSegment,
    FourBar,
    PositionFunction,
    SliderCrank,
    TabulatedPositionFunction,
    cycloidal,
    harmonic,
    modified_sine,
    modified_trapezoid,
    polynomial_345,
)

EPS = np.finfo(float).eps
LAWS = [harmonic(), cycloidal(), modified_sine(), modified_trapezoid(), polynomial_345()]
LAW_IDS = [law.name for law in LAWS]

# Peak |s'|, |s''|, |s'''| of the normalised double-dwell laws: Norton, Cam Design and
# Manufacturing Handbook (2009), Table 3-3; harmonic π/2, π²/2, π³/2; cycloidal 2, 2π, 4π²;
# 3-4-5: 15/8, 10/√3, 60 (analytic maxima of the polynomial's derivatives).
PEAKS = {
    "harmonic": (np.pi / 2, np.pi**2 / 2, np.pi**3 / 2),
    "cycloidal": (2.0, 2 * np.pi, 4 * np.pi**2),
    "modified sine": (1.760, 5.528, 69.47),
    "modified trapezoid": (2.000, 4.888, 61.43),
    "3-4-5 polynomial": (1.875, 10 / np.sqrt(3), 60.0),
}


def _fd(values, h):
    """Central differences (truncation error h² f'''/6) on an evenly spaced grid."""
    return (values[2:] - values[:-2]) / (2 * h)


@pytest.mark.parametrize("law", LAWS, ids=LAW_IDS)
def test_law_end_conditions_and_peaks(law):
    s, s1, s2, s3 = law.evaluate(np.array([0.0, 1.0]))
    # double-dwell conditions s(0) = 0, s(1) = 1, s'(0) = s'(1) = 0; round-off ~ 10 eps
    assert_allclose(s, [0.0, 1.0], atol=10 * EPS)
    assert_allclose(s1, [0.0, 0.0], atol=10 * EPS)
    z = np.linspace(0.0, 1.0, 400001)
    peaks = [np.max(np.abs(d)) for d in law.evaluate(z)[1:]]
    # published values have 4 significant digits -> rtol 5e-4; grid 2.5e-6 resolves the peak
    assert_allclose(peaks, PEAKS[law.name], rtol=5e-4)


@pytest.mark.parametrize("law", LAWS, ids=LAW_IDS)
def test_law_derivatives_match_finite_differences(law):
    h = 1e-4
    z = np.arange(0.0, 1.0 + h / 2, h)
    d = law.evaluate(z)
    breaks = np.asarray(getattr(law, "starts", (0.0,)))
    # points within 2h of a piece boundary see the jump of a higher derivative
    keep = np.min(np.abs(z[1:-1, None] - breaks[None, :]), axis=1) > 2 * h
    for k in range(3):
        # central-difference truncation h²/6 max|s^(k+3)|, with max|s'''| <= 70 (Norton's
        # Table 3-3) and each further derivative at most a factor ω <= 4π larger; plus
        # round-off eps max|s^(k)|/h
        tol = h**2 / 6 * 70 * (4 * np.pi) ** k + 100 * EPS * np.max(np.abs(d[k])) / h
        assert np.max(np.abs(_fd(d[k], h) - d[k + 1][1:-1])[keep]) < tol


@pytest.mark.parametrize("law", LAWS, ids=LAW_IDS)
def test_law_continuity_class_at_dwell(law):
    # At a joint with a dwell all derivatives of the dwell vanish, so the jump of s^(k)
    # is its end value. Published classes (Norton 2009, ch. 3): harmonic jumps in
    # acceleration; cycloidal, modified sine/trapezoid, 3-4-5 in jerk only (finite).
    ends = np.array([0.0, 1.0])
    _, s1, s2, s3 = law.evaluate(ends)
    assert_allclose(s1, 0.0, atol=10 * EPS)
    if law.continuity >= 2:
        assert_allclose(s2, 0.0, atol=100 * EPS)
        assert np.all(np.abs(s3) > 1.0)
        assert np.all(np.isfinite(s3))
    else:
        assert np.all(np.abs(s2) > 1.0)
    assert law.continuity == (1 if law.name == "harmonic" else 2)


def _cam(law, h=0.02):
    """Rise 100°, dwell 80°, return 120°, dwell 60° (lift h, m)."""
    d = np.deg2rad
    return CamProfile((CamSegment(d(100), h, law), CamSegment(d(80)),
                       CamSegment(d(120), -h, law), CamSegment(d(60))), phi_start=0.3)


@pytest.mark.parametrize("law", LAWS, ids=LAW_IDS)
def test_cam_profile_periodic_and_jumps(law):
    cam = _cam(law)
    assert isinstance(cam, PositionFunction)
    phi = np.linspace(-7.0, 7.0, 301)
    for a, b in zip(cam.derivatives(phi), cam.derivatives(phi + 2 * np.pi), strict=True):
        # U(φ + 2π) = U(φ): only the mod-2π reduction rounds, ~ 1e3 eps in the angle
        assert_allclose(a, b, atol=1e3 * EPS * np.max(np.abs(a) + 1.0))
    joints = 0.3 + np.deg2rad([0.0, 100.0, 180.0, 300.0])
    delta = 1e-7
    left, right = cam.derivatives(joints - delta), cam.derivatives(joints + delta)
    beta = np.deg2rad([60.0, 100.0, 80.0, 120.0])  # segment before each joint
    # jump of U^(k) across a joint is O(delta * max|U^(k+1)|) if U^(k) is continuous
    bound = [delta * 0.02 * PEAKS[law.name][k] / np.min(beta) ** (k + 1) * 2 for k in range(3)]
    for k in range(law.continuity + 1):
        # bound: round-off allowance on an O(1) jump bound: a few eps
        assert np.all(np.abs(right[k] - left[k]) < bound[k] + 1e-15)
    jump = np.abs(right[law.continuity + 1] - left[law.continuity + 1])
    assert np.all(jump > 1e3 * bound[law.continuity])  # a true (finite) jump


def test_cam_profile_derivatives_match_finite_differences():
    cam = _cam(modified_sine())
    h = 1e-5
    phi = np.arange(0.0, 2 * np.pi, h)
    d = cam.derivatives(phi)
    # segment joints, and the modified-sine piece joints at z = 1/8, 7/8 where U'''' jumps
    joints = np.mod(0.3 + np.deg2rad([0.0, 12.5, 87.5, 100.0, 180.0, 195.0, 285.0, 300.0]),
                    2 * np.pi)
    keep = np.min(np.abs(phi[1:-1, None] - joints[None, :]), axis=1) > 3 * h
    for k in range(3):
        scale = np.max(np.abs(d[k + 1]))
        err = np.max(np.abs(_fd(d[k], h) - d[k + 1][1:-1])[keep]) / scale
        assert err < 1e-6  # h²/6 (4π/β)² ~ 3e-9, plus round-off eps U/(h U') ~ 1e-10


def test_cam_profile_values():
    cam = CamProfile((CamSegment(np.pi, 0.01, cycloidal()), CamSegment(np.pi, -0.01,
                      cycloidal())))
    # cycloidal law at z = 1/2 is s = 1/2, s' = 2 (analytic), U' = h s'/β
    assert_allclose(cam(np.pi / 2), 0.005, rtol=10 * EPS)
    assert_allclose(cam(np.pi / 2, order=1), 0.01 * 2 / np.pi, rtol=10 * EPS)
    assert_allclose(cam(np.pi), 0.01, rtol=10 * EPS)


@pytest.mark.parametrize(
    ("segments", "match"),
    [
        ((CamSegment(np.pi, 0.01, cycloidal()), CamSegment(np.pi / 2, -0.01, cycloidal())),
         "beta sum"),
        ((CamSegment(np.pi, 0.01, cycloidal()), CamSegment(np.pi, -0.02, cycloidal())),
         "not be periodic"),
        ((CamSegment(2 * np.pi, 0.0), CamSegment(0.0)), "segment 1: beta"),
        ((CamSegment(np.pi, 0.01), CamSegment(np.pi, -0.01, cycloidal())), "segment 0: lift"),
        ((), "at least one"),
    ],
)
def test_cam_profile_bad_input(segments, match):
    with pytest.raises(ValueError, match=match):
        CamProfile(segments)


LINKAGES = [
    SliderCrank(0.1, 0.35, 0.02),
    FourBar(1.0, 3.0, 2.5, 3.2),
    FourBar(1.0, 3.0, 2.5, 3.2, branch=-1, output="coupler"),
    FourBar(3.2, 3.0, 2.5, 1.0),  # double crank: output turns fully
]


@pytest.mark.parametrize("pf", LINKAGES, ids=["slider-crank", "crank-rocker", "coupler", "drag"])
def test_linkage_derivatives_match_finite_differences(pf):
    h = 1e-4
    phi = np.arange(-1.0, 2 * np.pi + 1.0, h)
    d = pf.derivatives(phi)
    for k in range(3):
        err = np.max(np.abs(_fd(d[k], h) - d[k + 1][1:-1])) / np.max(np.abs(d[k + 1]))
        # relative truncation error h²/6 * max|U^(k+3)|/max|U^(k+1)| ~ 1e-8 * O(10)
        assert err < 1e-6


def test_slider_crank_closed_form():
    # centric slider-crank (e = 0): stroke 2r, x(0) = r + l, x(π) = l − r; U'(0) = 0,
    # U''(0) = −r(1 + r/l) (Dresig & Holzweißig, ch. 2, exact at dead centre)
    r, l = 0.1, 0.35
    sc = SliderCrank(r, l)
    assert_allclose(sc(np.array([0.0, np.pi])), [r + l, l - r], rtol=10 * EPS)
    assert_allclose(sc(0.0, order=1), 0.0, atol=10 * EPS)
    assert_allclose(sc(0.0, order=2), -r * (1 + r / l), rtol=10 * EPS)


def test_four_bar_closure_and_periodicity():
    fb = FourBar(1.0, 3.0, 2.5, 3.2)
    phi = np.linspace(0, 2 * np.pi, 97)
    theta, psi = fb.angles(phi)
    loop = fb.a * np.exp(1j * phi) + fb.b * np.exp(1j * theta) - fb.c * np.exp(1j * psi) - fb.d
    assert_allclose(np.abs(loop), 0.0, atol=10 * EPS * fb.d)  # closure to round-off
    for a, b in zip(fb.derivatives(phi), fb.derivatives(phi + 2 * np.pi), strict=True):
        assert_allclose(a, b, atol=1e3 * EPS)


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: SliderCrank(0.1, 0.11, 0.02), "coupler length"),
        (lambda: SliderCrank(-0.1, 0.3), "crank radius"),
        (lambda: FourBar(1.0, 1.5, 2.5, 3.2), "dead centre"),  # b + c < d + a: crank stops
        (lambda: FourBar(1.0, 3.0, 2.5, 3.2, branch=0), "branch"),
        (lambda: FourBar(1.0, 3.0, 0.0, 3.2), "link length c"),
    ],
)
def test_linkage_bad_geometry(make, match):
    with pytest.raises(ValueError, match=match):
        make()


def test_position_function_bad_order_and_angles():
    sc = SliderCrank(0.1, 0.35)
    with pytest.raises(ValueError, match="order"):
        sc(0.0, order=4)
    with pytest.raises(ValueError, match="NaN"):
        sc(np.array([0.0, np.nan]))


def test_tabulated_convergence_rate_of_third_derivative():
    # Quintic spline: error of the k-th derivative is O(h^(6-k)) (de Boor 2001, ch. XII),
    # so U''' converges at order 3. Reference: the exact slider-crank derivatives.
    exact = SliderCrank(0.1, 0.3)
    x = np.linspace(0.0, 2 * np.pi, 1001)
    sizes = np.array([32, 64, 128])
    errors = []
    for n in sizes:
        p = np.linspace(0.0, 2 * np.pi, n + 1)
        f = TabulatedPositionFunction(p, exact(p))
        errors.append(np.max(np.abs(f(x, order=3) - exact(x, order=3))))
    rate = -np.polyfit(np.log(sizes), np.log(errors), 1)[0]
    assert 2.8 < rate < 3.5


def test_tabulated_is_periodic_with_continuous_third_derivative():
    p = np.linspace(0.0, 2 * np.pi, 41)
    f = TabulatedPositionFunction(p, 0.01 * np.sin(p) + 0.003 * np.cos(3 * p))
    phi = np.linspace(-3.0, 3.0, 61)
    for a, b in zip(f.derivatives(phi), f.derivatives(phi + 2 * np.pi), strict=True):
        assert_allclose(a, b, atol=1e4 * EPS * 0.1)
    # U''' is continuous (C⁴ spline) across the knots and the period seam: jump over
    # 2δ is O(δ max|U''''|) ~ 1e-9 * 0.3
    knots = np.concatenate([p, [0.0]])
    left, right = f(knots - 1e-9, order=3), f(knots + 1e-9, order=3)
    assert np.max(np.abs(right - left)) < 1e-8
    # its own derivatives agree with central differences (h = 1e-4, h² U^(5)/6 ~ 1e-9)
    h = 1e-4
    g = np.arange(0.0, 2 * np.pi, h)
    d = f.derivatives(g)
    for k in range(3):
        assert np.max(np.abs(_fd(d[k], h) - d[k + 1][1:-1])) < 1e-7


def test_tabulated_increment():
    p = np.linspace(0.0, 2 * np.pi, 129)
    f = TabulatedPositionFunction(p, p + 0.1 * np.sin(p), increment=2 * np.pi)
    x = np.linspace(-1.0, 8.0, 50)
    # bound: periodic spline of 129 points: interpolation error ~h⁴ f'''' = 6e-10
    assert_allclose(f(x), x + 0.1 * np.sin(x), atol=1e-9)  # spline error O(h^6) ~ 1e-10
    assert_allclose(f(x, order=1), 1 + 0.1 * np.cos(x), atol=1e-8)


@pytest.mark.parametrize(
    ("phi", "U", "match"),
    [
        (np.linspace(0, 2 * np.pi, 20), np.sin(np.linspace(0, 2 * np.pi, 20)) + 0.1 *
         np.linspace(0, 1, 20), "not periodic"),
        (np.linspace(0, 6.0, 20), np.zeros(20), "span one revolution"),
        (np.r_[0.0, 0.0, np.linspace(0.5, 2 * np.pi, 18)], np.zeros(20), "strictly increasing"),
        (np.linspace(0, 2 * np.pi, 5), np.zeros(5), "at least 7"),
    ],
)
def test_tabulated_bad_input(phi, U, match):
    with pytest.raises(ValueError, match=match):
        TabulatedPositionFunction(phi, U)
