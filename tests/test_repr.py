"""Short representations: a model, a superelement or a result in a notebook or log shows
what it is in one line, never its arrays."""

import numpy as np

import femmech as fm
from femmech.fe import sections
from femmech.reduction.component_modes import craig_bampton


def test_reprs_are_one_line_summaries():
    x = np.linspace(0.0, 2.0, 21)
    beam = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(20), np.arange(1, 21)]),
                              node_sets={"root": [0], "tip": [20]})
    steel = fm.Material(E=210e9, nu=0.3, rho=7850.0)
    model = fm.build_model(beam, {"all": fm.BeamProperty(sections.circle(0.05), steel)},
                           supports=[fm.Support("root", dofs="all")])
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
