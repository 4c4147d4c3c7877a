"""Model checks: inputs that give wrong numbers without an error are reported.

Nearly coincident nodes that split a frame, pieces that are free bodies by accident and
unit mix-ups give a ModelWarning from build_model and fm.modes, naming nodes, distances
and values, and lines in ``femmech check`` and the ``femmech run`` log; merging the
nodes (Mesh.merge_nodes, scene key merge_nodes) restores the intended model. Consistent
models in m-kg-s and mm-t-s stay silent (pyproject turns any FemmechWarning into an
error, so every other test and example checks that too).
"""

import json
import tomllib
import warnings

import numpy as np
import pytest
from numpy.testing import assert_allclose

import femmech as fm
from femmech.cli import main
from femmech.errors import SceneError
from femmech.fe import checks, sections
from femmech.fe.generators import members_frame
from femmech.fe.mesh import merged_node_index
from femmech.fe.model import model_findings
from femmech.scene.build import prepare
from femmech.scene.load import Scene
from femmech.scene.run import run_scene

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0, name="steel")
RHS = sections.rectangular_hollow(0.06, 0.08, 0.004)
PORTAL = {"joints": {"foot_l": [0.0, 0.0, 0.0], "top_l": [0.0, 0.0, 1.0],
                     "top_r": [1.5, 0.0, 1.0], "foot_r": [1.5, 0.0, 0.0]},
          "members": [{"group": "columns", "chain": ["foot_l", "top_l"], "divisions": 6},
                      {"group": "beam", "chain": ["top_l", "top_r"], "divisions": 8},
                      {"group": "columns", "chain": ["top_r", "foot_r"], "divisions": 6}]}
"""Portal frame 1.5 m x 1 m, clamped feet."""


def portal(gap: float = 0.0, scale: float = 1.0) -> fm.Mesh:
    """The portal; with ``gap`` > 0 the beam starts at its own joint ``top_l2``, ``gap``
    metres from the column's top ``top_l`` (a split joint: node 2 beside node 1)."""
    joints = {k: scale * np.array(v) for k, v in PORTAL["joints"].items()}
    members = [dict(m) for m in PORTAL["members"]]
    if gap:
        joints = {"foot_l": joints["foot_l"], "top_l": joints["top_l"],
                  "top_l2": joints["top_l"] + [gap, 0.0, 0.0], "top_r": joints["top_r"],
                  "foot_r": joints["foot_r"]}
        members[1]["chain"] = ["top_l2", "top_r"]
    return members_frame(joints, members, {"feet": ["foot_l", "foot_r"]})


def build(mesh, material=STEEL, section=RHS, **kwargs):
    prop = fm.BeamProperty(section, material)
    kwargs.setdefault("supports", [fm.Support("feet")])
    return fm.build_model(mesh, {"columns": prop, "beam": prop}, **kwargs)


def warned(fn, *args, **kwargs) -> str:
    """The ModelWarning messages of ``fn(*args, **kwargs)`` joined by " | " (at least one;
    pytest.warns re-raises warnings that a ``match`` misses, so all are collected)."""
    with pytest.warns(fm.ModelWarning) as record:
        fn(*args, **kwargs)
    assert all(issubclass(w.category, fm.ModelWarning) for w in record)
    return " | ".join(str(w.message) for w in record)


def silent(fn, *args, **kwargs):
    """Call ``fn`` with every warning turned into an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return fn(*args, **kwargs)


# --- near nodes ----------------------------------------------------------------------------

@pytest.mark.parametrize("gap", [1e-8, 1e-6, 1e-4])
def test_split_joint_is_reported_and_merging_restores_the_frame(gap):
    """The issue's probe: members meeting at two nodes ``gap`` apart leave the beam end
    free, so the first frequency drops from 32.7 Hz to 12.6 Hz without an error. The
    warning names nodes 1 and 2 and their distance; after merge_nodes the model is the
    intact portal (reference: the portal built with one joint)."""
    intact = silent(fm.modes, silent(build, portal()), n_modes=2)
    split_mesh = portal(gap)
    with pytest.warns(fm.ModelWarning, match=rf"nodes 1 and 2 are {gap:.3g} m apart"):
        split = build(split_mesh)
    assert fm.modes(split, n_modes=1).freq_hz[0] < 0.5 * intact.freq_hz[0]
    merged = split_mesh.merge_nodes(2 * gap)
    assert merged.n_nodes == split_mesh.n_nodes - 1
    result = silent(fm.modes, silent(build, merged), n_modes=2)
    # the beam's interior nodes stay where the split mesh put them (up to gap off their
    # intact places): frequencies agree to ~gap / length (measured 5e-9 at gap = 1e-4)
    # bound: floor of rtol where gap = 0: the same model, eigensolver round-off eps λ_max/λ
    assert_allclose(result.freq_hz, intact.freq_hz, rtol=max(gap, 1e-12))


def test_near_nodes_lists_ids_and_distances_and_skips_joined_and_fine_meshes():
    points = np.array([[0, 0, 0], [1, 0, 0], [1 + 3e-7, 0, 0], [2, 0, 0],
                       [2, 1e-6, 0], [3, 0, 0], [3, 2e-3, 0], [3.1, 2e-3, 0]], dtype=float)
    cells = {"line": np.array([[0, 1], [2, 3], [3, 5], [4, 5], [5, 6], [6, 7]])}
    pairs, dist = checks.near_nodes(points, cells)
    # 1-2: split (3e-7 m); 3-4 (1e-6 m) are joined by no element either; 5-6 share an
    # element; 3.1 m model: default tol 3.1e-4 m
    assert pairs.tolist() == [[1, 2], [3, 4]]
    assert_allclose(dist, [3e-7, 1e-6], rtol=1e-9)  # bound: coordinates' round-off
    pairs, _ = checks.near_nodes(points, cells, joined=[(4, 3)])  # e.g. a spring
    assert pairs.tolist() == [[1, 2]]
    assert checks.near_nodes(points, cells, tol=1e-7)[0].size == 0
    # a pair 2 mm apart next to 0.1 m elements is not near (local fraction 1e-2); with
    # elements of 1 mm nodes 2 mm apart are neighbours of a fine mesh
    fine = np.array([[0, 0, 0], [1e-3, 0, 0], [0, 2e-3, 0], [1e-3, 2e-3, 0], [5, 0, 0]])
    lines = {"line": np.array([[0, 1], [2, 3], [1, 4]])}
    assert checks.near_nodes(fine, lines, tol=0.01)[0].size == 0


def test_merge_nodes_remaps_cells_and_sets_and_names_collapsing_cells():
    mesh = portal(1e-6)
    merged = mesh.merge_nodes(1e-5)
    new = merged_node_index(mesh.points, 1e-5)
    assert new[:5].tolist() == [0, 1, 1, 2, 3]  # node 2 joins node 1, the rest move down
    assert_allclose(merged.points, np.delete(mesh.points, 2, axis=0))
    assert merged.node_sets["top_l2"].tolist() == [1]
    assert merged.node_sets["feet"].tolist() == [0, 3]  # joints foot_l (0), foot_r (4 → 3)
    assert np.array_equal(merged.cells["line"], new[mesh.cells["line"]])
    assert mesh.merge_nodes(1e-5, keep=[2]).n_nodes == mesh.n_nodes  # kept apart
    with pytest.raises(ValueError, match=r"line cell \d+ \(nodes .*\) would collapse"):
        mesh.merge_nodes(0.2)  # elements are 0.17-0.19 m long


# --- loose parts -------------------------------------------------------------------------

def test_loose_piece_and_unattached_mass_are_reported():
    mesh = portal()
    extra = np.array([[0.5, 1.0, 0.0], [1.0, 1.0, 0.0], [2.0, 2.0, 2.0]])  # a beam, a node
    lines = np.vstack([mesh.cells["line"], [[mesh.n_nodes, mesh.n_nodes + 1]]])
    sets = {**mesh.cell_sets, "beam": {"line": np.r_[mesh.cell_sets["beam"]["line"],
                                                     len(lines) - 1]}}
    loose = fm.Mesh(np.vstack([mesh.points, extra]), {"line": lines}, sets, mesh.node_sets)
    n = mesh.n_nodes
    with pytest.warns(fm.ModelWarning) as record:
        build(loose, masses=[fm.PointMass(n + 2, 5.0)])
    text = [str(w.message) for w in record]
    assert any(f"nodes {n}, {n + 1} (2 nodes): a piece that no element" in t for t in text)
    assert any(f"nodes {n + 2} (1 node): a piece that no element" in t for t in text), text
    # a spring to the ground holds the mass: only the beam is loose
    found = model_findings(loose, {"columns": fm.BeamProperty(RHS, STEEL),
                                   "beam": fm.BeamProperty(RHS, STEEL)},
                           masses=[fm.PointMass(n + 2, 5.0)],
                           springs=[fm.Spring(n + 2, None, 1e5)], supports=[fm.Support("feet")])
    assert [f.nodes.tolist() for f in found] == [[n, n + 1]]
    # an anchor (e.g. a mechanism attached to the beam) holds the beam
    found = model_findings(loose, {"columns": fm.BeamProperty(RHS, STEEL),
                                   "beam": fm.BeamProperty(RHS, STEEL)},
                           springs=[fm.Spring(n + 2, None, 1e5)],
                           supports=[fm.Support("feet")], anchors=[n])
    assert found == ()


def test_many_loose_pieces_are_summed_up():
    """Eight unattached point-mass nodes beside a supported beam: five named, three
    counted."""
    found = checks.loose_parts(10, {"line": np.array([[0, 1]])}, anchored=[0])
    assert [f.nodes.tolist() for f in found[:5]] == [[2], [3], [4], [5], [6]]
    assert found[5].message == "3 more free pieces (3 nodes)"
    assert found[5].nodes.tolist() == [7, 8, 9]


def test_free_model_in_two_pieces_is_reported():
    mesh = fm.Mesh.from_lines([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], [[0, 1], [2, 3]])
    with pytest.warns(fm.ModelWarning, match=r"no support and falls into 2 pieces.*nodes 0,"
                                             r" 1 \(2 nodes\); nodes 2, 3 \(2 nodes\)"):
        fm.build_model(mesh, {"all": fm.BeamProperty(RHS, STEEL)})
    silent(fm.build_model, mesh, {"all": fm.BeamProperty(RHS, STEEL)},
           springs=[fm.Spring(1, 2, 1e6)])


# --- units -------------------------------------------------------------------------------

def test_millimetre_geometry_with_si_steel_warns():
    """The portal drawn in mm (1500 x 1000) with E in Pa, ρ in kg/m³ and the section in
    m: 1.8e3 "m" across."""
    with pytest.warns(fm.ModelWarning, match=r"1803 m across .* is the geometry in mm"):
        build(portal(scale=1e3))


def test_mm_t_s_material_on_metre_geometry_warns():
    mmts = fm.Material(E=2.1e5, nu=0.3, rho=7.85e-9, name="steel_mm")
    with pytest.warns(fm.ModelWarning, match=r"mm-t-s units .* only 1.803 across .* in m\?"):
        build(portal(), material=mmts)


def test_mixed_and_inconsistent_materials_warn():
    mpa = fm.Material(E=2.1e5, nu=0.3, rho=7850.0, name="MPa_kg")  # N/mm² with kg/m³
    with pytest.warns(fm.ModelWarning, match=r"'MPa_kg'.* wave speed sqrt\(E/rho\) = 5.17"):
        build(portal(), material=mpa)
    mmts = fm.Material(E=2.1e5, nu=0.3, rho=7.85e-9, name="steel_mm")
    prop = fm.BeamProperty(RHS, STEEL)
    with pytest.warns(fm.ModelWarning, match=r"\['steel'\] are in Pa .* \['steel_mm'\]"):
        fm.build_model(portal(), {"columns": prop, "beam": fm.BeamProperty(RHS, mmts)},
                       supports=[fm.Support("feet")])


def test_section_in_millimetres_warns():
    """RHS 60 x 80 x 4 given in mm on a frame in m: an 80 m deep section on members of
    1-1.8 m."""
    section = sections.rectangular_hollow(60.0, 80.0, 4.0)
    text = warned(build, portal(), section=section)
    assert "'columns': the section is 80 m deep but the group's elements span only 1.803 m" \
        in text
    assert "'beam': the section is 80 m deep but the group's elements span only 1.5 m" in text


def test_point_mass_orders_off_warns():
    mesh = portal()
    node = int(mesh.node_sets["top_r"][0])
    # frame: 3.5 m of RHS, A = 1.055e-3 m², 7850 kg/m³: 29 kg; 50 t is 1.7e3 times that
    text = warned(build, mesh, masses=[fm.PointMass(node, 5e4)])
    assert f"mass of all elements (29.01 kg, outside [1e-07, 1000] times): 5e+04 kg at node" \
        f" {node} (1.72e+03 times)" in text
    silent(build, mesh, masses=[fm.PointMass(node, 500.0)])  # a motor: 17 times


def test_absurd_frequencies_warn():
    """ρ in t/mm³ with E in Pa and lengths in m: frequencies 1e6 times too high (and a
    wave speed of 5e9)."""
    t_per_mm3 = fm.Material(E=210e9, nu=0.3, rho=7.85e-9, name="steel")
    with pytest.warns(fm.ModelWarning) as record:
        fm.modes(build(portal(), material=t_per_mm3), n_modes=2)
    text = " ".join(str(w.message) for w in record)
    assert "wave speed sqrt(E/rho) = 5.17e+09" in text
    assert "first elastic natural frequency is 3.271e+07 Hz" in text
    low = checks.frequency_findings(np.array([0.0, 2e-4, 5.0]), np.array([True, False, False]),
                                    supported=True)
    assert "is 0.0002 Hz, below 0.001 Hz" in low[0].message
    assert checks.frequency_findings(np.array([2e-4]), np.array([False]), False) == []


@pytest.mark.parametrize(("L", "Mu"), [(1.0, 1.0), (1e3, 1e-3)])
def test_consistent_models_in_si_and_mm_t_s_are_silent(L, Mu):
    """The portal with a 100 kg mass in m-kg-s and in mm-t-s (lengths x1e3, masses x1e-3,
    E x1e-6, ρ x1e-12): no warning, the same frequencies (units conversion is exact up to
    round-off: measured 1e-13)."""
    steel = fm.Material(E=210e9 * Mu / L, nu=0.3, rho=7850.0 * Mu / L**3)
    section = sections.rectangular_hollow(0.06 * L, 0.08 * L, 0.004 * L)
    mesh = portal(scale=L)
    node = int(mesh.node_sets["top_r"][0])
    model = silent(build, mesh, material=steel, section=section,
                   masses=[fm.PointMass(node, 100.0 * Mu)])
    result = silent(fm.modes, model, n_modes=3)
    ref = silent(fm.modes, silent(build, portal(), masses=[fm.PointMass(node, 100.0)]), n_modes=3)
    # bound: the same model after the check: identical matrices, round-off eps λ_max/λ
    assert_allclose(result.freq_hz, ref.freq_hz, rtol=1e-9)


# --- scenes: femmech check and femmech run -----------------------------------------------

def scene_text(gap: float, merge: str | None = None, support_nodes='"feet"') -> str:
    """The portal as a scene file (members generator), split by ``gap`` (m) if > 0."""
    top_l2 = f"top_l2 = [{gap!r}, 0.0, 1.0]" if gap else ""
    beam = '"top_l2"' if gap else '"top_l"'
    merge_line = f'merge_nodes = "{merge}"' if merge else ""
    sections_ = "".join(f"""
[parts.frame.sections.{g}]
section = "rectangular_hollow"
width = "60 mm"
height = "80 mm"
wall = "4 mm"
material = "steel"
""" for g in ("columns", "beam"))
    return f"""
[scene]
name = "portal"

[materials.steel]
E = "210 GPa"
nu = 0.3
rho = "7850 kg/m^3"

[parts.frame]
{merge_line}

[parts.frame.generator]
kind = "members"
node_sets = {{feet = ["foot_l", "foot_r"]}}

[parts.frame.generator.joints]
foot_l = [0.0, 0.0, 0.0]
top_l = [0.0, 0.0, 1.0]
{top_l2}
top_r = [1.5, 0.0, 1.0]
foot_r = [1.5, 0.0, 0.0]

[[parts.frame.generator.members]]
group = "columns"
chain = ["foot_l", "top_l"]
divisions = 6

[[parts.frame.generator.members]]
group = "beam"
chain = [{beam}, "top_r"]
divisions = 8

[[parts.frame.generator.members]]
group = "columns"
chain = ["top_r", "foot_r"]
divisions = 6
{sections_}
[[parts.frame.supports]]
nodes = {support_nodes}

[analyses.modes]
n_modes = 2
vtu = false
"""


def write_scene(path, text: str):
    path.write_text(text, encoding="utf-8")
    return path


def test_scene_check_and_run_report_near_nodes_and_merge_fixes_them(tmp_path, capsys):
    path = write_scene(tmp_path / "split.toml", scene_text(1e-6))
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "split.toml: warning: [parts.frame] near nodes:" in out
    assert "nodes 1 and 2 are 1e-06 m apart" in out
    result = run_scene(path, tmp_path / "out", cache_dir=None)
    assert any("nodes 1 and 2 are 1e-06 m apart" in line for line in result.log)
    assert "nodes 1 and 2 are 1e-06 m apart" in (tmp_path / "out" / "run.log").read_text()
    merged = run_scene(write_scene(tmp_path / "merged.toml", scene_text(1e-6, "0.01 mm")),
                       tmp_path / "out2", cache_dir=None)
    intact = run_scene(write_scene(tmp_path / "intact.toml", scene_text(0.0)),
                       tmp_path / "out3", cache_dir=None)
    assert not any("warning" in line for line in merged.log + intact.log)
    hz = [json.loads((tmp_path / d / "results.json").read_text())["modes"]
          for d in ("out", "out2", "out3")]
    # merged: the intact portal's numbers up to its beam nodes' offset, gap / length ~ 1e-6
    # (measured 2e-12)
    assert_allclose(hz[1]["freq_hz"], hz[2]["freq_hz"], rtol=1e-6)
    assert hz[0]["freq_hz"][0] < 0.5 * hz[2]["freq_hz"][0]  # split: 12.6 Hz, not 32.7


def test_scene_merge_refuses_node_indices():
    scene = Scene.from_dict(tomllib.loads(scene_text(1e-6, "0.01 mm", "[0, 3]")))
    with pytest.raises(SceneError, match=r"\[parts.frame\] merge_nodes: node indices change"
                                         r" when nodes are merged.*\(0, 3\)"):
        prepare(scene)
    found = prepare(Scene.from_dict(tomllib.loads(scene_text(1e-6)))).findings["frame"]
    assert [f.kind for f in found] == ["near nodes"]
    assert found[0].nodes.tolist() == [1, 2]


def test_near_nodes_of_a_dense_cluster_stay_cheap():
    # 3 000 coincident node pairs stacked on one point make 4.5 million pairs closer than
    # the tolerance; the check must name the nodes without listing every pair (it took
    # 29 s and gigabytes for a 10-million-pair mesh before)
    from femmech.fe import checks
    rng = np.random.default_rng(0)
    n = 3000
    cluster = rng.normal(scale=1e-9, size=(n, 3))
    far = np.array([[1.0, 0.0, 0.0]])
    points = np.vstack([cluster, far])
    lines = np.column_stack([np.arange(n), np.full(n, n)])  # every node to the far node
    pairs, dist = checks.near_nodes(points, {"line": lines})
    assert len(pairs) <= checks.K_NEAREST * n
    assert set(np.unique(pairs)) == set(range(n))  # every clustered node is named
    assert np.all(dist < 1e-4)
    found = checks.near_node_findings(points, {"line": lines})
    assert len(found) == 1
    assert "and" in found[0].message
    assert found[0].message.count("apart") == checks.MAX_LISTED
