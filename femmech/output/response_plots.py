"""Response histories (PNG): one panel per coordinate over the drive angle or time.

Stage 7 (output): uses output.charts (angle axis) and output.export (atomic writes);
matplotlib is imported inside the function.
"""

from __future__ import annotations

import numpy as np

from femmech.output.charts import set_angle_axis
from femmech.output.export import atomic_path


def response_unit(name: str, units=None) -> str:
    """Unit of a response column: frame DOFs ``part:node:dof`` are m (u*) or rad (r*);
    mechanism coordinates that of ``units`` (column → unit, from the catalogue), else
    "m or rad" (a user mechanism's SI unit)."""
    dof = name.rsplit(":", 1)[-1] if name.count(":") == 2 else ""
    return {"u": "m", "r": "rad"}.get(dof[:1]) or (units or {}).get(name) or "m or rad"


def plot_response(x, columns: dict, path, periodic: bool, title: str = "", shown=None,
                  units=None) -> None:
    """One panel per column of ``columns`` (name → values (n,)) over ``x`` (n,): the
    drive angle in degrees (``periodic``) or the time in s; each panel titled by
    ``shown`` (column → readable name), its y axis by the unit (``units``: column → unit
    of a mechanism coordinate)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure as MplFigure

    x = np.asarray(x)
    fig = MplFigure(figsize=(8, 1.2 + 1.8 * max(1, len(columns))), dpi=110,
                    layout="constrained")
    FigureCanvasAgg(fig)
    if title:
        fig.suptitle(title, fontsize=10)
    for i, (name, values) in enumerate(columns.items() or {"(none)": 0 * x}.items()):
        ax = fig.add_subplot(max(1, len(columns)), 1, i + 1)
        ax.plot(x, values, lw=1.0)
        ax.set_title((shown or {}).get(name, name), loc="left", fontsize=9)
        ax.set_ylabel(response_unit(name, units), fontsize=8)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3), useMathText=True)
        ax.grid(alpha=0.3)
        if periodic:
            set_angle_axis(ax, float(x.min()), float(x.max()))  # ticks every 45°
    ax.set_xlabel("drive angle φ (°)" if periodic else "time t (s)")
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
