"""Old path of :mod:`femmech.fe.elements.shell` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "DRILLING": "femmech.fe.elements.shell.DRILLING",
        "ELEMENT_CHUNK": "femmech.fe.elements.shell.ELEMENT_CHUNK",
        "SHEAR_FACTOR": "femmech.fe.elements.shell.SHEAR_FACTOR",
        "STABILISATION": "femmech.fe.elements.shell.STABILISATION",
        "shell_frames": "femmech.fe.elements.shell.shell_frames",
        "shell_matrices": "femmech.fe.elements.shell.shell_matrices",
    })
