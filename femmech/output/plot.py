"""Off-screen PNG images of mode shapes that explain themselves, fast.

Each image shows the deformed model in 3D (:mod:`femmech.output.renderer`): beams as
tubes along the element curves recovered with the elements' shape functions, shells
and the outer surfaces of solids as flat-shaded faces with thin edges, coloured by
``|u| / max |u|`` on one scale, over a grey ghost of the undeformed model, with glyphs
for supports, point masses, rigid links and springs. Around it (:mod:`.annotate`): the
title (mode number, frequency and, for beam models, the mode type of
:mod:`femmech.analysis.mode_types`), the deformation scale ``"deformation ×N"``, the
colour bar with its quantity, a legend of exactly the glyphs drawn and an x-y-z triad.

All images of one call share one camera, fitted to the undeformed model and every
drawn deformed shape (:func:`femmech.output.camera.fit_camera`), and one off-screen
scene whose points and scalars are replaced per mode (benchmarks/mode_images.py times
it);
:func:`plot_modes` can spread images over worker processes (``workers``).

The drawing does not depend on shell thickness, and the plotter has its own document
theme, so the global pyvista theme does not change the image. pyvista is imported
only inside the functions.

Uses analysis.modes and .mode_types, fe and output.export,
.mode_geometry, .camera, .annotate and .renderer.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from femmech.analysis.mode_types import mode_types
from femmech.analysis.modes import ModeSet
from femmech.fe.model import FEModel, node_index
from femmech.output.annotate import (
    Layout,
    compose,
    make_layout,
    panel_image,
    scale_text,
)
from femmech.output.camera import Camera, camera_from_position, check_view, fit_camera, screen_axes
from femmech.output.export import atomic_path, check_sizes, mode_indices
from femmech.output.mode_geometry import (  # noqa: F401 (re-exported: the drawing's numbers)
    MASS_RADIUS_FRACTION,
    RADIUS_RANGE,
    SCALE_FRACTION,
    Glyphs,
    drawn_points,
    fixed_nodes,
    largest_displacement,
    mode_mesh,
    mode_scale,
    model_glyphs,
    model_size,
    surface_mesh,
)
from femmech.output.renderer import (  # noqa: F401 (re-exported)
    CMAP,
    SUPERSAMPLE,
    Decoration,
    ModeRenderer,
    scene_legend,
    select_headless_backend,
)
from femmech.output.surfaces import shell_cells, solid_cells, surface_nodes

PNG_COMPRESSION = 3
"""zlib level of the PNG files (6 is PIL's default: 10 % smaller files, 2.5 times slower)."""


@dataclass(frozen=True)
class _Batch:
    """Everything needed to draw some modes of one model (picklable, for worker processes)."""

    model: FEModel
    shapes: np.ndarray  # (n_dof, n_images)
    scales: tuple
    titles: tuple
    lines: tuple  # further header lines per image
    files: tuple
    camera: Camera
    layout: Layout
    glyphs: Glyphs
    legend: tuple
    n_sub: int
    show_undeformed: bool

    def part(self, keep) -> _Batch:
        """The same batch for the images ``keep`` (indices into this batch)."""
        keep = list(keep)
        pick = lambda seq: tuple(seq[i] for i in keep)  # noqa: E731
        return _Batch(self.model, self.shapes[:, keep], pick(self.scales), pick(self.titles),
                      pick(self.lines), pick(self.files), self.camera, self.layout, self.glyphs,
                      self.legend, self.n_sub, self.show_undeformed)


def mode_title(modes: ModeSet, index: int) -> str:
    """Image title such as ``"Mode 3: 17.71 Hz"`` (modes numbered from 1)."""
    if modes.rigid[index]:
        return f"Mode {index + 1}: rigid-body (0 Hz)"
    return f"Mode {index + 1}: {modes.freq_hz[index]:.4g} Hz"


def plot_mode(model: FEModel, modes: ModeSet, index: int, filename, scale: float | None = None,
              window_size=(1024, 768), camera=None, n_sub: int = 8,
              show_undeformed: bool = True, masses=None, title: str | None = None,
              decorate=None, mode_type: bool | None = None) -> Path:
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
        is drawn as :data:`SCALE_FRACTION` of the model size). Stated on the image.
    window_size : (int, int)
        Image width and height, pixels.
    camera : str or camera position, optional
        ``"iso"`` (default), ``"xy"``, ``"xz"``, ``"yz"`` (fitted to the drawn shapes),
        or a pyvista camera position ``[(position), (focal point), (view up)]``.
    n_sub : int
        Sub-intervals per element of the drawn curves.
    show_undeformed : bool
        Draw a grey ghost of the undeformed model.
    masses : sequence of PointMass, optional
        Point masses to draw as balls at their displaced nodes; default: all point
        masses of the model (``model.mass_nodes``).
    title : str, optional
        Replaces the default title (:func:`mode_title`).
    decorate : callable or Decoration, optional
        Further 3D glyphs: ``decorate(plotter, scale)`` adds actors, or a
        :class:`~femmech.output.renderer.Decoration` that also gives their points (for
        the camera) and legend entries.
    mode_type : bool, optional
        Add the mode type (:func:`femmech.analysis.mode_types.classify_mode`) under the
        title. Default: on for beam models, off for models with shells or solids (whose
        strain energy is not classified).

    Returns
    -------
    Path
        ``filename``.
    """
    return plot(model, modes, [index], [Path(filename)], workers=1, scale=scale,
                 window_size=window_size, camera=camera, n_sub=n_sub,
                 show_undeformed=show_undeformed, masses=masses, title=title,
                 decorate=decorate, mode_type=mode_type)[0]


def plot_modes(model: FEModel, modes: ModeSet, out_dir, indices=None, prefix: str = "mode",
               workers: int | None = None, progress=None, **kwargs) -> list[Path]:
    """Render several modes to ``out_dir/{prefix}_{n:02d}.png`` (n from 1), one per mode.

    All images share one camera (fitted to every drawn shape) and one off-screen scene.

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
    workers : int, optional
        Worker processes, each with its own scene (default 1; ignored with a
        ``decorate`` callable). Spawned workers import the main script, which then needs
        an ``if __name__ == "__main__":`` guard. On 2 cores a pool does not pay
        (benchmarks/mode_images.py): Mesa's software OpenGL already renders on every
        core, and each worker pays the start-up of Python, VTK and a render window.
    progress : callable, optional
        Wraps the iterable of image numbers drawn, e.g. a ``tqdm`` progress bar (serial
        drawing only).
    **kwargs
        As :func:`plot_mode` (``window_size``, ``camera``, ``masses``, ``mode_type``, ...).

    Returns
    -------
    list of Path
        The written files, in the order of ``indices``.
    """
    out = Path(out_dir)
    if not out.is_dir():
        raise FileNotFoundError(f"output folder {out} does not exist")
    idx = [int(i) for i in mode_indices(modes, indices)]
    files = [out / f"{prefix}_{i + 1:02d}.png" for i in idx]
    return plot(model, modes, idx, files, workers=workers, progress=progress, **kwargs)


def plot(model, modes, indices, files, workers, scale=None, window_size=(1024, 768),
          camera=None, n_sub=8, show_undeformed=True, masses=None, title=None, decorate=None,
          mode_type=None, progress=None, scale_note: bool | None = None,
          reach: float | None = None) -> list[Path]:
    """Plan the images of ``indices`` (0-based) and draw them, serially or on workers.

    ``scale_note``: state on the images that the scale puts the largest displacement at
    :data:`SCALE_FRACTION` of the model size (default: when ``scale`` is None).
    ``reach`` (m): fit the camera to the undeformed drawing with every point moved by up
    to this much in any direction, instead of to the drawn modes, so that every image of
    the model gets the same camera whatever mode it shows (images drawn one per call)."""
    check_sizes(model, modes)
    check_view(camera)
    indices = [int(i) for i in mode_indices(modes, indices)]
    if decorate is not None and not isinstance(decorate, Decoration):
        decorate = Decoration(decorate)
    mass_nodes = None if masses is None else [node_index(model.mesh, m.node, "point mass")
                                              for m in masses]
    glyphs = model_glyphs(model, mass_nodes)
    shapes = modes.shapes[:, indices]
    scales = tuple(mode_scale(model, shapes[:, k], n_sub) if scale is None else float(scale)
                   for k in range(len(indices)))
    types = _type_labels(model, modes, indices, mode_type)
    note = SCALE_FRACTION if (scale is None if scale_note is None else scale_note) else None
    lines = tuple(((t,) if t else ()) + ((scale_text(s, note), scale_text(s)),)
                  for t, s in zip(types, scales, strict=True))
    titles = tuple(mode_title(modes, i) if title is None else title for i in indices)
    legend = scene_legend(glyphs, len(model.beams.cells) > 0, surface_nodes(model).size > 0,
                          show_undeformed) + (decorate.legend if decorate else ())
    layout = make_layout(window_size, max(len(x) for x in lines), legend)
    view_w, view_h = layout.view_size
    if camera is None or isinstance(camera, str):
        points = _envelope(model, shapes, scales, glyphs, n_sub, decorate, reach)
        cam = fit_camera(points, camera or "iso", view_w / view_h)
    else:
        cam = camera_from_position(camera)
    batch = _Batch(model, shapes, scales, titles, lines, tuple(Path(f) for f in files), cam,
                   layout, glyphs, legend, int(n_sub), bool(show_undeformed))
    n = _worker_count(workers, len(indices)) if decorate is None else 1
    if n <= 1:
        return _draw(batch, decorate, progress)
    return _draw_on_workers(batch, n)


def _envelope(model, shapes, scales, glyphs, n_sub, decorate, reach) -> np.ndarray:
    """Points (n, 3), m, the camera must show: every drawn mode, or with ``reach`` the
    undeformed drawing with every point moved by ``reach`` in 26 directions (a
    displacement of at most ``reach`` keeps a point inside that sphere, up to the margin
    of the fit)."""
    if reach is None:
        points = [drawn_points(model, shapes[:, k], s, glyphs, n_sub)
                  for k, s in enumerate(scales)]
        points += [decorate.points(s) for s in scales] if decorate else []
        return np.concatenate(points)
    rest = [drawn_points(model, np.zeros(model.n_dof), 0.0, glyphs, 1)]
    rest += [decorate.points(0.0)] if decorate else []
    # |u| <= reach: the 26 directions to the neighbours of a cube cell, on that sphere
    grid = np.array(np.meshgrid([-1, 0, 1], [-1, 0, 1], [-1, 0, 1])).reshape(3, -1).T
    grid = grid[np.any(grid != 0, axis=1)]
    sphere = reach * grid / np.linalg.norm(grid, axis=1)[:, None]
    return (np.concatenate(rest)[:, None, :] + sphere[None]).reshape(-1, 3)


def _type_labels(model, modes, indices, mode_type) -> tuple:
    """Mode-type label per image ('' when off); default on for beam models only."""
    beam_model = not shell_cells(model) and not solid_cells(model) and len(model.beams.cells)
    if mode_type is None:
        mode_type = bool(beam_model)
    if not mode_type:
        return ("",) * len(indices)
    found = mode_types(model, modes.shapes[:, indices], modes.rigid[indices])
    return tuple(t.label for t in found)


def _worker_count(workers, n_images: int) -> int:
    """Processes to use: ``workers`` (default 1), at most one per image."""
    if workers is None:
        return 1
    if int(workers) != workers or int(workers) < 1:
        raise ValueError(f"workers must be a positive integer, got {workers!r}")
    return min(int(workers), n_images)


def _draw(batch: _Batch, decorate: Decoration | None = None, progress=None) -> list[Path]:
    """Draw a batch with one scene: per image, render, annotate, write."""
    with ModeRenderer(batch.model, batch.layout.view_size, batch.camera, batch.glyphs,
                      batch.n_sub, batch.show_undeformed) as renderer:
        background = panel_image(batch.layout, batch.legend, screen_axes(batch.camera), CMAP,
                                 renderer.k)
        for k in (progress or iter)(range(len(batch.files))):
            view = renderer.render(batch.shapes[:, k], batch.scales[k], decorate)
            _write_png(compose(view, background, batch.layout, batch.titles[k], batch.lines[k],
                               renderer.k), batch.files[k])
    return list(batch.files)


def _draw_on_workers(batch: _Batch, n: int) -> list[Path]:
    """Split a batch into ``n`` contiguous parts drawn by ``n`` spawned processes."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    parts = [p for p in np.array_split(np.arange(len(batch.files)), n) if p.size]
    context = multiprocessing.get_context("spawn")  # no fork of a process with a GL context
    threads = max(1, (os.cpu_count() or 1) // len(parts))
    with ProcessPoolExecutor(len(parts), mp_context=context, initializer=_share_cores,
                             initargs=(threads,)) as pool:
        done = list(pool.map(_draw, [batch.part(p) for p in parts]))
    return [f for part in done for f in part]


def _share_cores(threads: int) -> None:
    """In a worker: Mesa's software rasteriser on ``threads`` threads (it takes every core
    by default, and n workers would each take them all), unless the user chose."""
    os.environ.setdefault("LP_NUM_THREADS", str(threads))


def _write_png(image: np.ndarray, filename) -> None:
    """Write an (H, W, 3) uint8 array to a PNG file atomically."""
    from PIL import Image

    with atomic_path(filename) as tmp:
        Image.fromarray(image).save(tmp, format="PNG", compress_level=PNG_COMPRESSION)
