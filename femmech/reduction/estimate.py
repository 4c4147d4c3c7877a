"""Stage 3: a-posteriori error estimates of a superelement's reduced frequencies.

Estimates how far the eigenfrequencies of a reduced model lie above those of the full
model from the residuals of the reduced eigenpairs on the interior DOFs, reusing the
``K_ii`` factorisation of the reduction (no solve of the full model):

* :func:`frequency_error_estimates`: modes of the superelement alone;
* :func:`confirmed_indices`: whether each reduced mode is the full model's mode of the
  same number within its estimate (Sturm counts of the full model; a residual estimate
  alone cannot see a full mode that the reduction missed);
* :func:`coupled_error_forms` and :func:`coupled_error_estimates`: quasi-modes of a
  coupled machine (mechanisms mounted on the superelement's interface) over a whole
  sweep, as a quadratic form in the reduced coordinates (three n_r × n_r matrices built
  once; O(n_r²) per angle and mode).

The coupled system is read by duck typing (``frame``, ``n_frame``, ``mounts``,
``touched``: a :class:`femmech.coupling.CoupledSystem`); this stage does not import the
coupling.

Imports :mod:`femmech.fe`, :mod:`femmech.solve` and its own package.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from femmech.fe.dofs import COMPONENTS, DOF_PER_NODE, dof_label
from femmech.fe.model import FEModel
from femmech.reduction.products import plus_sparse, product_phase, symmetric_product
from femmech.reduction.superelement import Superelement
from femmech.solve import tolerances
from femmech.solve.pencil import factorize
from femmech.solve.sturm import confirm_indices

REAL_RTOL = tolerances.REAL_RTOL
"""Eigenvalues with ``|Im λ| <= REAL_RTOL |λ|`` and vectors with imaginary parts below
``REAL_RTOL`` times their largest entry count as real (LAPACK round-off)."""


def frequency_error_estimates(model: FEModel, se: Superelement, omega2: np.ndarray,
                              q: np.ndarray) -> np.ndarray:
    """A-posteriori relative frequency errors of reduced eigenpairs, without a full solve.

    For a Ritz pair (λ̃, x = T q) with mass-normalised x, the residual
    ``r = K x - λ̃ M x`` vanishes on the interface in the reduced sense
    (``r_b = -Ψᵀ r_i``), so ``K⁻¹ r = [0; K_ii⁻¹ r_i]`` and the eigenvalue error is
    estimated by ``λ̃ - λ ≈ rᵀ (K - λ M)⁻¹ r ≈ r_iᵀ K_ii⁻¹ r_i`` (exact to first order
    in λ / ω²_truncated). The relative frequency error is half the relative eigenvalue
    error. Reuses the K_ii factorisation of the reduction.

    Parameters
    ----------
    model : FEModel
        The model that was reduced.
    se : Superelement
    omega2 : ndarray (n_modes,)
        Reduced eigenvalues, rad²/s².
    q : ndarray (n_r, n_modes)
        Reduced eigenvectors, mass-normalised with ``se.M``.

    Returns
    -------
    ndarray (n_modes,)
        Estimated ``(f_reduced - f_full) / f_full``; 0 for rigid-body modes (λ̃ ≈ 0).
    """
    lu = se.interior_factor
    K, M = model.K_free.tocsr(), model.M_free.tocsr()
    interior = se.free_interior
    if lu is None:
        lu = factorize(K[interior][:, interior])
    u = se.expand_free(q)
    r = (K[interior] @ u) - (M[interior] @ u) * omega2
    eta = np.einsum("ij,ij->j", r, lu.solve(r))
    scale = np.abs(se.K).max() / max(np.abs(se.M).max(), 1e-300)
    rigid = np.abs(omega2) <= 1e-12 * scale
    return np.where(rigid, 0.0, 0.5 * eta / np.where(rigid, 1.0, omega2))


INDEX_SAFETY = 2.0
"""The interval of :func:`confirmed_indices` is this many times the error estimate wide:
the first-order estimate underestimates the error by the factor ``1 - λ/ω²_j`` of the
lowest fixed-interface mode left out (up to 1/4 below ``f_max`` with the default
cutoff of twice ``f_max``, i.e. an error up to 1.33 times the estimate)."""

INDEX_RTOL = 1e-6
"""Smallest relative width (in frequency) of the interval of :func:`confirmed_indices`:
the relative margin of the Sturm cuts of :mod:`femmech.solve.sturm`, above the dense
reduced solver's round-off."""


def confirmed_indices(model: FEModel, omega2: np.ndarray, estimate: np.ndarray,
                      first_index: int = 1, rigid: np.ndarray | None = None,
                      each: bool = False) -> tuple[np.ndarray, int]:
    """Whether each reduced mode is the full model's mode of the same number.

    :func:`frequency_error_estimates` measures how far a reduced eigenpair is from *some*
    eigenpair of the full model. If the reduction misses a full mode (too few
    fixed-interface modes for a mode with little interface motion), every reduced mode
    above it is compared with the wrong full mode: measured on a cantilever plate reduced
    with 1 fixed-interface mode and residual vectors, reduced mode 10 lies 27 % above the
    full mode 10 with an estimate of 5.5e-6 (it is within 1e-5 of full mode 12). A
    Sturm count settles it: the ``k``-th full eigenvalue lies in
    ``[λ̃_k / (1 + w_k)², λ̃_k]`` with ``w_k = max(INDEX_SAFETY |e_k|, INDEX_RTOL)``
    exactly when fewer than k full eigenvalues lie below the lower end (the upper end
    holds by Rayleigh-Ritz: the reduction is a Galerkin projection of the full model).
    By default one count just above the highest mode decides every mode if it finds
    exactly as many full eigenvalues as there are reduced ones up to there (nothing
    missed), taking each interval to hold a full eigenvalue of its own, which is what the
    estimate asserts (:func:`femmech.solve.sturm.confirm_indices` with ``distinct``);
    where it finds more, or with ``each=True``, a count at the lower end of each mode's
    interval decides without that assumption (counts shared where intervals overlap).
    Each count is one indefinite factorisation of the full ``K - c M`` (measured on a
    cantilever plate of 21 960 free DOFs, 10 modes: 1.2 s per count on a shared machine,
    against 1.45 s for the modes and their estimates). Rigid-body modes are confirmed
    without a count.

    Parameters
    ----------
    model : FEModel
        The model that was reduced.
    omega2 : ndarray (n_modes,)
        Reduced eigenvalues, ascending, rad²/s².
    estimate : ndarray (n_modes,)
        Their relative frequency error estimates (:func:`frequency_error_estimates`).
    first_index : int
        Position (1-based) of ``omega2[0]`` in the reduced spectrum (1 for the lowest
        modes; more for a band that starts above 0).
    rigid : ndarray (n_modes,) of bool, optional
        Rigid-body modes (no count).
    each : bool
        Count at every mode's interval (no assumption on the estimates).

    Returns
    -------
    confirmed : ndarray (n_modes,) of bool
        True where the full model's mode of the same number lies within the interval.
    n_counts : int
        Factorisations of the full model made.
    """
    lam = np.asarray(omega2, dtype=float)
    width = np.maximum(INDEX_SAFETY * np.abs(np.asarray(estimate, dtype=float)), INDEX_RTOL)
    lower = lam / (1.0 + width) ** 2
    if rigid is not None:
        lower = np.where(rigid, -np.inf, lower)
    index = first_index + np.arange(lam.size)
    return confirm_indices(model.K_free, model.M_free, lower, lam, index, distinct=not each)


@dataclass(frozen=True)
class CoupledErrorForms:
    """The three n_r × n_r matrices of the coupled error estimate of one superelement.

    For reduced frame coordinates q (n_r,) and an eigenvalue λ (rad²/s²) the interior
    residual of the expanded field ``u = T q`` is ``r_i = A q - λ B q`` with
    ``A = (K T)_i = [0, K_ii Φ]`` and ``B = (M T)_i = [M_ib + M_ii Ψ, M_ii Φ]``, and
    ``r_iᵀ K_ii⁻¹ r_i = qᵀ (G0 - 2 λ G1 + λ² G2) q`` with

    * ``G0 = Aᵀ K_ii⁻¹ A = diag(0, Φᵀ K_ii Φ)`` (N/m-like units of K_r),
    * ``G1 = sym(Aᵀ K_ii⁻¹ B) = sym([[0, 0], [Φᵀ B]])`` (units of M_r; ``Φᵀ B`` is the
      modal row block of the reduced mass ``M_r``, taken from it),
    * ``G2 = Bᵀ K_ii⁻¹ B`` (M_r² / K_r; n_r solves with the K_ii factor).

    Attributes
    ----------
    G0, G1, G2 : ndarray (n_r, n_r), symmetric
    superelement : Superelement
        The superelement they belong to.
    lambda_scale : float
        ``max|K_r| / max|M_r|``, rad²/s²: eigenvalues below ``1e-12`` of it are rigid-body
        modes (estimate 0).
    seconds : float
        Wall time of :func:`coupled_error_forms`, s.
    """

    G0: np.ndarray
    G1: np.ndarray
    G2: np.ndarray
    superelement: Superelement = field(compare=False, repr=False)
    lambda_scale: float = 1.0
    seconds: float = 0.0


def coupled_error_forms(model: FEModel, se: Superelement) -> CoupledErrorForms:
    """Build the matrices of :func:`coupled_error_estimates` once per superelement.

    Costs ``n_r`` solves with the superelement's ``K_ii`` factorisation (factorised anew
    if the superelement was loaded from a file; ``n_q`` solves only where the reduction
    kept its ``inertia_response``) and products of n_i × n_r blocks; every angle and
    mode afterwards costs O(n_r²).

    Parameters
    ----------
    model : FEModel
        The model that was reduced to ``se``.
    se : Superelement

    Returns
    -------
    CoupledErrorForms

    Raises
    ------
    ValueError
        If ``model`` is not the model reduced to ``se``, or ``se`` has a reduced interface
        (interface modes instead of the physical interface DOFs).
    """
    start = time.perf_counter()
    if getattr(se, "interface_basis", None) is not None:
        raise ValueError("the superelement has a reduced interface (interface modes): its"
                         " interface DOFs are not kept, so the residual is not the interior"
                         " one alone; use interface_error_estimates, or a superelement with"
                         " the physical interface")
    K, M = model.K_free.tocsr(), model.M_free.tocsr()
    interior, b = se.free_interior, se.free_interface
    if se.Psi.shape[0] != interior.size or K.shape[0] != se.T.shape[1]:
        raise ValueError(f"the model ({model.n_free} free DOFs) is not the model reduced to"
                         f" this superelement ({se.T.shape[1]} free DOFs)")
    K_ii, M_i = K[interior][:, interior], M[interior]
    M_ii, M_ib = M_i[:, interior], M_i[:, b]
    lu = se.interior_factor if se.interior_factor is not None else factorize(K_ii)
    with product_phase(interior.size, se.n_reduced):
        G0, G1, G2 = _forms(lu, K_ii, M_ii, M_ib, se)
    scale = np.abs(se.K).max() / max(np.abs(se.M).max(), 1e-300)
    return CoupledErrorForms(G0, G1, G2, se, float(scale),
                             time.perf_counter() - start)


def _forms(lu, K_ii, M_ii, M_ib, se: Superelement):
    """G0, G1, G2 (n_r, n_r) of :class:`CoupledErrorForms`.

    ``K_ii⁻¹ M_ii Φ`` is formed as ``(Φ - K_ii⁻¹ P) Λ⁻¹`` with the modes' residuals
    ``P = K_ii Φ - M_ii Φ Λ`` (an identity for any Φ, Λ): a solve is accurate relative to
    its right-hand side, and P is small for the fixed-interface modes, whereas the
    solve of ``M_ii Φ`` itself has errors ~ eps ‖K_ii‖ / ω² that the cancellation of the
    three terms of the estimate exposes (measured: a floor of 7e-10 on the relative
    frequency error of a 20k-DOF shaft, against 5e-16 this way). Blocks with the
    constraint modes, ``K_ii⁻¹ (M_ib + M_ii Ψ)``, are solved directly, or taken from the
    superelement (``inertia_response``) where the residual vectors' solve was kept.
    Every n_i × n_q block is formed row-major (a column-major copy of M_ii Φ and the
    mixed-layout update cost 0.35 s of 0.4 s at 150k × 40).
    """
    n_b, n_r = se.n_interface, se.n_reduced
    Phi, lam = se.Phi, se.modal_omega2
    B_b = plus_sparse(M_ii @ se.Psi, M_ib)  # (n_i, n_b)
    D_b = se.inertia_response
    if D_b is None or D_b.shape != B_b.shape:
        D_b = lu.solve(B_b)
    B_q = M_ii @ Phi  # (n_i, n_q)
    K_Phi = K_ii @ Phi
    G0, G1 = np.zeros((n_r, n_r)), np.zeros((n_r, n_r))
    G0[n_b:, n_b:] = _sym(Phi.T @ K_Phi)
    P = K_Phi
    P -= B_q * lam  # the modes' residuals, in place of K_ii Φ
    D_q = lu.solve(P)
    del P, K_Phi
    np.subtract(Phi, D_q, out=D_q)
    D_q /= lam
    G2 = np.empty((n_r, n_r))
    G2[:n_b, :n_b] = _sym(symmetric_product(D_b, B_b))
    G2[n_b:, :n_b] = D_q.T @ B_b
    G2[:n_b, n_b:] = G2[n_b:, :n_b].T
    G2[n_b:, n_b:] = _sym(D_q.T @ B_q)
    G1[n_b:] = se.M[n_b:]  # Φᵀ B, as the reduction formed it (its products of Φ, M, Ψ)
    return G0, _sym(G1), G2


def _sym(A: np.ndarray) -> np.ndarray:
    return 0.5 * (A + A.T)


def coupled_error_estimates(forms: CoupledErrorForms, system, omega2,
                            vectors) -> np.ndarray:
    """A-posteriori relative errors of coupled quasi-eigenfrequencies over a sweep.

    The quasi-modes of a coupled machine whose frame is a Craig-Bampton superelement
    lie above those of the same machine with the unreduced frame (Rayleigh-Ritz: the
    reduced coupled system is the Galerkin projection of the full one with the basis
    ``diag(T, I)``). This estimates by how much, from the residual on the frame's
    interior DOFs, without a full solve:

    For a reduced coupled mode ``z = [q; x]`` (q the superelement's coordinates, x the
    mechanisms' own coordinates, z mass-normalised in the coupled M(φ)) with eigenvalue
    λ̃, the expanded mode ``w = [T q; x]`` is mass-normalised in the full coupled M(φ).
    If the mechanisms touch interface DOFs only, the interior rows of the full residual
    ``(C - λ̃ M) w`` are the frame's alone, ``r_i = (K u - λ̃ M u)_i`` with ``u = T q``,
    and the Galerkin conditions make the whole residual ``C [0; K_ii⁻¹ r_i; 0]`` (its
    interface rows are ``-Ψᵀ r_i``, its mechanism rows 0; in the multiplier form up to
    a constraint force ``Hᵀ μ``, which does not touch interior DOFs either). Hence, as
    in :func:`frequency_error_estimates`,
    ``λ̃ - λ ≈ rᵀ (C - λ M)⁻¹ r ≈ r_iᵀ K_ii⁻¹ r_i`` (first order in the residual and in
    λ / ω²_j of the fixed-interface modes left out, which the estimate underestimates by
    the factor ``1 - λ/ω²_j``). Since r_i is linear in q this is the quadratic form
    ``qᵀ (G0 - 2 λ̃ G1 + λ̃² G2) q`` of :class:`CoupledErrorForms`. The relative
    frequency error is half the relative eigenvalue error:
    ``(f̃ - f) / f ≈ ½ (λ̃ - λ) / λ̃``.

    Parameters
    ----------
    forms : CoupledErrorForms
        From :func:`coupled_error_forms` of the superelement that is ``system.frame``.
    system : femmech.coupling.CoupledSystem
        The coupled machine (primal or multiplier form) whose quasi-modes are given.
    omega2 : array_like (n_angles, n_modes) or (n_modes,)
        Eigenvalues λ̃ = ω², rad²/s² (``Sweep.eigenvalues``; complex with a zero
        imaginary part is accepted).
    vectors : array_like (n_angles, n, n_modes) or (n, n_modes)
        The quasi-modes, mass-normalised with the coupled M(φ) (``Sweep.vectors`` of a
        sweep with ``keep_vectors=True``); only the first ``n_frame`` rows are read.

    Returns
    -------
    ndarray, the shape of omega2
        Estimated ``(f_reduced - f_full) / f_full`` of each mode; 0 for rigid-body
        modes. Values at round-off level (below ~1e-13) may come out slightly negative.

    Raises
    ------
    ValueError
        If the frame is not the superelement of ``forms``, a mechanism is attached to an
        interior DOF of the frame (the estimate does not apply: add the DOF to the
        interface), the modes are complex (unsymmetric C(φ), damped sweeps) or the
        shapes do not fit.
    """
    se = forms.superelement
    _require_interface_mounts(system, se)
    lam, q, single = _real_modes(omega2, vectors, system.n, se.n_reduced)
    n_angles, n_r, n_modes = q.shape
    Q = q.transpose(1, 0, 2).reshape(n_r, n_angles * n_modes)
    GQ = (np.vstack([forms.G0, forms.G1, forms.G2]) @ Q).reshape(3, n_r, -1)
    parts = np.einsum("kj,tkj->tj", Q, GQ).reshape(3, n_angles, n_modes)
    eta = parts[0] - 2.0 * lam * parts[1] + lam**2 * parts[2]
    rigid = np.abs(lam) <= 1e-12 * forms.lambda_scale
    out = np.where(rigid, 0.0, 0.5 * eta / np.where(rigid, 1.0, lam))
    return out[0] if single else out


def _real_modes(omega2, vectors, n: int, n_r: int):
    """(λ (A, m), q (A, n_r, m), single) from the eigenvalues and vectors of a sweep."""
    lam, V = np.asarray(omega2), np.asarray(vectors)
    single = lam.ndim == 1
    if single:
        lam, V = lam[None], V[None]
    if lam.ndim != 2 or V.ndim != 3 or V.shape[0] != lam.shape[0] \
            or V.shape[2] != lam.shape[1] or V.shape[1] != n:
        raise ValueError(f"omega2 {np.shape(omega2)} and vectors {np.shape(vectors)} do not"
                         f" fit: expected (n_angles, n_modes) and (n_angles, {n}, n_modes)")
    if np.iscomplexobj(lam):
        if np.any(np.abs(lam.imag) > REAL_RTOL * np.abs(lam)):
            raise ValueError("complex eigenvalues (unsymmetric C(φ) or a damped sweep): the"
                             " coupled error estimate needs undamped symmetric quasi-modes"
                             " (Omega = 0, damped=False)")
        lam = lam.real
    q = V[:, :n_r]
    if np.iscomplexobj(q):
        if np.abs(q.imag).max(initial=0.0) > REAL_RTOL * np.abs(q).max(initial=0.0):
            raise ValueError("complex mode shapes: the coupled error estimate needs undamped"
                             " symmetric quasi-modes (Omega = 0, damped=False)")
        q = q.real
    return lam.astype(float), np.ascontiguousarray(q, dtype=float), single


def _require_interface_mounts(system, se: Superelement) -> None:
    """ValueError unless ``system``'s frame is ``se`` and every mechanism attaches to
    interface DOFs only (checked on the reduced couplings and on each attachment's
    physical DOFs)."""
    frame = getattr(system, "frame", None)
    if not isinstance(frame, Superelement):
        raise ValueError("the coupled error estimate needs a coupled system whose frame is a"
                         f" Superelement, got {type(frame).__name__}")
    if frame is not se and not (frame.K.shape == se.K.shape and np.array_equal(frame.K, se.K)
                                and np.array_equal(frame.M, se.M)):
        raise ValueError("the error forms were built for another superelement than the"
                         " system's frame; call coupled_error_forms(model, system.frame)")
    n_b = se.n_interface
    for mount, idx in zip(system.mounts, system.touched, strict=True):
        modal = idx[(idx >= n_b) & (idx < system.n_frame)]
        if modal.size:
            raise ValueError(f"{mount.name}: couples to the superelement's modal coordinate"
                             f" {int(modal[0])}, i.e. is attached to interior DOFs; the"
                             " coupled error estimate needs mechanisms on interface DOFs only")
        for att in mount.attachments:
            _require_interface_attachment(se, mount.name, att)


def _require_interface_attachment(se: Superelement, name: str, att) -> None:
    """ValueError if the frame motion of attachment ``att`` involves an interior DOF."""
    node = int(att.node)
    if isinstance(att.direction, str):
        w = np.zeros(DOF_PER_NODE)
        w[COMPONENTS.index(att.direction)] = 1.0
    else:
        w = np.asarray(att.direction, dtype=float)
    row = np.asarray(se.T[DOF_PER_NODE * node + np.arange(DOF_PER_NODE)].T @ w).ravel()
    if np.any(row[se.free_interior]):
        dof = dof_label(DOF_PER_NODE * node + int(np.argmax(np.abs(w))))
        raise ValueError(f"{name}: attachment of {att.coordinate!r} at {dof} moves interior"
                         " (non-interface) DOFs of the superelement; the coupled error"
                         " estimate needs mechanisms on interface DOFs only (add the"
                         " attachment's DOFs to the interface)")
