"""Mode-type labels from energy fractions (femmech.analysis.mode_types), on modes whose
kind is known analytically: a clamped-free bar, a free-free frame, a frame on springs."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

import femmech as fm
from femmech.analysis.mode_types import (
    KINDS,
    classify_mode,
    dominant_axis,
    kinetic_fractions,
    mode_types,
    rigid_motion_fractions,
)
from femmech.fe import sections

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)
LENGTH, WIDTH, HEIGHT = 0.5, 0.02, 0.04  # m: width along local y (= global y), height along z


def _bar(n_el=20, supports=True):
    """Euler-Bernoulli bar along x (no shear, no rotary inertia), clamped at x = 0."""
    x = np.linspace(0.0, LENGTH, n_el + 1)
    mesh = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(n_el), np.arange(1, n_el + 1)]),
                              node_sets={"root": [0]})
    prop = fm.BeamProperty(sections.rectangle(WIDTH, HEIGHT), STEEL, shear=False,
                           rotary_inertia=False)
    return fm.build_model(mesh, {"all": prop},
                          supports=[fm.Support("root")] if supports else [])


def _analytic_cantilever():
    """First frequencies (Hz) of a clamped-free bar by kind, with their expected labels.

    Bending (Blevins, Formulas for Natural Frequency and Mode Shape, table 8-1,
    clamped-free): f = λ² / (2π L²) √(E I / (ρ A)), λ₁ = 1.87510407. Torsion and axial
    (Blevins table 8-19 and 8-16, fixed-free rod/shaft): f = √(G J / (ρ I_p)) / (4 L) and
    f = √(E / ρ) / (4 L), with the section's St Venant constant J and polar moment I_p.
    """
    sec = sections.rectangle(WIDTH, HEIGHT)
    rho, E, G = STEEL.rho, STEEL.E, STEEL.shear_modulus
    bend = lambda inertia: 1.87510407**2 / (2 * np.pi * LENGTH**2) * np.sqrt(  # noqa: E731
        E * inertia / (rho * sec.A))
    ip = sec.Ip if sec.Ip is not None else sec.Iy + sec.Iz
    return {
        # weak plane: bending about z (Iz = h w³ / 12), deflection along y
        "bending about z, moving in y": bend(sec.Iz),
        "bending about y, moving in z": bend(sec.Iy),
        "torsion about x": np.sqrt(G * sec.J / (rho * ip)) / (4 * LENGTH),
        "axial x": np.sqrt(E / rho) / (4 * LENGTH),
    }


def test_cantilever_modes_are_labelled_by_their_kind():
    model = _bar()
    result = fm.modes(model, n_modes=12)
    types = mode_types(model, result.shapes, result.rigid)
    for label, f in _analytic_cantilever().items():
        k = int(np.argmin(np.abs(result.freq_hz - f)))
        # 20 cubic elements: bending within 1e-5, linear axial and torsion elements within
        # (π/2 / 20)² / 24 ~ 3e-4 of the analytic frequency; 1 % tells the modes apart
        assert result.freq_hz[k] == pytest.approx(f, rel=1e-2), label
        assert types[k].label == label
    # the energy splits exactly (decoupled local stiffness): one part holds everything,
    # bound: up to the eigenvector's round-off
    weak = types[int(np.argmin(np.abs(result.freq_hz
                                      - _analytic_cantilever()["bending about z, moving in y"])))]
    assert_allclose(weak.strain, [0, 0, 0, 1, 0], atol=1e-9)
    assert weak.axis == "z"
    assert weak.kinetic[1] > 0.9  # uy carries the kinetic energy (rz the rest)
    # bound: energy fractions sum to 1 by construction: ~n eps
    assert_allclose(weak.kinetic.sum(), 1.0, rtol=1e-12)


def test_free_free_frame_rigid_modes_and_first_elastic_mode():
    # an L-shaped frame without supports or springs: six zero-frequency modes
    points = np.array([[0, 0, 0], [0.5, 0, 0], [1, 0, 0], [1, 0.5, 0], [1, 1, 0]], dtype=float)
    mesh = fm.Mesh.from_lines(points, [[0, 1], [1, 2], [2, 3], [3, 4]])
    model = fm.build_model(mesh, {"all": fm.BeamProperty(sections.circle(0.03), STEEL)})
    result = fm.modes(model, n_modes=8)
    assert result.rigid.sum() == 6
    types = mode_types(model, result.shapes, result.rigid)
    assert [t.label for t in types[:6]] == ["rigid body"] * 6
    assert not types[6].label.startswith("rigid")
    # a rigid-body mode stores (almost) no strain energy compared with an elastic one of
    # the same mass normalisation: ω² = 2 U / (φᵀ M φ) with φᵀ M φ = 1
    U = [0.5 * s @ (model.K @ s) for s in result.shapes.T]
    assert max(U[:6]) < 1e-6 * U[6]


def test_frame_on_soft_springs_moves_as_a_rigid_body():
    # the cantilever bar without its clamp, on four soft springs: the six lowest modes
    # are the bar moving rigidly on them (spring stiffness 1e3 N/m vs bar bending ~1e5)
    model0 = _bar(n_el=8, supports=False)
    springs = [fm.Spring(n, None, [1e3, 1e3, 1e3, 1.0, 1.0, 1.0]) for n in (0, 8)]
    model = fm.build_model(model0.mesh, {"all": fm.BeamProperty(
        sections.rectangle(WIDTH, HEIGHT), STEEL, shear=False, rotary_inertia=False)},
        springs=springs)
    result = fm.modes(model, n_modes=7)
    types = mode_types(model, result.shapes, result.rigid)
    assert all(t.label.startswith("rigid body on springs") for t in types[:6])
    assert all(t.strain[KINDS.index("springs")] > 0.99 for t in types[:6])
    translations = [t.label for t in types[:6] if t.label.endswith("translation x")]
    assert translations  # the axial rigid mode: the whole bar along x on its springs
    k = types.index(next(t for t in types if t.label.endswith("translation x")))
    assert rigid_motion_fractions(model, result.shapes[:, k])[0] > 0.99


def test_pure_parts():
    # kinetic fractions of a unit translation in y of a lumped model: all uy
    M = np.diag([2.0, 2.0, 2.0, 0.1, 0.1, 0.1] * 2)
    u = np.array([0, 1, 0, 0, 0, 0] * 2, dtype=float)
    assert_allclose(kinetic_fractions(M, u), [0, 1, 0, 0, 0, 0])
    assert_allclose(kinetic_fractions(M, np.zeros(12)), np.zeros(6))
    # axes: energy along a skew direction has no global axis; along z it has
    assert dominant_axis(np.array([1.0, 1.0]), np.array([[0, 0, 1.0], [0, 0, -1.0]])) == "z"
    skew = np.array([[1.0, 1.0, 0.0]]) / np.sqrt(2)
    assert dominant_axis(np.array([1.0]), skew) == "skew"  # 45° from x and y
    assert dominant_axis(np.array([1.0, 1.0]), np.eye(3)[:2]) == "several"  # 50 % each
    assert dominant_axis(np.zeros(1), skew) is None


def test_mixed_label_and_errors():
    model = _bar(n_el=4)
    result = fm.modes(model, n_modes=8)
    assert not classify_mode(model, result.shapes[:, 0]).label.startswith("mixed")
    # equal strain energy in two kinds (torsion and bending modes, scaled): mixed
    types = mode_types(model, result.shapes)
    bend = next(k for k, t in enumerate(types) if t.label.startswith("bending"))
    tors = next(k for k, t in enumerate(types) if t.label.startswith("torsion"))
    w = result.freq_hz[[bend, tors]] * 2 * np.pi  # mass-normalised: U = ω² / 2
    mixed = classify_mode(model, result.shapes[:, bend] / w[0] + result.shapes[:, tors] / w[1])
    assert mixed.label.startswith("mixed: ")
    assert "bending 50 %" in mixed.label
    assert "torsion 50 %" in mixed.label
    with pytest.raises(ValueError, match="entries"):
        classify_mode(model, np.zeros(5))
