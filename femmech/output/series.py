"""Result series for ParaView: mode sets, sweeps over the drive angle and time responses
as one collection with steps (PVD or XDMF), read by ParaView's time controls.

A series is the model's cells once and, per step, point data on all mesh nodes:
``displacement`` and ``rotation`` (n_nodes, 3) in the model's units (m, rad; mode shapes
mass-normalised: m/√kg, rad/√kg). Steps are

* mode sets (:func:`write_mode_series`): one step per mode, "time" = mode number;
* sweeps (:func:`write_sweep_series`): one step per drive angle, "time" = angle in
  degrees, one displacement field per tracked branch (``branch_{k}_displacement``);
* time responses (:func:`write_response_series`): one step per output time, "time" = t
  in s, the frame's displacement.

Formats, chosen by the file's suffix:

``.pvd``
    A ParaView collection file and a folder ``<name>_steps/`` beside it with one VTU per
    step (binary, any ParaView or VTK reader).
``.xdmf``
    One XDMF file with the data inline as XML (no HDF5 library needed; meshio's
    ``TimeSeriesReader`` and ParaView read it). Larger than binary VTU; prefer PVD for
    big models.

Files are written atomically: the PVD's folder is filled under a temporary name and
renamed into place, then the collection file is written (its own atomic rename), so no
file is ever half-written and a failure while the steps are written leaves the previous
series whole.

Uses fe, coupling, output.machine (recovery of the frame's full
fields) and output.export (checks, cells, atomic writes); meshio only.
"""

from __future__ import annotations

import os
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np

from femmech.analysis.modes import ModeSet
from femmech.coupling import CoupledSystem
from femmech.fe.dofs import DOF_PER_NODE
from femmech.fe.model import FEModel
from femmech.output.export import add_field_data, atomic_path, check_sizes, mode_indices
from femmech.output.machine import frame_shape
from femmech.output.surfaces import cell_blocks

FORMATS = (".pvd", ".xdmf")


def write_mode_series(model: FEModel, modes: ModeSet, filename, indices=None) -> Path:
    """Mode shapes as a series: step k is mode k (1-based), frequency in ``frequency_hz``.

    Parameters
    ----------
    model : FEModel
    modes : ModeSet
        Of ``model`` (shapes (n_dof, n_modes)).
    filename : str or os.PathLike
        ``.pvd`` or ``.xdmf``; its folder must exist.
    indices : sequence of int, optional
        0-based modes to write (default all).

    Returns
    -------
    Path
    """
    check_sizes(model, modes)
    idx = mode_indices(modes, indices)
    steps = [(float(i + 1), _nodal(modes.shapes[:, i]),
              {"frequency_hz": float(modes.freq_hz[i])}) for i in idx]
    return _write(model, steps, filename, "mode number")


def write_sweep_series(model: FEModel, system: CoupledSystem, sweep, filename,
                       branches=None) -> Path:
    """Quasi-modes over the drive angle: one step per angle (time = angle in degrees).

    Parameters
    ----------
    model : FEModel
        The frame's FE model (the full mesh the fields live on).
    system : CoupledSystem
        The coupled machine the sweep was computed on; its frame is ``model`` itself or a
        :class:`~femmech.reduction.superelement.Superelement` of it (fields recovered).
    sweep : femmech.analysis.sweep.Sweep
        With ``vectors`` (computed with ``keep_vectors=True``).
    filename : str or os.PathLike
        ``.pvd`` or ``.xdmf``.
    branches : sequence of int, optional
        0-based tracked branches to write (default all).

    Returns
    -------
    Path
    """
    if sweep.vectors is None:
        raise ValueError("the sweep has no mode shapes: compute it with keep_vectors=True")
    n_branches = np.shape(sweep.freq_hz)[1]
    chosen = range(n_branches) if branches is None else [int(b) for b in branches]
    for b in chosen:
        if not 0 <= b < n_branches:
            raise ValueError(f"branch {b} does not exist: the sweep tracks {n_branches}"
                             " branches (0-based)")
    steps = []
    for a, phi in enumerate(np.asarray(sweep.phi)):
        fields, meta = {}, {}
        for b in chosen:
            u = _nodal(_frame_field(model, system, sweep.vectors[a][:, b]))
            fields[f"branch_{b + 1}_displacement"] = u["displacement"]
            fields[f"branch_{b + 1}_rotation"] = u["rotation"]
            meta[f"branch_{b + 1}_frequency_hz"] = float(sweep.freq_hz[a, b])
        steps.append((float(np.rad2deg(phi)), fields, meta))
    return _write(model, steps, filename, "drive angle (deg)")


def write_response_series(model: FEModel, system: CoupledSystem, response, filename,
                          every: int = 1) -> Path:
    """Frame displacements of a time response: one step per output time (time = t, s).

    Parameters
    ----------
    model : FEModel
        The frame's FE model.
    system : CoupledSystem
        The coupled machine the response was computed on.
    response : femmech.analysis.response.Response
        ``q`` (n_t, n) in the system's coordinates.
    filename : str or os.PathLike
        ``.pvd`` or ``.xdmf``.
    every : int
        Write every ``every``-th output time (default all).

    Returns
    -------
    Path
    """
    if every < 1:
        raise ValueError(f"every must be a positive integer, got {every}")
    q = np.asarray(response.q)
    steps = [(float(response.t[k]), _nodal(_frame_field(model, system, q[k])),
              {"drive_angle_deg": float(np.rad2deg(response.phi[k]))})
             for k in range(0, len(q), every)]
    return _write(model, steps, filename, "time (s)")


def _frame_field(model: FEModel, system: CoupledSystem, x) -> np.ndarray:
    """Full FE displacement (n_dof,) of the frame part of coupled coordinates x, checked
    against ``model`` (a superelement recovers the DOFs of the model it was reduced from)."""
    u = frame_shape(system, x)
    if u.shape[0] != model.n_dof:
        raise ValueError(f"the coupled system's frame recovers {u.shape[0]} DOFs, the model"
                         f" has {model.n_dof}: pass the FE model it was reduced from")
    return u


def _nodal(u_full: np.ndarray) -> dict:
    nodal = np.asarray(u_full, dtype=float).reshape(-1, DOF_PER_NODE)
    return {"displacement": nodal[:, :3].copy(), "rotation": nodal[:, 3:].copy()}


def _write(model: FEModel, steps: list, filename, time_label: str) -> Path:
    target = Path(filename)
    if target.suffix not in FORMATS:
        raise ValueError(f"series file {target.name}: the suffix must be one of {FORMATS}")
    if not target.parent.is_dir():
        raise FileNotFoundError(f"cannot write {target}: folder {target.parent} does not exist")
    if not steps:
        raise ValueError("a series needs at least one step")
    blocks = [(kind, cells) for kind, cells, _, _ in cell_blocks(model)]
    if target.suffix == ".xdmf":
        _write_xdmf(model.mesh.points, blocks, steps, target)
    else:
        _write_pvd(model.mesh.points, blocks, steps, target, time_label)
    return target


def _write_xdmf(points, blocks, steps, target: Path) -> None:
    with atomic_path(target) as tmp:
        with meshio.xdmf.TimeSeriesWriter(tmp, data_format="XML") as writer:
            writer.write_points_cells(points, blocks)
            for time, fields, _ in steps:
                writer.write_data(time, point_data=fields)


def _write_pvd(points, blocks, steps, target: Path, time_label: str) -> None:
    folder = target.with_name(f"{target.stem}_steps")
    staging = target.with_name(f".{target.stem}_steps.{os.getpid()}.tmp")
    shutil.rmtree(staging, ignore_errors=True)
    staging.mkdir()
    try:
        root = ET.Element("VTKFile", type="Collection", version="0.1")
        collection = ET.SubElement(root, "Collection")
        for k, (time, fields, meta) in enumerate(steps):
            name = f"step_{k:05d}.vtu"
            meshio.write(staging / name, meshio.Mesh(points, blocks, point_data=fields),
                         file_format="vtu")
            add_field_data(staging / name, {key: ("Float64", np.array([value]))
                                             for key, value in meta.items()})
            ET.SubElement(collection, "DataSet", timestep=repr(time), group="", part="0",
                          file=f"{folder.name}/{name}")
        root.insert(0, ET.Comment(f" femmech series: timestep = {time_label} "))
        old = target.with_name(f".{target.stem}_steps.{os.getpid()}.old")
        if folder.exists():
            os.replace(folder, old)  # the previous series stays whole until replaced
        os.replace(staging, folder)
        shutil.rmtree(old, ignore_errors=True)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    with atomic_path(target) as tmp:
        ET.ElementTree(root).write(tmp, encoding="utf-8", xml_declaration=True)


def read_pvd(filename) -> list[tuple[float, Path]]:
    """(time, VTU path) of each step of a PVD collection, in file order."""
    path = Path(filename)
    root = ET.parse(path).getroot()
    if root.get("type") != "Collection":
        raise ValueError(f"{path.name} is not a VTK collection (PVD) file")
    return [(float(d.get("timestep")), path.parent / d.get("file"))
            for d in root.iter("DataSet")]
