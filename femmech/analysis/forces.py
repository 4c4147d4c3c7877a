"""Force recovery from time histories: attachment (bearing), drive, support and section forces.

Sign convention (first three functions): a force is the generalized force in the positive
direction of the coordinate it belongs to.

* :func:`attachment_forces` returns the force the **mechanism exerts on the frame**
  along the attachment direction ``L u`` (N for a displacement direction, N m for a
  rotation). For an elastic attachment (bearing spring/damper ``½ k (q_c − L u)²``) it
  is the spring/damper force ``k (q_c − L u) + c (q̇_c − L u̇)``; for a rigid attachment
  (primal form: q_c = L u) it is the mechanism's generalized force in that coordinate,
  ``−(M_m q̈_m + B_m q̇_m + C_m q_m − F_m)_c`` (the equation row of the mechanism alone:
  whatever is not balanced inside the mechanism is carried by the frame). Both are the
  same physical force: the elastic one tends to the rigid one as k → ∞.
* :func:`drive_forces` returns the generalized force the drive must supply to keep the
  programmed motion (seed 5.2.2 eq. 2 for j = n+1; seed 5.2.3.1 eq. 17 for the crane's
  cylinder force): the drive row of the nonlinear 2nd-kind equations (seed 5.2.1 eq. 13)
  ``Q_d = (M q̈ + h(q, q̇) + W_pot,q − Q*)_d`` evaluated on the programmed motion plus
  the vibration coordinates of a response (N m for an angle, N for a length).
* :func:`support_reactions` returns the force a support exerts on the frame.
* :func:`beam_section_forces` returns section forces of beam elements in their local
  axes, with the beam convention stated in :class:`SectionForces` (not the coordinate
  convention above).

Uses analysis.response, coupling, reduction and fe; nothing here writes
files.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femmech.analysis.response import drive_angles, frame_history, node_component
from femmech.coupling import CoupledSystem, frame_row
from femmech.fe.dofs import COMPONENTS, DOF_PER_NODE
from femmech.fe.elements.beam import local_matrices
from femmech.fe.model import FEModel
from femmech.reduction.substructures import Assembly


@dataclass(frozen=True)
class AttachmentForces:
    """Attachment force histories.

    Attributes
    ----------
    labels : tuple of str
        ``"mount.coordinate"`` per attachment (in mount and attachment order).
    rigid : ndarray of bool (n_att,)
        True for rigid attachments (force from the mechanism's equation row).
    forces : ndarray (n_t, n_att)
        Force exerted by the mechanism on the frame along the attachment direction,
        N or N m.
    """

    labels: tuple
    rigid: np.ndarray
    forces: np.ndarray


def _mechanism_states(system: CoupledSystem, index: int, response):
    """q_m, q̇_m, q̈_m (n_t, n_m) of mount ``index`` from the global histories."""
    P, idx = system.projections[index], system.touched[index]
    return tuple(np.asarray(x)[:, idx] @ P.T for x in (response.q, response.v, response.a))


def _mechanism_rows(mount, states, drive_state):
    """−(M_m q̈ + B_m q̇ + C_m q − F_m) (n_t, n_m) of one mount."""
    phi, Omega, Omega_dot = drive_state
    angle = mount.ratio * phi + mount.phase
    speed, accel = mount.ratio * Omega, mount.ratio * Omega_dot
    m = mount.model
    q, v, a = states
    residual = (np.einsum("tij,tj->ti", m.M(angle), a)
                + np.einsum("tij,tj->ti", m.B(angle, speed), v)
                + np.einsum("tij,tj->ti", m.C(angle, speed, accel), q)
                - m.F(angle, speed, accel))
    return -residual


def attachment_forces(system: CoupledSystem, response, drive=None) -> AttachmentForces:
    """Forces in the mechanism-frame attachments over time.

    Parameters
    ----------
    system : CoupledSystem
        Primal form (the multiplier form is not integrated in time).
    response : Response
        From :func:`~femmech.analysis.response.time_response` or
        :func:`~femmech.analysis.response.periodic_steady_state` on ``system``.
    drive : callable or tuple of three callables, optional
        The drive law of the response; needed only for rigid attachments (their force
        depends on Ω and Ω̇, which the response does not store).

    Returns
    -------
    AttachmentForces
        Sign: force of the mechanism on the frame, positive along the attachment
        direction (see the module docstring).

    Raises
    ------
    ValueError
        For the multiplier form, a response of another size, or a rigid attachment
        without ``drive`` (naming the attachment).
    """
    if system.H is not None and len(system.H):
        raise ValueError("attachment_forces needs the primal form (couple(..., form='primal'))")
    q = np.asarray(response.q)
    if q.ndim != 2 or q.shape[1] != system.n:
        raise ValueError(f"response.q must have shape (n_t, {system.n}), got {q.shape}")
    drive_state = None if drive is None else drive_angles(drive, np.asarray(response.t, float))
    labels, rigid, columns = [], [], []
    for i, mount in enumerate(system.mounts):
        names = list(mount.model.coordinate_names)
        states = _mechanism_states(system, i, response)
        rows = None
        for att in mount.attachments:
            k = names.index(att.coordinate)
            label = f"{mount.name}.{att.coordinate}"
            labels.append(label)
            rigid.append(att.stiffness is None)
            if att.stiffness is None:
                if drive_state is None:
                    raise ValueError(f"attachment {label} is rigid: give the drive law to"
                                     " recover its force")
                if rows is None:
                    rows = _mechanism_rows(mount, states, drive_state)
                columns.append(rows[:, k])
                continue
            L = frame_row(system.frame, att.node, att.direction)
            u, ud = q[:, :system.n_frame] @ L, np.asarray(response.v)[:, :system.n_frame] @ L
            columns.append(att.stiffness * (states[0][:, k] - u)
                           + att.damping * (states[1][:, k] - ud))
    forces = np.column_stack(columns) if columns else np.zeros((q.shape[0], 0))
    return AttachmentForces(tuple(labels), np.array(rigid, dtype=bool), forces)


def drive_forces(lagrange, response, drive, system: CoupledSystem | None = None,
                 mount: int = 0) -> np.ndarray:
    """Drive forces needed to keep the programmed motion, as time histories.

    Parameters
    ----------
    lagrange : LagrangeModel
        :func:`~femmech.mechanisms.second_kind` model of the same mechanism (and the same
        parameters and position functions) as the rheolinear model of the response.
    response : Response
        Time history of the rheolinear model alone, or of a coupled ``system``.
    drive : callable or tuple of three callables
        The drive law of the response (φ, Ω, Ω̇ of the main drive).
    system : CoupledSystem, optional
        The coupled system of the response; its mount ``mount`` is evaluated (drive angle
        ``ratio φ + phase``; rigidly attached coordinates follow the frame).
    mount : int
        Index of the mount in ``system``.

    Returns
    -------
    ndarray (n_t, F)
        Q_d = (M q̈ + h + W_pot,q − Q*)_d for each drive of the mechanism, N m or N. The
        vibration accelerations are the response's (the full nonlinear drive row, not a
        linearisation about the rigid motion).
    """
    t = np.asarray(response.t, dtype=float)
    phi, Omega, Omega_dot = drive_angles(drive, t)
    if system is None:
        states, ratio, phase = (np.asarray(response.q), np.asarray(response.v),
                                np.asarray(response.a)), 1.0, 0.0
        model = None
    else:
        states = _mechanism_states(system, mount, response)
        model = system.mounts[mount].model
        ratio, phase = system.mounts[mount].ratio, system.mounts[mount].phase
    names = ([c.name for c in lagrange.mechanism.coordinates])
    drives = [c.name for c in lagrange.mechanism.drives]
    if len(drives) != 1:
        raise ValueError(f"drive_forces handles one drive; the mechanism has {drives}")
    vib = list(model.coordinate_names) if model is not None else \
        [n for n in names if n not in drives]
    if states[0].shape[1] != len(vib):
        raise ValueError(f"the response has {states[0].shape[1]} vibration coordinates, the"
                         f" mechanism {len(vib)} ({vib})")
    full = [np.zeros((t.size, len(names))) for _ in range(3)]
    d = names.index(drives[0])
    for x, s, prog in zip(full, states, (ratio * phi + phase, ratio * Omega,
                                         ratio * Omega_dot), strict=True):
        x[:, [names.index(v) for v in vib]] = s
        x[:, d] = prog
    q, qd, qdd = full
    M = lagrange.M(q)
    residual = (np.einsum("tij,tj->ti", M, qdd) + lagrange.velocity_terms(q, qd)
                + lagrange.gradient(q) - lagrange.Q(q, qd))
    return residual[:, [d]]


def support_reactions(system: CoupledSystem, model, response, dofs, mass_coef: float = 0.0,
                      stiffness_coef: float = 0.0) -> np.ndarray:
    """Reactions at supported DOFs of the frame (e.g. a kinematically driven shaft end).

    The support holds the DOF at zero, so its reaction is the DOF's row of the unconstrained
    equations of motion, ``R_d = (K u + B u̇ + M ü)_d`` with ``B = a M + b K`` (Rayleigh,
    as in :func:`~femmech.analysis.response.rayleigh_damping`); only the full-model DOFs
    coupled to d are recovered (:func:`~femmech.analysis.response.frame_history`). For the
    rotation about the shaft axis at a kinematic drive this is the drive torque the motor
    supplies to keep φ(t), the shaft's own vibration included. Loads applied at d itself
    (none in a coupled system: mechanisms act through attachments) are not subtracted.

    Parameters
    ----------
    system : CoupledSystem
    model : FEModel
        The frame's FE model (its unconstrained K and M).
    response : Response
    dofs : sequence
        Supported full-model DOFs: indices ``6 * node + component`` or ``(node, component)``.
    mass_coef, stiffness_coef : float
        Rayleigh coefficients a (1/s) and b (s) of the frame damping of the response.

    Returns
    -------
    ndarray (n_t, n_dofs)
        Force (N) or moment (N m) the support exerts on the frame.
    """
    d = []
    for dof in dofs:
        node, component = node_component(model, dof)
        d.append(DOF_PER_NODE * int(node) + COMPONENTS.index(component))
    d = np.array(d, dtype=np.int64)
    free = np.zeros(model.n_dof, dtype=bool)
    free[model.free] = True
    if free[d].any():
        raise ValueError(f"DOF {int(d[free[d]][0])} (node {int(d[free[d]][0]) // DOF_PER_NODE})"
                         " is not supported: a reaction exists only at supported DOFs")
    K, M = model.K.tocsr()[d], model.M.tocsr()[d]
    cols = np.union1d(K.indices, M.indices)  # CSR: column indices of the rows d
    K, M = K[:, cols].toarray(), M[:, cols].toarray()
    u, v, a = (frame_history(system, model, x, cols)
               for x in (response.q, response.v, response.a))
    B = mass_coef * M + stiffness_coef * K
    return u @ K.T + v @ B.T + a @ M.T


SECTION_COMPONENTS = ("N", "Vy", "Vz", "T", "My", "Mz")


@dataclass(frozen=True)
class SectionForces:
    """Section forces of beam elements at their two ends, as time histories.

    Attributes
    ----------
    elements : ndarray of int (n_el,)
        Beam element indices (rows of ``model.beams.cells``), in the order requested.
    forces : ndarray (n_t, n_el, 2, 6)
        Section forces at end a (``[:, :, 0]``) and end b (``[:, :, 1]``) in the element's
        local axes, components :data:`SECTION_COMPONENTS` = (N, Vy, Vz, T, My, Mz): N and
        V in N, T and M in N m. Sign: the force and moment vectors that the part of the
        member on the +x side of the cut exerts on the part on the −x side (local x from
        node a to node b). N > 0 is tension; dMz/dx = −Vy and dMy/dx = +Vz between loads.
    dynamic : bool
        True if the inertia and damping forces of the elements are included.
    """

    elements: np.ndarray
    forces: np.ndarray
    dynamic: bool

    def component(self, name: str) -> np.ndarray:
        """One component, ndarray (n_t, n_el, 2) (ends a and b), N or N m."""
        if name not in SECTION_COMPONENTS:
            raise ValueError(f"unknown section force component {name!r}; use one of"
                             f" {SECTION_COMPONENTS}")
        return self.forces[..., SECTION_COMPONENTS.index(name)]


def _beam_elements(model, elements) -> np.ndarray:
    """Beam element indices from an index, a cell group name or a sequence of both."""
    n_beams = len(model.beams.cells)
    if n_beams == 0:
        raise ValueError("the model has no beam elements: section forces need beams")
    items = [elements] if isinstance(elements, (str, int, np.integer)) else list(elements)
    if not items:
        raise ValueError("no beam elements requested: give element indices or group names")
    out = []
    for item in items:
        if isinstance(item, str):
            if item not in model.mesh.cell_sets:
                raise ValueError(model.mesh.unknown_cell_set(item, "element group"))
            idx = model.mesh.cell_sets[item].get("line", np.empty(0, dtype=np.int64))
            if not len(idx):
                raise ValueError(f"element group {item!r} has no beam (line) elements")
            out.append(np.asarray(idx, dtype=np.int64))
        elif isinstance(item, (int, np.integer)) and not isinstance(item, bool):
            if not 0 <= item < n_beams:
                raise ValueError(f"beam element {item} is out of range: the model has"
                                 f" {n_beams} beam elements (0..{n_beams - 1})")
            out.append(np.array([item], dtype=np.int64))
        else:
            raise TypeError(f"beam element {item!r}: give an element index (int) or a cell"
                            " group name (str)")
    return np.concatenate(out)


def _check_frame(system: CoupledSystem, model, part):
    """The frame (or Assembly part) that ``model`` belongs to; raises on a mismatch."""
    frame = system.frame
    if isinstance(frame, Assembly):
        if part is None or not 0 <= part < len(frame.parts):
            raise ValueError(f"the frame is an Assembly of {len(frame.parts)} parts: give the"
                             f" part index of the FE model (part=0..{len(frame.parts) - 1})")
        frame = frame.parts[part]
    elif part is not None:
        raise ValueError(f"part={part} is given, but the frame is not an Assembly")
    n_dof = frame.n_dof if isinstance(frame, FEModel) else frame.T.shape[0]
    if n_dof != model.n_dof:
        raise ValueError(f"the model has {model.n_dof} DOFs, the frame {n_dof}: give the FE"
                         " model the frame was built (or reduced) from")


def beam_section_forces(system: CoupledSystem, model, response, elements,
                        dynamic: bool = False, mass_coef: float = 0.0,
                        stiffness_coef: float = 0.0, part: int | None = None) -> SectionForces:
    """Section forces at the ends of beam elements, as time histories.

    The element end forces in local axes are ``f = K_e u_e`` (``dynamic=False``, the
    default) or ``f = K_e u_e + B_e u̇_e + M_e ü_e`` with ``B_e = a M_e + b K_e``
    (``dynamic=True``); u_e are the element's 12 local DOFs, recovered from the response
    through only their rows of the recovery
    (:func:`~femmech.analysis.response.frame_history`), and K_e, M_e the element's own
    matrices (:func:`~femmech.fe.elements.beam.local_matrices`). The force the node exerts on
    the element is f; the section force (see :class:`SectionForces`) is ``−f_a`` at end a
    and ``+f_b`` at end b.

    Which part. ``K_e u_e`` is the elastic section force: the stress resultant of the
    element's own displacement field (N = EA ε, M = EI κ of the interpolation, constant
    N, V, T and linear M along the element), the part that stress and fatigue checks use
    (σ = N/A ± M c/I). It does not depend on the damping model and is what a
    mode-displacement recovery gives. ``M_e ü_e`` is the work-equivalent (consistent)
    nodal load of the element's own distributed inertia, which belongs to the element's
    mass, not to a cut; ``a M_e u̇_e`` is the mass-proportional Rayleigh force, a
    damping to ground rather than an internal force. Adding them gives the forces by
    which the nodes drive the element: these balance exactly at every node against the
    nodal loads, point-mass inertia and support reactions (use ``dynamic=True`` for such
    balances, e.g. the load a member passes to a joint), and at the element ends they
    include the element's share of its own inertia, which the elastic part misses. The
    two differ by O(element mass × acceleration), which vanishes as the mesh is refined,
    and are equal in a static state. Hence the default is the elastic part.
    Parameters
    ----------
    system : CoupledSystem
        With the frame reduced from (or equal to) ``model``.
    model : FEModel
        The frame's FE model (its beam elements and DOF numbering).
    response : Response
        Time history on ``system`` (``q``; ``v`` and ``a`` with ``dynamic=True``).
    elements : int, str or sequence of int and str
        Beam element indices (rows of ``model.beams.cells``) or cell group names of the
        mesh (all beam elements of the group, in the group's order).
    dynamic : bool
        Include the element inertia and damping forces (see above).
    mass_coef, stiffness_coef : float
        Rayleigh coefficients a (1/s) and b (s) of the frame damping of the response, as
        in :func:`~femmech.analysis.response.rayleigh_damping`; with ``dynamic=True`` only.
    part : int, optional
        For an :class:`~femmech.reduction.substructures.Assembly` frame: the part ``model`` is.

    Returns
    -------
    SectionForces
        ``forces`` (n_t, n_el, 2, 6), N and N m, in the element's local axes.

    Raises
    ------
    ValueError
        For a model without beams, an unknown group, an element index out of range, a
        model that does not match the frame, or damping coefficients without
        ``dynamic=True``.
    """
    if not dynamic and (mass_coef or stiffness_coef):
        raise ValueError("mass_coef and stiffness_coef apply to the dynamic end forces only:"
                         " give dynamic=True")
    _check_frame(system, model, part)
    idx = _beam_elements(model, elements)
    beams = model.beams
    cells = beams.cells[idx]
    dofs = (DOF_PER_NODE * cells[:, :, None] + np.arange(DOF_PER_NODE)).reshape(-1, 12)
    unique, inverse = np.unique(dofs, return_inverse=True)
    keys = [int(d) for d in unique] if part is None else [
        ((part, int(d) // DOF_PER_NODE), COMPONENTS[int(d) % DOF_PER_NODE]) for d in unique]
    props = beams.properties[idx]
    if props.shape != (len(idx), 11):
        raise ValueError("the model's BeamSet has no element properties (build it with"
                         " femmech.build_model)")
    K, M = local_matrices(beams.length[idx], *props[:, :10].T, rotary_inertia=props[:, 10])
    R = beams.frames[idx]

    def local(history):
        """Element DOFs in local axes, (n_t, n_el, 12)."""
        u = frame_history(system, model, history, keys)[:, inverse.reshape(dofs.shape)]
        u = u.reshape(u.shape[0], len(idx), 4, 3)
        return np.einsum("eij,tekj->teki", R, u).reshape(u.shape[0], len(idx), 12)

    f = np.einsum("eij,tej->tei", K, local(response.q))
    if dynamic:
        v, a = local(response.v), local(response.a)
        f += (np.einsum("eij,tej->tei", M, a + mass_coef * v)
              + stiffness_coef * np.einsum("eij,tej->tei", K, v))
    forces = f.reshape(f.shape[0], len(idx), 2, 6)
    forces[:, :, 0] *= -1.0
    return SectionForces(idx, forces, bool(dynamic))
