"""Quasi-eigenfrequencies of a chain over the drive angle by several methods (PNG), one
panel per method.

Stage 7 (output): uses output.charts (angle axis) and output.export (atomic writes);
matplotlib is imported inside the function.
"""

from __future__ import annotations

import numpy as np

from femmech.output.charts import set_angle_axis
from femmech.output.export import atomic_path


def plot_method_sweeps(sweeps: dict, path, title: str = "", bands=None) -> None:
    """Quasi-eigenfrequencies over the drive angle, one panel per method side by side,
    with a common frequency axis (Hz) so the panels compare at a glance.

    ``sweeps``: method → result with ``phi`` (n_angles,) rad and ``freq_hz`` (n_angles,
    k) Hz. ``bands``: optional (lo_hz, hi_hz) arrays of harmonic bands, shaded grey.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure as MplFigure

    n = len(sweeps)
    fig = MplFigure(figsize=(3.3 * n + 1.0, 4.4), dpi=110)
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, n, sharey=True, squeeze=False)[0]
    values = np.concatenate([np.ravel(s.freq_hz) for s in sweeps.values()])
    top = float(np.nanmax(values)) * 1.06
    colors = [f"C{k % 10}" for k in range(max(s.freq_hz.shape[1] for s in sweeps.values()))]
    for ax, (method, s) in zip(axes, sweeps.items(), strict=True):
        deg = np.rad2deg(np.asarray(s.phi))
        for k in range(s.freq_hz.shape[1]):
            ax.plot(deg, s.freq_hz[:, k], color=colors[k], lw=1.4, label=f"f{k + 1}")
        if bands is not None:
            for lo, hi in zip(*bands, strict=True):
                if lo < top:
                    ax.axhspan(lo, hi, color="0.85", zorder=0, lw=0)
        ax.set_title(method, fontsize=10)
        set_angle_axis(ax, float(deg.min()), float(deg.max()))
        ax.set_xlabel("drive angle φ (°)")
        ax.grid(True, alpha=0.3)
    axes[0].set_ylim(0.0, top)
    axes[0].legend(fontsize=7, ncol=3, loc="lower right", title="branch (tracked)",
                   title_fontsize=7)
    axes[0].set_ylabel("quasi-eigenfrequency (Hz)")
    if title:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
