"""The FE model: mesh + element properties + lumped items + constraints → sparse K, M.

Symbols: K stiffness (N/m, N m/rad), M mass (kg, kg m²), both (n_dof, n_dof) CSR with
``n_dof = 6 n_nodes``; constraints are eliminated by ``u = T u_free`` so that the free
system is ``Tᵀ K T``, ``Tᵀ M T``.

Uses only the fe package (mesh, sections,
materials, elements, assembly, constraints, lumped items, parts, checks).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from femmech.fe import checks
from femmech.fe.assembly import assemble
from femmech.fe.constraints import (
    EquationSet,
    InterpolatingLink,
    RigidLink,
    Support,
    add_interpolated_nodes,
    add_interpolating_link,
    add_rigid_links,
    constraint_transform,
    fixed_mask,
)
from femmech.fe.dofs import DOF_PER_NODE, element_dofs, node_dofs
from femmech.fe.elements.beam import beam_matrices, local_frames
from femmech.fe.elements.registry import kinds
from femmech.fe.lumped import PointMass, Spring
from femmech.fe.materials import Material
from femmech.fe.mesh import QUAD8_CENTRE, Mesh, quad8_centres, quad8_to_quad9
from femmech.fe.parts import (
    ShellProperty,
    ShellSet,
    SolidProperty,
    SolidSet,
    check_part_types,
    shell_blocks,
    solid_parts,
)
from femmech.fe.sections import BeamSection
from femmech.html import html_summary


@dataclass(frozen=True)
class BeamProperty:
    """Section, material and orientation of the beam elements of one group.

    Attributes
    ----------
    section : BeamSection
    material : Material
    orientation : array_like (3,), optional
        Orientation vector (global coordinates, any length), in the plane that
        ``orientation_plane`` names. Default: the rule of
        :func:`femmech.fe.elements.beam.local_frames` (local z upwards).
    shear : bool
        Timoshenko shear deformation; False gives Euler-Bernoulli bending.
    rotary_inertia : bool
        Include the rotary inertia of bending.
    orientation_plane : ``"xy"`` or ``"xz"``
        Which local plane ``orientation`` lies in. ``"xy"`` (default): it points towards
        local y, as Nastran's CBAR/CBEAM vector v and the direction line of an
        Abaqus/CalculiX ``*BEAM SECTION`` (the n1 axis; their t, n1, n2 are x, y, z).
        ``"xz"``: it points towards local z, as OpenSees' ``vecxz`` of ``geomTransf`` and
        an Abaqus ``*NORMAL`` (n2); converted exactly (local z = the part of the vector
        normal to the axis, local y = z × x, :func:`xz_to_xy`). A vector copied with the
        wrong plane turns the section by 90° without an error.
    """

    section: BeamSection
    material: Material
    orientation: object = None
    shear: bool = True
    rotary_inertia: bool = True
    orientation_plane: str = "xy"


# columns of BeamSet.properties: the arguments of elements.beam.local_matrices (after the
# length) and the rotary inertia flag
BEAM_PROPERTY_COLUMNS = ("E", "G", "rho", "A", "Iy", "Iz", "J", "Ip", "Asy", "Asz",
                         "rotary_inertia")


@dataclass(frozen=True)
class BeamSet:
    """Beam elements of a model, for recovery and drawing.

    Attributes
    ----------
    cells : ndarray (n_elements, 2)
    frames : ndarray (n_elements, 3, 3)
        Local axes (rows) in global coordinates.
    length : ndarray (n_elements,), m
    radius : ndarray (n_elements,), m
        Drawing radius (half the largest section dimension).
    group : ndarray (n_elements,) of str
    phi : ndarray (n_elements, 2)
        Shear parameters ``Φ = 12 E I / (G A_s L²)`` of the local x-y plane (Iz, Asy) and
        x-z plane (Iy, Asz); 0 for Euler-Bernoulli bending.
    properties : ndarray (n_elements, 11)
        Element data in the order of :data:`BEAM_PROPERTY_COLUMNS` (E, G in Pa, ρ in
        kg/m³, A, A_s in m², I, J, I_p in m⁴, rotary inertia flag 0/1), so that element
        matrices can be rebuilt (:func:`femmech.fe.elements.beam.local_matrices`) for
        force recovery.
    """

    cells: np.ndarray
    frames: np.ndarray
    length: np.ndarray
    radius: np.ndarray
    group: np.ndarray
    phi: np.ndarray
    properties: np.ndarray = field(default_factory=lambda: np.zeros((0, 11)))


@dataclass(frozen=True)
class FEModel:
    """Assembled FE model.

    Attributes
    ----------
    mesh : Mesh
    K, M : scipy.sparse.csr_matrix (n_dof, n_dof)
        Unconstrained stiffness and mass.
    T : scipy.sparse.csr_matrix (n_dof, n_free)
        Constraint transformation, ``u = T u_free``.
    free : ndarray (n_free,)
        Independent DOFs (the columns of T are the unit vectors of these DOFs, plus the
        rigid-link contributions).
    beams : BeamSet
    mass_nodes : ndarray (n_masses,)
        Nodes that carry point masses (for drawing).
    links : ndarray (n_links, 2)
        Node pairs joined by rigid links (master, slave) or node-to-node springs, for
        drawing.
    shells : ShellSet
        Shell elements (empty without shell properties).
    solids : SolidSet
        Solid elements (empty without solid properties).
    inactive : ndarray (n_inactive,)
        Rotational DOFs of solid nodes with neither stiffness, mass nor constraint
        (nodes that only solid elements use); removed from ``free`` like supported DOFs,
        but they are not supports.
    inputs : dict
        The keyword arguments of :func:`build_model` besides the mesh (properties,
        masses, springs, supports, links), so that the model can be rebuilt on another
        mesh of the same groups (:func:`femmech.fe.refine.refined_model`).
    tied : ndarray (n_tied,)
        Translational DOFs of the centre nodes of quad8 skins on solid faces, which follow
        the serendipity interpolation of their cells' eight nodes (dependent: not in
        ``free``; their rows of T carry the weights; :mod:`femmech.fe.elements.shell9`).
    """

    mesh: Mesh
    K: sp.csr_matrix
    M: sp.csr_matrix
    T: sp.csr_matrix
    free: np.ndarray
    beams: BeamSet
    mass_nodes: np.ndarray
    links: np.ndarray
    K_free: sp.csr_matrix = field(repr=False)
    M_free: sp.csr_matrix = field(repr=False)
    shells: ShellSet = field(default_factory=ShellSet)
    solids: SolidSet = field(default_factory=SolidSet)
    inactive: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64))
    inputs: dict = field(default_factory=dict, repr=False, compare=False)
    tied: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64))

    def __repr__(self) -> str:
        kinds = ", ".join(f"{len(c)} {k}" for k, c in self.mesh.cells.items())
        return (f"FEModel({self.mesh.n_nodes} nodes, {kinds}; {self.n_dof} DOFs,"
                f" {self.n_free} free; K, M sparse with {self.K_free.nnz} non-zeros)")

    def _repr_html_(self) -> str:
        rows = [(kind, len(cells)) for kind, cells in self.mesh.cells.items()]
        facts = [("DOFs", f"{self.n_dof} ({self.n_free} free)"),
                 ("total mass / kg", self.total_mass()),
                 ("K, M", f"sparse, {self.K_free.nnz} non-zeros (free DOFs)")]
        return html_summary(f"FEModel: {self.mesh.n_nodes} nodes", facts,
                            ("cell kind", "elements"), rows)

    @property
    def n_dof(self) -> int:
        """Number of DOFs before constraints (6 per node)."""
        return self.K.shape[0]

    @property
    def n_free(self) -> int:
        """Number of independent DOFs after supports and rigid links."""
        return self.T.shape[1]

    def expand(self, u_free: np.ndarray) -> np.ndarray:
        """Full DOF vector(s) (n_dof, ...) from free DOF vector(s) (n_free, ...)."""
        return self.T @ u_free

    def total_mass(self) -> float:
        """Translational mass, kg: ``eᵀ M e / 3`` summed over the three rigid translations."""
        e = np.zeros((self.n_dof, 3))
        for i in range(3):
            e[i::DOF_PER_NODE, i] = 1.0
        return float(np.trace(e.T @ (self.M @ e)) / 3.0)


def build_model(mesh: Mesh, beams: dict[str, BeamProperty] | None = None, masses=(),
                springs=(), supports=(), rigid_links=(), interpolating_links=(),
                shells: dict[str, ShellProperty] | None = None,
                solids: dict[str, SolidProperty] | None = None,
                node_tol: float | None = None) -> FEModel:
    """Assemble an :class:`FEModel`.

    Parameters
    ----------
    mesh : Mesh
    beams : dict[str, BeamProperty], optional
        Cell-set name → property of its line elements; every line element needs exactly one.
    masses : sequence of PointMass
    springs : sequence of Spring
    supports : sequence of Support
    rigid_links : sequence of RigidLink
        RBE2-like links (chains allowed: a master may be the slave of another link).
    interpolating_links : sequence of InterpolatingLink
        RBE3-like links: a reference node follows the average motion of a patch.
    shells : dict[str, ShellProperty], optional
        Cell-set name → property of its triangle and quad cells (flat shell elements of
        :mod:`femmech.fe.elements.shell`, sharing nodes and DOFs with beams); every such
        cell needs exactly one. quad9 and quad8 cells are MITC9 shells
        (:mod:`femmech.fe.elements.shell9`); each quad8 cell gets a centre node
        (:func:`femmech.fe.mesh.quad8_to_quad9`), appended after the mesh's nodes (or
        the node already at its centre), and the model's mesh is the converted one. On
        a quad8 cell whose eight nodes all belong to solid elements (a skin on a solid
        face) an added centre node's translations follow the serendipity interpolation
        of the eight (constraint equations in ``T``, :attr:`FEModel.tied`;
        :mod:`femmech.fe.elements.shell9`, "quad8 meshes").
    solids : dict[str, SolidProperty], optional
        Cell-set name → property of its tetra, tetra10, hexahedron, hexahedron20 and
        hexahedron27 cells (:mod:`femmech.fe.elements.solid`, translations only); every such
        cell needs exactly one. A node shared with a beam or shell couples translations
        only; join a beam end to a patch of solid nodes with a rigid or interpolating
        link to transmit moments (:mod:`femmech.fe.parts`).
    node_tol : float, optional
        Distance (m) below which two nodes that nothing joins are reported as nearly
        coincident; default :data:`femmech.fe.checks.NEAR_NODE_TOL` times the model size.

    Raises
    ------
    ValueError
        Naming the offending element, node or group: unknown group names, elements
        without or with two properties, unused nodes, coincident nodes that no spring or
        rigid link joins, zero-length elements, orientation vectors along an element.

    Warns
    -----
    ModelWarning
        For each finding of :func:`model_findings` (nearly coincident nodes, loose parts,
        unit mix-ups, badly shaped shell elements), naming the nodes, elements, groups
        and values.
    """
    beams = {} if beams is None else beams
    shells = {} if shells is None else shells
    solids = {} if solids is None else solids
    _check_arguments(mesh, beams, masses, springs, supports, rigid_links, interpolating_links,
                     shells, solids)
    centres = quad8_centres(mesh)
    mesh = quad8_to_quad9(mesh)  # MITC9 shells: quad8 cells get their centre nodes
    beam_set, Ke, Me, edofs = _beam_blocks(mesh, beams, bool(shells), bool(solids))
    shell_set, shell_stiff, shell_mass = shell_blocks(mesh, shells)
    n_dof = DOF_PER_NODE * mesh.n_nodes
    solid_set, solid_stiff, solid_mass = solid_parts(mesh, solids, n_dof)
    stiff_blocks = [(edofs, Ke)] + shell_stiff
    mass_blocks = [(edofs, Me)] + shell_mass
    used = np.zeros(mesh.n_nodes, dtype=bool)
    used[beam_set.cells.ravel()] = True
    for cells in (*shell_set.cells.values(), *solid_set.cells.values()):
        used[cells.ravel()] = True
    joined, mass_nodes = _lumped_blocks(mesh, masses, springs, stiff_blocks, mass_blocks, used)
    masters, slaves, labels = _rigid_pairs(mesh, rigid_links)
    spiders = _spider_nodes(mesh, interpolating_links)
    for m, s in [(masters, slaves)] + [(np.full(p.size, r), p) for r, p, _, _ in spiders]:
        used[m] = True
        used[s] = True
        joined.extend(zip(m.tolist(), s.tolist(), strict=True))
    _check_nodes(mesh, used, joined)
    skin = _skin_centres(centres, solid_set, mesh.n_nodes)
    fixed, eqs, tied = _constraint_equations(mesh, n_dof, supports, masters, slaves, labels,
                                             spiders, skin)
    K = sum(solid_stiff, assemble(stiff_blocks, n_dof)).tocsr()
    M = sum(solid_mass, assemble(mass_blocks, n_dof)).tocsr()
    inactive = _inactive_rotations(solid_set, K, M, eqs)
    T, free = constraint_transform(n_dof, fixed | inactive, eqs)
    Tt = T.T.tocsr()
    links = np.array(joined, dtype=np.int64).reshape(-1, 2)
    checks.warn(model_findings(mesh, beams, masses, springs, supports, rigid_links,
                               interpolating_links, shells, solids, node_tol=node_tol))
    return FEModel(mesh, K, M, T, free, beam_set, np.array(mass_nodes, dtype=np.int64), links,
                   (Tt @ K @ T).tocsr(), (Tt @ M @ T).tocsr(), shell_set, solid_set,
                   np.flatnonzero(inactive),
                   dict(beams=beams, masses=masses, springs=springs, supports=supports,
                        rigid_links=rigid_links, interpolating_links=interpolating_links,
                        shells=shells, solids=solids, node_tol=node_tol), tied)


def _check_arguments(mesh, beams, masses, springs, supports, rigid_links, interpolating_links,
                     shells, solids) -> None:
    """Types of :func:`build_model`'s arguments (TypeError, ValueError for an empty mesh)."""
    if not isinstance(mesh, Mesh):
        raise TypeError(f"mesh must be a Mesh, got {type(mesh).__name__}")
    if mesh.n_nodes == 0:
        raise ValueError("the mesh has no nodes")
    _check_types(beams, masses, springs, supports, rigid_links, interpolating_links)
    check_part_types(shells, solids)


def _lumped_blocks(mesh: Mesh, masses, springs, stiff_blocks: list, mass_blocks: list,
                   used: np.ndarray) -> tuple[list, list]:
    """Add the blocks of point masses and springs, mark their nodes used.

    Appends to ``stiff_blocks`` and ``mass_blocks`` and sets ``used`` in place; returns the
    node pairs the springs join and the nodes of the point masses.
    """
    joined, mass_nodes = [], []
    for item in masses:
        node = node_index(mesh, item.node, "point mass")
        mass_nodes.append(node)
        mass_blocks.append((node_dofs([node])[None, :], item.matrix()[None]))
        used[node] = True
    for item in springs:
        k = item.matrix()
        a = node_index(mesh, item.node_a, "spring")
        used[a] = True
        if item.node_b is None:
            stiff_blocks.append((node_dofs([a])[None, :], k[None]))
            continue
        b = node_index(mesh, item.node_b, "spring")
        if a == b:
            raise ValueError(f"spring {item.node_a!r}-{item.node_b!r} connects node {a} to itself")
        used[b] = True
        joined.append((a, b))
        stiff_blocks.append((node_dofs([a, b])[None, :], np.block([[k, -k], [-k, k]])[None]))
    return joined, mass_nodes


def _constraint_equations(mesh: Mesh, n_dof: int, supports, masters, slaves, labels,
                          spiders, centres) -> tuple[np.ndarray, EquationSet, np.ndarray]:
    """Mask (n_dof,) of supported DOFs, the equations of rigid links, quad8 centre nodes
    on solid faces (``centres``: :func:`_skin_centres`) and interpolating links, and the
    tied centre DOFs (n_tied,).

    A centre node's translations follow the serendipity interpolation of its eight
    nodes (:func:`femmech.fe.constraints.add_interpolated_nodes`), except for the DOFs
    that a support fixes, a rigid link makes dependent or a link uses as its master or
    reference: these keep that role.
    """
    fixed = np.zeros(n_dof, dtype=bool)
    for item in supports:
        fixed |= fixed_mask(mesh.n_nodes, node_indices(mesh, item.nodes, "support"), item.dofs)
    eqs = EquationSet.empty()
    add_rigid_links(eqs, mesh.points, masters, slaves, labels)
    substitution, tied = None, np.empty(0, dtype=np.int64)
    if len(centres[0]):
        blocked = fixed.copy()
        blocked[eqs.dependent()] = True
        roles = np.concatenate([masters, [r for r, _, _, _ in spiders]]).astype(np.int64)
        blocked[node_dofs(roles).ravel()] = True
        before = len(eqs.owner)
        substitution = add_interpolated_nodes(eqs, n_dof, *centres, QUAD8_CENTRE,
                                              "translations", blocked,
                                              "quad8 centre node tie")
        if len(eqs.owner) > before:
            tied = np.sort(eqs.owner[-1][0])
    for reference, patch, weights, label in spiders:
        blocked = fixed.copy()
        blocked[eqs.dependent()] = True
        add_interpolating_link(eqs, mesh.points, reference, patch, weights, blocked, label,
                               substitution)
    return fixed, eqs, tied


def _skin_centres(centres, solid_set: SolidSet, n_nodes: int):
    """The quad8 centre nodes (and their eight nodes) of the quad8 cells whose eight
    nodes all belong to solid elements: skins and coatings on a solid face.

    ``centres``: :func:`femmech.fe.mesh.quad8_centres`. Such a centre node is held by
    nothing but the (usually thin) shell while the eight others move with the solid;
    left free, its transverse motion is a local mode of the skin alone (a steel
    cantilever with a 0.1 mm quad8 skin on its end: four extra modes from 5.1 kHz,
    between the solid's first (1.61 kHz) and second (7.30 kHz) modes).
    :func:`_constraint_equations` ties its translations to the serendipity
    interpolation of the eight, the kinematics of the file's 8-node element; its
    rotations stay free (a skin's rotations are held by its transverse shear, local
    frequencies near ``sqrt(12 k G / ρ) / (2 π t)``, 16 MHz at t = 0.1 mm). The
    centre nodes of other quad8 shells stay MITC9 centre nodes: a free shell has no
    such local mode, and the 9-node element is the more accurate (module docstring of
    :mod:`femmech.fe.elements.shell9`).
    """
    nodes, parents = centres
    if not len(nodes) or not solid_set.cells:
        return nodes[:0], parents[:0]
    solid = np.zeros(n_nodes, dtype=bool)
    for cells in solid_set.cells.values():
        solid[cells.ravel()] = True
    on_face = solid[parents].all(axis=1)
    return nodes[on_face], parents[on_face]


def _inactive_rotations(solid_set: SolidSet, K, M, eqs: EquationSet) -> np.ndarray:
    """Mask (n_dof,) of rotations of solid nodes with zero K and M diagonals that no
    constraint equation names (K, M are semi-definite: a zero diagonal is a zero row)."""
    mask = np.zeros(K.shape[0], dtype=bool)
    if not solid_set.cells:
        return mask
    nodes = np.unique(np.concatenate([c.ravel() for c in solid_set.cells.values()]))
    mask[(DOF_PER_NODE * nodes[:, None] + np.arange(3, 6)).ravel()] = True
    mask &= (K.diagonal() == 0) & (M.diagonal() == 0)
    for part in eqs.rows + eqs.cols:
        mask[part] = False
    return mask


def _check_types(beams, masses, springs, supports, rigid_links, interpolating_links):
    if not isinstance(beams, Mapping):
        raise TypeError(f"beams must be a dict {{cell-set name: BeamProperty}},"
                        f" got {type(beams).__name__}")
    for label, items, kind in (("masses", masses, PointMass), ("springs", springs, Spring),
                               ("supports", supports, Support),
                               ("rigid_links", rigid_links, RigidLink),
                               ("interpolating_links", interpolating_links,
                                InterpolatingLink)):
        if isinstance(items, (kind, str, Mapping)) or not hasattr(items, "__iter__"):
            raise TypeError(f"{label} must be a sequence of {kind.__name__},"
                            f" got {type(items).__name__} (wrap a single item in a list)")
        for i, item in enumerate(items):
            if not isinstance(item, kind):
                raise TypeError(f"{label}[{i}] must be a {kind.__name__},"
                                f" got {type(item).__name__}")
    for name, prop in beams.items():
        if not isinstance(prop, BeamProperty):
            raise TypeError(f"beams[{name!r}] must be a BeamProperty, got {type(prop).__name__}")
        if not isinstance(prop.section, BeamSection) or not isinstance(prop.material, Material):
            raise TypeError(f"beams[{name!r}]: section must be a BeamSection and material a"
                            " Material")


def _beam_blocks(mesh: Mesh, beams: dict[str, BeamProperty], with_shells: bool = False,
                 with_solids: bool = False):
    shell_kinds, solid_kinds = kinds("shell"), kinds("solid")
    known = ("line",) + (shell_kinds if with_shells else ()) + (solid_kinds if with_solids
                                                               else ())
    unsupported = [k for k, v in mesh.cells.items() if k not in known and len(v)]
    if unsupported:
        raise ValueError(f"the mesh has {unsupported} cells, which have no element property;"
                         " build_model supports line (beam) cells, with shell properties"
                         f" {shell_kinds} cells and with solid properties {solid_kinds}"
                         " cells")
    lines = mesh.cells.get("line", np.empty((0, 2), dtype=np.int64))
    owner = np.full(len(lines), -1)
    names = list(beams)
    for g, name in enumerate(names):
        if name not in mesh.cell_sets:
            raise ValueError(f"beam property for {mesh.unknown_cell_set(name)}")
        idx = mesh.cell_sets[name].get("line", np.empty(0, dtype=np.int64))
        twice = idx[owner[idx] >= 0]
        if twice.size:
            raise ValueError(f"line element {twice[0]} is in groups {names[owner[twice[0]]]!r}"
                             f" and {name!r}, both with beam properties")
        owner[idx] = g
    missing = np.flatnonzero(owner < 0)
    if missing.size:
        e = missing[0]
        groups = [n for n, s in mesh.cell_sets.items() if e in s.get("line", ())]
        raise ValueError(f"line element {e} (nodes {lines[e].tolist()}) has no beam property"
                         f" ({missing.size} such elements); its groups: {groups}")
    props = [beams[n] for n in names]
    orient = _orientations(mesh, lines, owner, props, names)
    R, length = local_frames(mesh.points, lines, orient)
    table = np.array([_property_row(p) for p in props]).reshape(len(props), 12)
    rows = table[owner] if len(lines) else np.zeros((0, 12))
    E, G, rho, A, Iy, Iz, J, Ip, Asy, Asz, rot, radius = rows.T
    Ke, Me = beam_matrices(mesh.points, lines, orient, E, G, rho, A, Iy, Iz, J, Ip, Asy, Asz,
                           rotary_inertia=rot)
    group = np.array(names, dtype=object)[owner] if len(lines) else np.empty(0, dtype=object)
    phi = 12.0 * E[:, None] * np.column_stack([Iz, Iy]) / (
        G[:, None] * np.column_stack([Asy, Asz]) * length[:, None] ** 2)
    return (BeamSet(lines, R, length, radius, group, phi, rows[:, :11]), Ke, Me,
            element_dofs(lines))


def _property_row(p: BeamProperty) -> list[float]:
    s, m = p.section, p.material
    inf = np.inf
    asy = s.Asy if (p.shear and s.Asy is not None) else inf
    asz = s.Asz if (p.shear and s.Asz is not None) else inf
    return [m.E, m.shear_modulus, m.rho, s.A, s.Iy, s.Iz, s.J, s.polar_moment, asy, asz,
            float(p.rotary_inertia), s.draw_radius]


def _orientations(mesh, lines, owner, props, names=None) -> np.ndarray:
    """Per-element orientation vectors in the local x-y plane; groups without one use the
    default rule, vectors given in the x-z plane are converted (:func:`xz_to_xy`).
    ``names`` (of the groups, for messages) defaults to their positions."""
    R_default, _ = local_frames(mesh.points, lines, None) if len(lines) else (np.zeros((0, 3, 3)),
                                                                              None)
    orient = R_default[:, 1, :].copy()
    names = list(range(len(props))) if names is None else names
    for g, p in enumerate(props):
        if p.orientation_plane not in ("xy", "xz"):
            raise ValueError(f"beams[{names[g]!r}]: orientation_plane must be 'xy' or 'xz',"
                             f" got {p.orientation_plane!r}")
        if p.orientation is not None:
            v = np.asarray(p.orientation, dtype=float)
            if v.shape != (3,) or not np.isfinite(v).all() or not np.any(v):
                raise ValueError(f"orientation of a beam group must be a non-zero 3-vector,"
                                 f" got {p.orientation!r}")
            mine = np.flatnonzero(owner == g)
            orient[mine] = v if p.orientation_plane == "xy" else xz_to_xy(
                R_default[mine, 0, :], v, f"beams[{names[g]!r}]", mine)
    return orient


def xz_to_xy(ex: np.ndarray, v: np.ndarray, label: str = "orientation",
             elements=None) -> np.ndarray:
    """Local y axes (n, 3) of elements with axes ``ex`` (n, 3, unit) from a vector ``v``
    (3,) in their local x-z plane: z = normalised part of ``v`` normal to x, y = z × x.

    Raises ValueError naming ``label`` and the element (``elements[i]``, default i) if
    ``v`` is parallel to an axis.
    """
    ez = v - (ex @ v)[:, None] * ex
    nz = np.linalg.norm(ez, axis=1)
    bad = np.flatnonzero(~(nz > 1e-6 * np.linalg.norm(v)))
    if bad.size:
        e = int(bad[0] if elements is None else elements[bad[0]])
        raise ValueError(f"{label}: orientation vector {v.tolist()} (orientation_plane 'xz')"
                         f" is parallel to the axis {ex[bad[0]].round(6).tolist()} of line"
                         f" element {e}")
    ez /= nz[:, None]
    return np.cross(ez, ex)


def node_index(mesh: Mesh, ref, what: str) -> int:
    """Node index from an int or from a group that holds exactly one node."""
    nodes = node_indices(mesh, ref, what)
    if nodes.size != 1:
        raise ValueError(f"{what}: group {ref!r} holds {nodes.size} nodes; exactly one expected")
    return int(nodes[0])


def node_indices(mesh: Mesh, ref, what: str) -> np.ndarray:
    """Node indices from a group name, an int or a sequence of ints (checked)."""
    if isinstance(ref, str):
        try:
            return mesh.nodes_of(ref)
        except ValueError as exc:
            raise ValueError(f"{what}: {exc}") from None
    nodes = np.atleast_1d(np.asarray(ref))
    if nodes.size == 0:  # an empty list is float by default
        return np.empty(0, dtype=np.int64)
    if not np.issubdtype(nodes.dtype, np.integer):
        raise TypeError(f"{what}: nodes must be a group name or node indices, got {ref!r}")
    bad = nodes[(nodes < 0) | (nodes >= mesh.n_nodes)]
    if bad.size:
        raise ValueError(f"{what}: node {bad[0]} does not exist (the mesh has"
                         f" {mesh.n_nodes} nodes)")
    return nodes.astype(np.int64)


def _rigid_pairs(mesh: Mesh, links):
    """Master, slave and label per slave node of all rigid links."""
    masters, slaves, labels = [], [], []
    for link in links:
        m = node_index(mesh, link.master, "rigid link master")
        s = node_indices(mesh, link.slaves, "rigid link slaves")
        s = s[s != m]
        if s.size == 0:
            raise ValueError(f"rigid link with master {link.master!r} has no slave nodes")
        masters.append(np.full(s.size, m))
        slaves.append(s)
        labels.extend([f"rigid link (master {m})"] * s.size)
    if not masters:
        return np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64), []
    return np.concatenate(masters), np.concatenate(slaves), labels


def _spider_nodes(mesh: Mesh, links):
    """(reference, patch, weights, label) of each interpolating link."""
    out = []
    for link in links:
        r = node_index(mesh, link.reference, "interpolating link reference")
        p = node_indices(mesh, link.patch, "interpolating link patch")
        p = np.unique(p[p != r])
        out.append((r, p, link.weights, f"interpolating link (reference {r})"))
    return out


def _check_nodes(mesh: Mesh, used: np.ndarray, joined) -> None:
    unused = np.flatnonzero(~used)
    if unused.size:
        raise ValueError(f"node {unused[0]} at {mesh.points[unused[0]].tolist()} is not used by"
                         f" any element, mass, spring or rigid link ({unused.size} unused nodes)")
    scale = max(float(np.ptp(mesh.points, axis=0).max()), 1e-300)
    pairs = cKDTree(mesh.points).query_pairs(1e-9 * scale, output_type="ndarray")
    if pairs.size:
        ok = {tuple(sorted(p)) for p in joined}
        for a, b in pairs:
            if (min(a, b), max(a, b)) not in ok:
                raise ValueError(f"nodes {a} and {b} coincide at {mesh.points[a].tolist()} but no"
                                 " spring or rigid link joins them; merge them (duplicate nodes)")


def model_findings(mesh: Mesh, beams=None, masses=(), springs=(), supports=(), rigid_links=(),
                   interpolating_links=(), shells=None, solids=None, anchors=(),
                   node_tol: float | None = None) -> tuple[checks.Finding, ...]:
    """Suspicious inputs of :func:`build_model` (same arguments), without assembly.

    Nearly coincident nodes that nothing joins, pieces that are free bodies by accident,
    unit mix-ups and badly shaped shell elements (:mod:`femmech.fe.checks`). ``anchors``:
    further nodes held from outside the model (group names or node indices, e.g. the
    attachments of mechanisms), so that a piece holding one is not reported as loose.
    References are resolved as in :func:`build_model` (ValueError naming the item when one
    does not exist).
    """
    beams, shells, solids = beams or {}, shells or {}, solids or {}
    joined, held = [], [node_indices(mesh, a, "anchor") for a in anchors]
    held += [node_indices(mesh, s.nodes, "support") for s in supports]
    for item in springs:
        a = node_index(mesh, item.node_a, "spring")
        if item.node_b is None:
            held.append(np.array([a]))
        else:
            joined.append((a, node_index(mesh, item.node_b, "spring")))
    masters, slaves, _ = _rigid_pairs(mesh, rigid_links)
    joined += zip(masters.tolist(), slaves.tolist(), strict=True)
    joined += [(r, q) for r, p, _, _ in _spider_nodes(mesh, interpolating_links) for q in p]
    points = mesh.points
    materials, sections, element_mass = {}, [], 0.0
    families = ((beams, ("line",)), (shells, kinds("shell")), (solids, kinds("solid")))
    for props, group_kinds in families:
        for group, prop in props.items():
            m = prop.material
            key = m.name if materials.get(m.name, (m.E, m.rho)) == (m.E, m.rho) \
                else f"{m.name} ({group})"
            materials[key] = (m.E, m.rho)
            per_area = prop.section.A if props is beams else \
                (prop.thickness if props is shells else 1.0)
            for kind, idx in mesh.cell_sets.get(group, {}).items():
                if kind in group_kinds and len(idx):
                    cells = mesh.cells[kind][idx]
                    element_mass += m.rho * per_area * float(
                        checks.cell_measure(points, kind, cells).sum())
                    if props is beams:
                        span = float(np.linalg.norm(np.ptp(points[cells.ravel()], axis=0)))
                        sections.append((group, 2.0 * prop.section.draw_radius, span))
    masses = [(node_index(mesh, m.node, "point mass"), float(m.mass)) for m in masses]
    cells = {k: c for k, c in mesh.cells.items() if k != "vertex"}
    extent = float(np.linalg.norm(np.ptp(points, axis=0)))
    held = np.concatenate(held) if held else np.empty(0, dtype=np.int64)
    return tuple(checks.near_node_findings(points, cells, joined, node_tol)
                 + checks.loose_parts(mesh.n_nodes, cells, joined, held)
                 + checks.unit_findings(extent, materials, sections, masses, element_mass)
                 + checks.shape_findings(points, cells, checks.cell_groups(
                     mesh.cell_sets, list(shells), {k: c for k, c in cells.items()
                                                    if k in kinds("shell")})))
