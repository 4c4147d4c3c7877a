"""Frame-mechanism coupling: rheolinear mechanisms mounted on frames.

A coupled machine has global coordinates ``x = [u; q_own]``: the frame coordinates u
(reduced coordinates of a :class:`~femmech.reduction.superelement.Superelement`, global coordinates
of an :class:`~femmech.reduction.substructures.Assembly`, or free DOFs of an unreduced
:class:`~femmech.fe.model.FEModel`) followed by the mechanisms' own vibration coordinates.
A mechanism coordinate attached *rigidly* to the frame is the frame motion
``q_c = L u`` (DOF compatibility, primal assembly); an *elastic* attachment keeps q_c as
an own coordinate and adds a bearing spring/damper ``½ k (q_c - L u)²``. ``L`` is a
weighted combination of the six DOFs (ux, uy, uz, rx, ry, rz) of a frame node, e.g. a
guide direction or a shaft's torsion component.

With ``q_m = P x`` for each mechanism (P constant and sparse), the coupled rheolinear
system of seed 5.2.2 eq. 9 at drive angle φ is

    M(φ) = M_0 + Σ Pᵀ M_m(φ_m) P,  B(φ) = B_0 + Σ Pᵀ B_m P,  C(φ) = K_0 + Σ Pᵀ C_m P,
    F(φ) = Σ Pᵀ F_m,

with φ_m = ratio_m φ + phase_m. The constant frame part is assembled once; per angle only
the small mechanism blocks are evaluated (vectorised over all angles) and added on the
few coordinates they touch. Symbols: M mass, B damping, C stiffness, F force (the
chapter's); the frame's K is C_0.

On a superelement, mechanisms attach to interface DOFs only (:func:`couple` refuses an
interior node): the reduced basis holds the static response to forces at the interface,
not at an interior node, so that a cam mounted one node off the interface of the
textile shaft (examples/textile_shaft.py, 4 cams, f_max 400 Hz) gave quasi-frequencies
6.6e-5 off, against 6e-13 at the interface node. Output at interior nodes (recovery
through Ψ and Φ, :func:`frame_row`) is the reduced model's own and stays allowed.

Uses reduction, fe and mechanisms (the position protocol); no analysis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from femmech.errors import InputError
from femmech.fe.dofs import COMPONENTS, DOF_PER_NODE
from femmech.fe.model import FEModel, node_index
from femmech.html import html_summary
from femmech.mechanisms.catalogue import coordinate_unit, describe
from femmech.reduction.substructures import Assembly
from femmech.reduction.superelement import Superelement


@dataclass(frozen=True)
class Attachment:
    """Connects one mechanism vibration coordinate to a frame node.

    Attributes
    ----------
    coordinate : str
        Name of the mechanism's vibration coordinate (e.g. ``"y_guide"``).
    node : int or str
        Frame node (index or single-node group). For an Assembly frame give
        ``(part_index, node)``.
    direction : str or array_like (6,)
        A component name (``"uy"``) or weights of (ux, uy, uz, rx, ry, rz) (unitless for
        a unit direction; m/rad to turn a rotation into a displacement), so that the
        attached frame motion is ``Σ w_k u_k``.
    stiffness : float or None
        ``None`` for a rigid attachment; otherwise the bearing stiffness, N/m or N m/rad.
    damping : float
        Bearing damping, N s/m or N m s/rad (elastic attachments only).
    """

    coordinate: str
    node: object
    direction: object
    stiffness: float | None = None
    damping: float = 0.0


@dataclass(frozen=True)
class Mount:
    """A rheolinear mechanism model placed in a machine.

    Attributes
    ----------
    model : femmech.mechanisms.RheolinearModel
        One drive; its drive angle is ``ratio * φ + phase`` (rad).
    attachments : tuple of Attachment
    ratio : float
        Transmission ratio from the machine's main drive angle φ.
    phase : float
        Angle offset, rad (identical mechanisms working out of phase on one shaft).
    name : str
    """

    model: object
    attachments: tuple = ()
    ratio: float = 1.0
    phase: float = 0.0
    name: str = "mechanism"


@dataclass(frozen=True)
class CoupledSystem:
    """Frame plus mounted mechanisms; evaluate with :meth:`matrices`.

    Attributes
    ----------
    frame : Superelement, Assembly or FEModel
    mounts : tuple of Mount
    M0, B0, K0 : ndarray or sparse (n, n)
        Constant parts: frame mass/stiffness (zero-padded to the global size) plus the
        bearing springs and dampers of elastic attachments.
    projections : tuple of ndarray (n_m, n_touched)
        ``q_m = P[:, touched] x[touched]`` for each mount.
    touched : tuple of ndarray
        Global coordinates each mount touches.
    n_frame : int
        Number of frame coordinates (the first ones).
    labels : tuple of str
        A label per global coordinate (``"frame 12"``, ``"cam2.q2"``).
    H : ndarray (n_c, n) or None
        Multiplier form only: rigid attachments as constraints ``H x = 0`` (seed 5.2.1
        eqs. 15-21, the mechanism's base coordinate minus the frame motion); ``None`` in
        the primal form, where they are eliminated.
    """

    frame: object
    mounts: tuple
    M0: object
    B0: object
    K0: object
    projections: tuple
    touched: tuple
    n_frame: int
    labels: tuple
    H: np.ndarray | None = None

    def __repr__(self) -> str:
        kind = type(self.frame).__name__
        return (f"CoupledSystem({self.n} coordinates: {kind} frame with {self.n_frame},"
                f" {len(self.mounts)} mounted mechanism(s) with {self.n - self.n_frame};"
                f" {'sparse' if self.is_sparse else 'dense'})")

    def _repr_html_(self) -> str:
        rows = [(m.name, type(m.model).__name__) for m in self.mounts]
        facts = [("frame", f"{type(self.frame).__name__}, {self.n_frame} coordinates"),
                 ("mechanism coordinates", self.n - self.n_frame),
                 ("matrices", "sparse" if self.is_sparse else "dense")]
        return html_summary(f"CoupledSystem: {self.n} coordinates", facts,
                            ("mount", "mechanism model"), rows)

    @property
    def n(self) -> int:
        """Number of global coordinates."""
        return self.M0.shape[0]

    def describe(self, label: str) -> str:
        """Readable name of the global coordinate ``label`` (one of :attr:`labels`): a
        mechanism coordinate as ``"follower deformation [cam1.q]"`` (its mechanism's
        ``labels``, :func:`femmech.mechanisms.catalogue.describe`); others unchanged."""
        found = self._mount_coordinate(label)
        return label if found is None else describe(found[0].model, found[1],
                                                     f"{found[0].name}.")

    def unit(self, label: str) -> str:
        """SI unit of the mechanism coordinate ``label`` (``"m"``, ``"rad"``), from its
        mechanism's labels and the catalogue (:func:`~femmech.mechanisms.catalogue.
        coordinate_unit`); ``""`` for frame coordinates and where the mechanism does not
        say."""
        found = self._mount_coordinate(label)
        return "" if found is None else coordinate_unit(found[0].model, found[1])

    def _mount_coordinate(self, label: str):
        """``(mount, coordinate name)`` of a mechanism coordinate ``label``
        (``"cam1.q"``), None for a frame coordinate."""
        for mount in self.mounts:
            prefix = f"{mount.name}."
            if label.startswith(prefix) and label[len(prefix):]:
                return mount, label[len(prefix):]
        return None

    @property
    def is_sparse(self) -> bool:
        """True when the frame is an unreduced (sparse) model."""
        return sp.issparse(self.M0)

    def mechanism_blocks(self, phi, Omega: float = 0.0, Omega_dot: float = 0.0):
        """Per mount: M_m, B_m, C_m (n_angles, t, t) and F_m (n_angles, t) on ``touched``.

        ``phi`` (n_angles,) main drive angles, rad; ``Omega`` main drive speed, rad/s;
        ``Omega_dot`` main drive acceleration, rad/s². Mechanism matrices are evaluated
        for all angles in one call per model and transmission ratio: mounts sharing a
        model (identical mechanisms on one shaft) are evaluated together, once per
        distinct phase.
        """
        phi = np.atleast_1d(np.asarray(phi, dtype=float))
        shared = {}
        for k, mount in enumerate(self.mounts):
            shared.setdefault((id(mount.model), mount.ratio), []).append(k)
        own = [None] * len(self.mounts)
        for ks in shared.values():
            m, ratio = self.mounts[ks[0]].model, self.mounts[ks[0]].ratio
            phases, which = np.unique([self.mounts[k].phase for k in ks], return_inverse=True)
            angle = ratio * phi + phases[:, None]  # (n_phases, n_angles)
            speed, accel = ratio * Omega, ratio * Omega_dot
            values = (m.M(angle), m.B(angle, speed), m.C(angle, speed, accel),
                      m.F(angle, speed, accel))
            for k, i in zip(ks, which, strict=True):
                own[k] = [A[i] for A in values]
        return [(_project(P, Mm), _project(P, Bm), _project(P, Cm),
                 np.einsum("ki,ak->ai", P, Fm))
                for P, (Mm, Bm, Cm, Fm) in zip(self.projections, own, strict=True)]

    def matrices(self, phi: float, Omega: float = 0.0, Omega_dot: float = 0.0):
        """Coupled M, B, C (n, n) and F (n,) at one drive angle (dense or sparse)."""
        blocks = self.mechanism_blocks([phi], Omega, Omega_dot)
        return assemble_at(self, blocks, 0)


def require_dense_primal(system: CoupledSystem, what: str) -> None:
    """Raise ValueError unless ``system`` has a reduced (dense) frame and the primal form.

    Time integration and monodromy need ``M(φ) q'' + B q' + C q = F`` as an ODE: the
    multiplier form is a differential-algebraic system. ``what`` names the caller.
    """
    if system.is_sparse:
        raise ValueError(f"{what} needs a reduced frame (dense matrices); reduce the frame"
                         " with craig_bampton first")
    if system.H is not None and len(system.H):
        raise ValueError(f"{what} needs the primal form (the multiplier form is a"
                         " differential-algebraic system); couple(..., form='primal')")


def _project(P: np.ndarray, A: np.ndarray) -> np.ndarray:
    """``Pᵀ A P`` for a stack of matrices A (n_angles, n_m, n_m) → (n_angles, t, t)."""
    return np.einsum("ki,akl,lj->aij", P, A, P, optimize=True)


def assemble_at(system: CoupledSystem, blocks, index: int):
    """Add the mechanism blocks of angle ``index`` to the constant matrices."""
    if system.is_sparse:
        parts = {key: [] for key in "MBC"}
        F = np.zeros(system.n)
        for idx, (Mm, Bm, Cm, Fm) in zip(system.touched, blocks, strict=True):
            r, c = np.meshgrid(idx, idx, indexing="ij")
            for key, A in zip("MBC", (Mm, Bm, Cm), strict=True):
                parts[key].append(sp.coo_matrix((A[index].ravel(), (r.ravel(), c.ravel())),
                                                shape=(system.n, system.n)))
            F[idx] += Fm[index]
        M = (system.M0 + sum(parts["M"])).tocsr()
        B = (system.B0 + sum(parts["B"])).tocsr()
        C = (system.K0 + sum(parts["C"])).tocsr()
        return M, B, C, F
    one = [tuple(X[index:index + 1] for X in block) for block in blocks]
    return tuple(X[0] for X in assemble_stack(system, one))


def assemble_stack(system: CoupledSystem, blocks):
    """Dense M, B, C (k, n, n) and F (k, n) at all k angles of ``blocks`` at once.

    The vectorised form of :func:`assemble_at` for reduced frames (time integrators need
    the matrices at many time points).
    """
    if system.is_sparse:
        raise ValueError("assemble_stack needs a reduced frame (dense matrices); use"
                         " assemble_at for an unreduced one")
    k = blocks[0][0].shape[0] if blocks else 1
    M, B, C = (np.repeat(A[None], k, axis=0) for A in (system.M0, system.B0, system.K0))
    F = np.zeros((k, system.n))
    for idx, (Mm, Bm, Cm, Fm) in zip(system.touched, blocks, strict=True):
        ix = (slice(None), idx[:, None], idx[None, :])
        M[ix] += Mm
        B[ix] += Bm
        C[ix] += Cm
        F[:, idx] += Fm
    return M, B, C, F


def drive_breakpoints(system: CoupledSystem, angle_period: float = 2 * np.pi) -> np.ndarray:
    """Main-drive angles in [0, Θ), rad, where a mounted mechanism's matrices may jump.

    The breakpoints of each mount's model (``model.breakpoints()``, e.g. the joints of a
    cam programme, in the mechanism's own angle θ = ratio φ + phase) mapped to the main
    drive angle φ over the cycle Θ = ``angle_period``. Sorted and unique.
    """
    from femmech.mechanisms.position import preimages

    found = [preimages(get(), m.ratio, m.phase, angle_period) for m in system.mounts
             if (get := getattr(m.model, "breakpoints", None)) is not None]
    return np.unique(np.concatenate(found)) if found else np.zeros(0)


def frame_row(frame, node, direction) -> np.ndarray:
    """Row vector L (n_frame,) with ``Σ w_k u_k(node) = L u`` for frame coordinates u."""
    w = direction_weights(direction)
    if isinstance(frame, Assembly):
        if not (isinstance(node, tuple) and len(node) == 2):
            raise ValueError("on an Assembly frame, give the node as (part_index, node)")
        part, local = node
        row_local = frame_row(frame.parts[part], local, w)
        row = np.zeros(frame.n_dof)
        np.add.at(row, frame.part_dofs[part], row_local)
        return row
    T = frame.T.tocsr()
    node_id = _node_id(frame, node)
    full_rows = T[DOF_PER_NODE * node_id + np.arange(DOF_PER_NODE)]
    free_row = np.asarray(full_rows.T @ w).ravel()  # (n_free,)
    if isinstance(frame, FEModel):
        return free_row
    se = frame
    row = np.zeros(se.n_reduced)
    n_b, V = se.n_boundary, se.interface_basis  # u_b = V η_c with a reduced interface
    row[:n_b] = free_row[se.free_interface] if V is None else free_row[se.free_interface] @ V
    interior = free_row[se.free_interior]
    if np.any(interior):
        row[:n_b] += interior @ se.Psi
        row[n_b:] += interior @ se.Phi
    return row


def _require_interface(frame, mount: str, att: Attachment) -> None:
    """InputError if attachment ``att`` moves an interior DOF of a superelement frame (or
    of a superelement part of an Assembly)."""
    se, node = frame, att.node
    if isinstance(frame, Assembly):
        if not (isinstance(node, tuple) and len(node) == 2):
            return  # frame_row names the mistake
        part, node = node
        se = frame.parts[part]
    if not isinstance(se, Superelement):
        return
    w = direction_weights(att.direction)
    node_id = _node_id(se, node)
    rows = se.T.tocsr()[DOF_PER_NODE * node_id + np.arange(DOF_PER_NODE)]
    moved = np.asarray(rows.T @ w).ravel()[se.free_interior]
    if not np.any(moved):
        return
    component = COMPONENTS[int(np.argmax(np.abs(w)))]
    where = "" if not isinstance(frame, Assembly) else f" of part {att.node[0]}"
    raise InputError(
        f"{mount}: attachment of {att.coordinate!r} at node {node_id} {component}{where} is"
        " interior to the superelement (node not on its interface, or not in this"
        " component); mechanisms couple through interface DOFs only: add the node to the"
        f" interface, craig_bampton(model, interface=[..., ({node_id}, [{component!r}])]) or"
        f" in a scene {{ nodes = {node_id}, dofs = [\"{component}\"] }} in"
        " [parts.<part>.reduction] interface, and reduce again")


def _node_id(frame, node) -> int:
    if isinstance(frame, FEModel):
        return node_index(frame.mesh, node, "attachment")
    if isinstance(node, (int, np.integer)) and 0 <= node < frame.n_dof // DOF_PER_NODE:
        return int(node)
    raise ValueError(f"attachment node {node!r}: on a Superelement give a node index"
                     f" (0..{frame.n_dof // DOF_PER_NODE - 1})")


def direction_weights(direction) -> np.ndarray:
    if isinstance(direction, str):
        if direction not in COMPONENTS:
            raise ValueError(f"unknown direction {direction!r}; use one of {COMPONENTS}"
                             " or six weights")
        w = np.zeros(DOF_PER_NODE)
        w[COMPONENTS.index(direction)] = 1.0
        return w
    w = np.asarray(direction, dtype=float)
    if w.shape != (DOF_PER_NODE,) or not np.isfinite(w).all() or not w.any():
        raise ValueError(f"direction must be a component name or six finite weights, not all"
                         f" zero; got {direction!r}")
    return w


def frame_matrices(frame):
    """Constant frame K and M: dense for superelements and assemblies of superelements,
    sparse for FE models and assemblies with FE parts."""
    if isinstance(frame, Superelement):
        return frame.K, frame.M
    if isinstance(frame, Assembly):
        if all(isinstance(p, Superelement) for p in frame.parts):
            return frame.K.toarray(), frame.M.toarray()  # reduced: small and dense
        return frame.K, frame.M
    if isinstance(frame, FEModel):
        return frame.K_free, frame.M_free
    raise TypeError(f"frame must be a Superelement, Assembly or FEModel, got"
                    f" {type(frame).__name__}")


def couple(frame, mounts, form: str = "primal", allow_interior: bool = False) -> CoupledSystem:
    """Build the coupled system of a frame and mounted mechanisms.

    Parameters
    ----------
    frame : Superelement, Assembly or FEModel
    mounts : sequence of Mount
    form : str
        ``"primal"``: rigidly attached coordinates are replaced by the frame motion
        (DOF compatibility). ``"multiplier"``: every mechanism coordinate stays a global
        coordinate and rigid attachments become constraints ``H x = 0`` with Lagrange
        multipliers (the interface forces), the chapter's mixed form (seed 5.2.1 eq. 21);
        both give the same quasi-modes.
    allow_interior : bool
        Accept attachments that move interior (non-interface) DOFs of a superelement.
        Their coupling then rests on the constraint and fixed-interface modes alone and
        is only as accurate as those represent a force at that node (6.6e-5 off on the
        textile shaft, 6e-13 at the interface node); for studies of that error only.

    Returns
    -------
    CoupledSystem

    Raises
    ------
    ValueError
        Naming the mount and coordinate for unknown coordinate names, coordinates
        attached twice, or bad attachment nodes/directions.
    InputError
        (a ValueError) naming the mount, coordinate, node and component of an attachment
        at a node that is interior to a superelement frame (not on its interface, or not
        in that component), with how to add it to the interface.
    """
    if form not in ("primal", "multiplier"):
        raise ValueError(f"form must be 'primal' or 'multiplier', got {form!r}")
    K_frame, M_frame = frame_matrices(frame)
    n_frame = K_frame.shape[0]
    mounts = tuple(mounts)
    constraints = []
    rows_of, labels = [], [f"frame {i}" for i in range(n_frame)]
    springs = []
    n = n_frame
    for mount in mounts:
        names = list(mount.model.coordinate_names)
        rows = [None] * len(names)
        attached = {}
        for att in mount.attachments:
            if att.coordinate not in names:
                raise ValueError(f"{mount.name}: attachment of unknown coordinate"
                                 f" {att.coordinate!r}; the mechanism has {names}")
            if att.coordinate in attached:
                raise ValueError(f"{mount.name}: coordinate {att.coordinate!r} attached twice")
            attached[att.coordinate] = att
        if not allow_interior:
            for att in mount.attachments:
                _require_interface(frame, mount.name, att)
        for k, name in enumerate(names):
            att = attached.get(name)
            if att is not None and att.stiffness is None and form == "primal":
                rows[k] = ("frame", frame_row(frame, att.node, att.direction))
                continue
            rows[k] = ("own", n)
            labels.append(f"{mount.name}.{name}")
            if att is not None and att.stiffness is None:
                constraints.append((n, frame_row(frame, att.node, att.direction)))
            elif att is not None:
                springs.append((n, frame_row(frame, att.node, att.direction),
                                float(att.stiffness), float(att.damping)))
            n += 1
        rows_of.append(rows)
    projections, touched = [], []
    for rows in rows_of:
        P = np.zeros((len(rows), n))
        for k, (kind, value) in enumerate(rows):
            if kind == "frame":
                P[k, :n_frame] = value
            else:
                P[k, value] = 1.0
        idx = np.flatnonzero(np.any(P != 0, axis=0))
        projections.append(P[:, idx])
        touched.append(idx)
    M0, B0, K0 = _constant_parts(K_frame, M_frame, n, springs)
    H = None
    if form == "multiplier":
        H = np.zeros((len(constraints), n))
        for i, (own, row) in enumerate(constraints):
            H[i, own] = 1.0
            H[i, :n_frame] = -row
    return CoupledSystem(frame, mounts, M0, B0, K0, tuple(projections), tuple(touched),
                         n_frame, tuple(labels), H)


def _constant_parts(K_frame, M_frame, n, springs):
    """Frame matrices padded to n, plus bearing springs and dampers."""
    n_frame = K_frame.shape[0]
    sparse = sp.issparse(K_frame)
    pad = (lambda A: sp.block_diag([A, sp.csr_matrix((n - n_frame, n - n_frame))]).tocsr()) \
        if sparse else (lambda A: np.pad(A, (0, n - n_frame)))
    M0, K0 = pad(M_frame), pad(K_frame)
    B0 = sp.csr_matrix((n, n)) if sparse else np.zeros((n, n))
    for own, row, k, c in springs:
        d = np.zeros(n)
        d[own] = 1.0
        d[:n_frame] -= row
        idx = np.flatnonzero(d)
        block = np.outer(d[idx], d[idx])
        if sparse:
            r, cidx = np.meshgrid(idx, idx, indexing="ij")
            add = sp.coo_matrix((block.ravel(), (r.ravel(), cidx.ravel())), shape=(n, n))
            K0 = (K0 + k * add).tocsr()
            B0 = (B0 + c * add).tocsr()
        else:
            K0[np.ix_(idx, idx)] += k * block
            B0[np.ix_(idx, idx)] += c * block
    return M0, B0, K0
