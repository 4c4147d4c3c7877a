"""Mass properties and modal participation: how much mass each mode moves per direction.

For mass-normalised modes φ_k (``φ_kᵀ M φ_k = 1``) and the rigid-body influence vector
r_d of direction d (unit translation along x, y, z, or unit rotation about an axis
parallel to x, y, z through a reference point), the participation factor is
``Γ_kd = φ_kᵀ M r_d`` (kg^½; kg^½ m for rotations) and the effective modal mass
``m_eff,kd = Γ_kd²`` (kg; kg m² for rotations). The modes are expansions
``φ = T φ_free`` of the free DOFs, so supports and links are respected through the
model's constraint transformation T; the formulas use the unconstrained M.

The reference of each direction is its rigid-body mass ``m_d = r_dᵀ M r_d``: the total
mass for translations, the moment of inertia about the axis for rotations. For a model
without supports (free-free, or on springs) r_d lies in the span of T and the effective
masses of all modes sum to m_d exactly (completeness of the M-orthonormal modes). For a
supported model the sum over all modes is the M-projection of r_d onto the free
motions, ``bᵀ M_free⁻¹ b`` with ``b = Tᵀ M r_d`` (:func:`reachable_masses`): the
remainder is mass that moves with the supports and appears in no mode (for a fine
mesh, a small part of the elements next to the supports).

Mass properties (total mass, centre of mass, inertia tensor) come from M and the
rigid-body vectors, not from element formulas, so point masses and every element kind
count. :func:`element_group_masses` gives the share of each element group (density
times length·area, area·thickness or volume) for a cross-check against M.

Uses fe (checks.cell_measure, dofs, model) and solve (factorize, the
rigid-body vectors of :func:`femmech.solve.lobpcg.rigid_body_modes`);
pure functions on arrays, plus :func:`participation` for an FEModel and a ModeSet.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femmech.fe.checks import cell_measure
from femmech.fe.dofs import DOF_PER_NODE
from femmech.fe.model import BEAM_PROPERTY_COLUMNS, FEModel
from femmech.solve.lobpcg import rigid_body_modes

DIRECTIONS = ("x", "y", "z", "rx", "ry", "rz")
"""The six rigid-body directions: translations along and rotations about x, y, z."""

UNITS = ("kg", "kg", "kg", "kg·m²", "kg·m²", "kg·m²")
"""Unit of the effective mass of each direction in :data:`DIRECTIONS`."""


def rigid_body_vectors(points, reference=(0.0, 0.0, 0.0), rotations=None) -> np.ndarray:
    """Rigid-body influence vectors of the six directions, shape (6 n_nodes, 6).

    Column d is the DOF vector (node-interleaved ``ux, uy, uz, rx, ry, rz``) of a unit
    rigid motion: for d < 3 a unit translation (m) along axis d; for d >= 3 a unit
    rotation (rad) about the axis parallel to axis d - 3 through ``reference``, whose
    translations are ``e × (x - reference)``.

    Parameters
    ----------
    points : array_like (n_nodes, 3), m
    reference : array_like (3,), m
        Point on the rotation axes.
    rotations : array_like (n_nodes,) of bool, optional
        False for nodes without rotational DOFs (nodes of solid elements only): their
        rotation components stay 0. Default: every node has them (beams, shells).
    """
    x = np.asarray(points, dtype=float)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"points must have shape (n_nodes, 3), got {np.shape(points)}")
    n = len(x)
    R = rigid_body_modes(x, np.arange(DOF_PER_NODE * n), center=reference)
    if rotations is not None:
        R.reshape(n, DOF_PER_NODE, 6)[~np.asarray(rotations, dtype=bool), 3:, :] = 0.0
    return R


def participation_factors(shapes, M, R) -> np.ndarray:
    """``Γ = Φᵀ M R``, shape (n_modes, 6): kg^½ (translations), kg^½ m (rotations).

    Parameters
    ----------
    shapes : ndarray (n_dof, n_modes)
        Mass-normalised mode shapes on all DOFs.
    M : sparse or dense (n_dof, n_dof)
        Unconstrained mass matrix, kg and kg m².
    R : ndarray (n_dof, 6)
        Rigid-body vectors (:func:`rigid_body_vectors`).
    """
    shapes = np.asarray(shapes, dtype=float)
    if shapes.ndim != 2 or shapes.shape[0] != R.shape[0]:
        raise ValueError(f"shapes must have shape (n_dof={R.shape[0]}, n_modes), got"
                         f" {shapes.shape}")
    return shapes.T @ np.asarray(M @ R)


def rigid_body_masses(M, R) -> np.ndarray:
    """``diag(Rᵀ M R)``, shape (6,): mass (kg) of each translation and moment of
    inertia (kg m²) about each rotation axis of ``R``."""
    return np.einsum("id,id->d", R, np.asarray(M @ R))


def reachable_masses(M_free, T, M, R) -> np.ndarray | None:
    """Sum of the effective masses over all modes, shape (6,): ``bᵀ M_free⁻¹ b``,
    ``b = Tᵀ M R`` (the M-norm of the projection of each r_d onto the free motions).

    Equals :func:`rigid_body_masses` for a model without supports; less by the mass that
    moves with the supports otherwise. None if ``M_free`` is singular (massless free
    DOFs), where the projection is undefined.
    """
    from femmech.solve.direct import factorize

    b = np.asarray(T.T @ np.asarray(M @ R))
    try:
        factor = factorize(M_free, definite=True)
    except ValueError:  # not positive definite: a free DOF without mass
        return None
    return np.einsum("id,id->d", b, factor.solve(b))


@dataclass(frozen=True)
class MassProperties:
    """Rigid-body mass properties of a model.

    Attributes
    ----------
    total : float
        Mass, kg (mean of the three translational rigid-body masses).
    centre : ndarray (3,)
        Centre of mass, m.
    inertia : ndarray (3, 3)
        Inertia tensor about the centre of mass in global axes, kg m².
    """

    total: float
    centre: np.ndarray
    inertia: np.ndarray


def mass_properties(M, points, rotations=None) -> MassProperties:
    """Total mass, centre of mass and inertia tensor from M and rigid-body vectors.

    The 6x6 rigid-body mass matrix about the origin, ``R₀ᵀ M R₀``, has the block
    ``m [c]ₓᵀ`` between translations and rotations (``e_j × c`` for a rotation about
    axis j); its antisymmetric part gives the centre c. The inertia tensor is the rotation
    block of ``R_cᵀ M R_c``. Point masses and rotary inertias in M count.

    Parameters
    ----------
    M : sparse or dense (6 n_nodes, 6 n_nodes)
    points : array_like (n_nodes, 3), m
    rotations : array_like (n_nodes,) of bool, optional
        As in :func:`rigid_body_vectors`.

    Raises
    ------
    ValueError
        If the model has no mass.
    """
    R0 = rigid_body_vectors(points, rotations=rotations)
    G = R0.T @ np.asarray(M @ R0)
    total = float(np.trace(G[:3, :3]) / 3.0)
    if not total > 0:
        raise ValueError(f"the model has no mass (total translational mass {total} kg)")
    S = G[:3, 3:]  # S[i, j] = m (e_j × c)_i
    centre = np.array([S[1, 2] - S[2, 1], S[2, 0] - S[0, 2], S[0, 1] - S[1, 0]]) / (2 * total)
    Rc = rigid_body_vectors(points, centre, rotations)[:, 3:]
    inertia = Rc.T @ np.asarray(M @ Rc)
    return MassProperties(total, centre, 0.5 * (inertia + inertia.T))


@dataclass(frozen=True)
class Participation:
    """Modal participation of a set of modes in the six rigid-body directions.

    Attributes
    ----------
    gamma : ndarray (n_modes, 6)
        Participation factors Γ, kg^½ (x, y, z) and kg^½ m (rx, ry, rz).
    effective_mass : ndarray (n_modes, 6)
        ``Γ²``, kg and kg m².
    rigid_mass : ndarray (6,)
        ``r_dᵀ M r_d``: total mass (kg) and moments of inertia about the rotation axes
        (kg m²): the reference of the fractions.
    reference : ndarray (3,)
        Point on the rotation axes, m.
    reachable : ndarray (6,) or None
        Sum of the effective masses over all modes of the model
        (:func:`reachable_masses`), None if not computed.
    """

    gamma: np.ndarray
    effective_mass: np.ndarray
    rigid_mass: np.ndarray
    reference: np.ndarray
    reachable: np.ndarray | None = None

    @property
    def cumulative(self) -> np.ndarray:
        """Running sums of the effective masses over the modes, (n_modes, 6)."""
        return np.cumsum(self.effective_mass, axis=0)

    @property
    def cumulative_fraction(self) -> np.ndarray:
        """Running sums divided by :attr:`rigid_mass`, (n_modes, 6); NaN for a direction
        without mass."""
        return cumulative_fractions(self.effective_mass, self.rigid_mass)


def cumulative_fractions(effective_mass, rigid_mass) -> np.ndarray:
    """``cumsum(m_eff) / m_d`` over the modes (axis 0), NaN where ``m_d`` is 0."""
    m_eff = np.asarray(effective_mass, dtype=float)
    total = np.asarray(rigid_mass, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(total > 0, np.cumsum(m_eff, axis=0) / np.where(total > 0, total, 1),
                        np.nan)


def modal_participation(shapes, M, R, reference=(0.0, 0.0, 0.0)) -> Participation:
    """:class:`Participation` of mass-normalised ``shapes`` (n_dof, n_modes) for the
    rigid-body vectors ``R`` (n_dof, 6) built about ``reference`` (m)."""
    gamma = participation_factors(shapes, M, R)
    return Participation(gamma, gamma**2, rigid_body_masses(M, R),
                         np.asarray(reference, dtype=float))


def node_rotations(model: FEModel) -> np.ndarray:
    """(n_nodes,) bool: False for nodes whose rotations are inactive (solid-only nodes)."""
    rotations = np.ones(model.mesh.n_nodes, dtype=bool)
    inactive = np.asarray(model.inactive, dtype=np.int64)
    counts = np.bincount(inactive // DOF_PER_NODE, minlength=model.mesh.n_nodes)
    rotations[counts == 3] = False
    return rotations


def participation(model: FEModel, mode_set, reference=None,
                  reachable: bool = False) -> Participation:
    """Modal participation of the modes of ``model`` (a :class:`ModeSet` of it or of its
    superelement, whose shapes are recovered to all DOFs).

    Parameters
    ----------
    model : FEModel
    mode_set : femmech.analysis.modes.ModeSet
    reference : array_like (3,), optional
        Point on the rotation axes (m); default the centre of mass.
    reachable : bool
        Also compute :func:`reachable_masses` (one factorisation of M_free).
    """
    rotations = node_rotations(model)
    if reference is None:
        reference = mass_properties(model.M, model.mesh.points, rotations).centre
    R = rigid_body_vectors(model.mesh.points, reference, rotations)
    out = modal_participation(mode_set.shapes, model.M, R, reference)
    if reachable:
        out = Participation(out.gamma, out.effective_mass, out.rigid_mass, out.reference,
                            reachable_masses(model.M_free, model.T, model.M, R))
    return out


@dataclass(frozen=True)
class GroupMass:
    """Mass of the elements of one cell group: ``kind`` (beam, shell, solid), number of
    elements, mass (kg)."""

    kind: str
    n_elements: int
    mass: float


def element_group_masses(model: FEModel, densities=None) -> dict[str, GroupMass]:
    """Mass of each element group from its geometry: ρ A L (beams), ρ t · area (shells),
    ρ · volume (solids), kg. These are the translational masses that the consistent mass
    matrices integrate; point masses are not included (compare the sum with
    :func:`mass_properties`).

    Parameters
    ----------
    model : FEModel
    densities : dict[str, float], optional
        Density (kg/m³) of each shell and solid group (the model keeps the beams' own).

    Raises
    ------
    KeyError
        Naming a shell or solid group without a density.
    """
    densities = {} if densities is None else densities
    out: dict[str, list] = {}

    def add(kind, groups, masses):
        for name in np.unique(groups):
            pick = groups == name
            entry = out.setdefault(str(name), [kind, 0, 0.0])
            entry[1] += int(pick.sum())
            entry[2] += float(masses[pick].sum())

    beams = model.beams
    if len(beams.cells):
        rho = beams.properties[:, BEAM_PROPERTY_COLUMNS.index("rho")]
        area = beams.properties[:, BEAM_PROPERTY_COLUMNS.index("A")]
        add("beam", np.asarray(beams.group), rho * area * beams.length)
    points = model.mesh.points
    for kind, part in (("shell", model.shells), ("solid", model.solids)):
        for cell_kind, cells in part.cells.items():
            groups = np.asarray(part.group[cell_kind])
            missing = sorted(set(groups.tolist()) - set(densities))
            if missing:
                raise KeyError(f"no density for the {kind} group(s) {missing}")
            rho = np.array([densities[g] for g in groups], dtype=float)
            size = cell_measure(points, cell_kind, cells)
            if kind == "shell":
                size = size * part.thickness[cell_kind]
            add(kind, groups, rho * size)
    return {name: GroupMass(*entry) for name, entry in out.items()}
