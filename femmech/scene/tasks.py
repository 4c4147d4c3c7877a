"""The analyses of a scene run: each computes, writes its files and returns a report
:class:`~femmech.output.report.Section` and its key numbers (JSON-able, no timings).

Each task takes ``(workshop, spec, out)``; see :mod:`femmech.scene.run` for the workshop
(lazy FE models, cached reductions, coupled machines) and :mod:`femmech.scene.analyses`
for the specs.

Stage 8 (scene), compute and write: uses scene.workshop, scene.build, analysis, output,
coupling and mechanisms.
"""

from __future__ import annotations

import csv
import io
import math
import time
import warnings
from dataclasses import dataclass

import numpy as np

from femmech.analysis.discretisation import discretisation_error_of
from femmech.analysis.drive_events import spring_forces, trip_and_brake
from femmech.analysis.modes import modes, superelement_modes
from femmech.analysis.reference import Comparison, compare_coupled
from femmech.analysis.response import (
    SpeedRamp,
    frame_history,
    periodic_steady_state,
    rayleigh_damping,
    time_response,
)
from femmech.analysis.stability import stability_chart
from femmech.analysis.studies import merge_charts
from femmech.analysis.sweep import sweep
from femmech.chain.sweep import chain_sweep
from femmech.chain.synthesis import (
    FrequencyBands,
    Parameter,
    frequency_bands,
    margin_of,
    synthesise,
)
from femmech.coupling import couple
from femmech.errors import ConvergenceWarning
from femmech.fe.model import node_index
from femmech.mechanisms import Spring, quasi_modes
from femmech.mechanisms.catalogue import readable
from femmech.output import export_modes_vtu, frequency_table, plot_mac, write_frequency_csv
from femmech.output.animate import animate_mode
from femmech.output.campbell import plot_campbell, plot_margins, plot_synthesis
from femmech.output.charts import format_speed, needs_log_scale, set_angle_axis, speed_scale
from femmech.output.export import atomic_path
from femmech.output.formatting import Quantity, format_value
from femmech.output.histories import plot_event_histories, write_history_csv
from femmech.output.report import Figure, Flagged, Section, Table, rigid_modes_note
from femmech.output.series import write_mode_series
from femmech.output.stability_charts import plot_stability_chart
from femmech.output.sweeps import plot_quasi_frequencies
from femmech.output.tables import error_budget_columns
from femmech.scene.analyses import MAX_DRIVE_EVALUATIONS
from femmech.scene.build import machine_mounts
from femmech.scene.chain import (
    DESIGN,
    METHOD_NAMES,
    build_chain,
    design_quantity,
    design_values,
    plot_method_sweeps,
)
from femmech.scene.machine import describe_quantity, parameter_kinds
from femmech.scene.summary import participation_tables
from femmech.scene.units import ANGLE, FORCE, LENGTH, MOMENT, ROT_STIFFNESS, STIFFNESS
from femmech.scene.workshop import progress


def _list(a) -> list:
    """Nested list of floats with NaN as None (valid JSON)."""
    a = np.asarray(a, dtype=float)
    if a.ndim > 1:
        return [_list(x) for x in a]
    return [float(x) if math.isfinite(x) else None for x in np.atleast_1d(a)]


def _write_csv(path, header, rows) -> None:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    writer.writerows([[repr(float(v)) if isinstance(v, (float, np.floating)) else v
                       for v in row] for row in rows])
    with atomic_path(path) as tmp:
        tmp.write_text(buffer.getvalue(), encoding="utf-8")


def run_modes(ws, spec, out):
    """Natural modes of a part (full FE model or its superelement)."""
    drawn = spec.images or spec.vtu or spec.series or spec.animate
    model = ws.model(spec.part) if (spec.model == "full" or drawn
                                    or spec.discretisation_error) else None
    with ws.timed("eigen solve"):
        if spec.model == "full":
            result = modes(model, n_modes=spec.n_modes, band_hz=spec.band_hz)
        else:
            result = superelement_modes(ws.superelement(spec.part), spec.n_modes,
                                        spec.band_hz, model=model)
    with atomic_path(out / "frequencies.txt") as tmp:
        tmp.write_text(frequency_table(result), encoding="utf-8")
    write_frequency_csv(result, out / "frequencies.csv")
    files = ["frequencies.csv", "frequencies.txt"]
    if spec.vtu:
        export_modes_vtu(model, result, out / "modes.vtu")
        files.append("modes.vtu")
    if spec.series:
        write_mode_series(model, result, out / "modes.pvd")
        files.append("modes.pvd")  # with its folder modes_steps/
    figures = []
    for k in spec.animate:  # 1-based mode numbers; those beyond the computed set: noted
        if k > result.n_modes:
            ws.log(f"modes: animate mode {k}: only {result.n_modes} modes were computed")
            continue
        with ws.timed("mode animations"):
            path = animate_mode(model, result, k - 1, out / f"mode_{k:02d}.gif")
        figures.append(Figure(path.name, f"mode {k}: {result.freq_hz[k - 1]:.3f} Hz, moving"
                                         " through one period (slowed down)"))
    if spec.images:
        from femmech.output import plot_modes

        n = min(spec.images, result.n_modes)
        with ws.timed("mode images"):  # one scene and one camera for all images
            paths = plot_modes(model, result, out, range(n), prefix="mode",
                               progress=lambda it: progress(it, "mode images", ws.bars))
        figures += [Figure(p.name, f"mode {i + 1}: {result.freq_hz[i]:.3f} Hz")
                    for i, p in enumerate(paths)]
    est, confirmed = result.error_estimate, result.index_confirmed
    header = ("mode", "frequency (Hz)", "rigid") + (("estimated rel. error",) if est is not
                                                    None else ()) + (
        ("index vs full",) if confirmed is not None else ())
    rows = tuple((i + 1, Quantity(float(f), digits=6), "yes" if r else "no")
                 + ((Quantity(float(est[i]), digits=2),) if est is not None else ())
                 + ((_index_cell(confirmed[i]),) if confirmed is not None else ())
                 for i, (f, r) in enumerate(zip(result.freq_hz, result.rigid, strict=True)))
    solver = f", factorisation {result.solver}" if result.solver else ""
    text = (f"Part {spec.part!r}, {spec.model} model ({result.method} solver{solver}):"
            f" {result.n_modes} modes.",)
    if result.n_unconfirmed:
        text += (f"{result.n_unconfirmed} reduced mode(s) marked unconfirmed: a Sturm count"
                 " of the full model shows that the full mode of the same number lies below"
                 " the error estimate (the reduction missed a mode below them); their"
                 " estimates compare with another full mode. Keep more fixed-interface"
                 " modes.",)
    extra = {}
    if spec.discretisation_error:  # opt-in: one h/2 refinement of the full model
        with ws.timed("discretisation estimate"):
            disc = discretisation_error_of(result, model, reduced=spec.model != "full")
        more, cells = error_budget_columns(disc, est)
        header, rows = header + more, tuple(r + c for r, c in zip(rows, cells, strict=True))
        text += (f"Discretisation error: estimated by one uniform refinement (h/2, free DOFs"
                 f" {' → '.join(map(str, disc.n_dof))}) and Richardson extrapolation with"
                 f" rate h^{disc.rate:g} ({', '.join(disc.kinds)} elements); highlighted"
                 " estimates are not trusted (their reason is given)."
                 + (" Total = discretisation + reduction." if est is not None else ""),)
        extra["discretisation_error"] = _list(np.where(disc.trusted, disc.error, np.nan))
    with ws.timed("mass participation"):
        tables, notes = participation_tables(model if model is not None else
                                             ws.model(spec.part), result, spec.part)
    section = Section("Natural modes", text + notes,
                      (Table("Natural frequencies", header, rows,
                             rigid_modes_note(result.rigid)), *tables),
                      tuple(figures), tuple(files), gallery=True)
    return section, {"part": spec.part, "model": spec.model, "freq_hz": _list(result.freq_hz),
                     **extra}


def _index_cell(confirmed):
    """The index cell of a reduced mode: confirmed by the full model's Sturm count or
    flagged."""
    return "confirmed" if confirmed else Flagged("unconfirmed")


def run_sweep(ws, spec, out):
    """Quasi-eigenfrequencies over the drive angle, per speed."""
    phi = np.asarray(spec.angles, dtype=float)
    unit, curves, notes = spec.speed_unit, {}, []
    for W in spec.speeds:
        label = format_speed(W, unit)
        with ws.timed("sweep"):
            if spec.mechanism is not None:
                q = quasi_modes(ws.prepared.mechanisms[spec.mechanism], phi, Omega=W)
                n_default = min(6, q.freq_hz.shape[1])
                curves[label] = _Curve(q.phi, q.freq_hz[:, :spec.n_modes or n_default])
                if spec.n_modes is None and q.freq_hz.shape[1] < 6:
                    notes.append(f"n_modes not given: the mechanism has"
                                 f" {q.freq_hz.shape[1]} branches, fewer than the default 6;"
                                 " all are shown")
            else:
                s = sweep(ws.machine(), phi, Omega=W, n_modes=spec.n_modes, track=spec.track)
                curves[label] = _Curve(s.phi, s.freq_hz)
                notes.extend(s.notes)
    what = f"mechanism {spec.mechanism!r} alone" if spec.mechanism else "coupled machine"
    plot_quasi_frequencies(curves, out / "quasi_frequencies.png",
                           title=f"{ws.scene.name}: {what}", speed_unit=unit)
    n = next(iter(curves.values())).freq_hz.shape[1]
    rows = [(W * speed_scale(unit), float(np.rad2deg(a)), *c.freq_hz[i])
            for W, c in zip(spec.speeds, curves.values(), strict=True)
            for i, a in enumerate(c.phi)]
    _write_csv(out / "quasi_frequencies.csv", [_speed_column(unit), "angle_deg"] +
               [f"f{k + 1}_hz" for k in range(n)], rows)
    table_rows = tuple((label, k + 1, float(np.nanmin(c.freq_hz[:, k])),
                        float(np.nanmax(c.freq_hz[:, k])))
                       for label, c in curves.items() for k in range(n))
    figures = [Figure("quasi_frequencies.png", f"Quasi-eigenfrequencies of the {what}")]
    for angle in spec.mode_images_at:
        figures.append(_coupled_image(ws, spec, angle, out))
    text = (f"{phi.size} drive angles from {np.rad2deg(phi[0]):.1f}° to"
            f" {np.rad2deg(phi[-1]):.1f}°, {n} branches, speeds {', '.join(curves)}.",
            *(f"{note}." for note in dict.fromkeys(notes)))
    section = Section("Quasi-eigenfrequencies over the drive angle", text,
                      (Table("Range of each branch over the sweep", ("speed", "branch",
                                                                    "min (Hz)", "max (Hz)"),
                             table_rows),), tuple(figures), ("quasi_frequencies.csv",))
    return section, {"phi_rad": _list(phi), "speeds_rad_s": list(spec.speeds),
                     "freq_hz": [_list(c.freq_hz) for c in curves.values()]}


def _speed_column(unit: str) -> str:
    """CSV column of a drive speed in ``unit``: speed_rpm, speed_rad_s."""
    return "speed_" + unit.replace("/", "_")


def _speed_range(lo: float, hi: float, unit: str) -> str:
    """Speeds lo..hi (rad/s) as text in ``unit``: "100..300 rpm", or "100 rpm"."""
    a, b = format_speed(lo, unit), format_speed(hi, unit)
    return a if a == b else f"{a.split()[0]}..{b}"


@dataclass(frozen=True)
class _Curve:
    """phi (rad) and freq_hz of one sweep, for plot_quasi_frequencies."""

    phi: np.ndarray
    freq_hz: np.ndarray


def _coupled_image(ws, spec, angle: float, out) -> Figure:
    """The lowest coupled quasi-mode at exactly the requested angle (rad) and the first
    speed of the sweep: solved there, not taken from the nearest angle of the sweep grid."""
    from femmech.output.machine import plot_coupled_mode

    W = float(spec.speeds[0])
    at = sweep(ws.machine(), np.array([angle]), Omega=W, n_modes=1, track=False,
               keep_vectors=True)
    deg = float(np.rad2deg(angle))
    name = "coupled_mode_" + f"{deg:g}".replace(".", "p") + "deg.png"  # 22.5° → 22p5deg
    part = next(iter(ws.scene.parts))
    plot_coupled_mode(ws.model(part), ws.machine(), at.vectors[0, :, 0], at.freq_hz[0, 0],
                      out / name, angle=angle, speed=W, mode_number=1,
                      speed_unit=spec.speed_unit)
    return Figure(name, f"lowest coupled quasi-mode at φ = {deg:g}°,"
                  f" {format_speed(W, spec.speed_unit)}: {at.freq_hz[0, 0]:.2f} Hz")


def _damped(ws, rayleigh):
    system = ws.machine()
    return rayleigh_damping(system, *rayleigh) if any(rayleigh) else system


def run_stability(ws, spec, out):
    """Floquet spectral radius over drive speed (stability chart), each point checked."""
    system = _damped(ws, spec.rayleigh)
    speeds = np.asarray(spec.speeds, dtype=float)
    with warnings.catch_warnings():  # unconverged points are marked below, not warned
        warnings.simplefilter("ignore", ConvergenceWarning)
        points = [stability_chart(system, [W], n_steps=spec.n_steps,
                                  angle_period=spec.angle_period, tol=spec.tol,
                                  rtol=spec.rtol, max_steps=spec.max_steps)
                  for W in progress(speeds, "stability", ws.bars)]
    chart = merge_charts(points, 1, len(points), speeds, None)
    radius, error, stable = chart.spectral_radius[0], chart.error[0], chart.stable[0]
    ok, steps = chart.converged[0], chart.n_steps[0]
    unit, scale = spec.speed_unit, speed_scale(spec.speed_unit)
    plot_stability_chart(chart, out / "stability_chart.png", title=ws.scene.name,
                         speed_unit=unit)
    _write_csv(out / "stability.csv", [_speed_column(unit), "spectral_radius",
                                       "error_estimate", "converged", "n_steps", "stable"],
               [(W * scale, r, e, int(c), n, int(s) if c else "")
                for W, r, e, c, n, s in zip(speeds, radius, error, ok, steps, stable,
                                            strict=True)])
    unstable = speeds[~stable & ok]
    text = (f"{speeds.size} speeds from {format_speed(speeds[0], unit)} to"
            f" {format_speed(speeds[-1], unit)};"
            f" Rayleigh damping (mass, stiffness) = {spec.rayleigh}. Magnus steps per period"
            f" doubled from {spec.n_steps} until the spectral radius changed by at most"
            f" {spec.rtol:g} (relative; {steps.min()}..{steps.max()} steps were needed)."
            f" Unstable at {unstable.size} speeds"
            + (f" ({_speed_range(unstable.min(), unstable.max(), unit)}, shaded in the"
               " chart)." if unstable.size else "."),)
    flags = ()
    if not ok.all():
        bad = speeds[~ok]
        flags = (f"{int((~ok).sum())} of {speeds.size} speeds"
                 f" ({_speed_range(bad.min(), bad.max(), unit)}) did NOT converge"
                 f" within max_steps = {spec.max_steps} Magnus steps per"
                 " period: their spectral radius and verdict may be wrong (hollow circles on"
                 " a hatched band in the chart, converged = 0 in stability.csv). Raise"
                 " max_steps.",)
        ws.log(f"stability: {flags[0]}")
    rows = tuple((float(W * scale), float(r), f"{e:.1e}", "yes" if s else "no")
                 if c else (float(W * scale), Flagged(f"{r:.6g} NOT CONVERGED"), f"{e:.1e}",
                            Flagged("unknown"))
                 for W, r, e, c, s in zip(speeds, radius, error, ok, stable, strict=True))
    section = Section("Stability chart", text, (Table("Spectral radius of the monodromy"
                                                      " matrix", (f"speed ({unit})", "max |μ|",
                                                                  "error estimate of max |μ|",
                                                                  "stable"), rows),),
                      (Figure("stability_chart.png", "Floquet stability over drive speed"),),
                      ("stability.csv",), warnings=flags)
    return section, {"speeds_rad_s": _list(speeds), "spectral_radius": _list(radius),
                     "error_estimate": _list(error), "converged": [bool(c) for c in ok]}


def run_response(ws, spec, out):
    """Periodic steady state or run-up: histories of chosen coordinates."""
    system = _damped(ws, spec.rayleigh)
    labels = list(system.labels)  # outputs checked against them by scene_build.prepare
    with ws.timed("time integration"), warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)  # marked in the report
        if spec.kind == "periodic":
            r = periodic_steady_state(system, spec.speed, n_steps=spec.n_steps,
                                      rtol=spec.rtol, max_steps=spec.max_steps)
        else:
            t = np.linspace(0.0, spec.t_end, spec.n_steps + 1)
            r = time_response(system, t, SpeedRamp(spec.speed_start, spec.speed_end,
                                                   spec.duration))
    columns = {x: r.q[:, labels.index(x)] for x in spec.outputs}
    names = list(ws.scene.parts)
    for part, node, dof in spec.frame_dofs:
        idx = node_index(ws.prepared.meshes[part], node, "frame_dofs")
        ref = idx if len(names) == 1 else (names.index(part), idx)
        columns[f"{part}:{node}:{dof}"] = frame_history(system, None, r.q, [(ref, dof)])[:, 0]
    _write_csv(out / "response.csv", ["t_s", "phi_rad", *columns],
               [(t, p, *(c[i] for c in columns.values()))
                for i, (t, p) in enumerate(zip(r.t, r.phi, strict=True))])
    title = (f"Periodic steady state at {format_speed(spec.speed, spec.speed_unit)}"
             if spec.kind == "periodic" else
             f"Run-up {format_speed(spec.speed_start, spec.speed_unit)} →"
             f" {format_speed(spec.speed_end, spec.speed_unit)} in {spec.duration:g} s")
    shown = {k: system.describe(k) for k in columns}  # HTML and plot; the CSV keeps k
    _plot_response(r, columns, spec.kind, out / "response.png", title, shown,
                   {k: system.unit(k) for k in columns})
    loose = r.converged is False

    def cell(x):
        return Flagged(f"{x:.6g} NOT CONVERGED") if loose else float(x)

    rows = tuple((shown[k], cell(np.abs(c).max()), cell(c.max() - c.min()))
                 for k, c in columns.items())
    if spec.kind == "periodic":
        text = (f"Periodic steady state at {format_speed(spec.speed, spec.speed_unit)} by"
                " shooting"
                f" (generalised-α), {r.n_steps} steps per period: steps doubled from"
                f" {spec.n_steps} until q changed by at most {spec.rtol:g} (relative, mass"
                f" norm); estimated error {r.error:.1e}.",)
    else:
        text = (f"Run-up {format_speed(spec.speed_start, spec.speed_unit)} →"
                f" {format_speed(spec.speed_end, spec.speed_unit)} in"
                f" {spec.duration:g} s, {spec.n_steps} steps (generalised-α, fixed steps).",)
    flags = ()
    if loose:
        flags = (f"The periodic steady state did NOT converge within max_steps ="
                 f" {spec.max_steps} steps per period (estimated error {r.error:.1e} >"
                 f" {spec.rtol:g}): its amplitudes may be wrong. Raise max_steps.",)
        ws.log(f"response: {flags[0]}")
    section = Section("Forced response", text, (Table("Amplitudes (m, rad or modal)",
                                                      ("coordinate", "max |x|",
                                                       "peak to peak"), rows),),
                      (Figure("response.png", "Response histories"),), ("response.csv",),
                      warnings=flags)
    summary = {k: {"max_abs": float(np.abs(c).max()), "peak_to_peak":
                   float(c.max() - c.min())} for k, c in columns.items()}
    if spec.kind == "periodic":
        summary["convergence"] = {"converged": bool(r.converged), "error_estimate":
                                  float(r.error), "n_steps": int(r.n_steps)}
    return section, summary


def _response_unit(name: str, units=None) -> str:
    """Unit of a response column: frame DOFs ``part:node:dof`` are m (u*) or rad (r*);
    mechanism coordinates that of ``units`` (column → unit, from the catalogue), else
    "m or rad" (a user mechanism's SI unit)."""
    dof = name.rsplit(":", 1)[-1] if name.count(":") == 2 else ""
    return {"u": "m", "r": "rad"}.get(dof[:1]) or (units or {}).get(name) or "m or rad"


def _plot_response(r, columns, kind, path, title: str = "", shown=None, units=None) -> None:
    """One panel per column, titled by ``shown`` (column → readable name); the y axis
    carries the unit (``units``: column → unit of a mechanism coordinate)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure as MplFigure

    fig = MplFigure(figsize=(8, 1.2 + 1.8 * max(1, len(columns))), dpi=110,
                    layout="constrained")
    FigureCanvasAgg(fig)
    if title:
        fig.suptitle(title, fontsize=10)
    x = np.rad2deg(r.phi) if kind == "periodic" else r.t
    for i, (name, values) in enumerate(columns.items() or {"(none)": 0 * x}.items()):
        ax = fig.add_subplot(max(1, len(columns)), 1, i + 1)
        ax.plot(x, values, lw=1.0)
        ax.set_title((shown or {}).get(name, name), loc="left", fontsize=9)
        ax.set_ylabel(_response_unit(name, units), fontsize=8)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3), useMathText=True)
        ax.grid(alpha=0.3)
        if kind == "periodic":
            set_angle_axis(ax, float(x.min()), float(x.max()))  # ticks every 45°
    ax.set_xlabel("drive angle φ (°)" if kind == "periodic" else "time t (s)")
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")


def _compare(ws, reduced, full, angles, n_modes, desc) -> Comparison:
    parts = [compare_coupled(reduced, full, [a], n_modes)
             for a in progress(angles, desc, ws.bars)]
    return Comparison(np.concatenate([c.phi for c in parts]),
                      np.vstack([c.freq_full_hz for c in parts]),
                      np.vstack([c.freq_reduced_hz for c in parts]),
                      np.concatenate([c.mac for c in parts]),
                      np.concatenate([c.seconds_full for c in parts]),
                      float(np.mean([c.seconds_reduced for c in parts])))


def run_check(ws, spec, out):
    """Reduced versus unreduced coupled machine; optionally error and time per angle of
    several reduction sizes (the speed-versus-error comparison)."""
    part = next(iter(ws.scene.parts))
    reduced, full = ws.machine(), ws.machine(full=True)
    with ws.timed("check"):
        comp = _compare(ws, reduced, full, spec.angles, spec.n_modes, "check")
    with atomic_path(out / "reduced_vs_full.txt") as tmp:
        tmp.write_text(comp.table() + "\n", encoding="utf-8")
    k = np.arange(spec.n_modes)
    matches = matched_full_modes(comp)
    _write_csv(out / "reduced_vs_full.csv", ["angle_deg", "mode", "full_hz", "reduced_hz",
                                             "rel_error", "mac", "matches_full_mode"],
               [(float(np.rad2deg(a)), int(j + 1), comp.freq_full_hz[i, j],
                 comp.freq_reduced_hz[i, j], comp.rel_error[i, j], comp.diag_mac[i, j],
                 int(matches[i, j] + 1))
                for i, a in enumerate(comp.phi) for j in k])
    plot_mac(comp.mac[0], out / "mac_reduced_vs_full.png", "reduced coupled modes",
             "full coupled modes", f"MAC at φ = {np.rad2deg(comp.phi[0]):.0f}°")
    se = ws.superelement(part)
    err, mac = float(np.abs(comp.rel_error).max()), float(comp.diag_mac.min())
    rows = [("full", full.n, 1e3 * float(comp.seconds_full.mean()), 0.0, 1.0),
            ("scene reduction", reduced.n, 1e3 * comp.seconds_reduced, err, mac)]
    levels = []
    for f_max in spec.levels:
        system = couple(ws.superelement(part, f_max), machine_mounts(ws.prepared))
        c = _compare(ws, system, full, spec.angles, spec.n_modes, f"f_max {f_max:g} Hz")
        e, m = float(np.abs(c.rel_error).max()), float(c.diag_mac.min())
        rows.append((f"f_max {f_max:g} Hz", system.n, 1e3 * c.seconds_reduced, e, m))
        levels.append({"f_max_hz": f_max, "n": system.n, "max_rel_error": e, "min_mac": m})
    tables = [Table("Reduced versus full at the check angles", ("angle (°)", "mode",
                                                               "full (Hz)", "reduced (Hz)",
                                                               "rel. error", "MAC",
                                                               "matches full mode"),
                    tuple((f"{np.rad2deg(a):.1f}", j + 1,  # 8 digits: the error is ~1e-7
                           Quantity(float(comp.freq_full_hz[i, j]), digits=8),
                           Quantity(float(comp.freq_reduced_hz[i, j]), digits=8),
                           f"{comp.rel_error[i, j]:.2e}", f"{comp.diag_mac[i, j]:.8f}",
                           j + 1 if matches[i, j] == j else
                           Flagged(f"{matches[i, j] + 1}: index unconfirmed"))
                          for i, a in enumerate(comp.phi) for j in k)),
              Table("Speed versus error", ("model", "coordinates", "ms per angle",
                                           "max |rel. error|", "min MAC"),
                    tuple((r[0], r[1], f"{r[2]:.2f}", f"{r[3]:.2e}", f"{r[4]:.8f}")
                          for r in rows))]
    figures = [Figure("mac_reduced_vs_full.png", "MAC of reduced against full modes")]
    files = ["reduced_vs_full.txt", "reduced_vs_full.csv"]
    if levels:
        _plot_speed_error(rows, out / "speed_vs_error.png")
        figures.append(Figure("speed_vs_error.png", "Time per angle versus frequency error"))
    text = (f"Superelement of part {part!r}: {se.n_reduced} coordinates (full model"
            f" {len(se.free_interface) + len(se.free_interior)} free DOFs); max |rel. error|"
            f" {err:.2e}, min MAC {mac:.8f} at {comp.phi.size} angles.",)
    off = np.count_nonzero(matches != k)
    if off:
        text += (f"{off} reduced mode(s) resemble another full mode (largest MAC) that is"
                 " also nearer in frequency than the full mode of the same number: the"
                 " reduction missed a full mode below them, so their rows compare different"
                 " modes (marked 'index unconfirmed'). Keep more fixed-interface modes.",)
    section = Section("Reduced versus full", text, tuple(tables), tuple(figures), tuple(files))
    return section, {"rel_error": _list(comp.rel_error), "diag_mac": _list(comp.diag_mac),
                     "max_rel_error": err, "min_mac": mac, "levels": levels}


def matched_full_modes(comp: Comparison) -> np.ndarray:
    """The full mode (0-based) that each reduced mode is, (n_angles, n_modes) of int.

    Reduced mode k is full mode k unless another full mode j has the largest MAC with it
    and lies nearer to its frequency than full mode k: then the reduction missed a full
    mode below, and the row of mode k compares two different modes. A largest MAC off the
    diagonal alone is not enough (the pairs of a symmetric frame mix freely).
    """
    n = comp.freq_full_hz.shape[1]
    same = np.arange(n)
    best = np.argmax(comp.mac, axis=2)
    f_red, f_full = comp.freq_reduced_hz, comp.freq_full_hz
    own = np.abs(f_red / f_full - 1.0)
    other = np.abs(f_red / np.take_along_axis(f_full, best, axis=1) - 1.0)
    return np.where((best != same) & (other < own), best, same)


def _plot_speed_error(rows, path) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure as MplFigure

    fig = MplFigure(figsize=(6.5, 4.2), dpi=110)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    times = [r[2] for r in rows]
    ax.set_xscale("log" if needs_log_scale(times) else "linear")  # a decade or more: log
    ax.set_yscale("log")
    for name, n, ms, err, _ in rows[1:]:
        ax.plot(ms, max(err, 1e-16), "o")
        ax.annotate(f"{name} ({n})", (ms, max(err, 1e-16)), fontsize=7, xytext=(4, 2),
                    textcoords="offset points")
    ax.axvline(rows[0][2], color="0.4", ls="--", lw=0.8)
    ax.annotate(f"full ({rows[0][1]})", (rows[0][2], 0.5), xycoords=("data", "axes fraction"),
                rotation=90, fontsize=7, ha="right")
    ax.set_xlabel("time per drive angle (ms)")
    ax.set_ylabel("max |relative frequency error|")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")


def run_drive_event(ws, spec, out):
    """A drive run up to speed, tripped when its force reaches a limit, braked to rest in
    each braking time: CSV per run, a PNG of the histories, a table of the peaks."""
    model, mech = ws.prepared.mechanisms[spec.mechanism], ws.scene.mechanisms[spec.mechanism]
    with ws.timed("time integration"):
        result = trip_and_brake(model, spec.drive, spec.start, spec.speed, spec.ramp_time,
                                spec.trip_force, spec.braking_times, spec.time_after_stop,
                                end=spec.end, t_max=spec.t_max, samples=spec.samples,
                                method=spec.method, rtol=spec.rtol, atol=spec.atol,
                                max_step=spec.max_step or math.inf, verify=spec.verify,
                                max_evaluations=MAX_DRIVE_EVALUATIONS)
    free = [q.name for q in model.mechanism.coordinates if q not in model.mechanism.drives]
    keys = ("force", spec.drive, *(spec.outputs if spec.outputs is not None else free))
    what = {key: _event_quantity(mech, model, spec, key) for key in keys}
    runs = {f"braking {format_value(r.brake_time, 's', trim=True)}": (r.brake_time, r.history)
            for r in result.runs} or {"approach (no trip)": (None, result.approach)}
    values = {label: _event_values(model, spec, h, keys) for label, (_, h) in runs.items()}
    files = []
    for label, (tb, h) in runs.items():
        name = ("drive_event_approach.csv" if tb is None else "drive_event_braking_"
                + f"{tb:g}".replace(".", "p") + "s.csv")
        write_history_csv(h.t, {_csv_column(key, what[key][1]): v
                                for key, v in values[label].items()}, out / name)
        files.append(name)
    _plot_drive_event(result, runs, values, what, out / "drive_event.png",
                      f"{ws.scene.name}: {what['force'][0]} and braking" if result.tripped
                      else f"{ws.scene.name}: no trip")
    force_unit = "N·m" if spec.rotational else "N"
    text = _drive_event_text(spec, model.mechanism.name, result, what, force_unit)
    flags = () if result.tripped else (text[1] + " Nothing was braked.",)
    for flag in flags:
        ws.log(f"drive_event: {flag}")
    tables = (_drive_event_table(result, values, what, spec),) if result.tripped else ()
    section = Section("Drive-force trip and braking", text[:1] + text[2:] if flags else text,
                      tables,
                      (Figure("drive_event.png", "Time histories; dotted line: the trip"
                              if result.tripped else "Time histories (no trip)"),),
                      tuple(files), warnings=flags)
    return section, _drive_event_numbers(result, values, keys[2:])


def _event_quantity(mech, model, spec, key: str) -> tuple:
    """(description, dimension or None) of a quantity shown by a drive event."""
    if key == "force":
        label, kind = describe_quantity(mech, f"force {spec.drive}")
        return (label if kind else f"force of drive {spec.drive}",
                MOMENT if spec.rotational else FORCE)
    label, kind = describe_quantity(mech, key)
    if key == spec.drive:
        kind = ANGLE if spec.rotational else LENGTH
    elif kind is None and key.startswith("spring"):
        spring = [el for el in model.mechanism.elements
                  if isinstance(el, Spring)][int(key[6:]) - 1]
        c = str(spring.c)
        kind = {STIFFNESS: FORCE, ROT_STIFFNESS: MOMENT}.get(parameter_kinds(mech).get(c))
        label = f"force of spring {key[6:]} ({c})"
    return label, kind


def _event_values(model, spec, history, keys) -> dict:
    """SI values (n_t,) of each quantity of a drive event over one history."""
    names = [q.name for q in model.mechanism.coordinates]
    drives = [q.name for q in model.mechanism.drives]
    springs = spring_forces(model, history.q) if any(k.startswith("spring") for k in keys) \
        else None
    return {key: history.drive_forces[:, drives.index(spec.drive)] if key == "force" else
            springs[:, int(key[6:]) - 1] if key.startswith("spring") and key not in names
            else history.q[:, names.index(key)] for key in keys}


_SI_UNITS = {LENGTH: "m", ANGLE: "rad", FORCE: "N", MOMENT: "N·m"}


def _csv_column(key: str, kind) -> str:
    """CSV header of a quantity: name and SI unit (``force_N``, ``q3_rad``)."""
    unit = _SI_UNITS.get(kind, "SI").replace("·", "_")
    return f"{key.replace(' ', '_')}_{unit}"


def _display(kind, values) -> tuple[str, float]:
    """(unit, factor from SI) in which a quantity reads well: kN, MN, mm, degrees."""
    peak = float(np.nanmax(np.abs(values))) if np.size(values) else 0.0
    if kind in (FORCE, MOMENT):
        unit = _SI_UNITS[kind]
        return next(((p + unit, f) for p, f, lim in (("M", 1e-6, 1e6), ("k", 1e-3, 1e3))
                     if peak >= lim), (unit, 1.0))
    if kind is ANGLE:
        return "°", 180 / math.pi
    if kind is LENGTH and peak < 0.1:
        return "mm", 1e3
    return _SI_UNITS.get(kind, "SI units"), 1.0


def _plot_drive_event(result, runs, values, what, path, title) -> None:
    panels, levels = {}, {}
    for key, (label, kind) in what.items():
        unit, f = _display(kind, np.concatenate([v[key] for v in values.values()]))
        sign = ", tension +" if key.startswith("spring") and key not in result.coordinate_names \
            else ""
        ylabel = f"{readable(label, key)}\n({unit}{sign})"
        panels[ylabel] = {run: (h.t, f * values[run][key]) for run, (_, h) in runs.items()}
        if key == "force":
            levels[ylabel] = (f * result.limit, "trip force " + format_value(
                result.limit, _SI_UNITS[kind], trim=True))
    event = (result.t_trip, "trip") if result.tripped else None
    plot_event_histories(panels, path, event, levels, title)


def _drive_event_text(spec, machine: str, result, what, force_unit: str) -> tuple:
    unit = "rad" if spec.rotational else "m"

    def q(x, u=unit):
        return format_value(x, u, trim=True)
    brakes = ", ".join(q(b, "s") for b in spec.braking_times)
    drive = what[spec.drive][0] + ("" if what[spec.drive][0] == spec.drive else
                                   f" {spec.drive}")
    case = (f"Mechanism {spec.mechanism!r} ({machine}) with the {drive} prescribed:"
            " nonlinear equations of the 2nd kind. From static rest"
            f" at {spec.drive} = {q(spec.start)} the drive speed is ramped to"
            f" {q(spec.speed, unit + '/s')} in {q(spec.ramp_time, 's')} (cycloidal), then held,"
            f" until the {what['force'][0]} reaches the trip force"
            f" {q(spec.trip_force, force_unit)}; then the drive is braked to rest (cycloidal)"
            f" in {brakes} and followed for"
            f" {q(spec.time_after_stop, 's')}.")
    end = result.approach
    outcome = (f"Tripped at t = {q(result.t_trip, 's')}, {spec.drive} ="
               f" {q(result.drive_at_trip)}; the {what['force'][0]} was"
               f" {q(result.static_force_start, force_unit)} at the start." if result.tripped
               else f"No trip: the {what['force'][0]} reached at most"
               f" {q(result.extreme_before_trip, force_unit)}, short of the trip force"
               f" {q(spec.trip_force, force_unit)}, before the run ended at t ="
               f" {q(end.t[-1], 's')}, {spec.drive} ="
               f" {q(end.q[-1, result.coordinate_names.index(spec.drive)])}"
               " (end of travel or t_max).")
    return case, outcome, result.accuracy.statement(force_unit)


def _extreme(values: np.ndarray) -> float:
    """The value of largest magnitude (signed)."""
    return float(values[np.argmax(np.abs(values))]) if values.size else math.nan


def _drive_event_table(result, values, what, spec) -> Table:
    outputs = [k for k in what if k not in ("force", spec.drive)]
    force_unit = _SI_UNITS[what["force"][1]]
    header = ("braking time", "trip time", "stop time", f"peak {what['force'][0]}",
              "quasi-static at rest", "dynamic factor",
              *(f"extreme {readable(what[k][0], k)} after the trip" for k in outputs))
    rows = []
    for run, v in zip(result.runs, values.values(), strict=False):
        after = run.history.t >= result.t_trip
        cells = []
        for k in outputs:
            unit, f = _display(what[k][1], v[k])
            cells.append(Quantity(f * _extreme(v[k][after]), "" if unit == "SI units" else
                                  unit))
        rows.append((Quantity(run.brake_time, "s"), Quantity(result.t_trip, "s"),
                     Quantity(run.t_stop, "s"), Quantity(run.peak_force, force_unit),
                     Quantity(run.static_force_end, force_unit),
                     run.peak_force / run.static_force_end, *cells))
    return Table("Peaks per braking time (extremes: the value of largest magnitude at or"
                 " after the trip, signed)", header, tuple(rows))


def _drive_event_numbers(result, values, outputs) -> dict:
    """Key numbers for results.json (SI; NaN as None); extremes of the ``outputs``."""
    def num(x):
        return float(x) if math.isfinite(x) else None
    acc = result.accuracy
    runs = [{"braking_time_s": r.brake_time, "t_stop_s": r.t_stop,
             "peak_drive_force": r.peak_force, "static_drive_force_at_rest": r.static_force_end,
             "extremes_after_trip": {k: _extreme(v[k][r.history.t >= result.t_trip])
                                     for k in outputs}}
            for r, v in zip(result.runs, values.values(), strict=False)]
    return {"drive": result.drive, "tripped": result.tripped, "t_trip_s": num(result.t_trip),
            "drive_at_trip": num(result.drive_at_trip), "trip_force": result.limit,
            "static_drive_force_at_start": result.static_force_start,
            "extreme_drive_force_before_trip": result.extreme_before_trip, "runs": runs,
            "message": result.message,
            "accuracy": {"method": acc.method, "rtol": acc.rtol, "atol": acc.atol,
                         "max_step_s": num(acc.max_step), "checked": acc.checked,
                         "trip_time_change_s": num(acc.trip_time_change),
                         "peak_force_change": num(acc.peak_force_change),
                         "force_change": num(acc.force_change)}}




def _chain_rows(sweeps: dict, reference: str):
    """Per method and branch: min, max over φ (Hz) and the largest relative difference
    from the ``reference`` method (frequencies sorted per angle before comparing)."""
    ref = np.sort(sweeps[reference].freq_hz, axis=1)
    rows, diffs = [], {}
    for method, s in sweeps.items():
        f = np.sort(s.freq_hz, axis=1)
        k = min(f.shape[1], ref.shape[1])
        d = np.abs(f[:, :k] - ref[:, :k]) / np.where(ref[:, :k] > 0, ref[:, :k], 1.0)
        diffs[method] = float(d.max()) if d.size else 0.0
        rows += [(method, j + 1, float(f[:, j].min()), float(f[:, j].max()),
                  f"{d[:, j].max():.1e}" if j < k else "-") for j in range(f.shape[1])]
    return tuple(rows), diffs


def run_chain_sweep(ws, spec, out):
    """Quasi-eigenfrequencies of the chain over the drive angle by each method, side by
    side: CSV, a chart with one panel per method, the differences between methods."""
    chain, phi = ws.prepared.chain, np.asarray(spec.angles, dtype=float)
    sweeps, seconds = {}, {}
    for method in spec.methods:
        with ws.timed(f"chain sweep {method}"):
            start = time.perf_counter()
            sweeps[method] = chain_sweep(chain, phi, spec.n_modes, method=method)
            seconds[method] = time.perf_counter() - start
    reference = "assembled" if "assembled" in sweeps else spec.methods[0]
    rows, diffs = _chain_rows(sweeps, reference)
    plot_method_sweeps(sweeps, out / "chain_sweep.png", f"{ws.scene.name}: {chain.n_units}"
                       f" units, quasi-eigenfrequencies by method")
    n = spec.n_modes
    _write_csv(out / "chain_frequencies.csv", ["method", "angle_deg"] +
               [f"f{k + 1}_hz" for k in range(n)],
               [(m, float(np.rad2deg(a)), *s.freq_hz[i]) for m, s in sweeps.items()
                for i, a in enumerate(s.phi)])
    text = (f"Chain of {chain.n_units} units ({chain.n} coordinates), {phi.size} drive angles"
            f" from {np.rad2deg(phi[0]):.1f}° to {np.rad2deg(phi[-1]):.1f}°, the {n} lowest"
            " quasi-eigenfrequencies of the frozen chain (C(φ) v = ω² M(φ) v, Ω = 0) by "
            + "; ".join(f"{m}: {METHOD_NAMES[m]}, {1e3 * seconds[m] / phi.size:.2f} ms per"
                        f" angle" for m in sweeps) + ".",
            f"The column 'vs {reference}' is the largest relative difference from the"
            f" {reference} frequencies over all angles (sorted per angle). Round-off level"
            " (1e-9 and below) means the methods agree; the continuum's difference is its"
            " modelling error (smeared units), largest for the higher branches.")
    table = Table("Range of each branch over the revolution, by method",
                  ("method", "branch", "min (Hz)", "max (Hz)", f"vs {reference}"), rows)
    section = Section("Chain: quasi-eigenfrequencies over the drive angle by method", text,
                      (table,), (Figure("chain_sweep.png", "Quasi-eigenfrequencies of the"
                                        " chain over one revolution; one panel per method,"
                                        " common frequency axis"),),
                      ("chain_frequencies.csv",))
    return section, {"phi_rad": _list(phi), "reference": reference,
                     "freq_hz": {m: _list(s.freq_hz) for m, s in sweeps.items()},
                     "max_rel_difference": diffs}


def _rpm(speeds) -> tuple:
    """A speed range (rad/s) in rpm."""
    return tuple(float(W) * 60 / (2 * np.pi) for W in speeds)


def _margin_text(m, required: float) -> str:
    """One sentence on a resonance margin (:class:`femmech.chain.synthesis.Margin`)."""
    verdict = "meets" if m.value >= required else "does NOT meet"
    return (f"resonance margin {100 * m.value:+.2f} % ({verdict} the required"
            f" {100 * required:g} %): closest is branch f{m.branch + 1} = {m.frequency_hz:.2f}"
            f" Hz at φ = {np.rad2deg(m.angle):.0f}°, {m.side} the band of harmonic"
            f" k = {m.harmonic} ({m.band_hz[0]:.2f}–{m.band_hz[1]:.2f} Hz)")


def run_campbell(ws, spec, out):
    """Campbell diagram of the chain: the bands of its quasi-eigenfrequencies over one
    revolution against the harmonic fan k·n over the speed range."""
    rpm, chain = _rpm(spec.speeds), ws.prepared.chain
    with ws.timed("campbell"):
        bands = frequency_bands(chain, np.asarray(spec.angles, dtype=float))
        shown = FrequencyBands(bands.phi, bands.freq_hz[:, :spec.n_modes])
        m = margin_of(bands, rpm, spec.harmonics, spec.n_modes)
    plot_campbell(shown, rpm, spec.harmonics, out / "campbell.png", margin=spec.margin)
    _write_csv(out / "campbell_bands.csv", ["branch", "min_hz", "mean_hz", "max_hz",
                                            "margin"],
               [(k + 1, shown.low[k], shown.mean[k], shown.high[k], m.per_branch[k])
                for k in range(shown.freq_hz.shape[1])])
    text = (f"Speed range {rpm[0]:.0f}–{rpm[1]:.0f} rpm, harmonics k = 1…{spec.harmonics}:"
            f" band k covers k·n/60 Hz over the range. The {shown.freq_hz.shape[1]} lowest"
            f" quasi-eigenfrequencies of the frozen chain at {bands.phi.size} drive angles;"
            " each branch is drawn as its min–max band over one revolution. Margin of a"
            " frequency f to band k: max(1 − f/(k n_lo/60), f/(k n_hi/60) − 1), negative"
            " inside the band.", "The r" + _margin_text(m, spec.margin)[1:] + ".")
    rows = tuple((k + 1, float(shown.low[k]), float(shown.high[k]),
                  f"{100 * m.per_branch[k]:+.2f} %" if m.per_branch[k] >= spec.margin else
                  Flagged(f"{100 * m.per_branch[k]:+.2f} %"))
                 for k in range(shown.freq_hz.shape[1]))
    table = Table("Branches over one revolution and their margin to the harmonic bands",
                  ("branch", "min (Hz)", "max (Hz)", "margin"), rows)
    section = Section("Chain: Campbell diagram", text, (table,),
                      (Figure("campbell.png", "Campbell diagram: quasi-eigenfrequency bands"
                              " (min–max over one revolution) and the harmonic fan k·n;"
                              " red marks: resonances inside the speed range"),),
                      ("campbell_bands.csv",),
                      warnings=() if m.value >= spec.margin else
                      (f"The design resonates: {_margin_text(m, spec.margin)}.",))
    return section, {"speed_rpm": list(rpm), "harmonics": spec.harmonics,
                     "margin": m.value, "required": spec.margin,
                     "low_hz": _list(shown.low), "high_hz": _list(shown.high)}


_LOG_SCALE = ("coupling_stiffness", "flywheel_inertia", "follower_stiffness", "hub_inertia",
              "station_inertia")
"""Design parameters searched on a log scale (they may span decades)."""


def run_synthesis(ws, spec, out):
    """Synthesis: design parameters within bounds that keep every quasi-eigenfrequency
    the required margin away from the harmonic bands; before/after Campbell diagrams."""
    chain_spec, rpm = ws.scene.chain, _rpm(spec.speeds)
    current = design_values(chain_spec)
    params = [Parameter(name, lo, hi, current[name], log=name in _LOG_SCALE and lo > 0)
              for name, lo, hi in spec.parameters]
    with ws.timed("synthesis"):
        r = synthesise(lambda values: build_chain(chain_spec, values), params, rpm,
                       spec.harmonics, spec.margin, spec.n_modes, spec.n_angles,
                       spec.starts, spec.seed, spec.objective)
    plot_synthesis(r, out / "synthesis_campbell.png")
    plot_margins(r, out / "synthesis_margins.png")
    _write_csv(out / "synthesis.csv", ["parameter", "before_si", "after_si", "lower_si",
                                       "upper_si"],
               [(p.name, r.before[p.name], r.after[p.name], p.lower, p.upper)
                for p in params])
    rows = tuple((name, DESIGN[name][1], design_quantity(name, r.before[name]),
                  design_quantity(name, r.after[name], 5),
                  f"{design_quantity(name, lo)} … {design_quantity(name, hi)}")
                 for name, lo, hi in spec.parameters)
    rows += (("resonance margin", "smallest relative distance to a harmonic band",
              f"{100 * r.margin_before.value:+.2f} %", f"{100 * r.margin_after.value:+.2f} %",
              f"required ≥ {100 * spec.margin:g} %"),)
    bad = r.not_converged
    text = (f"Speed range {rpm[0]:.0f}–{rpm[1]:.0f} rpm, harmonics k = 1…{spec.harmonics},"
            f" required margin {100 * spec.margin:g} %, {spec.n_angles} drive angles per"
            f" revolution, {'all' if spec.n_modes is None else spec.n_modes} branches."
            f" Objective {spec.objective!r}: " + (
                "the feasible design closest to the scene's (normalised parameters)"
                if spec.objective == "closest" else "the largest margin within the bounds")
            + f"; {len(r.starts)} starts (the scene's design and a Latin hypercube), gradients"
            " from the eigenvalue sensitivities (KS-smoothed minimum over angles, branches"
            f" and harmonics); {r.evaluations} designs evaluated in {r.seconds:.1f} s.",
            "Before: " + _margin_text(r.margin_before, spec.margin) + ".",
            "After: " + _margin_text(r.margin_after, spec.margin) + f"; on a 4× finer angle"
            f" grid {100 * r.margin_check.value:+.2f} %.")
    warn = () if r.feasible else ("No start met the required margin within the bounds: the"
                                  " design with the largest margin is shown. Widen the"
                                  " bounds or narrow the speed range.",)
    if bad:
        text += (f"{len(bad)} of {len(r.starts)} starts ended without the optimiser's"
                 " convergence flag (their designs are still evaluated exactly).",)
    section = Section("Chain: synthesis", text, (Table(
        "Design parameters before and after the synthesis", ("parameter", "meaning",
                                                              "before", "after", "bounds"),
        rows),), (Figure("synthesis_campbell.png", "Campbell diagram before (grey) and after"
                         " (colour) the synthesis; hatched: harmonic bands widened by the"
                         " margin"),
                  Figure("synthesis_margins.png", "Smallest margin of each branch to the"
                         " harmonic bands, before and after")), ("synthesis.csv",),
        warnings=warn)
    return section, {"feasible": bool(r.feasible), "margin_before": r.margin_before.value,
                     "margin_after": r.margin_after.value,
                     "margin_after_fine": r.margin_check.value, "required": spec.margin,
                     "before": dict(r.before), "after": dict(r.after),
                     "evaluations": r.evaluations}


TASKS = {"modes": run_modes, "sweep": run_sweep, "stability": run_stability,
         "response": run_response, "check": run_check, "drive_event": run_drive_event,
         "chain_sweep": run_chain_sweep, "campbell": run_campbell,
         "synthesis": run_synthesis}


def __getattr__(name: str):
    """Names this module had before the restructures, from their new places
    (docs/architecture.md, "Moved names")."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "summary_section": "femmech.scene.summary.summary_section",
    }, removed={
        "RPM": "an internal factor; use femmech.output.charts.SPEED_UNITS['rpm']",
    })
