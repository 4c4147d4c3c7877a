"""Prescribed-drive load cases with a trip and braking (femmech.analysis.drive_events).

References: the mobile crane example's implementation before the load case became a
library function (examples/crane_braking.py at commit 645c8b2: its own Newton iteration
and solve_ivp segments; numbers measured with it are quoted below), the crane's axle
forces (textbook chapter 5.2.3.1 eq. 18), the cycloidal SpeedRamp (its own position at the
computed travel time) and a torsion shaft whose drive torque is −c q (Lagrange's drive
row of 2T = J (θ' + q')², 2V = c q²).
"""

import math

import numpy as np
import pytest
import sympy
from models import OLD_PEAK, OLD_T_TRIP
from numpy.testing import assert_allclose

from femmech.analysis.drive_events import (
    spring_forces,
    static_drive_forces,
    static_rest,
    travel_time,
    trip_and_brake,
)
from femmech.analysis.response import SpeedRamp
from femmech.mechanisms import (
    Damper,
    Mechanism,
    RotaryInertia,
    Spring,
    mobile_crane,
    mobile_crane_parameters,
    second_kind,
)

P = mobile_crane_parameters()
T2 = 2 * 2 * np.pi * np.sqrt(P["rS5"] / P["g"])  # two pendulum periods, s
# bound: integrator tolerances of the run (solve_ivp), not test tolerances
CRANE = dict(drive="q4", start=4.7, speed=-0.1, ramp_time=T2, limit=300e3, t_after=T2,
             end=2.6, max_step=0.05, rtol=1e-10, atol=1e-12)
# Measured with the example's own implementation (commit 645c8b2, same model and settings):
OLD_STATIC_END = {0.2: 302567.50637064717}  # N, quasi-static Q4 at the final rest
OLD_REST = [-0.11790279264744541, 0.013811170589781608, 0.0, 4.7]  # static rest at 4.7 m


@pytest.fixture(scope="module")
def crane():
    return second_kind(mobile_crane(), P)


@pytest.fixture(scope="module")
def shaft():
    """A rotor J driven through a torsion spring c, with a viscous load b on it."""
    q, th, J, c, b = sympy.symbols("q theta J c b", real=True)
    mech = Mechanism((q, th), (RotaryInertia(J, th + q), Spring(c, q), Damper(b, th + q)),
                     drives=(th,), name="shaft")
    return second_kind(mech, {"J": 1.0, "c": 100.0, "b": 2.0})


def _old_newton(model, q4, tol=1e-13):
    """The example's former iteration: q_f -= K_ff⁻¹ W_pot,f from q = 0."""
    q = np.array([0.0, 0.0, 0.0, q4])
    for _ in range(50):
        dq = np.linalg.solve(model.stiffness(q)[:3, :3], model.gradient(q)[:3])
        q[:3] -= dq
        if np.abs(dq).max() < tol:
            return q
    raise AssertionError("no convergence")


@pytest.mark.parametrize("q4", [3.9, 4.7])
def test_static_rest_is_the_examples(crane, q4):
    q = static_rest(crane, [q4])
    # the same Newton steps as the example's former code: equal to the last bit
    assert np.array_equal(q, _old_newton(crane, q4))
    # bound: Newton on weight forces ~3e5 N: round-off ~1e3 eps·3e5 N
    assert np.abs(crane.gradient(q)[:3]).max() < 1e-9  # N: W_pot,f = 0 (weights ~3e5 N)
    if q4 == 4.7:
        assert q.tolist() == OLD_REST
    assert static_rest(crane, {"q4": q4}).tolist() == q.tolist()  # by name


def test_static_rest_failures_name_the_coordinate(crane):
    with pytest.raises(RuntimeError, match=r"did not converge in 1 Newton steps: the force on"
                                           r" coordinate 'q\d'"):
        static_rest(crane, [4.7], maxiter=1)
    # the load standing upside down above its suspension is a rest, but not a stable one
    with pytest.raises(ValueError, match="not stable.*coordinate 'q3'"):
        static_rest(crane, [4.7], q_guess=[0.0, 0.0, np.pi, 0.0])
    with pytest.raises(ValueError, match=r"one per drive \['q4'\]"):
        static_rest(crane, {"q5": 4.7})


def test_spring_forces_are_the_axle_forces(crane):
    q = np.array([[-0.1, 0.02, 0.1, 4.0], [0.01, -0.03, 0.0, 3.5]])
    F_v = P["c"] * (q[:, 0] - P["l1"] * q[:, 1])  # eq. 18, front axle
    F_h = P["c"] * (q[:, 0] + P["l2"] * q[:, 1])  # rear axle
    # bound: the same two linear formulas: a few eps
    assert_allclose(spring_forces(crane, q), np.column_stack([F_v, F_h]), rtol=1e-14)


@pytest.mark.parametrize("end", [2.6, 4.65])  # after the ramp, and within it
def test_travel_time_reaches_the_end(end):
    t = travel_time(4.7, end, -0.1, T2)
    position = SpeedRamp(0.0, -0.1, T2, phi0=4.7)(np.array([t]))[0][0]
    assert position == pytest.approx(end, abs=1e-12)  # bound: brentq to ~eps of the ramp time


def test_crane_load_case_equals_the_examples_former_numbers(crane):
    r = trip_and_brake(crane, brake_times=(0.2,), **CRANE)
    # Same model, tolerances and steps as the former implementation: its numbers are met
    # bit for bit (measured); allow the integrator-tolerance level the verify run shows
    # (trip time 6e-10 s, peak 1.2e-3 N at 10x tighter tolerances).
    assert r.tripped
    assert r.message == ""
    assert r.t_trip == pytest.approx(OLD_T_TRIP, abs=1e-8)
    run = r.runs[0]
    assert run.peak_force == pytest.approx(OLD_PEAK[0.2], abs=0.05)
    # bound: the same computation as recorded: a few eps
    assert run.static_force_end == pytest.approx(OLD_STATIC_END[0.2], rel=1e-12)
    # bound: brentq to ~eps of the trip time: a few eps of 10 s
    assert run.t_stop == pytest.approx(r.t_trip + 0.2, abs=1e-12)
    h = run.history
    assert h.t.size == 2 * 1500 - 1
    assert h.t[-1] == pytest.approx(r.t_trip + 0.2 + T2)
    # bound: braking ends at rest: velocity set to 0 by the event, integrator round-off
    assert abs(h.qd[-1, 3]) < 1e-12  # cylinder at rest after braking
    assert h.drive_forces[h.t < r.t_trip, 0].max() < 300e3  # below the limit until the trip
    # bound: the event is located by the integrator's root finder to ~eps of t: force error
    # eps-level
    assert r.approach.drive_forces[-1, 0] == pytest.approx(300e3, rel=1e-9)  # event located


def test_limit_never_reached_is_flagged(crane):
    r = trip_and_brake(crane, **{**CRANE, "end": 4.5, "limit": 900e3}, brake_times=(0.2,),
                       samples=50)
    assert not r.tripped
    assert r.runs == ()
    assert math.isnan(r.t_trip)
    assert "did not reach the limit 900000" in r.message
    assert "'q4'" in r.message
    assert r.extreme_before_trip < 900e3
    # bound: the run stops at the end-of-travel event, located to ~eps of t
    assert r.approach.q[-1, 3] == pytest.approx(4.5, abs=1e-9)  # ran to the end of travel


def test_verify_states_the_tolerance_effect(crane):
    r = trip_and_brake(crane, **{**CRANE, "end": 4.5, "limit": 900e3}, brake_times=(0.2,),
                       samples=50, verify=True)
    acc = r.accuracy
    assert acc.checked
    assert acc.rtol == 1e-10
    assert len(acc.coordinate_change) == 4
    # a change at tolerance level: rtol 1e-10 of forces ~2e5 N is 2e-5 N per step
    assert 0 < acc.force_change < 0.1
    assert "ten times tighter" in acc.statement()
    assert "Not checked" in trip_and_brake(crane, **{**CRANE, "end": 4.5, "limit": 900e3},
                                           brake_times=(0.2,), samples=50
                                           ).accuracy.statement()


@pytest.mark.parametrize(("bad", "message"), [
    ({"drive": "q3"}, r"drive 'q3' is not a drive.*\['q4'\]"),
    ({"end": 5.0}, "direction of travel"),
    ({"end": None}, "give end"),
    ({"limit": 10e3}, "already at or beyond the limit"),  # 17 kN at the start
    ({"speed": 0.0}, "speed must not be 0"),
    ({"brake_times": (0.2, -1.0)}, "braking times must be positive"),
])
def test_bad_inputs_are_named(crane, bad, message):
    args = {**CRANE, "brake_times": (0.2,), "samples": 20, **bad}
    with pytest.raises(ValueError, match=message):
        trip_and_brake(crane, **args)


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_rotational_drive_trips_during_the_ramp(shaft, sign):
    # Overload clutch on a shaft: the drive torque is −c q (drive row of the Lagrange
    # equations); the ramp's acceleration and the viscous load raise it to the limit
    # before the speed is reached, so the trip falls inside the start-up ramp.
    r = trip_and_brake(shaft, "theta", 0.0, sign * 40.0, 2.0, sign * 50.0, (0.5,), 2.0,
                       t_max=5.0, samples=400)
    assert r.tripped
    assert 0 < r.t_trip < 2.0
    # bound: the event is located to ~eps of t by the root finder
    assert r.approach.drive_forces[-1, 0] == pytest.approx(sign * 50.0, rel=1e-9)
    # bound: a linear spring force of O(1) displacements: a few eps of 100 N
    assert_allclose(r.approach.drive_forces[:, 0], -100.0 * r.approach.q[:, 0], atol=1e-9)
    h = r.runs[0].history
    k = np.searchsorted(h.t, r.t_trip)
    # the braking starts from the speed at the trip (continuous), and ends at rest
    # bound: the same state handed from one run to the next: a few eps
    assert h.qd[k, 1] == pytest.approx(r.approach.qd[-1, 1], rel=1e-12)
    assert h.qd[-1, 1] == 0.0
    assert sign * r.runs[0].peak_force >= 50.0
    assert static_drive_forces(shaft, np.zeros(2))[0] == 0.0  # no load at rest


def test_event_histories_take_runs_of_different_lengths(tmp_path):
    from femmech.output.histories import plot_event_histories

    t1, t2 = np.linspace(0, 1, 50), np.linspace(0, 2, 80)
    panels = {"force (kN)": {"a": (t1, np.sin(t1)), "b": (t2, np.cos(t2))}}
    path = plot_event_histories(panels, tmp_path / "h.png", event=(0.5, "trip"),
                                levels={"force (kN)": (0.8, "limit")})
    assert path.stat().st_size > 5_000
    with pytest.raises(ValueError, match="curve 'b': expected 80 values"):
        plot_event_histories({"x": {"b": (t2, t1)}}, tmp_path / "bad.png")


def test_evaluation_budget_stops_a_long_run(crane):
    with pytest.raises(RuntimeError, match="more than 50 evaluations of the equations"):
        trip_and_brake(crane, **CRANE, brake_times=(0.2,), samples=20, max_evaluations=50)


def test_static_rest_outside_the_range_of_motion(crane):
    # q4 > r24 + r34 = 5.5 m: the cylinder triangle does not close (arccos of > 1)
    with pytest.raises(ValueError, match=r"static rest at q4 = 5.6: the force on coordinate"
                                         r" 'q\d' is not finite .*range of motion"):
        static_rest(crane, [5.6])
