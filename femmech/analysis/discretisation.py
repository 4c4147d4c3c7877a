"""Discretisation error of a full FE model's frequencies, per mode, by one refinement.

The model's mesh is refined uniformly (h/2, :func:`femmech.fe.refine.refine_mesh`) and the
model rebuilt on it with the same properties, supports, masses, springs and links
(:func:`femmech.fe.refine.refined_model`, or the caller's own ``build(mesh)``). Both are
solved; each coarse mode is matched to a fine mode by the mass-weighted MAC on the coarse
nodes (the first nodes of the refined mesh), and the pair is Richardson-extrapolated with
the element family's asymptotic rate p (``f(h) = f₀ + C hᵖ``):

    f₀ ≈ f_fine - (f_coarse - f_fine) / (2ᵖ - 1),
    error = (f_coarse - f₀) / f₀           (relative error of the coarse frequency).

Rates :data:`RATES` (exponent of h for frequencies) were measured on reference problems
with a log-log fit over three or four meshes (docs: the estimator's section; the tests
repeat the cheaper fits). A model of several families uses the smallest rate, which makes
the estimate larger (conservative).

A number that may be wrong is flagged, never shown plain (:attr:`DiscretisationEstimate.flag`):
``"unmatched"`` (no fine mode with MAC >= ``mac_min``), ``"wrong direction"`` (a
conforming family whose frequency rose on refinement), ``"not asymptotic"`` (the
refinement changed the frequency by more than ``max_change``; then h is too coarse for
the extrapolation, and the error is at least the change), ``"rate"`` (with ``levels=3``:
the observed rate is below 0.7 p, so the estimate may be optimistic), ``"rigid"``.

Uses analysis.modes, fe (mesh, model, refine) and errors.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from femmech.analysis.modes import ModeSet, modes
from femmech.errors import ModelWarning
from femmech.fe.dofs import DOF_PER_NODE
from femmech.fe.mesh import Mesh
from femmech.fe.model import FEModel
from femmech.fe.refine import refine_mesh, refined_model

RATES = {"line": 2.0, "triangle": 2.0, "quad": 2.0, "tetra": 1.0, "hexahedron": 1.5,
         "quad9": 4.0, "triangle6": 3.0}
"""Convergence exponent p of frequencies, ``|f(h) - f₀| ~ hᵖ``, used per cell kind:
the measured rate in the range of meshes a model uses, rounded down where it varies, so
that the estimate errs on the large side (docs: the estimator's section).

* ``line`` 2: the exact-stiffness beam with consistent mass converges as h⁴ in
  Euler-Bernoulli bending but as h² in axial and torsional modes (linear fields) and,
  with shear and rotary inertia, tends to h² (measured 4 → 2.5 → 2.1); p = 2 over-estimates
  pure bending errors by 25 % (16/15 against 4/3).
* ``quad``, ``triangle`` 2: MITC4 and MITC3 plates, measured 2.0-2.1 (simply supported
  square plate, 8 → 32 elements per side).
* ``quad9`` 4: MITC9 plates, measured 3.9-4.0 (same plate, 4 → 16 elements per side).
* ``triangle6`` 3: MITC6 plates, measured 3.2-3.8 (the same, two triangles per square).
* ``hexahedron`` 1.5: linear hexahedra in bending, measured 1.5-1.8 before the asymptotic
  2 (shear locking of coarse meshes).
* ``tetra`` 1: linear tetrahedra in bending, measured 0.4-1.6 at practical sizes (locking).
"""

CONFORMING = {"line", "tetra", "hexahedron"}
"""Kinds whose frequencies can only fall on uniform refinement (Rayleigh-Ritz on nested
conforming spaces with consistent mass); a rise is flagged. MITC shells are mixed
(assumed strains) and may approach from either side."""

FLAGS = ("rigid", "unmatched", "wrong direction", "not asymptotic", "rate")


@dataclass(frozen=True)
class DiscretisationEstimate:
    """Estimated discretisation error per mode of an FE model (one uniform refinement).

    Attributes
    ----------
    freq_hz : ndarray (n,)
        Frequencies of the model as given, Hz.
    freq_fine_hz : ndarray (n,)
        Frequencies of the matched modes of the h/2 model, Hz (NaN if unmatched).
    freq_extrapolated_hz : ndarray (n,)
        Richardson extrapolation ``f₀``, Hz.
    error : ndarray (n,)
        Estimated relative error of ``freq_hz``, ``(f - f₀) / f₀`` (> 0: too high);
        NaN if unmatched, 0 for rigid-body modes.
    rate : float
        Exponent p used (:data:`RATES`).
    rate_observed : ndarray (n,)
        ``log2((f₁ - f₂) / (f₂ - f₃))`` from a second refinement (``levels=3``), else NaN.
    change : ndarray (n,)
        Relative change on refinement ``(f - f(h/2)) / f(h/2)``; for a mode that
        converges from above, a lower bound of its error (shown for flagged modes).
    mac : ndarray (n,)
        Mass-weighted MAC of the match on the coarse nodes (subspace MAC for repeated
        fine frequencies).
    flag : ndarray (n,) of str
        "" if the estimate is trusted, else one of :data:`FLAGS`.
    n_dof : tuple of int
        Free DOFs of each level (coarse first).
    kinds : tuple of str
        Cell kinds of the model.
    """

    freq_hz: np.ndarray
    freq_fine_hz: np.ndarray
    freq_extrapolated_hz: np.ndarray
    error: np.ndarray
    rate: float
    rate_observed: np.ndarray
    change: np.ndarray
    mac: np.ndarray
    flag: np.ndarray
    n_dof: tuple
    kinds: tuple

    @property
    def trusted(self) -> np.ndarray:
        """(n,) bool: the estimate of the mode carries no flag."""
        return self.flag == ""

    def max_error(self) -> float:
        """Largest |error| of the elastic modes; inf if one of them is flagged."""
        elastic = self.flag != "rigid"
        if not np.all(self.trusted[elastic]):
            return float("inf")
        return float(np.max(np.abs(self.error[elastic]), initial=0.0))

    def describe(self, k: int) -> str:
        """The estimate of mode ``k`` (0-based) as text, with its flag: ``"2.1e-03"``,
        ``"≥ 1.3e-01 (not asymptotic)"``, ``"? (unmatched, MAC 0.62)"``."""
        flag, e = self.flag[k], self.error[k]
        if flag == "rigid":
            return "rigid"
        if flag == "unmatched":
            return f"? (unmatched, MAC {self.mac[k]:.2f})"
        if flag == "not asymptotic":
            return f"≥ {abs(self.change[k]):.1e} (not asymptotic)"
        return f"{e:.1e}" + (f" ({flag})" if flag else "")

    def table(self) -> str:
        """Plain-text table: mode, f, f(h/2), f₀, estimated error (with flags)."""
        lines = [f"discretisation error by h/2 refinement, rate p = {self.rate:g}"
                 f" ({', '.join(self.kinds)}); DOFs {' -> '.join(map(str, self.n_dof))}",
                 f"{'mode':>4} {'f (Hz)':>14} {'f h/2 (Hz)':>14} {'f0 (Hz)':>14}  error"]
        for k in range(len(self.freq_hz)):
            lines.append(f"{k + 1:>4} {self.freq_hz[k]:>14.6g} {self.freq_fine_hz[k]:>14.6g}"
                         f" {self.freq_extrapolated_hz[k]:>14.6g}  {self.describe(k)}")
        return "\n".join(lines)

    def __repr__(self) -> str:
        return (f"DiscretisationEstimate({len(self.freq_hz)} modes, p = {self.rate:g},"
                f" max |error| {self.max_error():.2g}, {int(np.sum(~self.trusted))} flagged)")


def discretisation_error(model_or_builder: FEModel | Callable[[Mesh], FEModel],
                         n_modes: int | None = None,
                         band_hz: tuple[float, float] | None = None, *,
                         mesh: Mesh | None = None, levels: int = 2,
                         rate: float | None = None, mac_min: float = 0.9,
                         max_change: float = 0.1, coarse: ModeSet | None = None
                         ) -> DiscretisationEstimate:
    """Estimate the discretisation error of each requested frequency of a full FE model.

    Parameters
    ----------
    model_or_builder : FEModel or callable
        A model made by :func:`femmech.build_model` (rebuilt on the refined mesh from its
        kept inputs), or ``build(mesh) -> FEModel`` for models made another way (then
        ``mesh`` is required).
    n_modes, band_hz
        The modes, as in :func:`femmech.analysis.modes.modes`.
    mesh : Mesh, optional
        The coarse mesh for ``build``.
    levels : int
        2 (the model and one refinement) or 3 (a second refinement, for the observed
        rate ``rate_observed``; about 4 (shells) to 8 (solids) times the cost).
    rate : float, optional
        Exponent p instead of :data:`RATES`.
    mac_min : float
        Smallest MAC of a match (below: flagged ``"unmatched"``).
    max_change : float
        Largest relative change ``|f - f(h/2)| / f(h/2)`` of the asymptotic range.
    coarse : ModeSet, optional
        The model's modes if already computed (same n_modes/band_hz), to save a solve.

    Returns
    -------
    DiscretisationEstimate

    Raises
    ------
    ValueError
        For a cell kind without a known rate (give ``rate``), bad arguments, or a model
        that cannot be rebuilt (:func:`femmech.fe.refine.refined_model`).
    NotImplementedError
        For cell kinds that are not refined (:func:`femmech.fe.refine.refine_mesh`).
    """
    if levels not in (2, 3):
        raise ValueError(f"levels must be 2 or 3, got {levels!r}")
    models = _level_models(model_or_builder, mesh, levels)
    kinds = tuple(k for k, c in models[0].mesh.cells.items() if k != "vertex" and len(c))
    p = _rate(kinds, rate)
    found = coarse if coarse is not None else modes(models[0], n_modes=n_modes,
                                                    band_hz=band_hz)
    chain, macs = [found.freq_hz], []
    previous = found
    for below, model in zip(models[:-1], models[1:], strict=True):
        with warnings.catch_warnings():  # the coarse model's findings, said once
            warnings.simplefilter("ignore", ModelWarning)
            finer = modes(model, n_modes=previous.n_modes + max(4, previous.n_modes // 2))
        pick, mac = match_modes(previous, finer, below.M, n_nodes=below.mesh.n_nodes)
        freq = np.where(pick >= 0, finer.freq_hz[np.maximum(pick, 0)], np.nan)
        chain.append(freq if previous is found else _follow(chain[-1], freq, pick))
        macs.append(mac)
        previous = _subset(finer, pick)
    return _estimate(chain, macs, found.rigid, p, mac_min, max_change,
                     tuple(m.n_free for m in models), kinds)


def _level_models(model_or_builder, mesh, levels: int) -> list[FEModel]:
    """The coarse model and its ``levels - 1`` refinements."""
    if isinstance(model_or_builder, FEModel):
        if mesh is not None:
            raise ValueError("give mesh only with a build(mesh) function, not with a model")
        return [model_or_builder] + [refined_model(model_or_builder, k)
                                     for k in range(1, levels)]
    if not callable(model_or_builder):
        raise TypeError("discretisation_error needs an FEModel or a build(mesh) function,"
                        f" got {type(model_or_builder).__name__}")
    if not isinstance(mesh, Mesh):
        raise ValueError("discretisation_error(build, ...): give the coarse mesh= as well")
    out, m = [], mesh
    for _ in range(levels):
        out.append(model_or_builder(m))
        m = refine_mesh(m)
    return out


def _rate(kinds, rate) -> float:
    """The rate of the given kinds (smallest of :data:`RATES`), or ``rate`` if given."""
    if rate is not None:
        if not (np.isfinite(rate) and rate > 0):
            raise ValueError(f"rate must be a positive number, got {rate!r}")
        return float(rate)
    unknown = [k for k in kinds if k not in RATES]
    if unknown:
        raise ValueError(f"no measured convergence rate for {unknown} cells (known:"
                         f" {sorted(RATES)}); give rate=")
    return min(RATES[k] for k in kinds)


def match_modes(coarse: ModeSet, fine: ModeSet, M=None, n_nodes: int | None = None,
                cluster_tol: float = 1e-3) -> tuple[np.ndarray, np.ndarray]:
    """Fine mode matched to each coarse mode, by MAC on the coarse nodes.

    Parameters
    ----------
    coarse, fine : ModeSet
        ``fine`` on a mesh whose first nodes are the coarse nodes.
    M : sparse (n_dof, n_dof), optional
        Coarse mass matrix for a mass-weighted MAC (default: unweighted).
    n_nodes : int
        Number of coarse nodes (default: from ``coarse.shapes``).
    cluster_tol : float
        Fine modes closer than this relative frequency gap form one cluster (repeated
        frequencies, whose individual shapes are arbitrary); a coarse mode's MAC is with
        the span of its partner's cluster.

    Returns
    -------
    pick : ndarray (n_coarse,) of int
        Index into ``fine`` (-1 where nothing is left to match).
    mac : ndarray (n_coarse,)
        MAC of each match (0 where unmatched).
    """
    n = DOF_PER_NODE * (n_nodes if n_nodes is not None else coarse.shapes.shape[0] // 6)
    a, b = coarse.shapes[:n], fine.shapes[:n]
    W = (lambda x: M @ x) if M is not None else (lambda x: x)
    Wa, Wb = W(a), W(b)
    single = (a.T @ Wb) ** 2 / np.outer(np.einsum("ij,ij->j", a, Wa),
                                         np.einsum("ij,ij->j", b, Wb))
    clusters = _clusters(fine.freq_hz, cluster_tol)
    subspace = np.empty_like(single)
    for members in clusters:
        B = b[:, members]
        G = B.T @ W(B)  # Gram matrix of the cluster: project in the M inner product
        proj = np.linalg.solve(G, B.T @ Wa)
        num = np.einsum("ij,ij->j", Wa, B @ proj)
        subspace[:, members] = (num / np.einsum("ij,ij->j", a, Wa))[:, None]
    score = subspace + 1e-3 * single
    rows, cols = linear_sum_assignment(-score)
    pick = np.full(a.shape[1], -1)
    pick[rows] = cols
    mac = np.zeros(a.shape[1])
    mac[rows] = subspace[rows, cols]
    return pick, np.clip(mac, 0.0, 1.0)


def _clusters(freq: np.ndarray, tol: float) -> list[np.ndarray]:
    """Index groups of consecutive (ascending) frequencies closer than ``tol`` relative."""
    f = np.asarray(freq, dtype=float)
    gap = np.diff(f) > tol * np.maximum(np.abs(f[1:]), 1e-300)
    starts = np.concatenate([[0], np.flatnonzero(gap) + 1, [f.size]])
    return [np.arange(starts[i], starts[i + 1]) for i in range(starts.size - 1)]


def _subset(modeset: ModeSet, pick: np.ndarray) -> ModeSet:
    """The matched modes of ``modeset`` in the order of ``pick`` (unmatched: mode 0)."""
    idx = np.maximum(pick, 0)
    return ModeSet(modeset.freq_hz[idx], modeset.omega2[idx], modeset.shapes[:, idx],
                   modeset.rigid[idx], modeset.method, modeset.sigma,
                   modeset.residual[idx], modeset.sturm_count)


def _follow(previous: np.ndarray, freq: np.ndarray, pick: np.ndarray) -> np.ndarray:
    """Frequencies of the next level, NaN where the previous level had none."""
    return np.where(np.isfinite(previous) & (pick >= 0), freq, np.nan)


def _estimate(chain, macs, rigid, p, mac_min, max_change, n_dof, kinds):
    """Richardson extrapolation of levels 0 and 1, flags, observed rates (3 levels)."""
    f0, f1 = chain[0], chain[1]
    d = f0 - f1
    f_ext = f1 - d / (2.0 ** p - 1.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        error = np.where(rigid, 0.0, (f0 - f_ext) / f_ext)
        change = d / f1
    mac = macs[0]
    conforming = set(kinds) <= CONFORMING
    flag = np.full(f0.size, "", dtype=object)
    rate_obs = np.full(f0.size, np.nan)
    if len(chain) == 3:
        d2 = f1 - chain[2]
        small = np.abs(d) <= 1e-9 * np.abs(f1)
        with np.errstate(invalid="ignore", divide="ignore"):
            rate_obs = np.where(small | (d * d2 <= 0), np.nan, np.log2(d / d2))
        slow = np.isfinite(rate_obs) & (rate_obs < 0.7 * p)
        slow |= ~small & (d * d2 < 0) | (macs[1] < mac_min)
        flag[slow] = "rate"
    flag[np.abs(change) > max_change] = "not asymptotic"
    if conforming:
        flag[d < -1e-9 * np.abs(f1)] = "wrong direction"
    flag[~(mac >= mac_min)] = "unmatched"
    flag[np.asarray(rigid)] = "rigid"
    error = np.where(flag == "unmatched", np.nan, error)
    return DiscretisationEstimate(np.asarray(f0), f1, f_ext, error, p, rate_obs, change, mac,
                                  flag.astype(str), n_dof, kinds)


def discretisation_error_of(result: ModeSet, model: FEModel, reduced: bool | None = None,
                            **options) -> DiscretisationEstimate:
    """The discretisation estimate of each mode of ``result``, modes of ``model`` itself or
    of its reduction (:func:`femmech.analysis.modes.superelement_modes`).

    For reduced modes the full model's modes are solved, estimated, and matched to the
    reduced ones by MAC (recovered shapes), so that the report can show the
    discretisation error beside the reduction estimate of the same mode. ``options`` go
    to :func:`discretisation_error` (``levels``, ``rate``, ``mac_min``, ``max_change``).
    The frequencies in the returned estimate are the full model's. ``reduced``: whether
    ``result`` holds modes of a reduction (default: if it carries a reduction error
    estimate, i.e. ``superelement_modes`` was given the model).
    """
    if reduced is None:
        reduced = result.error_estimate is not None
    if not reduced:
        return discretisation_error(model, coarse=result, **options)
    full = modes(model, n_modes=result.n_modes + max(4, result.n_modes // 2))
    est = discretisation_error(model, coarse=full, **options)
    pick, mac = match_modes(result, full, model.M)
    mac_min = options.get("mac_min", 0.9)
    take = np.maximum(pick, 0)
    flag = np.where(mac >= mac_min, est.flag[take], "unmatched")
    flag = np.where(result.rigid, "rigid", flag)
    fields = {name: getattr(est, name)[take] for name in
              ("freq_hz", "freq_fine_hz", "freq_extrapolated_hz", "error", "rate_observed",
               "change")}
    fields["error"] = np.where(flag == "unmatched", np.nan, fields["error"])
    return DiscretisationEstimate(**fields, rate=est.rate, mac=np.minimum(mac, est.mac[take]),
                                  flag=flag.astype(str), n_dof=est.n_dof, kinds=est.kinds)
