"""The stability chart draws what its title says: red spans exactly over the unstable
speeds, hatched spans over the unconverged ones, and no claim of shading when nothing is
shaded."""

import numpy as np
import pytest

from femmech.analysis.stability import StabilityChart
from femmech.output.stability_charts import stability_figure

RED = (0.8392156862745098, 0.15294117647058825, 0.1568627450980392)  # matplotlib tab:red


def chart(radius, converged=None):
    radius = np.atleast_2d(np.asarray(radius, dtype=float))
    speeds = np.linspace(10.0, 100.0, radius.shape[1])  # rad/s
    tol = 1e-6
    return StabilityChart(speeds, None, radius, radius <= 1 + tol, tol,
                          converged=None if converged is None else np.atleast_2d(converged))


def spans(ax, hatched: bool) -> list[tuple[float, float]]:
    out = []
    for p in ax.patches:
        if bool(p.get_hatch()) == hatched:
            x0 = p.get_x()
            out.append((x0, x0 + p.get_width()))
    return sorted(out)


def test_unstable_speeds_are_shaded_and_only_those():
    radius = [0.5, 0.9, 1.2, 1.5, 0.8, 0.7, 1.1, 0.6]
    c = chart(radius)
    ax = stability_figure(c).axes[0]
    red = spans(ax, hatched=False)
    unstable = c.speeds[np.asarray(radius) > 1 + c.tol]
    assert len(red) == unstable.size
    for (x0, x1), s in zip(red, unstable, strict=True):
        assert x0 < s < x1
    for p in ax.patches:
        assert p.get_facecolor()[:3] == pytest.approx(RED)
    assert "(shaded: unstable)" in ax.get_title()


def test_a_stable_chart_claims_no_shading():
    ax = stability_figure(chart([0.5, 0.6, 0.9, 0.99])).axes[0]
    assert not ax.patches
    assert "shaded" not in ax.get_title()
    assert "stable at every point" in ax.get_title()


def test_unconverged_points_are_hatched_and_named_in_the_title():
    c = chart([0.5, 1.3, 0.9, 0.99], converged=[True, True, False, True])
    ax = stability_figure(c).axes[0]
    assert len(spans(ax, hatched=False)) == 1
    hatched = spans(ax, hatched=True)
    assert len(hatched) == 1
    assert hatched[0][0] < c.speeds[2] < hatched[0][1]
    assert "hatched: not converged" in ax.get_title()
    c = chart([0.5, 0.6, 0.9, 0.99], converged=[True, False, True, True])
    title = stability_figure(c).axes[0].get_title()
    assert "shaded" not in title
    assert "no converged point unstable" in title
