"""Mode shapes to VTU files for ParaView (via meshio; no pyvista), and atomic file output.

Every writer in :mod:`femmech.output` goes through :func:`atomic_path`: the data is
written to a temporary file in the target folder and renamed onto the target with
:func:`os.replace`, so a failure never leaves a half-written file behind.

Uses analysis.modes, fe and output.surfaces.
"""

from __future__ import annotations

import os
import secrets
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import meshio
import numpy as np

from femmech.analysis.modes import ModeSet
from femmech.fe.dofs import DOF_PER_NODE
from femmech.fe.model import FEModel
from femmech.output.surfaces import cell_blocks


@contextmanager
def atomic_path(filename) -> Iterator[Path]:
    """Context manager yielding a temporary path that replaces ``filename`` on success.

    The temporary file lies in the target folder (so that :func:`os.replace` is an atomic
    rename on POSIX and Windows) and keeps the target's suffix, for writers that choose
    the format by extension. On any exception the temporary file is removed and the
    target is left as it was.

    Parameters
    ----------
    filename : str or os.PathLike

    Yields
    ------
    Path
        Where the caller writes; it does not exist yet.

    Raises
    ------
    FileNotFoundError
        If the target folder does not exist.
    """
    target = Path(filename)
    if not target.parent.is_dir():
        raise FileNotFoundError(f"cannot write {target}: folder {target.parent} does not exist")
    tmp = target.with_name(f".{target.stem}.{secrets.token_hex(6)}.tmp{target.suffix}")
    try:
        yield tmp
        os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)


def mode_indices(modes: ModeSet, indices) -> np.ndarray:
    """Validated 0-based mode indices (all modes by default)."""
    if indices is None:
        return np.arange(modes.n_modes)
    idx = np.atleast_1d(np.asarray(indices))
    if not np.issubdtype(idx.dtype, np.integer):
        raise TypeError(f"mode indices must be integers, got {indices!r}")
    bad = idx[(idx < 0) | (idx >= modes.n_modes)]
    if bad.size:
        raise ValueError(f"mode index {bad[0]} does not exist: the mode set has"
                         f" {modes.n_modes} modes (0-based indices)")
    return idx.astype(np.int64)


def check_sizes(model: FEModel, modes: ModeSet) -> None:
    if modes.shapes.shape[0] != model.n_dof:
        raise ValueError(f"the mode shapes have {modes.shapes.shape[0]} DOFs but the model has"
                         f" {model.n_dof}; were they computed for another model?")


def export_modes_vtu(model: FEModel, modes: ModeSet, filename, indices=None) -> Path:
    """Write the model's elements with mode shapes as point data to a VTU file for ParaView.

    Modes are numbered from 1 in the file (mode ``i`` is ``modes.shapes[:, i - 1]``),
    as in the titles of :func:`femmech.output.plot_mode`.

    Parameters
    ----------
    model : FEModel
        Beams, shells and (when the model has ``solids``) solid elements, in any mix.
    modes : ModeSet
    filename : str or os.PathLike
        Target ``.vtu`` file; its folder must exist. Written atomically.
    indices : sequence of int, optional
        0-based indices of the modes to write (default all).

    Returns
    -------
    Path
        ``filename``.

    Notes
    -----
    Contents (mass-normalised shapes, so the magnitudes are in m/√kg and rad/√kg):

    - cells: one block per element type, in this order: beams as ``line``, shells as
      ``triangle`` and ``quad``, solids by their meshio type (``tetra``,
      ``hexahedron``, ...); all mesh points are written (nodes used only by masses or
      links have no cell);
    - cell data ``group_id`` (int), the index of the element's group (beam, shell or
      solid property group) in the sorted names of all groups, and ``thickness`` (m,
      shells; 0 for beams and solids);
    - point data ``mode_{n}_displacement`` and ``mode_{n}_rotation``, (n_nodes, 3);
    - field data ``mode_number`` (1-based), ``frequency_hz``, ``rigid`` (0/1) for the
      written modes, in the order written, and ``group_{name}`` = [group_id] per group.

    meshio 5.3 writes no field data to VTU (its reader reads it), so the ``FieldData``
    block (VTK XML format, ascii) is added to the file before it is renamed into place.
    In ParaView, "Warp By Vector" with a mode's displacement shows the deformed shape.
    """
    check_sizes(model, modes)
    idx = mode_indices(modes, indices)
    blocks = cell_blocks(model)
    names = sorted({str(g) for _, _, group, _ in blocks for g in group})
    lookup = np.array(names, dtype=object)
    point_data = {}
    for i in idx:
        nodal = modes.shapes[:, i].reshape(-1, DOF_PER_NODE)
        point_data[f"mode_{i + 1}_displacement"] = nodal[:, :3].copy()
        point_data[f"mode_{i + 1}_rotation"] = nodal[:, 3:].copy()
    cell_data = {
        "group_id": [np.searchsorted(lookup, np.asarray(group, dtype=str).astype(object))
                     .astype(np.int32) for _, _, group, _ in blocks],
        "thickness": [np.asarray(t, dtype=float) for _, _, _, t in blocks],
    }
    mesh = meshio.Mesh(model.mesh.points, [(kind, cells) for kind, cells, _, _ in blocks],
                       point_data=point_data, cell_data=cell_data if blocks else {})
    field = {
        "mode_number": ("Int64", (idx + 1).astype(np.int64)),
        "frequency_hz": ("Float64", modes.freq_hz[idx].astype(float)),
        "rigid": ("Int8", modes.rigid[idx].astype(np.int8)),
    }
    field.update({f"group_{name}": ("Int32", np.array([g], dtype=np.int32))
                  for g, name in enumerate(names)})
    with atomic_path(filename) as tmp:
        meshio.write(tmp, mesh, file_format="vtu")
        add_field_data(tmp, field)
    return Path(filename)


def add_field_data(path: Path, field: dict) -> None:
    """Insert a ``<FieldData>`` block of ascii arrays into a VTK XML UnstructuredGrid file."""
    tree = ET.parse(path)
    grid = tree.getroot().find("UnstructuredGrid")
    block = ET.Element("FieldData")
    for name, (vtk_type, values) in field.items():
        array = ET.SubElement(block, "DataArray", type=vtk_type, Name=name,
                              NumberOfTuples=str(len(values)), format="ascii")
        array.text = " ".join(repr(v) for v in values.tolist())
    grid.insert(0, block)
    tree.write(path, xml_declaration=True, encoding="utf-8")
