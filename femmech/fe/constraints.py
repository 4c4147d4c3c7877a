"""Supports and multi-point constraints, eliminated exactly by ``u = T u_free``.

* A rigid link (RBE2-like) ties slave nodes to a master node: for a slave at offset
  ``r = x_s - x_m``, ``u_s = u_m + θ_m × r`` and ``θ_s = θ_m`` (small rotations).
* An interpolating link (RBE3-like) makes a reference node follow the weighted
  least-squares rigid-body fit of the translations of a patch of nodes (a bearing bore,
  a bolt circle): ``u_ref = A u_patch`` with
  ``A = (Σ w_i S_iᵀ S_i)⁻¹ [w_1 S_1ᵀ ... w_n S_nᵀ]``, ``S_i = [I, -[r_i]×]``. It
  distributes a load on the reference node to the patch without stiffening it
  (MSC Nastran Quick Reference Guide, RBE3). Six patch DOFs, chosen by column-pivoted QR
  of A, become dependent, so the reference node stays an independent 6-DOF node that
  can serve as a superelement interface.

* An interpolated node follows a fixed linear combination of other nodes, component
  by component, ``u_c = Σ w_j u_j`` (the centre node that a quad8 skin on a solid face
  gets for the MITC9 element, its translations tied to the serendipity interpolation
  of the eight others: :func:`femmech.fe.mesh.quad8_centres`).

Every constraint is a set of equations ``u_dep = G u_indep``; chains (a link whose
master is the slave of another) are resolved by substitution. Fixed and dependent DOFs
are removed; the reduced matrices are ``Tᵀ K T`` and ``Tᵀ M T``, with no penalty
stiffness to spoil the conditioning.

Uses only fe.dofs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from femmech.fe.dofs import DOF_PER_NODE, components, dof_label


@dataclass(frozen=True)
class Support:
    """Fixed DOFs (zero displacement) at the nodes of a group or at given nodes.

    Attributes
    ----------
    nodes : str, int or sequence of int
        A node set or cell set name, a node index, or node indices.
    dofs : str or sequence
        Components to fix, see :func:`femmech.fe.dofs.components` (default ``"all"``).
    """

    nodes: object
    dofs: object = "all"


@dataclass(frozen=True)
class RigidLink:
    """Rigid body tying ``slaves`` to ``master`` (RBE2-like, all six DOFs).

    Attributes
    ----------
    master : int or str
        A node index or a group holding exactly one node.
    slaves : str, int or sequence of int
        A group name or node indices.
    """

    master: object
    slaves: object


@dataclass(frozen=True)
class InterpolatingLink:
    """Reference node following the average motion of a patch (RBE3-like).

    Attributes
    ----------
    reference : int or str
        A node index or a group holding exactly one node (6 DOFs; usually a node used
        by nothing else, e.g. a bearing centre).
    patch : str, int or sequence of int
        The patch nodes (at least three, not collinear); only their translations enter.
    weights : array_like (n_patch,), optional
        Non-negative weights (default equal), e.g. tributary areas.
    """

    reference: object
    patch: object
    weights: object = None


def rigid_link_matrix(offset: np.ndarray) -> np.ndarray:
    """Slave DOFs from master DOFs, shape (n, 6, 6), for offsets ``r`` (n, 3), m."""
    n = len(offset)
    G = np.tile(np.eye(6), (n, 1, 1))
    rx, ry, rz = offset.T
    # θ × r = [[0, rz, -ry], [-rz, 0, rx], [ry, -rx, 0]] θ
    G[:, 0, 4], G[:, 0, 5] = rz, -ry
    G[:, 1, 3], G[:, 1, 5] = -rz, rx
    G[:, 2, 3], G[:, 2, 4] = ry, -rx
    return G


def interpolation_matrix(reference: np.ndarray, patch: np.ndarray, weights=None) -> np.ndarray:
    """``A`` (6, 3 n) with ``u_ref = A u_patch`` (weighted least-squares rigid fit).

    Raises ValueError if the patch cannot determine all six reference DOFs (fewer than
    three nodes, or collinear nodes: the rotation about their line is undetermined).
    """
    r = patch - reference
    w = np.ones(len(patch)) if weights is None else np.asarray(weights, dtype=float)
    if w.shape != (len(patch),) or not np.all(np.isfinite(w)) or (w < 0).any() or w.sum() <= 0:
        raise ValueError(f"weights must be {len(patch)} non-negative numbers, not all zero")
    S = np.zeros((len(patch), 3, 6))
    S[:, :, :3] = np.eye(3)
    S[:, :, 3:] = rigid_link_matrix(r)[:, :3, 3:]  # θ × r_i
    normal = np.einsum("n,nai,naj->ij", w, S, S)
    size = max(np.abs(r).max(), 1e-300)
    scaled = normal / np.outer(_scales(size), _scales(size))
    if np.linalg.cond(scaled) > 1e10:
        raise ValueError("the patch does not determine all six DOFs of the reference node"
                         " (fewer than three nodes, or all on one line)")
    rhs = (w[:, None, None] * S).transpose(2, 0, 1).reshape(6, -1)
    return np.linalg.solve(normal, rhs)


def _scales(length: float) -> np.ndarray:
    return np.array([1.0, 1.0, 1.0, length, length, length])


@dataclass
class EquationSet:
    """Growing list of constraint equations ``u_dep = G u_indep`` in COO form."""

    rows: list
    cols: list
    vals: list
    owner: list  # one label per dependent DOF entry

    @classmethod
    def empty(cls) -> EquationSet:
        """No equations yet."""
        return cls([], [], [], [])

    def add(self, dep: np.ndarray, indep: np.ndarray, G: np.ndarray, label: str) -> None:
        """Add ``u[dep] = G u[indep]`` (dep (k,), indep (m,), G (k, m))."""
        r, c = np.meshgrid(dep, indep, indexing="ij")
        nz = G != 0
        self.rows.append(r[nz])
        self.cols.append(c[nz])
        self.vals.append(G[nz])
        self.owner.append((np.asarray(dep), label))

    def dependent(self) -> np.ndarray:
        """All dependent DOFs so far."""
        parts = [dep for dep, _ in self.owner]
        return np.concatenate(parts) if parts else np.empty(0, dtype=np.int64)


def add_rigid_links(eqs: EquationSet, points: np.ndarray, masters, slaves, labels) -> None:
    """Equations of rigid links, one master per slave node (vectorised over slaves)."""
    if len(slaves) == 0:
        return
    G = rigid_link_matrix(points[slaves] - points[masters])
    for m, s, g, label in zip(masters, slaves, G, labels, strict=True):
        eqs.add(DOF_PER_NODE * s + np.arange(6), DOF_PER_NODE * m + np.arange(6), g, label)


def add_interpolated_nodes(eqs: EquationSet, n_dof: int, nodes: np.ndarray,
                           parents: np.ndarray, weights: np.ndarray, comps,
                           blocked: np.ndarray, label: str) -> sp.csr_matrix:
    """Equations ``u_d[nodes[i]] = Σ_j weights[j] u_d[parents[i, j]]``, d in ``comps``.

    Vectorised over the nodes; each component d is tied to the same component of the
    parents. DOFs marked in ``blocked`` (n_dof,) are left out (fixed, already
    dependent, or the reference or master of a link: they keep their own equation).

    Parameters
    ----------
    eqs : EquationSet
        Appended to in place.
    n_dof : int
    nodes : ndarray (k,), int
        The interpolated nodes.
    parents : ndarray (k, p), int
        The nodes each one follows.
    weights : ndarray (p,)
        Interpolation weights (e.g. shape functions at the node's natural coordinates).
    comps : str or sequence
        The tied components, see :func:`femmech.fe.dofs.components`.
    blocked : ndarray (n_dof,), bool
    label : str
        Names the constraint in error messages.

    Returns
    -------
    scipy.sparse.csr_matrix (n_dof, n_dof)
        The substitution ``u = S u`` that these equations define: identity rows for the
        DOFs they leave alone, the weights for the tied ones (for
        :func:`add_interpolating_link`, whose patch may hold tied nodes).
    """
    comp = components(comps)
    dep = (DOF_PER_NODE * np.asarray(nodes)[:, None] + comp).ravel()  # (c k,)
    indep = (DOF_PER_NODE * np.asarray(parents)[:, None, :]
             + comp[None, :, None]).reshape(dep.size, -1)  # (c k, p)
    keep = ~blocked[dep]
    dep, indep = dep[keep], indep[keep]
    if dep.size:
        eqs.rows.append(np.repeat(dep, indep.shape[1]))
        eqs.cols.append(indep.ravel())
        eqs.vals.append(np.tile(np.asarray(weights, dtype=float), dep.size))
        eqs.owner.append((dep, label))
    rest = np.setdiff1d(np.arange(n_dof), dep)
    rows = np.concatenate([rest, np.repeat(dep, indep.shape[1])])
    cols = np.concatenate([rest, indep.ravel()])
    vals = np.concatenate([np.ones(rest.size), np.tile(np.asarray(weights, dtype=float),
                                                       dep.size)])
    return sp.csr_matrix((vals, (rows, cols)), shape=(n_dof, n_dof))


def add_interpolating_link(eqs: EquationSet, points: np.ndarray, reference: int,
                           patch: np.ndarray, weights, blocked: np.ndarray, label: str,
                           substitution: sp.spmatrix | None = None) -> None:
    """Equations of one RBE3-like link: six patch translations become dependent.

    ``blocked`` (n_dof,) marks DOFs that cannot be made dependent (fixed, or already
    dependent); the six are picked among the others by column-pivoted QR of A.
    ``substitution`` (n_dof, n_dof), from :func:`add_interpolated_nodes`: patch DOFs that
    are interpolated from other nodes enter through those nodes (``A`` becomes ``A S``),
    so that the link does not lean on a DOF that depends on its own dependent ones (a
    cycle). The patch's fit, and so the link, is the same.
    """
    try:
        A = interpolation_matrix(points[reference], points[patch], weights)
    except ValueError as exc:
        raise ValueError(f"{label}: {exc}") from None
    patch_dofs = (DOF_PER_NODE * patch[:, None] + np.arange(3)).ravel()
    if substitution is not None:
        S = sp.csr_matrix(substitution)[patch_dofs].tocsc()
        patch_dofs = np.flatnonzero(np.diff(S.indptr))  # the DOFs the patch rests on
        A = np.asarray((S[:, patch_dofs].T @ A.T).T)
    candidates = np.flatnonzero(~blocked[patch_dofs])
    if candidates.size < 6:
        raise ValueError(f"{label}: fewer than six patch DOFs are free to carry the link")
    _, R, piv = sla.qr(A[:, candidates], mode="economic", pivoting=True)
    if abs(R[5, 5]) <= 1e-10 * abs(R[0, 0]):
        raise ValueError(f"{label}: the free patch DOFs do not determine the reference node")
    dep_cols = candidates[piv[:6]]
    rest = np.setdiff1d(np.arange(A.shape[1]), dep_cols)
    Ad_inv = np.linalg.inv(A[:, dep_cols])
    ref_dofs = DOF_PER_NODE * reference + np.arange(6)
    G = np.hstack([Ad_inv, -Ad_inv @ A[:, rest]])
    eqs.add(patch_dofs[dep_cols], np.concatenate([ref_dofs, patch_dofs[rest]]), G, label)


def constraint_transform(n_dof: int, fixed: np.ndarray, eqs: EquationSet):
    """Sparse ``T`` (n_dof, n_free) with ``u = T u_free``, and the free DOF indices.

    Raises
    ------
    ValueError
        If a DOF is dependent in two constraints, a dependent DOF is also fixed, or the
        constraints form a cycle.
    """
    dep = eqs.dependent()
    labels = [label for d, label in eqs.owner for _ in range(len(d))]
    uniq, first, counts = np.unique(dep, return_index=True, return_counts=True)
    if (counts > 1).any():
        dof = uniq[counts > 1][0]
        who = [labels[i] for i in np.flatnonzero(dep == dof)]
        raise ValueError(f"{dof_label(int(dof))} is dependent in two constraints: {who[0]}"
                         f" and {who[1]}")
    clash = dep[fixed[dep]]
    if clash.size:
        raise ValueError(f"{dof_label(int(clash[0]))} is both supported and dependent in"
                         f" {labels[int(np.flatnonzero(dep == clash[0])[0])]}; support the"
                         " master/reference instead")
    is_dep = np.zeros(n_dof, dtype=bool)
    is_dep[dep] = True
    indep = np.flatnonzero(~is_dep)
    rows = np.concatenate([indep] + eqs.rows)
    cols = np.concatenate([indep] + eqs.cols)
    vals = np.concatenate([np.ones(indep.size)] + eqs.vals)
    E = sp.coo_matrix((vals, (rows, cols)), shape=(n_dof, n_dof)).tocsc()
    for _ in range(64):  # each product halves the remaining chain length
        if E[:, dep].nnz == 0:
            break
        E = (E @ E).tocsc()
        E.eliminate_zeros()
    else:
        raise ValueError("constraints form a cycle (e.g. two links that are each other's"
                         f" master), involving {dof_label(int(dep[0]))}")
    free = np.flatnonzero(~is_dep & ~fixed)
    return E[:, free].tocsr(), free


def fixed_mask(n_nodes: int, nodes: np.ndarray, spec) -> np.ndarray:
    """Boolean (n_nodes * 6,) mask of DOFs fixed at ``nodes`` for components ``spec``."""
    mask = np.zeros(n_nodes * DOF_PER_NODE, dtype=bool)
    comps = components(spec)
    mask[(DOF_PER_NODE * np.asarray(nodes)[:, None] + comps).ravel()] = True
    return mask
