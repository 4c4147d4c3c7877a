"""The ``femmech`` command: ``run`` and ``check``, exit codes and one-line errors."""

import subprocess
import sys
from pathlib import Path

import pytest
from scene_texts import CRAIG_BAMPTON, frame_scene

from femmech.cli import main

ROOT = Path(__file__).resolve().parent.parent

SCENE = frame_scene("cli test", subdivisions=2, parts_extra=CRAIG_BAMPTON, n_modes=4)


@pytest.fixture
def scene(tmp_path) -> Path:
    path = tmp_path / "frame.toml"
    path.write_text(SCENE)
    return path


@pytest.fixture
def bad_scene(tmp_path) -> Path:
    path = tmp_path / "bad.toml"
    path.write_text(SCENE.replace('nodes = "base"', 'nodes = "base"\nfixed = true'))
    return path


def test_check_valid_scene(scene, capsys):
    assert main(["check", str(scene)]) == 0
    out = capsys.readouterr().out
    assert out.startswith("frame.toml: OK: parts frame (")
    assert "analyses ['modes']" in out


def test_check_bad_scene_exit_3_with_one_line(bad_scene, capsys):
    assert main(["check", str(bad_scene)]) == 3
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err.startswith("error: bad.toml: [parts.frame.supports[0]] fixed: unknown key;"
                          " expected one of ['dofs', 'nodes']")


def test_check_missing_scene(tmp_path, capsys):
    assert main(["check", str(tmp_path / "nowhere.toml")]) == 3
    assert "nowhere.toml: scene file not found" in capsys.readouterr().err


def test_run_bad_scene_exit_3(bad_scene, tmp_path, capsys):
    assert main(["run", str(bad_scene), "--out", str(tmp_path / "out"), "--no-cache"]) == 3
    assert "unknown key" in capsys.readouterr().err
    assert not (tmp_path / "out" / "report.html").exists()


def test_usage_errors_exit_2(capsys):
    with pytest.raises(SystemExit) as info:
        main([])
    assert info.value.code == 2
    with pytest.raises(SystemExit) as info:
        main(["run", "scene.toml"])  # --out is required
    assert info.value.code == 2


def test_run_writes_report_and_reuses_cache(scene, tmp_path, capsys):
    cache = tmp_path / "cache"
    args = ["run", str(scene), "--cache-dir", str(cache)]
    assert main([*args, "--out", str(tmp_path / "a")]) == 0
    out = capsys.readouterr().out
    assert "cache miss: part 'frame'" in out
    assert main([*args, "--out", str(tmp_path / "b"), "--quiet"]) == 0
    assert capsys.readouterr().out.strip() == str(tmp_path / "b" / "report.html")
    assert "cache hit: part 'frame'" in (tmp_path / "b" / "run.log").read_text()
    for name in ("report.html", "results.json", "frequencies.csv"):
        assert (tmp_path / "b" / name).is_file()
    assert main(["run", str(scene), "--out", str(tmp_path / "c"), "--no-cache", "-q"]) == 0
    assert "cache off: part 'frame'" in (tmp_path / "c" / "run.log").read_text()
    assert not list((tmp_path / "c").glob("*.npz"))


def test_module_entry_point_exit_codes(scene, bad_scene):
    # what the installed `femmech` script runs ([project.scripts] femmech = femmech.cli:main)
    ok = subprocess.run([sys.executable, "-m", "femmech", "check", str(scene)], cwd=ROOT,
                        capture_output=True, text=True, timeout=120, check=False)
    assert ok.returncode == 0, ok.stderr
    bad = subprocess.run([sys.executable, "-m", "femmech", "check", str(bad_scene)], cwd=ROOT,
                         capture_output=True, text=True, timeout=120, check=False)
    assert bad.returncode == 3
    assert bad.stderr.count("\n") == 1
    assert bad.stderr.startswith("error: bad.toml: ")


def test_cache_info_and_clear(scene, tmp_path, capsys):
    cache = tmp_path / "cache"
    assert main(["run", str(scene), "--out", str(tmp_path / "a"), "--cache-dir", str(cache),
                 "-q"]) == 0
    (cache / "notes.txt").write_text("not femmech's")
    capsys.readouterr()
    assert main(["cache", "info", "--cache-dir", str(cache)]) == 0
    info = capsys.readouterr().out
    assert f"reduction cache {cache}" in info
    assert "1 entry," in info
    assert "1 other files" in info
    assert main(["cache", "clear", "--cache-dir", str(cache)]) == 0
    assert "removed" in capsys.readouterr().out
    assert [p.name for p in cache.iterdir()] == ["notes.txt"]


def test_version(capsys):
    import femmech

    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out.strip() == f"femmech {femmech.__version__}"


def test_verbosity_through_logging(scene, tmp_path, capsys):
    # library code logs (logger 'femmech'); the command line shows INFO, -q only warnings
    # and the report's path, -v also the DEBUG lines (timings)
    args = ["run", str(scene), "--no-cache"]
    assert main([*args, "--out", str(tmp_path / "a")]) == 0
    normal = capsys.readouterr().out
    assert "cache off: part 'frame'" in normal
    assert "timings (s):" not in normal
    assert main([*args, "--out", str(tmp_path / "b"), "-v"]) == 0
    assert "timings (s): prepare" in capsys.readouterr().out
    assert main([*args, "--out", str(tmp_path / "c"), "-q"]) == 0
    assert capsys.readouterr().out.strip() == str(tmp_path / "c" / "report.html")
    import logging

    assert not logging.getLogger("femmech").handlers  # nothing left behind


CHECK_IMPORTS = """
import sys
from femmech.cli import main
code = main(["check", sys.argv[1]])
print(code, *sorted(m for m in sys.modules if m.split(".")[0] in {"pyvista", "vtk",
      "vtkmodules", "matplotlib"} or m in {"femmech.output.plot", "femmech.output.renderer",
      "femmech.analysis.modes", "femmech.analysis.stability", "femmech.chain.synthesis",
      "scipy.optimize", "scipy.interpolate"}))
"""
"""Runs ``femmech check`` and prints its exit code and the unwanted modules it imported."""


@pytest.mark.parametrize("name", ["press_frame.toml", "frame_modes.toml"])
def test_check_imports_no_rendering_and_no_solver(name):
    """``femmech check`` validates a scene without the rendering stack (pyvista, vtk,
    matplotlib), the modules that draw or solve (mode and stability analyses, the chain
    optimiser) and scipy's optimiser: a fresh interpreter has none of them afterwards.
    Structural, not timed (benchmarks/check_time.py times it)."""
    done = subprocess.run([sys.executable, "-c", CHECK_IMPORTS, str(ROOT / "examples" / name)],
                          cwd=ROOT, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1] == "0", done.stdout
