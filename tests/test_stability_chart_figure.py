"""The stability chart draws what its title says, read back from the figure's artists:
red patches exactly over the unstable speeds (both the speed line and the speed ×
parameter plane), hollow markers iff there are unconverged points, one legend, resonance
labels whose boxes overlap nothing, and no claim of shading when nothing is shaded."""

import numpy as np
import pytest
from matplotlib.colors import to_rgb
from matplotlib.patches import Rectangle
from matplotlib.text import Text

from femmech.analysis.stability import StabilityChart
from femmech.output.charts import drawn_extent, overlapping_pairs
from femmech.output.stability_charts import (
    stability_figure,
    unstable_intervals,
)

RED = to_rgb("tab:red")
RPM = 60 / (2 * np.pi)  # rad/s → rpm
TOL = 1e-6


def chart(radius, converged=None, values=None):
    radius = np.atleast_2d(np.asarray(radius, dtype=float))
    speeds = np.linspace(10.0, 100.0, radius.shape[1])  # rad/s
    periods = 2 * np.pi / np.tile(speeds, (radius.shape[0], 1))
    return StabilityChart(speeds, None if values is None else np.asarray(values), radius,
                          radius <= 1 + TOL, TOL, "frame damping ratio ζ (-)", periods,
                          converged=None if converged is None else np.atleast_2d(converged))


def red_patches(ax) -> list:
    return [p for p in ax.patches if not p.get_hatch() and
            p.get_facecolor()[:3] == pytest.approx(RED)]


def x_extent(p) -> tuple[float, float]:
    if isinstance(p, Rectangle):
        return p.get_x(), p.get_x() + p.get_width()
    x = p.get_path().vertices[:, 0]
    return float(x.min()), float(x.max())


def hollow_markers(ax) -> list:
    return [ln for ln in ax.lines if ln.get_marker() == "o" and ln.get_linestyle() == "None"
            and ln.get_markerfacecolor() == "none" and len(ln.get_xdata())]


def speeds_in(patches, speeds) -> np.ndarray:
    """Mask of speeds that lie inside (strictly) any of the patches' x extents."""
    inside = np.zeros(len(speeds), dtype=bool)
    for p in patches:
        x0, x1 = x_extent(p)
        # bound: patch extents are the speeds themselves: ~eps of O(100) values
        inside |= (speeds > x0 - 1e-9) & (speeds < x1 + 1e-9)
    return inside


def test_unstable_speeds_are_shaded_and_only_those():
    radius = [0.5, 0.9, 1.2, 1.5, 0.8, 0.7, 1.1, 0.6]
    c = chart(radius)
    fig = stability_figure(c)
    ax = fig.axes[0]
    red = sorted(red_patches(ax), key=lambda p: x_extent(p)[0])
    unstable = np.asarray(radius) > 1 + TOL
    assert len(red) == 2  # two runs of unstable speeds
    assert speeds_in(red, c.speeds).tolist() == unstable.tolist()
    # each patch spans its run, from the crossing of ρ = 1 + tol to the next one
    expected = unstable_intervals(c.speeds, radius, unstable, np.zeros(8, bool), TOL)
    # bound: the same interval ends from the same interpolation: ~eps of O(100) values
    assert np.ravel([x_extent(p) for p in red]) == pytest.approx(np.ravel(expected),
                                                                 abs=1e-9)
    # by hand: ρ = 0.9 at 22.857 and 1.2 at 35.714 rad/s; ln ρ reaches ln(1 + 1e-6) at
    # t = ln(1/0.9) / ln(1.2/0.9) = 0.36624 of the step: 22.857 + 0.36624 · 12.857
    assert expected[0][0] == pytest.approx(27.566, abs=1e-3)
    assert "(shaded: unstable)" in fig.get_suptitle()
    assert not hollow_markers(ax)


def test_intervals_cross_where_log_radius_reaches_the_limit():
    # ln ρ linear between 40 (ρ = 0.9) and 50 rad/s (ρ = 2): ln(1 + tol) ≈ 0 is reached at
    # t = ln(1/0.9)/ln(2/0.9) = 0.13195 of the step, at 41.3195; the run ends at the end
    s = np.array([30.0, 40.0, 50.0, 60.0])
    r = np.array([0.4, 0.9, 2.0, 3.0])
    ((a, b),) = unstable_intervals(s, r, r > 1 + TOL, np.zeros(4, bool), TOL)
    assert a == pytest.approx(41.3195, abs=1e-4)
    assert b == 60.0
    # next to an unconverged point the boundary is halfway (no verdict there)
    loose = np.array([0, 1, 0, 0], bool)
    assert unstable_intervals(s, r, (r > 1 + TOL) & ~loose, loose, TOL) == [(45.0, 60.0)]


def test_a_stable_chart_claims_no_shading():
    fig = stability_figure(chart([0.5, 0.6, 0.9, 0.99]))
    assert not red_patches(fig.axes[0])
    assert "shaded" not in fig.get_suptitle()
    assert "stable at every point" in fig.get_suptitle()


def test_unconverged_points_are_hollow_on_a_hatched_band_and_named():
    c = chart([0.5, 1.3, 0.9, 0.99], converged=[True, True, False, True])
    fig = stability_figure(c)
    ax = fig.axes[0]
    assert len(red_patches(ax)) == 1
    hatched = [p for p in ax.patches if p.get_hatch()]
    assert len(hatched) == 1
    x0, x1 = x_extent(hatched[0])
    assert x0 < c.speeds[2] < x1
    (dots,) = hollow_markers(ax)
    assert dots.get_xdata().tolist() == [c.speeds[2]]
    assert "hatched: not converged" in fig.get_suptitle()
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend[:2] == ["unstable (ρ > 1 + tol)", "not converged (no verdict)"]
    # the unconverged point is no part of the curve and of no red patch
    assert np.isnan(ax.lines[1].get_ydata()[2])
    assert not speeds_in(red_patches(ax), c.speeds)[2]
    c = chart([0.5, 0.6, 0.9, 0.99], converged=[True, False, True, True])
    title = stability_figure(c).get_suptitle()
    assert "shaded" not in title
    assert "no converged point unstable" in title


def test_the_plane_shades_each_unstable_run_of_each_row():
    rng = np.random.default_rng(3)
    radius = 1.0 + 0.2 * rng.standard_normal((4, 15))  # scattered unstable points
    converged = rng.random((4, 15)) > 0.15
    c = chart(radius, converged, values=[0.0, 0.01, 0.02, 0.03])
    for quantity in ("radius", "growth_rate"):
        fig = stability_figure(c, quantity=quantity)
        ax = fig.axes[0]
        red = red_patches(ax)
        unstable = (radius > 1 + TOL) & converged
        assert len(red) == sum(len(unstable_intervals(c.speeds, radius[i], unstable[i],
                                                      ~converged[i], TOL)) for i in range(4))
        for i, v in enumerate(c.values):
            row = [p for p in red if p.get_y() <= v <= p.get_y() + p.get_height()]
            # the patches of row i cover its unstable speeds and no other speed
            assert speeds_in(row, c.speeds).tolist() == unstable[i].tolist(), (quantity, i)
        (dots,) = hollow_markers(ax)
        assert sorted(zip(dots.get_xdata(), dots.get_ydata(), strict=True)) == sorted(
            (c.speeds[j], c.values[i]) for i, j in zip(*np.nonzero(~converged), strict=True))
        assert "hollow circles: not converged" in fig.get_suptitle()
    c = chart(radius, None, values=[0.0, 0.01, 0.02, 0.03])
    assert not hollow_markers(stability_figure(c).axes[0])


def test_the_radius_axis_is_log_only_beyond_a_decade():
    ax = stability_figure(chart([0.45, 0.9, 0.97, 0.99])).axes[0]
    assert ax.get_yscale() == "linear"
    ax = stability_figure(chart([0.005, 0.5, 0.97, 0.99])).axes[0]
    assert ax.get_yscale() == "log"
    assert "log scale" in ax.get_ylabel()
    # an unconverged value (unreliable) does not decide the scale
    ax = stability_figure(chart([0.0003, 0.76, 0.91, 0.95], [False, True, True, True])).axes[0]
    assert ax.get_yscale() == "linear"


@pytest.mark.parametrize("values", [None, [0.0, 0.01, 0.02]])
def test_crowded_resonance_labels_overlap_nothing(values):
    # twenty marks, pairs 1 % apart and four on the same speed, in rpm; with an
    # unconverged point so that the legend has two entries
    n_rows = 1 if values is None else len(values)
    radius = np.tile(np.linspace(0.9, 1.1, 30), (n_rows, 1))
    converged = np.ones((n_rows, 30), bool)
    converged[0, 5] = False
    c = chart(radius, converged, values)
    marks = {f"2f{k}/{j}": 2 * 2 * np.pi * f / j for k, f in ((1, 40.0), (2, 40.4))
             for j in range(6, 16)}
    marks |= {"f1/1": 60.0, "f2/1": 60.0, "f3/1": 60.0, "f4/1": 60.0}
    fig = stability_figure(c, marks=marks, quantity="growth_rate", speed_unit="rpm")
    ax = fig.axes[0]
    labels = [t for t in ax.texts if t.get_gid() == "mark-label"]
    inside = [s for s in marks.values() if c.speeds[0] <= s <= c.speeds[-1]]
    # every mark inside the range is named, the four coincident ones by one label
    named = [name for t in labels for name in t.get_text().split(", ")]
    assert len(named) == len(inside)
    assert "f1/1, f2/1, f3/1, f4/1" in [t.get_text() for t in labels]
    others = [fig._suptitle, ax.get_legend(), ax.xaxis.label, ax.yaxis.label,
              *[a for a in fig.axes if a is not ax]]
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    boxes = [drawn_extent(a, renderer) for a in labels + others]
    assert overlapping_pairs(boxes) == []
    # the labels sit above the plot, off the data
    top = ax.get_window_extent(renderer).y1
    assert all(Text.get_window_extent(t, renderer).y0 >= top for t in labels)
    assert ax.get_xlabel() == "drive speed (rpm)"
    lo, hi = ax.get_xlim()
    assert lo <= 10 * RPM <= 100 * RPM <= hi <= lo + 1.03 * 90 * RPM  # the range, in rpm


def test_one_legend_below_the_plot():
    c = chart([0.5, 1.3, 0.9, 0.99], converged=[True, True, False, True])
    fig = stability_figure(c, speed_unit="rpm")
    ax = fig.axes[0]
    assert not fig.legends
    assert [a.get_legend() is not None for a in fig.axes] == [True]
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    legend = ax.get_legend().get_window_extent(renderer)
    assert legend.y1 <= ax.xaxis.get_tightbbox(renderer).y0 + 0.5  # below the x label


def test_damping_levels_are_named_curves_over_speed():
    """layout='lines' (what plot_speed_study draws): one curve per damping level, each named
    in the legend by its value and drawn from the first to the last speed, the unstable run
    of a level as a red segment on its curve; a plane of four levels drew wide flat bands
    that no legend named."""
    zetas = [0.0025, 0.005, 0.01, 0.02]
    radius = np.full((4, 12), 0.9)
    radius[0, 5:7] = 1.01  # the lightest damping crosses the limit at two speeds
    c = chart(radius, values=zetas)
    fig = stability_figure(c, quantity="growth_rate", speed_unit="rpm", layout="lines")
    ax = fig.axes[0]
    assert len(fig.axes) == 1  # no colour bar: the legend names the levels
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert [f"frame damping ratio ζ = {z:g}" for z in zetas] == labels[:4]
    assert labels[4:] == ["unstable (ρ > 1 + tol)", "stability limit (growth rate 0)"]
    lo, hi = ax.get_xlim()
    # bound: the limits are the speeds ± 1 % of the span, computed in float: ~eps of 1e3
    assert lo <= c.speeds[0] * RPM <= lo + 0.011 * (hi - lo)
    assert hi - 0.011 * (hi - lo) <= c.speeds[-1] * RPM <= hi
    red = [line for line in ax.get_lines() if line.get_linewidth() > 2
           and to_rgb(line.get_color()) == pytest.approx(RED)]
    assert len(red) == 1
    assert red[0].get_xdata() == pytest.approx(c.speeds[5:7] * RPM)
    with pytest.raises(ValueError, match="layout"):
        stability_figure(c, layout="bands")
