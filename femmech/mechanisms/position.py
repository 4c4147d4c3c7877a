"""The position-function protocol shared by cams, linkages and tabulated functions.

A position function (German *Lagefunktion*, the chapter's transmission function) maps the
drive angle φ of a rigid mechanism to the position U(φ) of its output member. The
mechanism equations need U and its first three derivatives with respect to φ: U' and U''
enter the mass and damping terms, U''' enters the stiffness matrix C (seed chapter
5.2.2, text after Table 5.1).

Imports nothing of femmech.
"""

from typing import Protocol, runtime_checkable

import numpy as np

__all__ = ["PositionFunction", "as_angles"]


@runtime_checkable
class PositionFunction(Protocol):
    """A position function U(φ) with exact derivatives up to the third order.

    Implementations are immutable and vectorised: they accept an array of drive angles
    φ (rad, any shape) and return arrays of the same shape.
    """

    def derivatives(self, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Return ``(U, U', U'', U''')`` at the drive angles ``phi`` (rad).

        The units are those of the output (m or rad) per rad to the power of the order.
        """
        ...

    def __call__(self, phi: np.ndarray, order: int = 0) -> np.ndarray:
        """Return the derivative of order ``order`` (0 to 3) of U at ``phi`` (rad)."""
        ...


def as_angles(phi) -> np.ndarray:
    """Convert drive angles to a float64 array and reject non-finite values.

    Parameters
    ----------
    phi : array_like
        Drive angles, rad, any shape.

    Returns
    -------
    ndarray
        ``phi`` as float64, same shape.

    Raises
    ------
    ValueError
        If any angle is NaN or infinite.
    """
    phi = np.asarray(phi, dtype=float)
    if not np.all(np.isfinite(phi)):
        raise ValueError("drive angle phi contains NaN or infinite values")
    return phi


def check_order(order: int) -> int:
    """Check a derivative order for ``PositionFunction.__call__``; return it as int."""
    if order not in (0, 1, 2, 3):
        raise ValueError(f"derivative order must be 0, 1, 2 or 3, got {order!r}")
    return int(order)


def preimages(points, scale: float, offset: float, span: float = 2.0 * np.pi) -> np.ndarray:
    """Angles x ∈ [0, span) with ``scale * x + offset ≡ p (mod 2π)`` for each p in points.

    Maps the breakpoints of a 2π-periodic function of an angle ψ = scale · x + offset (a
    position function of ``2 θ + c``, a mechanism geared to the main drive) to the
    angle x. Returns them sorted and unique (rad).
    """
    points = np.asarray(points, dtype=float).ravel()
    if points.size == 0 or scale == 0 or not np.isfinite(scale * offset * span):
        return np.zeros(0)
    lo, hi = sorted((offset, offset + scale * span))  # range of ψ over x ∈ [0, span)
    k = np.arange(np.floor((lo - points.max()) / (2 * np.pi)),
                  np.ceil((hi - points.min()) / (2 * np.pi)) + 1)
    x = ((points[:, None] + 2 * np.pi * k[None, :]).ravel() - offset) / scale
    return np.unique(x[(x >= 0) & (x < span)])
