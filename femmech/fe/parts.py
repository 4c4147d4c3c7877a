"""Shell and solid element properties and their assembly for :func:`femmech.build_model`.

Shells (:mod:`femmech.fe.elements.shell`) have the six DOFs per node of the beams and share
nodes with them. Solids (:mod:`femmech.fe.elements.solid`) have translations only: a node
shared by a solid and a beam or shell couples the translations, and the beam's or
shell's rotations stay its own (a hinge). To transmit moments from a beam into a solid,
tie the beam node to a patch of solid nodes with a
:class:`~femmech.fe.constraints.RigidLink` (stiff patch) or an
:class:`~femmech.fe.constraints.InterpolatingLink` (patch deforms freely). Rotational DOFs
that only solid elements touch carry neither stiffness nor mass; ``build_model`` removes
them (:attr:`femmech.fe.model.FEModel.inactive`).

Uses fe.mesh, .materials, .dofs and the element
registry (:mod:`femmech.fe.elements.registry`): every registered shell and solid cell
kind is assembled here.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from femmech.fe.dofs import element_dofs
from femmech.fe.elements.registry import ELEMENTS, kinds
from femmech.fe.elements.shell import DRILLING
from femmech.fe.materials import Material
from femmech.fe.mesh import NODES_PER_CELL, Mesh


@dataclass(frozen=True)
class ShellProperty:
    """Thickness and material of the shell elements (triangles, quads) of one group.

    Attributes
    ----------
    thickness : float
        Shell thickness, m.
    material : Material
    drilling : float
        Drilling penalty ``γ / G`` tying the rotation about the shell normal to the
        in-plane rotation (:mod:`femmech.fe.elements.shell`); the default changes plate and
        membrane frequencies by < 1e-4. Thick shells with nodes free to rotate about the
        normal get a cluster of spurious drilling modes near
        ``sqrt(12 drilling G / ρ) / (2π t)`` (884 Hz for steel at t = 0.2 m);
        :func:`femmech.modes` reports them (:mod:`femmech.analysis.shell_checks`), and raising
        ``drilling`` moves them up as its square root.

    Notes
    -----
    The transverse shear correction factor is ``k = 5/6``
    (:data:`femmech.fe.elements.shell.SHEAR_FACTOR`, Reissner-Mindlin's value for a
    homogeneous plate, exact for the parabolic shear stress) for every material: unlike
    the Cowper coefficients of beam sections (:mod:`femmech.fe.sections`) it does not
    depend on Poisson's ratio. ``Material.nu`` (or G) enters the shell through the
    plane-stress matrix and ``G = E / (2 (1 + ν))`` of the shear and drilling terms.
    """

    thickness: float
    material: Material
    drilling: float = DRILLING

    def __post_init__(self):
        if not isinstance(self.material, Material):
            raise TypeError(f"ShellProperty material must be a Material,"
                            f" got {type(self.material).__name__}")
        t = self.thickness
        if isinstance(t, bool) or not (isinstance(t, (int, float, np.floating, np.integer))
                                       and np.isfinite(t) and t > 0):
            raise ValueError(f"ShellProperty thickness must be a positive number, got {t!r}")
        if not (np.isfinite(self.drilling) and self.drilling > 0):
            raise ValueError(f"ShellProperty drilling must be positive, got {self.drilling!r}")


@dataclass(frozen=True)
class ShellSet:
    """Shell elements of a model by cell type (``"triangle"``, ``"quad"``).

    Attributes
    ----------
    cells : dict[str, ndarray (n_elements, 3 or 4)]
    group : dict[str, ndarray (n_elements,) of str]
    thickness : dict[str, ndarray (n_elements,)], m
    """

    cells: dict = field(default_factory=dict)
    group: dict = field(default_factory=dict)
    thickness: dict = field(default_factory=dict)


@dataclass(frozen=True)
class SolidProperty:
    """Material of the solid elements (tetrahedra, hexahedra) of one group.

    Attributes
    ----------
    material : Material
    """

    material: Material

    def __post_init__(self):
        if not isinstance(self.material, Material):
            raise TypeError(f"SolidProperty material must be a Material,"
                            f" got {type(self.material).__name__}")
        if not -1.0 < self.material.poisson_ratio < 0.5:
            raise ValueError(f"SolidProperty material {self.material.name!r}: Poisson's ratio"
                             f" must lie in (-1, 0.5), got {self.material.poisson_ratio}")


@dataclass(frozen=True)
class SolidSet:
    """Solid elements of a model by meshio cell type (``"tetra"``, ``"hexahedron20"``, ...).

    Attributes
    ----------
    cells : dict[str, ndarray (n_elements, k)]
        Connectivity in meshio (VTK) node order.
    group : dict[str, ndarray (n_elements,) of str]
    """

    cells: dict = field(default_factory=dict)
    group: dict = field(default_factory=dict)


def check_part_types(shells, solids) -> None:
    """TypeError unless ``shells`` and ``solids`` map names to the right properties."""
    for label, parts, kind in (("shells", shells, ShellProperty),
                               ("solids", solids, SolidProperty)):
        if not isinstance(parts, Mapping):
            raise TypeError(f"{label} must be a dict {{cell-set name: {kind.__name__}}},"
                            f" got {type(parts).__name__}")
        for name, prop in parts.items():
            if not isinstance(prop, kind):
                raise TypeError(f"{label}[{name!r}] must be a {kind.__name__},"
                                f" got {type(prop).__name__}")


def _owner(mesh: Mesh, kind: str, names: list[str], what: str) -> np.ndarray:
    """Index into ``names`` of the group of each ``kind`` cell (checked)."""
    cells = mesh.cells.get(kind, np.empty((0, NODES_PER_CELL[kind]), dtype=np.int64))
    owner = np.full(len(cells), -1)
    for g, name in enumerate(names):
        idx = mesh.cell_sets[name].get(kind, np.empty(0, dtype=np.int64))
        twice = idx[owner[idx] >= 0]
        if twice.size:
            raise ValueError(f"{kind} element {twice[0]} is in groups"
                             f" {names[owner[twice[0]]]!r} and {name!r}, both with {what}"
                             " properties")
        owner[idx] = g
    missing = np.flatnonzero(owner < 0)
    if missing.size:
        e = missing[0]
        groups = [n for n, s in mesh.cell_sets.items() if e in s.get(kind, ())]
        raise ValueError(f"{kind} element {e} (nodes {cells[e].tolist()}) has no {what}"
                         f" property ({missing.size} such elements); its groups: {groups}")
    return owner


def _check_groups(mesh: Mesh, names, kinds, what: str) -> None:
    for name in names:
        if name not in mesh.cell_sets:
            raise ValueError(f"{what} property for {mesh.unknown_cell_set(name)}")
        if not any(len(mesh.cell_sets[name].get(k, ())) for k in kinds):
            raise ValueError(f"{what} property for group {name!r}, which has no"
                             f" {' or '.join(kinds)} cells")


def shell_blocks(mesh: Mesh, shells: dict[str, ShellProperty]):
    """ShellSet and (dofs, matrices) stiffness and mass blocks of the shell cells."""
    if not shells:
        return ShellSet(), [], []
    names = list(shells)
    _check_groups(mesh, names, kinds("shell"), "shell")
    table = np.array([[p.material.E, p.material.poisson_ratio, p.material.rho, p.thickness,
                       p.drilling] for p in shells.values()])
    cells_by, group_by, thick_by, stiff, mass = {}, {}, {}, [], []
    for kind in kinds("shell"):
        cells = mesh.cells.get(kind)
        if cells is None or not len(cells):
            continue
        owner = _owner(mesh, kind, names, "shell")
        E, nu, rho, t, drill = table[owner].T
        Ke, Me = ELEMENTS[kind].matrices(mesh.points, cells, E, nu, rho, t, drilling=drill)
        dofs = element_dofs(cells)
        stiff.append((dofs, Ke))
        mass.append((dofs, Me))
        cells_by[kind] = cells
        group_by[kind] = np.array(names, dtype=object)[owner]
        thick_by[kind] = t
    return ShellSet(cells_by, group_by, thick_by), stiff, mass


def solid_parts(mesh: Mesh, solids: dict[str, SolidProperty], n_dof: int):
    """SolidSet and the global stiffness and mass (CSR, n_dof x n_dof) of the solid cells.

    Returns ``(SolidSet, [K], [M])``; the lists are empty without solids.
    """
    if not solids:
        return SolidSet(), [], []
    names = list(solids)
    _check_groups(mesh, names, kinds("solid"), "solid")
    table = np.array([[p.material.E, p.material.poisson_ratio, p.material.rho]
                      for p in solids.values()])
    cells_by, group_by, stiff, mass = {}, {}, [], []
    for kind in kinds("solid"):
        cells = mesh.cells.get(kind)
        if cells is None or not len(cells):
            continue
        owner = _owner(mesh, kind, names, "solid")
        E, nu, rho = table[owner].T
        K, M = ELEMENTS[kind].matrices(mesh.points, cells, kind, E, nu, rho, n_dof)
        stiff.append(K)
        mass.append(M)
        cells_by[kind] = cells
        group_by[kind] = np.array(names, dtype=object)[owner]
    return SolidSet(cells_by, group_by), stiff, mass


def __getattr__(name: str):
    """Names this module had before the restructures, from their new places
    (docs/architecture.md, "Moved names")."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
    }, removed={
        "SHELL_TYPES": "use femmech.fe.elements.registry.kinds('shell')",
    })
