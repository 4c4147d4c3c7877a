"""Off-screen image of the local axes of beam elements: a triad at each element's midpoint.

The picture to look at when a section's orientation is in doubt (a vector copied from a
deck with the other convention, ``orientation_plane``): local x (along the element) red,
local y green, local z blue, drawn over the grey beams, and shells as light faces; the
global X, Y, Z axes are shown in the lower right corner.
``femmech.fe.sections`` puts a rectangle's ``width`` along local y and its ``height``
along local z, so the blue arrows show where each section's height points.

pyvista is imported inside the function (as for mode images); the headless window and the
view names are those of the mode images (:mod:`femmech.output.renderer`,
:mod:`femmech.output.camera`), and the axis colours those of their view triad
(:data:`femmech.output.annotate.AXIS_COLORS`).

Uses fe (the model's beam frames), output.annotate, .camera,
.mode_geometry, .renderer and .export.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from femmech.fe.model import FEModel
from femmech.output.annotate import AXIS_COLORS
from femmech.output.camera import VIEWS, check_view
from femmech.output.export import atomic_path
from femmech.output.mode_geometry import model_size
from femmech.output.renderer import SUPERSAMPLE, select_headless_backend

ARROW_FRACTION = 0.4
"""Default arrow length: this fraction of the median length of the drawn elements."""


def plot_local_axes(model: FEModel, filename, elements=None, length: float | None = None,
                    window_size=(1024, 768), camera=None, title: str | None = None) -> Path:
    """Render the local axes of beam elements off-screen to a PNG file.

    Parameters
    ----------
    model : FEModel
    filename : str or os.PathLike
        Target PNG; its folder must exist. Written atomically.
    elements : str, int or sequence of them, optional
        Beam groups (cell-set names) or line element indices to draw triads on; default
        all beam elements. All beams are drawn grey either way.
    length : float, optional
        Arrow length, m; default :data:`ARROW_FRACTION` of the median element length of
        the selection.
    window_size : (int, int)
        Image width and height, pixels.
    camera : str or camera position, optional
        As in :func:`femmech.output.plot.plot_mode` (default ``"iso"``).
    title : str, optional
        Default ``"Local beam axes: x red, y green, z blue"``.

    Returns
    -------
    Path
        ``filename``.

    Raises
    ------
    ValueError
        If the model has no beams, a group is unknown (listing the groups) or an index is
        out of range.
    """
    check_view(camera)
    beams = model.beams
    if not len(beams.cells):
        raise ValueError("the model has no beam elements to draw local axes of")
    chosen = _selection(model, elements)
    middle = model.mesh.points[beams.cells[chosen]].mean(axis=1)
    size = float(np.median(beams.length[chosen])) * ARROW_FRACTION if length is None \
        else float(length)
    if not (np.isfinite(size) and size > 0):
        raise ValueError(f"length must be a positive distance (m), got {length}")
    caption = (f"{chosen.size} of {len(beams.cells)} beam elements; arrows {size:.3g} m"
               f" (model {model_size(model):.3g} m)")
    title = "Local beam axes: x red, y green, z blue" if title is None else title
    image = _render(model, middle, beams.frames[chosen], size, window_size, camera,
                    (title, caption))
    _write_png(image, filename)
    return Path(filename)


def _render(model: FEModel, middle: np.ndarray, frames: np.ndarray, size: float,
            window_size, camera, texts) -> np.ndarray:
    """(H, W, 3) image: the structure, one arrow per axis (rows of ``frames``, (n, 3, 3))
    at the points ``middle`` (n, 3), the title and caption ``texts``, global axes."""
    width, height = (int(v) for v in window_size)
    select_headless_backend()
    import pyvista as pv

    k = SUPERSAMPLE
    plotter = pv.Plotter(off_screen=True, window_size=[k * width, k * height],
                         theme=pv.themes.DocumentTheme())
    try:
        font = int(np.clip(round(min(width, height) / 48), 8, 64))
        _add_structure(plotter, model, pv)
        for axis, color in enumerate(AXIS_COLORS[a] for a in "xyz"):
            cloud = pv.PolyData(middle)
            cloud["vectors"] = frames[:, axis, :]
            arrow = pv.Arrow(start=(0.0, 0.0, 0.0), direction=(1.0, 0.0, 0.0), scale=size,
                             tip_length=0.3, tip_radius=0.08, shaft_radius=0.03)
            plotter.add_mesh(cloud.glyph(orient="vectors", scale=False, geom=arrow),
                             color=color, smooth_shading=True)
        plotter.add_text(texts[0], position="upper_edge", font_size=font, color="black")
        plotter.add_text(texts[1], position="lower_left", font_size=font, color="#444444")
        plotter.add_axes(line_width=2 * k, xlabel="X", ylabel="Y", zlabel="Z")  # global
        if camera is None or isinstance(camera, str):
            direction, up = VIEWS[camera or "iso"]
            plotter.view_vector(direction, viewup=up)
            plotter.reset_camera()
        else:
            plotter.camera_position = camera
        image = plotter.screenshot(return_img=True)
    finally:
        plotter.close()
    return _downsample(image, k)


def _downsample(image: np.ndarray, k: int) -> np.ndarray:
    """Average k x k pixel blocks of an (H, W, C) uint8 image (supersampling)."""
    h, w, c = image.shape[0] // k, image.shape[1] // k, image.shape[2]
    blocks = image[:h * k, :w * k].reshape(h, k, w, k, c).astype(float)
    return np.rint(blocks.mean(axis=(1, 3))).astype(np.uint8)


def _write_png(image: np.ndarray, filename) -> None:
    from PIL import Image

    with atomic_path(filename) as tmp:
        Image.fromarray(image[..., :3]).save(tmp, format="PNG")


def _selection(model: FEModel, elements) -> np.ndarray:
    """Indices of the beam elements named by groups and/or indices (checked)."""
    n = len(model.beams.cells)
    if elements is None:
        return np.arange(n)
    items = [elements] if isinstance(elements, (str, int, np.integer)) else list(elements)
    out = []
    for item in items:
        if isinstance(item, str):
            if item not in model.mesh.cell_sets:
                raise ValueError(model.mesh.unknown_cell_set(item, "beam group"))
            out.append(np.asarray(model.mesh.cell_sets[item].get("line", ()), dtype=np.int64))
        else:
            index = int(item)
            if not 0 <= index < n:
                raise ValueError(f"line element {index} does not exist (the model has {n})")
            out.append(np.array([index]))
    chosen = np.unique(np.concatenate(out)) if out else np.empty(0, dtype=np.int64)
    if not chosen.size:
        raise ValueError(f"no beam elements selected by {elements!r}")
    return chosen


def _add_structure(plotter, model: FEModel, pv) -> None:
    """Grey beams (lines) and light shell faces, for orientation."""
    cells = model.beams.cells
    lines = np.column_stack([np.full(len(cells), 2), cells]).ravel()
    plotter.add_mesh(pv.PolyData(model.mesh.points, lines=lines), color="#7f7f7f",
                     line_width=3, render_lines_as_tubes=True)
    faces = []
    for kind, block in model.mesh.cells.items():
        if kind in ("triangle", "quad"):
            faces.append(np.column_stack([np.full(len(block), block.shape[1]), block]).ravel())
    if faces:
        plotter.add_mesh(pv.PolyData(model.mesh.points, faces=np.concatenate(faces)),
                         color="#d9d9d9", opacity=0.6, show_edges=True, edge_color="#9a9a9a")
