"""Engineering number formatting for reports: a value, its unit, fixed significant digits.

One function, :func:`format_value`, turns every number of the report into text:

* integers (Python and numpy integers) stay integers: ``1128``, ``-3``;
* other numbers get ``digits`` significant digits (default 4), decimal rounding of the
  value's shortest representation, so no binary artefacts (``0.30000000000000004`` →
  ``0.3000``); trailing zeros are kept so that a column shows its precision
  (``65.10 Hz`` under ``4.914 Hz``), ``trim=True`` drops them (input values: ``0.3``,
  ``210 GPa``);
* plain notation for ``1e-3 <= |x| < 10**digits``; outside, engineering notation with an
  exponent that is a multiple of 3: ``12.35e3``, ``250.0e-6``;
* SI prefixes only for the units of :data:`PREFIXES`, and only the prefixes listed there
  (``210 GPa``, ``800 kN/m``, ``17.00 ms``). Masses stay in kg and densities in kg/m³
  (``7850 kg/m³``, ``12.35e3 kg``), lengths in m and frequencies in Hz: the units in which
  engineers compare these numbers;
* zero is ``0``; NaN and infinities are ``nan``, ``inf``, ``-inf`` without the unit:
  :func:`is_flagged` tells the report to highlight them.

:class:`Quantity` carries a value with its unit and digits into a report table cell
(:func:`femmech.output.report.render_table` formats bare floats with the defaults).

Imports nothing of femmech.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from numbers import Integral, Real

PREFIXES = {
    "Pa": "kMG",
    "N": "kM",
    "N/m": "kMG",
    "N·m": "kM",
    "N·m/rad": "kMG",
    "J": "kM",
    "W": "kM",
    "s": "mµn",
}
"""Units that take SI prefixes in reports, with the prefixes they may take."""

_POWERS = {"n": -9, "µ": -6, "m": -3, "k": 3, "M": 6, "G": 9}


def is_flagged(value) -> bool:
    """True for NaN and infinities (real numbers only): the report highlights them."""
    return (isinstance(value, Real) and not isinstance(value, Integral)
            and not math.isfinite(float(value)))


def format_value(value, unit: str = "", digits: int = 4, trim: bool = False) -> str:
    """Text of ``value`` with its ``unit``: see the module docstring for the rules.

    Parameters
    ----------
    value : int, float or numpy scalar
    unit : str
        Appended after a space (``"kg/m³"``); prefixed if it is in :data:`PREFIXES`.
    digits : int
        Significant digits of non-integer values (>= 1).
    trim : bool
        Drop trailing zeros of the decimals.

    Examples
    --------
    >>> format_value(210e9, "Pa", trim=True), format_value(0.1 + 0.2)
    ('210 GPa', '0.3000')
    >>> format_value(7850.0, "kg/m³"), format_value(-2.5e-5, "kg"), format_value(1128)
    ('7850 kg/m³', '-25.00e-6 kg', '1128')
    """
    if isinstance(digits, bool) or not isinstance(digits, Integral) or digits < 1:
        raise ValueError(f"digits must be a positive integer, got {digits!r}")
    if isinstance(value, bool) or not isinstance(value, Real):
        raise TypeError(f"format_value expects a real number, got {type(value).__name__}"
                        f" {value!r}")
    if isinstance(value, Integral):
        text = str(int(value))
    else:
        x = float(value)
        if not math.isfinite(x):  # no unit: the value is no quantity
            return "nan" if math.isnan(x) else ("inf" if x > 0 else "-inf")
        if x == 0.0:
            text = "0"
        else:
            text, unit = _real_text(x, unit, int(digits), trim)
    return f"{text} {unit}" if unit else text


def _real_text(x: float, unit: str, digits: int, trim: bool) -> tuple[str, str]:
    """Text of a finite non-zero x and the unit with its prefix."""
    mantissa, exp = f"{abs(x):.{digits - 1}e}".split("e")  # decimal rounding, exact
    figures, exp = mantissa.replace(".", ""), int(exp)  # |x| ≈ d.ddd · 10^exp
    eng = 3 * math.floor(exp / 3)
    prefix = next((p for p, n in _POWERS.items() if n == eng), None)
    suffix = ""
    if eng != 0 and prefix is not None and prefix in PREFIXES.get(unit, ""):
        text, unit = _place(figures, exp - eng), prefix + unit
    elif -3 <= exp < digits or eng == 0:
        text = _place(figures, exp)
    else:
        text, suffix = _place(figures, exp - eng), f"e{eng}"
    if trim and "." in text:
        text = text.rstrip("0").rstrip(".")
    return ("-" if x < 0 else "") + text + suffix, unit


def _place(figures: str, exp: int) -> str:
    """The digits ``figures`` (d.ddd × 10^exp) as a decimal string, without exponent."""
    point = exp + 1
    if point <= 0:
        return "0." + "0" * -point + figures
    if point >= len(figures):
        return figures + "0" * (point - len(figures))
    return figures[:point] + "." + figures[point:]


@dataclass(frozen=True)
class Quantity:
    """A number for a report table cell, formatted by :func:`format_value`.

    Attributes
    ----------
    value : int or float
    unit : str
    digits : int
    trim : bool
    """

    value: object
    unit: str = ""
    digits: int = 4
    trim: bool = False

    def __str__(self) -> str:
        return format_value(self.value, self.unit, self.digits, self.trim)

    @property
    def flagged(self) -> bool:
        """NaN or infinite: highlighted in the report."""
        return is_flagged(self.value)
