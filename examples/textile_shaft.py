"""Textile-machine main shaft with N identical cam mechanisms, mounted in a frame.

Physics (textbook chapter 5, "Schwingungsmodelle mit mehreren Freiheitsgraden", section 5.1,
figure 5.1: chains of identical mechanisms on one main shaft):
a steel main shaft (d = 60 mm) along x carries N cams at 0.1 m spacing. It runs in
bearings (radial stiffness 2e8 N/m) on pedestals of a welded base beam (HEB-like
I-section) that stands on four feet. The drive end of the shaft follows the programmed
motion φ = Ωt (kinematic drive: its twist is fixed). Each cam drives a follower mass
m2 = 2 kg through a contact spring c2 = 1e6 N/m; the follower's guide is fixed to the
base beam under the cam. Per mechanism (Table 5.1 case 1 with the guide motion added):

    2T = J_c (θ' + q_s')² + m2 x2'²,  x2 = y_g + U(θ + q_s) + q2,  2V = c2 q2²,

where q_s is the shaft twist at the cam (attached to the shaft node's rx), y_g the guide
displacement (attached to the base-beam node's uz) and q2 the follower deflection. U is
a 3-4-5 polynomial rise of 30 mm over 90°, dwell, return, dwell.

The frame and shaft (one FE model) are reduced by Craig-Bampton with the 2N attachment
DOFs as interface; the coupled quasi-eigenfrequencies are swept over one revolution and
compared with the unreduced coupled model at a few angles.

Run: ``python examples/textile_shaft.py --n 10 --out out/textile``
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import sympy

import femmech as fm
from femmech.analysis.forces import attachment_forces, drive_forces, support_reactions
from femmech.analysis.reference import compare_coupled
from femmech.analysis.response import (
    ConstantSpeed,
    frame_history,
    periodic_steady_state,
    rayleigh_coefficients,
    rayleigh_damping,
)
from femmech.analysis.stability import speed_study
from femmech.analysis.sweep import sweep
from femmech.coupling import Attachment, Mount, couple
from femmech.fe import sections
from femmech.mechanisms import (
    CamProfile,
    CamSegment,
    Damper,
    Mechanism,
    PointMass,
    RotaryInertia,
    Spring,
    polynomial_345,
    position_function,
    rheolinear,
    second_kind,
)
from femmech.output.histories import plot_orbit, plot_time_histories, write_history_csv
from femmech.output.machine import plot_coupled_mode
from femmech.output.stability_charts import plot_speed_study
from femmech.output.sweeps import (
    plot_mac,
    plot_quasi_frequencies,
    write_sweep_csv,
    write_sweep_json,
)
from femmech.reduction import craig_bampton

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0, name="steel")
SPACING = 0.1  # m between cams
HEIGHT = 0.4  # m, shaft axis above the base beam
BEARING_EVERY = 5  # cams between bearings
BEARING_K = 2e8  # N/m, radial
OPERATING_RPM = 900.0  # dynamics: main-shaft speed of the steady state
FRAME_ZETA, ZETA_BAND_HZ = 0.02, (100.0, 600.0)  # frame and shaft Rayleigh damping
# kg m², kg, N/m, N s/m (b2: 2 % of critical, 2ζ√(c2 m2) = 57 N s/m)
PARAMS = {"J_c": 2e-3, "m2": 2.0, "c2": 1e6, "b2": 57.0}
CAM = CamProfile((CamSegment(np.pi / 2, 0.03, polynomial_345()), CamSegment(np.pi / 2, 0.0),
                  CamSegment(np.pi / 2, -0.03, polynomial_345()), CamSegment(np.pi / 2, 0.0)))


def cam_mechanism() -> Mechanism:
    """One cam mechanism with shaft twist q_s, guide motion y_g and follower deflection q2
    (damper b2 on q2)."""
    theta, qs, yg, q2 = sympy.symbols("theta q_s y_g q2")
    Jc, m2, c2, b2 = sympy.symbols("J_c m2 c2 b2")
    U = position_function("U")
    x2 = yg + U(theta + qs) + q2
    return Mechanism((qs, yg, q2, theta),
                     (RotaryInertia(Jc, theta + qs), PointMass(m2, (x2,)), Spring(c2, q2),
                      Damper(b2, q2)), drives=(theta,), name="cam")


def frame_and_shaft(n_cams: int, per_spacing: int = 2) -> tuple[fm.FEModel, np.ndarray,
                                                                np.ndarray]:
    """FE model of shaft, pedestals and base beam; returns (model, cam nodes, guide nodes)."""
    n_x = (n_cams + 1) * per_spacing + 1
    x = np.linspace(0.0, (n_cams + 1) * SPACING, n_x)
    shaft = np.column_stack([x, 0 * x, np.full(n_x, HEIGHT)])
    base = np.column_stack([x, 0 * x, 0 * x])
    stations = np.arange(0, n_x, BEARING_EVERY * per_spacing)
    if stations[-1] != n_x - 1:
        stations = np.append(stations, n_x - 1)
    tops = np.column_stack([x[stations], 0 * stations, np.full(stations.size, HEIGHT)])
    points = np.vstack([shaft, base, tops])
    chain = lambda start: np.column_stack([start + np.arange(n_x - 1),  # noqa: E731
                                           start + np.arange(1, n_x)])
    top_ids = 2 * n_x + np.arange(stations.size)
    pedestals = np.column_stack([n_x + stations, top_ids])
    lines = np.vstack([chain(0), chain(n_x), pedestals])
    n_sh, n_b = n_x - 1, n_x - 1
    mesh = fm.Mesh.from_lines(points, lines, cell_sets={
        "shaft": np.arange(n_sh), "base": n_sh + np.arange(n_b),
        "pedestals": n_sh + n_b + np.arange(len(pedestals))},
        node_sets={"drive": [0], "feet": n_x + _feet(n_x, per_spacing)})
    beams = {
        "shaft": fm.BeamProperty(sections.circle(0.06), STEEL),
        "base": fm.BeamProperty(sections.i_section(0.2, 0.2, 0.009, 0.015), STEEL),
        "pedestals": fm.BeamProperty(sections.rectangular_hollow(0.1, 0.1, 0.008), STEEL),
    }
    bearings = [fm.Spring(int(s), int(t), [0.0, BEARING_K, BEARING_K, 0, 0, 0])
                for s, t in zip(stations, top_ids, strict=True)]
    bearings.append(fm.Spring(0, int(top_ids[0]), [BEARING_K, 0, 0, 0, 0, 0]))  # axial
    model = fm.build_model(mesh, beams, springs=bearings, supports=[
        fm.Support("feet"), fm.Support("drive", ["rx"])])
    cams = per_spacing * (1 + np.arange(n_cams))
    return model, cams, n_x + cams


def _feet(n_x: int, per_spacing: int) -> np.ndarray:
    """Base-beam node positions of the four feet: the ends and two nodes between cams."""
    between = lambda i: per_spacing * (i // per_spacing) + per_spacing // 2 or 1  # noqa: E731
    return np.array([0, between(n_x // 3), between(2 * n_x // 3), n_x - 1])


def mounts(cam_nodes, guide_nodes):
    """One Mount per cam (all in phase), attached to the shaft's rx and the base's uz."""
    model = rheolinear(cam_mechanism(), PARAMS, {"U": CAM})
    return [Mount(model, (Attachment("q_s", int(c), "rx"), Attachment("y_g", int(g), "uz")),
                  name=f"cam{i + 1}")
            for i, (c, g) in enumerate(zip(cam_nodes, guide_nodes, strict=True))]


def build(n_cams: int = 10, f_max_hz: float = 400.0, per_spacing: int = 2):
    """(reduced coupled system, full coupled system, FE model, superelement).

    ``per_spacing`` elements of shaft and base beam between neighbouring cams.
    """
    model, cams, guides = frame_and_shaft(n_cams, per_spacing)
    interface = [(cams, ["rx"]), (guides, ["uz"])]
    se = craig_bampton(model, interface, f_max_hz=f_max_hz)
    reduced = couple(se, mounts(cams, guides))
    full = couple(model, mounts(cams, guides))
    return reduced, full, model, se


def dynamics(out_dir="out/textile", n_cams: int = 10, rpm: float = OPERATING_RPM,
             n_speeds: int = 60, zetas=(0.0025, 0.005, 0.01, 0.02),
             n_steps: int = 32) -> dict:
    """Periodic steady state at ``rpm`` and Floquet stability over speed.

    Steady state (shooting, ρ∞ = 1, Richardson-extrapolated): follower deflections of the
    first, middle and last
    cam, the motor torque at the kinematic drive end (rx reaction,
    :func:`~femmech.analysis.forces.support_reactions`) next to the sum of the cams'
    drive rows (what a rigid shaft would transmit), the guide forces on the base beam,
    and the orbit of the shaft at the middle cam. Stability over 300..1800 rpm
    (:func:`femmech.analysis.stability.speed_study`), with 2 f_k / j marked.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    base, _, model, _ = build(n_cams)
    rayleigh = rayleigh_coefficients(FRAME_ZETA, *ZETA_BAND_HZ)
    system = rayleigh_damping(base, *rayleigh)
    W = 2 * np.pi * rpm / 60.0
    drive = ConstantSpeed(W)
    r = periodic_steady_state(system, W, n_steps=720, rho_inf=1.0, richardson=True)
    forces = attachment_forces(system, r, drive)
    motor = support_reactions(system, model, r, [("drive", "rx")], *rayleigh)[:, 0]
    lagrange = second_kind(cam_mechanism(), PARAMS, {"U": CAM})
    rows = sum(drive_forces(lagrange, r, drive, system, mount=k)[:, 0] for k in range(n_cams))
    shown = sorted({0, n_cams // 2, n_cams - 1})
    middle = int(system.mounts[n_cams // 2].attachments[0].node)
    orbit = frame_history(system, model, r.q, [(middle, "uy"), (middle, "uz")])
    deg = np.rad2deg(r.phi)
    q2 = {f"cam{k + 1}": r.q[:, system.labels.index(f"cam{k + 1}.q2")] for k in shown}
    guide = {f"cam{k + 1}": forces.forces[:, forces.labels.index(f"cam{k + 1}.y_g")]
             for k in shown}
    plot_time_histories(deg, {
        "follower deflection q2 (µm)": {k: 1e6 * v for k, v in q2.items()},
        "guide force on base (kN)": {k: 1e-3 * v for k, v in guide.items()},
        "torque (N m)": {"motor (drive-end reaction)": motor,
                         "Σ cam drive rows (rigid shaft)": rows}},
        out / "steady_state.png", xlabel="main-shaft angle φ (deg)",
        title=f"{n_cams} cams at {rpm:.0f} rpm: periodic steady state",
        angle_deg=True)
    plot_orbit(1e6 * orbit[:, 0], 1e6 * orbit[:, 1], out / "shaft_orbit.png",
               f"shaft at cam {n_cams // 2 + 1}, u_y (µm)", "u_z (µm)",
               f"Main shaft over one revolution at {rpm:.0f} rpm")
    write_history_csv(r.t, {"phi_deg": deg, **{f"{k}.q2_m": v for k, v in q2.items()},
                            **{f"{k}.guide_N": v for k, v in guide.items()},
                            "motor_torque_Nm": motor, "cam_drive_rows_Nm": rows},
                      out / "steady_state.csv")
    study = speed_study(base, 2 * np.pi / 60.0 * np.linspace(300.0, 1800.0, n_speeds),
                        FRAME_ZETA, ZETA_BAND_HZ, zetas, n_steps=n_steps,
                        orders=range(1, 13))
    plot_speed_study(study, out, f"{n_cams} cams")
    print(f"steady state at {rpm:.0f} rpm: follower deflection up to"
          f" {1e6 * max(np.abs(v).max() for v in q2.values()):.1f} µm, motor torque"
          f" {motor.min():.1f} .. {motor.max():.1f} N m (cam drive rows"
          f" {rows.min():.1f} .. {rows.max():.1f} N m)")
    print(f"stability: {study.summary()}")
    return {"steady_state": r, "forces": forces, "motor_torque": motor, "drive_rows": rows,
            "study": study, "system": system}


def main(out_dir="out/textile", n_cams: int = 10, n_angles: int = 181,
         n_modes: int = 6, with_dynamics: bool = True, n_speeds: int = 60) -> dict:
    """Sweep the coupled machine over one revolution; compare with the full model."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    reduced, full, model, se = build(n_cams)
    phi = np.linspace(0.0, 2 * np.pi, n_angles)
    start = time.perf_counter()
    result = sweep(reduced, phi, n_modes=n_modes, keep_vectors=True)
    t_sweep = time.perf_counter() - start
    a = n_angles // 8  # 45°, in the cams' rise
    plot_coupled_mode(model, reduced, result.vectors[a, :, 0], result.freq_hz[a, 0],
                      out / "coupled_mode_1.png", angle=phi[a], speed=0.0, mode_number=1)
    check = phi[[0, n_angles // 8, n_angles // 4, n_angles // 2]]
    comparison = compare_coupled(reduced, full, check, n_modes)
    errors, macs = np.abs(comparison.rel_error), comparison.diag_mac
    plot_quasi_frequencies({"coupled (reduced)": result}, out / "quasi_frequencies.png",
                           title=f"Main shaft with {n_cams} cam mechanisms in a frame")
    write_sweep_csv(result, out / "quasi_frequencies.csv")
    write_sweep_json(result, out / "quasi_frequencies.json", {"n_cams": n_cams})
    (out / "reduced_vs_full.txt").write_text(comparison.table() + "\n")
    plot_mac(comparison.mac[1], out / "mac_reduced_vs_full.png", "reduced coupled modes",
             "full coupled modes", f"MAC at φ = {np.rad2deg(check[1]):.0f}°")
    print(f"{n_cams} cams: FE model {model.n_free} free DOFs, superelement {se.n_reduced}"
          f" coordinates, coupled {reduced.n}")
    print(f"sweep of {n_angles} angles: {t_sweep:.2f} s ({1e3 * t_sweep / n_angles:.2f} ms"
          f" per angle); full coupled ARPACK: {1e3 * comparison.seconds_full.mean():.1f} ms"
          " per angle")
    print(f"reduced vs full at {len(check)} angles: max frequency error {errors.max():.2e},"
          f" min MAC {macs.min():.6f}")
    summary = {"sweep": result, "max_error": errors.max(), "min_mac": macs.min(),
               "time_per_angle_reduced": t_sweep / n_angles,
               "time_per_angle_full": comparison.seconds_full.mean(),
               "n_full": full.n, "n_reduced": reduced.n}
    if with_dynamics:
        summary["dynamics"] = dynamics(out, n_cams, n_speeds=n_speeds)
    return summary


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/textile")
    parser.add_argument("--n", type=int, default=10, help="number of cam mechanisms")
    parser.add_argument("--angles", type=int, default=181)
    parser.add_argument("--speeds", type=int, default=60, help="speeds of the stability chart")
    args = parser.parse_args()
    main(args.out, args.n, args.angles, n_speeds=args.speeds)
