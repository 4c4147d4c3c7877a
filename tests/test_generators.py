"""The parametric frame generator: counts, groups, node sets, and a model that builds.

Reference counts: a grid of (bx+1)(by+1)(bz+1) joints has bx (by+1)(bz+1) members along
x (and cyclically for y, z); k elements per member add k - 1 interior nodes each.
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from scipy.spatial import cKDTree

import femmech as fm
from femmech.fe import sections
from femmech.fe.generators import grid_frame, grid_frame_size

CASES = [((2, 2, 2), 1), ((2, 1, 3), 3), ((3, 0, 0), 2), ((2, 1, 0), 4), ((1, 1, 1), 1)]


def _members(bays):
    bx, by, bz = bays
    return {"beams_x": bx * (by + 1) * (bz + 1), "beams_y": by * (bx + 1) * (bz + 1),
            "columns": bz * (bx + 1) * (by + 1)}


@pytest.mark.parametrize(("bays", "k"), CASES)
def test_counts_match_formulas(bays, k):
    size = (3.0, 2.0, 1.5)
    mesh = grid_frame(bays, size, k)
    joints = np.prod(np.add(bays, 1))
    members = _members(bays)
    n_members = sum(members.values())
    assert mesh.n_nodes == joints + (k - 1) * n_members
    assert len(mesh.cells["line"]) == k * n_members
    assert set(mesh.cell_sets) == {name for name, n in members.items() if n}
    for name, n in members.items():
        if n:
            assert len(mesh.cell_sets[name]["line"]) == k * n


@pytest.mark.parametrize(("bays", "k"), CASES)
def test_groups_cover_elements_once_and_mesh_is_clean(bays, k):
    size = (3.0, 2.0, 1.5)
    mesh = grid_frame(bays, size, k)
    lines = mesh.cells["line"]
    all_idx = np.concatenate([s["line"] for s in mesh.cell_sets.values()])
    assert_array_equal(np.sort(all_idx), np.arange(len(lines)))  # each element exactly once
    # no duplicate nodes (closer than 1e-9 of the size), no unused nodes
    assert len(cKDTree(mesh.points).query_pairs(1e-9 * max(size))) == 0
    assert_array_equal(np.unique(lines), np.arange(mesh.n_nodes))
    # element lengths: member length / k, and members lie along their group's axis
    for axis, name in enumerate(("beams_x", "beams_y", "columns")):
        if name not in mesh.cell_sets:
            continue
        d = np.diff(mesh.points[lines[mesh.cell_sets[name]["line"]]], axis=1)[:, 0]
        expected = np.zeros(3)
        expected[axis] = size[axis] / bays[axis] / k
        # bound: generated coordinates: sums of O(size) steps, ~10 eps of the size
        assert_allclose(d, np.broadcast_to(expected, d.shape), rtol=0, atol=1e-14 * max(size))
    # no element appears twice (also not reversed)
    assert len(np.unique(np.sort(lines, axis=1), axis=0)) == len(lines)


def test_node_sets():
    size = (3.0, 2.0, 1.5)
    mesh = grid_frame((2, 1, 3), size, 2)
    z = mesh.points[:, 2]
    joints = mesh.node_sets["joints"]
    assert len(joints) == 3 * 2 * 4
    # base: joints at z = 0 (interior nodes of members are not joints)
    base = np.flatnonzero(np.isclose(z, 0.0))
    base_joints = np.intersect1d(base, joints)
    assert_array_equal(np.sort(mesh.node_sets["base"]), base_joints)
    top_joints = np.intersect1d(np.flatnonzero(np.isclose(z, size[2])), joints)
    assert_array_equal(np.sort(mesh.node_sets["top"]), top_joints)
    assert len(base_joints) == len(top_joints) == 3 * 2
    # joints sit on the grid coordinates
    grid = mesh.points[joints] / np.array(size) * np.array([2, 1, 3])
    # bound: grid coordinates scaled to integers: ~10 eps of O(1) values
    assert_allclose(grid, np.round(grid), rtol=0, atol=1e-12)


def test_a_model_builds_and_has_sensible_modes():
    mesh = grid_frame((2, 1, 1), (2.0, 1.0, 1.0), 2)
    steel = fm.Material(E=210e9, nu=0.3, rho=7850.0)
    tube = fm.BeamProperty(sections.rectangular_hollow(0.08, 0.08, 0.004), steel)
    model = fm.build_model(mesh, {"beams_x": tube, "beams_y": tube, "columns": tube},
                           supports=[fm.Support("base")])
    assert model.n_free == 6 * (mesh.n_nodes - 6)
    # every element has a beam property: total mass = ρ A × total member length
    length = 2 * 2 * 2.0 + 3 * 2 * 1.0 + 6 * 1.0  # beams_x, beams_y, columns (m)
    # bound: consistent mass integrates ρ A exactly: ~n eps of the sum
    assert_allclose(model.total_mass(), 7850.0 * tube.section.A * length, rtol=1e-12)
    result = fm.modes(model, n_modes=3)
    assert not result.rigid.any()
    assert (result.freq_hz > 0).all()


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"bays": (0, 0, 0)}, "bays must be three non-negative integers, not all zero"),
    ({"bays": (1, -1, 1)}, "bays must be three non-negative integers"),
    ({"bays": (1, 1)}, "bays must be three"),
    ({"subdivisions": 0}, "subdivisions must be >= 1, got 0"),
    ({"size": (1.0, 0.0, 1.0)}, "size must be three positive lengths"),
    ({"size": (1.0, 1.0)}, "size must be three positive lengths"),
    ({"size": (1.0, np.nan, 1.0)}, "size must be three positive lengths"),
])
def test_generator_errors(kwargs, match):
    with pytest.raises(ValueError, match=match):
        grid_frame(**kwargs)


@pytest.mark.parametrize(("bays", "subdivisions"), [((1, 1, 1), 1), ((2, 3, 1), 3),
                                                    ((0, 0, 2), 2), ((3, 0, 0), 1)])
def test_grid_frame_size_counts_what_grid_frame_builds(bays, subdivisions):
    # the count the scene checks against MAX_NODES/MAX_CELLS before building anything
    mesh = grid_frame(bays, (1.0, 1.0, 1.0), subdivisions)
    n_elements = sum(len(c) for c in mesh.cells.values())
    assert grid_frame_size(bays, subdivisions) == (mesh.n_nodes, n_elements)
