"""One self-contained HTML report page: inline CSS, no scripts, no external resources.

Images (PNG) and data files (CSV, JSON, VTU) are referenced by relative names and lie
next to the page, so the folder can be moved or zipped as a whole. The page is written
atomically (:func:`femmech.output.export.atomic_path`); :func:`write_report` refuses to
write a page that references a missing file.

Every number in a table cell is formatted by :func:`femmech.output.formatting.format_value`
(engineering notation, fixed significant digits, no float artefacts); NaN and infinite
values are highlighted like :class:`Flagged` cells.

Every string of a section (titles, paragraphs, warnings, captions, cells, file names, the
log) is text: the page is built by :func:`femmech.html.element`, which escapes it exactly
once, so a scene name or group name holding ``<script>`` shows as written and never runs.
Link targets must be relative paths (:func:`femmech.html.url`).

Uses html, output.export and output.formatting.
"""

from __future__ import annotations

import html
import re
from dataclasses import dataclass, field
from numbers import Real
from pathlib import Path

from femmech.html import Markup, element, fragment
from femmech.output.formatting import Quantity, format_value, is_flagged

CSS = """
body{font-family:system-ui,-apple-system,'Segoe UI',sans-serif;margin:0 auto;max-width:1100px;
padding:1em 2em;color:#222;line-height:1.45}
h1{margin-bottom:.2em}h2{border-bottom:2px solid #3b6ea5;padding-bottom:.2em;margin-top:1.6em}
.meta{color:#666;font-size:.9em}nav a{margin-right:1em}
table{border-collapse:collapse;margin:.6em 0 1em;font-size:.88em}
caption{caption-side:top;text-align:left;font-weight:600;padding:.3em 0}
th,td{border:1px solid #ccd;padding:.25em .6em;text-align:left;vertical-align:top}
th{background:#eef3f9}td.num{text-align:right;font-variant-numeric:tabular-nums;
white-space:nowrap}
figure{display:inline-block;margin:.5em 1em .5em 0;vertical-align:top}
figure img{max-width:min(100%,720px);border:1px solid #dde}
figcaption{font-size:.85em;color:#444}
.gallery img{width:340px}pre{background:#f6f6f6;padding:.7em;overflow-x:auto;font-size:.82em}
ul.files{font-size:.9em}
.warning{border-left:4px solid #c0392b;background:#fdecea;padding:.4em .8em}
td.flagged{background:#fdecea;color:#8b1a10;font-weight:600}
p.note{font-size:.85em;color:#444;margin-top:-.6em}
"""


@dataclass(frozen=True)
class Table:
    """A table: caption, header cells and rows of cells.

    A cell is a str, an int, a float (4 significant digits), a
    :class:`~femmech.output.formatting.Quantity` (value with unit and digits) or a
    :class:`Flagged` text. ``note`` is a sentence shown under the table (e.g.
    :func:`rigid_modes_note` under a table of natural frequencies).
    """

    caption: str
    header: tuple
    rows: tuple
    note: str = ""


def rigid_modes_note(rigid) -> str:
    """The sentence under a table of natural modes that says how ``n_modes`` counts.

    ``rigid``: the rigid-body flags of the modes (:attr:`femmech.ModeSet.rigid`), e.g.
    ``"n_modes counts rigid-body modes: 6 of the 12 modes are rigid (0 Hz)."``; for no
    rigid mode, ``"n_modes counts rigid-body modes: none of the 12 modes is rigid."``.
    """
    flags = [bool(r) for r in rigid]
    n, k = len(flags), sum(flags)
    if not k:
        return f"n_modes counts rigid-body modes: none of the {n} modes is rigid."
    return f"n_modes counts rigid-body modes: {k} of the {n} modes {'is' if k == 1 else 'are'}" \
           " rigid (0 Hz)."


@dataclass(frozen=True)
class Figure:
    """An image file (relative to the report folder) with its caption."""

    file: str
    caption: str


@dataclass(frozen=True)
class Section:
    """One section of the report.

    Attributes
    ----------
    title : str
    paragraphs : tuple of str
    tables : tuple of Table
    figures : tuple of Figure
    files : tuple of str
        Data files (relative names) to link.
    gallery : bool
        Show the figures as small thumbnails (mode images).
    warnings : tuple of str
        Findings the reader must not miss (unconverged results), shown highlighted
        before the tables.
    preformatted : tuple of str
        Lines shown as one preformatted block after the tables (a run log).
    """

    title: str
    paragraphs: tuple = ()
    tables: tuple = ()
    figures: tuple = ()
    files: tuple = ()
    gallery: bool = False
    anchor: str = field(default="")
    warnings: tuple = ()
    preformatted: tuple = ()


@dataclass(frozen=True)
class Flagged:
    """A table cell whose value may be wrong (e.g. not converged): shown highlighted."""

    text: str


_NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)(e[-+]?\d+)?( ?%| [^\s\d]+)?$")
"""A cell's text that is a number, optionally with a unit: right-aligned."""


def _cell(value) -> Markup:
    """One ``<td>``: class ``flagged`` for Flagged, NaN and infinite values, class
    ``num`` (right-aligned) for numbers."""
    classes = []
    if isinstance(value, Flagged) or (isinstance(value, Quantity) and value.flagged) \
            or is_flagged(value):
        classes.append("flagged")
    text = _text(value)
    if (isinstance(value, (Quantity, Real)) and not isinstance(value, bool)) or \
            _NUMBER.match(text):
        classes.append("num")
    return element("td", text, class_=" ".join(classes) or None)


def _text(value) -> str:
    """The cell's text (not yet escaped: :func:`femmech.html.element` escapes it)."""
    if isinstance(value, Flagged):
        return str(value.text)
    if isinstance(value, Real) and not isinstance(value, (bool, Quantity)):
        return format_value(value)
    return str(value)


def render_table(table: Table) -> str:
    """HTML of one table; numbers formatted by
    :func:`~femmech.output.formatting.format_value`."""
    head = element("thead", element("tr", [element("th", _text(h)) for h in table.header]))
    body = element("tbody", [element("tr", [_cell(c) for c in row]) for row in table.rows])
    note = element("p", table.note, class_="note") if table.note else None
    return fragment(element("table", element("caption", table.caption), head, body), note)


def _figure(fig: Figure) -> Markup:
    return element("figure", element("a", element("img", src=fig.file, alt=fig.caption),
                                     href=fig.file), element("figcaption", fig.caption))


def render_section(section: Section, anchor: str) -> str:
    """HTML of one section."""
    parts = [element("h2", section.title)]
    parts += [element("p", p) for p in section.paragraphs]
    parts += [element("p", Markup("&#9888; "), w, class_="warning") for w in section.warnings]
    parts += [render_table(t) for t in section.tables]
    if section.figures:
        parts.append(element("div", [_figure(f) for f in section.figures],
                             class_="gallery" if section.gallery else None))
    if section.preformatted:
        parts.append(element("pre", "\n".join(section.preformatted)))
    if section.files:
        parts.append(element("ul", [element("li", element("a", f, href=f))
                                    for f in section.files], class_="files"))
    # the section's lines are joined by newlines, as the page always was
    return Markup(f'<section id="{html.escape(anchor, quote=True)}">'
                  + "\n".join(parts) + "\n</section>")


def render_report(title: str, meta: str, sections, log_lines=()) -> str:
    """The whole page as a string."""
    anchors = [f"s{i + 1}" for i in range(len(sections))]
    nav = element("nav", [element("a", s.title, href=f"#{a}")
                          for a, s in zip(anchors, sections, strict=True)])
    body = "\n".join(render_section(s, a) for s, a in zip(sections, anchors, strict=True))
    log = ""
    if log_lines:
        log = element("section", element("h2", "Run log"), element("pre", "\n".join(log_lines)),
                      id="log")
    head = element("head", Markup('<meta charset="utf-8">'),
                   element("meta", name="viewport",
                           content="width=device-width, initial-scale=1"),
                   element("title", title), element("style", Markup(CSS)))
    header = element("header", element("h1", title), element("p", meta, class_="meta"), nav)
    return (f'<!DOCTYPE html>\n<html lang="en">{head}\n<body>{header}\n{body}\n{log}\n'
            "</body></html>\n")


def write_report(out_dir, title: str, meta: str, sections, log_lines=(),
                 name: str = "report.html") -> Path:
    """Write the report page into ``out_dir`` (atomically) and return its path.

    Raises
    ------
    FileNotFoundError
        If a figure or data file of a section is not in ``out_dir``.
    """
    out = Path(out_dir)
    for section in sections:
        for file in [f.file for f in section.figures] + list(section.files):
            if not (out / file).is_file():
                raise FileNotFoundError(f"report section {section.title!r} references"
                                        f" {file}, which is not in {out}")
    from femmech.output.export import atomic_path  # meshio: not for a scene's tables

    target = out / name
    with atomic_path(target) as tmp:
        tmp.write_text(render_report(title, meta, sections, log_lines), encoding="utf-8")
    return target
