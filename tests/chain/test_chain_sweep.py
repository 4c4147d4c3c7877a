"""Chain sweeps over the drive angle: MAC tracking (transfer, assembled), label tracking
(cyclic, continuum), methods side by side."""

import numpy as np
import pytest

from femmech.analysis.sweep import clusters, subspace_mac
from femmech.chain import Chain, End, chain, follower_unit
from femmech.chain.sweep import chain_sweep, compare_methods
from femmech.chain.transfer import assembled_modes
from femmech.mechanisms import CamProfile, CamSegment, modified_sine

STROKE = 0.03
UNIT = follower_unit(CamProfile((CamSegment(np.radians(120), STROKE, modified_sine()),
                                 CamSegment(np.radians(60)),
                                 CamSegment(np.radians(120), -STROKE, modified_sine()),
                                 CamSegment(np.radians(60)))), 2e-3, 0.5, 2e5)
# modified-sine rise/return 120°, dwells 60°, 30 mm; hub 2e-3 kg m², follower 0.5 kg, 2e5 N/m


def test_transfer_and_assembled_sweeps_agree_branch_by_branch():
    # N = 10 phased over a revolution: at every angle 2–4 units share a dwell, so the
    # follower root 100.66 Hz is exactly repeated, splits and re-forms; the tracked
    # branches (cluster bases made solver-independent and carried through) agree
    n = 10
    ch = chain(UNIT, n, 0.25, 0.04, phases=2 * np.pi * np.arange(n) / n,
               left=End.elastic(2e4), right=End.flywheel(0.05))
    phi = np.radians(np.arange(0.0, 361.0, 10.0))
    got = chain_sweep(ch, phi, 12, "transfer")
    ref = chain_sweep(ch, phi, 12, "assembled")
    assert got.freq_hz.shape == (phi.size, 12)
    assert got.form == "symmetric"
    # roots to 1e-12 (bisection) against eigh's ~1e-13: 1e-9 is the target
    # bound: bisection rtol 1e-12 on λ vs eigh ~1e-13: f agrees to ~1e-12
    assert np.abs(got.freq_hz / ref.freq_hz - 1).max() <= 1e-9
    # 10° steps: the coupled follower shapes of units in a rise change that much per step
    assert got.mac_step.min() > 0.8
    assert np.array_equal(got.mac_step > 0.99,
                                                       ref.mac_step > 0.99)
    # periodic: after a revolution the same frequencies, but crossing branches may come
    # back permuted (a branch keeps its identity, not its rank)
    # bound: the same roots after a revolution, each to 1e-12
    assert np.allclose(np.sort(got.freq_hz[-1]), np.sort(got.freq_hz[0]), rtol=1e-9)


def _two_shafts():
    """A shaft clamped in the middle: two independent halves whose units run 1.3 rad
    apart, so the follower branches of the halves cross (exactly: no coupling)."""
    J, k = np.full(7, 2.5e-3), np.full(6, 8.1e4)
    clamped = np.zeros(7, bool)
    clamped[3] = True
    units = np.array([0, 1, 2, 4, 5, 6])
    return Chain(UNIT, J, k, units, np.array([0.0, 0.1, 0.2, 1.3, 1.4, 1.5]), None, clamped)


def test_tracking_through_a_crossing_keeps_identity():
    ch = _two_shafts()
    phi = np.radians(np.arange(0.0, 361.0, 3.0))
    sw = chain_sweep(ch, phi, 4, "transfer", keep_vectors=True)
    left = np.zeros(ch.n, bool)
    left[ch.unit_dofs[:3].ravel()] = True  # coordinates of the left half
    M0 = ch.sparse_matrices(0.0)[0]
    on_left = [np.sum(np.abs(sw.vectors[0][left, b]) ** 2 * M0.diagonal()[left])
               for b in range(4)]
    b = int(np.argmax(on_left))  # the left half's branch (the others are right-half modes)
    rank = np.argsort(np.argsort(sw.freq_hz, axis=1), axis=1)[:, b]
    assert rank.min() == 0
    assert rank.max() == 3
    for a, angle in enumerate(phi):
        ref = assembled_modes(ch, angle, n_modes=8)
        M = ch.sparse_matrices(angle)[0]
        v = sw.vectors[a][:, [b]]
        # identity by MAC against the assembled vectors (span of a repeated root when the
        # left units share a dwell): the branch is an assembled mode of the left half
        sub = subspace_mac(v, ref.vectors, clusters(ref.freq_hz, 1e-9), M)[0]
        j = int(np.argmax(sub))
        assert sub[j] > 1 - 1e-8
        # bound: bisection rtol 1e-12 vs eigh ~1e-13
        assert np.isclose(ref.freq_hz[j], sw.freq_hz[a, b], rtol=1e-9)
        # no mixing with the right half beyond the conditioning of close roots: a vector's
        # error is ~ε / (relative gap), and the halves' roots come within ~1e-9 here
        assert np.linalg.norm(v[~left]) <= 1e-6 * np.linalg.norm(v)


def test_label_tracking_for_the_closed_forms():
    pytest.importorskip("femmech.chain.cyclic")
    # uniform chain (identical cells, equal phases): the cyclic closed form per wave
    ch = chain(UNIT, 8, 0.25, 0.04, phases=0.3, cells=True)
    phi = np.radians(np.arange(0.0, 121.0, 20.0))
    cyc = chain_sweep(ch, phi, 6, "cyclic")
    ref = chain_sweep(ch, phi, 6, "transfer")
    # labels fix the branches: same frequencies as the MAC-tracked transfer sweep
    # (the closed form is exact; both ~1e-12)
    # bound: closed form (eigh of 2×2, ~1e-15) vs bisection rtol 1e-12
    assert np.allclose(np.sort(cyc.freq_hz, axis=1), np.sort(ref.freq_hz, axis=1),
                       rtol=1e-9, atol=1e-6)
    # a column passes to another label where one leaves the 6 lowest (mac_step 0 there)
    assert np.all((cyc.mac_step > 0.9) | (cyc.mac_step == 0.0))
    both = compare_methods(ch, phi[:2], 4, methods=("transfer", "continuum"))
    assert set(both) == {"transfer", "continuum"}
    assert both["continuum"].freq_hz.shape == (2, 4)


def test_sweep_requests():
    ch = chain(UNIT, 3, 0.25, 0.04)
    with pytest.raises(ValueError, match="unknown method 'holzer'"):
        chain_sweep(ch, [0.0], 2, "holzer")
    with pytest.raises(ValueError, match="n_modes"):
        chain_sweep(ch, [0.0], ch.n + 1)
