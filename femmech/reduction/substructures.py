"""Assembly of several superelements and plain FE parts into one system.

Physical coordinates of different parts (superelement interface DOFs, or all free DOFs
of an unreduced :class:`~femmech.fe.model.FEModel`) are the same global DOF when their nodes
coincide (within ``tol`` times the overall size) and their components agree; modal
coordinates stay private to their superelement. The assembled matrices are sparse;
superelement blocks enter as dense blocks (primal assembly, Craig & Bampton 1968).

Stage 3 (reduction): imports :mod:`femmech.fe` and its own package.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from femmech.fe.dofs import COMPONENTS, DOF_PER_NODE
from femmech.fe.model import FEModel
from femmech.reduction.superelement import Superelement


@dataclass(frozen=True)
class Assembly:
    """Coupled system of parts.

    Attributes
    ----------
    K, M : scipy.sparse.csr_matrix (n, n)
        Assembled stiffness (N/m, N m/rad) and mass (kg, kg m²) in the global coordinates.
    parts : tuple of Superelement or FEModel
    part_dofs : tuple of ndarray
        Global index of each coordinate of each part (reduced coordinates of a
        superelement, free DOFs of an FE model).
    points : ndarray (n_physical, 3)
        Node position of each physical global DOF (the first ``n_physical`` globals).
    components : ndarray (n_physical,)
        Component (0..5 = ux..rz) of each physical global DOF.
    """

    K: sp.csr_matrix
    M: sp.csr_matrix
    parts: tuple
    part_dofs: tuple
    points: np.ndarray
    components: np.ndarray

    @property
    def n_dof(self) -> int:
        """Number of global coordinates."""
        return self.K.shape[0]

    def recover(self, q: np.ndarray, part: int) -> np.ndarray:
        """Full DOF vector(s) (n_dof_part, ...) of one part from global coordinates q."""
        q = np.asarray(q, dtype=float)
        if q.shape[0] != self.n_dof:
            raise ValueError(f"vector has {q.shape[0]} rows, the assembly has {self.n_dof}")
        local = q[self.part_dofs[part]]
        item = self.parts[part]
        return item.recover(local) if isinstance(item, Superelement) else item.expand(local)


def _coordinates(part):
    """(K, M, points, components, is_physical) of one part's coordinates."""
    if isinstance(part, Superelement):
        n_b = part.n_interface
        points = np.vstack([part.interface_points, np.full((part.n_modal, 3), np.nan)])
        comps = np.concatenate([part.interface_dofs % DOF_PER_NODE,
                                np.full(part.n_modal, -1)])
        physical = np.arange(part.n_reduced) < n_b
        return sp.coo_matrix(part.K), sp.coo_matrix(part.M), points, comps, physical
    if isinstance(part, FEModel):
        points = part.mesh.points[part.free // DOF_PER_NODE]
        physical = np.ones(part.n_free, dtype=bool)
        return (part.K_free.tocoo(), part.M_free.tocoo(), points, part.free % DOF_PER_NODE,
                physical)
    raise TypeError(f"parts must be Superelement or FEModel objects, got {type(part).__name__}")


def assemble_parts(parts, tol: float = 1e-9) -> Assembly:
    """Couple parts through coincident physical DOFs (primal assembly).

    Parameters
    ----------
    parts : sequence of Superelement or FEModel
    tol : float
        Nodes closer than ``tol`` times the largest extent of all parts coincide.

    Returns
    -------
    Assembly

    Raises
    ------
    ValueError
        If two DOFs of the same part would be merged (coincident nodes inside a part), or
        a part shares no DOF with any other part (a loose part is probably a mistake:
        assemble it separately).
    """
    parts = tuple(parts)
    if not parts:
        raise ValueError("no parts to assemble")
    for i, part in enumerate(parts):
        if getattr(part, "interface_basis", None) is not None:
            raise ValueError(f"part {i} has a reduced interface (interface modes, from"
                             " reduce_interface): its interface DOFs are not kept, so it"
                             " cannot be joined to other parts at coincident DOFs; reduce it"
                             " with craig_bampton for an assembly")
    data = [_coordinates(p) for p in parts]
    owner = np.concatenate([np.full(len(d[2]), i) for i, d in enumerate(data)])
    points = np.vstack([d[2] for d in data])
    comps = np.concatenate([d[3] for d in data])
    physical = np.concatenate([d[4] for d in data])
    labels = _match(points, comps, physical, owner, tol)
    n_global = labels.max() + 1
    starts = np.cumsum([0] + [len(d[2]) for d in data])
    part_dofs = tuple(labels[starts[i]:starts[i + 1]] for i in range(len(parts)))
    _check_connected(part_dofs, physical, starts)
    K = _scatter([d[0] for d in data], part_dofs, n_global)
    M = _scatter([d[1] for d in data], part_dofs, n_global)
    phys_labels = labels[physical]
    n_phys = phys_labels.max() + 1 if phys_labels.size else 0
    out_points = np.zeros((n_phys, 3))
    out_comps = np.zeros(n_phys, dtype=np.int64)
    out_points[phys_labels] = points[physical]
    out_comps[phys_labels] = comps[physical]
    return Assembly(K, M, parts, part_dofs, out_points, out_comps)


def _match(points, comps, physical, owner, tol):
    """Global label of every coordinate: physical ones clustered, modal ones unique."""
    idx = np.flatnonzero(physical)
    n_phys = idx.size
    finite = points[idx]
    scale = float(np.ptp(finite, axis=0).max()) if n_phys else 1.0
    pairs = cKDTree(finite).query_pairs(tol * max(scale, 1e-300), output_type="ndarray")
    pairs = pairs[comps[idx][pairs[:, 0]] == comps[idx][pairs[:, 1]]] if len(pairs) else pairs
    graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])),
                          shape=(n_phys, n_phys)) if len(pairs) else sp.coo_matrix(
                              (n_phys, n_phys))
    _, cluster = connected_components(graph, directed=False)
    same_part = owner[idx][pairs[:, 0]] == owner[idx][pairs[:, 1]] if len(pairs) else []
    if np.any(same_part):
        a, b = idx[pairs[np.flatnonzero(same_part)[0]]]
        raise ValueError(f"part {owner[a]} has two coincident {COMPONENTS[comps[a]]} DOFs at"
                         f" {points[a].tolist()}: cannot match parts by position there")
    labels = np.empty(len(points), dtype=np.int64)
    labels[idx] = cluster
    n_clusters = cluster.max() + 1 if n_phys else 0
    modal = np.flatnonzero(~physical)
    labels[modal] = n_clusters + np.arange(modal.size)
    return labels


def _check_connected(part_dofs, physical, starts):
    if len(part_dofs) < 2:
        return
    for i, dofs in enumerate(part_dofs):
        mine = dofs[physical[starts[i]:starts[i + 1]]]
        others = np.concatenate([d for j, d in enumerate(part_dofs) if j != i])
        if not np.isin(mine, others).any():
            raise ValueError(f"part {i} shares no DOF with the other parts (no coincident"
                             " interface nodes); check its interface or coordinates")


def _scatter(blocks, part_dofs, n):
    rows = np.concatenate([d[b.row] for b, d in zip(blocks, part_dofs, strict=True)])
    cols = np.concatenate([d[b.col] for b, d in zip(blocks, part_dofs, strict=True)])
    vals = np.concatenate([b.data for b in blocks])
    return sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsr()
