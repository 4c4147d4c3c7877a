"""Peer target 2: Craig-Bampton reduction against one full 20-mode eigensolve.

femmech: ``craig_bampton(model, 8 top joints (n_b = 48), n_modes=30)`` with residual
vectors (the default), i.e. one factorisation of K_ii serving the constraint modes, the
fixed-interface eigensolve (Sturm-checked) and the residual vectors, then the projection.
Peer: ``fm.modes(model, 20)`` on the same model (the cost a user compares a reduction with:
one full solve). Target: reduction ≤ 1.2 × full solve. Error column: the largest relative
error of the reduced model's f1..f20 against the full solve's.

Run: ``python benchmarks/peer_craig_bampton.py [--size tiny|small|medium] [--repeats 3]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import peers  # noqa: E402
from craig_bampton import interface_nodes, max_error, reduced_frequencies  # noqa: E402

import femmech as fm  # noqa: E402
import femmech.reduction as reduction  # noqa: E402
from femmech.solve import threads  # noqa: E402

N_FULL, N_MODES, TARGET = 20, 30, 1.2
CASES = {"tiny": ("1k",), "small": ("5k", "24k"), "medium": ("5k", "24k", "151k"),
         "large": ("5k", "24k", "151k")}


def case_row(case: str, repeats: int) -> dict:
    model = peers.frame(case)
    nodes = interface_nodes(model.mesh, "8 joints").tolist()
    t = peers.interleaved({
        "cb": lambda: reduction.craig_bampton(model, nodes, n_modes=N_MODES),
        "full": lambda: fm.modes(model, N_FULL)}, repeats, warmup=case != "151k")
    se, full = t["cb"].value, t["full"].value
    error = max_error(reduced_frequencies(se.K, se.M), full.freq_hz[:N_FULL], N_FULL)
    phases = ", ".join(f"{k} {v:.3f}" for k, v in se.timings.items())
    return dict(case=case, n=model.n_free, n_b=se.n_interface, n_r=se.n_reduced,
                n_res=se.n_residual, cb=t["cb"], full=t["full"], error=error,
                ratio=t["cb"].min / t["full"].min, phases=phases, solver=full.solver)


def main(size: str = "small", repeats: int = 3):
    before = peers.idle_baseline()
    rows = [case_row(case, repeats) for case in CASES[size]]
    after = peers.idle_baseline()
    text = peers.table(
        f"Target 2: Craig-Bampton (8 joints, n_b = 48, {N_MODES} modes + residual vectors)"
        f" vs one full {N_FULL}-mode eigensolve (femmech.modes); target <= {TARGET}",
        ["model", "free DOFs", "n_b", "n_r (res.)", "CB s min / median",
         "full s min / median", "CB / full", "max |df|/f (f1-f20)", "backend", "verdict"],
        [[r["case"], f"{r['n']:,}", str(r["n_b"]), f"{r['n_r']} ({r['n_res']})",
          r["cb"].cell(), r["full"].cell(), f"{r['ratio']:.2f}", f"{r['error']:.1e}",
          r["solver"], peers.verdict(r["ratio"], TARGET)] for r in rows])
    text += [f"{r['case']}: CB phases of the last run (s): {r['phases']}" for r in rows]
    text += [peers.baseline_line(before, after), threads.describe(), ""]
    out = [dict(case=r["case"], n=r["n"], cb_min=r["cb"].min, full_min=r["full"].min,
                ratio=r["ratio"], error=r["error"]) for r in rows]
    return text, out


if __name__ == "__main__":
    peers.cli(main, CASES, __doc__)
