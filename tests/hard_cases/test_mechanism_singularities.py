"""Hard case 5: mechanism singularities.

Dead centres of a slider-crank (U' = 0) and a four-bar near its toggle position
(transmission angle near 0), and the crane's luffing cylinder near its stroke limits.
Each is either handled (finite, correct results) or rejected with an explanation; a NaN
never reaches a result.
"""

import numpy as np
import pytest
from hard_models import STEEL, line_mesh
from numpy.testing import assert_allclose

import femmech as fm
from femmech.analysis.reference import full_modes
from femmech.analysis.sweep import sweep
from femmech.coupling import Attachment, Mount, couple
from femmech.fe import sections
from femmech.mechanisms import (
    FourBar,
    Mechanism,
    RotaryInertia,
    SliderCrank,
    Spring,
    mobile_crane,
    mobile_crane_parameters,
    position_function,
    quasi_modes,
    rheolinear,
)
from femmech.mechanisms.mounted import slider_crank
from femmech.reduction.component_modes import craig_bampton

PRESS = {"J1": 1.5, "m2": 150.0, "c1": 1e6, "c2": 1e9, "b1": 0.0, "b2": 0.0, "F2": 0.0,
         "r": 0.05, "l": 0.35, "e": 0.0}  # kg m², kg, N m/rad, N/m, ..., m
F_CRANK = np.sqrt(PRESS["c1"] / PRESS["J1"]) / (2 * np.pi)  # 129.95 Hz


def _portal():
    """Portal frame in the x-z plane: columns at x = 0 and 0.6 m (1 m high, clamped feet),
    top beam; 0.1 m elements, 100 x 100 x 8 mm tubes. Node sets: crank (top middle),
    guide (left column, mid-height)."""
    corners = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.6, 0.0, 1.0], [0.6, 0.0, 0.0]])
    points, lines = [corners[:1]], []
    for a, b, k in ((0, 1, 10), (1, 2, 6), (2, 3, 10)):
        t = np.arange(1, k + 1)[:, None] / k
        points.append(corners[a] + t * (corners[b] - corners[a]))
    points = np.vstack(points)
    lines = np.column_stack([np.arange(len(points) - 1), np.arange(1, len(points))])
    mesh = fm.Mesh.from_lines(points, lines, node_sets={
        "feet": [0, len(points) - 1], "crank": [13], "guide": [5]})
    prop = fm.BeamProperty(sections.rectangular_hollow(0.1, 0.1, 0.008), STEEL)
    return fm.build_model(mesh, {"all": prop}, supports=[fm.Support("feet")])


def _press_mount(crank, guide):
    model = rheolinear(slider_crank(), PRESS)
    down = (0.0, 0.0, -1.0, 0.0, 0.0, 0.0)
    return Mount(model, (Attachment("u_b", crank, down), Attachment("v_b", crank, "ux"),
                         Attachment("v_g", guide, "ux")), name="press")


def test_slider_crank_dead_centres_on_an_elastic_frame():
    """At the dead centres (φ = 0, π; U' = 0 for e = 0) the ram decouples from the crank:
    ``x = u_b + r cos ψ + √(l² - (r sin ψ - v_g + v_b)²)`` has ∂x/∂ψ = 0, so the crank
    twist q_t is a mode of its own at sqrt(c1/J1)/2π = 129.95 Hz exactly, however the
    frame moves (analytic). Naive: a model in the ram coordinate (reduced inertia
    J/U'² → ∞) divides by zero there; femmech's crank coordinate keeps M(φ) regular.
    Full model, reduced model and the sweep through both dead centres."""
    fe = _portal()
    crank, guide = (int(fe.mesh.node_sets[n][0]) for n in ("crank", "guide"))
    se = craig_bampton(fe, [(crank, ["ux", "uz"]), (guide, ["ux"])], n_modes=12)
    reduced = couple(se, [_press_mount(crank, guide)])
    phi = np.linspace(0.0, 2 * np.pi, 49)  # includes 0, π and 2π exactly
    result = sweep(reduced, phi, n_modes=6)
    for arr in (result.freq_hz, result.eigenvalues, result.damping_ratio, result.mac_step):
        assert np.isfinite(arr).all()
    assert not result.unstable.any()
    for a in (0, 24, 48):
        # bound: the crank branch at the dead centres: dense LAPACK round-off (measured 4e-16)
        assert np.abs(result.freq_hz[a] / F_CRANK - 1).min() < 1e-10
    # elsewhere the crank couples to the ram and the frame: its branch moves away
    assert np.abs(result.freq_hz[12] / F_CRANK - 1).min() > 1e-3
    full = couple(fe, [_press_mount("crank", "guide")])
    for angle in (0.0, np.pi):
        lam, _ = full_modes(full, angle, 6)
        f_full = np.sqrt(lam.real) / (2 * np.pi)
        # bound: dense LAPACK of a 152-DOF pencil: eps λ_max/λ (roundoff.py), measured 2e-16
        assert np.abs(f_full / F_CRANK - 1).min() < 1e-9  # full model (152): measured 2e-16
        a = int(round(angle / (2 * np.pi) * 48))
        # CB (12 modes + residual vectors) vs full: measured 4e-9
        assert_allclose(np.sort(result.freq_hz[a]), f_full, rtol=1e-6)


def test_slider_crank_geometry_that_cannot_turn_is_rejected():
    """A crank that cannot turn (l <= r + |e|) would give √(negative) = NaN positions; it
    is rejected when built, with the condition in the message."""
    with pytest.raises(ValueError, match=r"must exceed r \+ \|e\|"):
        SliderCrank(0.05, 0.06, 0.02)


# --- four-bar near the toggle position ----------------------------------------------------

def _rocker():
    """Crank (twist q1, stiffness c1, inertia J1) drives a rocker (inertia J2) through
    the four-bar U; the rocker's bearing turns with the frame (r_f: frame rotation rz)
    and the rocker arm is elastic (q2, c2): ψ = r_f + U(θ + q1) + q2."""
    import sympy

    theta, q1, rf, q2 = sympy.symbols("theta q1 r_f q2")
    J1, J2, c1, c2 = sympy.symbols("J1 J2 c1 c2")
    psi = rf + position_function("U")(theta + q1) + q2
    return Mechanism((q1, rf, q2, theta), (RotaryInertia(J1, theta + q1), RotaryInertia(J2, psi),
                                           Spring(c1, q1), Spring(c2, q2)),
                     drives=(theta,), name="four-bar rocker")


ROCKER = {"J1": 0.05, "J2": 0.2, "c1": 2e4, "c2": 5e4}  # kg m², N m/rad


@pytest.mark.parametrize("margin", [1e-2, 1e-6])
def test_four_bar_near_toggle_stays_finite(margin):
    """Four-bar a = 1, b = 2.5, c = 1.5 + margin, d = 3 (m): at φ = π the coupler and the
    rocker are nearly collinear (transmission angle ~1.46 √margin rad). U' stays bounded
    (0.81) but U'' ~ 1/√margin and U''' ~ 1/margin: the speed terms of C(φ, Ω) become
    large. Naive: finite differences of U lose all digits there, and the eigen solver
    meets a nearly singular or indefinite C. femmech's exact loop-closure derivatives
    stay finite; the coupled sweep at speed returns finite values and flags any branch
    whose frozen-angle stiffness is negative (divergence) instead of returning NaN."""
    U = FourBar(1.0, 2.5, 1.5 + margin, 3.0)
    phi = np.linspace(0.0, 2 * np.pi, 2001)
    derivs = np.array(U.derivatives(phi))
    assert np.isfinite(derivs).all()
    theta, psi = U.angles(phi)
    assert np.abs(np.sin(psi - theta)).min() < 1.5 * np.sqrt(margin)  # toggle reached
    # exact U'' against central differences of the exact U' near the toggle (FD error)
    p0, h = np.pi + 1e-3, 1e-7
    assert_allclose(U(p0, 2), (U(p0 + h, 1) - U(p0 - h, 1)) / (2 * h), rtol=1e-5)
    fe = fm.build_model(line_mesh(20, 1.0, node_sets={"ends": [0, 20]}),
                        {"all": fm.BeamProperty(sections.rectangular_hollow(0.06, 0.08, 0.004),
                                                STEEL)},
                        supports=[fm.Support("ends", "translations"), fm.Support(0, ["rx"])])
    model = rheolinear(_rocker(), ROCKER, {"U": U})
    system = couple(craig_bampton(fe, [(6, ["rz"])], n_modes=8),
                    [Mount(model, (Attachment("r_f", 6, "rz"),), name="rocker")])
    angles = np.linspace(np.pi - 0.05, np.pi + 0.05, 21)  # through the toggle
    for Omega in (0.0, 20.0):
        result = sweep(system, angles, Omega=Omega, n_modes=4)
        for arr in (result.freq_hz, result.eigenvalues, result.damping_ratio):
            assert np.isfinite(arr).all()
        # a branch without positive real stiffness is flagged, not given a NaN frequency
        lam = result.eigenvalues
        # bound: eigenvalues real to round-off eps|λ| of dense QZ: 1e-9 |λ| flags only true complex
        # pairs
        assert np.all(result.unstable[(lam.real < 0) | (np.abs(lam.imag) > 1e-9 * abs(lam))])
    assert result.form == "unsymmetric"
    # measured: margin 1e-6 at Ω = 20 rad/s gives 3 (angle, branch) pairs with λ < 0 next
    # to the toggle (the Ω² U''' terms), margin 1e-2 none
    assert result.unstable.any() == (margin < 1e-3)


def test_four_bar_at_the_toggle_is_rejected_with_the_reason():
    """At margin 0 the crank cannot pass the toggle (U' infinite, the position not
    defined beyond): rejected when built, with the Grashof-type condition."""
    with pytest.raises(ValueError, match="cannot turn fully without a dead centre"):
        FourBar(1.0, 2.5, 1.5, 3.0)


# --- crane luffing cylinder near its stroke limits ----------------------------------------

def test_crane_cylinder_near_stroke_limits():
    """The crane's boom angle is φ3 = arccos((s² - r24² - r34²) / (2 r24 r34)) + γ of the
    cylinder length s; with r24 = 1.5 m, r34 = 4 m the stroke is (2.5, 5.5) m. Inside it,
    even 1e-9 m from the ends, the quasi-modes are finite. At or beyond the ends arccos
    is undefined or its derivative infinite: before this issue numpy warned and scipy
    failed deep inside ('array must not contain infs or NaNs'); now a ValueError names
    the mechanism, the matrix and the drive position."""
    model = rheolinear(mobile_crane(), mobile_crane_parameters())
    inside = np.array([2.5 + 1e-9, 2.6, 4.0, 5.4, 5.5 - 1e-9])
    for Omega in (0.0, 0.05):  # m/s cylinder speed: the speed terms carry dφ3/ds
        result = quasi_modes(model, inside, Omega=Omega)
        assert np.isfinite(result.omega_sq).all()
    for s in (2.4, 2.5, 5.5, 5.6):
        with pytest.raises(ValueError, match=rf"'mobile crane': [MC] is not finite at drive"
                                             rf" position \[?{s}"):
            quasi_modes(model, [4.0, s], Omega=0.05)
