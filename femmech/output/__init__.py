"""Output of results: off-screen images (pyvista), VTU files (meshio), frequency tables.

pyvista is imported only inside the plotting functions, so importing this package
does not import pyvista.

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
* :mod:`.report`: one self-contained HTML report page.
* :mod:`.folder`: one run, one output folder (staging folder and manifest);
  :mod:`.folder_swap`: its crash-safe swap (run lock, journal, recovery of killed runs).

Stage 7 (output): uses analysis, coupling, reduction, fe and errors; of femmech only
:mod:`femmech.scene` imports it.
"""

from femmech.output.export import atomic_path, export_modes_vtu
from femmech.output.machine import plot_coupled_mode
from femmech.output.plot import mode_mesh, mode_scale, mode_title, plot_mode, plot_modes
from femmech.output.sweeps import (
    plot_mac,
    plot_quasi_frequencies,
    write_sweep_csv,
    write_sweep_json,
)
from femmech.output.tables import frequency_table, write_frequency_csv

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
