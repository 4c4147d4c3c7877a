"""A main shaft carrying N identical mechanisms: the chain of seed 5.1 (Bild 5.1).

The shaft is a torsional chain of *nodes* (rotation angles, rad) joined by massless
torsion springs (stiffness ``k_j``, N m/rad); each node has a rotary inertia (kg m²: its
disc plus half of each adjacent shaft segment, lumped), an optional spring to ground
(N m/rad: an elastic coupling to a speed-controlled drive) and may be clamped (its
rotation removed). ``n_units`` identical mechanisms sit on nodes; unit ``u`` runs at the
drive angle ``φ + δ_u`` and its coordinate ``attach`` *is* the rotation of its node (the
shaft twist there, like q1 of Table 5.1), its other coordinates are internal (followers).

The frozen chain at drive angle φ is the linear system
``M(φ) q̈ + B(φ, Ω) q̇ + C(φ, Ω, Ω̇) q = 0`` assembled from the shaft and the units'
matrices (the "assembled model": FEM of the chapter's list). Coordinates are ordered node
by node: the rotation of node i, then the internal coordinates of the unit on node i
(if any), so the matrices are banded. Clamped nodes are removed.

Build a chain with :func:`chain` (uniform shaft from diameters) or the :class:`Chain`
constructor (any node inertias and spring stiffnesses); ends with :class:`End`.

Stage 6 (chain): imports mechanisms (for the unit protocol only), nothing above.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp
import sympy

STEEL_G = 80.77e9
"""Shear modulus of steel, Pa (E = 210 GPa, ν = 0.3: G = E / 2(1 + ν))."""

STEEL_RHO = 7850.0
"""Density of steel, kg/m³."""


@dataclass(frozen=True)
class End:
    """Condition at one end of the shaft.

    Attributes
    ----------
    stiffness : float
        Torsional spring from the end node to ground, N m/rad (an elastic coupling to a
        drive whose angle is prescribed); 0 for none.
    inertia : float
        Rotary inertia added to the end node, kg m² (flywheel, motor rotor); 0 for none.
    clamped : bool
        The end node's rotation is fixed (rigid drive); stiffness is then ignored.
    """

    stiffness: float = 0.0
    inertia: float = 0.0
    clamped: bool = False

    def __post_init__(self):
        for name in ("stiffness", "inertia"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"End.{name} must be finite and >= 0, got {value!r}")

    @classmethod
    def free(cls) -> End:
        """A free end."""
        return cls()

    @classmethod
    def fixed(cls) -> End:
        """A clamped end (rotation fixed)."""
        return cls(clamped=True)

    @classmethod
    def elastic(cls, stiffness: float, inertia: float = 0.0) -> End:
        """An elastic coupling (N m/rad) to a rigidly driven motor, plus an inertia (kg m²)."""
        return cls(stiffness=stiffness, inertia=inertia)

    @classmethod
    def flywheel(cls, inertia: float) -> End:
        """A flywheel (kg m²) on an otherwise free end."""
        return cls(inertia=inertia)


@dataclass(frozen=True, eq=False)
class Chain:
    """A torsional shaft of ``n_nodes`` nodes carrying ``n_units`` identical mechanisms.

    The general constructor: any node inertias, segment stiffnesses, ground springs and
    clamps (:func:`chain` builds the common uniform shaft from its diameter). Node i has
    the rotation θ_i (rad), rotary inertia ``node_inertia[i]`` (kg m²: discs, lumped
    shaft; 0 for a massless node) and a spring ``ground[i]`` (N m/rad) to ground;
    segment i joins nodes i and i + 1 with the torsional stiffness ``spring[i]``
    (N m/rad, > 0). Unit u sits on node ``unit_node[u]`` and runs at φ + ``phase[u]``.
    ``left`` and ``right`` (:class:`End`) add an end condition to node 0 and node
    n_nodes − 1: their inertia to ``node_inertia``, their stiffness to ``ground``,
    their clamp to ``clamped``. They are applied once, here, and stored as None, so
    ``dataclasses.replace`` of a chain does not apply them twice.

    Example: three nodes, a flywheel and a coupling at the left, units on nodes 1 and 2::

        Chain(unit, node_inertia=[0.0, 2e-3, 2e-3], spring=[5e3, 8e4],
              unit_node=[1, 2], phase=[0.0, np.pi], left=End.elastic(2e4, 0.8))

    Attributes
    ----------
    unit : object
        The mechanism: ``unit.n`` coordinates, ``unit.M(phi)`` (S + (m, m)),
        ``unit.B(phi, Omega)`` and ``unit.C(phi, Omega, Omega_dot)`` (S + (m, m)) for
        ``phi`` of any shape S, rad (a :class:`~femmech.mechanisms.RheolinearModel`).
    node_inertia : ndarray (n_nodes,)
        Rotary inertia of each node (discs, lumped shaft, end inertias), kg m², >= 0.
    spring : ndarray (n_nodes - 1,)
        Torsional stiffness of the shaft segment between node i and i + 1, N m/rad, > 0.
    unit_node : ndarray (n_units,) of int
        Node carrying each unit (distinct nodes).
    phase : ndarray (n_units,) or float
        Phase angle δ_u of each unit, rad: unit u sees the drive angle φ + δ_u.
    ground : ndarray (n_nodes,), optional
        Torsional spring from each node to ground, N m/rad (elastic ends); default 0.
    clamped : ndarray (n_nodes,) of bool, optional
        Nodes whose rotation is fixed (removed from the coordinates); default none.
    attach : int
        Index of the unit coordinate that is the rotation of its node.
    x : ndarray (n_nodes,), optional
        Axial position of each node, m (plots only); default 0, 1, 2, ...
    left, right : End, optional
        End conditions added to the first and last node (see above); None after
        construction.
    """

    unit: object
    node_inertia: np.ndarray
    spring: np.ndarray
    unit_node: np.ndarray
    phase: np.ndarray
    ground: np.ndarray = None
    clamped: np.ndarray = None
    attach: int = 0
    x: np.ndarray = None
    left: End | None = None
    right: End | None = None
    _index: tuple = field(init=False, repr=False)
    _shaft_matrices: tuple = field(init=False, repr=False)

    def __post_init__(self):
        J = _vector("node_inertia", self.node_inertia, lower=0.0)
        n_nodes = J.size
        if n_nodes < 1:
            raise ValueError("a chain needs at least one node")
        k = _vector("spring", self.spring, lower=0.0, strict=True)
        if k.size != n_nodes - 1:
            raise ValueError(f"spring must have n_nodes - 1 = {n_nodes - 1} entries,"
                             f" got {k.size}")
        nodes = np.asarray(self.unit_node)
        if nodes.ndim != 1 or not np.issubdtype(nodes.dtype, np.integer):
            raise ValueError("unit_node must be a 1-D array of node indices")
        if nodes.size and (nodes.min() < 0 or nodes.max() >= n_nodes):
            bad = nodes[(nodes < 0) | (nodes >= n_nodes)][0]
            raise ValueError(f"unit_node {bad} is not a node (0..{n_nodes - 1})")
        if np.unique(nodes).size != nodes.size:
            raise ValueError("two units sit on the same node; give each unit its own node")
        phase = np.broadcast_to(_vector("phase", np.atleast_1d(self.phase)), nodes.shape)
        ground = np.zeros(n_nodes) if self.ground is None else _vector(
            "ground", self.ground, lower=0.0)
        clamped = (np.zeros(n_nodes, bool) if self.clamped is None
                   else np.asarray(self.clamped, dtype=bool))
        x = np.arange(n_nodes, dtype=float) if self.x is None else _vector("x", self.x)
        for name, value in (("ground", ground), ("clamped", clamped), ("x", x)):
            if value.shape != (n_nodes,):
                raise ValueError(f"{name} must have n_nodes = {n_nodes} entries,"
                                 f" got {value.shape}")
        J, ground, clamped = _apply_ends(J, ground, clamped, self.left, self.right)
        m = int(getattr(self.unit, "n", 0))
        if m < 1 or not 0 <= self.attach < m:
            raise ValueError(f"attach must index a unit coordinate (0..{m - 1}),"
                             f" got {self.attach}")
        for name, value in (("node_inertia", J), ("spring", k), ("unit_node", nodes),
                            ("phase", np.array(phase, dtype=float)), ("ground", ground),
                            ("clamped", clamped), ("x", x), ("left", None), ("right", None)):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "_index", _dof_index(self))
        object.__setattr__(self, "_shaft_matrices", self._shaft())

    @property
    def n_nodes(self) -> int:
        return self.node_inertia.size

    @property
    def n_units(self) -> int:
        return self.unit_node.size

    @property
    def m(self) -> int:
        """Coordinates per unit (one of them, ``attach``, is its node's rotation)."""
        return int(self.unit.n)

    @property
    def n(self) -> int:
        """Number of coordinates of the assembled model."""
        return int(self._index[2])

    @property
    def node_dof(self) -> np.ndarray:
        """(n_nodes,) coordinate of each node's rotation, -1 for clamped nodes."""
        return self._index[0]

    @property
    def unit_dofs(self) -> np.ndarray:
        """(n_units, m) coordinates of each unit's coordinates (its ``attach`` column is
        its node's rotation, -1 on a clamped node)."""
        return self._index[1]

    def unit_matrices(self, phi, Omega: float = 0.0, Omega_dot: float = 0.0):
        """Matrices of every unit at drive angle(s) φ (rad).

        Returns
        -------
        M, B, C : ndarray S + (n_units, m, m)
            ``unit.M(φ + δ_u)``, ``unit.B(φ + δ_u, Ω)``, ``unit.C(φ + δ_u, Ω, Ω̇)``.
        """
        angle = np.asarray(phi, dtype=float)[..., None] + self.phase
        return (self.unit.M(angle), self.unit.B(angle, Omega),
                self.unit.C(angle, Omega, Omega_dot))

    def sparse_matrices(self, phi: float, Omega: float = 0.0, Omega_dot: float = 0.0):
        """Assembled ``(M, B, C)`` at one drive angle φ (rad): scipy.sparse CSR (n, n).

        Units: M in kg m² (rotations) / kg (translations), C in N m/rad or N/m, B in
        N m s/rad or N s/m, as the unit's coordinates give.
        """
        Mu, Bu, Cu = self.unit_matrices(float(phi), Omega, Omega_dot)
        shaft_M, shaft_C = self._shaft_matrices
        shaft_B = sp.coo_matrix((self.n, self.n))
        return tuple((shaft + self._scatter(U)).tocsr() for shaft, U in
                     ((shaft_M, Mu), (shaft_B, Bu), (shaft_C, Cu)))

    def M(self, phi) -> np.ndarray:
        """Dense assembled mass matrix, S + (n, n), for small chains (sweeps)."""
        angle = np.asarray(phi, dtype=float)
        return self._dense(angle, self.unit.M(angle[..., None] + self.phase),
                           self._shaft_matrices[0])

    def B(self, phi, Omega) -> np.ndarray:
        """Dense assembled damping matrix, S + (n, n)."""
        angle = np.asarray(phi, dtype=float)
        return self._dense(angle, self.unit.B(angle[..., None] + self.phase, Omega), None)

    def C(self, phi, Omega=0.0, Omega_dot=0.0) -> np.ndarray:
        """Dense assembled stiffness matrix, S + (n, n)."""
        angle = np.asarray(phi, dtype=float)
        blocks = self.unit.C(angle[..., None] + self.phase, Omega, Omega_dot)
        return self._dense(angle, blocks, self._shaft_matrices[1])

    def F(self, phi, Omega=0.0, Omega_dot=0.0) -> np.ndarray:
        """Assembled force vector, S + (n,): the units' F(φ + δ_u, Ω, Ω̇) (the shaft
        carries no load; components on clamped rotations are dropped)."""
        angle = np.asarray(phi, dtype=float)
        Fu = self.unit.F(angle[..., None] + self.phase, Omega, Omega_dot)  # S+(N, m)
        flat = Fu.reshape(-1, self.n_units * self.m)
        dofs = self.unit_dofs.reshape(-1)
        keep = dofs >= 0
        out = np.zeros((flat.shape[0], self.n))
        np.add.at(out, (slice(None), dofs[keep]), flat[:, keep])
        return out.reshape(angle.shape + (self.n,))

    def _dense(self, angle, blocks, shaft) -> np.ndarray:
        """Dense (S + (n, n)) assembly of unit blocks S + (n_units, m, m) plus a shaft part."""
        flat = blocks.reshape((-1,) + blocks.shape[-3:])
        out = np.zeros((flat.shape[0], self.n, self.n))
        if shaft is not None:
            out += shaft.toarray()
        dofs = self.unit_dofs
        r = np.broadcast_to(dofs[:, :, None], flat.shape[1:])
        c = np.broadcast_to(dofs[:, None, :], flat.shape[1:])
        keep = (r >= 0) & (c >= 0)
        np.add.at(out, (slice(None), r[keep], c[keep]), flat[:, keep])
        return out.reshape(angle.shape + (self.n, self.n))

    def _shaft(self):
        """Shaft mass and stiffness (n, n) sparse: node inertias, segments, ground."""
        dof = self.node_dof
        rows, cols, vals = [], [], []
        for (i, j, k) in zip(dof[:-1], dof[1:], self.spring, strict=True):
            for r, c, v in ((i, i, k), (j, j, k), (i, j, -k), (j, i, -k)):
                if r >= 0 and c >= 0:
                    rows.append(r), cols.append(c), vals.append(v)
        free = dof >= 0
        rows += dof[free].tolist()
        cols += dof[free].tolist()
        vals += self.ground[free].tolist()
        C = sp.coo_matrix((vals, (rows, cols)), shape=(self.n, self.n))
        M = sp.coo_matrix((self.node_inertia[free], (dof[free], dof[free])),
                          shape=(self.n, self.n))
        return M, C

    def _scatter(self, blocks) -> sp.coo_matrix:
        """Sum the unit blocks (n_units, m, m) into an (n, n) sparse matrix (clamped
        coordinates dropped)."""
        dofs = self.unit_dofs
        r = np.broadcast_to(dofs[:, :, None], blocks.shape)
        c = np.broadcast_to(dofs[:, None, :], blocks.shape)
        keep = (r >= 0) & (c >= 0)
        return sp.coo_matrix((blocks[keep], (r[keep], c[keep])), shape=(self.n, self.n))


def _apply_ends(J, ground, clamped, left, right):
    """Node inertias, ground springs and clamps with the End conditions ``left`` (node 0)
    and ``right`` (last node) added (copies)."""
    J, ground, clamped = J.copy(), ground.copy(), clamped.copy()
    for name, end, node in (("left", left, 0), ("right", right, -1)):
        if end is None:
            continue
        if not isinstance(end, End):
            raise ValueError(f"Chain {name} must be an End (End.free(), End.fixed(),"
                             f" End.elastic(k, J), End.flywheel(J)), got {end!r}")
        J[node] += end.inertia
        ground[node] += end.stiffness
        clamped[node] |= end.clamped
    return J, ground, clamped


def _dof_index(chain: Chain):
    """Coordinate numbering node by node: (node_dof, unit_dofs, n)."""
    m = chain.m
    unit_at = np.full(chain.n_nodes, -1)
    unit_at[chain.unit_node] = np.arange(chain.n_units)
    node_dof = np.full(chain.n_nodes, -1)
    unit_dofs = np.full((chain.n_units, m), -1)
    internal = [i for i in range(m) if i != chain.attach]
    n = 0
    for node in range(chain.n_nodes):
        if not chain.clamped[node]:
            node_dof[node] = n
            n += 1
        u = unit_at[node]
        if u >= 0:
            unit_dofs[u, chain.attach] = node_dof[node]
            unit_dofs[u, internal] = np.arange(n, n + m - 1)
            n += m - 1
    return node_dof, unit_dofs, n


def _vector(name: str, value, lower: float | None = None, strict: bool = False) -> np.ndarray:
    v = np.asarray(value, dtype=float).reshape(-1)
    bad = ~np.isfinite(v)
    if lower is not None:
        bad |= (v <= lower) if strict else (v < lower)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        need = "finite" + ("" if lower is None else f" and {'>' if strict else '>='} {lower}")
        raise ValueError(f"{name}[{i}] = {v[i]!r} must be {need}")
    return v


def torsion_segment(length: float, diameter: float, bore: float = 0.0, G: float = STEEL_G,
                    rho: float = STEEL_RHO) -> tuple[float, float]:
    """Stiffness (N m/rad) and rotary inertia (kg m²) of a round shaft segment.

    ``k = G I_p / L`` and ``J = ρ I_p L`` with ``I_p = π (d⁴ − d_i⁴) / 32`` (m⁴); lengths
    and diameters in m, G in Pa, ρ in kg/m³.
    """
    for name, value in (("length", length), ("diameter", diameter), ("G", G), ("rho", rho)):
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be finite and > 0, got {value!r}")
    if not 0 <= bore < diameter:
        raise ValueError(f"bore must lie in [0, diameter = {diameter}), got {bore!r}")
    Ip = np.pi * (diameter**4 - bore**4) / 32
    return G * Ip / length, rho * Ip * length


def chain(unit, n_units: int, spacing: float, shaft_diameter: float | None = None, *,
          station_inertia: float = 0.0, phases=0.0, left: End = End(), right: End = End(),
          end_length: float | None = None, cells: bool = False, bore: float = 0.0,
          G: float = STEEL_G, rho: float = STEEL_RHO, attach: int = 0,
          shaft_stiffness: float | None = None, shaft_inertia: float | None = None) -> Chain:
    """A uniform main shaft with ``n_units`` equally spaced identical mechanisms.

    Nodes: one per unit, ``spacing`` (m) apart; with ``end_length`` (m) a further node at
    each end, that far from the outer units, carries the end condition (a shaft stub to
    the drive coupling or bearing). Each shaft segment's inertia is lumped half to each of
    its nodes; every unit node gets ``station_inertia`` (kg m²: a disc, the cam hub).
    With ``cells=True`` the shaft reaches half a spacing beyond the outer units instead, so
    every unit node carries exactly one spacing of shaft inertia: the chain is then a row
    of identical cells (what the cyclic closed form and the continuum assume).

    The shaft per spacing has the stiffness c_s = G I_p / spacing and the inertia
    J_s = ρ I_p spacing (:func:`torsion_segment`) unless given exactly:
    ``shaft_stiffness`` = c_s (N m/rad) and ``shaft_inertia`` = J_s (kg m², 0 for a
    massless shaft) replace the values from the diameter; an end stub of length L then
    has c_s · spacing / L and J_s · L / spacing. With both given, ``shaft_diameter`` may
    be None.

    Parameters
    ----------
    unit : object
        Mechanism model (:class:`Chain` attribute ``unit``); its coordinate ``attach``
        is the shaft rotation at its node.
    n_units : int
    spacing : float
        Distance between neighbouring units, m.
    shaft_diameter : float, optional
        Outer diameter, m (``bore``: inner diameter, m); needed unless both
        ``shaft_stiffness`` and ``shaft_inertia`` are given.
    end_length : float, optional
        Length of an end stub, m (adds an end node at each end).
    cells : bool
        Shaft inertia as identical cells (see above).
    station_inertia : float
        Inertia added at each unit node, kg m².
    phases : float or array_like (n_units,)
        Phase angle δ_u of each unit, rad.
    left, right : End
        End conditions (applied at the end nodes).
    G, rho : float
        Shear modulus (Pa) and density (kg/m³) of the shaft.
    shaft_stiffness : float, optional
        Exact torsional stiffness of one spacing of shaft, N m/rad (> 0).
    shaft_inertia : float, optional
        Exact rotary inertia of one spacing of shaft, kg m² (>= 0; 0: massless shaft).

    Returns
    -------
    Chain
    """
    if int(n_units) != n_units or n_units < 1:
        raise ValueError(f"n_units must be a positive integer, got {n_units!r}")
    n_units = int(n_units)
    if not (np.isfinite(spacing) and spacing > 0):
        raise ValueError(f"spacing must be finite and > 0, got {spacing!r}")
    k_s, J_s = _shaft_per_spacing(spacing, shaft_diameter, bore, G, rho, shaft_stiffness,
                                  shaft_inertia)
    lengths = [spacing] * (n_units - 1)
    if end_length is not None:
        if not (np.isfinite(end_length) and end_length > 0):
            raise ValueError(f"end_length must be finite and > 0, got {end_length!r}")
        lengths = [end_length] + lengths + [end_length]
    ratio = np.asarray(lengths, dtype=float) / spacing
    spring, Jseg = k_s / ratio, J_s * ratio
    n_nodes = len(lengths) + 1
    J = np.zeros(n_nodes)
    J[:-1] += Jseg / 2
    J[1:] += Jseg / 2
    first = 0 if end_length is None else 1
    unit_node = np.arange(first, first + n_units)
    if cells:  # the half spacing beyond each outer unit
        J[unit_node[0]] += J_s / 2
        J[unit_node[-1]] += J_s / 2
    J[unit_node] += station_inertia
    x = np.concatenate([[0.0], np.cumsum(lengths)])
    return Chain(unit, J, spring, unit_node, np.broadcast_to(np.asarray(phases, float),
                 (n_units,)).copy(), None, None, attach, x, left=left, right=right)


def _shaft_per_spacing(spacing, diameter, bore, G, rho, stiffness, inertia):
    """(c_s N m/rad, J_s kg m²) of one spacing of shaft: the exact values where given,
    else from the diameter (:func:`torsion_segment`)."""
    if stiffness is not None and not (np.isfinite(stiffness) and stiffness > 0):
        raise ValueError(f"shaft_stiffness must be finite and > 0 N m/rad, got {stiffness!r}")
    if inertia is not None and not (np.isfinite(inertia) and inertia >= 0):
        raise ValueError(f"shaft_inertia must be finite and >= 0 kg m², got {inertia!r}")
    if stiffness is not None and inertia is not None:
        return float(stiffness), float(inertia)
    if diameter is None:
        raise ValueError("give shaft_diameter, or both shaft_stiffness and shaft_inertia")
    k, J = torsion_segment(spacing, diameter, bore, G, rho)
    return (k if stiffness is None else float(stiffness)), (J if inertia is None
                                                            else float(inertia))


def follower_unit(cam, inertia: float, mass: float, stiffness: float, damping: float = 0.0,
                  force: float = 0.0, c_g: float = 0.0):
    """The standard unit: Table 5.1 case 1 without its shaft spring (the chain is the shaft).

    A cam (or linkage) ``cam`` (position function U(ψ), m, of the shaft angle ψ, rad) on
    its node (rotary inertia ``inertia``, kg m², of the cam hub about the shaft) moves a
    follower mass ``mass`` (kg) through its elastic follower train ``stiffness`` (N/m;
    ``damping`` N s/m) against a process force ``force`` (N). ``c_g`` (N/m) is a spring
    from the follower to ground (the frame: a return spring), acting on the follower's
    absolute position x2 = U(ψ) + q2 and unstressed at x2 = 0 (potential ½ c_g x2²).
    Coordinates (q1, q2): q1 the shaft rotation at the node (rad, ``attach = 0``), q2 the
    follower's elastic deflection relative to the cam motion (m). Frozen (Ω = 0)::

        M = [[J + m U'², m U'], [m U', m]]
        C = [[F U'' + c_g (U'² + U U''), c_g U'], [c_g U', c + c_g]]

    (c_g couples q1 and q2 through U': the unit's internal coordinate is relative to
    the cam motion; see the continuum's validity conditions in docs/chain.md).

    Returns
    -------
    RheolinearModel
    """
    from femmech.mechanisms import Spring, rheolinear, table_5_1_case
    from femmech.mechanisms.catalogue import coordinate_labels

    for name, value in (("inertia", inertia), ("mass", mass), ("stiffness", stiffness),
                        ("damping", damping), ("c_g", c_g)):
        if not (np.isfinite(value) and value >= 0):
            raise ValueError(f"follower_unit: {name} must be finite and >= 0, got {value!r}")
    if not np.isfinite(force):
        raise ValueError(f"follower_unit: force must be finite, got {force!r}")
    if not mass > 0 or not stiffness > 0:
        raise ValueError(f"follower_unit: mass and stiffness must be > 0, got {mass!r},"
                         f" {stiffness!r}")
    values = {"J1": inertia, "m2": mass, "c1": 0.0, "c2": stiffness, "b1": 0.0,
              "b2": damping, "F2": force}
    mech = replace(table_5_1_case(1), labels=coordinate_labels(
        "follower_unit(cam, inertia, mass, stiffness)"))
    if c_g > 0:
        x2 = next(e.position[0] for e in mech.elements if type(e).__name__ == "PointMass")
        cg = sympy.Symbol("cg", positive=True)
        mech = replace(mech, elements=mech.elements + (Spring(cg, x2),))
        values["cg"] = c_g
    return rheolinear(mech, values, {"U": cam})
