"""Hard case 3: repeated and clustered eigenvalues.

A doubly symmetric frame (square plan, square tubes: pairs of equal frequencies by
symmetry) and a shaft carrying N = 50 identical cam mechanisms (in the cams' dwell the
50 follower modes coincide exactly; in the rise they split into a dense cluster). Every
member of a cluster must be found, clusters are compared as subspaces (their vectors are
any basis), and sweeps must follow clusters without losing or swapping branches.
"""

import numpy as np
import pytest
import scipy.linalg as sla
import sympy
from hard_models import STEEL, cluster_slices, grid_model, line_mesh, subspace_cos2
from numpy.testing import assert_allclose

import femmech as fm
from femmech.analysis.modes import superelement_modes
from femmech.analysis.reference import full_modes
from femmech.analysis.sweep import sweep
from femmech.coupling import Attachment, Mount, couple
from femmech.fe import sections
from femmech.mechanisms import (
    CamProfile,
    CamSegment,
    Mechanism,
    PointMass,
    RotaryInertia,
    Spring,
    polynomial_345,
    position_function,
    rheolinear,
)
from femmech.reduction.component_modes import craig_bampton

SQUARE = sections.rectangular_hollow(0.06, 0.06, 0.004)


@pytest.fixture(scope="module", params=[2, 3], ids=["dense", "arpack"])
def square_frame(request):
    """Square-plan frame 2 x 2 bays (1 m x 1 m x 0.8 m), clamped base, square tubes:
    symmetric under the 8 operations of the square (pairs of equal eigenvalues); 2 or 3
    elements per member (252 or 450 free DOFs: dense and sparse paths). Dense LAPACK
    reference (lowest 40 eigenpairs)."""
    model = grid_model(bays=(2, 2, 1), size=(1.0, 1.0, 0.8), subdivisions=request.param,
                       section=SQUARE)
    lam, X = sla.eigh(model.K_free.toarray(), model.M_free.toarray(), subset_by_index=[0, 39])
    return model, lam, X


# eigenvalues equal within the dense reference's round-off (~eps λ_max / λ, < 1e-8 here)
# count as repeated; the frame's pairs are exact to 1e-13, distinct modes 1e-3 apart
PAIR_RTOL = 1e-8


def test_every_member_of_a_repeated_eigenvalue_is_found(square_frame):
    """Naive: a single Lanczos run finds one vector of a repeated eigenvalue (its Krylov
    space sees one direction of the eigenspace), and ``n_modes`` cuts a pair in half, so
    a symmetric partner mode is lost; comparing vectors one by one then fails for the
    members found, because any rotation within the pair is as good. femmech returns the
    whole cluster at the n-th mode, completes clusters by Sturm count and deflation, and
    this test compares subspaces."""
    model, lam, X = square_frame
    slices = [s for s in cluster_slices(lam[:40], PAIR_RTOL)]
    pairs = [s for s in slices if s.stop - s.start == 2]
    assert len(pairs) >= 8  # the symmetry makes many pairs among the lowest 40 modes
    cut = pairs[2].start + 1  # ask for a count that ends inside the third pair
    result = fm.modes(model, n_modes=cut)
    assert result.n_modes == cut + 1  # the pair is returned whole
    assert_allclose(result.omega2, lam[:cut + 1], rtol=1e-9)  # bound: measured 4e-12 (λ)
    free = model.free
    M = model.M_free
    for s in slices:
        if s.stop > result.n_modes:
            break
        # subspace of each cluster against the reference: measured 1 - cos² < 1e-15
        assert subspace_cos2(result.shapes[free, s], X[:, s], M) > 1 - 1e-8


def test_reduced_symmetric_frame_keeps_the_pairs(square_frame):
    """Craig-Bampton with the (symmetric) top joints as interface keeps the symmetry: the
    reduced pencil has the same pairs (equal to 1e-13), and each recovered pair spans the
    full model's pair (subspace, measured 1 - cos² < 5e-8)."""
    model, lam, X = square_frame
    se = craig_bampton(model, "top", n_modes=20)
    result = superelement_modes(se, n_modes=16, model=model)
    # CB (20 modes + residual vectors) truncation: measured 7e-8 and 1.3e-6 in λ
    assert_allclose(result.omega2[:16], lam[:16], rtol=1e-5)
    for s in cluster_slices(lam[:16], PAIR_RTOL):
        # bound: members of an exact pair (symmetry) from one CB solve: split by eps λ_max/λ only
        assert_allclose(result.omega2[s], result.omega2[s.start], rtol=1e-9)
        assert subspace_cos2(result.shapes[model.free, s], X[:, s], model.M_free) > 1 - 1e-6


# --- N = 50 identical mechanisms on one shaft --------------------------------------------

N_CAMS = 50
PARAMS = {"J_c": 2e-3, "m2": 2.0, "c2": 1e6}  # kg m², kg, N/m
F_FOLLOWER = np.sqrt(PARAMS["c2"] / PARAMS["m2"]) / (2 * np.pi)  # 112.54 Hz, U' = 0
CAM = CamProfile((CamSegment(np.pi / 2, 0.03, polynomial_345()), CamSegment(np.pi / 2, 0.0),
                  CamSegment(np.pi / 2, -0.03, polynomial_345()), CamSegment(np.pi / 2, 0.0)))


def _cam():
    """Cam on the shaft (twist q_s attached to the shaft's rx), follower guided by the
    ground: x2 = U(θ + q_s) + q2, 2T = J_c (θ' + q_s')² + m2 x2'², 2V = c2 q2²."""
    theta, qs, q2 = sympy.symbols("theta q_s q2")
    Jc, m2, c2 = sympy.symbols("J_c m2 c2")
    x2 = position_function("U")(theta + qs) + q2
    return Mechanism((qs, q2, theta), (RotaryInertia(Jc, theta + qs), PointMass(m2, (x2,)),
                                       Spring(c2, q2)), drives=(theta,), name="cam")


@pytest.fixture(scope="module")
def fifty_cams():
    """Steel shaft d = 60 mm, 5.1 m, 102 elements, on bearings every 1 m, its drive end
    held in torsion; 50 identical cams at 0.1 m spacing, all in phase. Reduced: CB with
    the 50 cam twists as interface and 20 modes (+ residual vectors)."""
    per = 2
    n_el = (N_CAMS + 1) * per
    mesh = line_mesh(n_el, (N_CAMS + 1) * 0.1,
                     node_sets={"drive": [0], "bearings": np.arange(0, n_el + 1, 10 * per)})
    fe = fm.build_model(mesh, {"all": fm.BeamProperty(sections.circle(0.06), STEEL)},
                        supports=[fm.Support("bearings", "translations"),
                                  fm.Support("drive", ["rx"])])
    cams = per * (1 + np.arange(N_CAMS))
    model = rheolinear(_cam(), PARAMS, {"U": CAM})
    mounts = [Mount(model, (Attachment("q_s", int(c), "rx"),), name=f"cam{i}")
              for i, c in enumerate(cams)]
    se = craig_bampton(fe, [(cams, ["rx"])], n_modes=20)
    return couple(se, mounts), couple(fe, mounts)


def test_full_coupled_model_finds_all_fifty_coincident_modes(fifty_cams):
    """In the dwell (U' = 0) the followers decouple from the shaft: 50 modes at exactly
    sqrt(c2/m2)/2π = 112.54 Hz (analytic). Naive: ARPACK alone returns a few of them; the
    Sturm count shows the rest missing and deflated restarts add them."""
    _, full = fifty_cams
    assert full.n > 400  # sparse shift-invert path
    lam, V = full_modes(full, 0.75 * np.pi, N_CAMS + 3)
    f = np.sqrt(lam.real) / (2 * np.pi)
    in_cluster = np.abs(f / F_FOLLOWER - 1) < 1e-9  # bound: round-off of a 649-DOF solve
    assert np.count_nonzero(in_cluster) == N_CAMS
    # the cluster's span is the span of the 50 follower coordinates (unit vectors)
    followers = np.zeros((full.n, N_CAMS))
    followers[full.n_frame + np.arange(N_CAMS), np.arange(N_CAMS)] = 1.0
    M = full.matrices(0.75 * np.pi)[0]
    # bound: Davis-Kahan: the cluster's subspace moves by eps λ_max/gap, gap ~ f_follower
    assert subspace_cos2(V[:, in_cluster].real, followers, M) > 1 - 1e-9


def test_sweep_tracks_the_cluster_as_a_subspace(fifty_cams):
    """Over a revolution the cluster forms (dwell, 50-fold) and splits (rise: 111.2 ...
    112.54 Hz). Naive MAC tracking compares each vector with each vector: inside the
    cluster the basis is arbitrary, so the MAC steps drop to ~0.04 (measured before this
    issue) and branches hop between cluster members and neighbours. femmech compares a
    branch with the span of the cluster (subspace MAC, femmech.analysis.sweep.clusters)
    and completes clusters cut by n_modes. Measured minimum MAC step 0.95 (n_modes = 6)
    and 0.87 (n_modes = 60, the cluster and the shaft modes around it): the lowest
    values belong to a torsion branch that changes by 10 Hz between 10° steps."""
    reduced, full = fifty_cams
    phi = np.linspace(0.0, 2 * np.pi, 37)
    for n_modes in (6, 60):
        result = sweep(reduced, phi, n_modes=n_modes)
        assert result.mac_step.min() > 0.8
        # in the dwells (90°-180°, 270°-360°) the cluster branches sit at the analytic
        # value; they are the same columns at every dwell angle (no branch swapped in)
        dwell = (phi > np.pi / 2 + 0.01) & (phi < np.pi - 0.01)
        # bound: dwell: branches exactly at F_FOLLOWER up to eps λ_max/λ of dense LAPACK
        members = np.abs(result.freq_hz[dwell] / F_FOLLOWER - 1) < 1e-9
        assert np.all(members == members[0])
        assert members[0].sum() == min(N_CAMS, n_modes - 1)
    # reduced against full at a rise angle: the split cluster as a subspace
    a = 3  # 30°, in the rise
    result = sweep(reduced, phi[a:a + 1], n_modes=53, keep_vectors=True, track=False)
    lam, V = full_modes(full, phi[a], 53)
    assert_allclose(result.freq_hz[0], np.sqrt(lam.real) / (2 * np.pi), rtol=1e-7)
    se = reduced.frame
    shapes = np.vstack([se.expand_free(result.vectors[0, :reduced.n_frame]),
                        result.vectors[0, reduced.n_frame:]])
    M = full.matrices(phi[a])[0]
    # the cluster between the shaft torsion mode (67.5 Hz) and the shaft's bending pair
    # (121.25 Hz): 49 follower modes from 107.0 to 112.53 Hz at 30°
    f_full = np.sqrt(lam.real) / (2 * np.pi)
    cluster = np.flatnonzero((f_full > 100.0) & (f_full < 120.0))
    assert cluster.size == N_CAMS - 1
    assert subspace_cos2(shapes[:, cluster], V[:, cluster].real, M) > 1 - 1e-6
