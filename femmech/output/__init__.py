"""Output of results: off-screen images (pyvista), VTU files (meshio), frequency tables.

pyvista and matplotlib are imported only inside the plotting functions, and the names
below only on first use, so importing this package or any of its submodules imports
neither.

* :mod:`.plot`: off-screen images of mode shapes with pyvista (PNG), one scene and one
  camera per model.
* :mod:`.machine`: off-screen images of coupled machine modes (frame plus mechanisms).
* :mod:`.renderer`: the reusable off-screen scene of one model, redrawn per mode.
* :mod:`.mode_geometry`: what a mode image draws where: scale, curves, surfaces, glyphs.
* :mod:`.camera`: named views, a camera fitted to all drawn points, the axis triad.
* :mod:`.annotate`: title lines, colour bar, legend and triad around the 3D view (PIL).
* :mod:`.surfaces`: cells of a model by kind for drawing and export.
* :mod:`.export`: mode shapes to VTU files, and atomic file output.
* :mod:`.sweeps`: sweeps over the drive angle: quasi-eigenfrequency diagrams and MAC
  matrices (PNG), tables (CSV, JSON).
* :mod:`.charts`: speed units, axis scales and overlap-free label placement of the charts.
* :mod:`.stability_charts`: Floquet stability charts and speed studies (PNG).
* :mod:`.histories`: time histories and orbits of a forced response (PNG, CSV).
* :mod:`.tables`: frequency tables of a mode set (text, CSV).
* :mod:`.report`: one self-contained HTML report page; :mod:`.formatting`: its
  engineering numbers (value, unit, significant digits).
* :mod:`.animate`: a mode shape swinging through a period (GIF); :mod:`.series`: result
  series for ParaView; :mod:`.campbell`: Campbell diagrams of chains;
  :mod:`.local_axes`: the local axes of beam elements (PNG); :mod:`.chain_plots`: a chain
  sweep by method (PNG).
* :mod:`.response_plots`: forced-response histories of a scene (PNG);
  :mod:`.speed_error`: reduced-versus-full error over speed (PNG); :mod:`.csv_rows`: CSV
  tables written atomically.
* :mod:`.folder`: one run, one output folder (staging folder and manifest);
  :mod:`.folder_swap`: its crash-safe swap (run lock, journal, recovery of killed runs).

Uses analysis, coupling, reduction, fe and errors; of femmech only
:mod:`femmech.scene` imports it.
"""

from femmech.deprecation import lazy_names

_LAZY = {
    "atomic_path": "femmech.output.export",
    "export_modes_vtu": "femmech.output.export",
    "plot_coupled_mode": "femmech.output.machine",
    "mode_mesh": "femmech.output.plot",
    "mode_scale": "femmech.output.plot",
    "mode_title": "femmech.output.plot",
    "plot_mode": "femmech.output.plot",
    "plot_modes": "femmech.output.plot",
    "plot_mac": "femmech.output.sweeps",
    "plot_quasi_frequencies": "femmech.output.sweeps",
    "write_sweep_csv": "femmech.output.sweeps",
    "write_sweep_json": "femmech.output.sweeps",
    "frequency_table": "femmech.output.tables",
    "write_frequency_csv": "femmech.output.tables",
}
"""Public name → its module, imported on first use: importing a submodule (the scene
reader uses :mod:`.formatting` and :mod:`.charts`) does not import the plotting modules."""

__all__ = [
    "atomic_path",
    "export_modes_vtu",
    "frequency_table",
    "mode_mesh",
    "mode_scale",
    "mode_title",
    "plot_coupled_mode",
    "plot_mac",
    "plot_mode",
    "plot_modes",
    "plot_quasi_frequencies",
    "write_frequency_csv",
    "write_sweep_csv",
    "write_sweep_json",
]


__getattr__, __dir__ = lazy_names(__name__, _LAZY)
