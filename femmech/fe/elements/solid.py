"""Isoparametric solid elements (3 translational DOFs per node), vectorised.

Cell types (meshio names, VTK node order) and their scikit-fem reference elements:

======================  ==============  =======================  =====================
meshio type             nodes           scikit-fem element       quadrature (exact to)
======================  ==============  =======================  =====================
``"tetra"``             4 (P1)          ``ElementTetP1``         degree 2 (4 points)
``"tetra10"``           10 (P2)         ``ElementTetP2``         degree 4 (11 points)
``"hexahedron"``        8 (Q1)          ``ElementHex1``          2 x 2 x 2 Gauss
``"hexahedron20"``      20 (serendip.)  ``ElementHexS2``         3 x 3 x 3 Gauss
``"hexahedron27"``      27 (Q2)         ``ElementHex2``          3 x 3 x 3 Gauss
======================  ==============  =======================  =====================

scikit-fem supplies the reference shape functions (``Element.lbasis``), the reference
node locations (``Element.doflocs``, used to permute its local DOFs to meshio's node
order) and the quadrature rules (``skfem.quadrature.get_quadrature``). The isoparametric
map and the integrals are batched numpy here, element by element, instead of through
``skfem.Basis``: a Basis numbers quadratic DOFs by scikit-fem's own edges and faces,
while femmech needs the mesh's nodes; and scikit-fem's vector elasticity form is slower
than the scalar derivative blocks used below.

Stiffness (linear elasticity, ``σ = λ tr(ε) I + 2 μ ε``, ``λ = 2 G ν / (1 - 2 ν)``,
``μ = G``): with ``S_ab[i, j] = ∫ ∂_a φ_i ∂_b φ_j dV``, the 3 x 3 block of nodes i, j is

    ``K[(i, a), (j, b)] = λ S_ab[i, j] + μ (δ_ab Σ_c S_cc[i, j] + S_ba[i, j])``

(the bilinear form ``∫ λ div u div v + 2 μ ε(u) : ε(v)``, e.g. Hughes, The Finite
Element Method, 1987, sec. 2.7). Mass: consistent, ``M[(i, a), (j, b)] = δ_ab ρ ∫ φ_i
φ_j dV``. Full integration throughout: no hourglass modes, but the linear elements
(tetra, hexahedron) lock in bending (shear locking; tests quantify it); use the
quadratic ones for bending-dominated parts.

DOFs: ``ux, uy, uz`` per node, node-major (``3 node_local + component``);
:func:`assemble_solid` places them at femmech's ``6 node + component``.

Uses only fe.assembly and fe.dofs.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import skfem
from skfem.quadrature import get_quadrature

from femmech.fe.assembly import assemble
from femmech.fe.dofs import DOF_PER_NODE
from femmech.fe.elements.registry import ElementType, register

_HEX_VERTICES = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                          [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float)
# VTK / meshio edge order of quadratic hexahedra (vtkQuadraticHexahedron)
_HEX_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4),
              (0, 4), (1, 5), (2, 6), (3, 7)]
# VTK face centres 20-25 (vtkTriQuadraticHexahedron): x = 0, x = 1, y = 0, y = 1, z = 0, z = 1
_HEX_FACES = [[0, .5, .5], [1, .5, .5], [.5, 0, .5], [.5, 1, .5], [.5, .5, 0], [.5, .5, 1]]
_TET_VERTICES = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
# VTK / meshio edge order of tetra10 (vtkQuadraticTetra)
_TET_EDGES = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)]


def _midpoints(vertices, edges):
    return np.array([(vertices[a] + vertices[b]) / 2 for a, b in edges])


REFERENCE_NODES = {
    "tetra": _TET_VERTICES,
    "tetra10": np.vstack([_TET_VERTICES, _midpoints(_TET_VERTICES, _TET_EDGES)]),
    "hexahedron": _HEX_VERTICES,
    "hexahedron20": np.vstack([_HEX_VERTICES, _midpoints(_HEX_VERTICES, _HEX_EDGES)]),
    "hexahedron27": np.vstack([_HEX_VERTICES, _midpoints(_HEX_VERTICES, _HEX_EDGES),
                               _HEX_FACES, [[.5, .5, .5]]]),
}
"""Reference coordinates of the nodes of each cell type in meshio (VTK) order."""

_ELEMENTS = {"tetra": (skfem.ElementTetP1, 2), "tetra10": (skfem.ElementTetP2, 4),
             "hexahedron": (skfem.ElementHex1, 3), "hexahedron20": (skfem.ElementHexS2, 5),
             "hexahedron27": (skfem.ElementHex2, 5)}
SOLID_TYPES = tuple(_ELEMENTS)
"""meshio cell types with solid elements."""

CHUNK_ENTRIES = 2_000_000
"""Element-matrix entries per batch in :func:`assemble_solid` (16 MB per temporary)."""


def reference_element(kind: str):
    """Shape functions at the quadrature points of a cell type, in meshio node order.

    Parameters
    ----------
    kind : str
        One of :data:`SOLID_TYPES`.

    Returns
    -------
    N : ndarray (n_points, k)
        Shape function values.
    dN : ndarray (n_points, 3, k)
        Derivatives with respect to the reference coordinates.
    weights : ndarray (n_points,)
        Quadrature weights (they sum to the reference volume, 1/6 or 1).
    """
    if kind not in _ELEMENTS:
        raise ValueError(f"{kind!r} is not a solid cell type; expected one of {SOLID_TYPES}")
    element_type, order = _ELEMENTS[kind]
    element = element_type()
    nodes = REFERENCE_NODES[kind]
    # scikit-fem local DOF of each meshio node, by reference location
    distance = np.linalg.norm(element.doflocs[None, :, :] - nodes[:, None, :], axis=2)
    perm = np.argmin(distance, axis=1)
    if not (np.allclose(distance[np.arange(len(nodes)), perm], 0.0)
            and np.unique(perm).size == len(nodes)):
        raise RuntimeError(f"scikit-fem's {element_type.__name__} nodes do not match {kind}")
    X, W = get_quadrature(element.refdom, order)
    N = np.empty((X.shape[1], len(nodes)))
    dN = np.empty((X.shape[1], 3, len(nodes)))
    for j, i in enumerate(perm):
        phi, dphi = element.lbasis(X, i)
        N[:, j] = phi
        dN[:, :, j] = np.asarray(dphi).T
    return N, dN, W


def solid_matrices(points, cells, kind: str, E, nu, rho):
    """Stiffness and consistent mass of solid elements of one cell type.

    Parameters
    ----------
    points : ndarray (n_nodes, 3), m
    cells : ndarray (n_elements, k), int
        Connectivity in meshio (VTK) node order.
    kind : str
        meshio cell type, one of :data:`SOLID_TYPES`.
    E, nu, rho : float or ndarray (n_elements,)
        Young's modulus (Pa), Poisson's ratio, density (kg/m³).

    Returns
    -------
    K : ndarray (n_elements, 3 k, 3 k), N/m
    M : ndarray (n_elements, 3 k, 3 k), kg
        DOFs ``ux, uy, uz`` per node, node-major, global axes.

    Raises
    ------
    ValueError
        For an inverted or degenerate element (non-positive Jacobian at a quadrature
        point), naming the first one.
    """
    cells = np.asarray(cells, dtype=np.int64)
    n, k = cells.shape
    N, dN, W = reference_element(kind)
    if k != N.shape[1]:
        raise ValueError(f"{kind} cells must have {N.shape[1]} nodes, got {k}")
    E, nu, rho = (np.broadcast_to(np.asarray(p, dtype=float), (n,)) for p in (E, nu, rho))
    X = np.asarray(points, dtype=float)[cells]
    J = np.einsum("qai,eib->eqab", dN, X)  # J[a, b] = ∂x_b / ∂ξ_a
    det = np.linalg.det(J)
    scale = np.ptp(X, axis=1).max(axis=1) ** 3 if n else np.zeros(0)
    bad = np.flatnonzero(~(det > 1e-12 * scale[:, None]).all(axis=1))
    if bad.size:
        e = bad[0]
        raise ValueError(f"{kind} element {e} (nodes {cells[e].tolist()}) is inverted or"
                         f" degenerate: check its node order ({bad.size} such elements)")
    dNx = np.linalg.solve(J, np.broadcast_to(dN, (n,) + dN.shape))  # ∂φ/∂x, (n, q, 3, k)
    wdet = det * W
    S = np.einsum("eq,eqai,eqbj->eijab", wdet, dNx, dNx, optimize=True)
    mu = E / (2.0 * (1.0 + nu))
    lam = 2.0 * mu * nu / (1.0 - 2.0 * nu)
    trace = np.trace(S, axis1=3, axis2=4)
    K = (lam[:, None, None, None, None] * S
         + mu[:, None, None, None, None] * (trace[..., None, None] * np.eye(3)
                                            + np.swapaxes(S, 3, 4)))
    K = K.transpose(0, 1, 3, 2, 4).reshape(n, 3 * k, 3 * k)
    m = np.einsum("e,eq,qi,qj->eij", rho, wdet, N, N, optimize=True)
    M = (m[:, :, None, :, None] * np.eye(3)[None, None, :, None, :]).reshape(n, 3 * k, 3 * k)
    return K, M


def solid_dofs(cells: np.ndarray) -> np.ndarray:
    """femmech DOFs ``6 node + (0, 1, 2)`` of each element, (n_elements, 3 k)."""
    cells = np.asarray(cells, dtype=np.int64)
    return (DOF_PER_NODE * cells[:, :, None] + np.arange(3)).reshape(len(cells), -1)


def assemble_solid(points, cells, kind: str, E, nu, rho, n_dof: int, chunk: int | None = None):
    """Global stiffness and mass of solid elements in femmech's 6-DOF numbering.

    Parameters
    ----------
    points, cells, kind, E, nu, rho
        As for :func:`solid_matrices`.
    n_dof : int
        Size of the global matrices (``6 n_nodes``).
    chunk : int, optional
        Elements per batch (bounds memory; the result does not depend on it beyond
        round-off in the order of summation). Default: about :data:`CHUNK_ENTRIES`
        element-matrix entries per batch.

    Returns
    -------
    K, M : scipy.sparse.csr_matrix (n_dof, n_dof), N/m and kg
        Zero rows and columns at the rotational DOFs.
    """
    cells = np.asarray(cells, dtype=np.int64)
    n = len(cells)
    E, nu, rho = (np.broadcast_to(np.asarray(p, dtype=float), (n,)) for p in (E, nu, rho))
    chunk = chunk or max(1, CHUNK_ENTRIES // (3 * cells.shape[1]) ** 2)
    K = sp.csr_matrix((n_dof, n_dof))
    M = sp.csr_matrix((n_dof, n_dof))
    for start in range(0, n, chunk):
        part = slice(start, start + chunk)
        try:
            Ke, Me = solid_matrices(points, cells[part], kind, E[part], nu[part], rho[part])
        except ValueError as exc:  # report the element index in the whole cell block
            raise ValueError(_shift_index(str(exc), kind, start)) from None
        dofs = solid_dofs(cells[part])
        K = K + assemble([(dofs, Ke)], n_dof)
        M = M + assemble([(dofs, Me)], n_dof)
    return K.tocsr(), M.tocsr()


def _shift_index(message: str, kind: str, offset: int) -> str:
    head = f"{kind} element "
    if offset == 0 or not message.startswith(head):
        return message
    number, _, rest = message[len(head):].partition(" ")
    return f"{head}{int(number) + offset} {rest}"


for _kind in SOLID_TYPES:
    register(ElementType(_kind, "solid", assemble_solid))
