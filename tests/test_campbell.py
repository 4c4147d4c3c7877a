"""Campbell diagrams (femmech.output.campbell)."""

from __future__ import annotations

import numpy as np
import pytest

from femmech.chain.synthesis import FrequencyBands
from femmech.output.campbell import campbell_figure, plot_campbell, plot_margins


def _bands(centres, spread=0.02, n_angles=12):
    """Branches f_i(φ) = c_i (1 + spread sin φ), Hz: band c_i (1 ± spread)."""
    phi = np.linspace(0, 2 * np.pi, n_angles, endpoint=False)
    return FrequencyBands(phi, np.outer(1 + spread * np.sin(phi), centres))


def _gids(fig, gid):
    ax = fig.axes[0]
    artists = list(ax.lines) + list(ax.patches) + list(ax.texts)
    return [a for a in artists if a.get_gid() == gid]


def test_campbell_png_and_artists(tmp_path):
    # 600-900 rpm, K = 3: bands 10-15, 20-30, 30-45 Hz; y axis to 1.15 × 45 × 1.05 = 54 Hz
    bands = _bands([8.0, 25.0, 40.0, 70.0])  # 25 Hz meets 2·n and 40 Hz meets 3·n
    before = _bands([12.0, 26.0, 41.0, 71.0])
    path = plot_campbell(bands, (600, 900), 3, tmp_path / "c" / "campbell.png",
                         before=before, margin=0.05)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    fig = campbell_figure(bands, (600, 900), 3, before=before, margin=0.05)
    assert len(_gids(fig, "harmonic")) == 3
    assert len(_gids(fig, "harmonic-label")) == 3
    assert len(_gids(fig, "forbidden")) == 3
    assert len(_gids(fig, "branch-band")) == 3  # 70 Hz lies above the axis: not drawn
    assert len(_gids(fig, "branch-mean")) == 3
    assert len(_gids(fig, "before-band")) == 3
    assert len(_gids(fig, "speed-range")) == 1
    # resonances: 25 Hz band [24.5, 25.5] on 2·n at 735-765 rpm; 40 Hz [39.2, 40.8] on 3·n
    # at 784-816 rpm; 8 Hz and the 1·n band 10-15 Hz do not meet
    marks = _gids(fig, "crossing")
    assert len(marks) == 2
    np.testing.assert_allclose(sorted(m.get_xdata()[0] for m in marks), [750.0, 800.0],
                               rtol=1e-3)  # at the mean of each band (sin mean ≈ 0)
    # before: 12 Hz inside band 1 (720 rpm), 26 Hz on 2·n, 41 Hz on 3·n
    assert len(_gids(fig, "crossing-before")) == 3
    assert "2 resonances" in fig._suptitle.get_text()
    assert "1 higher branch not shown" in fig._suptitle.get_text()


def test_campbell_without_margin_has_no_hatching():
    fig = campbell_figure(np.array([[8.0, 25.0]]), (600, 900), 4)
    assert _gids(fig, "forbidden") == []
    assert len(_gids(fig, "harmonic")) == 4


def test_cluster_gets_one_label():
    fig = campbell_figure(_bands([8.0, 25.0, 25.01, 25.02]), (600, 900), 3)
    labels = [t.get_text() for t in _gids(fig, "branch-label")]
    assert labels == ["f1", "f2–f4"]


@pytest.mark.parametrize("speed", [(900, 600), (0, 600), (-5, 10)])
def test_bad_speed_range(speed):
    with pytest.raises(ValueError, match="speed_rpm"):
        campbell_figure(_bands([8.0]), speed, 3)


def test_no_branches():
    with pytest.raises(ValueError, match="no branches"):
        campbell_figure(np.zeros((12, 0)), (600, 900), 3)
    with pytest.raises(ValueError, match="harmonics"):
        campbell_figure(_bands([8.0]), (600, 900), 0)


def test_margin_chart(tmp_path):
    class Result:  # the fields plot_margins reads
        speed_rpm, harmonics, required = (600.0, 900.0), 3, 0.05
        bands_before, bands_after = _bands([12.0, 25.0]), _bands([9.0, 32.0])
    path = plot_margins(Result(), tmp_path / "margins.png")
    assert path.read_bytes()[:4] == b"\x89PNG"
