"""Stage 3, substructure reduction: FE model → small superelement with recovery.

Guyan and Craig-Bampton superelements with residual vectors and an a-posteriori
frequency error estimate (:mod:`.reduce`), their validated file format
(:mod:`.superelement_file`), and the assembly of several superelements and plain FE
parts into one system (:mod:`.substructures`).

Imports :mod:`femmech.fe` and :mod:`femmech.solve`; never mechanisms, coupling or analyses.
"""

from femmech.reduction.reduce import (
    CUTOFF_FACTOR,
    FORMAT_VERSION,
    Superelement,
    craig_bampton,
    frequency_error_estimates,
    guyan,
    interface_dofs,
)
from femmech.reduction.substructures import Assembly, assemble_parts

__all__ = [
    "CUTOFF_FACTOR",
    "FORMAT_VERSION",
    "Assembly",
    "Superelement",
    "assemble_parts",
    "craig_bampton",
    "frequency_error_estimates",
    "guyan",
    "interface_dofs",
]
