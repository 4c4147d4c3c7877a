"""Hard case 6: thin shells.

Steel plates 1 m x 1 m at span/thickness 1e3 and 1e4 (t = 1 mm, 0.1 mm), with regular,
distorted (interior nodes moved by up to 30 % of the element size) and warped
(hyperbolic paraboloid, z = 0.05 (2x - 1)(2y - 1) m) quadrilateral meshes.

At a/t = 1e4 the bending eigenvalues are ~1e-13 of the largest element eigenvalues (the
rotations carry inertia ρt³/12 only) and ~1e-9 of the typical translational diagonal
ratio: a scale taken from all DOFs puts rigid-body thresholds and shifts above them.

Reference: Kirchhoff plate, simply supported on all edges,
``ω_mn = π² (m² + n²) / a² · sqrt(D / (ρ t))``, ``D = E t³ / (12 (1 - ν²))`` (Leissa,
Vibration of Plates, NASA SP-160, 1969, §4.1); Mindlin's correction is < 1e-5 here.
"""

import numpy as np
import pytest
from numpy.testing import assert_allclose
from roundoff import EPS, scaled_condition

import femmech as fm
from femmech.analysis.modes import superelement_modes
from femmech.reduction.component_modes import craig_bampton

E, NU, RHO = 210e9, 0.3, 7850.0
PLATE = fm.Material(E=E, nu=NU, rho=RHO, name="steel")


def plate_mesh(n, distort=0.0, warp=0.0, triangles=False, seed=1):
    """n x n quads (or 2 n² triangles) on the unit square; interior nodes moved by up to
    ``distort`` times the element size (fixed seed), lifted to ``z = warp (2x-1)(2y-1)``."""
    X, Y = np.meshgrid(np.linspace(0.0, 1.0, n + 1), np.linspace(0.0, 1.0, n + 1))
    x, y = X.ravel(), Y.ravel()
    inner = (x > 0) & (x < 1) & (y > 0) & (y < 1)
    rng = np.random.default_rng(seed)
    x = x + inner * distort / n * rng.uniform(-1.0, 1.0, x.size)
    y = y + inner * distort / n * rng.uniform(-1.0, 1.0, y.size)
    points = np.column_stack([x, y, warp * (2 * x - 1) * (2 * y - 1)])
    i = np.arange(x.size).reshape(n + 1, n + 1)
    quads = np.column_stack([i[:-1, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, 1:].ravel(),
                             i[1:, :-1].ravel()])
    if triangles:
        cells = np.vstack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
        return fm.Mesh(points, {"triangle": cells}, {"plate": {"triangle": np.arange(len(cells))}})
    return fm.Mesh(points, {"quad": quads}, {"plate": {"quad": np.arange(len(quads))}})


def simply_supported(mesh, t):
    """Edges held in translation (rotations free): simply supported, membrane and bending
    in one stiffness matrix (nothing removed by hand)."""
    x, y = mesh.points[:, 0], mesh.points[:, 1]
    edge = np.flatnonzero(np.isclose(x, 0) | np.isclose(x, 1) | np.isclose(y, 0)
                          | np.isclose(y, 1))
    return fm.build_model(mesh, shells={"plate": fm.ShellProperty(t, PLATE)},
                          supports=[fm.Support(edge, "translations")])


def kirchhoff_hz(t, mn=((1, 1), (1, 2), (2, 1), (2, 2))):
    D = E * t**3 / (12 * (1 - NU**2))
    return np.array([np.pi * (m * m + n * n) * np.sqrt(D / (RHO * t)) / 2 for m, n in mn])


# Measured relative errors of the 4 lowest frequencies (the same at a/t = 1e3 and 1e4):
# 8 x 8 regular 1.7/6.6/6.6/7.3 %, distorted 2.3/7.3/8.7/9.9 %; 12 x 12 regular
# 0.8/2.8/2.8/3.1 %, distorted 1.1/3.4/3.8/4.3 % (MITC4: O(h²), tests/test_shell_verification).
ERROR_BOUND = {8: 0.11, 12: 0.05}


@pytest.mark.parametrize("distort", [0.0, 0.3], ids=["regular", "distorted"])
@pytest.mark.parametrize("n", [8, 12], ids=["dense", "sparse"])
def test_thin_plate_neither_locks_nor_loses_modes(n, distort):
    """Naive: displacement-based shear (locking) makes the a/t = 1e4 plate orders of
    magnitude too stiff; a shift from the median diagonal ratio (1.2e14 rad²/s², set by
    the rotations) lies 1e13 below the lowest bending eigenvalue, so that shift-invert
    Lanczos cannot separate the modes (before this issue: 'Sturm check: eigenvalues
    still missing after 10 deflated restarts') and the rigid threshold 1e-12 x scale
    declared the three lowest bending modes rigid (reported as 0 Hz). femmech: MITC4
    (no locking: the errors at 1e4 equal those at 1e3), the scale from the smallest
    per-component median (femmech.analysis.modes.model_eigenvalue_scale), and a band
    search confirms by Sturm count that no spurious mode lies among them."""
    errors = []
    for t in (1e-3, 1e-4):
        model = simply_supported(plate_mesh(n, distort), t)
        ref = kirchhoff_hz(t)
        result = fm.modes(model, n_modes=4)
        # 12 x 12: ARPACK, or block Lanczos where ARPACK did not converge within its
        # iteration limit (which depends on round-off of the starting vector's Krylov space)
        assert result.method in (("dense",) if n == 8 else ("arpack", "block-lanczos"))
        assert not result.rigid.any()
        err = result.freq_hz / ref - 1
        assert np.all(err > 0)
        assert err.max() < ERROR_BOUND[n]
        errors.append(err)
        # modes (1,1), (1,2), (2,1), (2,2) below 1.18 f22 and (1,3) at 1.25 f22: exactly
        # four, whatever the mesh (no zero-energy or drilling mode among them)
        band = fm.modes(model, band_hz=(0.0, 1.18 * ref[3]))
        assert band.n_modes == 4
        # another shift (band centre), other round-off: ~eps cond₂ of the diagonally scaled
        # pencil (roundoff.scaled_condition: 1.3e-7 in λ at a/t = 1e4, see
        # test_reduced_thin_shells); measured up to 6e-8 at 1e4
        assert_allclose(band.freq_hz, result.freq_hz, rtol=1e-6)
    # no locking: a/t = 1e4 and 1e3 have the same discretisation error (differences
    # measured 2.5e-5: Mindlin's shear term; a locking element would be ~(a/t)² = 100
    # times stiffer at 1e4)
    assert_allclose(errors[1], errors[0], atol=1e-4)


@pytest.mark.parametrize("t", [1e-3, 1e-4])
def test_warped_free_shell_keeps_six_rigid_modes(t):
    """A free hyperbolic-paraboloid shell of warped quads (each quad's nodes lie off its
    mean plane). Naive: building a warped quad on its projection without the rigid
    offsets gives rigid rotations strain energy (fewer than six zero modes), and at
    a/t = 1e4 a rigid threshold from all DOFs calls elastic modes rigid. femmech: exactly
    six, and the elastic frequencies agree with a mesh of flat triangles of the same
    surface (no warping) and converge under refinement."""
    quads = fm.modes(fm.build_model(plate_mesh(12, warp=0.05),
                                    shells={"plate": fm.ShellProperty(t, PLATE)}), n_modes=10)
    fine = fm.modes(fm.build_model(plate_mesh(24, warp=0.05),
                                   shells={"plate": fm.ShellProperty(t, PLATE)}), n_modes=10)
    tri = fm.modes(fm.build_model(plate_mesh(24, warp=0.05, triangles=True),
                                  shells={"plate": fm.ShellProperty(t, PLATE)}), n_modes=10)
    for result in (quads, fine, tri):
        assert result.rigid.tolist() == [True] * 6 + [False] * 4
    # measured against the 24 x 24 quads: 12 x 12 quads 0.6-3.0 % (O(h²) discretisation),
    # 24 x 24 flat triangles 0.03-0.35 %
    assert_allclose(quads.freq_hz[6:], fine.freq_hz[6:], rtol=0.04)
    assert_allclose(tri.freq_hz[6:], fine.freq_hz[6:], rtol=0.01)


def test_reduced_thin_shells():
    """Craig-Bampton of thin shells, with rotational interface DOFs (inertia ρt³/12):
    the simply supported distorted plate reduced onto its centre node, and the free warped
    shell reduced onto two corners, which must keep six rigid-body modes. Naive (before
    this issue): superelement_modes took its rigid threshold from the largest diagonal
    ratio of the reduced pencil, only a lower bound of λ_max (3000 times below it here),
    and reported one (a/t = 1e3) or five (1e4) of the six rigid modes as elastic."""
    for t in (1e-3, 1e-4):
        model = simply_supported(plate_mesh(12, 0.3), t)
        full = fm.modes(model, n_modes=8)
        centre = int(np.argmin(np.linalg.norm(model.mesh.points[:, :2] - 0.5, axis=1)))
        reduced = superelement_modes(craig_bampton(model, [centre], n_modes=10), n_modes=8)
        assert not reduced.rigid.any()
        err = reduced.freq_hz / full.freq_hz - 1
        # Rayleigh-Ritz: upper bounds up to the round-off of the two solves, ~eps cond₂ of
        # the diagonally scaled K + λ_1 M (roundoff.scaled_condition): 1.3e-9 at a/t = 1e3,
        # 1.3e-7 at 1e4 (eps λ_max/λ_1 would be 0.3). Measured -4e-10 (SkylakeX) and -4e-9
        # (Haswell kernel) at 1e4, against the old bound -1e-8
        K, M = model.K_free, model.M_free
        assert err.min() > -EPS * scaled_condition(K + full.omega2[0] * M)
        assert err.max() < 1e-3
        free = fm.build_model(plate_mesh(12, warp=0.05),
                              shells={"plate": fm.ShellProperty(t, PLATE)})
        full = fm.modes(free, n_modes=10)
        reduced = superelement_modes(craig_bampton(free, [0, 12], n_modes=12), n_modes=10,
                                     model=free)
        assert reduced.rigid.tolist() == [True] * 6 + [False] * 4
        err = reduced.freq_hz[6:] / full.freq_hz[6:] - 1
        # as above, with the first elastic eigenvalue (8.3e-9 at 1e3, 8.3e-7 at 1e4;
        # measured +1.5e-8 .. +1.7e-8 at 1e4: truncation, positive, moved 2e-9 by the kernel)
        K, M = free.K_free, free.M_free
        assert err.min() > -EPS * scaled_condition(K + full.omega2[6] * M)
        assert err.max() < 1e-3
