"""Benchmark: speed versus error of Guyan and Craig-Bampton reduction of a machine frame.

Model (``large``, the default): a machine-frame-like steel space frame,
:func:`femmech.fe.generators.grid_frame` with 8 x 4 x 4 bays over 4 m x 2 m x 2 m (bay
0.5 m), every member subdivided into 16 Timoshenko elements: 51 750 DOFs, hollow
sections (longitudinals 80 x 120 x 5 mm, cross beams 80 x 80 x 5 mm, columns
100 x 100 x 6 mm box), fixed at the base joints. Interface: all six DOFs of the top
joints on the two long edges (the seats of the machine's guide rails), n_b = 108.

In one process the benchmark runs

- the full reference: ``femmech.modes(model, n_modes=20)`` (time, f1..f20);
- Guyan, and Craig-Bampton with several counts of fixed-interface modes and with
  ``f_max_hz = f20`` (modes below ``CUTOFF_FACTOR`` x f20). For each: reduction time
  (total and the library's split ``Superelement.timings``), reduced solve time
  (``scipy.linalg.eigh(se.K, se.M, subset_by_index=[0, 19])``), max and median relative
  error of the first 20 frequencies against the full solve, the largest a-posteriori
  estimate (``frequency_error_estimates``) and the ratio estimate / true error per mode
  (median and range, over modes whose true error is above round-off), the time of the
  estimate, and the smallest mass-weighted MAC between the recovered and the full
  shapes (modes paired by order; for a cluster of equal frequencies, the cosine² of the
  largest principal angle between the two subspaces).

The table is printed and written to ``benchmarks/results/reduction.txt``; a log-log
plot of total time (reduction + reduced solve) against max relative frequency error,
with the estimated error beside the true one and the full solve's time as a horizontal
line, goes to ``benchmarks/results/reduction.png``.

Usage::

    python benchmarks/reduction.py [--size tiny|small|large] [--columns box|i]

``--columns i`` uses open I-section columns (100 x 100 x 6/10 mm) instead: their
clamped-clamped torsion modes (~351 Hz, one per column, 180 columns) form a dense
cluster of fixed-interface modes just above f20, which is slow for ARPACK and stalls
the Craig-Bampton convergence at a fixed mode count (see benchmarks/README.md).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np
import scipy
import scipy.linalg as sla

import femmech as fm
import femmech.reduction as reduction
from femmech.fe import sections
from femmech.fe.generators import grid_frame
from femmech.output.export import atomic_path

N_MODES = 20
STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0, name="steel")
RESULTS = Path(__file__).resolve().parent / "results"
# name: (bays, size m, subdivisions, Craig-Bampton mode counts)
SIZES = {
    "tiny": ((2, 1, 1), (1.0, 0.5, 0.5), 4, (5, 10, 20)),           # 432 DOFs (smoke test)
    "small": ((4, 2, 2), (2.0, 1.0, 1.0), 8, (10, 20, 40, 80)),     # 4 302 DOFs
    "large": ((8, 4, 4), (4.0, 2.0, 2.0), 16, (10, 20, 40, 80, 160)),  # 51 750 DOFs
}
COLUMNS = {
    "box": sections.rectangular_hollow(0.1, 0.1, 0.006),
    "i": sections.i_section(0.1, 0.1, 0.006, 0.01),
}
ROUND_OFF = 1e-10  # true relative errors below this are round-off: no estimate ratio


# --- model ----------------------------------------------------------------------------

def build(size: str, columns: str = "box"):
    """The frame model and its interface nodes (top joints on the two long edges)."""
    bays, extent, subdivisions, _ = SIZES[size]
    mesh = grid_frame(bays, extent, subdivisions)
    beams = {
        "beams_x": fm.BeamProperty(sections.rectangular_hollow(0.08, 0.12, 0.005), STEEL),
        "beams_y": fm.BeamProperty(sections.rectangular_hollow(0.08, 0.08, 0.005), STEEL),
        "columns": fm.BeamProperty(COLUMNS[columns], STEEL),
    }
    model = fm.build_model(mesh, beams, supports=[fm.Support("base")])
    top = mesh.node_sets["top"]
    y = mesh.points[top, 1]
    rails = top[np.isclose(y, 0.0) | np.isclose(y, extent[1])]
    return model, rails


# --- measurements ---------------------------------------------------------------------

def full_case(model):
    """Reference: the 20 lowest modes of the full model."""
    start = time.perf_counter()
    result = fm.modes(model, n_modes=N_MODES)
    seconds = time.perf_counter() - start
    return {"case": "full", "n_b": 0, "n_q": 0, "n_r": model.n_free, "reduce_s": None,
            "solve_s": seconds, "total_s": seconds, "freq_hz": result.freq_hz[:N_MODES],
            "shapes": result.shapes[:, :N_MODES], "method": result.method,
            "sturm_count": result.sturm_count}


def reduced_case(model, interface, full, label, repeat=1, **selector):
    """Reduce (Guyan if no selector), solve, compare with ``full``; one table row.

    Reduction and reduced solve run ``repeat`` times; the fastest run is reported.
    """
    runs = [_reduce_and_solve(model, interface, selector) for _ in range(repeat)]
    se, omega2, q, reduce_s, solve_s = min(runs, key=lambda run: run[3] + run[4])
    start = time.perf_counter()
    estimate = reduction.frequency_error_estimates(model, se, omega2, q)
    estimate_s = time.perf_counter() - start
    freq_hz = np.sqrt(np.clip(omega2, 0.0, None)) / (2 * np.pi)
    f_ref = full["freq_hz"][:len(freq_hz)]
    error = (freq_hz - f_ref) / f_ref
    ratio = estimate[np.abs(error) > ROUND_OFF] / error[np.abs(error) > ROUND_OFF]
    mac_order, mac_best = mac_pairs(full["shapes"][:, :len(freq_hz)], se.recover(q), f_ref,
                                    model.M)
    timings = {k: se.timings[k] for k in ("factorisation", "constraint_modes",
                                          "fixed_interface_modes", "projection")}
    n_res = getattr(se, "n_residual", 0)
    n_fixed = se.n_modal - n_res
    return {"case": label, "n_b": se.n_interface, "n_q": n_fixed, "n_res": n_res,
            "n_r": se.n_reduced,
            "reduce_s": reduce_s, "timings": timings, "solve_s": solve_s,
            "total_s": reduce_s + solve_s, "estimate_s": estimate_s, "freq_hz": freq_hz,
            "error": error, "estimate": estimate, "mac_order": mac_order, "mac_best": mac_best,
            "max_err": float(np.abs(error).max()), "median_err": float(np.median(np.abs(error))),
            "min_err": float(error.min()), "max_est": float(np.abs(estimate).max()),
            "ratio": ratio, "min_mac": float(mac_order.min()),
            "min_mac_best": float(mac_best.min()),
            "f_top_modal_hz": float(se.modal_freq_hz[:n_fixed].max()) if n_fixed else None}


def _reduce_and_solve(model, interface, selector):
    start = time.perf_counter()
    if selector:
        se = reduction.craig_bampton(model, interface, **selector)
    else:
        se = reduction.guyan(model, interface)
    reduce_s = time.perf_counter() - start
    start = time.perf_counter()
    omega2, q = sla.eigh(se.K, se.M, subset_by_index=[0, min(N_MODES, se.n_reduced) - 1])
    return se, omega2, q, reduce_s, time.perf_counter() - start


def clusters(freq_hz, rtol=1e-6):
    """Index groups of (numerically) equal frequencies, in ascending order."""
    groups = [[0]]
    for i in range(1, len(freq_hz)):
        if abs(freq_hz[i] - freq_hz[i - 1]) <= rtol * freq_hz[i]:
            groups[-1].append(i)
        else:
            groups.append([i])
    return groups


def mac_pairs(full_shapes, shapes, full_freq_hz, M):
    """Mass-weighted MAC of recovered vs full modes: paired by order, and best match.

    Both sets are M-orthonormal, so MAC = (φᵀ M ψ)². Paired by order, a cluster of equal
    full frequencies is compared as a subspace: each of its modes gets the smallest
    singular value² of Φ_Cᵀ M Ψ_C (cos² of the largest principal angle). Best match:
    for each full mode, the largest MAC with any of the recovered modes (insensitive to
    close modes that swap order in the reduced model).

    Returns
    -------
    (ndarray (n,), ndarray (n,))
    """
    C = full_shapes.T @ (M @ shapes)
    order = np.diag(C) ** 2
    for group in clusters(full_freq_hz):
        if len(group) > 1:
            order[group] = np.linalg.svd(C[np.ix_(group, group)], compute_uv=False).min() ** 2
    return order, (C**2).max(axis=1)


# --- output ---------------------------------------------------------------------------

def machine_info(load_start) -> list[str]:
    cpu = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                if line.startswith("model name")), platform.processor())
    load = [", ".join(f"{x:.1f}" for x in loads) for loads in (load_start, os.getloadavg())]
    threads = os.environ.get("OPENBLAS_NUM_THREADS", "default")
    return [f"machine: {os.cpu_count()} CPUs ({cpu}), OPENBLAS_NUM_THREADS={threads},"
            f" load average (1, 5, 15 min) at start {load[0]}, at end {load[1]}",
            f"python {platform.python_version()}, numpy {np.__version__},"
            f" scipy {scipy.__version__}, femmech {getattr(fm, '__version__', 'dev')}"]


def _table(header, lines):
    widths = [max(len(h), *(len(x[i]) for x in lines)) for i, h in enumerate(header)]
    out = ["  ".join(h.rjust(w) for h, w in zip(header, widths, strict=True))]
    return out + ["  ".join(c.rjust(w) for c, w in zip(x, widths, strict=True)) for x in lines]


def _ratio(r):
    ratio = r["ratio"]
    if ratio.size == 0:
        return "- (round-off)"
    return f"{np.median(ratio):.2f} [{ratio.min():.2f}, {ratio.max():.2f}]"


def format_report(model, interface, full, rows, size, columns, load_start) -> list[str]:
    f = full["freq_hz"]
    out = machine_info(load_start) + [
        f"model: grid_frame {SIZES[size][0]} bays, {SIZES[size][2]} elements/member,"
        f" {columns} columns; {model.n_dof:,} DOFs, {model.n_free:,} free,"
        f" {len(model.beams.cells):,} elements",
        f"interface: top joints on the long edges, {len(interface)} nodes,"
        f" n_b = {rows[0]['n_b']} DOFs",
        f"full: femmech.modes(n_modes={N_MODES}) {full['solve_s']:.2f} s ({full['method']},"
        f" Sturm count {full['sturm_count']})",
        "f1..f20 Hz: " + " ".join(f"{x:.2f}" for x in f), ""]
    header = ["case", "n_q", "n_res", "n_r", "reduce s", "factor", "constr", "fixed-if", "project",
              "solve s", "total s", "max err", "median err", "max est", "est/true med [range]",
              "est s", "min MAC order/best"]
    lines = [[r["case"], str(r["n_q"]), str(r["n_res"]), str(r["n_r"]), f"{r['reduce_s']:.2f}",
              *(f"{t:.2f}" for t in r["timings"].values()), f"{r['solve_s']:.3f}",
              f"{r['total_s']:.2f}", f"{r['max_err']:.2e}", f"{r['median_err']:.2e}",
              f"{r['max_est']:.2e}", _ratio(r), f"{r['estimate_s']:.2f}",
              f"{r['min_mac']:.4f} / {r['min_mac_best']:.4f}"] for r in rows]
    lines.append(["full", "-", "-", f"{model.n_free}", "-", "-", "-", "-", "-",
                  f"{full['solve_s']:.3f}", f"{full['total_s']:.2f}", "0", "0", "-", "-", "-",
                  "1 / 1"])
    notes = ["", "CB: classical Craig-Bampton (residual_vectors=False); CB+RV: with residual"
             " vectors (the default); n_q fixed-interface modes, n_res residual vectors;",
             "times in s; factor/constr/fixed-if/project = Superelement.timings"
             " (K_ii factorisation, constraint modes, fixed-interface modes + residual"
             " vectors, projection);",
             "errors: relative errors of f1..f20 vs the full solve; est = a-posteriori"
             " frequency_error_estimates; est/true over modes with error > 1e-10;",
             "MAC mass-weighted; order: paired by order (subspace for equal frequencies),"
             " best: best match among the 20 recovered modes."]
    top = [r["f_top_modal_hz"] for r in rows if r["case"].endswith("f_max=f20")]
    if top and top[0] is not None:
        notes.append(f"f_max=f20: f_max = {f[-1]:.2f} Hz, highest fixed-interface mode"
                     f" kept {top[0]:.1f} Hz (cutoff {reduction.CUTOFF_FACTOR:g} x f_max).")
    return out + _table(header, lines) + notes + [""] + mode_table(full, rows)


def mode_table(full, rows, cases=("CB f_max=f20", "CB+RV f_max=f20")) -> list[str]:
    """Per-mode comparison for the f_max cases: true vs estimated error, MAC."""
    picked = [r for r in rows if r["case"] in cases]
    header = ["mode", "f full Hz"]
    for r in picked:
        header += [f"{r['case']}: err", "est", "est/true", "MAC order"]
    lines = []
    for i, f in enumerate(full["freq_hz"]):
        line = [str(i + 1), f"{f:.3f}"]
        for r in picked:
            e, est = r["error"][i], r["estimate"][i]
            line += [f"{e:.2e}", f"{est:.2e}", f"{est / e:.2f}" if abs(e) > ROUND_OFF else "-",
                     f"{r['mac_order'][i]:.4f}"]
        lines.append(line)
    return ["Per mode, f_max = f20 cases:"] + _table(header, lines)


def plot(full, rows, path, title="Guyan / Craig-Bampton: time vs error"):
    """Log-log total time vs max relative frequency error (true and estimated)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8.0, 5.5))
    series = [("Guyan", lambda c: c == "Guyan", "k"),
              ("CB", lambda c: c.startswith("CB "), "tab:blue"),
              ("CB + residual vectors", lambda c: c.startswith("CB+RV "), "tab:red")]
    for name, pick, color in series:
        sel = [r for r in rows if pick(r["case"])]
        err = np.maximum([r["max_err"] for r in sel], 1e-16)
        est = np.maximum([r["max_est"] for r in sel], 1e-16)
        t = np.array([r["total_s"] for r in sel])
        counted = np.array([not r["case"].endswith("f_max=f20") for r in sel])
        ax.loglog(err[counted], t[counted], "o-", color=color, mfc="none", ms=7,
                  label=f"{name}: true max error")
        if not counted.all():
            ax.loglog(err[~counted], t[~counted], "s", color=color, mfc="none", ms=8,
                      label=f"{name}: f_max = f20 (true)")
        ax.loglog(est, t, "x", color=color, ms=7, label=f"{name}: estimated max error")
        for r, e, x, y in zip(sel, err, est, t, strict=True):
            ax.plot([e, x], [y, y], ":", color=color, lw=0.8)
            tag = r["case"].split(" ", 1)[-1] if r["case"] != "Guyan" else "Guyan"
            ax.annotate(tag, (e, y), textcoords="offset points", xytext=(5, 4), fontsize=7,
                        color=color)
    ax.axhline(full["solve_s"], color="grey", ls="--",
               label=f"full model, 20 modes ({full['solve_s']:.2f} s)")
    ax.set_xlabel("max relative error of f1..f20 vs the full model")
    ax.set_ylabel("reduction + reduced eigen solve, s")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=120)
    plt.close(fig)


def _write(path: Path, text: str):
    with atomic_path(path) as tmp:
        tmp.write_text(text)


# --- entry points ---------------------------------------------------------------------

def main(size: str = "large", columns: str = "box", repeat: int = 1, out_dir=RESULTS,
         echo=True) -> list[dict]:
    """Run the benchmark; return one dict per reduced case (keys as in the table).

    Each timed part runs ``repeat`` times and the fastest is reported (the full solve
    too). Writes ``reduction.txt`` and ``reduction.png`` to ``out_dir`` (if not None).
    """
    if size not in SIZES:
        raise ValueError(f"unknown size {size!r}; choose from {list(SIZES)}")
    load_start = os.getloadavg()
    model, interface = build(size, columns)
    log = (lambda msg: print(msg, file=sys.stderr, flush=True)) if echo else (lambda msg: None)
    log(f"... model {model.n_free:,} free DOFs, n_b = {6 * len(interface)}")
    full = min((full_case(model) for _ in range(repeat)), key=lambda row: row["solve_s"])
    log(f"... full solve {full['solve_s']:.1f} s")
    rows = [reduced_case(model, interface, full, "Guyan", repeat)]
    f_max = float(full["freq_hz"][-1])
    for name, rv in (("CB", False), ("CB+RV", True)):
        for n_q in SIZES[size][3]:
            rows.append(reduced_case(model, interface, full, f"{name} {n_q}", repeat,
                                     n_modes=n_q, residual_vectors=rv))
            log(f"... {name} {n_q}: {rows[-1]['total_s']:.1f} s")
        rows.append(reduced_case(model, interface, full, f"{name} f_max=f20", repeat,
                                 f_max_hz=f_max, residual_vectors=rv))
    text = "\n".join(format_report(model, interface, full, rows, size, columns,
                                     load_start))
    if echo:
        print(text)
    if out_dir is not None:
        out_dir = Path(out_dir)
        out_dir.mkdir(parents=True, exist_ok=True)
        _write(out_dir / "reduction.txt", text + "\n")
        plot(full, rows, out_dir / "reduction.png",
             f"{model.n_free:,} free DOFs, n_b = {rows[0]['n_b']}: time vs error"
             f" (labels: fixed-interface mode count)")
    return rows


def _cli(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--size", choices=list(SIZES), default="large")
    parser.add_argument("--columns", choices=list(COLUMNS), default="box")
    parser.add_argument("--repeat", type=int, default=3,
                        help="runs per timed case, the fastest is reported (default 3)")
    args = parser.parse_args(argv)
    main(args.size, args.columns, args.repeat)


if __name__ == "__main__":
    _cli()
