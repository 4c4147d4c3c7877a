"""Peer target 7: femmech's Craig-Bampton against Exudyn's Hurty-Craig-Bampton.

The same reduction on both sides (benchmarks/exudyn_hcb.py explains how the two are made
equal): the grid frames' ``K_free``, ``M_free``, all six DOFs of 8 top joints (n_b = 48),
classical Craig-Bampton with 30 fixed-interface modes; Exudyn's
``ComputeHurtyCraigBamptonModes`` (allBoundaryNodes) plus the projection ``Vᵀ K V``,
``Vᵀ M V``. Times interleaved, min / median of ``repeats``. Target: Exudyn / femmech ≥ 10
at ~150k DOFs (a regression floor). Error: the largest relative difference of the lowest
20 frequencies of the two reduced models, and of femmech's against the full model.

Run: ``python benchmarks/peer_exudyn.py [--size tiny|small|medium] [--repeats 3]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import peers  # noqa: E402
from craig_bampton import (  # noqa: E402
    N_FULL,
    N_MODES,
    interface_nodes,
    max_error,
    reduced_frequencies,
)
from exudyn_hcb import exudyn_hcb, exudyn_version, femmech_cb  # noqa: E402

import femmech as fm  # noqa: E402
from femmech.solve import threads  # noqa: E402

TARGET = 10.0
CASES = {"tiny": ("1k",), "small": ("24k",), "medium": ("24k", "151k"),
         "large": ("24k", "151k")}


def case_row(case: str, repeats: int) -> dict:
    model = peers.frame(case)
    nodes = interface_nodes(model.mesh, "8 joints")
    n_q = femmech_cb(model, nodes, N_MODES)["n_q"]  # (a completed cluster may add modes)
    t = peers.interleaved({"femmech": lambda: femmech_cb(model, nodes, N_MODES),
                           "exudyn": lambda: exudyn_hcb(model, nodes, n_q)}, repeats)
    ours, theirs = t["femmech"].value, t["exudyn"].value
    f_ours = reduced_frequencies(ours["K"], ours["M"])
    f_theirs = reduced_frequencies(theirs["K"], theirs["M"])
    full = fm.modes(model, N_FULL).freq_hz[:N_FULL]
    return dict(case=case, n=model.n_free, n_r=f"{ours['n_b']}+{ours['n_q']}",
                femmech=t["femmech"], exudyn=t["exudyn"],
                ratio=t["exudyn"].min / t["femmech"].min,
                diff=max_error(f_theirs, f_ours, N_FULL), err=max_error(f_ours, full, N_FULL))


def main(size: str = "small", repeats: int = 3):
    version = exudyn_version()
    if version is None:
        return ["Target 7: exudyn not installed (pip install 'femmech[bench]'): skipped", ""], []
    before = peers.idle_baseline()
    rows = [case_row(case, repeats) for case in CASES[size]]
    after = peers.idle_baseline()
    text = peers.table(
        f"Target 7: femmech craig_bampton vs Exudyn {version} HCB (allBoundaryNodes) +"
        f" projection; same K, M, 8 joints (n_b = 48), {N_MODES} modes; target Exudyn /"
        f" femmech >= {TARGET:g} at ~150k DOFs",
        ["model", "free DOFs", "n_b+n_q", "femmech s min / median", "Exudyn s min / median",
         "Exudyn / femmech", "max |df|/f fm-exu", "fm vs full (f1-f20)", "verdict"],
        [[r["case"], f"{r['n']:,}", r["n_r"], r["femmech"].cell(), r["exudyn"].cell(),
          f"{r['ratio']:.1f}", f"{r['diff']:.1e}", f"{r['err']:.1e}",
          peers.verdict(r["ratio"], TARGET, at_most=False) if r["n"] > 100_000 else "(size)"]
         for r in rows])
    text += [peers.baseline_line(before, after), threads.describe(), ""]
    out = [dict(case=r["case"], n=r["n"], femmech_min=r["femmech"].min,
                exudyn_min=r["exudyn"].min, ratio=r["ratio"], diff=r["diff"]) for r in rows]
    return text, out


if __name__ == "__main__":
    peers.cli(main, CASES, __doc__)
