"""Element property tests of the solid elements (tetra, tetra10, hexahedron, hexahedron20,
hexahedron27) and their integration into :func:`femmech.build_model`.

Each single element is the reference element mapped by a distorting polynomial map
``x = F(ξ)`` that its shape functions represent exactly (affine for the tetra, trilinear
for the hexahedron, quadratic for the quadratic types), then rotated. Checks: symmetry,
semi-definiteness, exactly six zero-energy modes (the rigid motions), the constant-strain
patch test, mass ``ρ V`` with ``V = ∫ det DF dξ`` integrated exactly by sympy (an
independent computation), dimensional scaling, and the meshio (VTK) node order.
"""

import numpy as np
import pytest
import scipy.linalg as sl
import sympy
from numpy.testing import assert_allclose

import femmech as fm
from femmech.fe.elements.solid import (
    REFERENCE_NODES,
    SOLID_TYPES,
    assemble_solid,
    reference_element,
    solid_matrices,
)
from femmech.fe.sections import rectangle

E, NU, RHO = 200e9, 0.3, 7800.0
EPS = np.finfo(float).eps
ROT = sl.qr(np.random.default_rng(5).normal(size=(3, 3)))[0]
A = np.array([[1.2, 0.2, -0.1], [0.1, 0.9, 0.15], [-0.05, 0.1, 0.7]])
_XI = sympy.symbols("x y z")


def _map(kind):
    """Distorting map ξ → x as sympy expressions, representable by the element."""
    x, y, z = _XI
    lin = sympy.Matrix(A) * sympy.Matrix(_XI)
    if kind == "tetra":
        extra = sympy.zeros(3, 1)
    elif kind == "hexahedron":
        extra = sympy.Matrix([0.15 * x * y, -0.1 * y * z * x, 0.2 * x * z])
    else:  # complete quadratic: in the span of P2, serendipity and Q2
        extra = sympy.Matrix([0.1 * y**2, 0.12 * x * z, -0.08 * x**2 + 0.05 * y * z])
    return lin + extra


def _volume(kind):
    """Exact volume of the mapped element, ∫ det DF over the reference domain (sympy)."""
    x, y, z = _XI
    det = sympy.expand(_map(kind).jacobian(_XI).det())
    if kind.startswith("tetra"):
        return float(sympy.integrate(det, (z, 0, 1 - x - y), (y, 0, 1 - x), (x, 0, 1)))
    return float(sympy.integrate(det, (x, 0, 1), (y, 0, 1), (z, 0, 1)))


def _element(kind, scale=1.0, rotate=True):
    f = sympy.lambdify(_XI, _map(kind), "numpy")
    ref = REFERENCE_NODES[kind]
    X = np.array([np.ravel(f(*p)) for p in ref]) * scale
    X = X @ ROT.T if rotate else X
    K, M = solid_matrices(X, np.arange(len(X))[None], kind, E, NU, RHO)
    return X, K[0], M[0]


def _rigid_modes(X):
    """(3 n, 6): translations and rotations about the origin."""
    R = np.zeros((len(X), 3, 6))
    R[:, :, :3] = np.eye(3)
    for i in range(3):
        R[:, :, 3 + i] = np.cross(np.eye(3)[i], X)
    return R.reshape(-1, 6)


@pytest.mark.parametrize("kind", SOLID_TYPES)
def test_symmetric_semidefinite_six_rigid_modes(kind):
    X, K, M = _element(kind)
    # round-off: entries are sums of O(n_points k) products, relative eps x 100
    assert_allclose(K, K.T, rtol=0, atol=100 * EPS * abs(K).max())
    assert_allclose(M, M.T, rtol=0, atol=100 * EPS * abs(M).max())
    lam = np.linalg.eigvalsh(K)
    # bound: positive semi-definite K: eigh's round-off eps λ_max (roundoff.py)
    assert lam[0] > -1e-12 * lam[-1]
    # exactly six zero-energy modes: the seventh eigenvalue is far from round-off (the
    # measured gap lam7 / lam_max is > 1e-4 for all five types; a spurious mode would
    # sit at ~1e-16)
    # bound: rigid eigenvalues of eigh: eps λ_max; the 7th is > 1e-4 λ_max
    assert np.all(np.abs(lam[:6]) < 1e-12 * lam[-1])
    assert lam[6] > 1e-5 * lam[-1]
    R = _rigid_modes(X)
    # bound: rigid motions: K R = 0 in exact arithmetic, ~n eps of |K| |X|
    assert_allclose(K @ R, 0.0, atol=1e-11 * abs(K).max() * abs(X).max())
    assert np.linalg.eigvalsh(M)[0] > 0  # consistent mass is positive definite


@pytest.mark.parametrize("kind", SOLID_TYPES)
def test_mass_is_rho_v_on_distorted_element(kind):
    X, _, M = _element(kind)
    V = _volume(kind)  # sympy, exact
    R = _rigid_modes(X)
    # bound: the quadrature integrates det DF exactly for these maps (degree <= 3 in total for
    # the quadratic types, trilinear-squared for Q1): round-off only
    assert_allclose(np.diag(R[:, :3].T @ M @ R[:, :3]), RHO * V, rtol=1e-12)


@pytest.mark.parametrize("kind", SOLID_TYPES)
def test_constant_strain_patch(kind):
    """A linear displacement field u = G x stores ½ V (λ tr(ε)² + 2 μ ε:ε) exactly."""
    X, K, _ = _element(kind)
    G = np.array([[1.0, 0.4, -0.3], [0.2, -0.5, 0.7], [0.1, 0.6, 0.8]]) * 1e-3
    u = (X @ G.T).ravel()
    eps = 0.5 * (G + G.T)
    mu = E / (2 * (1 + NU))
    lam = 2 * mu * NU / (1 - 2 * NU)
    energy = _volume(kind) * (lam * np.trace(eps) ** 2 + 2 * mu * np.sum(eps**2))
    # bound: exact for isoparametric elements (patch test); round-off only
    assert_allclose(u @ K @ u, energy, rtol=1e-11)


@pytest.mark.parametrize("kind", SOLID_TYPES)
def test_scaling_and_frame_invariance(kind):
    _, K1, M1 = _element(kind)
    _, K2, M2 = _element(kind, scale=3.0)
    # K ∝ E L (N/m), M ∝ ρ L³ (kg)
    # bound: scaling laws exact: ~n eps of the largest entry
    assert_allclose(K2, 3.0 * K1, rtol=0, atol=1e-12 * abs(K2).max())
    assert_allclose(M2, 27.0 * M1, rtol=0, atol=1e-12 * abs(M2).max())
    X, K0, _ = _element(kind, rotate=False)
    Q = np.kron(np.eye(len(X)), ROT)  # u_rotated = Q u
    # bound: rotated element: Q K Qᵀ = K(X Qᵀ) exactly, ~n eps of the largest entry
    assert_allclose(Q @ K0 @ Q.T, K1, rtol=0, atol=1e-11 * abs(K1).max())
    Ke, _ = solid_matrices(X, np.arange(len(X))[None], kind, 2 * E, NU, RHO)
    # bound: two identical elements summed: a few eps
    assert_allclose(Ke[0], 2 * K0, rtol=1e-14)


@pytest.mark.parametrize("kind", SOLID_TYPES)
def test_node_order_is_meshio_vtk(kind):
    """Shape function j is 1 at reference node j and 0 at the others, in VTK order.

    VTK node order (vtkQuadraticTetra, vtkQuadraticHexahedron,
    vtkTriQuadraticHexahedron docs), as meshio uses: the mid-edge nodes of tetra10 lie on
    edges (0,1), (1,2), (0,2), (0,3), (1,3), (2,3); those of the quadratic hexahedra on
    (0,1), (1,2), (2,3), (3,0), (4,5), (5,6), (6,7), (7,4), (0,4), (1,5), (2,6), (3,7);
    hexahedron27 adds the faces x=0, x=1, y=0, y=1, z=0, z=1 and the centre.
    """
    ref = REFERENCE_NODES[kind]
    edges = {"tetra10": [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)]}
    hex_edges = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4),
                 (0, 4), (1, 5), (2, 6), (3, 7)]
    edges["hexahedron20"] = edges["hexahedron27"] = hex_edges
    for m, (a, b) in enumerate(edges.get(kind, [])):
        k = (4 if kind == "tetra10" else 8) + m
        assert_allclose(ref[k], (ref[a] + ref[b]) / 2)
    if kind == "hexahedron27":
        assert_allclose(ref[20:], [[0, .5, .5], [1, .5, .5], [.5, 0, .5], [.5, 1, .5],
                                   [.5, .5, 0], [.5, .5, 1], [.5, .5, .5]])
    N, _, W = reference_element(kind)
    # bound: partition of unity of polynomial shape functions: ~n eps
    assert_allclose(N.sum(axis=1), 1.0, rtol=1e-13)  # partition of unity
    # bound: quadrature weights summed: ~n eps
    assert_allclose(W.sum(), 1 / 6 if kind.startswith("tetra") else 1.0, rtol=1e-13)
    X = ref.copy()
    Ke, _ = solid_matrices(X, np.arange(len(X))[None], kind, E, NU, RHO)
    assert np.all(np.isfinite(Ke))


def test_inverted_element_raises_naming_it():
    X = REFERENCE_NODES["hexahedron"]
    cells = np.array([np.arange(8), [4, 5, 6, 7, 0, 1, 2, 3]])
    with pytest.raises(ValueError, match=r"hexahedron element 1 \(nodes \[4, 5"):
        solid_matrices(X, cells, "hexahedron", E, NU, RHO)
    with pytest.raises(ValueError, match="not a solid cell type"):
        solid_matrices(X, cells, "wedge", E, NU, RHO)


def _two_hexes():
    """Two unit hexahedra side by side along x (12 nodes) plus a beam from node 9."""
    ref = REFERENCE_NODES["hexahedron"]
    points = np.vstack([ref, ref[[1, 2, 5, 6]] + [1, 0, 0], [[3.0, 1.0, 1.0]]])
    cells = np.array([np.arange(8), [1, 8, 9, 2, 5, 10, 11, 6]])
    return fm.Mesh(points, {"hexahedron": cells, "line": [[11, 12]]},
                   {"block": {"hexahedron": [0, 1]}, "arm": {"line": [0]}})


def test_build_model_with_solids_and_a_beam():
    mesh = _two_hexes()
    steel = fm.Material(E=E, nu=NU, rho=RHO)
    beam = fm.BeamProperty(rectangle(0.1, 0.1), steel)
    model = fm.build_model(mesh, {"arm": beam}, solids={"block": fm.SolidProperty(steel)})
    # ρ V of the two unit cubes plus ρ A L of the beam (L = 1)
    # bound: consistent mass integrated exactly: ~n eps
    assert_allclose(model.total_mass(), RHO * (2.0 + 0.01), rtol=1e-12)
    assert model.solids.cells["hexahedron"].shape == (2, 8)
    assert model.solids.group["hexahedron"].tolist() == ["block", "block"]
    # rotations of the 11 solid-only nodes are inactive; node 11 keeps the beam's
    expected = (6 * np.setdiff1d(np.arange(12), [11])[:, None] + np.arange(3, 6)).ravel()
    assert model.inactive.tolist() == expected.tolist()
    assert model.n_free == 6 * 13 - expected.size
    # free-free: six rigid modes plus one hinge (the beam turns about node 11 freely)
    lam = sl.eigh(model.K_free.toarray(), model.M_free.toarray(), eigvals_only=True)
    assert np.sum(np.abs(lam) < 1e-8 * lam[-1]) == 9  # 6 rigid + 3 hinge rotations


def test_build_model_solid_errors_name_the_item():
    mesh = _two_hexes()
    steel = fm.Material(E=E, nu=NU, rho=RHO)
    beam = fm.BeamProperty(rectangle(0.1, 0.1), steel)
    with pytest.raises(ValueError, match=r"\['hexahedron'\] cells, which have no element"):
        fm.build_model(mesh, {"arm": beam})
    with pytest.raises(TypeError, match=r"solids\['block'\] must be a SolidProperty"):
        fm.build_model(mesh, {"arm": beam}, solids={"block": steel})
    with pytest.raises(ValueError, match="solid property for unknown group 'nope'"):
        fm.build_model(mesh, {"arm": beam}, solids={"nope": fm.SolidProperty(steel)})
    with pytest.raises(ValueError, match="group 'arm', which has no tetra"):
        fm.build_model(mesh, {"arm": beam}, solids={"arm": fm.SolidProperty(steel)})
    with pytest.raises(TypeError, match="SolidProperty material must be a Material"):
        fm.SolidProperty("steel")


def test_assembly_in_chunks_equals_dense_scatter():
    """assemble_solid (batched, any chunk size) equals an independent dense scatter."""
    mesh = _two_hexes()
    cells = mesh.cells["hexahedron"]
    Ke, Me = solid_matrices(mesh.points, cells, "hexahedron", E, NU, RHO)
    K = np.zeros((6 * mesh.n_nodes,) * 2)
    for c, k in zip(cells, Ke, strict=True):
        d = (6 * c[:, None] + np.arange(3)).ravel()
        K[np.ix_(d, d)] += k
    for chunk in (None, 1):
        Ks, Ms = assemble_solid(mesh.points, cells, "hexahedron", E, NU, RHO, K.shape[0],
                                chunk=chunk)
        # bound: assembled sums in another order: ~n eps of the largest entry
        assert_allclose(Ks.toarray(), K, rtol=0, atol=1e-13 * abs(K).max())
        # bound: consistent mass integrated exactly: ~n eps
        assert_allclose(Ms.sum() / 3, RHO * 2.0, rtol=1e-13)  # two unit cubes
    bad = np.vstack([cells, cells[1][[4, 5, 6, 7, 0, 1, 2, 3]]])  # element 2 inverted
    with pytest.raises(ValueError, match=r"hexahedron element 2 \(nodes \[5, 10"):
        assemble_solid(mesh.points, bad, "hexahedron", E, NU, RHO, K.shape[0], chunk=1)
