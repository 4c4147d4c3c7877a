"""Stage 3, substructure reduction: FE model → small superelement with recovery.

* :mod:`.superelement`: the :class:`Superelement` (reduced matrices, recovery of the full
  field, save/load) and :func:`interface_dofs`;
* :mod:`.component_modes`: Guyan and Craig-Bampton reduction with residual vectors;
* :mod:`.products`: the dense-block products of the reduction;
* :mod:`.estimate`: the a-posteriori frequency error estimate of a reduction;
* :mod:`.superelement_file`: the validated file format (writer and reader), with
  :mod:`.superelement_format` (fields, checksums, messages), :mod:`.superelement_archive`
  (zip members and ``.npy`` headers) and :mod:`.superelement_checks` (meta, shapes,
  values);
* :mod:`.substructures`: the assembly of several superelements and plain FE parts into
  one system.

Imports :mod:`femmech.errors`, :mod:`femmech.fe` and :mod:`femmech.solve`; never
mechanisms, coupling or analyses.
"""

from femmech.reduction.component_modes import CUTOFF_FACTOR, craig_bampton, guyan
from femmech.reduction.estimate import frequency_error_estimates
from femmech.reduction.substructures import Assembly, assemble_parts
from femmech.reduction.superelement import FORMAT_VERSION, Superelement, interface_dofs

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
