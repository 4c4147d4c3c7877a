"""On-disk cache of reductions (superelements), keyed by a hash of what they depend on.

The key is the SHA-256 of everything a reduction depends on
(:func:`femmech.scene.build.reduction_key_data`). The cache folder holds, per key (64 hex
digits), only these files; any other file is foreign and left alone:

``<key>.npz``
    The superelement (:meth:`femmech.reduction.reduce.Superelement.save`).
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
from femmech.reduction.reduce import FORMAT_VERSION, Superelement

LOCK_TIMEOUT = 3600.0
"""Longest wait, s, for another process that holds a key's lock (it is building that
reduction). Then the reduction is built here too, without storing it (CacheWarning)."""

STALE_AGE = 3600.0
"""Age, s, beyond which a temporary file counts as left by a killed run even while its
key's lock is held (a write takes seconds; a writer that holds the lock longer is hung)."""

_LOG = logging.getLogger("femmech.cache")

DEFAULT_MAX_BYTES = 2 * 1024**3
"""Default size limit of the cache folder's entries, bytes (2 GiB)."""

MAX_BYTES_ENV = "FEMMECH_CACHE_MAX_BYTES"
"""Environment variable of the size limit: bytes, or with a suffix K, M, G, T (KiB ...)."""

_KEY = re.compile(r"[0-9a-f]{64}")
_FILES = (("data", re.compile(r"([0-9a-f]{64})\.npz")),
          ("manifest", re.compile(r"([0-9a-f]{64})\.json")),
          ("lock", re.compile(r"([0-9a-f]{64})\.lock")),
          ("temporary", re.compile(r"\.([0-9a-f]{64})\..+")))
_UNITS = {"": 1, "k": 1024, "m": 1024**2, "g": 1024**3, "t": 1024**4}


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


def _why(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}".replace("\n", " ")


def _sha256_file(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def read_entry(folder, key: str) -> tuple[Superelement | None, str | None]:
    """``(superelement, None)`` for a valid entry, ``(None, None)`` if there is none and
    ``(None, reason)`` if it is incomplete, truncated, corrupt, foreign or unreadable."""
    data_path, manifest_path = entry_paths(folder, key)
    try:
        if not data_path.exists() and not manifest_path.exists():
            return None, None
        try:
            manifest = json.loads(manifest_path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            return None, "no manifest (interrupted write)"
        except ValueError as exc:
            return None, f"unreadable manifest ({_why(exc)})"
        if not isinstance(manifest, dict) or manifest.get("key") != key:
            return None, "manifest of another entry (foreign)"
        if not data_path.exists():
            return None, "superelement file missing"
        size = data_path.stat().st_size
        if size != manifest.get("size"):
            return None, f"size {size} bytes, manifest says {manifest.get('size')} (truncated?)"
        if _sha256_file(data_path) != manifest.get("sha256"):
            return None, "checksum mismatch"
        return Superelement.load(data_path), None
    except OSError as exc:
        return None, f"cannot read ({_why(exc)})"
    except (ValueError, LookupError, TypeError, EOFError) as exc:  # rejected by the loader
        return None, f"not a valid superelement file ({_why(exc)})"


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
                    "size": data_path.stat().st_size, "sha256": _sha256_file(data_path),
                    "format": FORMAT_VERSION, "created": time.strftime("%Y-%m-%dT%H:%M:%S")}
        with atomic_path(manifest_path) as tmp:
            tmp.write_text(json.dumps(manifest, indent=1), encoding="utf-8")
    except BaseException:
        _remove(manifest_path, data_path)
        raise
    return data_path


def _remove(*paths: Path) -> int:
    """Unlink the files that exist; the number removed (errors ignored)."""
    count = 0
    for path in paths:
        with suppress(OSError):
            path.unlink()
            count += 1
    return count


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
                evicted = _evict(folder, limit, key)
    seconds = time.perf_counter() - start
    head, action, outcome = _WORDS[status]
    detail = f": {'; '.join(problems)};" if problems else ","
    log(f"{head}: {label} ({short}){detail} {action} in {seconds:.2f} s")
    if evicted[0]:
        log(f"cache evicted: {evicted[0]} least recently used entries ({_size(evicted[1])})"
            f" to stay within {_size(limit)}")
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
    return sum(_remove(path) for key, path, stat in _scan(folder)["temporary"]
               if _is_stale(folder, key, stat))


def _evict(folder: Path, limit: int, keep: str) -> tuple[int, int]:
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
                _remove(*paths)
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
             f" {_size(info.total_bytes)} of"
             f" {_size(info.max_bytes)} (limit; ${MAX_BYTES_ENV})"]
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


def _size(n: float) -> str:
    """Bytes in binary units: ``'1.5 MiB'``."""
    for unit in ("B", "KiB", "MiB"):
        if n < 1024:
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} GiB"
