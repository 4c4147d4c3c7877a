"""The BLAS thread counts the tests run with (tests/conftest.py).

``.ci/run`` runs the suite on all cores, then with ``FEMMECH_TEST_BLAS_THREADS=1`` and
``=2``, so that round-off is summed in other orders. This checks, inside the run, that the
extra runs really compute on the asked count in every femmech phase (threadpoolctl's view
of every loaded BLAS and OpenMP library), and the first on more than one thread outside
the solve phases where the machine has more than one core.
"""

import os

import numpy as np
from threadpoolctl import threadpool_info

from femmech.solve import threads


def _counts() -> set[int]:
    np.ones((2, 2)) @ np.ones((2, 2))  # a BLAS is loaded
    return {lib["num_threads"] for lib in threadpool_info()}


def test_blas_threads_follow_the_session_setting():
    text = os.environ.get("FEMMECH_TEST_BLAS_THREADS", "").strip()
    with threads.solve_phase():
        solve = _counts()
    with threads.factor_phase():
        factor = _counts()
    if text:  # the second run of .ci/run: every phase on n threads
        n = int(text)
        assert threads.settings() == threads.ThreadSettings(n, n)
        assert _counts() == solve == factor == {n}
    elif threads.settings() == threads.ThreadSettings() and (os.cpu_count() or 1) > 1 \
            and not any(os.environ.get(v) for v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")):
        # the README run with femmech's defaults: solve phases on 1 thread, the rest on the
        # libraries' default (all cores), so the two runs of .ci/run differ in the order
        # of sums outside the solve phases
        assert solve == {1}
        assert max(factor) > 1
