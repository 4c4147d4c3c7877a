"""Shared pieces of the charts: speed units, axis scales, angle ticks and label placement.

The label placement is a greedy search on boxes in display coordinates (pixels): each
label offers candidate boxes in order of preference and takes the first one that is free
of the boxes already placed and of obstacles (a legend, a colour bar). It is a pure
function (:func:`place_labels`), so it is tested without drawing; the chart modules turn
text extents into candidate boxes and the chosen boxes back into text positions.

Imports nothing of femmech; matplotlib objects come in duck-typed.
"""

from __future__ import annotations

import math

import numpy as np

SPEED_UNITS = {"rad/s": 1.0, "rpm": 60.0 / (2 * math.pi), "Hz": 1.0 / (2 * math.pi)}
"""Factor from rad/s to each unit a drive speed may be shown in (Hz: revolutions per s)."""

SPEED_SYMBOLS = {"rad/s": "Ω", "rpm": "n", "Hz": "n"}
"""Symbol of the drive speed in each unit: Ω (rad/s) or the rotational speed n."""

MAX_LABEL_SHIFT = 120.0
"""Farthest (pixels) a mark's label is moved sideways in the one-row layout above a
chart; beyond it the labels are stacked in rows instead."""


def speed_scale(unit: str) -> float:
    """Factor from rad/s to ``unit`` ("rad/s", "rpm" or "Hz"); ValueError for others."""
    if unit not in SPEED_UNITS:
        raise ValueError(f"speed_unit must be one of {sorted(SPEED_UNITS)}, got {unit!r}")
    return SPEED_UNITS[unit]


def format_speed(speed: float, unit: str) -> str:
    """A drive speed given in rad/s as text in ``unit``: whole rpm, 0.1 rad/s or 0.01 Hz."""
    value = speed * speed_scale(unit)
    digits = {"rpm": 0, "rad/s": 1, "Hz": 2}[unit]
    return f"{value:.{digits}f} {unit}"


def speed_resolution(unit: str) -> str:
    """How finely :func:`format_speed` labels a speed, for error messages."""
    speed_scale(unit)
    return {"rpm": "whole rpm", "rad/s": "rad/s to one decimal", "Hz": "Hz to 0.01"}[unit]


def needs_log_scale(values) -> bool:
    """True if the finite values are all positive and span more than a decade."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size < 2 or v.min() <= 0:
        return False
    return bool(v.max() > 10.0 * v.min())


def angle_tick_step(span_deg: float) -> float | None:
    """Tick step (°) for a drive-angle axis spanning ``span_deg``: 45° up to one
    revolution, 90° up to two; None (automatic ticks) below 90° or above 720°."""
    if 90.0 <= span_deg <= 360.0 + 1e-9:
        return 45.0
    if 360.0 < span_deg <= 720.0 + 1e-9:
        return 90.0
    return None


def set_angle_axis(ax, deg_min: float, deg_max: float, axis: str = "x") -> None:
    """Limit a drive-angle axis (°) to [deg_min, deg_max] with ticks every 45° or 90°."""
    set_lim = ax.set_xlim if axis == "x" else ax.set_ylim
    set_ticks = ax.set_xticks if axis == "x" else ax.set_yticks
    if deg_max > deg_min:
        set_lim(deg_min, deg_max)
    step = angle_tick_step(deg_max - deg_min)
    if step is not None:
        first = math.ceil(deg_min / step - 1e-9) * step
        set_ticks(np.arange(first, deg_max + 1e-9, step))


def boxes_overlap(a, b, pad: float = 0.0) -> bool:
    """Whether boxes (x0, y0, x1, y1) overlap by more than touching; ``pad`` grows ``a``.

    A box of zero width or height (a leader line) overlaps a box it crosses.
    """
    return bool(a[0] - pad < b[2] and b[0] < a[2] + pad and
                a[1] - pad < b[3] and b[1] < a[3] + pad)


def overlapping_pairs(boxes, pad: float = 0.0) -> list[tuple[int, int]]:
    """Index pairs (i < j) of boxes (n, 4) that overlap (:func:`boxes_overlap`)."""
    boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
    return [(i, j) for i in range(len(boxes)) for j in range(i + 1, len(boxes))
            if boxes_overlap(boxes[i], boxes[j], pad)]


def _inside(box, bounds) -> bool:
    return bool(bounds is None or (box[0] >= bounds[0] and box[1] >= bounds[1] and
                                   box[2] <= bounds[2] and box[3] <= bounds[3]))


def _free(box, taken, pad: float) -> bool:
    return not any(boxes_overlap(box, t, pad) for t in taken)


def place_labels(candidates, obstacles=(), bounds=None, leaders=None,
                 pad: float = 1.0, columns=None) -> np.ndarray:
    """Greedy placement of labels on free spots, in the order the labels are given.

    Parameters
    ----------
    candidates : sequence of n array_like (m_i, 4)
        Boxes (x0, y0, x1, y1) label i may take, most preferred first (display units).
    obstacles : array_like (k, 4)
        Boxes no label may overlap (a legend, a colour bar).
    bounds : (x0, y0, x1, y1), optional
        Every chosen box lies inside.
    leaders : sequence of n array_like (m_i, 4), optional
        Per candidate, the box of the line that joins the label to what it names (zero
        width for a vertical line); it must not cross labels placed before, and later
        labels must not cross it. If no candidate of a label has a free leader, the
        first candidate with a free box is taken anyway: boxes never overlap, leaders may.
    pad : float
        Least gap between two boxes.
    columns : sequence of n boxes, optional
        Where each label's leader will run whatever candidate it takes (e.g. the line's
        x from the axes upwards): a label's box preferably covers no column of a label
        placed after it, so that that label's leader stays free.

    Returns
    -------
    ndarray (n,) of int
        The chosen candidate of each label; -1 where no candidate box was free.
    """
    taken = [np.asarray(b, dtype=float) for b in np.asarray(obstacles, float).reshape(-1, 4)]
    lines: list[np.ndarray] = []
    chosen = np.full(len(candidates), -1, dtype=int)
    for i, boxes in enumerate(candidates):
        boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
        lead = (np.asarray(leaders[i], dtype=float).reshape(-1, 4) if leaders is not None
                else None)
        ok = [j for j, b in enumerate(boxes) if _inside(b, bounds) and _free(b, taken, pad)]
        if lead is not None:
            ok = [j for j in ok if _free(lead[j], taken, 0.0) and
                  _free(boxes[j], lines, 0.0)] or ok
        if columns is not None:
            later = [np.asarray(c, dtype=float) for c in columns[i + 1:]]
            ok = [j for j in ok if _free(boxes[j], later, 0.0)] or ok
        if not ok:
            continue
        chosen[i] = ok[0]
        taken.append(boxes[ok[0]])
        if lead is not None:
            lines.append(lead[ok[0]])
    return chosen



def _isotonic(targets) -> np.ndarray:
    """Least-squares non-decreasing fit to ``targets`` (pool adjacent violators)."""
    blocks: list[list[float]] = []  # [sum, count]
    for v in targets:
        blocks.append([float(v), 1])
        while len(blocks) > 1 and blocks[-2][0] * blocks[-1][1] > blocks[-1][0] * blocks[-2][1]:
            total, count = blocks.pop()
            blocks[-1][0] += total
            blocks[-1][1] += count
    return np.concatenate([np.full(int(c), t / c) for t, c in blocks])


def spread_1d(centres, widths, gap: float, lo: float, hi: float) -> np.ndarray | None:
    """Left edges of labels in one row: centred on ``centres`` where they fit, else
    moved apart as little as possible (least squares), in the same order, ``gap`` apart
    and inside [lo, hi]; None if their total width does not fit.

    Because the order is kept, straight leaders from each centre to its label never
    cross (the charts' resonance labels above the plot).
    """
    c, w = np.asarray(centres, dtype=float), np.asarray(widths, dtype=float)
    order = np.argsort(c, kind="stable")
    c, w = c[order], w[order]
    offset = np.concatenate([[0.0], np.cumsum(w[:-1] + gap)])
    total = offset[-1] + w[-1] if w.size else 0.0
    if total > hi - lo:
        return None
    left = _isotonic(c - w / 2 - offset) + offset
    left = np.minimum(np.maximum(left, lo + offset), hi - total + offset)
    out = np.empty_like(left)
    out[order] = left
    return out

# --- labels of a drawn figure ---------------------------------------------------------

def text_size(fig, text: str, fontsize: float) -> tuple[float, float]:
    """Width and height (pixels) of ``text`` at ``fontsize`` in ``fig``."""
    probe = fig.text(0, 0, text, fontsize=fontsize)
    box = probe.get_window_extent(fig.canvas.get_renderer())
    probe.remove()
    return box.width, box.height


def drawn_extent(artist, renderer) -> tuple:
    """Display box (x0, y0, x1, y1) of a drawn artist; of an annotation, the box of its
    text alone (its leader line is not part of the label)."""
    from matplotlib.text import Annotation, Text

    if isinstance(artist, Annotation):
        return tuple(Text.get_window_extent(artist, renderer).extents)
    return tuple(artist.get_window_extent(renderer).extents)


def _extents(fig, artists) -> list:
    """Display boxes (x0, y0, x1, y1) of drawn artists (texts, legends, axes)."""
    renderer = fig.canvas.get_renderer()
    return [drawn_extent(a, renderer) for a in artists]


def _obstacles(fig, ax) -> list:
    """Boxes a label must not cover: the axes' legend and the figure's other axes."""
    items = [a for a in fig.axes if a is not ax] + [lg for lg in [ax.get_legend()] if lg]
    return _extents(fig, items + list(fig.legends))


def _merge_close(xs, labels, min_px: float) -> list[tuple[float, list]]:
    """Marks (display x, label) sorted by x; marks closer than min_px share one label."""
    groups: list[tuple[float, list]] = []
    for x, label in sorted(zip(xs, labels, strict=True)):
        if groups and x - groups[-1][0] < min_px:
            groups[-1][1].append(label)
        else:
            groups.append((x, [label]))
    return groups


def label_vertical_marks(fig, ax, xs, labels, fontsize: float = 7, color: str = "0.25",
                         gid: str = "mark-label") -> list:
    """Label vertical lines at data x ``xs`` above the plot, without overlaps.

    Each label sits in a row above the axes, joined to its line by a dotted leader;
    rows stack upwards where neighbours would overlap (:func:`place_labels`), and lines
    less than 2 pixels apart share one label ("a, b"). Placement is redone after the
    layout engine has made room for the rows. Returns the annotations (gid ``gid``).
    """
    texts: list = []
    for _ in range(3):
        for t in texts:
            t.remove()
        fig.canvas.draw()
        texts = _place_vertical(fig, ax, xs, labels, fontsize, color, gid)
        fig.canvas.draw()
        if not overlapping_pairs(_extents(fig, texts) + _obstacles(fig, ax)):
            break
    return texts


def _place_vertical(fig, ax, xs, labels, fontsize, color, gid) -> list:
    box = ax.get_window_extent(fig.canvas.get_renderer())
    xd = ax.transData.transform(np.column_stack([xs, np.zeros(len(xs))]))[:, 0]
    groups = _merge_close(xd, labels, 2.0)
    texts = [", ".join(g[1]) for g in groups]
    sizes = [text_size(fig, t, fontsize) for t in texts]
    height, gap, fractions = max(h for _, h in sizes), 2.0, (0.5, 0.3, 0.7, 0.05, 0.95)
    candidates, leaders, where = [], [], []
    for (x, _), (w, h) in zip(groups, sizes, strict=True):
        spots = [(f, box.y1 + gap + r * (height + gap)) for r in range(len(groups))
                 for f in fractions]
        candidates.append([(x - f * w, y, x - f * w + w, y + h) for f, y in spots])
        leaders.append([(x, box.y1, x, y) for f, y in spots])
        where.append(spots)
    bounds = (fig.bbox.x0 + 1, -np.inf, fig.bbox.x1 - 1, np.inf)
    places = _one_row(fig, ax, box, groups, sizes, bounds)
    if places is None:  # rows above each other, vertical leaders where possible
        columns = [(x, box.y1, x, np.inf) for x, _ in groups]
        chosen = place_labels(candidates, _obstacles(fig, ax), bounds, leaders, pad=gap,
                              columns=columns)
        places = [None if j < 0 else ((0.5 - spots[j][0]) * w, spots[j][1], spots[j][0])
                  for spots, (w, _), j in zip(where, sizes, chosen, strict=True)]
    points = 72.0 / fig.dpi
    out = []
    for (x, _), text, place in zip(groups, texts, places, strict=True):
        if place is None:
            continue
        dx, y, f = place
        out.append(ax.annotate(
            text, xy=(ax.transData.inverted().transform((x, box.y1))[0], 1.0),
            xycoords=("data", "axes fraction"), xytext=(dx * points, (y - box.y1) * points),
            textcoords="offset points", ha="center", va="bottom", fontsize=fontsize,
            color=color, gid=gid, annotation_clip=False,
            arrowprops={"arrowstyle": "-", "color": color, "lw": 0.6, "ls": ":",
                        "shrinkA": 0, "shrinkB": 0, "relpos": (f, 0.0)}))
    return out


def _one_row(fig, ax, box, groups, sizes, bounds) -> list | None:
    """All labels in one row above the axes (:func:`spread_1d`), each joined to its line
    by a straight leader: [(dx, y, relpos), ...] in pixels, or None if they do not fit."""
    xs = np.array([x for x, _ in groups])
    widths = np.array([w for w, _ in sizes])
    lefts = spread_1d(xs, widths, 4.0, bounds[0], bounds[2])
    if lefts is None:
        return None
    shift = lefts + widths / 2 - xs
    most = float(np.abs(shift).max())
    if most > MAX_LABEL_SHIFT:
        return None
    y = box.y1 + float(np.clip(0.4 * most, 3.0, 0.4 * MAX_LABEL_SHIFT))  # leaders ≤ 68°
    boxes = [(lft, y, lft + w, y + h) for lft, (w, h) in zip(lefts, sizes, strict=True)]
    if any(not _free(b, _obstacles(fig, ax), 1.0) for b in boxes):
        return None
    return [(float(d), y, 0.5) for d in shift]


def label_right_margin(fig, ax, ys, labels, colors, fontsize: float = 8,
                       gid: str = "margin-label", priority=None) -> list:
    """Label horizontal positions (data y ``ys``) in the margin right of the axes.

    Each label starts just right of the axes at its y, or as near as it fits without
    overlapping another label (moved up or down in steps; a thin line joins a moved
    label to its y). Labels are placed by ascending ``priority`` (default all 0), then
    from the bottom up; labels that find no place are left out. Returns the annotations.
    """
    texts: list = []
    for _ in range(3):
        for t in texts:
            t.remove()
        fig.canvas.draw()
        texts = _place_right(fig, ax, ys, labels, colors, fontsize, gid, priority)
        fig.canvas.draw()
        if not overlapping_pairs(_extents(fig, texts) + _obstacles(fig, ax)):
            break
    return texts


def _place_right(fig, ax, ys, labels, colors, fontsize, gid, priority) -> list:
    box = ax.get_window_extent(fig.canvas.get_renderer())
    yd = ax.transData.transform(np.column_stack([np.zeros(len(ys)), ys]))[:, 1]
    order = np.lexsort((yd, np.zeros(len(ys)) if priority is None else priority))
    sizes = [text_size(fig, str(t), fontsize) for t in labels]
    step, x0 = 2.0, box.x1 + 6.0
    n_steps = int(box.height / step) + 1
    shifts = [0.0] + [s * k * step for k in range(1, n_steps) for s in (1, -1)]
    candidates = []
    for i in order:
        w, h = sizes[i]
        candidates.append([(x0, yd[i] + d - h / 2, x0 + w, yd[i] + d + h / 2)
                           for d in shifts])
    bounds = (box.x1, box.y0 - 20.0, np.inf, box.y1 + 20.0)  # the layout makes room
    chosen = place_labels(candidates, _obstacles(fig, ax), bounds, pad=1.0)
    points, out = 72.0 / fig.dpi, []
    for i, j in zip(order, chosen, strict=True):
        if j < 0 or not np.isfinite(yd[i]):
            continue
        d = shifts[j]
        arrow = ({"arrowstyle": "-", "color": colors[i], "lw": 0.6, "shrinkA": 0,
                  "shrinkB": 0, "relpos": (0.0, 0.5)} if abs(d) > 1.0 else None)
        out.append(ax.annotate(
            str(labels[i]), xy=(1.0, ys[i]), xycoords=("axes fraction", "data"),
            xytext=(6.0 * points, d * points), textcoords="offset points", ha="left",
            va="center", fontsize=fontsize, color=colors[i], gid=gid,
            annotation_clip=False, arrowprops=arrow))
    return out


def legend_below(fig, ax, handles, labels, fontsize: float = 8):
    """The axes' one legend, centred below its x-axis label (outside the plot, so it
    covers no data; the layout engine makes room). Returns the Legend."""
    from matplotlib.transforms import ScaledTranslation

    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    drop = (ax.get_window_extent(renderer).y0 - ax.xaxis.get_tightbbox(renderer).y0) \
        * 72.0 / fig.dpi + 2.0  # points from the axes' bottom to below the x label
    where = ax.transAxes + ScaledTranslation(0.0, -drop / 72.0, fig.dpi_scale_trans)
    return ax.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.0),
                     bbox_transform=where, ncols=min(len(handles), 3), fontsize=fontsize,
                     frameon=False)
