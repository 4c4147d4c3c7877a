"""Stage 3: Craig-Bampton reduction with a reduced interface, for interfaces of many DOFs.

Rails and long bearings give interfaces of ~1 000 DOFs; plain Craig-Bampton
(:mod:`femmech.reduction.component_modes`) then forms the n_i x n_b constraint modes
``Ψ = -K_ii⁻¹ K_ib`` and n_i x n_b x n_b products and keeps all n_b interface DOFs as
coordinates. Here the interface motion is itself reduced,

    u_b = V η_c,   u = [[V, 0], [Ψ V, Φ]] [η_c; η] (+ residual vectors),

with an interface basis V (n_b, n_c) that is M_G-orthonormal and diagonalises S (a
Rayleigh-Ritz basis of the Guyan interface pencil ``S = K_bb - K_bi K_ii⁻¹ K_ib``,
``M_G = Tᵀ M T``, ``T = [I; Ψ]``), spanned by

* the interface traces of the component's own eigenvectors below ``TRACE_FACTOR * f_max``
  (system-level interface modes: the component is the system, the mechanisms mounted on
  it are light perturbations; D. Krattiger et al., "Interface reduction for Hurty/
  Craig-Bampton substructured models: review and improvements", Mech. Syst. Signal
  Process. 114 (2019) 579-603, show how much faster system-level interface modes
  converge than component-level ones). With them the component's band modes are as
  exact as with the whole interface;
* the attachment vectors ``S⁻¹ E`` of the interface nodes where mechanisms are mounted
  (E: unit loads on their DOFs; residual flexibility, R. H. MacNeal, Computers &
  Structures 1 (1971) 581): the static flexibility at a mount is exact, and the change of
  the interface motion by a mounted mechanism is a static response to its force there;
* optionally (``cc_modes``) the lowest characteristic constraint (CC) modes, eigenvectors
  of ``S V = M_G V Θ`` (M. P. Castanier, Y.-C. Tan and C. Pierre, "Characteristic
  constraint modes for component mode synthesis", AIAA J. 39 (2001) 1182-1187), for
  interfaces loaded where no attachment was declared.

Measured on the rails (n_b = 1 002) of the 24k-DOF grid frame with four 200 kg
spring-masses on rail nodes, error of the coupled frequencies below f_max against plain
Craig-Bampton with the whole interface (f_max = 160 Hz / 282 Hz): CC modes alone up to
6 f_max (38 / 83 modes) plus attachment vectors 9.4e-4 / 2.1e-4, up to 10 f_max 5.5e-5 /
5.7e-5; traces up to 1.2 f_max plus attachment vectors 5.4e-5 / 4.6e-5, plus CC modes up
to 2 f_max 5.4e-5 / 3.7e-6 (dense study; tests/test_interface_reduction.py and
benchmarks/peer_interface.py measure the shipped path). Without attachment vectors a
point mount is poorly represented: 400 CC modes left 0.7 % on the 5k-DOF frame.

Ψ and S are never formed. ``S⁻¹ Tᵀ g = (K⁻¹ g)_b`` for any full vector g (the bb block of
K⁻¹ is S⁻¹), so the attachment vectors are traces of solves with the whole free K, and
the CC modes come from a block Krylov iteration on ``S⁻¹ M_G y = (K⁻¹ M T y)_b`` with
``T y = [y; -K_ii⁻¹ K_ib y]`` (one solve with K and one with K_ii per vector). K is
factorised shifted, ``K - σM`` with σ = :func:`~femmech.solve.pencil.default_shift`
(1e-6 of the typical eigenvalue below zero), so that free-free components (singular K)
need no special path: the shift changes the attachment vectors and the Krylov operator by
O(σ/λ) ~ 1e-6 only, while every Rayleigh-Ritz step uses the exact S and M_G
(``Wᵀ K W``, ``Wᵀ M W`` with ``W = T V``). The images ``W = T V`` give ``Ψ V`` (n_c K_ii
solves); residual vectors are formed for the n_c loaded directions only
(``K_ii⁻¹ (M_ii Ψ V + M_ib V)``), and every dense product is n_i x (n_c + n_q) wide.

:func:`interface_error_estimates` gives the a-posteriori frequency error of reduced (or,
with the attachment loads, coupled) eigenpairs against the unreduced model from their
residuals, with the factorisation of K kept from the reduction.

Imports :mod:`femmech.fe`, :mod:`femmech.solve` and its own package.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from femmech.fe.dofs import COMPONENTS, DOF_PER_NODE
from femmech.fe.model import FEModel, node_indices
from femmech.reduction.component_modes import (
    CUTOFF_FACTOR,
    factorize_interior,
    fixed_interface_modes,
    interior_blocks,
    partition,
    residual_modes,
)
from femmech.reduction.products import rows_contiguous
from femmech.reduction.superelement import Superelement
from femmech.solve import threads
from femmech.solve.eigen import solve_symmetric
from femmech.solve.pencil import default_shift, factorize

TRACE_FACTOR = 1.2
"""The interface traces of the component's own modes up to this multiple of f_max join the
interface basis (``mode_traces=True``). They make the component's band modes as exact as
with the whole interface; attachment vectors (and CC modes) cover the change of the
interface motion by the mounted mechanisms. Measured on the rails (n_b = 1 002) of the
24k-DOF frame, four 200 kg spring-masses declared as attachments, error of the coupled
frequencies below f_max against plain Craig-Bampton (f_max = 160 Hz / 282 Hz): traces up
to 1.0 f_max 5.4e-5 / 2.9e-4, up to 1.2 f_max 5.4e-5 / 4.6e-5 (34 modes at 282 Hz), up
to 1.5 f_max 5.4e-5 / 2.9e-5 (56 modes); CC modes alone up to 6 f_max 9.4e-4 / 2.1e-4."""

CC_CUTOFF_FACTOR = 2.0
"""Cutoff of the CC modes as a multiple of ``f_max_hz`` for ``cc_modes="auto"``. With the
mode traces they are a reserve for mounts where no attachment was declared: on the rails
of the 24k-DOF frame (f_max = 282 Hz) CC modes up to 2 f_max lowered the coupled error of
traces plus attachment vectors from 4.6e-5 to 3.7e-6 (at 160 Hz: none, 5.4e-5), at about
2.5x the cost of the rest of the reduction; hence ``cc_modes=0`` is the default.
Without traces, CC modes need about 10 f_max for 1e-4 (module docstring)."""

KRYLOV_BLOCK = 8
"""Columns of the random start block of the CC Krylov iteration: the largest multiplicity
of a CC eigenvalue it resolves in one block (symmetric frames have pairs and quadruples)."""

RITZ_RTOL = 1e-3
"""A Ritz value of the CC pencil is converged when it changed by less than this fraction
between two Krylov blocks. The CC modes only span the interface basis, so their
eigenvector accuracy (~sqrt of this) is ample."""

THIN_WIDTH = 300
"""The dense blocks of this reduction are n x (n_c + n_q) with n_c + n_q ~ 100: thin
products that gain nothing from a second BLAS thread and stall when other processes load
the cores. Up to this width they run in the *solve* thread phase
(:func:`femmech.solve.threads.solve_phase`): on the 151k-DOF frame under load the residual
vectors of 34 directions took 13 s of products in the *factor* phase
(:func:`~femmech.reduction.products.product_phase` chose it by flops)."""

DROP_RTOL = 1e-10
"""Krylov directions whose M_G-norm² fell below this fraction after the orthogonalisation
(units-free: every column is scaled to unit M_G-norm first) are linearly dependent and
dropped."""


def reduce_interface(model: FEModel, interface, n_modes: int | None = None,
                     cutoff_hz: float | None = None, f_max_hz: float | None = None,
                     cc_modes=0, attachments=(),
                     residual_vectors: bool = True, mode_traces: bool = True,
                     seed: int = 0) -> Superelement:
    """Craig-Bampton reduction with a reduced interface (see the module docstring).

    Parameters
    ----------
    model : FEModel
    interface : see :func:`~femmech.reduction.superelement.interface_dofs`
    n_modes, cutoff_hz, f_max_hz :
        Fixed-interface modes, as in :func:`~femmech.reduction.component_modes.craig_bampton`
        (give exactly one).
    cc_modes : int >= 0 or "auto"
        Number of characteristic constraint modes in the interface basis, or ``"auto"``:
        all CC modes up to ``CC_CUTOFF_FACTOR * f_max_hz`` (with ``cutoff_hz`` given:
        f_max = ``cutoff_hz / CUTOFF_FACTOR``). Default 0 (traces and attachment vectors
        only, :data:`CC_CUTOFF_FACTOR` tells why). ``cc_modes >= n_b`` keeps the whole
        interface: the reduced model then equals plain Craig-Bampton to round-off.
    attachments : sequence of int or str
        Interface nodes (indices or node groups) where mechanisms will be attached; their
        attachment vectors make the static flexibility at these nodes exact. Declare every
        such node: a mechanism mounted on an undeclared interface node misses the local
        flexibility under its point load (coupled errors of 30-100 % measured in
        tests/test_interface_reduction.py, which :func:`interface_error_estimates` flags).
    residual_vectors : bool
        Residual vectors of the n_c loaded interface directions (as in craig_bampton).
    mode_traces : bool
        Add the interface traces of the component's own modes up to
        ``TRACE_FACTOR * f_max`` (needs f_max_hz or cutoff_hz); see the module docstring.
    seed : int
        Seed of the random start block (results are reproducible).

    Returns
    -------
    Superelement
        The interface basis holds n_c = (CC modes) + (traces) + (6 per attachment node)
        columns at most (dependent ones dropped). ``method = "craig-bampton-cc"``;
        reduced coordinates ``[η_c; η]``;
        ``interface_basis`` = V (n_b, n_c) (u_b = V η_c), ``Psi`` = Ψ V (n_i, n_c),
        ``interface_factor`` the factorisation of ``K - σM`` for the error estimate.
    """
    selection, f_max = _selection(n_modes, cutoff_hz, f_max_hz)
    t0 = time.perf_counter()
    dofs, b, interior, K, M = partition(model, interface)
    Kii, Kib, Mii, Mib = interior_blocks(K, M, interior, b)
    lu = factorize_interior(Kii, model.free[interior])
    sigma = default_shift(K, M)
    full = factorize((K - sigma * M).tocsc())
    t1 = time.perf_counter()
    want = _cc_request(cc_modes, f_max, b.size)
    if f_max is None and not len(np.atleast_1d(attachments)) and want[1] == 0:
        raise ValueError("reduce_interface with n_modes and neither cc_modes nor attachments"
                         " has no interface basis: give f_max_hz (mode traces), cc_modes or"
                         " attachments")
    E = _attachment_loads(model, dofs, attachments)
    W = np.zeros((model.n_free, 0))
    if want[1] > 0:
        W = characteristic_modes(K, M, b, interior, lu, full, want, seed=seed)[2]
    if W.shape[1] < b.size:
        traces = _traces(K, M, b, full, sigma, E, f_max if mode_traces else None)
        W = _join(K, M, W, traces, b, interior, Kib, lu)
    V = np.ascontiguousarray(W[b])
    t2 = time.perf_counter()
    omega2, Phi = fixed_interface_modes(Kii, Mii, selection, lu)
    Psi = rows_contiguous(W[interior])
    n_residual = 0
    with _phase(Psi.shape[1] + Phi.shape[1]):
        if residual_vectors:
            MibV = (Mib @ sp.csr_matrix(V)).tocsr()  # rows next to b only
            more_omega2, more_Phi, _ = residual_modes(Kii, Mii, MibV, Psi, Phi, lu)
            omega2, Phi = np.concatenate([omega2, more_omega2]), np.hstack([Phi, more_Phi])
            n_residual = more_omega2.size
        t3 = time.perf_counter()
        Kr, Mr = _project(K, M, W, interior, Mii, Phi, omega2)
    t4 = time.perf_counter()
    timings = dict(factorisation=t1 - t0, constraint_modes=t2 - t1,
                   fixed_interface_modes=t3 - t2, projection=t4 - t3)
    points = model.mesh.points[dofs // DOF_PER_NODE]
    return Superelement(Kr, Mr, "craig-bampton-cc", dofs, points, omega2, Psi, Phi, b,
                        interior, model.T.tocsr(), timings, n_residual, lu,
                        interface_basis=V, interface_factor=full)


def _traces(K, M, b, full, sigma, E, f_max):
    """Interface traces (n_b, k) of the attachment responses ``K⁻¹ [E; 0]`` (whose traces
    are ``S⁻¹ E``) and, for ``f_max`` given, of the component's eigenvectors below
    ``TRACE_FACTOR * f_max`` (:func:`~femmech.solve.eigen.solve_symmetric`: a band from
    zero, found as the lowest modes by shift-invert Lanczos with the factorisation of
    ``K - σM`` and Sturm-checked; a block Krylov space of the traces' own took 240 solves
    for 17 modes)."""
    n_free = K.shape[0]
    G = np.zeros((n_free, E.shape[1]))
    G[b] = E
    Xa = full.solve(G) if E.shape[1] else np.zeros((n_free, 0))
    if f_max is None:
        return np.ascontiguousarray(Xa[b])
    hi = (2 * np.pi * TRACE_FACTOR * f_max) ** 2
    X = solve_symmetric(K, M, band=(0.0, hi), sigma=sigma, factor=full).vectors
    return np.ascontiguousarray(np.hstack([X[b], Xa[b]]))


def _join(K, M, W, traces, b, interior, Kib, lu):
    """Images (n_free, k) of the union of span(W[b]) and the ``traces``, M_G-orthonormal
    with diagonal ``Wᵀ K W`` (Rayleigh-Ritz on the Guyan pencil)."""
    if traces.shape[1] == 0:
        return W
    with _phase(W.shape[1] + traces.shape[1]):
        Wt = _image(traces, K.shape[0], b, interior, Kib, lu)
        extra, _ = _m_orthonormal(Wt, M @ Wt, W, M @ W)
        W = np.hstack([W, extra])
        stiff = W.T @ (K @ W)
        _, Z = np.linalg.eigh(0.5 * (stiff + stiff.T))
        return W @ Z


def _phase(width: int):
    """BLAS thread phase for products of n x ``width`` blocks (:data:`THIN_WIDTH`)."""
    return threads.solve_phase() if width <= THIN_WIDTH else threads.factor_phase()


def _selection(n_modes, cutoff_hz, f_max_hz):
    """(selection of fixed-interface modes, f_max in Hz or None), validated."""
    given = [v is not None for v in (n_modes, cutoff_hz, f_max_hz)]
    if sum(given) != 1:
        raise ValueError("give exactly one of n_modes, cutoff_hz and f_max_hz")
    if f_max_hz is not None:
        if not float(f_max_hz) > 0:
            raise ValueError(f"f_max_hz must be positive, got {f_max_hz}")
        cutoff_hz = CUTOFF_FACTOR * float(f_max_hz)
    if cutoff_hz is not None:
        if not cutoff_hz > 0:
            raise ValueError(f"cutoff_hz must be positive, got {cutoff_hz}")
        return ("cutoff", float(cutoff_hz)), float(cutoff_hz) / CUTOFF_FACTOR
    if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) or n_modes < 0:
        raise ValueError(f"n_modes must be an integer >= 0, got {n_modes!r}")
    return ("count", int(n_modes)), None


def _cc_request(cc_modes, f_max, n_b):
    """("count", n_c) or ("cutoff", ω²_cut) of CC modes, validated."""
    if isinstance(cc_modes, str):
        if cc_modes != "auto":
            raise ValueError(f"cc_modes must be an integer >= 0 or 'auto', got"
                             f" {cc_modes!r}")
        if f_max is None:
            raise ValueError("cc_modes='auto' needs f_max_hz or cutoff_hz (the CC"
                             " cutoff is CC_CUTOFF_FACTOR * f_max); give an integer"
                             " cc_modes with n_modes")
        return ("cutoff", (2 * np.pi * CC_CUTOFF_FACTOR * f_max) ** 2)
    if isinstance(cc_modes, bool) or not isinstance(cc_modes, (int, np.integer)) \
            or cc_modes < 0:
        raise ValueError(f"cc_modes must be an integer >= 0 or 'auto', got"
                         f" {cc_modes!r}")
    return ("count", min(int(cc_modes), n_b))


def _attachment_loads(model, dofs, attachments) -> np.ndarray:
    """Unit loads (n_b, n_a) on every interface DOF of the attachment nodes."""
    nodes = [node_indices(model.mesh, a, "attachments") for a in
             ([attachments] if isinstance(attachments, (str, int, np.integer))
              else attachments)]
    nodes = np.unique(np.concatenate(nodes)) if nodes else np.zeros(0, dtype=int)
    on_interface = np.isin(dofs // DOF_PER_NODE, nodes)
    missing = np.setdiff1d(nodes, dofs[on_interface] // DOF_PER_NODE)
    if missing.size:
        raise ValueError(f"attachments: node {int(missing[0])} is not an interface node;"
                         " attachment vectors are for interface nodes (mounts on interior"
                         " nodes need none)")
    pos = np.flatnonzero(on_interface)
    E = np.zeros((dofs.size, pos.size))
    E[pos, np.arange(pos.size)] = 1.0
    return E


def _image(Y, n_free, b, interior, Kib, lu):
    """``T Y = [Y; -K_ii⁻¹ K_ib Y]`` on the free DOFs, (n_free, k)."""
    W = np.zeros((n_free, Y.shape[1]))
    W[b] = Y
    W[interior] = -lu.solve(Kib @ Y)
    return W


def _m_orthonormal(W, MW, WQ, MWQ):
    """Columns of W made M-orthonormal to WQ and to each other; (W, MW) kept/dropped.

    Two classical Gram-Schmidt passes against WQ (Kahan-Parlett), then a scaled Gram
    eigen-decomposition that drops dependent directions (:data:`DROP_RTOL`)."""
    norms = np.sqrt(np.maximum(np.einsum("ij,ij->j", W, MW), 0.0))
    ok = norms > 0  # unit M-norms before the projection: the drop test is relative
    W, MW = W[:, ok] / norms[ok], MW[:, ok] / norms[ok]
    for _ in range(2 if WQ.shape[1] else 0):
        C = MWQ.T @ W
        W, MW = W - WQ @ C, MW - MWQ @ C
    w, Z = np.linalg.eigh(0.5 * ((W.T @ MW) + (W.T @ MW).T))
    keep = w > DROP_RTOL
    Z = Z[:, keep] / np.sqrt(w[keep])
    return W @ Z, MW @ Z


def characteristic_modes(K, M, b, interior, lu, full, want, seed: int = 0):
    """Lowest characteristic constraint modes of the Guyan interface pencil (S, M_G).

    Block Krylov iteration on ``S⁻¹ M_G`` with full M_G-reorthogonalisation (carried out
    on the images ``W = T Q``, since ``yᵀ M_G y = (T y)ᵀ M (T y)``) and Rayleigh-Ritz with
    the exact ``Wᵀ K W``; see the module docstring.

    Parameters
    ----------
    K, M : sparse (n_free, n_free)
    b, interior : ndarray of int
        Positions of the interface and interior DOFs among the free DOFs.
    lu, full : Factor
        Factorisations of K_ii and of ``K - σM`` (σ <= 0).
    want : ("count", n_c) or ("cutoff", ω²_cut)
    seed : int
        Seed of the random start block.

    Returns
    -------
    theta : ndarray (k,)
        CC eigenvalues (Ritz values, converged to :data:`RITZ_RTOL`), rad²/s².
    V : ndarray (n_b, k)
        Interface basis, M_G-orthonormal.
    W : ndarray (n_free, k)
        ``T V`` on the free DOFs.
    """
    n_free, n_b = K.shape[0], b.size
    Kib = K[interior][:, b]
    step = lambda G: _image(full.solve(G)[b], n_free, b, interior, Kib, lu)  # noqa: E731
    R = np.random.default_rng(seed).standard_normal((n_b, min(KRYLOV_BLOCK, n_b)))
    start = step(M @ _image(R, n_free, b, interior, Kib, lu))
    with _phase(KRYLOV_BLOCK):  # products with blocks of KRYLOV_BLOCK columns
        W, theta = _krylov(K, M, start, step, want, n_b)
    return theta, np.ascontiguousarray(W[b]), W


def _krylov(K, M, start, step, want, n_b):
    """Converged lowest Ritz pairs (images W (n_free, k), values (k,)) of the pencil that
    ``step`` inverts (``step(M W)`` is the next block of images), the basis kept
    M-orthonormal; k by ``want`` (a count or the Ritz values below a cutoff)."""
    kind, value = want
    cap = min(n_b, 4 * start.shape[1])
    WQ = np.empty((K.shape[0], cap))
    block, _ = _m_orthonormal(start, M @ start, WQ[:, :0], WQ[:, :0])
    m, Kp, previous = 0, np.zeros((0, 0)), None
    while block.shape[1]:
        if m + block.shape[1] > cap:
            cap = min(max(2 * cap, m + block.shape[1]), n_b + start.shape[1])
            WQ = np.concatenate([WQ[:, :m], np.empty((K.shape[0], cap - m))], axis=1)
        KB = K @ block
        cross = WQ[:, :m].T @ KB
        Kp = np.block([[Kp, cross], [cross.T, block.T @ KB]])
        WQ[:, m:m + block.shape[1]] = block
        m += block.shape[1]
        theta, C = np.linalg.eigh(0.5 * (Kp + Kp.T))
        k = value if kind == "count" else int(np.count_nonzero(theta <= value))
        if m >= n_b or _converged(theta, previous, min(k + 1, m), block.shape[1]):
            k = min(k, m)
            return WQ[:, :m] @ C[:, :k], theta[:k]
        previous = theta
        nxt = step(M @ block)
        block, _ = _m_orthonormal(nxt, M @ nxt, WQ[:, :m], M @ WQ[:, :m])
    k = value if kind == "count" else int(np.count_nonzero(theta <= value))
    return WQ[:, :m] @ C[:, :min(k, m)], theta[:min(k, m)]


def _converged(theta, previous, k, p) -> bool:
    """The lowest k Ritz values moved by less than RITZ_RTOL, with a block beyond them."""
    if previous is None or previous.size < k or theta.size < k + p:
        return False
    scale = np.maximum(np.abs(theta[:k]), 1e-4 * abs(theta[k - 1]))
    return bool(np.all(np.abs(previous[:k] - theta[:k]) <= RITZ_RTOL * scale))


def _project(K, M, W, interior, Mii, Phi, omega2):
    """Reduced K, M of the basis [[V, 0], [Ψ V, Φ]] from its images W = T V (n_free, n_c).

    The coupling ``Φᵀ (K_ib V + K_ii Ψ V)`` vanishes (K_ii Ψ = -K_ib), so K_r is block
    diagonal; every dense product is (n_free or n_i) x (n_c or n_q) wide."""
    KW, MW = K @ W, M @ W
    n_c, n_q = W.shape[1], Phi.shape[1]
    Kr = np.zeros((n_c + n_q, n_c + n_q))
    Mr = np.zeros_like(Kr)
    Kcc, Mcc = W.T @ KW, W.T @ MW
    Kr[:n_c, :n_c] = 0.5 * (Kcc + Kcc.T)
    Kr[n_c:, n_c:] = np.diag(omega2)
    Mr[:n_c, :n_c] = 0.5 * (Mcc + Mcc.T)
    Mcq = MW[interior].T @ Phi
    Mr[:n_c, n_c:], Mr[n_c:, :n_c] = Mcq, Mcq.T
    Mqq = Phi.T @ (Mii @ Phi)
    Mr[n_c:, n_c:] = 0.5 * (Mqq + Mqq.T)
    return Kr, Mr


def interface_error_estimates(model: FEModel, se: Superelement, omega2, q,
                              loads=None) -> np.ndarray:
    """A-posteriori relative frequency errors of reduced eigenpairs against the unreduced
    model, without a full eigensolve.

    For a Ritz pair (λ̃, u = T_r q) with ``uᵀ M u = 1`` the residual
    ``r = K u - λ̃ M u - f`` (f: the loads of attached mechanisms in that mode, zero for
    the superelement alone) is orthogonal to the reduced basis, and
    ``λ̃ - λ ≈ rᵀ (K - λ M)⁻¹ r ≈ rᵀ K⁻¹ r`` (first order in λ / ω² of the truncated
    directions, as :func:`~femmech.reduction.estimate.frequency_error_estimates`, which
    covers the interior only). Here the residual lives on the interface too, and
    ``K⁻¹`` is applied with the factorisation of ``K - σM`` kept from the reduction.
    The relative frequency error is half the relative eigenvalue error.

    Parameters
    ----------
    model : FEModel
        The model that was reduced.
    se : Superelement
        From :func:`reduce_interface` (or any superelement: the full K is then factorised).
    omega2 : ndarray (k,)
        Reduced (or coupled) eigenvalues, rad²/s².
    q : ndarray (n_r, k)
        The frame part of the reduced eigenvectors, scaled so that the whole eigenvector
        (frame and mechanism coordinates) has unit modal mass.
    loads : ndarray (n_free, k), optional
        Forces of the attached mechanisms on the frame's free DOFs in each mode, N (or
        N m), e.g. ``-ℓᵀ (C_m - λ M_m) q_m`` per attachment row ℓ.

    Returns
    -------
    ndarray (k,)
        Estimated ``(f_reduced - f_full) / f_full``; 0 for rigid-body modes.
    """
    K, M = model.K_free.tocsr(), model.M_free.tocsr()
    full = se.interface_factor
    if full is None:
        full = factorize((K - default_shift(K, M) * M).tocsc())
    omega2 = np.atleast_1d(np.asarray(omega2, dtype=float))
    u = se.expand_free(np.asarray(q, dtype=float).reshape(se.n_reduced, -1))
    r = K @ u - (M @ u) * omega2
    if loads is not None:
        r -= np.asarray(loads, dtype=float).reshape(r.shape)
    eta = np.einsum("ij,ij->j", r, full.solve(r))
    scale = np.abs(se.K).max() / max(np.abs(se.M).max(), 1e-300)
    rigid = np.abs(omega2) <= 1e-12 * scale
    return np.where(rigid, 0.0, 0.5 * eta / np.where(rigid, 1.0, omega2))


def attachment_loads(se: Superelement, system, phi: float, omega2, vectors) -> np.ndarray:
    """Forces (n_free, k) of the mounted mechanisms on the frame's free DOFs in coupled
    modes, for :func:`interface_error_estimates`.

    For a rigid attachment of mechanism coordinate c (primal form) the force is
    ``-ℓ h_c`` with ``h = (C_m - λ M_m) q_m`` the mechanism's generalised force and ℓ the
    attachment's physical row (weights on the node's free DOFs); an elastic one adds
    ``-ℓ k (ℓᵀu - q_own)``. Undamped quasi-modes at drive speed 0.

    Parameters
    ----------
    se : Superelement
        ``system.frame``.
    system : femmech.coupling.CoupledSystem
        Primal form, frame ``se``.
    phi : float
        Main drive angle of the modes, rad.
    omega2 : ndarray (k,)
        Coupled eigenvalues, rad²/s².
    vectors : ndarray (n, k)
        Coupled modes, mass-normalised with the coupled M(φ).
    """
    if system.frame is not se or system.H is not None:
        raise ValueError("attachment_loads needs a primal coupled system whose frame is se")
    lam = np.atleast_1d(np.asarray(omega2, dtype=float))
    X = np.asarray(vectors, dtype=float).reshape(system.n, -1)
    loads = np.zeros((se.T.shape[1], X.shape[1]))
    for mount, P, idx in zip(system.mounts, system.projections, system.touched, strict=True):
        angle = mount.ratio * phi + mount.phase
        Mm, Cm = mount.model.M(angle), mount.model.C(angle, 0.0, 0.0)
        qm = P @ X[idx]
        names = list(mount.model.coordinate_names)
        for att in mount.attachments:
            ell = _physical_row(se, att.node, att.direction)
            c = names.index(att.coordinate)
            if att.stiffness is None:
                h = Cm[c] @ qm - lam * (Mm[c] @ qm)
                loads -= np.outer(ell, h)
            else:
                own = system.labels.index(f"{mount.name}.{att.coordinate}")
                stretch = ell @ se.expand_free(X[:system.n_frame]) - X[own]
                loads -= np.outer(ell, float(att.stiffness) * stretch)
    return loads


def _physical_row(se: Superelement, node, direction) -> np.ndarray:
    """Weights (n_free,) of an attachment's direction on the free DOFs of its node."""
    if isinstance(direction, str):
        w = np.zeros(DOF_PER_NODE)
        w[COMPONENTS.index(direction)] = 1.0
    else:
        w = np.asarray(direction, dtype=float)
    rows = se.T.tocsr()[DOF_PER_NODE * int(node) + np.arange(DOF_PER_NODE)]
    return np.asarray(rows.T @ w).ravel()
