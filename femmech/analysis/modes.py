"""Free vibration modes of an FE model: ``K φ = ω² M φ``.

Stage 5 (analysis): uses reduction, fe and solve; nothing here writes files.
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from femmech.analysis.shell_checks import drilling_findings, drilling_fractions
from femmech.errors import ModelWarning
from femmech.fe import checks
from femmech.fe.dofs import DOF_PER_NODE
from femmech.fe.model import FEModel
from femmech.html import html_summary
from femmech.reduction.estimate import confirmed_indices, frequency_error_estimates
from femmech.reduction.superelement import Superelement
from femmech.solve import direct
from femmech.solve.eigen import RIGID_TOL, solve_symmetric
from femmech.solve.pencil import default_shift, eigenvalue_scale


@dataclass(frozen=True)
class ModeSet:
    """Natural modes of a model.

    Attributes
    ----------
    freq_hz : ndarray (n_modes,)
        Natural frequencies, Hz, ascending; rigid-body modes are reported as 0.
    omega2 : ndarray (n_modes,)
        Eigenvalues ω², rad²/s², as computed (rigid-body modes are ~0, may be tiny negative).
    shapes : ndarray (n_dof, n_modes)
        Full-model mode shapes (constrained DOFs included), mass-normalised
        (``φᵀ M φ = 1``, kg⁻½ scaled), largest-magnitude free entry positive.
    rigid : ndarray (n_modes,) of bool
        True for rigid-body (zero-frequency) modes.
    method : str
        ``"dense"`` or ``"arpack"``.
    sigma : float
        Shift, rad²/s².
    residual : ndarray (n_modes,)
        Relative residual of each eigenpair.
    sturm_count : int or None
        Sturm-sequence count that confirmed the result (None if not checked).
    error_estimate : ndarray (n_modes,) or None
        For modes of a reduced model: a-posteriori estimate of the relative frequency
        error against the unreduced model (see
        :func:`femmech.reduction.estimate.frequency_error_estimates`).
    solver : str or None
        Sparse direct solver of the shift-invert factorisation (``"superlu"``,
        ``"cholmod"``, ``"pardiso"``; :mod:`femmech.solve.direct`), ``"pyamg"`` for LOBPCG,
        None for dense LAPACK.
    drilling : ndarray (n_modes,) or None
        For models with shell elements: the fraction of each mode's kinetic energy in
        rotations about the shell normals
        (:func:`femmech.analysis.shell_checks.drilling_fractions`); near 1 for the
        spurious drilling modes of thick shells, near 0 for structural modes. None for
        models without shells.
    index_confirmed : ndarray (n_modes,) of bool or None
        For modes of a reduced model checked against the unreduced one
        (:func:`superelement_modes` with ``model``): True where a Sturm count of the full
        model confirms that the full mode of the same number lies within the error
        estimate (:func:`femmech.reduction.estimate.confirmed_indices`); False where the
        reduction missed a full mode below it, so that the estimate compares it with
        another full mode. None if not checked.
    """

    freq_hz: np.ndarray
    omega2: np.ndarray
    shapes: np.ndarray
    rigid: np.ndarray
    method: str
    sigma: float
    residual: np.ndarray
    sturm_count: int | None
    error_estimate: np.ndarray | None = None
    solver: str | None = None
    drilling: np.ndarray | None = None
    index_confirmed: np.ndarray | None = None

    def __repr__(self) -> str:
        f = np.asarray(self.freq_hz)
        shown = ", ".join(f"{x:.4g}" for x in f[:6]) + (", ..." if f.size > 6 else "")
        rigid = f", {int(np.sum(self.rigid))} rigid-body" if np.any(self.rigid) else ""
        return f"ModeSet({f.size} modes{rigid}: [{shown}] Hz; {self.method})"

    def _repr_html_(self) -> str:
        f, estimate = np.asarray(self.freq_hz), self.error_estimate
        confirmed = self.index_confirmed
        header = ("mode", "f / Hz", "rigid", "residual") + (
            ("error estimate",) if estimate is not None else ()) + (
            ("index",) if confirmed is not None else ())
        rows = [(k + 1, float(f[k]), "yes" if self.rigid[k] else "", float(self.residual[k]))
                + ((float(estimate[k]),) if estimate is not None else ())
                + ((_index_text(confirmed[k]),) if confirmed is not None else ())
                for k in range(f.size)]
        facts = [("method", self.method + (f" ({self.solver})" if self.solver else "")),
                 ("shift σ / (rad/s)²", float(self.sigma)),
                 ("Sturm count", "not checked" if self.sturm_count is None
                  else self.sturm_count)]
        return html_summary(f"ModeSet: {f.size} modes", facts, header, rows)

    @property
    def n_unconfirmed(self) -> int:
        """Number of modes whose index the full model did not confirm (0 if not checked)."""
        c = self.index_confirmed
        return 0 if c is None else int(np.count_nonzero(~np.asarray(c)))

    @property
    def n_modes(self) -> int:
        """Number of modes."""
        return len(self.freq_hz)

    def nodal(self, mode: int) -> np.ndarray:
        """Nodal values of one mode, shape (n_nodes, 6): ux, uy, uz, rx, ry, rz."""
        return self.shapes[:, mode].reshape(-1, 6)


def _index_text(confirmed) -> str:
    return "confirmed" if confirmed else "UNCONFIRMED"


def modes(model: FEModel, n_modes: int | None = None, band_hz: tuple[float, float] | None = None,
          sigma: float | None = None, check: bool = True, solver: str | None = None,
          method: str = "shift-invert") -> ModeSet:
    """Natural modes of ``model`` by shift-invert Lanczos (ARPACK) or dense LAPACK.

    Solves ``Kf φ = ω² Mf φ`` for the constrained system ``Kf = Tᵀ K T``, ``Mf = Tᵀ M T``
    and expands ``φ`` to all DOFs. Free-free structures work: the default shift lies
    below zero, so a singular K is never factorised, and rigid-body modes come out at
    ~0 Hz flagged in :attr:`ModeSet.rigid`. A repeated n-th eigenvalue returns its whole
    cluster (possibly more than ``n_modes`` modes). Systems below
    :data:`femmech.solve.eigen.DENSE_BELOW` free DOFs use dense LAPACK.

    Parameters
    ----------
    model : FEModel
    n_modes : int, optional
        Number of lowest modes, rigid-body modes included: ``n_modes=12`` of a free-free
        structure gives its 6 rigid-body modes (0 Hz, flagged in :attr:`ModeSet.rigid`)
        and its 6 lowest elastic modes.
    band_hz : (float, float), optional
        All modes with ``f_lo <= f <= f_hi``, Hz (exactly one of n_modes and band_hz). A
        band from 0 holds all rigid-body modes (:data:`femmech.solve.eigen.RIGID_TOL`).
    sigma : float, optional
        Shift in rad²/s² (default: ``-1e-6 ×`` the eigenvalue scale, or the band centre).
    check : bool
        Confirm by a Sturm-sequence count that no mode below the last one was missed.
    solver : str, optional
        Sparse direct solver (``"auto"``, ``"superlu"``, ``"cholmod"``, ``"pardiso"``);
        default :func:`femmech.solve.direct.default_solver`. Reported in
        :attr:`ModeSet.solver`.
    method : str
        ``"shift-invert"`` (Lanczos on a factorisation, Sturm-checked; dense LAPACK for
        small models) or ``"lobpcg"`` (AMG-preconditioned LOBPCG without a factorisation,
        for models too large to factorise: :mod:`femmech.solve.lobpcg`; n_modes only, no
        Sturm check).

    Returns
    -------
    ModeSet

    Warns
    -----
    ModelWarning
        For a first elastic frequency that only a unit mix-up gives
        (:func:`femmech.fe.checks.frequency_findings`), and for spurious drilling modes of
        thick shells (:func:`femmech.analysis.shell_checks.drilling_findings`).

    Examples
    --------
    >>> import numpy as np, femmech as fm
    >>> from femmech import sections
    >>> x = np.linspace(0.0, 1.0, 11)
    >>> mesh = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
    ...                           np.column_stack([np.arange(10), np.arange(1, 11)]),
    ...                           node_sets={"root": [0]})
    >>> prop = fm.BeamProperty(sections.circle(0.02), fm.Material(E=210e9, nu=0.3, rho=7850))
    >>> model = fm.build_model(mesh, {"all": prop}, supports=[fm.Support("root")])
    >>> result = fm.modes(model, n_modes=2)
    >>> result.freq_hz.round(1).tolist()  # two equal bending modes (Euler-Bernoulli: 14.47 Hz)
    [14.5, 14.5]
    """
    band = _band(band_hz)
    if model.n_free == 0:
        raise ValueError("all DOFs are constrained: the model has no free DOF")
    Kf, Mf = model.K_free, model.M_free
    scale = model_eigenvalue_scale(model)
    if method == "lobpcg":
        result = _lobpcg(model, n_modes, band, sigma)
    elif method == "shift-invert":
        with direct.use(solver):
            result = solve_symmetric(Kf, Mf, n_modes=n_modes, band=band, sigma=sigma,
                                     check=check, scale=scale)
    else:
        raise ValueError(f"method must be 'shift-invert' or 'lobpcg', got {method!r}")
    out = _with_drilling(_mode_set(result, model.expand(result.vectors), scale), model)
    lowest = band is None or band[0] <= RIGID_TOL * scale
    checks.warn(checks.frequency_findings(out.freq_hz, out.rigid, is_supported(model), lowest))
    return out


def _with_drilling(out: ModeSet, model: FEModel | None) -> ModeSet:
    """``out`` with :attr:`ModeSet.drilling` for a model with shells, warned about."""
    if model is None or not any(len(c) for c in model.shells.cells.values()):
        return out
    share = drilling_fractions(model, out.shapes)
    checks.warn(drilling_findings(share, out.freq_hz, out.rigid))
    return dataclasses.replace(out, drilling=share)


def is_supported(model: FEModel) -> bool:
    """True if some DOF is fixed (a support), i.e. a row of T is empty and the DOF is not
    an inactive rotation of a solid node."""
    empty = np.diff(model.T.tocsr().indptr) == 0
    empty[model.inactive] = False
    return bool(empty.any())


def _lobpcg(model: FEModel, n_modes, band, sigma):
    from femmech.fe.nullspace import near_nullspace, node_blocksize
    from femmech.solve.lobpcg import lobpcg_symmetric

    if band is not None or sigma is not None or n_modes is None:
        raise ValueError("method='lobpcg' computes the n_modes lowest modes: give n_modes,"
                         " no band_hz and no sigma")
    return lobpcg_symmetric(model.K_free, model.M_free, n_modes, B=near_nullspace(model),
                            blocksize=node_blocksize(model.free))


def model_eigenvalue_scale(model: FEModel) -> float:
    """Eigenvalue scale (rad²/s²) of the free system: shift, rigid threshold, residuals.

    The smallest, over the DOF components ux ... rz, of the median ratio
    ``diag K_free / diag M_free`` (:func:`femmech.solve.pencil.eigenvalue_scale` per
    component). One median over all DOFs is ruled by the rotations of thin shells, whose
    inertia ρt³/12 is tiny: at span/thickness 1e4 their ratios are 1e5 times the
    translational ones and 1e13 times the lowest bending eigenvalue, so that the
    threshold ``RIGID_TOL * scale`` declared the lowest bending modes rigid (0 Hz) and the
    shift ``-1e-6 scale`` lay so far below them that shift-invert Lanczos could not
    separate them (Sturm check failed).

    Where rigid links tie every element into one rigid body, ``K_free = Tᵀ K T`` holds
    only cancellation round-off (~eps times the element stiffness): its diagonal would
    set a meaningless scale, and with it a shift above the round-off eigenvalues (K - σM
    indefinite) and residuals relative to nothing. If no diagonal entry with mass exceeds
    ``1e-10`` of the element stiffness scale, the scale of the unconstrained K and M is
    used (every mode is then rigid).
    """
    Kf, Mf = model.K_free, model.M_free
    dk = np.asarray(Kf.diagonal(), dtype=float)
    dm = np.asarray(Mf.diagonal(), dtype=float)
    noise = 1e-10 * float(np.abs(model.K.diagonal()).max(initial=0.0))
    if noise > 0 and not np.any((dk > noise) & (dm > 0)):
        return eigenvalue_scale(model.K, model.M)
    component = model.free % DOF_PER_NODE
    ok = (dk > 0) & (dm > 0)
    medians = [np.median(dk[ok & (component == c)] / dm[ok & (component == c)])
               for c in range(DOF_PER_NODE) if np.any(ok & (component == c))]
    return float(min(medians)) if medians else eigenvalue_scale(Kf, Mf)


def superelement_modes(se: Superelement, n_modes: int | None = None,
                       band_hz: tuple[float, float] | None = None,
                       model: FEModel | None = None, index_check: bool | str = True
                       ) -> ModeSet:
    """Modes of a reduced model, ``K_r q = ω² M_r q``, recovered to all DOFs.

    Parameters
    ----------
    se : Superelement
    n_modes, band_hz
        As in :func:`modes` (dense LAPACK on the reduced matrices); ``n_modes`` counts
        rigid-body modes too.
    model : FEModel, optional
        The model that was reduced; when given, each mode gets an a-posteriori estimate
        of its relative frequency error (:attr:`ModeSet.error_estimate`), computed from
        the residual in the full model without a full eigen solve, and for shell models
        its drilling share (:attr:`ModeSet.drilling`).
    index_check : bool or str
        With ``model``: confirm by Sturm counts of the full model that each reduced mode
        is the full mode of the same number within its estimate
        (:attr:`ModeSet.index_confirmed`, :func:`femmech.reduction.estimate.
        confirmed_indices`); the estimate alone cannot see a full mode that the
        reduction missed. ``True`` (or ``"top"``): one count above the highest mode
        (one indefinite factorisation of the full model), and a count per mode only if
        it finds a missed mode; ``"each"``: a count per mode (fewer where the estimates
        overlap), without assuming that the estimates bound the distance to distinct
        full eigenvalues; ``False`` skips it for models too large to factorise.

    Returns
    -------
    ModeSet
        ``shapes`` are the recovered full-model shapes (n_dof, n_modes).

    Warns
    -----
    ModelWarning
        Naming the modes whose index the full model did not confirm.
    """
    Kr, Mr = se.K, se.M
    # a reduced pencil mixes interface and modal coordinates whose diagonal ratios differ
    # by decades; its rigid-body eigenvalues sit at round-off of the largest eigenvalue
    # (measured up to 1.4e-14 λ_max), so the rigid threshold (RIGID_TOL λ_max) and the
    # residual floor (1e-9 λ_max: the residuals of rigid modes are ~eps λ_max) scale with
    # λ_max itself. The largest diagonal ratio, used before, is only a lower bound of
    # λ_max: 3000 times below it for a free shell at span/thickness 1e4, where five of the
    # six rigid-body modes were then reported as elastic.
    lam_max = _largest_eigenvalue(Kr, Mr)
    result = solve_symmetric(Kr, Mr, n_modes=n_modes, band=_band(band_hz),
                             sigma=default_shift(Kr, Mr), scale=1e-3 * lam_max,
                             rigid_tol=RIGID_TOL * lam_max,
                             dense_below=np.iinfo(np.int64).max)
    estimate = None
    if model is not None:
        estimate = frequency_error_estimates(model, se, result.omega2, result.vectors)
    out = _with_drilling(_mode_set(result, se.recover(result.vectors), lam_max, estimate), model)
    if index_check not in (True, False, None, "top", "each"):
        raise ValueError(f"index_check must be True, False, 'top' or 'each', got"
                         f" {index_check!r}")
    if model is not None and index_check and out.n_modes:
        first = 1 if band_hz is None else 1 + _count_below(Kr, Mr, float(result.omega2[0]))
        confirmed, _ = confirmed_indices(model, result.omega2, estimate, first, out.rigid,
                                         each=index_check == "each")
        out = dataclasses.replace(out, index_confirmed=confirmed)
        if not confirmed.all():
            warnings.warn(_unconfirmed_message(out, first), ModelWarning, stacklevel=2)
    lowest = band_hz is None or band_hz[0] == 0
    checks.warn(checks.frequency_findings(out.freq_hz, out.rigid, False, lowest))
    return out


def _unconfirmed_message(out: ModeSet, first: int) -> str:
    bad = np.flatnonzero(~out.index_confirmed)
    names = ", ".join(f"{first + k} ({out.freq_hz[k]:.5g} Hz)" for k in bad[:5])
    more = f" and {bad.size - 5} more" if bad.size > 5 else ""
    return (f"reduced mode(s) {names}{more}: index not confirmed, the full model's mode of"
            " the same number lies below the error estimate (Sturm count): the reduction"
            " missed a full mode below, so the estimate compares with another full mode;"
            " keep more fixed-interface modes (n_modes, cutoff_hz or f_max_hz of"
            " craig_bampton)")


def _count_below(K, M, lam: float) -> int:
    """Number of eigenvalues of the dense pencil (K, M) below ``lam`` less a relative
    1e-9 (the modes of a band below its first computed one)."""
    sigma = default_shift(K, M)
    mu = scipy.linalg.eigh(M, K - sigma * M, eigvals_only=True)
    cut = lam - 1e-9 * max(abs(lam), 1e-300)
    finite = mu > 1e-12 * mu.max()
    return int(np.count_nonzero(sigma + 1.0 / mu[finite] < cut))


def _largest_eigenvalue(K, M) -> float:
    """Largest finite eigenvalue of a dense pencil (shift-inverted, eigenvalues only)."""
    sigma = default_shift(K, M)
    mu = scipy.linalg.eigh(M, K - sigma * M, eigvals_only=True)
    return float(sigma + 1.0 / mu[mu > 1e-12 * mu.max()].min())


def _band(band_hz):
    """Band in rad²/s² from Hz, checked; None passes through."""
    if band_hz is None:
        return None
    lo, hi = (float(v) for v in band_hz)
    if not 0 <= lo < hi:
        raise ValueError(f"band_hz must be (low, high) with 0 <= low < high, got {band_hz}")
    return ((2 * np.pi * lo) ** 2, (2 * np.pi * hi) ** 2)


def _mode_set(result, shapes, scale, estimate=None) -> ModeSet:
    rigid = np.abs(result.omega2) <= RIGID_TOL * scale
    freq = np.where(rigid, 0.0, np.sqrt(np.clip(result.omega2, 0.0, None)) / (2 * np.pi))
    return ModeSet(freq, result.omega2, shapes, rigid, result.method, result.sigma,
                   result.residual, result.sturm_count, estimate,
                   getattr(result, "solver", None))


def rigid_body_frequencies(model: FEModel) -> np.ndarray:
    """Frequencies (Hz, ascending, (6,)) of the model moving as a rigid body on its springs.

    Rayleigh-Ritz on the six rigid-body motions about the centroid of the nodes,
    ``u = u_0 + θ × (x - x_c)``: the 6x6 pencil ``(Gᵀ K G, Gᵀ M G)``. By the
    Courant-Fischer principle these are upper bounds of the six lowest eigenvalues, and
    close to them when the structure is much stiffer than its mounts (e.g. a machine
    frame on elastic feet). Uses the unconstrained K and M (supports are ignored).
    """
    import scipy.linalg

    from femmech.fe.constraints import rigid_link_matrix

    points = model.mesh.points
    G = rigid_link_matrix(points - points.mean(axis=0)).reshape(-1, 6)
    Kr = G.T @ (model.K @ G)
    Mr = G.T @ (model.M @ G)
    return np.sqrt(np.abs(scipy.linalg.eigvalsh(Kr, Mr))) / (2 * np.pi)
