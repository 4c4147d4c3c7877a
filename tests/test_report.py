"""HTML report of a scene run: self-contained page, atomic writes, and a real headless
browser (Debian's Chromium) that loads the page and its images (issue 8)."""

import os
import re
import shutil
import struct
import subprocess
import tomllib
from pathlib import Path

import pytest

from femmech.output.report import Figure, Section, Table, write_report
from femmech.scene.load import Scene
from femmech.scene.run import run_scene

ROOT = Path(__file__).resolve().parent.parent

# A small frame (one mode image) and a mechanism alone (quasi-frequency diagram).
SCENE = """
[scene]
name = "report test"
description = "frame modes & a slider-crank <mechanism>"

[materials.steel]
E = "210 GPa"
nu = 0.3
rho = "7850 kg/m^3"

[parts.frame.generator]
kind = "grid_frame"
bays = [1, 1, 1]
size = [1.0, 0.6, 0.8]

[parts.frame.sections]
beams_x = { section = "circle", diameter = "40 mm", material = "steel" }
beams_y = { section = "circle", diameter = "40 mm", material = "steel" }
columns = { section = "circle", diameter = "50 mm", material = "steel" }

[[parts.frame.supports]]
nodes = "base"

[mechanisms.press]
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

[analyses.modes]
n_modes = 3
images = 1
vtu = true

[analyses.sweep]
mechanism = "press"
angles = { start = "0 deg", stop = "360 deg", n = 37 }
n_modes = 2
speeds = ["0 rpm", "300 rpm"]
"""

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
    """Width and height from the PNG header (IHDR chunk; PNG specification, sect. 11.2.2)."""
    header = path.read_bytes()[:24]
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
    assert "<td>2.5</td>" in text
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


def test_report_opens_in_headless_chromium_and_images_load(report_run, tmp_path):
    browser = _chromium()
    if browser is None:
        message = ("Chromium is missing: install it with `apt-get update && apt-get install -y"
                   " chromium` (Debian's package; .ci/run does this)")
        if os.environ.get("CI") == "true":
            pytest.fail(message)
        pytest.skip(message)
    out = report_run.out_dir
    html = report_run.report.read_text()
    # a copy of the page next to it (same relative image paths) with a probe script that
    # writes each image's natural size into the DOM once the page has loaded
    probe = out / "probe.html"
    probe.write_text(html.replace("</body>", PROBE + "</body>"))
    try:
        done = subprocess.run([browser, *CHROMIUM_FLAGS, f"--user-data-dir={tmp_path}",
                               "--virtual-time-budget=10000", "--dump-dom", probe.as_uri()],
                              capture_output=True, text=True, timeout=180, check=False)
    finally:
        probe.unlink()
    found = re.findall(r"IMG (\S+) (\d+) (\d+)", done.stdout)
    assert done.returncode == 0, done.stderr[-2000:]
    expected = re.findall(r'<img src="([^"]+)"', html)
    assert sorted(name for name, _, _ in found) == sorted(expected)
    for name, width, height in found:
        # loaded and decoded: the browser's natural size is the PNG's own size
        assert (int(width), int(height)) == _png_size(out / name), name
        assert int(width) > 100
