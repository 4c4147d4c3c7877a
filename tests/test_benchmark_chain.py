"""Smoke test of benchmarks/chain.py at tiny sizes (no timing assertions)."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

BENCHMARK = Path(__file__).resolve().parents[1] / "benchmarks" / "chain.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("bench_chain", BENCHMARK)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_chain_benchmark_runs_every_method(bench, tmp_path):
    out = tmp_path / "chain.txt"
    sizes = (4, 8, 16)
    rows = bench.main(sizes=sizes, repeats=1, n_modes=4, out_file=out, echo=False)
    names = set(bench.methods())
    for N in sizes:
        got = {r["method"]: r for r in rows if r["N"] == N}
        assert set(got) == names  # every method at every size; n = 2N <= DENSE_MAX
        for r in got.values():
            assert r["n"] == 2 * N  # follower unit: node rotation + follower
            assert r["reference"] == "dense eigh"
            assert r["min_s"] >= 0  # values not asserted: no timing in tests
            assert r["median_s"] >= r["min_s"]
        assert np.isnan(got["dense eigh"]["max_rel_error"])
        # bound: the exact methods solve the same frozen problem as LAPACK: round-off (measured
        # <= 2e-13 up to N = 100; bisection rtol 1e-12), so 1e-9 hides no wrong root
        for name in ("assembled ARPACK", "transfer", "transfer + vectors", "cyclic"):
            assert got[name]["max_rel_error"] < 1e-9, name
        # the continuum is a model: its long-wave error μ²/24 and the smeared ends
        # (measured 8e-4 … 1e-3 for these chains), not round-off
        # bound: lower end only: > 0 shows a model error, not round-off
        assert 1e-12 < got["continuum"]["max_rel_error"] < 1e-2
    p = bench.growth_exponents(rows)
    assert set(p) == names  # three sizes: every method gets a fitted exponent
    text = out.read_text()
    for heading in ("machine:", "versions:", "solvers:", "growth exponent", "transfer"):
        assert heading in text


def test_reference_falls_back_to_transfer_above_dense_max(bench, monkeypatch):
    # beyond DENSE_MAX the transfer result is the reference (no dense solve)
    monkeypatch.setattr(bench, "DENSE_MAX", 10)
    rows = bench.run(sizes=(8,), repeats=1, n_modes=3,
                     skip=lambda name, N: name in ("transfer + vectors", "continuum"))
    assert {r["method"] for r in rows} == {"assembled ARPACK", "transfer", "cyclic"}
    assert all(r["reference"] == "transfer" for r in rows)
    (arpack,) = [r for r in rows if r["method"] == "assembled ARPACK"]
    # bound: ARPACK (tol 0) against the same frozen pencil: eps λ_max/λ (roundoff.py)
    assert arpack["max_rel_error"] < 1e-9
