"""Scene tables ``[mechanisms.<name>]`` and ``[[mounts]]``: mechanism models and attachments.

A mechanism is a built-in model of :mod:`femmech.mechanisms` (a registered type,
:data:`femmech.mechanisms.registry.MECHANISM_TYPES`) or a
function in a user Python module (``module = "my_mech.py"``, ``function = "build"``)
returning a symbolic :class:`~femmech.mechanisms.Mechanism` (or a ready
``RheolinearModel`` or ``LagrangeModel``), with parameter values (SI or unit strings) and
position functions (cams, linkages). Its ``form`` (:data:`FORMS`) says which equations
are built: ``rheolinear`` (the default; mounts, sweeps) or ``second_kind`` (the nonlinear
equations with prescribed drives; drive events). A mount places a mechanism on a part:
:class:`femmech.coupling.Mount`.

Stage 8 (scene), reading: uses scene.reader, scene.units, fe.dofs and the factories of
mechanisms; nothing is built here.
"""

from __future__ import annotations

import inspect
import math
from dataclasses import dataclass, field
from pathlib import Path

import femmech.mechanisms  # noqa: F401  (its factory modules register the types)
from femmech.fe.dofs import COMPONENTS
from femmech.mechanisms.catalogue import Entry
from femmech.mechanisms.motion_laws import LAWS
from femmech.mechanisms.registry import MECHANISM_TYPES
from femmech.scene.reader import Reader, file_path, show
from femmech.scene.units import (
    ACCELERATION,
    ANGLE,
    DAMPING,
    DIMENSIONLESS,
    FORCE,
    INERTIA,
    LENGTH,
    MASS,
    MOMENT,
    ROT_DAMPING,
    ROT_STIFFNESS,
    STIFFNESS,
    Kind,
)

BUILTIN_MODELS = {name: kind.factory for name, kind in MECHANISM_TYPES.items()}
"""Built-in mechanism models by scene name → factory of :mod:`femmech.mechanisms`, as
registered (:data:`femmech.mechanisms.registry.MECHANISM_TYPES`); ``options`` are the
factory's keyword arguments (checked against its signature). A new mechanism type joins
scenes by its registration next to its factory."""

FORMS = ("rheolinear", "second_kind")
"""Equations a scene builds for a mechanism (``form``): ``rheolinear`` (linearised about
the programmed drive motion, :func:`femmech.mechanisms.rheolinear`; for mounts and
sweeps; the default) or ``second_kind`` (the nonlinear Lagrange equations of the 2nd kind
with prescribed drives, :func:`femmech.mechanisms.second_kind`; for drive events)."""

UNIT_KINDS = {"m": LENGTH, "rad": ANGLE, "N": FORCE, "N·m": MOMENT, "kg": MASS,
               "kg·m²": INERTIA, "N/m": STIFFNESS, "N·m/rad": ROT_STIFFNESS,
               "N·s/m": DAMPING, "N·m·s/rad": ROT_DAMPING, "m/s²": ACCELERATION}
"""Dimension of each SI unit the catalogue gives a built-in parameter or quantity."""


def catalogue_entry(model: str | None, options: dict) -> Entry | None:
    """The :data:`~femmech.mechanisms.catalogue.CATALOGUE` entry of a built-in ``model``
    with its factory ``options`` (None for user modules)."""
    kind = MECHANISM_TYPES.get(model)
    return kind.entry(options) if kind is not None else None


QUANTITIES = {model: {c.name: (c.meaning, UNIT_KINDS.get(c.unit))
                      for c in kind.quantities({"case": 1, "kinematic_drive": True})}
              for model, kind in MECHANISM_TYPES.items()}
"""Per built-in model (its default options; ``table_5_1_case``: case 1): quantity → (what
it is physically, its dimension), from :data:`femmech.mechanisms.catalogue.CATALOGUE`.
Quantities are coordinate names, ``"force <drive>"`` (the force a drive supplies) and
``"spring<k>"`` (the force of the k-th spring, 1-based in the mechanism's element order).
:func:`describe_quantity` follows the options of a mechanism."""

POSITION_KINDS = ("cam", "slider_crank", "four_bar", "chapter_cam")
MOTION_LAWS = tuple(LAWS)
"""Names of the cam motion laws a scene may use (:data:`femmech.mechanisms.motion_laws.LAWS`)."""


@dataclass(frozen=True)
class PositionSpec:
    """A position function U(φ) by kind (see :data:`POSITION_KINDS`) and parameters (SI)."""

    name: str
    kind: str
    params: dict
    where: str = field(default="", compare=False)


@dataclass(frozen=True)
class MechanismSpec:
    """A mechanism: built-in ``model`` with ``options``, or ``module`` + ``function``."""

    name: str
    model: str | None
    module: str | None
    function: str | None
    options: dict
    parameters: dict
    position_functions: tuple
    where: str = field(default="", compare=False)
    form: str = "rheolinear"


def describe_quantity(spec: MechanismSpec, name: str) -> tuple[str, Kind | None]:
    """(physical description, dimension or None) of a quantity of a mechanism (see
    :data:`QUANTITIES`); without a description the name itself, and None when the
    dimension is unknown (a user module's coordinates). For a readable label with the
    raw name in brackets: :func:`femmech.mechanisms.catalogue.readable`."""
    entry = catalogue_entry(spec.model, spec.options)
    found = entry.coordinate(name) if entry is not None else None
    return (found.meaning, UNIT_KINDS.get(found.unit)) if found else (name, None)


@dataclass(frozen=True)
class AttachmentSpec:
    """:class:`femmech.coupling.Attachment` with the node as a group name or index."""

    coordinate: str
    node: object
    direction: object
    stiffness: float | None = None
    damping: float = 0.0
    where: str = field(default="", compare=False)


@dataclass(frozen=True)
class MountSpec:
    """:class:`femmech.coupling.Mount` of a named mechanism on a named part."""

    name: str
    mechanism: str
    part: str
    attachments: tuple
    ratio: float = 1.0
    phase: float = 0.0
    where: str = field(default="", compare=False)


def parameter_kinds(spec: MechanismSpec) -> dict:
    """Parameter name → expected dimension for a built-in model (empty for user modules):
    the registered type's parameters (:meth:`femmech.mechanisms.registry.MechanismType.
    parameter_units`) under the names its options give them."""
    kind = MECHANISM_TYPES.get(spec.model)
    units = kind.parameter_units(spec.options) if kind is not None else {}
    return {name: UNIT_KINDS[unit] for name, unit in units.items()}


def read_mechanisms(root: Reader, base: Path) -> dict:
    """All ``[mechanisms.<name>]`` tables → {name: MechanismSpec}."""
    out = {}
    for name, r in root.named_tables("mechanisms").items():
        r.expect("model", "module", "function", "options", "parameters", "position_functions",
                 "form")
        if r.has("model") == r.has("module"):
            raise r.error(None, "give exactly one of model (built-in: one of"
                                f" {list(BUILTIN_MODELS)}) and module (a Python file)")
        model = r.string("model", None, choices=tuple(BUILTIN_MODELS))
        module = function = None
        if model is None:
            module = file_path(base, r.string("module"))
            if not module.is_file():
                raise r.error("module", f"file not found: {module}")
            module, function = str(module), r.string("function")
        options = _options(r, model)
        spec = MechanismSpec(name, model, module, function, dict(options), {}, (), r.where)
        kinds = parameter_kinds(spec)
        p = r.table("parameters", {})
        params = {key: p.number(key, kinds.get(key)) for key in p.data}
        funcs = tuple(_position(n, t) for n, t in r.named_tables("position_functions").items())
        out[name] = MechanismSpec(name, model, module, function, dict(options), params, funcs,
                                  r.where, r.string("form", FORMS[0], choices=FORMS))
    return out


def _options(r: Reader, model: str | None) -> dict:
    """The ``options`` table: keyword arguments of the factory (names checked for the
    built-in models, with a "did you mean")."""
    options = r.get("options", {})
    if isinstance(options, dict) and model is not None:
        signature = inspect.signature(BUILTIN_MODELS[model])
        r.child("options", options).expect(*signature.parameters)
    if not isinstance(options, dict) or not all(
            isinstance(v, (str, int, bool)) for v in options.values()):
        raise r.error("options", f"expected a table of strings, integers or booleans, got"
                                 f" {show(options)}")
    return options


_POSITION_KEYS = {"cam": ("kind", "segments", "phi_start", "base"),
                  "slider_crank": ("kind", "r", "l", "e"),
                  "four_bar": ("kind", "a", "b", "c", "d", "branch", "output"),
                  "chapter_cam": ("kind", "name")}


def _position(name: str, r: Reader) -> PositionSpec:
    r.expect(*dict.fromkeys(k for keys in _POSITION_KEYS.values() for k in keys))
    kind = r.string("kind", choices=POSITION_KINDS)
    r.expect(*_POSITION_KEYS[kind], context=f"for kind = {kind!r}")
    if kind == "cam":
        segments = []
        for s in r.tables("segments"):
            s.expect("beta", "lift", "law")
            law = s.string("law", None, choices=MOTION_LAWS)
            lift = _lift(s)
            if lift != 0 and law is None:
                raise s.error("law", f"missing (required for a lift): one of {list(MOTION_LAWS)}")
            segments.append((s.number("beta", ANGLE, positive=True), lift, law))
        if not segments:
            raise r.error("segments", "missing (required): [[...segments]] with beta, lift, law")
        # the checks of femmech.mechanisms.CamProfile, here so that `check` makes them
        # for cams of user-code mechanisms too (which it does not build)
        total = sum(beta for beta, _, _ in segments)
        if abs(total - 2 * math.pi) > 1e-9:
            raise r.error("segments", f"the angles beta sum to {total:.12g} rad"
                                      f" ({math.degrees(total):.9g} deg), not one revolution")
        lifts = [lift for _, lift, _ in segments]
        if abs(sum(lifts)) > 1e-12 * max(1.0, max(abs(h) for h in lifts)):
            raise r.error("segments", f"the lifts sum to {sum(lifts):.6g}, not 0 (the cam"
                                      " would not return to its start after one revolution)")
        params = {"segments": tuple(segments), "phi_start": r.number("phi_start", ANGLE, 0.0),
                  "base": r.number("base", LENGTH, 0.0)}
    elif kind == "slider_crank":
        params = {k: r.number(k, LENGTH, 0.0 if k == "e" else None) for k in ("r", "l", "e")}
        if params["r"] is None or params["l"] is None:
            raise r.error("r" if params["r"] is None else "l", "missing (required)")
        if not params["r"] > 0:
            raise r.error("r", f"expected a positive crank radius, got {params['r']:g} m")
        if not params["l"] > params["r"] + abs(params["e"]):
            raise r.error("l", f"expected a coupler longer than r + |e| ="
                               f" {params['r'] + abs(params['e']):g} m (a fully rotating"
                               f" crank), got {params['l']:g} m")
    elif kind == "four_bar":
        params = {k: r.number(k, LENGTH, positive=True) for k in "abcd"}
        params["branch"] = r.integer("branch", 1, minimum=-1, maximum=1)
        if params["branch"] == 0:
            raise r.error("branch", "expected +1 or -1, got 0")
        params["output"] = r.string("output", "rocker", choices=("rocker", "coupler"))
        a, b, c, d = (params[k] for k in "abcd")
        if not (abs(b - c) < abs(d - a) and d + a < b + c):
            raise r.error(None, f"four-bar a={a:g}, b={b:g}, c={c:g}, d={d:g} m: the crank"
                                " cannot turn fully without a dead centre; need |b - c| <"
                                " |d - a| and d + a < b + c")
    else:
        params = {"name": r.string("name", choices=("U1", "U2"))}
    return PositionSpec(name, kind, params, r.where)


def _lift(s: Reader) -> float:
    from femmech.errors import SceneError

    value = s.get("lift", 0.0)
    for kind in (LENGTH, ANGLE):
        try:
            return s.convert("lift", value, kind)
        except SceneError:
            pass
    raise s.error("lift", "expected a length (translating follower, e.g. '30 mm') or an angle"
                          f" (rocker, e.g. '20 deg'), got {value!r}")


def read_mounts(root: Reader, parts: dict, mechanisms: dict) -> tuple:
    """All ``[[mounts]]`` → tuple of MountSpec (names of mechanism and part checked)."""
    out = []
    for r in root.tables("mounts"):
        r.expect("name", "mechanism", "part", "attachments", "ratio", "phase")
        mech = r.string("mechanism")
        if mech not in mechanisms:
            raise r.error("mechanism", f"expected one of the [mechanisms] {sorted(mechanisms)},"
                                       f" got {mech!r}")
        if mechanisms[mech].form != "rheolinear":
            raise r.error("mechanism", f"mechanism {mech!r} has form ="
                                       f" {mechanisms[mech].form!r}; a mounted mechanism needs"
                                       " form = 'rheolinear' (the default)")
        default_part = next(iter(parts)) if len(parts) == 1 else None
        part = r.string("part", default_part)
        if part not in parts:
            raise r.error("part", f"expected one of the [parts] {sorted(parts)}, got {part!r}")
        attachments = []
        for a in r.tables("attachments"):
            a.expect("coordinate", "node", "direction", "stiffness", "damping")
            direction = a.get("direction")
            if isinstance(direction, list):
                direction = a.vector("direction", (DIMENSIONLESS,) * 6)
                if not any(direction):
                    raise a.error("direction", "expected six weights, not all zero")
            elif direction not in COMPONENTS:
                raise a.error("direction", f"expected a component name {list(COMPONENTS)} or"
                                           f" six weights, got {show(direction)}")
            rotation = isinstance(direction, str) and direction.startswith("r")
            stiffness = a.number("stiffness", ROT_STIFFNESS if rotation else STIFFNESS, None,
                                 positive=True)
            damping = a.number("damping", ROT_DAMPING if rotation else DAMPING, 0.0,
                               non_negative=True)
            coordinate = a.string("coordinate")
            if coordinate in [att.coordinate for att in attachments]:
                raise a.error("coordinate", f"coordinate {coordinate!r} is attached twice in"
                                            " this mount")
            attachments.append(AttachmentSpec(coordinate, a.node_ref("node"), direction,
                                              stiffness, damping, a.where))
        if not attachments:
            raise r.error("attachments", "missing (required): at least one attachment")
        out.append(MountSpec(r.string("name", f"{mech}{len(out) + 1}"), mech, part,
                             tuple(attachments), r.number("ratio", DIMENSIONLESS, 1.0),
                             r.number("phase", ANGLE, 0.0), r.where))
    names = [m.name for m in out]
    for i, name in enumerate(names):
        if name in names[:i]:
            raise root.error(f"mounts[{i}].name", f"duplicate mount name {name!r}")
    return tuple(out)
