"""Isotropic linear-elastic materials (SI units).

Stage 2 (fe, independent of mechanisms): imports nothing of femmech.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass

import numpy as np

MODULUS_RANGE = (1e-100, 1e100)
"""Range of E and G accepted, in the unit of the model (Pa, N/mm², psi, ...): every real
material of every unit system lies far inside (soft gels: 1e2 Pa; diamond: 1.2e12 Pa).
Outside, the element matrices (E or G times section and length factors) leave the normal
floats: a 2 m steel cantilever of E = 5e-324 (subnormal) has NaN matrices ("the mass
matrix has no positive diagonal entry"), E = 1e-310 stops LAPACK, E = 1e300 overflows;
E = 1e-300 still solves. 1e±100 leaves 200 orders for the other factors."""
DENSITY_RANGE = (1e-100, 1e100)
"""Range of a non-zero density ρ accepted (kg/m³, t/mm³, ...; ρ = 0 is a massless
material): a 2 m steel cantilever of ρ = 1e-300 overflows in the eigenvalues (E/ρ),
ρ = 1e-290 still solves."""


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
        _in_range(self.E, MODULUS_RANGE, f"material {self.name!r}: E", "MODULUS_RANGE")
        if self.rho:
            _in_range(self.rho, DENSITY_RANGE, f"material {self.name!r}: rho",
                      "DENSITY_RANGE")
        if (self.nu is None) == (self.G is None):
            raise ValueError(f"material {self.name!r}: give exactly one of nu and G")
        if self.nu is not None and not -1.0 < self.nu < 0.5:
            raise ValueError(f"material {self.name!r}: nu must lie in (-1, 0.5), got {self.nu}")
        if self.G is not None and not (np.isfinite(self.G) and self.G > 0):
            raise ValueError(f"material {self.name!r}: G must be positive and finite, got {self.G}")
        if self.G is not None:
            _in_range(self.G, MODULUS_RANGE, f"material {self.name!r}: G", "MODULUS_RANGE")

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


def _in_range(value: float, bounds: tuple, label: str, limit: str) -> None:
    low, high = bounds
    if not low <= value <= high:
        raise ValueError(f"{label} = {value!r} is outside [{low:g}, {high:g}] ({limit}): the"
                         " element matrices would not be finite normal numbers; no unit"
                         " system has such a material")


STEEL = Material(E=210e9, nu=0.3, rho=7850.0, name="steel")
ALUMINIUM = Material(E=70e9, nu=0.33, rho=2700.0, name="aluminium")
