"""Uniform refinement (h/2) of a mesh with its groups, and the model rebuilt on it.

Every cell is split in two (lines), four (triangles, quads) or eight (tetrahedra,
hexahedra) by new nodes at its edge midpoints, face centres (quads, hexahedron faces) and
cell centre (hexahedra). A new node shared by neighbouring cells is made once: its parent
nodes (the edge's two, the face's four) are sorted into a key, and equal keys give one
node. The coordinates are the mean of the parents, which is where the element's own
(bi-, tri-)linear map puts them, so the refined mesh covers the same geometry.

Numbering: the coarse nodes keep their indices ``0 … n-1`` and the new nodes follow
(edge midpoints, then face centres, then cell centres), so that node references of a
model (supports, masses, springs, links, attachments given by index) stay valid and a
coarse mode shape can be compared with a fine one on the first ``6 n`` DOFs. The children
of cell ``e`` are cells ``c e … c e + c - 1`` (``c`` children per cell) of the same kind;
cell sets name the children of their cells, so per-group properties (sections,
orientation vectors, thicknesses, materials) carry over to the children unchanged.

Node sets keep their nodes and gain each new node all of whose parents are in the set:
the midpoints of a supported plate edge are supported, as the coarse model's edge was
(its displacement along the edge was interpolated from supported nodes). Midpoints of
edges that only line (beam) elements use join a set only if it holds every coarse node:
beam node sets name points (joints, supports, attachments), and a beam between two
supported joints keeps its free interior. A set of one node is unchanged. (A triangle
with all three nodes in a set, e.g. at a corner of a boundary set, gives its interior
edge's midpoint to the set too; in the coarse model that triangle was held entirely.)

Quadratic shells (``quad9``, ``triangle6``) split into four at their own nodes; the new
mid-edge and centre nodes of the children are placed by the parent's quadratic map, so
curved cells stay on their surface. ``line3``, ``quad8``, ``tetra10``, ``hexahedron20``,
``hexahedron27`` and wedges are not refined: :func:`refine_mesh` raises
NotImplementedError naming the kind.

Uses fe.mesh and fe.model (:func:`refined_model` rebuilds with
:func:`~femmech.fe.model.build_model`).
"""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np

from femmech.errors import ModelWarning
from femmech.fe.constraints import InterpolatingLink, RigidLink, Support
from femmech.fe.mesh import Mesh
from femmech.fe.model import FEModel, build_model

_HEX_FACES = ((0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6),
              (3, 0, 4, 7))
_HEX_EDGES = ((0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4),
              (1, 5), (2, 6), (3, 7))
# VTK corner order of a hexahedron as (x, y, z) offsets in {0, 1}
_HEX_CORNERS = ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1),
                (0, 1, 1))


def _hex_children() -> np.ndarray:
    """Children (8, 8) of a hexahedron as indices into [8 corners, 12 edge midpoints,
    6 face centres, centre], from the 3 x 3 x 3 lattice of those 27 nodes."""
    lattice = {}
    corners = 2 * np.array(_HEX_CORNERS)
    for i, c in enumerate(corners):
        lattice[tuple(c)] = i
    for i, (a, b) in enumerate(_HEX_EDGES):
        lattice[tuple((corners[a] + corners[b]) // 2)] = 8 + i
    for i, face in enumerate(_HEX_FACES):
        lattice[tuple(corners[list(face)].sum(axis=0) // 4)] = 20 + i
    lattice[(1, 1, 1)] = 26
    return np.array([[lattice[tuple(np.array(origin) + offset)] for offset in _HEX_CORNERS]
                     for origin in _HEX_CORNERS])


# per cell kind: (edges, faces, cell centre?, children as indices into
# [corners, edge midpoints, face centres, centre])
_SCHEMES = {
    "line": (((0, 1),), (), False, ((0, 2), (2, 1))),
    "triangle": (((0, 1), (1, 2), (2, 0)), (), False,
                 ((0, 3, 5), (3, 1, 4), (5, 4, 2), (3, 4, 5))),
    "quad": (((0, 1), (1, 2), (2, 3), (3, 0)), ((0, 1, 2, 3),), False,
             ((0, 4, 8, 7), (4, 1, 5, 8), (8, 5, 2, 6), (7, 8, 6, 3))),
    # edges 4: 01, 5: 02, 6: 03, 7: 12, 8: 13, 9: 23; octahedron split along 5-8 (m02-m13)
    "tetra": (((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)), (), False,
              ((0, 4, 5, 6), (4, 1, 7, 8), (5, 7, 2, 9), (6, 8, 9, 3),
               (5, 8, 4, 6), (5, 8, 6, 9), (5, 8, 9, 7), (5, 8, 7, 4))),
    "hexahedron": (_HEX_EDGES, _HEX_FACES, True, tuple(map(tuple, _hex_children()))),
}


def children_per_cell(kind: str) -> int:
    """Number of children of one cell of ``kind`` (1 for vertex cells)."""
    if kind == "vertex":
        return 1
    return len(_SCHEMES[kind][3]) if kind in _SCHEMES else len(_QUADRATIC[kind][2])


def refine_mesh(mesh: Mesh) -> Mesh:
    """The mesh with every cell split uniformly (h/2), groups carried over.

    :func:`refine_with_parents` also returns the parents of the new nodes.

    Parameters
    ----------
    mesh : Mesh
        Cells of the kinds in :data:`REFINABLE`.

    Returns
    -------
    Mesh
        Nodes ``0 … n-1`` are the coarse nodes (same coordinates), new nodes follow;
        cells of each kind ``c`` times as many (children of cell ``e`` at ``c e …``); cell
        sets hold the children of their cells; node sets as in the module docstring.

    Raises
    ------
    NotImplementedError
        For cells of a kind that is not refined (quadratic cells, wedges), naming it.
    """
    return refine_with_parents(mesh)[0]


def refine_with_parents(mesh: Mesh) -> tuple[Mesh, list]:
    """:func:`refine_mesh` and the parents of the new nodes: a list of int arrays
    (edges (m, 2), faces (m, 4), hexahedron corners (m, 8), then the child edges (m, 2)
    and child quad corners (m, 4) of quadratic cells) whose rows, in order, are the parent
    nodes of new nodes ``n, n + 1, …`` (``n`` coarse nodes); rows of edges that only
    line cells use are -1 (they join no node set but a set of all nodes)."""
    todo = {k: c for k, c in mesh.cells.items() if k != "vertex" and len(c)}
    other = sorted(set(todo) - set(_SCHEMES) - set(_QUADRATIC))
    if other:
        raise NotImplementedError(f"refine_mesh: {other} cells are not refined (only"
                                  f" {sorted(_SCHEMES) + sorted(_QUADRATIC)}); refine the"
                                  " mesh in its generator")
    n = mesh.n_nodes
    linear = {k: c for k, c in todo.items() if k in _SCHEMES}
    quadratic = {k: c for k, c in todo.items() if k in _QUADRATIC}
    points, cells, parents = _split_linear(mesh.points, linear)
    more, quad_cells, quad_parents = _split_quadratic(mesh.points, quadratic, len(points))
    points = np.vstack([points, more])
    cells = {**mesh.cells, **cells, **quad_cells}
    parents += quad_parents
    cell_sets = {name: {k: _child_indices(idx, children_per_cell(k) if k in todo else 1)
                        for k, idx in by_kind.items()}
                 for name, by_kind in mesh.cell_sets.items()}
    node_sets = {name: extended_nodes(nodes, n, parents) for name, nodes in
                 mesh.node_sets.items()}
    return Mesh(points, cells, cell_sets, node_sets), parents


def _split_linear(coarse: np.ndarray, todo: dict) -> tuple[np.ndarray, dict, list]:
    """Points (coarse + new), refined cells and parents of the new nodes for the linear
    cell kinds ``todo`` (:data:`_SCHEMES`)."""
    n = len(coarse)
    edge_keys = [np.sort(c[:, list(_SCHEMES[k][0])], axis=2).reshape(-1, 2)
                 for k, c in todo.items()]
    face_keys = [np.sort(c[:, list(_SCHEMES[k][1])], axis=2).reshape(-1, 4)
                 for k, c in todo.items() if _SCHEMES[k][1]]
    edges, edge_id = _unique_rows(edge_keys, 2, n)
    from_line = np.concatenate([np.full(len(c) * len(_SCHEMES[k][0]), k == "line")
                                for k, c in todo.items()]) if todo else np.zeros(0, bool)
    line_only = np.ones(len(edges), dtype=bool)
    line_only[edge_id[~from_line] - n] = False
    faces, face_id = _unique_rows(face_keys, 4, n + len(edges))
    centres = [c for k, c in todo.items() if _SCHEMES[k][2]]
    parents = [edges, faces] + centres
    points = np.vstack([coarse] + [coarse[p].mean(axis=1) for p in parents])
    cells, offset_e, offset_f, offset_c = {}, 0, 0, n + len(edges) + len(faces)
    for kind, c in todo.items():
        n_edges, n_faces, centre, children = _SCHEMES[kind]
        local = [c, edge_id[offset_e:offset_e + len(c) * len(n_edges)].reshape(len(c), -1)]
        offset_e += len(c) * len(n_edges)
        if n_faces:
            local.append(face_id[offset_f:offset_f + len(c) * len(n_faces)].reshape(len(c), -1))
            offset_f += len(c) * len(n_faces)
        if centre:
            local.append(offset_c + np.arange(len(c))[:, None])
            offset_c += len(c)
        new = np.hstack(local)[:, np.array(children)]  # (n_cells, n_children, k)
        cells[kind] = _orient(points, kind, new.reshape(-1, new.shape[2]))
    parents[0] = np.where(line_only[:, None], -1, edges)
    return points, cells, parents


def _quad9_shapes(ref: np.ndarray) -> np.ndarray:
    """Biquadratic Lagrange shape functions (..., 9) of the VTK quad9 at ``ref`` (..., 2)."""
    nodes = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [0, -1], [1, 0], [0, 1], [-1, 0],
                      [0, 0]])

    def lagrange(t, a):
        return np.where(a == 0, 1 - t ** 2, 0.5 * t * (t + a))

    x, y = ref[..., 0, None], ref[..., 1, None]
    return lagrange(x, nodes[:, 0]) * lagrange(y, nodes[:, 1])


def _triangle6_shapes(ref: np.ndarray) -> np.ndarray:
    """Quadratic shape functions (..., 6) of the VTK triangle6 at ``ref`` (..., 2)."""
    x, y = ref[..., 0], ref[..., 1]
    a, b, c = 1 - x - y, x, y
    return np.stack([a * (2 * a - 1), b * (2 * b - 1), c * (2 * c - 1), 4 * a * b, 4 * b * c,
                     4 * c * a], axis=-1)


# quadratic cells: (reference coordinates of the nodes, shape functions, children as
# corner indices into the parent's nodes, a child's edges, child centre node?)
_QUADRATIC = {
    "quad9": (np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [0, -1], [1, 0], [0, 1], [-1, 0],
                        [0, 0]], dtype=float), _quad9_shapes,
              ((0, 4, 8, 7), (4, 1, 5, 8), (8, 5, 2, 6), (7, 8, 6, 3)),
              ((0, 1), (1, 2), (2, 3), (3, 0)), True),
    "triangle6": (np.array([[0, 0], [1, 0], [0, 1], [0.5, 0], [0.5, 0.5], [0, 0.5]]),
                  _triangle6_shapes, ((0, 3, 5), (3, 1, 4), (5, 4, 2), (3, 4, 5)),
                  ((0, 1), (1, 2), (2, 0)), False),
}


def _split_quadratic(coarse: np.ndarray, todo: dict, first: int
                     ) -> tuple[np.ndarray, dict, list]:
    """New points, refined cells and parents of the new nodes (ids from ``first``) for
    quadratic cells: each splits into 4 at its own nodes, and each child's mid-edge and
    centre nodes lie where the parent's quadratic map puts them (a curved cell stays
    curved). Child edges shared by neighbours make one node (sorted key)."""
    keys, where, centres, centre_at = [], [], [], []
    for kind, c in todo.items():
        ref, shapes, children, edges, centre = _QUADRATIC[kind]
        corners = c[:, np.array(children)]  # (m, n_children, n_corners)
        keys.append(np.sort(corners[:, :, np.array(edges)], axis=3).reshape(-1, 2))
        mid = ref[np.array(children)][:, np.array(edges)].mean(axis=2)  # (nc, ne, 2)
        where.append(np.einsum("cek,mkd->mced", shapes(mid), coarse[c]).reshape(-1, 3))
        if centre:
            centres.append(corners.reshape(-1, corners.shape[2]))
            at = ref[np.array(children)].mean(axis=1)  # (nc, 2)
            centre_at.append(np.einsum("ck,mkd->mcd", shapes(at), coarse[c]).reshape(-1, 3))
    if not keys:
        return np.empty((0, 3)), {}, []
    rows = np.concatenate(keys)
    unique, index, inverse = np.unique(rows, axis=0, return_index=True, return_inverse=True)
    edge_id = first + inverse.ravel()
    points = np.vstack([np.concatenate(where)[index]] + centre_at)
    cells, offset_e, offset_c = {}, 0, first + len(unique)
    for kind, c in todo.items():
        _, _, children, edges, centre = _QUADRATIC[kind]
        size = len(c) * len(children)
        local = [c[:, np.array(children)].reshape(size, -1),
                 edge_id[offset_e:offset_e + size * len(edges)].reshape(size, -1)]
        offset_e += size * len(edges)
        if centre:
            local.append(offset_c + np.arange(size)[:, None])
            offset_c += size
        cells[kind] = np.hstack(local)
    return points, cells, [unique] + centres


REFINABLE = tuple(_SCHEMES) + tuple(_QUADRATIC) + ("vertex",)
"""Cell kinds :func:`refine_mesh` splits (vertex cells are kept as they are)."""


def _unique_rows(keys: list, width: int, first: int) -> tuple[np.ndarray, np.ndarray]:
    """Unique sorted keys (m, width) and the new node id of each row of the concatenated
    ``keys`` (ids from ``first``, in the order of the unique keys)."""
    if not keys:
        return np.empty((0, width), dtype=np.int64), np.empty(0, dtype=np.int64)
    rows = np.concatenate(keys)
    unique, inverse = np.unique(rows, axis=0, return_inverse=True)
    return unique, first + inverse.ravel()


def _orient(points: np.ndarray, kind: str, cells: np.ndarray) -> np.ndarray:
    """Tetrahedra with a negative signed volume get two nodes swapped (the octahedron's
    children are listed without regard to orientation); other kinds pass unchanged."""
    if kind != "tetra":
        return cells
    p = points[cells]
    volume = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]),
                       p[:, 3] - p[:, 0])
    flip = volume < 0
    cells = cells.copy()
    cells[flip, 2], cells[flip, 3] = cells[flip, 3], cells[flip, 2].copy()
    return cells


def _child_indices(idx: np.ndarray, n_children: int) -> np.ndarray:
    """Indices of the children of cells ``idx`` (children of cell e at n_children e + j)."""
    return (np.asarray(idx)[:, None] * n_children + np.arange(n_children)).ravel()


def extended_nodes(nodes, n: int, parents: list) -> np.ndarray:
    """``nodes`` plus each new node all of whose parents are among them (new nodes
    numbered from ``n`` in the order of ``parents``: :func:`refine_with_parents`)."""
    nodes = np.atleast_1d(np.asarray(nodes, dtype=np.int64))
    member = np.zeros(n + 1, dtype=bool)  # member[-1]: the parent of line-only midpoints
    member[nodes] = True
    member[-1] = member[:n].all()
    inside = np.concatenate([member[p].all(axis=1) for p in parents]) if parents else \
        np.zeros(0, dtype=bool)
    return np.concatenate([nodes, n + np.flatnonzero(inside)])


def refined_model(model: FEModel, levels: int = 1) -> FEModel:
    """``model`` rebuilt on its mesh refined ``levels`` times (:func:`refine_mesh`).

    Uses the inputs ``build_model`` kept (:attr:`FEModel.inputs`): the same properties,
    masses, springs, supports and links; node indices stay valid because the coarse nodes
    keep theirs. Node lists given by index (supports, rigid-link slaves, interpolating
    patches without weights) gain the new nodes between their nodes, as node sets do.
    Model warnings are not repeated (the coarse build issued them).

    Raises
    ------
    ValueError
        If ``model`` was not made by :func:`femmech.build_model` (no inputs kept), or the
        rebuild fails (e.g. an interpolating link with weights on a patch given by a cell
        set, which gains nodes).
    """
    if not model.inputs:
        raise ValueError("refined_model: this FEModel keeps no build_model inputs (made by"
                         " another route); pass a build(mesh) function instead")
    if int(levels) < 1:
        raise ValueError(f"refined_model: levels must be >= 1, got {levels!r}")
    mesh, inputs = model.mesh, dict(model.inputs)
    for _ in range(int(levels)):
        n = mesh.n_nodes
        mesh, parents = refine_with_parents(mesh)
        inputs = _extended_inputs(inputs, n, parents)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        try:
            return build_model(mesh, **inputs)
        except ValueError as exc:
            raise ValueError(f"refined_model: rebuilding on the refined mesh failed: {exc}"
                             ) from None


def _extended_inputs(inputs: dict, n: int, parents: list) -> dict:
    """``build_model`` inputs with node index lists (of two or more nodes) extended by
    the new nodes between them (:func:`extended_nodes`); group names and single nodes
    pass unchanged (node sets are extended by :func:`refine_mesh`)."""
    def grow(ref):
        if isinstance(ref, str) or np.ndim(ref) == 0 or np.size(ref) < 2:
            return ref
        return extended_nodes(ref, n, parents)

    out = dict(inputs)
    out["supports"] = [replace(s, nodes=grow(s.nodes)) if isinstance(s, Support) else s
                       for s in inputs.get("supports", ())]
    out["rigid_links"] = [replace(r, slaves=grow(r.slaves)) if isinstance(r, RigidLink)
                          else r for r in inputs.get("rigid_links", ())]
    out["interpolating_links"] = [
        replace(i, patch=grow(i.patch)) if isinstance(i, InterpolatingLink)
        and i.weights is None else i for i in inputs.get("interpolating_links", ())]
    return out
