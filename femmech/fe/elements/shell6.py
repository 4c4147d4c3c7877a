"""MITC6: the 6-node quadratic shell triangle with 6 DOF per node, vectorised.

Lee & Bathe, "Development of MITC isotropic triangular shell finite elements", Comput.
Struct. 82 (2004) 945-962 (the MITC6 elements); Lee & Bathe, "The quadratic MITC plate
and MITC shell elements in plate bending", Adv. Eng. Softw. 41 (2010) 712-728. Node
order of meshio's ``"triangle6"`` (VTK_QUADRATIC_TRIANGLE): corners 0, 1, 2
counter-clockwise at the area coordinates (r, s) = (0, 0), (1, 0), (0, 1), edge
midpoints 3, 4, 5 on the edges 0-1, 1-2, 2-0.

The element is flat, built in the local frame of its three corners (x along 0 → 1, z the
normal of the corner plane) and rotated to global axes; DOFs per node
``ux, uy, uz, rx, ry, rz``, shared with beams. Membrane, bending and drilling parts are
uncoupled in the local frame. **Curved geometry is faceted per element**: mid-side nodes
off the corner plane (e.g. a quadratic mesh of a cylinder) are projected onto it and tied
to their projections by rigid offsets (``u_p = u + θ × (p - x)``, as for warped MITC4
quads in :mod:`.shell`), so rigid-body motions give zero strain energy; the curvature
enters through the orientations of neighbouring elements, and a curved element is no
better than the flat facet through its corners. The in-plane map is isoparametric
(quadratic), so curved edges within the plane are followed.

Bending (Mindlin-Reissner, the sign conventions of :mod:`.shell`)
    Quadratic w; quadratic rotations enriched with the cubic bubble ``27 r s (1 - r - s)``
    (two amplitudes, condensed statically per element, without mass). The covariant
    transverse shear strains ``e_a = w,a + θy x,a - θx y,a`` (a = r, s) are replaced by
    the assumed field of the MITC6 elements (Lee & Bathe 2004)::

        ẽ_r = a1 + b1 r + c1 s - s (d r + e s)
        ẽ_s = a2 + b2 r + c2 s + r (d r + e s)

    (the rotated Raviart-Thomas space of degree 2, 8 parameters), tied to the
    displacement-based strains by eight conditions: the tangential strain at the two
    Gauss points ``1/2 ∓ 1/(2√3)`` of each edge (e_r on 0-1, e_s - e_r on 1-2, e_s on
    2-0; Lee & Bathe's edge tying) and the element means of e_r and e_s over the (r, s)
    triangle. Gauss-point tying equals the L² projection of the quadratic tangential
    strain onto linears, so these are the moments of the reduction operator of MITC7
    (Brezzi, Bathe & Fortin, "Mixed-interpolated elements for Reissner-Mindlin plates",
    IJNME 28 (1989) 1787-1801), whose rotation bubble this element also takes: with the
    bubble condensed it is MITC7 on the six nodes of a triangle6. Both choices were
    measured against the plain MITC6 on the simply supported square (λ₁ errors on 8 x 8 /
    16 x 16 squares of two triangles, a/t = 1000, tests):

    * interior tying at a point (e_r, e_s at the centroid, :data:`INTERIOR` =
      ``"centroid"``, no bubble): -0.20 %, -0.059 %, too flexible and O(h²);
    * means, no bubble (:data:`BUBBLE` = False): +0.038 %, +0.0024 % on alternating
      diagonals, but +0.70 %, +0.060 % with all diagonals one way, growing to +0.85 %,
      +0.19 % at a/t = 10⁴ (shear locking on that mesh pattern);
    * means and bubble (the element): +0.029 %, +0.0020 % (alternating), +0.044 %,
      +0.0035 % (one way), the same at a/t = 10⁴: no locking, O(h⁴).

    The Cartesian strains follow from ``e = J γ``. Shear stiffness ``k G t``,
    ``k = 5/6``, no stabilisation factor (unlike the linear MITC3 of :mod:`.shell`).

Membrane
    Quadratic displacements (the linear strain triangle, LST); flat, hence no membrane
    locking. Drilling rotation rz: the Hughes & Brezzi penalty ``½ γ t ∫ (θz - ω)² dA``,
    ``ω = ½ (v,x - u,y)``, ``γ = drilling · G``, θz interpolated quadratically; a single
    free element has exactly six zero-energy modes.

Integration: the 6-point degree-4 triangle rule (Strang & Fix 1973; Dunavant, IJNME 21
(1985) 1129-1148) for every part: exact for straight-sided elements (membrane
integrand of degree 2; bending with the bubble, the assumed shear, the element means of
the bubble's shear, the drilling penalty and the mass of degree 4 at most).

Mass: consistent, from the quadratic shape functions for all six fields, ``ρ t`` for
the translations and ``ρ t³ / 12`` for the rotations, with the same nominal drilling
inertia ``ρ t³ / 12`` as :mod:`.shell`.

Imports fe.elements.registry and the shared helpers of fe.elements.shell;
arrays in, element matrices out.
"""

from __future__ import annotations

import numpy as np

from femmech.fe.elements.registry import ElementType, register
from femmech.fe.elements.shell import (
    DRILLING,
    ELEMENT_CHUNK,
    SHEAR_FACTOR,
    batched,
    expand_uv,
    global_matrices,
    integrate,
    membrane_b,
    plane_stress,
    shell_frames,
)

NODES = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5]])
"""Area coordinates (r, s) of the six nodes in meshio's triangle6 order."""

_A1, _W1 = 0.445948490915965, 0.223381589678011
_A2, _W2 = 0.091576213509771, 0.109951743655322
POINTS = np.array([[_A1, _A1], [1 - 2 * _A1, _A1], [_A1, 1 - 2 * _A1],
                   [_A2, _A2], [1 - 2 * _A2, _A2], [_A2, 1 - 2 * _A2]])
"""Points (6, 2) of the degree-4 rule (Dunavant 1985, table for p = 4) and their
weights (6,), which sum to the reference area 1/2."""
WEIGHTS = 0.5 * np.array([_W1, _W1, _W1, _W2, _W2, _W2])

_G1, _G2 = 0.5 - 0.5 / np.sqrt(3.0), 0.5 + 0.5 / np.sqrt(3.0)
TYING = np.array([[_G1, 0.0], [_G2, 0.0], [_G2, _G1], [_G1, _G2], [0.0, _G2], [0.0, _G1]])
"""Edge tying points (6, 2): the two Gauss points of the edges 0-1, 1-2, 2-0."""
TYING_DIRECTION = np.array([[1.0, 0.0], [1.0, 0.0], [-1.0, 1.0], [-1.0, 1.0], [0.0, 1.0],
                            [0.0, 1.0]])
"""Edge tangents (6, 2) in (r, s): the covariant strain tied at each edge point."""
BUBBLE = True
"""Enrich the rotations with the cubic bubble of MITC7 (condensed per element); without
it the element stiffens on uniform meshes of thin plates (module docstring)."""
INTERIOR = "mean"
"""The two interior conditions: ``"mean"`` ties the element means of e_r and e_s (the
default, O(h⁴) frequencies), ``"centroid"`` their values at the centroid (measured
O(h²) and too flexible, module docstring); kept to reproduce that measurement."""


def shape6(points):
    """Quadratic shape functions N (q, 6) and derivatives (q, 2, 6) by (r, s) at (q, 2)."""
    points = np.asarray(points, dtype=float)
    r, s = points[:, 0], points[:, 1]
    u = 1.0 - r - s
    zero = np.zeros_like(r)
    N = np.stack([u * (2 * u - 1), r * (2 * r - 1), s * (2 * s - 1), 4 * r * u, 4 * r * s,
                  4 * s * u], axis=1)
    dr = np.stack([1 - 4 * u, 4 * r - 1, zero, 4 * (u - r), 4 * s, -4 * s], axis=1)
    ds = np.stack([1 - 4 * u, zero, 4 * s - 1, -4 * r, 4 * r, 4 * (u - s)], axis=1)
    return N, np.stack([dr, ds], axis=1)


def _assumed_basis(points):
    """Basis (q, 2, 8) of the MITC6 assumed covariant shear field (ẽ_r, ẽ_s) at (q, 2)."""
    r, s = points[:, 0], points[:, 1]
    one, zero = np.ones_like(r), np.zeros_like(r)
    er = [one, r, s, zero, zero, zero, -s * r, -s * s]
    es = [zero, zero, zero, one, r, s, r * r, r * s]
    return np.stack([np.stack(er, axis=1), np.stack(es, axis=1)], axis=1)


def _interpolation(interior=INTERIOR):
    """(q, 2, 8): the assumed covariant strains at the integration points from the eight
    tied values (six edge values, two interior ones); the same for all elements, since
    the space and the tying live in (r, s)."""
    edge = np.einsum("ta,tak->tk", TYING_DIRECTION, _assumed_basis(TYING))
    inner = _assumed_basis(POINTS)
    if interior == "mean":
        inner = np.einsum("q,qak->ak", WEIGHTS / WEIGHTS.sum(), inner)
    else:
        inner = _assumed_basis(np.full((1, 2), 1.0 / 3.0))[0]
    tying = np.vstack([edge, inner])
    return np.linalg.solve(tying.T, _assumed_basis(POINTS).transpose(0, 2, 1)).transpose(0, 2, 1)


_INTERPOLATION = {kind: _interpolation(kind) for kind in ("mean", "centroid")}


def frames6(points: np.ndarray, cells: np.ndarray):
    """Local frames, in-plane node coordinates and offsets of 6-node shell elements.

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    cells : ndarray (n_elements, 6), int
        meshio triangle6 node order (module docstring).

    Returns
    -------
    R : ndarray (n_elements, 3, 3)
        Rows are the local unit axes x, y, z (z = normal of the corner plane).
    xy : ndarray (n_elements, 6, 2), m
        Local in-plane coordinates of the nodes projected on the corner plane, relative
        to the centroid of the corners.
    z : ndarray (n_elements, 6), m
        Offsets of the nodes from the corner plane (zero for corners and flat elements).

    Raises
    ------
    ValueError
        For a degenerate element (zero area), naming the first one.
    """
    try:
        R, _, _ = shell_frames(points, cells[:, :3])
    except ValueError as err:
        raise ValueError(f"triangle6 {err}") from None
    X = points[cells]
    local = np.einsum("eij,ekj->eki", R, X - X[:, :3].mean(axis=1)[:, None, :])
    z = local[:, :, 2]
    z[:, :3] = 0.0  # the corners lie in their plane (round-off)
    return R, local[:, :, :2], z


def _jacobians(xy, points):
    """N (q, 6), dN by (r, s) (q, 2, 6), J (n, q, 2, 2) with ``J[a, b] = ∂x_b/∂r_a``."""
    N, dN = shape6(points)
    return N, dN, np.einsum("qai,eib->eqab", dN, xy)


def quadrature(xy):
    """N (6, 6), Cartesian derivatives (n, 6, 2, 6), J (n, 6, 2, 2), w det J (n, 6)."""
    N, dN, J = _jacobians(xy, POINTS)
    det = J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
    if np.any(det <= 0):
        e = int(np.flatnonzero((det <= 0).any(axis=1))[0])
        raise ValueError(f"triangle6 element {e} is inverted or too distorted (det J <= 0"
                         " at an integration point; corners must go counter-clockwise"
                         " and the mid-side nodes lie near the edge midpoints)")
    dN_xy = np.linalg.solve(J, np.broadcast_to(dN, J.shape[:2] + (2, 6)))
    return N, dN_xy, J, det * WEIGHTS


def bubble(points):
    """Cubic bubble ``27 r s (1 - r - s)`` (q,) and its derivatives (q, 2) at (q, 2)."""
    points = np.asarray(points, dtype=float)
    r, s = points[:, 0], points[:, 1]
    u = 1.0 - r - s
    return 27 * r * s * u, np.stack([27 * s * (u - r), 27 * r * (u - s)], axis=1)


def _covariant_rows(xy, points, direction):
    """Rows (n, p, 20) of the displacement-based covariant shear strain along
    ``direction`` (p, 2) at ``points`` (p, 2): ``d_a (w,a + θy x,a - θx y,a)``; DOFs
    (w, θx, θy) per node, then the bubble amplitudes of θx and θy."""
    N, dN, J = _jacobians(xy, points)
    b, _ = bubble(points)
    dy = np.einsum("ta,eta->et", direction, J[..., 1])  # d_a y,a
    dx = np.einsum("ta,eta->et", direction, J[..., 0])
    B = np.zeros(J.shape[:2] + (20,))
    B[..., 0:18:3] = np.einsum("ta,tai->ti", direction, dN)[None]
    B[..., 1:18:3] = -N[None] * dy[..., None]
    B[..., 2:18:3] = N[None] * dx[..., None]
    B[..., 18] = -b * dy
    B[..., 19] = b * dx
    return B


def _tied_shear(xy, J):
    """MITC6 assumed Cartesian shear rows (n, 6 points, 2, 20), DOFs as
    :func:`_covariant_rows`."""
    interior = INTERIOR  # read at call time (a test switches it to "centroid")
    rows = [_covariant_rows(xy, TYING, TYING_DIRECTION)]
    for d in np.eye(2):  # the interior conditions on e_r and e_s
        if interior == "mean":
            B = _covariant_rows(xy, POINTS, np.tile(d, (len(POINTS), 1)))
            rows.append(np.einsum("q,eqj->ej", WEIGHTS / WEIGHTS.sum(), B)[:, None])
        else:
            rows.append(_covariant_rows(xy, np.full((1, 2), 1.0 / 3.0), d[None]))
    cov = np.einsum("qat,etj->eqaj", _INTERPOLATION[interior], np.concatenate(rows, axis=1))
    return np.linalg.solve(J, cov)  # e = J γ


def _bending(xy, Db, Ds):
    """MITC6 bending + shear stiffness (n, 18, 18), DOFs (w, θx, θy) per node, with
    the rotation bubble condensed (:data:`BUBBLE`)."""
    _, dN_xy, J, wdet = quadrature(xy)
    _, db = bubble(POINTS)
    db_xy = np.linalg.solve(J, np.broadcast_to(db[:, :, None], J.shape[:2] + (2, 1)))[..., 0]
    Bb = np.zeros(dN_xy.shape[:2] + (3, 20))
    Bb[..., 0, 2:18:3] = dN_xy[..., 0, :]
    Bb[..., 1, 1:18:3] = -dN_xy[..., 1, :]
    Bb[..., 2, 2:18:3] = dN_xy[..., 1, :]
    Bb[..., 2, 1:18:3] = -dN_xy[..., 0, :]
    Bb[..., 0, 19] = db_xy[..., 0]
    Bb[..., 1, 18] = -db_xy[..., 1]
    Bb[..., 2, 19] = db_xy[..., 1]
    Bb[..., 2, 18] = -db_xy[..., 0]
    Bs = _tied_shear(xy, J)
    eye = np.broadcast_to(np.eye(2), (len(xy), 2, 2)) * Ds[:, None, None]
    K = integrate(Bb, Db, wdet) + integrate(Bs, eye, wdet)
    if not BUBBLE:  # read at call time (a test measures the element without it)
        return K[:, :18, :18]
    Kab = K[:, :18, 18:]
    return K[:, :18, :18] - Kab @ np.linalg.solve(K[:, 18:, 18:], np.swapaxes(Kab, 1, 2))


def shell6_matrices(points, cells, E, nu, rho, thickness, shear_factor=SHEAR_FACTOR,
                    drilling=DRILLING):
    """Global stiffness and consistent mass of MITC6 shell triangles.

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    cells : ndarray (n_elements, 6), int
        meshio triangle6 node order (module docstring).
    E, nu, rho, thickness : float or ndarray (n_elements,)
        Young's modulus (Pa), Poisson's ratio, density (kg/m³), thickness (m).
    shear_factor : float
        Transverse shear correction factor k.
    drilling : float or ndarray (n_elements,)
        Drilling penalty ``γ / G`` (:mod:`femmech.fe.elements.shell`).

    Returns
    -------
    K : ndarray (n_elements, 36, 36), N/m, N, N m/rad
    M : ndarray (n_elements, 36, 36), kg, kg m, kg m²
        DOFs ``ux, uy, uz, rx, ry, rz`` per node, node-major, global axes.
    """
    cells = np.asarray(cells, dtype=np.int64)
    n = len(cells)
    if cells.ndim != 2 or cells.shape[1] != 6:
        raise ValueError(f"triangle6 shell cells must have shape (n, 6), got {cells.shape}")
    if n == 0:
        return np.zeros((0, 36, 36)), np.zeros((0, 36, 36))
    chunk = ELEMENT_CHUNK // 2  # 36 x 36 blocks: about 2.3 times the memory of a quad's
    if n > chunk:
        return batched(shell6_matrices, chunk, points, cells, E, nu, rho, thickness,
                       shear_factor, drilling)
    R, xy, z = frames6(np.asarray(points, dtype=float), cells)
    E, nu, rho, t, drill = (np.broadcast_to(np.asarray(p, dtype=float), (n,)).copy()
                            for p in (E, nu, rho, thickness, drilling))
    G = E / (2.0 * (1.0 + nu))
    C = plane_stress(E, nu)
    N, dN_xy, _, wdet = quadrature(xy)
    Km = expand_uv(integrate(membrane_b(dN_xy), C * t[:, None, None], wdet), 6)
    Kb = _bending(xy, C * (t**3 / 12.0)[:, None, None], shear_factor * G * t)
    return global_matrices(R, z, Km, Kb, N, dN_xy, wdet, G, t, rho, drill)


register(ElementType("triangle6", "shell", shell6_matrices))
