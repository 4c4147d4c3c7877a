"""Off-screen images of coupled machine modes: the deformed frame plus the mechanisms.

The frame part of a coupled mode is recovered to the full FE model (through the
superelement when the frame is reduced) and drawn with :func:`plot_mode`; each mounted
mechanism is drawn schematically at its first translational attachment: a connector
from the (displaced) frame node to a block that stands for the mechanism's moving body,
displaced by the mechanism coordinate of largest amplitude along the attachment
direction. The title states the frequency, the drive angle (``φ = 45°``) and speed, the
legend lists the mechanism glyph next to the frame's.

Uses analysis.modes, coupling, reduction, fe and output.plot,
.mode_geometry, .annotate and .renderer.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from femmech.analysis.modes import ModeSet
from femmech.coupling import CoupledSystem, direction_weights
from femmech.fe.dofs import DOF_PER_NODE
from femmech.fe.model import FEModel, node_index
from femmech.output.annotate import LegendEntry
from femmech.output.charts import format_speed
from femmech.output.mode_geometry import SCALE_FRACTION, marker_size, model_size
from femmech.output.plot import plot
from femmech.output.renderer import Decoration
from femmech.reduction.superelement import Superelement

MECHANISM_COLOR = "#ff7f00"
OFFSET_FRACTION = 0.08
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


def coupled_title(freq_hz: float, angle: float | None = None, speed: float | None = None,
                  number: int | None = None, speed_unit: str = "rpm") -> str:
    """Title of a coupled-mode image: ``"Coupled mode 1: 60.54 Hz at φ = 90°, speed 300 rpm"``.

    ``angle`` is the drive angle in rad (shown in degrees, to 0.1°), ``speed`` the drive
    speed in rad/s (shown in ``speed_unit``: "rpm", "rad/s" or "Hz"), ``number`` the
    mode's number from 1.
    """
    text = "Coupled mode" + (f" {number}" if number is not None else "") + f": {freq_hz:.2f} Hz"
    if angle is not None:
        text += f" at φ = {float(np.rad2deg(angle)):.4g}°"
    if speed is not None:
        text += f"{',' if angle is not None else ' at'} speed {format_speed(speed, speed_unit)}"
    return text


def plot_coupled_mode(model: FEModel, system: CoupledSystem, x: np.ndarray, freq_hz: float,
                      filename, angle: float | None = None, speed: float | None = None,
                      mode_number: int | None = None, speed_unit: str = "rpm",
                      **kwargs) -> Path:
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
        Drive angle, rad (title: ``φ = 45°``).
    speed : float, optional
        Drive speed Ω the mode was solved at, rad/s (title: in ``speed_unit``).
    mode_number : int, optional
        Number of the mode from 1 (title: ``Coupled mode 1``).
    speed_unit : str
        ``"rpm"`` (default), ``"rad/s"`` or ``"Hz"``, for the title.
    **kwargs
        Passed to :func:`plot_mode` (``window_size``, ``camera``, ``scale``,
        ``mode_type``, ...). The default scale draws the largest of the frame and
        mechanism displacements as :data:`~femmech.output.plot.SCALE_FRACTION` of the
        model size, and the camera (with the default scale) is then the same for every
        coupled mode of the model: fitted to the undeformed frame and mechanisms grown by
        that largest displacement. The mode type is off by default (it would describe the
        frame only).
    """
    u = frame_shape(system, x)
    modes = ModeSet(np.array([freq_hz]), np.array([(2 * np.pi * freq_hz) ** 2]), u[:, None],
                    np.array([False]), "coupled", 0.0, np.zeros(1), None)
    glyphs = _mechanism_glyphs(model, system, np.real_if_close(x), u)
    if kwargs.get("scale") is None:
        largest = max([np.abs(u.reshape(-1, DOF_PER_NODE)[:, :3]).max()]
                      + [abs(g[3]) for g in glyphs])
        kwargs["scale"] = SCALE_FRACTION * model_size(model) / largest if largest > 0 else 1.0
        kwargs["scale_note"] = True
        # nothing moves further than SCALE_FRACTION of the size: one camera for every
        # coupled mode of this model (all angles, speeds and modes look alike)
        kwargs.setdefault("reach", SCALE_FRACTION * model_size(model))
    kwargs.setdefault("mode_type", False)
    decoration = mechanism_decoration(glyphs, model_size(model), marker_size(model))
    return plot(model, modes, [0], [Path(filename)], workers=1, decorate=decoration,
                 title=coupled_title(freq_hz, angle, speed, mode_number, speed_unit), **kwargs)[0]


def mechanism_decoration(glyphs, size: float, marker: float) -> Decoration:
    """The mechanisms of :func:`_mechanism_glyphs` as a :class:`Decoration`: a connector
    tube from the displaced attachment node to a block for the mechanism's moving body,
    :data:`OFFSET_FRACTION` of the model size (``size``, m) away, displaced by its
    coordinate; ``marker`` (m) sets the connector's radius."""
    offset = OFFSET_FRACTION * size
    edge = 0.5 * offset

    def ends(scale):
        return [(point + scale * frame_u, point - offset * d + scale * body * d)
                for point, frame_u, d, body in glyphs]

    def draw(plotter, scale):
        _draw_mechanisms(plotter, ends(scale), edge, 0.4 * marker)

    def points(scale):  # the corners of the blocks
        corners = 0.5 * edge * np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
        blocks = np.array([block for _, block in ends(scale)]).reshape(-1, 1, 3)
        return (blocks + corners[None]).reshape(-1, 3)

    legend = (LegendEntry("mechanism attachment", MECHANISM_COLOR, "block"),) if glyphs else ()
    return Decoration(draw, points, legend)


def _mechanism_glyphs(model, system, x, u):
    """Per mount: (node position, frame displacement, unit direction, body displacement)."""
    nodal = u.reshape(-1, DOF_PER_NODE)
    out = []
    for mount, P, idx in zip(system.mounts, system.projections, system.touched, strict=True):
        q = P @ np.real(x[idx])
        for att in mount.attachments:
            w = direction_weights(att.direction)[:3]
            if not np.any(w):
                continue
            node = att.node if isinstance(att.node, (int, np.integer)) else \
                node_index(model.mesh, att.node, "attachment")
            d = w / np.linalg.norm(w)
            body = q[np.argmax(np.abs(q))] if q.size else 0.0
            out.append((model.mesh.points[node], nodal[node, :3], d, body))
            break
    return out


def _draw_mechanisms(plotter, ends, size: float, radius: float) -> None:
    """A connector tube and a block (edge ``size``, m) per mechanism (pyvista actors)."""
    if not ends:
        return
    import pyvista as pv

    for base, block in ends:
        plotter.add_mesh(pv.Line(base, block).tube(radius=radius, n_sides=12),
                         color=MECHANISM_COLOR, smooth_shading=True)
        plotter.add_mesh(pv.Cube(center=block, x_length=size, y_length=size, z_length=size),
                         color=MECHANISM_COLOR, smooth_shading=False)
