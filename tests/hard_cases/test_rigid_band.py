"""Hard case: frequency bands from 0 Hz hold every rigid-body mode.

The computed ω² of a rigid-body mode is round-off of either sign (~1e-17 of the
eigenvalue scale). Naive band selection ``ω² >= 0`` kept the modes rounded up and dropped
the others: ``band_hz=(0, f)`` returned 4 of the 6 rigid-body modes of a free grid frame
on the dense path (3 in the issue's probe), and the sparse band search counted at the
band's lower edge by factorising the singular K itself (then found 5 of a Sturm count of
7, or "12 of 10"). Now a band from 0 (or from below the rigid threshold) returns all
modes up to its upper edge, on the sparse path by the lowest-modes search with a shift
below zero. References: the number of rigid-body modes from the supports (6 for a free
body, 3 about a pinned point, 1 about a hinge axis) and dense ``scipy.linalg.eigh`` on the
small pencils for the elastic ones.
"""

import numpy as np
import pytest
import scipy.linalg as sla
from hard_models import RHS, STEEL, grid_model, rigid_fields, subspace_cos2
from numpy.testing import assert_allclose

import femmech as fm
from femmech.analysis.modes import model_eigenvalue_scale, superelement_modes
from femmech.fe.generators import grid_frame
from femmech.reduction.component_modes import craig_bampton
from femmech.solve.eigen import RIGID_TOL, solve_symmetric


def plate_model():
    """Free steel plate 1 m x 0.6 m x 5 mm of 8 x 5 quads (324 DOFs)."""
    x, y = np.meshgrid(np.linspace(0, 1.0, 9), np.linspace(0, 0.6, 6), indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel(), 0 * x.ravel()])
    i = np.arange(points.shape[0]).reshape(x.shape)
    quads = np.column_stack([i[:-1, :-1].ravel(), i[1:, :-1].ravel(), i[1:, 1:].ravel(),
                             i[:-1, 1:].ravel()])
    mesh = fm.Mesh(points, {"quad": quads}, {"plate": {"quad": np.arange(len(quads))}})
    return fm.build_model(mesh, shells={"plate": fm.ShellProperty(0.005, STEEL)})


def block_model():
    """Free steel block 0.4 x 0.1 x 0.1 m of 12 x 3 x 3 hexahedra (624 free DOFs)."""
    shape = (13, 4, 4)
    axes = [np.linspace(0, s, n) for s, n in zip((0.4, 0.1, 0.1), shape, strict=True)]
    points = np.column_stack([a.ravel() for a in np.meshgrid(*axes, indexing="ij")])
    i = np.arange(points.shape[0]).reshape(shape)
    c = i[:-1, :-1, :-1], i[1:, :-1, :-1], i[1:, 1:, :-1], i[:-1, 1:, :-1]
    top = [j[:, :, 1:] for j in (i[:-1, :-1], i[1:, :-1], i[1:, 1:], i[:-1, 1:])]
    hexes = np.column_stack([j.ravel() for j in (*c, *top)])
    mesh = fm.Mesh(points, {"hexahedron": hexes}, {"block": {"hexahedron": np.arange(len(hexes))}})
    return fm.build_model(mesh, solids={"block": fm.SolidProperty(STEEL)})


def frame_on(support: str):
    """Grid frame (312 DOFs less 3 or 6 supported) with the translations of one base joint
    fixed (pinned: 3 rigid rotations about it) or of two (hinged: 1 rigid rotation about
    their axis)."""
    mesh = grid_frame((2, 1, 1), (1.2, 0.8, 1.0), 3)
    base = mesh.node_sets["base"]
    nodes = base[:1] if support == "pinned" else base[:2]
    prop = fm.BeamProperty(RHS, STEEL)
    return fm.build_model(mesh, {n: prop for n in mesh.cell_sets},
                          supports=[fm.Support(nodes.tolist(), "translations")])


MODELS = {"free frame": (lambda: grid_model(subdivisions=3, supported=False), 6),
          "free plate": (plate_model, 6), "free block": (block_model, 6),
          "pinned frame": (lambda: frame_on("pinned"), 3),
          "hinged frame": (lambda: frame_on("hinged"), 1)}


@pytest.fixture(scope="module", params=list(MODELS))
def case(request):
    """(name, model, number of rigid-body modes, dense reference eigenvalues)."""
    build, n_rigid = MODELS[request.param]
    model = build()
    # shift-inverted, M x = μ (K - σM) x with σ < 0 (λ = σ + 1/μ): relative accuracy
    # ~eps for the lowest modes, where eigh(K, M) has ~eps λ_max / λ (3e-8 on the plate)
    K, M = model.K_free.toarray(), model.M_free.toarray()
    sigma = -1e-6 * model_eigenvalue_scale(model)
    mu = sla.eigh(M, K - sigma * M, eigvals_only=True)
    return request.param, model, n_rigid, np.sort(sigma + 1.0 / mu[mu > 0])


def band_solve(model, band_hz, path):
    """Modes in ``band_hz`` on the dense or the sparse path (forced by dense_below)."""
    scale = model_eigenvalue_scale(model)
    band = tuple((2 * np.pi * f) ** 2 for f in band_hz)
    result = solve_symmetric(model.K_free, model.M_free, band=band, scale=scale,
                             dense_below=10**9 if path == "dense" else 0)
    return result, np.abs(result.omega2) <= RIGID_TOL * scale


@pytest.mark.parametrize("path", ["dense", "sparse"])
@pytest.mark.parametrize("low", ["zero", "below threshold", "above threshold"])
def test_band_from_zero_returns_every_rigid_mode(case, path, low):
    """Bands (low, f) with f between the 3rd and 4th elastic mode: low = 0 and low below
    the rigid threshold (1e-9 Hz) hold all rigid-body modes; low = 1 Hz (above the
    threshold, below the first elastic mode) holds none of them. The elastic modes are
    those of the dense reference in the band."""
    name, model, n_rigid, lam = case
    elastic = lam[n_rigid:]
    f_hi = np.sqrt(0.5 * (elastic[2] + elastic[3])) / (2 * np.pi)
    f_lo = {"zero": 0.0, "below threshold": 1e-9, "above threshold": 1.0}[low]
    assert f_lo < np.sqrt(elastic[0]) / (2 * np.pi)
    result, rigid = band_solve(model, (f_lo, f_hi), path)
    expect_rigid = 0 if low == "above threshold" else n_rigid
    assert result.method in (("dense",) if path == "dense" else ("arpack", "block-lanczos"))
    assert rigid.tolist() == [True] * expect_rigid + [False] * 3, name
    if path == "sparse" and low != "above threshold":
        assert result.sigma < 0  # K - σM positive definite: K itself never factorised
    # bound: elastic eigenvalues: both shift-inverted, eigenvalue errors ~ eps cond and, on the
    # sparse path, the square of the Lanczos tolerance 1e-12: measured up to 7e-12
    # (plate, sparse), 3e-13 elsewhere
    assert_allclose(result.omega2[expect_rigid:], elastic[:3], rtol=1e-10)
    if expect_rigid == 6:  # the zero modes span the six rigid-body motions
        X = result.vectors[:, :6]
        R = rigid_fields(model.mesh.points)[model.free]
        # bound: rigid subspace well separated (gap = λ_7): Davis-Kahan eps λ_max/λ_7 (measured
        # 2e-15)
        assert subspace_cos2(X, R, model.M_free) > 1 - 1e-12  # measured 1 - 2e-15


@pytest.mark.parametrize(("subdivisions", "method"), [(3, "dense"), (8, "arpack")])
def test_modes_band_from_zero_on_free_frame(subdivisions, method):
    """``fm.modes(band_hz=(0, f))`` on a free frame: the six rigid-body modes (flagged,
    0 Hz) and the elastic ones up to f, as ``n_modes`` gives them. 312 DOFs take the
    dense path, 912 DOFs the sparse one (DENSE_BELOW = 400)."""
    model = grid_model(subdivisions=subdivisions, supported=False)
    lowest = fm.modes(model, n_modes=12)
    f_hi = 0.5 * (lowest.freq_hz[8] + lowest.freq_hz[9])  # between the 3rd and 4th elastic
    result = fm.modes(model, band_hz=(0.0, f_hi))
    assert result.method == method
    assert result.rigid.tolist() == [True] * 6 + [False] * 3
    assert_allclose(result.freq_hz[:6], 0.0, atol=0)
    # bound: the same eigenproblem solved twice: round-off of the two solves (measured 1e-13)
    assert_allclose(result.omega2[6:], lowest.omega2[6:9], rtol=1e-9)
    if method == "arpack":
        assert result.sigma < 0


def test_superelement_band_from_zero_on_free_frame():
    """The reduced model of the free frame (Craig-Bampton, base joints as interface):
    its rigid-body eigenvalues lie at round-off of λ_max of either sign (measured
    -1.5e-8 ... 9e-9 rad²/s²) and a band from 0 holds all six of them."""
    model = grid_model(subdivisions=3, supported=False)
    se = craig_bampton(model, "base", n_modes=10)
    lowest = superelement_modes(se, n_modes=10)
    f_hi = 0.5 * (lowest.freq_hz[8] + lowest.freq_hz[9])
    result = superelement_modes(se, band_hz=(0.0, f_hi))
    assert result.rigid.tolist() == [True] * 6 + [False] * 3
    # bound: the same dense reduced eigenproblem solved twice: identical up to round-off
    assert_allclose(result.omega2[6:], lowest.omega2[6:9], rtol=1e-12)
