"""Scene table ``[analyses]``: which results to compute, with their settings (SI).

Each ``[analyses.<kind>]`` is read by its analysis kind (:data:`femmech.scene.registry.KINDS`,
one module each in :mod:`femmech.scene.kinds`; docs/scenes.md lists them); the top-level
``[synthesis]`` is read with the scene and passed in. Each kind is requested at most once.

``speed_unit`` (a key of ``[analyses]`` itself: "rpm", the default, or "rad/s") is the
one unit in which the scene's charts, tables and report show drive speeds; the readers of
the kinds that show speeds copy it into their specs.

Stage 8 (scene), reading: uses scene.reader, scene.registry and scene.kinds.common.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from femmech.scene.kinds.common import MAX_MODES, SPEED_UNITS, ReadContext
from femmech.scene.reader import Reader
from femmech.scene.registry import KINDS

__all__ = ["MAX_MODES", "Analyses", "read_analyses"]  # MAX_MODES: for femmech.scene.load


@dataclass(frozen=True)
class Analyses:
    """The requested analyses: ``specs`` (kind name → its spec, in run order); each kind
    is also an attribute (``analyses.modes``: its spec, None when not requested)."""

    specs: dict = field(default_factory=dict)
    speed_unit: str = "rpm"
    where: dict = field(default_factory=dict, compare=False)

    def __getattr__(self, name: str):
        if name in KINDS:
            return self.specs.get(name)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def __hash__(self):
        return hash((tuple(self.specs.items()), self.speed_unit))

    def requested(self) -> tuple[str, ...]:
        """Names of the requested kinds, in run order."""
        return tuple(k for k in KINDS if k in self.specs)


def read_analyses(r: Reader, parts: dict, mechanisms: dict, has_mounts: bool,
                  extra: dict | None = None, synthesis=None) -> Analyses:
    """Parse ``[analyses]``; each kind's reader checks that it has what it needs.

    ``extra``: what the readers need of the scene besides its parts and mechanisms
    (``{"chain": ChainSpec or None}``, :func:`femmech.scene.chain.chain_analyses`);
    ``synthesis``: the spec of the top-level ``[synthesis]`` (read with the scene).
    """
    tables = [k for k in KINDS.values() if not k.top_level]
    r.expect("speed_unit", *(k.name for k in tables))
    unit = r.string("speed_unit", SPEED_UNITS[0], choices=SPEED_UNITS)
    context = ReadContext(parts, mechanisms, has_mounts, (extra or {}).get("chain"), unit)
    found, where = {}, {}
    if synthesis is not None:
        found["synthesis"], where["synthesis"] = synthesis, "synthesis"
    for kind in tables:
        if r.has(kind.name):
            t = r.table(kind.name)
            where[kind.name] = t.where
            t.expect(*kind.keys)
            found[kind.name] = kind.read(t, context)
    if not found:
        names = [f"[analyses.{k.name}]" if not k.top_level else f"[{k.name}]"
                 for k in KINDS.values()]
        raise r.error(None, f"no analyses requested: add {', '.join(names[:-1])} or"
                            f" {names[-1]}")
    specs = {k: found[k] for k in KINDS if k in found}
    return Analyses(specs, speed_unit=unit, where=where)


def __getattr__(name: str):
    """Names this module had before the analysis kinds got their modules, from their new
    places (docs/architecture.md, "Moved names")."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "CheckSpec": "femmech.scene.kinds.check.CheckSpec",
        "DriveEventSpec": "femmech.scene.kinds.drive_event.DriveEventSpec",
        "MAX_ANIMATIONS": "femmech.scene.kinds.common.MAX_ANIMATIONS",
        "MAX_DRIVE_EVALUATIONS": "femmech.scene.kinds.common.MAX_DRIVE_EVALUATIONS",
        "MAX_DRIVE_STEPS": "femmech.scene.kinds.common.MAX_DRIVE_STEPS",
        "MAX_HISTORIES": "femmech.scene.kinds.common.MAX_HISTORIES",
        "MAX_IMAGES": "femmech.scene.kinds.common.MAX_IMAGES",
        "MAX_LEVELS": "femmech.scene.kinds.common.MAX_LEVELS",
        "MAX_POINTS": "femmech.scene.kinds.common.MAX_POINTS",
        "MAX_RUNS": "femmech.scene.kinds.common.MAX_RUNS",
        "MAX_STEPS": "femmech.scene.kinds.common.MAX_STEPS",
        "MAX_SWEEP_POINTS": "femmech.scene.kinds.common.MAX_SWEEP_POINTS",
        "ModesSpec": "femmech.scene.kinds.modes.ModesSpec",
        "ResponseSpec": "femmech.scene.kinds.response.ResponseSpec",
        "StabilitySpec": "femmech.scene.kinds.stability.StabilitySpec",
        "SweepSpec": "femmech.scene.kinds.sweep.SweepSpec",
        "read_values": "femmech.scene.kinds.common.read_values",
    })
