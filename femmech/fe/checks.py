"""Model checks: inputs that give wrong numbers without an error.

Each check is a pure function on arrays that returns :class:`Finding` s, one-line
messages naming the nodes, groups and values concerned. :func:`femmech.build_model`
runs them (through :func:`femmech.fe.model.model_findings`) and issues each finding as a
:class:`~femmech.errors.ModelWarning`; ``femmech check`` and ``femmech run`` print them.

Near nodes (:func:`near_nodes`)
    Distinct nodes closer than :data:`NEAR_NODE_TOL` times the model size that no
    element, spring or link joins: a frame whose members end at two nodes 1e-6 m apart
    is split there (a portal frame 1.5 m x 1 m whose beam starts 1e-6 m beside the column
    top: first frequency 12.64 Hz instead of 32.71 Hz, with no error). Merge them with
    :meth:`femmech.Mesh.merge_nodes` (scene key ``merge_nodes``).
Loose parts (:func:`loose_parts`)
    Connected components of the node graph (elements, springs, links) that neither a
    support nor a spring to the ground holds while the rest of the model is held: a
    free body by accident, whose rigid-body modes appear at 0 Hz; and free-free models
    that fall into several pieces.
Units (:func:`unit_findings`, :func:`frequency_findings`)
    Mix-ups that show in the magnitudes: metre-sized materials (E in Pa) on geometry of
    more than :data:`SI_EXTENT_ABOVE` (millimetres?), mm-t-s materials (ρ in t/mm³) on
    geometry below :data:`MMTS_EXTENT_BELOW` (metres?), both kinds in one model, a
    material whose wave speed ``sqrt(E/ρ)`` no material has, a beam section larger
    than the members it belongs to, point masses orders of magnitude above or below the
    mass of the elements, and first natural frequencies outside
    [:data:`FREQ_BELOW_HZ`, :data:`FREQ_ABOVE_HZ`]. A consistent model in any unit
    system (m-kg-s, mm-t-s) passes.
Element shapes (:func:`shell_shapes`, :func:`shape_findings`)
    Shell elements whose shape costs accuracy: an edge aspect ratio above
    :data:`ASPECT_ABOVE`, quads warped by more than :data:`WARP_ABOVE`, interior angles
    outside :data:`QUAD_ANGLES` (quads) or :data:`TRIANGLE_ANGLES` (triangles), named by
    element id (the index within its cell kind, as in the element errors of
    :mod:`femmech.fe.elements.shell`) and group. Spurious drilling modes of thick shells
    are a property of the modes, not the inputs: :mod:`femmech.analysis.shell_checks`.

Uses only errors (ModelWarning).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from femmech.errors import ModelWarning

NEAR_NODE_TOL = 1e-4
"""Default near-node distance, relative to the bounding-box diagonal of the model (a
frame of 2 m: 0.2 mm). Only pairs closer than :data:`LOCAL_FRACTION` of the shortest
element at either node count, so that fine meshes (small elements next to each other)
are not flagged."""

LOCAL_FRACTION = 1e-2
"""Near nodes must also be closer than this fraction of the smallest element (shortest
distance between two corner nodes) at either node."""

MAX_LISTED = 5
"""Node pairs, parts or items named in one message; the others are counted."""

MAX_PAIRS = 1_000_000
"""Above this many node pairs closer than the near-node distance (clusters of coincident
nodes: k nodes make k(k-1)/2 pairs), :func:`near_nodes` pairs each node with its
:data:`K_NEAREST` nearest neighbours only, so the check stays O(n log n)."""

K_NEAREST = 8

SI_E_ABOVE = 1e8
"""E >= 1e8 means Pa: no material is stiffer than 1e8 N/mm² (diamond: 1.2e6 N/mm²)."""

MMTS_RHO_BELOW = 1e-5
"""0 < ρ < 1e-5 means t/mm³ (steel 7.85e-9): no solid is that light in kg/m³."""

SI_EXTENT_ABOVE = 50.0
"""A model with a material in Pa and a bounding-box diagonal above this (m) is flagged
(machine frames in mm have diagonals of 1e2-1e4)."""

MMTS_EXTENT_BELOW = 10.0
"""A model with a material in t/mm³ and a bounding-box diagonal below this (mm) is
flagged (a machine in metres has a diagonal of 0.1-10)."""

WAVE_SPEED_RANGE = (10.0, 1e8)
"""Wave speeds ``sqrt(E/ρ)`` outside this range (m/s or mm/s) come from mixed units:
E in N/mm² with ρ in kg/m³ gives 5 for steel, E in Pa with ρ in t/mm³ gives 5e9. Real
materials lie within 20 m/s (soft rubber) and 1.3e4 m/s (beryllium); in mm/s, from 2e4
to 1.3e7."""

MASS_RATIO_RANGE = (1e-7, 1e3)
"""Point masses below or above these multiples of the mass of all elements are flagged
(a mass in g given as kg, or in kg in an mm-t-s model, is 1e3 times too large). Only
where every material has the density of a solid (:data:`SOLID_RHO`): lumped-mass models
with (nearly) massless beams carry masses of any multiple of theirs (the processing
machine's rigid-frame check scales ρ by 1e-6)."""

SOLID_RHO = (100.0, 1e-10)
"""Densities of solids: ρ >= 100 kg/m³, or 1e-10 <= ρ < :data:`MMTS_RHO_BELOW` t/mm³."""

FREQ_BELOW_HZ = 1e-3
"""An elastic mode below this frequency in a supported model is flagged."""

FREQ_ABOVE_HZ = 1e6
"""A lowest elastic mode above this frequency is flagged (ρ in t/mm³ with the rest in
SI raises frequencies 1e6 times)."""


@dataclass(frozen=True)
class Finding:
    """A suspicious feature of a model.

    Attributes
    ----------
    kind : str
        ``"near nodes"``, ``"loose part"``, ``"units"``, ``"frequency"``,
        ``"element shape"`` or ``"drilling modes"``.
    message : str
        One line naming the nodes, groups and values concerned.
    nodes : ndarray (n,) of int
        Nodes concerned (empty where none applies).
    """

    kind: str
    message: str
    nodes: np.ndarray


def _listed(items, total: int | None = None) -> str:
    items = list(items)
    total = len(items) if total is None else total
    more = total - min(len(items), MAX_LISTED)
    return ", ".join(items[:MAX_LISTED]) + (f" and {more} more" if more > 0 else "")


CORNERS = {"line": 2, "line3": 2, "triangle": 3, "triangle6": 3, "quad": 4, "quad8": 4,
           "quad9": 4, "tetra": 4, "tetra10": 4, "hexahedron": 8, "hexahedron20": 8,
           "hexahedron27": 8, "wedge": 6}
"""Number of corner nodes (listed first, meshio order) per cell type."""


def local_size(points: np.ndarray, cells: dict) -> np.ndarray:
    """Per node, the smallest distance between two corner nodes of any cell at it, m.

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    cells : dict[str, ndarray (n_cells, nodes_per_cell)]

    Returns
    -------
    ndarray (n_nodes,)
        ``inf`` for nodes of no cell.
    """
    size = np.full(len(points), np.inf)
    for kind, c in cells.items():
        c = np.asarray(c)
        k = CORNERS.get(kind, 0)
        if k < 2 or not len(c):
            continue
        i, j = np.triu_indices(k, 1)
        h = np.linalg.norm(points[c[:, i]] - points[c[:, j]], axis=2).min(axis=1)
        np.minimum.at(size, c.ravel(), np.repeat(h, c.shape[1]))
    return size


def near_nodes(points: np.ndarray, cells: dict, joined=(), tol: float | None = None):
    """Pairs of distinct nodes closer than ``tol`` that no cell or joint connects.

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    cells : dict[str, ndarray (n_cells, nodes_per_cell)]
        Element connectivity by cell type.
    joined : array_like (n_joints, 2) of int
        Node pairs joined by springs or links (not reported).
    tol : float, optional
        Distance, m; default :data:`NEAR_NODE_TOL` times the bounding-box diagonal.
        Pairs must also be closer than :data:`LOCAL_FRACTION` of the smallest cell at
        either node (:func:`local_size`).

    Returns
    -------
    pairs : ndarray (n_pairs, 2) of int
        Node ids, smaller first, sorted by distance.
    distance : ndarray (n_pairs,), m
    """
    points = np.asarray(points, dtype=float)
    if tol is None:
        tol = NEAR_NODE_TOL * float(np.linalg.norm(np.ptp(points, axis=0)))
    empty = np.empty((0, 2), dtype=np.int64), np.empty(0)
    if tol <= 0 or len(points) < 2:
        return empty
    tree = cKDTree(points)
    n_close = (int(tree.count_neighbors(tree, tol)) - len(points)) // 2  # dual-tree count
    if n_close <= MAX_PAIRS:
        pairs = tree.query_pairs(tol, output_type="ndarray")
    else:  # a dense cluster (many coincident nodes) has ~k^2/2 pairs: each node's nearest
        # K_NEAREST neighbours instead, which still names every near node
        dist, idx = tree.query(points, k=K_NEAREST + 1, distance_upper_bound=tol)
        rows = np.repeat(np.arange(len(points)), K_NEAREST + 1).reshape(idx.shape)
        hit = np.isfinite(dist) & (idx != rows)
        pairs = np.unique(np.sort(np.column_stack([rows[hit], idx[hit]]), axis=1), axis=0)
    if not len(pairs):
        return empty
    pairs = np.sort(pairs, axis=1)
    dist = np.linalg.norm(points[pairs[:, 0]] - points[pairs[:, 1]], axis=1)
    local = local_size(points, cells)
    keep = dist < LOCAL_FRACTION * np.minimum(local[pairs[:, 0]], local[pairs[:, 1]])
    pairs, dist = pairs[keep], dist[keep]
    keep = ~_connected(len(points), cells, joined, pairs)
    order = np.argsort(dist[keep], kind="stable")
    return pairs[keep][order], dist[keep][order]


def _graph(n_nodes: int, cells, joined) -> sp.csr_matrix:
    """Graph of nodes and cells (vertices: nodes, then one per cell): an edge from each
    cell to each of its nodes, and one per joined node pair; symmetric."""
    cells = [np.asarray(c) for c in (cells.values() if isinstance(cells, dict) else cells)]
    cells = [c for c in cells if c.ndim == 2 and c.size]
    n_cells = sum(len(c) for c in cells)
    rows = [np.asarray(joined, dtype=np.int64).reshape(-1, 2)[:, 0]]
    cols = [np.asarray(joined, dtype=np.int64).reshape(-1, 2)[:, 1]]
    first = n_nodes
    for c in cells:
        rows.append(np.repeat(first + np.arange(len(c)), c.shape[1]))
        cols.append(c.ravel())
        first += len(c)
    r, c = np.concatenate(rows), np.concatenate(cols)
    n = n_nodes + n_cells
    return sp.coo_matrix((np.ones(2 * r.size), (np.concatenate([r, c]), np.concatenate([c, r]))),
                         shape=(n, n)).tocsr()


def _connected(n_nodes: int, cells, joined, pairs) -> np.ndarray:
    """Mask (n_pairs,): the two nodes of each pair share a cell or are joined."""
    G = _graph(n_nodes, cells, joined)
    a, b = pairs[:, 0], pairs[:, 1]
    ends = {(min(p), max(p)) for p in np.asarray(joined, dtype=np.int64).reshape(-1, 2).tolist()}
    direct = np.array([(i, j) in ends for i, j in zip(a.tolist(), b.tolist(), strict=True)],
                      dtype=bool)
    shared = np.asarray(G[a].multiply(G[b]).sum(axis=1)).ravel() > 0
    return direct | shared


def near_node_findings(points, cells, joined=(), tol: float | None = None) -> list[Finding]:
    """:func:`near_nodes` as one finding naming the closest pairs and their distances."""
    pairs, dist = near_nodes(points, cells, joined, tol)
    if not len(pairs):
        return []
    named = [f"nodes {a} and {b} are {d:.3g} m apart"
             for (a, b), d in zip(pairs[:MAX_LISTED], dist[:MAX_LISTED], strict=True)]
    message = (f"{len(pairs)} pair(s) of nodes nearly coincide but no element, spring or"
               f" link joins them, so the model is split there: {_listed(named, len(pairs))};"
               " merge"
               " them (Mesh.merge_nodes(tol), scene key merge_nodes) or join them")
    return [Finding("near nodes", message, np.unique(pairs))]


def loose_parts(n_nodes: int, cells, joined=(), anchored=()) -> list[Finding]:
    """Pieces of the node graph that are free bodies by accident.

    The graph joins the nodes of each cell and each joined pair (springs between
    nodes, rigid and interpolating links). With ``anchored`` nodes (supports, springs
    to the ground, attachments to the outside), every piece without one is reported;
    without any, a model in several pieces is reported (each piece has its own six
    rigid-body modes).

    Parameters
    ----------
    n_nodes : int
    cells : dict[str, ndarray] or sequence of ndarray (n_cells, nodes_per_cell)
    joined : array_like (n_joints, 2) of int
    anchored : array_like of int
        Nodes held by a support or a spring to the ground.

    Returns
    -------
    list of Finding
        ``nodes``: all nodes of the piece (of the smaller pieces for a free model).
    """
    _, label = connected_components(_graph(n_nodes, cells, joined), directed=False)
    label = np.unique(label[:n_nodes], return_inverse=True)[1]  # the nodes' pieces, 0..
    n_parts = int(label.max(initial=-1)) + 1
    if n_parts < 2:
        return []
    sizes = np.bincount(label, minlength=n_parts)
    anchored = np.asarray(anchored, dtype=np.int64).ravel()
    held = np.zeros(n_parts, dtype=bool)
    held[label[anchored]] = True

    def piece(p):
        nodes = np.flatnonzero(label == p)
        return f"nodes {_listed([str(i) for i in nodes[:MAX_LISTED]], nodes.size)}" \
               f" ({nodes.size} node{'s' if nodes.size > 1 else ''})"

    if not held.any():
        by_size = np.argsort(-sizes, kind="stable")
        return [Finding("loose part", f"the model has no support and falls into {n_parts}"
                        " pieces that no element, spring or link connects, each moving on its"
                        f" own: {'; '.join(piece(p) for p in by_size[:MAX_LISTED])}"
                        + (f" and {n_parts - MAX_LISTED} more" if n_parts > MAX_LISTED else ""),
                        np.flatnonzero(label != by_size[0]))]
    loose = np.flatnonzero(~held)
    out = [Finding("loose part", f"{piece(p)}: a piece that no element, spring or link"
                   " connects to the supported rest of the model, a free body (rigid-body"
                   " modes at 0 Hz)", np.flatnonzero(label == p)) for p in loose[:MAX_LISTED]]
    if loose.size > MAX_LISTED:
        rest = np.flatnonzero(np.isin(label, loose[MAX_LISTED:]))
        out.append(Finding("loose part", f"{loose.size - MAX_LISTED} more free pieces"
                           f" ({rest.size} nodes)", rest))
    return out


def cell_measure(points: np.ndarray, kind: str, cells: np.ndarray) -> np.ndarray:
    """Length (m), area (m²) or volume (m³) of each cell from its corner nodes.

    Quads and hexahedra are split into triangles and tetrahedra (exact for flat quads
    and parallelepipeds; curved quadratic cells are measured by their corners).

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    kind : str
        meshio cell type.
    cells : ndarray (n_cells, nodes_per_cell)

    Returns
    -------
    ndarray (n_cells,)
    """
    x = points[np.asarray(cells)[:, :CORNERS[kind]]]
    if kind in ("line", "line3"):
        return np.linalg.norm(x[:, 1] - x[:, 0], axis=1)
    if kind.startswith(("triangle", "quad")):
        fans = [(0, 1, 2)] if kind.startswith("triangle") else [(0, 1, 2), (0, 2, 3)]
        return sum(0.5 * np.linalg.norm(np.cross(x[:, b] - x[:, a], x[:, c] - x[:, a]), axis=1)
                   for a, b, c in fans)
    tets = {"tetra": [(0, 1, 2, 3)], "wedge": [(0, 1, 2, 3), (1, 2, 3, 4), (2, 3, 4, 5)],
            "hexahedron": [(0, 1, 2, 6), (0, 2, 3, 6), (0, 3, 7, 6), (0, 7, 4, 6),
                           (0, 4, 5, 6), (0, 5, 1, 6)]}[kind.rstrip("0123456789")]
    return sum(np.abs(np.linalg.det(np.stack([x[:, b] - x[:, a], x[:, c] - x[:, a],
                                              x[:, d] - x[:, a]], axis=1))) / 6.0
               for a, b, c, d in tets)


def unit_findings(extent: float, materials: dict, sections=(), masses=(),
                  element_mass: float = 0.0) -> list[Finding]:
    """Unit mix-ups visible in the magnitudes of the inputs (see the module docstring).

    Parameters
    ----------
    extent : float
        Bounding-box diagonal of the model, in its length unit (m).
    materials : dict[str, (float, float)]
        Name → (E, ρ) of the materials used, Pa and kg/m³.
    sections : sequence of (str, float, float)
        Beam group, section depth (twice the draw radius, m) and the diagonal of the
        bounding box of the group's nodes (m).
    masses : sequence of (int, float)
        Node and mass (kg) of each point mass.
    element_mass : float
        Mass of all elements, kg (0: mass checks skipped).

    Returns
    -------
    list of Finding
    """
    out = []
    si = {n: v for n, v in materials.items() if v[0] >= SI_E_ABOVE}
    mmts = {n: v for n, v in materials.items() if 0 < v[1] < MMTS_RHO_BELOW}
    lo, hi = WAVE_SPEED_RANGE
    for name, (E, rho) in materials.items():
        if rho > 0 and not lo <= np.sqrt(E / rho) <= hi:
            out.append(Finding("units", f"material {name!r}: E = {E:.4g} and rho = {rho:.4g}"
                               f" give a wave speed sqrt(E/rho) = {np.sqrt(E / rho):.3g} (m/s or"
                               f" mm/s), outside [{lo:g}, {hi:g}] for any material: E and"
                               " rho in different units (Pa with t/mm³, or N/mm² with kg/m³)?",
                               np.empty(0, dtype=np.int64)))
    if si and mmts:
        out.append(Finding("units", f"materials {sorted(si)} are in Pa (E >= {SI_E_ABOVE:g})"
                           f" but {sorted(mmts)} in t/mm³ (rho < {MMTS_RHO_BELOW:g}): one model"
                           " mixes m-kg-s and mm-t-s units", np.empty(0, dtype=np.int64)))
    elif si and extent > SI_EXTENT_ABOVE:
        name, (E, rho) = next(iter(si.items()))
        out.append(Finding("units", f"the model is {extent:.4g} m across (bounding-box"
                           f" diagonal) with material {name!r} in SI units (E = {E:.4g} Pa,"
                           f" rho = {rho:.4g} kg/m³): is the geometry in mm? Give coordinates"
                           " in m, or E, rho and masses in mm-t-s units (N/mm², t/mm³, t)",
                           np.empty(0, dtype=np.int64)))
    elif mmts and extent < MMTS_EXTENT_BELOW:
        name, (E, rho) = next(iter(mmts.items()))
        out.append(Finding("units", f"material {name!r} is in mm-t-s units (E = {E:.4g}"
                           f" N/mm², rho = {rho:.4g} t/mm³) but the model is only {extent:.4g}"
                           " across (bounding-box diagonal, mm): is the geometry in m?",
                           np.empty(0, dtype=np.int64)))
    for group, depth, span in sections:
        if depth > span:
            out.append(Finding("units", f"beam group {group!r}: the section is {depth:.4g} m"
                               f" deep but the group's elements span only {span:.4g} m: section"
                               " dimensions in mm, or geometry in other units?",
                               np.empty(0, dtype=np.int64)))
    if all(rho >= SOLID_RHO[0] or SOLID_RHO[1] <= rho < MMTS_RHO_BELOW
           for _, rho in materials.values()):
        out += _mass_findings(masses, element_mass)
    return out


def _mass_findings(masses, element_mass: float) -> list[Finding]:
    if element_mass <= 0 or not len(masses):
        return []
    lo, hi = MASS_RATIO_RANGE
    nodes = np.array([m[0] for m in masses], dtype=np.int64)
    ratio = np.array([m[1] for m in masses], dtype=float) / element_mass
    bad = np.flatnonzero((ratio > hi) | ((ratio > 0) & (ratio < lo)))
    if not bad.size:
        return []
    named = [f"{masses[i][1]:.4g} kg at node {nodes[i]} ({ratio[i]:.3g} times)" for i in bad]
    return [Finding("units", f"point masses far from the mass of all elements"
                    f" ({element_mass:.4g} kg, outside [{lo:g}, {hi:g}] times): {_listed(named)};"
                    " masses in g or t, or materials in other units?", nodes[bad])]


def frequency_findings(freq_hz: np.ndarray, rigid: np.ndarray, supported: bool,
                       lowest: bool = True) -> list[Finding]:
    """Natural frequencies that only a unit mix-up gives.

    Parameters
    ----------
    freq_hz : ndarray (n_modes,), Hz, ascending
    rigid : ndarray (n_modes,) of bool
        Rigid-body modes (not judged).
    supported : bool
        The model has fixed DOFs: an elastic mode below :data:`FREQ_BELOW_HZ` is flagged.
    lowest : bool
        The modes start at the lowest one: a first elastic mode above
        :data:`FREQ_ABOVE_HZ` is flagged.
    """
    elastic = np.asarray(freq_hz)[~np.asarray(rigid, dtype=bool)]
    if not elastic.size:
        return []
    none = np.empty(0, dtype=np.int64)
    if lowest and elastic[0] > FREQ_ABOVE_HZ:
        return [Finding("frequency", f"the first elastic natural frequency is"
                        f" {elastic[0]:.4g} Hz, above {FREQ_ABOVE_HZ:g} Hz: are rho or the"
                        " masses in t (mm-t-s) while the rest is in m-kg-s?", none)]
    if supported and elastic[0] < FREQ_BELOW_HZ:
        return [Finding("frequency", f"the first elastic natural frequency of this supported"
                        f" model is {elastic[0]:.4g} Hz, below {FREQ_BELOW_HZ:g} Hz: units"
                        " (E in N/mm² with the rest in SI?) or a nearly free part?", none)]
    return []


ASPECT_ABOVE = 10.0
"""Edge aspect ratio (longest / shortest edge of the corner polygon, the definition of
Abaqus/CAE's Verify Mesh and of HyperMesh and OptiStruct for shells) above which an element
is reported. An element ten times longer than wide resolves the field along its long side
with a tenth of the points it has across, so the error is set by the long side while the
DOFs are spent on the short one; 10 is the usual limit of those tools' quality checks for
stress and frequency analysis (Nastran's far laxer 100 only guards against singularity)."""

WARP_ABOVE = 0.05
"""Quad warping ``z₀ / (d̄ / 2)`` above which a quad is reported: ``z₀`` the distance of the
corners from the element's mean plane (the ``±z₀`` of the warped-quad correction in
:mod:`femmech.fe.elements.shell`), ``d̄`` the mean length of the two diagonals, so that
``d̄ / 2`` is the distance of a square's corners from its centre. 0.05 is the default
tolerance of MSC Nastran's quad warping test (GEOMCHECK ``Q4_WARP``); the flat
element built on the mean plane is a fair stand-in only while the corners lie close to
it."""

QUAD_ANGLES = (15.0, 165.0)
"""Interior angles of quads (degrees) outside this range are reported: the warning limits
of OptiStruct's CQUAD4 vertex-angle check. The bilinear map of a quad with an angle near
180° (or 0°) has a Jacobian near zero at that corner, and the element stiffens. Nastran's
stricter GEOMCHECK angles (30°-150°) flag the moderately distorted quads of free meshes
that still do well: a simply supported thin plate, 8 x 8 MITC4 quads with the interior
nodes moved randomly by up to 30 % of the element size (largest angle 163.7°), errs
2.3/7.3/8.7/9.9 % in its first four frequencies against 1.7/6.6/6.6/7.3 % on the regular
mesh (tests/hard_cases/test_thin_shells.py)."""

TRIANGLE_ANGLES = (10.0, 160.0)
"""Interior angles of triangles (degrees) outside this range are reported (GEOMCHECK's
triangle limits ``T3_SKEW`` 10°, ``T3_IAMAX`` 160°, applied to the corner angles): slivers
whose smallest altitude is a small fraction of their longest edge."""


def shell_shapes(points: np.ndarray, kind: str, cells: np.ndarray) -> dict:
    """Shape measures of shell elements from their corner nodes, vectorised.

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    kind : str
        ``"triangle"``, ``"quad"`` or a quadratic variant (``"triangle6"``, ``"quad8"``,
        ``"quad9"``: corner nodes only, listed first).
    cells : ndarray (n_cells, nodes_per_cell)

    Returns
    -------
    dict of ndarray (n_cells,)
        ``"aspect"``: longest / shortest edge (``inf`` for a zero-length edge);
        ``"warping"``: ``z₀ / (d̄ / 2)`` (:data:`WARP_ABOVE`; 0 for triangles);
        ``"min_angle"``, ``"max_angle"``: smallest and largest interior angle, degrees.
    """
    k = CORNERS[kind]
    x = np.asarray(points, dtype=float)[np.asarray(cells)[:, :k]]  # (n, k, 3)
    edge = np.roll(x, -1, axis=1) - x  # edge i runs from corner i to corner i + 1
    length = np.linalg.norm(edge, axis=2)
    with np.errstate(divide="ignore", invalid="ignore"):
        aspect = np.where(length.min(axis=1) > 0, length.max(axis=1)
                          / np.where(length.min(axis=1) > 0, length.min(axis=1), 1.0), np.inf)
        a, b = -np.roll(edge, 1, axis=1), edge  # the two edges leaving each corner
        cos = np.sum(a * b, axis=2) / (np.linalg.norm(a, axis=2) * length)
    angle = np.degrees(np.arccos(np.clip(np.nan_to_num(cos, nan=1.0), -1.0, 1.0)))
    warping = np.zeros(len(x))
    if k == 4:
        d1, d2 = x[:, 2] - x[:, 0], x[:, 3] - x[:, 1]
        normal = np.cross(d1, d2)
        size = np.linalg.norm(normal, axis=1)
        z0 = np.abs(np.sum(normal * (x[:, 0] - x.mean(axis=1)), axis=1))
        half = 0.25 * (np.linalg.norm(d1, axis=1) + np.linalg.norm(d2, axis=1))
        with np.errstate(divide="ignore", invalid="ignore"):
            warping = np.where(size * half > 0, z0 / np.where(size * half > 0, size * half,
                                                              1.0), np.inf)
    return {"aspect": aspect, "warping": warping, "min_angle": angle.min(axis=1),
            "max_angle": angle.max(axis=1)}


def cell_groups(cell_sets: dict, names, cells: dict) -> dict:
    """Per cell kind of ``cells``, the group (of ``names``) of each cell, ``None`` where the
    cell is in none of them: dict[str, ndarray (n_cells,) of object]."""
    out = {kind: np.full(len(c), None, dtype=object) for kind, c in cells.items()}
    for name in names:
        for kind, idx in cell_sets.get(name, {}).items():
            if kind in out:
                out[kind][np.asarray(idx, dtype=np.int64)] = name
    return out


def shape_findings(points: np.ndarray, cells: dict, groups: dict) -> list[Finding]:
    """Badly shaped shell elements, one finding per measure (:func:`shell_shapes`).

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    cells : dict[str, ndarray (n_cells, nodes_per_cell)]
        Shell cells by kind (other kinds are skipped).
    groups : dict[str, ndarray (n_cells,) of object]
        Group of each cell (:func:`cell_groups`); cells with ``None`` are not checked.

    Returns
    -------
    list of Finding
        Kind ``"element shape"``; the worst elements first, named ``quad 12 (group
        'plate')`` with their value, and the nodes of every reported element.
    """
    bad = {"aspect": [], "warping": [], "angle": []}
    for kind, c in cells.items():
        c = np.asarray(c)
        if not kind.startswith(("triangle", "quad")) or kind not in CORNERS or not len(c):
            continue
        group = groups.get(kind, np.full(len(c), None, dtype=object))
        checked = np.array([g is not None for g in group], dtype=bool)
        m = shell_shapes(points, kind, c)
        lo, hi = TRIANGLE_ANGLES if kind.startswith("triangle") else QUAD_ANGLES
        off = np.maximum(lo - m["min_angle"], m["max_angle"] - hi)  # degrees beyond a limit
        angle = np.where(lo - m["min_angle"] >= m["max_angle"] - hi, m["min_angle"],
                         m["max_angle"])
        for key, value, worse, hit in (
                ("aspect", m["aspect"], m["aspect"], m["aspect"] > ASPECT_ABOVE * _ROUND),
                ("warping", m["warping"], m["warping"], m["warping"] > WARP_ABOVE * _ROUND),
                ("angle", angle, off, off > 1e-9)):  # limits met exactly pass (round-off)
            e = np.flatnonzero(hit & checked)
            if e.size:
                bad[key].append((worse[e], value[e], e, kind, group[e], c[e]))
    return [_shape_finding(key, items) for key, items in bad.items() if items]


_ROUND = 1.0 + 1e-9
"""Elements exactly at a limit (a 10:1 grid) are not reported despite round-off."""

_SHAPE_TEXT = {
    "aspect": (f"an edge aspect ratio (longest / shortest edge) above {ASPECT_ABOVE:g}", "{:.3g}",
               "; such elongated elements lose accuracy along their long side: remesh with"
               " elements closer to square"),
    "warping": (f"corners off their mean plane by more than {WARP_ABOVE:g} of half the mean"
                " diagonal (warping)", "{:.3g}", "; the flat element on the mean plane then"
                " misses the curvature: refine the curved region"),
    "angle": (f"interior angles outside {QUAD_ANGLES[0]:g}-{QUAD_ANGLES[1]:g}° (quads) or"
              f" {TRIANGLE_ANGLES[0]:g}-{TRIANGLE_ANGLES[1]:g}° (triangles)", "{:.1f}°",
              "; distorted elements are too stiff: remesh")}


def _shape_finding(key: str, items: list) -> Finding:
    """One finding from the (worse, value, ids, kind, groups, cells) batches of a measure."""
    worse = np.concatenate([i[0] for i in items])
    value = np.concatenate([i[1] for i in items])
    ids = np.concatenate([i[2] for i in items])
    kind = np.concatenate([np.full(i[2].size, i[3], dtype=object) for i in items])
    group = np.concatenate([i[4] for i in items])
    order = np.argsort(-worse, kind="stable")[:MAX_LISTED]
    head, fmt, advice = _SHAPE_TEXT[key]
    named = [f"{kind[j]} {ids[j]} (group {group[j]!r}): {fmt.format(value[j])}" for j in order]
    nodes = np.unique(np.concatenate([np.ravel(i[5]) for i in items]))
    return Finding("element shape", f"{ids.size} shell element(s) with {head}:"
                   f" {_listed(named, ids.size)}{advice}", nodes)


def warn(findings) -> None:
    """Issue each finding as a :class:`~femmech.errors.ModelWarning`."""
    for f in findings:
        warnings.warn(f"{f.kind}: {f.message}", ModelWarning, stacklevel=3)
