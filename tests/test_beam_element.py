"""Property tests of the 2-node 3D Timoshenko / Euler-Bernoulli frame element.

Each test builds single elements with :func:`femmech.fe.elements.beam.beam_matrices` in a random
orientation and checks a property that any correct frame element must have: symmetry,
rigid-body null space, mass totals, unit scaling, invariance under rotation, consistency
of the closed-form Timoshenko stiffness with the IIE shape functions, and the
Euler-Bernoulli limit against textbook matrices.

Round-off tolerances are written as a multiple of ``EPS`` (machine epsilon) times the size
of the quantity; the multiple covers the O(10-100) floating-point operations per entry.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
from numpy.testing import assert_allclose, assert_array_less
from roundoff import eigenvalue_rtol, largest_eigenvalue
from scipy.spatial.transform import Rotation

import femmech as fm
from femmech.fe import sections
from femmech.fe.elements.beam import (
    beam_matrices,
    bending_matrices,
    bending_shape_functions,
    local_frames,
    local_matrices,
)

EPS = np.finfo(float).eps
E, NU, RHO = 210e9, 0.3, 7850.0
G = E / (2.0 * (1.0 + NU))

SECTIONS = {
    "rectangle": sections.rectangle(0.03, 0.05),
    "circle": sections.circle(0.04),
    "tube": sections.tube(0.06, 0.05),
    "I": sections.i_section(0.10, 0.055, 0.0041, 0.0057),
    "box": sections.rectangular_hollow(0.08, 0.05, 0.004),
    "general": sections.general(A=2e-3, Iy=3e-6, Iz=1e-6, J=5e-7, Asy=1.5e-3, Asz=1.2e-3,
                                Ip=4.5e-6),
}


def _section_args(section, shear: bool):
    """(A, Iy, Iz, J, Ip, Asy, Asz) of a section; ``shear=False`` gives inf shear areas."""
    asy = section.Asy if (shear and section.Asy is not None) else np.inf
    asz = section.Asz if (shear and section.Asz is not None) else np.inf
    return section.A, section.Iy, section.Iz, section.J, section.polar_moment, asy, asz


def _element(section, shear=True, rotary=True, seed=0, scale=1.0, material=(E, G, RHO)):
    """One element of length ~0.9 m at a random position and orientation.

    Returns (points (2, 3), orientation (3,), K (12, 12), M (12, 12)).
    """
    rng = np.random.default_rng(seed)
    a = rng.uniform(-1.0, 1.0, 3)
    axis = rng.standard_normal(3)
    axis *= 0.9 / np.linalg.norm(axis)
    points = scale * np.array([a, a + axis])
    orientation = rng.standard_normal(3)
    A, Iy, Iz, J, Ip, Asy, Asz = _section_args(section, shear)
    s2, s4 = scale**2, scale**4
    Ke, Me = beam_matrices(points, np.array([[0, 1]]), orientation, *material,
                           A * s2, Iy * s4, Iz * s4, J * s4, Ip * s4, Asy * s2, Asz * s2,
                           rotary_inertia=rotary)
    return points, orientation, Ke[0], Me[0]


def _rigid_body_vectors(points: np.ndarray) -> np.ndarray:
    """Six rigid-body motions (12, 6): unit translations, then unit rotations about the origin.

    For a rotation θ, node displacement ``u = θ × x`` and node rotation ``θ``.
    """
    U = np.zeros((12, 6))
    for k in range(3):
        e = np.eye(3)[k]
        for node in range(2):
            U[6 * node + k, k] = 1.0
            U[6 * node:6 * node + 3, 3 + k] = np.cross(e, points[node])
            U[6 * node + 3 + k, 3 + k] = 1.0
    return U


CASES = [(name, shear) for name in SECTIONS for shear in (True, False)]


@pytest.mark.parametrize(("name", "shear"), CASES)
def test_symmetry(name, shear):
    _, _, K, M = _element(SECTIONS[name], shear=shear, seed=1)
    # round-off of Tᵀ K T with 12-term sums: 100 eps ‖K‖
    assert np.abs(K - K.T).max() <= 100 * EPS * np.abs(K).max()
    assert np.abs(M - M.T).max() <= 100 * EPS * np.abs(M).max()


@pytest.mark.parametrize(("name", "shear"), CASES)
def test_rigid_body_null_space(name, shear):
    points, _, K, _ = _element(SECTIONS[name], shear=shear, seed=2)
    U = _rigid_body_vectors(points)
    norm_k = np.linalg.norm(K, 2)
    # zero strain energy: |uᵀ K u| <= 100 eps ‖K‖ ‖u‖², ‖K u‖ <= 1e3 eps ‖K‖ ‖u‖
    # (coordinates ~1 m, so ‖u‖ ~ 1 and the cancellation error is ~eps ‖K‖ ‖u‖ per sum)
    energy = np.abs(np.einsum("ik,ij,jk->k", U, K, U))
    assert np.all(energy <= 100 * EPS * norm_k * np.sum(U**2, axis=0))
    assert np.all(np.linalg.norm(K @ U, axis=0) <= 1e3 * EPS * norm_k * np.linalg.norm(U, axis=0))
    # exactly six eigenvalues at round-off level: the smallest elastic one (torsion of the
    # bound: thin I section, GJ/L ~ 1e-6 ‖K‖) lies far above 1e-10 ‖K‖, rigid ones ~eps ‖K‖
    lam, V = np.linalg.eigh(0.5 * (K + K.T))
    assert np.all(lam >= -1e3 * EPS * norm_k)
    zero = np.abs(lam) <= 1e-10 * norm_k
    assert zero.sum() == 6
    # the null space is the rigid-body span: eigenvector perturbation theory bounds the
    # principal angles by ~eps ‖K‖ / λ_7 (the gap to the first elastic eigenvalue)
    angles = sla.subspace_angles(V[:, zero], U)
    assert angles.max() <= 100 * EPS * norm_k / lam[~zero].min()


@pytest.mark.parametrize(("name", "shear"), CASES)
@pytest.mark.parametrize("rotary", [True, False])
def test_mass_positive_definite_and_totals(name, shear, rotary):
    section = SECTIONS[name]
    points, _, _, M = _element(section, shear=shear, rotary=rotary, seed=3)
    length = np.linalg.norm(points[1] - points[0])
    lam = np.linalg.eigvalsh(0.5 * (M + M.T))
    # positive definite: smallest eigenvalue well above round-off (1e3 eps ‖M‖)
    assert lam.min() > 1e3 * EPS * lam.max()
    # unit rigid translation in a random direction: uᵀ M u = ρ A L (Przemieniecki 1968,
    # consistent mass reproduces the element mass); round-off 100 eps: a 12-term quadratic
    # form errs by ~2 · 12 eps times its cancellation |u|ᵀ|M||u| / uᵀMu (Higham, Accuracy and
    # Stability of Numerical Algorithms, 2002, §3.1), which is 1 to 5.4 for these elements
    # (measured up to 16 eps)
    direction = np.random.default_rng(4).standard_normal(3)
    direction /= np.linalg.norm(direction)
    u = np.tile(np.r_[direction, 0.0, 0.0, 0.0], 2)
    assert_allclose(u @ M @ u, RHO * section.A * length, rtol=100 * EPS)
    # unit rigid rotation about the element axis (nodes on the axis do not translate):
    # uᵀ M u = ρ Ip L, the torsional inertia of the bar
    R, _ = local_frames(points, np.array([[0, 1]]))
    u = np.tile(np.r_[0.0, 0.0, 0.0, R[0, 0]], 2)
    assert_allclose(u @ M @ u, RHO * section.polar_moment * length, rtol=100 * EPS)


@pytest.mark.parametrize(("name", "shear"), CASES)
@pytest.mark.parametrize("rotary", [True, False])
def test_rigid_rotation_about_transverse_axis(name, shear, rotary):
    """Rotation about local z through the midpoint: ρ A L³/12 + ρ Iz L (rotary part).

    A rigid rotation (linear deflection, constant rotation, zero shear strain) lies in the
    span of the IIE shape functions for any Φ, so the consistent mass integrates its kinetic
    energy exactly.
    """
    section = SECTIONS[name]
    points, orientation, _, M = _element(section, shear=shear, rotary=rotary, seed=5)
    R, length = local_frames(points, np.array([[0, 1]]), orientation)
    ex, ez = R[0, 0], R[0, 2]
    mid = points.mean(axis=0)
    u = np.concatenate([np.r_[np.cross(ez, p - mid), ez] for p in points])
    expected = RHO * section.A * length[0] ** 3 / 12 + rotary * RHO * section.Iz * length[0]
    # round-off 100 eps, as in test_mass_positive_definite_and_totals (measured 8.5 eps)
    assert_allclose(u @ M @ u, expected, rtol=100 * EPS)
    assert abs(ex @ ez) < 10 * EPS


@pytest.mark.parametrize("name", list(SECTIONS))
def test_unit_scaling_per_dof_type(name):
    """Scale all lengths by s: K_tt ∝ s, K_tr ∝ s², K_rr ∝ s³; M_tt ∝ s³, M_tr ∝ s⁴, M_rr ∝ s⁵.

    That is ``K(s) = s D K D`` and ``M(s) = s³ D M D`` with ``D = diag(1, 1, 1, s, s, s)`` per
    node (dimensional analysis of EA/L, EI/L³, GJ/L, ρAL, ρAL³, ρIL).
    """
    s = 7.3
    section = SECTIONS[name]
    _, _, K1, M1 = _element(section, seed=6)
    _, _, Ks, Ms = _element(section, seed=6, scale=s)
    D = np.tile(np.r_[1.0, 1.0, 1.0, s, s, s], 2)
    # round-off: both sides ~100 operations per entry, 1e3 eps relative to the largest entry
    assert_allclose(Ks, s * D[:, None] * K1 * D[None, :], rtol=0,
                    atol=1e3 * EPS * np.abs(Ks).max())
    assert_allclose(Ms, s**3 * D[:, None] * M1 * D[None, :], rtol=0,
                    atol=1e3 * EPS * np.abs(Ms).max())


def _cantilever(length_unit: float, force_unit: float, mass_unit: float):
    """Tube cantilever (10 elements, 60 free DOFs), inputs in the given unit system."""
    stress_unit = force_unit / length_unit**2
    n = 10
    x = np.linspace(0.0, 1.2, n + 1) / length_unit
    mesh = fm.Mesh.from_lines(np.column_stack([x, 0.3 * x, -0.2 * x]),
                              np.column_stack([np.arange(n), np.arange(1, n + 1)]),
                              node_sets={"root": [0]})
    section = sections.tube(0.06 / length_unit, 0.05 / length_unit, nu=NU)
    material = fm.Material(E=E / stress_unit, nu=NU, rho=RHO / (mass_unit / length_unit**3))
    return fm.build_model(mesh, {"all": fm.BeamProperty(section, material)},
                          supports=[fm.Support("root")])


def test_units_m_kg_s_vs_mm_t_s():
    """Frequencies are the same in m-kg-s and mm-t-s (N = t mm/s², MPa, t/mm³)."""
    si = _cantilever(1.0, 1.0, 1.0)
    result = fm.modes(si, n_modes=8)
    f_mm = fm.modes(_cantilever(1e-3, 1.0, 1e3), n_modes=8).freq_hz
    # round-off of the two solves (roundoff.eigenvalue_rtol: femmech's dense path works on
    # the shift-inverted pencil; λ_max / λ_1 = 4.4e5 for this 60-DOF pencil), half that in
    # f: 4.9e-10 for mode 1, 3e-12 for mode 8. Measured 5e-13 .. 8e-13 (mode 1) and
    # 2e-14 .. 6e-14 (mode 8) on SkylakeX and Haswell kernels
    rtol = 0.5 * eigenvalue_rtol(result.omega2, largest_eigenvalue(si.K_free, si.M_free))
    assert_array_less(np.abs(f_mm / result.freq_hz - 1), rtol)


@pytest.mark.parametrize(("name", "shear"), CASES)
def test_invariance_under_rigid_rotation(name, shear):
    section = SECTIONS[name]
    points, orientation, K, M = _element(section, shear=shear, seed=7)
    Q = Rotation.random(random_state=8).as_matrix()
    A, Iy, Iz, J, Ip, Asy, Asz = _section_args(section, shear)
    Kq, Mq = beam_matrices(points @ Q.T, np.array([[0, 1]]), Q @ orientation, E, G, RHO,
                           A, Iy, Iz, J, Ip, Asy, Asz)
    T = np.kron(np.eye(4), Q)
    # matrices transform as K' = T K Tᵀ (round-off 1e3 eps of the largest entry)
    assert_allclose(Kq[0], T @ K @ T.T, rtol=0, atol=1e3 * EPS * np.abs(K).max())
    assert_allclose(Mq[0], T @ M @ T.T, rtol=0, atol=1e3 * EPS * np.abs(M).max())
    # free-element frequencies unchanged: the six elastic eigenvalues of (K, M); relative
    # bound: round-off of eigh ~ eps cond(M) λ_max / λ (≲ 1e-9 here)
    lam = sla.eigh(K, M, eigvals_only=True)[6:]
    lam_q = sla.eigh(Kq[0], Mq[0], eigvals_only=True)[6:]
    assert_allclose(lam_q, lam, rtol=1e-9)


def _polynomial_derivative(values: np.ndarray, xi: np.ndarray, length: float) -> np.ndarray:
    """d/dx of cubic polynomials given by their values at 4 points; values (4, n_fun)."""
    coef = np.polynomial.polynomial.polyfit(xi, values, 3)
    return coef, np.polynomial.polynomial.polyder(coef) / length


@pytest.mark.parametrize("phi", [0.0, 0.05, 0.8, 6.0])
def test_timoshenko_stiffness_equals_iie_energy(phi):
    """Closed-form K (Przemieniecki eq. 5.116) = ∫ EI θ'² + G As (w' − θ)² dx of the IIE fields.

    Derivatives of the cubic/quadratic IIE shape functions are obtained by fitting the
    function values at 4 points (exact interpolation), integrals by 6-point Gauss-Legendre
    (exact for the degree-2 integrand). Also checks the nodal interpolation conditions and
    the homogeneous static Timoshenko equations ``(G As γ)' = 0``, ``EI θ'' + G As γ = 0``
    that define the IIE (Friedman & Kosmatka 1993).
    """
    L, EI = 0.8, 3.0e5
    GAs = np.inf if phi == 0 else 12.0 * EI / (phi * L**2)
    length, p = np.array([L]), np.array([phi])
    xi_fit = np.array([0.0, 0.3, 0.7, 1.0])
    Nw, Nt = bending_shape_functions(xi_fit, length, p)
    cw, dw = _polynomial_derivative(Nw[0], xi_fit, L)
    ct, dt = _polynomial_derivative(Nt[0], xi_fit, L)
    assert_allclose(Nw[0][[0, 3]], [[1, 0, 0, 0], [0, 0, 1, 0]], atol=10 * EPS)
    assert_allclose(Nt[0][[0, 3]], [[0, 1, 0, 0], [0, 0, 0, 1]], atol=10 * EPS)
    gx, gw = np.polynomial.legendre.leggauss(6)
    xq, wq = 0.5 * (gx + 1.0), 0.5 * gw * L
    P = np.polynomial.polynomial
    w_x = P.polyval(xq, dw).T  # (n_q, 4): dw/dx
    theta = P.polyval(xq, ct).T
    theta_x = P.polyval(xq, dt).T
    gamma = w_x - theta
    K_quad = EI * np.einsum("q,qi,qj->ij", wq, theta_x, theta_x)
    K_ref, _ = bending_matrices(length, np.array([EI]), np.array([GAs]), np.ones(1), np.zeros(1))
    scale = np.abs(K_ref[0]).max()
    if phi > 0:
        K_quad += GAs * np.einsum("q,qi,qj->ij", wq, gamma, gamma)
        # IIE definition: constant shear strain and EI θ'' = -G As γ
        theta_xx = P.polyval(xq, P.polyder(dt) / L).T
        # bound: constant shear strain in the IIE element: ~10 eps of its largest value
        assert_allclose(gamma, np.broadcast_to(gamma[:1], gamma.shape), atol=1e-10 * np.abs(
            gamma).max())
        assert_allclose(EI * theta_xx, -GAs * gamma, atol=1e-9 * np.abs(GAs * gamma).max())
    else:
        # bound: θ = w' exactly (Hermite): ~10 eps of w'
        assert np.abs(gamma).max() <= 1e-12 * np.abs(w_x).max()  # θ = w' (Hermite)
    # bound: the polynomial fit amplifies round-off by cond(Vandermonde) ~ 1e2: tolerance 1e-10 ‖K‖
    assert_allclose(K_quad, K_ref[0], rtol=0, atol=1e-10 * scale)


def _hermite_reference(L: float, EI: float, rhoA: float, rhoI: float):
    """Textbook Euler-Bernoulli beam matrices, DOFs (w_a, θ_a, w_b, θ_b), θ = dw/dx.

    Stiffness: Przemieniecki (1968) eq. 5.116 with Φ = 0. Consistent translational mass
    ρAL/420 [...] and rotary-inertia matrix ρI/(30 L) [...]: Przemieniecki (1968), ch. 11
    (consistent mass of a beam element with rotary inertia); also Cook, Malkus & Plesha,
    Concepts and Applications of FEA, 4th ed., ch. 11.
    """
    K = EI / L**3 * np.array([[12, 6 * L, -12, 6 * L],
                              [6 * L, 4 * L**2, -6 * L, 2 * L**2],
                              [-12, -6 * L, 12, -6 * L],
                              [6 * L, 2 * L**2, -6 * L, 4 * L**2]])
    Mt = rhoA * L / 420 * np.array([[156, 22 * L, 54, -13 * L],
                                    [22 * L, 4 * L**2, 13 * L, -3 * L**2],
                                    [54, 13 * L, 156, -22 * L],
                                    [-13 * L, -3 * L**2, -22 * L, 4 * L**2]])
    Mr = rhoI / (30 * L) * np.array([[36, 3 * L, -36, 3 * L],
                                     [3 * L, 4 * L**2, -3 * L, -L**2],
                                     [-36, -3 * L, 36, -3 * L],
                                     [3 * L, -L**2, -3 * L, 4 * L**2]])
    return K, Mt + Mr


def test_euler_bernoulli_limit_matches_hermite_element():
    """Φ → 0 (As → ∞) gives the textbook Hermite element, in both bending planes.

    Local x-z plane DOFs are (w, ry) with ry = -dw/dx, hence the sign change of the rotation
    rows/columns. The distance to the Φ = 0 element shrinks linearly with Φ.
    """
    L, section = 0.7, SECTIONS["general"]
    length = np.array([L])
    args = [np.array([v]) for v in (E, G, RHO, section.A, section.Iy, section.Iz, section.J,
                                    section.polar_moment)]
    K0, M0 = local_matrices(length, *args, np.array([np.inf]), np.array([np.inf]))
    for idx, inertia, sign in (([1, 5, 7, 11], section.Iz, 1.0), ([2, 4, 8, 10], section.Iy, -1.0)):
        S = np.diag([1.0, sign, 1.0, sign])
        Kh, Mh = _hermite_reference(L, E * inertia, RHO * section.A, RHO * inertia)
        sub = np.ix_(idx, idx)
        assert_allclose(K0[0][sub], S @ Kh @ S, rtol=0, atol=100 * EPS * np.abs(Kh).max())
        # the 4-point Gauss rule integrates the degree-6 products exactly: round-off only
        assert_allclose(M0[0][sub], S @ Mh @ S, rtol=0, atol=100 * EPS * np.abs(Mh).max())
    gaps = []
    phis = np.array([1e-2, 1e-4, 1e-6])
    for phi in phis:
        As = 12 * E * section.Iz / (G * phi * L**2)  # Φ of the x-y plane
        K, M = local_matrices(length, *args, np.array([As]), np.array([As]))
        gaps.append(np.abs(K - K0).max() / np.abs(K0).max())
    slope = np.polyfit(np.log(phis), np.log(gaps), 1)[0]
    assert 0.95 < slope < 1.05  # K(Φ) - K(0) = O(Φ): linear in Φ


def test_orientation_parallel_to_axis_raises():
    points = np.array([[0.0, 0, 0], [1, 0, 0], [1, 0, 1], [1, 1, 1]])
    cells = np.array([[0, 1], [1, 2], [2, 3]])
    orientation = np.array([[0.0, 1, 0], [0, 0, 2], [1, 0, 0]])  # element 1 is along z
    with pytest.raises(ValueError, match=r"element 1 .*parallel"):
        local_frames(points, cells, orientation)
    mesh = fm.Mesh.from_lines(points, cells, cell_sets={"a": [0, 2], "b": [1]})
    material = fm.Material(E=E, nu=NU, rho=RHO)
    beams = {"a": fm.BeamProperty(SECTIONS["circle"], material),
             "b": fm.BeamProperty(SECTIONS["circle"], material, orientation=(0, 0, -3))}
    with pytest.raises(ValueError, match=r"element 1 .*parallel"):
        fm.build_model(mesh, beams)
