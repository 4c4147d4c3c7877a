"""Time integration of the nonlinear mechanism equations (seed 5.2.1).

Two forms of the equations of motion of a rigid (or partly elastic) mechanism are
integrated with ``scipy.integrate`` on their first-order form y = (q, q̇):

* **2nd kind** (eq. 13, minimal coordinates): M(q) q̈ + h(q, q̇) + W_pot,j = Q*(q, q̇),
  with the drive ("program") coordinates prescribed by a drive law; the drive rows give
  the generalized drive forces (e.g. the crane's cylinder force, 5.2.3.1 eq. 17).
  :func:`integrate_second_kind`.
* **Mixed type** (eqs. 14–21, redundant coordinates and multipliers): at every state the
  symmetric, indefinite system (eq. "25", errata 5)

      [ M  Hᵀ ] [ q̈ ]   [ Q* − W_pot,j − h ]
      [ H  0  ] [ λ ] = [ −h_ik,l q̇_k q̇_l  ]

  is solved for q̈ and the joint forces λ. :func:`integrate_mixed`.

The mixed form enforces the constraints f(q) = 0 only at the acceleration level, so the
integration error makes f(q) and H q̇ drift away from zero (a quadratic growth in time is
typical). Three treatments (Hairer & Wanner, *Solving ODEs II*, 2nd ed., Springer 1996,
sec. VII.2; Baumgarte, Comput. Meth. Appl. Mech. Eng. 1 (1972) 1):

* ``"projection"``: after every accepted step of the integrator (stepped one step at a
  time through its ``OdeSolver`` class) the state is projected back onto the
  constraint manifold, positions by the mass-weighted least-distance problem
  min ½ (q − q*)ᵀ M (q − q*) s.t. f(q) = 0 (Gauss–Newton, i.e. SQP with the Hessian M),
  velocities by min ½ (q̇ − q̇*)ᵀ M (q̇ − q̇*) s.t. H q̇ = 0 (one linear solve). Both use the
  saddle-point matrix of the equations of motion. The drift stays at round-off.
  Projecting after every step, not only at the output times, keeps every step's error
  estimate on a consistent state and makes the result independent of the output grid
  (between sparse output times the drift would grow as without stabilization).
* ``"baumgarte"``: the acceleration row is replaced by
  H q̈ = −h_ik,l q̇_k q̇_l − 2α H q̇ − β² f, so the constraint error e = f obeys
  ë + 2α ė + β² e = 0 (driven by the truncation error): bounded, not zero.
* ``"none"``: the plain index-1 form, to show the drift.

Units SI (m, rad, s, N, N·m); symbols of the chapter: M mass, Q* generalized forces,
H = (h_ij) constraint Jacobian, λ multipliers.

Uses only mechanisms (the models it integrates); nothing here writes
files.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import integrate

from femmech.mechanisms.models import LagrangeModel, MixedModel

__all__ = [
    "MixedResult",
    "SecondKindResult",
    "integrate_mixed",
    "integrate_second_kind",
    "project_positions",
    "project_velocities",
]

EPS = np.finfo(float).eps
METHODS = {"RK23": integrate.RK23, "RK45": integrate.RK45, "DOP853": integrate.DOP853,
           "Radau": integrate.Radau, "BDF": integrate.BDF, "LSODA": integrate.LSODA}
ONE_STEP = ("RK23", "RK45", "DOP853", "Radau")
STABILIZATIONS = ("projection", "baumgarte", "none")


@dataclass(frozen=True)
class SecondKindResult:
    """Time history of the 2nd-kind equations (seed 5.2.1 eq. 13).

    Attributes
    ----------
    t : ndarray (n_t,)
        Output times, s (the requested grid, cut at a terminal event).
    q, qd, qdd : ndarray (n_t, n)
        Free (non-drive) coordinates, their velocities and accelerations (m, rad, per s).
    drive_q, drive_qd, drive_qdd : ndarray (n_t, F)
        Prescribed drive coordinates, velocities and accelerations (F = 0 without drives).
    drive_forces : ndarray (n_t, F)
        Generalized forces (N or N·m) the drives supply to enforce their motion: the drive
        rows of eq. 13, Σ_k m_pk q̈_k + h_p + W_pot,p − Q*_p.
    coordinate_names, drive_names : tuple of str
        Names of the columns of ``q`` and of ``drive_q``.
    t_events : tuple of ndarray
        Event times, one array per event function (empty without events).
    nfev : int
        Number of right-hand-side evaluations.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    drive_q: np.ndarray
    drive_qd: np.ndarray
    drive_qdd: np.ndarray
    drive_forces: np.ndarray
    coordinate_names: tuple[str, ...]
    drive_names: tuple[str, ...]
    t_events: tuple[np.ndarray, ...]
    nfev: int


@dataclass(frozen=True)
class MixedResult:
    """Time history of the mixed-type equations (seed 5.2.1 eqs. 14–21).

    Attributes
    ----------
    t : ndarray (n_t,)
        Output times, s.
    q, qd, qdd : ndarray (n_t, N)
        All coordinates (including the redundant ones), velocities, accelerations.
    multipliers : ndarray (n_t, n_c)
        Lagrange multipliers λ_i, the joint forces in the units of the constraint
        normalisation (N for constraints f_i in m).
    constraint_drift : ndarray (n_t,)
        max_i |f_i(q)|, in the units of f.
    velocity_drift : ndarray (n_t,)
        max_i |Σ_j h_ij q̇_j|, in the units of f per second.
    coordinate_names : tuple of str
    stabilization : str
        ``"projection"``, ``"baumgarte"`` or ``"none"``.
    nfev : int
        Number of right-hand-side evaluations.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    multipliers: np.ndarray
    constraint_drift: np.ndarray
    velocity_drift: np.ndarray
    coordinate_names: tuple[str, ...]
    stabilization: str
    nfev: int


def _times(t) -> np.ndarray:
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise ValueError(f"t must be a 1-D array of at least two times, got shape {t.shape}")
    if not np.isfinite(t).all():
        raise ValueError("t contains non-finite times")
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        i = bad[0]
        raise ValueError(f"t must be strictly increasing: t[{i}] = {t[i]} s, "
                         f"t[{i + 1}] = {t[i + 1]} s")
    return t


def _state(label: str, value, names: tuple[str, ...]) -> np.ndarray:
    x = np.asarray(value, dtype=float)
    if x.shape != (len(names),):
        raise ValueError(f"{label} must have shape ({len(names)},) for the coordinates "
                         f"{names}, got {x.shape}")
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        raise ValueError(f"{label} of coordinate {names[bad[0]]!r} is not finite")
    return x.copy()


def _method(method: str, stabilization: str = "none"):
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; use one of {sorted(METHODS)}")
    if stabilization == "projection" and method not in ONE_STEP:
        raise ValueError(f"projection restarts the integrator after every step, which drops "
                         f"the multistep method {method!r} to order 1; use one of {ONE_STEP}")
    return METHODS[method]


def _check_finite(time: float, y: np.ndarray, names: tuple[str, ...], what: str):
    """Raise ValueError naming the first non-finite entry of ``y`` (q then q̇ halves)."""
    bad = np.flatnonzero(~np.isfinite(y))
    if bad.size:
        n, i = len(names), bad[0]
        kind = what if what != "state" else ("position" if i < n else "velocity")
        raise ValueError(f"non-finite {kind} of coordinate {names[i % n]!r} at t = {time:.6g} s")


def _drive_values(drive, t: np.ndarray, n_drives: int) -> tuple[np.ndarray, ...]:
    """(q_d, q̇_d, q̈_d), each (n_t, F), from a drive law or a tuple of three callables."""
    if isinstance(drive, tuple):
        if len(drive) != 3 or not all(callable(f) for f in drive):
            raise TypeError("give the drive as a law object or a tuple of three callables "
                            "(q(t), qd(t), qdd(t))")
        out = tuple(f(t) for f in drive)
    elif callable(drive):
        out = tuple(drive(t))
        if len(out) != 3:
            raise TypeError(f"the drive law must return (q, qd, qdd), got {len(out)} arrays")
    else:
        raise TypeError(f"drive must be a drive law (callable t -> (q, qd, qdd)) or a tuple of "
                        f"three callables, got {type(drive).__name__}")
    shape = t.shape + (n_drives,)
    arrays = []
    for name, x in zip(("position", "speed", "acceleration"), out, strict=True):
        a = np.asarray(x, dtype=float)
        try:
            a = np.broadcast_to(a[..., None] if n_drives == 1 and a.ndim <= t.ndim else a,
                                shape)
        except ValueError:
            raise ValueError(f"the drive law's {name} has shape {a.shape}; expected "
                             f"{t.shape} or {shape} for {n_drives} drive(s)") from None
        if not np.isfinite(a).all():
            k = np.flatnonzero(~np.isfinite(a).all(axis=-1))[0]
            raise ValueError(f"the drive law gives a non-finite {name} at t = {t[k]:.6g} s")
        arrays.append(a)
    return tuple(arrays)


def _solve_ivp(rhs, t, y0, method, rtol, atol, max_step, events=None):
    sol = integrate.solve_ivp(rhs, (t[0], t[-1]), y0, method=method, t_eval=t, rtol=rtol,
                              atol=atol, max_step=max_step, events=events)
    if sol.status < 0:
        raise RuntimeError(f"{method} failed at t = {sol.t[-1] if sol.t.size else t[0]:.6g} s: "
                           f"{sol.message}")
    return sol


def integrate_second_kind(model: LagrangeModel, t, q0, qd0, drive=None, method: str = "DOP853",
                          rtol: float = 1e-9, atol: float = 1e-12, events=None,
                          max_step: float = np.inf) -> SecondKindResult:
    """Integrate the nonlinear 2nd-kind equations (seed 5.2.1 eq. 13) over the grid ``t``.

    The free coordinates follow M_ff q̈_f = Q*_f − W_pot,f − h_f − M_fd q̈_d, with the drive
    coordinates q_d(t) prescribed (feedback of the vibrations on the drive neglected, as
    for the crane's cylinder, 5.2.3.1); the drive rows give the drive forces.

    Parameters
    ----------
    model : LagrangeModel
        From :func:`~femmech.mechanisms.second_kind`.
    t : array_like (n_t,)
        Strictly increasing output times, s; the integration runs from t[0] to t[-1] and
        the solution is sampled on ``t`` with the method's dense output.
    q0, qd0 : array_like (n,)
        Initial free coordinates and velocities, in the order of
        ``mechanism.vibration_coordinates`` (all coordinates when there are no drives).
    drive : callable or tuple, optional
        Required iff the mechanism has drives: a law ``drive(t) -> (q, qd, qdd)`` such as
        :class:`~femmech.analysis.response.ConstantSpeed` or
        :class:`~femmech.analysis.response.SpeedRamp` (each array (n_t,) for one drive,
        (n_t, F) for F drives), or a tuple of three callables of t.
    method : str
        ``solve_ivp`` method: "DOP853" (default, non-stiff), "Radau" (stiff), "RK45", ….
    rtol, atol : float
        Relative and absolute tolerances of the integrator (atol in m, rad, m/s, rad/s).
    events : callable or list, optional
        ``solve_ivp`` events ``event(t, y)`` with y = (q, q̇) of the free coordinates,
        shape (2n,); a terminal event cuts the output grid.
    max_step : float
        Largest step, s.

    Returns
    -------
    SecondKindResult

    Raises
    ------
    ValueError
        For wrong shapes, a non-increasing ``t``, a missing or superfluous drive, or a state
        or acceleration that becomes non-finite (naming the coordinate and the time).
    RuntimeError
        If the integrator fails.
    """
    if not isinstance(model, LagrangeModel):
        raise TypeError(f"model must be a LagrangeModel (second_kind), got {type(model).__name__}")
    t = _times(t)
    mech = model.mechanism
    coords = mech.coordinates
    d = [coords.index(x) for x in mech.drives]
    f = [i for i in range(model.N) if i not in d]
    names = tuple(coords[i].name for i in f)
    drive_names = tuple(x.name for x in mech.drives)
    q0, qd0 = _state("q0", q0, names), _state("qd0", qd0, names)
    if d and drive is None:
        raise ValueError(f"the mechanism has the drive coordinates {drive_names}; give drive=")
    if not d and drive is not None:
        raise ValueError("the mechanism has no drive coordinates; drive must be None")
    n, F = len(f), len(d)
    grid_drive = _drive_values(drive, t, F) if d else (np.zeros((t.size, 0)),) * 3

    def full(time, y):
        q, qd = np.empty(y.shape[:-1] + (model.N,)), np.empty(y.shape[:-1] + (model.N,))
        q[..., f], qd[..., f] = y[..., :n], y[..., n:]
        a_d = None
        if d:
            qq, vv, a_d = _drive_values(drive, np.atleast_1d(time), F)
            if y.ndim == 1:
                qq, vv, a_d = qq[0], vv[0], a_d[0]
            q[..., d], qd[..., d] = qq, vv
        with np.errstate(all="ignore"):
            return model.accelerations(q, qd, a_d)

    def rhs(time, y):
        _check_finite(time, y, names, "state")
        qdd = full(time, y).qdd[f]
        _check_finite(time, qdd, names, "acceleration")
        return np.concatenate([y[n:], qdd])

    sol = _solve_ivp(rhs, t, np.concatenate([q0, qd0]), method, rtol, atol, max_step, events)
    y = sol.y.T
    for k in range(y.shape[0]):
        _check_finite(sol.t[k], y[k], names, "state")
    k = sol.t.size
    acc = full(sol.t, y)
    return SecondKindResult(sol.t, y[:, :n], y[:, n:], acc.qdd[:, f], *(x[:k] for x in grid_drive),
                            acc.drive_forces.reshape(k, F), names, drive_names,
                            tuple(sol.t_events) if events is not None else (), sol.nfev)


# ------------------------------------------------------------------ mixed type


def _mixed_accelerations(model: MixedModel, q, qd, baumgarte=None):
    """q̈ (N,) and λ (n_c,) of eq. "25", with the Baumgarte row if (α, β) are given."""
    sol = model.solve(q, qd)
    if baumgarte is None:
        return sol.qdd, sol.multipliers
    alpha, beta = baumgarte
    N = q.size
    b = sol.b.copy()
    b[N:] -= 2 * alpha * (sol.A[N:, :N] @ qd) + beta**2 * model.constraints(q)
    x = np.linalg.solve(sol.A, b)
    return x[:N], x[N:]


def _saddle(M, H):
    n_c = H.shape[0]
    return np.block([[M, H.T], [H, np.zeros((n_c, n_c))]])


def project_positions(model: MixedModel, q, maxiter: int = 20) -> np.ndarray:
    """Closest point of the constraint manifold f(q) = 0 in the mass metric M(q*).

    Solves min ½ (q − q*)ᵀ M (q − q*) s.t. f(q) = 0 by Gauss–Newton (SQP with the Hessian
    M): [[M, Hᵀ], [H, 0]] [Δ; μ] = [−M (q_k − q*); −f(q_k)], q_{k+1} = q_k + Δ, with H at
    q_k, until the correction reaches round-off. ``q`` has shape (N,).

    Raises
    ------
    RuntimeError
        If the iteration does not converge within ``maxiter`` steps.
    """
    q_star = np.asarray(q, dtype=float)
    M = model.lagrange.M(q_star)
    q, previous = q_star.copy(), np.inf
    N = q.size
    for _ in range(maxiter):
        H = model.jacobian(q)
        rhs = np.concatenate([-M @ (q - q_star), -model.constraints(q)])
        dq = np.linalg.solve(_saddle(M, H), rhs)[:N]
        q = q + dq
        step, floor = np.abs(dq).max(initial=0.0), 16 * EPS * (1 + np.abs(q).max())
        # converged, or stalled at the round-off floor (ill-conditioned H)
        if step <= floor or (step >= previous and step <= 1e4 * floor):
            return q
        previous = step
    f = model.constraints(q)
    i = int(np.argmax(np.abs(f)))
    raise RuntimeError(f"position projection did not converge in {maxiter} iterations: "
                       f"constraint {i} residual {f[i]:.3e}, last correction {step:.3e}")


def project_velocities(model: MixedModel, q, qd) -> np.ndarray:
    """Velocities closest to ``qd`` in the mass metric with H(q) q̇ = 0 (shape (N,))."""
    q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
    M, H = model.lagrange.M(q), model.jacobian(q)
    rhs = np.concatenate([M @ qd, np.zeros(H.shape[0])])
    return np.linalg.solve(_saddle(M, H), rhs)[:q.size]


def _project_state(model: MixedModel, y: np.ndarray) -> np.ndarray:
    N = y.size // 2
    q = project_positions(model, y[:N])
    return np.concatenate([q, project_velocities(model, q, y[N:])])


def _check_consistent(model: MixedModel, q0, qd0, tol: float):
    exprs = model.lagrange.mechanism.constraints
    for label, r in (("position", model.constraints(q0)),
                     ("velocity", model.jacobian(q0) @ qd0)):
        bad = np.flatnonzero(np.abs(r) > tol)
        if bad.size:
            i = bad[np.argmax(np.abs(r[bad]))]
            what = "f" if label == "position" else "H q̇ of"
            raise ValueError(f"inconsistent initial {label}s: {what} constraint {i} ({exprs[i]}) "
                             f"has residual {r[i]:.3e} > {tol:g}; correct q0/qd0 or pass "
                             "project_initial=True")


def _projected_run(model, rhs, t, y0, solver_class, rtol, atol, max_step):
    """Step by step with the OdeSolver class, projecting after every accepted step.

    Each step starts a fresh solver from the projected state with the step size the
    controller proposed, so the solvers' internal state is never overwritten (for the RK
    methods this costs one extra evaluation per step, the one FSAL would save; Radau
    re-evaluates its Jacobian). Output points inside a step are taken from the step's
    dense output and projected too.
    """
    ys = np.empty((t.size, y0.size))
    ys[0] = y0
    k, t_cur, y_cur, h, nfev = 1, t[0], y0, None, 0
    while k < t.size:
        solver = solver_class(rhs, t_cur, y_cur, t[-1], rtol=rtol, atol=atol,
                              max_step=max_step, first_step=h)
        message = solver.step()
        nfev += solver.nfev
        if solver.status == "failed":
            raise RuntimeError(f"{solver_class.__name__} failed at t = {t_cur:.6g} s: {message}")
        hi = int(np.searchsorted(t, solver.t, side="right"))
        if hi > k:
            dense = solver.dense_output()
            for j in range(k, hi):
                ys[j] = _project_state(model, dense(t[j]))
            k = hi
        t_cur, y_cur = solver.t, _project_state(model, solver.y)
        # the step size the controller proposes next (h_abs of the RK and Radau classes)
        h = min(getattr(solver, "h_abs", solver.step_size), t[-1] - t_cur)
    return ys, nfev


def integrate_mixed(model: MixedModel, t, q0, qd0, stabilization: str = "projection",
                    baumgarte: tuple[float, float] = (10.0, 10.0), method: str = "DOP853",
                    rtol: float = 1e-9, atol: float = 1e-12, max_step: float = np.inf,
                    project_initial: bool = False, tol_initial: float = 1e-9) -> MixedResult:
    """Integrate the mixed-type equations (seed 5.2.1 eqs. 14–21) with drift control.

    Parameters
    ----------
    model : MixedModel
        From :func:`~femmech.mechanisms.mixed_type` (scleronomic constraints, no drives).
    t : array_like (n_t,)
        Strictly increasing output times, s.
    q0, qd0 : array_like (N,)
        Initial coordinates and velocities (all coordinates, redundant ones included).
    stabilization : {"projection", "baumgarte", "none"}
        Drift control (module docstring). ``"projection"`` projects after every accepted
        step and at the output points (one-step methods only).
    baumgarte : (float, float)
        (α, β), 1/s, of the Baumgarte row H q̈ = −h_ik,l q̇_k q̇_l − 2α H q̇ − β² f; α = β
        damps the constraint error critically with the time constant 1/α. Keep 1/α well
        above the step size (explicit methods) and below the time scale of the motion.
    method : str
        ``solve_ivp`` method ("DOP853" default; "Radau" for stiff problems).
    rtol, atol : float
        Integrator tolerances (atol in the units of q and q̇).
    max_step : float
        Largest step, s.
    project_initial : bool
        Project q0 and qd0 onto f = 0, H q̇ = 0 (mass-weighted) instead of rejecting an
        inconsistent initial state.
    tol_initial : float
        Largest accepted |f_i(q0)| and |(H qd0)_i| without ``project_initial`` (units of f,
        and of f per second).

    Returns
    -------
    MixedResult
        q̈ and λ at the output points are those of the integrated (stabilised) equations.

    Raises
    ------
    ValueError
        For wrong shapes, unknown stabilization or method, bad Baumgarte parameters, an
        inconsistent initial state (naming the constraint and its residual) or a state that
        becomes non-finite (naming the coordinate and the time).
    RuntimeError
        If the integrator or the projection fails.
    """
    if not isinstance(model, MixedModel):
        raise TypeError(f"model must be a MixedModel (mixed_type), got {type(model).__name__}")
    if stabilization not in STABILIZATIONS:
        raise ValueError(f"unknown stabilization {stabilization!r}; use one of {STABILIZATIONS}")
    solver_class = _method(method, stabilization)
    ab = None
    if stabilization == "baumgarte":
        ab = tuple(float(x) for x in np.asarray(baumgarte, dtype=float).ravel())
        if len(ab) != 2 or not all(np.isfinite(x) and x >= 0 for x in ab):
            raise ValueError(f"baumgarte must be two finite non-negative rates (alpha, beta) "
                             f"in 1/s, got {baumgarte!r}")
    t = _times(t)
    names = tuple(x.name for x in model.lagrange.mechanism.coordinates)
    q0, qd0 = _state("q0", q0, names), _state("qd0", qd0, names)
    if project_initial:
        q0 = project_positions(model, q0)
        qd0 = project_velocities(model, q0, qd0)
    else:
        _check_consistent(model, q0, qd0, tol_initial)
    y0 = np.concatenate([q0, qd0])
    N = q0.size

    def rhs(time, y):
        _check_finite(time, y, names, "state")
        try:
            qdd, _ = _mixed_accelerations(model, y[:N], y[N:], ab)
        except np.linalg.LinAlgError:
            raise ValueError(f"the matrix [[M, Hᵀ], [H, 0]] is singular at t = {time:.6g} s: "
                             "redundant constraints or a singular M") from None
        _check_finite(time, qdd, names, "acceleration")
        return np.concatenate([y[N:], qdd])

    if stabilization == "projection":
        y0 = _project_state(model, y0)
        ys, nfev = _projected_run(model, rhs, t, y0, solver_class, rtol, atol, max_step)
    else:
        sol = _solve_ivp(rhs, t, y0, method, rtol, atol, max_step)
        ys, nfev = sol.y.T, sol.nfev
    for k in range(t.size):
        _check_finite(t[k], ys[k], names, "state")
    q, qd = ys[:, :N], ys[:, N:]
    out = [_mixed_accelerations(model, q[k], qd[k], ab) for k in range(t.size)]
    drift = np.abs(model.constraints(q)).max(axis=-1, initial=0.0)
    vdrift = np.abs(np.einsum("kij,kj->ki", model.jacobian(q), qd)).max(axis=-1, initial=0.0)
    return MixedResult(t, q, qd, np.array([o[0] for o in out]), np.array([o[1] for o in out]),
                       drift, vdrift, names, stabilization, nfev)

