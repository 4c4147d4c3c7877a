"""A run killed at any rename of the output-folder swap loses no user file: each rename
step k of replacing an existing --out (holding a user file at the top and one inside
femmech's ``modes_steps/``) is hooked in a subprocess that dies there with os._exit(9),
before or after the rename (os.replace: the journal; os.rename: the folders and user
files); then the user's files must still exist under the parent folder, and a re-run into
the same --out must end with the new results and the user's files in ``out`` and no hidden
sibling left, with a FemmechWarning naming the recovery where the swap had begun. The
killed run's pid may meanwhile belong to another live process (reused): the recovery is
decided by the run lock and the journal, not by the pid."""

import json
import os
import subprocess
import sys
import textwrap
import time
import warnings
from pathlib import Path

import pytest

from femmech.errors import FemmechWarning
from femmech.output import folder_swap
from femmech.output.folder import MANIFEST, staged_output

VICTIM = textwrap.dedent("""
    import os, sys
    from pathlib import Path
    from femmech.output import folder
    out, k, when = Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    calls = [0]
    def hooked(real):
        def rename(src, dst, *a, **kw):
            calls[0] += 1
            if calls[0] == k and when == "before":
                os._exit(9)
            real(src, dst, *a, **kw)
            if calls[0] == k and when == "after":
                os._exit(9)
        return rename
    os.rename, os.replace = hooked(os.rename), hooked(os.replace)
    with folder.staged_output(out) as stage:
        (stage / "modes_steps").mkdir()
        (stage / "report.html").write_text("r2")
        (stage / "modes_steps" / "step_00000.vtu").write_text("s2")
    print("RENAMES", calls[0])
""")

USER = {"mine.txt": "mine", "modes_steps/my_notes.txt": "notes"}


def _first_run(out: Path) -> None:
    with staged_output(out) as stage:
        (stage / "modes_steps").mkdir()
        (stage / "report.html").write_text("r1")
        (stage / "modes_steps" / "step_00000.vtu").write_text("s1")
    for rel, text in USER.items():
        (out / rel).write_text(text)


def _victim(out: Path, k: int, when: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    return subprocess.run([sys.executable, "-c", VICTIM, str(out), str(k), when],
                          capture_output=True, text=True, timeout=120, env=env)


def _renames_of_a_replacement(tmp_path: Path) -> int:
    out = tmp_path / "count" / "out"
    _first_run(out)
    done = _victim(out, 0, "never")
    assert done.returncode == 0, done.stderr
    return int(done.stdout.split()[-1])


def test_the_replacement_has_the_expected_renames(tmp_path):
    # the journal, out -> old, staging -> out, one per user file (mine.txt,
    # modes_steps/my_notes.txt)
    assert _renames_of_a_replacement(tmp_path) == 5


SEEN = {(1, "before"): None, (1, "after"): None, (2, "before"): None,
        (2, "after"): "interrupted swap completed", (3, "before"): "interrupted swap completed",
        (3, "after"): "interrupted swap recovered", (4, "before"): "interrupted swap recovered",
        (4, "after"): "interrupted swap recovered", (5, "before"): "interrupted swap recovered",
        (5, "after"): None}
"""What the re-run says about the killed run, per step: nothing while ``out`` was never
moved (journal not written or written, out -> old not done) or once every user file was
back (only femmech's files left aside); "completed" when ``out`` was missing (the killed
run's results are put in place); "recovered" when user files were still aside."""


def _reuse_pid(parent: Path, pid: int) -> None:
    """Rename the hidden siblings of the killed run as if made by process ``pid``."""
    for path in parent.iterdir():
        head, sep, tail = path.name.partition(".femmech-")
        if sep:
            kind, _, rest = tail.partition("-")
            path.rename(parent / f"{head}{sep}{kind}-{pid}-{rest.partition('-')[2]}")


@pytest.mark.parametrize("pid", ["own", "reused"])
@pytest.mark.parametrize("when", ["before", "after"])
@pytest.mark.parametrize("k", [1, 2, 3, 4, 5])
def test_a_run_killed_at_rename_k_loses_nothing_and_the_rerun_recovers(tmp_path, k, when,
                                                                      pid):
    out = tmp_path / "out"
    _first_run(out)
    crashed = _victim(out, k, when)
    assert crashed.returncode == 9, crashed.stderr
    if pid == "reused":  # the dead run's pid now belongs to a live process (our parent)
        _reuse_pid(tmp_path, os.getppid())
    # (i) every user file still exists somewhere under the parent folder
    for rel, text in USER.items():
        name = Path(rel).name
        found = [p for p in tmp_path.rglob(name) if p.read_text() == text]
        assert found, f"{rel} lost after a kill {when} rename {k}"
    # (ii) a re-run into the same --out ends with the new results and the user's files
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with staged_output(out) as stage:
            (stage / "modes_steps").mkdir()
            (stage / "report.html").write_text("r3")
            (stage / "modes_steps" / "step_00000.vtu").write_text("s3")
    assert (out / "report.html").read_text() == "r3"
    assert (out / "modes_steps" / "step_00000.vtu").read_text() == "s3"
    for rel, text in USER.items():
        assert (out / rel).read_text() == text
    assert not [p.name for p in tmp_path.iterdir() if ".femmech-" in p.name]
    # (iii) the user is told: the warning of the re-run names the nested user file
    messages = [str(w.message) for w in caught if issubclass(w.category, FemmechWarning)]
    assert any("my_notes.txt" in m for m in messages), messages
    seen = SEEN[k, when]
    recovery = [m for m in messages if "interrupted swap" in m]
    if seen is None:
        assert not recovery, messages
    else:
        assert len(recovery) == 1, messages
        assert seen in recovery[0], messages
        assert ".out.femmech-old-" in recovery[0]
        assert "killed" in recovery[0]


def _aside(tmp_path: Path, pid: int, journal: bool) -> Path:
    """``out`` as a killed run by process ``pid`` left it after moving it aside and putting
    its results in place: the previous folder with a user file, optionally the journal."""
    out = tmp_path / "out"
    _first_run(out)
    old = tmp_path / f".out.femmech-old-{pid}-abcd1234"
    os.rename(out, old)
    (out / "modes_steps").mkdir(parents=True)  # the killed run's results, put in place
    (out / "report.html").write_text("r2")
    (out / "modes_steps" / "step_00000.vtu").write_text("s2")
    (out / MANIFEST).write_text(json.dumps(
        {"by": "femmech", "files": ["report.html", "modes_steps/step_00000.vtu"]}))
    if journal:
        (tmp_path / f".out.femmech-journal-{pid}-abcd1234.json").write_text(json.dumps(
            {"by": "femmech", "out": "out", "old": old.name, "new": "x",
             "ours": ["report.html", "modes_steps/step_00000.vtu"], "user_files": list(USER)}))
    return old


def _rerun(out: Path) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with staged_output(out) as stage:
            (stage / "report.html").write_text("r3")
    return [str(w.message) for w in caught if issubclass(w.category, FemmechWarning)]


@pytest.mark.skipif(os.name == "nt", reason="run locks need flock")
def test_the_previous_folder_of_a_run_that_holds_its_lock_is_left_alone(tmp_path):
    """A concurrent run (its lock held: here by this process) keeps its siblings, although
    its pid (1) tells nothing."""
    old = _aside(tmp_path, 1, journal=True)
    lock = tmp_path / ".out.femmech-lock-1-abcd1234"
    fd = folder_swap.hold_lock(lock)
    try:
        assert _rerun(tmp_path / "out") == []
        assert (old / "mine.txt").read_text() == "mine"
        assert not (tmp_path / "out" / "mine.txt").exists()
    finally:
        os.close(fd)
    # its lock released (the run died, pid 1 still runs): the next run recovers
    messages = _rerun(tmp_path / "out")
    assert len(messages) == 1, messages
    assert "interrupted swap recovered" in messages[0]
    for rel, text in USER.items():
        assert (tmp_path / "out" / rel).read_text() == text
    assert not [p.name for p in tmp_path.iterdir() if ".femmech-" in p.name]


@pytest.mark.parametrize("pid", [1, "parent"])
def test_a_previous_folder_without_lock_whose_pid_runs_is_named_then_recovered(tmp_path, pid):
    """A sibling without a run lock (left by an older femmech) whose pid is a live process
    (maybe reused): left in place with a warning naming it while young; recovered once
    older than STALE_AGE (a run never takes that long between two renames)."""
    pid = os.getppid() if pid == "parent" else pid
    old = _aside(tmp_path, pid, journal=False)
    messages = _rerun(tmp_path / "out")
    assert len(messages) == 1, messages
    assert messages[0] == (f"--out {tmp_path / 'out'}: {old.name} holds the previous folder"
                           f" of a run (process {pid}) that may still be running; left in"
                           " place (if no femmech run writes into this folder, your files"
                           " there are safe to move back)")
    assert (old / "modes_steps" / "my_notes.txt").read_text() == "notes"
    past = time.time() - folder_swap.STALE_AGE - 60
    os.utime(old, (past, past))
    messages = _rerun(tmp_path / "out")
    assert any("interrupted swap recovered" in m for m in messages), messages
    for rel, text in USER.items():
        assert (tmp_path / "out" / rel).read_text() == text
    assert not old.exists()
