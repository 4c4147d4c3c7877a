"""Mechanisms whose bearings and guides move with an elastic frame (for frame coupling).

The chapter's mechanisms (seed 5.2.2 Table 5.1, 5.2.3.2) are fixed to a rigid ground.
Mounted on a frame (:mod:`femmech.coupling`), the ground points become vibration
coordinates that :class:`~femmech.coupling.Attachment` ties to frame DOFs. Each factory
below returns a symbolic :class:`~femmech.mechanisms.symbolic.Mechanism` with one drive
``theta`` (rad) whose ground coordinates vanish for a rigid frame, and then reduces
*exactly* to the chapter model named in its docstring. Parameter names are arguments so
that several mechanisms of one machine can use the chapter's names (m1, c3, c6 / m2, c4,
c7). Symbols: M mass, B damping, C stiffness, F force (seed chapter).

Coordinates are small displacements (m) or rotations (rad) about the rigid motion:

* cam follower: ``q_s`` shaft twist at the cam, ``y_c`` cam-centre displacement along
  the follower axis, ``y_f`` displacement of the return-spring base, ``q`` follower
  deformation;
* slider-crank: ``q_t`` crankshaft twist, ``u_b``/``v_b`` crank-bearing displacement
  along/across the slider axis, ``v_g`` guide displacement across the slider axis,
  ``q`` connecting-rod (output) deformation.

Coordinate meanings, units and signs: :data:`femmech.mechanisms.catalogue.CATALOGUE`
(docs/mechanisms.md, "Reference of the built-in mechanisms").

Uses mechanisms.symbolic and .catalogue.
"""

from __future__ import annotations

import sympy

from femmech.mechanisms.catalogue import coordinate_labels
from femmech.mechanisms.registry import MechanismType, register
from femmech.mechanisms.symbolic import (
    Damper,
    Load,
    Mechanism,
    PointMass,
    RotaryInertia,
    Spring,
    position_function,
)

__all__ = ["cam_follower", "slider_crank"]


def _symbols(names: str):
    return sympy.symbols(names, real=True)


def cam_follower(U: str = "U", m: str = "m", c: str = "c", c_return: str = "c_r",
                 b: str = "b", F: str = "F", J: str | None = None,
                 name: str = "cam follower") -> Mechanism:
    """Cam mechanism on an elastic shaft whose follower spring is anchored to the frame.

    The cam turns at ψ = θ + q_s (θ drive angle, q_s shaft twist at the cam); its centre
    moves by y_c along the follower axis (shaft bending in the bearings). The follower
    mass m sits at

        y = y_c + U(ψ) + q,   2T = m ẏ² [+ J ψ̇²],   2V = c q² + c_r (y − y_f)²,

    with follower elasticity c (N/m), return spring c_r (N/m) between the follower and
    its base on the frame (displacement y_f), damper b on q and process force F against
    y. For y_c = y_f = 0 this is one cam branch of the processing machine of seed
    5.2.3.2 (eqs. 11, 16: m1, c3, c6, b3, F1 with U1), the shaft inertia J being either
    part of this mechanism (``J`` given) or of the FE shaft (``J=None``).

    Parameters
    ----------
    U : str
        Name of the position function (lift in m over the cam angle in rad).
    m, c, c_return, b, F : str
        Parameter names (kg, N/m, N/m, N s/m, N).
    J : str or None
        Name of the cam's rotary inertia (kg m²), or None if the frame model holds it.
    name : str

    Returns
    -------
    Mechanism
        Coordinates ``(q_s, y_c, y_f, q, theta)``, drive ``theta``.
    """
    theta, qs, yc, yf, q = _symbols("theta q_s y_c y_f q")
    m_, c_, cr, b_, F_ = _symbols(" ".join((m, c, c_return, b, F)))
    psi = theta + qs
    y = yc + position_function(U)(psi) + q
    elements = [PointMass(m_, (y,)), Spring(c_, q), Spring(cr, y - yf), Damper(b_, q),
                Load(-F_, y)]
    if J is not None:
        elements.insert(0, RotaryInertia(sympy.Symbol(J, real=True), psi))
    return Mechanism((qs, yc, yf, q, theta), tuple(elements), drives=(theta,), name=name,
                     labels=coordinate_labels("cam_follower()"))


register(MechanismType("cam_follower", cam_follower))


def slider_crank(m: str = "m2", c: str = "c2", J: str = "J1", c_t: str = "c1",
                 b: str = "b2", b_t: str = "b1", F: str = "F2",
                 name: str = "slider-crank") -> Mechanism:
    """Slider-crank with an elastic crankshaft whose crank bearing and guide move.

    Axes: s along the slider axis (the direction in which the slider position grows),
    n across it, in the mechanism plane. The crank (radius r) turns at ψ = θ + q_t about
    its bearing at (n, s) = (v_b, u_b); the guide line lies at n = e + v_g. The crank pin
    is at (v_b + r sin ψ, u_b + r cos ψ), so the slider (rod length l) is at

        s = u_b + r cos ψ + √(l² − (r sin ψ − e − v_g + v_b)²),

    which is :class:`~femmech.mechanisms.linkages.SliderCrank` ``(r, l, e)`` displaced
    by the bearing and with the offset changed by the guide. The ram (mass m) follows
    the slider through the output elasticity c (N/m, rod and ram in series, measured
    along the slider axis as in Table 5.1) and moves across with the guide:

        x = s + q,   2T = J ψ̇² + m (ẋ² + v̇_g²),   2V = c_t q_t² + c q²,

    with dampers b_t on q_t and b on q and a process force F against x. For
    u_b = v_b = v_g = 0 this is Table 5.1 case 1 (seed 5.2.2; errata §A) with
    U = SliderCrank(r, l, e): J1, m2, c1, c2, b1, b2, F2 by default.

    The position is regular at the dead centres (U' = 0) because l > r + |e|; there the
    crank torsion decouples from the ram. Neglected: the masses of crank and rod, and
    the frame's small rotations at the bearing and guide (they turn the slider axis).

    Parameters
    ----------
    m, c, J, c_t, b, b_t, F : str
        Parameter names (kg, N/m, kg m², N m/rad, N s/m, N m s/rad, N). The geometry
        parameters are ``r``, ``l``, ``e`` (m).
    name : str

    Returns
    -------
    Mechanism
        Coordinates ``(q_t, u_b, v_b, v_g, q, theta)``, drive ``theta``.
    """
    theta, qt, ub, vb, vg, q = _symbols("theta q_t u_b v_b v_g q")
    r, l, e = _symbols("r l e")
    m_, c_, J_, ct, b_, bt, F_ = _symbols(" ".join((m, c, J, c_t, b, b_t, F)))
    psi = theta + qt
    s = ub + r * sympy.cos(psi) + sympy.sqrt(l**2 - (r * sympy.sin(psi) - e - vg + vb)**2)
    x = s + q
    elements = (RotaryInertia(J_, psi), PointMass(m_, (x, vg)), Spring(ct, qt), Spring(c_, q),
                Damper(bt, qt), Damper(b_, q), Load(-F_, x))
    return Mechanism((qt, ub, vb, vg, q, theta), elements, drives=(theta,), name=name,
                     labels=coordinate_labels("slider_crank()"))


register(MechanismType("slider_crank", slider_crank))
