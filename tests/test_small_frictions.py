"""Small frictions: the residual warning names the mode and its
frequency; the count of n_modes includes rigid-body modes (docstrings and the report note);
the section shear coefficient's ν is documented where users set it."""

import warnings

import numpy as np
import pytest

import femmech as fm
from femmech.errors import FemmechWarning
from femmech.fe import generators, sections
from femmech.output.report import Table, render_table, rigid_modes_note
from femmech.solve import eigen
from femmech.solve.residuals import residual_message

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)


def test_residual_message_names_modes_and_frequencies_worst_first():
    omega2 = (2 * np.pi * np.array([0.0, 10.0, 20.0])) ** 2
    text = residual_message(np.array([1e-9, 3e-5, 2e-6]), np.full(3, 1e-6), omega2)
    assert text.startswith("eigen solve: mode 2 (f = 10 Hz): relative residual 3.00e-05"
                           " exceeds 1.0e-06; mode 3 (f = 20 Hz)")
    assert "mode 1 " not in text
    assert residual_message(np.array([1e-9]), np.array([1e-6]), omega2[:1]) is None
    many = residual_message(np.ones(8), np.full(8, 1e-6), np.arange(8.0))
    assert "and 3 more modes" in many


def test_eigen_solve_warns_with_the_mode_number(monkeypatch):
    mesh = generators.rectangular_plate(1.0, 1.0, 2, 2)
    model = fm.build_model(mesh, shells={"plate": fm.ShellProperty(0.01, STEEL)},
                           supports=[fm.Support("edges")])
    # every residual above a zero limit: the warning must list modes by number and f
    monkeypatch.setattr(eigen, "residual_limits", lambda K, X, den: np.zeros(X.shape[1]))
    with pytest.warns(FemmechWarning, match=r"eigen solve: mode \d+ \(f = [\d.e+]+ Hz\):"
                                            r" relative residual"):
        fm.modes(model, n_modes=2)


def test_n_modes_counts_rigid_body_modes_and_the_report_says_so():
    assert "rigid-body modes included" in fm.modes.__doc__
    assert "counts\n        rigid-body modes" in fm.analysis.modes.superelement_modes.__doc__
    mesh = generators.rectangular_plate(1.0, 0.5, 4, 2)
    model = fm.build_model(mesh, shells={"plate": fm.ShellProperty(0.01, STEEL)})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FemmechWarning)
        result = fm.modes(model, n_modes=8)
    assert result.n_modes == 8
    assert int(result.rigid.sum()) == 6  # free-free: 6 of the 8 requested modes are rigid
    note = rigid_modes_note(result.rigid)
    assert note == "n_modes counts rigid-body modes: 6 of the 8 modes are rigid (0 Hz)."
    assert rigid_modes_note([False, False]) == \
        "n_modes counts rigid-body modes: none of the 2 modes is rigid."
    assert rigid_modes_note([True, False]).endswith("1 of the 2 modes is rigid (0 Hz).")
    html = render_table(Table("Natural frequencies", ("mode",), ((1,),), note))
    assert html.endswith('</table><p class="note">' + note + "</p>")
    assert "note" not in render_table(Table("t", ("a",), ((1,),)))


def test_cowper_coefficients_stated_in_the_docstrings():
    # sections.py module notes: rectangle k = 0.833 / 0.850 / 0.857, circle 0.857 / 0.886 /
    # 0.900 for nu = 0 / 0.3 / 0.5 (Cowper 1966)
    k_rect = [sections.rectangle(1.0, 1.0, nu=nu).Asy for nu in (0.0, 0.3, 0.4999)]
    k_circ = [sections.circle(1.0, nu=nu).Asy / (np.pi / 4) for nu in (0.0, 0.3, 0.4999)]
    np.testing.assert_allclose(k_rect, [0.833, 0.850, 0.857], atol=6e-4)
    np.testing.assert_allclose(k_circ, [0.857, 0.886, 0.900], atol=6e-4)
    assert abs(k_circ[0] / k_circ[1] - 1) == pytest.approx(0.033, abs=5e-4)  # "3.3 %"
    for doc in (sections.__doc__, sections.rectangle.__doc__, sections.tube.__doc__):
        assert "nu=material.nu" in doc
    assert "5/6" in fm.ShellProperty.__doc__
    assert "Poisson" in fm.ShellProperty.__doc__
