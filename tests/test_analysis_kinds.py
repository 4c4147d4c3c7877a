"""The registry of analysis kinds (femmech.scene.registry): ``femmech check`` lists every
kind a run executes, and a new kind is one module (here: a toy kind of this test file)."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import pytest

from femmech.cli import main
from femmech.output.report import Section
from femmech.scene.kinds.common import AnalysisKind, ReadContext
from femmech.scene.load import Scene
from femmech.scene.registry import KINDS, register
from femmech.scene.run import run_scene
from femmech.scene.units import LENGTH

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize(("name", "kinds"), [
    ("knitting_machine_chain.toml", ("chain_sweep", "campbell", "synthesis")),
    ("crane_braking.toml", ("drive_event",)),
])
def test_check_lists_every_kind_a_run_executes(name, kinds, capsys):
    """Every requested kind is listed (the chain's three kinds were missing)."""
    assert main(["check", str(ROOT / "examples" / name)]) == 0
    line = capsys.readouterr().out.splitlines()[0]
    listed = line.split("analyses ")[-1]
    for kind in kinds:
        assert repr(kind) in listed, line


def test_registry_holds_the_run_order():
    assert list(KINDS)[:6] == ["modes", "sweep", "stability", "response", "check",
                               "drive_event"]
    assert list(KINDS)[6:] == ["chain_sweep", "campbell", "synthesis"]
    with pytest.raises(ValueError, match="already exists"):
        register(KINDS["modes"])


def _read_toy(t, context: ReadContext):
    return (t.number("length", LENGTH), len(context.parts))


def _run_toy(ws, spec, out):
    (out / "toy.txt").write_text(f"{spec[0]!r}\n", encoding="utf-8")
    return Section("Toy", (f"length {spec[0]} m",), files=("toy.txt",)), {"length_m": spec[0]}


TOY = AnalysisKind("toy", ("length",), _read_toy, _run_toy, "a toy kind of a test", order=5)


def test_toy_kind_touches_one_module(monkeypatch, tmp_path):
    """A kind defined in this test, registered, is read from ``[analyses.toy]``, runs
    first (order 5) and writes its numbers to results.json and its file."""
    data = tomllib.loads((ROOT / "examples" / "mechanism_quasi_modes.toml").read_text())
    data["analyses"] = {"toy": {"length": "25 mm"}}  # its mechanism, only the toy kind
    with pytest.raises(Exception, match="toy"):  # not registered: an unknown table
        Scene.from_dict(data, tmp_path)
    monkeypatch.setitem(KINDS, "toy", TOY)
    scene = Scene.from_dict(data, tmp_path)
    assert scene.analyses.toy == (0.025, 0)  # '25 mm' in SI; no parts
    result = run_scene(scene, tmp_path / "out", cache_dir=None)
    assert result.results == {"toy": {"length_m": 0.025}}
    assert json.loads((tmp_path / "out" / "results.json").read_text()) == result.results
    assert (tmp_path / "out" / "toy.txt").read_text() == "0.025\n"


def test_docs_list_every_kind():
    """docs/scenes.md lists each registered kind once, with its description, and nothing
    else, in run order."""
    import re

    text = (ROOT / "docs" / "scenes.md").read_text(encoding="utf-8")
    listed = re.findall(r"^- `\[(?:analyses\.)?(\w+)\]`: (.*)\.$", text, flags=re.M)
    assert [name for name, _ in listed] == list(KINDS)
    assert all(KINDS[name].describe == line for name, line in listed)
