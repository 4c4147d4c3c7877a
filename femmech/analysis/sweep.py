"""Quasi-eigenfrequencies and quasi-eigenmodes of a coupled machine over the drive angle.

At each frozen drive angle φ the coupled system (seed 5.2.2 eq. 9) gives the eigenproblem

* ``C v = λ M v`` (λ = ω²) when C(φ) is symmetric and damping is ignored (LAPACK eigh),
* the same with an unsymmetric C (LAPACK eig; complex λ flag flutter-type instability),
* ``(s² M + s B + C) v = 0`` with damping, solved in first-order form
  ``[[0, I], [-C, -B]] z = s [[I, 0], [0, M]] z`` (LAPACK eig).

Modes are followed from angle to angle by the modal assurance criterion (MAC, mass
weighted) and frequency continuity, solved as an assignment problem, so crossing branches
keep their identity (they swap order) and veering branches keep theirs (they do not).
Clusters of (nearly) repeated frequencies, whose vectors are any basis of their subspace,
are compared as subspaces. Growing motions (flutter: complex λ; divergence: λ < 0; Re s > 0)
are kept and flagged (:attr:`Sweep.unstable`), never reported as plain frequencies.

Stage 5 (analysis): uses coupling and solve; nothing here writes files.
"""

from __future__ import annotations

import warnings
from contextlib import contextmanager
from dataclasses import dataclass, replace

import numpy as np

from femmech.analysis.tracking import (  # noqa: F401  (public names of this module)
    CLUSTER_RTOL,
    assign_branches,
    clusters,
    cuts_cluster,
    mac_matrix,
    splits,
    subspace_mac,
    track_batch,
)
from femmech.coupling import CoupledSystem
from femmech.html import Flag, html_summary
from femmech.solve import dense, threads, tolerances
from femmech.solve.dense import PencilError, dense_symmetric

SYMMETRY_RTOL = tolerances.SYMMETRY_RTOL
"""C(φ) counts as symmetric when ``max|C - Cᵀ| <= SYMMETRY_RTOL * max|C|``
(:data:`femmech.solve.tolerances.SYMMETRY_RTOL`)."""

REAL_RTOL = tolerances.REAL_RTOL
"""λ (or s) with ``|Im| <= REAL_RTOL |λ|`` counts as real
(:data:`femmech.solve.tolerances.REAL_RTOL`)."""

ZERO_RTOL = tolerances.ZERO_OF_LARGEST_RTOL
"""λ with ``|λ| <= ZERO_RTOL`` times the largest diagonal ratio of C and M counts as zero
(rigid-body modes; :data:`femmech.solve.tolerances.ZERO_OF_LARGEST_RTOL`)."""

UNSTABLE_RTOL = 1e-9
"""A branch is flagged unstable where its damping ratio is below ``-UNSTABLE_RTOL``."""

DEFAULT_MODES = 6
"""Branches followed when ``n_modes`` is not given: this many, or all a system has where it
has fewer (the sweep's :attr:`Sweep.notes` say so)."""

class _SolvePhase:
    """Default of the deprecated ``blas_threads``: the limits of :mod:`femmech.solve.threads`."""

    def __repr__(self):
        return "femmech.solve.threads"


_SOLVE_PHASE = _SolvePhase()


@dataclass(frozen=True)
class Sweep:
    """Tracked quasi-modes over a set of drive angles.

    Attributes
    ----------
    phi : ndarray (n_angles,)
        Drive angles, rad.
    freq_hz : ndarray (n_angles, n_modes)
        Quasi-eigenfrequency of each tracked branch (column), Hz: ``Re √λ / 2π`` for
        the undamped forms (0 for λ < 0), the damped frequency ``Im s / 2π`` with damping.
    eigenvalues : ndarray (n_angles, n_modes), complex
        λ = ω² (undamped forms) or s (damped form) of each branch.
    damping_ratio : ndarray (n_angles, n_modes)
        ``-Re s / |s|`` (damped form). Undamped forms (motion ``e^{st}``, ``s = ±i√λ``):
        that of the growing root, 0 for real λ > 0, ``-|Im √λ| / |√λ|`` < 0 for complex λ
        (flutter: both members of the conjugate pair grow) and -1 for λ < 0 (divergence).
        Negative values flag growing motion (:attr:`unstable`).
    vectors : ndarray (n_angles, n, n_modes) or None
        Mode shapes (global coordinates), mass-normalised, if requested.
    mac_step : ndarray (n_angles, n_modes)
        MAC of each branch with itself at the previous angle (1 at the first angle); in a
        cluster of close frequencies, the MAC with the cluster's span (subspace MAC).
    form : str
        ``"symmetric"``, ``"unsymmetric"`` or ``"damped"`` (the most general used).
    notes : tuple of str
        How the sweep was set up where a default adapted to the system, e.g. that
        ``n_modes`` was left out and the system has fewer than :data:`DEFAULT_MODES`
        branches (then all of them are followed).
    """

    phi: np.ndarray
    freq_hz: np.ndarray
    eigenvalues: np.ndarray
    damping_ratio: np.ndarray
    vectors: np.ndarray | None
    mac_step: np.ndarray
    form: str
    notes: tuple[str, ...] = ()

    def __repr__(self) -> str:
        phi = np.rad2deg(np.asarray(self.phi))
        f = np.asarray(self.freq_hz)
        band = f"{np.nanmin(f):.4g}..{np.nanmax(f):.4g} Hz" if f.size else "-"
        notes = "".join(f"; {note}" for note in self.notes)
        return (f"Sweep({phi.size} angles {phi.min():.4g}..{phi.max():.4g} deg,"
                f" {f.shape[-1]} branches over {band}; {self.form}{notes})")

    def _repr_html_(self) -> str:
        f = np.asarray(self.freq_hz)
        rows = []
        for k in range(f.shape[-1]):
            grows = bool(np.any(self.unstable[:, k]))
            rows.append((k + 1, float(np.nanmin(f[:, k])), float(np.nanmax(f[:, k])),
                         float(np.min(self.mac_step[:, k])),
                         Flag("grows at some angles") if grows else ""))
        phi = np.rad2deg(np.asarray(self.phi))
        facts = [("drive angles", f"{phi.size}, {phi.min():.4g}° … {phi.max():.4g}°"),
                 ("form", self.form)] + [("note", note) for note in self.notes]
        return html_summary(f"Sweep: {f.shape[-1]} branches", facts,
                            ("branch", "min f / Hz", "max f / Hz", "min MAC step",
                             "frozen-angle growth"), rows)

    @property
    def unstable(self) -> np.ndarray:
        """(n_angles, n_modes) bool: the branch's frozen-angle motion grows (flutter,
        divergence or Re s > 0). A quasi-static indicator; the stability of the
        time-periodic system is decided by :mod:`femmech.analysis.stability`."""
        return self.damping_ratio < -UNSTABLE_RTOL


def frozen_modes(M, B, C, n_modes: int, damped: bool = False, H=None):
    """Lowest quasi-modes at one angle (dense): (eigenvalues, freq_hz, ratio, V, form).

    M, B, C (n, n): mass, damping (read only if ``damped``, otherwise it may be None)
    and stiffness. With constraints ``H x = 0`` (multiplier form), the undamped problem is
    solved as ``[[C, Hᵀ], [H, 0]] [v; μ] = λ [[M, 0], [0, 0]] [v; μ]`` (seed 5.2.1
    eq. 21 for harmonic motion); μ are the interface forces of the mode.
    """
    M, C = np.asarray(M), np.asarray(C)
    scale = _lambda_scale(M, C)
    symmetric = np.abs(C - C.T).max() <= SYMMETRY_RTOL * max(np.abs(C).max(), 1e-300)
    if H is not None and len(H):
        return _constrained_modes(M, C, np.asarray(H), n_modes, damped, symmetric, scale)
    if damped:
        return _damped_modes(M, np.asarray(B), C, n_modes, scale)
    if symmetric:
        try:
            lam, V = dense_symmetric(0.5 * (C + C.T), M, n_modes)
        except ValueError:  # C - σM indefinite: eigenvalues below σ < 0 (divergence)
            lam, V = _general_modes(0.5 * (C + C.T), M, n_modes)
            lam, V = lam.real.astype(complex), _normalise(V.real, M)
        freq, ratio = _undamped(lam, scale)
        return lam.astype(complex), freq, ratio, V, "symmetric"
    lam, V = _general_modes(C, M, n_modes)
    freq, ratio = _undamped(lam, scale)
    return lam, freq, ratio, _normalise(V, M), "unsymmetric"


def _lambda_scale(M, C) -> float:
    """Largest ``|C_ii| / M_ii`` over coordinates with mass: a (lower) estimate of max |λ|,
    the scale of round-off in λ."""
    dm, dc = np.diag(M), np.abs(np.diag(C))
    ratio = dc[dm > 0] / dm[dm > 0]
    return float(ratio.max()) if ratio.size and ratio.max() > 0 else 1.0


def _general_modes(C, M, n_modes):
    """Lowest (by Re λ) finite eigenpairs of ``C v = λ M v`` (QZ), conjugate pairs with
    Im λ > 0 first."""
    lam, V = dense.unsymmetric_pencil(C, M)
    finite = np.isfinite(lam) & (np.abs(lam) < 1e300)
    lam, V = lam[finite], V[:, finite]
    order = np.lexsort((-lam.imag, lam.real))[:n_modes]
    return lam[order], V[:, order]


def _undamped(lam, scale):
    """Frequency (Hz) and damping ratio of undamped quasi-modes from λ = ω² (complex).

    The motion is ``e^{st}`` with ``s² = -λ``, ``s = ±i√λ``: real λ > 0 oscillates
    (ratio 0); λ < 0 (divergence) and complex λ (flutter; both members of a conjugate
    pair) have a root with ``Re s = |Im √λ| > 0`` (ratio ``-|Im √λ| / |√λ|``). λ within
    ``ZERO_RTOL * scale`` of zero (rigid-body modes) and imaginary parts below
    ``REAL_RTOL |λ|`` (round-off) count as zero.
    """
    lam = np.asarray(lam, dtype=complex)
    lam = np.where(np.abs(lam.imag) <= REAL_RTOL * np.abs(lam), lam.real, lam)
    lam = np.where(np.abs(lam) <= ZERO_RTOL * scale, 0.0, lam)
    root = np.sqrt(lam)  # principal branch: Re >= 0
    size = np.abs(root)
    ratio = -np.abs(root.imag) / np.where(size > 0, size, 1.0)
    return root.real / (2 * np.pi), ratio


def _damped_modes(M, B, C, n_modes, scale):
    """Damped quasi-modes from the first-order form (QZ): one root of each oscillating
    pair (Im s > 0), plus growing real roots (divergence, Re s > 0), which would otherwise
    be dropped with the decaying real roots of overdamped motions."""
    n = M.shape[0]
    s, Z = dense.damped_pencil(M, B, C)
    finite = np.isfinite(s) & (np.abs(s) < 1e300)
    real = np.abs(s.imag) <= REAL_RTOL * np.abs(s)
    growing = real & (s.real > 1e-6 * np.sqrt(scale))
    keep = finite & (((s.imag > 0) & ~real) | growing)
    s, V = np.where(real, s.real, s)[keep], Z[:n, keep]
    order = np.argsort(s.imag, kind="stable")[:n_modes]
    s, V = s[order], V[:, order]
    return s, s.imag / (2 * np.pi), -s.real / np.abs(s), _normalise(V, M), "damped"


def _constrained_modes(M, C, H, n_modes, damped, symmetric, scale):
    """Quasi-modes of the multiplier form (QZ on the augmented pencil, finite λ only)."""
    if damped:
        raise ValueError("the multiplier form supports undamped quasi-modes; use the primal"
                         " form for damped ones")
    n, n_c = M.shape[0], H.shape[0]
    # the multipliers scaled to C's magnitude (an exact change of their units): unscaled
    # rows of H ~ 1 against C ~ 1e8 cost QZ 7e-9 .. 1.3e-8 relative on the cam beam of
    # tests/test_coupling.py (40-digit reference), scaled 1e-15
    s = np.abs(C).max() / max(np.abs(H).max(), 1e-300)
    A = np.block([[C, s * H.T], [s * H, np.zeros((n_c, n_c))]])
    E = np.zeros_like(A)
    E[:n, :n] = M
    lam, Z = _general_modes(A, E, n_modes)
    V = Z[:n]
    V = _normalise(V.real if np.abs(V.imag).max() <= 1e-12 * np.abs(V).max() else V, M)
    freq, ratio = _undamped(lam, scale)
    return lam, freq, ratio, V, "symmetric" if symmetric else "unsymmetric"


def _normalise(V, M):
    norms = np.sqrt(np.abs(np.einsum("ij,ij->j", V.conj(), M @ V)))
    return V / np.where(norms > 0, norms, 1.0)


def sweep(system: CoupledSystem, phi, Omega: float = 0.0, Omega_dot: float = 0.0,
          n_modes: int | None = None, damped: bool = False, track: bool = True,
          keep_vectors: bool = False, frequency_weight: float = 0.1,
          blas_threads=_SOLVE_PHASE) -> Sweep:
    """Quasi-modes of a coupled machine at many drive angles, with mode tracking.

    The mechanism matrices are evaluated for all angles at once
    (:meth:`~femmech.coupling.CoupledSystem.mechanism_blocks`); the per-angle solves run
    under :func:`femmech.solve.threads.solve_phase` (one BLAS thread by default: many small
    dense solves run fastest so; on this project's 2-core machine under load, 2 threads
    made a 271-coordinate sweep 25x slower).

    Parameters
    ----------
    system : CoupledSystem or mechanism model
        A coupled machine with a reduced (dense) frame (for an unreduced frame use
        :func:`femmech.analysis.reference.full_modes`), or a mechanism alone: any object
        with ``M(phi)``, ``B(phi, Omega)`` and ``C(phi, Omega, Omega_dot)`` that map
        angles of shape S to matrices S + (n, n) (a
        :class:`~femmech.mechanisms.RheolinearModel` with one drive, or a chain model);
        see :func:`_sweep_model`. A model may track all its n branches.
    phi : array_like (n_angles,)
        Drive angles, rad, in sweep order (e.g. ``np.linspace(0, 2π, 361)``).
    Omega, Omega_dot : float
        Drive speed (rad/s) and acceleration (rad/s²); Ω = 0 gives the potential part
        of C only (symmetric for position-independent loads).
    n_modes : int, optional
        Number of branches to follow, at most the system's branches (n - 1 of a coupled
        system with n coordinates, n of a model alone). ``None``: :data:`DEFAULT_MODES`, or
        all branches where the system has fewer (said in :attr:`Sweep.notes`).
    damped : bool
        Include B(φ) (first-order form); otherwise B is ignored.
    track : bool
        Follow branches by MAC + frequency continuity; otherwise sort by frequency.
    keep_vectors : bool
        Store the mode shapes (n_angles, n, n_modes).
    frequency_weight : float
        Weight of the relative frequency jump against ``1 - MAC`` in the assignment.
    blas_threads : int or None
        Deprecated (DeprecationWarning): set the threads with
        ``femmech.solve.threads.limit(solve=n)`` or ``FEMMECH_THREADS``. Given, it is the solve
        limit of this call (``None``: leave the libraries alone).

    Returns
    -------
    Sweep
    """
    if not isinstance(system, CoupledSystem):
        return _sweep_model(system, phi, Omega, Omega_dot, n_modes, damped, track,
                            keep_vectors, frequency_weight, blas_threads)
    if system.is_sparse:
        raise ValueError("sweep needs a reduced frame (Superelement or Assembly of"
                         " superelements); use femmech.analysis.reference.full_modes for"
                         " an unreduced frame")
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    n_modes, notes = branch_count(n_modes, system.n - 1, "coupled system",
                                  f"{system.n} coordinates")
    extra = min(n_modes + max(2, n_modes // 2), system.n - (0 if damped else 1))
    with _solve_phase(blas_threads):
        if not damped and (system.H is None or not len(system.H)):
            try:
                result = _lean_loop(_angle_stacks(system, phi, Omega, Omega_dot), system.n,
                                    phi, n_modes, extra, track, keep_vectors, frequency_weight)
                return replace(result, notes=notes)
            except _NotLeanError:
                pass  # e.g. C(φ) unsymmetric at some angle: the general path below
        matrices = _angle_matrices(system, phi, Omega, Omega_dot, damped)
        result = _sweep_loop(matrices, system.n, system.H, phi, n_modes, extra, damped, track,
                             keep_vectors, frequency_weight)
    return replace(result, notes=notes)


def branch_count(n_modes, available: int, what: str, size: str) -> tuple[int, tuple[str, ...]]:
    """``(n_modes, notes)``: the branches to follow and the note that says how a default
    adapted.

    ``n_modes`` None gives :data:`DEFAULT_MODES`, or all ``available`` branches where there
    are fewer (with a note naming the count); an explicit count must lie in
    1..``available``. ``what`` and ``size`` name the system in messages (e.g.
    ``"mechanism model"``, ``"2 coordinates"``).
    """
    if n_modes is None:
        if available < 1:
            raise ValueError(f"the {what} ({size}) has no branch to follow")
        if available >= DEFAULT_MODES:
            return DEFAULT_MODES, ()
        branches = f"{available} branch" + ("es" if available > 1 else "")
        return available, (f"n_modes not given: the {what} ({size}) has {branches}, fewer"
                           f" than the default {DEFAULT_MODES}; all are followed",)
    if isinstance(n_modes, bool) or int(n_modes) != n_modes or not 0 < n_modes <= available:
        raise ValueError(f"n_modes must be an integer in 1..{available} (the {what} has"
                         f" {size}), got {n_modes}")
    return int(n_modes), ()


def _sweep_model(model, phi, Omega, Omega_dot, n_modes, damped, track, keep_vectors,
                 frequency_weight, blas_threads) -> Sweep:
    """:func:`sweep` of a mechanism model alone (no frame, no constraints).

    The model is a duck type: ``M(phi)``, ``B(phi, Omega)`` (read only if ``damped``)
    and ``C(phi, Omega, Omega_dot)``, each called once with all angles (n_angles,) and
    returning (n_angles, n, n); ``n`` (if present) is checked against the matrices.
    """
    if not all(callable(getattr(model, name, None)) for name in ("M", "B", "C")):
        raise TypeError("sweep needs a CoupledSystem or a mechanism model with M(phi),"
                        " B(phi, Omega) and C(phi, Omega, Omega_dot), got"
                        f" {type(model).__name__}")
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    if phi.ndim != 1:
        raise ValueError(f"phi must be 1-D (one drive), got shape {phi.shape}")
    matrices, n = _model_matrices(model, phi, Omega, Omega_dot, damped)
    n_modes, notes = branch_count(n_modes, n, "mechanism model", f"{n} coordinates")
    extra = min(n_modes + max(2, n_modes // 2), n)
    with _solve_phase(blas_threads):
        if not damped:
            try:
                result = _lean_loop(_model_stacks(matrices, n), n, phi, n_modes, extra,
                                    track, keep_vectors, frequency_weight)
                return replace(result, notes=notes)
            except _NotLeanError:
                pass  # e.g. C(φ) unsymmetric at some angle: the general path below
        result = _sweep_loop(matrices, n, None, phi, n_modes, extra, damped, track,
                             keep_vectors, frequency_weight)
    return replace(result, notes=notes)


def _model_stacks(matrices, n: int):
    """``stack(a, b) -> (M, C, symmetric)`` of :func:`_lean_loop` from the per-angle
    ``matrices(a)`` of :func:`_model_matrices` (which index stacks of all angles)."""
    M, C = (matrices(slice(None))[k] for k in (0, 2))
    symmetric = bool(np.array_equal(C, C.transpose(0, 2, 1)))
    return lambda a, b: (M[a:b], C[a:b], symmetric)


def _model_matrices(model, phi, Omega, Omega_dot, damped: bool):
    """``(matrices(a) -> (M, B, C), n)`` of a mechanism model, evaluated for all angles
    in one vectorised call per matrix; B is None unless ``damped``."""
    stacks = {"M": model.M(phi), "C": model.C(phi, Omega, Omega_dot)}
    if damped:
        stacks["B"] = model.B(phi, Omega)
    stacks = {k: np.asarray(v, dtype=float) for k, v in stacks.items()}
    n = stacks["M"].shape[-1] if stacks["M"].ndim else 0
    for name, X in stacks.items():
        if X.shape != (phi.size, n, n):
            raise ValueError(f"the model's {name}(phi) has shape {X.shape} for"
                             f" {phi.size} angles, expected ({phi.size}, n, n)")
    if getattr(model, "n", n) != n:
        raise ValueError(f"the model says n = {model.n} but M(phi) is {n} x {n}")
    B = stacks.get("B")
    return (lambda a: (stacks["M"][a], None if B is None else B[a], stacks["C"][a])), n


def parameter_sweep(system_at, values, phi: float = 0.0, n_modes: int | None = None,
                    damped: bool = False, keep_vectors: bool = False,
                    frequency_weight: float = 0.1, blas_threads=_SOLVE_PHASE) -> Sweep:
    """Quasi-modes at a fixed drive angle over a parameter, with mode tracking.

    Parameters
    ----------
    system_at : callable
        ``system_at(value) -> (CoupledSystem, Omega)``: the machine and drive speed
        (rad/s) for one parameter value, e.g. ``lambda W: (system, W)`` for a drive-speed
        sweep or ``lambda k: (build(k), 0.0)`` for a stiffness. All systems must have the
        same coordinates.
    values : array_like (n_values,)
        Parameter values in sweep order (their own unit).
    phi : float
        Drive angle, rad.
    n_modes, damped, keep_vectors, frequency_weight, blas_threads
        As in :func:`sweep`.

    Returns
    -------
    Sweep
        With ``phi`` holding the parameter values.
    """
    values = np.atleast_1d(np.asarray(values, dtype=float))
    first, _ = system_at(values[0])
    n_modes, notes = branch_count(n_modes, first.n - 1, "coupled system",
                                  f"{first.n} coordinates")
    extra = min(n_modes + max(2, n_modes // 2), first.n - (0 if damped else 1))

    def matrices(a):
        system, Omega = system_at(values[a])
        if system.n != first.n:
            raise ValueError(f"parameter value {values[a]}: the system has {system.n}"
                             f" coordinates, the first one {first.n}")
        return system.matrices(phi, Omega)[:3]

    with _solve_phase(blas_threads):
        result = _sweep_loop(matrices, first.n, first.H, values, n_modes, extra, damped, True,
                             keep_vectors, frequency_weight)
    return replace(result, notes=notes)


@contextmanager
def _solve_phase(blas_threads):
    """:func:`femmech.solve.threads.solve_phase`, with the deprecated ``blas_threads`` (if
    given) as the solve limit."""
    if blas_threads is _SOLVE_PHASE:
        with threads.solve_phase():
            yield
        return
    warnings.warn("blas_threads is deprecated: the sweeps run under femmech.solve.threads"
                  " (femmech.solve.threads.limit(solve=n) or FEMMECH_THREADS='solve=n')",
                  DeprecationWarning, stacklevel=4)
    with threads.limit(solve=blas_threads), threads.solve_phase():
        yield


def _angle_matrices(system: CoupledSystem, phi, Omega, Omega_dot, damped: bool):
    """``matrices(a) -> (M, B, C)`` (n, n) at angle ``phi[a]``, equal to
    :func:`femmech.coupling.assemble_at` to round-off; B is None unless ``damped``.

    The mechanism blocks are evaluated for all angles at once, summed per matrix entry
    they touch (mounts may share coordinates) and added per angle with one indexed
    update to a copy of the constant part.
    """
    n, where, parts = _angle_parts(system, phi, Omega, Omega_dot, damped)

    def matrices(a):
        out = [None] * 3
        for k, (constant, values) in parts.items():
            A = constant.copy()
            A[where] += values[a]
            out[k] = A.reshape(n, n)
        return tuple(out)

    return matrices


def _angle_stacks(system: CoupledSystem, phi, Omega, Omega_dot):
    """``stack(a, b) -> (M, C, symmetric)``: M, C (b - a, n, n), the matrices of
    :func:`_angle_matrices` (bit-identical) at angles ``phi[a:b]``, assembled in one indexed
    update per matrix, and whether every C(φ) is symmetric to the bit (then C is its own
    symmetric part and needs no symmetry check).

    Each matrix is stored transposed (the returned arrays are transposed views, each
    matrix Fortran-contiguous), so that LAPACK reads them without a copy."""
    n, where, parts = _angle_parts(system, phi, Omega, Omega_dot, False)
    transposed = (where % n) * n + where // n  # where each touched entry's mirror lies
    mirror = np.minimum(np.searchsorted(where, transposed), max(where.size - 1, 0))
    constant, values = parts[2]
    symmetric = bool(np.array_equal(constant, constant.reshape(n, n).T.ravel())
                     and np.array_equal(where[mirror], transposed)
                     and (values == values[:, mirror]).all())
    constants = {k: parts[k][0].reshape(n, n).T.ravel() for k in (0, 2)}

    def stack(a, b):
        out = []
        for k in (0, 2):
            A = np.repeat(constants[k][None], b - a, axis=0)
            A[:, transposed] += parts[k][1][a:b]
            out.append(A.reshape(b - a, n, n).transpose(0, 2, 1))
        return (*out, symmetric)

    return stack


def _angle_parts(system: CoupledSystem, phi, Omega, Omega_dot, damped: bool):
    """``(n, where, parts)``: the flat indices ``where`` of the entries the mounts touch and,
    per matrix k (0 M, 1 B if ``damped``, 2 C), its constant part (n², ) and the summed
    mechanism values (n_angles, where.size) of all angles."""
    n, n_angles = system.n, phi.size
    blocks = system.mechanism_blocks(phi, Omega, Omega_dot)
    flat = [(idx[:, None] * n + idx).ravel() for idx in system.touched]
    where = np.unique(np.concatenate([np.zeros(0, dtype=int), *flat]))
    entries = [np.searchsorted(where, f) for f in flat]

    def summed(k):  # (n_angles, where.size): values of matrix k (0 M, 1 B, 2 C)
        out = np.zeros((n_angles, where.size))
        for e, b in zip(entries, blocks, strict=True):
            out[:, e] += b[k].reshape(n_angles, -1)  # e: distinct entries of one mount
        return out

    parts = {k: (A.ravel(), summed(k)) for k, A in enumerate((system.M0, system.B0, system.K0))
             if damped or k != 1}
    return n, where, parts


def _sweep_loop(matrices, n, H, phi, n_modes, extra, damped, track, keep_vectors,
                frequency_weight) -> Sweep:
    n_angles = phi.size
    lam = np.zeros((n_angles, n_modes), dtype=complex)
    freq = np.zeros((n_angles, n_modes))
    ratio = np.zeros((n_angles, n_modes))
    mac_step = np.ones((n_angles, n_modes))
    vectors = np.zeros((n_angles, n, n_modes), dtype=complex) if keep_vectors else None
    forms, previous = set(), None
    limit = n - (0 if damped else 1)
    for a in range(n_angles):
        M, B, C = matrices(a)
        ev, f, r, V, form = frozen_modes(M, B, C, extra, damped, H)
        groups = clusters(f) if track else None
        while track and ev.size == extra < limit and cuts_cluster(groups, f.size, n_modes):
            extra = min(2 * extra, limit)  # complete the cluster (kept for later angles)
            ev, f, r, V, form = frozen_modes(M, B, C, extra, damped, H)
            groups = clusters(f)
        if ev.size < n_modes:
            raise ValueError(f"at {phi[a]:.6g}: only {ev.size} finite quasi-modes (massless"
                             " coordinates have infinite eigenvalues); ask for at most"
                             f" {ev.size} modes")
        forms.add(form)
        if track and previous is not None:
            pick, macs = assign_branches(previous, V, f, groups, M, frequency_weight)
        else:
            pick, macs = np.arange(n_modes), np.ones(n_modes)
        lam[a], freq[a], ratio[a], mac_step[a] = ev[pick], f[pick], r[pick], macs
        previous = (V[:, pick], f[pick])
        if keep_vectors:
            vectors[a] = previous[0]
    form = "damped" if "damped" in forms else ("unsymmetric" if "unsymmetric" in forms
                                                else "symmetric")
    if vectors is not None and form == "symmetric":
        vectors = vectors.real
    return Sweep(phi, freq, lam, ratio, vectors, mac_step, form)


LEAN_CHUNK = 64
"""Most angles per batch of the lean path (:func:`_lean_loop`): the matrices and the
M-products of one batch are formed at once."""

LEAN_BATCH_BYTES = 2 * 2**20
"""A batch holds at most this many bytes per stack of matrices (fewer angles for large n,
so that a batch's matrices stay in cache between the steps that pass over them)."""


class _NotLeanError(Exception):
    """An angle needs the general path of :func:`_sweep_loop` (C(φ) not symmetric,
    ``C - σM`` not positive definite, infinite eigenvalues, no mass)."""


def _lean_loop(stack, n, phi, n_modes, extra, track, keep_vectors, weight) -> Sweep:
    """:func:`_sweep_loop` for undamped, unconstrained, symmetric sweeps, batched.

    ``stack(a, b) -> (M, C, symmetric)`` gives the matrices (b - a, n, n) of angles a..b-1
    and whether all C are symmetric to the bit (:func:`_angle_stacks`). Per batch
    of angles the shifts, scales, LAPACK inputs and M-products are formed at once and the
    solves call LAPACK directly (:func:`_lean_solve`: the calls of
    :func:`~femmech.solve.dense.dense_symmetric`, bit-identical eigenpairs); only the
    assignment is per angle. A batch grows from 1 angle to :data:`LEAN_CHUNK` and starts
    anew where a cluster is cut (the candidates are then doubled, as in
    :func:`_sweep_loop`); the first angle is solved by :func:`frozen_modes` itself
    (:func:`_first_angle`). Raises :class:`_NotLeanError` if an angle needs the general
    path.
    """
    n_angles, limit = phi.size, n - 1
    out = {"lam": np.zeros((n_angles, n_modes), dtype=complex),
           "freq": np.zeros((n_angles, n_modes)), "ratio": np.zeros((n_angles, n_modes)),
           "mac": np.ones((n_angles, n_modes)),
           "vectors": np.zeros((n_angles, n, n_modes)) if keep_vectors else None}
    a, size, previous = 0, 1, None
    while a < n_angles:
        b = min(a + size, n_angles)
        M, C, symmetric = stack(a, b)
        lam, X, f, r = (_first_angle(M[0], C[0], extra) if b == 1
                        else _lean_solve(M, C, extra, symmetric))
        split = splits(f)
        if track and extra < limit:
            cut = ~split[:, n_modes - 1:].any(axis=1)  # = cuts_cluster of each angle
            if cut[0]:
                extra, size = min(2 * extra, limit), 1
                continue
            if cut.any():
                b = a + int(np.argmax(cut))
                M, lam, X, f, r, split = (x[: b - a] for x in (M, lam, X, f, r, split))
        if track:
            previous = track_batch(M, X, f, split, previous, (a, lam, r), n_modes, weight, out)
        else:
            _store(out, slice(a, b), np.arange(n_modes), lam, f, r, X, None)
        a, size = b, min(2 * size, LEAN_CHUNK, max(4, LEAN_BATCH_BYTES // (8 * n * n)))
    return Sweep(phi, out["freq"], out["lam"], out["ratio"], out["vectors"], out["mac"],
                 "symmetric")


def _first_angle(M, C, extra):
    """The first angle by :func:`frozen_modes` itself, as a batch of one (the results of
    :func:`_lean_solve`, bit-identical); raises :class:`_NotLeanError` where the general
    path is needed."""
    ev, f, r, V, form = frozen_modes(M, None, C, extra)
    if form != "symmetric" or ev.size != min(extra, len(M)) or np.iscomplexobj(V):
        raise _NotLeanError("the first angle needs the general path")
    return ev[None], V[None], f[None], r[None]


def _store(out, at, pick, lam, f, r, X, mac):
    """Write candidates ``pick`` (p,) of λ, f, ratio (..., q) and X (..., n, q) as the
    branches at angles ``at`` (an index or a slice), with their MAC step if not None."""
    out["lam"][at], out["freq"][at], out["ratio"][at] = lam[..., pick], f[..., pick], r[..., pick]
    if mac is not None:
        out["mac"][at] = mac
    if out["vectors"] is not None:
        out["vectors"][at] = X[..., pick]


def _lean_solve(M, C, extra, symmetric: bool = False):
    """:func:`frozen_modes` (undamped, symmetric) of a batch of angles, bit-identical.

    M, C (k, n, n); ``symmetric``: every C is symmetric to the bit (so that it is its own
    symmetric part ``(C + Cᵀ)/2``, and the symmetry check passes). Returns λ (k, q) complex,
    mass-normalised vectors (k, n, q), frequency (Hz) and damping ratio (k, q), ascending,
    q = min(extra, n). The shift σ, the λ scale and the LAPACK inputs are formed for the
    batch at once; the driver follows :data:`~femmech.solve.dense.ALL_PAIRS_FRACTION` as
    in :func:`~femmech.solve.dense.dense_symmetric`
    (:func:`~femmech.solve.dense.shift_inverted_stack`). Raises :class:`_NotLeanError` where
    the general path is needed (it then raises or falls back as before).
    """
    k, n = M.shape[:2]
    K = C if symmetric else _symmetric_part(C)
    dm, dk = np.diagonal(M, axis1=1, axis2=2), np.diagonal(K, axis1=1, axis2=2)
    sigma, scale = _lean_shifts(dm, dk)
    wanted = min(extra, n)
    # LAPACK's inputs in Fortran order, C-contiguous stacks of the transposes: Mf[i].T is
    # M[i] (a copy: LAPACK overwrites it), Af[i].T is K[i] - σ M[i] (K[i] = K[i]ᵀ)
    Mt = M.transpose(0, 2, 1)
    Mf = Mt.copy() if Mt.flags.c_contiguous else np.ascontiguousarray(Mt)
    Af = np.multiply(Mf, sigma[:, None, None])
    np.subtract(K.transpose(0, 2, 1), Af, out=Af)
    try:
        mu, X = dense.shift_inverted_stack(Mf, Af, wanted)
    except PencilError as exc:
        raise _NotLeanError(str(exc)) from exc
    top = np.maximum(np.abs(mu).max(axis=1), 1e-300)[:, None]
    if not (mu > tolerances.INFINITE_MU_RTOL * top).all():
        raise _NotLeanError("infinite eigenvalues (massless coordinates)")
    omega2 = sigma[:, None] + 1.0 / mu
    X = X / np.sqrt(mu)[:, None, :]
    order = np.argsort(omega2, axis=1)
    omega2 = np.take_along_axis(omega2, order, axis=1)
    freq, ratio = _undamped(omega2, scale[:, None])
    return (omega2.astype(complex), np.take_along_axis(X, order[:, None, :], axis=2), freq,
            ratio)


def _symmetric_part(C):
    """``(C + Cᵀ)/2`` of each matrix of C (k, n, n); raises :class:`_NotLeanError` unless
    every C is symmetric within :data:`SYMMETRY_RTOL` (the test of :func:`frozen_modes`)."""
    k = len(C)
    CT = C.transpose(0, 2, 1)
    skew = C - CT
    np.abs(skew, out=skew)
    skew = skew.reshape(k, -1).max(axis=1)
    if not (skew <= SYMMETRY_RTOL * np.maximum(np.abs(C).reshape(k, -1).max(axis=1),
                                                1e-300)).all():
        raise _NotLeanError("C(φ) not symmetric")
    return 0.5 * (C + CT)


def _lean_shifts(dm, dk):
    """Shift σ (:func:`~femmech.solve.pencil.default_shift`) and λ scale
    (:func:`_lambda_scale`) of each angle from the diagonals of M and K (k, n), the
    medians of all angles at once where the coordinates with mass and stiffness agree."""
    ok = (dm > 0) & (dk > 0)
    if not (dm > 0).any(axis=1).all():
        raise _NotLeanError("no mass")
    if (ok == ok[0]).all():
        typical = (np.median(dk[:, ok[0]] / dm[:, ok[0]], axis=1) if ok[0].any()
                   else np.ones(len(dk)))
    else:
        typical = np.array([np.median(k[o] / m[o]) if o.any() else 1.0  # eigenvalue_scale
                            for k, m, o in zip(dk, dm, ok, strict=True)])
    ratio = np.divide(np.abs(dk), dm, out=np.full(dm.shape, -np.inf), where=dm > 0)
    top = ratio.max(axis=1)
    return -1e-6 * typical, np.where(top > 0, top, 1.0)


def frequency_sensitivities(build, p: float, phi: float, n_modes: int, Omega: float = 0.0,
                            rel_step: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """Quasi-eigenfrequencies and their derivatives with respect to a parameter.

    For ``C v = λ M v`` with symmetric C and mass-normalised v,
    ``dλ/dp = vᵀ (dC/dp - λ dM/dp) v`` (Fox & Kapoor, AIAA J. 6 (1968) 2426), and
    ``df/dp = dλ/dp / (8 π² f)``. The matrix derivatives are central differences of the
    coupled matrices (cheap: no eigen solve), so any parameter of the frame, the
    mounts or the mechanisms can be studied through ``build``.

    Parameters
    ----------
    build : callable
        ``build(p) -> CoupledSystem`` (reduced frame).
    p : float
        Parameter value (its own unit).
    phi : float
        Drive angle, rad.
    n_modes : int
    Omega : float
        Drive speed, rad/s (C must stay symmetric: use 0 or a symmetric case).
    rel_step : float
        Relative step of the matrix differences (``h = rel_step * max(|p|, 1)``).

    Returns
    -------
    freq_hz : ndarray (n_modes,)
    dfreq_dp : ndarray (n_modes,), Hz per unit of p
    """
    M, _, C, _ = build(p).matrices(phi, Omega)
    lam, freq, _, V, form = frozen_modes(M, M, C, n_modes)
    if form != "symmetric":
        raise ValueError("sensitivities need a symmetric C(φ); use Omega = 0")
    h = rel_step * max(abs(p), 1.0)
    Mp, _, Cp, _ = build(p + h).matrices(phi, Omega)
    Mm, _, Cm, _ = build(p - h).matrices(phi, Omega)
    dM, dC = (Mp - Mm) / (2 * h), (Cp - Cm) / (2 * h)
    dlam = np.einsum("ij,ij->j", V, (dC @ V) - (dM @ V) * lam.real)
    return freq, dlam / (8 * np.pi**2 * freq)
