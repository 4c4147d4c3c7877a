"""The shell and solid element types :func:`femmech.build_model` knows, by meshio cell kind.

An element module registers each cell kind it computes (:func:`register`, at the end of
the module); :mod:`femmech.fe.parts` assembles every registered kind of a family from the
properties of that family, in registration order. Adding an element type therefore
touches only ``femmech/fe/elements/``: its module and the import that registers it in
``femmech/fe/elements/__init__.py`` (docs/architecture.md).

Two families, by the properties and DOFs they take:

``"shell"`` (:class:`~femmech.fe.parts.ShellProperty`, 6 DOFs per node, shared with beams)
    ``matrices(points, cells, E, nu, rho, thickness, drilling=...) -> (Ke, Me)``, each
    (n_elements, 6 k, 6 k) on the element DOFs ``6 · node + component`` of the k nodes
    of each cell (:func:`femmech.fe.dofs.element_dofs`), global axes; ``E`` (Pa), ``nu``,
    ``rho`` (kg/m³), ``thickness`` (m) and ``drilling`` are arrays (n_elements,).
``"solid"`` (:class:`~femmech.fe.parts.SolidProperty`, 3 translations per node)
    ``matrices(points, cells, kind, E, nu, rho, n_dof) -> (K, M)``: the kind's global
    sparse stiffness and mass (n_dof, n_dof) on the 6-DOF-per-node numbering, rotations
    left empty; material arrays (n_elements,).

Uses only fe.mesh (the node count of each cell kind); the element modules
import it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from femmech.fe.mesh import NODES_PER_CELL

FAMILIES = ("shell", "solid")


@dataclass(frozen=True)
class ElementType:
    """One cell kind and the batched function that computes its element matrices.

    Attributes
    ----------
    cell : str
        meshio cell type, e.g. ``"quad"``; the mesh must know its node count
        (:data:`femmech.fe.mesh.NODES_PER_CELL`).
    family : str
        ``"shell"`` or ``"solid"``: which properties it takes and what ``matrices``
        returns (module docstring).
    matrices : callable
        The batched element computation of the family's signature.
    """

    cell: str
    family: str
    matrices: Callable

    def __post_init__(self):
        if self.family not in FAMILIES:
            raise ValueError(f"element family must be one of {FAMILIES}, got {self.family!r}")
        if self.cell not in NODES_PER_CELL:
            raise ValueError(f"unknown cell kind {self.cell!r}; meshes know"
                             f" {sorted(NODES_PER_CELL)}")
        if not callable(self.matrices):
            raise TypeError(f"matrices of {self.cell!r} must be callable")


ELEMENTS: dict[str, ElementType] = {}
"""Registered element types by cell kind, in registration order."""


def register(element: ElementType) -> ElementType:
    """Make ``element`` known to :func:`femmech.build_model`; a kind registers once."""
    if element.cell in ELEMENTS:
        raise ValueError(f"cell kind {element.cell!r} already has an element"
                         f" ({ELEMENTS[element.cell].matrices.__qualname__})")
    ELEMENTS[element.cell] = element
    return element


def kinds(family: str) -> tuple[str, ...]:
    """Cell kinds registered for ``family``, in registration order."""
    return tuple(kind for kind, element in ELEMENTS.items() if element.family == family)
