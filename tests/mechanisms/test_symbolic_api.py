"""The general mechanism description: validation, shapes, several drives, caching."""

import numpy as np
import pytest
import sympy
from numpy.testing import assert_allclose

from femmech.mechanisms import (
    Damper,
    Load,
    Mechanism,
    PointMass,
    RotaryInertia,
    SliderCrank,
    Spring,
    lagrange_terms,
    position_function,
    rheolinear,
    second_kind,
    table_5_1_case,
    velocity_symbol,
)

EPS = np.finfo(float).eps
P1 = dict(J1=0.1, m2=2.0, c1=1e4, c2=1e5, b1=1.0, b2=10.0, F2=50.0)
SC = SliderCrank(0.05, 0.2)


def test_shapes_follow_the_angle_array():
    model = rheolinear(table_5_1_case(1), P1, {"U": SC})
    assert model.M(0.3).shape == (2, 2)
    assert model.C(np.zeros((3, 4)), 2.0).shape == (3, 4, 2, 2)
    assert model.F(np.zeros(5), np.linspace(1, 2, 5)).shape == (5, 2)
    assert model.coordinate_names == ("q1", "q2")


def test_same_symbolic_model_different_numbers_and_position_functions():
    # the symbolic derivation is cached per mechanism; binding other numbers reuses it
    mech = table_5_1_case(1)
    a = rheolinear(mech, P1, {"U": SC})
    b = rheolinear(mech, P1 | {"m2": 4.0}, {"U": SliderCrank(0.06, 0.3)})
    assert a._compiled[0] is b._compiled[0]
    phi = np.array([0.7])
    U1 = SliderCrank(0.06, 0.3)(phi, order=1)
    assert_allclose(b.M(phi)[0, 1, 1], 4.0, rtol=EPS)
    assert_allclose(b.M(phi)[0, 0, 1], 4.0 * U1[0], rtol=4 * EPS)  # m2 U' (Table 5.1)


@pytest.mark.parametrize(
    ("params", "funcs", "error", "match"),
    [
        ({k: v for k, v in P1.items() if k != "c1"}, {"U": SC}, ValueError, "missing values"),
        (P1 | {"k9": 1.0}, {"U": SC}, ValueError, "unknown parameters"),
        (P1, {}, ValueError, "missing position functions"),
        (P1, {"U": SC, "V": SC}, ValueError, "unknown position functions"),
        (P1, {"U": np.sin}, TypeError, "does not implement"),
    ],
)
def test_binding_errors(params, funcs, error, match):
    with pytest.raises(error, match=match):
        rheolinear(table_5_1_case(1), params, funcs)


def test_description_errors():
    q, th = sympy.symbols("q theta")
    with pytest.raises(ValueError, match="not one of the coordinates"):
        Mechanism((q,), (Spring(1, q),), drives=(th,))
    with pytest.raises(ValueError, match="repeated"):
        Mechanism((q, q), (Spring(1, q),))
    with pytest.raises(TypeError, match="unsupported type"):
        Mechanism((q,), ("spring",))
    with pytest.raises(ValueError, match="drive and vibration"):
        rheolinear(Mechanism((q,), (Spring(1, q),)))
    phi = sympy.Symbol("Omega")
    with pytest.raises(ValueError, match="reserves"):
        rheolinear(Mechanism((q, th), (Spring(phi, q),), drives=(th,)))


def test_fourth_derivative_is_refused():
    U = position_function("U")
    x = sympy.Symbol("x")
    with pytest.raises(ValueError, match="4th derivative"):
        sympy.diff(U(x), x, 4)


def test_two_drives_and_a_velocity_dependent_load():
    # Output x = U(θ1) + V(θ2) + q (e.g. a differential drive); rheolinear F of the follower
    # coordinate from eq. 10: F = −m(U'Ω̇1 + V'Ω̇2 + U''Ω1² + V''Ω2²) − c·0 − k(U'Ω1 + V'Ω2)
    # for the viscous load −k ẋ (Q* = −k ẋ, b_qq = k). Reference: hand derivation.
    q, t1, t2 = sympy.symbols("q theta1 theta2")
    m, c, k = sympy.symbols("m c k")
    U, V = position_function("U"), position_function("V")
    x = U(t1) + V(t2) + q
    xdot = sum(sympy.diff(x, s) * velocity_symbol(s) for s in (q, t1, t2))
    mech = Mechanism((q, t1, t2), (PointMass(m, (x,)), Spring(c, q), Load(-k * xdot, x)),
                     drives=(t1, t2))
    cam_v = SliderCrank(0.03, 0.25, 0.01)
    model = rheolinear(mech, dict(m=2.0, c=1e4, k=3.0), {"U": SC, "V": cam_v})
    phi = np.array([[0.1, 2.0], [1.5, 4.0], [3.0, 5.5]])
    W, Wd = np.array([3.0, -2.0]), np.array([0.5, 0.25])
    a, b = SC.derivatives(phi[:, 0]), cam_v.derivatives(phi[:, 1])
    F = (-2.0 * (a[1] * Wd[0] + b[1] * Wd[1] + a[2] * W[0]**2 + b[2] * W[1]**2)
         - 3.0 * (a[1] * W[0] + b[1] * W[1]))
    assert_allclose(model.F(phi, W, Wd)[:, 0], F, rtol=100 * EPS)
    assert_allclose(model.B(phi, W)[:, 0, 0], 3.0, rtol=EPS)
    assert_allclose(model.C(phi, W, Wd)[:, 0, 0], 1e4, rtol=EPS)
    with pytest.raises(ValueError, match="shape"):
        model.M(np.zeros(3))


def test_second_kind_generalized_masses_of_a_slider_crank_by_eq_6():
    # crank inertia J and slider mass m at x = U(φ): m_φφ = J + m U'² (eq. 6; Dresig ch. 2);
    # m_φφφ = m_φφ,φ = 2 m U' U'' (eq. 13: m_lkk = m_kk,l, here all indices the crank)
    phi_s, J, m = sympy.symbols("phi_c J m")
    U = position_function("U")
    mech = Mechanism((phi_s,), (RotaryInertia(J, phi_s), PointMass(m, (U(phi_s),)),
                                Damper(0.0, phi_s)))
    model = second_kind(mech, dict(J=0.3, m=1.7), {"U": SC})
    ang = np.linspace(0, 2 * np.pi, 9)[:, None]
    _, U1, U2, _ = SC.derivatives(ang[:, 0])
    assert_allclose(model.M(ang)[:, 0, 0], 0.3 + 1.7 * U1**2, rtol=10 * EPS)
    assert_allclose(model.christoffel(ang)[:, 0, 0, 0], 2 * 1.7 * U1 * U2, rtol=10 * EPS,
                    atol=10 * EPS * np.max(np.abs(U1 * U2)))
    assert lagrange_terms(mech).christoffel.shape == (1, 1, 1)


def test_binding_check_compiles_nothing_until_the_first_evaluation():
    """Checking a model's parameters (``femmech check``) derives the equations but does not
    lambdify them; the first evaluation does, and gives the closed form."""
    from femmech.mechanisms.evaluate import check_bindings, compile_expressions

    phi, q, k, m = sympy.symbols("phi q k m")
    compiled = compile_expressions((k * sympy.cos(phi) + m * q,), (phi, q))
    assert [s.name for s in compiled.parameters] == ["k", "m"]
    assert "_function" not in compiled.__dict__     # nothing lambdified yet
    out = compiled([np.array([0.0, np.pi]), np.array([1.0, 2.0])], [3.0, 5.0], {})
    assert "_function" in compiled.__dict__
    # k cos(phi) + m q at (0, 1) and (pi, 2): 3 + 5 = 8, -3 + 10 = 7 (round-off only)
    np.testing.assert_allclose(out[:, 0], [8.0, 7.0], rtol=1e-12)  # bound: 2 flops, eps 2.2e-16
    with pytest.raises(ValueError, match="unknown parameters"):
        check_bindings((compiled,), {"k": 1.0, "m": 1.0, "c": 2.0}, {}, set())
