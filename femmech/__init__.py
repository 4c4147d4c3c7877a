"""femmech: finite-element frames and mechanism models for the dynamics of machines.

Importing femmech has no side effects and does not import pyvista (see
:mod:`femmech.output` for images and files).

Its packages, along the data flow: :mod:`.solve` (sparse linear algebra),
:mod:`.fe` (the FE model) and :mod:`.mechanisms`, :mod:`.reduction` (superelements),
:mod:`.coupling` (frame and mechanisms), :mod:`.analysis`, :mod:`.chain`, :mod:`.output`,
:mod:`.scene` (scene files), :mod:`.cli` and :mod:`.__main__` (the command line); beneath
them :mod:`.errors`, :mod:`.version`, :mod:`.html` and :mod:`.deprecation` (moved names).

Not a stage: it re-exports the public API of the stages (docs/architecture.md);
nothing inside femmech imports it.
"""

from femmech.deprecation import lazy_names
from femmech.errors import (
    CacheWarning,
    ConvergenceWarning,
    FemmechWarning,
    FileFormatError,
    InputError,
    ModelWarning,
    NumericalError,
    SceneError,
    UserCodeError,
)
from femmech.version import __version__

_LAZY = {
    "DiscretisationEstimate": "femmech.analysis.discretisation",
    "discretisation_error": "femmech.analysis.discretisation",
    "ModeSet": "femmech.analysis.modes",
    "modes": "femmech.analysis.modes",
    "generators": "femmech.fe",
    "sections": "femmech.fe",
    "InterpolatingLink": "femmech.fe.constraints",
    "RigidLink": "femmech.fe.constraints",
    "Support": "femmech.fe.constraints",
    "PointMass": "femmech.fe.lumped",
    "Spring": "femmech.fe.lumped",
    "Material": "femmech.fe.materials",
    "Mesh": "femmech.fe.mesh",
    "read_mesh": "femmech.fe.mesh_io",
    "BeamProperty": "femmech.fe.model",
    "FEModel": "femmech.fe.model",
    "ShellProperty": "femmech.fe.model",
    "ShellSet": "femmech.fe.model",
    "SolidProperty": "femmech.fe.model",
    "SolidSet": "femmech.fe.model",
    "build_model": "femmech.fe.model",
    "refine_mesh": "femmech.fe.refine",
    "BeamSection": "femmech.fe.sections",
    # the main verbs of the data flow: reduce, couple, sweep, judge stability, respond, run
    "craig_bampton": "femmech.reduction",
    "guyan": "femmech.reduction",
    "rheolinear": "femmech.mechanisms",
    "Attachment": "femmech.coupling",
    "Mount": "femmech.coupling",
    "couple": "femmech.coupling",
    "sweep": "femmech.analysis.sweep",
    "speed_study": "femmech.analysis.stability",
    "stability_chart": "femmech.analysis.stability",
    "periodic_steady_state": "femmech.analysis.response",
    "load_scene": "femmech.scene",
    "run_scene": "femmech.scene",
}
"""Public name → the module it lives in, imported on first use (PEP 562), so that
``import femmech`` (and every ``python -m femmech`` command, e.g. ``femmech check``)
imports neither the solvers nor the analyses it does not use."""

__all__ = [
    "__version__",
    "generators",
    "sections",
    "BeamProperty",
    "BeamSection",
    "CacheWarning",
    "FEModel",
    "ConvergenceWarning",
    "DiscretisationEstimate",
    "FemmechWarning",
    "FileFormatError",
    "InputError",
    "InterpolatingLink",
    "Material",
    "Mesh",
    "ModelWarning",
    "ModeSet",
    "NumericalError",
    "PointMass",
    "RigidLink",
    "SceneError",
    "ShellProperty",
    "ShellSet",
    "SolidProperty",
    "SolidSet",
    "Spring",
    "Support",
    "UserCodeError",
    "build_model",
    "discretisation_error",
    "modes",
    "read_mesh",
    "refine_mesh",
    "Attachment",
    "Mount",
    "couple",
    "craig_bampton",
    "guyan",
    "load_scene",
    "periodic_steady_state",
    "rheolinear",
    "run_scene",
    "speed_study",
    "stability_chart",
    "sweep",
]


_OLD_MODULES = frozenset({
    "assembly", "cache", "checks", "constraints", "dofs", "elements", "io", "linalg", "lobpcg",
    "lumped", "materials", "mesh", "model", "parts", "recovery", "report", "scene_analyses",
    "scene_build", "scene_machine", "scene_mechanisms", "scene_mesh", "scene_reader", "scene_run",
    "scene_tasks", "solvers", "substructures", "superelement_file", "threads", "units",
})
"""Top-level modules of the previous layout, kept as old paths (docs/architecture.md,
"Moved names"): ``femmech.io`` etc. still work as attributes of femmech."""


def _old_module(name: str):
    """An old top-level module (``fm.linalg``) as an attribute of femmech: its names warn
    and lead to their new places."""
    import importlib

    if name in _OLD_MODULES:
        return importlib.import_module(f"femmech.{name}")
    raise AttributeError(f"module 'femmech' has no attribute {name!r}")


__getattr__, __dir__ = lazy_names(__name__, _LAZY, fallback=_old_module)
