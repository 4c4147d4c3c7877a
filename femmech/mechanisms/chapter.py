"""Built-in mechanism models of the seed chapter (Table 5.1, 5.2.3.1, 5.2.3.2).

Each function returns a symbolic :class:`~femmech.mechanisms.symbolic.Mechanism`;
parameters stay symbolic (their names are listed in each docstring) and are given
values when a model is built (:func:`~femmech.mechanisms.models.rheolinear`,
:func:`~femmech.mechanisms.models.second_kind`,
:func:`~femmech.mechanisms.models.mixed_type`). The energies are those of errata §A,
from which every corrected closed form of the errata was derived.

Coordinates: q1, q2, … are vibration (elastic) coordinates; ``theta`` is the drive
angle of Table 5.1 (θ = Ωt) and q1 the drive of the processing machine with kinematic
drive. Examples
--------
>>> from femmech.mechanisms import SliderCrank, rheolinear
>>> model = rheolinear(table_5_1_case(1), dict(J1=0.1, m2=2.0, c1=1e4, c2=1e5, b1=1.0,
...                    b2=10.0, F2=50.0), {"U": SliderCrank(0.05, 0.2)})
>>> model.M([0.0, 1.0]).shape
(2, 2, 2)

Coordinate meanings, units and signs: :data:`femmech.mechanisms.catalogue.CATALOGUE`
(docs/mechanisms.md, "Reference of the built-in mechanisms").

Uses mechanisms.symbolic, .motion_laws and
.catalogue.
"""

import numpy as np
import sympy

from femmech.mechanisms.catalogue import coordinate_labels
from femmech.mechanisms.motion_laws import (
    CamProfile,
    CamSegment,
    modified_sine,
    polynomial_345,
)
from femmech.mechanisms.registry import MechanismType, register
from femmech.mechanisms.symbolic import (
    Damper,
    Load,
    Mechanism,
    PointMass,
    Potential,
    RotaryInertia,
    Spring,
    position_function,
)

__all__ = [
    "mobile_crane",
    "mobile_crane_parameters",
    "processing_machine",
    "processing_machine_mixed",
    "processing_machine_parameters",
    "table_5_1_case",
]


def _symbols(names: str):
    return sympy.symbols(names, real=True)


def table_5_1_case(case: int) -> Mechanism:
    """Return the mechanism of Table 5.1 (seed 5.2.2), cases 1–4 (energies of errata §A).

    The drive shaft turns at θ = Ωt (drive coordinate ``theta``); q1 is the twist of
    the drive shaft, so the cam or linkage angle is ψ = θ + q1.

    * Case 1: shaft J1, c1, b1; output mass m2 at x2 = U(ψ) + q2 on spring c2, damper
      b2; process force F2 against x2. Coordinates (q1, q2).
    * Case 2: as case 1 with two masses m2, m3 at U(ψ) + q2, U(ψ) + q3, springs c2, c3
      (between them), dampers b2, b3, force F3 on m3. Coordinates (q1, q2, q3).
    * Case 3: two mechanisms U2, U3 on J1 with m2, c2, b2, F2 and m3, c3, b3, F3.
    * Case 4 (reconstruction of errata item 18): two identical mechanisms U between an
      elastic input shaft (J12, J13, c11, c12, b11, b12) and an elastic output shaft
      (J22, J23, c21, c22, b21, b22), output torques T2, T3. Coordinates (q1, q2).

    Position-function names: ``U`` (cases 1, 2, 4), ``U2`` and ``U3`` (case 3).
    """
    theta, q1, q2, q3 = _symbols("theta q1 q2 q3")
    psi = theta + q1
    if case == 1:
        U = position_function("U")
        J1, m2, c1, c2, b1, b2, F2 = _symbols("J1 m2 c1 c2 b1 b2 F2")
        x2 = U(psi) + q2
        elements = (RotaryInertia(J1, psi), PointMass(m2, (x2,)), Spring(c1, q1), Spring(c2, q2),
                    Damper(b1, q1), Damper(b2, q2), Load(-F2, x2))
        coords = (q1, q2)
    elif case == 2:
        U = position_function("U")
        J1, m2, m3, c1, c2, c3, b1, b2, b3, F3 = _symbols("J1 m2 m3 c1 c2 c3 b1 b2 b3 F3")
        x2, x3 = U(psi) + q2, U(psi) + q3
        elements = (RotaryInertia(J1, psi), PointMass(m2, (x2,)), PointMass(m3, (x3,)),
                    Spring(c1, q1), Spring(c2, q2), Spring(c3, q3 - q2), Damper(b1, q1),
                    Damper(b2, q2), Damper(b3, q3 - q2), Load(-F3, x3))
        coords = (q1, q2, q3)
    elif case == 3:
        U2, U3 = position_function("U2"), position_function("U3")
        J1, m2, m3, c1, c2, c3, b1, b2, b3, F2, F3 = _symbols(
            "J1 m2 m3 c1 c2 c3 b1 b2 b3 F2 F3")
        x2, x3 = U2(psi) + q2, U3(psi) + q3
        elements = (RotaryInertia(J1, psi), PointMass(m2, (x2,)), PointMass(m3, (x3,)),
                    Spring(c1, q1), Spring(c2, q2), Spring(c3, q3), Damper(b1, q1),
                    Damper(b2, q2), Damper(b3, q3), Load(-F2, x2), Load(-F3, x3))
        coords = (q1, q2, q3)
    elif case == 4:
        return _table_5_1_case_4()
    else:
        raise ValueError(f"Table 5.1 has cases 1 to 4, got {case!r}")
    return Mechanism(coords + (theta,), elements, drives=(theta,), name=f"Table 5.1 case {case}",
                     labels=coordinate_labels(f"table_5_1_case({case})"))


register(MechanismType("table_5_1_case", table_5_1_case,
                      lambda options: f"table_5_1_case({options.get('case')})",
                      tuple(f"table_5_1_case({case})" for case in (1, 2, 3, 4))))


def _table_5_1_case_4() -> Mechanism:
    theta, q1, q2 = _symbols("theta q1 q2")
    U = position_function("U")
    J12, J13, J22, J23, c11, c12, c21, c22, b11, b12, b21, b22, T2, T3 = _symbols(
        "J12 J13 J22 J23 c11 c12 c21 c22 b11 b12 b21 b22 T2 T3")
    a2 = theta + q1
    a3 = a2 + q2
    o1, o2, o3 = U(theta), U(a2), U(a3)
    elements = (RotaryInertia(J12, a2), RotaryInertia(J13, a3), RotaryInertia(J22, o2),
                RotaryInertia(J23, o3), Spring(c11, q1), Spring(c12, q2), Spring(c21, o2 - o1),
                Spring(c22, o3 - o2), Damper(b11, q1), Damper(b12, q2), Damper(b21, o2 - o1),
                Damper(b22, o3 - o2), Load(-T2, o2), Load(-T3, o3))
    return Mechanism((q1, q2, theta), elements, drives=(theta,), name="Table 5.1 case 4",
                     labels=coordinate_labels("table_5_1_case(4)"))


def _processing_machine_parts(q, y1, y2):
    """Elements shared by the 5.2.3.2 models (energies of errata §A, eqs. 11, 16, 7)."""
    q1, q2, q3, q4, q5 = q
    J0, J1, J2, m1, m2 = _symbols("J0 J1 J2 m1 m2")
    cT1, cT2, c3, c4, c6, c7 = _symbols("cT1 cT2 c3 c4 c6 c7")
    bT1, bT2, b3, b4, F1, F2 = _symbols("bT1 bT2 b3 b4 F1 F2")
    return (RotaryInertia(J0, q1), RotaryInertia(J1, q1 + q2), RotaryInertia(J2, q1 + q2 + q3),
            PointMass(m1, (y1,)), PointMass(m2, (y2,)),
            Spring(cT1, q2), Spring(cT2, q3), Spring(c3, q4), Spring(c4, q5), Spring(c6, y1),
            Spring(c7, y2), Damper(bT1, q2), Damper(bT2, q3), Damper(b3, q4), Damper(b4, q5),
            Load(-F1, y1), Load(-F2, y2))


def processing_machine(kinematic_drive: bool = False) -> Mechanism:
    """Return the processing machine of seed 5.2.3.2 (elastic shaft, two cam mechanisms).

    Coordinates q1 = φ0 (input angle), q2, q3 (shaft twists), q4, q5 (follower
    deformations); φ1 = q1 + q2, φ2 = q1 + q2 + q3, y1 = U1(φ1) + q4, y2 = U2(φ2) + q5.

    2T = J0 q̇1² + J1 φ̇1² + J2 φ̇2² + m1 ẏ1² + m2 ẏ2²                       (eq. 11)
    2V = cT1 q2² + cT2 q3² + c3 q4² + c4 q5² + c6 y1² + c7 y2²                (eq. 16)
    δW = M0 δq1 − F1 δy1 − F2 δy2 − R1 δq2 − … − R4 δq5,  R = b q̇             (eq. 7)

    Parameters
    ----------
    kinematic_drive : bool
        False: 5 DOF, the input torque M0 acts on q1 (eqs. 13–19). True: q1 is the
        drive coordinate (q1 = φ, q̇1 = Ω), leaving the 4 DOF q2…q5 (eqs. 20–23 with
        errata 30–33); M0 is then not a parameter.

    Notes
    -----
    Parameter names: J0, J1, J2, m1, m2, cT1, cT2, c3, c4, c6, c7, bT1, bT2, b3, b4, F1,
    F2 (and M0 for the free drive). Position functions: ``U1``, ``U2``.
    """
    q = _symbols("q1 q2 q3 q4 q5")
    U1, U2 = position_function("U1"), position_function("U2")
    y1, y2 = U1(q[0] + q[1]) + q[3], U2(q[0] + q[1] + q[2]) + q[4]
    elements = _processing_machine_parts(q, y1, y2)
    if kinematic_drive:
        return Mechanism(q, elements, drives=(q[0],), name="processing machine, kinematic drive",
                         labels=coordinate_labels("processing_machine(kinematic_drive=True)"))
    M0 = sympy.Symbol("M0", real=True)
    return Mechanism(q, elements + (Load(M0, q[0]),), name="processing machine",
                     labels=coordinate_labels("processing_machine()"))


register(MechanismType(
    "processing_machine", processing_machine,
    lambda options: "processing_machine(kinematic_drive=True)"
    if options.get("kinematic_drive") else "processing_machine()",
    ("processing_machine()", "processing_machine(kinematic_drive=True)")))


def processing_machine_mixed() -> Mechanism:
    """Return the processing machine in mixed form: 7 coordinates, 2 constraints.

    Seed 5.2.3.2 eqs. 1–10.

    Redundant coordinates q6 = x1, q7 = x2 with f1 = U1(q1 + q2) − q6 = 0 and
    f2 = U2(q1 + q2 + q3) − q7 = 0 (eq. 5); y1 = q6 + q4, y2 = q7 + q5. The masses are
    constant (eq. 2). Same parameter names as :func:`processing_machine` (with M0).
    """
    q = _symbols("q1 q2 q3 q4 q5 q6 q7")
    U1, U2 = position_function("U1"), position_function("U2")
    y1, y2 = q[5] + q[3], q[6] + q[4]
    M0 = sympy.Symbol("M0", real=True)
    elements = _processing_machine_parts(q[:5], y1, y2) + (Load(M0, q[0]),)
    constraints = (U1(q[0] + q[1]) - q[5], U2(q[0] + q[1] + q[2]) - q[6])
    return Mechanism(q, elements, constraints=constraints, name="processing machine, mixed form",
                     labels=coordinate_labels("processing_machine_mixed()"))


def processing_machine_parameters(kinematic_drive: bool = True) -> dict[str, float]:
    """Return illustrative parameter values (SI) for :func:`processing_machine`.

    The chapter gives no numbers. These describe a light two-cam drive: shaft inertias
    J1 = J2 = 2e-3 kg·m², shaft stiffnesses 2e4 N·m/rad, follower masses 3 kg and 2 kg on
    follower elasticities 1e6 N/m and 6e5 N/m, return springs 5e3 N/m, about 2 % damping
    of the follower modes.
    """
    values = dict(J0=0.5, J1=2e-3, J2=2e-3, m1=3.0, m2=2.0, cT1=2e4, cT2=2e4, c3=1e6, c4=6e5,
                  c6=5e3, c7=5e3, bT1=0.2, bT2=0.2, b3=70.0, b4=70.0, F1=0.0, F2=0.0)
    if not kinematic_drive:
        values["M0"] = 0.0
    return values


def processing_machine_cams() -> dict[str, CamProfile]:
    """Return illustrative cam programmes U1, U2 for :func:`processing_machine` (lift m, rad).

    The chapter gives none. U1: modified-sine rise of 50 mm over 100°, dwell 80°, return,
    dwell. U2: 3-4-5 rise of 40 mm over 90°, dwell 70°, return 90°, dwell 110°, starting
    at 40°.
    """
    d = np.deg2rad
    u1 = CamProfile((CamSegment(d(100), 0.05, modified_sine()), CamSegment(d(80)),
                     CamSegment(d(100), -0.05, modified_sine()), CamSegment(d(80))))
    u2 = CamProfile((CamSegment(d(90), 0.04, polynomial_345()), CamSegment(d(70)),
                     CamSegment(d(90), -0.04, polynomial_345()), CamSegment(d(110))),
                    phi_start=d(40))
    return {"U1": u1, "U2": u2}


def mobile_crane() -> Mechanism:
    """Return the mobile crane of seed 5.2.3.1, corrected geometry (errata §A, items 22–26).

    Coordinates q1 (vertical chassis displacement, m), q2 (chassis rotation, rad), q3
    (pendulum angle φ5, rad), q4 = s4 (cylinder length, m; the drive). With
    β = φ3(q4) + q2, φ3 = arccos((q4² − r24² − r34²)/(2 r24 r34)) + γ, β5 = β + α:

        x_S3 = x23 + r_S3 cos β,               y_S3 = q1 + ξ23 q2 + η23 + r_S3 sin β
        x_S5 = x23 + r25 cos β5 − r_S5 sin q3,  y_S5 = q1 + ξ23 q2 + η23 + r25 sin β5 − r_S5 cos q3
        2T = m2 q̇1² + J_S2 q̇2² + m3 |ṙ_S3|² + J_S3 β̇² + m5 |ṙ_S5|² + J_S5 q̇3²   (eq. 1)
        V = ½c(q1 − l1 q2)² + ½c(q1 + l2 q2)² + g(m2 q1 + m3 y_S3 + m5 y_S5)   (eq. 13, errata 24)

    Notes
    -----
    The chassis CG height is measured from its static reference, y_S2 = q1 (plus a
    constant that does not enter the equations). Parameter names: m2, m3, m5, JS2, JS3,
    JS5, x23, xi23, eta23, rS3, rS5, r24, r34, r25, alpha, gamma, c, l1, l2, g.
    """
    q1, q2, q3, q4 = _symbols("q1 q2 q3 q4")
    m2, m3, m5, JS2, JS3, JS5 = _symbols("m2 m3 m5 JS2 JS3 JS5")
    x23, xi23, eta23, rS3, rS5, r24, r34, r25 = _symbols("x23 xi23 eta23 rS3 rS5 r24 r34 r25")
    alpha, gamma, c, l1, l2, g = _symbols("alpha gamma c l1 l2 g")
    phi3 = sympy.acos((q4**2 - r24**2 - r34**2) / (2 * r24 * r34)) + gamma
    beta = phi3 + q2
    beta5 = beta + alpha
    base_y = q1 + xi23 * q2 + eta23
    r3 = (x23 + rS3 * sympy.cos(beta), base_y + rS3 * sympy.sin(beta))
    r5 = (x23 + r25 * sympy.cos(beta5) - rS5 * sympy.sin(q3),
          base_y + r25 * sympy.sin(beta5) - rS5 * sympy.cos(q3))
    elements = (PointMass(m2, (q1,)), RotaryInertia(JS2, q2), PointMass(m3, r3),
                RotaryInertia(JS3, beta), PointMass(m5, r5), RotaryInertia(JS5, q3),
                Spring(c, q1 - l1 * q2), Spring(c, q1 + l2 * q2),
                Potential(g * (m2 * q1 + m3 * r3[1] + m5 * r5[1])))
    return Mechanism((q1, q2, q3, q4), elements, drives=(q4,), name="mobile crane",
                     labels=coordinate_labels("mobile_crane()"))


register(MechanismType("mobile_crane", mobile_crane))


def mobile_crane_parameters() -> dict[str, float]:
    """Return illustrative crane parameters (SI); r24 = 1.5 m, r34 = 4 m as in errata 23."""
    return dict(m2=2.0e4, m3=3.0e3, m5=5.0e3, JS2=8.0e4, JS3=2.5e4, JS5=0.0, x23=-1.0,
                xi23=-1.0, eta23=1.5, rS3=5.0, rS5=8.0, r24=1.5, r34=4.0, r25=12.0,
                alpha=0.05, gamma=0.3, c=1.2e6, l1=2.0, l2=2.5, g=9.81)
