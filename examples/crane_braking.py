"""Mobile crane: the luffing cylinder is braked when the load-moment limiter trips.

Physics
-------
A rigid chassis (mass m2 in kg, inertia J_S2 in kg·m²) rides on two tyre springs (c in
N/m at the front and rear axles, distances l1, l2 in m from the chassis CG), carries a
luffing boom (m3, J_S3) moved by a hydraulic cylinder of length q4 = s4 (m), and the load
m5 hangs from the boom tip on a rope of length r_S5 (m) as a pendulum. Coordinates: q1
vertical chassis displacement (m), q2 chassis rotation (rad), q3 = φ5 space-fixed
pendulum angle (rad), q4 the cylinder length, prescribed.

The cylinder length q4(t) is a kinematic drive; the 2nd-kind equations give q1'', q2'',
q3'' and the cylinder force Q4 (N) that enforces q4(t).
``femmech.mechanisms.second_kind(mobile_crane(), ...)`` derives both from the energies.
The axle (tyre spring) forces are F_v = c (q1 − l1 q2) (front), F_h = c (q1 + l2 q2)
(rear), positive in tension: in the static rest they are negative and carry the weight,
F_v + F_h = −(m2 + m3 + m5) g (the potential measures q1 from unloaded springs).

The load case: the cylinder retracts (the boom lowers and the outreach grows), so the
static cylinder force Q4 grows; the load-moment limiter (a pressure cell) trips when Q4
reaches ``LIMIT`` and the cylinder is braked to rest. The inertia forces of this braking
raise Q4 above its quasi-static value and set the load swinging. The run
(:func:`femmech.analysis.drive_events.trip_and_brake`):

1. static rest at q4 = ``Q4_START`` by Newton's method;
2. cylinder speed ramped from 0 to −``SPEED`` with the cycloidal
   :class:`~femmech.analysis.response.SpeedRamp` over two pendulum periods
   T = 2π √(r_S5 / g): the spectrum of the ramp's acceleration pulse vanishes at the
   pendulum frequency, so a linear pendulum is left without residual swing;
3. constant speed until Q4 = ``LIMIT`` (a terminal event of the integrator), at the
   latest when q4 reaches ``Q4_END`` (the cylinder triangle stays open);
4. cycloidal braking to rest within each braking time (s), then two pendulum periods at
   rest.

Integrator: ``scipy.integrate.solve_ivp`` (DOP853) on (q1, q2, q3, q1', q2', q3').
Units SI throughout. Parameters are the illustrative ``mobile_crane_parameters()`` (no
damping in the chapter's model, so the swing and the chassis bounce do not decay). The
scene ``examples/crane_braking.toml`` runs the same load case through ``femmech run``.

Source: the textbook chapter's section 5.2.3.1, eqs. 1–18 (summary-en.md §4), corrected
per errata items 22–25 and §A.

Run ``python examples/crane_braking.py --out DIR`` to write ``crane_braking.png`` and
``crane_braking.csv``.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from femmech.analysis.drive_events import (
    spring_forces,
    static_drive_forces,
    trip_and_brake,
)
from femmech.analysis.drive_events import static_rest as rest_of
from femmech.mechanisms import mobile_crane, mobile_crane_parameters, second_kind

PARAMS = mobile_crane_parameters()
Q4_START = 4.7  # m, Q4 ≈ 0.05 MN: the limit is reached after the start-up ramp
Q4_END = PARAMS["r34"] - PARAMS["r24"] + 0.1  # m, shortest length used (triangle open)
SPEED = 0.1  # m/s, cylinder retraction speed
LIMIT = 300e3  # N, limiter force (reached near q4 = 3.9 m)
BRAKE_TIMES = (0.2, 0.5, 1.0)  # s
RTOL, ATOL = 1e-10, 1e-12
MAX_STEP = 0.05  # s, a tenth of the chassis bounce period (about 0.6 s)
SAMPLES = 1500  # output samples per phase (approach; braking and run-on)


@lru_cache(maxsize=1)
def model():
    """The 2nd-kind model of the crane with ``PARAMS`` (built once)."""
    return second_kind(mobile_crane(), PARAMS)


def pendulum_period(params=PARAMS) -> float:
    """Small-swing period 2π √(r_S5 / g) of the load on a fixed suspension point, s."""
    return 2 * np.pi * np.sqrt(params["rS5"] / params["g"])


def static_rest(q4: float) -> np.ndarray:
    """Static rest (q1, q2, q3, q4) at cylinder length q4 (m): W_pot,j = 0 for j = 1..3."""
    return rest_of(model(), [q4])


def static_force(q4: float) -> float:
    """Quasi-static cylinder force Q4 = W_pot,4 at the static rest for q4 (m), N."""
    return float(static_drive_forces(model(), static_rest(q4))[0])


@lru_cache(maxsize=2)
def load_case(verify: bool = False):
    """The limiter load case for all ``BRAKE_TIMES`` (a ``TripAndBrake``)."""
    T = pendulum_period()
    return trip_and_brake(model(), "q4", Q4_START, -SPEED, 2 * T, LIMIT, BRAKE_TIMES, 2 * T,
                          end=Q4_END, samples=SAMPLES, rtol=RTOL, atol=ATOL,
                          max_step=MAX_STEP, verify=verify)


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
        Cylinder force, N.
    F_v, F_h : ndarray (n_t,)
        Front and rear axle forces, N, tension positive.
    t_trip, t_stop : float
        Limiter trip time and end of braking, s.
    brake_time : float
        Braking time, s.
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


def simulate(brake_time: float) -> CraneRun:
    """The run with braking time ``brake_time`` (one of ``BRAKE_TIMES``), s."""
    case = load_case()
    run = next(r for r in case.runs if r.brake_time == brake_time)
    h = run.history
    F_v, F_h = spring_forces(model(), h.q).T  # the tyre springs: front, rear axle
    return CraneRun(h.t, h.q, h.qd, h.drive_forces[:, 0], F_v, F_h, case.t_trip, run.t_stop,
                    brake_time)


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
    axes[0].set_title("Mobile crane: luffing cylinder braked by the load-moment limiter")
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
