"""Hard case 9: high mode counts and wide bands.

A pinned-pinned steel shaft (L = 10 m, d = 50 mm, Euler-Bernoulli: no shear, no rotary
inertia), one end held in torsion, n elements (6 n DOFs): bending in two equal planes
(pairs), axial and torsional modes interleave, so that 200 modes hold ~60 bending pairs,
~40 axial and ~60 torsional modes up to 5.4 kHz.

Reference (analytic): bending ``f_k = (kπ/L)² sqrt(EI/(ρA)) / 2π`` (pinned-pinned,
Blevins, Formulas for Natural Frequency and Mode Shape, table 8-1), twice; axial
(fixed-fixed) and torsion (fixed-free) in the exact discrete form of linear elements with
consistent mass, ``ω² = 6 c² / h² · (1 - cos θ) / (2 + cos θ)``, ``θ = k π h / L`` and
``(k - ½) π h / L``, ``c² = E/ρ`` or ``G/ρ`` (the FE solution of the wave equation on a
uniform mesh). The cubic bending elements converge as h⁴: at 1000 elements the 100th
bending mode is off by 2.6e-6 (measured).
"""

import numpy as np
import pytest
from hard_models import STEEL, line_mesh
from numpy.testing import assert_allclose

import femmech as fm
from femmech.analysis.modes import superelement_modes
from femmech.fe import sections
from femmech.reduction.component_modes import craig_bampton

LENGTH = 10.0
SHAFT = sections.circle(0.05)


def shaft(n, section=SHAFT):
    mesh = line_mesh(n, LENGTH, node_sets={"ends": [0, n], "root": [0], "mid": [n // 2]})
    prop = fm.BeamProperty(section, STEEL, shear=False, rotary_inertia=False)
    return fm.build_model(mesh, {"all": prop}, supports=[fm.Support("ends", "translations"),
                                                          fm.Support("root", ["rx"])])


def reference_hz(n, count, section=SHAFT):
    """The ``count`` lowest frequencies (Hz) of the n-element model (see module doc)."""
    E, rho, G = STEEL.E, STEEL.rho, STEEL.shear_modulus
    h = LENGTH / n
    k = np.arange(1, count + 1)
    bending = (k * np.pi / LENGTH) ** 2 * np.sqrt(E * section.Iy / (rho * section.A)) / (2 * np.pi)

    def discrete(c2, theta):
        return np.sqrt(6 * c2 / h**2 * (1 - np.cos(theta)) / (2 + np.cos(theta))) / (2 * np.pi)

    axial = discrete(E / rho, k * np.pi * h / LENGTH)
    torsion = discrete(G / rho, (k - 0.5) * np.pi * h / LENGTH)
    return np.sort(np.concatenate([bending, bending, axial, torsion]))[:count]


# Bending discretisation (h⁴, measured 2.6e-6 at the 100th bending mode, 1000 elements)
# and round-off: the bending stiffness of a fine beam mesh has condition ~(L/h)⁴ = 1e12,
# so any float64 solver resolves the lowest bending eigenvalue only to ~eps (L/h)⁴ λ₁/λ
# (measured for mode 1: 2e-6 ... 1.8e-5 in frequency for shifts from -1e2 to -1e9; with
# 2000 elements 1.4e-5 ... 2.6e-4, as scipy's own splu + eigsh give).
RTOL = 1e-5


def tolerance(freq_hz, n):
    """Per-mode relative tolerance (frequency): discretisation plus the round-off bound."""
    return RTOL + np.finfo(float).eps * n**4 * (freq_hz[0] / freq_hz) ** 2


@pytest.fixture(scope="module")
def model_1000():
    return shaft(1000)


def test_two_hundred_modes(model_1000):
    """Naive: ARPACK asked for 200 modes from one start vector misses members of the 100
    repeated bending pairs, or returns 199 because the count cuts a pair; without a
    Sturm check nobody notices. femmech completes the cut pair, and the Sturm count of
    K - σM at the last eigenvalue confirms that none below it is missing."""
    model = model_1000
    assert model.n_free == 5999
    result = fm.modes(model, n_modes=200)
    assert result.method in ("arpack", "block-lanczos")  # the sparse path
    assert result.n_modes in (200, 201)  # a pair cut at 200 is returned whole
    assert result.sturm_count == result.n_modes
    assert result.residual.max() < 1e-6  # measured 4.8e-7 (lowest modes: eps λ_max / λ)
    ref = reference_hz(1000, result.n_modes)
    # measured: 1.8e-5 for the lowest pair, below 2.6e-6 from the 3rd mode on
    assert np.all(np.abs(result.freq_hz / ref - 1) <= tolerance(ref, 1000))


def test_band_far_above_zero(model_1000):
    """All modes between the 150th and the 190th (2.9 ... 4.6 kHz), 150 modes above zero:
    the shift sits at the band centre, K - σM is indefinite (factorised with pivoting),
    and Sturm counts at both edges fix how many modes the band holds. Naive: a shift at
    zero reaches the band only after all 150 lower modes; an indefinite factorisation
    without pivoting loses accuracy; a band count without Sturm misses members."""
    ref = reference_hz(1000, 200)
    lo, hi = 0.5 * (ref[149] + ref[150]), 0.5 * (ref[189] + ref[190])
    assert ref[150] - ref[149] > 1.0
    assert ref[190] - ref[189] > 1.0
    result = fm.modes(model_1000, band_hz=(lo, hi))
    assert result.n_modes == 40
    assert result.sigma > (2 * np.pi * lo) ** 2  # shifted away from zero
    assert_allclose(result.freq_hz, ref[150:190], rtol=RTOL)  # measured 1.6e-6


def test_reduced_model_with_many_modes(model_1000):
    """Craig-Bampton with the mid node as interface and every fixed-interface mode below
    2 f_max (band search from 0 on the K_ii factorisation): the 80 lowest modes of the
    reduced model are upper bounds of the full ones and close to them."""
    ref = reference_hz(1000, 120)
    se = craig_bampton(model_1000, "mid", f_max_hz=ref[79])
    assert se.n_modal > 100
    result = superelement_modes(se, n_modes=80)
    err = result.freq_hz[:80] / ref[:80] - 1
    assert err.min() > -RTOL
    assert err.max() < 2e-3  # measured 7.4e-4 (the highest modes near f_max)


@pytest.mark.slow
def test_five_hundred_modes_of_a_23k_dof_frame():
    """Heavy variant (run with ``-m slow``): 500 modes of a 6 x 4 x 3 bay grid frame
    (23 082 free DOFs; members of 12 elements, so that no (L/h)⁴ conditioning limits the
    accuracy), against five band searches that cover the same range, each fixed by its own
    Sturm counts (an independent path: other shifts, indefinite factorisations)."""
    from hard_models import grid_model

    model = grid_model(bays=(6, 4, 3), size=(3.0, 2.0, 1.5), subdivisions=12)
    result = fm.modes(model, n_modes=500)
    assert result.sturm_count == result.n_modes
    f = result.freq_hz
    edges = [0.0] + [0.5 * (f[i - 1] + f[i]) for i in (100, 200, 300, 400)] + [f[-1] * 1.0001]
    bands = [fm.modes(model, band_hz=(lo, hi)).freq_hz for lo, hi in zip(edges[:-1], edges[1:],
                                                                        strict=True)]
    assert_allclose(np.concatenate(bands), f, rtol=1e-8)
