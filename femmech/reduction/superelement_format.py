"""Old path of the fields, checksums and messages of superelement files, now in
:mod:`femmech.reduction.superelement_file` (the whole file format is in that module).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new place."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "ARRAYS": "femmech.reduction.superelement_file.ARRAYS",
        "FIELDS": "femmech.reduction.superelement_file.FIELDS",
        "FLOATS": "femmech.reduction.superelement_file.FLOATS",
        "FORMAT_VERSION": "femmech.reduction.superelement_file.FORMAT_VERSION",
        "INDICES": "femmech.reduction.superelement_file.INDICES",
        "METHODS": "femmech.reduction.superelement_file.METHODS",
        "READABLE_VERSIONS": "femmech.reduction.superelement_file.READABLE_VERSIONS",
        "checksums": "femmech.reduction.superelement_file.checksums",
        "field_digest": "femmech.reduction.superelement_file.field_digest",
        "meta_digest": "femmech.reduction.superelement_file.meta_digest",
    })
