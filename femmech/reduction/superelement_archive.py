"""Old path of the container checks of superelement files (zip members, npy headers,
regular files), now in :mod:`femmech.reduction.superelement_file` (the whole file format
is in that module).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new place."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "CHUNK": "femmech.reduction.superelement_file.CHUNK",
        "DEFLATE_MAX_RATIO": "femmech.reduction.superelement_file.DEFLATE_MAX_RATIO",
        "EXPANSION_FLOOR": "femmech.reduction.superelement_file.EXPANSION_FLOOR",
        "MAX_EXPANSION": "femmech.reduction.superelement_file.MAX_EXPANSION",
        "MAX_HEADER": "femmech.reduction.superelement_file.MAX_HEADER",
        "MAX_META_CHARS": "femmech.reduction.superelement_file.MAX_META_CHARS",
        "ZIP_OVERHEAD": "femmech.reduction.superelement_file.ZIP_OVERHEAD",
        "ZIP_TAIL": "femmech.reduction.superelement_file.ZIP_TAIL",
        "open_regular": "femmech.reduction.superelement_file.open_regular",
        "read_regular": "femmech.reduction.superelement_file.read_regular",
    })
