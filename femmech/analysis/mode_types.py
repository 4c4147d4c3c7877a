"""What kind of motion a mode of a beam model is: a short label from energy fractions.

A mode shape ``u`` (full DOF vector) is split two ways:

* **kinetic energy by DOF component** ``c`` (ux, uy, uz, rx, ry, rz):
  ``T_c = ½ u_cᵀ M_cc u_c`` with ``M_cc`` the mass matrix restricted to the DOFs of that
  component (global axes). The fractions ``T_c / Σ T_c`` say in which direction the
  mass moves (cross terms between components, e.g. of the consistent beam mass, are left
  out of both numerator and denominator).
* **strain energy by deformation**: for every beam element, the local element stiffness
  (:func:`femmech.fe.elements.beam.local_matrices`) is block-diagonal in axial
  ``(u_a, u_b)``, torsion ``(rx_a, rx_b)``, bending about local z ``(v, rz)`` and bending
  about local y ``(w, ry)`` DOFs, so ``U_e = ½ u_eᵀ K_e u_e`` splits exactly into these
  four parts. The rest of ``½ uᵀ K u`` is stored in springs (``"springs"``). Each part
  has an axis in global coordinates: the element axis (local x) for axial and torsion,
  local y or z for bending; the energy-weighted tensor ``A = Σ_e U_e a_e a_eᵀ`` of a
  kind gives its dominant global axis.

The label (rule of :func:`classify_mode`, thresholds as module constants):

1. ``rigid`` (a zero-frequency mode, e.g. :attr:`femmech.ModeSet.rigid`):
   ``"rigid body"``.
2. Springs hold at least :data:`SPRING_SHARE` of the strain energy: the structure moves
   as a rigid body on its springs: ``"rigid body on springs: translation x + rotation
   about y"``, from the rigid-body motion fitted to the mode (mass-weighted, about the
   centre of mass), naming the components with at least :data:`PART_SHARE` of its
   kinetic energy.
3. One kind (axial, torsion, bending) holds at least :data:`DOMINANT_SHARE` of the
   strain energy: ``"bending about y"``, ``"torsion about x"``, ``"axial x"``; the axis
   is named when the largest eigenvalue of the kind's axis tensor holds at least
   :data:`AXIS_SHARE` of its trace and its eigenvector lies within 25° of a global axis
   (|cos| >= :data:`AXIS_COS`), else ``"about a skew axis"`` (a dominant eigenvalue off
   the axes) or ``"about several axes"``. Bending adds ``", moving in y"`` when one
   translation holds at least :data:`DOMINANT_SHARE` of the translational kinetic energy.
4. Otherwise ``"mixed: springs 39 % + bending 34 % + torsion 27 %"`` (the kinds and
   springs with at least :data:`PART_SHARE` of the strain energy).

Only beam models are classified: shell and solid strain energy cannot be told apart from
springs here, so models with shells or solids raise ValueError.

Uses fe only (model, DOF numbering, beam element matrices).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femmech.fe.constraints import rigid_link_matrix
from femmech.fe.dofs import COMPONENTS, DOF_PER_NODE  # noqa: F401 (COMPONENTS: public here too)
from femmech.fe.elements.beam import PLANE_XY, PLANE_XZ, local_matrices
from femmech.fe.model import FEModel

KINDS = ("axial", "torsion", "bending about y", "bending about z", "springs")
"""Strain energy parts, in the order of :attr:`ModeType.strain` (bending about the
element's local y and z axes)."""
DOMINANT_SHARE = 0.6
"""A kind of deformation (or a translation direction) that holds this fraction names the mode."""
SPRING_SHARE = 0.8
"""Springs holding this fraction of the strain energy make the mode a rigid body on springs."""
PART_SHARE = 0.2
"""Smallest share listed in a mixed label or a rigid-body motion."""
AXIS_SHARE = 0.7
"""The dominant eigenvalue of an axis tensor must hold this fraction of its trace."""
AXIS_COS = 0.9
"""|cos| between that eigenvector and a global axis (within about 25.8 degrees)."""
_AXES = "xyz"
_LOCAL = {  # local DOF indices of each beam kind, and the local axis (row of R) it acts about
    "axial": (np.array([0, 6]), 0),
    "torsion": (np.array([3, 9]), 0),
    "bending about y": (PLANE_XZ, 1),
    "bending about z": (PLANE_XY, 2),
}


@dataclass(frozen=True)
class ModeType:
    """The kind of motion of one mode.

    Attributes
    ----------
    label : str
        Short description (see the module notes), e.g. ``"bending about z, moving in y"``.
    kinetic : ndarray (6,)
        Fractions of the kinetic energy by DOF component (:data:`COMPONENTS`), sum 1
        (all 0 for a zero shape).
    strain : ndarray (5,)
        Fractions of the strain energy by part (:data:`KINDS`), sum 1 (all 0 for a
        rigid-body mode without strain energy).
    axis : str or None
        Global axis (``"x"``, ``"y"``, ``"z"``) of the dominant deformation, ``"skew"``
        or ``"several"`` (see :func:`dominant_axis`); None for rigid-body and mixed modes.
    """

    label: str
    kinetic: np.ndarray
    strain: np.ndarray
    axis: str | None = None


def kinetic_fractions(M, u: np.ndarray) -> np.ndarray:
    """Kinetic energy fractions ``T_c / Σ T_c`` by DOF component c, (6,).

    Parameters
    ----------
    M : sparse or dense (n_dof, n_dof)
        Unconstrained mass matrix (DOF ``6 · node + c``), kg, kg m, kg m².
    u : ndarray (n_dof,)
        Full mode shape (constrained DOFs included).
    """
    u = np.asarray(u, dtype=float)
    energy = np.empty(DOF_PER_NODE)
    for c in range(DOF_PER_NODE):
        idx = np.arange(c, len(u), DOF_PER_NODE)
        energy[c] = 0.5 * u[idx] @ (M[idx][:, idx] @ u[idx])
    energy = np.clip(energy, 0.0, None)
    total = energy.sum()
    return energy / total if total > 0 else energy


def beam_strain_energies(model: FEModel, u: np.ndarray) -> np.ndarray:
    """Strain energy of every beam element by kind, (n_elements, 4), J per (unit of u)².

    Columns: axial, torsion, bending about local y, bending about local z (the first four
    of :data:`KINDS`); each row sums to ``½ u_eᵀ K_e u_e`` of the element.
    """
    beams = model.beams
    if not len(beams.cells):
        return np.zeros((0, 4))
    props = beams.properties
    if props.shape != (len(beams.cells), 11):
        raise ValueError("the model's BeamSet has no element properties (build it with"
                         " femmech.build_model)")
    K, _ = local_matrices(beams.length, *props[:, :10].T, rotary_inertia=props[:, 10])
    nodal = np.asarray(u, dtype=float).reshape(-1, DOF_PER_NODE)[beams.cells]  # (e, 2, 6)
    local = np.einsum("eij,eakj->eaki", beams.frames, nodal.reshape(-1, 2, 2, 3))
    local = local.reshape(-1, 12)
    out = np.empty((len(local), 4))
    for k, (idx, _) in enumerate(_LOCAL.values()):
        part = local[:, idx]
        out[:, k] = 0.5 * np.einsum("ei,eij,ej->e", part, K[:, idx[:, None], idx[None, :]],
                                    part)
    return out


def dominant_axis(weights: np.ndarray, axes: np.ndarray) -> str | None:
    """Global axis of an energy-weighted set of unit vectors.

    Parameters
    ----------
    weights : ndarray (n,)
        Non-negative energies.
    axes : ndarray (n, 3)
        Unit vectors in global coordinates (the sign does not matter).

    Returns
    -------
    str or None
        ``"x"``, ``"y"`` or ``"z"`` when the largest eigenvalue of ``Σ w a aᵀ`` holds at
        least :data:`AXIS_SHARE` of its trace and its eigenvector is within
        ``arccos(AXIS_COS)`` of that axis; ``"skew"`` when it dominates but lies between
        the global axes; ``"several"`` when no eigenvalue dominates; None for zero weights.
    """
    tensor = np.einsum("e,ei,ej->ij", weights, axes, axes)
    trace = np.trace(tensor)
    if trace <= 0:
        return None
    values, vectors = np.linalg.eigh(tensor)
    if values[-1] < AXIS_SHARE * trace:
        return "several"
    v = vectors[:, -1]
    best = int(np.argmax(np.abs(v)))
    return _AXES[best] if abs(v[best]) >= AXIS_COS else "skew"


def rigid_motion_fractions(model: FEModel, u: np.ndarray) -> np.ndarray:
    """Kinetic energy fractions of the rigid-body part of a motion, about the centre of mass.

    The mode is projected (mass-weighted) onto the six rigid-body motions
    ``u = v + ω × (x - x_c)`` about the centre of mass ``x_c``, where the kinetic energy
    splits into ``½ m |v|²`` and ``½ ωᵀ J ω``.

    Returns
    -------
    ndarray (6,)
        Shares of ``m v_x², m v_y², m v_z², J_xx ω_x², J_yy ω_y², J_zz ω_z²`` in their sum
        (translations x, y, z and rotations about x, y, z); all 0 for no rigid motion.
    """
    points = model.mesh.points
    G = rigid_link_matrix(points - points.mean(axis=0)).reshape(-1, 6)
    Mr = G.T @ (model.M @ G)
    mass = np.trace(Mr[:3, :3]) / 3.0
    if mass <= 0:
        return np.zeros(6)
    # Mr[3:, :3] = m [c×] about the centroid: the centre of mass c relative to it
    skew = Mr[3:, :3] / mass
    centre = np.array([skew[2, 1] - skew[1, 2], skew[0, 2] - skew[2, 0],
                       skew[1, 0] - skew[0, 1]]) / 2.0
    G = rigid_link_matrix(points - points.mean(axis=0) - centre).reshape(-1, 6)
    Mr = G.T @ (model.M @ G)
    q = np.linalg.lstsq(Mr, G.T @ (model.M @ np.asarray(u, dtype=float)), rcond=None)[0]
    energy = np.concatenate([mass * q[:3] ** 2, np.diag(Mr)[3:] * q[3:] ** 2])
    total = energy.sum()
    return energy / total if total > 0 else energy


def classify_mode(model: FEModel, u: np.ndarray, rigid: bool = False) -> ModeType:
    """Label one mode of a beam model by its energy fractions (rule: module notes).

    Parameters
    ----------
    model : FEModel
        A beam model (no shell or solid elements); springs and point masses allowed.
    u : ndarray (n_dof,)
        Full mode shape (e.g. a column of :attr:`femmech.ModeSet.shapes`).
    rigid : bool
        The mode is a zero-frequency rigid-body mode.

    Raises
    ------
    ValueError
        For a model with shell or solid elements, or a vector of the wrong size.
    """
    _check(model, u)
    kinetic = kinetic_fractions(model.M, u)
    per_element = beam_strain_energies(model, u)
    beam_total = per_element.sum(axis=0)
    total = 0.5 * float(u @ (model.K @ u))
    springs = max(total - beam_total.sum(), 0.0)
    strain = np.append(beam_total, springs)
    strain = strain / strain.sum() if strain.sum() > 0 else np.zeros(5)
    if rigid:
        return ModeType("rigid body", kinetic, strain)
    if strain[4] >= SPRING_SHARE:
        motion = _rigid_motion_text(rigid_motion_fractions(model, u))
        return ModeType("rigid body on springs" + (f": {motion}" if motion else ""),
                        kinetic, strain)
    shares = {"axial": strain[0], "torsion": strain[1], "bending": strain[2] + strain[3]}
    kind = max(shares, key=shares.get)
    if shares[kind] < DOMINANT_SHARE:  # fractions of all the strain energy (springs too)
        parts = sorted(((s, k) for k, s in {**shares, "springs": strain[4]}.items()
                        if s >= PART_SHARE), reverse=True)
        text = " + ".join(f"{k} {100 * s:.0f} %" for s, k in parts)
        return ModeType(f"mixed: {text}" if text else "mixed", kinetic, strain)
    axis = _kind_axis(model, per_element, kind)
    return ModeType(_kind_label(kind, axis, kinetic), kinetic, strain, axis)


def mode_types(model: FEModel, shapes: np.ndarray, rigid=None) -> list[ModeType]:
    """:func:`classify_mode` for every column of ``shapes`` (n_dof, n_modes).

    ``rigid`` (n_modes,) of bool flags zero-frequency modes (default none).
    """
    shapes = np.asarray(shapes, dtype=float)
    rigid = np.zeros(shapes.shape[1], dtype=bool) if rigid is None else np.asarray(rigid)
    return [classify_mode(model, shapes[:, k], bool(rigid[k])) for k in range(shapes.shape[1])]


def _check(model: FEModel, u: np.ndarray) -> None:
    cells = [*getattr(model.shells, "cells", {}).values(), *getattr(model.solids, "cells",
                                                                     {}).values()]
    if any(len(c) for c in cells):
        raise ValueError("mode types classify beam models only; this model has shell or solid"
                         " elements, whose strain energy is not split by kind")
    if np.shape(u) != (model.n_dof,):
        raise ValueError(f"the mode shape must have {model.n_dof} entries (the model's full"
                         f" DOFs), got shape {np.shape(u)}")


def _kind_axis(model: FEModel, per_element: np.ndarray, kind: str) -> str | None:
    """Dominant global axis of one kind (bending: both planes together)."""
    names = ["bending about y", "bending about z"] if kind == "bending" else [kind]
    weights, axes = [], []
    for name in names:
        column = list(_LOCAL).index(name)
        weights.append(per_element[:, column])
        axes.append(model.beams.frames[:, _LOCAL[name][1]])
    return dominant_axis(np.concatenate(weights), np.concatenate(axes))


def _kind_label(kind: str, axis: str | None, kinetic: np.ndarray) -> str:
    """``"bending about z, moving in y"``, ``"torsion about x"``, ``"axial x"``,
    ``"bending about a skew axis"``, ``"axial, several directions"``, ..."""
    if kind == "axial":
        return {None: "axial", "skew": "axial, skew direction",
                "several": "axial, several directions"}.get(axis, f"axial {axis}")
    label = {None: kind, "skew": f"{kind} about a skew axis",
             "several": f"{kind} about several axes"}.get(axis, f"{kind} about {axis}")
    if kind == "bending":
        translation = kinetic[:3]
        if translation.sum() > 0 and translation.max() >= DOMINANT_SHARE * translation.sum():
            label += f", moving in {_AXES[int(np.argmax(translation))]}"
    return label


def _rigid_motion_text(fractions: np.ndarray) -> str:
    """``"translation x + rotation about y"`` from :func:`rigid_motion_fractions`."""
    names = [f"translation {a}" for a in _AXES] + [f"rotation about {a}" for a in _AXES]
    order = np.argsort(fractions)[::-1]
    return " + ".join(names[i] for i in order if fractions[i] >= PART_SHARE)
