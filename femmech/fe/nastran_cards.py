"""What :func:`femmech.read_mesh` carries of a Nastran deck, card by card.

meshio 5 reads ``GRID`` coordinates and the element cards it knows, and drops every other
card without a word (``RBE2``, ``CONM2``, ``CELAS1``, properties, materials, large-field
element cards such as ``CBAR*``, ``INCLUDE``); it keeps both of two GRIDs or elements with
one number (the elements both count, the first GRID is left over). :func:`census` reads
the bulk data once, before meshio does, and

* refuses, naming the card and its line: a GRID or element number defined twice (element
  numbers are unique over all element cards, as in Nastran), a number that is no positive
  integer below 2**63, an element listing a GRID the deck does not define, ``INCLUDE``
  (the included file would not be read) and PS components other than the digits 1-6;
* counts the cards femmech does not carry into the model, by name (:attr:`Census.dropped`),
  and the GRIDs whose fields CD (displacement system) or PS (permanent single-point
  constraints) are set: femmech's DOFs are in the basic system, and the PS constraints
  become node sets ``PS<components>`` (:attr:`Census.ps_sets`), applied only by a
  :class:`~femmech.fe.constraints.Support` that names them.

:func:`not_carried` words the counts as one line for a
:class:`~femmech.errors.ModelWarning`.

Imports only femmech.errors and
fe.nastran_sets (the card reader).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from femmech.errors import FileFormatError
from femmech.fe.deck_lines import HiddenLines
from femmech.fe.nastran_sets import SET_CARDS, bulk_cards

LINE_CARDS = ("CBAR", "CBEAM", "CBUSH", "CBUSH1D", "CGAP")
"""Element cards with two GRIDs and an orientation (meshio keeps the two GRIDs only)."""
ELEMENT_CARDS = LINE_CARDS + (
    "CROD", "CTRIA3", "CTRIAR", "CTRIA6", "CTRAX6", "CTRIAX6", "CQUAD4", "CQUADR", "CSHEAR",
    "CQUAD8", "CQUAD9", "CTETRA", "CPENTA", "CHEXA", "CPYRAM", "CPYRA")
"""Element cards meshio reads (as written: upper case, small or free field). Those whose
cells femmech has no element for (pyramids, 15-node wedges) are refused by
:func:`femmech.fe.mesh_io.from_meshio`; ``CELAS1``, which meshio reads as a vertex, is
dropped (a vertex is no element) and counted here."""
GRID_CARDS = ("GRID", "GRID*")
HIDDEN_CARDS = ("CELAS1",)
"""Cards hidden from meshio (:class:`WithoutCards`): it reads ``CELAS1`` as a vertex cell
and fails on its second field ("Illegal cell type vertex"); counted as not carried."""
MAX_ID = 2**63 - 1
"""Largest GRID or element number read (int64; Nastran itself allows 8 digits)."""


@dataclass(frozen=True)
class Census:
    """The bulk data cards of a deck as far as femmech reads them.

    Attributes
    ----------
    dropped : dict[str, int]
        Card name (as written) → count, for the cards femmech does not carry.
    ps_sets : dict[str, ndarray of int64]
        ``"PS<components>"`` → GRID numbers whose PS field gives those components
        (sorted digits, e.g. ``"PS123"``).
    cd_grids : int
        Number of GRIDs with a displacement coordinate system CD ≠ 0.
    set_cards : tuple
        The ``SET1``, ``SET3`` and ``SPC1`` cards as :func:`~femmech.fe.nastran_sets.bulk_cards`
        gives them (for :func:`~femmech.fe.nastran_sets.add_sets`).
    hidden : bool
        Whether the deck has cards of :data:`HIDDEN_CARDS`.
    """

    dropped: dict = field(default_factory=dict)
    ps_sets: dict = field(default_factory=dict)
    cd_grids: int = 0
    set_cards: tuple = ()
    hidden: bool = False


def census(path) -> Census:
    """Read the bulk data of ``path`` (module docstring): the checks, then the counts.

    Raises
    ------
    FileFormatError
        Naming the card, the number and the line(s).
    """
    dropped = Counter()
    grids, grid_lines, elements, element_lines, refs, ref_owner = [], [], [], [], [], []
    ps, cd, set_cards = {}, 0, []
    for name, fields, line in bulk_cards(path, None, raw_names=True):
        label = f"{name} (line {line})"
        if name.upper() == "INCLUDE":
            raise FileFormatError(f"{label}: included files are not read (meshio ignores"
                                  " INCLUDE); write the bulk data into one file")
        if name in GRID_CARDS:
            grid = _id(_field(fields, 0), label, "ID")
            grids.append(grid)
            grid_lines.append(line)
            cd += _field(fields, 5) not in ("", "0")
            digits = _field(fields, 6)
            if digits not in ("", "0"):
                ps.setdefault(_components(digits, f"GRID {grid} (line {line})"),
                              []).append(grid)
        elif name in ELEMENT_CARDS:
            eid = _id(_field(fields, 0), label, "EID")
            elements.append(eid)
            element_lines.append((name, line))
            nodes = fields[2:4] if name in LINE_CARDS else fields[2:]
            for text in nodes:
                number = _node(text, f"{name} {eid} (line {line})")
                if number is not None:
                    refs.append(number)
                    ref_owner.append(len(elements) - 1)
        elif name.upper().rstrip("*") in SET_CARDS:
            set_cards.append((name.upper().rstrip("*"), fields, line))
        else:
            dropped[name] += 1
    grid_ids = np.array(grids, dtype=np.int64)
    _unique(grid_ids, lambda i: f"GRID {grids[i]}", lambda i: f"line {grid_lines[i]}")
    element_ids = np.array(elements, dtype=np.int64)
    _unique(element_ids, lambda i: f"element {elements[i]}",
            lambda i: "{} line {}".format(*element_lines[i]))
    refs = np.array(refs, dtype=np.int64)
    missing = np.flatnonzero(~np.isin(refs, grid_ids))
    if missing.size:
        k = ref_owner[missing[0]]
        card, line = element_lines[k]
        raise FileFormatError(f"{card} {elements[k]} (line {line}) lists GRID"
                              f" {refs[missing[0]]}, which the file does not define"
                              f" ({missing.size} such references)")
    return Census(dict(dropped), {f"PS{c}": np.unique(np.array(g, dtype=np.int64))
                                  for c, g in sorted(ps.items())}, cd, tuple(set_cards),
                  any(name in dropped for name in HIDDEN_CARDS))


def not_carried(found: Census) -> str | None:
    """One line on what the deck holds that the model will not have (None: nothing)."""
    parts = []
    if found.dropped:
        cards = sorted(found.dropped.items(), key=lambda kv: (-kv[1], kv[0]))
        listed = ", ".join(f"{name} x{n}" for name, n in cards[:20])
        more = f" and {len(cards) - 20} other card names" if len(cards) > 20 else ""
        parts.append(f"cards not carried into the model: {listed}{more} (femmech reads GRID,"
                     " the element cards, SET1, SET3 and SPC1; give masses (PointMass),"
                     " springs, rigid links (RigidLink), supports, properties and materials"
                     " in femmech)")
    if found.ps_sets:
        sets = ", ".join(f"{name} ({len(g)} GRIDs)" for name, g in found.ps_sets.items())
        parts.append(f"GRID permanent constraints (field PS) are not applied: they are the"
                     f" node sets {sets}; fix them with a Support on each (components 1-6"
                     " = ux, uy, uz, rx, ry, rz)")
    if found.cd_grids:
        parts.append(f"{found.cd_grids} GRIDs give a displacement coordinate system (field"
                     " CD), which is not carried: femmech's DOFs, supports and springs are"
                     " in the basic system")
    return "; ".join(parts) or None


def _field(fields: list[str], k: int) -> str:
    return fields[k] if k < len(fields) else ""


def _id(text: str, label: str, what: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise FileFormatError(f"{label}: {what} must be an integer, got {text[:20]!r}") from None
    if not 0 < value <= MAX_ID:
        raise FileFormatError(f"{label}: {what} {text[:30]} is out of range (a positive"
                              " integer below 2**63)")
    return value


def _node(text: str, label: str) -> int | None:
    """A GRID number of an element's node field, or None for a blank or non-integer
    field (meshio refuses the latter itself)."""
    try:
        value = int(text)
    except ValueError:
        return None
    if not 0 < value <= MAX_ID:
        raise FileFormatError(f"{label}: GRID {text[:30]} is out of range (a positive"
                              " integer below 2**63)")
    return value


def _components(digits: str, label: str) -> str:
    if not digits.isdigit() or not set(digits) <= set("123456"):
        raise FileFormatError(f"{label}: PS {digits[:20]!r}; expected the digits 1-6 of the"
                              " constrained components")
    return "".join(sorted(set(digits)))


def _unique(ids: np.ndarray, what, where) -> None:
    """FileFormatError naming the first number of ``ids`` given twice and both places."""
    if ids.size < 2:
        return
    order = np.argsort(ids, kind="stable")
    twice = np.flatnonzero(ids[order][1:] == ids[order][:-1])
    if twice.size:
        first, second = int(order[twice[0]]), int(order[twice[0] + 1])
        raise FileFormatError(f"{what(first)} is defined twice ({where(first)} and"
                              f" {where(second)}; {twice.size} numbers defined more than"
                              " once): give each its own number")


class WithoutCards(HiddenLines):
    """The lines of an open deck without the bulk data cards :data:`HIDDEN_CARDS` (and
    their continuation lines), for meshio's Nastran reader (which reads by ``readline``)."""

    def __init__(self, f):
        super().__init__(f)
        self.in_bulk, self.skipping = False, False

    def hides(self, line: str) -> bool:
        text = line.rstrip("\r\n")
        if not self.in_bulk:
            self.in_bulk = text.strip().upper().startswith("BEGIN BULK")
            return False
        head = text.split(",", 1)[0] if "," in text else text[:8]
        if head[:1] not in ("+", "*", "$") and head.strip():  # a card's first line
            self.skipping = head.strip() in HIDDEN_CARDS
        return self.skipping
