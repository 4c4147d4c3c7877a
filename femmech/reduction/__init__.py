"""Stage 3, substructure reduction: FE model → small superelement with recovery.

* :mod:`.superelement`: the :class:`Superelement` (reduced matrices, recovery of the full
  field, save/load) and :func:`interface_dofs`;
* :mod:`.component_modes`: Guyan and Craig-Bampton reduction with residual vectors;
* :mod:`.products`: the dense-block products of the reduction;
* :mod:`.estimate`: the a-posteriori frequency error estimates of a reduction, of the
  superelement's modes and of coupled quasi-modes over a sweep;
* :mod:`.interface_modes`: Craig-Bampton with a reduced interface (mode traces,
  attachment vectors, characteristic constraint modes) and its error estimate;
* :mod:`.superelement_file`: the validated file format in one module (fields, checksums,
  the writer, the reader and its checks of zip members, ``.npy`` headers, meta, shapes
  and values; :mod:`.superelement_format`, :mod:`.superelement_archive` and
  :mod:`.superelement_checks` are old paths of its parts);
* :mod:`.substructures`: the assembly of several superelements and plain FE parts into
  one system.

Imports :mod:`femmech.errors`, :mod:`femmech.fe` and :mod:`femmech.solve`; never
mechanisms, coupling or analyses.
"""

from femmech.deprecation import lazy_names

_LAZY = {
    "CUTOFF_FACTOR": "femmech.reduction.component_modes",
    "craig_bampton": "femmech.reduction.component_modes",
    "guyan": "femmech.reduction.component_modes",
    "CoupledErrorForms": "femmech.reduction.estimate",
    "coupled_error_estimates": "femmech.reduction.estimate",
    "coupled_error_forms": "femmech.reduction.estimate",
    "frequency_error_estimates": "femmech.reduction.estimate",
    "interface_error_estimates": "femmech.reduction.interface_modes",
    "reduce_interface": "femmech.reduction.interface_modes",
    "Assembly": "femmech.reduction.substructures",
    "assemble_parts": "femmech.reduction.substructures",
    "FORMAT_VERSION": "femmech.reduction.superelement",
    "Superelement": "femmech.reduction.superelement",
    "interface_dofs": "femmech.reduction.superelement",
}
"""Public name → its module, imported on first use: reading a superelement file or the
format version does not import the eigensolvers of :mod:`.component_modes`."""

__all__ = [
    "CUTOFF_FACTOR",
    "FORMAT_VERSION",
    "Assembly",
    "CoupledErrorForms",
    "Superelement",
    "assemble_parts",
    "coupled_error_estimates",
    "coupled_error_forms",
    "craig_bampton",
    "frequency_error_estimates",
    "guyan",
    "interface_dofs",
    "interface_error_estimates",
    "reduce_interface",
]


_MOVED = {
    "PIVOT_RTOL": "femmech.reduction.component_modes.PIVOT_RTOL",
    "SYMMETRIC_BLOCK": "femmech.reduction.products.SYMMETRIC_BLOCK",
    "THIN_PRODUCT_FLOPS": "femmech.reduction.products.THIN_PRODUCT_FLOPS",
}
"""Names this package had before the restructures → their new places (docs/architecture.md,
"Moved names")."""

__getattr__, __dir__ = lazy_names(__name__, _LAZY, moved_names=_MOVED)
