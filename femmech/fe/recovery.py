"""Field recovery on beam elements: displacements along each element from its nodal DOFs.

Recovery turns nodal DOF vectors (a static solution or a mode shape) into fields inside
the elements, so that coarse meshes draw as smooth curves and exported fields can be
sampled between nodes. Everything is vectorised over elements.

Uses fe.model, .dofs and the beam element.
"""

from __future__ import annotations

import numpy as np

from femmech.fe.dofs import DOF_PER_NODE
from femmech.fe.elements.beam import bending_shape_functions
from femmech.fe.model import FEModel


def beam_deflection_curves(model: FEModel, u_full: np.ndarray, n_sub: int = 8,
                           phi: np.ndarray | None = None):
    """Displacements along every beam element, interpolated with its shape functions.

    Each element's nodal DOFs are rotated to its local axes (``u_local = R u``), the
    axial displacement is interpolated linearly, the two bending deflections with the
    beam's bending shape functions (:func:`femmech.fe.elements.beam.bending_shape_functions`;
    local x-y plane from ``(v, rz)``, local x-z plane from ``(w, -ry)``), and the result
    is rotated back to global axes (``u = Rᵀ u_local``).

    Parameters
    ----------
    model : FEModel
    u_full : ndarray (n_dof,)
        Full DOF vector (constrained DOFs included), m and rad, e.g. a column of
        :attr:`femmech.ModeSet.shapes` or ``model.expand(u_free)``.
    n_sub : int
        Number of sub-intervals per element; each element gives ``n_sub + 1`` points
        (its two end nodes included, so nodes shared by elements appear repeatedly).
    phi : ndarray (n_elements, 2), optional
        Shear parameters ``Φ = 12 E I / (G A_s L²)`` of the local x-y plane (``Iz``,
        ``Asy``) and the x-z plane (``Iy``, ``Asz``). Default: the model's own
        (``model.beams.phi``), so the interpolation is the element's (exact for a
        static end-loaded Timoshenko element); zeros give cubic Hermite interpolation.

    Returns
    -------
    points : ndarray (n_elements * (n_sub + 1), 3), m
        Undeformed positions, element by element, from node a to node b.
    displacements : ndarray (n_elements * (n_sub + 1), 3), m
        Global displacement at each point. End points equal the nodal translations
        exactly; a cubic deflection field is reproduced exactly inside the elements.

    Raises
    ------
    ValueError
        If ``u_full`` does not have ``model.n_dof`` entries, ``n_sub < 1`` or ``phi``
        has the wrong shape.

    Examples
    --------
    >>> import numpy as np, femmech as fm
    >>> from femmech import sections
    >>> from femmech.fe.recovery import beam_deflection_curves
    >>> mesh = fm.Mesh.from_lines([[0, 0, 0], [2, 0, 0]], [[0, 1]])
    >>> prop = fm.BeamProperty(sections.circle(0.02), fm.Material(E=210e9, rho=7850, nu=0.3))
    >>> model = fm.build_model(mesh, {"all": prop})
    >>> u = np.zeros(12)
    >>> u[11] = 1.0  # rz = 1 rad at node 1: v = L (x³ - x²) with x = s / L
    >>> points, disp = beam_deflection_curves(model, u, n_sub=2)
    >>> disp[:, 1].tolist()  # v at s = 0, 1, 2 m
    [0.0, -0.25, 0.0]
    """
    u = np.asarray(u_full, dtype=float)
    if u.shape != (model.n_dof,):
        raise ValueError(f"u_full must have shape ({model.n_dof},), got {u.shape}")
    if int(n_sub) != n_sub or n_sub < 1:
        raise ValueError(f"n_sub must be a positive integer, got {n_sub}")
    beams = model.beams
    n_el = len(beams.cells)
    phi = beams.phi if phi is None else np.asarray(phi, dtype=float)
    if phi.shape != (n_el, 2):
        raise ValueError(f"phi must have shape ({n_el}, 2), got {phi.shape}")
    xi = np.linspace(0.0, 1.0, int(n_sub) + 1)
    R = beams.frames
    nodal = u.reshape(-1, DOF_PER_NODE)[beams.cells]  # (n_el, 2, 6)
    trans = np.einsum("eij,enj->eni", R, nodal[:, :, :3])  # local (u, v, w) at a and b
    rot = np.einsum("eij,enj->eni", R, nodal[:, :, 3:])  # local (rx, ry, rz) at a and b
    Nv, _ = bending_shape_functions(xi, beams.length, phi[:, 0])
    Nw, _ = bending_shape_functions(xi, beams.length, phi[:, 1])
    dofs_v = np.stack([trans[:, 0, 1], rot[:, 0, 2], trans[:, 1, 1], rot[:, 1, 2]], axis=1)
    dofs_w = np.stack([trans[:, 0, 2], -rot[:, 0, 1], trans[:, 1, 2], -rot[:, 1, 1]], axis=1)
    local = np.stack([
        np.outer(trans[:, 0, 0], 1.0 - xi) + np.outer(trans[:, 1, 0], xi),
        np.einsum("epk,ek->ep", Nv, dofs_v),
        np.einsum("epk,ek->ep", Nw, dofs_w),
    ], axis=-1)  # (n_el, n_sub + 1, 3)
    displacements = np.einsum("eji,epj->epi", R, local)
    start = model.mesh.points[beams.cells[:, 0]]
    end = model.mesh.points[beams.cells[:, 1]]
    points = start[:, None, :] + xi[None, :, None] * (end - start)[:, None, :]
    return points.reshape(-1, 3), displacements.reshape(-1, 3)
