"""Mesh input through meshio (Gmsh .msh, Abaqus .inp, Nastran .bdf, VTU, MED, ... anything
meshio reads), with the file's node and element sets as :class:`Mesh` node and cell sets.

Where the groups of each format come from is in :mod:`femmech.fe.mesh_sets`; Abaqus decks
and Nastran bulk data have their sets read by femmech itself, because meshio 5 loses or
garbles them (:mod:`femmech.fe.abaqus_sets`, :mod:`femmech.fe.nastran_sets`). A mesh file
is untrusted input: its size, node and cell counts and every set are checked, and every
problem is one :class:`~femmech.errors.FileFormatError` line naming the file and the item.

Stage 2 (fe, independent of mechanisms): uses fe.mesh, fe.mesh_sets, fe.abaqus_sets,
fe.nastran_sets (and meshio).
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np

from femmech.errors import FileFormatError
from femmech.fe import abaqus_sets, nastran_sets
from femmech.fe.mesh import MAX_CELLS, MAX_NODES, NODES_PER_CELL, Mesh
from femmech.fe.mesh_sets import collect_sets

MAX_MESH_FILE_BYTES = 4 * 2**30
"""Largest mesh file read, bytes (an ASCII Gmsh file of a million nodes and five million
tetrahedra has about 400 MB); a mesh file is untrusted input, refused before reading."""
ABAQUS_SUFFIXES = (".inp",)
NASTRAN_SUFFIXES = (".bdf", ".fem", ".nas")
"""File name endings meshio reads as Abaqus and as Nastran (``meshio.extension_to_filetypes``)."""


def from_meshio(mesh) -> Mesh:
    """Convert a ``meshio.Mesh``: cell blocks of one type are merged (in block order), and
    the groups of every form meshio returns (:func:`femmech.fe.mesh_sets.collect_sets`)
    become :attr:`Mesh.node_sets` and :attr:`Mesh.cell_sets`; vertex cells are not kept
    (a set of vertex cells, a Gmsh physical point, becomes a node set).

    Raises
    ------
    FileFormatError
        An unsupported cell type, or a set that is not valid (naming it).
    """
    offsets, cells = [], {}
    for block in mesh.cells:
        if block.type not in NODES_PER_CELL:
            raise FileFormatError(f"unsupported cell type {block.type!r} in the mesh file"
                                  f" (femmech reads {sorted(NODES_PER_CELL)})")
        cells.setdefault(block.type, [])
        offsets.append(sum(len(c) for c in cells[block.type]))
        cells[block.type].append(np.asarray(block.data))
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
    return Mesh(mesh.points, merged, cell_sets,
                {name: np.unique(idx) for name, idx in node_sets.items()})


def read_mesh(path) -> Mesh:
    """Read any meshio-readable file (Gmsh ``.msh``, Abaqus ``.inp``, Nastran ``.bdf``, VTU,
    ...) into a :class:`Mesh` with the file's node and element sets (module docstring).

    Raises
    ------
    FileNotFoundError
        Naming the path.
    FileFormatError
        (a ValueError) naming the file and the problem: a file too large, unreadable,
        with too many nodes or cells, an unsupported cell type, or a set that is not valid
        (naming the set).
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
        raw = _meshio_read(path, "abaqus" if deck is not None else None)
        _check_counts(len(raw.points), sum(len(block.data) for block in raw.cells))
        if deck is not None:
            raw.point_sets, raw.cell_sets = abaqus_sets.deck_sets(deck, raw)
        elif suffix in NASTRAN_SUFFIXES:
            nastran_sets.add_sets(path, raw)
        return from_meshio(raw)
    except (ValueError, TypeError) as exc:  # FileFormatError, Mesh's checks
        raise FileFormatError(f"{path}: {exc}") from None


def _check_counts(n_points: int, n_cells: int) -> None:
    if n_points > MAX_NODES or n_cells > MAX_CELLS:
        raise FileFormatError(f"{n_points} nodes and {n_cells} cells; at most {MAX_NODES} and"
                              f" {MAX_CELLS} (limits MAX_NODES, MAX_CELLS)")


def _meshio_read(path: Path, deck_format: str | None = None):
    """``meshio.read``, its own printed warnings kept, every failure a FileFormatError; an
    Abaqus deck (``deck_format="abaqus"``) is read without its set blocks
    (:class:`femmech.fe.abaqus_sets.WithoutSets`)."""
    import meshio

    said = io.StringIO()  # meshio prints warnings and errors of its own; keep them
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            if deck_format is None:
                return meshio.read(path)
            with open(path, encoding="utf-8", errors="replace") as f:
                return meshio.read(abaqus_sets.WithoutSets(f), deck_format)
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
