"""Scenes too large for the machine are refused before anything is built: one line with
the estimated memory and the limit in GB (femmech.scene.memory), also from the command
line (exit code 3, no "internal error"); band values of mesh = "auto" are validated."""

from __future__ import annotations

import time
import tomllib
from pathlib import Path

import pytest
from scene_texts import frame_scene

from femmech.cli import INPUT, main
from femmech.errors import SceneError
from femmech.fe.generators import members_frame
from femmech.scene.build import prepare
from femmech.scene.load import Scene
from femmech.scene.memory import MEMORY_ENV, estimate_bytes, memory_limit

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"

GRID = frame_scene("a million joints", bays=(100, 100, 99), size=(10.0, 10.0, 10.0))

PLATE = """
[scene]
name = "plate"

[materials.steel]
E = "210 GPa"
nu = 0.3
rho = "7850 kg/m^3"

[parts.plate]
MESH

[parts.plate.generator]
kind = "rectangular_plate"
a = 1.0
b = 1.0
DIVISIONS

[parts.plate.shells]
plate = { thickness = "5 mm", material = "steel" }

[[parts.plate.supports]]
nodes = "edges"

[analyses.modes]
n_modes = 3
images = 0
vtu = false
"""


def _plate(divisions=None, f_max=None) -> str:
    mesh = f'mesh = "auto"\nf_max_hz = {f_max}' if f_max is not None else ""
    return PLATE.replace("MESH", mesh).replace(
        "DIVISIONS", f"divisions = {list(divisions)}" if divisions else "")


def _error(text: str, file: str = "big.toml") -> str:
    with pytest.raises(SceneError) as info:
        prepare(Scene.from_dict(tomllib.loads(text), EXAMPLES, file))
    message = str(info.value)
    assert "\n" not in message
    return message


@pytest.fixture
def limit_16gb(monkeypatch):
    monkeypatch.setenv(MEMORY_ENV, "16")


def test_million_joint_grid_fails_fast_from_the_command_line(tmp_path, capsys, limit_16gb):
    scene = tmp_path / "grid.toml"
    scene.write_text(GRID)
    start = time.perf_counter()
    code = main(["run", str(scene), "--out", str(tmp_path / "out"), "--no-cache"])
    seconds = time.perf_counter() - start
    err = capsys.readouterr().err.strip()
    assert code == INPUT, err
    assert "internal error" not in err
    assert len(err.splitlines()) == 1
    # 101 x 101 x 100 joints = 1020100 nodes, 3029899 beams (grid_frame_size)
    assert err.startswith("error: grid.toml: [parts.frame.generator] bays: the part would"
                          " need at least ")
    assert "GB of memory (1020100 nodes, 3029899 elements, 6120600 DOFs" in err
    assert f"the limit is 16 GB (${MEMORY_ENV}" in err
    assert seconds < 3.0  # measured 0.01 s: refused from the counts, no mesh is generated
    assert not (tmp_path / "out").exists()


def test_3000_by_3000_plate_is_refused_with_the_estimate(limit_16gb):
    message = _error(_plate(divisions=(3000, 3000)))
    assert message.startswith("big.toml: [parts.plate.generator] divisions: the part would"
                              " need at least ")
    assert "(9006001 nodes, 9000000 elements, 54036006 DOFs" in message
    # element matrices alone: 9e6 quads x 24^2 entries x 8 bytes x 2 (K, M) = 83 GB
    need = float(message.split("at least ")[1].split(" GB")[0])
    assert need >= 83


def test_the_limit_can_be_raised_and_a_bad_limit_is_named(monkeypatch):
    monkeypatch.setenv(MEMORY_ENV, "1e6")  # 1 PB: the estimate no longer refuses
    assert memory_limit() == (1e15, f"${MEMORY_ENV}")
    monkeypatch.setenv(MEMORY_ENV, "lots")
    message = _error(_plate(divisions=(4, 4)))
    assert f"[parts.plate.generator] divisions: ${MEMORY_ENV}: expected a positive number" \
           " of GB, got 'lots'" in message


def test_default_limit_is_the_available_memory():
    limit, source = memory_limit()
    assert 0 < limit < float("inf")
    assert "memory" in source


def test_estimate_is_a_lower_bound_of_the_element_matrices():
    # one quad shell: 4 nodes x 6 DOFs, K and M element matrices of 24 x 24 float64
    quads = estimate_bytes(10**6, {4: 10**6}, 2)
    assert quads >= 2 * 10**6 * 24**2 * 8
    # a surface fills less than a solid grid of the same node count (n log n < n^(4/3))
    assert estimate_bytes(10**6, {2: 3 * 10**6}, 2) < estimate_bytes(10**6, {2: 3 * 10**6}, 3)


@pytest.mark.parametrize("f_max", ["1e29", "1e12"])
def test_huge_band_of_auto_members_is_one_line_not_a_type_error(f_max, limit_16gb):
    # the press frame's members sized for f_max: 1e29 Hz gave counts beyond float64
    press = (EXAMPLES / "press_frame.toml").read_text().replace(', element_size = "0.1 m"', "")
    press = press.replace("[parts.frame.generator]",
                          f'[parts.frame]\nmesh = "auto"\nf_max_hz = {f_max}\n\n'
                          "[parts.frame.generator]", 1)
    message = _error(press, "press.toml")
    assert f"mesh = 'auto' (target_error 0.001, band f_max_hz = {float(f_max):g}):" in message
    assert "TypeError" not in message


def test_huge_band_of_an_auto_plate_goes_through_the_estimate(limit_16gb):
    message = _error(_plate(f_max="1e29"))
    assert "band f_max_hz = 1e+29): the part would need at least" in message
    assert "the limit is 16 GB" in message


@pytest.mark.parametrize(("value", "expected"), [
    ('"inf Hz"', "f_max_hz: expected a frequency"),
    ('"nan Hz"', "f_max_hz: expected a frequency"),
    ("-5", "f_max_hz: expected a positive value, got -5"),
    ('"many"', "f_max_hz: expected a frequency"),
    ("1e31", r"f_max_hz: expected a magnitude of at most 1e\+30"),
])
def test_bad_band_values_are_named(value, expected):
    with pytest.raises(SceneError, match=r"\[parts.plate\] " + expected):
        Scene.from_dict(tomllib.loads(_plate(f_max=value)), EXAMPLES, "big.toml")


def test_members_frame_refuses_a_count_beyond_float64():
    members = [{"group": "g", "chain": ["a", "b"], "divisions": 10**400}]
    with pytest.raises(ValueError, match="at most 100000 per member"):
        members_frame({"a": (0, 0, 0), "b": (1, 0, 0)}, members)
