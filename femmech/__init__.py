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
