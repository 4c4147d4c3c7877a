"""Off-screen images of coupled machine modes: the deformed frame plus the mechanisms.

The frame part of a coupled mode is recovered to the full FE model (through the
superelement when the frame is reduced) and drawn with :func:`plot_mode`; each mounted
mechanism is drawn schematically at its first translational attachment: a connector
from the (displaced) frame node to a block that stands for the mechanism's moving body,
displaced by the mechanism coordinate of largest amplitude along the attachment
direction.

Stage 6 (output): uses analysis.modes, coupling, reduction, fe and output.plot.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from femmech.analysis.modes import ModeSet
from femmech.coupling import CoupledSystem, _weights
from femmech.fe.dofs import DOF_PER_NODE
from femmech.fe.model import FEModel, node_index
from femmech.output.plot import SCALE_FRACTION, model_size, plot_mode
from femmech.reduction.superelement import Superelement

MECHANISM_COLOR = "#e07b00"
OFFSET_FRACTION = 0.06
"""Distance of a mechanism's block from its attachment node, fraction of the model size."""


def frame_shape(system: CoupledSystem, x: np.ndarray) -> np.ndarray:
    """Full FE displacement (n_dof,) of the frame part of a coupled vector x (n,)."""
    frame = system.frame
    x = np.real_if_close(np.asarray(x))
    if np.iscomplexobj(x):
        x = x.real
    part = x[:system.n_frame]
    if isinstance(frame, Superelement):
        return frame.recover(part)
    if isinstance(frame, FEModel):
        return frame.expand(part)
    raise TypeError("frame_shape supports Superelement and FEModel frames")


def plot_coupled_mode(model: FEModel, system: CoupledSystem, x: np.ndarray, freq_hz: float,
                      filename, angle: float | None = None, **kwargs) -> Path:
    """Render one coupled quasi-mode (frame + mechanisms) to a PNG file.

    Parameters
    ----------
    model : FEModel
        The frame's FE model (the one reduced to ``system.frame``, or the frame itself).
    system : CoupledSystem
    x : ndarray (n,)
        The mode in the system's coordinates (e.g. ``sweep.vectors[a, :, k]``).
    freq_hz : float
        Its quasi-eigenfrequency, Hz (for the title).
    filename : str or os.PathLike
    angle : float, optional
        Drive angle, rad (for the title).
    **kwargs
        Passed to :func:`plot_mode` (``window_size``, ``camera``, ``scale``, ...). The
        default scale draws the largest of the frame and mechanism displacements as
        :data:`~femmech.output.plot.SCALE_FRACTION` of the model size.
    """
    u = frame_shape(system, x)
    modes = ModeSet(np.array([freq_hz]), np.array([(2 * np.pi * freq_hz) ** 2]), u[:, None],
                    np.array([False]), "coupled", 0.0, np.zeros(1), None)
    title = f"Coupled mode: {freq_hz:.2f} Hz"
    if angle is not None:
        title += f" at phi = {np.rad2deg(angle):.0f} deg"  # VTK's font lacks φ and °
    glyphs = _mechanism_glyphs(model, system, np.real_if_close(x), u)
    if kwargs.get("scale") is None:
        largest = max([np.abs(u.reshape(-1, DOF_PER_NODE)[:, :3]).max()]
                      + [abs(g[3]) for g in glyphs])
        kwargs["scale"] = SCALE_FRACTION * model_size(model) / largest if largest > 0 else 1.0

    def decorate(plotter, scale):
        _draw_mechanisms(plotter, glyphs, scale, OFFSET_FRACTION * model_size(model))

    return plot_mode(model, modes, 0, filename, title=title, decorate=decorate, **kwargs)


def _mechanism_glyphs(model, system, x, u):
    """Per mount: (node position, frame displacement, unit direction, body displacement)."""
    nodal = u.reshape(-1, DOF_PER_NODE)
    out = []
    for mount, P, idx in zip(system.mounts, system.projections, system.touched, strict=True):
        q = P @ np.real(x[idx])
        for att in mount.attachments:
            w = _weights(att.direction)[:3]
            if not np.any(w):
                continue
            node = att.node if isinstance(att.node, (int, np.integer)) else \
                node_index(model.mesh, att.node, "attachment")
            d = w / np.linalg.norm(w)
            body = q[np.argmax(np.abs(q))] if q.size else 0.0
            out.append((model.mesh.points[node], nodal[node, :3], d, body))
            break
    return out


def _draw_mechanisms(plotter, glyphs, scale, offset):
    """Connector lines and blocks for each mechanism (pyvista actors)."""
    if not glyphs:
        return
    import pyvista as pv

    size = 0.4 * offset
    for point, frame_u, d, body in glyphs:
        base = point + scale * frame_u
        block = point - offset * d + scale * body * d
        plotter.add_mesh(pv.Line(base, block), color=MECHANISM_COLOR, line_width=3)
        plotter.add_mesh(pv.Cube(center=block, x_length=size, y_length=size, z_length=size),
                         color=MECHANISM_COLOR, smooth_shading=False)
