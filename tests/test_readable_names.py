"""Report tables and plots name mechanism coordinates readably, CSV columns stay raw.

A coordinate shows as "meaning [raw name]" (femmech.mechanisms.catalogue, the same text
as docs/mechanisms.md) in the HTML tables and the plot labels of the report; the CSV
files keep the machine-readable names (``press.q``) that scene files use.
"""

from __future__ import annotations

import csv
import re
import tomllib
from pathlib import Path

import matplotlib.axes
import numpy as np

import femmech as fm
from femmech.coupling import Attachment, Mount, couple
from femmech.fe import sections
from femmech.mechanisms import cam_follower, cam_program, rheolinear
from femmech.scene import Scene, run_scene

ROOT = Path(__file__).resolve().parents[1]
PRESS = ROOT / "examples" / "press_frame.toml"


def _press_run_up(tmp_path, monkeypatch):
    data = tomllib.loads(PRESS.read_text())
    data["analyses"] = {"response": {"kind": "run_up", "speed_start": "0 rpm",
                                     "speed_end": "300 rpm", "duration": "0.02 s",
                                     "t_end": "0.02 s", "n_steps": 20,
                                     "outputs": ["press.q_t", "press.q"],
                                     "frame_dofs": [{"node": "guide", "dof": "ux"}]}}
    scene = Scene.from_dict(data, ROOT / "examples", "press_frame.toml")
    ylabels, titles = [], []

    def recorder(name, into):
        original = getattr(matplotlib.axes.Axes, name)

        def record(self, label, *args, **kwargs):
            into.append(label)
            return original(self, label, *args, **kwargs)
        monkeypatch.setattr(matplotlib.axes.Axes, name, record)

    recorder("set_ylabel", ylabels)
    recorder("set_title", titles)
    result = run_scene(scene, tmp_path, cache_dir=None)
    return result, ylabels, titles


def _cells(html: str, caption: str) -> list[list[str]]:
    table = re.search(rf"<caption>{re.escape(caption)}.*?</table>", html, re.S).group(0)
    return [re.findall(r"<td[^>]*>(.*?)</td>", row, re.S)
            for row in re.findall(r"<tr>(.*?)</tr>", table, re.S) if "<td" in row]


def test_response_table_and_plot_use_readable_names_and_csv_the_raw_ones(tmp_path,
                                                                         monkeypatch):
    result, ylabels, titles = _press_run_up(tmp_path, monkeypatch)
    html = result.report.read_text(encoding="utf-8")
    rows = _cells(html, "Amplitudes (m, rad or modal)")
    assert [r[0] for r in rows] == ["crankshaft twist [press.q_t]",
                                    "output (rod and ram) deformation [press.q]",
                                    "frame:guide:ux"]
    # panels are titled by the readable name; the y axis has the coordinate's unit (the
    # catalogue: q_t is a twist in rad, q a deformation in m), a frame DOF its own
    assert titles == ["crankshaft twist [press.q_t]",
                      "output (rod and ram) deformation [press.q]", "frame:guide:ux"]
    assert ylabels == ["rad", "m", "m"]
    with open(tmp_path / "response.csv", newline="") as f:
        header = next(csv.reader(f))
    assert header == ["t_s", "phi_rad", "press.q_t", "press.q", "frame:guide:ux"]
    # the summary's mechanism and mount tables
    (mechanism,) = _cells(html, "Mechanisms (parameters")
    assert mechanism[2].startswith("crankshaft twist [q_t], crank-bearing displacement along"
                                   " the slider axis [u_b]")
    (mount,) = _cells(html, "Mechanisms mounted")
    assert "guide displacement across the slider axis [v_g]" in mount[3]
    assert "v_g→guide:ux" in mount[4]  # attachments keep the scene's spelling


def test_coupled_system_describes_its_labels():
    # a cam follower whose cam centre rides elastically on a beam's mid-span node
    x = np.linspace(0.0, 1.0, 5)
    mesh = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(4), np.arange(1, 5)]),
                              node_sets={"ends": [0, 4]})
    prop = fm.BeamProperty(sections.rectangular_hollow(0.06, 0.08, 0.004),
                           fm.Material(E=210e9, nu=0.3, rho=7850.0))
    frame = fm.build_model(mesh, {"all": prop}, supports=[fm.Support("ends", "all")])
    cam = cam_program(0.01, 120, 60, 120, 60)
    model = rheolinear(cam_follower(J="J"), dict(m=1.0, c=1e6, c_r=1e3, b=0.0, F=0.0,
                                                  J=1e-3), {"U": cam})
    system = couple(frame, [Mount(model, (Attachment("y_c", 2, "uy", stiffness=1e7),),
                                  name="cam1")], allow_interior=True)
    own = [label for label in system.labels if label.startswith("cam1.")]
    assert own == ["cam1.q_s", "cam1.y_c", "cam1.y_f", "cam1.q"]
    assert [system.describe(label) for label in own] == [
        "shaft twist at the cam [cam1.q_s]", "cam-centre displacement [cam1.y_c]",
        "return-spring base displacement [cam1.y_f]", "follower deformation [cam1.q]"]
    assert system.describe("frame 3") == "frame 3"
    assert [system.unit(label) for label in own] == ["rad", "m", "m", "m"]
    assert system.unit("frame 3") == ""
