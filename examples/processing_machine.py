"""Cam-driven processing machine with an FE drive shaft, mounted in a welded frame.

Physics
-------
The chapter's machine (section 5.2.3.2, errata §A): a drive shaft carries the discs J0
(drive end), J1 and J2 with torsional stiffnesses cT1, cT2 between them; two cam
mechanisms U1 (on J1) and U2 (on J2) move the follower masses m1, m2 through the
follower elasticities c3, c4 against the return springs c6, c7. Here

* the shaft is a steel beam FE model (Timoshenko, d = 30 mm), each segment of length
  ``L_k = G I_p / cT_k`` so that its torsional stiffness *is* cT_k (0.321 m for
  cT = 2e4 N m/rad); the discs are PointMass rotary inertias (J, J/2, J/2) kg m² with
  disc masses 20/2/2 kg at the three stations;
* the shaft runs in radial bearings (2e8 N/m; at the drive end also axial 2e8 N/m and
  tilting 5e6 N m/rad, a gearbox output bearing that carries the flywheel J0) at the
  mid-points of the three top cross members of a box frame of steel tubes
  (``grid_frame((2, 1, 1), (2 L, 0.3, 0.35))``, 50x50x4 mm hollow sections, feet clamped);
* the drive end follows the programmed motion φ = Ωt (kinematic drive: its twist rx is
  fixed), so, as in the chapter's 4-DOF model, J0 does not enter the torsion;
* each cam is a :func:`femmech.mechanisms.mounted.cam_follower` with the follower axis
  along z: its shaft twist q_s is the shaft node's rx, the cam centre y_c its uz (shaft
  bending and bearing deflection), the return-spring base y_f the uz of the cross-member
  node 75 mm beside the bearing; the follower deformation q is its own coordinate.

Parameters: ``processing_machine_parameters()`` (SI), the cams of
``examples/mechanism_quasi_modes.py`` (modified-sine and 3-4-5 rise/return, 50/40 mm).
Shaft and frame form one FE model, reduced by Craig-Bampton (residual vectors) with the
six attachment DOFs as interface; the coupled quasi-eigenfrequencies (section 5.2.2 eq. 9,
Ω = 0: symmetric potential C) are swept over one revolution and compared with

1. the chapter's mechanism-only model (rigid frame: bearings as supports, return springs
   anchored at supported nodes; shaft density scaled down so that only the discs carry
   inertia, as in the lumped model), see :func:`rigid_check`;
2. the unreduced coupled model at several angles (:func:`compare`).

What the steady state shows
---------------------------
``dynamics`` runs the machine at 1200 rpm (Ω = 125.7 rad/s, 20 Hz; the chapter gives no
speed) with 2 % Rayleigh damping of the frame. The follower deformation q is the
follower spring's own elongation, y − y_c − U(θ + q_s) in m (plotted in µm), not the
follower's travel y = y_c + U + q. It reaches 9.3 mm (cam 1) and 18.6 mm (cam 2)
against strokes of 50 and 40 mm. That is a near-resonance of the linear model, not a
unit or labelling slip. On a rigid cam the follower modes are √((c + c_r)/m)/2π =
92.1 Hz (cam 1, ζ = b/(2√(m (c + c_r))) = 2.0 %) and 87.5 Hz (cam 2, ζ = 3.2 %), and
the coupled quasi-frequencies of these branches run from 80.2 to 91.5 Hz over the
revolution. They lie between the 4th and 5th harmonics of the speed (80, 100 Hz), and a
rise lasts 100° or 90° (13.9 or 12.5 ms), about one follower period (10.9, 11.4 ms).
The 4th harmonic dominates q of cam 2 (amplified 5.7 times on a rigid cam), and the 5th
and 3rd dominate q of cam 1. The numbers that settle it, for cam 1 / cam 2:

* quasi-static deformation under the peak inertia force, m max|U''| Ω² / c: 4.3 / 4.9 mm;
* the follower alone on a rigid cam in steady state (harmonic balance): 9.3 / 16.4 mm;
* the chapter's 4-DOF model (rigid frame, elastic shaft): 9.6 / 18.2 mm;
* this coupled model: 9.3 / 18.6 mm. The frame lowers the follower branches by 0.4 to
  0.7 %, which changes the amplitudes by −3 / +2 %.

``tests/test_coupled_examples.py`` checks the coupled result against the 4-DOF model,
solved independently by Fourier collocation. Linear theory keeps the cam contact
bilateral. A deformation of 18.6 mm is a follower spring force c q of about 11 kN, so a
real force-closed follower with 5 kN/m return springs would lift off the cam at this
speed. The deformations fall at lower speeds: on a rigid cam they are up to 3.0 mm at
600 rpm and 0.5 mm at 300 rpm. The stability chart covers 300..2400 rpm.

Run time: the full run (sweep over 181 angles, steady state with 2880 steps per
revolution, stability chart over 70 speeds and 4 damping ratios) takes 115 s of CPU
time. On 2 cores shared with other jobs that was 6.1 min of wall time (8.6 min has been
seen). About 95 % of it is the stability chart, whose progress bar shows on stderr.
``--quick`` takes 30 s of CPU time (74 s of wall time under the same load). It uses 37
angles, 6 speeds and 2 damping ratios, and a steady state that starts from 180 steps
and doubles to the same tolerance (rtol 1e-3, 1440 steps). It gives the same
deformations to 0.15 % (9274.4 / 18554.2 µm, against 9286.9 / 18553.8 µm).

Sources: textbook chapter 5, "Schwingungsmodelle mit mehreren Freiheitsgraden", section
5.2.3.2, eqs. 11, 16, 20, 21 with errata 29-30; Norton, *Cam Design
and Manufacturing Handbook* (2009), ch. 3 (cam laws); torsion of a circular shaft
``c_T = G I_p / L`` (e.g. Gere & Goodno, *Mechanics of Materials*, §3.3).

Run: ``python examples/processing_machine.py --out out/processing_machine [--quick]``
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

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
from femmech.fe.generators import grid_frame
from femmech.mechanisms import (
    processing_machine,
    processing_machine_cams,
    processing_machine_parameters,
    quasi_modes,
    rheolinear,
    second_kind,
)
from femmech.mechanisms.mounted import cam_follower
from femmech.output.histories import plot_orbit, plot_time_histories, write_history_csv
from femmech.output.stability_charts import plot_speed_study
from femmech.output.sweeps import plot_quasi_frequencies, write_sweep_csv
from femmech.reduction import craig_bampton
from femmech.scene.workshop import progress

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0, name="steel")
SHAFT = sections.circle(0.03)
FRAME_SECTION = sections.rectangular_hollow(0.05, 0.05, 0.004)
WIDTH, HEIGHT = 0.3, 0.35  # m, frame width (y) and shaft height (z)
BRACKET_OFFSET = 0.075  # m, return-spring base beside the bearing along y
BEARING_K = 2e8  # N/m
DRIVE_TILT_K = 5e6  # N m/rad, tilting stiffness of the drive-end (gearbox) bearing
DISC_MASS = (20.0, 2.0, 2.0)  # kg at the J0, J1, J2 stations
PARAMS = processing_machine_parameters(kinematic_drive=True)
# dynamics: operating speed (illustrative, as examples/mechanism_quasi_modes.py; the
# chapter gives none), frame (and FE shaft) Rayleigh damping
OPERATING_RPM = 1200.0
FRAME_ZETA, ZETA_BAND_HZ = 0.02, (80.0, 500.0)
CAMS = (("U1", "m1", "c3", "c6", "b3", "F1"), ("U2", "m2", "c4", "c7", "b4", "F2"))
QUICK = dict(n_angles=37, n_speeds=6, zetas=(0.005, 0.02), steady_steps=180)
"""Settings of ``--quick``: the same steady state (step doubling to the same rtol)."""


def segment_lengths(params=PARAMS) -> np.ndarray:
    """Shaft segment lengths L_k = G I_p / cT_k (m) giving the chapter's cT1, cT2."""
    return STEEL.shear_modulus * SHAFT.J / np.array([params["cT1"], params["cT2"]])


def _shaft_mesh(lengths, per_segment: int):
    """Shaft points along x at (y, z) = (WIDTH/2, HEIGHT) and the station indices."""
    x = np.concatenate([[0.0], *(np.linspace(a, a + L, per_segment + 1)[1:] for a, L in
                                 zip(np.concatenate([[0.0], np.cumsum(lengths)[:-1]]),
                                     lengths, strict=True))])
    points = np.column_stack([x, np.full(x.size, WIDTH / 2), np.full(x.size, HEIGHT)])
    return points, per_segment * np.arange(3)


def _nearest(points, target) -> int:
    return int(np.argmin(np.linalg.norm(points - np.asarray(target), axis=1)))


def _discs(stations) -> list[fm.PointMass]:
    """Disc masses with polar inertia J and diametral J/2 (thin disc) at the stations."""
    inertia = (PARAMS["J0"], PARAMS["J1"], PARAMS["J2"])
    return [fm.PointMass(int(s), m, (J, J / 2, J / 2))
            for s, m, J in zip(stations, DISC_MASS, inertia, strict=True)]


def build_fe(rigid_frame: bool = False, rho_scale: float = 1.0, per_segment: int = 4):
    """FE model of shaft (+ frame); returns (model, station nodes (3,), bracket nodes (2,)).

    ``rigid_frame``: no frame, the bearings are supports (uy, uz; the drive end
    clamped) and the return-spring bases are the supported station nodes.
    ``rho_scale`` scales the shaft's density (the discs keep their inertia).
    """
    lengths = segment_lengths()
    shaft_pts, stations = _shaft_mesh(lengths, per_segment)
    n_s = len(shaft_pts)
    shaft_lines = np.column_stack([np.arange(n_s - 1), np.arange(1, n_s)])
    steel = fm.Material(E=STEEL.E, nu=STEEL.nu, rho=STEEL.rho * rho_scale)
    beams = {"shaft": fm.BeamProperty(SHAFT, steel)}
    if rigid_frame:
        mesh = fm.Mesh.from_lines(shaft_pts, shaft_lines, {"shaft": np.arange(n_s - 1)})
        supports = [fm.Support(int(stations[0])),
                    fm.Support([int(s) for s in stations[1:]], ["uy", "uz"])]
        model = fm.build_model(mesh, beams, masses=_discs(stations), supports=supports)
        return model, stations, stations[1:]
    frame = grid_frame((2, 1, 1), (lengths.sum(), WIDTH, HEIGHT), subdivisions=4)
    points = np.vstack([frame.points, shaft_pts])
    lines = np.vstack([frame.cells["line"], frame.n_nodes + shaft_lines])
    n_frame_cells = len(frame.cells["line"])
    stations = frame.n_nodes + stations
    mesh = fm.Mesh(points, {"line": lines},
                   {"frame": {"line": np.arange(n_frame_cells)},
                    "shaft": {"line": n_frame_cells + np.arange(n_s - 1)}},
                   {"feet": frame.node_sets["base"], "drive_end": [int(stations[0])]})
    housings = [_nearest(frame.points, points[s]) for s in stations]
    brackets = np.array([_nearest(frame.points, points[s] + [0.0, BRACKET_OFFSET, 0.0])
                         for s in stations[1:]])
    beams["frame"] = fm.BeamProperty(FRAME_SECTION, STEEL)
    bearings = [fm.Spring(int(s), h, [0.0, BEARING_K, BEARING_K, 0, 0, 0])
                for s, h in zip(stations, housings, strict=True)]
    bearings.append(fm.Spring(int(stations[0]), housings[0],
                              [BEARING_K, 0, 0, 0, DRIVE_TILT_K, DRIVE_TILT_K]))
    model = fm.build_model(mesh, beams, masses=_discs(stations), springs=bearings,
                           supports=[fm.Support("feet"), fm.Support(int(stations[0]), ["rx"])])
    return model, stations, brackets


def cam_models(form=rheolinear) -> list:
    """The two cam mechanisms with the chapter's parameter names (U1: m1, c3, c6, ...),
    built by ``form`` (:func:`rheolinear` for the coupled system, :func:`second_kind`
    for the drive torque)."""
    return [form(cam_follower(U, m, c, cr, b, F, name=f"cam {U}"),
                 {p: PARAMS[p] for p in (m, c, cr, b, F)}, {U: processing_machine_cams()[U]})
            for U, m, c, cr, b, F in CAMS]


def follower_estimates(rpm: float = OPERATING_RPM) -> list[dict]:
    """Each cam's follower on a rigid cam (rigid shaft and frame), at ``rpm``.

    Keys: ``f_hz``, its natural frequency √((c + c_r)/m)/2π (Hz); ``zeta``, its damping
    ratio b/(2√(m (c + c_r))); ``order``, f_hz over the speed in Hz; ``quasi_static``,
    the deformation m max|U''| Ω²/c (m) under the peak inertia force.
    """
    W = 2 * np.pi * rpm / 60.0
    phi = np.linspace(0.0, 2 * np.pi, 3601)
    estimates = []
    for U, m, c, cr, b, _ in CAMS:
        m, c, cr, b = (PARAMS[k] for k in (m, c, cr, b))
        w = np.sqrt((c + cr) / m)
        accel = np.abs(processing_machine_cams()[U].derivatives(phi)[2]).max() * W**2
        estimates.append({"f_hz": w / (2 * np.pi), "zeta": b / (2 * np.sqrt(m * (c + cr))),
                          "order": w / W, "quasi_static": m * accel / c})
    return estimates


def dominant_order(history) -> int:
    """Harmonic order (≥ 1) of the largest Fourier amplitude of a periodic history
    sampled on one period (n_t + 1 points, the last repeating the first)."""
    return int(np.argmax(np.abs(np.fft.rfft(np.asarray(history)[:-1])[1:]))) + 1


def mounts(stations, brackets) -> list[Mount]:
    """The cam mechanisms attached to the shaft stations and the return-spring brackets."""
    return [Mount(model, (Attachment("q_s", int(stations[k + 1]), "rx"),
                          Attachment("y_c", int(stations[k + 1]), "uz"),
                          Attachment("y_f", int(brackets[k]), "uz")), name=f"cam{k + 1}")
            for k, model in enumerate(cam_models())]


def build(f_max_hz: float = 1500.0, rigid_frame: bool = False, rho_scale: float = 1.0):
    """(reduced coupled system, full coupled system, FE model, superelement)."""
    model, stations, brackets = build_fe(rigid_frame, rho_scale)
    interface = [(stations[1:], ["rx"])]
    if not rigid_frame:
        interface += [(stations[1:], ["uz"]), (brackets, ["uz"])]
    se = craig_bampton(model, interface, f_max_hz=f_max_hz)
    reduced = couple(se, mounts(stations, brackets))
    full = couple(model, mounts(stations, brackets))
    return reduced, full, model, se


def mechanism_only(phi):
    """Quasi-modes of the chapter's 4-DOF model (kinematic drive, Ω = 0)."""
    model = rheolinear(processing_machine(kinematic_drive=True), PARAMS, processing_machine_cams())
    return quasi_modes(model, phi)


def rigid_check(phi, rho_scale: float = 1e-6):
    """Max relative difference of the rigid-frame coupled sweep from the chapter model.

    With the bearings rigid, y_c = y_f = 0 and the FE shaft gives exactly cT1, cT2; the
    only difference is the shaft's own (distributed) mass, scaled by ``rho_scale``. It
    adds about ``rho I_p L`` to the disc inertias and raises the shaft's bending modes by
    ``1/sqrt(rho_scale)``, so the difference falls linearly with ``rho_scale``.
    """
    reduced, _, _, _ = build(rigid_frame=True, rho_scale=rho_scale, f_max_hz=2000.0)
    coupled = sweep(reduced, phi, n_modes=4, track=False)
    alone = mechanism_only(phi)
    return float(np.abs(coupled.freq_hz / alone.freq_hz - 1).max()), coupled, alone


def steady_state(base, rpm: float = OPERATING_RPM, steady_steps: int = 720):
    """Periodic steady state at ``rpm`` of the coupled machine ``base`` (:func:`build`)
    with the frame's Rayleigh damping.

    Shooting with ρ∞ = 1, Richardson-extrapolated, from ``steady_steps`` steps per
    revolution doubled to the default rtol. Returns (Response, damped system, Rayleigh
    coefficients (a in 1/s, b in s)).
    """
    rayleigh = rayleigh_coefficients(FRAME_ZETA, *ZETA_BAND_HZ)
    system = rayleigh_damping(base, *rayleigh)
    r = periodic_steady_state(system, 2 * np.pi * rpm / 60.0, n_steps=steady_steps,
                              rho_inf=1.0, richardson=True)
    return r, system, rayleigh


def dynamics(out_dir="out/processing_machine", rpm: float = OPERATING_RPM,
             n_speeds: int = 70, zetas=(0.0025, 0.005, 0.01, 0.02),
             n_steps: int = 32, steady_steps: int = 720, bars: bool = False) -> dict:
    """Periodic steady state at ``rpm`` and Floquet stability over speed.

    Steady state (:func:`steady_state`): follower deformations q of both cams
    (the near-resonance of the module docstring), shaft twist at
    the cams, forces of the cams on shaft and frame, the motor torque at the kinematic
    drive (reaction of the drive end's rx support, :func:`support_reactions`) next to the
    sum of the cams' drive rows (what a rigid shaft would transmit), and the orbit of the
    shaft centre at cam 1. Stability over 300..2400 rpm
    (:func:`femmech.analysis.stability.speed_study`), with 2 f_k / j marked; ``bars``
    shows its progress.
    """
    start = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    base, _, model, _ = build()
    r, system, rayleigh = steady_state(base, rpm, steady_steps)
    W = 2 * np.pi * rpm / 60.0
    drive = ConstantSpeed(W)
    forces = attachment_forces(system, r, drive)
    cams = [int(m.attachments[0].node) for m in system.mounts]
    motor = support_reactions(system, model, r, [("drive_end", "rx")], *rayleigh)[:, 0]
    rows = sum(drive_forces(lg, r, drive, system, mount=k)[:, 0]
               for k, lg in enumerate(cam_models(second_kind)))
    twist = frame_history(system, model, r.q, [(c, "rx") for c in cams])
    centre = frame_history(system, model, r.q, [(cams[0], "uy"), (cams[0], "uz")])
    deg = np.rad2deg(r.phi)
    q = {f"cam{k + 1}.q": r.q[:, system.labels.index(f"cam{k + 1}.q")] for k in range(2)}
    force_curves = dict(zip(forces.labels, forces.forces.T, strict=True))
    where = {"y_c": "at the cam bearing", "y_f": "at the return-spring base"}
    plot_time_histories(deg, {
        "follower deformation q (µm)": {system.describe(k): 1e6 * v for k, v in q.items()},
        "shaft twist at cam (mrad)": {f"cam {k + 1}": 1e3 * twist[:, k] for k in range(2)},
        "cam force on frame (N)": {
            f"cam {k[3]} {where[k.split('.')[1]]} [{k}]": f
            for k, f in force_curves.items() if k.split(".")[-1] in where},
        "torque (N m)": {"motor (drive-end reaction)": motor,
                         "Σ cam drive rows (rigid shaft)": rows}},
        out / "steady_state.png", xlabel="drive angle φ (deg)",
        title=f"Processing machine at {rpm:.0f} rpm: periodic steady state (follower"
              " modes near the 4th and 5th harmonics)", angle_deg=True)
    plot_orbit(1e6 * centre[:, 0], 1e6 * centre[:, 1], out / "shaft_orbit_cam1.png",
               "shaft centre at cam 1, u_y (µm)", "u_z (µm)",
               f"Shaft at cam 1 over one revolution at {rpm:.0f} rpm")
    write_history_csv(r.t, {"phi_deg": deg, **{f"{k}_m": v for k, v in q.items()},
                            **{f"{k}_N_or_Nm": f for k, f in force_curves.items()},
                            "motor_torque_Nm": motor, "cam_drive_rows_Nm": rows},
                      out / "steady_state.csv")
    print(f"steady state at {rpm:.0f} rpm ({r.n_steps} steps per revolution,"
          f" {time.perf_counter() - start:.1f} s): follower deformation up to"
          f" {1e6 * max(np.abs(v).max() for v in q.values()):.1f} µm, motor torque"
          f" {motor.min():.1f} .. {motor.max():.1f} N m (cam drive rows"
          f" {rows.min():.1f} .. {rows.max():.1f} N m)", flush=True)
    for (name, v), e in zip(q.items(), follower_estimates(rpm), strict=True):
        print(f"  {name}: up to {1e6 * np.abs(v).max():.1f} µm ="
              f" {np.abs(v).max() / e['quasi_static']:.1f} x the quasi-static m a_max/c ="
              f" {1e6 * e['quasi_static']:.1f} µm; harmonic {dominant_order(v)} dominates,"
              f" follower mode {e['f_hz']:.1f} Hz = {e['order']:.2f} x speed on a rigid"
              f" cam, ζ = {100 * e['zeta']:.1f} %", flush=True)
    start = time.perf_counter()
    study = speed_study(base, 2 * np.pi / 60.0 * np.linspace(300.0, 2400.0, n_speeds),
                        FRAME_ZETA, ZETA_BAND_HZ, zetas, n_steps=n_steps,
                        progress=lambda points: progress(points, "stability", bars))
    plot_speed_study(study, out, "Processing machine")
    print(f"stability ({n_speeds} speeds x {1 + len(zetas)} damping cases,"
          f" {time.perf_counter() - start:.1f} s): {study.summary()}", flush=True)
    return {"steady_state": r, "forces": forces, "motor_torque": motor, "drive_rows": rows,
            "study": study, "system": system}


def main(out_dir="out/processing_machine", n_angles: int | None = None, n_modes: int = 9,
         with_dynamics: bool = True, n_speeds: int | None = None, quick: bool = False,
         bars: bool = False) -> dict:
    """Sweep, plot, CSV and both checks, then ``dynamics``; returns the key numbers.

    ``n_angles`` and ``n_speeds`` default to 181 and 70, or to :data:`QUICK` with
    ``quick`` (which also shortens the steady state's first step count and the damping
    ratios of the chart); ``bars`` shows the stability chart's progress.
    """
    settings = QUICK if quick else dict(n_angles=181, n_speeds=70,
                                        zetas=(0.0025, 0.005, 0.01, 0.02), steady_steps=720)
    n_angles = settings["n_angles"] if n_angles is None else n_angles
    n_speeds = settings["n_speeds"] if n_speeds is None else n_speeds
    start = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    phi = np.linspace(0.0, 2 * np.pi, n_angles)
    reduced, full, model, se = build()
    result = sweep(reduced, phi, n_modes=n_modes)
    check = np.deg2rad([0.0, 50.0, 120.0, 230.0, 320.0])
    comparison = compare_coupled(reduced, full, check, n_modes)
    errors, macs = np.abs(comparison.rel_error), comparison.diag_mac
    rigid_error, rigid, alone = rigid_check(phi)
    plot_quasi_frequencies({"frame + FE shaft (reduced)": result},
                           out / "quasi_frequencies.png",
                           title="Cam-driven processing machine on a frame")
    plot_quasi_frequencies({"rigid frame, massless FE shaft": rigid, "chapter model": alone},
                           out / "rigid_frame_check.png",
                           title="Rigid frame: coupled model vs mechanism alone")
    write_sweep_csv(result, out / "quasi_frequencies.csv")
    (out / "reduced_vs_full.txt").write_text(comparison.table() + "\n")
    print(f"FE model {model.n_free} free DOFs, superelement {se.n_reduced}, coupled"
          f" {reduced.n}; segment lengths {segment_lengths()} m")
    print(f"reduced vs full at {len(check)} angles: max frequency error {errors.max():.2e},"
          f" min MAC {macs.min():.10f}")
    print(f"rigid frame vs chapter model: max relative difference {rigid_error:.2e}"
          f" (sweep and checks over {n_angles} angles: {time.perf_counter() - start:.1f} s)",
          flush=True)
    summary = {"sweep": result, "max_error": float(errors.max()), "min_mac": float(macs.min()),
               "rigid_error": rigid_error, "n_full": full.n, "n_reduced": reduced.n}
    if with_dynamics:
        summary["dynamics"] = dynamics(out, n_speeds=n_speeds, zetas=settings["zetas"],
                                       steady_steps=settings["steady_steps"], bars=bars)
    print(f"total {time.perf_counter() - start:.1f} s")
    return summary


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/processing_machine")
    parser.add_argument("--angles", type=int, default=None, help="sweep angles (181)")
    parser.add_argument("--speeds", type=int, default=None,
                        help="speeds of the stability chart (70)")
    parser.add_argument("--quick", action="store_true",
                        help="37 angles, 6 speeds x 2 damping ratios, the same steady state")
    args = parser.parse_args()
    main(args.out, args.angles, n_speeds=args.speeds, quick=args.quick, bars=True)
