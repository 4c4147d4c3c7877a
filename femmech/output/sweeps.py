"""Sweeps over the drive angle: the quasi-eigenfrequency diagram and MAC matrices (PNG),
quasi-mode tables (CSV, JSON).

:func:`plot_quasi_frequencies` takes any result with ``phi`` and ``freq_hz``
(mechanism-only :class:`~femmech.mechanisms.QuasiModes` or a coupled
:class:`~femmech.analysis.sweep.Sweep`).

Uses output.export (atomic writes) and output.charts; results come in
duck-typed, and matplotlib is imported inside the functions.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from femmech.output.charts import (
    SPEED_SYMBOLS,
    format_speed,
    label_right_margin,
    needs_log_scale,
    set_angle_axis,
    speed_scale,
)
from femmech.output.export import atomic_path

_STYLES = ("-", "--", ":", "-.")


def quasi_frequency_figure(curves: dict, title: str = "", speed: float | None = None,
                           orders=(1, 2, 3, 4, 5, 6), speed_unit: str = "rpm"):
    """The matplotlib Figure of :func:`plot_quasi_frequencies` (same arguments)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    speed_scale(speed_unit)  # checks the unit
    symbol = SPEED_SYMBOLS[speed_unit]
    if not curves:
        raise ValueError("plot_quasi_frequencies needs at least one curve")
    fig = Figure(figsize=(9.0, 5.0), dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    handles, degs, values = [], [], []
    for i, (label, res) in enumerate(curves.items()):
        deg, freq = np.rad2deg(np.asarray(res.phi)), np.asarray(res.freq_hz)
        if freq.ndim != 2 or freq.shape[0] != deg.size:
            raise ValueError(f"curve {label!r}: freq_hz must be (n_angles, n) with"
                             f" n_angles = {deg.size}, got shape {freq.shape}")
        for k in range(freq.shape[1]):
            ax.plot(deg, freq[:, k], ls=_STYLES[i % 4], color=f"C{k % 10}", lw=1.3)
        handles.append(Line2D([], [], color="k", ls=_STYLES[i % 4], lw=1.3, label=label))
        degs.append(deg)
        values.append(freq.ravel())
    values = np.concatenate(values)
    values = values[np.isfinite(values)]
    marks = _harmonics(speed, orders, values, symbol)
    for f in marks.values():
        ax.axhline(f, color="0.45", lw=0.8, ls=(0, (1, 2)))
    if marks:
        handles.append(Line2D([], [], color="0.45", lw=0.8, ls=(0, (1, 2)),
                              label=f"k·{symbol}: harmonics of {symbol} ="
                                    f" {format_speed(speed, speed_unit)}"))
    _frequency_axis(ax, values)
    degs = np.concatenate(degs)
    set_angle_axis(ax, float(degs.min()), float(degs.max()))
    ax.set_xlabel("drive angle φ (°)")
    ax.grid(True, which="major", lw=0.3, alpha=0.6)
    if title:
        fig.suptitle(title, fontsize=11)
    fig.legend(handles=handles, loc="outside lower center", ncols=min(len(handles), 3),
               fontsize=8, frameon=False)
    _label_branches(fig, ax, curves, marks)
    return fig


def _harmonics(speed, orders, values, symbol: str) -> dict:
    """{"k·n": frequency (Hz)} of the drive-speed harmonics inside the plotted range."""
    if speed is None or values.size == 0:
        return {}
    lo, hi = values.min(), values.max()
    return {f"{k}·{symbol}": k * speed / (2 * np.pi) for k in orders
            if lo <= k * speed / (2 * np.pi) <= hi}


def _frequency_axis(ax, values) -> None:
    """Linear frequency axis, or log (said in the label) if the range spans a decade."""
    from matplotlib.ticker import FuncFormatter

    if needs_log_scale(values):
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(FuncFormatter(
            lambda v, _: f"{v:g}" if round(v / 10 ** np.floor(np.log10(v))) in (2, 5)
            else ""))
        ax.set_ylabel("quasi-eigenfrequency (Hz, log scale)")
    else:
        ax.set_ylabel("quasi-eigenfrequency (Hz)")


def _label_branches(fig, ax, curves: dict, marks: dict) -> None:
    """Name each branch (f1, f2, …, in its colour) and each harmonic at the right edge."""
    first = next(iter(curves.values()))
    freq = np.asarray(first.freq_hz)
    ys, labels, colors = [], [], []
    for k in range(freq.shape[1]):
        finite = np.flatnonzero(np.isfinite(freq[:, k]))
        if finite.size:
            ys.append(freq[finite[-1], k])
            labels.append(f"f{k + 1}")
            colors.append(f"C{k % 10}")
    for label, f in marks.items():
        ys.append(f)
        labels.append(label)
        colors.append("0.35")
    if ys:  # branches first: a harmonic's label gives way to a branch's
        label_right_margin(fig, ax, ys, labels, colors, fontsize=9,
                           priority=[0] * (len(ys) - len(marks)) + [1] * len(marks))


def plot_quasi_frequencies(curves: dict, filename, title: str = "",
                           speed: float | None = None, orders=(1, 2, 3, 4, 5, 6),
                           speed_unit: str = "rpm") -> Path:
    """Quasi-eigenfrequencies (Hz) over the drive angle (°) as a PNG.

    Parameters
    ----------
    curves : dict of str to result
        Label → result with ``phi`` (n_angles,) in rad and ``freq_hz`` (n_angles, n) in
        Hz (:class:`~femmech.mechanisms.QuasiModes`, :class:`~femmech.analysis.sweep.Sweep`);
        each result has one line style (named in the one legend, below the plot), each
        branch k one colour, named "fk" at the right edge.
    filename : str or path-like
        Target PNG, written atomically.
    title : str
        Figure title.
    speed : float, optional
        Drive speed, rad/s: its harmonics k·speed/(2π) Hz for k in ``orders`` that lie in
        the plotted frequency range are drawn as dotted lines, labelled "k·n" (or "k·Ω")
        at the right edge.
    orders : sequence of int
        Harmonic orders k.
    speed_unit : {"rpm", "rad/s", "Hz"}
        Unit of the speed in the legend; the symbol is n (rpm, Hz) or Ω (rad/s).

    The frequency axis is linear unless the plotted frequencies span more than a decade
    (then log, said in the axis label); the angle axis spans the data with ticks every
    45° (up to one revolution) or 90°. No two labels overlap each other or the legend.
    """
    fig = quasi_frequency_figure(curves, title, speed, orders, speed_unit)
    Path(filename).parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(filename) as tmp:
        fig.savefig(tmp, format="png")
    return Path(filename)


def plot_mac(mac: np.ndarray, filename, row_label: str = "mode", col_label: str = "mode",
             title: str = "MAC") -> Path:
    """Draw a MAC matrix (values 0..1, shape (p, q)) as an annotated heat map PNG."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    mac = np.asarray(mac, dtype=float)
    if mac.ndim != 2:
        raise ValueError(f"mac must be a 2D array, got shape {mac.shape}")
    fig = Figure(figsize=(1.2 + 0.5 * mac.shape[1], 1.0 + 0.5 * mac.shape[0]), dpi=120,
                 layout="constrained")
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
