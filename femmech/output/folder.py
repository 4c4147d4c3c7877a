"""One run, one output folder: a run writes into a staging folder that replaces ``out``
only when the run has succeeded.

The staging folder is a hidden sibling of ``out`` (``.<name>.femmech-new-<pid>-<hex>``),
so the final step is a rename on one file system. An ``out`` that is a symbolic link (or
lies below one) is resolved first: the swap happens beside the folder the link points to,
and the link stays a link to the new run's folder. A folder written by femmech holds a
manifest, :data:`MANIFEST`, listing the files of its run. A new run into the same folder
replaces exactly those files; every other file, at the top or inside one of femmech's
own subfolders (e.g. ``modes_steps/``), is the user's and is carried over into the new
folder at the same place (a FemmechWarning names those inside femmech's subfolders, and
any that had to be renamed because the new run wrote a file of the same name). A failed
or interrupted run leaves the previous folder as it was; its staging folder is removed at
once, or by the next run into the same folder if the process was killed. The swap itself
is crash-safe (:mod:`.folder_swap`: a run lock decides whether a run still runs, a journal
what a killed swap had done): the next run completes or undoes it and never removes a
folder holding a user's file. A folder that is neither empty nor written by femmech (its
manifest missing, or no regular file: a link, FIFO, device, directory or larger than
:data:`~femmech.output.folder_swap.MAX_MANIFEST_BYTES`) is refused, so ``--out`` can
never make femmech delete a user's files.

Uses errors and :mod:`.folder_swap`.
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from femmech.errors import InputError
from femmech.output.folder_swap import (
    MANIFEST,
    STALE_AGE,
    hold_lock,
    manifest_problem,
    new_token,
    read_manifest,
    recover,
    release_lock,
    run_files,
    sibling,
    swap,
    user_items,
)

__all__ = ["MANIFEST", "STALE_AGE", "check_output_folder", "output_path", "read_manifest",
           "real_output_path", "staged_output"]


def output_path(out) -> Path:
    """The absolute path of the output folder ``out`` (``~`` expanded, links kept)."""
    return Path(out).expanduser().absolute()


def real_output_path(out) -> Path:
    """The folder a run replaces: :func:`output_path` with symbolic links resolved (a
    dangling link: the path it points to). InputError for a link loop."""
    path = output_path(out)
    try:
        return path.resolve()
    except (OSError, RuntimeError) as exc:  # RuntimeError: a loop before Python 3.13
        raise InputError(f"--out {path}: cannot resolve its symbolic links ({exc})") from None


def check_output_folder(out) -> Path:
    """The output folder with its links resolved (:func:`real_output_path`), or
    InputError naming it if it cannot be used: it is a file, or a non-empty folder
    without a femmech manifest."""
    out = real_output_path(out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out}: exists and is not a folder")
    if out.is_dir() and any(out.iterdir()):
        problem = manifest_problem(out)
        if problem is not None:
            raise InputError(f"--out {out}: the folder is not empty and was not written by"
                             f" femmech ({problem}); give a new or empty folder (femmech"
                             " replaces the files of its previous run there, and never"
                             " touches others)")
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
    out = real_output_path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    recover(out)  # killed runs into out: their swaps finished or undone first
    out = check_output_folder(out)
    token = new_token()
    lock = hold_lock(sibling(out, "lock", token))
    staging = sibling(out, "new", token)
    try:
        staging.mkdir()
        try:
            yield staging
            _write_manifest(staging)
            _replace(out, staging, token)
        except BaseException:
            shutil.rmtree(staging, ignore_errors=True)
            raise
    finally:
        release_lock(out, token, lock)


def _write_manifest(staging: Path) -> None:
    files = sorted(p.relative_to(staging).as_posix() for p in staging.rglob("*") if p.is_file())
    (staging / MANIFEST).write_text(json.dumps({"by": "femmech", "files": files}, indent=1),
                                    encoding="utf-8")


def _replace(out: Path, staging: Path, token: str) -> None:
    """Put ``staging`` in the place of ``out``, carrying over the user's own files."""
    if not out.exists():
        os.rename(staging, out)
        return
    ours = run_files(out)
    swap(out, staging, token, ours, list(user_items(out, ours)))
