"""Time per drive angle versus frequency error of several reduction sizes (PNG).

Stage 7 (output): uses output.charts (log-scale rule) and output.export (atomic
writes); matplotlib is imported inside the function.
"""

from __future__ import annotations

from femmech.output.charts import needs_log_scale
from femmech.output.export import atomic_path


def plot_speed_error(rows, path) -> None:
    """``rows``: (name, coordinates, ms per angle, max rel. error, min MAC) per model,
    the full model first (drawn as a dashed vertical line), then the reductions (points
    labelled "name (coordinates)"); log error axis, log time axis over a decade or more."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure as MplFigure

    fig = MplFigure(figsize=(6.5, 4.2), dpi=110)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    times = [r[2] for r in rows]
    ax.set_xscale("log" if needs_log_scale(times) else "linear")  # a decade or more: log
    ax.set_yscale("log")
    for name, n, ms, err, _ in rows[1:]:
        ax.plot(ms, max(err, 1e-16), "o")
        ax.annotate(f"{name} ({n})", (ms, max(err, 1e-16)), fontsize=7, xytext=(4, 2),
                    textcoords="offset points")
    ax.axvline(rows[0][2], color="0.4", ls="--", lw=0.8)
    ax.annotate(f"full ({rows[0][1]})", (rows[0][2], 0.5), xycoords=("data", "axes fraction"),
                rotation=90, fontsize=7, ha="right")
    ax.set_xlabel("time per drive angle (ms)")
    ax.set_ylabel("max |relative frequency error|")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
