"""A mechanism-only tracked sweep and static equilibrium (operating point).

* ``femmech.analysis.sweep.sweep`` of a mechanism model alone (no frame): the same
  frequencies as :func:`femmech.mechanisms.quasi_modes` at each angle, and tracking
  through a true crossing.
* :func:`femmech.mechanisms.static_equilibrium`: the crane's static sag under gravity
  against the vertical force balance m_total g = F_v + F_h (seed 5.2.3.1 eq. 18), the
  moment balance and the vertical pendulum; a preloaded spring and a pendulum under a
  constant torque against their closed forms; the rheolinear operating point of Table 5.1
  case 1 against its closed form and against the nonlinear (2nd-kind) equilibrium.
"""

import numpy as np
import pytest
import sympy
from numpy.testing import assert_allclose

from femmech.analysis.sweep import sweep
from femmech.errors import NumericalError
from femmech.mechanisms import (
    Load,
    Mechanism,
    PointMass,
    Potential,
    SliderCrank,
    Spring,
    cam_program,
    mobile_crane,
    mobile_crane_parameters,
    position_function,
    quasi_modes,
    rheolinear,
    second_kind,
    static_equilibrium,
    table_5_1_case,
)

CASE_1 = dict(J1=0.1, m2=2.0, c1=1e4, c2=1e5, b1=1.0, b2=10.0, F2=50.0)
PHI = np.linspace(0.0, 2 * np.pi, 121)


@pytest.fixture(scope="module")
def case_1():
    return rheolinear(table_5_1_case(1), CASE_1, {"U": SliderCrank(0.05, 0.2)})


# --- item 1: mechanism-only sweep ------------------------------------------------------

def test_mechanism_sweep_equals_frozen_quasi_modes(case_1):
    # Same pencil (M(φ), C(φ, 0, 0)) solved by two routes: sweep's shift-inverted LAPACK
    # driver and quasi_modes' eigh. Round-off of a 2x2 pencil: 1e-12 relative is ~5e3 eps.
    result = sweep(case_1, PHI, n_modes=2)
    reference = quasi_modes(case_1, PHI)
    assert result.freq_hz.shape == (PHI.size, 2)
    assert result.form == "symmetric"
    # bound: dense eig of a 2x2 pencil on both sides: eps·cond (roundoff.py)
    assert_allclose(np.sort(result.freq_hz, axis=1), reference.freq_hz, rtol=1e-12)
    assert result.mac_step.min() > 0.9  # the two branches are followed smoothly
    # independent reference: the roots of det(C - λM) = 0 of each 2x2 pencil in closed
    # form (a λ² + b λ + c = 0), no LAPACK involved
    M, C = case_1.M(PHI), case_1.C(PHI, 0.0, 0.0)
    a = M[:, 0, 0] * M[:, 1, 1] - M[:, 0, 1] * M[:, 1, 0]
    b = -(M[:, 0, 0] * C[:, 1, 1] + M[:, 1, 1] * C[:, 0, 0] - M[:, 0, 1] * C[:, 1, 0]
          - M[:, 1, 0] * C[:, 0, 1])
    c = C[:, 0, 0] * C[:, 1, 1] - C[:, 0, 1] * C[:, 1, 0]
    root = np.sqrt(b**2 - 4 * a * c)
    lam = np.sort(np.stack([(-b - root) / (2 * a), (-b + root) / (2 * a)], axis=1), axis=1)
    exact = np.sqrt(lam) / (2 * np.pi)
    # bound: quadratic formula with cancellation in -b - root: cond ~ λ2/λ1 ~ 1e2, so
    # ~1e-14 relative; 1e-10 leaves margin for both dense drivers
    assert_allclose(np.sort(result.freq_hz, axis=1), exact, rtol=1e-10)
    assert_allclose(reference.freq_hz, exact, rtol=1e-10)


def test_mechanism_sweep_at_speed_and_damped(case_1):
    # At speed C is unsymmetric (errata 30): the unsymmetric form, same λ as eig(C, M).
    Omega = 60.0
    result = sweep(case_1, PHI, Omega=Omega, n_modes=2)
    reference = quasi_modes(case_1, PHI, Omega)
    # bound: dense eig of a 2x2 pencil on both sides, with Ω terms: ~eps·cond (roundoff.py)
    assert_allclose(np.sort(result.freq_hz, axis=1), reference.freq_hz, rtol=1e-10)
    damped = sweep(case_1, PHI, Omega=Omega, n_modes=2, damped=True, keep_vectors=True)
    assert damped.form == "damped"
    assert damped.vectors.shape == (PHI.size, 2, 2)
    # light damping (b2 = 10 N s/m on 2 kg: ζ ≈ 0.005): damped ≈ undamped frequency
    assert_allclose(np.sort(damped.freq_hz, axis=1), reference.freq_hz, rtol=1e-3)
    assert (damped.damping_ratio > 0).all()


def _variable_lever():
    """Two uncoupled oscillators: m2 on a lever of ratio V(θ) (m11 = m2 V², c1) and m3 on
    c3. f1 = √(c1/(m2 V²))/2π varies over the cycle, f2 = √(c3/m3)/2π does not: the
    branches cross exactly (the coupling is zero), so sorted frequencies swap their
    modes there and tracked branches must not."""
    theta, q1, q2 = sympy.symbols("theta q1 q2")
    m2, m3, c1, c3 = sympy.symbols("m2 m3 c1 c3")
    V = position_function("V")
    mech = Mechanism((q1, q2, theta), (PointMass(m2, (V(theta) * q1,)), PointMass(m3, (q2,)),
                                       Spring(c1, q1), Spring(c3, q2)), drives=(theta,))
    cam = cam_program(1.0, rise=120, dwell_top=60, return_=120, dwell_bottom=60,
                      law="modified_sine", base=1.0)  # V from 1 to 2
    return rheolinear(mech, dict(m2=1.0, m3=1.0, c1=4e4, c3=2e4), {"V": cam})


def test_tracking_follows_a_crossing():
    # f1 = √(4e4/V²)/2π runs from 31.8 Hz (V = 1) to 15.9 Hz (V = 2); f2 = 22.5 Hz.
    model = _variable_lever()
    tracked = sweep(model, PHI, n_modes=2, keep_vectors=True)
    f2 = np.sqrt(2e4) / (2 * np.pi)
    # the branch starting as the q2 mode (lower at V = 1) stays at f2 through the crossings
    lever = np.argmax(np.abs(tracked.vectors[0, 0, :]))  # the branch that moves q1
    other = 1 - lever
    # bound: 2x2 eig against the closed-form f2: eps·cond
    assert_allclose(tracked.freq_hz[:, other], f2, rtol=1e-12)
    assert np.ptp(tracked.freq_hz[:, lever]) > 15.0  # it sweeps through f2 and back
    assert tracked.mac_step.min() > 0.999
    unsorted = sweep(model, PHI, n_modes=2, track=False)
    assert np.ptp(unsorted.freq_hz[:, 0]) > 5.0  # sorted columns swap modes at the crossing


class _Duck:
    """The duck type of a chain model: M(phi), B(phi, Omega), C(phi, Omega, Omega_dot), n."""

    n = 3

    def M(self, phi):
        phi = np.asarray(phi, dtype=float)
        out = np.broadcast_to(np.eye(3), phi.shape + (3, 3)).copy()
        out[..., 0, 0] += 0.5 * np.cos(phi) ** 2
        return out

    def B(self, phi, Omega):
        return np.zeros(np.shape(phi) + (3, 3))

    def C(self, phi, Omega, Omega_dot=0.0):
        K = np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]]) * 1e4
        return np.broadcast_to(K, np.shape(phi) + (3, 3)).copy()


def test_any_object_with_the_model_duck_type_sweeps():
    duck = _Duck()
    result = sweep(duck, PHI, n_modes=3)
    M, C = duck.M(PHI), duck.C(PHI, 0.0)
    lam = np.array([np.linalg.eigvals(np.linalg.solve(m, c)) for m, c in zip(M, C, strict=False)])
    # bound: 2x2 eig against eigvals(M⁻¹C) of the same matrices: eps·cond
    assert_allclose(np.sort(result.freq_hz, axis=1),
                    np.sort(np.sqrt(lam.real), axis=1) / (2 * np.pi), rtol=1e-12)


def test_mechanism_sweep_errors(case_1):
    with pytest.raises(ValueError, match="n_modes must be an integer in 1..2"):
        sweep(case_1, PHI, n_modes=3)
    with pytest.raises(TypeError, match="M\\(phi\\), B\\(phi, Omega\\)"):
        sweep(object(), PHI)

    class Wrong(_Duck):
        n = 4

    with pytest.raises(ValueError, match="n = 4 but M\\(phi\\) is 3 x 3"):
        sweep(Wrong(), PHI)


# --- item 3: static equilibrium --------------------------------------------------------

@pytest.fixture(scope="module")
def crane():
    return second_kind(mobile_crane(), mobile_crane_parameters())


@pytest.mark.parametrize("s4", [3.0, 4.5, 5.2])  # cylinder lengths, m (range 2.5..5.5)
def test_crane_sags_by_its_weight(crane, s4):
    p = mobile_crane_parameters()
    q, info = static_equilibrium(crane, s4)
    assert info.converged
    assert info.iterations <= 5
    assert q[3] == s4  # the drive stays where it was put
    # vertical balance: every mass's y has ∂y/∂q1 = 1, so F_v + F_h = -m_total g
    # (seed 5.2.3.1 eq. 18: F_v = c(q1 - l1 q2), F_h = c(q1 + l2 q2)); mean sag m g/(2c)
    m_total = p["m2"] + p["m3"] + p["m5"]
    Fv, Fh = p["c"] * (q[0] - p["l1"] * q[1]), p["c"] * (q[0] + p["l2"] * q[1])
    # bound: Newton equilibrium to ~eps of the residual; linear springs: a few eps
    assert_allclose(Fv + Fh, -m_total * p["g"], rtol=1e-12)
    assert_allclose((q[0] - p["l1"] * q[1] + q[0] + p["l2"] * q[1]) / 2,
                    -m_total * p["g"] / (2 * p["c"]), rtol=1e-12)
    # moment balance about the chassis reference, written by hand from eq. 13:
    # -l1 F_v + l2 F_h + g[m3 (ξ23 + r_S3 cos β) + m5 (ξ23 + r25 cos(β + α))] = 0
    phi3 = np.arccos((s4**2 - p["r24"]**2 - p["r34"]**2) / (2 * p["r24"] * p["r34"])) + p["gamma"]
    beta = phi3 + q[1]
    moment = (-p["l1"] * Fv + p["l2"] * Fh
              + p["g"] * (p["m3"] * (p["xi23"] + p["rS3"] * np.cos(beta))
                          + p["m5"] * (p["xi23"] + p["r25"] * np.cos(beta + p["alpha"]))))
    # bound: moment balance of weight-level terms: ~10 eps of m g r
    assert abs(moment) < 1e-9 * m_total * p["g"] * p["r25"]
    # bound: vertical load: the angle is 0 up to Newton's eps
    assert q[2] == pytest.approx(0.0, abs=1e-14)  # the load hangs vertically


def test_newton_failure_names_iterations_and_residual(crane):
    with pytest.raises(NumericalError, match=r"did not converge in 1 Newton iterations:"
                                             r" residual \d"):
        static_equilibrium(crane, 5.0, max_iter=1)


def test_preloaded_spring_and_gravity_closed_form():
    # Mass m on a spring c compressed by δ0 at q = 0, gravity along -q, drive s moving
    # the spring's base: c (q - s + δ0) + m g = 0 → q = s - δ0 - m g / c.
    q, s = sympy.symbols("q s")
    m, c, g, d0 = sympy.symbols("m c g delta0")
    mech = Mechanism((q, s), (PointMass(m, (q,)), Spring(c, q - s + d0), Potential(m * g * q)),
                     drives=(s,))
    vals = dict(m=3.0, c=2e4, g=9.81, delta0=0.01)
    x, info = static_equilibrium(second_kind(mech, vals), 0.02)
    # bound: linear spring equilibrium: Newton converges to a few eps
    assert_allclose(x[0], 0.02 - 0.01 - 3.0 * 9.81 / 2e4, rtol=1e-13)
    assert info.iterations == 1  # linear: one Newton step
    assert_allclose(info.stiffness, [[2e4]])


def test_pendulum_under_constant_torque_closed_form():
    # m g L sin θ = T0 → θ = arcsin(T0 / (m g L)); nonlinear, and T0 is a load (Q*),
    # not a potential, so the load enters the residual (and its tangent is zero).
    th = sympy.Symbol("theta")
    m, g, L, T0 = sympy.symbols("m g L T0")
    mech = Mechanism((th,), (PointMass(m, (L * sympy.sin(th), -L * sympy.cos(th))),
                             Potential(-m * g * L * sympy.cos(th)), Load(T0, th)))
    vals = dict(m=2.0, g=9.81, L=0.5, T0=6.0)
    x, info = static_equilibrium(second_kind(mech, vals), None, q0=[0.1])
    # bound: Newton on a smooth scalar equation: a few eps of the root
    assert_allclose(x[0], np.arcsin(6.0 / (2.0 * 9.81 * 0.5)), rtol=1e-12)
    assert 2 <= info.iterations <= 8  # quadratic convergence from 0.1 rad
    with pytest.raises(NumericalError, match="Newton iterations: residual"):
        static_equilibrium(second_kind(mech, {**vals, "T0": 20.0}), None, q0=[0.1])


def test_rheolinear_operating_point_closed_form_and_nonlinear(case_1):
    # Table 5.1 case 1 at rest (Ω = 0): C = diag(c1 + F2 U'', c2), F = (-F2 U', -F2)
    # (errata 13-15), so q1 = -F2 U'/(c1 + F2 U''), q2 = -F2/c2.
    U = SliderCrank(0.05, 0.2)
    q, info = static_equilibrium(case_1, PHI)
    _, U1, U2, _ = U.derivatives(PHI)
    F2, c1, c2 = CASE_1["F2"], CASE_1["c1"], CASE_1["c2"]
    # bound: closed-form static solution, Newton to a few eps (atol for q ~ 0)
    assert_allclose(q[:, 0], -F2 * U1 / (c1 + F2 * U2), rtol=1e-12, atol=1e-18)
    # bound: closed-form static solution, Newton to a few eps
    assert_allclose(q[:, 1], -F2 / c2, rtol=1e-12)
    assert info.converged
    assert info.iterations == 1
    # the nonlinear equilibrium with θ held (2nd kind): c1 q1 = -F2 U'(θ + q1); the
    # linear one differs at second order in q1: here |q1| <= 2.6e-4 rad, measured 4e-8 of it.
    nonlinear = second_kind(table_5_1_case(1), CASE_1, {"U": U})
    for phi, expected in zip(PHI[::10], q[::10], strict=True):
        x, _ = static_equilibrium(nonlinear, phi)
        # bound: atol only for zero entries: round-off of O(1e-3) displacements
        assert_allclose(x[:2], expected, rtol=1e-5, atol=1e-12)
