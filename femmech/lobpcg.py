"""Old path of :mod:`femmech.solve.lobpcg` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "DOF_PER_NODE": "femmech.fe.dofs.DOF_PER_NODE",
        "amg_preconditioner": "femmech.solve.lobpcg.amg_preconditioner",
        "lobpcg_symmetric": "femmech.solve.lobpcg.lobpcg_symmetric",
        "near_nullspace": "femmech.fe.nullspace.near_nullspace",
        "node_blocksize": "femmech.fe.nullspace.node_blocksize",
        "rigid_body_modes": "femmech.fe.nullspace.rigid_body_modes",
    })
