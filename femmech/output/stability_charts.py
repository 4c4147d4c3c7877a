"""Stability charts: Floquet spectral radius over drive speed (and a second parameter),
with the unstable region shaded and unconverged points marked; speed studies.

Stage 6 (output): uses only output.export (atomic writes); charts and studies
(:mod:`femmech.analysis.stability`) come in duck-typed, and matplotlib is imported
inside the functions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from femmech.output.export import atomic_path

_LOOSE_LABEL = "not converged (value unreliable)"


def chart_legend(unstable: np.ndarray, loose: np.ndarray) -> str:
    """What the shading of a stability chart shows, for its title: only what is drawn."""
    if unstable.any():
        parts = ["shaded: unstable"]
    else:
        parts = ["no converged point unstable" if loose.any() else "stable at every point"]
    if loose.any():
        parts.append("hatched: not converged, no verdict")
    return "; ".join(parts)


def stability_figure(chart, title: str = "Floquet stability", speed_label: str | None = None,
                     marks: dict | None = None, quantity: str = "radius",
                     speed_unit: str = "rad/s"):
    """The matplotlib Figure of :func:`plot_stability_chart` (same arguments)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    scales = {"rad/s": 1.0, "Hz": 1 / (2 * np.pi), "rpm": 60 / (2 * np.pi)}
    if speed_unit not in scales:
        raise ValueError(f"speed_unit must be one of {sorted(scales)}, got {speed_unit!r}")
    scale = scales[speed_unit]
    speed_label = speed_label or f"drive speed ({speed_unit})"
    speeds, radius = scale * np.asarray(chart.speeds), np.asarray(chart.spectral_radius)
    loose = chart.unconverged.reshape(radius.shape)
    unstable = ~np.asarray(chart.stable) & ~loose
    if speeds.size < 2 or radius.shape != (radius.shape[0], speeds.size):
        raise ValueError(f"the chart needs >= 2 speeds and radii (n_values, {speeds.size}),"
                         f" got {speeds.size} speeds and radii {radius.shape}")
    fig = Figure(figsize=(7.0, 4.5), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    if quantity not in ("radius", "growth_rate"):
        raise ValueError(f"quantity must be 'radius' or 'growth_rate', got {quantity!r}")
    if chart.values is None or len(chart.values) < 2:
        _draw_speed_line(ax, chart, speeds, radius, loose, unstable, quantity)
    else:
        _draw_speed_plane(fig, ax, chart, speeds, radius, loose, unstable, quantity)
    _draw_speed_marks(ax, marks, scale)
    ax.set_xlabel(speed_label)
    ax.set_title(f"{title} ({chart_legend(unstable, loose)})")
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        unique = dict(zip(labels, handles, strict=True))
        ax.legend(unique.values(), unique.keys(), fontsize=7, loc="best")
    fig.tight_layout()
    return fig


def _draw_speed_line(ax, chart, speeds, radius, loose, unstable, quantity: str) -> None:
    """One curve over speed (no second parameter): unstable bands shaded, loose ones hatched."""
    if quantity == "radius":
        y = np.maximum(radius[0], 1e-300)
        ax.set_yscale("log")
        ax.axhline(1.0 + chart.tol, color="tab:red", lw=0.8, ls="--")
        ax.set_ylabel("spectral radius max|μ|")
    else:
        y = chart.growth_rate[0]
        ax.axhline(0.0, color="tab:red", lw=0.8, ls="--")
        ax.set_ylabel("growth rate ln(max|μ|)/T (1/s)")
    ax.plot(speeds, np.where(loose[0], np.nan, y), color="k", lw=1.2)
    edges = np.concatenate([[speeds[0]], 0.5 * (speeds[1:] + speeds[:-1]), [speeds[-1]]])
    for j in np.flatnonzero(unstable[0]):
        ax.axvspan(edges[j], edges[j + 1], color="tab:red", alpha=0.25, lw=0,
                   label="unstable")
    for j in np.flatnonzero(loose[0]):
        ax.axvspan(edges[j], edges[j + 1], facecolor="none", edgecolor="0.45",
                   hatch="///", lw=0, label=_LOOSE_LABEL)
    if loose[0].any():
        finite = np.isfinite(y) & loose[0]
        ax.plot(speeds[finite], y[finite], ls="none", marker="x", color="0.45", ms=5)


def _draw_speed_plane(fig, ax, chart, speeds, radius, loose, unstable, quantity: str) -> None:
    """The (speed, parameter) plane: unstable regions shaded, their boundary drawn."""
    values = np.asarray(chart.values)
    if quantity == "growth_rate":
        mesh = ax.pcolormesh(speeds, values, chart.growth_rate, shading="nearest",
                             cmap="viridis")
        fig.colorbar(mesh, ax=ax, label="growth rate ln(max|μ|)/T (1/s)")
    ax.contourf(speeds, values, unstable.astype(float), levels=[0.5, 1.5],
                colors=["tab:red"], alpha=0.35)
    ax.contour(speeds, values, np.log(np.maximum(radius, 1e-300)),
               levels=[np.log1p(chart.tol)], colors=["tab:red"], linewidths=0.8)
    if loose.any():
        S, V = np.meshgrid(speeds, values)
        ax.scatter(S[loose], V[loose], marker="s", s=60, facecolor="white",
                   edgecolor="0.3", hatch="////", lw=0.6, zorder=3, label=_LOOSE_LABEL)
    ax.set_ylabel(chart.parameter_name)


def _draw_speed_marks(ax, marks: dict | None, scale: float) -> None:
    """A dotted vertical line with its label at each marked speed (rad/s, drawn × scale)."""
    for label, speed in (marks or {}).items():
        ax.axvline(scale * speed, color="0.3", lw=0.7, ls=":")
        ax.annotate(str(label), (scale * speed, 1.0), xycoords=("data", "axes fraction"),
                    xytext=(-2, -4), textcoords="offset points", rotation=90, va="top",
                    ha="right", fontsize=7)


def plot_stability_chart(chart, filename, title: str = "Floquet stability",
                         speed_label: str | None = None,
                         marks: dict | None = None, quantity: str = "radius",
                         speed_unit: str = "rad/s") -> Path:
    """Draw a :class:`~femmech.analysis.stability.StabilityChart` as a PNG.

    With a second parameter: the (speed, parameter) plane with the unstable regions
    (spectral radius > 1 + tol, parametric resonances) shaded and the boundary drawn.
    Without: over speed, the spectral radius (log scale, ``quantity="radius"``) or the
    growth rate ln(max|μ|)/T in 1/s (``quantity="growth_rate"``, where resonances show
    as bumps at any speed), with unstable speed ranges shaded. Points whose monodromy
    matrix missed its tolerance (``chart.converged`` False) are hatched grey and drawn
    as crosses off the curve, never as part of it. ``marks``
    ({label: speed}) adds labelled vertical lines, e.g. the predicted resonance speeds
    2ω_k/j, in rad/s like the chart. ``speed_unit`` ("rad/s", "Hz" or "rpm") is the unit
    of the speed axis; ``speed_label`` overrides its label.
    """
    fig = stability_figure(chart, title, speed_label, marks, quantity, speed_unit)
    with atomic_path(filename) as tmp:
        fig.savefig(tmp, format="png")
    return Path(filename)


def plot_speed_study(study, out_dir, name: str, speed_unit: str = "rpm") -> list[Path]:
    """The two pictures of a :class:`~femmech.analysis.stability.SpeedStudy` (PNG).

    ``stability_speed.png``: growth rate over speed at the nominal frame damping;
    ``stability_chart.png`` (with damping ratios): growth rate over speed and frame
    damping, unstable regions shaded. Both mark the predicted resonance speeds; ``name``
    starts the titles.
    """
    out = Path(out_dir)
    files = [plot_stability_chart(study.line, out / "stability_speed.png",
                                  title=f"{name}: growth rate, frame ζ = {study.zeta:g}",
                                  marks=study.marks, quantity="growth_rate",
                                  speed_unit=speed_unit)]
    if study.chart is not None:
        files.append(plot_stability_chart(
            study.chart, out / "stability_chart.png", marks=study.marks,
            title=f"{name}: growth rate over speed and frame damping",
            quantity="growth_rate", speed_unit=speed_unit))
    return files
