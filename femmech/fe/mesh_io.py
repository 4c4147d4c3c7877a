"""Mesh input through meshio (Gmsh .msh, VTU, XDMF, ... anything meshio reads).

Stage 2 (fe, independent of mechanisms): uses only fe.mesh (and meshio).
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np

from femmech.fe.mesh import MAX_CELLS, MAX_NODES, NODES_PER_CELL, Mesh

MAX_MESH_FILE_BYTES = 4 * 2**30
"""Largest mesh file read, bytes (an ASCII Gmsh file of a million nodes and five million
tetrahedra has about 400 MB); a mesh file is untrusted input, refused before reading."""


def from_meshio(mesh) -> Mesh:
    """Convert a ``meshio.Mesh``: cell blocks of one type are merged, cell sets (Gmsh
    physical groups) become :attr:`Mesh.cell_sets`, and sets made of vertex cells
    (Gmsh physical points) become :attr:`Mesh.node_sets`. Sets named ``gmsh:*`` are
    ignored.

    Readers that return groups as integer cell data instead of cell sets are decoded
    too: Gmsh 2.2 files (``gmsh:physical`` tags named by ``field_data``) and files such
    as VTU to which meshio wrote cell sets as one integer array named ``"a-b-c"`` (value
    ``k`` = set ``k``, -1 = none; see ``meshio.Mesh.cell_sets_to_data``).
    """
    offsets, cells = [], {}
    for block in mesh.cells:
        if block.type not in NODES_PER_CELL:
            raise ValueError(f"unsupported cell type {block.type!r} in the mesh file")
        cells.setdefault(block.type, [])
        offsets.append(sum(len(c) for c in cells[block.type]))
        cells[block.type].append(np.asarray(block.data))
    merged = {kind: np.concatenate(parts) for kind, parts in cells.items()}
    cell_sets, node_sets = {}, {}
    raw_sets = {k: v for k, v in mesh.cell_sets.items() if not k.startswith("gmsh:")}
    for name, per_block in (raw_sets or _sets_from_cell_data(mesh)).items():
        by_type = {}
        for block, offset, idx in zip(mesh.cells, offsets, per_block, strict=True):
            if idx is None or len(idx) == 0:
                continue
            idx = np.asarray(idx)
            if idx.dtype.kind not in "iu" or idx.min() < 0 or idx.max() >= len(block.data):
                raise ValueError(f"group {name!r} references {block.type} cells outside the"
                                 f" {len(block.data)} of its block")
            by_type.setdefault(block.type, []).append(idx.astype(np.int64) + offset)
        by_type = {kind: np.concatenate(parts) for kind, parts in by_type.items()}
        if set(by_type) == {"vertex"}:
            node_sets[name] = np.unique(merged["vertex"][by_type["vertex"]])
            if node_sets[name].dtype.kind not in "iu":
                raise ValueError(f"node group {name!r}: vertex cells must hold node indices")
        else:
            by_type.pop("vertex", None)
            cell_sets[name] = by_type
    merged.pop("vertex", None)
    return Mesh(mesh.points, merged, cell_sets, node_sets)


def _sets_from_cell_data(mesh) -> dict:
    """Cell sets (name → index array per block) from integer cell data, see from_meshio."""
    data = mesh.cell_data
    if "gmsh:physical" in data:
        names = {(int(v[0]), int(v[1])): k for k, v in mesh.field_data.items() if len(v) == 2}
        out = {}
        for k, (block, tags) in enumerate(zip(mesh.cells, data["gmsh:physical"], strict=True)):
            tags = np.asarray(tags)
            for tag in np.unique(tags[tags > 0]):
                name = names.get((int(tag), _CELL_DIM.get(block.type, -1)), str(tag))
                out.setdefault(name, [None] * len(mesh.cells))[k] = np.flatnonzero(tags == tag)
        return out
    out = {}
    for key, arrays in data.items():
        names = key.split("-")
        values = [np.asarray(a) for a in arrays]
        if (key.startswith("gmsh:") or len(set(names)) != len(names)
                or not all(v.dtype.kind in "iu" and v.ndim == 1 for v in values)
                or any(v.size and (v.min() < -1 or v.max() >= len(names)) for v in values)):
            continue
        for i, name in enumerate(names):
            out[name] = [np.flatnonzero(v == i) for v in values]
    return out


_CELL_DIM = {"vertex": 0, "line": 1, "line3": 1, "triangle": 2, "quad": 2, "triangle6": 2,
             "quad8": 2, "quad9": 2, "tetra": 3, "tetra10": 3, "hexahedron": 3,
             "hexahedron20": 3, "hexahedron27": 3, "wedge": 3}


def read_mesh(path) -> Mesh:
    """Read any meshio-readable file (e.g. Gmsh ``.msh``) into a :class:`Mesh`.

    Raises FileNotFoundError naming the path, or ValueError naming the file and the
    problem.
    """
    import meshio

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"mesh file not found: {path}")
    size = path.stat().st_size
    if size > MAX_MESH_FILE_BYTES:
        raise ValueError(f"{path}: file of {size} bytes; at most {MAX_MESH_FILE_BYTES}"
                         " (limit MAX_MESH_FILE_BYTES)")
    said = io.StringIO()  # meshio prints warnings and errors of its own; keep them
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            raw = meshio.read(path)
    except Exception as exc:  # meshio raises many types; report them uniformly
        raise ValueError(f"{path}: meshio could not read the file ({exc})") from exc
    except SystemExit as exc:  # meshio 5.3 calls sys.exit(1) when no reader succeeds
        first = " ".join(said.getvalue().split())[:200]
        raise ValueError(f"{path}: meshio could not read the file (no reader for its"
                         f" extension accepted the contents: {first})") from exc
    n_points = len(raw.points)
    n_cells = sum(len(block.data) for block in raw.cells)
    if n_points > MAX_NODES or n_cells > MAX_CELLS:
        raise ValueError(f"{path}: {n_points} nodes and {n_cells} cells; at most {MAX_NODES}"
                         f" and {MAX_CELLS} (limits MAX_NODES, MAX_CELLS)")
    try:
        return from_meshio(raw)
    except (ValueError, TypeError) as exc:
        raise ValueError(f"{path}: {exc}") from exc
