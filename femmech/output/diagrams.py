"""Diagrams and tables of sweeps: MAC matrices (PNG), quasi-mode tables (CSV, JSON).

The quasi-eigenfrequency diagram itself is
:func:`femmech.mechanisms.plot_quasi_frequencies`, which takes any result with ``phi``
and ``freq_hz`` (mechanism-only quasi-modes or a coupled :class:`Sweep`).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from femmech.output.export import atomic_path


def plot_mac(mac: np.ndarray, filename, row_label: str = "mode", col_label: str = "mode",
             title: str = "MAC") -> Path:
    """Draw a MAC matrix (values 0..1, shape (p, q)) as an annotated heat map PNG."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    mac = np.asarray(mac, dtype=float)
    if mac.ndim != 2:
        raise ValueError(f"mac must be a 2D array, got shape {mac.shape}")
    fig = Figure(figsize=(1.2 + 0.5 * mac.shape[1], 1.0 + 0.5 * mac.shape[0]), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    image = ax.imshow(mac, vmin=0.0, vmax=1.0, cmap="viridis", origin="upper")
    fig.colorbar(image, ax=ax, shrink=0.8)
    ax.set_xticks(range(mac.shape[1]), [str(j + 1) for j in range(mac.shape[1])])
    ax.set_yticks(range(mac.shape[0]), [str(i + 1) for i in range(mac.shape[0])])
    ax.set_xlabel(col_label)
    ax.set_ylabel(row_label)
    ax.set_title(title)
    if mac.size <= 400:
        for (i, j), value in np.ndenumerate(mac):
            ax.text(j, i, f"{value:.2f}", ha="center", va="center", fontsize=7,
                    color="white" if value < 0.6 else "black")
    fig.tight_layout()
    with atomic_path(filename) as tmp:
        fig.savefig(tmp, format="png")
    return Path(filename)


def write_sweep_csv(sweep, filename) -> Path:
    """Table of a sweep: angle (deg), then per branch frequency (Hz), damping ratio, MAC step."""
    n = sweep.freq_hz.shape[1]
    header = ["angle_deg"] + [f"f{k + 1}_hz" for k in range(n)] + \
        [f"zeta{k + 1}" for k in range(n)] + [f"mac_step{k + 1}" for k in range(n)]
    rows = np.column_stack([np.rad2deg(sweep.phi), sweep.freq_hz, sweep.damping_ratio,
                            sweep.mac_step])
    with atomic_path(filename) as tmp:
        np.savetxt(tmp, rows, delimiter=",", header=",".join(header), comments="",
                   fmt="%.10g")
    return Path(filename)


def write_sweep_json(sweep, filename, metadata: dict | None = None) -> Path:
    """The sweep's angles (rad), tracked frequencies (Hz), damping ratios and form as JSON."""
    data = {
        "form": sweep.form,
        "phi_rad": sweep.phi.tolist(),
        "freq_hz": sweep.freq_hz.tolist(),
        "damping_ratio": sweep.damping_ratio.tolist(),
        "mac_step": sweep.mac_step.tolist(),
        "metadata": metadata or {},
    }
    with atomic_path(filename) as tmp:
        Path(tmp).write_text(json.dumps(data, indent=1))
    return Path(filename)


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
    else:
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
    for label, speed in (marks or {}).items():
        ax.axvline(scale * speed, color="0.3", lw=0.7, ls=":")
        ax.annotate(str(label), (scale * speed, 1.0), xycoords=("data", "axes fraction"),
                    xytext=(-2, -4), textcoords="offset points", rotation=90, va="top",
                    ha="right", fontsize=7)
    ax.set_xlabel(speed_label)
    ax.set_title(f"{title} ({chart_legend(unstable, loose)})")
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        unique = dict(zip(labels, handles, strict=True))
        ax.legend(unique.values(), unique.keys(), fontsize=7, loc="best")
    fig.tight_layout()
    return fig


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


def plot_time_histories(t, panels: dict, filename, title: str = "",
                        xlabel: str = "time (s)") -> Path:
    """Time histories in stacked panels sharing the time axis (PNG).

    Parameters
    ----------
    t : array_like (n_t,)
        Times (or drive angles: set ``xlabel``).
    panels : dict
        ``{y_label: {curve_label: values (n_t,)}}``, one panel per entry, top to bottom;
        the y label carries the unit, e.g. ``"force (kN)"``.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    t = np.asarray(t, dtype=float)
    if not panels:
        raise ValueError("plot_time_histories needs at least one panel")
    for ylabel, curves in panels.items():
        for label, values in curves.items():
            if np.shape(values) != t.shape:
                raise ValueError(f"panel {ylabel!r}, curve {label!r}: expected {t.shape[0]}"
                                 f" values (one per time), got shape {np.shape(values)}")
    fig = Figure(figsize=(7.5, 1.0 + 2.0 * len(panels)), dpi=120)
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
    for ax, (ylabel, curves) in zip(axes, panels.items(), strict=True):
        for label, values in curves.items():
            ax.plot(t, values, lw=1.0, label=label)
        ax.set_ylabel(ylabel)
        ax.grid(True, lw=0.3)
        if len(curves) > 1:
            ax.legend(fontsize=7, loc="upper right", ncols=min(4, len(curves)))
    axes[-1].set_xlabel(xlabel)
    if title:
        axes[0].set_title(title)
    fig.tight_layout()
    with atomic_path(filename) as tmp:
        fig.savefig(tmp, format="png")
    return Path(filename)


def plot_orbit(x, y, filename, xlabel: str = "x", ylabel: str = "y", title: str = "",
               equal: bool = True) -> Path:
    """Orbit y(x) of a periodic motion, e.g. a bearing centre over one cycle (PNG).

    The start point is marked with a dot and the direction of travel with an arrow;
    ``equal`` uses equal axis scales (displacements in the same unit).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if x.shape != y.shape or x.ndim != 1 or x.size < 3:
        raise ValueError(f"x and y must be 1D with the same length >= 3, got {x.shape},"
                         f" {y.shape}")
    fig = Figure(figsize=(5.0, 5.0), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.plot(x, y, color="k", lw=1.0)
    ax.plot(x[0], y[0], "o", color="tab:red", ms=4)
    k = max(1, x.size // 50)
    ax.annotate("", xy=(x[k], y[k]), xytext=(x[0], y[0]),
                arrowprops={"arrowstyle": "->", "color": "tab:red"})
    if equal:
        ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3)
    if title:
        ax.set_title(title)
    fig.tight_layout()
    with atomic_path(filename) as tmp:
        fig.savefig(tmp, format="png")
    return Path(filename)


def write_history_csv(t, columns: dict, filename, time_label: str = "t_s") -> Path:
    """Time histories as CSV: the time column, then one column per ``{name: values}``."""
    t = np.asarray(t, dtype=float)
    for name, values in columns.items():
        if np.shape(values) != t.shape:
            raise ValueError(f"column {name!r}: expected {t.shape[0]} values, got shape"
                             f" {np.shape(values)}")
    rows = np.column_stack([t, *[np.asarray(v, dtype=float) for v in columns.values()]])
    with atomic_path(filename) as tmp:
        np.savetxt(tmp, rows, delimiter=",", header=",".join([time_label, *columns]),
                   comments="", fmt="%.10g")
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
