"""Old path of :mod:`femmech.scene.cache` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "CacheInfo": "femmech.scene.cache_folder.CacheInfo",
        "CachedReduction": "femmech.scene.cache.CachedReduction",
        "DEFAULT_MAX_BYTES": "femmech.scene.cache_folder.DEFAULT_MAX_BYTES",
        "LOCK_TIMEOUT": "femmech.scene.cache.LOCK_TIMEOUT",
        "MAX_BYTES_ENV": "femmech.scene.cache_folder.MAX_BYTES_ENV",
        "STALE_AGE": "femmech.scene.cache_folder.STALE_AGE",
        "cache_info": "femmech.scene.cache_folder.cache_info",
        "cache_max_bytes": "femmech.scene.cache_folder.cache_max_bytes",
        "cached_reduction": "femmech.scene.cache.cached_reduction",
        "clear_cache": "femmech.scene.cache_folder.clear_cache",
        "default_cache_dir": "femmech.scene.cache_folder.default_cache_dir",
        "entry_paths": "femmech.scene.cache_folder.entry_paths",
        "format_cache_info": "femmech.scene.cache_folder.format_cache_info",
        "lock_path": "femmech.scene.cache_folder.lock_path",
        "read_entry": "femmech.scene.cache.read_entry",
        "remove_stale_temporaries": "femmech.scene.cache_folder.remove_stale_temporaries",
        "write_entry": "femmech.scene.cache.write_entry",
    })
