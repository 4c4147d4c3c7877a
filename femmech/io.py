"""Mesh input through meshio (Gmsh .msh, VTU, XDMF, ... anything meshio reads)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from femmech.mesh import NODES_PER_CELL, Mesh


def from_meshio(mesh) -> Mesh:
    """Convert a ``meshio.Mesh``: cell blocks of one type are merged, cell sets (Gmsh
    physical groups) become :attr:`Mesh.cell_sets`, and sets made of vertex cells
    (Gmsh physical points) become :attr:`Mesh.node_sets`. Sets named ``gmsh:*`` are
    ignored.
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
    for name, per_block in mesh.cell_sets.items():
        if name.startswith("gmsh:"):
            continue
        by_type = {}
        for block, offset, idx in zip(mesh.cells, offsets, per_block, strict=True):
            if idx is None or len(idx) == 0:
                continue
            by_type.setdefault(block.type, []).append(np.asarray(idx, dtype=np.int64) + offset)
        by_type = {kind: np.concatenate(parts) for kind, parts in by_type.items()}
        if set(by_type) == {"vertex"}:
            node_sets[name] = np.unique(merged["vertex"][by_type["vertex"]])
        else:
            by_type.pop("vertex", None)
            cell_sets[name] = by_type
    merged.pop("vertex", None)
    return Mesh(mesh.points, merged, cell_sets, node_sets)


def read_mesh(path) -> Mesh:
    """Read any meshio-readable file (e.g. Gmsh ``.msh``) into a :class:`Mesh`.

    Raises FileNotFoundError naming the path, or ValueError naming the file and the
    problem.
    """
    import meshio

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"mesh file not found: {path}")
    try:
        raw = meshio.read(path)
    except Exception as exc:  # meshio raises many types; report them uniformly
        raise ValueError(f"{path}: meshio could not read the file ({exc})") from exc
    try:
        return from_meshio(raw)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from exc
