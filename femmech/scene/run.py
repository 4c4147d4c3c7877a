"""Run a scene: compute only what its analyses need, reuse cached reductions, report.

``run_scene(scene, out)`` is what ``femmech run`` calls. Objects are built lazily by a
:class:`~femmech.scene.workshop.Workshop` (an explicit memo kept for one run): a part's
FE model is assembled only when an analysis or a cache miss needs it, its reduction is
loaded from the cache when the key matches (:mod:`femmech.scene.cache`), and the
unreduced coupled machine is built only for the full-versus-reduced check. Results go to
``out``, which a run replaces as a whole when it succeeds (:mod:`femmech.output.folder`):
the report page (``report.html``), ``results.json`` (key numbers, no timings: identical
for identical inputs), ``run.log`` and the files of each analysis.

Stage 8 (scene), the top: uses scene.registry (the analysis kinds), scene.workshop,
scene.build, the cache and output; only femmech.cli and the package's __init__ import it.
"""

from __future__ import annotations

import json
import logging
import time
import warnings
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from femmech.errors import CacheWarning, ModelWarning, NumericalError, SceneError
from femmech.output.export import atomic_path
from femmech.output.report import Section, write_report
from femmech.scene.build import (
    fail,
    finding_lines,
    prepare,
)
from femmech.scene.cache_folder import default_cache_dir
from femmech.scene.load import Scene, load_scene
from femmech.scene.registry import KINDS
from femmech.scene.summary import appendix_section, summary_section
from femmech.scene.workshop import Workshop, progress
from femmech.version import __version__

LOG = logging.getLogger("femmech.run")
"""Every line of a run's log (``run.log``) also goes here: INFO, and WARNING for the
``warning:`` lines (suspicious inputs, cache problems). ``femmech run`` shows INFO
and above (``-q``: WARNING and above, ``-v``: everything)."""

DEFAULT = object()
"""Marker: use :func:`femmech.scene.cache_folder.default_cache_dir`."""


@dataclass(frozen=True)
class RunResult:
    """What a run produced.

    Attributes
    ----------
    out_dir : Path
    report : Path
    results : dict
        Key numbers as written to ``results.json``.
    log : tuple of str
        The run log (also ``run.log``): one line per cache entry and step.
    timings : dict[str, float]
        Seconds per step.
    """

    out_dir: Path
    report: Path
    results: dict
    log: tuple
    timings: dict


def run_scene(scene, out, cache_dir=DEFAULT, log: Callable[[str], None] | None = None,
              bars: bool = False, allow_code: bool = False, code_root=None) -> RunResult:
    """Compute the analyses of ``scene`` (a Scene or a scene file) and write the report.

    All files are written into a staging folder that replaces ``out`` only when the run
    has succeeded (:func:`femmech.output.folder.staged_output`): the report, images and
    tables in ``out`` always belong to one complete run, and a failed run leaves the
    previous one as it was.

    Parameters
    ----------
    scene : Scene or path
    out : path
        Output folder: created (with its parents) if missing; an existing one must be
        empty or written by an earlier run (InputError otherwise).
    cache_dir : path or None
        Reduction cache; default :func:`femmech.scene.cache_folder.default_cache_dir`,
        None: no cache.
    log : callable, optional
        Also receives each log line as it happens (e.g. ``print``); the lines always go
        to the logger ``femmech.run`` (:data:`LOG`) as well.
    bars : bool
        tqdm progress bars for the long steps.
    allow_code : bool
        Run the Python modules the scene names (``module =``); refused otherwise. Only for
        scenes from authors you trust (threat model: docs/robustness.md).
    code_root : path, optional
        Folder the scene's modules must lie in (default: the scene's folder).

    Returns
    -------
    RunResult

    Raises
    ------
    SceneError
        For an invalid scene (one line naming the file, key and expectation); its
        subclass UserCodeError for refused or failing scene code.
    NumericalError
        When a computation on a valid scene fails (naming the analysis).
    """
    from femmech.output.folder import output_path, staged_output

    scene = scene if isinstance(scene, Scene) else load_scene(scene)
    lines: list[str] = []

    def emit(line: str) -> None:
        lines.append(line)
        LOG.log(logging.WARNING if line.startswith("warning:") else logging.INFO, line)
        if log is not None:
            log(line)

    cache = default_cache_dir() if cache_dir is DEFAULT else cache_dir
    start = time.perf_counter()
    with logged_warnings(emit, "prepare"):  # e.g. what a mesh file loses (read_mesh)
        prepared = prepare(scene, allow_code=allow_code, code_root=code_root)
    with staged_output(out) as stage:
        final = output_path(out)
        ws = Workshop(prepared, cache, emit, bars)
        ws.timings["prepare"] = time.perf_counter() - start
        for line in finding_lines(prepared):
            emit(line)
        sections, results = [], {}
        requested = scene.analyses.requested()
        for kind in progress(requested, "analyses", bars):
            with ws.timed(f"analysis {kind}"), logged_warnings(emit, f"analysis {kind}"):
                section, numbers = _analysis(ws, kind, stage)
            sections.append(section)
            results[kind] = numbers
            emit(f"{kind}: done in {ws.timings[f'analysis {kind}']:.2f} s")
        with ws.timed("model summary"), logged_warnings(emit, "model summary"):
            sections.insert(0, summary_section(ws))
        ws.timings["total"] = time.perf_counter() - start
        LOG.debug("timings (s): " + ", ".join(f"{k} {v:.3f}" for k, v in ws.timings.items()))
        _write_json(stage / "results.json", results)
        sections.append(Section("Files", files=("results.json", "run.log")))
        emit(f"report: {final / 'report.html'}")
        with atomic_path(stage / "run.log") as tmp:
            tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
        sections.append(appendix_section(ws, final, lines))
        meta = (f"scene {scene.file} · femmech {__version__} ·"
                f" {time.strftime('%Y-%m-%d %H:%M')} · {ws.timings['total']:.1f} s")
        title = scene.name + (f" — {scene.description}" if scene.description else "")
        report = write_report(stage, title, meta, sections)
    return RunResult(final, final / report.name, results, tuple(lines), dict(ws.timings))


NUMERICAL_FAILURES = (RuntimeError, np.linalg.LinAlgError, ArithmeticError)
"""Exceptions of a computation on valid input (ArithmeticError includes FloatingPointError
and OverflowError); reported as NumericalError."""


def _analysis(ws: Workshop, kind: str, out: Path):
    """Run one analysis kind; its errors named at its table (``[analyses.<kind>]``)."""

    scene = ws.scene
    try:
        return KINDS[kind].run(ws, scene.analyses.specs[kind], out)
    except (SceneError, NumericalError):
        raise
    except NUMERICAL_FAILURES as exc:  # valid input, failed computation
        where = scene.analyses.where[kind]
        raise NumericalError(f"{scene.file}: [{where}]: the computation failed:"
                             f" {type(exc).__name__}: {exc}".replace("\n", " ")) from exc
    except ValueError as exc:  # e.g. more modes than coordinates: name the analysis
        raise fail(scene, scene.analyses.where[kind], None, str(exc)) from None


@contextmanager
def logged_warnings(emit: Callable[[str], None], step: str):
    """:class:`~femmech.errors.ModelWarning` s and :class:`~femmech.errors.CacheWarning` s
    raised inside go to the run log as ``warning: <step>: <message>``; other warnings pass
    on unchanged."""
    caught = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ModelWarning)
            warnings.simplefilter("always", CacheWarning)
            yield
    finally:
        for w in caught:
            if issubclass(w.category, (ModelWarning, CacheWarning)):
                emit(f"warning: {step}: {w.message}")
            else:
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def _write_json(path: Path, data) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(data, indent=1, sort_keys=True), encoding="utf-8")
