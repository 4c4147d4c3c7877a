"""Force recovery from time histories: attachment (bearing) forces and drive forces.

Sign convention (both functions): a force is the generalized force in the positive
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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femmech.analysis.response import _drive, _node_component, frame_history
from femmech.coupling import CoupledSystem, frame_row
from femmech.dofs import COMPONENTS, DOF_PER_NODE


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
    drive_state = None if drive is None else _drive(drive, np.asarray(response.t, float))
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
    phi, Omega, Omega_dot = _drive(drive, t)
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
        node, component = _node_component(model, dof)
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
