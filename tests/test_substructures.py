"""Assembly of superelements and FE parts; Craig-Bampton with residual vectors."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

import femmech as fm
from femmech.analysis.modes import superelement_modes
from femmech.fe import sections
from femmech.fe.generators import grid_frame
from femmech.fe.mesh import line_submesh
from femmech.reduction.component_modes import craig_bampton
from femmech.reduction.substructures import assemble_parts
from femmech.solve.eigen import solve_symmetric

PROP = fm.BeamProperty(sections.rectangular_hollow(0.1, 0.1, 0.005),
                       fm.Material(E=210e9, nu=0.3, rho=7850.0))
N_MODES = 20


def _model(mesh):
    return fm.build_model(mesh, {name: PROP for name in mesh.cell_sets},
                          supports=[fm.Support("base")])


@pytest.fixture(scope="module")
def split_frame():
    """A 4 x 2 x 2-bay frame (3,294 DOFs) and its two halves cut at x = 2 m."""
    mesh = grid_frame((4, 2, 2), (4.0, 2.0, 2.0), subdivisions=6)
    full = fm.modes(_model(mesh), n_modes=N_MODES)
    middle = mesh.points[mesh.cells["line"]].mean(axis=1)[:, 0]
    halves = [line_submesh(mesh, middle < 2.0), line_submesh(mesh, middle >= 2.0)]
    cut = np.setdiff1d(np.intersect1d(halves[0][1], halves[1][1]), mesh.node_sets["base"])
    parts = [(_model(sub), np.flatnonzero(np.isin(ids, cut))) for sub, ids in halves]
    return full, parts


def _frequencies(assembly):
    result = solve_symmetric(assembly.K, assembly.M, n_modes=N_MODES)
    return np.sqrt(result.omega2) / (2 * np.pi), result


@pytest.mark.parametrize(("n_modes", "residual", "tol"), [
    # measured max errors over the 20 modes: 8.98e-3 (60 modes), 2.80e-5 (60 modes +
    # residual vectors); tolerances 1.5x the measurement, far below the Guyan error (1.5e-1)
    (60, False, 1.35e-2),
    (60, True, 4.2e-5),
])
def test_split_and_reassembled_frame_matches_full(split_frame, n_modes, residual, tol):
    full, parts = split_frame
    ses = [craig_bampton(m, cut, n_modes=n_modes, residual_vectors=residual)
           for m, cut in parts]
    assembly = assemble_parts(ses)
    f, _ = _frequencies(assembly)
    error = (f - full.freq_hz) / full.freq_hz
    # bound: Rayleigh-Ritz: the assembled reduced model gives upper bounds (round-off 1e-9)
    assert error.min() > -1e-9
    assert error.max() < tol


def test_mixed_fe_part_and_superelement(split_frame):
    # One half kept as a plain FE part: only the other half's reduction error remains.
    full, parts = split_frame
    (m0, _), (m1, cut1) = parts
    assembly = assemble_parts([m0, craig_bampton(m1, cut1, n_modes=60,
                                                 residual_vectors=True)])
    # the superelement's interface merges into the FE part's DOFs; it adds its 60 modes
    # and one residual vector per interface DOF
    assert assembly.n_dof == m0.n_free + 60 + 6 * len(cut1)
    f, result = _frequencies(assembly)
    error = (f - full.freq_hz) / full.freq_hz
    # bound: Rayleigh-Ritz upper bounds; allowance for both solves' eps λ_max/λ (roundoff.py)
    assert error.min() > -1e-9
    assert error.max() < 4.2e-5  # as above (measured 2.8e-5)
    # recovery per part: the FE half's vector at the cut equals the superelement's
    shape0 = assembly.recover(result.vectors[:, 0], 0).reshape(-1, 6)
    shape1 = assembly.recover(result.vectors[:, 0], 1).reshape(-1, 6)
    p0, p1 = m0.mesh.points, m1.mesh.points
    for node in cut1:
        other = np.flatnonzero(np.all(np.isclose(p0, p1[node]), axis=1))[0]
        # bound: the same interface DOFs in both parts: eigenvector round-off ~eps λ_max/gap
        assert_allclose(shape1[node], shape0[other], rtol=0, atol=1e-12)


def test_parts_without_shared_dofs_are_rejected(split_frame):
    _, parts = split_frame
    m0 = parts[0][0]
    moved = fm.build_model(
        fm.Mesh(m0.mesh.points + [100.0, 0, 0], m0.mesh.cells, m0.mesh.cell_sets,
                m0.mesh.node_sets), {n: PROP for n in m0.mesh.cell_sets},
        supports=[fm.Support("base")])
    with pytest.raises(ValueError, match="part 0 shares no DOF"):
        assemble_parts([m0, moved])
    with pytest.raises(TypeError, match="Superelement or FEModel"):
        assemble_parts([m0, "frame"])


@pytest.fixture(scope="module")
def machine_frame():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "examples" / "frame_modes.py"
    spec = importlib.util.spec_from_file_location("frame_modes", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    model = module.build()
    return model, fm.modes(model, n_modes=12)


def test_residual_vectors_on_shipped_frame(machine_frame):
    # Shipped machine frame, interface = 4 feet + motor (30 DOFs), 10 lowest modes
    # (4.9-58.4 Hz). Measured max relative errors: plain CB with modes up to 2x f_10
    # (8 modes) 1.4e-2; with residual vectors 1.4e-6 (< 0.1 % by far).
    model, full = machine_frame
    f_max = full.freq_hz[9]
    plain = superelement_modes(craig_bampton(model, ["feet", "motor"], f_max_hz=f_max,
                                             residual_vectors=False), n_modes=10, model=model)
    se = craig_bampton(model, ["feet", "motor"], f_max_hz=f_max, residual_vectors=True)
    assert (se.kinds == "residual").sum() == 30
    aug = superelement_modes(se, n_modes=10, model=model)
    err_plain = (plain.freq_hz - full.freq_hz[:10]) / full.freq_hz[:10]
    err_aug = (aug.freq_hz - full.freq_hz[:10]) / full.freq_hz[:10]
    # bound: Rayleigh-Ritz upper bounds; allowance for both solves' eps λ_max/λ (roundoff.py)
    assert err_aug.min() > -1e-9  # upper bounds
    assert err_aug.max() < 1e-3  # the acceptance threshold
    assert err_aug.max() < 1e-3 * err_plain.max()  # residual vectors gain > 1000x
    # bound: where the true error is measurable (> 5e-9; the full ARPACK solve itself is good
    # to ~1e-10 relative), the estimate tracks it within 15 % (measured ratios 0.95-1.00)
    measurable = err_aug > 5e-9
    assert measurable.sum() >= 5
    ratio = aug.error_estimate[measurable] / err_aug[measurable]
    assert np.all((ratio > 0.85) & (ratio < 1.1))
    mac = (aug.shapes.T @ (model.M @ full.shapes[:, :10])) ** 2  # both mass-normalised
    assert np.diag(mac).min() > 0.99


def test_residual_vectors_nested_and_converging(machine_frame):
    # Bases are nested as modes are added (span(Φ_k) + K⁻¹ M span(Ψ)), so the reduced
    # frequencies decrease monotonically towards the full ones.
    model, full = machine_frame
    previous = None
    for n in (0, 4, 10, 20):
        se = craig_bampton(model, ["feet", "motor"], n_modes=n, residual_vectors=True)
        f = superelement_modes(se, n_modes=10).freq_hz
        # bound: Rayleigh-Ritz upper bounds; allowance for both solves' eps λ_max/λ (roundoff.py)
        assert np.all(f >= full.freq_hz[:10] * (1 - 1e-9))
        if previous is not None:
            assert np.all(f <= previous * (1 + 1e-9))
        previous = f


def test_residual_vectors_survive_save_and_load(machine_frame, tmp_path):
    model, _ = machine_frame
    se = craig_bampton(model, ["feet", "motor"], n_modes=4, residual_vectors=True)
    back = type(se).load(se.save(tmp_path / "frame.npz"))
    assert back.n_residual == se.n_residual == 30
    assert list(back.kinds) == list(se.kinds)
    q = np.arange(se.n_reduced, dtype=float)
    assert_allclose(back.recover(q), se.recover(q), rtol=0, atol=0)
