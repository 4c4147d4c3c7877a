"""Run a scene: compute only what its analyses need, reuse cached reductions, report.

``run_scene(scene, out)`` is what ``femmech run`` calls. Objects are built lazily by a
:class:`Workshop` (an explicit memo kept for one run): a part's FE model is assembled only
when an analysis or a cache miss needs it, its reduction is loaded from the cache when
the key matches (:mod:`femmech.cache`), and the unreduced coupled machine is built only
for the full-versus-reduced check. Results go to ``out``, which a run replaces as a whole
when it succeeds (:mod:`femmech.output.folder`): the report page (``report.html``),
``results.json`` (key numbers, no timings: identical for identical inputs), ``run.log``
and the files of each analysis."""

from __future__ import annotations

import json
import logging
import sys
import time
import warnings
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import femmech as fm
from femmech.cache import cached_reduction, default_cache_dir
from femmech.coupling import couple
from femmech.errors import CacheWarning, ModelWarning, NumericalError, SceneError
from femmech.output.export import atomic_path
from femmech.report import Section, Table, write_report
from femmech.scene import Scene, load_scene
from femmech.scene_build import (
    Prepared,
    fail,
    finding_lines,
    machine_mounts,
    part_model,
    prepare,
    reduce_part,
    reduction_key_data,
    sha256_key,
)
from femmech.substructures import assemble_parts

LOG = logging.getLogger("femmech.run")
"""Every line of a run's log (``run.log``) also goes here: INFO, and WARNING for the
``warning:`` lines (suspicious inputs, cache problems). ``femmech run`` shows INFO
and above (``-q``: WARNING and above, ``-v``: everything)."""

DEFAULT = object()
"""Marker: use :func:`femmech.cache.default_cache_dir`."""


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


def progress(iterable, desc: str, enabled: bool, total: int | None = None):
    """``tqdm`` progress bar on stderr when ``enabled``, else the iterable itself."""
    if not enabled:
        return iterable
    from tqdm import tqdm

    return tqdm(iterable, desc=desc, total=total, leave=False, file=sys.stderr)


class Workshop:
    """Lazily built objects of one run: FE models, superelements, coupled machines.

    Parameters
    ----------
    prepared : Prepared
    cache_dir : path or None
        Reduction cache folder; None turns caching off.
    log : callable
        Receives one line per event.
    bars : bool
        Show progress bars.

    Attributes
    ----------
    models, superelements, machines : dict
        What was built so far: FE models by part, superelements by (part, f_max_hz or
        None), coupled machines by ``full`` (bool).
    timings : dict[str, float]
        Seconds per step.
    cache_status : dict[str, str]
        Cache status per reduction label.
    """

    def __init__(self, prepared: Prepared, cache_dir, log: Callable[[str], None], bars: bool):
        self.prepared, self.scene = prepared, prepared.scene
        self.cache_dir, self.log, self.bars = cache_dir, log, bars
        self.timings: dict[str, float] = {}
        self.cache_status: dict[str, str] = {}
        self.models, self.superelements, self.machines = {}, {}, {}

    @contextmanager
    def timed(self, step: str):
        """Add the time of the block to ``timings[step]``."""
        start = time.perf_counter()
        try:
            yield
        finally:
            self.timings[step] = self.timings.get(step, 0.0) + time.perf_counter() - start

    def model(self, part: str) -> fm.FEModel:
        """The part's assembled FE model (assembled once)."""
        if part not in self.models:
            with self.timed(f"assembly {part}"):
                spec = self.scene.parts[part]
                self.models[part] = part_model(self.scene, spec, self.prepared.meshes[part])
            model = self.models[part]
            self.log(f"assembled part {part!r}: {model.mesh.n_nodes} nodes, {model.n_free}"
                     " free DOFs")
        return self.models[part]

    def superelement(self, part: str, f_max_hz: float | None = None):
        """The part's reduction, from the cache or built (``f_max_hz``: another size)."""
        memo = (part, f_max_hz)
        if memo not in self.superelements:
            spec = self.scene.parts[part]
            key = self.prepared.keys[part] if f_max_hz is None else _key(self.scene, spec,
                                                                           f_max_hz)
            label = f"part {part!r}" + (f" at f_max {f_max_hz:g} Hz" if f_max_hz else "")
            with self.timed(f"reduction {part}"):
                got = cached_reduction(self.cache_dir, key, label,
                                       lambda: reduce_part(self.scene, spec, self.model(part),
                                                           f_max_hz), self.log)
            self.superelements[memo] = got.superelement
            self.cache_status[label] = got.status
        return self.superelements[memo]

    def machine(self, full: bool = False):
        """The coupled machine: reduced frame(s), or the unreduced FE model (one part)."""
        if full not in self.machines:
            names = list(self.scene.parts)
            with self.timed("coupling"):
                if full:
                    frame = self.model(names[0])
                else:
                    frames = [self.superelement(n) for n in names]
                    frame = frames[0] if len(frames) == 1 else assemble_parts(frames)
                index = None if len(names) == 1 else {n: i for i, n in enumerate(names)}
                self.machines[full] = couple(frame, machine_mounts(self.prepared, index))
        return self.machines[full]


def _key(scene: Scene, spec, f_max_hz: float) -> str:
    return sha256_key(reduction_key_data(scene, spec, f_max_hz))


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
        Reduction cache; default :func:`femmech.cache.default_cache_dir`, None: no cache.
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
    from femmech.scene_tasks import TASKS, summary_section

    scene = scene if isinstance(scene, Scene) else load_scene(scene)
    lines: list[str] = []

    def emit(line: str) -> None:
        lines.append(line)
        LOG.log(logging.WARNING if line.startswith("warning:") else logging.INFO, line)
        if log is not None:
            log(line)

    cache = default_cache_dir() if cache_dir is DEFAULT else cache_dir
    start = time.perf_counter()
    prepared = prepare(scene, allow_code=allow_code, code_root=code_root)
    with staged_output(out) as stage:
        final = output_path(out)
        ws = Workshop(prepared, cache, emit, bars)
        ws.timings["prepare"] = time.perf_counter() - start
        for line in finding_lines(prepared):
            emit(line)
        sections, results = [], {}
        requested = [k for k in TASKS if getattr(scene.analyses, k) is not None]
        for kind in progress(requested, "analyses", bars):
            with ws.timed(f"analysis {kind}"), logged_warnings(emit, f"analysis {kind}"):
                section, numbers = _analysis(ws, kind, stage)
            sections.append(section)
            results[kind] = numbers
            emit(f"{kind}: done in {ws.timings[f'analysis {kind}']:.2f} s")
        ws.timings["total"] = time.perf_counter() - start
        LOG.debug("timings (s): " + ", ".join(f"{k} {v:.3f}" for k, v in ws.timings.items()))
        sections.insert(0, summary_section(ws))
        _write_json(stage / "results.json", results)
        sections.append(Section("Files", files=("results.json", "run.log")))
        emit(f"report: {final / 'report.html'}")
        with atomic_path(stage / "run.log") as tmp:
            tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
        meta = (f"scene {scene.file} · femmech {fm.__version__} ·"
                f" {time.strftime('%Y-%m-%d %H:%M')} · {ws.timings['total']:.1f} s")
        title = scene.name + (f" — {scene.description}" if scene.description else "")
        report = write_report(stage, title, meta, sections, lines)
    return RunResult(final, final / report.name, results, tuple(lines), dict(ws.timings))


NUMERICAL_FAILURES = (RuntimeError, np.linalg.LinAlgError, ArithmeticError)
"""Exceptions of a computation on valid input (ArithmeticError includes FloatingPointError
and OverflowError); reported as NumericalError."""


def _analysis(ws: Workshop, kind: str, out: Path):
    """Run one analysis task; its errors named at ``[analyses.<kind>]``."""
    from femmech.scene_tasks import TASKS

    scene = ws.scene
    try:
        return TASKS[kind](ws, getattr(scene.analyses, kind), out)
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


def timings_table(ws: Workshop) -> Table:
    """Seconds per step."""
    return Table("Timings", ("step", "seconds"),
                 tuple((k, round(v, 3)) for k, v in ws.timings.items()))
