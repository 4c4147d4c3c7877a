"""The report sections that describe a scene run: model summary, mass participation of
the natural modes, and the appendix.

* :func:`summary_section` (first section): parts with element counts by type, nodes and
  DOFs; materials with their values; mass properties from the mass matrices (total
  mass, centre of mass, inertia) and the mass of each element group; supports, springs,
  point masses, links and reduction interfaces; reduction settings with the
  superelement's a-posteriori frequency error estimate; mechanisms and mounts. A scene
  without parts gets no part tables.
* :func:`participation_tables`: effective modal masses and participation factors per
  direction with cumulative fractions (:mod:`femmech.analysis.participation`), for the
  natural-modes section.
* :func:`appendix_section` (last section): scene file and command, software versions,
  sparse solver backends, thread pools, timings per step, the run log.

Numbers are formatted by :mod:`femmech.output.formatting` (units in cells or headers).

Stage 8 (scene), report: uses scene.load, scene.machine, scene.units, fe, analysis
(participation, modes), reduction, solve (direct, threads) and output (report,
formatting); receives the run's :class:`~femmech.scene.workshop.Workshop`.
"""

from __future__ import annotations

import importlib.metadata
import os
import platform
import warnings

import numpy as np

from femmech.analysis.modes import is_supported, superelement_modes
from femmech.analysis.participation import (
    DIRECTIONS,
    element_group_masses,
    mass_properties,
    node_rotations,
    participation,
)
from femmech.errors import ModelWarning
from femmech.fe.dofs import COMPONENTS, components
from femmech.fe.model import node_indices
from femmech.output.formatting import Quantity, format_value
from femmech.output.report import Flagged, Section, Table
from femmech.reduction.component_modes import CUTOFF_FACTOR
from femmech.scene import units
from femmech.scene.cache_folder import default_cache_dir
from femmech.scene.chain import chain_table
from femmech.scene.load import SECTION_SHAPES
from femmech.scene.machine import parameter_kinds
from femmech.scene.mechanisms import coordinate_labels
from femmech.solve import direct, threads
from femmech.version import __version__

UNIT_LABELS = {
    units.LENGTH: "m", units.AREA: "m²", units.SECOND_MOMENT: "m⁴", units.MASS: "kg",
    units.TIME: "s", units.FORCE: "N", units.MOMENT: "N·m", units.PRESSURE: "Pa",
    units.DENSITY: "kg/m³", units.INERTIA: "kg·m²", units.STIFFNESS: "N/m",
    units.ROT_STIFFNESS: "N·m/rad", units.DAMPING: "N·s/m", units.ROT_DAMPING: "N·m·s/rad",
    units.FREQUENCY: "Hz", units.ANGLE: "rad", units.SPEED: "rad/s",
    units.LINEAR_SPEED: "m/s", units.ACCELERATION: "m/s²",
    units.INVERSE_TIME: "1/s", units.DIMENSIONLESS: "",
}
"""Unit shown for the SI value of each kind of scene quantity."""

PACKAGES = ("numpy", "scipy", "scikit-fem", "meshio", "pyvista", "vtk", "matplotlib",
            "sympy", "threadpoolctl", "pyamg", "mkl", "scikit-sparse", "tqdm", "dask")
"""Distributions whose versions the appendix lists (installed or not)."""

ESTIMATE_MODES = 10
"""Error estimates of a superelement without a frequency limit: its lowest modes."""

SHOWN_ZERO = 1e-10
"""Effective masses below this fraction of the direction's rigid-body mass are shown as
0 (Γ below 1e-5 of its scale; round-off of symmetric modes)."""


def _q(value, unit="", digits=4, trim=False) -> Quantity:
    return Quantity(value, unit, digits, trim)


def _nodes_text(mesh, ref) -> str:
    """``"feet (4 nodes)"``, ``"node 12"`` or ``"nodes 1, 2, 3"``."""
    n = len(node_indices(mesh, ref, "summary"))
    if isinstance(ref, str):
        return f"{ref} ({n} node{'s' if n != 1 else ''})"
    if isinstance(ref, (int, np.integer)):
        return f"node {ref}"
    shown = ", ".join(str(i) for i in ref[:6]) + (", …" if len(ref) > 6 else "")
    return f"nodes {shown} ({n})"


def _dofs_text(dofs) -> str:
    if isinstance(dofs, str) and dofs in ("all", "translations", "rotations"):
        return dofs
    return ", ".join(COMPONENTS[c] for c in components(dofs))


# --- model summary ----------------------------------------------------------------------

def summary_section(ws) -> Section:
    """Model summary: parts, materials, masses, supports and interfaces, reductions,
    mechanisms and mounts; no part tables for a mechanism-only scene.

    Assembles nothing: masses (from M) and error estimates are given for the parts whose
    FE model an analysis or a cache miss assembled (a reduction from the cache needs
    none); the others are named in a paragraph."""
    scene, tables, text = ws.scene, [], []
    if scene.parts:
        models = {name: ws.models[name] for name in scene.parts if name in ws.models}
        props = {name: mass_properties(m.M, m.mesh.points, node_rotations(m))
                 for name, m in models.items()}
        tables += [_parts_table(ws), _materials_table(scene)]
        if models:
            groups, check = _groups_table(scene, models, props)
            tables += [_mass_table(props), groups]
            text.append(check)
        missing = [name for name in scene.parts if name not in models]
        if missing:
            text.append(f"Not assembled in this run (reduction from the cache, and no analysis"
                        f" needed the full model): part(s) {', '.join(map(repr, missing))};"
                        " their masses and error estimates need the assembled model (run"
                        " without the cache, --no-cache, to include them).")
        items = _items_table(ws)
        if items.rows:
            tables.append(items)
        if any(p.reduction is not None for p in scene.parts.values()):
            tables.append(_reductions_table(ws, models))
    if scene.mechanisms:
        tables.append(_mechanisms_table(ws))
    if scene.mounts:
        tables.append(_mounts_table(ws))
    if scene.chain is not None:
        tables.append(chain_table(scene.chain, ws.prepared.chain))
    machine = ws.machines.get(False)
    if machine is not None:
        text.append(f"Coupled machine: {machine.n} coordinates ({machine.n_frame} frame,"
                    f" {machine.n - machine.n_frame} mechanism).")
    full = ws.machines.get(True)
    if full is not None:
        text.append(f"Unreduced coupled machine (for the check): {full.n} coordinates.")
    return Section("Model summary", tuple(text), tuple(tables))


def _dof_counts(ws, name: str) -> tuple:
    """(fixed, dependent, inactive, free) DOFs of a part; "-" where not known (model not
    assembled: free DOFs from the superelement)."""
    m = ws.models.get(name)
    if m is None:
        se = ws.superelements.get((name, None))
        free = len(se.free_interface) + len(se.free_interior) if se is not None else "-"
        return "-", "-", "-", free
    empty = np.diff(m.T.tocsr().indptr) == 0
    empty[m.inactive] = False
    fixed, inactive = int(empty.sum()), len(m.inactive)
    return fixed, m.n_dof - m.n_free - fixed - inactive, inactive, m.n_free


def _parts_table(ws) -> Table:
    meshes = {name: ws.prepared.meshes[name] for name in ws.scene.parts}
    kinds = sorted({k for mesh in meshes.values() for k, c in mesh.cells.items() if len(c)})
    rows = tuple((name, mesh.n_nodes, *(len(mesh.cells.get(k, ())) for k in kinds),
                  6 * mesh.n_nodes, *_dof_counts(ws, name)) for name, mesh in meshes.items())
    return Table("Parts: elements by cell type, nodes and DOFs (6 per node)",
                 ("part", "nodes", *(f"{k} elements" for k in kinds), "DOFs",
                  "fixed (supports)", "dependent (links)", "inactive (solid rotations)",
                  "free DOFs"), rows)


def _materials_table(scene) -> Table:
    used = {}
    for part in scene.parts.values():
        for p in (*part.sections, *part.shells, *part.solids):
            used.setdefault(p.material, []).append(f"{part.name}: {p.group}")
    rows = []
    for name, m in scene.materials.items():
        nu = m.nu if m.nu is not None else m.E / (2 * m.G) - 1
        G = m.G if m.G is not None else m.E / (2 * (1 + m.nu))
        rows.append((name, _q(m.E, "Pa", trim=True), _q(nu, trim=True),
                     _q(G, "Pa", digits=4, trim=True), _q(m.rho, "kg/m³", trim=True),
                     ", ".join(used.get(name, ["(unused)"]))))
    return Table("Materials (G or ν derived from the other where not given)",
                 ("material", "E", "ν", "G", "ρ", "used by (part: group)"), tuple(rows))


def _mass_table(props: dict) -> Table:
    rows = tuple((name, _q(p.total), *(_q(c) for c in p.centre),
                  *(_q(p.inertia[i, i]) for i in range(3)))
                 for name, p in props.items())
    return Table("Mass properties from the mass matrix M (rigid-body vectors r: m = r_xᵀ M r_x;"
                 " point masses included); moments of inertia about the centre of mass",
                 ("part", "mass (kg)", "centre x (m)", "centre y (m)", "centre z (m)",
                  "I_xx (kg·m²)", "I_yy (kg·m²)", "I_zz (kg·m²)"), rows)


def _section_text(s) -> str:
    kinds = dict(SECTION_SHAPES[s.shape] + ((("Asy", units.AREA), ("Asz", units.AREA),
                                             ("Ip", units.SECOND_MOMENT))))
    dims = ", ".join(f"{key} " + (format_value(v * 1e3, "mm", trim=True)
                                  if kinds[key] == units.LENGTH else
                                  format_value(v, UNIT_LABELS[kinds[key]], trim=True))
                     for key, v in s.dims)
    return f"{s.shape} ({dims})"


def _groups_table(scene, models: dict, props: dict) -> tuple[Table, str]:
    """Mass of each element group (ρ × geometry) and of the point masses, against M, for
    the assembled parts ``models``."""
    rows, worst = [], 0.0
    for name, model in models.items():
        part, total = scene.parts[name], props[name].total
        densities = {p.group: scene.materials[p.material].rho
                     for p in (*part.shells, *part.solids)}
        masses = element_group_masses(model, densities)
        described = {s.group: (_section_text(s), s.material) for s in part.sections}
        described.update({s.group: (format_value(s.thickness * 1e3, "mm", trim=True)
                                     + " thick", s.material) for s in part.shells})
        described.update({s.group: ("solid", s.material) for s in part.solids})
        for group, g in masses.items():
            what, material = described.get(group, ("", ""))
            rows.append((name, group, g.kind, what, material, g.n_elements, _q(g.mass),
                         _q(100 * g.mass / total)))
        point = [i.values for i in part.items if i.kind == "mass"]
        point_mass = sum(v["mass"] for v in point)
        if point:
            rows.append((name, "point masses", "lumped", ", ".join(
                str(v["node"]) for v in point[:6]) + (", …" if len(point) > 6 else ""),
                "", len(point), _q(float(point_mass)), _q(100 * point_mass / total)))
        listed = sum(g.mass for g in masses.values()) + point_mass
        rows.append((name, "total from M", "", "", "", "", _q(total), _q(100.0)))
        worst = max(worst, abs(listed - total) / total)
    check = (f"Mass by element group: ρ × length × area (beams), ρ × area × thickness"
             f" (shells), ρ × volume (solids); with the point masses they add up to the total"
             f" mass from M within {worst:.1e} (relative).")
    return Table("Mass by element group (kg) and its share of the part's mass (%)",
                 ("part", "group", "kind", "section / thickness", "material", "elements",
                  "mass (kg)", "share (%)"), tuple(rows)), check


def _stiffness_text(k) -> str:
    """A spring's stiffness: scalar (translations) or the non-zero of six components."""
    if np.ndim(k) == 0:
        return "translations " + format_value(float(k), "N/m", trim=True)
    labels = [("N/m" if i < 3 else "N·m/rad") for i in range(6)]
    parts = [f"{COMPONENTS[i]} {format_value(float(v), labels[i], trim=True)}"
             for i, v in enumerate(np.ravel(k)) if v]
    return ", ".join(parts) or "0"


def _item_row(part: str, mesh, item) -> tuple:
    v = item.values
    if item.kind == "support":
        return part, "support", _nodes_text(mesh, v["nodes"]), "fixed: " + _dofs_text(v["dofs"])
    if item.kind == "spring":
        to = "ground" if v["node_b"] is None else _nodes_text(mesh, v["node_b"])
        return (part, "spring", f"{_nodes_text(mesh, v['node_a'])} – {to}",
                _stiffness_text(v["stiffness"]))
    if item.kind == "mass":
        inertia = "" if v["inertia"] is None else "; inertia " + ", ".join(
            format_value(float(x), trim=True) for x in np.ravel(v["inertia"])) + " kg·m²"
        return (part, "point mass", _nodes_text(mesh, v["node"]),
                format_value(float(v["mass"]), "kg", trim=True) + inertia)
    if item.kind == "rigid_link":
        return (part, "rigid link", f"{_nodes_text(mesh, v['master'])} → slaves"
                f" {_nodes_text(mesh, v['slaves'])}", "all 6 DOFs of the slaves")
    weights = "equal weights" if v["weights"] is None else "given weights"
    return (part, "interpolating link", f"{_nodes_text(mesh, v['reference'])} ← patch"
            f" {_nodes_text(mesh, v['patch'])}", f"reference follows the patch ({weights})")


def _items_table(ws) -> Table:
    """Supports, springs, point masses, links and reduction interfaces of every part."""
    rows = []
    for name, part in ws.scene.parts.items():
        mesh = ws.prepared.meshes[name]
        rows += [_item_row(name, mesh, item) for item in part.items]
        for i in part.reduction.interface if part.reduction else ():
            rows.append((name, "reduction interface", _nodes_text(mesh, i.nodes),
                         _dofs_text(i.dofs)))
    return Table("Supports, springs, point masses, links and reduction interfaces",
                 ("part", "kind", "nodes", "DOFs / values"), tuple(rows))


def _selection_text(r) -> str:
    if r.method == "guyan":
        return "static condensation (no modes)"
    if r.f_max_hz is not None:
        return (f"f_max {format_value(r.f_max_hz, 'Hz', trim=True)}: fixed-interface modes"
                f" below {format_value(CUTOFF_FACTOR * r.f_max_hz, 'Hz', trim=True)}")
    if r.cutoff_hz is not None:
        return f"fixed-interface modes below {format_value(r.cutoff_hz, 'Hz', trim=True)}"
    return f"{r.n_modes} lowest fixed-interface modes"


def _estimate(se, model, r) -> str | Flagged:
    """The largest a-posteriori relative frequency error estimate of the superelement's
    own modes up to its frequency of interest (or of its lowest modes), as text."""
    top = r.f_max_hz if r.f_max_hz is not None else (
        r.cutoff_hz / CUTOFF_FACTOR if r.cutoff_hz is not None else None)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ModelWarning)
            if top is not None:
                result = superelement_modes(se, band_hz=(0.0, top), model=model)
            else:
                result = superelement_modes(se, min(ESTIMATE_MODES, se.n_reduced),
                                            model=model)
    except (ValueError, RuntimeError, np.linalg.LinAlgError) as exc:  # the report goes on
        return f"not computed: {type(exc).__name__}: {exc}"
    est = np.abs(result.error_estimate)
    scope = (f"the {est.size} modes up to {format_value(top, 'Hz', trim=True)}"
             if top is not None else f"the {est.size} lowest modes")
    if not est.size:
        return f"no mode up to {format_value(top, 'Hz', trim=True)}"
    k = int(np.argmax(est))
    text = (f"{format_value(float(est[k]), digits=2)} (largest of {scope}, at"
            f" {format_value(float(result.freq_hz[k]), 'Hz')})")
    if result.n_unconfirmed:
        bad = np.flatnonzero(~result.index_confirmed)
        text += (f"; index unconfirmed for mode(s) {', '.join(str(int(j) + 1) for j in bad)}"
                 " (Sturm count of the full model: the reduction missed a full mode below"
                 " them, so their estimates compare with another full mode)")
        return Flagged(text)
    return text


def _reduction_column(ws, name: str, r, model) -> tuple:
    """The cells of one part in :func:`_reductions_table`."""
    se = ws.superelements.get((name, None))
    head = (r.method, _selection_text(r), "yes" if r.residual_vectors else "no")
    if se is None:
        return head + ("not built in this run",) + ("-",) * 5
    kept = se.modal_freq_hz[:se.n_modal - se.n_residual]
    modes = f"{kept.size}" + (f" (highest {format_value(float(kept.max()), 'Hz')})"
                              if kept.size else "")
    estimate = "needs the assembled model"
    if model is not None:
        with ws.timed(f"error estimate {name}"):
            estimate = _estimate(se, model, r)
    return head + (se.n_interface, modes, se.n_residual, se.n_reduced, estimate,
                   ws.cache_status.get(f"part {name!r}", "-"))


ROWS = ("method", "mode selection", "residual vectors", "interface DOFs",
        "fixed-interface modes kept", "residual vectors kept", "reduced coordinates",
        "estimated relative frequency error", "cache")
"""Rows of the reductions table (one column per reduced part)."""


def _reductions_table(ws, models: dict) -> Table:
    parts = [(name, p.reduction) for name, p in ws.scene.parts.items() if p.reduction]
    columns = [_reduction_column(ws, name, r, models.get(name)) for name, r in parts]
    rows = tuple((label, *(c[i] for c in columns)) for i, label in enumerate(ROWS))
    return Table("Reductions: settings, size, and the a-posteriori estimate of the relative"
                 " frequency error of the superelement's own modes against the full model"
                 " (reduction.estimate, without a full solve)",
                 ("", *(name for name, _ in parts)), rows)


def _parameters_text(spec, values: dict) -> str:
    kinds = parameter_kinds(spec)
    return ", ".join(f"{k} = " + (format_value(float(v), UNIT_LABELS.get(kinds.get(k), ""),
                                               trim=True)
                                  if isinstance(v, (int, float)) and not isinstance(v, bool)
                                  else str(v)) for k, v in values.items())


def _mechanisms_table(ws) -> Table:
    rows = []
    for name, spec in ws.scene.mechanisms.items():
        model = ws.prepared.mechanisms.get(name)
        coords = ", ".join(coordinate_labels(model)) if model is not None else "(not built)"
        what = spec.model if spec.model else f"{spec.module}:{spec.function}"
        if spec.options:
            what += " (" + ", ".join(f"{k} = {str(v).lower() if isinstance(v, bool) else v}"
                                     for k, v in spec.options.items()) + ")"
        if spec.form != "rheolinear":
            what += f"; form = {spec.form}"
        rows.append((name, what, coords, _parameters_text(spec, spec.parameters)))
    return Table("Mechanisms (parameters in SI units)",
                 ("mechanism", "model", "coordinates", "parameters"), tuple(rows))


def _mounts_table(ws) -> Table:
    rows = tuple((m.name, m.mechanism, m.part,
                  ", ".join(coordinate_labels(ws.prepared.mechanisms[m.mechanism]))
                  if m.mechanism in ws.prepared.mechanisms else "(not built)",
                  ", ".join(f"{a.coordinate}→{a.node}:{a.direction}"
                            if isinstance(a.direction, str) else f"{a.coordinate}→{a.node}"
                            for a in m.attachments))
                 for m in ws.scene.mounts)
    return Table("Mechanisms mounted", ("mount", "mechanism", "part", "coordinates",
                                        "attachments"), rows)


# --- mass participation of natural modes ------------------------------------------------

def _shown(value: float, scale: float, digits: int = 4) -> Quantity:
    """A quantity, shown as 0 below :data:`SHOWN_ZERO` × ``scale``."""
    return _q(0) if abs(value) < SHOWN_ZERO * scale else _q(float(value), digits=digits)


def _mass_rows(p, freq_hz, dirs) -> tuple:
    """Rows: mode, frequency, then (m_eff, cumulative %) per direction in ``dirs``; a
    last row with the rigid-body mass of each direction. Cumulative percentages with 5
    significant digits (99.996 %, not 100.0 %)."""
    frac = 100 * p.cumulative_fraction
    rows = []
    for k, f in enumerate(freq_hz):
        cells = []
        for d in dirs:
            cells += [_shown(p.effective_mass[k, d], p.rigid_mass[d]),
                      _shown(frac[k, d], 100.0, digits=5)]
        rows.append((k + 1, _q(float(f)), *cells))
    rigid = []
    for d in dirs:
        rigid += [_q(float(p.rigid_mass[d])), _q(100.0, digits=5)]
    rows.append(("rigid body r_dᵀ M r_d", "", *rigid))
    return tuple(rows)


def participation_tables(model, result, part: str) -> tuple[tuple, tuple]:
    """Tables and paragraphs of the mass participation of ``result`` (a ModeSet of
    ``model`` or of its superelement): effective masses per direction with cumulative
    fractions of the rigid-body mass (translations; rotations about the centre of
    mass) and the participation factors Γ."""
    supported = is_supported(model)
    p = participation(model, result, reachable=supported)
    c = ", ".join(format_value(float(x), trim=False) for x in p.reference)
    text = [f"Mass participation of part {part!r}: Γ_kd = φ_kᵀ M r_d for the mass-normalised"
            " modes φ_k and the rigid-body vectors r_d (unit translation along x, y, z; unit"
            f" rotation about axes through the centre of mass ({c}) m); effective modal"
            " masses m_eff = Γ². Cumulative fractions (Σ) are relative to r_dᵀ M r_d, the"
            f" total mass {format_value(float(p.rigid_mass[0]), 'kg')} for translations and"
            " the moment of inertia about the axis for rotations."]
    last = 100 * p.cumulative_fraction[-1]
    text.append(f"After {result.n_modes} modes: " + ", ".join(
        f"{d} {format_value(float(v), '%', digits=5)}" for d, v in zip(DIRECTIONS, last,
                                                                     strict=True)) + ".")
    if p.reachable is not None:
        reach = 100 * p.reachable / p.rigid_mass
        text.append("The part is supported: even all modes of the full model reach only "
                    + ", ".join(f"{d} {format_value(float(v), '%', digits=5)}"
                                for d, v in zip(DIRECTIONS, reach, strict=True))
                    + "; the rest is mass that moves with the supports.")
    freq = result.freq_hz
    translations = Table("Effective modal masses, translations (kg), and cumulative"
                         " fractions of the total mass (%)",
                         ("mode", "frequency (Hz)", "m_eff x", "Σ x (%)", "m_eff y",
                          "Σ y (%)", "m_eff z", "Σ z (%)"), _mass_rows(p, freq, (0, 1, 2)))
    rotations = Table("Effective modal masses, rotations about the centre of mass (kg·m²),"
                      " and cumulative fractions of the moments of inertia (%)",
                      ("mode", "frequency (Hz)", "m_eff rx", "Σ rx (%)", "m_eff ry",
                       "Σ ry (%)", "m_eff rz", "Σ rz (%)"), _mass_rows(p, freq, (3, 4, 5)))
    scale = np.sqrt(np.maximum(p.rigid_mass, 0.0))
    gamma = Table("Participation factors Γ = φᵀ M r (√kg for x, y, z; √kg·m for rx, ry, rz)",
                  ("mode", "frequency (Hz)", *(f"Γ {d}" for d in DIRECTIONS)),
                  tuple((k + 1, _q(float(f)),
                         *(_q(0) if abs(g) < np.sqrt(SHOWN_ZERO) * s else _q(float(g))
                           for g, s in zip(p.gamma[k], scale, strict=True)))
                        for k, f in enumerate(freq)))
    text.append(f"Effective masses below {SHOWN_ZERO:g} of the direction's rigid-body mass"
                " (and Γ below its square root) are shown as 0.")
    return (translations, rotations, gamma), tuple(text)


# --- appendix --------------------------------------------------------------------------

def _version(dist: str) -> str:
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return "not installed"


def _software_table() -> Table:
    rows = [("femmech", __version__),
            ("Python", f"{platform.python_version()} ({platform.python_implementation()})"),
            ("platform", f"{platform.system()} {platform.release()} {platform.machine()}")]
    rows += [(d, _version(d)) for d in PACKAGES]
    return Table("Software", ("package", "version"), tuple(rows))


def _solver_table(ws) -> Table:
    installed, libraries = direct.available(), direct.versions()
    rows = [(name, "yes" if name in installed else "no", libraries.get(name, "-"))
            for name in direct.BACKENDS]
    for name, model in ws.models.items():
        rows.append((f"used for part {name!r}", f"{model.n_free} free DOFs",
                     direct.resolve(None, model.n_free)))
    return Table(f"Sparse direct solvers (default {direct.default_solver()!r}; 'auto' takes"
                 f" SuperLU below {direct.AUTO_MIN_SIZE} unknowns, else the first installed"
                 f" of {', '.join(direct.AUTO_ORDER)})", ("backend", "installed", "library"),
                 tuple(rows))


def _threads_table() -> Table:
    from threadpoolctl import threadpool_info

    rows = tuple((lib.get("internal_api", "?"), lib.get("version") or "-",
                  lib.get("num_threads", "-"), lib.get("filepath", "-"))
                 for lib in threadpool_info())
    s = threads.settings()
    return Table(f"BLAS and OpenMP thread pools (femmech limits: solve phases"
                 f" {s.solve or 'all'}, factorisations {s.factor or 'all'} threads;"
                 f" {os.cpu_count()} CPUs)",
                 ("library", "version", "threads", "file"), rows)


def appendix_section(ws, out, log_lines=()) -> Section:
    """Appendix (the report's last section): scene file and command, software and solver
    versions, thread pools, timings per step (s) and the run log."""
    scene = ws.scene
    path = scene.base_dir / scene.file
    cache = "" if ws.cache_dir == default_cache_dir() else (
        " --no-cache" if ws.cache_dir is None else f" --cache-dir {ws.cache_dir}")
    source = (f"Scene file: {path}. Equivalent command: femmech run {path} --out {out}{cache}."
              if path.is_file() else f"Scene {scene.file!r} given as data (no file; base"
              f" folder {scene.base_dir}); output folder {out}.")
    text = (source,
            f"Reduction cache: {ws.cache_dir if ws.cache_dir is not None else 'off'}.")
    timings = Table("Timings per step (wall clock; analyses include their steps)",
                    ("step", "time"), tuple((k, _q(float(v), "s"))
                                            for k, v in ws.timings.items()))
    return Section("Appendix: software, solvers, threads, timings", text,
                   (_software_table(), _solver_table(ws), _threads_table(), timings),
                   preformatted=tuple(log_lines))
