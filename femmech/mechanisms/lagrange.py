"""Symbolic equations of motion of a mechanism: 2nd-kind, mixed-type and rheolinear.

From a :class:`~femmech.mechanisms.symbolic.Mechanism` this module derives with sympy

* the generalized masses m_jk(q) = Σ m r_,j·r_,k + Σ J α_,j α_,k (seed 5.2.1 eq. 6),
* the terms m_klj = m_jk,l + m_jl,k − m_kl,j (eq. 13 with errata item 1),
* the potential gradient W_pot,j and stiffnesses c_jk = W_pot,jk (eqs. 7–9),
* the generalized non-potential forces Q*_j = Σ F_i ∂s_i/∂q_j (eqs. 10–12),
* the constraint Jacobian h_ij = ∂f_i/∂q_j and the terms Σ h_ik,l q̇_k q̇_l (eqs. 15–21),
* the rheolinear matrices M, B, C and force F about the programmed drive motion
  (seed 5.2.2 eq. 10 with errata items 9–11).

The nonlinear equations of the 2nd kind (eq. 13, with the exact potential gradient in
place of Σ c_jk q_k) read

    Σ_k m_jk q̈_k + ½ Σ_k Σ_l m_klj q̇_k q̇_l + W_pot,j = Q*_j(q, q̇),   j = 1 … N.

Symbols follow the textbook: M mass, B damping, C stiffness, F force.

Uses only mechanisms.symbolic.
"""

import functools
from dataclasses import dataclass

import sympy

from femmech.mechanisms.symbolic import (
    Damper,
    Load,
    Mechanism,
    PointMass,
    Potential,
    RotaryInertia,
    Spring,
    velocity_symbol,
)

__all__ = ["LagrangeTerms", "RheolinearTerms", "lagrange_terms", "rheolinear_terms"]


@dataclass(frozen=True)
class LagrangeTerms:
    """Symbolic terms of the nonlinear equations of motion (seed 5.2.1 eqs. 6–21).

    Attributes
    ----------
    coordinates, velocities : tuple of sympy.Symbol (N,)
        q and q̇.
    mass : sympy.ImmutableMatrix (N, N)
        m_jk(q), kg, kg·m or kg·m² depending on the coordinates.
    christoffel : sympy.ImmutableDenseNDimArray (N, N, N)
        m_klj indexed ``[k, l, j]`` (errata item 1), so that equation j contains
        ½ Σ_kl m_klj q̇_k q̇_l.
    potential : sympy.Expr
        W_pot(q), J.
    gradient : sympy.ImmutableMatrix (N, 1)
        W_pot,j.
    stiffness : sympy.ImmutableMatrix (N, N)
        c_jk = W_pot,jk (eq. 9), evaluated at q (not at q = 0).
    forces : sympy.ImmutableMatrix (N, 1)
        Q*_j(q, q̇).
    constraint_jacobian : sympy.ImmutableMatrix (n_c, N)
        h_ij = ∂f_i/∂q_j (eq. 17).
    constraint_curvature : sympy.ImmutableMatrix (n_c, 1)
        Σ_k Σ_l h_ik,l q̇_k q̇_l, so that Σ_k h_ik q̈_k = −(this) (eq. 21, scleronomic).
    """

    coordinates: tuple[sympy.Symbol, ...]
    velocities: tuple[sympy.Symbol, ...]
    mass: sympy.ImmutableMatrix
    christoffel: sympy.ImmutableDenseNDimArray
    potential: sympy.Expr
    gradient: sympy.ImmutableMatrix
    stiffness: sympy.ImmutableMatrix
    forces: sympy.ImmutableMatrix
    constraint_jacobian: sympy.ImmutableMatrix
    constraint_curvature: sympy.ImmutableMatrix

    def velocity_terms(self) -> sympy.ImmutableMatrix:
        """Return ½ Σ_k Σ_l m_klj q̇_k q̇_l as an (N, 1) matrix."""
        n = len(self.coordinates)
        qd = self.velocities
        return sympy.ImmutableMatrix([
            sympy.Rational(1, 2) * sum(self.christoffel[k, l, j] * qd[k] * qd[l]
                                       for k in range(n) for l in range(n))
            for j in range(n)])


def _jacobian(expr: sympy.Expr, q) -> list[sympy.Expr]:
    return [sympy.diff(expr, qj) for qj in q]


def _mass_matrix(mech: Mechanism) -> sympy.Matrix:
    """m_jk = Σ m r_,j·r_,k + Σ J α_,j α_,k (seed 5.2.1 eq. 6)."""
    q = mech.coordinates
    n = len(q)
    M = sympy.zeros(n, n)
    for el in mech.elements:
        if isinstance(el, PointMass):
            for x in el.position:
                g = sympy.Matrix(_jacobian(x, q))
                M += el.m * g * g.T
        elif isinstance(el, RotaryInertia):
            g = sympy.Matrix(_jacobian(el.angle, q))
            M += el.J * g * g.T
    return M


def _potential(mech: Mechanism) -> sympy.Expr:
    V = sympy.Integer(0)
    for el in mech.elements:
        if isinstance(el, Spring):
            V += el.c * el.deflection**2 / 2
        elif isinstance(el, Potential):
            V += el.energy
    return V


def _forces(mech: Mechanism, qd) -> sympy.Matrix:
    """Q*_j = Σ F ∂s/∂q_j − Σ b ṡ ∂s/∂q_j (seed 5.2.1 eqs. 10–12)."""
    q = mech.coordinates
    Q = sympy.zeros(len(q), 1)
    for el in mech.elements:
        if isinstance(el, Load):
            Q += el.magnitude * sympy.Matrix(_jacobian(el.displacement, q))
        elif isinstance(el, Damper):
            g = sympy.Matrix(_jacobian(el.deflection, q))
            rate = sum(gk * v for gk, v in zip(g, qd, strict=True))
            Q += -el.b * rate * g
    return Q


@functools.cache
def lagrange_terms(mech: Mechanism) -> LagrangeTerms:
    """Derive the symbolic terms of the equations of motion of ``mech``.

    Parameters
    ----------
    mech : Mechanism
        The symbolic description (hashable; results are cached per mechanism).

    Returns
    -------
    LagrangeTerms
        m_jk, m_klj, W_pot, W_pot,j, c_jk, Q*_j, h_ij and the constraint curvature terms.
    """
    q = mech.coordinates
    n = len(q)
    qd = tuple(velocity_symbol(qj) for qj in q)
    M = _mass_matrix(mech)
    dM = [[[sympy.diff(M[j, k], q[l]) for l in range(n)] for k in range(n)] for j in range(n)]
    # m_klj = m_jk,l + m_jl,k − m_kl,j (errata item 1), stored as [k, l, j]
    chris = sympy.ImmutableDenseNDimArray(
        [[[dM[j][k][l] + dM[j][l][k] - dM[k][l][j] for j in range(n)] for l in range(n)]
         for k in range(n)])
    V = _potential(mech)
    grad = sympy.Matrix(_jacobian(V, q))
    stiffness = sympy.hessian(V, q) if n else sympy.zeros(0, 0)
    H = sympy.Matrix([_jacobian(f, q) for f in mech.constraints]) if mech.constraints else \
        sympy.zeros(0, n)
    curvature = sympy.Matrix([
        sum(sympy.diff(H[i, k], q[l]) * qd[k] * qd[l] for k in range(n) for l in range(n))
        for i in range(H.shape[0])]) if mech.constraints else sympy.zeros(0, 1)
    return LagrangeTerms(q, qd, sympy.ImmutableMatrix(M), chris, V, sympy.ImmutableMatrix(grad),
                         sympy.ImmutableMatrix(stiffness),
                         sympy.ImmutableMatrix(_forces(mech, qd)), sympy.ImmutableMatrix(H),
                         sympy.ImmutableMatrix(curvature))


@dataclass(frozen=True)
class RheolinearTerms:
    """Symbolic rheolinear system M q̈ + B q̇ + C q = F (seed 5.2.2 eqs. 9–10, errata 9–11).

    The matrices refer to the vibration coordinates only and are functions of the drive
    positions φ_p, speeds Ω_p and accelerations Ω̇_p of the programmed motion
    q_p(t) (p over the drives), with the vibration coordinates set to zero.

    Attributes
    ----------
    coordinates : tuple of sympy.Symbol (n,)
        Vibration coordinates.
    drives : tuple of sympy.Symbol (F,)
        Drive coordinates.
    angle, speed, acceleration : tuple of sympy.Symbol (F,)
        Symbols φ_p, Ω_p, Ω̇_p standing for q_p, q̇_p, q̈_p on the programmed motion.
    M, B, C : sympy.ImmutableMatrix (n, n)
        Mass, damping and stiffness matrices; C may be unsymmetric.
    F : sympy.ImmutableMatrix (n, 1)
        Force vector, including −W_pot,j on the rigid motion (errata item 11).
    """

    coordinates: tuple[sympy.Symbol, ...]
    drives: tuple[sympy.Symbol, ...]
    angle: tuple[sympy.Symbol, ...]
    speed: tuple[sympy.Symbol, ...]
    acceleration: tuple[sympy.Symbol, ...]
    M: sympy.ImmutableMatrix
    B: sympy.ImmutableMatrix
    C: sympy.ImmutableMatrix
    F: sympy.ImmutableMatrix


def _drive_symbols(drives):
    one = len(drives) == 1
    names = [("phi", "Omega", "Omega_dot") if one else
             (f"phi_{d.name}", f"Omega_{d.name}", f"Omega_dot_{d.name}") for d in drives]
    return tuple(tuple(sympy.Symbol(nm[i], real=True) for nm in names) for i in range(3))


@functools.cache
def rheolinear_terms(mech: Mechanism) -> RheolinearTerms:
    """Linearise the equations of ``mech`` about its programmed drive motion.

    Implements seed 5.2.2 eq. 10 with the corrections of errata items 9–11
    (indices e: vibration coordinates, p, l: drives, bars: on the rigid motion)::

        M_jk = m̄_jk
        B_jk = b_jk + Σ_l m̄_klj q̇_l,                b_jk = −∂Q*_j/∂q̇_k
        C_jk = c_jk − Q*_j,k + Σ_p [m_jp,k q̈_p + ½ Σ_l m_plj,k q̇_p q̇_l]
        F_j  = Q̄*_j − W_pot,j − Σ_k [m̄_jk q̈_k + ½ Σ_l m̄_klj q̇_k q̇_l]

    with c_jk = W_pot,jk on the rigid motion.

    Parameters
    ----------
    mech : Mechanism
        Must have at least one drive coordinate and at least one vibration coordinate.

    Returns
    -------
    RheolinearTerms
    """
    if not mech.drives or not mech.vibration_coordinates:
        raise ValueError(f"mechanism {mech.name!r}: the rheolinear form needs drive and "
                         "vibration coordinates")
    t = lagrange_terms(mech)
    q, qd = mech.coordinates, t.velocities
    phi, Om, Omd = _drive_symbols(mech.drives)
    used = {s.name for s in t.mass.free_symbols | t.forces.free_symbols | t.potential.free_symbols}
    clash = sorted(used & {s.name for s in phi + Om + Omd})
    if clash:
        raise ValueError(f"mechanism {mech.name!r} uses the names {clash}, which the "
                         "rheolinear form reserves for the drive angle, speed and acceleration")
    e = [q.index(x) for x in mech.vibration_coordinates]
    d = [q.index(x) for x in mech.drives]
    rigid = {q[i]: 0 for i in e} | {qd[i]: 0 for i in e}
    rigid |= {q[i]: phi[a] for a, i in enumerate(d)} | {qd[i]: Om[a] for a, i in enumerate(d)}
    qdot = {i: Om[a] for a, i in enumerate(d)}
    qddot = {i: Omd[a] for a, i in enumerate(d)}
    m, ch, Q = t.mass, t.christoffel, t.forces

    def on_rigid(x):
        return sympy.sympify(x).xreplace(rigid)

    def inertia(j):  # Σ_p [m_jp q̈_p + ½ Σ_l m_plj q̇_p q̇_l]
        return sum(m[j, p] * qddot[p] + sum(ch[p, l, j] * qdot[p] * qdot[l] for l in d) / 2
                   for p in d)

    M = [[on_rigid(m[j, k]) for k in e] for j in e]
    B = [[on_rigid(-sympy.diff(Q[j], qd[k]) + sum(ch[k, l, j] * qdot[l] for l in d))
          for k in e] for j in e]
    C = [[on_rigid(t.stiffness[j, k] - sympy.diff(Q[j], q[k]) + sympy.diff(inertia(j), q[k]))
          for k in e] for j in e]
    F = [[on_rigid(Q[j] - t.gradient[j] - inertia(j))] for j in e]
    return RheolinearTerms(mech.vibration_coordinates, mech.drives, phi, Om, Omd,
                           *(sympy.ImmutableMatrix(x) for x in (M, B, C, F)))
