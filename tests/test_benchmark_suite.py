"""Smoke test of the components benchmark suite (benchmarks/run.py --suite components) at
size tiny: no timing assertions. The peer suite is tests/test_benchmarks_peers.py."""

import importlib.util
import math
import re
import sys
from pathlib import Path

import numpy as np
import pytest

SUITE = Path(__file__).resolve().parents[1] / "benchmarks" / "run.py"
HEADER = ("machine:", "cores", "GiB RAM", "load average", "versions: python", "numpy",
          "scipy", "scikit-fem", "femmech", "mkl", "PARDISO", "scikit-sparse", "exudyn",
          "solvers: installed", "femmech threads: solve=", "suite BLAS limit")


@pytest.fixture(scope="module")
def suite():
    spec = importlib.util.spec_from_file_location("benchmark_suite", SUITE)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclass needs the module registered
    spec.loader.exec_module(module)
    yield module
    sys.modules.pop(spec.name, None)


@pytest.fixture(scope="module")
def tiny(suite, tmp_path_factory):
    out = tmp_path_factory.mktemp("results")
    return suite.main("tiny", out_dir=out, echo=False, suite="components"), out


def _numbers(value):
    """Every int/float inside nested dicts, lists, tuples and arrays (None skipped)."""
    if isinstance(value, dict):
        for v in value.values():
            yield from _numbers(v)
    elif isinstance(value, (list, tuple)):
        for v in value:
            yield from _numbers(v)
    elif isinstance(value, np.ndarray) and value.dtype.kind in "biufc":
        yield from value.ravel().tolist()
    elif isinstance(value, (int, float, np.integer, np.floating)) \
            and not isinstance(value, bool):
        yield value


def test_every_entry_runs_and_writes_a_table_with_the_header(suite, tiny):
    results, out = tiny
    assert list(results) == list(suite.COMPONENTS)
    for name, result in results.items():
        assert result.error is None, f"{name}: {result.error}"
        text = (out / f"{name}.txt").read_text()
        assert text == result.text + "\n"
        assert text.startswith(f"benchmark: {name} (suite size tiny)")
        head = text.split("\n\n", 1)[0]  # the header ends at the first empty line
        for item in HEADER:
            assert item in head, f"{name}: header lacks {item!r}"
        # no table cell or row value is NaN or infinite
        assert not re.search(r"\b(nan|inf)\b", text, re.IGNORECASE), name
        values = list(_numbers(result.rows))
        assert all(math.isfinite(v) for v in values), name
        if name != "exudyn_hcb" or suite.exudyn_hcb.exudyn_version():
            assert result.rows, f"{name}: no rows"
            assert values, f"{name}: no numbers"


def test_rows_describe_the_models_and_agree_where_they_must(suite, tiny):
    results, _ = tiny
    modes = [r for r in results["assembly"].rows if r["table"] == "modes"]
    # grid_frame((2, 2, 2), subdivisions=2) with the base joints clamped (frame_modes.py)
    assert [(r["case"], r["free_dofs"]) for r in modes] == [("tiny", 432)]
    assert all(r["build_over_eigen"] > 0 for r in modes)
    solver_rows = results["eigensolve"].rows
    from femmech.solve import direct
    assert sorted(r["solver"] for r in solver_rows) == sorted(direct.available())
    # bound: same pencil, every backend: ARPACK to round-off (measured <= 1e-13); 1e-10 margin
    assert all(r["max_freq_diff"] < 1e-10 for r in solver_rows)
    cb = results["craig_bampton"].rows
    assert {(r["interface"], r["variant"]) for r in cb} == {
        (i, v) for i in ("8 joints", "rails") for v in ("CB", "CB+RV")}
    for r in cb:
        assert r["n_b"] == (48 if r["interface"] == "8 joints" else 270)  # 8 / 45 nodes x 6
        # Rayleigh-Ritz: reduced frequencies are upper bounds; residual vectors only add
        # to the basis (measured: CB 8.0e-2, CB+RV 2.9e-4 on f1..f20 for 8 joints)
        assert 0 <= r["err10"] <= r["err20"]
    by = {(r["interface"], r["variant"]): r for r in cb}
    for i in ("8 joints", "rails"):
        assert by[(i, "CB+RV")]["err20"] <= by[(i, "CB")]["err20"]
    sweep = results["reduced_sweep"].rows
    assert all(r["n_reduced"] <= 100 for r in sweep)  # the suite's target r <= 100
    assert sorted({r["n_angles"] for r in sweep}) == [36, 360]
    (coupled,) = results["coupled"].rows
    # reduced vs full coupled textile shaft, 6 lowest modes: the Craig-Bampton + residual
    # vector basis below 2 x 400 Hz reproduces them far within the 0.1 % band
    # accuracy (measured 1.2e-13 on this 4-cam model)
    assert coupled["max_rel_error"] < 1e-3
    assert len(coupled["per_angle"]["phi"]) == 2
    # bound: the ARPACK reference at one angle: an independent eigensolver on the same
    # full coupled pencil agrees with femmech's full solve to round-off (measured 1e-13)
    (arpack,) = coupled["arpack"]
    assert arpack["max_rel_diff"] < 1e-9
    assert arpack["arpack_solves"] >= coupled["n_modes"]
    assert "scipy eigsh (ARPACK" in results["coupled"].text
    # bases of the speed-against-error table, each inside the one before (fewer residual
    # vectors, then fewer fixed-interface modes): Ritz values of nested subspaces can only
    # rise (Courant-Fischer), so the errors may not fall, up to round-off (measured on
    # this 4-cam model: 1.2e-13, 1.1e-11, and 9.4 with no fixed-interface mode at all)
    variants = coupled["variants"]
    assert len(variants) == len(suite.REDUCTION_VARIANTS)
    sizes = [v["n_reduced"] for v in variants]
    assert sizes == sorted(sizes, reverse=True)
    assert sizes[0] == coupled["n_reduced"]
    errors = [v["max_rel_error"] for v in variants]
    assert errors[0] < 1e-3
    assert all(v["tracked_ms"] > 0 for v in variants)
    # bound: Rayleigh-Ritz nesting: errors grow, allowance for eps λ_max/λ round-off
    assert all(b >= a - 1e-12 for a, b in zip(errors, errors[1:], strict=False))


def test_exudyn_entry_matches_femmech_or_says_it_is_missing(suite, tiny):
    result = tiny[0]["exudyn_hcb"]
    if suite.exudyn_hcb.exudyn_version() is None:
        assert "exudyn: not installed" in result.text
        assert result.rows == []
        return
    assert [r["threads"] for r in result.rows] == ["default", "1 thread"]
    for r in result.rows:
        # the same interface and number of fixed-interface modes on both sides
        assert (r["n_b"], r["n_q"]) == (r["exudyn_n_b"], r["exudyn_n_q"]) == (48, r["n_q"])
        # both are the classical Craig-Bampton space of the same K, M: the bases agree to
        # round-off (measured sine 2.6e-14, frequencies 3e-14); 1e-8 leaves a wide margin
        assert r["subspace_sine"] < 1e-8
        assert r["diff"] < 1e-8
        assert r["femmech_err20"] == pytest.approx(r["exudyn_err20"], rel=1e-6)


def test_exudyn_entry_reports_a_missing_package(suite, monkeypatch, tmp_path):
    monkeypatch.setattr(suite.exudyn_hcb, "exudyn_version", lambda: None)
    results = suite.main("tiny", only=["exudyn_hcb"], out_dir=tmp_path, echo=False)
    text = (tmp_path / "exudyn_hcb.txt").read_text()
    assert "exudyn: not installed (pip install exudyn" in text
    assert results["exudyn_hcb"].rows == []
    assert results["exudyn_hcb"].error is None


def test_bad_arguments_are_named(suite, tmp_path):
    with pytest.raises(ValueError, match="unknown size 'huge'"):
        suite.main("huge", out_dir=None, echo=False)
    with pytest.raises(ValueError, match="unknown benchmarks"):
        suite.main("tiny", only=["nope"], out_dir=None, echo=False)
    # basis variants are judged against the full solves: without checked angles, say so
    with pytest.raises(ValueError, match="variants need n_check > 0"):
        suite.coupled_sweep.main(n_cams=4, n_angles=12, n_check=0, per_spacing=2,
                                 variants=((400.0, True),))


def test_old_suite_names_still_run_with_a_deprecation_message(suite, monkeypatch, tmp_path,
                                                              capsys):
    monkeypatch.setattr(suite.exudyn_hcb, "exudyn_version", lambda: None)  # a fast entry
    assert set(suite.SUITES) == {"peers", "components"}
    for old, new in (("issue10", "components"), ("issue24", "peers")):
        assert suite.SUITE_ALIASES[old] == new
        with pytest.warns(DeprecationWarning, match=f"'{old}' is deprecated; use '{new}'"):
            results = suite.main("tiny", only=["exudyn_hcb"], out_dir=None, echo=False,
                                 suite=old)
        assert list(results) == ["exudyn_hcb"]
    code = suite._cli(["--suite", "issue10", "--size", "tiny", "--only", "exudyn_hcb",
                       "--out", str(tmp_path)])
    assert code == 0
    assert "--suite issue10 is deprecated; use --suite components" in capsys.readouterr().err
    with pytest.raises(ValueError, match="unknown suite 'nonexistent'"):
        suite.main("tiny", out_dir=None, echo=False, suite="nonexistent")
