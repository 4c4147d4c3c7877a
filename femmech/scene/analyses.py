"""Scene table ``[analyses]``: which results to compute, with their settings (SI).

Kinds (each at most once): ``modes`` (:func:`femmech.modes` or
:func:`femmech.analysis.modes.superelement_modes`), ``sweep`` (quasi-modes over the drive
angle, :func:`femmech.analysis.sweep.sweep` or :func:`femmech.mechanisms.quasi_modes`),
``stability`` (:func:`femmech.analysis.stability.stability_chart` over drive speed),
``response`` (:func:`femmech.analysis.response.periodic_steady_state` or a run-up by
:func:`~femmech.analysis.response.time_response`) and ``check`` (reduced versus full,
:func:`femmech.analysis.reference.compare_coupled`, optionally over several reduction
sizes: the speed-versus-error comparison).

Stage 7 (scene), reading: uses scene.reader, scene.units and the defaults of
analysis.response and analysis.magnus.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from femmech.analysis.magnus import MAX_STEPS as MONODROMY_MAX_STEPS
from femmech.analysis.magnus import RTOL as MONODROMY_RTOL
from femmech.analysis.response import STEADY_STATE_MAX_STEPS, STEADY_STATE_RTOL
from femmech.scene.reader import Reader, show
from femmech.scene.units import ANGLE, DIMENSIONLESS, FREQUENCY, INVERSE_TIME, SPEED, TIME

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


@dataclass(frozen=True)
class ModesSpec:
    """Natural modes of one part (full model or superelement)."""

    part: str
    n_modes: int | None
    band_hz: tuple | None
    model: str
    images: int
    vtu: bool


@dataclass(frozen=True)
class SweepSpec:
    """Quasi-modes over drive angles (rad) at one or more drive speeds (rad/s)."""

    angles: tuple
    n_modes: int
    speeds: tuple
    mechanism: str | None
    track: bool
    mode_images_at: tuple


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
    where: dict = field(default_factory=dict, compare=False)


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


_KEYS = {"modes": ("part", "n_modes", "band_hz", "model", "images", "vtu"),
         "sweep": ("angles", "n_modes", "speeds", "mechanism", "track", "mode_images_at"),
         "stability": ("speeds", "n_steps", "angle_period", "rayleigh", "tol", "rtol",
                       "max_steps"),
         "response": ("kind", "speed", "n_steps", "speed_start", "speed_end", "duration",
                      "t_end", "outputs", "frame_dofs", "rayleigh", "rtol", "max_steps"),
         "check": ("angles", "n_modes", "f_max_hz_levels")}
"""Keys of each analysis table."""


def read_analyses(r: Reader, parts: dict, mechanisms: dict, has_mounts: bool) -> Analyses:
    """Parse ``[analyses]``; checks that each analysis has what it needs."""
    r.expect(*_READERS)
    out, where = {}, {}
    readers = {k: r.table(k) for k in _READERS if r.has(k)}
    for kind, t in readers.items():
        t.expect(*_KEYS[kind])
        where[kind] = t.where
        out[kind] = _READERS[kind](t, parts, mechanisms, has_mounts)
    if not out:
        raise r.error(None, "no analyses requested: add [analyses.modes], [analyses.sweep],"
                            " [analyses.stability], [analyses.response] or [analyses.check]")
    return Analyses(**out, where=where)


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
    return ModesSpec(part, n_modes, band, model, images, t.boolean("vtu", True))


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
    if mechanism is None:
        _needs_machine(t, parts, has_mounts, "a sweep of the machine (no mechanism key)")
    angles = _values(t, "angles", ANGLE, (0.0, 2 * np.pi))
    at = _values(t, "mode_images_at", ANGLE, (), maximum=MAX_IMAGES, limit="MAX_IMAGES")
    if at and (mechanism is not None or len(parts) != 1):
        raise t.error("mode_images_at", "mode images need a machine of one part (not a"
                                        " mechanism alone, not an assembly of parts)")
    n_modes = _n_modes(t, 6)
    speeds = _values(t, "speeds", SPEED, (0.0,))
    rpm = [round(W * 30 / np.pi) for W in speeds]
    twice = [r for i, r in enumerate(rpm) if r in rpm[:i]]
    if twice:
        raise t.error("speeds", f"two speeds round to {twice[0]} rpm; each curve of a sweep is"
                                " labelled by its speed in whole rpm")
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


_READERS = {"modes": _modes, "sweep": _sweep, "stability": _stability, "response": _response,
            "check": _check}
