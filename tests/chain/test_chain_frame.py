"""The chain on an elastic frame (femmech.chain.frame): the guided unit against its own
Lagrange derivation, the coupled system against closed forms, the chain alone (stiff
frame) and the unreduced frame (Craig-Bampton), and a tracked sweep."""

import numpy as np
import pytest
import scipy.linalg as sla
import sympy

import femmech as fm
from femmech.analysis.reference import full_modes
from femmech.analysis.sweep import sweep
from femmech.chain import End, chain, follower_unit
from femmech.chain.frame import guided_unit, mount_chain
from femmech.coupling import frame_row
from femmech.fe import sections
from femmech.mechanisms import CamProfile, CamSegment, modified_sine
from femmech.reduction.component_modes import craig_bampton, guyan
from femmech.reduction.estimate import frequency_error_estimates

STROKE = 0.03
J_HUB, MASS, STIFF, DAMP, FORCE = 2e-3, 0.5, 2e5, 40.0, 150.0
BEARINGS = [8, 16, 24, 32]  # beam nodes at x = 0.2, 0.4, 0.6, 0.8 m
PHI = np.linspace(0.0, 2 * np.pi, 13)
SECTION = sections.rectangular_hollow(0.06, 0.08, 0.004)


def cam() -> CamProfile:
    """Modified-sine rise 120°, dwell 60°, return 120°, dwell 60°; stroke 30 mm."""
    return CamProfile((CamSegment(np.radians(120), STROKE, modified_sine()),
                       CamSegment(np.radians(60)),
                       CamSegment(np.radians(120), -STROKE, modified_sine()),
                       CamSegment(np.radians(60))))


@pytest.fixture(scope="module")
def unit():
    return follower_unit(cam(), J_HUB, MASS, STIFF, damping=DAMP, force=FORCE)


@pytest.fixture(scope="module")
def four(unit):
    """Four phased units 0.2 m apart on a 30 mm shaft, elastic drive coupling."""
    return chain(unit, 4, 0.2, 0.03, phases=np.arange(4) * np.pi / 2,
                 left=End.elastic(2e4))


def beam(E=210e9, n=40):
    """Simply supported 1 m steel tube along x; the units' followers guided in uy."""
    x = np.linspace(0.0, 1.0, n + 1)
    mesh = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(n), np.arange(1, n + 1)]),
                              node_sets={"ends": [0, n], "bearings": BEARINGS})
    prop = fm.BeamProperty(SECTION, fm.Material(E=E, nu=0.3, rho=7850.0))
    return fm.build_model(mesh, {"all": prop}, supports=[
        fm.Support("ends", "translations"), fm.Support(0, ["rx"])])


def alone(ch, phi, k):
    """Lowest k quasi-frequencies (Hz) of the chain alone (assembled, dense eigh)."""
    return np.array([np.sqrt(sla.eigh(ch.C(p), ch.M(p), eigvals_only=True)[:k])
                     for p in np.atleast_1d(phi)]) / (2 * np.pi)


def _lagrange_follower_on_frame():
    """M, B, C, F of Table 5.1 case 1 (c1 = 0) whose frame point moves by y along the
    follower axis, derived here independently of femmech.mechanisms.lagrange:
    2T = J ψ̇² + m (ẏ + d/dt U(ψ) + q̇2)², 2V = c q2², damper b on q2, process force F
    against the frame-relative position U(ψ) + q2; ψ = θ + q1. U(θ + q1) is expanded to
    second order in q1 (exact for the linearised equations), U_k = U^(k)(θ)."""

    class Uk(sympy.Function):  # U_k(θ), d/dθ U_k = U_{k+1}
        def fdiff(self, argindex=2):
            return Uk(self.args[0] + 1, self.args[1])

    t, eps = sympy.symbols("t epsilon")
    J, m, c, b, F = sympy.symbols("J m c b F")
    th = sympy.Function("theta")(t)
    z = [sympy.Function(f"z{i}")(t) for i in range(3)]
    q1, q2, y = (eps * zi for zi in z)
    U = Uk(0, th) + Uk(1, th) * q1 + Uk(2, th) * q1**2 / 2
    x_rel = U + q2
    T = (J * sympy.diff(th + q1, t)**2 + m * sympy.diff(y + x_rel, t)**2) / 2
    V = c * q2**2 / 2
    Om, Omd = sympy.symbols("Omega Omega_dot")
    Us = sympy.symbols("U0:5")
    rows = {key: sympy.zeros(3, 3) for key in "MBC"}
    Fv = sympy.zeros(3, 1)
    for j, zj in enumerate(z):
        # Lagrange's equation of q_j = ε z_j (divided by ε), non-conservative forces
        # Q_j = -F ∂x_rel/∂q_j - b q̇2 ∂q2/∂q_j; order ε⁰: -F_j, order ε¹: M z̈ + B ż + C z
        Q = -F * sympy.diff(x_rel, zj) - b * sympy.diff(q2, t) * sympy.diff(q2, zj)
        E = sympy.expand(((sympy.diff(sympy.diff(T, sympy.diff(zj, t)), t)
                           - sympy.diff(T, zj) + sympy.diff(V, zj) - Q) / eps).doit())
        E1 = E.coeff(eps, 1)
        for i, zi in enumerate(z):
            for key, d in (("M", sympy.diff(zi, t, 2)), ("B", sympy.diff(zi, t)), ("C", zi)):
                rows[key][j, i] = E1.coeff(d)
                E1 = E1.subs(d, 0)
        assert E1 == 0  # linear in z
        Fv[j] = -E.coeff(eps, 0)

    def subs(A):
        A = A.subs(sympy.diff(th, t, 2), Omd).subs(sympy.diff(th, t), Om)
        return A.subs({Uk(k, th): Us[k] for k in range(5)})

    out = {key: subs(A) for key, A in rows.items()}
    out["F"] = subs(Fv)
    return out, (J, m, c, b, F, Om, Omd, Us)


def test_guided_unit_matches_its_lagrange_derivation(unit):
    # sympy: the linearised equations of a follower on a moving frame point (derived in
    # the test, not by femmech's lagrange module) against guided_unit's compiled
    # matrices, with Ω, Ω̇ ≠ 0 (all kinetic terms) at a point of the rise; both are the
    # same closed form evaluated in floating point: round-off, 1e-12.
    sym, (J, m, c, b, F, Om, Omd, Us) = _lagrange_follower_on_frame()
    g = guided_unit(unit)
    assert g.coordinate_names == ("q1", "q2", "y_frame")
    phi, speed, accel = 1.0, 7.0, 3.0
    values = {J: J_HUB, m: MASS, c: STIFF, b: DAMP, F: FORCE, Om: speed, Omd: accel}
    values.update({Us[k]: cam()(phi, k) for k in range(4)})
    expected = {key: np.array(A.subs(values), dtype=float) for key, A in sym.items()}
    got = {"M": g.M(phi), "B": g.B(phi, speed), "C": g.C(phi, speed, accel),
           "F": g.F(phi, speed, accel)[:, None]}
    for key in "MBCF":
        scale = np.abs(expected[key]).max()
        # bound: sympy-lambdified products: a few ulps of the largest entry
        assert np.abs(got[key] - expected[key]).max() <= 1e-12 * scale, key
    # without the frame coordinate it is the chain's unit (Table 5.1 case 1)
    # bound: as above
    assert np.allclose(g.C(phi, speed, accel)[:2, :2], unit.C(phi, speed, accel),
                       rtol=1e-13, atol=0)


def test_single_dof_frame_closed_form(unit):
    # One unit on a clamped shaft node (q1 = 0) on a one-DOF frame (k_f, m_f: a Guyan
    # condensed cantilever tip, values read from the superelement): coordinates (u, q2),
    # M = [[m_f + m, m], [m, m]], K = diag(k_f, c) (follower at u + U + q2), so
    # λ solves m_f m λ² - (k_f m + c (m_f + m)) λ + k_f c = 0.
    mesh = fm.Mesh.from_lines(np.array([[0.0, 0, 0], [0.5, 0, 0]]), np.array([[0, 1]]))
    prop = fm.BeamProperty(SECTION, fm.Material(E=210e9, nu=0.3, rho=7850.0))
    fe = fm.build_model(mesh, {"all": prop}, supports=[
        fm.Support(0, "all"), fm.Support(1, ["ux", "uz", "rx", "ry"])])
    se = guyan(fe, [(1, ["uy"])])
    kf, mf = se.K[0, 0], se.M[0, 0]
    ch = chain(unit, 1, 0.2, 0.03, left=End.fixed())
    assert ch.n == 1  # the follower only
    system = mount_chain(ch, se, [1], "uy")
    M, _, C, _ = system.matrices(1.3)
    lam = sla.eigh(C, M, eigvals_only=True)
    a, bq, cq = mf * MASS, kf * MASS + STIFF * (mf + MASS), kf * STIFF
    root = np.sqrt(bq**2 - 4 * a * cq)
    # bound: eigh of a 2×2 pencil vs the quadratic formula: ~1e-15
    assert np.allclose(lam, [(bq - root) / (2 * a), (bq + root) / (2 * a)], rtol=1e-12)


def test_stiff_frame_tends_to_chain_alone(four):
    # A frame 100, 1000 and 10 000 times stiffer: the coupled branches approach the
    # chain-alone values (assembled eigh) with an error falling like 1/stiffness
    # (measured 2.8e-4, 2.2e-5, 2.1e-6 for the 8 lowest over 13 angles).
    ref = alone(four, PHI, 8)
    errors = []
    for factor in (1e2, 1e3, 1e4):
        se = craig_bampton(beam(210e9 * factor), "bearings", n_modes=10)
        result = sweep(mount_chain(four, se, BEARINGS, "uy"), PHI, n_modes=8, track=False)
        errors.append(np.abs(result.freq_hz / ref - 1).max())
    assert 0.05 < errors[1] / errors[0] < 0.2
    assert 0.05 < errors[2] / errors[1] < 0.2
    assert errors[2] < 1e-5


def test_soft_frame_reduced_matches_unreduced(four):
    # The real frame: its first modes (190, 237 Hz) lie among the chain's (100 … 1160 Hz)
    # and move the lowest branch from 100.0 to 95.4 Hz. Craig-Bampton (10 modes +
    # residual vectors) against the unreduced FE frame in the same coupling (sparse
    # shift-invert with Sturm check): they agree within the reduction's own error
    # estimate of the frame modes in the band (+ 1e-10 for the two solvers' round-off).
    fe = beam()
    se = craig_bampton(fe, "bearings", n_modes=10)
    reduced = mount_chain(four, se, BEARINGS, "uy")
    full = mount_chain(four, fe, BEARINGS, "uy")
    assert reduced.n == se.n_reduced + four.n
    assert full.n == fe.K_free.shape[0] + four.n
    lam, q = sla.eigh(se.K, se.M)
    band = np.sqrt(lam) / (2 * np.pi) < 2 * 1200.0
    estimate = frequency_error_estimates(fe, se, lam[band], q[:, band]).max()
    result = sweep(reduced, PHI, n_modes=8, track=False)
    assert result.freq_hz[0, 0] < 0.97 * alone(four, PHI[0], 1)[0, 0]  # the frame matters
    for a in (0, 3, 7):
        omega2, _ = full_modes(full, PHI[a], 8)
        f_full = np.sqrt(omega2.real) / (2 * np.pi)
        # bound: the estimate plus eigh round-off ~1e-13
        assert np.abs(result.freq_hz[a] / f_full - 1).max() <= estimate + 1e-10


def test_tracked_sweep_of_the_coupled_chain(four):
    # analysis.sweep on the CoupledSystem with MAC tracking: the same set of
    # frequencies as the untracked (sorted) sweep at every angle, and each branch
    # continuous from angle to angle (MAC with itself > 0.9).
    se = craig_bampton(beam(), "bearings", n_modes=10)
    system = mount_chain(four, se, BEARINGS, "uy")
    phi = np.linspace(0.0, 2 * np.pi, 73)
    tracked = sweep(system, phi, n_modes=6)
    plain = sweep(system, phi, n_modes=6, track=False)
    # bound: the same eigh per angle, only sorted: ~1e-15
    assert np.allclose(np.sort(tracked.freq_hz, axis=1), plain.freq_hz, rtol=1e-10)
    assert tracked.mac_step.min() > 0.9


def test_frame_loaded_by_follower_inertia(four):
    # F(φ) at speed: the frame row of unit u gets the follower's inertia force of the
    # programmed motion, -m (U'' Ω² + U' Ω̇) (the y row of the derivation above; the
    # process force is internal), projected by the attachment row: here node uy.
    fe = beam()
    system = mount_chain(four, fe, BEARINGS, "uy")
    speed, accel, phi = 20.0, 5.0, np.radians(20.0)  # every unit in a rise or return
    _, _, _, F = system.matrices(phi, speed, accel)
    expected = np.zeros(system.n_frame)
    for u, node in enumerate(BEARINGS):
        psi = phi + four.phase[u]
        force = -MASS * (cam()(psi, 2) * speed**2 + cam()(psi, 1) * accel)
        expected += force * frame_row(fe, node, "uy")
    assert np.count_nonzero(expected) == 4
    # bound: the same products in another order: a few ulps
    assert np.allclose(F[:system.n_frame], expected, rtol=1e-12, atol=0)


def test_clear_errors(four, unit):
    se = craig_bampton(beam(), "bearings", n_modes=4)
    with pytest.raises(ValueError, match="one frame node per unit"):
        mount_chain(four, se, BEARINGS[:3], "uy")
    with pytest.raises(ValueError, match="direction"):
        mount_chain(four, se, BEARINGS, ["uy", "uz"])
    other = guided_unit(follower_unit(cam(), J_HUB, 2 * MASS, STIFF))
    with pytest.raises(ValueError, match="not the chain's unit M"):
        mount_chain(four, se, BEARINGS, "uy", frame_unit=other)
    with pytest.raises(ValueError, match="plus one"):
        mount_chain(four, se, BEARINGS, "uy", frame_unit=unit)
    with pytest.raises(ValueError, match="already used"):
        guided_unit(unit, name="q2")


def test_multiplier_form_gives_the_same_quasi_modes(four):
    # couple(form="multiplier"): the frame coordinates y_u stay coordinates with
    # constraints y_u = L_u x_frame (QZ on the augmented pencil); same frequencies as the
    # primal form (measured 5e-10: QZ round-off on the augmented pencil, vs eigh's 1e-13)
    se = craig_bampton(beam(), "bearings", n_modes=10)
    primal = sweep(mount_chain(four, se, BEARINGS, "uy"), PHI[:4], n_modes=6, track=False)
    mixed = mount_chain(four, se, BEARINGS, "uy", form="multiplier")
    assert mixed.H.shape == (four.n_units, mixed.n)
    result = sweep(mixed, PHI[:4], n_modes=6, track=False)
    assert np.allclose(result.freq_hz, primal.freq_hz, rtol=1e-8, atol=0)
