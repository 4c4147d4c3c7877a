"""Acceptance on the machines: power balance of the drive force, coupled Floquet
multipliers against direct integration, the Ritz-basis monodromy, support reactions and
the steady-state / stability sections of the coupled-machine examples."""

import dataclasses
import importlib.util
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
import sympy
from models import PARAMS, simply_supported_beam
from numpy.testing import assert_allclose
from scipy.integrate import cumulative_simpson, solve_ivp

from femmech.analysis.floquet import coupled_monodromy, floquet, quasi_modal_basis
from femmech.analysis.forces import drive_forces, support_reactions
from femmech.analysis.response import (
    ConstantSpeed,
    periodic_steady_state,
    rayleigh_coefficients,
    rayleigh_damping,
)
from femmech.analysis.stability import resonance_speeds, stability_chart
from femmech.coupling import Attachment, Mount, couple
from femmech.mechanisms import CamProfile, CamSegment, harmonic, rheolinear, second_kind
from femmech.output.histories import plot_orbit, plot_time_histories, write_history_csv
from femmech.reduction.component_modes import craig_bampton

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _load(name):
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


# --- power balance of the drive force (acceptance) --------------------------------------

def test_crane_cylinder_force_balances_the_power_flow():
    # Crane braking case (examples/crane_braking.py, seed 5.2.3.1): no dampers, so the
    # power the cylinder puts in, Q4 q4', must equal the rate of change of T + V:
    # ∫ Q4 q4' dt = E(t) - E(0), E = ½ q'ᵀ M(q) q' + V(q) over all four coordinates
    # (the drive included), V the chapter's potential (eq. 13, errata 24) from the
    # symbolic model. Q4 comes from the force recovery (the drive row, eq. 17), E from
    # the mass matrix and potential: independent evaluations of the same model.
    cb = _load("crane_braking")
    run = cb.simulate(0.5)
    m = cb.model()
    coords = m.mechanism.coordinates
    potential = m.terms.potential
    V = sympy.lambdify(coords, potential.subs({s: m.parameters[s.name] for s in
                                               potential.free_symbols
                                               if s.name in m.parameters}), "numpy")
    T = 0.5 * np.einsum("ti,tij,tj->t", run.qd, m.M(run.q), run.qd)
    E = T + V(*run.q.T)
    power = run.Q4 * run.qd[:, 3]
    for part in (slice(None, 1499), slice(1499, None)):  # the two integration segments
        t, P, dE = run.t[part], power[part], E[part] - E[part][0]
        work = cumulative_simpson(P, x=t, initial=0.0)
        scale = np.abs(work).max()
        # Simpson on 1500 samples per segment: O(h⁴) quadrature error; the integrator's
        # rtol 1e-10 is far below. Measured 2.4e-7 and 1.5e-8 of the work done.
        assert np.abs(work - dE).max() < 2e-6 * scale
    assert np.abs(power).max() > 1e3  # W: the check is not trivially 0 = 0


# --- coupled Floquet multipliers vs direct integration (acceptance) ---------------------

@pytest.fixture(scope="module")
def small_cam_system(damped_cam_system):
    """The damped cam on the beam with a harmonic cam (rise and return by half cosines:
    a full cosine, smooth in all derivatives) and the beam reduced to 2 fixed-interface
    modes at the guide's uy (5 coordinates, highest frame frequency 677 Hz), so that an
    explicit adaptive reference solver takes few steps."""
    mech = damped_cam_system.mounts[0].model.mechanism
    cam = CamProfile((CamSegment(np.pi, 0.02, harmonic()), CamSegment(np.pi, -0.02, harmonic())))
    model = rheolinear(mech, {**PARAMS, "d1": 2.0, "d2": 80.0}, {"U": cam})
    se = craig_bampton(simply_supported_beam(), [("mid", ["uy"])], n_modes=2,
                       residual_vectors=False)
    system = couple(se, [Mount(model, (Attachment("y_g", 20, "uy"),), name="cam")])
    return dataclasses.replace(system, B0=system.B0 + 1.0 * system.M0 + 1e-5 * system.K0)


def test_coupled_multipliers_match_direct_integration(small_cam_system):
    # Reference: Φ' = A(t) Φ integrated by DOP853 (rtol 1e-11) with M, B, C from
    # CoupledSystem.matrices at every stage (the per-angle public path), independent of
    # the vectorised Magnus scheme. Magnus-4, measured: 6.6e-6 (128 steps) and 4.0e-7
    # (256 steps) of max|Φ| on Φ (ratio 16.6: fourth order), 4.3e-9 on the multipliers.
    system, Omega = small_cam_system, 60.0
    n = system.n
    T = 2 * np.pi / Omega

    def rhs(t, y):
        M, B, C = system.matrices(Omega * t, Omega)[:3]
        X = np.linalg.solve(M, np.hstack([C, B]))
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-X]])
        return (A @ y.reshape(2 * n, 2 * n)).ravel()

    # bound: integrator tolerances of the DOP853 reference, not test tolerances
    ref = solve_ivp(rhs, (0.0, T), np.eye(2 * n).ravel(), method="DOP853", rtol=1e-11,
                    atol=1e-11).y[:, -1].reshape(2 * n, 2 * n)
    errors = [np.abs(coupled_monodromy(system, Omega, n_steps=k, rtol=None) - ref).max()
              / np.abs(ref).max() for k in (128, 256)]  # fixed steps: the order
    assert errors[1] < 2e-6
    assert errors[0] / errors[1] > 12  # 16 for fourth order
    mu = floquet(coupled_monodromy(system, Omega, n_steps=256), T).multipliers
    assert_allclose(np.sort_complex(mu), np.sort_complex(floquet(ref, T).multipliers),
                    atol=5e-8)
    assert 0.1 < np.abs(mu).max() < 1  # damped, yet not decayed to nothing in one period


def test_ritz_basis_monodromy_converges(damped_cam_system):
    # The full monodromy (all 20 coupled coordinates, residual-vector modes included) is
    # the reference; the projected one keeps the lowest quasi-modes at 8 angles. The
    # spectral radius belongs to the least damped slow motion, so a few modes suffice.
    # Measured relative errors 8.8e-6 (1 branch, 3 columns), 2.0e-6 (4 branches, 5
    # columns), 2.5e-6 (8 branches): the floor is the quasi-static contribution of the
    # dropped stiff modes, far below what a stability verdict needs.
    system, Omega = damped_cam_system, 30.0
    full = np.abs(np.linalg.eigvals(coupled_monodromy(system, Omega, 128))).max()
    errors = []
    for n_modes in (1, 4, 8):
        V = quasi_modal_basis(system, n_modes)
        assert V.shape[0] == system.n
        assert V.shape[1] <= 8 * n_modes
        # bound: an orthonormalised basis (QR): ~n eps
        assert_allclose(V.T @ V, np.eye(V.shape[1]), atol=1e-12)
        reduced = np.abs(np.linalg.eigvals(coupled_monodromy(system, Omega, 128,
                                                             basis=V))).max()
        errors.append(abs(reduced / full - 1))
    assert errors[0] < 2e-5
    assert max(errors[1:]) < 5e-6


def test_basis_errors(damped_cam_system):
    system = damped_cam_system
    with pytest.raises(ValueError, match="basis must have shape"):
        coupled_monodromy(system, 30.0, 8, basis=np.ones((3, 2)))
    with pytest.raises(ValueError, match="linearly dependent"):
        coupled_monodromy(system, 30.0, 8, basis=np.ones((system.n, 2)))
    with pytest.raises(ValueError, match="n_modes"):
        quasi_modal_basis(system, 0)


# --- small pieces ----------------------------------------------------------------------

def test_rayleigh_coefficients_hit_the_ratio_at_both_frequencies():
    a, b = rayleigh_coefficients(0.03, 50.0, 400.0)
    for f in (50.0, 400.0):
        w = 2 * np.pi * f
        # bound: closed-form Rayleigh coefficients, a few operations: a few eps
        assert a / (2 * w) + b * w / 2 == pytest.approx(0.03, rel=1e-14)
    assert a / (2 * 2 * np.pi * 150) + b * 2 * np.pi * 150 / 2 < 0.03  # lower inside
    with pytest.raises(ValueError, match="f1_hz < f2_hz"):
        rayleigh_coefficients(0.03, 400.0, 50.0)


def test_growth_rate_of_a_time_invariant_oscillator_is_minus_zeta_omega():
    # x'' + 2ζω x' + ω² x = 0 "driven" at any speed: μ = exp((−ζω ± iω_d) T), so
    # ln|μ|/T = −ζω exactly, whatever the speed (while the radius itself varies).
    omega, zeta = 8.0, 0.02

    def system(Omega):
        return 1.0, 2 * zeta * omega, omega**2, 2 * np.pi / Omega

    chart = stability_chart(system, [3.0, 7.0, 20.0], n_steps=16)
    # bound: Magnus of a constant-coefficient system is exact: expm round-off ~n_steps eps
    assert_allclose(chart.growth_rate, -zeta * omega, rtol=1e-10)
    assert np.ptp(chart.spectral_radius) > 0.1


def test_resonance_speeds():
    marks = resonance_speeds([10.0, 25.0], orders=(1, 2), within=(0.0, 100.0))
    # 2 f / j in rad/s: 2·2π·10/1 = 125.7 is outside, 62.8 inside; f2: 157 and 314 out
    assert marks == pytest.approx({"2f1/2": 2 * np.pi * 10.0})
    forced = resonance_speeds([10.0], orders=(1,), kind="forced")
    assert forced == pytest.approx({"f1/1": 2 * np.pi * 10.0})
    with pytest.raises(ValueError, match="kind"):
        resonance_speeds([10.0], kind="combination")


def test_history_plots_and_csv(tmp_path):
    t = np.linspace(0.0, 1.0, 50)
    out = plot_time_histories(t, {"x (m)": {"a": np.sin(t), "b": np.cos(t)},
                                  "y (N)": {"c": t}}, tmp_path / "h.png", title="h")
    assert out.stat().st_size > 5000
    assert plot_orbit(np.cos(6 * t), np.sin(6 * t), tmp_path / "o.png").stat().st_size > 5000
    csv = write_history_csv(t, {"a": np.sin(t)}, tmp_path / "h.csv")
    # bound: CSV of repr-precision floats: round trip to ~1 ulp
    assert_allclose(np.loadtxt(csv, delimiter=",", skiprows=1)[:, 1], np.sin(t), rtol=1e-9)
    with pytest.raises(ValueError, match="panel 'x', curve 'a'"):
        plot_time_histories(t, {"x": {"a": t[:3]}}, tmp_path / "bad.png")
    with pytest.raises(ValueError, match="column 'a'"):
        write_history_csv(t, {"a": t[:3]}, tmp_path / "bad.csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["h.csv", "h.png", "o.png"]


# --- support reactions -----------------------------------------------------------------

@pytest.fixture(scope="module")
def processing():
    pm = _load("processing_machine")
    base, _, model, _ = pm.build()
    rayleigh = rayleigh_coefficients(pm.FRAME_ZETA, *pm.ZETA_BAND_HZ)
    return pm, rayleigh_damping(base, *rayleigh), model, rayleigh


def test_drive_end_torque_is_the_cams_torque_at_low_speed(processing):
    # At 30 rpm the cams' harmonics that matter lie far below the shaft's torsion modes
    # (~90 Hz), so the shaft transmits the cam torques quasi-statically: the reaction
    # at the kinematic drive end equals the sum of the cams' drive rows (seed 5.2.2 eq.
    # 2, j = n+1) up to the shaft's own inertia torque. Measured 6.8e-5 of the peak.
    pm, system, model, rayleigh = processing
    W = 2 * np.pi * 30 / 60
    r = periodic_steady_state(system, W, n_steps=720, rho_inf=1.0)
    drive = ConstantSpeed(W)
    motor = support_reactions(system, model, r, [("drive_end", "rx")], *rayleigh)[:, 0]
    rows = sum(drive_forces(lg, r, drive, system, mount=k)[:, 0]
               for k, lg in enumerate(pm.cam_models(second_kind)))
    assert np.abs(motor - rows).max() < 5e-4 * np.abs(rows).max()
    with pytest.raises(ValueError, match="is not supported"):
        support_reactions(system, model, r, [("drive_end", "uy")])


# --- the examples' steady-state and stability sections ---------------------------------

def test_press_dynamics(tmp_path):
    # Quasi-static check at bottom dead centre (φ = 0): the ram accelerates with
    # ẍ = -r Ω² (1 + r/l) (slider-crank, e.g. Dresig & Holzweißig, Maschinendynamik,
    # ch. 2), so the output elasticity carries q = m2 r Ω² (1 + r/l) / c2 and the crank
    # bearing the force m2 r Ω² (1 + r/l) (the crank's mass is neglected). At 600
    # strokes/min the first frame mode (60 Hz) and the ram mode lie far above the
    # speed's harmonics that matter; measured deviations 0.25 % for both.
    press = _load("press_frame")
    result = press.dynamics(tmp_path, n_speeds=3, zetas=(0.005, 0.02))
    p, g = press.PARAMS, press.GEOMETRY
    W = 2 * np.pi * press.OPERATING_SPM / 60
    inertia = p["m2"] * g["r"] * W**2 * (1 + g["r"] / g["l"])  # N
    r, forces = result["steady_state"], result["forces"]
    q_ram = r.q[0, result["system"].labels.index("press.q")]
    assert q_ram == pytest.approx(inertia / p["c2"], rel=1e-2)
    assert forces.forces[0, 0] == pytest.approx(inertia, rel=1e-2)
    # at both dead centres the rod lies on the slider axis: no lateral guide force
    # beyond the ram's lateral inertia on the vibrating gib (measured 3.6e-3 at BDC and
    # 4.2e-4 at TDC of the bearing force at BDC)
    for k in (0, 360):
        assert abs(forces.forces[k, 2]) < 5e-3 * abs(forces.forces[0, 0])
    study = result["study"]
    assert study.chart.spectral_radius.shape == (2, 3)
    assert study.line.stable.all()  # damped press: stable in 100..3000 strokes/min
    # the study covers the speeds the scene asks for ([analyses.stability] speeds of
    # press_frame.toml, read independently here): first and last speed, also in the chart
    scene = tomllib.loads((EXAMPLES / "press_frame.toml").read_text())["analyses"]
    asked = scene["stability"]["speeds"]
    assert (asked["start"], asked["stop"]) == ("100 rpm", "3000 rpm")
    rpm = 30 / np.pi  # rad/s -> rpm
    for drawn in (study.line, study.chart):
        # bound: rpm -> rad/s -> rpm in float64, a few eps of 3000
        assert drawn.speeds[[0, -1]] * rpm == pytest.approx([100.0, 3000.0], rel=1e-12)
    for name in ("steady_state.png", "crank_bearing_orbit.png", "steady_state.csv",
                 "stability_speed.png", "stability_chart.png"):
        assert (tmp_path / name).stat().st_size > 1000


@pytest.mark.parametrize("name", ["processing_machine", "textile_shaft"])
def test_machine_dynamics_sections_run(tmp_path, name):
    module = _load(name)
    result = module.dynamics(tmp_path, n_speeds=2, zetas=(0.01, 0.02))
    r = result["steady_state"]
    # bound: periodic steady state solved to the linear solve's eps·cond of the harmonic system
    assert_allclose(r.q[-1], r.q[0], atol=1e-9 * np.abs(r.q).max())  # periodic
    assert result["study"].chart.spectral_radius.shape == (2, 2)
    for png in ("steady_state.png", "stability_speed.png", "stability_chart.png"):
        assert (tmp_path / png).stat().st_size > 1000
    assert (tmp_path / "steady_state.csv").stat().st_size > 1000
