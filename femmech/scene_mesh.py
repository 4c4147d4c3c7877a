"""Old path of :mod:`femmech.scene.mesh` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "GENERATORS": "femmech.scene.mesh.GENERATORS",
        "MAX_BAYS": "femmech.scene.mesh.MAX_BAYS",
        "MAX_SUBDIVISIONS": "femmech.scene.mesh.MAX_SUBDIVISIONS",
        "MeshSpec": "femmech.scene.mesh.MeshSpec",
        "read_mesh_spec": "femmech.scene.mesh.read_mesh_spec",
    })
