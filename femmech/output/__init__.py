"""Output of results: off-screen images (pyvista), VTU files (meshio), frequency tables.

pyvista is imported only inside the plotting functions, so importing this package
does not import pyvista.
"""

from femmech.output.diagrams import plot_mac, write_sweep_csv, write_sweep_json
from femmech.output.export import atomic_path, export_modes_vtu
from femmech.output.machine import plot_coupled_mode
from femmech.output.plot import mode_mesh, mode_scale, mode_title, plot_mode, plot_modes
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
    "write_frequency_csv",
    "write_sweep_csv",
    "write_sweep_json",
]
