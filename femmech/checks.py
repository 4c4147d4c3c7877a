"""Old path of :mod:`femmech.fe.checks` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "CORNERS": "femmech.fe.checks.CORNERS",
        "FREQ_ABOVE_HZ": "femmech.fe.checks.FREQ_ABOVE_HZ",
        "FREQ_BELOW_HZ": "femmech.fe.checks.FREQ_BELOW_HZ",
        "Finding": "femmech.fe.checks.Finding",
        "K_NEAREST": "femmech.fe.checks.K_NEAREST",
        "LOCAL_FRACTION": "femmech.fe.checks.LOCAL_FRACTION",
        "MASS_RATIO_RANGE": "femmech.fe.checks.MASS_RATIO_RANGE",
        "MAX_LISTED": "femmech.fe.checks.MAX_LISTED",
        "MAX_PAIRS": "femmech.fe.checks.MAX_PAIRS",
        "MMTS_EXTENT_BELOW": "femmech.fe.checks.MMTS_EXTENT_BELOW",
        "MMTS_RHO_BELOW": "femmech.fe.checks.MMTS_RHO_BELOW",
        "NEAR_NODE_TOL": "femmech.fe.checks.NEAR_NODE_TOL",
        "SI_EXTENT_ABOVE": "femmech.fe.checks.SI_EXTENT_ABOVE",
        "SI_E_ABOVE": "femmech.fe.checks.SI_E_ABOVE",
        "SOLID_RHO": "femmech.fe.checks.SOLID_RHO",
        "WAVE_SPEED_RANGE": "femmech.fe.checks.WAVE_SPEED_RANGE",
        "cell_measure": "femmech.fe.checks.cell_measure",
        "frequency_findings": "femmech.fe.checks.frequency_findings",
        "local_size": "femmech.fe.checks.local_size",
        "loose_parts": "femmech.fe.checks.loose_parts",
        "near_node_findings": "femmech.fe.checks.near_node_findings",
        "near_nodes": "femmech.fe.checks.near_nodes",
        "unit_findings": "femmech.fe.checks.unit_findings",
        "warn": "femmech.fe.checks.warn",
    })
