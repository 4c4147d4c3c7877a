"""Old path of :mod:`femmech.reduction.superelement_file` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "ARRAYS": "femmech.reduction.superelement_file.ARRAYS",
        "CHUNK": "femmech.reduction.superelement_file.CHUNK",
        "DEFLATE_MAX_RATIO": "femmech.reduction.superelement_file.DEFLATE_MAX_RATIO",
        "EXPANSION_FLOOR": "femmech.reduction.superelement_file.EXPANSION_FLOOR",
        "FIELDS": "femmech.reduction.superelement_file.FIELDS",
        "FLOATS": "femmech.reduction.superelement_file.FLOATS",
        "FORMAT_VERSION": "femmech.reduction.superelement_file.FORMAT_VERSION",
        "INDICES": "femmech.reduction.superelement_file.INDICES",
        "MAX_EXPANSION": "femmech.reduction.superelement_file.MAX_EXPANSION",
        "MAX_HEADER": "femmech.reduction.superelement_file.MAX_HEADER",
        "MAX_META_CHARS": "femmech.reduction.superelement_file.MAX_META_CHARS",
        "MAX_TIMINGS": "femmech.reduction.superelement_file.MAX_TIMINGS",
        "METHODS": "femmech.reduction.superelement_file.METHODS",
        "PSD_RTOL": "femmech.reduction.superelement_file.PSD_RTOL",
        "READABLE_VERSIONS": "femmech.reduction.superelement_file.READABLE_VERSIONS",
        "SYMMETRY_RTOL": "femmech.reduction.superelement_file.SYMMETRY_RTOL",
        "checksums": "femmech.reduction.superelement_file.checksums",
        "field_digest": "femmech.reduction.superelement_file.field_digest",
        "meta_digest": "femmech.reduction.superelement_file.meta_digest",
        "read": "femmech.reduction.superelement_file.read",
        "write": "femmech.reduction.superelement_file.write",
    })
