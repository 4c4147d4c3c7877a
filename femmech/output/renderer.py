"""One off-screen pyvista scene per model, redrawn for each mode: fast mode images.

:class:`ModeRenderer` builds the plotter, its meshes and actors once for a model and
then, per mode, only replaces points and scalars: the deformed beam curves feed VTK tube
and glyph filters (a pipeline, so the tubes follow their curves at the next render), the
shell and solid surfaces move in place, the undeformed ghost, the supports and the
camera stay. Building the scene and compiling its shaders takes most of a first image;
the following images cost a render and a read-back of the pixels.

What is drawn: tubes along the element curves coloured by ``|u| / max |u|`` with
spheres at the nodes, shells and solid surfaces flat-shaded with thin edges on the same
colour scale, a grey ghost of the undeformed model, dark cubes at supported nodes, red
balls at point masses, brown tubes for rigid links and spider legs, magenta coils for
springs (to the ground: from the moving node to a fixed ground plate; between coincident
nodes: a short vertical coil round the joint). Only what a model has is drawn, and
:attr:`ModeRenderer.legend` lists exactly that.

Headless rendering: VTK >= 9.4 picks its OpenGL window at run time (X, then EGL, then
OSMesa; https://docs.vtk.org/en/latest/advanced/runtime_settings.html). Without a
display, :func:`select_headless_backend` sets ``VTK_DEFAULT_OPENGL_WINDOW`` to the EGL
window (or to OSMesa when only libOSMesa is found) before the first render window is
created, unless the variable is already set; this skips the failing X attempt and its
warning.

Uses fe.dofs and output.mode_geometry, .camera and .annotate.
"""

from __future__ import annotations

import ctypes.util
import os
import sys
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from femmech.fe.dofs import DOF_PER_NODE
from femmech.fe.model import FEModel
from femmech.output.annotate import LegendEntry
from femmech.output.camera import Camera
from femmech.output.mode_geometry import (
    MASS_RADIUS_FRACTION,
    SPRING_LENGTH_FRACTION,
    Glyphs,
    coil,
    joint_nodes,
    marker_size,
    mode_mesh,
    model_size,
    node_radius,
    support_size,
    surface_mesh,
)
from femmech.output.surfaces import surface_nodes

SUPERSAMPLE = 2
"""Images are rendered at this multiple of the requested size and averaged down: EGL and
OSMesa windows support neither FXAA nor (reliably) MSAA."""
CMAP = "viridis"
COLORS = {"ghost": "#c4c4c4", "support": "#3c3c3c", "mass": "#b2182b", "link": "#a6611a",
          "spring": "#d01c8b", "edge": "#2b2b2b"}
LABELS = {"ghost": "undeformed", "support": "support", "mass": "point mass",
          "link": "rigid link / spider", "spring": "spring"}
_GLYPH = {"ghost": "ghost", "support": "square", "mass": "circle", "link": "line",
          "spring": "coil"}
_FEATURE_ANGLE = 30.0  # degrees: sharper edges belong to the undeformed outline
_TURNS = 5  # turns of a drawn coil spring


@dataclass(frozen=True)
class Decoration:
    """Further 3D glyphs of an image (e.g. mechanisms), drawn for a given scale.

    Attributes
    ----------
    draw : callable
        ``draw(plotter, scale)`` adds pyvista actors.
    points : callable
        ``points(scale)`` → ndarray (n, 3), m: what ``draw`` puts where (for the camera).
    legend : tuple of LegendEntry
        Entries for what ``draw`` adds.
    """

    draw: Callable
    points: Callable = field(default=lambda scale: np.empty((0, 3)))
    legend: tuple = ()


def select_headless_backend() -> None:
    """Choose VTK's EGL (or OSMesa) window when there is no display (see module notes)."""
    if not sys.platform.startswith("linux") or "VTK_DEFAULT_OPENGL_WINDOW" in os.environ:
        return
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return
    if ctypes.util.find_library("EGL"):
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"
    elif ctypes.util.find_library("OSMesa"):
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkOSOpenGLRenderWindow"


def scene_legend(glyphs: Glyphs, has_beams: bool, has_surfaces: bool,
                 show_undeformed: bool) -> tuple[LegendEntry, ...]:
    """Legend entries of exactly the glyphs a :class:`ModeRenderer` draws for a model."""
    drawn = {"ghost": show_undeformed and (has_beams or has_surfaces),
             "support": glyphs.supports.size > 0, "mass": glyphs.masses.size > 0,
             "link": len(glyphs.links) > 0,
             "spring": len(glyphs.springs) > 0 or glyphs.ground.size > 0}
    return tuple(LegendEntry(LABELS[k], COLORS[k], _GLYPH[k]) for k, shown in drawn.items()
                 if shown)


class ModeRenderer:
    """An off-screen scene of one model that draws any of its mode shapes.

    Parameters
    ----------
    model : FEModel
    view_size : (int, int)
        Width and height of the 3D view, pixels (rendered ``supersample`` times larger).
    camera : Camera
        Used for every mode (:func:`femmech.output.camera.fit_camera`).
    glyphs : Glyphs
        Supports, masses, links and springs to draw
        (:func:`~femmech.output.mode_geometry.model_glyphs`).
    n_sub : int
        Sub-intervals per element of the drawn curves.
    show_undeformed : bool
        Draw the grey ghost of the undeformed model.
    supersample : int

    Examples
    --------
    ``with ModeRenderer(model, (800, 600), camera, glyphs) as r: image = r.render(u, 30.0)``
    """

    def __init__(self, model: FEModel, view_size, camera: Camera, glyphs: Glyphs,
                 n_sub: int = 8, show_undeformed: bool = True, supersample: int = SUPERSAMPLE):
        select_headless_backend()
        import pyvista as pv

        self.model, self.glyphs, self.n_sub, self.k = model, glyphs, int(n_sub), int(supersample)
        width, height = (int(v) for v in view_size)
        self.plotter = pv.Plotter(off_screen=True, window_size=[self.k * width, self.k * height],
                                  theme=pv.themes.DocumentTheme())
        # multisampling costs 3-4 times the render time in Mesa's software OpenGL; the
        # supersampling (k x k pixels averaged) smooths the edges instead
        self.plotter.render_window.SetMultiSamples(0)
        # one headlight: half the fragment cost of pyvista's five-light kit, same reading
        self.plotter.renderer.remove_all_lights()
        self.plotter.renderer.add_light(pv.Light(light_type="headlight"))
        self.size = model_size(model)
        self.marker = marker_size(model)
        self.node_r = node_radius(model)
        self._surface_nodes = surface_nodes(model)
        self.has_beams = len(model.beams.cells) > 0
        self.has_surfaces = self._surface_nodes.size > 0
        self.legend = scene_legend(glyphs, self.has_beams, self.has_surfaces, show_undeformed)
        zero = np.zeros(model.n_dof)
        self._style = {"scalars": "magnitude", "cmap": CMAP, "clim": (0.0, 1.0),
                       "show_scalar_bar": False}
        if self.has_beams:
            self._add_beams(zero, show_undeformed)
        if self.has_surfaces:
            self._add_surfaces(zero, show_undeformed)
        self._add_markers()
        self.plotter.camera_position = camera.as_pyvista()
        self.plotter.camera.view_angle = camera.view_angle
        self.plotter.renderer.reset_camera_clipping_range()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        """Release the render window."""
        self.plotter.close()

    def render(self, u: np.ndarray, scale: float, decoration: Decoration | None = None):
        """The 3D view of mode ``u`` (n_dof,) drawn ``scale`` times, (k h, k w, 3) uint8."""
        u = np.asarray(u, dtype=float)
        nodal = scale * u.reshape(-1, DOF_PER_NODE)[:, :3]
        displaced = self.model.mesh.points + nodal
        largest = self._update_beams(u, scale, nodal)
        if self.has_surfaces:
            disp = nodal[self._surface_nodes]
            largest = max(largest, float(np.linalg.norm(disp, axis=1).max()))
        self._normalise(largest)
        if self.has_surfaces:
            self._surface.points = displaced[self._surface_nodes]
            self._surface.point_data["magnitude"] = self._magnitude(nodal[self._surface_nodes])
        self._update_markers(displaced)
        before = set(self.plotter.renderer.actors)
        if decoration is not None:
            decoration.draw(self.plotter, scale)
        try:
            self.plotter.renderer.reset_camera_clipping_range()
            image = _grab(self.plotter.render_window)
        finally:
            for name in set(self.plotter.renderer.actors) - before:
                self.plotter.remove_actor(name, render=False)
        return image

    # -- building ---------------------------------------------------------------------

    def _add_beams(self, zero, show_undeformed) -> None:
        """Tubes along the curves (tube filter on ``_lines``), joint spheres (glyph filter)."""
        import pyvista as pv

        style = {**self._style, "smooth_shading": True, "specular": 0.3, "specular_power": 20}
        self._lines = mode_mesh(self.model, zero, 0.0, self.n_sub)
        self._lines.point_data.active_scalars_name = "radius"
        _colour_by_magnitude(self.plotter.add_mesh(_tube_filter(self._lines, n_sides=24,
                                                                vary=True), **style))
        self._joint_nodes = joint_nodes(self.model)
        self._joints = pv.PolyData(self.model.mesh.points[self._joint_nodes])
        self._joints.point_data["radius"] = self.node_r[self._joint_nodes]
        self._joints.point_data["magnitude"] = np.zeros(self._joint_nodes.size)
        self._joints.point_data.active_scalars_name = "radius"
        sphere = pv.Sphere(radius=1.0, theta_resolution=20, phi_resolution=12)
        _colour_by_magnitude(self.plotter.add_mesh(_glyph_filter(self._joints, sphere,
                                                                 by_scalar=True), **style))
        if show_undeformed:
            ghost = mode_mesh(self.model, zero, 0.0, 1)
            self.plotter.add_mesh(ghost.tube(radius=0.35 * float(self.node_r.max()), n_sides=12,
                                             capping=False),
                                  color=COLORS["ghost"], smooth_shading=True)

    def _add_surfaces(self, zero, show_undeformed) -> None:
        """Flat-shaded surfaces with thin edges, moved in place; the outline ghost."""
        self._surface = surface_mesh(self.model, zero, 0.0)
        self.plotter.add_mesh(self._surface, smooth_shading=False, show_edges=True,
                              edge_color=COLORS["edge"], line_width=self.k // 2 or 1,
                              ambient=0.2, diffuse=0.8, specular=0.0, **self._style)
        if show_undeformed:
            ghost = surface_mesh(self.model, zero, 0.0).extract_feature_edges(
                feature_angle=_FEATURE_ANGLE, boundary_edges=True, non_manifold_edges=True,
                feature_edges=True, manifold_edges=False)
            self.plotter.add_mesh(ghost, color=COLORS["ghost"], line_width=1.5 * self.k)

    def _add_markers(self) -> None:
        """Supports (static cubes), masses, links and springs (updated per mode)."""
        import pyvista as pv

        g, points = self.glyphs, self.model.mesh.points
        if g.supports.size:
            edge = support_size(self.model, g)
            cube = pv.Cube(x_length=edge, y_length=edge, z_length=edge)
            cubes = pv.PolyData(points[g.supports]).glyph(scale=False, orient=False, geom=cube)
            self.plotter.add_mesh(cubes, color=COLORS["support"])
        if g.masses.size:
            self._masses = pv.PolyData(points[g.masses].copy())
            ball = pv.Sphere(radius=MASS_RADIUS_FRACTION * self.size)
            self.plotter.add_mesh(_glyph_filter(self._masses, ball, by_scalar=False),
                                  color=COLORS["mass"], smooth_shading=True, specular=0.4)
        if len(g.links):
            self._links = pv.PolyData(points.copy(), lines=np.column_stack(
                [np.full(len(g.links), 2), g.links]).ravel())
            self.plotter.add_mesh(_tube_filter(self._links, radius=0.4 * self.marker),
                                  color=COLORS["link"], smooth_shading=True)
        if len(g.springs) or g.ground.size:
            spring_points, spring_lines = self._spring_lines(points)
            self._springs = pv.PolyData(spring_points, lines=spring_lines)
            self.plotter.add_mesh(_tube_filter(self._springs, radius=0.2 * self.marker),
                                  color=COLORS["spring"], smooth_shading=True)
        if g.ground.size:
            plate = pv.Cube(x_length=4 * self.marker, y_length=4 * self.marker,
                            z_length=0.6 * self.marker)
            ends = points[g.ground] + SPRING_LENGTH_FRACTION * self.size * g.ground_dir
            self.plotter.add_mesh(pv.PolyData(ends).glyph(scale=False, orient=False, geom=plate),
                                  color=COLORS["support"])

    # -- per mode ---------------------------------------------------------------------

    def _update_beams(self, u, scale, nodal) -> float:
        """Move the curves and joints; returns the largest scaled displacement on them."""
        if not self.has_beams:
            return 0.0
        from femmech.fe.recovery import beam_deflection_curves

        points, disp = beam_deflection_curves(self.model, u, self.n_sub)
        disp = scale * disp
        self._lines.points = points + disp
        self._curve_disp, self._nodal = disp, nodal
        return float(np.linalg.norm(disp, axis=1).max()) if len(disp) else 0.0

    def _normalise(self, largest: float) -> None:
        """Colour scalars of the beams: ``|u| / largest`` (shared with the surfaces)."""
        self._largest = largest
        if self.has_beams:
            self._lines.point_data["magnitude"] = self._magnitude(self._curve_disp)
            self._lines.point_data.active_scalars_name = "radius"
            nodal = self._nodal[self._joint_nodes]
            self._joints.points = self.model.mesh.points[self._joint_nodes] + nodal
            self._joints.point_data["magnitude"] = self._magnitude(nodal)
            self._joints.point_data.active_scalars_name = "radius"

    def _magnitude(self, disp: np.ndarray) -> np.ndarray:
        norm = np.linalg.norm(disp, axis=1)
        return norm / self._largest if self._largest > 0 else norm

    def _update_markers(self, displaced: np.ndarray) -> None:
        g = self.glyphs
        if g.masses.size:
            self._masses.points = displaced[g.masses]
        if len(g.links):
            self._links.points = displaced
        if len(g.springs) or g.ground.size:
            self._springs.points = self._spring_lines(displaced)[0]

    def _spring_lines(self, displaced: np.ndarray):
        """Points and lines of every spring's coil (node pairs, then to the ground); a coil
    between coincident nodes is wider than the tubes there, so that it shows round them."""
        g, r = self.glyphs, self.node_r
        ground = (self.model.mesh.points[g.ground]
                  + SPRING_LENGTH_FRACTION * self.size * g.ground_dir)
        chains = [coil(*_spread(displaced[a], displaced[b], 3.0 * self.marker),
                       1.6 * max(r[a], r[b], 0.5 * self.marker), _TURNS)
                  for a, b in g.springs]
        chains += [coil(a, b, self.marker, _TURNS) for a, b in zip(displaced[g.ground], ground,
                                                                   strict=True)]
        n = len(chains[0])
        lines = np.column_stack([np.full(len(chains), n),
                                 np.arange(len(chains) * n).reshape(-1, n)]).ravel()
        return np.concatenate(chains), lines


def _spread(a: np.ndarray, b: np.ndarray, half: float):
    """Ends of a drawn spring from a to b; a spring between (nearly) coincident nodes is
    drawn as a short vertical coil of length ``2 half`` centred between them."""
    if np.linalg.norm(b - a) >= half:
        return a, b
    centre, up = 0.5 * (a + b), np.array([0.0, 0.0, half])
    return centre - up, centre + up


def _grab(window) -> np.ndarray:
    """Render the window once and read its pixels, (height, width, 3) uint8, top row first."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkCommonCore import vtkUnsignedCharArray

    window.Render()
    width, height = window.GetSize()
    data = vtkUnsignedCharArray()
    window.GetPixelData(0, 0, width - 1, height - 1, 0, data, 0)  # back buffer, RGB
    return np.ascontiguousarray(vtk_to_numpy(data).reshape(height, width, 3)[::-1])


def _colour_by_magnitude(actor) -> None:
    """Colour a filter's output by its ``"magnitude"`` point array, whichever is active."""
    actor.mapper.SetScalarModeToUsePointFieldData()
    actor.mapper.SelectColorArray("magnitude")


def _tube_filter(lines, radius: float = 1.0, n_sides: int = 12, vary: bool = False):
    """A vtkTubeFilter on ``lines`` (radius by the active point scalars when ``vary``)."""
    from vtkmodules.vtkFiltersCore import vtkTubeFilter

    tube = vtkTubeFilter()
    tube.SetInputData(lines)
    tube.SetNumberOfSides(n_sides)
    tube.CappingOn()
    if vary:
        tube.SetVaryRadiusToVaryRadiusByAbsoluteScalar()
    else:
        tube.SetRadius(radius)
    return tube


def _glyph_filter(points, source, by_scalar: bool):
    """A vtkGlyph3D putting ``source`` at every point (scaled by the active scalars)."""
    from vtkmodules.vtkFiltersCore import vtkGlyph3D

    glyph = vtkGlyph3D()
    glyph.SetInputData(points)
    glyph.SetSourceData(source)
    glyph.OrientOff()
    if by_scalar:
        glyph.SetScaleModeToScaleByScalar()
    else:
        glyph.SetScaleModeToDataScalingOff()
    glyph.SetScaleFactor(1.0)
    return glyph
