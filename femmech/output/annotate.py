"""The 2D parts of a mode image: title lines, colour bar, legend and axis triad (PIL).

A mode image is a 3D view (rendered by :mod:`femmech.output.renderer`) pasted into a
white canvas with a header band (title, mode type, deformation scale) above it and a
panel to its right (colour bar, legend of the glyphs drawn, x-y-z triad of the view).
Text is set with DejaVu Sans (shipped with matplotlib: φ, °, ×, superscripts), sized
from the image height so that it reads at 100 % zoom: 17 px body text and 27 px titles
on a 1024 x 768 image.

The texts are composed by pure functions (:func:`format_factor`, :func:`scale_text`,
:data:`COLOUR_BAR_TITLE`) so that tests can check them without rendering.

Uses nothing of femmech (PIL, matplotlib's font files and colour map).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

COLOUR_BAR_TITLE = ("displacement", "|u| / max |u|", "(dimensionless)")
"""Title of the colour bar: colours show each point's displacement magnitude relative to
the largest of the mode (mode shapes have no absolute size)."""
COLOUR_BAR_TICKS = (1.0, 0.5, 0.0)
AXIS_COLORS = {"x": "#d62728", "y": "#2ca02c", "z": "#1f77b4"}
"""Triad colours (red, green, blue for x, y, z as in ParaView and most CAD programs)."""
TEXT_COLOR = "#1a1a1a"
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


@dataclass(frozen=True)
class LegendEntry:
    """One line of the legend.

    Attributes
    ----------
    label : str
    color : str
        Hex colour of the glyph.
    glyph : str
        How the swatch is drawn: ``"square"``, ``"circle"``, ``"line"`` (thick),
        ``"ghost"`` (thin, light), ``"coil"`` (a spring) or ``"block"`` (a square on a
        line: a mechanism attached to the frame).
    """

    label: str
    color: str
    glyph: str


@dataclass(frozen=True)
class Layout:
    """Sizes of a mode image, pixels: the whole image, the header band and the panel."""

    width: int
    height: int
    header: int
    panel: int
    title_size: int
    text_size: int

    @property
    def view_size(self) -> tuple[int, int]:
        """Width and height of the 3D view (left of the panel, below the header)."""
        return self.width - self.panel, self.height - self.header


def format_factor(value: float) -> str:
    """A positive number to 3 significant digits, without exponent from 0.01 to 99 900.

    >>> [format_factor(v) for v in (1234.5, 12.34, 0.04567, 2.0, 3.2e6, 4.5e-4)]
    ['1230', '12.3', '0.0457', '2', '3.2·10⁶', '4.5·10⁻⁴']
    """
    value = float(value)
    if not math.isfinite(value) or value <= 0:
        return f"{value:g}"
    exponent = math.floor(math.log10(value))
    mantissa = round(value / 10**exponent, 2)
    if mantissa >= 10:  # 9.996 rounds up to 10.0
        mantissa, exponent = mantissa / 10, exponent + 1
    if -2 <= exponent <= 4:
        digits = max(2 - exponent, 0)
        return f"{mantissa * 10**exponent:.{digits}f}".rstrip("0").rstrip(".") if digits \
            else f"{round(mantissa * 10**exponent):d}"
    text = f"{mantissa:.2f}".rstrip("0").rstrip(".")
    return f"{text}·10{str(exponent).translate(_SUPERSCRIPT)}"


def scale_text(scale: float, fraction: float | None = None) -> str:
    """``"deformation ×1230"``, with ``" (largest displacement drawn as 12 % of the model
    size)"`` when the scale was chosen automatically (``fraction`` of the model size)."""
    text = f"deformation ×{format_factor(scale)}"
    if fraction is not None:
        text += f" (largest displacement drawn as {100 * fraction:.3g} % of the model size)"
    return text


@lru_cache(maxsize=32)
def font(size: int, bold: bool = False):
    """DejaVu Sans (bold) at ``size`` pixels, from matplotlib's font folder."""
    import matplotlib
    from PIL import ImageFont

    name = "DejaVuSans-Bold.ttf" if bold else "DejaVuSans.ttf"
    return ImageFont.truetype(str(Path(matplotlib.get_data_path()) / "fonts" / "ttf" / name),
                              int(size))


def text_width(text: str, size: int, bold: bool = False) -> int:
    """Width of a text line in pixels."""
    return int(math.ceil(font(size, bold).getlength(text)))


def make_layout(window_size, header_lines: int, legend: tuple[LegendEntry, ...]) -> Layout:
    """Sizes for an image of ``window_size`` (width, height) with a title and
    ``header_lines`` further lines above the view and the legend in the right panel."""
    width, height = (int(v) for v in window_size)
    title = int(np.clip(round(height / 28), 12, 60))
    text = int(np.clip(round(height / 45), 10, 36))
    pad = max(text // 2, 4)
    header = 2 * pad + round(1.25 * title) + round(1.35 * text) * header_lines
    labels = [e.label for e in legend] + list(COLOUR_BAR_TITLE)
    widest = max(text_width(s, text) for s in labels)
    panel = int(np.clip(widest + 2.5 * text + 3 * pad, 0.16 * width, 0.4 * width))
    return Layout(width, height, header, panel, title, text)


def panel_image(layout: Layout, legend: tuple[LegendEntry, ...], axes: np.ndarray,
                colormap: str, k: int = 1) -> np.ndarray:
    """A white image of the layout's size with its panel drawn: colour bar, legend, triad.

    The panel is the same for every mode of a model, so it is drawn once per model.

    Parameters
    ----------
    layout : Layout
    legend : tuple of LegendEntry
    axes : ndarray (3, 3)
        Rows x, y, z: their (right, up, into the screen) components
        (:func:`femmech.output.camera.screen_axes`).
    colormap : str
        Matplotlib colour map of the 3D colours (for the colour bar).
    k : int
        Supersampling: drawn at ``k`` times the size, averaged down (smooth lines).

    Returns
    -------
    ndarray (height, width, 3) uint8
    """
    from PIL import Image, ImageDraw

    W, H = k * layout.width, k * layout.height
    canvas = Image.new("RGB", (W, H), "white")
    draw = ImageDraw.Draw(canvas)
    s = k * layout.text_size
    x0 = W - k * layout.panel + s // 2
    y = _colour_bar(draw, canvas, x0, k * layout.header + s // 2, s, H, colormap)
    y = _legend(draw, x0, y + s, s, legend)
    radius = min(0.3 * k * layout.panel, 0.09 * H)
    centre = (W - k * layout.panel / 2, H - radius - 1.2 * s)
    if centre[1] - radius > y:
        _triad(draw, centre, radius, s, axes)
    return np.asarray(canvas.reduce(k) if k > 1 else canvas)


def compose(view: np.ndarray, background: np.ndarray, layout: Layout, title: str,
            lines: tuple[str, ...], k: int = 1) -> np.ndarray:
    """One image: the 3D ``view`` below the header, on the ``background`` with its panel.

    Parameters
    ----------
    view : ndarray (k · view height, k · view width, 3) uint8
        3D rendering at ``k`` times :attr:`Layout.view_size` (averaged down here).
    background : ndarray (height, width, 3) uint8
        :func:`panel_image` of the same layout.
    layout : Layout
    title : str
        First header line (bold).
    lines : tuple of str or of tuples of str
        Further header lines; a tuple gives alternatives, longest first: the first that
        fits the width is drawn (a line too long is set smaller).
    k : int
        Supersampling factor of ``view``.

    Returns
    -------
    ndarray (height, width, 3) uint8
    """
    from PIL import Image, ImageDraw

    canvas = Image.fromarray(background)
    rendered = Image.fromarray(view)
    canvas.paste(rendered.reduce(k) if k > 1 else rendered, (0, layout.header))
    _header(ImageDraw.Draw(canvas), layout, title, lines)
    return np.asarray(canvas)


def _header(draw, layout: Layout, title: str, lines) -> None:
    """Title (bold, shrunk to fit the width) and further lines, centred."""
    W = layout.width
    size = layout.title_size
    while size > 10 and font(size, True).getlength(title) > 0.97 * W:
        size -= 1
    y = layout.text_size // 2
    draw.text((W / 2, y), title, font=font(size, True), fill=TEXT_COLOR, anchor="mt")
    y += round(1.25 * layout.title_size)
    for line in lines:
        line = _fitting(line, layout.text_size, 0.97 * W)
        size = layout.text_size
        while size > 8 and font(size).getlength(line) > 0.97 * W:
            size -= 1
        draw.text((W / 2, y), line, font=font(size), fill=TEXT_COLOR, anchor="mt")
        y += round(1.35 * layout.text_size)


def _fitting(line, size: int, width: float) -> str:
    """``line`` itself, or of a tuple of alternatives (longest first) the first that fits
    ``width`` pixels at ``size`` (else the last)."""
    if isinstance(line, str):
        return line
    return next((text for text in line if font(size).getlength(text) <= width), line[-1])


def _colour_bar(draw, canvas, x0: float, y: float, s: int, H: int, colormap: str) -> float:
    """Title lines, a vertical gradient and its tick labels; returns the y below it."""
    import matplotlib
    from PIL import Image

    for line in COLOUR_BAR_TITLE:
        draw.text((x0, y), line, font=font(s), fill=TEXT_COLOR)
        y += round(1.25 * s)
    y += s // 2
    height, width = int(0.25 * H), int(1.2 * s)
    values = np.linspace(1.0, 0.0, height)
    rgb = (matplotlib.colormaps[colormap](values)[:, :3] * 255).round().astype(np.uint8)
    canvas.paste(Image.fromarray(np.repeat(rgb[:, None, :], width, axis=1)), (int(x0), int(y)))
    draw.rectangle([x0, y, x0 + width - 1, y + height - 1], outline=TEXT_COLOR,
                   width=max(s // 12, 1))
    for tick in COLOUR_BAR_TICKS:
        ty = y + (1.0 - tick) * (height - 1)
        draw.line([x0 + width, ty, x0 + width + s // 3, ty], fill=TEXT_COLOR,
                  width=max(s // 12, 1))
        draw.text((x0 + width + s // 2, ty), f"{tick:.1f}", font=font(s), fill=TEXT_COLOR,
                  anchor="lm")
    return y + height


def _legend(draw, x0: float, y: float, s: int, legend) -> float:
    """One line per entry: a swatch (1.8 s wide) and its label; returns the y below it."""
    for entry in legend:
        box = (x0, y + 0.15 * s, x0 + 1.8 * s, y + 1.05 * s)
        _swatch(draw, box, entry)
        draw.text((x0 + 2.3 * s, y + 0.6 * s), entry.label, font=font(s), fill=TEXT_COLOR,
                  anchor="lm")
        y += round(1.5 * s)
    return y


def _swatch(draw, box, entry: LegendEntry) -> None:
    """The glyph of one legend entry inside ``box`` (x0, y0, x1, y1)."""
    x0, y0, x1, y1 = box
    cx, cy, h = (x0 + x1) / 2, (y0 + y1) / 2, y1 - y0
    thick = max(int(0.28 * h), 1)
    if entry.glyph == "square":
        draw.rectangle([cx - 0.4 * h, cy - 0.4 * h, cx + 0.4 * h, cy + 0.4 * h], fill=entry.color)
    elif entry.glyph == "circle":
        draw.ellipse([cx - 0.45 * h, cy - 0.45 * h, cx + 0.45 * h, cy + 0.45 * h],
                     fill=entry.color)
    elif entry.glyph in ("line", "ghost"):
        width = thick if entry.glyph == "line" else max(thick // 2, 1)
        draw.line([x0, cy, x1, cy], fill=entry.color, width=width)
    elif entry.glyph == "coil":  # a prolate cycloid: a coil spring seen from the side
        t = np.linspace(0.0, 8 * np.pi, 160)
        xs = x0 + 0.25 * h + (x1 - x0 - 0.5 * h) * t / t[-1] - 0.25 * h * np.sin(t)
        ys = cy - 0.4 * h * np.cos(t)
        draw.line(list(zip(xs, ys, strict=True)), fill=entry.color, width=max(thick // 2, 1),
                  joint="curve")
    elif entry.glyph == "block":
        draw.line([x0, cy, cx, cy], fill=entry.color, width=max(thick // 2, 1))
        draw.rectangle([cx, cy - 0.35 * h, cx + 0.7 * h, cy + 0.35 * h], fill=entry.color)
    else:
        raise ValueError(f"unknown legend glyph {entry.glyph!r}")


def _triad(draw, centre, radius: float, s: int, axes: np.ndarray) -> None:
    """Arrows of x, y, z from ``centre`` along their screen directions (``axes`` (3, 3):
    right, up, into the screen), labelled; axes pointing away are drawn first."""
    cx, cy = centre
    order = np.argsort(-axes[:, 2])  # pointing away from the viewer first
    width = max(s // 6, 2)
    for i in order:
        name = "xyz"[i]
        dx, dy = radius * axes[i, :2]
        end = (cx + dx, cy - dy)
        color = AXIS_COLORS[name]
        draw.line([cx, cy, *end], fill=color, width=width)
        length = math.hypot(dx, dy)
        if length > 0.15 * radius:
            ux, uy = dx / length, -dy / length
            head = 0.45 * s
            left = (end[0] - head * ux - 0.5 * head * uy, end[1] - head * uy + 0.5 * head * ux)
            right = (end[0] - head * ux + 0.5 * head * uy, end[1] - head * uy - 0.5 * head * ux)
            draw.polygon([end, left, right], fill=color)
            label = (cx + dx + 0.7 * s * ux, cy - dy + 0.7 * s * uy)
        else:  # along the viewing direction: label next to the centre
            label = (cx + 0.6 * s, cy - 0.6 * s)
        draw.text(label, name, font=font(s, True), fill=color, anchor="mm")
    draw.ellipse([cx - width, cy - width, cx + width, cy + width], fill=TEXT_COLOR)
