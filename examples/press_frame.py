"""Slider-crank press in a C-frame: coupled quasi-eigenfrequencies over one stroke.

Physics
-------
A C-frame press (steel box sections, in the x-z plane): a column (x = 0, 2 m high,
clamped at its foot), a crown (upper arm, 0.6 m deep) carrying the crank housing at its
front end, a gib hanging 0.4 m down from the crown front that guides the ram, and a bed
(lower arm at z = 0.6 m) whose front rests on a leg (clamped foot). The press mechanism
is a :func:`femmech.mechanisms.mounted.slider_crank` (case 1 of Table 5.1 in section 5.2.2
of the chapter, with
U = SliderCrank(r, l): crank radius r = 50 mm, i.e. a 100 mm stroke, rod l = 350 mm, no
offset) whose slider axis points down (-z):

* the flywheel turns at the programmed angle φ = Ωt (kinematic drive); the crankshaft
  (c1 = 1e6 N m/rad) connects it to the crank (J1 = 1.5 kg m²): coordinate q_t;
* the crank bearing moves with the crown's front node: u_b = -uz (along the slider
  axis), v_b = ux (across);
* the guide moves with the gib's lower node: v_g = ux; the guide reaction (rod thrust
  F tan β) and the ram's lateral inertia load the frame there;
* the ram (m2 = 150 kg) follows the slider through the output elasticity
  c2 = 1e9 N/m (rod, ram and bearings in series): coordinate q.

At φ = 0 the crank pin is below its centre: bottom dead centre (BDC), φ = π top dead
centre. The slider-crank position function is regular there (l > r), only U' = 0: the
crank torsion then decouples from ram and frame, and its frequency is exactly
√(c1/J1)/(2π) = 130 Hz whatever the frame. The sweep includes both dead centres.

The frame is reduced by Craig-Bampton (residual vectors) with the three attachment DOFs
as interface; the coupled system (section 5.2.2 eq. 9, Ω = 0: symmetric potential C) is
swept over one revolution and compared with the unreduced coupled model, and, with the
mechanism attached at a clamped node (rigid frame), with Table 5.1 case 1 alone.

Sources: textbook chapter 5, "Schwingungsmodelle mit mehreren Freiheitsgraden", section
5.2.2, Table 5.1 case 1 and eq. 9-10, errata §A; slider-crank
kinematics, Dresig & Holzweißig, *Maschinendynamik*, ch. 2; C-frame press layout,
Schuler GmbH, *Metal Forming Handbook*, Springer (1998), on press types. Parameters
are illustrative (SI).

Run: ``python examples/press_frame.py --out out/press_example`` (not the scene's ``out/press``:
both write ``stability_chart.png``, the scene its spectral radius over speed, this script
its growth rate per frame damping ratio)
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import scipy.linalg as sla

import femmech as fm
from femmech.analysis.forces import attachment_forces, beam_section_forces, drive_forces
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
    SliderCrank,
    quasi_modes,
    rheolinear,
    second_kind,
    table_5_1_case,
)
from femmech.mechanisms.mounted import slider_crank
from femmech.output.histories import plot_orbit, plot_time_histories, write_history_csv
from femmech.output.stability_charts import plot_speed_study
from femmech.output.sweeps import plot_quasi_frequencies, write_sweep_csv
from femmech.reduction import craig_bampton
from femmech.scene.load import load_scene

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0, name="steel")
GEOMETRY = {"r": 0.05, "l": 0.35, "e": 0.0}  # m
PARAMS = {"J1": 1.5, "m2": 150.0, "c1": 1e6, "c2": 1e9, "b1": 0.0, "b2": 0.0, "F2": 0.0}
JOINTS = {  # m, in the x-z plane
    "column_foot": (0.0, 0.0, 0.0), "bed_root": (0.0, 0.0, 0.6), "column_top": (0.0, 0.0, 2.0),
    "crank": (0.6, 0.0, 2.0), "guide": (0.6, 0.0, 1.6), "bed_front": (0.6, 0.0, 0.6),
    "leg_foot": (0.6, 0.0, 0.0)}
MEMBERS = {  # group: (joint chain, box section width/height, wall) in m
    "column": (("column_foot", "bed_root", "column_top"), 0.35, 0.02),
    "crown": (("column_top", "crank"), 0.35, 0.02),
    "gib": (("crank", "guide"), 0.15, 0.012),
    "bed": (("bed_root", "bed_front"), 0.3, 0.02),
    "leg": (("bed_front", "leg_foot"), 0.2, 0.012),
}
ELEMENT_SIZE = 0.1  # m
# dynamics (steady state and stability): dampers of about 2 % of critical on the crank
# torsion (2ζ√(c1 J1) = 49 N m s/rad) and on the ram (2ζ√(c2 m2) = 1.5e4 N s/m), frame
# Rayleigh damping ζ = 2 % at 60 and 400 Hz (welded steel frame with bolted joints)
DAMPED = {**PARAMS, "b1": 50.0, "b2": 1.5e4}
FRAME_ZETA, ZETA_BAND_HZ = 0.02, (60.0, 400.0)
OPERATING_SPM = 600.0  # strokes per minute
SCENE = Path(__file__).with_suffix(".toml")  # the same press as a scene


def study_speeds(n_speeds: int | None = None) -> np.ndarray:
    """Drive speeds of the stability study, rad/s: the range the scene's
    ``[analyses.stability] speeds`` asks for (100..3000 strokes/min), at ``n_speeds``
    evenly spaced points (None: the scene's own speeds)."""
    speeds = load_scene(SCENE).analyses.stability.speeds
    if n_speeds is None:
        return np.asarray(speeds, dtype=float)
    return np.linspace(min(speeds), max(speeds), n_speeds)


def frame_mesh(element_size: float = ELEMENT_SIZE) -> fm.Mesh:
    """Beam mesh of the C-frame; node sets name the joints (one node each) and feet."""
    names = list(JOINTS)
    points = [np.array([JOINTS[n] for n in names], dtype=float)]
    n_points, lines, cell_sets = len(names), [], {}
    for group, (chain, _, _) in MEMBERS.items():
        start = sum(len(c) for c in lines)
        for a, b in zip(chain[:-1], chain[1:], strict=True):
            pa, pb = np.array(JOINTS[a]), np.array(JOINTS[b])
            k = max(1, int(round(np.linalg.norm(pb - pa) / element_size)))
            inner = pa + np.outer(np.arange(1, k) / k, pb - pa)
            ids = np.concatenate([[names.index(a)], n_points + np.arange(k - 1),
                                  [names.index(b)]])
            points.append(inner)
            n_points += k - 1
            lines.append(np.column_stack([ids[:-1], ids[1:]]))
        cell_sets[group] = start + np.arange(sum(len(c) for c in lines) - start)
    node_sets = {n: [i] for i, n in enumerate(names)}
    node_sets["feet"] = [names.index("column_foot"), names.index("leg_foot")]
    return fm.Mesh.from_lines(np.vstack(points), np.vstack(lines), cell_sets, node_sets)


def frame_model(stiffness_scale: float = 1.0) -> fm.FEModel:
    """FE model of the C-frame, feet clamped; ``stiffness_scale`` multiplies E."""
    material = fm.Material(E=STEEL.E * stiffness_scale, nu=STEEL.nu, rho=STEEL.rho)
    beams = {group: fm.BeamProperty(sections.rectangular_hollow(size, size, wall), material)
             for group, (_, size, wall) in MEMBERS.items()}
    return fm.build_model(frame_mesh(), beams, supports=[fm.Support("feet")])


def press_mount(crank, guide, params=PARAMS) -> Mount:
    """The slider-crank with its attachments (nodes as indices or names)."""
    model = rheolinear(slider_crank(), {**params, **GEOMETRY})
    down = (0.0, 0.0, -1.0, 0.0, 0.0, 0.0)
    return Mount(model, (Attachment("u_b", crank, down), Attachment("v_b", crank, "ux"),
                         Attachment("v_g", guide, "ux")), name="press")


def build(f_max_hz: float = 800.0, stiffness_scale: float = 1.0, params=PARAMS):
    """(reduced coupled system, full coupled system, FE model, superelement)."""
    model = frame_model(stiffness_scale)
    crank, guide = (int(model.mesh.node_sets[n][0]) for n in ("crank", "guide"))
    se = craig_bampton(model, [(crank, ["ux", "uz"]), (guide, ["ux"])], f_max_hz=f_max_hz)
    mount = press_mount(crank, guide, params)
    return couple(se, [mount]), couple(model, [mount]), model, se


def mechanism_only(phi):
    """Quasi-modes of Table 5.1 case 1 with the slider-crank (rigid frame, Ω = 0)."""
    U = SliderCrank(GEOMETRY["r"], GEOMETRY["l"], GEOMETRY["e"])
    return quasi_modes(rheolinear(table_5_1_case(1), PARAMS, {"U": U}), phi)


def rigid_check(phi, n_modes: int = 8):
    """Mechanism attached at the clamped column foot: the coupled spectrum must be the
    union of the frame's and the mechanism-only quasi-frequencies. Returns the max
    relative difference, the coupled sweep and the mechanism-only result."""
    model = frame_model()
    se = craig_bampton(model, [(int(model.mesh.node_sets["crank"][0]), ["ux"])],
                       f_max_hz=800.0)
    foot = int(model.mesh.node_sets["column_foot"][0])
    coupled = sweep(couple(se, [press_mount(foot, foot)]), phi, n_modes=n_modes, track=False)
    frame = np.sqrt(sla.eigh(se.K, se.M, eigvals_only=True)) / (2 * np.pi)
    alone = mechanism_only(phi)
    expected = np.sort(np.hstack([alone.freq_hz, np.tile(np.sort(frame), (phi.size, 1))]),
                       axis=1)[:, :n_modes]
    return float(np.abs(coupled.freq_hz / expected - 1).max()), coupled, alone


def dynamics(out_dir="out/press_example", spm: float = OPERATING_SPM, n_speeds: int | None = None,
             zetas=(0.0025, 0.005, 0.01, 0.02), n_steps: int = 32) -> dict:
    """Periodic steady state at ``spm`` strokes/min and Floquet stability over speed.

    Steady state (shooting, Richardson-extrapolated; ρ∞ = 1 so that the rigid-attachment
    forces are those of the discrete solution): ram deflection, crank twist, crank-bearing
    and guide forces on the frame, drive torque (the crank's drive row, section 5.2.2 eq. 2
    for j = n+1), the column-foot bending moment (elastic section force) and the orbit of
    the crank bearing. Stability
    (:func:`femmech.analysis.stability.speed_study`): growth rate ln(max|μ|)/T over
    the speeds the scene asks for (:func:`study_speeds`: 100..3000 strokes/min, the scene's
    30 points unless ``n_speeds`` is given) at the nominal damping and per frame damping
    ratio (one curve each), with
    the principal parametric resonances 2 f_k / j of the two lowest branches marked.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    base, _, model, _ = build(params=DAMPED)
    system = rayleigh_damping(base, *rayleigh_coefficients(FRAME_ZETA, *ZETA_BAND_HZ))
    W = 2 * np.pi * spm / 60.0
    drive = ConstantSpeed(W)
    r = periodic_steady_state(system, W, n_steps=720, rho_inf=1.0, richardson=True)
    forces = attachment_forces(system, r, drive)
    torque = drive_forces(second_kind(slider_crank(), {**DAMPED, **GEOMETRY}), r, drive,
                          system)[:, 0]
    bearing = frame_history(system, model, r.q, [("crank", "ux"), ("crank", "uz")])
    # column element at the foot (end a); local y = global y: My bends the C-frame's plane
    foot = int(model.mesh.cell_sets["column"]["line"][0])
    foot_My = beam_section_forces(system, model, r, foot).component("My")[:, 0, 0]
    deg = np.rad2deg(r.phi)
    q_ram, q_t = (r.q[:, system.labels.index(f"press.{c}")] for c in ("q", "q_t"))
    force_curves = dict(zip(forces.labels, forces.forces.T, strict=True))
    plot_time_histories(deg, {
        "ram deflection q (µm)": {"q": 1e6 * q_ram},
        "crank twist q_t (mrad)": {"q_t": 1e3 * q_t},
        "force on frame (kN)": {k: 1e-3 * f for k, f in force_curves.items()},
        "drive torque (kN m)": {"crank drive row": 1e-3 * torque},
        "column foot bending\nmoment (kN m)": {"M_y (elastic)": 1e-3 * foot_My}},
        out / "steady_state.png", xlabel="crank angle φ (deg), BDC at 0°",
        title=f"Press at {spm:.0f} strokes/min: periodic steady state",
        angle_deg=True)
    plot_orbit(1e6 * bearing[:, 0], 1e6 * bearing[:, 1], out / "crank_bearing_orbit.png",
               "crank bearing u_x (µm)", "crank bearing u_z (µm)",
               f"Crank bearing over one stroke at {spm:.0f} strokes/min")
    write_history_csv(r.t, {"phi_deg": deg, "q_ram_m": q_ram, "q_t_rad": q_t,
                            **{f"{k}_N": f for k, f in force_curves.items()},
                            "drive_torque_Nm": torque, "column_foot_My_Nm": foot_My},
                      out / "steady_state.csv")
    study = speed_study(base, study_speeds(n_speeds), FRAME_ZETA,
                        ZETA_BAND_HZ, zetas, n_steps=n_steps, orders=range(1, 9))
    plot_speed_study(study, out, "Press")
    print(f"steady state at {spm:.0f} strokes/min: ram deflection {1e6 * np.ptp(q_ram):.1f} µm"
          f" peak to peak, crank-bearing force up to"
          f" {1e-3 * np.abs(forces.forces[:, 0]).max():.1f} kN, drive torque up to"
          f" {1e-3 * np.abs(torque).max():.2f} kN m")
    print(f"stability: {study.summary()}")
    return {"steady_state": r, "forces": forces, "torque": torque, "bearing": bearing,
            "study": study, "system": system, "column_foot_My": foot_My}


def main(out_dir="out/press_example", n_angles: int = 181, n_modes: int = 8,
         with_dynamics: bool = True, n_speeds: int | None = None) -> dict:
    """Sweep over one revolution (BDC at 0° and 360°, TDC at 180°), plot, CSV, checks."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    phi = np.linspace(0.0, 2 * np.pi, n_angles)
    reduced, full, model, se = build()
    result = sweep(reduced, phi, n_modes=n_modes)
    check = np.deg2rad([0.0, 2.0, 45.0, 90.0, 135.0, 180.0, 270.0])
    comparison = compare_coupled(reduced, full, check, n_modes)
    errors, macs = np.abs(comparison.rel_error), comparison.diag_mac
    rigid_error, rigid, alone = rigid_check(phi)
    crank_hz = np.sqrt(PARAMS["c1"] / PARAMS["J1"]) / (2 * np.pi)
    dead = [np.abs(result.freq_hz[i] - crank_hz).min() / crank_hz for i in (0, n_angles // 2)]
    plot_quasi_frequencies({"press in C-frame (reduced)": result}, out / "quasi_frequencies.png",
                           title="Slider-crank press in a C-frame (BDC at 0°, TDC at 180°)")
    plot_quasi_frequencies({"mechanism only (Table 5.1 case 1)": alone},
                           out / "mechanism_only.png", title="Slider-crank press, rigid frame")
    write_sweep_csv(result, out / "quasi_frequencies.csv")
    (out / "reduced_vs_full.txt").write_text(comparison.table() + "\n")
    print(f"frame {model.n_free} free DOFs, superelement {se.n_reduced}, coupled {reduced.n}")
    print(f"reduced vs full at {len(check)} angles: max frequency error {errors.max():.2e},"
          f" min MAC {macs.min():.10f}")
    print(f"rigid frame: max relative difference from frame ∪ mechanism {rigid_error:.2e};"
          f" crank branch at the dead centres off √(c1/J1) by {max(dead):.1e}")
    summary = {"sweep": result, "max_error": float(errors.max()), "min_mac": float(macs.min()),
               "rigid_error": rigid_error, "dead_centre_error": float(max(dead)),
               "n_full": full.n, "n_reduced": reduced.n}
    if with_dynamics:
        summary["dynamics"] = dynamics(out, n_speeds=n_speeds)
    return summary


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/press_example")
    parser.add_argument("--angles", type=int, default=181)
    parser.add_argument("--speeds", type=int, default=None, help="speeds of the stability"
                        " chart (default: those of the scene, press_frame.toml)")
    args = parser.parse_args()
    main(args.out, args.angles, n_speeds=args.speeds)
