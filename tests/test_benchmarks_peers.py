"""Smoke test of the peer suite (benchmarks/run.py) at size tiny, one repeat.

No timing assertions: the tables must run, carry the header, and their error columns must
show that femmech and the peer solved the same problem.
"""

import importlib.util
import math
import sys
from pathlib import Path

import pytest

SUITE = Path(__file__).resolve().parents[1] / "benchmarks" / "run.py"


@pytest.fixture(scope="module")
def suite():
    spec = importlib.util.spec_from_file_location("benchmark_suite_peers", SUITE)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclass needs the module registered
    spec.loader.exec_module(module)
    yield module
    sys.modules.pop(spec.name, None)


@pytest.fixture(scope="module")
def tiny(suite, tmp_path_factory):
    out = tmp_path_factory.mktemp("peers")
    return suite.main("tiny", out_dir=out, echo=False, repeats=1), out


def test_every_target_runs_and_prints_its_table(suite, tiny):
    results, out = tiny
    assert list(results) == list(suite.PEER_TARGETS)
    for name, result in results.items():
        assert result.error is None, f"{name}: {result.error}"
        text = (out / f"{name}.txt").read_text()
        assert text.startswith(f"benchmark: {name} (suite size tiny)")
        if "not installed" in text:
            continue
        assert "Target " in text, name
        # timed comparisons carry the idle baseline; the memory entry is absolute
        assert "idle baseline" in text or name == "t6_memory", name
        for row in result.rows:
            for key, value in row.items():
                if isinstance(value, float):
                    assert math.isfinite(value), f"{name}: {key} = {value}"


def test_eigensolve_peers_solve_the_same_pencil(tiny):
    (row,) = tiny[0]["t1_eigensolve"].rows
    assert row["n"] == 1080
    assert row["ratio"] > 0
    # bound: femmech (Lanczos to 1e-12 Ritz residuals) and ARPACK (tol 0) on the same pencil agree
    # to round-off: measured 1.6e-12 .. 5.8e-12 over the backends
    assert row["max_diff"] < 1e-9
    assert row["residual"] < 1e-6  # femmech's own residual check (measured 1e-10)


def test_craig_bampton_row_is_a_reduction_of_the_same_model(tiny):
    (row,) = tiny[0]["t2_craig_bampton"].rows
    # Rayleigh-Ritz upper bounds; with 30 modes + residual vectors the tiny frame's f1..f20
    # are within 10 % (measured 2.2e-5 at 5k, 8e-2 on the 1k frame whose 20th mode is
    # above the fixed-interface cutoff)
    assert 0 <= row["error"] < 0.2


def test_exudyn_row_is_the_same_reduction(suite, tiny):
    result = tiny[0]["t7_exudyn"]
    if not result.rows:
        assert "not installed" in result.text
        return
    (row,) = result.rows
    # the same classical Craig-Bampton space: frequencies agree to round-off (7e-13)
    assert row["diff"] < 1e-8


def test_interface_reduction_keeps_the_band(tiny):
    for row in tiny[0]["t3_interface"].rows:
        # coupled band frequencies against the whole interface: target 1e-3 (measured
        # 2e-5 .. 6e-5 on the 24k/151k frames), and the estimate within a factor 3
        assert row["err"] <= 1e-3
        # bound: slack for a zero error: round-off of the estimate
        assert row["est"] <= 3 * row["err"] + 1e-12


def test_sweep_rows_agree_with_lapack(tiny):
    for row in tiny[0]["t4_sweep"].rows:
        # bound: tracked frequencies against the bare all-pairs solve of the same pencils:
        # round-off (measured 5e-13 .. 1.4e-12)
        assert row["error"] < 1e-9


def test_monodromy_sides_reach_the_same_accuracy(tiny):
    for row in tiny[0]["t5_monodromy"].rows:
        # the peer's tolerance is chosen so that its spectral-radius error is at most
        # femmech's; both against the same tight reference
        # bound: slack for equal errors: round-off, ~10 eps
        assert row["peer_err"] <= row["femmech_err"] + 1e-15
        assert row["femmech_err"] < 1e-3


def test_end_to_end_is_certified(tiny):
    (row,) = tiny[0]["t6_end_to_end"].rows
    # the estimate over all angles and the true error at the checked angles are far
    # below the 0.1 % target (measured 4e-11 on the tiny shaft)
    assert row["estimated_error"] < 1e-3
    assert row["true_error"] < 1e-3
    (memory,) = tiny[0]["t6_memory"].rows
    assert 0 < memory["maxrss_gb"] < 8
