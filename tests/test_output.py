"""Output: beam field recovery, mode-shape images, VTU export, frequency tables.

Data are checked first (recovered curves against analytic beam fields, the automatic
scale, the colour field), then one image against a committed reference PNG.
Regenerate the reference with ``FEMMECH_UPDATE_IMAGES=1 python -m pytest
tests/test_output.py`` after an intended change, and look at it before committing.
"""

from __future__ import annotations

import csv
import os
import subprocess
import sys
from pathlib import Path

import meshio
import numpy as np
import pytest
import pyvista as pv
import scipy.sparse.linalg as spla
from numpy.testing import assert_allclose
from PIL import Image

import femmech as fm
from femmech.fe import sections
from femmech.fe.recovery import beam_deflection_curves
from femmech.output import (
    atomic_path,
    export_modes_vtu,
    frequency_table,
    mode_mesh,
    mode_scale,
    mode_title,
    plot_mode,
    plot_modes,
    write_frequency_csv,
)
from femmech.output.annotate import (
    COLOUR_BAR_TITLE,
    LegendEntry,
    format_factor,
    make_layout,
    panel_image,
    scale_text,
)
from femmech.output.camera import fit_camera, project, screen_axes
from femmech.output.mode_geometry import (
    drawn_points,
    ground_springs,
    joined_pairs,
    joint_nodes,
    model_glyphs,
)
from femmech.output.plot import RADIUS_RANGE, SCALE_FRACTION
from femmech.output.renderer import COLORS, ModeRenderer, scene_legend

IMAGES = Path(__file__).parent / "images"
STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)
EPS = np.finfo(float).eps


@pytest.fixture(autouse=True)
def _reset_theme():
    """Each test starts from pyvista's default theme (plot_mode uses its own anyway)."""
    pv.global_theme.restore_defaults()
    yield
    pv.global_theme.restore_defaults()


def _line_model(n_el, length=1.0, axis=(1.0, 0.0, 0.0), section=None, shear=False,
                rotary_inertia=False):
    """Cantilever of n_el elements along ``axis``, clamped at node 0."""
    direction = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    s = np.linspace(0.0, length, n_el + 1)
    mesh = fm.Mesh.from_lines(s[:, None] * direction,
                              np.column_stack([np.arange(n_el), np.arange(1, n_el + 1)]),
                              node_sets={"root": [0]})
    prop = fm.BeamProperty(section or sections.circle(0.02), STEEL, shear=shear,
                           rotary_inertia=rotary_inertia)
    return fm.build_model(mesh, {"all": prop}, supports=[fm.Support("root")]), s, direction


def _static(model, node, force):
    """Static displacement (full DOFs) under a force (N) at a node."""
    f = np.zeros(model.n_dof)
    f[6 * node:6 * node + 3] = force
    u_free = spla.spsolve(model.K_free.tocsc(), model.T.T @ f)
    return model.expand(u_free)


def _frame_3d():
    """Small 3D frame: a bent pipe with members along all three axes and a skew one."""
    points = np.array([[0, 0, 0], [0, 0, 1], [0.5, 0, 1], [1, 0, 1], [1, 0.6, 1],
                       [1, 0.6, 0.4], [1.4, 1.0, 0.2]], dtype=float)
    lines = np.column_stack([np.arange(6), np.arange(1, 7)])
    mesh = fm.Mesh.from_lines(points, lines, node_sets={"base": [0]})
    prop = fm.BeamProperty(sections.rectangle(0.04, 0.02), STEEL)
    return fm.build_model(mesh, {"all": prop}, supports=[fm.Support("base")])


def test_import_femmech_output_does_not_import_pyvista():
    code = ("import sys, femmech, femmech.output, femmech.fe.recovery;"
            "assert not {'pyvista', 'vtk', 'vtkmodules'} & set(sys.modules)")
    subprocess.run([sys.executable, "-c", code], check=True)


def test_curves_end_points_equal_nodal_translations():
    model = _frame_3d()
    u = np.random.default_rng(1).standard_normal(model.n_dof)
    points, disp = beam_deflection_curves(model, u, n_sub=5)
    ends = disp.reshape(-1, 6, 3)[:, [0, -1]]
    nodal = u.reshape(-1, 6)[:, :3][model.beams.cells]
    # only round-off: a rotation to local axes and back (a few eps times |u|)
    assert_allclose(ends, nodal, rtol=0, atol=20 * EPS * np.abs(u).max())
    assert_allclose(points.reshape(-1, 6, 3)[:, [0, -1]], model.mesh.points[model.beams.cells],
                    rtol=0, atol=10 * EPS)


def test_curves_reproduce_cubic_tip_load_deflection():
    # Euler-Bernoulli cantilever, skew axis, tip force P normal to it:
    # w(s) = P s² (3L - s) / (6 E I) (Timoshenko & Gere, Mechanics of Materials, case 1),
    # a cubic, which the Hermite interpolation of exact nodal values reproduces exactly.
    length, d, P = 1.3, 0.02, 50.0
    model, _, axis = _line_model(3, length, axis=(1.0, 2.0, 0.5), section=sections.circle(d))
    load_dir = np.cross(axis, [0.0, 0.0, 1.0])
    load_dir /= np.linalg.norm(load_dir)
    u = _static(model, 3, P * load_dir)
    points, disp = beam_deflection_curves(model, u, n_sub=7)
    s = points @ axis
    EI = STEEL.E * np.pi * d**4 / 64
    expected = (P * s**2 * (3 * length - s) / (6 * EI))[:, None] * load_dir
    # bound: round-off of the static solve: cond(K) ~ (L/d)^2 (L/h)^2 ~ 1e5, times eps, times |w|
    assert_allclose(disp, expected, rtol=0, atol=1e-9 * np.abs(expected).max())


def test_curves_with_shear_parameter_reproduce_timoshenko_field():
    # One Timoshenko element along x, tip force P along global y, which is the local y
    # axis (default orientation: local y = ẑ × x = global y), so the x-y plane (Iz, Asy)
    # bends. Exact field v(s) = P s² (3L - s) / (6 E Iz) + P s / (G Asy) (Timoshenko &
    # Gere, Mechanics of Materials, cantilever plus shear deflection), reproduced by the
    # IIE shape functions with Φ = 12 E Iz / (G Asy L²) (Friedman & Kosmatka 1993).
    length, P = 0.2, 1e3
    sec = sections.rectangle(0.05, 0.08)
    model, _, _ = _line_model(1, length, section=sec, shear=True, rotary_inertia=True)
    u = _static(model, 1, [0.0, P, 0.0])
    G = STEEL.shear_modulus
    phi = np.array([[12 * STEEL.E * sec.Iz / (G * sec.Asy * length**2),
                     12 * STEEL.E * sec.Iy / (G * sec.Asz * length**2)]])
    points, disp = beam_deflection_curves(model, u, n_sub=10, phi=phi)
    s = points[:, 0]
    expected = P * s**2 * (3 * length - s) / (6 * STEEL.E * sec.Iz) + P * s / (G * sec.Asy)
    # bound: static solve round-off: eps·cond(K) of the beam, cond ~1e5 (comment above)
    assert_allclose(disp[:, 1], expected, rtol=0, atol=1e-10 * expected.max())  # round-off
    default = beam_deflection_curves(model, u, n_sub=10)[1]  # the model's own Φ
    # bound: the same interpolation of the same displacements: ~10 eps of the largest
    assert_allclose(default, disp, rtol=0, atol=1e-12 * np.abs(disp).max())
    hermite = beam_deflection_curves(model, u, n_sub=10, phi=np.zeros((1, 2)))[1][:, 1]
    assert np.abs(hermite - expected).max() > 1e-3 * expected.max()  # Φ matters here


def test_first_mode_curve_matches_analytic_cantilever_shape():
    # Blevins, Formulas for Natural Frequency and Mode Shape, table 8-1 (clamped-free):
    # λ₁ = 1.87510407, σ₁ = 0.734095514,
    # φ(x) = cosh(λx/L) - cos(λx/L) - σ (sinh(λx/L) - sin(λx/L)).
    model, _, _ = _line_model(8, section=sections.rectangle(0.01, 0.02))
    result = fm.modes(model, n_modes=1)
    points, disp = beam_deflection_curves(model, result.shapes[:, 0], n_sub=4)
    lam, sigma = 1.87510407, 0.734095514
    x = lam * points[:, 0]
    exact = np.cosh(x) - np.cos(x) - sigma * (np.sinh(x) - np.sin(x))
    # weak bending: the section's width 0.01 m lies along local y, which is global y
    # (default orientation: local y = ẑ × x), so the bar deflects along global y
    shape = disp[:, 1] / disp[-1, 1]
    # discretisation error of an 8-element cubic Hermite mode shape: O(h^4) ~ 2e-4
    assert_allclose(shape, exact / exact[-1], rtol=0, atol=1e-3)
    # no motion in the stiff plane, up to the eigenvector's accuracy (residual / gap, the
    # two planes' frequencies differ by a factor 2): ~1e-11 measured, 1e-8 allowed
    assert_allclose(disp[:, 2], 0.0, atol=1e-8 * np.abs(disp).max())


def test_curves_validate_arguments():
    model, _, _ = _line_model(2)
    with pytest.raises(ValueError, match="shape"):
        beam_deflection_curves(model, np.zeros(5))
    with pytest.raises(ValueError, match="n_sub"):
        beam_deflection_curves(model, np.zeros(model.n_dof), n_sub=0)
    with pytest.raises(ValueError, match="phi"):
        beam_deflection_curves(model, np.zeros(model.n_dof), phi=np.zeros(2))


def test_auto_scale_and_colour_field():
    model = _frame_3d()
    result = fm.modes(model, n_modes=3)
    u = result.shapes[:, 2]
    scale = mode_scale(model, u)
    mesh = mode_mesh(model, u, scale)
    size = np.ptp(model.mesh.points, axis=0).max()
    largest = np.linalg.norm(mesh.point_data["displacement"], axis=1).max()
    # bound: definition of the scale: one product and division, a few eps
    assert_allclose(largest, SCALE_FRACTION * size, rtol=1e-12)  # definition of the scale
    magnitude = mesh.point_data["magnitude"]
    assert magnitude.min() >= 0.0
    # bound: normalised magnitudes: a division by the maximum, 1 ulp
    assert_allclose(magnitude.max(), 1.0, rtol=1e-12)
    assert np.ptp(magnitude) > 0.5  # a fixed base and a moving tip: the colours vary
    radius = mesh.point_data["radius"]
    # bound: radii from a linear map of magnitudes: a few eps
    assert radius.min() >= RADIUS_RANGE[0] * size * (1 - 1e-12)
    assert radius.max() <= RADIUS_RANGE[1] * size * (1 + 1e-12)
    assert mesh.n_points == len(model.beams.cells) * 9
    assert mode_scale(model, np.zeros(model.n_dof)) == 1.0


def test_titles():
    ms = fm.ModeSet(np.array([0.0, 17.7134]), np.array([1e-9, 1.2e4]), np.zeros((6, 2)),
                    np.array([True, False]), "dense", -1.0, np.zeros(2), None)
    assert mode_title(ms, 0) == "Mode 1: rigid-body (0 Hz)"
    assert mode_title(ms, 1) == "Mode 2: 17.71 Hz"


def test_plot_modes_writes_pngs_of_requested_size(tmp_path):
    model = _frame_3d()
    result = fm.modes(model, n_modes=2)
    files = plot_modes(model, result, tmp_path, prefix="frame", window_size=(320, 240),
                       masses=[fm.PointMass(6, 1.0)])
    assert [f.name for f in files] == ["frame_01.png", "frame_02.png"]
    for f in files:
        with Image.open(f) as img:
            assert img.size == (320, 240)
            pixels = np.asarray(img.convert("RGB"), dtype=float)
        assert pixels.std() > 10  # not a blank image
    assert sorted(p.name for p in tmp_path.iterdir()) == ["frame_01.png", "frame_02.png"]


def test_headless_backend_choice(monkeypatch):
    from femmech.output.renderer import select_headless_backend as _select_headless_backend

    monkeypatch.delenv("VTK_DEFAULT_OPENGL_WINDOW", raising=False)
    monkeypatch.setenv("DISPLAY", ":0")
    _select_headless_backend()
    assert "VTK_DEFAULT_OPENGL_WINDOW" not in os.environ  # a display: VTK decides
    monkeypatch.delenv("DISPLAY")
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr("ctypes.util.find_library", lambda name: None)
    _select_headless_backend()
    assert "VTK_DEFAULT_OPENGL_WINDOW" not in os.environ  # no EGL, no OSMesa: VTK decides
    monkeypatch.setattr("ctypes.util.find_library", lambda name: f"lib{name}.so.1")
    _select_headless_backend()
    assert os.environ["VTK_DEFAULT_OPENGL_WINDOW"] == "vtkEGLRenderWindow"


def test_plot_mode_rejects_bad_arguments(tmp_path):
    model, _, _ = _line_model(2)
    result = fm.modes(model, n_modes=2)
    with pytest.raises(ValueError, match="mode index 5"):
        plot_mode(model, result, 5, tmp_path / "x.png")
    with pytest.raises(ValueError, match="unknown camera"):
        plot_mode(model, result, 0, tmp_path / "x.png", camera="top")
    assert not list(tmp_path.iterdir())


def test_cantilever_image_matches_reference(tmp_path):
    # First bending mode of a clamped-free rectangular bar (unique direction: the weak
    # plane, deflection along global y), 4 elements drawn as smooth cubic curves, seen
    # along z.
    model, _, _ = _line_model(4, section=sections.rectangle(0.01, 0.02))
    result = fm.modes(model, n_modes=1)
    out = plot_mode(model, result, 0, tmp_path / "cantilever.png", window_size=(400, 300),
                    camera="xy")
    reference = IMAGES / "cantilever_mode1.png"
    if os.environ.get("FEMMECH_UPDATE_IMAGES"):
        reference.parent.mkdir(exist_ok=True)
        reference.write_bytes(out.read_bytes())
    error = pv.compare_images(str(out), str(reference), use_vtk=False)
    # Mean over pixels of the summed |ΔRGB| (0..765), measured against this reference
    # (report layout: header, panel and triad around the view): a 1 % camera zoom 6.1,
    # a 3 % larger displacement scale 7.8 (the size of shading and edge differences
    # between OpenGL drivers or VTK versions is below these); the bar deflecting the
    # other way 12.6, the second (stiff-plane) bending mode 11.6; re-rendering 0.0. The
    # threshold 10 separates the two groups.
    assert error < 10.0, f"image differs from {reference}: mean pixel error {error:.2f}"


def test_vtu_round_trip(tmp_path):
    model = _frame_3d()
    result = fm.modes(model, n_modes=3)
    path = export_modes_vtu(model, result, tmp_path / "modes.vtu", indices=[0, 2])
    back = meshio.read(path)
    assert_allclose(back.points, model.mesh.points, rtol=0, atol=0)
    assert_allclose(back.cells_dict["line"], model.beams.cells)
    for i in (0, 2):
        nodal = result.nodal(i)
        assert_allclose(back.point_data[f"mode_{i + 1}_displacement"], nodal[:, :3], rtol=0)
        assert_allclose(back.point_data[f"mode_{i + 1}_rotation"], nodal[:, 3:], rtol=0)
    assert "mode_2_displacement" not in back.point_data
    assert_allclose(back.field_data["frequency_hz"], result.freq_hz[[0, 2]], rtol=0)
    assert back.field_data["mode_number"].tolist() == [1, 3]
    assert back.field_data["rigid"].tolist() == [0, 0]
    assert back.field_data["group_all"].tolist() == [0]
    assert back.cell_data["group_id"][0].tolist() == [0] * len(model.beams.cells)


def test_failed_writes_leave_no_file(tmp_path, monkeypatch):
    model, _, _ = _line_model(2)
    result = fm.modes(model, n_modes=2)
    with pytest.raises(FileNotFoundError, match="does not exist"):
        export_modes_vtu(model, result, tmp_path / "missing" / "modes.vtu")
    target = tmp_path / "modes.vtu"
    target.write_text("previous")

    def partial_write(path, *args, **kwargs):
        Path(path).write_text("<VTKFile half-written")
        raise OSError("disk full")

    monkeypatch.setattr(meshio, "write", partial_write)
    with pytest.raises(OSError, match="disk full"):
        export_modes_vtu(model, result, target)
    assert target.read_text() == "previous"  # the old file is untouched
    assert [p.name for p in tmp_path.iterdir()] == ["modes.vtu"]  # no temporary left

    def interrupted_write(filename):
        with atomic_path(filename) as tmp:
            tmp.write_text("mode,freq_hz\n1,")
            raise RuntimeError("interrupted")

    with pytest.raises(RuntimeError, match="interrupted"):
        interrupted_write(tmp_path / "table.csv")
    assert [p.name for p in tmp_path.iterdir()] == ["modes.vtu"]


def test_frequency_table_and_csv(tmp_path):
    # free-free beam: six rigid-body modes first
    mesh = fm.Mesh.from_lines([[0, 0, 0], [0.5, 0, 0], [1, 0, 0]], [[0, 1], [1, 2]])
    model = fm.build_model(mesh, {"all": fm.BeamProperty(sections.circle(0.02), STEEL)})
    result = fm.modes(model, n_modes=8)
    lines = frequency_table(result).splitlines()
    assert lines[0].split() == ["mode", "freq", "[Hz]", "rigid", "residual"]
    assert len(lines) == 1 + result.n_modes
    assert lines[1].split()[:3] == ["1", "0.0000", "yes"]
    assert lines[7].split()[2] == "no"
    path = write_frequency_csv(result, tmp_path / "freq.csv")
    with path.open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert [int(r["mode"]) for r in rows] == list(range(1, result.n_modes + 1))
    assert_allclose([float(r["freq_hz"]) for r in rows], result.freq_hz, rtol=0)
    assert [bool(int(r["rigid"])) for r in rows] == result.rigid.tolist()
    assert_allclose([float(r["residual"]) for r in rows], result.residual, rtol=0)


# -- one scene per model, one camera, annotations ---------------------------------


def _decorated_frame():
    """The 3D frame with every glyph: a support (node 0), a 20 kg mass 0.2 m above node 3
    on a rigid link, a spring to the ground at node 5, and a spring from node 6 to a
    coincident node 7 that starts a short beam to node 8."""
    base = _frame_3d()
    points = np.vstack([base.mesh.points, base.mesh.points[6], base.mesh.points[6] + [0.3, 0, 0],
                        base.mesh.points[3] + [0, 0, 0.2]])
    lines = np.vstack([base.beams.cells, [[7, 8]]])
    mesh = fm.Mesh.from_lines(points, lines, node_sets={"base": [0]})
    prop = fm.BeamProperty(sections.rectangle(0.04, 0.02), STEEL)
    return fm.build_model(mesh, {"all": prop}, supports=[fm.Support("base")],
                          masses=[fm.PointMass(9, 20.0)],
                          springs=[fm.Spring(5, None, [1e5] * 3 + [0] * 3),
                                   fm.Spring(6, 7, [1e7] * 3 + [1e4] * 3)],
                          rigid_links=[fm.RigidLink(3, [9])])


def test_texts_of_the_annotations():
    # 3 significant digits, no exponent from 0.01 to 99 900 (issue: "2-3 significant digits")
    assert [format_factor(v) for v in (1234.5, 12.34, 0.04567, 2.0, 99.96, 0.01)] == \
        ["1230", "12.3", "0.0457", "2", "100", "0.01"]
    assert format_factor(3.2e6) == "3.2·10⁶"
    assert format_factor(4.5e-4) == "4.5·10⁻⁴"
    assert scale_text(4.333) == "deformation ×4.33"
    assert scale_text(1234.5, 0.12) == ("deformation ×1230 (largest displacement drawn as 12 %"
                                        " of the model size)")
    # the colours are |u| relative to the mode's largest |u|: a ratio, said so
    assert COLOUR_BAR_TITLE == ("displacement", "|u| / max |u|", "(dimensionless)")


def test_springs_links_and_legend_of_exactly_the_glyphs_drawn():
    model = _decorated_frame()
    links, springs = joined_pairs(model)
    assert links.tolist() == [[3, 9]]  # no stiffness between them: a constraint
    assert springs.tolist() == [[6, 7]]  # K couples them, no beam joins them
    nodes, directions = ground_springs(model)
    assert nodes.tolist() == [5]
    assert_allclose(directions, [[0, 0, -1]])  # equal stiffness: drawn downwards
    glyphs = model_glyphs(model)
    assert glyphs.supports.tolist() == [0]
    assert glyphs.masses.tolist() == [9]
    labels = [e.label for e in scene_legend(glyphs, True, False, True)]
    assert labels == ["undeformed", "support", "point mass", "rigid link / spider", "spring"]
    bare, _, _ = _line_model(2)
    bare_glyphs = model_glyphs(bare)
    assert [e.label for e in scene_legend(bare_glyphs, True, False, True)] == ["undeformed",
                                                                              "support"]
    assert scene_legend(model_glyphs(_free_bar()), True, False, False) == ()
    # balls only where tubes end or meet at an angle: not at the straight bar's middle
    # node, not at the frame's node 2 (on a straight run), not at the mass node 9
    assert joint_nodes(bare).tolist() == [0, 2]
    assert joint_nodes(model).tolist() == [0, 1, 3, 4, 5, 6, 7, 8]


def _free_bar():
    mesh = fm.Mesh.from_lines([[0, 0, 0], [1, 0, 0]], [[0, 1]])
    return fm.build_model(mesh, {"all": fm.BeamProperty(sections.circle(0.02), STEEL)})


def test_fit_camera_shows_all_points_centred():
    rng = np.random.default_rng(4)
    points = rng.standard_normal((200, 3)) * [2.0, 0.5, 1.0] + [10.0, -3.0, 1.0]
    for view, aspect in (("iso", 4 / 3), ("xz", 1.0), (((0.2, -1, 0.4), (0, 0, 1)), 0.6)):
        camera = fit_camera(points, view, aspect, margin=0.1)
        ndc = project(camera, points, aspect)
        # bound: projection of the scene box: a few products of O(1) values, ~10 eps
        assert np.abs(ndc).max() == pytest.approx(0.9, abs=1e-9)  # tight in one direction
        tight = int(np.argmax(np.abs(ndc).max(axis=0)))
        # centred: the extremes of the tight direction sit symmetrically
        # bound: symmetric projection of a centred box: ~10 eps of O(1) coordinates
        assert ndc[:, tight].max() == pytest.approx(-ndc[:, tight].min(), abs=1e-9)
    with pytest.raises(ValueError, match="unknown camera 'top'"):
        fit_camera(points, "top")


def test_screen_axes_of_the_named_views():
    points = np.eye(3)
    # xy: looking down z, y up; x to the right, z towards the viewer
    # bound: axis permutation of O(1) coordinates: a few eps
    assert_allclose(screen_axes(fit_camera(points, "xy")), [[1, 0, 0], [0, 1, 0], [0, 0, -1]],
                    atol=1e-12)
    # xz: looking along +y, z up, x to the right, y into the screen
    # bound: axis permutation of O(1) coordinates: a few eps
    assert_allclose(screen_axes(fit_camera(points, "xz")), [[1, 0, 0], [0, 0, 1], [0, 1, 0]],
                    atol=1e-12)


def test_one_scene_one_camera_for_all_modes(tmp_path, monkeypatch):
    import femmech.output.plot as plot

    model = _decorated_frame()
    result = fm.modes(model, n_modes=4)
    seen, texts = [], []
    render = ModeRenderer.render

    def spy_render(self, u, scale, decoration=None):
        image = render(self, u, scale, decoration)
        seen.append((id(self), [tuple(v) for v in self.plotter.camera_position],
                     self._lines.points.copy(), u, scale, image.shape))
        return image

    def spy_compose(view, background, layout, title, lines, k=1):
        texts.append((title, lines))
        return compose(view, background, layout, title, lines, k)

    compose = plot.compose
    monkeypatch.setattr(ModeRenderer, "render", spy_render)
    monkeypatch.setattr(plot, "compose", spy_compose)
    plot_modes(model, result, tmp_path, window_size=(320, 240), workers=1)
    assert len({s[0] for s in seen}) == 1  # one scene for the four images
    assert all(s[1] == seen[0][1] for s in seen)  # one camera
    camera = plot.camera_from_position(seen[0][1])
    height, width = seen[0][5][:2]
    for _, _, points, u, scale, _ in seen:
        # the scene's curves are the mode's curves (points replaced per mode)
        # bound: the same displaced points computed twice: a few eps of O(1) coordinates
        assert_allclose(points, mode_mesh(model, u, scale).points, rtol=0, atol=1e-12)
        # nothing leaves the frame: every drawn point of every mode projects inside
        glyphs = model_glyphs(model)
        ndc = project(camera, drawn_points(model, u, scale, glyphs), width / height)
        assert np.abs(ndc).max() < 1.0
    for k, (title, lines) in enumerate(texts):
        assert title == mode_title(result, k)
        scale = mode_scale(model, result.shapes[:, k])
        assert lines[-1] == (scale_text(scale, SCALE_FRACTION), scale_text(scale))
        assert len(lines) == 2
        assert lines[0]


def test_panel_draws_colour_bar_legend_and_triad():
    legend = (LegendEntry("point mass", COLORS["mass"], "circle"),
              LegendEntry("spring", COLORS["spring"], "coil"))
    layout = make_layout((640, 480), 1, legend)
    image = panel_image(layout, legend, screen_axes(fit_camera(np.eye(3), "iso")), "viridis", 2)
    assert image.shape == (480, 640, 3)
    panel = image[:, -layout.panel:].reshape(-1, 3).astype(int)
    assert (image[:, :-layout.panel] == 255).all()  # the view area stays free

    def has(color):
        rgb = np.array([int(color[i:i + 2], 16) for i in (1, 3, 5)])
        return (np.abs(panel - rgb).sum(axis=1) < 20).any()

    # viridis ends (#fde725, #440154), the glyph colours, the triad's red, green and blue
    for color in ("#fde725", "#440154", COLORS["mass"], COLORS["spring"], "#d62728",
                  "#2ca02c", "#1f77b4"):
        assert has(color), color


def test_workers_draw_the_same_images(tmp_path):
    model = _decorated_frame()
    result = fm.modes(model, n_modes=2)
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    serial = plot_modes(model, result, tmp_path / "a", window_size=(240, 180), workers=1)
    pooled = plot_modes(model, result, tmp_path / "b", window_size=(240, 180), workers=2)
    for a, b in zip(serial, pooled, strict=True):
        assert a.name == b.name
        assert np.array_equal(np.asarray(Image.open(a)), np.asarray(Image.open(b)))
    with pytest.raises(ValueError, match="workers"):
        plot_modes(model, result, tmp_path, workers=0)


def test_explicit_camera_is_used_as_given(tmp_path, monkeypatch):
    model, _, _ = _line_model(2)
    result = fm.modes(model, n_modes=1)
    seen = []
    render = ModeRenderer.render

    def spy(self, u, scale, decoration=None):
        seen.append([tuple(v) for v in self.plotter.camera_position])
        return render(self, u, scale, decoration)

    monkeypatch.setattr(ModeRenderer, "render", spy)
    position = [(0.5, -3.0, 0.2), (0.5, 0.0, 0.0), (0.0, 0.0, 1.0)]
    plot_mode(model, result, 0, tmp_path / "a.png", window_size=(200, 150), camera=position)
    # bound: a camera position passed through: exact up to a few eps
    assert_allclose(np.array(seen[0]), np.array(position), atol=1e-12)
    with pytest.raises(ValueError, match="three 3-vectors"):
        plot_mode(model, result, 0, tmp_path / "b.png", camera=[(0, 0, 1)])
