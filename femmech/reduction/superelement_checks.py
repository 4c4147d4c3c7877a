"""Old path of the checks of meta, shapes and values of superelement files, now in
:mod:`femmech.reduction.superelement_file` (the whole file format is in that module).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new place."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "MAX_TIMINGS": "femmech.reduction.superelement_file.MAX_TIMINGS",
        "PSD_RTOL": "femmech.reduction.superelement_file.PSD_RTOL",
        "SYMMETRY_RTOL": "femmech.reduction.superelement_file.SYMMETRY_RTOL",
    })
