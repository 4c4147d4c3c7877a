"""docs/mechanisms.md lists every built-in mechanism, its coordinates and its parameters.

The list of mechanisms is introspected from the code (the factories of
femmech.mechanisms.mounted and .chapter, the scene's BUILTIN_MODELS, the chain's
follower unit), and so are their coordinates and parameters (the symbols of the
Mechanism each factory returns), so a new mechanism, coordinate or parameter without
documentation turns these tests red. The readable names that tables and plots use
come from the same catalogue as the page.
"""

from __future__ import annotations

import importlib.util
import inspect
import re
from pathlib import Path

import pytest
import sympy

import femmech.mechanisms.chapter as chapter
import femmech.mechanisms.mounted as mounted
from femmech.chain import follower_unit
from femmech.mechanisms import Mechanism, cam_follower, cam_program, mobile_crane
from femmech.mechanisms.catalogue import CATALOGUE, describe, readable, reference_markdown
from femmech.scene.machine import BUILTIN_MODELS, QUANTITIES, catalogue_entry

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "mechanisms.md"
START, END = "<!-- mechanism-reference:start -->", "<!-- mechanism-reference:end -->"


def _calls(name: str, factory) -> dict[str, str]:
    """Every variant of a factory, catalogue key → the call that builds it: each valid
    value of a required integer argument (``table_5_1_case(1)`` … until ValueError),
    each value of a boolean option; options that default to None (an optional element,
    ``cam_follower(J=...)``) are set to their own name, so the element's parameter is in."""
    sig = inspect.signature(factory)
    required = [p for p in sig.parameters.values() if p.default is inspect.Parameter.empty]
    if required:
        calls = {}
        for k in range(1, 20):
            try:
                factory(k)
            except ValueError:
                break
            calls[f"{name}({k})"] = f"{name}({k})"
        assert calls, name
        return calls
    flags = [p.name for p in sig.parameters.values() if isinstance(p.default, bool)]
    extra = ", ".join(f"{p.name}={p.name!r}" for p in sig.parameters.values()
                      if p.default is None)
    calls = {f"{name}()": f"{name}({extra})"}
    for flag in flags:
        calls[f"{name}({flag}={not sig.parameters[flag].default})"] = \
            f"{name}({flag}={not sig.parameters[flag].default})"
    return calls


def builtin_mechanisms() -> dict[str, Mechanism]:
    """Catalogue key → Mechanism, for every public factory that returns a Mechanism."""
    found = {}
    for module in (mounted, chapter):
        for name in module.__all__:
            factory = getattr(module, name)
            if inspect.signature(factory).return_annotation not in ("Mechanism", Mechanism):
                continue  # parameter and cam dictionaries
            for key, call in _calls(name, factory).items():
                found[key] = eval(call, vars(module))  # noqa: S307 - our own call strings
    return found


def _position_functions(mech: Mechanism) -> set[str]:
    exprs = [x for el in mech.elements for x in vars(el).values()] + list(mech.constraints)
    flat = [y for x in exprs for y in (x if isinstance(x, tuple) else (x,))]
    return {getattr(f, "position_name", None) for e in flat
            for f in sympy.sympify(e).atoms(sympy.Function)} - {None}


def _sections(text: str) -> dict[str, str]:
    """Python call → its section of the reference block (from its ``Python:`` line)."""
    block = text.split(START)[1].split(END)[0]
    out = {}
    for section in block.split("\n### ")[1:]:
        match = re.search(r"^Python: `femmech\.(?:mechanisms|chain)\.(.+)`$", section, re.M)
        assert match, section[:80]
        out[match.group(1)] = section
    return out


def _rows(section: str, first_header: str) -> list[str]:
    """The backticked names of the first column of the table headed ``first_header``."""
    lines = section.splitlines()
    start = next((i for i, line in enumerate(lines)
                  if line.startswith(f"| {first_header} |")), None)
    if start is None:
        return []
    names = []
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        names.append(line.split("|")[1].strip().removesuffix(" (drive)").strip("`"))
    return names


def missing_from_page(text: str, mechanisms: dict) -> list[str]:
    """What of ``mechanisms`` (call → Mechanism) the page ``text`` does not document."""
    sections, missing = _sections(text), []
    for call, mech in mechanisms.items():
        section = sections.get(call)
        if section is None:
            missing.append(f"{call}: no section")
            continue
        coords = _rows(section, "coordinate")
        params = _rows(section, "parameter")
        posfns = _rows(section, "position function")
        missing += [f"{call}: coordinate {q.name}" for q in mech.coordinates
                    if q.name not in coords]
        missing += [f"{call}: parameter {p.name}" for p in mech.parameters
                    if p.name not in params]
        missing += [f"{call}: position function {u}" for u in _position_functions(mech)
                    if u not in posfns]
        figure = re.search(r"!\[[^\]]*\]\((figures/[^)]+\.png)\)", section)
        if figure is None or not (DOC.parent / figure.group(1)).is_file():
            missing.append(f"{call}: figure")
    return missing


def test_every_builtin_mechanism_coordinate_and_parameter_is_on_the_page():
    mechanisms = builtin_mechanisms()
    assert len(mechanisms) >= 10  # 2 mounted, 4 cases, 3 machine forms, the crane
    assert not missing_from_page(DOC.read_text(encoding="utf-8"), mechanisms)


def test_the_page_check_notices_what_is_missing():
    # the check above can fail: drop one coordinate row, one parameter row and a section
    text = DOC.read_text(encoding="utf-8")
    mechanisms = builtin_mechanisms()
    text = re.sub(r"^\| `(y_f|rS5)` \|.*\n", "", text, flags=re.M)
    text = text.replace("Python: `femmech.mechanisms.table_5_1_case(3)`", "Python: (none)")
    with pytest.raises(AssertionError):  # the section without its Python line
        missing_from_page(text, mechanisms)
    text = text.replace("Python: (none)", "Python: `femmech.mechanisms.gone()`")
    assert sorted(missing_from_page(text, mechanisms)) == [
        "cam_follower(): coordinate y_f", "mobile_crane(): parameter rS5",
        "table_5_1_case(3): no section"]


def test_every_factory_and_scene_model_has_a_catalogue_entry():
    mechanisms = builtin_mechanisms()
    for call, mech in mechanisms.items():
        entry = CATALOGUE[call]
        assert [c.name for c in entry.coordinates] == [q.name for q in mech.coordinates]
        assert tuple(q.name for q in mech.drives) == entry.drives, call
        assert {p.name for p in entry.parameters} == {p.name for p in mech.parameters}, call
        assert {u.name for u in entry.position_functions} == _position_functions(mech), call
        assert all(c.meaning and c.unit and c.sign for c in entry.coordinates), call
        assert all(p.meaning and p.unit and p.default for p in entry.parameters), call
        assert dict(mech.labels) == {c.name: c.meaning for c in entry.coordinates}, call
    for model in BUILTIN_MODELS:  # the scene spelling of each scene model
        entry = catalogue_entry(model, {"case": 1})
        assert entry is not None, model
        assert f'model = "{model}"' in entry.scene, model
        assert entry.call in mechanisms
    assert set(CATALOGUE) - set(mechanisms) == {"follower_unit(cam, inertia, mass, stiffness)"}


def test_the_chain_follower_unit_is_catalogued():
    entry = CATALOGUE["follower_unit(cam, inertia, mass, stiffness)"]
    names = {p.name for p in entry.parameters + entry.position_functions}
    assert names == set(inspect.signature(follower_unit).parameters)
    unit = follower_unit(cam_program(0.01, 120, 60, 120, 60), 1e-3, 1.0, 1e5)
    assert unit.coordinate_names == tuple(c.name for c in entry.coordinates)
    assert describe(unit, "q2", "unit3.") == "follower deflection [unit3.q2]"
    assert '[chain.unit] kind = "cam_follower"' == entry.scene


def test_the_reference_block_is_the_rendered_catalogue():
    # meanings, units, signs and defaults on the page are those that label the plots
    text = DOC.read_text(encoding="utf-8")
    block = text.split(START)[1].split(END)[0]
    assert block.strip() == reference_markdown().strip(), (
        "regenerate the block with femmech.mechanisms.catalogue.reference_markdown()")


def test_readable_names_come_from_the_mechanism():
    mech = cam_follower(m="m1")
    assert describe(mech, "y_f", "cam1.") == "return-spring base displacement [cam1.y_f]"
    assert describe(mech, "q") == "follower deformation [q]"
    assert describe(mobile_crane(), "q3") == "pendulum angle [q3]"
    theta, x = sympy.symbols("theta x")
    plain = Mechanism((x, theta), (), drives=(theta,))
    assert describe(plain, "x", "m.") == "m.x"   # a user mechanism without labels
    labelled = Mechanism((x, theta), (), drives=(theta,), labels=(("x", "slide"),))
    assert describe(labelled, "x") == "slide [x]"
    assert labelled == plain  # labels are not part of equality (shared equation cache)
    assert readable("", "q1") == readable("q1", "q1") == "q1"
    with pytest.raises(ValueError, match="labels must be .* pairs of its coordinates"):
        Mechanism((x, theta), (), labels=(("y", "nothing"),), name="bad")
    # the scene's quantity descriptions follow the catalogue
    assert QUANTITIES["mobile_crane"]["q1"][0] == "chassis heave"
    assert QUANTITIES["slider_crank"]["v_g"][0] == "guide displacement across the slider axis"


def test_the_chapter_symbol_table_agrees_with_the_catalogue():
    # the page's older table of chapter symbols gives the same units as the reference
    spec = importlib.util.spec_from_file_location(
        "symbol_table", ROOT / "tests" / "mechanisms" / "test_gaps_symbol_table.py")
    symbols = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(symbols)
    calls = {"T5.1-1": "table_5_1_case(1)", "T5.1-2": "table_5_1_case(2)",
             "T5.1-3": "table_5_1_case(3)", "T5.1-4": "table_5_1_case(4)",
             "crane": "mobile_crane()", "machine": "processing_machine()",
             "machine-mixed": "processing_machine_mixed()"}
    rows = symbols._rows()
    assert {model for model, *_ in rows} == set(calls)
    for model, name, _, unit, _ in rows:
        entry = CATALOGUE[calls[model]]
        units = {x.name: x.unit for x in
                 entry.coordinates + entry.parameters + entry.position_functions}
        assert units.get(name) == unit, (model, name, unit, units.get(name))


def test_every_registered_mechanism_type_has_factory_parameters_and_quantities():
    """One registration per mechanism type: its factory, its parameters with a dimension
    the scene knows, its coordinates and output quantities; the scene accepts exactly the
    registered names."""
    import inspect

    from femmech.mechanisms.registry import MECHANISM_TYPES
    from femmech.scene import machine

    assert set(MECHANISM_TYPES) == {"cam_follower", "slider_crank", "table_5_1_case",
                                    "processing_machine", "mobile_crane"}
    assert machine.BUILTIN_MODELS == {n: t.factory for n, t in MECHANISM_TYPES.items()}
    for name, kind in MECHANISM_TYPES.items():
        assert callable(kind.factory)
        options = {"case": 1} if name == "table_5_1_case" else {}
        signature = inspect.signature(kind.factory).parameters
        assert set(options) <= set(signature)
        units = kind.parameter_units(options)
        assert units
        assert all(machine.UNIT_KINDS.get(u) is not None for u in units.values())
        quantities = kind.quantities(options)
        assert quantities
        assert all(c.unit for c in quantities)
        spec = machine.MechanismSpec("m", name, None, None, options, {}, ())
        assert machine.parameter_kinds(spec) == {n: machine.UNIT_KINDS[u]
                                                 for n, u in units.items()}


def test_a_role_renamed_by_an_option_keeps_its_dimension():
    from femmech.scene import machine
    from femmech.scene.units import INERTIA, MASS, STIFFNESS

    spec = machine.MechanismSpec("m", "cam_follower", None, None,
                                 {"m": "m_f", "J": "J_cam"}, {}, ())
    kinds = machine.parameter_kinds(spec)
    assert kinds["m_f"] == MASS
    assert kinds["J_cam"] == INERTIA
    assert "m" not in kinds
    assert kinds["c_r"] == STIFFNESS  # a role left at its default name
    assert "J" not in machine.parameter_kinds(machine.MechanismSpec(
        "m", "cam_follower", None, None, {}, {}, ()))  # J unset: no rotary inertia


def test_registering_a_mechanism_type_twice_is_refused():
    from femmech.mechanisms.registry import MECHANISM_TYPES, MechanismType, register

    with pytest.raises(ValueError, match="'cam_follower' is already registered"):
        register(MechanismType("cam_follower", MECHANISM_TYPES["cam_follower"].factory))
    with pytest.raises(ValueError, match="no catalogue entry 'toy\\(\\)'"):
        MechanismType("toy", print)
