"""Warning class of femmech (errors are plain ``ValueError``/``TypeError``)."""


class FemmechWarning(UserWarning):
    """A result was computed but deserves the user's attention (e.g. poor convergence)."""


class SceneError(ValueError):
    """A scene file is invalid; the one-line message names the file, the key and what was
    expected (``scene.toml: [parts.frame.sections.posts] section: expected one of ...``)."""
