"""Old path of :mod:`femmech.fe.constraints` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "EquationSet": "femmech.fe.constraints.EquationSet",
        "InterpolatingLink": "femmech.fe.constraints.InterpolatingLink",
        "RigidLink": "femmech.fe.constraints.RigidLink",
        "Support": "femmech.fe.constraints.Support",
        "add_interpolating_link": "femmech.fe.constraints.add_interpolating_link",
        "add_rigid_links": "femmech.fe.constraints.add_rigid_links",
        "constraint_transform": "femmech.fe.constraints.constraint_transform",
        "fixed_mask": "femmech.fe.constraints.fixed_mask",
        "interpolation_matrix": "femmech.fe.constraints.interpolation_matrix",
        "rigid_link_matrix": "femmech.fe.constraints.rigid_link_matrix",
    })
