"""Mesh input through meshio (Gmsh .msh, Abaqus .inp, Nastran .bdf, VTU, MED, ... anything
meshio reads), with the file's node and element sets as :class:`Mesh` node and cell sets.

Where the groups of each format come from is in :mod:`femmech.fe.mesh_sets`; Abaqus decks
and Nastran bulk data have their sets read by femmech itself, because meshio 5 loses or
garbles them (:mod:`femmech.fe.abaqus_sets`, :mod:`femmech.fe.nastran_sets`). A mesh file
is untrusted input: its size, node and cell counts and every set are checked, and every
problem is one :class:`~femmech.errors.FileFormatError` line naming the file and the item.

What a file holds that the model will not have is said, not dropped silently: one
:class:`~femmech.errors.ModelWarning` per file names elements repeated on the same nodes
and, for Nastran, the cards femmech does not carry (:mod:`femmech.fe.nastran_cards`).

Uses fe.mesh, fe.mesh_sets, fe.abaqus_sets,
fe.nastran_sets, fe.nastran_cards (and meshio).
"""

from __future__ import annotations

import contextlib
import io
import warnings
from pathlib import Path

import numpy as np

from femmech.errors import FileFormatError, ModelWarning
from femmech.fe import abaqus_sets, nastran_cards, nastran_sets
from femmech.fe.checks import MAX_LISTED  # repeated elements named in the warning
from femmech.fe.mesh import (
    MAX_CELLS,
    MAX_NODES,
    NODES_PER_CELL,
    Mesh,
    check_coordinates,
    repeated_cells,
)
from femmech.fe.mesh_sets import collect_sets

MAX_MESH_FILE_BYTES = 4 * 2**30
"""Largest mesh file read, bytes (an ASCII Gmsh file of a million nodes and five million
tetrahedra has about 400 MB); a mesh file is untrusted input, refused before reading."""
ABAQUS_SUFFIXES = (".inp",)
NASTRAN_SUFFIXES = (".bdf", ".fem", ".nas")
"""File name endings meshio reads as Abaqus and as Nastran (``meshio.extension_to_filetypes``)."""


def from_meshio(mesh, repeats: str = "drop") -> Mesh:
    """Convert a ``meshio.Mesh``: cell blocks of one type are merged (in block order), and
    the groups of every form meshio returns (:func:`femmech.fe.mesh_sets.collect_sets`)
    become :attr:`Mesh.node_sets` and :attr:`Mesh.cell_sets`; vertex cells are not kept
    (a set of vertex cells, a Gmsh physical point, becomes a node set).

    Cells on the nodes of an earlier cell of their type (:func:`femmech.fe.mesh.repeated_cells`)
    are named in a :class:`~femmech.errors.ModelWarning` and, with ``repeats="drop"``,
    dropped: the first is kept, in the sets of all its copies (a Gmsh 2.2 file writes an
    element once per physical group it is in; a second element on the same nodes doubles
    the stiffness and mass there). ``repeats="keep"`` keeps them, as Nastran and Abaqus do
    with two elements of a deck on the same nodes (read_mesh keeps them for those decks).

    Raises
    ------
    FileFormatError
        An unsupported cell type, or a set that is not valid (naming it).
    """
    converted, note = _converted(mesh, repeats)
    if note:
        warnings.warn(f"read_mesh: {note}", ModelWarning, stacklevel=2)
    return converted


def _converted(mesh, repeats: str) -> tuple[Mesh, str | None]:
    """:func:`from_meshio`'s mesh and its warning about repeated cells (None: none)."""
    if repeats not in ("drop", "keep"):
        raise ValueError(f"repeats must be 'drop' or 'keep', got {repeats!r}")
    offsets, cells, ids = [], {}, {}
    block_ids = getattr(mesh, "cells_id", None)
    for k, block in enumerate(mesh.cells):
        if block.type not in NODES_PER_CELL:
            raise FileFormatError(f"unsupported cell type {block.type!r} in the mesh file"
                                  f" (femmech reads {sorted(NODES_PER_CELL)})")
        cells.setdefault(block.type, [])
        offsets.append(sum(len(c) for c in cells[block.type]))
        cells[block.type].append(np.asarray(block.data))
        if block_ids is not None and len(block_ids) == len(mesh.cells):
            ids.setdefault(block.type, []).append(np.asarray(block_ids[k]))
    merged = {kind: np.concatenate(parts) for kind, parts in cells.items()}
    node_sets, raw_cell_sets = collect_sets(mesh)
    cell_sets = {}
    for name, per_block in raw_cell_sets.items():
        by_type = {}
        for block, offset, idx in zip(mesh.cells, offsets, per_block, strict=True):
            if idx is not None and len(idx) and block.type != "vertex":
                by_type.setdefault(block.type, []).append(idx + offset)
        cell_sets[name] = {kind: np.concatenate(parts) for kind, parts in by_type.items()}
    merged.pop("vertex", None)
    notes = []
    for kind in list(merged):
        found, originals = repeated_cells(merged[kind])
        if not found.size:
            continue
        numbers = np.concatenate(ids[kind]) if kind in ids else None
        notes.append(_repeats_note(kind, found, originals, numbers))
        if repeats == "drop":
            merged[kind], new = _without(merged[kind], found, originals)
            for by_type in cell_sets.values():
                if kind in by_type:
                    by_type[kind] = np.unique(new[by_type[kind]])
    note = None
    if notes:
        what = ("dropped: each element is kept once, in the sets of all its copies"
                if repeats == "drop" else "kept, as the solver of the deck keeps them: the"
                " stiffness and mass of each count")
        note = (f"{'; '.join(notes)}; {what} (two elements on the same nodes double the"
                " stiffness and mass there; write each element once)")
    return Mesh(mesh.points, merged, cell_sets,
                {name: np.unique(idx) for name, idx in node_sets.items()}), note


def _repeats_note(kind: str, found: np.ndarray, originals: np.ndarray, numbers) -> str:
    """``2 quad elements repeat the nodes of an earlier one (numbers): 7 (as 3), ...``;
    elements named by their numbers in the file (``numbers``, by index) or by index."""
    label = "numbers" if numbers is not None else "indices in the file's order"
    pairs = ", ".join(f"{a if numbers is None else numbers[a]} (as"
                      f" {b if numbers is None else numbers[b]})" for a, b in
                      zip(found[:MAX_LISTED], originals[:MAX_LISTED], strict=True))
    more = f" and {found.size - MAX_LISTED} more" if found.size > MAX_LISTED else ""
    return (f"{found.size} {kind} elements repeat the nodes of an earlier one ({label}):"
            f" {pairs}{more}")


def _without(cells: np.ndarray, found: np.ndarray, originals: np.ndarray):
    """``cells`` without the rows ``found``, and the new index of each old row (a dropped
    row maps to its original's)."""
    keep = np.ones(len(cells), dtype=bool)
    keep[found] = False
    new = np.cumsum(keep) - 1
    new[found] = new[originals]
    return cells[keep], new


def read_mesh(path) -> Mesh:
    """Read any meshio-readable file (Gmsh ``.msh``, Abaqus ``.inp``, Nastran ``.bdf``, VTU,
    ...) into a :class:`Mesh` with the file's node and element sets (module docstring).

    What the file holds and the model will not have is said in one
    :class:`~femmech.errors.ModelWarning`: elements on the nodes of another (dropped, or
    for Nastran and Abaqus decks kept), and of a Nastran deck the cards not carried
    (``RBE2``, ``CONM2``, properties, ...) by name and count, and the GRIDs' PS
    constraints (node sets ``PS<components>``) and CD systems
    (:mod:`femmech.fe.nastran_cards`).

    Raises
    ------
    FileNotFoundError
        Naming the path.
    FileFormatError
        (a ValueError) naming the file and the problem: a file too large, unreadable,
        with too many nodes or cells, an unsupported cell type, a set that is not valid
        (naming the set), a node with coordinates non-finite or beyond
        :data:`femmech.fe.mesh.MAX_COORDINATE`, of a Nastran deck a GRID or element
        number given twice or out of range (naming the card and its lines).
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"mesh file not found: {path}")
    size = path.stat().st_size
    if size > MAX_MESH_FILE_BYTES:
        raise FileFormatError(f"{path}: file of {size} bytes; at most {MAX_MESH_FILE_BYTES}"
                              " (limit MAX_MESH_FILE_BYTES)")
    suffix = path.suffix.lower()
    try:  # an Abaqus deck is scanned first: it bounds what meshio would allocate
        deck = abaqus_sets.scan_deck(path) if suffix in ABAQUS_SUFFIXES else None
        if deck is not None:
            _check_counts(len(deck.node_ids), sum(len(ids) for _, ids in deck.blocks))
            abaqus_sets.check_numbers(deck)
        found = nastran_cards.census(path) if suffix in NASTRAN_SUFFIXES else None
        raw = _meshio_read(path, "abaqus" if deck is not None else
                           "nastran" if found is not None and found.hidden else None)
        _check_counts(len(raw.points), sum(len(block.data) for block in raw.cells))
        numbers = np.frombuffer(deck.node_ids, dtype=np.int64) if deck is not None else \
            getattr(raw, "points_id", None)
        check_coordinates(raw.points, numbers, "GRID" if found is not None else "node")
        if deck is not None:
            raw.point_sets, raw.cell_sets = abaqus_sets.deck_sets(deck, raw)
            raw.cells_id = [np.frombuffer(ids, dtype=np.int64) for _, ids in deck.blocks]
        elif found is not None:
            nastran_sets.add_sets(path, raw, found.ps_sets, found.set_cards)
        mesh, note = _converted(raw, "keep" if deck is not None or found is not None
                                else "drop")
    except (ValueError, TypeError, OverflowError) as exc:  # FileFormatError, Mesh's checks
        raise FileFormatError(f"{path}: {exc}") from None
    notes = [n for n in (note, nastran_cards.not_carried(found) if found else None) if n]
    if notes:
        warnings.warn(f"{path}: {'; '.join(notes)}", ModelWarning, stacklevel=2)
    return mesh


def _check_counts(n_points: int, n_cells: int) -> None:
    if n_points > MAX_NODES or n_cells > MAX_CELLS:
        raise FileFormatError(f"{n_points} nodes and {n_cells} cells; at most {MAX_NODES} and"
                              f" {MAX_CELLS} (limits MAX_NODES, MAX_CELLS)")


def _meshio_read(path: Path, deck_format: str | None = None):
    """``meshio.read``, its own printed warnings kept, every failure a FileFormatError; an
    Abaqus deck (``deck_format="abaqus"``) is read without its set blocks
    (:class:`femmech.fe.abaqus_sets.WithoutSets`), a Nastran deck (``"nastran"``) without
    the cards meshio fails on (:class:`femmech.fe.nastran_cards.WithoutCards`)."""
    import meshio

    said = io.StringIO()  # meshio prints warnings and errors of its own; keep them
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            if deck_format is None:
                return meshio.read(path)
            hide = abaqus_sets.WithoutSets if deck_format == "abaqus" else \
                nastran_cards.WithoutCards
            with open(path, encoding="utf-8", errors="replace") as f:
                return meshio.read(hide(f), deck_format)
    except KeyError as exc:
        if deck_format == "abaqus":  # sets are hidden from meshio: an element's node
            raise FileFormatError(f"an element lists node {exc.args[0]}, which the *NODE"
                                  " block does not define") from None
        raise FileFormatError(f"meshio could not read the file (KeyError: {exc})") from None
    except Exception as exc:  # meshio raises many types; report them uniformly
        raise FileFormatError(f"meshio could not read the file ({type(exc).__name__}:"
                              f" {exc})") from None
    except SystemExit:  # meshio 5.3 calls sys.exit(1) when no reader succeeds
        first = " ".join(said.getvalue().split())[:200]
        raise FileFormatError("meshio could not read the file (no reader for its extension"
                              f" accepted the contents: {first})") from None
