"""Smoke test of benchmarks/scale.py at its tiny size (no timing assertions)."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

BENCHMARK = Path(__file__).resolve().parents[1] / "benchmarks" / "scale.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("bench_scale", BENCHMARK)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_machine_bed_mesh_has_the_documented_groups(bench):
    mesh, groups = bench.machine_bed(2)
    # n = 2: 40 x 8 x 6 quads over length, width, height -> 28 nodes per ring, 41 rings
    assert len(mesh.cells["quad"]) == 40 * 28
    assert mesh.n_nodes == 28 * 41 + 4  # + the four bearing centres
    assert len(groups["seats"]) == len(groups["brackets"]) == 4
    for centre, patch in groups["seats"]:
        assert patch.size >= 1
        assert mesh.points[centre, 2] == pytest.approx(bench.HEIGHT + bench.SEAT_HEIGHT)
        # bound: generated coordinates: exact to ~eps of O(1) values
        assert np.all(np.abs(mesh.points[patch, 2] - bench.HEIGHT) < 1e-12)  # top plate
    with pytest.raises(ValueError, match="positive integer"):
        bench.machine_bed(0)


def test_scale_benchmark_runs_every_phase(bench, tmp_path):
    out = tmp_path / "scale.txt"
    row = bench.main("tiny", n_angles=12, n_check=1, out_file=out, echo=False)
    # n = 1: 294 plate nodes + 4 bearing centres, 6 DOFs each
    assert (row["dofs"], row["interface_dofs"]) == (1788, 28)
    # 30 fixed-interface modes + one residual vector per interface DOF (none dropped)
    assert row["reduced"] == 28 + 30 + row["residual_vectors"]
    assert row["coupled"] == row["reduced"] + 4  # one follower coordinate q per cam
    for phase in ("mesh", "build", "reduce", "couple", "sweep", "check"):
        assert row[f"{phase}_s"] >= 0  # values not asserted: no timing in tests
        assert row[f"{phase}_peak_mb"] >= 0
    assert set(row["reduce_split"]) == {"factorisation", "constraint_modes",
                                        "fixed_interface_modes", "projection"}
    # reduced vs full coupled at one angle, 10 branches: Craig-Bampton (30 modes +
    # residual vectors) truncation error, measured 3.8e-6
    assert row["max_rel_error"] < 1e-4
    assert row["min_mac"] > 0.999
    text = out.read_text()
    for heading in ("Phases", "Craig-Bampton split", "sweep:", "reduced vs full coupled"):
        assert heading in text
    with pytest.raises(ValueError, match="unknown size"):
        bench.run("huge")
