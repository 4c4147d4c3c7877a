"""Mechanism models of a scene: built-in factories or user modules → RheolinearModel."""

from __future__ import annotations

import hashlib
import importlib.util

from femmech.errors import SceneError
from femmech.mechanisms import (
    CamProfile,
    CamSegment,
    FourBar,
    Mechanism,
    RheolinearModel,
    SliderCrank,
    cam_follower,
    cycloidal,
    harmonic,
    modified_sine,
    modified_trapezoid,
    polynomial_345,
    processing_machine,
    processing_machine_cams,
    rheolinear,
    slider_crank,
    table_5_1_case,
)
from femmech.scene_build import fail

FACTORIES = {"cam_follower": cam_follower, "slider_crank": slider_crank,
             "table_5_1_case": table_5_1_case, "processing_machine": processing_machine}
LAWS = {"polynomial_345": polynomial_345, "cycloidal": cycloidal, "harmonic": harmonic,
        "modified_sine": modified_sine, "modified_trapezoid": modified_trapezoid}


def mechanism_model(scene, spec) -> RheolinearModel:
    """The rheolinear model of a :class:`~femmech.scene_machine.MechanismSpec`."""
    try:
        if spec.model is not None:
            built = FACTORIES[spec.model](**spec.options)
        else:
            function = getattr(load_module(spec.module), spec.function, None)
            if not callable(function):
                raise fail(scene, spec.where, "function", f"{spec.module} has no function"
                           f" {spec.function!r}")
            built = function(**spec.options)
    except SceneError:
        raise
    except Exception as exc:  # any failure of the factory or of user code (wrong option
        # names or types, a bug) is reported at its scene location
        raise fail(scene, spec.where, "options" if spec.model else "function",
                   f"{type(exc).__name__}: {exc}") from None
    if isinstance(built, RheolinearModel):
        if spec.parameters or spec.position_functions:
            raise fail(scene, spec.where, "parameters", "the function returned a ready"
                       " RheolinearModel: give no parameters or position_functions")
        return built
    if not isinstance(built, Mechanism):
        raise fail(scene, spec.where, "function" if spec.module else "model",
                   f"expected a Mechanism or RheolinearModel, got {type(built).__name__}")
    funcs = {p.name: position_function(scene, p) for p in spec.position_functions}
    try:
        return rheolinear(built, spec.parameters, funcs)
    except (ValueError, TypeError, KeyError, AttributeError) as exc:
        raise fail(scene, spec.where, "parameters", str(exc).strip("'\"")) from None


def position_function(scene, p):
    """CamProfile, SliderCrank, FourBar or a chapter cam from a PositionSpec."""
    try:
        if p.kind == "cam":
            segments = tuple(CamSegment(beta, lift, LAWS[law]() if law else None)
                             for beta, lift, law in p.params["segments"])
            return CamProfile(segments, p.params["phi_start"], p.params["base"])
        if p.kind == "slider_crank":
            return SliderCrank(**p.params)
        if p.kind == "four_bar":
            return FourBar(**p.params)
        return processing_machine_cams()[p.params["name"]]
    except ValueError as exc:
        raise fail(scene, p.where, None, str(exc)) from None


def load_module(path: str):
    """Import a user Python file under a private module name (one per path)."""
    name = "femmech_scene_" + hashlib.sha256(str(path).encode()).hexdigest()[:12]
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
