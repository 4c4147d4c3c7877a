"""Old path of :mod:`femmech.fe.elements.solid` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "CHUNK_ENTRIES": "femmech.fe.elements.solid.CHUNK_ENTRIES",
        "REFERENCE_NODES": "femmech.fe.elements.solid.REFERENCE_NODES",
        "SOLID_TYPES": "femmech.fe.elements.solid.SOLID_TYPES",
        "assemble_solid": "femmech.fe.elements.solid.assemble_solid",
        "reference_element": "femmech.fe.elements.solid.reference_element",
        "solid_dofs": "femmech.fe.elements.solid.solid_dofs",
        "solid_matrices": "femmech.fe.elements.solid.solid_matrices",
    })
