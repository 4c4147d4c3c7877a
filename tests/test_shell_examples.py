"""The shell example and the shipped shell meshes reproduce independent estimates."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import meshio
import numpy as np
import pytest
from numpy.testing import assert_allclose
from roundoff import EPS

import femmech as fm

ROOT = Path(__file__).resolve().parent.parent
MESHES = ROOT / "meshes"
STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)


def _load(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "examples" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def box_run(tmp_path_factory):
    module = _load("shell_frame_modes")
    return module, module.main(tmp_path_factory.mktemp("box"), n_modes=12, n_images=2)


def _polygon_area(points, centre):
    """Area of the polygon through points (sorted by angle about centre), m²."""
    angle = np.arctan2(points[:, 1] - centre[1], points[:, 0] - centre[0])
    p = points[np.argsort(angle)]
    return 0.5 * abs(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))


def test_box_example_mass(box_run):
    module, result = box_run
    model = result["model"]
    # geometry of meshes/welded_box_frame.geo: L, W, H = 1.2, 0.8, 0.6 m; rib W x H;
    # stiffener ring 2 (L + W) long; the bore is the polygon of its mesh nodes (flat
    # elements end on straight chords)
    L, W, H = 1.2, 0.8, 0.6
    bore = model.mesh.points[model.mesh.node_sets["bore"]]
    hole = _polygon_area(bore[:, :2], (0.35, 0.4))
    assert_allclose(hole, np.pi * 0.09**2, rtol=0.06)  # 12 chords: sin(2π/n)/(2π/n) = 0.95
    t = module.THICKNESS
    volume = (t["top_plate"] * (L * W - hole) + t["walls"] * 2 * (L + W) * H
              + t["rib"] * W * H + module.STIFFENER.A * 2 * (L + W))
    mass = module.STEEL.rho * volume + module.ROTOR_MASS
    # consistent shell and beam mass matrices integrate ρ t and ρ A exactly on flat
    # elements: round-off only, that of eᵀ M e summed over n_dof terms of one sign, at most
    # n_dof eps relative (Higham 2002, §3.1; ~2e-12 here). Measured 2e-14 (SkylakeX),
    # 3e-16 (Haswell kernel): the order of the sum decides, not the model
    assert_allclose(result["total_mass_kg"], mass, rtol=model.n_dof * EPS)


def test_box_example_mount_modes_below_rigid_body_bound(box_run):
    _, result = box_run
    f = result["freq_hz"][:6]
    bound = result["rigid_body_estimate_hz"]
    # bound: Rayleigh-Ritz on the six rigid-body motions gives upper bounds of the six lowest
    # eigenvalues (Courant-Fischer); round-off of both solves is ~1e-10 relative.
    assert np.all(f <= bound * (1 + 1e-10))
    # the mounts (3e5/8e5 N/m) are much softer than the welded box, so the bound is
    # close: measured 0.1-1.9 % above; 5 % would be exceeded if the plates' flexibility
    # entered the mount modes
    assert np.all(f >= 0.95 * bound)
    assert result["freq_hz"][6] > 1.5 * bound[-1]  # then the box's own modes begin


def test_box_example_writes_mixed_vtu_and_images(box_run):
    _, result = box_run
    model = result["model"]
    back = meshio.read(result["vtu"])
    assert [c.type for c in back.cells] == ["line", "quad"]
    assert len(back.cells_dict["quad"]) == len(model.shells.cells["quad"])
    assert "mode_12_displacement" in back.point_data
    assert [p.name for p in result["images"]] == ["mode_01.png", "mode_02.png"]


def _bore_check(mesh, bore, centre, radius):
    nodes = mesh.points[mesh.nodes_of(bore)]
    centre = mesh.points[mesh.nodes_of(centre)[0]]
    # bound: Gmsh places the nodes of a circle on the circle (OpenCASCADE geometry): round-off
    assert_allclose(np.linalg.norm(nodes - centre, axis=1), radius, rtol=1e-9)


def test_welded_box_mesh_groups():
    mesh = fm.read_mesh(MESHES / "welded_box_frame.msh")
    assert mesh.n_nodes < 3000
    assert {"top_plate", "walls", "rib", "stiffeners", "bore"} <= set(mesh.cell_sets)
    assert {f"foot_{i}" for i in range(1, 5)} | {"feet", "bearing"} <= set(mesh.node_sets)
    # bound: mesh coordinates on a plane of the geometry: ~eps of O(1) values
    assert_allclose(mesh.points[mesh.node_sets["feet"]][:, 2], 0.0, atol=1e-12)
    _bore_check(mesh, "bore", "bearing", 0.09)
    # the stiffener ring lies at z = 0.3 m on the walls and shares their nodes
    ring = mesh.nodes_of("stiffeners")
    # bound: mesh coordinates on a plane of the geometry: ~eps of O(1) values
    assert_allclose(mesh.points[ring, 2], 0.3, atol=1e-12)
    assert np.isin(ring, mesh.nodes_of("walls")).all()


def test_c_frame_press_mesh_mass():
    mesh = fm.read_mesh(MESHES / "c_frame_press.msh")
    assert mesh.n_nodes < 3000
    t = {"side_plates": 0.04, "back_plate": 0.03, "throat": 0.03, "table": 0.05,
         "crown": 0.05}
    model = fm.build_model(mesh, shells={k: fm.ShellProperty(v, STEEL) for k, v in t.items()},
                           supports=[fm.Support("feet")])
    # areas from meshes/c_frame_press.geo: D, Hc, B = 1.0, 2.0, 0.6 m, throat gap
    # (D - xg) x (z2 - z1) = 0.6 x 0.6 m open to the front
    area = {"side_plates": 2 * (1.0 * 2.0 - 0.6 * 0.6), "back_plate": 0.6 * 2.0,
            "throat": 0.6 * 0.6, "table": 0.6 * 0.6, "crown": 0.6 * 0.6}
    mass = STEEL.rho * sum(t[k] * area[k] for k in t)
    # flat elements: round-off of a sum of n_dof terms, as in test_box_example_mass
    assert_allclose(model.total_mass(), mass, rtol=model.n_dof * EPS)
    for name in ("table_centre", "ram"):
        assert mesh.node_sets[name].size == 1  # a mesh node of the plates
    assert model.n_free == model.n_dof - 4 * 6


def test_side_wall_mesh_mixes_quads_and_triangles():
    example = _load("shell_frame_modes")
    mesh = example.edges_to_node_sets(fm.read_mesh(MESHES / "side_wall.msh"),
                                      ["bore_1", "bore_2", "base"])
    assert mesh.n_nodes < 3000
    assert len(mesh.cells["quad"]) > 100
    assert len(mesh.cells["triangle"]) > 100
    assert len(mesh.cells["line"]) == 0
    _bore_check(mesh, "bore_1", "bearing_1", 0.08)
    _bore_check(mesh, "bore_2", "bearing_2", 0.065)
    model = fm.build_model(mesh, shells={"wall": fm.ShellProperty(0.02, STEEL)},
                           supports=[fm.Support("base")],
                           interpolating_links=[fm.InterpolatingLink("bearing_1", "bore_1"),
                                                fm.InterpolatingLink("bearing_2", "bore_2")])
    # plate area 1.6 x 1.0 m minus the two bores (polygons of their nodes)
    holes = sum(_polygon_area(mesh.points[mesh.nodes_of(b)][:, [0, 2]],
                              mesh.points[mesh.nodes_of(c)[0]][[0, 2]])
                for b, c in (("bore_1", "bearing_1"), ("bore_2", "bearing_2")))
    # bound: consistent mass integrated exactly: ~n eps
    assert_allclose(model.total_mass(), STEEL.rho * 0.02 * (1.6 - holes), rtol=1e-12)


def test_shell_benchmark_smoke(tmp_path):
    # benchmarks/shell_modes.py at its tiny size (no timing assertions): the wrappers are
    # reached and the references agree
    spec = importlib.util.spec_from_file_location("shell_modes",
                                                  ROOT / "benchmarks" / "shell_modes.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    mesh = module.box_girder(2)
    assert mesh.n_nodes == 10 * 2 * (10 * 2 + 1)  # perimeter rings x rings
    (row,) = module.main(sizes=("tiny",), out_file=tmp_path / "shell.txt", echo=False)
    # box_girder(1): 10 x 11 nodes, the two end rings of 10 nodes clamped
    assert (row["dofs"], row["free_dofs"], row["elements"]) == (660, 540, 100)
    assert row["sturm_count"] == row["n_modes"] >= 20
    # both references solve the same pencil; dense LAPACK's round-off on this thin-shell
    # pencil is ~2e-9 (the sparse solvers agree to ~1e-12), so 1e-7 hides no wrong mode
    assert all(r["max_rel_err"] < 1e-7 for r in row["references"])
    assert "Reference" in (tmp_path / "shell.txt").read_text()
