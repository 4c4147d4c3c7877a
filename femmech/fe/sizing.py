"""Meshes sized for a frequency band: element lengths from wavelengths and error constants.

A mode's relative frequency error is a weighted average (Rayleigh quotient) of the
errors the elements make on the local wave, so a mesh whose elements resolve the
*shortest* wave up to ``f_max`` to a target error meets it for every mode up to ``f_max``.
The shortest wave of a beam member or a shell at ω = 2π f_max is found from its
dispersion relation, and the element length from the element's measured error as a
function of the number ``n`` of elements per half-wavelength:

==========================  =========================================  ==================
element                     relative frequency error ε(n)              measured on
==========================  =========================================  ==================
beam, bending (IIE, cubic)  (π/n)⁴ / 1440 + s² (π/n)² / 24              simply supported
                            with s² = E I k² / (G A_s) (shear)          beam, Blevins 1979
beam, axial and torsion     (π/n)² / 24 (linear, consistent mass)       fixed bar
MITC4 quad (bending)        0.125 (π/n)²                                simply supported
MITC3 triangle (bending)    0.115 (π/n)²                                plate, Leissa 1969
==========================  =========================================  ==================

The beam constants are the known asymptotic errors of consistent-mass elements (cubic
Hermite: (kh)⁴/1440, linear: (kh)²/24, with kh = π/n), confirmed by measurement
(``tests/test_sizing.py``): ε n⁴ = 0.0665, 0.0673 at n = 4, 8 against π⁴/1440 = 0.0676
(rate 3.98), and ε n² = 0.4120, 0.4114 for the bar against π²/24 = 0.4112. The shear term
was fitted to Timoshenko beams with s² from 2.5e-4 to 0.23: (ε − (π/n)⁴/1440) n² / s² =
0.30 … 0.405 at n = 4 … 8, against the bound's π²/24 = 0.411. The shell constants are
the envelope of ε (n/π)² over wave directions on a simply supported square plate (t/a =
0.01, 24 x 24 and 48 x 48, Mindlin's exact solution; Leissa NASA SP-160 §4.1 in the thin
limit): MITC4 0.056 (diagonal waves) to 0.118 (waves 9.5° off a grid line, rising
towards aligned waves; bound 0.125), MITC3 0.091 to 0.112 (bound 0.115); rate 2.0 for
both. Thicker plates (t/a = 0.05, 0.1) give smaller constants.

Uses fe.sections and fe.materials (beam
properties are read by attribute); no assembly, no eigen solves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from femmech.fe.materials import Material
from femmech.fe.sections import BeamSection

SHEAR_FACTOR_PLATE = 5.0 / 6.0
"""Shear correction factor of the shell elements (:mod:`femmech.fe.elements.shell`)."""


@dataclass(frozen=True)
class ErrorModel:
    """Relative frequency error of an element vs elements per half-wavelength ``n``:
    ``ε(n) = c4 (π/n)⁴ + c2 (π/n)²`` (``c2`` may grow with the shear parameter)."""

    c4: float
    c2: float
    source: str


BEAM_BENDING = ErrorModel(1.0 / 1440.0, 0.0, "IIE Timoshenko / cubic Hermite, consistent mass")
BEAM_SHEAR_C2 = 1.0 / 24.0
"""Coefficient of ``s² (π/n)²`` in the beam's bending error (shear-flexible members)."""
BEAM_LINEAR = ErrorModel(0.0, 1.0 / 24.0, "linear axial and torsional fields, consistent mass")
SHELL_BENDING = {
    "quad": ErrorModel(0.0, 0.125, "MITC4, envelope over wave directions"),
    "triangle": ErrorModel(0.0, 0.115, "MITC3, envelope over wave directions"),
    "quad9": ErrorModel(0.002, 0.0, "MITC9, envelope of 0.0013-0.0018 measured on the"
                        " first ten modes of a thin simply supported plate, 8x8 and 16x16"),
    "triangle6": ErrorModel(0.012, 0.0, "MITC6, envelope of 0.0015-0.0116 measured on the"
                            " same plate (rate 3.7-3.9: the larger constant covers it)"),
}
"""Error models of the shell kinds with measured constants (``ε = c4 (π/n)⁴ + c2 (π/n)²``,
n elements per bending half-wave; thin simply supported plate, a/t = 1000, against
Leissa's closed form)."""
SHELL_MEMBRANE_C2 = 0.125
"""Membrane waves of the linear shells: taken as their bending constant (an upper bound of
the bilinear membrane's error, (π/n)²/24 for a bar; membrane waves are long and rarely
decide the size)."""


def elements_per_half_wave(target_error: float, model: ErrorModel, c2_extra: float = 0.0) -> float:
    """Smallest ``n`` (elements per half-wavelength, real) with ``ε(n) <= target_error``.

    ``ε(n) = c4 u² + (c2 + c2_extra) u`` with ``u = (π/n)²``: the positive root of the
    quadratic in u.
    """
    _check_target(target_error)
    a, b = model.c4, model.c2 + c2_extra
    if a == 0.0:
        u = target_error / b
    else:
        u = 2.0 * target_error / (b + math.sqrt(b * b + 4.0 * a * target_error))
    return math.pi / math.sqrt(u)


def _check_target(target_error: float) -> None:
    if not (isinstance(target_error, (int, float, np.floating)) and 1e-8 <= target_error < 1):
        raise ValueError(f"target_error must be a relative error in [1e-8, 1), got"
                         f" {target_error!r}")


def _check_f_max(f_max: float) -> float:
    if not (isinstance(f_max, (int, float, np.floating, np.integer)) and np.isfinite(f_max)
            and f_max > 0):
        raise ValueError(f"f_max must be a positive frequency in Hz, got {f_max!r}")
    return 2.0 * math.pi * float(f_max)


def flexural_wavenumber(omega: float, stiffness: float, mass: float, rotary: float = 0.0,
                        shear: float = math.inf) -> float:
    """Wavenumber k (rad/m) of free flexural waves at ``omega`` (rad/s).

    Timoshenko beam (Graff, Wave Motion in Elastic Solids, 1975, §3.4) or Mindlin plate
    with ``stiffness`` = E I or D (N m² or N m), ``mass`` = ρ A or ρ t (kg/m, kg/m²),
    ``rotary`` = ρ I or ρ t³/12 (kg m, kg), ``shear`` = G A_s or κ G t (N, N/m):
    ``EI k⁴ − ω² (ρI + ρA EI / GA_s) k² − ω² (ρA − ρI ρA ω² / GA_s) = 0``; the larger
    root in k² (the propagating branch). ``rotary = 0``, ``shear = inf``: Euler-Bernoulli,
    ``k = (ρA ω² / EI)^(1/4)``.
    """
    w2 = omega * omega
    b = w2 * (rotary + mass * stiffness / shear)
    c = w2 * (mass - rotary * mass * w2 / shear)
    k2 = (b + math.sqrt(b * b + 4.0 * stiffness * c)) / (2.0 * stiffness)
    return math.sqrt(k2)


def bending_wavelength(stiffness: float, mass: float, omega: float) -> float:
    """Euler-Bernoulli / Kirchhoff bending wavelength ``2π (EI / (ρA ω²))^(1/4)``, m."""
    return 2.0 * math.pi * (stiffness / (mass * omega * omega)) ** 0.25


def beam_element_length(section: BeamSection, material: Material, f_max: float,
                        target_error: float, shear: bool = True,
                        rotary_inertia: bool = True) -> float:
    """Longest beam element (m) that keeps every wave up to ``f_max`` (Hz) within
    ``target_error`` (relative frequency error): bending about both axes (Timoshenko
    dispersion with the section's shear areas), axial and torsional waves."""
    omega = _check_f_max(f_max)
    E, G, rho = material.E, material.shear_modulus, material.rho
    lengths = []
    for inertia, shear_area in ((section.Iy, section.Asz), (section.Iz, section.Asy)):
        ga = G * shear_area if (shear and shear_area is not None) else math.inf
        k = flexural_wavenumber(omega, E * inertia, rho * section.A,
                                rho * inertia if rotary_inertia else 0.0, ga)
        s2 = E * inertia * k * k / ga
        n = elements_per_half_wave(target_error, BEAM_BENDING, BEAM_SHEAR_C2 * s2)
        lengths.append(math.pi / k / n)
    n_linear = elements_per_half_wave(target_error, BEAM_LINEAR)
    c_axial = math.sqrt(E / rho)
    c_torsion = math.sqrt(G * section.J / (rho * section.polar_moment))
    lengths += [math.pi * c / omega / n_linear for c in (c_axial, c_torsion)]
    return min(lengths)


def beam_divisions(lengths, properties, f_max: float, target_error: float) -> np.ndarray:
    """Elements per member for the band up to ``f_max`` (Hz) and ``target_error``.

    Parameters
    ----------
    lengths : array_like (n_members,)
        Member lengths, m.
    properties : sequence of BeamProperty (or of (BeamSection, Material) pairs)
        The property of each member.

    Returns
    -------
    ndarray (n_members,) of int
        ``ceil(L / h_max)`` (at least 1), ``h_max`` from :func:`beam_element_length`.
    """
    lengths = np.asarray(lengths, dtype=float).reshape(-1)
    if len(properties) != len(lengths):
        raise ValueError(f"{len(lengths)} member lengths but {len(properties)} properties")
    if not (np.isfinite(lengths).all() and (lengths > 0).all()):
        raise ValueError(f"member lengths must be positive, got {lengths[lengths <= 0][:5]}")
    h = np.array([_element_length(p, f_max, target_error) for p in properties])
    return np.maximum(1, np.ceil(lengths / h * (1 - 1e-12))).astype(np.int64)


def _element_length(prop, f_max: float, target_error: float) -> float:
    if isinstance(prop, tuple):
        return beam_element_length(prop[0], prop[1], f_max, target_error)
    return beam_element_length(prop.section, prop.material, f_max, target_error,
                               prop.shear, prop.rotary_inertia)


def shell_size(thickness: float, material: Material, f_max: float, target_error: float,
               element: str = "quad") -> float:
    """Largest shell element size h (m, side of a quad or of the right triangles' legs)
    for the band up to ``f_max`` (Hz) and ``target_error``.

    Bending: Mindlin plate wavenumber at ω (shear factor 5/6, rotary inertia ρt³/12;
    Kirchhoff's ``2π (D / (ρ t ω²))^(1/4)`` for thin plates), ``D = E t³ / (12 (1 − ν²))``;
    membrane: the in-plane shear wave ``sqrt(G/ρ)`` (the shorter of the two in-plane
    waves). ``element``: ``"quad"`` (MITC4), ``"triangle"`` (MITC3), ``"quad9"`` (MITC9) or
    ``"triangle6"`` (MITC6).
    """
    if element not in SHELL_BENDING:
        raise ValueError(f"element must be one of {list(SHELL_BENDING)} (measured error"
                         f" constants), got {element!r}")
    if not (np.isfinite(thickness) and thickness > 0):
        raise ValueError(f"thickness must be a positive length in m, got {thickness!r}")
    omega = _check_f_max(f_max)
    t, E, nu, G, rho = thickness, material.E, material.poisson_ratio, \
        material.shear_modulus, material.rho
    D = E * t**3 / (12.0 * (1.0 - nu * nu))
    k = flexural_wavenumber(omega, D, rho * t, rho * t**3 / 12.0, SHEAR_FACTOR_PLATE * G * t)
    h_bending = math.pi / k / elements_per_half_wave(target_error, SHELL_BENDING[element])
    n_membrane = elements_per_half_wave(target_error, ErrorModel(0.0, SHELL_MEMBRANE_C2, ""))
    h_membrane = math.pi * math.sqrt(G / rho) / omega / n_membrane
    return min(h_bending, h_membrane)


def divisions(length: float, h_max: float) -> int:
    """Elements along ``length`` (m) no longer than ``h_max`` (m): ``ceil``, at least 1."""
    return max(1, math.ceil(length / h_max * (1 - 1e-12)))


def member_segment_divisions(joints, members, beams, f_max: float,
                             target_error: float) -> list[list[int]]:
    """Elements of each straight segment of each member of a
    :func:`femmech.fe.generators.members_frame` description (``beams``: group →
    BeamProperty), for the band up to ``f_max`` and ``target_error``."""
    out = []
    for m, member in enumerate(members):
        group = member["group"]
        if group not in beams:
            raise ValueError(f"member {m}: group {group!r} has no beam property")
        h = _element_length(beams[group], f_max, target_error)
        chain = list(member["chain"])
        out.append([divisions(math.dist(joints[a], joints[b]), h)
                    for a, b in zip(chain[:-1], chain[1:], strict=True)])
    return out


def sized_members(joints, members, beams, f_max: float, target_error: float) -> list[dict]:
    """The members of a ``members_frame`` description, one per straight segment, each
    with its ``divisions`` from :func:`member_segment_divisions` (same nodes and element
    order as the chains: interior nodes still follow segment by segment)."""
    counts = member_segment_divisions(joints, members, beams, f_max, target_error)
    out = []
    for member, ks in zip(members, counts, strict=True):
        chain = list(member["chain"])
        out += [{"group": member["group"], "chain": [a, b], "divisions": k}
                for a, b, k in zip(chain[:-1], chain[1:], ks, strict=True)]
    return out


def grid_subdivisions(bays, size, beams, f_max: float, target_error: float) -> int:
    """Elements per member of a :func:`femmech.fe.generators.grid_frame` (one count for
    all members): the largest over its groups ``beams_x``, ``beams_y``, ``columns``
    (member lengths ``size[i] / bays[i]``) that ``beams`` (group → BeamProperty) holds."""
    counts = [1]
    for axis, group in enumerate(("beams_x", "beams_y", "columns")):
        if bays[axis] > 0 and group in beams:
            h = _element_length(beams[group], f_max, target_error)
            counts.append(divisions(size[axis] / bays[axis], h))
    return max(counts)


def shell_divisions(lengths, h_max: float) -> tuple[int, ...]:
    """Elements along each side ``lengths`` (m) of a plate or box no longer than ``h_max``."""
    return tuple(divisions(float(L), h_max) for L in lengths)
