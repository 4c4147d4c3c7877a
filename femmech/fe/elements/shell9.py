"""MITC9: the 9-node quadratic shell quadrilateral with 6 DOF per node, vectorised.

Bucalem & Bathe, "Higher-order MITC general shell elements", IJNME 36 (1993) 3729-3754;
Bathe, Lee & Hiller, "Towards improving the MITC9 shell element", Comput. Struct. 81
(2003) 477-489. Node order of meshio's ``"quad9"`` (VTK_BIQUADRATIC_QUAD): corners 0-3
counter-clockwise at natural coordinates (-1, -1), (1, -1), (1, 1), (-1, 1), edge
midpoints 4-7 on the edges 0-1, 1-2, 2-3, 3-0, centre 8.

The element is flat, built in its local frame like the MITC4 quad of
:mod:`femmech.fe.elements.shell` (x, y in the mean plane, z its normal) and rotated to
global axes; DOFs per node ``ux, uy, uz, rx, ry, rz``, shared with beams. Membrane,
bending and drilling parts are uncoupled in the local frame. **Curved geometry is
faceted per element**: nodes off the mean plane (normal along the cross product of the
corner diagonals, through the centroid of the nine nodes) are projected onto it and
tied to their projections by rigid offsets (``u_p = u + θ × (p - x)``, as for warped
MITC4 quads), so that rigid-body motions give zero strain energy; the curvature of a
shell enters through the orientations of neighbouring elements, and a curved element
is no better than the flat facet through its nodes.

Bending (Mindlin-Reissner, the sign conventions of :mod:`.shell`)
    Biquadratic w and rotations; curvatures integrated with 3 x 3 Gauss points. The
    transverse shear is interpolated from covariant strains tied at points (MITC):
    ``γ_ξ = w,ξ + θy x,ξ - θx y,ξ`` is evaluated at the 2 x 3 points ``ξ = ±1/√3``,
    ``η ∈ {η₁, η₂, η₃}`` and interpolated between them by the product of the linear
    Lagrange polynomials in ξ and the quadratic ones in η; ``γ_η`` symmetrically; the
    Cartesian strains follow from ``γ_nat = J γ_xy`` at each Gauss point. Shear stiffness
    ``k G t``, ``k = 5/6``.

    * ``tying="edges"`` (default): η = -1, 0, 1. ``γ_ξ`` is the tangential shear of the
      edges η = ±1: it is tied at the two Gauss points of each of these edges (values
      that the two elements of an edge share, as the tangential moments of
      Raviart-Thomas-type shear spaces are) and at two interior points on η = 0. This
      follows the construction of the MITC9 plate element (Bathe, Bucalem & Brezzi,
      "Displacement and stress convergence of our MITC plate bending elements", Eng.
      Comput. 7 (1990) 291-302: tangential shear moments on the edges plus interior
      conditions), in point form.
    * ``tying="gauss"``: η = 0, ±√(3/5), the points of Bucalem & Bathe's MITC9 shell
      element (1993, the transverse shear tied like ``e_rr``/``e_ss``).

    On parallelogram (affine) elements both give the same stiffness: the covariant
    shear of the displacement field is quadratic along each tying line, so any three
    points give it exactly. On distorted (non-affine) meshes only the edge tying stays
    free of shear locking — measured on the simply supported plate, 4 x 4 elements
    with corners moved by 30 % of the element size: λ₁ errors 1.2e-3 at a/t = 10 … 10⁴
    with ``"edges"``, 1.1e-3, 4.6e-3, 6.0e-2, 0.35 with ``"gauss"`` (tests/test_shell9.py).
    Frequencies converge as h⁴ (measured slopes 3.9-4.0 on regular, 3.7-3.9 on
    distorted meshes).

Membrane
    Biquadratic displacements with full 3 x 3 Gauss integration, not the assumed
    membrane strains of MITC9: in a flat element membrane and bending are uncoupled,
    so there is no membrane locking (it appears in curved elements, which this one is
    not). Drilling rotation rz: the Hughes & Brezzi penalty ``½ γ t ∫ (θz - ω)² dA``,
    ``ω = ½ (v,x - u,y)``, ``γ = drilling · G``, at the 3 x 3 Gauss points, as for the
    linear elements; a single free element has exactly six zero-energy modes.

Mass: consistent, from the biquadratic shape functions for all six fields (3 x 3 Gauss,
exact for parallelogram elements), ``ρ t`` for the translations and ``ρ t³ / 12`` for
the rotations, with the same nominal drilling inertia ``ρ t³ / 12`` as :mod:`.shell`.

``"quad8"`` meshes: :func:`femmech.fe.mesh.quad8_to_quad9` adds the centre node where
the serendipity map puts it, and :func:`femmech.build_model` applies it. The centre
node of a free quad8 shell stays a MITC9 centre node: the 9-node element is the more
accurate one, and a free shell has no local mode of it (the quad8 plate gives the quad9
plate's frequencies). Where all eight nodes of a quad8 cell belong to solid elements (a
skin or coating on a solid face, as decks from other codes have), the centre node would
be held by nothing but the skin while the eight move with the solid: its transverse
motion is then a local mode of the skin alone, low for a thin skin (bending stiffness
``∝ t³`` against mass ``∝ t``). There ``build_model`` ties the centre's translations to
the serendipity interpolation of the eight, ``u_9 = -¼ Σ corners + ½ Σ edge nodes``
(:data:`femmech.fe.mesh.QUAD8_CENTRE`), the kinematics of the file's 8-node element, as
linear constraint equations eliminated with the supports and links (``u = T u_free``,
:mod:`femmech.fe.constraints`), so mode shapes and files show the centre's motion as
interpolated. Its rotations stay free: tying them too restricts the MITC9 shear
interpolation to serendipity rotations, which locks (regular 4 x 4 simply supported
plate, a/t = 10³: λ₁ +121 %), while the translations alone do not (λ₁ error 5.3e-3 at
both a/t = 10³ and 10⁴); a skin's free centre rotation is held by its transverse shear,
near ``sqrt(12 k G / ρ) / (2 π t)`` (16 MHz for a 0.1 mm steel skin). An untied centre
would add spurious modes among the solid's (kHz on a steel cantilever with a 0.1 mm
quad8 skin on its end); tied, the solid's modes stay, each lowered by the skin's mass as
the first-order mass perturbation predicts (tests/test_quad8_skin.py).
Where a node is already at the centre (the face centre of a ``hexahedron27`` under the
skin), it is the centre node and nothing is tied: the solid holds it (an added node
would coincide with it).

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

NODES = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0], [0.0, -1.0],
                  [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, 0.0]])
"""Natural coordinates (ξ, η) of the nine nodes in meshio's quad9 order."""

_A = np.sqrt(0.6)
_GAUSS1, _WEIGHT1 = np.array([-_A, 0.0, _A]), np.array([5.0, 8.0, 5.0]) / 9.0
GAUSS = np.array([[x, y] for y in _GAUSS1 for x in _GAUSS1])
"""3 x 3 Gauss points (9, 2) and their weights (9,)."""
WEIGHTS = np.array([wx * wy for wy in _WEIGHT1 for wx in _WEIGHT1])
_R = 1.0 / np.sqrt(3.0)
_TYING_A = np.array([-_R, _R])  # the linear direction of the tying grid
TYING = {"edges": np.array([-1.0, 0.0, 1.0]), "gauss": np.array([-_A, 0.0, _A])}
"""Tying lines of the quadratic direction: ``γ_ξ`` is tied at ξ = ±1/√3 and η in
``TYING[kind]`` (γ_η symmetrically). ``"edges"`` (default): η = -1, 0, 1, the edges and
the centre line; ``"gauss"``: η = 0, ±√(3/5) (module docstring)."""


def _lagrange(points, x):
    """1D Lagrange polynomials through ``points`` (p,) and their derivatives at x (q,).

    Returns L, dL of shape (q, p).
    """
    x = np.asarray(x, dtype=float)[:, None]
    L = np.ones((len(x), len(points)))
    dL = np.zeros_like(L)
    for i, pi in enumerate(points):
        others = [pj for j, pj in enumerate(points) if j != i]
        denom = np.prod([pi - pj for pj in others])
        L[:, i] = np.prod([x[:, 0] - pj for pj in others], axis=0) / denom
        for m in range(len(others)):
            dL[:, i] += np.prod([x[:, 0] - pj for j, pj in enumerate(others) if j != m],
                                axis=0) / denom
    return L, dL


def shape9(points):
    """Biquadratic shape functions N (q, 9) and natural derivatives (q, 2, 9) at (q, 2)."""
    points = np.asarray(points, dtype=float)
    grid = np.array([-1.0, 0.0, 1.0])
    Lx, dLx = _lagrange(grid, points[:, 0])
    Ly, dLy = _lagrange(grid, points[:, 1])
    i = (NODES[:, 0] + 1).astype(int)
    j = (NODES[:, 1] + 1).astype(int)
    N = Lx[:, i] * Ly[:, j]
    dN = np.stack([dLx[:, i] * Ly[:, j], Lx[:, i] * dLy[:, j]], axis=1)
    return N, dN


def frames9(points: np.ndarray, cells: np.ndarray):
    """Local frames, in-plane node coordinates and offsets of 9-node shell elements.

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    cells : ndarray (n_elements, 9), int
        meshio quad9 node order, corners counter-clockwise about the element normal.

    Returns
    -------
    R : ndarray (n_elements, 3, 3)
        Rows are the local unit axes x, y, z (z = normal) in global coordinates.
    xy : ndarray (n_elements, 9, 2), m
        Local in-plane coordinates of the nodes projected on the mean plane.
    z : ndarray (n_elements, 9), m
        Offsets of the nodes from the mean plane (zero for flat elements).

    Raises
    ------
    ValueError
        For a degenerate element (zero area), naming the first one.
    """
    try:  # the frame of the corners, as for the 4-node quad
        R, _, _ = shell_frames(points, cells[:, :4])
    except ValueError as err:
        raise ValueError(f"quad9 {err}") from None
    X = points[cells]
    local = np.einsum("eij,ekj->eki", R, X - X.mean(axis=1)[:, None, :])
    return R, local[:, :, :2], local[:, :, 2]


def _jacobians(xy, points):
    """N (q, 9), dN natural (q, 2, 9), J (n, q, 2, 2) with ``J[a, b] = ∂x_b/∂ξ_a``."""
    N, dN = shape9(points)
    return N, dN, np.einsum("qai,eib->eqab", dN, xy)


def _gauss(xy):
    """N (9, 9), Cartesian derivatives (n, 9, 2, 9), J (n, 9, 2, 2), w det J (n, 9)."""
    N, dN, J = _jacobians(xy, GAUSS)
    det = J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
    if np.any(det <= 0):
        e = int(np.flatnonzero((det <= 0).any(axis=1))[0])
        raise ValueError(f"quad9 element {e} is inverted or too distorted (det J <= 0 at"
                         " a Gauss point; corners must go round the element and the edge"
                         " nodes lie near the edge midpoints)")
    dN_xy = np.linalg.solve(J, np.broadcast_to(dN, J.shape[:2] + (2, 9)))
    return N, dN_xy, J, det * WEIGHTS


def _covariant_row(N, dN, J, a):
    """Rows (n, q, 27) of the covariant shear strain γ_a, DOFs (w, θx, θy) per node.

    ``γ_a = w,a + θy x,a - θx y,a`` (a = 0: ξ, a = 1: η).
    """
    B = np.zeros(J.shape[:2] + (27,))
    B[..., 0::3] = dN[:, a, :]
    B[..., 1::3] = -N[None, :, :] * J[..., a, 1, None]
    B[..., 2::3] = N[None, :, :] * J[..., a, 0, None]
    return B


def _tied_shear(xy, J, lines):
    """MITC9 assumed covariant shear rows (n, 9 Gauss points, 2, 27); ``lines`` (3,)."""
    rows = []
    for a in (0, 1):  # γ_ξ: linear in ξ, quadratic in η; γ_η the other way round
        lin, quad = np.meshgrid(_TYING_A, lines, indexing="ij")
        tying = np.stack([lin.ravel(), quad.ravel()] if a == 0
                         else [quad.ravel(), lin.ravel()], axis=1)  # (6, 2)
        Nt, dNt, Jt = _jacobians(xy, tying)
        Bt = _covariant_row(Nt, dNt, Jt, a)  # (n, 6, 27)
        La, _ = _lagrange(_TYING_A, GAUSS[:, a])
        Lb, _ = _lagrange(lines, GAUSS[:, 1 - a])
        weights = (La[:, :, None] * Lb[:, None, :]).reshape(len(GAUSS), 6)
        rows.append(np.einsum("qt,etj->eqj", weights, Bt))
    return np.linalg.solve(J, np.stack(rows, axis=2))  # γ_nat = J γ_xy


def _bending(xy, Db, Ds, lines):
    """MITC9 bending + shear stiffness (n, 27, 27), DOFs (w, θx, θy) per node."""
    _, dN_xy, J, wdet = _gauss(xy)
    Bb = np.zeros(dN_xy.shape[:2] + (3, 27))
    Bb[..., 0, 2::3] = dN_xy[..., 0, :]
    Bb[..., 1, 1::3] = -dN_xy[..., 1, :]
    Bb[..., 2, 2::3] = dN_xy[..., 1, :]
    Bb[..., 2, 1::3] = -dN_xy[..., 0, :]
    Bs = _tied_shear(xy, J, lines)
    eye = np.broadcast_to(np.eye(2), (len(xy), 2, 2)) * Ds[:, None, None]
    return integrate(Bb, Db, wdet) + integrate(Bs, eye, wdet)


def shell9_matrices(points, cells, E, nu, rho, thickness, shear_factor=SHEAR_FACTOR,
                    drilling=DRILLING, tying="edges"):
    """Global stiffness and consistent mass of MITC9 shell elements.

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    cells : ndarray (n_elements, 9), int
        meshio quad9 node order (module docstring).
    E, nu, rho, thickness : float or ndarray (n_elements,)
        Young's modulus (Pa), Poisson's ratio, density (kg/m³), thickness (m).
    shear_factor : float
        Transverse shear correction factor k.
    drilling : float or ndarray (n_elements,)
        Drilling penalty ``γ / G`` (:mod:`femmech.fe.elements.shell`).
    tying : ``"edges"`` (default) or ``"gauss"``
        Tying lines of the transverse shear (:data:`TYING`, module docstring).

    Returns
    -------
    K : ndarray (n_elements, 54, 54), N/m, N, N m/rad
    M : ndarray (n_elements, 54, 54), kg, kg m, kg m²
        DOFs ``ux, uy, uz, rx, ry, rz`` per node, node-major, global axes.
    """
    cells = np.asarray(cells, dtype=np.int64)
    n = len(cells)
    if tying not in TYING:
        raise ValueError(f"tying must be one of {list(TYING)}, got {tying!r}")
    if cells.ndim != 2 or cells.shape[1] != 9:
        raise ValueError(f"quad9 shell cells must have shape (n, 9), got {cells.shape}")
    if n == 0:
        return np.zeros((0, 54, 54)), np.zeros((0, 54, 54))
    chunk = ELEMENT_CHUNK // 4  # 54 x 54 blocks: about 5 times the memory of a quad's
    if n > chunk:
        return batched(shell9_matrices, chunk, points, cells, E, nu, rho, thickness,
                       shear_factor, drilling, tying=tying)
    R, xy, z = frames9(np.asarray(points, dtype=float), cells)
    E, nu, rho, t, drill = (np.broadcast_to(np.asarray(p, dtype=float), (n,)).copy()
                            for p in (E, nu, rho, thickness, drilling))
    G = E / (2.0 * (1.0 + nu))
    C = plane_stress(E, nu)
    N, dN_xy, _, wdet = _gauss(xy)
    Km = expand_uv(integrate(membrane_b(dN_xy), C * t[:, None, None], wdet), 9)
    Kb = _bending(xy, C * (t**3 / 12.0)[:, None, None], shear_factor * G * t, TYING[tying])
    return global_matrices(R, z, Km, Kb, N, dN_xy, wdet, G, t, rho, drill)


register(ElementType("quad9", "shell", shell9_matrices))
