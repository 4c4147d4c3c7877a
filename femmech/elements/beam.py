"""Old path of :mod:`femmech.fe.elements.beam` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "beam_matrices": "femmech.fe.elements.beam.beam_matrices",
        "bending_matrices": "femmech.fe.elements.beam.bending_matrices",
        "bending_shape_functions": "femmech.fe.elements.beam.bending_shape_functions",
        "local_frames": "femmech.fe.elements.beam.local_frames",
        "local_matrices": "femmech.fe.elements.beam.local_matrices",
        "rotate_to_global": "femmech.fe.elements.beam.rotate_to_global",
    })
