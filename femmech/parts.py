"""Old path of :mod:`femmech.fe.parts` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "ShellProperty": "femmech.fe.parts.ShellProperty",
        "ShellSet": "femmech.fe.parts.ShellSet",
        "SolidProperty": "femmech.fe.parts.SolidProperty",
        "SolidSet": "femmech.fe.parts.SolidSet",
        "check_part_types": "femmech.fe.parts.check_part_types",
        "shell_blocks": "femmech.fe.parts.shell_blocks",
        "solid_parts": "femmech.fe.parts.solid_parts",
    }, removed={
        "SHELL_TYPES": "use femmech.fe.elements.registry.kinds('shell')",
    })
