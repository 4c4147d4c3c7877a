"""One run, one output folder: a run writes into a staging folder that replaces ``out``
only when the run has succeeded.

The staging folder is a hidden sibling of ``out`` (``.<name>.femmech-new-<pid>-<hex>``),
so the final step is a rename on one file system. A folder written by femmech holds a
manifest, :data:`MANIFEST`, listing the files of its run. A new run into the same folder
replaces exactly those files; files the user put there later (not in the manifest) are
carried over untouched. A failed or interrupted run leaves the previous folder as it was;
its staging folder is removed at once, or by the next run into the same folder if the
process was killed. A folder that is neither empty nor written by femmech is refused, so
``--out`` can never make femmech delete a user's files.

Stage 7 (output): uses only errors.
"""

from __future__ import annotations

import json
import os
import secrets
import shutil
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from femmech.errors import InputError

MANIFEST = ".femmech-run.json"
"""File name of the manifest in an output folder: ``{"files": [...], "by": "femmech"}``."""

_TAG = ".femmech-"

STALE_AGE = 24 * 3600.0
"""s; where a process cannot be asked whether it still runs (Windows, where signal 0 is
Ctrl-C), a staging folder older than this counts as left by a killed run."""


def _siblings(out: Path) -> list[Path]:
    """Staging and retired folders of ``out`` left by earlier runs."""
    prefix = f".{out.name}{_TAG}"
    return [p for p in out.parent.iterdir() if p.name.startswith(prefix)]


def _alive(pid: int, path: Path) -> bool:
    """Whether the run that made ``path`` may still be running."""
    if os.name == "nt":  # os.kill(pid, 0) would send CTRL_C_EVENT there
        try:
            return time.time() - path.stat().st_mtime < STALE_AGE
        except OSError:
            return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # e.g. another user's process: leave its folder alone
        return True
    return True


def _remove_stale(out: Path) -> None:
    """Remove staging/retired siblings of ``out`` whose process no longer runs."""
    for path in _siblings(out):
        try:
            pid = int(path.name.rsplit("-", 2)[-2])
        except (ValueError, IndexError):
            continue
        if pid != os.getpid() and not _alive(pid, path):
            shutil.rmtree(path, ignore_errors=True)


def read_manifest(folder: Path) -> list[str] | None:
    """Relative paths listed in ``folder``'s manifest; None if it has no valid one."""
    try:
        data = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or data.get("by") != "femmech":
        return None
    files = data.get("files")
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        return None
    return files


def output_path(out) -> Path:
    """The absolute path of the output folder ``out`` (``~`` expanded, links kept)."""
    return Path(out).expanduser().absolute()


def check_output_folder(out) -> Path:
    """The absolute output folder, or InputError naming it if it cannot be used: it is a
    file, or a non-empty folder without a femmech manifest."""
    out = output_path(out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out}: exists and is not a folder")
    if out.is_dir() and any(out.iterdir()) and read_manifest(out) is None:
        raise InputError(f"--out {out}: the folder is not empty and was not written by femmech"
                         f" (no {MANIFEST}); give a new or empty folder (femmech replaces the"
                         " files of its previous run there, and never touches others)")
    return out


@contextmanager
def staged_output(out) -> Iterator[Path]:
    """Yield an empty staging folder; on success it becomes ``out`` (see the module).

    Parameters
    ----------
    out : path
        The output folder; created with its parents if missing.

    Yields
    ------
    Path
        Where the run writes all its files (flat or in subfolders).

    Raises
    ------
    InputError
        ``out`` is a file or a non-empty folder that femmech did not write.
    OSError
        The parent folder cannot be created or written.
    """
    out = check_output_folder(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    _remove_stale(out)
    token = f"{os.getpid()}-{secrets.token_hex(4)}"
    staging = out.parent / f".{out.name}{_TAG}new-{token}"
    staging.mkdir()
    try:
        yield staging
        _write_manifest(staging)
        _replace(out, staging, token)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise


def _write_manifest(staging: Path) -> None:
    files = sorted(p.relative_to(staging).as_posix() for p in staging.rglob("*") if p.is_file())
    (staging / MANIFEST).write_text(json.dumps({"by": "femmech", "files": files}, indent=1),
                                    encoding="utf-8")


def _replace(out: Path, staging: Path, token: str) -> None:
    """Put ``staging`` in the place of ``out``, carrying over the user's own files."""
    if not out.exists():
        os.rename(staging, out)
        return
    ours = set(read_manifest(out) or ()) | {MANIFEST}
    retired = out.parent / f".{out.name}{_TAG}old-{token}"
    os.rename(out, retired)
    os.rename(staging, out)
    for item in retired.iterdir():  # files the user added after the previous run
        if item.name not in ours and not any(f.startswith(item.name + "/") for f in ours) \
                and not (out / item.name).exists():
            os.rename(item, out / item.name)
    shutil.rmtree(retired, ignore_errors=True)
