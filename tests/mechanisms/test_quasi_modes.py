"""Quasi-eigenfrequencies at frozen angles, and the processing-machine example."""

import importlib.util
from pathlib import Path

import numpy as np
from numpy.testing import assert_allclose

from femmech.mechanisms import FourBar, rheolinear, table_5_1_case
from femmech.mechanisms.quasi_modes import frozen_eigen, quasi_modes

EPS = np.finfo(float).eps
EXAMPLE = Path(__file__).parents[2] / "examples" / "mechanism_quasi_modes.py"
PARAMS = dict(J1=0.02, m2=1.5, c1=2e4, c2=3e5, b1=0.1, b2=20.0, F2=30.0)


def _case_1():
    return rheolinear(table_5_1_case(1), PARAMS, {"U": FourBar(1.0, 3.0, 2.5, 3.2)})


def _quadratic_roots(M, C):
    """Roots of det(C − λM) = 0 for 2×2 matrices (closed form, independent of LAPACK)."""
    a = M[:, 0, 0] * M[:, 1, 1] - M[:, 0, 1] * M[:, 1, 0]
    b = -(C[:, 0, 0] * M[:, 1, 1] + C[:, 1, 1] * M[:, 0, 0]
          - C[:, 0, 1] * M[:, 1, 0] - C[:, 1, 0] * M[:, 0, 1])
    c = C[:, 0, 0] * C[:, 1, 1] - C[:, 0, 1] * C[:, 1, 0]
    disc = np.sqrt((b**2 - 4 * a * c).astype(complex))
    return np.sort_complex(np.column_stack([(-b - disc) / (2 * a), (-b + disc) / (2 * a)]))


def test_symmetric_case_matches_closed_form_and_is_mass_normalised():
    model = _case_1()
    phi = np.linspace(0, 2 * np.pi, 37)
    res = quasi_modes(model, phi)  # Ω = 0: C = diag(c1 + F2 U'', c2), symmetric
    assert res.symmetric.all()
    ref = np.sqrt(_quadratic_roots(model.M(phi), model.C(phi, 0.0)).real) / (2 * np.pi)
    # bound: roots of a quadratic: cancellation in b² − 4ac, relative error ~ cond * eps; 1e-10
    assert_allclose(res.freq_hz, ref, rtol=1e-10)
    M = model.M(phi)
    gram = np.einsum("aji,ajk,akl->ail", res.modes, M, res.modes)
    assert_allclose(gram, np.broadcast_to(np.eye(2), gram.shape), atol=1e3 * EPS)


def test_unsymmetric_C_at_speed_uses_general_solver():
    model = _case_1()
    phi = np.linspace(0, 2 * np.pi, 37)
    W = 40.0
    M, C = model.M(phi), model.C(phi, W)
    res = quasi_modes(model, phi, Omega=W)
    assert not res.symmetric.any()  # C21 = m2 Ω² U''' ≠ C12 = 0 (Table 5.1)
    ref = _quadratic_roots(M, C)
    # bound: roots of a quadratic, cond·eps (comment above)
    assert_allclose(res.omega_sq, ref, rtol=1e-10)
    # the right eigenvectors satisfy C v = λ M v: a backward-stable eigensolver leaves a
    # residual ~eps (‖C‖ + |λ| ‖M‖) ‖v‖ per column (LAPACK Users' Guide, §4.8); 10 times
    # that (measured 0.96 times on SkylakeX, 0.72 on Haswell; the old bound 1e3 eps
    # max|C| left out |λ| ‖M‖ ‖v‖)
    for i in range(len(phi)):
        v, lam = res.modes[i], res.omega_sq[i].real
        resid = np.linalg.norm(C[i] @ v - M[i] @ v * lam, axis=0)
        bound = EPS * (np.linalg.norm(C[i], 2) + np.abs(lam) * np.linalg.norm(M[i], 2))
        assert np.all(resid < 10 * bound * np.linalg.norm(v, axis=0))


def test_frozen_eigen_complex_pair_gives_nan_frequency():
    # C = [[1, 2], [-2, 1]] with M = I has λ = 1 ± 2i (flutter-type frozen state)
    M = np.eye(2)[None]
    C = np.array([[[1.0, 2.0], [-2.0, 1.0]]])
    lam, modes, sym = frozen_eigen(M, C)
    assert_allclose(lam[0], [1 - 2j, 1 + 2j], rtol=10 * EPS)
    assert np.isnan(modes).all()
    assert not sym[0]


def _load_example():
    spec = importlib.util.spec_from_file_location("mechanism_quasi_modes", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_example_sweeps_360_degrees_and_writes_plot(tmp_path):
    result = _load_example().main(tmp_path)
    # bound: In the common dwell the mechanisms decouple: closed-form reference of the example's
    # docstring (two-inertia shaft and single follower oscillators); LAPACK round-off
    assert_allclose(result["dwell_hz"], result["dwell_reference_hz"], rtol=1e-12)
    # bound: LAPACK round-off of the dwell value, eps λ_max/λ of a small pencil
    assert np.all(result["freq_min_hz"] <= result["dwell_hz"] * (1 + 1e-12))
    assert np.all(result["freq_max_hz"] >= result["dwell_hz"] * (1 - 1e-12))
    # the cams change the follower and first shaft frequencies by several per cent
    assert np.max(result["freq_max_hz"] / result["freq_min_hz"]) > 1.05
    assert 0.0 < result["at_speed_max_shift"] < 0.2
    png = result["plot"]
    assert png.exists()
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert list(tmp_path.iterdir()) == [png]  # no temporary files left behind
