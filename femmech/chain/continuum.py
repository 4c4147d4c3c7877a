"""The smeared continuum of seed 5.1: shaft plus mechanisms as one torsional continuum.

The chain's cells (spacing ``a``, m) are smeared along the shaft: torsional stiffness
``GJ = k a`` (N m²/rad), rotary inertia ``J / a`` per length (kg m), and the units'
matrices per length ``M̄(φ)/a``, ``C̄(φ)/a`` with, for phased units, the mean over the
units at the drive angle (the chapter's smearing of kinematic and inertial properties):

    M̄(φ) = (1/N) Σ_u M_u(φ + δ_u),    C̄(φ) = (1/N) Σ_u C_u(φ + δ_u).

Every cross-section carries the node rotation θ(x, t) (the unit coordinate ``attach``) and
the units' internal coordinates q(x, t); per unit length

    (M̄ + J e_a e_aᵀ)/a · ẍ + C̄/a · x − GJ θ'' e_a = 0,    x = (θ, q).

With θ = Θ(x) w_a, q = Θ(x) w_q and Θ'' = −β² Θ (β = μ/a, rad/m) this is the small
problem of :mod:`.cyclic` with the shaft term ``k a² β² = k μ²``:

    (C̄ + k μ_j² e_a e_aᵀ) w = λ (M̄ + J e_a e_aᵀ) w.

The discrete chain has ``2k(1 − cos μ) = k μ² − k μ⁴/12 + …`` instead: the continuum is its
long-wave limit, stiffer by the relative ``μ²/12`` in κ, so a shaft-like mode is
``≈ μ²/24`` too high in frequency (first order: ``δf/f = w_a² k μ⁴ / (24 λ)``).

End conditions (``ends``):

* ``"cell"`` (default): the chain's own end equation applied to the smooth field,
  ``GJ [Θ(x₀) − Θ(x₀ − a)]/a = k_g Θ(x₀)`` at the end node x₀ (a ground spring ``k_g`` on
  the end node, as in the chain): a difference form of ``GJ Θ' = k_g Θ``. With
  ``Θ = cos(μ s − α)`` (s the node index) it reads ``tan α_L = (g − 1 + cos μ)/sin μ``,
  ``g = k_g/k``, and the modes are the roots of ``μ(N − 1) − α_L − α_R = lπ`` (monotone
  for g ≤ 2; a bracketed root finder per mode). Free (g = 0: ``Θ' = 0`` half a spacing
  beyond the end node) and g = 1 (a clamp one spacing beyond) give the closed forms of
  :func:`~femmech.chain.cyclic.wave_numbers`: the continuum's wave numbers are then *exactly*
  the chain's and its error is the dispersion error alone. g > 2 adds a mode localised
  at that end that no long-wave model has: refused (use ``"shaft"``).
* ``"shaft"``: the pointwise condition ``GJ Θ' = ±k_g Θ`` at the shaft ends x = 0 and
  x = N a (half a spacing beyond the outer units): ``μN − atan(g_L/μ) − atan(g_R/μ) = lπ``,
  root l bracketed in ``[lπ/N, (l + 1)π/N)``. It puts the spring half a cell further
  out than the chain does, an O(1/N) difference in μ for grounded ends.

Phased units (``smearing="impedance"``, the default): the units' exact dynamic stiffness
on their nodes, d_u(λ) (the condensation of :mod:`.transfer`), is averaged instead of
their matrices; per wave ``k μ_j² − λ J + d̄(λ) = 0``. It does not depend on the units'
internal coordinates; ``smearing="matrices"`` (the mean M̄, C̄ above) does, for phased
units. Validity conditions (:func:`validity_problems`): μ_j ≤ :data:`MU_VALID`; for phased
units f ≤ :data:`FREQ_VALID` × the lowest internal frequency and a spread of the units'
static stiffness d_u(0) ≤ :data:`SPREAD_VALID` × k μ_j². ``continuum_modes`` returns an
error estimate (``ChainModes.error``, against the transfer-matrix roots) and warns
(ModelWarning) outside the range.

Stage 6 (chain): numpy/scipy; imports the chain's cyclic helpers, the transfer method's
unit condensation (error estimate) and result type.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from femmech.chain.cyclic import (
    expand,
    frequencies,
    symmetric_unit_matrices,
    unit_branches,
    wave_numbers,
)
from femmech.chain.impedance import (
    chain_impedance,
    impedance_roots,
    impedance_vectors,
)
from femmech.chain.results import ChainModes

ENDS = ("cell", "shaft")

SMEARINGS = ("impedance", "matrices")
"""How the units are smeared (:func:`continuum_modes`)."""

MU_VALID = 0.5
"""Validity: wave numbers μ_j = β a (rad per cell) up to this; the dispersion error of the
shaft-like modes is then below √(μ²/(2 − 2cos μ)) − 1 ≈ μ²/24 ≈ 1 %."""

FREQ_VALID = 0.5
"""Validity for phased units: frequencies up to this fraction of the lowest internal
frequency of the units (√μ_min / 2π, the follower frequency). Measured maximum errors of
the impedance smearing below it: docs/chain.md."""

SPREAD_VALID = 0.1
"""Validity for phased units whose static torsional stiffness on the node, d_u(0) (process
force F U'', ground spring c_g), differs between units: the spread (standard deviation)
of d_u(0) up to this fraction of the shaft stiffness κ_j = k μ_j² of a root's wave (the
low modes then do not depend on where along the shaft the stiff and the soft units sit).
Measured: std/κ = 0.07 gave 1.1 %, 0.34 gave 4.3 %, 2 gave 36 % on the lowest root."""

ERROR_WARN = 0.01
"""A ModelWarning is issued when the error estimate of a delivered root exceeds this
(relative frequency error)."""


@dataclass(frozen=True)
class Continuum:
    """Smeared properties of a chain at one drive angle.

    Attributes
    ----------
    GJ : float
        Torsional stiffness ``k a``, N m²/rad.
    spacing : float
        Cell length a, m.
    n_cells : int
    node_inertia : float
        Shaft inertia per cell J, kg m² (per length: J / a, kg m).
    M, C : ndarray (m, m)
        Mean unit matrices per cell M̄(φ), C̄(φ) (per length: divide by a).
    g_left, g_right : float
        End ground springs over the cell stiffness, k_g / k.
    attach : int
    """

    GJ: float
    spacing: float
    n_cells: int
    node_inertia: float
    M: np.ndarray
    C: np.ndarray
    g_left: float
    g_right: float
    attach: int

    @property
    def k(self) -> float:
        """Cell stiffness GJ / a, N m/rad."""
        return self.GJ / self.spacing


def _check_chain(chain) -> None:
    """ValueError naming the first property the smeared continuum cannot represent."""
    if chain.n_nodes < 2:
        raise ValueError("the continuum needs at least 2 cells (n_nodes >= 2)")
    if chain.clamped.any():
        raise ValueError(f"node {int(np.flatnonzero(chain.clamped)[0])} is clamped; the"
                         " continuum takes free or elastic ends (End.elastic)")
    bare = np.setdiff1d(np.arange(chain.n_nodes), chain.unit_node)
    if bare.size:
        raise ValueError(f"node {int(bare[0])} carries no unit; the continuum smears one"
                         " unit per cell (no end stubs: end_length=None)")
    J, k, g = chain.node_inertia, chain.spring, chain.ground
    for name, v, unit in (("node inertia", J, "kg m²"), ("spring", k, "N m/rad")):
        bad = np.flatnonzero(np.abs(v - v[0]) > 1e-12 * abs(v[0]))
        if bad.size:
            raise ValueError(f"{name} {int(bad[0])} is {v[bad[0]]:.6g} {unit}, {name} 0 is"
                             f" {v[0]:.6g} {unit}: the continuum needs identical cells"
                             " (chain(..., cells=True), no end inertias)")
    inner = np.flatnonzero(g[1:-1]) + 1
    if inner.size:
        raise ValueError(f"node {int(inner[0])} has a ground spring (only the ends may)")


def smear(chain, phi: float, Omega: float = 0.0, Omega_dot: float = 0.0) -> Continuum:
    """The smeared continuum of ``chain`` at drive angle φ (rad): :class:`Continuum`."""
    _check_chain(chain)
    Mu, Cu = symmetric_unit_matrices(chain, phi, Omega, Omega_dot)
    x = chain.x
    a = float((x[-1] - x[0]) / (chain.n_nodes - 1))
    k = float(chain.spring[0])
    return Continuum(k * a, a, chain.n_nodes, float(chain.node_inertia[0]), Mu.mean(0),
                     Cu.mean(0), chain.ground[0] / k, chain.ground[-1] / k, chain.attach)


def _alpha_cell(mu, g):
    """Phase α of Θ = cos(μ s − α) meeting the cell end condition, rad."""
    return np.arctan((g - 1 + np.cos(mu)) / np.sin(mu))


def _alpha_shaft(mu, g):
    return np.arctan(g / mu)


def mode_wave_numbers(n_cells: int, g_left: float, g_right: float, count: int,
                      ends: str = "cell") -> tuple[np.ndarray, np.ndarray]:
    """Labels and wave numbers μ (rad per cell) of the continuum's ``count`` lowest
    shapes, at most ``n_cells``; closed form where one exists, else brentq per mode."""
    N, count = int(n_cells), min(int(count), int(n_cells))
    grounded = (g_left > 0) or (g_right > 0)
    labels = np.arange(count) + (1 if grounded else 0)
    if ends not in ENDS:
        raise ValueError(f"unknown ends {ends!r}; known: {', '.join(ENDS)}")
    if ends == "cell":
        for side, g in (("left", g_left), ("right", g_right)):
            if g > 2:
                raise ValueError(f"{side} ground spring is {g:.6g} k > 2k: the chain has a"
                                 " mode localised at that end which the continuum cannot"
                                 " represent (use ends='shaft')")
        cases = {(0.0, 0.0): "free-free", (1.0, 0.0): "grounded-free",
                 (0.0, 1.0): "free-grounded", (1.0, 1.0): "grounded-grounded"}
        case = cases.get((float(g_left), float(g_right)))
        if case is not None:
            return labels, wave_numbers(N, case)[1][:count]

        def h(mu, level):
            return (mu * (N - 1) - _alpha_cell(mu, g_left) - _alpha_cell(mu, g_right)
                    - level * np.pi)

        lo, hi = 1e-12, np.pi - 1e-12
        mu = [brentq(h, lo, hi, args=(level,), xtol=1e-15, rtol=1e-15)
              for level in range(count)]
        return labels, np.array(mu)
    if not grounded:
        return labels, labels * np.pi / N

    def h(mu, level):
        return (mu * N - _alpha_shaft(mu, g_left) - _alpha_shaft(mu, g_right)
                - level * np.pi)

    mu = [brentq(h, max(level * np.pi / N, 1e-300), (level + 1) * np.pi / N,
                 args=(level,), xtol=1e-15, rtol=1e-15) for level in range(count)]
    return labels, np.array(mu)


def mode_shapes(n_cells: int, mu: np.ndarray, g_left: float, ends: str = "cell"):
    """Continuum shapes Θ_j sampled at the nodes, (N, K) (unnormalised)."""
    mu = np.asarray(mu, dtype=float)
    if ends == "cell":
        s = np.arange(n_cells)[:, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            alpha = np.where(mu > 0, _alpha_cell(mu, g_left), 0.0)
    else:
        s = np.arange(n_cells)[:, None] + 0.5
        with np.errstate(divide="ignore", invalid="ignore"):
            alpha = np.where(mu > 0, _alpha_shaft(mu, g_left), 0.0)
    return np.cos(mu * s - alpha)


def continuum_modes(chain, phi: float, n_modes: int, *, ends: str = "cell",
                    Omega: float = 0.0, Omega_dot: float = 0.0, vectors: bool = True,
                    smearing: str = "impedance", estimate: bool = True,
                    warn: bool = True) -> ChainModes:
    """The ``n_modes`` lowest quasi-eigenfrequencies of the smeared continuum.

    Parameters
    ----------
    chain : Chain
        One unit on every node, identical cells (``chain(..., cells=True)``), free or
        elastic ends, phases arbitrary.
    phi : float
        Drive angle, rad.
    n_modes : int
        How many roots (at most n = N m).
    ends : {"cell", "shaft"}
        End condition form (module docstring).
    smearing : {"impedance", "matrices"}
        ``"impedance"`` (default): the mean of the units' exact dynamic stiffness on their
        nodes, d̄(λ) = mean_u d_u(λ); independent of the units' internal coordinates.
        ``"matrices"``: the mean unit matrices M̄, C̄ (the chapter's smearing); for phased
        units its result depends on the units' choice of internal coordinates
        (docs/chain.md). Both are the same for identical phases.
    estimate : bool
        Also solve the same chain by transfer matrices (:func:`~femmech.chain.transfer.
        transfer_modes`, O(N) per root) and return the relative error of each root
        (``error``, matched by rank).
    warn : bool
        Issue a :class:`~femmech.errors.ModelWarning` when a delivered root lies outside
        the validity range (:func:`validity_problems`; with ``estimate``: when its
        estimated error exceeds :data:`ERROR_WARN`).

    Returns
    -------
    ChainModes
        ``method="continuum"``, ``label`` = mode number j (as the cyclic wave number),
        ``error`` (with ``estimate``) the relative frequency error f_continuum /
        f_transfer − 1 per root; vectors: the continuum shapes at the assembled
        coordinates, normalised with the assembled M(φ) (``vᵀ M v = 1``).
    """
    if smearing not in SMEARINGS:
        raise ValueError(f"smearing must be one of {', '.join(SMEARINGS)}, got {smearing!r}")
    c = smear(chain, phi, Omega, Omega_dot)
    n_modes = int(n_modes)
    if not 1 <= n_modes <= chain.n:
        raise ValueError(f"n_modes must be in 1..{chain.n}, got {n_modes}")
    labels, mu = mode_wave_numbers(c.n_cells, c.g_left, c.g_right, n_modes, ends)
    where = f"continuum at φ = {phi:.6g} rad"
    if smearing == "impedance":
        imp = chain_impedance(chain, phi, Omega, Omega_dot)
        lam, wave = impedance_roots(imp, c.k * mu**2, c.node_inertia)
        order = np.lexsort((wave, lam))[:n_modes]
        freq = frequencies(lam[order], where)
        label = labels[wave[order]]
        vec = None
        if vectors:
            shapes = mode_shapes(c.n_cells, mu[wave[order]], c.g_left, ends)
            vec = impedance_vectors(chain, phi, lam[order], shapes, imp, Omega, Omega_dot)
    else:
        Mp = c.M.copy()
        Mp[c.attach, c.attach] += c.node_inertia
        lam, W = unit_branches(Mp, c.C, c.k * mu**2, c.attach)
        m = Mp.shape[0]
        order = np.argsort(lam.reshape(-1), kind="stable")[:n_modes]
        freq = frequencies(lam.reshape(-1)[order], where)
        label = np.repeat(labels, m)[order]
        vec = None
        if vectors:
            vec = expand(chain, mode_shapes(c.n_cells, mu, c.g_left, ends), W)[:, order]
            M = chain.sparse_matrices(float(phi))[0]
            vec = vec / np.sqrt(np.einsum("ik,ik->k", vec, M @ vec))
    error = _estimate(chain, phi, freq, Omega) if estimate else None
    if warn:
        _warn(chain, phi, freq, label, error, c, ends)
    return ChainModes(freq, vec, "continuum", label=label, error=error)


def _estimate(chain, phi, freq, Omega) -> np.ndarray:
    """Relative error of the continuum's roots against the transfer-matrix roots of the
    same chain (the k-th lowest against the k-th lowest)."""
    from femmech.chain.transfer import transfer_modes

    ref = transfer_modes(chain, phi, n_modes=freq.size, vectors=False, Omega=Omega).freq_hz
    tiny = 1e-9 * max(float(np.abs(ref).max(initial=0.0)), 1e-300)
    with np.errstate(divide="ignore", invalid="ignore"):
        err = np.where(np.abs(ref) > tiny, freq / ref - 1,
                       np.where(np.abs(freq) > tiny, np.inf, 0.0))
    return err


def validity_problems(chain, phi: float, modes: ChainModes, ends: str = "cell") -> list:
    """Why roots of a continuum solution lie outside the continuum's validity range.

    Conditions (measured in docs/chain.md): (1) long waves, wave number μ_j ≤
    :data:`MU_VALID` rad per cell (dispersion error ≲ μ²/24 ≈ 1 %); (2) for phased units
    (phases not all equal), frequencies up to :data:`FREQ_VALID` times the lowest
    internal frequency √μ_min / 2π of the units (the follower frequency): near and
    above it the smeared model cannot resolve the units' individual couplings.

    Returns
    -------
    list of str
        One line per violated condition (empty: all roots inside).
    """
    c = smear(chain, phi)
    out = []
    labels, mu = mode_wave_numbers(c.n_cells, c.g_left, c.g_right, c.n_cells, ends)
    mu_of = dict(zip(labels.tolist(), mu.tolist(), strict=True))
    mu_root = np.array([mu_of.get(int(j), np.nan) for j in modes.label])
    long = np.flatnonzero(mu_root > MU_VALID)
    if long.size:
        i = int(long[0])
        out.append(f"{long.size} root(s) have wave numbers μ > {MU_VALID:g} rad per cell"
                   f" (first: f = {modes.freq_hz[i]:.6g} Hz, mode {int(modes.label[i])},"
                   f" μ = {mu_root[i]:.3g}: dispersion ≈ {100 * mu_root[i] ** 2 / 24:.2g} %)")
    if np.ptp(chain.phase) > 0:
        imp = chain_impedance(chain, phi, 0.0, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            static = imp.caa - np.where(imp.alpha == 0, 0.0, imp.alpha**2 / imp.mu).sum(axis=1)
        spread = float(np.std(static))
        lowest_pole = imp.poles[0] if imp.poles.size else np.inf
        lam = np.sign(modes.freq_hz) * (2 * np.pi * modes.freq_hz) ** 2
        weak = np.flatnonzero((c.k * np.nan_to_num(mu_root) ** 2 * SPREAD_VALID < spread)
                              & (lam < lowest_pole))
        if weak.size:
            i = int(weak[0])
            out.append(f"{weak.size} root(s) of phased units whose static stiffness d_u(0)"
                       f" varies (std {spread:.3g} N m/rad) by more than {SPREAD_VALID:g} ×"
                       f" the shaft stiffness k μ² of their wave (first: f ="
                       f" {modes.freq_hz[i]:.6g} Hz, k μ² = {c.k * mu_root[i] ** 2:.3g}"
                       " N m/rad)")
        internal = imp.mu[imp.mu > 0]
        if internal.size:
            f_int = np.sqrt(internal.min()) / (2 * np.pi)
            high = np.flatnonzero(modes.freq_hz > FREQ_VALID * f_int)
            if high.size:
                out.append(f"{high.size} root(s) of phased units lie above {FREQ_VALID:g} ×"
                           f" the units' lowest internal frequency {f_int:.6g} Hz (first:"
                           f" {modes.freq_hz[high[0]]:.6g} Hz)")
    return out


def _warn(chain, phi, freq, label, error, c, ends) -> None:
    """The ModelWarning of :func:`continuum_modes` (see there)."""
    import warnings

    from femmech.errors import ModelWarning

    problems = validity_problems(chain, phi, ChainModes(freq, None, "continuum", label=label),
                                 ends)
    if error is not None:
        worst = float(np.max(np.abs(error), initial=0.0))
        if worst <= ERROR_WARN:
            return
        problems.append(f"estimated error up to {100 * worst:.3g} % (transfer-matrix roots"
                        " of the same chain: ChainModes.error)")
    if problems:
        warnings.warn(f"continuum at φ = {float(phi):.6g} rad outside its validity range: "
                      + "; ".join(problems) + "; use transfer_modes or assembled_modes there",
                      ModelWarning, stacklevel=3)


@dataclass(frozen=True)
class ErrorTable:
    """Relative error of the continuum against the discrete chain, per N and mode number.

    Attributes
    ----------
    n_values : ndarray (a,) of int
        Numbers of units N.
    modes : ndarray (b,) of int
        Mode (wave) numbers j.
    mu : ndarray (a, b)
        Wave number μ_j of the chain, rad per cell (NaN where j does not exist for N).
    f_discrete : ndarray (a, b, m)
        Chain frequencies of wave j, branch r (ascending), Hz.
    error : ndarray (a, b, m)
        ``f_continuum / f_discrete − 1`` per branch (NaN where j does not exist).
    """

    n_values: np.ndarray
    modes: np.ndarray
    mu: np.ndarray
    f_discrete: np.ndarray
    error: np.ndarray

    def markdown(self, branch: int | None = None, digits: int = 2) -> str:
        """A Markdown table: rows N, columns j, entries the relative error in % (the
        largest over branches unless ``branch`` is given); "–" where j ≥ modes of N."""
        a = np.abs(self.error)
        err = (np.where(np.isnan(a).all(2), np.nan, np.nan_to_num(a).max(2))
               if branch is None else a[..., branch])
        head = "| N | " + " | ".join(f"j = {j}" for j in self.modes) + " |"
        rule = "|---:|" + "---:|" * self.modes.size
        rows = [f"| {n} | " + " | ".join("–" if np.isnan(e) else f"{100 * e:.{digits}g} %"
                                         for e in err[i]) + " |"
                for i, n in enumerate(self.n_values)]
        return "\n".join([head, rule, *rows])


def _by_label(modes: ChainModes, labels, m: int) -> np.ndarray:
    """Frequencies (len(labels), m) of each wave, ascending; NaN for absent waves."""
    out = np.full((len(labels), m), np.nan)
    for row, j in enumerate(labels):
        f = np.sort(modes.freq_hz[modes.label == j])
        out[row, : f.size] = f
    return out


def continuum_error_table(unit, n_values=(5, 10, 20, 40, 100), modes=(1, 2, 3, 5, 10), *,
                          spacing: float = 0.25, shaft_diameter: float = 0.04,
                          phi: float = 0.0, left=None, right=None,
                          station_inertia: float = 0.0, ends: str = "cell") -> ErrorTable:
    """Error of the continuum against the discrete uniform chain (cyclic closed form).

    For each N a uniform chain ``chain(unit, N, spacing, shaft_diameter, cells=True)``
    (spacing and diameter in m, ``station_inertia`` kg m², ends ``left``/``right``:
    :class:`~femmech.chain.model.End`, free or ground springs; default free) is solved at
    drive angle ``phi`` (rad) by :func:`~femmech.chain.cyclic.cyclic_modes` and by
    :func:`continuum_modes`; waves are matched by their label j.

    Returns
    -------
    ErrorTable
    """
    from femmech.chain.cyclic import cyclic_modes
    from femmech.chain.model import End, chain

    left = End() if left is None else left
    right = End() if right is None else right
    n_values = np.asarray(n_values, dtype=int)
    modes = np.asarray(modes, dtype=int)
    m = int(unit.n)
    f_d = np.full((n_values.size, modes.size, m), np.nan)
    f_c = np.full_like(f_d, np.nan)
    mu = np.full((n_values.size, modes.size), np.nan)
    for i, N in enumerate(n_values):
        ch = chain(unit, int(N), spacing, shaft_diameter, cells=True, left=left,
                   right=right, station_inertia=station_inertia)
        f_d[i] = _by_label(cyclic_modes(ch, phi, vectors=False), modes, m)
        f_c[i] = _by_label(continuum_modes(ch, phi, ch.n, ends=ends, vectors=False,
                                           estimate=False, warn=False), modes, m)
        c = smear(ch, phi)
        labels, mu_all = mode_wave_numbers(c.n_cells, c.g_left, c.g_right, c.n_cells, ends)
        for b, j in enumerate(modes):
            mu[i, b] = mu_all[labels == j][0] if np.any(labels == j) else np.nan
    with np.errstate(invalid="ignore", divide="ignore"):
        error = f_c / f_d - 1
    return ErrorTable(n_values, modes, mu, f_d, error)
