"""Nonlinear time integration of mechanisms: 2nd kind and mixed type (seed 5.2.1).

References: the exact large-amplitude pendulum period T = 4 √(L/g) K(sin(θ0/2)) (complete
elliptic integral of the first kind, scipy.special.ellipk with m = k²; e.g. Landau &
Lifshitz, Mechanics, §11, problem 1), the rope tension from energy conservation, the
same mechanism in minimal coordinates (2nd kind) and an independent solve_ivp of the
hand-derived equation of a pendulum with a driven suspension point.
"""

import numpy as np
import pytest
import sympy
from numpy.testing import assert_allclose
from scipy.integrate import solve_ivp
from scipy.special import ellipk

from femmech.analysis.nonlinear import integrate_mixed, integrate_second_kind
from femmech.analysis.response import ConstantSpeed, SpeedRamp
from femmech.mechanisms import (
    FourBar,
    Mechanism,
    PointMass,
    Potential,
    RotaryInertia,
    mixed_type,
    position_function,
    second_kind,
)

G, LEN, MASS = 9.81, 1.0, 2.0  # m/s², m, kg
THETA0 = 2.0  # rad (115°): far from the linear range, T/T_lin = 1.35
PERIOD = 4 * np.sqrt(LEN / G) * ellipk(np.sin(THETA0 / 2) ** 2)
X0 = np.array([LEN * np.sin(THETA0), -LEN * np.cos(THETA0)])


def _symbols(names):
    return sympy.symbols(names, real=True, seq=True)


@pytest.fixture(scope="module")
def cartesian():
    """Pendulum in (x, y), y up; constraint f = (x² + y² − L²)/(2L), a length.

    With this normalisation H = (x, y)/L is the unit vector along the rope, so the
    mixed-type equations m ẍ + λ x/L = 0, m ÿ + λ y/L = −m g say that λ is the rope
    tension S (N). The radial balance m L θ̇² = S − m g cos θ with the energy
    L θ̇² = 2 g (cos θ − cos θ0) gives S = m g (3 cos θ − 2 cos θ0), cos θ = −y/L.
    """
    x, y = _symbols("x y")
    m, g, L = _symbols("m g L")
    mech = Mechanism((x, y), (PointMass(m, (x, y)), Potential(m * g * y)),
                     constraints=((x**2 + y**2 - L**2) / (2 * L),), name="cartesian pendulum")
    return mixed_type(mech, dict(m=MASS, g=G, L=LEN))


@pytest.fixture(scope="module")
def angular():
    (th,) = _symbols("theta")
    m, g, L = _symbols("m g L")
    mech = Mechanism((th,), (PointMass(m, (L * sympy.sin(th), -L * sympy.cos(th))),
                             Potential(-m * g * L * sympy.cos(th))), name="angle pendulum")
    return second_kind(mech, dict(m=MASS, g=G, L=LEN))


@pytest.fixture(scope="module")
def swing(cartesian):
    """Two periods with projection, rtol 1e-10 (measured: 1967 evaluations)."""
    t = np.linspace(0.0, 2 * PERIOD, 201)
    # bound: integrator tolerances of the run (not test tolerances; the asserts below allow 1e-8)
    return integrate_mixed(cartesian, t, X0, [0.0, 0.0], rtol=1e-10, atol=1e-12)


def test_pendulum_period_and_tension(swing, angular):
    r = swing
    # exact period: back at the start after T and 2T. Global error of DOP853 at rtol 1e-10
    # over two periods: measured 1.2e-10 m, allow 1e-8 m.
    assert_allclose(r.q[100], X0, atol=1e-8)
    assert_allclose(r.q[-1], X0, atol=1e-8)
    # bound: angle form, integrated tightly (rtol 1e-12): measured difference 4.1e-10 m
    s = integrate_second_kind(angular, r.t, [THETA0], [0.0], rtol=1e-12, atol=1e-14)
    assert_allclose(r.q[:, 0], LEN * np.sin(s.q[:, 0]), atol=1e-8)
    assert_allclose(r.q[:, 1], -LEN * np.cos(s.q[:, 0]), atol=1e-8)
    # bound: pendulum period closed by an integrator at rtol 1e-12: error ~1e-12 θ per period, x1e2
    assert_allclose(s.q[100, 0], THETA0, atol=1e-10)  # measured 1.1e-13 rad
    # rope tension (fixture docstring): S = m g (3 cos θ − 2 cos θ0); max S = 75 N,
    # measured error 1.1e-8 N (the position error times m g): allow 1e-6 N
    cos_theta = -r.q[:, 1] / LEN
    assert_allclose(r.multipliers[:, 0], MASS * G * (3 * cos_theta - 2 * np.cos(THETA0)),
                    atol=1e-6)
    # bound: drift at round-off (f ~ L = 1 m): < 1e-12 L
    assert r.constraint_drift.max() < 1e-12 * LEN
    assert r.velocity_drift.max() < 1e-12 * LEN
    # accelerations returned are those of the equations: ẍ = −S x/(m L) (measured exact)
    # bound: the same formula as the integrator's right-hand side: a few eps of O(1) terms
    assert_allclose(r.qdd[:, 0], -r.multipliers[:, 0] * r.q[:, 0] / (MASS * LEN), atol=1e-9)


def test_projection_conserves_energy(swing):
    # undamped: E = ½ m |v|² + m g y constant. Projection is not a conserving scheme; the
    # energy error is the global integration error, accumulated over ~150 steps of
    # rtol 1e-10: measured 6.7e-10 relative, allow 1e-8 (100 rtol)
    E = 0.5 * MASS * (swing.qd**2).sum(axis=1) + MASS * G * swing.q[:, 1]
    E0 = -MASS * G * LEN * np.cos(THETA0)
    assert np.abs(E - E0).max() < 1e-8 * abs(E0)


N_PERIODS, PER_PERIOD = 6, 20


@pytest.fixture(scope="module")
def long_runs(cartesian):
    """Six periods at rtol 1e-6 with the three drift treatments (20 outputs per period)."""
    t = np.linspace(0.0, N_PERIODS * PERIOD, N_PERIODS * PER_PERIOD + 1)
    # bound: integrator tolerances of the runs, not test tolerances
    return {s: integrate_mixed(cartesian, t, X0, [0.0, 0.0], stabilization=s, rtol=1e-6,
                               atol=1e-9) for s in ("none", "projection", "baumgarte")}


def _per_period_max(d):
    return d[1:].reshape(N_PERIODS, PER_PERIOD).max(axis=1)


def test_drift_without_stabilization_grows(long_runs):
    d = _per_period_max(long_runs["none"].constraint_drift)
    # measured per-period maxima 4.9e-6, 1.2e-5, 2.6e-5, 4.5e-5, 7.0e-5, 1.0e-4 m: the
    # drift grows about quadratically (the velocity error integrates), 100 × rtol at the end
    assert d[-1] > 3e-5 * LEN
    assert d[-1] > 10 * d[0]
    assert np.all(np.diff(d) > 0)
    assert long_runs["none"].velocity_drift.max() > 1e-6  # measured 1.2e-5 m/s


def test_projection_keeps_drift_at_round_off(long_runs):
    r = long_runs["projection"]
    # bound: projection to the constraint each step: ~n eps L (measured 1.1e-16 m)
    assert r.constraint_drift.max() < 1e-12 * LEN  # measured 1.1e-16 m
    assert r.velocity_drift.max() < 1e-12 * LEN  # measured 4.4e-16 m/s


def test_baumgarte_keeps_drift_bounded(long_runs):
    d = _per_period_max(long_runs["baumgarte"].constraint_drift)
    # α = β = 10/s: the error obeys ë + 2α ė + β² e = (truncation error), so it stays
    # at the level of the local error over β². Measured per-period maxima 8.9e-8, 4.1e-8,
    # 1.3e-7, 5.2e-8, 5.1e-8, 4.4e-8 m: no trend. Allow 1e-6 m and no growth (last three
    # periods at most 3 × the first three).
    assert d.max() < 1e-6 * LEN
    assert d[3:].max() < 3 * d[:3].max()
    assert d.max() < 1e-2 * _per_period_max(long_runs["none"].constraint_drift)[-1]


# ------------------------------------------------------------- four-bar, closed loop

FB = dict(a=0.1, b=0.35, c=0.3, d=0.35)  # m: Grashof crank-rocker, no dead centre
FB_PARAMS = dict(FB, m_a=0.5, m_b=1.0, m_c=0.8, g=9.81)  # kg, m/s²


def _four_bar_elements(phi, th, ps):
    """Uniform bars: crank a about A0 = 0, coupler b from A, rocker c about B0 = (d, 0)."""
    a, b, c, d, ma, mb, mc, g = _symbols("a b c d m_a m_b m_c g")
    ax, ay = a * sympy.cos(phi), a * sympy.sin(phi)
    cb = (ax + b / 2 * sympy.cos(th), ay + b / 2 * sympy.sin(th))
    cc = (d + c / 2 * sympy.cos(ps), c / 2 * sympy.sin(ps))
    return (PointMass(ma, (ax / 2, ay / 2)), RotaryInertia(ma * a**2 / 12, phi),
            PointMass(mb, cb), RotaryInertia(mb * b**2 / 12, th),
            PointMass(mc, cc), RotaryInertia(mc * c**2 / 12, ps),
            Potential(g * (ma * ay / 2 + mb * cb[1] + mc * cc[1])))


def test_four_bar_redundant_vs_minimal():
    phi, th, ps = _symbols("phi theta psi")
    a, b, c, d = _symbols("a b c d")
    loop = (a * sympy.cos(phi) + b * sympy.cos(th) - c * sympy.cos(ps) - d,
            a * sympy.sin(phi) + b * sympy.sin(th) - c * sympy.sin(ps))
    redundant = Mechanism((phi, th, ps), _four_bar_elements(phi, th, ps), constraints=loop,
                          name="four-bar, link angles")
    u_th, u_ps = position_function("U_coupler"), position_function("U_rocker")
    minimal = Mechanism((phi,), _four_bar_elements(phi, u_th(phi), u_ps(phi)),
                        name="four-bar, crank angle")
    funcs = {"U_coupler": FourBar(**FB, output="coupler"), "U_rocker": FourBar(**FB)}
    phi0, w0 = 0.3, 4.0  # rad, rad/s: the crank swings back over a half turn under gravity
    th0, ps0 = FourBar(**FB).angles(phi0)
    q0 = [phi0, float(th0), float(ps0)]
    qd0 = [w0, funcs["U_coupler"](phi0, 1) * w0, funcs["U_rocker"](phi0, 1) * w0]
    t = np.linspace(0.0, 1.5, 76)
    # bound: integrator tolerances of the runs, not test tolerances
    r = integrate_mixed(mixed_type(redundant, FB_PARAMS), t, q0, qd0, rtol=1e-10, atol=1e-12)
    s = integrate_second_kind(second_kind(minimal, FB_PARAMS, funcs), t, [phi0], [w0],
                              rtol=1e-10, atol=1e-12)
    assert np.ptp(s.q[:, 0]) > 3.0  # large motion (measured 4.3 rad)
    th_s, ps_s = FourBar(**FB).angles(s.q[:, 0])
    # two integrations at rtol 1e-10: measured differences ≤ 1.5e-9 rad, allow 1e-7 rad
    assert_allclose(r.q[:, 0], s.q[:, 0], atol=1e-7)
    assert_allclose(r.q[:, 1], th_s, atol=1e-7)
    assert_allclose(r.q[:, 2], ps_s, atol=1e-7)
    assert_allclose(r.qd[:, 0], s.qd[:, 0], atol=1e-6)  # measured 1.6e-8 rad/s
    # bound: projection to the constraint each step: ~n eps of lengths ~0.35 m
    assert r.constraint_drift.max() < 1e-14  # m; measured 1.1e-16 (lengths ~0.35 m)


# ------------------------------------------------------- prescribed drive, 2nd kind

M0 = 3.0  # kg, carriage of the suspension point


@pytest.fixture(scope="module")
def carriage_pendulum():
    """Pendulum (θ) hanging from a carriage at x = s, s the drive coordinate."""
    th, s = _symbols("theta s")
    m, m0, g, L = _symbols("m m0 g L")
    mech = Mechanism((th, s), (PointMass(m0, (s,)),
                               PointMass(m, (s + L * sympy.sin(th), -L * sympy.cos(th))),
                               Potential(-m * g * L * sympy.cos(th))), drives=(s,),
                     name="pendulum on a driven carriage")
    return second_kind(mech, dict(m=MASS, m0=M0, g=G, L=LEN))


def _reference(law, t, theta0, omega0):
    """Hand-derived: L θ̈ = −g sin θ − s̈ cos θ; carriage force m0 s̈ + m ẍ_mass."""
    def rhs(time, y):
        acc = law(np.array([time]))[2][0]
        return [y[1], -(G * np.sin(y[0]) + acc * np.cos(y[0])) / LEN]
    # bound: integrator tolerances of the DOP853 reference, not test tolerances
    sol = solve_ivp(rhs, (t[0], t[-1]), [theta0, omega0], method="DOP853", t_eval=t,
                    rtol=1e-12, atol=1e-14)
    th, w = sol.y
    acc = law(t)[2]
    thdd = -(G * np.sin(th) + acc * np.cos(th)) / LEN
    force = M0 * acc + MASS * (acc + LEN * (np.cos(th) * thdd - np.sin(th) * w**2))
    return th, w, thdd, force


def test_driven_suspension_speed_ramp(carriage_pendulum):
    law = SpeedRamp(0.0, 1.5, 1.0, t_start=0.2)  # 0 → 1.5 m/s in 1 s; peak s̈ = 3 m/s²
    t = np.linspace(0.0, 4.0, 161)
    # bound: integrator tolerances of the run, not test tolerances
    r = integrate_second_kind(carriage_pendulum, t, [0.1], [0.0], drive=law, rtol=1e-11,
                              atol=1e-13)
    th, w, thdd, force = _reference(law, t, 0.1, 0.0)
    # two DOP853 runs at rtol ≤ 1e-11: measured 1.6e-11 rad, 2.9e-11 rad/s, 1.5e-10
    # rad/s²; allow 1e-8, 1e-8, 1e-7
    assert_allclose(r.q[:, 0], th, atol=1e-8)
    assert_allclose(r.qd[:, 0], w, atol=1e-8)
    assert_allclose(r.qdd[:, 0], thdd, atol=1e-7)
    # drive force up to 13.8 N (measured), error measured 3.7e-10 N; allow 1e-7 N
    assert np.abs(force).max() > 5.0
    assert_allclose(r.drive_forces[:, 0], force, atol=1e-7)
    phi, Omega, Omega_dot = law(t)
    assert_allclose(r.drive_q[:, 0], phi)
    assert_allclose(r.drive_qd[:, 0], Omega)
    assert_allclose(r.drive_qdd[:, 0], Omega_dot)
    assert r.coordinate_names == ("theta",)
    assert r.drive_names == ("s",)


def test_constant_speed_suspension_is_galilean(carriage_pendulum, angular):
    # a uniformly moving suspension changes nothing (Galilei): the same swing as on a
    # fixed point, and the carriage force m ẍ_mass is the swing's horizontal inertia
    t = np.linspace(0.0, PERIOD, 41)
    # bound: integrator tolerances of the runs, not test tolerances
    r = integrate_second_kind(carriage_pendulum, t, [THETA0], [0.0],
                              drive=ConstantSpeed(2.0, phi0=0.5), rtol=1e-11, atol=1e-13)
    s = integrate_second_kind(angular, t, [THETA0], [0.0], rtol=1e-11, atol=1e-13)
    # bound: measured identical (s̈ = 0: the same arithmetic for θ); allow 1e-9 rad
    assert_allclose(r.q, s.q, atol=1e-9)
    th, w, thdd = r.q[:, 0], r.qd[:, 0], r.qdd[:, 0]
    assert_allclose(r.drive_forces[:, 0],
                    MASS * LEN * (np.cos(th) * thdd - np.sin(th) * w**2), atol=1e-8)


def test_event_quarter_period(angular):
    # from rest at θ0 the pendulum first passes θ = 0 at T/4 (exact, elliptic)
    def bottom(t, y):
        return y[0]
    bottom.terminal, bottom.direction = True, -1.0
    t = np.linspace(0.0, PERIOD, 101)
    # bound: integrator tolerances of the run, not test tolerances
    r = integrate_second_kind(angular, t, [THETA0], [0.0], events=bottom, rtol=1e-12,
                              atol=1e-14)
    # bound: event root found to ~eps of t; the run's rtol 1e-12 on θ moves it ~1e-12
    assert_allclose(r.t_events[0][0], PERIOD / 4, rtol=1e-9)  # measured 4.7e-14 relative
    assert r.t[-1] <= PERIOD / 4
    assert r.t.size == 26


# ------------------------------------------------------------------------- errors


def test_bad_input_errors(cartesian, angular, carriage_pendulum):
    t = np.linspace(0.0, 1.0, 11)
    with pytest.raises(ValueError, match=r"q0 must have shape \(1,\)"):
        integrate_second_kind(angular, t, [0.1, 0.2], [0.0])
    with pytest.raises(ValueError, match=r"qd0 must have shape \(2,\)"):
        integrate_mixed(cartesian, t, X0, [0.0])
    with pytest.raises(ValueError, match=r"strictly increasing: t\[1\]"):
        integrate_second_kind(angular, [0.0, 1.0, 0.5], [0.1], [0.0])
    with pytest.raises(ValueError, match="q0 of coordinate 'theta' is not finite"):
        integrate_second_kind(angular, t, [np.nan], [0.0])
    with pytest.raises(ValueError, match="unknown stabilization 'penalty'"):
        integrate_mixed(cartesian, t, X0, [0.0, 0.0], stabilization="penalty")
    with pytest.raises(ValueError, match="unknown method"):
        integrate_mixed(cartesian, t, X0, [0.0, 0.0], method="Euler")
    with pytest.raises(ValueError, match="multistep method 'BDF'"):
        integrate_mixed(cartesian, t, X0, [0.0, 0.0], method="BDF")
    with pytest.raises(ValueError, match="baumgarte must be"):
        integrate_mixed(cartesian, t, X0, [0.0, 0.0], stabilization="baumgarte",
                        baumgarte=(-1.0, 1.0))
    with pytest.raises(ValueError, match=r"drive coordinates \('s',\)"):
        integrate_second_kind(carriage_pendulum, t, [0.1], [0.0])
    with pytest.raises(ValueError, match="no drive coordinates"):
        integrate_second_kind(angular, t, [0.1], [0.0], drive=ConstantSpeed(1.0))
    with pytest.raises(TypeError, match="LagrangeModel"):
        integrate_second_kind(cartesian, t, X0, [0.0, 0.0])
    with pytest.raises(TypeError, match="MixedModel"):
        integrate_mixed(angular, t, [0.1], [0.0])


def test_inconsistent_initial_conditions(cartesian):
    t = np.linspace(0.0, 0.5, 11)
    # rope 1 % too long: f = (1.01² − 1)/2 = 0.01005 m
    with pytest.raises(ValueError, match=r"f constraint 0 .* residual 1\.005e-02"):
        integrate_mixed(cartesian, t, 1.01 * X0, [0.0, 0.0])
    # velocity with a radial component 0.1 m/s
    radial = 0.1 * X0 / LEN
    with pytest.raises(ValueError, match=r"H q̇ of constraint 0 .* residual 1\.000e-01"):
        integrate_mixed(cartesian, t, X0, radial)
    r = integrate_mixed(cartesian, t, 1.01 * X0, radial, project_initial=True,
                        stabilization="none")
    # the mass-weighted (here Euclidean) closest point on the circle is X0 itself, and
    # the radial velocity is removed: the motion starts from rest at X0
    # bound: the closest-point projection of a point on the circle returns it: a few eps of O(1)
    # values
    assert_allclose(r.q[0], X0, atol=1e-15)
    assert_allclose(r.qd[0], 0.0, atol=1e-15)


def test_non_finite_state_names_coordinate_and_time():
    (x,) = _symbols("x")
    # V = √x pulls x from rest at 1 m to 0, where the force −1/(2√x) is infinite, at
    # t = ∫₀¹ dx / √(2(1 − √x)) = 4√2/3 = 1.8856 s (energy ½ ẋ² + √x = 1)
    mech = Mechanism((x,), (PointMass(1, (x,)), Potential(sympy.sqrt(x))), name="sqrt")
    with pytest.raises(ValueError, match=r"non-finite (acceleration|position) of coordinate "
                                         r"'x' at t = 1\.88"):
        integrate_second_kind(second_kind(mech), np.linspace(0.0, 5.0, 6), [1.0], [0.0])
