"""Threads of BLAS / OpenMP libraries per phase: solve loops on one, factorisations on all.

Measurements on this project's 2-core machine under load: loops of triangular solves and
small dense updates (ARPACK, per-angle eigen solves of reduced systems) ran up to 10x
slower with 2 BLAS threads than with 1, while sparse factorisations and large GEMMs
gain from 2 (benchmarks/README.md). femmech therefore runs

* *solve* phases (ARPACK's Lanczos loop, repeated vector solves) with
  :attr:`ThreadSettings.solve` threads, default 1, and
* *factor* phases (sparse factorisations, block solves, GEMMs) with
  :attr:`ThreadSettings.factor` threads, default ``None`` = leave the libraries alone
  (all cores unless the user limited them, e.g. with ``OMP_NUM_THREADS``).

Override for the whole process with the environment variable ``FEMMECH_THREADS``
(``"solve=1,factor=2"``; a single integer sets both; ``"none"``/``"all"`` leaves a
phase alone), for a block of code with :func:`limit`, or permanently with :func:`set_threads`.
The limits are applied through threadpoolctl to every loaded BLAS (OpenBLAS, MKL, BLIS)
and OpenMP runtime (MKL PARDISO and CHOLMOD thread through them).

Stage 1, solve (linear algebra): imports only :mod:`femmech.errors` and other
:mod:`femmech.solve` modules, never :mod:`femmech.fe` or higher.
"""

from __future__ import annotations

import os
import sys
from contextlib import contextmanager, nullcontext
from dataclasses import dataclass, replace

from threadpoolctl import ThreadpoolController, threadpool_info

ENV_VAR = "FEMMECH_THREADS"
_KEEP = object()


@dataclass(frozen=True)
class ThreadSettings:
    """Thread limits per phase; ``None`` leaves the libraries' own setting alone.

    Attributes
    ----------
    solve : int or None
        Threads in solve-dominated loops (ARPACK, repeated triangular solves).
    factor : int or None
        Threads in factorisations, block solves and GEMMs.
    """

    solve: int | None = 1
    factor: int | None = None


def _check(name: str, value):
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ValueError(f"{name} threads must be a positive integer or None, got {value!r}")
    return value


def parse(text: str) -> ThreadSettings:
    """Settings from a string like ``"solve=1,factor=2"``, ``"2"`` or ``"solve=none"``."""
    def value(item: str, token: str):
        token = token.strip().lower()
        if token in ("none", "all", ""):
            return None
        try:
            return _check(item, int(token))
        except ValueError:
            raise ValueError(f"{ENV_VAR}: cannot read {token!r} as a thread count (give a"
                             " positive integer or 'none')") from None

    text = text.strip()
    if "=" not in text:
        n = value("solve/factor", text)
        return ThreadSettings(n, n)
    fields = {}
    for part in text.split(","):
        key, _, token = part.partition("=")
        key = key.strip().lower()
        if key not in ("solve", "factor"):
            raise ValueError(f"{ENV_VAR}: unknown phase {key!r} in {text!r}; use solve= and"
                             " factor=")
        fields[key] = value(key, token)
    return replace(ThreadSettings(), **fields)


def _from_environment() -> ThreadSettings:
    text = os.environ.get(ENV_VAR)
    return ThreadSettings() if text is None else parse(text)


_settings = _from_environment()


def settings() -> ThreadSettings:
    """The thread limits in force."""
    return _settings


def set_threads(solve=_KEEP, factor=_KEEP) -> ThreadSettings:
    """Change the limits for the rest of the process; returns the previous settings."""
    global _settings
    previous = _settings
    changes = {}
    if solve is not _KEEP:
        changes["solve"] = _check("solve", solve)
    if factor is not _KEEP:
        changes["factor"] = _check("factor", factor)
    _settings = replace(_settings, **changes)
    return previous


@contextmanager
def limit(solve=_KEEP, factor=_KEEP):
    """Use other limits inside a ``with`` block, e.g. ``with limit(solve=2): ...``."""
    previous = set_threads(solve, factor)
    try:
        yield _settings
    finally:
        set_threads(previous.solve, previous.factor)


_controller: ThreadpoolController | None = None
_controller_key = None


def refresh():
    """Forget the cached list of loaded libraries (call after loading one by hand, e.g.
    through ctypes); the next phase looks them up again."""
    global _controller
    _controller = None


def blas_controller() -> ThreadpoolController:
    """threadpoolctl's controller of the loaded BLAS/OpenMP libraries, cached.

    Looking the libraries up costs ~2.5 ms (``threadpool_limits`` does it on every
    entry); the cached controller switches in ~0.03 ms, so that loops may change the
    limit per step (e.g. :func:`gemm_phase` inside Lanczos). The cache is renewed when
    Python modules were imported since (new extension modules may bring a BLAS) and by
    :func:`refresh`.
    """
    global _controller, _controller_key
    key = len(sys.modules)
    if _controller is None or key != _controller_key:
        _controller, _controller_key = _look_up(), key
    return _controller


LOOK_UPS = 3
"""Lookups of the loaded libraries until their list stops growing (:func:`_look_up`)."""


def _look_up() -> ThreadpoolController:
    """A controller of every loaded library, including those the lookup itself loads.

    Reading a library's thread count can load another: ``libmkl_rt`` (PARDISO) loads its
    threading layer and OpenMP runtime (``libiomp5``, or ``libgomp``) on the first
    ``mkl_get_max_threads``, after threadpoolctl has listed the loaded files. A
    controller from that first lookup misses the runtime, which then keeps its own count
    (``OMP_NUM_THREADS``, else all cores) inside every phase. So look again while the
    list grows (once more in practice: 2.5-5 ms more, measured under load, and only when
    the cache is renewed).
    """
    controller = ThreadpoolController()
    for _ in range(LOOK_UPS - 1):
        again = ThreadpoolController()
        if _files(again) <= _files(controller):
            break
        controller = again
    return controller


def _files(controller: ThreadpoolController) -> set[str]:
    return {lib.filepath for lib in controller.lib_controllers}


def _switch(limits):
    """The libraries on ``limits`` threads in a ``with`` block (None: no change)."""
    return nullcontext() if limits is None else blas_controller().limit(limits=limits)


_outside: list = []  # thread counts before each enclosing phase (for gemm_phase)


@contextmanager
def _limited(limits):
    """:func:`_switch`, remembering the counts from before (:func:`gemm_phase`)."""
    if limits is None:
        yield
        return
    _outside.append(blas_controller().info())
    try:
        with _switch(limits):
            yield
    finally:
        _outside.pop()


def exactly(n: int):
    """Every loaded BLAS and OpenMP library on ``n`` threads in a ``with`` block."""
    return _switch(n)


@contextmanager
def solve_phase():
    """Apply the *solve* limit to all loaded BLAS and OpenMP libraries in the block."""
    with _limited(_settings.solve):
        yield


@contextmanager
def factor_phase():
    """Apply the *factor* limit to all loaded BLAS and OpenMP libraries in the block."""
    with _limited(_settings.factor):
        yield


@contextmanager
def gemm_phase():
    """The *factor* limit inside a solve phase, for products that stream a large basis.

    Products like ``Vᵀ W`` with V of ``n x m`` (m ~ 100, e.g. Lanczos
    reorthogonalisation) are bound by memory bandwidth, which one core does not saturate:
    at 151k x 88, 2 threads took 10 ms instead of 18 ms. With *factor* None the libraries'
    counts from before the enclosing phase apply (outside any phase: no change).
    """
    limits = _settings.factor
    if limits is None and _outside:
        limits = _outside[-1]
    with _switch(limits):
        yield


def describe() -> str:
    """One line for reports: the settings and each loaded library's thread count."""
    s = _settings
    libs = ", ".join(f"{lib.get('internal_api')} {lib.get('version') or ''}".rstrip()
                     + f" ({lib.get('num_threads')} threads)" for lib in threadpool_info())
    return (f"femmech threads: solve={s.solve or 'all'}, factor={s.factor or 'all'}"
            f" ({os.cpu_count()} CPUs); libraries: {libs or 'none loaded'}")
