"""Smoke test of benchmarks/plate_shells.py at tiny sizes (no timing assertions)."""

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

BENCHMARK = Path(__file__).resolve().parents[1] / "benchmarks" / "plate_shells.py"


@pytest.fixture(scope="module")
def plate_shells():
    spec = importlib.util.spec_from_file_location("plate_shells", BENCHMARK)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclass resolves annotations through it
    spec.loader.exec_module(module)
    yield module
    sys.modules.pop(spec.name, None)


def test_plate_benchmark_runs_and_reports_sane_rows(plate_shells, tmp_path):
    out = tmp_path / "plate_shells.txt"
    everything = plate_shells.main("tiny", out_file=out, echo=False)
    labels = [kind.label for kind in plate_shells.ELEMENTS]
    assert {r["element"] for r in everything} == set(labels)  # a row group per kind
    rows = [r for r in everything if r["element"] in ("MITC4", "MITC9")]
    assert [r["element"] for r in rows] == ["MITC4", "MITC4", "MITC9", "MITC9"]
    # n x n MITC4 and n/2 x n/2 MITC9 have the same nodes: (n + 1)² x 6 DOFs
    assert [r["dofs"] for r in rows] == [294, 486, 294, 486]
    for r in rows:
        assert len(r["errors"]) == plate_shells.N_FREQ
        assert r["max_err"] == pytest.approx(np.abs(r["errors"]).max())
        assert r["seconds"] >= 0
    # finer is better, and at equal DOFs MITC9 beats MITC4 (measured at 486 DOFs: max
    # error 9.9 % vs 38 %; first frequency 0.07 % vs 1.7 %)
    by = {(r["element"], r["n"]): r for r in rows}
    assert by["MITC4", 8]["max_err"] < by["MITC4", 6]["max_err"]
    assert by["MITC9", 4]["max_err"] < by["MITC9", 3]["max_err"]
    assert by["MITC9", 4]["max_err"] < 0.5 * by["MITC4", 8]["max_err"]
    text = out.read_text()
    for heading in ("Simply supported square plate", "DOFs for max |err|", "MITC9"):
        assert heading in text


def test_reference_is_leissa_closed_form_for_thin_plates(plate_shells):
    # ω_mn = π² (m² + n²) sqrt(D/ρt) for a unit square (Leissa, NASA SP-160, 1969); the
    # Mindlin values lie below by ~(m² + n²) t²: 3.1e-5 for mode 10 at a/t = 1000
    lam = plate_shells.mindlin_frequency_parameters(1e-3)
    kirchhoff = np.sort([np.pi**2 * (m**2 + n**2) for m in range(1, 5) for n in range(1, 5)])
    np.testing.assert_allclose(lam, kirchhoff[:10], rtol=4e-5)
    assert np.all(lam < kirchhoff[:10])


def test_dofs_for_target_interpolates_and_extrapolates(plate_shells):
    rows = [{"dofs": 100, "max_err": 1e-1}, {"dofs": 400, "max_err": 1e-2},
            {"dofs": 1600, "max_err": 1e-4}]
    smallest, estimate, how = plate_shells.dofs_for(rows, 1e-3)
    # between 400 (1e-2) and 1600 (1e-4): slope -10/3 in log-log, 1e-3 at 400 * 4^0.5
    assert (smallest, how) == (1600, "interpolated")
    assert estimate == pytest.approx(800.0)
    smallest, estimate, how = plate_shells.dofs_for(rows[:2], 1e-3)
    # beyond 400 on the line through (100, 1e-1), (400, 1e-2): slope -1/log10(4)
    assert (smallest, how) == (None, "extrapolated")
    assert estimate == pytest.approx(1600.0)
