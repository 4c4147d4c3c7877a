"""Result type shared by every chain eigen-solution (transfer, assembled, cyclic, continuum).

Stage 6 (chain): numpy only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ChainModes:
    """Quasi-eigenfrequencies (and modes) of a frozen chain at one drive angle.

    Attributes
    ----------
    freq_hz : ndarray (k,)
        Frequencies f = ω / 2π, Hz, ascending (repeated roots appear repeatedly); a
        root λ = ω² < 0 (divergence) is reported as f = −√|λ| / 2π (transfer,
        assembled).
    vectors : ndarray (n, k) or None
        Mode shapes in the assembled coordinates of the chain (the numbering of
        ``Chain.sparse_matrices``: rad for rotations, m for translations),
        M-normalised (``vᵀ M v = 1``, kg m² / kg units); None if not computed.
    method : str
        ``"transfer"``, ``"assembled"``, ``"cyclic"`` or ``"continuum"``.
    label : ndarray (k,) of int or None
        Wave / mode number where the method has one (cyclic, continuum), else None.
    count : ndarray (k,) of int or None
        Wittrick–Williams count of eigenvalues strictly below each root (transfer),
        else None.
    converged : ndarray (k,) of bool
        The root's bracket met its tolerance (and its checks, transfer).
    error : ndarray (k,) or None
        Estimated relative frequency error of each root where the method is an
        approximation (continuum: against the transfer-matrix roots of the same chain),
        else None.
    """

    freq_hz: np.ndarray
    vectors: np.ndarray | None
    method: str
    label: np.ndarray | None = None
    count: np.ndarray | None = None
    converged: np.ndarray | None = None
    error: np.ndarray | None = None

    def __post_init__(self):
        freq = np.asarray(self.freq_hz, dtype=float).reshape(-1)
        object.__setattr__(self, "freq_hz", freq)
        conv = (np.ones(freq.size, bool) if self.converged is None
                else np.asarray(self.converged, dtype=bool).reshape(-1))
        object.__setattr__(self, "converged", conv)
        for name in ("label", "count"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, np.asarray(value, dtype=int).reshape(-1))
        if self.error is not None:
            object.__setattr__(self, "error", np.asarray(self.error, dtype=float).reshape(-1))
        for name in ("label", "count", "converged", "error"):
            value = getattr(self, name)
            if value is not None and value.size != freq.size:
                raise ValueError(f"ChainModes.{name} has {value.size} entries,"
                                 f" freq_hz has {freq.size}")
        if self.vectors is not None:
            vec = np.asarray(self.vectors)
            if vec.ndim != 2 or vec.shape[1] != freq.size:
                raise ValueError(f"ChainModes.vectors must be (n, {freq.size}),"
                                 f" got {vec.shape}")

    @property
    def omega2(self) -> np.ndarray:
        """Eigenvalues λ = ω², (rad/s)², (k,); negative for negative ``freq_hz``."""
        return np.sign(self.freq_hz) * (2 * np.pi * self.freq_hz) ** 2

    def __len__(self) -> int:
        return self.freq_hz.size

    def __repr__(self) -> str:
        k = self.freq_hz.size
        shown = ", ".join(f"{f:.6g}" for f in self.freq_hz[:5]) + (", ..." if k > 5 else "")
        text = f"ChainModes({self.method}: {k} roots, f = [{shown}] Hz"
        if self.vectors is not None:
            text += f", vectors {self.vectors.shape}"
        bad = np.flatnonzero(~self.converged)
        if bad.size:
            text += f", UNCONVERGED roots {bad.tolist()}"
        return text + ")"
