"""Parametric meshes of machine-like frames, for examples, tests and benchmarks.

Uses only fe.mesh.
"""

from __future__ import annotations

import numpy as np

from femmech.fe.mesh import MAX_CELLS, MAX_NODES, Mesh


def grid_frame_size(bays, subdivisions: int = 1) -> tuple[int, int]:
    """(nodes, elements) :func:`grid_frame` makes, computed without building it.

    ``bays`` (3 ints >= 0): the joints form a (bx+1)(by+1)(bz+1) grid, each of the
    bx(by+1)(bz+1) + by(bx+1)(bz+1) + bz(bx+1)(by+1) members between neighbours has
    ``subdivisions`` elements and so ``subdivisions - 1`` interior nodes. Python ints:
    no overflow for any request.
    """
    bx, by, bz = (int(b) for b in bays)
    n_members = bx * (by + 1) * (bz + 1) + by * (bx + 1) * (bz + 1) + bz * (bx + 1) * (by + 1)
    n_joints = (bx + 1) * (by + 1) * (bz + 1)
    return n_joints + (subdivisions - 1) * n_members, n_members * subdivisions


def grid_frame(bays=(2, 2, 2), size=(1.0, 1.0, 1.0), subdivisions: int = 1) -> Mesh:
    """Space frame of beams on a regular grid of joints, members subdivided into elements.

    Parameters
    ----------
    bays : (int, int, int)
        Number of bays along x, y, z (joints: ``(bx + 1)(by + 1)(bz + 1)``).
    size : (float, float, float)
        Overall dimensions, m.
    subdivisions : int
        Elements per member (>= 1).

    Returns
    -------
    Mesh
        Line cells with cell sets ``"beams_x"``, ``"beams_y"`` (horizontal members) and
        ``"columns"`` (along z), and node sets ``"base"`` (joints at z = 0), ``"top"``
        (joints at the top) and ``"joints"``. Number of nodes:
        ``joints + (subdivisions - 1) * members``.
    """
    bays = tuple(int(b) for b in bays)
    if len(bays) != 3 or min(bays) < 0 or sum(b > 0 for b in bays) == 0:
        raise ValueError(f"bays must be three non-negative integers, not all zero, got {bays}")
    size = tuple(float(s) for s in size)
    if len(size) != 3 or not all(np.isfinite(s) and s > 0 for s in size):
        raise ValueError(f"size must be three positive lengths, got {size}")
    if subdivisions < 1:
        raise ValueError(f"subdivisions must be >= 1, got {subdivisions}")
    n_nodes, n_elements = grid_frame_size(bays, subdivisions)
    if n_nodes > MAX_NODES or n_elements > MAX_CELLS:
        raise ValueError(f"grid_frame{bays} with {subdivisions} subdivisions would have"
                         f" {n_elements} elements and {n_nodes} nodes; at most"
                         f" {MAX_CELLS} and {MAX_NODES} (MAX_CELLS, MAX_NODES)")
    shape = tuple(b + 1 for b in bays)
    axes = [np.linspace(0.0, s, n) for s, n in zip(size, shape, strict=True)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    joints = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    ids = np.arange(joints.shape[0]).reshape(shape)
    members = {}
    for axis, name in enumerate(("beams_x", "beams_y", "columns")):
        if bays[axis] == 0:
            continue
        a = np.delete(ids, -1, axis=axis).ravel()
        b = np.delete(ids, 0, axis=axis).ravel()
        members[name] = np.column_stack([a, b])
    points, cells, cell_sets = subdivide(joints, members, subdivisions)
    node_sets = {
        "base": ids[:, :, 0].ravel(),
        "top": ids[:, :, -1].ravel(),
        "joints": ids.ravel(),
    }
    return Mesh(points, {"line": cells}, cell_sets, node_sets)


def subdivide(joints, members, k):
    """Split each member into ``k`` elements with new interior nodes (vectorised)."""
    points = [joints]
    cells, cell_sets = [], {}
    n_points, n_cells = len(joints), 0
    for name, pairs in members.items():
        m = len(pairs)
        t = np.arange(1, k) / k
        inner = (joints[pairs[:, 0], None, :] * (1 - t)[None, :, None]
                 + joints[pairs[:, 1], None, :] * t[None, :, None]).reshape(-1, 3)
        inner_ids = n_points + np.arange(m * (k - 1)).reshape(m, k - 1)
        chain = np.column_stack([pairs[:, 0], inner_ids, pairs[:, 1]])
        cells.append(np.stack([chain[:, :-1], chain[:, 1:]], axis=-1).reshape(-1, 2))
        cell_sets[name] = {"line": n_cells + np.arange(m * k)}
        points.append(inner)
        n_points += len(inner)
        n_cells += m * k
    return np.concatenate(points), np.concatenate(cells), cell_sets


MAX_ELEMENTS_PER_MEMBER = 100_000
"""Guard against a unit slip (a length in mm given as m) exhausting the memory."""


def members_frame(joints, members, node_sets=None) -> Mesh:
    """Beam mesh from named joints and chains of members, each subdivided into elements.

    Parameters
    ----------
    joints : dict[str, array_like (3,)]
        Joint name → coordinates, m. Every joint becomes a node and a one-node node set
        of its name.
    members : sequence of dict
        Each with ``group`` (cell-set name; several members may share one), ``chain``
        (two or more joint names, consecutive joints joined by straight members) and
        either ``element_size`` (m; ``max(1, round(length / element_size))`` elements
        per member) or ``divisions`` (elements per member).
    node_sets : dict[str, sequence of str], optional
        Extra node sets made of joints (e.g. ``{"feet": ["left_foot", "right_foot"]}``).

    Returns
    -------
    Mesh
        Line cells; cell sets by group (in order of appearance), node sets per joint and
        from ``node_sets``. Interior nodes follow the joints, member by member.

    Raises
    ------
    ValueError
        Naming an unknown joint, a member without length or a bad subdivision.
    """
    names = list(joints)
    index = {name: i for i, name in enumerate(names)}
    points = [np.array([joints[n] for n in names], dtype=float).reshape(-1, 3)]
    pieces = [(m, member, a, b, _divisions(m, member, a, b, points[0], index))
              for m, member in enumerate(members) for a, b in _pairs(m, member, index)]
    n_elements = sum(k for *_, k in pieces)
    n_nodes = len(names) + n_elements - len(pieces)
    if n_nodes > MAX_NODES or n_elements > MAX_CELLS:
        raise ValueError(f"the members would have {n_elements} elements and {n_nodes} nodes;"
                         f" at most {MAX_CELLS} and {MAX_NODES} (MAX_CELLS, MAX_NODES)")
    n_points, n_lines, lines, groups = len(names), 0, [], {}
    for _, member, a, b, k in pieces:
        pa, pb = points[0][index[a]], points[0][index[b]]
        inner = pa + np.outer(np.arange(1, k) / k, pb - pa)
        ids = np.concatenate([[index[a]], n_points + np.arange(k - 1), [index[b]]])
        points.append(inner)
        n_points += k - 1
        lines.append(np.column_stack([ids[:-1], ids[1:]]))
        groups.setdefault(member["group"], []).append(n_lines + np.arange(k))
        n_lines += k
    sets = {n: [i] for n, i in index.items()}
    for name, members_of_set in (node_sets or {}).items():
        unknown = [j for j in members_of_set if j not in index]
        if unknown:
            raise ValueError(f"node set {name!r}: unknown joints {unknown[:10]}")
        sets[name] = [index[j] for j in members_of_set]
    cell_sets = {g: np.concatenate(parts) for g, parts in groups.items()}
    return Mesh.from_lines(np.vstack(points), np.vstack(lines), cell_sets, sets)


def _pairs(m: int, member, index: dict):
    """Consecutive joint pairs of a member's chain (names checked)."""
    chain = list(member["chain"])
    unknown = [j for j in chain if j not in index]
    if len(chain) < 2 or unknown:
        raise ValueError(f"member {m} ({member['group']!r}): chain {chain[:10]} needs >= 2"
                         f" known joints; unknown: {unknown[:10]}")
    return zip(chain[:-1], chain[1:], strict=True)


def _divisions(m: int, member, a: str, b: str, points, index: dict) -> int:
    """Elements of the straight member from joint ``a`` to ``b`` (see members_frame)."""
    length = float(np.linalg.norm(points[index[b]] - points[index[a]]))
    if not (np.isfinite(length) and length > 0.0):
        raise ValueError(f"member {m} ({member['group']!r}): joints {a!r} and {b!r}"
                         f" are {length} m apart")
    k = member.get("divisions") or length / member["element_size"]
    # a sized count may be a Python int beyond float64 (e.g. for f_max = 1e29 Hz)
    if not (k <= MAX_ELEMENTS_PER_MEMBER if isinstance(k, int)
            else np.isfinite(k) and round(k) <= MAX_ELEMENTS_PER_MEMBER):
        shown = f"{k:.6g}" if not isinstance(k, int) or k < 10**300 else f"1e+{len(str(k)) - 1}"
        raise ValueError(f"member {m} ({member['group']!r}) from {a!r} to {b!r}: {shown}"
                         f" elements (length {length:.6g} m); at most"
                         f" {MAX_ELEMENTS_PER_MEMBER} per member")
    return max(1, round(k))


# --------------------------------------------------------------------------------------
# Shell shapes: rectangular plate, box (rectangular tube with end plates), stiffened plate
# --------------------------------------------------------------------------------------

SURFACE_KINDS = {"quad": 1, "triangle": 1, "quad9": 2, "triangle6": 2}
"""Shell cell kinds the surface generators make → node spacing per element edge (1:
corner nodes only; 2: quadratic cells with mid-side nodes)."""


def _surface_kind(kind: str) -> int:
    if kind not in SURFACE_KINDS:
        raise ValueError(f"kind must be one of {list(SURFACE_KINDS)}, got {kind!r}")
    return SURFACE_KINDS[kind]


def _counts(**counts: int) -> None:
    for name, n in counts.items():
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise ValueError(f"{name} must be an integer >= 1, got {n!r}")


def _lengths(**lengths: float) -> None:
    for name, v in lengths.items():
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be a positive length in m, got {v!r}")


def surface_cells(grid: np.ndarray, kind: str) -> np.ndarray:
    """Cells on a structured grid of node ids (vectorised).

    Parameters
    ----------
    grid : ndarray (p r + 1, p c + 1) of int
        Node ids of an ``r`` x ``c`` patch of elements, ``p`` nodes per element edge
        (``p = 1`` for ``"quad"``/``"triangle"``, 2 for ``"quad9"``/``"triangle6"``).
        Rows run along the second surface direction, columns along the first: the
        cells turn counter-clockwise about first × second.
    kind : ``"quad"``, ``"triangle"``, ``"quad9"`` or ``"triangle6"``

    Returns
    -------
    ndarray (r c, 4 | 9) or (2 r c, 3 | 6)
        Connectivity in meshio/Gmsh node order (corners, then mid-sides, then the centre).
        Triangles split each quad along alternating diagonals (no preferred direction).
    """
    p = _surface_kind(kind)
    rows, cols = (grid.shape[0] - 1) // p, (grid.shape[1] - 1) // p

    def at(dr: int, dc: int) -> np.ndarray:  # node (dr, dc) of every element patch
        return grid[dr: dr + p * rows: p, dc: dc + p * cols: p].ravel()

    c00, c10, c11, c01 = at(0, 0), at(0, p), at(p, p), at(p, 0)  # (row, col) offsets
    if kind == "quad":
        return np.column_stack([c00, c10, c11, c01])
    if kind == "quad9":
        return np.column_stack([c00, c10, c11, c01, at(0, 1), at(1, 2), at(2, 1), at(1, 0),
                                at(1, 1)])
    flip = ((np.arange(rows)[:, None] + np.arange(cols)) % 2).ravel().astype(bool)[:, None]
    if kind == "triangle":
        t1 = np.where(flip, np.column_stack([c00, c10, c01]), np.column_stack([c00, c10, c11]))
        t2 = np.where(flip, np.column_stack([c10, c11, c01]), np.column_stack([c00, c11, c01]))
        return np.vstack([t1, t2])
    m = at(1, 1)  # triangle6: corners, then the mid-sides of edges 0-1, 1-2, 2-0
    t1 = np.where(flip, np.column_stack([c00, c10, c01, at(0, 1), m, at(1, 0)]),
                  np.column_stack([c00, c10, c11, at(0, 1), at(1, 2), m]))
    t2 = np.where(flip, np.column_stack([c10, c11, c01, at(1, 2), at(2, 1), m]),
                  np.column_stack([c00, c11, c01, m, at(2, 1), at(1, 0)]))
    return np.vstack([t1, t2])


def rectangular_plate_size(nx: int, ny: int, kind: str = "quad") -> tuple[int, int]:
    """(nodes, cells) :func:`rectangular_plate` makes, computed without building it."""
    p = _surface_kind(kind)
    return (p * ny + 1) * (p * nx + 1), nx * ny * (2 if kind.startswith("triangle") else 1)


def box_size(nx: int, ny: int, nz: int, end_plates: bool = True,
             kind: str = "quad") -> tuple[int, int]:
    """(nodes, cells) :func:`box` makes, computed without building it."""
    p = _surface_kind(kind)
    n_tube = (p * nx + 1) * p * (2 * ny + 2 * nz)
    n_end = (p * ny - 1) * (p * nz - 1)
    per_quad = 2 if kind.startswith("triangle") else 1
    return (n_tube + 2 * n_end * end_plates,
            per_quad * (2 * nx * (ny + nz) + 2 * ny * nz * end_plates))


def _check_size(n_nodes: int, n_cells: int, what: str) -> None:
    if n_nodes > MAX_NODES or n_cells > MAX_CELLS:
        raise ValueError(f"{what} would have {n_cells} elements and {n_nodes} nodes; at most"
                         f" {MAX_CELLS} and {MAX_NODES} (MAX_CELLS, MAX_NODES)")


def rectangular_plate(a: float, b: float, nx: int, ny: int, kind: str = "quad",
                      origin=(0.0, 0.0, 0.0)) -> Mesh:
    """Flat rectangular plate ``[0, a] x [0, b]`` in the x-y plane, ``nx`` x ``ny`` elements.

    Parameters
    ----------
    a, b : float
        Side lengths along x and y, m.
    nx, ny : int
        Elements along x and y (>= 1); ``kind = "triangle"``/``"triangle6"`` gives two
        triangles per rectangle.
    kind : ``"quad"`` (default), ``"triangle"``, ``"quad9"`` or ``"triangle6"``
    origin : array_like (3,)
        Position of the corner (0, 0), m.

    Returns
    -------
    Mesh
        Cell set ``"plate"``; node sets ``"edge_x0"`` (x = 0), ``"edge_xa"`` (x = a),
        ``"edge_y0"``, ``"edge_yb"``, ``"edges"`` (the whole boundary) and ``"corners"``
        (4 nodes, in the order (0, 0), (a, 0), (a, b), (0, b)). Nodes number row by row
        along x: ``(p ny + 1)(p nx + 1)`` of them, ``p = 2`` for quadratic kinds.
    """
    _lengths(a=a, b=b)
    _counts(nx=nx, ny=ny)
    p = _surface_kind(kind)
    rows, cols = p * ny + 1, p * nx + 1
    _check_size(*rectangular_plate_size(nx, ny, kind), f"rectangular_plate({nx} x {ny},"
                f" {kind!r})")
    X, Y = np.meshgrid(np.linspace(0.0, a, cols), np.linspace(0.0, b, rows))
    points = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)]) + np.asarray(
        origin, dtype=float)
    grid = np.arange(X.size).reshape(rows, cols)
    cells = surface_cells(grid, kind)
    return Mesh(points, {kind: cells}, {"plate": {kind: np.arange(len(cells))}},
                _plate_node_sets(grid))


def _plate_node_sets(grid: np.ndarray) -> dict:
    """Edge and corner node sets of a plate's node grid (rows along y, columns along x)."""
    boundary = np.concatenate([grid[0, :-1], grid[:-1, -1], grid[-1, :0:-1], grid[:0:-1, 0]])
    return {"edge_x0": grid[:, 0], "edge_xa": grid[:, -1], "edge_y0": grid[0, :],
            "edge_yb": grid[-1, :], "edges": boundary,
            "corners": np.array([grid[0, 0], grid[0, -1], grid[-1, -1], grid[-1, 0]])}


BOX_FACES = ("bottom", "side_yw", "top", "side_y0")
"""The walls of :func:`box` in the order of the section's perimeter (counter-clockwise
about +x, starting at y = z = 0)."""


def box(length: float, width: float, height: float, nx: int, ny: int, nz: int,
        end_plates: bool = True, kind: str = "quad") -> Mesh:
    """Rectangular tube of shells along x, optionally closed by end plates.

    The section ``[0, width] x [0, height]`` (y, z) runs from x = 0 to x = ``length``;
    walls and end plates share their edge nodes.

    Parameters
    ----------
    length, width, height : float
        Outer dimensions along x, y, z, m (mid-surfaces of the walls).
    nx, ny, nz : int
        Elements along x, y and z (>= 1).
    end_plates : bool
        Close both ends with plates of ``ny`` x ``nz`` elements.
    kind : ``"quad"`` (default), ``"triangle"``, ``"quad9"`` or ``"triangle6"``

    Returns
    -------
    Mesh
        Cell sets ``"bottom"`` (z = 0), ``"top"`` (z = height), ``"side_y0"`` (y = 0),
        ``"side_yw"`` (y = width), ``"walls"`` (the four), and with end plates
        ``"end_x0"``, ``"end_xl"`` and ``"ends"``; node sets of the same names (the nodes
        of those cells; without end plates ``"end_x0"``/``"end_xl"`` are the end rings)
        and ``"corners"`` (the 8 corners). Wall normals point outwards.
    """
    _lengths(length=length, width=width, height=height)
    _counts(nx=nx, ny=ny, nz=nz)
    p = _surface_kind(kind)
    per = p * (2 * ny + 2 * nz)  # perimeter nodes of one section
    n_tube = (p * nx + 1) * per
    n_end = (p * ny - 1) * (p * nz - 1)
    _check_size(*box_size(nx, ny, nz, end_plates, kind), f"box({nx} x {ny} x {nz},"
                f" {kind!r})")
    my, mz = p * ny, p * nz
    x = np.linspace(0.0, length, p * nx + 1)
    section = _perimeter(width, height, my, mz)  # (per, 2): y, z
    points = [np.column_stack([np.repeat(x, per), np.tile(section, (len(x), 1))])]
    tube = np.arange(n_tube).reshape(len(x), per)
    wall = np.column_stack([tube, tube[:, :1]])  # closed: last column = first
    bounds = np.cumsum([0, my, mz, my, mz])
    cells, node_sets = [], {}
    for face, lo, hi in zip(BOX_FACES, bounds[:-1], bounds[1:], strict=True):
        cells.append(surface_cells(wall[:, lo: hi + 1], kind))  # normal: tangent × x
        node_sets[face] = np.unique(wall[:, lo: hi + 1])
    node_sets.update(walls=np.arange(n_tube), end_x0=tube[0], end_xl=tube[-1])
    if end_plates:
        y, z = np.linspace(0, width, my + 1)[1:-1], np.linspace(0, height, mz + 1)[1:-1]
        for end, station in (("end_x0", 0), ("end_xl", 1)):
            grid = _end_grid(tube[-station], my, mz, n_tube + station * n_end)
            points.append(np.column_stack([np.full(n_end, x[-station]), np.repeat(y, mz - 1),
                                           np.tile(z, my - 1)]))
            cells.append(surface_cells(grid[:, ::-1] if station else grid, kind))  # outwards
            node_sets[end] = np.unique(grid)
    corners = tube[[0, -1]][:, bounds[:-1]].ravel()
    return _box_mesh(np.vstack(points), cells, node_sets, kind, end_plates, corners)


def _perimeter(width: float, height: float, my: int, mz: int) -> np.ndarray:
    """(y, z) of the ``2 my + 2 mz`` nodes around the section, counter-clockwise about +x
    from (0, 0), each node once."""
    sy, sz = np.linspace(0, width, my + 1)[:-1], np.linspace(0, height, mz + 1)[:-1]
    return np.vstack([np.column_stack([sy, np.zeros(my)]),
                      np.column_stack([np.full(mz, width), sz]),
                      np.column_stack([width - sy, np.full(my, height)]),
                      np.column_stack([np.zeros(mz), height - sz])])


def _end_grid(ring: np.ndarray, my: int, mz: int, first: int) -> np.ndarray:
    """Node grid (rows along y, columns along z) of an end plate: the section ring's nodes
    on the boundary, new ids from ``first`` inside (z fastest)."""
    grid = np.empty((my + 1, mz + 1), dtype=np.int64)
    grid[:, 0] = ring[: my + 1]                             # bottom, y rising
    grid[-1, :] = ring[my: my + mz + 1]                     # side y = width, z rising
    grid[::-1, -1] = ring[my + mz: 2 * my + mz + 1]         # top, y falling
    grid[0, ::-1] = np.append(ring[2 * my + mz:], ring[0])  # side y = 0, z falling
    grid[1:-1, 1:-1] = first + np.arange((my - 1) * (mz - 1)).reshape(my - 1, mz - 1)
    return grid


def _box_mesh(points, cells, node_sets, kind, end_plates, corners) -> Mesh:
    """The box's mesh: walls first, then the end plates; cell sets per face and in all."""
    sizes = np.cumsum([0] + [len(c) for c in cells])
    names = BOX_FACES + (("end_x0", "end_xl") if end_plates else ())
    cell_sets = {name: {kind: np.arange(lo, hi)}
                 for name, lo, hi in zip(names, sizes[:-1], sizes[1:], strict=True)}
    cell_sets["walls"] = {kind: np.arange(sizes[4])}
    if end_plates:
        cell_sets["ends"] = {kind: np.arange(sizes[4], sizes[-1])}
        node_sets["ends"] = np.concatenate([node_sets["end_x0"], node_sets["end_xl"]])
    node_sets["corners"] = corners
    return Mesh(points, {kind: np.vstack(cells)}, cell_sets, node_sets)


def stiffened_plate(a: float, b: float, nx: int, ny: int, stiffeners_x=(), stiffeners_y=(),
                    kind: str = "quad") -> Mesh:
    """Rectangular plate (:func:`rectangular_plate`) with beam stiffeners on its nodes.

    Stiffeners are line (beam) elements along grid lines of the plate mesh, one per node
    spacing, sharing the plate's nodes (no offset: the beams lie in the mid-plane; give
    their section an eccentric ``Iy`` by the parallel-axis rule if they sit on one side).

    Parameters
    ----------
    a, b, nx, ny, kind :
        As :func:`rectangular_plate`.
    stiffeners_x : sequence of float
        y positions (m) of stiffeners running along x (from x = 0 to a).
    stiffeners_y : sequence of float
        x positions (m) of stiffeners running along y.
        Each position must lie on a grid line of the plate (``j b / ny``, ``i a / nx``)
        within 1e-9 of the side; ValueError naming the position and the nearest lines
        otherwise.

    Returns
    -------
    Mesh
        The plate's cells, sets and node sets, plus line cells with cell sets
        ``"stiffeners"`` (all), ``"stiffeners_x"`` and ``"stiffeners_y"``, and node sets
        ``"stiffener_x<k>"``/``"stiffener_y<k>"`` (the nodes of the k-th stiffener, 0-based).
    """
    plate = rectangular_plate(a, b, nx, ny, kind)
    p = SURFACE_KINDS[kind]
    grid = np.arange(plate.n_nodes).reshape(p * ny + 1, p * nx + 1)
    rows = _grid_lines(stiffeners_x, b, p * ny, "stiffeners_x", "y", ny)
    cols = _grid_lines(stiffeners_y, a, p * nx, "stiffeners_y", "x", nx)
    lines_x, lines_y = grid[rows], grid[:, cols].T  # (k, nodes along the stiffener)
    segs = [np.stack([g[:, :-1], g[:, 1:]], axis=-1).reshape(-1, 2) for g in (lines_x, lines_y)]
    if len(segs[0]) + len(segs[1]) == 0:
        raise ValueError("stiffened_plate needs at least one stiffener (stiffeners_x or"
                         " stiffeners_y); use rectangular_plate for a bare plate")
    n_x = len(segs[0])
    lines = np.vstack(segs)
    cell_sets = dict(plate.cell_sets)
    cell_sets.update(stiffeners={"line": np.arange(len(lines))},
                     stiffeners_x={"line": np.arange(n_x)},
                     stiffeners_y={"line": np.arange(n_x, len(lines))})
    node_sets = dict(plate.node_sets)
    node_sets.update({f"stiffener_x{k}": g for k, g in enumerate(lines_x)})
    node_sets.update({f"stiffener_y{k}": g for k, g in enumerate(lines_y)})
    return Mesh(plate.points, {**plate.cells, "line": lines}, cell_sets, node_sets)


def _grid_lines(positions, side: float, m: int, key: str, axis: str, n: int) -> np.ndarray:
    """Grid-line indices (of ``m + 1`` lines over ``side``) of stiffener positions."""
    pos = np.atleast_1d(np.asarray(positions, dtype=float))
    if pos.ndim != 1 or not np.isfinite(pos).all():
        raise ValueError(f"{key} must be a list of {axis} positions in m, got {positions!r}")
    index = np.rint(pos / side * m).astype(np.int64)
    off = np.abs(index * side / m - pos) > 1e-9 * side
    bad = np.flatnonzero(off | (index < 0) | (index > m))
    if bad.size:
        step = side / n
        raise ValueError(f"{key}[{bad[0]}] = {pos[bad[0]]:.6g} m is not on a grid line of the"
                         f" plate ({axis} = k {step:.6g} m, k = 0..{n}); choose positions or"
                         " element counts that match")
    if len(np.unique(index)) != len(index):
        raise ValueError(f"{key}: two stiffeners on the same line {axis} ="
                         f" {pos[np.flatnonzero(np.diff(np.sort(index)) == 0)[0]]:.6g} m")
    return index
