"""The chain API: follower ground spring, exact shaft values, the Chain constructor with
End, sweeps that keep every branch among the n lowest, the assembled solver choice, and
the names docs/chain.md gives."""

import importlib
import re
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla

from femmech.chain import Chain, End, chain, follower_unit, torsion_segment
from femmech.chain.sweep import chain_sweep
from femmech.chain.transfer import assembled_modes, transfer_modes
from femmech.mechanisms import cam_program

CAM = cam_program(0.03, rise=120, dwell_top=60, return_=120, dwell_bottom=60,
                  law="modified_sine")
ROOT = Path(__file__).resolve().parents[2]


# --- follower ground spring --------------------------------------------------------------

def test_follower_ground_spring_matrices():
    # V = ½ c q2² + ½ c_g (U(ψ) + q2)², ψ = φ + q1, process force F on x2: linearised
    # about q = 0 (by hand): C11 = F U'' + c_g (U'² + U U''), C12 = c_g U', C22 = c + c_g;
    # M unchanged [[J + m U'², m U'], [m U', m]]
    J, m, c, F, cg = 2e-3, 0.5, 2e5, 40.0, 3e4
    phi = np.array([0.3, 1.0, 2.4, 3.0])
    unit = follower_unit(CAM, J, m, c, force=F, c_g=cg)
    U, U1, U2, _ = CAM.derivatives(phi)
    C = unit.C(phi, 0.0, 0.0)
    M = unit.M(phi)
    # bound: sympy-lambdified products of O(1) factors, a few ulps -> 1e-12 relative
    assert np.allclose(C[:, 0, 0], F * U2 + cg * (U1**2 + U * U2), rtol=1e-12, atol=1e-12)
    assert np.allclose(C[:, 0, 1], cg * U1, rtol=1e-12, atol=0)
    assert np.allclose(C[:, 1, 0], cg * U1, rtol=1e-12, atol=0)
    assert np.allclose(C[:, 1, 1], c + cg, rtol=1e-12)  # bound: one sum, 1 ulp
    # bound: the same expressions evaluated twice: identical up to ~1 ulp
    assert np.allclose(M, follower_unit(CAM, J, m, c, force=F).M(phi), rtol=1e-14, atol=0)
    # c_g = 0 is the unit without it
    assert np.array_equal(follower_unit(CAM, J, m, c, c_g=0.0).C(phi, 0.0, 0.0),
                          follower_unit(CAM, J, m, c).C(phi, 0.0, 0.0))


@pytest.mark.parametrize("bad", [-1.0, np.nan, np.inf])
def test_follower_ground_spring_is_validated(bad):
    with pytest.raises(ValueError, match="c_g must be finite and >= 0"):
        follower_unit(CAM, 2e-3, 0.5, 2e5, c_g=bad)


def test_ground_spring_chain_transfer_equals_assembled():
    # C_ia = c_g U' ≠ 0: the condensation's α terms are exercised
    unit = follower_unit(CAM, 2e-3, 0.5, 2e5, c_g=5e4)
    ch = chain(unit, 6, 0.25, 0.04, phases=np.linspace(0, 5, 6), left=End.elastic(1e4))
    M, _, C = ch.sparse_matrices(0.7)
    lam = sla.eigh(C.toarray(), M.toarray(), eigvals_only=True)
    modes = transfer_modes(ch, 0.7, n_modes=ch.n)
    assert modes.converged.all()
    # bisection to 1e-12, eigh ~1e-13 relative here (no rigid mode: grounded)
    # bound: bisection rtol 1e-12 on λ; eigh ~1e-13 relative (grounded, no rigid mode)
    assert np.allclose(modes.omega2, lam, rtol=1e-9)


# --- chain(): exact shaft values, massless shaft ------------------------------------------

def test_exact_shaft_stiffness_and_inertia():
    unit = follower_unit(CAM, 2e-3, 0.5, 2e5)
    ch = chain(unit, 4, 0.3, None, shaft_stiffness=5e4, shaft_inertia=1e-3, cells=True,
               station_inertia=1e-4)
    assert np.array_equal(ch.spring, np.full(3, 5e4))
    # bound: sums of two doubles: <= 2 ulps
    assert np.allclose(ch.node_inertia, 1e-3 + 1e-4, rtol=1e-15)  # one spacing per cell
    stub = chain(unit, 3, 0.3, None, shaft_stiffness=5e4, shaft_inertia=1e-3,
                 end_length=0.1)
    # a stub of length L: c_s · spacing / L, J_s · L / spacing
    # bound: one multiplication/division per value: <= 2 ulps
    assert np.allclose(stub.spring, [1.5e5, 5e4, 5e4, 1.5e5], rtol=1e-14)
    assert np.allclose(stub.node_inertia[[0, 1]], [1e-3 / 6, 1e-3 / 6 + 5e-4], rtol=1e-14)
    # only one exact value: the other from the diameter
    k, J = torsion_segment(0.3, 0.04)
    half = chain(unit, 4, 0.3, 0.04, shaft_stiffness=5e4)
    assert np.array_equal(half.spring, np.full(3, 5e4))
    # bound: torsion_segment's own product, a few ulps
    assert np.allclose(half.node_inertia[1], J, rtol=1e-14)


def test_massless_shaft():
    unit = follower_unit(CAM, 2e-3, 0.5, 2e5)
    ch = chain(unit, 5, 0.25, 0.04, shaft_inertia=0.0, station_inertia=1e-3,
               phases=np.linspace(0, 4, 5))
    assert np.array_equal(ch.node_inertia, np.full(5, 1e-3))
    M, _, C = ch.sparse_matrices(0.4)
    lam = sla.eigh(C.toarray(), M.toarray(), eigvals_only=True)
    modes = transfer_modes(ch, 0.4, n_modes=ch.n)
    assert modes.converged.all()
    # a free–free chain: one rigid-body root (0, eigh's ±1e-16 λ_max), the rest to 1e-9
    assert modes.freq_hz[0] == 0.0
    # bound: bisection rtol 1e-12; eigh eps·λ_max/λ_1 ~1e-12 here
    assert np.allclose(modes.omega2[1:], lam[1:], rtol=1e-9)


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"shaft_stiffness": 0.0}, "shaft_stiffness must be finite and > 0"),
    ({"shaft_inertia": -1.0}, "shaft_inertia must be finite and >= 0"),
    ({"shaft_diameter": None}, "give shaft_diameter, or both"),
])
def test_exact_shaft_values_are_validated(kwargs, message):
    unit = follower_unit(CAM, 2e-3, 0.5, 2e5)
    args = {"shaft_diameter": 0.04, **kwargs}
    with pytest.raises(ValueError, match=message):
        chain(unit, 3, 0.25, **args)


# --- the Chain constructor with End ----------------------------------------------------------

def test_chain_constructor_takes_ends():
    unit = follower_unit(CAM, 2e-3, 0.5, 2e5)
    ref = chain(unit, 3, 0.25, 0.04, left=End.elastic(2e4, 0.8), right=End.fixed())
    k, J = torsion_segment(0.25, 0.04)
    mine = Chain(unit, [J / 2, J, J / 2], [k, k], [0, 1, 2], 0.0,
                 left=End.elastic(2e4, 0.8), right=End.fixed())
    # bound: the same sums in another order: <= 2 ulps
    assert np.allclose(mine.node_inertia, ref.node_inertia, rtol=1e-15)
    assert np.array_equal(mine.ground, ref.ground)
    assert np.array_equal(mine.clamped, ref.clamped)
    assert mine.left is None
    assert mine.right is None
    for a, b in zip(mine.sparse_matrices(0.5), ref.sparse_matrices(0.5), strict=True):
        assert abs(a - b).max() <= 1e-15 * max(abs(b).max(), 1.0)  # bound: 2-term sums, ulps
    # applied once: a copy does not add the flywheel and coupling again
    from dataclasses import replace

    again = replace(mine, phase=np.array([0.0, 1.0, 2.0]))
    assert np.array_equal(again.node_inertia, mine.node_inertia)
    assert np.array_equal(again.ground, mine.ground)
    with pytest.raises(ValueError, match="Chain left must be an End"):
        Chain(unit, [J, J], [k], [0], 0.0, left=2e4)


# --- sweeps keep every branch among the n lowest -------------------------------------------

def _switching_pair():
    """Two independent halves (clamped middle node): at φ = 0 unit B (phase 90°, mid-rise,
    large reduced inertia J + m U'²) has the lower shaft root, at φ = 60° unit A (phase 0,
    mid-rise) does while B dwells: the lowest branch changes."""
    unit = follower_unit(CAM, 2e-3, 0.5, 2e5)
    J = np.array([1e-3, 1e-3, 1e-3])
    clamped = np.array([False, True, False])
    return Chain(unit, J, np.array([2e2, 2e2]), np.array([0, 2]),
                 np.radians([0.0, 90.0]), None, clamped)


@pytest.mark.parametrize("method", ["transfer", "assembled"])
def test_sweep_keeps_a_branch_that_becomes_one_of_the_lowest(method):
    ch = _switching_pair()
    phi = np.radians(np.arange(0.0, 121.0, 5.0))
    sw = chain_sweep(ch, phi, 1, method)
    lowest = []  # reference: dense eigh of the assembled chain at each angle
    for p in phi:
        M, _, C = ch.sparse_matrices(p)
        lowest.append(np.sqrt(sla.eigh(C.toarray(), M.toarray(), eigvals_only=True)[0])
                      / (2 * np.pi))
    assert sw.freq_hz.shape == (phi.size, 1)
    # the column holds the lowest root at every angle (eigh vs bisection: 1e-9) ...
    assert np.allclose(sw.freq_hz[:, 0], lowest, rtol=1e-9)  # bound: rtol 1e-12 / eigh 1e-13
    # ... and says where it passes from one branch to the other (B lowest at φ = 0, A at 60°)
    assert np.count_nonzero(sw.mac_step[:, 0] == 0.0) >= 1
    assert sw.mac_step[0, 0] == 1.0


# --- assembled_modes: dense or sparse -------------------------------------------------------

def test_assembled_solver_choice():
    unit = follower_unit(CAM, 2e-3, 0.5, 2e5)
    ch = chain(unit, 150, 0.25, 0.04, phases=np.linspace(0, 6, 150), left=End.fixed())
    dense = assembled_modes(ch, 0.3, n_modes=8, solver="dense")
    sparse = assembled_modes(ch, 0.3, n_modes=8, solver="sparse")
    auto = assembled_modes(ch, 0.3, n_modes=8)
    # Lanczos residual <= 1e-6 relative: eigenvalues converge quadratically (~1e-12);
    # dense eigh ~eps λ_max / λ_1 ≈ 1e-10 on the lowest root of this 299-coordinate chain
    # bound: Lanczos residual <= 1e-6 -> λ error ~1e-12 (quadratic); eigh ~1e-10 on the lowest
    assert np.allclose(sparse.freq_hz, dense.freq_hz, rtol=1e-9)
    assert np.allclose(auto.freq_hz, dense.freq_hz, rtol=1e-9)
    M = ch.sparse_matrices(0.3)[0]
    mac = (dense.vectors.T @ (M @ sparse.vectors)) ** 2
    assert np.allclose(np.diag(mac), 1.0, atol=1e-8)  # same modes (M-normalised both)
    band = assembled_modes(ch, 0.3, f_max=dense.freq_hz[-1] * (1 + 1e-9), solver="sparse")
    assert np.allclose(band.freq_hz, dense.freq_hz, rtol=1e-9)  # bound: as above (Lanczos band)
    with pytest.raises(ValueError, match="solver must be one of"):
        assembled_modes(ch, 0.3, n_modes=3, solver="lapack")
    with pytest.raises(ValueError, match="sparse solver needs n_modes or f_max"):
        assembled_modes(ch, 0.3, solver="sparse")


# --- docs/chain.md names importable things ---------------------------------------------------

def test_dotted_names_in_chain_docs_exist():
    text = (ROOT / "docs" / "chain.md").read_text(encoding="utf-8")
    names = set(re.findall(r"`(femmech(?:\.\w+)+)`", text))
    names |= set(re.findall(r"\(`?(femmech(?:\.\w+)+)`?\)", text))
    assert names  # the doc does name things
    missing = []
    for name in sorted(names):
        parts = name.split(".")
        for cut in range(len(parts), 0, -1):
            try:
                obj = importlib.import_module(".".join(parts[:cut]))
            except ImportError:
                continue
            try:
                for attr in parts[cut:]:
                    obj = getattr(obj, attr)
            except AttributeError:
                missing.append(name)
            break
        else:
            missing.append(name)
    assert not missing, missing
