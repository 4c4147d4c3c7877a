"""Smoke test of benchmarks/reduction.py at the tiny size (no timing assertions)."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

BENCHMARK = Path(__file__).resolve().parents[1] / "benchmarks" / "reduction.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("reduction_benchmark", BENCHMARK)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_reduction_benchmark_runs_and_reports_sane_rows(bench, tmp_path):
    rows = bench.main("tiny", out_dir=tmp_path, echo=False)
    by_case = {r["case"]: r for r in rows}
    plain = ["Guyan", "CB 5", "CB 10", "CB 20", "CB f_max=f20"]
    augmented = ["CB+RV 5", "CB+RV 10", "CB+RV 20", "CB+RV f_max=f20"]
    assert list(by_case) == plain + augmented
    # interface: the 3 + 3 top joints on the long edges of grid_frame((2, 1, 1)), 6 DOFs each
    for r in rows:
        assert r["n_b"] == 36
        assert r["n_r"] == r["n_b"] + r["n_q"] + r["n_res"]
    assert by_case["Guyan"]["n_q"] == 0
    # residual vectors: at most one per interface DOF, none in the classical basis
    assert all(by_case[c]["n_res"] == 0 for c in plain)
    assert all(0 < by_case[c]["n_res"] <= 36 for c in augmented)
    # a requested count may grow to complete a cluster of equal fixed-interface frequencies
    for n in (5, 10, 20):
        assert by_case[f"CB {n}"]["n_q"] >= n
    for r in rows:
        assert min(r["reduce_s"], r["solve_s"], r["estimate_s"]) >= 0
        # the library's phases are part of the reduction time (1 ms clock slack)
        assert sum(r["timings"].values()) <= r["reduce_s"] + 1e-3
        # Rayleigh-Ritz: reduced frequencies are upper bounds of the full ones (the 1e-8
        # slack covers the eigen solvers' round-off, ~1e-12 relative)
        assert r["min_err"] >= -1e-8
        assert 0 <= r["median_err"] <= r["max_err"]
        assert r["max_est"] > 0
        assert np.all(np.isfinite(r["ratio"]))
        # bound: MAC <= 1 up to round-off of normalised products: ~n eps
        assert 0 <= r["min_mac"] <= 1 + 1e-9
    # nested bases (Guyan ⊂ CB 5 ⊂ CB 10 ⊂ CB 20 ⊂ CB f_max, the lowest fixed-interface
    # modes first; CB n ⊂ CB+RV n, which adds vectors): by Rayleigh-Ritz no eigenvalue, hence
    # no largest error, can increase (slack: eigen solver round-off)
    def not_worse(a, b):
        # bound: slack for the reduced and full solves' round-off eps λ_max/λ (roundoff.py)
        return by_case[b]["max_err"] <= by_case[a]["max_err"] * (1 + 1e-6) + 1e-10

    assert all(not_worse(a, b) for a, b in zip(plain, plain[1:], strict=False))
    assert all(not_worse(a, b) for a, b in zip(augmented, augmented[1:], strict=False))
    assert all(not_worse(f"CB {c[6:]}", c) for c in augmented)
    text = (tmp_path / "reduction.txt").read_text()
    for item in ("Guyan", "CB f_max", "CB+RV", "full", "est/true", "MAC", "n_b = 36", "CPUs",
                 "Per mode"):
        assert item in text
    assert (tmp_path / "reduction.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
