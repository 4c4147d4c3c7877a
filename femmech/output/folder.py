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
once, or by the next run into the same folder if the process was killed (a previous
folder retired by a run killed during the swap is put back, or its user files carried
over). A folder that is neither empty nor written by femmech is refused, so ``--out`` can
never make femmech delete a user's files.

Stage 7 (output): uses only errors.
"""

from __future__ import annotations

import json
import os
import secrets
import shutil
import time
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from femmech.errors import FemmechWarning, InputError

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
    """Clear the staging/retired siblings of ``out`` whose process no longer runs: staging
    folders are removed; a retired folder (the previous run, moved aside by a run killed
    during the swap) is put back if ``out`` is missing, else its user files are carried
    over into ``out`` before it is removed."""
    for path in _siblings(out):
        try:
            pid = int(path.name.rsplit("-", 2)[-2])
        except (ValueError, IndexError):
            continue
        if pid == os.getpid() or _alive(pid, path):
            continue
        if path.name.startswith(f".{out.name}{_TAG}old-"):
            if not os.path.lexists(out):
                os.rename(path, out)
                warnings.warn(FemmechWarning(
                    f"--out {out}: a run (process {pid}) was killed during its swap; the"
                    f" previous folder, hidden as {path.name}, is put back (interrupted swap"
                    " recovered)"), stacklevel=4)
                continue
            _retire(path, out, _ours(path), recovered=True)
        else:
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
    ours = _ours(out)
    retired = out.parent / f".{out.name}{_TAG}old-{token}"
    os.rename(out, retired)
    os.rename(staging, out)
    _retire(retired, out, ours)


def _ours(folder: Path) -> set[str]:
    """Relative paths (POSIX) of the files femmech wrote into ``folder``: its manifest's."""
    return set(read_manifest(folder) or ()) | {MANIFEST}


def _user_items(folder: Path, ours: set[str], parents: set[str], rel: str = ""):
    """Relative paths under ``folder`` that femmech did not write: files (and links) not
    in ``ours``, and whole folders that hold none of ``ours`` (``parents``: the folders
    that do)."""
    for item in sorted(folder.iterdir()):
        path = rel + item.name
        if path in ours:
            continue
        if path in parents and item.is_dir() and not item.is_symlink():
            yield from _user_items(item, ours, parents, path + "/")
        else:
            yield path


def _free_name(path: Path) -> Path:
    """``path``, or ``<stem>.kept<suffix>`` (``.kept2``, ...) if that name is taken."""
    candidate, n = path, 1
    while os.path.lexists(candidate):
        candidate = path.with_name(f"{path.stem}.kept{n if n > 1 else ''}{path.suffix}")
        n += 1
    return candidate


def _retire(retired: Path, out: Path, ours: set[str], recovered: bool = False) -> None:
    """Move the user's files from the previous folder ``retired`` into ``out`` at the same
    relative places, then remove ``retired``; kept (and named in a warning) if a file
    could not be moved. Warns naming the files carried into femmech's subfolders and
    those renamed because the new run wrote the same name."""
    parents = {"/".join(f.split("/")[:i]) for f in ours for i in range(1, f.count("/") + 1)}
    nested, renamed, stuck = [], [], []
    for rel in _user_items(retired, ours, parents):
        target = _free_name(out / rel)
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            os.rename(retired / rel, target)
        except OSError:
            stuck.append(rel)
            continue
        if target != out / rel:
            renamed.append(f"{rel} -> {target.relative_to(out).as_posix()}")
        elif "/" in rel:
            nested.append(rel)
    if not stuck:
        shutil.rmtree(retired, ignore_errors=True)
    notes = []
    if recovered:
        notes.append(f"a run killed during its swap left the previous folder as"
                     f" {retired.name}; your files still there were moved into the folder"
                     " (interrupted swap recovered)")
    if nested:
        notes.append(f"kept your files inside femmech's subfolders: {_listed(nested)}")
    if renamed:
        notes.append(f"the new run wrote files of the same names as yours, kept as:"
                     f" {_listed(renamed)}")
    if stuck:
        notes.append(f"could not move {_listed(stuck)}; the previous folder is left as"
                     f" {retired}")
    if notes:
        # stacklevel 5: past _replace or _remove_stale, staged_output and contextlib, to
        # the with statement of the caller
        warnings.warn(FemmechWarning(f"--out {out}: " + "; ".join(notes)), stacklevel=5)


def _listed(paths: list[str], at_most: int = 10) -> str:
    more = len(paths) - at_most
    return ", ".join(paths[:at_most]) + (f" and {more} more" if more > 0 else "")
