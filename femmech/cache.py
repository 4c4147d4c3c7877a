"""On-disk cache of reductions (superelements), keyed by a hash of what they depend on.

An entry is two files in the cache folder: ``<key>.npz`` (written by
:meth:`femmech.reduction.Superelement.save`) and ``<key>.json``, a manifest with the
SHA-256 and size of the ``.npz`` file. Both are written atomically (temporary file +
rename), the manifest last, so an interrupted write leaves either no entry or one without
a manifest, which is never trusted. On reading, the checksum is verified and the file
loaded; a missing, truncated or corrupted entry is rebuilt and rewritten. The key is the
SHA-256 of everything the reduction depends on (:func:`femmech.scene_build.reduction_key_data`:
mesh content, materials, sections, interface, settings, femmech version).
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from femmech.output.export import atomic_path
from femmech.reduction import FORMAT_VERSION, Superelement


@dataclass(frozen=True)
class CachedReduction:
    """A superelement and how it was obtained.

    Attributes
    ----------
    superelement : Superelement
    status : str
        ``"hit"``, ``"miss"`` (built and stored), ``"corrupt"`` (entry rejected, rebuilt
        and stored) or ``"off"`` (built, cache not used).
    key : str
        64 hex digits.
    seconds : float
        Time to load or to build, s.
    """

    superelement: Superelement
    status: str
    key: str
    seconds: float


def default_cache_dir() -> Path:
    """``$FEMMECH_CACHE_DIR``, else ``$XDG_CACHE_HOME/femmech``, else ``~/.cache/femmech``."""
    if os.environ.get("FEMMECH_CACHE_DIR"):
        return Path(os.environ["FEMMECH_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "femmech"


def entry_paths(folder, key: str) -> tuple[Path, Path]:
    """(superelement file, manifest) of the entry ``key``."""
    folder = Path(folder)
    return folder / f"{key}.npz", folder / f"{key}.json"


def _sha256_file(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def read_entry(folder, key: str) -> tuple[Superelement | None, str | None]:
    """``(superelement, None)`` for a valid entry, ``(None, None)`` if there is none and
    ``(None, reason)`` if it is incomplete, truncated or corrupt."""
    data_path, manifest_path = entry_paths(folder, key)
    if not data_path.exists() and not manifest_path.exists():
        return None, None
    try:
        manifest = json.loads(manifest_path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None, "no manifest (interrupted write)"
    except (OSError, ValueError) as exc:
        return None, f"unreadable manifest ({exc})"
    if not isinstance(manifest, dict) or manifest.get("key") != key:
        return None, "manifest of another entry"
    if not data_path.exists():
        return None, "superelement file missing"
    if data_path.stat().st_size != manifest.get("size"):
        return None, (f"size {data_path.stat().st_size} bytes, manifest says"
                      f" {manifest.get('size')} (truncated?)")
    if _sha256_file(data_path) != manifest.get("sha256"):
        return None, "checksum mismatch"
    try:
        return Superelement.load(data_path), None
    except ValueError as exc:
        return None, str(exc)


def write_entry(folder, key: str, se: Superelement, label: str) -> Path:
    """Store ``se`` under ``key`` (atomically: data first, manifest last)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    data_path, manifest_path = entry_paths(folder, key)
    manifest_path.unlink(missing_ok=True)  # an old manifest must not vouch for new data
    se.save(data_path)
    manifest = {"key": key, "label": label, "file": data_path.name,
                "size": data_path.stat().st_size, "sha256": _sha256_file(data_path),
                "format": FORMAT_VERSION, "created": time.strftime("%Y-%m-%dT%H:%M:%S")}
    with atomic_path(manifest_path) as tmp:
        tmp.write_text(json.dumps(manifest, indent=1), encoding="utf-8")
    return data_path


def cached_reduction(folder, key: str, label: str, build: Callable[[], Superelement],
                     log: Callable[[str], None] = print) -> CachedReduction:
    """Load the reduction ``key`` from ``folder`` or build and store it; logs one line:
    ``cache hit``, ``cache miss`` or ``cache corrupt, rebuilt`` with ``label`` and the key.

    ``folder=None`` turns the cache off (always builds, logs ``cache off``).
    """
    start = time.perf_counter()
    short = key[:12]
    if folder is None:
        se = build()
        seconds = time.perf_counter() - start
        log(f"cache off: {label} ({short}), reduced in {seconds:.2f} s")
        return CachedReduction(se, "off", key, seconds)
    se, problem = read_entry(folder, key)
    if se is not None:
        seconds = time.perf_counter() - start
        log(f"cache hit: {label} ({short}), loaded in {seconds:.2f} s")
        return CachedReduction(se, "hit", key, seconds)
    se = build()
    write_entry(folder, key, se, label)
    seconds = time.perf_counter() - start
    if problem is None:
        log(f"cache miss: {label} ({short}), reduced and stored in {seconds:.2f} s")
        return CachedReduction(se, "miss", key, seconds)
    log(f"cache corrupt, rebuilt: {label} ({short}): {problem}; reduced and stored in"
        f" {seconds:.2f} s")
    return CachedReduction(se, "corrupt", key, seconds)
