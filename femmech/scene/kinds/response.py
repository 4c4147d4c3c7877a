"""Analysis kind ``response``: the periodic steady state at one drive speed
(:func:`femmech.analysis.response.periodic_steady_state`) or a run-up between two speeds
(:func:`femmech.analysis.response.time_response`): histories of chosen coordinates and
frame DOFs as CSV and plot, amplitudes in the report.

Stage 8 (scene): reading uses scene.kinds.common; the runner imports the analysis and
output modules it calls when it runs.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from femmech.errors import ConvergenceWarning
from femmech.output.charts import format_speed
from femmech.output.csv_rows import write_csv
from femmech.output.report import Figure, Flagged, Section, Table
from femmech.scene.kinds.common import (
    MAX_HISTORIES,
    MAX_STEPS,
    AnalysisKind,
    ReadContext,
    damped,
    needs_machine,
    read_rayleigh,
)
from femmech.scene.reader import Reader, show
from femmech.scene.units import DIMENSIONLESS, SPEED, TIME


@dataclass(frozen=True)
class ResponseSpec:
    """Periodic steady state at ``speed`` or a run-up ``speed_start`` → ``speed_end``."""

    kind: str
    speed: float | None
    n_steps: int
    speed_start: float | None
    speed_end: float | None
    duration: float | None
    t_end: float | None
    outputs: tuple
    frame_dofs: tuple
    rayleigh: tuple
    rtol: float
    max_steps: int
    speed_unit: str = "rpm"


def read(t: Reader, context: ReadContext) -> ResponseSpec:
    """``[analyses.response]`` → :class:`ResponseSpec` in the scene's speed unit."""
    parts = context.parts
    needs_machine(t, parts, context.has_mounts, "a response")
    kind = t.string("kind", "periodic", choices=("periodic", "run_up"))
    speed = t.number("speed", SPEED, None, positive=True)
    ramp = [t.number("speed_start", SPEED, None, non_negative=True),
            t.number("speed_end", SPEED, None, non_negative=True),
            t.number("duration", TIME, None, positive=True),
            t.number("t_end", TIME, None, positive=True)]
    if kind == "periodic" and (speed is None or any(v is not None for v in ramp)):
        raise t.error("speed", "a periodic response needs speed (and no run-up keys)")
    if kind == "run_up" and (speed is not None or any(v is None for v in ramp)):
        raise t.error(None, "a run-up needs speed_start, speed_end, duration and t_end")
    dofs = []
    for d in t.tables("frame_dofs"):
        d.expect("part", "node", "dof")
        part = d.string("part", next(iter(parts)))
        if part not in parts:
            raise d.error("part", f"expected one of the [parts] {sorted(parts)}, got"
                                  f" {show(part)}")
        dofs.append((part, d.node_ref("node"),
                     d.string("dof", choices=("ux", "uy", "uz", "rx", "ry", "rz"))))
    outputs = t.strings("outputs", ())
    if len(outputs) + len(dofs) > MAX_HISTORIES:
        raise t.error("outputs", f"{len(outputs)} outputs and {len(dofs)} frame_dofs; at most"
                                 f" {MAX_HISTORIES} histories (limit MAX_HISTORIES)")
    n_steps = t.integer("n_steps", 512, minimum=2, maximum=MAX_STEPS, limit="MAX_STEPS")
    from femmech.analysis.response import STEADY_STATE_MAX_STEPS, STEADY_STATE_RTOL

    return ResponseSpec(kind, speed, n_steps, *ramp, outputs, tuple(dofs), read_rayleigh(t),
                        t.number("rtol", DIMENSIONLESS, STEADY_STATE_RTOL, positive=True),
                        t.integer("max_steps", max(STEADY_STATE_MAX_STEPS, n_steps),
                                  minimum=n_steps, maximum=MAX_STEPS, limit="MAX_STEPS"),
                        context.speed_unit)


def run(ws, spec, out):
    """Periodic steady state or run-up: histories of chosen coordinates."""
    from femmech.analysis.response import (
        SpeedRamp,
        frame_history,
        periodic_steady_state,
        time_response,
    )
    from femmech.fe.model import node_index
    from femmech.output.response_plots import plot_response

    system = damped(ws, spec.rayleigh)
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
    write_csv(out / "response.csv", ["t_s", "phi_rad", *columns],
               [(t, p, *(c[i] for c in columns.values()))
                for i, (t, p) in enumerate(zip(r.t, r.phi, strict=True))])
    title = (f"Periodic steady state at {format_speed(spec.speed, spec.speed_unit)}"
             if spec.kind == "periodic" else
             f"Run-up {format_speed(spec.speed_start, spec.speed_unit)} →"
             f" {format_speed(spec.speed_end, spec.speed_unit)} in {spec.duration:g} s")
    shown = {k: system.describe(k) for k in columns}  # HTML and plot; the CSV keeps k
    periodic = spec.kind == "periodic"
    plot_response(np.rad2deg(r.phi) if periodic else r.t, columns, out / "response.png",
                  periodic, title, shown, {k: system.unit(k) for k in columns})
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


KIND = AnalysisKind(
    "response", ("kind", "speed", "n_steps", "speed_start", "speed_end", "duration", "t_end",
                 "outputs", "frame_dofs", "rayleigh", "rtol", "max_steps"),
    read, run, "forced response: periodic steady state at one drive speed or a run-up,"
    " histories of chosen coordinates", order=40)
