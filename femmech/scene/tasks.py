"""The analyses of a scene run: each computes, writes its files and returns a report
:class:`~femmech.output.report.Section` and its key numbers (JSON-able, no timings).

Each task takes ``(workshop, spec, out)``; see :mod:`femmech.scene.run` for the workshop
(lazy FE models, cached reductions, coupled machines) and :mod:`femmech.scene.analyses`
for the specs.

Stage 7 (scene), compute and write: uses scene.workshop, scene.build, analysis, output,
coupling and mechanisms.
"""

from __future__ import annotations

import csv
import io
import math
import warnings
from dataclasses import dataclass

import numpy as np

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
from femmech.coupling import couple
from femmech.errors import ConvergenceWarning
from femmech.fe.model import node_index
from femmech.mechanisms import plot_quasi_frequencies, quasi_modes
from femmech.output import export_modes_vtu, frequency_table, plot_mac, write_frequency_csv
from femmech.output.export import atomic_path
from femmech.output.report import Figure, Flagged, Section, Table
from femmech.output.stability_charts import plot_stability_chart
from femmech.scene.build import machine_mounts
from femmech.scene.workshop import progress, timings_table

RPM = 60.0 / (2 * math.pi)
"""rad/s → rpm."""


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


def summary_section(ws) -> Section:
    """Model summary: DOFs before and after reduction, modes kept, cache, timings."""
    scene, rows = ws.scene, []
    for name, part in scene.parts.items():
        mesh = ws.prepared.meshes[name]
        model = ws.models.get(name)
        se = ws.superelements.get((name, None))
        n_free = model.n_free if model is not None else (
            len(se.free_interface) + len(se.free_interior) if se is not None else "-")
        red = part.reduction
        rows.append((name, mesh.n_nodes, 6 * mesh.n_nodes, n_free,
                     red.method if red else "none",
                     se.n_interface if se is not None else "-",
                     se.n_modal - se.n_residual if se is not None else "-",
                     se.n_residual if se is not None else "-",
                     se.n_reduced if se is not None else "-",
                     ws.cache_status.get(f"part {name!r}", "-")))
    tables = [Table("Parts", ("part", "nodes", "DOFs", "free DOFs", "reduction",
                              "interface DOFs", "modes kept", "residual vectors",
                              "reduced coordinates", "cache"), tuple(rows))]
    if scene.mounts:
        mrows = tuple((m.name, m.mechanism, m.part,
                       ", ".join(ws.prepared.mechanisms[m.mechanism].coordinate_names),
                       ", ".join(f"{a.coordinate}→{a.node}:{a.direction}"
                                 if isinstance(a.direction, str) else
                                 f"{a.coordinate}→{a.node}" for a in m.attachments))
                      for m in scene.mounts)
        tables.append(Table("Mechanisms mounted", ("mount", "mechanism", "part", "coordinates",
                                                   "attachments"), mrows))
    text = []
    machine = ws.machines.get(False)
    if machine is not None:
        text.append(f"Coupled machine: {machine.n} coordinates ({machine.n_frame} frame,"
                    f" {machine.n - machine.n_frame} mechanism).")
    full = ws.machines.get(True)
    if full is not None:
        text.append(f"Unreduced coupled machine (for the check): {full.n} coordinates.")
    return Section("Model summary", tuple(text), tuple(tables) + (timings_table(ws),))


def run_modes(ws, spec, out):
    """Natural modes of a part (full FE model or its superelement)."""
    model = ws.model(spec.part) if (spec.model == "full" or spec.images or spec.vtu) else None
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
    figures = []
    if spec.images:
        from femmech.output import plot_mode

        n = min(spec.images, result.n_modes)
        with ws.timed("mode images"):
            paths = [plot_mode(model, result, i, out / f"mode_{i + 1:02d}.png")
                     for i in progress(range(n), "mode images", ws.bars)]
        figures = [Figure(p.name, f"mode {i + 1}: {result.freq_hz[i]:.3f} Hz")
                   for i, p in enumerate(paths)]
    est = result.error_estimate
    header = ("mode", "frequency (Hz)", "rigid") + (("estimated rel. error",) if est is not
                                                    None else ())
    rows = tuple((i + 1, float(f), "yes" if r else "no") + ((f"{est[i]:.1e}",) if est is not
                                                           None else ())
                 for i, (f, r) in enumerate(zip(result.freq_hz, result.rigid, strict=True)))
    text = (f"Part {spec.part!r}, {spec.model} model ({result.method} solver):"
            f" {result.n_modes} modes.",)
    section = Section("Natural modes", text, (Table("Natural frequencies", header, rows),),
                      tuple(figures), tuple(files), gallery=True)
    return section, {"part": spec.part, "model": spec.model, "freq_hz": _list(result.freq_hz)}


def run_sweep(ws, spec, out):
    """Quasi-eigenfrequencies over the drive angle, per speed."""
    phi = np.asarray(spec.angles, dtype=float)
    curves = {}
    for W in spec.speeds:
        label = f"{W * RPM:.0f} rpm"
        with ws.timed("sweep"):
            if spec.mechanism is not None:
                q = quasi_modes(ws.prepared.mechanisms[spec.mechanism], phi, Omega=W)
                curves[label] = _Curve(q.phi, q.freq_hz[:, :spec.n_modes])
            else:
                s = sweep(ws.machine(), phi, Omega=W, n_modes=spec.n_modes, track=spec.track)
                curves[label] = _Curve(s.phi, s.freq_hz)
    what = f"mechanism {spec.mechanism!r} alone" if spec.mechanism else "coupled machine"
    plot_quasi_frequencies(curves, out / "quasi_frequencies.png",
                           title=f"{ws.scene.name}: {what}")
    n = next(iter(curves.values())).freq_hz.shape[1]
    rows = [(W, float(np.rad2deg(a)), *c.freq_hz[i]) for W, c in zip(spec.speeds,
                                                                      curves.values(),
                                                                      strict=True)
            for i, a in enumerate(c.phi)]
    _write_csv(out / "quasi_frequencies.csv", ["speed_rad_s", "angle_deg"] +
               [f"f{k + 1}_hz" for k in range(n)], rows)
    table_rows = tuple((label, k + 1, float(np.nanmin(c.freq_hz[:, k])),
                        float(np.nanmax(c.freq_hz[:, k])))
                       for label, c in curves.items() for k in range(n))
    figures = [Figure("quasi_frequencies.png", f"Quasi-eigenfrequencies of the {what}")]
    for angle in spec.mode_images_at:
        figures.append(_coupled_image(ws, spec, angle, out))
    text = (f"{phi.size} drive angles from {np.rad2deg(phi[0]):.1f}° to"
            f" {np.rad2deg(phi[-1]):.1f}°, {n} branches, speeds {list(curves)}.",)
    section = Section("Quasi-eigenfrequencies over the drive angle", text,
                      (Table("Range of each branch over the sweep", ("speed", "branch",
                                                                    "min (Hz)", "max (Hz)"),
                             table_rows),), tuple(figures), ("quasi_frequencies.csv",))
    return section, {"phi_rad": _list(phi), "speeds_rad_s": list(spec.speeds),
                     "freq_hz": [_list(c.freq_hz) for c in curves.values()]}


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
                      out / name, angle=angle)
    return Figure(name, f"lowest coupled quasi-mode at φ = {deg:g}°, {W * RPM:.0f} rpm:"
                  f" {at.freq_hz[0, 0]:.2f} Hz")


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
    plot_stability_chart(chart, out / "stability_chart.png", title=ws.scene.name,
                         speed_unit="rpm")
    _write_csv(out / "stability.csv", ["speed_rad_s", "speed_rpm", "spectral_radius",
                                       "error_estimate", "converged", "n_steps", "stable"],
               [(W, W * RPM, r, e, int(c), n, int(s) if c else "")
                for W, r, e, c, n, s in zip(speeds, radius, error, ok, steps, stable,
                                            strict=True)])
    unstable = speeds[~stable & ok]
    text = (f"{speeds.size} speeds from {speeds[0] * RPM:.0f} to {speeds[-1] * RPM:.0f} rpm;"
            f" Rayleigh damping (mass, stiffness) = {spec.rayleigh}. Magnus steps per period"
            f" doubled from {spec.n_steps} until the spectral radius changed by at most"
            f" {spec.rtol:g} (relative; {steps.min()}..{steps.max()} steps were needed)."
            f" Unstable at {unstable.size} speeds"
            + (f" ({unstable.min() * RPM:.0f}..{unstable.max() * RPM:.0f} rpm)." if
               unstable.size else "."),)
    flags = ()
    if not ok.all():
        bad = speeds[~ok] * RPM
        where = (f"{bad.min():.0f} rpm" if bad.size == 1 else
                 f"{bad.min():.0f}..{bad.max():.0f} rpm")
        flags = (f"{int((~ok).sum())} of {speeds.size} speeds ({where}) did NOT converge"
                 f" within max_steps = {spec.max_steps} Magnus steps per"
                 " period: their spectral radius and verdict may be wrong (hatched in the"
                 " chart, converged = 0 in stability.csv). Raise max_steps.",)
        ws.log(f"stability: {flags[0]}")
    rows = tuple((float(W * RPM), float(r), f"{e:.1e}", "yes" if s else "no")
                 if c else (float(W * RPM), Flagged(f"{r:.6g} NOT CONVERGED"), f"{e:.1e}",
                            Flagged("unknown"))
                 for W, r, e, c, s in zip(speeds, radius, error, ok, stable, strict=True))
    section = Section("Stability chart", text, (Table("Spectral radius of the monodromy"
                                                      " matrix", ("speed (rpm)", "max |μ|",
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
    _plot_response(r, columns, spec.kind, out / "response.png")
    loose = r.converged is False

    def cell(x):
        return Flagged(f"{x:.6g} NOT CONVERGED") if loose else float(x)

    rows = tuple((k, cell(np.abs(c).max()), cell(c.max() - c.min()))
                 for k, c in columns.items())
    if spec.kind == "periodic":
        text = (f"Periodic steady state at {spec.speed * RPM:.0f} rpm by shooting"
                f" (generalised-α), {r.n_steps} steps per period: steps doubled from"
                f" {spec.n_steps} until q changed by at most {spec.rtol:g} (relative, mass"
                f" norm); estimated error {r.error:.1e}.",)
    else:
        text = (f"Run-up {spec.speed_start * RPM:.0f} → {spec.speed_end * RPM:.0f} rpm in"
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


def _plot_response(r, columns, kind, path) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure as MplFigure

    fig = MplFigure(figsize=(8, 1.2 + 1.8 * max(1, len(columns))), dpi=110)
    FigureCanvasAgg(fig)
    x = np.rad2deg(r.phi) if kind == "periodic" else r.t
    for i, (name, values) in enumerate(columns.items() or {"(none)": 0 * x}.items()):
        ax = fig.add_subplot(max(1, len(columns)), 1, i + 1)
        ax.plot(x, values, lw=1.0)
        ax.set_ylabel(name, fontsize=8)
        ax.grid(alpha=0.3)
    ax.set_xlabel("drive angle φ (°)" if kind == "periodic" else "time t (s)")
    fig.tight_layout()
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
    _write_csv(out / "reduced_vs_full.csv", ["angle_deg", "mode", "full_hz", "reduced_hz",
                                             "rel_error", "mac"],
               [(float(np.rad2deg(a)), int(j + 1), comp.freq_full_hz[i, j],
                 comp.freq_reduced_hz[i, j], comp.rel_error[i, j], comp.diag_mac[i, j])
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
                                                               "rel. error", "MAC"),
                    tuple((f"{np.rad2deg(a):.1f}", j + 1, float(comp.freq_full_hz[i, j]),
                           float(comp.freq_reduced_hz[i, j]),
                           f"{comp.rel_error[i, j]:.2e}", f"{comp.diag_mac[i, j]:.8f}")
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
    section = Section("Reduced versus full", text, tuple(tables), tuple(figures), tuple(files))
    return section, {"rel_error": _list(comp.rel_error), "diag_mac": _list(comp.diag_mac),
                     "max_rel_error": err, "min_mac": mac, "levels": levels}


def _plot_speed_error(rows, path) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure as MplFigure

    fig = MplFigure(figsize=(6.5, 4.2), dpi=110)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for name, n, ms, err, _ in rows[1:]:
        ax.loglog(ms, max(err, 1e-16), "o")
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


TASKS = {"modes": run_modes, "sweep": run_sweep, "stability": run_stability,
         "response": run_response, "check": run_check}
