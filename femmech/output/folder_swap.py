"""The crash-safe swap of an output folder: run lock, journal, recovery of killed runs.

A run into ``out`` names its hidden siblings in ``out``'s parent with one token
``<pid>-<hex>`` (``P`` = ``.<name>.femmech-``):

``P lock-<token>``
    The run lock: an empty file that the run holds locked (``flock``) from before its
    staging folder exists until its last sibling is gone. The system releases the lock
    when the process dies, so whether a run still runs is decided by the lock, never by
    its pid alone (a pid is reused by unrelated processes).
``P new-<token>``
    The staging folder: only files of the run.
``P old-<token>``
    The previous ``out``, moved aside during the swap; it may hold the user's files.
``P journal-<token>.json``
    Written atomically before the swap begins: ``out``, ``old``, ``new``, the files of
    the previous run (``ours``: replaced) and the user's files still to move back
    (``user_files``). Removed only when ``old`` is gone.

The swap is: journal, ``out -> old``, ``new -> out``, each user file ``old/f -> out/f``,
remove ``old`` (only if no user file is left in it), remove the journal. The recovery of a
run found dead (:func:`recover`) completes it from any of these steps: ``out`` missing and
``new`` complete: ``new -> out`` then the user files; ``out`` missing and no ``new``:
``old -> out`` (put back); ``out`` present: the user files from ``old``. A folder holding a
user file is never removed; if a file cannot be moved, the folder stays with a warning
naming it. Siblings of an older femmech without a lock file are judged by their pid and
age (:data:`STALE_AGE`), and an ``old`` folder kept so is named in a warning.

Uses errors and the regular-file reader of :mod:`femmech.reduction`.
"""

from __future__ import annotations

import json
import os
import secrets
import shutil
import time
import warnings
from pathlib import Path

from femmech.errors import FemmechWarning, FileFormatError
from femmech.reduction.superelement_file import read_regular

try:  # POSIX; elsewhere runs are judged by their pid and age
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None

MANIFEST = ".femmech-run.json"
"""File name of the manifest in an output folder: ``{"files": [...], "by": "femmech"}``."""

MAX_MANIFEST_BYTES = 64 << 20
"""Largest output-folder manifest or swap journal read, bytes (a run of 10^5 files
writes about 5 MB)."""

STALE_AGE = 24 * 3600.0
"""s; a sibling without a run lock (an older femmech, or a system without ``flock``) whose
pid runs counts as left by a killed run when older than this (the pid may be reused)."""

_TAG = ".femmech-"
_KINDS = ("new", "old", "lock", "journal", "jtmp")


def prefix(out: Path) -> str:
    return f".{out.name}{_TAG}"


def sibling(out: Path, kind: str, token: str) -> Path:
    """The hidden sibling of ``out`` of kind ``new``, ``old``, ``lock``, ``journal`` or
    ``jtmp`` (the journal's temporary) for the run ``token``."""
    suffix = ".json" if kind in ("journal", "jtmp") else ""
    return out.parent / f"{prefix(out)}{kind}-{token}{suffix}"


def new_token() -> str:
    return f"{os.getpid()}-{secrets.token_hex(4)}"


def read_manifest(folder: Path) -> list[str] | None:
    """Relative paths listed in ``folder``'s manifest; None if it has no valid one (also if
    it is no regular file of at most :data:`MAX_MANIFEST_BYTES` bytes: see
    :func:`manifest_problem`)."""
    return _manifest(folder)[0]


def manifest_problem(folder: Path) -> str | None:
    """Why ``folder`` has no valid manifest (one line), or None if it has one."""
    return _manifest(folder)[1]


def _manifest(folder: Path) -> tuple[list[str] | None, str | None]:
    path = folder / MANIFEST
    try:
        data = json.loads(read_regular(path, "output-folder manifest", MAX_MANIFEST_BYTES))
    except FileNotFoundError:
        return None, f"no {MANIFEST}"
    except FileFormatError as exc:
        return None, str(exc)
    except (OSError, ValueError) as exc:
        return None, f"{path}: not a readable output-folder manifest: {exc}"
    files = data.get("files") if isinstance(data, dict) else None
    if (not isinstance(data, dict) or data.get("by") != "femmech" or not isinstance(files, list)
            or not all(isinstance(f, str) for f in files)):
        return None, f"{path}: not a femmech manifest"
    return files, None


# --- the run lock ---------------------------------------------------------------------

def hold_lock(path: Path) -> int | None:
    """Create ``path`` and lock it for this process; the descriptor, or None where files
    cannot be locked (then no lock file is left)."""
    if fcntl is None:
        return None
    for _ in range(10):
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0), 0o644)
        except OSError:  # a read-only parent fails later, with its own message
            return None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            if os.path.samestat(os.fstat(fd), os.stat(path)):
                return fd
        except OSError:
            pass
        os.close(fd)  # unlinked or replaced meanwhile, or no flock here
    path.unlink(missing_ok=True)
    return None


def release_lock(out: Path, token: str, fd: int | None) -> None:
    """Drop the run lock; its file goes unless the run left an ``old`` folder or journal
    (a failed swap that could not be rolled back: the next run recovers it)."""
    if fd is None:
        return
    if not (os.path.lexists(sibling(out, "old", token))
            or os.path.lexists(sibling(out, "journal", token))):
        sibling(out, "lock", token).unlink(missing_ok=True)
    os.close(fd)


def _try_lock(path: Path) -> int | bool | None:
    """The descriptor of ``path`` locked here (its run is dead), False if another process
    holds it (the run is alive), None if it cannot be told (no such file, no flock)."""
    if fcntl is None:
        return None
    try:
        fd = os.open(path, os.O_RDWR | getattr(os, "O_NOFOLLOW", 0))
    except OSError:
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        return False
    except OSError:
        os.close(fd)
        return None
    return fd


def _pid_alive(pid: int, path: Path) -> bool:
    """Whether the run of a sibling without a run lock may still be running: its pid
    runs and the sibling is younger than :data:`STALE_AGE`."""
    try:
        young = time.time() - path.stat().st_mtime < STALE_AGE
    except OSError:
        return False
    if os.name == "nt":  # os.kill(pid, 0) would send CTRL_C_EVENT there
        return young
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # e.g. another user's process
        return young
    return young


# --- the swap -------------------------------------------------------------------------

def swap(out: Path, staging: Path, token: str, ours: set[str], user: list[str]) -> None:
    """Put ``staging`` in the place of the existing folder ``out`` (see the module),
    carrying over the user's files ``user`` (relative paths; ``ours``: the files of the
    previous run). If a step fails in this process, ``out`` is put back before the error
    propagates (or, if that fails too, the journal stays for the next run)."""
    old, journal = sibling(out, "old", token), sibling(out, "journal", token)
    tmp = sibling(out, "jtmp", token)
    tmp.write_text(json.dumps({"by": "femmech", "out": out.name, "old": old.name,
                               "new": staging.name, "ours": sorted(ours),
                               "user_files": user}, indent=1), encoding="utf-8")
    os.replace(tmp, journal)
    try:
        os.rename(out, old)
    except BaseException:
        journal.unlink(missing_ok=True)
        raise
    try:
        os.rename(staging, out)
    except BaseException:
        if not os.path.lexists(out) and os.path.isdir(old):
            os.rename(old, out)
            journal.unlink(missing_ok=True)
        raise
    if retire(old, out, ours):
        journal.unlink(missing_ok=True)


def user_items(folder: Path, ours: set[str], parents: set[str] | None = None,
               rel: str = ""):
    """Relative paths under ``folder`` that femmech did not write: files (and links) not
    in ``ours``, and whole folders that hold none of ``ours`` (``parents``: the folders
    that do)."""
    if parents is None:
        parents = _parents(ours)
    for item in sorted(folder.iterdir()):
        path = rel + item.name
        if path in ours:
            continue
        if path in parents and item.is_dir() and not item.is_symlink():
            yield from user_items(item, ours, parents, path + "/")
        else:
            yield path


def _parents(ours: set[str]) -> set[str]:
    return {"/".join(f.split("/")[:i]) for f in ours for i in range(1, f.count("/") + 1)}


def _free_name(path: Path) -> Path:
    """``path``, or ``<stem>.kept<suffix>`` (``.kept2``, ...) if that name is taken."""
    candidate, n = path, 1
    while os.path.lexists(candidate):
        candidate = path.with_name(f"{path.stem}.kept{n if n > 1 else ''}{path.suffix}")
        n += 1
    return candidate


def retire(old: Path, out: Path, ours: set[str], recovered: str = "",
           quiet: bool = False) -> bool:
    """Move the user's files from the previous folder ``old`` into ``out`` at the same
    relative places, then remove ``old``; True if it is gone. It is kept (and named in a
    warning) if a file could not be moved. Warns naming the files carried into femmech's
    subfolders and those renamed because the new run wrote the same name, after the note
    ``recovered`` (the recovery of a killed run) if given (if ``quiet``, only when a
    user file was there)."""
    nested, renamed, stuck, moved = [], [], [], 0
    for rel in user_items(old, ours):
        target = _free_name(out / rel)
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            os.rename(old / rel, target)
        except OSError:
            stuck.append(rel)
            continue
        moved += 1
        if target != out / rel:
            renamed.append(f"{rel} -> {target.relative_to(out).as_posix()}")
        elif "/" in rel:
            nested.append(rel)
    if not stuck:
        shutil.rmtree(old, ignore_errors=True)
    notes = [recovered] if recovered and (moved or stuck or not quiet) else []
    if nested:
        notes.append(f"kept your files inside femmech's subfolders: {_listed(nested)}")
    if renamed:
        notes.append(f"the new run wrote files of the same names as yours, kept as:"
                     f" {_listed(renamed)}")
    if stuck:
        notes.append(f"could not move {_listed(stuck)}; the previous folder is left as"
                     f" {old}")
    if notes:
        _warn(out, "; ".join(notes))
    return not os.path.lexists(old)


def _warn(out: Path, text: str) -> None:
    # stacklevel 6: past retire, swap or recover, staged_output and contextlib, to about
    # the with statement of the caller
    warnings.warn(FemmechWarning(f"--out {out}: {text}"), stacklevel=6)


def _listed(paths: list[str], at_most: int = 10) -> str:
    more = len(paths) - at_most
    return ", ".join(paths[:at_most]) + (f" and {more} more" if more > 0 else "")


# --- recovery of killed runs ----------------------------------------------------------

def _tokens(out: Path) -> dict[str, dict[str, Path]]:
    """{token: {kind: path}} of the hidden siblings of ``out``."""
    found: dict[str, dict[str, Path]] = {}
    head = prefix(out)
    for path in out.parent.iterdir():
        if not path.name.startswith(head):
            continue
        kind, _, token = path.name[len(head):].partition("-")
        token = token.removesuffix(".json")
        pid, _, tail = token.partition("-")
        if kind in _KINDS and pid.isdigit() and tail:
            found.setdefault(token, {})[kind] = path
    return found


def recover(out: Path) -> None:
    """Finish or undo the swaps of runs into ``out`` that were killed, and remove their
    staging folders (see the module); siblings of runs that still run are left alone."""
    for token, paths in sorted(_tokens(out).items()):
        fd = _try_lock(paths["lock"]) if "lock" in paths else None
        if fd is False:
            continue  # the run holds its lock: it runs
        if fd is None and _pid_alive(int(token.split("-")[0]), next(iter(paths.values()))):
            if "old" in paths:
                _warn(out, f"{paths['old'].name} holds the previous folder of a run"
                           f" (process {token.split('-')[0]}) that may still be running;"
                           " left in place (if no femmech run writes into this folder,"
                           " your files there are safe to move back)")
            continue
        try:
            _recover_run(out, token)
        finally:
            if fd is not None:
                release_lock(out, token, fd)
            elif "lock" in paths and not (os.path.lexists(sibling(out, "old", token))
                                          or os.path.lexists(sibling(out, "journal", token))):
                paths["lock"].unlink(missing_ok=True)


def _recover_run(out: Path, token: str) -> None:
    old, new = sibling(out, "old", token), sibling(out, "new", token)
    pid = token.split("-")[0]
    journal = _read_journal(sibling(out, "journal", token))
    aside = old.is_dir() and not old.is_symlink()
    ours = journal if journal is not None else (run_files(old) if aside else set())
    if aside:
        if not os.path.lexists(out) and new.is_dir() and journal is not None \
                and (new / MANIFEST).is_file():
            os.rename(new, out)
            retire(old, out, ours, f"a run (process {pid}) was killed while replacing the"
                                   " folder; its new results are put in place and your"
                                   f" files carried over from {old.name} (interrupted"
                                   " swap completed)")
        elif not os.path.lexists(out):
            os.rename(old, out)
            _warn(out, f"a run (process {pid}) was killed during its swap; the previous"
                       f" folder, hidden as {old.name}, is put back (interrupted swap"
                       " recovered)")
        else:
            retire(old, out, ours, f"a run (process {pid}) killed during its swap left the"
                                   f" previous folder as {old.name}; your files still"
                                   " there were moved into the folder (interrupted swap"
                                   " recovered)", quiet=True)
    if new.is_dir() and not new.is_symlink():
        shutil.rmtree(new, ignore_errors=True)
    sibling(out, "jtmp", token).unlink(missing_ok=True)
    if not os.path.lexists(old):
        sibling(out, "journal", token).unlink(missing_ok=True)


def _read_journal(path: Path) -> set[str] | None:
    """The files of the previous run (``ours`` with the manifest) from a swap journal;
    None if there is none or it is damaged (then the previous folder's own manifest
    decides, and a folder holding anything else is never removed)."""
    try:
        data = json.loads(read_regular(path, "swap journal", MAX_MANIFEST_BYTES))
    except (OSError, ValueError):
        return None
    files = data.get("ours") if isinstance(data, dict) else None
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        return None
    return set(files) | {MANIFEST}


def run_files(folder: Path) -> set[str]:
    """Relative paths (POSIX) of the files femmech wrote into ``folder``: its manifest's."""
    return set(read_manifest(folder) or ()) | {MANIFEST}
