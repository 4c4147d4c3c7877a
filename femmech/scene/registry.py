"""The registry of analysis kinds: :data:`KINDS`, name → :class:`AnalysisKind`, in run
order. Reading a scene (:func:`femmech.scene.analyses.read_analyses`), running it
(:mod:`femmech.scene.run`), ``femmech check`` and the docs test all take the kinds from
here.

The kinds are the modules of :mod:`femmech.scene.kinds` (each ends with ``KIND = ...``),
found by name when this module is first imported, so adding a kind is adding its module;
:func:`register` adds a kind defined elsewhere (a test's toy kind).

Stage 8 (scene): uses scene.kinds.common (imports the kind modules by name, importlib).
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Mapping

from femmech.scene import kinds as _package
from femmech.scene.kinds.common import AnalysisKind

SHARED = ("common",)
"""Modules of :mod:`femmech.scene.kinds` that are not kinds (what the kinds share)."""


def kind_modules() -> tuple[str, ...]:
    """Dotted names of the kind modules of :mod:`femmech.scene.kinds`, sorted by name."""
    return tuple(f"{_package.__name__}.{m.name}"
                 for m in sorted(pkgutil.iter_modules(_package.__path__), key=lambda m: m.name)
                 if m.name not in SHARED)


def _discover() -> dict[str, AnalysisKind]:
    found = []
    for name in kind_modules():
        kind = getattr(importlib.import_module(name), "KIND", None)
        if not isinstance(kind, AnalysisKind):
            raise TypeError(f"{name}: a kind module must end with KIND = AnalysisKind(...)")
        found.append(kind)
    return {k.name: k for k in sorted(found, key=lambda k: k.order)}


KINDS: dict[str, AnalysisKind] = _discover()
"""Every analysis kind by name, in run order (ascending ``order``)."""


def register(kind: AnalysisKind) -> AnalysisKind:
    """Add ``kind`` to :data:`KINDS` at its place in the run order; a name registers once."""
    if kind.name in KINDS or kind.name == "speed_unit":
        raise ValueError(f"analysis kind {kind.name!r} already exists")
    ordered = sorted((*KINDS.values(), kind), key=lambda k: k.order)
    KINDS.clear()
    KINDS.update((k.name, k) for k in ordered)
    return kind


class _Runners(Mapping):
    """Kind name → its runner, read live from :data:`KINDS` (the old ``TASKS`` table)."""

    def __getitem__(self, name: str):
        return KINDS[name].run

    def __iter__(self):
        return iter(KINDS)

    def __len__(self) -> int:
        return len(KINDS)


RUNNERS: Mapping = _Runners()
"""Kind name → runner ``(workshop, spec, out) -> (Section, numbers)``, a read-only view of
:data:`KINDS` (what ``femmech.scene.tasks.TASKS`` was)."""
