"""Named groups of a meshio mesh, from every place a reader puts them, as node and cell sets.

meshio readers return groups in several forms; :func:`collect_sets` gathers them all into
``node sets`` (name → point indices) and ``cell sets`` (name → one index array per cell
block, meshio's layout):

==========================  =====================================================  ==========
source                      meshio field                                           becomes
==========================  =====================================================  ==========
Abaqus ``*NSET``, Exodus    ``mesh.point_sets``                                    node sets
Abaqus ``*ELSET``, Gmsh 4   ``mesh.cell_sets`` (sets of only vertex cells:         cell sets
physical groups, FLAC3D     Gmsh physical points → node sets)
Gmsh 2.2                    ``cell_data["gmsh:physical"]`` + ``field_data`` names  cell sets
VTU/VTK written by meshio   integer data named ``"a-b-c"`` (value k = set k)       both
                            (point data: :func:`split_point_key`)
MED families                ``cell_data["cell_tags"]`` / ``point_data["point_tags"]``  both
                            with ``mesh.cell_tags`` / ``mesh.point_tags``
Nastran property IDs        ``cell_data["nastran:ref"]``                           ``PID<n>``
Medit, TetGen, UGRID refs   ``cell_data["medit:ref"]`` ... (:data:`LABEL_DATA`),   ``ref<n>``,
SU2 markers, AVS materials  ``point_data["medit:ref"]``, ``["tetgen:ref"]``        ``tag<n>``
==========================  =====================================================  ==========

Names are used as written, except that surrounding blanks and quotes are removed and
control characters replaced by ``?`` (they would break one-line messages); two sets that
end up with one name keep it apart by a suffix ``~2``, ``~3`` with a
:class:`~femmech.errors.FemmechWarning`. A mesh file is untrusted input: every index is
checked against its block (ranges, integer type) and a bad set raises
:class:`~femmech.errors.FileFormatError` naming the set.

Imports only femmech.errors (and numpy).
"""

from __future__ import annotations

import unicodedata
import warnings

import numpy as np

from femmech.errors import FemmechWarning, FileFormatError

MAX_SETS = 100_000
"""Most node and cell sets of a mesh file (a large deck has a few thousand)."""
MAX_SET_MEMBERS = 50_000_000
"""Most members (nodes or elements, counted per set) that the set cards of a deck may
list or generate in all (:mod:`femmech.fe.abaqus_sets`, :mod:`femmech.fe.nastran_sets`):
a ``GENERATE`` or ``THRU`` range is counted before it is expanded."""
MAX_NAME_LENGTH = 256
"""Longest set name, characters (Abaqus allows 80, MED 80, Gmsh any)."""
SEPARATORS = ("-", "_", "#", "+", "/")
"""Characters with which meshio joins set names into one data name (``join_strings``):
the first one that no name contains."""
_NOT_SETS = ("cell_tags", "point_tags")


def collect_sets(mesh) -> tuple[dict, dict]:
    """Node sets and cell sets of a ``meshio.Mesh`` from all the sources of the module.

    Returns
    -------
    node_sets : dict[str, ndarray of int64]
        Name → point indices (unsorted, as given).
    cell_sets : dict[str, list[ndarray of int64 or None]]
        Name → indices into each cell block of ``mesh.cells`` (None: none of that block).

    Raises
    ------
    FileFormatError
        Naming the set: indices that are not integers or outside their block, a set that
        does not give one array per block, an empty or over-long name, too many sets.
    """
    n_blocks = len(mesh.cells)
    names = _Names()
    nodes = [(name, idx) for name, idx in getattr(mesh, "point_sets", {}).items()]
    if not nodes:
        nodes = _joined_point_data(mesh)
    nodes += _med_families(mesh, "point") + _point_labels(mesh)
    cells = [(name, per_block) for name, per_block in mesh.cell_sets.items()
             if not str(name).startswith("gmsh:")]
    if not cells:
        cells = _gmsh_physical(mesh) or _joined_cell_data(mesh)
    cells += _med_families(mesh, "cell") + _cell_labels(mesh)
    if len(nodes) + len(cells) > MAX_SETS:
        raise FileFormatError(f"{len(nodes) + len(cells)} node and cell sets; at most"
                              f" {MAX_SETS} (limit MAX_SETS)")
    node_sets, cell_sets = {}, {}
    for name, idx in nodes:
        node_sets[names.node(name)] = _point_indices(idx, len(mesh.points), name)
    for name, per_block in cells:
        per_block = _block_indices(per_block, mesh.cells, name)
        used = [k for k in range(n_blocks) if per_block[k] is not None and len(per_block[k])]
        if used and all(mesh.cells[k].type == "vertex" for k in used):
            # only vertex cells: a group of points (Gmsh physical points)
            points = np.concatenate([np.asarray(mesh.cells[k].data)[per_block[k]].ravel()
                                     for k in used])
            node_sets[names.node(name)] = _point_indices(points, len(mesh.points), name)
        else:
            cell_sets[names.cell(name)] = per_block
    return node_sets, cell_sets


class _Names:
    """Clean names, unique per kind: the second set of one name gets ``~2``, with a warning."""

    def __init__(self):
        self.taken = {"node": set(), "cell": set()}

    def node(self, raw) -> str:
        return self._unique(raw, "node")

    def cell(self, raw) -> str:
        return self._unique(raw, "cell")

    def _unique(self, raw, kind: str) -> str:
        name = clean_name(raw)
        taken = self.taken[kind]
        if name in taken:
            k = 2
            while f"{name}~{k}" in taken:
                k += 1
            warnings.warn(FemmechWarning(
                f"two {kind} sets are named {name!r} in the mesh file; the second is"
                f" renamed {name}~{k}"), stacklevel=4)
            name = f"{name}~{k}"
        taken.add(name)
        return name


def clean_name(raw) -> str:
    """A set name as written, without surrounding blanks and quotes, control characters
    replaced by ``?`` (FileFormatError for an empty or over-long name)."""
    name = str(raw).strip().strip('"').strip()
    name = "".join("?" if unicodedata.category(c) == "Cc" else c for c in name)
    if not name:
        raise FileFormatError(f"a set has an empty name ({raw!r})")
    if len(name) > MAX_NAME_LENGTH:
        raise FileFormatError(f"set name {name[:40]!r}... has {len(name)} characters; at most"
                              f" {MAX_NAME_LENGTH} (limit MAX_NAME_LENGTH)")
    return name


def _point_indices(idx, n_points: int, name) -> np.ndarray:
    idx = np.asarray(idx).ravel()
    if idx.size and idx.dtype.kind not in "iu":
        raise FileFormatError(f"node set {name!r}: indices must be integers, got {idx.dtype}")
    idx = idx.astype(np.int64)
    bad = idx[(idx < 0) | (idx >= n_points)]
    if bad.size:
        raise FileFormatError(f"node set {name!r} references node {bad[0]}, but the mesh has"
                              f" {n_points} nodes")
    return idx


def _block_indices(per_block, blocks, name) -> list:
    """Checked int64 index arrays, one per block (None kept)."""
    if isinstance(per_block, np.ndarray) or not hasattr(per_block, "__len__") or \
            len(per_block) != len(blocks):
        n = len(per_block) if hasattr(per_block, "__len__") else "no"
        raise FileFormatError(f"cell set {name!r} gives {n} index arrays for the"
                              f" {len(blocks)} cell blocks of the mesh")
    out = []
    for block, idx in zip(blocks, per_block, strict=True):
        if idx is None:
            out.append(None)
            continue
        idx = np.asarray(idx).ravel()
        if idx.size and idx.dtype.kind not in "iu":
            raise FileFormatError(f"cell set {name!r}: indices must be integers, got"
                                  f" {idx.dtype}")
        idx = idx.astype(np.int64)
        bad = idx[(idx < 0) | (idx >= len(block.data))]
        if bad.size:
            raise FileFormatError(f"cell set {name!r} references {block.type} cell {bad[0]}"
                                  f" of a block of {len(block.data)}")
        out.append(idx)
    return out


def _gmsh_physical(mesh) -> list:
    """Gmsh 2.2: physical tags per cell, named by ``field_data`` {name: [tag, dim]}."""
    if "gmsh:physical" not in mesh.cell_data:
        return []
    names = {(int(v[0]), int(v[1])): k for k, v in mesh.field_data.items()
             if np.ndim(v) == 1 and len(v) == 2}
    out = {}
    for k, (block, tags) in enumerate(zip(mesh.cells, mesh.cell_data["gmsh:physical"],
                                          strict=True)):
        tags = np.asarray(tags)
        for tag in np.unique(tags[tags > 0]):
            name = names.get((int(tag), CELL_DIM.get(block.type, -1)), str(tag))
            out.setdefault(name, [None] * len(mesh.cells))[k] = np.flatnonzero(tags == tag)
    return list(out.items())


def split_joined(key: str, n_values: int) -> list[str] | None:
    """The set names that meshio joined into the data name ``key`` (``cell_sets_to_data``,
    ``point_sets_to_data``) when values 0 … n_values - 1 occur, or None if ``key`` is not
    such a name (duplicates, or fewer names than values)."""
    if ":" in key or key in _NOT_SETS:
        return None
    found = []
    for i, sep in enumerate(SEPARATORS):
        # meshio takes the first separator that no name contains: the earlier ones occur
        if any(earlier not in key for earlier in SEPARATORS[:i]):
            break
        names = key.split(sep)
        if len(set(names)) == len(names) and all(names) and n_values <= len(names):
            found.append(names)
    # "Set-1_Set-2" splits at "-" too: prefer the split with one name per value
    exact = [names for names in found if len(names) == n_values]
    return (exact or found or [None])[0]


def _joined_values(arrays) -> int | None:
    """1 + the largest value of integer set data (-1 = none), or None if not such data."""
    values = [np.asarray(a) for a in arrays]
    if not values or not all(v.dtype.kind in "iu" and v.ndim == 1 for v in values):
        return None
    if any(v.size and v.min() < -1 for v in values):
        return None
    return max((int(v.max()) for v in values if v.size), default=-1) + 1


def _joined_cell_data(mesh) -> list:
    out = []
    for key, arrays in mesh.cell_data.items():
        n = _joined_values(arrays)
        names = None if n is None else split_joined(str(key), n)
        if names is not None:
            out += [(name, [np.flatnonzero(np.asarray(v) == i) for v in arrays])
                    for i, name in enumerate(names)]
    return out


def split_point_key(key: str, n_values: int) -> list[str] | None:
    """Set names of point data written by meshio 5.3's VTU and VTK writers, which pass the
    joined name ``K = c.join(names)`` as the join character, so that two or more sets are
    named ``K.join(names)`` (``"a_b"`` → ``"aa_bb"``); else as :func:`split_joined` (one
    set: its name). None if ``key`` is neither."""
    if ":" in key or key in _NOT_SETS:
        return None
    length, n = len(key), max(n_values, 2)
    while (n - 1) ** 2 < length:  # len(key) = S + (n - 1)(S + n - 1), S = total name length
        total, rest = divmod(length - (n - 1) ** 2, n)
        for first in range(1, total + 1) if not rest else ():
            joined = key[first:first + total + n - 1]
            for sep in SEPARATORS:
                names = joined.split(sep)
                if len(names) == n and names[0] == key[:first] and joined.join(names) == key:
                    return names
        n += 1
    return split_joined(key, n_values)


def _joined_point_data(mesh) -> list:
    out = []
    for key, values in mesh.point_data.items():
        n = _joined_values([values])
        names = None if n is None else split_point_key(str(key), n)
        if names is not None:
            out += [(name, np.flatnonzero(np.asarray(values) == i))
                    for i, name in enumerate(names)]
    return out


def _med_families(mesh, kind: str) -> list:
    """MED groups: a family tag per point or cell; each family lists its groups."""
    families = getattr(mesh, f"{kind}_tags", None)
    data = (mesh.point_data if kind == "point" else mesh.cell_data).get(f"{kind}_tags")
    if not families or data is None:
        return []
    groups = {}
    for tag, names in families.items():
        for name in names:
            groups.setdefault(name, []).append(int(tag))
    if kind == "point":
        tags = np.asarray(data)
        return [(name, np.flatnonzero(np.isin(tags, t))) for name, t in groups.items()]
    return [(name, [np.flatnonzero(np.isin(np.asarray(d), t)) for d in data])
            for name, t in groups.items()]


LABEL_DATA = {"nastran:ref": "PID", "medit:ref": "ref", "tetgen:ref": "ref",
              "ugrid:ref": "ref", "su2:tag": "tag", "avsucd:material": "material"}
"""Integer cell data that numbers regions (Nastran property IDs, Medit and TetGen
references, SU2 markers, AVS-UCD materials), and the prefix of the sets they become."""
POINT_LABEL_DATA = {"medit:ref": "ref", "tetgen:ref": "ref"}
"""Integer point data that numbers point regions (Nastran's is a coordinate system)."""


def _cell_labels(mesh) -> list:
    """Cells of each value of :data:`LABEL_DATA` → cell sets ``<prefix><value>``."""
    out = []
    for key, prefix in LABEL_DATA.items():
        data = mesh.cell_data.get(key)
        if data is None:
            continue
        if len(data) != len(mesh.cells) or any(len(d) != len(b.data)
                                               for d, b in zip(data, mesh.cells, strict=True)):
            what = "property ID (PID field blank); give every element its PID" \
                if key == "nastran:ref" else f"{key} value"
            raise FileFormatError(f"some elements have no {what}")
        values = [np.asarray(d) for d in data]
        if any(v.size and v.dtype.kind not in "iu" for v in values):
            raise FileFormatError(f"{key}: element labels must be integers")
        labels = np.unique(np.concatenate(values)) if values else []
        out += [(f"{prefix}{int(n)}", [np.flatnonzero(v == n) for v in values])
                for n in labels]
    return out


def _point_labels(mesh) -> list:
    """Points of each value of :data:`POINT_LABEL_DATA` → node sets ``<prefix><value>``."""
    out = []
    for key, prefix in POINT_LABEL_DATA.items():
        values = mesh.point_data.get(key)
        if values is None:
            continue
        values = np.asarray(values).ravel()
        if values.size and values.dtype.kind not in "iu" or len(values) != len(mesh.points):
            raise FileFormatError(f"{key}: one integer label per point expected")
        out += [(f"{prefix}{int(n)}", np.flatnonzero(values == n)) for n in np.unique(values)]
    return out


CELL_DIM = {"vertex": 0, "line": 1, "line3": 1, "triangle": 2, "quad": 2, "triangle6": 2,
            "quad8": 2, "quad9": 2, "tetra": 3, "tetra10": 3, "hexahedron": 3,
            "hexahedron20": 3, "hexahedron27": 3, "wedge": 3}
"""Dimension of each cell type (Gmsh numbers physical groups per dimension)."""
