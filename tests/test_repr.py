"""Short representations: a model, a superelement or a result in a notebook or log shows
what it is in one line, never its arrays."""

import numpy as np

import femmech as fm
from femmech.fe import sections
from femmech.reduction.component_modes import craig_bampton


def _cantilever():
    """A 2 m steel cantilever of 20 beam elements, circular 50 mm section."""
    x = np.linspace(0.0, 2.0, 21)
    beam = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(20), np.arange(1, 21)]),
                              node_sets={"root": [0], "tip": [20]})
    steel = fm.Material(E=210e9, nu=0.3, rho=7850.0)
    model = fm.build_model(beam, {"all": fm.BeamProperty(sections.circle(0.05), steel)},
                           supports=[fm.Support("root", dofs="all")])
    return beam, model


def test_reprs_are_one_line_summaries():
    beam, model = _cantilever()
    modes = fm.modes(model, n_modes=8)
    se = craig_bampton(model, ["tip"], n_modes=6, residual_vectors=True)
    expected = [
        (beam, "Mesh(21 nodes; 20 line; 1 cell sets, 2 node sets)"),
        (model, "FEModel(21 nodes, 20 line; 126 DOFs, 120 free;"),
        (modes, "ModeSet(8 modes: ["),
        (se, "Superelement(craig-bampton: 18 coordinates = 6 interface DOFs, 12 modal"
            " (6 residual vectors); full model 126 DOFs)"),
    ]
    for obj, start in expected:
        text = repr(obj)
        assert text.startswith(start), text
        assert "\n" not in text
        assert len(text) < 200
        assert "array(" not in text
    assert f"{modes.freq_hz[0]:.4g}" in repr(modes)


def _html_ok(obj, title: str) -> str:
    html = obj._repr_html_()
    assert html.startswith('<div class="femmech-repr"><strong>' + title), html[:120]
    assert "array(" not in html  # never the arrays
    assert "[[" not in html
    assert "<script" not in html
    return html


def test_html_reprs_are_small_tables():
    """Notebook views: a title, key facts and at most MAX_ROWS result rows."""
    from femmech.analysis.response import Response
    from femmech.analysis.stability import StabilityChart
    from femmech.analysis.sweep import Sweep
    from femmech.coupling import couple
    from femmech.html import MAX_ROWS

    beam, model = _cantilever()
    modes = fm.modes(model, n_modes=20)  # 21: the round beam's 20th/21st modes are a pair
    html = _html_ok(modes, f"ModeSet: {modes.n_modes} modes")
    assert f"{modes.freq_hz[0]:.6g}" in html
    assert f"… {modes.n_modes - MAX_ROWS} more" in html
    assert "Sturm count" in html
    se = craig_bampton(model, ["tip"], n_modes=6)
    _html_ok(couple(se, []), f"CoupledSystem: {se.n_reduced} coordinates")
    assert "node sets" in _html_ok(beam, "Mesh: 21 nodes")
    # total mass ρ A L = 7850 · π 0.025² · 2 = 30.82 kg (exact for the consistent mass)
    assert "30.8" in _html_ok(model, "FEModel: 21 nodes")
    assert "fixed-interface modes" in _html_ok(se, f"Superelement: {se.n_reduced} coordinates")

    phi = np.linspace(0.0, np.pi, 5)
    freq = np.column_stack([10.0 + phi, 20.0 + phi])
    sweep = Sweep(phi, freq, (2 * np.pi * freq) ** 2, np.zeros_like(freq), None,
                  np.ones_like(freq), "symmetric")
    assert "frozen-angle growth" in _html_ok(sweep, "Sweep: 2 branches")

    speeds = np.array([10.0, 20.0, 30.0])
    rho = np.array([[0.9, 1.2, 0.95]])
    chart = StabilityChart(speeds, None, rho, rho <= 1.0, 0.0,
                           converged=np.array([[True, True, False]]), rtol=1e-3)
    html = _html_ok(chart, "StabilityChart")
    assert "1 points NOT CONVERGED" in html
    assert "color: #b2182b" in html  # flagged

    t = np.linspace(0.0, 1.0, 11)
    q = np.zeros((11, 3))
    response = Response(t, q, q, q, t, error=0.2, converged=False, n_steps=64)
    assert "2.0e-01 NOT CONVERGED" in _html_ok(response, "Response")
