"""MITC9 9-node shell quadrilateral (femmech.fe.elements.shell9) and quad8 meshes.

References: the exact Mindlin frequencies of the simply supported square plate
(``mindlin_ssss``, Mindlin 1951; tends to Leissa's Kirchhoff closed form
``λ = π² (m² + n²)``, NASA SP-160 (1969)) and the Kirchhoff Rayleigh-Ritz solution of
the clamped plate (``ritz_kirchhoff``), both from tests/test_shell_verification.py.
Frequency parameters ``λ = ω a² sqrt(ρ t / D)``.
"""

from functools import partial

import numpy as np
import pytest
import scipy.linalg as sl
from models import NU, RHO, STEEL, E, ritz_kirchhoff, ss_reference, ssss_plate
from numpy.testing import assert_allclose

import femmech as fm
from femmech.fe.dofs import element_dofs
from femmech.fe.elements import registry
from femmech.fe.elements.registry import ELEMENTS
from femmech.fe.elements.shell9 import NODES, shell9_matrices
from femmech.fe.generators import box, rectangular_plate
from femmech.fe.mesh import quad8_to_quad9


def _bilinear(corners, natural):
    xi, eta = natural[:, 0], natural[:, 1]
    N = 0.25 * np.stack([(1 - xi) * (1 - eta), (1 + xi) * (1 - eta), (1 + xi) * (1 + eta),
                         (1 - xi) * (1 + eta)], axis=1)
    return N @ corners


def _element(warp=0.0, curved=True):
    """One distorted quad9 (trapezoid-like corners, moved edge and centre nodes)."""
    corners = np.array([[0, 0, 0], [2.0, 0.2, 0], [2.3, 1.9, 0], [-0.2, 1.5, 0]])
    X = _bilinear(corners, NODES)
    if curved:
        X[4] += [0.05, 0.08, 0]
        X[8] += [0.1, -0.05, 0]
    X[:, 2] += warp * np.array([1, -1, 1, -1, 0.3, 0, -0.2, 0.1, 0.4])
    return X


def _rigid_modes(X):
    """Six rigid-body vectors (54, 6) about the origin, DOFs ux uy uz rx ry rz."""
    R = np.zeros((len(X), 6, 6))
    for a in range(3):
        R[:, a, a] = 1.0
        R[:, 3 + a, 3 + a] = 1.0
        R[:, :3, 3 + a] = np.cross(np.eye(3)[a], X)  # u = θ × x
    return R.reshape(6 * len(X), 6)


@pytest.mark.parametrize("warp", [0.0, 0.1])
def test_six_zero_energy_modes_which_are_rigid(warp):
    X = _element(warp)
    K, M = shell9_matrices(X, np.arange(9)[None], E, NU, RHO, 0.05)
    K, M = K[0], M[0]
    # bound: symmetric by construction: ~n eps of the largest entry
    assert_allclose(K, K.T, atol=1e-12 * np.abs(K).max())
    # bound: symmetric by construction: ~n eps of the largest entry
    assert_allclose(M, M.T, atol=1e-12 * np.abs(M).max())
    assert np.linalg.eigvalsh(M).min() > 0
    w = sl.eigh(K, M, eigvals_only=True)
    # bound: six zero eigenvalues (round-off ~1e-6 rad²/s² against the 7th at ~8e4): a 1e-9
    # relative gap to the largest one separates them; the seventh is a true deformation
    assert np.all(np.abs(w[:6]) < 1e-9 * w[-1])
    assert w[6] > 1e-3 * w[8]
    R = _rigid_modes(X)
    # bound: K R = 0 in exact arithmetic; K's entries carry ~eps of their sums: ~n eps ‖K‖, n = 54
    assert np.abs(K @ R).max() < 1e-9 * np.abs(K).max()


def test_mass_is_rho_t_area_and_rotary_inertia():
    X = _element(curved=False)
    t = 0.02
    _, M = shell9_matrices(X, np.arange(9)[None], E, NU, RHO, t)
    area = 0.5 * abs(np.cross(X[2] - X[0], X[3] - X[1])[2])  # flat quadrilateral
    ones = np.zeros((54, 6))
    for c in range(6):
        ones[c::6, c] = 1.0
    total = ones.T @ M[0] @ ones
    # bound: consistent mass integrated exactly: ~n eps
    assert_allclose(np.diag(total), [RHO * t * area] * 3 + [RHO * t**3 / 12 * area] * 3,
                    rtol=1e-12)


def test_invariant_to_global_rotation():
    X = _element(warp=0.05)
    Q = sl.expm(np.cross(np.eye(3), [0.3, -0.7, 0.5]))
    K, M = shell9_matrices(X, np.arange(9)[None], E, NU, RHO, 0.05)
    K2, M2 = shell9_matrices(X @ Q.T, np.arange(9)[None], E, NU, RHO, 0.05)
    T = np.kron(np.eye(18), Q)  # global DOFs rotate with Q (translations and rotations)
    # bound: Tᵀ K T = K exactly; orthogonal T: ~n eps of the largest entry, n = 54
    assert_allclose(T.T @ K2[0] @ T, K[0], atol=1e-9 * np.abs(K).max())
    assert_allclose(T.T @ M2[0] @ T, M[0], atol=1e-9 * np.abs(M).max())


def _patch(curved_inside):
    """2 x 2 patch of distorted quad9 elements, 25 nodes, boundary nodes listed."""
    g = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    corner = np.array([[[0, 0], [1.1, 0], [2, 0]], [[0, 0.9], [0.8, 1.2], [2, 1.1]],
                       [[0, 2], [1.2, 2], [2, 2]]], dtype=float)
    del g
    pts = np.zeros((5, 5, 2))
    for j in range(2):
        for i in range(2):
            c = np.array([corner[j, i], corner[j, i + 1], corner[j + 1, i + 1], corner[j + 1, i]])
            local = _bilinear(np.column_stack([c, np.zeros(4)]), NODES)[:, :2]
            for (a, b), p in zip(((NODES + 1).astype(int)), local, strict=True):
                pts[2 * j + b, 2 * i + a] = p
    if curved_inside:  # interior edge and centre nodes moved: curved inner edges
        pts[2, 1] += [0.05, 0.07]
        pts[1, 1] += [-0.04, 0.06]
        pts[3, 2] += [0.06, 0.03]
    idx = np.arange(25).reshape(5, 5)
    cells = []
    for j in range(2):
        for i in range(2):
            J, Ii = 2 * j, 2 * i
            cells.append([idx[J, Ii], idx[J, Ii + 2], idx[J + 2, Ii + 2], idx[J + 2, Ii],
                          idx[J, Ii + 1], idx[J + 1, Ii + 2], idx[J + 2, Ii + 1],
                          idx[J + 1, Ii], idx[J + 1, Ii + 1]])
    boundary = np.unique(np.concatenate([idx[0], idx[-1], idx[:, 0], idx[:, -1]]))
    return np.column_stack([pts.reshape(25, 2), np.zeros(25)]), np.array(cells), boundary


def _solve_patch(points, cells, boundary, exact):
    """Prescribe ``exact`` (25, 6) on the boundary, solve the interior, return (25, 6)."""
    K = np.zeros((150, 150))
    Ke, _ = shell9_matrices(points, cells, E, NU, RHO, 0.05)
    dofs = element_dofs(cells)
    for e in range(len(cells)):
        K[np.ix_(dofs[e], dofs[e])] += Ke[e]
    fixed = (6 * boundary[:, None] + np.arange(6)).ravel()
    free = np.setdiff1d(np.arange(150), fixed)
    u = exact.ravel().copy()
    u[free] = np.linalg.solve(K[np.ix_(free, free)], -K[np.ix_(free, fixed)] @ u[fixed])
    return u.reshape(25, 6)


@pytest.mark.parametrize("curved_inside", [False, True])
def test_membrane_patch_test_constant_strain(curved_inside):
    # u = a + εx x + ½γ y …: linear fields lie in the isoparametric space for any node
    # positions, so the patch must reproduce them to round-off
    points, cells, boundary = _patch(curved_inside)
    x, y = points[:, 0], points[:, 1]
    exact = np.zeros((25, 6))
    exact[:, 0] = 1e-3 * (1 + 2 * x + 0.5 * y)
    exact[:, 1] = 1e-3 * (-0.5 + 0.3 * x - 1.5 * y)
    exact[:, 5] = 0.5 * (0.3e-3 - 0.5e-3)  # θz = ω = ½ (v,x - u,y): the drilling penalty is 0
    u = _solve_patch(points, cells, boundary, exact)
    # bound: patch test: exact in the element, static solve eps·cond(K) of a small patch
    assert_allclose(u, exact, atol=1e-12)


def test_bending_patch_test_constant_curvature():
    # w = ½ (a x² + b y²) + c x y with θy = -w,x, θx = w,y (no shear): constant curvature
    # and zero shear strain, an exact solution without load; quadratic w lies in the space
    # of straight-sided elements (edge nodes at the midpoints)
    points, cells, boundary = _patch(False)
    x, y = points[:, 0], points[:, 1]
    a, b, c = 2e-3, -1e-3, 0.7e-3
    exact = np.zeros((25, 6))
    exact[:, 2] = 0.5 * (a * x**2 + b * y**2) + c * x * y
    exact[:, 3] = b * y + c * x
    exact[:, 4] = -(a * x + c * y)
    u = _solve_patch(points, cells, boundary, exact)
    # bound: patch test: exact in the element, static solve eps·cond(K) of a small patch
    assert_allclose(u, exact, atol=1e-12)


def _lambda1_errors(distort):
    """|λ₁/λ₁_exact - 1| on 4 x 4 MITC9 for a/t = 10, 100, 1e3, 1e4."""
    errors = []
    for slenderness in (10.0, 100.0, 1e3, 1e4):
        t = 1.0 / slenderness
        errors.append(abs(ssss_plate(4, t, distort, modes=1)[0] / ss_reference(t, 1)[0] - 1))
    return np.array(errors)


@pytest.mark.parametrize("distort", [0.0, 0.3])
def test_no_shear_locking_over_span_to_thickness_10_to_1e4(distort):
    # a locking element stiffens without bound as a/t grows; MITC9 on 4 x 4 elements keeps
    # λ₁ within its discretisation error at every slenderness. Measured (λ₁ vs exact
    # Mindlin, a/t = 10, 100, 1e3, 1e4): regular mesh 6.6e-4, 6.9e-4, 6.9e-4, 6.9e-4;
    # 30 % distorted 1.15e-3, 1.21e-3, 1.21e-3, 1.21e-3 (λ₁ → 19.74 = 2 π², Leissa 1969)
    errors = _lambda1_errors(distort)
    assert errors.max() < 2e-3
    # thin limit: the error no longer depends on t (a locking element's grows as (a/t)^p)
    assert abs(errors[3] - errors[1]) < 0.01 * errors[1]


def test_gauss_line_tying_locks_on_distorted_meshes(monkeypatch):
    # why the default ties the shear on the edges: with the tying lines η = 0, ±√(3/5)
    # the shear constraints of a non-affine element are all interior, and λ₁ locks —
    # measured 1.1e-3, 4.6e-3, 6.0e-2, 0.35 for a/t = 10 … 1e4 on the 30 % distorted mesh
    # (identical to the edge tying on affine meshes: the covariant shear of an affine
    # element is quadratic along the tying lines, so any three points give it exactly)
    gauss = registry.ElementType("quad9", "shell", partial(shell9_matrices, tying="gauss"))
    monkeypatch.setitem(registry.ELEMENTS, "quad9", gauss)
    assert _lambda1_errors(0.0).max() < 1e-3  # regular mesh: no locking (6.9e-4)
    errors = _lambda1_errors(0.3)
    assert errors[3] > 30 * errors[0]


def test_clamped_thin_plate_against_kirchhoff_ritz():
    # clamped square, a/t = 1000: Kirchhoff λ₁ = 35.985, λ₂ = λ₃ = 73.394 (Leissa 1969,
    # table 4.23: 35.99, 73.41), here by the independent Rayleigh-Ritz solver; 8 x 8
    # MITC9 measured 1e-4 / 7e-4 high
    t = 1e-3
    mesh = rectangular_plate(1.0, 1.0, 8, 8, kind="quad9")
    model = fm.build_model(mesh, shells={"plate": fm.ShellProperty(t, STEEL)},
                           supports=[fm.Support(mesh.node_sets["edges"], "all")])
    res = fm.modes(model, n_modes=4)
    D = E * t**3 / (12 * (1 - NU**2))
    lam = 2 * np.pi * res.freq_hz[:3] * np.sqrt(RHO * t / D)
    ref = ritz_kirchhoff(12, clamped=True)[:3]
    assert_allclose(lam, ref, rtol=2e-3)
    assert np.all(lam > ref * (1 - 1e-4))  # from above (Mindlin vs Kirchhoff: ~ -1e-5)


def test_thin_plate_first_ten_frequencies_within_0p1_percent_on_16x16():
    # the accuracy goal; closed form ω_mn = π² (m²/a² + n²/b²) sqrt(D/ρt) (Leissa 1969)
    # with the Mindlin correction (3.1e-5 for mode 10 at a/t = 1000); measured max error 6.8e-4
    t = 1e-3
    lam = ssss_plate(16, t, modes=10)
    kirchhoff = np.sort([np.pi**2 * (m**2 + k**2) for m in range(1, 5) for k in range(1, 5)])
    assert_allclose(ss_reference(t, 10), kirchhoff[:10], rtol=4e-5)  # measured 3.1e-5
    assert np.abs(lam / ss_reference(t, 10) - 1).max() < 1e-3


def test_frequencies_converge_at_fourth_order():
    # thin plate a/t = 1000, n = 2, 4, 8, 16; measured slopes 3.9-4.3 for the first four
    # modes (λ of a p = 2 element: O(h^2p) = O(h⁴))
    t = 1e-3
    ref = ss_reference(t, 4)
    ns = (2, 4, 8, 16)
    errors = np.array([np.abs(ssss_plate(n, t, modes=4) / ref - 1) for n in ns])
    assert np.all(errors > 0)  # stiff from above on these meshes
    for mode in range(4):
        slope = np.polyfit(np.log(1.0 / np.array(ns[1:])), np.log(errors[1:, mode]), 1)[0]
        assert 3.6 < slope < 4.6, (mode, slope)


def test_quad8_mesh_gives_the_quad9_frequencies():
    # the centre node the serendipity map puts at (0, 0) is the quad9 centre of a
    # straight-sided element: both meshes are the same model (up to node numbering)
    t = 1e-2
    lam9 = ssss_plate(4, t, distort=0.3, modes=6)
    lam8 = ssss_plate(4, t, distort=0.3, kind="quad8", modes=6)
    # bound: the same pencil up to node numbering: eps·cond₂(D(K + λ₁M)D) = 8e-12 in λ
    # (roundoff.scaled_condition; eps λ_max/λ_1 = 2.8e-9 is the cruder bound); measured 1.4e-13
    assert_allclose(lam8, lam9, rtol=1e-9)


def test_quad8_to_quad9_places_the_serendipity_centre_and_keeps_groups():
    corners = np.array([[0, 0, 0], [2.0, 0, 0], [2, 1, 0.2], [0, 1, 0]])
    X8 = _bilinear(corners, NODES[:8])
    X8[4] += [0.0, -0.1, 0.0]  # a curved edge
    nine = np.vstack([X8, [9.0, 9.0, 9.0]])
    mesh = fm.Mesh(nine, {"quad8": np.arange(8)[None], "line": np.array([[0, 8]])},
                   {"plate": {"quad8": [0]}, "bar": {"line": [0]}}, {"ends": [0, 8]})
    out = quad8_to_quad9(mesh)
    assert "quad8" not in out.cells
    assert out.cells["quad9"].tolist() == [[0, 1, 2, 3, 4, 5, 6, 7, 9]]
    # serendipity shape functions at (0, 0): -1/4 at the corners, 1/2 at the edge nodes
    centre = 0.5 * X8[4:].sum(axis=0) - 0.25 * X8[:4].sum(axis=0)
    assert_allclose(out.points[9], centre)
    assert_allclose(out.points[9], _bilinear(corners, np.zeros((1, 2)))[0] + [0, -0.05, 0])
    assert out.cell_sets["plate"]["quad9"].tolist() == [0]
    assert out.cell_sets["bar"] == {"line": [0]}
    assert out.node_sets["ends"].tolist() == [0, 8]
    assert quad8_to_quad9(out) is out


def test_quad9_is_registered_as_a_shell():
    assert ELEMENTS["quad9"].family == "shell"


def test_errors_name_the_element():
    X = _element()
    bad = X.copy()
    bad[8] = 0.5 * (X[1] + X[2]) + (X[1] - X[0])  # centre node outside the element
    with pytest.raises(ValueError, match="quad9 element 1 is inverted or too distorted"):
        shell9_matrices(np.vstack([X, bad]), np.array([np.arange(9), np.arange(9) + 9]),
                        E, NU, RHO, 0.01)
    with pytest.raises(ValueError, match="tying must be one of"):
        shell9_matrices(X, np.arange(9)[None], E, NU, RHO, 0.01, tying="nodes")
    with pytest.raises(ValueError, match="shape"):
        shell9_matrices(X, np.arange(8)[None], E, NU, RHO, 0.01)


@pytest.mark.slow
def test_box_against_mitc4_fine_mesh():
    # closed box 1.0 x 0.4 x 0.3 m of 5 mm steel, free: elastic modes 7-16 (folded plates:
    # membrane and bending coupled at the edges). Reference: MITC4 on 80 x 32 x 24 quads
    # per wall direction (63k DOFs), Richardson-extrapolated with 40 x 16 x 12 by the
    # measured h² rate: ref = (4 f_fine - f_coarse) / 3. MITC9 on 40 x 16 x 12 elements
    # (250k DOFs, not run here) agrees with it within 9e-5, which bounds the reference's
    # own error. Measured errors against it: MITC9 20 x 8 x 6 (15.8k DOFs) 0.025-0.079 %,
    # MITC4 at the same DOFs 0.55-1.6 %; MITC9 10 x 4 x 3 (3.9k DOFs) 0.15-0.76 %.
    t = 0.005

    def freqs(kind, k):
        mesh = box(1.0, 0.4, 0.3, 10 * k, 4 * k, 3 * k, kind=kind)
        model = fm.build_model(mesh, shells={"walls": fm.ShellProperty(t, STEEL),
                                             "ends": fm.ShellProperty(t, STEEL)})
        return fm.modes(model, n_modes=16).freq_hz[6:16]

    coarse4 = freqs("quad", 4)
    ref = (4 * freqs("quad", 8) - coarse4) / 3
    err9 = np.abs(freqs("quad9", 2) / ref - 1)
    assert err9.max() < 1.5e-3
    assert err9.max() < 0.2 * np.abs(coarse4 / ref - 1).min()  # same DOFs as coarse4
    assert np.abs(freqs("quad9", 1) / ref - 1).max() < 1e-2
