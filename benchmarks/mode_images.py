"""Benchmark: time per mode image, the old path (one plotter per image) and the new one.

The frame example (``examples/frame_modes.py``: 193 beam elements,
springs, a motor mass on a rigid link; 12 modes) and the shell example
(``examples/shell_frame_modes.py``: 1 576 nodes of shells, stiffeners, a spider; 8
images, as the example writes) are drawn at the default 1024 x 768 by

- ``old``: the former per-image path of femmech (a verbatim copy below, from
  ``femmech/output/plot.py`` at commit 21c9fe6): a new off-screen plotter per image,
  2 x 2 supersampling with VTK's default 4-sample MSAA and five-light kit, the camera
  reset per image, ``plot_mode`` called in a loop (as ``plot_modes`` did);
- ``new``: :func:`femmech.output.plot_modes` with ``workers=1``: one scene per model,
  points and scalars replaced per mode, one camera, the current annotations;
- ``new, 2 workers``: the same on two spawned worker processes.

Each path runs ``--repeats`` times (default 3) into a fresh folder; the table gives the
minimum total wall time, the time per image, the CPU time of that run (this process and
its workers; with other programs sharing the cores it is the steadier figure), and, where
this process writes the PNGs, the time to the first image (the new path builds its scene
and compiles its shaders there) and the time per image after the first. The mode shapes
are solved once per model, outside the timing; pyvista is imported before the first
timed run.

Usage::

    python benchmarks/mode_images.py [--repeats 3] [--only frame|shell]

Results are printed and written to ``benchmarks/results/mode_images.txt``.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import tempfile
import time
from pathlib import Path

import numpy as np

import femmech as fm
import femmech.output.plot
from femmech.fe.dofs import DOF_PER_NODE
from femmech.fe.model import node_index
from femmech.output import plot_modes
from femmech.output.export import atomic_path
from femmech.output.mode_geometry import (
    fixed_nodes,
    largest_displacement,
    mode_mesh,
    mode_scale,
    model_size,
    node_radius,
    surface_mesh,
)
from femmech.output.plot import mode_title
from femmech.output.renderer import select_headless_backend
from femmech.output.surfaces import surface_nodes

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"

# -- the old path, as it was (femmech/output/plot.py at 21c9fe6, docstrings left out) -----

SCALE_FRACTION = 0.12
RADIUS_RANGE = (0.006, 0.02)
MASS_RADIUS_FRACTION = 0.03
SUPERSAMPLE = 2
_VIEWS = {"iso": "view_isometric", "xy": "view_xy", "xz": "view_xz", "yz": "view_yz"}
_CMAP = "viridis"
_GHOST_COLOR = "#9a9a9a"
_FIXTURE_COLOR = "#3c3c3c"
_MASS_COLOR = "#b2182b"
_LINK_COLOR = "#d08c2c"  # rigid links and node-to-node springs
_EDGE_COLOR = "#2b2b2b"
_FEATURE_ANGLE = 30.0  # degrees: sharper edges belong to the undeformed outline


def old_plot_mode(model, modes, index, filename, scale=None, window_size=(1024, 768),
                  camera=None, n_sub=8, show_undeformed=True, masses=None, title=None,
                  decorate=None):
    """The old ``plot_mode`` (argument checks left out)."""
    u = modes.shapes[:, index]
    scale = mode_scale(model, u, n_sub) if scale is None else float(scale)
    if masses is None:
        mass_nodes = model.mass_nodes
    else:
        mass_nodes = np.array([node_index(model.mesh, m.node, "point mass") for m in masses],
                              dtype=np.int64)
    width, height = (int(v) for v in window_size)
    select_headless_backend()
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
    _old_write_png(_downsample(image, k), filename)
    return Path(filename)


def _font_size(window_size) -> int:
    return int(np.clip(round(min(window_size) / 48), 8, 64))


def _downsample(image: np.ndarray, k: int) -> np.ndarray:
    h, w, c = image.shape[0] // k, image.shape[1] // k, image.shape[2]
    blocks = image[:h * k, :w * k].reshape(h, k, w, k, c).astype(float)
    return np.rint(blocks.mean(axis=(1, 3))).astype(np.uint8)


def _add_scene(plotter, model, u, scale, n_sub, show_undeformed, mass_nodes,
               font_size) -> None:
    import pyvista as pv

    bar = {"title": "displacement\n(relative)", "vertical": True, "n_labels": 3, "fmt": "%.1f",
           "position_x": 0.87, "position_y": 0.25, "width": 0.05, "height": 0.5,
           "color": "black", "title_font_size": font_size, "label_font_size": font_size,
           "unconstrained_font_size": True}
    style = {"scalars": "magnitude", "cmap": _CMAP, "clim": (0.0, 1.0)}
    node_r = node_radius(model)
    marker = float(node_r.max()) if node_r.max() > 0 else RADIUS_RANGE[0] * model_size(model)
    has_surface = surface_nodes(model).size > 0
    largest = scale * largest_displacement(model, u, n_sub) if has_surface else None
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
    node_r = node_radius(model)
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
    import pyvista as pv

    fixed = fixed_nodes(model)
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


def _set_camera(plotter, camera) -> None:
    camera = "iso" if camera is None else camera
    if isinstance(camera, str):
        getattr(plotter, _VIEWS[camera])()
        plotter.reset_camera()
    else:
        plotter.camera_position = camera


def _old_write_png(image: np.ndarray, filename) -> None:
    from PIL import Image

    with atomic_path(filename) as tmp:
        Image.fromarray(image).save(tmp, format="PNG")



# -- the measurement ----------------------------------------------------------------------


def _example(name: str):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def cases(only=None) -> dict:
    """``{name: (model, modes, indices)}`` of the two examples, modes solved here."""
    out = {}
    if only in (None, "frame"):
        model = _example("frame_modes").build()
        out["frame (12 modes)"] = (model, fm.modes(model, n_modes=12), list(range(12)))
    if only in (None, "shell"):
        model = _example("shell_frame_modes").build()
        out["shell (8 of 12 modes)"] = (model, fm.modes(model, n_modes=12), list(range(8)))
    return out


def _cpu() -> float:
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


_WRITES: list[float] = []
"""perf_counter() at every PNG written in this process (both paths append to it)."""


def _stamped(write):
    def wrapped(*args, **kwargs):
        write(*args, **kwargs)
        _WRITES.append(time.perf_counter())

    return wrapped


def _time(draw, repeats: int) -> tuple[float, float, float, float]:
    """Minimum wall time of ``draw(folder)`` over ``repeats`` runs, that run's CPU time, the
    time to its first image and the time per image after the first (NaN when the images
    are written by worker processes)."""
    best = (np.inf,) * 4
    for _ in range(repeats):
        _WRITES.clear()
        with tempfile.TemporaryDirectory() as folder:
            t0, c0 = time.perf_counter(), _cpu()
            draw(Path(folder))
            wall, cpu = time.perf_counter() - t0, _cpu() - c0
        first, after = np.nan, np.nan
        if len(_WRITES) > 1:
            first, after = _WRITES[0] - t0, (_WRITES[-1] - _WRITES[0]) / (len(_WRITES) - 1)
        best = min(best, (wall, cpu, first, after))
    return best


def paths(model, modes, indices) -> dict:
    """The three ways of drawing ``indices``: callables of an output folder."""
    return {
        "old: plotter per image": lambda out: [
            old_plot_mode(model, modes, i, out / f"mode_{i + 1:02d}.png") for i in indices],
        "new: one scene": lambda out: plot_modes(model, modes, out, indices, workers=1),
        "new: one scene, 2 workers": lambda out: plot_modes(model, modes, out, indices,
                                                            workers=2),
    }


def main(repeats: int = 3, only=None, out_file=HERE / "results" / "mode_images.txt") -> str:
    """Time every path on every case; print and write the table."""
    select_headless_backend()
    import pyvista  # noqa: F401  (its import, ~1 s, is no part of any path's time)

    global _old_write_png
    _old_write_png = _stamped(_old_write_png)
    femmech.output.plot._write_png = _stamped(femmech.output.plot._write_png)

    load = os.getloadavg()
    rows = []
    for name, (model, modes, indices) in cases(only).items():
        for path, draw in paths(model, modes, indices).items():
            wall, cpu, first, after = _time(draw, repeats)
            n = len(indices)
            rows.append((name, path, n, wall, wall / n, cpu / n,
                         "-" if np.isnan(first) else f"{first:.2f}",
                         "-" if np.isnan(after) else f"{after:.3f}"))
    lines = [f"mode images, 1024 x 768; min of {repeats} runs; load average"
             f" {load[0]:.1f} at the start, {os.getloadavg()[0]:.1f} at the end"
             f" ({os.cpu_count()} cores)", "",
             f"{'model':<22} {'path':<26} {'images':>6} {'total s':>8} {'s/image':>8}"
             f" {'CPU s/image':>11} {'first s':>8} {'s/image after first':>20}"]
    lines += [f"{n:<22} {p:<26} {k:>6d} {w:>8.2f} {s:>8.3f} {c:>11.3f} {u:>8} {a:>20}"
              for n, p, k, w, s, c, u, a in rows]
    text = "\n".join(lines)
    print(text)
    out_file = Path(out_file)
    out_file.parent.mkdir(parents=True, exist_ok=True)
    out_file.write_text(text + "\n", encoding="utf-8")
    return text


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="runs per path (min is kept)")
    parser.add_argument("--only", choices=["frame", "shell"], help="one of the two models")
    args = parser.parse_args()
    main(args.repeats, args.only)
