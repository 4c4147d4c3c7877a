"""Old path of :mod:`femmech.fe.lumped` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "PointMass": "femmech.fe.lumped.PointMass",
        "Spring": "femmech.fe.lumped.Spring",
    })
