"""Sparse direct solvers of symmetric systems behind one interface.

:func:`factorize` returns a :class:`~femmech.solve.factor.Factor` with ``solve`` (vector or
block right-hand sides), the inertia count ``n_negative`` (negative pivots = negative
eigenvalues of A, Sylvester's law of inertia, for Sturm-sequence checks), ``refactor`` (new
values on the same sparsity pattern, reusing the symbolic analysis where the backend can)
and ``pivots`` (diagonal pivots, for singularity checks). Backends:

``"superlu"`` (:mod:`.superlu`)
    scipy's SuperLU in symmetric mode (minimum degree on ``Aᵀ + A``, diagonal pivots),
    always available. No separate symbolic phase: ``refactor`` factorises anew.
``"cholmod"`` (:mod:`.cholmod`)
    CHOLMOD via scikit-sparse (``sksparse.cholmod``): supernodal/simplicial LLᵀ for
    positive definite A, simplicial LDLᵀ (no pivoting, inertia from D) otherwise.
    ``refactor`` reuses the analysis (``cholesky_inplace``).
``"pardiso"`` (:mod:`.pardiso`)
    Intel MKL PARDISO through a ctypes binding of ``libmkl_rt`` (pip package ``mkl``):
    SPD mode (mtype 2, Cholesky) for positive definite A, symmetric indefinite mode
    (mtype -2, Bunch-Kaufman pivoting within supernodes) otherwise, with the number of
    negative eigenvalues from ``iparm(23)``. ``refactor`` runs phase 22 only.

``solver="auto"`` takes the first installed of :data:`AUTO_ORDER` for systems of at
least :data:`AUTO_MIN_SIZE` unknowns and CHOLMOD (else SuperLU) below.
The environment variable ``FEMMECH_SOLVER`` sets the default (``"auto"``).
Factorisations run under :func:`femmech.solve.threads.factor_phase`.

Install the fast backends with ``pip install femmech[fast]`` (MKL PARDISO, wheels on
PyPI); CHOLMOD needs SuiteSparse's headers to build scikit-sparse (``apt-get install
libsuitesparse-dev`` and ``pip install "scikit-sparse<0.5"`` for Debian 12's SuiteSparse
5; scikit-sparse 0.5 needs SuiteSparse 7).

This module picks the backend (:func:`available`, :func:`resolve`, :func:`use`) and
factorises (:func:`factorize`); each backend lives in its own module.

Stage 1, solve (linear algebra): imports only :mod:`femmech.errors` and other
:mod:`femmech.solve` modules, never :mod:`femmech.fe` or higher.
"""

from __future__ import annotations

import contextlib
import importlib.metadata
import importlib.util
import os

from femmech.solve import threads
from femmech.solve.cholmod import CholmodFactor
from femmech.solve.factor import Factor, square_matrix
from femmech.solve.pardiso import PardisoFactor, mkl_library, mkl_version
from femmech.solve.superlu import SuperLUFactor

BACKENDS = ("superlu", "cholmod", "pardiso")
"""All backend names."""

AUTO_ORDER = ("pardiso", "cholmod", "superlu")
"""Preference of ``solver="auto"`` among installed backends (fastest first, from
benchmarks/solvers.py)."""

AUTO_MIN_SIZE = 20_000
"""``"auto"`` uses CHOLMOD (where installed, else SuperLU) below this many unknowns.
Peer suite (benchmarks/peer_eigensolve.py, 5 472-DOF frame, shift factorisation + solve):
CHOLMOD 2.1 ms + 0.05 ms per solve, SuperLU 4.3 ms + 0.26 ms, PARDISO 120 ms + 0.11 ms.
Before: Factorisation + 55 solves of grid
frames (this 2-core machine under load): 1 080 DOFs: SuperLU 14 ms, CHOLMOD 13 ms,
PARDISO 125 ms; 3 744 DOFs: 84, 40, 436 ms; 13 200 DOFs: 0.42, 0.45, 0.67 s; 23 760
DOFs: 1.2, 1.1, 1.3 s (benchmarks/solvers.py). MKL's thread start-up dominates small
systems; the fast backends pay off on large and dense (solid) models."""

ENV_VAR = "FEMMECH_SOLVER"


def available() -> tuple[str, ...]:
    """Installed backends, in :data:`AUTO_ORDER`."""
    found = []
    for name in AUTO_ORDER:
        if name == "superlu":
            found.append(name)
        elif name == "cholmod" and importlib.util.find_spec("sksparse") is not None:
            try:
                import sksparse.cholmod  # noqa: F401
            except ImportError:
                continue
            found.append(name)
        elif name == "pardiso" and mkl_library() is not None:
            found.append(name)
    return tuple(found)


_chosen: list[str] = []


def default_solver() -> str:
    """The default backend name: set by :func:`use`, else ``FEMMECH_SOLVER``, else ``"auto"``."""
    if _chosen:
        return _chosen[-1]
    return os.environ.get(ENV_VAR, "auto").strip().lower() or "auto"


@contextlib.contextmanager
def use(solver: str | None):
    """Make ``solver`` the default inside a ``with`` block (None: keep the default).

    E.g. ``with direct.use("superlu"): fm.modes(model, 20)``. Raises like :func:`resolve`
    if the backend is unknown or not installed.
    """
    if solver is None:
        yield default_solver()
        return
    name = str(solver).lower()
    if name != "auto":
        resolve(name)
    _chosen.append(name)
    try:
        yield name
    finally:
        _chosen.pop()


def resolve(solver: str | None = None, n: int | None = None) -> str:
    """The backend that ``factorize(A, solver)`` uses for an n × n matrix.

    Raises ValueError for an unknown name and ImportError for a backend that is not
    installed.
    """
    solver = default_solver() if solver is None else str(solver).lower()
    if solver == "auto":
        installed = available()
        if n is not None and n < AUTO_MIN_SIZE:
            return "cholmod" if "cholmod" in installed else "superlu"
        return installed[0]
    if solver not in BACKENDS:
        raise ValueError(f"unknown solver {solver!r}; choose from 'auto', {', '.join(BACKENDS)}")
    if solver not in available():
        hint = ("pip install 'femmech[fast]' (the mkl package)" if solver == "pardiso" else
                "apt-get install libsuitesparse-dev; pip install 'scikit-sparse<0.5'")
        raise ImportError(f"solver {solver!r} is not installed ({hint})")
    return solver


def factorize(A, solver: str | None = None, definite: bool | None = None,
              pivot_threshold: float = 0.0) -> Factor:
    """Factorise a symmetric sparse matrix A (n × n).

    Parameters
    ----------
    A : sparse matrix or ndarray (n, n)
        Symmetric (only one triangle is read by CHOLMOD and PARDISO).
    solver : str, optional
        ``"auto"``, ``"superlu"``, ``"cholmod"`` or ``"pardiso"``; default
        :func:`default_solver`.
    definite : bool, optional
        True: A is positive definite (Cholesky / SPD mode; ValueError if not). False: A
        may be indefinite (LDLᵀ, inertia available). None: try Cholesky first and fall
        back to LDLᵀ; either way ``n_negative`` is right.
    pivot_threshold : float
        SuperLU only: 0 takes every diagonal pivot; e.g. 0.01 rejects small diagonal
        pivots of an indefinite A (shift inside the spectrum), at the price of the
        inertia count (off-diagonal pivots).

    Returns
    -------
    Factor

    Raises
    ------
    ValueError
        With "singular" in the message when A cannot be factorised (exact zero pivot), or
        "not positive definite" with ``definite=True``.
    """
    A = square_matrix(A)
    name = resolve(solver, A.shape[0])
    if name == "superlu":
        with threads.factor_phase():
            return SuperLUFactor(A, pivot_threshold)
    if name == "cholmod":
        return CholmodFactor(A, definite)
    return PardisoFactor(A, definite)


def versions() -> dict[str, str]:
    """Versions of the installed backends' libraries, for reports."""
    import scipy
    out = {"superlu": f"scipy {scipy.__version__}"}
    if "cholmod" in available():
        try:
            out["cholmod"] = f"scikit-sparse {importlib.metadata.version('scikit-sparse')}"
        except importlib.metadata.PackageNotFoundError:
            out["cholmod"] = "scikit-sparse"
    if "pardiso" in available():
        out["pardiso"] = mkl_version() or "mkl"
    return out


def __getattr__(name: str):
    """Names this module had before the restructures, from their new places
    (docs/architecture.md, "Moved names")."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "PARALLEL_SOLVE_COLUMNS": "femmech.solve.pardiso.PARALLEL_SOLVE_COLUMNS",
        "PARALLEL_SOLVE_MAX_BYTES": "femmech.solve.pardiso.PARALLEL_SOLVE_MAX_BYTES",
        "PARDISO_LOOP_FILL": "femmech.solve.pardiso.PARDISO_LOOP_FILL",
        "PARDISO_PERTURBATION": "femmech.solve.pardiso.PARDISO_PERTURBATION",
        "PARDISO_SOLVE_MODE": "femmech.solve.pardiso.PARDISO_SOLVE_MODE",
    })
