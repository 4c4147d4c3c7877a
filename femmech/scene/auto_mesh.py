"""Generated meshes of scene parts, and ``mesh = "auto"``: element counts sized for a band.

:func:`generate` builds any generator of :mod:`femmech.scene.mesh` from its parameters
(counts given). :func:`auto_mesh` picks the counts of a ``mesh = "auto"`` part from its
band and ``target_error`` (:mod:`femmech.fe.sizing`: elements per half-wavelength of the
shortest wave at f_max for beams, a shell size for shells). A band given as ``n_modes``
is turned into a frequency on the mesh itself: a coarse mesh gives a first (high)
estimate of the last mode's frequency, the mesh sized for it a better one, until the
counts no longer change (at most :data:`MAX_ROUNDS` solves).

Stage 8 (scene), building: uses fe (generators, sizing) and analysis.modes.
"""

from __future__ import annotations

import math

from femmech.analysis.modes import modes
from femmech.fe import sizing
from femmech.fe.generators import box, grid_frame, members_frame, rectangular_plate
from femmech.fe.mesh import Mesh

MAX_ROUNDS = 4
"""Most sizing rounds (eigen solves) for a band given as ``n_modes``."""
COARSE_ELEMENTS = 8
"""Elements along the longest side of a shell part's first (coarse) mesh; beam members
start with 2 elements each."""
_SHELL_SIDES = {"rectangular_plate": ("a", "b"), "box": ("length", "width", "height")}


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
            return generate(spec.generator, sized_params(
                spec.generator, spec.params, spec.target_error, value, beams, shells))
        params = _coarse_params(spec.generator, spec.params)
        mesh = generate(spec.generator, params)
        for _ in range(MAX_ROUNDS):
            f = float(modes(model_of(mesh), n_modes=int(value)).freq_hz[-1])
            if not f > 0.0:  # only rigid-body modes asked for: any mesh resolves them
                return mesh
            new = sized_params(spec.generator, spec.params, spec.target_error, f, beams,
                               shells)
            if new == params:
                break
            params, mesh = new, generate(spec.generator, new)
        return mesh
    except ValueError as exc:
        raise ValueError(f"mesh = 'auto' (target_error {spec.target_error:g}, band"
                         f" {kind} = {value:g}): {exc}; raise target_error or narrow the"
                         " band") from None
