"""femmech: finite-element frames and mechanism models for the dynamics of machines.

Importing femmech has no side effects and does not import pyvista (see
:mod:`femmech.output` for images and files).

Not a stage: it re-exports the public API of the stages (docs/architecture.md);
nothing inside femmech imports it.
"""

from femmech.analysis.discretisation import DiscretisationEstimate, discretisation_error
from femmech.analysis.modes import ModeSet, modes
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
from femmech.fe import generators, sections
from femmech.fe.constraints import InterpolatingLink, RigidLink, Support
from femmech.fe.lumped import PointMass, Spring
from femmech.fe.materials import Material
from femmech.fe.mesh import Mesh
from femmech.fe.mesh_io import read_mesh
from femmech.fe.model import (
    BeamProperty,
    FEModel,
    ShellProperty,
    ShellSet,
    SolidProperty,
    SolidSet,
    build_model,
)
from femmech.fe.refine import refine_mesh
from femmech.fe.sections import BeamSection
from femmech.version import __version__

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
]


_OLD_MODULES = frozenset({
    "assembly", "cache", "checks", "constraints", "dofs", "elements", "io", "linalg", "lobpcg",
    "lumped", "materials", "mesh", "model", "parts", "recovery", "report", "scene_analyses",
    "scene_build", "scene_machine", "scene_mechanisms", "scene_mesh", "scene_reader", "scene_run",
    "scene_tasks", "solvers", "substructures", "superelement_file", "threads", "units",
})
"""Top-level modules of the previous layout, kept as old paths (docs/architecture.md,
"Moved names"): ``femmech.io`` etc. still work as attributes of femmech."""


def __getattr__(name: str):
    """An old top-level module (``fm.linalg``) as an attribute: its names warn and lead to
    their new places."""
    if name in _OLD_MODULES:
        import importlib

        return importlib.import_module(f"femmech.{name}")
    raise AttributeError(f"module 'femmech' has no attribute {name!r}")
