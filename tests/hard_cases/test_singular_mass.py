"""Hard case 4: singular mass matrices.

A lumped-mass shaft (massless beam elements, point masses without rotary inertia: the
rotational DOFs carry no mass) and a cam mechanism whose follower touches the cam through
a massless roller (a coordinate without mass). Massless DOFs have infinite eigenvalues;
they must be excluded cleanly, never returned as huge or NaN frequencies, never crash the
solver, and never contaminate the finite modes.

Reference: static condensation of the massless DOFs, ``K_c = K_mm - K_mr K_rr⁻¹ K_rm``,
which leaves the finite eigenvalues unchanged exactly (the massless DOFs follow the
others statically), solved by dense LAPACK.
"""

import numpy as np
import pytest
import scipy.linalg as sla
import sympy
from hard_models import CAM, EPS, line_mesh
from numpy.testing import assert_allclose, assert_array_less
from roundoff import eigenvalue_rtol

import femmech as fm
from femmech.analysis.modes import superelement_modes
from femmech.analysis.reference import full_modes
from femmech.analysis.sweep import sweep
from femmech.coupling import Attachment, Mount, couple
from femmech.fe import sections
from femmech.mechanisms import (
    Mechanism,
    PointMass,
    RotaryInertia,
    Spring,
    position_function,
    rheolinear,
)
from femmech.reduction.component_modes import craig_bampton, guyan

MASSLESS_STEEL = fm.Material(E=210e9, nu=0.3, rho=0.0, name="massless steel")


def lumped_shaft(n, supports=("root",)):
    """Cantilever (or simply supported) shaft, 1 m, d = 20 mm, n massless elements with a
    0.1 kg point mass on every node but the root: 3 massive DOFs per node."""
    mesh = line_mesh(n, 1.0, node_sets={"root": [0], "tip": [n], "mid": [n // 2]})
    masses = [fm.PointMass(i, 0.1) for i in range(1, n + 1)]
    support = [fm.Support(s) if s == "root" else fm.Support(s, "translations")
               for s in supports]
    return fm.build_model(mesh, {"all": fm.BeamProperty(sections.circle(0.02), MASSLESS_STEEL)},
                          masses=masses, supports=support)


def condensed_eigenvalues(K, M):
    """Finite eigenvalues of (K, M) with massless DOFs statically condensed (dense)."""
    K, M = (A.toarray() if hasattr(A, "toarray") else np.asarray(A) for A in (K, M))
    m = np.diag(M) > 0
    Kc = K[np.ix_(m, m)] - K[np.ix_(m, ~m)] @ np.linalg.solve(K[np.ix_(~m, ~m)], K[np.ix_(~m, m)])
    return sla.eigh(Kc, M[np.ix_(m, m)], eigvals_only=True)


@pytest.mark.parametrize(("n", "method"), [(20, "dense"), (100, "arpack")])
def test_massless_rotations_give_only_finite_modes(n, method):
    """Naive: ``eigh(K, M)`` stops (M not positive definite); ``eigh(M, K)`` returns the
    zero eigenvalues μ = 1/λ of the massless DOFs, which become inf or 1e30 'frequencies'
    after inversion; ARPACK's M-inner product does not see the massless components of its
    vectors (measured residuals of 1e46 before this issue), and asking for nearly as many
    modes as there are massive DOFs overran the Krylov space ('could not build an Arnoldi
    factorization'). femmech keeps only finite eigenvalues, purifies ARPACK's vectors
    with one operator step, caps the Lanczos basis at the number of massive DOFs and
    rejects impossible requests naming the count."""
    model = lumped_shaft(n)
    n_mass = 3 * n
    assert int(np.count_nonzero(model.M_free.diagonal() > 0)) == n_mass
    ref = condensed_eigenvalues(model.K_free, model.M_free)
    few = fm.modes(model, n_modes=10)
    assert few.method == method
    # round-off (roundoff.eigenvalue_rtol; condensed pencil, λ_max = ref[-1]): 10 eps
    # λ_max / λ_1 is 1.3e-8 (n = 20) and 2.9e-7 (n = 100), and λ_1's pair lies 40 times
    # below the next. Measured 2e-11 (dense), 5e-9 (ARPACK; the old rtol 1e-8 lay below
    # the bound)
    assert_array_less(np.abs(few.omega2 / ref[:10] - 1), eigenvalue_rtol(ref[:10], ref[-1]))
    many = fm.modes(model, n_modes=n_mass - 2)  # all but two finite modes
    assert np.isfinite(many.freq_hz).all()
    assert many.n_modes == n_mass - 2
    # relative residual ‖K x - λ M x‖ / (λ ‖M x‖) of a backward-stable solve ~eps λ_max / λ
    # (1.3e-9 and 2.9e-8 for the lowest modes); 10 times that. Measured 1.7e-10 (58 of 60),
    # 1.2e-9 (298 of 300)
    assert many.residual.max() < 10 * EPS * ref[-1] / ref[0]
    # lowest modes as above; the highest ones to ~eps λ_k / λ_1 (shift-invert): bound
    # 3.6e-10 for λ_298 (n = 100). Measured 6e-11 (dense), 5e-9 (ARPACK, lowest modes),
    # 6e-11 (ARPACK, highest)
    rtol = eigenvalue_rtol(ref[:n_mass - 2], ref[-1])
    assert_array_less(np.abs(many.omega2 / ref[:n_mass - 2] - 1), rtol)
    with pytest.raises(ValueError, match=f"only {n_mass} of the {model.n_free} DOFs carry mass"):
        fm.modes(model, n_modes=n_mass + 1)


def test_guyan_onto_massive_dofs_is_exact():
    """Guyan's static condensation is exact when every condensed DOF is massless: the
    superelement on the translations reproduces the full spectrum to round-off (a
    naive 'Guyan is approximate' tolerance would hide errors). Craig-Bampton with a
    massless interior computes its fixed-interface modes from a singular M_ii."""
    model = lumped_shaft(20)
    ref = condensed_eigenvalues(model.K_free, model.M_free)
    se = guyan(model, [(np.arange(1, 21), ["ux", "uy", "uz"])])
    result = superelement_modes(se, n_modes=30)
    # both round-off (roundoff.eigenvalue_rtol: 1.3e-8 for λ_1; the old rtol 1e-9 lay below
    # it); measured 2e-11
    assert_array_less(np.abs(result.omega2[:30] / ref[:30] - 1),
                      eigenvalue_rtol(ref[:30], ref[-1]))
    se = craig_bampton(model, ["mid", "tip"], n_modes=12)
    assert np.isfinite(se.modal_omega2).all()
    result = superelement_modes(se, n_modes=8)
    err = np.sqrt(result.omega2 / ref[:8]) - 1
    # bound: Rayleigh-Ritz upper bounds; allowance for both solves' eps λ_max/λ (roundoff.py)
    assert err.min() > -1e-9
    assert err.max() < 1e-5


def _roller_cam(massless_roller: bool):
    """Table 5.1 case 1 with the guide y_g on the frame, the follower touching the cam
    through a roller r: springs c_a (cam-roller) and c_b (roller-follower) in series.
    ``massless_roller``: r is a coordinate without mass; otherwise the series springs are
    condensed by hand into k = c_a c_b / (c_a + c_b) (the reference)."""
    theta, q1, yg, r, q2 = sympy.symbols("theta q1 y_g r q2")
    J1, m2, c1, ca, cb = sympy.symbols("J1 m2 c1 c_a c_b")
    x2 = yg + position_function("U")(theta + q1) + q2
    if massless_roller:
        springs = (Spring(ca, r), Spring(cb, q2 - r))
        coords = (q1, yg, r, q2, theta)
    else:
        springs = (Spring(ca * cb / (ca + cb), q2),)
        coords = (q1, yg, q2, theta)
    return Mechanism(coords, (RotaryInertia(J1, theta + q1), PointMass(m2, (x2,)),
                              Spring(c1, q1)) + springs, drives=(theta,), name="roller cam")


ROLLER = {"J1": 0.05, "m2": 3.0, "c1": 2e4, "c_a": 8e5, "c_b": 2e6}  # kg m², kg, N(m)/m(rad)


def test_coupled_sweep_with_massless_frame_dofs_and_massless_mechanism_coordinate():
    """The lumped-mass shaft (simply supported) carries the roller cam: the coupled M(φ)
    is singular in the frame rotations and the roller. Naive: the coupled solver returns
    infinite 'quasi-frequencies' among the lowest, or its branch count runs past the
    finite modes into an IndexError. femmech's sweep equals the hand-condensed model and
    rejects a request for more branches than finite modes, naming the count."""
    fe = lumped_shaft(20, supports=("root", "tip"))
    phi = np.linspace(0.0, 2 * np.pi, 19)
    systems = {}
    for massless in (True, False):
        model = rheolinear(_roller_cam(massless), ROLLER, {"U": CAM})
        mount = Mount(model, (Attachment("y_g", 10, "uy"),), name="cam")
        se = craig_bampton(fe, "mid", n_modes=10)
        systems[massless] = (couple(se, [mount]), couple(fe, [mount]))
    reduced, full = systems[True]
    result = sweep(reduced, phi, n_modes=8)
    expected = sweep(systems[False][0], phi, n_modes=8)
    # bound: the same reduced frame, roller condensed or not: round-off (measured 2e-14)
    assert_allclose(result.freq_hz, expected.freq_hz, rtol=1e-9)
    assert not result.unstable.any()
    # against the unreduced coupled model (M singular in 61 of 120 coordinates):
    # measured 2e-7 (CB truncation with 10 modes + residual vectors)
    lam, _ = full_modes(full, phi[2], 8)
    assert_allclose(result.freq_hz[2], np.sqrt(lam.real) / (2 * np.pi), rtol=1e-6)
    finite = int(np.count_nonzero(np.diag(reduced.matrices(0.0)[0]) > 0))
    assert finite == reduced.n - 2  # massless: the roller and the shaft's torsion (rx)
    with pytest.raises(ValueError, match="finite quasi-modes"):
        sweep(reduced, phi[:2], n_modes=reduced.n - 1)
