"""Benchmark: a 1M-DOF shell/beam machine frame, Craig-Bampton reduced and swept with cams.

Model (:func:`machine_bed`): a welded machine bed, a rectangular steel box of 6 mm plates
4.0 m long (x), 0.8 m wide (y), 0.6 m high (z), meshed with flat quads (MITC4 bending +
membrane + drilling, :mod:`femmech.fe.elements.shell`; ``n`` quads per 0.2 m), stiffened by
ring frames (box-section beams 60 x 60 x 5 mm round the perimeter every 0.2 m) and two
top rails (80 x 80 x 6 mm along the top edges), standing on four feet (all DOFs of the
bottom-plate nodes within 0.2 m of either end fixed). Sizes ``"tiny"``, ``"small"``,
``"medium"``, ``"large"``: ``n = 1, 6, 12, 24``, 1 788, 61 008, 242 952 and 969 720 DOFs
(1 548, 58 692, 234 630 and 937 926 free).

Machine: a cam shaft on four bearing seats on the top plate, each seat an RBE2 spider
(:class:`~femmech.RigidLink`) from the bearing centre 80 mm above the plate to the plate
nodes within 50 mm of the seat, and four return-spring brackets (single top-plate nodes
0.2 m beside the seats). Interface: the six DOFs of the four bearing centres and uz of
the four brackets, 28 DOFs. Four cam followers (:func:`femmech.mechanisms.mounted.
cam_follower`, the processing machine's first cam U1 with m1, c3, c6, b3 and a cam
inertia of 2e-3 kg m², phases 0, 90, 180, 270°) are attached rigidly: the cam's twist to
the seat's rx, the cam centre to its uz, the return-spring base to the bracket's uz.

Phases, each timed and with its peak resident memory above the start of the phase
(``VmHWM`` reset through ``/proc/self/clear_refs``, the helpers of ``frame_modes.py``):

- mesh: generating the quads, beams and spiders;
- build: ``build_model`` (element matrices of shells and beams, assembly, ``Tᵀ K T``);
- reduce: ``craig_bampton`` with 30 fixed-interface modes and residual vectors, split as
  :attr:`~femmech.reduction.superelement.Superelement.timings` (factorisation of
  ``K_ii``, constraint modes, fixed-interface modes with their Sturm check, projection);
- couple: mounting the four mechanisms on the superelement;
- sweep: 360 drive angles, 10 tracked branches with mode shapes;
- check (optional, ``--check k``): the unreduced coupled system solved at k angles by
  shift-invert Lanczos with Sturm check, for the frequency error of the reduced sweep.

Usage::

    python benchmarks/scale.py                      # the 1M-DOF model (~10 min, ~10 GB)
    python benchmarks/scale.py --size medium --check 2
    python benchmarks/scale.py --size tiny          # smoke test

Results are printed and written to ``benchmarks/results/scale.txt``.
"""

from __future__ import annotations

import argparse
import dataclasses
import gc
import importlib.util
import resource
import sys
import time
from pathlib import Path

import numpy as np

import femmech as fm
from femmech.analysis.reference import compare_coupled
from femmech.analysis.sweep import sweep
from femmech.coupling import Attachment, Mount, couple
from femmech.fe import sections
from femmech.mechanisms import processing_machine_cams, processing_machine_parameters
from femmech.mechanisms.models import rheolinear
from femmech.mechanisms.mounted import cam_follower
from femmech.reduction.component_modes import craig_bampton
from femmech.solve import direct, threads

HERE = Path(__file__).resolve().parent
LENGTH, WIDTH, HEIGHT = 4.0, 0.8, 0.6  # m: machine bed (x, y, z)
CELL = 0.2  # m: n quads per CELL; ring frames every CELL
THICKNESS = 0.006  # m: plates
STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)
RING = sections.rectangular_hollow(0.06, 0.06, 0.005)
RAIL = sections.rectangular_hollow(0.08, 0.08, 0.006)
FOOT = 0.2  # m: bottom-plate nodes this close to either end are fixed
SEAT_RADIUS = 0.05  # m: plate nodes of a bearing seat
SEAT_HEIGHT = 0.08  # m: bearing centre above the top plate
BRACKET_OFFSET = 0.2  # m: return-spring bracket beside its seat (x)
SEATS_X = (0.6, 1.4, 2.6, 3.4)  # m: bearing seats along the bed
CAM_INERTIA = 2e-3  # kg m²
N_FIXED_MODES = 30
N_ANGLES = 360
N_BRANCHES = 10
SIZES = {"tiny": 1, "small": 6, "medium": 12, "large": 24}


def _frame_helpers():
    """The measurement helpers of benchmarks/frame_modes.py (one implementation)."""
    spec = importlib.util.spec_from_file_location("_frame_modes_helpers", HERE / "frame_modes.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


fmb = _frame_helpers()


def machine_bed(n: int) -> tuple[fm.Mesh, dict]:
    """Mesh of the machine bed with ``n`` quads per 0.2 m, and the machine's node groups.

    Returns
    -------
    Mesh
        Quads in the cell set ``"plates"``, ring-frame beams in ``"rings"``, top-rail
        beams in ``"rails"``; node sets ``"feet"`` (fixed), ``"seat{k}"`` (bearing
        centres) and ``"bracket{k}"`` (return-spring bases), k = 1..4.
    dict
        ``"seats"``: (bearing-centre node, plate nodes of its spider) per seat;
        ``"brackets"``: bracket nodes.
    """
    if not (isinstance(n, int) and n >= 1):
        raise ValueError(f"n (quads per {CELL} m) must be a positive integer, got {n!r}")
    nl, nw, nh = (round(d / CELL * n) for d in (LENGTH, WIDTH, HEIGHT))
    corners = np.array([[0, 0], [WIDTH, 0], [WIDTH, HEIGHT], [0, HEIGHT], [0, 0]])
    counts = [nw, nh, nw, nh]
    ring = np.vstack([c0 + np.outer(np.arange(k) / k, c1 - c0)
                      for c0, c1, k in zip(corners[:-1], corners[1:], counts, strict=True)])
    p = len(ring)  # nodes round the perimeter, counter-clockwise seen from +x
    x = np.linspace(0.0, LENGTH, nl + 1)
    points = np.column_stack([np.repeat(x, p), np.tile(ring[:, 0], nl + 1),
                              np.tile(ring[:, 1], nl + 1)])
    i = np.arange(nl)[:, None]
    j = np.arange(p)[None, :]
    a, b = i * p + j, i * p + (j + 1) % p
    quads = np.stack([a, a + p, b + p, b], axis=-1).reshape(-1, 4)
    stations = np.arange(0, nl + 1, n)  # ring frames every CELL
    rings = np.stack([stations[:, None] * p + j, stations[:, None] * p + (j + 1) % p],
                     axis=-1).reshape(-1, 2)
    top_corners = (nw + nh, 2 * nw + nh)  # ring indices of (W, H) and (0, H)
    rails = np.vstack([np.column_stack([np.arange(nl) * p + c, np.arange(1, nl + 1) * p + c])
                       for c in top_corners])
    bottom = points[:, 2] < 1e-9
    feet = np.flatnonzero(bottom & ((points[:, 0] <= FOOT + 1e-9)
                                    | (points[:, 0] >= LENGTH - FOOT - 1e-9)))
    top = np.flatnonzero(np.abs(points[:, 2] - HEIGHT) < 1e-9)
    h = CELL / n
    radius = max(SEAT_RADIUS, 1.01 * h)  # at least the 3 x 3 patch of a coarse mesh
    centres, patches, brackets = [], [], []
    for k, xs in enumerate(SEATS_X):
        seat = np.array([xs, WIDTH / 2, HEIGHT])
        patches.append(top[np.linalg.norm(points[top] - seat, axis=1) <= radius])
        centres.append(len(points) + k)
        bracket = seat + [max(BRACKET_OFFSET, 2 * h), 0.0, 0.0]  # outside the spider
        brackets.append(int(top[np.argmin(np.linalg.norm(points[top] - bracket, axis=1))]))
    seat_points = np.array([[xs, WIDTH / 2, HEIGHT + SEAT_HEIGHT] for xs in SEATS_X])
    node_sets = {"feet": feet}
    for k, (c, br) in enumerate(zip(centres, brackets, strict=True)):
        node_sets[f"seat{k + 1}"] = np.array([c])
        node_sets[f"bracket{k + 1}"] = np.array([br])
    lines = np.vstack([rings, rails])
    mesh = fm.Mesh(np.vstack([points, seat_points]), {"quad": quads, "line": lines},
                   {"plates": {"quad": np.arange(len(quads))},
                    "rings": {"line": np.arange(len(rings))},
                    "rails": {"line": len(rings) + np.arange(len(rails))}},
                   node_sets)
    return mesh, {"seats": list(zip(centres, patches, strict=True)), "brackets": brackets}


def build(mesh: fm.Mesh, groups: dict) -> fm.FEModel:
    """The FE model of the bed: plates, ring frames, rails, feet and seat spiders."""
    beams = {"rings": fm.BeamProperty(RING, STEEL, orientation=[1.0, 0.0, 0.0]),
             "rails": fm.BeamProperty(RAIL, STEEL, orientation=[0.0, 0.0, 1.0])}
    links = [fm.RigidLink(int(c), patch) for c, patch in groups["seats"]]
    return fm.build_model(mesh, beams, shells={"plates": fm.ShellProperty(THICKNESS, STEEL)},
                          supports=[fm.Support("feet")], rigid_links=links)


def interface(groups: dict) -> list:
    """Six DOFs of each bearing centre, uz of each bracket: 28 DOFs."""
    return [int(c) for c, _ in groups["seats"]] + [(groups["brackets"], ["uz"])]


def mounts(groups: dict) -> list[Mount]:
    """Four cam followers (cam U1, phases 0, 90, 180, 270°) on the seats and brackets."""
    p = processing_machine_parameters()
    params = {"m": p["m1"], "c": p["c3"], "c_r": p["c6"], "b": p["b3"], "F": p["F1"],
              "J": CAM_INERTIA}
    model = rheolinear(cam_follower("U", "m", "c", "c_r", "b", "F", J="J", name="cam"),
                       params, {"U": processing_machine_cams()["U1"]})
    return [Mount(model, (Attachment("q_s", int(c), "rx"), Attachment("y_c", int(c), "uz"),
                          Attachment("y_f", int(br), "uz")),
                  phase=0.5 * np.pi * k, name=f"cam{k + 1}")
            for k, ((c, _), br) in enumerate(zip(groups["seats"], groups["brackets"],
                                                  strict=True))]


def _timed(row: dict, key: str, func, *args, **kwargs):
    """``func(*args, **kwargs)`` with its seconds in ``row[key + '_s']`` and its peak
    memory above the start in ``row[key + '_peak_mb']``."""
    with fmb.peak_memory(row, f"{key}_peak_mb"):
        start = time.perf_counter()
        out = func(*args, **kwargs)
        row[f"{key}_s"] = time.perf_counter() - start
    return out


def run(size: str = "large", n_angles: int = N_ANGLES, n_check: int = 0,
        n_fixed_modes: int = N_FIXED_MODES, n_branches: int = N_BRANCHES) -> dict:
    """Build, reduce, couple and sweep the machine of ``size``; return the measurements.

    The dict holds the sizes (``dofs``, ``free_dofs``, ``interface_dofs``, ``reduced``,
    ``coupled``), per phase the seconds (``*_s``) and peak memory (``*_peak_mb``), the
    reduction's split (``reduce_split``), the process's peak resident memory
    (``maxrss_mb``), the lowest coupled frequencies at φ = 0 and, with ``n_check > 0``,
    the largest relative frequency error of the reduced sweep against the full coupled
    solve (``max_rel_error``) and its seconds per angle (``full_s``).
    """
    if size not in SIZES:
        raise ValueError(f"unknown size {size!r}; choose from {list(SIZES)}")
    for name, value in (("n_angles", n_angles), ("n_branches", n_branches),
                        ("n_fixed_modes", n_fixed_modes)):
        if value < 1:
            raise ValueError(f"{name} must be a positive integer, got {value}")
    row = {"size": size, "n": SIZES[size], "solver": "?", "sweep_angles": n_angles}
    mesh, groups = _timed(row, "mesh", machine_bed, SIZES[size])
    model = _timed(row, "build", build, mesh, groups)
    row.update(dofs=model.n_dof, free_dofs=model.n_free, quads=len(mesh.cells["quad"]),
               beams=len(mesh.cells["line"]))
    se = _timed(row, "reduce", craig_bampton, model, interface(groups),
                n_modes=n_fixed_modes)
    row.update(interface_dofs=se.n_interface, fixed_modes=n_fixed_modes,
               residual_vectors=se.n_residual, reduced=se.K.shape[0],
               reduce_split=dict(se.timings))
    row["solver"] = getattr(se.interior_factor, "name", row["solver"])  # K_ii's backend
    cams = mounts(groups)  # the symbolic cam model, derived once for all couplings
    system = _timed(row, "couple", couple, se, cams)
    row["coupled"] = system.n
    phi = np.linspace(0.0, 2 * np.pi, n_angles, endpoint=False)
    result = _timed(row, "sweep", sweep, system, phi, n_modes=n_branches, keep_vectors=True)
    row["sweep_ms_per_angle"] = 1e3 * row["sweep_s"] / n_angles
    row["f0_hz"] = result.freq_hz[0].tolist()
    if n_check > 0:
        # free the K_ii factorisation (the superelement keeps it for recovery) before the
        # full solves factorise the whole model
        system = couple(dataclasses.replace(se, interior_factor=None), cams)
        del result, se
        gc.collect()
        full = couple(model, cams)
        check = phi[:: max(1, n_angles // n_check)][:n_check]
        comparison = _timed(row, "check", compare_coupled, system, full, check, n_branches)
        row["max_rel_error"] = float(np.abs(comparison.rel_error).max())
        row["min_mac"] = float(comparison.diag_mac.min())
        row["full_s"] = float(comparison.seconds_full.mean())
        row["n_check"] = len(check)
    row["maxrss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return row


def format_report(row: dict, header: bool = True) -> list[str]:
    """Plain-text tables of one run, headed (``header``) by machine, versions and threads."""
    lines = fmb.machine_info() + [threads.describe(),
                                  "solvers: " + "; ".join(f"{k}: {v}" for k, v
                                                          in direct.versions().items())] \
        if header else []
    lines += [f"sparse solver of K_ii: {row['solver']}", ""]
    lines.append(f"Machine bed {LENGTH} x {WIDTH} x {HEIGHT} m, {THICKNESS * 1e3:g} mm plates"
                 f" (n = {row['n']} quads per {CELL} m): {row['quads']:,} quads,"
                 f" {row['beams']:,} beams, {row['dofs']:,} DOFs, {row['free_dofs']:,} free;"
                 f" interface {row['interface_dofs']} DOFs; Craig-Bampton"
                 f" {row['fixed_modes']} fixed-interface modes + {row['residual_vectors']}"
                 f" residual vectors = {row['reduced']} coordinates; coupled with four cams:"
                 f" {row['coupled']}")
    phases = [("mesh", "mesh generation"), ("build", "build_model (elements, assembly, T'KT)"),
              ("reduce", "Craig-Bampton reduction"), ("couple", "coupling (4 cam followers)"),
              ("sweep", f"sweep ({row['sweep_angles']} angles, vectors)")]
    if "check_s" in row:
        phases.append(("check", f"full coupled check ({row['n_check']} angles)"))
    table = [[label, f"{row[f'{key}_s']:.2f}", f"{row[f'{key}_peak_mb']:.0f}"]
             for key, label in phases]
    lines += fmb._table("Phases (peak MB: resident memory above the start of the phase)",
                        ["phase", "s", "peak MB"], table)
    split = row["reduce_split"]
    lines += fmb._table("Craig-Bampton split", list(split) + ["total"],
                        [[f"{v:.2f}" for v in split.values()]
                         + [f"{sum(split.values()):.2f}"]])
    lines.append(f"sweep: {row['sweep_ms_per_angle']:.2f} ms per angle; lowest coupled"
                 f" frequencies at phi = 0: "
                 + ", ".join(f"{f:.2f}" for f in row["f0_hz"][:6]) + " Hz")
    if "check_s" in row:
        lines.append(f"reduced vs full coupled ({row['n_check']} angles, {N_BRANCHES}"
                     f" branches): max relative frequency error {row['max_rel_error']:.2e},"
                     f" min MAC {row['min_mac']:.6f}; full solve {row['full_s']:.1f} s per"
                     f" angle = {1e3 * row['full_s'] / row['sweep_ms_per_angle']:.0f}x the"
                     " reduced sweep's time per angle")
    lines.append(f"process peak resident memory (ru_maxrss): {row['maxrss_mb']:.0f} MB")
    return lines


def main(size: str = "large", n_angles: int = N_ANGLES, n_check: int = 0,
         out_file=HERE / "results" / "scale.txt", echo: bool = True) -> dict:
    """Run :func:`run` and print / write the report (``out_file=None``: not written)."""
    row = run(size, n_angles, n_check)
    fmb.publish("\n".join(format_report(row)), out_file, echo)
    return row


def _cli(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--size", default="large", choices=list(SIZES))
    parser.add_argument("--angles", type=int, default=N_ANGLES)
    parser.add_argument("--check", type=int, default=0,
                        help="angles at which the unreduced coupled system is solved too")
    parser.add_argument("--out", default=str(HERE / "results" / "scale.txt"))
    args = parser.parse_args(argv)
    main(args.size, args.angles, args.check, Path(args.out))


if __name__ == "__main__":
    sys.exit(_cli())
