"""Stage 3: Guyan and Craig-Bampton reduction of an FE model to a superelement.

The free DOFs of an :class:`~femmech.fe.model.FEModel` (after supports and rigid links)
are split into interface DOFs ``b`` (kept physically: bearings, mounts, joints to other
substructures) and interior DOFs ``i``. With ``K_ii`` factorised once,

* constraint modes ``Ψ = -K_ii⁻¹ K_ib`` (static response to unit interface motions),
* fixed-interface normal modes ``K_ii Φ = M_ii Φ Λ`` (shift-invert at σ = 0, reusing the
  same factorisation), mass-normalised,

give the Craig-Bampton basis ``u = [[I, 0], [Ψ, Φ]] [u_b; η]`` (R. R. Craig and
M. C. C. Bampton, "Coupling of substructures for dynamic analyses", AIAA J. 6 (1968)
1313-1319); Guyan's static condensation (R. J. Guyan, AIAA J. 3 (1965) 380) is the case
without Φ. The reduced matrices are ``Tᵀ K T`` and ``Tᵀ M T``; ``K_r`` is block diagonal
``diag(K_bb + K_bi Ψ, Λ)``. Only the tall dense bases (n_i × n_b, n_i × n_q) are formed,
never a dense matrix of full-model size.

The dense-block products (thread phases, in-place updates, symmetric products) are in
:mod:`femmech.reduction.products`; the a-posteriori error estimate of the reduced
frequencies in :mod:`femmech.reduction.estimate`.

Imports :mod:`femmech.fe`, :mod:`femmech.solve` and its own package.
"""

from __future__ import annotations

import time

import numpy as np

from femmech.fe.dofs import DOF_PER_NODE, dof_label
from femmech.fe.model import FEModel
from femmech.reduction.products import (
    plus_sparse,
    product_phase,
    rows_contiguous,
    subtract_product,
    symmetric_product,
)
from femmech.reduction.superelement import Superelement, interface_dofs
from femmech.solve.eigen import solve_symmetric, sturm_verified
from femmech.solve.pencil import factorize

CUTOFF_FACTOR = 2.0
"""Default cutoff of fixed-interface modes as a multiple of the highest frequency of
interest (``f_max_hz``). With residual vectors (the default) the modes below f_max of the
shipped machine frame are accurate to 1.4e-6; plain Craig-Bampton
(``residual_vectors=False``) reaches only 1.4e-2 there and needs about 6 f_max for 0.1 %
(tests/test_reduction.py, benchmarks/reduction.py)."""

LOW_MEMORY_DOFS = 500_000
"""From this many interior DOFs, :func:`craig_bampton` (with ``n_modes``) frees the
``K_ii`` factorisation before the Sturm check of the fixed-interface modes, so that two
factorisations are never held at once, and the superelement keeps none
(``interior_factor`` is None: error estimates factorise again when asked). Measured on a
1 008 150-DOF MITC4 box with 4 interface nodes (30 modes + residual vectors): peak resident
memory 8.5 GB with both factorisations alive (the count's factor of ``K_ii - cut M_ii``
on top of the shift factor, 2.0-2.5 GB each), 7.1 GB with this order (the Lanczos basis
of the fixed-interface modes is then the peak; the superelement afterwards 2.7 GB less)."""

KEEP_RESPONSE_BYTES = 256e6
"""Craig-Bampton with residual vectors keeps the solved ``K_ii⁻¹ (M_ii Ψ + M_ib)``
(n_i × n_b) on the superelement (``inertia_response``) up to this size in bytes, and never
in the low-memory order (:data:`LOW_MEMORY_DOFS`): the coupled error estimate needs the
same n_b solves again. Measured on the 150k-DOF frame of ``benchmarks/peer_end_to_end.py``
(24 interface DOFs, 58 MB): the 24 solves cost 0.05-0.13 s of the 2.1-2.5 s study. An
interface of 1 002 DOFs at 151k would need 1.2 GB and is not kept."""

PIVOT_RTOL = 1e-11
"""A pivot of the ``K_ii`` factorisation below this fraction of its diagonal entry marks
K_ii as singular. The zero pivot of an unrestrained interior comes out as round-off
(measured -6e-16 and 1.3e-13 on free-free frames), while regular frames give ratios of
1e-4 and more, and a 1e6 stiffness contrast 7e-9; below 1e-11 (cond(K_ii) > 1e11) a
solve would keep fewer than five significant digits anyway."""


def guyan(model: FEModel, interface) -> Superelement:
    """Guyan (static) condensation onto the interface DOFs.

    Reproduces the full model's static response to any load on the interface DOFs
    exactly (to round-off); the mass is condensed with the static shapes.
    """
    return _reduce(model, interface, None, method="guyan")


def craig_bampton(model: FEModel, interface, n_modes: int | None = None,
                  cutoff_hz: float | None = None, f_max_hz: float | None = None,
                  residual_vectors: bool = True) -> Superelement:
    """Craig-Bampton reduction: interface DOFs + fixed-interface normal modes.

    Parameters
    ----------
    model : FEModel
    interface : see :func:`interface_dofs`
    n_modes : int, optional
        Number of fixed-interface modes.
    cutoff_hz : float, optional
        Keep all fixed-interface modes below this frequency, Hz.
    f_max_hz : float, optional
        Highest frequency of interest, Hz; keeps modes below ``CUTOFF_FACTOR * f_max_hz``.
    residual_vectors : bool
        Augment the basis with the static response of the interior to the inertia
        forces of unit interface accelerations, ``K_ii⁻¹ (M_ii Ψ + M_ib)``, made
        M-orthogonal to the kept modes (the truncated modes' quasi-static part, cf.
        Dickens & Stroeve, "Modal truncation vectors for reduced dynamic substructure
        models", AIAA 2000-1578). Costs n_b solves with the existing factorisation and
        adds up to n_b coordinates (kind ``"residual"``); on the shipped machine frame it
        lowers the error of the 10 lowest modes with 10 fixed-interface modes from 7e-3
        to 6e-7. ``False`` gives the classical Craig-Bampton basis.

    Give exactly one of ``n_modes``, ``cutoff_hz`` and ``f_max_hz``.

    Returns
    -------
    Superelement
        Reduced frequencies are upper bounds of the full ones (Rayleigh-Ritz) and
        converge as modes are added.
    """
    given = [v is not None for v in (n_modes, cutoff_hz, f_max_hz)]
    if sum(given) != 1:
        raise ValueError("give exactly one of n_modes, cutoff_hz and f_max_hz")
    if f_max_hz is not None:
        cutoff_hz = CUTOFF_FACTOR * float(f_max_hz)
    if cutoff_hz is not None and not cutoff_hz > 0:
        raise ValueError(f"cutoff_hz must be positive, got {cutoff_hz}")
    if n_modes is not None and n_modes < 0:
        raise ValueError(f"n_modes must be >= 0, got {n_modes}")
    selection = ("count", int(n_modes)) if n_modes is not None else ("cutoff", cutoff_hz)
    return _reduce(model, interface, selection, method="craig-bampton",
                   residual_vectors=residual_vectors)


def partition(model: FEModel, interface):
    """(interface DOFs in the full model, their positions b among the free DOFs, the
    interior positions, K_free and M_free as CSR); ValueError if nothing is interior."""
    dofs = interface_dofs(model, interface)
    b = np.searchsorted(model.free, dofs)
    interior = np.setdiff1d(np.arange(model.n_free), b)
    if interior.size == 0:
        raise ValueError("every free DOF is an interface DOF: nothing to reduce")
    return dofs, b, interior, model.K_free.tocsr(), model.M_free.tocsr()


def interior_blocks(K, M, interior, b):
    """(K_ii, K_ib, M_ii, M_ib) as CSR, the interior rows sliced once (each slice of rows
    is a copy of the model's size)."""
    Ki, Mi = K[interior], M[interior]
    return Ki[:, interior], Ki[:, b], Mi[:, interior], Mi[:, b]


def _reduce(model: FEModel, interface, selection, method: str,
            residual_vectors: bool = False, low_memory: bool | None = None) -> Superelement:
    dofs, b, interior, K, M = partition(model, interface)
    Kii, Kib, Mii, Mib = interior_blocks(K, M, interior, b)
    timings = {}
    t0 = time.perf_counter()
    lu = factorize_interior(Kii, model.free[interior])
    t1 = time.perf_counter()
    Psi = rows_contiguous(lu.solve(Kib.toarray(order="F")), scale=-1.0)
    t2 = time.perf_counter()
    if low_memory is None:
        low_memory = interior.size >= LOW_MEMORY_DOFS and selection is not None \
            and selection[0] == "count" and selection[1] > 0
    omega2, Phi = fixed_interface_modes(Kii, Mii, selection, lu, check=not low_memory)
    n_fixed = omega2.size
    n_residual = 0
    response = None
    with product_phase(Psi.shape[0], Psi.shape[1] + Phi.shape[1]):
        if residual_vectors:
            keep = not low_memory and 8 * Psi.size <= KEEP_RESPONSE_BYTES
            more_omega2, more_Phi, response = residual_modes(Kii, Mii, Mib, Psi, Phi, lu,
                                                                keep)
            omega2, Phi = np.concatenate([omega2, more_omega2]), np.hstack([Phi, more_Phi])
            n_residual = more_omega2.size
        t3 = time.perf_counter()
        Kr, Mr = _project(K[b][:, b], Kib, Mii, Mib, M[b][:, b], Psi, Phi, omega2)
    t4 = time.perf_counter()
    if low_memory:  # the Sturm check of the fixed-interface modes, with K_ii's factor freed
        lu = None
        count, found = sturm_verified(Kii, Mii, omega2[:n_fixed])
        if count != found:  # modes missed (a cluster): the full path with deflated restarts
            return _reduce(model, interface, selection, method, residual_vectors, False)
    t5 = time.perf_counter()
    timings.update(factorisation=t1 - t0, constraint_modes=t2 - t1,
                   fixed_interface_modes=t3 - t2 + t5 - t4, projection=t4 - t3)
    points = model.mesh.points[dofs // DOF_PER_NODE]
    return Superelement(Kr, Mr, method, dofs, points, omega2, Psi, Phi, b, interior,
                        model.T.tocsr(), timings, n_residual, lu, inertia_response=response)


def factorize_interior(Kii, dofs):
    """LU of ``K_ii``; ValueError naming a DOF of a zero pivot if K_ii is singular.

    SuperLU rarely stops on a singular symmetric matrix: the zero pivot of an unrestrained
    motion comes out as round-off, so every pivot is compared with its diagonal entry
    (for positive definite K_ii, ``λ_min <= pivot <= diagonal``).
    """
    try:
        lu = factorize(Kii)
        pivots, order = lu.pivots()  # pivot j belongs to row/column order[j] of K_ii
        ratio = pivots / np.abs(Kii.diagonal()[order])
        bad = np.flatnonzero(~(ratio > PIVOT_RTOL))
        where = f" (zero pivot at {dof_label(int(dofs[order[bad[0]]]))})" if bad.size else ""
    except ValueError:
        bad, where = [0], ""
    if len(bad):
        raise ValueError(f"the interior stiffness K_ii is singular{where}: the interface (with"
                         " the supports) does not restrain all rigid-body motions of every"
                         " part; add interface DOFs")
    return lu


def fixed_interface_modes(Kii, Mii, selection, lu, check: bool = True):
    """(ω², Φ) of the fixed-interface modes, with ``lu`` (K_ii) as the shift factor;
    ``check=False`` leaves the Sturm check of a mode count to the caller."""
    n_i = Kii.shape[0]
    if selection is None or (selection[0] == "count" and selection[1] == 0):
        return np.empty(0), np.empty((n_i, 0))
    kind, value = selection
    if kind == "count":
        if value >= n_i:
            raise ValueError(f"n_modes={value} but the interior has only {n_i} DOFs")
        result = solve_symmetric(Kii, Mii, n_modes=value, sigma=0.0, factor=lu, check=check)
    else:
        result = solve_symmetric(Kii, Mii, band=(0.0, (2 * np.pi * value) ** 2), sigma=0.0,
                                 factor=lu)
    return result.omega2, result.vectors


def residual_modes(Kii, Mii, Mib, Psi, Phi, lu, keep: bool = False):
    """Residual vectors, as K- and M-orthogonal pseudo-modes: (ω², vectors (n_i, <= n_b),
    ``K_ii⁻¹ (M_ii Ψ + M_ib)`` (n_i, n_b) if ``keep`` else None).

    ``R = K_ii⁻¹ (M_ii Ψ + M_ib)`` minus its M-projection on Φ; a Rayleigh-Ritz solve
    in span(R) makes the vectors mutually K- and M-orthogonal (they are K-orthogonal to
    Φ because ``Φᵀ K_ii R = Λ Φᵀ M_ii R = 0``). Each column is first scaled to unit
    M-norm; directions of M-norm² below 1e-10 after the projection (linearly dependent
    ones, or all of them when Φ holds every interior mode) are dropped. The scaling makes
    the test independent of units: the columns of translational and rotational interface
    DOFs differ by a length unit, and a threshold relative to their sum kept 36 vectors
    of a frame in m-kg-s but 26 of the same frame in mm-t-s.
    """
    R = rows_contiguous(lu.solve(plus_sparse(Mii @ Psi, Mib)))
    response = R.copy() if keep else None
    MR = Mii @ R
    scale = np.sqrt(np.einsum("ij,ij->j", R, MR))  # M-norms before removing Φ
    scale = 1.0 / np.where(scale > 0, scale, 1.0)
    R *= scale  # in place: two n_i x n_b temporaries cost 2.3 s at 151k x 1 002
    MR *= scale
    MPhi = Mii @ Phi
    for _ in range(2):  # twice is enough (Kahan-Parlett) for M-orthogonality to Φ
        c = Phi.T @ MR
        subtract_product(R, Phi, c)
        subtract_product(MR, MPhi, c)
    gram = symmetric_product(R, MR)
    w, V = np.linalg.eigh(0.5 * (gram + gram.T))
    keep = w > 1e-10
    R = R @ (V[:, keep] / np.sqrt(w[keep]))  # M-orthonormal basis of the kept directions
    stiff = R.T @ (Kii @ R)
    omega2, Z = np.linalg.eigh(0.5 * (stiff + stiff.T))
    # one n_i x n_b x n_b product (the Gram matrix); the others have the kept columns only
    # (an interface of 1 002 DOFs along rails kept 108)
    return omega2, R @ Z, response


def _project(Kbb, Kib, Mii, Mib, Mbb, Psi, Phi, omega2):
    """Reduced K, M of the basis [[I, 0], [Ψ, Φ]] (sparse-times-dense products only).

    ``Ψᵀ M_ib`` is formed as ``(M_ibᵀ Ψ)ᵀ``, not from a dense copy of M_ib (n_i x n_b:
    1.2 GB at 151k x 1 002), and ``Ψᵀ M_ii Ψ`` by
    :func:`~femmech.reduction.products.symmetric_product`.
    """
    Kg = Kbb.toarray() + Kib.T @ Psi
    MiiPsi = Mii @ Psi
    MibPsi = Mib.T @ Psi
    Mg = Mbb.toarray() + MibPsi + MibPsi.T + symmetric_product(Psi, MiiPsi)
    Mbq = (Mib.T @ Phi) + MiiPsi.T @ Phi
    n_b, n_q = Kg.shape[0], Phi.shape[1]
    Kr = np.zeros((n_b + n_q, n_b + n_q))
    Mr = np.zeros_like(Kr)
    Kr[:n_b, :n_b] = 0.5 * (Kg + Kg.T)
    Kr[n_b:, n_b:] = np.diag(omega2)
    Mr[:n_b, :n_b] = 0.5 * (Mg + Mg.T)
    Mr[:n_b, n_b:] = Mbq
    Mr[n_b:, :n_b] = Mbq.T
    Mr[n_b:, n_b:] = Phi.T @ (Mii @ Phi)
    Mr[n_b:, n_b:] = 0.5 * (Mr[n_b:, n_b:] + Mr[n_b:, n_b:].T)
    return Kr, Mr

