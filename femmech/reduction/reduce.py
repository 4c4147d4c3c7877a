"""Old path of the reduction (previous layout), now :mod:`femmech.reduction.superelement`,
:mod:`femmech.reduction.component_modes`, :mod:`femmech.reduction.products`,
:mod:`femmech.reduction.estimate` and :mod:`femmech.reduction.superelement_file`.

Every public name it had works here with a DeprecationWarning naming its new place
(docs/architecture.md, "Moved names"); nothing inside femmech imports this module.
"""


def __getattr__(name: str):
    """The previous layout's names, from their new places."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "CUTOFF_FACTOR": "femmech.reduction.component_modes.CUTOFF_FACTOR",
        "FORMAT_VERSION": "femmech.reduction.superelement_file.FORMAT_VERSION",
        "PIVOT_RTOL": "femmech.reduction.component_modes.PIVOT_RTOL",
        "SYMMETRIC_BLOCK": "femmech.reduction.products.SYMMETRIC_BLOCK",
        "Superelement": "femmech.reduction.superelement.Superelement",
        "THIN_PRODUCT_FLOPS": "femmech.reduction.products.THIN_PRODUCT_FLOPS",
        "craig_bampton": "femmech.reduction.component_modes.craig_bampton",
        "frequency_error_estimates": "femmech.reduction.estimate.frequency_error_estimates",
        "guyan": "femmech.reduction.component_modes.guyan",
        "interface_dofs": "femmech.reduction.superelement.interface_dofs",
    })
