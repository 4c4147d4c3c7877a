"""Smoke test of benchmarks/solvers.py at a tiny size (no timing assertions)."""

import importlib.util
from pathlib import Path

import pytest

from femmech.solve import direct

BENCHMARK = Path(__file__).resolve().parents[1] / "benchmarks" / "solvers.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("bench_solvers", BENCHMARK)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_solver_benchmark_runs_every_installed_backend(bench, tmp_path):
    out = tmp_path / "solvers.txt"
    rows = bench.main(sizes=("tiny",), out_file=out, echo=False)
    names = [r["solver"] for r in rows]
    assert names[0] == "superlu"  # the reference of the agreement column
    assert sorted(names) == sorted(direct.available())
    for r in rows:
        # grid_frame((2, 2, 2), subdivisions=4), base joints clamped: 1 080 free DOFs
        assert (r["case"], r["free_dofs"], r["solver"]) == ("tiny", 1080, r["solver"])
        for key in ("analyse_s", "factorise_s", "solves_s", "unit_s", "factor_s",
                    "arpack_s", "sturm_s", "eigen_s", "eigen_nocheck_s", "peak_mb"):
            assert r[key] >= 0  # values not asserted: no timing in tests
        assert r["ratio"] > 0
        assert r["ratio_nocheck"] > 0
        # block Lanczos solved at least one vector per mode
        assert r["vectors_solved"] >= bench.N_MODES
        assert r["solves"] >= 1
        # >= 20 modes, all confirmed by the Sturm count of this backend's inertia
        assert r["n_modes"] >= bench.N_MODES
        assert r["sturm_count"] == r["n_modes"]
        assert r["max_residual"] < 1e-8
        # bound: every backend solves the same pencil: ARPACK converges to round-off (measured
        # 1e-13), so 1e-10 leaves a margin without hiding a wrong mode
        assert r["max_freq_diff"] < 1e-10
        # the side-by-side ARPACK reference (scipy eigsh on the same factor): an independent
        # bound: eigensolver agrees with femmech's to round-off (measured 4e-13 on this frame)
        assert r["arpack_solves"] >= bench.N_MODES
        assert r["ratio_arpack"] > 0
        assert r["arpack_max_diff"] < 1e-10
    text = out.read_text()
    for heading in ("Full 20-mode eigen solve", "reference algorithm: scipy eigsh",
                    "femmech threads", "solvers: superlu", "auto picks"):
        assert heading in text
    with pytest.raises(ValueError, match="unknown sizes"):
        bench.main(sizes=("huge",), out_file=None, echo=False)
