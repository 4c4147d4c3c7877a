"""Old path of :mod:`femmech.solve.threads` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "ENV_VAR": "femmech.solve.threads.ENV_VAR",
        "ThreadSettings": "femmech.solve.threads.ThreadSettings",
        "describe": "femmech.solve.threads.describe",
        "exactly": "femmech.solve.threads.exactly",
        "factor_phase": "femmech.solve.threads.factor_phase",
        "gemm_phase": "femmech.solve.threads.gemm_phase",
        "limit": "femmech.solve.threads.limit",
        "parse": "femmech.solve.threads.parse",
        "refresh": "femmech.solve.threads.refresh",
        "set_threads": "femmech.solve.threads.set_threads",
        "settings": "femmech.solve.threads.settings",
        "solve_phase": "femmech.solve.threads.solve_phase",
    })
