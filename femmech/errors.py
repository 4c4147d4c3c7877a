"""Warning class of femmech (errors are plain ``ValueError``/``TypeError``)."""


class FemmechWarning(UserWarning):
    """A result was computed but deserves the user's attention (e.g. poor convergence)."""
