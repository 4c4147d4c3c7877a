"""Session setup shared by all tests: BLAS thread counts.

Round-off depends on the order of sums, which differs between OpenBLAS kernels (Haswell,
SkylakeX, Zen, ...) and between thread counts. Tolerances must hold on any of them (see
``roundoff.py``). To catch a tolerance that only holds for one summation order, ``.ci/run``
runs the tests again with ``FEMMECH_TEST_BLAS_THREADS=1`` and with ``=2``. The default run
computes femmech's solve phases and the hard cases on 1 thread and leaves everything else
on all cores (``femmech.solve.threads``, ``hard_cases/conftest.py``), so each part of the suite
sums in another order in one of the two extra runs. OpenBLAS only splits large
operations between threads, so this catches part of what another kernel changes (in probe
runs, 44 % of the assertions whose values a Haswell kernel changed); the tolerances
themselves must follow from the problem.

``FEMMECH_TEST_BLAS_THREADS=N`` runs every phase of the session on N threads:

* every loaded BLAS and OpenMP library is limited to N threads (threadpoolctl), and
  ``OPENBLAS_NUM_THREADS``, ``MKL_NUM_THREADS`` and ``OMP_NUM_THREADS`` are set to N for
  libraries loaded later (PARDISO's MKL, CHOLMOD's OpenMP) and for subprocesses;
* femmech's *solve* and *factor* phases use N threads (``femmech.solve.threads.set_threads``);
* ``hard_cases/conftest.py`` limits its modules to N threads instead of 1.

The header of the pytest run names the libraries and their thread counts. Tests marked
``heavy`` (minutes each: large meshes that confirm a light test's claim at a tighter
target) run only with ``FEMMECH_HEAVY_TESTS=1``; otherwise they are reported as skipped
with that reason, never silently dropped. This file also
puts ``tests/`` on ``sys.path`` (pytest's ``prepend`` import mode), so that ``roundoff``
imports from ``hard_cases/`` and ``mechanisms/`` too.
"""

from __future__ import annotations

import os

import pytest
from threadpoolctl import threadpool_limits

ENV_VAR = "FEMMECH_TEST_BLAS_THREADS"


def session_threads() -> int | None:
    """Thread count asked for by ``FEMMECH_TEST_BLAS_THREADS`` (None: not set)."""
    text = os.environ.get(ENV_VAR, "").strip()
    if not text:
        return None
    if not text.isdigit() or int(text) < 1:
        raise pytest.UsageError(f"{ENV_VAR} must be a positive integer, got {text!r}")
    return int(text)


_limits = []  # the threadpoolctl limit in force for the session


def pytest_configure(config):
    """Apply ``FEMMECH_TEST_BLAS_THREADS`` (module docstring) before collection."""
    n = session_threads()
    if n is None:
        return
    for var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
        os.environ[var] = str(n)
    import numpy as np

    from femmech.solve import threads
    np.ones((2, 2)) @ np.ones((2, 2))  # load the BLAS
    threads.set_threads(solve=n, factor=n)
    _limits.append(threadpool_limits(limits=n))


def pytest_unconfigure(config):
    while _limits:
        _limits.pop().restore_original_limits()


def pytest_report_header(config):
    import numpy as np

    from femmech.solve import threads
    np.ones((2, 2)) @ np.ones((2, 2))  # load the BLAS
    n = session_threads()
    asked = f"{ENV_VAR}={n}" if n is not None else f"{ENV_VAR} not set"
    return f"{asked}; {threads.describe()}"


HEAVY_VAR = "FEMMECH_HEAVY_TESTS"


def pytest_collection_modifyitems(config, items):
    """Skip ``heavy`` tests unless ``FEMMECH_HEAVY_TESTS=1`` (module docstring)."""
    if os.environ.get(HEAVY_VAR) == "1":
        return
    skip = pytest.mark.skip(reason=f"heavy (minutes): run with {HEAVY_VAR}=1")
    for item in items:
        if "heavy" in item.keywords:
            item.add_marker(skip)


@pytest.fixture(scope="module")
def damped_cam_system():
    """The damped Table 5.1 cam on the simply supported beam (``models.damped_cam_on_beam``),
    built once per test module."""
    from models import damped_cam_on_beam

    return damped_cam_on_beam()
