"""Test models shared by several test files: one place, so that no test file imports
from another.

Plates (the exact Mindlin frequency parameters of the simply supported square plate and
the Kirchhoff Rayleigh-Ritz solution, with their sources), structured plate and solid
meshes, the Table 5.1 case 1 cam on a simply supported beam, Nastran deck writers, a
field-by-field superelement comparison and the crane braking numbers of the former
example. ``tests/`` is on ``sys.path`` (see ``conftest.py``), so test files in
sub-folders import it as ``models`` too. Scene texts live in ``scene_texts.py``, the
hard cases' models in ``hard_cases/hard_models.py``.
"""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import scipy.linalg as sl
import scipy.sparse as sp
import sympy
from numpy.polynomial import legendre, polynomial
from numpy.testing import assert_array_equal

import femmech as fm
from femmech.coupling import Attachment, Mount, couple
from femmech.fe import sections
from femmech.fe.elements.solid import REFERENCE_NODES
from femmech.fe.generators import rectangular_plate
from femmech.mechanisms import (
    CamProfile,
    CamSegment,
    Damper,
    Mechanism,
    PointMass,
    RotaryInertia,
    Spring,
    polynomial_345,
    position_function,
    rheolinear,
)
from femmech.reduction.component_modes import craig_bampton
from femmech.reduction.superelement import Superelement

# --- Square plates: the exact Mindlin and Kirchhoff references ---------------------------

E, NU, RHO = 200e9, 0.3, 8000.0
STEEL = fm.Material(E=E, nu=NU, rho=RHO)


def plate_mesh(n, a=1.0, b=None, tri=False, ny=None):
    """Rectangle [0, a] x [0, b] of n x ny quads (or 2 n ny triangles), group "plate"."""
    b = a if b is None else b
    ny = n if ny is None else ny
    X, Y = np.meshgrid(np.linspace(0, a, n + 1), np.linspace(0, b, ny + 1))
    points = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    i = np.arange(X.size).reshape(ny + 1, n + 1)
    quads = np.column_stack([i[:-1, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, 1:].ravel(),
                             i[1:, :-1].ravel()])
    if tri:  # alternate the diagonal so that the mesh has no preferred direction
        flip = ((np.arange(ny)[:, None] + np.arange(n)) % 2).ravel().astype(bool)
        t1 = np.where(flip[:, None], quads[:, [0, 1, 3]], quads[:, [0, 1, 2]])
        t2 = np.where(flip[:, None], quads[:, [1, 2, 3]], quads[:, [0, 2, 3]])
        cells = np.vstack([t1, t2])
        return fm.Mesh(points, {"triangle": cells}, {"plate": {"triangle": np.arange(len(cells))}})
    return fm.Mesh(points, {"quad": quads}, {"plate": {"quad": np.arange(len(quads))}})


def mindlin_ssss(m, n, t, a=1.0, k=5.0 / 6.0):
    """Exact Mindlin frequency parameter of mode (m, n) of a simply supported square plate.

    Mindlin, "Influence of rotatory inertia and shear on flexural motions of isotropic,
    elastic plates", J. Appl. Mech. 18 (1951) 31-38: with ``w = W sin αx sin βy``,
    ``ψx = X cos αx sin βy``, ``ψy = Y sin αx cos βy`` (α = mπ/a, β = nπ/a, k² = α² + β²)
    the plate equations ``kGt (∇²w + ∇·ψ) = ρt ẅ`` and
    ``D/2 [(1 - ν) ∇²ψ + (1 + ν) ∇(∇·ψ)] - kGt (ψ + ∇w) = ρt³/12 ψ̈`` become the 3 x 3
    symmetric eigenproblem below; its lowest root is the flexural frequency.
    """
    G = E / (2 * (1 + NU))
    D = E * t**3 / (12 * (1 - NU**2))
    al, be = m * np.pi / a, n * np.pi / a
    k2, s = al**2 + be**2, k * G * t
    K = np.array([[s * k2, s * al, s * be],
                  [s * al, D / 2 * ((1 - NU) * k2 + (1 + NU) * al**2) + s,
                   D / 2 * (1 + NU) * al * be],
                  [s * be, D / 2 * (1 + NU) * al * be,
                   D / 2 * ((1 - NU) * k2 + (1 + NU) * be**2) + s]])
    M = np.diag([RHO * t, RHO * t**3 / 12, RHO * t**3 / 12])
    w2 = sl.eigh(K, M, eigvals_only=True)[0]
    return np.sqrt(w2) * a**2 * np.sqrt(RHO * t / D)


def ritz_kirchhoff(n, clamped, nu=NU):
    """Kirchhoff square-plate frequency parameters by Rayleigh-Ritz (independent solver).

    Basis ``φ_i(ξ) φ_j(η)`` on [-1, 1]², Legendre polynomials ``P_0..P_{n-1}`` (free
    edges: natural conditions) or ``(1 - ξ²)² P_i`` (clamped); energy
    ``D/2 ∫ w_xx² + w_yy² + 2ν w_xx w_yy + 2(1 - ν) w_xy²`` (Leissa 1969, eq. 1.5).
    Upper bounds converging to 7 digits at n = 12 (checked against n = 16).
    """
    xq, wq = legendre.leggauss(2 * n + 12)
    rows = []
    for i in range(n):
        c = legendre.leg2poly(np.eye(n)[i])
        if clamped:
            c = polynomial.polymul(c, [1, 0, -2, 0, 1])
        rows.append([polynomial.polyval(xq, polynomial.polyder(c, d)) for d in range(3)])
    F = np.array(rows)

    def gram(p, q):
        return np.einsum("iq,jq,q->ij", F[:, p], F[:, q], wq)

    A0, A1, A2, B02 = gram(0, 0), gram(1, 1), gram(2, 2), gram(0, 2)
    K = (np.kron(A2, A0) + np.kron(A0, A2) + nu * (np.kron(B02.T, B02) + np.kron(B02, B02.T))
         + 2 * (1 - nu) * np.kron(A1, A1))
    lam = sl.eigh(K, np.kron(A0, A0), eigvals_only=True)
    return 4 * np.sqrt(np.abs(lam))  # d/dx = (2/a) d/dξ: λ = 4 sqrt(eigenvalue)


def slope(h, err):
    return np.polyfit(np.log(h), np.log(err), 1)[0]


def ssss_plate(n, t, distort=0.0, kind="quad9", modes=4):
    """Frequency parameters of the hard simply supported unit square plate, n x n mesh.

    ``distort`` moves the interior element corners randomly by up to that fraction of
    the element size (edge and centre nodes follow the straight-sided map).
    """
    mesh = rectangular_plate(1.0, 1.0, n, n, kind="quad9")
    if distort:
        mesh = distorted_plate(mesh, n, distort)
    if kind == "quad8":
        mesh = to_quad8(mesh)
    x, y = mesh.points[:, 0], mesh.points[:, 1]
    edge_x = np.flatnonzero(np.isclose(x, 0) | np.isclose(x, 1))
    edge_y = np.flatnonzero(np.isclose(y, 0) | np.isclose(y, 1))
    supports = [fm.Support(np.arange(mesh.n_nodes), ["ux", "uy", "rz"]),
                fm.Support(edge_x, ["uz", "rx"]), fm.Support(edge_y, ["uz", "ry"])]
    model = fm.build_model(mesh, shells={"plate": fm.ShellProperty(t, STEEL)},
                           supports=supports)
    res = fm.modes(model, n_modes=modes)
    D = E * t**3 / (12 * (1 - NU**2))
    return (2 * np.pi * res.freq_hz * np.sqrt(RHO * t / D))[:modes]


def distorted_plate(mesh, n, amount, seed=1):
    """Move interior corner nodes; place edge and centre nodes on the straight-sided map."""
    m = 2 * n + 1
    P = mesh.points[:, :2].reshape(m, m, 2).copy()
    rng = np.random.default_rng(seed)
    shift = rng.uniform(-1, 1, (n - 1, n - 1, 2)) * amount / n
    P[2:-1:2, 2:-1:2] += shift
    P[1::2, ::2] = 0.5 * (P[:-1:2, ::2] + P[2::2, ::2])  # edge nodes between corners
    P[::2, 1::2] = 0.5 * (P[::2, :-1:2] + P[::2, 2::2])
    P[1::2, 1::2] = 0.25 * (P[:-1:2, :-1:2] + P[2::2, :-1:2] + P[:-1:2, 2::2] + P[2::2, 2::2])
    points = np.column_stack([P.reshape(-1, 2), np.zeros(m * m)])
    return fm.Mesh(points, mesh.cells, mesh.cell_sets, mesh.node_sets)


def to_quad8(mesh):
    """The quad9 mesh without its centre nodes (quad8 cells, nodes renumbered)."""
    cells = mesh.cells["quad9"]
    keep = np.setdiff1d(np.arange(mesh.n_nodes), cells[:, 8])
    new = np.full(mesh.n_nodes, -1)
    new[keep] = np.arange(len(keep))
    node_sets = {k: new[v][new[v] >= 0] for k, v in mesh.node_sets.items()}
    return fm.Mesh(mesh.points[keep], {"quad8": new[cells[:, :8]]},
                   {"plate": {"quad8": np.arange(len(cells))}}, node_sets)



def ss_reference(t, modes=4):
    pairs = [(1, 1), (1, 2), (2, 1), (2, 2), (1, 3), (3, 1), (2, 3), (3, 2), (1, 4), (4, 1)]
    return np.array([mindlin_ssss(m, k, t) for m, k in pairs[:modes]])


# --- Meshes on the unit square and tensor grids of solids --------------------------------

def plate_cells(n, kind):
    """Points and cells of n x n elements of ``kind`` on the unit square (quadratic kinds
    on the (2n + 1)² grid of their nodes)."""
    p = 2 if kind in ("quad9", "triangle6") else 1
    X, Y = np.meshgrid(np.linspace(0, 1, p * n + 1), np.linspace(0, 1, p * n + 1))
    points = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    i = np.arange(X.size).reshape(p * n + 1, p * n + 1)
    if p == 1:
        quads = np.column_stack([i[:-1, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, 1:].ravel(),
                                 i[1:, :-1].ravel()])
        if kind == "quad":
            return points, quads
        flip = ((np.arange(n)[:, None] + np.arange(n)) % 2).ravel().astype(bool)
        t1 = np.where(flip[:, None], quads[:, [0, 1, 3]], quads[:, [0, 1, 2]])
        t2 = np.where(flip[:, None], quads[:, [1, 2, 3]], quads[:, [0, 2, 3]])
        return points, np.vstack([t1, t2])
    b = i[:-1:2, :-1:2].ravel()  # lower-left corner of each 2 x 2 block of nodes
    w = p * n + 1
    q9 = np.column_stack([b, b + 2, b + 2 + 2 * w, b + 2 * w, b + 1, b + 2 + w, b + 1 + 2 * w,
                          b + w, b + 1 + w])
    if kind == "quad9":
        return points, q9
    # two triangle6 per block, split along the diagonal 0-2 of the block
    return points, np.vstack([q9[:, [0, 1, 2, 4, 5, 8]], q9[:, [0, 2, 3, 8, 6, 7]]])


TET_EDGES = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)]


def kuhn_tets():
    """The six tetrahedra of the unit cube around its diagonal (Kuhn), positive volume."""
    tets = []
    for perm in itertools.permutations(range(3)):
        v = [np.zeros(3)]
        for axis in perm:
            v.append(v[-1] + np.eye(3)[axis])
        v = np.array(v)
        if np.linalg.det(v[1:] - v[0]) < 0:
            v[[1, 2]] = v[[2, 1]]
        tets.append(v)
    return tets


def grid_solid(kind, xs, ys, zs, keep=None, group="solid"):
    """Solid mesh of the boxes of the tensor grid ``xs x ys x zs`` (box boundaries, m).

    ``keep`` (bool, one entry per box) selects boxes; a box is one hexahedron or six
    tetrahedra. Quadratic nodes sit on the grid refined by midpoints.
    """
    xs, ys, zs = (np.asarray(c, dtype=float) for c in (xs, ys, zs))
    shape = (len(xs) - 1, len(ys) - 1, len(zs) - 1)
    keep = np.ones(shape, dtype=bool) if keep is None else np.asarray(keep)
    if kind.startswith("hexahedron"):
        local = [REFERENCE_NODES[kind]]
    else:
        local = kuhn_tets()
        if kind == "tetra10":
            local = [np.vstack([t, [(t[a] + t[b]) / 2 for a, b in TET_EDGES]]) for t in local]
    fine = [np.sort(np.concatenate([c, (c[1:] + c[:-1]) / 2])) for c in (xs, ys, zs)]
    dims = [len(f) for f in fine]
    boxes = np.argwhere(keep)
    cells = np.concatenate([
        np.ravel_multi_index(np.moveaxis((2 * (boxes[:, None, :] + ref)).round().astype(int),
                                         2, 0), dims) for ref in local])
    used, cells = np.unique(cells, return_inverse=True)
    cells = cells.reshape(-1, len(local[0]))
    idx = np.unravel_index(used, dims)
    points = np.column_stack([fine[a][idx[a]] for a in range(3)])
    return fm.Mesh(points, {kind: cells}, {group: {kind: np.arange(len(cells))}})


# --- cantilever bar, L = 1 m, square 0.05 m (L/h = 20) ---------------------------------
L, H = 1.0, 0.05


# --- Table 5.1 case 1 cam on a simply supported beam, the 2-DOF Hill system ---------------

# Table 5.1 case 1 of the seed chapter
PARAMS = {"J1": 0.05, "m2": 3.0, "c1": 2e4, "c2": 5e5}
CAM = CamProfile((CamSegment(np.pi / 2, 0.02, polynomial_345()), CamSegment(np.pi / 2, 0.0),
                  CamSegment(np.pi / 2, -0.02, polynomial_345()), CamSegment(np.pi / 2, 0.0)))



def cam_mechanism(with_guide: bool):
    """Table 5.1 case 1 (shaft twist q1, follower deflection q2), optionally with the
    follower guide displacement y_g of the frame as a further coordinate:
    x2 = y_g + U(θ + q1) + q2, 2T = J1 (θ' + q1')² + m2 x2'², 2V = c1 q1² + c2 q2²."""
    theta, q1, yg, q2 = sympy.symbols("theta q1 y_g q2")
    J1, m2, c1, c2 = sympy.symbols("J1 m2 c1 c2")
    U = position_function("U")
    x2 = (yg if with_guide else 0) + U(theta + q1) + q2
    coords = (q1, yg, q2, theta) if with_guide else (q1, q2, theta)
    return Mechanism(coords, (RotaryInertia(J1, theta + q1), PointMass(m2, (x2,)),
                              Spring(c1, q1), Spring(c2, q2)), drives=(theta,))


def simply_supported_beam(n=40, E=210e9):
    """Simply supported 1 m beam along x (uy bending carries the cam guide at mid-span)."""
    x = np.linspace(0.0, 1.0, n + 1)
    mesh = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(n), np.arange(1, n + 1)]),
                              node_sets={"ends": [0, n], "mid": [n // 2]})
    material = fm.Material(E=E, nu=0.3, rho=7850.0)
    prop = fm.BeamProperty(sections.rectangular_hollow(0.06, 0.08, 0.004), material)
    return fm.build_model(mesh, {"all": prop}, supports=[
        fm.Support("ends", "translations"), fm.Support(0, ["rx"])])


def cam_with_dampers_on_beam():
    """Table 5.1 case 1 cam on the simply supported beam (``simply_supported_beam``), with
    dampers on the shaft twist and follower (2 N m s/rad, 80 N s/m); the frame undamped."""
    theta, q1, yg, q2 = sympy.symbols("theta q1 y_g q2")
    J1, m2, c1, c2, d1, d2 = sympy.symbols("J1 m2 c1 c2 d1 d2")
    x2 = yg + position_function("U")(theta + q1) + q2
    mech = Mechanism((q1, yg, q2, theta),
                     (RotaryInertia(J1, theta + q1), PointMass(m2, (x2,)), Spring(c1, q1),
                      Spring(c2, q2), Damper(d1, q1), Damper(d2, q2)), drives=(theta,))
    model = rheolinear(mech, {**PARAMS, "d1": 2.0, "d2": 80.0}, {"U": CAM})
    return couple(craig_bampton(simply_supported_beam(), "mid", n_modes=6),
                  [Mount(model, (Attachment("y_g", 20, "uy"),), name="cam")])


def damped_cam_on_beam():
    """:func:`cam_with_dampers_on_beam` with Rayleigh damping of the frame
    (B₀ += 1.0 M₀ + 1e-5 K₀); the ``damped_cam_system`` fixture of ``conftest.py``."""
    system = cam_with_dampers_on_beam()
    return dataclasses.replace(system, B0=system.B0 + 1.0 * system.M0 + 1e-5 * system.K0)


def hill_2dof():
    """Two coupled DOF with periodic mass, damping and stiffness (period 2π/3)."""
    w = 3.0

    def M(t):
        m = np.zeros((t.size, 2, 2))
        m[:, 0, 0] = 1.0 + 0.3 * np.cos(w * t)
        m[:, 1, 1] = 2.0
        m[:, 0, 1] = m[:, 1, 0] = 0.2 * np.sin(w * t)
        return m

    def C(t):
        c = np.zeros((t.size, 2, 2))
        c[:, 0, 0] = 20.0 + 8.0 * np.cos(w * t)
        c[:, 1, 1] = 35.0
        c[:, 0, 1], c[:, 1, 0] = -5.0, -5.0 + 2.0 * np.sin(2 * w * t)
        return c

    B = np.array([[0.2, 0.5], [-0.5, 0.1]])  # damping plus a gyroscopic part
    return M, B, C, 2 * np.pi / w


# --- Nastran decks -------------------------------------------------------------------------

def nastran_field(value) -> str:
    return f"{value!s:<8}"


def grid_card(gid, x, cd="", ps="") -> str:
    """A small-field GRID: ID, CP, X1-X3, CD, PS (fields 2-8)."""
    return "GRID    " + "".join(nastran_field(v) for v in (gid, "", x, 0.0, 0.0, cd, ps)) + "\n"


def cbar_card(eid, a, b, pid=1) -> str:
    return "CBAR    " + "".join(nastran_field(v) for v in (eid, pid, a, b, "0.", "1.", "0.")) + "\n"


def deck(tmp_path, extra="", grids=None, bars=None, name="frame.bdf"):
    """A cantilever of 4 CBARs along x (GRIDs 1-5, 0.5 m apart), plus ``extra`` cards."""
    grids = grids if grids is not None else "".join(grid_card(i + 1, 0.5 * i) for i in range(5))
    bars = bars if bars is not None else "".join(cbar_card(i + 1, i + 1, i + 2)
                                                 for i in range(4))
    path = tmp_path / name
    path.write_text("SOL 103\nCEND\nBEGIN BULK\n" + grids + bars + extra + "ENDDATA\n")
    return path


# --- Superelements -------------------------------------------------------------------------

def assert_same_superelement(a, b):
    for f in dataclasses.fields(Superelement):
        if f.name in ("interior_factor", "inertia_response"):  # run-time caches, not saved
            continue
        x, y = getattr(a, f.name), getattr(b, f.name)
        if sp.issparse(x):
            assert x.shape == y.shape
            assert (x != y).nnz == 0
        elif isinstance(x, np.ndarray):
            assert x.dtype == y.dtype, f.name
            assert_array_equal(x, y)
        else:
            assert x == y, f.name


# --- Crane trip and braking: the example's former implementation ----------------------------

# Measured with the example's own implementation (commit 645c8b2, same model and settings):
OLD_T_TRIP = 13.793197428431492  # s
OLD_PEAK = {0.2: 390602.53763092135, 0.5: 390388.4588700416, 1.0: 382467.5094894752}  # N
