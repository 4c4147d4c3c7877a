"""Element property tests of the flat shell elements (quad MITC4/QM6, triangle MITC3/CST).

Each test builds single elements with :func:`femmech.fe.elements.shell.shell_matrices` and
checks a property that any correct element has: symmetry, semi-definiteness, exactly
six rigid-body modes, mass and rotary inertia, dimensional scaling, invariance to the
global frame and to the node numbering, the membrane patch test; then the integration
into :func:`femmech.build_model`.
"""

import numpy as np
import pytest
import scipy.linalg as sl
from numpy.testing import assert_allclose

import femmech as fm
from femmech.fe.elements.shell import shell_frames, shell_matrices
from femmech.fe.sections import rectangle

E, NU, RHO, T = 200e9, 0.3, 7800.0, 0.02
EPS = np.finfo(float).eps

ELEMENTS = {
    "square": np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]),
    "distorted": np.array([[0.0, 0, 0], [1.3, 0.2, 0], [1.1, 0.9, 0], [0.2, 1.2, 0]]),
    "warped": np.array([[0.0, 0, 0.04], [1.3, 0.2, -0.04], [1.1, 0.9, 0.04], [0.2, 1.2, -0.04]]),
    "triangle": np.array([[0.0, 0, 0], [1.2, 0.1, 0], [0.3, 0.9, 0]]),
    "slender triangle": np.array([[0.0, 0, 0], [2.0, 0, 0], [1.7, 0.3, 0]]),
}
ROT = sl.qr(np.random.default_rng(3).normal(size=(3, 3)))[0]


def _element(name, rotate=True):
    X = ELEMENTS[name] @ ROT.T if rotate else ELEMENTS[name]
    cells = np.arange(len(X))[None, :]
    K, M = shell_matrices(X, cells, E, NU, RHO, T)
    return X, K[0], M[0]


def _rigid_modes(X):
    """(6 n, 6): three translations, three rotations about the origin."""
    R = np.zeros((len(X), 6, 6))
    R[:, :3, :3] = np.eye(3)
    for i in range(3):
        axis = np.eye(3)[i]
        R[:, :3, 3 + i] = np.cross(axis, X)
        R[:, 3 + i, 3 + i] = 1.0
    return R.reshape(-1, 6)


def _area(X):
    if len(X) == 3:
        return 0.5 * np.linalg.norm(np.cross(X[1] - X[0], X[2] - X[0]))
    _, xy, _ = shell_frames(X, np.arange(4)[None, :])
    x, y = xy[0].T
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


@pytest.mark.parametrize("name", ELEMENTS)
def test_symmetric_and_semidefinite(name):
    _, K, M = _element(name)
    # round-off: products of O(1e2) terms of size |K|
    assert_allclose(K, K.T, atol=1e3 * EPS * abs(K).max())
    assert_allclose(M, M.T, atol=1e3 * EPS * abs(M).max())
    assert np.linalg.eigvalsh(M).min() > 0  # consistent mass with rotary (drilling) inertia


@pytest.mark.parametrize("name", ELEMENTS)
def test_exactly_six_zero_energy_modes_which_are_rigid(name):
    X, K, _ = _element(name)
    # scale DOFs to unit length so that translations and rotations compare
    lam, vec = np.linalg.eigh(K)
    scale = lam[-1]
    # bound: rigid eigenvalues of eigh: eps·scale (round-off); elastic ones > 1e-9 scale
    n_zero = np.sum(lam < 1e-12 * scale)
    assert n_zero == 6, lam[:8] / scale
    # the smallest elastic eigenvalue (drilling/bending, t/L = 0.02) is far above round-off
    # bound: the lowest elastic eigenvalue lies far above eigh's eps·scale round-off
    assert lam[6] > 1e-9 * scale
    rigid = _rigid_modes(X)
    # bound: rigid motions: K r = 0 in exact arithmetic, ~n eps·scale·|r|
    assert np.abs(K @ rigid).max() < 1e-12 * scale * np.abs(rigid).max()
    # the null space equals the span of the rigid-body motions (principal angles ~ 0)
    angles = sl.subspace_angles(vec[:, :6], rigid)
    assert angles.max() < 1e-6


@pytest.mark.parametrize("name", ELEMENTS)
def test_mass_and_rotary_inertia(name):
    X, _, M = _element(name)
    A = _area(X)
    rigid = _rigid_modes(X)
    for i in range(3):  # each rigid translation carries ρ t A (exact quadrature)
        # bound: consistent mass integrated exactly: ~n eps
        assert_allclose(rigid[:, i] @ M @ rigid[:, i], RHO * T * A, rtol=1e-12)
    if name == "warped":  # nodal rotations also move the offset (projected) nodes
        return
    for i in range(3):  # nodal rotations only: ρ t³/12 A about every axis
        e = np.zeros((len(X), 6))
        e[:, 3 + i] = 1.0
        # bound: consistent mass integrated exactly: ~n eps
        assert_allclose(e.ravel() @ M @ e.ravel(), RHO * T**3 / 12 * A, rtol=1e-12)


@pytest.mark.parametrize("name", ELEMENTS)
def test_dimensional_scaling(name):
    """All lengths (coordinates and thickness) times s: K → s D K D, M → s³ D M D,
    D = diag(1, 1, 1, s, s, s) per node (dimensional analysis); K ∝ E, M ∝ ρ."""
    X = ELEMENTS[name]
    cells = np.arange(len(X))[None, :]
    K1, M1 = shell_matrices(X, cells, E, NU, RHO, T)
    s = 3.7
    K2, M2 = shell_matrices(s * X, cells, 2 * E, NU, 5 * RHO, s * T)
    D = np.tile([1, 1, 1, s, s, s], len(X))
    # bound: scaling laws exact in exact arithmetic: ~n eps relative, atol for zeros
    assert_allclose(K2, 2 * s * D[:, None] * K1 * D, rtol=1e-10, atol=1e-12 * abs(K2).max())
    # bound: scaling laws exact in exact arithmetic: ~n eps relative, atol for zeros
    assert_allclose(M2, 5 * s**3 * D[:, None] * M1 * D, rtol=1e-10,
                    atol=1e-12 * abs(M2).max())


@pytest.mark.parametrize("name", ELEMENTS)
def test_invariant_to_global_rotation_and_node_numbering(name):
    X = ELEMENTS[name]
    n = len(X)
    cells = np.arange(n)[None, :]
    K, M = shell_matrices(X, cells, E, NU, RHO, T)
    Q = np.kron(np.eye(2 * n), ROT)
    Kr, Mr = shell_matrices(X @ ROT.T, cells, E, NU, RHO, T)
    atol = 1e-12 * abs(K).max()
    assert_allclose(Kr[0], Q @ K[0] @ Q.T, atol=atol)
    # bound: rotated element: Q M Qᵀ = M(X Qᵀ) exactly, ~n eps of the largest entry
    assert_allclose(Mr[0], Q @ M[0] @ Q.T, atol=1e-12 * abs(M).max())
    # start the cycle at another node: the same element, permuted DOFs
    shift = np.roll(np.arange(n), 1)
    Kp, _ = shell_matrices(X, shift[None, :], E, NU, RHO, T)
    dofs = (6 * shift[:, None] + np.arange(6)).ravel()
    assert_allclose(Kp[0], K[0][np.ix_(dofs, dofs)], atol=atol)


@pytest.mark.parametrize("kind", ["quad", "triangle"])
def test_membrane_patch_test(kind):
    """A linear in-plane field u = B x (+ θz = ω) on the boundary of a distorted patch
    gives the same linear field inside (constant strain patch test; QM6 passes it through
    Taylor's correction of the incompatible modes)."""
    P = np.array([[0.0, 0, 0], [2, 0, 0], [2, 3, 0], [0, 2, 0],
                  [0.4, 0.4, 0], [1.4, 0.3, 0], [1.6, 2.0, 0], [0.3, 1.6, 0]])
    quads = np.array([[0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7], [4, 5, 6, 7]])
    cells = quads if kind == "quad" else np.vstack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    K, _ = shell_matrices(P, cells, E, NU, RHO, T)
    Kg = np.zeros((48, 48))
    dofs = (6 * cells[:, :, None] + np.arange(6)).reshape(len(cells), -1)
    for d, k in zip(dofs, K, strict=True):
        Kg[np.ix_(d, d)] += k
    B = np.array([[1e-3, 2e-3], [-0.5e-3, 3e-3]])
    u = np.zeros((8, 6))
    u[:, :2] = P[:, :2] @ B.T
    u[:, 5] = 0.5 * (B[1, 0] - B[0, 1])
    u = u.ravel()
    inner = (6 * np.arange(4, 8)[:, None] + np.arange(6)).ravel()
    outer = np.setdiff1d(np.arange(48), inner)
    solved = np.linalg.solve(Kg[np.ix_(inner, inner)], -Kg[np.ix_(inner, outer)] @ u[outer])
    # bound: patch test: exact in the element, static solve eps·cond(K) of a small patch
    assert_allclose(solved, u[inner], atol=1e-12)


def _square_mesh(kinds=("quad",)):
    points = [[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0]]
    cells = {"quad": [[0, 1, 2, 3]], "triangle": [[1, 4, 5], [1, 5, 2]], "line": [[0, 1]]}
    sets = {"q": {"quad": [0]}, "t": {"triangle": [0, 1]}, "edge": {"line": [0]}}
    return fm.Mesh(points, {k: cells[k] for k in kinds},
                   {k: v for k, v in sets.items() if next(iter(v)) in kinds})


def test_build_model_assembles_shells_with_beams():
    mesh = _square_mesh(("quad", "triangle", "line"))
    steel = fm.Material(E=E, nu=NU, rho=RHO)
    beam = fm.BeamProperty(rectangle(0.05, 0.05), steel)
    shells = {"q": fm.ShellProperty(0.01, steel), "t": fm.ShellProperty(0.02, steel)}
    model = fm.build_model(mesh, {"edge": beam}, shells=shells)
    # total mass: ρ t A of both shell groups plus ρ A L of the beam
    # bound: consistent mass integrated exactly: ~n eps
    assert_allclose(model.total_mass(), RHO * (0.01 * 1 + 0.02 * 1 + 0.05**2 * 1), rtol=1e-12)
    assert model.shells.cells["quad"].tolist() == [[0, 1, 2, 3]]
    assert model.shells.group["triangle"].tolist() == ["t", "t"]
    assert_allclose(model.shells.thickness["triangle"], [0.02, 0.02])
    lam = np.linalg.eigvalsh(model.K.toarray())
    # bound: rigid eigenvalues of eigh: eps λ_max (roundoff.py)
    assert np.sum(lam < 1e-10 * lam[-1]) == 6  # one free body: beam and shells share nodes
    # without the beam, K is the sum of the element matrices (independent dense scatter)
    model = fm.build_model(_square_mesh(("quad", "triangle")), shells=shells)
    K = np.zeros((36, 36))
    for cells, t in (([[0, 1, 2, 3]], 0.01), ([[1, 4, 5], [1, 5, 2]], 0.02)):
        cells = np.array(cells)
        Ke, _ = shell_matrices(mesh.points, cells, E, NU, RHO, t)
        for c, k in zip(cells, Ke, strict=True):
            d = (6 * c[:, None] + np.arange(6)).ravel()
            K[np.ix_(d, d)] += k
    # bound: assembled sums in another order: ~n eps of the largest entry
    assert_allclose(model.K.toarray(), K, rtol=0, atol=1e-12 * abs(K).max())


@pytest.mark.parametrize(("shells", "match"), [
    (None, r"\['quad', 'triangle'\] cells, which have no element property"),
    ({"q": "plate"}, r"shells\['q'\] must be a ShellProperty, got str"),
    ({"nope": fm.ShellProperty(0.01, fm.Material(E=E, nu=NU, rho=RHO))},
     "shell property for unknown group 'nope'"),
    ({"q": fm.ShellProperty(0.01, fm.Material(E=E, nu=NU, rho=RHO))},
     r"triangle element 0 \(nodes \[1, 4, 5\]\) has no shell property"),
])
def test_build_model_shell_errors_name_the_item(shells, match):
    mesh = _square_mesh(("quad", "triangle"))
    with pytest.raises((ValueError, TypeError), match=match):
        fm.build_model(mesh, shells=shells)


def test_shell_property_validates():
    steel = fm.Material(E=E, nu=NU, rho=RHO)
    with pytest.raises(ValueError, match="thickness must be a positive number"):
        fm.ShellProperty(0.0, steel)
    with pytest.raises(TypeError, match="material must be a Material"):
        fm.ShellProperty(0.01, "steel")
    with pytest.raises(ValueError, match="zero area"):
        shell_matrices(np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]]), np.array([[0, 1, 2]]),
                       E, NU, RHO, T)
