"""Synthesis of a chain: keep its quasi-eigenfrequencies out of the drive harmonics.

The drive runs at speeds n in [n_lo, n_hi] (rpm); its harmonics k·n/60 (Hz, k = 1 … K)
sweep the *harmonic bands* ``[k n_lo/60, k n_hi/60]``. The frozen chain (Ω = 0,
``C(φ) v = ω² M(φ) v``) has quasi-eigenfrequencies f_i(φ) that change with the drive
angle φ. A design is safe if every f_i(φ), at every angle and for every k, stays out of
each band widened by a relative margin m: ``f <= (1 - m) k n_lo/60`` or
``f >= (1 + m) k n_hi/60``.

Signed relative distance of a frequency f to band k (:func:`band_distance`)::

    d_k(f) = max(1 - f / (k n_lo/60), f / (k n_hi/60) - 1)

(negative inside the band, 0 on its edges, ``>= m`` outside the widened band). The
*resonance margin* of a design (:func:`resonance_margin`) is the smallest d over the
branches, the sampled angles of one revolution and the harmonics; it is the quantity
synthesis drives to ``>= m``.

The minimum is not smooth; the optimiser sees its Kreisselmeier–Steinhauser (KS) bound
with the inner ``max`` smoothed the same way (:func:`ks_margin`)::

    KS = -(1/ρ) ln Σ_j 1 / (exp(ρ a_j) + exp(ρ b_j)),   a_j = 1 - f/lo_k, b_j = f/hi_k - 1

over all terms j = (angle, branch, harmonic); ``min d - ln(n_terms)/ρ <= KS <=
min d + ln(2)/ρ`` (the ln 2 only inside a band). Its gradient needs df/dp, from the
Fox–Kapoor formula ``dλ/dp = vᵀ (dC/dp - λ dM/dp) v`` (M-normalised v, λ = ω²) with
central differences of the assembled matrices of ``build(p ± h)`` (no extra eigen
solves), as :func:`femmech.analysis.sweep.frequency_sensitivities`. A cluster of
repeated eigenvalues has no unique per-mode derivative, but the KS sum over the cluster
is a symmetric (spectral) function of its eigenvalues: its derivative is
``g'(λ) trace(V_cᵀ (dC - λ dM) V_c)``, which the per-mode formula summed over any
M-orthonormal basis V_c of the cluster gives exactly; so the aggregate's gradient is
well defined although the single branches' are not.

:func:`synthesise` searches the continuous parameters (normalised to [0, 1]) from a
multistart (the initial design plus a Latin hypercube) and enumerates integer or
categorical ones (cam law choice) in an outer loop. Per start it maximises KS
(L-BFGS-B, bounds: minimises the resonance measure ``-margin``); if that meets the
margin it then moves to the design closest to the initial one with ``KS >= m`` (SLSQP
from that feasible point).

Stage 6 (chain): uses chain.model (duck-typed), scipy.optimize and scipy.stats.qmc.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize
from scipy.special import logsumexp
from scipy.stats import qmc

from femmech.analysis import tracking
from femmech.solve import dense, threads, tolerances

DEFAULT_ANGLES = 72
"""Drive angles sampled over one revolution (every 5°) when none are given."""

KS_RHO = 200.0
"""Sharpness ρ of the KS aggregate, per unit relative distance: terms 1/ρ = 0.5 % farther
from a band than the closest one weigh e⁻¹ as much."""

CLUSTER_RTOL = tracking.CLUSTER_RTOL
"""Frequencies this close (relative) to the last one kept by ``n_modes`` are kept too,
so a cluster of repeated eigenvalues is never cut (its aggregate is smooth only whole);
the cluster width of mode tracking (:data:`femmech.analysis.tracking.CLUSTER_RTOL`)."""

FD_STEP = 1e-6
"""Step in the normalised parameter (range [0, 1]) of the matrix differences."""


@dataclass(frozen=True)
class Parameter:
    """A design variable of :func:`synthesise`.

    Parameters
    ----------
    name : str
        Key of the value in the dict given to ``build``.
    lower, upper : float
        Bounds, in the parameter's SI unit (``lower < upper``; equal bounds fix it).
    start : float or object, optional
        Initial design value (default: the middle of the bounds, geometric if ``log``;
        the first choice for a categorical parameter).
    integer : bool
        The value is an integer in lower … upper; such parameters are enumerated.
    log : bool
        Searched on a log scale (``lower > 0``): stiffnesses, inertias spanning decades.
    choices : tuple, optional
        Categorical values (e.g. cam law names); made with :meth:`choice`. ``build``
        receives the chosen item itself.
    """

    name: str
    lower: float = 0.0
    upper: float = 1.0
    start: object = None
    integer: bool = False
    log: bool = False
    choices: tuple | None = None

    def __post_init__(self):
        if self.choices is not None:
            if len(self.choices) < 1:
                raise ValueError(f"parameter {self.name!r}: choices must not be empty")
            object.__setattr__(self, "choices", tuple(self.choices))
            return
        lo, hi = float(self.lower), float(self.upper)
        if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi):
            raise ValueError(f"parameter {self.name!r}: need finite lower <= upper, got"
                             f" {self.lower!r}, {self.upper!r}")
        if self.log and lo <= 0:
            raise ValueError(f"parameter {self.name!r}: log scale needs lower > 0")
        if self.start is not None and not lo <= float(self.start) <= hi:
            raise ValueError(f"parameter {self.name!r}: start {self.start!r} is outside"
                             f" [{lo:g}, {hi:g}]")

    @classmethod
    def choice(cls, name: str, options, start=None) -> Parameter:
        """A categorical parameter: ``build`` gets one of ``options`` (enumerated)."""
        options = tuple(options)
        if start is not None and start not in options:
            raise ValueError(f"parameter {name!r}: start {start!r} is not a choice")
        return cls(name, 0, len(options) - 1, start, True, False, options)

    @property
    def discrete(self) -> bool:
        """True for integer, categorical and fixed (lower == upper) parameters: they are
        enumerated, not searched."""
        return self.integer or self.choices is not None or self.lower == self.upper

    def options(self) -> list:
        """The values a discrete parameter takes."""
        if self.choices is not None:
            return list(self.choices)
        if not self.integer:
            return [float(self.lower)]
        return list(range(int(np.ceil(self.lower)), int(np.floor(self.upper)) + 1))

    def initial(self):
        """The initial design value."""
        if self.start is not None:
            return self.start
        if self.discrete:
            return self.options()[0]
        return self.value(0.5)

    def value(self, x: float) -> float:
        """Parameter value (SI) at the normalised coordinate x in [0, 1]."""
        if self.log:
            return float(self.lower * (self.upper / self.lower) ** x)
        return float(self.lower + x * (self.upper - self.lower))

    def normalised(self, value: float) -> float:
        """The normalised coordinate of a value (0 for fixed parameters)."""
        if self.upper == self.lower:
            return 0.0
        if self.log:
            return float(np.log(value / self.lower) / np.log(self.upper / self.lower))
        return float((value - self.lower) / (self.upper - self.lower))


@dataclass(frozen=True)
class Margin:
    """Resonance margin of one design (:func:`resonance_margin`).

    Attributes
    ----------
    value : float
        Smallest signed relative distance d (see the module docstring) of any branch, at
        any sampled angle, to any harmonic band; < 0: some frequency lies inside a band.
    branch : int
        Critical branch, 0-based (branch i = the (i+1)-th lowest frequency at each angle).
    harmonic : int
        Critical harmonic order k.
    angle : float
        Critical drive angle, rad.
    frequency_hz : float
        The critical branch's frequency there, Hz.
    band_hz : tuple of float
        The critical harmonic band (k n_lo/60, k n_hi/60), Hz.
    per_branch : ndarray (n_branches,)
        Smallest d of each branch over the angles and harmonics.
    """

    value: float
    branch: int
    harmonic: int
    angle: float
    frequency_hz: float
    band_hz: tuple
    per_branch: np.ndarray

    @property
    def side(self) -> str:
        """Where the critical frequency lies: "below", "above" or "inside" its band."""
        lo, hi = self.band_hz
        return "below" if self.frequency_hz < lo else (
            "above" if self.frequency_hz > hi else "inside")

    def __repr__(self) -> str:
        return (f"Margin({self.value:+.4f}: f{self.branch + 1} = {self.frequency_hz:.4g} Hz"
                f" at φ = {np.rad2deg(self.angle):.1f}° {self.side} band k = {self.harmonic}"
                f" [{self.band_hz[0]:.4g}, {self.band_hz[1]:.4g}] Hz)")


@dataclass(frozen=True)
class FrequencyBands:
    """Quasi-eigenfrequencies of one design over the revolution.

    ``phi`` (n_angles,) rad; ``freq_hz`` (n_angles, n_branches) Hz, ascending per angle
    (branch i = i-th lowest; continuous in φ, not MAC-tracked). :attr:`low`, :attr:`high`,
    :attr:`mean` (n_branches,): the band of each branch over the revolution, Hz.
    """

    phi: np.ndarray
    freq_hz: np.ndarray

    @property
    def low(self) -> np.ndarray:
        return self.freq_hz.min(axis=0)

    @property
    def high(self) -> np.ndarray:
        return self.freq_hz.max(axis=0)

    @property
    def mean(self) -> np.ndarray:
        return self.freq_hz.mean(axis=0)


@dataclass(frozen=True)
class StartReport:
    """One start of the multistart: where it began, where it ended, whether it converged.

    ``stage``: "max_margin" (L-BFGS-B on -KS from the start), "closest" (then SLSQP:
    least change with KS >= margin from the feasible max-margin point, ρ sharpened
    twice) or "fixed" (no continuous parameter: the design is only evaluated).
    ``converged``: the success flag of the optimiser that produced ``values``;
    ``message``: all optimisers' messages; ``distance``: normalised Euclidean distance of
    the continuous parameters from the initial design plus 1 per changed discrete one.
    """

    start: dict
    values: dict
    margin: float
    distance: float
    feasible: bool
    converged: bool
    stage: str
    message: str
    iterations: int
    evaluations: int


@dataclass(frozen=True)
class SynthesisResult:
    """Outcome of :func:`synthesise`.

    Attributes
    ----------
    before, after : dict
        Parameter values of the initial and of the chosen design.
    chain_before, chain_after : Chain
        ``build(before)``, ``build(after)``.
    margin_before, margin_after : Margin
        Resonance margins on the optimisation's angle grid.
    margin_check : Margin
        The chosen design's margin on a 4× finer angle grid (the min between samples).
    bands_before, bands_after : FrequencyBands
        Quasi-eigenfrequencies of both designs over the revolution (all branches).
    required : float
        The requested margin m.
    feasible : bool
        ``margin_after.value >= required``. False: no start met the margin; ``after`` is
        the design with the largest margin found (the resonance measure minimised).
    starts : tuple of StartReport
        Every start (per combination of discrete values), in the order run.
    evaluations : int
        Designs whose frequencies were computed over the revolution (eigen solves).
    builds : int
        Calls of ``build`` (evaluations plus the matrix differences of the gradients).
    seconds : float
        Wall time.
    """

    before: dict
    after: dict
    chain_before: object
    chain_after: object
    margin_before: Margin
    margin_after: Margin
    margin_check: Margin
    bands_before: FrequencyBands
    bands_after: FrequencyBands
    speed_rpm: tuple
    harmonics: int
    required: float
    feasible: bool
    starts: tuple
    evaluations: int
    builds: int
    seconds: float

    @property
    def not_converged(self) -> list[int]:
        """Indices of the starts whose optimiser did not report success."""
        return [i for i, s in enumerate(self.starts) if not s.converged]

    def summary(self) -> str:
        """A few lines: verdict, margins before/after, values, cost, unconverged starts."""
        verdict = ("meets" if self.feasible else "CANNOT meet (best found shown)")
        lines = [f"synthesis {verdict} the margin {self.required:.3g} over"
                 f" {self.speed_rpm[0]:g}-{self.speed_rpm[1]:g} rpm, k = 1..{self.harmonics}",
                 f"  before: {self.margin_before!r}", f"  after:  {self.margin_after!r}",
                 f"  after, 4x finer angles: {self.margin_check.value:+.4f}"]
        for name in self.before:
            lines.append(f"  {name}: {self.before[name]!r} -> {self.after[name]!r}")
        bad = self.not_converged
        lines.append(f"  {len(self.starts)} starts ({len(bad)} not converged: {bad}),"
                     f" {self.evaluations} evaluations, {self.builds} builds,"
                     f" {self.seconds:.2f} s")
        return "\n".join(lines)

    def __repr__(self) -> str:
        return (f"SynthesisResult({'feasible' if self.feasible else 'infeasible'}, margin"
                f" {self.margin_before.value:+.4f} -> {self.margin_after.value:+.4f}"
                f" (required {self.required:g}), {self.evaluations} evaluations)")


# --- frequencies of the frozen chain ---------------------------------------------------

def harmonic_bands(speed_rpm, harmonics: int) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper edges (Hz) of the harmonic bands k = 1 … K: k·n_lo/60, k·n_hi/60."""
    lo_rpm, hi_rpm = _speed_range(speed_rpm)
    if int(harmonics) != harmonics or harmonics < 1:
        raise ValueError(f"harmonics must be a positive integer K, got {harmonics!r}")
    k = np.arange(1, int(harmonics) + 1, dtype=float)
    return k * lo_rpm / 60.0, k * hi_rpm / 60.0


def _speed_range(speed_rpm) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in speed_rpm)
    except (TypeError, ValueError):
        raise ValueError(f"speed_rpm must be a pair (n_lo, n_hi) in rpm, got {speed_rpm!r}"
                         ) from None
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo <= hi):
        raise ValueError(f"speed_rpm must satisfy 0 < n_lo <= n_hi, got ({lo:g}, {hi:g})")
    return lo, hi


def band_distance(freq_hz, lo_hz, hi_hz) -> np.ndarray:
    """Signed relative distance ``max(1 - f/lo, f/hi - 1)`` of frequencies to bands.

    ``freq_hz`` any shape S, ``lo_hz``, ``hi_hz`` (K,) → S + (K,). Negative inside a
    band, ``>= m`` outside the band widened to ``[(1 - m) lo, (1 + m) hi]``.
    """
    f = np.asarray(freq_hz, dtype=float)[..., None]
    return np.maximum(1.0 - f / lo_hz, f / hi_hz - 1.0)


def frozen_eigen(M, C, phi=None) -> tuple[np.ndarray, np.ndarray]:
    """All eigenpairs of ``C v = λ M v`` at each angle (batched, dense).

    M (n_angles, n, n) symmetric positive definite, C symmetric (within
    :data:`femmech.solve.tolerances.SYMMETRY_RTOL`). Returns λ (n_angles, n) ascending
    (λ = ω², rad²/s²) and V (n_angles, n, n), M-normalised columns: a thin call of
    :func:`femmech.solve.dense.symmetric_pencil` (``driver="standard"``).
    """
    asym = np.abs(C - np.swapaxes(C, 1, 2)).max(axis=(1, 2))
    bad = asym > tolerances.SYMMETRY_RTOL * np.abs(C).max(axis=(1, 2))
    if bad.any():
        raise ValueError(f"C(φ) is not symmetric at {_where(phi, bad)}: synthesis uses the"
                         " frozen problem with Omega = 0 and symmetric loads")
    try:
        return dense.symmetric_pencil(C, M, driver="standard")
    except np.linalg.LinAlgError:
        ok = np.array([np.all(np.linalg.eigvalsh(m) > 0) for m in M])
        if ok.all():
            raise
        raise ValueError(f"M(φ) is not positive definite at {_where(phi, ~ok)} (a"
                         " coordinate without mass?)") from None


def _where(phi, mask) -> str:
    a = int(np.flatnonzero(mask)[0])
    if phi is None:
        return f"angle index {a}"
    return f"φ = {np.rad2deg(np.atleast_1d(phi)[a]):.6g}° ({int(mask.sum())} angles)"


def _frequencies(lam) -> np.ndarray:
    return np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi)


def _kept(freq, n_modes) -> np.ndarray:
    """(n_angles, n) bool: the n_modes lowest per angle plus the rest of a cut cluster."""
    keep = np.ones(freq.shape, bool)
    if n_modes is None or n_modes >= freq.shape[1]:
        return keep
    if int(n_modes) != n_modes or n_modes < 1:
        raise ValueError(f"n_modes must be a positive integer or None, got {n_modes!r}")
    last = freq[:, int(n_modes) - 1:int(n_modes)]
    keep[:, int(n_modes):] = freq[:, int(n_modes):] <= last * (1 + CLUSTER_RTOL)
    return keep


def _angles(phi, n_angles) -> np.ndarray:
    if phi is None:
        return np.linspace(0.0, 2 * np.pi, int(n_angles), endpoint=False)
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    if phi.ndim != 1 or phi.size < 1 or not np.all(np.isfinite(phi)):
        raise ValueError("phi must be a 1-D array of finite drive angles (rad)")
    return phi


def frequency_bands(chain, phi=None, n_angles: int = DEFAULT_ANGLES) -> FrequencyBands:
    """All quasi-eigenfrequencies of the frozen chain over the revolution (Hz)."""
    phi = _angles(phi, n_angles)
    with threads.solve_phase():
        lam, _ = frozen_eigen(chain.M(phi), chain.C(phi), phi)
    return FrequencyBands(phi, _frequencies(lam))


def _distances(freq, lo, hi, keep) -> np.ndarray:
    """:func:`band_distance` of the kept branches (``keep``: bool, shape of ``freq``),
    ``inf`` for the others: S + (K,)."""
    return np.where(keep[..., None], band_distance(freq, lo, hi), np.inf)


def margin_of(bands: FrequencyBands, speed_rpm, harmonics: int, n_modes=None) -> Margin:
    """:class:`Margin` of given frequency bands (see :func:`resonance_margin`)."""
    lo, hi = harmonic_bands(speed_rpm, harmonics)
    freq = np.asarray(bands.freq_hz)
    d = _distances(freq, lo, hi, _kept(freq, n_modes))
    a, i, k = np.unravel_index(int(np.argmin(d)), d.shape)
    per_branch = d.min(axis=(0, 2))
    return Margin(float(d[a, i, k]), int(i), int(k) + 1, float(bands.phi[a]),
                  float(freq[a, i]), (float(lo[k]), float(hi[k])),
                  per_branch[np.isfinite(per_branch)])


def resonance_margin(chain, speed_rpm, harmonics: int, n_modes: int | None = None,
                     phi=None, n_angles: int = DEFAULT_ANGLES) -> Margin:
    """Signed relative distance of a chain's quasi-eigenfrequencies to the harmonic bands.

    Parameters
    ----------
    chain : Chain
    speed_rpm : (float, float)
        Speed range (n_lo, n_hi), rpm, 0 < n_lo <= n_hi.
    harmonics : int
        Highest harmonic order K (bands k = 1 … K).
    n_modes : int, optional
        Only the n_modes lowest branches (plus the rest of a cluster they cut); default all.
    phi : array_like (n_angles,), optional
        Drive angles, rad; default ``n_angles`` equally spaced over one revolution.

    Returns
    -------
    Margin
        ``value >= m`` means every sampled frequency keeps the relative margin m.
    """
    return margin_of(frequency_bands(chain, phi, n_angles), speed_rpm, harmonics, n_modes)


def ks_margin(freq_hz, lo_hz, hi_hz, rho: float = KS_RHO, keep=None):
    """Smooth lower bound of the margin (KS) and its derivative with respect to each f.

    ``KS = -(1/ρ) ln Σ 1/(exp(ρ a) + exp(ρ b))`` over all kept (angle, branch) and bands
    k, with ``a = 1 - f/lo_k``, ``b = f/hi_k - 1`` (module docstring). freq_hz
    (n_angles, n) Hz; returns KS and dKS/df (n_angles, n), 1/Hz (0 where not kept).
    """
    f = np.asarray(freq_hz, dtype=float)[..., None]
    a, b = 1.0 - f / lo_hz, f / hi_hz - 1.0
    s = -np.logaddexp(rho * a, rho * b)  # -ρ·smoothmax(a, b)
    if keep is not None:
        s = np.where(np.asarray(keep)[..., None], s, -np.inf)
    total = logsumexp(s)
    w = np.exp(s - total)  # weight of each term (softmin)
    sa, sb = np.exp(rho * a + s), np.exp(rho * b + s)  # σ of the smooth max
    dks = np.sum(w * (-sa / lo_hz + sb / hi_hz), axis=-1)
    return float(-total / rho), dks


# --- the optimisation problem ----------------------------------------------------------

@dataclass
class _Problem:
    """One combination of discrete values: the margin and its gradient as functions of
    the normalised continuous parameters x (memoised: fun and jac share one solve)."""

    build: object
    continuous: list
    fixed: dict
    phi: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    n_modes: int | None
    rho: float
    counts: dict
    _memo: dict = field(default_factory=dict)

    def values(self, x) -> dict:
        out = dict(self.fixed)
        out.update({p.name: p.value(float(v)) for p, v in zip(self.continuous, x,
                                                              strict=True)})
        return out

    def matrices(self, x):
        self.counts["builds"] += 1
        chain = self.build(self.values(x))
        return chain.M(self.phi), chain.C(self.phi)

    def evaluate(self, x):
        """(KS, dKS/dx, true margin) at x."""
        key = (self.rho, *np.round(np.asarray(x, dtype=float), 15))
        if key in self._memo:
            return self._memo[key]
        M, C = self.matrices(x)
        self.counts["evaluations"] += 1
        lam, V = frozen_eigen(M, C, self.phi)
        freq = _frequencies(lam)
        keep = _kept(freq, self.n_modes)
        ks, dks_df = ks_margin(freq, self.lo, self.hi, self.rho, keep)
        margin = float(_distances(freq, self.lo, self.hi, keep).min())
        safe = freq > 1e-9 * max(float(freq.max()), 1e-300)  # rigid-body modes: no df/dλ
        g = np.where(safe, dks_df / (8 * np.pi**2 * np.where(safe, freq, 1.0)), 0.0)
        grad = np.array([self._directional(x, j, lam, V, g)
                         for j in range(len(self.continuous))])
        self._memo = {key: (ks, grad, margin)}
        return ks, grad, margin

    def margin(self, x) -> float:
        """The true margin at x alone (one build and eigen solve, no gradient)."""
        M, C = self.matrices(x)
        self.counts["evaluations"] += 1
        freq = _frequencies(np.linalg.eigvalsh(dense.standard_form(M, C)))
        return float(_distances(freq, self.lo, self.hi, _kept(freq, self.n_modes)).min())

    def _directional(self, x, j, lam, V, g) -> float:
        """dKS/dx_j = Σ g vᵀ (dC - λ dM) v, matrices differenced in x_j (central inside
        [0, 1], one-sided at a bound: the parameter never leaves its bounds)."""
        up, down = np.array(x, dtype=float), np.array(x, dtype=float)
        up[j] = min(up[j] + FD_STEP, 1.0)
        down[j] = max(down[j] - FD_STEP, 0.0)
        Mp, Cp = self.matrices(up)
        Mm, Cm = self.matrices(down)
        h = up[j] - down[j]
        dM, dC = (Mp - Mm) / h, (Cp - Cm) / h
        dlam = np.sum(V * (dC @ V - lam[:, None, :] * (dM @ V)), axis=1)  # (angles, modes)
        return float(np.sum(g * dlam))


def _closest(problem: _Problem, x_start, x0, margin: float):
    """SLSQP: least change ½|x - x0|² subject to KS(x) >= margin, 0 <= x <= 1."""
    cons = {"type": "ineq", "fun": lambda x: problem.evaluate(x)[0] - margin,
            "jac": lambda x: problem.evaluate(x)[1][None, :]}
    return minimize(lambda x: 0.5 * np.sum((x - x0) ** 2), x_start, jac=lambda x: x - x0,
                    method="SLSQP", bounds=[(0.0, 1.0)] * len(x0), constraints=[cons],
                    options={"maxiter": 100, "ftol": 1e-10})


def _max_margin(problem: _Problem, x_start):
    """L-BFGS-B: maximise KS(x) (minimise the resonance measure -KS), 0 <= x <= 1."""
    def fun(x):
        ks, grad, _ = problem.evaluate(x)
        return -ks, -grad
    return minimize(fun, x_start, jac=True, method="L-BFGS-B",
                    bounds=[(0.0, 1.0)] * len(x_start),
                    options={"maxiter": 200, "ftol": 1e-12, "gtol": 1e-9})


def _run_start(problem, x_start, x0, margin, method, discrete_change) -> StartReport:
    """One start: the largest margin from x_start (L-BFGS-B); then, for "closest" and if
    that met the margin, the least change from x0 (:func:`_nearest`)."""
    counted = problem.counts["evaluations"]
    run = _max_margin(problem, x_start)
    x = np.clip(run.x, 0.0, 1.0)
    true, stage, converged = problem.evaluate(x)[2], "max_margin", bool(run.success)
    message, nit = str(run.message), int(run.nit)
    if method == "closest" and true >= margin:
        x, true, ok, note, steps = _nearest(problem, x, x0, margin)
        stage, converged = "closest", converged and ok
        message, nit = f"{message}; then {note}", nit + steps
    return StartReport(problem.values(x_start), problem.values(x), true,
                       float(np.linalg.norm(x - x0)) + discrete_change, true >= margin,
                       converged, stage, message, nit,
                       problem.counts["evaluations"] - counted)


def _nearest(problem, x, x0, margin):
    """SLSQP from the feasible x towards x0 with KS >= margin, for ρ, 4ρ, 16ρ in turn,
    each from the last design that met the margin: a sharper KS is a tighter bound, so
    the design ends closer to the required margin (and a run whose line search failed
    gets another chance). Returns (x, margin, success, message, iterations): x always
    meets the margin; success is that of the run that produced it (True if none did)."""
    true, ok, notes, steps, rho = problem.evaluate(x)[2], True, [], 0, problem.rho
    try:
        for factor in (1.0, 4.0, 16.0):
            problem.rho = rho * factor
            run = _closest(problem, x, x0, margin)
            xc = np.clip(run.x, 0.0, 1.0)
            true_c = problem.evaluate(xc)[2]
            steps += int(run.nit)
            notes.append(f"SLSQP ρ={problem.rho:g}: {run.message}")
            better = np.linalg.norm(xc - x0) <= np.linalg.norm(x - x0)
            if true_c >= margin and better:
                x, true, ok = xc, true_c, bool(run.success)
            else:
                notes[-1] += " (not kept: below the margin or farther)"
    finally:
        problem.rho = rho
    return x, true, ok, "; ".join(notes), steps


def _starts(n_continuous: int, x0, starts: int, seed) -> np.ndarray:
    """The initial design, then a Latin hypercube of starts - 1 points in [0, 1]^d
    (screened by :func:`_screened_starts`)."""
    if int(starts) != starts or starts < 1:
        raise ValueError(f"starts must be a positive integer, got {starts!r}")
    if starts == 1:
        return x0[None]
    lhs = qmc.LatinHypercube(d=n_continuous, seed=seed).random(int(starts) - 1)
    return np.vstack([x0[None], lhs])


def margin_sensitivities(build, parameters, values: dict, speed_rpm, harmonics: int,
                         n_modes: int | None = None, n_angles: int = DEFAULT_ANGLES,
                         rho: float = KS_RHO) -> tuple[float, dict, float]:
    """The KS margin of a design, its derivatives and the true margin (what synthesis sees).

    ``values``: the design (as given to ``build``); derivatives are taken with respect to
    the continuous ``parameters`` (Fox–Kapoor with differenced matrices, module
    docstring). Returns ``(KS, {name: dKS/dp in 1/unit of p}, margin)``.
    """
    parameters = _check_parameters(parameters)
    continuous = [p for p in parameters if not p.discrete]
    fixed = {k: v for k, v in values.items() if k not in {p.name for p in continuous}}
    lo, hi = harmonic_bands(speed_rpm, harmonics)
    problem = _Problem(build, continuous, fixed, _angles(None, n_angles), lo, hi, n_modes,
                       rho, {"evaluations": 0, "builds": 0})
    x = np.array([p.normalised(values[p.name]) for p in continuous])
    ks, grad, margin = problem.evaluate(x)
    dx_dp = [(np.log(p.upper / p.lower) * values[p.name]) ** -1 if p.log
             else 1.0 / (p.upper - p.lower) for p in continuous]
    return ks, {p.name: float(g * d) for p, g, d in zip(continuous, grad, dx_dp,
                                                         strict=True)}, margin


def _check_parameters(parameters) -> list:
    parameters = list(parameters)
    names = [p.name for p in parameters]
    if not parameters:
        raise ValueError("synthesise needs at least one Parameter")
    if len(set(names)) != len(names):
        raise ValueError(f"parameter names must be unique, got {names}")
    return parameters


def synthesise(build, parameters, speed_rpm, harmonics: int, margin: float = 0.05,
               n_modes: int | None = None, n_angles: int = DEFAULT_ANGLES, starts: int = 8,
               seed=0, method: str = "closest", rho: float = KS_RHO) -> SynthesisResult:
    """Choose design parameters so that no quasi-eigenfrequency meets a drive harmonic.

    Parameters
    ----------
    build : callable
        ``build(values: dict) -> Chain``: the user's model from parameter values (SI),
        keyed by :attr:`Parameter.name`.
    parameters : sequence of Parameter
        Design variables with bounds; discrete ones (integer, :meth:`Parameter.choice`)
        are enumerated (all combinations: keep them few).
    speed_rpm : (float, float)
        Speed range (n_lo, n_hi), rpm.
    harmonics : int
        Highest drive harmonic K (k = 1 … K).
    margin : float
        Required relative margin m (0.05: 5 % below/above each harmonic band).
    n_modes : int, optional
        Branches considered (lowest, plus the rest of a cluster they cut); default all.
    n_angles : int
        Drive angles over one revolution (equally spaced).
    starts : int
        Starts per combination of discrete values: the initial design, then a Latin
        hypercube (``scipy.stats.qmc``, ``seed``).
    method : {"closest", "max_margin"}
        "max_margin": the largest margin within the bounds (L-BFGS-B from each start);
        "closest": then, from each start's feasible result, the design nearest the
        initial one (normalised parameters) with KS >= margin (SLSQP).
    rho : float
        KS sharpness (:data:`KS_RHO`).

    Returns
    -------
    SynthesisResult
        Feasible designs are preferred, then the smallest change ("closest") or the
        largest margin; ``feasible`` False says that no start met the margin.
    """
    with threads.solve_phase():  # many small dense solves: fastest on one BLAS thread
        return _synthesise(build, parameters, speed_rpm, harmonics, margin, n_modes,
                           n_angles, starts, seed, method, rho)


def _synthesise(build, parameters, speed_rpm, harmonics: int, margin: float = 0.05,
               n_modes: int | None = None, n_angles: int = DEFAULT_ANGLES, starts: int = 8,
               seed=0, method: str = "closest", rho: float = KS_RHO) -> SynthesisResult:
    """:func:`synthesise` inside the solve phase."""
    t0 = time.perf_counter()
    parameters = _check_parameters(parameters)
    if method not in ("closest", "max_margin"):
        raise ValueError(f"method must be 'closest' or 'max_margin', got {method!r}")
    if not (np.isfinite(margin) and 0 <= margin < 1):
        raise ValueError(f"margin must lie in [0, 1), got {margin!r}")
    lo, hi = harmonic_bands(speed_rpm, harmonics)
    phi = _angles(None, n_angles)
    continuous = [p for p in parameters if not p.discrete]
    discrete = [p for p in parameters if p.discrete]
    before = {p.name: p.initial() for p in parameters}
    x0 = np.array([p.normalised(before[p.name]) for p in continuous])
    counts = {"evaluations": 0, "builds": 0}
    reports = []
    for combo in itertools.product(*(p.options() for p in discrete)):
        fixed = dict(zip((p.name for p in discrete), combo, strict=True))
        change = sum(fixed[p.name] != before[p.name] for p in discrete)
        problem = _Problem(build, continuous, fixed, phi, lo, hi, n_modes, rho, counts)
        reports += _combination(problem, x0, margin, method, change, starts, seed)
    best = _best(reports, method, margin)
    return _result(build, parameters, before, best, reports, phi, speed_rpm, harmonics,
                   margin, n_modes, counts, t0)


def _combination(problem, x0, margin, method, change, starts, seed) -> list:
    """Start reports of one combination of discrete values."""
    if not problem.continuous:
        true = problem.evaluate(np.zeros(0))[2]
        values = problem.values(np.zeros(0))
        return [StartReport(values, values, true, float(change), true >= margin, True,
                            "fixed", "evaluated (no continuous parameter)", 0, 1)]
    return [_run_start(problem, x_start, x0, margin, method, change)
            for x_start in _screened_starts(problem, x0, starts, seed)]


SCREEN_PER_START = 8
"""Designs screened (margin only, no gradient) per Latin-hypercube start: the local runs
start from the best of them, so a few starts find the feasible region of a multimodal
margin (the knitting example: 2 starts, where 3 unscreened ones were needed)."""


def _screened_starts(problem, x0, starts: int, seed) -> np.ndarray:
    """The initial design, then the starts - 1 best (largest margin) of a Latin hypercube
    of SCREEN_PER_START · (starts - 1) designs."""
    candidates = _starts(len(x0), x0, SCREEN_PER_START * (int(starts) - 1) + 1, seed) \
        if int(starts) == starts and starts > 1 else _starts(len(x0), x0, starts, seed)
    if len(candidates) == 1:
        return candidates
    scores = np.array([problem.margin(x) for x in candidates[1:]])
    best = np.argsort(-scores, kind="stable")[: int(starts) - 1]
    return np.vstack([x0[None], candidates[1:][best]])


def _best(reports, method, margin) -> StartReport:
    feasible = [r for r in reports if r.feasible]
    if feasible and method == "closest":
        return min(feasible, key=lambda r: (r.distance, -r.margin))
    return max(reports, key=lambda r: r.margin)


def _result(build, parameters, before, best, reports, phi, speed_rpm, harmonics, margin,
            n_modes, counts, t0) -> SynthesisResult:
    chains = build(before), build(best.values)
    counts["builds"] += 2
    bands = [frequency_bands(c, phi) for c in chains]
    margins = [margin_of(b, speed_rpm, harmonics, n_modes) for b in bands]
    fine = np.linspace(0.0, 2 * np.pi, 4 * phi.size, endpoint=False)
    check = margin_of(frequency_bands(chains[1], fine), speed_rpm, harmonics, n_modes)
    counts["evaluations"] += 3
    return SynthesisResult(dict(before), dict(best.values), chains[0], chains[1],
                           margins[0], margins[1], check, bands[0], bands[1],
                           tuple(float(v) for v in speed_rpm), int(harmonics),
                           float(margin), margins[1].value >= margin, tuple(reports),
                           counts["evaluations"], counts["builds"],
                           time.perf_counter() - t0)
