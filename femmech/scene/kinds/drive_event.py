"""Analysis kind ``drive_event``: a drive run up to speed, tripped when its force reaches
a limit and braked to rest, for several braking times
(:func:`femmech.analysis.drive_events.trip_and_brake` on a mechanism of form
``second_kind``): a CSV per run, the time histories, a table of the peaks.

Stage 8 (scene): reading uses scene.kinds.common and scene.machine (what a built-in
mechanism's quantities are); the runner imports the analysis and output modules it calls
when it runs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from femmech.errors import SceneError
from femmech.mechanisms.catalogue import readable
from femmech.output.formatting import Quantity, format_value
from femmech.output.report import Figure, Section, Table
from femmech.scene.kinds.common import (
    MAX_DRIVE_EVALUATIONS,
    MAX_DRIVE_STEPS,
    MAX_HISTORIES,
    MAX_POINTS,
    MAX_RUNS,
    AnalysisKind,
    ReadContext,
    read_values,
)
from femmech.scene.machine import describe_quantity, parameter_kinds
from femmech.scene.reader import Reader, show
from femmech.scene.units import (
    ANGLE,
    DIMENSIONLESS,
    FORCE,
    LENGTH,
    LINEAR_SPEED,
    MOMENT,
    ROT_STIFFNESS,
    SPEED,
    STIFFNESS,
    TIME,
)


@dataclass(frozen=True)
class DriveEventSpec:
    """A drive run up to speed, tripped when its force reaches ``trip_force``, braked to
    rest in each of ``braking_times`` (:func:`femmech.analysis.drive_events.trip_and_brake`).

    SI units; positions, speeds and forces of a translational drive in m, m/s, N, of a
    rotational one (``rotational``) in rad, rad/s, N·m. ``outputs`` None: all free
    coordinates; ``max_step`` None: no limit.
    """

    mechanism: str
    drive: str
    rotational: bool
    start: float
    end: float | None
    t_max: float | None
    speed: float
    ramp_time: float
    trip_force: float
    braking_times: tuple
    time_after_stop: float
    outputs: tuple | None
    samples: int
    method: str
    rtol: float
    atol: float
    max_step: float | None
    verify: bool


def second_kind_mechanism(t: Reader, mechanisms: dict) -> str:
    """The ``mechanism`` key (default: the only one of form second_kind), checked."""
    candidates = sorted(n for n, m in mechanisms.items() if m.form == "second_kind")
    name = t.string("mechanism", candidates[0] if len(candidates) == 1 else None)
    if name not in mechanisms:
        raise t.error("mechanism", f"expected one of the [mechanisms] {sorted(mechanisms)},"
                                   f" got {show(name)}")
    if mechanisms[name].form != "second_kind":
        raise t.error("mechanism", f"a drive event needs the nonlinear equations: set form ="
                                   f" 'second_kind' in [mechanisms.{name}]")
    return name


def is_rotational(t: Reader, spec, drive: str) -> bool:
    """Whether the drive is an angle: from a built-in model's drive force (a force or a
    moment), else from the unit of ``start``."""
    kind = describe_quantity(spec, f"force {drive}")[1]
    if kind in (FORCE, MOMENT):
        return kind is MOMENT
    fits = []
    for kind in (LENGTH, ANGLE):
        try:
            t.number("start", kind)
            fits.append(kind)
        except SceneError:
            pass
    if len(fits) != 1:
        raise t.error("start", f"expected a length or an angle with its unit (e.g. '4.7 m' or"
                               f" '30 deg': the dimension of drive {drive!r} is not known"
                               f" otherwise), got {show(t.get('start'))}")
    return fits[0] is ANGLE


def read(t: Reader, context: ReadContext) -> DriveEventSpec:
    """``[analyses.drive_event]`` → :class:`DriveEventSpec` (SI units)."""
    from femmech.analysis.drive_events import travel_time
    from femmech.analysis.nonlinear import METHODS as INTEGRATORS

    mechanisms = context.mechanisms
    mechanism = second_kind_mechanism(t, mechanisms)
    drive = t.string("drive")
    rotational = is_rotational(t, mechanisms[mechanism], drive)
    position = ANGLE if rotational else LENGTH
    start, end = t.number("start", position), t.number("end", position, None)
    speed = t.number("speed", SPEED if rotational else LINEAR_SPEED)
    if speed == 0:
        raise t.error("speed", "expected a non-zero drive speed (its sign is the direction)")
    if end is not None and not (end - start) * speed > 0:
        raise t.error("end", f"expected the end of travel in the direction of the speed"
                             f" ({speed:g}) from start ({start:g}), got {end:g} (SI units)")
    t_max = t.number("t_max", TIME, None, positive=True)
    if end is None and t_max is None:
        raise t.error(None, "give end (the end of travel) or t_max (the latest trip time):"
                            " the run stops there if the force never reaches trip_force")
    ramp = t.number("ramp_time", TIME, positive=True)
    force = t.number("trip_force", MOMENT if rotational else FORCE)
    if force == 0:
        raise t.error("trip_force", "expected a non-zero force (a positive limit is reached"
                                    " from below, a negative one from above)")
    brakes = read_values(t, "braking_times", TIME, maximum=MAX_RUNS, limit="MAX_RUNS")
    if brakes is None or min(brakes) <= 0:
        raise t.error("braking_times", "expected a list of positive braking times, e.g."
                                       " ['0.2 s', '0.5 s']")
    after = t.number("time_after_stop", TIME, 0.0, non_negative=True)
    outputs = t.strings("outputs", None)
    if outputs is not None and (len(outputs) > MAX_HISTORIES or len(set(outputs))
                                < len(outputs)):
        raise t.error("outputs", f"expected at most {MAX_HISTORIES} distinct names (limit"
                                 f" MAX_HISTORIES), got {show(list(outputs))}")
    rtol = t.number("rtol", DIMENSIONLESS, 1e-10, positive=True)
    if not rtol < 1:
        raise t.error("rtol", f"expected a relative tolerance below 1, got {rtol:g}")
    max_step = t.number("max_step", TIME, None, positive=True)
    longest = min(travel_time(start, end, speed, ramp) if end is not None else np.inf,
                  t_max or np.inf) + max(brakes) + after
    if max_step is not None and longest / max_step > MAX_DRIVE_STEPS:
        raise t.error("max_step", f"{longest:.6g} s in steps of {max_step:g} s; at most"
                                  f" {MAX_DRIVE_STEPS} steps (limit MAX_DRIVE_STEPS)")
    return DriveEventSpec(mechanism, drive, rotational, start, end, t_max, speed, ramp, force,
                          brakes, after, outputs,
                          t.integer("samples", 1500, minimum=2, maximum=MAX_POINTS,
                                    limit="MAX_POINTS"),
                          t.string("method", "DOP853", choices=tuple(INTEGRATORS)), rtol,
                          t.number("atol", DIMENSIONLESS, 1e-12, positive=True), max_step,
                          t.boolean("verify", False))


def run(ws, spec, out):
    """A drive run up to speed, tripped when its force reaches a limit, braked to rest in
    each braking time: CSV per run, a PNG of the histories, a table of the peaks."""
    from femmech.analysis.drive_events import trip_and_brake
    from femmech.output.histories import write_history_csv

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
    what = {key: event_quantity(mech, model, spec, key) for key in keys}
    runs = {f"braking {format_value(r.brake_time, 's', trim=True)}": (r.brake_time, r.history)
            for r in result.runs} or {"approach (no trip)": (None, result.approach)}
    values = {label: event_values(model, spec, h, keys) for label, (_, h) in runs.items()}
    files = []
    for label, (tb, h) in runs.items():
        name = ("drive_event_approach.csv" if tb is None else "drive_event_braking_"
                + f"{tb:g}".replace(".", "p") + "s.csv")
        write_history_csv(h.t, {csv_column(key, what[key][1]): v
                                for key, v in values[label].items()}, out / name)
        files.append(name)
    plot_drive_event(result, runs, values, what, out / "drive_event.png",
                      f"{ws.scene.name}: {what['force'][0]} and braking" if result.tripped
                      else f"{ws.scene.name}: no trip")
    force_unit = "N·m" if spec.rotational else "N"
    text = drive_event_text(spec, model.mechanism.name, result, what, force_unit)
    flags = () if result.tripped else (text[1] + " Nothing was braked.",)
    for flag in flags:
        ws.log(f"drive_event: {flag}")
    tables = (drive_event_table(result, values, what, spec),) if result.tripped else ()
    section = Section("Drive-force trip and braking", text[:1] + text[2:] if flags else text,
                      tables,
                      (Figure("drive_event.png", "Time histories; dotted line: the trip"
                              if result.tripped else "Time histories (no trip)"),),
                      tuple(files), warnings=flags)
    return section, drive_event_numbers(result, values, keys[2:])


def event_quantity(mech, model, spec, key: str) -> tuple:
    """(description, dimension or None) of a quantity shown by a drive event."""
    from femmech.mechanisms import Spring

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


def event_values(model, spec, history, keys) -> dict:
    """SI values (n_t,) of each quantity of a drive event over one history."""
    from femmech.analysis.drive_events import spring_forces

    names = [q.name for q in model.mechanism.coordinates]
    drives = [q.name for q in model.mechanism.drives]
    springs = spring_forces(model, history.q) if any(k.startswith("spring") for k in keys) \
        else None
    return {key: history.drive_forces[:, drives.index(spec.drive)] if key == "force" else
            springs[:, int(key[6:]) - 1] if key.startswith("spring") and key not in names
            else history.q[:, names.index(key)] for key in keys}


SI_UNITS = {LENGTH: "m", ANGLE: "rad", FORCE: "N", MOMENT: "N·m"}


def csv_column(key: str, kind) -> str:
    """CSV header of a quantity: name and SI unit (``force_N``, ``q3_rad``)."""
    unit = SI_UNITS.get(kind, "SI").replace("·", "_")
    return f"{key.replace(' ', '_')}_{unit}"


def display(kind, values) -> tuple[str, float]:
    """(unit, factor from SI) in which a quantity reads well: kN, MN, mm, degrees."""
    peak = float(np.nanmax(np.abs(values))) if np.size(values) else 0.0
    if kind in (FORCE, MOMENT):
        unit = SI_UNITS[kind]
        return next(((p + unit, f) for p, f, lim in (("M", 1e-6, 1e6), ("k", 1e-3, 1e3))
                     if peak >= lim), (unit, 1.0))
    if kind is ANGLE:
        return "°", 180 / math.pi
    if kind is LENGTH and peak < 0.1:
        return "mm", 1e3
    return SI_UNITS.get(kind, "SI units"), 1.0


def plot_drive_event(result, runs, values, what, path, title) -> None:
    panels, levels = {}, {}
    for key, (label, kind) in what.items():
        unit, f = display(kind, np.concatenate([v[key] for v in values.values()]))
        sign = ", tension +" if key.startswith("spring") and key not in result.coordinate_names \
            else ""
        ylabel = f"{readable(label, key)}\n({unit}{sign})"
        panels[ylabel] = {run: (h.t, f * values[run][key]) for run, (_, h) in runs.items()}
        if key == "force":
            levels[ylabel] = (f * result.limit, "trip force " + format_value(
                result.limit, SI_UNITS[kind], trim=True))
    event = (result.t_trip, "trip") if result.tripped else None
    from femmech.output.histories import plot_event_histories

    plot_event_histories(panels, path, event, levels, title)


def drive_event_text(spec, machine: str, result, what, force_unit: str) -> tuple:
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


def extreme(values: np.ndarray) -> float:
    """The value of largest magnitude (signed)."""
    return float(values[np.argmax(np.abs(values))]) if values.size else math.nan


def drive_event_table(result, values, what, spec) -> Table:
    outputs = [k for k in what if k not in ("force", spec.drive)]
    force_unit = SI_UNITS[what["force"][1]]
    header = ("braking time", "trip time", "stop time", f"peak {what['force'][0]}",
              "quasi-static at rest", "dynamic factor",
              *(f"extreme {readable(what[k][0], k)} after the trip" for k in outputs))
    rows = []
    for run, v in zip(result.runs, values.values(), strict=False):
        after = run.history.t >= result.t_trip
        cells = []
        for k in outputs:
            unit, f = display(what[k][1], v[k])
            cells.append(Quantity(f * extreme(v[k][after]), "" if unit == "SI units" else
                                  unit))
        rows.append((Quantity(run.brake_time, "s"), Quantity(result.t_trip, "s"),
                     Quantity(run.t_stop, "s"), Quantity(run.peak_force, force_unit),
                     Quantity(run.static_force_end, force_unit),
                     run.peak_force / run.static_force_end, *cells))
    return Table("Peaks per braking time (extremes: the value of largest magnitude at or"
                 " after the trip, signed)", header, tuple(rows))


def drive_event_numbers(result, values, outputs) -> dict:
    """Key numbers for results.json (SI; NaN as None); extremes of the ``outputs``."""
    def num(x):
        return float(x) if math.isfinite(x) else None
    acc = result.accuracy
    runs = [{"braking_time_s": r.brake_time, "t_stop_s": r.t_stop,
             "peak_drive_force": r.peak_force, "static_drive_force_at_rest": r.static_force_end,
             "extremes_after_trip": {k: extreme(v[k][r.history.t >= result.t_trip])
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


KIND = AnalysisKind(
    "drive_event", ("mechanism", "drive", "start", "end", "t_max", "speed", "ramp_time",
                    "trip_force", "braking_times", "time_after_stop", "outputs", "samples",
                    "method", "rtol", "atol", "max_step", "verify"),
    read, run, "a drive run up to speed, tripped at a force limit and braked to rest, per"
    " braking time (mechanism of form second_kind)", order=60)
