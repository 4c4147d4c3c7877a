"""Images of coupled machine modes (frame recovered from the superelement + mechanisms)."""

import importlib.util
from pathlib import Path

import numpy as np
from numpy.testing import assert_allclose

from femmech.analysis.reference import full_modes
from femmech.analysis.sweep import sweep
from femmech.output.machine import _mechanism_glyphs, frame_shape, plot_coupled_mode

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
