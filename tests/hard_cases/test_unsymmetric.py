"""Hard case 8: unsymmetric C(φ), damping, complex-conjugate pairs, flutter.

A two-mass mechanism on a base y_b that is attached to the frame, with a circulatory
(follower-type) coupling force of size P between its two coordinates:

    x_i = y_b + q_i,  2T = m (x_1'² + x_2'²),  2V = k_1 q_1² + k_2 q_2²,
    Q*_1 = -P q_2,  Q*_2 = P q_1   →   C = [[k_1, P], [-P, k_2]] (seed 5.2.2 eq. 10).

On a rigid base, ``λ = k̄/m ± √(Δ² - P²)/m`` (k̄ = (k_1 + k_2)/2, Δ = (k_2 - k_1)/2): real for
P < Δ, a complex-conjugate pair (flutter) for P > Δ. The undamped motion is ``e^{st}``,
``s = ±i√λ``: a complex λ always has a growing root, for *both* members of the pair.
"""

import numpy as np
import pytest
import sympy
from hard_models import RHS, STEEL, line_mesh
from numpy.testing import assert_allclose

import femmech as fm
from femmech.analysis.reference import full_modes
from femmech.analysis.sweep import parameter_sweep, sweep
from femmech.coupling import Attachment, Mount, couple
from femmech.mechanisms import Damper, Load, Mechanism, PointMass, Spring, rheolinear
from femmech.reduction.component_modes import craig_bampton

MASS, K1, K2 = 1.0, 4e4, 6e4  # kg, N/m
P_CRIT = (K2 - K1) / 2  # N/m: flutter onset on a rigid base


def _pair_mechanism():
    theta, yb, q1, q2 = sympy.symbols("theta y_b q1 q2")
    m, k1, k2, P, b = sympy.symbols("m k1 k2 P b")
    elements = (PointMass(m, (yb + q1,)), PointMass(m, (yb + q2,)), Spring(k1, q1),
                Spring(k2, q2), Load(P * q1, q2), Load(-P * q2, q1), Damper(b, q1),
                Damper(b, q2))
    return Mechanism((yb, q1, q2, theta), elements, drives=(theta,), name="flutter pair")


MECHANISM = _pair_mechanism()


def _frame():
    """Simply supported 1 m beam (lowest bending mode 144 Hz, above the pair's 32-39 Hz)."""
    mesh = line_mesh(20, 1.0, node_sets={"ends": [0, 20], "mid": [10]})
    return fm.build_model(mesh, {"all": fm.BeamProperty(RHS, STEEL)},
                          supports=[fm.Support("ends", "translations"), fm.Support(0, ["rx"])])


FRAME = _frame()
SE = craig_bampton(FRAME, "mid", n_modes=8)


def _system(P, b=0.0, node=0, form="primal", frame=SE):
    """The pair mounted at ``node`` (0: a supported node, i.e. a rigid base)."""
    model = rheolinear(MECHANISM, {"m": MASS, "k1": K1, "k2": K2, "P": P, "b": b})
    return couple(frame, [Mount(model, (Attachment("y_b", node, "uy"),), name="pair")], form)


def assert_same_values(got, expected, rtol):
    """Complex values equal as sets (each matched to its nearest; pairs with equal real
    parts make sort_complex order them by round-off)."""
    got, expected = np.asarray(got), np.asarray(expected)
    assert got.shape == expected.shape
    dist = np.abs(got[:, None] - expected[None, :])
    assert np.array_equal(np.sort(dist.argmin(axis=0)), np.arange(got.size))
    assert dist.min(axis=0).max() <= rtol * np.abs(expected).max()


def _rigid_base_lambda(P):
    root = np.sqrt(complex(P_CRIT**2 - P**2))
    return np.array([(K1 + K2) / 2 - root, (K1 + K2) / 2 + root]) / MASS


def test_flutter_pair_is_detected_and_reported():
    """Naive: symmetrising C (eigh) hides the flutter entirely; sorting eig's complex λ by
    real part and reporting √(Re λ) as the frequency makes the pair look like two modes
    at one frequency, one of them 'damped' (before this issue the members of a pair got
    damping ratios -0.066 and +0.066). femmech reports Re √λ / 2π, the growth ratio
    -|Im √λ| / |√λ| for both members, and flags both unstable (Sweep.unstable)."""
    loads = np.linspace(0.0, 2 * P_CRIT, 20)  # N/m; the onset P_CRIT lies between samples
    result = parameter_sweep(lambda P: (_system(P), 0.0), loads, phi=0.3, n_modes=4)
    assert result.form == "unsymmetric"
    for i, P in enumerate(loads):
        lam = _rigid_base_lambda(P)
        # the two mechanism branches are the two lowest (frame from 144 Hz)
        order = np.argsort(result.freq_hz[i])[:2]
        got = result.eigenvalues[i, order]
        # bound: dense QZ round-off (measured 4e-16 relative)
        assert_same_values(got, lam, rtol=1e-9)
        root = np.sqrt(lam)
        # bound: dense QZ on a 2-DOF pencil: eps·cond relative (measured 4e-16)
        assert_allclose(np.sort(result.freq_hz[i, order]), np.sort(root.real) / (2 * np.pi),
                        rtol=1e-9)
        flutter = P > P_CRIT
        assert result.unstable[i, order].tolist() == [flutter, flutter]
        if flutter:
            ratio = -np.abs(root.imag) / np.abs(root)
            assert_allclose(result.damping_ratio[i, order], ratio, rtol=1e-7)
        assert not result.unstable[i, np.argsort(result.freq_hz[i])[2:]].any()  # the frame


def test_damping_raises_the_flutter_onset():
    """With dampers b on q1 and q2 (B = b I commutes with C, M = m I), each λ of C gives
    ``m s² + b s + m λ = 0`` (analytic): the pair grows only once ``Re s > 0``, i.e. when
    the growth |Im √λ| of the undamped pair exceeds about b / (2m). Checked in the
    first-order (damped) form against the analytic roots; 'growing' must be flagged
    from Re s > 0, not guessed from frequencies."""
    b = 40.0  # N s/m
    loads = np.array([0.5, 1.02, 1.5, 3.0]) * P_CRIT
    result = parameter_sweep(lambda P: (_system(P, b), 0.0), loads, phi=0.0, n_modes=3,
                             damped=True)
    assert result.form == "damped"
    for i, P in enumerate(loads):
        lam = _rigid_base_lambda(P)
        s = np.concatenate([np.roots([MASS, b, MASS * v]) for v in lam])
        s = s[s.imag > 0]
        order = np.argsort(result.freq_hz[i])[:2]
        # bound: dense QZ and np.roots of a quadratic: eps·cond (measured 2e-12)
        assert_same_values(result.eigenvalues[i, order], s, rtol=1e-9)  # measured 2e-12
        assert result.unstable[i, order].any() == (s.real.max() > 0)
    # just above the undamped onset the damping still wins; far above it does not
    assert result.unstable[:, :2].any(axis=1).tolist() == [False, False, True, True]


@pytest.mark.parametrize("damped", [False, True])
def test_divergence_is_flagged_not_hidden(damped):
    """A negative stiffness (k2 < 0, P = 0: C symmetric, λ < 0) is a divergence: the
    motion grows like e^{√(-λ) t}. Naive: √ of a clipped λ reports 0 Hz like a rigid-body
    mode; a shift-inverted Cholesky solve fails ('K - σM not positive definite', which
    before this issue surfaced as 'some DOF has neither stiffness nor mass'); the damped
    form keeps roots with Im s > 0 only and silently drops the real growing root. femmech
    returns it with frequency 0, damping ratio -1 and the unstable flag."""
    model = rheolinear(MECHANISM, {"m": MASS, "k1": K1, "k2": -1e4, "P": 0.0, "b": 10.0})
    system = couple(SE, [Mount(model, (Attachment("y_b", 0, "uy"),), name="pair")])
    result = sweep(system, [0.0, 1.0], n_modes=3, damped=damped)
    assert result.unstable.sum(axis=1).tolist() == [1, 1]
    k = np.flatnonzero(result.unstable[0])[0]
    assert result.freq_hz[0, k] == 0.0
    assert result.damping_ratio[0, k] == -1.0
    if damped:  # m s² + b s + k2 = 0: the growing real root (analytic)
        expected = (-10.0 + np.sqrt(100.0 + 4e4)) / 2
        # bound: dense QZ against the closed-form real root: eps·cond of a 2-DOF pencil
        assert_allclose(result.eigenvalues[0, k], expected, rtol=1e-9)
    else:
        assert_allclose(result.eigenvalues[0, k], -1e4 / MASS, rtol=1e-9)
    assert result.form == ("damped" if damped else "symmetric")


def test_flutter_on_an_elastic_frame_reduced_full_and_multiplier_form():
    """The pair on the beam's mid-span (elastic base): reduced (CB) against the unreduced
    model (sparse shift-invert ARPACK, scipy eigs), and the multiplier form (the base as
    a constraint), which before this issue reported form 'symmetric' and damping ratio
    0 for any C: the flutter pair must be flagged in all three."""
    P = 1.5 * P_CRIT
    reduced = _system(P, node=10)
    result = sweep(reduced, [0.0], n_modes=4, track=False)
    assert result.form == "unsymmetric"
    pair = np.abs(result.eigenvalues[0].imag) > 1e-6 * np.abs(result.eigenvalues[0])
    assert pair.sum() == 2
    assert result.unstable[0, pair].all()
    full = _system(P, node="mid", frame=FRAME)
    lam, _ = full_modes(full, 0.0, 4)
    # CB (8 modes + residual vectors) vs full: measured 2e-9 of max |λ|
    assert_same_values(result.eigenvalues[0], lam, rtol=1e-7)
    mixed = sweep(_system(P, node=10, form="multiplier"), [0.0], n_modes=4, track=False)
    assert mixed.form == "unsymmetric"
    assert_same_values(mixed.eigenvalues[0], result.eigenvalues[0], rtol=1e-8)  # meas. 5e-14
    assert mixed.unstable.sum() == 2
