"""Prescribed-drive load cases with a trip event and braking (nonlinear, 2nd kind).

A mechanism whose drive coordinate is prescribed (a hydraulic cylinder's length, a press
crank's angle) is run along a programme, and a protective device acts on the force the
drive supplies: a crane's load-moment limiter (a pressure cell) or a press's overload
clutch trips when that force reaches a limit, and the drive is then braked to rest. The
inertia forces of the braking lift the drive force above its quasi-static value; they
are what the brake and the structure are dimensioned for (the mobile crane of the
textbook chapter, section 5.2.3.1).

The load case, for the 2nd-kind equations (chapter section 5.2.1 eq. 13; the drive rows
give the drive forces, e.g. the crane's cylinder force, 5.2.3.1 eq. 17):

1. static rest at the drive's start value, W_pot,j − Q*_j(q, 0) = 0 for the free
   coordinates j (:func:`static_rest`, Newton's method);
2. the drive speed ramped from 0 to ``speed`` over ``ramp_time`` by the cycloidal
   :class:`~femmech.analysis.response.SpeedRamp` (no jerk steps), then held;
3. trip when the chosen drive force reaches ``limit`` (a terminal event of the
   integrator; a positive limit is reached from below, a negative one from above);
   if it is not reached before the drive arrives at ``end`` (end of travel) or
   ``t_max``, the result says so (``tripped`` False, ``message``) and nothing is braked;
4. for each braking time: cycloidal deceleration from the drive speed at the trip to
   rest, then ``t_after`` at rest (:func:`trip_and_brake`). The braking starts with zero
   deceleration, so a trip during the start-up ramp makes the drive acceleration jump to
   zero there (the speed and position stay continuous).

The drives other than the driven one (if any) are held at constant values. Integrator:
``scipy.integrate.solve_ivp`` (default DOP853) on (q_f, q̇_f) of the free coordinates,
with dense output so that the braking starts from the state at the trip time exactly.
The accuracy is stated by the tolerances and, on request (``verify=True``), measured
against a second run at ten times tighter tolerances (:class:`Accuracy`).

Units SI: m, rad, s, N, N·m; drive forces in N for a translational drive, N·m for a
rotational one.

Uses mechanisms (the 2nd-kind model and its springs) and
analysis.response (the drive law); nothing here writes files.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy import integrate, optimize

from femmech.analysis.response import SpeedRamp
from femmech.mechanisms.evaluate import compile_expressions
from femmech.mechanisms.models import LagrangeModel
from femmech.mechanisms.symbolic import Spring

__all__ = ["Accuracy", "BrakingRun", "History", "TripAndBrake", "spring_forces",
           "static_drive_forces", "static_rest", "travel_time", "trip_and_brake"]

EPS = np.finfo(float).eps


@dataclass(frozen=True)
class History:
    """Time history of all coordinates of a 2nd-kind model under prescribed drives.

    Attributes
    ----------
    t : ndarray (n_t,)
        Times, s.
    q, qd : ndarray (n_t, N)
        All coordinates (drives included, in the order of ``mechanism.coordinates``) and
        their velocities (m, rad and per s).
    drive_forces : ndarray (n_t, F)
        Generalized forces the drives supply (N or N·m), in the order of the drives.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    drive_forces: np.ndarray


@dataclass(frozen=True)
class BrakingRun:
    """One braking time: the whole history from the start, trip and braking included.

    Attributes
    ----------
    brake_time : float
        Duration of the cycloidal deceleration to rest, s.
    t_stop : float
        End of braking (trip time + ``brake_time``), s.
    history : History
        From t = 0 to ``t_stop + t_after``; the approach samples are shared by all runs.
    peak_force : float
        Extreme of the tripping drive force at or after the trip, in the direction of the
        limit (the largest value for a positive limit), N or N·m.
    static_force_end : float
        Quasi-static drive force at the static rest of the final drive position, N or N·m
        (``peak_force / static_force_end`` is the dynamic factor of the braking).
    """

    brake_time: float
    t_stop: float
    history: History
    peak_force: float
    static_force_end: float


@dataclass(frozen=True)
class Accuracy:
    """Integrator settings and, if checked, the change at ten times tighter tolerances.

    Attributes
    ----------
    method : str
        ``solve_ivp`` method.
    rtol, atol : float
        Tolerances (atol in m, rad, m/s, rad/s).
    max_step : float
        Largest step, s (``inf``: none).
    checked : bool
        Whether a second run at rtol/10, atol/10 was made; the changes below are NaN
        (or empty) without it.
    trip_time_change : float
        |Δ trip time|, s.
    peak_force_change : float
        Largest |Δ peak force| over the braking runs, N or N·m.
    force_change : float
        Largest |Δ drive force| over all samples of all runs, N or N·m.
    coordinate_change : tuple of float (N,)
        Largest |Δ q_j| over all samples of all runs, per coordinate (m or rad).
    """

    method: str
    rtol: float
    atol: float
    max_step: float
    checked: bool = False
    trip_time_change: float = float("nan")
    peak_force_change: float = float("nan")
    force_change: float = float("nan")
    coordinate_change: tuple = ()

    def statement(self, force_unit: str = "N") -> str:
        """One sentence on how accurate the numbers are (for a report)."""
        step = "" if math.isinf(self.max_step) else f", largest step {self.max_step:g} s"
        text = (f"Integrated by {self.method} with rtol = {self.rtol:g}, atol ="
                f" {self.atol:g}{step}.")
        if not self.checked:
            return text + " Not checked against a run at tighter tolerances."
        return text + (f" A second run at ten times tighter tolerances changed the trip"
                       f" time by {self.trip_time_change:.1e} s, the peak drive force by"
                       f" {self.peak_force_change:.1e} {force_unit} and the drive force"
                       f" anywhere by at most {self.force_change:.1e} {force_unit}.")


@dataclass(frozen=True)
class TripAndBrake:
    """Result of :func:`trip_and_brake`.

    Attributes
    ----------
    coordinate_names, drive_names : tuple of str
        Names of all coordinates (columns of ``q``) and of the drives (columns of the
        drive forces).
    drive : str
        The driven coordinate whose force trips.
    start, speed, ramp_time, limit, t_after : float
        The load case (m or rad, per s, s, N or N·m, s).
    rest : ndarray (N,)
        Static rest at the start (all coordinates).
    static_force_start : float
        Drive force at that rest, N or N·m.
    tripped : bool
        Whether the drive force reached ``limit``.
    t_trip, drive_at_trip : float
        Trip time (s) and drive position there; NaN if not tripped.
    approach : History
        From t = 0 to the trip (or to the end of travel or ``t_max`` without a trip).
    extreme_before_trip : float
        Extreme drive force of the approach in the direction of the limit.
    runs : tuple of BrakingRun
        One per braking time (empty without a trip).
    message : str
        Why nothing was braked (empty after a trip).
    accuracy : Accuracy
    """

    coordinate_names: tuple
    drive_names: tuple
    drive: str
    start: float
    speed: float
    ramp_time: float
    limit: float
    t_after: float
    rest: np.ndarray
    static_force_start: float
    tripped: bool
    t_trip: float
    drive_at_trip: float
    approach: History
    extreme_before_trip: float
    runs: tuple
    message: str
    accuracy: Accuracy


def _layout(model: LagrangeModel):
    """(free indices, drive indices, coordinate names, drive names) of a model."""
    if not isinstance(model, LagrangeModel):
        raise TypeError(f"model must be a LagrangeModel (second_kind), got"
                        f" {type(model).__name__}")
    coords = model.mechanism.coordinates
    d = [coords.index(x) for x in model.mechanism.drives]
    f = [i for i in range(len(coords)) if i not in d]
    return f, d, tuple(c.name for c in coords), tuple(x.name for x in model.mechanism.drives)


def _drive_vector(model: LagrangeModel, drive_values) -> np.ndarray:
    """Drive values (F,) from a mapping {drive name: value} or a sequence in drive order."""
    _, d, _, names = _layout(model)
    if isinstance(drive_values, dict):
        unknown = sorted(set(drive_values) - set(names))
        missing = [n for n in names if n not in drive_values]
        if unknown or missing:
            raise ValueError(f"drive values: give one per drive {list(names)};"
                             f" unknown {unknown}, missing {missing}")
        values = [drive_values[n] for n in names]
    else:
        values = np.atleast_1d(np.asarray(drive_values, dtype=float)).tolist()
    x = np.asarray(values, dtype=float)
    if x.shape != (len(d),) or not np.isfinite(x).all():
        raise ValueError(f"drive values: expected {len(d)} finite values for the drives"
                         f" {list(names)}, got {values!r}")
    return x


def _static_residual(model, q, f):
    """W_pot,f − Q*_f(q, 0) and its Jacobian (potential stiffness minus ∂Q*/∂q)."""
    zero = np.zeros_like(q)
    r = model.gradient(q)[f] - model.Q(q, zero)[f]
    K = model.stiffness(q)[np.ix_(f, f)]
    if np.any(model.Q(q, zero)[f]):  # position-dependent loads: central differences
        for j, i in enumerate(f):
            h = math.sqrt(EPS) * (1.0 + abs(q[i]))
            up, down = q.copy(), q.copy()
            up[i] += h
            down[i] -= h
            K[:, j] -= (model.Q(up, zero)[f] - model.Q(down, zero)[f]) / (2 * h)
    return r, K


def static_rest(model: LagrangeModel, drive_values, q_guess=None, tol: float = 1e-13,
                maxiter: int = 50) -> np.ndarray:
    """Static rest of the free coordinates at fixed drive values (step 1 of the load case).

    Solves W_pot,j(q) − Q*_j(q, 0) = 0 for the free coordinates j by Newton's method with
    the potential stiffness c_jk = W_pot,jk (eq. 9; minus ∂Q*_j/∂q_k by central
    differences when there are loads), from ``q_guess`` (default: all free coordinates
    0), until the largest correction is below ``tol · max(1, max |q_f|)``.

    Parameters
    ----------
    model : LagrangeModel
        From :func:`~femmech.mechanisms.second_kind`.
    drive_values : mapping or array_like (F,)
        Drive positions (m or rad), by drive name or in the order of the drives.
    q_guess : array_like (N,), optional
        Start of the iteration (all coordinates; its drive entries are replaced).
    tol : float
        Relative size of the last correction that counts as converged.
    maxiter : int
        Most Newton steps.

    Returns
    -------
    ndarray (N,)
        All coordinates at rest (drives at ``drive_values``), m or rad.

    Raises
    ------
    ValueError
        If the stiffness of the free coordinates is singular (naming the coordinate
        without a restoring force) or not positive definite at the solution (an unstable
        rest, naming the coordinate that moves most in the unstable direction).
    RuntimeError
        If Newton's method does not converge, naming the coordinate with the largest
        remaining force.
    """
    f, d, names, _ = _layout(model)
    q = np.zeros(len(names)) if q_guess is None else np.array(q_guess, dtype=float)
    q[d] = _drive_vector(model, drive_values)
    where = ", ".join(f"{names[i]} = {q[i]:.6g}" for i in d)
    for _ in range(maxiter):
        with np.errstate(all="ignore"):  # reported below, naming the coordinate
            r, K = _static_residual(model, q, f)
        if not (np.isfinite(r).all() and np.isfinite(K).all()):
            j = int(np.argmin(np.isfinite(r) & np.isfinite(K).all(axis=1)))
            raise ValueError(f"static rest at {where}: the force on coordinate"
                             f" {names[f[j]]!r} is not finite (is the drive position, or"
                             f" {names[f[j]]} = {q[f[j]]:.6g}, outside the range of"
                             " motion?)")
        try:
            dq = np.linalg.solve(K, r)
        except np.linalg.LinAlgError:
            j = int(np.argmin(np.abs(np.diag(K))))
            raise ValueError(f"static rest at {where}: the potential stiffness of the free"
                             f" coordinates is singular (coordinate {names[f[j]]!r} has no"
                             " restoring force?)") from None
        q[f] -= dq
        if np.abs(dq).max(initial=0.0) < tol * max(1.0, np.abs(q[f]).max(initial=0.0)):
            _check_stable(K, f, names, where)
            return q
    r, _ = _static_residual(model, q, f)
    j = int(np.argmax(np.abs(r)))
    raise RuntimeError(f"static rest at {where} did not converge in {maxiter} Newton steps:"
                       f" the force on coordinate {names[f[j]]!r} is still {r[j]:.3e}"
                       " (N or N·m)")


def _check_stable(K, f, names, where) -> None:
    w, v = np.linalg.eigh(0.5 * (K + K.T))
    if w.size and w[0] <= 0:
        j = int(np.argmax(np.abs(v[:, 0])))
        raise ValueError(f"static rest at {where} is not stable (potential stiffness"
                         f" eigenvalue {w[0]:.3e}, mostly coordinate {names[f[j]]!r}): start"
                         " from another q_guess")


def static_drive_forces(model: LagrangeModel, q) -> np.ndarray:
    """Drive forces W_pot,d − Q*_d(q, 0) at rest in the state ``q`` (N,) → (F,), N or N·m."""
    _, d, _, _ = _layout(model)
    q = np.asarray(q, dtype=float)
    return model.gradient(q)[..., d] - model.Q(q, np.zeros_like(q))[..., d]


def spring_forces(model: LagrangeModel, q) -> np.ndarray:
    """Forces c·s(q) of the mechanism's springs, in element order: shape (..., n_springs).

    Positive when the deflection s is positive (tension for a spring written as an
    elongation); N for a stiffness in N/m, N·m for one in N·m/rad. For the mobile crane
    (chapter section 5.2.3.1 eq. 18) these are the front and rear axle forces F_v, F_h.
    """
    springs = [el for el in model.mechanism.elements if isinstance(el, Spring)]
    q = np.asarray(q, dtype=float)
    if not springs:
        return np.zeros(q.shape[:-1] + (0,))
    compiled = compile_expressions(tuple(s.c * s.deflection for s in springs),
                                   tuple(model.mechanism.coordinates))
    params = [model.parameters[p.name] for p in compiled.parameters]
    return compiled(list(np.moveaxis(q, -1, 0)), params, model.position_functions)


class _Drives:
    """All drives at times t: the driven one (column k) from ``law``, the others held."""

    def __init__(self, law, k: int, values: np.ndarray):
        self.law, self.k, self.values = law, k, values

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        q = np.broadcast_to(self.values, t.shape + self.values.shape).copy()
        qd, qdd = np.zeros_like(q), np.zeros_like(q)
        q[..., self.k], qd[..., self.k], qdd[..., self.k] = self.law(t)
        return q, qd, qdd


class _Budget:
    """Counts right-hand-side evaluations; raises RuntimeError beyond ``limit``."""

    def __init__(self, limit: int | None):
        self.limit, self.used = limit, 0

    def spend(self, t: float) -> None:
        self.used += 1
        if self.limit is not None and self.used > self.limit:
            raise RuntimeError(f"the integration needed more than {self.limit} evaluations of"
                               f" the equations of motion (at t = {t:.6g} s): shorten the"
                               " simulated time or raise max_evaluations")


@dataclass(frozen=True)
class _Setup:
    """Model layout and integrator settings shared by the segments of one load case."""

    model: LagrangeModel
    f: list
    d: list
    names: tuple
    method: str
    rtol: float
    atol: float
    max_step: float
    budget: _Budget


def _full_state(s: _Setup, drives, t, y):
    """All coordinates, velocities (n_t, N) and drive accelerations (n_t, F) at times t."""
    t, y = np.atleast_1d(t), np.atleast_2d(y)
    qq, vv, aa = drives(t)
    n = len(s.f)
    q, qd = np.empty((t.size, len(s.names))), np.empty((t.size, len(s.names)))
    q[:, s.f], qd[:, s.f] = y[:, :n], y[:, n:]
    q[:, s.d], qd[:, s.d] = qq, vv
    return q, qd, aa


def _rhs(s: _Setup, drives):
    n = len(s.f)

    def rhs(t, y):
        s.budget.spend(t)
        q, qd, aa = _full_state(s, drives, t, y)
        with np.errstate(all="ignore"):
            qdd = s.model.accelerations(q[0], qd[0], aa[0]).qdd[s.f]
        if not np.isfinite(qdd).all():
            j = int(np.flatnonzero(~np.isfinite(qdd))[0])
            raise ValueError(f"non-finite acceleration of coordinate {s.names[s.f[j]]!r} at"
                             f" t = {t:.6g} s (outside the range of motion?)")
        return np.r_[y[n:], qdd]
    return rhs


def _drive_forces(s: _Setup, drives, t, y) -> np.ndarray:
    q, qd, aa = _full_state(s, drives, t, y)
    return s.model.accelerations(q, qd, aa).drive_forces


def _segment(s: _Setup, drives, t_span, y0, n: int, event=None):
    """Integrate over t_span (cut at a terminal event): (times (n,), states (n, 2n_f),
    end time, whether the event ended it)."""
    sol = integrate.solve_ivp(_rhs(s, drives), t_span, y0, method=s.method, rtol=s.rtol,
                              atol=s.atol, dense_output=True, max_step=s.max_step,
                              events=event)
    if sol.status < 0:
        raise RuntimeError(f"{s.method} failed on t = {t_span[0]:.6g}..{t_span[1]:.6g} s:"
                           f" {sol.message}")
    hit = event is not None and sol.t_events[0].size > 0
    t_end = float(sol.t_events[0][0]) if hit else float(sol.t[-1])
    t = np.linspace(t_span[0], t_end, n)
    return t, sol.sol(t).T, t_end, hit


def _history(s: _Setup, pieces) -> History:
    """Join segments [(drives, t, y), ...]; each joint sample is kept once (the later)."""
    rows = [(dr, t[:-1], y[:-1]) if k < len(pieces) - 1 else (dr, t, y)
            for k, (dr, t, y) in enumerate(pieces)]
    t = np.concatenate([r[1] for r in rows])
    q, qd = (np.vstack(x) for x in zip(*[_full_state(s, dr, ti, yi)[:2]
                                          for dr, ti, yi in rows], strict=True))
    forces = np.vstack([_drive_forces(s, dr, ti, yi) for dr, ti, yi in rows])
    return History(t, q, qd, forces)


def travel_time(start: float, end: float, speed: float, ramp_time: float) -> float:
    """Time (s) at which a drive started from rest at ``start`` reaches ``end``: the
    cycloidal ramp to ``speed`` over ``ramp_time``, then the constant speed (m or rad,
    per s; ``end`` in the direction of ``speed``)."""
    travel = (end - start) / speed  # the time at constant speed
    if not travel > 0 or not ramp_time > 0:
        raise ValueError(f"end = {end:g} must lie in the direction of travel (speed ="
                         f" {speed:g}) from start = {start:g}, and the ramp time must be"
                         f" positive (got {ramp_time:g} s)")
    if travel >= ramp_time / 2:  # ramp covers speed·ramp_time/2
        return ramp_time / 2 + travel

    def covered(tau):  # SpeedRamp angle over the ramp, in units of speed·ramp_time
        return tau**2 / 2 + (math.cos(2 * math.pi * tau) - 1) / (4 * math.pi**2)
    return ramp_time * optimize.brentq(lambda x: covered(x) - travel / ramp_time, 0.0, 1.0)


@dataclass(frozen=True)
class _Case:
    """The load case of :func:`trip_and_brake` in SI units, checked."""

    k: int
    hold: np.ndarray
    start: float
    speed: float
    ramp_time: float
    limit: float
    brake_times: tuple
    t_after: float
    t_end: float
    samples: int
    q_guess: np.ndarray | None


def trip_and_brake(model: LagrangeModel, drive: str, start: float, speed: float,
                   ramp_time: float, limit: float, brake_times, t_after: float,
                   end: float | None = None, t_max: float | None = None, held=None,
                   q_guess=None, samples: int = 1500, method: str = "DOP853",
                   rtol: float = 1e-10, atol: float = 1e-12, max_step: float = math.inf,
                   verify: bool = False, max_evaluations: int | None = None) -> TripAndBrake:
    """Run the drive up to speed, trip at a drive-force limit, brake to rest (module doc).

    Parameters
    ----------
    model : LagrangeModel
        From :func:`~femmech.mechanisms.second_kind`, with at least one drive.
    drive : str
        Name of the driven coordinate; its force is watched.
    start : float
        Drive position at the start (m or rad); the mechanism starts at static rest there.
    speed : float
        Constant drive speed after the start-up ramp (m/s or rad/s; its sign is the
        direction of travel, e.g. negative for a retracting cylinder).
    ramp_time : float
        Duration of the cycloidal start-up ramp from rest to ``speed``, s.
    limit : float
        Drive force that trips (N or N·m, non-zero): a positive limit is reached from
        below, a negative one from above.
    brake_times : sequence of float
        Braking times, s (each > 0): one braking run each.
    t_after : float
        Time simulated after the end of braking, s (>= 0).
    end : float, optional
        End of travel (m or rad, in the direction of ``speed`` from ``start``): the run
        ends there if the limit has not been reached.
    t_max : float, optional
        Latest trip time, s. At least one of ``end`` and ``t_max`` is required.
    held : mapping, optional
        Values of the other drives {name: value}, held constant (required iff there are
        other drives).
    q_guess : array_like (N,), optional
        Start of the Newton iteration of the static rest (:func:`static_rest`).
    samples : int
        Output samples per phase (approach; braking and run-on), >= 2.
    method, rtol, atol, max_step
        Integrator (``solve_ivp``) settings; atol in m, rad, m/s, rad/s; max_step in s.
    verify : bool
        Also run at rtol/10, atol/10 and report the changes in :class:`Accuracy`.
    max_evaluations : int, optional
        Most evaluations of the equations of motion for the whole call (a guard against
        runs that would take hours); None: no limit.

    Returns
    -------
    TripAndBrake
        ``tripped`` False (with ``message``) when the limit is not reached before ``end``
        or ``t_max``; the approach history is then still given.

    Raises
    ------
    ValueError
        For inconsistent inputs (named), a start whose static drive force is already at
        or beyond the limit, or a state that leaves the range of motion.
    RuntimeError
        If the static rest or the integrator fails, or ``max_evaluations`` is exceeded.
    """
    f, d, names, drive_names = _layout(model)
    if drive not in drive_names:
        raise ValueError(f"drive {drive!r} is not a drive of mechanism"
                         f" {model.mechanism.name!r}; its drives are {list(drive_names)}")
    k = drive_names.index(drive)
    hold = _held(model, k, held, start)
    case = _case(k, hold, start, speed, ramp_time, limit, brake_times, t_after, end, t_max,
                 samples, q_guess)
    budget = _Budget(max_evaluations)
    s = _Setup(model, f, d, names, method, float(rtol), float(atol), float(max_step), budget)
    result = _load_case(s, case)
    if not verify:
        return result
    tight = _load_case(_Setup(model, f, d, names, method, rtol / 10, atol / 10, max_step,
                              budget), case)
    return _with_accuracy(result, tight, case.k)


def _held(model, k: int, held, start) -> np.ndarray:
    """Drive values (F,) with the driven one at ``start`` and the others held."""
    names = _layout(model)[3]
    others = [n for i, n in enumerate(names) if i != k]
    given = dict(held or {})
    if sorted(given) != sorted(others):
        raise ValueError(f"held: give a value for each other drive {others}, got"
                         f" {sorted(given)}")
    return _drive_vector(model, {**given, names[k]: start})


def _case(k, hold, start, speed, ramp_time, limit, brake_times, t_after, end, t_max,
          samples, q_guess) -> _Case:
    values = {"start": start, "speed": speed, "ramp_time": ramp_time, "limit": limit,
              "t_after": t_after}
    for key, v in values.items():
        if not math.isfinite(v):
            raise ValueError(f"{key} must be finite, got {v!r}")
    for key in ("speed", "limit"):
        if values[key] == 0:
            raise ValueError(f"{key} must not be 0")
    if not ramp_time > 0 or not t_after >= 0:
        raise ValueError(f"expected ramp_time > 0 and t_after >= 0 s, got {ramp_time!r},"
                         f" {t_after!r}")
    brakes = tuple(float(b) for b in brake_times)
    if not all(math.isfinite(b) and b > 0 for b in brakes):
        raise ValueError(f"braking times must be positive and finite, got {brakes}")
    if end is None and t_max is None:
        raise ValueError("give end (the end of travel) or t_max (the latest trip time)")
    if end is not None and not (end - start) * speed > 0:
        raise ValueError(f"end = {end:g} must lie in the direction of travel (speed ="
                         f" {speed:g}) from start = {start:g}")
    if t_max is not None and not t_max > 0:
        raise ValueError(f"t_max must be positive, got {t_max!r} s")
    t_end = min(travel_time(start, end, speed, ramp_time) if end is not None else math.inf,
                t_max if t_max is not None else math.inf)
    if isinstance(samples, bool) or int(samples) != samples or samples < 2:
        raise ValueError(f"samples must be an integer >= 2, got {samples!r}")
    guess = None if q_guess is None else np.asarray(q_guess, dtype=float)
    return _Case(k, hold, float(start), float(speed), float(ramp_time), float(limit), brakes,
                 float(t_after), float(t_end), int(samples), guess)


def _extreme(values: np.ndarray, sign: float) -> float:
    """The extreme of ``values`` in the direction ``sign`` (max for +1, min for −1)."""
    return float(sign * np.max(sign * values))


def _load_case(s: _Setup, c: _Case) -> TripAndBrake:
    """Static rest, approach until the trip, one braking run per braking time."""
    rest = static_rest(s.model, c.hold, c.q_guess)
    force0 = float(static_drive_forces(s.model, rest)[c.k])
    sign = math.copysign(1.0, c.limit)
    drive = s.model.mechanism.drives[c.k].name
    if sign * force0 >= abs(c.limit):
        raise ValueError(f"the force of drive {drive!r} at the static rest at the start is"
                         f" {force0:.6g}, already at or beyond the limit {c.limit:.6g}")
    law = SpeedRamp(0.0, c.speed, c.ramp_time, phi0=c.start)
    drives = _Drives(law, c.k, c.hold)

    def trip(t, y):
        return _drive_forces(s, drives, t, y)[0, c.k] - c.limit
    trip.terminal, trip.direction = True, sign
    y0 = np.r_[rest[s.f], np.zeros(len(s.f))]
    t, y, t_trip, hit = _segment(s, drives, (0.0, c.t_end), y0, c.samples, trip)
    approach = _history(s, [(drives, t, y)])
    extreme = _extreme(approach.drive_forces[:, c.k], sign)
    names = tuple(x.name for x in s.model.mechanism.coordinates)
    common = dict(coordinate_names=names, drive_names=tuple(x.name for x in
                                                            s.model.mechanism.drives),
                  drive=drive, start=c.start, speed=c.speed, ramp_time=c.ramp_time,
                  limit=c.limit, t_after=c.t_after, rest=rest, static_force_start=force0,
                  approach=approach, extreme_before_trip=extreme,
                  accuracy=Accuracy(s.method, s.rtol, s.atol, s.max_step))
    if not hit:
        position = float(law(np.array([t_trip]))[0][0])
        message = (f"the force of drive {drive!r} did not reach the limit {c.limit:.6g} (N,"
                   f" or N·m for a rotation): its extreme was {extreme:.6g} before the run"
                   f" ended at t ="
                   f" {t_trip:.6g} s, {drive} = {position:.6g} (end of travel or t_max)")
        return TripAndBrake(**common, tripped=False, t_trip=math.nan,
                            drive_at_trip=math.nan, runs=(), message=message)
    q_trip, v_trip = (float(x[0]) for x in law(np.array([t_trip]))[:2])
    runs = tuple(_brake(s, c, (drives, t, y), t_trip, q_trip, v_trip, rest, tb)
                 for tb in c.brake_times)
    return TripAndBrake(**common, tripped=True, t_trip=t_trip, drive_at_trip=q_trip,
                        runs=runs, message="")


def _brake(s: _Setup, c: _Case, approach, t_trip, q_trip, v_trip, rest,
           brake_time) -> BrakingRun:
    """Cycloidal braking from the speed at the trip to rest in ``brake_time``, then
    ``c.t_after``."""
    law = SpeedRamp(v_trip, 0.0, brake_time, t_start=t_trip, phi0=q_trip - v_trip * t_trip)
    drives = _Drives(law, c.k, c.hold)
    t_stop = t_trip + brake_time
    t, y, _, _ = _segment(s, drives, (t_trip, t_stop + c.t_after), approach[2][-1],
                          c.samples)
    history = _history(s, [approach, (drives, t, y)])
    sign = math.copysign(1.0, c.limit)
    peak = _extreme(history.drive_forces[history.t >= t_trip, c.k], sign)
    final = c.hold.copy()
    final[c.k] = history.q[-1, s.d[c.k]]
    at_rest = static_rest(s.model, final, rest)
    static = float(static_drive_forces(s.model, at_rest)[c.k])
    return BrakingRun(brake_time, t_stop, history, peak, static)


def _with_accuracy(result: TripAndBrake, tight: TripAndBrake, k: int) -> TripAndBrake:
    """``result`` with the changes of the tighter run ``tight`` in its Accuracy."""
    pairs = [(a.history, b.history) for a, b in zip(result.runs, tight.runs, strict=False)]
    if not pairs or result.tripped != tight.tripped:
        pairs = [(result.approach, tight.approach)]
    n = [min(a.t.size, b.t.size) for a, b in pairs]
    dq = np.max([np.abs(a.q[:m] - b.q[:m]).max(axis=0) for (a, b), m in zip(pairs, n,
                                                                           strict=True)],
                axis=0)
    dF = max(float(np.abs(a.drive_forces[:m, k] - b.drive_forces[:m, k]).max())
             for (a, b), m in zip(pairs, n, strict=True))
    dpeak = max((abs(a.peak_force - b.peak_force)
                 for a, b in zip(result.runs, tight.runs, strict=False)), default=math.nan)
    dtrip = abs(result.t_trip - tight.t_trip) if result.tripped and tight.tripped else \
        math.nan
    acc = result.accuracy
    checked = Accuracy(acc.method, acc.rtol, acc.atol, acc.max_step, True, dtrip, dpeak, dF,
                       tuple(float(x) for x in dq))
    return replace(result, accuracy=checked)
