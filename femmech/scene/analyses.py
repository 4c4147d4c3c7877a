"""Scene table ``[analyses]``: which results to compute, with their settings (SI).

Kinds (each at most once): ``modes`` (:func:`femmech.modes` or
:func:`femmech.analysis.modes.superelement_modes`), ``sweep`` (quasi-modes over the drive
angle, :func:`femmech.analysis.sweep.sweep` or :func:`femmech.mechanisms.quasi_modes`),
``stability`` (:func:`femmech.analysis.stability.stability_chart` over drive speed),
``response`` (:func:`femmech.analysis.response.periodic_steady_state` or a run-up by
:func:`~femmech.analysis.response.time_response`) and ``check`` (reduced versus full,
:func:`femmech.analysis.reference.compare_coupled`, optionally over several reduction
sizes: the speed-versus-error comparison) and ``drive_event`` (a drive run up to speed,
tripped when its force reaches a limit and braked to rest, for several braking times:
:func:`femmech.analysis.drive_events.trip_and_brake` on a mechanism of form
``second_kind``).

``speed_unit`` (a key of ``[analyses]`` itself: "rpm", the default, or "rad/s") is the
one unit in which the scene's charts, tables and report show drive speeds; it is copied
into the sweep, stability and response specs.

Stage 8 (scene), reading: uses scene.reader, scene.units, scene.machine (what a built-in
mechanism's coordinates are), the defaults of analysis.response and analysis.magnus,
analysis.nonlinear (the integrators), analysis.drive_events (travel time) and
output.charts (how a speed is labelled).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from femmech.errors import SceneError
from femmech.output.charts import format_speed, speed_resolution
from femmech.scene.machine import describe_quantity
from femmech.scene.reader import Reader, show
from femmech.scene.units import (
    ANGLE,
    DIMENSIONLESS,
    FORCE,
    FREQUENCY,
    INVERSE_TIME,
    LENGTH,
    LINEAR_SPEED,
    MOMENT,
    SPEED,
    TIME,
)

MAX_MODES = 2000
"""Most modes a scene may ask for (``n_modes`` of a reduction or an analysis)."""
MAX_POINTS = 100_000
"""Most drive angles of a sweep or check, speeds, or values of any list of an analysis."""
MAX_SWEEP_POINTS = 1_000_000
"""Most (angle, speed) points of a sweep (each an eigenvalue problem)."""
MAX_STEPS = 2**20
"""Most time steps per period (``n_steps``, ``max_steps``) of a stability chart or a
response."""
MAX_IMAGES = 100
"""Most pictures an analysis may ask for (mode images, coupled mode images)."""
MAX_HISTORIES = 64
"""Most histories of a response (``outputs`` plus ``frame_dofs``; one plot row each)."""
MAX_LEVELS = 20
"""Most reduction sizes of the speed-versus-error comparison (``f_max_hz_levels``; each
a full reduction and coupled solve)."""
MAX_RUNS = 20
"""Most braking times of a drive event (each a time integration)."""
MAX_DRIVE_STEPS = 2**22
"""Most steps of size ``max_step`` a drive event may need (its simulated time over
``max_step``)."""
MAX_DRIVE_EVALUATIONS = 1_000_000
"""Most evaluations of the equations of motion in one drive event, all runs together
(the crane example needs 4e4; a million take minutes): a run that needs more stops with
an error instead of running for hours."""
SPEED_UNITS = ("rpm", "rad/s")
"""Units a scene may show drive speeds in (``[analyses] speed_unit``; the first is the
default)."""


MAX_ANIMATIONS = 12
"""Most mode animations (GIF, about 1 s and 0.8 MB each) one modes analysis may ask for."""


@dataclass(frozen=True)
class ModesSpec:
    """Natural modes of one part (full model or superelement)."""

    part: str
    n_modes: int | None
    band_hz: tuple | None
    model: str
    images: int
    vtu: bool
    series: bool = False
    animate: tuple = ()
    discretisation_error: bool = False


@dataclass(frozen=True)
class SweepSpec:
    """Quasi-modes over drive angles (rad) at one or more drive speeds (rad/s)."""

    angles: tuple
    n_modes: int | None  # None: up to 6, all branches where fewer exist (said in the report)
    speeds: tuple
    mechanism: str | None
    track: bool
    mode_images_at: tuple
    speed_unit: str = "rpm"


@dataclass(frozen=True)
class StabilitySpec:
    """Spectral radius of the monodromy matrix over drive speeds (rad/s)."""

    speeds: tuple
    n_steps: int
    angle_period: float
    rayleigh: tuple
    tol: float
    rtol: float
    max_steps: int
    speed_unit: str = "rpm"


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


@dataclass(frozen=True)
class CheckSpec:
    """Reduced versus full coupled quasi-modes at ``angles`` (rad); with ``levels``
    (f_max in Hz) also the error and time per angle of several reduction sizes."""

    angles: tuple
    n_modes: int
    levels: tuple


@dataclass(frozen=True)
class Analyses:
    """The requested analyses (None: not requested)."""

    modes: ModesSpec | None = None
    sweep: SweepSpec | None = None
    stability: StabilitySpec | None = None
    response: ResponseSpec | None = None
    check: CheckSpec | None = None
    drive_event: DriveEventSpec | None = None
    speed_unit: str = "rpm"
    where: dict = field(default_factory=dict, compare=False)
    chain_sweep: object = None  # femmech.scene.chain.ChainSweepSpec
    campbell: object = None  # femmech.scene.chain.CampbellSpec
    synthesis: object = None  # femmech.scene.chain.SynthesisSpec (table [synthesis])


def _values(r: Reader, key: str, kind, default=None, maximum: int = MAX_POINTS,
            limit: str = "MAX_POINTS") -> tuple:
    """A list of quantities, or a table {start, stop, n} (linspace, inclusive, start <=
    stop); at most ``maximum`` values (the constant named ``limit``)."""
    value = r.get(key, default)
    if value is default:
        return default
    if isinstance(value, list) and value:
        if len(value) > maximum:
            raise r.error(key, f"{len(value)} values; at most {maximum} (limit {limit})")
        return tuple(r.convert(key, v, kind) for v in value)
    if isinstance(value, dict):
        t = r.child(key, value)
        t.expect("start", "stop", "n")
        start, stop = t.number("start", kind), t.number("stop", kind)
        n = t.integer("n", minimum=1, maximum=maximum, limit=limit)
        if stop < start:
            raise t.error("stop", f"expected stop >= start ({start:g} in SI units), got"
                                  f" {stop:g}")
        if n > 1 and stop == start:
            raise t.error("n", f"expected n = 1 for stop = start, got {n}")
        return tuple(np.linspace(start, stop, n).tolist())
    raise r.error(key, f"expected a list of values or a table {{start, stop, n}}, got"
                       f" {show(value)}")


read_values = _values
"""Public name of :func:`_values` (for the chain tables, femmech.scene.chain)."""


def _rayleigh(r: Reader) -> tuple:
    if not r.has("rayleigh"):
        return (0.0, 0.0)
    t = r.table("rayleigh")
    t.expect("mass", "stiffness")
    return (t.number("mass", INVERSE_TIME, 0.0, non_negative=True),
            t.number("stiffness", TIME, 0.0, non_negative=True))


def _only_part(r: Reader, parts: dict) -> str:
    part = r.string("part", next(iter(parts)) if len(parts) == 1 else None)
    if part not in parts:
        raise r.error("part", f"expected one of the [parts] {sorted(parts)}, got {show(part)}")
    return part


_KEYS = {"modes": ("part", "n_modes", "band_hz", "model", "images", "vtu", "series",
                   "animate", "discretisation_error"),
         "sweep": ("angles", "n_modes", "speeds", "mechanism", "track", "mode_images_at"),
         "stability": ("speeds", "n_steps", "angle_period", "rayleigh", "tol", "rtol",
                       "max_steps"),
         "response": ("kind", "speed", "n_steps", "speed_start", "speed_end", "duration",
                      "t_end", "outputs", "frame_dofs", "rayleigh", "rtol", "max_steps"),
         "check": ("angles", "n_modes", "f_max_hz_levels"),
         "drive_event": ("mechanism", "drive", "start", "end", "t_max", "speed", "ramp_time",
                         "trip_force", "braking_times", "time_after_stop", "outputs",
                         "samples", "method", "rtol", "atol", "max_step", "verify")}
"""Keys of each analysis table."""


def read_analyses(r: Reader, parts: dict, mechanisms: dict, has_mounts: bool,
                  extra: dict | None = None, synthesis=None) -> Analyses:
    """Parse ``[analyses]``; checks that each analysis has what it needs.

    ``extra``: {kind: reader(table) -> spec} of analyses read elsewhere (the chain's,
    :mod:`femmech.scene.chain`); ``synthesis``: the spec of the top-level ``[synthesis]``.
    """
    extra = extra or {}
    r.expect("speed_unit", *_READERS, *extra)
    unit = r.string("speed_unit", SPEED_UNITS[0], choices=SPEED_UNITS)
    out, where = {}, {}
    if synthesis is not None:
        out["synthesis"], where["synthesis"] = synthesis, "synthesis"
    readers = {k: r.table(k) for k in (*_READERS, *extra) if r.has(k)}
    for kind, t in readers.items():
        where[kind] = t.where
        if kind in extra:
            out[kind] = extra[kind](t)
            continue
        t.expect(*_KEYS[kind])
        out[kind] = _READERS[kind](t, parts, mechanisms, has_mounts)
        if kind in ("sweep", "stability", "response"):
            out[kind] = replace(out[kind], speed_unit=unit)
    if not out:
        raise r.error(None, "no analyses requested: add [analyses.modes], [analyses.sweep],"
                            " [analyses.stability], [analyses.response], [analyses.check]"
                            " or [analyses.drive_event] (a chain: [analyses.chain_sweep],"
                            " [analyses.campbell] or [synthesis])")
    if "sweep" in out:
        _distinct_labels(readers["sweep"], out["sweep"].speeds, unit)
    return Analyses(**out, speed_unit=unit, where=where)


def _distinct_labels(t: Reader, speeds: tuple, unit: str) -> None:
    """Each curve of a sweep is labelled by its speed in ``unit``: no two labels alike."""
    labels = [format_speed(W, unit) for W in speeds]
    twice = [s for i, s in enumerate(labels) if s in labels[:i]]
    if twice:
        raise t.error("speeds", f"two speeds round to {twice[0]}; each curve of a sweep is"
                                f" labelled by its speed in {speed_resolution(unit)}")


def _n_modes(t: Reader, default=None, minimum: int = 1):
    return t.integer("n_modes", default, minimum=minimum, maximum=MAX_MODES, limit="MAX_MODES")


def _modes(t: Reader, parts, mechanisms, has_mounts) -> ModesSpec:
    part = _only_part(t, parts)
    n_modes = _n_modes(t)
    band = _values(t, "band_hz", FREQUENCY)
    if (n_modes is None) == (band is None):
        raise t.error(None, "give exactly one of n_modes and band_hz")
    if band is not None:
        if len(band) != 2:
            raise t.error("band_hz", f"expected [low, high], got {show(list(band))}")
        if not 0 <= band[0] < band[1]:
            raise t.error("band_hz", f"expected 0 <= low < high, got {show(list(band))} Hz")
    reduced = parts[part].reduction is not None
    model = t.string("model", "reduced" if reduced else "full", choices=("full", "reduced"))
    if model == "reduced" and not reduced:
        raise t.error("model", f"part {part!r} has no [reduction]; use model = 'full'")
    images = t.integer("images", min(n_modes or 6, 6), minimum=0, maximum=MAX_IMAGES,
                       limit="MAX_IMAGES")
    animate = t.get("animate", [])
    if not (isinstance(animate, list) and all(isinstance(k, int) and not isinstance(k, bool)
                                              and k >= 1 for k in animate)):
        raise t.error("animate", "expected a list of mode numbers (1 = the lowest mode), got"
                                 f" {show(animate)}")
    if len(set(animate)) > MAX_ANIMATIONS:
        raise t.error("animate", f"at most {MAX_ANIMATIONS} animations (MAX_ANIMATIONS)")
    return ModesSpec(part, n_modes, band, model, images, t.boolean("vtu", True),
                     t.boolean("series", False), tuple(sorted(set(animate))),
                     t.boolean("discretisation_error", False))


def _needs_machine(t: Reader, parts, has_mounts, what: str) -> None:
    if not has_mounts:
        raise t.error(None, f"{what} needs a machine: add [[mounts]] placing mechanisms on"
                            " parts")
    unreduced = [n for n, p in parts.items() if p.reduction is None]
    if unreduced:
        raise t.error(None, f"{what} needs reduced frames; part {unreduced[0]!r} has no"
                            " [reduction]")


def _sweep(t: Reader, parts, mechanisms, has_mounts) -> SweepSpec:
    mechanism = t.string("mechanism", None)
    if mechanism is not None and mechanism not in mechanisms:
        raise t.error("mechanism", f"expected one of the [mechanisms] {sorted(mechanisms)},"
                                   f" got {show(mechanism)}")
    if mechanism is not None and mechanisms[mechanism].form != "rheolinear":
        raise t.error("mechanism", f"mechanism {mechanism!r} has form ="
                                   f" {mechanisms[mechanism].form!r}; quasi-modes need form ="
                                   " 'rheolinear' (the default)")
    if mechanism is None:
        _needs_machine(t, parts, has_mounts, "a sweep of the machine (no mechanism key)")
    angles = _values(t, "angles", ANGLE, (0.0, 2 * np.pi))
    at = _values(t, "mode_images_at", ANGLE, (), maximum=MAX_IMAGES, limit="MAX_IMAGES")
    if at and (mechanism is not None or len(parts) != 1):
        raise t.error("mode_images_at", "mode images need a machine of one part (not a"
                                        " mechanism alone, not an assembly of parts)")
    n_modes = _n_modes(t)  # None: sweep's default (6, or all branches where fewer exist)
    speeds = _values(t, "speeds", SPEED, (0.0,))
    if len(angles) * len(speeds) > MAX_SWEEP_POINTS:
        raise t.error("speeds", f"{len(angles)} angles x {len(speeds)} speeds; at most"
                                f" {MAX_SWEEP_POINTS} points (limit MAX_SWEEP_POINTS)")
    return SweepSpec(angles, n_modes, speeds, mechanism, t.boolean("track", True), at)


def _stability(t: Reader, parts, mechanisms, has_mounts) -> StabilitySpec:
    _needs_machine(t, parts, has_mounts, "a stability chart")
    speeds = _values(t, "speeds", SPEED)
    if speeds is None or len(speeds) < 2 or min(speeds) <= 0:
        raise t.error("speeds", "expected >= 2 positive drive speeds (list or {start, stop,"
                                " n}), e.g. {start = '100 rpm', stop = '3000 rpm', n = 30}")
    n_steps = t.integer("n_steps", 32, minimum=4, maximum=MAX_STEPS, limit="MAX_STEPS")
    from femmech.analysis.magnus import MAX_STEPS as MONODROMY_MAX_STEPS
    from femmech.analysis.magnus import RTOL as MONODROMY_RTOL

    return StabilitySpec(speeds, n_steps,
                         t.number("angle_period", ANGLE, 2 * np.pi, positive=True),
                         _rayleigh(t), t.number("tol", DIMENSIONLESS, 1e-6, positive=True),
                         t.number("rtol", DIMENSIONLESS, MONODROMY_RTOL, positive=True),
                         t.integer("max_steps", max(MONODROMY_MAX_STEPS, n_steps),
                                   minimum=n_steps, maximum=MAX_STEPS, limit="MAX_STEPS"))


def _response(t: Reader, parts, mechanisms, has_mounts) -> ResponseSpec:
    _needs_machine(t, parts, has_mounts, "a response")
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

    return ResponseSpec(kind, speed, n_steps, *ramp, outputs, tuple(dofs), _rayleigh(t),
                        t.number("rtol", DIMENSIONLESS, STEADY_STATE_RTOL, positive=True),
                        t.integer("max_steps", max(STEADY_STATE_MAX_STEPS, n_steps),
                                  minimum=n_steps, maximum=MAX_STEPS, limit="MAX_STEPS"))


def _check(t: Reader, parts, mechanisms, has_mounts) -> CheckSpec:
    _needs_machine(t, parts, has_mounts, "a full-versus-reduced check")
    if len(parts) != 1:
        raise t.error(None, "the full-versus-reduced check needs a machine of one part")
    angles = _values(t, "angles", ANGLE)
    if angles is None:
        raise t.error("angles", "missing (required): the drive angles to compare at")
    levels = _values(t, "f_max_hz_levels", FREQUENCY, (), maximum=MAX_LEVELS,
                     limit="MAX_LEVELS")
    if levels and min(levels) <= 0:
        raise t.error("f_max_hz_levels", f"expected positive frequencies, got"
                                         f" {show(list(levels))}")
    reduction = next(iter(parts.values())).reduction
    if levels and reduction.method != "craig_bampton":
        raise t.error("f_max_hz_levels", "needs a craig_bampton reduction")
    return CheckSpec(angles, _n_modes(t, 6), levels)


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


def _second_kind_mechanism(t: Reader, mechanisms: dict) -> str:
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


def _is_rotational(t: Reader, spec, drive: str) -> bool:
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


def _drive_event(t: Reader, parts, mechanisms, has_mounts) -> DriveEventSpec:
    from femmech.analysis.drive_events import travel_time
    from femmech.analysis.nonlinear import METHODS as INTEGRATORS

    mechanism = _second_kind_mechanism(t, mechanisms)
    drive = t.string("drive")
    rotational = _is_rotational(t, mechanisms[mechanism], drive)
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
    brakes = _values(t, "braking_times", TIME, maximum=MAX_RUNS, limit="MAX_RUNS")
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


_READERS = {"modes": _modes, "sweep": _sweep, "stability": _stability, "response": _response,
            "check": _check, "drive_event": _drive_event}
