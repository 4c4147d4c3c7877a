"""Flat shell elements with 6 DOF per node (3-node triangle, 4-node quad), vectorised.

Each element is flat, built in a local frame (x, y in the element's mean plane, z its
normal) and rotated to global axes; the DOFs per node are ``ux, uy, uz, rx, ry, rz`` as
for the beam, so that shells and beams share nodes. Membrane, bending and drilling
parts are uncoupled in the local frame (a flat element); curvature enters through the
different orientations of neighbouring elements.

Bending (Mindlin-Reissner, ``u(z) = u + z θy``, ``v(z) = v - z θx``)
    Curvatures ``κx = θy,x``, ``κy = -θx,y``, ``κxy = θy,y - θx,x``; transverse shear
    ``γxz = w,x + θy``, ``γyz = w,y - θx``; ``D_b = E t³ / (12 (1 - ν²))``, shear
    stiffness ``k G t`` with ``k = 5/6``.

    * Quad: MITC4 (Dvorkin & Bathe, "A continuum mechanics based four-node shell element
      for general nonlinear analysis", Eng. Comput. 1 (1984) 77-88; Bathe & Dvorkin,
      "A four-node plate bending element based on Mindlin/Reissner plate theory and a
      mixed interpolation", IJNME 21 (1985) 367-383): bilinear w and rotations; the
      covariant shear strains are tied at the edge midpoints, ``γ_ξ`` at (0, ±1) and
      ``γ_η`` at (±1, 0), and interpolated linearly across (IJNME 1985, eqs. 8-9), which
      removes shear locking; 2 x 2 Gauss quadrature.
    * Triangle: MITC3 (Lee & Bathe, "Development of MITC isotropic triangular shell
      finite elements", Comput. Struct. 82 (2004) 945-962): linear w and rotations; the
      assumed shear field is the rotated lowest-order Raviart-Thomas (Nédélec) field
      ``γ = a + b (-(y - y_c), x - x_c)`` whose tangential integrals along the three
      edges equal those of the displacement-based strain (the assumed-strain space of
      Lee & Bathe's tying). Its shear stiffness is scaled by ``t² / (t² + α h²)``, ``α = 0.1``,
      ``h`` the longest edge (Lyly, Stenberg & Vihinen, "A stable bilinear element for
      the Reissner-Mindlin plate model", CMAME 110 (1993) 343-357; Bletzinger, Bischoff
      & Ramm, Comput. Struct. 75 (2000) 321-334 use the same stabilisation for DSG3),
      which keeps the shear energy bounded as t → 0 and vanishes as O(h²) with the
      discretisation error. Measured on the thin (a/t = 1000) simply supported square,
      λ₁ errors at 4/8/16 elements per side: 24 %, 5.3 %, 1.3 % without, 14.7 %, 3.6 %,
      0.9 % with the stabilisation (MITC4 quads: 7.3 %, 1.7 %, 0.43 %).

Membrane
    * Quad: bilinear displacements plus Wilson's incompatible modes ``1 - ξ²``,
      ``1 - η²`` in Taylor's form (QM6: derivatives of the extra modes with the centre
      Jacobian, scaled by ``det J₀ / det J``, so that the patch test is passed; Taylor,
      Beresford & Wilson, IJNME 10 (1976) 1211-1219), condensed statically per element.
      They remove the parasitic shear of in-plane bending.
    * Triangle: constant strain (CST).
    * Drilling rotation rz: Hughes & Brezzi ("On drilling degrees of freedom", CMAME 72
      (1989) 105-121) penalty ``½ γ t ∫ (θz - ω)² dA`` with the in-plane rotation
      ``ω = ½ (v,x - u,y)``, integrated at the 2 x 2 Gauss points (quad) and the three
      edge midpoints (triangle), with ``γ = drilling · G``. It ties θz to the membrane
      rotation (so a beam's torsion about the shell normal is transmitted) and leaves a
      single free element with exactly six zero-energy modes. It is uncoupled from
      bending in a flat plate; changing ``drilling`` from 1e-3 to the default 1e-2 moves
      the in-plane frequencies of NAFEMS FV32 by < 1e-4, while Hughes & Brezzi's
      ``γ = G`` stiffens them by up to 0.5 % on a 16 x 8 mesh (tests).

Mass: consistent, from the same bilinear (quad, 2 x 2 Gauss, exact for flat quads) or
linear (triangle, exact) shape functions for all six fields, with ``ρ t`` for the
translations and ``ρ t³ / 12`` for the rotations. The drilling inertia ``ρ t³ / 12`` has
no physical basis in shell theory; it is a small nominal value that keeps M positive
definite. Local drilling modes lie near ``ω ≈ sqrt(12 drilling G / ρ) / t`` (3.4 kHz for
steel, t = 50 mm), far above the flexural and membrane modes of thin shells; for thick
shells raise ``drilling``.

Warped quads: the element is built on the projection of its nodes onto the mean plane
(normal along the cross product of the diagonals, through the centroid); the nodes lie
at ``±z₀`` from it. The projected nodes are tied to the real nodes by rigid offsets
(``u_p = u + θ × (p - x)``, the rigid-link warping correction discussed by MacNeal,
Finite Elements: Their Design and Performance, 1994), so that rigid-body motions of the
real nodes give zero strain energy. Warping makes the element less accurate; keep ``z₀``
small compared to the element size.

Imports nothing of femmech; arrays in, element matrices out.
"""

from __future__ import annotations

import numpy as np

from femmech.fe.elements.registry import ElementType, register

SHEAR_FACTOR = 5.0 / 6.0
DRILLING = 1e-2
STABILISATION = 0.1
ELEMENT_CHUNK = 8192
"""Elements per batch of :func:`shell_matrices`: the batch's intermediate arrays (about ten
of 24 x 24 per quad) stay near 0.4 GB however large the mesh, where one batch of all
elements would grow with it. Results do not depend on it (each element's arithmetic is
its own)."""

_G = 1.0 / np.sqrt(3.0)
_QUAD_GAUSS = np.array([[-_G, -_G], [_G, -_G], [_G, _G], [-_G, _G]])
_QUAD_NODES = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
# local DOF index blocks (per node, then node-major over the element)
_MEMBRANE = (0, 1, 5)  # u, v, θz
_BENDING = (2, 3, 4)  # w, θx, θy


def shell_frames(points: np.ndarray, cells: np.ndarray):
    """Local frames and in-plane coordinates of flat shell elements.

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    cells : ndarray (n_elements, 3 or 4), int
        Nodes counter-clockwise about the element normal.

    Returns
    -------
    R : ndarray (n_elements, 3, 3)
        Rows are the local unit axes x, y, z (z = normal) in global coordinates.
    xy : ndarray (n_elements, n_nodes, 2), m
        Local in-plane coordinates of the nodes projected on the mean plane, relative
        to the centroid.
    z : ndarray (n_elements, n_nodes), m
        Offsets of the nodes from the mean plane (zero for triangles and flat quads).

    Raises
    ------
    ValueError
        For a degenerate element (zero area), naming the first one.
    """
    X = points[cells]
    centre = X.mean(axis=1)
    if cells.shape[1] == 4:
        normal = np.cross(X[:, 2] - X[:, 0], X[:, 3] - X[:, 1])
        ex = X[:, 1] + X[:, 2] - X[:, 0] - X[:, 3]
    else:
        normal = np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])
        ex = X[:, 1] - X[:, 0]
    size = np.linalg.norm(normal, axis=1)
    scale = max(float(np.ptp(points, axis=0).max()), 1e-300)
    bad = np.flatnonzero(~(size > 1e-12 * scale**2))
    if bad.size:
        e = bad[0]
        raise ValueError(f"shell element {e} (nodes {cells[e].tolist()}) has zero area"
                         f" ({bad.size} degenerate elements in all)")
    ez = normal / size[:, None]
    ex = ex - np.sum(ex * ez, axis=1)[:, None] * ez
    ex /= np.linalg.norm(ex, axis=1)[:, None]
    ey = np.cross(ez, ex)
    R = np.stack([ex, ey, ez], axis=1)
    local = np.einsum("eij,ekj->eki", R, X - centre[:, None, :])
    return R, local[:, :, :2], local[:, :, 2]


def shell_matrices(points, cells, E, nu, rho, thickness, shear_factor=SHEAR_FACTOR,
                   drilling=DRILLING):
    """Global stiffness and consistent mass of flat shell elements of one type.

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    cells : ndarray (n_elements, 3) triangles or (n_elements, 4) quads, int
    E, nu, rho, thickness : float or ndarray (n_elements,)
        Young's modulus (Pa), Poisson's ratio, density (kg/m³), thickness (m).
    shear_factor : float
        Transverse shear correction factor k.
    drilling : float or ndarray (n_elements,)
        Drilling penalty ``γ / G`` (see the module docstring).

    Returns
    -------
    K : ndarray (n_elements, 6 n, 6 n), N/m, N, N m/rad
    M : ndarray (n_elements, 6 n, 6 n), kg, kg m, kg m²
        DOFs ``ux, uy, uz, rx, ry, rz`` per node, node-major, global axes.
    """
    cells = np.asarray(cells, dtype=np.int64)
    n, k = cells.shape
    if n == 0:
        return np.zeros((0, 6 * k, 6 * k)), np.zeros((0, 6 * k, 6 * k))
    if n > ELEMENT_CHUNK:
        return batched(shell_matrices, ELEMENT_CHUNK, points, cells, E, nu, rho, thickness,
                       shear_factor, drilling)
    R, xy, z = shell_frames(np.asarray(points, dtype=float), cells)
    E, nu, rho, t = (np.broadcast_to(np.asarray(p, dtype=float), (n,)).copy()
                     for p in (E, nu, rho, thickness))
    G = E / (2.0 * (1.0 + nu))
    C = plane_stress(E, nu)
    if k == 4:
        N, dN, wdet = _quad_points(xy, _QUAD_GAUSS, np.ones(4))
        Km = _quad_membrane(xy, C * t[:, None, None])
        Kb = _quad_bending(xy, C * (t**3 / 12.0)[:, None, None], shear_factor * G * t)
    elif k == 3:
        N, dN, wdet = _triangle_points(xy)
        Km = _triangle_membrane(dN[:, 0], wdet.sum(axis=1), C * t[:, None, None])
        Kb = _triangle_bending(xy, dN[:, 0], wdet.sum(axis=1),
                               C * (t**3 / 12.0)[:, None, None], shear_factor * G * t, t)
    else:
        raise ValueError(f"shell cells must have 3 or 4 nodes, got {k}")
    return global_matrices(R, z if k == 4 else None, Km, Kb, N, dN, wdet, G, t, rho,
                           drilling)


def batched(matrices, chunk: int, points, cells, E, nu, rho, thickness, shear_factor,
            drilling, **options):
    """``matrices(points, cells, ...)`` of a shell kind in batches of ``chunk`` elements,
    written into the result arrays (bounds the temporaries); the per-element properties
    (float or (n_elements,)) are sliced with the cells, ``options`` passed unchanged."""
    n, size = len(cells), 6 * cells.shape[1]
    per = [np.broadcast_to(np.asarray(p, dtype=float), (n,))
           for p in (E, nu, rho, thickness, drilling)]
    K, M = np.empty((n, size, size)), np.empty((n, size, size))
    for start in range(0, n, chunk):
        part = slice(start, start + chunk)
        K[part], M[part] = matrices(points, cells[part], *(p[part] for p in per[:4]),
                                    shear_factor, drilling=per[4][part], **options)
    return K, M


def global_matrices(R, z, Km, Kb, N, dN, wdet, G, t, rho, drilling):
    """Element stiffness and mass in global axes from the local parts of a flat shell.

    ``Km`` (n, 2k, 2k) membrane (u, v), ``Kb`` (n, 3k, 3k) bending (w, θx, θy), both
    local; the drilling penalty (``drilling · G``), the consistent mass (``ρ t``,
    ``ρ t³ / 12``) from ``N`` (q, k), ``dN`` (n, q, 2, k) and ``wdet`` (n, q) are added
    here; ``z`` (n, k): node offsets from the element plane (rigid offsets), or None.
    Returns K, M (n, 6k, 6k) on the DOFs ``ux … rz`` per node, global axes.
    """
    n, k = wdet.shape[0], N.shape[-1]
    Km += _drilling(N, dN, wdet, drilling * G * t)
    K = np.zeros((n, 6 * k, 6 * k))
    _scatter(K, Km, _MEMBRANE, k)
    _scatter(K, Kb, _BENDING, k)
    M = _mass(N, wdet, rho * t, rho * t**3 / 12.0)
    T = None if z is None else _offsets(z)
    return _to_global(R, K, T), _to_global(R, M, T)


def plane_stress(E, nu):
    """Plane-stress matrices ``E / (1 - ν²) [[1, ν, 0], [ν, 1, 0], [0, 0, (1 - ν)/2]]``."""
    C = np.zeros((len(E), 3, 3))
    C[:, 0, 0] = C[:, 1, 1] = 1.0
    C[:, 0, 1] = C[:, 1, 0] = nu
    C[:, 2, 2] = 0.5 * (1.0 - nu)
    return C * (E / (1.0 - nu**2))[:, None, None]


def _quad_shape(points):
    """Bilinear shape functions N (q, 4) and natural derivatives (q, 2, 4) at (q, 2)."""
    xi, eta = points[:, :1], points[:, 1:]
    a, b = _QUAD_NODES[:, 0], _QUAD_NODES[:, 1]
    N = 0.25 * (1 + xi * a) * (1 + eta * b)
    dN = np.stack([0.25 * a * (1 + eta * b), 0.25 * b * (1 + xi * a)], axis=1)
    return N, dN


def _quad_points(xy, points, weights):
    """N (q, 4), Cartesian derivatives (n, q, 2, 4) and weight x det J (n, q)."""
    N, dN = _quad_shape(points)
    J = np.einsum("qai,eib->eqab", dN, xy)
    det = J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
    if np.any(det <= 0):
        e = int(np.flatnonzero((det <= 0).any(axis=1))[0])
        raise ValueError(f"quad element {e} is inverted or not convex (node order must"
                         " go round the element)")
    dN_xy = np.linalg.solve(J, np.broadcast_to(dN, J.shape[:2] + (2, 4)))
    return N, dN_xy, det * weights


def membrane_b(dN):
    """Strain-displacement rows (…, 3, 2 k) of plane stress, DOFs (u, v) per node."""
    B = np.zeros(dN.shape[:-2] + (3, 2 * dN.shape[-1]))
    B[..., 0, 0::2] = dN[..., 0, :]
    B[..., 1, 1::2] = dN[..., 1, :]
    B[..., 2, 0::2] = dN[..., 1, :]
    B[..., 2, 1::2] = dN[..., 0, :]
    return B


def integrate(B, D, wdet):
    """Σ_q w_q det J_q Bᵀ D B for B (n, q, r, m), D (n, r, r), wdet (n, q)."""
    return np.einsum("eqri,ers,eqsj,eq->eij", B, D, B, wdet, optimize=True)


def _quad_membrane(xy, Ct):
    """Membrane stiffness (n, 12, 12), DOFs (u, v, θz) per node, QM6 condensed."""
    _, dN, wdet = _quad_points(xy, _QUAD_GAUSS, np.ones(4))
    Bc = membrane_b(dN)
    # incompatible modes 1 - ξ², 1 - η² with the centre Jacobian (Taylor et al. 1976)
    _, dN0 = _quad_shape(np.zeros((1, 2)))
    J0 = np.einsum("ai,eib->eab", dN0[0], xy)
    det0 = np.linalg.det(J0)
    nat = np.zeros((4, 2, 2))
    nat[:, 0, 0] = -2.0 * _QUAD_GAUSS[:, 0]
    nat[:, 1, 1] = -2.0 * _QUAD_GAUSS[:, 1]
    dP = np.linalg.solve(J0[:, None], np.broadcast_to(nat, (len(xy), 4, 2, 2)))
    dP *= (det0[:, None] / (wdet))[:, :, None, None]
    Bi = membrane_b(dP)
    Kcc = integrate(Bc, Ct, wdet)
    Kci = np.einsum("eqri,ers,eqsj,eq->eij", Bc, Ct, Bi, wdet, optimize=True)
    Kii = integrate(Bi, Ct, wdet)
    Km = Kcc - Kci @ np.linalg.solve(Kii, np.swapaxes(Kci, 1, 2))
    return expand_uv(Km, 4)


def expand_uv(Kuv, k):
    """(n, 2k, 2k) over (u, v) per node → (n, 3k, 3k) over (u, v, θz) per node."""
    idx = (3 * np.arange(k)[:, None] + np.arange(2)).ravel()
    K = np.zeros((len(Kuv), 3 * k, 3 * k))
    K[:, idx[:, None], idx] = Kuv
    return K


def _covariant_shear(N, dN, J):
    """Rows (n, q, 2, 12) of the covariant shear strains (γ_ξ, γ_η), DOFs (w, θx, θy)."""
    B = np.zeros(J.shape[:2] + (2, 12))
    for a in range(2):  # γ_a = w,a + θy x,a - θx y,a
        B[..., a, 0::3] = dN[:, a, :]
        B[..., a, 1::3] = -N[None, :, :] * J[..., a, 1, None]
        B[..., a, 2::3] = N[None, :, :] * J[..., a, 0, None]
    return B


def _quad_bending(xy, Db, Ds):
    """MITC4 bending + shear stiffness (n, 12, 12), DOFs (w, θx, θy) per node."""
    N, dN_xy, wdet = _quad_points(xy, _QUAD_GAUSS, np.ones(4))
    Bb = np.zeros(dN_xy.shape[:2] + (3, 12))
    Bb[..., 0, 2::3] = dN_xy[..., 0, :]
    Bb[..., 1, 1::3] = -dN_xy[..., 1, :]
    Bb[..., 2, 2::3] = dN_xy[..., 1, :]
    Bb[..., 2, 1::3] = -dN_xy[..., 0, :]
    K = integrate(Bb, Db, wdet)
    # tying points A (0,-1), C (0,1) for γ_ξ and D (-1,0), B (1,0) for γ_η (Bathe 1985)
    tying = np.array([[0.0, -1.0], [0.0, 1.0], [-1.0, 0.0], [1.0, 0.0]])
    Nt, dNt = _quad_shape(tying)
    Jt = np.einsum("qai,eib->eqab", dNt, xy)
    Bt = _covariant_shear(Nt, dNt, Jt)
    xi, eta = _QUAD_GAUSS[:, 0, None], _QUAD_GAUSS[:, 1, None]
    g_xi = 0.5 * (1 - eta) * Bt[:, None, 0, 0] + 0.5 * (1 + eta) * Bt[:, None, 1, 0]
    g_eta = 0.5 * (1 - xi) * Bt[:, None, 2, 1] + 0.5 * (1 + xi) * Bt[:, None, 3, 1]
    _, dN = _quad_shape(_QUAD_GAUSS)
    J = np.einsum("qai,eib->eqab", dN, xy)
    Bs = np.linalg.solve(J, np.stack([g_xi, g_eta], axis=2))  # γ_nat = J γ_xy
    eye = np.broadcast_to(np.eye(2), (len(xy), 2, 2)) * Ds[:, None, None]
    return K + integrate(Bs, eye, wdet)


def _triangle_points(xy):
    """Linear triangle: N (3, 3) at the edge midpoints, derivatives (n, 3, 2, 3), w det."""
    x, y = xy[..., 0], xy[..., 1]
    area2 = (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (x[:, 2] - x[:, 0]) * (y[:, 1] - y[:, 0])
    b = np.stack([y[:, 1] - y[:, 2], y[:, 2] - y[:, 0], y[:, 0] - y[:, 1]], axis=1)
    c = np.stack([x[:, 2] - x[:, 1], x[:, 0] - x[:, 2], x[:, 1] - x[:, 0]], axis=1)
    dN = np.stack([b, c], axis=1) / area2[:, None, None]
    N = np.array([[0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]])  # exact for degree 2
    wdet = np.repeat(area2[:, None] / 6.0, 3, axis=1)
    return N, np.repeat(dN[:, None], 3, axis=1), wdet


def _triangle_membrane(dN, area, Ct):
    """CST stiffness (n, 9, 9), DOFs (u, v, θz) per node."""
    B = membrane_b(dN)
    return expand_uv(area[:, None, None] * np.swapaxes(B, 1, 2) @ Ct @ B, 3)


def _triangle_bending(xy, dN, area, Db, Ds, t):
    """MITC3 bending + stabilised shear stiffness (n, 9, 9), DOFs (w, θx, θy) per node."""
    n = len(xy)
    Bb = np.zeros((n, 3, 9))
    Bb[:, 0, 2::3] = dN[:, 0]
    Bb[:, 1, 1::3] = -dN[:, 1]
    Bb[:, 2, 2::3] = dN[:, 1]
    Bb[:, 2, 1::3] = -dN[:, 0]
    K = area[:, None, None] * np.swapaxes(Bb, 1, 2) @ Db @ Bb
    i, j = np.array([0, 1, 2]), np.array([1, 2, 0])
    tvec = xy[:, j] - xy[:, i]  # (n, 3 edges, 2)
    mid = 0.5 * (xy[:, j] + xy[:, i])  # relative to the centroid
    # tangential integral of the shear strain along each edge, ∫ γ·dx
    Btau = np.zeros((n, 3, 9))
    for e in range(3):
        Btau[:, e, 3 * j[e]] += 1.0
        Btau[:, e, 3 * i[e]] -= 1.0
        for node in (i[e], j[e]):  # β = (θy, -θx) at the midpoint, dotted with the edge
            Btau[:, e, 3 * node + 1] = -0.5 * tvec[:, e, 1]
            Btau[:, e, 3 * node + 2] = 0.5 * tvec[:, e, 0]
    A = np.stack([tvec[..., 0], tvec[..., 1],
                  mid[..., 0] * tvec[..., 1] - mid[..., 1] * tvec[..., 0]], axis=2)
    coef = np.linalg.solve(A, Btau)  # (a1, a2, b) of γ = a + b (-y, x)
    P = np.zeros((n, 3, 2, 3))  # the field at the edge midpoints (exact for degree 2)
    P[..., 0, 0] = P[..., 1, 1] = 1.0
    P[..., 0, 2] = -mid[..., 1]
    P[..., 1, 2] = mid[..., 0]
    Bs = P @ coef[:, None]
    h2 = np.max(np.sum(tvec**2, axis=2), axis=1)
    ds = Ds * t**2 / (t**2 + STABILISATION * h2)
    eye = np.broadcast_to(np.eye(2), (n, 2, 2)) * ds[:, None, None]
    return K + integrate(Bs, eye, np.repeat(area[:, None] / 3.0, 3, axis=1))


def _drilling(N, dN, wdet, gamma_t):
    """Hughes-Brezzi drilling penalty (n, 3k, 3k), DOFs (u, v, θz) per node."""
    k = N.shape[1]
    B = np.zeros(dN.shape[:2] + (1, 3 * k))
    B[..., 0, 0::3] = 0.5 * dN[..., 1, :]
    B[..., 0, 1::3] = -0.5 * dN[..., 0, :]
    B[..., 0, 2::3] = N
    return integrate(B, gamma_t[:, None, None], wdet)


def _scatter(K, part, comps, k):
    idx = (6 * np.arange(k)[:, None] + np.array(comps)).ravel()
    K[:, idx[:, None], idx] += part


def _mass(N, wdet, rho_t, rho_i):
    """Consistent mass (n, 6k, 6k): ``∫ Nᵀ N`` times ρt (translations), ρt³/12 (rotations)."""
    scalar = np.einsum("qi,qj,eq->eij", N, N, wdet)
    k = N.shape[1]
    density = np.stack([rho_t] * 3 + [rho_i] * 3, axis=1)
    M = scalar[:, :, None, :, None] * (density[:, None, :, None, None]
                                       * np.eye(6)[None, None, :, None, :])
    return M.reshape(len(scalar), 6 * k, 6 * k)


def _offsets(z):
    """Rigid offsets (n, 24, 24) from the real nodes to their projections (local axes)."""
    n, k = z.shape
    T = np.broadcast_to(np.eye(6 * k), (n, 6 * k, 6 * k)).copy()
    # u_p = u + θ × r with r = (0, 0, -z): (θ × r)_x = θy r_z, (θ × r)_y = -θx r_z
    for a in range(k):
        r = -z[:, a]
        T[:, 6 * a + 0, 6 * a + 4] = r
        T[:, 6 * a + 1, 6 * a + 3] = -r
    return T


def _to_global(R, A, T=None):
    """``Qᵀ A Q`` with ``Q = T blockdiag(R, …)`` (local = Q global)."""
    n, m = len(R), A.shape[1] // 3
    Q = np.zeros((n, m, 3, m, 3))
    for a in range(m):
        Q[:, a, :, a, :] = R
    Q = Q.reshape(n, 3 * m, 3 * m)
    if T is not None:
        Q = T @ Q
    return np.swapaxes(Q, 1, 2) @ A @ Q


register(ElementType("triangle", "shell", shell_matrices))
register(ElementType("quad", "shell", shell_matrices))
