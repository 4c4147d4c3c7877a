"""Scene keys of a part's mesh: a mesh file or a generator (``grid_frame``, ``members``).

The sizes a generator would produce are computed from the scene's numbers and checked
against :data:`femmech.fe.mesh.MAX_NODES` and ``MAX_CELLS`` before anything is allocated;
members may not overlap and their elements may not be shorter than the near-node distance
of :mod:`femmech.fe.checks`.

Stage 8 (scene), reading: uses scene.reader, scene.units and fe (generators' sizes,
mesh checks); nothing is built here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from femmech.fe.checks import NEAR_NODE_TOL
from femmech.fe.generators import MAX_ELEMENTS_PER_MEMBER, grid_frame_size
from femmech.fe.mesh import MAX_CELLS, MAX_NODES
from femmech.scene.reader import Reader, one_line, show
from femmech.scene.units import LENGTH

GENERATORS = ("grid_frame", "members")
MAX_SUBDIVISIONS = 10_000
"""Most elements per member of the ``grid_frame`` generator (``subdivisions``)."""
MAX_BAYS = 1000
"""Most bays along one axis of the ``grid_frame`` generator."""
_GENERATOR_KEYS = {"grid_frame": ("kind", "bays", "size", "subdivisions"),
                   "members": ("kind", "joints", "members", "node_sets")}


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


def read_mesh_spec(r: Reader, base: Path) -> MeshSpec:
    """The mesh of a part: a file (``mesh``) or a generator table, sizes checked."""
    if r.has("mesh") == r.has("generator"):
        raise r.error(None, "give exactly one of mesh (a file) and generator (a table)")
    edges = r.strings("edge_node_groups", ())
    merge = r.number("merge_nodes", LENGTH, None, positive=True)
    if r.has("mesh"):
        file = base / r.string("mesh")
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
    params = _grid_frame(g) if kind == "grid_frame" else _members(g)
    return MeshSpec(None, kind, params, edges, g.where, merge)


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


def _check_counts(r: Reader, key: str, n_nodes: int, n_elements: int) -> None:
    if n_nodes > MAX_NODES:
        raise r.error(key, f"the mesh would have {n_nodes} nodes; at most {MAX_NODES}"
                           " (limit MAX_NODES)")
    if n_elements > MAX_CELLS:
        raise r.error(key, f"the mesh would have {n_elements} elements; at most {MAX_CELLS}"
                           " (limit MAX_CELLS)")


def _members(g: Reader) -> dict:
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
        if (size is None) == (divisions is None):
            raise m.error(None, "give exactly one of element_size and divisions")
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
