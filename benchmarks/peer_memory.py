"""Peer target 6 (second half): peak memory of reducing a ~1M-DOF shell frame.

A closed steel box of 6 mm MITC4 shells (4.0 x 0.8 x 0.6 m, ``box(..., nx, ny, nz)``,
clamped at x = 0), reduced by ``craig_bampton`` onto all six DOFs of four top-plate nodes
with 30 fixed-interface modes and residual vectors. Each size runs in a child process of
its own, so that its peak resident memory (``ru_maxrss``) is that of this job alone; a
sampling thread (every 20 ms, ``VmRSS``) records the peak within each phase (build, K_ii
factorisation, constraint modes, Lanczos, Sturm check, residual vectors, projection).
Target: the 1M-DOF reduction within 8 GB peak. No peer: the number is absolute.

Run: ``python benchmarks/peer_memory.py [--size tiny|small|medium]`` (medium: 1 008 150
free DOFs, ~4-9 min and ~7 GB).
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import threading
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import peers  # noqa: E402

TARGET_GB = 8.0
BOXES = {"tiny": (20, 4, 3), "small": (120, 24, 18), "medium": (480, 96, 72),
         "large": (480, 96, 72)}


def _rss_mb() -> float:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS"):
                return int(line.split()[1]) / 1024
    return 0.0


def child(nx: int, ny: int, nz: int) -> dict:
    """Build and reduce the box in this process; phase peaks (MB), times (s)."""
    import numpy as np

    import femmech as fm
    import femmech.reduction.component_modes as cm
    import femmech.solve.eigen as eigen
    from femmech.fe.generators import box

    label, peaks = ["start"], {}

    def sample():
        while True:
            peaks[label[0]] = max(peaks.get(label[0], 0.0), _rss_mb())
            time.sleep(0.02)
    threading.Thread(target=sample, daemon=True).start()

    def phase(module, name, tag):
        original = getattr(module, name)

        def wrapped(*args, **kwargs):
            before, label[0] = label[0], tag
            try:
                return original(*args, **kwargs)
            finally:
                label[0] = before
        setattr(module, name, wrapped)
    for module, name, tag in [(cm, "factorize_interior", "K_ii factorisation"),
                              (eigen, "lowest_pairs", "Lanczos (fixed-interface modes)"),
                              (eigen, "inertia_below", "Sturm check"),
                              (cm, "residual_modes", "residual vectors"),
                              (cm, "_project", "projection")]:
        phase(module, name, tag)
    steel = fm.Material(E=210e9, nu=0.3, rho=7850.0)
    label[0] = "build_model"
    start = time.perf_counter()
    mesh = box(4.0, 0.8, 0.6, nx, ny, nz)
    shell = fm.ShellProperty(0.006, steel)
    model = fm.build_model(mesh, shells={"walls": shell, "ends": shell},
                           supports=[fm.Support("end_x0")])
    build_s = time.perf_counter() - start
    top = mesh.node_sets["top"]
    p = mesh.points[top]
    nodes = [int(top[np.argmin(np.hypot(p[:, 0] - x, p[:, 1] - 0.4))])
             for x in (1.0, 2.0, 3.0, 3.9)]
    label[0] = "other reduction steps"
    start = time.perf_counter()
    se = cm.craig_bampton(model, nodes, n_modes=30, residual_vectors=True)
    reduce_s = time.perf_counter() - start
    label[0] = "done"
    time.sleep(0.05)
    return dict(free=model.n_free, n_r=se.n_reduced, build_s=build_s, reduce_s=reduce_s,
                peaks=peaks, maxrss_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
                / 1024, kept_factor=se.interior_factor is not None)


def main(size: str = "small", repeats: int = 1):
    """One child run per size (memory peaks do not need repeats; ``repeats`` is ignored)."""
    nx, ny, nz = BOXES[size]
    out = subprocess.run([sys.executable, __file__, "--child", str(nx), str(ny), str(nz)],
                         capture_output=True, text=True, check=False)
    if out.returncode != 0:
        raise RuntimeError(f"child run failed: {out.stderr[-2000:]}")
    row = json.loads(out.stdout.strip().splitlines()[-1])
    gb = row["maxrss_mb"] / 1024
    text = peers.table(
        f"Target 6b: peak memory of a Craig-Bampton reduction of a MITC4 shell box"
        f" ({nx} x {ny} x {nz} elements, 4 interface nodes, 30 modes + residual vectors);"
        f" target <= {TARGET_GB:g} GB at ~1M DOFs",
        ["phase", "peak resident MB"],
        [[name, f"{mb:,.0f}"] for name, mb in row["peaks"].items()])
    text += [f"{row['free']:,} free DOFs, reduced to {row['n_r']}: build {row['build_s']:.1f}"
             f" s, reduction {row['reduce_s']:.1f} s; process peak (ru_maxrss) {gb:.2f} GB ->"
             + (f" {peers.verdict(gb, TARGET_GB)}" if row["free"] > 500_000 else " (size)")
             + f"; K_ii factor kept in the superelement: {row['kept_factor']}", ""]
    return text, [dict(size=size, free=row["free"], maxrss_gb=gb, reduce_s=row["reduce_s"])]


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        print(json.dumps(child(*(int(a) for a in sys.argv[2:5]))))
        sys.exit(0)
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--size", choices=tuple(BOXES), default="small")
    args = parser.parse_args()
    print("\n".join(main(args.size)[0]))
