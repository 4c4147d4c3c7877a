"""Badly scaled units: the transfer method's roots are verified, never confidently wrong.

Every test compares the transfer roots with the assembled model (dense ``eigh``) and the
Wittrick–Williams count with the assembled model's Sturm (inertia) count
(:func:`femmech.solve.sturm.inertia_below`, an LDLᵀ of C − σM, independent of the
transfer recursion), for massless, nearly massless, very stiff and very soft units.
"""

import numpy as np
import pytest
import scipy.linalg as sla

from femmech.chain import Chain, End, chain, follower_unit
from femmech.chain import transfer as tr
from femmech.chain.transfer import count_below, transfer_modes
from femmech.errors import ConvergenceWarning
from femmech.mechanisms import cam_program
from femmech.solve.sturm import inertia_below

CAM = cam_program(0.03, rise=120, dwell_top=60, return_=120, dwell_bottom=60,
                  law="modified_sine")
SPACING, DIAMETER = 0.25, 0.04  # m, steel shaft: k = 8.1e4 N m/rad, J = 2.5e-4 kg m²/spacing


def reference(ch, phi):
    """All eigenvalues of the assembled chain, dense eigh (M positive definite here)."""
    M, _, C = ch.sparse_matrices(phi)
    return sla.eigh(C.toarray(), M.toarray(), eigvals_only=True)


def sturm(ch, phi, lam):
    """Assembled Sturm counts (eigenvalues below each λ of ``lam``)."""
    M, _, C = ch.sparse_matrices(phi)
    return np.array([inertia_below(C.tocsc(), M.tocsc(), float(x)) for x in lam])


def test_nearly_massless_unit_keeps_its_roots():
    # hub inertia 0 and φ = 1e-6 rad (U' ≈ 6e-13: M_aa = m U'² ≈ 6e-27 kg m², tiny but not
    # zero). The old scale max|C_aa| / M_aa ≈ 3.5e21 rad²/s² made every root below ~940 Hz
    # "rigid-body" and reported 0 Hz, converged.
    unit = follower_unit(CAM, inertia=0.0, mass=0.5, stiffness=2e5, force=100.0)
    ch = chain(unit, 2, SPACING, DIAMETER)
    phi = 1e-6
    lam = reference(ch, phi)
    modes = transfer_modes(ch, phi, n_modes=4)
    assert modes.converged.all()
    # first root: the process force's stiffness F U'' on the shaft inertia, 0.048 Hz;
    # then the two followers at √(c/m)/2π = 100.66 Hz and the shaft mode
    assert modes.freq_hz[0] > 0.01
    assert np.allclose(modes.freq_hz[1:3], np.sqrt(2e5 / 0.5) / (2 * np.pi), rtol=1e-6)
    # eigh's error on the lowest root is ~eps λ_max / λ_1 ≈ 1e-16 · 6.6e8 / 0.09 ≈ 1e-6
    assert np.allclose(modes.omega2, lam, rtol=1e-5)
    # bound: bisection rtol 1e-12; eigh eps·λ_max/λ ≈ 1e-16 · 6.6e8 / 4e5 ≈ 2e-13 on these
    assert np.allclose(modes.omega2[1:], lam[1:], rtol=1e-10)


def _massless_hub(phi_dwell):
    # hub inertia 0, unit in a dwell (U' = 0 exactly: M_aa = 0): the node carries the
    # shaft inertia only
    unit = follower_unit(CAM, inertia=0.0, mass=0.5, stiffness=2e5)
    return chain(unit, 4, SPACING, DIAMETER, phases=[0.0, 0.5, 1.0, 2.9],
                 left=End.elastic(1e4)), phi_dwell


CASES = {
    "massless-hub": lambda: _massless_hub(np.radians(150.0)),
    "nearly-massless-hub": lambda: (chain(follower_unit(CAM, 0.0, 0.5, 2e5, force=100.0), 5,
                                          SPACING, DIAMETER, phases=1e-7 * np.arange(5)),
                                    1e-6),
    "stiff-follower": lambda: (chain(follower_unit(CAM, 2e-3, 0.5, 2e13), 5, SPACING, DIAMETER,
                                     phases=np.linspace(0, 5, 5), left=End.fixed()), 0.3),
    "soft-follower": lambda: (chain(follower_unit(CAM, 2e-3, 0.5, 1e-3), 5, SPACING, DIAMETER,
                                    phases=np.linspace(0, 5, 5)), 0.3),
    "soft-shaft-heavy-flywheel": lambda: (chain(follower_unit(CAM, 2e-3, 0.5, 2e5), 5, SPACING,
                                                0.002, phases=np.linspace(0, 5, 5),
                                                left=End.flywheel(1e4)), 0.3),
}


@pytest.mark.parametrize("name", list(CASES))
def test_badly_scaled_units_agree_with_the_assembled_count(name):
    ch, phi = CASES[name]()
    lam = reference(ch, phi)
    f_top = 1.001 * np.sqrt(lam[-1]) / (2 * np.pi)
    modes = transfer_modes(ch, phi, f_max=f_top)
    assert modes.converged.all()
    assert len(modes) == ch.n
    # eigh's absolute error ~eps λ_max (a relative eps λ_max / λ on each root: up to ~1e-6
    # on the soft ones next to a 2e13 N/m spring); the transfer roots to rtol 1e-12
    # bound: bisection rtol 1e-12 on λ plus eigh's absolute eps·λ_max
    tol = 1e-9 * np.abs(lam) + 100 * np.finfo(float).eps * np.abs(lam).max()
    assert np.all(np.abs(modes.omega2 - lam) <= tol)
    # W–W count against the assembled Sturm count between and around every root
    cuts = np.unique(np.concatenate([0.5 * (lam[1:] + lam[:-1]), [1.5 * lam[-1]],
                                     [-1.0 - abs(lam[0])]]))
    cuts = cuts[np.min(np.abs(cuts[:, None] - lam), axis=1) > 1e-6 * np.abs(cuts)]
    f = np.sign(cuts) * np.sqrt(np.abs(cuts)) / (2 * np.pi)
    assert np.array_equal(count_below(ch, phi, f), sturm(ch, phi, cuts))


def test_massless_node_has_no_root():
    # no shaft inertia (rho = 0), hub inertia 0 and a dwell: the node has no mass at all,
    # its eigenvalue is infinite and is not counted; the finite roots are those of the
    # followers' c/m and of the remaining nodes
    unit = follower_unit(CAM, inertia=0.0, mass=0.5, stiffness=2e5)
    J = np.array([1e-2, 0.0, 1e-2])
    ch = Chain(unit, J, np.array([8e4, 8e4]), np.array([1]), np.array([0.0]))
    phi = np.radians(150.0)  # dwell: U' = 0
    modes = transfer_modes(ch, phi, f_max=1e5)
    assert modes.converged.all()
    assert len(modes) == 3  # n = 4 coordinates, one massless
    # references: rigid rotation 0; the follower √(c/m); the outer nodes antisymmetric,
    # the middle node massless and at rest: λ = k / J (the middle node is a fixed point)
    assert modes.freq_hz[0] == 0.0
    # bound: bisection rtol 1e-12 on λ (references exact: c/m and k/J)
    assert np.allclose(modes.omega2[1:], np.sort([2e5 / 0.5, 8e4 / 1e-2]), rtol=1e-10)


def test_a_root_that_does_not_verify_is_flagged(monkeypatch):
    # simulate a scale that swallows the roots (the old failure: a zero threshold far above
    # the lowest roots): the verification must catch it, flag the roots and warn
    unit = follower_unit(CAM, inertia=0.0, mass=0.5, stiffness=2e5, force=100.0)
    ch = chain(unit, 2, SPACING, DIAMETER)
    monkeypatch.setattr(tr, "ZERO_RTOL", 1e-2)
    with pytest.warns(ConvergenceWarning, match="not verified"):
        modes = transfer_modes(ch, 1e-6, n_modes=4)
    zero = modes.freq_hz == 0.0
    assert zero.any()
    assert not modes.converged[zero].any()
    assert "UNCONVERGED" in repr(modes)


def test_a_count_that_disagrees_with_the_assembled_sturm_count_is_flagged(monkeypatch):
    # simulate a Wittrick–Williams count gone wrong (the assembled Sturm count one higher
    # at every cut): every root is flagged and a warning names the cut
    unit = follower_unit(CAM, 2e-3, 0.5, 2e5)
    ch = chain(unit, 4, SPACING, DIAMETER, phases=[0.0, 1.0, 2.0, 3.0], left=End.fixed())
    real = tr._sturm_counts
    monkeypatch.setattr(tr, "_sturm_counts", lambda M, C, cuts: [
        None if c is None else c + 1 for c in real(M, C, cuts)])
    with pytest.warns(ConvergenceWarning, match="Sturm count"):
        modes = transfer_modes(ch, 0.4, n_modes=3)
    assert not modes.converged.any()
    # without the check (verify=False) nothing is compared
    assert transfer_modes(ch, 0.4, n_modes=3, verify=False).converged.all()
