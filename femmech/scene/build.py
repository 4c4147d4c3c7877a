"""From a validated :class:`~femmech.scene.load.Scene` to API objects: meshes, FE models,
superelements, mechanism models and mounts.

:func:`prepare` does everything that needs no FE computation (reads or generates the
meshes, leaving the sizing solves of ``mesh = "auto"`` parts to the first look-up,
merges nearly coincident nodes where the scene asks, builds the mechanism models,
checks every group name, node index and coordinate name, and collects the suspicious
inputs of each part, :mod:`femmech.fe.checks`) and is what ``femmech check`` runs;
:func:`part_model`, :func:`reduce_part` and :func:`machine_mounts` are the computing
steps that :mod:`femmech.scene.run` calls only when an analysis needs them. Errors of the API
raised here are re-raised as one-line :class:`~femmech.errors.SceneError` naming the
scene location.

Stage 8 (scene), plan and build: uses scene.load, scene.mechanisms, fe, reduction and
coupling.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from femmech.errors import ModelWarning, SceneError, UserCodeError, did_you_mean, name_list
from femmech.fe import sections as sec
from femmech.fe.constraints import InterpolatingLink, RigidLink, Support
from femmech.fe.dofs import COMPONENTS
from femmech.fe.generators import grid_frame, members_frame
from femmech.fe.lumped import PointMass, Spring
from femmech.fe.mesh import Mesh
from femmech.fe.mesh_io import read_mesh
from femmech.fe.model import (
    BeamProperty,
    FEModel,
    ShellProperty,
    SolidProperty,
    build_model,
    model_findings,
    node_index,
    node_indices,
)
from femmech.fe.sections import BeamSection
from femmech.scene.auto_mesh import auto_mesh, generate, planned_mesh
from femmech.scene.chain import check_chain
from femmech.scene.load import PartSpec, Scene, fail
from femmech.scene.mechanisms import check_drive_event, confined_module, mechanism_model
from femmech.scene.memory import memory_problem, mesh_counts
from femmech.scene.mesh import generator_counts
from femmech.version import __version__

if TYPE_CHECKING:
    from femmech.coupling import Mount

_ITEMS = {"support": Support, "mass": PointMass, "spring": Spring,
          "rigid_link": RigidLink, "interpolating_link": InterpolatingLink}


@dataclass(frozen=True)
class Prepared:
    """A scene with its meshes and mechanism models, all references checked.

    Attributes
    ----------
    scene : Scene
    meshes : PartMeshes
        Per part; a ``mesh = "auto"`` part that needs solves to be sized is sized on
        first look-up.
    mechanisms : dict[str, RheolinearModel]
        Per mechanism.
    keys : dict[str, str]
        Per part with a reduction: SHA-256 of everything its reduction depends on (see
        :func:`reduction_key_data`).
    findings : dict[str, tuple of femmech.fe.checks.Finding]
        Per part: suspicious inputs (:func:`part_findings`).
    unexecuted : tuple of str
        Mechanisms from user modules that were not built (``prepare(run_code=False)``);
        absent from ``mechanisms``.
    chain : femmech.chain.Chain or None
        The scene's ``[chain]``, built (cheap: no solve).
    """

    scene: Scene
    meshes: dict
    mechanisms: dict
    keys: dict
    findings: dict = field(default_factory=dict)
    unexecuted: tuple = ()
    chain: object = None


def prepare(scene: Scene, allow_code: bool = False, code_root=None,
            run_code: bool = True) -> Prepared:
    """Read/generate meshes and build mechanisms; check all references (no FE assembly).

    Parameters
    ----------
    scene : Scene
    allow_code : bool
        Run the Python modules a scene names (``module =``). Without this opt-in such a
        scene is refused (:class:`~femmech.errors.UserCodeError`): a scene file is data,
        its code runs only for a user who trusts its author.
    code_root : path, optional
        Folder user modules must lie in (default: the scene's folder).
    run_code : bool
        False (what ``femmech check`` does): never run user code, whatever ``allow_code``
        says; its module paths are checked, its mechanisms are listed in
        :attr:`Prepared.unexecuted` and the checks that need their coordinates are skipped.
    """
    planned = {name: planned_part_mesh(scene, part) for name, part in scene.parts.items()}
    meshes = {name: mesh for name, (mesh, _) in planned.items()}
    for name, part in scene.parts.items():
        check_part(scene, part, meshes[name])
    coded = [spec for spec in scene.mechanisms.values() if spec.module is not None]
    for spec in coded:
        confined_module(scene, spec, code_root)
    if coded and run_code and not allow_code:
        spec = coded[0]
        raise fail(scene, spec.where, "module", f"{Path(spec.module).name} is Python code;"
                   " femmech runs code named by a scene only with --allow-code (API:"
                   " allow_code=True). Allow it only for scenes from authors you trust;"
                   " 'femmech check' never runs it", UserCodeError)
    models = {name: mechanism_model(scene, spec, code_root)
              for name, spec in scene.mechanisms.items()
              if run_code or spec.module is None}
    for mount in scene.mounts:
        _check_mount(scene, mount, meshes[mount.part], models.get(mount.mechanism))
    if len(models) == len(scene.mechanisms):
        _check_outputs(scene, models)
    check_drive_event(scene, models)
    keys = {name: sha256_key(reduction_key_data(scene, part))
            for name, part in scene.parts.items() if part.reduction is not None}
    findings = {name: part_findings(scene, part, meshes[name])
                for name, part in scene.parts.items()}
    unexecuted = tuple(name for name in scene.mechanisms if name not in models)
    chain = check_chain(scene.chain, scene.file) if scene.chain is not None else None
    pending = {name: partial(part_mesh, scene, scene.parts[name])
               for name, (_, final) in planned.items() if not final}
    return Prepared(scene, PartMeshes(meshes, pending), models, keys, findings, unexecuted,
                    chain)


def finding_lines(prepared: Prepared) -> list[str]:
    """One line ``warning: [parts.<name>] kind: message`` per finding of each part."""
    return [f"warning: [{prepared.scene.parts[name].where}] {f.kind}: {f.message}"
            for name, found in prepared.findings.items() for f in found]


class PartMeshes(Mapping):
    """Part name → :class:`~femmech.fe.mesh.Mesh`; a ``mesh = "auto"`` part whose sizing
    needs eigen solves is sized when its mesh is first looked up (planning never solves).

    Iterating (``items()``, ``values()``) does not size: it gives each pending part's
    planning mesh (:func:`femmech.scene.auto_mesh.planned_mesh`), so that listing the
    parts (``femmech check``) costs no solve; ``meshes[name]`` gives the final mesh.
    """

    def __init__(self, meshes: dict, pending: dict):
        self._meshes, self._pending = dict(meshes), dict(pending)

    def __getitem__(self, name: str) -> Mesh:
        if name in self._pending:
            self._meshes[name] = self._pending.pop(name)()
        return self._meshes[name]

    def __iter__(self):
        return iter(self._meshes)

    def __len__(self) -> int:
        return len(self._meshes)

    def items(self):
        """(name, mesh) pairs, pending parts with their planning mesh (no sizing)."""
        return self._meshes.items()

    def values(self):
        """The meshes, pending parts with their planning mesh (no sizing)."""
        return self._meshes.values()

    def pending(self) -> tuple:
        """Names of the parts still to be sized."""
        return tuple(self._pending)


def part_mesh(scene: Scene, part: PartSpec) -> Mesh:
    """The part's mesh: read from its file or generated; edge groups turned into nodes."""
    return _part_mesh(scene, part, plan=False)[0]


def planned_part_mesh(scene: Scene, part: PartSpec) -> tuple[Mesh, bool]:
    """The part's mesh as far as known without solving, and whether it is final (see
    :func:`femmech.scene.auto_mesh.planned_mesh`; meshes of files and given counts are)."""
    return _part_mesh(scene, part, plan=True)


def _part_mesh(scene: Scene, part: PartSpec, plan: bool) -> tuple[Mesh, bool]:
    spec = part.mesh
    final = True
    for where, key, ref in _node_refs(scene, part) if spec.auto else ():
        if not isinstance(ref, str):  # node indices depend on the sized counts
            raise fail(scene, part.where, "mesh", f"with mesh = 'auto' give nodes by group"
                       f" name, not {np.ravel(ref).tolist()} ([{where}] {key})")
    if spec.file is None and not spec.auto:  # counts given: checked before building
        key = _COUNT_KEYS[spec.generator]
        if spec.generator == "grid_frame" and spec.params["subdivisions"] == 1:
            key = "bays"
        _check_memory(scene, spec, generator_counts(spec.generator, spec.params), key)
    try:
        if spec.file is not None:
            mesh = read_mesh(spec.file)
            _check_memory(scene, spec, mesh_counts(mesh), "mesh")
        elif spec.auto:  # mesh = "auto": counts sized for the part's band
            args = _model_args(scene, part)
            if plan:
                mesh, final = planned_mesh(spec, args["beams"], args["shells"] or {})
            else:
                mesh = auto_mesh(spec, args["beams"], args["shells"] or {},
                                 lambda m: part_model(scene, part, m))
        elif spec.generator in ("rectangular_plate", "box"):
            mesh = generate(spec.generator, spec.params)
        elif spec.generator == "grid_frame":
            mesh = grid_frame(**spec.params)
        else:
            mesh = members_frame(**spec.params)
        mesh = edges_to_node_sets(mesh, spec.edge_node_groups)
    except SceneError:  # from part_model of an auto mesh: already located
        raise
    except (ValueError, FileNotFoundError) as exc:
        key = "mesh" if spec.file is not None else None
        raise fail(scene, spec.where, key, str(exc)) from None
    return (mesh if spec.merge_tol is None else merged_mesh(scene, part, mesh)), final


_COUNT_KEYS = {"grid_frame": "subdivisions", "members": "members",
               "rectangular_plate": "divisions", "box": "divisions"}


def _check_memory(scene: Scene, spec, counts: dict, key: str) -> None:
    """SceneError at ``[spec.where] key`` (one line: the estimate and the limit in GB) if
    a part of these counts would need more memory than this machine has
    (:mod:`femmech.scene.memory`)."""
    try:
        problem = memory_problem(**counts)
    except ValueError as exc:  # a bad $FEMMECH_MEMORY_LIMIT_GB
        raise fail(scene, spec.where, key, str(exc)) from None
    if problem is not None:
        raise fail(scene, spec.where, key, problem)


def merged_mesh(scene: Scene, part: PartSpec, mesh: Mesh) -> Mesh:
    """The part's mesh with the nodes closer than ``merge_nodes`` merged.

    Node indices change by merging, so every node of the part (items, interface, mount
    attachments, response DOFs) must be given by group name (SceneError otherwise). The
    two nodes of a spring between nodes are never merged (they may coincide on purpose).
    """
    for where, key, ref in _node_refs(scene, part):
        if not isinstance(ref, str):
            raise fail(scene, part.where, "merge_nodes", f"node indices change when nodes"
                       f" are merged; give the nodes by group name, not {ref!r} ([{where}]"
                       f" {key})")
    keep = [_resolve(scene, mesh, item.values[key], item.where, key, one=True)
            for item in part.items if item.kind == "spring"
            and item.values.get("node_b") is not None for key in ("node_a", "node_b")]
    try:
        return mesh.merge_nodes(part.mesh.merge_tol, keep)
    except ValueError as exc:
        raise fail(scene, part.where, "merge_nodes", str(exc)) from None


def _node_refs(scene: Scene, part: PartSpec):
    """(where, key, reference) of every node reference to the part in the scene."""
    for item in part.items:
        for key in ("node", "node_a", "node_b", "master", "reference", "nodes", "slaves",
                    "patch"):
            if item.values.get(key) is not None:
                yield item.where, key, item.values[key]
    for item in (part.reduction.interface if part.reduction else ()):
        yield item.where, "nodes", item.nodes
    for mount in scene.mounts:
        if mount.part == part.name:
            yield from ((a.where, "node", a.node) for a in mount.attachments)
    response = scene.analyses.response
    for p, node, _ in (response.frame_dofs if response is not None else ()):
        if p == part.name:
            yield scene.analyses.where["response"], "frame_dofs", node


def edges_to_node_sets(mesh: Mesh, names) -> Mesh:
    """Mesh without the line cells of the groups ``names``, which become node sets (a Gmsh
    physical curve that marks nodes, e.g. a bearing bore, rather than beams)."""
    if not names:
        return mesh
    lines = mesh.cells.get("line", np.empty((0, 2), dtype=np.int64))
    drop = np.zeros(len(lines), dtype=bool)
    node_sets = dict(mesh.node_sets)
    for name in names:
        idx = mesh.cell_sets.get(name, {}).get("line")
        if idx is None or set(mesh.cell_sets[name]) != {"line"}:
            line_groups = sorted(n for n, s in mesh.cell_sets.items() if "line" in s)
            raise ValueError(f"edge_node_groups: {name!r} is not a group of line cells; line"
                             f" groups: {line_groups}")
        drop[idx] = True
        node_sets[name] = np.unique(lines[idx])
    new = np.cumsum(~drop) - 1
    cell_sets = {}
    for name, by_type in mesh.cell_sets.items():
        if name not in names:
            by_type = dict(by_type)
            if "line" in by_type:
                by_type["line"] = new[by_type["line"][~drop[by_type["line"]]]]
            cell_sets[name] = by_type
    return Mesh(mesh.points, {**mesh.cells, "line": lines[~drop]}, cell_sets, node_sets)


def check_part(scene: Scene, part: PartSpec, mesh: Mesh) -> None:
    """Group names of properties and node references of items and interface exist."""
    for prop in (*part.sections, *part.shells, *part.solids):
        if prop.group not in mesh.cell_sets:
            raise fail(scene, prop.where, None, f"group {prop.group!r} is not a cell group of"
                       f" the mesh; expected one of {name_list(mesh.cell_sets)}"
                       f"{did_you_mean(prop.group, mesh.cell_sets)}")
    lines = mesh.cells.get("line", np.empty((0, 2)))
    owned = np.zeros(len(lines), dtype=bool)
    for prop in part.sections:
        owned[mesh.cell_sets[prop.group].get("line", [])] = True
    if not owned.all():
        e = int(np.flatnonzero(~owned)[0])
        groups = [n for n, s in mesh.cell_sets.items() if e in s.get("line", ())]
        raise fail(scene, part.where, "sections", f"line element {e} has no section"
                   f" ({np.count_nonzero(~owned)} such elements); its groups: {groups}")
    for item in part.items:
        for key, value in item.values.items():
            if key in ("node", "node_a", "master", "reference") or (
                    key == "node_b" and value is not None):
                _resolve(scene, mesh, value, item.where, key, one=True)
            elif key in ("nodes", "slaves", "patch"):
                _resolve(scene, mesh, value, item.where, key, one=False)
    for item in (part.reduction.interface if part.reduction else ()):
        _resolve(scene, mesh, item.nodes, item.where, "nodes", one=False)


def _resolve(scene, mesh, ref, where, key, one: bool):
    try:
        return node_index(mesh, ref, key) if one else node_indices(mesh, ref, key)
    except (ValueError, TypeError) as exc:
        message = str(exc).removeprefix(f"{key}: ")
        raise fail(scene, where, key, message) from None


def _check_mount(scene, mount, mesh, model) -> None:
    """Attachment coordinates (unless ``model`` is None: user code not run), nodes and
    directions of a mount."""
    for att in mount.attachments:
        if model is not None and att.coordinate not in model.coordinate_names:
            names = model.coordinate_names
            raise fail(scene, att.where, "coordinate", f"expected one of the coordinates"
                       f" {list(names)} of mechanism {mount.mechanism!r}, got"
                       f" {att.coordinate!r}")
        _resolve(scene, mesh, att.node, att.where, "node", one=True)
        if isinstance(att.direction, str) and att.direction not in COMPONENTS:
            raise fail(scene, att.where, "direction", f"expected one of"
                       f" {list(COMPONENTS)} or six weights, got {att.direction!r}")


def own_coordinates(scene: Scene, models: dict) -> list[str]:
    """Labels ``"mount.coordinate"`` of the coupled machine's own (not rigidly attached)
    mechanism coordinates, as in :attr:`femmech.coupling.CoupledSystem.labels`."""
    out = []
    for mount in scene.mounts:
        rigid = {a.coordinate for a in mount.attachments if a.stiffness is None}
        out += [f"{mount.name}.{c}" for c in models[mount.mechanism].coordinate_names
                if c not in rigid]
    return out


def _check_outputs(scene: Scene, models: dict) -> None:
    spec = scene.analyses.response
    if spec is None:
        return
    own = own_coordinates(scene, models)
    for name in spec.outputs:
        if name not in own:
            raise fail(scene, scene.analyses.where["response"], "outputs",
                       f"expected labels of the machine's own coordinates {own}, got {name!r}")


def part_model(scene: Scene, part: PartSpec, mesh: Mesh) -> FEModel:
    """:func:`femmech.build_model` of the part (assembly of K and M).

    Its :class:`~femmech.errors.ModelWarning` s are silenced: :func:`prepare` reports the
    same findings (:func:`part_findings`), where scene attachments count as anchors.
    """
    try:
        args = _model_args(scene, part)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ModelWarning)
            return build_model(mesh, **args)
    except (ValueError, TypeError) as exc:
        raise fail(scene, part.where, None, str(exc)) from None


def part_findings(scene: Scene, part: PartSpec, mesh: Mesh) -> tuple:
    """:func:`femmech.fe.model.model_findings` of the part, without assembly; the nodes of
    mount attachments and of a reduction interface count as held (anchors)."""
    anchors = [a.node for m in scene.mounts if m.part == part.name for a in m.attachments]
    anchors += [i.nodes for i in (part.reduction.interface if part.reduction else ())]
    try:
        return model_findings(mesh, **_model_args(scene, part), anchors=anchors)
    except (ValueError, TypeError) as exc:
        raise fail(scene, part.where, None, str(exc)) from None


def _model_args(scene: Scene, part: PartSpec) -> dict:
    """Keyword arguments of :func:`femmech.build_model` for the part (without the mesh)."""
    mats = scene.materials
    beams, shells, solids = {}, {}, {}
    for s in part.sections:
        section = _section(s)
        beams[s.group] = BeamProperty(section, mats[s.material], s.orientation, s.shear,
                                         s.rotary_inertia, s.orientation_plane)
    for s in part.shells:
        shells[s.group] = ShellProperty(s.thickness, mats[s.material])
    for s in part.solids:
        solids[s.group] = SolidProperty(mats[s.material])
    lists = {kind: [] for kind in _ITEMS}
    for item in part.items:
        lists[item.kind].append(_ITEMS[item.kind](**item.values))
    return {"beams": beams, "masses": lists["mass"], "springs": lists["spring"],
            "supports": lists["support"], "rigid_links": lists["rigid_link"],
            "interpolating_links": lists["interpolating_link"], "shells": shells or None,
            "solids": solids or None}


def _section(s) -> BeamSection:
    dims = dict(s.dims)
    factory = getattr(sec, s.shape)
    return factory(**dims, name=s.group)


def interface(part: PartSpec) -> list:
    """The interface in the form of :func:`femmech.reduction.superelement.interface_dofs`."""
    return [(i.nodes if isinstance(i.nodes, (str, int)) else list(i.nodes), i.dofs)
            for i in part.reduction.interface]


def reduce_part(scene: Scene, part: PartSpec, model: FEModel, f_max_hz: float | None = None):
    """Guyan or Craig-Bampton superelement of the part (``f_max_hz`` overrides the
    scene's mode selection, for the speed-versus-error comparison)."""
    from femmech.reduction.component_modes import craig_bampton, guyan

    r = part.reduction
    try:
        if r.method == "guyan":
            return guyan(model, interface(part))
        if f_max_hz is not None:
            return craig_bampton(model, interface(part), f_max_hz=f_max_hz,
                                 residual_vectors=r.residual_vectors)
        return craig_bampton(model, interface(part), n_modes=r.n_modes, cutoff_hz=r.cutoff_hz,
                             f_max_hz=r.f_max_hz, residual_vectors=r.residual_vectors)
    except ValueError as exc:
        raise fail(scene, r.where, "interface", str(exc)) from None


def reduction_key_data(scene: Scene, part: PartSpec, f_max_hz: float | None = None) -> dict:
    """Everything a part's reduction depends on, as plain JSON data.

    That is every field of the part's spec (so a field added to :class:`PartSpec` joins
    the key by itself): the mesh file's content (SHA-256) or the generator's parameters,
    ``edge_node_groups`` and ``merge_nodes``; sections, shells, solids, items; the
    interface and every reduction setting (method, mode selection, residual vectors). Also
    the materials the part uses, the femmech version, the superelement file format and
    :data:`femmech.reduction.component_modes.CUTOFF_FACTOR` (the modes an ``f_max_hz``
    keeps). Not in it: the part's name, file paths and scene locations, and the sparse
    solver backend and thread counts, which change a reduction by round-off only.
    """
    from femmech.reduction.component_modes import CUTOFF_FACTOR
    from femmech.reduction.superelement import FORMAT_VERSION

    data = plain(part)
    del data["name"]
    if part.mesh.file is not None:
        data["mesh"]["file"] = hashlib.sha256(Path(part.mesh.file).read_bytes()).hexdigest()
    if part.mesh.auto:  # mesh = "auto": the counts follow the target and the band
        data["mesh"]["auto"] = {"target_error": part.mesh.target_error,
                                "band": list(part.mesh.band)}
    if f_max_hz is not None:
        data["reduction"].update(n_modes=None, cutoff_hz=None, f_max_hz=float(f_max_hz))
    return {"femmech": __version__, "format": FORMAT_VERSION,
            "cutoff_factor": CUTOFF_FACTOR, "part": data,
            "materials": {n: plain(scene.materials[n]) for n in part.materials_used()}}


def plain(obj):
    """JSON-able copy of nested dataclasses, dicts and sequences (fields with
    ``compare=False``, i.e. scene locations, left out)."""
    if dataclasses.is_dataclass(obj):
        return {f.name: plain(getattr(obj, f.name)) for f in dataclasses.fields(obj)
                if f.compare}
    if isinstance(obj, dict):
        return {str(k): plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [plain(v) for v in obj]
    if isinstance(obj, (np.floating, np.integer, np.bool_)):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    return obj


def sha256_key(data) -> str:
    """SHA-256 (hex) of JSON data, independent of key order."""
    text = json.dumps(data, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def machine_mounts(prepared: Prepared, part_index: dict | None = None) -> list[Mount]:
    """The scene's mounts as API objects; nodes resolved to indices, as
    ``(part_index, node)`` pairs when ``part_index`` ({part name: index}) is given."""
    from femmech.coupling import Attachment, Mount

    scene = prepared.scene
    out = []
    for m in scene.mounts:
        mesh = prepared.meshes[m.part]
        atts = []
        for a in m.attachments:
            node = node_index(mesh, a.node, "attachment")
            if part_index is not None:
                node = (part_index[m.part], node)
            atts.append(Attachment(a.coordinate, node, a.direction, a.stiffness, a.damping))
        out.append(Mount(prepared.mechanisms[m.mechanism], tuple(atts), m.ratio, m.phase,
                         m.name))
    return out

