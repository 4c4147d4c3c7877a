"""Strict reading of one table of a scene file: typed values, units, unknown keys, limits.

Every error is a one-line :class:`~femmech.errors.SceneError` naming the file, the key path
and what was expected, e.g.
``scene.toml: [parts.frame.sections.posts] section: expected one of [...], got 'foo'``.

A table reader first declares the keys its table may hold (:meth:`Reader.expect`), so that
a misspelt key is reported, with a "did you mean", before any missing or inconsistent
value. :func:`check_limits` bounds the size of everything a scene can hand over (nesting
depth, list and string lengths, number of values) before any of it is read.

Stage 8 (scene), reading: uses scene.units and fe.mesh (limits on mesh sizes).
"""

from __future__ import annotations

import difflib
import os
import re
from contextlib import contextmanager
from pathlib import Path

from femmech.errors import SceneError
from femmech.fe.mesh import MAX_NODES
from femmech.scene.units import Kind, quantity

MAX_SCENE_BYTES = 16 * 2**20
"""Largest scene file read, bytes (a scene of a big machine is a few hundred kB)."""
MAX_DEPTH = 16
"""Deepest nesting of tables and lists (the scene format uses at most 6 levels)."""
MAX_LIST_LENGTH = 100_000
"""Longest list (or array of tables) and largest table (number of keys)."""
MAX_STRING_LENGTH = 10_000
"""Longest string value, characters."""
MAX_KEY_LENGTH = 200
"""Longest key (also names of groups, materials, parts, mechanisms), characters."""
MAX_VALUES = 1_000_000
"""Most values (leaves, lists and tables) in one scene."""
MAX_MAGNITUDE = 1e30
"""Largest magnitude of a quantity in SI units (a penalty stiffness of 1e20 N/m fits; beyond
this, powers of the value in section and element formulas overflow)."""

_MISSING = object()
_PLAIN_KEY = re.compile(r"^[A-Za-z0-9_\-]+$")
_LINE_BREAKS = {ord(c): repr(c)[1:-1] for c in "\n\r\v\f\x1c\x1d\x1e\x85\u2028\u2029"}


def show(value) -> str:
    """repr of a value, cut to 60 characters (for messages)."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def key_text(key) -> str:
    """A key as written in a key path: bare when it is a TOML bare key, else quoted."""
    if isinstance(key, str) and _PLAIN_KEY.match(key):
        return key
    return show(str(key))


def one_line(text: str) -> str:
    """``text`` with every line break escaped (messages stay one line)."""
    return text.translate(_LINE_BREAKS)


def file_path(base, name) -> Path:
    """The file ``name`` (a scene value, or a path given by the user) relative to the
    folder ``base``: absolute, with ``..`` and symbolic links resolved, as files are read
    and as messages show them (``/x/meshes/frame.msh``, not
    ``/x/examples/../meshes/frame.msh``). A name that cannot be resolved (a NUL byte, a
    loop of links) is only normalised."""
    path = Path(base) / name
    try:
        return path.resolve()
    except (OSError, ValueError, RuntimeError):
        return Path(os.path.normpath(path.absolute()))


def closest(word, names) -> str | None:
    """The name of ``names`` nearest to ``word`` (difflib ratio >= 0.6), for a "did you
    mean"; None if none is near."""
    close = difflib.get_close_matches(str(word), [str(n) for n in names], n=1, cutoff=0.6)
    return close[0] if close else None


def unknown_key_message(key, allowed, context: str = "") -> str:
    """``unknown key[ context]; did you mean 'x'? expected one of [...]``."""
    names = sorted(str(a) for a in allowed)
    near = closest(key, names)
    hint = f" did you mean {near!r}?" if near else ""
    context = f" {context}" if context else ""
    return f"unknown key{context};{hint} expected one of {names}"


def check_limits(data, file: str) -> None:
    """Bound nesting depth, list, table, key and string sizes and the number of values of
    a scene (a dict as read from TOML), before anything is read from it.

    Iterative (no recursion), so a hostile nesting cannot exhaust the stack here.

    Raises
    ------
    SceneError
        Naming the key path and the limit exceeded.
    """
    stack = [((), data)]
    count = 0
    while stack:
        path, value = stack.pop()
        count += 1
        if count > MAX_VALUES:
            raise _limit_error(file, (), f"more than {MAX_VALUES} values in the scene")
        if isinstance(value, dict):
            items = list(value.items())
            for key, _ in items:
                if not isinstance(key, str):
                    raise _limit_error(file, path, f"key {show(key)}: keys must be strings")
                if len(key) > MAX_KEY_LENGTH or not key.isprintable():
                    raise _limit_error(file, path, f"key {show(key)}: expected at most"
                                       f" {MAX_KEY_LENGTH} printable characters")
        elif isinstance(value, list):
            items = [(f"[{i}]", v) for i, v in enumerate(value)]
        else:
            if isinstance(value, str) and len(value) > MAX_STRING_LENGTH:
                raise _limit_error(file, path, f"string of {len(value)} characters; at most"
                                   f" {MAX_STRING_LENGTH}")
            continue
        if len(items) > MAX_LIST_LENGTH:
            what = "table of" if isinstance(value, dict) else "list of"
            raise _limit_error(file, path, f"{what} {len(items)} entries; at most"
                               f" {MAX_LIST_LENGTH}")
        if items and len(path) >= MAX_DEPTH:
            raise _limit_error(file, path, f"nested deeper than {MAX_DEPTH} levels")
        stack.extend((path + (key,), item) for key, item in items)


def _limit_error(file: str, path: tuple, message: str) -> SceneError:
    where = ""
    for key in path:
        where += key if key.startswith("[") and where else f".{key_text(key)}"
    where = where.lstrip(".")
    place = f"[{where}]: " if where else ""
    return SceneError(one_line(f"{file}: {place}{message}"))


class Reader:
    """Reader of one scene table: its allowed keys first, then typed values.

    Parameters
    ----------
    data : dict
        The table.
    where : str
        Its key path (``"parts.frame.sections.posts"``; ``""`` for the top level).
    file : str
        Name of the scene file for the messages.
    """

    def __init__(self, data, where: str, file: str):
        self.where, self.file = where, file
        if not isinstance(data, dict):
            place = f"[{where}]: " if where else ""
            raise SceneError(one_line(f"{file}: {place}expected a table, got {show(data)}"))
        self.data = data

    def error(self, key: str | None, message: str) -> SceneError:
        """A SceneError located at ``key`` of this table."""
        place = f"[{self.where}]" if self.where else ""
        place = f"{place} {key_text(key)}" if key is not None else place
        return SceneError(one_line(f"{self.file}: {place.strip()}: {message}"))

    def expect(self, *keys: str, context: str = "") -> None:
        """Declare the keys this table may hold; the first other key is an error now,
        before any value is read, with the closest allowed key as a suggestion.

        May be called again with fewer keys once a choice is read (``context`` then says
        why, e.g. ``"for section = 'tube'"``).
        """
        for key in self.data:
            if key not in keys:
                raise self.error(key, unknown_key_message(key, keys, context))

    def child(self, key: str, data) -> Reader:
        """Reader of a nested table (``key`` may be ``"name"`` or ``"name[2]"``)."""
        where = f"{self.where}.{key}" if self.where else key
        return Reader(data, where, self.file)

    def table(self, key: str, default=_MISSING) -> Reader:
        """Reader of the nested table at ``key`` (of ``default`` when it is missing)."""
        return self.child(key_text(key), self.get(key, default))

    def has(self, key: str) -> bool:
        """Whether the table has ``key``."""
        return key in self.data

    def get(self, key: str, default=_MISSING):
        """Raw value; a missing key without default is an error."""
        if key in self.data:
            return self.data[key]
        if default is _MISSING:
            raise self.error(key, "missing (required)")
        return default

    def number(self, key: str, kind: Kind | None, default=_MISSING, positive: bool = False,
               non_negative: bool = False):
        """A quantity in SI (see :func:`femmech.scene.units.quantity`)."""
        value = self.get(key, default)
        if value is default and default is not _MISSING:
            return default
        return self.convert(key, value, kind, positive, non_negative)

    def convert(self, key: str, value, kind: Kind | None, positive: bool = False,
                non_negative: bool = False) -> float:
        """Convert one value (of ``key``) to SI, with sign checks."""
        try:
            out = quantity(value, kind)
        except (TypeError, ValueError) as exc:
            head, _, detail = str(exc).partition("; ")
            detail = f" ({detail})" if detail else ""
            raise self.error(key, f"{head}, got {show(value)}{detail}") from None
        if not abs(out) <= MAX_MAGNITUDE:
            raise self.error(key, f"expected a magnitude of at most {MAX_MAGNITUDE:g} in SI"
                                  f" units (limit MAX_MAGNITUDE), got {show(value)}")
        if positive and not out > 0:
            raise self.error(key, f"expected a positive value, got {show(value)}")
        if non_negative and not out >= 0:
            raise self.error(key, f"expected a value >= 0, got {show(value)}")
        return out

    def vector(self, key: str, kinds, default=_MISSING):
        """A list of quantities, one kind per entry (``kinds`` a sequence) → tuple."""
        value = self.get(key, default)
        if value is default and default is not _MISSING:
            return default
        kinds = tuple(kinds)
        if not isinstance(value, list) or len(value) != len(kinds):
            raise self.error(key, f"expected a list of {len(kinds)} values, got {show(value)}")
        return tuple(self.convert(key, v, k) for v, k in zip(value, kinds, strict=True))

    def integer(self, key: str, default=_MISSING, minimum: int | None = None,
                maximum: int | None = None, limit: str = ""):
        """An integer (TOML integer, not a float or bool) in [minimum, maximum]; ``limit``
        names the constant behind ``maximum`` for the message."""
        value = self.get(key, default)
        if value is default and default is not _MISSING:
            return default
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(key, f"expected an integer, got {show(value)}")
        if minimum is not None and value < minimum:
            raise self.error(key, f"expected an integer >= {minimum}, got {show(value)}")
        if maximum is not None and value > maximum:
            limit = f" (limit {limit})" if limit else ""
            raise self.error(key, f"expected an integer <= {maximum}{limit}, got"
                                  f" {show(value)}")
        return value

    def boolean(self, key: str, default=_MISSING):
        """true or false."""
        value = self.get(key, default)
        if not isinstance(value, bool):
            raise self.error(key, f"expected true or false, got {show(value)}")
        return value

    def string(self, key: str, default=_MISSING, choices=None):
        """A string, optionally one of ``choices``."""
        value = self.get(key, default)
        if value is default and default is not _MISSING:
            return default
        if not isinstance(value, str):
            raise self.error(key, f"expected a string, got {show(value)}")
        if choices is not None and value not in choices:
            near = closest(value, choices)
            hint = f" (did you mean {near!r}?)" if near else ""
            raise self.error(key, f"expected one of {sorted(choices)}, got"
                                  f" {show(value)}{hint}")
        return value

    def strings(self, key: str, default=_MISSING) -> tuple:
        """A list of strings → tuple."""
        value = self.get(key, default)
        if value is default and default is not _MISSING:
            return default
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise self.error(key, f"expected a list of strings, got {show(value)}")
        return tuple(value)

    def node_ref(self, key: str, many: bool = False, default=_MISSING):
        """A node: a group name or a node index; with ``many`` also a list of indices."""
        value = self.get(key, default)
        if value is default and default is not _MISSING:
            return default
        if isinstance(value, str) or (isinstance(value, int) and not isinstance(value, bool)):
            if isinstance(value, int) and not 0 <= value <= MAX_NODES:
                raise self.error(key, f"expected a node index >= 0 and <= {MAX_NODES} (limit"
                                      f" MAX_NODES), got {show(value)}")
            return value
        if many and isinstance(value, list) and value and all(
                isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= MAX_NODES
                for v in value):
            return tuple(value)
        what = "a group name, a node index or a list of node indices" if many else \
            "a group name or a node index"
        raise self.error(key, f"expected {what}, got {show(value)}")

    def tables(self, key: str) -> list[Reader]:
        """An array of tables (``[[key]]``) → readers named ``key[i]`` (0-based)."""
        value = self.get(key, [])
        if not isinstance(value, list):
            raise self.error(key, f"expected an array of tables ([[{key}]]), got {show(value)}")
        return [self.child(f"{key}[{i}]", item) for i, item in enumerate(value)]

    def named_tables(self, key: str) -> dict[str, Reader]:
        """A table of tables (``[key.name]``) → {name: reader}."""
        value = self.get(key, {})
        if not isinstance(value, dict):
            raise self.error(key, f"expected a table of named tables, got {show(value)}")
        return {name: self.child(f"{key}.{key_text(name)}", item)
                for name, item in value.items()}


@contextmanager
def relocate(r: Reader, keys, prefix: str = ""):
    """Re-raise the library's ValueError or TypeError in the block as a SceneError at
    ``[table] key``: the first of ``keys`` the message names as its argument (``"...: E
    must ..."``, ``"E = ... is outside"``), else at the table; ``prefix`` (the library's
    own naming of the item, e.g. ``"material 'steel': "``) is dropped from the message,
    which the table's location replaces."""
    try:
        yield
    except (ValueError, TypeError) as exc:
        message = str(exc).removeprefix(prefix)
        key = next((k for k in keys if re.match(rf"{re.escape(k)}\b", message)),
                   None)
        raise r.error(key, message) from None
