"""Supports and rigid links (exact elimination ``u = T u_free``).

References are independent of :mod:`femmech.fe.constraints`: the rigid-body kinematics
``u_s = u_m + θ_m × r``, ``θ_s = θ_m`` (small rotations) are evaluated here with
``np.cross``, and "rigid" is approached by making the linked part of a beam model
stiffer and stiffer (the difference must fall like 1/stiffness).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
from numpy.testing import assert_allclose, assert_array_equal

import femmech as fm
from femmech.fe import sections

EPS = np.finfo(float).eps
STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)
SECTION = sections.circle(0.03)
# cantilever along x (nodes 0-4), tip node 4 carries an arm to three off-axis nodes
ARM_POINTS = np.array([[0.0, 0, 0], [0.25, 0, 0], [0.5, 0, 0], [0.75, 0, 0], [1.0, 0, 0],
                       [1.0, 0.3, 0.0], [1.0, 0.0, -0.25], [1.2, 0.1, 0.1]])
CANTILEVER = np.array([[0, 1], [1, 2], [2, 3], [3, 4]])
ARM = np.array([[4, 5], [4, 6], [4, 7]])
SLAVES = np.array([5, 6, 7])
MASSES = [fm.PointMass(5, 2.0, [0.01, 0.02, 0.03]), fm.PointMass(6, 1.5),
          fm.PointMass(7, 3.0, [0.02, 0.02, 0.01])]


def rigid_motion(points, master, nodes, u_master):
    """Full 6-DOF motion (len(nodes), 6) of ``nodes`` rigidly attached to ``master``."""
    r = points[nodes] - points[master]
    return np.column_stack([u_master[:3] + np.cross(u_master[3:], r),
                            np.tile(u_master[3:], (len(nodes), 1))])


def hand_transform(points, n_nodes, free_nodes, links):
    """Dense T (6 n_nodes, 6 len(free_nodes)) built column by column from rigid motions.

    ``links`` maps a master node (in free_nodes) to its slave nodes; other nodes are fixed.
    """
    T = np.zeros((6 * n_nodes, 6 * len(free_nodes)))
    for j, node in enumerate(free_nodes):
        for c in range(6):
            col = 6 * j + c
            T[6 * node + c, col] = 1.0
            slaves = links.get(node, [])
            if slaves:
                motion = rigid_motion(points, node, np.array(slaves), np.eye(6)[c])
                for s, row in zip(slaves, motion, strict=True):
                    T[6 * s:6 * s + 6, col] = row
    return T


def arm_model(factor=None, support=True):
    """Cantilever + arm: rigid link if ``factor`` is None, else beams ``factor`` x stiffer."""
    supports = [fm.Support(0)] if support else []
    prop = fm.BeamProperty(SECTION, STEEL)
    if factor is None:
        mesh = fm.Mesh.from_lines(ARM_POINTS, CANTILEVER)
        return fm.build_model(mesh, {"all": prop}, masses=MASSES, supports=supports,
                              rigid_links=[fm.RigidLink(4, SLAVES)])
    lines = np.vstack([CANTILEVER, ARM])
    mesh = fm.Mesh.from_lines(ARM_POINTS, lines, {"beam": [0, 1, 2, 3], "arm": [4, 5, 6]})
    stiff = fm.Material(E=factor * STEEL.E, nu=0.3, rho=0.0)  # massless: masses are lumped
    return fm.build_model(mesh, {"beam": prop, "arm": fm.BeamProperty(SECTION, stiff)},
                          masses=MASSES, supports=supports)


def static(model, loads):
    """Full displacement vector for nodal loads {node: (6,)} (N, N m)."""
    f = np.zeros(model.n_dof)
    for node, value in loads.items():
        f[6 * node:6 * node + 6] = value
    u_free = np.linalg.solve(model.K_free.toarray(), model.T.T @ f)
    return model.expand(u_free)


LOADS = {6: [10.0, -20.0, 30.0, 1.0, 2.0, -3.0], 7: [0.0, 5.0, 0.0, 0.0, 0.0, 4.0]}


# ---------------------------------------------------------------------------- rigid links


def test_rigid_link_static_slaves_move_rigidly():
    model = arm_model()
    u = static(model, LOADS).reshape(-1, 6)
    # u_s = u_m + θ_m × r, θ_s = θ_m; round-off relative to the largest displacement
    assert_allclose(u[SLAVES], rigid_motion(ARM_POINTS, 4, SLAVES, u[4]), rtol=0,
                    atol=100 * EPS * np.abs(u).max())


def test_stiff_arm_converges_to_rigid_link_like_one_over_stiffness():
    u_rigid = static(arm_model(), LOADS)
    factors = np.array([1e2, 1e3, 1e4, 1e6])
    diffs = np.array([np.abs(static(arm_model(f), LOADS) - u_rigid).max() for f in factors])
    diffs /= np.abs(u_rigid).max()
    # the arm's own compliance makes the difference c / factor (c ≈ 0.07 here); it must
    # drop 10x per decade (1 %: the next term of the expansion is O(1/factor²))
    assert_allclose(diffs[:2] / diffs[1:3], 10.0, rtol=1e-2)
    assert diffs[2] < 1e-5
    # at 1e6 the stiff model is limited by its own round-off, eps cond(K) ≈ 3e-4 (cond 1.2e12
    # against 6.8e5 for the rigid link): still within 1e-4 of the exact elimination
    assert diffs[3] < 1e-4


def test_stiff_arm_modes_converge_to_rigid_link_modes():
    f_rigid = fm.modes(arm_model(), n_modes=6).freq_hz
    factors = [1e2, 1e3, 1e4, 1e6]
    rel = np.array([np.abs(fm.modes(arm_model(f), n_modes=6).freq_hz / f_rigid - 1).max()
                    for f in factors])
    # error ∝ 1/factor (1 %: O(1/factor²) remainder); 1e6 is round-off limited as above
    assert_allclose(rel[:2] / rel[1:3], 10.0, rtol=1e-2)
    assert rel[3] < 1e-5


def test_rigid_link_modes_slaves_move_rigidly():
    result = fm.modes(arm_model(), n_modes=6)
    for i in range(result.n_modes):
        nodal = result.nodal(i)
        assert_allclose(nodal[SLAVES], rigid_motion(ARM_POINTS, 4, SLAVES, nodal[4]), rtol=0,
                        atol=100 * EPS * np.abs(nodal).max())


def test_free_free_with_rigid_links_has_six_rigid_body_modes():
    result = fm.modes(arm_model(support=False), n_modes=8)
    assert result.rigid.sum() == 6
    assert result.rigid[:6].all()
    # the first elastic mode is a genuine frequency (cantilever-like bending, ~10 Hz)
    assert result.freq_hz[6] > 1.0
    # rigid-body modes: slaves still follow the master
    for i in range(6):
        nodal = result.nodal(i)
        assert_allclose(nodal[SLAVES], rigid_motion(ARM_POINTS, 4, SLAVES, nodal[4]), rtol=0,
                        atol=100 * EPS * np.abs(nodal).max())


def _two_beams_linked():
    """Beam 0-1, rigid link 1 → 2 (offset (0, 0.4, 0.3)), beam 2-3; node 0 clamped."""
    points = np.array([[0.0, 0, 0], [1.0, 0, 0], [1.0, 0.4, 0.3], [2.0, 0.4, 0.3]])
    mesh = fm.Mesh.from_lines(points, [[0, 1], [2, 3]])
    model = fm.build_model(mesh, {"all": fm.BeamProperty(SECTION, STEEL)},
                           supports=[fm.Support(0)], rigid_links=[fm.RigidLink(1, [2])])
    return points, model


def test_transform_shape_and_entries_match_hand_elimination():
    points, model = _two_beams_linked()
    T_hand = hand_transform(points, 4, [1, 3], {1: [2]})
    assert model.T.shape == (24, 12)  # 24 DOFs - 6 fixed - 6 slave
    assert_array_equal(model.free, np.r_[6:12, 18:24])
    assert_allclose(model.T.toarray(), T_hand, rtol=0, atol=0)  # entries are offsets, exact


def test_no_penalty_reduced_matrices_equal_hand_elimination():
    points, model = _two_beams_linked()
    T_hand = hand_transform(points, 4, [1, 3], {1: [2]})
    K, M = model.K.toarray(), model.M.toarray()
    K_hand, M_hand = T_hand.T @ K @ T_hand, T_hand.T @ M @ T_hand
    # same products, only summation order differs: round-off of the largest entry
    assert_allclose(model.K_free.toarray(), K_hand, rtol=0, atol=100 * EPS * np.abs(K).max())
    assert_allclose(model.M_free.toarray(), M_hand, rtol=0, atol=100 * EPS * np.abs(M).max())
    # conditioning unaffected (a penalty of 1e6-1e8 x the stiffness would multiply it)
    cond = np.linalg.cond(model.K_free.toarray())
    assert_allclose(cond, np.linalg.cond(K_hand), rtol=1e-6)
    assert np.abs(model.K_free.toarray()).max() <= 2 * np.abs(K).max()


def test_rigid_link_by_group_names():
    mesh = fm.Mesh.from_lines(ARM_POINTS, CANTILEVER, node_sets={"hub": [4], "rim": SLAVES})
    model = fm.build_model(mesh, {"all": fm.BeamProperty(SECTION, STEEL)}, masses=MASSES,
                           supports=[fm.Support(0)], rigid_links=[fm.RigidLink("hub", "rim")])
    assert_allclose(model.K_free.toarray(), arm_model().K_free.toarray(), rtol=0, atol=0)


def _link_errors_mesh():
    points = np.array([[0.0, 0, 0], [1.0, 0, 0], [1.0, 1, 0], [1.0, 2, 0], [2.0, 0, 0]])
    return fm.Mesh.from_lines(points, [[0, 1], [1, 4]])


@pytest.mark.parametrize(("links", "supports", "match"), [
    ([fm.RigidLink(1, [2, 3]), fm.RigidLink(4, [3])], [],
     r"node 3 ux is dependent in two constraints: rigid link \(master 1\) and rigid link"),
    ([fm.RigidLink(1, [2]), fm.RigidLink(2, [1]), fm.RigidLink(4, [3])], [],
     "constraints form a cycle"),
    ([fm.RigidLink(1, [2, 3])], [fm.Support(3, ["uy"])], "node 3 uy is both supported"),
    ([fm.RigidLink(1, [])], [], "rigid link with master 1 has no slave nodes"),
    ([fm.RigidLink(1, [1])], [], "rigid link with master 1 has no slave nodes"),
    ([fm.RigidLink(1, [2, 9])], [], "rigid link slaves: node 9 does not exist"),
    ([fm.RigidLink("nowhere", [2, 3])], [], "rigid link master: unknown group 'nowhere'"),
])
def test_rigid_link_errors(links, supports, match):
    # (a chain, where a master is the slave of another link, is valid: see
    # test_chained_rigid_links_move_rigidly)
    mesh = _link_errors_mesh()
    with pytest.raises(ValueError, match=match):
        fm.build_model(mesh, {"all": fm.BeamProperty(SECTION, STEEL)}, supports=supports,
                       rigid_links=links)


# ------------------------------------------------------------------------------- supports


def _support_mesh():
    points = np.column_stack([np.linspace(0, 2, 5), np.zeros(5), np.zeros(5)])
    lines = np.column_stack([np.arange(4), np.arange(1, 5)])
    return fm.Mesh.from_lines(points, lines, {"left_half": [0, 1], "right_half": [2, 3]},
                              node_sets={"root": [0], "ends": [0, 4]})


def _fixed(supports):
    mesh = _support_mesh()
    prop = fm.BeamProperty(SECTION, STEEL)
    model = fm.build_model(mesh, {"left_half": prop, "right_half": prop}, supports=supports)
    fixed = np.setdiff1d(np.arange(model.n_dof), model.free)
    # without rigid links T is a selection of identity columns
    assert_allclose(model.T.toarray(), np.eye(model.n_dof)[:, model.free], rtol=0, atol=0)
    return fixed


@pytest.mark.parametrize(("supports", "expected"), [
    ([fm.Support("root")], np.arange(6)),
    ([fm.Support("ends", "translations")], np.r_[0:3, 24:27]),
    ([fm.Support("left_half")], np.arange(18)),  # cell set: nodes 0, 1, 2
    ([fm.Support([1, 3], ["ux", "rz"])], [6, 11, 18, 23]),
    ([fm.Support(2, "rotations")], [15, 16, 17]),
    ([fm.Support(4, "uz")], [26]),
    ([fm.Support(np.int64(4), [0, 5])], [24, 29]),
    ([fm.Support("root", ["ux"]), fm.Support("root", ["ux", "uy"])], [0, 1]),  # overlaps ok
])
def test_supports_fix_the_named_dofs(supports, expected):
    assert_array_equal(_fixed(supports), expected)


@pytest.mark.parametrize(("support", "error", "match"), [
    (fm.Support(0, "uw"), ValueError, r"unknown DOF component 'uw'.*'ux'"),
    (fm.Support(0, ["ux", "tx"]), ValueError, "unknown DOF component 'tx'"),
    (fm.Support(0, [6]), ValueError, "unknown DOF component 6"),
    (fm.Support("rot"), ValueError, r"unknown group 'rot'.*'ends'.*'left_half'.*'root'"),
    (fm.Support(7), ValueError, "support: node 7 does not exist"),
    (fm.Support(-1), ValueError, "support: node -1 does not exist"),
    (fm.Support(1.5), TypeError, "support: nodes must be a group name or node indices"),
])
def test_support_errors(support, error, match):
    with pytest.raises(error, match=match):
        _fixed([support])


def test_fully_supported_model_has_no_free_dofs_for_modes():
    mesh = _support_mesh()
    prop = fm.BeamProperty(SECTION, STEEL)
    model = fm.build_model(mesh, {"left_half": prop, "right_half": prop},
                           supports=[fm.Support("left_half"), fm.Support("right_half")])
    assert model.n_free == 0
    with pytest.raises(ValueError, match="no free DOF"):
        fm.modes(model, n_modes=1)


def test_rigid_link_dense_eigenproblem_matches_hand_elimination():
    points, model = _two_beams_linked()
    T_hand = hand_transform(points, 4, [1, 3], {1: [2]})
    K, M = model.K.toarray(), model.M.toarray()
    ref = sla.eigh(T_hand.T @ K @ T_hand, T_hand.T @ M @ T_hand, eigvals_only=True)[:4]
    result = fm.modes(model, n_modes=4)
    # bound: dense LAPACK on both sides: round-off, relative to ω²
    assert_allclose(result.omega2[:4], ref, rtol=1e-9)


def test_chained_rigid_links_move_rigidly():
    # Link 1 -> 2 and link 2 -> 3: node 3 follows node 1 through node 2, so both slaves
    # move with node 1 as one rigid body: u_s = u_1 + θ_1 × (x_s - x_1), θ_s = θ_1.
    mesh = _link_errors_mesh()
    model = fm.build_model(mesh, {"all": fm.BeamProperty(SECTION, STEEL)},
                           rigid_links=[fm.RigidLink(1, [2]), fm.RigidLink(2, [3])])
    rng = np.random.default_rng(3)
    u = model.expand(rng.standard_normal(model.n_free)).reshape(-1, 6)
    for s in (2, 3):
        r = mesh.points[s] - mesh.points[1]
        # bound: a product of exact sparse matrices: round-off only
        assert_allclose(u[s, :3], u[1, :3] + np.cross(u[1, 3:], r), rtol=0, atol=1e-14)
        # bound: a product of exact sparse matrices: round-off only, O(1) entries
        assert_allclose(u[s, 3:], u[1, 3:], rtol=0, atol=1e-14)
