"""Quasi-eigenfrequencies and quasi-eigenmodes of a mechanism at frozen drive angles.

At each frozen drive angle φ the generalized eigenproblem

    C(φ, Ω, Ω̇) v = ω² M(φ) v

of the rheolinear model (seed 5.2.2 eq. 9; symbols M mass, C stiffness) is solved, and
the frequencies f = ω/(2π) are followed over a revolution (seed 5.1: "quasi-
eigenfrequencies"). With Ω = Ω̇ = 0 and position-independent loads, C is the symmetric
potential part and the symmetric pencil is solved (LAPACK ``sygvd`` of all pairs,
``driver="plain"`` of :func:`femmech.solve.dense.symmetric_pencil`); otherwise C is
generally unsymmetric (errata item 30) and QZ is used
(:func:`femmech.solve.dense.unsymmetric_pencil`). Damping B is ignored (undamped
quasi-modes). The tracked sweep of a mechanism alone, with damping, is
:func:`femmech.analysis.sweep.sweep`; it solves the same pencils by the shift-inverted
driver of the same module (the lowest modes to ~eps relative however wide the spectrum)
and agrees with :func:`quasi_modes` to round-off.

The diagram of the quasi-eigenfrequencies over the drive angle is
:func:`femmech.output.sweeps.plot_quasi_frequencies`.

Stage 2 (mechanisms, independent of fe): imports only :mod:`femmech.solve` (stage 1).
"""

from dataclasses import dataclass

import numpy as np

from femmech.solve import dense, tolerances

__all__ = ["QuasiModes", "frozen_eigen", "quasi_modes"]


@dataclass(frozen=True)
class QuasiModes:
    """Quasi-eigenfrequencies over drive angles.

    Attributes
    ----------
    phi : ndarray (n_angles,)
        Drive angles, rad.
    omega_sq : ndarray (n_angles, n), complex
        Eigenvalues ω² = λ, 1/s², ascending by real part at each angle.
    freq_hz : ndarray (n_angles, n)
        √λ/(2π), Hz, ascending; NaN where λ is not real and positive (possible only for
        unsymmetric C: divergence or flutter at the frozen angle).
    modes : ndarray (n_angles, n, n)
        Column i is the mode of ``freq_hz[:, i]``, normalised to vᵀ M v = 1 with its
        largest-magnitude entry positive; NaN for complex eigenvalues.
    symmetric : ndarray (n_angles,), bool
        True where C was symmetric and ``eigh`` was used.
    """

    phi: np.ndarray
    omega_sq: np.ndarray
    freq_hz: np.ndarray
    modes: np.ndarray
    symmetric: np.ndarray


def _normalise(v: np.ndarray, M: np.ndarray) -> np.ndarray:
    """Scale columns to vᵀ M v = 1 and make each column's largest entry positive."""
    norm = np.sqrt(np.abs(np.einsum("ij,ik,kj->j", v, M, v)))
    v = v / norm
    idx = np.argmax(np.abs(v), axis=0)
    return v * np.sign(v[idx, np.arange(v.shape[1])])


def _eigen_one(M: np.ndarray, C: np.ndarray, rtol_symmetry: float, rtol_real: float):
    scale = np.max(np.abs(C))
    if np.max(np.abs(C - C.T)) <= rtol_symmetry * scale:
        lam, v = dense.symmetric_pencil(0.5 * (C + C.T), M, driver="plain")
        return lam.astype(complex), _normalise(v, M), True
    lam, v = dense.unsymmetric_pencil(C, M)
    order = np.lexsort((lam.imag, lam.real))
    lam, v = lam[order], v[:, order]
    real = np.abs(lam.imag) <= rtol_real * np.abs(lam)
    modes = np.full(v.shape, np.nan)
    if np.any(real):
        modes[:, real] = _normalise(v[:, real].real, M)
    return lam, modes, False


def frozen_eigen(M: np.ndarray, C: np.ndarray,
                 rtol_symmetry: float = tolerances.SYMMETRY_RTOL,
                 rtol_real: float = tolerances.REAL_RTOL
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Solve C v = λ M v for a stack of frozen-angle matrices (all pairs, dense).

    A thin call of :mod:`femmech.solve.dense` per angle; the bare 3-tuple is kept for
    callers that unpack it.

    Parameters
    ----------
    M : ndarray (n_angles, n, n)
        Symmetric positive definite mass matrices.
    C : ndarray (n_angles, n, n)
        Stiffness matrices, symmetric or not.
    rtol_symmetry : float
        C counts as symmetric if max|C − Cᵀ| <= rtol_symmetry · max|C|; default
        :data:`femmech.solve.tolerances.SYMMETRY_RTOL`.
    rtol_real : float
        λ counts as real if |Im λ| <= rtol_real · |λ|; default
        :data:`femmech.solve.tolerances.REAL_RTOL`.

    Returns
    -------
    omega_sq : ndarray (n_angles, n), complex
        Eigenvalues λ = ω², ascending by real part.
    modes : ndarray (n_angles, n, n)
        M-normalised real eigenvectors (columns); NaN for complex λ.
    symmetric : ndarray (n_angles,), bool
    """
    out = [_eigen_one(m, c, rtol_symmetry, rtol_real) for m, c in zip(M, C, strict=True)]
    return (np.array([o[0] for o in out]), np.array([o[1] for o in out]),
            np.array([o[2] for o in out]))


def quasi_modes(model, phi, Omega=0.0, Omega_dot=0.0) -> QuasiModes:
    """Quasi-eigenfrequencies of a rheolinear mechanism model at frozen angles.

    Parameters
    ----------
    model : RheolinearModel
        Provides ``M(phi)`` and ``C(phi, Omega, Omega_dot)`` with one drive.
    phi : array_like (n_angles,)
        Drive angles, rad.
    Omega, Omega_dot : float
        Drive speed (rad/s) and acceleration (rad/s²) entering the kinematic stiffness
        terms of C (errata item 30); 0 gives the potential (static) part.

    Returns
    -------
    QuasiModes
    """
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    if phi.ndim != 1:
        raise ValueError(f"phi must be 1-D (one drive), got shape {phi.shape}")
    lam, modes, sym = frozen_eigen(model.M(phi), model.C(phi, Omega, Omega_dot))
    ok = (np.abs(lam.imag) <= 1e-9 * np.abs(lam)) & (lam.real > 0)
    freq = np.where(ok, np.sqrt(np.abs(lam.real)) / (2 * np.pi), np.nan)
    return QuasiModes(phi, lam, freq, modes, sym)


def __getattr__(name: str):
    """Names this module had before the restructures, from their new places
    (docs/architecture.md, "Moved names")."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "plot_quasi_frequencies": "femmech.output.sweeps.plot_quasi_frequencies",
    })
