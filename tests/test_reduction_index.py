"""Whether a reduced mode is the full model's mode of the same number (Sturm counts).

The residual estimate of a superelement's modes measures the distance to *some* full
eigenpair; a full mode that the reduction misses shifts the numbering of every reduced
mode above it while the estimates stay small. References: dense ``scipy.linalg.eigh`` of
the full ``K_free, M_free`` (independent of the reduction and of the counts).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

import femmech as fm
from femmech.analysis.modes import superelement_modes
from femmech.errors import ModelWarning
from femmech.fe.generators import rectangular_plate
from femmech.reduction.component_modes import craig_bampton
from femmech.reduction.estimate import INDEX_RTOL, INDEX_SAFETY, confirmed_indices
from femmech.solve.sturm import confirm_indices

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)


@pytest.fixture(scope="module")
def plate():
    """Cantilever steel plate 1 m x 0.8 m x 10 mm, 4 x 4 MITC4 (120 free DOFs), clamped
    at x = 0; its dense eigenfrequencies (Hz) as the reference."""
    mesh = rectangular_plate(1.0, 0.8, 4, 4)
    model = fm.build_model(mesh, shells={"plate": fm.ShellProperty(0.01, STEEL)},
                           supports=[fm.Support("edge_x0")])
    lam = sla.eigh(model.K_free.toarray(), model.M_free.toarray(), eigvals_only=True)
    return model, np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi)


def _truth(reduced, f_full):
    """Whether the dense full mode k lies in reduced mode k's interval (the definition)."""
    w = np.maximum(INDEX_SAFETY * np.abs(reduced.error_estimate), INDEX_RTOL)
    return f_full[:reduced.n_modes] >= reduced.freq_hz / (1.0 + w)


def test_a_missed_full_mode_is_flagged(plate):
    """1 fixed-interface mode + residual vectors at two free-edge nodes: reduced mode 10
    is 27 % above full mode 10 (dense: 493.95 against 389.02 Hz) with an estimate of
    5.5e-6 (it is full mode 12); the count flags it, and the flags are exactly the modes
    whose full counterpart lies outside the interval."""
    model, f_full = plate
    se = craig_bampton(model, [4, 24], n_modes=1)
    with pytest.warns(ModelWarning, match=r"reduced mode\(s\) .*10 \(493"):
        reduced = superelement_modes(se, n_modes=12, model=model)
    with pytest.warns(ModelWarning, match=r"reduced mode\(s\) .*10 \(493"):
        each = superelement_modes(se, n_modes=12, model=model, index_check="each")
    np.testing.assert_array_equal(each.index_confirmed, reduced.index_confirmed)
    assert reduced.freq_hz[9] > 1.2 * f_full[9]
    assert abs(reduced.error_estimate[9]) < 1e-4  # the estimate alone does not see it
    assert not reduced.index_confirmed[9]
    np.testing.assert_array_equal(reduced.index_confirmed, _truth(reduced, f_full))
    assert reduced.n_unconfirmed == np.count_nonzero(~_truth(reduced, f_full)) >= 1
    assert "UNCONFIRMED" in reduced._repr_html_()


def test_an_accurate_reduction_is_confirmed(plate):
    """12 fixed-interface modes: all 12 modes within 1e-5 of the dense reference and
    confirmed, without a warning; index_check=False leaves the field unset."""
    model, f_full = plate
    se = craig_bampton(model, [4, 24], n_modes=12)
    reduced = superelement_modes(se, n_modes=12, model=model)
    assert np.all(reduced.freq_hz / f_full[:12] - 1 < 1e-5)
    assert reduced.index_confirmed.all()
    assert reduced.n_unconfirmed == 0
    assert superelement_modes(se, n_modes=12, model=model,
                              index_check=False).index_confirmed is None
    # one count above mode 12 finds 12 full eigenvalues: it decides all 12 modes
    ok, n_counts = confirmed_indices(model, reduced.omega2, reduced.error_estimate)
    assert ok.all()
    assert n_counts == 1
    ok, n_counts = confirmed_indices(model, reduced.omega2, reduced.error_estimate, each=True)
    assert ok.all()
    assert n_counts == 12
    assert superelement_modes(se, n_modes=12).index_confirmed is None


def test_a_band_counts_from_its_first_mode(plate):
    """A band above 0 numbers its modes after the reduced modes below it: the flags are
    those of the same modes computed from the lowest."""
    model, _ = plate
    se = craig_bampton(model, [4, 24], n_modes=1)
    with pytest.warns(ModelWarning):
        lowest = superelement_modes(se, n_modes=12, model=model)
    band = (0.5 * (lowest.freq_hz[2] + lowest.freq_hz[3]),
            0.5 * (lowest.freq_hz[10] + lowest.freq_hz[11]))
    with pytest.warns(ModelWarning, match=r"10 \(493"):
        part = superelement_modes(se, band_hz=band, model=model)
    assert part.n_modes == 8
    np.testing.assert_array_equal(part.index_confirmed, lowest.index_confirmed[3:11])


def test_confirm_indices_on_a_known_spectrum():
    """K = diag(1 ... 6), M = I: eigenvalue k is k. An approximation of 3.5 claimed as
    number 3 with the interval [3.4, 3.5] is not confirmed (3 eigenvalues below 3.4);
    [2.9, 3.5] is; the intervals of a double eigenvalue share one count; lower <= 0
    needs none."""
    K, M = sp.diags(np.arange(1.0, 7.0)).tocsc(), sp.identity(6, format="csc")
    ok, n = confirm_indices(K, M, [0.95, 1.95, 3.4], [1.0, 2.0, 3.5], [1, 2, 3])
    np.testing.assert_array_equal(ok, [True, True, False])
    assert n == 3
    ok, n = confirm_indices(K, M, [0.95, 1.95, 2.9], [1.0, 2.0, 3.5], [1, 2, 3])
    np.testing.assert_array_equal(ok, [True, True, True])
    assert n == 3
    double = sp.diags([1.0, 2.0, 2.0, 4.0]).tocsc()
    ok, n = confirm_indices(double, sp.identity(4, format="csc"), [0.9, 1.9, 1.95],
                            [1.0, 2.0, 2.0], [1, 2, 3])
    assert ok.all()
    assert n == 2
    ok, n = confirm_indices(K, M, [-np.inf, 0.0], [0.0, 0.0], [1, 2])
    assert ok.all()
    assert n == 0


PLATE_SCENE = """
[scene]
name = "cantilever plate"

[materials.steel]
E = 210e9
nu = 0.3
rho = 7850.0

[parts.plate.generator]
kind = "rectangular_plate"
a = 1.0
b = 0.8
divisions = [4, 4]

[parts.plate.shells.plate]
thickness = 0.01
material = "steel"

[[parts.plate.supports]]
nodes = "edge_x0"

[parts.plate.reduction]
method = "craig_bampton"
n_modes = 1
interface = [{ nodes = [4, 24] }]

[analyses.modes]
n_modes = 12
model = "reduced"
images = 0
vtu = true  # builds the full model: the table then has the estimate and the index
"""


def test_the_scene_marks_unconfirmed_modes(plate, tmp_path):
    """The scene's reduced modes table marks the modes of the case above as unconfirmed
    (in the HTML report and results), and the reductions table says so."""
    import tomllib

    from femmech.scene.load import Scene
    from femmech.scene.run import run_scene

    scene = Scene.from_dict(tomllib.loads(PLATE_SCENE), tmp_path, "plate.toml")
    run_scene(scene, tmp_path / "out", cache_dir=None)
    html = (tmp_path / "out" / "report.html").read_text(encoding="utf-8")
    assert '<td class="flagged">unconfirmed</td>' in html
    assert "reduced mode(s) marked unconfirmed" in html
    assert "index unconfirmed for mode(s)" in html
    assert "mode(s) 6, 10 (Sturm" in html  # the flags of the test above
    # the CSV a user post-processes carries the same flags (1: confirmed, 0: unconfirmed)
    import csv

    with open(tmp_path / "out" / "frequencies.csv", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    unconfirmed = [int(r["mode"]) for r in rows if r["index_confirmed"] == "0"]
    assert unconfirmed == [6, 10]


def test_one_count_above_all_decides_when_nothing_is_missed():
    """distinct=True: approximations of 1, 2, 3 (nothing missed) cost one count; of 1, 2
    and 4 claimed as number 3 (3 missed) the top count finds 4 eigenvalues and the
    per-entry counts flag number 3 only."""
    K, M = sp.diags(np.arange(1.0, 7.0)).tocsc(), sp.identity(6, format="csc")
    ok, n = confirm_indices(K, M, [0.95, 1.95, 2.95], [1.0, 2.0, 3.0], [1, 2, 3],
                            distinct=True)
    assert ok.all()
    assert n == 1
    ok, n = confirm_indices(K, M, [0.95, 1.95, 3.95], [1.0, 2.0, 4.0], [1, 2, 3],
                            distinct=True)
    np.testing.assert_array_equal(ok, [True, True, False])
    assert n == 4


def test_reduced_versus_full_rows_name_the_full_mode_they_match():
    """The check's table: reduced modes 2 and 3 that resemble full modes 3 and 4 (largest
    MAC) and lie nearer to them in frequency are matched to them (the reduction missed
    full mode 2); a mixed pair of equal frequencies (MAC off the diagonal, same
    frequency) keeps its numbers."""
    from femmech.analysis.reference import Comparison
    from femmech.scene.kinds.check import matched_full_modes

    missed = np.zeros((1, 4, 4))
    missed[0, [0, 1, 2, 3], [0, 2, 3, 3]] = 1.0
    comp = Comparison(np.zeros(1), np.array([[10.0, 20.0, 30.0, 40.0]]),
                      np.array([[10.0, 30.001, 40.001, 55.0]]), missed, np.zeros(1), 0.0)
    np.testing.assert_array_equal(matched_full_modes(comp), [[0, 2, 3, 3]])
    pair = np.zeros((1, 4, 4))
    pair[0, [0, 1, 2, 3], [0, 2, 1, 3]] = 1.0
    comp = Comparison(np.zeros(1), np.array([[10.0, 20.0, 20.0, 40.0]]),
                      np.array([[10.0, 20.0, 20.0, 40.0]]), pair, np.zeros(1), 0.0)
    np.testing.assert_array_equal(matched_full_modes(comp), [[0, 1, 2, 3]])
