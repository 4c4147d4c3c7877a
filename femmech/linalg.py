"""Old path of :mod:`femmech.solve.eigen` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "ALL_PAIRS_FRACTION": "femmech.solve.dense.ALL_PAIRS_FRACTION",
        "BLOCK_SIZE": "femmech.solve.lanczos.BLOCK_SIZE",
        "DENSE_BELOW": "femmech.solve.eigen.DENSE_BELOW",
        "EigenResult": "femmech.solve.eigen.EigenResult",
        "FAR_SHIFT": "femmech.solve.lanczos.FAR_SHIFT",
        "GUARD_TOL": "femmech.solve.lanczos.GUARD_TOL",
        "LANCZOS_TOL": "femmech.solve.lanczos.LANCZOS_TOL",
        "MAX_BASIS_BYTES": "femmech.solve.lanczos.MAX_BASIS_BYTES",
        "MAX_DEFLATIONS": "femmech.solve.eigen.MAX_DEFLATIONS",
        "MAX_SOLVES_PER_MODE": "femmech.solve.lanczos.MAX_SOLVES_PER_MODE",
        "PROBES": "femmech.solve.lanczos.PROBES",
        "REORTHOGONALIZE_BELOW": "femmech.solve.lanczos.REORTHOGONALIZE_BELOW",
        "RESIDUAL_TOL": "femmech.solve.residuals.RESIDUAL_TOL",
        "RIGID_TOL": "femmech.solve.eigen.RIGID_TOL",
        "SEMI_ORTHOGONAL": "femmech.solve.lanczos.SEMI_ORTHOGONAL",
        "STREAM_COLUMNS": "femmech.solve.lanczos.STREAM_COLUMNS",
        "default_shift": "femmech.solve.pencil.default_shift",
        "dense_symmetric": "femmech.solve.dense.dense_symmetric",
        "eigenvalue_scale": "femmech.solve.pencil.eigenvalue_scale",
        "factorize": "femmech.solve.pencil.factorize",
        "inertia_below": "femmech.solve.sturm.inertia_below",
        "normalize_modes": "femmech.solve.residuals.normalize_modes",
        "residual_limits": "femmech.solve.residuals.residual_limits",
        "residuals": "femmech.solve.residuals.residuals",
        "solve_symmetric": "femmech.solve.eigen.solve_symmetric",
    })
