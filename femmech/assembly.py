"""Scatter batched element matrices into one sparse matrix (single COO → CSR)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def assemble(blocks, n_dof: int) -> sp.csr_matrix:
    """Sum element matrices into a sparse (n_dof, n_dof) CSR matrix.

    Parameters
    ----------
    blocks : iterable of (dofs, matrices)
        ``dofs`` int array (n_elements, n_ldof) and ``matrices`` (n_elements, n_ldof,
        n_ldof). All blocks are concatenated and converted once; duplicates are summed.
    n_dof : int
        Size of the global matrix.
    """
    rows, cols, vals = [], [], []
    for dofs, mats in blocks:
        if len(dofs) == 0:
            continue
        n_ldof = dofs.shape[1]
        rows.append(np.repeat(dofs, n_ldof, axis=1).ravel())
        cols.append(np.tile(dofs, (1, n_ldof)).ravel())
        vals.append(np.asarray(mats, dtype=float).ravel())
    if not rows:
        return sp.csr_matrix((n_dof, n_dof))
    matrix = sp.coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(n_dof, n_dof),
    ).tocsr()
    matrix.sum_duplicates()
    return matrix
