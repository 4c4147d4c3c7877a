"""Block Lanczos with partial reorthogonalisation, ordering reuse of the Sturm check and
chunked shell element batches.

References: dense LAPACK on the same pencil (:func:`femmech.solve.dense.dense_symmetric`,
shift-inverted, relative accuracy ~eps for the lowest modes), ARPACK (``arpack``) and a
fresh factorisation of each backend. Tolerances name what limits them: eigenvalues of a
backward-stable solve are exact for a pencil perturbed by ~eps ‖K‖, so they carry an absolute
error ~eps λ_max (``roundoff.eigenvalue_atol``), which is the whole difference between two
such solvers; the relative error eps λ_max / λ_k is largest for the lowest modes (3e-8 for
the tube's first pair, 8e-12 for the frame's first mode). How far below that bound a
result lands depends on the BLAS kernel's summation order (4e-14 on one
machine, 2e-12 on another), so no tolerance here is tighter than the bound.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from numpy.testing import assert_allclose
from roundoff import EPS, eigenvalue_atol

import femmech as fm
import femmech.fe.elements.shell as shell
from femmech.fe import sections
from femmech.fe.generators import grid_frame
from femmech.solve import arpack, cholmod, direct, eigen, lanczos, pardiso, superlu
from femmech.solve.dense import dense_symmetric
from femmech.solve.eigen import solve_symmetric
from femmech.solve.pencil import default_shift, eigenvalue_scale, factorize
from femmech.solve.residuals import residuals

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)
BACKENDS = [pytest.param(name, marks=pytest.mark.skipif(
    name not in direct.available(), reason=f"{name} not installed"))
    for name in direct.BACKENDS]


def frame(subdivisions=3):
    """Grid frame (3, 2, 2) bays of 0.5 m, base joints clamped: 1 044 free DOFs (subdivisions
    3), 1 494 (4)."""
    mesh = grid_frame((3, 2, 2), (1.5, 1.0, 1.0), subdivisions)
    prop = fm.BeamProperty(sections.rectangular_hollow(0.06, 0.08, 0.004), STEEL)
    return fm.build_model(mesh, dict.fromkeys(mesh.cell_sets, prop), supports=[fm.Support("base")])


def tube_cantilever(n=100):
    """Cantilever of a circular tube along x, 600 free DOFs: every bending eigenvalue is
    double (bending about y and z alike)."""
    x = np.linspace(0.0, 2.0, n + 1)
    mesh = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(n), np.arange(1, n + 1)]),
                              node_sets={"root": [0]})
    prop = fm.BeamProperty(sections.tube(0.05, 0.04), STEEL)
    return fm.build_model(mesh, {"all": prop}, supports=[fm.Support("root")])


@pytest.fixture(scope="module")
def pencil():
    model = frame()
    K, M = model.K_free, model.M_free
    sigma = default_shift(K, M)
    lam, X = dense_symmetric(K, M, 40, sigma=sigma)
    return K, M, sigma, lam, factorize(K - sigma * M, solver="superlu")


@pytest.mark.parametrize("variant", [{}, {"partial": False}, {"max_dim": 24}, {"block": 1},
                                     {"block": 4}],
                         ids=["partial", "full", "restarted", "b1", "b4"])
def test_block_lanczos_matches_dense(pencil, variant):
    K, M, sigma, ref, lu = pencil
    omega2, X = lanczos.block_lanczos(K, M, 14, sigma, lu, n_wanted=12, **variant)
    # bound: Ritz residuals <= 1e-12 |θ| give eigenvalue errors ~1e-14; both solvers' round-off
    # ~eps λ_max absolute: 10 eps λ_max = 7.6e-11 of λ_1 (module docstring), within 1e-10.
    # Measured 5.3e-14 for every variant
    assert_allclose(omega2[:12], ref[:12], rtol=1e-10)
    gram = X.T @ (M @ X)
    # M-orthonormal Ritz vectors: measured 2e-15 (full), 1e-10 (partial: a semi-orthogonal
    # basis, |VᵀMV - I| <= sqrt(eps) by construction)
    assert np.abs(gram - np.eye(len(omega2))).max() < 1e-8
    res = residuals(K, M, omega2, X, 1e-6 * eigenvalue_scale(K, M))
    # limited by the semi-orthogonal basis (|VᵀMV - I| <= sqrt(eps) = 1.5e-8), not by the
    # BLAS: measured 2e-11 .. 1.4e-10; 1.1e-8 .. 1.9e-8 after a restart (every kernel tried)
    assert res[:12].max() < 1e-7


def test_block_lanczos_agrees_with_arpack_on_a_larger_frame():
    # 1 494 DOFs, 20 modes + guards: the production path of solve_symmetric
    model = frame(4)
    K, M = model.K_free, model.M_free
    sigma = default_shift(K, M)
    lu = factorize(K - sigma * M, solver="superlu")
    ref, _ = arpack.arpack(K, M, 24, sigma, lu)
    omega2, _ = lanczos.block_lanczos(K, M, 24, sigma, lu, n_wanted=20)
    # both round-off of the same pencil, ~eps λ_max absolute: 10 eps λ_max is 1.3e-10 of λ_1
    # and 1.8e-12 of λ_20 (measured 2e-15; rtol 1e-12 was below the bound for λ_1..λ_9)
    assert_allclose(omega2[:20], ref[:20], rtol=0, atol=eigenvalue_atol(K, M))


def test_block_lanczos_returns_both_members_of_double_eigenvalues():
    # Single-vector Lanczos sees one vector of each double eigenvalue and finds the second
    # only from round-off, late; a block of two finds both in one run (no Sturm restart).
    model = tube_cantilever()
    K, M = model.K_free, model.M_free
    sigma = default_shift(K, M)
    lu = factorize(K - sigma * M, solver="superlu")
    omega2, _ = lanczos.block_lanczos(K, M, 8, sigma, lu, n_wanted=6)
    ref, _ = arpack.arpack(K, M, 8, sigma, lu)  # ARPACK at machine-precision tolerance
    # round-off of both, ~eps λ_max absolute: 10 eps λ_max = 1.8e-4 rad²/s², i.e. 3.4e-7 of
    # the first pair (5 287 rad²/s²) and 1e-9 of the third; a missed member would differ by
    # the gap to the next pair, a factor 39 (measured 1.5e-13 relative; the old rtol 1e-12
    # lay below the bound and failed on a Haswell kernel at 2e-12)
    atol = eigenvalue_atol(K, M)
    assert_allclose(omega2[:6], ref[:6], rtol=0, atol=atol)
    # members of a pair equal to round-off (the model is exactly symmetric; ARPACK's own
    # pairs differ by 2.1e-12 relative, the block's by 2.0e-12 with numpy's AVX-512 loops
    # on any OpenBLAS kernel, 7e-14 with its AVX2 loops)
    assert_allclose(omega2[0:6:2], omega2[1:6:2], rtol=0, atol=2 * atol)
    result = solve_symmetric(K, M, n_modes=6)
    # the sparse path (600 DOFs >= DENSE_BELOW): ARPACK, or block Lanczos where ARPACK
    # did not converge within its iteration limit
    assert result.method in ("arpack", "block-lanczos")
    assert result.sturm_count == 6


def test_deflated_block_lanczos_finds_the_next_modes(pencil):
    K, M, sigma, ref, lu = pencil
    first, X = lanczos.block_lanczos(K, M, 4, sigma, lu)
    more, _ = lanczos.block_lanczos(K, M, 4, sigma, lu, deflate=X)
    # bound: round-off of both solvers, 10 eps λ_max = 7.6e-11 of λ_1 (module docstring);
    # measured 5e-14
    assert_allclose(np.sort(np.concatenate([first, more])), ref[:8], rtol=1e-10)


@pytest.mark.parametrize("name", BACKENDS)
def test_factorize_like_equals_a_fresh_factorisation(pencil, name):
    K, M, sigma, ref, _ = pencil
    shift = direct.factorize((K - sigma * M).tocsc(), name, definite=True)
    cut = 0.5 * (ref[9] + ref[10])
    A = (K - cut * M).tocsc()
    like = shift.factorize_like(A, definite=False)
    fresh = direct.factorize(A, name, definite=False)
    # Sylvester: 10 eigenvalues of the pencil lie below the cut (dense reference)
    assert like.n_negative == fresh.n_negative == 10
    b = np.random.default_rng(3).standard_normal((A.shape[0], 3))
    # same ordering, same arithmetic up to the order of sums: measured 0 (PARDISO), 2e-14
    # of the largest entry (SuperLU, CHOLMOD). Each solve has relative error ~eps cond₂(A)
    # bound: = 2e-11 (cond₂(A) = 9.1e4, numpy.linalg.cond, for the cut midway between λ_10 and
    # λ_11): 1e-9 is 50 times that
    x = fresh.solve(b)
    assert np.abs(like.solve(b) - x).max() <= 1e-9 * np.abs(x).max()
    _, rows = like.pivots()
    assert np.array_equal(np.sort(rows), np.arange(A.shape[0]))  # a permutation of A's rows


@pytest.mark.parametrize("name", BACKENDS)
def test_sturm_check_factorises_on_the_shift_ordering(monkeypatch, name):
    model = frame()
    K, M = model.K_free, model.M_free
    calls = {"factorize": 0, "like": 0}
    factorize_ = direct.factorize

    def counting_factorize(*args, **kwargs):
        calls["factorize"] += 1
        return factorize_(*args, **kwargs)

    monkeypatch.setattr(direct, "factorize", counting_factorize)
    for cls in (superlu.SuperLUFactor, cholmod.CholmodFactor, pardiso.PardisoFactor):
        monkeypatch.setattr(cls, "factorize_like", _counted(cls.factorize_like, calls))
    with direct.use(name):
        result = solve_symmetric(K, M, n_modes=10)
    assert calls == {"factorize": 1, "like": 1}  # the shift; the count on its ordering
    assert result.sturm_count == result.omega2.size


def _counted(method, calls):
    def wrapper(self, *args, **kwargs):
        calls["like"] += 1
        return method(self, *args, **kwargs)
    return wrapper


@pytest.mark.skipif("pardiso" not in direct.available(), reason="pardiso not installed")
def test_pardiso_blocks_on_a_sparse_factor_are_solved_column_by_column(pencil, monkeypatch):
    K, M, sigma, _, _ = pencil
    A = (K - sigma * M).tocsc()
    f = direct.factorize(A, "pardiso", definite=True)
    assert f.iparm[17] < pardiso.PARDISO_LOOP_FILL * f.n  # a beam frame: a sparse factor
    rng = np.random.default_rng(5)
    block = rng.standard_normal((K.shape[0], 40))
    looped = np.column_stack([f.solve(block[:, j]) for j in range(40)])
    assert np.array_equal(f.solve(block), looped)  # the same single solves
    monkeypatch.setattr(pardiso, "PARDISO_LOOP_FILL", 0)  # as for a dense (shell) factor
    x = f.solve(block)  # PARDISO's multi-right-hand-side solve
    # bound: backward error ~eps cond
    assert np.abs(A @ x - block).max() < 1e-9 * np.abs(block).max()


def test_shell_element_batches_do_not_change_the_matrices(monkeypatch):
    # the chunked batch computes each element with its own arithmetic: bit-identical
    n = 12
    x, y = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 0.5, n + 1), indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel(), 0.01 * np.sin(3 * x.ravel())])
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    quads = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    tris = np.vstack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    thickness = np.linspace(0.004, 0.006, len(quads))
    for cells, t in ((quads, thickness), (tris, 0.005)):
        monkeypatch.setattr(shell, "ELEMENT_CHUNK", 10**9)
        K0, M0 = shell.shell_matrices(points, cells, 210e9, 0.3, 7850.0, t)
        monkeypatch.setattr(shell, "ELEMENT_CHUNK", 7)
        K1, M1 = shell.shell_matrices(points, cells, 210e9, 0.3, 7850.0, t)
        assert np.array_equal(K0, K1)
        assert np.array_equal(M0, M1)


PATHS = {"arpack-first": None, "block-lanczos": 0}
"""The two paths of the lowest modes: ARPACK for exactly the wanted pairs on small models
(eigen.ARPACK_BELOW), and the guarded block Lanczos of large ones (ARPACK_BELOW = 0)."""


def _path(monkeypatch, path):
    if PATHS[path] is not None:
        monkeypatch.setattr(eigen, "ARPACK_BELOW", PATHS[path])


@pytest.mark.parametrize("path", PATHS)
def test_sturm_check_completes_a_cluster_of_twelve_cut_by_n_modes(monkeypatch, path):
    """Twelve equal oscillators (eigenvalue 1e4, 12-fold, like 12 equal cams) beside a
    1 000-mass spring chain, cut by ``n_modes``. Block Lanczos
    (block 2) sees only a few members of a repeated eigenvalue per run; the Sturm count
    must make the deflated runs find every member below the cut. A first version
    truncated the merged set back to ``n_modes`` before counting again and looped until
    it gave up (12 cams of the textile shaft, 6 modes). ARPACK (single vector) sees one
    member; the same count and deflated runs complete the set."""
    _path(monkeypatch, path)
    n_chain, n_osc = 1000, 12
    k_chain = 4e7  # lowest chain eigenvalues ~99 j², ten of them below the cluster
    main = np.full(n_chain, 2 * k_chain)
    main[-1] = k_chain  # free end; fixed at the other
    chain = sp.diags([main, -k_chain * np.ones(n_chain - 1), -k_chain * np.ones(n_chain - 1)],
                     [0, 1, -1])
    osc = sp.diags(np.full(n_osc, 1e4))
    K = sp.block_diag([chain, osc]).tocsr()
    M = sp.identity(n_chain + n_osc, format="csr")
    lam = np.sort(np.concatenate([np.linalg.eigvalsh(chain.toarray()), osc.diagonal()]))
    first = int(np.searchsorted(lam, 1e4))  # chain modes below the cluster
    for n_modes in (first + 1, first + 6):  # the cut falls inside the cluster
        result = solve_symmetric(K, M, n_modes=n_modes)
        n = result.omega2.size
        assert n >= first + n_osc  # the whole cluster
        assert result.sturm_count == n
        # every eigenvalue up to the cut, and only those; dense reference: both round-off,
        # ~eps λ_max absolute (λ_max = 1.6e8 rad²/s² of the chain, 10 eps λ_max = 3.6e-9 of
        # λ_1 = 99 rad²/s²: the old rtol 1e-10 lay below it; measured 2.5e-11)
        assert n == np.count_nonzero(lam <= result.cut)
        assert_allclose(result.omega2, lam[:n], rtol=0, atol=10 * EPS * lam[-1])
        # relative residual ~eps λ_max / λ_1 = 3.6e-10 (roundoff.py) times a small constant:
        # measured 6e-10 (SkylakeX) .. 1.7e-9 (Haswell kernel); 100 eps λ_max / λ_1 = 3.6e-8
        # (the old 1e-8 was within 6x of the Haswell value)
        assert result.residual.max() < 100 * EPS * lam[-1] / lam[0]


@pytest.mark.parametrize("path", PATHS)
def test_far_default_shift_is_moved_towards_the_wanted_eigenvalues(monkeypatch, path):
    """A 500-mass chain (eigenvalues ~99 (2j - 1)² rad²/s²) beside 1 500 very stiff
    coordinates (1e13 N/m on 1 kg each, like stiff contacts): the default shift
    -1e-6 median(K_ii/M_ii) = -1e7 lies 1e5 times further below zero than λ_1 is above
    it, so θ = 1/(λ - σ) of the 20 wanted differ by 1 % only. The solver moves σ to
    -max(λ_1, 1e-3 |σ|) = -1e4 (lanczos.FAR_SHIFT) and factorises again; the result
    equals the dense reference and passes the Sturm check. (On the ARPACK-first path
    ARPACK does not converge within ARPACK_MAXITER restarts there, and block Lanczos,
    which moves the shift, takes over.)"""
    _path(monkeypatch, path)
    n_chain, k_chain = 500, 1e7
    main = np.full(n_chain, 2 * k_chain)
    main[-1] = k_chain  # free end; fixed at the other
    chain = sp.diags([main, -k_chain * np.ones(n_chain - 1), -k_chain * np.ones(n_chain - 1)],
                     [0, 1, -1])
    K = sp.block_diag([chain, sp.diags(np.full(3 * n_chain, 1e13))]).tocsr()
    M = sp.identity(4 * n_chain, format="csr")
    lam = np.linalg.eigvalsh(chain.toarray())  # the stiff ones are all 1e13
    default = default_shift(K, M)
    assert -default > 1e4 * lam[0]  # far below: the case of lanczos.FAR_SHIFT
    result = solve_symmetric(K, M, n_modes=20)
    assert result.sigma == pytest.approx(-1e-3 * -default)  # moved, bounded by 1e-3 |σ|
    assert result.sturm_count == result.omega2.size == 20
    # bound: dense reference (eigvalsh of the chain, ~eps λ_max(chain) = 1e-8 absolute, 1e-10
    # of λ_1): measured 3e-12; at the unmoved shift 8.5e-10, with residuals of 1.3e-5
    assert_allclose(result.omega2, lam[:20], rtol=1e-10)


def test_small_models_take_arpack_for_exactly_the_wanted_pairs(monkeypatch):
    """Below ARPACK_BELOW the lowest modes come from one ARPACK run of n_modes +
    ARPACK_GUARD pairs (no block Lanczos), Sturm-checked; the result equals the block-Lanczos
    path's to round-off (both ~eps λ_max absolute, eigenvalue_atol)."""
    model = tube_cantilever()  # 600 DOFs; pairs of double eigenvalues
    K, M = model.K_free, model.M_free
    calls = []
    monkeypatch.setattr(lanczos, "lowest_pairs", _counting(lanczos.lowest_pairs, calls))
    monkeypatch.setattr(eigen, "lowest_pairs", lanczos.lowest_pairs)
    first = solve_symmetric(K, M, n_modes=5)  # the 5th is a double: the cluster comes back
    assert calls == []  # ARPACK only
    assert first.omega2.size == first.sturm_count == 6
    monkeypatch.setattr(eigen, "ARPACK_BELOW", 0)
    block = solve_symmetric(K, M, n_modes=5)
    assert len(calls) == 1
    assert_allclose(first.omega2, block.omega2, rtol=0, atol=eigenvalue_atol(K, M))


def test_a_missed_double_member_is_found_by_the_count(monkeypatch):
    """ARPACK_GUARD = 0 and 3 modes of the tube (pairs 1-2, 3-4): the count just above λ_3
    shows 4 eigenvalues, a deflated run adds the 4th (the pair is not cut)."""
    model = tube_cantilever()
    K, M = model.K_free, model.M_free
    monkeypatch.setattr(eigen, "ARPACK_GUARD", 0)
    result = solve_symmetric(K, M, n_modes=3)
    ref = dense_symmetric(K, M, 6)[0]
    assert result.omega2.size == result.sturm_count == 4
    assert_allclose(result.omega2, ref[:4], rtol=0, atol=eigenvalue_atol(K, M))


def test_without_a_count_the_guarded_path_runs(monkeypatch):
    """Where the Sturm count is not available (a factorisation that pivoted off the
    diagonal), the ARPACK-first result (no guards) is replaced by the guarded block
    Lanczos, whose guards see a cut cluster."""
    model = tube_cantilever()
    K, M = model.K_free, model.M_free
    monkeypatch.setattr(eigen, "inertia_below", lambda *args, **kw: None)
    calls = []
    monkeypatch.setattr(eigen, "lowest_pairs", _counting(lanczos.lowest_pairs, calls))
    result = solve_symmetric(K, M, n_modes=3)
    assert len(calls) == 1
    assert result.sturm_count is None
    assert result.omega2.size == 4  # the guards completed the pair


def _counting(func, calls):
    def wrapped(*args, **kwargs):
        calls.append(args[2])
        return func(*args, **kwargs)
    return wrapped


def test_arpack_takes_over_where_block_lanczos_does_not_converge(pencil, monkeypatch):
    """With no solves allowed (MAX_SOLVES_PER_MODE = -1e9) block Lanczos gives up at
    once; solve_symmetric warns and ARPACK returns the same modes (dense reference,
    round-off of the shift-inverted pencil). (ARPACK_BELOW = 0: the block-Lanczos path,
    which small models otherwise skip.)"""
    K, M, _, _, _ = pencil
    expected = dense_symmetric(K, M, 8)[0]
    monkeypatch.setattr(lanczos, "MAX_SOLVES_PER_MODE", -10**9)
    monkeypatch.setattr(eigen, "ARPACK_BELOW", 0)
    with pytest.warns(fm.FemmechWarning, match="falling back to ARPACK"):
        result = solve_symmetric(K, M, n_modes=8, dense_below=0)
    assert result.sturm_count == result.omega2.size >= 8
    # bound: ARPACK (tol 0) against the dense reference: eps λ_max/λ (roundoff.py)
    assert_allclose(result.omega2[:8], expected, rtol=1e-9)


@pytest.mark.parametrize("path", PATHS)
def test_band_from_zero_with_a_given_factor_is_found_as_the_lowest_modes(monkeypatch, path):
    """A band (0, hi) with a factor of K at σ = 0 (the fixed-interface modes of a
    Craig-Bampton cutoff) is solved as the n lowest modes, n from the Sturm count below
    hi, with that factor (no new shift factorisation): every eigenvalue below hi, checked
    by the count, equal to the dense reference (both round-off, eigenvalue_atol)."""
    _path(monkeypatch, path)
    model = frame()
    K, M = model.K_free, model.M_free
    ref = dense_symmetric(K, M, 20)[0]
    hi = 0.5 * (ref[11] + ref[12])
    lu = factorize(K, solver="superlu")
    made = []
    monkeypatch.setattr(eigen, "factorize", lambda *a, **kw: made.append(a) or factorize(*a, **kw))
    result = solve_symmetric(K, M, band=(0.0, hi), sigma=0.0, factor=lu)
    assert made == []  # the given factor served the shift
    assert result.omega2.size == result.sturm_count == 12
    assert_allclose(result.omega2, ref[:12], rtol=0, atol=eigenvalue_atol(K, M))


@pytest.mark.parametrize("path", PATHS)
def test_method_names_the_algorithm_that_ran(monkeypatch, path):
    # EigenResult.method says which algorithm computed the pairs: "block-lanczos" where
    # femmech's block Lanczos ran (it said "arpack" there), "arpack" where ARPACK did.
    # Reference eigenvalues: the fixed-free spring chain's closed form
    # λ_j = 4 k/m sin²((2j - 1) π / (2 (2n + 1))) (Rayleigh, Theory of Sound §120).
    _path(monkeypatch, path)
    n, k, m = 600, 1e6, 1.0
    main = np.full(n, 2 * k)
    main[-1] = k
    K = sp.diags([main, -k * np.ones(n - 1), -k * np.ones(n - 1)], [0, 1, -1]).tocsc()
    M = sp.identity(n, format="csc") * m
    result = eigen.solve_symmetric(K, M, n_modes=5)
    assert result.method == path.removesuffix("-first")
    j = np.arange(1, 6)
    exact = 4 * k / m * np.sin((2 * j - 1) * np.pi / (2 * (2 * n + 1))) ** 2
    # bound: Lanczos converged to LANCZOS_TOL 1e-12 relative (ARPACK to eps) -> 1e-9 safe
    assert_allclose(result.omega2[:5], exact, rtol=1e-9)
