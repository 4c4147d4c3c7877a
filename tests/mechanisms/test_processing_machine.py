"""Processing machine of seed 5.2.3.2 against the chapter's corrected closed forms.

References: eqs. 13, 15, 18, 19 (5-DOF 2nd-kind form), eqs. 20, 21, 23 with errata items
29–33 (4-DOF form with kinematic drive), eq. 8 (multipliers) and errata item 5 (mixed
and 2nd-kind accelerations agree). Random parameters, states and angles; the closed
forms use the same numeric U, U', U'', U''', so differences are round-off only.
"""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from femmech.mechanisms import (
    CamProfile,
    CamSegment,
    FourBar,
    mixed_type,
    modified_sine,
    processing_machine,
    processing_machine_mixed,
    rheolinear,
    second_kind,
)

EPS = np.finfo(float).eps
NAMES = ("J0 J1 J2 m1 m2 cT1 cT2 c3 c4 c6 c7 bT1 bT2 b3 b4 F1 F2 M0").split()


def _functions():
    d = np.deg2rad
    cam = CamProfile((CamSegment(d(120), 0.3, modified_sine()), CamSegment(d(60)),
                      CamSegment(d(120), -0.3, modified_sine()), CamSegment(d(60))))
    return {"U1": FourBar(1.0, 3.0, 2.5, 3.2), "U2": cam}


def _parameters(rng, kinematic):
    p = {n: rng.uniform(0.5, 2.0) for n in NAMES}
    if kinematic:
        del p["M0"]
    return p


def _rel_err(actual, expected):
    """Max deviation relative to the largest entry of each matrix or vector."""
    axes = tuple(range(1, expected.ndim))
    scale = np.max(np.abs(expected), axis=axes, keepdims=True)
    return np.max(np.abs(actual - expected) / scale)


# Entries are sums of at most ~8 products of O(1) numbers: round-off below 100 eps.
TOL = 100 * EPS


@pytest.fixture(scope="module")
def free_model():
    rng = np.random.default_rng(11)
    p = _parameters(rng, kinematic=False)
    return second_kind(processing_machine(), p, _functions()), p


def test_mass_matrix_eq_13_and_m11j_eq_15(free_model):
    model, p = free_model
    rng = np.random.default_rng(1)
    q = rng.uniform(-1, 1, (30, 5)) * [3.0, 0.1, 0.1, 0.01, 0.01]
    f = _functions()
    _, A1, A2, _ = f["U1"].derivatives(q[:, 0] + q[:, 1])
    _, B1, B2, _ = f["U2"].derivatives(q[:, 0] + q[:, 1] + q[:, 2])
    J0, J1, J2, m1, m2 = (p[k] for k in ("J0", "J1", "J2", "m1", "m2"))
    m11 = J0 + J1 + J2 + m1 * A1**2 + m2 * B1**2  # eq. 14
    a, b = m11 - J0, J2 + m2 * B1**2
    z = np.zeros_like(m11)
    M = np.array([[m11, a, b, m1 * A1, m2 * B1], [a, a, b, m1 * A1, m2 * B1],
                  [b, b, b, z, m2 * B1], [m1 * A1, m1 * A1, z, m1 + z, z],
                  [m2 * B1, m2 * B1, m2 * B1, z, m2 + z]])  # eq. 13
    assert _rel_err(model.M(q), np.moveaxis(M, -1, 0)) < TOL
    # eq. 15: m_11j, j = 1..5
    m11j = np.array([2 * (m1 * A1 * A2 + m2 * B1 * B2), 2 * (m1 * A1 * A2 + m2 * B1 * B2),
                     2 * m2 * B1 * B2, 2 * m1 * A2, 2 * m2 * B2]).T
    assert _rel_err(model.christoffel(q)[:, 0, 0, :], m11j) < TOL


def test_stiffness_eq_18_19(free_model):
    model, p = free_model
    rng = np.random.default_rng(2)
    q = rng.uniform(-1, 1, (30, 5)) * [3.0, 0.1, 0.1, 0.0, 0.0]  # Hessian at q4 = q5 = 0
    f = _functions()
    A0, A1, A2, _ = f["U1"].derivatives(q[:, 0] + q[:, 1])
    B0, B1, B2, _ = f["U2"].derivatives(q[:, 0] + q[:, 1] + q[:, 2])
    cT1, cT2, c3, c4, c6, c7 = (p[k] for k in ("cT1", "cT2", "c3", "c4", "c6", "c7"))
    c11 = c6 * (A0 * A2 + A1**2) + c7 * (B0 * B2 + B1**2)  # eq. 18, = c12
    c13 = c7 * (B0 * B2 + B1**2)  # eq. 18, = c23
    z = np.zeros_like(c11)
    C = np.array([[c11, c11, c13, c6 * A1, c7 * B1],
                  [c11, c11 + cT1, c13, c6 * A1, c7 * B1],
                  [c13, c13, c13 + cT2, z, c7 * B1],
                  [c6 * A1, c6 * A1, z, c3 + c6 + z, z],
                  [c7 * B1, c7 * B1, c7 * B1, z, c4 + c7 + z]])  # eq. 19
    assert _rel_err(model.stiffness(q), np.moveaxis(C, -1, 0)) < TOL


@pytest.fixture(scope="module")
def kinematic_case():
    rng = np.random.default_rng(21)
    p = _parameters(rng, kinematic=True)
    model = rheolinear(processing_machine(kinematic_drive=True), p, _functions())
    phi = rng.uniform(0, 2 * np.pi, 40)
    f = _functions()
    return model, p, phi, f["U1"].derivatives(phi), f["U2"].derivatives(phi)


def test_kinematic_drive_M_eq_20_and_B_errata_30(kinematic_case):
    model, p, phi, (_, A1, A2, _), (_, B1, B2, _) = kinematic_case
    J1, J2, m1, m2 = (p[k] for k in ("J1", "J2", "m1", "m2"))
    z = np.zeros_like(phi)
    a, b = J1 + J2 + m1 * A1**2 + m2 * B1**2, J2 + m2 * B1**2
    M = np.array([[a, b, m1 * A1, m2 * B1], [b, b, z, m2 * B1], [m1 * A1, z, m1 + z, z],
                  [m2 * B1, m2 * B1, z, m2 + z]])  # eq. 20
    assert _rel_err(model.M(phi), np.moveaxis(M, -1, 0)) < TOL
    s1, s2 = A1 * A2, B1 * B2
    G = np.array([[2 * (m1 * s1 + m2 * s2), 2 * m2 * s2, z, z],
                  [2 * m2 * s2, 2 * m2 * s2, z, z], [2 * m1 * A2, z, z, z],
                  [2 * m2 * B2, 2 * m2 * B2, z, z]])  # errata 30
    W = 3.7
    B = np.moveaxis(W * G, -1, 0) + np.diag([p["bT1"], p["bT2"], p["b3"], p["b4"]])
    assert _rel_err(model.B(phi, W), B) < TOL


def test_kinematic_drive_C_eq_21_plus_errata_30(kinematic_case):
    model, p, phi, (A0, A1, A2, A3), (B0, B1, B2, B3) = kinematic_case
    m1, m2, F1, F2 = (p[k] for k in ("m1", "m2", "F1", "F2"))
    cT1, cT2, c3, c4, c6, c7 = (p[k] for k in ("cT1", "cT2", "c3", "c4", "c6", "c7"))
    z = np.zeros_like(phi)
    c11 = c6 * (A0 * A2 + A1**2) + c7 * (B0 * B2 + B1**2)
    c13 = c7 * (B0 * B2 + B1**2)
    C21 = np.array([[c11 + cT1, c13, c6 * A1, c7 * B1], [c13, c13 + cT2, z, c7 * B1],
                    [c6 * A1, z, c3 + c6 + z, z], [c7 * B1, c7 * B1, z, c4 + c7 + z]])  # eq. 21
    e1, e2, s1, s2 = A2**2 + A1 * A3, B2**2 + B1 * B3, A1 * A2, B1 * B2
    K_W = np.array([[m1 * e1 + m2 * e2, m2 * e2, z, z], [m2 * e2, m2 * e2, z, z],
                    [m1 * A3, z, z, z], [m2 * B3, m2 * B3, z, z]])  # errata 30
    K_a = np.array([[2 * (m1 * s1 + m2 * s2), 2 * m2 * s2, z, z],
                    [2 * m2 * s2, 2 * m2 * s2, z, z], [m1 * A2, z, z, z],
                    [m2 * B2, m2 * B2, z, z]])  # errata 30
    C_F = np.array([[F1 * A2 + F2 * B2, F2 * B2, z, z], [F2 * B2, F2 * B2, z, z],
                    [z, z, z, z], [z, z, z, z]])  # errata 30/33
    for W, Wd in [(0.0, 0.0), (2.5, 0.0), (2.5, -1.3)]:
        ref = np.moveaxis(C21 + Wd * K_a + W**2 * K_W + C_F, -1, 0)
        assert _rel_err(model.C(phi, W, Wd), ref) < TOL


def test_kinematic_drive_F_eq_23_corrected(kinematic_case):
    model, p, phi, (A0, A1, A2, _), (B0, B1, B2, _) = kinematic_case
    J1, J2, m1, m2, c6, c7, F1, F2 = (p[k] for k in "J1 J2 m1 m2 c6 c7 F1 F2".split())
    W, Wd = 2.1, 0.7
    # eq. 23 with errata 31 (−(m11 − J0) q̈1), 32 (sign of m2 U2'U2'' q̇1²), 33 (process forces)
    F = np.array([
        -(J1 + J2 + m1 * A1**2 + m2 * B1**2) * Wd - (m1 * A1 * A2 + m2 * B1 * B2) * W**2
        - c6 * A0 * A1 - c7 * B0 * B1 - F1 * A1 - F2 * B1,
        -(J2 + m2 * B1**2) * Wd - m2 * B1 * B2 * W**2 - c7 * B0 * B1 - F2 * B1,
        -m1 * A1 * Wd - m1 * A2 * W**2 - c6 * A0 - F1,
        -m2 * B1 * Wd - m2 * B2 * W**2 - c7 * B0 - F2]).T
    assert _rel_err(model.F(phi, W, Wd), F) < TOL


def _consistent_states(rng, n):
    """Random 5-coordinate states and the redundant q6, q7 and rates from eqs. 9–10."""
    f = _functions()
    q = rng.uniform(-1, 1, (n, 5)) * [3.0, 0.2, 0.2, 0.05, 0.05]
    qd = rng.uniform(-1, 1, (n, 5)) * [5.0, 0.5, 0.5, 0.2, 0.2]
    p1, p2 = q[:, 0] + q[:, 1], q[:, 0] + q[:, 1] + q[:, 2]
    w1, w2 = qd[:, 0] + qd[:, 1], qd[:, 0] + qd[:, 1] + qd[:, 2]
    U1, U2 = f["U1"].derivatives(p1), f["U2"].derivatives(p2)
    q7 = np.column_stack([q, U1[0], U2[0]])
    qd7 = np.column_stack([qd, U1[1] * w1, U2[1] * w2])
    return q, qd, q7, qd7, U1, U2


def test_mixed_form_equals_second_kind_and_multipliers_eq_8():
    rng = np.random.default_rng(31)
    p = _parameters(rng, kinematic=False)
    funcs = _functions()
    lag = second_kind(processing_machine(), p, funcs)
    mixed = mixed_type(processing_machine_mixed(), p, funcs)
    q, qd, q7, qd7, U1, U2 = _consistent_states(rng, 12)
    acc = lag.accelerations(q, qd).qdd
    for i in range(q.shape[0]):
        sol = mixed.solve(q7[i], qd7[i])
        assert_allclose(sol.A, sol.A.T, rtol=0, atol=0)  # A is exactly symmetric (eq. 25)
        # errata item 5: accelerations agree to ~1e-14; cond(A) ~ 25 for these states, so
        # allow cond * size * eps ~ 1e3 eps relative to the largest acceleration
        scale = np.max(np.abs(acc[i]))
        assert_allclose(sol.qdd[:5], acc[i], rtol=0, atol=1e3 * EPS * scale)
        a = acc[i]
        # eq. 9/10: q̈6 = U1''(q̇1+q̇2)² + U1'(q̈1+q̈2), q̈7 likewise
        w1, w2 = qd[i, 0] + qd[i, 1], qd[i, 0] + qd[i, 1] + qd[i, 2]
        q6dd = U1[2][i] * w1**2 + U1[1][i] * (a[0] + a[1])
        q7dd = U2[2][i] * w2**2 + U2[1][i] * (a[0] + a[1] + a[2])
        assert_allclose(sol.qdd[5:], [q6dd, q7dd], rtol=0, atol=1e3 * EPS * scale)
        # eq. 8: λ1 = m1(q̈4 + q̈6) + c6(q4 + q6) + F1, λ2 = m2(q̈5 + q̈7) + c7(q5 + q7) + F2
        lam1 = p["m1"] * (a[3] + q6dd) + p["c6"] * (q[i, 3] + q7[i, 5]) + p["F1"]
        lam2 = p["m2"] * (a[4] + q7dd) + p["c7"] * (q[i, 4] + q7[i, 6]) + p["F2"]
        lam_scale = np.max(np.abs([lam1, lam2]))
        assert_allclose(sol.multipliers, [lam1, lam2], rtol=0, atol=1e3 * EPS * lam_scale)


def test_kinematic_drive_torque_from_second_kind():
    # With q1 prescribed, equation j = 1 gives the drive torque (5.2.3.2, text after eq. 10).
    # Reference: row 1 of eq. 13 solved for M0 with the free (5-DOF) model.
    rng = np.random.default_rng(41)
    p = _parameters(rng, kinematic=False)
    funcs = _functions()
    free = second_kind(processing_machine(), p, funcs)
    kin_p = {k: v for k, v in p.items() if k != "M0"}
    driven = second_kind(processing_machine(kinematic_drive=True), kin_p, funcs)
    q = rng.uniform(-1, 1, 5) * [3.0, 0.2, 0.2, 0.05, 0.05]
    qd = rng.uniform(-1, 1, 5)
    res = driven.accelerations(q, qd, drive_accelerations=[0.4])
    M = free.M(q)
    rhs = free.Q(q, qd) - free.gradient(q) - free.velocity_terms(q, qd)
    rhs[0] -= p["M0"]  # Q*_1 without the input torque M0
    torque = M[0] @ res.qdd - rhs[0]
    assert_allclose(res.drive_forces, [torque], rtol=1e3 * EPS)
    # the remaining rows of eq. 13 are satisfied by the computed accelerations
    full_rhs = rhs.copy()
    full_rhs[0] += torque
    assert_allclose(M @ res.qdd, full_rhs, rtol=0, atol=1e3 * EPS * np.max(np.abs(full_rhs)))
