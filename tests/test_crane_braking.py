"""Mobile crane braked by its load-moment limiter: examples/crane_braking.py and its
scene examples/crane_braking.toml (reading, strict errors, end to end).

References: the textbook chapter's section 5.2.3.1: the potential of eq. 13 with the
gravity factor of errata 24 (static balances), the cylinder triangle derivative φ3,4 of
errata 23 (static cylinder force), the linear pendulum under a moving suspension point
(start-up ramp); the numbers of the example's implementation before the load case became
a library function (commit 645c8b2), quoted in tests/test_drive_events.py.
"""

import importlib.util
import json
import re
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from models import OLD_PEAK, OLD_T_TRIP
from numpy.testing import assert_allclose

from femmech.analysis.nonlinear import integrate_second_kind
from femmech.analysis.response import SpeedRamp
from femmech.cli import main
from femmech.errors import SceneError
from femmech.output import histories
from femmech.scene import Scene, prepare

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
    """φ3,4 (1/m, errata 23), β = φ3 + q2 and β5 = β + α (rad; chapter eqs. 2–6)."""
    r24, r34, q4 = P["r24"], P["r34"], q[3]
    u = q4**2 - r24**2 - r34**2
    dphi3 = -2 * q4 / np.sqrt(4 * r24**2 * r34**2 - u**2)
    beta = np.arccos(u / (2 * r24 * r34)) + P["gamma"] + q[1]
    return dphi3, beta, beta + P["alpha"]


@pytest.fixture(scope="module")
def runs():
    return {tb: cb.simulate(tb) for tb in cb.BRAKE_TIMES}


def test_example_numbers_are_the_former_implementations(runs):
    # same model, tolerances and steps as before: the same numbers (measured: to the bit)
    for tb, run in runs.items():
        assert run.t_trip == pytest.approx(OLD_T_TRIP, abs=1e-8)
        assert run.Q4[run.t >= run.t_trip].max() == pytest.approx(OLD_PEAK[tb], abs=0.05)


@pytest.mark.parametrize("q4", [3.9, 4.2, 4.7])
def test_static_rest_balances(q4):
    q = cb.static_rest(q4)
    m = cb.model()
    acc = m.accelerations(q, np.zeros(4), [0.0])
    # round-off of weight-level forces (100 eps · m_tot g) over the smallest mass (m2 + ...)
    assert np.abs(acc.qdd).max() < 100 * EPS * WEIGHT / (P["m2"] + P["m3"] + P["m5"])
    # bound: Newton to round-off of weight-level terms (line above): angles to ~10 eps
    assert q[2] == pytest.approx(0.0, abs=1e-14)  # the load hangs vertically
    F_v = P["c"] * (q[0] - P["l1"] * q[1])  # eq. 18, tension positive
    F_h = P["c"] * (q[0] + P["l2"] * q[1])
    # W_pot,1 = 0 (eq. 13, errata 24): the axle forces carry the whole weight
    # bound: Newton's residual at round-off, ~10 eps of the weight
    assert F_v + F_h == pytest.approx(-WEIGHT, rel=1e-12)
    # W_pot,2 = 0: −l1 F_v + l2 F_h + g (m3 y_S3,2 + m5 y_S5,2) = 0 with
    # y_S3,2 = ξ23 + r_S3 cos β, y_S5,2 = ξ23 + r25 cos β5 (chapter eqs. 3, 6)
    _, beta, beta5 = _angles(q)
    moment = P["g"] * (P["m3"] * (P["xi23"] + P["rS3"] * np.cos(beta))
                       + P["m5"] * (P["xi23"] + P["r25"] * np.cos(beta5)))
    # bound: moment balance of weight-level terms: ~10 eps of the weight
    assert -P["l1"] * F_v + P["l2"] * F_h + moment == pytest.approx(0.0, abs=1e-12 * WEIGHT)


def test_rest_stays_at_rest():
    q = cb.static_rest(4.2)
    law = SpeedRamp(0.0, 0.0, 1.0, phi0=4.2)  # q4 held constant
    r = integrate_second_kind(cb.model(), np.linspace(0.0, 5.0, 50), q[:3], np.zeros(3),
                              drive=law, rtol=cb.RTOL, atol=cb.ATOL)
    # bound: accelerations ~1e-15 m/s² act for 5 s: drift ≲ 1e-14 m; 1e-10 covers the atol
    assert np.abs(r.q - q[:3]).max() < 1e-10
    assert np.abs(r.qd).max() < 1e-10


@pytest.mark.parametrize("q4", [3.9, 4.5])
def test_drive_force_at_rest_is_static_cylinder_force(q4):
    q = cb.static_rest(q4)
    Q4 = cb.model().accelerations(q, np.zeros(4), [0.0]).drive_forces[0]
    # ∂W_pot/∂q4 = g φ3,4 (m3 r_S3 cos β + m5 r25 cos β5) from eqs. 3, 6, 13 (errata 23, 24)
    dphi3, beta, beta5 = _angles(q)
    expected = P["g"] * dphi3 * (P["m3"] * P["rS3"] * np.cos(beta)
                                 + P["m5"] * P["r25"] * np.cos(beta5))
    assert_allclose(Q4, expected, rtol=1e-12)  # bound: round-off of a few operations
    assert_allclose(cb.static_force(q4), expected, rtol=1e-12)


def test_constant_speed_phase_is_nearly_quiet():
    case = cb.load_case()
    t, y, t_trip = case.approach.t, case.approach.q, case.t_trip
    T = cb.pendulum_period()
    assert t_trip > 2 * T  # the limiter trips after the start-up ramp
    q_end = y[np.searchsorted(t, 2 * T)]
    dphi3, _, beta5 = _angles(q_end)
    # horizontal boom-tip speed at the end of the ramp, dx_tip/dt = −r25 sin β5 φ3,4 q4'
    v_tip = abs(P["r25"] * np.sin(beta5) * dphi3 * cb.SPEED)
    impulsive = v_tip / (2 * np.pi / T * P["rS5"])  # swing after a step start (rad)
    # A cycloidal ramp over exactly two periods leaves a linear pendulum at rest (its
    # acceleration spectrum vanishes at 2π/T); the geometric nonlinearity (φ3,4, β5 change
    # along the ramp) and the chassis leave a residue: require < 10 % of the step start.
    quiet = np.abs(y[t >= 2 * T, 2]).max()
    assert quiet < 0.1 * impulsive
    assert abs(case.drive_at_trip - 3.9) < 0.05  # trips near 3.9 m (probe)


def test_braking_swing_and_force(runs):
    swings = [cb.swing_amplitude(runs[tb], runs[tb].t_trip) for tb in cb.BRAKE_TIMES]
    # shorter braking = sharper pulse at the pendulum frequency: larger swing
    assert np.all(np.diff(swings) < 0)
    t, y = cb.load_case().approach.t, cb.load_case().approach.q
    assert min(swings) > 10 * np.abs(y[t >= 2 * cb.pendulum_period(), 2]).max()
    for run in runs.values():
        during = (run.t >= run.t_trip) & (run.t <= run.t_stop)
        static = cb.static_force(run.q[-1, 3])  # quasi-static Q4 at the final rest length
        # the chapter's point: braking inertia forces lift Q4 above the quasi-static force
        assert run.Q4[during].max() > 1.05 * static
        assert run.Q4[during].max() > cb.LIMIT
        # bound: braking ends at rest: velocity set to 0 by the event, integrator round-off
        assert abs(run.qd[-1, 3]) < 1e-12  # cylinder at rest after braking


def test_main_writes_outputs(tmp_path, runs):
    result = cb.main(tmp_path / "new" / "folder")  # a missing output folder is created
    assert result["png"].stat().st_size > 10_000
    data = np.loadtxt(result["csv"], delimiter=",", skiprows=1)
    assert data.shape[1] == 6 * len(cb.BRAKE_TIMES)
    assert_allclose(result["swing_rad"][0.2], cb.swing_amplitude(runs[0.2], runs[0.2].t_trip))


# --- the scene: reading ------------------------------------------------------------------

TOML = EXAMPLES / "crane_braking.toml"


def _scene_dict():
    return tomllib.loads(TOML.read_text(encoding="utf-8"))


def test_scene_reads_the_examples_load_case():
    scene = Scene.from_dict(_scene_dict(), EXAMPLES, "crane.toml")
    spec = scene.analyses.drive_event
    assert scene.mechanisms["crane"].form == "second_kind"
    assert scene.mechanisms["crane"].parameters == cb.PARAMS  # units converted exactly
    T2 = 2 * cb.pendulum_period()
    assert (spec.drive, spec.start, spec.end, spec.speed) == ("q4", cb.Q4_START, cb.Q4_END,
                                                              -cb.SPEED)
    assert (spec.ramp_time, spec.time_after_stop) == (T2, T2)  # 15 digits in the file
    assert (spec.trip_force, spec.braking_times) == (cb.LIMIT, cb.BRAKE_TIMES)
    assert (spec.rtol, spec.atol, spec.max_step) == (cb.RTOL, cb.ATOL, cb.MAX_STEP)
    assert not spec.rotational
    assert spec.outputs == ("q1", "q2", "q3", "spring1", "spring2")


def _set(data, path, value):
    *head, key = path.split(".")
    table = data
    for k in head:
        table = table[k]
    if value is None:
        del table[key]
    else:
        table[key] = value


@pytest.mark.parametrize(("path", "value", "fragment"), [
    ("analyses.drive_event.trip_forc", "300 kN",
     r"\[analyses.drive_event\] trip_forc: unknown key; did you mean 'trip_force'\?"),
    ("analyses.drive_event.trip_force", "300 kN*m",
     r"\[analyses.drive_event\] trip_force: expected a force .* is a moment"),
    ("analyses.drive_event.trip_force", "0 N", r"\[analyses.drive_event\] trip_force: .*non-zero"),
    ("analyses.drive_event.speed", "0.1 rad/s",
     r"\[analyses.drive_event\] speed: expected a linear speed"),
    ("analyses.drive_event.speed", "0 m/s", r"\[analyses.drive_event\] speed: .*non-zero"),
    ("analyses.drive_event.start", "4.7 kg", r"\[analyses.drive_event\] start: expected a length"),
    ("analyses.drive_event.end", "5 m", r"\[analyses.drive_event\] end: .*direction of the speed"),
    ("analyses.drive_event.end", None, r"\[analyses.drive_event\]: give end .* or t_max"),
    ("analyses.drive_event.ramp_time", "-1 s",
     r"\[analyses.drive_event\] ramp_time: expected a positive value"),
    ("analyses.drive_event.braking_times", ["0.2 s", "0 s"],
     r"\[analyses.drive_event\] braking_times: expected a list of positive braking times"),
    ("analyses.drive_event.braking_times", ["1 s"] * 21,
     r"\[analyses.drive_event\] braking_times: 21 values; at most 20 \(limit MAX_RUNS\)"),
    ("analyses.drive_event.samples", 1, r"\[analyses.drive_event\] samples: .*>= 2"),
    ("analyses.drive_event.method", "Euler", r"\[analyses.drive_event\] method: expected one of"),
    ("analyses.drive_event.max_step", "1e-9 s",
     r"\[analyses.drive_event\] max_step: .* \(limit MAX_DRIVE_STEPS\)"),
    ("analyses.drive_event.outputs", ["q1", "q1"], r"\[analyses.drive_event\] outputs: .*distinct"),
    ("analyses.drive_event.mechanism", "crane2",
     r"\[analyses.drive_event\] mechanism: expected one of the \[mechanisms\] \['crane'\]"),
    ("mechanisms.crane.form", "second", r"\[mechanisms.crane\] form: expected one of"
                                        r" \['rheolinear', 'second_kind'\].*did you mean"),
    ("mechanisms.crane.form", None,
     r"\[analyses.drive_event\] mechanism: a drive event needs the nonlinear equations: set"
     r" form = 'second_kind' in \[mechanisms.crane\]"),
    ("mechanisms.crane.parameters.g", "9.81 m/s",
     r"\[mechanisms.crane.parameters\] g: expected an acceleration"),
])
def test_bad_scene_values_are_one_line_errors_at_their_key(path, value, fragment):
    data = _scene_dict()
    _set(data, path, value)
    with pytest.raises(SceneError) as info:
        Scene.from_dict(data, EXAMPLES, "crane.toml")
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith("crane.toml: ")
    assert re.search(fragment, message), message


@pytest.mark.parametrize(("key", "value", "fragment"), [
    ("drive", "q3", r"drive: expected one of the drive coordinates \['q4'\]"),
    ("outputs", ["q3", "spring3"], r"outputs: expected coordinates or spring forces .*"
                                   r"'spring2'\], got 'spring3'"),
])
def test_names_are_checked_against_the_built_mechanism(key, value, fragment):
    data = _scene_dict()
    data["analyses"]["drive_event"][key] = value
    scene = Scene.from_dict(data, EXAMPLES, "crane.toml")  # names: known once built
    with pytest.raises(SceneError, match=r"^crane.toml: \[analyses.drive_event\] " + fragment):
        prepare(scene)


def test_second_kind_mechanisms_are_refused_where_rheolinear_is_needed():
    data = _scene_dict()
    data["analyses"] = {"sweep": {"mechanism": "crane", "angles": [4.0, 4.5]}}
    with pytest.raises(SceneError, match=r"\[analyses.sweep\] mechanism: .*form ="
                                         r" 'second_kind'; quasi-modes need form = 'rheolinear'"):
        Scene.from_dict(data, EXAMPLES, "crane.toml")


# --- the scene: end to end -----------------------------------------------------------------

def test_crane_scene_runs_end_to_end(tmp_path, monkeypatch):
    out = tmp_path / "out"
    panels = []
    plot = histories.plot_event_histories

    def record(histories, *args, **kwargs):
        panels.extend(histories)
        return plot(histories, *args, **kwargs)

    monkeypatch.setattr(histories, "plot_event_histories", record)
    assert main(["run", str(TOML), "--out", str(out), "--no-cache", "-q"]) == 0
    files = {"drive_event.png", "report.html", "results.json", "run.log",
             "drive_event_braking_0p2s.csv", "drive_event_braking_0p5s.csv",
             "drive_event_braking_1s.csv"}
    assert files <= {p.name for p in out.iterdir()}
    assert (out / "drive_event.png").stat().st_size > 20_000
    numbers = json.loads((out / "results.json").read_text())["drive_event"]
    assert numbers["tripped"] is True
    # the scene computes what the example computes: the former example's numbers
    assert numbers["t_trip_s"] == pytest.approx(OLD_T_TRIP, abs=1e-8)
    peaks = {r["braking_time_s"]: r["peak_drive_force"] for r in numbers["runs"]}
    assert peaks == pytest.approx(OLD_PEAK, abs=0.05)
    # verify = true: the change at 10x tighter tolerances is at the tolerance level
    assert numbers["accuracy"]["checked"] is True
    assert numbers["accuracy"]["peak_force_change"] < 0.05  # N (measured 1.2e-3)
    data = np.loadtxt(out / "drive_event_braking_0p2s.csv", delimiter=",", skiprows=1)
    header = (out / "drive_event_braking_0p2s.csv").read_text().splitlines()[0]
    assert header == "t_s,force_N,q4_m,q1_m,q2_rad,q3_rad,spring1_N,spring2_N"
    assert data.shape == (2999, 8)
    # bound: the CSV holds 10 significant digits: rounding 5e-11 relative
    assert data[:, 1].max() == pytest.approx(OLD_PEAK[0.2], rel=1e-9)  # 10 digits in CSV
    report = (out / "report.html").read_text(encoding="utf-8")
    assert "Drive-force trip and braking" in report
    assert "peak cylinder force" in report
    assert "front axle force" in report
    assert "390.6 kN" in report  # the 0.2 s peak in the table
    # readable names with the raw ones in brackets (mechanisms.catalogue); CSV: raw names
    assert "extreme chassis heave [q1] after the trip" in report
    assert "extreme front axle force [spring1] after the trip" in report
    assert [p.split("\n")[0] for p in panels] == [
        "cylinder force [force]", "cylinder length [q4]", "chassis heave [q1]",
        "chassis pitch [q2]", "pendulum angle [q3]", "front axle force [spring1]",
        "rear axle force [spring2]"]


def _shaft_scene(**event):
    """A built-in model whose coordinates' dimensions femmech does not record."""
    return {"mechanisms": {"m": {"model": "table_5_1_case", "options": {"case": 1},
                                 "form": "second_kind"}},
            "analyses": {"drive_event": {"drive": "theta", "speed": "100 rpm",
                                         "ramp_time": "1 s", "trip_force": "50 N*m",
                                         "braking_times": ["0.1 s"], "t_max": "5 s",
                                         **event}}}


def test_drive_dimension_comes_from_the_unit_of_start():
    spec = Scene.from_dict(_shaft_scene(start="10 deg"), ".", "s.toml").analyses.drive_event
    assert spec.rotational
    assert spec.start == pytest.approx(np.radians(10))
    assert spec.speed == pytest.approx(100 * 2 * np.pi / 60)
    assert spec.mechanism == "m"  # the only mechanism of form second_kind
    with pytest.raises(SceneError, match=r"start: expected a length or an angle with its unit"):
        Scene.from_dict(_shaft_scene(start=0.0), ".", "s.toml")  # m or rad? not known
    with pytest.raises(SceneError, match=r"speed: expected a linear speed"):
        Scene.from_dict(_shaft_scene(start="0 m"), ".", "s.toml")  # a length: m/s expected
