"""The chain model: assembled matrices against hand-built ones, ends, validation."""

import numpy as np
import pytest

from femmech.chain import Chain, End, chain, follower_unit, torsion_segment
from femmech.mechanisms import CamProfile, CamSegment, modified_sine

STROKE = 0.03


def cam() -> CamProfile:
    """Modified-sine rise 120°, dwell 60°, return 120°, dwell 60°; stroke 30 mm."""
    return CamProfile((CamSegment(np.radians(120), STROKE, modified_sine()),
                       CamSegment(np.radians(60)),
                       CamSegment(np.radians(120), -STROKE, modified_sine()),
                       CamSegment(np.radians(60))))


J_HUB, MASS, STIFF = 2e-3, 0.5, 2e5


@pytest.fixture(scope="module")
def unit():
    return follower_unit(cam(), J_HUB, MASS, STIFF)


def test_torsion_segment_formula():
    # k = G π d⁴ / (32 L), J = ρ π d⁴ L / 32 (solid round shaft, Roark Table 10.1 case 1)
    k, J = torsion_segment(0.5, 0.04, G=80e9, rho=7800.0)
    Ip = np.pi * 0.04**4 / 32
    # bound: k, J are the formulas evaluated in another order: a few eps
    assert k == pytest.approx(80e9 * Ip / 0.5, rel=1e-14)
    assert J == pytest.approx(7800.0 * Ip * 0.5, rel=1e-14)
    with pytest.raises(ValueError, match="bore"):
        torsion_segment(0.5, 0.04, bore=0.05)


def test_unit_matrices_follow_table_5_1(unit):
    # Table 5.1 case 1 frozen (Ω = 0, F2 = 0): M = [[J + m U'², m U'], [m U', m]], C = diag(0, c)
    phi = np.radians(60.0)  # mid-rise: U' at its largest
    U1 = cam()(phi, 1)
    M, C = unit.M(phi), unit.C(phi, 0.0)
    # bound: sympy-lambdified products of O(1) factors: a few ulps
    assert np.allclose(M, [[J_HUB + MASS * U1**2, MASS * U1], [MASS * U1, MASS]],
                       rtol=1e-13, atol=0)
    # bound: as above
    assert np.allclose(C, [[0, 0], [0, STIFF]], rtol=1e-13, atol=1e-12)


def test_two_unit_chain_matches_hand_assembly(unit):
    k, Js = torsion_segment(0.25, 0.04)
    ch = chain(unit, 2, 0.25, 0.04, phases=[0.0, np.pi / 2], left=End.elastic(5e4, 0.1),
               right=End.flywheel(0.05))
    phi = 0.4
    M, B, C = (A.toarray() for A in ch.sparse_matrices(phi))
    Mu, _, Cu = ch.unit_matrices(phi)
    # coordinates: θ0, q2 of unit 0, θ1, q2 of unit 1
    M_hand = np.zeros((4, 4))
    C_hand = np.zeros((4, 4))
    M_hand[np.ix_([0, 1], [0, 1])] += Mu[0]
    M_hand[np.ix_([2, 3], [2, 3])] += Mu[1]
    M_hand[0, 0] += Js / 2 + 0.1
    M_hand[2, 2] += Js / 2 + 0.05
    C_hand[np.ix_([0, 1], [0, 1])] += Cu[0]
    C_hand[np.ix_([2, 3], [2, 3])] += Cu[1]
    C_hand[np.ix_([0, 2], [0, 2])] += k * np.array([[1, -1], [-1, 1]])
    C_hand[0, 0] += 5e4
    # bound: the same sums in another order: a few ulps
    assert np.allclose(M, M_hand, rtol=1e-14, atol=0)
    # bound: as above
    assert np.allclose(C, C_hand, rtol=1e-14, atol=0)
    assert not B.any()
    assert np.allclose(ch.M(phi), M)
    assert np.allclose(ch.C(phi), C)
    assert ch.M(np.array([[0.1, 0.2]])).shape == (1, 2, 4, 4)


def test_clamped_end_removes_its_rotation(unit):
    ch = chain(unit, 3, 0.25, 0.04, left=End.fixed(), end_length=0.1)
    assert ch.node_dof.tolist() == [-1, 0, 2, 4, 6]
    assert ch.n == 7
    # the stub spring from the clamped node now holds node 1 to ground
    k_stub = torsion_segment(0.1, 0.04)[0]
    k = torsion_segment(0.25, 0.04)[0]
    C = ch.sparse_matrices(0.0)[2].toarray()
    # bound: one sum of two terms: 1 ulp
    assert C[0, 0] == pytest.approx(k_stub + k, rel=1e-14)
    # a unit on a clamped node keeps its follower
    ch2 = chain(unit, 2, 0.25, 0.04, left=End.fixed())
    assert ch2.unit_dofs.tolist() == [[-1, 0], [1, 2]]
    lam = np.linalg.eigvalsh(np.linalg.solve(ch2.M(0.0), ch2.C(0.0)))  # M, C at a dwell
    # bound: a dwell root is exactly c/m; eigh ~1e-13 relative
    assert np.isclose(np.sort(lam), STIFF / MASS, rtol=1e-9).sum() >= 1


def test_cells_give_equal_node_inertias(unit):
    ch = chain(unit, 5, 0.25, 0.04, cells=True, station_inertia=1e-3)
    # bound: sums of the same two doubles: 1 ulp
    assert np.allclose(ch.node_inertia, ch.node_inertia[0], rtol=1e-15)
    plain = chain(unit, 5, 0.25, 0.04, station_inertia=1e-3)
    # total inertia: N spacings of shaft (cells) against N − 1 (plain)
    Js = torsion_segment(0.25, 0.04)[1]
    # bound: a sum of N = 5 terms minus another: ~N eps of the sums, relative to Js
    assert ch.node_inertia.sum() - plain.node_inertia.sum() == pytest.approx(Js, rel=1e-12)


def test_large_chain_is_sparse_and_banded(unit):
    ch = chain(unit, 1000, 0.1, 0.04, phases=np.linspace(0, 2 * np.pi, 1000))
    M, _, C = ch.sparse_matrices(0.3)
    assert M.shape == (2000, 2000)
    rows, cols = C.nonzero()
    assert np.abs(rows - cols).max() <= 2  # node-by-node numbering: bandwidth 2
    assert C.nnz < 5 * ch.n


@pytest.mark.parametrize(("kwargs", "message"), [
    (dict(node_inertia=[1.0, -1.0], spring=[1.0], unit_node=[0], phase=0.0),
     r"node_inertia\[1\]"),
    (dict(node_inertia=[1.0, 1.0], spring=[0.0], unit_node=[0], phase=0.0), r"spring\[0\]"),
    (dict(node_inertia=[1.0, 1.0], spring=[1.0, 2.0], unit_node=[0], phase=0.0),
     "n_nodes - 1"),
    (dict(node_inertia=[1.0, 1.0], spring=[1.0], unit_node=[2], phase=0.0), "unit_node 2"),
    (dict(node_inertia=[1.0, 1.0], spring=[1.0], unit_node=[1, 1], phase=0.0),
     "same node"),
    (dict(node_inertia=[1.0, 1.0], spring=[1.0], unit_node=[0], phase=np.nan),
     r"phase\[0\]"),
    (dict(node_inertia=[1.0, 1.0], spring=[1.0], unit_node=[0], phase=0.0, attach=2),
     "attach"),
])
def test_bad_chain_names_the_item(unit, kwargs, message):
    with pytest.raises(ValueError, match=message):
        Chain(unit, **kwargs)


def test_bad_end_and_unit_parameters(unit):
    with pytest.raises(ValueError, match="End.stiffness"):
        End.elastic(-1.0)
    with pytest.raises(ValueError, match="n_units"):
        chain(unit, 0, 0.25, 0.04)
    with pytest.raises(ValueError, match="mass"):
        follower_unit(cam(), J_HUB, 0.0, STIFF)


def test_force_vector_scatters_the_units_loads():
    # F of Table 5.1 case 1 at Ω = 0: Q = [−F2 U', −F2] (process force F2 against x2)
    unit = follower_unit(cam(), J_HUB, MASS, STIFF, force=10.0)
    ch = chain(unit, 3, 0.25, 0.04, phases=[0.0, 1.0, 2.0], left=End.fixed())
    F = ch.F(0.5)
    U1 = cam()(0.5 + np.array([0.0, 1.0, 2.0]), 1)
    # node 0 is clamped: its rotation row is dropped, its follower row stays
    expected = np.array([-10.0, -10 * U1[1], -10.0, -10 * U1[2], -10.0])
    # bound: scatter of the same values: exact up to summation order
    assert np.allclose(F, expected, rtol=1e-12, atol=1e-12)
    assert ch.F(np.zeros((2, 3))).shape == (2, 3, ch.n)
