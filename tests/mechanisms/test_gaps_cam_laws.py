"""Cam laws by name, rise–dwell–return programmes in degrees, their
breakpoints, and speed ramps shaped by any law.

Reference peak values (unit rise over unit angle, s' = C_v, max |s''| = C_a, max |s'''|
= C_j): R. L. Norton, *Cam Design and Manufacturing Handbook*, 2nd ed., Industrial
Press 2009, Table 3-3 (also Rothbart, *Cam Design Handbook*, McGraw-Hill 2004, ch. 2):

    law                 C_v      C_a     C_j
    cycloidal           2.000    6.283   39.48
    modified sine       1.760    5.528   69.47
    modified trapezoid  2.000    4.888   61.43
    3-4-5 polynomial    1.875    5.774   60.00
    4-5-6-7 polynomial  2.188    7.513   52.50
    harmonic            π/2      π²/2    (∞ at a dwell: π³/2 inside)
"""

import numpy as np
import pytest
import sympy
from numpy.testing import assert_allclose
from scipy.integrate import cumulative_trapezoid, quad

from femmech.analysis.response import SpeedRamp
from femmech.mechanisms import CamProfile, cam_program, motion_law, polynomial_4567
from femmech.mechanisms.motion_laws import LAWS

# name: (C_v, C_a, C_j, source precision): exact closed forms where the law has one,
# otherwise the handbook's 3 to 4 significant digits (rtol 1e-3 covers their rounding)
PEAKS = {
    "cycloidal": (2.0, 2 * np.pi, 4 * np.pi**2, 1e-9),
    "harmonic": (np.pi / 2, np.pi**2 / 2, np.pi**3 / 2, 1e-9),
    "modified_sine": (1.76, 5.53, 69.5, 3e-3),
    "modified_trapezoid": (2.0, 4.89, 61.4, 1e-3),
    "polynomial_345": (1.875, 10 / np.sqrt(3), 60.0, 1e-9),
    "polynomial_4567": (2.1875, 7.51, 52.5, 1e-3),
}
CONTINUITY = {"harmonic": 1, "cycloidal": 2, "modified_sine": 2, "modified_trapezoid": 2,
              "polynomial_345": 2, "polynomial_4567": 3}
Z = np.linspace(0.0, 1.0, 400_001)  # peak on the grid within (Δz)² s'''' ~ 1e-9 relative


@pytest.mark.parametrize("name", sorted(LAWS))
def test_law_ends_and_peak_values(name):
    law = motion_law(name)
    s, s1, s2, s3 = law.evaluate(Z)
    # bound: closed-form law at z = 0: exact to a few eps
    assert s[0] == pytest.approx(0.0, abs=1e-15)
    assert s[-1] == pytest.approx(1.0, abs=1e-14)
    cv, ca, cj, rtol = PEAKS[name]
    assert_allclose(s1.max(), cv, rtol=rtol)
    assert_allclose(np.abs(s2).max(), ca, rtol=rtol)
    assert_allclose(np.abs(s3).max(), cj, rtol=max(rtol, 1e-8))
    # symmetric laws: s'(z) = s'(1 - z), peak velocity at mid-rise
    # bound: symmetric law evaluated at z and 1 - z: round-off ~10 eps of the peak
    assert_allclose(s1, s1[::-1], atol=1e-12 * cv)
    assert_allclose(s1[Z.size // 2], cv, rtol=rtol)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_continuity_order_at_a_dwell_and_inside(name):
    law = motion_law(name)
    k = CONTINUITY[name]
    assert law.continuity == k
    ends = np.array(law.evaluate(np.array([0.0, 1.0])))  # (4, 2): s..s''' at both ends
    # bound: derivatives vanish at the ends by construction: ~10 eps of O(1) coefficients
    assert_allclose(ends[1:k + 1], 0.0, atol=1e-12)  # s', ..., s^(k) meet the dwell
    if k < 3:
        assert np.abs(ends[k + 1]).min() > 1.0  # s^(k+1) jumps against the dwell
    for j in law.joints():  # inside piecewise laws s, s', s'' are continuous
        left, right = (np.array(law.evaluate(np.array([j + d]))) for d in (-1e-10, 0.0))
        assert_allclose(left[:3], right[:3], atol=1e-8)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_integral_of_the_law(name):
    law = motion_law(name)
    for z in (0.1, 0.3, 0.55, 0.9, 1.0):
        expected, _ = quad(lambda u: float(law.evaluate(u)[0]), 0.0, z, epsabs=1e-14,
                           points=[j for j in law.joints() if j < z] or None)
        # bound: quad to epsabs 1e-14 against the closed-form integral
        assert_allclose(law.integral(z), expected, rtol=1e-12, atol=1e-15)


def test_4567_polynomial_from_its_boundary_conditions():
    # degree 7, s(0) = 0, s(1) = 1, s' = s'' = s''' = 0 at both ends: unique (sympy)
    z = sympy.Symbol("z")
    a = sympy.symbols("a0:8")
    s = sum(ai * z**i for i, ai in enumerate(a))
    eqs = [s.subs(z, 0), s.subs(z, 1) - 1]
    eqs += [sympy.diff(s, z, k).subs(z, x) for k in (1, 2, 3) for x in (0, 1)]
    solution = sympy.solve(eqs, a)
    assert tuple(float(solution[ai]) for ai in a) == polynomial_4567().coefficients
    # its jerk peak is at mid-rise: |s'''(1/2)| = 105/2
    jerk = sympy.diff(s.subs(solution), z, 3)
    assert jerk.subs(z, sympy.Rational(1, 2)) == -sympy.Rational(105, 2)


def test_program_levels_and_breakpoints():
    cam = cam_program(0.03, rise=100, dwell_top=80, return_=120, dwell_bottom=60,
                      law="modified_trapezoid", return_law="3-4-5", start=20, base=0.01)
    d = np.deg2rad
    # bound: closed-form cam at its dwells: exact to a few eps of 0.04
    assert_allclose(cam(d([20, 120, 150, 200, 320, 350, 380])),
                    [0.01, 0.04, 0.04, 0.04, 0.01, 0.01, 0.01], atol=1e-15)
    expected = [20 + 100 * f for f in (0, 1 / 8, 3 / 8, 5 / 8, 7 / 8)] + [120, 200, 320]
    # bound: breakpoints are sums of degrees converted to radians and back: ~10 eps of 400
    assert_allclose(np.rad2deg(cam.breakpoints()), sorted(expected), atol=1e-12)
    assert cam == CamProfile.from_program(0.03, 100, 80, 120, 60, "modified_trapezoid",
                                          "polynomial_345", 20, 0.01)


def test_program_is_continuous_to_the_laws_order_at_its_joints():
    for name, k in CONTINUITY.items():
        cam = cam_program(0.02, rise=90, dwell_top=90, return_=90, dwell_bottom=90, law=name)
        scale = 0.02 / np.deg2rad(90) ** np.arange(4)  # stroke / β^k: size of U^(k)
        for phi in cam.breakpoints():
            left = np.array(cam.derivatives(phi - 1e-9))
            right = np.array(cam.derivatives(phi))
            assert_allclose(left[:k + 1], right[:k + 1], atol=1e-6 * scale[:k + 1].max()), name


def test_zero_dwells_are_left_out():
    cam = cam_program(0.01, rise=180, dwell_top=0, return_=180, law="cycloidal")
    assert len(cam.segments) == 2
    assert_allclose(np.rad2deg(cam.breakpoints()), [0.0, 180.0])


def test_program_errors_name_the_problem():
    with pytest.raises(ValueError, match="sum.*370.*not 360"):
        cam_program(0.01, rise=100, dwell_top=90, return_=90, dwell_bottom=90)
    with pytest.raises(ValueError, match="dwell_top must be a finite angle >= 0"):
        cam_program(0.01, rise=180, dwell_top=-10, return_=100, dwell_bottom=90)
    with pytest.raises(ValueError, match="return_ must be > 0"):
        cam_program(0.01, rise=180, dwell_top=90, return_=0, dwell_bottom=90)
    with pytest.raises(ValueError, match="stroke must be finite and non-zero"):
        cam_program(0.0, rise=90, dwell_top=90, return_=90, dwell_bottom=90)
    with pytest.raises(ValueError, match="unknown motion law 'cubic'; known laws: cycloidal,"
                                         " harmonic, modified_sine, modified_trapezoid,"
                                         " polynomial_345, polynomial_4567"):
        cam_program(0.01, rise=90, dwell_top=90, return_=90, dwell_bottom=90, law="cubic")


# --- speed ramps ------------------------------------------------------------------------

def test_default_ramp_is_unchanged():
    # the cycloidal ramp as it was before the law option, written out (bit for bit)
    t = np.linspace(-0.2, 2.5, 1001)
    ramp = SpeedRamp(5.0, 30.0, 1.5, t_start=0.3, phi0=0.7)
    tau = np.clip((t - 0.3) / 1.5, 0.0, 1.0)
    s = tau - np.sin(2 * np.pi * tau) / (2 * np.pi)
    angle = 1.5 * (tau**2 / 2 + (np.cos(2 * np.pi * tau) - 1) / (4 * np.pi**2))
    phi = 0.7 + 5.0 * t + 25.0 * (angle + np.clip(t - 0.3 - 1.5, 0.0, None))
    Omega_dot = 25.0 / 1.5 * (1 - np.cos(2 * np.pi * tau)) * ((tau > 0) & (tau < 1))
    got = ramp(t)
    for a, b in zip(got, (phi, 5.0 + 25.0 * s, Omega_dot), strict=True):
        assert np.array_equal(a, b)
    # bound: the same law evaluated by another call path: a few eps
    assert_allclose(SpeedRamp(5.0, 30.0, 1.5, 0.3, 0.7, law=motion_law("cycloidal"))(t), got,
                    rtol=1e-14, atol=1e-12)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_ramp_with_any_law_is_consistent(name):
    # φ' = Ω and Ω' = Ω̇ (trapezoidal integration on 2e5 steps: error ~ h² Ω''' ~ 1e-9),
    # end speeds, and the peak acceleration ΔΩ C_v / duration
    t = np.linspace(0.0, 2.0, 200_001)
    ramp = SpeedRamp(10.0, 40.0, 1.2, t_start=0.4, phi0=0.3, law=name)
    phi, Omega, Omega_dot = ramp(t)
    assert_allclose(phi - phi[0], cumulative_trapezoid(Omega, t, initial=0.0), atol=1e-7)
    assert_allclose(Omega - Omega[0], cumulative_trapezoid(Omega_dot, t, initial=0.0),
                    atol=1e-6)
    assert Omega[0] == 10.0
    # bound: ramp end value from closed form: a few eps of 40
    assert Omega[-1] == pytest.approx(40.0, abs=1e-12)
    assert_allclose(Omega_dot.max(), 30.0 / 1.2 * PEAKS[name][0],
                    rtol=max(PEAKS[name][3], 1e-6))
    joints = motion_law(name).joints()
    assert_allclose(ramp.breakpoints(), 0.4 + 1.2 * np.concatenate([[0.0], joints, [1.0]]))


def test_ramp_rejects_an_unknown_law():
    with pytest.raises(ValueError, match="unknown motion law 'linear'"):
        SpeedRamp(0.0, 10.0, 1.0, law="linear")
