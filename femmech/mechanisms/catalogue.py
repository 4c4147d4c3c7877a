"""What the built-in mechanisms' coordinates and parameters mean: the one place for labels.

Every built-in mechanism factory (:mod:`.mounted`, :mod:`.chapter`) and the chain's
follower unit has an :class:`Entry` in :data:`CATALOGUE`: its coordinates (name,
meaning, SI unit, sign convention), its parameters (name, meaning, SI unit, default),
its position functions and its scene spelling. The factories attach the coordinate
meanings to the :class:`~femmech.mechanisms.symbolic.Mechanism` they return
(``Mechanism.labels``); tables and plots ask :func:`describe` for a readable name such
as ``"follower deformation [cam1.q]"`` (the raw name in brackets, as CSV columns spell
it). docs/mechanisms.md ("Reference of the built-in mechanisms") lists the same entries
and a test keeps the two equal.

Stage 2 (mechanisms, independent of fe): imports nothing of femmech.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["CATALOGUE", "Coordinate", "Entry", "Parameter", "coordinate_labels",
           "coordinate_unit", "describe", "readable"]


@dataclass(frozen=True)
class Coordinate:
    """A coordinate (or a derived quantity such as a drive force): name, what it is
    physically, SI unit and sign convention (empty for quantities without one)."""

    name: str
    meaning: str
    unit: str
    sign: str = ""


@dataclass(frozen=True)
class Parameter:
    """A parameter: default symbol name, meaning, SI unit, default value (text) and the
    factory option that renames it (empty when its name is fixed)."""

    name: str
    meaning: str
    unit: str
    default: str = "required"
    option: str = ""


@dataclass(frozen=True)
class Entry:
    """One built-in mechanism: ``call`` (the Python factory call), ``scene`` (its
    scene-file spelling), coordinates (drives marked by ``drives``), parameters,
    position functions, derived ``quantities`` (drive and spring forces of drive events)
    and the file name of its figure under docs/figures/."""

    call: str
    title: str
    scene: str
    coordinates: tuple[Coordinate, ...]
    parameters: tuple[Parameter, ...]
    position_functions: tuple[Parameter, ...] = ()
    drives: tuple[str, ...] = ("theta",)
    quantities: tuple[Coordinate, ...] = ()
    figure: str = ""

    def coordinate(self, name: str) -> Coordinate | None:
        """The coordinate or quantity called ``name``, None if there is none."""
        return next((c for c in self.coordinates + self.quantities if c.name == name), None)


_THETA = Coordinate("theta", "drive angle", "rad", "θ = Ωt, + in the drive's sense of rotation")
_CAM_U = Parameter("U", "cam lift over the cam angle ψ", "m", "required", "U")

_CAM_FOLLOWER = Entry(
    "cam_follower()", "Cam follower on an elastic shaft and frame (mounted)",
    'model = "cam_follower"',
    (Coordinate("q_s", "shaft twist at the cam", "rad",
                "+ with the drive; the cam turns at ψ = θ + q_s"),
     Coordinate("y_c", "cam-centre displacement", "m",
                "+ along the follower axis, in the sense of the lift"),
     Coordinate("y_f", "return-spring base displacement", "m", "+ as y_c"),
     Coordinate("q", "follower deformation", "m",
                "+ as y_c; follower position y = y_c + U(ψ) + q"),
     _THETA),
    (Parameter("m", "follower mass", "kg", option="m"),
     Parameter("c", "follower elasticity (spring on q)", "N/m", option="c"),
     Parameter("c_r", "return spring between follower and frame, on y − y_f", "N/m",
               option="c_return"),
     Parameter("b", "follower damping (on q)", "N·s/m", option="b"),
     Parameter("F", "process force, acting against y", "N", option="F"),
     Parameter("J", "rotary inertia of the cam", "kg·m²",
               "none: the FE shaft holds it (option J unset)", option="J")),
    (_CAM_U,), figure="cam_follower.png")

_SLIDER_CRANK = Entry(
    "slider_crank()", "Slider-crank with an elastic crankshaft, bearing and guide (mounted)",
    'model = "slider_crank"',
    (Coordinate("q_t", "crankshaft twist", "rad",
                "+ with the drive; the crank turns at ψ = θ + q_t"),
     Coordinate("u_b", "crank-bearing displacement along the slider axis", "m",
                "+ along s, the sense in which the slider position grows"),
     Coordinate("v_b", "crank-bearing displacement across the slider axis", "m",
                "+ along n, the in-plane normal to s towards the crank pin at ψ = 90°"),
     Coordinate("v_g", "guide displacement across the slider axis", "m",
                "+ along n; the guide line lies at n = e + v_g"),
     Coordinate("q", "output (rod and ram) deformation", "m",
                "+ along s; ram position x = s + q"),
     _THETA),
    (Parameter("m2", "ram mass", "kg", option="m"),
     Parameter("c2", "output elasticity, rod and ram in series, along s", "N/m", option="c"),
     Parameter("J1", "crank rotary inertia", "kg·m²", option="J"),
     Parameter("c1", "crankshaft torsional stiffness (on q_t)", "N·m/rad", option="c_t"),
     Parameter("b2", "output damping (on q)", "N·s/m", option="b"),
     Parameter("b1", "crankshaft damping (on q_t)", "N·m·s/rad", option="b_t"),
     Parameter("F2", "process force, acting against x", "N", option="F"),
     Parameter("r", "crank radius", "m"),
     Parameter("l", "connecting-rod length (l > r + |e|)", "m"),
     Parameter("e", "guide offset across the slider axis", "m")),
    figure="slider_crank.png")

_SHAFT = (Coordinate("q1", "twist of the drive shaft", "rad",
                     "+ with the drive; cam or linkage angle ψ = θ + q1"),
          Coordinate("q2", "follower-spring deflection", "m",
                     "+ with U; output position x2 = U(ψ) + q2"))
_CASE_1_PARAMETERS = (
    Parameter("J1", "drive-shaft inertia", "kg·m²"),
    Parameter("c1", "drive-shaft torsional stiffness", "N·m/rad"),
    Parameter("b1", "drive-shaft damping", "N·m·s/rad"),
    Parameter("m2", "output mass", "kg"),
    Parameter("c2", "follower stiffness", "N/m"),
    Parameter("b2", "follower damping", "N·s/m"))
_U = Parameter("U", "position function of the cam or linkage, over ψ", "m (or rad)")

_CASES = (
    Entry("table_5_1_case(1)", "Table 5.1 case 1: shaft, mechanism U, one output mass",
          'model = "table_5_1_case", options = {case = 1}', _SHAFT + (_THETA,),
          _CASE_1_PARAMETERS + (Parameter("F2", "process force against x2", "N"),), (_U,),
          figure="table_5_1_case_1.png"),
    Entry("table_5_1_case(2)", "Table 5.1 case 2: two-mass follower chain",
          'model = "table_5_1_case", options = {case = 2}',
          _SHAFT + (Coordinate("q3", "deflection of the second mass", "m",
                               "+ with U; x3 = U(ψ) + q3"), _THETA),
          _CASE_1_PARAMETERS + (Parameter("m3", "second follower mass", "kg"),
                                Parameter("c3", "spring between m2 and m3", "N/m"),
                                Parameter("b3", "damper between m2 and m3", "N·s/m"),
                                Parameter("F3", "process force on m3, against x3", "N")),
          (Parameter("U", "position function of the cam or linkage, over ψ", "m"),),
          figure="table_5_1_case_2.png"),
    Entry("table_5_1_case(3)", "Table 5.1 case 3: two mechanisms on one shaft",
          'model = "table_5_1_case", options = {case = 3}',
          _SHAFT + (Coordinate("q3", "deflection of the second output", "m",
                               "+ with U3; x3 = U3(ψ) + q3"), _THETA),
          _CASE_1_PARAMETERS + (Parameter("F2", "process force against x2", "N"),
                                Parameter("m3", "output mass of the second mechanism", "kg"),
                                Parameter("c3", "follower stiffness of the second mechanism",
                                          "N/m"),
                                Parameter("b3", "follower damping of the second mechanism",
                                          "N·s/m"),
                                Parameter("F3", "process force of the second mechanism, against"
                                                " x3", "N")),
          (Parameter("U2", "position function of the first mechanism (output m2)", "m"),
           Parameter("U3", "position function of the second mechanism (output m3)", "m")),
          figure="table_5_1_case_3.png"),
    Entry("table_5_1_case(4)", "Table 5.1 case 4: two mechanisms between elastic shafts",
          'model = "table_5_1_case", options = {case = 4}',
          (Coordinate("q1", "twist of input-shaft segment 1", "rad",
                      "+ with the drive; mechanism 2 input at θ + q1"),
           Coordinate("q2", "twist of input-shaft segment 2", "rad",
                      "+ with the drive; mechanism 3 input at θ + q1 + q2"),
           Coordinate("theta", "input-shaft drive angle", "rad", _THETA.sign)),
          (Parameter("J12", "input-shaft inertia at mechanism 2", "kg·m²"),
           Parameter("J13", "input-shaft inertia at mechanism 3", "kg·m²"),
           Parameter("J22", "output-shaft inertia at mechanism 2", "kg·m²"),
           Parameter("J23", "output-shaft inertia at mechanism 3", "kg·m²"),
           Parameter("c11", "input-shaft stiffness, segment 1", "N·m/rad"),
           Parameter("c12", "input-shaft stiffness, segment 2", "N·m/rad"),
           Parameter("c21", "output-shaft stiffness, segment 1", "N·m/rad"),
           Parameter("c22", "output-shaft stiffness, segment 2", "N·m/rad"),
           Parameter("b11", "input-shaft damping, segment 1", "N·m·s/rad"),
           Parameter("b12", "input-shaft damping, segment 2", "N·m·s/rad"),
           Parameter("b21", "output-shaft damping, segment 1", "N·m·s/rad"),
           Parameter("b22", "output-shaft damping, segment 2", "N·m·s/rad"),
           Parameter("T2", "output torque at mechanism 2, against its output angle", "N·m"),
           Parameter("T3", "output torque at mechanism 3, against its output angle", "N·m")),
          (Parameter("U", "position function of both mechanisms (output angle)", "rad"),),
          figure="table_5_1_case_4.png"),
)


def _machine_parameters(values: str) -> tuple[Parameter, ...]:
    rows = (("J0", "input inertia", "kg·m²"), ("J1", "shaft inertia at cam 1", "kg·m²"),
            ("J2", "shaft inertia at cam 2", "kg·m²"), ("m1", "follower mass 1", "kg"),
            ("m2", "follower mass 2", "kg"), ("cT1", "shaft stiffness J0–J1", "N·m/rad"),
            ("cT2", "shaft stiffness J1–J2", "N·m/rad"), ("c3", "follower elasticity 1", "N/m"),
            ("c4", "follower elasticity 2", "N/m"), ("c6", "return spring 1 (on y1)", "N/m"),
            ("c7", "return spring 2 (on y2)", "N/m"),
            ("bT1", "shaft damping J0–J1", "N·m·s/rad"),
            ("bT2", "shaft damping J1–J2", "N·m·s/rad"),
            ("b3", "follower damping 1", "N·s/m"), ("b4", "follower damping 2", "N·s/m"),
            ("F1", "process force on m1, against y1", "N"),
            ("F2", "process force on m2, against y2", "N"))
    return tuple(Parameter(n, m, u, values) for n, m, u in rows)


_MACHINE_COORDINATES = (
    Coordinate("q1", "drive shaft angle", "rad", "φ0, + in the drive's sense of rotation"),
    Coordinate("q2", "shaft twist 1 (J0–J1)", "rad", "+ with q1; cam 1 at φ1 = q1 + q2"),
    Coordinate("q3", "shaft twist 2 (J1–J2)", "rad", "+ with q1; cam 2 at φ2 = q1 + q2 + q3"),
    Coordinate("q4", "follower 1 deformation", "m", "+ with U1; y1 = U1(φ1) + q4"),
    Coordinate("q5", "follower 2 deformation", "m", "+ with U2; y2 = U2(φ2) + q5"))
_MACHINE_CAMS = (Parameter("U1", "cam on J1 (lift over φ1)", "m",
                           "illustrative: processing_machine_cams()"),
                 Parameter("U2", "cam on J2 (lift over φ2)", "m",
                           "illustrative: processing_machine_cams()"))
_M0 = Parameter("M0", "input torque on q1 (free drive only)", "N·m",
                "illustrative: processing_machine_parameters(kinematic_drive=False)")
_DRIVE_TORQUE = Coordinate("force q1", "drive torque", "N·m", "+ driving q1")

_MACHINES = (
    Entry("processing_machine()", "Processing machine, free drive (5 DOF)",
          'model = "processing_machine"', _MACHINE_COORDINATES,
          _machine_parameters("illustrative: processing_machine_parameters()") + (_M0,),
          _MACHINE_CAMS, drives=(), figure="processing_machine.png"),
    Entry("processing_machine(kinematic_drive=True)",
          "Processing machine, kinematic drive (4 DOF)",
          'model = "processing_machine", options = {kinematic_drive = true}',
          _MACHINE_COORDINATES,
          _machine_parameters("illustrative: processing_machine_parameters()"),
          _MACHINE_CAMS, drives=("q1",), quantities=(_DRIVE_TORQUE,),
          figure="processing_machine.png"),
    Entry("processing_machine_mixed()", "Processing machine in mixed form (7 coordinates)",
          "(not a scene model; Python only)",
          _MACHINE_COORDINATES + (
              Coordinate("q6", "redundant cam-1 lift x1", "m", "constraint q6 = U1(q1 + q2)"),
              Coordinate("q7", "redundant cam-2 lift x2", "m",
                         "constraint q7 = U2(q1 + q2 + q3)")),
          _machine_parameters("illustrative: processing_machine_parameters()") + (_M0,),
          _MACHINE_CAMS, drives=(), figure="processing_machine.png"),
)

_CRANE_VALUES = "illustrative: mobile_crane_parameters()"
_CRANE = Entry(
    "mobile_crane()", "Mobile crane with luffing cylinder and load pendulum",
    'model = "mobile_crane"  # drive events: form = "second_kind"',
    (Coordinate("q1", "chassis heave", "m", "y_S2 − y_20, + up"),
     Coordinate("q2", "chassis pitch", "rad",
                "φ2, + counter-clockwise (x right, y up): the boom angle β = φ3 + q2 grows"),
     Coordinate("q3", "pendulum angle", "rad",
                "φ5, space-fixed from the downward vertical, + swings the load towards −x"),
     Coordinate("q4", "cylinder length", "m", "s4, + lengthens the cylinder (boom up)")),
    tuple(Parameter(n, m, u, _CRANE_VALUES) for n, m, u in (
        ("m2", "chassis mass", "kg"), ("m3", "boom mass", "kg"), ("m5", "load mass", "kg"),
        ("JS2", "chassis inertia about its CG", "kg·m²"),
        ("JS3", "boom inertia about its CG", "kg·m²"),
        ("JS5", "load inertia about its CG", "kg·m²"),
        ("x23", "horizontal position of the boom pivot", "m"),
        ("xi23", "horizontal offset of the boom pivot from the chassis reference", "m"),
        ("eta23", "height of the boom pivot above the chassis reference", "m"),
        ("rS3", "boom pivot to boom CG", "m"),
        ("rS5", "rope length, boom tip to load CG", "m"),
        ("r24", "cylinder base to boom pivot", "m"),
        ("r34", "boom pivot to cylinder head", "m"),
        ("r25", "boom pivot to boom tip", "m"),
        ("alpha", "angle between the pivot–boom-CG and pivot–tip lines", "rad"),
        ("gamma", "offset of the boom angle φ3 in the cylinder triangle", "rad"),
        ("c", "tyre (axle) stiffness, each axle", "N/m"),
        ("l1", "front axle to chassis reference", "m"),
        ("l2", "rear axle to chassis reference", "m"),
        ("g", "gravity", "m/s²"))),
    drives=("q4",),
    quantities=(Coordinate("force q4", "cylinder force", "N", "+ pushes the cylinder longer"),
                Coordinate("spring1", "front axle force", "N", "tension +"),
                Coordinate("spring2", "rear axle force", "N", "tension +")),
    figure="mobile_crane.png")

_FOLLOWER_UNIT = Entry(
    "follower_unit(cam, inertia, mass, stiffness)",
    "Chain follower unit (femmech.chain.follower_unit)",
    '[chain.unit] kind = "cam_follower"',
    (Coordinate("q1", "shaft rotation at the unit's node", "rad",
                "+ with the drive; the chain's node rotation"),
     Coordinate("q2", "follower deflection", "m", "+ with U; x2 = U(ψ) + q2")),
    (Parameter("inertia", "cam-hub rotary inertia about the shaft", "kg·m²", "required",
               "inertia"),
     Parameter("mass", "follower mass", "kg", "required", "mass"),
     Parameter("stiffness", "follower-train stiffness", "N/m", "required", "stiffness"),
     Parameter("damping", "follower-train damping", "N·s/m", "0", "damping"),
     Parameter("force", "process force against x2", "N", "0", "force"),
     Parameter("c_g", "spring from follower to ground (return spring) on x2", "N/m", "0",
               "ground_stiffness")),
    (Parameter("cam", "cam programme U(ψ) ([chain.unit.cam])", "m", "required", "cam"),),
    drives=(), figure="follower_unit.png")

CATALOGUE: dict[str, Entry] = {e.call: e for e in (_CAM_FOLLOWER, _SLIDER_CRANK, *_CASES,
                                                   *_MACHINES, _CRANE, _FOLLOWER_UNIT)}
"""Every built-in mechanism by its factory call (``"table_5_1_case(2)"``)."""


def coordinate_labels(call: str) -> tuple[tuple[str, str], ...]:
    """(coordinate name, meaning) pairs of the catalogue entry ``call``, for
    ``Mechanism(labels=...)``."""
    return tuple((c.name, c.meaning) for c in CATALOGUE[call].coordinates)


def readable(meaning: str, name: str) -> str:
    """The readable name of a quantity: ``"meaning [name]"``, or ``name`` alone when the
    meaning is empty or the name itself."""
    return f"{meaning} [{name}]" if meaning and meaning != name else name


def describe(model, name: str, prefix: str = "") -> str:
    """Readable name of coordinate ``name`` of ``model`` (a Mechanism, or any model with a
    ``mechanism``), e.g. ``describe(model, "y_f", "cam1.")`` → ``"return-spring base
    displacement [cam1.y_f]"``; the raw ``prefix + name`` where the mechanism says nothing
    about it (user mechanisms without labels)."""
    return readable(_meaning(model, name) or "", prefix + name)


def _meaning(model, name: str) -> str | None:
    """The meaning the mechanism of ``model`` gives coordinate ``name`` (its ``labels``),
    None if it gives none."""
    mechanism = getattr(model, "mechanism", model)
    return dict(getattr(mechanism, "labels", ())).get(name)


def coordinate_unit(model, name: str) -> str:
    """SI unit of coordinate ``name`` of ``model`` (a Mechanism, or a model with a
    ``mechanism``): that of the catalogue coordinate with the same name and meaning
    (``"m"``, ``"rad"``); ``""`` where the mechanism's labels do not say (user mechanisms)."""
    meaning = _meaning(model, name)
    if meaning is None:
        return ""
    units = {c.unit for e in CATALOGUE.values() for c in e.coordinates
             if c.name == name and c.meaning == meaning}
    return units.pop() if len(units) == 1 else ""


def _anchor(heading: str) -> str:
    """GitHub's anchor of a heading (lower case, punctuation dropped, spaces to hyphens)."""
    return "".join(ch for ch in heading.lower() if ch.isalnum() or ch in "_- ").replace(" ", "-")


def _heading(entry: Entry) -> str:
    return entry.title


def _table(header: tuple, rows) -> list[str]:
    return ["| " + " | ".join(header) + " |", "|" + "---|" * len(header),
            *("| " + " | ".join(row) + " |" for row in rows)]


def reference_markdown() -> str:
    """The reference section of docs/mechanisms.md (between its ``mechanism-reference``
    markers) rendered from :data:`CATALOGUE`: an index, then per mechanism its scene
    spelling, figure and the tables of coordinates, parameters, position functions and
    derived quantities. tests/test_mechanism_reference.py checks the page against it."""
    entries = list(CATALOGUE.values())
    lines = [f"- [{e.call}](#{_anchor(_heading(e))})" for e in entries] + [""]
    for e in entries:
        lines += [f"### {_heading(e)}", "", f"Python: `femmech.mechanisms.{e.call}`"
                  if not e.call.startswith("follower_unit") else
                  f"Python: `femmech.chain.{e.call}`", "",
                  f"Scene file: `{e.scene}`" if e.scene.startswith(("model", "[")) else
                  f"Scene file: {e.scene}", "",
                  f"![{e.call}](figures/{e.figure})", ""]
        lines += _table(("coordinate", "meaning", "unit", "sign convention"),
                        ((f"`{c.name}`" + (" (drive)" if c.name in e.drives else ""),
                          c.meaning, c.unit, c.sign) for c in e.coordinates)) + [""]
        lines += _table(("parameter", "scene option", "meaning", "unit", "default"),
                        ((f"`{p.name}`", f"`{p.option}`" if p.option else "–", p.meaning,
                          p.unit, p.default) for p in e.parameters)) + [""]
        if e.position_functions:
            lines += _table(("position function", "scene option", "meaning", "unit",
                             "default"),
                            ((f"`{p.name}`", f"`{p.option}`" if p.option else "–",
                              p.meaning, p.unit, p.default)
                             for p in e.position_functions)) + [""]
        if e.quantities:
            lines += _table(("drive-event quantity", "meaning", "unit", "sign convention"),
                            ((f"`{c.name}`", c.meaning, c.unit, c.sign)
                             for c in e.quantities)) + [""]
    return "\n".join(lines).rstrip() + "\n"
