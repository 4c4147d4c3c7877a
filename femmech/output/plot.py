"""Off-screen images of mode shapes with pyvista (PNG, no display needed).

pyvista is imported inside the functions, so ``import femmech.output`` stays light.
Beams are drawn as tubes along the deformed curves recovered with the elements' shape
functions (:func:`femmech.fe.recovery.beam_deflection_curves`), coloured by the
displacement magnitude, over a grey ghost of the undeformed structure.

Shells are drawn as surfaces at their mid-surface (no thickness) and solids by their
outer surface (:mod:`femmech.output.surfaces`), deformed, coloured by the displacement
magnitude interpolated linearly over each face, with flat shading and thin element
edges, so that the image looks the same for any plate thickness. Their undeformed
ghost is a grey wireframe of the outlines (free edges, plate junctions and edges
sharper than 30 degrees). Beams, shells and solids of one model share one colour scale.

Headless rendering: VTK >= 9.4 picks its OpenGL window at run time (X, then EGL, then
OSMesa; https://docs.vtk.org/en/latest/advanced/runtime_settings.html). Without a
display, :func:`plot_mode` sets ``VTK_DEFAULT_OPENGL_WINDOW`` to the EGL window (or to
OSMesa when only libOSMesa is found) before the first render window is created, unless
the variable is already set; this skips the failing X attempt and its warning.

Stage 6 (output): uses analysis.modes, fe and output.export and .surfaces.
"""

from __future__ import annotations

import ctypes.util
import os
import sys
from pathlib import Path

import numpy as np

from femmech.analysis.modes import ModeSet
from femmech.fe.dofs import DOF_PER_NODE
from femmech.fe.model import FEModel, node_index
from femmech.fe.recovery import beam_deflection_curves
from femmech.output.export import _check_sizes, _mode_indices, atomic_path
from femmech.output.surfaces import shell_cells, solid_cells, surface_faces, surface_nodes

SCALE_FRACTION = 0.12
"""Automatic scale: the largest drawn displacement is this fraction of the model size."""
RADIUS_RANGE = (0.006, 0.02)
"""Drawn tube radii are the sections' drawing radii clipped to this range, as fractions of
the model size: thin frames stay visible and thick sections do not hide the deformation."""
MASS_RADIUS_FRACTION = 0.03
"""Radius of the spheres drawn at point masses, as a fraction of the model size."""
SUPERSAMPLE = 2
"""Images are rendered at this multiple of the requested size and averaged down: EGL and
OSMesa windows support neither FXAA nor (reliably) MSAA, and VTK's SSAA pass shrinks text."""
_VIEWS = {"iso": "view_isometric", "xy": "view_xy", "xz": "view_xz", "yz": "view_yz"}
_CMAP = "viridis"
_GHOST_COLOR = "#9a9a9a"
_FIXTURE_COLOR = "#3c3c3c"
_MASS_COLOR = "#b2182b"
_LINK_COLOR = "#d08c2c"  # rigid links and node-to-node springs
_EDGE_COLOR = "#2b2b2b"
_FEATURE_ANGLE = 30.0  # degrees: sharper edges belong to the undeformed outline


def model_size(model: FEModel) -> float:
    """Largest extent of the model's bounding box, m (1 for a model of one point)."""
    extent = float(np.ptp(model.mesh.points, axis=0).max())
    return extent if extent > 0 else 1.0


def mode_scale(model: FEModel, u_full: np.ndarray, n_sub: int = 8,
               fraction: float = SCALE_FRACTION) -> float:
    """Scale factor that makes the largest displacement ``fraction`` of the model size.

    The largest displacement is taken along the recovered beam curves (it may lie
    between nodes) and over the nodes of shell and solid surfaces. A zero shape gets
    scale 1.

    Parameters
    ----------
    model : FEModel
    u_full : ndarray (n_dof,)
        Full DOF vector, m and rad.
    n_sub : int
        Sub-intervals per element of the recovered curves.
    fraction : float
        Target ratio of the largest drawn displacement to :func:`model_size`.

    Returns
    -------
    float
        Scale factor (1/the unit of ``u_full``, times m).
    """
    largest = _largest_displacement(model, u_full, n_sub)
    return fraction * model_size(model) / largest if largest > 0 else 1.0


def _largest_displacement(model: FEModel, u_full: np.ndarray, n_sub: int) -> float:
    """Largest translation along the beam curves and at the surface nodes, m."""
    _, disp = beam_deflection_curves(model, u_full, n_sub)
    largest = float(np.linalg.norm(disp, axis=1).max()) if len(disp) else 0.0
    nodes = surface_nodes(model)
    if nodes.size:
        nodal = np.asarray(u_full, dtype=float).reshape(-1, DOF_PER_NODE)[nodes, :3]
        largest = max(largest, float(np.linalg.norm(nodal, axis=1).max()))
    return largest


def mode_title(modes: ModeSet, index: int) -> str:
    """Image title such as ``"Mode 3: 17.71 Hz"`` (modes numbered from 1)."""
    if modes.rigid[index]:
        return f"Mode {index + 1}: rigid-body (0 Hz)"
    return f"Mode {index + 1}: {modes.freq_hz[index]:.4g} Hz"


def mode_mesh(model: FEModel, u_full: np.ndarray, scale: float, n_sub: int = 8):
    """Deformed beams as pyvista polylines, one per element, with the drawing data.

    Parameters
    ----------
    model : FEModel
    u_full : ndarray (n_dof,)
        Full DOF vector (a mode shape), m and rad.
    scale : float
        Displacement magnification.
    n_sub : int
        Sub-intervals per element (each element is a polyline of ``n_sub + 1`` points).

    Returns
    -------
    pyvista.PolyData
        Points at the deformed positions ``x + scale u``. Point data ``"displacement"``
        (scaled displacement, m, (n_points, 3)), ``"magnitude"`` (``|u| / max |u|``, 0..1;
        all 0 for a zero shape) and ``"radius"`` (tube radius, m: the section's drawing
        radius clipped to :data:`RADIUS_RANGE` times the model size).
    """
    import pyvista as pv

    points, disp = beam_deflection_curves(model, u_full, n_sub)
    disp = scale * disp
    norm = np.linalg.norm(disp, axis=1)
    largest = norm.max() if norm.size else 0.0
    n_el, n_pt = len(model.beams.cells), n_sub + 1
    lines = np.hstack([np.full((n_el, 1), n_pt),
                       np.arange(n_el * n_pt).reshape(n_el, n_pt)]).ravel()
    mesh = pv.PolyData(points + disp, lines=lines)
    mesh.point_data["displacement"] = disp
    mesh.point_data["magnitude"] = norm / largest if largest > 0 else norm
    mesh.point_data["radius"] = np.repeat(_tube_radius(model), n_pt)
    return mesh


def surface_mesh(model: FEModel, u_full: np.ndarray, scale: float,
                 largest: float | None = None):
    """Deformed shell and solid surfaces as a pyvista mesh of triangles and quads.

    Parameters
    ----------
    model : FEModel
    u_full : ndarray (n_dof,)
        Full DOF vector (a mode shape), m and rad; only the translations are drawn.
    scale : float
        Displacement magnification.
    largest : float, optional
        Scaled displacement (m) that maps to magnitude 1 (default: the largest on the
        surface), so that beams and surfaces share one colour scale.

    Returns
    -------
    pyvista.PolyData
        The faces of :func:`femmech.output.surfaces.surface_faces` over the surface
        nodes only (renumbered; point data ``"node"`` holds the model node index), at
        ``x + scale u``. Point data ``"displacement"`` (scaled, m, (n_points, 3)) and
        ``"magnitude"`` (``|u| / largest``, 0..1); no faces for a beam model.
    """
    import pyvista as pv

    faces = surface_faces(model)
    nodes = surface_nodes(model)
    new = np.full(model.mesh.n_nodes, -1, dtype=np.int64)
    new[nodes] = np.arange(nodes.size)
    stream = [np.column_stack([np.full(len(f), f.shape[1]), new[f]]).ravel()
              for f in faces.values()]
    disp = scale * np.asarray(u_full, dtype=float).reshape(-1, DOF_PER_NODE)[nodes, :3]
    norm = np.linalg.norm(disp, axis=1)
    if largest is None:
        largest = float(norm.max()) if norm.size else 0.0
    mesh = pv.PolyData(model.mesh.points[nodes] + disp,
                       faces=np.concatenate(stream) if stream else None)
    mesh.point_data["node"] = nodes
    mesh.point_data["displacement"] = disp
    mesh.point_data["magnitude"] = norm / largest if largest > 0 else norm
    return mesh


def _tube_radius(model: FEModel) -> np.ndarray:
    """Drawing radius per element, m, clipped to :data:`RADIUS_RANGE` of the model size."""
    low, high = RADIUS_RANGE
    return np.clip(model.beams.radius, low * model_size(model), high * model_size(model))


def _node_radius(model: FEModel) -> np.ndarray:
    """Per node, the largest tube radius of its elements (0 for nodes without beams)."""
    radius = np.zeros(model.mesh.n_nodes)
    np.maximum.at(radius, model.beams.cells, _tube_radius(model)[:, None])
    return radius


def _fixed_nodes(model: FEModel) -> np.ndarray:
    """Nodes with at least one DOF fixed by a support (an all-zero row of T).

    Nodes used only by solid elements count only their translations: their rotations
    have no stiffness and are fixed by the model itself, not by a support.
    """
    T = model.T.tocsr()
    fixed = (np.diff(T.indptr) == 0).reshape(-1, DOF_PER_NODE)
    solids = solid_cells(model)
    if solids:
        solid_only = np.zeros(model.mesh.n_nodes, dtype=bool)
        solid_only[np.concatenate([c.ravel() for c in solids.values()])] = True
        solid_only[model.beams.cells.ravel()] = False
        for cells in shell_cells(model).values():
            solid_only[cells.ravel()] = False
        fixed[solid_only, 3:] = False
    return np.flatnonzero(fixed.any(axis=1))


def _select_headless_backend() -> None:
    """Choose VTK's EGL (or OSMesa) window when there is no display (see module notes)."""
    if not sys.platform.startswith("linux") or "VTK_DEFAULT_OPENGL_WINDOW" in os.environ:
        return
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return
    if ctypes.util.find_library("EGL"):
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"
    elif ctypes.util.find_library("OSMesa"):
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkOSOpenGLRenderWindow"


def plot_mode(model: FEModel, modes: ModeSet, index: int, filename, scale: float | None = None,
              window_size=(1024, 768), camera=None, n_sub: int = 8,
              show_undeformed: bool = True, masses=None, title: str | None = None,
              decorate=None) -> Path:
    """Render one mode shape off-screen to a PNG file.

    Parameters
    ----------
    model : FEModel
    modes : ModeSet
    index : int
        0-based mode index; the title numbers modes from 1 (``"Mode 1: 14.47 Hz"``).
    filename : str or os.PathLike
        Target PNG; its folder must exist. Written atomically.
    scale : float, optional
        Displacement magnification (default :func:`mode_scale`: the largest displacement
        is drawn as :data:`SCALE_FRACTION` of the model size).
    window_size : (int, int)
        Image width and height, pixels.
    camera : str or camera position, optional
        ``"iso"`` (default), ``"xy"``, ``"xz"``, ``"yz"``, or a pyvista camera position
        ``[(position), (focal point), (view up)]``.
    n_sub : int
        Sub-intervals per element of the drawn curves.
    show_undeformed : bool
        Draw a thin grey ghost of the undeformed beams.
    masses : sequence of PointMass, optional
        Point masses to draw as spheres at their displaced nodes; default: all point
        masses of the model (``model.mass_nodes``).
    title : str, optional
        Replaces the default title (:func:`mode_title`).
    decorate : callable, optional
        ``decorate(plotter, scale)`` adds further actors (e.g. mechanisms drawn
        schematically) before the camera is set.

    Returns
    -------
    Path
        ``filename``.

    Notes
    -----
    Tubes follow the element curves, coloured by ``|u| / max |u|``; nodes carry spheres
    of the tube radius (clean joints) and supported nodes (any DOF fixed) dark cubes.
    Shells and the outer surfaces of solids are drawn as flat-shaded faces with thin
    edges (:func:`surface_mesh`) over a grey wireframe of their undeformed outlines, on
    the same colour scale as the tubes; the drawing does not depend on shell thickness.
    The plotter has its own document theme, so the global pyvista theme does not change
    the image.
    """
    _check_sizes(model, modes)
    _check_camera(camera)
    index = int(_mode_indices(modes, [index])[0])
    u = modes.shapes[:, index]
    scale = mode_scale(model, u, n_sub) if scale is None else float(scale)
    if masses is None:
        mass_nodes = model.mass_nodes
    else:
        mass_nodes = np.array([node_index(model.mesh, m.node, "point mass") for m in masses],
                              dtype=np.int64)
    width, height = (int(v) for v in window_size)
    _select_headless_backend()
    import pyvista as pv

    k = SUPERSAMPLE
    plotter = pv.Plotter(off_screen=True, window_size=[k * width, k * height],
                         theme=pv.themes.DocumentTheme())
    try:
        font = _font_size((k * width, k * height))
        _add_scene(plotter, model, u, scale, n_sub, show_undeformed, mass_nodes, int(1.3 * font))
        if decorate is not None:
            decorate(plotter, scale)
        plotter.add_text(mode_title(modes, index) if title is None else title,
                         position="upper_edge", font_size=font, color="black")
        _set_camera(plotter, camera)
        image = plotter.screenshot(return_img=True)
    finally:
        plotter.close()
    _write_png(_downsample(image, k), filename)
    return Path(filename)


def plot_modes(model: FEModel, modes: ModeSet, out_dir, indices=None, prefix: str = "mode",
               **kwargs) -> list[Path]:
    """Render several modes to ``out_dir/{prefix}_{n:02d}.png`` (n from 1), one per mode.

    Parameters
    ----------
    model : FEModel
    modes : ModeSet
    out_dir : str or os.PathLike
        Existing folder.
    indices : sequence of int, optional
        0-based mode indices (default all).
    prefix : str
        File name prefix.
    **kwargs
        Passed to :func:`plot_mode` (``window_size``, ``camera``, ``masses``, ...).

    Returns
    -------
    list of Path
        The written files, in the order of ``indices``.
    """
    out = Path(out_dir)
    if not out.is_dir():
        raise FileNotFoundError(f"output folder {out} does not exist")
    return [plot_mode(model, modes, int(i), out / f"{prefix}_{i + 1:02d}.png", **kwargs)
            for i in _mode_indices(modes, indices)]


def _font_size(window_size) -> int:
    """Title font size for a render window, legible from 400x300 to 1920x1080 images."""
    return int(np.clip(round(min(window_size) / 48), 8, 64))


def _downsample(image: np.ndarray, k: int) -> np.ndarray:
    """Average k x k pixel blocks of an (H, W, C) uint8 image (supersampling anti-aliasing)."""
    h, w, c = image.shape[0] // k, image.shape[1] // k, image.shape[2]
    blocks = image[:h * k, :w * k].reshape(h, k, w, k, c).astype(float)
    return np.rint(blocks.mean(axis=(1, 3))).astype(np.uint8)


def _write_png(image: np.ndarray, filename) -> None:
    """Write an (H, W, 3) uint8 array to a PNG file atomically."""
    from PIL import Image

    with atomic_path(filename) as tmp:
        Image.fromarray(image).save(tmp, format="PNG")


def _add_scene(plotter, model, u, scale, n_sub, show_undeformed, mass_nodes,
               font_size) -> None:
    """Beams (tubes, joints), shell/solid surfaces, their ghosts, supports, masses, links."""
    import pyvista as pv

    bar = {"title": "displacement\n(relative)", "vertical": True, "n_labels": 3, "fmt": "%.1f",
           "position_x": 0.87, "position_y": 0.25, "width": 0.05, "height": 0.5,
           "color": "black", "title_font_size": font_size, "label_font_size": font_size,
           "unconstrained_font_size": True}
    style = {"scalars": "magnitude", "cmap": _CMAP, "clim": (0.0, 1.0)}
    node_r = _node_radius(model)
    marker = float(node_r.max()) if node_r.max() > 0 else RADIUS_RANGE[0] * model_size(model)
    has_surface = surface_nodes(model).size > 0
    largest = scale * _largest_displacement(model, u, n_sub) if has_surface else None
    if len(model.beams.cells):
        _add_beams(plotter, model, u, scale, n_sub, show_undeformed, style, bar, largest)
        bar = None  # one colour bar, drawn with the first scalar mesh
    if has_surface:
        _add_surfaces(plotter, model, u, scale, show_undeformed, style, bar, largest)
    displaced = model.mesh.points + scale * u.reshape(-1, DOF_PER_NODE)[:, :3]
    _add_markers(plotter, model, displaced, mass_nodes, node_r, marker)
    if len(model.links):
        segments = pv.PolyData(displaced, lines=np.column_stack(
            [np.full(len(model.links), 2), model.links]).ravel())
        plotter.add_mesh(segments.tube(radius=0.4 * marker, n_sides=12),
                         color=_LINK_COLOR, smooth_shading=True)


def _add_beams(plotter, model, u, scale, n_sub, show_undeformed, style, bar, largest) -> None:
    """Deformed tubes with joint spheres and the undeformed ghost tubes."""
    import pyvista as pv

    style = {**style, "smooth_shading": True, "specular": 0.3, "specular_power": 20}
    lines = mode_mesh(model, u, scale, n_sub)
    if largest is None:
        largest = np.linalg.norm(lines.point_data["displacement"], axis=1).max()
    elif largest > 0:  # shared with the surfaces
        lines.point_data["magnitude"] = (np.linalg.norm(lines.point_data["displacement"], axis=1)
                                         / largest)
    plotter.add_mesh(lines.tube(scalars="radius", absolute=True, n_sides=24, capping=True),
                     scalar_bar_args=bar, **style)
    node_r = _node_radius(model)
    nodal = scale * u.reshape(-1, DOF_PER_NODE)[:, :3]
    joints = pv.PolyData(model.mesh.points + nodal)
    joints.point_data["radius"] = node_r
    norm = np.linalg.norm(nodal, axis=1)
    joints.point_data["magnitude"] = norm / largest if largest > 0 else norm
    sphere = pv.Sphere(radius=1.0, theta_resolution=24, phi_resolution=16)
    plotter.add_mesh(joints.glyph(scale="radius", orient=False, geom=sphere),
                     show_scalar_bar=False, **style)
    if show_undeformed:
        ghost = mode_mesh(model, np.zeros_like(u), 0.0, 1)
        plotter.add_mesh(ghost.tube(radius=0.35 * float(node_r.max()), n_sides=12,
                                    capping=False),
                         color=_GHOST_COLOR, opacity=0.35, smooth_shading=True)


def _add_surfaces(plotter, model, u, scale, show_undeformed, style, bar, largest) -> None:
    """Deformed shell/solid surfaces (flat shading, thin edges) and the outline ghost."""
    surface = surface_mesh(model, u, scale, largest)
    plotter.add_mesh(surface, smooth_shading=False, show_edges=True, edge_color=_EDGE_COLOR,
                     line_width=1, ambient=0.2, diffuse=0.8, specular=0.0,
                     show_scalar_bar=bar is not None, scalar_bar_args=bar or {}, **style)
    if show_undeformed:
        ghost = surface_mesh(model, np.zeros_like(u), 0.0).extract_feature_edges(
            feature_angle=_FEATURE_ANGLE, boundary_edges=True, non_manifold_edges=True,
            feature_edges=True, manifold_edges=False)
        plotter.add_mesh(ghost, color=_GHOST_COLOR, line_width=3, opacity=0.7)


def _add_markers(plotter, model, displaced, mass_nodes, node_r, marker) -> None:
    """Dark cubes at supported nodes (undeformed), red spheres at point masses (displaced).

    Cubes are three times the largest tube radius at the supported nodes, or three times
    ``marker`` (m) where no beam meets them.
    """
    import pyvista as pv

    fixed = _fixed_nodes(model)
    if fixed.size:
        radius = float(node_r[fixed].max())
        edge = 3.0 * (radius if radius > 0 else marker)
        cube = pv.Cube(x_length=edge, y_length=edge, z_length=edge)
        cubes = pv.PolyData(model.mesh.points[fixed]).glyph(scale=False, orient=False,
                                                            geom=cube)
        plotter.add_mesh(cubes, color=_FIXTURE_COLOR)
    if mass_nodes.size:
        ball = pv.Sphere(radius=MASS_RADIUS_FRACTION * model_size(model))
        balls = pv.PolyData(displaced[mass_nodes]).glyph(scale=False, orient=False, geom=ball)
        plotter.add_mesh(balls, color=_MASS_COLOR, smooth_shading=True, specular=0.4)


def _check_camera(camera) -> None:
    if isinstance(camera, str) and camera not in _VIEWS:
        raise ValueError(f"unknown camera {camera!r}; use one of {sorted(_VIEWS)} or a"
                         " pyvista camera position")


def _set_camera(plotter, camera) -> None:
    """Apply a named view or an explicit camera position, then fit the scene."""
    camera = "iso" if camera is None else camera
    if isinstance(camera, str):
        getattr(plotter, _VIEWS[camera])()
        plotter.reset_camera()
    else:
        plotter.camera_position = camera
