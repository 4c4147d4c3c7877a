"""Static equilibrium of a mechanism under gravity and preload: its operating point.

Two models, two meanings of "static":

* :class:`~femmech.mechanisms.LagrangeModel` (:func:`~femmech.mechanisms.second_kind`,
  seed 5.2.1 eq. 13): with the drive coordinates held at given values and all
  velocities zero, the free coordinates f rest where the potential is stationary under
  the applied loads,

      r(q) = W_pot,f(q) − Q*_f(q, 0) = 0.

  It is solved by Newton's method with the model's stiffness c_ff = W_pot,ff (eq. 9)
  minus the load derivative ∂Q*_f/∂q_f (central differences; zero for loads that do not
  depend on the position). This is the reference position of the crane (seed 5.2.3.1:
  "the initial static rest position is the reference") and of any mechanism whose
  gravity or spring preload moves it before it runs.

* :class:`~femmech.mechanisms.RheolinearModel` (:func:`~femmech.mechanisms.rheolinear`,
  seed 5.2.2 eq. 9): its coordinates are already deviations from the programmed rigid
  motion, and gravity and preload enter F as −W_pot,j on that motion (errata 11). The
  operating point is the linear quasi-static deflection C(φ, Ω, Ω̇) q = F(φ, Ω, Ω̇) at
  each frozen angle: with Ω = Ω̇ = 0 the static sag under gravity, preload and process
  loads; with the drive speed, the quasi-static deflection including the rigid-body
  inertia forces. One linear solve (exact for the linear model), vectorised over angles.

Uses mechanisms.models and errors.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femmech.errors import NumericalError
from femmech.mechanisms.models import LagrangeModel, RheolinearModel

__all__ = ["StaticEquilibrium", "static_equilibrium"]


@dataclass(frozen=True)
class StaticEquilibrium:
    """Convergence record of :func:`static_equilibrium`.

    Attributes
    ----------
    iterations : int
        Newton iterations taken (1 for the linear solve of a rheolinear model).
    residual : float
        Final out-of-balance force max |r|, N or N·m (the largest over angles for a
        rheolinear model).
    converged : bool
        ``residual <= tol * reference``.
    reference : float
        Force scale of the test: max |r| at the start (Lagrange model) or max |F|
        (rheolinear model), N or N·m.
    stiffness : ndarray
        Tangent stiffness of the free coordinates at the solution, (n_f, n_f) (Lagrange)
        or C (S + (n, n)) (rheolinear); its inverse gives the static flexibility.
    """

    iterations: int
    residual: float
    converged: bool
    reference: float
    stiffness: np.ndarray


def static_equilibrium(model, phi, q0=None, tol: float = 1e-10, max_iter: int = 50,
                       Omega: float = 0.0, Omega_dot: float = 0.0):
    """Static equilibrium (operating point) of a mechanism model at drive position φ.

    Parameters
    ----------
    model : LagrangeModel or RheolinearModel
        See the module docstring for what each gives.
    phi : float or array_like
        Lagrange model: the values of the drive coordinates, shape (F,) or a scalar for
        one drive (rad or m); none for a model without drives (pass ``None``).
        Rheolinear model: drive angles of any shape S (S + (F,) for F drives), rad.
    q0 : array_like (N,), optional
        Lagrange model: start of the Newton iteration (its drive entries are replaced by
        ``phi``); zeros by default. Ignored for a rheolinear model.
    tol : float
        Convergence: max |r| <= tol times the initial max |r| (Lagrange).
    max_iter : int
        Most Newton iterations.
    Omega, Omega_dot : float
        Rheolinear model only: drive speed (rad/s) and acceleration (rad/s²) of the
        quasi-static deflection; 0 for the static one.

    Returns
    -------
    q : ndarray
        Lagrange: all N coordinates (N,), drives included (m, rad). Rheolinear: the
        deflections, shape S + (n,).
    info : StaticEquilibrium

    Raises
    ------
    NumericalError
        When Newton does not converge in ``max_iter`` iterations (the message names the
        iterations and the residual) or the stiffness is singular.
    """
    if isinstance(model, RheolinearModel):
        return _rheolinear_equilibrium(model, phi, Omega, Omega_dot, tol)
    if isinstance(model, LagrangeModel):
        return _lagrange_equilibrium(model, phi, q0, tol, max_iter)
    raise TypeError("static_equilibrium needs a LagrangeModel (second_kind) or a"
                    f" RheolinearModel (rheolinear), got {type(model).__name__}")


def _rheolinear_equilibrium(model, phi, Omega, Omega_dot, tol):
    """C(φ, Ω, Ω̇) q = F(φ, Ω, Ω̇) at every angle (one solve each)."""
    C = model.C(phi, Omega, Omega_dot)
    F = model.F(phi, Omega, Omega_dot)
    try:
        q = np.linalg.solve(C, F[..., None])[..., 0]
    except np.linalg.LinAlgError as exc:
        raise NumericalError(f"mechanism {model.mechanism.name!r}: C(phi) is singular at"
                             " some angle (a coordinate without stiffness: no static"
                             " equilibrium)") from exc
    residual = float(np.abs(np.einsum("...ij,...j->...i", C, q) - F).max(initial=0.0))
    reference = float(np.abs(F).max(initial=0.0))
    return q, StaticEquilibrium(1, residual, residual <= max(tol * reference, 1e-300)
                                or residual == 0.0, reference, C)


def _split(model: LagrangeModel, phi, q0):
    """Start vector (N,) with the drives set, and the indices of drives and free ones."""
    coords = model.mechanism.coordinates
    drives = [coords.index(x) for x in model.mechanism.drives]
    free = [i for i in range(model.N) if i not in drives]
    q = np.zeros(model.N) if q0 is None else np.array(q0, dtype=float)
    if q.shape != (model.N,):
        raise ValueError(f"q0 must have shape ({model.N},) (coordinates"
                         f" {[c.name for c in coords]}), got {q.shape}")
    if drives:
        if phi is None:
            raise ValueError(f"give the drive positions phi for {model.mechanism.drives}")
        values = np.atleast_1d(np.asarray(phi, dtype=float))
        if values.shape != (len(drives),):
            raise ValueError(f"phi must hold {len(drives)} drive position(s)"
                             f" {[coords[i].name for i in drives]}, got shape {values.shape}")
        q[drives] = values
    if not free:
        raise ValueError("the mechanism has no free coordinate: nothing to solve")
    return q, np.array(free)


def _residual(model: LagrangeModel, q, free):
    """Out-of-balance forces r_f = W_pot,f − Q*_f(q, 0) (N or N·m), shape (n_f,)."""
    return (model.gradient(q) - model.Q(q, np.zeros_like(q)))[free]


def _tangent(model: LagrangeModel, q, free):
    """∂r_f/∂q_f: the model's stiffness c_ff minus central differences of Q*_f."""
    K = model.stiffness(q)[np.ix_(free, free)]
    zero = np.zeros_like(q)
    h = 1e-6 * np.maximum(np.abs(q[free]), 1.0)
    steps = np.zeros((free.size, q.size))
    steps[np.arange(free.size), free] = h
    dQ = (model.Q(q + steps, zero) - model.Q(q - steps, zero))[:, free] / (2 * h[:, None])
    return K - dQ.T


def _lagrange_equilibrium(model: LagrangeModel, phi, q0, tol, max_iter):
    """Newton on r_f(q) = 0 with the drives fixed (see the module docstring)."""
    q, free = _split(model, phi, q0)
    r = _residual(model, q, free)
    reference = float(np.abs(r).max())
    for iteration in range(max_iter + 1):
        residual = float(np.abs(r).max())
        if not np.isfinite(residual):
            break
        if residual <= tol * reference:
            return q, StaticEquilibrium(iteration, residual, True, reference,
                                        _tangent(model, q, free))
        if iteration == max_iter:
            break
        K = _tangent(model, q, free)
        try:
            q[free] -= np.linalg.solve(K, r)
        except np.linalg.LinAlgError as exc:
            raise NumericalError(f"mechanism {model.mechanism.name!r}: the stiffness of"
                                 f" the free coordinates is singular at iteration"
                                 f" {iteration} (a coordinate without stiffness, or no"
                                 " equilibrium)") from exc
        r = _residual(model, q, free)
    raise NumericalError(f"mechanism {model.mechanism.name!r}: static equilibrium did not"
                         f" converge in {max_iter} Newton iterations: residual"
                         f" {residual:.3e} against tolerance {tol * reference:.3e}"
                         f" (tol {tol:g} x initial residual {reference:.3e}); try another"
                         " start q0, more iterations, or check that an equilibrium exists")
