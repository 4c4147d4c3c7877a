"""Moved public names keep working from their old places, with a DeprecationWarning.

The tables below were taken from git history: the public API surface (every module's
public top-level names, and the re-exports of package ``__init__`` files) at the commit
before the first restructure into packages (9b9c9e1) and at every commit since, compared
with the names importable now. Each name that no longer imports from its old place is
either MOVED (old module, old name, new dotted path) or REMOVED (with the reason and what
replaces it). docs/architecture.md ("Moved names") shows the same table by module.
"""

from __future__ import annotations

import ast
import importlib
import re
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "femmech"

MOVED = [
    ("femmech.scene.analyses", "CheckSpec", "femmech.scene.kinds.check.CheckSpec"),
    ("femmech.scene.analyses", "DriveEventSpec", "femmech.scene.kinds.drive_event.DriveEventSpec"),
    ("femmech.scene.analyses", "MAX_ANIMATIONS", "femmech.scene.kinds.common.MAX_ANIMATIONS"),
    ("femmech.scene.analyses", "MAX_DRIVE_EVALUATIONS",
     "femmech.scene.kinds.common.MAX_DRIVE_EVALUATIONS"),
    ("femmech.scene.analyses", "MAX_DRIVE_STEPS", "femmech.scene.kinds.common.MAX_DRIVE_STEPS"),
    ("femmech.scene.analyses", "MAX_HISTORIES", "femmech.scene.kinds.common.MAX_HISTORIES"),
    ("femmech.scene.analyses", "MAX_IMAGES", "femmech.scene.kinds.common.MAX_IMAGES"),
    ("femmech.scene.analyses", "MAX_LEVELS", "femmech.scene.kinds.common.MAX_LEVELS"),
    ("femmech.scene.analyses", "MAX_POINTS", "femmech.scene.kinds.common.MAX_POINTS"),
    ("femmech.scene.analyses", "MAX_RUNS", "femmech.scene.kinds.common.MAX_RUNS"),
    ("femmech.scene.analyses", "MAX_STEPS", "femmech.scene.kinds.common.MAX_STEPS"),
    ("femmech.scene.analyses", "MAX_SWEEP_POINTS", "femmech.scene.kinds.common.MAX_SWEEP_POINTS"),
    ("femmech.scene.analyses", "ModesSpec", "femmech.scene.kinds.modes.ModesSpec"),
    ("femmech.scene.analyses", "ResponseSpec", "femmech.scene.kinds.response.ResponseSpec"),
    ("femmech.scene.analyses", "StabilitySpec", "femmech.scene.kinds.stability.StabilitySpec"),
    ("femmech.scene.analyses", "SweepSpec", "femmech.scene.kinds.sweep.SweepSpec"),
    ("femmech.scene.analyses", "read_values", "femmech.scene.kinds.common.read_values"),
    ("femmech.scene.chain", "CampbellSpec", "femmech.scene.kinds.campbell.CampbellSpec"),
    ("femmech.scene.chain", "ChainSweepSpec", "femmech.scene.kinds.chain_sweep.ChainSweepSpec"),
    ("femmech.scene.chain", "MAX_HARMONICS", "femmech.scene.kinds.common.MAX_HARMONICS"),
    ("femmech.scene.chain", "plot_method_sweeps", "femmech.output.chain_plots.plot_method_sweeps"),
    ("femmech.scene.chain", "read_campbell", "femmech.scene.kinds.campbell.read"),
    ("femmech.scene.chain", "read_chain_sweep", "femmech.scene.kinds.chain_sweep.read"),
    ("femmech.scene.tasks", "TASKS", "femmech.scene.registry.RUNNERS"),
    ("femmech.scene.tasks", "matched_full_modes", "femmech.scene.kinds.check.matched_full_modes"),
    ("femmech.scene.tasks", "run_campbell", "femmech.scene.kinds.campbell.run"),
    ("femmech.scene.tasks", "run_chain_sweep", "femmech.scene.kinds.chain_sweep.run"),
    ("femmech.scene.tasks", "run_check", "femmech.scene.kinds.check.run"),
    ("femmech.scene.tasks", "run_drive_event", "femmech.scene.kinds.drive_event.run"),
    ("femmech.scene.tasks", "run_modes", "femmech.scene.kinds.modes.run"),
    ("femmech.scene.tasks", "run_response", "femmech.scene.kinds.response.run"),
    ("femmech.scene.tasks", "run_stability", "femmech.scene.kinds.stability.run"),
    ("femmech.scene.tasks", "run_sweep", "femmech.scene.kinds.sweep.run"),
    ("femmech.scene.tasks", "run_synthesis", "femmech.scene.kinds.synthesis.run"),
    ("femmech.analysis.stability", "ATOL", "femmech.analysis.magnus.ATOL"),
    ("femmech.analysis.stability", "Floquet", "femmech.analysis.floquet.Floquet"),
    ("femmech.analysis.stability", "GAUSS_OFFSETS", "femmech.analysis.magnus.GAUSS_OFFSETS"),
    ("femmech.analysis.stability", "Monodromy", "femmech.analysis.magnus.Monodromy"),
    ("femmech.analysis.stability", "coupled_floquet", "femmech.analysis.floquet.coupled_floquet"),
    ("femmech.analysis.stability", "coupled_monodromy",
     "femmech.analysis.floquet.coupled_monodromy"),
    ("femmech.analysis.stability", "expm_stack", "femmech.analysis.magnus.expm_stack"),
    ("femmech.analysis.stability", "first_order_matrices",
     "femmech.analysis.magnus.first_order_matrices"),
    ("femmech.analysis.stability", "floquet", "femmech.analysis.floquet.floquet"),
    ("femmech.analysis.stability", "integrate_monodromy",
     "femmech.analysis.magnus.integrate_monodromy"),
    ("femmech.analysis.stability", "monodromy", "femmech.analysis.floquet.monodromy"),
    ("femmech.analysis.stability", "step_grid", "femmech.analysis.magnus.step_grid"),
    ("femmech.assembly", "assemble", "femmech.fe.assembly.assemble"),
    ("femmech.cache", "CacheInfo", "femmech.scene.cache_folder.CacheInfo"),
    ("femmech.cache", "CachedReduction", "femmech.scene.cache.CachedReduction"),
    ("femmech.cache", "DEFAULT_MAX_BYTES", "femmech.scene.cache_folder.DEFAULT_MAX_BYTES"),
    ("femmech.cache", "LOCK_TIMEOUT", "femmech.scene.cache.LOCK_TIMEOUT"),
    ("femmech.cache", "MAX_BYTES_ENV", "femmech.scene.cache_folder.MAX_BYTES_ENV"),
    ("femmech.cache", "STALE_AGE", "femmech.scene.cache_folder.STALE_AGE"),
    ("femmech.cache", "cache_info", "femmech.scene.cache_folder.cache_info"),
    ("femmech.cache", "cache_max_bytes", "femmech.scene.cache_folder.cache_max_bytes"),
    ("femmech.cache", "cached_reduction", "femmech.scene.cache.cached_reduction"),
    ("femmech.cache", "clear_cache", "femmech.scene.cache_folder.clear_cache"),
    ("femmech.cache", "default_cache_dir", "femmech.scene.cache_folder.default_cache_dir"),
    ("femmech.cache", "entry_paths", "femmech.scene.cache_folder.entry_paths"),
    ("femmech.cache", "format_cache_info", "femmech.scene.cache_folder.format_cache_info"),
    ("femmech.cache", "lock_path", "femmech.scene.cache_folder.lock_path"),
    ("femmech.cache", "read_entry", "femmech.scene.cache.read_entry"),
    ("femmech.cache", "remove_stale_temporaries",
     "femmech.scene.cache_folder.remove_stale_temporaries"),
    ("femmech.cache", "write_entry", "femmech.scene.cache.write_entry"),
    ("femmech.checks", "CORNERS", "femmech.fe.checks.CORNERS"),
    ("femmech.checks", "FREQ_ABOVE_HZ", "femmech.fe.checks.FREQ_ABOVE_HZ"),
    ("femmech.checks", "FREQ_BELOW_HZ", "femmech.fe.checks.FREQ_BELOW_HZ"),
    ("femmech.checks", "Finding", "femmech.fe.checks.Finding"),
    ("femmech.checks", "K_NEAREST", "femmech.fe.checks.K_NEAREST"),
    ("femmech.checks", "LOCAL_FRACTION", "femmech.fe.checks.LOCAL_FRACTION"),
    ("femmech.checks", "MASS_RATIO_RANGE", "femmech.fe.checks.MASS_RATIO_RANGE"),
    ("femmech.checks", "MAX_LISTED", "femmech.fe.checks.MAX_LISTED"),
    ("femmech.checks", "MAX_PAIRS", "femmech.fe.checks.MAX_PAIRS"),
    ("femmech.checks", "MMTS_EXTENT_BELOW", "femmech.fe.checks.MMTS_EXTENT_BELOW"),
    ("femmech.checks", "MMTS_RHO_BELOW", "femmech.fe.checks.MMTS_RHO_BELOW"),
    ("femmech.checks", "NEAR_NODE_TOL", "femmech.fe.checks.NEAR_NODE_TOL"),
    ("femmech.checks", "SI_EXTENT_ABOVE", "femmech.fe.checks.SI_EXTENT_ABOVE"),
    ("femmech.checks", "SI_E_ABOVE", "femmech.fe.checks.SI_E_ABOVE"),
    ("femmech.checks", "SOLID_RHO", "femmech.fe.checks.SOLID_RHO"),
    ("femmech.checks", "WAVE_SPEED_RANGE", "femmech.fe.checks.WAVE_SPEED_RANGE"),
    ("femmech.checks", "cell_measure", "femmech.fe.checks.cell_measure"),
    ("femmech.checks", "frequency_findings", "femmech.fe.checks.frequency_findings"),
    ("femmech.checks", "local_size", "femmech.fe.checks.local_size"),
    ("femmech.checks", "loose_parts", "femmech.fe.checks.loose_parts"),
    ("femmech.checks", "near_node_findings", "femmech.fe.checks.near_node_findings"),
    ("femmech.checks", "near_nodes", "femmech.fe.checks.near_nodes"),
    ("femmech.checks", "unit_findings", "femmech.fe.checks.unit_findings"),
    ("femmech.checks", "warn", "femmech.fe.checks.warn"),
    ("femmech.constraints", "EquationSet", "femmech.fe.constraints.EquationSet"),
    ("femmech.constraints", "InterpolatingLink", "femmech.fe.constraints.InterpolatingLink"),
    ("femmech.constraints", "RigidLink", "femmech.fe.constraints.RigidLink"),
    ("femmech.constraints", "Support", "femmech.fe.constraints.Support"),
    ("femmech.constraints", "add_interpolating_link",
     "femmech.fe.constraints.add_interpolating_link"),
    ("femmech.constraints", "add_rigid_links", "femmech.fe.constraints.add_rigid_links"),
    ("femmech.constraints", "constraint_transform", "femmech.fe.constraints.constraint_transform"),
    ("femmech.constraints", "fixed_mask", "femmech.fe.constraints.fixed_mask"),
    ("femmech.constraints", "interpolation_matrix", "femmech.fe.constraints.interpolation_matrix"),
    ("femmech.constraints", "rigid_link_matrix", "femmech.fe.constraints.rigid_link_matrix"),
    ("femmech.dofs", "COMPONENTS", "femmech.fe.dofs.COMPONENTS"),
    ("femmech.dofs", "DOF_PER_NODE", "femmech.fe.dofs.DOF_PER_NODE"),
    ("femmech.dofs", "components", "femmech.fe.dofs.components"),
    ("femmech.dofs", "dof_label", "femmech.fe.dofs.dof_label"),
    ("femmech.dofs", "element_dofs", "femmech.fe.dofs.element_dofs"),
    ("femmech.dofs", "node_dofs", "femmech.fe.dofs.node_dofs"),
    ("femmech.elements.beam", "beam_matrices", "femmech.fe.elements.beam.beam_matrices"),
    ("femmech.elements.beam", "bending_matrices", "femmech.fe.elements.beam.bending_matrices"),
    ("femmech.elements.beam", "bending_shape_functions",
     "femmech.fe.elements.beam.bending_shape_functions"),
    ("femmech.elements.beam", "local_frames", "femmech.fe.elements.beam.local_frames"),
    ("femmech.elements.beam", "local_matrices", "femmech.fe.elements.beam.local_matrices"),
    ("femmech.elements.beam", "rotate_to_global", "femmech.fe.elements.beam.rotate_to_global"),
    ("femmech.elements.shell", "DRILLING", "femmech.fe.elements.shell.DRILLING"),
    ("femmech.elements.shell", "ELEMENT_CHUNK", "femmech.fe.elements.shell.ELEMENT_CHUNK"),
    ("femmech.elements.shell", "SHEAR_FACTOR", "femmech.fe.elements.shell.SHEAR_FACTOR"),
    ("femmech.elements.shell", "STABILISATION", "femmech.fe.elements.shell.STABILISATION"),
    ("femmech.elements.shell", "shell_frames", "femmech.fe.elements.shell.shell_frames"),
    ("femmech.elements.shell", "shell_matrices", "femmech.fe.elements.shell.shell_matrices"),
    ("femmech.elements.solid", "CHUNK_ENTRIES", "femmech.fe.elements.solid.CHUNK_ENTRIES"),
    ("femmech.elements.solid", "REFERENCE_NODES", "femmech.fe.elements.solid.REFERENCE_NODES"),
    ("femmech.elements.solid", "SOLID_TYPES", "femmech.fe.elements.solid.SOLID_TYPES"),
    ("femmech.elements.solid", "assemble_solid", "femmech.fe.elements.solid.assemble_solid"),
    ("femmech.elements.solid", "reference_element", "femmech.fe.elements.solid.reference_element"),
    ("femmech.elements.solid", "solid_dofs", "femmech.fe.elements.solid.solid_dofs"),
    ("femmech.elements.solid", "solid_matrices", "femmech.fe.elements.solid.solid_matrices"),
    ("femmech.io", "MAX_MESH_FILE_BYTES", "femmech.fe.mesh_io.MAX_MESH_FILE_BYTES"),
    ("femmech.io", "from_meshio", "femmech.fe.mesh_io.from_meshio"),
    ("femmech.io", "read_mesh", "femmech.fe.mesh_io.read_mesh"),
    ("femmech.linalg", "ALL_PAIRS_FRACTION", "femmech.solve.dense.ALL_PAIRS_FRACTION"),
    ("femmech.linalg", "BLOCK_SIZE", "femmech.solve.lanczos.BLOCK_SIZE"),
    ("femmech.linalg", "DENSE_BELOW", "femmech.solve.eigen.DENSE_BELOW"),
    ("femmech.linalg", "EigenResult", "femmech.solve.eigen.EigenResult"),
    ("femmech.linalg", "FAR_SHIFT", "femmech.solve.lanczos.FAR_SHIFT"),
    ("femmech.linalg", "GUARD_TOL", "femmech.solve.lanczos.GUARD_TOL"),
    ("femmech.linalg", "LANCZOS_TOL", "femmech.solve.lanczos.LANCZOS_TOL"),
    ("femmech.linalg", "MAX_BASIS_BYTES", "femmech.solve.lanczos.MAX_BASIS_BYTES"),
    ("femmech.linalg", "MAX_DEFLATIONS", "femmech.solve.eigen.MAX_DEFLATIONS"),
    ("femmech.linalg", "MAX_SOLVES_PER_MODE", "femmech.solve.lanczos.MAX_SOLVES_PER_MODE"),
    ("femmech.linalg", "PROBES", "femmech.solve.lanczos.PROBES"),
    ("femmech.linalg", "REORTHOGONALIZE_BELOW", "femmech.solve.lanczos.REORTHOGONALIZE_BELOW"),
    ("femmech.linalg", "RESIDUAL_TOL", "femmech.solve.residuals.RESIDUAL_TOL"),
    ("femmech.linalg", "RIGID_TOL", "femmech.solve.eigen.RIGID_TOL"),
    ("femmech.linalg", "SEMI_ORTHOGONAL", "femmech.solve.lanczos.SEMI_ORTHOGONAL"),
    ("femmech.linalg", "STREAM_COLUMNS", "femmech.solve.lanczos.STREAM_COLUMNS"),
    ("femmech.linalg", "default_shift", "femmech.solve.pencil.default_shift"),
    ("femmech.linalg", "dense_symmetric", "femmech.solve.dense.dense_symmetric"),
    ("femmech.linalg", "eigenvalue_scale", "femmech.solve.pencil.eigenvalue_scale"),
    ("femmech.linalg", "factorize", "femmech.solve.pencil.factorize"),
    ("femmech.linalg", "inertia_below", "femmech.solve.sturm.inertia_below"),
    ("femmech.linalg", "normalize_modes", "femmech.solve.residuals.normalize_modes"),
    ("femmech.linalg", "residual_limits", "femmech.solve.residuals.residual_limits"),
    ("femmech.linalg", "residuals", "femmech.solve.residuals.residuals"),
    ("femmech.linalg", "solve_symmetric", "femmech.solve.eigen.solve_symmetric"),
    ("femmech.lobpcg", "DOF_PER_NODE", "femmech.fe.dofs.DOF_PER_NODE"),
    ("femmech.lobpcg", "amg_preconditioner", "femmech.solve.lobpcg.amg_preconditioner"),
    ("femmech.lobpcg", "lobpcg_symmetric", "femmech.solve.lobpcg.lobpcg_symmetric"),
    ("femmech.lobpcg", "near_nullspace", "femmech.fe.nullspace.near_nullspace"),
    ("femmech.lobpcg", "node_blocksize", "femmech.fe.nullspace.node_blocksize"),
    ("femmech.lobpcg", "rigid_body_modes", "femmech.fe.nullspace.rigid_body_modes"),
    ("femmech.lumped", "PointMass", "femmech.fe.lumped.PointMass"),
    ("femmech.lumped", "Spring", "femmech.fe.lumped.Spring"),
    ("femmech.materials", "ALUMINIUM", "femmech.fe.materials.ALUMINIUM"),
    ("femmech.materials", "Material", "femmech.fe.materials.Material"),
    ("femmech.materials", "STEEL", "femmech.fe.materials.STEEL"),
    ("femmech.materials", "check_real", "femmech.fe.materials.check_real"),
    ("femmech.mechanisms", "plot_quasi_frequencies",
     "femmech.output.sweeps.plot_quasi_frequencies"),
    ("femmech.mechanisms.quasi_modes", "plot_quasi_frequencies",
     "femmech.output.sweeps.plot_quasi_frequencies"),
    ("femmech.mesh", "MAX_CELLS", "femmech.fe.mesh.MAX_CELLS"),
    ("femmech.mesh", "MAX_NODES", "femmech.fe.mesh.MAX_NODES"),
    ("femmech.mesh", "Mesh", "femmech.fe.mesh.Mesh"),
    ("femmech.mesh", "NODES_PER_CELL", "femmech.fe.mesh.NODES_PER_CELL"),
    ("femmech.mesh", "line_submesh", "femmech.fe.mesh.line_submesh"),
    ("femmech.mesh", "merged_node_index", "femmech.fe.mesh.merged_node_index"),
    ("femmech.model", "BEAM_PROPERTY_COLUMNS", "femmech.fe.model.BEAM_PROPERTY_COLUMNS"),
    ("femmech.model", "BeamProperty", "femmech.fe.model.BeamProperty"),
    ("femmech.model", "BeamSet", "femmech.fe.model.BeamSet"),
    ("femmech.model", "FEModel", "femmech.fe.model.FEModel"),
    ("femmech.model", "build_model", "femmech.fe.model.build_model"),
    ("femmech.model", "model_findings", "femmech.fe.model.model_findings"),
    ("femmech.model", "node_index", "femmech.fe.model.node_index"),
    ("femmech.model", "node_indices", "femmech.fe.model.node_indices"),
    ("femmech.output.diagrams", "chart_legend", "femmech.output.stability_charts.chart_legend"),
    ("femmech.output.diagrams", "plot_mac", "femmech.output.sweeps.plot_mac"),
    ("femmech.output.diagrams", "plot_orbit", "femmech.output.histories.plot_orbit"),
    ("femmech.output.diagrams", "plot_speed_study",
     "femmech.output.stability_charts.plot_speed_study"),
    ("femmech.output.diagrams", "plot_stability_chart",
     "femmech.output.stability_charts.plot_stability_chart"),
    ("femmech.output.diagrams", "plot_time_histories",
     "femmech.output.histories.plot_time_histories"),
    ("femmech.output.diagrams", "stability_figure",
     "femmech.output.stability_charts.stability_figure"),
    ("femmech.output.diagrams", "write_history_csv", "femmech.output.histories.write_history_csv"),
    ("femmech.output.diagrams", "write_sweep_csv", "femmech.output.sweeps.write_sweep_csv"),
    ("femmech.output.diagrams", "write_sweep_json", "femmech.output.sweeps.write_sweep_json"),
    ("femmech.parts", "ShellProperty", "femmech.fe.parts.ShellProperty"),
    ("femmech.parts", "ShellSet", "femmech.fe.parts.ShellSet"),
    ("femmech.parts", "SolidProperty", "femmech.fe.parts.SolidProperty"),
    ("femmech.parts", "SolidSet", "femmech.fe.parts.SolidSet"),
    ("femmech.parts", "check_part_types", "femmech.fe.parts.check_part_types"),
    ("femmech.parts", "shell_blocks", "femmech.fe.parts.shell_blocks"),
    ("femmech.parts", "solid_parts", "femmech.fe.parts.solid_parts"),
    ("femmech.recovery", "beam_deflection_curves", "femmech.fe.recovery.beam_deflection_curves"),
    ("femmech.reduction", "PIVOT_RTOL", "femmech.reduction.component_modes.PIVOT_RTOL"),
    ("femmech.reduction", "SYMMETRIC_BLOCK", "femmech.reduction.products.SYMMETRIC_BLOCK"),
    ("femmech.reduction", "THIN_PRODUCT_FLOPS", "femmech.reduction.products.THIN_PRODUCT_FLOPS"),
    ("femmech.reduction.reduce", "CUTOFF_FACTOR",
     "femmech.reduction.component_modes.CUTOFF_FACTOR"),
    ("femmech.reduction.reduce", "FORMAT_VERSION",
     "femmech.reduction.superelement_file.FORMAT_VERSION"),
    ("femmech.reduction.reduce", "PIVOT_RTOL", "femmech.reduction.component_modes.PIVOT_RTOL"),
    ("femmech.reduction.reduce", "SYMMETRIC_BLOCK", "femmech.reduction.products.SYMMETRIC_BLOCK"),
    ("femmech.reduction.reduce", "Superelement", "femmech.reduction.superelement.Superelement"),
    ("femmech.reduction.reduce", "THIN_PRODUCT_FLOPS",
     "femmech.reduction.products.THIN_PRODUCT_FLOPS"),
    ("femmech.reduction.reduce", "craig_bampton",
     "femmech.reduction.component_modes.craig_bampton"),
    ("femmech.reduction.reduce", "frequency_error_estimates",
     "femmech.reduction.estimate.frequency_error_estimates"),
    ("femmech.reduction.reduce", "guyan", "femmech.reduction.component_modes.guyan"),
    ("femmech.reduction.reduce", "interface_dofs", "femmech.reduction.superelement.interface_dofs"),
    ("femmech.reduction.superelement_archive", "CHUNK",
     "femmech.reduction.superelement_file.CHUNK"),
    ("femmech.reduction.superelement_archive", "DEFLATE_MAX_RATIO",
     "femmech.reduction.superelement_file.DEFLATE_MAX_RATIO"),
    ("femmech.reduction.superelement_archive", "EXPANSION_FLOOR",
     "femmech.reduction.superelement_file.EXPANSION_FLOOR"),
    ("femmech.reduction.superelement_archive", "MAX_EXPANSION",
     "femmech.reduction.superelement_file.MAX_EXPANSION"),
    ("femmech.reduction.superelement_archive", "MAX_HEADER",
     "femmech.reduction.superelement_file.MAX_HEADER"),
    ("femmech.reduction.superelement_archive", "MAX_META_CHARS",
     "femmech.reduction.superelement_file.MAX_META_CHARS"),
    ("femmech.reduction.superelement_archive", "ZIP_OVERHEAD",
     "femmech.reduction.superelement_file.ZIP_OVERHEAD"),
    ("femmech.reduction.superelement_archive", "ZIP_TAIL",
     "femmech.reduction.superelement_file.ZIP_TAIL"),
    ("femmech.reduction.superelement_archive", "open_regular",
     "femmech.reduction.superelement_file.open_regular"),
    ("femmech.reduction.superelement_archive", "read_regular",
     "femmech.reduction.superelement_file.read_regular"),
    ("femmech.reduction.superelement_checks", "MAX_TIMINGS",
     "femmech.reduction.superelement_file.MAX_TIMINGS"),
    ("femmech.reduction.superelement_checks", "PSD_RTOL",
     "femmech.reduction.superelement_file.PSD_RTOL"),
    ("femmech.reduction.superelement_checks", "SYMMETRY_RTOL",
     "femmech.reduction.superelement_file.SYMMETRY_RTOL"),
    ("femmech.reduction.superelement_format", "ARRAYS",
     "femmech.reduction.superelement_file.ARRAYS"),
    ("femmech.reduction.superelement_format", "FIELDS",
     "femmech.reduction.superelement_file.FIELDS"),
    ("femmech.reduction.superelement_format", "FLOATS",
     "femmech.reduction.superelement_file.FLOATS"),
    ("femmech.reduction.superelement_format", "FORMAT_VERSION",
     "femmech.reduction.superelement_file.FORMAT_VERSION"),
    ("femmech.reduction.superelement_format", "INDICES",
     "femmech.reduction.superelement_file.INDICES"),
    ("femmech.reduction.superelement_format", "METHODS",
     "femmech.reduction.superelement_file.METHODS"),
    ("femmech.reduction.superelement_format", "READABLE_VERSIONS",
     "femmech.reduction.superelement_file.READABLE_VERSIONS"),
    ("femmech.reduction.superelement_format", "checksums",
     "femmech.reduction.superelement_file.checksums"),
    ("femmech.reduction.superelement_format", "field_digest",
     "femmech.reduction.superelement_file.field_digest"),
    ("femmech.reduction.superelement_format", "meta_digest",
     "femmech.reduction.superelement_file.meta_digest"),
    ("femmech.report", "CSS", "femmech.output.report.CSS"),
    ("femmech.report", "Figure", "femmech.output.report.Figure"),
    ("femmech.report", "Flagged", "femmech.output.report.Flagged"),
    ("femmech.report", "Section", "femmech.output.report.Section"),
    ("femmech.report", "Table", "femmech.output.report.Table"),
    ("femmech.report", "render_report", "femmech.output.report.render_report"),
    ("femmech.report", "render_section", "femmech.output.report.render_section"),
    ("femmech.report", "render_table", "femmech.output.report.render_table"),
    ("femmech.report", "write_report", "femmech.output.report.write_report"),
    ("femmech.scene", "GENERAL_OPTIONAL", "femmech.scene.load.GENERAL_OPTIONAL"),
    ("femmech.scene", "InterfaceSpec", "femmech.scene.load.InterfaceSpec"),
    ("femmech.scene", "ItemSpec", "femmech.scene.load.ItemSpec"),
    ("femmech.scene", "MaterialSpec", "femmech.fe.materials.Material"),
    ("femmech.scene.load", "MaterialSpec", "femmech.fe.materials.Material"),
    ("femmech.scene", "PartSpec", "femmech.scene.load.PartSpec"),
    ("femmech.scene", "REDUCTIONS", "femmech.scene.load.REDUCTIONS"),
    ("femmech.scene", "ReductionSpec", "femmech.scene.load.ReductionSpec"),
    ("femmech.scene", "SECTION_SHAPES", "femmech.scene.load.SECTION_SHAPES"),
    ("femmech.scene", "SectionSpec", "femmech.scene.load.SectionSpec"),
    ("femmech.scene", "ShellSpec", "femmech.scene.load.ShellSpec"),
    ("femmech.scene", "SolidSpec", "femmech.scene.load.SolidSpec"),
    ("femmech.scene.cache", "CacheInfo", "femmech.scene.cache_folder.CacheInfo"),
    ("femmech.scene.cache", "DEFAULT_MAX_BYTES", "femmech.scene.cache_folder.DEFAULT_MAX_BYTES"),
    ("femmech.scene.cache", "MAX_BYTES_ENV", "femmech.scene.cache_folder.MAX_BYTES_ENV"),
    ("femmech.scene.cache", "STALE_AGE", "femmech.scene.cache_folder.STALE_AGE"),
    ("femmech.scene.cache", "cache_info", "femmech.scene.cache_folder.cache_info"),
    ("femmech.scene.cache", "clear_cache", "femmech.scene.cache_folder.clear_cache"),
    ("femmech.scene.cache", "default_cache_dir", "femmech.scene.cache_folder.default_cache_dir"),
    ("femmech.scene.cache", "format_cache_info", "femmech.scene.cache_folder.format_cache_info"),
    ("femmech.scene.mechanisms", "FACTORIES", "femmech.scene.machine.BUILTIN_MODELS"),
    ("femmech.scene.tasks", "summary_section", "femmech.scene.summary.summary_section"),
    ("femmech.scene_analyses", "Analyses", "femmech.scene.analyses.Analyses"),
    ("femmech.scene_analyses", "CheckSpec", "femmech.scene.analyses.CheckSpec"),
    ("femmech.scene_analyses", "MAX_HISTORIES", "femmech.scene.analyses.MAX_HISTORIES"),
    ("femmech.scene_analyses", "MAX_IMAGES", "femmech.scene.analyses.MAX_IMAGES"),
    ("femmech.scene_analyses", "MAX_LEVELS", "femmech.scene.analyses.MAX_LEVELS"),
    ("femmech.scene_analyses", "MAX_MODES", "femmech.scene.analyses.MAX_MODES"),
    ("femmech.scene_analyses", "MAX_POINTS", "femmech.scene.analyses.MAX_POINTS"),
    ("femmech.scene_analyses", "MAX_STEPS", "femmech.scene.analyses.MAX_STEPS"),
    ("femmech.scene_analyses", "MAX_SWEEP_POINTS", "femmech.scene.analyses.MAX_SWEEP_POINTS"),
    ("femmech.scene_analyses", "ModesSpec", "femmech.scene.analyses.ModesSpec"),
    ("femmech.scene_analyses", "ResponseSpec", "femmech.scene.analyses.ResponseSpec"),
    ("femmech.scene_analyses", "StabilitySpec", "femmech.scene.analyses.StabilitySpec"),
    ("femmech.scene_analyses", "SweepSpec", "femmech.scene.analyses.SweepSpec"),
    ("femmech.scene_analyses", "read_analyses", "femmech.scene.analyses.read_analyses"),
    ("femmech.scene_build", "Prepared", "femmech.scene.build.Prepared"),
    ("femmech.scene_build", "check_part", "femmech.scene.build.check_part"),
    ("femmech.scene_build", "edges_to_node_sets", "femmech.scene.build.edges_to_node_sets"),
    ("femmech.scene_build", "fail", "femmech.scene.load.fail"),
    ("femmech.scene_build", "finding_lines", "femmech.scene.build.finding_lines"),
    ("femmech.scene_build", "interface", "femmech.scene.build.interface"),
    ("femmech.scene_build", "machine_mounts", "femmech.scene.build.machine_mounts"),
    ("femmech.scene_build", "merged_mesh", "femmech.scene.build.merged_mesh"),
    ("femmech.scene_build", "own_coordinates", "femmech.scene.build.own_coordinates"),
    ("femmech.scene_build", "part_findings", "femmech.scene.build.part_findings"),
    ("femmech.scene_build", "part_mesh", "femmech.scene.build.part_mesh"),
    ("femmech.scene_build", "part_model", "femmech.scene.build.part_model"),
    ("femmech.scene_build", "plain", "femmech.scene.build.plain"),
    ("femmech.scene_build", "prepare", "femmech.scene.build.prepare"),
    ("femmech.scene_build", "reduce_part", "femmech.scene.build.reduce_part"),
    ("femmech.scene_build", "reduction_key_data", "femmech.scene.build.reduction_key_data"),
    ("femmech.scene_build", "sha256_key", "femmech.scene.build.sha256_key"),
    ("femmech.scene_machine", "AttachmentSpec", "femmech.scene.machine.AttachmentSpec"),
    ("femmech.scene_machine", "BUILTIN_MODELS", "femmech.scene.machine.BUILTIN_MODELS"),
    ("femmech.scene_machine", "MOTION_LAWS", "femmech.scene.machine.MOTION_LAWS"),
    ("femmech.scene_machine", "MechanismSpec", "femmech.scene.machine.MechanismSpec"),
    ("femmech.scene_machine", "MountSpec", "femmech.scene.machine.MountSpec"),
    ("femmech.scene_machine", "POSITION_KINDS", "femmech.scene.machine.POSITION_KINDS"),
    ("femmech.scene_machine", "PositionSpec", "femmech.scene.machine.PositionSpec"),
    ("femmech.scene_machine", "parameter_kinds", "femmech.scene.machine.parameter_kinds"),
    ("femmech.scene_machine", "read_mechanisms", "femmech.scene.machine.read_mechanisms"),
    ("femmech.scene_machine", "read_mounts", "femmech.scene.machine.read_mounts"),
    ("femmech.scene_mechanisms", "FACTORIES", "femmech.scene.machine.BUILTIN_MODELS"),
    ("femmech.scene_mechanisms", "LAWS", "femmech.mechanisms.motion_laws.LAWS"),
    ("femmech.scene_mechanisms", "code_error", "femmech.scene.mechanisms.code_error"),
    ("femmech.scene_mechanisms", "confined_module", "femmech.scene.mechanisms.confined_module"),
    ("femmech.scene_mechanisms", "load_module", "femmech.scene.mechanisms.load_module"),
    ("femmech.scene_mechanisms", "mechanism_model", "femmech.scene.mechanisms.mechanism_model"),
    ("femmech.scene_mechanisms", "position_function", "femmech.scene.mechanisms.position_function"),
    ("femmech.scene_mesh", "GENERATORS", "femmech.scene.mesh.GENERATORS"),
    ("femmech.scene_mesh", "MAX_BAYS", "femmech.scene.mesh.MAX_BAYS"),
    ("femmech.scene_mesh", "MAX_SUBDIVISIONS", "femmech.scene.mesh.MAX_SUBDIVISIONS"),
    ("femmech.scene_mesh", "MeshSpec", "femmech.scene.mesh.MeshSpec"),
    ("femmech.scene_mesh", "read_mesh_spec", "femmech.scene.mesh.read_mesh_spec"),
    ("femmech.scene_reader", "MAX_DEPTH", "femmech.scene.reader.MAX_DEPTH"),
    ("femmech.scene_reader", "MAX_KEY_LENGTH", "femmech.scene.reader.MAX_KEY_LENGTH"),
    ("femmech.scene_reader", "MAX_LIST_LENGTH", "femmech.scene.reader.MAX_LIST_LENGTH"),
    ("femmech.scene_reader", "MAX_MAGNITUDE", "femmech.scene.reader.MAX_MAGNITUDE"),
    ("femmech.scene_reader", "MAX_SCENE_BYTES", "femmech.scene.reader.MAX_SCENE_BYTES"),
    ("femmech.scene_reader", "MAX_STRING_LENGTH", "femmech.scene.reader.MAX_STRING_LENGTH"),
    ("femmech.scene_reader", "MAX_VALUES", "femmech.scene.reader.MAX_VALUES"),
    ("femmech.scene_reader", "Reader", "femmech.scene.reader.Reader"),
    ("femmech.scene_reader", "check_limits", "femmech.scene.reader.check_limits"),
    ("femmech.scene_reader", "closest", "femmech.scene.reader.closest"),
    ("femmech.scene_reader", "key_text", "femmech.scene.reader.key_text"),
    ("femmech.scene_reader", "one_line", "femmech.scene.reader.one_line"),
    ("femmech.scene_reader", "show", "femmech.scene.reader.show"),
    ("femmech.scene_reader", "unknown_key_message", "femmech.scene.reader.unknown_key_message"),
    ("femmech.scene_run", "DEFAULT", "femmech.scene.run.DEFAULT"),
    ("femmech.scene_run", "LOG", "femmech.scene.run.LOG"),
    ("femmech.scene_run", "NUMERICAL_FAILURES", "femmech.scene.run.NUMERICAL_FAILURES"),
    ("femmech.scene_run", "RunResult", "femmech.scene.run.RunResult"),
    ("femmech.scene_run", "Workshop", "femmech.scene.workshop.Workshop"),
    ("femmech.scene_run", "logged_warnings", "femmech.scene.run.logged_warnings"),
    ("femmech.scene_run", "progress", "femmech.scene.workshop.progress"),
    ("femmech.scene_run", "run_scene", "femmech.scene.run.run_scene"),
    ("femmech.scene_tasks", "TASKS", "femmech.scene.tasks.TASKS"),
    ("femmech.scene_tasks", "run_check", "femmech.scene.tasks.run_check"),
    ("femmech.scene_tasks", "run_modes", "femmech.scene.tasks.run_modes"),
    ("femmech.scene_tasks", "run_response", "femmech.scene.tasks.run_response"),
    ("femmech.scene_tasks", "run_stability", "femmech.scene.tasks.run_stability"),
    ("femmech.scene_tasks", "run_sweep", "femmech.scene.tasks.run_sweep"),
    ("femmech.scene_tasks", "summary_section", "femmech.scene.summary.summary_section"),
    ("femmech.solve.direct", "PARALLEL_SOLVE_COLUMNS",
     "femmech.solve.pardiso.PARALLEL_SOLVE_COLUMNS"),
    ("femmech.solve.direct", "PARALLEL_SOLVE_MAX_BYTES",
     "femmech.solve.pardiso.PARALLEL_SOLVE_MAX_BYTES"),
    ("femmech.solve.direct", "PARDISO_LOOP_FILL", "femmech.solve.pardiso.PARDISO_LOOP_FILL"),
    ("femmech.solve.direct", "PARDISO_PERTURBATION", "femmech.solve.pardiso.PARDISO_PERTURBATION"),
    ("femmech.solve.direct", "PARDISO_SOLVE_MODE", "femmech.solve.pardiso.PARDISO_SOLVE_MODE"),
    ("femmech.solve.eigen", "ALL_PAIRS_FRACTION", "femmech.solve.dense.ALL_PAIRS_FRACTION"),
    ("femmech.solve.eigen", "BLOCK_SIZE", "femmech.solve.lanczos.BLOCK_SIZE"),
    ("femmech.solve.eigen", "FAR_SHIFT", "femmech.solve.lanczos.FAR_SHIFT"),
    ("femmech.solve.eigen", "GUARD_TOL", "femmech.solve.lanczos.GUARD_TOL"),
    ("femmech.solve.eigen", "LANCZOS_TOL", "femmech.solve.lanczos.LANCZOS_TOL"),
    ("femmech.solve.eigen", "MAX_BASIS_BYTES", "femmech.solve.lanczos.MAX_BASIS_BYTES"),
    ("femmech.solve.eigen", "MAX_SOLVES_PER_MODE", "femmech.solve.lanczos.MAX_SOLVES_PER_MODE"),
    ("femmech.solve.eigen", "PROBES", "femmech.solve.lanczos.PROBES"),
    ("femmech.solve.eigen", "REORTHOGONALIZE_BELOW", "femmech.solve.lanczos.REORTHOGONALIZE_BELOW"),
    ("femmech.solve.eigen", "RESIDUAL_TOL", "femmech.solve.residuals.RESIDUAL_TOL"),
    ("femmech.solve.eigen", "SEMI_ORTHOGONAL", "femmech.solve.lanczos.SEMI_ORTHOGONAL"),
    ("femmech.solve.eigen", "STREAM_COLUMNS", "femmech.solve.lanczos.STREAM_COLUMNS"),
    ("femmech.solve.eigen", "residuals", "femmech.solve.residuals.residuals"),
    ("femmech.solve.lobpcg", "DOF_PER_NODE", "femmech.fe.dofs.DOF_PER_NODE"),
    ("femmech.solve.lobpcg", "near_nullspace", "femmech.fe.nullspace.near_nullspace"),
    ("femmech.solve.lobpcg", "node_blocksize", "femmech.fe.nullspace.node_blocksize"),
    ("femmech.solve.lobpcg", "rigid_body_modes", "femmech.fe.nullspace.rigid_body_modes"),
    ("femmech.solvers", "AUTO_MIN_SIZE", "femmech.solve.direct.AUTO_MIN_SIZE"),
    ("femmech.solvers", "AUTO_ORDER", "femmech.solve.direct.AUTO_ORDER"),
    ("femmech.solvers", "BACKENDS", "femmech.solve.direct.BACKENDS"),
    ("femmech.solvers", "CholmodFactor", "femmech.solve.cholmod.CholmodFactor"),
    ("femmech.solvers", "ENV_VAR", "femmech.solve.direct.ENV_VAR"),
    ("femmech.solvers", "Factor", "femmech.solve.factor.Factor"),
    ("femmech.solvers", "PARALLEL_SOLVE_COLUMNS", "femmech.solve.pardiso.PARALLEL_SOLVE_COLUMNS"),
    ("femmech.solvers", "PARALLEL_SOLVE_MAX_BYTES",
     "femmech.solve.pardiso.PARALLEL_SOLVE_MAX_BYTES"),
    ("femmech.solvers", "PARDISO_LOOP_FILL", "femmech.solve.pardiso.PARDISO_LOOP_FILL"),
    ("femmech.solvers", "PARDISO_PERTURBATION", "femmech.solve.pardiso.PARDISO_PERTURBATION"),
    ("femmech.solvers", "PARDISO_SOLVE_MODE", "femmech.solve.pardiso.PARDISO_SOLVE_MODE"),
    ("femmech.solvers", "PardisoFactor", "femmech.solve.pardiso.PardisoFactor"),
    ("femmech.solvers", "SuperLUFactor", "femmech.solve.superlu.SuperLUFactor"),
    ("femmech.solvers", "available", "femmech.solve.direct.available"),
    ("femmech.solvers", "default_solver", "femmech.solve.direct.default_solver"),
    ("femmech.solvers", "factorize", "femmech.solve.direct.factorize"),
    ("femmech.solvers", "mkl_version", "femmech.solve.pardiso.mkl_version"),
    ("femmech.solvers", "resolve", "femmech.solve.direct.resolve"),
    ("femmech.solvers", "use", "femmech.solve.direct.use"),
    ("femmech.solvers", "versions", "femmech.solve.direct.versions"),
    ("femmech.substructures", "Assembly", "femmech.reduction.substructures.Assembly"),
    ("femmech.substructures", "assemble_parts", "femmech.reduction.substructures.assemble_parts"),
    ("femmech.superelement_file", "ARRAYS", "femmech.reduction.superelement_file.ARRAYS"),
    ("femmech.superelement_file", "CHUNK", "femmech.reduction.superelement_file.CHUNK"),
    ("femmech.superelement_file", "DEFLATE_MAX_RATIO",
     "femmech.reduction.superelement_file.DEFLATE_MAX_RATIO"),
    ("femmech.superelement_file", "EXPANSION_FLOOR",
     "femmech.reduction.superelement_file.EXPANSION_FLOOR"),
    ("femmech.superelement_file", "FIELDS", "femmech.reduction.superelement_file.FIELDS"),
    ("femmech.superelement_file", "FLOATS", "femmech.reduction.superelement_file.FLOATS"),
    ("femmech.superelement_file", "FORMAT_VERSION",
     "femmech.reduction.superelement_file.FORMAT_VERSION"),
    ("femmech.superelement_file", "INDICES", "femmech.reduction.superelement_file.INDICES"),
    ("femmech.superelement_file", "MAX_EXPANSION",
     "femmech.reduction.superelement_file.MAX_EXPANSION"),
    ("femmech.superelement_file", "MAX_HEADER", "femmech.reduction.superelement_file.MAX_HEADER"),
    ("femmech.superelement_file", "MAX_META_CHARS",
     "femmech.reduction.superelement_file.MAX_META_CHARS"),
    ("femmech.superelement_file", "MAX_TIMINGS", "femmech.reduction.superelement_file.MAX_TIMINGS"),
    ("femmech.superelement_file", "METHODS", "femmech.reduction.superelement_file.METHODS"),
    ("femmech.superelement_file", "PSD_RTOL", "femmech.reduction.superelement_file.PSD_RTOL"),
    ("femmech.superelement_file", "READABLE_VERSIONS",
     "femmech.reduction.superelement_file.READABLE_VERSIONS"),
    ("femmech.superelement_file", "SYMMETRY_RTOL",
     "femmech.reduction.superelement_file.SYMMETRY_RTOL"),
    ("femmech.superelement_file", "checksums", "femmech.reduction.superelement_file.checksums"),
    ("femmech.superelement_file", "field_digest",
     "femmech.reduction.superelement_file.field_digest"),
    ("femmech.superelement_file", "meta_digest", "femmech.reduction.superelement_file.meta_digest"),
    ("femmech.superelement_file", "read", "femmech.reduction.superelement_file.read"),
    ("femmech.superelement_file", "write", "femmech.reduction.superelement_file.write"),
    ("femmech.threads", "ENV_VAR", "femmech.solve.threads.ENV_VAR"),
    ("femmech.threads", "ThreadSettings", "femmech.solve.threads.ThreadSettings"),
    ("femmech.threads", "describe", "femmech.solve.threads.describe"),
    ("femmech.threads", "exactly", "femmech.solve.threads.exactly"),
    ("femmech.threads", "factor_phase", "femmech.solve.threads.factor_phase"),
    ("femmech.threads", "gemm_phase", "femmech.solve.threads.gemm_phase"),
    ("femmech.threads", "limit", "femmech.solve.threads.limit"),
    ("femmech.threads", "parse", "femmech.solve.threads.parse"),
    ("femmech.threads", "refresh", "femmech.solve.threads.refresh"),
    ("femmech.threads", "set_threads", "femmech.solve.threads.set_threads"),
    ("femmech.threads", "settings", "femmech.solve.threads.settings"),
    ("femmech.threads", "solve_phase", "femmech.solve.threads.solve_phase"),
    ("femmech.units", "ANGLE", "femmech.scene.units.ANGLE"),
    ("femmech.units", "AREA", "femmech.scene.units.AREA"),
    ("femmech.units", "DAMPING", "femmech.scene.units.DAMPING"),
    ("femmech.units", "DENSITY", "femmech.scene.units.DENSITY"),
    ("femmech.units", "DIMENSIONLESS", "femmech.scene.units.DIMENSIONLESS"),
    ("femmech.units", "Dimension", "femmech.scene.units.Dimension"),
    ("femmech.units", "FORCE", "femmech.scene.units.FORCE"),
    ("femmech.units", "FREQUENCY", "femmech.scene.units.FREQUENCY"),
    ("femmech.units", "INERTIA", "femmech.scene.units.INERTIA"),
    ("femmech.units", "INVERSE_TIME", "femmech.scene.units.INVERSE_TIME"),
    ("femmech.units", "KINDS", "femmech.scene.units.KINDS"),
    ("femmech.units", "Kind", "femmech.scene.units.Kind"),
    ("femmech.units", "LENGTH", "femmech.scene.units.LENGTH"),
    ("femmech.units", "MASS", "femmech.scene.units.MASS"),
    ("femmech.units", "MAX_TEXT", "femmech.scene.units.MAX_TEXT"),
    ("femmech.units", "MOMENT", "femmech.scene.units.MOMENT"),
    ("femmech.units", "PRESSURE", "femmech.scene.units.PRESSURE"),
    ("femmech.units", "ROT_DAMPING", "femmech.scene.units.ROT_DAMPING"),
    ("femmech.units", "ROT_STIFFNESS", "femmech.scene.units.ROT_STIFFNESS"),
    ("femmech.units", "SECOND_MOMENT", "femmech.scene.units.SECOND_MOMENT"),
    ("femmech.units", "SPEED", "femmech.scene.units.SPEED"),
    ("femmech.units", "STIFFNESS", "femmech.scene.units.STIFFNESS"),
    ("femmech.units", "TIME", "femmech.scene.units.TIME"),
    ("femmech.units", "UNITS", "femmech.scene.units.UNITS"),
    ("femmech.units", "describe", "femmech.scene.units.describe"),
    ("femmech.units", "parse_unit", "femmech.scene.units.parse_unit"),
    ("femmech.units", "quantity", "femmech.scene.units.quantity"),
]
"""(old module, old name, new dotted path): ``old.name`` warns and is the new object."""

ALIASED = [
    ("femmech.generators", "femmech.fe.generators",
     ("grid_frame", "grid_frame_size", "members_frame", "MAX_ELEMENTS_PER_MEMBER")),
    ("femmech.sections", "femmech.fe.sections",
     ("BeamSection", "circle", "general", "i_section", "rectangle",
      "rectangle_torsion_constant", "rectangular_hollow", "tube")),
]
"""Old module paths that are still attributes of femmech (``fm.generators``): importing the
old path warns once and gives the module itself, so the attribute stays the same object."""

REMOVED = [
    ("femmech.chain.synthesis", "frozen_matrices",
     "Chain.M(phi) and Chain.C(phi) build the same matrices"),
    ("femmech.fe.parts", "SHELL_TYPES",
     "use femmech.fe.elements.registry.kinds('shell')"),
    ("femmech.parts", "SHELL_TYPES",
     "use femmech.fe.elements.registry.kinds('shell')"),
    ("femmech.scene.tasks", "RPM",
     "an internal factor; use femmech.output.charts.SPEED_UNITS['rpm']"),
    ("femmech.scene.workshop", "timings_table",
     "the report's appendix (femmech.scene.summary) has the timings"),
    ("femmech.scene_run", "timings_table",
     "the report's appendix (femmech.scene.summary) has the timings"),
    ("femmech.scene_tasks", "RPM",
     "an internal factor; use femmech.output.charts.SPEED_UNITS['rpm']"),
]
"""(old module, name, reason): gone without a new place; the old module says why."""

NOT_SHIMMED = {("femmech.chain.synthesis", "frozen_matrices")}
"""Removed names whose module has no ``__getattr__`` (femmech.chain keeps its own surface)."""


def _split(path: str):
    module, _, attr = path.rpartition(".")
    return importlib.import_module(module), attr


@pytest.mark.parametrize(("old", "name", "new"), MOVED, ids=[f"{o}.{n}" for o, n, _ in MOVED])
def test_moved_name_warns_and_is_the_new_object(old, name, new):
    module = importlib.import_module(old)  # an old module file imports without a warning
    with pytest.warns(DeprecationWarning, match=re.escape(f"{old}.{name} moved to {new}")):
        obj = getattr(module, name)
    place, attr = _split(new)
    assert obj is getattr(place, attr)


@pytest.mark.parametrize(("old", "name", "new"), [
    ("femmech.io", "from_meshio", "femmech.fe.mesh_io.from_meshio"),
    ("femmech.analysis.stability", "floquet", "femmech.analysis.floquet.floquet"),
    ("femmech.analysis.stability", "monodromy", "femmech.analysis.floquet.monodromy"),
    ("femmech.scene", "PartSpec", "femmech.scene.load.PartSpec"),  # a package's __getattr__
])
def test_from_import_statement_names_the_callers_line(old, name, new):
    """``from old import name`` works; the warning points at the line that imports."""
    namespace = {}
    with pytest.warns(DeprecationWarning, match=re.escape(f"moved to {new}")) as record:
        exec(compile(f"from {old} import {name}", __file__, "exec"), namespace)
    place, attr = _split(new)
    assert namespace[name] is getattr(place, attr)
    assert {w.filename for w in record} == {__file__}


def test_old_top_level_modules_are_attributes_of_femmech():
    import femmech as fm
    from femmech.fe.mesh_io import from_meshio
    from femmech.solve.eigen import solve_symmetric

    assert fm.io is importlib.import_module("femmech.io")
    with pytest.warns(DeprecationWarning, match="femmech.io.from_meshio moved to"):
        assert fm.io.from_meshio is from_meshio
    with pytest.warns(DeprecationWarning, match="femmech.linalg.solve_symmetric moved to"):
        assert fm.linalg.solve_symmetric is solve_symmetric
    with pytest.raises(AttributeError, match="no attribute 'not_a_name'"):
        fm.not_a_name  # noqa: B018


@pytest.mark.parametrize(("old", "new", "names"), ALIASED)
def test_aliased_old_module_path(old, new, names):
    import femmech as fm

    sys.modules.pop(old, None)  # the first import of the old path warns
    with pytest.warns(DeprecationWarning, match=re.escape(f"{old} moved to {new}")):
        module = importlib.import_module(old)
    assert module is importlib.import_module(new)
    assert getattr(fm, old.rpartition(".")[2]) is module  # the attribute is not replaced
    for name in names:
        assert hasattr(module, name), name


@pytest.mark.parametrize(("old", "name", "reason"), REMOVED,
                         ids=[f"{o}.{n}" for o, n, _ in REMOVED])
def test_removed_name_says_why(old, name, reason):
    module = importlib.import_module(old)
    if (old, name) in NOT_SHIMMED:
        assert not hasattr(module, name)
        return
    with pytest.raises(AttributeError, match=re.escape(f"{old}.{name} was removed: {reason}")):
        getattr(module, name)


def test_unknown_names_still_fail():
    """A module ``__getattr__`` must not swallow other names (or submodule imports)."""
    import femmech.analysis.stability as stability
    import femmech.scene as scene

    with pytest.raises(AttributeError, match="has no attribute 'flqouet'"):
        stability.flqouet  # noqa: B018
    from femmech.scene import cache_folder  # a submodule, found after __getattr__ refuses

    assert cache_folder is importlib.import_module("femmech.scene.cache_folder")
    assert scene.run_scene.__module__ == "femmech.scene.run"


def _shim_tables() -> tuple[set, set]:
    """(old, name, new) and (old, name, reason) of every ``moved(__name__, name, {...},
    removed={...})`` call and every package's ``_MOVED = {...}`` table (for
    ``lazy_names``) in femmech, read from the source."""
    moved, removed = set(), set()
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        old = ".".join(parts)
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                    and node.func.id == "moved" and isinstance(node.args[2], ast.Dict)):
                moved |= {(old, k, v) for k, v in ast.literal_eval(node.args[2]).items()}
                for keyword in node.keywords:
                    removed |= {(old, k, v)
                                for k, v in ast.literal_eval(keyword.value).items()}
            if (isinstance(node, ast.Assign) and len(node.targets) == 1
                    and getattr(node.targets[0], "id", None) == "_MOVED"):
                # a package's table for femmech.deprecation.lazy_names(..., moved=_MOVED)
                moved |= {(old, k, v) for k, v in ast.literal_eval(node.value).items()}
    return moved, removed


def test_tables_match_the_old_places():
    """Every entry of the old places is in the tables above and the other way round."""
    moved, removed = _shim_tables()
    assert moved == set(MOVED)
    assert removed == {r for r in REMOVED if r[:2] not in NOT_SHIMMED}
    assert len(MOVED) == len(set(MOVED))
