"""Vectorised element matrices (one batched computation for all elements of a kind).

* :mod:`.beam`: two-node 3D Timoshenko frame element, 6 DOF per node.
* :mod:`.shell`: flat shell elements, 6 DOF per node (3-node triangle, 4-node quad).
* :mod:`.shell9`: MITC9, the 9-node quadratic shell quad, 6 DOF per node.
* :mod:`.shell6`: MITC6, the 6-node quadratic shell triangle, 6 DOF per node.
* :mod:`.solid`: isoparametric solid elements, 3 translations per node (tetra,
  hexahedron and their quadratic forms).
* :mod:`.registry`: the shell and solid cell kinds :func:`femmech.build_model` knows;
  each element module registers its kinds, and importing this package imports them all.

Uses only fe.assembly and fe.dofs (in :mod:`.solid`).
"""

from femmech.fe.elements import shell, shell6, shell9, solid  # noqa: F401  (they register their kinds)
