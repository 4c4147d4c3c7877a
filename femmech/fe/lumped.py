"""Lumped items: point masses and 6x6 springs (node-to-node or node-to-ground).

A node is referred to by its index or by the name of a group that holds exactly one
node. All matrices act in global axes unless a spring is given its own ``axes``.

Uses only fe.materials.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femmech.fe.materials import check_real


@dataclass(frozen=True)
class PointMass:
    """Rigid point mass at a node.

    Attributes
    ----------
    node : int or str
    mass : float
        kg.
    inertia : array_like (3, 3) or (3,), optional
        Rotary inertia about the node in global axes, kg m² (a 3-vector is a diagonal).
    """

    node: int | str
    mass: float
    inertia: object = None

    def matrix(self) -> np.ndarray:
        """6x6 mass matrix, kg and kg m²."""
        check_real(self.mass, f"point mass at {self.node!r}: mass")
        if not (np.isfinite(self.mass) and self.mass >= 0):
            raise ValueError(f"point mass at {self.node!r}: mass must be >= 0, got {self.mass}")
        out = np.zeros((6, 6))
        out[:3, :3] = self.mass * np.eye(3)
        if self.inertia is not None:
            out[3:, 3:] = _sym_psd(self.inertia, 3, f"point mass at {self.node!r}: inertia")
        return out


@dataclass(frozen=True)
class Spring:
    """Linear spring between two nodes, or between a node and the ground.

    Attributes
    ----------
    node_a : int or str
    node_b : int or str or None
        ``None`` grounds the spring.
    stiffness : float, array_like (6,) or (6, 6)
        N/m for translations, N m/rad for rotations; a scalar applies to the three
        translations only, a 6-vector is a diagonal.
    axes : array_like (3, 3), optional
        Rows are the spring's local axes in global coordinates (default: global axes).
    """

    node_a: int | str
    node_b: int | str | None
    stiffness: object
    axes: object = None

    def matrix(self) -> np.ndarray:
        """Global 6x6 stiffness ``k`` (the element matrix is [[k, -k], [-k, k]])."""
        label = f"spring {self.node_a!r}-{self.node_b!r}"
        k = _real_matrix(self.stiffness, f"{label}: stiffness")
        if k.ndim == 0:
            k = np.diag([float(k)] * 3 + [0.0] * 3)
        elif k.shape == (6,):
            k = np.diag(k)
        k = _sym_psd(k, 6, f"{label}: stiffness")
        if self.axes is not None:
            R = np.asarray(self.axes, dtype=float)
            if R.shape != (3, 3) or not np.allclose(R @ R.T, np.eye(3), atol=1e-9):
                raise ValueError(f"{label}: axes must be a 3x3 rotation matrix")
            T = np.kron(np.eye(2), R)
            k = T.T @ k @ T
        return k


def _real_matrix(value, label: str) -> np.ndarray:
    """Float array of real numbers; TypeError naming ``label`` otherwise."""
    try:
        a = np.asarray(value)
    except ValueError:  # ragged nested sequences
        raise ValueError(f"{label} must be a rectangular array of numbers") from None
    if a.dtype.kind not in "iuf":
        raise TypeError(f"{label} must be real numbers, got {value!r}")
    return a.astype(float)


def _sym_psd(value, n: int, label: str) -> np.ndarray:
    a = _real_matrix(value, label)
    if a.shape == (n,):
        a = np.diag(a)
    if a.shape != (n, n):
        raise ValueError(f"{label} must have shape ({n}, {n}) or ({n},), got {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"{label} has non-finite entries")
    scale = max(np.abs(a).max(), 1e-300)
    if not np.allclose(a, a.T, rtol=0, atol=1e-12 * scale):
        raise ValueError(f"{label} is not symmetric")
    if np.linalg.eigvalsh(a).min() < -1e-12 * scale:
        raise ValueError(f"{label} is not positive semi-definite")
    return 0.5 * (a + a.T)
