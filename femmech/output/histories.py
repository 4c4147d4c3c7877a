"""Time histories of a forced response: panels over time, orbits, CSV tables.

Uses output.export (atomic writes) and output.charts (angle ticks);
arrays come in, and matplotlib is imported inside the functions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from femmech.output.charts import set_angle_axis
from femmech.output.export import atomic_path


def plot_time_histories(t, panels: dict, filename, title: str = "",
                        xlabel: str = "time (s)", angle_deg: bool = False) -> Path:
    """Time histories in stacked panels sharing the time axis (PNG).

    Parameters
    ----------
    t : array_like (n_t,)
        Times (or drive angles: set ``xlabel``).
    panels : dict
        ``{y_label: {curve_label: values (n_t,)}}``, one panel per entry, top to bottom;
        the y label carries the unit, e.g. ``"force (kN)"``. A curve with its own times
        is given as a pair ``(times (m,), values (m,))`` instead of ``values``. A panel
        of several curves has its legend right of it, outside the plot (none when it
        names the same curves as the panel above).
    angle_deg : bool
        ``t`` are drive angles in degrees: the axis spans them with ticks every 45° (up
        to one revolution) or 90°.
    """
    fig = time_histories_figure(t, panels, title, xlabel, angle_deg)
    with atomic_path(filename) as tmp:
        fig.savefig(tmp, format="png")
    return Path(filename)


def time_histories_figure(t, panels: dict, title: str = "", xlabel: str = "time (s)",
                          angle_deg: bool = False):
    """The matplotlib Figure of :func:`plot_time_histories` (same arguments)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    t = np.asarray(t, dtype=float)
    if not panels:
        raise ValueError("plot_time_histories needs at least one panel")
    for ylabel, curves in panels.items():
        for label, values in curves.items():
            times, values = _curve(t, values)
            if np.shape(values) != times.shape:
                raise ValueError(f"panel {ylabel!r}, curve {label!r}: expected"
                                 f" {times.shape[0]} values (one per time), got shape"
                                 f" {np.shape(values)}")
    fig = Figure(figsize=(8.5, 1.0 + 2.0 * len(panels)), dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
    above = None
    for ax, (ylabel, curves) in zip(axes, panels.items(), strict=True):
        for label, values in curves.items():
            ax.plot(*_curve(t, values), lw=1.0, label=label)
        ax.set_ylabel(ylabel)
        ax.grid(True, lw=0.3)
        if len(curves) > 1 and list(curves) != above:
            ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0),
                      borderaxespad=0.0)
        above = list(curves)
    axes[-1].set_xlabel(xlabel)
    if angle_deg and t.size:
        set_angle_axis(axes[-1], float(t.min()), float(t.max()))
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def _curve(t: np.ndarray, values):
    """(times, values) of a curve given as values on ``t`` or as a (times, values) pair."""
    if isinstance(values, tuple) and len(values) == 2:
        return np.asarray(values[0], dtype=float), values[1]
    return t, values


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
    fig = Figure(figsize=(5.0, 5.0), dpi=120, layout="constrained")
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


def plot_event_histories(panels: dict, filename, event: tuple | None = None,
                         levels: dict | None = None, title: str = "",
                         xlabel: str = "time (s)") -> Path:
    """Time histories of runs that share a start and part at an event (PNG).

    Parameters
    ----------
    panels : dict
        ``{y_label: {curve_label: (times (m,), values (m,))}}``, one panel per entry, top
        to bottom; each curve has its own times (runs of different lengths).
    event : (float, str), optional
        Time (s) and name of the event (e.g. a trip): a dotted vertical line on every
        panel, named on the top one.
    levels : dict, optional
        ``{y_label: (value, text)}``: a dashed horizontal line with its text on that
        panel (e.g. the force limit).
    """
    fig = time_histories_figure(np.zeros(0), panels, title, xlabel)
    for ax, ylabel in zip(fig.axes, panels, strict=True):
        if event is not None:
            ax.axvline(event[0], color="k", lw=0.8, ls=":")
        if levels and ylabel in levels:
            value, text = levels[ylabel]
            ax.axhline(value, color="k", lw=0.8, ls="--")
            ax.annotate(text, (0.01, value), xycoords=("axes fraction", "data"),
                        xytext=(0, 3), textcoords="offset points", fontsize=8)
    if event is not None and fig.axes:
        fig.axes[0].annotate(f" {event[1]}", (event[0], 1.0),
                             xycoords=("data", "axes fraction"), xytext=(2, -10),
                             textcoords="offset points", fontsize=8)
    with atomic_path(filename) as tmp:
        fig.savefig(tmp, format="png")
    return Path(filename)
