"""Position functions of the slider-crank and the four-bar linkage, with exact derivatives.

Both are driven by a fully rotating crank at angle φ (rad). The derivatives U', U'', U'''
with respect to φ follow from differentiating the loop-closure equations (no finite
differences). Geometries for which the crank cannot turn fully, or would pass a dead
centre (stationary configuration of the output), are rejected when the object is built.

References
----------
.. [1] H. Dresig, F. Holzweißig, *Maschinendynamik*, Springer, ch. 2 (position functions
   of the slider-crank and four-bar linkage).
.. [2] R. L. Norton, *Design of Machinery*, 5th ed., McGraw-Hill, 2012, ch. 4 and 7
   (Grashof condition, loop-closure equations and their derivatives).

Uses only mechanisms.position.
"""

from dataclasses import dataclass
from typing import Literal

import numpy as np

from femmech.mechanisms.position import as_angles, check_order

__all__ = ["FourBar", "SliderCrank"]


@dataclass(frozen=True)
class SliderCrank:
    """Slider-crank: slider position x(φ) = r cos φ + √(l² − (r sin φ − e)²).

    The crank (radius ``r``) turns about the origin; the slider moves along the x axis at
    distance ``e`` (offset) from it, connected by the coupler of length ``l``.

    Parameters
    ----------
    r : float
        Crank radius, m, > 0.
    l : float
        Coupler length, m; the crank turns fully only if l > r + |e|.
    e : float
        Offset of the slider line, m.

    Notes
    -----
    With w = r sin φ − e and L = √(l² − w²), so that L L' = −w w',

        L'' = −(w'² + w w'' + L'²)/L,   L''' = −(3 w' w'' + w w''' + 3 L' L'')/L,

    and U^(k) = r cos^(k)(φ) + L^(k).
    """

    r: float
    l: float
    e: float = 0.0

    def __post_init__(self):
        if not self.r > 0:
            raise ValueError(f"crank radius r must be positive, got {self.r}")
        if not self.l > self.r + abs(self.e):
            raise ValueError(f"coupler length l = {self.l} must exceed r + |e| = "
                             f"{self.r + abs(self.e)} for a fully rotating crank")

    def derivatives(self, phi) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Return ``(U, U', U'', U''')``: slider position (m) and its φ-derivatives (m/rad^k)."""
        phi = as_angles(phi)
        s, c = np.sin(phi), np.cos(phi)
        w, w1, w2, w3 = self.r * s - self.e, self.r * c, -self.r * s, -self.r * c
        L = np.sqrt(self.l**2 - w**2)
        L1 = -w * w1 / L
        L2 = -(w1**2 + w * w2 + L1**2) / L
        L3 = -(3 * w1 * w2 + w * w3 + 3 * L1 * L2) / L
        return self.r * c + L, -self.r * s + L1, -self.r * c + L2, self.r * s + L3

    def __call__(self, phi, order: int = 0) -> np.ndarray:
        """Return U^(order)(φ) at ``phi`` (rad)."""
        return self.derivatives(phi)[check_order(order)]


def _cross(ax, ay, bx, by):
    return ax * by - ay * bx


@dataclass(frozen=True)
class FourBar:
    """Four-bar linkage with a fully rotating input crank; U is the rocker or coupler angle.

    Crank a turns about A0 = (0, 0) at angle φ; the rocker c turns about B0 = (d, 0) at
    angle ψ; the coupler b joins the crank pin A and the rocker pin B at angle θ:

        a e^{iφ} + b e^{iθ} − c e^{iψ} − d = 0.

    Parameters
    ----------
    a, b, c, d : float
        Crank, coupler, rocker and ground lengths, m, > 0.
    branch : {+1, -1}
        Assembly mode: ψ = arg(A − B0) − branch·δ, with δ ∈ (0, π) the angle at B0 in the
        triangle A B0 B.
    output : {"rocker", "coupler"}
        Which angle (rad) is returned as U.

    Raises
    ------
    ValueError
        If the crank cannot turn fully without the coupler and rocker becoming collinear
        (dead centre of the output, where U' is infinite): the distance |A − B0| ranges over
        [|d − a|, d + a] and must stay inside (|b − c|, b + c).

    Notes
    -----
    Differentiating the loop equation k times gives at every order the linear system
    b θ^(k) i e^{iθ} − c ψ^(k) i e^{iψ} = R_k, solved with 2-D cross products; its
    determinant b c sin(ψ − θ) vanishes only at a dead centre (Norton [2]_, sec. 7.3).
    """

    a: float
    b: float
    c: float
    d: float
    branch: int = 1
    output: Literal["rocker", "coupler"] = "rocker"

    def __post_init__(self):
        for name in ("a", "b", "c", "d"):
            if not getattr(self, name) > 0:
                raise ValueError(f"link length {name} must be positive, got {getattr(self, name)}")
        if self.branch not in (1, -1):
            raise ValueError(f"branch must be +1 or -1, got {self.branch!r}")
        if self.output not in ("rocker", "coupler"):
            raise ValueError(f"output must be 'rocker' or 'coupler', got {self.output!r}")
        lo, hi = abs(self.d - self.a), self.d + self.a
        if not (abs(self.b - self.c) < lo and hi < self.b + self.c):
            raise ValueError(
                f"four-bar a={self.a}, b={self.b}, c={self.c}, d={self.d}: the crank cannot "
                f"turn fully without a dead centre; need |b - c| < |d - a| and d + a < b + c")

    def angles(self, phi) -> tuple[np.ndarray, np.ndarray]:
        """Return the coupler angle θ and rocker angle ψ (rad) at crank angles ``phi``.

        Both are continuous in φ (no wrapping at ±π). For d > a (crank-rocker) ψ and θ
        are periodic; for d < a (double crank) ψ and θ grow by 2π per revolution.
        """
        phi = as_angles(phi)
        crank = self.a * np.exp(1j * phi)
        p = crank - self.d  # from B0 to the crank pin A
        # arg(p) without a branch cut: d - a e^{iφ} (or a - d e^{-iφ}) has positive real part
        if self.d > self.a:
            arg_p = np.pi + np.angle(self.d - crank)
        else:
            arg_p = phi + np.angle(self.a - self.d * np.exp(-1j * phi))
        f = np.abs(p)
        delta = np.arccos((self.c**2 + f**2 - self.b**2) / (2 * self.c * f))
        psi = arg_p - self.branch * delta
        coupler = self.d + self.c * np.exp(1j * psi) - crank  # B - A
        # the coupler-rocker angle stays inside (0, π) or (-π, 0): no wrap
        theta = psi + np.angle(coupler * np.exp(-1j * psi))
        return theta, psi

    def derivatives(self, phi) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Return ``(U, U', U'', U''')``: output angle (rad) and its φ-derivatives (rad/rad^k)."""
        phi = as_angles(phi)
        theta, psi = self.angles(phi)
        a, b, c = self.a, self.b, self.c
        # unit normals u = i e^{iθ}, v = i e^{iψ}; n_x, n_y of i e^{iφ}
        ux, uy, vx, vy = -np.sin(theta), np.cos(theta), -np.sin(psi), np.cos(psi)
        det = _cross(ux, uy, vx, vy)
        # the k-th derivative of a e^{iφ} is a i^k e^{iφ}
        ek = [np.cos(phi), np.sin(phi)]

        def solve(rx, ry):
            return _cross(rx, ry, vx, vy) / (b * det), _cross(rx, ry, ux, uy) / (c * det)

        # order 1: a i e^{iφ} + b θ' u − c ψ' v = 0
        t1, p1 = solve(a * ek[1], -a * ek[0])
        # order 2: −a e^{iφ} + b(θ'' u − θ'² e^{iθ}) − c(ψ'' v − ψ'² e^{iψ}) = 0
        rx = a * ek[0] + b * t1**2 * uy - c * p1**2 * vy
        ry = a * ek[1] - b * t1**2 * ux + c * p1**2 * vx
        t2, p2 = solve(rx, ry)
        # order 3: −a i e^{iφ} + b(θ''' u − 3θ'θ'' e^{iθ} − θ'³ u) − c(same in ψ) = 0
        rx = (-a * ek[1] + b * (3 * t1 * t2 * uy + t1**3 * ux)
              - c * (3 * p1 * p2 * vy + p1**3 * vx))
        ry = (a * ek[0] + b * (-3 * t1 * t2 * ux + t1**3 * uy)
              - c * (-3 * p1 * p2 * vx + p1**3 * vy))
        t3, p3 = solve(rx, ry)
        if self.output == "rocker":
            return psi, p1, p2, p3
        return theta, t1, t2, t3

    def __call__(self, phi, order: int = 0) -> np.ndarray:
        """Return U^(order)(φ) at ``phi`` (rad)."""
        return self.derivatives(phi)[check_order(order)]
