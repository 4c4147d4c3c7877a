"""Charts that read at a glance: the greedy label placement on boxes,
axis scales and angle ticks, the quasi-eigenfrequency diagram read back from its
artists, time histories, and one speed unit per scene (the ``[analyses] speed_unit`` key,
the sweep and stability tasks' CSV headers, labels and report tables)."""

import csv
import math
import tomllib
from contextlib import nullcontext
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import femmech.analysis.stability
import femmech.mechanisms
from femmech.analysis.stability import StabilityChart
from femmech.errors import SceneError
from femmech.output.charts import (
    angle_tick_step,
    boxes_overlap,
    drawn_extent,
    format_speed,
    needs_log_scale,
    overlapping_pairs,
    place_labels,
    speed_scale,
    spread_1d,
)
from femmech.output.histories import plot_time_histories, time_histories_figure
from femmech.output.sweeps import quasi_frequency_figure
from femmech.scene.kinds import stability as stability_kind
from femmech.scene.kinds import sweep as sweep_kind
from femmech.scene.kinds.common import SPEED_UNITS
from femmech.scene.kinds.stability import StabilitySpec
from femmech.scene.kinds.sweep import SweepSpec
from femmech.scene.load import Scene

RPM = 60 / (2 * math.pi)  # rad/s → rpm
EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def drawn_boxes(fig, artists) -> list:
    """Renderer boxes (x0, y0, x1, y1) of artists after the figure is drawn (of a label
    with a leader line, its text)."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    return [drawn_extent(a, renderer) for a in artists]


# --- the greedy placement: a pure function on boxes ------------------------------------

def test_boxes_overlap_only_when_they_share_area():
    assert boxes_overlap((0, 0, 10, 10), (5, 5, 15, 15))
    assert not boxes_overlap((0, 0, 10, 10), (10, 0, 20, 10))  # touching is not overlap
    assert boxes_overlap((0, 0, 10, 10), (10.5, 0, 20, 10), pad=1.0)
    assert boxes_overlap((5, -5, 5, 20), (0, 0, 10, 10))  # a vertical leader crossing
    assert not boxes_overlap((12, -5, 12, 20), (0, 0, 10, 10))


def test_place_labels_takes_the_first_free_candidate():
    # three labels that all prefer the same spot: the second and third move on
    spot, above, higher = (0, 0, 10, 5), (0, 6, 10, 11), (0, 12, 10, 17)
    chosen = place_labels([[spot, above, higher]] * 3, pad=0.5)
    assert chosen.tolist() == [0, 1, 2]


def test_place_labels_respects_obstacles_bounds_and_gives_up_when_full():
    legend = (0, 0, 10, 5)
    chosen = place_labels([[(0, 0, 10, 5), (0, 10, 10, 15), (0, 30, 10, 35)]],
                          obstacles=[legend], bounds=(0, 0, 100, 20))
    assert chosen.tolist() == [1]  # the first overlaps the legend, the last is outside
    chosen = place_labels([[(0, 0, 10, 5)], [(0, 0, 10, 5)]])
    assert chosen.tolist() == [0, -1]  # no free candidate: left out, never overlapping


def test_place_labels_prefers_free_leaders_but_never_overlaps_boxes():
    # label 0 sits at x 0..10 in row 0; label 1's line is at x = 5: a row-1 box above it
    # would have its leader cross label 0, so the box beside (x 20..30) is preferred
    row0 = (0, 0, 10, 5)
    boxes = [[row0], [(0, 6, 10, 11), (20, 0, 30, 5)]]
    leaders = [[(5, -1, 5, 0)], [(5, -1, 5, 6), (25, -1, 25, 0)]]
    assert place_labels(boxes, leaders=leaders).tolist() == [0, 1]
    # with only the crossing candidate it is taken: leaders may cross, boxes may not
    assert place_labels(boxes[:1] + [boxes[1][:1]],
                        leaders=[leaders[0], leaders[1][:1]]).tolist() == [0, 0]


def test_greedy_placement_of_many_crowded_labels_has_no_overlaps():
    # 40 labels anchored within 100 px, each offered 40 stacked rows: all placed, and the
    # chosen boxes are pairwise disjoint (the property the charts rely on)
    rng = np.random.default_rng(7)
    xs = np.sort(rng.uniform(0, 100, 40))
    candidates = [[(x - 15, 12 * r, x + 15, 12 * r + 10) for r in range(40)] for x in xs]
    chosen = place_labels(candidates, pad=1.0)
    assert (chosen >= 0).all()
    boxes = [candidates[i][j] for i, j in enumerate(chosen)]
    assert overlapping_pairs(boxes, pad=0.5) == []


def test_place_labels_keeps_later_leaders_free_where_it_can():
    # lines at x = 0 and x = 3; label 0 may centre on its line (covering x = 3) or sit
    # left of it: with the columns it leaves x = 3 free, and label 1 goes above it
    boxes = [[(-10, 0, 10, 5), (-19, 0, 1, 5)], [(-7, 0, 13, 5), (-7, 6, 13, 11)]]
    leaders = [[(0, -1, 0, 0)] * 2, [(3, -1, 3, 0), (3, -1, 3, 6)]]
    columns = [(0, -1, 0, np.inf), (3, -1, 3, np.inf)]
    assert place_labels(boxes, leaders=leaders).tolist() == [0, 1]  # leader 1 crosses
    assert place_labels(boxes, leaders=leaders, columns=columns).tolist() == [1, 1]


def test_spread_keeps_order_moves_little_and_stays_inside():
    # isolated labels stay centred on their lines
    left = spread_1d([10.0, 50.0], [10.0, 10.0], 2.0, 0.0, 100.0)
    assert left.tolist() == [5.0, 45.0]
    # three labels on one line spread symmetrically about it, 2 apart, in order
    left = spread_1d([50.0, 50.0, 50.0], [10.0, 10.0, 10.0], 2.0, 0.0, 100.0)
    assert left.tolist() == pytest.approx([33.0, 45.0, 57.0])
    # pushed off the edge: shifted in, still in order and disjoint; too wide: None
    left = spread_1d([1.0, 2.0], [10.0, 10.0], 2.0, 0.0, 100.0)
    assert left.tolist() == [0.0, 12.0]
    assert spread_1d([50.0] * 9, [12.0] * 9, 2.0, 0.0, 100.0) is None
    rng = np.random.default_rng(11)
    x = rng.uniform(0, 400, 25)
    w = rng.uniform(10, 30, 25)
    left = spread_1d(x, w, 3.0, 0.0, 1000.0)
    order = np.argsort(x, kind="stable")
    # bound: label boxes placed by float sums of widths: ~eps of O(100) px
    assert np.all(np.diff(left[order]) >= w[order][:-1] + 3.0 - 1e-9)  # order, gap
    assert left.min() >= 0.0
    assert (left + w).max() <= 1000.0


# --- scales, ticks and units --------------------------------------------------------------

def test_log_scale_only_beyond_a_decade():
    assert not needs_log_scale([80.0, 790.0])
    assert needs_log_scale([80.0, 820.0, np.nan])
    assert not needs_log_scale([-1.0, 50.0])  # nothing to log
    assert not needs_log_scale([np.nan, 5.0])


@pytest.mark.parametrize(("span", "step"), [(360, 45), (180, 45), (90, 45), (720, 90),
                                            (45, None), (1080, None)])
def test_angle_ticks_every_45_or_90_degrees(span, step):
    assert angle_tick_step(span) == step


def test_speed_format_and_units():
    W = 1200 / RPM  # 1200 rpm in rad/s
    assert format_speed(W, "rpm") == "1200 rpm"
    assert format_speed(W, "rad/s") == "125.7 rad/s"  # 40π = 125.66…
    assert format_speed(W, "Hz") == "20.00 Hz"
    assert speed_scale("rpm") == pytest.approx(RPM)
    with pytest.raises(ValueError, match="speed_unit must be one of"):
        speed_scale("rmp")


# --- the quasi-eigenfrequency diagram -------------------------------------------------------

def curve(freq, n_angles=73, span=2 * np.pi):
    phi = np.linspace(0.0, span, n_angles)
    freq = np.column_stack([f + 0.05 * f * np.sin(2 * phi) for f in freq])
    return SimpleNamespace(phi=phi, freq_hz=freq)


def margin_labels(fig):
    return [t for t in fig.axes[0].texts if t.get_gid() == "margin-label"]


def test_quasi_diagram_is_linear_within_a_decade_with_45_degree_ticks():
    fig = quasi_frequency_figure({"0 rpm": curve([85, 92, 150, 300])}, title="t")
    ax = fig.axes[0]
    assert ax.get_yscale() == "linear"
    assert "log" not in ax.get_ylabel()
    assert ax.get_xlim() == (0.0, 360.0)
    assert ax.get_xticks().tolist() == list(range(0, 361, 45))
    assert [t.get_text() for t in margin_labels(fig)] == ["f1", "f2", "f3", "f4"]


def test_quasi_diagram_goes_log_beyond_a_decade_and_says_so():
    fig = quasi_frequency_figure({"static": curve([80, 300, 820])})
    ax = fig.axes[0]
    assert ax.get_yscale() == "log"
    assert "log scale" in ax.get_ylabel()


def test_quasi_diagram_spans_the_swept_angles():
    fig = quasi_frequency_figure({"half": curve([10, 20], span=np.pi)})
    ax = fig.axes[0]
    assert ax.get_xlim() == (0.0, 180.0)
    assert ax.get_xticks().tolist() == [0, 45, 90, 135, 180]


def test_quasi_diagram_has_one_legend_and_no_overlapping_labels():
    # crowded: two speeds, branches 1 Hz apart and ten harmonics of 1200 rpm (20 Hz)
    # among them, several on top of a branch
    W = 1200 / RPM
    fig = quasi_frequency_figure({"0 rpm": curve([80, 81, 100, 120, 160]),
                                  "1200 rpm": curve([79, 80.5, 99, 119, 158])},
                                 speed=W, orders=range(1, 13), speed_unit="rpm")
    ax = fig.axes[0]
    legends = list(fig.legends) + [a.get_legend() for a in fig.axes if a.get_legend()]
    assert len(legends) == 1
    assert [t.get_text() for t in legends[0].get_texts()] == [
        "0 rpm", "1200 rpm", "k·n: harmonics of n = 1200 rpm"]
    labels = margin_labels(fig)
    texts = sorted(t.get_text() for t in labels)
    # 4·n = 80 Hz … 8·n = 160 Hz lie in the plotted range (the curves span 75…168 Hz)
    assert texts == sorted(["f1", "f2", "f3", "f4", "f5"] +
                           [f"{k}·n" for k in range(4, 9)])
    boxes = drawn_boxes(fig, labels + legends)
    assert overlapping_pairs(boxes) == []
    # each branch label starts right of the plot, never over the data
    x1 = drawn_boxes(fig, [ax])[0][2]
    assert all(b[0] >= x1 for b in boxes[:len(labels)])


def test_quasi_diagram_harmonics_in_rad_s_use_omega():
    fig = quasi_frequency_figure({"a": curve([15, 25])}, speed=2 * np.pi * 10.0,
                                 orders=(1, 2, 3), speed_unit="rad/s")
    texts = {t.get_text() for t in margin_labels(fig)}
    assert {"2·Ω"} <= texts  # 20 Hz is inside 14.25…26.25 Hz; 10 and 30 Hz are not
    assert not {"1·Ω", "3·Ω"} & texts
    assert "Ω = 62.8 rad/s" in fig.legends[0].get_texts()[-1].get_text()


# --- time histories -------------------------------------------------------------------------

def test_histories_over_angle_tick_every_45_degrees_with_legends_outside(tmp_path):
    deg = np.linspace(0.0, 360.0, 91)
    panels = {"q": {"a": deg, "b": -deg}, "f": {"a": deg, "b": deg}, "m": {"x": deg}}
    fig = time_histories_figure(deg, panels, "t", "angle φ (°)", angle_deg=True)
    axes = fig.axes
    # the second panel names the same curves as the first: no second legend
    assert [ax.get_legend() is not None for ax in axes] == [True, False, False]
    assert axes[-1].get_xticks().tolist() == list(range(0, 361, 45))
    legend, plot = drawn_boxes(fig, [axes[0].get_legend(), axes[0]])
    assert legend[0] >= plot[2]  # outside, right of the data
    assert plot_time_histories(deg, panels, tmp_path / "h.png").stat().st_size > 10_000


# --- one speed unit per scene ---------------------------------------------------------------

def scene_data() -> dict:
    """The shipped mechanism-only scene (a sweep at 0 and 1200 rpm), as a dict."""
    return tomllib.loads((EXAMPLES / "mechanism_quasi_modes.toml").read_text())


def test_speed_unit_defaults_to_rpm_and_is_read_strictly():
    data = scene_data()
    analyses = Scene.from_dict(data, EXAMPLES, "s.toml").analyses
    assert SPEED_UNITS == ("rpm", "rad/s")
    assert analyses.speed_unit == "rpm"
    assert analyses.sweep.speed_unit == "rpm"
    data["analyses"]["speed_unit"] = "rad/s"
    assert Scene.from_dict(data, EXAMPLES, "s.toml").analyses.sweep.speed_unit == "rad/s"
    data["analyses"]["speed_unit"] = "rad/S"
    with pytest.raises(SceneError, match=r"\[analyses\] speed_unit: expected one of"
                                         r" \['rad/s', 'rpm'\], got 'rad/S' \(did you mean"
                                         r" 'rad/s'\?\)"):
        Scene.from_dict(data, EXAMPLES, "s.toml")
    data["analyses"]["speed_unit"] = 60
    with pytest.raises(SceneError, match=r"speed_unit: expected a string, got 60"):
        Scene.from_dict(data, EXAMPLES, "s.toml")


def test_sweep_speeds_must_differ_in_the_scene_unit():
    data = scene_data()
    # 100.051 rad/s = 955.4 rpm and 100.14 rad/s = 956.3 rpm: distinct in whole rpm, but
    # both 100.1 rad/s to one decimal
    data["analyses"]["sweep"]["speeds"] = ["100.051 rad/s", "100.14 rad/s"]
    assert Scene.from_dict(data, EXAMPLES, "s.toml").analyses.sweep.speed_unit == "rpm"
    data["analyses"]["speed_unit"] = "rad/s"
    with pytest.raises(SceneError, match=r"\[analyses.sweep\] speeds: two speeds round to"
                                         r" 100.1 rad/s; each curve of a sweep is labelled"
                                         r" by its speed in rad/s to one decimal"):
        Scene.from_dict(data, EXAMPLES, "s.toml")


def workshop(out_name="t"):
    logs = []
    return SimpleNamespace(scene=SimpleNamespace(name=out_name), bars=False, log=logs.append,
                           machine=lambda: None, timed=lambda what: nullcontext(),
                           prepared=SimpleNamespace(mechanisms={"m": None}), logs=logs)


@pytest.mark.parametrize("unit", ["rpm", "rad/s"])
def test_sweep_task_shows_speeds_in_the_scene_unit(monkeypatch, tmp_path, unit):
    def fake_quasi_modes(model, phi, Omega=0.0):
        return SimpleNamespace(phi=phi, freq_hz=np.column_stack([50 + 0 * phi + Omega,
                                                                 90 + 0 * phi]))

    monkeypatch.setattr(femmech.mechanisms, "quasi_modes", fake_quasi_modes)
    speeds = (0.0, 1200 / RPM)
    spec = SweepSpec(tuple(np.linspace(0, 2 * np.pi, 9)), 2, speeds, "m", True, (),
                     speed_unit=unit)
    section, results = sweep_kind.run(workshop(), spec, tmp_path)
    with open(tmp_path / "quasi_frequencies.csv", newline="") as f:
        rows = list(csv.reader(f))
    column = {"rpm": "speed_rpm", "rad/s": "speed_rad_s"}[unit]
    assert rows[0][:2] == [column, "angle_deg"]
    # bound: one unit conversion: one rounding
    assert float(rows[-1][0]) == pytest.approx(speeds[1] * speed_scale(unit), rel=1e-12)
    labels = {"rpm": ["0 rpm", "1200 rpm"], "rad/s": ["0.0 rad/s", "125.7 rad/s"]}[unit]
    assert sorted({r[0] for r in section.tables[0].rows}) == labels
    assert results["speeds_rad_s"] == list(speeds)  # results.json stays SI
    other = {"rpm": "rad/s", "rad/s": "rpm"}[unit]
    assert other not in " ".join(section.paragraphs)


@pytest.mark.parametrize("unit", ["rpm", "rad/s"])
def test_stability_task_shows_speeds_in_the_scene_unit(monkeypatch, tmp_path, unit):
    def fake_chart(system, speeds, **options):
        W = speeds[0]
        r = np.array([[1.2 if 100 < W < 120 else 0.9]])
        return StabilityChart(np.asarray(speeds), None, r, r <= 1 + 1e-6, 1e-6,
                              periods=np.array([[2 * np.pi / W]]), error=1e-9 * r,
                              converged=np.array([[W < 140]]), n_steps=np.array([[64]]),
                              rtol=1e-4)

    monkeypatch.setattr(femmech.analysis.stability, "stability_chart", fake_chart)
    speeds = tuple(np.linspace(80.0, 150.0, 8))  # rad/s: 110, 120 unstable; 150 loose
    spec = StabilitySpec(speeds, 32, 2 * np.pi, (0.0, 0.0), 1e-6, 1e-4, 256,
                         speed_unit=unit)
    ws = workshop()
    section, results = stability_kind.run(ws, spec, tmp_path)
    with open(tmp_path / "stability.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    column = {"rpm": "speed_rpm", "rad/s": "speed_rad_s"}[unit]
    assert list(rows[0])[0] == column
    # bound: one unit conversion: one rounding
    assert [float(r[column]) for r in rows] == pytest.approx(
        [W * speed_scale(unit) for W in speeds], rel=1e-12)
    assert section.tables[0].header[0] == f"speed ({unit})"
    other = {"rpm": "rad/s", "rad/s": "rpm"}[unit]
    text = " ".join(section.paragraphs + section.warnings)
    assert unit in text
    assert other not in text
    assert results["speeds_rad_s"] == pytest.approx(list(speeds))
    assert (tmp_path / "stability_chart.png").stat().st_size > 10_000
