"""Old path of :mod:`femmech.scene.machine` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "AttachmentSpec": "femmech.scene.machine.AttachmentSpec",
        "BUILTIN_MODELS": "femmech.scene.machine.BUILTIN_MODELS",
        "MOTION_LAWS": "femmech.scene.machine.MOTION_LAWS",
        "MechanismSpec": "femmech.scene.machine.MechanismSpec",
        "MountSpec": "femmech.scene.machine.MountSpec",
        "POSITION_KINDS": "femmech.scene.machine.POSITION_KINDS",
        "PositionSpec": "femmech.scene.machine.PositionSpec",
        "parameter_kinds": "femmech.scene.machine.parameter_kinds",
        "read_mechanisms": "femmech.scene.machine.read_mechanisms",
        "read_mounts": "femmech.scene.machine.read_mounts",
    })
