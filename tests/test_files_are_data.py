"""Scene files are data, runs are clean: scene code only with opt-in and from the scene's
folder, one consistent output folder per run, documented exit codes with one-line errors."""

from __future__ import annotations

import dataclasses
import errno
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scene_texts import frame_scene

from femmech.cli import FILESYSTEM, INPUT, INTERNAL, NUMERICAL, main
from femmech.errors import InputError, UserCodeError
from femmech.output.folder import MANIFEST
from femmech.scene.build import prepare
from femmech.scene.load import load_scene
from femmech.scene.registry import KINDS
from femmech.scene.run import run_scene

ROOT = Path(__file__).resolve().parent.parent

FRAME = frame_scene(subdivisions=1, n_modes="N_MODES", images="IMAGES")

# the processing machine of the chapter through a user module (the built-in made by user code)
MECHANISM = """
[scene]
name = "user mechanism"

[mechanisms.machine]
module = "MODULE"
function = "build"
options = { kinematic_drive = true }

[mechanisms.machine.parameters]
J0 = 0.5
J1 = 2e-3
J2 = 2e-3
m1 = 3
m2 = 2
cT1 = 2e4
cT2 = 2e4
c3 = 1e6
c4 = 6e5
c6 = 5e3
c7 = 5e3
bT1 = 0.2
bT2 = 0.2
b3 = 70
b4 = 70
F1 = 0
F2 = 0

[mechanisms.machine.position_functions.U1]
kind = "chapter_cam"
name = "U1"

[mechanisms.machine.position_functions.U2]
kind = "chapter_cam"
name = "U2"

[analyses.sweep]
mechanism = "machine"
angles = { start = "0 deg", stop = "360 deg", n = 7 }
"""

MODULE = """
from pathlib import Path

Path(__file__).with_name("ran.txt").write_text("imported")  # proves the code ran

def build(**options):
    from femmech.mechanisms import processing_machine
    return processing_machine(**options)
"""


def frame_scene(folder: Path, n_modes: int = 3, images: int = 0, name="frame.toml") -> Path:
    path = folder / name
    path.write_text(FRAME.replace("N_MODES", str(n_modes)).replace("IMAGES", str(images)))
    return path


def code_scene(folder: Path, module_text: str = MODULE, module: str = "mech.py") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    if module_text is not None:
        (folder / Path(module).name).write_text(module_text)
    path = folder / "mech.toml"
    path.write_text(MECHANISM.replace("MODULE", module))
    return path


def one_line(text: str) -> str:
    assert text.count("\n") == 1, text
    return text.strip()


# --- scene code only with opt-in ----------------------------------------------------------

def test_scene_code_is_refused_without_opt_in(tmp_path):
    path = code_scene(tmp_path)
    with pytest.raises(UserCodeError, match=r"mech.toml: \[mechanisms.machine\] module: "
                       r"mech.py is Python code.*--allow-code"):
        prepare(load_scene(path))
    with pytest.raises(UserCodeError):
        run_scene(path, tmp_path / "out", cache_dir=None)
    assert not (tmp_path / "ran.txt").exists()
    assert not (tmp_path / "out").exists()


def test_check_never_runs_scene_code(tmp_path, capsys):
    path = code_scene(tmp_path)
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "[mechanisms.machine] module mech.py: user code, not executed" in out
    assert not (tmp_path / "ran.txt").exists()


def test_cli_run_needs_allow_code(tmp_path, capsys):
    path = code_scene(tmp_path)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-cache"]) == INPUT
    assert "--allow-code" in one_line(capsys.readouterr().err)
    assert not (tmp_path / "ran.txt").exists()
    assert not out.exists()
    assert main(["run", str(path), "--out", str(out), "--no-cache", "--allow-code", "-q"]) == 0
    assert (tmp_path / "ran.txt").exists()
    assert (out / "report.html").is_file()
    assert (out / "quasi_frequencies.csv").is_file()


@pytest.mark.parametrize("where", ["parent", "absolute", "symlink"])
def test_module_outside_the_scene_folder_is_refused_even_with_opt_in(tmp_path, where):
    scene_dir = tmp_path / "shared" / "scene"
    outside = tmp_path / "shared" / "evil.py"
    outside.parent.mkdir(parents=True)
    outside.write_text(MODULE)
    if where == "symlink":  # a link inside the folder that leads out
        scene_dir.mkdir()
        (scene_dir / "mech.py").symlink_to(outside)
        path = code_scene(scene_dir, None, "mech.py")
    else:
        module = "../evil.py" if where == "parent" else str(outside)
        path = code_scene(scene_dir, None, module)
    with pytest.raises(UserCodeError, match="lies outside the scene's folder"):
        prepare(load_scene(path), allow_code=True)
    with pytest.raises(UserCodeError, match="lies outside the scene's folder"):
        prepare(load_scene(path), run_code=False)  # check refuses the path too
    assert not (tmp_path / "shared" / "ran.txt").exists()
    # a root the user names explicitly admits it
    prepared = prepare(load_scene(path), allow_code=True, code_root=tmp_path / "shared")
    assert "machine" in prepared.mechanisms
    assert (tmp_path / "shared" / "ran.txt").exists()


def test_module_must_be_a_python_file(tmp_path):
    path = code_scene(tmp_path, MODULE, "mech.txt")
    with pytest.raises(UserCodeError, match=r"module: expected a Python file \(\.py\)"):
        prepare(load_scene(path), allow_code=True)


@pytest.mark.parametrize(("body", "expected"), [
    ("import sys\nsys.exit(0)\n", r"module: the user code called sys.exit\(0\) in mech.py"),
    ("def build(**o):\n    raise SystemExit('bye')\n", r"sys.exit\('bye'\)"),
    ("def build(**o):\n    return 1 / 0\n", r"function: the user code raised ZeroDivisionError"),
    ("x = 1\n", r"function: mech.py has no function 'build'"),
    ("def build(**o):\n    return 42\n", r"expected a Mechanism or RheolinearModel, got int"),
])
def test_failing_scene_code_gives_one_line_and_exit_3(tmp_path, capsys, body, expected):
    path = code_scene(tmp_path, body)
    with pytest.raises(InputError, match=expected):
        prepare(load_scene(path), allow_code=True)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--allow-code", "--no-cache"]) == INPUT
    assert one_line(capsys.readouterr().err).startswith("error: mech.toml: [mechanisms.machine]")
    assert not out.exists()


def test_exiting_module_in_a_subprocess_exits_3(tmp_path):
    # sys.exit(0) inside user code used to end femmech with exit 0 and no report
    path = code_scene(tmp_path, "import sys\nsys.exit(0)\n")
    run = subprocess.run([sys.executable, "-m", "femmech", "run", str(path), "--out",
                          str(tmp_path / "out"), "--allow-code", "--no-cache"], cwd=ROOT,
                         capture_output=True, text=True, timeout=300, check=False)
    assert run.returncode == INPUT, run.stderr
    assert "sys.exit(0)" in one_line(run.stderr)


def test_shipped_textile_scene_needs_the_opt_in():
    path = ROOT / "examples" / "textile_shaft.toml"
    assert "--allow-code" in path.read_text()  # its header says how to run it
    with pytest.raises(UserCodeError):
        prepare(load_scene(path))
    prepared = prepare(load_scene(path), run_code=False)
    assert prepared.unexecuted == ("cam",)


# --- one run, one output folder -----------------------------------------------------------

def _files(folder: Path) -> set[str]:
    return {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()}


def _tree(folder: Path, skip: tuple[Path, ...]) -> dict[str, int]:
    """Every file under ``folder`` outside ``skip`` with its size and mtime."""
    out = {}
    for p in folder.rglob("*"):
        if p.is_file() and not any(p.is_relative_to(s) for s in skip):
            st = p.stat()
            out[p.relative_to(folder).as_posix()] = (st.st_size, st.st_mtime_ns)
    return out


def test_two_runs_into_one_folder_leave_the_second_set(tmp_path):
    out = tmp_path / "out"
    first = run_scene(frame_scene(tmp_path, images=2), out, cache_dir=None)
    assert {"mode_01.png", "mode_02.png", MANIFEST} <= _files(out)
    (out / "my_notes.txt").write_text("kept")  # the user's own file
    second = run_scene(frame_scene(tmp_path, images=0, name="b.toml"), out, cache_dir=None)
    files = _files(out)
    assert "mode_01.png" not in files  # nothing of the first run is left
    assert (out / "my_notes.txt").read_text() == "kept"
    import json
    listed = set(json.loads((out / MANIFEST).read_text())["files"])
    assert files == listed | {MANIFEST, "my_notes.txt"}
    assert second.report == out / "report.html"
    assert first.out_dir == second.out_dir
    assert "scene b.toml" in (out / "report.html").read_text()
    assert not [p for p in tmp_path.iterdir() if ".femmech-" in p.name]


def test_failed_run_leaves_the_previous_run_intact(tmp_path, monkeypatch):
    out = tmp_path / "out"
    run_scene(frame_scene(tmp_path), out, cache_dir=None)
    before = _tree(out, ())

    def broken(ws, spec, folder):
        (folder / "frequencies.csv").write_text("half")
        raise RuntimeError("eigensolver broke")

    monkeypatch.setitem(KINDS, "modes", dataclasses.replace(KINDS["modes"], run=broken))
    with pytest.raises(RuntimeError, match=r"\[analyses.modes\]: the computation failed"):
        run_scene(frame_scene(tmp_path), out, cache_dir=None)
    assert _tree(out, ()) == before
    assert not [p for p in tmp_path.iterdir() if ".femmech-" in p.name]


def test_missing_out_folder_is_created_with_parents(tmp_path):
    out = tmp_path / "a" / "b" / "c"
    result = run_scene(frame_scene(tmp_path), out, cache_dir=None)
    assert result.report.is_file()


def test_foreign_folder_is_refused_and_untouched(tmp_path, capsys):
    out = tmp_path / "home"
    out.mkdir()
    (out / "thesis.tex").write_text("precious")
    with pytest.raises(InputError, match="not empty and was not written by femmech"):
        run_scene(frame_scene(tmp_path), out, cache_dir=None)
    assert _files(out) == {"thesis.tex"}
    assert main(["run", str(frame_scene(tmp_path)), "--out", str(out), "--no-cache"]) == INPUT
    assert "--out" in one_line(capsys.readouterr().err)
    (tmp_path / "file").write_text("x")
    with pytest.raises(InputError, match="exists and is not a folder"):
        run_scene(frame_scene(tmp_path), tmp_path / "file", cache_dir=None)


def test_staging_left_by_a_killed_run_is_removed(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)
    stale = tmp_path / f".out.femmech-new-{int(dead.stdout)}-abcd1234"
    stale.mkdir()
    (stale / "report.html").write_text("half")
    run_scene(frame_scene(tmp_path), tmp_path / "out", cache_dir=None)
    assert not stale.exists()


def test_a_run_writes_nowhere_but_out_and_the_cache(tmp_path):
    # a scene whose name looks like a path, run with a cache and an output folder elsewhere:
    # every file written lies in out/ or in the cache folder
    folder = tmp_path / "scenes" / "deep"
    folder.mkdir(parents=True)
    scene = frame_scene(folder).read_text().replace('name = "frame"',
                                                    'name = "../../../escape/report"')
    path = folder / "frame.toml"
    path.write_text(scene)
    cache, out = tmp_path / "cache", tmp_path / "results" / "out"
    before = _tree(tmp_path, ())
    run_scene(path, out, cache_dir=cache)
    after = _tree(tmp_path, (out, cache))
    assert after == before
    assert (out / "report.html").is_file()


# --- exit codes ---------------------------------------------------------------------------

def test_numerical_failure_exits_4_naming_the_analysis(tmp_path, monkeypatch, capsys):
    def diverges(ws, spec, folder):
        raise RuntimeError("ARPACK did not converge")

    monkeypatch.setitem(KINDS, "modes", dataclasses.replace(KINDS["modes"], run=diverges))
    code = main(["run", str(frame_scene(tmp_path)), "--out", str(tmp_path / "o"), "--no-cache"])
    assert code == NUMERICAL
    err = one_line(capsys.readouterr().err)
    assert err.startswith("numerical failure: frame.toml: [analyses.modes]: the computation"
                          " failed: RuntimeError: ARPACK did not converge")


def test_internal_error_exits_1_with_traceback_only_under_debug(tmp_path, monkeypatch, capsys):
    def bug(ws, spec, folder):
        return {}["missing"]

    monkeypatch.setitem(KINDS, "modes", dataclasses.replace(KINDS["modes"], run=bug))
    args = ["run", str(frame_scene(tmp_path)), "--out", str(tmp_path / "o"), "--no-cache"]
    assert main(args) == INTERNAL
    err = one_line(capsys.readouterr().err)
    assert err.startswith("internal error: KeyError")
    assert "--debug" in err
    assert main([*args, "--debug"]) == INTERNAL
    assert "Traceback (most recent call last)" in capsys.readouterr().err


def test_full_disk_exits_5(tmp_path, monkeypatch, capsys):
    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr("femmech.scene.run.write_report", full)
    code = main(["run", str(frame_scene(tmp_path)), "--out", str(tmp_path / "o"), "--no-cache"])
    assert code == FILESYSTEM
    assert "No space left on device" in one_line(capsys.readouterr().err)
    assert not (tmp_path / "o").exists()


def test_mode_image_is_drawn_at_the_requested_angle(tmp_path):
    # the sweep grid (every 60°) does not contain 45° or 22.5°: the image is solved at the
    # angle asked for, and its file name and caption say so (it used to be the nearest
    # grid angle, without a word)
    import tomllib

    from femmech.analysis.sweep import sweep
    from femmech.scene.load import Scene
    from femmech.scene.workshop import Workshop

    data = tomllib.loads((ROOT / "examples" / "press_frame.toml").read_text())
    data["analyses"] = {"sweep": {"angles": {"start": "0 deg", "stop": "360 deg", "n": 7},
                                  "n_modes": 2, "mode_images_at": ["45 deg", "22.5 deg"]}}
    scene = Scene.from_dict(data, ROOT / "examples", "press_frame.toml")
    result = run_scene(scene, tmp_path / "out", cache_dir=None)
    html = result.report.read_text()
    for name, deg in (("coupled_mode_45deg.png", "45"), ("coupled_mode_22p5deg.png", "22.5")):
        assert (result.out_dir / name).stat().st_size > 10_000
        assert f"lowest coupled quasi-mode at φ = {deg}°" in html
    # the caption's frequency is the solve at 45°, not at the grid's 60°
    ws = Workshop(prepare(scene), None, lambda line: None, False)
    at_45 = sweep(ws.machine(), np.deg2rad([45.0]), n_modes=1, track=False).freq_hz[0, 0]
    assert f"{at_45:.2f} Hz" in html


@pytest.mark.parametrize("manifest", ["[1, 2]", '"femmech"', "{not json", '{"by": "femmech",'
                                      ' "files": [1]}', '{"files": ["report.html"]}'])
def test_a_damaged_run_manifest_makes_the_folder_foreign(tmp_path, manifest):
    # the manifest is a file in a folder users exchange: a damaged one is never trusted
    # (and never crashes the run), so the folder counts as not written by femmech
    out = tmp_path / "out"
    out.mkdir()
    (out / MANIFEST).write_text(manifest)
    (out / "thesis.tex").write_text("precious")
    with pytest.raises(InputError, match="not empty and was not written by femmech"):
        run_scene(frame_scene(tmp_path), out, cache_dir=None)
    assert (out / "thesis.tex").read_text() == "precious"
