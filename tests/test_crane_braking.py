"""Crane braking case of seed 5.2.3.1 (examples/crane_braking.py).

References: the potential of eq. 13 with the gravity factor of errata 24 (static
balances), the cylinder triangle derivative φ3,4 of errata 23 (static cylinder force) and
the linear pendulum under a moving suspension point (start-up ramp).
"""

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
EPS = np.finfo(float).eps


def _load(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


cb = _load("crane_braking")
P = cb.PARAMS
WEIGHT = (P["m2"] + P["m3"] + P["m5"]) * P["g"]  # N


def _angles(q):
    """φ3,4 (1/m, errata 23), β = φ3 + q2 and β5 = β + α (rad; seed eqs. 2–6)."""
    r24, r34, q4 = P["r24"], P["r34"], q[3]
    u = q4**2 - r24**2 - r34**2
    dphi3 = -2 * q4 / np.sqrt(4 * r24**2 * r34**2 - u**2)
    beta = np.arccos(u / (2 * r24 * r34)) + P["gamma"] + q[1]
    return dphi3, beta, beta + P["alpha"]


@pytest.fixture(scope="module")
def runs():
    return {tb: cb.simulate(tb) for tb in cb.BRAKE_TIMES}


@pytest.mark.parametrize("q4", [3.9, 4.2, 4.7])
def test_static_rest_balances(q4):
    q = cb.static_rest(q4)
    m = cb.model()
    acc = m.accelerations(q, np.zeros(4), [0.0])
    # round-off of weight-level forces (100 eps · m_tot g) over the smallest mass (m2 + ...)
    assert np.abs(acc.qdd).max() < 100 * EPS * WEIGHT / (P["m2"] + P["m3"] + P["m5"])
    assert q[2] == pytest.approx(0.0, abs=1e-14)  # the load hangs vertically
    F_v = P["c"] * (q[0] - P["l1"] * q[1])  # eq. 18, tension positive
    F_h = P["c"] * (q[0] + P["l2"] * q[1])
    # W_pot,1 = 0 (eq. 13, errata 24): the axle forces carry the whole weight
    assert F_v + F_h == pytest.approx(-WEIGHT, rel=1e-12)
    # W_pot,2 = 0: −l1 F_v + l2 F_h + g (m3 y_S3,2 + m5 y_S5,2) = 0 with
    # y_S3,2 = ξ23 + r_S3 cos β, y_S5,2 = ξ23 + r25 cos β5 (seed eqs. 3, 6)
    _, beta, beta5 = _angles(q)
    moment = P["g"] * (P["m3"] * (P["xi23"] + P["rS3"] * np.cos(beta))
                       + P["m5"] * (P["xi23"] + P["r25"] * np.cos(beta5)))
    assert -P["l1"] * F_v + P["l2"] * F_h + moment == pytest.approx(0.0, abs=1e-12 * WEIGHT)


def test_rest_stays_at_rest():
    q = cb.static_rest(4.2)
    law = cb.SpeedRamp(0.0, 0.0, 1.0, phi0=4.2)  # q4 held constant
    t, y, _ = cb._segment(law, (0.0, 5.0), np.r_[q[:3], 0, 0, 0], 50)
    # accelerations ~1e-15 m/s² act for 5 s: drift ≲ 1e-14 m; 1e-10 covers the atol
    assert np.abs(y[:, :3] - q[:3]).max() < 1e-10
    assert np.abs(y[:, 3:]).max() < 1e-10


@pytest.mark.parametrize("q4", [3.9, 4.5])
def test_drive_force_at_rest_is_static_cylinder_force(q4):
    q = cb.static_rest(q4)
    Q4 = cb.model().accelerations(q, np.zeros(4), [0.0]).drive_forces[0]
    # ∂W_pot/∂q4 = g φ3,4 (m3 r_S3 cos β + m5 r25 cos β5) from eqs. 3, 6, 13 (errata 23, 24)
    dphi3, beta, beta5 = _angles(q)
    expected = P["g"] * dphi3 * (P["m3"] * P["rS3"] * np.cos(beta)
                                 + P["m5"] * P["r25"] * np.cos(beta5))
    assert_allclose(Q4, expected, rtol=1e-12)  # round-off of a few operations
    assert_allclose(cb.static_force(q4), expected, rtol=1e-12)


def test_constant_speed_phase_is_nearly_quiet():
    law, t, y, t_trip = cb.approach()
    T = cb.pendulum_period()
    assert t_trip > 2 * T  # the limiter trips after the start-up ramp
    q_end = np.r_[y[np.searchsorted(t, 2 * T), :3], law(np.array([2 * T]))[0]]
    dphi3, _, beta5 = _angles(q_end)
    # horizontal boom-tip speed at the end of the ramp, dx_tip/dt = −r25 sin β5 φ3,4 q4'
    v_tip = abs(P["r25"] * np.sin(beta5) * dphi3 * cb.SPEED)
    impulsive = v_tip / (2 * np.pi / T * P["rS5"])  # swing after a step start (rad)
    # A cycloidal ramp over exactly two periods leaves a linear pendulum at rest (its
    # acceleration spectrum vanishes at 2π/T); the geometric nonlinearity (φ3,4, β5 change
    # along the ramp) and the chassis leave a residue: require < 10 % of the step start.
    quiet = np.abs(y[t >= 2 * T, 2]).max()
    assert quiet < 0.1 * impulsive
    assert abs(law(np.array([t_trip]))[0][0] - 3.9) < 0.05  # trips near 3.9 m (probe)


def test_braking_swing_and_force(runs):
    swings = [cb.swing_amplitude(runs[tb], runs[tb].t_trip) for tb in cb.BRAKE_TIMES]
    # shorter braking = sharper pulse at the pendulum frequency: larger swing
    assert np.all(np.diff(swings) < 0)
    _, t, y, _ = cb.approach()
    assert min(swings) > 10 * np.abs(y[t >= 2 * cb.pendulum_period(), 2]).max()
    for run in runs.values():
        during = (run.t >= run.t_trip) & (run.t <= run.t_stop)
        static = cb.static_force(run.q[-1, 3])  # quasi-static Q4 at the final rest length
        # the chapter's point: braking inertia forces lift Q4 above the quasi-static force
        assert run.Q4[during].max() > 1.05 * static
        assert run.Q4[during].max() > cb.LIMIT
        assert abs(run.qd[-1, 3]) < 1e-12  # cylinder at rest after braking


def test_main_writes_outputs(tmp_path, runs):
    result = cb.main(tmp_path / "new" / "folder")  # a missing output folder is created
    assert result["png"].stat().st_size > 10_000
    data = np.loadtxt(result["csv"], delimiter=",", skiprows=1)
    assert data.shape[1] == 6 * len(cb.BRAKE_TIMES)
    assert_allclose(result["swing_rad"][0.2], cb.swing_amplitude(runs[0.2], runs[0.2].t_trip))
