"""Campbell diagrams of chains: quasi-eigenfrequency bands against the drive harmonics.

Speed n (rpm) on x, frequency (Hz) on y. The frozen quasi-eigenfrequencies do not depend
on the speed but on the drive angle: each branch is drawn as a horizontal band (its
min–max over one revolution, shaded) with its mean as a line. The harmonics k·n/60
(k = 1 … K) form a fan of rays from the origin; the speed range is shaded; inside it
the forbidden zones (harmonic ± the relative margin m: between the rays k·n(1 - m)/60
and k·n(1 + m)/60) are hatched; where a branch band meets a harmonic ray inside the
speed range, the resonance is marked (red segment, dot at the mean). An optional
``before`` design is overlaid faded (grey bands, dashed means, hollow resonance marks).

:func:`plot_synthesis` draws the before/after diagram of a
:class:`~femmech.chain.synthesis.SynthesisResult` and :func:`plot_margins` its margin per
branch.

Uses output.charts and output.export, and the band geometry of
femmech.chain.synthesis; matplotlib is imported inside the functions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from femmech.chain.synthesis import band_distance, harmonic_bands
from femmech.output.charts import label_right_margin, legend_below
from femmech.output.export import atomic_path

X_BEYOND = 1.15
"""The speed axis runs to this multiple of n_hi (a little beyond the speed range)."""

RESONANCE_COLOR = "tab:red"


def _frequencies(bands, what: str) -> np.ndarray:
    """(n_angles, n_branches) Hz from an object with ``freq_hz`` or an array."""
    freq = np.asarray(getattr(bands, "freq_hz", bands), dtype=float)
    if freq.ndim == 1:
        freq = freq[None, :]
    if freq.ndim != 2 or freq.shape[1] == 0 or freq.shape[0] == 0:
        raise ValueError(f"{what}: no branches to draw (need freq_hz of shape (n_angles,"
                         f" n_branches) with n_branches >= 1, got {freq.shape})")
    if not np.all(np.isfinite(freq)):
        raise ValueError(f"{what}: freq_hz has non-finite values")
    return np.sort(freq, axis=1)


def _groups(low, high) -> list[tuple[int, int]]:
    """Runs of branches (first, last) whose bands overlap or touch: one label each."""
    out: list[list[int]] = []
    for i in range(low.size):
        if out and low[i] <= high[out[-1][1]] * (1 + 1e-3):
            out[-1][1] = i
        else:
            out.append([i, i])
    return [tuple(g) for g in out]


def _colors(low, high) -> list[str]:
    """Colour of each branch: one per group of overlapping bands (a cluster reads as one)."""
    out = [""] * low.size
    for g, (first, last) in enumerate(_groups(low, high)):
        out[first:last + 1] = [f"C{g % 10}"] * (last - first + 1)
    return out


def _draw_bands(ax, freq, faded: bool, y_top: float) -> int:
    """Shade each branch's band, draw its mean; returns the number of branches drawn."""
    low, high, mean = freq.min(axis=0), freq.max(axis=0), freq.mean(axis=0)
    colors, drawn = _colors(low, high), 0
    for i in np.flatnonzero(low <= y_top):
        color = "0.55" if faded else colors[i]
        ax.axhspan(low[i], high[i], color=color, alpha=0.22 if faded else 0.35, lw=0,
                   gid="before-band" if faded else "branch-band", zorder=1)
        ax.axhline(mean[i], color=color, lw=0.9 if faded else 1.3,
                   ls=(0, (4, 2)) if faded else "-", alpha=0.8 if faded else 1.0,
                   gid="before-mean" if faded else "branch-mean", zorder=2)
        drawn += 1
    return drawn


def _draw_fan(ax, lo_rpm, hi_rpm, harmonics, margin, x_max, y_top) -> None:
    """Harmonic rays k·n/60, labelled at their end, and the forbidden zones (hatched)."""
    for k in range(1, harmonics + 1):
        x_end = min(x_max, 60.0 * y_top / k)
        ax.plot([0.0, x_end], [0.0, k * x_end / 60.0], color="0.3", lw=0.9, gid="harmonic",
                zorder=3)
        ax.annotate(f"{k}·n", (x_end, k * x_end / 60.0), xytext=(-3, -3 if x_end < x_max
                                                                else 2),
                    textcoords="offset points", ha="right", va="top" if x_end < x_max
                    else "bottom", fontsize=8, color="0.2", gid="harmonic-label",
                    bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none",
                          "alpha": 0.8}, zorder=6)
        if margin > 0:
            xs = [lo_rpm, hi_rpm, hi_rpm, lo_rpm]
            ys = [k * lo_rpm / 60 * (1 - margin), k * hi_rpm / 60 * (1 - margin),
                  k * hi_rpm / 60 * (1 + margin), k * lo_rpm / 60 * (1 + margin)]
            ax.fill(xs, ys, facecolor="none", edgecolor=RESONANCE_COLOR, hatch="////",
                    lw=0.0, alpha=0.45, gid="forbidden", zorder=2)


def _crossings(ax, freq, lo_rpm, hi_rpm, harmonics, faded: bool) -> int:
    """Mark where branch bands meet harmonic rays inside the speed range; returns how
    many (branch, k) pairs resonate."""
    low, high, mean = freq.min(axis=0), freq.max(axis=0), freq.mean(axis=0)
    count = 0
    for k in range(1, harmonics + 1):
        for i in range(low.size):
            n0, n1 = max(60 * low[i] / k, lo_rpm), min(60 * high[i] / k, hi_rpm)
            if n0 > n1:
                continue
            count += 1
            gid = "crossing-before" if faded else "crossing"
            if not faded:
                ax.plot([n0, n1], [k * n0 / 60, k * n1 / 60], color=RESONANCE_COLOR, lw=3,
                        solid_capstyle="butt", gid=gid + "-segment", zorder=4)
            n_mean = float(np.clip(60 * mean[i] / k, n0, n1))
            ax.plot([n_mean], [k * n_mean / 60], "o", ms=5, gid=gid, zorder=5,
                    mfc="none" if faded else RESONANCE_COLOR,
                    mec="0.45" if faded else RESONANCE_COLOR)
    return count


def _label_groups(fig, ax, freq, y_top) -> None:
    low, high, mean = freq.min(axis=0), freq.max(axis=0), freq.mean(axis=0)
    ys, labels, colors = [], [], []
    for g, (first, last) in enumerate(_groups(low, high)):
        if low[first] > y_top:
            break
        labels.append(f"f{first + 1}" if first == last else f"f{first + 1}–f{last + 1}")
        y = float(np.mean(mean[first:last + 1]))  # inside the axes if the band reaches out
        ys.append(y if y < y_top else 0.5 * (low[first] + y_top))
        colors.append(f"C{g % 10}")
    label_right_margin(fig, ax, ys, labels, colors, fontsize=8, gid="branch-label")


def campbell_figure(bands, speed_rpm, harmonics: int, before=None, margin: float = 0.0,
                    title: str | None = None):
    """The matplotlib Figure of :func:`plot_campbell` (same arguments, no file)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    lo_hz, hi_hz = harmonic_bands(speed_rpm, harmonics)  # checks the range and K
    lo_rpm, hi_rpm, harmonics = 60 * lo_hz[0], 60 * hi_hz[0], int(harmonics)
    if not (np.isfinite(margin) and 0 <= margin < 1):
        raise ValueError(f"margin must lie in [0, 1), got {margin!r}")
    freq = _frequencies(bands, "bands")
    old = None if before is None else _frequencies(before, "before")
    x_max, y_top = X_BEYOND * hi_rpm, X_BEYOND * hi_hz[-1] * (1 + margin)
    fig = Figure(figsize=(9.0, 6.0), dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.axvspan(lo_rpm, hi_rpm, color="0.92", lw=0, gid="speed-range", zorder=0)
    _draw_fan(ax, lo_rpm, hi_rpm, harmonics, margin, x_max, y_top)
    if old is not None:
        _draw_bands(ax, old, True, y_top)
        _crossings(ax, old, lo_rpm, hi_rpm, harmonics, True)
    shown = _draw_bands(ax, freq, False, y_top)
    hits = _crossings(ax, freq, lo_rpm, hi_rpm, harmonics, False)
    ax.set_xlim(0.0, x_max)
    ax.set_ylim(0.0, y_top)
    ax.set_xlabel("drive speed n (rpm)")
    ax.set_ylabel("frequency (Hz)")
    ax.grid(True, lw=0.3, alpha=0.5)
    above = freq.shape[1] - shown
    fig.suptitle(title or _title(harmonics, margin, hits, above), fontsize=10)
    _legend(fig, ax, before is not None, margin)
    _label_groups(fig, ax, freq, y_top)
    return fig


def _title(harmonics, margin, hits, above) -> str:
    first = (f"Campbell diagram: quasi-eigenfrequency bands over one revolution and"
             f" harmonics k·n, k = 1…{harmonics}")
    second = (f"{hits} resonance{'s' if hits != 1 else ''} in the speed range"
              + (f"; forbidden zones = harmonic ± {100 * margin:g} %" if margin else "")
              + (f"; {above} higher branch{'es' if above != 1 else ''} not shown"
                 if above else ""))
    return f"{first}\n{second}"


def _legend(fig, ax, with_before: bool, margin: float) -> None:
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    band = (Patch(color="C0", alpha=0.35), Line2D([], [], color="C0", lw=1.3))
    handles = [band,
               Line2D([], [], color="0.3", lw=0.9, label="harmonic k·n/60"),
               Patch(color="0.92", label="speed range")]
    if margin > 0:
        handles.append(Patch(facecolor="none", edgecolor=RESONANCE_COLOR, hatch="////",
                             alpha=0.6, label=f"forbidden: k·n/60 ± {100 * margin:g} %"))
    handles.append(Line2D([], [], color=RESONANCE_COLOR, lw=3, marker="o",
                          label="resonance in the speed range"))
    if with_before:
        handles += [(Patch(color="0.55", alpha=0.3),
                     Line2D([], [], color="0.55", lw=0.9, ls=(0, (4, 2)))),
                    Line2D([], [], ls="none", marker="o", mfc="none", mec="0.45")]
    labels = ["branch: min–max over φ (band), mean (line)"] + [
        h.get_label() for h in handles[1:len(handles) - (2 if with_before else 0)]]
    if with_before:
        labels += ["before (initial design)", "resonance before"]
    legend_below(fig, ax, handles, labels, fontsize=8)


def plot_campbell(bands, speed_rpm, harmonics: int, path, before=None,
                  margin: float = 0.0, title: str | None = None) -> Path:
    """Campbell diagram of a chain (PNG).

    Parameters
    ----------
    bands : FrequencyBands, Sweep or array_like (n_angles, n_branches)
        Quasi-eigenfrequencies (Hz) over the drive angle: anything with ``freq_hz``
        (:class:`~femmech.chain.synthesis.FrequencyBands`,
        :class:`~femmech.analysis.sweep.Sweep`) or the array itself. Branch i is the
        (i+1)-th lowest frequency at each angle; its band is its min–max over the angles.
    speed_rpm : (float, float)
        Speed range (n_lo, n_hi), rpm, 0 < n_lo <= n_hi.
    harmonics : int
        Highest harmonic order K of the fan.
    path : str or path-like
        Target PNG (written atomically).
    before : same types as ``bands``, optional
        An earlier design drawn faded underneath.
    margin : float
        Relative margin m of the forbidden zones (0: none hatched).
    title : str, optional
        Replaces the automatic two-line title.

    The frequency axis runs to 1.15 × K n_hi/60 (1 + m); branches above are counted in
    the title, not drawn. Raises ValueError for a reversed or non-positive speed range,
    K < 1, or no branches.
    """
    fig = campbell_figure(bands, speed_rpm, harmonics, before, margin, title)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
    return Path(path)


def plot_synthesis(result, path, title: str | None = None) -> Path:
    """Before/after Campbell diagram of a :func:`~femmech.chain.synthesis.synthesise`
    result, with its margins in the title."""
    after, before = result.margin_after, result.margin_before
    verdict = "meets" if result.feasible else "does NOT meet"
    title = title or (
        f"Synthesis, {result.speed_rpm[0]:g}–{result.speed_rpm[1]:g} rpm, k = 1…"
        f"{result.harmonics}: margin {before.value:+.3f} → {after.value:+.3f}"
        f" ({verdict} the required {result.required:g})\nCampbell diagram: colour ="
        " after, grey = before; bands = min–max over one revolution")
    return plot_campbell(result.bands_after, result.speed_rpm, result.harmonics, path,
                         before=result.bands_before, margin=result.required, title=title)


def plot_margins(result, path) -> Path:
    """Per-branch resonance margin before and after a synthesis (bar chart PNG).

    Bars: the smallest signed relative distance of each branch (over the revolution and
    all harmonics) to a harmonic band; the required margin is a dashed line, branches
    below it are the ones that resonate or come too close.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    lo, hi = harmonic_bands(result.speed_rpm, result.harmonics)
    values = [band_distance(_frequencies(b, name), lo, hi).min(axis=(0, 2))
              for b, name in ((result.bands_before, "before"), (result.bands_after, "after"))]
    n = int(np.sum((values[0] < 1.0) | (values[1] < 1.0))) or 1  # far branches left out
    keep = np.argsort(np.minimum(values[0], values[1]))[:max(n, 1)]
    keep.sort()
    fig = Figure(figsize=(max(5.0, 1.2 + 0.5 * keep.size), 4.0), dpi=120,
                 layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    x = np.arange(keep.size)
    for j, (v, label, color) in enumerate(((values[0], "before", "0.6"),
                                           (values[1], "after", "C0"))):
        ax.bar(x + (j - 0.5) * 0.38, 100 * np.minimum(v[keep], 1.0), 0.38, color=color,
               label=label, gid=f"margin-{label}")
    ax.axhline(100 * result.required, color=RESONANCE_COLOR, ls="--", lw=1,
               label=f"required {100 * result.required:g} %")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xticks(x, [f"f{i + 1}" for i in keep])
    ax.set_xlabel("branch (i-th lowest quasi-eigenfrequency)")
    ax.set_ylabel("margin (%, capped at 100)")
    ax.set_title("Resonance margin per branch\n(smallest relative distance to a harmonic"
                 f" band, k = 1…{result.harmonics}; < 0: inside)", fontsize=9)
    ax.legend(fontsize=8)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
    return Path(path)
