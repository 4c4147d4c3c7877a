"""Peer target 3: Craig-Bampton with a reduced interface for rails (~1 000 interface DOFs).

Target: the reduction (``femmech.reduction.reduce_interface``) costs <= 3x one full
20-mode eigensolve (``femmech.modes(model, 20)``) of the same model, and the coupled
quasi-eigenfrequencies in the band stay within 0.1 % of the unreduced-interface model
(plain Craig-Bampton with residual vectors, ``craig_bampton``, the target's 4.7-14x).

Models: the grid frames of benchmarks/peers.py (``frame``): ``tiny`` 1k (1 080 free DOFs;
rails = all 45 top nodes, n_b = 270), ``small`` 24k (23 760; n_b = 1 002) and ``medium``
151k (151 200; n_b = 1 002). Rails: the interface of benchmarks/craig_bampton.py (the
first 167 top-face nodes, whole lines of top members, all six DOFs). Band: f <= f_max with
f_max the 10th or the 20th frequency of the full solve; fixed-interface modes up to
2 f_max (``f_max_hz``). Machine: four 200 kg spring-masses (0.6 f_max on a rigid base)
hung on rail nodes 3, 40, 90 and 150 (uz), declared as ``attachments``.

Columns: reduction s and full 20-mode solve s (min / median of ``repeats`` runs,
interleaved), their ratio of minima, the plain Craig-Bampton reduction (one run: it is
the slow reference), the largest relative error of the coupled frequencies in the band
against the plain model, the reduction's own a-posteriori estimate of that error
(``interface_error_estimates`` with ``attachment_loads``; max over the band) and the
estimate / true error of the worst mode.

Usage: ``python benchmarks/peer_interface.py [--size tiny|small|medium] [--repeats 3]``.
"""

from __future__ import annotations

import gc
import sys
import time
from pathlib import Path

import numpy as np
import scipy.linalg as sla
import sympy

import femmech as fm
from femmech.coupling import Attachment, Mount, couple
from femmech.mechanisms import rheolinear
from femmech.mechanisms.symbolic import Mechanism, PointMass, Spring
from femmech.reduction import craig_bampton
from femmech.reduction.interface_modes import (
    attachment_loads,
    interface_error_estimates,
    reduce_interface,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from craig_bampton import interface_nodes  # noqa: E402  (sibling benchmarks)
from peers import (  # noqa: E402
    baseline_line,
    cli,
    frame,
    idle_baseline,
    interleaved,
    table,
    verdict,
)

SIZES = {"tiny": "1k", "small": "24k", "medium": "151k", "large": "151k"}
RATIO_TARGET = 3.0
ERROR_TARGET = 1e-3
MOUNT_NODES = (3, 40, 90, 150)  # positions along the rails (tiny: modulo the 45 nodes)
MASS = 200.0  # kg per spring-mass
BANDS = (10, 20)  # f_max = the full model's 10th / 20th frequency


def _rails(model, name):
    if name == "1k":
        z = model.mesh.points[:, 2]
        return np.flatnonzero(np.isclose(z, z.max()))
    return interface_nodes(model.mesh, "rails")


def _mounts(nodes, f_max):
    theta, yg, q = sympy.symbols("theta y_g q")
    k = MASS * (2 * np.pi * 0.6 * f_max) ** 2
    mech = rheolinear(Mechanism((yg, q, theta), (PointMass(MASS, (yg + q,)), Spring(k, q)),
                                drives=(theta,)), {}, {})
    return [Mount(mech, (Attachment("y_g", int(n), "uz"),), name=f"m{i}")
            for i, n in enumerate(nodes)]


def _coupled(frame_se, mounts, n):
    system = couple(frame_se, mounts)
    M, _, C, _ = system.matrices(0.0)
    w, X = sla.eigh(C, M, subset_by_index=[0, n - 1])
    return np.sqrt(np.clip(w, 0.0, None)) / (2 * np.pi), w, X, system


def band_row(model, name, rails, full, n_band, repeats) -> dict:
    """One row: times, errors and estimate for the band f <= f_{n_band} of the full model."""
    f_max = float(full.value.freq_hz[n_band - 1])
    picks = rails[np.array(MOUNT_NODES) % rails.size]
    reduce = lambda: reduce_interface(model, rails.tolist(), f_max_hz=f_max,  # noqa: E731
                                      attachments=picks.tolist())
    times = interleaved({"full": lambda: fm.modes(model, 20), "cc": reduce}, repeats)
    cc = times["cc"].value
    gc.collect()
    start = time.perf_counter()
    se = craig_bampton(model, rails.tolist(), f_max_hz=f_max)
    plain_s = time.perf_counter() - start
    mounts = _mounts(picks, f_max)
    n = min(3 * n_band + 10, cc.n_reduced)
    ref = _coupled(se, mounts, n)[0]
    del se
    f, w, X, system = _coupled(cc, mounts, n)
    band = ref <= f_max
    err = (f[band] - ref[band]) / ref[band]
    loads = attachment_loads(cc, system, 0.0, w, X)
    est = interface_error_estimates(model, cc, w, X[:system.n_frame], loads)[band]
    worst = int(np.argmax(np.abs(err)))
    ratio = times["cc"].min / times["full"].min
    ok = ratio <= RATIO_TARGET and np.abs(err).max() <= ERROR_TARGET
    return dict(model=name, n_free=model.n_free, n_b=cc.n_interface, n_c=cc.n_boundary,
                n_r=cc.n_reduced, f_max=f_max, n_band=int(band.sum()),
                cc=times["cc"], full=times["full"], ratio=ratio, plain_s=plain_s,
                plain_ratio=plain_s / times["full"].min, err=float(np.abs(err).max()),
                est=float(est.max()), est_ratio=float(est[worst] / err[worst])
                if err[worst] else float("nan"), timings=dict(cc.timings),
                verdict="met" if ok else "MISSED")


def main(size: str = "small", repeats: int = 3):
    """Run the target-3 table for ``size`` (tiny / small / medium); (lines, rows)."""
    if size not in SIZES:
        raise ValueError(f"unknown size {size!r}; choose from {list(SIZES)}")
    name = SIZES[size]
    before = idle_baseline()
    model = frame(name)
    rails = _rails(model, name)
    full = interleaved({"full": lambda: fm.modes(model, 20)}, 1)["full"]
    rows = [band_row(model, name, rails, full, n, repeats) for n in BANDS]
    after = idle_baseline()
    cells = [[r["model"], f"{r['n_free']:,}", str(r["n_b"]), str(r["n_c"]),
              f"{r['f_max']:.0f} ({r['n_band']})", r["cc"].cell(), r["full"].cell(),
              f"{r['ratio']:.2f}", f"{r['plain_s']:.2f} ({r['plain_ratio']:.1f}x)",
              f"{r['err']:.1e}", f"{r['est']:.1e}", f"{r['est_ratio']:.2f}",
              verdict(r["ratio"], RATIO_TARGET) if r["err"] <= ERROR_TARGET else "MISSED"]
             for r in rows]
    lines = table(
        "Target 3: reduced-interface Craig-Bampton (reduce_interface) vs one full 20-mode"
        f" solve (femmech.modes), rails interface, {repeats} interleaved repeats",
        ["model", "free DOFs", "n_b", "n_c", "f_max Hz (modes)", "reduce s min/med",
         "full s min/med", "ratio", "plain CB s", "max err", "estimate", "est/true",
         "verdict"], cells)
    lines += [f"targets: ratio <= {RATIO_TARGET}, coupled error <= {ERROR_TARGET:.0e} vs plain"
              " Craig-Bampton + residual vectors on the whole interface (plain CB: one run);",
              "phases of the last reduction (s): " + "; ".join(
                  f"{r['f_max']:.0f} Hz: " + ", ".join(f"{k} {v:.2f}" for k, v in
                                                       r["timings"].items()) for r in rows),
              baseline_line(before, after), ""]
    return lines, rows


if __name__ == "__main__":
    cli(main, SIZES, __doc__)
