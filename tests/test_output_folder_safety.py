"""Re-runs into one --out: femmech replaces only the files it wrote (its manifest), keeps
the user's files wherever they are (also inside femmech's own subfolders), resolves an
--out that is a symbolic link and leaves no hidden folder behind."""

import json
import os
import sys
from pathlib import Path

import pytest

from femmech.errors import FemmechWarning
from femmech.output.folder import MANIFEST, staged_output


def _run(out, files: dict[str, str]) -> None:
    """One 'run' writing ``files`` (relative path → text) through the staging folder."""
    with staged_output(out) as stage:
        for rel, text in files.items():
            (stage / rel).parent.mkdir(parents=True, exist_ok=True)
            (stage / rel).write_text(text)


def _tree(folder: Path) -> dict[str, str]:
    return {p.relative_to(folder).as_posix(): p.read_text() for p in folder.rglob("*")
            if p.is_file() and p.name != MANIFEST}


def _hidden(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if ".femmech-" in p.name)


RUN = {"report.html": "r1", "modes.pvd": "p1", "modes_steps/step_00000.vtu": "s1",
       "modes_steps/step_00001.vtu": "s1"}


def test_user_file_inside_a_femmech_subfolder_is_kept_and_named(tmp_path):
    out = tmp_path / "out"
    _run(out, RUN)
    (out / "modes_steps" / "my_notes.txt").write_text("mine")
    (out / "modes_steps" / "mine").mkdir()
    (out / "modes_steps" / "mine" / "a.txt").write_text("mine too")
    (out / "top.txt").write_text("top")  # at the top: kept silently, as before
    second = {"report.html": "r2", "modes.pvd": "p2", "modes_steps/step_00000.vtu": "s2"}
    with pytest.warns(FemmechWarning, match=r"--out .*out: kept your files inside femmech's"
                      r" subfolders: modes_steps/mine, modes_steps/my_notes.txt$"):
        _run(out, second)
    assert _tree(out) == {**second, "modes_steps/my_notes.txt": "mine",
                          "modes_steps/mine/a.txt": "mine too", "top.txt": "top"}
    # the step the second run no longer writes is gone: it was femmech's
    assert not (out / "modes_steps" / "step_00001.vtu").exists()
    assert set(json.loads((out / MANIFEST).read_text())["files"]) == set(second)
    assert _hidden(tmp_path) == []


def test_user_file_with_the_name_of_a_new_file_is_renamed_not_lost(tmp_path):
    out = tmp_path / "out"
    _run(out, {"report.html": "r1", "modes_steps/step_00000.vtu": "s1"})
    (out / "modes_steps" / "step_00001.vtu").write_text("user's own")
    with pytest.warns(FemmechWarning, match=r"modes_steps/step_00001.vtu ->"
                      r" modes_steps/step_00001.kept.vtu"):
        _run(out, {"report.html": "r2", "modes_steps/step_00000.vtu": "s2",
                   "modes_steps/step_00001.vtu": "s2"})
    assert (out / "modes_steps" / "step_00001.vtu").read_text() == "s2"
    assert (out / "modes_steps" / "step_00001.kept.vtu").read_text() == "user's own"
    assert _hidden(tmp_path) == []


@pytest.mark.skipif(sys.platform == "win32", reason="symbolic links need privileges")
def test_out_that_is_a_symbolic_link_stays_a_link_and_leaves_nothing_behind(tmp_path):
    target = tmp_path / "data" / "results"
    target.mkdir(parents=True)
    link = tmp_path / "link"
    link.symlink_to(target, target_is_directory=True)
    _run(link, RUN)
    (link / "notes.txt").write_text("mine")
    _run(link, {"report.html": "r2"})
    assert link.is_symlink()
    assert link.resolve() == target.resolve()
    assert _tree(target) == {"report.html": "r2", "notes.txt": "mine"}
    assert _hidden(tmp_path) == []
    assert _hidden(target.parent) == []
    # a dangling link: the run creates the folder it points to
    dangling = tmp_path / "dangling"
    dangling.symlink_to(tmp_path / "later", target_is_directory=True)
    _run(dangling, {"report.html": "r"})
    assert dangling.is_symlink()
    assert (tmp_path / "later" / "report.html").is_file()


def test_failed_run_into_a_link_changes_nothing(tmp_path):
    target = tmp_path / "target"
    link = tmp_path / "link"
    link.symlink_to(target, target_is_directory=True)
    _run(link, RUN)
    before = _tree(target)

    def broken_run():
        with staged_output(link) as stage:
            (stage / "report.html").write_text("half")
            raise RuntimeError("broke")

    with pytest.raises(RuntimeError, match="broke"):
        broken_run()
    assert _tree(target) == before
    assert link.is_symlink()
    assert _hidden(tmp_path) == []


def test_previous_folder_retired_by_a_killed_swap_is_put_back_or_carried_over(tmp_path):
    out = tmp_path / "out"
    _run(out, RUN)
    (out / "modes_steps" / "mine.txt").write_text("mine")
    # a run killed between its two renames: the previous folder lies aside, out is missing
    dead = 2 ** 22 + 12345  # above the default pid_max (2^22): no such process
    retired = tmp_path / f".out.femmech-old-{dead}-abcd1234"
    os.rename(out, retired)
    with pytest.warns(FemmechWarning, match="is put back"), \
            pytest.warns(FemmechWarning, match="modes_steps/mine.txt"):
        _run(out, {"report.html": "r2"})
    assert (out / "modes_steps" / "mine.txt").read_text() == "mine"
    assert _hidden(tmp_path) == []
    # killed after the second rename: out is the new run, the aside folder holds a user file
    retired.mkdir()
    (retired / MANIFEST).write_text(json.dumps({"by": "femmech", "files": ["old.csv"]}))
    (retired / "old.csv").write_text("femmech's")
    (retired / "precious.txt").write_text("mine")
    with pytest.warns(FemmechWarning, match="interrupted swap recovered"):
        _run(out, {"report.html": "r3"})
    assert (out / "precious.txt").read_text() == "mine"
    assert not (out / "old.csv").exists()
    assert _hidden(tmp_path) == []


def test_a_swap_that_fails_in_the_process_puts_the_previous_folder_back(tmp_path, monkeypatch):
    """A rename of the swap that fails (here: putting the new results in place, as on a
    full or read-only disk) puts the previous folder back at once, before the error
    propagates; a later run in the same process then replaces it as usual."""
    out = tmp_path / "out"
    _run(out, RUN)
    (out / "mine.txt").write_text("mine")
    before = _tree(out)
    real = os.rename

    def failing(src, dst):
        if Path(src).name.startswith(".out.femmech-new-"):
            raise OSError(28, "No space left on device")
        real(src, dst)

    monkeypatch.setattr(os, "rename", failing)
    with pytest.raises(OSError, match="No space left"):
        _run(out, {"report.html": "r2"})
    monkeypatch.setattr(os, "rename", real)
    assert _tree(out) == before
    assert _hidden(tmp_path) == []
    _run(out, {"report.html": "r3"})
    assert _tree(out) == {"report.html": "r3", "mine.txt": "mine"}
