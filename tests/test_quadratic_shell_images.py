"""Quadratic shells (quad9, triangle6) are drawn as linear sub-faces through every node."""

import numpy as np
import pytest

import femmech as fm
from femmech.fe import generators
from femmech.output.surfaces import surface_faces

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)


@pytest.mark.parametrize(("kind", "base", "per_cell"), [("quad9", "quad", 4),
                                                 ("triangle6", "triangle", 4)])
def test_quadratic_shells_become_linear_faces(kind, base, per_cell, tmp_path):
    mesh = generators.rectangular_plate(1.0, 0.6, 3, 2, kind=kind)
    model = fm.build_model(mesh, shells={"plate": fm.ShellProperty(0.01, STEEL)},
                           supports=[fm.Support("edges", ["ux", "uy", "uz"])])
    faces = surface_faces(model)
    n_cells = len(mesh.cells[kind])
    assert list(faces) == [base]
    assert len(faces[base]) == per_cell * n_cells
    # every node of the mesh is a corner of some drawn face (no star-shaped polygons)
    assert np.array_equal(np.unique(faces[base]), np.arange(mesh.points.shape[0]))
    # the sub-faces tile the element: their areas sum to the plate's 1.0 x 0.6 m
    p = model.mesh.points[faces[base]]
    if base == "quad":
        area = 0.5 * np.linalg.norm(np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1]), axis=1)
    else:
        area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    # bound: areas from exact quadrature of straight-sided cells: ~n eps
    assert area.sum() == pytest.approx(0.6, rel=1e-12)
    from femmech.output import plot_mode
    result = fm.modes(model, n_modes=2)
    out = plot_mode(model, result, 0, tmp_path / f"{kind}.png")
    assert (tmp_path / f"{kind}.png").stat().st_size > 10_000
    del out
