"""Mobile crane of seed 5.2.3.1: the luffing cylinder is braked when the limiter trips.

Physics
-------
A rigid chassis (mass m2 in kg, inertia J_S2 in kg·m²) rides on two tyre springs (c in
N/m at the front and rear axles, distances l1, l2 in m from the chassis CG), carries a
luffing boom (m3, J_S3) moved by a hydraulic cylinder of length q4 = s4 (m), and the load
m5 hangs from the boom tip on a rope of length r_S5 (m) as a pendulum. Coordinates
(seed 5.2.3.1, errata §A): q1 vertical chassis displacement (m), q2 chassis rotation
(rad), q3 = φ5 space-fixed pendulum angle (rad), q4 the cylinder length, prescribed.

The cylinder length q4(t) is a kinematic drive; the 2nd-kind equations (seed eqs.
14–16, with the corrected velocity terms of errata 25 and the gravity factor of errata
24) give q1'', q2'', q3'', and eq. 17 gives the cylinder force Q4 (N) that enforces
q4(t). ``femmech.mechanisms.second_kind(mobile_crane(), ...)`` derives both from the
energies of errata §A (geometry with errata 22, 23). The axle (tyre spring) forces are
eq. 18, F_v = c (q1 − l1 q2) (front), F_h = c (q1 + l2 q2) (rear), positive in
tension: in the static rest they are negative and carry the weight,
F_v + F_h = −(m2 + m3 + m5) g (the potential of eq. 13 measures q1 from unloaded springs).

The load case (summary §4, "purpose"): the cylinder retracts (the boom lowers and the
outreach grows), so the static cylinder force Q4 grows; the load-moment limiter (a
pressure cell) trips when Q4 reaches ``limit`` and the cylinder is braked to rest. The
inertia forces of this braking raise Q4 above its quasi-static value and set the load
swinging. The run:

1. static rest at q4 = ``q4_start`` (W_pot,j = 0, j = 1..3, by Newton's method);
2. cylinder speed ramped from 0 to −``speed`` with the cycloidal
   :class:`~femmech.analysis.response.SpeedRamp` over two pendulum periods
   T = 2π √(r_S5 / g): the spectrum of the ramp's acceleration pulse vanishes at the
   pendulum frequency, so a linear pendulum is left without residual swing;
3. constant speed until Q4 = ``limit`` (a ``solve_ivp`` event);
4. cycloidal braking to rest within ``brake_time`` (s), then ``t_after`` (s) at rest.

Integrator: ``scipy.integrate.solve_ivp`` (DOP853) on (q1, q2, q3, q1', q2', q3').
Units SI throughout. Parameters are the illustrative ``mobile_crane_parameters()`` (no
damping in the chapter's model, so the swing and the chassis bounce do not decay).

Sources: seed chapter 5.2.3.1 eqs. 1–18 (summary-en.md §4) with errata items 22–25 and §A.

Run ``python examples/crane_braking.py --out DIR`` to write ``crane_braking.png`` and
``crane_braking.csv``.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from femmech.analysis.response import SpeedRamp
from femmech.mechanisms import mobile_crane, mobile_crane_parameters, second_kind

PARAMS = mobile_crane_parameters()
Q4_START = 4.7  # m, Q4 ≈ 0.05 MN: the limit is reached after the start-up ramp
SPEED = 0.1  # m/s, cylinder retraction speed
LIMIT = 300e3  # N, limiter force (reached near q4 = 3.9 m)
BRAKE_TIMES = (0.2, 0.5, 1.0)  # s
RTOL, ATOL = 1e-10, 1e-12
MAX_STEP = 0.05  # s, a tenth of the chassis bounce period (about 0.6 s)


@lru_cache(maxsize=1)
def model():
    """The 2nd-kind model of the crane with ``PARAMS`` (built once)."""
    return second_kind(mobile_crane(), PARAMS)


def pendulum_period(params=PARAMS) -> float:
    """Small-swing period 2π √(r_S5 / g) of the load on a fixed suspension point, s."""
    return 2 * np.pi * np.sqrt(params["rS5"] / params["g"])


def static_rest(q4: float, tol: float = 1e-13) -> np.ndarray:
    """Static rest (q1, q2, q3, q4) at cylinder length q4 (m): W_pot,j = 0 for j = 1..3.

    Newton's method with the potential stiffness W_pot,jk; converges from q = 0 in a few
    steps (the potential is quadratic in q1 and nearly so in q2, q3).
    """
    m = model()
    q = np.array([0.0, 0.0, 0.0, q4])
    for _ in range(50):
        g = m.gradient(q)[:3]
        dq = np.linalg.solve(m.stiffness(q)[:3, :3], g)
        q[:3] -= dq
        if np.abs(dq).max() < tol:
            return q
    raise RuntimeError(f"static rest at q4 = {q4} m did not converge")


def static_force(q4: float) -> float:
    """Quasi-static cylinder force Q4 = W_pot,4 at the static rest for q4 (m), N."""
    return float(model().gradient(static_rest(q4))[3])


@dataclass(frozen=True)
class CraneRun:
    """Time history of one braking run (SI units).

    Attributes
    ----------
    t : ndarray (n_t,)
        Times, s.
    q, qd : ndarray (n_t, 4)
        Coordinates q1 (m), q2 (rad), q3 (rad), q4 (m) and their rates.
    Q4 : ndarray (n_t,)
        Cylinder force (eq. 17), N.
    F_v, F_h : ndarray (n_t,)
        Front and rear axle forces (eq. 18), N, tension positive.
    t_trip, t_stop : float
        Limiter trip time and end of braking, s.
    brake_time : float
        Braking time, s (``inf`` for a run without braking).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    Q4: np.ndarray
    F_v: np.ndarray
    F_h: np.ndarray
    t_trip: float
    t_stop: float
    brake_time: float


def _rhs(law):
    m = model()

    def f(t, y):
        q4, v4, a4 = (float(x[0]) for x in law(np.array([t])))
        acc = m.accelerations(np.r_[y[:3], q4], np.r_[y[3:], v4], [a4])
        return np.r_[y[3:], acc.qdd[:3]]
    return f


def _drive_force(law, t, y) -> np.ndarray:
    q4, v4, a4 = law(np.atleast_1d(t))
    y = np.atleast_2d(y)
    acc = model().accelerations(np.column_stack([y[:, :3], q4]),
                                np.column_stack([y[:, 3:], v4]), a4[:, None])
    return acc.drive_forces[:, 0]


def _segment(law, t_span, y0, n, events=None):
    sol = solve_ivp(_rhs(law), t_span, y0, method="DOP853", rtol=RTOL, atol=ATOL,
                    dense_output=True, events=events, max_step=MAX_STEP)
    if sol.status < 0:
        raise RuntimeError(f"solve_ivp failed on {t_span}: {sol.message}")
    t_end = sol.t_events[0][0] if events is not None and sol.t_events[0].size else sol.t[-1]
    t = np.linspace(t_span[0], t_end, n)
    return t, sol.sol(t).T, t_end


@lru_cache(maxsize=4)
def approach(q4_start: float = Q4_START, speed: float = SPEED, limit: float = LIMIT,
             n: int = 1500):
    """Start-up ramp and constant speed until Q4 = ``limit``: (law, t, y (n, 6), t_trip)."""
    T = pendulum_period()
    law = SpeedRamp(0.0, -speed, 2 * T, phi0=q4_start)
    y0 = np.r_[static_rest(q4_start)[:3], 0.0, 0.0, 0.0]

    def trip(t, y):
        return _drive_force(law, t, y)[0] - limit
    trip.terminal, trip.direction = True, 1.0
    p = PARAMS  # q4 > r34 − r24 keeps the cylinder triangle open (arccos defined)
    t_max = T + (q4_start - (p["r34"] - p["r24"]) - 0.1) / speed
    t, y, t_trip = _segment(law, (0.0, t_max), y0, n, events=trip)
    if t_trip >= t_max:
        raise RuntimeError(f"the limiter force {limit} N is not reached")
    return law, t, y, t_trip


def _history(parts, brake_time, t_trip, t_stop) -> CraneRun:
    p = PARAMS
    t = np.concatenate([np.delete(ti, -1) if k < len(parts) - 1 else ti
                        for k, (_, ti, _) in enumerate(parts)])
    rows = [(law, ti, yi) if k == len(parts) - 1 else (law, ti[:-1], yi[:-1])
            for k, (law, ti, yi) in enumerate(parts)]
    y = np.vstack([yi for _, _, yi in rows])
    drive = np.vstack([np.column_stack(law(ti)) for law, ti, _ in rows])
    Q4 = np.concatenate([_drive_force(law, ti, yi) for law, ti, yi in rows])
    q = np.column_stack([y[:, :3], drive[:, 0]])
    qd = np.column_stack([y[:, 3:], drive[:, 1]])
    F_v = p["c"] * (q[:, 0] - p["l1"] * q[:, 1])
    F_h = p["c"] * (q[:, 0] + p["l2"] * q[:, 1])
    return CraneRun(t, q, qd, Q4, F_v, F_h, t_trip, t_stop, brake_time)


def simulate(brake_time: float | None, t_after: float | None = None, n: int = 1500,
             **approach_args) -> CraneRun:
    """Run the load case; ``brake_time`` None runs on at constant speed (no braking).

    Parameters
    ----------
    brake_time : float or None
        Duration of the cycloidal deceleration from −speed to rest, s.
    t_after : float, optional
        Time simulated after the end of braking, s; default two pendulum periods.
    n : int
        Samples per segment.
    **approach_args
        ``q4_start`` (m), ``speed`` (m/s), ``limit`` (N) of :func:`approach`.
    """
    law, t0, y0, t_trip = approach(**approach_args, n=n)
    speed = approach_args.get("speed", SPEED)
    t_after = 2 * pendulum_period() if t_after is None else t_after
    q4_trip = float(law(np.array([t_trip]))[0][0])
    if brake_time is None:
        brake, t_stop, tb = law, t_trip + t_after, np.inf
    else:
        brake = SpeedRamp(-speed, 0.0, brake_time, t_start=t_trip,
                          phi0=q4_trip + speed * t_trip)
        t_stop, tb = t_trip + brake_time, brake_time
    t1, y1, _ = _segment(brake, (t_trip, t_stop + (0.0 if brake_time is None else t_after)),
                         y0[-1], n)
    return _history([(law, t0, y0), (brake, t1, y1)], tb, t_trip, t_stop)


def plot(runs: dict[float, CraneRun], filename) -> Path:
    """Three panels over time: cylinder force, axle forces, pendulum angle (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from femmech.output import atomic_path

    fig, axes = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    for k, (tb, run) in enumerate(runs.items()):
        color = f"C{k}"
        label = f"braking {tb:g} s"
        axes[0].plot(run.t, run.Q4 / 1e3, color=color, label=label)
        axes[1].plot(run.t, run.F_v / 1e3, color=color, label=f"F_v, {label}")
        axes[1].plot(run.t, run.F_h / 1e3, color=color, ls="--", label=f"F_h, {label}")
        axes[2].plot(run.t, np.degrees(run.q[:, 2]), color=color, label=label)
    t_trip = next(iter(runs.values())).t_trip
    for ax in axes:
        ax.axvline(t_trip, color="k", lw=0.8, ls=":")
        ax.grid(True, alpha=0.3)
    axes[0].axhline(LIMIT / 1e3, color="k", lw=0.8, ls="--")
    axes[0].text(t_trip, LIMIT / 1e3, " limiter trips", va="bottom", fontsize=8)
    axes[0].set_ylabel("cylinder force Q4 (kN)")
    axes[1].set_ylabel("axle forces (kN, tension +)")
    axes[2].set_ylabel("pendulum angle q3 (deg)")
    axes[2].set_xlabel("time (s)")
    axes[0].legend(fontsize=8)
    axes[1].legend(fontsize=7, ncol=3)
    axes[0].set_title("Mobile crane (seed 5.2.3.1): cylinder braked by the load-moment limiter")
    fig.tight_layout()
    with atomic_path(filename) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
    return Path(filename)


def write_csv(runs: dict[float, CraneRun], filename) -> Path:
    """Per braking time tb the columns t (s), q4 (m), Q4, F_v, F_h (N), q3 (rad)."""
    from femmech.output import atomic_path

    if len({run.t.size for run in runs.values()}) != 1:
        raise ValueError("the runs must have the same number of samples")
    header, cols = [], []
    for tb, run in runs.items():
        header += [f"{name}_tb{tb:g}" for name in ("t_s", "q4_m", "Q4_N", "Fv_N", "Fh_N",
                                                    "q3_rad")]
        cols += [run.t, run.q[:, 3], run.Q4, run.F_v, run.F_h, run.q[:, 2]]
    with atomic_path(filename) as tmp:
        np.savetxt(tmp, np.column_stack(cols), delimiter=",", header=",".join(header),
                   comments="", fmt="%.10g")
    return Path(filename)


def swing_amplitude(run: CraneRun, after: float) -> float:
    """Largest |q3| (rad) at times ≥ ``after`` (s)."""
    return float(np.abs(run.q[run.t >= after, 2]).max())


def main(out_dir=".") -> dict:
    """Run the three braking times, write PNG and CSV; return the key numbers."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    runs = {tb: simulate(tb) for tb in BRAKE_TIMES}
    first = runs[BRAKE_TIMES[0]]
    q4_end = {tb: float(r.q[-1, 3]) for tb, r in runs.items()}
    result = {
        "t_trip": first.t_trip,
        "q4_trip": float(np.interp(first.t_trip, first.t, first.q[:, 3])),
        "peak_Q4": {tb: float(r.Q4[r.t >= r.t_trip].max()) for tb, r in runs.items()},
        "static_Q4_end": {tb: static_force(q4) for tb, q4 in q4_end.items()},
        "swing_rad": {tb: swing_amplitude(r, r.t_trip) for tb, r in runs.items()},
        "png": plot(runs, out / "crane_braking.png"),
        "csv": write_csv(runs, out / "crane_braking.csv"),
    }
    return result


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=".", help="output folder (default: .)")
    res = main(parser.parse_args().out)
    print(f"limiter trips at t = {res['t_trip']:.3f} s, q4 = {res['q4_trip']:.4f} m")
    for tb in BRAKE_TIMES:
        print(f"braking {tb:g} s: peak Q4 = {res['peak_Q4'][tb] / 1e3:.1f} kN "
              f"(static at rest {res['static_Q4_end'][tb] / 1e3:.1f} kN), "
              f"swing {np.degrees(res['swing_rad'][tb]):.3f} deg")
    print(f"wrote {res['png']} and {res['csv']}")
