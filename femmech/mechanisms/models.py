"""Numerical mechanism models: rheolinear, Lagrange 2nd kind and mixed type.

Each model is built from a symbolic :class:`~femmech.mechanisms.symbolic.Mechanism`, the
values of its parameters and the numeric position functions, and evaluates its matrices
vectorised over arrays of angles or states. The symbolic derivation and ``lambdify`` are
cached per mechanism, so building many models with different parameter values is cheap.

Symbols follow the seed chapter: M mass, B damping, C stiffness, F force (5.2.2 eq. 9).

Uses mechanisms.symbolic, .lagrange, .evaluate and
.position.
"""

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import sympy

from femmech.mechanisms.evaluate import CompiledExpressions, check_bindings, compile_expressions
from femmech.mechanisms.lagrange import (
    LagrangeTerms,
    RheolinearTerms,
    lagrange_terms,
    rheolinear_terms,
)
from femmech.mechanisms.position import PositionFunction, preimages
from femmech.mechanisms.symbolic import Mechanism

__all__ = [
    "Accelerations",
    "LagrangeModel",
    "MixedModel",
    "MixedSolution",
    "RheolinearModel",
    "mixed_type",
    "rheolinear",
    "second_kind",
]


def _flat(matrix) -> tuple:
    return tuple(matrix[i, j] for i in range(matrix.shape[0]) for j in range(matrix.shape[1]))


def _known_parameters(mechanism: Mechanism) -> set[str]:
    """Names of all parameters of the mechanism (used or not by a given form)."""
    return {s.name for s in mechanism.parameters}


def _param_values(compiled: CompiledExpressions, values: Mapping[str, float]) -> list[float]:
    return [values[s.name] for s in compiled.parameters]


@dataclass(frozen=True, eq=False)
class RheolinearModel:
    """Rheolinear model M(φ) q̈ + B(φ, Ω) q̇ + C(φ, Ω, Ω̇) q = F(φ, Ω, Ω̇).

    Seed 5.2.2 eqs. 9–10 (errata 9–11), about the programmed drive motion q_p = φ,
    q̇_p = Ω, q̈_p = Ω̇; q holds the n vibration coordinates. Build with
    :func:`rheolinear`.

    Shapes: for one drive, ``phi`` has any shape S and results have shape S + (n, n)
    (matrices) or S + (n,) (force). For F > 1 drives, ``phi`` has shape S + (F,).
    ``Omega`` and ``Omega_dot`` broadcast against ``phi``. Units: φ in rad (or m for a
    translational drive), Ω in rad/s, Ω̇ in rad/s².
    """

    mechanism: Mechanism
    terms: RheolinearTerms
    parameters: Mapping[str, float]
    position_functions: Mapping[str, PositionFunction]
    _compiled: tuple[CompiledExpressions, ...]

    @property
    def n(self) -> int:
        """Number of vibration coordinates."""
        return len(self.terms.coordinates)

    @property
    def coordinate_names(self) -> tuple[str, ...]:
        """Names of the vibration coordinates (order of rows and columns)."""
        return tuple(q.name for q in self.terms.coordinates)

    def _evaluate(self, which: int, phi, Omega, Omega_dot, shape) -> np.ndarray:
        n_drives = len(self.terms.drives)
        phi = np.asarray(phi, dtype=float)
        if n_drives > 1 and (phi.ndim == 0 or phi.shape[-1] != n_drives):
            raise ValueError(f"phi must have shape (..., {n_drives}) for {n_drives} drives, "
                             f"got {phi.shape}")
        phi, Omega, Omega_dot = np.broadcast_arrays(phi, Omega, Omega_dot)
        cols = [np.moveaxis(x, -1, 0) if n_drives > 1 else x[None] for x in
                (phi, Omega, Omega_dot)]
        inputs = [c for x in cols for c in x]
        compiled = self._compiled[which]
        with np.errstate(all="ignore"):  # reported below, naming the position
            out = compiled(inputs, _param_values(compiled, self.parameters),
                           self.position_functions)
        batch = phi.shape[:-1] if n_drives > 1 else phi.shape
        out = out.reshape(batch + shape)
        bad = ~np.isfinite(out.reshape(batch + (-1,))).all(axis=-1)
        if bad.any():
            where = phi[np.unravel_index(np.flatnonzero(bad)[0], batch)] if batch else phi
            raise ValueError(
                f"mechanism {self.mechanism.name!r}: {'MBCF'[which]} is not finite at drive"
                f" position {np.round(where, 12).tolist()} ({int(bad.sum())} of"
                f" {bad.size} positions): outside the range of motion, or a singular"
                " position (stroke limit, dead centre) where a position derivative is"
                " infinite")
        return out

    def breakpoints(self) -> np.ndarray:
        """Drive angles in [0, 2π), rad, where M, B, C or F may jump (cam joints), sorted.

        Collected from the position functions that offer ``breakpoints()``
        (:class:`~femmech.mechanisms.CamProfile`) through their arguments, which must be
        linear in the drive angle on the programmed motion (``U(θ)``, ``U(2θ + c)``);
        other arguments, and models with several drives, contribute none. Smooth position
        functions (linkages, quintic tabulated splines) have none.
        """
        if len(self.terms.drives) != 1:
            return np.zeros(0)
        angle = self.terms.angle[0]
        values = {sympy.Symbol(k): v for k, v in self.parameters.items()}
        found = []
        matrices = (self.terms.M, self.terms.B, self.terms.C, self.terms.F)
        for f in set().union(*(m.atoms(sympy.Function) for m in matrices)):
            get = getattr(self.position_functions.get(getattr(f, "position_name", None)),
                          "breakpoints", None)
            if get is None:
                continue
            arg = sympy.expand(f.args[0].subs(values))
            scale, offset = arg.diff(angle), arg.subs(angle, 0)
            if scale.is_number and offset.is_number:
                found.append(preimages(get(), float(scale), float(offset)))
        return np.unique(np.concatenate(found)) if found else np.zeros(0)

    def M(self, phi) -> np.ndarray:
        """Mass matrix M(φ) = (m̄_jk), shape S + (n, n), symmetric."""
        return self._evaluate(0, phi, 0.0, 0.0, (self.n, self.n))

    def B(self, phi, Omega) -> np.ndarray:
        """Damping matrix B = (b_jk + Σ_l m̄_klj Ω_l), shape S + (n, n), unsymmetric in general."""
        return self._evaluate(1, phi, Omega, 0.0, (self.n, self.n))

    def C(self, phi, Omega, Omega_dot=0.0) -> np.ndarray:
        """Stiffness matrix C(φ, Ω, Ω̇) of eq. 10 (errata 10), shape S + (n, n), as it is.

        C = c_jk − Q*_j,k + Σ_p [m_jp,k Ω̇_p + ½ Σ_l m_plj,k Ω_p Ω_l]; with Ω = Ω̇ = 0
        and position-independent loads it is the symmetric potential part W_pot,jk.
        """
        return self._evaluate(2, phi, Omega, Omega_dot, (self.n, self.n))

    def F(self, phi, Omega, Omega_dot=0.0) -> np.ndarray:
        """Force vector F(φ, Ω, Ω̇) of eq. 10 with −W_pot,j (errata 11), shape S + (n,)."""
        return self._evaluate(3, phi, Omega, Omega_dot, (self.n,))


def rheolinear(mechanism: Mechanism, parameters: Mapping | None = None,
               position_functions: Mapping | None = None) -> RheolinearModel:
    """Build the rheolinear model of ``mechanism`` (seed 5.2.2 eqs. 8–10, errata 9–11).

    Parameters
    ----------
    mechanism : Mechanism
        Symbolic description with at least one drive coordinate.
    parameters : mapping, optional
        Values (SI) of the free symbols, by symbol or name.
    position_functions : mapping, optional
        Numeric position functions by the names used in ``position_function(name)``.

    Returns
    -------
    RheolinearModel
    """
    terms = rheolinear_terms(mechanism)
    inputs = terms.angle + terms.speed + terms.acceleration
    compiled = tuple(compile_expressions(_flat(m), inputs)
                     for m in (terms.M, terms.B, terms.C, terms.F))
    values, funcs = check_bindings(compiled, parameters or {}, position_functions or {},
                                   _known_parameters(mechanism))
    return RheolinearModel(mechanism, terms, values, funcs, compiled)


@dataclass(frozen=True)
class Accelerations:
    """Result of the 2nd-kind equations at one or more states.

    Attributes
    ----------
    qdd : ndarray (..., N)
        Accelerations of all coordinates (drive entries equal the prescribed values).
    drive_forces : ndarray (..., F)
        Generalized forces the drives must supply to enforce the prescribed motion
        (e.g. the cylinder force Q4 of the crane, seed 5.2.3.1 eq. 17); empty without drives.
    """

    qdd: np.ndarray
    drive_forces: np.ndarray


@dataclass(frozen=True, eq=False)
class LagrangeModel:
    """Nonlinear equations of the 2nd kind (seed 5.2.1 eq. 13), evaluated numerically.

        M(q) q̈ + h(q, q̇) + W_pot,j(q) = Q*(q, q̇),   h_j = ½ Σ_kl m_klj q̇_k q̇_l.

    States ``q`` and ``qd`` have shape (..., N) in the order of ``mechanism.coordinates``.
    Build with :func:`second_kind`.
    """

    mechanism: Mechanism
    terms: LagrangeTerms
    parameters: Mapping[str, float]
    position_functions: Mapping[str, PositionFunction]
    _compiled: dict

    @property
    def N(self) -> int:
        """Number of coordinates."""
        return len(self.terms.coordinates)

    def _eval(self, key: str, q, qd=None) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        if q.shape[-1:] != (self.N,):
            raise ValueError(f"q must have shape (..., {self.N}), got {q.shape}")
        qd = np.zeros_like(q) if qd is None else np.broadcast_to(np.asarray(qd, float), q.shape)
        compiled, shape = self._compiled[key]
        inputs = list(np.moveaxis(q, -1, 0)) + list(np.moveaxis(qd, -1, 0))
        out = compiled(inputs, _param_values(compiled, self.parameters), self.position_functions)
        return out.reshape(q.shape[:-1] + shape)

    def M(self, q) -> np.ndarray:
        """Generalized masses m_jk(q) (eq. 6), shape (..., N, N)."""
        return self._eval("mass", q)

    def christoffel(self, q) -> np.ndarray:
        """m_klj(q) indexed ``[..., k, l, j]`` (eq. 13, errata 1), shape (..., N, N, N)."""
        return self._eval("christoffel", q)

    def stiffness(self, q) -> np.ndarray:
        """c_jk(q) = W_pot,jk (eq. 9), shape (..., N, N)."""
        return self._eval("stiffness", q)

    def gradient(self, q) -> np.ndarray:
        """W_pot,j(q), shape (..., N)."""
        return self._eval("gradient", q)

    def Q(self, q, qd) -> np.ndarray:
        """Generalized non-potential forces Q*_j(q, q̇) (eq. 11), shape (..., N)."""
        return self._eval("forces", q, qd)

    def velocity_terms(self, q, qd) -> np.ndarray:
        """h_j = ½ Σ_kl m_klj q̇_k q̇_l, shape (..., N)."""
        return self._eval("velocity", q, qd)

    def accelerations(self, q, qd, drive_accelerations=None) -> Accelerations:
        """Solve eq. 13 for q̈; drives (if any) follow ``drive_accelerations`` (..., F)."""
        q = np.asarray(q, dtype=float)
        M = self.M(q)
        rhs = self.Q(q, qd) - self.gradient(q) - self.velocity_terms(q, qd)
        coords = self.mechanism.coordinates
        d = [coords.index(x) for x in self.mechanism.drives]
        f = [i for i in range(self.N) if i not in d]
        qdd = np.zeros(q.shape)
        if d:
            if drive_accelerations is None:
                raise ValueError("prescribe the accelerations of the drives "
                                 f"{self.mechanism.drives}")
            qdd[..., d] = np.broadcast_to(drive_accelerations, q.shape[:-1] + (len(d),))
        b = rhs[..., f] - np.einsum("...ij,...j->...i", M[..., f, :][..., d], qdd[..., d])
        qdd[..., f] = np.linalg.solve(M[..., f, :][..., f], b[..., None])[..., 0]
        drive = np.einsum("...ij,...j->...i", M[..., d, :], qdd) - rhs[..., d]
        return Accelerations(qdd, drive)


def _lagrange_compiled(terms: LagrangeTerms, constraints: tuple = ()) -> dict:
    inputs = terms.coordinates + terms.velocities
    N = len(terms.coordinates)
    chris = tuple(terms.christoffel[k, l, j] for k in range(N) for l in range(N)
                  for j in range(N))
    table = {"mass": (_flat(terms.mass), (N, N)), "christoffel": (chris, (N, N, N)),
             "stiffness": (_flat(terms.stiffness), (N, N)),
             "gradient": (_flat(terms.gradient), (N,)), "forces": (_flat(terms.forces), (N,)),
             "velocity": (_flat(terms.velocity_terms()), (N,)),
             "jacobian": (_flat(terms.constraint_jacobian),
                          (terms.constraint_jacobian.shape[0], N)),
             "curvature": (_flat(terms.constraint_curvature),
                           (terms.constraint_curvature.shape[0],)),
             "constraints": (tuple(constraints), (len(constraints),))}
    return {k: (compile_expressions(e, inputs), s) for k, (e, s) in table.items()}


def second_kind(mechanism: Mechanism, parameters: Mapping | None = None,
                position_functions: Mapping | None = None) -> LagrangeModel:
    """Build the nonlinear 2nd-kind model of ``mechanism`` (seed 5.2.1 eqs. 5–13).

    Parameters and position functions as for :func:`rheolinear`.
    """
    terms = lagrange_terms(mechanism)
    compiled = _lagrange_compiled(terms, mechanism.constraints)
    values, funcs = check_bindings([c for c, _ in compiled.values()], parameters or {},
                                   position_functions or {}, _known_parameters(mechanism))
    return LagrangeModel(mechanism, terms, values, funcs, compiled)


@dataclass(frozen=True)
class MixedSolution:
    """Solution of the augmented system A x = b of the mixed-type equations.

    Attributes
    ----------
    qdd : ndarray (N + n_c,)
        Accelerations of all coordinates, including the redundant ones.
    multipliers : ndarray (n_c,)
        Lagrange multipliers λ_i, the constraint (joint) forces (seed 5.2.3.2 eq. 8).
    A : ndarray (N + n_c, N + n_c)
        The symmetric, indefinite matrix [[M, Hᵀ], [H, 0]] (eq. "25").
    b : ndarray (N + n_c,)
        Right-hand side [Q* − W_pot,j − h; −Σ h_ik,l q̇_k q̇_l].
    """

    qdd: np.ndarray
    multipliers: np.ndarray
    A: np.ndarray
    b: np.ndarray


@dataclass(frozen=True, eq=False)
class MixedModel:
    """Lagrange equations of mixed type with multipliers (seed 5.2.1 eqs. 14–21).

        Σ_k m_jk q̈_k + Σ_i h_ij λ_i = Q*_j − W_pot,j − ½ Σ_kl m_klj q̇_k q̇_l,
        Σ_k h_ik q̈_k = −Σ_k Σ_l h_ik,l q̇_k q̇_l          (scleronomic f_i(q) = 0).

    The second row is eq. 21 without ḣ_i, exact for constraints without explicit time
    dependence (errata item 4). Build with :func:`mixed_type`.
    """

    lagrange: LagrangeModel

    def constraints(self, q) -> np.ndarray:
        """Constraint values f_i(q) (eq. 15), shape (..., n_c), for q of shape (..., N)."""
        return self.lagrange._eval("constraints", q)

    def jacobian(self, q) -> np.ndarray:
        """Constraint Jacobian h_ij = ∂f_i/∂q_j (eq. 17), shape (..., n_c, N)."""
        return self.lagrange._eval("jacobian", q)

    def solve(self, q, qd) -> MixedSolution:
        """Assemble and solve A x = b at one state ``q``, ``qd`` of shape (N + n_c,)."""
        lg = self.lagrange
        q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
        if q.ndim != 1:
            raise ValueError(f"solve takes one state of shape ({lg.N},), got {q.shape}")
        M = lg.M(q)
        H = lg._eval("jacobian", q)
        n_c = H.shape[0]
        A = np.block([[M, H.T], [H, np.zeros((n_c, n_c))]])
        b = np.concatenate([lg.Q(q, qd) - lg.gradient(q) - lg.velocity_terms(q, qd),
                            -lg._eval("curvature", q, qd)])
        x = np.linalg.solve(A, b)
        return MixedSolution(x[:lg.N], x[lg.N:], A, b)


def mixed_type(mechanism: Mechanism, parameters: Mapping | None = None,
               position_functions: Mapping | None = None) -> MixedModel:
    """Build the mixed-type model of a mechanism with redundant coordinates.

    ``mechanism.constraints`` holds f_i(q) = 0; ``mechanism.drives`` must be empty.
    Parameters and position functions as for :func:`rheolinear`.
    """
    if not mechanism.constraints:
        raise ValueError(f"mechanism {mechanism.name!r} has no constraints for the mixed form")
    if mechanism.drives:
        raise ValueError("the mixed-type form here does not take prescribed drives")
    return MixedModel(second_kind(mechanism, parameters, position_functions))
