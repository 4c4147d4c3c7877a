"""Small models and checks shared by the hard-case tests.

Imported as a top-level module (pytest's rootdir-relative ``prepend`` import mode puts
this folder on ``sys.path``), like the helpers of ``tests/``.
"""

from __future__ import annotations

import numpy as np
import sympy

import femmech as fm
from femmech.fe import sections
from femmech.mechanisms import (
    CamProfile,
    CamSegment,
    Mechanism,
    PointMass,
    RotaryInertia,
    Spring,
    polynomial_345,
    position_function,
)

EPS = np.finfo(float).eps
STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0, name="steel")
RHS = sections.rectangular_hollow(0.06, 0.08, 0.004)
CAM = CamProfile((CamSegment(np.pi / 2, 0.02, polynomial_345()), CamSegment(np.pi / 2, 0.0),
                  CamSegment(np.pi / 2, -0.02, polynomial_345()), CamSegment(np.pi / 2, 0.0)))
"""3-4-5 rise of 20 mm over 90°, dwell, return, dwell (U' = 0 on [π/2, π] and [3π/2, 2π])."""


def line_mesh(n: int, length: float = 1.0, node_sets=None) -> fm.Mesh:
    """``n`` line elements along x from 0 to ``length`` (m), one cell set ``"all"``."""
    x = np.linspace(0.0, length, n + 1)
    return fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(n), np.arange(1, n + 1)]),
                              node_sets=node_sets)


def grid_model(bays=(2, 1, 1), size=(1.2, 0.8, 1.0), subdivisions=3, supported=True,
               section=RHS, material=STEEL) -> fm.FEModel:
    """Grid frame of one section, clamped at the base joints unless ``supported`` is False."""
    from femmech.fe.generators import grid_frame

    mesh = grid_frame(bays, size, subdivisions)
    prop = fm.BeamProperty(section, material)
    supports = [fm.Support("base")] if supported else []
    return fm.build_model(mesh, {name: prop for name in mesh.cell_sets}, supports=supports)


def cam_mechanism(with_guide: bool = True, grounded_guide: bool = False) -> Mechanism:
    """Seed Table 5.1 case 1 (shaft twist q1, follower deflection q2), with the follower
    guide displacement y_g of the frame as a further coordinate:
    ``x2 = y_g + U(θ + q1) + q2``, ``2T = J1 (θ' + q1')² + m2 x2'²``,
    ``2V = c1 q1² + c2 q2² [+ c_g y_g²]`` (``grounded_guide``: a spring c_g from the guide
    to the ground, which grounds the frame point the guide is attached to)."""
    theta, q1, yg, q2 = sympy.symbols("theta q1 y_g q2")
    J1, m2, c1, c2, cg = sympy.symbols("J1 m2 c1 c2 c_g")
    U = position_function("U")
    x2 = (yg if with_guide else 0) + U(theta + q1) + q2
    coords = (q1, yg, q2, theta) if with_guide else (q1, q2, theta)
    elements = [RotaryInertia(J1, theta + q1), PointMass(m2, (x2,)), Spring(c1, q1),
                Spring(c2, q2)]
    if grounded_guide:
        elements.append(Spring(cg, yg))
    return Mechanism(coords, tuple(elements), drives=(theta,), name="cam")


CAM_PARAMS = {"J1": 0.05, "m2": 3.0, "c1": 2e4, "c2": 5e5}
"""kg m², kg, N m/rad, N/m: mechanism-alone frequencies 100 Hz (c1/J1) and 65 Hz (c2/m2)."""


def orthonormal(U, M):
    """M-orthonormal basis (n, k) of span(U) (Cholesky of the Gram matrix)."""
    G = U.conj().T @ (M @ U)
    return U @ np.linalg.inv(np.linalg.cholesky(0.5 * (G + G.conj().T))).conj().T


def subspace_cos2(U, P, M) -> float:
    """cos² of the largest M-principal angle between span(U) and span(P) (same size):
    1 when the subspaces coincide, whatever bases they are given in."""
    s = np.linalg.svd(orthonormal(U, M).conj().T @ (M @ orthonormal(P, M)), compute_uv=False)
    return float(s.min() ** 2)


def cluster_slices(lam, rtol):
    """Slices of runs of eigenvalues (ascending) within ``rtol`` of their neighbour."""
    lam = np.asarray(lam)
    breaks = np.flatnonzero(np.diff(lam) > rtol * np.abs(lam[1:])) + 1
    edges = np.concatenate([[0], breaks, [lam.size]])
    return [slice(a, b) for a, b in zip(edges[:-1], edges[1:], strict=True)]


def rigid_field(points, centre, motion):
    """Full 6-DOF vector (6 n_nodes,) of the small rigid motion ``motion = (t, θ)``."""
    r = points - centre
    u = np.column_stack([motion[:3] + np.cross(motion[3:], r),
                         np.tile(motion[3:], (len(points), 1))])
    return u.ravel()


def rigid_fields(points) -> np.ndarray:
    """(6 n_nodes, 6): the six rigid-body motions about the centroid."""
    centre = points.mean(axis=0)
    return np.column_stack([rigid_field(points, centre, e) for e in np.eye(6)])
