"""Beam cross-sections: area, second moments, torsion constant and shear areas.

Local section axes follow the element frame of :mod:`femmech.fe.elements.beam`: the beam
axis is local x, the section lies in the local (y, z) plane, and ``y``, ``z`` are the
principal axes. ``Iy = ∫ z² dA`` resists bending about y (deflection along z),
``Iz = ∫ y² dA`` resists bending about z (deflection along y). ``Asy`` and ``Asz`` are
the effective shear areas for shear forces along y and z; ``None`` means shear-rigid
(Euler-Bernoulli) in that direction.

Shear coefficients and Poisson's ratio. The shear area is ``As = k A`` with the shear
coefficient ``k`` of the shape; for the solid rectangle and the circular tube it is
Cowper's (1966), which depends on Poisson's ratio ν. A section is built before it meets a
material, so :func:`rectangle`, :func:`tube` and :func:`circle` take their own ``nu``
(default 0.3) and do not read ``Material.nu``: pass ``nu=material.nu`` to match them. The
beam element then uses the material's shear modulus, ``G As = Material.shear_modulus · k A``
(ν enters twice: through G from ``Material``, through k from the section). Scenes build
their sections with the default ν = 0.3 whatever the material. The error is small: k of a
rectangle is 0.833, 0.850 and 0.857 for ν = 0, 0.3 and 0.5, of a solid circle 0.857, 0.886
and 0.900, so a material with ν anywhere in [0, 0.5] changes k from its ν = 0.3 value by
at most 3.3 % (circle, ν = 0), and a frequency by less than that times the share of its
strain energy in shear deformation. Thin-walled sections
(:func:`i_section`, :func:`rectangular_hollow`) use ν-independent approximations (web or
wall areas). Shells use ``k = 5/6`` for every material
(:data:`femmech.fe.elements.shell.SHEAR_FACTOR`, see :class:`femmech.ShellProperty`).

Stage 2 (fe, independent of mechanisms): uses only fe.materials.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femmech.fe.materials import check_real


@dataclass(frozen=True)
class BeamSection:
    """Cross-section properties of a prismatic beam (SI units).

    Attributes
    ----------
    A : float
        Area, m^2.
    Iy, Iz : float
        Second moments of area about the local y and z axes, m^4.
    J : float
        Saint-Venant torsion constant, m^4 (not the polar moment, except for circles).
    Asy, Asz : float or None
        Effective shear areas for shear along y and z, m^2; ``None`` = shear-rigid.
    Ip : float or None
        Polar moment of area used for the torsional mass ``rho * Ip``, m^4;
        ``None`` means ``Iy + Iz``.
    shape : str
        ``"rectangle"``, ``"circle"``, ``"tube"``, ``"i"``, ``"box"`` or ``"general"``.
    dims : tuple of float
        The defining dimensions of ``shape`` (m), used for drawing.
    name : str
        Label for reports and error messages.
    """

    A: float
    Iy: float
    Iz: float
    J: float
    Asy: float | None = None
    Asz: float | None = None
    Ip: float | None = None
    shape: str = "general"
    dims: tuple[float, ...] = ()
    name: str = "section"

    def __post_init__(self):
        for key in ("A", "Iy", "Iz", "J", "Asy", "Asz", "Ip"):
            value = getattr(self, key)
            if value is not None or key in ("A", "Iy", "Iz", "J"):
                check_real(value, f"section {self.name!r}: {key}")
        for key in ("A", "Iy", "Iz", "J"):
            value = getattr(self, key)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(
                    f"section {self.name!r}: {key} must be positive and finite, got {value}"
                )
        for key in ("Asy", "Asz", "Ip"):
            value = getattr(self, key)
            if value is not None and not (np.isfinite(value) and value > 0):
                raise ValueError(
                    f"section {self.name!r}: {key} must be positive, finite or None, got {value}"
                )

    @property
    def polar_moment(self) -> float:
        """Polar moment of area for rotary (torsional) inertia, m^4."""
        return float(self.Ip) if self.Ip is not None else self.Iy + self.Iz

    @property
    def draw_radius(self) -> float:
        """Half the largest section dimension (or of an equivalent circle), m."""
        if self.dims:
            return 0.5 * max(self.dims[:2]) if self.shape != "tube" else 0.5 * self.dims[0]
        return float(np.sqrt(self.A / np.pi))


def _positive(name: str, **values: float) -> None:
    for key, value in values.items():
        check_real(value, f"{name}: {key}")
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"{name}: {key} must be positive and finite, got {value}")


def _poisson(name: str, nu: float) -> None:
    check_real(nu, f"{name}: nu")
    if not -1.0 < nu < 0.5:
        raise ValueError(f"{name}: nu must lie in (-1, 0.5), got {nu}")


def rectangle_torsion_constant(a: float, b: float, terms: int = 50) -> float:
    """Saint-Venant torsion constant of a solid a x b rectangle, m^4.

    Series solution (Timoshenko & Goodier, Theory of Elasticity, 3rd ed., §109):
    ``J = a b³ [1/3 - (64 / π⁵)(b / a) Σ_{n odd} tanh(n π a / 2b) / n⁵]`` with a >= b.
    A square gives ``J = 0.1406 a⁴``.
    """
    a, b = max(a, b), min(a, b)
    n = np.arange(1, 2 * terms, 2, dtype=float)
    series = np.sum(np.tanh(n * np.pi * a / (2.0 * b)) / n**5)
    return float(a * b**3 * (1.0 / 3.0 - 64.0 / np.pi**5 * (b / a) * series))


def rectangle(width: float, height: float, nu: float = 0.3, name: str = "rectangle"):
    """Solid rectangle, ``width`` along local y and ``height`` along local z (m).

    Shear coefficient after Cowper (1966), J. Appl. Mech. 33:335, ``k = 10(1+ν)/(12+11ν)``
    (0.850 for ν = 0.3). ``nu`` is Poisson's ratio of this formula only (default 0.3):
    give ``nu=material.nu`` to match the beam's material, whose shear modulus G the element
    uses (module notes).
    """
    _positive(name, width=width, height=height)
    _poisson(name, nu)
    A = width * height
    k = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu)
    return BeamSection(
        A=A, Iy=width * height**3 / 12.0, Iz=height * width**3 / 12.0,
        J=rectangle_torsion_constant(width, height), Asy=k * A, Asz=k * A,
        shape="rectangle", dims=(width, height), name=name,
    )


def tube(outer_diameter: float, inner_diameter: float, nu: float = 0.3, name: str = "tube"):
    """Circular tube (m); ``inner_diameter = 0`` gives a solid circle.

    Shear coefficient after Cowper (1966):
    ``k = 6(1+ν)(1+m²)² / ((7+6ν)(1+m²)² + (20+12ν)m²)``, ``m = d_i / d_o``. ``nu`` is
    Poisson's ratio of this formula only (default 0.3, not read from a Material): give
    ``nu=material.nu`` to match the beam's material (module notes).
    """
    _positive(name, outer_diameter=outer_diameter)
    _poisson(name, nu)
    check_real(inner_diameter, f"{name}: inner_diameter")
    if not 0.0 <= inner_diameter < outer_diameter:
        raise ValueError(
            f"{name}: inner_diameter must lie in [0, outer_diameter), got {inner_diameter}"
        )
    m2 = (inner_diameter / outer_diameter) ** 2
    A = np.pi / 4.0 * (outer_diameter**2 - inner_diameter**2)
    inertia = np.pi / 64.0 * (outer_diameter**4 - inner_diameter**4)
    k = 6.0 * (1 + nu) * (1 + m2) ** 2 / ((7 + 6 * nu) * (1 + m2) ** 2 + (20 + 12 * nu) * m2)
    shape = "tube" if inner_diameter > 0 else "circle"
    return BeamSection(
        A=A, Iy=inertia, Iz=inertia, J=2.0 * inertia, Asy=k * A, Asz=k * A, Ip=2.0 * inertia,
        shape=shape, dims=(outer_diameter, inner_diameter), name=name,
    )


def circle(diameter: float, nu: float = 0.3, name: str = "circle"):
    """Solid circle of ``diameter`` (m); see :func:`tube` for the shear coefficient."""
    _positive(name, diameter=diameter)
    return tube(diameter, 0.0, nu=nu, name=name)


def i_section(height: float, width: float, web: float, flange: float, name: str = "I"):
    """Doubly symmetric I/H section: ``height`` along z, flange ``width`` along y (m).

    ``web`` and ``flange`` are the web and flange thicknesses. Torsion constant of the
    open thin-walled section ``J = (2 b t_f³ + (h - t_f) t_w³) / 3``; shear areas
    ``Asz = h t_w`` (web) and ``Asy = 5/6 · 2 b t_f`` (flanges), the usual engineering
    approximations (Pilkey, Formulas for Stress, Strain and Structural Matrices, 2nd ed.,
    table 2-5 and §2.10).
    """
    _positive(name, height=height, width=width, web=web, flange=flange)
    if 2 * flange >= height or web >= width:
        raise ValueError(f"{name}: need 2*flange < height and web < width")
    h, b, tw, tf = height, width, web, flange
    hw = h - 2 * tf
    return BeamSection(
        A=2 * b * tf + hw * tw,
        Iy=(b * h**3 - (b - tw) * hw**3) / 12.0,
        Iz=(2 * tf * b**3 + hw * tw**3) / 12.0,
        J=(2 * b * tf**3 + (h - tf) * tw**3) / 3.0,
        Asy=5.0 / 6.0 * 2 * b * tf, Asz=h * tw,
        shape="i", dims=(h, b, tw, tf), name=name,
    )


def rectangular_hollow(width: float, height: float, wall: float, name: str = "box"):
    """Rectangular hollow section (m), ``width`` along y, ``height`` along z.

    Torsion constant from Bredt's formula for a closed thin-walled section,
    ``J = 2 t (b - t)² (h - t)² / (b + h - 2t)``; shear areas of the walls parallel to
    the shear force, ``Asy = 2 b t`` and ``Asz = 2 h t`` (Pilkey, op. cit.).
    """
    _positive(name, width=width, height=height, wall=wall)
    if 2 * wall >= min(width, height):
        raise ValueError(f"{name}: wall must be less than half of width and height")
    b, h, t = width, height, wall
    bi, hi = b - 2 * t, h - 2 * t
    return BeamSection(
        A=b * h - bi * hi,
        Iy=(b * h**3 - bi * hi**3) / 12.0,
        Iz=(h * b**3 - hi * bi**3) / 12.0,
        J=2 * t * (b - t) ** 2 * (h - t) ** 2 / (b + h - 2 * t),
        Asy=2 * b * t, Asz=2 * h * t,
        shape="box", dims=(b, h, t), name=name,
    )


def general(A: float, Iy: float, Iz: float, J: float, Asy: float | None = None,
            Asz: float | None = None, Ip: float | None = None, name: str = "general"):
    """Section from given properties (principal axes); see :class:`BeamSection`."""
    return BeamSection(A=A, Iy=Iy, Iz=Iz, J=J, Asy=Asy, Asz=Asz, Ip=Ip, name=name)
