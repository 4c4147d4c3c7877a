"""Design studies as independent jobs on a standard executor: local processes or Dask.

A stability chart over drive speed × a design parameter, or the angle sweeps of many
design variants, is a set of independent evaluations. They run through a
:class:`concurrent.futures.Executor`:

* by default a :class:`~concurrent.futures.ProcessPoolExecutor` on this machine
  (``max_workers`` default: the CPUs available to the process), whose workers run with
  one BLAS thread each (``threads_per_worker``) so that the workers do not oversubscribe
  the cores;
* any executor the caller passes (e.g. a ``ThreadPoolExecutor``, an ``MPIPoolExecutor``);
* a Dask cluster when the caller passes a ``distributed.Client``
  (``client.get_executor()``; pip extra ``femmech[dask]``).

Results come back in job order and are identical to the serial evaluation (each job
runs the same code on the same inputs; tests/test_studies.py compares exactly).

Jobs travel by pickle: pass module-level functions, ``functools.partial`` of them, or
objects of module-level classes, not lambdas or closures. Models holding symbolic
mechanisms (sympy functions created at run time) do not pickle: send a *recipe* (a
module-level function and its parameters) that builds the model inside the job.

Uses analysis.stability and .sweep, solve (thread limits) and errors;
nothing here writes files.
"""

from __future__ import annotations

import dataclasses
import math
import multiprocessing
import os
import warnings
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Executor, ProcessPoolExecutor
from contextlib import contextmanager

import numpy as np

from femmech.analysis import stability
from femmech.errors import ConvergenceWarning
from femmech.solve import threads


def default_workers(n_jobs: int | None = None) -> int:
    """Worker processes by default: the CPUs available to this process, at most n_jobs."""
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cpus = os.cpu_count() or 1
    return max(1, min(cpus, n_jobs or cpus))


_worker_limits = None


def _init_worker(n_threads: int):
    """Process-pool initializer: n_threads BLAS/OpenMP threads in this worker."""
    global _worker_limits
    from threadpoolctl import threadpool_limits

    for var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
        os.environ[var] = str(n_threads)  # for libraries loaded later (MKL PARDISO)
    _worker_limits = threadpool_limits(limits=n_threads)
    threads.set_threads(solve=1, factor=n_threads)


def process_executor(max_workers: int | None = None,
                     threads_per_worker: int = 1) -> ProcessPoolExecutor:
    """A process pool for studies: forkserver start (spawn where unavailable), workers
    limited to ``threads_per_worker`` BLAS threads. Use it in a ``with`` block."""
    methods = multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
    return ProcessPoolExecutor(max_workers=max_workers or default_workers(),
                               mp_context=context, initializer=_init_worker,
                               initargs=(int(threads_per_worker),))


@contextmanager
def _executor(executor, client, max_workers, n_jobs):
    if executor is not None and client is not None:
        raise ValueError("give an executor or a Dask client, not both")
    if executor is not None:
        if not isinstance(executor, Executor):
            raise TypeError(f"executor must be a concurrent.futures.Executor, got"
                            f" {type(executor).__name__}")
        yield executor
    elif client is not None:
        if not hasattr(client, "get_executor"):
            raise TypeError(f"client must be a distributed.Client, got {type(client).__name__}")
        yield client.get_executor()
    else:
        workers = max_workers or default_workers(n_jobs)
        if workers < 1:
            raise ValueError(f"max_workers must be >= 1, got {max_workers}")
        if workers == 1:
            yield None  # serial, in this process
        else:
            with process_executor(workers) as pool:
                yield pool


def _run_batch(func, batch):
    return [func(*args) for args in batch]


def run(func: Callable, jobs: Iterable[Sequence], executor: Executor | None = None,
        client=None, max_workers: int | None = None, chunksize: int | None = None,
        timeout: float | None = None) -> list:
    """``[func(*args) for args in jobs]`` through an executor, in job order.

    Parameters
    ----------
    func : callable
        Picklable (module-level function, ``functools.partial``, module-level class).
    jobs : iterable of argument tuples
    executor : concurrent.futures.Executor, optional
        Used as given (not shut down). Default: a process pool of ``max_workers``.
    client : distributed.Client, optional
        Run on this Dask cluster (``client.get_executor()``).
    max_workers : int, optional
        Processes of the default pool (default :func:`default_workers`); 1 runs serially
        in this process.
    chunksize : int, optional
        Jobs per task (default: about four tasks per worker, fewer round trips).
    timeout : float, optional
        Seconds to wait for all results; ``TimeoutError`` beyond.

    Returns
    -------
    list
        One result per job. An exception of a job is raised with a note naming the job.
    """
    jobs = [tuple(args) for args in jobs]
    if not jobs:
        return []
    with _executor(executor, client, max_workers, len(jobs)) as ex:
        if ex is None:
            return _run_batch(func, jobs)
        workers = getattr(ex, "_max_workers", None) or max_workers or default_workers()
        size = chunksize or max(1, math.ceil(len(jobs) / (4 * workers)))
        if size < 1:
            raise ValueError(f"chunksize must be >= 1, got {chunksize}")
        starts = range(0, len(jobs), size)
        futures = [ex.submit(_run_batch, func, jobs[i:i + size]) for i in starts]
        out = []
        for start, future in zip(starts, futures, strict=True):
            try:
                out.extend(future.result(timeout=timeout))
            except Exception as exc:
                exc.add_note(f"in study jobs {start}..{min(start + size, len(jobs)) - 1}"
                             f" of {len(jobs)} (func {getattr(func, '__name__', func)!r})")
                for f in futures:
                    f.cancel()
                raise
        return out


def grid(func: Callable, *axes, executor: Executor | None = None, client=None,
         max_workers: int | None = None, timeout: float | None = None) -> np.ndarray:
    """``func(a, b, ...)`` for every point of the grid ``axes[0] × axes[1] × ...``.

    Returns
    -------
    ndarray of object, shape ``(len(axes[0]), len(axes[1]), ...)``
        The results (``np.array(out.tolist())`` makes a float array of scalar results).
    """
    axes = [list(np.atleast_1d(a)) for a in axes]
    if not axes:
        raise ValueError("give at least one axis of values")
    shape = tuple(len(a) for a in axes)
    points = [tuple(a[i] for a, i in zip(axes, index, strict=True))
              for index in np.ndindex(*shape)]
    results = run(func, points, executor, client, max_workers, timeout=timeout)
    out = np.empty(len(results), dtype=object)
    out[:] = results
    return out.reshape(shape)


def _chart_part(system_or_callable, speeds, value, options):
    values = None if value is None else [value]
    with warnings.catch_warnings():  # the merged chart warns once
        warnings.simplefilter("ignore", ConvergenceWarning)
        return stability.stability_chart(system_or_callable, speeds, values, **options)


def stability_chart(system_or_callable, speeds, second_parameter_values=None,
                    executor: Executor | None = None, client=None,
                    max_workers: int | None = None, timeout: float | None = None,
                    **options) -> stability.StabilityChart:
    """:func:`femmech.analysis.stability.stability_chart`, its points run in parallel.

    Parameters
    ----------
    system_or_callable, speeds, second_parameter_values
        As in :func:`~femmech.analysis.stability.stability_chart`; must pickle (a
        CoupledSystem without symbolic mechanisms, or a module-level function
        ``f(Omega[, value])``).
    executor, client, max_workers, timeout
        As in :func:`run`.
    **options
        ``n_steps``, ``angle_period``, ``tol``, ``parameter_name``, ``basis``,
        ``rtol``, ``max_steps``.

    Returns
    -------
    StabilityChart
        Equal, array for array, to the serial chart.
    """
    speeds = np.atleast_1d(np.asarray(speeds, dtype=float))
    values = None if second_parameter_values is None else \
        np.atleast_1d(np.asarray(second_parameter_values, dtype=float))
    rows = [None] if values is None else list(values)
    n_tasks = 4 * (max_workers or default_workers())
    per_row = max(1, min(speeds.size, math.ceil(n_tasks / len(rows))))
    pieces = [s for s in np.array_split(np.arange(speeds.size), per_row) if s.size]
    jobs = [(system_or_callable, speeds[s], value, options) for value in rows for s in pieces]
    parts = run(_chart_part, jobs, executor, client, max_workers, chunksize=1,
                timeout=timeout)
    chart = merge_charts(parts, len(rows), len(pieces), speeds, values)
    stability.warn_unconverged_chart(chart)
    return chart


def merge_charts(parts, n_rows, n_pieces, speeds, values):
    """One chart from row × speed-piece charts (row-major): per-point arrays are joined."""
    first = parts[0]
    shape = first.spectral_radius.shape
    merged = {}
    for field in dataclasses.fields(first):
        value = getattr(first, field.name)
        if isinstance(value, np.ndarray) and value.shape == shape:
            rows = [np.concatenate([getattr(parts[r * n_pieces + p], field.name)
                                    for p in range(n_pieces)], axis=1) for r in range(n_rows)]
            merged[field.name] = np.concatenate(rows, axis=0)
    return dataclasses.replace(first, speeds=speeds, values=values, **merged)


def _sweep_job(build, variant, phi, options):
    from femmech.analysis.sweep import sweep

    return sweep(build(variant), phi, **options)


def sweep_variants(build: Callable, variants: Sequence, phi, executor: Executor | None = None,
                   client=None, max_workers: int | None = None,
                   timeout: float | None = None, **options) -> list:
    """Quasi-mode sweeps over drive angle of many design variants, in parallel.

    Parameters
    ----------
    build : callable
        ``build(variant) -> CoupledSystem`` (reduced frame), picklable; it runs inside
        the job, so it may build symbolic mechanisms there.
    variants : sequence
        Picklable design parameters, one per variant.
    phi : array_like (n_angles,)
        Drive angles, rad.
    executor, client, max_workers, timeout
        As in :func:`run`.
    **options
        Passed to :func:`femmech.analysis.sweep.sweep` (``Omega``, ``n_modes``, ...).

    Returns
    -------
    list of Sweep, one per variant, in order.
    """
    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    return run(_sweep_job, [(build, v, phi, options) for v in variants], executor, client,
               max_workers, chunksize=1, timeout=timeout)
