"""Stability charts: Floquet spectral radius over drive speed (and a second parameter),
with the unstable region shaded and unconverged points marked; speed studies.

What a chart draws, and nothing else is claimed by its title or legend:

* unstable speeds (converged points with ρ = max|μ| > 1 + tol) as red patches, one per
  run of unstable speeds (per row of the second parameter), from boundary to boundary
  (:func:`unstable_intervals`);
* unconverged points as hollow circles at their (unreliable) value, over a grey hatched
  band on the speed line; no verdict is drawn for them;
* predicted resonance speeds as dotted lines, labelled above the plot without overlaps
  (:func:`femmech.output.charts.label_vertical_marks`);
* one legend, outside the plot.

Uses output.export (atomic writes) and output.charts; charts and
studies (:mod:`femmech.analysis.stability`) come in duck-typed, and matplotlib is imported
inside the functions.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from femmech.output.charts import (
    label_vertical_marks,
    legend_below,
    needs_log_scale,
    speed_scale,
)
from femmech.output.export import atomic_path

UNSTABLE_LABEL = "unstable (ρ > 1 + tol)"
LOOSE_LABEL = "not converged (no verdict)"
UNSTABLE_COLOR = "tab:red"


def runs(mask) -> list[tuple[int, int]]:
    """First and last index (inclusive) of each run of True in a 1-D mask."""
    m = np.concatenate([[False], np.asarray(mask, dtype=bool), [False]])
    d = np.diff(m.astype(int))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1, strict=True))


def _crossing(s0, s1, r0, r1, level) -> float:
    """Speed between s0 and s1 where ln ρ, linear in speed, reaches ln(level)."""
    if not (np.isfinite(r0) and np.isfinite(r1) and r0 > 0 and r1 > 0) or r0 == r1:
        return 0.5 * (s0 + s1)
    t = (np.log(level) - np.log(r0)) / (np.log(r1) - np.log(r0))
    return float(s0 + np.clip(t, 0.0, 1.0) * (s1 - s0))


def unstable_intervals(speeds, radius, unstable, loose, tol: float) -> list[tuple[float,
                                                                                 float]]:
    """Speed intervals of one row of a chart over which it is unstable.

    Parameters
    ----------
    speeds : array_like (n,)
        Increasing speeds (any unit).
    radius : array_like (n,)
        Spectral radii ρ.
    unstable, loose : array_like (n,) of bool
        Converged points with ρ > 1 + tol; unconverged points (no verdict).
    tol : float

    Returns
    -------
    list of (start, end)
        One interval per run of unstable points. Next to a converged stable point the
        boundary is where ln ρ, interpolated linearly in speed, crosses ln(1 + tol); next
        to an unconverged point it is halfway; at the ends of the range it is the end
        speed. Every unstable speed lies inside an interval, every other speed outside.
    """
    s, r = np.asarray(speeds, dtype=float), np.asarray(radius, dtype=float)
    loose = np.asarray(loose, dtype=bool)
    out = []
    for i0, i1 in runs(unstable):
        a = s[0] if i0 == 0 else (0.5 * (s[i0 - 1] + s[i0]) if loose[i0 - 1] else
                                  _crossing(s[i0 - 1], s[i0], r[i0 - 1], r[i0], 1 + tol))
        b = s[-1] if i1 == s.size - 1 else (0.5 * (s[i1] + s[i1 + 1]) if loose[i1 + 1] else
                                            _crossing(s[i1], s[i1 + 1], r[i1], r[i1 + 1],
                                                      1 + tol))
        out.append((float(a), float(b)))
    return out


def loose_intervals(speeds, loose) -> list[tuple[float, float]]:
    """Speed bands of the runs of unconverged points: halfway to the neighbours."""
    s = np.asarray(speeds, dtype=float)
    edges = np.concatenate([[s[0]], 0.5 * (s[1:] + s[:-1]), [s[-1]]])
    return [(float(edges[i0]), float(edges[i1 + 1])) for i0, i1 in runs(loose)]


def chart_legend(unstable: np.ndarray, loose: np.ndarray, loose_mark: str = "hatched") -> str:
    """What the shading of a stability chart shows, for its title: only what is drawn."""
    if unstable.any():
        parts = ["shaded: unstable"]
    else:
        parts = ["no converged point unstable" if loose.any() else "stable at every point"]
    if loose.any():
        parts.append(f"{loose_mark}: not converged, no verdict")
    return "; ".join(parts)


def stability_figure(chart, title: str = "Floquet stability", speed_label: str | None = None,
                     marks: dict | None = None, quantity: str = "radius",
                     speed_unit: str = "rad/s", layout: str = "plane"):
    """The matplotlib Figure of :func:`plot_stability_chart` (same arguments)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    scale = speed_scale(speed_unit)
    if quantity not in ("radius", "growth_rate"):
        raise ValueError(f"quantity must be 'radius' or 'growth_rate', got {quantity!r}")
    if layout not in ("plane", "lines"):
        raise ValueError(f"layout must be 'plane' or 'lines', got {layout!r}")
    speeds, radius = scale * np.asarray(chart.speeds), np.asarray(chart.spectral_radius)
    if speeds.size < 2 or radius.shape != (radius.shape[0], speeds.size):
        raise ValueError(f"the chart needs >= 2 speeds and radii (n_values, {speeds.size}),"
                         f" got {speeds.size} speeds and radii {radius.shape}")
    loose = chart.unconverged.reshape(radius.shape)
    unstable = ~np.asarray(chart.stable) & ~loose
    fig = Figure(figsize=(8.0, 4.8), dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    line = chart.values is None or len(chart.values) < 2
    draw = _draw_speed_line if line else (_draw_speed_lines if layout == "lines"
                                          else _draw_speed_plane)
    handles = draw(fig, ax, chart, speeds, radius, loose, unstable, quantity)
    ax.set_xlabel(speed_label or f"drive speed ({speed_unit})")
    mark = "hatched" if line else "hollow circles"
    legend = f"({chart_legend(unstable, loose, mark)})"
    whole = f"{title} {legend}"
    fig.suptitle(whole if len(whole) <= 90 else f"{textwrap.fill(title, 90)}\n{legend}",
                 fontsize=11)
    if handles:
        legend_below(fig, ax, list(handles.values()), list(handles))
    _draw_speed_marks(fig, ax, marks, scale)
    return fig


def _draw_speed_line(fig, ax, chart, speeds, radius, loose, unstable, quantity: str) -> dict:
    """One curve over speed (no second parameter): unstable runs shaded, loose ones
    hatched with hollow circles. Returns the legend entries {label: handle}."""
    if quantity == "radius":
        y, limit = radius[0], 1.0 + chart.tol
        log = needs_log_scale(np.append(y[~loose[0]], limit))  # converged values decide
        ax.set_ylabel("spectral radius max|μ|" + (" (log scale)" if log else ""))
        if log:
            ax.set_yscale("log")
            y = np.where(y > 0, y, np.nan)
        limit_label = "stability limit ρ = 1 + tol"
    else:
        y, limit = chart.growth_rate[0], 0.0
        ax.set_ylabel("growth rate ln(max|μ|)/T (1/s)")
        limit_label = "stability limit (growth rate 0)"
    limit_line = ax.axhline(limit, color=UNSTABLE_COLOR, lw=0.8, ls="--")
    ax.plot(speeds, np.where(loose[0], np.nan, y), color="k", lw=1.2, marker="o", ms=2.5)
    handles = {}
    for a, b in unstable_intervals(speeds, radius[0], unstable[0], loose[0], chart.tol):
        handles[UNSTABLE_LABEL] = ax.axvspan(a, b, color=UNSTABLE_COLOR, alpha=0.25, lw=0)
    if loose[0].any():
        for a, b in loose_intervals(speeds, loose[0]):
            band = ax.axvspan(a, b, facecolor="none", edgecolor="0.45", hatch="///", lw=0)
        finite = np.isfinite(y) & loose[0]
        (dots,) = ax.plot(speeds[finite], y[finite], ls="none", marker="o", ms=6,
                          mfc="none", mec="0.2", mew=1.2)
        handles[LOOSE_LABEL] = (band, dots)
    handles[limit_label] = limit_line
    ax.grid(True, lw=0.3, alpha=0.5)
    span = speeds[-1] - speeds[0]
    ax.set_xlim(speeds[0] - 0.01 * span, speeds[-1] + 0.01 * span)
    return handles


def _draw_speed_plane(fig, ax, chart, speeds, radius, loose, unstable, quantity: str) -> dict:
    """The (speed, parameter) plane: the growth rate as colours (``growth_rate``), each
    run of unstable speeds of each parameter row as a red rectangle (rows end halfway
    between parameter values, like the colour cells), unconverged points as hollow
    circles. Returns the legend entries {label: handle}."""
    from matplotlib import patheffects
    from matplotlib.patches import Rectangle

    values = np.asarray(chart.values, dtype=float)
    order = np.argsort(values)
    values, radius, loose, unstable = values[order], radius[order], loose[order], \
        unstable[order]
    if quantity == "growth_rate":
        mesh = ax.pcolormesh(speeds, values, np.asarray(chart.growth_rate)[order],
                             shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label="growth rate ln(max|μ|)/T (1/s)")
    edges = np.concatenate([[values[0]], 0.5 * (values[1:] + values[:-1]), [values[-1]]])
    handles = {}
    for i in range(values.size):
        for a, b in unstable_intervals(speeds, radius[i], unstable[i], loose[i], chart.tol):
            handles[UNSTABLE_LABEL] = ax.add_patch(Rectangle(
                (a, edges[i]), b - a, edges[i + 1] - edges[i], facecolor=UNSTABLE_COLOR,
                alpha=0.7, edgecolor=UNSTABLE_COLOR, lw=0.8))
    if loose.any():
        S, V = np.meshgrid(speeds, values)
        (dots,) = ax.plot(S[loose], V[loose], ls="none", marker="o", ms=7, mfc="none",
                          mec="white", mew=1.3, path_effects=[
                              patheffects.withStroke(linewidth=2.6, foreground="k")])
        handles[LOOSE_LABEL] = dots
    ax.set_xlim(speeds[0], speeds[-1])  # cells end where the patches do
    ax.set_ylim(values[0], values[-1])
    ax.set_ylabel(chart.parameter_name)
    return handles


def _draw_speed_lines(fig, ax, chart, speeds, radius, loose, unstable, quantity: str) -> dict:
    """One curve over speed per value of the second parameter, in the legend by its value
    (few values, e.g. frame damping levels, whose curves a plane would draw as wide flat
    bands): the converged points joined, unstable runs as thick red segments on their
    curve, unconverged points as hollow circles. Returns the legend entries."""
    from matplotlib import colormaps

    values = np.asarray(chart.values, dtype=float)
    order = np.argsort(values)
    if quantity == "radius":
        y, limit, ylabel = radius, 1.0 + chart.tol, "spectral radius max|μ|"
        limit_label = "stability limit ρ = 1 + tol"
    else:
        y, limit = np.asarray(chart.growth_rate, dtype=float), 0.0
        ylabel, limit_label = "growth rate ln(max|μ|)/T (1/s)", "stability limit (growth rate 0)"
    name = chart.parameter_name.split(" (")[0] if chart.parameter_name else "value"
    colours = colormaps["viridis"](np.linspace(0.0, 0.85, values.size))
    handles, marked = {}, {}  # the levels first in the legend, then the marks
    for colour, i in zip(colours, order, strict=True):
        (curve,) = ax.plot(speeds, np.where(loose[i], np.nan, y[i]), color=colour, lw=1.4,
                           marker="o", ms=2.5)
        handles[f"{name} = {values[i]:.4g}"] = curve
        for a, b in runs(unstable[i]):
            (bad,) = ax.plot(speeds[a:b + 1], y[i, a:b + 1], color=UNSTABLE_COLOR, lw=4.0,
                             alpha=0.7, solid_capstyle="butt")
            marked[UNSTABLE_LABEL] = bad
        if loose[i].any():
            (dots,) = ax.plot(speeds[loose[i]], y[i, loose[i]], ls="none", marker="o", ms=6,
                              mfc="none", mec=colour, mew=1.2)
            marked[LOOSE_LABEL] = dots
    marked[limit_label] = ax.axhline(limit, color=UNSTABLE_COLOR, lw=0.8, ls="--")
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3, alpha=0.5)
    span = speeds[-1] - speeds[0]
    ax.set_xlim(speeds[0] - 0.01 * span, speeds[-1] + 0.01 * span)
    return handles | marked


def _draw_speed_marks(fig, ax, marks: dict | None, scale: float) -> None:
    """A dotted vertical line at each marked speed (rad/s, drawn × scale) inside the
    speed range, labelled above the plot (no two labels overlap)."""
    lo, hi = sorted(ax.get_xlim())
    inside = {str(k): scale * v for k, v in (marks or {}).items() if lo <= scale * v <= hi}
    for x in inside.values():
        ax.axvline(x, color="0.3", lw=0.7, ls=":")
    if inside:
        label_vertical_marks(fig, ax, list(inside.values()), list(inside))


def plot_stability_chart(chart, filename, title: str = "Floquet stability",
                         speed_label: str | None = None,
                         marks: dict | None = None, quantity: str = "radius",
                         speed_unit: str = "rad/s", layout: str = "plane") -> Path:
    """Draw a :class:`~femmech.analysis.stability.StabilityChart` as a PNG.

    With a second parameter and ``layout="plane"``: the (speed, parameter) plane, each run
    of unstable speeds (spectral radius > 1 + tol, parametric resonances) of each
    parameter value a red rectangle; with ``quantity="growth_rate"`` the growth rate as
    colours. With ``layout="lines"`` (for a few values, e.g. damping levels): one curve
    over speed per parameter value, each named in the legend by its value, unstable runs
    as thick red segments on their curve. Without a second parameter: over
    speed, the spectral radius (``quantity="radius"``; log scale only if it spans more
    than a decade) or the growth rate ln(max|μ|)/T in 1/s (``quantity="growth_rate"``,
    where resonances show as bumps at any speed), with unstable speed ranges shaded.
    Points whose monodromy matrix missed its tolerance (``chart.converged`` False) are
    hollow circles (on a hatched grey band over speed), never part of the curve or of a
    shaded region. ``marks`` ({label: speed}) adds dotted vertical lines, e.g. the
    predicted resonance speeds 2ω_k/j, in rad/s like the chart; their labels sit above the
    plot without overlapping. ``speed_unit`` ("rad/s", "rpm" or "Hz") is the unit of the
    speed axis; ``speed_label`` overrides its label.
    """
    fig = stability_figure(chart, title, speed_label, marks, quantity, speed_unit, layout)
    with atomic_path(filename) as tmp:
        fig.savefig(tmp, format="png")
    return Path(filename)


def plot_speed_study(study, out_dir, name: str, speed_unit: str = "rpm") -> list[Path]:
    """The two pictures of a :class:`~femmech.analysis.stability.SpeedStudy` (PNG).

    ``stability_speed.png``: growth rate over speed at the nominal frame damping;
    ``stability_chart.png`` (with damping ratios): growth rate over speed, one curve per
    frame damping ratio named in the legend (``layout="lines"``: the growth rate of a
    stable machine is about -ζω of its least damped mode, nearly constant over speed, so a
    (speed, ζ) plane of a few ratios shows wide flat bands), unstable runs in red. Both
    cover the study's speeds and mark the predicted resonance speeds; ``name`` starts the
    titles; ``speed_unit`` ("rpm", "rad/s" or "Hz") is the speed axis' unit.
    """
    out = Path(out_dir)
    files = [plot_stability_chart(study.line, out / "stability_speed.png",
                                  title=f"{name}: growth rate, frame ζ = {study.zeta:g}",
                                  marks=study.marks, quantity="growth_rate",
                                  speed_unit=speed_unit)]
    if study.chart is not None:
        files.append(plot_stability_chart(
            study.chart, out / "stability_chart.png", marks=study.marks,
            title=f"{name}: growth rate over speed per frame damping ratio",
            quantity="growth_rate", speed_unit=speed_unit, layout="lines"))
    return files
