"""Error control of the monodromy matrix: steps, estimate, true error and time over speed.

The slider-crank press of examples/press_frame.toml (25 coupled coordinates, frame
Rayleigh damping 2 1/s and 1e-5 s as in its stability analysis) at drive speeds from 10
to 3000 rpm. For each speed, side by side in one process:

* the old fixed step count (128 Magnus steps per period, no check);
* the step-doubling integration (``coupled_monodromy(..., rtol=...)``) at the tolerances
  asked for: steps per period reached, the estimate |ρ_N − ρ_{N/2}| / ρ, the true error
  and the time;
* the reference: the same integrator at rtol 1e-8 (at most 32 768 steps).

Run: ``python benchmarks/monodromy_error_control.py [--rtol 1e-3 1e-4] [--rpm 10 100 3000]``
(the full default set takes a few minutes on two cores; low speeds dominate, since the
steps needed grow as 1/Ω).
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

from femmech.analysis.floquet import coupled_monodromy
from femmech.analysis.response import rayleigh_damping
from femmech.errors import ConvergenceWarning
from femmech.scene.build import prepare
from femmech.scene.load import load_scene
from femmech.scene.run import Workshop

HERE = Path(__file__).resolve().parent
RPM = 2 * np.pi / 60


def press():
    """The press of examples/press_frame.toml with its stability analysis' damping."""
    scene = load_scene(HERE.parent / "examples" / "press_frame.toml")
    workshop = Workshop(prepare(scene), None, lambda line: None, False)
    return rayleigh_damping(workshop.machine(), 2.0, 1e-5)


def main(argv=None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rpm", type=float, nargs="+", default=[10, 30, 100, 300, 1000, 3000])
    parser.add_argument("--rtol", type=float, nargs="+", default=[1e-3, 1e-4, 1e-5])
    args = parser.parse_args(argv)
    system = press()
    rows = []
    print(f"{'rpm':>6} {'rtol':>7} {'steps':>6} {'estimate':>9} {'true err':>9}"
          f" {'time s':>7} {'conv':>5}   fixed 128 steps (true err)")
    for rpm in args.rpm:
        W = rpm * RPM
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConvergenceWarning)
            ref = coupled_monodromy(system, W, 32, rtol=1e-8, max_steps=2**15,
                                    full_output=True)
            fixed = coupled_monodromy(system, W, 128, rtol=None, full_output=True)
            for rtol in args.rtol:
                start = time.perf_counter()
                got = coupled_monodromy(system, W, rtol=rtol, full_output=True)
                seconds = time.perf_counter() - start
                rho = ref.spectral_radius
                row = {"rpm": rpm, "rtol": rtol, "steps": got.n_steps,
                       "estimate": got.error / got.spectral_radius,
                       "true": abs(got.spectral_radius - rho) / rho, "seconds": seconds,
                       "converged": got.converged, "fixed_true":
                       abs(fixed.spectral_radius - rho) / rho}
                rows.append(row)
                print(f"{rpm:6.0f} {rtol:7.0e} {row['steps']:6d} {row['estimate']:9.1e}"
                      f" {row['true']:9.1e} {seconds:7.2f} {str(got.converged):>5}"
                      f"   {fixed.spectral_radius:.6g} ({row['fixed_true']:.1e})")
        print(f"{'':6} reference {rho:.10g} ({ref.n_steps} steps, converged {ref.converged})")
    return rows


if __name__ == "__main__":
    main()
