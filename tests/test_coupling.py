"""Frame-mechanism coupling and quasi-mode sweeps (core)."""

import numpy as np
import pytest
import scipy.linalg as sla
import sympy
from models import CAM, PARAMS, cam_mechanism, simply_supported_beam
from numpy.testing import assert_allclose

import femmech as fm
from femmech.analysis.sweep import frequency_sensitivities, frozen_modes, mac_matrix, sweep
from femmech.coupling import Attachment, Mount, couple
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
    quasi_modes,
    rheolinear,
)
from femmech.reduction.component_modes import craig_bampton
from femmech.solve.eigen import solve_symmetric

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)
PHI = np.linspace(0.0, 2 * np.pi, 73)


@pytest.fixture(scope="module")
def cam_model():
    return rheolinear(cam_mechanism(True), PARAMS, {"U": CAM})


def test_rigidly_held_guide_reproduces_mechanism_alone(cam_model):
    # Guide attached at a supported node (uy fixed): y_g = 0 exactly, so the coupled
    # spectrum is the union of the frame's and the mechanism-alone quasi-frequencies
    # (quasi_modes on Table 5.1 case 1); dense LAPACK on both: round-off.
    fe = simply_supported_beam()
    se = craig_bampton(fe, "mid", n_modes=10)
    system = couple(se, [Mount(cam_model, (Attachment("y_g", 0, "uy"),), name="cam")])
    alone = quasi_modes(rheolinear(cam_mechanism(False), PARAMS, {"U": CAM}), PHI)
    frame = np.sqrt(sla.eigh(se.K, se.M, eigvals_only=True)[:4]) / (2 * np.pi)
    result = sweep(system, PHI, n_modes=6, track=False)
    for a in range(PHI.size):
        expected = np.sort(np.concatenate([alone.freq_hz[a], frame]))[:6]
        # bound: dense eigh on both sides of a decoupled pencil: eps λ_max/λ (roundoff.py)
        assert_allclose(result.freq_hz[a], expected, rtol=1e-9)


def test_stiff_frame_converges_to_mechanism_alone(cam_model):
    # A frame 100 and 1000 times stiffer: the mechanism branches approach the
    # mechanism-alone values with an error falling like 1/stiffness. (Much stiffer
    # frames hit round-off: dense eigh resolves λ_min to ~eps·λ_max/λ_min ~ 1e-6 at 1e6.)
    alone = quasi_modes(rheolinear(cam_mechanism(False), PARAMS, {"U": CAM}), PHI[:10])
    errors = []
    for factor in (1e2, 1e3):
        se = craig_bampton(simply_supported_beam(E=210e9 * factor), "mid", n_modes=6)
        system = couple(se, [Mount(cam_model, (Attachment("y_g", 20, "uy"),), name="cam")])
        result = sweep(system, PHI[:10], n_modes=2, track=False)
        errors.append(np.abs(result.freq_hz / alone.freq_hz[:, :2] - 1).max())
    assert 0.05 < errors[1] / errors[0] < 0.2  # 10x stiffer, error / 10
    assert errors[1] < 1e-3


def test_reduced_coupled_matches_full_coupled(cam_model):
    # Craig-Bampton (residual vectors) frame vs the unreduced FE frame in the same
    # coupled system, at angles in dwell and rise: frequencies and mode shapes.
    fe = simply_supported_beam()
    mount = lambda node: Mount(cam_model, (Attachment("y_g", node, "uy"),), name="cam")  # noqa: E731
    reduced = couple(craig_bampton(fe, "mid", n_modes=10), [mount(20)])
    full = couple(fe, [mount("mid")])
    result = sweep(reduced, PHI, n_modes=5, keep_vectors=True, track=False)
    for a in (0, 9, 18, 40):  # 0°, 45° (rise), 90°, 200° (return)
        M, _, C, _ = full.matrices(PHI[a])
        ref = solve_symmetric(C, M, n_modes=5)
        f_ref = np.sqrt(ref.omega2) / (2 * np.pi)
        # measured 1e-10 (the frame modes below 800 Hz are resolved to 1e-9 by CB +
        # residual vectors); 1e-7 leaves room for the full solve's own round-off
        assert_allclose(result.freq_hz[a], f_ref, rtol=1e-7)
        se = reduced.frame
        shapes = np.vstack([se.expand_free(result.vectors[a, :reduced.n_frame]),
                            result.vectors[a, reduced.n_frame:]])
        mac = np.diag(mac_matrix(shapes, ref.vectors, M))
        assert mac.min() > 0.999999


def test_elastic_attachment_tends_to_rigid(cam_model):
    # A bearing spring k between the guide coordinate and the frame: as k grows the
    # frequencies approach the rigid attachment's, with error ~ 1/k.
    se = craig_bampton(simply_supported_beam(), "mid", n_modes=10)
    rigid = sweep(couple(se, [Mount(cam_model, (Attachment("y_g", 20, "uy"),))]), PHI[:5],
                  n_modes=5, track=False).freq_hz
    errors = []
    for k in (1e10, 1e12):
        system = couple(se, [Mount(cam_model, (Attachment("y_g", 20, "uy", stiffness=k),))])
        assert system.n == couple(se, [Mount(cam_model, (Attachment("y_g", 20, "uy"),))]).n + 1
        f = sweep(system, PHI[:5], n_modes=5, track=False).freq_hz
        errors.append(np.abs(f / rigid - 1).max())
    assert errors[1] < 2e-2 * errors[0]
    assert errors[1] < 1e-6  # measured 2.3e-7 at k = 1e12 N/m


def _two_oscillators(coupling: float):
    """q1: constant 10 Hz-ish oscillator; q2: stiffness 1 + 0.8 U(θ) varies with the
    angle so that its frequency crosses q1's; an optional spring couples them."""
    theta, q1, q2 = sympy.symbols("theta q1 q2")
    k12 = sympy.Symbol("k12")
    U = position_function("U")
    elements = (PointMass(1.0, (q1,)), PointMass(1.0, (q2,)), Spring(4000.0, q1),
                Potential(sympy.Rational(1, 2) * 4000.0 * (0.6 + 0.8 * U(theta)) * q2**2),
                Spring(k12, q1 - q2))
    mech = Mechanism((q1, q2, theta), elements, drives=(theta,))
    harmonic = CamProfile((CamSegment(np.pi, 1.0, polynomial_345()),
                           CamSegment(np.pi, -1.0, polynomial_345())))
    return rheolinear(mech, {"k12": coupling}, {"U": harmonic})


def _oscillator_system(coupling):
    x = np.linspace(0.0, 2.0, 5)
    tiny = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              [[0, 1], [1, 2], [2, 3], [3, 4]], node_sets={"a": [0], "b": [4]})
    fe = fm.build_model(tiny, {"all": fm.BeamProperty(sections.circle(0.5), STEEL)},
                        supports=[fm.Support("a"), fm.Support("b")])
    se = craig_bampton(fe, [2], n_modes=0)  # a stiff frame far above the band
    return couple(se, [Mount(_two_oscillators(coupling), name="osc")])


def test_tracking_follows_a_crossing():
    # Uncoupled: branch "q1" stays at sqrt(4000)/2π = 10.07 Hz while "q2" sweeps from
    # 7.8 Hz through it to 11.9 Hz and back: tracked branches cross (their order swaps)
    # and each keeps its frequency curve and shape (MAC step ~ 1).
    result = sweep(_oscillator_system(0.0), PHI, n_modes=2)
    f_q1 = np.sqrt(4000.0) / (2 * np.pi)
    # bound: a decoupled oscillator: its frequency is exact to eigh's eps λ_max/λ
    constant = np.abs(result.freq_hz - f_q1).max(axis=0) < 1e-9 * f_q1
    assert constant.sum() == 1  # exactly one branch is the constant q1 branch
    other = result.freq_hz[:, ~constant][:, 0]
    assert other.min() < f_q1 < other.max()  # the other one crosses it
    assert result.mac_step.min() > 0.999
    untracked = sweep(_oscillator_system(0.0), PHI, n_modes=2, track=False)
    assert np.all(np.diff(untracked.freq_hz, axis=1) >= 0)  # sorted: no branch crosses


def test_tracking_keeps_veering_branches_apart():
    # Weakly coupled (k12 = 100 N/m): the branches veer instead of crossing; tracked
    # branch 0 stays the lower one at every angle, with continuous shapes.
    result = sweep(_oscillator_system(100.0), PHI, n_modes=2)
    assert np.all(result.freq_hz[:, 0] < result.freq_hz[:, 1])
    gap = (result.freq_hz[:, 1] - result.freq_hz[:, 0]).min()
    assert gap > 0.05  # the veering gap (~ k12 / (2π·2·sqrt(4000)) ~ 0.13 Hz at least)
    assert result.mac_step.min() > 0.5


def test_sensitivity_matches_finite_differences(cam_model):
    # df_i/dp for the follower stiffness c2 (N/m): Fox-Kapoor formula vs central finite
    # differences of the frequencies (step 1e-4 relative: truncation ~1e-8, round-off
    # ~1e-12/1e-4): agreement to 1e-5 relative; a mode c2 hardly affects has df ~ 0,
    # where the FD quotient is noise: f resolved to ~1e-12 relative over 2h = 100 N/m
    # gives ~2e-12 Hz/(N/m), so atol = 1e-7 max|df| (5e-12).
    se = craig_bampton(simply_supported_beam(), "mid", n_modes=10)

    def build(c2):
        model = rheolinear(cam_mechanism(True), {**PARAMS, "c2": c2}, {"U": CAM})
        return couple(se, [Mount(model, (Attachment("y_g", 20, "uy"),))])

    c2, phi = PARAMS["c2"], 0.6
    f, df = frequency_sensitivities(build, c2, phi, n_modes=4)
    h = 1e-4 * c2
    fp = frozen_modes(*_mbc(build(c2 + h), phi), n_modes=4)[1]
    fm_ = frozen_modes(*_mbc(build(c2 - h), phi), n_modes=4)[1]
    assert_allclose(df, (fp - fm_) / (2 * h), rtol=1e-5, atol=1e-7 * np.abs(df).max())
    assert np.abs(df).max() > 0  # c2 matters for at least one mode


def _mbc(system, phi):
    M, B, C, _ = system.matrices(phi)
    return M, B, C


def test_damped_form_reduces_to_undamped_without_damping(cam_model):
    # With B = 0 the first-order form gives s = ±iω: the same frequencies, zero damping.
    se = craig_bampton(simply_supported_beam(), "mid", n_modes=6)
    system = couple(se, [Mount(cam_model, (Attachment("y_g", 20, "uy"),))])
    M, B, C, _ = system.matrices(0.4)
    undamped = frozen_modes(M, B, C, 4)
    damped = frozen_modes(M, 0 * B, C, 4, damped=True)
    assert_allclose(damped[1], undamped[1], rtol=1e-8)
    assert np.abs(damped[2]).max() < 1e-8


def test_attachment_errors(cam_model):
    se = craig_bampton(simply_supported_beam(), "mid", n_modes=4)
    with pytest.raises(ValueError, match="unknown coordinate 'y'"):
        couple(se, [Mount(cam_model, (Attachment("y", 20, "uy"),), name="cam")])
    with pytest.raises(ValueError, match="attached twice"):
        couple(se, [Mount(cam_model, (Attachment("y_g", 20, "uy"), Attachment("y_g", 20, "uz")))])
    with pytest.raises(ValueError, match="unknown direction"):
        couple(se, [Mount(cam_model, (Attachment("y_g", 20, "up"),))])


def test_multiplier_form_equals_primal(cam_model):
    # Seed 5.2.1 eq. 21: keeping the guide coordinate and enforcing y_g = u_frame by a
    # multiplier gives the same quasi-modes as eliminating it (QZ vs Cholesky-based
    # LAPACK on the same physics: round-off, ~1e-9 relative for these pencils).
    se = craig_bampton(simply_supported_beam(), "mid", n_modes=8)
    mount = Mount(cam_model, (Attachment("y_g", 20, "uy"),), name="cam")
    primal = sweep(couple(se, [mount]), PHI[::6], n_modes=5, track=False)
    system = couple(se, [mount], form="multiplier")
    assert system.H.shape == (1, system.n)
    mixed = sweep(system, PHI[::6], n_modes=5, track=False)
    assert_allclose(mixed.freq_hz, primal.freq_hz, rtol=1e-8)
    with pytest.raises(ValueError, match="form must be"):
        couple(se, [mount], form="mixed")


def test_speed_sweep_tracks_unsymmetric_stiffness(cam_model):
    # Drive-speed sweep at a fixed angle in the rise: with Ω > 0 the kinematic terms make
    # C(φ, Ω) unsymmetric (seed 5.2.2: "C is non-symmetric"), so the eig path is used;
    # at Ω = 0 it must equal the symmetric sweep, and the frequencies move continuously
    # with Ω (tracked branches: small steps, MAC steps ~ 1).
    from femmech.analysis.sweep import parameter_sweep

    se = craig_bampton(simply_supported_beam(), "mid", n_modes=8)
    system = couple(se, [Mount(cam_model, (Attachment("y_g", 20, "uy"),), name="cam")])
    speeds = np.linspace(0.0, 60.0, 31)  # rad/s
    result = parameter_sweep(lambda W: (system, W), speeds, phi=0.6, n_modes=4)
    assert result.form == "unsymmetric"
    at_rest = sweep(system, [0.6], n_modes=4, track=False)
    # bound: the same pencil at speed 0 solved by two paths: eps λ_max/λ (roundoff.py)
    assert_allclose(result.freq_hz[0], at_rest.freq_hz[0], rtol=1e-9)
    assert np.abs(np.diff(result.freq_hz, axis=0)).max() < 0.05 * result.freq_hz.min()
    assert result.mac_step.min() > 0.99
    assert np.abs(result.freq_hz[-1] - result.freq_hz[0]).max() > 1e-3  # Ω matters


def test_free_floating_frame_keeps_rigid_body_modes(cam_model):
    # An unsupported beam carrying the cam mechanism: nothing grounds the frame, so six
    # quasi-frequencies are 0 (the shift-inverted dense solve handles the singular C),
    # and the elastic ones match the unreduced coupled model (CB + residual vectors).
    n = 20
    x = np.linspace(0.0, 1.0, n + 1)
    mesh = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(n), np.arange(1, n + 1)]),
                              node_sets={"mid": [n // 2], "ends": [0, n]})
    prop = fm.BeamProperty(sections.rectangular_hollow(0.06, 0.08, 0.004), STEEL)
    fe = fm.build_model(mesh, {"all": prop})
    mount = lambda node: Mount(cam_model, (Attachment("y_g", node, "uy"),))  # noqa: E731
    reduced = couple(craig_bampton(fe, ["mid", "ends"], n_modes=6), [mount(n // 2)])
    result = sweep(reduced, PHI[:6], n_modes=9, track=False)
    scale = result.freq_hz[:, 6:].min()
    # round-off level of a zero eigenvalue: ~eps·λ_max/λ → frequency ~1e-6 of the scale
    assert np.all(result.freq_hz[:, :6] < 1e-5 * scale)
    from femmech.analysis.reference import full_modes

    lam, _ = full_modes(couple(fe, [mount("mid")]), PHI[3], 9)
    f_full = np.sqrt(np.clip(lam.real, 0, None)) / (2 * np.pi)
    assert_allclose(result.freq_hz[3, 6:], f_full[6:], rtol=1e-6)


def test_assembly_frame_equals_single_superelement(cam_model):
    # The beam split in two superelements (assembled at the mid node) carries the
    # mechanism at the shared node (part, node) — the same machine as one superelement
    # of the whole beam: equal quasi-frequencies (both exact to ~1e-9 in this band).
    from femmech.fe.mesh import line_submesh
    from femmech.reduction.substructures import assemble_parts

    fe = simply_supported_beam()
    mesh = fe.mesh
    left = mesh.points[mesh.cells["line"]].mean(axis=1)[:, 0] < 0.5
    parts = []
    for keep in (left, ~left):
        sub, ids = line_submesh(mesh, keep)
        node_sets = {"ends": [i for i, g in enumerate(ids) if g in (0, 40)]}
        sub = fm.Mesh(sub.points, sub.cells, sub.cell_sets, node_sets)
        supports = [fm.Support("ends", "translations")]
        if 0 in ids:
            supports.append(fm.Support(int(np.flatnonzero(ids == 0)[0]), ["rx"]))
        part = fm.build_model(sub, {"all": fe_property()}, supports=supports)
        cut = int(np.flatnonzero(ids == 20)[0])
        parts.append((craig_bampton(part, [cut], n_modes=10), cut))
    assembly = assemble_parts([se for se, _ in parts])
    mount = Mount(cam_model, (Attachment("y_g", (0, parts[0][1]), "uy"),))
    split = sweep(couple(assembly, [mount]), PHI[:8], n_modes=5, track=False)
    whole = sweep(couple(craig_bampton(fe, "mid", n_modes=20),
                         [Mount(cam_model, (Attachment("y_g", 20, "uy"),))]),
                  PHI[:8], n_modes=5, track=False)
    assert_allclose(split.freq_hz, whole.freq_hz, rtol=1e-6)


def fe_property():
    return fm.BeamProperty(sections.rectangular_hollow(0.06, 0.08, 0.004), STEEL)


def test_batched_angle_matrices_equal_per_angle_assembly(cam_model):
    # The sweep evaluates the mechanisms once for all angles, grouped by model and ratio
    # (here one model at two phases and two ratios), and adds the blocks per angle at
    # precomputed entries; mounts "a" and "c" share the frame coordinate of node 20.
    from femmech.analysis.sweep import _angle_matrices
    from femmech.coupling import assemble_at

    se = craig_bampton(simply_supported_beam(), "mid", n_modes=6)
    system = couple(se, [
        Mount(cam_model, (Attachment("y_g", 20, "uy"),), name="a"),
        Mount(cam_model, (Attachment("y_g", 20, "uy", stiffness=1e8, damping=50.0),),
              phase=0.7, name="b"),
        Mount(cam_model, (Attachment("y_g", 20, "uy"),), ratio=2.0, phase=0.7, name="c")])
    assert np.intersect1d(system.touched[0], system.touched[2]).size == 1
    phi, Omega, Omega_dot = PHI[:20], 30.0, 5.0
    blocks = system.mechanism_blocks(phi, Omega, Omega_dot)
    for mount, P, got in zip(system.mounts, system.projections, blocks, strict=True):
        m, r = mount.model, mount.ratio
        angle = r * phi + mount.phase
        own = (m.M(angle), m.B(angle, r * Omega), m.C(angle, r * Omega, r * Omega_dot))
        for A, B in zip(got, own, strict=False):  # got also holds F
            # bound: a congruence Pᵀ B P of exact selection matrices: a few eps
            assert_allclose(A, np.einsum("ki,akl,lj->aij", P, B, P), rtol=1e-13, atol=0)
        assert_allclose(got[3], m.F(angle, r * Omega, r * Omega_dot) @ P, rtol=1e-13)
    for damped in (True, False):
        matrices = _angle_matrices(system, phi, Omega, Omega_dot, damped)
        for a in range(phi.size):
            expected = assemble_at(system, blocks, a)[:3]
            for A, B in zip(matrices(a), expected, strict=True):
                if A is None:
                    assert not damped
                    continue
                # bound: the same products in another order: a few eps of the largest
                assert np.abs(A - B).max() <= 1e-13 * np.abs(B).max()


@pytest.mark.parametrize("n_modes", [3, 8])
def test_dense_symmetric_drivers_agree(monkeypatch, n_modes):
    # femmech.solve.dense.dense_symmetric solves the shift-inverted pencil for all pairs
    # (sygvd, 8 of 30 wanted) or the wanted ones (sygvx, 3 of 30, the sweep's frozen-angle
    # solves): both give the same lowest pairs to round-off, with a massless coordinate
    # (infinite λ, dropped) and with a rigid-body mode (singular C: its μ = 1/(0 - σ)
    # dominates, and the round-off of the others grows to ~eps·λ/|σ|, here ~1e-11).
    from femmech.solve import dense
    rng = np.random.default_rng(7)
    n = 30
    A, B = rng.standard_normal((n, n)), rng.standard_normal((n, n))
    M = B @ B.T / n + np.eye(n)
    M[-1], M[:, -1] = 0.0, 0.0
    C = A @ A.T + n * np.eye(n)
    free = np.eye(n) - np.full((n, n), 1.0 / n)  # removes the rigid motion (1, ..., 1)
    assert 3 < dense.ALL_PAIRS_FRACTION * n < 8
    for stiffness, rtol in ((C, 1e-12), (free @ C @ free, 1e-9)):
        lam, V = dense.dense_symmetric(stiffness, M, n_modes)
        other = 2.0 if n_modes == 8 else 0.0  # the other driver
        monkeypatch.setattr(dense, "ALL_PAIRS_FRACTION", other)
        lam_ref, V_ref = dense.dense_symmetric(stiffness, M, n_modes)
        monkeypatch.undo()
        assert lam.size == n_modes
        # bound: dense LAPACK against the monkeypatched path, same pencil: atol eps-level of λ_max
        assert_allclose(lam, lam_ref, rtol=rtol, atol=1e-12 * lam[-1])
        # bound: M-orthonormal eigenvectors: ~n eps·cond(M)
        assert_allclose(V.T @ M @ V, np.eye(n_modes), atol=1e-10)
        # bound: same eigenvectors from two solvers: Davis-Kahan eps λ_max/gap
        assert_allclose(np.abs(np.einsum("ij,ij->j", V, M @ V_ref)), 1.0, rtol=1e-9)
    # bound: rigid-body λ = 0 ± eps λ_max (roundoff.py)
    assert abs(lam[0]) < 1e-10 * lam[-1]  # the rigid-body mode


def test_subspace_mac_equals_pseudo_inverse_formula():
    # subspace_mac (eigen-decomposed Gram of each group) against the pseudo-inverse
    # formula x̄ᵀ W Y_g (Y_gᴴ W Y_g)⁺ Y_gᴴ W x / (xᴴ W x), with a rank-deficient group.
    from femmech.analysis.sweep import subspace_mac

    rng = np.random.default_rng(11)
    n = 12
    A = rng.standard_normal((n, n))
    W = A @ A.T + n * np.eye(n)
    X, Y = rng.standard_normal((n, 4)), rng.standard_normal((n, 6))
    Y[:, 2] = Y[:, 0] - 2.0 * Y[:, 1]  # group [0, 1, 2] spans two dimensions only
    groups = [np.array([0, 1, 2]), np.array([3]), np.array([4, 5])]
    expected = np.empty((4, 6))
    nx = np.einsum("ij,ij->j", X, W @ X)
    for g in groups:
        P = Y[:, g].T @ W @ X
        coef = np.linalg.pinv(Y[:, g].T @ W @ Y[:, g], rcond=1e-12, hermitian=True) @ P
        expected[:, g] = (np.einsum("ij,ij->j", P, coef) / nx)[:, None]
    # bound: the same Gram products and pinv: ~eps·cond of the group's Gram matrix
    assert_allclose(subspace_mac(X, Y, groups, W), expected, rtol=1e-10)
    # bound: a one-vector group: subspace MAC = MAC, the same products: a few eps
    assert_allclose(subspace_mac(X, Y[:, 3:4], [np.array([0])], W)[:, 0],
                    mac_matrix(X, Y[:, 3:4], W)[:, 0], rtol=1e-12)


def test_sweep_threads_follow_femmech_threads(monkeypatch, cam_model):
    # The per-angle solves run in femmech.solve.threads' solve phase (1 BLAS thread by
    # default); the former blas_threads argument still works but is deprecated.
    import warnings

    from threadpoolctl import threadpool_info

    import femmech.analysis.sweep as sweep_module
    from femmech.solve import threads
    system = couple(craig_bampton(simply_supported_beam(), "mid", n_modes=6),
                    [Mount(cam_model, (Attachment("y_g", 20, "uy"),))])
    seen, solve = [], sweep_module.frozen_modes

    def spy(*args, **kwargs):
        seen.append({lib["num_threads"] for lib in threadpool_info()})
        return solve(*args, **kwargs)

    monkeypatch.setattr(sweep_module, "frozen_modes", spy)
    with threads.limit(solve=1), warnings.catch_warnings():
        warnings.simplefilter("error")
        result = sweep(system, PHI[:3], n_modes=3)
    assert seen
    assert all(s == {1} for s in seen)
    with pytest.warns(DeprecationWarning, match="blas_threads") as record:
        old = sweep(system, PHI[:3], n_modes=3, blas_threads=1)
    assert record[0].filename == __file__
    assert_allclose(old.eigenvalues, result.eigenvalues, rtol=0)
