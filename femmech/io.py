"""Old path of :mod:`femmech.fe.mesh_io` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "MAX_MESH_FILE_BYTES": "femmech.fe.mesh_io.MAX_MESH_FILE_BYTES",
        "from_meshio": "femmech.fe.mesh_io.from_meshio",
        "read_mesh": "femmech.fe.mesh_io.read_mesh",
    })
