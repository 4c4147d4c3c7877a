"""Mode animations: one mode shape swinging through a period, as an animated GIF.

Each frame is the mode drawn at ``cos(2π (k + ½) / n_frames)`` of its amplitude (the
half step keeps every frame off the zero crossing), with one scale, one camera and one
scene for all frames (:mod:`femmech.output.plot`), so the motion is the mode's and not
an artefact of re-scaling; the header states the mode, frequency and magnification as on
the still images. Frames are written by Pillow (a matplotlib dependency); the GIF is
written atomically.

Uses analysis.modes and output.plot (pyvista inside).
"""

from __future__ import annotations

import dataclasses
import tempfile
from pathlib import Path

import numpy as np

from femmech.analysis.modes import ModeSet
from femmech.fe.model import FEModel
from femmech.output.export import atomic_path, check_sizes, mode_indices
from femmech.output.plot import mode_scale, mode_title, plot

MAX_FRAMES = 240
"""Most frames of one animation (10 s at 24 frames per second)."""


def animate_mode(model: FEModel, modes: ModeSet, index: int, filename, n_frames: int = 24,
                 fps: float = 12.0, scale: float | None = None, **kwargs) -> Path:
    """Write an animated GIF of mode ``index`` (0-based) swinging through one period.

    Parameters
    ----------
    model : FEModel
    modes : ModeSet
        Of ``model``.
    index : int
        0-based mode index.
    filename : str or os.PathLike
        Target ``.gif``; its folder must exist.
    n_frames : int
        Frames per period (4 … :data:`MAX_FRAMES`); a multiple of 4 keeps the turning
        points symmetric.
    fps : float
        Frames per second of the GIF (the animation is slowed down: one period takes
        ``n_frames / fps`` seconds whatever the frequency).
    scale : float, optional
        Magnification; default as the still images (:func:`~femmech.output.plot.mode_scale`).
    **kwargs
        As :func:`femmech.output.plot.plot_mode` (``window_size``, ``camera``, ``masses``,
        ``n_sub``, ``show_undeformed``, ``title``); ``window_size`` defaults to 800 × 600.

    Returns
    -------
    Path
    """
    target = Path(filename)
    if target.suffix.lower() != ".gif":
        raise ValueError(f"animation file {target.name}: the suffix must be .gif")
    if not target.parent.is_dir():
        raise FileNotFoundError(f"cannot write {target}: folder {target.parent} does not exist")
    check_sizes(model, modes)
    index = int(mode_indices(modes, [index])[0])
    if int(n_frames) != n_frames or not 4 <= n_frames <= MAX_FRAMES:
        raise ValueError(f"n_frames must be an integer from 4 to {MAX_FRAMES}, got {n_frames}")
    if not 0.5 <= fps <= 50.0:
        raise ValueError(f"fps must lie between 0.5 and 50, got {fps}")
    shape = modes.shapes[:, index]
    scale = mode_scale(model, shape, kwargs.get("n_sub", 8)) if scale is None else float(scale)
    phases = np.cos(2.0 * np.pi * (np.arange(n_frames) + 0.5) / n_frames)
    frames = _frames(modes, index, phases)
    kwargs.setdefault("title", mode_title(modes, index))
    kwargs.setdefault("window_size", (800, 600))  # a GIF of 24 frames: about 0.8 MB
    with tempfile.TemporaryDirectory(prefix="femmech-gif-") as tmp:
        files = [Path(tmp) / f"frame_{k:03d}.png" for k in range(n_frames)]
        plot(model, frames, list(range(n_frames)), files, workers=None, scale=scale,
              mode_type=False, scale_note=True, **kwargs)
        _write_gif(files, target, 1000.0 / fps)
    return target


def _frames(modes: ModeSet, index: int, phases: np.ndarray) -> ModeSet:
    """A mode set whose k-th 'mode' is mode ``index`` times ``phases[k]``."""
    n = len(phases)
    pick = lambda a: None if a is None else np.repeat(np.asarray(a)[[index]], n)  # noqa: E731
    return dataclasses.replace(
        modes, freq_hz=pick(modes.freq_hz), omega2=pick(modes.omega2),
        shapes=modes.shapes[:, [index]] * phases[None, :], rigid=pick(modes.rigid),
        residual=pick(modes.residual), error_estimate=pick(modes.error_estimate))


def _write_gif(files: list[Path], target: Path, duration_ms: float) -> None:
    from PIL import Image

    images = [Image.open(f).convert("RGB") for f in files]
    palette = images[0].quantize(colors=255, method=Image.Quantize.MEDIANCUT)
    frames = [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in images]
    with atomic_path(target) as tmp:
        frames[0].save(tmp, format="GIF", save_all=True, append_images=frames[1:],
                       duration=int(round(duration_ms)), loop=0, optimize=False)
