"""Old path of :mod:`femmech.reduction.superelement_file` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "ARRAYS": "femmech.reduction.superelement_format.ARRAYS",
        "CHUNK": "femmech.reduction.superelement_archive.CHUNK",
        "DEFLATE_MAX_RATIO": "femmech.reduction.superelement_archive.DEFLATE_MAX_RATIO",
        "EXPANSION_FLOOR": "femmech.reduction.superelement_archive.EXPANSION_FLOOR",
        "FIELDS": "femmech.reduction.superelement_format.FIELDS",
        "FLOATS": "femmech.reduction.superelement_format.FLOATS",
        "FORMAT_VERSION": "femmech.reduction.superelement_format.FORMAT_VERSION",
        "INDICES": "femmech.reduction.superelement_format.INDICES",
        "MAX_EXPANSION": "femmech.reduction.superelement_archive.MAX_EXPANSION",
        "MAX_HEADER": "femmech.reduction.superelement_archive.MAX_HEADER",
        "MAX_META_CHARS": "femmech.reduction.superelement_archive.MAX_META_CHARS",
        "MAX_TIMINGS": "femmech.reduction.superelement_checks.MAX_TIMINGS",
        "METHODS": "femmech.reduction.superelement_format.METHODS",
        "PSD_RTOL": "femmech.reduction.superelement_checks.PSD_RTOL",
        "READABLE_VERSIONS": "femmech.reduction.superelement_format.READABLE_VERSIONS",
        "SYMMETRY_RTOL": "femmech.reduction.superelement_checks.SYMMETRY_RTOL",
        "checksums": "femmech.reduction.superelement_format.checksums",
        "field_digest": "femmech.reduction.superelement_format.field_digest",
        "meta_digest": "femmech.reduction.superelement_format.meta_digest",
        "read": "femmech.reduction.superelement_file.read",
        "write": "femmech.reduction.superelement_file.write",
    })
