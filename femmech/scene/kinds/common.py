"""What the analysis kinds share: the limits of their tables, readers of value lists and
common keys, and the helpers of their runners (results as JSON lists, speed columns).

Stage 8 (scene): uses scene.reader and scene.units; the kind modules of this package and
:mod:`femmech.scene.chain` import it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from femmech.output.charts import format_speed
from femmech.scene.reader import Reader, show
from femmech.scene.units import ANGLE, DIMENSIONLESS, INVERSE_TIME, SPEED, TIME

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
MAX_HARMONICS = 100
"""Highest drive harmonic k·Ω of a Campbell diagram or a synthesis."""


@dataclass(frozen=True)
class ReadContext:
    """What a kind's reader may check its table against: the scene's ``parts`` and
    ``mechanisms`` (name → spec), whether it has mounts, its ``[chain]`` (a
    :class:`femmech.scene.chain.ChainSpec` or None) and the ``[analyses] speed_unit``."""

    parts: dict
    mechanisms: dict
    has_mounts: bool
    chain: object = None
    speed_unit: str = "rpm"


@dataclass(frozen=True)
class AnalysisKind:
    """One analysis kind of a scene.

    Attributes
    ----------
    name : str
        Its table, ``[analyses.<name>]`` (or ``[<name>]`` when ``top_level``), the key of
        its numbers in ``results.json`` and the name ``femmech check`` lists.
    keys : tuple of str
        The keys its table allows.
    read : callable
        ``read(table, context) -> spec``: the table's :class:`~femmech.scene.reader.Reader`
        and a :class:`ReadContext`; returns a frozen spec in SI units (raises SceneError).
    run : callable
        ``run(workshop, spec, out) -> (Section, numbers)``: computes, writes its files into
        the folder ``out`` and returns its report section and JSON-able key numbers.
    describe : str
        One line of what it computes (``docs/scenes.md`` lists it).
    order : int
        Place in the run order (ascending; the built-in kinds use 10, 20, ...).
    top_level : bool
        Its table is a top-level table read with the scene (``[synthesis]``), not one of
        ``[analyses]``.
    """

    name: str
    keys: tuple
    read: Callable
    run: Callable
    describe: str
    order: int
    top_level: bool = False

    def __post_init__(self):
        if not self.name.isidentifier():
            raise ValueError(f"analysis kind name must be an identifier, got {self.name!r}")
        if not (callable(self.read) and callable(self.run)):
            raise TypeError(f"analysis kind {self.name!r}: read and run must be callable")
        if not self.describe or "\n" in self.describe:
            raise ValueError(f"analysis kind {self.name!r}: describe must be one line")


def read_values(r: Reader, key: str, kind, default=None, maximum: int = MAX_POINTS,
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


def read_rayleigh(r: Reader) -> tuple:
    """``rayleigh = {mass, stiffness}``: (1/s, s), default (0, 0)."""
    if not r.has("rayleigh"):
        return (0.0, 0.0)
    t = r.table("rayleigh")
    t.expect("mass", "stiffness")
    return (t.number("mass", INVERSE_TIME, 0.0, non_negative=True),
            t.number("stiffness", TIME, 0.0, non_negative=True))


def only_part(r: Reader, parts: dict) -> str:
    part = r.string("part", next(iter(parts)) if len(parts) == 1 else None)
    if part not in parts:
        raise r.error("part", f"expected one of the [parts] {sorted(parts)}, got {show(part)}")
    return part


def read_n_modes(t: Reader, default=None, minimum: int = 1):
    return t.integer("n_modes", default, minimum=minimum, maximum=MAX_MODES, limit="MAX_MODES")


def needs_machine(t: Reader, parts, has_mounts, what: str) -> None:
    if not has_mounts:
        raise t.error(None, f"{what} needs a machine: add [[mounts]] placing mechanisms on"
                            " parts")
    unreduced = [n for n, p in parts.items() if p.reduction is None]
    if unreduced:
        raise t.error(None, f"{what} needs reduced frames; part {unreduced[0]!r} has no"
                            " [reduction]")


def chain_angles(t: Reader, n: int) -> tuple:
    return read_values(t, "angles", ANGLE, tuple(np.linspace(0, 2 * np.pi, n).tolist()))


def read_speed_range(t: Reader, key: str = "speeds") -> tuple:
    value = t.get(key)
    if not isinstance(value, list) or len(value) != 2:
        raise t.error(key, f"expected [lowest, highest] drive speed, e.g. ['1200 rpm',"
                           f" '1400 rpm'], got {show(value)}")
    lo, hi = (t.convert(key, v, SPEED) for v in value)
    if not 0 < lo < hi:
        raise t.error(key, f"expected 0 < lowest < highest, got {show(value)}")
    return lo, hi


def read_margin(t: Reader, default: float) -> float:
    margin = t.number("margin", DIMENSIONLESS, default, non_negative=True)
    if not margin < 0.5:
        raise t.error("margin", f"expected a relative margin below 0.5 (e.g. 0.03 for 3 %),"
                                f" got {margin:g}")
    return margin


def read_harmonics(t: Reader) -> int:
    return t.integer("harmonics", minimum=1, maximum=MAX_HARMONICS, limit="MAX_HARMONICS")


def needs_chain(t: Reader, chain_spec) -> None:
    if chain_spec is None:
        raise t.error(None, "needs a chain: add a [chain] table")


def listed(a) -> list:
    """Nested list of floats with NaN as None (valid JSON)."""
    a = np.asarray(a, dtype=float)
    if a.ndim > 1:
        return [listed(x) for x in a]
    return [float(x) if math.isfinite(x) else None for x in np.atleast_1d(a)]


def speed_column(unit: str) -> str:
    """CSV column of a drive speed in ``unit``: speed_rpm, speed_rad_s."""
    return "speed_" + unit.replace("/", "_")


def speed_range(lo: float, hi: float, unit: str) -> str:
    """Speeds lo..hi (rad/s) as text in ``unit``: "100..300 rpm", or "100 rpm"."""
    a, b = format_speed(lo, unit), format_speed(hi, unit)
    return a if a == b else f"{a.split()[0]}..{b}"


def damped(ws, rayleigh):
    """The workshop's coupled machine, with Rayleigh damping (mass, stiffness) if any."""
    from femmech.analysis.response import rayleigh_damping

    system = ws.machine()
    return rayleigh_damping(system, *rayleigh) if any(rayleigh) else system


def in_rpm(speeds) -> tuple:
    """A speed range (rad/s) in rpm."""
    return tuple(float(W) * 60 / (2 * np.pi) for W in speeds)


def margin_text(m, required: float) -> str:
    """One sentence on a resonance margin (:class:`femmech.chain.synthesis.Margin`)."""
    verdict = "meets" if m.value >= required else "does NOT meet"
    return (f"resonance margin {100 * m.value:+.2f} % ({verdict} the required"
            f" {100 * required:g} %): closest is branch f{m.branch + 1} = {m.frequency_hz:.2f}"
            f" Hz at φ = {np.rad2deg(m.angle):.0f}°, {m.side} the band of harmonic"
            f" k = {m.harmonic} ({m.band_hz[0]:.2f}–{m.band_hz[1]:.2f} Hz)")
