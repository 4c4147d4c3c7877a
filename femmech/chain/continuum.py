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

Stage 6 (chain): numpy/scipy; imports the chain's cyclic helpers and result type.
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
from femmech.chain.results import ChainModes

ENDS = ("cell", "shaft")


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
                    Omega: float = 0.0, Omega_dot: float = 0.0,
                    vectors: bool = True) -> ChainModes:
    """The ``n_modes`` lowest quasi-eigenfrequencies of the smeared continuum.

    Parameters
    ----------
    chain : Chain
        One unit on every node, identical cells (``chain(..., cells=True)``), free or
        elastic ends, phases arbitrary (smeared by the mean at φ).
    phi : float
        Drive angle, rad.
    n_modes : int
        How many roots (at most n = N m).
    ends : {"cell", "shaft"}
        End condition form (module docstring).

    Returns
    -------
    ChainModes
        ``method="continuum"``, ``label`` = mode number j (as the cyclic wave number),
        vectors: the continuum shapes ``Θ_j(x_i) w`` at the assembled coordinates,
        normalised with the assembled M(φ) (``vᵀ M v = 1``).
    """
    c = smear(chain, phi, Omega, Omega_dot)
    n_modes = int(n_modes)
    if not 1 <= n_modes <= chain.n:
        raise ValueError(f"n_modes must be in 1..{chain.n}, got {n_modes}")
    labels, mu = mode_wave_numbers(c.n_cells, c.g_left, c.g_right, n_modes, ends)
    Mp = c.M.copy()
    Mp[c.attach, c.attach] += c.node_inertia
    lam, W = unit_branches(Mp, c.C, c.k * mu**2, c.attach)
    m = Mp.shape[0]
    order = np.argsort(lam.reshape(-1), kind="stable")[:n_modes]
    freq = frequencies(lam.reshape(-1)[order], f"continuum at φ = {phi:.6g} rad")
    vec = None
    if vectors:
        vec = expand(chain, mode_shapes(c.n_cells, mu, c.g_left, ends), W)[:, order]
        M = chain.sparse_matrices(float(phi))[0]
        vec = vec / np.sqrt(np.einsum("ik,ik->k", vec, M @ vec))
    return ChainModes(freq, vec, "continuum",
                      label=np.repeat(labels, m)[order])


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
        f_c[i] = _by_label(continuum_modes(ch, phi, ch.n, ends=ends, vectors=False),
                           modes, m)
        c = smear(ch, phi)
        labels, mu_all = mode_wave_numbers(c.n_cells, c.g_left, c.g_right, c.n_cells, ends)
        for b, j in enumerate(modes):
            mu[i, b] = mu_all[labels == j][0] if np.any(labels == j) else np.nan
    with np.errstate(invalid="ignore", divide="ignore"):
        error = f_c / f_d - 1
    return ErrorTable(n_values, modes, mu, f_d, error)
