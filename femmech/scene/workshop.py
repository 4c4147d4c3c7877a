"""Lazily built objects of one scene run: FE models, superelements, coupled machines.

A :class:`Workshop` is an explicit memo kept for one run (:mod:`femmech.scene.run`): the
mesh of a ``mesh = "auto"`` part that needs solves to be sized is sized here, a
part's FE model is assembled only when an analysis or a cache miss needs it, its
reduction is loaded from the cache when the key matches (:mod:`femmech.scene.cache`), and
the unreduced coupled machine is built only for the full-versus-reduced check. The
analyses (:mod:`femmech.scene.tasks`) take a workshop and ask it for what they need.

Stage 8 (scene), compute: uses scene.build, scene.cache, fe, reduction, coupling and
output.report.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from contextlib import contextmanager

from femmech.coupling import couple
from femmech.fe.model import FEModel
from femmech.reduction.substructures import assemble_parts
from femmech.scene.build import (
    Prepared,
    machine_mounts,
    part_model,
    reduce_part,
    reduction_key_data,
    sha256_key,
)
from femmech.scene.cache import cached_reduction
from femmech.scene.load import Scene


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

    def model(self, part: str) -> FEModel:
        """The part's assembled FE model (assembled once)."""
        if part not in self.models:
            if part in self.prepared.meshes.pending():  # mesh = "auto": sized now
                with self.timed(f"mesh sizing {part}"):
                    mesh = self.prepared.meshes[part]
                self.log(f"sized the mesh of part {part!r} (mesh = 'auto'):"
                         f" {mesh.n_nodes} nodes")
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


def __getattr__(name: str):
    """Names this module had before the restructures, from their new places
    (docs/architecture.md, "Moved names")."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
    }, removed={
        "timings_table": "the report's appendix (femmech.scene.summary) has the timings",
    })
