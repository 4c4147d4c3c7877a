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

The monodromy matrix comes from the Magnus integrator of :mod:`femmech.analysis.magnus`
(step doubling until the spectral radius meets a tolerance): here for coefficients given
as functions of time (:func:`monodromy`) or for a coupled machine at constant drive speed
(:func:`coupled_monodromy`, optionally on a quasi-modal Ritz basis,
:func:`quasi_modal_basis`), and the multipliers and exponents from it (:func:`floquet`,
:class:`Floquet`). Charts over speed are :mod:`femmech.analysis.stability`.

Uses coupling, errors and analysis.magnus and .sweep; nothing here
writes files.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from femmech.analysis.magnus import MAX_STEPS, RTOL, Monodromy, integrate_monodromy
from femmech.analysis.sweep import frozen_modes, sweep
from femmech.coupling import (
    CoupledSystem,
    assemble_stack,
    drive_breakpoints,
    require_dense_primal,
)
from femmech.errors import ConvergenceWarning


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
    result = monodromy_record(M_of_t, B_of_t, C_of_t, period, n_steps, rtol, max_steps,
                              breakpoints)
    _warn_unconverged(result, f"period {float(period):.6g} s")
    return result if full_output else result.matrix


def monodromy_record(M_of_t, B_of_t, C_of_t, period, n_steps, rtol, max_steps,
                     breakpoints=()):
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
    result = coupled_monodromy_record(system, Omega, n_steps, angle_period, phi0, basis,
                                      rtol, max_steps)
    _warn_unconverged(result, f"drive speed {Omega:.6g} rad/s")
    return result if full_output else result.matrix


def coupled_monodromy_record(system, Omega, n_steps, angle_period, phi0, basis, rtol,
                             max_steps):
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


UNDAMPED_RTOL = 1e-9
"""A quasi-mode counts as undamped when its modal damping |vᵀ B_sym v| (v mass-normalised)
is at most UNDAMPED_RTOL · 2ω (damping ratio below 1e-9)."""


def coupled_floquet(system: CoupledSystem, Omega: float, n_steps: int = 32,
                    angle_period: float = 2 * np.pi, tol: float = 1e-6,
                    basis: np.ndarray | None = None, rtol: float | None = RTOL,
                    max_steps: int = MAX_STEPS, allow_undamped: bool = False) -> Floquet:
    """:func:`floquet` of :func:`coupled_monodromy` (period Θ/Ω), with its check.

    Without a ``basis``, a system with an undamped quasi-mode (at every one of 4 angles
    over the cycle; typically an undamped frame whose modes no mechanism damper moves)
    is refused with a ``ValueError``: each such mode has the multipliers |μ| = 1, so the
    spectral radius is 1 up to the integration error of the (stiff) undamped modes,
    whatever the damped mechanism motion does, and the verdict ``ρ <= 1 + tol`` then
    reads that error (tests/mechanisms/test_gaps_floquet.py: ρ = 1 + 2.8e-6, "unstable",
    for a cam on an undamped beam at 5 rad/s). Give the frame damping
    (:func:`femmech.analysis.response.rayleigh_damping`), a Ritz ``basis`` of the motions
    to judge, or ``allow_undamped=True`` for the conservative system's ρ as it is.
    """
    if basis is None and not allow_undamped:
        _refuse_undamped(system, Omega, angle_period)
    record = coupled_monodromy(system, Omega, n_steps, angle_period, basis=basis,
                               rtol=rtol, max_steps=max_steps, full_output=True)
    return floquet(record, angle_period / Omega, tol)


def _refuse_undamped(system: CoupledSystem, Omega: float, angle_period: float) -> None:
    """Raise ValueError if every one of 4 angles has an undamped quasi-mode
    (modes of C(φ, 0) v = λ M(φ) v, damping from the symmetric part of B(φ, Ω))."""
    require_dense_primal(system, "coupled_floquet")
    found = []
    for phi in np.arange(4) * (angle_period / 4):
        M, _, C, _ = system.matrices(phi, 0.0)
        B = system.matrices(phi, Omega)[1]
        _, freq, _, V, _ = frozen_modes(M, None, C, system.n)
        V = V.real
        damping = np.abs(np.einsum("ij,ij->j", V, 0.5 * (B + B.T) @ V))
        undamped = damping <= UNDAMPED_RTOL * 4 * np.pi * np.abs(freq)
        if not undamped.any():
            return
        found.append(freq[undamped])
    listed = ", ".join(f"{f:.4g}" for f in found[0][:6])
    raise ValueError(
        f"coupled_floquet: {found[0].size} quasi-mode(s) of the system are undamped"
        f" (at phi = 0: {listed} Hz; frame without damping?). Their Floquet multipliers"
        " lie on the unit circle, so the spectral radius is 1 up to integration error"
        " whatever the mechanisms do, and the stability verdict would read that error."
        " Add frame damping (femmech.analysis.response.rayleigh_damping), pass"
        " basis= spanning the motions to judge, or allow_undamped=True for the"
        " conservative system's spectral radius as it is")


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
    if int(n_modes) != n_modes or not 1 <= n_modes < system.n:  # the branches of sweep
        raise ValueError(f"n_modes must be an integer in 1..{system.n - 1} (the system has"
                         f" {system.n} coordinates), got {n_modes}")
    if int(n_angles) != n_angles or n_angles < 1:
        raise ValueError(f"n_angles must be a positive integer, got {n_angles}")
    phi = np.arange(int(n_angles)) * (angle_period / n_angles)
    result = sweep(system, phi, n_modes=int(n_modes), track=False, keep_vectors=True)
    stacked = np.concatenate(list(result.vectors), axis=1)
    U, s, _ = np.linalg.svd(stacked / np.linalg.norm(stacked, axis=0), full_matrices=False)
    return U[:, s > rtol * s[0]]
