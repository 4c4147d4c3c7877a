"""Hard case 7: units and scaling.

The same machine in m-kg-s and in mm-t-s (mm, tonne, s: force N, stress MPa, density
t/mm³): a steel grid frame on six elastic mounts with a motor mass, reduced by
Craig-Bampton, carrying a cam mechanism on its top. A quantity of dimension M^a L^b T^c
converts by the factor ``1e-3^a · 1e3^b``; frequencies (T^-1) are the same numbers.

Changing units scales translational DOFs by 1e3 against rotational ones (matrix entries
by up to 1e6 relative to each other), so it also tests that no step of the solution
depends on the DOF scaling: shifts, thresholds and tolerances must be relative, never
absolute in some unit.
"""

import numpy as np
import pytest
import sympy
from numpy.testing import assert_allclose
from roundoff import EPS, largest_eigenvalue

import femmech as fm
from femmech.analysis.modes import superelement_modes
from femmech.analysis.sweep import sweep
from femmech.coupling import Attachment, Mount, couple
from femmech.fe import sections
from femmech.fe.generators import grid_frame
from femmech.mechanisms import (
    CamProfile,
    CamSegment,
    Mechanism,
    PointMass,
    RotaryInertia,
    Spring,
    polynomial_345,
    position_function,
    rheolinear,
)
from femmech.reduction.component_modes import craig_bampton

UNITS = {"m-kg-s": (1.0, 1.0), "mm-t-s": (1e3, 1e-3)}  # (length, mass) per SI unit


def convert(value, L, Mu, mass=0, length=0):
    """SI value of dimension M^mass L^length T^… in the unit system (L, Mu)."""
    return value * Mu**mass * L**length


def _cam():
    """Seed Table 5.1 case 1 with the guide y_g on the frame:
    x2 = y_g + U(θ + q1) + q2, 2T = J1 (θ' + q1')² + m2 x2'², 2V = c1 q1² + c2 q2²."""
    theta, q1, yg, q2 = sympy.symbols("theta q1 y_g q2")
    J1, m2, c1, c2 = sympy.symbols("J1 m2 c1 c2")
    x2 = yg + position_function("U")(theta + q1) + q2
    return Mechanism((q1, yg, q2, theta), (RotaryInertia(J1, theta + q1), PointMass(m2, (x2,)),
                                           Spring(c1, q1), Spring(c2, q2)), drives=(theta,))


def machine(units: str, subdivisions: int):
    """(FE model, reduced coupled system) of the machine in ``units``."""
    L, Mu = UNITS[units]
    c = lambda v, m=0, l=0: convert(v, L, Mu, m, l)  # noqa: E731
    mesh = grid_frame((2, 1, 1), (c(1.2, l=1), c(0.8, l=1), c(1.0, l=1)), subdivisions)
    steel = fm.Material(E=c(210e9, 1, -1), nu=0.3, rho=c(7850.0, 1, -3))
    prop = fm.BeamProperty(sections.rectangular_hollow(c(0.06, l=1), c(0.08, l=1),
                                                       c(0.004, l=1)), steel)
    mount = [c(2e6, 1)] * 3 + [c(5e4, 1, 2)] * 3  # N/m, N m/rad
    base = mesh.node_sets["base"]
    top = mesh.node_sets["top"]
    motor = fm.PointMass(int(top[1]), c(80.0, 1), [c(1.5, 1, 2), c(2.0, 1, 2), c(1.0, 1, 2)])
    model = fm.build_model(mesh, {name: prop for name in mesh.cell_sets}, masses=[motor],
                           springs=[fm.Spring(int(b), None, mount) for b in base])
    se = craig_bampton(model, "top", n_modes=10)
    cam = CamProfile((CamSegment(np.pi / 2, c(0.02, l=1), polynomial_345()),
                      CamSegment(np.pi / 2, 0.0),
                      CamSegment(np.pi / 2, -c(0.02, l=1), polynomial_345()),
                      CamSegment(np.pi / 2, 0.0)))
    params = {"J1": c(0.05, 1, 2), "m2": c(3.0, 1), "c1": c(2e4, 1, 2), "c2": c(5e5, 1)}
    mech = rheolinear(_cam(), params, {"U": cam})
    system = couple(se, [Mount(mech, (Attachment("y_g", int(top[4]), "uz"),), name="cam")])
    return model, se, system


# Round-off: each system computes with its own rounding of the same numbers (relative
# eps per entry); eigenvalues differ by ~eps λ_max absolute (tests/roundoff.py), so
# frequencies by ~eps λ_max / (2 λ_1) relative at most, the full model's scale bounding the
# reduced and coupled ones (Ritz values lie inside the full spectrum): units_rtol, 3.5e-10
# (2 subdivisions) and 1.5e-9 (4; the former fixed 1e-10 lay below both). Measured in
# frequency: full 1.8e-13 (dense) and 1.5e-12 (ARPACK), reduced 2.3e-13 / 7.4e-13,
# coupled sweep 2.1e-13 / 5.6e-13. Before this issue the reduced models differed by
# 1.1e-4: the residual vectors' drop test of craig_bampton summed M-norms of translational
# and rotational columns (36 vectors kept in m-kg-s, 26 in mm-t-s).


def units_rtol(model, full) -> float:
    """Relative frequency round-off, 10 eps λ_max / (2 λ_1), of the SI model."""
    return 5 * EPS * largest_eigenvalue(model.K_free, model.M_free) / full.omega2[0]


@pytest.mark.parametrize(("subdivisions", "method"), [(2, "dense"), (4, "arpack")])
def test_same_machine_in_two_unit_systems(subdivisions, method):
    """Naive: an absolute tolerance or shift (a rigid-body threshold of 1e-6 rad²/s², a
    shift of -1, 'stiffness below 1e-3 is zero') means different things in N/m and N/mm
    and changes results with the units; ARPACK started from the same random vector in
    differently scaled coordinates must still converge to the same pairs. femmech's
    shifts and thresholds are relative to the pencil's own scale."""
    results, models = {}, {}
    for units in UNITS:
        model, se, system = machine(units, subdivisions)
        models[units] = model
        full = fm.modes(model, n_modes=12)
        assert full.method == method
        reduced = superelement_modes(se, n_modes=12)
        coupled = sweep(system, np.linspace(0.0, 2 * np.pi, 13), n_modes=8)
        results[units] = (full, reduced, coupled)
    (f1, r1, c1), (f2, r2, c2) = results.values()
    rtol = units_rtol(models["m-kg-s"], f1)
    assert_allclose(f2.freq_hz, f1.freq_hz, rtol=rtol)
    assert f2.sturm_count == f1.sturm_count
    assert f1.residual.max() < 1e-8
    assert f2.residual.max() < 1e-8
    assert_allclose(r2.freq_hz, r1.freq_hz, rtol=rtol)
    assert_allclose(c2.freq_hz, c1.freq_hz, rtol=rtol)
    # bound: MAC of the same branches from two unit systems: round-off ~eps cond, measured 5e-14
    assert_allclose(c2.mac_step, c1.mac_step, atol=1e-9)  # same branches: measured 5e-14
    # mode shapes: u_mm = D u_SI (D: 1e3 on translations, 1 on rotations) and
    # M_mm = Mu L² D⁻¹ M_SI D⁻¹, so mass-normalised shapes map as φ_SI = L √Mu D⁻¹ φ_mm
    L, Mu = UNITS["mm-t-s"]
    scale = np.tile([1 / L] * 3 + [1.0] * 3, f1.shapes.shape[0] // 6) * L * np.sqrt(Mu)
    si = f2.shapes * scale[:, None]
    model = machine("m-kg-s", subdivisions)[0]
    mac = np.abs(np.einsum("ij,ij->j", si, model.M @ f1.shapes))
    assert_allclose(mac[:6], 1.0, rtol=1e-8)  # distinct modes: measured 1 - 1e-15
