"""Node and element sets of an Abaqus or CalculiX input file (``.inp``), as the deck means them.

meshio 5.3 reads the nodes and elements of a deck, but its set reader loses or garbles
common forms without a word: a ``*NSET`` listing other sets comes back empty, an
``*ELSET`` listing set names keeps only the first name of a line and loses the cell
blocks, sets defined twice (which Abaqus joins) keep the last definition, element numbers
that do not exist are dropped, and a second ``*NODE`` block replaces the first. So
:func:`scan_deck` reads the deck's keywords itself, before meshio (bounded, so that a
``GENERATE`` range of a billion numbers is refused rather than allocated), and
:func:`deck_sets` maps the sets onto meshio's points and cell blocks afterwards; meshio
reads the deck through :class:`WithoutSets`, which hides the set blocks it would misread.

Read: ``*NODE`` (with ``NSET=``), ``*ELEMENT`` (``ELSET=``), ``*NSET`` and ``*ELSET``
with numbers, set names (case-blind, as in Abaqus), ``GENERATE`` (first, last[, step]) and
``*NSET, ELSET=`` (the nodes of an element set); repeated definitions add up. A model of one
``*PART`` with one ``*INSTANCE`` that is neither moved nor rotated (what Abaqus/CAE writes)
is read with its assembly sets; a part set whose name an assembly set also uses is named
``<instance>.<name>``, as Abaqus names it from the assembly. Refused with a
:class:`~femmech.errors.FileFormatError` naming the line, because meshio would read wrong
coordinates or elements: a second ``*NODE`` block, ``*INCLUDE``, node and element
generation (``*NGEN``, ``*NFILL``, ``*NCOPY``, ``*NMAP``, ``*ELGEN``, ``*ELCOPY``), local
node coordinate systems (``*SYSTEM``, ``*NODE, SYSTEM=``), several instances and moved
instances.

Imports only femmech.errors, fe.mesh and
fe.mesh_sets (limits).
"""

from __future__ import annotations

from array import array
from dataclasses import dataclass, field

import numpy as np

from femmech.errors import FileFormatError, did_you_mean
from femmech.fe.deck_lines import HiddenLines
from femmech.fe.mesh import MAX_CELLS, MAX_NODES
from femmech.fe.mesh_sets import MAX_SET_MEMBERS, MAX_SETS

REFUSED = {"INCLUDE": "the included file's elements and sets would be lost or misnumbered;"
                      " paste it into the deck",
           "SYSTEM": "meshio ignores local coordinate systems; write global coordinates",
           **dict.fromkeys(("NGEN", "NFILL", "NCOPY", "NMAP", "ELGEN", "ELCOPY"),
                           "meshio does not generate nodes or elements; write them out")}
"""Keywords that make meshio read other nodes or elements than the deck defines."""


@dataclass
class DeckSet:
    """One node or element set: numbers, ``GENERATE`` ranges, names of other sets (and for
    a node set, element sets whose nodes it holds), in the scope it was defined in."""

    name: str
    line: int
    numbers: array = field(default_factory=lambda: array("q"))
    ranges: list = field(default_factory=list)
    names: list = field(default_factory=list)
    element_sets: list = field(default_factory=list)


@dataclass
class Deck:
    """What :func:`scan_deck` found: node numbers in file order, per ``*ELEMENT`` block its
    meshio cell type and element numbers, and the sets by (scope, kind, folded name)."""

    node_ids: array = field(default_factory=lambda: array("q"))
    blocks: list = field(default_factory=list)
    sets: dict = field(default_factory=dict)
    instances: list = field(default_factory=list)
    n_listed: int = 0


def scan_deck(path) -> Deck:
    """Keywords, node and element numbers and set definitions of an ``.inp`` file.

    Raises
    ------
    FileFormatError
        Naming the line: a refused keyword (module docstring), a second ``*NODE`` block, a
        set keyword without its name, a number that is not an integer, a ``GENERATE`` line
        that is not ``first, last[, step]``, an element type meshio does not read, more
        than :data:`MAX_SET_MEMBERS` listed numbers.
    """
    reader = _Reader()
    with open(path, encoding="utf-8", errors="replace") as f:
        for lineno, line in enumerate(f, 1):
            if line.startswith("**") or not line.strip():
                continue
            try:
                if line.startswith("*"):  # as meshio tells keyword lines
                    reader.keyword(line.strip(), lineno)
                elif reader.data is not None:
                    reader.data(line.strip(), lineno)
            except FileFormatError as exc:
                raise FileFormatError(f"line {lineno}: {exc}") from None
    reader.close_block()
    return reader.deck


def _parameters(line: str) -> tuple[str, dict]:
    """Keyword and parameters (upper-case keys) of a keyword line:
    ``*Nset, nset=Tip, generate`` → ``("NSET", {"NSET": "Tip", "GENERATE": None})``."""
    words = line.lstrip("*").split(",")
    params = {}
    for word in words[1:]:
        key, eq, value = word.partition("=")
        params[key.strip().upper()] = value.strip() if eq else None
    return " ".join(words[0].split()).upper(), params


class _Reader:
    """State of :func:`scan_deck`: the current scope and the handler of data lines."""

    def __init__(self):
        self.deck = Deck()
        self.scope, self.data, self.block = "model", None, None
        self.in_instance, self.seen_nodes, self.n_elements = False, False, 0

    def keyword(self, line: str, lineno: int) -> None:
        self.close_block()
        name, params = _parameters(line)
        self.data = None
        if name in REFUSED:
            raise FileFormatError(f"*{name} is not supported: {REFUSED[name]}")
        if name == "PART":
            self.scope = "part"
        elif name in ("END PART", "END ASSEMBLY"):
            self.scope = "model"
        elif name == "ASSEMBLY":
            self.scope = "assembly"
        elif name == "INSTANCE":
            self._instance(params)
        elif name == "END INSTANCE":
            self.in_instance = False
        elif name == "NODE":
            self._node(params, lineno)
        elif name == "ELEMENT":
            self._element(params, lineno)
        elif name in ("NSET", "ELSET"):
            self._set(name, params, lineno)

    def _instance(self, params: dict) -> None:
        self.deck.instances.append(params.get("NAME") or "instance")
        if len(self.deck.instances) > 1:
            raise FileFormatError("a second *INSTANCE: meshio reads each part's nodes once;"
                                  " write one instance (or a flat deck)")
        self.in_instance, self.placement = True, 0

        def placement(text: str, lineno: int) -> None:
            values = [float(v) for v in text.split(",") if v.strip()]
            self.placement += 1
            moved = any(values) if self.placement == 1 else (len(values) >= 7 and values[6])
            if moved:
                raise FileFormatError(f"instance {self.deck.instances[-1]!r} is moved or"
                                      " rotated; meshio reads the part's coordinates as they"
                                      " are: place the part in the part itself")
        self.data = placement

    def _set_scope(self) -> str:
        return "part" if self.in_instance else self.scope

    def _node(self, params: dict, lineno: int) -> None:
        if self.seen_nodes:
            raise FileFormatError("a second *NODE block: meshio 5 keeps only the last one;"
                                  " put all nodes into one *NODE block")
        if (params.get("SYSTEM") or "R").upper() != "R":
            raise FileFormatError(f"*NODE, SYSTEM={params['SYSTEM']}: {REFUSED['SYSTEM']}")
        self.seen_nodes = True
        ids = self.deck.node_ids
        target = self._definition("NSET", params["NSET"], lineno) if params.get("NSET") else None

        def node(text: str, lineno: int) -> None:
            number = _integer(text.split(",", 1)[0])
            ids.append(number)
            if len(ids) > MAX_NODES:
                raise FileFormatError(f"more than {MAX_NODES} nodes (limit MAX_NODES)")
            if target is not None:
                self._count(1)
                target.numbers.append(number)
        self.data = node

    def _element(self, params: dict, lineno: int) -> None:
        from meshio._common import num_nodes_per_cell
        from meshio.abaqus._abaqus import abaqus_to_meshio_type

        kind = abaqus_to_meshio_type.get((params.get("TYPE") or "").upper())
        if kind not in num_nodes_per_cell:
            raise FileFormatError(f"*ELEMENT, TYPE={params.get('TYPE')}: an element type"
                                  " meshio 5 does not read")
        stride = num_nodes_per_cell[kind] + 1
        ids = array("q")
        target = self._definition("ELSET", params["ELSET"], lineno) if params.get("ELSET") \
            else None
        self.block = (kind, ids, target)
        position = [0]

        def element(text: str, lineno: int) -> None:
            for token in text.split(","):
                if token.strip():
                    if position[0] % stride == 0:
                        ids.append(_integer(token))
                        self.n_elements += 1
                        if self.n_elements > MAX_CELLS:
                            raise FileFormatError(f"more than {MAX_CELLS} elements (limit"
                                                  " MAX_CELLS)")
                    position[0] += 1
        self.data = element

    def close_block(self) -> None:
        """Add the element block being read to the deck (and to its ``ELSET=``)."""
        if self.block is not None:
            kind, ids, target = self.block
            self.deck.blocks.append((kind, ids))
            if target is not None:
                self._count(len(ids))
                target.numbers.extend(ids)
            self.block = None

    def _definition(self, kind: str, name: str | None, lineno: int) -> DeckSet:
        if not name:
            raise FileFormatError(f"*{kind} without the set's name ({kind}=...)")
        name = name.strip().strip('"')
        key = (self._set_scope(), kind, name.casefold())
        if key not in self.deck.sets and len(self.deck.sets) >= MAX_SETS:
            raise FileFormatError(f"more than {MAX_SETS} sets (limit MAX_SETS)")
        return self.deck.sets.setdefault(key, DeckSet(name, lineno))

    def _set(self, kind: str, params: dict, lineno: int) -> None:
        target = self._definition(kind, params.get(kind), lineno)
        if kind == "NSET" and params.get("ELSET"):
            target.element_sets.append(params["ELSET"].strip().strip('"'))
        generate = "GENERATE" in params

        def members(text: str, lineno: int) -> None:
            tokens = [t.strip() for t in text.split(",") if t.strip()]
            if generate:
                if len(tokens) not in (2, 3):
                    raise FileFormatError(f"*{kind}, GENERATE: expected 'first, last[, step]',"
                                          f" got {text[:60]!r}")
                target.ranges.append(tuple(_integer(t) for t in tokens) + (1,) *
                                     (3 - len(tokens)))
                return
            self._count(len(tokens))
            for token in tokens:
                if token[0].isdigit() or token[0] in "+-.":  # names start with a letter
                    target.numbers.append(_integer(token))
                else:
                    target.names.append(token.strip('"'))
        self.data = members

    def _count(self, n: int) -> None:
        self.deck.n_listed += n
        if self.deck.n_listed > MAX_SET_MEMBERS:
            raise FileFormatError(f"the sets list more than {MAX_SET_MEMBERS} numbers (limit"
                                  " MAX_SET_MEMBERS)")


def _integer(token: str) -> int:
    token = token.strip()
    try:
        value = int(token)
    except ValueError:
        raise FileFormatError(f"expected an integer, got {token[:40]!r}") from None
    if not -2**63 <= value < 2**63:  # array('q') would raise OverflowError, naming nothing
        raise FileFormatError(f"number {token[:30]} is out of range (an integer below 2**63)")
    return value


def check_numbers(deck: Deck) -> None:
    """No node or element number defined twice (FileFormatError naming it); meshio would
    keep the last definition and leave the first node unused or misnumber elements."""
    _Numbers(np.frombuffer(deck.node_ids, dtype=np.int64), "node")
    if deck.blocks:
        _Numbers(np.concatenate([np.frombuffer(ids, dtype=np.int64) for _, ids in deck.blocks]),
                 "element")


def check_against(deck: Deck, raw) -> None:
    """The deck's nodes and element blocks are those meshio read (FileFormatError if not)."""
    if len(deck.node_ids) != len(raw.points):
        raise FileFormatError(f"meshio read {len(raw.points)} nodes, the deck's *NODE block"
                              f" has {len(deck.node_ids)}")
    found = [(b.type, len(b.data)) for b in raw.cells]
    expected = [(kind, len(ids)) for kind, ids in deck.blocks]
    if found != expected:
        raise FileFormatError(f"meshio read the element blocks {found}, the deck defines"
                              f" {expected}")
    if len(deck.node_ids) > MAX_NODES or sum(n for _, n in found) > MAX_CELLS:
        raise FileFormatError("too many nodes or elements")  # read_mesh checks this first


def deck_sets(deck: Deck, raw) -> tuple[dict, dict]:
    """The deck's sets as meshio lays them out: ``point_sets`` {name: point indices} and
    ``cell_sets`` {name: [indices into each cell block]}.

    Raises
    ------
    FileFormatError
        Naming the set: a node or element number the deck does not define, a name that is
        no set of the deck (with a "did you mean"), sets that list each other in a circle,
        a bad ``GENERATE`` range, node or element numbers defined twice.
    """
    check_against(deck, raw)
    sizes = [len(ids) for _, ids in deck.blocks]
    element_ids = np.concatenate([np.frombuffer(ids, dtype=np.int64) for _, ids in deck.blocks]
                                 ) if deck.blocks else np.empty(0, dtype=np.int64)
    resolver = _Resolver(deck, _Numbers(np.frombuffer(deck.node_ids, dtype=np.int64), "node"),
                         _Numbers(element_ids, "element"), raw)
    block_of = np.repeat(np.arange(len(sizes)), sizes)
    start = np.concatenate([[0], np.cumsum(sizes)])
    point_sets, cell_sets = {}, {}
    for key, name in _final_names(deck).items():
        value = resolver.resolved(key)
        if key[1] == "NSET":
            point_sets[name] = value
        else:
            cell_sets[name] = [value[block_of[value] == k] - start[k] for k in range(len(sizes))]
    return point_sets, cell_sets


def _final_names(deck: Deck) -> dict:
    """Key → name; a part set that an assembly set's name also has → ``instance.name``."""
    out = {}
    for key, s in deck.sets.items():
        scope, kind, folded = key
        if scope == "part" and ("assembly", kind, folded) in deck.sets:
            instance = deck.instances[0] if deck.instances else "part"
            out[key] = f"{instance}.{s.name}"
        else:
            out[key] = s.name
    return out


class _Numbers:
    """Node or element numbers of the deck → 0-based indices (in file order)."""

    def __init__(self, ids: np.ndarray, what: str):
        self.order = np.argsort(ids, kind="stable")
        self.sorted = ids[self.order]
        self.what = what
        twice = np.flatnonzero(self.sorted[1:] == self.sorted[:-1])
        if twice.size:
            raise FileFormatError(f"{what} {self.sorted[twice[0]]} is defined twice")

    def indices(self, numbers: np.ndarray, label: str) -> np.ndarray:
        pos = np.minimum(np.searchsorted(self.sorted, numbers), max(len(self.sorted) - 1, 0))
        missing = numbers[self.sorted[pos] != numbers] if len(self.sorted) else numbers
        if missing.size:
            raise FileFormatError(f"{label} lists {self.what} {missing[0]}, which the deck does"
                                  f" not define ({missing.size} such numbers)")
        return self.order[pos]

    def count(self, first: int, last: int, step: int, label: str) -> int:
        """Numbers of a ``GENERATE`` range (checked, not expanded)."""
        if step <= 0 or last < first:
            raise FileFormatError(f"{label}: GENERATE range {first}, {last}, {step} is empty or"
                                  " backwards (expected first <= last and step > 0)")
        count = (last - first) // step + 1
        if count > len(self.sorted):
            raise FileFormatError(f"{label}: GENERATE range {first}, {last}, {step} spans"
                                  f" {count} numbers, more than the deck's {len(self.sorted)}"
                                  f" {self.what}s")
        return count


class _Resolver:
    """Members (node indices, or element indices over all blocks) of the deck's sets, with
    the sets they name resolved first (iteratively: no recursion limit, circles refused)."""

    def __init__(self, deck: Deck, nodes: _Numbers, elements: _Numbers, raw):
        self.deck, self.raw, self.done = deck, raw, {}
        self.numbers = {"NSET": nodes, "ELSET": elements}
        self.total = 0

    def label(self, key) -> str:
        kind = "node set" if key[1] == "NSET" else "element set"
        return f"{kind} {self.deck.sets[key].name!r} (line {self.deck.sets[key].line})"

    def refs(self, key) -> list:
        s = self.deck.sets[key]
        out = [self.find(key, name, key[1]) for name in s.names]
        return out + [self.find(key, name, "ELSET") for name in s.element_sets]

    def find(self, key, name: str, kind: str):
        """Key of the set ``name`` that set ``key`` lists: same scope, else qualified
        ``instance.name`` (a part set), else any scope."""
        folded = name.casefold()
        candidates = [(key[0], kind, folded)]
        if "." in folded:
            candidates.append(("part", kind, folded.split(".", 1)[1]))
        candidates += [(scope, kind, folded) for scope in ("model", "part", "assembly")]
        for candidate in candidates:
            if candidate in self.deck.sets:
                return candidate
        names = [s.name for k, s in self.deck.sets.items() if k[1] == kind]
        what = "node set" if kind == "NSET" else "element set"
        raise FileFormatError(f"{self.label(key)} lists {name!r}, which is no {what} of the"
                              f" deck{did_you_mean(name, names)}")

    def resolved(self, key) -> np.ndarray:
        stack, expanded = [key], set()
        while stack:
            k = stack[-1]
            if k in self.done:
                stack.pop()
                continue
            waiting = [d for d in self.refs(k) if d not in self.done]
            if k not in expanded:
                expanded.add(k)
                for d in waiting:
                    if d in expanded:
                        raise FileFormatError(f"{self.label(k)} and {self.label(d)} list each"
                                              " other (a circle of set names)")
                    stack.append(d)
                continue
            self.done[k] = self._members(k)
            stack.pop()
        return self.done[key]

    def _members(self, key) -> np.ndarray:
        s, kind = self.deck.sets[key], key[1]
        label, numbers = self.label(key), self.numbers[kind]
        listed = [np.frombuffer(s.numbers, dtype=np.int64)]
        for first, last, step in s.ranges:
            self._add(numbers.count(first, last, step, label), label)
            listed.append(np.arange(first, last + 1, step, dtype=np.int64))
        parts = [numbers.indices(np.concatenate(listed), label)]
        parts += [self.done[self.find(key, n, kind)] for n in s.names]
        for name in s.element_sets:  # *NSET, ELSET=: the nodes of those elements
            parts.append(self._nodes_of_elements(self.done[self.find(key, name, "ELSET")]))
        members = np.unique(np.concatenate(parts))
        self._add(members.size, label)
        return members

    def _add(self, n: int, label: str) -> None:
        self.total += n
        if self.total > MAX_SET_MEMBERS:
            raise FileFormatError(f"{label}: the sets hold more than {MAX_SET_MEMBERS} members"
                                  " in all (limit MAX_SET_MEMBERS)")

    def _nodes_of_elements(self, elements: np.ndarray) -> np.ndarray:
        sizes = [len(b.data) for b in self.raw.cells]
        start = np.concatenate([[0], np.cumsum(sizes)])
        parts = [np.asarray(b.data)[elements[(elements >= start[k]) & (elements < start[k + 1])]
                                    - start[k]].ravel() for k, b in enumerate(self.raw.cells)]
        return np.concatenate(parts) if parts else np.empty(0, dtype=np.int64)


class WithoutSets(HiddenLines):
    """The lines of an open deck without its ``*NSET`` and ``*ELSET`` blocks, for meshio's
    Abaqus reader (which reads by ``readline`` only): sets are read by :func:`deck_sets`,
    and meshio would stop at forms it does not know (``GENERATE`` with two numbers)."""

    def __init__(self, f):
        super().__init__(f)
        self.skipping = False

    def hides(self, line: str) -> bool:
        if line.startswith("*") and not line.startswith("**"):
            self.skipping = _parameters(line.strip())[0] in ("NSET", "ELSET")
        return self.skipping
