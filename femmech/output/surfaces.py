"""Cells of a model by kind, for drawing and export: beams, shell faces, solid surfaces.

Pure numpy (no pyvista). Shell elements (:attr:`femmech.FEModel.shells`) are drawn at
their mid-surface, so their cells are the drawn faces. Solid elements, when the model
has them (an attribute ``solids`` whose ``cells`` maps meshio cell types to
connectivity), are drawn by their outer surface: the faces that belong to exactly one
solid cell. Higher-order solids (``tetra10``, ``hexahedron20``, ...) are drawn with
their corner nodes, which meshio lists first.

Uses only fe.model.
"""

from __future__ import annotations

import numpy as np

from femmech.fe.model import FEModel

# Faces of the linear solid cells, by corner nodes in meshio / VTK order, ordered
# counter-clockwise seen from outside for a positively oriented cell.
_FACES = {
    "tetra": ([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]], []),
    "hexahedron": ([], [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5],
                        [2, 3, 7, 6], [3, 0, 4, 7]]),
    "wedge": ([[0, 2, 1], [3, 4, 5]], [[0, 1, 4, 3], [1, 2, 5, 4], [2, 0, 3, 5]]),
    "pyramid": ([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]], [[0, 3, 2, 1]]),
}
_CORNER_TYPE = {"tetra": "tetra", "tetra10": "tetra", "hexahedron": "hexahedron",
                "hexahedron20": "hexahedron", "hexahedron27": "hexahedron", "wedge": "wedge",
                "wedge15": "wedge", "pyramid": "pyramid", "pyramid13": "pyramid"}
_CORNERS = {"tetra": 4, "hexahedron": 8, "wedge": 6, "pyramid": 5}
_BY_WIDTH = {4: "tetra", 10: "tetra10", 8: "hexahedron", 20: "hexahedron20", 6: "wedge"}

# Quadratic shell cells are drawn as linear sub-faces through their mid-side and centre
# nodes (meshio node order: corners, then mid-sides, then the centre), so that the drawn
# surface passes through every node.
_LINEAR_FACES = {
    "triangle6": ("triangle", ((0, 3, 5), (3, 1, 4), (5, 4, 2), (3, 4, 5))),
    "quad9": ("quad", ((0, 4, 8, 7), (4, 1, 5, 8), (8, 5, 2, 6), (7, 8, 6, 3))),
    "quad8": ("triangle", ((0, 4, 7), (4, 1, 5), (5, 2, 6), (6, 3, 7), (4, 5, 7),
                           (5, 6, 7))),
}


def _typed_cells(cells) -> dict[str, np.ndarray]:
    """``{meshio type: connectivity}`` from a dict, or from one array (type by its width)."""
    if cells is None:
        return {}
    if isinstance(cells, dict):
        return {k: np.asarray(v, dtype=np.int64) for k, v in cells.items() if len(v)}
    cells = np.asarray(cells, dtype=np.int64)
    if cells.ndim != 2 or not len(cells):
        return {}
    if cells.shape[1] not in _BY_WIDTH:
        raise ValueError(f"cannot tell the type of solid cells with {cells.shape[1]} nodes")
    return {_BY_WIDTH[cells.shape[1]]: cells}


def shell_cells(model: FEModel) -> dict[str, np.ndarray]:
    """Shell cells by type (``"triangle"``, ``"quad"``); empty for a model without shells."""
    return _typed_cells(getattr(getattr(model, "shells", None), "cells", None))


def solid_cells(model: FEModel) -> dict[str, np.ndarray]:
    """Solid cells by meshio type; empty unless the model has ``solids`` with cells."""
    return _typed_cells(getattr(getattr(model, "solids", None), "cells", None))


def _groups(item, kind: str, n: int, default: str) -> np.ndarray:
    """Group name per cell of one type of a ShellSet-like object (``default`` if none)."""
    group = getattr(item, "group", None)
    if isinstance(group, dict) and kind in group:
        return np.asarray(group[kind], dtype=object)
    if group is not None and not isinstance(group, dict) and len(group) == n:
        return np.asarray(group, dtype=object)
    return np.full(n, default, dtype=object)


def cell_blocks(model: FEModel) -> list[tuple[str, np.ndarray, np.ndarray, np.ndarray]]:
    """All elements of a model as ``(meshio type, cells, group names, thickness m)`` blocks.

    Beams come first (``"line"``), then shells, then solids; empty blocks are left out.
    Thickness is the shell thickness (m) and 0 for beams and solids.
    """
    blocks = []
    if len(model.beams.cells):
        n = len(model.beams.cells)
        blocks.append(("line", model.beams.cells, np.asarray(model.beams.group, dtype=object),
                       np.zeros(n)))
    shells = getattr(model, "shells", None)
    for kind, cells in shell_cells(model).items():
        thick = getattr(shells, "thickness", {}).get(kind, np.zeros(len(cells)))
        blocks.append((kind, cells, _groups(shells, kind, len(cells), "shells"),
                       np.asarray(thick, dtype=float)))
    solids = getattr(model, "solids", None)
    for kind, cells in solid_cells(model).items():
        blocks.append((kind, cells, _groups(solids, kind, len(cells), "solids"),
                       np.zeros(len(cells))))
    return blocks


def boundary_faces(cells_by_type: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Outer faces of solid cells: faces that belong to exactly one cell.

    Parameters
    ----------
    cells_by_type : dict[str, ndarray (n_cells, n_nodes)]
        Solid cells by meshio type (tetra, hexahedron, wedge, pyramid and their
        higher-order variants, of which the corner nodes are used).

    Returns
    -------
    dict[str, ndarray]
        ``"triangle"`` (n, 3) and ``"quad"`` (n, 4) faces, node order as in the owning
        cell (outward normal for positively oriented cells); empty types left out.

    Raises
    ------
    ValueError
        For a cell type that is not a solid, naming it.

    Examples
    --------
    >>> import numpy as np
    >>> hexa = np.arange(12).reshape(1, 12)[:, [0, 1, 4, 3, 6, 7, 10, 9]]
    >>> two = np.vstack([hexa, hexa + 1])  # two hexahedra sharing one face
    >>> {k: len(v) for k, v in boundary_faces({"hexahedron": two}).items()}
    {'quad': 10}
    """
    faces = {3: [], 4: []}
    for kind, cells in cells_by_type.items():
        if kind not in _CORNER_TYPE:
            raise ValueError(f"{kind!r} cells are not solid cells; expected one of"
                             f" {sorted(_CORNER_TYPE)}")
        base = _CORNER_TYPE[kind]
        corners = np.asarray(cells, dtype=np.int64)[:, :_CORNERS[base]]
        for local in _FACES[base]:
            for face in local:
                faces[len(face)].append(corners[:, face])
    out = {}
    for width, name in ((3, "triangle"), (4, "quad")):
        if not faces[width]:
            continue
        allf = np.concatenate(faces[width])
        _, index, count = np.unique(np.sort(allf, axis=1), axis=0, return_index=True,
                                    return_counts=True)
        outer = np.sort(index[count == 1])
        if outer.size:
            out[name] = allf[outer]
    return out


def surface_faces(model: FEModel) -> dict[str, np.ndarray]:
    """Faces to draw as surfaces: shell cells and the outer faces of solid cells.

    Returns
    -------
    dict[str, ndarray]
        ``"triangle"`` (n, 3) and ``"quad"`` (n, 4) node indices; empty for a beam model.
        Quadratic shells (``triangle6``, ``quad8``, ``quad9``) come as linear sub-faces.
    """
    out = {}
    for kind, cells in shell_cells(model).items():
        base, subs = _LINEAR_FACES.get(kind, (kind, None))
        out.setdefault(base, []).append(
            cells if subs is None else np.concatenate([cells[:, list(f)] for f in subs]))
    for kind, faces in boundary_faces(solid_cells(model)).items():
        out.setdefault(kind, []).append(faces)
    return {k: np.concatenate(v) for k, v in out.items()}


def surface_nodes(model: FEModel) -> np.ndarray:
    """Sorted indices of the nodes on the drawn surfaces (shells and solid surfaces)."""
    faces = surface_faces(model)
    if not faces:
        return np.empty(0, dtype=np.int64)
    return np.unique(np.concatenate([f.ravel() for f in faces.values()]))
