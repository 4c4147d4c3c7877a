"""femmech's thread phases under the thread variables of cluster job scripts.

``OMP_NUM_THREADS=2 OPENBLAS_NUM_THREADS=2`` (as job scripts and many shells set them):
inside a solve phase on one thread, every loaded BLAS and OpenMP library runs on one
thread, also the OpenMP runtime that MKL (PARDISO) loads only when its thread count is
first read, which threadpoolctl's first lookup did not list (femmech.solve.threads
``_look_up``). Run in a fresh interpreter, so that no library is loaded before femmech's
first lookup. ``.ci/run`` also runs the whole suite once with both variables set.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from femmech.solve import pardiso

ROOT = Path(__file__).resolve().parents[1]

SCRIPT = """
import json
import numpy as np
from threadpoolctl import threadpool_info
from femmech.solve import pardiso, threads
assert pardiso.mkl_library() is not None
np.ones((4, 4)) @ np.ones((4, 4))
with threads.limit(solve=1), threads.solve_phase():
    inside = [(lib["internal_api"], lib["num_threads"]) for lib in threadpool_info()]
print(json.dumps(inside))
"""


@pytest.mark.skipif(pardiso.mkl_library() is None,
                    reason="MKL (pip install femmech[fast]) not installed")
def test_solve_phase_limits_the_openmp_runtime_mkl_loads_late():
    env = {k: v for k, v in os.environ.items() if k not in ("MKL_NUM_THREADS", "FEMMECH_THREADS")}
    env.update(OMP_NUM_THREADS="2", OPENBLAS_NUM_THREADS="2",
               PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")])))
    run = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                         text=True, timeout=120, check=True)
    inside = json.loads(run.stdout.strip().splitlines()[-1])
    assert "openmp" in {api for api, _ in inside}, inside  # MKL's runtime was found
    assert all(n == 1 for _, n in inside), inside
