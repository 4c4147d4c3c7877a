"""Full (unreduced) coupled reference solves and reduced-versus-full comparisons.

The reference is the same machine with the frame as an unreduced
:class:`~femmech.fe.model.FEModel`: sparse shift-invert ARPACK on the coupled matrices at
chosen angles (``eigsh`` path of :func:`femmech.solve.eigen.solve_symmetric` with its Sturm
check for symmetric C; ``scipy.sparse.linalg.eigs`` with a shift for unsymmetric C).

Stage 5 (analysis): uses analysis.sweep, coupling, reduction and solve; nothing here writes
files.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from femmech.analysis.sweep import sweep
from femmech.analysis.tracking import mac_matrix
from femmech.coupling import CoupledSystem
from femmech.reduction.superelement import Superelement
from femmech.solve.eigen import solve_symmetric
from femmech.solve.pencil import default_shift
from femmech.solve.tolerances import SYMMETRY_RTOL


def full_modes(system: CoupledSystem, phi: float, n_modes: int, Omega: float = 0.0):
    """Lowest quasi-modes of a coupled system at one angle, sparse or dense.

    Returns ``(eigenvalues λ = ω² (n_modes,), complex for unsymmetric C; vectors
    (n, n_modes) mass-normalised)``.
    """
    M, _, C, _ = system.matrices(phi, Omega)
    scale = abs(C).max()
    asym = abs(C - C.T).max() if sp.issparse(C) else np.abs(C - C.T).max()
    if asym <= SYMMETRY_RTOL * scale:
        result = solve_symmetric(0.5 * (C + C.T), M, n_modes=n_modes)
        return result.omega2[:n_modes].astype(complex), result.vectors[:, :n_modes]
    sigma = default_shift(C, M)
    lam, V = spla.eigs(sp.csc_matrix(C), k=n_modes, M=sp.csc_matrix(M), sigma=sigma,
                       v0=np.random.default_rng(12345).standard_normal(system.n))
    order = np.argsort(lam.real)
    V = V[:, order]
    norms = np.sqrt(np.abs(np.einsum("ij,ij->j", V.conj(), M @ V)))
    return lam[order], V / norms


@dataclass(frozen=True)
class Comparison:
    """Reduced versus full coupled quasi-modes at chosen angles.

    Attributes
    ----------
    phi : ndarray (n_angles,), rad
    freq_full_hz, freq_reduced_hz : ndarray (n_angles, n_modes), Hz (sorted by frequency)
    mac : ndarray (n_angles, n_modes, n_modes)
        MAC of reduced (rows) against full (columns) modes, mass-weighted with the full M.
    seconds_full : ndarray (n_angles,)
        Time of each full solve, s.
    seconds_reduced : float
        Time per angle of the reduced solve (one sweep over the angles), s.
    """

    phi: np.ndarray
    freq_full_hz: np.ndarray
    freq_reduced_hz: np.ndarray
    mac: np.ndarray
    seconds_full: np.ndarray
    seconds_reduced: float

    @property
    def rel_error(self) -> np.ndarray:
        """``f_reduced / f_full - 1``, shape (n_angles, n_modes)."""
        return self.freq_reduced_hz / self.freq_full_hz - 1.0

    @property
    def diag_mac(self) -> np.ndarray:
        """MAC of each reduced mode with the full mode of the same order, (n_angles, n_modes)."""
        return np.diagonal(self.mac, axis1=1, axis2=2)

    def table(self) -> str:
        """Plain-text report: per angle and mode, both frequencies, error and MAC."""
        lines = [f"{'angle deg':>9} {'mode':>4} {'full Hz':>12} {'reduced Hz':>12}"
                 f" {'rel err':>9} {'MAC':>10}"]
        for a, angle in enumerate(self.phi):
            for k in range(self.freq_full_hz.shape[1]):
                lines.append(f"{np.rad2deg(angle):9.2f} {k + 1:4d}"
                             f" {self.freq_full_hz[a, k]:12.5f} {self.freq_reduced_hz[a, k]:12.5f}"
                             f" {self.rel_error[a, k]:9.1e} {self.diag_mac[a, k]:10.8f}")
        lines.append(f"max |rel err| {np.abs(self.rel_error).max():.2e}, min MAC"
                     f" {self.diag_mac.min():.8f}; time per angle: full"
                     f" {1e3 * self.seconds_full.mean():.1f} ms, reduced"
                     f" {1e3 * self.seconds_reduced:.2f} ms")
        return "\n".join(lines)


def compare_coupled(reduced: CoupledSystem, full: CoupledSystem, phi, n_modes: int,
                    Omega: float = 0.0) -> Comparison:
    """Compare a reduced coupled machine with its unreduced twin at the angles ``phi``.

    ``reduced`` must have a :class:`~femmech.reduction.superelement.Superelement` frame of the FE
    model that is the frame of ``full`` (same mounts); reduced modes are recovered to the
    full coordinates (frame free DOFs, then the mechanisms' own coordinates) for the MAC.
    """
    se = reduced.frame
    if not isinstance(se, Superelement):
        raise TypeError("compare_coupled needs a reduced system whose frame is a Superelement")
    if full.n - full.n_frame != reduced.n - reduced.n_frame:
        raise ValueError("the reduced and full systems have different mechanism coordinates")
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    start = time.perf_counter()
    result = sweep(reduced, phi, Omega=Omega, n_modes=n_modes, keep_vectors=True, track=False)
    seconds_reduced = (time.perf_counter() - start) / phi.size
    f_full = np.zeros((phi.size, n_modes))
    macs = np.zeros((phi.size, n_modes, n_modes))
    seconds = np.zeros(phi.size)
    for a, angle in enumerate(phi):
        start = time.perf_counter()
        lam, V = full_modes(full, angle, n_modes, Omega)
        seconds[a] = time.perf_counter() - start
        f_full[a] = np.sqrt(np.clip(lam.real, 0.0, None)) / (2 * np.pi)
        shapes = np.vstack([se.expand_free(result.vectors[a, :reduced.n_frame]),
                            result.vectors[a, reduced.n_frame:]])
        M = full.matrices(angle, Omega)[0]
        macs[a] = mac_matrix(shapes, V, M)
    return Comparison(phi, f_full, result.freq_hz, macs, seconds, seconds_reduced)
