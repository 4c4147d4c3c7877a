"""Short HTML summaries of femmech objects for notebooks (``_repr_html_``).

Jupyter shows an object by its ``_repr_html_``: femmech's models and results give a title,
a few key facts and, for results, a small table of the first rows, never their arrays.
Numbers that may be wrong (not converged) are set in bold red with the word
"NOT CONVERGED", as everywhere else in femmech.

Stage 0: imports nothing of femmech; every stage may use it.
"""

from __future__ import annotations

from collections.abc import Sequence
from html import escape

MAX_ROWS = 12
"""Rows of a result table shown; the rest is summarised as "… n more"."""

_STYLE = ("font-family: sans-serif; font-size: 12px; border-collapse: collapse;"
          " margin: 2px 0")
_CELL = "padding: 1px 8px; text-align: left; border-bottom: 1px solid #ddd"
_FLAG = "color: #b2182b; font-weight: bold"


def flagged(text: str) -> str:
    """``text`` marked as a possibly wrong number (bold red); already HTML."""
    return f'<span style="{_FLAG}">{escape(text)}</span>'


class Flag:
    """A table value shown as flagged (bold red), e.g. ``Flag("NOT CONVERGED")``."""

    def __init__(self, text: str):
        self.text = text


def _cell(value) -> str:
    if isinstance(value, Flag):
        return flagged(value.text)
    if isinstance(value, float):
        return escape(f"{value:.6g}")
    return escape(str(value))


def html_summary(title: str, facts: Sequence[tuple[str, object]] = (),
                 header: Sequence[str] = (), rows: Sequence[Sequence] = (),
                 note: str = "") -> str:
    """One object as HTML: a bold title, facts as label/value rows, then a result table.

    Parameters
    ----------
    title : str
        E.g. ``"ModeSet: 12 modes"``.
    facts : sequence of (label, value)
        Key facts; values are shown with ``str`` (floats with 6 significant digits;
        :class:`Flag` values bold red).
    header, rows : sequences
        An optional table; only the first :data:`MAX_ROWS` rows are shown.
    note : str
        A line of plain text under the tables.

    Returns
    -------
    str
        Self-contained HTML (inline styles, no scripts).
    """
    parts = [f'<div class="femmech-repr"><strong>{escape(title)}</strong>']
    if facts:
        body = "".join(f'<tr><th style="{_CELL}">{escape(label)}</th>'
                       f'<td style="{_CELL}">{_cell(value)}</td></tr>'
                       for label, value in facts)
        parts.append(f'<table style="{_STYLE}">{body}</table>')
    if header:
        head = "".join(f'<th style="{_CELL}">{escape(h)}</th>' for h in header)
        td = f'<td style="{_CELL}">'
        shown = ["<tr>" + "".join(f"{td}{_cell(v)}</td>" for v in row) + "</tr>"
                 for row in list(rows)[:MAX_ROWS]]
        more = len(rows) - MAX_ROWS
        if more > 0:
            shown.append(f'<tr><td style="{_CELL}" colspan="{len(header)}">… {more} more'
                         "</td></tr>")
        parts.append(f'<table style="{_STYLE}"><tr>{head}</tr>{"".join(shown)}</table>')
    if note:
        parts.append(f"<div>{escape(note)}</div>")
    return "".join(parts) + "</div>"
