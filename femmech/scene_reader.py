"""Strict reading of one table of a scene file: typed values, units, unknown keys.

Every error is a one-line :class:`~femmech.errors.SceneError` naming the file, the key path
and what was expected, e.g.
``scene.toml: [parts.frame.sections.posts] section: expected one of [...], got 'foo'``.
"""

from __future__ import annotations

from femmech.errors import SceneError
from femmech.units import Kind, quantity

_MISSING = object()


def _show(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


class Reader:
    """Reader of one scene table; remembers the keys asked for to reject unknown ones.

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
            raise SceneError(f"{file}: [{where}]: expected a table, got {_show(data)}")
        self.data = data
        self.asked: list[str] = []

    def error(self, key: str | None, message: str) -> SceneError:
        """A SceneError located at ``key`` of this table."""
        place = f"[{self.where}]" if self.where else ""
        place = f"{place} {key}" if key is not None else place
        return SceneError(f"{self.file}: {place.strip()}: {message}")

    def child(self, key: str, data) -> Reader:
        """Reader of a nested table (``key`` may be ``"name"`` or ``"name[2]"``)."""
        where = f"{self.where}.{key}" if self.where else key
        return Reader(data, where, self.file)

    def has(self, key: str) -> bool:
        """Whether the table has ``key`` (counts as asked)."""
        self.asked.append(key)
        return key in self.data

    def get(self, key: str, default=_MISSING):
        """Raw value; a missing key without default is an error."""
        self.asked.append(key)
        if key in self.data:
            return self.data[key]
        if default is _MISSING:
            raise self.error(key, "missing (required)")
        return default

    def number(self, key: str, kind: Kind | None, default=_MISSING, positive: bool = False,
               non_negative: bool = False):
        """A quantity in SI (see :func:`femmech.units.quantity`)."""
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
            raise self.error(key, f"{head}, got {_show(value)}{detail}") from None
        if positive and not out > 0:
            raise self.error(key, f"expected a positive value, got {_show(value)}")
        if non_negative and not out >= 0:
            raise self.error(key, f"expected a value >= 0, got {_show(value)}")
        return out

    def vector(self, key: str, kinds, default=_MISSING):
        """A list of quantities, one kind per entry (``kinds`` a sequence) → tuple."""
        value = self.get(key, default)
        if value is default and default is not _MISSING:
            return default
        kinds = tuple(kinds)
        if not isinstance(value, list) or len(value) != len(kinds):
            raise self.error(key, f"expected a list of {len(kinds)} values, got {_show(value)}")
        return tuple(self.convert(key, v, k) for v, k in zip(value, kinds, strict=True))

    def integer(self, key: str, default=_MISSING, minimum: int | None = None,
                maximum: int | None = None):
        """An integer (TOML integer, not a float or bool) in [minimum, maximum]."""
        value = self.get(key, default)
        if value is default and default is not _MISSING:
            return default
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(key, f"expected an integer, got {_show(value)}")
        if minimum is not None and value < minimum:
            raise self.error(key, f"expected an integer >= {minimum}, got {value}")
        if maximum is not None and value > maximum:
            raise self.error(key, f"expected an integer <= {maximum}, got {value}")
        return value

    def boolean(self, key: str, default=_MISSING):
        """true or false."""
        value = self.get(key, default)
        if not isinstance(value, bool):
            raise self.error(key, f"expected true or false, got {_show(value)}")
        return value

    def string(self, key: str, default=_MISSING, choices=None):
        """A string, optionally one of ``choices``."""
        value = self.get(key, default)
        if value is default and default is not _MISSING:
            return default
        if not isinstance(value, str):
            raise self.error(key, f"expected a string, got {_show(value)}")
        if choices is not None and value not in choices:
            raise self.error(key, f"expected one of {sorted(choices)}, got {_show(value)}")
        return value

    def strings(self, key: str, default=_MISSING) -> tuple:
        """A list of strings → tuple."""
        value = self.get(key, default)
        if value is default and default is not _MISSING:
            return default
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise self.error(key, f"expected a list of strings, got {_show(value)}")
        return tuple(value)

    def node_ref(self, key: str, many: bool = False, default=_MISSING):
        """A node: a group name or a node index; with ``many`` also a list of indices."""
        value = self.get(key, default)
        if value is default and default is not _MISSING:
            return default
        if isinstance(value, str) or (isinstance(value, int) and not isinstance(value, bool)):
            if isinstance(value, int) and value < 0:
                raise self.error(key, f"expected a node index >= 0, got {value}")
            return value
        if many and isinstance(value, list) and value and all(
                isinstance(v, int) and not isinstance(v, bool) and v >= 0 for v in value):
            return tuple(value)
        what = "a group name, a node index or a list of node indices" if many else \
            "a group name or a node index"
        raise self.error(key, f"expected {what}, got {_show(value)}")

    def tables(self, key: str) -> list[Reader]:
        """An array of tables (``[[key]]``) → readers named ``key[i]`` (0-based)."""
        value = self.get(key, [])
        if not isinstance(value, list):
            raise self.error(key, f"expected an array of tables ([[{key}]]), got {_show(value)}")
        return [self.child(f"{key}[{i}]", item) for i, item in enumerate(value)]

    def named_tables(self, key: str) -> dict[str, Reader]:
        """A table of tables (``[key.name]``) → {name: reader}."""
        value = self.get(key, {})
        if not isinstance(value, dict):
            raise self.error(key, f"expected a table of named tables, got {_show(value)}")
        return {name: self.child(f"{key}.{name}", item) for name, item in value.items()}

    def finish(self) -> None:
        """Raise for the first key that was never asked for."""
        for key in self.data:
            if key not in self.asked:
                raise self.error(key, f"unknown key; expected one of {sorted(set(self.asked))}")
