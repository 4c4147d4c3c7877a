"""Engineering number formatting of the report (femmech.output.formatting)."""

import math

import numpy as np
import pytest

from femmech.output.formatting import Quantity, format_value, is_flagged
from femmech.output.report import Flagged, Table, render_table


@pytest.mark.parametrize(("value", "kwargs", "text"), [
    # float artefacts never show: decimal rounding to 4 significant digits
    (0.1 + 0.2, {}, "0.3000"),
    (0.1 + 0.2, {"trim": True}, "0.3"),
    (0.35000000000000003, {"unit": "m", "trim": True}, "0.35 m"),
    # integers stay integers, whatever their size
    (1128, {}, "1128"),
    (np.int64(-7), {"unit": "nodes"}, "-7 nodes"),
    (12345678901234, {}, "12345678901234"),
    # zero, negative zero, negatives
    (0.0, {"unit": "kg"}, "0 kg"),
    (-0.0, {}, "0"),
    (-12.3456, {}, "-12.35"),
    # trailing zeros kept: a column shows its precision
    (65.1, {}, "65.10"),
    (4.91371, {}, "4.914"),
    # rounding carries into the next decade
    (9.9996, {}, "10.00"),
    (999.96, {}, "1000"),
    (9999.6, {}, "10.00e3"),
    # plain notation from 1e-3 up to 10**digits, engineering exponents outside
    (0.0012345, {}, "0.001234"),
    (0.00012345, {}, "123.4e-6"),
    (12345.6, {"unit": "kg"}, "12.35e3 kg"),
    (-2.5e-5, {"unit": "kg"}, "-25.00e-6 kg"),
    (1e-300, {}, "1.000e-300"),
    (1.7976931348623157e308, {}, "179.8e306"),
    (123456.0, {"digits": 6}, "123456"),
    (1234567.0, {"digits": 6}, "1.23457e6"),
    # SI prefixes for the units that take them, not for kg, m, Hz
    (210e9, {"unit": "Pa", "trim": True}, "210 GPa"),
    (80.769e9, {"unit": "Pa"}, "80.77 GPa"),
    (3e5, {"unit": "N/m", "trim": True}, "300 kN/m"),
    (0.017, {"unit": "s"}, "17.00 ms"),
    (29.791, {"unit": "s"}, "29.79 s"),
    (3600.0, {"unit": "s"}, "3600 s"),
    (7850.0, {"unit": "kg/m³"}, "7850 kg/m³"),
    (1500.0, {"unit": "Hz"}, "1500 Hz"),
    (1e13, {"unit": "Pa"}, "10.00e12 Pa"),  # no tera: exponent instead
    (0.5, {"unit": "Pa"}, "0.5000 Pa"),  # no milli for Pa
    # other digit counts
    (8.2e-6, {"digits": 2}, "8.2e-6"),
    (2.0 / 3.0, {"digits": 1}, "0.7"),
    (640.0, {"digits": 1}, "600"),
    (64000.0, {"digits": 1}, "60e3"),
])
def test_format_value(value, kwargs, text):
    assert format_value(value, **kwargs) == text


def test_non_finite_values_are_flagged_and_shown_without_unit():
    assert format_value(math.nan, "kg") == "nan"
    assert format_value(np.inf) == "inf"
    assert format_value(-np.inf, "Hz") == "-inf"
    assert is_flagged(np.nan)
    assert is_flagged(np.float32("inf"))
    assert not is_flagged(1.0)
    assert not is_flagged(3)
    assert Quantity(np.nan, "kg").flagged
    html = render_table(Table("t", ("a", "b", "c"), ((np.nan, Quantity(-np.inf, "s"),
                                                       Flagged("x")),)))
    assert html.count('class="flagged num"') == 2
    assert '<td class="flagged">x</td>' in html


def test_bad_arguments():
    with pytest.raises(TypeError, match="real number"):
        format_value("1.0")
    with pytest.raises(TypeError, match="real number"):
        format_value(True)
    with pytest.raises(ValueError, match="digits"):
        format_value(1.0, digits=0)


def test_every_float_in_a_table_goes_through_format_value():
    rows = ((1, 0.1 + 0.2, np.float64(12345.678), Quantity(210e9, "Pa", trim=True), "text"),)
    html = render_table(Table("t", ("i", "x", "y", "E", "s"), rows))
    assert '<td class="num">1</td>' in html
    assert '<td class="num">0.3000</td>' in html
    assert '<td class="num">12.35e3</td>' in html
    assert '<td class="num">210 GPa</td>' in html
    assert "<td>text</td>" in html
    assert "0.30000000000000004" not in html


def test_random_values_round_trip_to_their_significant_digits():
    # the text, read back, equals the value rounded to 4 significant digits
    rng = np.random.default_rng(7)
    values = rng.standard_normal(500) * 10.0 ** rng.integers(-12, 13, 500)
    for v in values:
        text = format_value(float(v))
        # bound: the formatter's text against the same 4-digit rounding: a few eps
        assert float(text) == pytest.approx(float(f"{v:.3e}"), rel=1e-12), (v, text)
        mantissa = text.split("e")[0].lstrip("-").replace(".", "").lstrip("0")
        assert len(mantissa) == 4 or float(text) == 0, (v, text)
