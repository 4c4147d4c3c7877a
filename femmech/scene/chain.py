"""Scene tables ``[chain]``, ``[analyses.chain_sweep]``, ``[analyses.campbell]`` and
``[synthesis]``: a main shaft carrying N identical, phased cam-follower units
(:mod:`femmech.chain`), its quasi-eigenfrequencies over the drive angle by several
methods, its Campbell diagram and the choice of design parameters that keeps them out of
the drive harmonics.

Reading (:func:`read_chain`, :func:`read_chain_sweep`, :func:`read_campbell`,
:func:`read_synthesis`) checks every value at its key (units, ranges, unknown keys, the
cam programme) and returns frozen specs in SI units; nothing is built. :func:`build_chain`
turns a :class:`ChainSpec` (with optional design-parameter values, :data:`DESIGN`) into a
:class:`femmech.chain.Chain`. Scene data are never executed: the unit is the built-in
cam follower (:func:`femmech.chain.follower_unit`) with a cam programme
(:func:`femmech.mechanisms.cam_program`).

Stage 8 (scene), reading and building: uses scene.reader, scene.units, scene.analyses
(value lists and limits), chain and mechanisms.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from femmech.chain import End, chain, follower_unit
from femmech.chain.model import STEEL_G, STEEL_RHO
from femmech.errors import SceneError
from femmech.mechanisms import cam_program
from femmech.mechanisms.motion_laws import LAWS
from femmech.output.formatting import Quantity
from femmech.output.report import Table
from femmech.scene.analyses import MAX_MODES, read_values
from femmech.scene.reader import Reader, show
from femmech.scene.units import (
    ANGLE,
    DAMPING,
    DENSITY,
    DIMENSIONLESS,
    FORCE,
    INERTIA,
    LENGTH,
    MASS,
    PRESSURE,
    ROT_STIFFNESS,
    SPEED,
    STIFFNESS,
    Kind,
)

MAX_UNITS = 10_000
"""Most units of a chain (the assembled model is solved densely below 400 coordinates,
then sparse: :data:`femmech.chain.transfer.DENSE_MAX`; the transfer method is O(N))."""
MAX_HARMONICS = 100
"""Highest drive harmonic k·Ω of a Campbell diagram or a synthesis."""
MAX_STARTS = 64
"""Most starting points of a synthesis (each a local optimisation)."""
MAX_ANGLES = 3600
"""Most drive angles of a synthesis (every design evaluated at each)."""
METHODS = ("assembled", "transfer", "continuum", "cyclic")
"""Solution methods of a chain (:func:`femmech.chain.sweep.compare_methods`)."""
END_KINDS = ("free", "clamped", "elastic", "flywheel")
"""End conditions of the shaft (:class:`femmech.chain.End`)."""

DESIGN: dict[str, tuple[Kind, str]] = {
    "shaft_diameter": (LENGTH, "outer diameter of the main shaft"),
    "coupling_stiffness": (ROT_STIFFNESS, "stiffness of the elastic coupling at the left"
                                          " (drive) end"),
    "flywheel_inertia": (INERTIA, "flywheel (and motor) inertia at the left (drive) end"),
    "follower_mass": (MASS, "follower mass of every unit"),
    "follower_stiffness": (STIFFNESS, "follower-train stiffness of every unit"),
    "hub_inertia": (INERTIA, "cam hub inertia of every unit"),
    "station_inertia": (INERTIA, "inertia added at every unit station"),
    "phase_step": (ANGLE, "phase step between neighbouring units: δ_u = u · step"),
}
"""Design parameters a synthesis may vary: name → (dimension, meaning). Values in SI."""


@dataclass(frozen=True)
class CamSpec:
    """Rise–dwell–return–dwell cam programme (:func:`femmech.mechanisms.cam_program`):
    stroke in m, angles in degrees (as ``cam_program`` takes them)."""

    stroke: float
    rise: float
    dwell_top: float
    return_: float
    dwell_bottom: float
    law: str
    return_law: str | None
    start: float

    def profile(self):
        """The :class:`~femmech.mechanisms.CamProfile`."""
        return cam_program(self.stroke, self.rise, self.dwell_top, self.return_,
                           self.dwell_bottom, self.law, self.return_law, self.start)


@dataclass(frozen=True)
class EndSpec:
    """One shaft end: kind (:data:`END_KINDS`), stiffness (N m/rad), inertia (kg m²)."""

    kind: str = "free"
    stiffness: float = 0.0
    inertia: float = 0.0

    def end(self, stiffness=None, inertia=None) -> End:
        """The :class:`femmech.chain.End` (values overridden by design parameters)."""
        k = self.stiffness if stiffness is None else stiffness
        J = self.inertia if inertia is None else inertia
        return End(clamped=True) if self.kind == "clamped" else End(k, J)


@dataclass(frozen=True)
class ChainSpec:
    """A chain of ``n_units`` cam-follower units on a uniform main shaft (SI units).

    ``phases`` is a tuple of n_units angles (rad); ``uniform`` says they were given as
    "uniform" (δ_u = 2π u / N); ``ground_stiffness`` (N/m) is the follower's spring to
    ground, ``c_g`` of :func:`femmech.chain.follower_unit`. See
    :func:`femmech.chain.chain` for the other fields.
    """

    cam: CamSpec
    hub_inertia: float
    follower_mass: float
    follower_stiffness: float
    damping: float
    force: float
    n_units: int
    spacing: float
    shaft_diameter: float
    bore: float
    G: float
    rho: float
    station_inertia: float
    phases: tuple
    uniform: bool
    left: EndSpec
    right: EndSpec
    end_length: float | None
    cells: bool
    where: str = field(default="chain", compare=False)
    ground_stiffness: float = 0.0


@dataclass(frozen=True)
class ChainSweepSpec:
    """Quasi-eigenfrequencies of the chain over the drive angles (rad) by ``methods``."""

    methods: tuple
    n_modes: int
    angles: tuple


@dataclass(frozen=True)
class CampbellSpec:
    """Campbell diagram: the quasi-eigenfrequency bands (over ``angles``, rad) of the
    ``n_modes`` lowest branches against the drive speed range ``speeds`` = (lo, hi) rad/s,
    with the harmonics 1..``harmonics`` and the relative ``margin`` around their bands."""

    speeds: tuple
    harmonics: int
    n_modes: int
    angles: tuple
    margin: float


@dataclass(frozen=True)
class SynthesisSpec:
    """Design parameters ``parameters`` = ((name, low, high), ...) (SI, names of
    :data:`DESIGN`) chosen so that the quasi-eigenfrequencies keep the relative
    ``margin`` from every harmonic band k·[Ω_lo, Ω_hi], k = 1..``harmonics``, ``speeds``
    = (Ω_lo, Ω_hi) rad/s (:func:`femmech.chain.synthesis.synthesise`; ``n_modes`` None:
    every branch; ``objective`` its ``method``)."""

    parameters: tuple
    speeds: tuple
    harmonics: int
    margin: float
    starts: int
    n_modes: int | None
    n_angles: int
    objective: str
    seed: int


_CHAIN_KEYS = ("unit", "n_units", "spacing", "shaft_diameter", "bore", "G", "rho",
               "station_inertia", "phases", "left", "right", "end_length", "cells")
_UNIT_KEYS = ("kind", "cam", "inertia", "mass", "stiffness", "damping", "force",
              "ground_stiffness")
_CAM_KEYS = ("law", "return_law", "stroke", "rise", "dwell_top", "return", "dwell_bottom",
             "start")


def read_chain(r: Reader) -> ChainSpec:
    """Parse ``[chain]`` (``r`` its reader) into a :class:`ChainSpec`."""
    r.expect(*_CHAIN_KEYS)
    u = r.table("unit")
    u.expect(*_UNIT_KEYS)
    u.string("kind", "cam_follower", choices=("cam_follower",))
    cam = _cam(u.table("cam"))
    n = r.integer("n_units", minimum=1, maximum=MAX_UNITS, limit="MAX_UNITS")
    diameter = r.number("shaft_diameter", LENGTH, positive=True)
    bore = r.number("bore", LENGTH, 0.0, non_negative=True)
    if not bore < diameter:
        raise r.error("bore", f"expected less than shaft_diameter ({diameter:g} m), got"
                              f" {bore:g} m")
    phases, uniform = _phases(r, n)
    end_length = r.number("end_length", LENGTH, None, positive=True)
    spec = ChainSpec(cam, u.number("inertia", INERTIA, non_negative=True),
                     u.number("mass", MASS, positive=True),
                     u.number("stiffness", STIFFNESS, positive=True),
                     u.number("damping", DAMPING, 0.0, non_negative=True),
                     u.number("force", FORCE, 0.0), n,
                     r.number("spacing", LENGTH, positive=True), diameter, bore,
                     r.number("G", PRESSURE, STEEL_G, positive=True),
                     r.number("rho", DENSITY, STEEL_RHO, positive=True),
                     r.number("station_inertia", INERTIA, 0.0, non_negative=True),
                     phases, uniform, _end(r, "left"), _end(r, "right"), end_length,
                     r.boolean("cells", False), r.where,
                     ground_stiffness=u.number("ground_stiffness", STIFFNESS, 0.0,
                                               non_negative=True))
    if spec.left.kind == spec.right.kind == "clamped" and n == 1 and end_length is None:
        raise r.error("right", "a single unit without end_length has one node; it cannot"
                               " be clamped at both ends")
    return spec


def _cam(c: Reader) -> CamSpec:
    c.expect(*_CAM_KEYS)
    laws = tuple(LAWS)
    stroke = c.number("stroke", LENGTH)
    if stroke == 0:
        raise c.error("stroke", "expected a non-zero stroke (e.g. '30 mm')")
    angles = {k: c.number(k, ANGLE, 0.0 if k.startswith("dwell") else None,
                          non_negative=True) for k in ("rise", "dwell_top", "return",
                                                       "dwell_bottom")}
    for key in ("rise", "return"):
        if angles[key] is None:
            raise c.error(key, "missing (required)")
        if angles[key] == 0:
            raise c.error(key, "expected a positive angle")
    total = math.degrees(sum(angles.values()))
    if abs(total - 360.0) > 1e-6:
        raise c.error(None, f"rise + dwell_top + return + dwell_bottom = {total:.9g} deg;"
                            " expected one revolution (360 deg)")
    deg = {k: round(math.degrees(v), 9) for k, v in angles.items()}  # '120 deg' → 120
    deg["rise"] += 360.0 - sum(deg.values())  # exactly 360 for cam_program
    spec = CamSpec(stroke, deg["rise"], deg["dwell_top"], deg["return"],
                   deg["dwell_bottom"], c.string("law", "modified_sine", choices=laws),
                   c.string("return_law", None, choices=laws),
                   math.degrees(c.number("start", ANGLE, 0.0)))
    try:
        spec.profile()
    except ValueError as exc:
        raise c.error(None, str(exc)) from None
    return spec


def _phases(r: Reader, n: int) -> tuple[tuple, bool]:
    """``phases``: "uniform" (2π u / N), one angle for all, or a list of n angles (rad)."""
    value = r.get("phases", 0.0)
    if value == "uniform":
        return tuple((2 * np.pi * np.arange(n) / n).tolist()), True
    if isinstance(value, list):
        if len(value) != n:
            raise r.error("phases", f"expected n_units = {n} angles, got {len(value)}")
        return tuple(r.convert("phases", v, ANGLE) for v in value), False
    if isinstance(value, str) and not any(ch.isdigit() for ch in value):
        raise r.error("phases", f"expected 'uniform', an angle or a list of {n} angles, got"
                                f" {show(value)}")
    return (r.convert("phases", value, ANGLE),) * n, False


def _end(r: Reader, key: str) -> EndSpec:
    """``left``/``right``: a kind ("free", "clamped") or a table {kind, stiffness,
    inertia}."""
    value = r.get(key, "free")
    if isinstance(value, str):
        kind = r.string(key, choices=END_KINDS)
        if kind in ("elastic", "flywheel"):
            raise r.error(key, f"kind {kind!r} needs a table, e.g. {{ kind = '{kind}', "
                          + ("stiffness = '5e3 N*m/rad', inertia = '0.5 kg*m^2' }"
                             if kind == "elastic" else "inertia = '0.5 kg*m^2' }"))
        return EndSpec(kind)
    t = r.table(key)
    t.expect("kind", "stiffness", "inertia")
    kind = t.string("kind", choices=END_KINDS)
    allowed = {"free": (), "clamped": (), "elastic": ("stiffness", "inertia"),
               "flywheel": ("inertia",)}[kind]
    t.expect("kind", *allowed, context=f"for kind = {kind!r}")
    stiffness = t.number("stiffness", ROT_STIFFNESS, positive=True) if kind == "elastic" \
        else 0.0
    inertia = t.number("inertia", INERTIA, None if kind == "flywheel" else 0.0,
                       **({"positive": True} if kind == "flywheel" else
                          {"non_negative": True})) if allowed else 0.0
    return EndSpec(kind, stiffness, inertia)


def build_chain(spec: ChainSpec, design: dict | None = None):
    """The :class:`femmech.chain.Chain` of a spec; ``design`` ({name of :data:`DESIGN`:
    SI value}) overrides the spec's values (a synthesis trial).

    Raises
    ------
    ValueError
        For a design value the chain refuses (naming the parameter).
    """
    p = dict(design or {})
    unknown = set(p) - set(DESIGN)
    if unknown:
        raise ValueError(f"unknown design parameter {sorted(unknown)[0]!r}; expected one of"
                         f" {sorted(DESIGN)}")
    phases = np.asarray(spec.phases)
    if "phase_step" in p:
        phases = p["phase_step"] * np.arange(spec.n_units)
    unit = follower_unit(spec.cam.profile(), p.get("hub_inertia", spec.hub_inertia),
                         p.get("follower_mass", spec.follower_mass),
                         p.get("follower_stiffness", spec.follower_stiffness), spec.damping,
                         spec.force, c_g=spec.ground_stiffness)
    left = spec.left.end(p.get("coupling_stiffness"), p.get("flywheel_inertia"))
    return chain(unit, spec.n_units, spec.spacing,
                 p.get("shaft_diameter", spec.shaft_diameter),
                 station_inertia=p.get("station_inertia", spec.station_inertia),
                 phases=phases, left=left, right=spec.right.end(),
                 end_length=spec.end_length, cells=spec.cells, bore=spec.bore, G=spec.G,
                 rho=spec.rho)


def check_chain(spec: ChainSpec, file: str):
    """:func:`build_chain` of the spec; its ValueErrors as a SceneError at ``[chain]``."""
    try:
        return build_chain(spec)
    except ValueError as exc:
        raise SceneError(f"{file}: [{spec.where}]: {exc}".replace("\n", " ")) from None


def design_values(spec: ChainSpec) -> dict:
    """Current value (SI) of every design parameter of :data:`DESIGN` in the spec."""
    step = spec.phases[1] - spec.phases[0] if spec.n_units > 1 else 0.0
    return {"shaft_diameter": spec.shaft_diameter,
            "coupling_stiffness": spec.left.stiffness,
            "flywheel_inertia": spec.left.inertia, "follower_mass": spec.follower_mass,
            "follower_stiffness": spec.follower_stiffness, "hub_inertia": spec.hub_inertia,
            "station_inertia": spec.station_inertia, "phase_step": step}


def with_design(spec: ChainSpec, values: dict) -> ChainSpec:
    """The spec with design values (SI) written into its fields (for reports)."""
    fields = {"shaft_diameter": "shaft_diameter", "follower_mass": "follower_mass",
              "follower_stiffness": "follower_stiffness", "hub_inertia": "hub_inertia",
              "station_inertia": "station_inertia"}
    out = replace(spec, **{fields[k]: v for k, v in values.items() if k in fields})
    if "coupling_stiffness" in values or "flywheel_inertia" in values:
        out = replace(out, left=replace(out.left, stiffness=values.get(
            "coupling_stiffness", out.left.stiffness), inertia=values.get(
            "flywheel_inertia", out.left.inertia)))
    if "phase_step" in values:
        out = replace(out, phases=tuple((values["phase_step"] *
                                         np.arange(spec.n_units)).tolist()), uniform=False)
    return out


# --- analyses ----------------------------------------------------------------------------

def _angles(t: Reader, n: int) -> tuple:
    return read_values(t, "angles", ANGLE, tuple(np.linspace(0, 2 * np.pi, n).tolist()))


def _n_modes(t: Reader, default: int) -> int:
    return t.integer("n_modes", default, minimum=1, maximum=MAX_MODES, limit="MAX_MODES")


def _method_list(t: Reader, key: str, default: tuple) -> tuple:
    methods = t.strings(key, default)
    if not methods:
        raise t.error(key, f"expected at least one of {list(METHODS)}")
    for m in methods:
        if m not in METHODS:
            raise t.error(key, f"expected names of {list(METHODS)}, got {show(m)}")
    if len(set(methods)) < len(methods):
        raise t.error(key, f"a method is named twice: {show(list(methods))}")
    return methods


def _speed_range(t: Reader, key: str = "speeds") -> tuple:
    value = t.get(key)
    if not isinstance(value, list) or len(value) != 2:
        raise t.error(key, f"expected [lowest, highest] drive speed, e.g. ['1200 rpm',"
                           f" '1400 rpm'], got {show(value)}")
    lo, hi = (t.convert(key, v, SPEED) for v in value)
    if not 0 < lo < hi:
        raise t.error(key, f"expected 0 < lowest < highest, got {show(value)}")
    return lo, hi


def _margin(t: Reader, default: float) -> float:
    margin = t.number("margin", DIMENSIONLESS, default, non_negative=True)
    if not margin < 0.5:
        raise t.error("margin", f"expected a relative margin below 0.5 (e.g. 0.03 for 3 %),"
                                f" got {margin:g}")
    return margin


def _harmonics(t: Reader) -> int:
    return t.integer("harmonics", minimum=1, maximum=MAX_HARMONICS, limit="MAX_HARMONICS")


def _needs_chain(t: Reader, chain_spec) -> None:
    if chain_spec is None:
        raise t.error(None, "needs a chain: add a [chain] table")


def read_chain_sweep(t: Reader, chain_spec) -> ChainSweepSpec:
    """``[analyses.chain_sweep]``: methods (default assembled, transfer, continuum),
    n_modes (6), angles (0..360°, 73)."""
    t.expect("methods", "n_modes", "angles")
    _needs_chain(t, chain_spec)
    methods = _method_list(t, "methods", ("assembled", "transfer", "continuum"))
    return ChainSweepSpec(methods, _n_modes(t, 6), _angles(t, 73))


def read_campbell(t: Reader, chain_spec) -> CampbellSpec:
    """``[analyses.campbell]``: speeds [lo, hi], harmonics K, n_modes (6), angles (0..360°,
    37), margin (0.03)."""
    t.expect("speeds", "harmonics", "n_modes", "angles", "margin")
    _needs_chain(t, chain_spec)
    return CampbellSpec(_speed_range(t), _harmonics(t), _n_modes(t, 6), _angles(t, 37),
                        _margin(t, 0.03))


def read_synthesis(t: Reader, chain_spec) -> SynthesisSpec:
    """``[synthesis]``: parameters {name = [low, high]}, speeds [lo, hi], harmonics,
    margin (0.03), starts (8), n_modes (all), n_angles (72), objective ("closest"),
    seed (0)."""
    t.expect("parameters", "speeds", "harmonics", "margin", "starts", "n_modes", "n_angles",
             "objective", "seed")
    _needs_chain(t, chain_spec)
    p = t.table("parameters")
    p.expect(*DESIGN)
    if not p.data:
        raise t.error("parameters", f"expected at least one of {sorted(DESIGN)} with"
                                    " [low, high] bounds")
    current = design_values(chain_spec)
    params = tuple((name, *_bounds(p, name, current[name], chain_spec))
                   for name in p.data)
    starts = t.integer("starts", 8, minimum=1, maximum=MAX_STARTS, limit="MAX_STARTS")
    return SynthesisSpec(params, _speed_range(t), _harmonics(t), _margin(t, 0.03), starts,
                         _n_modes(t, None),
                         t.integer("n_angles", 72, minimum=1, maximum=MAX_ANGLES,
                                   limit="MAX_ANGLES"),
                         t.string("objective", "closest", choices=("closest", "max_margin")),
                         t.integer("seed", 0, minimum=0, maximum=2**32 - 1))


def _bounds(p: Reader, name: str, current: float, spec: ChainSpec) -> tuple:
    kind = DESIGN[name][0]
    value = p.get(name)
    if not isinstance(value, list) or len(value) != 2:
        raise p.error(name, f"expected [low, high] ({kind.name}, e.g. [{kind.example},"
                            f" ...]), got {show(value)}")
    lo, hi = (p.convert(name, v, kind) for v in value)
    if not lo < hi:
        raise p.error(name, f"expected low < high, got {show(value)}")
    if name != "phase_step" and lo < 0 or (name in ("shaft_diameter", "follower_mass",
                                                    "follower_stiffness") and lo <= 0):
        raise p.error(name, f"expected positive bounds, got {show(value)}")
    if name == "shaft_diameter" and not lo > spec.bore:
        raise p.error(name, f"expected a lower bound above the bore ({spec.bore:g} m)")
    if name == "coupling_stiffness" and spec.left.kind != "elastic":
        raise p.error(name, "needs an elastic left end: [chain.left] kind = 'elastic'")
    if name == "flywheel_inertia" and spec.left.kind not in ("elastic", "flywheel"):
        raise p.error(name, "needs a left end of kind 'elastic' or 'flywheel'")
    if not lo <= current <= hi:
        raise p.error(name, f"the scene's value {current:.6g} (SI) lies outside the bounds"
                            f" {show(value)}; the synthesis starts from it")
    return lo, hi


def chain_analyses(chain_spec) -> dict:
    """{kind: reader(table) -> spec} of the chain's analysis tables, for
    :func:`femmech.scene.analyses.read_analyses`."""
    return {"chain_sweep": lambda t: read_chain_sweep(t, chain_spec),
            "campbell": lambda t: read_campbell(t, chain_spec)}


# --- report ------------------------------------------------------------------------------

_SHOWN = {LENGTH: ("mm", 1e3), ANGLE: ("°", 180 / np.pi), INERTIA: ("kg·m²", 1.0),
          MASS: ("kg", 1.0), STIFFNESS: ("N/m", 1.0), ROT_STIFFNESS: ("N·m/rad", 1.0)}


def design_quantity(name: str, value: float, digits: int = 4) -> Quantity:
    """A design parameter's value (SI) as a report cell: diameters in mm, angles in °."""
    unit, f = _SHOWN[DESIGN[name][0]]
    return Quantity(float(value) * f, unit, digits)


def _end_text(end: EndSpec) -> str:
    parts = [end.kind]
    if end.stiffness:
        parts.append(f"coupling {Quantity(end.stiffness, 'N·m/rad', 4, True)}")
    if end.inertia:
        parts.append(f"inertia {Quantity(end.inertia, 'kg·m²', 4, True)}")
    return ", ".join(str(p) for p in parts)


def chain_table(spec: ChainSpec, built) -> Table:
    """The chain of a scene as a report table (what was built, in readable units)."""
    c = spec.cam
    law = c.law if c.return_law is None else f"{c.law} / {c.return_law}"
    phases = ("uniform: δ_u = 360° · u / N" if spec.uniform else
              ", ".join(f"{np.rad2deg(p):.4g}°" for p in spec.phases[:8])
              + (", ..." if spec.n_units > 8 else ""))

    def q(value, unit, digits=4):
        return Quantity(float(value), unit, digits, True)
    rows = (("units N", spec.n_units), ("spacing", q(spec.spacing, "m")),
            ("shaft diameter / bore", f"{q(spec.shaft_diameter * 1e3, 'mm')} /"
                                      f" {q(spec.bore * 1e3, 'mm')}"),
            ("shaft G, ρ", f"{q(spec.G, 'Pa')}, {q(spec.rho, 'kg/m³')}"),
            ("end stubs", "none" if spec.end_length is None else q(spec.end_length, "m")),
            ("station inertia", q(spec.station_inertia, "kg·m²")),
            ("cam", f"{law}, stroke {q(c.stroke * 1e3, 'mm')}; rise {c.rise:.6g}°, dwell"
                    f" {c.dwell_top:.6g}°, return {c.return_:.6g}°, dwell {c.dwell_bottom:.6g}°"
                    f" (rise starts at {c.start:.6g}°)"),
            ("hub inertia J", q(spec.hub_inertia, "kg·m²")),
            ("follower mass m, stiffness c, damping",
             f"{q(spec.follower_mass, 'kg')}, {q(spec.follower_stiffness, 'N/m')},"
             f" {q(spec.damping, 'N·s/m')}"),
            ("phases", phases), ("left end (drive)", _end_text(spec.left)),
            ("right end", _end_text(spec.right)),
            ("model", f"{built.n_nodes} shaft nodes, {built.n} coordinates (shaft rotations"
                      " and follower deflections)"))
    return Table("Chain of identical cam-follower units on the main shaft ([chain])",
                 ("quantity", "value"), rows)


METHOD_NAMES = {"assembled": "assembled model (dense/sparse eigen solve)",
                "transfer": "transfer matrices (Wittrick–Williams count)",
                "continuum": "smeared continuum", "cyclic": "cyclic (Bloch) closed form"}
"""What each method is, for captions."""


def plot_method_sweeps(sweeps: dict, path, title: str = "", bands=None) -> None:
    """Quasi-eigenfrequencies over the drive angle, one panel per method side by side,
    with a common frequency axis (Hz) so the panels compare at a glance.

    ``sweeps``: method → result with ``phi`` (n_angles,) rad and ``freq_hz`` (n_angles,
    k) Hz. ``bands``: optional (lo_hz, hi_hz) arrays of harmonic bands, shaded grey.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure as MplFigure

    from femmech.output.charts import set_angle_axis
    from femmech.output.export import atomic_path

    n = len(sweeps)
    fig = MplFigure(figsize=(3.3 * n + 1.0, 4.4), dpi=110)
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, n, sharey=True, squeeze=False)[0]
    values = np.concatenate([np.ravel(s.freq_hz) for s in sweeps.values()])
    top = float(np.nanmax(values)) * 1.06
    colors = [f"C{k % 10}" for k in range(max(s.freq_hz.shape[1] for s in sweeps.values()))]
    for ax, (method, s) in zip(axes, sweeps.items(), strict=True):
        deg = np.rad2deg(np.asarray(s.phi))
        for k in range(s.freq_hz.shape[1]):
            ax.plot(deg, s.freq_hz[:, k], color=colors[k], lw=1.4, label=f"f{k + 1}")
        if bands is not None:
            for lo, hi in zip(*bands, strict=True):
                if lo < top:
                    ax.axhspan(lo, hi, color="0.85", zorder=0, lw=0)
        ax.set_title(method, fontsize=10)
        set_angle_axis(ax, float(deg.min()), float(deg.max()))
        ax.set_xlabel("drive angle φ (°)")
        ax.grid(True, alpha=0.3)
    axes[0].set_ylim(0.0, top)
    axes[0].legend(fontsize=7, ncol=3, loc="lower right", title="branch (tracked)",
                   title_fontsize=7)
    axes[0].set_ylabel("quasi-eigenfrequency (Hz)")
    if title:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
