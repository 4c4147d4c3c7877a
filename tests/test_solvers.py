"""Sparse direct solver layer, thread control and AMG-preconditioned LOBPCG.

Every installed backend is compared with SuperLU (always tested) and with independent
references: dense LAPACK (``numpy.linalg.solve``, ``eigvalsh``, ``slogdet``) on the same
matrices, and scipy's shift-invert for the LOBPCG path. Backends that are not installed
are skipped (``pip install femmech[fast]`` gives PARDISO; CHOLMOD needs SuiteSparse).

Tolerances: a solve loses about ``eps · cond(A)`` (relative); the frames here have
cond(K - σM) ≈ 1e6..1e8, so 1e-10 relative agreement between backends is round-off.
"""

from __future__ import annotations

import pickle
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp
from numpy.testing import assert_allclose, assert_array_equal
from threadpoolctl import threadpool_info, threadpool_limits

import femmech as fm
from femmech.fe import nullspace, sections
from femmech.fe.generators import grid_frame
from femmech.reduction.component_modes import craig_bampton
from femmech.solve import direct, lobpcg, pardiso, threads
from femmech.solve.eigen import solve_symmetric
from femmech.solve.factor import Factor
from femmech.solve.pencil import eigenvalue_scale, factorize
from femmech.solve.sturm import inertia_below

sys.path.insert(0, str(Path(__file__).resolve().parent))
from models import grid_solid  # noqa: E402

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)
RHS = sections.rectangular_hollow(0.06, 0.08, 0.004)
FAST = [pytest.param(name, marks=pytest.mark.skipif(
    name not in direct.available(), reason=f"{name} not installed")) for name in direct.BACKENDS]


def frame_model(bays=(2, 1, 1), subdivisions=3, supported=True):
    mesh = grid_frame(bays, (1.2, 0.8, 1.0), subdivisions)
    prop = fm.BeamProperty(RHS, STEEL)
    return fm.build_model(mesh, dict.fromkeys(mesh.cell_sets, prop),
                          supports=[fm.Support("base")] if supported else [])


@pytest.fixture(scope="module")
def pencil():
    """K, M of a clamped grid frame (636 free DOFs) and its spectrum (dense LAPACK)."""
    model = frame_model(subdivisions=6)
    K, M = model.K_free.tocsc(), model.M_free.tocsc()
    with threadpool_limits(1):  # 0.2 s; 2 BLAS threads took 22 s on the loaded 2-core box
        lam = sla.eigh(K.toarray(), M.toarray(), eigvals_only=True)
    return K, M, lam


def test_backends_report_availability_and_superlu_is_always_there():
    assert "superlu" in direct.available()
    assert set(direct.available()) <= set(direct.BACKENDS)
    assert direct.available()[-1] == "superlu"  # the fallback of "auto" comes last
    assert direct.versions()["superlu"].startswith("scipy")


@pytest.mark.parametrize("name", FAST)
def test_solves_agree_with_dense_and_superlu(pencil, name):
    K, M, lam = pencil
    sigma = -1e-3 * lam[0]  # below the spectrum: K - σM positive definite
    A = (K - sigma * M).tocsc()
    rng = np.random.default_rng(1)
    b, B = rng.standard_normal(A.shape[0]), rng.standard_normal((A.shape[0], 4))
    f = direct.factorize(A, name)
    assert f.name == name
    assert f.n == A.shape[0]
    assert f.definite
    assert f.n_negative == 0
    ref = np.linalg.solve(A.toarray(), np.column_stack([b, B]))  # dense LAPACK
    x, X = f.solve(b), f.solve(B)
    assert x.shape == b.shape
    assert X.shape == B.shape
    # bound: cond(A) ~ λ_max/σ ~ 1e7 here: 1e-10 relative is round-off
    assert np.linalg.norm(x - ref[:, 0]) <= 1e-10 * np.linalg.norm(ref[:, 0])
    assert np.linalg.norm(X - ref[:, 1:]) <= 1e-10 * np.linalg.norm(ref[:, 1:])
    lu = direct.factorize(A, "superlu")
    # bound: eps·cond(A) of a linear solve, cond ~1e7 (comment above)
    assert np.linalg.norm(x - lu.solve(b)) <= 1e-10 * np.linalg.norm(x)


@pytest.mark.parametrize("name", FAST)
@pytest.mark.parametrize("index", [0, 7, 40])
def test_inertia_counts_eigenvalues_below_the_shift(pencil, name, index):
    # K - σM with σ midway between λ_index and λ_index+1 has exactly index + 1 negative
    # eigenvalues (Sylvester's law of inertia; λ from dense eigvalsh of L⁻¹KL⁻ᵀ)
    K, M, lam = pencil
    cut = 0.5 * (lam[index] + lam[index + 1])
    f = direct.factorize((K - cut * M).tocsc(), name, definite=False)
    assert f.n_negative == index + 1
    assert not f.definite
    assert f.n_negative == direct.factorize((K - cut * M).tocsc(), "superlu").n_negative
    # the indefinite factor solves too: backward error ‖Ax - b‖ / (‖A‖ ‖x‖) at round-off
    # (1e-12 leaves room for the growth of pivots of an LDLᵀ without pivoting)
    A = (K - cut * M).tocsc()
    b = np.random.default_rng(2).standard_normal(K.shape[0])
    x = f.solve(b)
    # bound: backward error of a stable factorisation: ~n eps ‖A‖ ‖x‖
    assert np.linalg.norm(A @ x - b) <= 1e-12 * sp.linalg.norm(A) * np.linalg.norm(x)


@pytest.mark.parametrize("name", FAST)
def test_definite_hint_falls_back_or_refuses(pencil, name):
    K, M, lam = pencil
    A = (K - 0.5 * (lam[2] + lam[3]) * M).tocsc()
    assert direct.factorize(A, name, definite=None).n_negative == 3  # tried, fell back
    if name != "superlu":  # SuperLU has one mode for all
        with pytest.raises(ValueError, match="not positive definite"):
            direct.factorize(A, name, definite=True)


@pytest.mark.parametrize("name", FAST)
def test_refactor_reuses_the_analysis(pencil, name):
    K, M, lam = pencil
    f = direct.factorize((K + 1.0 * M).tocsc(), name)
    analysed = f.timings["analyse"]
    b = np.arange(K.shape[0], dtype=float)
    for sigma in (-2.0, -0.5 * lam[0]):  # new positive definite values
        A = (K - sigma * M).tocsc()
        assert f.refactor(A) is f
        fresh = direct.factorize(A, "superlu").solve(b)
        # bound: cond(A) <= λ_max / (0.5 λ_1) ~ 1e7: 1e-10 relative is round-off
        assert np.linalg.norm(f.solve(b) - fresh) <= 1e-10 * np.linalg.norm(fresh)
    if name != "superlu":  # no new symbolic phase (SuperLU has none to keep)
        assert f.timings["analyse"] == analysed
    # values that are no longer positive definite: the factor switches to LDLᵀ
    A = (K - 0.5 * (lam[4] + lam[5]) * M).tocsc()
    assert f.refactor(A).n_negative == 5
    fresh = direct.factorize(A, "superlu").solve(b)
    # bound: eps·cond(A) of a linear solve near λ_5: cond ~1e8
    assert np.linalg.norm(f.solve(b) - fresh) <= 1e-9 * np.linalg.norm(fresh)
    with pytest.raises(ValueError, match="order"):
        f.refactor(sp.eye(3, format="csc"))


def test_pardiso_refuses_another_pattern(pencil):
    if "pardiso" not in direct.available():
        pytest.skip("pardiso not installed")
    K, M, _ = pencil
    f = direct.factorize((K + M).tocsc(), "pardiso")
    with pytest.raises(ValueError, match="pattern"):
        f.refactor(sp.eye(K.shape[0], format="csc") + sp.eye(K.shape[0], k=5))


def test_pardiso_thread_settings_may_change_between_calls(pencil):
    # regression: an analysis on 2 threads followed by a factorisation on 1 (the factor
    # phase limited after MKL was loaded) gave wrong solutions, then a segfault
    if "pardiso" not in direct.available():
        pytest.skip("pardiso not installed")
    K, M, lam = pencil
    A = (K + M).tocsc()
    b = np.ones(K.shape[0])
    direct.factorize(A, "pardiso")
    with threads.limit(factor=1):
        f = direct.factorize(A, "pardiso")
    with threads.limit(factor=2):
        f.refactor((K + 2 * M).tocsc())
    for solve_threads in (1, 2):
        with threadpool_limits(solve_threads):
            x = f.solve(b)
        A2 = K + 2 * M
        # bound: backward error of a stable factorisation: ~n eps ‖A‖ ‖x‖
        assert np.linalg.norm(A2 @ x - b) <= 1e-12 * sp.linalg.norm(A2) * np.linalg.norm(x)


def test_pardiso_parallel_block_solve_equals_the_column_loop(pencil, monkeypatch):
    # wide blocks on sparse factors are split between copies of the factor solved
    # concurrently (pardiso.PARALLEL_SOLVE_COLUMNS); same ordering and values: the same
    # floating-point operations per column, so the results are bitwise equal
    if "pardiso" not in direct.available():
        pytest.skip("pardiso not installed")
    K, M, _ = pencil
    f = direct.factorize((K + M).tocsc(), "pardiso")
    assert f.iparm[17] < pardiso.PARDISO_LOOP_FILL * f.n  # the column loop applies
    b = np.random.default_rng(3).standard_normal((K.shape[0], 9))
    serial = f.solve(b)
    monkeypatch.setattr(pardiso, "PARALLEL_SOLVE_COLUMNS", 4)
    with threads.limit(factor=3):
        parallel = f.solve(b)
    assert len(f._twins) == 2
    assert_array_equal(parallel, serial)
    A2 = (K + 2 * M).tocsc()
    f.refactor(A2)  # new values: the copies are dropped, not reused with old values
    assert f._twins == []
    with threads.limit(factor=2):
        x = f.solve(b)
    # bound: backward error of a stable factorisation: ~n eps ‖A‖ ‖x‖
    assert np.linalg.norm(A2 @ x - b) <= 1e-12 * sp.linalg.norm(A2) * np.linalg.norm(x)


@pytest.mark.parametrize("name", FAST)
def test_pivots_give_the_determinant_and_bound_the_diagonal(pencil, name):
    K, M, lam = pencil
    A = (K + 1e-3 * lam[0] * M).tocsc()
    piv, order = direct.factorize(A, name).pivots()
    assert np.array_equal(np.sort(order), np.arange(A.shape[0]))
    # bound: product of the pivots = det A (numpy slogdet: dense LU), 1e-10 relative in log
    sign, logdet = np.linalg.slogdet(A.toarray())
    assert sign == 1.0
    assert abs(np.log(piv).sum() - logdet) <= 1e-10 * abs(logdet)
    # positive definite: every pivot (a Schur complement diagonal) lies in (0, A_jj]
    assert np.all(piv > 0)
    # bound: pivots of an SPD factorisation <= A_jj in exact arithmetic: a few eps
    assert np.all(piv <= A.diagonal()[order] * (1 + 1e-12))


@pytest.mark.parametrize("name", FAST)
def test_singular_matrix_is_reported(name):
    # a DOF with neither stiffness nor mass: an exactly zero row and column
    A = sp.diags([2.0, 0.0, 3.0]).tocsc()
    with pytest.raises(ValueError, match="singular|not positive definite"):
        direct.factorize(A, name, definite=False if name != "superlu" else None)


@pytest.mark.parametrize("name", FAST)
def test_modes_report_the_solver_and_agree_across_backends(name):
    model = frame_model(bays=(2, 1, 1), subdivisions=5)  # 516 free DOFs > DENSE_BELOW
    ref = fm.modes(model, n_modes=12, solver="superlu")
    result = fm.modes(model, n_modes=12, solver=name)
    assert (ref.method, result.method) == ("arpack", "arpack")
    assert (ref.solver, result.solver) == ("superlu", name)
    assert result.sturm_count == result.n_modes  # inertia of K - cut M from this backend
    # bound: both converge ARPACK to round-off of the same pencil: measured 1e-13 relative;
    # each factorisation's backward error moves λ by eps λ_max: 10 eps λ_max/λ_1 = 3.4e-10
    # (roundoff.py; 1e-10 lay below it)
    assert_allclose(result.omega2, ref.omega2, rtol=1e-9)


def test_small_models_take_cholmod_or_superlu_and_dense_has_no_solver():
    model = frame_model(bays=(1, 1, 1), subdivisions=2)  # < DENSE_BELOW: LAPACK
    assert fm.modes(model, n_modes=3).solver is None
    small = "cholmod" if "cholmod" in direct.available() else "superlu"
    assert direct.resolve("auto", direct.AUTO_MIN_SIZE - 1) == small
    assert direct.resolve("auto", direct.AUTO_MIN_SIZE) == direct.available()[0]


def test_solver_names_are_checked(monkeypatch):
    with pytest.raises(ValueError, match="unknown solver 'umfpack'"):
        direct.resolve("umfpack")
    with pytest.raises(ValueError, match="unknown solver"):
        fm.modes(frame_model(), n_modes=3, solver="umfpack")
    monkeypatch.setattr(direct, "available", lambda: ("superlu",))
    with pytest.raises(ImportError, match="femmech\\[fast\\]"):
        direct.resolve("pardiso")
    with pytest.raises(ValueError, match="right-hand side of shape"):
        direct.factorize(sp.eye(3, format="csc"), "superlu").solve(np.ones(4))


def test_default_solver_from_environment_and_use(monkeypatch):
    monkeypatch.setenv(direct.ENV_VAR, "superlu")
    assert direct.default_solver() == "superlu"
    with direct.use("auto"):
        assert direct.default_solver() == "auto"
        with direct.use(None):
            assert direct.default_solver() == "auto"
    assert direct.default_solver() == "superlu"


def test_linalg_factorize_keeps_superlu_behaviour(pencil):
    # the SuperLU path of femmech.solve.pencil.factorize is the same call as before the solver
    # layer: SuperLU attributes stay reachable and the inertia count is unchanged
    K, M, lam = pencil
    with direct.use("superlu"):
        lu = factorize((K - 0.5 * (lam[3] + lam[4]) * M).tocsc())
        assert lu.name == "superlu"
        assert np.array_equal(lu.perm_r, lu.perm_c)  # diagonal pivots only
        assert int(np.count_nonzero(lu.U.diagonal() < 0)) == lu.n_negative == 4
        assert inertia_below(K, M, 0.5 * (lam[9] + lam[10])) == 10


def test_factor_pickles_as_none(pencil):
    # a factor is a per-process cache: it travels as None (studies send superelements to
    # worker processes), and the receiver factorises again where it needs one
    K, M, _ = pencil
    f = direct.factorize((K + M).tocsc(), "superlu")
    assert pickle.loads(pickle.dumps(f)) is None
    se = craig_bampton(frame_model(), "top", n_modes=3)
    assert isinstance(se.interior_factor, Factor)
    copy = pickle.loads(pickle.dumps(se))
    assert copy.interior_factor is None
    np.testing.assert_array_equal(copy.K, se.K)


# --- threads --------------------------------------------------------------------------

def test_thread_settings_parse_and_restore():
    assert threads.parse("solve=1,factor=2") == threads.ThreadSettings(1, 2)
    assert threads.parse("3") == threads.ThreadSettings(3, 3)
    assert threads.parse("factor=none") == threads.ThreadSettings(1, None)
    for bad in ("solve=0", "solve=x", "gemm=2"):
        with pytest.raises(ValueError, match=threads.ENV_VAR):
            threads.parse(bad)
    before = threads.settings()
    with threads.limit(solve=2, factor=1) as inside:
        assert inside == threads.ThreadSettings(2, 1)
    assert threads.settings() == before
    with pytest.raises(ValueError, match="positive integer"):
        threads.set_threads(solve=0)
    assert "solve=" in threads.describe()


def test_solve_phase_limits_every_loaded_library():
    np.ones((4, 4)) @ np.ones((4, 4))  # make sure a BLAS is loaded
    with threads.limit(solve=1), threads.solve_phase():
        assert all(lib["num_threads"] == 1 for lib in threadpool_info())


def test_gemm_phase_inside_a_solve_phase_and_back():
    np.ones((4, 4)) @ np.ones((4, 4))
    counts = lambda: {lib["num_threads"] for lib in threadpool_info()}  # noqa: E731
    outside = counts()
    with threads.limit(solve=1, factor=None), threads.solve_phase():
        with threads.gemm_phase():  # factor None: the counts from before the solve phase
            assert counts() == outside
        assert counts() == {1}
        with threads.limit(factor=1), threads.gemm_phase():
            assert counts() == {1}
    assert counts() == outside
    with threads.limit(factor=1), threads.gemm_phase():  # outside any phase: the factor limit
        assert counts() == {1}
    assert counts() == outside


def test_cached_library_list_sees_libraries_loaded_later():
    threads.refresh()
    first = threads.blas_controller()
    assert threads.blas_controller() is first  # cached: no new lookup (~2.5 ms each)
    threads.refresh()
    assert threads.blas_controller() is not first
    with threads.exactly(1):
        assert {lib["num_threads"] for lib in threadpool_info()} == {1}

# --- LOBPCG ---------------------------------------------------------------------------

def test_rigid_body_modes_span_the_null_space_of_a_free_model():
    # u = t + θ × r (and θ on rotation DOFs) is a rigid motion: K_free B = 0 to round-off
    model = frame_model(supported=False)
    B = nullspace.near_nullspace(model)
    K = model.K_free
    assert B.shape == (model.n_free, 6)
    # bound: rigid motions: K B = 0 in exact arithmetic, ~n eps ‖K‖ ‖B‖
    assert np.linalg.norm(K @ B) <= 1e-12 * sp.linalg.norm(K) * np.linalg.norm(B)
    assert np.linalg.matrix_rank(B) == 6
    assert nullspace.node_blocksize(model.free) == 6
    assert nullspace.node_blocksize(np.array([0, 1, 2, 6, 7, 8])) == 3
    assert nullspace.node_blocksize(np.array([0, 1, 3])) == 1


def test_lobpcg_sees_arrays_only():
    """The solver's rigid-body vectors and node blocks take each DOF's node coordinates,
    component and node: no DOF numbering, no FE model. Two nodes at x = 0 and x = 1 m on
    the x axis, one with all six components, one with translations only."""
    x = np.array([[0.0, 0.0, 0.0]] * 6 + [[1.0, 0.0, 0.0]] * 3)
    component = np.array([0, 1, 2, 3, 4, 5, 0, 1, 2])
    B = lobpcg.rigid_body_vectors(x, component)
    # rotation rz about the centroid (x = 1/3 m) moves the second node by 2/3 m in y
    # (θ × r with θ = e_z, r = (2/3, 0, 0)), exactly representable to round-off
    assert B[7, 5] == pytest.approx(2.0 / 3.0, rel=1e-15)  # bound: one subtraction, eps
    assert B[5, 5] == 1.0  # the rz DOF of the first node
    assert B[3, 5] == 0.0
    assert lobpcg.node_blocks(np.repeat([0, 1], 3), np.tile([0, 1, 2], 2)) == 3
    assert lobpcg.node_blocks(np.zeros(6, int), np.arange(6)) == 6
    assert lobpcg.node_blocks(np.array([0, 0, 0]), np.array([0, 1, 3])) == 1
    assert "DOF_PER_NODE" not in vars(lobpcg)  # the DOF numbering is stage 2's


@pytest.fixture(scope="module")
def solid_block():
    """Hexahedral steel block 1 x 0.2 x 0.3 m, 20 x 4 x 6 elements, clamped at x = 0
    (2 100 free DOFs, 3 per node)."""
    mesh = grid_solid("hexahedron", np.linspace(0, 1, 21), np.linspace(0, 0.2, 5),
                      np.linspace(0, 0.3, 7))
    # bound: generated coordinates: the root face at x = 0 to ~eps
    root = np.flatnonzero(mesh.points[:, 0] < 1e-12)
    return fm.build_model(mesh, solids={"solid": fm.SolidProperty(STEEL)},
                          supports=[fm.Support(root, "translations")])


def test_lobpcg_matches_shift_invert_on_a_solid_block(solid_block):
    model = solid_block
    assert lobpcg.node_blocksize(model.free) == 3
    ref = fm.modes(model, n_modes=10)
    result = fm.modes(model, n_modes=10, method="lobpcg")
    assert (result.method, result.solver, result.sturm_count) == ("lobpcg", "pyamg", None)
    # the same discrete pencil: first 10 frequencies to 1e-6 (measured 1e-12 at the
    # default rtol = 1e-8; eigenvalue errors go like the residual squared)
    assert_allclose(result.freq_hz, ref.freq_hz, rtol=1e-6)
    mac = np.abs(np.einsum("ij,ij->j", result.shapes, model.M @ ref.shapes))
    assert np.all(mac > 1 - 1e-6)  # the same mass-normalised shapes


def test_lobpcg_arguments_are_checked(solid_block):
    with pytest.raises(ValueError, match="n_modes"):
        fm.modes(solid_block, band_hz=(0, 100), method="lobpcg")
    with pytest.raises(ValueError, match="method"):
        fm.modes(solid_block, n_modes=2, method="jacobi-davidson")
    K = solid_block.K_free
    M = sp.diags(np.r_[0.0, np.ones(K.shape[0] - 1)])
    with pytest.raises(ValueError, match="mass on every DOF"):
        lobpcg.lobpcg_symmetric(K, M, 3)
    with pytest.raises(ValueError, match="n_modes"):
        lobpcg.lobpcg_symmetric(K, solid_block.M_free, 0)


def test_eigen_result_reports_a_user_factor(pencil):
    K, M, _ = pencil
    scale = eigenvalue_scale(K, M)
    f = direct.factorize((K + 1e-6 * scale * M).tocsc(), "superlu")
    result = solve_symmetric(K, M, n_modes=4, sigma=-1e-6 * scale, factor=f)
    assert result.solver == "superlu"
