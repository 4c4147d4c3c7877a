"""The lean batched path of the coupled sweep (femmech.analysis.sweep._lean_loop) against
the general per-angle path (_sweep_loop), which every sweep took before the lean path."""

import numpy as np
import pytest
import sympy
from numpy.testing import assert_allclose, assert_array_equal

import femmech as fm
from femmech.analysis import sweep as sw
from femmech.analysis import tracking
from femmech.coupling import Mount, couple
from femmech.fe import sections
from femmech.mechanisms import (
    CamProfile,
    CamSegment,
    Mechanism,
    PointMass,
    Potential,
    Spring,
    polynomial_345,
    position_function,
    rheolinear,
)
from femmech.reduction.component_modes import craig_bampton
from femmech.solve.pencil import eigenvalue_scale

PHI = np.linspace(0.0, 2 * np.pi, 97)


def _oscillators():
    """q1: a constant sqrt(4000)/2π = 10.07 Hz oscillator; q2: stiffness 4000 (0.6 + 0.8 U(θ))
    N/m, whose frequency sweeps 7.8..11.9 Hz through q1's."""
    theta, q1, q2 = sympy.symbols("theta q1 q2")
    U = position_function("U")
    mech = Mechanism((q1, q2, theta), (
        PointMass(1.0, (q1,)), PointMass(1.0, (q2,)), Spring(4000.0, q1),
        Potential(sympy.Rational(1, 2) * 4000.0 * (0.6 + 0.8 * U(theta)) * q2**2)),
        drives=(theta,))
    harmonic = CamProfile((CamSegment(np.pi, 1.0, polynomial_345()),
                           CamSegment(np.pi, -1.0, polynomial_345())))
    return rheolinear(mech, {}, {"U": harmonic})


@pytest.fixture(scope="module")
def machine():
    """A stiff beam (its modes far above the band) carrying three uncoupled copies of the
    oscillators, two of them in phase: the three q1 form an exact triple cluster at
    10.07 Hz, the two in-phase q2 an exact pair, and the q2 branches cross the q1 cluster."""
    x = np.linspace(0.0, 2.0, 5)
    mesh = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              [[0, 1], [1, 2], [2, 3], [3, 4]], node_sets={"a": [0], "b": [4]})
    steel = fm.Material(E=210e9, nu=0.3, rho=7850.0)
    fe = fm.build_model(mesh, {"all": fm.BeamProperty(sections.circle(0.5), steel)},
                        supports=[fm.Support("a"), fm.Support("b")])
    model = _oscillators()
    return couple(craig_bampton(fe, [2], n_modes=0),
                  [Mount(model, name="a"), Mount(model, name="b", phase=0.7),
                   Mount(model, name="c", phase=0.7)])


def _general(system, n_modes, track=True):
    extra = min(n_modes + max(2, n_modes // 2), system.n - 1)
    return sw._sweep_loop(sw._angle_matrices(system, PHI, 0.0, 0.0, False), system.n, None,
                          PHI, n_modes, extra, False, track, True, 0.1)


def _lean(system, n_modes, track=True):
    extra = min(n_modes + max(2, n_modes // 2), system.n - 1)
    return sw._lean_loop(sw._angle_stacks(system, PHI, 0.0, 0.0), system.n, PHI, n_modes,
                         extra, track, True, 0.1)


@pytest.mark.parametrize("n_modes", [2, 3, 5])
@pytest.mark.parametrize("track", [True, False])
def test_lean_path_equals_general_path(machine, n_modes, track):
    # Same LAPACK calls on the same matrices: eigenpairs bit-identical; the MAC steps come
    # from the same products grouped differently (batched): round-off, 1e-12 of MAC <= 1.
    # n_modes = 3 and 5 cut the clusters (the candidates are doubled mid-sweep), n_modes = 3
    # tracks a branch out of the lowest three (the batch's assumed candidates fail).
    old, new = _general(machine, n_modes, track), _lean(machine, n_modes, track)
    assert_array_equal(new.freq_hz, old.freq_hz)
    assert_array_equal(new.eigenvalues, old.eigenvalues)
    assert_array_equal(new.damping_ratio, old.damping_ratio)
    assert_array_equal(new.vectors, old.vectors)
    # bound: the same MAC arithmetic in another order: ~n eps of O(1) values
    assert_allclose(new.mac_step, old.mac_step, rtol=0, atol=1e-12)
    assert new.form == old.form == "symmetric"


def test_case_has_a_tracked_crossing_and_clusters(machine):
    # The comparison above is only worth something if the case exercises tracking: at some
    # angle a cluster of three (the q1 copies, exact repeats), and a tracked branch whose
    # rank among the branches changes (a crossing).
    result = sw.sweep(machine, PHI, n_modes=5)
    sizes = [max(g.size for g in sw.clusters(f)) for f in result.freq_hz]
    assert max(sizes) >= 3
    rank = np.argsort(np.argsort(result.freq_hz, axis=1, kind="stable"), axis=1)
    assert (rank != rank[0]).any()
    assert result.mac_step.min() > 0.99  # continuous shapes or cluster spans


def test_sweep_takes_the_lean_path(machine, monkeypatch):
    def general(*args, **kwargs):
        raise AssertionError("the general path ran")

    monkeypatch.setattr(sw, "_sweep_loop", general)
    sw.sweep(machine, PHI[:10], n_modes=3, keep_vectors=True)  # no AssertionError


def test_unsymmetric_angle_falls_back():
    # C(φ) unsymmetric beyond SYMMETRY_RTOL: the lean solve refuses (the general path then
    # uses LAPACK eig, as before).
    M = np.eye(3)[None]
    C = np.array([[[2.0, 1.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]]])
    with pytest.raises(sw._NotLeanError):
        sw._lean_solve(M, C, 2)


def test_splits_give_the_clusters():
    # tracking.splits (all angles at once) must group exactly as clusters() on sorted frequencies:
    # near repeats within CLUSTER_RTOL, chains of them, and rigid-body modes at round-off.
    rng = np.random.default_rng(7)
    base = np.sort(rng.uniform(1.0, 100.0, (40, 12)), axis=1)
    base[:, 3] = base[:, 2] * (1 + 0.5 * sw.CLUSTER_RTOL)  # a pair
    base[:, 5] = base[:, 4] * (1 + 0.9 * sw.CLUSTER_RTOL)
    base[:, 6] = base[:, 5] * (1 + 0.9 * sw.CLUSTER_RTOL)  # a chained triple
    base[::2, :2] = [1e-9, 3e-9]  # rigid-body modes
    f = np.sort(base, axis=1)
    split = tracking.splits(f)
    for row, s in zip(f, split, strict=True):
        expected = [g.tolist() for g in sw.clusters(row) if g.size > 1]
        assert [g.tolist() for g in tracking._groups(s)] == expected
    assert any(len(tracking._groups(s)) >= 2 for s in split)


def test_batched_span_mac_equals_per_angle():
    # _batch_span_mac (one eigh per cluster size for all angles) against _span_mac per
    # angle: the same formula, products grouped differently: round-off (1e-12 of MAC <= 1).
    rng = np.random.default_rng(3)
    k, p, q, n = 5, 4, 7, 9
    X, Y = rng.standard_normal((k, n, p)), rng.standard_normal((k, n, q))
    Y[:, :, 2] = Y[:, :, 1] + 1e-3 * Y[:, :, 2]  # a nearly dependent cluster member
    S = X.transpose(0, 2, 1) @ Y
    G = Y.transpose(0, 2, 1) @ Y
    nx = np.einsum("kij,kij->kj", X, X)
    mac = np.abs(S) ** 2 / (nx[:, :, None] * np.diagonal(G, axis1=1, axis2=2)[:, None, :])
    split = np.ones((k, q - 1), dtype=bool)
    split[:, 0] = split[:, 1] = False  # cluster 0..2
    split[1:, 4] = False  # cluster 4..5 at angles 1..4
    out = tracking._batch_span_mac(S, nx, G, split, mac)
    for j in range(k):
        expected = tracking._span_mac(S[j], nx[j], G[j], tracking._groups(split[j]), mac[j])
        # bound: batched and per-angle span MAC: the same products, ~n eps of O(1) values
        assert_allclose(out[j], expected, rtol=0, atol=1e-12)
    assert (out[:, :, :3] > mac[:, :, :3] + 1e-6).any()  # the span MAC differs from the MAC


def test_lean_shifts_equal_the_solver_defaults():
    # σ = default_shift (median of diag K / diag M) and the λ scale of each angle, all
    # angles at once, bit-identical to eigenvalue_scale / _lambda_scale per angle; also when
    # the coordinates with mass and stiffness differ between angles.
    rng = np.random.default_rng(5)
    dm = rng.uniform(0.5, 2.0, (6, 8))
    dk = rng.uniform(1e2, 1e4, (6, 8))
    dm[:, 0] = 0.0  # massless coordinate
    unstiff = dk.copy()
    unstiff[2, 3] = 0.0  # coordinate 3 without stiffness at angle 2 only
    for case in (dk, unstiff):
        sigma, scale = sw._lean_shifts(dm, case)
        for i in range(6):
            assert sigma[i] == -1e-6 * eigenvalue_scale(np.diag(case[i]), np.diag(dm[i]))
            assert scale[i] == sw._lambda_scale(np.diag(dm[i]), np.diag(case[i]))


@pytest.mark.parametrize("extra", [3, 20])
def test_lean_solve_equals_frozen_modes(extra):
    # 3 of 40 pairs: LAPACK sygvx (subset), 20 of 40: sygvd (all pairs), as
    # dense_symmetric chooses (ALL_PAIRS_FRACTION); the same calls on the same bits.
    rng = np.random.default_rng(11)
    k, n = 4, 40
    A = rng.standard_normal((k, n, n))
    M = A @ A.transpose(0, 2, 1) / n + np.eye(n)
    B = rng.standard_normal((k, n, n))
    C = 1e4 * (B @ B.transpose(0, 2, 1) / n + 0.1 * np.eye(n))
    lam, X, f, r = sw._lean_solve(M, C, extra)
    for i in range(k):
        ev, fi, ri, V, form = sw.frozen_modes(M[i], None, C[i], extra)
        assert form == "symmetric"
        assert_array_equal(lam[i], ev)
        assert_array_equal(f[i], fi)
        assert_array_equal(r[i], ri)
        assert_array_equal(X[i], V)


def test_bitwise_symmetric_stacks_skip_the_symmetry_check(machine):
    # The machine's C(φ) is symmetric to the bit (symmetric frame and mechanism blocks), so
    # the stack says so and _lean_solve may take C as its own symmetric part: the same bits
    # as with the check and (C + Cᵀ)/2.
    M, C, symmetric = sw._angle_stacks(machine, PHI[:7], 0.0, 0.0)(0, 7)
    assert symmetric
    fast, checked = sw._lean_solve(M, C, 6, True), sw._lean_solve(M, C, 6, False)
    for a, b in zip(fast, checked, strict=True):
        assert_array_equal(a, b)


def test_row_minima_agree_with_the_hungarian_assignment():
    # Where _row_minima says the rows' strict minima lie in distinct columns, that is the
    # assignment linear_sum_assignment finds (the unique optimum); ties or shared columns
    # must not be flagged.
    from scipy.optimize import linear_sum_assignment

    rng = np.random.default_rng(2)
    cost = rng.uniform(0.0, 1.0, (200, 4, 7))
    cost[::3, :, 0] = 0.0  # every row's minimum in column 0: not greedy
    cost[1::7, 0, 5] = cost[1::7, 0, 6] = -1.0  # a tie in row 0: not greedy
    sub = rng.uniform(0.0, 1.0, cost.shape)
    best, best_sub, greedy = tracking._row_minima(sub, cost)
    assert greedy.any()
    assert not greedy.all()
    assert not greedy[::3].any()
    assert not greedy[1::7].any()
    for j in np.flatnonzero(greedy):
        rows, cols = linear_sum_assignment(cost[j])
        assert_array_equal(cols, best[j])
        assert_array_equal(best_sub[j], sub[j][rows, cols])
