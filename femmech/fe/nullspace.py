"""Stage 2: the rigid-body modes of an FE model, the near-nullspace of its multigrid.

Maps the global DOF numbering (``DOF_PER_NODE * node + component``,
:mod:`femmech.fe.dofs`) to the arrays :mod:`femmech.solve.lobpcg` works on: each DOF's
node coordinates, component and node, so that the solver sees arrays only.

Imports :mod:`femmech.fe.dofs` and :mod:`femmech.solve.lobpcg`.
"""

from __future__ import annotations

import numpy as np

from femmech.fe.dofs import DOF_PER_NODE
from femmech.solve.lobpcg import node_blocks, rigid_body_vectors


def rigid_body_modes(points: np.ndarray, dofs: np.ndarray, center=None) -> np.ndarray:
    """Rigid-body motions on the given DOFs, (n_dofs, 6): ux, uy, uz, rx, ry, rz.

    Parameters
    ----------
    points : ndarray (n_nodes, 3)
        Node coordinates, m.
    dofs : ndarray (n_dofs,) of int
        Global DOF indices ``6 * node + component`` (components ux, uy, uz, rx, ry, rz).
    center : array_like (3,), optional
        Centre of the rotations, m; default: centroid of the DOFs' nodes.

    Returns
    -------
    ndarray (n_dofs, 6)
        As :func:`femmech.solve.lobpcg.rigid_body_vectors`.

    Raises
    ------
    ValueError
        Naming the first DOF whose node is not one of the points.
    """
    points = np.asarray(points, dtype=float)
    dofs = np.asarray(dofs, dtype=int)
    node, comp = np.divmod(dofs, DOF_PER_NODE)
    if dofs.size and (node.min() < 0 or node.max() >= len(points)):
        raise ValueError(f"DOF {int(dofs[(node < 0) | (node >= len(points))][0])} refers to"
                         f" a node outside the {len(points)} points")
    return rigid_body_vectors(points[node], comp, center)


def near_nullspace(model) -> np.ndarray:
    """Rigid-body modes of an FE model on its free DOFs, (n_free, 6)."""
    return rigid_body_modes(model.mesh.points, model.free)


def node_blocksize(dofs: np.ndarray) -> int:
    """6 or 3 if the global DOFs ``dofs`` (n_dofs,) come in complete consecutive node
    blocks of that size, else 1 (:func:`femmech.solve.lobpcg.node_blocks`)."""
    node, comp = np.divmod(np.asarray(dofs, dtype=int), DOF_PER_NODE)
    return node_blocks(node, comp)
