"""Mobile crane of seed 5.2.3.1 (corrected geometry, errata §A and items 22–25).

References: the generalized masses m_jk of errata §A (closed forms), the Hessian of the
kinetic energy eq. 1 with respect to the velocities (eq. 6), and the equations of motion
(14)–(17) with the corrected velocity terms of errata item 25 and gravity of item 24.
"""

import numpy as np
import pytest
import sympy
from numpy.testing import assert_allclose

from femmech.mechanisms import mobile_crane, mobile_crane_parameters, second_kind

EPS = np.finfo(float).eps
S = sympy.symbols
q1, q2, q3, q4 = S("q1 q2 q3 q4", real=True)
NAMES = "m2 m3 m5 JS2 JS3 JS5 x23 xi23 eta23 rS3 rS5 r24 r34 r25 alpha gamma c l1 l2 g"
P = dict(zip(NAMES.split(), S(NAMES, real=True), strict=True))


def _geometry():
    p = P
    phi3 = sympy.acos((q4**2 - p["r24"]**2 - p["r34"]**2) / (2 * p["r24"] * p["r34"])) \
        + p["gamma"]
    b = phi3 + q2
    b5 = b + p["alpha"]
    # errata 23: φ3,4 = −2 q4 / √(4 r24² r34² − (q4² − r24² − r34²)²)
    d34 = -2 * q4 / sympy.sqrt(4 * p["r24"]**2 * p["r34"]**2
                               - (q4**2 - p["r24"]**2 - p["r34"]**2)**2)
    return b, b5, d34


def _errata_mass_matrix():
    """m_jk of errata §A (checked there against the Hessian of T)."""
    b, b5, d = _geometry()
    m2, m3, m5, JS2, JS3, JS5 = (P[k] for k in "m2 m3 m5 JS2 JS3 JS5".split())
    xi, rS3, rS5, r25 = P["xi23"], P["rS3"], P["rS5"], P["r25"]
    cos, sin = sympy.cos, sympy.sin
    m11 = m2 + m3 + m5
    m12 = m3 * (xi + rS3 * cos(b)) + m5 * (xi + r25 * cos(b5))
    m13 = m5 * rS5 * sin(q3)
    m14 = d * (m3 * rS3 * cos(b) + m5 * r25 * cos(b5))
    m22 = JS2 + JS3 + m3 * (rS3**2 + xi**2 + 2 * xi * rS3 * cos(b)) \
        + m5 * (r25**2 + xi**2 + 2 * xi * r25 * cos(b5))
    m23 = m5 * rS5 * (r25 * sin(b5 + q3) + xi * sin(q3))
    m24 = d * (JS3 + m3 * (rS3**2 + xi * rS3 * cos(b)) + m5 * (r25**2 + xi * r25 * cos(b5)))
    m33 = JS5 + m5 * rS5**2
    m34 = d * m5 * rS5 * r25 * sin(b5 + q3)
    m44 = d**2 * (JS3 + m3 * rS3**2 + m5 * r25**2)
    return sympy.Matrix([[m11, m12, m13, m14], [m12, m22, m23, m24], [m13, m23, m33, m34],
                         [m14, m24, m34, m44]])


def _hessian_of_T():
    """m_jk = ∂²T/∂q̇_j∂q̇_k with T from eq. 1 and the positions (2)–(6) (errata 22)."""
    b, b5, _ = _geometry()
    qd = S("v1:5", real=True)
    t = sympy.Symbol("t")
    path = {q: sympy.Function(f"Q{i}")(t) for i, q in enumerate((q1, q2, q3, q4))}
    xS3 = P["x23"] + P["rS3"] * sympy.cos(b)
    yS3 = q1 + P["xi23"] * q2 + P["eta23"] + P["rS3"] * sympy.sin(b)
    xS5 = P["x23"] + P["r25"] * sympy.cos(b5) - P["rS5"] * sympy.sin(q3)
    yS5 = q1 + P["xi23"] * q2 + P["eta23"] + P["r25"] * sympy.sin(b5) - P["rS5"] * sympy.cos(q3)

    def rate(x):
        d = sympy.diff(x.xreplace(path), t)
        back = {sympy.diff(f, t): v for f, v in zip(path.values(), qd, strict=True)}
        return d.xreplace(back).xreplace({f: q for q, f in path.items()})

    T = (P["m2"] * qd[0]**2 + P["JS2"] * qd[1]**2 + P["m3"] * (rate(xS3)**2 + rate(yS3)**2)
         + P["JS3"] * rate(b)**2 + P["m5"] * (rate(xS5)**2 + rate(yS5)**2)
         + P["JS5"] * qd[2]**2) / 2
    return sympy.hessian(T, qd), yS3, yS5


def _random_case(seed):
    rng = np.random.default_rng(seed)
    base = mobile_crane_parameters()
    p = {k: v * rng.uniform(0.8, 1.25) for k, v in base.items()}
    p["r24"], p["r34"] = 1.5, 4.0  # errata 23 example geometry; q4 in (2.5, 5.5) m
    q = np.column_stack([rng.uniform(-0.05, 0.05, 8), rng.uniform(-0.02, 0.02, 8),
                         rng.uniform(-0.3, 0.3, 8), rng.uniform(3.0, 5.0, 8)])
    qd = rng.uniform(-0.3, 0.3, (8, 4))
    return p, q, qd


def _numeric(expr, p):
    args = (q1, q2, q3, q4) + tuple(P.values())
    fn = sympy.lambdify(args, expr, modules="numpy")
    return lambda q: np.array(fn(*q, *(p[k] for k in P)), dtype=float)


@pytest.fixture(scope="module")
def references():
    return _errata_mass_matrix(), _hessian_of_T()


def test_mass_matrix_errata_A_and_hessian_of_T(references):
    m_errata, (m_hessian, _, _) = references
    p, q, _ = _random_case(0)
    model = second_kind(mobile_crane(), p)
    M = model.M(q)
    f_err, f_hes = _numeric(m_errata, p), _numeric(m_hessian, p)
    for i in range(q.shape[0]):
        scale = np.max(np.abs(M[i]))
        # sums of a few products of O(1e4) terms: round-off 100 eps relative to max |m_jk|
        assert_allclose(M[i], f_err(q[i]), rtol=0, atol=100 * EPS * scale)
        assert_allclose(M[i], f_hes(q[i]), rtol=0, atol=100 * EPS * scale)


def _corrected_eom(m, yS3, yS5):
    """Left-hand sides minus right-hand sides of eqs. (14)–(16) and Q4 of (17), as
    corrected by errata items 24 and 25, with accelerations a1..a4 and rates v1..v4."""
    a, v = S("a1:5", real=True), S("v1:5", real=True)
    c, l1, l2, g = P["c"], P["l1"], P["l2"], P["g"]
    m2, m3, m5 = P["m2"], P["m3"], P["m5"]
    dm = {}

    def d(j, k, l):  # m_jk,l (1-based indices)
        key = (j, k, l)
        if key not in dm:
            dm[key] = sympy.diff(m[j - 1, k - 1], (q1, q2, q3, q4)[l - 1])
        return dm[key]

    def mq(j):
        return sum(m[j - 1, k] * a[k] for k in range(4))

    e14 = (mq(1) + d(1, 2, 2) * v[1]**2 + (d(1, 4, 2) + d(1, 2, 4)) * v[1] * v[3]
           + d(1, 3, 3) * v[2]**2 + d(1, 4, 4) * v[3]**2 + 2 * c * q1 + c * (l2 - l1) * q2
           + (m2 + m3 + m5) * g)
    e15 = (mq(2) + d(2, 2, 2) * v[1]**2 / 2 + d(2, 2, 4) * v[1] * v[3] + d(2, 3, 3) * v[2]**2
           + (2 * d(2, 4, 4) - d(4, 4, 2)) * v[3]**2 / 2 + c * (l2 - l1) * q1
           + c * (l1**2 + l2**2) * q2 + m3 * g * sympy.diff(yS3, q2)
           + m5 * g * sympy.diff(yS5, q2))
    e16 = (mq(3) + d(2, 3, 2) * v[1]**2 + (d(2, 3, 4) + d(3, 4, 2) - d(2, 4, 3)) * v[1] * v[3]
           + d(3, 4, 4) * v[3]**2 + m5 * g * sympy.diff(yS5, q3))
    Q4 = (mq(4) + (2 * d(2, 4, 2) - d(2, 2, 4)) * v[1]**2 / 2 + d(3, 4, 3) * v[2]**2
          + d(4, 4, 4) * v[3]**2 / 2 + m3 * g * sympy.diff(yS3, q4)
          + m5 * g * sympy.diff(yS5, q4))
    return sympy.Matrix([e14, e15, e16, Q4]), a, v


def test_equations_of_motion_errata_25(references):
    m_errata, (_, yS3, yS5) = references
    eqs, a, v = _corrected_eom(m_errata, yS3, yS5)
    args = (q1, q2, q3, q4) + tuple(a) + tuple(v) + tuple(P.values())
    fn = sympy.lambdify(args, eqs, modules="numpy")
    p, q, qd = _random_case(1)
    model = second_kind(mobile_crane(), p)
    drive_acc = np.random.default_rng(2).uniform(-0.2, 0.2, (q.shape[0], 1))
    res = model.accelerations(q, qd, drive_accelerations=drive_acc)
    for i in range(q.shape[0]):
        r = np.array(fn(*q[i], *res.qdd[i], *qd[i], *(p[k] for k in P)), float).ravel()
        # rows (14)–(16) vanish; row (17) is the cylinder force. Terms are up to ~1e6 N
        # (weights, tyre forces): round-off 1e3 eps relative to the largest weight term
        scale = p["g"] * (p["m2"] + p["m3"] + p["m5"]) * 10
        assert_allclose(r[:3], 0.0, atol=1e3 * EPS * scale)
        assert_allclose(r[3], res.drive_forces[i, 0], rtol=0, atol=1e3 * EPS * scale)


def test_rheolinear_crane_matrices_are_finite_inside_the_stroke():
    # the cylinder triangle closes for r34 − r24 < q4 < r34 + r24 (errata 23, 26)
    from femmech.mechanisms import rheolinear

    model = rheolinear(mobile_crane(), mobile_crane_parameters())
    s4 = np.linspace(2.6, 5.4, 15)
    M, C = model.M(s4), model.C(s4, 0.1, 0.0)
    assert np.all(np.isfinite(M))
    assert np.all(np.isfinite(C))
    assert np.all(np.linalg.eigvalsh(M) > 0)
