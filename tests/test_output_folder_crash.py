"""A run killed at any rename of the output-folder swap loses no user file: each rename
step k of replacing an existing --out (holding a user file at the top and one inside
femmech's ``modes_steps/``) is hooked in a subprocess that dies there with os._exit(9),
before or after the rename; then the user's files must still exist under the parent
folder, and a re-run into the same --out must end with the new results and the user's
files in ``out`` and no hidden sibling left, with a FemmechWarning naming the recovery."""

import os
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import pytest

from femmech.errors import FemmechWarning
from femmech.output.folder import staged_output

VICTIM = textwrap.dedent("""
    import os, sys
    from pathlib import Path
    from femmech.output import folder
    out, k, when = Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    real, calls = os.rename, [0]
    def rename(src, dst, *a, **kw):
        calls[0] += 1
        if calls[0] == k and when == "before":
            os._exit(9)
        real(src, dst, *a, **kw)
        if calls[0] == k and when == "after":
            os._exit(9)
    folder.os.rename = rename
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
    # out -> old, staging -> out, one per user file (mine.txt, modes_steps/my_notes.txt)
    assert _renames_of_a_replacement(tmp_path) == 4


@pytest.mark.parametrize("when", ["before", "after"])
@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_a_run_killed_at_rename_k_loses_nothing_and_the_rerun_recovers(tmp_path, k, when):
    out = tmp_path / "out"
    _first_run(out)
    crashed = _victim(out, k, when)
    assert crashed.returncode == 9, crashed.stderr
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
    if (k, when) != (1, "before"):  # the swap had begun: the recovery is named
        assert any("interrupted swap" in m for m in messages), messages
