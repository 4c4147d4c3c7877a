"""Supports and rigid links, eliminated exactly by a sparse transformation ``u = T u_free``.

A rigid link ties slave nodes to a master node: for a slave at offset ``r = x_s - x_m``,
``u_s = u_m + θ_m × r`` and ``θ_s = θ_m`` (small rotations). Fixed DOFs and slave DOFs
are removed; the reduced matrices are ``Tᵀ K T`` and ``Tᵀ M T``, so no penalty
stiffness spoils the conditioning.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from femmech.dofs import COMPONENTS, DOF_PER_NODE, components


@dataclass(frozen=True)
class Support:
    """Fixed DOFs (zero displacement) at the nodes of a group or at given nodes.

    Attributes
    ----------
    nodes : str, int or sequence of int
        A node set or cell set name, a node index, or node indices.
    dofs : str or sequence
        Components to fix, see :func:`femmech.dofs.components` (default ``"all"``).
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


def constraint_transform(points: np.ndarray, fixed: np.ndarray, masters: np.ndarray,
                         slaves: np.ndarray):
    """Sparse ``T`` (n_dof, n_free) with ``u = T u_free`` and the free DOF indices.

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    fixed : ndarray of bool (n_dof,)
        Fixed DOFs.
    masters, slaves : ndarray (n_pairs,), int
        Master node of each slave node.

    Raises
    ------
    ValueError
        If a node is the slave of two links, a master is itself a slave, or a slave
        DOF is also fixed.
    """
    n_dof = fixed.size
    is_slave = np.zeros(len(points), dtype=bool)
    uniq, counts = np.unique(slaves, return_counts=True)
    if (counts > 1).any():
        raise ValueError(f"node {uniq[counts > 1][0]} is a slave of more than one rigid link")
    is_slave[slaves] = True
    if is_slave[masters].any():
        node = masters[is_slave[masters]][0]
        raise ValueError(f"node {node} is the master of one rigid link and a slave of another;"
                         " merge the links into one")
    slave_dofs = (DOF_PER_NODE * slaves[:, None] + np.arange(6)).ravel()
    clash = slave_dofs[fixed[slave_dofs]]
    if clash.size:
        raise ValueError(f"node {clash[0] // 6} {COMPONENTS[clash[0] % 6]} is both supported"
                         " and the slave of a rigid link; support the master instead")
    dependent = fixed.copy()
    dependent[slave_dofs] = True
    free = np.flatnonzero(~dependent)
    column = np.full(n_dof, -1)
    column[free] = np.arange(free.size)
    rows = [free]
    cols = [np.arange(free.size)]
    vals = [np.ones(free.size)]
    if slaves.size:
        G = rigid_link_matrix(points[slaves] - points[masters])
        r = np.repeat(DOF_PER_NODE * slaves[:, None] + np.arange(6), 6, axis=1).ravel()
        m = np.tile(DOF_PER_NODE * masters[:, None] + np.arange(6), (1, 6)).ravel()
        keep = (column[m] >= 0) & (G.ravel() != 0)
        rows.append(r[keep])
        cols.append(column[m][keep])
        vals.append(G.ravel()[keep])
    T = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(n_dof, free.size)).tocsr()
    return T, free


def fixed_mask(n_nodes: int, nodes: np.ndarray, spec) -> np.ndarray:
    """Boolean (n_nodes * 6,) mask of DOFs fixed at ``nodes`` for components ``spec``."""
    mask = np.zeros(n_nodes * DOF_PER_NODE, dtype=bool)
    comps = components(spec)
    mask[(DOF_PER_NODE * np.asarray(nodes)[:, None] + comps).ravel()] = True
    return mask
