"""MITC6 shell triangles (triangle6, :mod:`femmech.fe.elements.shell6`): element
properties, patch tests, locking, convergence rate and plates against references.

Frequency parameters ``λ = ω a² sqrt(ρ t / D)``, ``D = E t³ / (12 (1 - ν²))``; the
references (Mindlin's exact simply supported plate, the Kirchhoff Ritz solver, Leissa's
values) come from ``test_shell_verification.py`` with their sources. Measured errors
quoted in the comments are those of the element as committed (t = 1 mm on a 1 m square,
a/t = 1000, unless stated).
"""

import meshio
import numpy as np
import pytest
import scipy.linalg as sl
from models import NU, RHO, STEEL, E, mindlin_ssss, ritz_kirchhoff, slope
from numpy.testing import assert_allclose

import femmech as fm
from femmech.fe.elements import shell6
from femmech.fe.elements.shell6 import POINTS, WEIGHTS, shell6_matrices

T = 0.02
EPS = np.finfo(float).eps
ROT = sl.qr(np.random.default_rng(3).normal(size=(3, 3)))[0]
_CORNERS = np.array([[0.0, 0, 0], [1.2, 0.1, 0], [0.3, 0.9, 0]])
_MID = 0.5 * (_CORNERS + np.roll(_CORNERS, -1, axis=0))  # edges 0-1, 1-2, 2-0
ELEMENTS = {
    "straight": np.vstack([_CORNERS, _MID]),
    # mid-side nodes moved in the plane: curved (isoparametric) edges
    "curved": np.vstack([_CORNERS, _MID + [[0.03, -0.05, 0], [0.04, 0.03, 0], [-0.05, 0.02, 0]]]),
    # mid-side nodes off the corner plane: faceted with rigid offsets
    "warped": np.vstack([_CORNERS, _MID + [[0, 0, 0.04], [0, 0, -0.03], [0, 0, 0.05]]]),
    "slender": np.vstack([[[0.0, 0, 0], [2.0, 0, 0], [1.7, 0.3, 0]],
                          [[1.0, 0, 0], [1.85, 0.15, 0], [0.85, 0.15, 0]]]),
}
PAIRS = [(1, 1), (1, 2), (2, 1), (2, 2), (1, 3), (3, 1), (2, 3), (3, 2), (1, 4), (4, 1)]
"""(m, n) of the first ten modes of the simply supported square (λ = π² (m² + n²))."""


def plate6(n, a=1.0, diagonal="alternate"):
    """[0, a]² as n x n squares, each cut into two triangle6 along a diagonal ("/", "\\\\"
    or "alternate": the direction alternates like a chessboard); group "plate"."""
    m = 2 * n + 1
    X, Y = np.meshgrid(np.linspace(0, a, m), np.linspace(0, a, m))
    points = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    g = np.arange(m * m).reshape(m, m)  # g[row (y), column (x)]
    r, c = (2 * v.ravel() for v in np.meshgrid(np.arange(n), np.arange(n), indexing="ij"))
    p00, p10, p11, p01 = g[r, c], g[r, c + 2], g[r + 2, c + 2], g[r + 2, c]
    bottom, right, top, left, centre = (g[r, c + 1], g[r + 1, c + 2], g[r + 2, c + 1],
                                        g[r + 1, c], g[r + 1, c + 1])
    if diagonal == "alternate":
        flip = ((r // 2 + c // 2) % 2).astype(bool)
    else:
        flip = np.full(len(r), diagonal == "\\")
    slash = [np.column_stack([p00, p10, p11, bottom, right, centre]),
             np.column_stack([p00, p11, p01, centre, top, left])]
    back = [np.column_stack([p00, p10, p01, bottom, centre, left]),
            np.column_stack([p10, p11, p01, right, top, centre])]
    cells = np.vstack([np.where(flip[:, None], b, s) for s, b in zip(slash, back, strict=True)])
    return fm.Mesh(points, {"triangle6": cells}, {"plate": {"triangle6": np.arange(len(cells))}})


def frequency_parameters(mesh, t, supports, n_modes, a=1.0):
    model = fm.build_model(mesh, shells={"plate": fm.ShellProperty(t, STEEL)},
                           supports=supports)
    D = E * t**3 / (12 * (1 - NU**2))
    return 2 * np.pi * fm.modes(model, n_modes=n_modes).freq_hz * a**2 * np.sqrt(RHO * t / D)


def ssss(n, t, diagonal="alternate", n_modes=4):
    """Hard simply supported unit square (w and the tangential rotation fixed on the
    edges, the condition of Mindlin's Navier solution); in-plane DOFs fixed."""
    mesh = plate6(n, diagonal=diagonal)
    x, y = mesh.points[:, 0], mesh.points[:, 1]
    edge_x = np.flatnonzero(np.isclose(x, 0) | np.isclose(x, 1))
    edge_y = np.flatnonzero(np.isclose(y, 0) | np.isclose(y, 1))
    supports = [fm.Support(np.arange(mesh.n_nodes), ["ux", "uy", "rz"]),
                fm.Support(edge_x, ["uz", "rx"]), fm.Support(edge_y, ["uz", "ry"])]
    return frequency_parameters(mesh, t, supports, n_modes)


def mindlin(t, n_modes=4):
    return np.array([mindlin_ssss(m, k, t) for m, k in PAIRS[:n_modes]])


def _element(name, rotate=True):
    X = ELEMENTS[name] @ ROT.T if rotate else ELEMENTS[name]
    K, M = shell6_matrices(X, np.arange(6)[None, :], E, NU, RHO, T)
    return X, K[0], M[0]


def _rigid_modes(X):
    """(6 n, 6): three translations, three rotations about the origin."""
    R = np.zeros((len(X), 6, 6))
    R[:, :3, :3] = np.eye(3)
    for i in range(3):
        R[:, :3, 3 + i] = np.cross(np.eye(3)[i], X)
        R[:, 3 + i, 3 + i] = 1.0
    return R.reshape(-1, 6)


def _assemble(points, cells):
    K, _ = shell6_matrices(points, cells, E, NU, RHO, T)
    n = 6 * len(points)
    Kg = np.zeros((n, n))
    dofs = (6 * cells[:, :, None] + np.arange(6)).reshape(len(cells), -1)
    for d, k in zip(dofs, K, strict=True):
        Kg[np.ix_(d, d)] += k
    return Kg


def test_quadrature_rule_is_exact_to_degree_four():
    # ∫ r^i s^j over the unit triangle = i! j! / (i + j + 2)!
    from math import factorial
    for i in range(5):
        for j in range(5 - i):
            exact = factorial(i) * factorial(j) / factorial(i + j + 2)
            # bound: the quadrature rule is exact to degree 4: ~10 eps of O(1) sums
            assert abs(WEIGHTS @ (POINTS[:, 0]**i * POINTS[:, 1]**j) - exact) < 1e-14


@pytest.mark.parametrize("name", ELEMENTS)
def test_symmetric_semidefinite_with_exactly_six_rigid_zero_modes(name):
    X, K, M = _element(name)
    assert_allclose(K, K.T, atol=1e3 * EPS * abs(K).max())  # round-off of O(1e2) sums
    assert np.linalg.eigvalsh(M).min() > 0
    lam, vec = np.linalg.eigh(K)
    scale = lam[-1]
    # bound: rigid eigenvalues of eigh: eps·scale (round-off); the 7th is > 1e-8 scale
    assert np.sum(lam < 1e-12 * scale) == 6, lam[:8] / scale
    # smallest elastic eigenvalue (bending, t/L = 0.02: ~(t/L)² of membrane ones, 3e-6
    # measured) far above round-off
    assert lam[6] > 1e-8 * scale
    rigid = _rigid_modes(X)
    # bound: rigid motions: K r = 0 in exact arithmetic, ~n eps·scale·|r|
    assert np.abs(K @ rigid).max() < 1e-12 * scale * np.abs(rigid).max()
    assert sl.subspace_angles(vec[:, :6], rigid).max() < 1e-6


@pytest.mark.parametrize("name", ["straight", "slender"])
def test_mass_and_rotary_inertia(name):
    X, _, M = _element(name)
    A = 0.5 * np.linalg.norm(np.cross(X[1] - X[0], X[2] - X[0]))
    rigid = _rigid_modes(X)
    for i in range(3):  # ρ t A per translation; the degree-4 rule is exact for N_i N_j
        # bound: consistent mass integrated exactly (degree-4 rule): ~n eps
        assert_allclose(rigid[:, i] @ M @ rigid[:, i], RHO * T * A, rtol=1e-12)
        e = np.zeros((6, 6))
        e[:, 3 + i] = 1.0
        # bound: consistent mass integrated exactly (degree-4 rule): ~n eps
        assert_allclose(e.ravel() @ M @ e.ravel(), RHO * T**3 / 12 * A, rtol=1e-12)


@pytest.mark.parametrize("name", ELEMENTS)
def test_invariant_to_global_rotation_and_node_numbering(name):
    """Spatial isotropy in Lee & Bathe's sense: the same element whichever corner is
    numbered first, in any orientation."""
    X = ELEMENTS[name]
    cells = np.arange(6)[None, :]
    K, M = shell6_matrices(X, cells, E, NU, RHO, T)
    Q = np.kron(np.eye(12), ROT)
    Kr, Mr = shell6_matrices(X @ ROT.T, cells, E, NU, RHO, T)
    atol = 1e-12 * abs(K).max()
    assert_allclose(Kr[0], Q @ K[0] @ Q.T, atol=atol)
    # bound: rotated element: Q M Qᵀ = M(X Qᵀ) exactly, round-off ~n eps of the largest entry
    assert_allclose(Mr[0], Q @ M[0] @ Q.T, atol=1e-12 * abs(M).max())
    for shift in ([1, 2, 0, 4, 5, 3], [2, 0, 1, 5, 3, 4]):
        Kp, _ = shell6_matrices(X, np.array([shift]), E, NU, RHO, T)
        dofs = (6 * np.array(shift)[:, None] + np.arange(6)).ravel()
        assert_allclose(Kp[0], K[0][np.ix_(dofs, dofs)], atol=atol)


def _patch(curved):
    """Distorted patch of 8 triangle6 (4 quads cut along diagonals); (points, cells,
    interior node ids). Edges straight, or with mid-side nodes moved (curved)."""
    corners = np.array([[0.0, 0, 0], [2, 0, 0], [2, 3, 0], [0, 2, 0], [0.4, 0.4, 0],
                        [1.4, 0.3, 0], [1.6, 2.0, 0], [0.3, 1.6, 0]])
    tri = np.array([[0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6],
                    [3, 0, 4], [3, 4, 7], [4, 5, 6], [4, 6, 7]])
    edges = {}
    points = list(corners)
    cells = []
    for a, b, c in tri:
        mids = []
        for i, j in ((a, b), (b, c), (c, a)):
            key = (min(i, j), max(i, j))
            if key not in edges:
                edges[key] = len(points)
                points.append(0.5 * (corners[i] + corners[j]))
            mids.append(edges[key])
        cells.append([a, b, c, *mids])
    points = np.array(points)
    if curved:  # move every interior-edge mid-side node in the plane
        rng = np.random.default_rng(5)
        for (i, j), k in edges.items():
            if i >= 4 or j >= 4:
                points[k, :2] += rng.uniform(-0.06, 0.06, 2)
    cells = np.array(cells)
    boundary = set(range(4)) | {k for (i, j), k in edges.items() if i < 4 and j < 4}
    inner = np.array(sorted(set(range(len(points))) - boundary))
    return points, cells, inner


def _solve_patch(points, cells, inner, u):
    """Interior DOFs from the boundary values of u (n_nodes, 6)."""
    K = _assemble(points, cells)
    idof = (6 * inner[:, None] + np.arange(6)).ravel()
    odof = np.setdiff1d(np.arange(K.shape[0]), idof)
    u = u.ravel()
    return np.linalg.solve(K[np.ix_(idof, idof)], -K[np.ix_(idof, odof)] @ u[odof]), u[idof]


@pytest.mark.parametrize("curved", [False, True])
def test_membrane_patch_test(curved):
    """A linear in-plane field u = B x with θz = ω on the boundary gives the same field
    inside (constant strain; the quadratic isoparametric map reproduces linear fields
    also with curved edges)."""
    points, cells, inner = _patch(curved)
    B = np.array([[1e-3, 2e-3], [-0.5e-3, 3e-3]])
    u = np.zeros((len(points), 6))
    u[:, :2] = points[:, :2] @ B.T
    u[:, 5] = 0.5 * (B[1, 0] - B[0, 1])
    solved, exact = _solve_patch(points, cells, inner, u)
    # bound: patch test: exact in the element, static solve eps·cond(K) of a small patch
    assert_allclose(solved, exact, atol=1e-12)


def test_bending_patch_test():
    """Constant curvature w = ½ (a x² + b y² + c xy) with the Kirchhoff rotations
    θx = w,y, θy = -w,x (zero shear, constant moments: an equilibrium state) on the
    boundary of the straight-sided patch: the interior reproduces it exactly, because
    the assumed shear space contains the gradients of quadratic w."""
    points, cells, inner = _patch(curved=False)
    x, y = points[:, 0], points[:, 1]
    a, b, c = 2e-3, -1e-3, 1.5e-3
    u = np.zeros((len(points), 6))
    u[:, 2] = 0.5 * (a * x**2 + b * y**2 + c * x * y)
    u[:, 3] = b * y + 0.5 * c * x
    u[:, 4] = -(a * x + 0.5 * c * y)
    solved, exact = _solve_patch(points, cells, inner, u)
    # bound: patch test: exact in the element, static solve eps·cond(K) of a small patch
    assert_allclose(solved, exact, atol=1e-11 * np.abs(u).max())


@pytest.mark.parametrize("name", ["straight", "curved", "slender"])
def test_constant_curvature_and_shear_energies(name, monkeypatch):
    """Energy of single flat elements in states the element must represent: constant
    shear ``½ k G t |γ|² A`` (w = g·x, θ = 0; the constants lie in the assumed shear
    space) exactly without the rotation bubble, and below it with the bubble (its
    condensation relaxes the state); constant curvature ``½ κᵀ D_b κ A`` exactly."""
    X, K, _ = _element(name, rotate=False)
    _, xy, _ = shell6.frames6(X, np.arange(6)[None, :])
    _, _, _, wdet = shell6.quadrature(xy)
    A = wdet.sum()
    x, y = X[:, 0], X[:, 1]
    g = np.array([4e-4, -3e-4])
    u = np.zeros((6, 6))
    u[:, 2] = g[0] * x + g[1] * y
    exact = 0.5 * 5 / 6 * E / (2 * (1 + NU)) * T * (g @ g) * A
    assert 0.5 * u.ravel() @ K @ u.ravel() < exact
    monkeypatch.setattr(shell6, "BUBBLE", False)
    K0 = shell6_matrices(X, np.arange(6)[None, :], E, NU, RHO, T)[0][0]
    # bound: strain energy of an exact field: ~n eps·cond of the element
    assert_allclose(0.5 * u.ravel() @ K0 @ u.ravel(), exact, rtol=1e-10)
    if name == "curved":  # quadratic w is not a quadratic function of (r, s) there
        return
    a, b, c = 2e-3, -1e-3, 1.5e-3
    u = np.zeros((6, 6))
    u[:, 2] = 0.5 * (a * x**2 + b * y**2 + c * x * y)
    u[:, 3] = b * y + 0.5 * c * x
    u[:, 4] = -(a * x + 0.5 * c * y)
    kappa = -np.array([a, b, c])  # κx = θy,x, κy = -θx,y, κxy = θy,y - θx,x
    Db = E * T**3 / (12 * (1 - NU**2)) * np.array([[1, NU, 0], [NU, 1, 0], [0, 0, (1 - NU) / 2]])
    # round-off: the shear terms, (L/t)² ~ 1e4 times the bending ones, cancel
    assert_allclose(0.5 * u.ravel() @ K @ u.ravel(), 0.5 * kappa @ Db @ kappa * A, rtol=1e-8)


def test_element_errors_name_the_element():
    X = ELEMENTS["straight"]
    with pytest.raises(ValueError, match=r"\(n, 6\)"):
        shell6_matrices(X, np.arange(3)[None, :], E, NU, RHO, T)
    with pytest.raises(ValueError, match="triangle6 element 1 is inverted"):
        # the second element has its mid-side nodes of edges 0-1 and 1-2 swapped
        shell6_matrices(X, np.array([[0, 1, 2, 3, 4, 5], [0, 1, 2, 4, 3, 5]]), E, NU, RHO, T)
    line = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [0.5, 0, 0], [1.5, 0, 0], [1, 0, 0]])
    with pytest.raises(ValueError, match="triangle6 shell element 0 .* zero area"):
        shell6_matrices(line, np.arange(6)[None, :], E, NU, RHO, T)


@pytest.mark.parametrize("diagonal", ["alternate", "/"])
def test_no_shear_locking_from_span_over_thickness_10_to_10000(diagonal):
    """λ₁ of the simply supported square on 8 x 8 squares against Mindlin's exact value
    for a/t = 10 … 10⁴ (tends to Kirchhoff's 2π², Leissa 1969 eq. 4.20). Measured
    errors: alternating diagonals 0.020 %, 0.028 %, 0.029 %, 0.029 %; one-way diagonals
    0.021 %, 0.036 %, 0.044 %, 0.044 %. A locking element's error would grow with a/t
    (without the rotation bubble, one-way diagonals: 0.70 % at 10³, 0.85 % at 10⁴)."""
    errs = np.array([ssss(8, t, diagonal, 1)[0] / mindlin(t, 1)[0] - 1
                     for t in (0.1, 0.01, 0.001, 0.0001)])
    assert np.all(errs > 0), errs  # stiff, from above
    assert errs.max() < 6e-4, errs  # the discretisation error of a/t = 10, times 3 at most
    assert errs[-1] < 1.05 * errs[-2], errs  # saturates: 10⁴ no worse than 10³
    assert abs(mindlin(1e-4, 1)[0] / (2 * np.pi**2) - 1) < 1e-6


@pytest.mark.slow
def test_first_ten_frequencies_converge_at_fourth_order():
    """Log-log fit of the errors of the first ten frequencies of the thin simply
    supported square (a/t = 1000) on 8, 16, 32 squares: measured slopes 3.66-3.91
    (alternating diagonals; 3.36-3.75 one way), O(h⁴) being the ideal for quadratic
    elements. Errors (max over the ten): 0.91 %, 0.080 %, 0.0057 % at 1734, 6534,
    25350 DOFs."""
    t = 0.001
    ref = mindlin(t, 10)
    hs, errs = [], []
    for n in (8, 16, 32):
        errs.append(ssss(n, t, n_modes=10) / ref - 1)
        hs.append(1.0 / n)
    errs = np.array(errs)
    assert np.all(errs > 0)
    slopes = np.array([slope(hs, errs[:, k]) for k in range(10)])
    assert np.all(slopes > 3.5), slopes
    assert errs[1].max() < 1e-3, errs.max(axis=1)
    assert errs[2].max() < 1e-4, errs.max(axis=1)


def test_isotropic_to_the_diagonal_direction():
    """Results do not depend on how the squares are cut: one-way "/" and "\\\\" meshes
    give identical frequencies (mirror images), and they differ from the alternating
    mesh by less than the discretisation error (16 x 16, measured: λ errors 2.0e-5 …
    2.9e-4 alternating, 3.5e-5 … 4.3e-4 one way). The degenerate pair (1, 2)/(2, 1),
    split by the one-way mesh, is split by less than its error."""
    t = 0.001
    ref = mindlin(t)
    slash, back, alt = (ssss(16, t, d) for d in ("/", "\\", "alternate"))
    # bound: the mirror meshes number their DOFs differently, so only round-off separates
    # them. ARPACK (eigsh tol 0: Ritz values to eps) adds ~eps; the factorisation's error
    # on this thin-plate pencil is eps·cond₂(D(K + λ₁M)D) = 2.2e-16 · 2.9e7 = 6.4e-9 in λ
    # (roundoff.scaled_condition), 3.2e-9 in f, x10 -> 3e-8 (measured 1.5e-9 for mode 1)
    assert_allclose(slash, back, rtol=3e-8)
    err_slash, err_alt = slash / ref - 1, alt / ref - 1
    assert np.all(np.abs(slash / alt - 1) < np.maximum(err_slash, err_alt)), (err_slash, err_alt)
    assert abs(slash[2] / slash[1] - 1) < 2 * err_slash[2]
    assert np.all(err_slash < 5e-4)


def test_clamped_square_plate():
    """λ₁ = 35.985 (Leissa 1969 table 4.23; the Ritz solver gives 35.98519). Measured
    errors at 4/8/16 squares: 1.74 %, 0.23 %, 0.015 % (slope 3.9 between 8 and 16;
    MITC4 quads: 1.02 % at 16, test_shell_verification)."""
    ritz = ritz_kirchhoff(12, clamped=True)[0]
    errs = []
    for n in (8, 16):
        mesh = plate6(n)
        x, y = mesh.points[:, 0], mesh.points[:, 1]
        edge = np.flatnonzero(np.isclose(x, 0) | np.isclose(x, 1) | np.isclose(y, 0)
                              | np.isclose(y, 1))
        supports = [fm.Support(np.arange(mesh.n_nodes), ["ux", "uy", "rz"]),
                    fm.Support(edge, "all")]
        errs.append(frequency_parameters(mesh, 0.001, supports, 1)[0] / ritz - 1)
    assert 0 < errs[0] < 0.003, errs
    assert 0 < errs[1] < 2.5e-4, errs
    assert slope([1 / 8, 1 / 16], errs) > 3.5


def test_thick_plate_against_mindlin():
    """a/t = 10: Mindlin's λ (3.4 % below Kirchhoff for mode 1) on 8 x 8 squares within
    0.1 % for four modes (measured 0.020 %, 0.097 %, 0.097 %, 0.27 % for mode (2, 2):
    that one within 0.3 %)."""
    t = 0.1
    lam = ssss(8, t)
    assert_allclose(lam[:3], mindlin(t)[:3], rtol=1e-3)
    assert_allclose(lam[3], mindlin(t)[3], rtol=3e-3)
    assert lam[0] < 2 * np.pi**2 * (1 - 0.03)


def test_free_plate_nafems_fv12_via_meshio_file(tmp_path):
    """NAFEMS FV12 free 10 m plate, t = 0.05 m (test_shell_verification: converged
    Kirchhoff values from the Ritz solver; Leissa 1969 table 4.70). The triangle6 mesh is
    written by meshio and read back by femmech. Measured errors on 8 x 8 squares:
    -0.022 % … +0.088 %; six rigid modes."""
    a, t = 10.0, 0.05
    mesh = plate6(8, a=a)
    path = tmp_path / "plate.vtu"
    meshio.write(path, meshio.Mesh(mesh.points, [("triangle6", mesh.cells["triangle6"])]))
    read = fm.read_mesh(path)
    assert set(read.cells) == {"triangle6"}
    cells = read.cells["triangle6"]
    mesh = fm.Mesh(read.points, {"triangle6": cells},
                   {"plate": {"triangle6": np.arange(len(cells))}})
    model = fm.build_model(mesh, shells={"plate": fm.ShellProperty(t, STEEL)})
    assert model.n_dof == 6 * 17 * 17
    res = fm.modes(model, n_modes=12)
    assert res.rigid[:6].all()
    assert not res.rigid[6:].any()
    D = E * t**3 / (12 * (1 - NU**2))
    to_hz = np.sqrt(D / (RHO * t)) / (2 * np.pi * a**2)
    kirchhoff = ritz_kirchhoff(12, clamped=False)[3:9] * to_hz
    assert_allclose(res.freq_hz[6:12], kirchhoff, rtol=1.5e-3)


@pytest.mark.slow
def test_variants_measured_in_the_docstring(monkeypatch):
    """The two variants the module docstring rejects, measured on the simply supported
    square (a/t = 1000, λ₁ on 8 and 16 squares): centroid tying without bubble is too
    flexible and O(h²); means without bubble lock on one-way diagonals."""
    t = 0.001
    ref = mindlin(t, 1)[0]
    monkeypatch.setattr(shell6, "BUBBLE", False)
    monkeypatch.setattr(shell6, "INTERIOR", "centroid")
    errs = [ssss(n, t, n_modes=1)[0] / ref - 1 for n in (8, 16)]  # -0.20 %, -0.059 %
    assert errs[0] < -1.5e-3
    assert errs[1] < -4e-4
    assert slope([1 / 8, 1 / 16], np.abs(errs)) < 2.2
    monkeypatch.setattr(shell6, "INTERIOR", "mean")
    err = ssss(16, 1e-4, "/", n_modes=1)[0] / mindlin(1e-4, 1)[0] - 1  # +0.19 %
    assert err > 1e-3
