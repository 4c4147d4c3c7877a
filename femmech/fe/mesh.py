"""The mesh: points, cells by type, named cell sets and node sets (meshio conventions).

Imports only femmech.errors (message wording) and
femmech.html (notebook view).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from femmech.errors import did_you_mean, name_list
from femmech.html import html_summary

NODES_PER_CELL = {
    "vertex": 1, "line": 2, "line3": 3, "triangle": 3, "quad": 4, "triangle6": 6,
    "quad8": 8, "quad9": 9, "tetra": 4, "tetra10": 10, "hexahedron": 8, "hexahedron20": 20,
    "hexahedron27": 27, "wedge": 6,
}

MAX_NODES = 10_000_000
"""Most nodes of a mesh read from a file or generated for a scene (60 million beam DOFs;
a real machine model has a few million). Scenes and mesh files are untrusted input: a
larger count is refused before it is allocated (:func:`femmech.fe.mesh_io.read_mesh`,
:mod:`femmech.fe.generators`)."""
MAX_CELLS = 20_000_000
"""Most cells (elements) of a mesh read from a file or generated for a scene."""
MAX_COORDINATE = 1e30
"""Largest coordinate magnitude of a node (m, or the length unit of the model). No mesh
in any unit system spans 1e30 units; far beyond, the element matrices overflow (their
terms hold the third and higher powers of the lengths: a 2 m cantilever with its section
scaled by 1e70 overflows, coordinates of 1e120 overflow ``L**3``) and squared distances
overflow at 1.3e154, each with numpy overflow warnings instead of an error."""


@dataclass(frozen=True)
class Mesh:
    """Nodes, cells and named groups.

    Attributes
    ----------
    points : ndarray (n_nodes, 3), m
    cells : dict[str, ndarray (n_cells, nodes_per_cell)]
        0-based connectivity by meshio cell type (``"line"``, ``"triangle"``, ...).
    cell_sets : dict[str, dict[str, ndarray]]
        Group name → cell type → indices into ``cells[type]``.
    node_sets : dict[str, ndarray]
        Group name → node indices.

    Raises
    ------
    ValueError
        Coordinates non-finite or beyond :data:`MAX_COORDINATE`, cells referencing
        missing nodes, or groups referencing missing cells, each naming the offending item.
    TypeError
        Coordinates that are not real numbers, connectivity or group indices that are not
        integers, or containers of the wrong kind, naming the item.
    """

    points: np.ndarray
    cells: dict[str, np.ndarray]
    cell_sets: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    node_sets: dict[str, np.ndarray] = field(default_factory=dict)

    def __post_init__(self):
        points = _real_array(self.points, "points")
        for label, value in (("cells", self.cells), ("cell_sets", self.cell_sets),
                             ("node_sets", self.node_sets)):
            if not isinstance(value, Mapping):
                raise TypeError(f"{label} must be a dict, got {type(value).__name__}")
        if points.ndim != 2 or points.shape[1] not in (2, 3):
            raise ValueError(f"points must have shape (n_nodes, 3), got {points.shape}")
        if points.shape[1] == 2:
            points = np.column_stack([points, np.zeros(len(points))])
        check_coordinates(points)
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "cells", {k: _check_cells(k, v, len(points))
                                           for k, v in self.cells.items()})
        sets = {}
        for name, by_type in self.cell_sets.items():
            sets[name] = {}
            if not isinstance(by_type, Mapping):
                raise TypeError(f"cell set {name!r} must be a dict {{cell type: indices}},"
                                f" got {type(by_type).__name__}")
            for kind, idx in by_type.items():
                idx = _indices(idx, f"cell set {name!r} ({kind} cells)")
                n_cells = len(self.cells.get(kind, ()))
                if idx.size and (idx.min() < 0 or idx.max() >= n_cells):
                    raise ValueError(f"cell set {name!r} references {kind} cell"
                                     f" {idx.max()}, but the mesh has {n_cells}")
                sets[name][kind] = idx
        object.__setattr__(self, "cell_sets", sets)
        node_sets = {}
        for name, nodes in self.node_sets.items():
            nodes = _indices(nodes, f"node set {name!r}")
            if nodes.size and (nodes.min() < 0 or nodes.max() >= len(points)):
                raise ValueError(f"node set {name!r} references node {nodes.max()},"
                                 f" but the mesh has {len(points)} nodes")
            node_sets[name] = nodes
        object.__setattr__(self, "node_sets", node_sets)

    def __repr__(self) -> str:
        cells = ", ".join(f"{len(c)} {k}" for k, c in self.cells.items()) or "no cells"
        return (f"Mesh({self.n_nodes} nodes; {cells}; {len(self.cell_sets)} cell sets,"
                f" {len(self.node_sets)} node sets)")

    def _repr_html_(self) -> str:
        rows = [(kind, len(cells)) for kind, cells in self.cells.items()]
        low, high = self.points.min(axis=0), self.points.max(axis=0)
        facts = [("extent / m", " × ".join(f"{d:.4g}" for d in high - low)),
                 ("cell sets", ", ".join(self.cell_sets) or "none"),
                 ("node sets", ", ".join(self.node_sets) or "none")]
        return html_summary(f"Mesh: {self.n_nodes} nodes", facts, ("cell kind", "cells"), rows)

    @property
    def n_nodes(self) -> int:
        """Number of nodes."""
        return len(self.points)

    @classmethod
    def from_lines(cls, points, lines, cell_sets=None, node_sets=None) -> Mesh:
        """Mesh of line cells from arrays.

        Parameters
        ----------
        points : array_like (n_nodes, 3), m
        lines : array_like (n_elements, 2), int
        cell_sets : dict[str, array_like of int], optional
            Group name → element indices. Default: one group ``"all"``.
        node_sets : dict[str, array_like of int], optional
        """
        lines = np.asarray(lines)
        if cell_sets is None:
            cell_sets = {"all": np.arange(len(lines))}
        return cls(points, {"line": lines},
                   {name: {"line": idx} for name, idx in cell_sets.items()},
                   dict(node_sets or {}))

    def merge_nodes(self, tol: float, keep=()) -> Mesh:
        """Mesh with the nodes closer than ``tol`` merged (cells and groups renumbered).

        Nodes within ``tol`` of each other, directly or through a chain, become one node,
        which keeps the lowest index and coordinates of its cluster; the other nodes are
        removed and the rest renumbered in order (:func:`merged_node_index` gives the new
        index of each old node). Node sets are remapped; cell sets are unchanged.

        Parameters
        ----------
        tol : float
            Distance, m (e.g. 1e-6 × the model size).
        keep : array_like of int
            Nodes never merged, e.g. the two ends of a zero-length spring.

        Raises
        ------
        ValueError
            If a cell would lose a node (two of its nodes closer than ``tol``), naming it.
        """
        new = merged_node_index(self.points, tol, keep)
        cells = {}
        for kind, c in self.cells.items():
            c = new[c]
            ordered = np.sort(c, axis=1)
            bad = np.flatnonzero((ordered[:, 1:] == ordered[:, :-1]).any(axis=1))
            if bad.size:
                e = int(bad[0])
                raise ValueError(f"merge_nodes({tol:g}): {kind} cell {e} (nodes"
                                 f" {self.cells[kind][e].tolist()}) would collapse: two of its"
                                 f" nodes are closer than {tol:g} m ({bad.size} such cells);"
                                 " use a smaller tolerance")
            cells[kind] = c
        first = np.unique(new, return_index=True)[1]
        node_sets = {name: np.unique(new[nodes]) for name, nodes in self.node_sets.items()}
        return Mesh(self.points[first], cells, self.cell_sets, node_sets)

    def group_names(self) -> list[str]:
        """All cell-set and node-set names."""
        return sorted(set(self.cell_sets) | set(self.node_sets))

    def nodes_of(self, name: str) -> np.ndarray:
        """Node indices of a node set, or the nodes of a cell set's cells (sorted)."""
        if name in self.node_sets:
            return self.node_sets[name]
        if name in self.cell_sets:
            parts = [self.cells[kind][idx].ravel() for kind, idx in self.cell_sets[name].items()]
            return np.unique(np.concatenate(parts)) if parts else np.empty(0, dtype=np.int64)
        names = self.group_names()
        raise ValueError(f"unknown group {name!r}; the mesh has {name_list(names)}"
                         f"{did_you_mean(name, names)}")

    def unknown_cell_set(self, name: str, what: str = "group") -> str:
        """Message for a cell set ``name`` that the mesh lacks: ``unknown group 'x'; the mesh
        has cell sets [...]; did you mean 'y'?`` (and a note if ``x`` is a node set)."""
        note = (f" ({name!r} is a node set; elements are named by cell sets)"
                if name in self.node_sets else "")
        return (f"unknown {what} {name!r}; the mesh has cell sets {name_list(self.cell_sets)}"
                f"{did_you_mean(name, self.cell_sets)}{note}")


def check_coordinates(points: np.ndarray, ids=None, what: str = "node") -> None:
    """ValueError naming the first node (``what`` and its number in ``ids``, else its
    index) whose coordinates are not finite or exceed :data:`MAX_COORDINATE` in
    magnitude, and how many such nodes there are; computes no squares (no overflow)."""
    points = np.asarray(points, dtype=float)
    if not points.size:
        return
    with np.errstate(invalid="ignore"):
        size = np.abs(points).max(axis=1)
    bad = np.flatnonzero(~(size <= MAX_COORDINATE))  # NaN compares False
    if bad.size:
        k = int(bad[0])
        name = f"{what} {ids[k]}" if ids is not None else f"{what} {k}"
        if not np.isfinite(points[k]).all():
            raise ValueError(f"{name} has non-finite coordinates {points[k].tolist()}"
                             f" ({bad.size} nodes with non-finite or too large ones)")
        raise ValueError(f"{name} has coordinates {points[k].tolist()} beyond"
                         f" ±{MAX_COORDINATE:g} (MAX_COORDINATE: the element matrices would"
                         f" overflow; {bad.size} such nodes)")


def repeated_cells(cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cells on the node set of an earlier cell (same nodes in any order).

    Parameters
    ----------
    cells : ndarray (n_cells, nodes_per_cell) of int

    Returns
    -------
    repeats : ndarray (n_repeats,) of int
        Indices of the cells whose nodes an earlier cell has, ascending.
    originals : ndarray (n_repeats,) of int
        For each, the index of the first cell on those nodes.
    """
    cells = np.asarray(cells)
    if len(cells) < 2:
        return np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64)
    key = np.sort(cells, axis=1)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    original = first[inverse.ravel()]
    repeats = np.flatnonzero(original != np.arange(len(cells)))
    return repeats, original[repeats]


def merged_node_index(points: np.ndarray, tol: float, keep=()) -> np.ndarray:
    """New index of each node when nodes closer than ``tol`` are merged.

    Clusters are the connected components of the pairs closer than ``tol`` (m; nodes in
    ``keep`` take part in none); each cluster becomes the node of its lowest index, and
    the new indices number the clusters in that order.

    Returns
    -------
    ndarray (n_nodes,) of int
        ``new[i]``: index of old node i in the merged mesh.
    """
    if not (np.isfinite(tol) and tol >= 0):
        raise ValueError(f"merge tolerance must be a distance >= 0 (m), got {tol}")
    n = len(points)
    pairs = cKDTree(points).query_pairs(tol, output_type="ndarray") if n > 1 else \
        np.empty((0, 2), dtype=np.int64)
    kept = np.zeros(n, dtype=bool)
    kept[_indices(keep, "merge_nodes keep")] = True
    pairs = pairs[~kept[pairs].any(axis=1)] if len(pairs) else pairs
    graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    first = np.full(label.max(initial=-1) + 1, n)
    np.minimum.at(first, label, np.arange(n))  # lowest node of each cluster
    rank = np.empty_like(first)
    rank[np.argsort(first)] = np.arange(first.size)
    return rank[label]


def _real_array(value, label: str) -> np.ndarray:
    """Float array from real numbers; TypeError naming ``label`` otherwise (complex values,
    strings, objects: a cast would drop or garble them)."""
    try:
        raw = np.asarray(value)
    except ValueError as exc:  # ragged nested sequences
        raise ValueError(f"{label} must be a rectangular array of numbers ({exc})") from None
    if raw.dtype.kind not in "iuf":
        raise TypeError(f"{label} must be real numbers, got dtype {raw.dtype}")
    return raw.astype(float)


def _indices(value, label: str) -> np.ndarray:
    """1-D int64 indices; TypeError naming ``label`` for non-integers (a float or bool
    index would be truncated or read as 0/1, silently selecting other items)."""
    idx = np.asarray(value).ravel()
    if idx.size and idx.dtype.kind not in "iu":
        raise TypeError(f"{label}: indices must be integers, got dtype {idx.dtype}")
    return idx.astype(np.int64)


def _check_cells(kind: str, cells, n_nodes: int) -> np.ndarray:
    if kind not in NODES_PER_CELL:
        raise ValueError(f"unsupported cell type {kind!r}")
    try:
        cells = np.asarray(cells)
    except ValueError:  # ragged nested sequences
        raise ValueError(f"{kind} cells must be a rectangular (n, {NODES_PER_CELL[kind]})"
                         " array of node indices") from None
    if cells.size == 0:
        return np.empty((0, NODES_PER_CELL[kind]), dtype=np.int64)
    if not np.issubdtype(cells.dtype, np.integer):
        raise ValueError(f"{kind} connectivity must be integer, got {cells.dtype}")
    cells = cells.astype(np.int64)
    if cells.ndim != 2 or cells.shape[1] != NODES_PER_CELL[kind]:
        raise ValueError(f"{kind} cells must have shape (n, {NODES_PER_CELL[kind]}),"
                         f" got {cells.shape}")
    bad = np.flatnonzero((cells < 0).any(axis=1) | (cells >= n_nodes).any(axis=1))
    if bad.size:
        e = bad[0]
        node = cells[e][(cells[e] < 0) | (cells[e] >= n_nodes)][0]
        raise ValueError(f"{kind} cell {e} (nodes {cells[e].tolist()}) references node {node},"
                         f" but the mesh has {n_nodes} nodes")
    if kind != "line":  # (a line with one node twice is named by the beam's length check)
        ordered = np.sort(cells, axis=1)
        twice = np.flatnonzero((ordered[:, 1:] == ordered[:, :-1]).any(axis=1))
        if twice.size:  # a collapsed cell: positive Jacobians inside, yet degenerate
            e = twice[0]
            node = ordered[e, 1:][ordered[e, 1:] == ordered[e, :-1]][0]
            raise ValueError(f"{kind} cell {e} (nodes {cells[e].tolist()}) uses node {node}"
                             f" twice: a degenerate cell ({twice.size} such cells)")
    return cells


def line_submesh(mesh: Mesh, elements) -> tuple[Mesh, np.ndarray]:
    """Mesh of a subset of the line elements, with nodes renumbered.

    Parameters
    ----------
    mesh : Mesh
    elements : array_like of int or bool (n_lines,)
        Line elements to keep (indices or a mask).

    Returns
    -------
    sub : Mesh
        Only the used nodes; cell sets and node sets restricted to what is kept (empty
        ones dropped).
    node_ids : ndarray (sub.n_nodes,)
        Original index of each node of ``sub``.
    """
    lines = mesh.cells.get("line", np.empty((0, 2), dtype=np.int64))
    keep = np.zeros(len(lines), dtype=bool)
    keep[np.asarray(elements)] = True
    node_ids = np.unique(lines[keep])
    new_node = np.full(mesh.n_nodes, -1)
    new_node[node_ids] = np.arange(node_ids.size)
    new_cell = np.full(len(lines), -1)
    new_cell[keep] = np.arange(keep.sum())
    cell_sets = {}
    for name, by_type in mesh.cell_sets.items():
        idx = new_cell[by_type.get("line", np.empty(0, dtype=np.int64))]
        if (idx >= 0).any():
            cell_sets[name] = {"line": idx[idx >= 0]}
    node_sets = {}
    for name, nodes in mesh.node_sets.items():
        sub = new_node[nodes]
        if (sub >= 0).any():
            node_sets[name] = sub[sub >= 0]
    sub = Mesh(mesh.points[node_ids], {"line": new_node[lines[keep]]}, cell_sets, node_sets)
    return sub, node_ids


QUAD8_CENTRE = np.array([-0.25, -0.25, -0.25, -0.25, 0.5, 0.5, 0.5, 0.5])
"""Serendipity shape functions of the 8-node quad at its centre, ``N_i(0, 0)`` (8,):
-¼ at the corners 0-3, ½ at the edge nodes 4-7 (meshio order). The centre value of any
field of the 8-node element is ``QUAD8_CENTRE @ values``."""


CENTRE_TOL = 1e-9
"""A node within this fraction of the model size (largest bounding-box side) of a quad8
cell's centre is its centre node (the distance at which ``build_model`` reports nodes
as coincident)."""


def quad8_to_quad9(mesh: Mesh) -> Mesh:
    """Mesh with each 8-node quad turned into a 9-node one (MITC9 shells take quad9).

    The centre node of each ``"quad8"`` cell is placed where the serendipity map puts
    the element centre, ``x(0, 0) = ½ Σ edge nodes - ¼ Σ corners`` (:data:`QUAD8_CENTRE`),
    and appended after the existing nodes, so that every node keeps its index and node
    sets stay valid. A node of the mesh already there (within :data:`CENTRE_TOL` times
    the model size: the face centre of a ``hexahedron27`` under a skin) is the centre
    node instead, and cells on the same eight nodes (stacked skins) share one. The
    cells join the ``"quad9"`` cells (after any already there), and cell sets follow
    them. A mesh without quad8 cells is returned unchanged. Where the eight nodes all
    belong to solid elements (a skin on a solid face), :func:`femmech.build_model` ties
    an added centre node's translations to the serendipity interpolation of the eight
    (:func:`quad8_centres`; :mod:`femmech.fe.elements.shell9`).

    Parameters
    ----------
    mesh : Mesh

    Returns
    -------
    Mesh
        ``mesh.n_nodes + n_added`` nodes (``n_added <= n_quad8``); no ``"quad8"`` cells.
    """
    quad8 = mesh.cells.get("quad8")
    if quad8 is None:
        return mesh
    new, centre, _ = _quad8_centre_nodes(mesh)
    old9 = mesh.cells.get("quad9", np.empty((0, 9), dtype=np.int64))
    cells = {k: v for k, v in mesh.cells.items() if k not in ("quad8", "quad9")}
    cells["quad9"] = np.vstack([old9, np.column_stack([quad8, new])])
    cell_sets = {}
    for name, by_type in mesh.cell_sets.items():
        sets = {k: v for k, v in by_type.items() if k not in ("quad8", "quad9")}
        parts = [by_type.get("quad9", np.empty(0, dtype=np.int64)),
                 len(old9) + by_type.get("quad8", np.empty(0, dtype=np.int64))]
        if "quad8" in by_type or "quad9" in by_type:
            sets["quad9"] = np.concatenate(parts)
        cell_sets[name] = sets
    return Mesh(np.vstack([mesh.points, centre]), cells, cell_sets, mesh.node_sets)


def quad8_centres(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """Centre nodes that :func:`quad8_to_quad9` adds for the quad8 cells of ``mesh``.

    Parameters
    ----------
    mesh : Mesh
        The mesh before the conversion.

    Returns
    -------
    centres : ndarray (n_added,), int
        Node indices of the added centre nodes in the converted mesh (not those that
        were already nodes of ``mesh``).
    nodes : ndarray (n_added, 8), int
        The eight nodes of the quad8 cell of each (meshio order), the nodes of the
        weights :data:`QUAD8_CENTRE`.
    """
    if "quad8" not in mesh.cells:
        return np.empty(0, dtype=np.int64), np.empty((0, 8), dtype=np.int64)
    _, centre, cells = _quad8_centre_nodes(mesh)
    return mesh.n_nodes + np.arange(len(centre)), mesh.cells["quad8"][cells]


def _quad8_centre_nodes(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centre node of each quad8 cell (n_quad8,) in the converted mesh, the added centre
    points (n_added, 3), m, and for each the first quad8 cell that has it (n_added,)."""
    quad8 = np.asarray(mesh.cells["quad8"], dtype=np.int64)
    if not len(quad8):
        return np.empty(0, dtype=np.int64), np.empty((0, 3)), np.empty(0, dtype=np.int64)
    _, first, inverse = np.unique(np.sort(quad8, axis=1), axis=0, return_index=True,
                                  return_inverse=True)
    order = np.argsort(first)  # distinct cells in the order of their first appearance
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    first, inverse = first[order], rank[inverse.ravel()]
    centre = np.einsum("i,eij->ej", QUAD8_CENTRE, mesh.points[quad8[first]])
    scale = max(float(np.ptp(mesh.points, axis=0).max()), 1e-300)
    dist, near = cKDTree(mesh.points).query(centre)
    there = dist <= CENTRE_TOL * scale
    index = np.where(there, near, 0)
    index[~there] = mesh.n_nodes + np.arange(np.count_nonzero(~there))
    return index[inverse], centre[~there], first[~there]
