"""User-tabulated position functions through a periodic quintic spline.

A measured or externally computed transmission function is given as a table
(φ_i, U_i) over one revolution. A periodic cubic spline would make U''' piecewise
constant and discontinuous; the quintic (degree 5) periodic spline used here is C⁴, so
U''' (needed by the stiffness matrix C, seed chapter 5.2.2) is continuous and
converges as O(h³) for smooth data (de Boor [1]_, ch. XII).

References
----------
.. [1] C. de Boor, *A Practical Guide to Splines*, rev. ed., Springer, 2001.

Uses only mechanisms.position.
"""

from dataclasses import dataclass, field

import numpy as np

from femmech.mechanisms.position import as_angles, check_order

__all__ = ["TabulatedPositionFunction"]

TWO_PI = 2.0 * np.pi


@dataclass(frozen=True, eq=False)
class TabulatedPositionFunction:
    """Periodic position function interpolated from a table (quintic periodic spline).

    Parameters
    ----------
    phi : array_like (n_points,)
        Strictly increasing drive angles, rad, with ``phi[-1] - phi[0] == 2π``.
    U : array_like (n_points,)
        Output values (m or rad). Periodicity requires ``U[-1] - U[0] == increment``.
    increment : float
        Change of U over one revolution (0 for a cam or rocker; e.g. 2π for an output
        that turns once per revolution). The spline interpolates U − increment·φ/(2π).
    rtol : float
        Relative tolerance (with respect to the range of U) of the periodicity check.

    Raises
    ------
    ValueError
        For fewer than 7 points, angles that are not strictly increasing or do not span
        2π, or a table that is not periodic.

    Examples
    --------
    >>> import numpy as np
    >>> phi = np.linspace(0, 2 * np.pi, 65)
    >>> f = TabulatedPositionFunction(phi, np.sin(phi))
    >>> bool(abs(f(1.0, order=3) + np.cos(1.0)) < 1e-3)
    True
    """

    phi: np.ndarray
    U: np.ndarray
    increment: float = 0.0
    rtol: float = 1e-9
    _spline: object = field(init=False, repr=False)

    def __post_init__(self):
        phi = np.array(self.phi, dtype=float)
        U = np.array(self.U, dtype=float)
        if phi.ndim != 1 or phi.shape != U.shape:
            raise ValueError(f"phi and U must be 1-D of equal length, got shapes {phi.shape} "
                             f"and {U.shape}")
        if phi.size < 7:
            raise ValueError(f"a quintic periodic spline needs at least 7 points, got {phi.size}")
        if not (np.all(np.isfinite(phi)) and np.all(np.isfinite(U))):
            raise ValueError("phi and U must be finite")
        if np.any(np.diff(phi) <= 0):
            i = int(np.argmax(np.diff(phi) <= 0))
            raise ValueError(f"phi must be strictly increasing; phi[{i + 1}] = {phi[i + 1]} "
                             f"<= phi[{i}] = {phi[i]}")
        span = phi[-1] - phi[0]
        if abs(span - TWO_PI) > 1e-9 * TWO_PI:
            raise ValueError(f"the table must span one revolution: phi[-1] - phi[0] = {span!r}, "
                             "not 2*pi")
        periodic = U - self.increment * (phi - phi[0]) / TWO_PI
        scale = max(np.ptp(periodic), abs(self.increment), np.finfo(float).tiny)
        gap = periodic[-1] - periodic[0]
        if abs(gap) > self.rtol * scale:
            raise ValueError(f"the table is not periodic: U[-1] - U[0] - increment = {gap:.3g}, "
                             f"more than rtol * range = {self.rtol * scale:.3g}")
        periodic[-1] = periodic[0]
        from scipy.interpolate import make_interp_spline  # a slow import: only when used

        spline = make_interp_spline(phi, periodic, k=5, bc_type="periodic")
        object.__setattr__(self, "phi", phi)
        object.__setattr__(self, "U", U)
        object.__setattr__(self, "_spline", spline)

    def derivatives(self, phi) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Return ``(U, U', U'', U''')`` at drive angles ``phi`` (rad, any shape)."""
        phi = as_angles(phi)
        t = self.phi[0] + np.mod(phi - self.phi[0], TWO_PI)
        ramp = self.increment / TWO_PI
        values = [self._spline(t, nu=k) for k in range(4)]
        values[0] = values[0] + ramp * (phi - self.phi[0])
        values[1] = values[1] + ramp
        return tuple(values)

    def __call__(self, phi, order: int = 0) -> np.ndarray:
        """Return U^(order)(φ) at ``phi`` (rad)."""
        return self.derivatives(phi)[check_order(order)]
