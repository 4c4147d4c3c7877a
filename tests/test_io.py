"""Mesh input through meshio: Gmsh 4.1 and 2.2 files, VTU, and error reporting.

The Gmsh 4.1 file is written by hand in the format Gmsh itself writes (Gmsh reference
manual, section "MSH file format", version 4.1: $Entities with physical tags per entity,
node and element blocks per entity, point elements of type 15 for physical points).
The Gmsh 2.2 and VTU files are written by meshio; they store the groups as integer cell
data (``gmsh:physical`` + ``$PhysicalNames``, or meshio's ``cell_sets_to_data`` array).
"""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

import femmech as fm
from femmech.fe import sections
from femmech.fe.mesh_io import from_meshio

EPS = np.finfo(float).eps

# an L-frame: beam (x, z = 0) -> post (z) -> beam again (x, z = 1); "beam" spans two curves
MSH41 = """\
$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
4
0 3 "root"
0 4 "tip"
1 1 "beam"
1 2 "post"
$EndPhysicalNames
$Entities
4 3 0 0
1 0 0 0 1 3
2 2 0 0 0
3 2 0 1 0
4 3 0 1 1 4
1 0 0 0 2 0 0 1 1 2 1 -2
2 2 0 0 2 0 1 1 2 2 2 -3
3 2 0 1 3 0 1 1 1 2 3 -4
$EndEntities
$Nodes
7 6 1 6
0 1 0 1
1
0 0 0
0 2 0 1
2
2 0 0
0 3 0 1
3
2 0 1
0 4 0 1
4
3 0 1
1 1 0 1
5
1 0 0
1 2 0 1
6
2 0 0.5
1 3 0 0
$EndNodes
$Elements
5 7 1 7
0 1 15 1
1 1
0 4 15 1
2 4
1 1 1 2
3 1 5
4 5 2
1 2 1 2
5 2 6
6 6 3
1 3 1 1
7 3 4
$EndElements
"""
# the same frame as arrays (Gmsh node tag t -> index t - 1)
POINTS = np.array([[0.0, 0, 0], [2, 0, 0], [2, 0, 1], [3, 0, 1], [1, 0, 0], [2, 0, 0.5]])
LINES = np.array([[0, 4], [4, 1], [1, 5], [5, 2], [2, 3]])
CELL_SETS = {"beam": [0, 1, 4], "post": [2, 3]}
NODE_SETS = {"root": [0], "tip": [3]}
BEAMS = {"beam": fm.BeamProperty(sections.rectangle(0.05, 0.08), fm.Material(210e9, 7850, 0.3)),
         "post": fm.BeamProperty(sections.tube(0.06, 0.05), fm.Material(70e9, 2700, 0.33))}


def _check_frame_mesh(mesh):
    assert_allclose(mesh.points, POINTS, rtol=0, atol=0)
    assert_array_equal(mesh.cells["line"], LINES)
    assert set(mesh.cells) == {"line"}  # vertex cells become node sets, not cells
    assert sorted(mesh.cell_sets) == ["beam", "post"]
    for name, idx in CELL_SETS.items():
        assert_array_equal(np.sort(mesh.cell_sets[name]["line"]), idx)
    assert sorted(mesh.node_sets) == ["root", "tip"]
    for name, idx in NODE_SETS.items():
        assert_array_equal(mesh.node_sets[name], idx)


def _model(mesh):
    return fm.build_model(mesh, BEAMS, masses=[fm.PointMass("tip", 5.0)],
                          supports=[fm.Support("root")])


def test_gmsh41_physical_groups_become_cell_and_node_sets(tmp_path):
    path = tmp_path / "frame.msh"
    path.write_text(MSH41)
    mesh = fm.read_mesh(path)
    _check_frame_mesh(mesh)
    # "beam" spans two line blocks (curves 1 and 3): the merged indices point at the right
    # elements, e.g. element 4 is the top beam from (2, 0, 1) to (3, 0, 1)
    assert_allclose(mesh.points[mesh.cells["line"][4]], [[2, 0, 1], [3, 0, 1]], rtol=0, atol=0)


def test_model_from_file_equals_model_from_arrays(tmp_path):
    path = tmp_path / "frame.msh"
    path.write_text(MSH41)
    from_file = _model(fm.read_mesh(path))
    from_arrays = _model(fm.Mesh.from_lines(POINTS, LINES, CELL_SETS, NODE_SETS))
    # same numbers in the same order: identical up to round-off (in fact bitwise)
    for a, b in ((from_file.K, from_arrays.K), (from_file.M, from_arrays.M),
                 (from_file.K_free, from_arrays.K_free)):
        assert_allclose(a.toarray(), b.toarray(), rtol=0, atol=EPS * abs(b).max())
    assert_array_equal(from_file.free, from_arrays.free)


def _meshio_frame():
    """The frame as a meshio mesh with two line blocks and two vertex blocks."""
    cells = [("line", LINES[:4]), ("line", LINES[4:]), ("vertex", np.array([[0]])),
             ("vertex", np.array([[3]]))]
    physical = [np.array([1, 1, 2, 2]), np.array([1]), np.array([3]), np.array([4])]
    field_data = {"beam": np.array([1, 1]), "post": np.array([2, 1]),
                  "root": np.array([3, 0]), "tip": np.array([4, 0])}
    return cells, physical, field_data


def test_gmsh22_written_by_meshio_round_trips_physical_groups(tmp_path):
    cells, physical, field_data = _meshio_frame()
    raw = meshio.Mesh(POINTS, cells, cell_data={"gmsh:physical": physical,
                                                "gmsh:geometrical": physical},
                      field_data=field_data)
    path = tmp_path / "frame22.msh"
    meshio.write(path, raw, file_format="gmsh22", binary=False)
    assert "$PhysicalNames" in path.read_text()
    mesh = fm.read_mesh(path)
    _check_frame_mesh(mesh)
    assert_allclose(_model(mesh).K.toarray(),
                    _model(fm.Mesh.from_lines(POINTS, LINES, CELL_SETS, NODE_SETS)).K.toarray(),
                    rtol=0, atol=0)


def test_gmsh22_physical_tags_are_matched_per_dimension(tmp_path):
    # Gmsh numbers physical groups per dimension: tag 1 may be a point and a curve group
    cells = [("line", LINES), ("vertex", np.array([[0], [3]]))]
    physical = [np.array([1, 1, 2, 2, 1]), np.array([1, 2])]
    field_data = {"beam": np.array([1, 1]), "post": np.array([2, 1]),
                  "root": np.array([1, 0]), "tip": np.array([2, 0])}
    raw = meshio.Mesh(POINTS, cells, cell_data={"gmsh:physical": physical,
                                                "gmsh:geometrical": physical},
                      field_data=field_data)
    path = tmp_path / "tags.msh"
    meshio.write(path, raw, file_format="gmsh22", binary=False)
    _check_frame_mesh(fm.read_mesh(path))


def test_vtu_with_cell_sets(tmp_path):
    cells = [("line", LINES[:2]), ("line", LINES[2:])]
    sets = {"beam": [np.array([0, 1]), np.array([2])],
            "post": [np.array([], dtype=int), np.array([0, 1])]}
    path = tmp_path / "frame.vtu"
    meshio.write(path, meshio.Mesh(POINTS, cells, cell_sets=sets))  # stored as cell data
    mesh = fm.read_mesh(path)
    assert_array_equal(mesh.cells["line"], LINES)
    assert sorted(mesh.cell_sets) == ["beam", "post"]
    for name, idx in CELL_SETS.items():
        assert_array_equal(np.sort(mesh.cell_sets[name]["line"]), idx)


def test_from_meshio_merges_blocks_and_offsets_set_indices():
    cells = [("line", LINES[:1]), ("vertex", np.array([[0]])), ("line", LINES[1:3]),
             ("line", LINES[3:])]
    sets = {"odd": [np.array([], dtype=int), None, np.array([0]), np.array([0])],
            "first": [np.array([0]), None, np.array([], dtype=int), np.array([], dtype=int)],
            "root": [None, np.array([0]), None, None],
            "gmsh:bounding_entities": [None, None, None, None]}
    mesh = from_meshio(meshio.Mesh(POINTS, cells, cell_sets=sets))
    assert_array_equal(mesh.cells["line"], LINES)
    # block offsets: the second line block starts at element 1, the third at element 3
    assert_array_equal(mesh.cell_sets["odd"]["line"], [1, 3])
    assert_array_equal(mesh.cell_sets["first"]["line"], [0])
    assert_array_equal(mesh.node_sets["root"], [0])
    assert "gmsh:bounding_entities" not in mesh.cell_sets


def test_triangles_in_file_are_kept_and_rejected_clearly_by_build_model(tmp_path):
    points = np.vstack([POINTS, [[0.0, 1.0, 0.0]]])
    cells = [("line", LINES), ("triangle", np.array([[0, 4, 6]]))]
    sets = {"beam": [np.array([0, 1, 4]), np.array([], dtype=int)], "post": [np.array([2, 3]),
                                                                   np.array([], dtype=int)],
            "plate": [np.array([], dtype=int), np.array([0])]}
    path = tmp_path / "mixed.vtu"
    meshio.write(path, meshio.Mesh(points, cells, cell_sets=sets))
    mesh = fm.read_mesh(path)
    assert_array_equal(mesh.cell_sets["plate"]["triangle"], [0])
    with pytest.raises(ValueError, match=r"\['triangle'\] cells, which have no element"):
        fm.build_model(mesh, BEAMS)


def test_unknown_group_from_file_lists_the_file_groups(tmp_path):
    path = tmp_path / "frame.msh"
    path.write_text(MSH41)
    mesh = fm.read_mesh(path)
    match = (r"unknown group 'Beam'; the mesh has cell sets \['beam', 'post'\]; did you mean"
             r" 'beam'\?")
    with pytest.raises(ValueError, match=match):
        fm.build_model(mesh, {"Beam": BEAMS["beam"], "post": BEAMS["post"]})


def test_unreadable_file_raises_file_format_error_naming_the_file(tmp_path):
    path = tmp_path / "garbage.msh"
    path.write_text("this is not a mesh\n")
    with pytest.raises(fm.FileFormatError, match=r"garbage\.msh: meshio could not read the"
                                                 " file"):
        fm.read_mesh(path)


def test_unknown_extension_raises_value_error_naming_the_file(tmp_path):
    path = tmp_path / "frame.unknownformat"
    path.write_text(MSH41)
    with pytest.raises(ValueError, match=r"frame\.unknownformat"):
        fm.read_mesh(path)


def test_file_with_bad_connectivity_names_file_and_cell(tmp_path):
    path = tmp_path / "bad.msh"
    # element 7 refers to node tag 4 -> replace by an undefined tag (meshio maps tags to
    # indices, an unknown tag gives an out-of-range or failed read: either way a ValueError)
    path.write_text(MSH41.replace("7 3 4\n", "7 3 9\n"))
    with pytest.raises(ValueError, match=r"bad\.msh"):
        fm.read_mesh(path)


def test_missing_file_raises_file_not_found_naming_the_path(tmp_path):
    path = tmp_path / "nowhere" / "frame.msh"
    with pytest.raises(FileNotFoundError, match=r"nowhere.frame\.msh"):
        fm.read_mesh(path)
    with pytest.raises(FileNotFoundError, match="mesh file not found"):
        fm.read_mesh(str(path))


# Curve end points of meshes/machine_frame.geo (m) by physical curve, and physical points
GEO_CURVES = {
    "columns": [((x, y, 0.0), (x, y, 0.3)) for x, y in ((0, 0), (2, 0), (2, 1), (0, 1))]
    + [((x, y, 0.3), (x, y, 1.2)) for x, y in ((0, 0), (2, 0), (2, 1), (0, 1))],
    "longitudinals": [((0, 0, 1.2), (1, 0, 1.2)), ((1, 0, 1.2), (2, 0, 1.2)),
                      ((0, 1, 1.2), (1, 1, 1.2)), ((1, 1, 1.2), (2, 1, 1.2))],
    "cross_beams": [((0, 0, 1.2), (0, 1, 1.2)), ((2, 0, 1.2), (2, 1, 1.2)),
                    ((1, 0, 1.2), (1, 0.35, 1.2)), ((1, 0.35, 1.2), (1, 0.65, 1.2)),
                    ((1, 0.65, 1.2), (1, 1, 1.2))],
    "rails": [((0, 0, 0.3), (2, 0, 0.3)), ((0, 1, 0.3), (2, 1, 0.3)),
              ((0, 0, 0.3), (0, 1, 0.3)), ((2, 0, 0.3), (2, 1, 0.3))],
    "brace": [((0, 1, 0.3), (1, 1, 1.2))],
}
GEO_POINTS = {"feet": [(0, 0, 0), (2, 0, 0), (2, 1, 0), (0, 1, 0)], "foot_3": [(2, 1, 0)],
              "motor_feet": [(1, 0.35, 1.2), (1, 0.65, 1.2)], "motor": [(1, 0.5, 1.45)]}


def test_real_gmsh_file_machine_frame():
    path = Path(__file__).resolve().parent.parent / "meshes" / "machine_frame.msh"
    mesh = fm.read_mesh(path)
    lines = mesh.cells["line"]
    all_idx = np.concatenate([s["line"] for s in mesh.cell_sets.values()])
    assert_array_equal(np.sort(all_idx), np.arange(len(lines)))  # each element in one group
    assert set(mesh.cell_sets) == set(GEO_CURVES)
    h = 0.1  # element size in the .geo
    for name, curves in GEO_CURVES.items():
        ends = np.array(curves, dtype=float)
        curve_length = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
        el = np.linalg.norm(np.diff(mesh.points[lines[mesh.cell_sets[name]["line"]]], axis=1),
                            axis=-1)
        # bound: the elements tile the curves: total length to round-off (%.16g coordinates)
        assert_allclose(el.sum(), curve_length.sum(), rtol=1e-12)
        # bound: element lengths of a %.16g mesh: ~10 eps of h, x1e6 margin
        assert el.max() <= h * (1 + 1e-9)
        # Gmsh 1D meshing puts ceil(L / h) elements on each curve (L / h not an integer here
        # except where it is exact: 0.3 / 0.1 -> 3)
        assert len(el) == sum(int(np.ceil(length / h - 1e-9)) for length in curve_length)
    for name, coords in GEO_POINTS.items():
        # bound: %.16g coordinates read back: ~1 ulp of O(1) values
        assert_allclose(mesh.points[mesh.node_sets[name]], coords, rtol=0, atol=1e-12)
    # nodes on the curves only once (no duplicates), and the model builds from the groups
    tube = fm.BeamProperty(sections.tube(0.06, 0.05), fm.Material(210e9, 7850, 0.3))
    model = fm.build_model(mesh, dict.fromkeys(GEO_CURVES, tube),
                           masses=[fm.PointMass("motor", 150.0)],
                           rigid_links=[fm.RigidLink("motor", "motor_feet")],
                           supports=[fm.Support("feet")])
    assert model.n_free == 6 * (mesh.n_nodes - 4 - 2)
