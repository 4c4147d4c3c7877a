"""Natural modes of a welded box frame of steel plates on elastic mounts, with a rotor.

Physics: an open-bottom box, 1.2 m x 0.8 m x 0.6 m (``meshes/welded_box_frame.msh``,
made from ``meshes/welded_box_frame.geo`` with Gmsh), welded from steel plates: a 15 mm
top plate with a bearing bore (radius 90 mm), 8 mm side walls and a 10 mm transverse
rib. A ring of 40 x 40 x 4 mm hollow-section stiffeners runs round the walls at mid
height. Plates are flat MITC4/MITC3 shells at their mid-surfaces, the stiffeners
Timoshenko beams on the wall mid-surfaces (no offset), all with 6 DOF per node
(``K φ = ω² M φ``). A 120 kg rotor share (rotary inertia diag(1.5, 1.5, 0.8) kg m²)
sits at the bore centre, tied to the nodes of the bore edge by an interpolating
(RBE3-like) link, so the bearing load spreads over the bore without stiffening it. The
box stands on four elastic mounts at its bottom corners (springs to the ground:
3e5 N/m horizontally and 8e5 N/m vertically each).

Checks against independent estimates:

- mass: ``Σ ρ t A`` over the plates (areas from the geometry, the bore as the polygon
  of its mesh nodes) + ``ρ A L`` of the stiffeners + the rotor;
- the six lowest modes are the box rocking on its mounts; restricted to the six
  rigid-body motions of the undeformed box, Rayleigh-Ritz gives a 6x6 eigenproblem
  whose frequencies are upper bounds of the FE ones (Rayleigh's principle) and close
  to them while the box is much stiffer than the mounts.

Outputs (in ``--out``, default ``out/shell_frame_modes``): ``frequencies.txt``,
``frequencies.csv``, ``modes.vtu`` (line + quad cells; open in ParaView) and
``mode_01.png`` ...

Run: ``python examples/shell_frame_modes.py --out out/shell_frame_modes``
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import femmech as fm
from femmech.analysis.modes import rigid_body_frequencies
from femmech.fe import sections
from femmech.output import export_modes_vtu, frequency_table, plot_modes, write_frequency_csv

MESH = Path(__file__).resolve().parent.parent / "meshes" / "welded_box_frame.msh"
STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0, name="steel")
THICKNESS = {"top_plate": 0.015, "walls": 0.008, "rib": 0.010}  # m
STIFFENER = sections.rectangular_hollow(0.04, 0.04, 0.004)
MOUNT = np.array([3e5, 3e5, 8e5, 0.0, 0.0, 0.0])  # N/m (translations), N m/rad
ROTOR_MASS = 120.0  # kg
ROTOR_INERTIA = np.array([1.5, 1.5, 0.8])  # kg m², about the bore centre


def edges_to_node_sets(mesh: fm.Mesh, names) -> fm.Mesh:
    """Mesh without the line cells of the groups ``names``, which become node sets.

    Gmsh exports a physical curve (a bore edge, a clamped edge) as line cells; when they
    mark nodes rather than beams, this turns them into node groups for supports and
    links, and renumbers the remaining line cells and their groups.
    """
    lines = mesh.cells.get("line", np.empty((0, 2), dtype=np.int64))
    drop = np.zeros(len(lines), dtype=bool)
    node_sets = dict(mesh.node_sets)
    for name in names:
        idx = mesh.cell_sets.get(name, {}).get("line")
        if idx is None or set(mesh.cell_sets[name]) != {"line"}:
            raise ValueError(f"group {name!r} is not a group of line cells")
        drop[idx] = True
        node_sets[name] = np.unique(lines[idx])
    new = np.cumsum(~drop) - 1
    cell_sets = {}
    for name, by_type in mesh.cell_sets.items():
        if name in names:
            continue
        by_type = dict(by_type)
        if "line" in by_type:
            kept = by_type["line"][~drop[by_type["line"]]]
            by_type["line"] = new[kept]
        cell_sets[name] = by_type
    cells = {**mesh.cells, "line": lines[~drop]}
    return fm.Mesh(mesh.points, cells, cell_sets, node_sets)


def build(mesh_path=MESH) -> fm.FEModel:
    """The box model: plates → shells, stiffeners → beams, bore → interpolating link."""
    mesh = edges_to_node_sets(fm.read_mesh(mesh_path), ["bore"])
    shells = {name: fm.ShellProperty(t, STEEL) for name, t in THICKNESS.items()}
    mounts = [fm.Spring(f"foot_{i}", None, MOUNT) for i in range(1, 5)]
    return fm.build_model(
        mesh, {"stiffeners": fm.BeamProperty(STIFFENER, STEEL)}, shells=shells,
        masses=[fm.PointMass("bearing", ROTOR_MASS, ROTOR_INERTIA)],
        springs=mounts,
        interpolating_links=[fm.InterpolatingLink("bearing", "bore")],
    )


def main(out_dir="out/shell_frame_modes", n_modes: int = 12, n_images: int = 8) -> dict:
    """Compute the modes, write table, CSV, VTU and PNG images; return key numbers."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    model = build()
    result = fm.modes(model, n_modes=n_modes)
    table = frequency_table(result)
    (out / "frequencies.txt").write_text(table + "\n")
    write_frequency_csv(result, out / "frequencies.csv")
    export_modes_vtu(model, result, out / "modes.vtu")
    images = plot_modes(model, result, out, indices=range(min(n_images, result.n_modes)),
                        prefix="mode")
    print(f"welded box frame: {model.mesh.n_nodes} nodes, {model.n_free} free DOFs,"
          f" mass {model.total_mass():.1f} kg, solver {result.method}")
    print(table)
    print(f"wrote {len(images)} images, frequencies.txt/.csv and modes.vtu to {out}")
    return {
        "freq_hz": result.freq_hz,
        "rigid_body_estimate_hz": rigid_body_frequencies(model),
        "total_mass_kg": model.total_mass(),
        "n_free": model.n_free,
        "images": images,
        "vtu": out / "modes.vtu",
        "model": model,
    }


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/shell_frame_modes", help="output folder")
    parser.add_argument("--modes", type=int, default=12, help="number of modes")
    args = parser.parse_args()
    main(args.out, args.modes)
