"""Old path of :mod:`femmech.fe.dofs` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "COMPONENTS": "femmech.fe.dofs.COMPONENTS",
        "DOF_PER_NODE": "femmech.fe.dofs.DOF_PER_NODE",
        "components": "femmech.fe.dofs.components",
        "dof_label": "femmech.fe.dofs.dof_label",
        "element_dofs": "femmech.fe.dofs.element_dofs",
        "node_dofs": "femmech.fe.dofs.node_dofs",
    })
