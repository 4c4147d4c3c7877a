"""Hard case 1: free-free frames and shafts.

Exactly six rigid-body modes, none lost or duplicated, and never a factorisation of the
singular K: full model (dense and sparse paths), reduced models (Guyan, Craig-Bampton),
bodies that are rigid by construction (K = 0 or K at round-off), and a free-free
superelement coupled to a grounded mechanism.
"""

import numpy as np
import pytest
import scipy.linalg as sla
from hard_models import (
    CAM,
    CAM_PARAMS,
    RHS,
    STEEL,
    cam_mechanism,
    grid_model,
    line_mesh,
    rigid_fields,
    subspace_cos2,
)
from numpy.testing import assert_allclose

import femmech as fm
from femmech.analysis.modes import superelement_modes
from femmech.analysis.reference import full_modes
from femmech.analysis.sweep import sweep
from femmech.coupling import Attachment, Mount, couple
from femmech.fe import sections
from femmech.mechanisms import rheolinear
from femmech.reduction.component_modes import craig_bampton, guyan
from femmech.solve.sturm import inertia_below


@pytest.mark.parametrize(("subdivisions", "method"), [(3, "dense"), (8, "arpack")])
def test_free_free_frame_has_exactly_six_rigid_modes(subdivisions, method):
    """Naive: factorising K itself (singular: SuperLU returns round-off pivots or fails),
    a shift of 0, or a rigid-mode threshold on absolute values counts 4, 5 or 7 zero
    modes, or returns round-off eigenvalues as spurious low 'elastic' modes. femmech
    shifts below zero (K - σM positive definite, Sturm count 0 below σ), flags the six
    zero modes relative to the eigenvalue scale and confirms the count by Sturm."""
    model = grid_model(subdivisions=subdivisions, supported=False)
    result = fm.modes(model, n_modes=12)
    assert result.method == method
    assert result.rigid.tolist() == [True] * 6 + [False] * 6
    # the factorised matrix K - σM is positive definite (no eigenvalue below σ < 0)
    assert result.sigma < 0
    assert inertia_below(model.K_free, model.M_free, result.sigma) == 0
    if method == "arpack":
        assert result.sturm_count == 12  # no mode below the 12th missed
    # the zero modes span the six rigid-body motions (a subspace: any basis will do);
    # bound: measured 1 - cos² = 1e-15 (dense) and 4e-14 (ARPACK)
    free = model.free
    R = rigid_fields(model.mesh.points)[free]
    assert subspace_cos2(result.shapes[free, :6], R, model.M_free) > 1 - 1e-10
    # bound: elastic modes: dense LAPACK on the (small) full pencil as the independent reference;
    # round-off ~ eps λ_max / λ_7 ~ 1e-10 relative (measured 3e-13, 2e-12)
    lam = sla.eigh(model.K_free.toarray(), model.M_free.toarray(), eigvals_only=True)
    assert_allclose(result.omega2[6:], lam[6:12], rtol=1e-9)
    # bound: zeros of dense LAPACK: eps λ_max absolute (roundoff.py), far below 1e-9 λ_7
    assert np.all(np.abs(lam[:6]) < 1e-9 * lam[6])  # the reference has six zeros too


def _rigid_point_masses():
    """Four point masses joined by one rigid link: K = 0 exactly."""
    points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    masses = [fm.PointMass(i, 2.0, inertia=[0.1, 0.2, 0.3]) for i in range(4)]
    return fm.build_model(fm.Mesh(np.array(points), {}), masses=masses,
                          rigid_links=[fm.RigidLink(0, [1, 2, 3])])


def _rigid_beams():
    """A crooked steel shaft whose nodes are all slaves of one rigid link: K_free = TᵀKT
    holds only cancellation round-off (measured 6e-8 against 7e8 N/m in K)."""
    mesh = fm.Mesh.from_lines([[0, 0, 0], [1, 0.3, 0.2], [2, 0.1, 0.5]], [[0, 1], [1, 2]])
    prop = fm.BeamProperty(sections.circle(0.05), STEEL)
    return fm.build_model(mesh, {"all": prop}, rigid_links=[fm.RigidLink(0, [1, 2])])


@pytest.mark.parametrize("build", [_rigid_point_masses, _rigid_beams])
def test_rigid_by_construction_gives_six_zero_modes(build):
    """Naive: the eigenvalue scale taken from diag(K_free) is 0 (K = 0: 'nothing can
    vibrate') or round-off (shift above the round-off eigenvalues: 'K - σM not positive
    definite'), and residuals relative to that scale are meaningless. Both failed before
    this issue; femmech now takes the scale of the unconstrained model when K_free is
    round-off only (femmech.analysis.modes.model_eigenvalue_scale)."""
    model = build()
    assert model.n_free == 6
    result = fm.modes(model, n_modes=6)  # a FemmechWarning (bad residual) would fail here
    assert result.rigid.all()
    assert_allclose(result.freq_hz, 0.0)
    assert result.residual.max() < 1e-6  # measured 0 and 2e-9
    # the modes are the six rigid motions (M-orthonormal basis of the whole space)
    # bound: M-orthonormal rigid basis: ~n eps·cond(M)
    assert_allclose(result.shapes[model.free].T @ (model.M_free @ result.shapes[model.free]),
                    np.eye(6), atol=1e-12)


@pytest.fixture(scope="module")
def shaft():
    """Free-free steel shaft, 1.2 m, d = 50 mm, 24 elements (150 DOFs)."""
    mesh = line_mesh(24, 1.2, node_sets={"mid": [12], "ends": [0, 24]})
    model = fm.build_model(mesh, {"all": fm.BeamProperty(sections.circle(0.05), STEEL)})
    lam = sla.eigh(model.K_free.toarray(), model.M_free.toarray(), eigvals_only=True)
    return model, lam


@pytest.mark.parametrize("method", ["guyan", "craig-bampton"])
def test_reduced_free_free_shaft_keeps_six_rigid_modes(shaft, method):
    """Naive: a reduction whose interior is not restrained (singular K_ii) divides by a
    round-off pivot, and a reduced pencil whose rigid-body eigenvalues sit at round-off of
    the largest one (~eps λ_max, not ~0) has rigid modes counted as elastic. femmech's
    interface must restrain the interior (checked), and superelement_modes flags rigid
    modes relative to the largest diagonal ratio of the reduced pencil."""
    model, lam = shaft
    if method == "guyan":
        se = guyan(model, ["mid", "ends"])
    else:
        se = craig_bampton(model, "mid", n_modes=8)
    result = superelement_modes(se, n_modes=10, model=model)
    assert result.rigid.tolist() == [True] * 6 + [False] * (result.n_modes - 6)
    R = rigid_fields(model.mesh.points)
    # bound: rigid subspace separated by λ_7: Davis-Kahan eps λ_max/λ_7 (measured 1e-14)
    assert subspace_cos2(result.shapes[:, :6], R, model.M) > 1 - 1e-10  # measured 1e-14
    # elastic modes: Rayleigh-Ritz upper bounds of the full ones (dense reference), tight
    # for Craig-Bampton with residual vectors (measured 2.4e-7), loose for Guyan on three
    # nodes (measured 2.6e-3 for the first bending pair, 0.146 for the second)
    err = np.sqrt(result.omega2[6:10] / lam[6:10]) - 1
    # bound: Rayleigh-Ritz upper bounds; allowance for both solves' eps λ_max/λ (roundoff.py)
    assert err.min() > -1e-9
    assert err.max() < {"guyan": 0.2, "craig-bampton": 1e-6}[method]


def test_free_free_superelement_on_grounded_mechanism():
    """A free-free shaft (superelement) carries a cam mechanism whose follower guide is
    attached to the shaft and grounded by a spring c_g: that grounds one motion of the
    shaft (u_y at the guide), so exactly five of the six rigid-body modes remain at every
    angle. Naive: a coupled solver that factorises C(φ) (singular), or a threshold that
    loses or adds a zero mode as M(φ) changes over the cam's rise. Reference: the
    unreduced coupled model (sparse shift-invert ARPACK with Sturm check)."""
    mesh = line_mesh(24, 1.2, node_sets={"guide": [8], "ends": [0, 24]})
    fe = fm.build_model(mesh, {"all": fm.BeamProperty(RHS, STEEL)})
    mech = rheolinear(cam_mechanism(grounded_guide=True), {**CAM_PARAMS, "c_g": 2e5},
                      {"U": CAM})
    mount = lambda node: Mount(mech, (Attachment("y_g", node, "uy"),), name="cam")  # noqa: E731
    se = craig_bampton(fe, ["guide", "ends"], n_modes=8)
    reduced = couple(se, [mount(8)])
    phi = np.linspace(0.0, 2 * np.pi, 25)
    result = sweep(reduced, phi, n_modes=9)
    elastic = result.freq_hz[:, 5:]
    # zero modes at round-off: the dense shift-invert solve gives ~1e-6 of the scale in
    # frequency (measured < 2e-7 Hz against 12 Hz for the lowest elastic branch)
    n_zero = np.count_nonzero(result.freq_hz < 1e-5 * elastic.min(), axis=1)
    assert n_zero.tolist() == [5] * phi.size
    assert not result.unstable.any()
    for a in (0, 3, 9):  # 0°, 45° (rise), 135° (dwell)
        lam, _ = full_modes(couple(fe, [mount("guide")]), phi[a], 9)
        f_full = np.sqrt(np.clip(lam.real, 0.0, None)) / (2 * np.pi)
        # CB + residual vectors of a 150-DOF shaft: measured 2e-9
        assert_allclose(np.sort(result.freq_hz[a])[5:], f_full[5:], rtol=1e-6)
