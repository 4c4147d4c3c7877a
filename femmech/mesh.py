"""Old path of :mod:`femmech.fe.mesh` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "MAX_CELLS": "femmech.fe.mesh.MAX_CELLS",
        "MAX_NODES": "femmech.fe.mesh.MAX_NODES",
        "Mesh": "femmech.fe.mesh.Mesh",
        "NODES_PER_CELL": "femmech.fe.mesh.NODES_PER_CELL",
        "line_submesh": "femmech.fe.mesh.line_submesh",
        "merged_node_index": "femmech.fe.mesh.merged_node_index",
    })
