"""Quantities with units for scene files: ``"210 GPa"`` → 2.1e11 (SI), dimension-checked.

A quantity is a plain number (taken as SI: m, kg, s, N, Pa, rad) or a string of a number
and a unit expression: unit names from :data:`UNITS`, joined by ``*`` (or a space, or
``·``) and ``/``, each with an optional integer power from -9 to 9 (``m^2``, ``m2``, ``s^-1``):
``"7850 kg/m^3"``, ``"2e4 N*m/rad"``, ``"1200 rpm"``, ``"90 deg"``.

Dimensions are exponents of (kg, m, s, rad). The radian is kept as its own dimension so
that an angular speed (rad/s, rpm) is never confused with a frequency (Hz = 1/s), which
differ by 2π; a rotational stiffness is therefore written ``N*m/rad``.

Stage 8 (scene), reading: imports nothing of femmech.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

Dimension = tuple[int, int, int, int]
"""Exponents of kg, m, s, rad."""


@dataclass(frozen=True)
class Kind:
    """An expected physical dimension, with a name and an example for error messages."""

    name: str
    dimension: Dimension
    example: str


def _dim(kg=0, m=0, s=0, rad=0) -> Dimension:
    return (kg, m, s, rad)


_N = _dim(kg=1, m=1, s=-2)
UNITS: dict[str, tuple[float, Dimension]] = {
    "m": (1.0, _dim(m=1)), "mm": (1e-3, _dim(m=1)), "cm": (1e-2, _dim(m=1)),
    "km": (1e3, _dim(m=1)),
    "kg": (1.0, _dim(kg=1)), "g": (1e-3, _dim(kg=1)), "t": (1e3, _dim(kg=1)),
    "s": (1.0, _dim(s=1)), "ms": (1e-3, _dim(s=1)), "min": (60.0, _dim(s=1)),
    "N": (1.0, _N), "kN": (1e3, _N), "MN": (1e6, _N),
    "Pa": (1.0, _dim(kg=1, m=-1, s=-2)), "kPa": (1e3, _dim(kg=1, m=-1, s=-2)),
    "MPa": (1e6, _dim(kg=1, m=-1, s=-2)), "GPa": (1e9, _dim(kg=1, m=-1, s=-2)),
    "Hz": (1.0, _dim(s=-1)), "kHz": (1e3, _dim(s=-1)),
    "rad": (1.0, _dim(rad=1)), "deg": (math.pi / 180.0, _dim(rad=1)),
    "rev": (2 * math.pi, _dim(rad=1)), "rpm": (2 * math.pi / 60.0, _dim(s=-1, rad=1)),
}

LENGTH = Kind("a length", _dim(m=1), "'30 mm'")
AREA = Kind("an area", _dim(m=2), "'12 cm^2'")
SECOND_MOMENT = Kind("a second moment of area", _dim(m=4), "'8e-6 m^4'")
MASS = Kind("a mass", _dim(kg=1), "'150 kg'")
TIME = Kind("a time", _dim(s=1), "'0.5 s'")
FORCE = Kind("a force", _N, "'2 kN'")
MOMENT = Kind("a moment", _dim(kg=1, m=2, s=-2), "'20 N*m'")
PRESSURE = Kind("a pressure or modulus", _dim(kg=1, m=-1, s=-2), "'210 GPa'")
DENSITY = Kind("a density", _dim(kg=1, m=-3), "'7850 kg/m^3'")
INERTIA = Kind("a rotary inertia", _dim(kg=1, m=2), "'4 kg*m^2'")
STIFFNESS = Kind("a stiffness", _dim(kg=1, s=-2), "'3e5 N/m'")
ROT_STIFFNESS = Kind("a rotational stiffness", _dim(kg=1, m=2, s=-2, rad=-1), "'2e4 N*m/rad'")
DAMPING = Kind("a damping coefficient", _dim(kg=1, s=-1), "'70 N*s/m'")
ROT_DAMPING = Kind("a rotational damping coefficient", _dim(kg=1, m=2, s=-1, rad=-1),
                   "'0.2 N*m*s/rad'")
FREQUENCY = Kind("a frequency", _dim(s=-1), "'400 Hz'")
ANGLE = Kind("an angle", _dim(rad=1), "'90 deg'")
SPEED = Kind("an angular speed", _dim(s=-1, rad=1), "'1200 rpm' or '125 rad/s'")
LINEAR_SPEED = Kind("a linear speed", _dim(m=1, s=-1), "'0.1 m/s'")
ACCELERATION = Kind("an acceleration", _dim(m=1, s=-2), "'9.81 m/s^2'")
INVERSE_TIME = Kind("a rate", _dim(s=-1), "'2 1/s'")
DIMENSIONLESS = Kind("a plain number", _dim(), "0.3")

KINDS = (LENGTH, AREA, SECOND_MOMENT, MASS, TIME, FORCE, MOMENT, PRESSURE, DENSITY, INERTIA,
         STIFFNESS, ROT_STIFFNESS, DAMPING, ROT_DAMPING, FREQUENCY, ANGLE, SPEED, LINEAR_SPEED,
         ACCELERATION, DIMENSIONLESS)

_NUMBER = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$")
_FACTOR = re.compile(r"^([A-Za-z]+)(?:\^?(-?\d))?$")  # powers -9..9
MAX_TEXT = 200
"""Longest quantity string, characters (``"7850 kg/m^3"``): longer ones are refused before
they are parsed."""


def parse_unit(text: str) -> tuple[float, Dimension]:
    """Factor to SI and dimension of a unit expression such as ``"N*m/rad"``.

    Raises ValueError naming an unknown unit.
    """
    expr = text.replace("·", "*").strip()
    factor, dim = 1.0, [0, 0, 0, 0]
    for k, side in enumerate(expr.split("/")):
        tokens = [t for t in re.split(r"[*\s]+", side) if t]
        if not tokens or (k > 0 and tokens == ["1"]):
            raise ValueError(f"malformed unit {text!r}")
        for token in tokens:
            if token == "1" and k == 0:
                continue
            match = _FACTOR.match(token)
            if not match or match.group(1) not in UNITS:
                raise ValueError(f"unknown unit {token!r}; known units: {', '.join(UNITS)}")
            power = (1 if k == 0 else -1) * int(match.group(2) or 1)
            f, d = UNITS[match.group(1)]
            factor *= f ** power
            dim = [a + power * b for a, b in zip(dim, d, strict=True)]
    return factor, tuple(dim)


def describe(dimension: Dimension) -> str:
    """Name of a dimension (``"a stiffness"``) or its exponents of kg, m, s, rad."""
    for kind in KINDS:
        if kind.dimension == dimension:
            return kind.name
    names = [f"{b}^{e}" for b, e in zip(("kg", "m", "s", "rad"), dimension, strict=True) if e]
    return " ".join(names) or "dimensionless"


def quantity(value, kind: Kind | None) -> float:
    """SI value of a plain number or a ``"number unit"`` string of the dimension ``kind``.

    ``kind=None`` accepts any known unit (a parameter of unknown dimension) and converts
    it to SI. Booleans are not numbers here.

    Raises
    ------
    TypeError
        For anything but a number or a string.
    ValueError
        For a malformed string, an unknown unit or a unit of another dimension; the
        message says what was expected.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise TypeError(_expected(kind))
    if not isinstance(value, str):
        try:
            out = float(value)
        except OverflowError:  # an integer beyond the float range
            raise ValueError(f"{_expected(kind)}; the value is not finite") from None
    else:
        if len(value) > MAX_TEXT:
            raise ValueError(f"{_expected(kind)}; longer than {MAX_TEXT} characters")
        match = _NUMBER.match(value)
        if not match:
            raise ValueError(_expected(kind))
        number, unit = float(match.group(1)), match.group(2)
        if not unit:
            out = number
        else:
            try:
                factor, dim = parse_unit(unit)
            except ValueError as exc:
                raise ValueError(f"{_expected(kind)}; {exc}") from None
            if kind is not None and dim != kind.dimension:
                raise ValueError(f"{_expected(kind)}; unit {unit!r} is {describe(dim)}")
            out = number * factor  # float product: overflows to inf, tested below
    if not math.isfinite(out):
        raise ValueError(f"{_expected(kind)}; the value is not finite")
    return out


def _expected(kind: Kind | None) -> str:
    if kind is None:
        return "expected a number or a string like '3 kg'"
    return f"expected {kind.name} (a number in SI units or a string like {kind.example})"
