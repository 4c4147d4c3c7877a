"""Old path of :mod:`femmech.scene.reader` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "MAX_DEPTH": "femmech.scene.reader.MAX_DEPTH",
        "MAX_KEY_LENGTH": "femmech.scene.reader.MAX_KEY_LENGTH",
        "MAX_LIST_LENGTH": "femmech.scene.reader.MAX_LIST_LENGTH",
        "MAX_MAGNITUDE": "femmech.scene.reader.MAX_MAGNITUDE",
        "MAX_SCENE_BYTES": "femmech.scene.reader.MAX_SCENE_BYTES",
        "MAX_STRING_LENGTH": "femmech.scene.reader.MAX_STRING_LENGTH",
        "MAX_VALUES": "femmech.scene.reader.MAX_VALUES",
        "Reader": "femmech.scene.reader.Reader",
        "check_limits": "femmech.scene.reader.check_limits",
        "closest": "femmech.scene.reader.closest",
        "key_text": "femmech.scene.reader.key_text",
        "one_line": "femmech.scene.reader.one_line",
        "show": "femmech.scene.reader.show",
        "unknown_key_message": "femmech.scene.reader.unknown_key_message",
    })
