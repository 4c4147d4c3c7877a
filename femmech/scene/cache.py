"""Stage 8: on-disk cache of reductions (superelements), keyed by a hash of what they depend on.

The key is the SHA-256 of everything a reduction depends on
(:func:`femmech.scene.build.reduction_key_data`). An entry is the superelement file, its
manifest and its lock file in the cache folder (:mod:`femmech.scene.cache_folder`
describes the files and manages the folder: size limit, eviction, info, clear).

Guarantees of :func:`cached_reduction`:

* Trusted only when checked: an entry is used only if its manifest names its key and the
  size, SHA-256 and the loader's validation of the ``.npz`` file agree. Both files are
  written by atomic renames, data first and manifest last; a failed write removes both.
* Never breaks a run: a cache that cannot be read or written (read-only or full folder,
  the folder path a file, a corrupt or foreign entry, a lock that cannot be taken) gives
  one :class:`~femmech.errors.CacheWarning` and a log line, and the freshly built
  superelement is returned. Only errors of ``build`` itself propagate.
* Built once: the key's lock is held while the entry is checked, built and written, so
  a second process asking for the same key waits and then loads the entry. After
  :data:`LOCK_TIMEOUT` it builds without storing.
* Bounded: after each write the least recently used entries are evicted until the
  folder holds at most :func:`cache_max_bytes` (the entry just written is kept).
* Self-cleaning: temporaries of killed runs go when the cache is next used.

Imports :mod:`femmech.errors`, :mod:`femmech.output` (atomic writes),
:mod:`femmech.reduction` and :mod:`femmech.scene.cache_folder`.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import re
import time
import warnings
from collections.abc import Callable
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from pathlib import Path

from filelock import FileLock, Timeout

from femmech.errors import CacheWarning
from femmech.output.export import atomic_path
from femmech.reduction.superelement import FORMAT_VERSION, Superelement
from femmech.reduction.superelement_file import open_regular, read_regular
from femmech.scene.cache_folder import (
    cache_max_bytes,
    entry_paths,
    evict,
    format_size,
    lock_path,
    remove,
    remove_stale_temporaries,
)

LOCK_TIMEOUT = 3600.0
"""Longest wait, s, for another process that holds a key's lock (it is building that
reduction). Then the reduction is built here too, without storing it (CacheWarning)."""

_LOG = logging.getLogger("femmech.cache")
_KEY = re.compile(r"[0-9a-f]{64}")


@dataclass(frozen=True)
class CachedReduction:
    """A superelement and how it was obtained.

    Attributes
    ----------
    superelement : Superelement
    status : str
        ``"hit"``, ``"miss"`` (built and stored), ``"corrupt"`` (entry rejected, rebuilt
        and stored), ``"unstored"`` (built, not stored) or ``"off"`` (cache not used).
    key : str
        64 hex digits.
    seconds : float
        Time to load or to build, s.
    """

    superelement: Superelement
    status: str
    key: str
    seconds: float


def _why(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}".replace("\n", " ")


MAX_MANIFEST = 1 << 20
"""Largest manifest read, bytes (a manifest holds a few hundred)."""


def sha256_file(path: Path, size: int | None = None) -> str:
    """SHA-256 hex of the cache entry ``path``, a regular file (not a link to one) of
    ``size`` bytes if given (else FileFormatError naming the sizes). A FIFO, a device, a
    directory or a link in its place: FileFormatError (:func:`open_regular`)."""
    digest = hashlib.sha256()
    with open_regular(path, "cache entry", follow_links=False) as stream:
        found = os.fstat(stream.fileno()).st_size
        if size is not None and found != size:
            raise _SizeMismatchError(f"size {found} bytes, manifest says {size}"
                                     f" ({'truncated' if found < size else 'appended to'}?)")
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


class _SizeMismatchError(Exception):
    """The entry's size (of the open file) differs from its manifest's."""


def read_entry(folder, key: str) -> tuple[Superelement | None, str | None]:
    """``(superelement, None)`` for a valid entry, ``(None, None)`` if there is none and
    ``(None, reason)`` if it is incomplete, truncated, corrupt, foreign or unreadable.

    Both files must be regular files, not symbolic links (a link in the cache folder
    could point anywhere; the folder itself may be a link): anything else is a damaged
    entry, read no further than the manifest's :data:`MAX_MANIFEST` bytes and the size
    the manifest gives."""
    data_path, manifest_path = entry_paths(folder, key)
    try:
        if not os.path.lexists(data_path) and not os.path.lexists(manifest_path):
            return None, None
        try:
            manifest = json.loads(_read_manifest(manifest_path))
        except FileNotFoundError:
            return None, "no manifest (interrupted write)"
        except ValueError as exc:  # FileFormatError too: a FIFO, a device, a link, too large
            return None, f"unreadable manifest ({_why(exc)})"
        if not isinstance(manifest, dict) or manifest.get("key") != key:
            return None, "manifest of another entry (foreign)"
        size = manifest.get("size")
        if not isinstance(size, int) or isinstance(size, bool):
            return None, f"unreadable manifest (size {size!r}, expected bytes)"
        try:
            digest = sha256_file(data_path, size)
        except FileNotFoundError:
            return None, "superelement file missing"
        except _SizeMismatchError as exc:
            return None, str(exc)
        if digest != manifest.get("sha256"):
            return None, "checksum mismatch"
        return Superelement.load(data_path), None
    except OSError as exc:
        return None, f"cannot read ({_why(exc)})"
    except (ValueError, LookupError, TypeError, EOFError) as exc:  # rejected by the loader
        return None, f"not a valid superelement file ({_why(exc)})"


def _read_manifest(path: Path) -> str:
    """The manifest's text, from a regular file (no link) of at most :data:`MAX_MANIFEST`
    bytes."""
    return read_regular(path, "cache manifest", MAX_MANIFEST).decode("utf-8")


def write_entry(folder, key: str, se: Superelement, label: str) -> Path:
    """Store ``se`` under ``key`` (atomically: data first, manifest last).

    Raises OSError if the folder cannot be written (read-only, full); then neither part
    of the entry nor a temporary file is left behind.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    data_path, manifest_path = entry_paths(folder, key)
    try:
        manifest_path.unlink(missing_ok=True)  # an old manifest must not vouch for new data
        se.save(data_path)
        manifest = {"key": key, "label": label, "file": data_path.name,
                    "size": data_path.stat().st_size, "sha256": sha256_file(data_path),
                    "format": FORMAT_VERSION, "created": time.strftime("%Y-%m-%dT%H:%M:%S")}
        with atomic_path(manifest_path) as tmp:
            tmp.write_text(json.dumps(manifest, indent=1), encoding="utf-8")
    except BaseException:
        remove(manifest_path, data_path)
        raise
    return data_path


def cached_reduction(folder, key: str, label: str, build: Callable[[], Superelement],
                     log: Callable[[str], None] | None = None, max_bytes: int | None = None,
                     lock_timeout: float = LOCK_TIMEOUT) -> CachedReduction:
    """Load the reduction ``key`` from ``folder`` or build and store it.

    Logs one line: ``cache hit``, ``cache miss``, ``cache corrupt, rebuilt``, ``cache not
    stored`` or ``cache off`` (``folder=None``: always builds), with ``label`` and the key;
    and ``cache evicted`` when the write pushed out old entries (limit ``max_bytes``, see
    :func:`cache_max_bytes`). Every problem with the cache also gives one CacheWarning
    naming the folder, the entry and the problem; the run goes on with the result of
    ``build``. Waits up to ``lock_timeout`` s for another process building the same key.
    """
    log = log or _LOG.info
    start = time.perf_counter()
    short = key[:12]
    if folder is None:
        se = build()
        seconds = time.perf_counter() - start
        log(f"cache off: {label} ({short}), reduced in {seconds:.2f} s")
        return CachedReduction(se, "off", key, seconds)
    if not _KEY.fullmatch(key):
        raise ValueError(f"cache key: expected 64 lowercase hex digits, got {key!r}")
    folder = Path(folder)
    limit = cache_max_bytes(max_bytes)
    problems: list[str] = []
    evicted = (0, 0)
    with _session(folder, key, lock_timeout, problems) as state:
        se, rejected = read_entry(folder, key) if state in ("held", "unlocked") else (None, None)
        if se is not None:
            with suppress(OSError):  # last use, for eviction
                os.utime(entry_paths(folder, key)[1])
            status = "hit"
        else:
            if rejected is not None:
                problems.insert(0, rejected)
            se = build()
            stored = state in ("held", "unlocked") and _store(folder, key, se, label, problems)
            status = ("corrupt" if rejected else "miss") if stored else "unstored"
            if stored:
                evicted = evict(folder, limit, key)
    seconds = time.perf_counter() - start
    head, action, outcome = _WORDS[status]
    detail = f": {'; '.join(problems)};" if problems else ","
    log(f"{head}: {label} ({short}){detail} {action} in {seconds:.2f} s")
    if evicted[0]:
        log(f"cache evicted: {evicted[0]} least recently used entries ({format_size(evicted[1])})"
            f" to stay within {format_size(limit)}")
    if problems:
        warnings.warn(f"reduction cache {folder}: entry {short} ({label}):"
                      f" {'; '.join(problems)}; {outcome}", CacheWarning, stacklevel=2)
    return CachedReduction(se, status, key, seconds)


_WORDS = {"hit": ("cache hit", "loaded", "loaded"),
          "miss": ("cache miss", "reduced and stored", "recomputed and stored"),
          "corrupt": ("cache corrupt, rebuilt", "reduced and stored", "recomputed and stored"),
          "unstored": ("cache not stored", "reduced", "recomputed, not stored")}
"""Per status: the log line's head, its action and the warning's outcome."""


@contextmanager
def _session(folder: Path, key: str, timeout: float, problems: list):
    """Open the cache and hold the key's lock around a lookup.

    Yields ``"held"``; ``"unlocked"`` if the lock file cannot be made (read-only folder:
    go on without); ``"busy"`` if another process held the lock for ``timeout`` s (build,
    do not store); ``"unusable"`` if the folder cannot be created. Problems are appended.
    """
    lock, state = FileLock(lock_path(folder, key), timeout=timeout), "held"
    try:
        folder.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(folder)
    except OSError as exc:
        state = "unusable"
        problems.append(f"cannot create the folder ({_why(exc)})")
    else:
        try:
            lock.acquire()
        except Timeout:
            state = "busy"
            problems.append(f"{lock_path(folder, key).name} held by another process for more"
                            f" than {timeout:g} s (LOCK_TIMEOUT)")
        except (OSError, NotImplementedError) as exc:  # old filelock: no flock on this disk
            state = "unlocked"
            problems.append(f"cannot lock, going on without ({_why(exc)})")
    try:
        yield state
    finally:
        if state == "held":
            lock.release()


def _store(folder: Path, key: str, se: Superelement, label: str, problems: list) -> bool:
    """:func:`write_entry`; False with a problem noted if the folder cannot be written."""
    try:
        write_entry(folder, key, se, label)
    except OSError as exc:
        problems.append(f"cannot store ({_why(exc)})")
        return False
    return True


def __getattr__(name: str):
    """Names this module had before the restructures, from their new places
    (docs/architecture.md, "Moved names")."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "CacheInfo": "femmech.scene.cache_folder.CacheInfo",
        "DEFAULT_MAX_BYTES": "femmech.scene.cache_folder.DEFAULT_MAX_BYTES",
        "MAX_BYTES_ENV": "femmech.scene.cache_folder.MAX_BYTES_ENV",
        "STALE_AGE": "femmech.scene.cache_folder.STALE_AGE",
        "cache_info": "femmech.scene.cache_folder.cache_info",
        "clear_cache": "femmech.scene.cache_folder.clear_cache",
        "default_cache_dir": "femmech.scene.cache_folder.default_cache_dir",
        "format_cache_info": "femmech.scene.cache_folder.format_cache_info",
    })
