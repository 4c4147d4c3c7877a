"""Memory a part needs, estimated from its counts before anything is built, and the limit.

A mesh that fits the count limits (:data:`femmech.fe.mesh.MAX_NODES`) can still need far
more memory than the machine has: a 3000 x 3000 plate (9 million nodes) or a grid frame of
a million joints ended in a MemoryError deep inside the assembly after minutes. The scene
therefore estimates, from the node and cell counts alone, what building and solving the
part takes and refuses it above :func:`memory_limit` with one line giving both in GB.

The estimate (:func:`estimate_bytes`) is a *lower* bound of the peak, so a refusal is
certain to be right: the mesh arrays, then the larger of (a) the element matrices of one
of K and M with the copy the assembly makes (:mod:`femmech.fe.assembly`) and (b) the CSR
matrices K and M plus the fill of one sparse factorisation under a nested-dissection
ordering (George 1973; Lipton, Rose & Tarjan 1979): about ``n log2 n`` node blocks for a
surface mesh, ``n^(4/3)`` for a solid or a three-dimensional grid of joints, ``n`` for a
line-like frame (members between a few joints add little fill), each block 6 x 6 values.
Eigenvectors and solver workspace come on top.

Stage 8 (scene), reading and building: imports only :mod:`femmech.fe.dofs` (the DOFs
per node).
"""

from __future__ import annotations

import math
import os

from femmech.fe.dofs import DOF_PER_NODE

MEMORY_ENV = "FEMMECH_MEMORY_LIMIT_GB"
"""Environment variable that sets the memory limit (GB = 1e9 bytes) instead of
:data:`MEMORY_FRACTION` of the available memory."""
MEMORY_FRACTION = 0.9
"""Share of the available memory (``MemAvailable``, else the physical memory) a part may
be estimated to need."""
_VALUE = 8  # bytes of a float64
_ENTRY = 12  # bytes of a CSR entry: float64 value + int32 index


def estimate_bytes(n_nodes: int, cells: dict, dimension: int, n_joints: int | None = None,
                   dofs_per_node: int = DOF_PER_NODE) -> float:
    """Lower bound of the peak memory (bytes) of building and factorising one part.

    Parameters
    ----------
    n_nodes : int
    cells : dict[int, int]
        Nodes per cell → number of such cells.
    dimension : int
        1 (line-like frame), 2 (surface) or 3 (solid, 3-D grid of joints): the fill law.
    n_joints : int, optional
        Nodes that carry the fill (the joints of a grid frame; default all nodes).
    dofs_per_node : int
        DOFs per node of the element matrices (3 for solids, 6 otherwise).
    """
    n_nodes = int(n_nodes)
    mesh = n_nodes * 3 * _VALUE + sum(k * n * 8 for k, n in cells.items())
    elements = 2 * sum(n * (dofs_per_node * k) ** 2 * _VALUE for k, n in cells.items())
    pairs = n_nodes + sum(n * k * (k - 1) for k, n in cells.items())  # node blocks of K
    matrices = 2 * pairs * DOF_PER_NODE ** 2 * _ENTRY
    m = max(int(n_joints if n_joints is not None else n_nodes), 1)
    fill = {1: m, 2: m * max(1.0, math.log2(m)), 3: m ** (4 / 3)}[dimension]
    factor = (fill + n_nodes) * DOF_PER_NODE ** 2 * _ENTRY
    return float(mesh + max(elements, matrices + factor))


def memory_limit() -> tuple[float, str]:
    """(bytes, where from): ``$FEMMECH_MEMORY_LIMIT_GB``, else :data:`MEMORY_FRACTION` of
    ``MemAvailable`` (``/proc/meminfo``), else of the physical memory; ``inf`` when none
    is known. ValueError naming the variable for a value that is not a positive number."""
    text = os.environ.get(MEMORY_ENV)
    if text is not None:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"${MEMORY_ENV}: expected a positive number of GB, got {text!r}")
        return value * 1e9, f"${MEMORY_ENV}"
    share = f"{MEMORY_FRACTION:.0%} of"
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    available = float(line.split()[1]) * 1024
                    return MEMORY_FRACTION * available, f"{share} the available memory"
    except (OSError, ValueError, IndexError):
        pass
    try:
        physical = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return math.inf, "unknown"
    return MEMORY_FRACTION * physical, f"{share} the physical memory"


def memory_problem(n_nodes: int, cells: dict, dimension: int, n_joints: int | None = None,
                   dofs_per_node: int = DOF_PER_NODE) -> str | None:
    """The reason (one sentence) a part of these counts cannot be built here, or None."""
    need = estimate_bytes(n_nodes, cells, dimension, n_joints, dofs_per_node)
    limit, source = memory_limit()
    if need <= limit:
        return None
    return (f"the part would need at least {need / 1e9:.3g} GB of memory ({_count(n_nodes)}"
            f" nodes, {_count(sum(cells.values()))} elements, {_count(n_nodes * DOF_PER_NODE)}"
            f" DOFs: mesh, element"
            f" matrices, K and M, factorisation fill); the limit is {limit / 1e9:.3g} GB"
            f" ({source}; ${MEMORY_ENV} sets it)")


def _count(n: int) -> str:
    """An integer as is, or with 3 digits beyond 1e12 (counts of absurd requests)."""
    return str(n) if n < 10**12 else f"{float(n):.3g}"


_SOLIDS = ("tetra", "tetra10", "hexahedron", "hexahedron20", "hexahedron27", "wedge")
_SHELLS = ("triangle", "quad", "triangle6", "quad8", "quad9")


def mesh_counts(mesh) -> dict:
    """The keyword arguments of :func:`memory_problem` for a mesh already read (a
    :class:`femmech.fe.mesh.Mesh`): solids count as 3-D, shells as surfaces, beams only as
    line-like frames (their fill is not known without the ordering)."""
    cells: dict[int, int] = {}
    for array in mesh.cells.values():
        cells[array.shape[1]] = cells.get(array.shape[1], 0) + len(array)
    kinds = {k for k, a in mesh.cells.items() if len(a)}
    dimension = 3 if kinds & set(_SOLIDS) else 2 if kinds & set(_SHELLS) else 1
    return {"n_nodes": mesh.n_nodes, "cells": cells, "dimension": dimension,
            "dofs_per_node": 3 if kinds and kinds <= set(_SOLIDS) else DOF_PER_NODE}
