"""Old path of :mod:`femmech.scene.mechanisms` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "FACTORIES": "femmech.scene.machine.BUILTIN_MODELS",
        "LAWS": "femmech.mechanisms.motion_laws.LAWS",
        "code_error": "femmech.scene.mechanisms.code_error",
        "confined_module": "femmech.scene.mechanisms.confined_module",
        "load_module": "femmech.scene.mechanisms.load_module",
        "mechanism_model": "femmech.scene.mechanisms.mechanism_model",
        "position_function": "femmech.scene.mechanisms.position_function",
    })
