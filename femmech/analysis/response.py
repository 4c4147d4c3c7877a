"""Forced response of coupled rheolinear systems in the time domain.

A machine driven along a prescribed law φ(t) (speed Ω = φ', acceleration Ω̇ = φ'')
vibrates as (seed 5.2.2 eq. 9)

    M(φ) q'' + B(φ, Ω) q' + C(φ, Ω, Ω̇) q = F(φ, Ω, Ω̇),

with the drive's inertia, centrifugal and Coriolis forces in F. Symbols are the
chapter's: M mass, B damping, C stiffness, F force; q the global coordinates of a
:class:`~femmech.coupling.CoupledSystem` (or the vibration coordinates of a
:class:`~femmech.mechanisms.RheolinearModel` alone).

Integrator: generalised-α (Chung & Hulbert, J. Appl. Mech. 60 (1993) 371), with the
equation of motion averaged between t_n and t_{n+1} (inertia with weight α_m, the rest
with α_f; the form of Erlicher, Bonaventura & Bursi, Comput. Mech. 28 (2002) 83, which
keeps second order with coefficients that vary in time, so the matrices are needed only
at the grid points):

    (1-α_m) M₁a₁ + α_m M₀a₀ + (1-α_f)(B₁v₁ + C₁q₁) + α_f(B₀v₀ + C₀q₀) = (1-α_f)F₁ + α_f F₀,
    q₁ = q₀ + h v₀ + h²[(½-β) a₀ + β a₁],   v₁ = v₀ + h[(1-γ) a₀ + γ a₁],

α_m = (2ρ∞-1)/(ρ∞+1), α_f = ρ∞/(ρ∞+1), γ = ½ - α_m + α_f, β = ¼(1 - α_m + α_f)².
It is implicit and unconditionally stable, second-order accurate, and its numerical
dissipation is set by the spectral radius ρ∞ at h → ∞: the stiff frame modes far above
the excitation are damped (ρ∞ < 1) without touching the resolved low modes, while
ρ∞ = 1 is the trapezoidal rule (Newmark average acceleration, energy conserving).

Uses coupling, fe (node and DOF lookup) and errors; nothing here writes
files.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from femmech.errors import ConvergenceWarning
from femmech.fe.dofs import COMPONENTS, DOF_PER_NODE
from femmech.fe.model import node_index
from femmech.html import Flag, html_summary
from femmech.mechanisms.motion_laws import motion_law

if TYPE_CHECKING:
    from femmech.coupling import CoupledSystem


@dataclass(frozen=True)
class Response:
    """Time history of the vibration coordinates.

    Attributes
    ----------
    t : ndarray (n_t,)
        Times, s.
    q, v, a : ndarray (n_t, n)
        Coordinates (m, rad, modal), their velocities and accelerations.
    phi : ndarray (n_t,)
        Main drive angle φ(t), rad.
    error : float
        Periodic steady state: estimated relative error of q (step doubling, see
        :func:`periodic_steady_state`); NaN without a check.
    converged : bool or None
        Whether ``error`` met the tolerance; ``None`` when unchecked (time responses on
        the user's grid, fixed-step steady states). An unconverged result is a number
        that may be wrong.
    n_steps : int or None
        Integration steps per period behind a steady state (the output grid may be
        coarser).
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    phi: np.ndarray
    error: float = float("nan")
    converged: bool | None = None
    n_steps: int | None = None

    def __repr__(self) -> str:
        t = np.asarray(self.t)
        state = ("" if self.converged is None else
                 f"; error {self.error:.1e}" + ("" if self.converged else " NOT CONVERGED"))
        return (f"Response({t.size} times {t[0]:.4g}..{t[-1]:.4g} s, {np.shape(self.q)[-1]}"
                f" coordinates{state})")

    def _repr_html_(self) -> str:
        t = np.asarray(self.t)
        facts = [("times / s", f"{t.size}, {t[0]:.4g} … {t[-1]:.4g}"),
                 ("coordinates", np.shape(self.q)[-1])]
        if self.converged is not None:
            facts.append(("estimated error", float(self.error) if self.converged
                          else Flag(f"{self.error:.1e} NOT CONVERGED")))
        if self.n_steps is not None:
            facts.append(("steps per period", self.n_steps))
        return html_summary("Response", facts)


@dataclass(frozen=True)
class ConstantSpeed:
    """Drive law φ = φ₀ + Ω t (Ω in rad/s, φ₀ in rad)."""

    Omega: float
    phi0: float = 0.0

    def __call__(self, t):
        """φ, Ω, Ω̇ at times t (n_t,) → three arrays (n_t,)."""
        t = np.asarray(t, dtype=float)
        return self.phi0 + self.Omega * t, np.full(t.shape, self.Omega), np.zeros(t.shape)


@dataclass(frozen=True)
class SpeedRamp:
    """Smooth speed change (run-up or braking) from Ω_start to Ω_end.

    Ω(t) = Ω_s + (Ω_e - Ω_s) s(τ), τ = (t - t_start)/duration, with the cycloidal ramp
    s(τ) = τ - sin(2πτ)/(2π) by default: the drive acceleration Ω̇ rises from and
    returns to zero (no jerk steps). Constant speeds before and after. Any cam motion
    law can shape the ramp instead (``law``: a name of
    :data:`femmech.mechanisms.motion_laws.LAWS` or a law object): then
    Ω̇ = (Ω_e - Ω_s) s'(τ)/duration and φ takes ``duration · ∫₀^τ s``; with
    ``"harmonic"`` Ω̇ jumps at both ends, with ``"polynomial_4567"`` even its rate is
    continuous. :meth:`breakpoints` gives the times where a derivative of Ω may jump.

    Attributes
    ----------
    Omega_start, Omega_end : float
        Speeds before and after the ramp, rad/s.
    duration : float
        Ramp time, s (> 0).
    t_start : float
        Ramp start, s.
    phi0 : float
        Drive angle at t = 0, rad.
    law : str or motion law
        Shape s(τ) of the ramp, ``"cycloidal"`` by default.
    """

    Omega_start: float
    Omega_end: float
    duration: float
    t_start: float = 0.0
    phi0: float = 0.0
    law: object = "cycloidal"

    def __post_init__(self):
        motion_law(self.law)  # an unknown name fails here, listing the known ones

    def breakpoints(self) -> np.ndarray:
        """Times, s, where Ω̇ or its rate may jump: the ramp's ends and the piece joints
        of a piecewise law (integrators align their steps with them)."""
        inner = motion_law(self.law).joints()
        return self.t_start + self.duration * np.concatenate([[0.0], inner, [1.0]])

    def __call__(self, t):
        """φ, Ω, Ω̇ at times t (n_t,) → three arrays (n_t,)."""
        if not self.duration > 0:
            raise ValueError(f"SpeedRamp duration must be positive, got {self.duration} s")
        t = np.asarray(t, dtype=float)
        d, dW = self.duration, self.Omega_end - self.Omega_start
        tau = np.clip((t - self.t_start) / d, 0.0, 1.0)
        if isinstance(self.law, str) and self.law == "cycloidal":
            s = tau - np.sin(2 * np.pi * tau) / (2 * np.pi)
            # ∫₀^τ s dτ' · d = d [τ²/2 + (cos 2πτ - 1)/(4π²)]
            ramp_angle = d * (tau**2 / 2 + (np.cos(2 * np.pi * tau) - 1) / (4 * np.pi**2))
            rate = 1 - np.cos(2 * np.pi * tau)
        else:
            law = motion_law(self.law)
            s, rate, _, _ = law.evaluate(tau)
            ramp_angle = d * law.integral(tau)
        after = np.clip(t - self.t_start - d, 0.0, None)
        phi = self.phi0 + self.Omega_start * t + dW * (ramp_angle + after)
        Omega = self.Omega_start + dW * s
        Omega_dot = dW / d * rate * ((tau > 0) & (tau < 1))
        return phi, Omega, Omega_dot


def drive_angles(drive, t):
    """φ, Ω, Ω̇ (n_t,) from a drive law object or a tuple of three callables."""
    if isinstance(drive, tuple):
        if len(drive) != 3 or not all(callable(f) for f in drive):
            raise TypeError("give the drive as a law object or a tuple of three callables"
                            " (phi(t), Omega(t), Omega_dot(t))")
        out = tuple(np.broadcast_to(np.asarray(f(t), dtype=float), t.shape) for f in drive)
    elif callable(drive):
        out = tuple(np.broadcast_to(np.asarray(x, dtype=float), t.shape) for x in drive(t))
    else:
        raise TypeError(f"drive must be a drive law (callable t -> (phi, Omega, Omega_dot))"
                        f" or a tuple of three callables, got {type(drive).__name__}")
    if not all(np.isfinite(x).all() for x in out):
        raise ValueError("the drive law gives non-finite φ, Ω or Ω̇")
    return out


def _matrices(system, phi, Omega, Omega_dot):
    """``matrices_at(k) -> (M, B, C, F)`` (dense) for the k-th time point."""
    from femmech.coupling import CoupledSystem, assemble_at, require_dense_primal

    if isinstance(system, CoupledSystem):
        require_dense_primal(system, "the response")
        blocks = system.mechanism_blocks(phi, Omega, Omega_dot)  # one vectorised call
        return lambda k: assemble_at(system, blocks, k)
    if all(hasattr(system, name) for name in ("M", "B", "C", "F", "coordinate_names")):
        stacks = (system.M(phi), system.B(phi, Omega), system.C(phi, Omega, Omega_dot),
                  system.F(phi, Omega, Omega_dot))
        return lambda k: tuple(s[k] for s in stacks)
    raise TypeError(f"system must be a CoupledSystem or a RheolinearModel, got"
                    f" {type(system).__name__}")


def alpha_parameters(rho_inf: float):
    """Generalised-α parameters (α_m, α_f, γ, β) for a spectral radius ρ∞ ∈ [0, 1]."""
    if not 0.0 <= rho_inf <= 1.0:
        raise ValueError(f"rho_inf must lie in [0, 1], got {rho_inf}")
    am, af = (2 * rho_inf - 1) / (rho_inf + 1), rho_inf / (rho_inf + 1)
    return am, af, 0.5 - am + af, 0.25 * (1 - am + af) ** 2


def _integrate(matrices_at, t, q0, v0, w, rho_inf, store):
    """Generalised-α for k columns at once: q, v (n, k); the force enters as F ⊗ w (k,).

    Returns (q, v, a) histories (n_t, n, k) when ``store``, else the final states.
    """
    am, af, gamma, beta = alpha_parameters(rho_inf)
    M0, B0, C0, F0 = matrices_at(0)
    q, v = q0, v0
    a = np.linalg.solve(M0, np.outer(F0, w) - B0 @ v - C0 @ q)
    hist = [(q, v, a)] if store else None
    for i in range(1, t.size):
        h = t[i] - t[i - 1]
        M1, B1, C1, F1 = matrices_at(i)
        qp = q + h * v + h * h * (0.5 - beta) * a
        vp = v + h * (1 - gamma) * a
        S = (1 - am) * M1 + (1 - af) * (gamma * h * B1 + beta * h * h * C1)
        r = (np.outer((1 - af) * F1 + af * F0, w) - am * (M0 @ a) - af * (B0 @ v + C0 @ q)
             - (1 - af) * (B1 @ vp + C1 @ qp))
        a = np.linalg.solve(S, r)
        q, v = qp + beta * h * h * a, vp + gamma * h * a
        M0, B0, C0, F0 = M1, B1, C1, F1
        if store:
            hist.append((q, v, a))
    if not store:
        return q, v, a
    return tuple(np.stack([s[j] for s in hist]) for j in range(3))


def _times(t) -> np.ndarray:
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2 or not np.all(np.diff(t) > 0) or not np.isfinite(t).all():
        raise ValueError("t must be a strictly increasing 1-D array of at least two finite"
                         " times, s")
    return t


def time_response(system, t, drive, q0=None, v0=None, rho_inf: float = 0.8) -> Response:
    """Forced response along a drive law by generalised-α time integration.

    Parameters
    ----------
    system : CoupledSystem or RheolinearModel
        A coupled machine with a reduced (dense) frame in the primal form, or one
        mechanism alone.
    t : array_like (n_t,)
        Time grid, s, strictly increasing (the steps h = diff(t)); the error is O(h²).
    drive : callable or tuple of three callables
        A law ``drive(t) -> (phi, Omega, Omega_dot)`` such as :class:`ConstantSpeed` or
        :class:`SpeedRamp`, or ``(phi_of_t, Omega_of_t, Omega_dot_of_t)``; rad, rad/s,
        rad/s².
    q0, v0 : array_like (n,), optional
        Initial coordinates and velocities (default zero); the initial acceleration
        follows from the equation of motion.
    rho_inf : float
        Spectral radius at infinite step, in [0, 1]: 1 conserves energy (trapezoidal
        rule), smaller values damp the unresolved high modes more strongly.

    Returns
    -------
    Response
    """
    t = _times(t)
    phi, Omega, Omega_dot = drive_angles(drive, t)
    matrices_at = _matrices(system, phi, Omega, Omega_dot)
    n = matrices_at(0)[0].shape[0]
    q0 = _initial(q0, n, "q0")
    v0 = _initial(v0, n, "v0")
    q, v, a = _integrate(matrices_at, t, q0[:, None], v0[:, None], np.ones(1), rho_inf,
                         store=True)
    return Response(t, q[..., 0], v[..., 0], a[..., 0], phi)


def _initial(x, n, name):
    if x is None:
        return np.zeros(n)
    x = np.asarray(x, dtype=float)
    if x.shape != (n,):
        raise ValueError(f"{name} must have shape ({n},), got {x.shape}")
    return x


STEADY_STATE_RTOL = 1e-3
"""Default tolerance of a periodic steady state: relative change of q (mass norm)."""

STEADY_STATE_MAX_STEPS = 2**15
"""Default cap on the integration steps per period of the step-doubling loop."""


def periodic_steady_state(system, Omega: float, n_steps: int = 512, rho_inf: float = 0.8,
                          angle_period: float = 2 * np.pi, phi0: float = 0.0,
                          richardson: bool = False, rtol: float | None = STEADY_STATE_RTOL,
                          max_steps: int = STEADY_STATE_MAX_STEPS) -> Response:
    """Periodic forced response at constant drive speed, by shooting, with error control.

    With φ = φ₀ + Ω t the coefficients and the force repeat with T = Θ/Ω. The
    generalised-α map over one period (N steps, initial acceleration from the equation
    of motion) is affine in z = [q; q']: ``z(T) = Φ z(0) + z_p`` with Φ from the 2n unit
    initial states (integrated together with the forced column z_p, from rest) and z_p
    the response to F. The periodic state is ``z(0) = (I - Φ)⁻¹ z_p``; its history is
    integrated once more. q and q' are periodic to round-off (z(T) = z(0)); the
    discretisation error is that of the integrator, O((T/N)²).

    Error control (step doubling): N starts at ``n_steps`` and doubles until two
    successive solutions differ by at most ``rtol`` on the output grid, measured as
    max_t ‖Δq(t)‖_M / max_t ‖q(t)‖_M in the mass norm at t = 0 (a unit-independent
    norm over all coordinates). The estimate is that of the coarser solution; the finer
    one, returned, is about 3 times (second order) or 15 times (Richardson) closer.
    At low speed the period is long against the frame's vibration periods and more
    steps are needed; a result that misses ``rtol`` within ``max_steps`` comes back with
    ``converged=False`` and a :class:`~femmech.errors.ConvergenceWarning`.

    Parameters
    ----------
    system : CoupledSystem or RheolinearModel
    Omega : float
        Drive speed, rad/s, > 0.
    n_steps : int
        Output points per period (t has n_steps + 1 points) and the first step count.
    rho_inf : float
        Generalised-α spectral radius at infinity.
    angle_period : float
        Θ, rad: the machine cycle (2π when all mount ratios are integers).
    phi0 : float
        Drive angle at t = 0, rad.
    richardson : bool
        Combine each pair of solutions as (4 x_{h/2} − x_h)/3 on the coarser grid
        (Richardson extrapolation of q, q', q''). With ρ∞ = 1 (trapezoidal rule, a
        symmetric method whose global error expands in even powers of h: Hairer,
        Nørsett & Wanner, Solving ODEs I, sect. II.8) the error falls from O(h²) to
        O(h⁴); the combination still satisfies the equation of motion at the grid points
        (weights summing to 1, linear equations). Worth it near resonances, where the
        O(h²) frequency error of the integrator shifts the resonance peak
        (benchmarks/response.py). For ρ∞ < 1
        the gain is one order only.
    rtol : float or None
        Tolerance of the step-doubling check; ``None``: integrate with ``n_steps`` only
        (and 2 n_steps for Richardson), unchecked.
    max_steps : int
        Largest step count per period tried.

    Returns
    -------
    Response
        Over one period, t = 0..T (n_steps + 1 points), with ``error``, ``converged``
        and the steps per period behind it (``n_steps``).

    Raises
    ------
    ValueError
        For Ω <= 0, a bad n_steps, or a free motion with a Floquet multiplier at 1
        (undamped resonance: I - Φ singular).
    """
    if not (np.isfinite(Omega) and Omega > 0):
        raise ValueError(f"drive speed Omega must be positive, got {Omega} rad/s")
    n_steps = check_step_control(n_steps, rtol, max_steps, minimum=2)

    def solve(n):
        return _shooting(system, Omega, n, rho_inf, angle_period, phi0)

    solutions = [solve(n_steps)]
    if richardson:
        solutions.append(solve(2 * n_steps))

    def level():  # the result from the newest solution(s)
        return _extrapolated(*solutions[-2:]) if richardson else solutions[-1]

    levels = [level()]
    if rtol is None:
        return replace(levels[0], n_steps=2 * n_steps if richardson else n_steps)
    mass = _matrices(system, *ConstantSpeed(Omega, phi0)(np.zeros(1)))(0)[0]
    error, converged = np.inf, False
    while 2 * (n := n_steps * 2 ** (len(solutions) - 1)) <= max_steps:
        solutions.append(solve(2 * n))
        levels.append(level())
        error = _change(levels[-2], levels[-1], mass)
        if error <= rtol:
            converged = True
            break
    finest = levels[-1]
    every = (finest.t.size - 1) // n_steps
    result = Response(finest.t[::every], finest.q[::every], finest.v[::every],
                      finest.a[::every], finest.phi[::every], float(error), converged,
                      (finest.t.size - 1) * (2 if richardson else 1))
    if not converged:
        warnings.warn(f"periodic steady state at {Omega:.6g} rad/s did not converge:"
                      f" estimated relative error {error:.2g} > rtol {rtol:g} after"
                      f" {result.n_steps} steps per period; raise max_steps",
                      ConvergenceWarning, stacklevel=2)
    return result


def check_step_control(n_steps, rtol, max_steps, minimum: int = 1) -> int:
    """Validate the step-doubling settings of a periodic solve; return ``n_steps`` as int.

    ``n_steps`` an integer >= ``minimum``, ``rtol`` positive or None (fixed steps),
    ``max_steps`` an integer >= ``n_steps``; a ValueError names the offending one.
    """
    if isinstance(n_steps, bool) or int(n_steps) != n_steps or n_steps < minimum:
        raise ValueError(f"n_steps must be an integer >= {minimum}, got {n_steps}")
    if rtol is not None and not (np.isfinite(rtol) and rtol > 0):
        raise ValueError(f"rtol must be positive (or None for fixed steps), got {rtol}")
    if isinstance(max_steps, bool) or int(max_steps) != max_steps or max_steps < n_steps:
        raise ValueError(f"max_steps must be an integer >= n_steps = {n_steps}, got"
                         f" {max_steps}")
    return int(n_steps)


def _extrapolated(coarse: Response, fine: Response) -> Response:
    """(4 x_{h/2} − x_h)/3 on the coarse grid, for q, q' and q''."""
    combined = [(4 * getattr(fine, k)[::2] - getattr(coarse, k)) / 3 for k in "qva"]
    return Response(coarse.t, *combined, coarse.phi)


def _change(coarse: Response, fine: Response, mass: np.ndarray) -> float:
    """max_t ‖q_fine − q_coarse‖_M / max_t ‖q_fine‖_M on the coarse grid."""
    every = (fine.t.size - 1) // (coarse.t.size - 1)
    q = fine.q[::every]

    def norm(x):
        return np.sqrt(np.abs(np.einsum("ti,ij,tj->t", x, mass, x))).max()

    scale = norm(q)
    return float(norm(q - coarse.q) / scale) if scale > 0 else 0.0


def _shooting(system, Omega, n_steps, rho_inf, angle_period, phi0) -> Response:
    """One shooting solve of the periodic state on n_steps equal steps (unchecked)."""
    t = np.linspace(0.0, angle_period / Omega, int(n_steps) + 1)
    drive = ConstantSpeed(Omega, phi0)
    matrices_at = _matrices(system, *drive(t))
    n = matrices_at(0)[0].shape[0]
    eye = np.eye(n)
    zeros = np.zeros((n, n))
    Q0 = np.hstack([eye, zeros, np.zeros((n, 1))])
    V0 = np.hstack([zeros, eye, np.zeros((n, 1))])
    w = np.r_[np.zeros(2 * n), 1.0]
    qT, vT, _ = _integrate(matrices_at, t, Q0, V0, w, rho_inf, store=False)
    Phi = np.vstack([qT[:, :-1], vT[:, :-1]])
    zp = np.r_[qT[:, -1], vT[:, -1]]
    A = np.eye(2 * n) - Phi
    if np.linalg.cond(A) > 1e12:
        raise ValueError(f"no unique periodic response at Omega = {Omega} rad/s: the free"
                         " motion has a Floquet multiplier at 1 (undamped resonance)")
    z0 = np.linalg.solve(A, zp)
    q, v, a = _integrate(matrices_at, t, z0[:n, None], z0[n:, None], np.ones(1), rho_inf,
                         store=True)
    return Response(t, q[..., 0], v[..., 0], a[..., 0], drive(t)[0])


def rayleigh_damping(system: CoupledSystem, mass_coef: float,
                     stiffness_coef: float) -> CoupledSystem:
    """Copy of ``system`` with frame damping B₀ += a M₀ + b K₀ (a in 1/s, b in s).

    M₀ and K₀ are the constant parts (the frame and bearing springs), so only the frame
    is damped; a mode of circular frequency ω gets the damping ratio a/(2ω) + bω/2.
    """
    B0 = system.B0 + mass_coef * system.M0 + stiffness_coef * system.K0
    return replace(system, B0=B0)


def rayleigh_coefficients(zeta: float, f1_hz: float, f2_hz: float) -> tuple[float, float]:
    """Rayleigh coefficients (a in 1/s, b in s) giving the damping ratio ζ at f1 and f2.

    From ζ(ω) = a/(2ω) + bω/2 at ω₁ = 2π f1 and ω₂ = 2π f2: a = 2ζ ω₁ω₂/(ω₁ + ω₂),
    b = 2ζ/(ω₁ + ω₂) (Chopra, Dynamics of Structures, 4th ed., eq. 11.4.9); between f1 and
    f2 the ratio is slightly below ζ, outside it grows.
    """
    if not (np.isfinite(zeta) and zeta >= 0):
        raise ValueError(f"damping ratio zeta must be >= 0, got {zeta}")
    if not (0 < f1_hz < f2_hz < np.inf):
        raise ValueError(f"need 0 < f1_hz < f2_hz, got f1_hz = {f1_hz}, f2_hz = {f2_hz}")
    w1, w2 = 2 * np.pi * f1_hz, 2 * np.pi * f2_hz
    return 2 * zeta * w1 * w2 / (w1 + w2), 2 * zeta / (w1 + w2)


def frame_history(system: CoupledSystem, model, q_history, dofs) -> np.ndarray:
    """Full-model frame displacements at chosen DOFs, as time histories.

    Only the rows of the recovery that are needed are built (one row of the constraint
    transformation and of the superelement's constraint and fixed-interface modes per
    DOF), so no full-size vector is expanded per time step.

    Parameters
    ----------
    system : CoupledSystem
    model : FEModel or None
        The frame's FE model, to resolve node group names; ``None`` for node indices.
    q_history : ndarray (n_t, n)
        Global coordinates over time (``Response.q``).
    dofs : sequence
        Full-model DOF indices (``6 * node + component``) or ``(node, component)`` pairs
        with a node index or single-node group name and a component name (``"uy"``).

    Returns
    -------
    ndarray (n_t, n_dofs)
        Displacements (m) or rotations (rad).
    """
    q_history = np.asarray(q_history, dtype=float)
    if q_history.ndim != 2 or q_history.shape[1] != system.n:
        raise ValueError(f"q_history must have shape (n_t, {system.n}), got"
                         f" {q_history.shape}")
    from femmech.coupling import frame_row

    rows = np.array([frame_row(system.frame, *node_component(model, d)) for d in dofs])
    return q_history[:, :system.n_frame] @ rows.T


def node_component(model, dof):
    if isinstance(dof, (int, np.integer)):
        return int(dof) // DOF_PER_NODE, COMPONENTS[int(dof) % DOF_PER_NODE]
    node, component = dof
    if isinstance(node, str):
        if model is None:
            raise ValueError(f"DOF {dof!r}: give the FE model to resolve node group names")
        node = node_index(model.mesh, node, "frame_history")
    return node, component
