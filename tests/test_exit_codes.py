"""Every row of the README's exit-code table, produced by the ``femmech`` command: one
scenario per documented code, run through :func:`femmech.cli.main` (and one through a
real process), with the one-line error and its normalised paths."""

from __future__ import annotations

import dataclasses
import errno
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scene_texts import frame_scene

from femmech.cli import EXIT_CODES, main
from femmech.scene.registry import KINDS

ROOT = Path(__file__).resolve().parent.parent
ROW = re.compile(r"^\| (\d+) \| (.+) \|$", re.M)

FRAME = frame_scene(mesh_line="MESH")
GENERATOR = ('generator = { kind = "grid_frame", bays = [1, 1, 1], size = [1.0, 0.6, 0.8],'
             ' subdivisions = 1 }')


def table(path: Path) -> dict[int, str]:
    """The exit-code table of a Markdown file: code → meaning."""
    section = path.read_text(encoding="utf-8").split("xit codes", 1)[1]
    return {int(code): text for code, text in ROW.findall(section)}


def frame_scene(folder: Path, mesh: str = GENERATOR) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "frame.toml"
    path.write_text(FRAME.replace("MESH", mesh))
    return path


def error_line(capsys) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err  # one line, no traceback
    return err.strip()


def failing_modes(exc: BaseException):
    def task(ws, spec, folder):
        raise exc
    return task


def run_args(tmp_path) -> list[str]:
    return ["run", str(frame_scene(tmp_path)), "--out", str(tmp_path / "out"), "--no-cache"]


# --- one scenario per documented code --------------------------------------------------

def exits_0(tmp_path, monkeypatch, capsys):
    code = main(["check", str(frame_scene(tmp_path))])
    assert "frame.toml: OK" in capsys.readouterr().out
    return code


def exits_1(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(KINDS, "modes",
                        dataclasses.replace(KINDS["modes"], run=failing_modes(KeyError("missing"))))
    code = main(run_args(tmp_path))
    assert error_line(capsys).startswith("internal error: KeyError")
    return code


def exits_2(tmp_path, monkeypatch, capsys):
    with pytest.raises(SystemExit) as info:  # argparse: --out is required
        main(["run", str(frame_scene(tmp_path))])
    assert "--out" in capsys.readouterr().err
    return info.value.code


def exits_3(tmp_path, monkeypatch, capsys):
    # a missing mesh file is an input error (the path the scene gives is wrong); the path
    # shown is normalised: no "examples/../meshes"
    scene = frame_scene(tmp_path / "examples", 'mesh = "../meshes/nowhere.msh"')
    code = main(["run", str(scene), "--out", str(tmp_path / "out"), "--no-cache"])
    line = error_line(capsys)
    missing = (tmp_path / "meshes" / "nowhere.msh").resolve()
    assert line == f"error: frame.toml: [parts.frame] mesh: file not found: '{missing}'"
    assert not (tmp_path / "out").exists()
    return code


def exits_4(tmp_path, monkeypatch, capsys):
    failure = np.linalg.LinAlgError("Singular matrix")
    monkeypatch.setitem(KINDS, "modes",
                        dataclasses.replace(KINDS["modes"], run=failing_modes(failure)))
    code = main(run_args(tmp_path))
    assert error_line(capsys).startswith("numerical failure: frame.toml: [analyses.modes]")
    return code


def exits_5(tmp_path, monkeypatch, capsys):
    # permission denied while writing the report (the tests may run as root, for whom
    # chmod does not refuse anything: the error is raised where the report is written)
    def refused(*args, **kwargs):
        raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), "report.html")

    monkeypatch.setattr("femmech.scene.run.write_report", refused)
    code = main(run_args(tmp_path))
    line = error_line(capsys)
    assert line.startswith("error: frame.toml: cannot read or write a file:")
    assert "Permission denied" in line
    assert not (tmp_path / "out").exists()
    return code


def exits_130(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(KINDS, "modes",
                        dataclasses.replace(KINDS["modes"], run=failing_modes(KeyboardInterrupt())))
    code = main(run_args(tmp_path))
    assert error_line(capsys) == "interrupted"
    return code


SCENARIOS = {0: exits_0, 1: exits_1, 2: exits_2, 3: exits_3, 4: exits_4, 5: exits_5,
             130: exits_130}


def test_readme_table_is_the_cli_table_and_the_scene_docs_table():
    readme = table(ROOT / "README.md")
    assert set(readme) == set(EXIT_CODES) == set(SCENARIOS)
    assert readme == table(ROOT / "docs" / "scenes.md")


@pytest.mark.parametrize("code", sorted(table(ROOT / "README.md")))
def test_each_documented_exit_code(code, tmp_path, monkeypatch, capsys):
    assert SCENARIOS[code](tmp_path, monkeypatch, capsys) == code


def test_missing_scene_file_is_an_input_error_with_a_normalised_path(tmp_path, capsys):
    (tmp_path / "examples").mkdir()
    given = tmp_path / "examples" / ".." / "nowhere.toml"
    assert main(["check", str(given)]) == 3
    assert error_line(capsys) == (f"error: nowhere.toml: scene file not found:"
                                  f" {(tmp_path / 'nowhere.toml').resolve()}")


def test_missing_mesh_file_exit_code_of_the_process(tmp_path):
    # what the installed script returns, not only main()
    scene = frame_scene(tmp_path / "examples", 'mesh = "../meshes/nowhere.msh"')
    done = subprocess.run([sys.executable, "-m", "femmech", "check", str(scene)], cwd=ROOT,
                          capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 3, done.stderr
    assert "/../" not in done.stderr
    assert done.stderr.count("\n") == 1


def test_missing_scene_module_path_is_normalised(tmp_path, capsys):
    scene = tmp_path / "examples" / "machine.toml"
    scene.parent.mkdir()
    scene.write_text('[scene]\nname = "m"\n\n[mechanisms.cam]\nmodule = "../code/nowhere.py"\n'
                     'function = "build"\n')
    assert main(["check", str(scene)]) == 3
    missing = (tmp_path / "code" / "nowhere.py").resolve()
    assert error_line(capsys) == (f"error: machine.toml: [mechanisms.cam] module: file not"
                                  f" found: {missing}")
