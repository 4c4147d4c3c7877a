"""Mechanism models of a scene: built-in factories or user modules → RheolinearModel
(``form = "rheolinear"``) or LagrangeModel (``form = "second_kind"``).

A user module (``module = "my_mech.py"``) is Python code: it runs only when the caller
opts in (``allow_code=True``, ``femmech run --allow-code``), and only from a file inside
the allowed root (the scene's folder unless the caller names another, ``code_root``).
See the threat model in docs/robustness.md.

Stage 8 (scene), build: uses scene.load, scene.machine and mechanisms.
"""

from __future__ import annotations

import hashlib
import importlib.util
from pathlib import Path

from femmech.errors import SceneError, UserCodeError
from femmech.mechanisms import (
    CamProfile,
    CamSegment,
    FourBar,
    LagrangeModel,
    Mechanism,
    RheolinearModel,
    SliderCrank,
    Spring,
    processing_machine_cams,
    rheolinear,
    second_kind,
)
from femmech.mechanisms.catalogue import describe
from femmech.mechanisms.motion_laws import LAWS
from femmech.scene.load import fail
from femmech.scene.machine import BUILTIN_MODELS

FORM_BUILDERS = {"rheolinear": (rheolinear, RheolinearModel),
                 "second_kind": (second_kind, LagrangeModel)}
"""``form`` → (builder from a symbolic Mechanism, the model class it returns)."""


def mechanism_model(scene, spec, code_root=None) -> RheolinearModel | LagrangeModel:
    """The model of a :class:`~femmech.scene.machine.MechanismSpec` in its ``form``:
    a RheolinearModel (``rheolinear``) or a LagrangeModel (``second_kind``).

    A user module is imported and its function called: the caller has checked the opt-in
    (:func:`femmech.scene.build.prepare`); its file must lie under ``code_root`` (default:
    the scene's folder). An exception or ``sys.exit`` inside user code becomes a
    :class:`~femmech.errors.UserCodeError` at the mechanism's location.
    """
    if spec.model is not None:
        try:
            built = BUILTIN_MODELS[spec.model](**spec.options)
        except Exception as exc:  # wrong option names or types: at the scene location
            raise fail(scene, spec.where, "options", f"{type(exc).__name__}: {exc}") from None
    else:
        path = confined_module(scene, spec, code_root)
        try:
            function = getattr(load_module(path), spec.function, None)
            if not callable(function):
                raise code_error(scene, spec, "function", f"{path.name} has no function"
                                 f" {spec.function!r}")
            built = function(**spec.options)
        except SceneError:
            raise
        except SystemExit as exc:  # a module that exits must not end femmech with its code
            raise code_error(scene, spec, "module", f"the user code called"
                             f" sys.exit({exc.code!r}) in {path.name}") from None
        except Exception as exc:  # any failure of user code is reported at its location
            raise code_error(scene, spec, "function", f"the user code raised"
                             f" {type(exc).__name__}: {exc}") from None
    return _in_form(scene, spec, built)


def _in_form(scene, spec, built):
    """The model of the spec's form from what the factory or user function returned."""
    build, cls = FORM_BUILDERS[spec.form]
    if isinstance(built, (RheolinearModel, LagrangeModel)):
        if not isinstance(built, cls):
            raise fail(scene, spec.where, "form", f"the function returned a ready"
                       f" {type(built).__name__}, not the {cls.__name__} of form ="
                       f" {spec.form!r}; return a symbolic Mechanism or change form")
        if spec.parameters or spec.position_functions:
            raise fail(scene, spec.where, "parameters", f"the function returned a ready"
                       f" {cls.__name__}: give no parameters or position_functions")
        return built
    if not isinstance(built, Mechanism):
        raise fail(scene, spec.where, "function" if spec.module else "model",
                   f"expected a Mechanism or {cls.__name__}, got {type(built).__name__}")
    funcs = {p.name: position_function(scene, p) for p in spec.position_functions}
    try:
        return build(built, spec.parameters, funcs)
    except (ValueError, TypeError, KeyError, AttributeError) as exc:
        raise fail(scene, spec.where, "parameters", str(exc).strip("'\"")) from None


def coordinate_names(model) -> tuple[str, ...]:
    """Names of a model's coordinates for tables: the vibration coordinates of a
    RheolinearModel; all coordinates of a LagrangeModel, drives marked ``(drive)``."""
    if isinstance(model, LagrangeModel):
        drives = set(model.mechanism.drives)
        return tuple(q.name + (" (drive)" if q in drives else "")
                     for q in model.mechanism.coordinates)
    return tuple(model.coordinate_names)


def coordinate_labels(model) -> tuple[str, ...]:
    """Readable names of :func:`coordinate_names` for HTML tables: ``"follower deformation
    [q]"`` (:func:`femmech.mechanisms.catalogue.describe`), drives marked ``(drive)``."""
    if isinstance(model, LagrangeModel):
        drives = set(model.mechanism.drives)
        return tuple(describe(model, q.name) + (" (drive)" if q in drives else "")
                     for q in model.mechanism.coordinates)
    return tuple(describe(model, name) for name in model.coordinate_names)


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


def code_error(scene, spec, key: str, message: str) -> UserCodeError:
    """A one-line UserCodeError at ``[mechanisms.<name>] key``."""
    return fail(scene, spec.where, key, message, UserCodeError)


def confined_module(scene, spec, code_root=None) -> Path:
    """The resolved path of a mechanism's user module, refused (UserCodeError) unless it
    is a ``.py`` file under ``code_root`` (default: the scene's folder; symbolic links are
    resolved first, so a link may not lead out either)."""
    root = Path(code_root if code_root is not None else scene.base_dir).resolve()
    path = Path(spec.module).resolve()
    if path.suffix != ".py":
        raise code_error(scene, spec, "module", f"expected a Python file (.py), got {path.name!r}")
    if not path.is_relative_to(root):
        where = "the scene's folder" if code_root is None else "the code root"
        raise code_error(scene, spec, "module", f"{path} lies outside {where} {root}; femmech"
                         " runs scene code only from there (name another folder with"
                         " --code-root / code_root=)")
    if not path.is_file():
        raise code_error(scene, spec, "module", f"file not found: {path}")
    return path


def load_module(path):
    """Import a user Python file under a private module name (one per path)."""
    name = "femmech_scene_" + hashlib.sha256(str(path).encode()).hexdigest()[:12]
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def output_names(model: LagrangeModel) -> tuple[str, ...]:
    """What a drive event of ``model`` can show: its coordinates and ``spring<k>``, the
    force of its k-th spring (1-based, element order)."""
    springs = sum(isinstance(el, Spring) for el in model.mechanism.elements)
    return (tuple(q.name for q in model.mechanism.coordinates)
            + tuple(f"spring{k + 1}" for k in range(springs)))


def check_drive_event(scene, models: dict) -> None:
    """The drive and outputs of ``[analyses.drive_event]`` against the built mechanism
    (skipped when its user code was not run)."""
    spec = scene.analyses.drive_event
    if spec is None or spec.mechanism not in models:
        return
    model, where = models[spec.mechanism], scene.analyses.where["drive_event"]
    drives = [x.name for x in model.mechanism.drives]
    if spec.drive not in drives:
        raise fail(scene, where, "drive", f"expected one of the drive coordinates {drives}"
                   f" of mechanism {spec.mechanism!r}, got {spec.drive!r}")
    allowed = output_names(model)
    for name in spec.outputs or ():
        if name not in allowed:
            raise fail(scene, where, "outputs", f"expected coordinates or spring forces of"
                       f" mechanism {spec.mechanism!r}, one of {list(allowed)}, got {name!r}")


def __getattr__(name: str):
    """Names this module had before the restructures, from their new places
    (docs/architecture.md, "Moved names")."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "FACTORIES": "femmech.scene.machine.BUILTIN_MODELS",
    })
