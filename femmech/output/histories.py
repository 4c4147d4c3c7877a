"""Time histories of a forced response: panels over time, orbits, CSV tables.

Stage 6 (output): uses only output.export (atomic writes); arrays come in, and
matplotlib is imported inside the functions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from femmech.output.export import atomic_path


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
