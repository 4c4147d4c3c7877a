"""Scene files: a machine and the analyses wanted, described in one TOML file.

A scene maps onto the Python API (the primary interface): parts → :func:`femmech.build_model`
(+ :func:`femmech.reduction.component_modes.craig_bampton` / ``guyan``), mechanisms →
:func:`femmech.mechanisms.rheolinear`, mounts → :class:`femmech.coupling.Mount`, analyses →
:mod:`femmech.analysis`. :func:`load_scene` reads and validates a file into frozen
dataclasses (:class:`Scene`); :meth:`Scene.from_dict` does the same for a dict built in
Python. Checks that need the meshes (group names, node indices) are in
:func:`femmech.scene.build.prepare`; :func:`femmech.scene.run.run_scene` computes.

Values are plain numbers in SI units or strings with units (``"210 GPa"``, see
:mod:`femmech.scene.units`). The format is described in ``docs/scenes.md``. Every error is a
one-line :class:`~femmech.errors.SceneError` naming the file, the key and the expectation.

Stage 8 (scene), validation: uses the table readers (scene.reader, .mesh, .machine,
.analyses), fe.sections and fe.dofs; the result is plain data, nothing is built.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from femmech.errors import SceneError
from femmech.fe.materials import Material
from femmech.scene.analyses import MAX_MODES, Analyses, read_analyses
from femmech.scene.chain import chain_analyses, read_chain, read_synthesis
from femmech.scene.mesh import MeshSpec, read_mesh_spec, resolve_auto_band
from femmech.scene.reader import (
    MAX_SCENE_BYTES,
    Reader,
    check_limits,
    file_path,
    one_line,
    relocate,
    show,
)
from femmech.scene.units import (
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
"""Section shapes of :mod:`femmech.fe.sections` and their required dimensions."""
GENERAL_OPTIONAL = (("Asy", AREA), ("Asz", AREA), ("Ip", SECOND_MOMENT))
REDUCTIONS = ("guyan", "craig_bampton")
_SPRING_KINDS = (STIFFNESS,) * 3 + (ROT_STIFFNESS,) * 3
_SECTION_KEYS = ("section", "material", "orientation", "orientation_plane", "shear",
                 "rotary_inertia")
_DIMENSION_KEYS = tuple(dict.fromkeys(
    key for dims in (*SECTION_SHAPES.values(), GENERAL_OPTIONAL) for key, _ in dims))
_PART_KEYS = ("mesh", "generator", "edge_node_groups", "merge_nodes", "sections", "shells",
              "solids", "supports", "masses", "springs", "rigid_links", "interpolating_links",
              "reduction", "target_error", "f_max_hz")
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
    orientation_plane: str = "xy"


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
    materials : dict[str, femmech.fe.materials.Material]
    parts : dict[str, PartSpec]
    mechanisms : dict[str, femmech.scene.machine.MechanismSpec]
    mounts : tuple of femmech.scene.machine.MountSpec
    analyses : Analyses
    chain : femmech.scene.chain.ChainSpec or None
        The table ``[chain]``: a main shaft with N identical mechanisms.
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
    chain: object = None  # femmech.scene.chain.ChainSpec of the table [chain]

    @classmethod
    def from_dict(cls, data: dict, base_dir=".", file: str = "<dict>") -> Scene:
        """Validate a scene given as a dict (the TOML structure); relative paths are
        resolved against ``base_dir``."""
        from femmech.scene.machine import read_mechanisms, read_mounts

        check_limits(data, file)
        root = Reader(data, "", file)
        root.expect("scene", "materials", "parts", "mechanisms", "mounts", "analyses",
                    "chain", "synthesis")
        base = Path(base_dir).resolve()
        head = root.table("scene", {})
        head.expect("name", "description")
        name = head.string("name", "scene")
        description = head.string("description", "")
        materials = {n: _material(n, r) for n, r in root.named_tables("materials").items()}
        parts = {n: _part(n, r, base, materials) for n, r in root.named_tables("parts").items()}
        mechanisms = read_mechanisms(root, base)
        mounts = read_mounts(root, parts, mechanisms)
        chain = read_chain(root.table("chain")) if root.has("chain") else None
        synthesis = read_synthesis(root.table("synthesis"), chain) if root.has(
            "synthesis") else None
        analyses = read_analyses(root.table("analyses", {}), parts, mechanisms, bool(mounts),
                                 chain_analyses(chain), synthesis)
        parts = resolve_auto_band(parts, analyses, file)  # mesh = "auto": its band
        if not parts and not mechanisms and chain is None:
            raise root.error(None, "the scene has neither [parts], [mechanisms] nor [chain]")
        return cls(name, description, file, base, materials, parts, mechanisms, mounts,
                   analyses, chain)


def load_scene(path) -> Scene:
    """Read and validate a scene file (TOML, UTF-8 with or without a byte-order mark);
    raises SceneError (one line) when invalid."""
    path = Path(path)
    if not path.is_file():
        raise SceneError(one_line(f"{path.name}: scene file not found:"
                                  f" {file_path(Path(), path)}"))
    name = one_line(path.name)
    size = path.stat().st_size
    if size > MAX_SCENE_BYTES:
        raise SceneError(f"{name}: file of {size} bytes; a scene has at most"
                         f" {MAX_SCENE_BYTES} (limit MAX_SCENE_BYTES)")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8-sig"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise SceneError(one_line(f"{name}: not valid TOML ({exc})")) from None
    except RecursionError:  # tomllib recurses into nested arrays and inline tables
        raise SceneError(f"{name}: not valid TOML (arrays or tables nested too deeply)"
                         ) from None
    return Scene.from_dict(data, path.parent, name)


def _material(name: str, r: Reader) -> Material:
    """The library's Material; its checks (E, rho, exactly one of nu and G, their ranges)
    are located at the key they name."""
    r.expect("E", "rho", "nu", "G")
    values = {"E": r.number("E", PRESSURE), "rho": r.number("rho", DENSITY),
              "nu": r.number("nu", DIMENSIONLESS, None), "G": r.number("G", PRESSURE, None)}
    with relocate(r, values, prefix=f"material {name!r}: "):
        return Material(**values, name=name)


def _material_name(r: Reader, materials: dict) -> str:
    name = r.string("material")
    if name not in materials:
        raise r.error("material", f"expected one of the [materials] {sorted(materials)},"
                                  f" got {name!r}")
    return name


def _section(group: str, r: Reader, materials: dict) -> SectionSpec:
    r.expect(*_SECTION_KEYS, *_DIMENSION_KEYS)
    shape = r.string("section", choices=SECTION_SHAPES)
    kinds = SECTION_SHAPES[shape] + (GENERAL_OPTIONAL if shape == "general" else ())
    r.expect(*_SECTION_KEYS, *(key for key, _ in kinds), context=f"for section = {shape!r}")
    dims = [(key, r.number(key, kind, positive=True)) for key, kind in kinds
            if r.has(key) or (key, kind) not in GENERAL_OPTIONAL]
    _check_dimensions(r, shape, dict(dims))
    material = _material_name(r, materials)
    orientation = r.vector("orientation", (DIMENSIONLESS,) * 3, None)
    plane = r.string("orientation_plane", "xy", choices=("xy", "xz"))
    if orientation is not None and not any(orientation):
        raise r.error("orientation", f"expected a non-zero vector (in the local {plane[0]}-"
                                     f"{plane[1]} plane)")
    return SectionSpec(group, shape, tuple(dims), material, orientation,
                       r.boolean("shear", True), r.boolean("rotary_inertia", True), r.where,
                       plane)


def _check_dimensions(r: Reader, shape: str, dims: dict) -> None:
    """Dimensions that fit together (the checks of :mod:`femmech.fe.sections`, at the key)."""
    from femmech.fe import sections
    if shape == "tube" and not dims["inner_diameter"] < dims["outer_diameter"]:
        raise r.error("inner_diameter", f"expected less than outer_diameter"
                      f" ({dims['outer_diameter']:g} m), got {dims['inner_diameter']:g} m")
    if shape == "i_section":
        if not 2 * dims["flange"] < dims["height"]:
            raise r.error("flange", f"expected less than half the height"
                          f" ({dims['height']:g} m), got {dims['flange']:g} m")
        if not dims["web"] < dims["width"]:
            raise r.error("web", f"expected less than the width ({dims['width']:g} m), got"
                          f" {dims['web']:g} m")
    if shape == "rectangular_hollow" and not 2 * dims["wall"] < min(dims["width"],
                                                                   dims["height"]):
        raise r.error("wall", f"expected less than half the smaller of width and height"
                      f" ({min(dims['width'], dims['height']):g} m), got {dims['wall']:g} m")
    try:  # anything else the section factory refuses (e.g. an overflowing property)
        getattr(sections, shape)(**dims)
    except (ValueError, TypeError, OverflowError) as exc:
        raise r.error(None, str(exc)) from None


def _dofs(r: Reader, key: str, default="all"):
    from femmech.fe.dofs import components

    value = r.get(key, default)
    try:
        if not isinstance(value, (str, list)):
            raise ValueError(f"expected a component name or a list of them, got {show(value)}")
        if not components(value).size:
            raise ValueError("expected at least one component")
    except (ValueError, TypeError) as exc:
        raise r.error(key, str(exc)) from None
    return value if isinstance(value, str) else tuple(value)


def _items(r: Reader) -> list[ItemSpec]:
    items = []
    for s in r.tables("supports"):
        s.expect("nodes", "dofs")
        items.append(ItemSpec("support", {"nodes": s.node_ref("nodes", many=True),
                                          "dofs": _dofs(s, "dofs")}, s.where))
    for m in r.tables("masses"):
        m.expect("node", "mass", "inertia")
        inertia = m.vector("inertia", (INERTIA,) * 3, None)
        if inertia is not None and min(inertia) < 0:
            raise m.error("inertia", f"expected three values >= 0, got {inertia}")
        items.append(ItemSpec("mass", {"node": m.node_ref("node"),
                                       "mass": m.number("mass", MASS, non_negative=True),
                                       "inertia": inertia}, m.where))
    for s in r.tables("springs"):
        items += _springs(s)
    tied = {}  # slave reference → the link that ties it
    for k in r.tables("rigid_links"):
        k.expect("master", "slaves")
        master, slaves = k.node_ref("master"), k.node_ref("slaves", many=True)
        for ref in slaves if isinstance(slaves, tuple) else (slaves,):
            if ref in tied or ref == master:
                other = "its master" if ref == master else tied[ref]
                raise k.error("slaves", f"node {ref!r} is already tied by {other}; a node"
                                        " follows at most one rigid link")
            tied[ref] = k.where.rsplit(".", 1)[-1]
        items.append(ItemSpec("rigid_link", {"master": master, "slaves": slaves}, k.where))
    for k in r.tables("interpolating_links"):
        items.append(_interpolating_link(k))
    return items


def _springs(s: Reader) -> list[ItemSpec]:
    s.expect("node_a", "node_b", "stiffness")
    value = s.get("stiffness")
    stiffness = s.vector("stiffness", _SPRING_KINDS) if isinstance(value, list) else \
        s.number("stiffness", STIFFNESS, non_negative=True)
    if isinstance(value, list) and min(stiffness) < 0:
        raise s.error("stiffness", f"expected six values >= 0, got {show(value)}")
    node_b = s.node_ref("node_b", default=None)
    nodes = s.get("node_a")
    if isinstance(nodes, list) and node_b is None:  # one grounded spring per node
        for i, node in enumerate(nodes):
            s.child(f"node_a[{i}]", {"node": node}).node_ref("node")
    else:
        nodes = [s.node_ref("node_a")]
        if nodes[0] == node_b:
            raise s.error("node_b", f"a spring joins two nodes; node_a and node_b are both"
                                    f" {node_b!r}")
    return [ItemSpec("spring", {"node_a": node, "node_b": node_b, "stiffness": stiffness},
                     s.where) for node in nodes]


def _interpolating_link(k: Reader) -> ItemSpec:
    k.expect("reference", "patch", "weights")
    patch = k.node_ref("patch", many=True)
    weights = k.get("weights", None)
    if weights is not None:
        if not isinstance(weights, list) or not weights:
            raise k.error("weights", f"expected a list of numbers, got {show(weights)}")
        weights = tuple(k.convert("weights", w, DIMENSIONLESS, non_negative=True)
                        for w in weights)
        if not any(weights):
            raise k.error("weights", "expected at least one positive weight")
        if isinstance(patch, tuple) and len(patch) != len(weights):
            raise k.error("weights", f"expected one weight per patch node ({len(patch)}),"
                                     f" got {len(weights)}")
    return ItemSpec("interpolating_link", {"reference": k.node_ref("reference"),
                                           "patch": patch, "weights": weights}, k.where)


def _reduction(r: Reader) -> ReductionSpec:
    from femmech.scene.units import FREQUENCY

    r.expect("method", "interface", "n_modes", "cutoff_hz", "f_max_hz", "residual_vectors")
    method = r.string("method", choices=REDUCTIONS)
    interface = []
    for i in r.tables("interface"):
        i.expect("nodes", "dofs")
        interface.append(InterfaceSpec(i.node_ref("nodes", many=True), _dofs(i, "dofs"),
                                       i.where))
    if not interface:
        raise r.error("interface", "missing (required): [[...reduction.interface]] entries"
                                   " with nodes and dofs")
    n_modes = r.integer("n_modes", None, minimum=0, maximum=MAX_MODES, limit="MAX_MODES")
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
    return spec


def _part(name: str, r: Reader, base: Path, materials: dict) -> PartSpec:
    r.expect(*_PART_KEYS)
    mesh = read_mesh_spec(r, base)
    sections = tuple(_section(g, t, materials) for g, t in r.named_tables("sections").items())
    shells, solids = [], []
    for group, t in r.named_tables("shells").items():
        t.expect("thickness", "material")
        shells.append(ShellSpec(group, t.number("thickness", LENGTH, positive=True),
                                _material_name(t, materials), t.where))
    for group, t in r.named_tables("solids").items():
        t.expect("material")
        solids.append(SolidSpec(group, _material_name(t, materials), t.where))
    if not (sections or shells or solids):
        raise r.error("sections", "missing (required): give [sections.<group>] (beams),"
                                  " [shells.<group>] or [solids.<group>]")
    items = _items(r)
    reduction = _reduction(r.table("reduction")) if r.has("reduction") else None
    return PartSpec(name, mesh, sections, tuple(shells), tuple(solids), tuple(items), reduction,
                    r.where)


def fail(scene: Scene, where: str, key: str | None, message: str,
         error: type[SceneError] = SceneError) -> SceneError:
    """A SceneError (or its subclass ``error``) at ``[where] key`` of the scene file."""
    place = f"[{where}]" + (f" {key}" if key else "")
    return error(f"{scene.file}: {place}: {message}".replace("\n", " "))


def __getattr__(name: str):
    """Names this module had before the scene read straight into library objects."""
    from femmech.deprecation import moved

    return moved(__name__, name, {"MaterialSpec": "femmech.fe.materials.Material"})
