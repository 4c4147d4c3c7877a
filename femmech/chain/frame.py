"""The chain on an elastic machine frame: its units' bearings on a (reduced) frame.

The main shaft runs in bearings of the machine frame and each unit's follower is guided
by the frame, so the frame point that carries unit u (its cam bearing and follower guide,
one frame node per unit) moves by ``y_u = L_u x_frame`` along the unit's follower axis
(``L_u``: :func:`femmech.coupling.frame_row` of the node and direction). The unit's
positions are measured from that moving point (the follower is at ``y_u + U(ψ) + q2``,
cf. :func:`femmech.mechanisms.mounted.cam_follower`): its kinetic energy takes the
absolute velocities, its springs, dampers and process forces the relative positions
(the process force's reaction goes into the frame-held work). The shaft's torsion is
not resisted by the bearings (node rotations stay the chain's own coordinates); the
follower's inertia forces load the frame.

Coupling: the whole chain is *one* mechanism of :func:`femmech.coupling.couple` (its
``M(φ)``, ``B(φ, Ω)``, ``C(φ, Ω, Ω̇)``, ``F`` per drive angle are the assembled chain
matrices plus one frame coordinate ``y_u`` per unit, rigidly attached to its frame
node), so the coupled system is the frame's constant part plus the chain's blocks, as
for any mounted mechanism, and the analyses of :mod:`femmech.analysis` (``sweep``,
``full_modes``, stability, response) apply unchanged. Each unit cannot be its own
mount: ``couple`` attaches mechanism coordinates to frame nodes only, and the units are
joined to one another by the shaft. In the primal form the coupled coordinates are
``x = [x_frame (n_frame); q_chain (chain.n)]`` with the chain's assembled numbering.

Stage 6 (chain): uses coupling, mechanisms and chain.model.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import sympy

from femmech.chain.model import Chain
from femmech.coupling import Attachment, CoupledSystem, Mount, couple
from femmech.mechanisms import rheolinear
from femmech.mechanisms.position import preimages
from femmech.mechanisms.symbolic import Mechanism, PointMass

FRAME_COORDINATE = "y_frame"
"""Name of the frame coordinate that :func:`guided_unit` appends to a unit."""

CHECK_ANGLES = (0.3, 1.7, 4.1)
"""Drive angles (rad) at which a guided unit is compared with the chain's unit."""

CHECK_RTOL = 1e-12
"""Relative tolerance of that comparison (both evaluate the same compiled terms)."""


def guided_unit(unit, name: str = FRAME_COORDINATE):
    """The chain's unit with its frame point as a further coordinate (the last one).

    From the unit's symbolic mechanism (``unit.mechanism``, e.g. a
    :func:`~femmech.chain.follower_unit`): every point mass's position (1-D, along the
    follower axis, m) becomes ``y + position`` in the kinetic energy, with ``y`` (m) the
    displacement of the frame point along that axis; rotary inertias, springs, dampers,
    loads and potentials keep their frame-relative arguments. For Table 5.1 case 1 this
    is ``2T = J ψ̇² + m (ẏ + d/dt U(ψ) + q̇2)²``, ``2V = c q2²`` (the cam follower of
    :func:`femmech.mechanisms.mounted.cam_follower` without return spring).

    Parameters
    ----------
    unit : RheolinearModel
        Built by :func:`femmech.mechanisms.rheolinear` from a mechanism whose point
        masses move on one axis.
    name : str
        Name of the frame coordinate (must be new).

    Returns
    -------
    RheolinearModel
        Coordinates ``unit.coordinate_names + (name,)``; for ``y = 0`` it is ``unit``.
    """
    mech = getattr(unit, "mechanism", None)
    if not isinstance(mech, Mechanism):
        raise ValueError(f"guided_unit needs a unit built by rheolinear (a symbolic"
                         f" mechanism), got {type(unit).__name__}; give frame_unit=")
    used = {s.name for s in mech.coordinates} | set(unit.parameters)
    if name in used:
        raise ValueError(f"frame coordinate name {name!r} is already used by the unit")
    y = sympy.Symbol(name, real=True)
    elements = []
    for element in mech.elements:
        if isinstance(element, PointMass):
            if len(element.position) != 1:
                raise ValueError(f"unit {mech.name!r}: a point mass moves in"
                                 f" {len(element.position)} dimensions; guided_unit needs"
                                 " masses on the follower axis only (give frame_unit=)")
            element = PointMass(element.m, (y + element.position[0],))
        elements.append(element)
    vib = mech.vibration_coordinates
    coords = vib + (y,) + tuple(c for c in mech.coordinates if c not in vib)
    guided = replace(mech, coordinates=coords, elements=tuple(elements),
                     name=f"{mech.name} on the frame")
    return rheolinear(guided, dict(unit.parameters), dict(unit.position_functions))


class _FramedChain:
    """The chain plus one frame coordinate per unit, as one mechanism for ``couple``.

    Coordinates: the chain's ``n`` (assembled numbering), then ``y_u`` of unit u at
    ``n + u``. Matrices: the assembled chain's plus, per unit, the guided unit's rows
    and columns of ``y_u`` (its other block is the chain's unit, already in the chain).
    """

    def __init__(self, chain: Chain, guided, name: str):
        self.chain, self.guided, self.frame_name = chain, guided, name
        m = chain.m
        self.n = chain.n + chain.n_units
        dofs = np.column_stack([chain.unit_dofs, chain.n + np.arange(chain.n_units)])
        self._dofs = np.where(dofs < 0, self.n, dofs)  # clamped: a discarded row
        self._own = np.zeros((m + 1, m + 1), bool)
        self._own[:m, :m] = True
        self.coordinate_names = _chain_labels(chain) + tuple(
            f"unit{u}.{name}" for u in range(chain.n_units))

    def _angles(self, phi):
        return np.asarray(phi, dtype=float)[..., None] + self.chain.phase

    def _assemble(self, base, blocks):
        """``base`` S + (n_c, n_c) padded to S + (n, n) plus the frame rows of blocks."""
        S = base.shape[:-2]
        out = np.zeros(S + (self.n + 1, self.n + 1))
        nc = self.chain.n
        out[..., :nc, :nc] = base
        blocks = np.where(self._own, 0.0, blocks)
        r = np.broadcast_to(self._dofs[:, :, None], blocks.shape[-3:])
        c = np.broadcast_to(self._dofs[:, None, :], blocks.shape[-3:])
        flat = out.reshape((-1,) + out.shape[-2:])
        for k, block in enumerate(blocks.reshape((-1,) + blocks.shape[-3:])):
            np.add.at(flat[k], (r, c), block)
        return out[..., :-1, :-1]

    def M(self, phi):
        return self._assemble(self.chain.M(phi), self.guided.M(self._angles(phi)))

    def B(self, phi, Omega=0.0):
        return self._assemble(self.chain.B(phi, Omega),
                              self.guided.B(self._angles(phi), Omega))

    def C(self, phi, Omega=0.0, Omega_dot=0.0):
        return self._assemble(self.chain.C(phi, Omega, Omega_dot),
                              self.guided.C(self._angles(phi), Omega, Omega_dot))

    def F(self, phi, Omega=0.0, Omega_dot=0.0):
        Fu = self.guided.F(self._angles(phi), Omega, Omega_dot)  # S + (n_units, m + 1)
        S = Fu.shape[:-2]
        out = np.zeros((int(np.prod(S, dtype=int)), self.n + 1))
        for k, f in enumerate(Fu.reshape((-1,) + Fu.shape[-2:])):
            np.add.at(out[k], self._dofs, f)
        return out[:, :-1].reshape(S + (self.n,))

    def breakpoints(self) -> np.ndarray:
        """Drive angles in [0, 2π), rad, where a unit's matrices may jump (its cam joints
        at φ + δ_u)."""
        get = getattr(self.chain.unit, "breakpoints", None)
        points = np.zeros(0) if get is None else np.asarray(get())
        found = [preimages(points, 1.0, d) for d in self.chain.phase]
        return np.unique(np.concatenate(found)) if found else np.zeros(0)


def _chain_labels(chain: Chain) -> tuple:
    """A name per assembled chain coordinate: ``node{i}.rot``, ``unit{u}.{name}``."""
    labels = [""] * chain.n
    for i, d in enumerate(chain.node_dof):
        if d >= 0:
            labels[d] = f"node{i}.rot"
    names = list(getattr(chain.unit, "coordinate_names", range(chain.m)))
    for u, dofs in enumerate(chain.unit_dofs):
        for k, d in enumerate(dofs):
            if d >= 0 and k != chain.attach:
                labels[d] = f"unit{u}.{names[k]}"
    return tuple(labels)


def _check_guided(chain: Chain, guided) -> None:
    """Raise ValueError unless ``guided`` is the chain's unit plus one last coordinate."""
    m = chain.m
    if int(getattr(guided, "n", -1)) != m + 1:
        raise ValueError(f"frame_unit must have the unit's {m} coordinates plus one (the"
                         f" frame point, last), got n = {getattr(guided, 'n', None)}")
    unit = chain.unit
    angle = np.asarray(CHECK_ANGLES)
    for Omega, Omega_dot in ((0.0, 0.0), (7.0, 3.0)):
        pairs = (("M", unit.M(angle), guided.M(angle)),
                 ("B", unit.B(angle, Omega), guided.B(angle, Omega)),
                 ("C", unit.C(angle, Omega, Omega_dot), guided.C(angle, Omega, Omega_dot)))
        for what, A, G in pairs:
            scale = max(np.abs(A).max(), np.abs(G).max(), 1e-300)
            if np.abs(G[..., :m, :m] - A).max() > CHECK_RTOL * scale:
                raise ValueError(f"frame_unit's {what} without its last coordinate is not"
                                 f" the chain's unit {what} (at Ω = {Omega} rad/s)")


def _per_unit(value, n_units: int, what: str) -> list:
    """One direction per unit from a single one (name or 6 weights) or a sequence."""
    if isinstance(value, str):
        return [value] * n_units
    arr = np.asarray(value, dtype=object)
    if arr.shape == (6,) and all(isinstance(v, (int, float, np.number)) for v in arr):
        return [np.asarray(value, dtype=float)] * n_units
    values = list(value)
    if len(values) != n_units:
        raise ValueError(f"{what}: give one for all units or one per unit ({n_units}),"
                         f" got {len(values)}")
    return values


def mount_chain(chain: Chain, frame, bearing_nodes, direction="uy", *, frame_unit=None,
                form: str = "primal", name: str = "chain") -> CoupledSystem:
    """Couple a chain to a machine frame: each unit's cam bearing and follower guide on
    a frame node.

    Parameters
    ----------
    chain : Chain
    frame : Superelement, Assembly or FEModel
        The machine frame (a Craig-Bampton superelement for sweeps; an unreduced
        FEModel for reference solves with :func:`femmech.analysis.reference.full_modes`).
    bearing_nodes : sequence (n_units,)
        Frame node carrying unit u (node index or single-node group; ``(part, node)`` on
        an Assembly), as for :class:`~femmech.coupling.Attachment`.
    direction : str, array_like (6,) or sequence (n_units,) of them
        The follower axis at that node: a component name (``"uy"``) or weights of
        (ux, uy, uz, rx, ry, rz), one for all units or one per unit.
    frame_unit : RheolinearModel, optional
        The unit with the frame point's displacement (m) as a last coordinate; default
        :func:`guided_unit` of ``chain.unit``. Checked against ``chain.unit``.
    form : str
        ``"primal"`` (frame motion substituted) or ``"multiplier"`` (see ``couple``).
    name : str
        Name of the mount (coordinate labels ``"chain.node3.rot"``, ``"chain.unit2.q2"``).

    Returns
    -------
    CoupledSystem
        Coordinates ``[frame; chain]`` (primal form): the chain's are ``x[n_frame:]`` in
        its assembled numbering.
    """
    nodes = list(bearing_nodes)
    if len(nodes) != chain.n_units:
        raise ValueError(f"bearing_nodes: one frame node per unit ({chain.n_units}),"
                         f" got {len(nodes)}")
    directions = _per_unit(direction, chain.n_units, "direction")
    guided = guided_unit(chain.unit) if frame_unit is None else frame_unit
    _check_guided(chain, guided)
    model = _FramedChain(chain, guided, FRAME_COORDINATE)
    attachments = tuple(Attachment(f"unit{u}.{FRAME_COORDINATE}", node, d)
                        for u, (node, d) in enumerate(zip(nodes, directions, strict=True)))
    return couple(frame, [Mount(model, attachments, name=name)], form=form)
