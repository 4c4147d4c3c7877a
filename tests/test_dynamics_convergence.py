"""No silent wrong numbers in periodic dynamics.

Fixed step counts gave Floquet multipliers and periodic steady states that were wrong at
low drive speed without a word (the press example at 10 rpm: spectral radius NaN at
128 Magnus steps, 0.00029 at 256, converged 0.00525). Monodromy matrices and steady
states now double their steps until a stated tolerance is met, put step boundaries on
the jumps of piecewise motion laws, and mark what did not converge in the result, the
chart, the CSV and the report.
"""

import csv
import tomllib
import warnings

import numpy as np
import pytest
import scipy.linalg as sla
import sympy
from models import simply_supported_beam  # simply supported 1 m beam, uy bending
from numpy.testing import assert_allclose

import femmech as fm
from femmech.analysis.floquet import coupled_floquet, coupled_monodromy, monodromy
from femmech.analysis.magnus import expm_stack
from femmech.analysis.response import periodic_steady_state, rayleigh_damping
from femmech.analysis.stability import stability_chart
from femmech.coupling import Attachment, Mount, couple, drive_breakpoints
from femmech.mechanisms import (
    CamProfile,
    CamSegment,
    Damper,
    Mechanism,
    PointMass,
    RotaryInertia,
    Spring,
    modified_sine,
    polynomial_345,
    position_function,
    rheolinear,
)
from femmech.output.stability_charts import stability_figure
from femmech.reduction.component_modes import craig_bampton
from femmech.scene.build import prepare
from femmech.scene.load import Scene, load_scene
from femmech.scene.run import run_scene
from femmech.scene.workshop import Workshop

ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]
CAM = CamProfile((CamSegment(np.pi / 2, 0.02, polynomial_345()), CamSegment(np.pi / 2, 0.0),
                  CamSegment(np.pi / 2, -0.02, modified_sine()), CamSegment(np.pi / 2, 0.0)))
OFFSET_CAM = CamProfile(CAM.segments, phi_start=0.3)  # joints off any uniform grid


# --- the pieces --------------------------------------------------------------------------

def test_expm_stack_matches_scipy():
    # Scaling and squaring with the degree-18 Taylor polynomial (Bader, Blanes & Casas
    # 2019; Higham's [13/13] Padé of the earlier integrator) has backward error below the unit
    # round-off; against scipy's Padé (matrix by matrix, other rounding) the forward
    # difference is bounded by the condition of the exponential, at most about ‖A‖₁
    # times eps relative to |e^A|: 50 eps max(1, ‖A‖₁) (measured at most 0.03 of it
    # with Padé, 0.02 with Taylor-18; 12 squarings at ‖A‖₁ ≈ 3.6e3).
    rng = np.random.default_rng(3)
    G = rng.standard_normal((6, 9, 9)) / 3.0  # non-normal
    G -= np.linalg.eigvals(G).real.max(axis=1)[:, None, None] * np.eye(9)  # |e^A| ~ 1
    A = np.array([0.0, 1e-3, 1.0, 30.0, 300.0, 1e3])[:, None, None] * G
    for a, e in zip(A, expm_stack(A), strict=True):
        ref = sla.expm(a)
        bound = 50 * np.finfo(float).eps * max(1.0, np.abs(a).sum(axis=0).max())
        assert np.abs(e - ref).max() <= bound * max(np.abs(ref).max(), 1.0)


def test_cam_profile_breakpoints_are_segment_and_piece_joints():
    # segments start at 0, 90, 180, 270 deg; the modified sine has pieces at 1/8, 7/8
    # of its 90 deg rise: 180 + 11.25 and 180 + 78.75 deg
    expected = np.deg2rad([0.0, 90.0, 180.0, 191.25, 258.75, 270.0])
    # bound: breakpoints from degree sums in radians: ~10 eps of 2π
    assert_allclose(CAM.breakpoints(), expected, atol=1e-12)
    shifted = CamProfile(CAM.segments, phi_start=np.deg2rad(100.0))
    # bound: breakpoints from degree sums in radians, mod 2π: ~10 eps of 2π
    assert_allclose(shifted.breakpoints(), np.sort(np.mod(expected + np.deg2rad(100.0),
                                                          2 * np.pi)), atol=1e-12)


def _cam_model(argument_scale=1, argument_offset=0.0, cam=CAM):
    """Table 5.1 case 1 cam follower with dampers; U evaluated at a θ + b."""
    theta, q1, yg, q2 = sympy.symbols("theta q1 y_g q2")
    J1, m2, c1, c2, d1, d2 = sympy.symbols("J1 m2 c1 c2 d1 d2")
    x2 = yg + position_function("U")(argument_scale * (theta + q1) + argument_offset) + q2
    mech = Mechanism((q1, yg, q2, theta),
                     (RotaryInertia(J1, theta + q1), PointMass(m2, (x2,)), Spring(c1, q1),
                      Spring(c2, q2), Damper(d1, q1), Damper(d2, q2)), drives=(theta,))
    return rheolinear(mech, {"J1": 0.05, "m2": 3.0, "c1": 2e4, "c2": 5e5, "d1": 2.0,
                             "d2": 80.0}, {"U": cam})


def test_mechanism_breakpoints_follow_the_argument_of_the_position_function():
    # U(2θ + 0.3): a joint at ψ_b is met where 2θ + 0.3 ≡ ψ_b, twice per revolution
    model = _cam_model(2, 0.3)
    psi = CAM.breakpoints()
    theta = model.breakpoints()
    assert theta.size == 2 * psi.size
    assert np.all((theta >= 0) & (theta < 2 * np.pi))
    # bound: breakpoints from degree sums in radians, mod 2π: ~10 eps of 2π
    assert_allclose(np.sort(np.mod(2 * theta + 0.3, 2 * np.pi)),
                    np.sort(np.concatenate([psi, psi])), atol=1e-12)
    assert_allclose(_cam_model().breakpoints(), psi, atol=1e-12)


@pytest.fixture(scope="module")
def cam_machine():
    """The cam follower on a simply supported beam (tests/test_stability.py), damped."""
    system = couple(craig_bampton(simply_supported_beam(20), "mid", n_modes=4),
                    [Mount(_cam_model(cam=OFFSET_CAM), (Attachment("y_g", 10, "uy"),),
                           name="cam")])
    return rayleigh_damping(system, 1.0, 1e-5)


def test_drive_breakpoints_follow_ratio_and_phase(cam_machine):
    # a mount geared 3:1 with phase 0.2 rad meets each joint three times per main turn
    geared = couple(cam_machine.frame, [Mount(cam_machine.mounts[0].model,
                                              cam_machine.mounts[0].attachments, ratio=3.0,
                                              phase=0.2)])
    phi = drive_breakpoints(geared)
    assert phi.size == 3 * OFFSET_CAM.breakpoints().size
    # bound: breakpoints from degree sums in radians, mod 2π: ~10 eps of 2π
    assert_allclose(np.sort(np.mod(3 * phi + 0.2, 2 * np.pi)),
                    np.sort(np.tile(OFFSET_CAM.breakpoints(), 3)), atol=1e-12)


# --- step boundaries on jumps ------------------------------------------------------------

def test_steps_on_breakpoints_keep_the_order_across_a_coefficient_jump():
    # C jumps from 40 to 90 N/m at t_b = 0.37 T: the exact monodromy matrix is the
    # product of the two constant-coefficient exponentials. Magnus is exact on each
    # constant piece, so with the jump on a step boundary only round-off remains
    # (each of ≤ 100 step products adds a few eps relative: ~1e-13 at most, measured
    # 1.2e-14; bound 1e-12); a step across the jump integrates a
    # discontinuous A with a two-point Gauss rule: error O(h), measured 1e-3 .. 1e-2.
    T, tb, c1, c2, b = 1.0, 0.37, 40.0, 90.0, 0.4

    def C(t):
        return np.where(np.mod(t, T) < tb, c1, c2)[:, None, None]

    def A(c):
        return np.array([[0.0, 1.0], [-c, -b]])

    exact = sla.expm(A(c2) * (T - tb)) @ sla.expm(A(c1) * tb)
    for n in (8, 33, 100):
        aligned = monodromy(1.0, b, C, T, n, rtol=None, breakpoints=[tb])
        # bound: products of n <= 100 step exponentials (expm to eps): ~n eps of the largest
        assert np.abs(aligned - exact).max() < 1e-12 * np.abs(exact).max()
    across = [np.abs(monodromy(1.0, b, C, T, n, rtol=None) - exact).max() for n in (16, 32)]
    assert min(across) > 1e-4  # what ignoring the jump costs
    # the adaptive path knows nothing of the jump here, but does not stop before it
    # has settled: it keeps doubling (first order) and meets rtol with many steps
    checked = monodromy(1.0, b, C, T, rtol=1e-5, max_steps=2**16, full_output=True)
    assert checked.converged
    assert abs(checked.spectral_radius - np.abs(np.linalg.eigvals(exact)).max()) < \
        1e-5 * checked.spectral_radius


def test_coupled_cam_machine_converges_at_fourth_order_with_joints_on_step_boundaries(
        cam_machine, monkeypatch):
    # The cam's joints (jerk jumps of the 3-4-5 law, piece joints of the modified sine)
    # lie off any uniform grid (phi_start = 0.3 rad). On step boundaries the global
    # error of Φ falls as h⁴ (measured 0.0043, 2.7e-4, 1.7e-5 at 128, 256, 512 steps
    # against 8192, |Φ| = 349); steps across them lose the order (0.0046, 0.012, 7e-4).
    Omega = 60.0
    ref = coupled_monodromy(cam_machine, Omega, 8192, rtol=None)

    def errors():
        return np.array([np.abs(coupled_monodromy(cam_machine, Omega, n, rtol=None)
                                - ref).max() for n in (128, 256, 512)])

    aligned = errors()
    assert np.all(aligned[:-1] / aligned[1:] > 10)  # 16 for fourth order
    import femmech.analysis.floquet as floquet

    monkeypatch.setattr(floquet, "drive_breakpoints", lambda *_: np.zeros(0))
    across = errors()
    assert across[-1] > 10 * aligned[-1]


# --- error control and marking ------------------------------------------------------------

@pytest.fixture(scope="module")
def press():
    """The slider-crank press of examples/press_frame.toml (25 coordinates), damped as
    in its stability analysis."""
    scene = load_scene(ROOT / "examples" / "press_frame.toml")
    workshop = Workshop(prepare(scene), None, lambda line: None, False)
    return rayleigh_damping(workshop.machine(), 2.0, 1e-5)


RPM = 2 * np.pi / 60
# Spectral radius of the press at 30 rpm by two integrators of the same first-order
# system: Magnus-4 with rtol 1e-8 (32 768 steps per period): 0.0917735369; the
# exponential midpoint rule (second order, symmetric) at 2^16 and 2^17 steps,
# Richardson-extrapolated: 0.0917735368. They agree to 1e-9 relative.
PRESS_30_RPM = 0.09177353


def test_low_speed_point_is_within_its_tolerance_of_the_converged_value(press):
    # the old fixed default (128 steps per period) is 28 % off at 30 rpm
    fixed = coupled_monodromy(press, 30 * RPM, 128, rtol=None, full_output=True)
    assert abs(fixed.spectral_radius - PRESS_30_RPM) > 0.2 * PRESS_30_RPM
    result = coupled_floquet(press, 30 * RPM, rtol=1e-3)
    assert result.converged
    assert result.n_steps >= 1024
    assert result.error <= 1e-3 * result.spectral_radius
    assert abs(result.spectral_radius - PRESS_30_RPM) <= result.error  # measured 1/20 of it


def test_unconverged_point_is_marked_and_warned(press):
    with pytest.warns(fm.ConvergenceWarning, match="did not converge"):
        record = coupled_monodromy(press, 30 * RPM, 32, max_steps=256, full_output=True)
    assert record.converged is False
    assert record.error > 1e-4 * record.spectral_radius
    with pytest.warns(fm.ConvergenceWarning, match="1 of 2 stability-chart points"):
        chart = stability_chart(press, [30 * RPM, 1500 * RPM], max_steps=256)
    assert chart.converged.tolist() == [[False, True]]
    assert chart.unconverged.tolist() == [[True, False]]
    # the chart draws the unconverged speed hatched and keeps it off the curve
    fig = stability_figure(chart, speed_unit="rpm")
    ax = fig.axes[0]
    hatched = [p for p in ax.patches if p.get_hatch()]
    assert len(hatched) == 1
    x0, x1 = hatched[0].get_x(), hatched[0].get_x() + hatched[0].get_width()
    assert x0 <= 30.0 <= x1
    curve = ax.lines[1].get_ydata()  # [0] is the 1 + tol line
    assert np.isnan(curve[0])
    assert np.isfinite(curve[1])
    assert "not converged" in [t.get_text() for t in ax.get_legend().get_texts()][0]


def test_periodic_steady_state_is_checked_and_marked(cam_machine):
    W = 2 * np.pi * 2.0
    good = periodic_steady_state(cam_machine, W, n_steps=64)
    assert good.converged
    assert good.error <= 1e-3
    assert good.n_steps > 64
    assert good.q.shape == (65, cam_machine.n)  # the output grid the user asked for
    # one more doubling changes q by about a quarter of the estimate (second order)
    finer = periodic_steady_state(cam_machine, W, n_steps=2 * good.n_steps, rtol=None)
    every = 2 * good.n_steps // 64
    change = np.abs(finer.q[::every] - good.q).max() / np.abs(good.q).max()
    assert change <= good.error  # measured 0.3 of it
    with pytest.warns(fm.ConvergenceWarning, match="did not converge"):
        loose = periodic_steady_state(cam_machine, W, n_steps=64, max_steps=128)
    assert loose.converged is False
    assert loose.error > 1e-3


# --- the scene: chart, CSV and report ----------------------------------------------------

def test_scene_marks_unconverged_points_in_chart_csv_and_report(tmp_path):
    data = tomllib.loads((ROOT / "examples" / "press_frame.toml").read_text())
    data["analyses"] = {
        "stability": {"speeds": ["10 rpm", "1500 rpm"], "max_steps": 256,
                      "rayleigh": {"mass": "2 1/s", "stiffness": "1e-5 s"}},
        "response": {"kind": "periodic", "speed": "600 rpm", "n_steps": 8, "max_steps": 16,
                     "outputs": ["press.q"],
                     "rayleigh": {"mass": "2 1/s", "stiffness": "1e-5 s"}}}
    scene = Scene.from_dict(data, ROOT / "examples", "press_low_speed.toml")
    with warnings.catch_warnings():
        warnings.simplefilter("error", fm.ConvergenceWarning)  # marked, not warned
        result = run_scene(scene, tmp_path, cache_dir=None)
    with open(tmp_path / "stability.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["converged"] for r in rows] == ["0", "1"]
    assert rows[0]["stable"] == ""  # no verdict from an unconverged number
    assert rows[1]["stable"] == "1"
    assert float(rows[1]["error_estimate"]) <= 1e-4 * float(rows[1]["spectral_radius"])
    html = (tmp_path / "report.html").read_text()
    assert html.count('class="warning"') == 2  # stability and response
    assert "did NOT converge" in html
    assert "NOT CONVERGED" in html
    assert result.results["stability"]["converged"] == [False, True]
    assert result.results["response"]["convergence"]["converged"] is False
