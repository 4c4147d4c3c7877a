"""Scene tables [chain], [analyses.chain_sweep], [analyses.campbell] and [synthesis]
(femmech.scene.chain): strict reading, the chain built from a scene, a small chain scene
end to end, and the knitting-machine example's numbers."""

import copy
import importlib.util
import tomllib
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from femmech.chain import End, chain, follower_unit
from femmech.errors import SceneError
from femmech.mechanisms import cam_program
from femmech.scene.build import prepare
from femmech.scene.chain import build_chain
from femmech.scene.load import Scene, load_scene
from femmech.scene.run import run_scene

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"

SMALL = """
[scene]
name = "small chain"

[chain]
n_units = 5
spacing = "0.25 m"
shaft_diameter = "50 mm"
phases = "uniform"
cells = true
left = { kind = "elastic", stiffness = "5e3 N*m/rad" }
right = "free"

[chain.unit]
inertia = "2e-3 kg*m^2"
mass = "0.6 kg"
stiffness = "3e5 N/m"
damping = "10 N*s/m"

[chain.unit.cam]
law = "modified_sine"
stroke = "30 mm"
rise = "120 deg"
dwell_top = "60 deg"
return = "120 deg"
dwell_bottom = "60 deg"

[analyses.chain_sweep]
n_modes = 4
angles = { start = "0 deg", stop = "360 deg", n = 13 }

[analyses.campbell]
speeds = ["1200 rpm", "1400 rpm"]
harmonics = 6

[synthesis]
parameters.follower_stiffness = ["1e5 N/m", "8e5 N/m"]
parameters.coupling_stiffness = ["1e3 N*m/rad", "2e4 N*m/rad"]
speeds = ["1200 rpm", "1400 rpm"]
harmonics = 6
starts = 2
n_angles = 12
"""


def small():
    return tomllib.loads(SMALL)


def _error(data) -> str:
    with pytest.raises(SceneError) as info:
        prepare(Scene.from_dict(data, EXAMPLES, "bad.toml"))
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith("bad.toml: ")
    return message


def _set(path, value):
    def change(data):
        d = data
        for key in path[:-1]:
            d = d[key]
        d[path[-1]] = value
    return change


def _drop(path):
    def change(data):
        d = data
        for key in path[:-1]:
            d = d[key]
        del d[path[-1]]
    return change


@pytest.mark.parametrize(("change", "fragment"), [
    (_set(("chain", "n_unit"), 3), "[chain] n_unit: unknown key; did you mean 'n_units'?"),
    (_set(("chain", "n_units"), 0), "[chain] n_units: expected an integer >= 1"),
    (_set(("chain", "n_units"), 10**6), "[chain] n_units: expected an integer <= 10000"),
    (_set(("chain", "spacing"), "250 kg"), "[chain] spacing: expected a length"),
    (_set(("chain", "shaft_diameter"), "-5 mm"), "[chain] shaft_diameter: expected a"
                                                 " positive value"),
    (_set(("chain", "bore"), "60 mm"), "[chain] bore: expected less than shaft_diameter"),
    (_set(("chain", "phases"), ["0 deg", "90 deg"]), "[chain] phases: expected n_units = 5"
                                                     " angles, got 2"),
    (_set(("chain", "phases"), "unifrom"), "[chain] phases: expected 'uniform', an angle"),
    (_set(("chain", "left"), "elastic"), "[chain] left: kind 'elastic' needs a table"),
    (_set(("chain", "left"), {"kind": "flywheel", "stiffness": 1.0}),
     "[chain.left] stiffness: unknown key for kind = 'flywheel'"),
    (_set(("chain", "right"), "hinged"), "[chain] right: expected one of"),
    (_set(("chain", "unit", "mass"), "0 kg"), "[chain.unit] mass: expected a positive"),
    (_set(("chain", "unit", "stiffness"), "3e5 N*m/rad"),
     "[chain.unit] stiffness: expected a stiffness"),
    (_set(("chain", "unit", "ground_stiffness"), "-1 N/m"),
     "[chain.unit] ground_stiffness: expected a"),
    (_set(("chain", "unit", "ground_stiffness"), "2e4 N*m/rad"),
     "[chain.unit] ground_stiffness: expected a stiffness"),
    (_set(("chain", "unit", "cam", "law"), "sine"), "[chain.unit.cam] law: expected one of"),
    (_set(("chain", "unit", "cam", "rise"), "100 deg"),
     "[chain.unit.cam]: rise + dwell_top + return + dwell_bottom = 340 deg"),
    (_set(("chain", "unit", "cam", "stroke"), "0 mm"), "[chain.unit.cam] stroke: expected a"
                                                       " non-zero stroke"),
    (_drop(("chain", "unit", "cam", "rise")), "[chain.unit.cam] rise: missing (required)"),
    (_set(("analyses", "chain_sweep", "methods"), ["transfer", "fem"]),
     "[analyses.chain_sweep] methods: expected names of"),
    (_set(("analyses", "chain_sweep", "n_mode"), 3),
     "[analyses.chain_sweep] n_mode: unknown key; did you mean 'n_modes'?"),
    (_set(("analyses", "campbell", "speeds"), ["1400 rpm", "1200 rpm"]),
     "[analyses.campbell] speeds: expected 0 < lowest < highest"),
    (_set(("analyses", "campbell", "speeds"), ["20 Hz", "25 Hz"]),
     "[analyses.campbell] speeds: expected an angular speed"),
    (_set(("analyses", "campbell", "margin"), 0.7), "[analyses.campbell] margin: expected a"
                                                    " relative margin below 0.5"),
    (_set(("synthesis", "parameters"), {"shaft_diameter": ["60 mm", "40 mm"]}),
     "[synthesis.parameters] shaft_diameter: expected low < high"),
    (_set(("synthesis", "parameters"), {"shaft_diam": ["40 mm", "60 mm"]}),
     "[synthesis.parameters] shaft_diam: unknown key; did you mean 'shaft_diameter'?"),
    (_set(("synthesis", "parameters"), {"follower_mass": ["0.7 kg", "1 kg"]}),
     "[synthesis.parameters] follower_mass: the scene's value 0.6 (SI) lies outside"),
    (_set(("synthesis", "parameters"), {"flywheel_inertia": ["0.1 kg*m^2", "1 kg*m^2"]}),
     "[synthesis.parameters] flywheel_inertia: the scene's value 0 (SI) lies outside"),
    (_set(("synthesis", "harmonics"), 0), "[synthesis] harmonics: expected an integer >= 1"),
    (_set(("synthesis", "starts"), 1000), "[synthesis] starts: expected an integer <= 64"),
])
def test_chain_scene_errors_name_the_key(change, fragment):
    data = copy.deepcopy(small())
    change(data)
    assert fragment in _error(data)


def test_chain_analyses_need_a_chain():
    data = small()
    del data["chain"]
    data["mechanisms"] = {"m": {"model": "processing_machine"}}  # a scene without chain
    data.pop("synthesis")
    assert "[analyses.chain_sweep]: needs a chain: add a [chain] table" in _error(data)


def test_scene_chain_equals_the_api_chain():
    """The scene's chain is the API's: same matrices at any angle (exact: same inputs)."""
    scene = Scene.from_dict(small(), EXAMPLES, "s.toml")
    built = prepare(scene).chain
    cam = cam_program(0.03, rise=120, dwell_top=60, return_=120, dwell_bottom=60,
                      law="modified_sine")
    api = chain(follower_unit(cam, 2e-3, 0.6, 3e5, 10.0), 5, 0.25, 0.05,
                phases=2 * np.pi * np.arange(5) / 5, left=End.elastic(5e3), cells=True)
    for phi in (0.0, 1.3):
        # bound: the same inputs through the same arithmetic: exact up to unit conversion (1 ulp)
        assert_allclose(built.M(phi), api.M(phi), rtol=1e-15, atol=0)
        # bound: as above
        assert_allclose(built.C(phi), api.C(phi), rtol=1e-15, atol=0)
    # a design value overrides the scene's: the follower stiffness is C's internal diagonal
    stiffer = build_chain(scene.chain, {"follower_stiffness": 4e5})
    assert_allclose(np.diag(stiffer.C(0.0))[stiffer.unit_dofs[:, 1]], 4e5)
    with pytest.raises(ValueError, match="unknown design parameter 'diameter'"):
        build_chain(scene.chain, {"diameter": 0.05})


def test_scene_follower_ground_spring():
    """``[chain.unit] ground_stiffness`` is follower_unit's c_g (N/m): same matrices."""
    data = small()
    data["chain"]["unit"]["ground_stiffness"] = "4e4 N/m"
    built = prepare(Scene.from_dict(data, EXAMPLES, "s.toml")).chain
    cam = cam_program(0.03, rise=120, dwell_top=60, return_=120, dwell_bottom=60,
                      law="modified_sine")
    api = chain(follower_unit(cam, 2e-3, 0.6, 3e5, 10.0, c_g=4e4), 5, 0.25, 0.05,
                phases=2 * np.pi * np.arange(5) / 5, left=End.elastic(5e3), cells=True)
    for phi in (0.0, 1.3):
        assert_allclose(built.C(phi), api.C(phi), rtol=1e-15, atol=0)  # bound: same inputs, exact
    # the follower's diagonal holds c + c_g; bound: one sum, exact to 1 ulp
    assert_allclose(np.diag(built.C(0.0))[built.unit_dofs[:, 1]], 3e5 + 4e4, rtol=1e-15)


def test_small_chain_scene_runs_end_to_end(tmp_path):
    result = run_scene(Scene.from_dict(small(), EXAMPLES, "small.toml"), tmp_path / "out",
                       cache_dir=None)
    r = result.results
    # transfer matrices and the assembled model solve the same frozen problem: they agree
    # to the roots' tolerance (1e-12 relative, transfer_modes' rtol), 1e-9 demanded
    # bound: both solve the same problem: bisection rtol 1e-12 vs eigh ~1e-13
    assert r["chain_sweep"]["max_rel_difference"]["transfer"] < 1e-9
    # the continuum differs by its dispersion error, about μ²/24 for the shaft modes
    # (docstring of femmech.chain.continuum): a few percent for 5 cells, not more
    assert 1e-6 < r["chain_sweep"]["max_rel_difference"]["continuum"] < 0.1
    syn = r["synthesis"]
    assert syn["feasible"]
    assert syn["margin_after"] >= syn["required"] > syn["margin_before"]
    assert syn["after"]["follower_stiffness"] != syn["before"]["follower_stiffness"]
    out = result.out_dir
    for name in ("chain_sweep.png", "campbell.png", "synthesis_campbell.png",
                 "synthesis_margins.png"):
        assert (out / name).stat().st_size > 10_000
    table = np.genfromtxt(out / "chain_frequencies.csv", delimiter=",", skip_header=1,
                          dtype=None, encoding="utf-8")
    assert len(table) == 3 * 13  # three methods, 13 angles
    html = (out / "report.html").read_text(encoding="utf-8")
    for text in ("Chain: quasi-eigenfrequencies over the drive angle by method",
                 "Chain: Campbell diagram", "Chain: synthesis", "Chain of identical"):
        assert text in html


def _example():
    spec = importlib.util.spec_from_file_location(
        "knitting_machine_chain", EXAMPLES / "knitting_machine_chain.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_example_scene_matches_the_example_script():
    """The scene describes the script's machine: same chain (exact) before synthesis."""
    module = _example()
    scene = load_scene(EXAMPLES / "knitting_machine_chain.toml")
    built, api = prepare(scene).chain, module.build(module.INITIAL)
    # bound: the same inputs, one unit conversion: 1 ulp
    assert_allclose(built.M(0.7), api.M(0.7), rtol=1e-15, atol=0)
    # bound: as above
    assert_allclose(built.C(0.7), api.C(0.7), rtol=1e-15, atol=0)
    spec = scene.analyses.synthesis
    bounds = {n: (lo, hi) for n, lo, hi in spec.parameters}
    assert bounds.keys() == module.BOUNDS.keys()
    for name, (lo, hi) in module.BOUNDS.items():  # unit conversion: one rounding
        # bound: one unit conversion: 1 ulp
        assert_allclose(bounds[name], (lo, hi), rtol=1e-15)
    assert spec.margin == module.MARGIN
    assert spec.harmonics == module.HARMONICS


@pytest.mark.slow
def test_knitting_machine_example(tmp_path):
    """Acceptance of the chain scenes: the φ-sweep by three methods, the Campbell diagram and a
    synthesis that moves every quasi-eigenfrequency out of the harmonic bands (about a
    minute on one core)."""
    r = _example().main(tmp_path, n_angles=37, starts=2)
    # transfer = assembled to the root tolerance; measured 2.4e-13
    # bound: bisection rtol 1e-12 vs eigh ~1e-13
    assert r["max_rel_difference"]["transfer"] < 1e-9
    # continuum: the smeared model's error for 28 cells and the 6 lowest branches,
    # measured 2.0e-2 (follower cluster smeared to one frequency); 5 % would flag a
    # wrong smearing (the follower frequency alone differs by 2 % across the cluster)
    assert r["max_rel_difference"]["continuum"] < 0.05
    # before: the coupling mode sits in band k = 2 and the follower cluster in k = 5
    assert r["margin_before"] < 0
    # after: every frequency at least 3 % clear, also on a 360-angle grid (the
    # optimisation sampled 24 angles; the uniform phasing keeps the bands flat in φ)
    assert r["feasible"]
    assert r["margin_after"] >= 0.03
    assert r["check_after"] >= 0.03 - 1e-4
    for name, (lo, hi) in _example().BOUNDS.items():
        assert lo <= r["after"][name] <= hi
    assert all(p.stat().st_size > 10_000 for p in r["plots"])
