"""Scene files: a machine and the analyses wanted, described in one TOML file.

A scene maps onto the Python API (the primary interface): parts → :func:`femmech.build_model`
(+ :func:`femmech.reduction.craig_bampton` / ``guyan``), mechanisms →
:func:`femmech.mechanisms.rheolinear`, mounts → :class:`femmech.coupling.Mount`, analyses →
:mod:`femmech.analysis`. :func:`load_scene` reads and validates a file into frozen
dataclasses (:class:`Scene`); :meth:`Scene.from_dict` does the same for a dict built in
Python. Checks that need the meshes (group names, node indices) are in
:func:`femmech.scene_build.prepare`; :func:`femmech.scene_run.run_scene` computes.

Values are plain numbers in SI units or strings with units (``"210 GPa"``, see
:mod:`femmech.units`). The format is described in ``docs/scenes.md``. Every error is a
one-line :class:`~femmech.errors.SceneError` naming the file, the key and the expectation.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from femmech.errors import SceneError
from femmech.scene_analyses import Analyses, read_analyses
from femmech.scene_reader import Reader
from femmech.units import (
    AREA,
    DENSITY,
    DIMENSIONLESS,
    INERTIA,
    LENGTH,
    MASS,
    PRESSURE,
    ROT_STIFFNESS,
    SECOND_MOMENT,
    STIFFNESS,
)

SECTION_SHAPES = {
    "rectangle": (("width", LENGTH), ("height", LENGTH)),
    "circle": (("diameter", LENGTH),),
    "tube": (("outer_diameter", LENGTH), ("inner_diameter", LENGTH)),
    "i_section": (("height", LENGTH), ("width", LENGTH), ("web", LENGTH), ("flange", LENGTH)),
    "rectangular_hollow": (("width", LENGTH), ("height", LENGTH), ("wall", LENGTH)),
    "general": (("A", AREA), ("Iy", SECOND_MOMENT), ("Iz", SECOND_MOMENT),
                ("J", SECOND_MOMENT)),
}
"""Section shapes of :mod:`femmech.sections` and their required dimensions."""
GENERAL_OPTIONAL = (("Asy", AREA), ("Asz", AREA), ("Ip", SECOND_MOMENT))
GENERATORS = ("grid_frame", "members")
REDUCTIONS = ("guyan", "craig_bampton")
_SPRING_KINDS = (STIFFNESS,) * 3 + (ROT_STIFFNESS,) * 3


@dataclass(frozen=True)
class MaterialSpec:
    """Isotropic material: E (Pa), rho (kg/m³), nu or G (Pa)."""

    name: str
    E: float
    rho: float
    nu: float | None = None
    G: float | None = None


@dataclass(frozen=True)
class SectionSpec:
    """Beam property of a cell group: shape, dimensions (m or m², m⁴), material name."""

    group: str
    shape: str
    dims: tuple
    material: str
    orientation: tuple | None = None
    shear: bool = True
    rotary_inertia: bool = True
    where: str = field(default="", compare=False)


@dataclass(frozen=True)
class ShellSpec:
    """Shell property of a cell group: thickness (m) and material name."""

    group: str
    thickness: float
    material: str
    where: str = field(default="", compare=False)


@dataclass(frozen=True)
class SolidSpec:
    """Solid property of a cell group: material name."""

    group: str
    material: str
    where: str = field(default="", compare=False)


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


@dataclass(frozen=True)
class ItemSpec:
    """A lumped item or constraint: ``kind`` (support, mass, spring, rigid_link,
    interpolating_link) with its fields as in the API dataclass of that name."""

    kind: str
    values: dict
    where: str = field(default="", compare=False)


@dataclass(frozen=True)
class InterfaceSpec:
    """Interface nodes (group, index or indices) and components."""

    nodes: object
    dofs: object = "all"
    where: str = field(default="", compare=False)


@dataclass(frozen=True)
class ReductionSpec:
    """Reduction of a part: method and its mode selection (see craig_bampton)."""

    method: str
    interface: tuple
    n_modes: int | None = None
    cutoff_hz: float | None = None
    f_max_hz: float | None = None
    residual_vectors: bool = True
    where: str = field(default="", compare=False)


@dataclass(frozen=True)
class PartSpec:
    """One FE part: mesh, properties per group, lumped items, constraints, reduction."""

    name: str
    mesh: MeshSpec
    sections: tuple = ()
    shells: tuple = ()
    solids: tuple = ()
    items: tuple = ()
    reduction: ReductionSpec | None = None
    where: str = field(default="", compare=False)

    def materials_used(self) -> list[str]:
        """Names of the materials the part refers to, sorted."""
        return sorted({p.material for p in (*self.sections, *self.shells, *self.solids)})


@dataclass(frozen=True)
class Scene:
    """A validated scene (all values SI). Build with :func:`load_scene` or :meth:`from_dict`.

    Attributes
    ----------
    name, description : str
    file : str
        Name of the scene file (for messages), ``"<dict>"`` when built from a dict.
    base_dir : Path
        Folder against which relative file names are resolved.
    materials : dict[str, MaterialSpec]
    parts : dict[str, PartSpec]
    mechanisms : dict[str, femmech.scene_machine.MechanismSpec]
    mounts : tuple of femmech.scene_machine.MountSpec
    analyses : Analyses
    """

    name: str
    description: str
    file: str
    base_dir: Path
    materials: dict
    parts: dict
    mechanisms: dict
    mounts: tuple
    analyses: Analyses

    @classmethod
    def from_dict(cls, data: dict, base_dir=".", file: str = "<dict>") -> Scene:
        """Validate a scene given as a dict (the TOML structure); relative paths are
        resolved against ``base_dir``."""
        from femmech.scene_machine import read_mechanisms, read_mounts

        root = Reader(data, "", file)
        base = Path(base_dir).resolve()
        head = root.child("scene", root.get("scene", {}))
        name = head.string("name", "scene")
        description = head.string("description", "")
        head.finish()
        materials = {n: _material(n, r) for n, r in root.named_tables("materials").items()}
        parts = {n: _part(n, r, base, materials) for n, r in root.named_tables("parts").items()}
        mechanisms = read_mechanisms(root, base)
        mounts = read_mounts(root, parts, mechanisms)
        analyses = read_analyses(root.child("analyses", root.get("analyses", {})), parts,
                                 mechanisms, bool(mounts))
        root.finish()
        if not parts and not mechanisms:
            raise root.error(None, "the scene has neither [parts] nor [mechanisms]")
        return cls(name, description, file, base, materials, parts, mechanisms, mounts,
                   analyses)


def load_scene(path) -> Scene:
    """Read and validate a scene file (TOML); raises SceneError (one line) when invalid."""
    path = Path(path)
    if not path.is_file():
        raise SceneError(f"{path}: scene file not found")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise SceneError(f"{path.name}: not valid TOML ({exc})") from None
    return Scene.from_dict(data, path.parent, path.name)


def _material(name: str, r: Reader) -> MaterialSpec:
    E = r.number("E", PRESSURE, positive=True)
    rho = r.number("rho", DENSITY, non_negative=True)
    nu = r.number("nu", DIMENSIONLESS, None)
    G = r.number("G", PRESSURE, None, positive=True)
    r.finish()
    if (nu is None) == (G is None):
        raise r.error(None, "give exactly one of nu and G")
    if nu is not None and not -1.0 < nu < 0.5:
        raise r.error("nu", f"expected a Poisson ratio in (-1, 0.5), got {nu}")
    return MaterialSpec(name, E, rho, nu, G)


def _material_name(r: Reader, materials: dict) -> str:
    name = r.string("material")
    if name not in materials:
        raise r.error("material", f"expected one of the [materials] {sorted(materials)},"
                                  f" got {name!r}")
    return name


def _section(group: str, r: Reader, materials: dict) -> SectionSpec:
    shape = r.string("section", choices=SECTION_SHAPES)
    dims = [(key, r.number(key, kind, positive=True)) for key, kind in SECTION_SHAPES[shape]]
    if shape == "general":
        dims += [(key, r.number(key, kind, positive=True)) for key, kind in GENERAL_OPTIONAL
                 if r.has(key)]
    material = _material_name(r, materials)
    orientation = r.vector("orientation", (DIMENSIONLESS,) * 3, None)
    spec = SectionSpec(group, shape, tuple(dims), material, orientation,
                       r.boolean("shear", True), r.boolean("rotary_inertia", True), r.where)
    r.finish()
    return spec


def _mesh(r: Reader, base: Path) -> MeshSpec:
    if r.has("mesh") == r.has("generator"):
        raise r.error(None, "give exactly one of mesh (a file) and generator (a table)")
    edges = r.strings("edge_node_groups", ())
    merge = r.number("merge_nodes", LENGTH, None, positive=True)
    if r.has("mesh"):
        file = base / r.string("mesh")
        if not file.is_file():
            raise r.error("mesh", f"file not found: {file}")
        return MeshSpec(str(file), None, {}, edges, r.where, merge)
    g = r.child("generator", r.get("generator"))
    kind = g.string("kind", choices=GENERATORS)
    if kind == "grid_frame":
        bays = g.get("bays")
        if not (isinstance(bays, list) and len(bays) == 3 and all(
                isinstance(b, int) and not isinstance(b, bool) and 0 <= b <= 1000
                for b in bays)):
            raise g.error("bays", f"expected three integers in 0..1000, got {bays!r}")
        params = {"bays": tuple(bays), "size": g.vector("size", (LENGTH,) * 3),
                  "subdivisions": g.integer("subdivisions", 1, minimum=1)}
        if params["subdivisions"] > 10_000:
            raise g.error("subdivisions", f"expected at most 10000, got {params['subdivisions']}")
    else:
        params = _members(g)
    g.finish()
    return MeshSpec(None, kind, params, edges, g.where, merge)


def _members(g: Reader) -> dict:
    raw = g.get("joints")
    if not isinstance(raw, dict):
        raise g.error("joints", f"expected a table {{name = [x, y, z]}}, got {raw!r}")
    joints = {}
    for name, xyz in raw.items():
        if not isinstance(xyz, list) or len(xyz) != 3:
            raise g.error(f"joints.{name}", f"expected three coordinates, got {xyz!r}")
        joints[name] = tuple(g.convert(f"joints.{name}", v, LENGTH) for v in xyz)
    if not joints:
        raise g.error("joints", "missing (required): a table {name = [x, y, z]}")
    members = []
    for m in g.tables("members"):
        chain = m.strings("chain")
        bad = [j for j in chain if j not in joints]
        if len(chain) < 2 or bad:
            raise m.error("chain", f"expected >= 2 joint names of [joints], got {list(chain)}")
        size = m.number("element_size", LENGTH, None, positive=True)
        divisions = m.integer("divisions", None, minimum=1)
        if (size is None) == (divisions is None):
            raise m.error(None, "give exactly one of element_size and divisions")
        members.append({"group": m.string("group"), "chain": chain, "element_size": size,
                        "divisions": divisions})
        m.finish()
    if not members:
        raise g.error("members", "missing (required): [[...members]] with group and chain")
    node_sets, raw_sets = {}, g.get("node_sets", {})
    if not isinstance(raw_sets, dict):
        raise g.error("node_sets", f"expected a table {{name = [joints]}}, got {raw_sets!r}")
    for name, value in raw_sets.items():
        if not isinstance(value, list) or not all(isinstance(v, str) and v in joints
                                                  for v in value):
            raise g.error(f"node_sets.{name}", f"expected a list of joint names, got {value!r}")
        node_sets[name] = tuple(value)
    return {"joints": joints, "members": tuple(members), "node_sets": node_sets}


def _dofs(r: Reader, key: str, default="all"):
    from femmech.dofs import components

    value = r.get(key, default)
    try:
        if not isinstance(value, (str, list)):
            raise ValueError(f"expected a component name or a list of them, got {value!r}")
        components(value)
    except ValueError as exc:
        raise r.error(key, str(exc)) from None
    return value if isinstance(value, str) else tuple(value)


def _items(r: Reader) -> list[ItemSpec]:
    items = []
    for s in r.tables("supports"):
        items.append(ItemSpec("support", {"nodes": s.node_ref("nodes", many=True),
                                          "dofs": _dofs(s, "dofs")}, s.where))
        s.finish()
    for m in r.tables("masses"):
        items.append(ItemSpec("mass", {"node": m.node_ref("node"),
                                       "mass": m.number("mass", MASS, non_negative=True),
                                       "inertia": m.vector("inertia", (INERTIA,) * 3, None)},
                              m.where))
        m.finish()
    for s in r.tables("springs"):
        value = s.get("stiffness")
        stiffness = s.vector("stiffness", _SPRING_KINDS) if isinstance(value, list) else \
            s.number("stiffness", STIFFNESS, non_negative=True)
        node_b = s.node_ref("node_b", default=None)
        nodes = s.get("node_a")
        if isinstance(nodes, list) and node_b is None:  # one grounded spring per node
            for node in nodes:
                s.child("node_a", {"node": node}).node_ref("node")
        else:
            nodes = [s.node_ref("node_a")]
        items += [ItemSpec("spring", {"node_a": node, "node_b": node_b,
                                      "stiffness": stiffness}, s.where) for node in nodes]
        s.finish()
    for k in r.tables("rigid_links"):
        items.append(ItemSpec("rigid_link", {"master": k.node_ref("master"),
                                             "slaves": k.node_ref("slaves", many=True)},
                              k.where))
        k.finish()
    for k in r.tables("interpolating_links"):
        weights = k.get("weights", None)
        if weights is not None:
            if not isinstance(weights, list):
                raise k.error("weights", f"expected a list of numbers, got {weights!r}")
            weights = tuple(k.convert("weights", w, DIMENSIONLESS, non_negative=True)
                            for w in weights)
        items.append(ItemSpec("interpolating_link",
                              {"reference": k.node_ref("reference"),
                               "patch": k.node_ref("patch", many=True), "weights": weights},
                              k.where))
        k.finish()
    return items


def _reduction(r: Reader) -> ReductionSpec:
    from femmech.units import FREQUENCY

    method = r.string("method", choices=REDUCTIONS)
    interface = []
    for i in r.tables("interface"):
        interface.append(InterfaceSpec(i.node_ref("nodes", many=True), _dofs(i, "dofs"),
                                       i.where))
        i.finish()
    if not interface:
        raise r.error("interface", "missing (required): [[...reduction.interface]] entries"
                                   " with nodes and dofs")
    n_modes = r.integer("n_modes", None, minimum=0)
    cutoff = r.number("cutoff_hz", FREQUENCY, None, positive=True)
    f_max = r.number("f_max_hz", FREQUENCY, None, positive=True)
    given = sum(v is not None for v in (n_modes, cutoff, f_max))
    if method == "craig_bampton" and given != 1:
        raise r.error(None, "craig_bampton needs exactly one of n_modes, cutoff_hz and f_max_hz")
    if method == "guyan" and given:
        raise r.error(None, "guyan keeps no fixed-interface modes: drop n_modes, cutoff_hz"
                            " and f_max_hz")
    spec = ReductionSpec(method, tuple(interface), n_modes, cutoff, f_max,
                         r.boolean("residual_vectors", method == "craig_bampton"), r.where)
    if method == "guyan" and spec.residual_vectors:
        raise r.error("residual_vectors", "residual vectors need method = 'craig_bampton'")
    r.finish()
    return spec


def _part(name: str, r: Reader, base: Path, materials: dict) -> PartSpec:
    mesh = _mesh(r, base)
    sections = tuple(_section(g, t, materials) for g, t in r.named_tables("sections").items())
    shells, solids = [], []
    for group, t in r.named_tables("shells").items():
        shells.append(ShellSpec(group, t.number("thickness", LENGTH, positive=True),
                                _material_name(t, materials), t.where))
        t.finish()
    for group, t in r.named_tables("solids").items():
        solids.append(SolidSpec(group, _material_name(t, materials), t.where))
        t.finish()
    if not (sections or shells or solids):
        raise r.error("sections", "missing (required): give [sections.<group>] (beams),"
                                  " [shells.<group>] or [solids.<group>]")
    items = _items(r)
    reduction = _reduction(r.child("reduction", r.get("reduction"))) if r.has("reduction") \
        else None
    r.finish()
    return PartSpec(name, mesh, sections, tuple(shells), tuple(solids), tuple(items), reduction,
                    r.where)
