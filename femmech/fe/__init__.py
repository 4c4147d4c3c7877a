"""The finite-element model: meshes, sections, materials, elements, assembly.

Data flow: mesh (:mod:`.mesh`, :mod:`.generators`; files through :mod:`.mesh_io`, with
their sets by :mod:`.mesh_sets`, :mod:`.abaqus_sets`, :mod:`.nastran_sets`, the lines meshio
may not see hidden by :mod:`.deck_lines`) → properties
(:mod:`.sections`, :mod:`.materials`) → element matrices (:mod:`.elements`) → sparse
global K, M (:mod:`.assembly`, :mod:`.dofs`) → supports, links, point masses and springs
(:mod:`.constraints`, :mod:`.lumped`) → :class:`~femmech.fe.model.FEModel`
(:mod:`.model`, :mod:`.parts`), with input checks (:mod:`.checks`), field recovery
inside beam elements (:mod:`.recovery`) and the rigid-body modes the multigrid of the
LOBPCG solver needs (:mod:`.nullspace`). Also a Nastran deck's cards
(:mod:`.nastran_cards`), meshes sized for a frequency band (:mod:`.sizing`) and uniform
refinement (:mod:`.refine`).

Imports :mod:`femmech.errors` and, in :mod:`.nullspace` only, :mod:`femmech.solve.lobpcg`:
no reduction or analysis code.
"""
