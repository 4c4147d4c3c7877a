"""Old path of :mod:`femmech.reduction.substructures` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "Assembly": "femmech.reduction.substructures.Assembly",
        "assemble_parts": "femmech.reduction.substructures.assemble_parts",
    })
