"""One self-contained HTML report page: inline CSS, no scripts, no external resources.

Images (PNG) and data files (CSV, JSON, VTU) are referenced by relative names and lie
next to the page, so the folder can be moved or zipped as a whole. The page is written
atomically (:func:`femmech.output.export.atomic_path`); :func:`write_report` refuses to
write a page that references a missing file.

Stage 6 (output): uses only output.export.
"""

from __future__ import annotations

import html
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import quote

from femmech.output.export import atomic_path

CSS = """
body{font-family:system-ui,-apple-system,'Segoe UI',sans-serif;margin:0 auto;max-width:1100px;
padding:1em 2em;color:#222;line-height:1.45}
h1{margin-bottom:.2em}h2{border-bottom:2px solid #3b6ea5;padding-bottom:.2em;margin-top:1.6em}
.meta{color:#666;font-size:.9em}nav a{margin-right:1em}
table{border-collapse:collapse;margin:.6em 0 1em;font-size:.88em}
caption{caption-side:top;text-align:left;font-weight:600;padding:.3em 0}
th,td{border:1px solid #ccd;padding:.25em .6em;text-align:right}
th{background:#eef3f9}td:first-child,th:first-child{text-align:left}
figure{display:inline-block;margin:.5em 1em .5em 0;vertical-align:top}
figure img{max-width:min(100%,720px);border:1px solid #dde}
figcaption{font-size:.85em;color:#444}
.gallery img{width:340px}pre{background:#f6f6f6;padding:.7em;overflow-x:auto;font-size:.82em}
ul.files{font-size:.9em}
.warning{border-left:4px solid #c0392b;background:#fdecea;padding:.4em .8em}
td.flagged{background:#fdecea;color:#8b1a10;font-weight:600}
"""


@dataclass(frozen=True)
class Table:
    """A table: caption, header cells and rows of cells (str or numbers)."""

    caption: str
    header: tuple
    rows: tuple


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
    """

    title: str
    paragraphs: tuple = ()
    tables: tuple = ()
    figures: tuple = ()
    files: tuple = ()
    gallery: bool = False
    anchor: str = field(default="")
    warnings: tuple = ()


@dataclass(frozen=True)
class Flagged:
    """A table cell whose value may be wrong (e.g. not converged): shown highlighted."""

    text: str


def _cell(value) -> str:
    if isinstance(value, Flagged):
        return html.escape(value.text)
    if isinstance(value, float):
        return html.escape(f"{value:.6g}")
    return html.escape(str(value))


def render_table(table: Table) -> str:
    """HTML of one table."""
    head = "".join(f"<th>{_cell(h)}</th>" for h in table.header)
    body = "".join("<tr>" + "".join(
        f'<td class="flagged">{_cell(c)}</td>' if isinstance(c, Flagged) else
        f"<td>{_cell(c)}</td>" for c in row) + "</tr>" for row in table.rows)
    return (f"<table><caption>{html.escape(table.caption)}</caption><thead><tr>{head}</tr>"
            f"</thead><tbody>{body}</tbody></table>")


def _figure(fig: Figure) -> str:
    return (f'<figure><a href="{quote(fig.file)}"><img src="{quote(fig.file)}"'
            f' alt="{html.escape(fig.caption)}"></a><figcaption>{html.escape(fig.caption)}'
            "</figcaption></figure>")


def render_section(section: Section, anchor: str) -> str:
    """HTML of one section."""
    parts = [f'<section id="{anchor}"><h2>{html.escape(section.title)}</h2>']
    parts += [f"<p>{html.escape(p)}</p>" for p in section.paragraphs]
    parts += [f'<p class="warning">&#9888; {html.escape(w)}</p>' for w in section.warnings]
    parts += [render_table(t) for t in section.tables]
    if section.figures:
        cls = ' class="gallery"' if section.gallery else ""
        parts.append(f"<div{cls}>" + "".join(_figure(f) for f in section.figures) + "</div>")
    if section.files:
        links = "".join(f'<li><a href="{quote(f)}">{html.escape(f)}</a></li>'
                        for f in section.files)
        parts.append(f'<ul class="files">{links}</ul>')
    parts.append("</section>")
    return "\n".join(parts)


def render_report(title: str, meta: str, sections, log_lines=()) -> str:
    """The whole page as a string."""
    anchors = [f"s{i + 1}" for i in range(len(sections))]
    nav = "".join(f'<a href="#{a}">{html.escape(s.title)}</a>'
                  for a, s in zip(anchors, sections, strict=True))
    body = "\n".join(render_section(s, a) for s, a in zip(sections, anchors, strict=True))
    log = ""
    if log_lines:
        log = ('<section id="log"><h2>Run log</h2><pre>' + html.escape("\n".join(log_lines))
               + "</pre></section>")
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<title>{html.escape(title)}</title><style>{CSS}</style></head>\n<body>"
            f"<header><h1>{html.escape(title)}</h1><p class=\"meta\">{html.escape(meta)}</p>"
            f"<nav>{nav}</nav></header>\n{body}\n{log}\n</body></html>\n")


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
    target = out / name
    with atomic_path(target) as tmp:
        tmp.write_text(render_report(title, meta, sections, log_lines), encoding="utf-8")
    return target
