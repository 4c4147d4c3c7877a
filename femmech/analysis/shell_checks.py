"""Spurious drilling modes of shell models: the drilling share of each mode's kinetic energy.

Flat shell elements carry a rotation about their normal (the drilling DOF, ``rz`` in
local axes) that shell theory does not have: a Hughes-Brezzi penalty ties it to the
in-plane rotation and a nominal inertia ``ρ t³ / 12`` keeps M positive definite
(:mod:`femmech.fe.elements.shell`). Where nodes can rotate about the normal nearly
freely, these two make local modes near ``ω² ≈ 12 drilling G / (ρ t²)``, one per node,
independent of the mesh size: for thin shells far above the structural modes, for thick
ones (steel, ``drilling = 1e-2``: below 1 kHz at t = 0.2 m) a tight cluster among them.

**Measure.** The fraction of a mode's kinetic energy in rotations about the shell normals,
``(P u)ᵀ M (P u) / uᵀ M u``, where ``P`` keeps at every shell node only the rotation about
the node's normal (the principal axis of the area-weighted normals of its elements, so
that inconsistently oriented elements do not cancel) and zeros everything else; nodes of
beams and point masses are left out (their rotational inertia is physical). The inertia
behind this share has no physical basis, so a mode that keeps most of its kinetic energy
there is spurious. A structural mode keeps little of it: bending modes almost none, in-plane
modes of order ``(2π t / λ)² / 12`` (λ their wavelength: the drilling rotation follows the
in-plane rotation ``½ (v,x - u,y)``); the modes of the cluster keep more than 99 %. Measured on a
simply supported 1 m steel plate, t = 0.2 m, 8 x 8 quads (tests/test_shell_quality.py):
0.0000 for the first bending mode, 0.998-1.000 for the 26 drilling modes that follow it;
with ``drilling`` raised to 1 the cluster leaves the 12 lowest modes, whose shares are at
most 0.065 (in-plane modes). The strain-energy share of the drilling penalty,
``uᵀ K_drill u / uᵀ K u``, tells the same (0.985-0.998 there) but needs the element
properties; the kinetic share needs only the assembled M and the geometry, so it holds for
every registered shell element kind.

**Threshold.** Modes with a share of at least :data:`DRILLING_SHARE` (most of their kinetic
energy in the nominal inertia) are reported; the measured gap between the two populations
(below 0.07 and above 0.99) leaves the threshold uncritical.

Uses fe (the model, its checks and DOF numbering).
"""

from __future__ import annotations

import numpy as np

from femmech.fe.checks import CORNERS, Finding
from femmech.fe.dofs import DOF_PER_NODE
from femmech.fe.model import FEModel

DRILLING_SHARE = 0.5
"""A mode with at least this fraction of its kinetic energy in rotations about the shell
normals is reported as a spurious drilling mode."""


def node_normals(model: FEModel) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals of the shell nodes of ``model``.

    Returns
    -------
    nodes : ndarray (n,) of int
        Nodes of shell elements that no beam element and no point mass uses.
    normals : ndarray (n, 3)
        Principal axis of ``Σ a nᵀ n`` over the elements at the node (element normals
        ``n`` from the corner nodes, weighted by the element area ``a``): the sign of
        the element orientation does not matter.
    """
    points = model.mesh.points
    tensor = np.zeros((len(points), 3, 3))
    for kind, cells in model.shells.cells.items():
        cells = np.asarray(cells)
        if not len(cells):
            continue
        x = points[cells[:, :CORNERS.get(kind, cells.shape[1])]]
        if x.shape[1] == 4:
            normal = np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1])  # 2 x area along n
        else:
            normal = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
        area = np.linalg.norm(normal, axis=1)
        outer = np.einsum("ei,ej->eij", normal, normal) / np.where(area > 0, area, 1.0)[:,
                                                                                  None, None]
        np.add.at(tensor, cells.ravel(), np.repeat(outer, cells.shape[1], axis=0))
    shell = np.einsum("nii->n", tensor) > 0
    shell[np.asarray(model.beams.cells, dtype=np.int64).ravel()] = False
    shell[np.asarray(model.mass_nodes, dtype=np.int64)] = False
    nodes = np.flatnonzero(shell)
    if not nodes.size:
        return nodes, np.zeros((0, 3))
    return nodes, np.linalg.eigh(tensor[nodes])[1][:, :, -1]


def drilling_fractions(model: FEModel, shapes: np.ndarray) -> np.ndarray:
    """Fraction of each mode's kinetic energy in rotations about the shell normals.

    Parameters
    ----------
    model : FEModel
    shapes : ndarray (n_dof, n_modes)
        Full mode shapes (e.g. :attr:`femmech.ModeSet.shapes`).

    Returns
    -------
    ndarray (n_modes,)
        In [0, 1]; zeros for a model without shell elements (module notes).
    """
    shapes = np.asarray(shapes, dtype=float)
    if shapes.ndim != 2 or shapes.shape[0] != model.n_dof:
        raise ValueError(f"mode shapes must have shape ({model.n_dof}, n_modes) (the model's"
                         f" full DOFs), got {shapes.shape}")
    nodes, normals = node_normals(model)
    out = np.zeros(shapes.shape[1])
    if not nodes.size or not shapes.shape[1]:
        return out
    rot = (DOF_PER_NODE * nodes[:, None] + np.arange(3, 6)).ravel()
    theta = shapes[rot].reshape(len(nodes), 3, -1)
    about = np.einsum("nc,ncm->nm", normals, theta)  # rotation about the node normal
    drill = np.zeros_like(shapes)
    drill[rot] = (normals[:, :, None] * about[:, None, :]).reshape(len(rot), -1)
    total = np.einsum("ij,ij->j", shapes, model.M @ shapes)
    part = np.einsum("ij,ij->j", drill, model.M @ drill)
    np.divide(part, total, out=out, where=total > 0)
    return np.clip(out, 0.0, 1.0)


def drilling_findings(fractions: np.ndarray, freq_hz: np.ndarray, rigid=None,
                      share: float = DRILLING_SHARE) -> list[Finding]:
    """Modes dominated by the drilling rotation, as one finding naming them.

    Parameters
    ----------
    fractions : ndarray (n_modes,)
        :func:`drilling_fractions`.
    freq_hz : ndarray (n_modes,), Hz
    rigid : ndarray (n_modes,) of bool, optional
        Rigid-body modes (not judged).
    share : float
        Threshold (:data:`DRILLING_SHARE`).
    """
    fractions = np.asarray(fractions, dtype=float)
    hit = fractions >= share
    if rigid is not None:
        hit &= ~np.asarray(rigid, dtype=bool)
    k = np.flatnonzero(hit)
    if not k.size:
        return []
    f, p = np.asarray(freq_hz, dtype=float)[k], 100 * fractions[k]
    return [Finding("drilling modes", f"{k.size} mode(s) keep at least {100 * share:g} % of"
                    f" their kinetic energy in the rotation about the shell normal: modes"
                    f" {mode_ranges(k + 1)} ({f.min():.4g}-{f.max():.4g} Hz,"
                    f" {p.min():.1f}-{p.max():.1f} %). That rotation's inertia rho t³/12 and"
                    " its penalty stiffness are numerical devices of flat shells, so these are"
                    " spurious drilling modes of thick shells (near sqrt(12 drilling G / rho)"
                    " / (2 pi t)); ignore them, or raise ShellProperty.drilling (the cluster"
                    " rises as its square root) to move them out of the band",
                    np.empty(0, dtype=np.int64))]


def mode_ranges(numbers) -> str:
    """``"3, 5-9, 12"`` from ascending mode numbers."""
    numbers = np.asarray(numbers, dtype=np.int64)
    if not numbers.size:
        return ""
    breaks = np.flatnonzero(np.diff(numbers) != 1)
    starts = np.concatenate([[numbers[0]], numbers[breaks + 1]])
    ends = np.concatenate([numbers[breaks], [numbers[-1]]])
    return ", ".join(str(a) if a == b else f"{a}-{b}" for a, b in zip(starts, ends, strict=True))
