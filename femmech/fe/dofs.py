"""DOF numbering: node-interleaved, ``dof = 6 * node + component``.

Components are ordered ``ux, uy, uz, rx, ry, rz`` (m and rad).

Imports nothing of femmech.
"""

from __future__ import annotations

import numpy as np

DOF_PER_NODE = 6
COMPONENTS = ("ux", "uy", "uz", "rx", "ry", "rz")
_ALIASES = {
    "all": COMPONENTS,
    "translations": COMPONENTS[:3],
    "rotations": COMPONENTS[3:],
}


def components(spec) -> np.ndarray:
    """Component indices (0..5) from ``"all"``, ``"translations"``, ``"rotations"``,
    a component name, or a sequence of names or indices.

    >>> components(["ux", "rz"]).tolist()
    [0, 5]
    """
    if isinstance(spec, str):
        names = _ALIASES.get(spec, (spec,))
    else:
        names = tuple(spec)
    out = []
    for name in names:
        if isinstance(name, (int, np.integer)) and 0 <= name < DOF_PER_NODE:
            out.append(int(name))
        elif name in COMPONENTS:
            out.append(COMPONENTS.index(name))
        else:
            raise ValueError(
                f"unknown DOF component {name!r}; expected one of {COMPONENTS},"
                f" 'all', 'translations' or 'rotations'"
            )
    return np.unique(out)


def node_dofs(nodes, comps=None) -> np.ndarray:
    """Global DOF indices of ``nodes`` (array) for component indices ``comps`` (default all).

    Returns an array of shape (len(nodes) * len(comps),), node-major.
    """
    nodes = np.asarray(nodes, dtype=np.int64).ravel()
    comps = np.arange(DOF_PER_NODE) if comps is None else np.asarray(comps)
    return (DOF_PER_NODE * nodes[:, None] + comps[None, :]).ravel()


def element_dofs(cells: np.ndarray) -> np.ndarray:
    """DOF indices of each element, shape (n_elements, 6 * nodes_per_element)."""
    cells = np.asarray(cells, dtype=np.int64)
    n_ldof = DOF_PER_NODE * cells.shape[1]  # explicit, so that zero elements also work
    return (DOF_PER_NODE * cells[:, :, None] + np.arange(DOF_PER_NODE)).reshape(len(cells), n_ldof)


def dof_label(dof: int) -> str:
    """Readable label such as ``"node 12 uz"``."""
    return f"node {dof // DOF_PER_NODE} {COMPONENTS[dof % DOF_PER_NODE]}"
