"""Coupled-machine examples: processing machine (a) and press in a C-frame (c).

Each example is checked against (1) the mechanism-only quasi-eigenfrequencies of the
mechanism issue with a rigid frame and (2) its unreduced coupled model at several angles.
"""

import importlib.util
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.linalg import toeplitz

from femmech.analysis.sweep import sweep
from femmech.mechanisms import (
    CamProfile,
    CamSegment,
    SliderCrank,
    polynomial_345,
    processing_machine,
    processing_machine_cams,
    processing_machine_parameters,
    rheolinear,
    table_5_1_case,
)
from femmech.mechanisms.mounted import cam_follower, slider_crank

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
PHI = np.linspace(0.0, 2 * np.pi, 37)
CAM = CamProfile((CamSegment(np.pi / 2, 0.02, polynomial_345()), CamSegment(np.pi / 2, 0.0),
                  CamSegment(np.pi / 2, -0.02, polynomial_345()), CamSegment(np.pi / 2, 0.0)))


def _load(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# --- mounted mechanisms reduce to the chapter's models on a rigid frame -----------------

def test_slider_crank_on_fixed_frame_is_table_5_1_case_1():
    # Frame coordinates (u_b, v_b, v_g) zero: the q_t, q block must be Table 5.1 case 1
    # with U = SliderCrank(r, l, e) (errata §A), also at speed (kinematic terms of
    # errata 30) and with damping and a process force. Both are evaluated from
    # closed-form derivatives (sympy sqrt vs linkages.SliderCrank): round-off only.
    p = dict(J1=2.0, m2=100.0, c1=2e6, c2=2e9, b1=1.0, b2=10.0, F2=500.0)
    geometry = dict(r=0.05, l=0.4, e=0.01)
    mounted = rheolinear(slider_crank(), {**p, **geometry})
    ref = rheolinear(table_5_1_case(1), p, {"U": SliderCrank(**geometry)})
    assert mounted.coordinate_names == ("q_t", "u_b", "v_b", "v_g", "q")
    phi, own = np.linspace(0.0, 2 * np.pi, 25), [0, 4]
    block = np.ix_(range(25), own, own)
    # bound: the same closed-form entries summed in another order: a few eps relative; atol for
    # zeros, ~eps of O(1) entries
    assert_allclose(mounted.M(phi)[block], ref.M(phi), rtol=1e-12, atol=1e-12)
    for Omega, Omega_dot in ((0.0, 0.0), (30.0, 5.0)):
        # bound: same entries in another order: a few eps; atol: round-off of the largest entries
        assert_allclose(mounted.B(phi, Omega)[block], ref.B(phi, Omega), rtol=1e-12,
                        atol=1e-9)
        # bound: same entries in another order: a few eps relative; atol for the c2 = 2e9 entries'
        # round-off
        assert_allclose(mounted.C(phi, Omega, Omega_dot)[block], ref.C(phi, Omega, Omega_dot),
                        rtol=1e-12, atol=1e-6)  # atol: round-off of c2 = 2e9 entries
        # bound: same entries in another order: a few eps relative; atol: round-off of large entries
        assert_allclose(mounted.F(phi, Omega, Omega_dot)[:, own], ref.F(phi, Omega, Omega_dot),
                        rtol=1e-12, atol=1e-9)


def test_slider_crank_frame_coupling_at_dead_centre():
    # At bottom dead centre (φ = 0, e = 0) the rod is along the slider axis: U' = 0 and
    # ∂s/∂v = 0, so the crank twist and the lateral coordinates decouple from the ram,
    # while the bearing displacement along the axis moves the ram one to one.
    p = dict(J1=2.0, m2=100.0, c1=2e6, c2=2e9, b1=0.0, b2=0.0, F2=0.0)
    M = rheolinear(slider_crank(), {**p, "r": 0.05, "l": 0.4, "e": 0.0}).M([0.0])[0]
    expected = np.zeros((5, 5))
    expected[0, 0] = p["J1"]
    expected[np.ix_([1, 4], [1, 4])] = p["m2"]
    expected[3, 3] = p["m2"]  # ram carried across by the guide
    # bound: exact inertia entries (sums of O(10) masses): a few eps
    assert_allclose(M, expected, atol=1e-12)


def test_cam_follower_with_inertia_is_table_5_1_case_1():
    # With J given, no return spring and a fixed frame (y_c = y_f = 0), the cam follower
    # is Table 5.1 case 1 without the shaft spring c1 (the FE shaft provides it).
    p = dict(J1=0.05, m2=3.0, c1=2e4, c2=5e5, b1=0.0, b2=7.0, F2=40.0)
    mech = cam_follower("U", "m2", "c2", "c_r", "b2", "F2", J="J1")
    own_params = {k: v for k, v in p.items() if k not in ("c1", "b1")}
    mounted = rheolinear(mech, {**own_params, "c_r": 0.0}, {"U": CAM})
    ref = rheolinear(table_5_1_case(1), p, {"U": CAM})
    phi, own = np.linspace(0.0, 2 * np.pi, 25), [0, 3]
    block = np.ix_(range(25), own, own)
    # bound: same entries in another order: a few eps relative, atol ~eps of O(1e-2) entries
    assert_allclose(mounted.M(phi)[block], ref.M(phi), rtol=1e-12, atol=1e-14)
    shaft = np.diag([p["c1"], 0.0])
    # bound: same entries in another order: a few eps relative, atol for the c1 ~1e6 entries'
    # round-off
    assert_allclose(mounted.C(phi, 20.0, 3.0)[block] + shaft, ref.C(phi, 20.0, 3.0),
                    rtol=1e-12, atol=1e-8)


# --- (a) processing machine of seed 5.2.3.2 ------------------------------------------------

@pytest.fixture(scope="module")
def machine():
    return _load("processing_machine")


@pytest.fixture(scope="module")
def machine_run(machine, tmp_path_factory):
    out = tmp_path_factory.mktemp("processing_machine")
    return out, machine.main(out, n_angles=37, with_dynamics=False)


def test_processing_machine_shaft_gives_chapter_stiffness(machine):
    # Segment length L = G I_p / cT: the FE shaft's static torsional stiffness is cT
    # (the beam element's torsion is exact for uniform twist), 0.3211 m for d = 30 mm.
    lengths = machine.segment_lengths()
    G, J = machine.STEEL.shear_modulus, machine.SHAFT.J
    # bound: G J / L against the same formula in the example: a few eps
    assert_allclose(G * J / lengths, [machine.PARAMS["cT1"], machine.PARAMS["cT2"]], rtol=1e-14)
    assert_allclose(lengths, 80.769e9 * np.pi * 0.03**4 / 32 / 2e4, rtol=1e-4)


def test_processing_machine_rigid_frame_reproduces_chapter(machine):
    # Rigid bearings and return-spring bases (supported nodes): y_c = y_f = 0 exactly and
    # the shaft segments are the springs cT1, cT2, so the coupled system differs from the
    # chapter's 4-DOF model (errata 29-30, Ω = 0) only by the shaft's distributed mass.
    # That adds ~ρ I_p L (10 % of J1 for steel) to the disc inertias: the difference is
    # linear in the density (measured 2.9e-4 at 1e-2, 2.9e-6 at 1e-4, 2.9e-8 at 1e-6;
    # 2.8 % for the first torsion branch of the steel shaft).
    phi = PHI[::3]
    error_small, coupled, alone = machine.rigid_check(phi, rho_scale=1e-6)
    error_large, _, _ = machine.rigid_check(phi, rho_scale=1e-4)
    assert error_small < 1e-7
    assert 0.9e2 < error_large / error_small < 1.1e2
    assert coupled.freq_hz.shape == alone.freq_hz.shape == (phi.size, 4)


def test_processing_machine_reduced_matches_full(machine_run):
    # Acceptance at 5 angles (dwell, rises, returns), the 9 modes below 450 Hz
    # (follower, frame and shaft-torsion branches). The largest error is the shaft's
    # first torsion branch (~310 Hz): the interior torsional inertia of the shaft is
    # carried only by residual vectors, whose error is of order (f / f_t)⁴ = 1.6e-5 with
    # f_t = √(G/ρ) / (2 L) = 5.0 kHz the first truncated fixed-interface torsion mode;
    # measured 4.1e-6 (1.2e-6 with f_max doubled), every other branch < 1e-8. Tolerances
    # 2e-5 and MAC > 1 - 1e-6 (measured 1 - 2.8e-8), far inside 0.5 % and 0.95.
    out, result = machine_run
    assert result["max_error"] < 2e-5
    assert result["min_mac"] > 1 - 1e-6
    assert result["rigid_error"] < 1e-7  # see the rigid-frame test


def test_processing_machine_outputs(machine_run):
    out, result = machine_run
    sweep_ = result["sweep"]
    assert sweep_.form == "symmetric"
    assert sweep_.freq_hz.shape == (37, 9)
    # bound: periodic cams: the spectrum closes on itself after one revolution (round-off);
    # the follower branches come back exchanged: they cross near 36° (a veering of
    # only 0.03 Hz, which the MAC tracking follows as a crossing)
    assert_allclose(np.sort(sweep_.freq_hz[-1]), np.sort(sweep_.freq_hz[0]), rtol=1e-9)
    assert (out / "quasi_frequencies.png").stat().st_size > 10_000
    assert (out / "rigid_frame_check.png").stat().st_size > 10_000
    table = np.loadtxt(out / "quasi_frequencies.csv", delimiter=",", skiprows=1)
    n = sweep_.freq_hz.shape[1]  # columns: angle, n frequencies, n ζ, n MAC steps
    # bound: the CSV holds 10 significant digits: rounding 5e-11 relative
    assert_allclose(table[:, 1:1 + n], sweep_.freq_hz, rtol=1e-9)  # written to 10 digits


def _collocation_steady_state(model, Omega, n_points):
    """Periodic steady state of M q'' + B q' + C q = F (rheolinear model, constant speed
    Omega in rad/s) by Fourier collocation at n_points (even) equally spaced angles,
    q(t) = Q(Ω t), d/dt = Ω D with the periodic spectral differentiation matrix D
    (Trefethen, Spectral Methods in MATLAB, SIAM 2000, ch. 3). Independent of the
    time integrator and of the coupling: one dense solve of n_points x n unknowns.
    Returns Q (n_points, n) in the model's coordinates (m, rad)."""
    phi = 2 * np.pi * np.arange(n_points) / n_points
    k = np.arange(1, n_points)
    column = np.r_[0.0, 0.5 * (-1.0) ** k / np.tan(k * np.pi / n_points)]
    D = toeplitz(column, -column)
    M, B = model.M(phi), model.B(phi, Omega)
    C, F = model.C(phi, Omega, 0.0), model.F(phi, Omega, 0.0)
    n = M.shape[1]
    A = (Omega**2 * np.einsum("iab,ij->iajb", M, D @ D)
         + Omega * np.einsum("iab,ij->iajb", B, D))
    A[np.arange(n_points), :, np.arange(n_points), :] += C
    return np.linalg.solve(A.reshape(n_points * n, -1), F.reshape(-1)).reshape(n_points, n)


def test_processing_machine_follower_deformation_is_the_follower_resonance(machine):
    # At 1200 rpm the follower deformations reach 9.3 and 18.6 mm (cam 1, cam 2) against
    # strokes of 50 and 40 mm. The independent estimate is the steady state of the chapter's
    # 4-DOF model (rigid frame, elastic shaft: seed 5.2.3.2 eqs. 20-23, errata 29-33),
    # solved by Fourier collocation instead of time integration: 9.59 / 18.20 mm
    # (N = 512 and 1024 agree to 6e-5). The coupled model differs by -3.3 % / +1.9 %,
    # because the frame and bearings lower the follower branches by 0.4 to 0.7 %
    # (80.20-91.51 Hz coupled, 80.54-92.12 Hz rigid, 73 angles). Near resonance (dynamic
    # amplification 5.7 of the 4th harmonic, frequency ratio r = 0.914) the amplitude
    # changes by about 2r^2/(1 - r^2) = 10 times that shift, 4 to 7 %: bound 8 %.
    W = 2 * np.pi * machine.OPERATING_RPM / 60.0
    base, _, _, _ = machine.build()
    r, system, _ = machine.steady_state(base, steady_steps=machine.QUICK["steady_steps"])
    q = np.column_stack([r.q[:, system.labels.index(f"cam{k}.q")] for k in (1, 2)])
    chapter = rheolinear(processing_machine(kinematic_drive=True),
                         processing_machine_parameters(kinematic_drive=True),
                         processing_machine_cams())
    reference = np.abs(_collocation_steady_state(chapter, W, 512)[:, 2:]).max(axis=0)
    assert_allclose(reference, [9.59e-3, 18.20e-3], rtol=1e-3)
    assert_allclose(np.abs(q).max(axis=0), reference, rtol=0.08)
    # It is a resonance and not a slip: the quasi-static deformation under the peak
    # inertia force, m max|U''| Ω² / c (4.30 / 4.93 mm), is exceeded 2.2 / 3.8 times, and
    # the harmonics next to the follower modes (92.1 / 87.5 Hz on a rigid cam, 4.61 / 4.38
    # times the speed) dominate: the 5th for cam 1, the 4th for cam 2.
    estimates = machine.follower_estimates()
    quasi_static = np.array([e["quasi_static"] for e in estimates])
    assert_allclose(quasi_static, [4.30e-3, 4.93e-3], rtol=2e-3)
    assert_allclose(np.abs(q).max(axis=0) / quasi_static, [2.2, 3.8], rtol=0.05)
    assert [machine.dominant_order(q[:, k]) for k in range(2)] == [5, 4]
    assert_allclose([e["f_hz"] for e in estimates], [92.12, 87.54], rtol=1e-3)


def test_processing_machine_scene_runs_the_scripts_steady_state(machine):
    # The scene form must solve the script's problem: the same speed and the same frame
    # damping (Rayleigh 2 % at 80 and 500 Hz, Chopra eq. 11.4.9), which the scene lists to
    # 4 significant digits (a, b = 17.332925 1/s, 1.0976203e-5 s).
    from femmech.analysis.response import rayleigh_coefficients
    from femmech.scene.load import load_scene

    response = load_scene(EXAMPLES / "processing_machine.toml").analyses.response
    assert response.kind == "periodic"
    # bound: "1200 rpm" converted by the unit parser: a few eps of round-off
    assert response.speed == pytest.approx(2 * np.pi * machine.OPERATING_RPM / 60.0,
                                           rel=1e-12)
    assert_allclose(response.rayleigh,
                    rayleigh_coefficients(machine.FRAME_ZETA, *machine.ZETA_BAND_HZ),
                    rtol=5e-4)  # the scene's 4 to 5 digits
    assert set(response.outputs) == {"cam1.q", "cam2.q"}


# --- (c) slider-crank press in a C-frame ---------------------------------------------------

@pytest.fixture(scope="module")
def press():
    return _load("press_frame")


@pytest.fixture(scope="module")
def press_run(press, tmp_path_factory):
    out = tmp_path_factory.mktemp("press")
    return out, press.main(out, n_angles=37, with_dynamics=False)


def test_press_reduced_matches_full(press_run):
    # Acceptance at 7 angles incl. BDC (0°), near BDC (2°) and TDC (180°), the
    # 8 modes below 420 Hz. Measured: max frequency error 2.7e-7 (the ram branch at
    # ~400 Hz; 1.0e-9 with f_max doubled, so it is the reduction's truncation), MAC
    # 1 - 1.0e-8. Tolerances 1e-6 and MAC > 1 - 1e-6, far inside 0.5 % and 0.95.
    _, result = press_run
    assert result["max_error"] < 1e-6
    assert result["min_mac"] > 1 - 1e-6


def test_press_rigid_frame_is_frame_and_mechanism(press_run):
    # Mechanism attached at the clamped foot: the frame coordinates drop out of the
    # mechanism, so the coupled spectrum is exactly the union of the frame modes and
    # Table 5.1 case 1 with the slider-crank; dense eigh on both: round-off (measured 6e-13).
    _, result = press_run
    # bound: dense eigh round-off eps λ_max/λ on both sides (roundoff.py), measured 6e-13
    assert result["rigid_error"] < 1e-9


def test_press_dead_centres(press, press_run):
    # At BDC and TDC U' = 0 and the rod is along the slider axis: the crank twist decouples
    # from ram and frame, so one branch is exactly √(c1/J1)/(2π) = 129.95 Hz (round-off).
    _, result = press_run
    # bound: exact decoupling; the closed form against dense eigh: eps·cond of a 2-DOF block
    assert result["dead_centre_error"] < 1e-12
    f = result["sweep"].freq_hz
    # bound: the same frozen pencil at 0 and 2π: dense eigh round-off eps λ_max/λ
    assert_allclose(f[-1], f[0], rtol=1e-9)  # one revolution closes the sweep
    crank_hz = np.sqrt(press.PARAMS["c1"] / press.PARAMS["J1"]) / (2 * np.pi)
    # bound: the closed form against a 10-digit literal: 5e-11 rounding
    assert_allclose(crank_hz, 129.9494669, rtol=1e-9)


def test_press_stiff_frame_converges_to_mechanism(press):
    # Frame 1e3 and 1e4 times stiffer (E scaled): the mechanism branches approach Table
    # 5.1 case 1 with the error falling like 1/stiffness (measured 3.8e-3 and 3.7e-4 on
    # the ram branch); the crank and ram frequencies stay below the frame's.
    phi = np.deg2rad([0.0, 45.0, 90.0, 180.0])
    alone = press.mechanism_only(phi).freq_hz
    errors = []
    for scale in (1e3, 1e4):
        reduced = press.build(stiffness_scale=scale)[0]
        f = sweep(reduced, phi, n_modes=4, track=False).freq_hz[:, :2]
        errors.append(np.abs(f / alone - 1).max())
    assert 0.08 < errors[1] / errors[0] < 0.12
    assert errors[1] < 1e-3


def test_press_outputs(press_run):
    out, result = press_run
    assert result["sweep"].form == "symmetric"
    assert (out / "quasi_frequencies.png").stat().st_size > 10_000
    assert (out / "mechanism_only.png").stat().st_size > 10_000
    table = np.loadtxt(out / "quasi_frequencies.csv", delimiter=",", skiprows=1)
    assert table.shape == (37, 1 + 3 * 8)  # angle, 8 frequencies, 8 ζ, 8 MAC steps
    # bound: the CSV holds 10 significant digits: rounding 5e-11 relative
    assert_allclose(table[:, 1:9], result["sweep"].freq_hz, rtol=1e-9)
