"""Reduced coupled sweep vs full coupled ARPACK solve: textile main shaft with N cams.

Prints, side by side in one run, the time per angle of the reduced coupled sweep
(Craig-Bampton superelement of shaft + frame, mechanisms added per angle, dense LAPACK)
and of the full coupled solve (unreduced FE model + mechanisms, shift-invert ARPACK with
Sturm check), with the frequency error and MAC between them.

Run: ``python benchmarks/coupled_sweep.py [--n 50] [--angles 360] [--check 8]``
"""

from __future__ import annotations

import argparse
import functools
import importlib.util
import os
import platform
import time
from pathlib import Path

import numpy as np
import scipy

HERE = Path(__file__).resolve().parent


@functools.cache
def _example():
    """examples/textile_shaft.py as a module, loaded once per process."""
    spec = importlib.util.spec_from_file_location(
        "textile_shaft", HERE.parent / "examples" / "textile_shaft.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def arpack_full(full, phi: float, n_modes: int) -> dict:
    """The full coupled problem at one angle by femmech (block Lanczos + Sturm check) and
    by scipy's ``eigsh`` (ARPACK, the named reference), side by side.

    ARPACK runs in shift-invert mode at the shift femmech's solve settled on (after its
    far-shift correction; ARPACK at the default shift of the textile shaft took 24-35 s
    per angle), with a factor of ``C - σM`` from the same backend as its operator, tol = 0
    and one thread in its loop; its time includes that factorisation. Returns seconds of
    both, ARPACK's solves and the largest relative difference of their eigenvalues.
    """
    from frame_modes import counted_eigsh  # sibling benchmark (run.py loads it first)

    from femmech.solve.eigen import solve_symmetric
    from femmech.solve.pencil import factorize

    M, _, C, _ = full.matrices(phi)
    C = 0.5 * (C + C.T)  # Ω = 0: symmetric up to round-off
    start = time.perf_counter()
    result = solve_symmetric(C, M, n_modes=n_modes)
    femmech_s = time.perf_counter() - start
    start = time.perf_counter()
    factor = factorize((C - result.sigma * M).tocsc(), solver=result.solver)
    omega2, solves = counted_eigsh(C, M, n_modes, result.sigma, factor,
                                   return_eigenvectors=False)
    arpack_s = time.perf_counter() - start
    ref = result.omega2[:n_modes]
    return {"phi": phi, "femmech_s": femmech_s, "arpack_s": arpack_s, "arpack_solves": solves,
            "solver": result.solver, "sigma": result.sigma,
            "max_rel_diff": float(np.max(np.abs(omega2 - ref) / np.abs(ref)))}


def reduction_variant(model, cams, guides, f_max_hz: float, residual_vectors: bool, phi,
                      check, f_full, n_modes: int) -> dict:
    """Speed against error of one Craig-Bampton basis for the same machine.

    Reduces ``model`` with fixed-interface modes up to ``f_max_hz`` (with or without
    residual vectors), couples the cams, times the sweep over ``phi`` with vectors, tracked
    and untracked (``track=False``: the per-angle solves alone, as the full solve does
    them; fastest of 3 each), and compares the sorted frequencies at ``check`` with the
    full model's ``f_full`` (n_check, n_modes), Hz.
    """
    from femmech.analysis.sweep import sweep
    from femmech.coupling import couple
    from femmech.reduction.component_modes import craig_bampton

    ex = _example()
    start = time.perf_counter()
    se = craig_bampton(model, [(cams, ["rx"]), (guides, ["uz"])], f_max_hz=f_max_hz,
                       residual_vectors=residual_vectors)
    reduce_s = time.perf_counter() - start
    reduced = couple(se, ex.mounts(cams, guides))
    seconds = {True: [], False: []}
    for _ in range(3):
        for track in (True, False):
            start = time.perf_counter()
            sweep(reduced, phi, n_modes=n_modes, keep_vectors=True, track=track)
            seconds[track].append(time.perf_counter() - start)
    f = np.sort(sweep(reduced, check, n_modes=n_modes, track=False).freq_hz, axis=1)
    return {"f_max_hz": f_max_hz, "residual_vectors": residual_vectors, "n_reduced": reduced.n,
            "n_modal": se.n_modal, "reduction_s": reduce_s,
            "tracked_ms": 1e3 * min(seconds[True]) / phi.size,
            "untracked_ms": 1e3 * min(seconds[False]) / phi.size,
            "max_rel_error": float(np.max(np.abs(f / f_full - 1.0)))}


def main(n_cams: int = 50, n_angles: int = 360, n_check: int = 8, n_modes: int = 6,
         per_spacing: int = 8, keep_vectors: bool = False, n_arpack: int = 0,
         variants=()) -> dict:
    """Run the comparison; return the measured numbers.

    ``keep_vectors`` stores the mode shapes in the timed sweep; ``n_check = 0`` skips the
    full coupled solves (sweep timing only: the ``full_*``, ``speedup``, error and MAC
    entries are then None). ``per_angle`` holds, per checked angle (rad), the full solve's
    seconds, the largest relative frequency error and the smallest MAC of the n_modes.
    ``n_arpack``: at that many of the checked angles the full problem is also solved by
    ARPACK (:func:`arpack_full`; list ``arpack``, empty by default). ``variants``: pairs
    (f_max_hz, residual_vectors) of further Craig-Bampton bases compared at the checked
    angles (:func:`reduction_variant`; list ``variants``; needs ``n_check > 0``).
    """
    from femmech.analysis.reference import compare_coupled
    from femmech.analysis.sweep import sweep

    if variants and n_check <= 0:
        raise ValueError("variants need n_check > 0: their errors are measured against the"
                         " full coupled solves at the checked angles")
    ex = _example()
    start = time.perf_counter()
    reduced, full, model, se = ex.build(n_cams, per_spacing=per_spacing)
    t_build = time.perf_counter() - start
    phi = np.linspace(0.0, 2 * np.pi, n_angles, endpoint=False)
    start = time.perf_counter()
    sweep(reduced, phi, n_modes=n_modes, keep_vectors=keep_vectors)
    t_sweep = time.perf_counter() - start
    out = {
        "n_cams": n_cams, "fe_free_dofs": model.n_free, "n_full": full.n,
        "n_reduced": reduced.n, "build_s": t_build, "reduction_s": sum(se.timings.values()),
        "reduction_timings": dict(se.timings), "n_angles": n_angles, "n_modes": n_modes,
        "keep_vectors": keep_vectors, "sweep_s": t_sweep,
        "sweep_per_angle_ms": 1e3 * t_sweep / n_angles, "full_per_angle_ms": None,
        "max_rel_error": None, "min_mac": None, "speedup": None, "per_angle": None,
        "arpack": [], "variants": [],
    }
    if n_check <= 0:
        return out
    check = phi[:: max(1, n_angles // n_check)][:n_check]
    comparison = compare_coupled(reduced, full, check, n_modes)
    errors, macs, t_full = (np.abs(comparison.rel_error), comparison.diag_mac,
                            comparison.seconds_full)
    out.update(full_per_angle_ms=1e3 * t_full.mean(), max_rel_error=errors.max(),
               min_mac=macs.min(),
               per_angle={"phi": check, "full_s": t_full,
                          "max_rel_error": errors.max(axis=1), "min_mac": macs.min(axis=1)})
    out["speedup"] = out["full_per_angle_ms"] / out["sweep_per_angle_ms"]
    out["arpack"] = [arpack_full(full, angle, n_modes) for angle in check[:n_arpack]]
    if variants:
        model, cams, guides = ex.frame_and_shaft(n_cams, per_spacing)  # the same model
        out["variants"] = [reduction_variant(model, cams, guides, f_max, rv, phi, check,
                                             comparison.freq_full_hz, n_modes)
                           for f_max, rv in variants]
    return out


def report(result: dict, n_angles: int) -> str:
    """Plain-text table with machine information."""
    lines = [
        f"machine: {os.cpu_count()} CPUs, {platform.machine()}, python"
        f" {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}",
        f"textile main shaft with {result['n_cams']} cam mechanisms in a frame:"
        f" FE {result['fe_free_dofs']} free DOFs; coupled full {result['n_full']},"
        f" reduced {result['n_reduced']} coordinates",
        f"build (FE + reduction + coupling): {result['build_s']:.2f} s"
        f" (reduction {result['reduction_s']:.2f} s)",
        "",
        f"{'path':<44}{'ms/angle':>10}",
        f"{'reduced coupled sweep (' + str(n_angles) + ' angles, tracked)':<44}"
        f"{result['sweep_per_angle_ms']:>10.2f}",
        f"{'full coupled solve (shift-invert, Sturm)':<44}{result['full_per_angle_ms']:>10.1f}",
        f"speedup per angle: {result['speedup']:.0f}x",
        f"reduced vs full (6 lowest modes, sampled angles): max relative frequency error"
        f" {result['max_rel_error']:.2e}, min MAC {result['min_mac']:.8f}",
    ]
    return "\n".join(lines)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=50)
    parser.add_argument("--angles", type=int, default=360)
    parser.add_argument("--check", type=int, default=8)
    parser.add_argument("--per-spacing", type=int, default=8,
                        help="FE elements of shaft and base between neighbouring cams")
    args = parser.parse_args()
    text = report(main(args.n, args.angles, args.check, per_spacing=args.per_spacing),
                  args.angles)
    print(text)
    (HERE / "results").mkdir(exist_ok=True)
    (HERE / "results" / "coupled_sweep.txt").write_text(text + "\n")
