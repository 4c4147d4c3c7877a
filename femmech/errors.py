"""Warning class of femmech (errors are plain ``ValueError``/``TypeError``)."""


class FemmechWarning(UserWarning):
    """A result was computed but deserves the user's attention (e.g. poor convergence)."""


class SceneError(ValueError):
    """A scene file is invalid; the one-line message names the file, the key and what was
    expected (``scene.toml: [parts.frame.sections.posts] section: expected one of ...``)."""


class ModelWarning(FemmechWarning):
    """A model input looks wrong (nearly coincident nodes, a free body by accident, a unit
    mix-up): the results are computed but are probably not those of the intended model.
    See :mod:`femmech.checks`."""


class ConvergenceWarning(FemmechWarning):
    """A stepped or iterative result missed its tolerance; it is returned marked as
    unconverged (``converged=False``) with its error estimate, never as a plain number."""
