"""The table of chapter symbols in docs/mechanisms.md matches the built-in models.

Every femmech name of the table must exist in its model (a parameter of the symbolic
mechanism and of the parameter dict for the crane and the processing machine, a
coordinate, the drive, or a position function), and every parameter and coordinate of
every model must be in the table (cases 2 and 3 inherit case 1's rows), so the table
can neither name something that is not there nor miss something that is.
"""

import re
from pathlib import Path

import pytest
import sympy

from femmech.mechanisms import (
    mobile_crane,
    mobile_crane_parameters,
    processing_machine,
    processing_machine_cams,
    processing_machine_mixed,
    processing_machine_parameters,
    table_5_1_case,
)

DOC = Path(__file__).resolve().parents[2] / "docs" / "mechanisms.md"
MODELS = {"T5.1-1": table_5_1_case(1), "T5.1-2": table_5_1_case(2),
          "T5.1-3": table_5_1_case(3), "T5.1-4": table_5_1_case(4),
          "crane": mobile_crane(), "machine": processing_machine(),
          "machine-mixed": processing_machine_mixed()}
VALUES = {"crane": mobile_crane_parameters(),
          "machine": processing_machine_parameters(kinematic_drive=False)}
INHERITS = {"T5.1-2": "T5.1-1", "T5.1-3": "T5.1-1", "machine-mixed": "machine"}
UNITS = re.compile(r"^(-|rad|m|kg|N|s|/|·|²|\(|\)| |or|, )+$")


def _rows():
    text = DOC.read_text(encoding="utf-8")
    block = text.split("<!-- symbol-table:start -->")[1].split("<!-- symbol-table:end -->")[0]
    rows = []
    for line in block.strip().splitlines()[2:]:  # header and rule
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        assert len(cells) == 6, line
        model, _, name, kind, unit, meaning = cells
        assert re.fullmatch(r"`\w+`", name), line
        rows.append((model, name.strip("`"), kind, unit, meaning))
    return rows


def _position_functions(mech):
    exprs = [x for el in mech.elements for x in vars(el).values()] + list(mech.constraints)
    flat = [y for x in exprs for y in (x if isinstance(x, tuple) else (x,))]
    return {getattr(f, "position_name", None) for e in flat
            for f in sympy.sympify(e).atoms(sympy.Function)} - {None}


def _names(mech, kind):
    if kind == "param":
        return {s.name for s in mech.parameters}
    if kind == "coord":
        return {q.name for q in mech.coordinates if q not in mech.drives}
    if kind == "drive":
        return {q.name for q in mech.drives}
    if kind == "posfn":
        return _position_functions(mech)
    raise AssertionError(f"unknown kind {kind!r}")


def test_every_listed_name_exists():
    rows = _rows()
    assert len(rows) > 80
    for model, name, kind, unit, meaning in rows:
        mech = MODELS[model]
        assert name in _names(mech, kind), (model, name, kind)
        if kind == "param" and model in VALUES:
            assert name in VALUES[model], (model, name)
        assert UNITS.match(unit), (model, name, unit)
        assert meaning


@pytest.mark.parametrize("model", sorted(MODELS))
def test_every_model_name_is_listed(model):
    listed = {(n, k) for m, n, k, _, _ in _rows() if m in (model, INHERITS.get(model))}
    mech = MODELS[model]
    for kind in ("param", "coord", "drive", "posfn"):
        names = _names(mech, kind)
        missing = {n for n in names if (n, kind) not in listed}
        assert not missing, (model, kind, sorted(missing))


def test_parameter_dicts_are_covered():
    listed = {n for m, n, k, _, _ in _rows() if k == "param"}
    for values in VALUES.values():
        assert set(values) <= listed
    assert set(processing_machine_cams()) <= {n for m, n, k, _, _ in _rows() if k == "posfn"}
