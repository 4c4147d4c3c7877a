"""Parametric meshes of machine-like frames, for examples, tests and benchmarks.

Stage 2 (fe, independent of mechanisms): uses only fe.mesh.
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
    points, cells, cell_sets = _subdivide(joints, members, subdivisions)
    node_sets = {
        "base": ids[:, :, 0].ravel(),
        "top": ids[:, :, -1].ravel(),
        "joints": ids.ravel(),
    }
    return Mesh(points, {"line": cells}, cell_sets, node_sets)


def _subdivide(joints, members, k):
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
    if not (np.isfinite(k) and round(k) <= MAX_ELEMENTS_PER_MEMBER):
        raise ValueError(f"member {m} ({member['group']!r}) from {a!r} to {b!r}: {k:.6g}"
                         f" elements (length {length:.6g} m); at most"
                         f" {MAX_ELEMENTS_PER_MEMBER} per member")
    return max(1, round(k))
