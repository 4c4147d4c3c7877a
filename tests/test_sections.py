"""Section constructors and materials against handbook values, and their input errors.

Handbooks: Roark's Formulas for Stress and Strain (Young & Budynas, 7th ed., table 10.7,
torsion constants K); Timoshenko & Goodier, Theory of Elasticity (3rd ed., §109, table of
k₁ for rectangles, 3 significant digits). Areas and second moments are checked against
independent composite-area sums (parallel-axis theorem).
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

import femmech as fm
from femmech.fe import sections

EPS = np.finfo(float).eps
RTOL = 10 * EPS  # closed-form expressions: round-off


def test_rectangle_area_and_moments():
    s = sections.rectangle(0.03, 0.08)  # width along y, height along z
    assert_allclose([s.A, s.Iy, s.Iz], [0.03 * 0.08, 0.03 * 0.08**3 / 12, 0.08 * 0.03**3 / 12],
                    rtol=RTOL)
    # Cowper (1966): k = 10 (1 + ν) / (12 + 11 ν) = 0.8497 for ν = 0.3
    assert_allclose(s.Asy / s.A, 13.0 / 15.3, rtol=RTOL)


def test_square_torsion_constant_roark():
    # Roark table 10.7, square of side 2a: K = 2.25 a⁴ = 0.1406 (2a)⁴; the exact series value
    # is 0.14058 (Timoshenko & Goodier), so Roark's 3 digits agree to 0.1 %
    a = 0.05
    assert_allclose(sections.rectangle(a, a).J, 0.1406 * a**4, rtol=1e-3)


@pytest.mark.parametrize(("ratio", "k1"), [
    (1.0, 0.141), (1.5, 0.196), (2.0, 0.229), (3.0, 0.263), (5.0, 0.291), (10.0, 0.312),
])
def test_rectangle_torsion_constant_timoshenko_table(ratio, k1):
    # J = k₁ a b³ with a >= b (Timoshenko & Goodier §109); table has 3 digits: ±0.0005 / k₁
    b = 0.02
    J = sections.rectangle(ratio * b, b).J
    assert_allclose(J, k1 * ratio * b * b**3, rtol=0.0005 / k1 + 1e-4)
    # symmetric in the two sides
    assert_allclose(sections.rectangle(b, ratio * b).J, J, rtol=RTOL)


def test_rectangle_torsion_constant_roark_formula():
    # Roark table 10.7 case 4 (a, b half sides, a >= b):
    # K = a b³ [16/3 - 3.36 (b/a)(1 - b⁴ / (12 a⁴))], an approximation of the series:
    # it departs from the series by at most 0.4 % (at a/b = 1.25; 0.09 % at a/b = 2)
    for a, b in ((0.06, 0.02), (0.05, 0.025), (0.1, 0.01), (0.05, 0.05), (0.05, 0.04)):
        K = a * b**3 * (16 / 3 - 3.36 * (b / a) * (1 - b**4 / (12 * a**4)))
        assert_allclose(sections.rectangle(2 * a, 2 * b).J, K, rtol=5e-3)


def test_circle_exact():
    d = 0.05
    s = sections.circle(d)
    # A = π d²/4, I = π d⁴/64, J = π d⁴/32 (Roark table 10.7 case 1)
    assert_allclose([s.A, s.Iy, s.Iz, s.J, s.polar_moment],
                    [np.pi * d**2 / 4, np.pi * d**4 / 64, np.pi * d**4 / 64, np.pi * d**4 / 32,
                     np.pi * d**4 / 32], rtol=RTOL)
    assert s.shape == "circle"


def test_tube_exact_and_thin_walled():
    do, di = 0.10, 0.096
    s = sections.tube(do, di)
    ro, ri = do / 2, di / 2
    # Roark table 10.7 case 10: K = π/2 (ro⁴ - ri⁴)
    assert_allclose(s.J, np.pi / 2 * (ro**4 - ri**4), rtol=RTOL)
    assert_allclose(s.A, np.pi * (ro**2 - ri**2), rtol=RTOL)
    # thin-walled: J ≈ 2 π r³ t with r the mean radius; exact = 2π r³ t (1 + (t / 2r)²)
    r, t = (ro + ri) / 2, ro - ri
    assert_allclose(s.J, 2 * np.pi * r**3 * t, rtol=1.01 * (t / (2 * r)) ** 2)
    assert s.J > 2 * np.pi * r**3 * t
    # Cowper (1966) thin-walled tube limit k → 2(1 + ν)/(4 + 3ν) = 0.531 for ν = 0.3
    assert_allclose(s.Asy / s.A, 2.6 / 4.9, rtol=2e-3)


def test_i_section_composite_areas_and_open_section_torsion():
    h, b, tw, tf = 0.30, 0.15, 0.0071, 0.0107  # IPE 300 without root fillets
    s = sections.i_section(h, b, tw, tf)
    hw = h - 2 * tf
    # composite: two flanges (b x tf at ±(h - tf)/2) + web (tw x hw), parallel-axis theorem
    A = 2 * b * tf + hw * tw
    Iy = 2 * (b * tf**3 / 12 + b * tf * ((h - tf) / 2) ** 2) + tw * hw**3 / 12
    Iz = 2 * tf * b**3 / 12 + hw * tw**3 / 12
    # bound: closed-form section properties: a few eps
    assert_allclose([s.A, s.Iy, s.Iz], [A, Iy, Iz], rtol=1e-12)
    # catalogue IPE 300: A = 53.8 cm² including 4 fillets of r = 15 mm, (4 - π) r² = 1.93 cm²
    assert_allclose(s.A + (4 - np.pi) * 0.015**2, 53.8e-4, rtol=1e-3)
    # thin-walled open section: K = Σ L t³ / 3 over centre-line lengths (Roark table 10.7,
    # I-beam without fillets: flanges b, web h - tf between flange mid-planes)
    assert_allclose(s.J, (2 * b * tf**3 + (h - tf) * tw**3) / 3, rtol=RTOL)


def test_rectangular_hollow_bredt():
    b, h, t = 0.12, 0.08, 0.005
    s = sections.rectangular_hollow(b, h, t)
    assert_allclose(s.A, b * h - (b - 2 * t) * (h - 2 * t), rtol=RTOL)
    assert_allclose(s.Iy, (b * h**3 - (b - 2 * t) * (h - 2 * t) ** 3) / 12, rtol=RTOL)
    assert_allclose(s.Iz, (h * b**3 - (h - 2 * t) * (b - 2 * t) ** 3) / 12, rtol=RTOL)
    # Bredt: K = 4 Aₘ² / ∮ ds / t, Aₘ the area enclosed by the wall centre line
    # (Roark table 10.7 case 16 with equal walls)
    Am = (b - t) * (h - t)
    assert_allclose(s.J, 4 * Am**2 * t / (2 * (b - t) + 2 * (h - t)), rtol=RTOL)


def test_general_section_keeps_given_values():
    s = sections.general(A=1e-3, Iy=2e-7, Iz=3e-7, J=1e-7)
    assert (s.A, s.Iy, s.Iz, s.J, s.Asy, s.Asz) == (1e-3, 2e-7, 3e-7, 1e-7, None, None)
    assert s.polar_moment == 5e-7  # Iy + Iz when Ip is not given


@pytest.mark.parametrize(("make", "match"), [
    (lambda: sections.rectangle(-0.01, 0.02), "rectangle: width must be positive"),
    (lambda: sections.rectangle(0.01, np.nan), "rectangle: height must be positive"),
    (lambda: sections.rectangle(0.01, 0.02, nu=0.7), r"rectangle: nu must lie in \(-1, 0.5\)"),
    (lambda: sections.circle(0.0), "circle: diameter must be positive"),
    (lambda: sections.circle(0.02, nu=-1.0), "circle: nu must lie in"),
    (lambda: sections.tube(0.05, 0.06), r"tube: inner_diameter must lie in \[0, outer_diam"),
    (lambda: sections.tube(0.05, -0.01), "tube: inner_diameter must lie in"),
    (lambda: sections.tube(np.inf, 0.01), "tube: outer_diameter must be positive and finite"),
    (lambda: sections.i_section(0.1, 0.05, 0.005, 0.06), "I: need 2.flange < height"),
    (lambda: sections.i_section(0.1, 0.05, 0.06, 0.01), "I: need .* web < width"),
    (lambda: sections.i_section(0.1, 0.05, -0.005, 0.01), "I: web must be positive"),
    (lambda: sections.rectangular_hollow(0.1, 0.05, 0.03), "box: wall must be less than half"),
    (lambda: sections.rectangular_hollow(0.1, 0.05, 0.0), "box: wall must be positive"),
    (lambda: sections.general(A=0.0, Iy=1.0, Iz=1.0, J=1.0), "section 'general': A must be"),
    (lambda: sections.general(A=1.0, Iy=1.0, Iz=-1.0, J=1.0), "'general': Iz must be"),
    (lambda: sections.general(A=1.0, Iy=1.0, Iz=1.0, J=1.0, Asy=0.0), "'general': Asy must"),
    (lambda: sections.general(A=1.0, Iy=1.0, Iz=1.0, J=1.0, Ip=np.nan), "'general': Ip must"),
])
def test_section_errors_name_the_parameter(make, match):
    with pytest.raises(ValueError, match=match):
        make()


def test_material_shear_modulus():
    assert_allclose(fm.Material(E=210e9, nu=0.3, rho=7850).shear_modulus, 210e9 / 2.6,
                    rtol=RTOL)  # G = E / 2(1 + ν)
    m = fm.Material(E=200e9, G=80e9, rho=7850)
    assert_allclose(m.poisson_ratio, 0.25, rtol=RTOL)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"E": 0.0, "nu": 0.3, "rho": 1.0}, "material 'steel': E must be positive"),
    ({"E": -1.0, "nu": 0.3, "rho": 1.0}, "E must be positive"),
    ({"E": np.inf, "nu": 0.3, "rho": 1.0}, "E must be positive and finite"),
    ({"E": 1.0, "nu": 0.5, "rho": 1.0}, r"nu must lie in \(-1, 0.5\), got 0.5"),
    ({"E": 1.0, "nu": -1.0, "rho": 1.0}, r"nu must lie in \(-1, 0.5\)"),
    ({"E": 1.0, "nu": 0.3, "G": 0.4, "rho": 1.0}, "give exactly one of nu and G"),
    ({"E": 1.0, "rho": 1.0}, "give exactly one of nu and G"),
    ({"E": 1.0, "G": 0.0, "rho": 1.0}, "G must be positive"),
    ({"E": 1.0, "nu": 0.3, "rho": -1.0}, "rho must be non-negative"),
])
def test_material_errors_name_the_parameter(kwargs, match):
    with pytest.raises(ValueError, match=match):
        fm.Material(**kwargs, name="steel")
