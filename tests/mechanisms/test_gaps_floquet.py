"""``coupled_floquet`` on an undamped frame.

The cam of Table 5.1 case 1 on the simply supported beam of tests/test_stability.py,
without frame damping. Why ρ = 1.000 came out: 15 of the 20 coupled quasi-modes (the
beam's modes that no mechanism damper moves, 237 Hz … 13.6 kHz) are undamped, and each
has Floquet multipliers on the unit circle, so max |μ| = 1 whatever the damped cam
motion does; what is left is the integration error of those stiff modes, measured
ρ = 1 + 2.8e-6 at Ω = 5 rad/s — above 1 + tol (1e-6), a spurious "unstable" verdict —
and 1 + 2.9e-7 at 30 rad/s. coupled_floquet now refuses such a system unless a basis
is given or ``allow_undamped=True``.
"""

import dataclasses

import numpy as np
import pytest
from models import cam_with_dampers_on_beam

from femmech.analysis.floquet import coupled_floquet, coupled_monodromy, floquet
from femmech.analysis.response import rayleigh_damping


@pytest.fixture(scope="module")
def undamped_frame():
    """The damped cam (dampers 2 N m s/rad and 80 N s/m) on the undamped beam."""
    return cam_with_dampers_on_beam()


def test_undamped_frame_is_refused_with_the_reason(undamped_frame):
    with pytest.raises(ValueError, match=r"15 quasi-mode\(s\) of the system are undamped"
                                         r" \(at phi = 0: 237.3, .*rayleigh_damping"):
        coupled_floquet(undamped_frame, 5.0)


def test_allow_undamped_gives_the_conservative_radius(undamped_frame):
    # the old result: ρ = 1 within the integration error of the undamped modes
    result = coupled_floquet(undamped_frame, 30.0, allow_undamped=True)
    assert abs(result.spectral_radius - 1.0) < 1e-5
    assert np.sum(np.abs(np.abs(result.multipliers) - 1.0) < 1e-5) >= 30  # 15 pairs


def test_damped_frame_result_is_unchanged(undamped_frame):
    # the check does not alter a damped machine's numbers: same as the path without it
    damped = rayleigh_damping(undamped_frame, 1.0, 1e-5)
    result = coupled_floquet(damped, 30.0)
    record = coupled_monodromy(damped, 30.0, full_output=True)
    expected = floquet(record, 2 * np.pi / 30.0)
    assert result.spectral_radius == expected.spectral_radius
    assert np.array_equal(result.multipliers, expected.multipliers)
    assert result.stable
    assert result.spectral_radius < 0.9


def test_a_basis_is_the_users_choice(undamped_frame):
    # with a basis the projected system is the user's responsibility: no refusal
    # (any basis; here the first three global coordinates)
    n = undamped_frame.n
    basis = np.eye(n)[:, :3]
    result = coupled_floquet(undamped_frame, 30.0, basis=basis)
    assert result.monodromy.shape == (6, 6)
    with pytest.raises(ValueError, match="undamped"):
        coupled_floquet(dataclasses.replace(undamped_frame), 30.0)
