"""Shell quality checks at run time.

Drilling cluster: a thick plate (t/a = 0.2) whose nodes rotate freely about the normal has
a cluster of spurious drilling modes near ``sqrt(12 drilling G / ρ) / (2π t)`` (884 Hz for
steel, drilling = 1e-2, t = 0.2 m; femmech.fe.elements.shell); fm.modes must report them
by number and leave structural modes (thin plates, beams) alone. Element shapes: edge
aspect ratio, quad warping and interior angles (femmech.fe.checks) reported by id and
group.
"""

import warnings

import numpy as np
import pytest

import femmech as fm
from femmech.analysis.shell_checks import (
    DRILLING_SHARE,
    drilling_findings,
    drilling_fractions,
    mode_ranges,
)
from femmech.errors import ModelWarning
from femmech.fe import checks, generators
from femmech.fe.assembly import assemble
from femmech.fe.dofs import element_dofs
from femmech.fe.elements.shell import shell_matrices

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)


def _plate_modes(t, n=8, n_modes=30, kind="quad", drilling=1e-2):
    mesh = generators.rectangular_plate(1.0, 1.0, n, n, kind=kind)
    model = fm.build_model(mesh, shells={"plate": fm.ShellProperty(t, STEEL, drilling)},
                           supports=[fm.Support("edges", "uz")])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = fm.modes(model, n_modes=n_modes)
    drilling = [str(w.message) for w in caught
                if issubclass(w.category, ModelWarning) and "drilling" in str(w.message)]
    return model, result, drilling


def _drilling_strain_share(model, result, t):
    """u_kᵀ K_drill u_k / u_kᵀ K u_k with K_drill = K(2d) - K(d) (K is linear in d)."""
    cells = model.shells.cells["quad"]
    K1, _ = shell_matrices(model.mesh.points, cells, STEEL.E, STEEL.nu, STEEL.rho, t,
                           drilling=1e-2)
    K2, _ = shell_matrices(model.mesh.points, cells, STEEL.E, STEEL.nu, STEEL.rho, t,
                           drilling=2e-2)
    Kd = assemble([(element_dofs(cells), K2 - K1)], model.n_dof).tocsr()
    u = result.shapes
    return np.einsum("ij,ij->j", u, Kd @ u) / np.einsum("ij,ij->j", u, model.K @ u)


def test_thick_plate_drilling_cluster_is_reported_by_mode_number():
    model, result, messages = _plate_modes(0.2)
    share = result.drilling
    assert share is not None
    assert share.shape == (result.n_modes,)
    elastic = ~result.rigid
    # predicted cluster frequency sqrt(12 d G / rho) / (2 pi t) (shell.py docstring)
    f_drill = np.sqrt(12 * 1e-2 * STEEL.shear_modulus / STEEL.rho) / (2 * np.pi * 0.2)
    assert f_drill == pytest.approx(884.2, abs=0.1)
    cluster = elastic & (share >= DRILLING_SHARE)
    # measured: mode 4 (835.6 Hz, first bending) share 0.0000; modes 5-30 (878.3-883.4
    # Hz) 0.998-1.000; the cluster lies within 1 % below f_drill
    assert cluster.sum() >= 20
    assert np.all(np.abs(result.freq_hz[cluster] / f_drill - 1) < 0.01)
    assert np.all(share[elastic & ~cluster] < 1e-3)
    assert np.all(share[cluster] > 0.99)
    numbers = np.flatnonzero(cluster) + 1
    assert len(messages) == 1
    assert f"modes {mode_ranges(numbers)} " in messages[0]
    # the strain-energy share of the drilling penalty tells the same (measured 0.985-0.998)
    strain = _drilling_strain_share(model, result, 0.2)
    assert np.all(strain[cluster] > 0.95)
    assert np.all(np.abs(strain[elastic & ~cluster]) < 1e-3)


def test_thin_plate_and_raised_penalty_do_not_warn():
    # t = 0.01 m: the cluster lies at 17.7 kHz, far above the 30 lowest plate modes
    _, result, messages = _plate_modes(0.01, n_modes=12)
    assert not messages
    assert np.all(result.drilling[~result.rigid] < 1e-3)
    # the thick plate with drilling = 1 (100 x 1e-2): cluster near 8.8 kHz, above the 12
    # lowest modes; its membrane modes keep a physical share ~(2 pi t / lambda)^2 / 12 in
    # the in-plane rotation θz = ω (measured at most 0.065), far below the threshold
    _, result, messages = _plate_modes(0.2, n_modes=12, drilling=1.0)
    assert not messages
    assert np.all(result.drilling[~result.rigid] < 0.1)


def test_triangles_report_the_cluster_too():
    _, result, messages = _plate_modes(0.2, n=6, n_modes=20, kind="triangle")
    assert messages
    assert np.any(result.drilling[~result.rigid] > 0.99)


def test_beam_model_has_no_drilling_share():
    mesh = generators.grid_frame((1, 1, 1), (1.0, 1.0, 1.0), subdivisions=2)
    beam = fm.BeamProperty(fm.sections.rectangular_hollow(0.05, 0.05, 0.004), STEEL)
    model = fm.build_model(mesh, {g: beam for g in mesh.cell_sets},
                           supports=[fm.Support(np.flatnonzero(mesh.points[:, 2] == 0))])
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelWarning)
        result = fm.modes(model, n_modes=6)
    assert result.drilling is None
    assert np.all(drilling_fractions(model, result.shapes) == 0.0)


def test_drilling_findings_skip_rigid_modes_and_word_ranges():
    assert mode_ranges([3, 5, 6, 7, 9]) == "3, 5-7, 9"
    f = drilling_findings(np.array([1.0, 0.9, 0.1, 0.6]), np.array([0.0, 5.0, 6.0, 7.0]),
                          rigid=np.array([True, False, False, False]))
    assert len(f) == 1
    assert "modes 2, 4 (5-7 Hz" in f[0].message
    assert drilling_findings(np.array([0.2, 0.49]), np.array([1.0, 2.0])) == []


def test_drilling_fractions_refuse_wrong_shapes():
    model, _, _ = _plate_modes(0.01, n=2, n_modes=3)
    with pytest.raises(ValueError, match="mode shapes must have shape"):
        drilling_fractions(model, np.zeros((5, 2)))


# ---- element shapes -----------------------------------------------------------------

def _quad_mesh(points, quads, group="skin"):
    return fm.Mesh(np.asarray(points, float), {"quad": np.asarray(quads)},
                   {group: {"quad": np.arange(len(quads))}})


def test_shape_measures_of_known_elements():
    # unit square: aspect 1, angles 90°, no warping
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                    [0, 0, 0], [12, 0, 0], [12, 1, 0], [0, 1, 0]], float)
    m = checks.shell_shapes(pts, "quad", np.array([[0, 1, 2, 3], [4, 5, 6, 7]]))
    np.testing.assert_allclose(m["aspect"], [1.0, 12.0])
    np.testing.assert_allclose(m["min_angle"], [90.0, 90.0])
    # bound: a plane element has zero warping: round-off of O(1) cross products
    np.testing.assert_allclose(m["warping"], [0.0, 0.0], atol=1e-15)
    # square with corners 0 and 2 raised by h: mean plane at h/2, z0 = h/2; half mean
    # diagonal sqrt(2)/2, so warping = (h/2) / (sqrt(2)/2) = h / sqrt(2)
    h = 0.1
    warped = np.array([[0, 0, h], [1, 0, 0], [1, 1, h], [0, 1, 0]], float)
    w = checks.shell_shapes(warped, "quad", np.array([[0, 1, 2, 3]]))["warping"]
    # bound: closed-form size of a square element: a few eps
    assert w[0] == pytest.approx(h / np.sqrt(2), rel=1e-12)
    # rhombus with a 20° corner; a triangle with a 5° corner
    a = np.radians(20.0)
    rhombus = np.array([[0, 0, 0], [1, 0, 0], [1 + np.cos(a), np.sin(a), 0],
                        [np.cos(a), np.sin(a), 0]])
    r = checks.shell_shapes(rhombus, "quad", np.array([[0, 1, 2, 3]]))
    assert r["min_angle"][0] == pytest.approx(20.0)
    assert r["max_angle"][0] == pytest.approx(160.0)
    b = np.radians(5.0)
    tri = np.array([[0, 0, 0], [1, 0, 0], [np.cos(b), np.sin(b), 0]])
    assert checks.shell_shapes(tri, "triangle", np.array([[0, 1, 2]]))["min_angle"][0] == \
        pytest.approx(5.0)


def test_bad_elements_are_named_with_ids_and_groups():
    # quads: 0 square, 1 long (aspect 12), 2 warped (one corner 0.2 up: z0 = 0.05, half
    # mean diagonal 0.717, warping 0.070), 3 a flat rhombus with a 10° corner
    a = np.radians(10.0)
    pts = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
           [13, 0, 0], [13, 1, 0],
           [14, 0, 0.2], [14, 1, 0],
           [20, 0, 0], [21, 0, 0], [21 + np.cos(a), np.sin(a), 0], [20 + np.cos(a), np.sin(a), 0]]
    quads = [[0, 1, 2, 3], [1, 4, 5, 2], [4, 6, 7, 5], [8, 9, 10, 11]]
    mesh = _quad_mesh(pts, quads)
    findings = checks.shape_findings(mesh.points, mesh.cells,
                                     checks.cell_groups(mesh.cell_sets, ["skin"], mesh.cells))
    text = {f.message.split(" with ")[1].split(" ")[1]: f for f in findings}
    assert len(findings) == 3
    assert all(f.kind == "element shape" for f in findings)
    assert "quad 1 (group 'skin'): 12;" in text["edge"].message
    assert "quad 2 (group 'skin'): 0.0697;" in text["off"].message  # warping
    assert "quad 3 (group 'skin'): 170.0°;" in text["angles"].message
    assert "quad 0 " not in " ".join(f.message for f in findings)
    assert set(text["edge"].nodes) == {1, 4, 5, 2}
    # cells of no checked group are skipped
    assert checks.shape_findings(mesh.points, mesh.cells,
                                 checks.cell_groups(mesh.cell_sets, [], mesh.cells)) == []


def test_build_model_warns_on_bad_shells_only():
    long = generators.rectangular_plate(20.0, 1.0, 1, 1)  # one 20:1 quad
    with pytest.warns(ModelWarning, match=r"aspect ratio .* quad 0 \(group 'plate'\): 20"):
        fm.build_model(long, shells={"plate": fm.ShellProperty(0.01, STEEL)})
    # exactly at the limit (a 10:1 quad) passes despite round-off
    at_limit = generators.rectangular_plate(10.0, 1.0, 1, 1)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelWarning)
        fm.build_model(at_limit, shells={"plate": fm.ShellProperty(0.01, STEEL)})
    good = generators.rectangular_plate(1.0, 1.0, 4, 4, kind="triangle")
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelWarning)
        fm.build_model(good, shells={"plate": fm.ShellProperty(0.01, STEEL)})


def test_shape_check_is_vectorised():
    # 250 000 quads (a 500 x 500 plate) checked in well under a second on one core
    import time

    mesh = generators.rectangular_plate(1.0, 1.0, 500, 500)
    start = time.perf_counter()
    groups = checks.cell_groups(mesh.cell_sets, ["plate"], mesh.cells)
    assert checks.shape_findings(mesh.points, mesh.cells, groups) == []
    assert time.perf_counter() - start < 5.0


def test_superelement_modes_carry_the_drilling_share():
    from femmech.reduction import craig_bampton

    mesh = generators.rectangular_plate(1.0, 1.0, 6, 6)
    model = fm.build_model(mesh, shells={"plate": fm.ShellProperty(0.2, STEEL)},
                           supports=[fm.Support("edges", "uz")])
    se = craig_bampton(model, [("corners", ["ux", "uy"])], n_modes=24)
    with pytest.warns(ModelWarning, match="drilling modes: .* modes "):
        result = fm.analysis.modes.superelement_modes(se, n_modes=12, model=model)
    assert result.drilling.shape == (result.n_modes,)
    assert np.any(result.drilling[~result.rigid] > 0.99)
    # without the model no share (and no warning)
    assert fm.analysis.modes.superelement_modes(se, n_modes=12).drilling is None
