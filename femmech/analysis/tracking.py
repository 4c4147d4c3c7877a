"""Mode tracking: which eigenpair at the next angle (or parameter value) continues each
branch, by the modal assurance criterion (MAC) and frequency continuity, solved as an
assignment problem; clusters of close frequencies are compared as subspaces.

Shared by the angle sweeps (:mod:`femmech.analysis.sweep`) and the chain sweeps
(:mod:`femmech.chain.sweep`); :func:`track_batch` tracks a batch of angles at once.

Stage 5 (analysis): numpy and scipy only.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

CLUSTER_RTOL = 1e-3
"""Frequencies closer than this (relative, chained) form a cluster for tracking: a branch
is compared with the span of a cluster (subspace MAC), not with its arbitrary basis."""


def mac_matrix(X, Y, W=None) -> np.ndarray:
    """MAC_ij = |x_iᴴ W y_j|² / ((x_iᴴ W x_i)(y_jᴴ W y_j)); X (n, p), Y (n, q) → (p, q)."""
    WY = Y if W is None else W @ Y
    WX = X if W is None else W @ X
    num = np.abs(X.conj().T @ WY) ** 2
    nx = np.real(np.einsum("ij,ij->j", X.conj(), WX))
    ny = np.real(np.einsum("ij,ij->j", Y.conj(), WY))
    return num / np.outer(nx, ny)


def track_batch(M, X, f, split, previous, values, n_modes, weight, out):
    """Assign the candidates of a batch of angles to the branches (:func:`_assign`).

    ``M`` (k, n, n), ``X`` (k, n, q) candidates, ``f`` (k, q) their frequencies (Hz,
    ascending), ``split`` (k, q - 1) the gaps between clusters (:func:`splits`),
    ``previous`` the branches at the angle before the batch (``(V (n, p), f (p,))`` or
    None), ``values = (first angle, λ (k, q), damping ratio (k, q))``. The terms of the
    assignment at angles 1..k-1 are formed for the batch at once (:func:`_pair_terms`),
    assuming that the branches occupy the same candidates (as a set) as at angle 0;
    per angle remain the Hungarian assignment and, where the assumption fails, the
    products of that pair (:func:`_assign`, as in :func:`_sweep_loop`). Returns
    ``previous`` for the next batch.
    """
    a0, lam, r = values
    k = len(f)
    MX = M @ X
    G = X.transpose(0, 2, 1) @ MX  # (k, q, q): candidates of each angle
    picks, macs = np.empty((k, n_modes), dtype=int), np.ones((k, n_modes))
    if previous is None:
        picks[0] = np.arange(n_modes)
    else:
        Vp, fp = previous
        Gp = Vp.T @ (M[0] @ Vp)
        picks[0], macs[0] = _assign(Vp.T @ MX[0], Gp.diagonal(), G[0].diagonal(), Gp, G[0],
                                    fp, f[0], _groups(split[0]) or None,
                                    _multi(clusters(fp)), weight)
    if k > 1:
        rows = np.sort(picks[0])
        sub, cost = _pair_terms(M, X, MX, G, f, split, rows, weight)
        best, best_sub, greedy = _row_minima(sub, cost)
        at = np.full(f.shape[1], -1)
        at[rows] = np.arange(rows.size)  # position of a candidate among ``rows``
        assumed = rows.tolist()
        for i in range(1, k):
            prev = picks[i - 1]
            if sorted(prev.tolist()) == assumed and greedy[i - 1]:
                picks[i], macs[i] = best[i - 1][at[prev]], best_sub[i - 1][at[prev]]
            elif sorted(prev.tolist()) == assumed:  # as formed for the batch
                picked, chosen = linear_sum_assignment(cost[i - 1][at[prev]])
                picks[i], macs[i] = chosen, sub[i - 1][at[prev]][picked, chosen]
            else:  # a branch moved to another candidate: this pair as in _sweep_loop
                Vp = X[i - 1][:, prev]
                Gp = Vp.T @ (M[i] @ Vp)
                picks[i], macs[i] = _assign(Vp.T @ MX[i], Gp.diagonal(), G[i].diagonal(), Gp,
                                            G[i], f[i - 1, prev], f[i], _groups(split[i]) or None,
                                            _multi(clusters(f[i - 1, prev])), weight)
    at = slice(a0, a0 + k)
    for name, A in (("lam", lam), ("freq", f), ("ratio", r)):
        out[name][at] = np.take_along_axis(A, picks, axis=1)
    out["mac"][at] = macs
    if out["vectors"] is not None:
        out["vectors"][at] = np.take_along_axis(X, picks[:, None, :], axis=2)
    return X[-1][:, picks[-1]], f[-1, picks[-1]]


def _row_minima(sub, cost):
    """Where the assignment is decided row by row: ``(best, best_sub, greedy)`` with
    ``best`` (k, p) each row's cheapest column of ``cost`` (k, p, q), ``best_sub`` the
    subspace MAC there, and ``greedy`` (k,) True where every row's minimum is strict and
    the rows' minima lie in distinct columns: that assignment is then the unique optimum,
    the one ``linear_sum_assignment`` returns."""
    best = cost.argmin(axis=2)
    two = np.partition(cost, 1, axis=2)[:, :, :2]
    distinct = (np.diff(np.sort(best, axis=1), axis=1) != 0).all(axis=1)
    greedy = (two[:, :, 0] < two[:, :, 1]).all(axis=1) & distinct
    return best, np.take_along_axis(sub, best[:, :, None], axis=2)[:, :, 0], greedy


def _pair_terms(M, X, MX, G, f, split, rows, weight):
    """Subspace MAC and cost of :func:`_assign` for the k - 1 consecutive pairs of angles
    of a batch, (k - 1, p, q) each, with the candidates ``rows`` (p, sorted) of the first
    angle of each pair as the previous branches (in that order) and all candidates of the
    second as the new ones. ``MX`` = M @ X and ``G`` = Xᵀ M X (k, q, q) of the batch."""
    Xp = X[:-1][:, :, rows]  # (k-1, n, p)
    S = Xp.transpose(0, 2, 1) @ MX[1:]
    P = Xp.transpose(0, 2, 1) @ (M[1:] @ Xp)
    n_prev, n_new = np.diagonal(P, axis1=1, axis2=2), np.diagonal(G[1:], axis1=1, axis2=2)
    mac = np.abs(S) ** 2 / (n_prev[:, :, None] * n_new[:, None, :])
    side = _batch_span_mac(S, n_prev, G[1:], splits(f[1:]), mac)  # the new clusters
    back = _batch_span_mac(S.transpose(0, 2, 1), n_new, P, splits(f[:-1, rows]),
                           mac.transpose(0, 2, 1))  # the previous branches' clusters
    sub = np.maximum(side, back.transpose(0, 2, 1))
    jump = weight * (np.abs(f[1:, None, :] - f[:-1, rows, None])
                     / np.maximum(f[:-1, rows], 1e-12)[:, :, None])
    return sub, 1.0 - sub + jump + 0.1 * (sub - mac)


def _batch_span_mac(S, nx, G, split, mac):
    """:func:`_span_mac` of many angles at once (k, p, q): the clusters of Y are runs of
    ascending frequencies (``split`` (k, q - 1), :func:`splits`); the Gram blocks of all
    clusters of one size are decomposed in one batched ``eigh``."""
    out = mac.copy()
    k, q = split.shape[0], split.shape[1] + 1
    bounds = np.ones((k, q + 1), dtype=bool)  # cluster starts, and the end of each row
    bounds[:, 1:q] = split
    where = np.flatnonzero(bounds)
    row, col = np.divmod(where, q + 1)
    sizes = np.diff(col)
    run = (row[:-1] == row[1:]) & (sizes > 1)  # clusters of more than one member
    all_rows = np.arange(S.shape[1])[None, :, None]
    for size in np.unique(sizes[run]):
        chosen = run & (sizes == size)
        j, s = row[:-1][chosen], col[:-1][chosen]
        idx = s[:, None] + np.arange(size)
        w, U = np.linalg.eigh(G[j[:, None, None], idx[:, :, None], idx[:, None, :]])
        w = np.where(w > 1e-12 * np.abs(w).max(axis=1, keepdims=True), w, np.inf)
        T = S[j[:, None, None], all_rows, idx[:, None, :]] @ U
        values = (np.abs(T) ** 2 / w[:, None, :]).sum(axis=2) / nx[j]
        out[j[:, None, None], all_rows, idx[:, None, :]] = values[:, :, None]
    return out


def _groups(split_row) -> list[np.ndarray]:
    """The clusters of more than one member of ascending frequencies whose gaps ``split_row``
    (q - 1,) flags (:func:`splits`); :func:`clusters` of them without the single ones."""
    bounds = [0, *(np.flatnonzero(split_row) + 1).tolist(), split_row.size + 1]
    return [np.arange(i, j) for i, j in zip(bounds[:-1], bounds[1:], strict=True) if j - i > 1]


def _multi(groups):
    """The groups of more than one member, or None if there are none."""
    multi = [g for g in groups if g.size > 1]
    return multi or None


def splits(f):
    """(k, q - 1) bool: the gap between ascending frequencies j and j + 1 (Hz, (k, q))
    separates two :func:`clusters` (same rule, all angles at once)."""
    size = np.maximum(f[:, 1:], 1e-3 * np.maximum(np.abs(f).max(axis=1, initial=0.0),
                                                   1e-300)[:, None])
    return f[:, 1:] - f[:, :-1] > CLUSTER_RTOL * size


def assign_branches(previous, V, f, groups, M, weight):
    """Columns of V continuing each previous branch (Hungarian assignment).

    ``previous = (V_prev (n, p), f_prev (p,))``, ``V`` (n, q) the new candidate vectors
    and ``f`` (q,) their frequencies (Hz), ``M`` the (n, n) weighting matrix, ``weight``
    the weight of the relative frequency jump. Returns ``(pick (p,), mac (p,))``: the
    candidate column continuing each branch and its (subspace) MAC.

    The similarity of a previous branch i and a candidate j is the larger of two
    subspace MACs: of branch i with the span of j's cluster, and of j with the span of
    i's cluster (clusters: :func:`clusters`); for isolated modes both are the MAC. A
    branch thus stays in its cluster although the cluster's vectors are an arbitrary
    basis, and a cluster that splits (or forms) is followed. Within a cluster the
    vector MAC breaks ties (``0.1 × (subspace MAC - MAC)``), so that close but distinct
    modes, e.g. at a crossing, keep their identity. ``groups``: the clusters of f. All
    M-products come from one Gram matrix of the previous and the new vectors.
    """
    V_prev, f_prev = previous
    p = V_prev.shape[1]
    Z = np.concatenate((V_prev, V), axis=1)
    G = Z.conj().T @ (M @ Z)  # (p + q, p + q)
    norms = G.diagonal().real
    return _assign(G[:p, p:], norms[:p], norms[p:], G[:p, :p], G[p:, p:], f_prev, f,
                   groups, clusters(f_prev), weight)


def _assign(S, n_prev, n_new, G_prev, G_new, f_prev, f, groups, groups_prev, weight):
    """:func:`assign_branches` from the M-products of the previous vectors (p) and the
    candidates (q): ``S`` (p, q), their norms ``n_prev`` (p,), ``n_new`` (q,) and Gram
    matrices ``G_prev`` (p, p), ``G_new`` (q, q); ``groups``, ``groups_prev``: the
    :func:`clusters` of ``f`` and ``f_prev``, or None where all are single (then both
    subspace MACs are the plain MAC and need not be formed). Returns ``(pick, mac)``."""
    mac = np.abs(S) ** 2 / (n_prev[:, None] * n_new)
    if groups is None and groups_prev is None:
        sub = mac
    else:
        sub = np.maximum(_span_mac(S, n_prev, G_new, groups or (), mac),
                         _span_mac(S.conj().T, n_new, G_prev, groups_prev or (), mac.T).T)
    jump = np.abs(f - f_prev[:, None]) / np.maximum(f_prev, 1e-12)[:, None]
    rows, pick = linear_sum_assignment(1.0 - sub + weight * jump + 0.1 * (sub - mac))
    return pick, sub[rows, pick]  # rows = 0..p-1 (p <= q: every branch is assigned)


def cuts_cluster(groups, n_candidates: int, n_modes: int) -> bool:
    """True if the last computed frequency is in the cluster of the n-th lowest: the
    candidates then hold only part of a cluster, whose span tracking needs whole.
    ``groups``: :func:`clusters` of the candidates (ascending, so the last group holds
    the highest)."""
    return n_candidates - groups[-1].size < n_modes


def clusters(freq_hz, rtol: float = CLUSTER_RTOL) -> list[np.ndarray]:
    """Groups of indices of close frequencies, in ascending order of frequency: sorted
    neighbours closer than ``rtol`` times the frequency (frequencies below 1e-3 of the
    largest count as that size, so rigid-body modes at round-off form one group)."""
    freq = np.asarray(freq_hz, dtype=float)
    order = np.argsort(freq, kind="stable")
    f = freq[order]
    size = np.maximum(f[1:], 1e-3 * max(float(np.abs(f).max(initial=0.0)), 1e-300))
    bounds = [0, *(np.flatnonzero(f[1:] - f[:-1] > rtol * size) + 1).tolist(), f.size]
    return [order[i:j] for i, j in zip(bounds[:-1], bounds[1:], strict=True)]


def subspace_mac(X, Y, groups, W=None) -> np.ndarray:
    """(p, q): for column j of Y, the MAC of each column of X with ``span(Y[:, g])``, g the
    group holding j: ``x̄ᵀ W Y_g (Y_gᴴ W Y_g)⁺ Y_gᴴ W x / (xᴴ W x)`` (1 if x lies in it).
    A group of one column gives the plain MAC."""
    WX = X if W is None else W @ X
    WY = Y if W is None else W @ Y
    S = X.conj().T @ WY
    nx = np.real(np.einsum("ij,ij->j", X.conj(), WX))
    G = Y.conj().T @ WY
    return _span_mac(S, nx, G, groups, np.abs(S) ** 2 / np.outer(nx, G.diagonal().real))


def _span_mac(S, nx, G, groups, mac) -> np.ndarray:
    """:func:`subspace_mac` from the products ``S = Xᴴ W Y`` (p, q), ``nx = diag(Xᴴ W X)``
    (p,) and ``G = Yᴴ W Y`` (q, q); ``mac`` (p, q), the plain MAC, serves groups of one."""
    out = mac.copy()
    for g in groups:
        if g.size > 1:  # P G_g⁺ Pᴴ with G_g = U diag(w) Uᴴ, w below 1e-12 max|w| dropped
            w, U = np.linalg.eigh(G[g[:, None], g])
            keep = w > 1e-12 * np.abs(w).max()
            T = S[:, g] @ U[:, keep]
            out[:, g] = ((np.abs(T) ** 2 / w[keep]).sum(axis=1) / nx)[:, None]
    return out
