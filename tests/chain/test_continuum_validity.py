"""The continuum's coordinate independence (impedance smearing), its error estimate and
its validity warning, with a follower ground spring c_g."""

import warnings

import numpy as np
import pytest
import scipy.linalg as sla

from femmech.chain import End, chain, follower_unit
from femmech.chain.continuum import continuum_modes, validity_problems
from femmech.chain.transfer import transfer_modes
from femmech.errors import ModelWarning
from femmech.mechanisms import cam_program

CAM = cam_program(0.03, rise=120, dwell_top=60, return_=120, dwell_bottom=60,
                  law="modified_sine")


class Absolute:
    """The follower unit in absolute follower coordinates: x = (q1, y), y = U' q1 + q2
    (linearised absolute follower displacement), q = T⁻¹ x with T = [[1, 0], [U', 1]]:
    M_x = T⁻ᵀ M T⁻¹, C_x = T⁻ᵀ C T⁻¹ (frozen, Ω = 0). Same physics, other coordinates."""

    def __init__(self, unit):
        self.unit, self.n = unit, 2

    def _Tinv(self, phi):
        U1 = CAM.derivatives(phi)[1]
        T = np.zeros(np.shape(phi) + (2, 2))
        T[..., 0, 0] = T[..., 1, 1] = 1.0
        T[..., 1, 0] = -U1
        return T

    def M(self, phi):
        T = self._Tinv(phi)
        return np.swapaxes(T, -1, -2) @ self.unit.M(phi) @ T

    def B(self, phi, Omega):
        return np.zeros(np.shape(phi) + (2, 2))

    def C(self, phi, Omega=0.0, Omega_dot=0.0):
        T = self._Tinv(phi)
        return np.swapaxes(T, -1, -2) @ self.unit.C(phi, Omega, Omega_dot) @ T


def _pair(N=40, c_g=2e4, left=None):
    unit = follower_unit(CAM, 2e-3, 0.5, 2e5, c_g=c_g)
    phases = 2 * np.pi * np.arange(N) / N
    kw = dict(cells=True, phases=phases, left=left or End.elastic(4e4))
    return chain(unit, N, 0.25, 0.04, **kw), chain(Absolute(unit), N, 0.25, 0.04, **kw)


def test_impedance_smearing_does_not_depend_on_the_units_coordinates():
    rel, ab = _pair()
    phi = 1.0
    # the chain itself is the same in both coordinates (exact: a congruence per unit)
    t_rel = transfer_modes(rel, phi, n_modes=6, vectors=False).freq_hz
    t_ab = transfer_modes(ab, phi, n_modes=6, vectors=False).freq_hz
    assert np.allclose(t_rel, t_ab, rtol=1e-9)  # bound: bisection rtol 1e-12 on λ, twice
    opts = dict(vectors=False, estimate=False, warn=False)
    imp_rel = continuum_modes(rel, phi, 6, **opts).freq_hz
    imp_ab = continuum_modes(ab, phi, 6, **opts).freq_hz
    # the mean of the units' dynamic stiffness on their nodes is coordinate-free; the
    # bisection to round-off of both -> the same roots to ~1e-13
    assert np.allclose(imp_rel, imp_ab, rtol=1e-9)  # bound: bisection to 4 ulps, twice
    mat_rel = continuum_modes(rel, phi, 6, smearing="matrices", **opts).freq_hz
    mat_ab = continuum_modes(ab, phi, 6, smearing="matrices", **opts).freq_hz
    # the chapter's smearing of M and C is not: measured 13.5 % apart on the lowest root,
    # 3.4 % on the second
    assert np.max(np.abs(mat_rel / mat_ab - 1)) > 0.05


def test_impedance_equals_matrices_for_identical_phases():
    unit = follower_unit(CAM, 2e-3, 0.5, 2e5, c_g=3e4)
    ch = chain(unit, 20, 0.25, 0.04, cells=True, phases=0.4, left=End.elastic(4e4))
    opts = dict(vectors=False, estimate=False, warn=False)
    a = continuum_modes(ch, 0.3, ch.n, **opts)
    b = continuum_modes(ch, 0.3, ch.n, smearing="matrices", **opts)
    # one small eigenproblem (eigh, ~1e-13) against its condensed scalar equation (bisection)
    assert np.allclose(a.freq_hz, b.freq_hz, rtol=1e-9)  # bound: eigh 1e-13, bisection 1e-15
    assert np.array_equal(a.label, b.label)


def test_error_estimate_is_the_error_against_the_chain():
    ch, _ = _pair(N=40, c_g=2e4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        co = continuum_modes(ch, 1.0, 5, vectors=False)
    M, _, C = ch.sparse_matrices(1.0)
    lam = sla.eigh(C.toarray(), M.toarray(), eigvals_only=True)[:5]
    f_ref = np.sqrt(lam) / (2 * np.pi)  # reference: dense eigh of the assembled chain
    assert co.error.shape == (5,)
    # the estimate uses transfer roots (1e-12); eigh ~1e-13 relative here
    assert np.allclose(co.error, co.freq_hz / f_ref - 1, rtol=0, atol=1e-9)  # bound: as said
    # measured with c_g = 2e4 N/m: the lowest root within 1.1 %, the next within 1 %
    assert np.abs(co.error[:2]).max() < 0.02


def test_warns_outside_the_validity_range():
    # c_g = 1e5 N/m on spread phases, N = 100: the lowest modes depend on where the stiff
    # and soft units sit (measured 11.5 Hz continuum against 15.65 Hz at φ = 1)
    ch, _ = _pair(N=100, c_g=1e5)
    with pytest.warns(ModelWarning, match="outside its validity range.*static stiffness"):
        co = continuum_modes(ch, 1.0, 3, vectors=False)
    assert np.abs(co.error).max() > ERROR_MEASURED_FLOOR
    # without the estimate the validity conditions alone warn
    with pytest.warns(ModelWarning, match="static stiffness d_u\\(0\\) varies"):
        continuum_modes(ch, 1.0, 3, vectors=False, estimate=False)
    # long waves (μ > 0.5) are named
    problems = validity_problems(ch, 1.0, continuum_modes(ch, 1.0, 40, vectors=False,
                                                          estimate=False, warn=False))
    assert any("wave numbers μ > 0.5" in p for p in problems)
    assert any("above 0.5 × the units' lowest internal frequency" in p for p in problems)


ERROR_MEASURED_FLOOR = 0.05  # the lowest root's measured error here is 26 %


def test_no_warning_inside_the_validity_range():
    # identical phases, the 3 lowest shaft modes of N = 40 (μ ≤ 3π/80): dispersion only
    unit = follower_unit(CAM, 2e-3, 0.5, 2e5)
    ch = chain(unit, 40, 0.25, 0.04, cells=True, phases=0.3)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelWarning)
        co = continuum_modes(ch, np.radians(150.0), 3, vectors=False)
    assert np.abs(co.error).max() < 1e-3  # μ²/24 with μ ≤ 0.16
    assert validity_problems(ch, np.radians(150.0), co) == []
