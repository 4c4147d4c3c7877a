"""Quasi-eigenfrequencies of a chain over the drive angle (slowly varying parameters),
tracked branch by branch, by any of the chain methods side by side.

* ``"transfer"`` (:func:`~femmech.chain.transfer.transfer_modes`) and ``"assembled"``
  (:func:`~femmech.chain.transfer.assembled_modes`): branches are followed by the
  mass-weighted MAC with frequency continuity, cluster-aware (the assignment of
  :mod:`femmech.analysis.sweep`: a branch is compared with the span of a cluster of
  close frequencies, so the arbitrary basis of a nearly repeated root cannot swap
  branches, and the vector MAC within the cluster keeps crossing branches apart);
* ``"cyclic"`` and ``"continuum"`` (:mod:`femmech.chain.cyclic`,
  :mod:`femmech.chain.continuum`): each root carries a wave / mode number; a branch is
  the pair (label, rank of the root within its label), fixed at the first angle.

Stage 6 (chain): imports analysis (the Sweep result and its tracking pieces).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from femmech.analysis.sweep import Sweep
from femmech.analysis.tracking import assign_branches, clusters, cuts_cluster
from femmech.chain import transfer
from femmech.chain.results import ChainModes
from femmech.chain.transfer import assembled_modes, transfer_modes

METHODS = ("transfer", "assembled", "cyclic", "continuum")
"""Methods :func:`chain_sweep` knows."""

REPEATED_RTOL = transfer.REPEATED_RTOL
"""Frequencies within this relative spread are one repeated root (its basis is aligned
to the branches' previous vectors); the same spread as the transfer solver's
(:data:`femmech.chain.transfer.REPEATED_RTOL`), whose roots are accurate to ~1e-12."""


def chain_sweep(chain, phi, n_modes: int, method: str = "transfer",
                frequency_weight: float = 0.1, keep_vectors: bool = False) -> Sweep:
    """Tracked quasi-eigenfrequencies of the frozen chain at the drive angles ``phi``.

    Parameters
    ----------
    chain : Chain
    phi : array_like (n_angles,)
        Drive angles, rad, in sweep order (e.g. ``np.linspace(0, 2π, 181)``).
    n_modes : int
        The n lowest roots at *every* angle, in n columns: a branch keeps its column
        while it is among the n lowest; when one leaves and another (from above) enters,
        the column passes to the entering branch and ``mac_step`` is 0 there. Tracking
        follows more branches than n (MAC: the sweep is repeated with twice as many
        where a root below the n-th lowest was not among them), so no root among the n
        lowest is missed at any angle.
    method : str
        One of :data:`METHODS`.
    frequency_weight : float
        Weight of the relative frequency jump against ``1 − MAC`` (MAC tracking).
    keep_vectors : bool
        Store the mode shapes (n_angles, n, n_modes) (methods with vectors).

    Returns
    -------
    Sweep
        ``form="symmetric"``; ``freq_hz`` = Re √λ / 2π (0 and damping ratio −1 for a
        root λ < 0: divergence); ``mac_step``: MAC (subspace MAC in clusters) of each
        branch with itself at the previous angle (0 where the column passes to another
        branch) (label tracking: the MAC of the same
        label's vectors if the method has vectors, else 1); NaN where a label-tracked
        branch is absent at an angle.
    """
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    if phi.ndim != 1 or phi.size == 0:
        raise ValueError(f"phi must be a non-empty 1-D array of angles, got shape {phi.shape}")
    if int(n_modes) != n_modes or not 1 <= n_modes <= chain.n:
        raise ValueError(f"n_modes must be an integer in 1..{chain.n}, got {n_modes!r}")
    n_modes = int(n_modes)
    if method in ("transfer", "assembled"):
        return _mac_sweep(chain, phi, n_modes, method, frequency_weight, keep_vectors)
    if method in ("cyclic", "continuum"):
        return _label_sweep(chain, phi, n_modes, method, keep_vectors)
    raise ValueError(f"unknown method {method!r}; known: {', '.join(METHODS)}")


def compare_methods(chain, phi, n_modes: int,
                    methods=("assembled", "transfer", "continuum"), **options) -> dict:
    """:func:`chain_sweep` by several methods on the same angles: ``{method: Sweep}``.

    ``options`` go to every :func:`chain_sweep` (``frequency_weight``, ``keep_vectors``).
    """
    return {m: chain_sweep(chain, phi, n_modes, m, **options) for m in methods}


def _modes(chain, phi, count, method, vectors=True) -> ChainModes:
    """The ``count`` lowest roots at one angle by ``method``."""
    if method == "transfer":
        return transfer_modes(chain, phi, n_modes=count, vectors=vectors)
    if method == "assembled":
        return assembled_modes(chain, phi, n_modes=count)
    if method == "cyclic":
        from femmech.chain.cyclic import cyclic_modes

        return cyclic_modes(chain, phi, vectors=vectors)
    from femmech.chain.continuum import continuum_modes

    return continuum_modes(chain, phi, count, vectors=vectors, estimate=False, warn=False)


def _lambda_columns(freq_hz):
    """(λ, frequency Re √λ / 2π, damping ratio) from signed frequencies (ChainModes)."""
    f = np.asarray(freq_hz, dtype=float)
    lam = np.sign(f) * (2 * np.pi * f) ** 2
    return lam.astype(complex), np.maximum(f, 0.0), np.where(f < 0, -1.0, 0.0)


def _mac_sweep(chain, phi, n_modes, method, weight, keep_vectors) -> Sweep:
    """MAC-tracked sweep of every branch that is among the ``n_modes`` lowest at some
    angle: more branches are tracked than asked for, and the sweep is repeated with
    twice as many wherever a root among the n lowest was not one of them."""
    tracked = min(n_modes + max(2, n_modes // 2), chain.n)
    while True:
        out = _track(chain, phi, n_modes, tracked, method, weight, keep_vectors)
        if out is not None or tracked == chain.n:
            break
        tracked = min(2 * tracked, chain.n)
    return _lowest_columns(phi, *out, n_modes)


def _lowest_columns(phi, lam, freq, ratio, mac_step, vectors, low, n_modes) -> Sweep:
    """The Sweep of the ``n_modes`` lowest roots at every angle from tracked branches
    (n_angles, b) with ``low`` True where a branch is among the n lowest: a branch keeps
    its column while it stays among them; a column whose branch leaves passes to a branch
    that enters (lowest first), with ``mac_step`` 0 at that angle."""
    n_angles = phi.size
    cols = np.full((n_angles, n_modes), -1)
    order = np.argsort(np.where(low[0], np.nan_to_num(freq[0], nan=np.inf), np.inf),
                       kind="stable")
    cols[0] = order[:n_modes]
    switched = np.zeros((n_angles, n_modes), bool)
    for a in range(1, n_angles):
        here = np.flatnonzero(low[a])
        here = here[np.argsort(np.nan_to_num(freq[a, here], nan=np.inf), kind="stable")]
        here = here[:n_modes]
        stay = np.isin(cols[a - 1], here)
        cols[a] = np.where(stay, cols[a - 1], -1)
        entering = [b for b in here if b not in cols[a]]
        free = np.flatnonzero(cols[a] < 0)
        for c, b in zip(free, entering, strict=False):
            cols[a, c] = b
            switched[a, c] = True
        cols[a, cols[a] < 0] = cols[a - 1, cols[a] < 0]  # (fewer than n roots: keep)
    rows = np.arange(n_angles)[:, None]
    macs = np.where(switched, 0.0, mac_step[rows, cols])
    vec = None if vectors is None else np.take_along_axis(vectors, cols[:, None, :], axis=2)
    return Sweep(phi, freq[rows, cols], lam[rows, cols], ratio[rows, cols], vec, macs,
                 "symmetric")


def _track(chain, phi, n_modes, tracked, method, weight, keep_vectors):
    """Follow ``tracked`` branches (the lowest at the first angle) over ``phi``.

    Returns ``(lam, freq, ratio, mac_step, vectors, low)`` (n_angles, tracked) arrays
    (vectors (n_angles, n, tracked) or None) with ``low`` True where the branch is among
    the ``n_modes`` lowest roots at that angle; None if at some angle a root below the
    n-th lowest is not on a tracked branch (more branches must be tracked)."""
    n_angles, n = phi.size, chain.n
    lam = np.zeros((n_angles, tracked), dtype=complex)
    freq, ratio = np.zeros((n_angles, tracked)), np.zeros((n_angles, tracked))
    mac_step = np.ones((n_angles, tracked))
    low = np.zeros((n_angles, tracked), bool)
    vectors = np.zeros((n_angles, n, tracked)) if keep_vectors else None
    extra = min(tracked + max(2, tracked // 2), n)
    previous = None
    for a, angle in enumerate(phi):
        modes = _modes(chain, angle, extra, method)
        f = modes.freq_hz
        groups = clusters(f)
        while f.size == extra < n and cuts_cluster(groups, f.size, tracked):
            extra = min(2 * extra, n)  # complete the cluster (kept for later angles)
            modes = _modes(chain, angle, extra, method)
            f = modes.freq_hz
            groups = clusters(f)
        M = chain.sparse_matrices(angle)[0]
        V = _canonical_repeated(modes.vectors, f, M)  # solver-independent before assigning
        if previous is None:
            pick, macs = np.arange(tracked), np.ones(tracked)
        else:
            pick, macs = assign_branches(previous, V, f, groups, M, weight)
            V = _align_repeated(V, f, pick, previous[0], M)
        top = f[min(n_modes, f.size) - 1]
        tol = REPEATED_RTOL * max(abs(top), 1e-300)
        below = np.flatnonzero(f < top - tol)
        if not np.isin(below, pick).all():
            return None  # a branch from above the tracked ones entered the n lowest
        low[a] = f[pick] <= top + tol
        lam[a], freq[a], ratio[a] = _lambda_columns(f[pick])
        mac_step[a] = macs
        previous = (V[:, pick], f[pick])
        if keep_vectors:
            vectors[a] = previous[0]
    return lam, freq, ratio, mac_step, vectors, low


def _align_repeated(V, f, pick, V_prev, M) -> np.ndarray:
    """Rotate the basis of every exactly repeated root (relative spread below
    :data:`REPEATED_RTOL`; e.g. followers of units in a dwell) onto the previous vectors
    of the branches assigned to it (orthogonal Procrustes in the M inner product), so a
    branch keeps its shape through the degeneracy instead of an arbitrary basis vector;
    distinct roots are left alone. Returns a copy of V (n, q)."""
    V = V.copy()
    for g in _exact_groups(f):
        branches = np.flatnonzero(np.isin(pick, g))
        if g.size < 2 or branches.size == 0:
            continue
        A = V[:, g].T @ (M @ V_prev[:, branches])  # (|g|, |branches|)
        U, _, Wt = np.linalg.svd(A, full_matrices=False)
        aligned = V[:, g] @ (U @ Wt)  # M-orthonormal, closest to the previous vectors
        V[:, pick[branches]] = aligned
    return V


def _canonical_repeated(V, f, M) -> np.ndarray:
    """A basis of every exactly repeated root independent of the solver: the k rows
    where the basis is most independent (QR with column pivoting) are made diagonal,
    then M-orthonormalised symmetrically (Löwdin, the closest orthonormal basis). For
    decoupled followers this gives one follower per vector. Returns a copy of V."""
    V = V.copy()
    for g in _exact_groups(f):
        if g.size < 2:
            continue
        rows = np.sort(sla.qr(V[:, g].T, pivoting=True, mode="r")[1][:g.size])
        B = V[:, g] @ np.linalg.inv(V[rows][:, g])
        w, U = np.linalg.eigh(B.T @ (M @ B))
        V[:, g] = B @ (U / np.sqrt(w)) @ U.T
    return V


def _exact_groups(f):
    f = np.asarray(f, dtype=float)
    size = np.maximum(np.abs(f[1:]), 1e-300)
    cuts = np.flatnonzero(np.abs(np.diff(f)) > REPEATED_RTOL * size) + 1
    return np.split(np.arange(f.size), cuts)


def _label_sweep(chain, phi, n_modes, method, keep_vectors) -> Sweep:
    n_angles, n = phi.size, chain.n
    count = min(n, 2 * n_modes + 2 * chain.m)
    keys = []  # every (label, rank) among the n lowest at some angle, first seen first
    for angle in phi:
        for key in _keys(_modes(chain, angle, count, method, vectors=False).label)[:n_modes]:
            if key not in keys:
                keys.append(key)
    n_branches = len(keys)
    low = np.zeros((n_angles, n_branches), bool)
    lam = np.full((n_angles, n_branches), np.nan, dtype=complex)
    freq = np.full((n_angles, n_branches), np.nan)
    ratio = np.zeros((n_angles, n_branches))
    mac_step = np.ones((n_angles, n_branches))
    vectors = np.full((n_angles, n, n_branches), np.nan) if keep_vectors else None
    previous = None
    for a, angle in enumerate(phi):
        modes = _modes(chain, angle, count, method, vectors=True)
        found = _keys(modes.label)
        where = {key: i for i, key in enumerate(found)}
        idx = np.array([where.get(key, -1) for key in keys])
        ok = idx >= 0
        lowest = set(found[:n_modes])
        low[a] = [key in lowest for key in keys]
        lam[a, ok], freq[a, ok], ratio[a, ok] = _lambda_columns(modes.freq_hz[idx[ok]])
        V = None if modes.vectors is None else np.full((n, n_branches), np.nan)
        if V is not None:
            V[:, ok] = modes.vectors[:, idx[ok]]
            if previous is not None:
                mac_step[a] = _same_mac(previous, V, chain.sparse_matrices(angle)[0])
            previous = V
            if keep_vectors:
                vectors[a] = V
    return _lowest_columns(phi, lam, freq, ratio, mac_step, vectors, low, n_modes)


def _keys(label) -> list[tuple[int, int]]:
    """(label, rank within the label) of each root (roots ascending)."""
    if label is None:
        raise ValueError("label tracking needs ChainModes.label (cyclic, continuum)")
    seen: dict[int, int] = {}
    out = []
    for j in np.asarray(label).tolist():
        out.append((j, seen.get(j, 0)))
        seen[j] = seen.get(j, 0) + 1
    return out


def _same_mac(X, Y, M) -> np.ndarray:
    """Column-wise MAC of X and Y (n, k) with weight M; NaN where a column is NaN."""
    MX, MY = M @ np.nan_to_num(X), M @ np.nan_to_num(Y)
    num = np.einsum("ij,ij->j", X, MY) ** 2
    return num / (np.einsum("ij,ij->j", X, MX) * np.einsum("ij,ij->j", Y, MY))
