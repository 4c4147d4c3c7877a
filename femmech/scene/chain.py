"""Scene tables ``[chain]`` and ``[synthesis]``: a main shaft carrying N identical, phased
cam-follower units (:mod:`femmech.chain`) and the choice of design parameters that keeps
its quasi-eigenfrequencies out of the drive harmonics. Its analyses are analysis kinds
(:mod:`femmech.scene.kinds.chain_sweep`, ``campbell``, ``synthesis``).

Reading (:func:`read_chain`, :func:`read_synthesis`) checks every value at its key
(units, ranges, unknown keys, the cam programme) and returns frozen specs in SI units;
nothing is built. :func:`build_chain` turns a :class:`ChainSpec` (with optional
design-parameter values, :data:`DESIGN`) into a :class:`femmech.chain.Chain`. Scene data
are never executed: the unit is the built-in cam follower
(:func:`femmech.chain.follower_unit`) with a cam programme
(:func:`femmech.mechanisms.cam_program`).

Stage 8 (scene), reading and building: uses scene.reader, scene.units,
scene.kinds.common (the shared readers), chain and mechanisms.
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
from femmech.scene.kinds.common import (
    needs_chain,
    read_harmonics,
    read_margin,
    read_n_modes,
    read_speed_range,
)
from femmech.scene.reader import Reader, show
from femmech.scene.units import (
    ANGLE,
    DAMPING,
    DENSITY,
    FORCE,
    INERTIA,
    LENGTH,
    MASS,
    PRESSURE,
    ROT_STIFFNESS,
    STIFFNESS,
    Kind,
)

MAX_UNITS = 10_000
"""Most units of a chain (the assembled model is solved densely below 400 coordinates,
then sparse: :data:`femmech.chain.transfer.DENSE_MAX`; the transfer method is O(N))."""
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


# --- the synthesis table (read with the scene; its kind: femmech.scene.kinds.synthesis) --

def chain_analyses(chain_spec) -> dict:
    """What the readers of the analysis kinds need of ``[chain]``: ``{"chain": spec or
    None}``, the ``extra`` of :func:`femmech.scene.analyses.read_analyses`."""
    return {"chain": chain_spec}


SYNTHESIS_KEYS = ("parameters", "speeds", "harmonics", "margin", "starts", "n_modes",
                  "n_angles", "objective", "seed")
"""Keys of the table ``[synthesis]``."""


def read_synthesis(t: Reader, chain_spec) -> SynthesisSpec:
    """``[synthesis]``: parameters {name = [low, high]}, speeds [lo, hi], harmonics,
    margin (0.03), starts (8), n_modes (all), n_angles (72), objective ("closest"),
    seed (0)."""
    t.expect(*SYNTHESIS_KEYS)
    needs_chain(t, chain_spec)
    p = t.table("parameters")
    p.expect(*DESIGN)
    if not p.data:
        raise t.error("parameters", f"expected at least one of {sorted(DESIGN)} with"
                                    " [low, high] bounds")
    current = design_values(chain_spec)
    params = tuple((name, *_bounds(p, name, current[name], chain_spec))
                   for name in p.data)
    starts = t.integer("starts", 8, minimum=1, maximum=MAX_STARTS, limit="MAX_STARTS")
    return SynthesisSpec(params, read_speed_range(t), read_harmonics(t),
                         read_margin(t, 0.03), starts, read_n_modes(t, None),
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


def __getattr__(name: str):
    """Names this module had before the analysis kinds got their modules, from their new
    places (docs/architecture.md, "Moved names")."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "CampbellSpec": "femmech.scene.kinds.campbell.CampbellSpec",
        "ChainSweepSpec": "femmech.scene.kinds.chain_sweep.ChainSweepSpec",
        "MAX_HARMONICS": "femmech.scene.kinds.common.MAX_HARMONICS",
        "plot_method_sweeps": "femmech.output.chain_plots.plot_method_sweeps",
        "read_campbell": "femmech.scene.kinds.campbell.read",
        "read_chain_sweep": "femmech.scene.kinds.chain_sweep.read",
    })
