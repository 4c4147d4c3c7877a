"""The discretisation-error estimate per mode against true errors.

The estimate (one h/2 refinement, Richardson with the family's rate,
:mod:`femmech.analysis.discretisation`) must lie within a factor 3 of the true relative
error of each trusted (unflagged) mode: ``truth / 3 <= estimate <= 3 truth``. Truths
come from closed forms (beams: Blevins, Formulas for Natural Frequency and Mode Shape,
1979, tables 8-1, 8-16, 8-19; Timoshenko: the Navier solution of the beam equations;
plates: Mindlin's exact solution, which tends to Leissa, NASA SP-160, 1969, table 4.20)
or, for the shell box, from two much finer meshes of the same elements (h/8, h/16)
extrapolated.
"""

import numpy as np
import pytest
import scipy.linalg as sl
from models import STEEL, mindlin_ssss, plate_cells

import femmech as fm
from femmech.analysis.discretisation import RATES, discretisation_error, match_modes
from femmech.fe.refine import refined_model
from femmech.fe.sections import rectangle

FACTOR = 3.0  # the acceptance: estimate within a factor 3 of the truth


def within_factor(est, truth, trusted):
    """Ratios est/truth of the trusted modes whose true error is above round-off; the
    assertion that each lies in [1/3, 3]."""
    # bound: truth above round-off of the frequencies (eps λ_max/λ ~1e-10 at most here)
    keep = trusted & (np.abs(truth) > 1e-9)
    ratio = est[keep] / truth[keep]
    assert keep.any()
    assert np.all((ratio >= 1 / FACTOR) & (ratio <= FACTOR)), (ratio, est, truth)
    return ratio


def line_mesh(n, L=1.0, sets=None):
    x = np.linspace(0.0, L, n + 1)
    return fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(n), np.arange(1, n + 1)]),
                              node_sets=sets or {})


def dominant(shapes):
    """Component ux/uy/uz/rx that dominates each mode (translations, else torsion)."""
    s = shapes.reshape(-1, 6, shapes.shape[1])
    trans = (s[:, :3] ** 2).sum(axis=0)
    tors = (s[:, 3] ** 2).sum(axis=0)
    comp = np.argmax(trans, axis=0)
    return np.where(tors > 10 * trans.max(axis=0), 3, comp)


def cantilever_truth(sec, L, comps):
    """Closed-form frequencies (Hz) of a cantilever, by dominant component and order.

    Bending: Blevins (1979) table 8-1, β_n L = 1.87510, 4.69409, 7.85476, 10.99554,
    14.13717; axial and torsion: tables 8-16 and 8-19, f = (2n - 1)/(4 L) sqrt(E/ρ) and
    sqrt(G J / (ρ I_p)).
    """
    bl = np.array([1.87510407, 4.69409113, 7.85475744, 10.99554073, 14.13716839])
    rA = STEEL.rho * sec.A
    table = {0: (2 * np.arange(1, 6) - 1) / (4 * L) * np.sqrt(STEEL.E / STEEL.rho),
             1: bl ** 2 / (2 * np.pi * L ** 2) * np.sqrt(STEEL.E * sec.Iz / rA),
             2: bl ** 2 / (2 * np.pi * L ** 2) * np.sqrt(STEEL.E * sec.Iy / rA),
             3: (2 * np.arange(1, 6) - 1) / (4 * L) * np.sqrt(
                 STEEL.shear_modulus * sec.J / (STEEL.rho * sec.polar_moment))}
    seen = {c: 0 for c in table}
    out = []
    for c in comps:
        out.append(table[c][seen[c]])
        seen[c] += 1
    return np.array(out)


def test_euler_bernoulli_cantilever_against_blevins():
    sec = rectangle(0.05, 0.02)
    model = fm.build_model(line_mesh(4, sets={"root": [0]}),
                           {"all": fm.BeamProperty(sec, STEEL, shear=False,
                                                   rotary_inertia=False)},
                           supports=[fm.Support("root")])
    est = discretisation_error(model, n_modes=8, levels=3)
    res = fm.modes(model, n_modes=8)
    truth = res.freq_hz / cantilever_truth(sec, 1.0, dominant(res.shapes)) - 1
    ratio = within_factor(est.error, truth, est.trusted)
    # p = 2 for lines (axial, torsion); pure bending converges as h⁴ and is over-estimated
    # by (4/3)/(16/15) = 1.25 asymptotically: conservative, never optimistic
    assert np.all(ratio > 0.95)
    assert np.nanmax(est.rate_observed) > 3.5  # the h⁴ of bending is seen with 3 levels


def timoshenko_ss(n, sec, L=1.0):
    """Navier solution of a simply supported Timoshenko beam (bending in x-z):
    ``w = W sin kx, ψ = Ψ cos kx``, k = nπ/L; the lowest root of the 2 x 2 pencil."""
    k, kGA, EI = n * np.pi / L, STEEL.shear_modulus * sec.Asz, STEEL.E * sec.Iy
    K = np.array([[kGA * k ** 2, -kGA * k], [-kGA * k, EI * k ** 2 + kGA]])
    M = np.diag([STEEL.rho * sec.A, STEEL.rho * sec.Iy])
    return np.sqrt(sl.eigh(K, M, eigvals_only=True)[0]) / (2 * np.pi)


def test_timoshenko_simply_supported_against_navier_solution():
    sec = rectangle(0.04, 0.12)  # stocky: L/h = 8, shear and rotary inertia matter
    mesh = line_mesh(4, sets={"all": np.arange(5), "ends": [0, 4]})
    model = fm.build_model(mesh, {"all": fm.BeamProperty(sec, STEEL)},
                           supports=[fm.Support("all", ["ux", "uy", "rx", "rz"]),
                                     fm.Support("ends", ["uz"])])
    est = discretisation_error(model, n_modes=4)
    truth = est.freq_hz / np.array([timoshenko_ss(n, sec) for n in range(1, 5)]) - 1
    assert np.all(np.abs(truth[:3]) < 0.1)  # the right modes: all bending in x-z
    # mode 4 (one element per half-wave, 33 % too high) changes by 28 %: flagged
    assert list(est.flag) == ["", "", "", "not asymptotic"]
    ratio = within_factor(est.error, truth, est.trusted)
    assert np.all(ratio > 0.95)  # measured 1.03-1.05


def plate_model(n, tri=False, t=0.01, kind=None):
    """Hard simply supported square plate 1 m x 1 m, n x n MITC4 (or 2 n² MITC3, or
    ``kind``), in-plane DOFs fixed; supports on node sets, which refinement extends
    along the edges."""
    kind = kind or ("triangle" if tri else "quad")
    points, cells = plate_cells(n, kind)
    x, y = points[:, 0], points[:, 1]
    sets = {"all": np.arange(len(points)),
            "ex": np.flatnonzero(np.isclose(x, 0) | np.isclose(x, 1)),
            "ey": np.flatnonzero(np.isclose(y, 0) | np.isclose(y, 1))}
    mesh = fm.Mesh(points, {kind: cells}, {"plate": {kind: np.arange(len(cells))}}, sets)
    return fm.build_model(mesh, shells={"plate": fm.ShellProperty(t, STEEL)},
                          supports=[fm.Support("all", ["ux", "uy", "rz"]),
                                    fm.Support("ex", ["uz", "rx"]),
                                    fm.Support("ey", ["uz", "ry"])])


def mindlin_hz(m, n, t=0.01, k=5.0 / 6.0):
    """Mindlin (1951) exact frequency (Hz) of mode (m, n) of the hard simply supported unit
    square plate of STEEL: the frequency parameter ``models.mindlin_ssss`` (which tends to
    Leissa's Kirchhoff values λ = π² (m² + n²)) as ω = λ √(D / (ρ t)) for a = 1 m."""
    D = STEEL.E * t ** 3 / (12 * (1 - STEEL.poisson_ratio ** 2))
    return mindlin_ssss(m, n, t, 1.0, k) * np.sqrt(D / (STEEL.rho * t)) / (2 * np.pi)


PLATE_TRUTH = np.sort([mindlin_hz(m, n) for m in range(1, 4) for n in range(1, 4)])[:6]


@pytest.mark.parametrize("tri", [False, True], ids=["MITC4", "MITC3"])
def test_simply_supported_plate_against_mindlin(tri):
    est = discretisation_error(plate_model(8, tri), n_modes=6)
    truth = est.freq_hz / PLATE_TRUTH - 1
    assert np.all(est.trusted[:3])  # 8 x 8: modes (1, 3), (3, 1) change by 13-18 %: flagged
    ratio = within_factor(est.error, truth, est.trusted)
    assert np.all(ratio > 0.8)  # measured 0.96-1.05 (rate 2.0-2.1)


@pytest.mark.parametrize("kind", ["quad9", "triangle6"])
def test_quadratic_shell_plate_against_mindlin(kind):
    # 4 x 4 MITC9 (2 x 16 MITC6): rates 3.9-4.0 (3.2-3.8) measured; p = 4 (3)
    est = discretisation_error(plate_model(4, kind=kind), n_modes=6)
    truth = est.freq_hz / PLATE_TRUTH - 1
    assert est.trusted.sum() >= 4
    ratio = within_factor(est.error, truth, est.trusted)
    assert np.all(ratio > 0.8)


def test_coarse_plate_modes_are_flagged_not_printed_plain():
    # 4 x 4 MITC4: modes (1, 3)/(3, 1) change by 60 % on refinement: not asymptotic
    est = discretisation_error(plate_model(4), n_modes=6)
    assert "not asymptotic" in set(est.flag)
    assert est.max_error() == np.inf
    k = int(np.flatnonzero(est.flag == "not asymptotic")[0])
    assert est.describe(k).startswith("≥")
    # the lower bound shown is the change on refinement, below the true error (the
    # modes converge from above): (1, 3) is 64 % too high on 4 x 4
    truth = est.freq_hz / PLATE_TRUTH - 1
    assert np.all(est.change[est.flag == "not asymptotic"] <= truth[est.flag == "not asymptotic"])


def tube(nx, ny, nz, L=1.2, W=0.4, H=0.3):
    """Rectangular tube of MITC4 quads along x (section W x H), node set "root" at x = 0."""
    per = np.vstack([np.column_stack([np.linspace(0, W, ny + 1)[:-1], np.zeros(ny)]),
                     np.column_stack([np.full(nz, W), np.linspace(0, H, nz + 1)[:-1]]),
                     np.column_stack([np.linspace(W, 0, ny + 1)[:-1], np.full(ny, H)]),
                     np.column_stack([np.zeros(nz), np.linspace(H, 0, nz + 1)[:-1]])])
    m, x = len(per), np.linspace(0, L, nx + 1)
    points = np.column_stack([np.repeat(x, m), np.tile(per, (nx + 1, 1))])
    i = np.arange(len(points)).reshape(nx + 1, m)
    j = np.roll(i, -1, axis=1)
    q = np.column_stack([i[:-1].ravel(), i[1:].ravel(), j[1:].ravel(), j[:-1].ravel()])
    return fm.Mesh(points, {"quad": q}, {"wall": {"quad": np.arange(len(q))}}, {"root": i[0]})


def box_model():
    """Cantilevered box beam 1.2 x 0.4 x 0.3 m, walls 10 mm, 12 x (4 + 3) x 2 MITC4 (0.1 m)."""
    return fm.build_model(tube(12, 4, 3), shells={"wall": fm.ShellProperty(0.01, STEEL)},
                          supports=[fm.Support("root")])


# f₀ of the box's first 8 modes: Richardson (p = 2) of h/4 and h/8 (10752 MITC4 quads),
# matched to the coarse modes by MAC; recomputed by test_box_truth (slow); observed
# rates between the levels 2.0-2.2
BOX_TRUTH = np.array([174.22922821, 185.21119999, 186.05281779, 219.02573165,
                      232.78888438, 267.77506702, 283.7205501, 325.41970614])


def box_truth(model, n_modes=8):
    coarse = fm.modes(model, n_modes=n_modes)
    freq = []
    for k in (2, 3):
        fine = fm.modes(refined_model(model, k), n_modes=n_modes + 6)
        pick, mac = match_modes(coarse, fine, model.M, model.mesh.n_nodes)
        assert np.all(mac > 0.9)
        freq.append(fine.freq_hz[pick])
    return freq[1] - (freq[0] - freq[1]) / 3.0


def test_shell_box_against_finer_meshes():
    est = discretisation_error(box_model(), n_modes=8)
    truth = est.freq_hz / BOX_TRUTH - 1
    assert np.all(est.mac > 0.99)
    ratio = within_factor(est.error, truth, est.trusted)
    assert np.all(ratio > 0.9)  # measured 0.96-1.02
    assert est.trusted.sum() >= 6  # mode 6 (10.4 % change) is flagged


@pytest.mark.slow
def test_box_truth():
    assert np.allclose(box_truth(box_model()), BOX_TRUTH, rtol=1e-6)


def test_rates_cover_the_refinable_kinds():
    from femmech.fe.refine import REFINABLE

    assert set(RATES) == set(REFINABLE) - {"vertex"}


# --- the report: the error budget per mode (discretisation + reduction) -------------------

SCENE = """
[scene]
name = "budget"

[materials.steel]
E = "210 GPa"
nu = 0.3
rho = "7850 kg/m^3"

[parts.frame.generator]
kind = "grid_frame"
bays = [1, 1, 1]
size = ["1 m", "0.5 m", "0.8 m"]
subdivisions = 1

[parts.frame.sections.beams_x]
section = "tube"
outer_diameter = "60 mm"
inner_diameter = "50 mm"
material = "steel"

[parts.frame.sections.beams_y]
section = "tube"
outer_diameter = "50 mm"
inner_diameter = "40 mm"
material = "steel"

[parts.frame.sections.columns]
section = "tube"
outer_diameter = "80 mm"
inner_diameter = "70 mm"
material = "steel"

[[parts.frame.supports]]
nodes = "base"

[parts.frame.reduction]
method = "craig_bampton"
n_modes = 8
interface = [{ nodes = "top", dofs = ["uz"] }]

[analyses.modes]
n_modes = 4
images = 0
vtu = false
"""


@pytest.mark.parametrize("model", ["reduced", "full"])
def test_scene_report_shows_the_error_budget(tmp_path, model):
    import tomllib

    from femmech.scene.load import Scene
    from femmech.scene.run import run_scene

    data = tomllib.loads(SCENE)
    data["analyses"]["modes"]["model"] = model
    plain = run_scene(Scene.from_dict(data, tmp_path), tmp_path / "plain", cache_dir=None)
    data["analyses"]["modes"]["discretisation_error"] = True
    budget = run_scene(Scene.from_dict(data, tmp_path), tmp_path / "budget", cache_dir=None)
    before, after = plain.results["modes"], budget.results["modes"]
    assert "discretisation_error" not in before  # default output unchanged
    assert after["freq_hz"] == before["freq_hz"]
    error = np.array(after["discretisation_error"], dtype=float)
    assert error.shape == (4,)
    # a frame of one beam element per member: the estimate against the same scene on
    # a mesh refined three times (Richardson of h/4 and h/8 with p = 2)
    from femmech.fe.refine import refined_model
    from femmech.scene.build import part_model, prepare

    prepared = prepare(Scene.from_dict(data, tmp_path))
    full = part_model(prepared.scene, prepared.scene.parts["frame"], prepared.meshes["frame"])
    f = [fm.modes(refined_model(full, k) if k else full, n_modes=4).freq_hz for k in (0, 2, 3)]
    truth = f[0] / (f[2] - (f[1] - f[2]) / 3) - 1
    ok = np.isfinite(error)
    within_factor(error[ok], truth[ok], np.ones(ok.sum(), dtype=bool))
    html = budget.report.read_text(encoding="utf-8")
    assert "discretisation error (h/2 estimate)" in html
    assert ("total estimated error" in html) == (model == "reduced")
    assert "discretisation error" not in plain.report.read_text(encoding="utf-8")


def test_builder_function_gives_the_same_estimate_as_the_kept_inputs():
    sec = rectangle(0.05, 0.02)
    prop = {"all": fm.BeamProperty(sec, STEEL)}

    def build(mesh):
        return fm.build_model(mesh, prop, supports=[fm.Support("root")])

    mesh = line_mesh(3, sets={"root": [0]})
    a = discretisation_error(build, mesh=mesh, n_modes=4)
    b = discretisation_error(build(mesh), n_modes=4)
    # bound: the same model built two ways: identical matrices, eigensolver round-off eps λ_max/λ
    assert np.allclose(a.error, b.error, rtol=1e-9)
    with pytest.raises(ValueError, match="mesh="):
        discretisation_error(build, n_modes=4)
    with pytest.raises(ValueError, match="rate"):
        discretisation_error(build(mesh), n_modes=4, rate=-1.0)
