"""Uniform mesh refinement (h/2) with groups kept, and the model rebuilt on it."""

import numpy as np
import pytest
import scipy.sparse.linalg as spla

import femmech as fm
from femmech.fe import checks
from femmech.fe.refine import refine_mesh, refined_model
from femmech.fe.sections import rectangle

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)


def grid(nx, ny, kind="quad"):
    """nx x ny quads (or 2 nx ny triangles) on [0, nx] x [0, ny], sets "plate", "left"."""
    X, Y = np.meshgrid(np.arange(nx + 1.0), np.arange(ny + 1.0))
    points = np.column_stack([X.ravel(), Y.ravel(), 0 * X.ravel()])
    i = np.arange(X.size).reshape(ny + 1, nx + 1)
    q = np.column_stack([i[:-1, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, 1:].ravel(),
                         i[1:, :-1].ravel()])
    cells = q if kind == "quad" else np.vstack([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])
    return fm.Mesh(points, {kind: cells}, {"plate": {kind: np.arange(len(cells))},
                                           "first": {kind: [0]}},
                   {"left": i[:, 0], "corner": [0]})


def brick(nx, ny, nz, tet=False):
    g = np.stack(np.meshgrid(np.arange(nx + 1.0), np.arange(ny + 1.0), np.arange(nz + 1.0),
                             indexing="ij"), -1).reshape(-1, 3)
    idx = np.arange(len(g)).reshape(nx + 1, ny + 1, nz + 1)

    def c(i, j, k):
        return idx[i:nx + i, j:ny + j, k:nz + k].ravel()

    H = np.column_stack([c(0, 0, 0), c(1, 0, 0), c(1, 1, 0), c(0, 1, 0), c(0, 0, 1),
                         c(1, 0, 1), c(1, 1, 1), c(0, 1, 1)])
    if tet:  # Kuhn: six tetrahedra about the diagonal 0-6, conforming between bricks
        H = np.vstack([H[:, q] for q in ([0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6],
                                         [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6])])
        H = H[:, [0, 2, 1, 3]] if signed_volume(g, H)[0] < 0 else H
    kind = "tetra" if tet else "hexahedron"
    return fm.Mesh(g, {kind: H}, {"all": {kind: np.arange(len(H))}},
                   {"face": np.flatnonzero(g[:, 0] == 0)})


def signed_volume(points, tets):
    p = points[tets]
    return np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]),
                     p[:, 3] - p[:, 0]) / 6.0


@pytest.mark.parametrize(("kind", "nodes", "cells"),
                         [("quad", 9 * 7, 4 * 12), ("triangle", 9 * 7, 4 * 24)])
def test_shell_counts_and_shared_nodes(kind, nodes, cells):
    mesh = grid(4, 3, kind)
    fine = refine_mesh(mesh)
    assert fine.n_nodes == nodes  # the 8 x 6 grid: shared new nodes made once
    assert len(fine.cells[kind]) == cells
    assert np.array_equal(fine.points[:mesh.n_nodes], mesh.points)  # coarse nodes first
    assert np.isclose(checks.cell_measure(fine.points, kind, fine.cells[kind]).sum(), 12.0)
    assert np.array_equal(fine.cell_sets["first"][kind], np.arange(4))  # children of 0
    # an edge set gains its edge midpoints; a one-node set stays one node
    assert np.array_equal(fine.node_sets["left"][:4], mesh.node_sets["left"])
    assert np.allclose(fine.points[fine.node_sets["left"], 0], 0.0)
    assert fine.node_sets["left"].size == 7
    assert fine.node_sets["corner"].tolist() == [0]


def test_quad_orientation_is_kept():
    fine = refine_mesh(grid(2, 2))
    p = fine.points[fine.cells["quad"]]
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 3] - p[:, 0])[:, 2]
    assert np.all(normal > 0)


@pytest.mark.parametrize("tet", [False, True], ids=["hexahedron", "tetra"])
def test_solid_counts_volume_and_orientation(tet):
    mesh = brick(3, 2, 2, tet)
    kind = "tetra" if tet else "hexahedron"
    fine = refine_mesh(mesh)
    assert fine.n_nodes == 7 * 5 * 5  # the 6 x 4 x 4 lattice
    assert len(fine.cells[kind]) == 8 * len(mesh.cells[kind])
    measure = checks.cell_measure(fine.points, kind, fine.cells[kind])
    assert np.isclose(measure.sum(), 12.0)
    assert np.allclose(measure, measure[0]) if not tet else measure.min() > 0
    if tet:
        assert np.all(signed_volume(fine.points, fine.cells[kind]) > 0)
    assert fine.node_sets["face"].size == 5 * 5  # the face x = 0 with its new nodes


def test_refined_meshes_are_nested_twice():
    mesh = brick(1, 1, 1)
    once = refine_mesh(mesh)
    twice = refine_mesh(once)
    assert twice.n_nodes == 5 ** 3
    assert np.array_equal(twice.points[:once.n_nodes], once.points)


@pytest.mark.parametrize("kind", ["quad8", "tetra10", "wedge"])
def test_unrefined_kinds_raise(kind):
    from femmech.fe.mesh import NODES_PER_CELL

    k = NODES_PER_CELL[kind]
    mesh = fm.Mesh(np.random.default_rng(0).random((k, 3)), {kind: [list(range(k))]})
    with pytest.raises(NotImplementedError, match=kind):
        refine_mesh(mesh)


def frame():
    """An L-shaped frame of two members with different sections and an orientation
    vector, a point mass and a spring: the pieces a rebuild must carry over."""
    points = [[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 0, 1], [2, 0, 2]]
    mesh = fm.Mesh(points, {"line": [[0, 1], [1, 2], [2, 3], [3, 4]]},
                   {"beam": {"line": [0, 1]}, "post": {"line": [2, 3]}},
                   {"root": [0], "tip": [4]})
    beams = {"beam": fm.BeamProperty(rectangle(0.05, 0.1), STEEL, orientation=(0, 1, 1)),
             "post": fm.BeamProperty(rectangle(0.08, 0.04), STEEL, shear=False)}
    return fm.build_model(mesh, beams, masses=[fm.PointMass("tip", 3.0)],
                          springs=[fm.Spring(2, None, 1e5)], supports=[fm.Support("root")])


def static_tip(model, direction):
    f = np.zeros(model.n_dof)
    f[6 * 4 + direction] = 1000.0  # N at the tip
    u = model.expand(spla.spsolve(model.K_free.tocsc(), model.T.T @ f))
    return u[6 * 4: 6 * 4 + 6]


def test_refined_beam_model_static_deflection_and_mass():
    coarse = frame()
    fine = refined_model(coarse)
    assert fine.mesh.n_nodes == 9
    assert len(fine.beams.cells) == 8
    # bound: the beam element's stiffness is exact for end loads: the same tip motion to round-off
    for direction in range(3):
        a, b = static_tip(coarse, direction), static_tip(fine, direction)
        assert np.allclose(a, b, rtol=1e-9, atol=1e-12 * np.abs(a).max())
    # bound: mass sums of ρ A L over split elements: ~n eps
    assert np.isclose(fine.total_mass(), coarse.total_mass(), rtol=1e-12)
    # children keep their parent's local axes (orientation vector) and properties
    # bound: frames copied from the parents: exact up to a few eps
    assert np.allclose(fine.beams.frames[::2], coarse.beams.frames, atol=1e-14)
    assert np.array_equal(fine.beams.properties[::2], coarse.beams.properties)
    assert np.array_equal(fine.beams.group[1::2], coarse.beams.group)


def test_refined_shell_model_keeps_mass_and_index_supports():
    mesh = grid(4, 2)
    left = np.flatnonzero(mesh.points[:, 0] == 0)  # by index, not by set
    model = fm.build_model(mesh, shells={"plate": fm.ShellProperty(0.01, STEEL)},
                           supports=[fm.Support(left)])
    fine = refined_model(model)
    # bound: mass sums of ρ A L over split elements: ~n eps
    assert np.isclose(fine.total_mass(), model.total_mass(), rtol=1e-12)
    fixed = np.flatnonzero(np.diff(fine.T.tocsr().indptr) == 0) // 6
    assert np.array_equal(np.unique(fixed), np.flatnonzero(fine.mesh.points[:, 0] == 0))


def test_model_without_inputs_is_refused():
    from dataclasses import replace

    with pytest.raises(ValueError, match="build_model inputs"):
        refined_model(replace(frame(), inputs={}))


def test_beam_node_sets_are_points_but_a_set_of_all_nodes_grows():
    mesh = fm.Mesh.from_lines([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 1], [1, 2]],
                              node_sets={"ends": [0, 1], "all": [0, 1, 2]})
    fine = refine_mesh(mesh)
    assert fine.node_sets["ends"].tolist() == [0, 1]  # pins at two joints stay two pins
    assert fine.node_sets["all"].tolist() == [0, 1, 2, 3, 4]
    # a beam along a shell edge: the midpoint belongs to the shell edge, so it joins
    shell = fm.Mesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
                    {"quad": [[0, 1, 2, 3]], "line": [[0, 1]]}, {}, {"edge": [0, 1]})
    fine = refine_mesh(shell)
    assert np.allclose(fine.points[fine.node_sets["edge"]][:, 1], 0.0)
    assert fine.node_sets["edge"].size == 3


@pytest.mark.parametrize(("kind", "cells"), [("quad9", 4 * 6), ("triangle6", 4 * 12)])
def test_quadratic_shells_split_in_four_on_their_own_map(kind, cells):
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from models import plate_cells

    # a 3 x 2 patch of elements on the (7 x 5)-node grid, bent onto a cylinder z = x²/4
    # (exactly quadratic: the parent's map reproduces it, so the children lie on it)
    points, c = plate_cells(3, kind)
    # bound: coordinates of a 3-node-per-side grid: exact to ~eps of O(1)
    keep = points[:, 1] <= 2 / 3 + 1e-12
    new = np.cumsum(keep) - 1
    c = new[c[np.all(keep[c], axis=1)]]
    points = points[keep] * [3, 3, 0]
    points[:, 2] = points[:, 0] ** 2 / 4
    mesh = fm.Mesh(points, {kind: c}, {"s": {kind: np.arange(len(c))}},
                   {"edge": np.flatnonzero(points[:, 1] == 0)})
    fine = refine_mesh(mesh)
    assert len(fine.cells[kind]) == cells
    assert fine.n_nodes == 13 * 9  # the (4 · 3 + 1) x (4 · 2 + 1) node grid, shared once
    assert np.allclose(fine.points[:, 2], fine.points[:, 0] ** 2 / 4)
    xy = np.unique(np.round(fine.points[:, :2] * 4, 9), axis=0)
    assert len(xy) == fine.n_nodes  # no duplicates, a regular grid of spacing 1/4
    assert np.allclose(xy, np.round(xy))
    assert np.allclose(fine.points[fine.node_sets["edge"], 1], 0.0)
    assert fine.node_sets["edge"].size == 13
