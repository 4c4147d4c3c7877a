"""Result series for ParaView (femmech.output.series): written, then read back with meshio
(PVD: each step's VTU; XDMF: meshio's TimeSeriesReader), and compared with the arrays."""

import meshio
import numpy as np
import pytest

import femmech as fm
from femmech.coupling import couple
from femmech.output.series import (
    read_pvd,
    write_mode_series,
    write_response_series,
    write_sweep_series,
)
from femmech.reduction import craig_bampton


@pytest.fixture(scope="module")
def cantilever():
    x = np.linspace(0.0, 1.0, 11)
    mesh = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(10), np.arange(1, 11)]),
                              node_sets={"root": [0], "tip": [10]})
    steel = fm.Material(E=210e9, nu=0.3, rho=7850.0)
    model = fm.build_model(mesh, {"all": fm.BeamProperty(fm.sections.rectangle(0.03, 0.05), steel)},
                           supports=[fm.Support("root")])
    return model, fm.modes(model, n_modes=4)


@pytest.mark.parametrize("suffix", [".pvd", ".xdmf"])
def test_mode_series_reads_back(cantilever, tmp_path, suffix):
    model, modes = cantilever
    path = write_mode_series(model, modes, tmp_path / f"modes{suffix}")
    nodal = modes.shapes.reshape(model.mesh.n_nodes, 6, -1)
    if suffix == ".pvd":
        steps = read_pvd(path)
        assert [t for t, _ in steps] == [1.0, 2.0, 3.0, 4.0]  # time = mode number
        for k, (_, vtu) in enumerate(steps):
            mesh = meshio.read(vtu)
            np.testing.assert_array_equal(mesh.points, model.mesh.points)
            np.testing.assert_array_equal(mesh.point_data["displacement"], nodal[:, :3, k])
            np.testing.assert_array_equal(mesh.point_data["rotation"], nodal[:, 3:, k])
            assert mesh.field_data["frequency_hz"][0] == modes.freq_hz[k]
    else:
        with meshio.xdmf.TimeSeriesReader(path) as reader:
            points, _ = reader.read_points_cells()
            np.testing.assert_allclose(points, model.mesh.points)
            assert reader.num_steps == 4
            for k in range(4):
                t, point_data, _ = reader.read_data(k)
                assert t == k + 1
                # bound: XML text round trip: repr-exact in meshio's writer, allow the last digit
                np.testing.assert_allclose(point_data["displacement"], nodal[:, :3, k],
                                           rtol=1e-12, atol=1e-12 * np.abs(nodal).max())


def test_sweep_and_response_series_recover_the_frame(cantilever, tmp_path):
    """Quasi-modes of a superelement frame without mechanisms are its modes at every
    angle (a rectangular section: the first two modes are distinct, not a pair): the
    recovered displacement of branch 1 is the full model's mode 1 (up to sign and the
    reduction error, 1e-6 relative for 8 fixed-interface modes + residuals)."""
    from femmech.analysis.response import Response
    from femmech.analysis.sweep import sweep

    model, modes = cantilever
    se = craig_bampton(model, ["tip"], n_modes=8, residual_vectors=True)
    system = couple(se, [])
    result = sweep(system, np.deg2rad([0.0, 90.0]), n_modes=2, keep_vectors=True)
    path = write_sweep_series(model, system, result, tmp_path / "sweep.pvd")
    steps = read_pvd(path)
    assert [t for t, _ in steps] == [0.0, 90.0]  # time = drive angle in degrees
    u = meshio.read(steps[1][1]).point_data["branch_1_displacement"]
    ref = modes.shapes.reshape(model.mesh.n_nodes, 6, -1)[:, :3, 0]
    sign = np.sign(np.vdot(u.ravel(), ref.ravel()))
    assert np.abs(sign * u - ref).max() <= 1e-5 * np.abs(ref).max()

    q = np.zeros((3, system.n))
    q[:, 0] = [0.0, 1e-3, 2e-3]  # first interface DOF of the tip: ux
    t = np.array([0.0, 0.1, 0.2])
    history = Response(t, q, q, q, 10.0 * t)
    path = write_response_series(model, system, history, tmp_path / "response.xdmf")
    with meshio.xdmf.TimeSeriesReader(path) as reader:
        reader.read_points_cells()
        times = [reader.read_data(k)[0] for k in range(reader.num_steps)]
        last = reader.read_data(2)[1]["displacement"]
    assert times == [0.0, 0.1, 0.2]
    assert last[10, 0] == pytest.approx(2e-3)  # the tip moved by the prescribed 2 mm


def test_bad_requests_name_the_problem(cantilever, tmp_path):
    model, modes = cantilever
    with pytest.raises(ValueError, match=r"suffix must be one of \('.pvd', '.xdmf'\)"):
        write_mode_series(model, modes, tmp_path / "modes.vtu")
    with pytest.raises(ValueError, match="mode index 7 does not exist"):
        write_mode_series(model, modes, tmp_path / "modes.pvd", indices=[7])
    with pytest.raises(FileNotFoundError, match="does not exist"):
        write_mode_series(model, modes, tmp_path / "missing" / "modes.pvd")


def test_rewriting_a_pvd_series_replaces_it_whole(cantilever, tmp_path):
    model, modes = cantilever
    write_mode_series(model, modes, tmp_path / "modes.pvd")
    write_mode_series(model, modes, tmp_path / "modes.pvd", indices=[0, 1])
    assert len(read_pvd(tmp_path / "modes.pvd")) == 2
    assert sorted(p.name for p in (tmp_path / "modes_steps").iterdir()) == [
        "step_00000.vtu", "step_00001.vtu"]
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []
