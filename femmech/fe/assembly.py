"""Scatter batched element matrices into one sparse matrix (single COO → CSR).

Element DOFs that come in whole nodes (``6 node + 0..5``, as for every element, point
mass and spring of :func:`femmech.fe.model.build_model`) are summed as 6 x 6 node blocks:
sorting the ``n_elements × nodes²`` block keys instead of the ``n_elements × n_ldof²``
entries sorts 36 times fewer keys.
The result is the same CSR matrix either way (same pattern, explicit zeros of the element
matrices included; sums equal up to the order of the terms).

Uses only fe.dofs.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from femmech.fe.dofs import DOF_PER_NODE


def assemble(blocks, n_dof: int) -> sp.csr_matrix:
    """Sum element matrices into a sparse (n_dof, n_dof) CSR matrix.

    Parameters
    ----------
    blocks : iterable of (dofs, matrices)
        ``dofs`` int array (n_elements, n_ldof) and ``matrices`` (n_elements, n_ldof,
        n_ldof). All blocks are concatenated and converted once; duplicates are summed.
    n_dof : int
        Size of the global matrix.

    Returns
    -------
    scipy.sparse.csr_matrix (n_dof, n_dof)
        In canonical format (sorted indices, no duplicates).
    """
    blocks = [(np.asarray(dofs), mats) for dofs, mats in blocks if len(dofs)]
    if not blocks:
        return sp.csr_matrix((n_dof, n_dof))
    if n_dof % DOF_PER_NODE == 0 and all(_whole_nodes(dofs) for dofs, _ in blocks):
        matrix = _assemble_node_blocks(blocks, n_dof)
    else:
        matrix = _assemble_entries(blocks, n_dof)
    matrix.sum_duplicates()  # no-op for canonical input; sets the canonical flag
    return matrix


def _whole_nodes(dofs: np.ndarray) -> bool:
    """True if each row of ``dofs`` lists whole nodes, ``6 node + (0, 1, ..., 5)``."""
    b = DOF_PER_NODE
    if dofs.ndim != 2 or dofs.shape[1] % b:
        return False
    d = dofs.reshape(len(dofs), -1, b)
    return bool(np.all(d[..., 0] % b == 0) and np.all(d - d[..., :1] == np.arange(b)))


def _assemble_node_blocks(blocks, n_dof: int) -> sp.csr_matrix:
    """Sum node blocks (b x b) by sorted block keys, then convert BSR → CSR."""
    b = DOF_PER_NODE
    n_nodes = n_dof // b
    keys, data = [], []
    for dofs, mats in blocks:
        n, k = len(dofs), dofs.shape[1] // b
        nodes = dofs[:, ::b] // b
        keys.append((nodes[:, :, None] * n_nodes + nodes[:, None, :]).ravel())
        mats = np.asarray(mats, dtype=float).reshape(n, k, b, k, b)
        data.append(mats.transpose(0, 1, 3, 2, 4).reshape(-1, b, b))
    key = np.concatenate(keys)
    order = np.argsort(key, kind="stable")
    key = key[order]
    first = np.flatnonzero(np.concatenate([[True], key[1:] != key[:-1]]))
    # sum the blocks of each key as a sparse 0/1 matrix times the stacked blocks (C loops,
    # terms in element order)
    select = sp.csr_matrix((np.ones(key.size), order, np.append(first, key.size)),
                           shape=(first.size, key.size))
    stacked = data[0] if len(data) == 1 else np.concatenate(data)
    values = (select @ stacked.reshape(key.size, b * b)).reshape(-1, b, b)
    block_row, block_col = np.divmod(key[first], n_nodes)
    indptr = np.concatenate([[0], np.cumsum(np.bincount(block_row, minlength=n_nodes))])
    return sp.bsr_matrix((values, block_col, indptr), shape=(n_dof, n_dof)).tocsr()


def _assemble_entries(blocks, n_dof: int) -> sp.csr_matrix:
    """General path: one COO entry per element-matrix entry."""
    rows, cols, vals = [], [], []
    for dofs, mats in blocks:
        n_ldof = dofs.shape[1]
        rows.append(np.repeat(dofs, n_ldof, axis=1).ravel())
        cols.append(np.tile(dofs, (1, n_ldof)).ravel())
        vals.append(np.asarray(mats, dtype=float).ravel())
    return sp.coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(n_dof, n_dof),
    ).tocsr()
