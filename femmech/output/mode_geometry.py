"""What a mode image draws, and where: scale, deformed curves and surfaces, glyph positions.

Numbers only, no rendering: the automatic displacement scale, the deformed beam curves
(recovered with the elements' shape functions, :func:`femmech.fe.recovery.beam_deflection_curves`)
and shell/solid surfaces as pyvista meshes (pyvista imported inside those two functions),
the nodes that carry supports, point masses and springs to the ground, the node pairs
joined by rigid links or by springs, the coil drawn for a spring, and all drawn points
of a mode (for a camera that shows every mode of a model whole).

Springs are not stored in :class:`~femmech.fe.model.FEModel`; they are found from its
stiffness matrix: element stiffness matrices give no force under a rigid-body motion,
springs to the ground do (``K G`` with ``G`` the six rigid-body motions), and a spring
between two nodes couples their DOFs in ``K`` while a rigid link or a spider (a
constraint) does not.

Uses fe (model, DOFs, recovery, rigid-body motions) and output.surfaces.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femmech.fe.constraints import rigid_link_matrix
from femmech.fe.dofs import DOF_PER_NODE
from femmech.fe.model import FEModel
from femmech.fe.recovery import beam_deflection_curves
from femmech.output.surfaces import shell_cells, solid_cells, surface_faces, surface_nodes

SCALE_FRACTION = 0.12
"""Automatic scale: the largest drawn displacement is this fraction of the model size."""
RADIUS_RANGE = (0.006, 0.02)
"""Drawn tube radii are the sections' drawing radii clipped to this range, as fractions of
the model size: thin frames stay visible and thick sections do not hide the deformation."""
MASS_RADIUS_FRACTION = 0.03
"""Radius of the spheres drawn at point masses, as a fraction of the model size."""
SPRING_LENGTH_FRACTION = 0.16
"""Length of the coil drawn for a spring to the ground, as a fraction of the model size:
longer than the largest drawn displacement (:data:`SCALE_FRACTION` with the automatic
scale), so that a spring is never drawn squeezed flat or turned inside out."""
_SPRING_TOL = 1e-10
"""Relative force under a rigid-body motion above which a node has a spring to the ground
(measured: 1.7e-4 at the mounts of examples/frame_modes.py, below 5e-16 elsewhere)."""


def model_size(model: FEModel) -> float:
    """Largest extent of the model's bounding box, m (1 for a model of one point)."""
    extent = float(np.ptp(model.mesh.points, axis=0).max())
    return extent if extent > 0 else 1.0


def largest_displacement(model: FEModel, u_full: np.ndarray, n_sub: int = 8) -> float:
    """Largest translation along the beam curves and at the surface nodes, (unit of u)."""
    _, disp = beam_deflection_curves(model, u_full, n_sub)
    largest = float(np.linalg.norm(disp, axis=1).max()) if len(disp) else 0.0
    nodes = surface_nodes(model)
    if nodes.size:
        nodal = np.asarray(u_full, dtype=float).reshape(-1, DOF_PER_NODE)[nodes, :3]
        largest = max(largest, float(np.linalg.norm(nodal, axis=1).max()))
    return largest


def mode_scale(model: FEModel, u_full: np.ndarray, n_sub: int = 8,
               fraction: float = SCALE_FRACTION) -> float:
    """Scale factor that makes the largest displacement ``fraction`` of the model size.

    The largest displacement is taken along the recovered beam curves (it may lie
    between nodes) and over the nodes of shell and solid surfaces. A zero shape gets
    scale 1.

    Parameters
    ----------
    model : FEModel
    u_full : ndarray (n_dof,)
        Full DOF vector, m and rad.
    n_sub : int
        Sub-intervals per element of the recovered curves.
    fraction : float
        Target ratio of the largest drawn displacement to :func:`model_size`.

    Returns
    -------
    float
        Scale factor (1/the unit of ``u_full``, times m).
    """
    largest = largest_displacement(model, u_full, n_sub)
    return fraction * model_size(model) / largest if largest > 0 else 1.0


def mode_mesh(model: FEModel, u_full: np.ndarray, scale: float, n_sub: int = 8):
    """Deformed beams as pyvista polylines, one per element, with the drawing data.

    Parameters
    ----------
    model : FEModel
    u_full : ndarray (n_dof,)
        Full DOF vector (a mode shape), m and rad.
    scale : float
        Displacement magnification.
    n_sub : int
        Sub-intervals per element (each element is a polyline of ``n_sub + 1`` points).

    Returns
    -------
    pyvista.PolyData
        Points at the deformed positions ``x + scale u``. Point data ``"displacement"``
        (scaled displacement, m, (n_points, 3)), ``"magnitude"`` (``|u| / max |u|``, 0..1;
        all 0 for a zero shape) and ``"radius"`` (tube radius, m: the section's drawing
        radius clipped to :data:`RADIUS_RANGE` times the model size).
    """
    import pyvista as pv

    points, disp = beam_deflection_curves(model, u_full, n_sub)
    disp = scale * disp
    norm = np.linalg.norm(disp, axis=1)
    largest = norm.max() if norm.size else 0.0
    n_el, n_pt = len(model.beams.cells), n_sub + 1
    lines = np.hstack([np.full((n_el, 1), n_pt),
                       np.arange(n_el * n_pt).reshape(n_el, n_pt)]).ravel()
    mesh = pv.PolyData(points + disp, lines=lines)
    mesh.point_data["displacement"] = disp
    mesh.point_data["magnitude"] = norm / largest if largest > 0 else norm
    mesh.point_data["radius"] = np.repeat(tube_radius(model), n_pt)
    return mesh


def surface_mesh(model: FEModel, u_full: np.ndarray, scale: float,
                 largest: float | None = None):
    """Deformed shell and solid surfaces as a pyvista mesh of triangles and quads.

    Parameters
    ----------
    model : FEModel
    u_full : ndarray (n_dof,)
        Full DOF vector (a mode shape), m and rad; only the translations are drawn.
    scale : float
        Displacement magnification.
    largest : float, optional
        Scaled displacement (m) that maps to magnitude 1 (default: the largest on the
        surface), so that beams and surfaces share one colour scale.

    Returns
    -------
    pyvista.PolyData
        The faces of :func:`femmech.output.surfaces.surface_faces` over the surface
        nodes only (renumbered; point data ``"node"`` holds the model node index), at
        ``x + scale u``. Point data ``"displacement"`` (scaled, m, (n_points, 3)) and
        ``"magnitude"`` (``|u| / largest``, 0..1); no faces for a beam model.
    """
    import pyvista as pv

    faces = surface_faces(model)
    nodes = surface_nodes(model)
    new = np.full(model.mesh.n_nodes, -1, dtype=np.int64)
    new[nodes] = np.arange(nodes.size)
    stream = [np.column_stack([np.full(len(f), f.shape[1]), new[f]]).ravel()
              for f in faces.values()]
    disp = scale * np.asarray(u_full, dtype=float).reshape(-1, DOF_PER_NODE)[nodes, :3]
    norm = np.linalg.norm(disp, axis=1)
    if largest is None:
        largest = float(norm.max()) if norm.size else 0.0
    mesh = pv.PolyData(model.mesh.points[nodes] + disp,
                       faces=np.concatenate(stream) if stream else None)
    mesh.point_data["node"] = nodes
    mesh.point_data["displacement"] = disp
    mesh.point_data["magnitude"] = norm / largest if largest > 0 else norm
    return mesh


def tube_radius(model: FEModel) -> np.ndarray:
    """Drawing radius per element, m, clipped to :data:`RADIUS_RANGE` of the model size."""
    low, high = RADIUS_RANGE
    return np.clip(model.beams.radius, low * model_size(model), high * model_size(model))


def node_radius(model: FEModel) -> np.ndarray:
    """Per node, the largest tube radius of its elements (0 for nodes without beams)."""
    radius = np.zeros(model.mesh.n_nodes)
    np.maximum.at(radius, model.beams.cells, tube_radius(model)[:, None])
    return radius


def joint_nodes(model: FEModel, angle: float = 5.0) -> np.ndarray:
    """Nodes where a tube needs a ball to look joined: free beam ends, nodes of three or
    more elements, and nodes where two elements meet at more than ``angle`` degrees."""
    cells = np.asarray(model.beams.cells)
    if not len(cells):
        return np.empty(0, dtype=np.int64)
    points = model.mesh.points
    axis = points[cells[:, 1]] - points[cells[:, 0]]
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    count = np.bincount(cells.ravel(), minlength=model.mesh.n_nodes)
    two = np.flatnonzero(count == 2)
    order = np.argsort(cells.ravel(), kind="stable")  # element ends grouped by node
    start = np.concatenate([[0], np.cumsum(count)])[two]
    first, second = order[start] // 2, order[start + 1] // 2  # the node's two elements
    bent = two[np.abs(np.einsum("ij,ij->i", axis[first], axis[second]))
               < np.cos(np.radians(angle))]
    return np.sort(np.concatenate([np.flatnonzero((count == 1) | (count >= 3)), bent]))


def marker_size(model: FEModel) -> float:
    """Reference size of glyphs, m: the largest tube radius (or the smallest drawn one)."""
    r = node_radius(model)
    return float(r.max()) if r.size and r.max() > 0 else RADIUS_RANGE[0] * model_size(model)


def fixed_nodes(model: FEModel) -> np.ndarray:
    """Nodes with at least one DOF fixed by a support (an all-zero row of T).

    Nodes used only by solid elements count only their translations: their rotations
    have no stiffness and are fixed by the model itself, not by a support.
    """
    T = model.T.tocsr()
    fixed = (np.diff(T.indptr) == 0).reshape(-1, DOF_PER_NODE)
    solids = solid_cells(model)
    if solids:
        solid_only = np.zeros(model.mesh.n_nodes, dtype=bool)
        solid_only[np.concatenate([c.ravel() for c in solids.values()])] = True
        solid_only[model.beams.cells.ravel()] = False
        for cells in shell_cells(model).values():
            solid_only[cells.ravel()] = False
        fixed[solid_only, 3:] = False
    return np.flatnonzero(fixed.any(axis=1))


def joined_pairs(model: FEModel) -> tuple[np.ndarray, np.ndarray]:
    """Split :attr:`FEModel.links` into rigid links/spiders and node-to-node springs.

    Returns
    -------
    links, springs : ndarray (n, 2) of int
        Pairs without stiffness between them (constraints: rigid links, the legs of
        interpolating links) and pairs that ``K`` couples without a beam between them
        (springs).
    """
    pairs = np.asarray(model.links, dtype=np.int64).reshape(-1, 2)
    if len(pairs):  # one glyph per pair (several springs may join the same two nodes)
        pairs = pairs[np.sort(np.unique(pairs, axis=0, return_index=True)[1])]
    if not len(pairs):
        return pairs, pairs
    K = model.K.tocsr()
    beam = {tuple(sorted(c)) for c in np.asarray(model.beams.cells).tolist()}
    is_spring = np.zeros(len(pairs), dtype=bool)
    for k, (a, b) in enumerate(pairs.tolist()):
        block = K[DOF_PER_NODE * a:DOF_PER_NODE * (a + 1), DOF_PER_NODE * b:DOF_PER_NODE * (b + 1)]
        is_spring[k] = block.count_nonzero() > 0 and (min(a, b), max(a, b)) not in beam
    return pairs[~is_spring], pairs[is_spring]


def ground_springs(model: FEModel) -> tuple[np.ndarray, np.ndarray]:
    """Nodes with a spring to the ground, and the direction in which to draw each.

    A node has a spring to the ground when ``K`` gives it a force under one of the six
    rigid-body motions (elements give none; see the module notes). Nodes of node-to-node
    springs are left out (such springs resist rigid rotations between distant nodes).

    Returns
    -------
    nodes : ndarray (n,) of int
    directions : ndarray (n, 3)
        Unit vectors from the node towards the spring's ground end: along the stiffest
        translation of the spring (``-z`` when it has none or all are equal), pointing
        away from the model's centroid.
    """
    points = model.mesh.points
    centroid = points.mean(axis=0)
    G = rigid_link_matrix(points - centroid).reshape(-1, 6)
    F = np.asarray(model.K @ G).reshape(-1, DOF_PER_NODE, 6)
    K = model.K.tocsr()
    row = np.sqrt(np.add.reduceat(np.asarray(K.multiply(K).sum(axis=1)).ravel(),
                                  np.arange(0, K.shape[0], DOF_PER_NODE)))
    reach = max(1.0, float(np.abs(points - centroid).max()))
    ratio = np.linalg.norm(F, axis=(1, 2)) / np.maximum(row * reach, 1e-300)
    nodes = np.flatnonzero(ratio > _SPRING_TOL)
    nodes = np.setdiff1d(nodes, joined_pairs(model)[1].ravel())
    directions = np.zeros((nodes.size, 3))
    for k, node in enumerate(nodes):
        block = 0.5 * (F[node, :3, :3] + F[node, :3, :3].T)  # the spring's translation block
        values, vectors = np.linalg.eigh(block)
        d = vectors[:, -1] if values[-1] > 1.01 * values[0] else np.array([0.0, 0.0, 1.0])
        outward = points[node] - centroid
        if abs(d[2]) >= 0.7:  # (nearly) vertical: the ground is below
            directions[k] = -np.sign(d[2]) * d
        else:
            directions[k] = (np.sign(d @ outward) or 1.0) * d
    return nodes, directions


def coil(start: np.ndarray, end: np.ndarray, radius: float, turns: int = 5,
         per_turn: int = 16) -> np.ndarray:
    """Points (turns · per_turn + 3, 3) of a coil spring from ``start`` to ``end`` (m).

    Straight ends of a tenth of the length each and a helix of ``turns`` turns and
    ``radius`` (m) about the axis between them; a zero-length axis is taken along z.
    """
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    axis = end - start
    length = np.linalg.norm(axis)
    d = axis / length if length > 0 else np.array([0.0, 0.0, 1.0])
    e1 = np.cross(d, [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(d, e1)
    t = np.linspace(0.0, 1.0, turns * per_turn + 1)
    angle = 2 * np.pi * turns * t
    helix = (start + np.outer(0.1 + 0.8 * t, axis)
             + radius * (np.outer(np.cos(angle), e1) + np.outer(np.sin(angle), e2)))
    return np.vstack([start, helix, end])


def support_size(model: FEModel, glyphs) -> float:
    """Edge of the cubes drawn at supported nodes, m: three times the largest tube radius
    there, or three times :func:`marker_size` where no beam meets them."""
    if not glyphs.supports.size:
        return 0.0
    radius = float(node_radius(model)[glyphs.supports].max())
    return 3.0 * (radius if radius > 0 else marker_size(model))


@dataclass(frozen=True)
class Glyphs:
    """Where a model's glyphs go (node indices into the mesh), found once per model.

    Attributes
    ----------
    supports : ndarray (n,)
        Nodes with a fixed DOF (:func:`fixed_nodes`).
    masses : ndarray (n,)
        Nodes of the point masses drawn.
    links, springs : ndarray (n, 2)
        Rigid-link / spider pairs and node-to-node spring pairs (:func:`joined_pairs`).
    ground : ndarray (n,)
        Nodes with a spring to the ground, and ``ground_dir`` (n, 3) the unit vector to
        its ground end (:func:`ground_springs`).
    """

    supports: np.ndarray
    masses: np.ndarray
    links: np.ndarray
    springs: np.ndarray
    ground: np.ndarray
    ground_dir: np.ndarray


def model_glyphs(model: FEModel, mass_nodes=None) -> Glyphs:
    """The :class:`Glyphs` of a model; ``mass_nodes`` default: all its point masses."""
    links, springs = joined_pairs(model)
    ground, ground_dir = ground_springs(model)
    masses = model.mass_nodes if mass_nodes is None else mass_nodes
    return Glyphs(fixed_nodes(model), np.asarray(masses, dtype=np.int64), links, springs,
                  ground, ground_dir)


def drawn_points(model: FEModel, u_full: np.ndarray, scale: float, glyphs: Glyphs,
                 n_sub: int = 8) -> np.ndarray:
    """Every point a mode image draws at ``scale`` (m, (n, 3)): undeformed nodes, deformed
    curves and surface nodes, the corners around mass balls, support cubes and spring
    coils, and the ground plates of springs (for fitting the camera)."""
    u = np.asarray(u_full, dtype=float)
    nodal = model.mesh.points + scale * u.reshape(-1, DOF_PER_NODE)[:, :3]
    cube = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T  # (8, 3)
    parts = [model.mesh.points, nodal[surface_nodes(model)],
             nodal[glyphs.masses, None, :] + MASS_RADIUS_FRACTION * model_size(model) * cube,
             model.mesh.points[glyphs.supports, None, :] + 0.5 * support_size(model, glyphs)
             * cube]
    if len(model.beams.cells):
        points, disp = beam_deflection_curves(model, u, n_sub)
        parts.append(points + scale * disp)
    if len(glyphs.springs):  # coils round joints: up to 3 markers from the node
        ends = nodal[np.unique(glyphs.springs)]
        parts.append(ends[:, None, :] + 3.0 * marker_size(model) * cube)
    if glyphs.ground.size:  # the ground plates (4 x 4 markers) under the springs
        ends = (model.mesh.points[glyphs.ground]
                + SPRING_LENGTH_FRACTION * model_size(model) * glyphs.ground_dir)
        corners = 2.0 * marker_size(model) * np.array([[1, 1, 0], [1, -1, 0], [-1, 1, 0],
                                                        [-1, -1, 0]])
        parts.append((ends[:, None, :] + corners[None]).reshape(-1, 3))
    return np.concatenate([p.reshape(-1, 3) for p in parts])
