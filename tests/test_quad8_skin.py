"""quad8 shells on the face of a solid (skins, coatings) and their MITC9 centre nodes.

A quad8 cell becomes a MITC9 shell with an added centre node
(:func:`femmech.fe.mesh.quad8_to_quad9`). On a solid face the eight nodes move with the
solid, and a free centre node is held by nothing but the skin: its transverse motion
was a local mode of the skin alone. ``build_model`` ties the translations of such
centre nodes to the serendipity interpolation of the eight (``-¼ Σ corners + ½ Σ edge
nodes``); the centre nodes of free quad8 shells stay MITC9 centre nodes.

References: the solid without the skin (the same hexahedron20 or hexahedron27 mesh),
and the first-order eigenvalue perturbation of adding the skin's mass,
``δω²/ω² = -φᵀ ΔM φ`` for a mass-normalised mode φ of the solid (Rayleigh; e.g.
Géradin & Rixen, Mechanical Vibrations), ``δf/f = -½ φᵀ ΔM φ``.
"""

import functools

import meshio
import numpy as np
import pytest
import scipy.sparse as sp
from models import grid_solid, ss_reference, ssss_plate
from numpy.testing import assert_allclose
from scipy.spatial import cKDTree

import femmech as fm
from femmech.fe.constraints import EquationSet, add_interpolated_nodes, constraint_transform
from femmech.fe.mesh import QUAD8_CENTRE, quad8_centres, quad8_to_quad9
from femmech.output.export import export_modes_vtu
from femmech.reduction import craig_bampton
from femmech.reduction.superelement import interface_dofs

STEEL = fm.Material(E=200e9, nu=0.3, rho=7850.0)
L, H, T_SKIN = 0.1, 0.02, 1e-4  # cantilever length, square side, skin thickness (m)
N_X, N_YZ = 6, 2  # hexahedron20 elements along and across


def _cantilever(skin: bool, clamped: bool = True, hub: bool = False, supports=(),
                kind="hexahedron20", **links):
    """Steel cantilever (``kind`` solids), root clamped; with ``skin`` a quad8 steel skin
    of thickness T_SKIN on its free end face x = L (group ``"skin"``); with ``hub`` a
    last node at (L + H, 0, 0) for a link."""
    mesh = grid_solid(kind, np.linspace(0, L, N_X + 1),
                      *(np.linspace(-H / 2, H / 2, N_YZ + 1),) * 2)
    # bound: grid coordinates are exact at x = 0 (linspace start), so the root face is
    # selected by 0 < 1e-12 with no round-off at all
    root = np.flatnonzero(mesh.points[:, 0] < 1e-12)
    supports = [fm.Support(root, "translations")] * clamped + list(supports)
    shells = None
    if skin:
        g = np.linspace(-H / 2, H / 2, 2 * N_YZ + 1)
        ij = np.array([(0, 0), (2, 0), (2, 2), (0, 2), (1, 0), (2, 1), (1, 2), (0, 1)])
        corners = np.array([(2 * i, 2 * j) for i in range(N_YZ) for j in range(N_YZ)])
        grid = corners[:, None, :] + ij  # (n_cells, 8, 2) indices into g
        X = np.stack([np.full(grid.shape[:2], L), g[grid[..., 0]], g[grid[..., 1]]], axis=-1)
        dist, cells = cKDTree(mesh.points).query(X.reshape(-1, 3))
        # bound: both grids come from the same linspace values (|x| <= 0.1 m), equal up to
        # a few eps * 0.1 m ~ 1e-16 m; 1e-12 m leaves the margin
        assert dist.max() < 1e-12  # the skin shares the solid's face nodes
        mesh = fm.Mesh(mesh.points, {**mesh.cells, "quad8": cells.reshape(-1, 8)},
                       {**mesh.cell_sets, "skin": {"quad8": np.arange(len(grid))}})
        shells = {"skin": fm.ShellProperty(T_SKIN, STEEL)}
    if hub:
        mesh = fm.Mesh(np.vstack([mesh.points, [L + H, 0.0, 0.0]]), mesh.cells,
                       mesh.cell_sets)
    return fm.build_model(mesh, solids={"solid": fm.SolidProperty(STEEL)}, shells=shells,
                          supports=supports, **links)


@functools.cache
def _pair(kind="hexahedron20"):
    solid, skinned = _cantilever(False, kind=kind), _cantilever(True, kind=kind)
    return solid, skinned, fm.modes(solid, 8), fm.modes(skinned, 8)


@pytest.fixture(scope="module")
def cantilevers():
    return _pair()


def _padded(A, n):
    """A (sparse, m x m) as the leading block of an n x n matrix."""
    return sp.block_diag([A, sp.csr_matrix((n - A.shape[0],) * 2)]).tocsr()


def _centres(model):
    """Centre nodes (k,) and their eight nodes (k, 8) of the model's converted quad8 cells."""
    cells = model.mesh.cells["quad9"]
    return cells[:, 8], cells[:, :8]


@pytest.mark.parametrize("kind", ["hexahedron20", "hexahedron27"])
def test_skin_on_a_solid_face_adds_no_modes_and_only_its_mass(kind):
    solid, skinned, f_solid, f_skin = _pair(kind)
    # the skin's mass is t / L = 1e-3 of the solid's: it lowers the solid's modes by
    # about that much and has no modes of its own in the band. hexahedron20, before the
    # centre nodes were tied: 1607.1, 1607.1, 5097.1, 6957.9, 6957.9, 7291.3 Hz against
    # the solid's 1610.2, 1610.2, 7298.7, 8700.4, 8700.4, 12721.9 Hz (four extra skin
    # modes). hexahedron27: the face centres are the skin's centre nodes (before: an
    # added node at each, "nodes coincide" and no model).
    if kind == "hexahedron27":
        assert skinned.mesh.n_nodes == solid.mesh.n_nodes
        assert skinned.tied.size == 0
    assert_allclose(skinned.total_mass() / solid.total_mass() - 1, T_SKIN / L, rtol=1e-6)
    n = 6  # bending pair, torsion, second bending pair, axial (the 7th/8th: 3rd pair)
    top = f_solid.freq_hz[n - 1]
    assert np.count_nonzero(f_skin.freq_hz < 1.001 * top) == n
    shift = f_skin.freq_hz[:n] / f_solid.freq_hz[:n] - 1
    # first order in the added mass: the solid's modes extended to the centre nodes by
    # the serendipity interpolation (rotations zero), δf/f = -½ φᵀ ΔM φ
    phi = np.zeros((skinned.n_dof, n))
    phi[:solid.n_dof] = f_solid.shapes[:, :n]
    centre, nodes = _centres(skinned)
    added = centre >= solid.mesh.n_nodes
    centre, nodes = centre[added], nodes[added]
    for d in range(3):
        phi[6 * centre + d] = np.einsum("i,eik->ek", QUAD8_CENTRE, phi[6 * nodes + d])
    dM = skinned.M - _padded(solid.M, skinned.n_dof)
    predicted = -0.5 * np.einsum("ik,ik->k", phi, dM @ phi)
    # measured shifts -1.95e-3 (bending), -1.01e-3 (torsion, axial), -1.71e-3 (second
    # bending), within 0.6 % of the prediction; the rest is second order in the mass
    # ratio (~1e-3 of the shift) and the skin's stiffness (membrane E t against the
    # solid's E H: t / H = 5e-3 of the end layer's energy, a share of that): bound 5 %
    assert_allclose(shift, predicted, rtol=0.05)
    # and the size physics predicts: δf/f = -½ m_skin φ_tip² / (φᵀMφ), -2 t / L for the
    # bending modes of a cantilever (modal mass m/4 at the tip), -t / L for the axial
    # and torsional ones (m/2)
    assert np.all((shift < 0) & (shift > -2.0 * T_SKIN / L))


def test_centre_nodes_show_the_serendipity_motion_in_modes_and_files(cantilevers, tmp_path):
    _, skinned, _, modes = cantilevers
    centre, nodes = _centres(skinned)
    shapes = modes.shapes.reshape(skinned.mesh.n_nodes, 6, -1)
    expected = np.einsum("i,eidk->edk", QUAD8_CENTRE, shapes[nodes, :3])
    scale = np.abs(shapes[:, :3]).max()
    # bound: T's rows are the weights ±¼, ½ of eight entries: round-off 8 eps of the
    # largest entry
    assert_allclose(shapes[centre, :3], expected, rtol=0, atol=1e-14 * scale)
    # the VTU export writes the recovered centre displacements
    path = export_modes_vtu(skinned, modes, tmp_path / "skin.vtu")
    written = meshio.read(path).point_data["mode_1_displacement"]
    assert written.dtype == np.float64
    # bound: the same 8 eps as above (the file holds the float64 values as computed)
    assert_allclose(written[centre], expected[:, :, 0], rtol=0, atol=1e-14 * scale)


def test_free_quad8_plate_keeps_the_mitc9_frequencies():
    # a free shell has no such local mode: its centre nodes stay MITC9 centre nodes, and
    # the plate keeps the MITC9 accuracy. Simply supported square plate, a/t = 100,
    # 4 x 4 elements, 30 % distorted, against the exact Mindlin frequencies (Mindlin
    # 1951; Leissa 1969 λ = π² (m² + n²) in the thin limit). Measured errors 1.2e-3,
    # 1.0e-2, 1.3e-2, 1.4e-2 (the quad9 mesh's). Tying the centre translations here too
    # would give 5.8e-3, 1.9e-2, 2.8e-2, 6.4e-2, and tying all six DOFs locks: 1.6e-2,
    # 5.1e-2, 7.7e-2, 0.33 (a/t = 1e3: 6.3e-2 ... 0.47).
    t = 1e-2
    lam8 = ssss_plate(4, t, distort=0.3, kind="quad8", modes=4)
    errors = lam8 / ss_reference(t, 4) - 1
    assert np.all(errors > 0)  # a conforming displacement model: from above
    assert errors[0] < 2e-3
    assert errors.max() < 2e-2


def _rigid_motions(model):
    """The six rigid-body motions (n_dof, 6) of the model's nodes, about the origin."""
    X = model.mesh.points
    U = np.zeros((model.mesh.n_nodes, 6, 6))
    for a in range(3):
        U[:, a, a] = 1.0
        U[:, 3 + a, 3 + a] = 1.0
        U[:, :3, 3 + a] = np.cross(np.eye(3)[a], X)  # u = θ × x
    return U.reshape(-1, 6)


def test_links_and_supports_may_name_a_tied_skin():
    # a cell-set name includes the centre nodes: a support keeps them fixed, a rigid
    # link keeps them as its slaves, and an interpolating link's patch takes them
    # through their eight nodes (so that the link and the tie form no cycle)
    skinned = _cantilever(True)
    centre, _ = _centres(skinned)
    k = len(centre)
    held = _cantilever(True, supports=[fm.Support("skin", "uz")])
    assert held.n_free == skinned.n_free - 21  # the 21 face nodes' uz; the centres' were tied
    free = np.zeros(held.n_dof, dtype=bool)
    free[held.free] = True
    assert not free[6 * centre + 2].any()  # fixed by the support
    assert not free[6 * centre].any()  # tied
    face = int(np.argmin(np.abs(skinned.mesh.points - [L, 0, 0]).sum(axis=1)))
    rigid = _cantilever(True, rigid_links=[fm.RigidLink(face, "skin")])
    # the 24 other skin nodes (20 face nodes, 4 centres) become the link's slaves
    assert rigid.n_free == skinned.n_free + 3 * k - 6 * 24
    spider = _cantilever(True, clamped=False, hub=True,
                         interpolating_links=[fm.InterpolatingLink(skinned.mesh.n_nodes - k,
                                                                   "skin")])
    free_free = _cantilever(True, clamped=False)
    assert spider.n_free == free_free.n_free + 6 - 6  # the hub's six; six patch DOFs
    # the constraints hold every rigid-body motion: the hub follows the face's fit, the
    # centres the serendipity interpolation (exact for linear fields)
    R = _rigid_motions(spider)
    R[spider.inactive] = 0.0  # the rotations of solid-only nodes are not in the model
    # bound: T's entries are sums of a few O(1) products (the inverted 6 x 6 block of the
    # link, scaled to the patch size): O(10) eps relative; measured 1.3e-14
    assert_allclose(spider.T @ R[spider.free], R, rtol=0, atol=1e-12)


def test_a_skin_group_is_an_interface_without_its_centre_nodes():
    skinned = _cantilever(True)
    centre, _ = _centres(skinned)
    assert skinned.tied.tolist() == sorted((6 * centre[:, None] + np.arange(3)).ravel())
    dofs = interface_dofs(skinned, "skin")
    assert dofs.size == 6 * 21 + 3 * len(centre)  # the face nodes; the centres' rotations
    assert not np.isin(dofs, skinned.tied).any()
    with pytest.raises(ValueError, match=f"node {centre[0]} ux belongs to the centre node"):
        interface_dofs(skinned, [int(centre[0])])
    se = craig_bampton(skinned, "skin", n_modes=4)
    assert se.n_interface == dofs.size


def test_interpolated_nodes_skip_blocked_dofs_and_give_the_substitution():
    eqs = EquationSet.empty()
    n_dof = 6 * 4
    blocked = np.zeros(n_dof, dtype=bool)
    blocked[6 * 3 + 1] = True  # uy of the interpolated node keeps its own role
    S = add_interpolated_nodes(eqs, n_dof, np.array([3]), np.array([[0, 1, 2]]),
                               np.array([0.25, 0.25, 0.5]), "translations", blocked, "tie")
    assert eqs.dependent().tolist() == [18, 20]
    T, free = constraint_transform(n_dof, np.zeros(n_dof, dtype=bool), eqs)
    assert np.isin([18, 19, 20], free).tolist() == [False, True, False]
    u = np.arange(n_dof, dtype=float)
    full = T @ u[free]
    assert full[18] == 0.25 * u[0] + 0.25 * u[6] + 0.5 * u[12]
    assert full[20] == 0.25 * u[2] + 0.25 * u[8] + 0.5 * u[14]
    assert_allclose((S @ u)[[18, 19, 20]], [full[18], u[19], full[20]])
    assert_allclose(np.delete(S @ u, [18, 20]), np.delete(u, [18, 20]))


def test_quad8_to_quad9_reuses_a_node_at_the_centre_and_shares_stacked_centres():
    X8 = np.array([[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0], [1, 0, 0], [2, 0.5, 0],
                   [1, 1, 0], [0, 0.5, 0]], dtype=float)
    points = np.vstack([X8, [[1.0, 0.5, 0.0], [5.0, 5.0, 5.0]]])  # node 8 at the centre
    cells = np.array([np.arange(8), [1, 2, 3, 0, 5, 6, 7, 4]])  # one cell twice (stacked)
    mesh = fm.Mesh(points, {"quad8": cells})
    out = quad8_to_quad9(mesh)
    assert out.n_nodes == mesh.n_nodes
    assert out.cells["quad9"][:, 8].tolist() == [8, 8]
    assert quad8_centres(mesh)[0].size == 0
    # without the node there: one added centre for both cells, tied to the first's nodes
    mesh = fm.Mesh(points[[0, 1, 2, 3, 4, 5, 6, 7, 9]], {"quad8": cells})
    out = quad8_to_quad9(mesh)
    assert out.n_nodes == mesh.n_nodes + 1
    assert out.cells["quad9"][:, 8].tolist() == [9, 9]
    centres, nodes = quad8_centres(mesh)
    assert centres.tolist() == [9]
    assert nodes.tolist() == [list(range(8))]
    assert_allclose(out.points[9], [1.0, 0.5, 0.0])
