"""The one dense pencil solver (femmech.solve.dense): its routines are the LAPACK calls the
callers made before, so their results are identical to the bit."""

import pathlib

import numpy as np
import pytest
import scipy.linalg as sla
from numpy.testing import assert_array_equal

from femmech.solve import dense


def _pencil(n, seed=0):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    K = A @ A.T + n * np.eye(n)
    B = rng.standard_normal((n, n))
    M = B @ B.T / n + np.eye(n)
    return K, M


def test_no_private_scipy_lapack_names():
    # the sygvx workspace comes from scipy's public dsygvx_lwork, not lapack._compute_lwork
    root = pathlib.Path(dense.__file__).resolve().parents[1]
    users = [p.name for p in root.rglob("*.py") if "_compute_lwork" in p.read_text()]
    assert users == []


@pytest.mark.parametrize("n", [5, 26, 76, 200])
def test_sygvx_is_scipy_eigh_subset_to_the_bit(n):
    # same workspace as scipy.linalg.eigh(subset_by_index) queries, hence the same bits
    K, M = _pencil(n)
    A = K + 1e-3 * M
    wanted = max(1, n // 10)
    mu_ref, X_ref = sla.eigh(M, A, subset_by_index=[n - wanted, n - 1])
    mu, X = dense.sygvx_largest(np.asfortranarray(M), np.asfortranarray(A), wanted)
    assert_array_equal(mu, mu_ref)
    assert_array_equal(X, X_ref)


def test_stack_of_pencils_equals_each_pencil():
    K, M = _pencil(12, 1)
    K2, M2 = _pencil(12, 2)
    lam, V = dense.unsymmetric_pencil(np.stack([K, K2]), np.stack([M, M2]))
    for i, (k, m) in enumerate(((K, M), (K2, M2))):
        ref = sla.eig(k, m)
        assert_array_equal(lam[i], ref[0])
        assert_array_equal(V[i], ref[1])
    lam, X = dense.symmetric_pencil(np.stack([K, K2]), np.stack([M, M2]), 3, driver="plain")
    assert_array_equal(lam[1], sla.eigh(K2, M2, subset_by_index=[0, 2])[0])


def test_drivers_agree_with_an_independent_solve():
    # reference: numpy's standard eigh of M^-1/2 K M^-1/2 formed by an eigendecomposition
    # of M (independent of every driver's route); well-conditioned pencil (cond ~ 1e2), so
    # all three agree to far better than 1e-10 relative
    K, M = _pencil(20, 3)
    w, Q = np.linalg.eigh(M)
    R = Q / np.sqrt(w)
    ref = np.linalg.eigvalsh(R.T @ K @ R)
    for driver in dense.SYMMETRIC_DRIVERS:
        lam, X = dense.symmetric_pencil(K, M, driver=driver)
        # bound: backward-stable LAPACK on a pencil of cond ~1e2 -> rel. error ~1e-14
        np.testing.assert_allclose(lam, ref, rtol=1e-10)
        np.testing.assert_allclose(X.T @ M @ X, np.eye(20), atol=1e-10)


def test_damped_pencil_roots_solve_the_quadratic():
    K, M = _pencil(6, 4)
    B = 0.01 * K
    s, Z = dense.damped_pencil(M, B, K)
    v = Z[:6]
    # residual of (s^2 M + s B + K) v relative to the terms' size; QZ backward error ~1e-15
    for j in range(12):
        r = (s[j] ** 2 * M + s[j] * B + K) @ v[:, j]
        size = (abs(s[j]) ** 2 * np.abs(M) + abs(s[j]) * np.abs(B) + np.abs(K)) @ np.abs(v[:, j])
        # bound: QZ backward error ~eps of the terms, 1e-10 leaves 1e5 eps of margin
        assert np.abs(r).max() <= 1e-10 * size.max()


def test_unknown_driver_is_named():
    K, M = _pencil(4)
    with pytest.raises(ValueError, match="driver must be one of.*'qr'"):
        dense.symmetric_pencil(K, M, driver="qr")
