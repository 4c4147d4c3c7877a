"""Two-node 3D Timoshenko frame element, 6 DOF per node, vectorised over elements.

Local DOF order per element: ``(u, v, w, rx, ry, rz)`` at node a, then at node b.
Local x runs from node a to node b; the orientation vector ``v`` fixes the local x-y
plane (local y is the part of ``v`` normal to x; z = x × y), as in Nastran's CBEAM.

Bending uses the interdependent interpolation element (IIE) of Friedman & Kosmatka,
"An improved two-node Timoshenko beam finite element", Computers & Structures 47 (1993)
473-481: cubic deflection and quadratic rotation whose coefficients depend on
``Φ = 12 E I / (G A_s L²)``. Its stiffness is exact for a prismatic Timoshenko beam
(Przemieniecki, Theory of Matrix Structural Analysis, 1968, eq. 5.116); the consistent
mass (translational ρA and rotary ρI parts) is integrated from the same shape functions
by 4-point Gauss quadrature, exact for these polynomials (degree <= 6). ``Φ = 0``
(shear-rigid) is the Euler-Bernoulli element with cubic Hermite interpolation. Axial
and torsional fields are linear; torsional inertia is ``ρ I_p``.

Imports nothing of femmech; arrays in, element matrices out.
"""

from __future__ import annotations

import numpy as np

# local DOF indices of the two bending planes, ordered (w_a, θ_a, w_b, θ_b) with θ = dw/dx
PLANE_XY = np.array([1, 5, 7, 11])  # deflection v, rotation rz = +dv/dx
PLANE_XZ = np.array([2, 4, 8, 10])  # deflection w, rotation ry = -dw/dx
_SIGN_XZ = np.array([1.0, -1.0, 1.0, -1.0])
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(4)
_XI = 0.5 * (_GAUSS_X + 1.0)
_WEIGHTS = 0.5 * _GAUSS_W


def local_frames(points: np.ndarray, cells: np.ndarray, orientation=None):
    """Rotation matrices and lengths of line elements.

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    cells : ndarray (n_elements, 2), int
    orientation : array_like (3,) or (n_elements, 3), optional
        Vector in the local x-y plane. Default: ``ẑ × x`` (horizontal), so that local z
        points upwards and a section's "height" is vertical; for elements within 2.6°
        of the z axis (|cos| > 0.999) global y, so that local z is ∓ global x.

    Returns
    -------
    R : ndarray (n_elements, 3, 3)
        Rows are the local unit axes x, y, z in global coordinates (``u_local = R u``).
    length : ndarray (n_elements,), m

    Raises
    ------
    ValueError
        For a zero-length element or an orientation vector parallel to an element axis,
        naming the first offending element.
    """
    axis = points[cells[:, 1]] - points[cells[:, 0]]
    length = np.linalg.norm(axis, axis=1)
    scale = max(float(np.ptp(points, axis=0).max()), 1e-300)
    short = np.flatnonzero(length <= 1e-12 * scale)
    if short.size:
        e = short[0]
        raise ValueError(
            f"element {e} (nodes {cells[e, 0]} and {cells[e, 1]}) has zero length"
            f" ({short.size} zero-length elements in all)"
        )
    ex = axis / length[:, None]
    if orientation is None:
        ref = np.cross([0.0, 0.0, 1.0], ex)
        ref[np.abs(ex[:, 2]) > 0.999] = [0.0, 1.0, 0.0]
    else:
        ref = np.broadcast_to(np.asarray(orientation, dtype=float), ex.shape)
    ey = ref - np.sum(ref * ex, axis=1)[:, None] * ex
    ny = np.linalg.norm(ey, axis=1)
    norm_ref = np.linalg.norm(ref, axis=1)
    bad = np.flatnonzero(~(ny > 1e-6 * norm_ref))
    if bad.size:
        e = bad[0]
        raise ValueError(
            f"element {e} (nodes {cells[e, 0]}-{cells[e, 1]}): orientation vector"
            f" {ref[e].tolist()} is parallel to the element axis {ex[e].round(6).tolist()}"
        )
    ey /= ny[:, None]
    ez = np.cross(ex, ey)
    return np.stack([ex, ey, ez], axis=1), length


def bending_shape_functions(xi: np.ndarray, length: np.ndarray, phi: np.ndarray):
    """IIE deflection and rotation shape functions of one bending plane.

    Parameters
    ----------
    xi : ndarray (n_points,)
        Positions along the element, 0 at node a and 1 at node b.
    length, phi : ndarray (n_elements,)
        Element lengths (m) and shear parameters Φ (-).

    Returns
    -------
    Nw, Ntheta : ndarray (n_elements, n_points, 4)
        ``w = Nw @ (w_a, θ_a, w_b, θ_b)`` and ``θ = Ntheta @ (...)``, θ = dw/dx + γ-free
        rotation of the section (Friedman & Kosmatka 1993, eq. 14).
    """
    x = xi[None, :]
    L = length[:, None]
    p = phi[:, None]
    c = 1.0 / (1.0 + p)
    Nw = np.stack([
        c * (2 * x**3 - 3 * x**2 - p * x + 1 + p),
        c * L * (x**3 - (2 + p / 2) * x**2 + (1 + p / 2) * x),
        c * (-2 * x**3 + 3 * x**2 + p * x),
        c * L * (x**3 - (1 - p / 2) * x**2 - p / 2 * x),
    ], axis=-1)
    Nt = np.stack([
        c * 6 / L * (x**2 - x),
        c * (3 * x**2 - (4 + p) * x + 1 + p),
        -c * 6 / L * (x**2 - x),
        c * (3 * x**2 - (2 - p) * x),
    ], axis=-1)
    return Nw, Nt


def bending_matrices(length, EI, GAs, rhoA, rhoI):
    """Stiffness and consistent mass of one bending plane, DOFs (w_a, θ_a, w_b, θ_b).

    Parameters
    ----------
    length, EI, GAs, rhoA, rhoI : ndarray (n_elements,)
        Length (m), bending stiffness (N m²), shear stiffness (N; ``inf`` = rigid),
        mass per length (kg/m) and rotary inertia per length (kg m).

    Returns
    -------
    K, M : ndarray (n_elements, 4, 4)
        ``K`` from Przemieniecki (1968) eq. 5.116; ``M`` integrated from the IIE shape
        functions (translational + rotary parts).
    """
    L = length
    phi = 12.0 * EI / (GAs * L**2)
    a = EI / ((1.0 + phi) * L**3)
    K = np.empty((len(L), 4, 4))
    K[:, 0] = np.stack([12 + 0 * L, 6 * L, -12 + 0 * L, 6 * L], axis=1)
    K[:, 1] = np.stack([6 * L, (4 + phi) * L**2, -6 * L, (2 - phi) * L**2], axis=1)
    K[:, 2] = -K[:, 0]
    K[:, 3] = np.stack([6 * L, (2 - phi) * L**2, -6 * L, (4 + phi) * L**2], axis=1)
    K *= a[:, None, None]
    Nw, Nt = bending_shape_functions(_XI, L, phi)
    wL = _WEIGHTS[None, :] * L[:, None]
    # M = Σ_q w_q L (ρA Nwᵀ Nw + ρI Nθᵀ Nθ) at the Gauss points, as batched 4x4 products
    M = np.swapaxes(Nw * (wL * rhoA[:, None])[:, :, None], 1, 2) @ Nw
    M += np.swapaxes(Nt * (wL * rhoI[:, None])[:, :, None], 1, 2) @ Nt
    return K, M


def local_matrices(length, E, G, rho, A, Iy, Iz, J, Ip, Asy, Asz, rotary_inertia=True):
    """Local 12x12 stiffness and mass of frame elements; all inputs (n_elements,) arrays.

    Units: m, Pa, kg/m^3, m^2, m^4. ``Asy``/``Asz = inf`` gives Euler-Bernoulli bending in
    that plane. Returns ``K, M`` of shape (n_elements, 12, 12) in the local frame.
    """
    n = len(length)
    K = np.zeros((n, 12, 12))
    M = np.zeros((n, 12, 12))
    bar = np.array([[1.0, -1.0], [-1.0, 1.0]])
    consistent_pair = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6.0
    for idx, stiff, inertia in ((np.array([0, 6]), E * A, rho * A),
                                (np.array([3, 9]), G * J, rho * Ip)):
        K[:, idx[:, None], idx[None, :]] = (stiff / length)[:, None, None] * bar
        M[:, idx[:, None], idx[None, :]] = (inertia * length)[:, None, None] * consistent_pair
    rot = np.asarray(rotary_inertia, dtype=float)
    for idx, inertia, shear_area, sign in (
        (PLANE_XY, Iz, Asy, None),
        (PLANE_XZ, Iy, Asz, _SIGN_XZ),
    ):
        Kb, Mb = bending_matrices(length, E * inertia, G * shear_area, rho * A,
                                  rot * rho * inertia)
        if sign is not None:
            Kb = Kb * np.outer(sign, sign)
            Mb = Mb * np.outer(sign, sign)
        K[:, idx[:, None], idx[None, :]] = Kb
        M[:, idx[:, None], idx[None, :]] = Mb
    return K, M


def rotate_to_global(R: np.ndarray, A_local: np.ndarray) -> np.ndarray:
    """``Tᵀ A T`` with ``T = blockdiag(R, R, R, R)``; R (n, 3, 3), A (n, 12, 12)."""
    n = len(R)
    T = np.zeros((n, 4, 3, 4, 3))
    for a in range(4):
        T[:, a, :, a, :] = R
    T = T.reshape(n, 12, 12)
    # batched 12x12 products (BLAS) rather than a structured einsum over the 3x3 blocks
    return np.swapaxes(T, 1, 2) @ A_local @ T


def beam_matrices(points, cells, orientation, E, G, rho, A, Iy, Iz, J, Ip, Asy, Asz,
                  rotary_inertia: bool = True):
    """Global stiffness and consistent mass of 3D frame elements.

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    cells : ndarray (n_elements, 2), int
    orientation : array_like (3,) or (n_elements, 3) or None
        See :func:`local_frames`.
    E, G, rho, A, Iy, Iz, J, Ip, Asy, Asz : float or ndarray (n_elements,)
        Material (Pa, Pa, kg/m³) and section (m², m⁴) properties; ``Asy``/``Asz = inf``
        for shear-rigid (Euler-Bernoulli) bending.
    rotary_inertia : bool or ndarray (n_elements,) of bool
        Include the rotary inertia ρI of bending (torsional inertia is always kept).

    Returns
    -------
    K : ndarray (n_elements, 12, 12), N/m, N, N m/rad
    M : ndarray (n_elements, 12, 12), kg, kg m, kg m²
    """
    R, length = local_frames(points, cells, orientation)
    n = len(cells)
    props = [np.broadcast_to(np.asarray(p, dtype=float), (n,))
             for p in (E, G, rho, A, Iy, Iz, J, Ip, Asy, Asz, rotary_inertia)]
    K, M = local_matrices(length, *props[:-1], rotary_inertia=props[-1])
    return rotate_to_global(R, K), rotate_to_global(R, M)
