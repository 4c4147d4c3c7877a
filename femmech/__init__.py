"""femmech: finite-element frames and mechanism models for the dynamics of machines.

Importing femmech has no side effects and does not import pyvista (see
:mod:`femmech.output` for images and files).
"""

from femmech.analysis.modes import ModeSet, modes
from femmech.constraints import InterpolatingLink, RigidLink, Support
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
from femmech.io import read_mesh
from femmech.lumped import PointMass, Spring
from femmech.materials import Material
from femmech.mesh import Mesh
from femmech.model import (
    BeamProperty,
    FEModel,
    ShellProperty,
    ShellSet,
    SolidProperty,
    SolidSet,
    build_model,
)
from femmech.sections import BeamSection

__version__ = "0.1.0"

__all__ = [
    "BeamProperty",
    "BeamSection",
    "CacheWarning",
    "FEModel",
    "ConvergenceWarning",
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
    "modes",
    "read_mesh",
]
