"""Shell-shape generators: rectangular plate, box (tube with end plates), stiffened plate.

Counts follow from the grids (n x m elements have (n + 1)(m + 1) nodes); masses are hand
sums ρ t area + ρ A L; the free-free box must have exactly six rigid-body modes (any
unshared edge node would add mechanisms).
"""

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

import femmech as fm
from femmech.fe.generators import box, rectangular_plate, stiffened_plate, surface_cells
from femmech.fe.sections import rectangular_hollow

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)


def cell_normals(mesh, kind):
    """Unit normals of the cells (cross product of the corner diagonals / edges)."""
    cells = mesh.cells[kind]
    p = mesh.points
    if kind.startswith("quad"):
        n = np.cross(p[cells[:, 2]] - p[cells[:, 0]], p[cells[:, 3]] - p[cells[:, 1]])
    else:
        n = np.cross(p[cells[:, 1]] - p[cells[:, 0]], p[cells[:, 2]] - p[cells[:, 0]])
    return n / np.linalg.norm(n, axis=1)[:, None]


def cell_areas(mesh, kind):
    cells, p = mesh.cells[kind], mesh.points
    if kind.startswith("quad"):
        d = np.cross(p[cells[:, 2]] - p[cells[:, 0]], p[cells[:, 3]] - p[cells[:, 1]])
    else:
        d = np.cross(p[cells[:, 1]] - p[cells[:, 0]], p[cells[:, 2]] - p[cells[:, 0]])
    return 0.5 * np.linalg.norm(d, axis=1)


@pytest.mark.parametrize(("kind", "nodes", "cells"), [("quad", 4 * 3, 6), ("triangle", 12, 12),
                                                ("quad9", 7 * 5, 6), ("triangle6", 35, 12)])
def test_plate_counts_and_edges(kind, nodes, cells):
    mesh = rectangular_plate(3.0, 2.0, 3, 2, kind=kind)
    assert mesh.n_nodes == nodes
    assert len(mesh.cells[kind]) == cells
    x, y = mesh.points[:, 0], mesh.points[:, 1]
    for name, mask in [("edge_x0", x == 0), ("edge_xa", np.isclose(x, 3.0)),
                       ("edge_y0", y == 0), ("edge_yb", np.isclose(y, 2.0))]:
        assert_array_equal(np.sort(mesh.node_sets[name]), np.flatnonzero(mask))
    boundary = np.isclose(x, 0) | np.isclose(x, 3) | np.isclose(y, 0) | np.isclose(y, 2)
    assert_array_equal(np.sort(mesh.node_sets["edges"]), np.flatnonzero(boundary))
    assert_allclose(mesh.points[mesh.node_sets["corners"], :2], [[0, 0], [3, 0], [3, 2], [0, 2]])
    # bound: cell areas of straight-sided cells summed: ~n eps
    assert_allclose(cell_areas(mesh, kind).sum(), 6.0, rtol=1e-14)
    assert (cell_normals(mesh, kind)[:, 2] > 0.999).all()  # counter-clockwise about +z


def test_quadratic_cells_put_mid_nodes_between_their_corners():
    for kind, pairs in [("quad9", [(0, 1, 4), (1, 2, 5), (2, 3, 6), (3, 0, 7)]),
                        ("triangle6", [(0, 1, 3), (1, 2, 4), (2, 0, 5)])]:
        mesh = rectangular_plate(1.0, 0.5, 2, 3, kind=kind)
        c, p = mesh.cells[kind], mesh.points
        for i, j, m in pairs:
            # bound: midside nodes are exact averages: 1 ulp of O(1) coordinates
            assert_allclose(p[c[:, m]], 0.5 * (p[c[:, i]] + p[c[:, j]]), atol=1e-15)
        if kind == "quad9":
            # bound: centre nodes are exact averages: ~1 ulp of O(1) coordinates
            assert_allclose(p[c[:, 8]], p[c[:, :4]].mean(axis=1), atol=1e-15)


def test_bad_arguments_name_the_item():
    with pytest.raises(ValueError, match="nx must be an integer >= 1"):
        rectangular_plate(1.0, 1.0, 0, 2)
    with pytest.raises(ValueError, match="kind must be one of"):
        rectangular_plate(1.0, 1.0, 2, 2, kind="hex")
    with pytest.raises(ValueError, match="width must be a positive length"):
        box(1.0, -1.0, 1.0, 2, 2, 2)
    with pytest.raises(ValueError, match=r"stiffeners_x\[1\] = 0.3 m is not on a grid line"):
        stiffened_plate(1.0, 1.0, 4, 4, stiffeners_x=[0.5, 0.3])


@pytest.mark.parametrize("kind", ["quad", "triangle", "quad9"])
@pytest.mark.parametrize("end_plates", [True, False])
def test_box_counts_sets_and_outward_normals(kind, end_plates):
    L, w, h, nx, ny, nz = 2.0, 0.6, 0.4, 5, 3, 2
    p = 2 if kind == "quad9" else 1
    mesh = box(L, w, h, nx, ny, nz, end_plates=end_plates, kind=kind)
    tube = (p * nx + 1) * p * 2 * (ny + nz)
    assert mesh.n_nodes == tube + end_plates * 2 * (p * ny - 1) * (p * nz - 1)
    per = 2 if kind == "triangle" else 1
    assert len(mesh.cells[kind]) == per * (2 * nx * (ny + nz) + end_plates * 2 * ny * nz)
    area = 2 * (w + h) * L + end_plates * 2 * w * h
    # bound: cell areas summed: ~n eps
    assert_allclose(cell_areas(mesh, kind).sum(), area, rtol=1e-13)
    centre = np.array([L, w, h]) / 2
    mid = mesh.points[mesh.cells[kind][:, :3]].mean(axis=1)
    assert (np.einsum("ij,ij->i", cell_normals(mesh, kind), mid - centre) > 0).all()
    pts = mesh.points
    for name, axis, value in [("bottom", 2, 0), ("top", 2, h), ("side_y0", 1, 0),
                              ("side_yw", 1, w), ("end_x0", 0, 0), ("end_xl", 0, L)]:
        # bound: set nodes lie on exact grid lines: 1 ulp of O(1) coordinates
        assert_allclose(pts[mesh.node_sets[name], axis], value, atol=1e-15)
        if name in mesh.cell_sets:
            cells = mesh.cells[kind][mesh.cell_sets[name][kind]]
            # bound: set cells lie on exact grid lines: 1 ulp of O(1) coordinates
            assert_allclose(pts[cells, axis], value, atol=1e-15)
    corners = pts[mesh.node_sets["corners"]]
    assert len(np.unique(corners.round(12), axis=0)) == 8
    assert set(np.unique(corners[:, 0])) == {0.0, L}
    # every node is used and no two nodes coincide: the walls share their edge nodes
    assert_array_equal(np.unique(mesh.cells[kind]), np.arange(mesh.n_nodes))
    assert len(np.unique(pts.round(12), axis=0)) == mesh.n_nodes


def test_free_box_has_six_rigid_modes_and_its_hand_mass():
    t = 0.005
    mesh = box(1.0, 0.5, 0.3, 6, 3, 2)
    model = fm.build_model(mesh, shells={"walls": fm.ShellProperty(t, STEEL),
                                         "ends": fm.ShellProperty(2 * t, STEEL)})
    mass = STEEL.rho * (t * 2 * (0.5 + 0.3) * 1.0 + 2 * t * 2 * 0.5 * 0.3)
    # bound: consistent mass integrates ρ t A exactly: ~n eps of the sum
    assert_allclose(model.total_mass(), mass, rtol=1e-12)
    f = fm.modes(model, n_modes=8).freq_hz
    # six rigid modes near 0 Hz (round-off of a free model: < 1e-3 Hz at this size),
    # then the first elastic mode far above
    assert (np.abs(f[:6]) < 1e-2).all()
    assert f[6] > 50.0


def test_stiffened_plate_shares_nodes_and_its_model_has_the_hand_mass():
    a, b, t = 1.2, 0.8, 0.004
    mesh = stiffened_plate(a, b, 6, 4, stiffeners_x=[0.4], stiffeners_y=[0.0, 0.6, 1.2])
    lines = mesh.cells["line"]
    assert len(lines) == 6 + 3 * 4
    # beams use plate nodes only: no new nodes
    assert mesh.n_nodes == 7 * 5
    assert lines.max() < mesh.n_nodes
    assert_allclose(mesh.points[mesh.node_sets["stiffener_x0"], 1], 0.4)
    assert_allclose(mesh.points[mesh.node_sets["stiffener_y1"], 0], 0.6)
    section = rectangular_hollow(0.04, 0.06, 0.003)
    model = fm.build_model(mesh, beams={"stiffeners": fm.BeamProperty(section, STEEL)},
                           shells={"plate": fm.ShellProperty(t, STEEL)})
    stiffener_length = a + 3 * b
    mass = STEEL.rho * (t * a * b + section.A * stiffener_length)
    # bound: consistent mass integrates ρ t A exactly: ~n eps of the sum
    assert_allclose(model.total_mass(), mass, rtol=1e-12)


def test_surface_cells_of_a_single_quadratic_patch():
    grid = np.arange(9).reshape(3, 3)
    assert_array_equal(surface_cells(grid, "quad9"), [[0, 2, 8, 6, 1, 5, 7, 3, 4]])
