"""Images of coupled machine modes (frame recovered from the superelement + mechanisms)."""

import importlib.util
from pathlib import Path

import numpy as np
from numpy.testing import assert_allclose

from femmech.analysis.reference import full_modes
from femmech.analysis.sweep import sweep
from femmech.output.machine import (
    _mechanism_glyphs,
    coupled_title,
    frame_shape,
    mechanism_decoration,
    plot_coupled_mode,
)

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _textile():
    spec = importlib.util.spec_from_file_location("textile_shaft", EXAMPLES / "textile_shaft.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_coupled_mode_image_shows_recovered_frame(tmp_path):
    reduced, full, model, se = _textile().build(4)
    result = sweep(reduced, [0.8], n_modes=3, keep_vectors=True, track=False)
    x = result.vectors[0, :, 0]
    u = frame_shape(reduced, x)
    # the recovered frame part equals the unreduced coupled mode's frame part (same
    # physics; CB + residual vectors resolve it to ~1e-6, sign fixed by a dot product)
    lam, V = full_modes(full, 0.8, 3)
    u_full = frame_shape(full, V[:, 0].real)
    sign = np.sign(u @ (model.M @ u_full))
    assert_allclose(sign * u, u_full, rtol=0, atol=1e-4 * np.abs(u_full).max())
    glyphs = _mechanism_glyphs(model, reduced, x, u)
    assert len(glyphs) == 4  # one schematic per mounted cam
    assert all(np.isclose(np.linalg.norm(g[2]), 1.0) for g in glyphs)
    path = plot_coupled_mode(model, reduced, x, result.freq_hz[0, 0], tmp_path / "mode.png",
                             angle=0.8, window_size=(400, 300))
    assert path.stat().st_size > 10_000
    assert not list(tmp_path.glob(".*"))  # atomic write left no temporary file


def test_coupled_images_of_one_model_share_one_camera(tmp_path, monkeypatch):
    from femmech.output.renderer import ModeRenderer

    reduced, _, model, _ = _textile().build(4)
    result = sweep(reduced, [0.0, 0.8, 2.0], n_modes=2, keep_vectors=True, track=False)
    cameras = []
    render = ModeRenderer.render

    def spy(self, u, scale, decoration=None):
        cameras.append([tuple(v) for v in self.plotter.camera_position])
        return render(self, u, scale, decoration)

    monkeypatch.setattr(ModeRenderer, "render", spy)
    for a, k in ((0, 0), (1, 1), (2, 0)):  # other angles, another mode
        plot_coupled_mode(model, reduced, result.vectors[a, :, k], result.freq_hz[a, k],
                          tmp_path / f"m{a}{k}.png", angle=result.phi[a],
                          window_size=(200, 150))
    assert len(cameras) == 3
    assert cameras[1] == cameras[0]
    assert cameras[2] == cameras[0]


def test_coupled_title_and_mechanism_glyphs():
    # φ with its symbol and degrees, the speed in rpm (2π · 5 rad/s = 300 rpm)
    assert coupled_title(60.537, np.pi / 2, 2 * np.pi * 5, 1) == \
        "Coupled mode 1: 60.54 Hz at φ = 90°, speed 300 rpm"
    assert coupled_title(12.0, np.deg2rad(22.5)) == "Coupled mode: 12.00 Hz at φ = 22.5°"
    assert coupled_title(12.0, speed=0.0) == "Coupled mode: 12.00 Hz at speed 0 rpm"
    # one mechanism at the origin acting along z, body coordinate 0.5: its block sits
    # OFFSET_FRACTION (0.08) x 2 m below the node and moves with scale x 0.5 along z
    glyph = (np.zeros(3), np.zeros(3), np.array([0.0, 0.0, 1.0]), 0.5)
    deco = mechanism_decoration([glyph], 2.0, 0.01)
    assert [e.label for e in deco.legend] == ["mechanism attachment"]
    corners = deco.points(1.0)
    assert corners.shape == (8, 3)
    # bound: box corners from sums of O(1) dimensions: a few eps
    assert_allclose(corners.mean(axis=0), [0.0, 0.0, -0.16 + 0.5], atol=1e-15)
    assert_allclose(np.ptp(corners, axis=0), [0.08] * 3)  # the block's edge: half the offset
    assert mechanism_decoration([], 2.0, 0.01).legend == ()
