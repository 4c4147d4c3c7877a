"""Shift-invert block Lanczos for the eigenpairs of ``K x = λ M x`` nearest a shift σ.

:func:`lowest_pairs` runs femmech's block Lanczos (:func:`block_lanczos`, with partial
reorthogonalisation and thick restarts; its steps are the methods of
:class:`_BlockLanczos`) and falls back to ARPACK (:mod:`.arpack`) where it does not
converge; the constants below set its tolerances, block size, reorthogonalisation and
memory. It also tells the caller when σ lies far below the wanted eigenvalues
(:class:`FarShiftError`).

Stage 1, solve (linear algebra): imports only :mod:`femmech.errors` and other
:mod:`femmech.solve` modules, never :mod:`femmech.fe` or higher.
"""

from __future__ import annotations

import contextlib
import warnings

import numpy as np
import scipy.sparse as sp

from femmech.errors import FemmechWarning
from femmech.solve import threads
from femmech.solve.arpack import arpack, purify
from femmech.solve.pencil import n_mass
from femmech.solve.sturm import complete_cluster

LANCZOS_TOL = 1e-12
"""Convergence of :func:`block_lanczos`: ``‖S x - θ x‖_M <= LANCZOS_TOL |θ|`` for every
wanted Ritz pair of ``S = (K - σM)⁻¹ M``. Eigenvalue errors go like the square of this
(measured 5e-15 relative on 24k and 151k-DOF frames against ARPACK at machine
precision); the relative residuals ``‖K x - λ M x‖ / (λ ‖M x‖)`` come out 10-300 times
larger (they weigh the stiff directions): 1e-10 to 6e-10 on those frames."""

GUARD_TOL = 1e-6
"""Convergence of the guard pairs of :func:`block_lanczos` (computed beyond the wanted
ones only to see whether the last wanted eigenvalue is repeated): their eigenvalues are
then accurate to ~1e-12, far below the 1e-6 of a cluster (:func:`~.sturm.complete_cluster`)."""

BLOCK_SIZE = 2
"""Block size of :func:`block_lanczos`. b >= 2 finds both members of a double
eigenvalue (symmetric structures) in one run, where single-vector Lanczos finds the
second only late, from round-off (a 24k-DOF frame: a 20-mode run with b = 1 returned
the 21st eigenvalue 5 % too high). Larger blocks need more vectors for the same modes
(21 modes of that frame: 86, 116 and 184 vectors for b = 2, 4, 8), and the
orthogonalisation, which grows with the square of the basis, costs more than the
block solves save (CHOLMOD solves 4 right-hand sides in ~2 times the time of one)."""

REORTHOGONALIZE_BELOW = 0.5
"""A second classical Gram-Schmidt pass runs for a block in which a vector kept less than
this fraction of its M-norm in the first (DGKS criterion; measured on a 24k-DOF frame:
most vectors keep 0.3-0.5 against the whole basis). With 0.01 (one pass nearly always)
the loss of orthogonality stalled the Ritz residuals at ~2e-11 relative, above
:data:`LANCZOS_TOL`."""

SEMI_ORTHOGONAL = float(np.sqrt(np.finfo(float).eps))
"""Partial reorthogonalisation (H. D. Simon, "The Lanczos algorithm with partial
reorthogonalization", Math. Comp. 42 (1984) 115-142; block form: R. G. Grimes, J. G.
Lewis, H. D. Simon, SIAM J. Matrix Anal. Appl. 15 (1994) 228-272): a new block is
orthogonalised against the whole basis only when the estimated loss of M-orthogonality
exceeds this (then it and the next block are). Semi-orthogonality keeps the Ritz values
as accurate as full reorthogonalisation: on a 151k-DOF frame 15 of 43 blocks were
reorthogonalised, the iteration took 1.6 s against 2.4 s with every block, with the
same eigenvalues to 1e-14."""

PROBES = 4
"""Random combinations of the Lanczos basis whose M-inner products with each new block
measure the loss of orthogonality that the recurrence of :data:`SEMI_ORTHOGONAL` does not
model: solves of an ill-conditioned ``K - σM`` (a 1e16 N/m connector on 1e3 N/m mounts)
lose it faster than ~eps |S| per step, and a run without them returned a mode with a
relative residual of 1e-4."""

MAX_BASIS_BYTES = 4 * 1024**3
"""Memory of the Lanczos basis (V and MV); beyond it the basis is restarted (thick
restart): 268 vectors at 1M DOFs, no restart for 20-40 modes up to ~1M DOFs."""

MAX_SOLVES_PER_MODE = 40
"""Cap of :func:`block_lanczos`: after ``MAX_SOLVES_PER_MODE k + 400`` solved vectors
without convergence (normal runs take 3-5 per mode) it gives up and ARPACK takes over
(:func:`lowest_pairs`); a safeguard against a basis that restarts without progress."""

_EPS = float(np.finfo(float).eps)

STREAM_COLUMNS = 16
"""Products with at least this many basis columns run under
:func:`femmech.solve.threads.gemm_phase` (all threads) inside Lanczos' one-thread loop."""

FAR_SHIFT = 100.0
"""A default shift σ < 0 counts as too far below the wanted eigenvalues when
``-σ > FAR_SHIFT λ_1`` for the Ritz estimate λ_1 of the lowest eigenvalue after 2k
Lanczos vectors: then the wanted θ = 1/(λ - σ) crowd together and Lanczos (and ARPACK)
converge slowly. The default shift ``-1e-6 λ_max`` of a model with very stiff parts can
be that far: the full textile shaft (150k DOFs, stiff cam contacts) had σ = -2.8e9 rad²/s²
for eigenvalues of 4e5-5e6; block Lanczos had not converged after 1 122 solves (31 s)
and ARPACK took 35 s more, while at σ = -2.8e6 the whole solve took 1.6 s.
:func:`~.eigen._sparse_lowest` then moves the shift to ``-max(λ_1, 1e-3 |σ|)`` and factorises
once more: the bound keeps the condition of ``K - σM`` (~λ_max/|σ|) below ~1e9. Models
with rigid-body modes (a Ritz value ~0) keep the default shift, whose distance from 0
is what makes their solves accurate (a free thin shell moved to -λ_1 had rigid-mode
residuals of 1.5e-6); frames and shells of the benchmarks have -σ / λ_1 = 0.2-1."""


class _NotConvergedError(RuntimeError):
    """:func:`block_lanczos` reached :data:`MAX_SOLVES_PER_MODE`."""


class FarShiftError(RuntimeError):
    """:func:`block_lanczos` found σ far below the wanted eigenvalues; ``shift`` is a
    better one (rad²/s²)."""

    def __init__(self, shift: float):
        super().__init__(f"shift far from the wanted eigenvalues; try {shift:.6g}")
        self.shift = shift


def lowest_pairs(K, M, k, sigma, lu, deflate=None, n_wanted=None, far_check=False):
    """``k`` eigenpairs nearest σ: block Lanczos, ARPACK where it does not converge.
    ``far_check``: raise :class:`FarShiftError` where σ is too far (:data:`FAR_SHIFT`)."""
    try:
        return block_lanczos(K, M, k, sigma, lu, deflate=deflate, n_wanted=n_wanted,
                              far_check=far_check)
    except _NotConvergedError as exc:
        warnings.warn(f"{exc}; falling back to ARPACK", FemmechWarning, stacklevel=3)
        return arpack(K, M, k, sigma, lu, deflate=deflate)


def _streaming(columns: int):
    """All threads for a product over ``columns`` basis columns (:data:`STREAM_COLUMNS`)."""
    return threads.gemm_phase() if columns >= STREAM_COLUMNS else contextlib.nullcontext()


def block_lanczos(K, M, k, sigma, lu, deflate=None, block=BLOCK_SIZE, tol=LANCZOS_TOL,
                   max_dim=None, seed=12345, n_wanted=None, partial=True, far_check=False):
    """``k`` eigenpairs nearest ``sigma`` by block Lanczos on ``S = (K - σM)⁻¹ M``.

    Each new block is M-orthonormalised against the previous two (block three-term
    recurrence) and, by partial reorthogonalisation (:data:`SEMI_ORTHOGONAL`), against the
    whole basis only when the estimated loss of orthogonality requires it: passes over
    the basis are memory-bound (at 151k DOFs and 90 vectors one costs about as much as
    five solves). Rayleigh-Ritz on the projected operator ``T = VᵀMSV`` (block
    tridiagonal; ``λ = σ + 1/θ``, as accurate as shift-invert ARPACK), convergence from
    the Ritz residuals ``‖S x - θ x‖_M = ‖B y_last‖`` of the recurrence. When the basis
    reaches ``max_dim`` vectors (default ``max(5k + 2b, 100)`` within
    :data:`MAX_BASIS_BYTES`) it is restarted with the best ``k + b`` Ritz vectors and the
    next block (thick restart) and continues with full reorthogonalisation of every block
    (as with ``partial=False``, and after a block lost rank). The start block is ``S R``
    for a random R, so every basis vector lies in the range of S (no components that M
    does not see). ``deflate`` (n, m): M-orthonormal eigenvectors projected out of the
    operator, as in :func:`~.arpack.arpack`.

    ``n_wanted``: only the ``n_wanted`` pairs nearest σ (and the rest of a cluster cut at
    the last of them) must reach ``tol``; the others of the k, guards that show whether the
    last wanted eigenvalue is repeated, stop at :data:`GUARD_TOL`. Default: all k.

    Returns ``omega2`` (ascending) and the Ritz vectors X (M-orthonormal).

    The steps are methods of :class:`_BlockLanczos`: the start block
    (:meth:`~_BlockLanczos.start`), one block step with local orthogonalisation and partial
    reorthogonalisation (:meth:`~_BlockLanczos.local_step`) or full reorthogonalisation
    (:meth:`~_BlockLanczos.full_step`), Rayleigh-Ritz and the convergence test
    (:meth:`~_BlockLanczos.ritz`, :meth:`~_BlockLanczos.converged`), a new direction where
    the Krylov space is (nearly) invariant (:meth:`~_BlockLanczos.widen`) and the thick
    restart (:meth:`~_BlockLanczos.restart`).
    """
    lanczos = _BlockLanczos(K, M, k, sigma, lu, deflate, block, tol, max_dim, seed, n_wanted)
    theta, Y, m = lanczos.iterate(partial, far_check)
    return lanczos.ritz_pairs(theta, Y, m)


class _BlockLanczos:
    """State of one run of :func:`block_lanczos`: the basis V, MV, the projected operator
    H, the orthogonality estimates of partial reorthogonalisation and the random probes."""

    def __init__(self, K, M, k, sigma, lu, deflate, block, tol, max_dim, seed, n_wanted):
        n = K.shape[0]
        n_defl = 0 if deflate is None else deflate.shape[1]
        krylov = n_mass(M) - n_defl
        k = min(k, krylov)
        if k < 1:
            raise ValueError(f"no further finite eigenvalue: only {n_mass(M)} of the {n} DOFs"
                             " carry mass")
        n_wanted = k if n_wanted is None else min(n_wanted, k)
        block = max(1, min(block, k))
        if max_dim is None:
            max_dim = min(max(5 * k + 2 * block, 100), MAX_BASIS_BYTES // (16 * n) - block)
        max_dim = max(min(max_dim, krylov), min(k + 2 * block, krylov))
        self.keep = min(k + block, max_dim - block)  # Ritz vectors kept at a thick restart
        self.rng = np.random.default_rng(seed)
        self.n, self.n_defl, self.krylov, self.k, self.n_wanted = n, n_defl, krylov, k, n_wanted
        self.block, self.max_dim, self.sigma, self.lu, self.tol = block, max_dim, sigma, lu, tol
        if n_defl:
            self.deflate, self.MX = deflate, M @ deflate
        if sp.issparse(M):
            M = M.tocsr()
        self.M = M
        self.V = np.empty((n, max_dim + block), order="F")  # columns contiguous: BLAS on V[:, :m]
        self.MV = np.empty((n, max_dim + block), order="F")
        self.H = np.zeros((max_dim + block, max_dim + block))
        self.work = np.empty((n, block), order="F")  # products V c, updated in place: the loop
        # allocates few vectors (a first touch of fresh memory costs ~1 ms per MB on the
        # project's VM; temporaries served by mmap made a 24k-DOF solve 1.8x slower)
        # partial reorthogonalisation: omega[i] estimates V_iᵀ M V_j for the blocks i <= j of
        # the current block j (omega_prev: of block j - 1); Grimes-Lewis-Simon recurrence
        self.omega = np.zeros((max_dim // block + 2, block, block))
        self.omega[0] = np.eye(block)
        self.omega_prev = np.zeros_like(self.omega)
        self.norm_t = 0.0
        self.force = False
        self.partial = True

    def project(self, Y):
        """Y without components along the deflated eigenvectors (``P = I - X Xᵀ M``)."""
        if not self.n_defl:
            return Y
        return Y - self.deflate @ (self.MX.T @ Y)

    def operator(self, MY):
        """``P (K - σM)⁻¹`` applied to MY (the deflated shift-invert operator on M Y)."""
        return self.project(self.lu.solve(MY))

    def m_times(self, W):
        """M W as an F-ordered block: column by column (scipy's multi-vector CSR product
        took 6.2 ms for two columns of 151k, two single products 2.6 ms, and it returns C
        order, which made later in-place updates of F-ordered blocks 17x slower)."""
        M = self.M
        if not sp.issparse(M):
            return np.asfortranarray(M @ W)
        out = np.empty(W.shape, order="F")
        for col in range(W.shape[1]):
            out[:, col] = M @ W[:, col]
        return out

    def orthogonalize(self, W, lo, hi, passes=3):
        """Classical Gram-Schmidt of W against V[:, lo:hi]; a further pass where one
        cancelled more than :data:`REORTHOGONALIZE_BELOW`. Returns (W, MW, C)."""
        V, MV = self.V, self.MV
        C = np.zeros((hi - lo, W.shape[1]))
        MW = None
        for _ in range(passes if hi > lo else 0):
            with _streaming(hi - lo):
                c = MV[:, lo:hi].T @ W
                W = W - V[:, lo:hi] @ c
            C += c
            MW = self.m_times(W)
            kept = np.diag(W.T @ MW)
            # M-norm² before the pass = kept + |c|² (Pythagoras; exact for M-orthonormal V)
            if np.all(kept >= REORTHOGONALIZE_BELOW**2 * (kept + (c * c).sum(axis=0))):
                break
        return W, (self.m_times(W) if MW is None else MW), C

    def orthogonalize_local(self, W, lo, hi):
        """Two classical Gram-Schmidt passes of W (overwritten) against the last blocks
        V[:, lo:hi], then one product with M. Returns (W, MW, C, WᵀMW). (A second pass
        only where DGKS asks for it would run on 43 of 43 blocks of the 151k-DOF frame:
        the recurrence cancels more than 3/4 of every new block's M-norm squared.)"""
        V, MV = self.V, self.MV
        part = self.work[:, :W.shape[1]]
        C = np.zeros((hi - lo, W.shape[1]))
        for _ in range(2):
            c = MV[:, lo:hi].T @ W
            np.matmul(V[:, lo:hi], c, out=part)
            W -= part
            C += c
        MW = self.m_times(W)
        return W, MW, C, W.T @ MW

    def normalize(self, W, MW, C, room, at=None, gram=None):
        """M-orthonormal basis Q of W (M-orthogonal to the basis): (Q, MQ, R), W = Q R.

        Directions that keep less than 1e-12 of the block's M-norm before the
        orthogonalisation (coefficients C) are numerically in span(V) and dropped (R loses
        rows), as are directions beyond ``room`` (M has no more rank). ``at``: write Q and
        MQ into the basis at column ``at`` (views are returned).
        """
        gram = W.T @ MW if gram is None else gram
        d, U = np.linalg.eigh(0.5 * (gram + gram.T))
        d, U = d[::-1], U[:, ::-1]
        size = np.sqrt(np.maximum(d, 0.0))
        before = np.sqrt(float(np.einsum("ij,ij->", C, C)) + max(d[0], 0.0)) if d.size else 0
        ok = (size > 1e-12 * before) & (np.cumsum(np.ones(len(d))) <= room)
        factor = U[:, ok] / size[ok]
        R = (U[:, ok] * size[ok]).T
        if at is None:
            return W @ factor, MW @ factor, R
        q = factor.shape[1]
        np.matmul(W, factor, out=self.V[:, at:at + q])
        np.matmul(MW, factor, out=self.MV[:, at:at + q])
        return self.V[:, at:at + q], self.MV[:, at:at + q], R

    def fresh(self, count, m):
        """``count`` new random directions S r, M-orthonormal to V[:, :m]."""
        W = self.project(self.operator(self.m_times(self.project(
            self.rng.standard_normal((self.n, count))))))
        W, MW, C = self.orthogonalize(W, 0, m)
        return self.normalize(W, MW, C, self.krylov - m)[:2]

    def converged(self, theta, est):
        """Whether the wanted Ritz pairs reached ``tol`` and the guards :data:`GUARD_TOL`."""
        k, tol = self.k, self.tol
        if len(theta) < k:
            return False
        lam = np.sort(self.sigma + 1.0 / theta[:k])
        tight = complete_cluster(lam, self.n_wanted) if self.n_wanted < k else k
        limit = np.where(np.arange(k) < tight, tol, max(tol, GUARD_TOL))
        return bool(np.all(est[:k] <= limit * np.abs(theta[:k])))

    def start(self):
        """The start block S R (random R) in the basis, and the probes; returns its size."""
        Q, MQ = self.fresh(self.block, 0)
        m = Q.shape[1]
        self.V[:, :m], self.MV[:, :m] = Q, MQ
        weights = self.rng.standard_normal((m, PROBES))
        self.probe_m, self.probe_n = MQ @ weights, (weights * weights).sum(axis=0)  # M P, |P|²_M
        self.probe_w = np.empty_like(self.probe_m)
        return m

    def iterate(self, partial, far_check):
        """The Lanczos loop: block steps until the Ritz pairs converge. ``partial`` and
        ``far_check`` as in :func:`block_lanczos`. Returns the Ritz values θ (nearest σ
        first), their coefficients Y in the basis and the basis size m."""
        block, krylov, k, H = self.block, self.krylov, self.k, self.H
        with threads.solve_phase():  # a loop of solves and thin products: 1 BLAS thread
            m = self.start()
            j0 = 0
            # near an exhausted Krylov space (few DOFs with mass) the local recurrence cannot
            # tell new directions from old ones: reorthogonalise fully there
            self.partial = partial and m == block and self.max_dim < krylov
            solved, max_solved = m, MAX_SOLVES_PER_MODE * k + 400
            while True:
                if solved > max_solved:
                    raise _NotConvergedError(f"block Lanczos: {k} eigenpairs near"
                                             f" σ = {self.sigma:.6g} not converged after"
                                             f" {solved} solves")
                SQ = self.operator(self.MV[:, j0:m])
                solved += m - j0
                Q, MQ, R, b = self.step(SQ, j0, m)
                H[m:m + b, j0:m] = R
                H[j0:m, m:m + b] = R.T
                if m < min(k, krylov) and b == block:  # fewer Ritz pairs than wanted:
                    Q, MQ, m, j0 = self.extend(Q, MQ, m)  # no Rayleigh-Ritz yet
                    continue
                theta, Y, est = self.ritz(m, j0, b, R)
                if far_check and m >= 2 * k + 2 * block:  # once: is σ far from the wanted?
                    far_check = False
                    self.check_shift(theta)
                if self.converged(theta, est) or (b == 0 and m >= krylov):
                    break
                if b < block and m + b < krylov:  # Krylov space (nearly) invariant: widen it
                    Q, MQ = self.widen(Q, MQ, m, b)
                if m + Q.shape[1] > self.max_dim:  # thick restart: best Ritz vectors + next block
                    Q, MQ, m = self.restart(Q, MQ, R, theta, Y, m, j0)
                b = Q.shape[1]
                if not np.may_share_memory(Q, self.V):  # (normalize wrote it there already)
                    self.V[:, m:m + b], self.MV[:, m:m + b] = Q, MQ
                j0, m = m, m + b
        return theta, Y, m

    def extend(self, Q, MQ, m):
        """Append the full block Q (when no Ritz pair can have converged yet: the basis
        holds fewer than k vectors); returns (Q, MQ, m, j0) for the next step."""
        b = Q.shape[1]
        if not np.may_share_memory(Q, self.V):
            self.V[:, m:m + b], self.MV[:, m:m + b] = Q, MQ
        return Q, MQ, m + b, m

    def step(self, SQ, j0, m):
        """The next block Q from SQ = S V[:, j0:m], M-orthonormal to the basis: locally
        orthogonalised while the basis is semi-orthogonal, else fully. Returns
        (Q, MQ, R, b), SQ = Q R + V C, b = Q's columns (0: no new direction)."""
        b = 0
        local = None
        if self.partial:  # local orthogonalisation against the blocks j - 1 and j
            Q, MQ, R, b, local = self.local_step(SQ, j0, m)
            if not b:
                self.partial = False  # a block lost rank: full reorthogonalisation from here
        if not self.partial:
            Q, MQ, R, b = self.full_step(SQ, j0, m, local)
        return Q, MQ, R, b

    def local_step(self, SQ, j0, m):
        """Orthogonalisation of SQ against the blocks j - 1 and j (block three-term
        recurrence), and against the whole basis where the estimated loss of orthogonality
        exceeds :data:`SEMI_ORTHOGONAL`. Returns (Q, MQ, R, b, local): b = block if Q
        is a full block (0: rank lost), local = (lo, C) of the local pass."""
        block, H, krylov = self.block, self.H, self.krylov
        b = 0
        j, lo = j0 // block, max(0, j0 - block)
        W, MW, C, gram = self.orthogonalize_local(SQ, lo, m)  # SQ overwritten
        local = (lo, C)
        Q, MQ, R = self.normalize(W, MW, C, krylov - m, at=m, gram=gram)
        if Q.shape[1] == block:
            A = 0.5 * (C[-block:] + C[-block:].T)
            B = H[j0:m, lo:j0]  # coefficient of block j in S V_{j-1} (empty: j = 0)
            self.norm_t = max(self.norm_t, np.abs(A).sum(1).max() + np.abs(R).sum(0).max()
                              + np.abs(B).sum(1).max(initial=0.0))
            r_inv = np.linalg.inv(R)
            new = self.estimate(j, A, B, r_inv)
            # the estimates assume solves accurate to ~eps |S|; an ill-conditioned
            # K - σM (stiff connectors on soft mounts) loses orthogonality faster:
            # random combinations of the basis measure it (RMS over the blocks)
            seen = np.abs(self.probe_m.T @ Q).max() / np.sqrt(self.probe_n.min()) * np.sqrt(j + 1)
            if self.force or max(np.abs(new[:j]).max(initial=0.0), seen) > SEMI_ORTHOGONAL:
                Wq, MWq, c = self.orthogonalize(Q, 0, m, passes=1)
                Q2, MQ2, fix = self.normalize(Wq, MWq, c, krylov - m)
                if Q2.shape[1] == block:
                    Q, MQ, R = Q2, MQ2, fix @ R
                    new[:j + 1] = _EPS
                    self.force = not self.force  # this block and the next one
                else:
                    Q = Q2
            if Q.shape[1] == block:
                self.accept(j, j0, m, new, MQ, A)
                b = block
        return Q, MQ, R, b, local

    def estimate(self, j, A, B, r_inv):
        """Estimates of V_iᵀ M V_{j+1} for the blocks i < j (Grimes-Lewis-Simon recurrence
        from the block coefficients A = V_jᵀ M S V_j, B and R⁻¹), with a round-off term."""
        block, H, omega, omega_prev = self.block, self.H, self.omega, self.omega_prev
        new = np.zeros_like(omega)
        if j:  # V_iᵀ M V_{j+1} for i < j
            i = np.arange(j)  # the diagonal and subdiagonal blocks of H, (j, b, b) each
            diag = H[:j * block, :j * block].reshape(j, block, j, block)[i, :, i, :]
            down = H[block:(j + 1) * block, :j * block].reshape(j, block, j, block)[i, :, i, :]
            up = np.concatenate([np.zeros((1, block, block)), down[:-1]])
            below = np.concatenate([np.zeros((1, block, block)), omega[:j - 1]])
            est = (up @ below + diag @ omega[:j]
                   + np.transpose(down, (0, 2, 1)) @ omega[1:j + 1]
                   - omega[:j] @ A - omega_prev[:j] @ B.T) @ r_inv
            noise = _EPS * self.norm_t * np.linalg.norm(r_inv, 2) * np.sqrt(block)
            new[:j] = est + np.where(est >= 0, noise, -noise)
        return new

    def accept(self, j, j0, m, new, MQ, A):
        """Take the full block j + 1 of a local step: its orthogonality estimates ``new``,
        the probes' new random combination of it, the diagonal block A of H."""
        new[j] = _EPS
        self.omega_prev, self.omega = self.omega, new
        self.omega[j + 1] = np.eye(self.block)
        weights = self.rng.standard_normal((self.block, PROBES))
        self.probe_m += np.matmul(MQ, weights, out=self.probe_w)
        self.probe_n += (weights * weights).sum(axis=0)
        self.H[j0:m, j0:m] = A

    def full_step(self, SQ, j0, m, local):
        """Classical Gram-Schmidt of SQ against the whole basis; ``local``: (lo, C) of a
        local pass that already overwrote SQ. Returns (Q, MQ, R, b)."""
        W, MW, C = self.orthogonalize(SQ, 0, m)
        if local is not None:  # SQ was locally orthogonalised in place first
            C[local[0]:m] += local[1]
        Q, MQ, R = self.normalize(W, MW, C, self.krylov - m)
        b = Q.shape[1]
        self.H[:m, j0:m] = C
        return Q, MQ, R, b

    def ritz(self, m, j0, b, R):
        """Rayleigh-Ritz on H[:m, :m]: θ (nearest σ first), Y, and the Ritz residuals
        ``‖B y_last‖`` of the recurrence (R: the new block's coefficient, b its size)."""
        H = self.H
        theta, Y = np.linalg.eigh(0.5 * (H[:m, :m] + H[:m, :m].T))
        order = np.argsort(-np.abs(theta))  # nearest σ first
        theta, Y = theta[order], Y[:, order]
        est = np.linalg.norm(R @ Y[j0:m, :], axis=0) if b else np.zeros(m)
        return theta, Y, est

    def check_shift(self, theta):
        """:class:`FarShiftError` where σ is far below the wanted eigenvalues
        (:data:`FAR_SHIFT`)."""
        sigma = self.sigma
        lam = sigma + 1.0 / theta[:self.k]
        low = lam.min()  # no rigid-body modes (|λ| ~ 0) and no negative ones
        if sigma < 0 and low > 1e-6 * -sigma and -sigma > FAR_SHIFT * low:
            raise FarShiftError(-max(low, 1e-3 * -sigma))

    def widen(self, Q, MQ, m, b):
        """The b < block directions Q completed by fresh random ones (the Krylov space is
        nearly invariant); full reorthogonalisation from here."""
        V, MV = self.V, self.MV
        self.partial = False
        V[:, m:m + b], MV[:, m:m + b] = Q, MQ
        Z, MZ = self.fresh(min(self.block - b, self.krylov - m - b), m + b)
        return np.hstack([V[:, m:m + b], Z]), np.hstack([MV[:, m:m + b], MZ])

    def restart(self, Q, MQ, R, theta, Y, m, j0):
        """Thick restart: the best Ritz vectors become the basis, Q (the next block) is
        orthogonalised against them. Returns (Q, MQ, m)."""
        V, MV, H = self.V, self.MV, self.H
        self.partial = False
        p = self.keep
        with _streaming(m):
            U, MU = V[:, :m] @ Y[:, :p], MV[:, :m] @ Y[:, :p]
        # re-M-orthonormalise (a semi-orthogonal basis gives Ritz vectors
        # orthogonal to ~1e-8 only): U' = U L⁻ᵀ, S U' = U' Lᵀ Θ L⁻ᵀ + Q R Y L⁻ᵀ
        chol = np.linalg.cholesky(0.5 * (U.T @ MU + MU.T @ U))
        inv_t = np.linalg.inv(chol).T
        V[:, :p], MV[:, :p] = U @ inv_t, MU @ inv_t
        H[:] = 0.0
        H[:p, :p] = chol.T @ (theta[:p, None] * inv_t)
        H[:p, :p] = 0.5 * (H[:p, :p] + H[:p, :p].T)
        coupling = (R @ Y[j0:m, :p]) @ inv_t
        H[p:p + coupling.shape[0], :p] = coupling
        m = p
        c = MV[:, :m].T @ Q  # Q against the new basis (round-off level)
        return Q - V[:, :m] @ c, MQ - MV[:, :m] @ c, m

    def ritz_pairs(self, theta, Y, m):
        """``omega2`` (ascending) and the Ritz vectors X of the wanted k."""
        sigma = self.sigma
        k = min(self.k, len(theta))
        order = np.argsort(1.0 / theta[:k])  # ascending λ = σ + 1/θ, ordered before the
        omega2 = sigma + 1.0 / theta[:k][order]  # product (columns of an n x k result)
        with _streaming(m):
            X = self.V[:, :m] @ Y[:, :k][:, order]
        if self.n_defl:
            X = self.project(X)
        if self.krylov + self.n_defl < self.n:
            X = purify(X, omega2, sigma, self.M, self.operator)
        return omega2, X


