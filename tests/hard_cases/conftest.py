"""Hard-case tests: one BLAS thread per module."""

import os

import pytest
from threadpoolctl import threadpool_limits


@pytest.fixture(autouse=True, scope="module")
def _single_blas_thread():
    """Dense LAPACK on the small and mid-size matrices of these tests runs fastest on one
    thread when the machine is shared (2 threads made the same solves several times
    slower under load; cf. femmech.solve.eigen.ARPACK_BLAS_THREADS). Module scope: the limit
    ends with each module and does not leak into the tests that run after this folder.
    ``FEMMECH_TEST_BLAS_THREADS`` (checked in tests/conftest.py) replaces the 1."""
    n = int(os.environ.get("FEMMECH_TEST_BLAS_THREADS", "").strip() or 1)
    with threadpool_limits(limits=n, user_api="blas"):
        yield
