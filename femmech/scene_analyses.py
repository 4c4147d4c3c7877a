"""Old path of :mod:`femmech.scene.analyses` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "Analyses": "femmech.scene.analyses.Analyses",
        "CheckSpec": "femmech.scene.analyses.CheckSpec",
        "MAX_HISTORIES": "femmech.scene.analyses.MAX_HISTORIES",
        "MAX_IMAGES": "femmech.scene.analyses.MAX_IMAGES",
        "MAX_LEVELS": "femmech.scene.analyses.MAX_LEVELS",
        "MAX_MODES": "femmech.scene.analyses.MAX_MODES",
        "MAX_POINTS": "femmech.scene.analyses.MAX_POINTS",
        "MAX_STEPS": "femmech.scene.analyses.MAX_STEPS",
        "MAX_SWEEP_POINTS": "femmech.scene.analyses.MAX_SWEEP_POINTS",
        "ModesSpec": "femmech.scene.analyses.ModesSpec",
        "ResponseSpec": "femmech.scene.analyses.ResponseSpec",
        "StabilitySpec": "femmech.scene.analyses.StabilitySpec",
        "SweepSpec": "femmech.scene.analyses.SweepSpec",
        "read_analyses": "femmech.scene.analyses.read_analyses",
    })
