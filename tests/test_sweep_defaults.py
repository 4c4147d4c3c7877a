"""Defaults that adapt to the model: a sweep without ``n_modes`` follows DEFAULT_MODES (6)
branches, or all of them where the system has fewer, and its notes say so; an explicit
count above the available branches stays an error naming both counts."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from femmech.analysis.sweep import DEFAULT_MODES, branch_count, parameter_sweep, sweep
from femmech.mechanisms import SliderCrank, quasi_modes, rheolinear, table_5_1_case

CASE_1 = dict(J1=0.1, m2=2.0, c1=1e4, c2=1e5, b1=1.0, b2=10.0, F2=50.0)
PHI = np.linspace(0.0, 2 * np.pi, 37)


@pytest.fixture(scope="module")
def two_dof():
    """Table 5.1 case 1 (crank and slider, 2 coordinates) as a mechanism alone."""
    return rheolinear(table_5_1_case(1), CASE_1, {"U": SliderCrank(0.05, 0.2)})


class _Diagonal:
    """A model with M = I and C = diag(k) at every angle: f_i = √k_i / 2π exactly."""

    def __init__(self, k):
        self.k = np.asarray(k, dtype=float)

    def M(self, phi):
        return np.broadcast_to(np.eye(self.k.size), np.shape(phi) + (self.k.size,) * 2).copy()

    def B(self, phi, Omega=0.0):
        return np.zeros(np.shape(phi) + (self.k.size,) * 2)

    def C(self, phi, Omega=0.0, Omega_dot=0.0):
        return np.broadcast_to(np.diag(self.k), np.shape(phi) + (self.k.size,) * 2).copy()


def test_two_dof_mechanism_alone_sweeps_with_defaults(two_dof):
    result = sweep(two_dof, PHI)  # used to fail: "n_modes must be ... 1..2, got 6"
    assert result.freq_hz.shape == (PHI.size, 2)
    assert result.notes == ("n_modes not given: the mechanism model (2 coordinates) has 2"
                            " branches, fewer than the default 6; all are followed",)
    assert "has 2 branches" in repr(result)
    assert "has 2 branches" in result._repr_html_()
    explicit = sweep(two_dof, PHI, n_modes=2)
    assert explicit.notes == ()
    assert np.array_equal(result.freq_hz, explicit.freq_hz)  # the same computation
    # reference: quasi_modes solves the same 2x2 pencils by eigh (round-off of a 2x2
    # pencil, 1e-12 relative ~ 5e3 eps, as in tests/mechanisms/test_mechanism_gaps.py)
    # bound: eigh of a 2x2 pencil, backward stable: rel. error <= ~10 eps * cond <= 1e-13
    assert_allclose(np.sort(result.freq_hz, axis=1), quasi_modes(two_dof, PHI).freq_hz,
                    rtol=1e-12)


def test_default_with_damping_and_untracked(two_dof):
    damped = sweep(two_dof, PHI[:5], Omega=10.0, damped=True)
    assert damped.freq_hz.shape == (5, 2)
    assert damped.form == "damped"
    assert damped.notes
    assert "has 2 branches" in damped.notes[0]
    assert sweep(two_dof, PHI[:5], track=False).freq_hz.shape == (5, 2)


def test_explicit_count_above_the_branches_is_an_error(two_dof):
    with pytest.raises(ValueError, match=r"n_modes must be an integer in 1\.\.2 \(the"
                                         r" mechanism model has 2 coordinates\), got 3"):
        sweep(two_dof, PHI, n_modes=3)
    with pytest.raises(ValueError, match="got 0"):
        sweep(two_dof, PHI, n_modes=0)
    with pytest.raises(ValueError, match="got 1.5"):
        sweep(two_dof, PHI, n_modes=1.5)


def test_large_model_keeps_six_without_a_note():
    k = (np.arange(1.0, 9.0) * 2 * np.pi) ** 2  # f = 1, 2, ..., 8 Hz
    result = sweep(_Diagonal(k), PHI[:4])
    assert result.freq_hz.shape == (4, DEFAULT_MODES)
    assert result.notes == ()
    # f_i = √k_i / 2π exactly; LAPACK round-off on a diagonal 8x8 pencil, ~1e3 eps
    # bound: diagonal pencil, eigh exact to a few eps in λ -> rel. error in f <= 1e-15
    assert_allclose(np.sort(result.freq_hz, axis=1), np.tile(np.arange(1.0, 7.0), (4, 1)),
                    rtol=1e-12)


def test_small_model_follows_all_branches():
    k = (np.array([3.0, 5.0, 7.0]) * 2 * np.pi) ** 2
    result = sweep(_Diagonal(k), PHI[:3])
    assert result.freq_hz.shape == (3, 3)
    assert result.notes == ("n_modes not given: the mechanism model (3 coordinates) has 3"
                            " branches, fewer than the default 6; all are followed",)
    # analytic f = 3, 5, 7 Hz; round-off as above
    # bound: diagonal pencil, eigh exact to a few eps in λ -> rel. error in f <= 1e-15
    assert_allclose(np.sort(result.freq_hz, axis=1), np.tile([3.0, 5.0, 7.0], (3, 1)),
                    rtol=1e-12)


def test_branch_count_of_coupled_systems():
    """A coupled system of n coordinates has n - 1 branches to follow (sweep, and
    parameter_sweep's first system)."""
    assert branch_count(None, 7, "coupled system", "8 coordinates") == (6, ())
    count, notes = branch_count(None, 3, "coupled system", "4 coordinates")
    assert count == 3
    assert notes == ("n_modes not given: the coupled system (4 coordinates)"
                                    " has 3 branches, fewer than the default 6; all are"
                                    " followed",)
    with pytest.raises(ValueError, match="no branch to follow"):
        branch_count(None, 0, "coupled system", "1 coordinates")
    with pytest.raises(ValueError, match=r"in 1\.\.3 \(the coupled system has 4"):
        branch_count(5, 3, "coupled system", "4 coordinates")
    with pytest.raises(ValueError, match="got True"):
        branch_count(True, 3, "coupled system", "4 coordinates")


def test_parameter_sweep_default(two_dof):
    """parameter_sweep takes CoupledSystem-like objects; the default is checked on a
    stand-in with n, H and matrices(phi, Omega) of the 2-coordinate mechanism."""

    class Frozen:
        n, H = 2, None

        def matrices(self, phi, Omega):
            return two_dof.M(phi), two_dof.B(phi, Omega), two_dof.C(phi, Omega, 0.0)

    result = parameter_sweep(lambda W: (Frozen(), W), [0.0, 5.0, 10.0], phi=0.3)
    # n = 2 coordinates of a coupled system: 1 branch (n - 1)
    assert result.freq_hz.shape == (3, 1)
    assert result.notes
    assert "has 1 branch," in result.notes[0]


def _three_coordinate_machine():
    """The cam of tests/test_stability.py (table 5.1 case 1 with dampers) on a simply
    supported beam held to bending in the xy plane, Guyan-reduced to the uy of its middle
    node: 3 coordinates (q1, q2 and the guide uy)."""
    import sympy

    import femmech as fm
    from femmech.coupling import Attachment, Mount, couple
    from femmech.fe import sections
    from femmech.mechanisms import (
        CamProfile,
        CamSegment,
        Damper,
        Mechanism,
        PointMass,
        RotaryInertia,
        Spring,
        polynomial_345,
        position_function,
    )
    from femmech.reduction import guyan

    n = 10
    x = np.linspace(0.0, 1.0, n + 1)
    mesh = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(n), np.arange(1, n + 1)]),
                              node_sets={"ends": [0, n], "mid": [n // 2],
                                         "all": list(range(n + 1))})
    prop = fm.BeamProperty(sections.rectangular_hollow(0.06, 0.08, 0.004),
                           fm.Material(E=210e9, nu=0.3, rho=7850.0))
    fe = fm.build_model(mesh, {"all": prop}, supports=[
        fm.Support("ends", "translations"), fm.Support("all", ["ux", "uz", "rx", "ry"])])
    theta, q1, yg, q2 = sympy.symbols("theta q1 y_g q2")
    cam = CamProfile((CamSegment(np.pi / 2, 0.02, polynomial_345()), CamSegment(np.pi / 2, 0.0),
                      CamSegment(np.pi / 2, -0.02, polynomial_345()),
                      CamSegment(np.pi / 2, 0.0)))
    x2 = yg + position_function("U")(theta + q1) + q2
    mech = Mechanism((q1, yg, q2, theta),
                     (RotaryInertia(0.05, theta + q1), PointMass(3.0, (x2,)), Spring(2e4, q1),
                      Spring(5e5, q2), Damper(2.0, q1), Damper(80.0, q2)), drives=(theta,))
    model = rheolinear(mech, {}, {"U": cam})
    return couple(guyan(fe, [("mid", ["uy"])]),
                  [Mount(model, (Attachment("y_g", n // 2, "uy"),), name="cam")])


def test_speed_study_defaults_fit_a_small_machine():
    """speed_study's basis (8 quasi-modes per angle) and marks (2 branches) fit a
    3-coordinate machine (2 branches): it used to fail with "n_modes must be an integer
    in 1..3, got 8"."""
    from femmech.analysis.floquet import quasi_modal_basis
    from femmech.analysis.stability import speed_study

    system = _three_coordinate_machine()
    assert system.n == 3
    counted = []
    study = speed_study(system, [20.0, 40.0], 0.02, (5.0, 200.0), [0.01], n_steps=16,
                        progress=lambda points: counted.append(len(points)) or points)
    assert counted == [2, 2]  # the speed line, then the (ζ, speed) chart of 1 x 2 points
    assert study.notes == ("basis_modes not given: all 2 branches of the system (3"
                           " coordinates; the default is 8)",)
    assert study.notes[0] in study.summary()
    assert study.mean_freq_hz.shape == (2,)  # both branches marked: the default 2 fits
    assert study.basis_size == 3  # 2 modes at 8 angles span all 3 coordinates
    with pytest.raises(ValueError, match=r"in 1\.\.2 \(the system has 3 coordinates\)"):
        quasi_modal_basis(system, 3)
