"""Stage 3: dense-block products of the reduction, fast for tall blocks of any width.

The reduction multiplies tall dense blocks (n_i x n_b constraint modes, n_i x n_q modes)
with sparse matrices and with each other. These helpers choose the BLAS thread phase by
the size of the product, keep blocks in C order for scipy's sparse products, update in
place without temporaries of full block size, and form symmetric products from the
blocks on and above the diagonal only.

Imports :mod:`femmech.solve`.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from femmech.solve import threads

THIN_PRODUCT_FLOPS = 1e9
"""Products of n_i x m blocks to m x m matrices (residual vectors, projection) below this
many flops (``2 n_i m²``) run on one BLAS thread (:func:`femmech.solve.threads.solve_phase`),
larger ones on all (``factor_phase``). Thin products gain nothing from a second thread
and stall when another process loads the core: OpenBLAS took 0.68 s instead of 4 ms for
one 28 x 58 692 by 58 692 x 28 product with two threads on this 2-core machine under
load; with ~1000 interface DOFs the products are true GEMMs (2e10-3e11 flops) that two
threads run nearly twice as fast."""


def product_phase(n_rows: int, n_cols: int):
    """Thread phase for products of an (n_rows, n_cols) block with its transpose."""
    if 2.0 * n_rows * n_cols**2 < THIN_PRODUCT_FLOPS:
        return threads.solve_phase()
    return threads.factor_phase()


def rows_contiguous(X, scale: float = 1.0):
    """``scale X`` in C order (one copy at most).

    scipy's sparse-times-dense product copies an F-ordered block to C order and is slow
    on it: ``M_ii Ψ`` with Ψ 151 200 x 1 002 took 4.3 s from F order and 0.53 s from C
    order (plus 0.41 s for the conversion). Factor solves return F order (PARDISO solves
    column by column)."""
    out = X if X.flags.c_contiguous else np.ascontiguousarray(X)
    if scale != 1.0:
        out = np.multiply(out, scale, out=out if out is not X else None)
    return out


def subtract_product(X, A, B):
    """``X -= A B`` in place, without the (n, m) temporary of ``A @ B`` (BLAS gemm with
    beta = 1 on the F-ordered view ``Xᵀ`` of a C-ordered X)."""
    if X.flags.c_contiguous and X.dtype == np.float64:
        out = sla.blas.dgemm(-1.0, np.asarray(B, dtype=float).T, np.asarray(A, dtype=float).T,
                             beta=1.0, c=X.T, overwrite_c=True)
        if np.shares_memory(out, X):
            return X
        X[...] = out.T
        return X
    X -= A @ B
    return X


def plus_sparse(A, S):
    """``A + S`` for dense A (updated in place) and sparse S, without a dense copy of S."""
    S = S.tocoo()
    np.add.at(A, (S.row, S.col), S.data)
    return A


SYMMETRIC_BLOCK = 256
"""Column block of :func:`symmetric_product`: ``AᵀB`` of n_b > this many columns is
formed from the blocks on and above the diagonal only."""


def symmetric_product(A, B):
    """``AᵀB`` (m, m) for (n, m) blocks whose product is symmetric (``A = Ψ``,
    ``B = M_ii Ψ``), from the column blocks i <= j only (the lower ones are transposes):
    with m = 1 002 (4 blocks), 10 of 16 block products, 63 % of the flops of one GEMM."""
    m = A.shape[1]
    if m <= SYMMETRIC_BLOCK:
        return A.T @ B
    cuts = np.linspace(0, m, -(-m // SYMMETRIC_BLOCK) + 1).astype(int)
    C = np.empty((m, m))
    for lo, hi in zip(cuts[:-1], cuts[1:], strict=True):
        C[lo:hi, lo:] = A[:, lo:hi].T @ B[:, lo:]
        C[hi:, lo:hi] = C[lo:hi, hi:].T
    return C
