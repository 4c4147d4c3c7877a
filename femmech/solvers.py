"""Old path of :mod:`femmech.solve.direct` (previous layout).

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "AUTO_MIN_SIZE": "femmech.solve.direct.AUTO_MIN_SIZE",
        "AUTO_ORDER": "femmech.solve.direct.AUTO_ORDER",
        "BACKENDS": "femmech.solve.direct.BACKENDS",
        "CholmodFactor": "femmech.solve.cholmod.CholmodFactor",
        "ENV_VAR": "femmech.solve.direct.ENV_VAR",
        "Factor": "femmech.solve.factor.Factor",
        "PARALLEL_SOLVE_COLUMNS": "femmech.solve.pardiso.PARALLEL_SOLVE_COLUMNS",
        "PARALLEL_SOLVE_MAX_BYTES": "femmech.solve.pardiso.PARALLEL_SOLVE_MAX_BYTES",
        "PARDISO_LOOP_FILL": "femmech.solve.pardiso.PARDISO_LOOP_FILL",
        "PARDISO_PERTURBATION": "femmech.solve.pardiso.PARDISO_PERTURBATION",
        "PARDISO_SOLVE_MODE": "femmech.solve.pardiso.PARDISO_SOLVE_MODE",
        "PardisoFactor": "femmech.solve.pardiso.PardisoFactor",
        "SuperLUFactor": "femmech.solve.superlu.SuperLUFactor",
        "available": "femmech.solve.direct.available",
        "default_solver": "femmech.solve.direct.default_solver",
        "factorize": "femmech.solve.direct.factorize",
        "mkl_version": "femmech.solve.pardiso.mkl_version",
        "resolve": "femmech.solve.direct.resolve",
        "use": "femmech.solve.direct.use",
        "versions": "femmech.solve.direct.versions",
    })
