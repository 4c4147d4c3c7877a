"""Lumped mechanism models: position functions, M(φ), B(φ), C(φ), F(φ), equations of motion.

The symbols follow the seed chapter (Dresig/Vul'fson, ch. 5): M mass, B damping,
C stiffness, F force.

* :mod:`.position`: the position-function protocol shared by cams, linkages and tables.
* :mod:`.motion_laws`: cam motion laws and cam programmes over one revolution.
* :mod:`.linkages`: slider-crank and four-bar position functions with exact derivatives.
* :mod:`.tabulated`: user-tabulated position functions (periodic quintic spline).
* :mod:`.symbolic`: symbolic description of a lumped mechanism (bodies, springs, loads).
* :mod:`.lagrange`: symbolic equations of motion (2nd kind, mixed type, rheolinear).
* :mod:`.evaluate`: vectorised numerical evaluation of the symbolic equations.
* :mod:`.models`: numerical mechanism models (rheolinear, 2nd kind, mixed type).
* :mod:`.quasi_modes`: quasi-eigenfrequencies and quasi-modes at frozen drive angles.
* :mod:`.statics`: static equilibrium (operating point) under gravity and preload.
* :mod:`.mounted`: mechanisms whose bearings and guides move with an elastic frame.
* :mod:`.chapter`: built-in models of the seed chapter (Table 5.1, 5.2.3.1, 5.2.3.2).
* :mod:`.catalogue`: what the built-in models' coordinates and parameters mean (units,
  signs; the readable labels of tables and plots, docs/mechanisms.md).
* :mod:`.registry`: the mechanism types a scene names, registered next to their factories.

Imports only its own modules.
"""

from femmech.mechanisms.chapter import (
    mobile_crane,
    mobile_crane_parameters,
    processing_machine,
    processing_machine_cams,
    processing_machine_mixed,
    processing_machine_parameters,
    table_5_1_case,
)
from femmech.mechanisms.lagrange import (
    LagrangeTerms,
    RheolinearTerms,
    lagrange_terms,
    rheolinear_terms,
)
from femmech.mechanisms.linkages import FourBar, SliderCrank
from femmech.mechanisms.models import (
    Accelerations,
    LagrangeModel,
    MixedModel,
    MixedSolution,
    RheolinearModel,
    mixed_type,
    rheolinear,
    second_kind,
)
from femmech.mechanisms.motion_laws import (
    CamProfile,
    CamSegment,
    MotionLaw,
    PolynomialLaw,
    SinusoidalLaw,
    cam_program,
    cycloidal,
    harmonic,
    modified_sine,
    modified_trapezoid,
    motion_law,
    polynomial_345,
    polynomial_4567,
)
from femmech.mechanisms.mounted import cam_follower, slider_crank
from femmech.mechanisms.position import PositionFunction
from femmech.mechanisms.quasi_modes import (
    QuasiModes,
    frozen_eigen,
    quasi_modes,
)
from femmech.mechanisms.statics import StaticEquilibrium, static_equilibrium
from femmech.mechanisms.symbolic import (
    Damper,
    Load,
    Mechanism,
    PointMass,
    Potential,
    RotaryInertia,
    Spring,
    position_function,
    velocity_symbol,
)
from femmech.mechanisms.tabulated import TabulatedPositionFunction

__all__ = [
    "Accelerations",
    "CamProfile",
    "CamSegment",
    "Damper",
    "FourBar",
    "LagrangeModel",
    "LagrangeTerms",
    "Load",
    "Mechanism",
    "MixedModel",
    "MixedSolution",
    "MotionLaw",
    "PointMass",
    "PolynomialLaw",
    "PositionFunction",
    "Potential",
    "QuasiModes",
    "RheolinearModel",
    "RheolinearTerms",
    "RotaryInertia",
    "SinusoidalLaw",
    "SliderCrank",
    "Spring",
    "StaticEquilibrium",
    "TabulatedPositionFunction",
    "cam_follower",
    "cam_program",
    "cycloidal",
    "frozen_eigen",
    "harmonic",
    "lagrange_terms",
    "mixed_type",
    "mobile_crane",
    "mobile_crane_parameters",
    "modified_sine",
    "modified_trapezoid",
    "motion_law",
    "polynomial_345",
    "polynomial_4567",
    "position_function",
    "processing_machine",
    "processing_machine_cams",
    "processing_machine_mixed",
    "processing_machine_parameters",
    "quasi_modes",
    "rheolinear",
    "rheolinear_terms",
    "second_kind",
    "slider_crank",
    "static_equilibrium",
    "table_5_1_case",
    "velocity_symbol",
]


def __getattr__(name: str):
    """Names this module had before the restructures, from their new places
    (docs/architecture.md, "Moved names")."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "plot_quasi_frequencies": "femmech.output.sweeps.plot_quasi_frequencies",
    })
