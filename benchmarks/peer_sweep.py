"""Peer target 4: the reduced coupled sweep per angle against bare LAPACK solves.

femmech: ``sweep(system, phi, n_modes, keep_vectors=True)`` over 360 angles, tracked (MAC
assignment with cluster subspaces), vectors kept: the lean batched path of
:mod:`femmech.analysis.sweep`. Its time includes evaluating the mechanisms at all angles.
Before: the general per-angle path of the same module (``_sweep_loop``, the path every sweep
once took), same results. Peer: ``scipy.linalg.eigh(C, M)`` of the same pencils
(the sweep's C(φ) and M(φ), assembled beforehand and not timed), one call per angle, under
the same thread limits, ``check_finite=False``, with the drivers that return all pairs
(``gv``, ``gvd``) or the ``n_modes`` lowest (``gvx``); the fastest driver is the peer.
Target: femmech ≤ 1.3 × peer. The LAPACK floor column times the sweep's own LAPACK calls
for its q candidates alone (the lower bound of any sweep that solves them so). Error
column: the largest relative difference of a tracked
frequency from the nearest frequency of the peer (``gvd``, all pairs) at its angle.

Systems: the textile shaft of examples/textile_shaft.py (shaft, pedestals and base beam,
Craig-Bampton without residual vectors, cams mounted on the shaft's rx and the base's uz):
5 cams for r = 20, 10 cams for r = 38 … 100, the number of fixed-interface modes setting r.

Run: ``python benchmarks/peer_sweep.py [--size tiny|small|medium] [--repeats 3]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import scipy.linalg as sla

sys.path.insert(0, str(Path(__file__).resolve().parent))

import peers  # noqa: E402
from coupled_sweep import _example  # noqa: E402

from femmech.analysis import sweep as sweep_module  # noqa: E402
from femmech.analysis import tracking  # noqa: E402
from femmech.coupling import assemble_stack, couple  # noqa: E402
from femmech.reduction.component_modes import craig_bampton  # noqa: E402
from femmech.solve import dense, threads  # noqa: E402

TARGET, N_MODES = 1.3, 6
# size: (reduced sizes r, angles)
CASES = {"tiny": ((20, 38), 24), "small": ((20, 38, 60, 76, 100), 360),
         "medium": ((20, 38, 60, 76, 100), 360),
         "large": ((20, 38, 60, 76, 100), 360)}
DRIVERS = ("gv", "gvd", "gvx")


def shaft_system(r: int):
    """The coupled textile shaft with ``r`` reduced coordinates (5 cams below r = 38)."""
    ex = _example()
    n_cams = 5 if r < 38 else 10
    model, cams, guides = ex.frame_and_shaft(n_cams, 2)
    interface = [(cams, ["rx"]), (guides, ["uz"])]
    sizes = {}
    for n_fixed in r - 3 * n_cams + np.array([0, -1, 1, -2, 2]):  # 3 n_cams + modes, but
        se = craig_bampton(model, interface, n_modes=int(n_fixed),  # repeated modes come
                           residual_vectors=False)                  # in whole
        system = couple(se, ex.mounts(cams, guides))
        if system.n == r:
            return system
        sizes[int(n_fixed)] = system.n
    raise ValueError(f"could not build a coupled shaft with r = {r}: modes -> sizes {sizes}")


def bare(M, C, driver: str, n_modes: int):
    """Frequencies (Hz, (n_angles, n) or the ``n_modes`` lowest with ``gvx``) of each pencil
    by one ``eigh`` call per angle."""
    subset = {"subset_by_index": [0, n_modes - 1]} if driver == "gvx" else {}
    with threads.solve_phase():
        lam = np.array([sla.eigh(c, m, driver=driver, check_finite=False, **subset)[0]
                        for c, m in zip(C, M, strict=True)])
    return np.sqrt(np.abs(lam)) / (2 * np.pi)


def candidates(M, C, n_modes: int) -> int:
    """Candidates q the sweep solves for at the first angle: n_modes + max(2, n_modes // 2),
    doubled while the last one lies in the cluster of the n_modes-th (tracking compares
    whole clusters)."""
    n = M.shape[-1]
    extra = min(n_modes + max(2, n_modes // 2), n - 1)
    while extra < n - 1:
        f = sweep_module._lean_solve(M[:1], C[:1], extra)[2]
        if tracking.splits(f)[:, n_modes - 1:].any():
            break
        extra = min(2 * extra, n - 1)
    return extra


def lapack_floor(M, C, q: int):
    """The LAPACK calls of the sweep alone (``sygvd``, or ``sygvx`` below 1/7 of the pairs)
    for q candidates of each pencil, with the shift-inverted inputs formed beforehand."""
    n = M.shape[-1]
    sigma = -1e-6 * np.median(np.diagonal(C, axis1=1, axis2=2)
                              / np.diagonal(M, axis1=1, axis2=2), axis=1)
    Mf = np.ascontiguousarray(M.transpose(0, 2, 1))
    Af = np.ascontiguousarray((C - sigma[:, None, None] * M).transpose(0, 2, 1))
    solve = (dense.sygvd_largest if q >= dense.ALL_PAIRS_FRACTION * n
             else dense.sygvx_largest)

    def run():
        Mc, Ac = Mf.copy(), Af.copy()
        with threads.solve_phase():
            for i in range(len(Mc)):
                solve(Mc[i].T, Ac[i].T, q)

    return run


def general_path(system, phi, n_modes: int):
    """The general per-angle path with the lean path's arguments."""
    extra = min(n_modes + max(2, n_modes // 2), system.n - 1)
    with threads.solve_phase():
        matrices = sweep_module._angle_matrices(system, phi, 0.0, 0.0, False)
        return sweep_module._sweep_loop(matrices, system.n, system.H, phi, n_modes, extra,
                                        False, True, True, 0.1)


def case_row(r: int, n_angles: int, repeats: int, n_modes: int = N_MODES) -> dict:
    system = shaft_system(r)
    phi = np.linspace(0.0, 2 * np.pi, n_angles, endpoint=False)
    M, _, C, _ = assemble_stack(system, system.mechanism_blocks(phi))
    C = 0.5 * (C + C.transpose(0, 2, 1))  # the sweep's symmetric part (C is symmetric at Ω = 0)
    sides = {"femmech": lambda: sweep_module.sweep(system, phi, n_modes=n_modes,
                                                   keep_vectors=True),
             "before": lambda: general_path(system, phi, n_modes)}
    sides.update({d: (lambda d=d: bare(M, C, d, n_modes)) for d in DRIVERS})
    q = candidates(M, C, n_modes)
    sides["floor"] = lapack_floor(M, C, q)
    t = peers.interleaved(sides, repeats, warmup=True)
    peer = min(DRIVERS, key=lambda d: t[d].min)
    f_fm, f_all = t["femmech"].value.freq_hz, t["gvd"].value
    # each tracked branch against the nearest of all the peer's frequencies at its angle
    # (tracked branches are not always the n_modes lowest: a branch keeps its identity)
    error = np.abs(f_fm[:, :, None] / f_all[:, None, :] - 1.0).min(axis=2).max()
    return dict(r=r, n_modes=n_modes, t=t, peer=peer, ratio=t["femmech"].min / t[peer].min, q=q,
                ratio_gvd=t["femmech"].min / t["gvd"].min,
                speedup=t["before"].min / t["femmech"].min, n_angles=n_angles,
                error=float(error),
                same=bool(np.array_equal(f_fm, t["before"].value.freq_hz)))


def main(size: str = "small", repeats: int = 3):
    rs, n_angles = CASES[size]
    before = peers.idle_baseline()
    rows = [case_row(r, n_angles, repeats) for r in rs]
    after = peers.idle_baseline()
    ms = 1e3 / n_angles
    text = peers.table(
        f"Target 4: reduced coupled sweep ({n_angles} angles, tracked, vectors kept) vs bare"
        f" LAPACK eigh(C, M) of the same pencils, ms per angle; target <= {TARGET}",
        ["r", "modes tracked", "femmech min / median", "before min / median",
         "peer min / median", "peer", "femmech / peer", "max |df|/f", "verdict",
         "femmech / sygvd", "verdict (sygvd)", "q", "LAPACK floor", "floor / peer"],
        [[str(x["r"]), str(x["n_modes"]), x["t"]["femmech"].cell(ms), x["t"]["before"].cell(ms),
          x["t"][x["peer"]].cell(ms), x["peer"], f"{x['ratio']:.2f}", f"{x['error']:.1e}",
          peers.verdict(x["ratio"], TARGET), f"{x['ratio_gvd']:.2f}",
          peers.verdict(x["ratio_gvd"], TARGET), str(x["q"]), x["t"]["floor"].cell(ms),
          f"{x['t']['floor'].min / x['t'][x['peer']].min:.2f}"] for x in rows])
    text += ["peer: the fastest bare driver (gvx computes only the n_modes lowest pairs);"
             " sygvd (gvd, all pairs) is the named per-angle reference",
             "q: candidates the sweep solves for per angle (the n_modes-th branch's cluster"
             " whole); LAPACK floor: the sweep's LAPACK calls for them alone (sygvd, or"
             " sygvx below 1/7 of the pairs), inputs formed beforehand."]
    text += [f"r = {x['r']}: bare drivers min ms/angle "
             + ", ".join(f"{d} {x['t'][d].min * ms:.3f}" for d in DRIVERS)
             + f"; before/femmech {x['speedup']:.2f}x; frequencies equal to before:"
             f" {x['same']}" for x in rows]
    text += [peers.baseline_line(before, after), threads.describe(), ""]
    out = [dict(r=x["r"], n_modes=x["n_modes"], femmech_ms=x["t"]["femmech"].min * ms,
                before_ms=x["t"]["before"].min * ms, peer=x["peer"],
                peer_ms=x["t"][x["peer"]].min * ms, ratio=x["ratio"], error=x["error"],
                ratio_sygvd=x["ratio_gvd"])
           for x in rows]
    return text, out


if __name__ == "__main__":
    peers.cli(main, CASES, __doc__)
