"""Mass properties and modal participation (femmech.analysis.participation) against
closed-form cases: a 2-DOF spring-mass chain, a point mass on springs, an
Euler-Bernoulli cantilever; completeness of all modes of small dense models."""

import numpy as np
import pytest
import scipy.linalg

import femmech as fm
from femmech import generators, sections
from femmech.analysis.participation import (
    cumulative_fractions,
    element_group_masses,
    mass_properties,
    modal_participation,
    participation,
    participation_factors,
    reachable_masses,
    rigid_body_masses,
    rigid_body_vectors,
)

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)


def _all_modes(model):
    """Every mode of the free system by dense LAPACK, mass-normalised, on all DOFs."""
    w2, v = scipy.linalg.eigh(model.K_free.toarray(), model.M_free.toarray())
    return w2, model.expand(v)


def test_two_dof_chain_closed_form():
    # ground -k- m -k- m along one axis: K = k [[2, -1], [-1, 1]], M = m I. The modes are
    # [1, g] and [1, -1/g] with the golden ratio g = (1 + √5)/2 (ω² = (3 ∓ √5)/2 k/m), so
    # Γ² = m (1 + g)² / (1 + g²) = 1.8944 m and m (1 - 1/g)² / (1 + 1/g²) = 0.1056 m,
    # summing to the total 2 m (the rigid translation r = [1, 1] lies in the free space).
    m, k = 3.0, 500.0
    M, K = m * np.eye(2), k * np.array([[2.0, -1.0], [-1.0, 1.0]])
    w2, phi = scipy.linalg.eigh(K, M)
    g = (1 + np.sqrt(5)) / 2
    np.testing.assert_allclose(w2, [(3 - np.sqrt(5)) / 2 * k / m, (3 + np.sqrt(5)) / 2 * k / m])
    gamma = participation_factors(phi, M, np.ones((2, 1)))
    expected = m * np.array([(1 + g) ** 2 / (1 + g**2), (1 - 1 / g) ** 2 / (1 + 1 / g**2)])
    # bound: closed-form 2-DOF modes: a few eps of O(1) terms
    np.testing.assert_allclose(gamma[:, 0] ** 2, expected, rtol=1e-12)
    np.testing.assert_allclose(expected.sum(), 2 * m, rtol=1e-14)  # the closed form itself
    np.testing.assert_allclose(rigid_body_masses(M, np.ones((2, 1))), [2 * m])
    # bound: ratios of closed-form masses: a few eps
    np.testing.assert_allclose(cumulative_fractions(gamma**2, [2 * m])[:, 0],
                               [expected[0] / (2 * m), 1.0], rtol=1e-12)


def test_point_mass_on_massless_springs():
    # one node: a 40 kg point mass with rotary inertia on grounded springs of distinct
    # stiffness per direction; each mode moves one DOF, so m_eff = m (translations) and
    # the rotary inertia (rotations about the node, the centre of mass), 0 elsewhere
    mesh = fm.Mesh(np.array([[0.3, -0.2, 1.1]]), {})
    mass, inertia = 40.0, np.array([1.5, 2.5, 3.5])
    model = fm.build_model(mesh, masses=[fm.PointMass(0, mass, inertia)],
                           springs=[fm.Spring(0, None, [1e4, 2e4, 3e4, 10.0, 20.0, 30.0])])
    props = mass_properties(model.M, mesh.points)
    # bound: a point mass: M holds it exactly, a few eps
    assert props.total == pytest.approx(mass, rel=1e-14)
    np.testing.assert_allclose(props.centre, mesh.points[0], atol=1e-15)
    # bound: point inertias taken from M exactly: a few eps of O(1) values
    np.testing.assert_allclose(props.inertia, np.diag(inertia), atol=1e-12)
    result = fm.modes(model, n_modes=6)
    p = participation(model, result)
    m_eff = np.zeros((6, 6))
    for k in range(6):  # the mode's moving DOF
        d = int(np.argmax(np.abs(result.shapes[:, k])))
        m_eff[k, d] = (mass, mass, mass, *inertia)[d]
    # bound: uncoupled modes: effective masses exact to eigh's eps·n of the mass
    np.testing.assert_allclose(p.effective_mass, m_eff, atol=1e-12 * mass)
    np.testing.assert_allclose(p.cumulative_fraction[-1], 1.0, rtol=1e-12)


def _cantilever(n_elements: int, length=2.0):
    x = np.linspace(0.0, length, n_elements + 1)
    mesh = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(n_elements),
                                               np.arange(1, n_elements + 1)]),
                              node_sets={"root": [0]})
    # Euler-Bernoulli without rotary inertia, as in the closed form; rectangle with
    # height ≠ width so that bending in y and z have distinct frequencies
    prop = fm.BeamProperty(sections.rectangle(0.03, 0.05), STEEL, shear=False,
                           rotary_inertia=False)
    return fm.build_model(mesh, {"all": prop}, supports=[fm.Support("root")])


def _cantilever_fractions(n: int) -> np.ndarray:
    """Effective mass fractions of the n lowest bending modes (one plane) of a continuous
    Euler-Bernoulli cantilever: 4 σ_k² / (β_k L)², with cos βL cosh βL = -1 and
    σ_k = (sinh βL - sin βL) / (cosh βL + cos βL) (Blevins, Formulas for natural frequency
    and mode shape, table 8-1; 0.6131, 0.1883, 0.0647, 0.0331, ...; they sum to 1)."""
    from scipy.optimize import brentq

    beta = np.array([brentq(lambda b: np.cos(b) * np.cosh(b) + 1, (k - 0.5) * np.pi - 1.4,
                            (k - 0.5) * np.pi + 1.4) for k in range(1, n + 1)])
    sigma = (np.sinh(beta) - np.sin(beta)) / (np.cosh(beta) + np.cos(beta))
    return 4 * sigma**2 / beta**2


@pytest.mark.slow
def test_cantilever_effective_masses_approach_the_total_mass():
    # Γ² of the bending modes against the closed form, mode by mode; their running sum
    # grows towards the beam's mass and passes 99 % after 41 bending modes in the plane
    # (the closed-form tail after n modes is ~4/(π² n))
    model = _cantilever(100)
    beam_mass = STEEL.rho * 0.03 * 0.05 * 2.0
    result = fm.modes(model, n_modes=240)
    p = participation(model, result)
    running = np.cumsum(p.effective_mass[:, 2]) / beam_mass
    assert np.all(np.diff(running) >= 0)
    # bound: modes with effective mass above eigh's round-off eps·(beam mass) are bending modes
    bending = np.flatnonzero(p.effective_mass[:, 2] > 1e-9 * beam_mass)  # x-z bending
    assert bending.size >= 45
    expected = np.cumsum(_cantilever_fractions(45))
    assert expected[0] == pytest.approx(0.6131, abs=1e-4)
    # 100 elements: measured agreement 6e-10 for the first four modes, 1e-6 at the 45th
    np.testing.assert_allclose(running[bending[:4]], expected[:4], rtol=1e-8)
    np.testing.assert_allclose(running[bending[:45]], expected, rtol=3e-6)
    assert running[bending[39]] < 0.99 < running[bending[40]]
    assert p.rigid_mass[2] == pytest.approx(beam_mass, rel=1e-12)  # bound: r_zᵀ M r_z = ρAL
    # bound: the same sum computed twice: a few eps
    assert running[-1] == pytest.approx(p.cumulative_fraction[-1, 2], rel=1e-12)


def test_supported_model_all_modes_reach_the_projection():
    # all modes of a supported model sum to the M-projection of r_z onto the free
    # motions (reachable_masses), which is less than ρAL by the mass that moves with
    # the support (measured 0.49 % for 60 elements)
    model = _cantilever(60)
    beam_mass = STEEL.rho * 0.03 * 0.05 * 2.0
    w2, shapes = _all_modes(model)
    R = rigid_body_vectors(model.mesh.points)
    all_z = modal_participation(shapes, model.M, R).effective_mass[:, 2].sum()
    reach = reachable_masses(model.M_free, model.T, model.M, R)
    # bound: the same projections by two formulas: ~n eps·cond(M_free)
    assert all_z == pytest.approx(reach[2], rel=1e-10)
    assert 0.99 * beam_mass < all_z < beam_mass
    p = participation(model, fm.modes(model, n_modes=4), reference=(0.0, 0.0, 0.0),
                      reachable=True)
    # bound: the same reachable masses: identical arithmetic up to order
    np.testing.assert_allclose(p.reachable, reach, rtol=1e-12)


def test_all_modes_of_a_small_model_sum_to_the_rigid_masses():
    # free-free grid frame with a point mass off the centre, and the same on springs:
    # r_d lies in the span of the free DOFs, so Σ_k Γ_kd² = r_dᵀ M r_d (completeness of
    # M-orthonormal modes), to round-off
    mesh = generators.grid_frame((2, 1, 1), (2.0, 1.0, 1.0), subdivisions=2)
    beam = fm.BeamProperty(sections.rectangular_hollow(0.08, 0.06, 0.004), STEEL)
    groups = {name: beam for name in mesh.cell_sets}
    mass = [fm.PointMass(3, 25.0, [0.4, 0.5, 0.6])]
    free = fm.build_model(mesh, groups, masses=mass)
    feet = np.flatnonzero(mesh.points[:, 2] == 0.0)
    mounted = fm.build_model(mesh, groups, masses=mass,
                             springs=[fm.Spring(int(n), None, [1e6, 1e6, 2e6, 0, 0, 0])
                                      for n in feet])
    for model in (free, mounted):
        w2, shapes = _all_modes(model)
        props = mass_properties(model.M, model.mesh.points)
        R = rigid_body_vectors(model.mesh.points, props.centre)
        p = modal_participation(shapes, model.M, R, props.centre)
        # bound: all modes of a small model: Σ fractions = 1 to ~n eps·cond(M) of eigh
        np.testing.assert_allclose(p.cumulative_fraction[-1], 1.0, rtol=1e-10)
        np.testing.assert_allclose(p.rigid_mass[:3], props.total, rtol=1e-13)
        # bound: rigid masses are sums of ρ A L (exact consistent mass): ~n eps
        np.testing.assert_allclose(p.rigid_mass[3:], np.diag(props.inertia), rtol=1e-13)
        # bound: reachable masses by projection, ~n eps·cond(M_free)
        np.testing.assert_allclose(reachable_masses(model.M_free, model.T, model.M, R),
                                   p.rigid_mass, rtol=1e-10)
    # the six rigid-body modes of the free frame carry all of it
    w2, shapes = _all_modes(free)
    p = modal_participation(shapes[:, :6], free.M, R, props.centre)
    # bound: rigid modes from eigh: the 6-mode subspace to Davis-Kahan eps λ_max/λ_7
    np.testing.assert_allclose(p.effective_mass.sum(axis=0), p.rigid_mass, rtol=1e-9)


def test_mass_properties_of_a_beam_with_an_end_mass():
    # beam along x (ρAL at its middle, I_zz = ρAL L²/12 about its centre, exact for the
    # consistent mass matrix: rigid motions lie in the cubic interpolation) with a point
    # mass at the tip: centre x_c = (ρAL L/2 + m L)/(ρAL + m), parallel-axis theorem
    model = _cantilever(10)
    length, m_tip = 2.0, 12.0
    model = fm.build_model(model.mesh, {"all": fm.BeamProperty(
        sections.rectangle(0.03, 0.05), STEEL, rotary_inertia=False)},
        masses=[fm.PointMass(10, m_tip)])
    beam = STEEL.rho * 0.03 * 0.05 * length
    props = mass_properties(model.M, model.mesh.points)
    total = beam + m_tip
    x_c = (beam * length / 2 + m_tip * length) / total
    # bound: sums of ρ A L terms (exact consistent mass): ~n eps
    assert props.total == pytest.approx(total, rel=1e-13)
    np.testing.assert_allclose(props.centre, [x_c, 0.0, 0.0], atol=1e-13)
    i_zz = beam * length**2 / 12 + beam * (length / 2 - x_c) ** 2 + m_tip * (length - x_c) ** 2
    # bound: sums of ρ A L x² terms: ~n eps
    assert props.inertia[2, 2] == pytest.approx(i_zz, rel=1e-12)
    assert props.inertia[1, 1] == pytest.approx(i_zz, rel=1e-12)  # same about y
    groups = element_group_masses(model)
    assert list(groups) == ["all"]
    assert groups["all"].kind == "beam"
    assert groups["all"].n_elements == 10
    # bound: the same sums in another order: ~n eps
    assert groups["all"].mass + m_tip == pytest.approx(props.total, rel=1e-13)


def test_rigid_body_vectors_and_errors():
    points = np.array([[1.0, 2.0, 3.0], [0.0, 0.0, 0.0]])
    R = rigid_body_vectors(points, reference=(1.0, 0.0, 0.0), rotations=[True, False])
    assert R.shape == (12, 6)
    # rotation about z through (1, 0, 0): node 0 at offset (0, 2, 3) moves by e_z × x
    np.testing.assert_allclose(R[0:3, 5], [-2.0, 0.0, 0.0])
    np.testing.assert_allclose(R[3:6, 5], [0.0, 0.0, 1.0])
    np.testing.assert_allclose(R[9:12], 0.0)  # node 1 has no rotational DOFs
    np.testing.assert_allclose(R[6:9, :3], np.eye(3))
    with pytest.raises(ValueError, match="shape"):
        rigid_body_vectors(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="no mass"):
        mass_properties(np.zeros((6, 6)), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="n_modes"):
        participation_factors(np.zeros((5, 2)), np.eye(12), R)
