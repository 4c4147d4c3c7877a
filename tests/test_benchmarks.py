"""Smoke test of benchmarks/frame_modes.py at a tiny size (no timing assertions)."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

BENCHMARK = Path(__file__).resolve().parents[1] / "benchmarks" / "frame_modes.py"


@pytest.fixture(scope="module")
def frame_modes():
    spec = importlib.util.spec_from_file_location("frame_modes", BENCHMARK)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_frame_modes_benchmark_runs_and_reports_sane_rows(frame_modes, tmp_path):
    out = tmp_path / "frame_modes.txt"
    rows = frame_modes.main(sizes=("tiny",), out_file=out, echo=False)
    (modal,) = [r for r in rows if r["table"] == "modes"]
    (assembly,) = [r for r in rows if r["table"] == "assembly"]
    # grid_frame((2, 2, 2), subdivisions=2): 27 joints + 54 mid-member nodes = 81 nodes,
    # 108 elements; the 9 base joints are fixed (6 DOFs each)
    assert (modal["dofs"], modal["free_dofs"], modal["elements"]) == (486, 432, 108)
    assert modal["method"] == "arpack"  # 432 free DOFs > DENSE_BELOW: the timed sparse path
    # phase times and memory are reported as non-negative numbers (values not asserted:
    # no timing in tests)
    for key in ("element_s", "coo_csr_s", "tkt_s", "build_s", "factor_s", "arpack_s",
                "sturm_s", "eigen_s"):
        assert modal[key] >= 0
    assert modal["build_peak_mb"] >= 0
    assert modal["eigen_peak_mb"] >= 0
    # >= 20 modes (a repeated 20th eigenvalue brings its whole cluster), all confirmed by
    # the Sturm count; supported frame: no rigid-body modes
    assert modal["n_modes"] >= 20
    assert modal["sturm_count"] == modal["n_modes"]
    assert modal["n_rigid"] == 0
    f = np.array(modal["f123_hz"])
    assert f.shape == (3,)
    assert np.all(f > 0)
    assert np.all(np.diff(f) >= 0)
    # residual and errors against dense LAPACK and scipy's eigsh: both solve the same
    # pencil to round-off (ARPACK tol=0 means machine precision; observed ~1e-12 for this
    # 432-DOF system), so 1e-8 leaves a wide margin without hiding a wrong mode
    assert modal["max_residual"] < 1e-8
    refs = modal["references"]
    assert [r["ref_s"] is not None for r in refs] == [True, True]
    assert all(r["max_rel_err"] < 1e-8 for r in refs)
    # bound: the loop and vectorised assemblies give the same matrices up to summation order
    assert assembly["elements"] == 108
    assert assembly["speedup"] > 0
    assert assembly["max_diff"] < 1e-12
    text = out.read_text()
    for heading in ("Build", "Modes", "Reference", "Assembly", "BLAS threads"):
        assert heading in text
