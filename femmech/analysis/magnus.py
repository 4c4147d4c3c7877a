"""Monodromy matrices by a fourth-order Magnus integrator with step-doubling error control.

Integrates the fundamental matrix of ``z' = A(t) z``, ``A(t) = [[0, I], [-M⁻¹C, -M⁻¹B]]``,
over one period T for any coefficients ``t -> (M, B, C)`` (:func:`integrate_monodromy`,
:class:`Monodromy`), with batched step exponentials (:func:`expm_stack`); the Floquet
analysis built on it is :mod:`femmech.analysis.floquet`.

Integrator: the fourth-order Magnus method with two Gauss points (Iserles & Nørsett,
Phil. Trans. R. Soc. A 357 (1999) 983; Blanes, Casas, Oteo & Ros, Phys. Rep. 470 (2009)
151, sect. 5): per step h, with A₁, A₂ evaluated at t + (1/2 ∓ √3/6) h,

    Ω_k = h/2 (A₁ + A₂) + (√3/12) h² [A₂, A₁],     Φ(t + h) = exp(Ω_k) Φ(t).

Why this scheme rather than explicit RK4 or an adaptive solver:

* it is exact for constant coefficients, so the stiff constant frame part (FE modes far
  above the drive frequency) neither limits the step (explicit RK4 needs h < 2.8/ω_max)
  nor is damped or amplified numerically; the step only has to resolve the variation of
  the mechanism coefficients over the cycle;
* it stays in the Lie group of the problem: det exp(Ω_k) = exp(tr Ω_k), so Liouville's
  formula det Φ(T) = exp ∫ tr A dt holds to quadrature accuracy, and for an undamped
  1-DOF Hill equation (A in sl(2) = sp(2)) every step is exactly area preserving, so
  the multipliers of a stable Mathieu equation stay on the unit circle and the verdict
  |tr Φ| ≶ 2 is not polluted by numerical damping or growth;
* the step exponentials are independent: they are computed for a whole chunk of steps
  at once (:func:`expm_stack`, batched scaling and squaring) and multiplied in a
  balanced tree, so the per-step Python cost is nil.

Error control: the step count doubles until the spectral radius settles
(:func:`integrate_monodromy`, :class:`Monodromy`). At high speed a few dozen steps per
period resolve the mechanism's variation over the cycle; at low speed the period is long
against the frame's vibration periods, the step exponentials no longer commute well
enough, and thousands of steps are needed. Fixed step counts were silently wrong there
(the press example at 10 rpm: NaN at 128 steps, 0.00029 at 256 where the converged
spectral radius is 0.00525). Steps start on the breakpoints of piecewise motion laws
(cam joints, where the jerk jumps; :func:`femmech.coupling.drive_breakpoints`), so no
quadrature straddles a jump of the coefficients.

Global error O(h⁴) (tests/test_stability.py measures the order).

Stage 5 (analysis): of femmech uses only analysis.response (the step-control check);
nothing here knows machines or writes files.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from femmech.analysis.response import check_step_control

GAUSS_OFFSETS = np.array([0.5 - np.sqrt(3.0) / 6.0, 0.5 + np.sqrt(3.0) / 6.0])
"""Two-point Gauss-Legendre nodes on [0, 1]."""

_CHUNK_BYTES = 2**25
"""Memory per stacked array of one chunk of steps (32 MiB)."""

RTOL = 1e-4
"""Default tolerance on the spectral radius of a monodromy matrix (relative). The
estimate is conservative: on the press example (10 to 3000 rpm) the true error was 1/8
to 1/70 of it (docs/robustness.md)."""

MAX_STEPS = 2**14
"""Default cap on the Magnus steps per period of the step-doubling loop (the press
example needs 8 192 at 10 rpm, 128 above 1 000 rpm)."""


@dataclass(frozen=True)
class Monodromy:
    """Monodromy matrix Φ(T) with the record of its step-doubling check.

    Attributes
    ----------
    matrix : ndarray (2n, 2n)
        Φ(T) from the finest step count tried.
    n_steps : int
        Magnus steps per period of ``matrix``.
    spectral_radius : float
        max |μ| of ``matrix`` (NaN when the integration overflowed).
    error : float
        Estimated absolute error of ``spectral_radius``: the change from the previous
        (half as many steps) solution, |ρ_N − ρ_{N/2}|; for a fourth-order scheme in its
        asymptotic range the true error is about 1/15 of it. ``inf`` when fewer than two
        finite solutions exist, NaN without a check (``rtol=None``).
    converged : bool or None
        The spectral radius met ``error <= rtol · ρ + ATOL`` at two successive doublings,
        or at one doubling that also cut the change at least fourfold; ``None`` when no
        check was asked for (``rtol=None``, fixed steps).
    rtol : float or None
        Tolerance asked for.
    """

    matrix: np.ndarray
    n_steps: int
    spectral_radius: float
    error: float
    converged: bool | None
    rtol: float | None


ATOL = 1e-14
"""Absolute floor of the spectral-radius tolerance: radii of strongly damped slow motions
(1e-20 at 1 rpm) are reported to within it, which decides the verdict all the same."""


def step_grid(counts, edges) -> tuple[np.ndarray, np.ndarray]:
    """Step starts and lengths (N,), s, with ``counts[i]`` equal steps on [edges[i], edges[i+1]].

    ``edges`` (m + 1,) are 0, the breakpoints in (0, T) and T: every breakpoint is a step
    boundary, so the quadrature of a step never straddles a jump of the coefficients.
    """
    counts = np.asarray(counts, dtype=int)
    lengths = np.diff(edges) / counts
    h = np.repeat(lengths, counts)
    local = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    return np.repeat(edges[:-1], counts) + local * h, h


def _segment_edges(period: float, breakpoints) -> np.ndarray:
    """0, the breakpoints (s, taken modulo T, near-duplicates merged) and T."""
    b = np.unique(np.mod(np.asarray(breakpoints, dtype=float).ravel(), period))
    b = b[(b > 1e-9 * period) & (b < (1 - 1e-9) * period)]
    if b.size > 1:
        b = b[np.r_[True, np.diff(b) > 1e-9 * period]]
    return np.r_[0.0, b, period]


def _initial_counts(edges: np.ndarray, n_steps: int) -> np.ndarray:
    """Steps per segment: about ``n_steps`` in all, proportional to length, at least one."""
    period = edges[-1]
    return np.maximum(1, np.round(n_steps * np.diff(edges) / period)).astype(int)


def _magnus_monodromy(coefficients, starts: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Magnus-4 product over steps (starts, h); ``coefficients(t) -> (M, B, C)`` stacks."""
    n = coefficients(np.zeros(1))[0].shape[-1]
    chunk = max(1, _CHUNK_BYTES // (8 * 2 * (2 * n) ** 2))  # A at two nodes per step
    Phi = np.eye(2 * n)
    for first in range(0, starts.size, chunk):
        t0, hk = starts[first:first + chunk], h[first:first + chunk]
        t = (t0[:, None] + GAUSS_OFFSETS[None, :] * hk[:, None]).ravel()
        with np.errstate(over="ignore", invalid="ignore"):
            A = first_order_matrices(*coefficients(t))
            A1, A2 = A[0::2], A[1::2]
            hk = hk[:, None, None]
            Omega = 0.5 * hk * (A1 + A2) + (np.sqrt(3.0) / 12.0) * hk**2 * (A2 @ A1 - A1 @ A2)
            if not np.isfinite(Omega).all():
                return np.full_like(Phi, np.nan)
            Phi = _tree_product(expm_stack(Omega)) @ Phi
        if not np.isfinite(Phi).all():
            return np.full_like(Phi, np.nan)
    return Phi


def _spectral_radius(Phi: np.ndarray) -> float:
    return float(np.abs(sla.eigvals(Phi)).max()) if np.isfinite(Phi).all() else np.nan


def _accepted(radii: list[float], rtol: float) -> bool:
    """Step-doubling acceptance of the last spectral radius (see :class:`Monodromy`)."""
    if len(radii) < 3 or not np.isfinite(radii[-3:]).all():
        return False
    d_prev, d_last = abs(radii[-2] - radii[-3]), abs(radii[-1] - radii[-2])
    ok_last = d_last <= rtol * radii[-1] + ATOL
    ok_prev = d_prev <= rtol * radii[-2] + ATOL
    return ok_last and (ok_prev or d_last <= 0.25 * d_prev)


def integrate_monodromy(coefficients, period: float, n_steps: int = 32,
                        rtol: float | None = RTOL, max_steps: int = MAX_STEPS,
                        breakpoints=()) -> Monodromy:
    """Magnus-4 monodromy with step doubling until the spectral radius meets ``rtol``.

    ``coefficients(t) -> (M, B, C)`` stacks at times t (k,); steps start at about
    ``n_steps`` per period (at least one per segment between ``breakpoints``, times in s
    where the coefficients jump) and double while the spectral radius changes by more
    than ``rtol`` (relative; see :class:`Monodromy`) and the count stays within
    ``max_steps``. ``rtol=None`` integrates with the initial steps only, unchecked.
    """
    if not (np.isfinite(period) and period > 0):
        raise ValueError(f"period must be positive and finite, got {period}")
    n_steps = check_step_control(n_steps, rtol, max_steps)
    edges = _segment_edges(period, breakpoints)
    counts = _initial_counts(edges, n_steps)
    radii: list[float] = []
    while True:
        Phi = _magnus_monodromy(coefficients, *step_grid(counts, edges))
        radii.append(_spectral_radius(Phi))
        n = int(counts.sum())
        if rtol is None:
            return Monodromy(Phi, n, radii[-1], np.nan, None, None)
        done = _accepted(radii, rtol)
        if done or 2 * n > max_steps:
            error = abs(radii[-1] - radii[-2]) if len(radii) > 1 else np.inf
            return Monodromy(Phi, n, radii[-1], error if np.isfinite(error) else np.inf,
                             done, float(rtol))
        counts = 2 * counts


def first_order_matrices(M, B, C) -> np.ndarray:
    """``A = [[0, I], [-M⁻¹C, -M⁻¹B]]`` for stacks M, B, C (k, n, n) → (k, 2n, 2n)."""
    k, n = M.shape[0], M.shape[-1]
    X = np.linalg.solve(M, np.concatenate([C, B], axis=-1))
    A = np.zeros((k, 2 * n, 2 * n))
    A[:, :n, n:] = np.eye(n)
    A[:, n:, :] = -X
    return A


_PADE13 = np.array([64764752532480000.0, 32382376266240000.0, 7771770303897600.0,
                    1187353796428800.0, 129060195264000.0, 10559470521600.0, 670442572800.0,
                    33522128640.0, 1323241920.0, 40840800.0, 960960.0, 16380.0, 182.0, 1.0])
_THETA13 = 5.371920351148152


def expm_stack(A: np.ndarray) -> np.ndarray:
    """Matrix exponentials of a stack (k, m, m), batched over k.

    Scaling and squaring with the [13/13] Padé approximant (Higham, SIAM J. Matrix Anal.
    Appl. 26 (2005) 1179, algorithm 2.3): each A_i is scaled by 2^-s_i so that
    ‖A_i‖₁ ≤ θ₁₃ (backward error below the unit round-off), the approximant costs six
    products and one solve, done for the whole stack at once, then s_i squarings.
    ``scipy.linalg.expm`` loops over a stack matrix by matrix, 5 to 6 times slower for
    the 50- and 148-wide step exponentials of the example machines
    (tests/test_dynamics_convergence.py compares the results).
    """
    k, m, _ = A.shape
    norm = np.abs(A).sum(axis=1).max(axis=1)
    with np.errstate(divide="ignore"):
        s = np.maximum(0, np.ceil(np.log2(norm / _THETA13)))
    s = np.where(np.isfinite(s), s, 0).astype(int)
    A = A / (2.0 ** s)[:, None, None]
    b, eye = _PADE13, np.eye(m)
    A2 = A @ A
    A4 = A2 @ A2
    A6 = A4 @ A2
    U = A @ (A6 @ (b[13] * A6 + b[11] * A4 + b[9] * A2) + b[7] * A6 + b[5] * A4
             + b[3] * A2 + b[1] * eye)
    V = A6 @ (b[12] * A6 + b[10] * A4 + b[8] * A2) + b[6] * A6 + b[4] * A4 + b[2] * A2 \
        + b[0] * eye
    E = np.linalg.solve(V - U, V + U)
    for j in range(int(s.max(initial=0))):
        more = s > j
        E[more] = E[more] @ E[more]
    return E


def _tree_product(E: np.ndarray) -> np.ndarray:
    """``E[-1] @ ... @ E[1] @ E[0]`` for a stack (k, m, m), by pairwise products."""
    while E.shape[0] > 1:
        if E.shape[0] % 2:
            E = np.concatenate([E, np.eye(E.shape[1])[None]])
        E = E[1::2] @ E[0::2]
    return E[0]
