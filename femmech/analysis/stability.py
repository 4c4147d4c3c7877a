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
  at once (stacked :func:`scipy.linalg.expm`) and multiplied in a balanced tree, so the
  per-step Python cost is nil.

Global error O(h⁴) (tests/test_stability.py measures the order).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from femmech.analysis.response import rayleigh_coefficients, rayleigh_damping
from femmech.analysis.sweep import sweep
from femmech.coupling import CoupledSystem, assemble_at, require_dense_primal

GAUSS_OFFSETS = np.array([0.5 - np.sqrt(3.0) / 6.0, 0.5 + np.sqrt(3.0) / 6.0])
"""Two-point Gauss-Legendre nodes on [0, 1]."""

_CHUNK_BYTES = 2**25
"""Memory per stacked array of one chunk of steps (32 MiB)."""


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
    """

    multipliers: np.ndarray
    spectral_radius: float
    stable: bool
    exponents: np.ndarray
    monodromy: np.ndarray
    period: float
    tol: float


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
    """

    speeds: np.ndarray
    values: np.ndarray | None
    spectral_radius: np.ndarray
    stable: np.ndarray
    tol: float
    parameter_name: str = "parameter"
    periods: np.ndarray | None = None

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


def _tree_product(E: np.ndarray) -> np.ndarray:
    """``E[-1] @ ... @ E[1] @ E[0]`` for a stack (k, m, m), by pairwise products."""
    while E.shape[0] > 1:
        if E.shape[0] % 2:
            E = np.concatenate([E, np.eye(E.shape[1])[None]])
        E = E[1::2] @ E[0::2]
    return E[0]


def _magnus_monodromy(coefficients, period: float, n_steps: int) -> np.ndarray:
    """Magnus-4 monodromy; ``coefficients(t) -> (M, B, C)`` stacks at times t (k,)."""
    if not (np.isfinite(period) and period > 0):
        raise ValueError(f"period must be positive and finite, got {period}")
    if int(n_steps) != n_steps or n_steps < 1:
        raise ValueError(f"n_steps must be a positive integer, got {n_steps}")
    n_steps, h = int(n_steps), period / n_steps
    n = coefficients(np.zeros(1))[0].shape[-1]
    chunk = max(1, _CHUNK_BYTES // (8 * 2 * (2 * n) ** 2))  # A at two nodes per step
    Phi = np.eye(2 * n)
    for start in range(0, n_steps, chunk):
        steps = np.arange(start, min(start + chunk, n_steps))
        t = ((steps[:, None] + GAUSS_OFFSETS[None, :]) * h).ravel()
        A = first_order_matrices(*coefficients(t))
        A1, A2 = A[0::2], A[1::2]
        Omega = 0.5 * h * (A1 + A2) + (np.sqrt(3.0) / 12.0) * h**2 * (A2 @ A1 - A1 @ A2)
        Phi = _tree_product(sla.expm(Omega)) @ Phi
    return Phi


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


def monodromy(M_of_t, B_of_t, C_of_t, period: float, n_steps: int = 256) -> np.ndarray:
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
        Magnus-4 steps per period (2 coefficient evaluations each); the error falls as
        n_steps⁻⁴ once the steps resolve the coefficients' variation.

    Returns
    -------
    ndarray (2n, 2n)
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
    def coefficients(t):
        return tuple(_stack(name, f, t) for name, f in
                     (("M_of_t", M_of_t), ("B_of_t", B_of_t), ("C_of_t", C_of_t)))

    shapes = {f.shape[1] for f in coefficients(np.zeros(1))}
    if len(shapes) != 1:
        raise ValueError(f"M_of_t, B_of_t and C_of_t disagree in size: {sorted(shapes)}")
    return _magnus_monodromy(coefficients, float(period), n_steps)


def floquet(Phi, period: float, tol: float = 1e-6) -> Floquet:
    """Floquet multipliers and exponents from a monodromy matrix Φ(T) (2n, 2n).

    ``tol`` is the margin of the verdict ``max|μ| <= 1 + tol``: it absorbs the integration
    error of multipliers on the unit circle (undamped, conservative systems).
    """
    Phi = np.asarray(Phi, dtype=float)
    if Phi.ndim != 2 or Phi.shape[0] != Phi.shape[1]:
        raise ValueError(f"the monodromy matrix must be square, got shape {Phi.shape}")
    mu = sla.eigvals(Phi)
    mu = mu[np.argsort(-np.abs(mu), kind="stable")]
    radius = float(np.abs(mu).max())
    with np.errstate(divide="ignore"):
        exponents = np.log(mu.astype(complex)) / period
    return Floquet(mu, radius, radius <= 1.0 + tol, exponents, Phi, float(period), tol)


def coupled_monodromy(system: CoupledSystem, Omega: float, n_steps: int = 256,
                      angle_period: float = 2 * np.pi, phi0: float = 0.0,
                      basis: np.ndarray | None = None) -> np.ndarray:
    """Monodromy matrix of a coupled machine running at constant drive speed Ω.

    The drive angle is φ = φ₀ + Ω t, so the period is T = Θ/Ω with Θ = ``angle_period``
    (2π when every mount's ratio is an integer; use the cycle angle of the machine
    otherwise). M, B, C (seed 5.2.2 eq. 9, with Ω̇ = 0) come from
    :meth:`CoupledSystem.mechanism_blocks` on the time grid and
    :func:`femmech.coupling.assemble_at`.

    Parameters
    ----------
    system : CoupledSystem
        Reduced (dense) frame, primal form.
    Omega : float
        Drive speed, rad/s, > 0.
    n_steps : int
        Magnus-4 steps per period: they must resolve the mechanism's variation over the
        cycle (cam rises, ...), not the frame's vibration periods.
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

    Returns
    -------
    ndarray (2n, 2n) or (2r, 2r)
        Φ(T) for ``z = [x; x']`` in the system's global coordinates x, or for
        ``z = [y; y']`` with a basis.

    Raises
    ------
    ValueError
        For an unreduced (sparse) frame, the multiplier form, Ω <= 0 or a bad basis.
    """
    require_dense_primal(system, "coupled_monodromy")
    if not (np.isfinite(Omega) and Omega > 0):
        raise ValueError(f"drive speed Omega must be positive, got {Omega} rad/s")
    V = None if basis is None else _checked_basis(basis, system.n)

    def coefficients(t):
        blocks = system.mechanism_blocks(phi0 + Omega * t, Omega)
        mats = [assemble_at(system, blocks, k)[:3] for k in range(t.size)]
        stacks = tuple(np.stack([m[i] for m in mats]) for i in range(3))
        return stacks if V is None else tuple(V.T @ X @ V for X in stacks)

    return _magnus_monodromy(coefficients, angle_period / Omega, n_steps)


def coupled_floquet(system: CoupledSystem, Omega: float, n_steps: int = 256,
                    angle_period: float = 2 * np.pi, tol: float = 1e-6,
                    basis: np.ndarray | None = None) -> Floquet:
    """:func:`floquet` of :func:`coupled_monodromy` (period Θ/Ω)."""
    Phi = coupled_monodromy(system, Omega, n_steps, angle_period, basis=basis)
    return floquet(Phi, angle_period / Omega, tol)


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
                    n_steps: int = 256, angle_period: float = 2 * np.pi, tol: float = 1e-6,
                    parameter_name: str = "parameter",
                    basis: np.ndarray | None = None) -> StabilityChart:
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
    n_steps, angle_period, tol
        As in :func:`coupled_monodromy` and :func:`floquet`.
    parameter_name : str
        Label of the second parameter for plots, with its unit.
    basis : ndarray (n, r), optional
        Ritz basis for coupled systems (:func:`coupled_monodromy`); the same for every
        point of the chart.

    Returns
    -------
    StabilityChart
        ``spectral_radius`` of shape (n_values, n_speeds), n_values = 1 without a second
        parameter. Unstable points (> 1 + tol) mark parametric resonances.
    """
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
    radius = np.zeros((len(rows), speeds.size))
    periods = np.zeros_like(radius)
    for i, p in enumerate(rows):
        for j, W in enumerate(speeds):
            radius[i, j], periods[i, j] = _radius(build(W, p), W, n_steps, angle_period,
                                                  basis)
    return StabilityChart(speeds, values, radius, radius <= 1.0 + tol, tol, parameter_name,
                          periods)


def _radius(model, Omega, n_steps, angle_period, basis=None) -> tuple[float, float]:
    """(spectral radius, period T in s) of one chart point."""
    if isinstance(model, CoupledSystem):
        period = angle_period / Omega
        Phi = coupled_monodromy(model, Omega, n_steps, angle_period, basis=basis)
    else:
        try:
            M_of_t, B_of_t, C_of_t, period = model
        except (TypeError, ValueError):
            raise TypeError("the callable must return a CoupledSystem or a tuple (M_of_t,"
                            f" B_of_t, C_of_t, period); got {type(model).__name__}") from None
        Phi = monodromy(M_of_t, B_of_t, C_of_t, period, n_steps)
    return float(np.abs(sla.eigvals(Phi)).max()), float(period)


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
        return text


def speed_study(system: CoupledSystem, speeds, zeta: float, band_hz: tuple[float, float],
                damping_ratios=None, n_steps: int = 128, basis_modes: int = 8,
                marked_branches: int = 2, orders=range(1, 13),
                angle_period: float = 2 * np.pi) -> SpeedStudy:
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
    n_steps, basis_modes, angle_period
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
                           basis=basis)
    chart = None
    if damping_ratios is not None:
        chart = stability_chart(lambda W, ratio: damped(ratio), speeds, damping_ratios,
                                n_steps=n_steps, angle_period=angle_period,
                                parameter_name="frame damping ratio ζ (-)", basis=basis)
    return SpeedStudy(line, chart, marks, mean_hz, basis.shape[1], float(zeta))
