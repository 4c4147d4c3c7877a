"""Rheolinear matrices of Table 5.1 (seed 5.2.2) against the corrected closed forms.

References: errata items 13–18 (C11 with U''², the F·U'' terms, case 1 Q, case 2 Q3, the
reconstructed case 4). Random parameters and angles; the closed forms are evaluated with
the same numeric U, U', U'', U''', so the only difference is round-off.
"""

import numpy as np
import pytest
import sympy

from femmech.mechanisms import FourBar, lagrange_terms, rheolinear, rheolinear_terms
from femmech.mechanisms.chapter import table_5_1_case

EPS = np.finfo(float).eps
N_ANGLES = 40


def _random_parameters(mech, rng):
    """Values in [0.5, 2) for every parameter (all are positive physical constants)."""
    t = lagrange_terms(mech)
    free = (t.mass.free_symbols | t.forces.free_symbols | t.potential.free_symbols)
    names = {s.name for s in free} - {s.name for s in t.coordinates + t.velocities}
    return {n: rng.uniform(0.5, 2.0) for n in sorted(names)}


def _round_off_check(actual, expected):
    """Entries are sums of a few products: allow 100 eps times the largest entry per angle."""
    scale = np.max(np.abs(expected), axis=tuple(range(1, expected.ndim)), keepdims=True)
    err = np.max(np.abs(actual - expected) / scale)
    assert err < 100 * EPS, err
    return err


def _setup(case, seed):
    rng = np.random.default_rng(seed)
    mech = table_5_1_case(case)
    p = _random_parameters(mech, rng)
    funcs = {"U": FourBar(1.0, 3.0, 2.5, 3.2)} if case != 3 else \
        {"U2": FourBar(1.0, 3.0, 2.5, 3.2), "U3": FourBar(1.0, 2.8, 2.0, 2.5, output="coupler")}
    model = rheolinear(mech, p, funcs)
    phi = rng.uniform(0, 2 * np.pi, N_ANGLES)
    Omega = rng.uniform(1.0, 5.0)
    derivs = {k: f.derivatives(phi) for k, f in funcs.items()}
    return model, p, phi, Omega, derivs


@pytest.mark.parametrize("seed", [0, 1])
def test_case_1(seed):
    model, p, phi, W, d = _setup(1, seed)
    _, U1, U2, U3 = d["U"]
    J1, m2, c1, c2, b1, b2, F2 = (p[k] for k in ("J1", "m2", "c1", "c2", "b1", "b2", "F2"))
    z = np.zeros_like(phi)
    # Table 5.1 case 1 (errata 13: U''², errata 14: + F2 U'', errata 15: Q)
    M = np.array([[J1 + m2 * U1**2, m2 * U1], [m2 * U1, m2 + z]])
    B = np.array([[b1 + 2 * m2 * W * U1 * U2, z], [2 * m2 * W * U2, b2 + z]])
    C = np.array([[c1 + m2 * W**2 * (U2**2 + U1 * U3) + F2 * U2, z], [m2 * W**2 * U3, c2 + z]])
    Q = np.array([-F2 * U1 - m2 * W**2 * U1 * U2, -F2 - m2 * W**2 * U2])
    for actual, ref in [(model.M(phi), M), (model.B(phi, W), B), (model.C(phi, W), C)]:
        _round_off_check(actual, np.moveaxis(ref, -1, 0))
    _round_off_check(model.F(phi, W), Q.T)


@pytest.mark.parametrize("seed", [0, 1])
def test_case_2(seed):
    model, p, phi, W, d = _setup(2, seed)
    _, U1, U2, U3 = d["U"]
    J1, m2, m3, c1, c2, c3 = (p[k] for k in ("J1", "m2", "m3", "c1", "c2", "c3"))
    b1, b2, b3, F3 = (p[k] for k in ("b1", "b2", "b3", "F3"))
    z = np.zeros_like(phi)
    m = m2 + m3
    # Table 5.1 case 2 with errata 13 (U''²), 14 (+ F3 U''), 17 (Q3 has U'')
    M = np.array([[J1 + m * U1**2, m2 * U1, m3 * U1], [m2 * U1, m2 + z, z], [m3 * U1, z, m3 + z]])
    B = np.array([[b1 + 2 * m * W * U1 * U2, z, z], [2 * m2 * W * U2, b2 + b3 + z, -b3 + z],
                  [2 * m3 * W * U2, -b3 + z, b3 + z]])
    C = np.array([[c1 + m * W**2 * (U2**2 + U1 * U3) + F3 * U2, z, z],
                  [m2 * W**2 * U3, c2 + c3 + z, -c3 + z], [m3 * W**2 * U3, -c3 + z, c3 + z]])
    Q = np.array([-F3 * U1 - m * W**2 * U1 * U2, -m2 * W**2 * U2, -F3 - m3 * W**2 * U2])
    for actual, ref in [(model.M(phi), M), (model.B(phi, W), B), (model.C(phi, W), C)]:
        _round_off_check(actual, np.moveaxis(ref, -1, 0))
    _round_off_check(model.F(phi, W), Q.T)


@pytest.mark.parametrize("seed", [0, 1])
def test_case_3(seed):
    model, p, phi, W, d = _setup(3, seed)
    _, A1, A2, A3 = d["U2"]
    _, B1, B2, B3 = d["U3"]
    J1, m2, m3, c1, c2, c3 = (p[k] for k in ("J1", "m2", "m3", "c1", "c2", "c3"))
    b1, b2, b3, F2, F3 = (p[k] for k in ("b1", "b2", "b3", "F2", "F3"))
    z = np.zeros_like(phi)
    # Table 5.1 case 3 with errata 13 (U''² per mechanism) and 14 (+ F2 U2'' + F3 U3'')
    M = np.array([[J1 + m2 * A1**2 + m3 * B1**2, m2 * A1, m3 * B1], [m2 * A1, m2 + z, z],
                  [m3 * B1, z, m3 + z]])
    B = np.array([[b1 + 2 * W * (m2 * A1 * A2 + m3 * B1 * B2), z, z],
                  [2 * m2 * W * A2, b2 + z, z], [2 * m3 * W * B2, z, b3 + z]])
    C = np.array([[c1 + m2 * W**2 * (A2**2 + A1 * A3) + m3 * W**2 * (B2**2 + B1 * B3)
                   + F2 * A2 + F3 * B2, z, z],
                  [m2 * W**2 * A3, c2 + z, z], [m3 * W**2 * B3, z, c3 + z]])
    Q = np.array([-F2 * A1 - m2 * W**2 * A1 * A2 - F3 * B1 - m3 * W**2 * B1 * B2,
                  -F2 - m2 * W**2 * A2, -F3 - m3 * W**2 * B2])
    for actual, ref in [(model.M(phi), M), (model.B(phi, W), B), (model.C(phi, W), C)]:
        _round_off_check(actual, np.moveaxis(ref, -1, 0))
    _round_off_check(model.F(phi, W), Q.T)


def test_case_4_reconstruction():
    model, p, phi, W, d = _setup(4, 3)
    _, U1, U2, U3 = d["U"]
    J12, J13, J22, J23 = (p[k] for k in ("J12", "J13", "J22", "J23"))
    c11, c12, c21, c22 = (p[k] for k in ("c11", "c12", "c21", "c22"))
    b11, b12, b21, b22, T2, T3 = (p[k] for k in ("b11", "b12", "b21", "b22", "T2", "T3"))
    e, g = U2**2 + U1 * U3, 2 * W * U1 * U2
    # errata item 18 (reconstructed model of errata §A)
    M = np.array([[J12 + J13 + U1**2 * (J22 + J23), J13 + J23 * U1**2],
                  [J13 + J23 * U1**2, J13 + J23 * U1**2]])
    B = np.array([[b11 + b21 * U1**2 + (J22 + J23) * g, J23 * g],
                  [J23 * g, b12 + b22 * U1**2 + J23 * g]])
    C = np.array([[c11 + c21 * U1**2 + (J22 + J23) * W**2 * e + b21 * W * U1 * U2
                   + (T2 + T3) * U2, J23 * W**2 * e + T3 * U2],
                  [J23 * W**2 * e + T3 * U2,
                   c12 + c22 * U1**2 + J23 * W**2 * e + b22 * W * U1 * U2 + T3 * U2]])
    Q = np.array([-U1 * ((J22 + J23) * W**2 * U2 + T2 + T3), -U1 * (J23 * W**2 * U2 + T3)])
    for actual, ref in [(model.M(phi), M), (model.B(phi, W), B), (model.C(phi, W), C)]:
        _round_off_check(actual, np.moveaxis(ref, -1, 0))
    _round_off_check(model.F(phi, W), Q.T)


@pytest.mark.parametrize("case", [1, 2, 3, 4])
def test_eq_10_equals_direct_linearisation(case):
    # Independent route (errata item 10): the Jacobians of the nonlinear residual of eq. 13,
    # R = M q̈ + ½ m_klj q̇_k q̇_l + W_pot,j − Q*, with respect to q̈, q̇, q of the vibration
    # coordinates on the rigid motion give M, B, C, and F = −R there. Exact (sympy).
    mech = table_5_1_case(case)
    lt, rt = lagrange_terms(mech), rheolinear_terms(mech)
    q, qd = lt.coordinates, lt.velocities
    qdd = sympy.symbols(f"a0:{len(q)}")
    R = lt.mass * sympy.Matrix(qdd) + lt.velocity_terms() + lt.gradient - lt.forces
    e = [q.index(x) for x in rt.coordinates]
    i_d = q.index(rt.drives[0])
    rigid = {q[i]: 0 for i in e} | {qd[i]: 0 for i in e} | {qdd[i]: 0 for i in e}
    rigid |= {q[i_d]: rt.angle[0], qd[i_d]: rt.speed[0], qdd[i_d]: rt.acceleration[0]}
    Re = R.extract(e, [0])
    for mine, wrt in [(rt.M, [qdd[i] for i in e]), (rt.B, [qd[i] for i in e]),
                      (rt.C, [q[i] for i in e])]:
        assert sympy.expand(Re.jacobian(wrt).xreplace(rigid) - mine) == sympy.zeros(*mine.shape)
    assert sympy.expand(-Re.xreplace(rigid) - rt.F) == sympy.zeros(*rt.F.shape)


def test_unsymmetric_C_is_returned_as_is():
    model, _, phi, W, _ = _setup(1, 5)
    C = model.C(phi, W)
    # C21 = m2 Ω² U''' (Table 5.1) while C12 = 0: C is not symmetric
    assert np.max(np.abs(C[:, 1, 0] - C[:, 0, 1])) > 0.1
