"""Hard case 2: stiffness contrast.

A slender steel tube (2 m, d = 40 mm) carrying a 20 kg motor runs in bearings of 1e12 N/m
(and N m/rad) that sit on mounts of 1e3 N/m (1e2 N m/rad); each bearing is joined to the
tube end by a 1 mm long, 100 mm thick, massless connector element (bending stiffness
12EI/L³ = 1.2e16 N/m, 1e10 times that of a 5 cm tube element). The bearing and mount
nodes carry no mass.

Such a connector costs accuracy in any float64 assembly: its entries absorb those of the
tube at the shared node to ~eps times its own size. Measured against the condensed
equivalent: 3.9e-7 (this model), 9e-7 with a 0.1 mm connector, 6e-6 with a 0.1 mm,
200 mm thick one (bending stiffness 2e20 N/m); with a 1 mm, 200 mm thick connector the
mount modes' relative residual reached 1.5e-6 and femmech warned (FemmechWarning, the
residual check of femmech.solve.eigen.solve_symmetric). The remedy is a
:class:`~femmech.RigidLink`, which eliminates the slave DOFs exactly (the condensed model
below).
"""

import numpy as np
import pytest
import scipy.linalg as sla
from hard_models import EPS, STEEL
from numpy.testing import assert_allclose
from roundoff import largest_eigenvalue

import femmech as fm
from femmech.analysis.modes import superelement_modes
from femmech.fe import sections
from femmech.reduction.component_modes import craig_bampton

K_BEARING, K_MOUNT, K_MOUNT_ROT = 1e12, 1e3, 1e2  # N/m (N m/rad for bearing rotations)
LENGTH, GAP = 2.0, 1e-3  # m: tube length, connector length
TUBE = sections.tube(0.04, 0.034)
MOTOR = fm.PointMass("mid", 20.0, [0.1, 0.2, 0.2])  # kg, kg m²


def _series(a, b):
    return a * b / (a + b)


def _tube_points(n):
    x = np.linspace(0.0, LENGTH, n + 1)
    return np.column_stack([x, 0 * x, 0 * x]), np.column_stack([np.arange(n),
                                                                 np.arange(1, n + 1)])


def hard_model(n):
    """Tube (n elements) + connectors + bearing springs + mounts; nodes n+1, n+2 are the
    bearings, n+3, n+4 the mounts (at the bearings' positions)."""
    tube, lines = _tube_points(n)
    ends = [[-GAP, 0.0, 0.0], [LENGTH + GAP, 0.0, 0.0]]
    points = np.vstack([tube, ends, ends])
    lines = np.vstack([lines, [[n + 1, 0], [n, n + 2]]])
    mesh = fm.Mesh.from_lines(points, lines,
                              cell_sets={"tube": np.arange(n), "connectors": [n, n + 1]},
                              node_sets={"mid": [n // 2], "mounts": [n + 3, n + 4]})
    beams = {"tube": fm.BeamProperty(TUBE, STEEL),
             "connectors": fm.BeamProperty(sections.circle(0.1),
                                           fm.Material(E=210e9, nu=0.3, rho=0.0))}
    bearing = [K_BEARING] * 6
    mount = [K_MOUNT] * 3 + [K_MOUNT_ROT] * 3
    springs = [fm.Spring(n + 1, n + 3, bearing), fm.Spring(n + 2, n + 4, bearing),
               fm.Spring(n + 3, None, mount), fm.Spring(n + 4, None, mount)]
    return fm.build_model(mesh, beams, springs=springs, masses=[MOTOR])


def condensed_model(n):
    """The equivalent: rigid links for the connectors, series springs to the ground."""
    tube, lines = _tube_points(n)
    points = np.vstack([tube, [[-GAP, 0.0, 0.0], [LENGTH + GAP, 0.0, 0.0]]])
    mesh = fm.Mesh.from_lines(points, lines, node_sets={"mid": [n // 2]})
    k_eff = [_series(K_BEARING, K_MOUNT)] * 3 + [_series(K_BEARING, K_MOUNT_ROT)] * 3
    return fm.build_model(mesh, {"all": fm.BeamProperty(TUBE, STEEL)},
                          springs=[fm.Spring(n + 1, None, k_eff), fm.Spring(n + 2, None, k_eff)],
                          rigid_links=[fm.RigidLink(0, [n + 1]), fm.RigidLink(n, [n + 2])],
                          masses=[MOTOR])


# Round-off bound of the comparison: any float64 solver resolves λ_min of the tube to about
# eps λ_max / λ_min (λ_max ~ 1e11 rad²/s² of a 5 cm tube element, λ_min = 77 rad²/s² of the
# mount modes): ~3e-7 in λ; the connector adds its own (see above). Measured frequency
# differences hard vs condensed: 3.9e-7 (dense, 40 elements), 1.5e-7 (ARPACK, 100).


def roundoff_rtol(n):
    """Relative frequency round-off of the n-element model: half the eigenvalue round-off
    10 eps λ_max / λ_min (roundoff.py) of the condensed pencil, λ_max from the finest tube
    element: 1.9e-6 (n = 40), 1.2e-5 (n = 100; the former fixed 1e-6 lay below it)."""
    model = condensed_model(n)
    lam_min = fm.modes(model, n_modes=1).omega2[0]
    return 5 * EPS * largest_eigenvalue(model.K_free, model.M_free) / lam_min


@pytest.mark.parametrize(("n", "method"), [(40, "dense"), (100, "arpack")])
def test_full_model_matches_condensed_equivalent(n, method):
    """Naive: ``eigh(K, M)`` cannot even start (M is singular: massless bearing and mount
    nodes), a penalty treatment of the connectors or a shift from the stiffest DOFs loses
    the 1.4 Hz mount modes to round-off, and a pivot test relative to the largest entry
    declares the 1e3 N/m mounts 'singular' beside 1e12 N/m bearings. femmech keeps the
    infinite eigenvalues of massless DOFs out (shift-invert), shifts from the median
    diagonal ratio and confirms the count by Sturm."""
    hard, ref = hard_model(n), condensed_model(n)
    result = fm.modes(hard, n_modes=12)
    expected = fm.modes(ref, n_modes=12)
    assert result.method == method
    assert not result.rigid.any()
    rtol = roundoff_rtol(n)
    assert_allclose(result.freq_hz, expected.freq_hz, rtol=rtol)
    # relative residual of the mount modes ~eps λ_max / λ_min (2 rtol): measured 4.3e-7
    # (dense), 1.5e-7 (ARPACK). NB femmech.solve.eigen warns (an error in tests) at a fixed 1e-6
    assert result.residual.max() < 2 * rtol
    if method == "arpack":
        assert result.sturm_count == 12
    # six rigid-body modes on the mounts (1.39 ... 7.0 Hz) below the tube's bending (41 Hz)
    assert result.freq_hz[0] < 1.5
    assert result.freq_hz[6] > 40.0


def test_naive_dense_solver_fails_where_femmech_does_not():
    """What breaks without care, shown on the same model: LAPACK's generalised solver
    needs a positive definite M and stops; femmech's dense path (shift-inverted pencil)
    returns the finite eigenvalues only."""
    hard = hard_model(40)
    with pytest.raises(np.linalg.LinAlgError):
        sla.eigh(hard.K_free.toarray(), hard.M_free.toarray())
    n_massless = int(np.count_nonzero(hard.M_free.diagonal() == 0))
    assert n_massless == 24  # bearing (6 x 2) and mount (6 x 2) nodes
    result = fm.modes(hard, n_modes=hard.n_free - n_massless)
    assert np.isfinite(result.freq_hz).all()
    assert result.n_modes == hard.n_free - n_massless


def test_reduced_model_matches_condensed_equivalent():
    """Craig-Bampton with the soft mounts as interface: the interior holds the 1e12 N/m
    bearings and the connectors, so K_ii spans 14 decades; its factorisation must not be
    declared singular (pivot test relative to each diagonal entry, not to the largest)
    and the reduced frequencies are Rayleigh-Ritz upper bounds of the full ones."""
    n = 40
    hard = hard_model(n)
    se = craig_bampton(hard, "mounts", n_modes=12)
    result = superelement_modes(se, n_modes=8, model=hard)
    expected = fm.modes(condensed_model(n), n_modes=8)
    # measured 1.6e-7: round-off (roundoff_rtol, 1.9e-6) plus CB truncation (< 1e-9 here);
    # the upper-bound property holds to round-off (measured -2.3e-7)
    rtol = roundoff_rtol(n)
    assert_allclose(result.freq_hz, expected.freq_hz, rtol=rtol)
    full = fm.modes(hard, n_modes=8)
    assert np.all(result.freq_hz >= full.freq_hz * (1 - rtol))
