"""HTML report of a scene run: self-contained page, atomic writes, and a real headless
browser (Debian's Chromium) that loads the page and its images; the model
summary, mass participation and appendix a reviewer signs, with formatted numbers."""

import os
import re
import shutil
import struct
import subprocess
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scene_texts import frame_scene

from femmech.analysis.modes import modes
from femmech.analysis.participation import participation
from femmech.output.report import Figure, Section, Table, write_report
from femmech.scene.build import part_model, prepare
from femmech.scene.load import Scene
from femmech.scene.run import run_scene

ROOT = Path(__file__).resolve().parent.parent

# A small frame (one mode image) and a mechanism alone (quasi-frequency diagram).
PRESS = """[mechanisms.press]
model = "table_5_1_case"
options = { case = 1 }
position_functions.U = { kind = "slider_crank", r = "50 mm", l = "350 mm" }

[mechanisms.press.parameters]
J1 = "1.5 kg*m^2"
m2 = "150 kg"
c1 = "1e6 N*m/rad"
c2 = "1e9 N/m"
b1 = 0
b2 = 0
F2 = 0
"""
SWEEP = """[analyses.sweep]
mechanism = "press"
angles = { start = "0 deg", stop = "360 deg", n = 37 }
n_modes = 2
speeds = ["0 rpm", "300 rpm"]
"""
SCENE = frame_scene("report test", description="frame modes & a slider-crank <mechanism>",
                    parts_extra=PRESS, images=1, vtu=True, after=SWEEP)

CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                  "--no-first-run", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync"]
PROBE = """<script>
window.addEventListener('load', function () {
  for (const img of document.images) {
    const p = document.createElement('p');
    p.className = 'femmech-probe';
    p.textContent = 'IMG ' + img.getAttribute('src') + ' ' + img.naturalWidth + ' '
      + img.naturalHeight;
    document.body.appendChild(p);
  }
});
</script>"""


@pytest.fixture(scope="module")
def report_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    scene = Scene.from_dict(tomllib.loads(SCENE), ROOT, "report.toml")
    return run_scene(scene, out / "out", cache_dir=None)


def _png_size(path: Path) -> tuple[int, int]:
    """Width and height from the PNG header (IHDR chunk; PNG specification, sect. 11.2.2)
    or the GIF logical screen descriptor (GIF89a specification, sect. 18: little endian)."""
    header = path.read_bytes()[:24]
    if header[:6] == b"GIF89a":
        return struct.unpack("<HH", header[6:10])
    assert header[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", header[16:24])


def test_write_report_tables_figures_links_and_escaping(tmp_path):
    (tmp_path / "a.png").write_bytes(b"")
    (tmp_path / "data.csv").write_text("x\n1\n")
    section = Section("Results <1>", ("M & K",), (Table("t", ("mode", "f"), ((1, 2.5),)),),
                      (Figure("a.png", "mode <1>"),), ("data.csv",))
    path = write_report(tmp_path, "title & more", "meta", [section], ["log <line>"])
    text = path.read_text()
    assert "<h2>Results &lt;1&gt;</h2>" in text
    assert "<p>M &amp; K</p>" in text
    assert '<img src="a.png" alt="mode &lt;1&gt;">' in text
    assert '<a href="data.csv">data.csv</a>' in text
    assert "log &lt;line&gt;" in text
    assert '<td class="num">2.500</td>' in text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "data.csv", "report.html"]
    with pytest.raises(FileNotFoundError, match="references missing.png"):
        write_report(tmp_path, "t", "m", [Section("s", figures=(Figure("missing.png", ""),))],
                     name="other.html")
    assert not (tmp_path / "other.html").exists()


def test_report_is_self_contained(report_run):
    out = report_run.out_dir
    html = report_run.report.read_text()
    refs = re.findall(r'(?:src|href)="([^"#]+)"', html)
    assert refs, "the report references its files"
    for ref in refs:
        assert "://" not in ref
        assert not ref.startswith("/")
        assert (out / ref).is_file(), ref
    assert "<script" not in html
    assert "<style>" in html
    images = re.findall(r'<img src="([^"]+)"', html)
    assert sorted(images) == ["mode_01.png", "quasi_frequencies.png"]
    for name in ("results.json", "run.log", "frequencies.csv", "modes.vtu",
                 "quasi_frequencies.csv"):
        assert name in refs
    # no temporary files left behind; the one hidden file is the run's manifest
    assert [p.name for p in out.glob(".*")] == [".femmech-run.json"]
    assert "frame modes &amp; a slider-crank &lt;mechanism&gt;" in html


def _chromium() -> str | None:
    return shutil.which("chromium") or (
        "/usr/bin/chromium" if Path("/usr/bin/chromium").exists() else None)


def _browser_check(out: Path, html: str, profile: Path) -> None:
    """Open the page in headless Chromium: no console messages (errors, failed scripts),
    every image loaded and decoded at its PNG size."""
    browser = _chromium()
    if browser is None:
        message = ("Chromium is missing: install it with `apt-get update && apt-get install -y"
                   " chromium` (Debian's package; .ci/run does this)")
        if os.environ.get("CI") == "true":
            pytest.fail(message)
        pytest.skip(message)
    # a copy of the page next to it (same relative image paths) with a probe script that
    # writes each image's natural size into the DOM once the page has loaded
    probe = out / "probe.html"
    probe.write_text(html.replace("</body>", PROBE + "</body>"))
    try:
        done = subprocess.run([browser, *CHROMIUM_FLAGS, f"--user-data-dir={profile}",
                               "--enable-logging=stderr", "--v=0",
                               "--virtual-time-budget=10000", "--dump-dom", probe.as_uri()],
                              capture_output=True, text=True, timeout=180, check=False)
    finally:
        probe.unlink()
    found = re.findall(r"IMG (\S+) (\d+) (\d+)", done.stdout)
    assert done.returncode == 0, done.stderr[-2000:]
    # the page's console (Chromium logs it as INFO:CONSOLE lines): nothing at all
    assert not [line for line in done.stderr.splitlines() if ":CONSOLE" in line]
    expected = re.findall(r'<img src="([^"]+)"', html)
    assert sorted(name for name, _, _ in found) == sorted(expected)
    for name, width, height in found:
        # loaded and decoded: the browser's natural size is the PNG's own size
        assert (int(width), int(height)) == _png_size(out / name), name
        assert int(width) > 100


def test_report_opens_in_headless_chromium_and_images_load(report_run, tmp_path):
    _browser_check(report_run.out_dir, report_run.report.read_text(), tmp_path)


# --- the report a reviewer signs ---------------------------------------------

RAW_FLOAT = re.compile(r"\d*\.?\d+")


def _cells(html: str) -> list[str]:
    return [re.sub(r"<[^>]+>", "", c) for c in re.findall(r"<td[^>]*>(.*?)</td>", html)]


def _table(html: str, caption_start: str) -> list[list[str]]:
    """Rows (cell texts) of the table whose caption starts with ``caption_start``."""
    match = re.search(r"<table><caption>" + re.escape(caption_start) + r".*?</table>", html)
    assert match, f"no table {caption_start!r}"
    return [_cells(row) for row in re.findall(r"<tr>(.*?)</tr>", match.group(0))[1:]]


def _assert_no_float_artefacts(html: str) -> None:
    """No table cell holds a number with 12 or more significant digits (a raw float such
    as 0.30000000000000004 or 379.91234567891)."""
    for cell in _cells(html):
        for number in RAW_FLOAT.findall(cell):
            digits = number.replace(".", "").lstrip("0")
            assert len(digits) < 12, f"raw float {number!r} in table cell {cell!r}"


def test_float_artefact_check_fails_on_raw_floats():
    assert RAW_FLOAT.findall("x 0.30000000000000004 kg")
    with pytest.raises(AssertionError, match="raw float"):
        _assert_no_float_artefacts("<td>0.30000000000000004</td>")
    with pytest.raises(AssertionError, match="raw float"):
        _assert_no_float_artefacts("<td class='num'>379.91234567891 kg</td>")
    _assert_no_float_artefacts("<td>0.3000</td><td>1128</td><td>12.35e3 kg</td>")


def _frame_example(images: int) -> Scene:
    data = tomllib.loads((ROOT / "examples" / "frame_modes.toml").read_text())
    data["analyses"]["modes"].update(images=images, vtu=False)
    return Scene.from_dict(data, ROOT / "examples", "frame_modes.toml")


@pytest.fixture(scope="module")
def frame_run(tmp_path_factory):
    """The frame example (examples/frame_modes.toml) with two mode images."""
    out = tmp_path_factory.mktemp("frame") / "out"
    return run_scene(_frame_example(2), out, cache_dir=None)


def test_frame_report_shows_masses_and_effective_modal_masses(frame_run):
    html = frame_run.report.read_text()
    sections = re.findall(r"<h2>(.*?)</h2>", html)
    assert sections[0] == "Model summary"
    assert sections[-1] == "Appendix: software, solvers, threads, timings"
    # masses: 150 kg motor plus the beams; the groups add up to the total from M
    (mass_row,) = _table(html, "Mass properties")
    total = float(mass_row[1])
    groups = _table(html, "Mass by element group")
    assert groups[-1][1] == "total from M"
    assert float(groups[-1][6]) == total
    assert sum(float(r[6]) for r in groups[:-1]) == pytest.approx(total, rel=2e-3)
    assert groups[-2][:7] == ["frame", "point masses", "lumped", "motor", "", "1", "150.0"]
    assert _table(html, "Materials")[0][1:5] == ["210 GPa", "0.3", "80.77 GPa", "7850 kg/m³"]
    # effective modal masses per mode: cumulative fractions grow to ~100 % of the total
    rows = _table(html, "Effective modal masses, translations")
    assert [r[0] for r in rows[:12]] == [str(k) for k in range(1, 13)]
    assert rows[-1][0].startswith("rigid body")
    for column in (3, 5, 7):  # Σ x, Σ y, Σ z (%)
        running = [float(r[column]) for r in rows[:12]]
        assert running == sorted(running)
        assert 99.9 < running[-1] <= 100.0
        assert float(rows[-1][column - 1]) == total  # r_dᵀ M r_d is the total mass
    assert _table(html, "Effective modal masses, rotations")
    assert len(_table(html, "Participation factors")) == 12
    _assert_no_float_artefacts(html)
    # appendix: versions, solvers, threads, timings (moved out of the summary)
    assert "numpy" in [r[0] for r in _table(html, "Software")]
    assert _table(html, "Sparse direct solvers")
    assert _table(html, "BLAS and OpenMP thread pools")
    steps = [r[0] for r in _table(html, "Timings per step")]
    assert {"eigen solve", "mode images", "total"} <= set(steps)
    assert "Timings" not in html[:html.index("<h2>Appendix")]  # only in the appendix
    assert "modes: done in" in html[html.index("<h2>Appendix"):]  # the run log, last


def test_frame_effective_masses_approach_the_total_mass_as_modes_are_added():
    # the frame on elastic mounts (no supports): the effective masses of all modes sum to
    # the total mass; the lowest six (rigid body on the mounts) already carry most of it
    scene = _frame_example(0)
    prepared = prepare(scene)
    model = part_model(scene, scene.parts["frame"], prepared.meshes["frame"])
    result = modes(model, n_modes=60)
    p = participation(model, result)
    fraction = p.cumulative_fraction[:, :3]  # x, y, z
    assert np.all(np.diff(fraction, axis=0) >= 0)
    # measured: 6 modes 99.91, 99.92, 99.79 %; 12 modes 99.96, 99.95, 99.96 %
    assert np.all(fraction[5] > 0.997)
    assert np.all(fraction[11] > fraction[5])
    assert np.all(fraction[11] > 0.999)
    assert np.all(fraction[-1] > fraction[11])
    # bound: cumulative fractions <= 1 up to ~n eps of the sums
    assert np.all(fraction[-1] <= 1 + 1e-12)
    # bound: rigid masses: sums of ρ A L (exact consistent mass), ~n eps
    np.testing.assert_allclose(p.rigid_mass[:3], model.total_mass(), rtol=1e-12)


def test_frame_report_opens_in_headless_chromium(frame_run, tmp_path):
    _browser_check(frame_run.out_dir, frame_run.report.read_text(), tmp_path)


def test_mechanism_only_report_has_no_parts_tables(tmp_path):
    data = tomllib.loads((ROOT / "examples" / "mechanism_quasi_modes.toml").read_text())
    data["analyses"]["sweep"]["angles"]["n"] = 25
    scene = Scene.from_dict(data, ROOT / "examples", "mechanism_quasi_modes.toml")
    html = run_scene(scene, tmp_path / "out", cache_dir=None).report.read_text()
    captions = re.findall(r"<caption>(.*?)</caption>", html)
    for table in ("Parts", "Materials", "Mass", "Supports", "Reductions"):
        assert not [c for c in captions if c.startswith(table)], table
    (mechanism,) = _table(html, "Mechanisms (parameters")
    # readable coordinate names with the raw name in brackets (mechanisms.catalogue)
    assert mechanism[:3] == ["machine", "processing_machine (kinematic_drive = true)",
                             "shaft twist 1 (J0–J1) [q2], shaft twist 2 (J1–J2) [q3],"
                             " follower 1 deformation [q4], follower 2 deformation [q5]"]
    assert "c3 = 1 MN/m" in mechanism[3]
    assert re.findall(r"<h2>(.*?)</h2>", html)[-1].startswith("Appendix")
    _assert_no_float_artefacts(html)
    _browser_check(tmp_path / "out", html, tmp_path / "profile")


def test_reduced_part_summary_with_error_estimate_and_cache_hit(tmp_path):
    # the press frame (Craig-Bampton, f_max 800 Hz): the summary gives the reduction's
    # settings and sizes and the largest estimated error of its modes up to 800 Hz; a
    # second run from the cache assembles nothing, so it names what it cannot give
    data = tomllib.loads((ROOT / "examples" / "press_frame.toml").read_text())
    data["analyses"] = {"sweep": {"angles": {"start": "0 deg", "stop": "360 deg", "n": 5},
                                  "n_modes": 2}}
    scene = Scene.from_dict(data, ROOT / "examples", "press_frame.toml")
    first = run_scene(scene, tmp_path / "a", cache_dir=tmp_path / "cache")
    rows = dict((r[0], r[1]) for r in _table(first.report.read_text(), "Reductions"))
    assert rows["method"] == "craig_bampton"
    assert rows["interface DOFs"] == "3"
    assert rows["cache"] == "miss"
    error = float(rows["estimated relative frequency error"].split()[0])
    assert 0 < error < 1e-4  # measured 8.2e-6 at 755.8 Hz
    assert "modes up to 800 Hz" in rows["estimated relative frequency error"]
    second = run_scene(scene, tmp_path / "b", cache_dir=tmp_path / "cache")
    assert not any(line.startswith("assembled part") for line in second.log)
    html = second.report.read_text()
    rows = dict((r[0], r[1]) for r in _table(html, "Reductions"))
    assert rows["cache"] == "hit"
    assert rows["estimated relative frequency error"] == "needs the assembled model"
    assert "Not assembled in this run" in html
    assert not re.findall(r"<caption>Mass", html)
    (part,) = _table(html, "Parts")
    assert part[:4] == ["frame", "43", "42", "258"]
    assert part[-1] == "246"  # free DOFs from the superelement


def test_supported_part_states_the_mass_its_modes_can_reach(report_run):
    # the test scene's frame stands on supported base nodes: its 3 modes carry part of
    # the mass, and the report states the limit of all modes (the rest moves with the
    # supports) next to the cumulative fractions
    html = report_run.report.read_text()
    assert "The part is supported: even all modes of the full model reach only" in html
    rows = _table(html, "Effective modal masses, translations")
    assert len(rows) == 4  # 3 modes and the rigid-body row
    assert all(0 <= float(r[c]) < 100 for r in rows[:3] for c in (3, 5, 7))
    _assert_no_float_artefacts(html)
