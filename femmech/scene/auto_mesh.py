"""Generated meshes of scene parts, and ``mesh = "auto"``: element counts sized for a band.

:func:`generate` builds any generator of :mod:`femmech.scene.mesh` from its parameters
(counts given). :func:`auto_mesh` picks the counts of a ``mesh = "auto"`` part from its
band and ``target_error`` (:mod:`femmech.fe.sizing`: elements per half-wavelength of the
shortest wave at f_max for beams, a shell size for shells). A band given as ``n_modes``
is turned into a frequency on the mesh itself: a coarse mesh gives a first (high)
estimate of the last mode's frequency, the mesh sized for it a better one, until the
counts no longer change (at most :data:`MAX_ROUNDS` solves).

Planning (:func:`femmech.scene.build.prepare`) never solves: it takes
:func:`planned_mesh`, which is final where the wave rule alone sizes the part, and the
solves of :func:`auto_mesh` run when the part's model is first needed.

Shell parts are then *checked*: the wave rule sizes for the waves inside a panel and
misses boundary layers (soft supports, clamped ends, folded corners), so the sized mesh's
discretisation error over the band is estimated (:func:`femmech.analysis.discretisation.
discretisation_error`: one h/2 refinement and Richardson) and the counts are scaled by
``(estimate / target)^(1/rate)`` where it exceeds the target, up to
:data:`MAX_CORRECTIONS` times. What still misses the target is said in a ModelWarning.

Stage 8 (scene), building: uses fe (generators, sizing) and analysis (modes,
discretisation).
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from femmech.errors import ModelWarning
from femmech.fe import sizing
from femmech.fe.generators import box, grid_frame, members_frame, rectangular_plate
from femmech.fe.mesh import Mesh
from femmech.scene.memory import memory_problem
from femmech.scene.mesh import generator_counts

MAX_ROUNDS = 4
"""Most sizing rounds (eigen solves) for a band given as ``n_modes``."""
COARSE_ELEMENTS = 8
"""Elements along the longest side of a shell part's first (coarse) mesh; beam members
start with 2 elements each."""
_SHELL_SIDES = {"rectangular_plate": ("a", "b"), "box": ("length", "width", "height")}
MAX_CORRECTIONS = 2
"""Most estimator-driven refinements of a sized shell mesh (each costs one h/2 solve)."""
SAFETY = 1.1
"""Extra factor on the element counts of a correction (the estimate's own spread)."""


def generate(kind: str, params: dict) -> Mesh:
    """The mesh of a scene generator with its counts (:mod:`femmech.fe.generators`)."""
    if kind == "grid_frame":
        return grid_frame(**params)
    if kind == "members":
        return members_frame(**params)
    if kind == "rectangular_plate":
        nx, ny = params["divisions"]
        return rectangular_plate(params["a"], params["b"], nx, ny, params["kind"])
    if kind == "box":
        nx, ny, nz = params["divisions"]
        return box(params["length"], params["width"], params["height"], nx, ny, nz,
                   params["end_plates"], params["kind"])
    raise ValueError(f"unknown generator {kind!r}")


def _fits(kind: str, params: dict, refined: bool = False) -> None:
    """ValueError if the mesh of these counts (``refined``: with the divisions doubled,
    the h/2 mesh of the shell check) would need more memory than this machine has
    (:func:`femmech.scene.memory.memory_problem`); nothing is built."""
    if refined:
        params = {**params, "divisions": tuple(2 * n for n in params["divisions"])}
    problem = memory_problem(**generator_counts(kind, params))
    if problem is not None:
        raise ValueError(problem + (" for the h/2 mesh of the shell check" if refined
                                    else ""))


def _built(kind: str, params: dict) -> Mesh:
    """:func:`generate` after the memory check (:func:`_fits`)."""
    _fits(kind, params)
    return generate(kind, params)


def sized_params(kind: str, params: dict, target_error: float, f_max: float, beams: dict,
                 shells: dict) -> dict:
    """The generator's parameters with counts for the band up to ``f_max`` (Hz).

    ``beams``: group → BeamProperty, ``shells``: group → ShellProperty of the part.
    Beam generators: elements per member (:func:`femmech.fe.sizing.sized_members`,
    :func:`~femmech.fe.sizing.grid_subdivisions`); shell generators: the smallest
    :func:`~femmech.fe.sizing.shell_size` over the part's shell groups, as counts per side.
    """
    if kind == "members":
        members = sizing.sized_members(params["joints"], params["members"], beams, f_max,
                                       target_error)
        return {**params, "members": tuple(members)}
    if kind == "grid_frame":
        k = sizing.grid_subdivisions(params["bays"], params["size"], beams, f_max,
                                     target_error)
        return {**params, "subdivisions": k}
    if not shells:
        raise ValueError(f"mesh = 'auto' with generator {kind!r} needs [shells.<group>]")
    h = min(sizing.shell_size(p.thickness, p.material, f_max, target_error, params["kind"])
            for p in shells.values())
    return {**params, "divisions": sizing.shell_divisions(
        [params[s] for s in _SHELL_SIDES[kind]], h)}


def _coarse_params(kind: str, params: dict) -> dict:
    """First mesh for a band given as ``n_modes``: 2 elements per beam member, shells
    with :data:`COARSE_ELEMENTS` along the longest side."""
    if kind == "members":
        return {**params, "members": tuple({**m, "divisions": 2, "element_size": None}
                                           for m in params["members"])}
    if kind == "grid_frame":
        return {**params, "subdivisions": 2}
    sides = [params[s] for s in _SHELL_SIDES[kind]]
    return {**params, "divisions": tuple(max(1, math.ceil(COARSE_ELEMENTS * s / max(sides)))
                                         for s in sides)}


def planned_mesh(spec, beams: dict, shells: dict) -> tuple[Mesh, bool]:
    """The mesh of a ``mesh = "auto"`` part as far as it is known without solving, and
    whether it is final.

    A beam part with a band given as ``f_max_hz`` is sized by the wave rule alone: its
    mesh is final. Otherwise (a band given as ``n_modes``, or a shell part, whose sized
    mesh is checked by an error estimate) sizing needs eigen solves, which planning
    never runs: the mesh returned (the wave-rule mesh of a shell part, the coarse first
    mesh of an ``n_modes`` band) has the part's groups and node sets for the checks of
    planning, and :func:`auto_mesh` sizes the final one when the model is first needed.
    ValueError as in :func:`auto_mesh`.
    """
    kind, value = spec.band
    try:
        if kind == "f_max_hz":
            params = sized_params(spec.generator, spec.params, spec.target_error, value,
                                  beams, shells)
        else:
            params = _coarse_params(spec.generator, spec.params)
        final = kind == "f_max_hz" and spec.generator not in _SHELL_SIDES
        return _built(spec.generator, params), final
    except ValueError as exc:
        raise ValueError(f"mesh = 'auto' (target_error {spec.target_error:g}, band"
                         f" {kind} = {value:g}): {exc}; raise target_error or narrow the"
                         " band") from None


def auto_mesh(spec, beams: dict, shells: dict, model_of) -> Mesh:
    """The mesh of a ``mesh = "auto"`` part (:class:`femmech.scene.mesh.MeshSpec`).

    ``model_of(mesh)`` builds the part's FE model (used only for a band given as
    ``n_modes``: the frequency of mode ``n_modes``, rigid-body modes counted, sets f_max).
    ValueError naming ``target_error`` and the band when the sized mesh exceeds the
    generators' limits.
    """
    kind, value = spec.band
    try:
        if kind == "f_max_hz":
            params = sized_params(spec.generator, spec.params, spec.target_error, value,
                                  beams, shells)
            f_max = value
        else:
            params, f_max = _sized_for_modes(spec, int(value), beams, shells, model_of)
            if f_max is None:  # only rigid-body modes asked for: any mesh resolves them
                return _built(spec.generator, params)
        if spec.generator in _SHELL_SIDES:
            params = _checked(spec, params, f_max, model_of)
        return _built(spec.generator, params)
    except ValueError as exc:
        raise ValueError(f"mesh = 'auto' (target_error {spec.target_error:g}, band"
                         f" {kind} = {value:g}): {exc}; raise target_error or narrow the"
                         " band") from None


def _sized_for_modes(spec, n_modes: int, beams: dict, shells: dict, model_of):
    """Counts for a band given as ``n_modes``: (params, f_max in Hz or None)."""
    from femmech.analysis.modes import modes  # only a sized mesh solves (not check)

    params = _coarse_params(spec.generator, spec.params)
    f = None
    for _ in range(MAX_ROUNDS):
        f = float(modes(model_of(_built(spec.generator, params)),
                        n_modes=n_modes).freq_hz[-1])
        if not f > 0.0:
            return params, None
        new = sized_params(spec.generator, spec.params, spec.target_error, f, beams, shells)
        if new == params:
            break
        params = new
    return params, f


def _checked(spec, params: dict, f_max: float, model_of) -> dict:
    """Shell counts whose estimated discretisation error over (0, f_max] meets the target:
    the estimate of the sized mesh scales the counts where it exceeds it (module
    docstring); flagged (untrusted) estimates count as twice the target."""
    from femmech.analysis.discretisation import discretisation_error  # solves: not in check

    target = spec.target_error
    for attempt in range(MAX_CORRECTIONS + 1):
        _fits(spec.generator, params, refined=True)
        est = discretisation_error(model_of(_built(spec.generator, params)),
                                   band_hz=(0.0, f_max * (1 + 1e-9)))
        worst = est.max_error()
        if worst <= target:
            return params
        if attempt == MAX_CORRECTIONS:
            break
        ratio = 2.0 if not np.isfinite(worst) else worst / target
        scale = SAFETY * ratio ** (1.0 / est.rate)
        params = {**params, "divisions": tuple(math.ceil(n * scale)
                                               for n in params["divisions"])}
    warnings.warn(ModelWarning(
        f"mesh = 'auto': the estimated discretisation error {worst:.3g} still exceeds"
        f" target_error {target:g} after {MAX_CORRECTIONS} refinements (divisions"
        f" {params['divisions']}); the report's estimate column shows it per mode"),
        stacklevel=3)
    return params
