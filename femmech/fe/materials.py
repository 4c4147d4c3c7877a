"""Isotropic linear-elastic materials (SI units).

Stage 2 (fe, independent of mechanisms): imports nothing of femmech.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass

import numpy as np


def check_real(value, label: str) -> None:
    """TypeError naming ``label`` unless ``value`` is a real number (not a bool, string or
    array, which would fail inside numpy with a message naming nothing)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{label} must be a real number, got {value!r}")


@dataclass(frozen=True)
class Material:
    """Isotropic linear-elastic material.

    Parameters
    ----------
    E : float
        Young's modulus, Pa.
    rho : float
        Density, kg/m^3.
    nu : float, optional
        Poisson's ratio (-1 < nu < 0.5). Give ``nu`` or ``G``, not both.
    G : float, optional
        Shear modulus, Pa. If omitted, ``G = E / (2 (1 + nu))``.
    name : str
        Label used in error messages and reports.

    Examples
    --------
    >>> steel = Material(E=210e9, nu=0.3, rho=7850.0, name="steel")
    >>> round(steel.shear_modulus / 1e9, 3)
    80.769
    """

    E: float
    rho: float
    nu: float | None = None
    G: float | None = None
    name: str = "material"

    def __post_init__(self):
        for key in ("E", "rho", "nu", "G"):
            value = getattr(self, key)
            if value is not None or key in ("E", "rho"):
                check_real(value, f"material {self.name!r}: {key}")
        if not (np.isfinite(self.E) and self.E > 0):
            raise ValueError(f"material {self.name!r}: E must be positive and finite, got {self.E}")
        if not (np.isfinite(self.rho) and self.rho >= 0):
            raise ValueError(
                f"material {self.name!r}: rho must be non-negative and finite, got {self.rho}"
            )
        if (self.nu is None) == (self.G is None):
            raise ValueError(f"material {self.name!r}: give exactly one of nu and G")
        if self.nu is not None and not -1.0 < self.nu < 0.5:
            raise ValueError(f"material {self.name!r}: nu must lie in (-1, 0.5), got {self.nu}")
        if self.G is not None and not (np.isfinite(self.G) and self.G > 0):
            raise ValueError(f"material {self.name!r}: G must be positive and finite, got {self.G}")

    @property
    def shear_modulus(self) -> float:
        """Shear modulus G, Pa."""
        if self.G is not None:
            return float(self.G)
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def poisson_ratio(self) -> float:
        """Poisson's ratio, from ``nu`` or from ``E / (2 G) - 1``."""
        if self.nu is not None:
            return float(self.nu)
        return self.E / (2.0 * self.G) - 1.0


STEEL = Material(E=210e9, nu=0.3, rho=7850.0, name="steel")
ALUMINIUM = Material(E=70e9, nu=0.33, rho=2700.0, name="aluminium")
