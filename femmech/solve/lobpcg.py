"""Lowest eigenpairs of very large models by AMG-preconditioned LOBPCG, without a factorisation.

For solid models of millions of DOFs the sparse factor of ``K - σM`` (fill grows like
n^(4/3) to n^(5/3) in 3-D) no longer fits in memory. LOBPCG (A. V. Knyazev, "Toward the
optimal preconditioned eigensolver: locally optimal block preconditioned conjugate
gradient method", SIAM J. Sci. Comput. 23 (2001) 517-541; ``scipy.sparse.linalg.lobpcg``)
needs only products with K and M and a preconditioner approximating ``K⁻¹``: here one
V-cycle of smoothed-aggregation algebraic multigrid (pyamg; P. Vaněk, J. Mandel,
M. Brezina, "Algebraic multigrid by smoothed aggregation for second and fourth order
elliptic problems", Computing 56 (1996) 179-196) of ``K - σM`` (σ < 0, so that free-free
models work), with the rigid-body modes as near-nullspace: 3 translations and 3 rotations
about the centroid, evaluated at the nodes' coordinates on each free DOF (6 components for
beam/shell nodes, the 3 translations for solid nodes whose rotations are not DOFs).
Memory is O(nnz(K)), time per iteration O(nnz(K) · block size).

No Sturm count is possible without a factorisation: the result is checked by its
residuals only (:attr:`femmech.solve.eigen.EigenResult.sturm_count` is None). LOBPCG converges to
the lowest eigenvalues from a random start in practice, but a mode can in principle be
missed; use shift-invert (:func:`femmech.solve.eigen.solve_symmetric`) where memory allows.

Stage 1, solve (linear algebra): sees sparse matrices and arrays only (the node
coordinates and component of each DOF); the rigid-body modes of an FE model are
:func:`femmech.fe.nullspace.near_nullspace`. Imports only :mod:`femmech.errors` and
other :mod:`femmech.solve` modules, never :mod:`femmech.fe` or higher.
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from femmech.errors import FemmechWarning
from femmech.solve.eigen import EigenResult
from femmech.solve.pencil import eigenvalue_scale
from femmech.solve.residuals import normalize_modes, residuals


def rigid_body_vectors(x: np.ndarray, component: np.ndarray, center=None) -> np.ndarray:
    """Rigid-body motions on a set of DOFs, (n_dofs, 6): ux, uy, uz, rx, ry, rz.

    Parameters
    ----------
    x : ndarray (n_dofs, 3)
        Coordinates of each DOF's node, m.
    component : ndarray (n_dofs,) of int
        Each DOF's component: 0, 1, 2 translations ux, uy, uz; 3, 4, 5 rotations rx, ry, rz.
    center : array_like (3,), optional
        Centre of the rotations, m; default: centroid of ``x`` (keeps the columns well
        conditioned).

    Returns
    -------
    ndarray (n_dofs, 6)
        Column k is a unit translation (k < 3) or a unit rotation (rad) about axis k - 3:
        translation DOFs get ``θ × (x - c)``, rotation DOFs get θ.
    """
    x = np.asarray(x, dtype=float)
    comp = np.asarray(component, dtype=int)
    c = x.mean(axis=0) if center is None else np.asarray(center, dtype=float)
    r = x - c
    B = np.zeros((comp.size, 6))
    trans = comp < 3
    B[trans, comp[trans]] = 1.0
    for axis in range(3):
        theta = np.zeros(3)
        theta[axis] = 1.0
        move = np.cross(theta, r)  # (n_dofs, 3): displacement of each DOF's node
        B[trans, 3 + axis] = move[trans, comp[trans]]
        B[~trans, 3 + axis] = (comp[~trans] - 3 == axis).astype(float)
    return B


def node_blocks(node: np.ndarray, component: np.ndarray) -> int:
    """6 or 3 if the DOFs come in complete node blocks of that size, else 1.

    ``node`` and ``component`` (n_dofs,) give each DOF's node and component (0..5); a
    block is ``size`` consecutive DOFs of one node with consecutive components (a
    beam/shell node has 6, a solid node 3). Aggregating whole nodes (pyamg on a BSR
    matrix) keeps the components of a node together; constraints that remove single
    components leave scalar aggregation.
    """
    node = np.asarray(node, dtype=int)
    comp = np.asarray(component, dtype=int)
    for size in (6, 3):
        if node.size % size:
            continue
        same = node.reshape(-1, size)
        if np.all(same == same[:, :1]) and np.all(np.diff(comp.reshape(-1, size), axis=1) == 1):
            return size
    return 1


def amg_preconditioner(A, B: np.ndarray | None = None, blocksize: int = 1):
    """One smoothed-aggregation V-cycle of A (n × n, symmetric positive definite).

    Parameters
    ----------
    A : sparse matrix (n, n)
    B : ndarray (n, m), optional
        Near-nullspace (rigid-body modes); default: constant vector.
    blocksize : int
        DOFs per node for block aggregation (see :func:`node_blocks`).

    Returns
    -------
    scipy.sparse.linalg.LinearOperator approximating ``A⁻¹``
    """
    import pyamg

    A = sp.csr_matrix(A)
    if blocksize > 1:
        A = A.tobsr(blocksize=(blocksize, blocksize))
    ml = pyamg.smoothed_aggregation_solver(A, B=B, symmetry="symmetric", max_coarse=500)
    return ml.aspreconditioner(cycle="V")


def lobpcg_symmetric(K, M, n_modes: int, B: np.ndarray | None = None, blocksize: int = 1,
                     rtol: float = 1e-8, maxiter: int = 500, extra: int | None = None,
                     seed: int = 12345) -> EigenResult:
    """Lowest ``n_modes`` eigenpairs of ``K x = λ M x`` by AMG-preconditioned LOBPCG.

    Parameters
    ----------
    K, M : sparse (n, n)
        Symmetric stiffness (positive semi-definite) and mass (positive definite on the
        DOFs with stiffness; LOBPCG needs an M without massless DOFs).
    n_modes : int
        Number of lowest eigenpairs.
    B : ndarray (n, m), optional
        Near-nullspace of K for the multigrid (:func:`rigid_body_vectors`; of an FE
        model: :func:`femmech.fe.nullspace.near_nullspace`).
    blocksize : int
        DOFs per node for block aggregation (:func:`node_blocks`).
    rtol : float
        Convergence tolerance of LOBPCG's residual norms ``‖K x / s - μ M x‖`` (``s``:
        :func:`~femmech.solve.pencil.eigenvalue_scale`, ``μ = λ / s``, ``xᵀMx = 1``).
        Eigenvalue errors go like its square: on a 2 100-DOF solid block 1e-8 gave
        frequencies within 1e-12 of shift-invert, 1e-6 within 3e-8 (tests/test_solvers.py).
    maxiter : int
        LOBPCG iterations at most.
    extra : int, optional
        Additional block vectors (default ``max(4, n_modes // 2)``): they speed up the
        convergence of the wanted ones and guard against a missed mode near the top.
    seed : int
        Start block (deterministic).

    Returns
    -------
    EigenResult
        ``method="lobpcg"``, ``solver="pyamg"``, ``sigma``: the shift of the multigrid
        matrix ``K - σM``; ``sturm_count`` None; ``residual`` as in
        :func:`~femmech.solve.residuals.residuals`. A FemmechWarning is issued if LOBPCG
        stopped before reaching ``rtol``.
    """
    n = K.shape[0]
    if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) \
            or not 0 < n_modes < n:
        raise ValueError(f"n_modes must be an integer in 1..{n - 1}, got {n_modes!r}")
    if np.any(np.asarray(M.diagonal()) <= 0):
        raise ValueError("LOBPCG needs mass on every DOF (M positive definite); condense"
                         " massless DOFs or use shift-invert (solve_symmetric)")
    scale = eigenvalue_scale(K, M)
    sigma = -1e-6 * scale
    extra = max(4, n_modes // 2) if extra is None else int(extra)
    m = min(n_modes + extra, n // 5 or 1)
    if m < n_modes:
        raise ValueError(f"{n_modes} modes of a {n}-DOF system: too many for LOBPCG, use"
                         " solve_symmetric")
    # scaled pencil: K/scale has eigenvalues ~1 where the modes of interest are ~1e-6..1
    Ks = sp.csr_matrix(K) / scale
    Ms = sp.csr_matrix(M)
    precond = amg_preconditioner((K - sigma * M) / scale, B, blocksize)
    X0 = np.random.default_rng(seed).standard_normal((n, m))
    if B is not None:  # rigid-body motions: the exact lowest modes of a free-free model
        X0[:, :min(B.shape[1], m)] = B[:, :m]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # "not reaching the requested tolerance"
        lam, X, history = spla.lobpcg(Ks, X0, B=Ms, M=precond, tol=rtol, maxiter=maxiter,
                                      largest=False, retResidualNormsHistory=True)
    order = np.argsort(lam)
    omega2 = lam[order][:n_modes] * scale
    X = normalize_modes(X[:, order][:, :n_modes], M)
    res = residuals(K, M, omega2, X, 1e-6 * scale)
    reached = float(np.max(np.asarray(history[-1])[order][:n_modes]))
    if not reached <= rtol:
        warnings.warn(f"LOBPCG stopped after {len(history)} iterations with a residual of"
                      f" {reached:.2e} > rtol = {rtol:.0e}; raise maxiter or use shift-invert",
                      FemmechWarning, stacklevel=2)
    return EigenResult(omega2, X, "lobpcg", sigma, res, None, None, solver="pyamg")


def __getattr__(name: str):
    """Names this module had that read the FE model's DOF numbering, from their new place
    in stage 2 (docs/architecture.md, "Moved names")."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "DOF_PER_NODE": "femmech.fe.dofs.DOF_PER_NODE",
        "near_nullspace": "femmech.fe.nullspace.near_nullspace",
        "node_blocksize": "femmech.fe.nullspace.node_blocksize",
        "rigid_body_modes": "femmech.fe.nullspace.rigid_body_modes",
    })
