"""Stage 8: the folder of the reduction cache: its files, stale temporaries, size, eviction.

The cache folder holds, per key (64 hex digits), only these files; any other file is
foreign and left alone:

``<key>.npz``
    The superelement (:meth:`femmech.reduction.superelement.Superelement.save`).
``<key>.json``
    Its manifest: key, size and SHA-256 of the ``.npz`` file. The manifest's
    modification time is the entry's last use (set again on every hit).
``<key>.lock``
    The key's lock file (:mod:`filelock`: ``flock`` on POSIX). Empty; it stays (unlinking
    a lock file that another process may be waiting on would split the lock), only
    :func:`clear_cache` removes it.
``.<key>.*``
    Temporary files of a write in progress (``Superelement.save`` and
    :func:`femmech.output.export.atomic_path` name theirs so).

This module knows these names and manages the folder: where it is
(:func:`default_cache_dir`), its size limit (:func:`cache_max_bytes`), the removal of
temporaries of killed runs, the eviction of least recently used entries, and
``femmech cache info`` / ``clear`` (:func:`cache_info`, :func:`clear_cache`). Reading and
writing an entry under its lock is :mod:`femmech.scene.cache`.

Imports :mod:`femmech.errors`; never the rest of the scene package.
"""

from __future__ import annotations

import os
import re
import time
import warnings
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from pathlib import Path

from filelock import FileLock, Timeout

from femmech.errors import CacheWarning

STALE_AGE = 3600.0
"""Age, s, beyond which a temporary file counts as left by a killed run even while its
key's lock is held (a write takes seconds; a writer that holds the lock longer is hung)."""

DEFAULT_MAX_BYTES = 2 * 1024**3
"""Default size limit of the cache folder's entries, bytes (2 GiB)."""

MAX_BYTES_ENV = "FEMMECH_CACHE_MAX_BYTES"
"""Environment variable of the size limit: bytes, or with a suffix K, M, G, T (KiB ...)."""

_FILES = (("data", re.compile(r"([0-9a-f]{64})\.npz")),
          ("manifest", re.compile(r"([0-9a-f]{64})\.json")),
          ("lock", re.compile(r"([0-9a-f]{64})\.lock")),
          ("temporary", re.compile(r"\.([0-9a-f]{64})\..+")))
_UNITS = {"": 1, "k": 1024, "m": 1024**2, "g": 1024**3, "t": 1024**4}


@dataclass(frozen=True)
class CacheInfo:
    """State of a cache folder (:func:`cache_info`).

    Attributes
    ----------
    folder : Path
    entries : int
        Complete entries (with a manifest).
    incomplete : int
        Superelement files without a manifest (interrupted writes).
    total_bytes, max_bytes : int
        Size of all entries, complete or not, and the limit (:func:`cache_max_bytes`).
    oldest_use, newest_use : float or None
        Last use of the least and of the most recently used entry, s since the epoch.
    stale_temporaries : int
        Temporary files left by killed runs (:func:`remove_stale_temporaries`).
    foreign_files : int
        Files and folders that are not femmech's (never removed).
    """

    folder: Path
    entries: int
    incomplete: int
    total_bytes: int
    max_bytes: int
    oldest_use: float | None
    newest_use: float | None
    stale_temporaries: int
    foreign_files: int


def default_cache_dir() -> Path:
    """``$FEMMECH_CACHE_DIR``, else ``$XDG_CACHE_HOME/femmech``, else ``~/.cache/femmech``."""
    if os.environ.get("FEMMECH_CACHE_DIR"):
        return Path(os.environ["FEMMECH_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "femmech"


def cache_max_bytes(max_bytes: int | None = None) -> int:
    """The size limit, bytes: ``max_bytes``, else ``$FEMMECH_CACHE_MAX_BYTES``, else
    :data:`DEFAULT_MAX_BYTES`. An unreadable variable gives a CacheWarning and the default.

    >>> cache_max_bytes(1000)
    1000
    """
    if max_bytes is not None:
        if int(max_bytes) < 0:
            raise ValueError(f"max_bytes must be >= 0, got {max_bytes}")
        return int(max_bytes)
    text = os.environ.get(MAX_BYTES_ENV, "").strip()
    if not text:
        return DEFAULT_MAX_BYTES
    match = re.fullmatch(r"(\d+)\s*(?:([kmgt])(?:i?b)?)?", text.lower())
    if match is None:
        warnings.warn(f"${MAX_BYTES_ENV}={text!r}: expected bytes, e.g. 2147483648 or 2G;"
                      f" using {DEFAULT_MAX_BYTES}", CacheWarning, stacklevel=2)
        return DEFAULT_MAX_BYTES
    return int(match[1]) * _UNITS[match[2] or ""]


def entry_paths(folder, key: str) -> tuple[Path, Path]:
    """(superelement file, manifest) of the entry ``key``."""
    folder = Path(folder)
    return folder / f"{key}.npz", folder / f"{key}.json"


def lock_path(folder, key: str) -> Path:
    """The lock file of the entry ``key``."""
    return Path(folder) / f"{key}.lock"


def remove(*paths: Path) -> int:
    """Unlink the files that exist; the number removed (errors ignored)."""
    count = 0
    for path in paths:
        with suppress(OSError):
            path.unlink()
            count += 1
    return count


@contextmanager
def _if_free(folder: Path, key: str, strict: bool = False):
    """Hold the key's lock if no process holds it now: yields True, or False if another
    process holds it or (unless ``strict``: OSError) the lock cannot be taken. Never waits."""
    lock = FileLock(lock_path(folder, key), timeout=0)
    try:
        lock.acquire()
    except Timeout:
        free = False
    except (OSError, NotImplementedError):
        if strict:
            raise
        free = False
    else:
        free = True
    try:
        yield free
    finally:
        if free:
            lock.release()


def _scan(folder: Path) -> dict[str, list]:
    """The folder's files by kind (data, manifest, lock, temporary, foreign) as lists of
    ``(key, path, stat)``; empty if the folder cannot be listed."""
    found = {kind: [] for kind, _ in _FILES} | {"foreign": []}
    try:
        items = list(os.scandir(folder))
    except OSError:
        return found
    for item in items:
        try:
            stat = item.stat(follow_symlinks=False)
            regular = item.is_file(follow_symlinks=False)
        except OSError:
            continue
        kind, key = "foreign", None
        for name, pattern in _FILES:
            match = pattern.fullmatch(item.name)
            if regular and match:
                kind, key = name, match[1]
                break
        found[kind].append((key, Path(item.path), stat))
    return found


def _entries(found: dict) -> dict[str, tuple[int, float, bool]]:
    """{key: (bytes, last use, complete)} of the entries in a :func:`_scan` result."""
    out: dict[str, tuple[int, float, bool]] = {}
    for kind in ("data", "manifest"):
        for key, _, stat in found[kind]:
            size, used, complete = out.get(key, (0, stat.st_mtime, False))
            out[key] = (size + stat.st_size, stat.st_mtime if kind == "manifest" else used,
                        complete or kind == "manifest")
    return out


def _is_stale(folder: Path, key: str, stat) -> bool:
    """A temporary is stale if older than STALE_AGE or if no process holds its key's lock
    (a writer holds the lock while its temporaries exist). Never creates a lock file."""
    if time.time() - stat.st_mtime > STALE_AGE or not lock_path(folder, key).exists():
        return True
    with _if_free(folder, key) as free:
        return free


def remove_stale_temporaries(folder) -> int:
    """Remove the temporary files of killed runs (see :func:`_is_stale`); the number
    removed. Temporaries of a write in progress in another process are kept."""
    folder = Path(folder)
    return sum(remove(path) for key, path, stat in _scan(folder)["temporary"]
               if _is_stale(folder, key, stat))


def evict(folder: Path, limit: int, keep: str) -> tuple[int, int]:
    """Remove least recently used entries (not ``keep``, not locked by another process)
    until the entries total at most ``limit`` bytes; (entries removed, bytes freed)."""
    entries = _entries(_scan(folder))
    total = sum(size for size, _, _ in entries.values())
    count = freed = 0
    for key, (size, _, _) in sorted(entries.items(), key=lambda item: item[1][1]):
        if total - freed <= limit:
            break
        if key == keep:
            continue
        paths = entry_paths(folder, key)[::-1]  # the manifest first
        with _if_free(folder, key) as free:
            if free:
                remove(*paths)
        if free and not any(path.exists() for path in paths):
            count, freed = count + 1, freed + size
    return count, freed


def cache_info(folder, max_bytes: int | None = None) -> CacheInfo:
    """Entries, size, last uses, stale temporaries and foreign files of a cache folder."""
    folder = Path(folder)
    found = _scan(folder)
    entries = _entries(found)
    uses = [used for _, used, complete in entries.values() if complete]
    stale = sum(_is_stale(folder, key, stat) for key, _, stat in found["temporary"])
    n_complete = sum(complete for _, _, complete in entries.values())
    return CacheInfo(folder, n_complete, len(entries) - n_complete,
                     sum(size for size, _, _ in entries.values()), cache_max_bytes(max_bytes),
                     min(uses, default=None), max(uses, default=None), stale,
                     len(found["foreign"]))


def format_cache_info(info: CacheInfo) -> str:
    """A few lines describing :func:`cache_info`'s result, for ``femmech cache info``."""
    def when(t):
        return time.strftime("%Y-%m-%d %H:%M", time.localtime(t))

    lines = [f"reduction cache {info.folder}",
             f"  {info.entries} {'entry' if info.entries == 1 else 'entries'},"
             f" {format_size(info.total_bytes)} of"
             f" {format_size(info.max_bytes)} (limit; ${MAX_BYTES_ENV})"]
    if info.oldest_use is not None:
        lines.append(f"  last used: oldest {when(info.oldest_use)}, newest"
                     f" {when(info.newest_use)}")
    if info.incomplete or info.stale_temporaries:
        lines.append(f"  {info.incomplete} incomplete entries (interrupted writes),"
                     f" {info.stale_temporaries} temporary files of killed runs")
    if info.foreign_files:
        lines.append(f"  {info.foreign_files} other files (not femmech's, left alone)")
    return "\n".join(lines)


def clear_cache(folder) -> int:
    """Remove all entries, temporaries and lock files of a cache folder; the number of
    files removed. Foreign files and the entries that another process is using (whose
    lock it holds) are left alone.

    Raises OSError if a file of femmech's cannot be removed (read-only folder).
    """
    folder = Path(folder)
    found = _scan(folder)
    files: dict[str, list[Path]] = {}
    for kind in ("manifest", "data", "temporary", "lock"):
        for key, path, _ in found[kind]:
            files.setdefault(key, []).append(path)
    count = 0
    for key, paths in sorted(files.items()):
        with _if_free(folder, key, strict=True) as free:
            if free:
                for path in paths:
                    path.unlink(missing_ok=True)
                lock_path(folder, key).unlink(missing_ok=True)  # unlinked while held
                count += len(paths)
    return count


def format_size(n: float) -> str:
    """Bytes in binary units: ``'1.5 MiB'``."""
    for unit in ("B", "KiB", "MiB"):
        if n < 1024:
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} GiB"
