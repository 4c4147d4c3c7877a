"""Old path of :mod:`femmech.fe.model` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "BEAM_PROPERTY_COLUMNS": "femmech.fe.model.BEAM_PROPERTY_COLUMNS",
        "BeamProperty": "femmech.fe.model.BeamProperty",
        "BeamSet": "femmech.fe.model.BeamSet",
        "FEModel": "femmech.fe.model.FEModel",
        "build_model": "femmech.fe.model.build_model",
        "model_findings": "femmech.fe.model.model_findings",
        "node_index": "femmech.fe.model.node_index",
        "node_indices": "femmech.fe.model.node_indices",
    })
