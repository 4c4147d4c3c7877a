"""Scene defaults that adapt to the model: a sweep without ``n_modes`` follows every branch
of a mechanism that has fewer than the default 6, and the report says so; warnings raised
while a scene is prepared (what a mesh file loses) reach the run log."""

from __future__ import annotations

import tomllib
from pathlib import Path

from models import deck

from femmech.scene.build import prepare
from femmech.scene.load import Scene, load_scene
from femmech.scene.run import run_scene

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_sweep_without_n_modes_follows_all_branches_of_a_small_mechanism(tmp_path):
    data = tomllib.loads((EXAMPLES / "mechanism_quasi_modes.toml").read_text())
    sweep = data["analyses"]["sweep"]
    del sweep["n_modes"]
    sweep["angles"] = {"start": "0 deg", "stop": "360 deg", "n": 13}
    sweep["speeds"] = ["0 rpm"]
    scene = Scene.from_dict(data, EXAMPLES, "mechanism.toml")
    n_coordinates = prepare(scene).mechanisms["machine"].M(0.0).shape[0]
    assert n_coordinates < 6  # the case: fewer branches than the default
    result = run_scene(scene, tmp_path / "out", cache_dir=None)
    freq = result.results["sweep"]["freq_hz"][0]
    assert len(freq[0]) == n_coordinates  # every branch, not an error and not 6
    report = (tmp_path / "out" / "report.html").read_text(encoding="utf-8")
    assert f"{n_coordinates} branches, fewer than the default 6; all are shown" in report


def test_warnings_of_preparing_a_scene_reach_the_run_log(tmp_path):
    # a deck with cards read_mesh does not carry (a ModelWarning while the scene is
    # prepared): the run log names them as a 'warning:' line, not a raw Python warning
    deck(tmp_path, "SPC1    1       123456  1\nCONM2   10      5               100.0\n")
    scene = tmp_path / "frame.toml"
    scene.write_text('[materials.steel]\nE = "210 GPa"\nnu = 0.3\nrho = "7850 kg/m^3"\n'
                     '[parts.frame]\nmesh = "frame.bdf"\n[parts.frame.sections.PID1]\n'
                     'section = "circle"\ndiameter = "30 mm"\nmaterial = "steel"\n'
                     'orientation = [0, 1, 0]\n[[parts.frame.supports]]\nnodes = "SPC1"\n'
                     '[analyses.modes]\nn_modes = 3\nimages = 0\nvtu = false\n')
    result = run_scene(load_scene(scene), tmp_path / "out", cache_dir=None)
    lines = [line for line in result.log if line.startswith("warning: prepare: ")]
    assert any("cards not carried into the model: CONM2 x1" in line for line in lines)
    assert any("CONM2 x1" in line
               for line in (tmp_path / "out" / "run.log").read_text().splitlines())



def test_material_errors_come_from_the_library_at_the_key_they_name():
    """The scene reads [materials.<name>] straight into femmech.fe.materials.Material: its
    checks (here E outside MODULUS_RANGE, which the scene did not check) name the key."""
    import pytest

    from femmech.errors import SceneError
    from femmech.scene import Scene

    data = {"materials": {"steel": {"E": 1e-150, "rho": 7850.0, "nu": 0.3}}}
    with pytest.raises(SceneError, match=r"\[materials\.steel\] E: E = 1e-150 .*MODULUS_RANGE"):
        Scene.from_dict(data)
    data["materials"]["steel"] = {"E": "210 GPa", "rho": 7850.0, "nu": 0.7}
    with pytest.raises(SceneError, match=r"\[materials\.steel\] nu: nu must lie in"):
        Scene.from_dict(data)
