"""Scene files: a machine and the analyses wanted, in one TOML file, run end to end.

One direction, no circles: quantities with units (:mod:`.units`) → strict reading of a
table (:mod:`.reader`) → the tables of parts' meshes (:mod:`.mesh`), mechanisms and
mounts (:mod:`.machine`) and analyses (:mod:`.analyses`) → the validated
:class:`~femmech.scene.load.Scene` (:mod:`.load`) → mechanism models (:mod:`.mechanisms`)
→ meshes, FE models, superelements and mounts with every reference checked
(:mod:`.build`) → cached reductions (:mod:`.cache`) → lazily built objects of one run
(:mod:`.workshop`) → the analyses' files and report sections, one module per kind in
:mod:`.kinds` and listed by :mod:`.registry` (old path: :mod:`.tasks`) → the run into one
output folder (:mod:`.run`). Beside them: generated meshes sized for a band
(:mod:`.auto_mesh`), the memory a part needs before it is built (:mod:`.memory`), the
cache's folder (:mod:`.cache_folder`), the chain tables (:mod:`.chain`) and the report
sections describing a run (:mod:`.summary`).

Sits on top: may import every lower stage, nothing imports it but :mod:`femmech.cli`.
"""

from femmech.deprecation import lazy_names

_LAZY = {
    "Prepared": "femmech.scene.build",
    "part_model": "femmech.scene.build",
    "prepare": "femmech.scene.build",
    "Scene": "femmech.scene.load",
    "load_scene": "femmech.scene.load",
    "RunResult": "femmech.scene.run",
    "run_scene": "femmech.scene.run",
}
"""Public name → its module, imported on first use: ``femmech check`` reads and prepares
a scene without importing the run (:mod:`.run`: tasks, report, plotting)."""

__all__ = ["Prepared", "RunResult", "Scene", "load_scene", "part_model", "prepare", "run_scene"]


_MOVED = {
    "GENERAL_OPTIONAL": "femmech.scene.load.GENERAL_OPTIONAL",
    "InterfaceSpec": "femmech.scene.load.InterfaceSpec",
    "ItemSpec": "femmech.scene.load.ItemSpec",
    "MaterialSpec": "femmech.fe.materials.Material",
    "PartSpec": "femmech.scene.load.PartSpec",
    "REDUCTIONS": "femmech.scene.load.REDUCTIONS",
    "ReductionSpec": "femmech.scene.load.ReductionSpec",
    "SECTION_SHAPES": "femmech.scene.load.SECTION_SHAPES",
    "SectionSpec": "femmech.scene.load.SectionSpec",
    "ShellSpec": "femmech.scene.load.ShellSpec",
    "SolidSpec": "femmech.scene.load.SolidSpec",
}
"""Names this package had before the restructures → their new places (docs/architecture.md,
"Moved names")."""

__getattr__, __dir__ = lazy_names(__name__, _LAZY, moved_names=_MOVED)
