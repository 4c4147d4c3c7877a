"""Stability charts and speed studies: Floquet spectral radii over drive speed.

A :class:`StabilityChart` holds the spectral radius of the monodromy matrix
(:mod:`femmech.analysis.floquet`) at every point of a grid of drive speeds and, optionally,
a second parameter (a damping ratio, a stiffness, an amplitude), with each point's
step-doubling record (:mod:`femmech.analysis.magnus`); unconverged points are marked.
:func:`speed_study` adds Rayleigh frame damping, a quasi-modal Ritz basis and the
predicted resonance speeds 2 f_k / j (:func:`resonance_speeds`) in one call.

Uses coupling, errors and analysis.floquet, .magnus, .response and
.sweep; nothing here writes files.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from femmech.analysis.floquet import (
    coupled_monodromy_record,
    monodromy_record,
    quasi_modal_basis,
)
from femmech.analysis.magnus import MAX_STEPS, RTOL
from femmech.analysis.response import rayleigh_coefficients, rayleigh_damping
from femmech.analysis.sweep import sweep
from femmech.coupling import CoupledSystem
from femmech.errors import ConvergenceWarning
from femmech.html import Flag, html_summary


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

    def _repr_html_(self) -> str:
        rho = np.asarray(self.spectral_radius)
        loose = self.unconverged
        n_unstable = int(np.sum(~np.asarray(self.stable) & ~loose))
        facts = [("speeds / (rad/s)", f"{len(self.speeds)}, {np.min(self.speeds):.4g} …"
                                      f" {np.max(self.speeds):.4g}"),
                 ("max spectral radius", float(np.nanmax(rho))),
                 ("unstable points", n_unstable)]
        if self.values is not None:
            facts.insert(1, (self.parameter_name, f"{len(self.values)} values"))
        if loose.any():
            facts.append(("not converged", Flag(f"{int(loose.sum())} points NOT CONVERGED")))
        if self.rtol is not None:
            facts.append(("tolerance (relative)", float(self.rtol)))
        return html_summary("StabilityChart", facts)

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
                    max_steps: int = MAX_STEPS, progress=None) -> StabilityChart:
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
    progress : callable, optional
        Wraps the list of chart points ``(row, speed index)`` as they are computed, e.g.
        a ``tqdm`` progress bar (:func:`femmech.scene.workshop.progress`).

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
    points = [(i, j) for i in range(len(rows)) for j in range(speeds.size)]
    for i, j in (progress or iter)(points):
        W = speeds[j]
        record, periods[i, j] = _point(build(W, rows[i]), W, n_steps, angle_period, basis,
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
        return (coupled_monodromy_record(model, Omega, n_steps, angle_period, 0.0, basis,
                                         rtol, max_steps), angle_period / Omega)
    try:
        M_of_t, B_of_t, C_of_t, period = model
    except (TypeError, ValueError):
        raise TypeError("the callable must return a CoupledSystem or a tuple (M_of_t,"
                        f" B_of_t, C_of_t, period); got {type(model).__name__}") from None
    return (monodromy_record(M_of_t, B_of_t, C_of_t, period, n_steps, rtol, max_steps),
            float(period))


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
    notes : tuple of str
        Defaults that adapted to the system (fewer basis modes or marked branches than
        :data:`BASIS_MODES` and :data:`MARKED_BRANCHES` where the system has fewer).
    """

    line: StabilityChart
    chart: StabilityChart | None
    marks: dict
    mean_freq_hz: np.ndarray
    basis_size: int
    zeta: float = float("nan")
    notes: tuple[str, ...] = ()

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
        return text + "".join(f"; {note}" for note in self.notes)


BASIS_MODES = 8
"""Quasi-modes per angle of :func:`speed_study`'s Ritz basis when not given (all n - 1
branches of a smaller system)."""

MARKED_BRANCHES = 2
"""Branches whose resonance speeds :func:`speed_study` marks when not given (all branches
of a smaller system)."""


def speed_study(system: CoupledSystem, speeds, zeta: float, band_hz: tuple[float, float],
                damping_ratios=None, n_steps: int = 32, basis_modes: int | None = None,
                marked_branches: int | None = None, orders=range(1, 13),
                angle_period: float = 2 * np.pi, rtol: float = RTOL,
                max_steps: int = MAX_STEPS, progress=None) -> SpeedStudy:
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
        As in :func:`coupled_monodromy` and :func:`quasi_modal_basis` (``basis_modes``
        None: :data:`BASIS_MODES`, at most the system's n - 1 branches).
    marked_branches : int, optional
        None: :data:`MARKED_BRANCHES`, at most the system's n - 1 branches. Adapted
        defaults are said in :attr:`SpeedStudy.notes`.
    orders : sequence of int
        Harmonic orders j of the marks.
    progress : callable, optional
        Wraps the points of the speed line and of the chart (:func:`stability_chart`).
    """
    speeds = np.atleast_1d(np.asarray(speeds, dtype=float))

    def damped(ratio):
        return rayleigh_damping(system, *rayleigh_coefficients(ratio, *band_hz))

    notes = []
    if basis_modes is None:
        basis_modes = min(BASIS_MODES, system.n - 1)
        if basis_modes < BASIS_MODES:
            notes.append(f"basis_modes not given: all {basis_modes} branches of the system"
                         f" ({system.n} coordinates; the default is {BASIS_MODES})")
    if marked_branches is None:
        marked_branches = min(MARKED_BRANCHES, system.n - 1)
        if marked_branches < MARKED_BRANCHES:
            notes.append(f"marked_branches not given: the system's only branch (the default"
                         f" is {MARKED_BRANCHES})")
    nominal = damped(zeta)
    basis = quasi_modal_basis(nominal, basis_modes, angle_period=angle_period)
    phi = np.linspace(0.0, angle_period, 36, endpoint=False)
    mean_hz = sweep(nominal, phi, n_modes=marked_branches).freq_hz.mean(axis=0)
    marks = resonance_speeds(mean_hz, orders, within=(speeds.min(), speeds.max()))
    line = stability_chart(nominal, speeds, n_steps=n_steps, angle_period=angle_period,
                           basis=basis, rtol=rtol, max_steps=max_steps, progress=progress)
    chart = None
    if damping_ratios is not None:
        chart = stability_chart(lambda W, ratio: damped(ratio), speeds, damping_ratios,
                                n_steps=n_steps, angle_period=angle_period, rtol=rtol,
                                max_steps=max_steps,
                                parameter_name="frame damping ratio ζ (-)", basis=basis,
                                progress=progress)
    return SpeedStudy(line, chart, marks, mean_hz, basis.shape[1], float(zeta), tuple(notes))


def __getattr__(name: str):
    """Names this module had before the restructures, from their new places
    (docs/architecture.md, "Moved names")."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "ATOL": "femmech.analysis.magnus.ATOL",
        "Floquet": "femmech.analysis.floquet.Floquet",
        "GAUSS_OFFSETS": "femmech.analysis.magnus.GAUSS_OFFSETS",
        "Monodromy": "femmech.analysis.magnus.Monodromy",
        "coupled_floquet": "femmech.analysis.floquet.coupled_floquet",
        "coupled_monodromy": "femmech.analysis.floquet.coupled_monodromy",
        "expm_stack": "femmech.analysis.magnus.expm_stack",
        "first_order_matrices": "femmech.analysis.magnus.first_order_matrices",
        "floquet": "femmech.analysis.floquet.floquet",
        "integrate_monodromy": "femmech.analysis.magnus.integrate_monodromy",
        "monodromy": "femmech.analysis.floquet.monodromy",
        "step_grid": "femmech.analysis.magnus.step_grid",
    })
