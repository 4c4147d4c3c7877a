"""Floquet stability of linear periodic (rheolinear) systems.

A machine running at constant drive speed Ω vibrates about its kinematic motion as
``M(t) q'' + B(t) q' + C(t) q = F(t)`` (seed 5.2.2 eq. 9 with φ = Ω t), whose coefficients
repeat with the period T = Θ/Ω of the machine cycle (Θ = 2π for one revolution of the
main drive). Written in first-order form ``z' = A(t) z``, ``z = [q; q']``,

    A(t) = [[0, I], [-M⁻¹C, -M⁻¹B]],

the free motion over one period is ``z(T) = Φ(T) z(0)`` with the monodromy matrix Φ(T)
(the fundamental matrix at T, Φ(0) = I). Its eigenvalues, the Floquet multipliers μ,
decide stability: the free vibrations decay when all |μ| < 1 and grow (parametric
resonance) when one |μ| > 1 (Floquet's theorem; Nayfeh & Mook, Nonlinear Oscillations,
Wiley 1979, sect. 5.2). The characteristic exponents are ``λ = ln μ / T``.

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
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from femmech.analysis.response import (
    check_step_control,
    rayleigh_coefficients,
    rayleigh_damping,
)
from femmech.analysis.sweep import sweep
from femmech.coupling import (
    CoupledSystem,
    assemble_stack,
    drive_breakpoints,
    require_dense_primal,
)
from femmech.errors import ConvergenceWarning

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


@dataclass(frozen=True)
class Floquet:
    """Floquet multipliers of a linear periodic system.

    Attributes
    ----------
    multipliers : ndarray (2n,), complex
        Eigenvalues μ of the monodromy matrix, by descending modulus.
    spectral_radius : float
        max |μ|: the amplification of the worst free motion over one period.
    stable : bool
        ``spectral_radius <= 1 + tol``.
    exponents : ndarray (2n,), complex, 1/s
        Characteristic exponents ``ln μ / T`` (principal logarithm: imaginary parts are
        defined modulo 2π/T). Re λ is the mean growth rate of the solution.
    monodromy : ndarray (2n, 2n)
        Φ(T) for ``z = [q; q']``.
    period : float
        T, s.
    tol : float
        Tolerance of the stability verdict.
    error : float
        Estimated error of ``spectral_radius`` from the step-doubling check of the
        monodromy matrix (:class:`Monodromy`); NaN when Φ came without one.
    converged : bool or None
        Whether Φ met its tolerance; ``None`` when unchecked. An unconverged result is a
        number that may be wrong: do not use it without a finer integration.
    n_steps : int or None
        Magnus steps per period of Φ.
    """

    multipliers: np.ndarray
    spectral_radius: float
    stable: bool
    exponents: np.ndarray
    monodromy: np.ndarray
    period: float
    tol: float
    error: float = float("nan")
    converged: bool | None = None
    n_steps: int | None = None


@dataclass(frozen=True)
class StabilityChart:
    """Spectral radii of the monodromy matrix over drive speed and a second parameter.

    Attributes
    ----------
    speeds : ndarray (n_speeds,)
        Drive speeds Ω, rad/s (or the callable's own speed-like parameter).
    values : ndarray (n_values,) or None
        Second parameter values (``None``: a speed sweep only, n_values = 1).
    spectral_radius : ndarray (n_values, n_speeds)
    stable : ndarray (n_values, n_speeds) of bool
        ``spectral_radius <= 1 + tol``.
    tol : float
    parameter_name : str
        Label of the second parameter (with its unit).
    periods : ndarray (n_values, n_speeds) or None
        Period T of each point, s (Θ/Ω for coupled systems).
    error : ndarray (n_values, n_speeds) or None
        Estimated error of each spectral radius (:class:`Monodromy`).
    converged : ndarray (n_values, n_speeds) of bool, or None
        Whether each point met the tolerance ``rtol``; an unconverged point is drawn,
        tabulated and reported as such, never as a plain number.
    n_steps : ndarray (n_values, n_speeds) of int, or None
        Magnus steps per period used at each point.
    rtol : float or None
        Tolerance of the spectral radii (relative).
    """

    speeds: np.ndarray
    values: np.ndarray | None
    spectral_radius: np.ndarray
    stable: np.ndarray
    tol: float
    parameter_name: str = "parameter"
    periods: np.ndarray | None = None
    error: np.ndarray | None = None
    converged: np.ndarray | None = None
    n_steps: np.ndarray | None = None
    rtol: float | None = None

    def __repr__(self) -> str:
        n_unstable = int(np.sum(~np.asarray(self.stable) & ~self.unconverged))
        loose = int(np.sum(self.unconverged))
        grid = f"{len(self.speeds)} speeds" + (f" x {len(self.values)} {self.parameter_name}"
                                               if self.values is not None else "")
        flags = f", {loose} NOT CONVERGED" if loose else ""
        return (f"StabilityChart({grid}; max spectral radius"
                f" {np.nanmax(self.spectral_radius):.6g}, {n_unstable} unstable{flags})")

    @property
    def unconverged(self) -> np.ndarray:
        """Mask (n_values, n_speeds) of points that missed their tolerance."""
        if self.converged is None:
            return np.zeros(self.spectral_radius.shape, dtype=bool)
        return ~np.asarray(self.converged, dtype=bool)

    @property
    def growth_rate(self) -> np.ndarray:
        """Largest real part of the characteristic exponents, ln(max|μ|)/T, 1/s.

        Unlike the spectral radius, which falls towards 0 at low speed only because the
        period grows, it is the decay rate −ζω of the least damped free motion of a
        time-invariant system, so parametric resonances stand out as bumps towards and
        above 0 (unstable) at any speed.
        """
        if self.periods is None:
            raise ValueError("this chart has no periods; build it with stability_chart")
        return np.log(np.maximum(self.spectral_radius, 1e-300)) / self.periods


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


def _stack(name: str, coefficient, t: np.ndarray) -> np.ndarray:
    """Evaluate a coefficient (callable of times, or constant matrix) at times t (k,)."""
    if callable(coefficient):
        value = np.asarray(coefficient(t), dtype=float)
    else:
        value = np.asarray(coefficient, dtype=float)
        if value.ndim == 0:
            value = value.reshape(1, 1)
        value = np.broadcast_to(value, (t.size, *value.shape[-2:]))
    if value.ndim != 3 or value.shape[0] != t.size or value.shape[1] != value.shape[2]:
        raise ValueError(f"{name} must give a stack ({t.size}, n, n) for {t.size} times,"
                         f" got shape {value.shape}")
    return value


def monodromy(M_of_t, B_of_t, C_of_t, period: float, n_steps: int = 32,
              rtol: float | None = RTOL, max_steps: int = MAX_STEPS, breakpoints=(),
              full_output: bool = False):
    """Monodromy matrix of ``M(t) q'' + B(t) q' + C(t) q = 0`` with period T.

    Parameters
    ----------
    M_of_t, B_of_t, C_of_t : callable or array_like (n, n)
        ``f(t) -> ndarray (k, n, n)`` for an array of times t (k,), s (vectorised); or a
        constant matrix (a scalar for n = 1). Units: kg, N s/m, N/m (any consistent set).
        M(t) must be invertible.
    period : float
        T, s: the coefficients satisfy f(t + T) = f(t).
    n_steps : int
        Initial Magnus-4 steps per period (2 coefficient evaluations each); the count
        doubles until the spectral radius meets ``rtol`` (the error falls as n_steps⁻⁴
        once the steps resolve the coefficients' variation).
    rtol : float or None
        Relative tolerance of the spectral radius (:class:`Monodromy` states the test);
        ``None`` integrates with exactly ``n_steps`` steps and no check.
    max_steps : int
        Largest step count tried; a result that misses ``rtol`` there is returned with a
        :class:`ConvergenceWarning` (and ``converged=False`` in the full output).
    breakpoints : array_like, optional
        Times in [0, T), s, where the coefficients jump (cam joints): step boundaries.
    full_output : bool
        Return the :class:`Monodromy` record instead of the bare matrix.

    Returns
    -------
    ndarray (2n, 2n) or Monodromy
        Φ(T) with ``[q; q'](T) = Φ(T) [q; q'](0)``.

    Examples
    --------
    Undamped oscillator ω = 2 rad/s over T = π/2 (a quarter of its period π): Φ rotates
    by ωT = π, so Φ = -I.

    >>> import numpy as np
    >>> Phi = monodromy(1.0, 0.0, 4.0, np.pi / 2, n_steps=8)
    >>> bool(np.allclose(Phi, -np.eye(2)))
    True
    """
    result = _record(M_of_t, B_of_t, C_of_t, period, n_steps, rtol, max_steps, breakpoints)
    _warn_unconverged(result, f"period {float(period):.6g} s")
    return result if full_output else result.matrix


def _record(M_of_t, B_of_t, C_of_t, period, n_steps, rtol, max_steps, breakpoints=()):
    """:class:`Monodromy` of :func:`monodromy`, without the warning."""
    def coefficients(t):
        return tuple(_stack(name, f, t) for name, f in
                     (("M_of_t", M_of_t), ("B_of_t", B_of_t), ("C_of_t", C_of_t)))

    shapes = {f.shape[1] for f in coefficients(np.zeros(1))}
    if len(shapes) != 1:
        raise ValueError(f"M_of_t, B_of_t and C_of_t disagree in size: {sorted(shapes)}")
    return integrate_monodromy(coefficients, float(period), n_steps, rtol, max_steps,
                               breakpoints)


def _warn_unconverged(result: Monodromy, where: str) -> None:
    if result.converged is False:
        warnings.warn(f"monodromy matrix at {where} did not converge: spectral radius"
                      f" {result.spectral_radius:.6g} with estimated error"
                      f" {result.error:.2g} after {result.n_steps} Magnus steps per period"
                      f" (rtol {result.rtol:g}); raise max_steps", ConvergenceWarning,
                      stacklevel=3)


def floquet(Phi, period: float, tol: float = 1e-6) -> Floquet:
    """Floquet multipliers and exponents from a monodromy matrix Φ(T) (2n, 2n).

    ``Phi`` is a matrix or a :class:`Monodromy` (whose convergence record is carried
    over). ``tol`` is the margin of the verdict ``max|μ| <= 1 + tol``: it absorbs the
    integration error of multipliers on the unit circle (undamped, conservative systems).
    """
    record = Phi if isinstance(Phi, Monodromy) else None
    Phi = np.asarray(Phi.matrix if record else Phi, dtype=float)
    if Phi.ndim != 2 or Phi.shape[0] != Phi.shape[1]:
        raise ValueError(f"the monodromy matrix must be square, got shape {Phi.shape}")
    if not np.isfinite(Phi).all():
        raise ValueError("the monodromy matrix contains NaN or inf (the integration"
                         " overflowed: use more steps)")
    mu = sla.eigvals(Phi)
    mu = mu[np.argsort(-np.abs(mu), kind="stable")]
    radius = float(np.abs(mu).max())
    with np.errstate(divide="ignore"):
        exponents = np.log(mu.astype(complex)) / period
    extra = (record.error, record.converged, record.n_steps) if record else ()
    return Floquet(mu, radius, radius <= 1.0 + tol, exponents, Phi, float(period), tol,
                   *extra)


def coupled_monodromy(system: CoupledSystem, Omega: float, n_steps: int = 32,
                      angle_period: float = 2 * np.pi, phi0: float = 0.0,
                      basis: np.ndarray | None = None, rtol: float | None = RTOL,
                      max_steps: int = MAX_STEPS, full_output: bool = False):
    """Monodromy matrix of a coupled machine running at constant drive speed Ω.

    The drive angle is φ = φ₀ + Ω t, so the period is T = Θ/Ω with Θ = ``angle_period``
    (2π when every mount's ratio is an integer; use the cycle angle of the machine
    otherwise). M, B, C (seed 5.2.2 eq. 9, with Ω̇ = 0) come from
    :meth:`CoupledSystem.mechanism_blocks` on the time grid and
    :func:`femmech.coupling.assemble_stack`. The steps start at every breakpoint of the
    mounted mechanisms (:func:`femmech.coupling.drive_breakpoints`: cam joints, where
    the jerk jumps) and double until the spectral radius meets ``rtol``.

    Parameters
    ----------
    system : CoupledSystem
        Reduced (dense) frame, primal form.
    Omega : float
        Drive speed, rad/s, > 0.
    n_steps : int
        Initial Magnus-4 steps per period. At high speed a few dozen resolve the
        mechanism's variation over the cycle; at low speed the period is long against
        the frame's vibration periods and the doubling goes on until the result settles.
    angle_period : float
        Θ, rad.
    phi0 : float
        Drive angle at t = 0, rad (the multipliers do not depend on it).
    basis : ndarray (n, r), optional
        Constant Ritz basis V (e.g. :func:`quasi_modal_basis`): the motion is sought as
        x = V y and the equations are projected, Vᵀ M V y'' + Vᵀ B V y' + Vᵀ C V y = 0.
        This keeps the r slow coupled modes that can be parametrically excited in the
        speed range and drops the stiff residual-vector and high frame modes, whose
        exponentials dominate the cost (about (2n)³ per step); the user chooses r.
    rtol, max_steps, full_output
        As in :func:`monodromy`.

    Returns
    -------
    ndarray (2n, 2n) or (2r, 2r), or Monodromy
        Φ(T) for ``z = [x; x']`` in the system's global coordinates x, or for
        ``z = [y; y']`` with a basis.

    Raises
    ------
    ValueError
        For an unreduced (sparse) frame, the multiplier form, Ω <= 0 or a bad basis.
    """
    result = _coupled_record(system, Omega, n_steps, angle_period, phi0, basis, rtol,
                             max_steps)
    _warn_unconverged(result, f"drive speed {Omega:.6g} rad/s")
    return result if full_output else result.matrix


def _coupled_record(system, Omega, n_steps, angle_period, phi0, basis, rtol, max_steps):
    """:class:`Monodromy` of :func:`coupled_monodromy`, without the warning."""
    require_dense_primal(system, "coupled_monodromy")
    if not (np.isfinite(Omega) and Omega > 0):
        raise ValueError(f"drive speed Omega must be positive, got {Omega} rad/s")
    V = None if basis is None else _checked_basis(basis, system.n)

    def coefficients(t):
        stacks = assemble_stack(system, system.mechanism_blocks(phi0 + Omega * t, Omega))[:3]
        return stacks if V is None else tuple(V.T @ X @ V for X in stacks)

    breaks = (drive_breakpoints(system, angle_period) - phi0) / Omega
    return integrate_monodromy(coefficients, angle_period / Omega, n_steps, rtol, max_steps,
                               breaks)


def coupled_floquet(system: CoupledSystem, Omega: float, n_steps: int = 32,
                    angle_period: float = 2 * np.pi, tol: float = 1e-6,
                    basis: np.ndarray | None = None, rtol: float | None = RTOL,
                    max_steps: int = MAX_STEPS) -> Floquet:
    """:func:`floquet` of :func:`coupled_monodromy` (period Θ/Ω), with its check."""
    record = coupled_monodromy(system, Omega, n_steps, angle_period, basis=basis,
                               rtol=rtol, max_steps=max_steps, full_output=True)
    return floquet(record, angle_period / Omega, tol)


def _checked_basis(basis, n: int) -> np.ndarray:
    V = np.asarray(basis, dtype=float)
    if V.ndim != 2 or V.shape[0] != n or not 0 < V.shape[1] <= n:
        raise ValueError(f"basis must have shape ({n}, r) with 0 < r <= {n}, got {V.shape}")
    if not np.isfinite(V).all():
        raise ValueError("basis contains NaN or inf")
    s = np.linalg.svd(V, compute_uv=False)
    if s[-1] <= 1e-10 * s[0]:
        raise ValueError(f"basis columns are linearly dependent (singular values"
                         f" {s[0]:.3e} ... {s[-1]:.3e})")
    return V


def quasi_modal_basis(system: CoupledSystem, n_modes: int, n_angles: int = 8,
                      angle_period: float = 2 * np.pi, rtol: float = 1e-8) -> np.ndarray:
    """Ritz basis of the lowest coupled quasi-modes at several drive angles.

    The undamped quasi-modes (Ω = 0) of the ``n_modes`` lowest branches at ``n_angles``
    equally spaced angles over the cycle Θ are stacked and orthonormalised (SVD; columns
    with singular values below ``rtol`` times the largest are dropped), so that the
    basis spans every position's low modes. Use it with :func:`coupled_monodromy`,
    :func:`coupled_floquet` or :func:`stability_chart` (``basis=``) to compute the
    Floquet multipliers of the slow motion only; check convergence by increasing
    ``n_modes`` (tests/test_stability.py shows the spectral radius converging).

    Returns
    -------
    ndarray (n, r), r <= n_modes · n_angles
        Orthonormal columns (Euclidean) in the system's global coordinates.
    """
    if int(n_modes) != n_modes or not 1 <= n_modes <= system.n:
        raise ValueError(f"n_modes must be an integer in 1..{system.n}, got {n_modes}")
    if int(n_angles) != n_angles or n_angles < 1:
        raise ValueError(f"n_angles must be a positive integer, got {n_angles}")
    phi = np.arange(int(n_angles)) * (angle_period / n_angles)
    result = sweep(system, phi, n_modes=int(n_modes), track=False, keep_vectors=True)
    stacked = np.concatenate(list(result.vectors), axis=1)
    U, s, _ = np.linalg.svd(stacked / np.linalg.norm(stacked, axis=0), full_matrices=False)
    return U[:, s > rtol * s[0]]


def resonance_speeds(freq_hz, orders=(1, 2, 3), kind: str = "parametric",
                     within: tuple[float, float] | None = None) -> dict:
    """Predicted resonance speeds of a machine whose coefficients repeat every revolution.

    A harmonic j of the drive speed Ω excites a mode of circular frequency ω_k
    parametrically near j Ω = 2 ω_k (principal parametric resonance) and as a forced
    vibration near j Ω = ω_k (Nayfeh & Mook, Nonlinear Oscillations, 1979, sect. 5.4;
    Dresig & Holzweißig, Maschinendynamik, ch. 6 on parametric excitation).

    Parameters
    ----------
    freq_hz : array_like (n_modes,)
        Representative (e.g. angle-averaged) quasi-eigenfrequencies, Hz.
    orders : sequence of int
        Harmonic orders j.
    kind : {"parametric", "forced"}
    within : (float, float), optional
        Keep only speeds in this range, rad/s (e.g. the chart's speed range).

    Returns
    -------
    dict
        ``{"2f1/1": Ω, ...}`` (or ``"f1/1"``), Ω in rad/s.
    """
    if kind not in ("parametric", "forced"):
        raise ValueError(f"kind must be 'parametric' or 'forced', got {kind!r}")
    factor, label = (2.0, "2f") if kind == "parametric" else (1.0, "f")
    marks = {}
    for k, f in enumerate(np.atleast_1d(np.asarray(freq_hz, dtype=float)), start=1):
        for j in orders:
            speed = factor * 2 * np.pi * f / j
            if within is None or within[0] <= speed <= within[1]:
                marks[f"{label}{k}/{j}"] = speed
    return marks


def stability_chart(system_or_callable, speeds, second_parameter_values=None,
                    n_steps: int = 32, angle_period: float = 2 * np.pi, tol: float = 1e-6,
                    parameter_name: str = "parameter",
                    basis: np.ndarray | None = None, rtol: float = RTOL,
                    max_steps: int = MAX_STEPS) -> StabilityChart:
    """Spectral radius of the monodromy matrix over drive speed (and a second parameter).

    Parameters
    ----------
    system_or_callable : CoupledSystem or callable
        A coupled machine (speed sweep only), or ``f(Omega)`` /
        ``f(Omega, value)`` (with ``second_parameter_values``) returning either a
        CoupledSystem or a tuple ``(M_of_t, B_of_t, C_of_t, period)`` as taken by
        :func:`monodromy` (e.g. a Mathieu equation with its forcing period 2π/Ω).
    speeds : array_like (n_speeds,)
        Drive speeds Ω, rad/s, > 0.
    second_parameter_values : array_like (n_values,) or None
        E.g. a damping ratio, a stiffness or an amplitude (own unit).
    n_steps, angle_period, tol, rtol, max_steps
        As in :func:`coupled_monodromy` and :func:`floquet`: every point's spectral
        radius is integrated until it meets ``rtol`` (step doubling from ``n_steps``).
    parameter_name : str
        Label of the second parameter for plots, with its unit.
    basis : ndarray (n, r), optional
        Ritz basis for coupled systems (:func:`coupled_monodromy`); the same for every
        point of the chart.

    Returns
    -------
    StabilityChart
        ``spectral_radius`` of shape (n_values, n_speeds), n_values = 1 without a second
        parameter. Unstable points (> 1 + tol) mark parametric resonances; points that
        missed ``rtol`` within ``max_steps`` are marked in ``converged`` (one
        :class:`ConvergenceWarning` names how many).
    """
    if rtol is None or not (np.isfinite(rtol) and rtol > 0):
        raise ValueError(f"rtol must be a positive tolerance, got {rtol}: every point of a"
                         " chart is checked")
    speeds = np.atleast_1d(np.asarray(speeds, dtype=float))
    values = None if second_parameter_values is None else \
        np.atleast_1d(np.asarray(second_parameter_values, dtype=float))
    if isinstance(system_or_callable, CoupledSystem):
        if values is not None:
            raise ValueError("a second parameter needs a callable f(Omega, value) building"
                             " the system; got a CoupledSystem")
        system = system_or_callable

        def build(W, _):
            return system
    elif callable(system_or_callable):
        def build(W, p):
            return system_or_callable(W) if values is None else system_or_callable(W, p)
    else:
        raise TypeError(f"system_or_callable must be a CoupledSystem or a callable, got"
                        f" {type(system_or_callable).__name__}")
    rows = [None] if values is None else values
    shape = (len(rows), speeds.size)
    radius, periods, error = np.zeros(shape), np.zeros(shape), np.zeros(shape)
    converged, steps = np.zeros(shape, dtype=bool), np.zeros(shape, dtype=int)
    for i, p in enumerate(rows):
        for j, W in enumerate(speeds):
            record, periods[i, j] = _point(build(W, p), W, n_steps, angle_period, basis,
                                           rtol, max_steps)
            radius[i, j], error[i, j] = record.spectral_radius, record.error
            converged[i, j], steps[i, j] = bool(record.converged), record.n_steps
    chart = StabilityChart(speeds, values, radius, radius <= 1.0 + tol, tol, parameter_name,
                           periods, error, converged, steps, float(rtol))
    warn_unconverged_chart(chart)
    return chart


def warn_unconverged_chart(chart: StabilityChart) -> None:
    """One :class:`ConvergenceWarning` naming the chart points that missed ``rtol``."""
    bad = chart.unconverged
    if bad.any():
        speeds = chart.speeds[bad.any(axis=0)]
        warnings.warn(f"{int(bad.sum())} of {bad.size} stability-chart points did not"
                      f" converge to rtol {chart.rtol:g} (speeds {speeds.min():.4g} to"
                      f" {speeds.max():.4g} rad/s); they are marked in the chart's"
                      " `converged`; raise max_steps", ConvergenceWarning, stacklevel=3)


def _point(model, Omega, n_steps, angle_period, basis, rtol, max_steps):
    """(:class:`Monodromy`, period T in s) of one chart point."""
    if isinstance(model, CoupledSystem):
        return (_coupled_record(model, Omega, n_steps, angle_period, 0.0, basis, rtol,
                                max_steps), angle_period / Omega)
    try:
        M_of_t, B_of_t, C_of_t, period = model
    except (TypeError, ValueError):
        raise TypeError("the callable must return a CoupledSystem or a tuple (M_of_t,"
                        f" B_of_t, C_of_t, period); got {type(model).__name__}") from None
    return _record(M_of_t, B_of_t, C_of_t, period, n_steps, rtol, max_steps), float(period)


@dataclass(frozen=True)
class SpeedStudy:
    """Floquet stability of a coupled machine over drive speed and frame damping.

    Attributes
    ----------
    line : StabilityChart
        Over speed at the nominal frame damping ratio.
    chart : StabilityChart or None
        Over speed and the frame damping ratio (``None`` without ratios).
    marks : dict
        Predicted principal parametric resonances ``{"2f1/j": Ω}`` (rad/s) in the range.
    mean_freq_hz : ndarray (n_branches,)
        Angle-averaged quasi-eigenfrequencies of the marked branches, Hz.
    basis_size : int
        Columns of the Ritz basis used for the monodromy matrices.
    zeta : float
        Nominal frame damping ratio of ``line``.
    """

    line: StabilityChart
    chart: StabilityChart | None
    marks: dict
    mean_freq_hz: np.ndarray
    basis_size: int
    zeta: float = float("nan")

    def summary(self) -> str:
        """One line: the largest growth rate at nominal damping and the unstable points."""
        text = (f"growth rate {self.line.growth_rate.max():.3g} 1/s at most (frame ζ ="
                f" {self.zeta:g}, {'stable' if self.line.stable.all() else 'UNSTABLE'})")
        if self.chart is not None:
            text += (f"; {int((~self.chart.stable).sum())} of {self.chart.stable.size}"
                     " (speed, ζ) points unstable")
        bad = sum(int(c.unconverged.sum()) for c in (self.line, self.chart) if c is not None)
        if bad:
            text += f"; {bad} points NOT CONVERGED (marked in the charts)"
        return text


def speed_study(system: CoupledSystem, speeds, zeta: float, band_hz: tuple[float, float],
                damping_ratios=None, n_steps: int = 32, basis_modes: int = 8,
                marked_branches: int = 2, orders=range(1, 13),
                angle_period: float = 2 * np.pi, rtol: float = RTOL,
                max_steps: int = MAX_STEPS) -> SpeedStudy:
    """Stability of a machine over speed, with Rayleigh frame damping, in one call.

    ``system`` carries the mechanisms' own damping but no frame damping; the frame gets
    Rayleigh damping of ratio ζ at both ends of ``band_hz``
    (:func:`~femmech.analysis.response.rayleigh_coefficients`). The monodromy matrices use
    the Ritz basis of the ``basis_modes`` lowest quasi-modes (:func:`quasi_modal_basis`,
    built once at the nominal damping), and the predicted resonance speeds 2 f_k / j of the
    ``marked_branches`` lowest branches (angle-averaged over 36 angles) are returned for
    the plots.

    Parameters
    ----------
    system : CoupledSystem
    speeds : array_like (n_speeds,)
        Drive speeds, rad/s.
    zeta : float
        Nominal frame damping ratio (-).
    band_hz : (float, float)
        Frequencies where the Rayleigh damping ratio equals ζ, Hz.
    damping_ratios : array_like, optional
        Frame damping ratios of the two-parameter chart.
    n_steps, basis_modes, angle_period, rtol, max_steps
        As in :func:`coupled_monodromy` and :func:`quasi_modal_basis`.
    marked_branches : int
    orders : sequence of int
        Harmonic orders j of the marks.
    """
    speeds = np.atleast_1d(np.asarray(speeds, dtype=float))

    def damped(ratio):
        return rayleigh_damping(system, *rayleigh_coefficients(ratio, *band_hz))

    nominal = damped(zeta)
    basis = quasi_modal_basis(nominal, basis_modes, angle_period=angle_period)
    phi = np.linspace(0.0, angle_period, 36, endpoint=False)
    mean_hz = sweep(nominal, phi, n_modes=marked_branches).freq_hz.mean(axis=0)
    marks = resonance_speeds(mean_hz, orders, within=(speeds.min(), speeds.max()))
    line = stability_chart(nominal, speeds, n_steps=n_steps, angle_period=angle_period,
                           basis=basis, rtol=rtol, max_steps=max_steps)
    chart = None
    if damping_ratios is not None:
        chart = stability_chart(lambda W, ratio: damped(ratio), speeds, damping_ratios,
                                n_steps=n_steps, angle_period=angle_period, rtol=rtol,
                                max_steps=max_steps,
                                parameter_name="frame damping ratio ζ (-)", basis=basis)
    return SpeedStudy(line, chart, marks, mean_hz, basis.shape[1], float(zeta))
