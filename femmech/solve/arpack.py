"""Shift-invert Lanczos by ARPACK (``scipy.sparse.linalg.eigsh``): the eigenpairs nearest
a shift, with found eigenvectors deflated (band searches, and the fallback where block
Lanczos does not converge), and the purification of eigenvectors of a singular M.

Stage 1, solve (linear algebra): imports only :mod:`femmech.errors` and other
:mod:`femmech.solve` modules, never :mod:`femmech.fe` or higher.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from femmech.solve import threads
from femmech.solve.pencil import n_mass


def arpack(K, M, k, sigma, lu, deflate=None, maxiter=None):
    """``k`` eigenpairs nearest ``sigma`` by shift-invert Lanczos (ARPACK).

    ``deflate`` (n, m), M-orthonormal eigenvectors already found, is projected out of the
    start vector and of every operator application (``P (K - σM)⁻¹`` with
    ``P = I - X Xᵀ M``), so the run finds further members of a repeated eigenvalue that a
    single Krylov sequence cannot see.

    The Krylov space of ``(K - σM)⁻¹ M`` has at most as many dimensions as M has DOFs
    with mass (a singular M: massless DOFs), less the deflated vectors; ARPACK's
    basis size ``ncv`` (and k below it) is capped there, where the default
    ``max(2k + 1, 20)`` made ARPACK stop with "could not build an Arnoldi factorization".
    ``maxiter``: ARPACK's cap on restarts (default scipy's, 10 n); beyond it
    ``scipy.sparse.linalg.ArpackNoConvergence`` is raised.
    """
    n = K.shape[0]
    krylov = n_mass(M) - (0 if deflate is None else deflate.shape[1])
    k = min(k, krylov - 1)
    if k < 1:
        raise ValueError(f"no further finite eigenvalue: only {n_mass(M)} of the {n} DOFs"
                         " carry mass")
    ncv = min(n, max(2 * k + 1, 20), krylov)
    v0 = np.random.default_rng(12345).standard_normal(n)
    solve = lu.solve
    if deflate is not None and deflate.shape[1]:
        MX = M @ deflate

        def solve(v):
            y = lu.solve(v)
            return y - deflate @ (MX.T @ y)

        v0 = v0 - deflate @ (MX.T @ v0)
    op = spla.LinearOperator((n, n), matvec=solve, dtype=float)
    with threads.solve_phase():  # a loop of solves: 1 BLAS thread (femmech.solve.threads)
        omega2, X = spla.eigsh(sp.csr_matrix(K), k=k, M=sp.csr_matrix(M), sigma=sigma,
                               which="LM", OPinv=op, v0=v0, ncv=ncv, maxiter=maxiter)
    if krylov + (0 if deflate is None else deflate.shape[1]) < n:
        X = purify(X, omega2, sigma, M, solve)
    order = np.argsort(omega2)
    return omega2[order], X[:, order]


def purify(X, omega2, sigma, M, solve):
    """One operator step ``x ← (λ - σ) (K - σM)⁻¹ M x`` for a singular M (massless DOFs).

    Lanczos vectors are M-orthonormal, and M does not see components in its null space:
    the computed eigenvectors carry such components unchecked (measured residuals of 1e46
    and more on a lumped-mass beam). One step of the operator removes them and leaves
    true eigenvectors unchanged (B. Nour-Omid, B. N. Parlett, T. Ericsson, P. S. Jensen,
    "How to implement the spectral transformation", Math. Comp. 48 (1987) 663-673).
    """
    return solve(M @ X) * (omega2 - sigma)


