"""The kernels of the monodromy integrator: the degree-18 Taylor
exponential, the balancing of the step exponentials, the block commutator and the batched
doubling levels, each against an independent computation.

The earlier integrator (Higham's [13/13] Padé exponential of the unbalanced
step exponents, one level at a time) is rebuilt here from scipy.linalg.expm (the same
Padé algorithm) as :func:`_reference_magnus`, so that "agrees with the old integrator"
is checked against code that does not share the new kernels.
"""

import numpy as np
import scipy.linalg as sla
from models import hill_2dof  # the 2-DOF Hill system with gyroscopic damping

from femmech.analysis import magnus
from femmech.analysis.floquet import monodromy, monodromy_record


def _stiff_hill():
    """A soft periodic oscillator (ω ≈ 6 rad/s) on a stiff support (ω ≈ 3e4 rad/s): the
    frame-and-mechanism pattern whose first-order matrix has ‖A‖₁ ~ ω_max² ≈ 1e9 while
    its eigenvalues are ~ω_max (period 1 s)."""
    k_stiff, m_support = 9e8, 1.0

    def M(t):
        return np.broadcast_to(np.diag([m_support, 1.0]), (t.size, 2, 2)).copy()

    def C(t):
        c = np.zeros((t.size, 2, 2))
        k = 36.0 * (1.0 + 0.3 * np.cos(2 * np.pi * t))
        c[:, 0, 0] = k_stiff + k
        c[:, 0, 1] = c[:, 1, 0] = -k
        c[:, 1, 1] = k
        return c

    return M, np.diag([300.0, 0.5]), C, 1.0


def _reference_magnus(M, B, C, T, n):
    """Magnus-4 over n equal steps with scipy.linalg.expm of each unbalanced step exponent
    (the earlier integrator, matrix by matrix)."""
    h = T / n
    t = (np.arange(n)[:, None] * h + magnus.GAUSS_OFFSETS[None, :] * h).ravel()
    Bs = np.broadcast_to(B, (t.size, *np.shape(B)))
    A = magnus.first_order_matrices(M(t), Bs, C(t))
    Phi = np.eye(A.shape[-1])
    for A1, A2 in zip(A[0::2], A[1::2], strict=True):
        Omega = 0.5 * h * (A1 + A2) + np.sqrt(3.0) / 12.0 * h**2 * (A2 @ A1 - A1 @ A2)
        Phi = sla.expm(Omega) @ Phi
    return Phi


def test_taylor18_exponential_matches_scipy_and_has_degree_18():
    # Against scipy's Padé expm (Higham 2005) on non-normal matrices over six decades of
    # norm: the difference is bounded by the conditioning, ~‖A‖₁ eps relative (measured
    # 5e-16 at ‖A‖₁ ≤ θ₁₈ and 2.4e-13 at 300): required 50 eps max(1, ‖A‖₁).
    rng = np.random.default_rng(11)
    G = rng.standard_normal((7, 12, 12))
    G /= np.abs(G).sum(axis=1).max(axis=1)[:, None, None]  # ‖G‖₁ = 1
    A = np.array([1e-3, 0.5, 1.0, magnus._THETA18, 3.0, 30.0, 300.0])[:, None, None] * G
    for a, e in zip(A, magnus.expm_stack(A), strict=True):
        ref = sla.expm(a)
        norm = np.abs(a).sum(axis=0).max()
        assert np.abs(e - ref).max() <= 50 * np.finfo(float).eps * max(1, norm) * \
            np.abs(ref).max()
    # Without scaling (|x| ≤ θ₁₈) the five-product formula is the Taylor polynomial of
    # degree 18 (Bader, Blanes & Casas 2019, eq. (19): its coefficients solve the order
    # conditions up to degree 18): on scalars it equals the Taylor sum to round-off.
    x = np.linspace(-1.0, 1.0, 9)
    taylor = sum(x**j / np.prod(np.arange(1, j + 1, dtype=float)) for j in range(19))
    got = magnus.expm_stack(x[:, None, None])[:, 0, 0]
    assert np.abs(got - taylor).max() < 4 * np.finfo(float).eps * taylor.max()


def test_block_commutator_equals_the_dense_one():
    # [P, Q] from four n-wide products equals PQ - QP of the balanced first-order
    # matrices to round-off (relative to ‖P‖ ‖Q‖).
    rng = np.random.default_rng(5)
    k, n = 4, 5
    M = rng.standard_normal((k, n, n)) + 6 * np.eye(n)
    A = magnus.first_order_matrices(M, rng.standard_normal((k, n, n)),
                                    rng.standard_normal((k, n, n)))
    d = 2.0 ** rng.integers(-6, 6, 2 * n)
    A = A * (d[None, None, :] / d[None, :, None])
    P, Q = A[:2], A[2:]
    dense = P @ Q - Q @ P
    scale = np.abs(P).max() * np.abs(Q).max() * 2 * n
    # bound: the same products summed in another order: ~n eps of the scale
    assert np.abs(magnus._first_order_commutator(P, Q) - dense).max() < 1e-14 * scale


def test_balancing_is_exact_and_cuts_the_norm_of_a_stiff_system():
    # Powers of 2, so D⁻¹ A D is exact; on the stiff system the 1-norm falls by orders
    # of magnitude (from ~ω_max² to ~ω_max: 9e8 → below 1e5 required; measured 3.3e4).
    M, B, C, _ = _stiff_hill()
    t = np.linspace(0, 1, 8)
    A = magnus.first_order_matrices(M(t), np.broadcast_to(B, (8, 2, 2)), C(t))
    d = magnus._balancing(A)
    assert np.all(np.log2(d) == np.round(np.log2(d)))
    balanced = A * (d[None, None, :] / d[None, :, None])
    assert np.array_equal(balanced / (d[None, None, :] / d[None, :, None]), A)
    norm = lambda X: np.abs(X).sum(axis=1).max()  # noqa: E731
    assert norm(A) > 8e8
    assert norm(balanced) < 1e5


def test_agrees_with_the_old_integrator_where_it_was_accurate():
    # Non-stiff 2-DOF Hill system at 16 and 64 steps: the new kernels (Taylor-18,
    # balancing, block commutator, batched products) and the old integrator (scipy expm
    # of every unbalanced step exponent) agree to round-off of the product: 1e-12
    # relative to ‖Φ‖ (measured 1e-15).
    M, B, C, T = hill_2dof()
    for n in (16, 64):
        new = monodromy(M, B, C, T, n, rtol=None)
        old = _reference_magnus(M, B, C, T, n)
        # bound: the same steps in another order: ~n eps of the products, n <= 64
        assert np.abs(new - old).max() < 1e-12 * np.abs(old).max(), n


def test_round_off_floor_on_a_stiff_system_against_an_exact_exponential():
    # Constant coefficients, stiff support (‖hA‖₁ = 1.8e5 unbalanced, 6.5 balanced, at
    # 1024 steps over 0.2 s): Magnus is exact, so only round-off of 1024 step
    # exponentials and their product remains. Reference: exp(A T) in 40-digit arithmetic
    # (mpmath). Measured ρ error 1.1e-12 (old integrator 7.8e-14; on the press example
    # the old one's floor was 1e-9 and the new one's 4e-13, docs/performance.md): required
    # 1e-11, 7 orders below the default tolerance 1e-4.
    import mpmath

    M, B, C, _ = _stiff_hill()
    C0 = C(np.zeros(1))[0]
    A = magnus.first_order_matrices(M(np.zeros(1)), B[None], C0[None])[0]
    T = 0.2
    with mpmath.workdps(40):
        exact = np.array(mpmath.expm(mpmath.matrix(A.tolist()) * T).tolist(), dtype=float)
    Phi = monodromy(M(np.zeros(1))[0], B, lambda t: np.broadcast_to(C0, (t.size, 2, 2)), T,
                    1024, rtol=None)
    rho = np.abs(np.linalg.eigvals(exact)).max()
    # bound: 1024 step exponentials of a constant system (exact Magnus): ~n eps growth
    assert abs(np.abs(np.linalg.eigvals(Phi)).max() - rho) < 1e-11 * rho


def test_batched_levels_equal_levels_one_at_a_time():
    # The step-doubling run integrates its first three levels in one batch: the accepted
    # matrix equals a fixed-step run with the same step count to round-off (the balancing
    # is taken from the first batch, which may differ: required 1e-13 relative to ‖Φ‖,
    # measured 0 at 64 steps), and the record's error is the difference of the last two
    # levels, recomputed one at a time.
    M, B, C, T = hill_2dof()
    record = monodromy_record(M, B, C, T, 16, 1e-6, 2**12)
    assert record.converged
    fixed = [monodromy(M, B, C, T, record.n_steps // f, rtol=None) for f in (2, 1)]
    # bound: the same fixed-step product: round-off only
    assert np.abs(record.matrix - fixed[1]).max() < 1e-13 * np.abs(fixed[1]).max()
    radii = [np.abs(np.linalg.eigvals(P)).max() for P in fixed]
    # bound: the same radii, subtracted in another order: a few eps
    assert abs(record.error - abs(radii[1] - radii[0])) < 1e-12
