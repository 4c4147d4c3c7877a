"""Scene keys of a part's mesh: a mesh file or a generator (``grid_frame``, ``members``,
``rectangular_plate``, ``box``), or ``mesh = "auto"``: a generator whose divisions are
sized for the band of the scene's analyses (:mod:`femmech.fe.sizing`, built by
:mod:`femmech.scene.auto_mesh`).

The sizes a generator would produce are computed from the scene's numbers and checked
against :data:`femmech.fe.mesh.MAX_NODES` and ``MAX_CELLS`` before anything is allocated;
members may not overlap and their elements may not be shorter than the near-node distance
of :mod:`femmech.fe.checks`.

Stage 8 (scene), reading: uses scene.reader, scene.units and fe (generators' sizes,
mesh checks); nothing is built here.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path

from femmech.errors import SceneError
from femmech.fe.checks import NEAR_NODE_TOL
from femmech.fe.generators import (
    MAX_ELEMENTS_PER_MEMBER,
    box_size,
    grid_frame_size,
    rectangular_plate_size,
)
from femmech.fe.mesh import MAX_CELLS, MAX_NODES, NODES_PER_CELL
from femmech.scene.reader import Reader, file_path, one_line, show
from femmech.scene.units import FREQUENCY, LENGTH

GENERATORS = ("grid_frame", "members", "rectangular_plate", "box")
MAX_SUBDIVISIONS = 10_000
"""Most elements per member of the ``grid_frame`` generator (``subdivisions``)."""
MAX_BAYS = 1000
"""Most bays along one axis of the ``grid_frame`` generator."""
_GENERATOR_KEYS = {"grid_frame": ("kind", "bays", "size", "subdivisions"),
                   "members": ("kind", "joints", "members", "node_sets"),
                   "rectangular_plate": ("kind", "a", "b", "divisions", "element"),
                   "box": ("kind", "length", "width", "height", "divisions", "end_plates",
                           "element")}
SHELL_GENERATOR_ELEMENTS = ("quad", "triangle", "quad9", "triangle6")
"""Cell kinds the shell generators make from a scene (the kinds with measured sizing
constants, :data:`femmech.fe.sizing.SHELL_BENDING`)."""
AUTO_TARGET_ERROR = 1e-3
"""Default ``target_error`` of ``mesh = "auto"``."""


@dataclass(frozen=True)
class MeshSpec:
    """A mesh file (absolute path) or a generator with its parameters (SI); nodes closer
    than ``merge_tol`` (m) are merged (:meth:`femmech.Mesh.merge_nodes`)."""

    file: str | None = None
    generator: str | None = None
    params: dict = field(default_factory=dict)
    edge_node_groups: tuple = ()
    where: str = field(default="", compare=False)
    merge_tol: float | None = None
    # mesh = "auto" (outside the dataclass comparison, so that the reduction cache keys of
    # other parts stay as they were; femmech.scene.build.reduction_key_data adds them for
    # auto parts): the target and the band to size for, ("f_max_hz", f) or ("n_modes", n),
    # filled in from the part's f_max_hz or the analyses (resolve_auto_band)
    auto: bool = field(default=False, compare=False)
    target_error: float | None = field(default=None, compare=False)
    band: tuple | None = field(default=None, compare=False)


def read_mesh_spec(r: Reader, base: Path) -> MeshSpec:
    """The mesh of a part: a file (``mesh``) or a generator table, sizes checked."""
    auto = r.has("mesh") and r.get("mesh") == "auto"
    if auto and not r.has("generator"):
        raise r.error("mesh", "mesh = 'auto' sizes a generator: add [generator] (kind"
                              " members, grid_frame, rectangular_plate or box)")
    if not auto and r.has("mesh") == r.has("generator"):
        raise r.error(None, "give exactly one of mesh (a file) and generator (a table)")
    for key in ("target_error", "f_max_hz"):
        if r.has(key) and not auto:
            raise r.error(key, "only with mesh = 'auto' (a generator sized for a band)")
    edges = r.strings("edge_node_groups", ())
    merge = r.number("merge_nodes", LENGTH, None, positive=True)
    if r.has("mesh") and not auto:
        file = file_path(base, r.string("mesh"))
        try:
            found = file.is_file()
        except (OSError, ValueError):  # a name too long or with a NUL byte
            found = False
        if not found:
            raise r.error("mesh", f"file not found: {one_line(str(file))!r}")
        return MeshSpec(str(file), None, {}, edges, r.where, merge)
    g = r.table("generator")
    g.expect(*dict.fromkeys(k for keys in _GENERATOR_KEYS.values() for k in keys))
    kind = g.string("kind", choices=GENERATORS)
    g.expect(*_GENERATOR_KEYS[kind], context=f"for kind = {kind!r}")
    if auto:
        _no_divisions(g, kind)
    readers = {"grid_frame": _grid_frame, "members": _members, "rectangular_plate": _plate,
               "box": _box}
    params = _members(g, auto) if kind == "members" else readers[kind](g)
    if not auto:
        if params.get("divisions", ()) is None:
            raise g.error("divisions", "missing (required) without mesh = 'auto'")
        return MeshSpec(None, kind, params, edges, g.where, merge)
    target = r.number("target_error", None, AUTO_TARGET_ERROR, positive=True)
    if not 1e-6 <= target <= 0.1:
        raise r.error("target_error", f"expected a relative frequency error in [1e-6, 0.1],"
                                      f" got {target:g}")
    f_max = r.number("f_max_hz", FREQUENCY, None, positive=True)
    band = ("f_max_hz", f_max) if f_max is not None else None
    return MeshSpec(None, kind, params, edges, g.where, merge, True, target, band)


_DIVISION_KEYS = {"grid_frame": ("subdivisions",), "rectangular_plate": ("divisions",),
                  "box": ("divisions",)}


def _no_divisions(g: Reader, kind: str) -> None:
    """With ``mesh = "auto"`` the element counts are computed: refuse given ones."""
    tables = g.tables("members") if kind == "members" and g.has("members") else [g]
    for t in tables:
        for key in _DIVISION_KEYS.get(kind, ("element_size", "divisions")):
            if t.has(key):
                raise t.error(key, "mesh = 'auto' computes the element counts; leave this out")


def _lengths(g: Reader, keys) -> dict:
    return {k: g.number(k, LENGTH, positive=True) for k in keys}


def _shell_divisions(g: Reader, n: int, names: str) -> tuple | None:
    """``divisions`` = n element counts (``None`` when absent: mesh = "auto")."""
    if not g.has("divisions"):
        return None
    value = g.get("divisions")
    if not (isinstance(value, list) and len(value) == n and all(
            isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= MAX_SUBDIVISIONS
            for v in value)):
        raise g.error("divisions", f"expected {n} integers {names} in 1..{MAX_SUBDIVISIONS}"
                                   f" (limit MAX_SUBDIVISIONS), got {show(value)}")
    return tuple(value)


def _plate(g: Reader) -> dict:
    """Parameters of :func:`femmech.fe.generators.rectangular_plate` (``divisions`` =
    [nx, ny]; without it the part must have ``mesh = "auto"``)."""
    params = _lengths(g, ("a", "b"))
    params["kind"] = g.string("element", "quad", choices=SHELL_GENERATOR_ELEMENTS)
    params["divisions"] = _shell_divisions(g, 2, "[nx, ny]")
    if params["divisions"] is not None:
        _check_counts(g, "divisions", *rectangular_plate_size(*params["divisions"],
                                                              params["kind"]))
    return params


def _box(g: Reader) -> dict:
    """Parameters of :func:`femmech.fe.generators.box` (``divisions`` = [nx, ny, nz])."""
    params = _lengths(g, ("length", "width", "height"))
    params["kind"] = g.string("element", "quad", choices=SHELL_GENERATOR_ELEMENTS)
    params["end_plates"] = g.boolean("end_plates", True)
    params["divisions"] = _shell_divisions(g, 3, "[nx, ny, nz]")
    if params["divisions"] is not None:
        _check_counts(g, "divisions", *box_size(*params["divisions"], params["end_plates"],
                                                params["kind"]))
    return params


def _grid_frame(g: Reader) -> dict:
    """Parameters of :func:`femmech.fe.generators.grid_frame`, sizes checked before use."""
    bays = g.get("bays")
    if not (isinstance(bays, list) and len(bays) == 3 and all(
            isinstance(b, int) and not isinstance(b, bool) and 0 <= b <= MAX_BAYS
            for b in bays) and any(bays)):
        raise g.error("bays", f"expected three integers in 0..{MAX_BAYS} (limit MAX_BAYS),"
                              f" not all zero, got {bays!r}")
    params = {"bays": tuple(bays), "size": g.vector("size", (LENGTH,) * 3),
              "subdivisions": g.integer("subdivisions", 1, minimum=1,
                                        maximum=MAX_SUBDIVISIONS, limit="MAX_SUBDIVISIONS")}
    if min(params["size"]) <= 0:
        raise g.error("size", f"expected three positive lengths, got {params['size']}")
    _check_counts(g, "bays", *grid_frame_size(bays))
    _check_counts(g, "subdivisions", *grid_frame_size(bays, params["subdivisions"]))
    return params


def generator_counts(kind: str, params: dict) -> dict:
    """What a generator with its counts would make, for
    :func:`femmech.scene.memory.memory_problem` (keyword arguments: ``n_nodes``, ``cells``
    (nodes per cell → cells), ``dimension``, ``n_joints``), computed without building it."""
    if kind == "grid_frame":
        n_nodes, n_cells = grid_frame_size(params["bays"], params["subdivisions"])
        dimension = max(1, sum(b > 0 for b in params["bays"]))
        return {"n_nodes": n_nodes, "cells": {2: n_cells}, "dimension": dimension,
                "n_joints": grid_frame_size(params["bays"])[0]}
    if kind == "members":
        n_cells = n_segments = 0
        for m in params["members"]:
            chain = list(m["chain"])
            for a, b in zip(chain[:-1], chain[1:], strict=True):
                length = math.dist(params["joints"][a], params["joints"][b])
                k = m.get("divisions") or length / m["element_size"]
                n_cells, n_segments = n_cells + max(1, round(k)), n_segments + 1
        return {"n_nodes": len(params["joints"]) + n_cells - n_segments,
                "cells": {2: n_cells}, "dimension": 1, "n_joints": None}
    size = rectangular_plate_size if kind == "rectangular_plate" else box_size
    extra = () if kind == "rectangular_plate" else (params["end_plates"],)
    n_nodes, n_cells = size(*params["divisions"], *extra, params["kind"])
    return {"n_nodes": n_nodes, "cells": {NODES_PER_CELL[params["kind"]]: n_cells},
            "dimension": 2, "n_joints": None}


def _check_counts(r: Reader, key: str, n_nodes: int, n_elements: int) -> None:
    if n_nodes > MAX_NODES:
        raise r.error(key, f"the mesh would have {n_nodes} nodes; at most {MAX_NODES}"
                           " (limit MAX_NODES)")
    if n_elements > MAX_CELLS:
        raise r.error(key, f"the mesh would have {n_elements} elements; at most {MAX_CELLS}"
                           " (limit MAX_CELLS)")


def _members(g: Reader, auto: bool = False) -> dict:
    raw = g.get("joints")
    if not isinstance(raw, dict) or not raw:
        raise g.error("joints", f"expected a table {{name = [x, y, z]}}, got {show(raw)}")
    joints = {}
    for name, xyz in raw.items():
        if not isinstance(xyz, list) or len(xyz) != 3:
            raise g.error(f"joints.{name}", f"expected three coordinates, got {show(xyz)}")
        joints[name] = tuple(g.convert(f"joints.{name}", v, LENGTH) for v in xyz)
    lo = [min(p[i] for p in joints.values()) for i in range(3)]
    hi = [max(p[i] for p in joints.values()) for i in range(3)]
    frame = _Frame(joints, NEAR_NODE_TOL * math.dist(lo, hi), {})
    members, n_nodes, n_elements = [], len(joints), 0
    for i, m in enumerate(g.tables("members")):
        m.expect("group", "chain", "element_size", "divisions")
        chain = m.strings("chain")
        bad = [j for j in chain if j not in joints]
        if len(chain) < 2 or bad:
            raise m.error("chain", f"expected >= 2 joint names of [joints], got"
                                   f" {show(list(chain))}")
        size = m.number("element_size", LENGTH, None, positive=True)
        divisions = m.integer("divisions", None, minimum=1, maximum=MAX_ELEMENTS_PER_MEMBER,
                              limit="MAX_ELEMENTS_PER_MEMBER")
        if (size is None) == (divisions is None) and not auto:
            raise m.error(None, "give exactly one of element_size and divisions")
        divisions = 1 if auto else divisions  # auto: sized later; overlaps checked here
        members.append({"group": m.string("group"), "chain": chain, "element_size": size,
                        "divisions": divisions})
        for k in _member_divisions(m, i, frame, chain, size, divisions):
            n_nodes, n_elements = n_nodes + k - 1, n_elements + k
        _check_counts(m, "element_size" if size else "divisions", n_nodes, n_elements)
    if not members:
        raise g.error("members", "missing (required): [[...members]] with group and chain")
    node_sets, raw_sets = {}, g.get("node_sets", {})
    if not isinstance(raw_sets, dict):
        raise g.error("node_sets", f"expected a table {{name = [joints]}}, got {show(raw_sets)}")
    for name, value in raw_sets.items():
        if not isinstance(value, list) or not all(isinstance(v, str) and v in joints
                                                  for v in value):
            raise g.error(f"node_sets.{name}", f"expected a list of joint names, got"
                                               f" {show(value)}")
        node_sets[name] = tuple(value)
    return {"joints": joints, "members": tuple(members), "node_sets": node_sets}


@dataclass
class _Frame:
    """Joints (m) of a ``members`` generator, the shortest element length allowed (m) and
    the segments (joint pairs) taken so far → index of their member."""

    joints: dict
    shortest: float
    segments: dict


def _member_divisions(m: Reader, i: int, frame: _Frame, chain, size, divisions) -> list[int]:
    """Elements of each straight member of a chain (as :func:`members_frame` divides).

    Refused: a segment (pair of joints) that another member or the chain itself already
    took (the two would overlap, every interior node doubled), and elements shorter than
    the near-node distance of :mod:`femmech.fe.checks` (``NEAR_NODE_TOL`` times the frame's
    size: such nodes could not be told apart from nearly coincident ones, and the stiffness
    contrast would make the model ill-conditioned).
    """
    out = []
    for a, b in zip(chain[:-1], chain[1:], strict=True):
        length = math.dist(frame.joints[a], frame.joints[b])
        if not (math.isfinite(length) and length > 0.0):
            raise m.error("chain", f"joints {a!r} and {b!r} are {length:g} m apart")
        segment = (min(a, b), max(a, b))
        if segment in frame.segments:
            raise m.error("chain", f"joints {a!r} and {b!r} are already joined by"
                          f" members[{frame.segments[segment]}]; members may not overlap")
        frame.segments[segment] = i
        k = divisions if divisions is not None else length / size
        key = "divisions" if divisions is not None else "element_size"
        if not (math.isfinite(k) and round(k) <= MAX_ELEMENTS_PER_MEMBER):
            raise m.error(key, f"{k:.6g} elements from {a!r} to {b!r} (length {length:.6g}"
                          f" m); at most {MAX_ELEMENTS_PER_MEMBER} per member (limit"
                          " MAX_ELEMENTS_PER_MEMBER)")
        k = max(1, round(k))
        if length / k < frame.shortest:
            raise m.error(key, f"elements of {length / k:.3g} m from {a!r} to {b!r}; at least"
                          f" {frame.shortest:.3g} m ({NEAR_NODE_TOL:g} of the frame's size,"
                          " the near-node distance of femmech.fe.checks)")
        out.append(k)
    return out


def resolve_auto_band(parts: dict, analyses, file: str) -> dict:
    """The parts with the band of each ``mesh = "auto"`` filled in (:attr:`MeshSpec.band`).

    In order: the part's ``f_max_hz``; the ``[analyses.modes]`` of the part (the top of
    ``band_hz``, else its ``n_modes``: the frequency of the last mode, found on the
    sized mesh itself); the part's reduction (``f_max_hz``, ``cutoff_hz``, else its
    ``n_modes``). SceneError at the part's ``mesh`` when none gives a band. The band then
    joins the reduction's cache key with the rest of the mesh spec.
    """
    modes = getattr(analyses, "modes", None)
    out = {}
    for name, part in parts.items():
        spec = part.mesh
        if not spec.auto or spec.band is not None:
            out[name] = part
            continue
        band = None
        if modes is not None and modes.part == name:
            band = (("f_max_hz", modes.band_hz[1]) if modes.band_hz is not None
                    else ("n_modes", modes.n_modes))
        elif part.reduction is not None and part.reduction.method == "craig_bampton":
            r = part.reduction
            f = r.f_max_hz if r.f_max_hz is not None else r.cutoff_hz
            band = ("f_max_hz", f) if f is not None else ("n_modes", r.n_modes)
        if band is None or band[1] is None or band[1] == 0:
            raise SceneError(one_line(
                f"{file}: [{part.where}] mesh: mesh = 'auto' needs a band to size for: give"
                " f_max_hz, an [analyses.modes] of this part (n_modes or band_hz) or a"
                " craig_bampton reduction"))
        out[name] = dataclasses.replace(part, mesh=dataclasses.replace(spec, band=band))
    return out
