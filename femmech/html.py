"""HTML built from text, escaped by construction, and short HTML summaries of femmech
objects for notebooks (``_repr_html_``).

Every piece of HTML femmech writes (the report page, :mod:`femmech.output.report`, and
the notebook summaries) is made by :func:`element`: its children and attribute values are
text and are escaped (:func:`html.escape` with ``quote=True``) exactly once, unless they
are :class:`Markup`, the one marker type for HTML that is already safe (what
:func:`element` and :func:`text` return). Scene names, descriptions, group and set
names, file names and messages can therefore hold ``<``, ``"`` or ``&`` without ever
becoming markup. Link targets (``href``, ``src``) must be relative references
(:func:`url`): a scheme such as ``javascript:`` or ``http:`` is refused.

Jupyter shows an object by its ``_repr_html_``: femmech's models and results give a title,
a few key facts and, for results, a small table of the first rows, never their arrays.
Numbers that may be wrong (not converged) are set in bold red with the word
"NOT CONVERGED", as everywhere else in femmech.

Stage 0: imports nothing of femmech; every stage may use it.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from html import escape
from urllib.parse import quote


class Markup(str):
    """A string of HTML that is safe to insert as is (made by :func:`element`,
    :func:`text` or :func:`url`, or written by femmech itself, e.g. the report's CSS).
    Any other string given to :func:`element` is text and is escaped."""

    __slots__ = ()


def text(value) -> Markup:
    """``value`` (str or anything with ``str``) as HTML text: escaped, ``quote=True``;
    :class:`Markup` is returned unchanged (never escaped twice)."""
    return value if isinstance(value, Markup) else Markup(escape(str(value), quote=True))


_SCHEME = re.compile(r"^[\s\x00-\x1f]*[A-Za-z][A-Za-z0-9+.\-]*:")
_FRAGMENT = re.compile(r"^#[A-Za-z0-9_\-]+$")


def url(path: str) -> Markup:
    """A link target: ``#anchor`` as is, else a relative path percent-encoded (``/``
    kept). ValueError naming it for a URL with a scheme (``javascript:``, ``data:``,
    ``http:``, ...), an absolute or network path (``/x``, ``//host``) or a backslash."""
    path = str(path)
    if _FRAGMENT.match(path):
        return Markup(path)
    if _SCHEME.match(path) or path.startswith(("/", "\\")) or "\\" in path:
        raise ValueError(f"link target {path!r}: expected a relative path inside the"
                         " report's folder")
    return Markup(quote(path))


_TAG = re.compile(r"^[a-z][a-z0-9]*$")
_ATTRIBUTE = re.compile(r"^[a-z][a-z0-9\-]*$")
_VOID = frozenset({"img", "meta", "br", "hr", "link"})
_URL_ATTRIBUTES = frozenset({"href", "src"})


def element(tag: str, *children, **attributes) -> Markup:
    """``<tag attributes>children</tag>`` with every child and attribute value escaped
    unless it is :class:`Markup`.

    Parameters
    ----------
    tag : str
        Lower-case tag name; void elements (``img``, ``meta``, ...) take no children.
    *children
        Text (escaped), :class:`Markup` (as is), None (left out) or lists/tuples of these.
    **attributes
        Name → value; a trailing ``_`` is dropped (``class_``), ``_`` becomes ``-``
        (``http_equiv``). None or False leaves the attribute out; other values are text,
        always escaped with ``quote=True`` (also :class:`Markup`: an attribute holds no
        markup); ``href`` and ``src`` go through :func:`url` first.
    """
    if not _TAG.match(tag):
        raise ValueError(f"HTML tag {tag!r}: expected a lower-case name")
    parts = [f"<{tag}"]
    for name, value in attributes.items():
        name = name.rstrip("_").replace("_", "-")
        if not _ATTRIBUTE.match(name):
            raise ValueError(f"HTML attribute {name!r}: expected a lower-case name")
        if value is None or value is False:
            continue
        if name in _URL_ATTRIBUTES:
            value = url(value)  # percent-encoded: escaping below changes nothing
        parts.append(f' {name}="{escape(str(value), quote=True)}"')
    parts.append(">")
    if tag in _VOID:
        if any(c is not None for c in children):
            raise ValueError(f"HTML element <{tag}> takes no children")
        return Markup("".join(parts))
    parts.append(_children(children))
    return Markup("".join(parts) + f"</{tag}>")


def _children(children) -> str:
    out = []
    for child in children:
        if child is None:
            continue
        if isinstance(child, (list, tuple)):
            out.append(_children(child))
        else:
            out.append(text(child))
    return "".join(out)


def fragment(*children) -> Markup:
    """Children side by side without an enclosing element (escaped as in
    :func:`element`)."""
    return Markup(_children(children))

MAX_ROWS = 12
"""Rows of a result table shown; the rest is summarised as "… n more"."""

_STYLE = ("font-family: sans-serif; font-size: 12px; border-collapse: collapse;"
          " margin: 2px 0")
_CELL = "padding: 1px 8px; text-align: left; border-bottom: 1px solid #ddd"
_FLAG = "color: #b2182b; font-weight: bold"


def flagged(value: str) -> Markup:
    """``value`` marked as a possibly wrong number (bold red)."""
    return element("span", value, style=_FLAG)


class Flag:
    """A table value shown as flagged (bold red), e.g. ``Flag("NOT CONVERGED")``."""

    def __init__(self, text: str):
        self.text = text


def _cell(value) -> Markup:
    if isinstance(value, Flag):
        return flagged(value.text)
    if isinstance(value, float):
        return text(f"{value:.6g}")
    return text(value)


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
        Self-contained HTML (inline styles, no scripts); every string given is escaped.
    """
    parts = [element("strong", title)]
    if facts:
        parts.append(element("table", [element("tr", element("th", label, style=_CELL),
                                                element("td", _cell(value), style=_CELL))
                                        for label, value in facts], style=_STYLE))
    if header:
        shown = [element("tr", [element("td", _cell(v), style=_CELL) for v in row])
                 for row in list(rows)[:MAX_ROWS]]
        more = len(rows) - MAX_ROWS
        if more > 0:
            shown.append(element("tr", element("td", f"… {more} more", style=_CELL,
                                               colspan=len(header))))
        parts.append(element("table", element("tr", [element("th", h, style=_CELL)
                                                     for h in header]), shown, style=_STYLE))
    if note:
        parts.append(element("div", note))
    return element("div", parts, class_="femmech-repr")
