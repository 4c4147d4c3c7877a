"""Sets of Nastran bulk data (``.bdf``, ``.fem``, ``.nas``): ``SET1``, ``SET3`` and ``SPC1``.

meshio 5 reads GRID points and elements with their property IDs (which
:mod:`femmech.fe.mesh_sets` turns into cell sets ``PID<n>``) but no set card, and reads
GRID coordinates as if in the basic system. :func:`add_sets` reads the set cards of the
bulk data itself and adds them to meshio's mesh by the GRID and element numbers meshio
kept (``points_id``, ``cells_id``):

* ``SET1 SID G1 G2 ... (THRU)`` → node set ``SET<SID>`` if every number is a GRID, else
  a cell set if every number is an element (a number that is both is read as a GRID);
* ``SET3 SID DES ID1 ...`` with ``DES`` = ``GRID``/``POINT`` → node set, ``ELEM`` → cell
  set, ``PROP`` → cell set of the elements of those properties; named ``SET<SID>``;
* ``SPC1 SID C G1 ... (THRU)`` → node set ``SPC<SID>`` (all SPC1 of one SID; the
  components ``C`` are not kept: give them in the :class:`~femmech.fe.constraints.Support`).

Cards in free (commas), small-field (8 columns) and large-field (``*``, 16 columns) format
with continuation lines are read. A GRID in a local coordinate system (``CP`` ≠ 0) is
refused, since meshio would place it wrongly. Every problem is a
:class:`~femmech.errors.FileFormatError` naming the card and its line.

Imports only femmech.errors and fe.mesh_sets
(limits).
"""

from __future__ import annotations

import numpy as np

from femmech.errors import FileFormatError
from femmech.fe.mesh_sets import MAX_SET_MEMBERS, MAX_SETS

SET_CARDS = ("SET1", "SET3", "SPC1")


def add_sets(path, raw, grid_sets=None, cards=None) -> None:
    """Add the ``SET1``, ``SET3`` and ``SPC1`` sets of the bulk data in ``path`` to the
    meshio mesh ``raw`` (as ``point_sets`` and per-block ``cell_sets``), in place, and
    the node sets ``grid_sets`` {name: GRID numbers} (the GRIDs' PS constraints,
    :attr:`femmech.fe.nastran_cards.Census.ps_sets`). ``cards``: the set cards as
    :func:`bulk_cards` gives them, if already read (else ``path`` is read)."""
    cp = raw.point_data.get("nastran:ref")
    if cp is not None and np.any(np.asarray(cp) != 0):
        cp = np.asarray(cp)
        k = int(np.flatnonzero(cp != 0)[0])
        # meshio lists CP only for GRIDs that give one: name the GRID when all do
        grid = f"GRID {raw.points_id[k]} is" if len(cp) == len(raw.points) else "GRIDs are"
        raise FileFormatError(f"{grid} given in coordinate system CP = {cp[k]}; meshio reads"
                              " coordinates as basic: write the GRIDs in the basic system"
                              " (CP blank or 0)")
    grids = _Lookup(np.asarray(raw.points_id, dtype=np.int64), "GRID")
    sizes = [len(b.data) for b in raw.cells]
    ids = [np.asarray(i, dtype=np.int64) for i in getattr(raw, "cells_id", [])]
    elements = _Lookup(np.concatenate(ids) if ids else np.empty(0, dtype=np.int64), "element")
    pids = raw.cell_data.get("nastran:ref")
    if pids is not None and [len(p) for p in pids] != sizes:
        raise FileFormatError("some elements have no property ID (PID field blank); give"
                              " every element its PID")
    nodes, cells, total = {}, {}, [0]
    for name, numbers in (grid_sets or {}).items():
        nodes[name] = [grids.indices(numbers, f"GRID field PS ({name})")]
    for card, fields, line in bulk_cards(path, SET_CARDS) if cards is None else cards:
        label = f"{card} (line {line})"
        if len(nodes) + len(cells) > MAX_SETS:
            raise FileFormatError(f"{label}: more than {MAX_SETS} sets (limit MAX_SETS)")
        sid, items = _integer(fields[0] if fields else "", label, "SID"), fields[1:]
        if card == "SPC1":
            numbers = _numbers(items[1:], label, grids.size, total)
            nodes.setdefault(f"SPC{sid}", []).append(grids.indices(numbers, label))
            continue
        des = items[0].strip().upper() if card == "SET3" and items else "GRID"
        numbers = _numbers(items[1:] if card == "SET3" else _skip_skin(items), label,
                           max(grids.size, elements.size), total)
        if card == "SET1" and not grids.has_all(numbers) and elements.has_all(numbers):
            des = "ELEM"
        name = f"SET{sid}"
        if des in ("GRID", "POINT"):
            nodes.setdefault(name, []).append(grids.indices(numbers, label))
        elif des == "ELEM":
            cells.setdefault(name, []).append(elements.indices(numbers, label))
        elif des == "PROP":
            cells.setdefault(name, []).append(_elements_of(pids, numbers, label))
        else:
            raise FileFormatError(f"{label}: DES {des!r}; expected GRID, POINT, ELEM or PROP")
    raw.point_sets = {**raw.point_sets, **{n: np.unique(np.concatenate(v))
                                            for n, v in nodes.items()}}
    start = np.concatenate([[0], np.cumsum(sizes)])
    for name, parts in cells.items():
        members = np.unique(np.concatenate(parts))
        raw.cell_sets[name] = [members[(members >= start[k]) & (members < start[k + 1])]
                               - start[k] for k in range(len(sizes))]


def bulk_cards(path, wanted=SET_CARDS, raw_names: bool = False):
    """``(card name, data fields, line number)`` of each bulk data card named in ``wanted``
    (None: every card), continuation lines joined; fields are stripped strings, blank ones
    ``""``. Names are upper case without a large-field ``*``, or with ``raw_names`` as
    written (as meshio reads them: ``CBAR*`` and ``cbar`` are no ``CBAR`` to meshio)."""
    card, fields, first, in_bulk = None, [], 0, False
    with open(path, encoding="utf-8", errors="replace") as f:
        for lineno, line in enumerate(f, 1):
            line = line.rstrip("\r\n")
            if not in_bulk:
                in_bulk = line.strip().upper().startswith("BEGIN BULK")
                continue
            if line.startswith("$") or not line.strip():
                continue
            if line.upper().startswith("ENDDATA"):
                break
            name, data = split_line(line, raw_names)
            if name is None:  # a continuation line
                if card is not None:
                    fields += data
                continue
            if card is not None:
                yield card, fields, first
            keep = wanted is None or name in wanted
            card, fields, first = (name, data, lineno) if keep else (None, [], 0)
    if card is not None:
        yield card, fields, first


def split_line(line: str, raw: bool = False) -> tuple[str | None, list[str]]:
    """Card name (None for a continuation line; as written with ``raw``, else upper case
    without a large-field ``*``) and the data fields 2-9 of one line."""
    if "," in line:
        parts = line.split(",")
        head = parts[0]
        data = [d.strip() for d in (parts[1:9] if len(parts) >= 10 else parts[1:])]
    else:
        head = line[:8]
        large = head[:1] == "*" or head.rstrip().endswith("*")
        data = [line[a:b].strip() for a, b in (_LARGE if large else _SMALL)]
    name = head.strip()
    if head[:1] in ("+", "*") or not name:  # a continuation line
        return None, data
    return (name if raw else name.rstrip("*").upper()), data


_SMALL = tuple((8 + 8 * i, 16 + 8 * i) for i in range(8))
_LARGE = tuple((8 + 16 * i, 24 + 16 * i) for i in range(4))


def _skip_skin(items: list[str]) -> list[str]:
    return items[1:] if items and items[0].upper() == "SKIN" else items


def _integer(text: str, label: str, what: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise FileFormatError(f"{label}: {what} must be an integer, got {text[:20]!r}") from None
    if not -2**63 <= value < 2**63:  # numpy would raise OverflowError, naming nothing
        raise FileFormatError(f"{label}: {what} {text[:30]} is out of range (an integer below"
                              " 2**63)")
    return value


def _numbers(items: list[str], label: str, most: int, total: list) -> np.ndarray:
    """Integers of a list with ``a THRU b`` ranges (at most ``most`` numbers in a range);
    ``total[0]`` counts the numbers of all cards (at most :data:`MAX_SET_MEMBERS`)."""
    items = [i for i in items if i]
    out, k = [], 0
    while k < len(items):
        if k + 2 < len(items) and items[k + 1].upper() == "THRU":
            a, b = _integer(items[k], label, "ID"), _integer(items[k + 2], label, "ID")
            if not 0 <= b - a < max(most, 1):
                raise FileFormatError(f"{label}: range {a} THRU {b} is backwards or longer than"
                                      f" the {most} points or elements of the file")
            total[0] += b - a + 1
            if total[0] <= MAX_SET_MEMBERS:
                out.append(np.arange(a, b + 1, dtype=np.int64))
            k += 3
        else:
            total[0] += 1
            out.append(np.array([_integer(items[k], label, "ID")], dtype=np.int64))
            k += 1
        if total[0] > MAX_SET_MEMBERS:
            raise FileFormatError(f"{label}: the set cards list more than {MAX_SET_MEMBERS}"
                                  " numbers in all (limit MAX_SET_MEMBERS)")
    return np.concatenate(out) if out else np.empty(0, dtype=np.int64)


class _Lookup:
    """GRID or element numbers → 0-based indices in meshio's order."""

    def __init__(self, ids: np.ndarray, what: str):
        self.order = np.argsort(ids, kind="stable")
        self.sorted, self.what, self.size = ids[self.order], what, len(ids)

    def _positions(self, numbers: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if not self.size:
            return np.zeros(len(numbers), dtype=np.int64), np.zeros(len(numbers), dtype=bool)
        pos = np.minimum(np.searchsorted(self.sorted, numbers), self.size - 1)
        return pos, self.sorted[pos] == numbers

    def has_all(self, numbers: np.ndarray) -> bool:
        return bool(self._positions(numbers)[1].all())

    def indices(self, numbers: np.ndarray, label: str) -> np.ndarray:
        pos, found = self._positions(numbers)
        if not found.all():
            raise FileFormatError(f"{label} lists {self.what} {numbers[~found][0]}, which the"
                                  f" file does not define ({np.count_nonzero(~found)} such"
                                  " numbers)")
        return self.order[pos]


def _elements_of(pids, numbers: np.ndarray, label: str) -> np.ndarray:
    """Indices (over all blocks) of the elements whose property ID is in ``numbers``."""
    if pids is None:
        raise FileFormatError(f"{label}: SET3 of properties, but no element has a property ID")
    all_pids = np.concatenate([np.asarray(p) for p in pids])
    missing = numbers[~np.isin(numbers, all_pids)]
    if missing.size:
        raise FileFormatError(f"{label} lists property {missing[0]}, which no element has")
    return np.flatnonzero(np.isin(all_pids, numbers))
