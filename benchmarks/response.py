"""Forced response at constant speed: shooting vs integrating through the transient.

The processing machine of seed 5.2.3.2 on its frame (examples/processing_machine.py,
reduced coupled system, frame Rayleigh damping ζ = 2 %) runs at 1200 rpm. The periodic
steady state is computed three ways, side by side in one process:

* ``periodic_steady_state``: shooting with the monodromy of the generalised-α map (one
  integration of 2n + 1 states over one period, a (2n, 2n) solve, one more period);
* ``time_response`` from rest over many revolutions until the free motion has decayed,
  the last revolution taken as the steady state (what one does without shooting);
* a reference: scipy's DOP853 at rtol 1e-11 over one period on the first-order form
  (the matrices evaluated at every stage), started from the Richardson-extrapolated
  shooting state at 2 × 2048 steps; its closure z(T) − z(0) shows how periodic it is.

Errors are max |q - q_ref| / max |q_ref| over the last period. Time per step of the
generalised-α loop is printed too (Python loop over steps; dense (n, n) solves).

Run: ``python benchmarks/response.py [--rpm 1200] [--quick]``
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import platform
import time
from pathlib import Path

import numpy as np
import scipy

HERE = Path(__file__).resolve().parent


def _example():
    spec = importlib.util.spec_from_file_location(
        "processing_machine", HERE.parent / "examples" / "processing_machine.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _reference(system, Omega, z0, n_out):
    """DOP853 over one period from z0 on the first-order form; q on n_out + 1 points."""
    from scipy.integrate import solve_ivp

    n, T = system.n, 2 * np.pi / Omega

    def rhs(t, z):
        M, B, C, F = system.matrices(Omega * t, Omega)
        return np.r_[z[n:], np.linalg.solve(M, F - B @ z[n:] - C @ z[:n])]

    t = np.linspace(0.0, T, n_out + 1)
    sol = solve_ivp(rhs, (0.0, T), z0, method="DOP853", rtol=1e-11, atol=1e-14, t_eval=t)
    return sol.y[:n].T, sol.y[:, -1], sol.nfev


def main(rpm: float = 1200.0, quick: bool = False, out_file=None, echo: bool = True) -> list:
    """Run the comparison; return the table rows (dicts)."""
    from femmech.analysis.response import (
        ConstantSpeed,
        periodic_steady_state,
        rayleigh_coefficients,
        rayleigh_damping,
        time_response,
    )
    from femmech.output.export import atomic_path

    ex = _example()
    base = ex.build()[0]
    system = rayleigh_damping(base, *rayleigh_coefficients(ex.FRAME_ZETA, *ex.ZETA_BAND_HZ))
    Omega = 2 * np.pi * rpm / 60.0
    T = 2 * np.pi / Omega
    n_ref = 256 if quick else 1024
    start = time.perf_counter()
    fine = periodic_steady_state(system, Omega, n_steps=2048, rho_inf=1.0, richardson=True)
    z0 = np.r_[fine.q[0], fine.v[0]]
    q_ref, zT, nfev = _reference(system, Omega, z0, n_ref)
    t_ref = time.perf_counter() - start
    scale = np.abs(q_ref).max()
    rows = [{"method": "reference: shooting + DOP853", "steps_per_period": 2048,
             "periods": 1, "seconds": t_ref, "rel_error": np.nan,
             "closure": np.abs(zT - z0)[:system.n].max() / scale, "nfev": nfev}]
    stride = lambda n: n_ref // n  # noqa: E731  (compare on the reference's grid)
    for n in ((64, 128) if quick else (128, 256, 512)):
        for label, kwargs in (("shooting, ρ∞ = 0.8", {}),
                              ("shooting, ρ∞ = 1 + Richardson", {"rho_inf": 1.0,
                                                                "richardson": True})):
            start = time.perf_counter()
            r = periodic_steady_state(system, Omega, n_steps=n, **kwargs)
            seconds = time.perf_counter() - start
            err = np.abs(r.q - q_ref[::stride(n)]).max() / scale
            rows.append({"method": label, "steps_per_period": n, "periods": 1,
                         "seconds": seconds, "rel_error": err})
    decay = 2 * np.pi * ex.ZETA_BAND_HZ[0] * ex.FRAME_ZETA  # 1/s, slowest frame decay
    for periods in ((5, 20) if quick else (10, 40, 160)):
        n = 256
        t = np.linspace(0.0, periods * T, periods * n + 1)
        start = time.perf_counter()
        r = time_response(system, t, ConstantSpeed(Omega))
        seconds = time.perf_counter() - start
        err = np.abs(r.q[-n - 1:] - q_ref[::stride(n)]).max() / scale
        rows.append({"method": "time_response from rest", "steps_per_period": n,
                     "periods": periods, "seconds": seconds, "rel_error": err,
                     "us_per_step": 1e6 * seconds / (periods * n),
                     "transient_left": np.exp(-decay * periods * T)})
    text = report(rows, system.n, rpm)
    if echo:
        print(text)
    if out_file is not None:
        with atomic_path(out_file) as tmp:
            Path(tmp).write_text(text + "\n")
    return rows


def report(rows, n, rpm) -> str:
    lines = [f"# Forced response: processing machine at {rpm:.0f} rpm, {n} coupled coordinates",
             f"# {platform.processor() or platform.machine()}, {os.cpu_count()} cores,"
             f" numpy {np.__version__}, scipy {scipy.__version__}",
             f"{'method':34s} {'steps/T':>8s} {'periods':>8s} {'time (s)':>9s}"
             f" {'rel. error':>11s}  notes"]
    for r in rows:
        notes = []
        if "closure" in r:
            notes.append(f"z(T) - z(0): {r['closure']:.1e}, {r['nfev']} rhs evaluations")
        if "us_per_step" in r:
            notes.append(f"{r['us_per_step']:.0f} µs/step, transient e^(-ζωt) ="
                         f" {r['transient_left']:.1e}")
        lines.append(f"{r['method']:34s} {r['steps_per_period']:8d} {r['periods']:8d}"
                     f" {r['seconds']:9.3f} {r['rel_error']:11.2e}  {'; '.join(notes)}")
    return "\n".join(lines)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rpm", type=float, default=1200.0)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    main(args.rpm, args.quick, out_file=HERE / "results" / "response.txt")
