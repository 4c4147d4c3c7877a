"""Sweeps over the drive angle: MAC matrices (PNG), quasi-mode tables (CSV, JSON).

The quasi-eigenfrequency diagram itself is
:func:`femmech.mechanisms.plot_quasi_frequencies`, which takes any result with ``phi``
and ``freq_hz`` (mechanism-only quasi-modes or a coupled :class:`Sweep`).

Stage 6 (output): uses only output.export (atomic writes); results come in duck-typed, and
matplotlib is imported inside the functions.
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
