"""The shipped examples run and reproduce independently computed numbers."""

import importlib.util
import re
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from femmech.fe import sections

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _load(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def frame_run(tmp_path_factory):
    module = _load("frame_modes")
    out = tmp_path_factory.mktemp("frame")
    return module, {**module.main(out), "out": out}


def test_frame_example_writes_a_paraview_series(frame_run):
    """modes.pvd: one step per mode (time = mode number), each a VTU meshio reads, with
    the displacement of that mode (femmech.output.series)."""
    import meshio

    from femmech.output.series import read_pvd

    _, result = frame_run
    steps = read_pvd(result["out"] / "modes.pvd")
    assert [t for t, _ in steps] == [float(k) for k in range(1, len(result["freq_hz"]) + 1)]
    for k, (_, vtu) in enumerate(steps):
        mesh = meshio.read(vtu)
        assert mesh.point_data["displacement"].shape == (len(mesh.points), 3)
        assert mesh.field_data["frequency_hz"][0] == result["freq_hz"][k]


def test_frame_example_writes_a_mode_animation(frame_run):
    """mode_07.gif: 24 frames of one period (23 after Pillow merges the two identical
    frames at a turning point), 800 x 600, looping; the frames differ (the mode moves)."""
    from PIL import Image

    _, result = frame_run
    with Image.open(result["out"] / "mode_07.gif") as gif:
        assert gif.size == (800, 600)
        assert gif.n_frames >= 20
        assert gif.info["loop"] == 0
        frames = []
        for k in (0, gif.n_frames // 4):
            gif.seek(k)
            frames.append(np.asarray(gif.convert("RGB"), dtype=float))
    assert np.abs(frames[0] - frames[1]).mean() > 1.0  # the shape moved between frames


def test_frame_example_mass(frame_run):
    module, result = frame_run
    # member lengths from meshes/machine_frame.geo: columns 4 x 1.2 m, longitudinals
    # 2 x 2 m, cross beams 3 x 1 m, rails 2 x 2 m + 2 x 1 m, brace sqrt(1² + 0.9²) m
    rho = module.STEEL.rho
    mass = rho * (
        4 * 1.2 * sections.i_section(0.1, 0.1, 0.006, 0.01).A
        + 4.0 * sections.rectangular_hollow(0.08, 0.12, 0.005).A
        + 3.0 * sections.rectangular_hollow(0.08, 0.08, 0.004).A
        + 6.0 * sections.tube(0.06, 0.05).A
        + np.hypot(1.0, 0.9) * sections.circle(0.03).A
    ) + module.MOTOR_MASS
    # bound: consistent mass matrices integrate rho*A exactly: round-off only
    assert_allclose(result["total_mass_kg"], mass, rtol=1e-12)


def test_frame_example_mount_modes_below_rigid_body_bound(frame_run):
    _, result = frame_run
    f = result["freq_hz"][:6]
    bound = result["rigid_body_estimate_hz"]
    # bound: Rayleigh-Ritz on the six rigid-body motions gives upper bounds of the six lowest
    # eigenvalues (Courant-Fischer); round-off of both solves is ~1e-10 relative.
    assert np.all(f <= bound * (1 + 1e-10))
    # the mounts (3e5..8e5 N/m) are much softer than the frame, so the bound is close:
    # measured 1.3-8.6 % above; 10 % would be exceeded if frame flexibility dominated
    # (with mounts 7x stiffer, 2e6/5e6 N/m, the gap was measured at 5-30 %).
    assert np.all(f >= 0.90 * bound)
    assert result["freq_hz"][6] > 1.5 * bound[-1]  # then the frame's own modes begin


def test_frame_example_writes_outputs(frame_run):
    _, result = frame_run
    assert len(result["images"]) == 12
    out = result["images"][0].parent
    for name in ("frequencies.txt", "frequencies.csv", "modes.vtu"):
        assert (out / name).stat().st_size > 0
    assert all(p.stat().st_size > 10_000 for p in result["images"])


def test_textile_shaft_reduced_matches_full(tmp_path):
    # Acceptance: reduced coupled vs full coupled at 4 angles (dwell, rise,
    # peak, return). Craig-Bampton with residual vectors resolves the frame/shaft modes
    # in the band to ~1e-8 (measured 1.3e-8 and MAC 1 - 1e-12), so the test demands
    # 1e-6 and MAC > 0.9999, far tighter than the 0.5 % / 0.95.
    module = _load("textile_shaft")
    result = module.main(tmp_path, n_cams=10, n_angles=37, with_dynamics=False)
    assert result["max_error"] < 1e-6
    assert result["min_mac"] > 0.9999
    sweep = result["sweep"]
    assert sweep.freq_hz.shape == (37, 6)
    assert sweep.form == "symmetric"
    # the cam law is periodic: the sweep closes on itself after one revolution
    # bound: the same frozen pencil at 0 and 2π: eigensolver round-off eps λ_max/λ
    assert np.allclose(sweep.freq_hz[0], sweep.freq_hz[-1], rtol=1e-9)
    assert (tmp_path / "quasi_frequencies.png").stat().st_size > 10_000
    assert (tmp_path / "quasi_frequencies.csv").read_text().count("\n") == 38
    table = np.loadtxt(tmp_path / "quasi_frequencies.csv", delimiter=",", skiprows=1)
    # bound: the CSV holds 10 significant digits: rounding 5e-11 relative
    assert np.allclose(table[:, 1:7], sweep.freq_hz, rtol=1e-9)  # written to 10 digits
    assert (tmp_path / "mac_reduced_vs_full.png").stat().st_size > 5_000
    assert (tmp_path / "coupled_mode_1.png").stat().st_size > 10_000
    assert (tmp_path / "quasi_frequencies.json").stat().st_size > 1_000


FLOAT = re.compile(r"\d+\.\d+(?:e[-+]?\d+)?|\d+e[-+]?\d+")
"""A decimal or exponent float in printed text (integers are not floats)."""


def significant_digits(text: str) -> int:
    """Significant digits of one float as printed: mantissa digits without leading zeros."""
    return len(text.split("e")[0].replace(".", "").lstrip("0"))


def test_knitting_summary_prints_engineering_numbers():
    # what main() returns, with the binary artefacts of real results (16-17 digits)
    module = _load("knitting_machine_chain")
    numbers = {"max_rel_difference": {"assembled": 0.0, "transfer": 2.4123456789012345e-13,
                                      "continuum": 0.020123456789012345},
               "margin_before": -0.012345678901234567, "margin_after": 0.030000000000000027,
               "check_after": 0.029987654321098765, "feasible": True,
               "before": dict(module.INITIAL),
               "after": {"coupling_stiffness": 4567.891234567891,
                         "shaft_diameter": 0.05123456789012345,
                         "follower_mass": 0.41234567890123456,
                         "follower_stiffness": 499999.99999999994},
               "seconds": {"sweeps": 1.2345678901234567, "synthesis": 45.678901234567895}}
    lines = module.summary_lines(numbers)
    floats = [f for line in lines for f in FLOAT.findall(line)]
    assert len(floats) >= 12  # every number above but the exact zero is a float
    assert max(significant_digits(f) for f in floats) <= 6, lines
    text = "\n".join(lines)
    assert "after: coupling_stiffness 4.568 kN·m/rad" in text  # units with the values
    assert "before -1.235 %" in text  # margins in per cent


@pytest.mark.slow
def test_knitting_machine_chain_example(tmp_path):
    # Acceptance example (numbers checked in tests/test_scene_chain.py): it runs
    # from the command line's main() and writes its three charts
    result = _load("knitting_machine_chain").main(tmp_path, n_angles=13, starts=1)
    # bound: transfer roots to 1e-12 relative against eigh's eps λ_max/λ (roundoff.py)
    assert result["max_rel_difference"]["transfer"] < 1e-9  # same problem, 1e-12 roots
    assert result["margin_after"] > result["margin_before"]
    assert [p.name for p in result["plots"]] == ["chain_sweep.png", "campbell.png",
                                                 "synthesis_campbell.png"]
    assert all(p.stat().st_size > 10_000 for p in result["plots"])
