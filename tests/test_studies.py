"""Design studies on executors: process pool, any executor, Dask.

The reference of every parallel result is the serial evaluation of the same function in
this process: jobs are independent, so the arrays must be equal exactly (not to a
tolerance). The test chart is the damped Mathieu equation of tests/test_stability.py,
x'' + 2ζω₀ x' + ω₀²(1 + ε cos Ωt) x = 0 (principal tongue at Ω = 2ω₀ for ε > 4ζ;
Nayfeh & Mook, Nonlinear Oscillations 1979, sect. 5.4), built from module-level
functions so that the jobs pickle.
"""

from __future__ import annotations

import functools
import operator
import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from femmech.analysis import stability, studies

W0, ZETA = 10.0, 0.01
SPEEDS = np.linspace(17.0, 23.0, 7)
EPSILONS = np.array([0.0, 0.03, 0.08])
N_STEPS = 64


def hill_stiffness(t, Omega, eps):
    """C(t) = ω₀² (1 + ε cos Ωt), shape (len(t), 1, 1)."""
    return (W0**2 * (1.0 + eps * np.cos(Omega * t)))[:, None, None]


def damped_mathieu(Omega, eps):
    """(M, B, C(t), period) of the damped Mathieu equation, picklable."""
    return 1.0, 2 * ZETA * W0, functools.partial(hill_stiffness, Omega=Omega, eps=eps), \
        2 * np.pi / Omega


def cam_on_beam(c2):
    """A cam follower (follower spring c2, N/m) on a simply supported beam, built inside
    the job: symbolic mechanisms do not pickle (tests/test_stability.py's machine)."""
    import sympy

    import femmech as fm
    from femmech.coupling import Attachment, Mount, couple
    from femmech.fe import sections
    from femmech.mechanisms import (
        CamProfile,
        CamSegment,
        Mechanism,
        PointMass,
        RotaryInertia,
        Spring,
        polynomial_345,
        position_function,
        rheolinear,
    )
    from femmech.reduction.component_modes import craig_bampton

    x = np.linspace(0.0, 1.0, 21)
    mesh = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(20), np.arange(1, 21)]),
                              node_sets={"ends": [0, 20], "mid": [10]})
    prop = fm.BeamProperty(sections.rectangular_hollow(0.06, 0.08, 0.004),
                           fm.Material(E=210e9, nu=0.3, rho=7850.0))
    beam = fm.build_model(mesh, {"all": prop}, supports=[
        fm.Support("ends", "translations"), fm.Support(0, ["rx"])])
    cam = CamProfile((CamSegment(np.pi, 0.02, polynomial_345()),
                      CamSegment(np.pi, -0.02, polynomial_345())))
    theta, q1, yg, q2 = sympy.symbols("theta q1 y_g q2")
    J1, m2, c1, k2 = sympy.symbols("J1 m2 c1 c2")
    mech = Mechanism((q1, yg, q2, theta),
                     (RotaryInertia(J1, theta + q1),
                      PointMass(m2, (yg + position_function("U")(theta + q1) + q2,)),
                      Spring(c1, q1), Spring(k2, q2)), drives=(theta,))
    model = rheolinear(mech, {"J1": 0.05, "m2": 3.0, "c1": 2e4, "c2": c2}, {"U": cam})
    return couple(craig_bampton(beam, "mid", n_modes=4),
                  [Mount(model, (Attachment("y_g", 10, "uy"),), name="cam")])


def failing_job(x):
    if x == 3:
        raise ValueError("bad design 3")
    return x


@pytest.fixture(scope="module")
def pool():
    """One process pool of two workers shared by the tests that pass an executor."""
    with studies.process_executor(max_workers=2) as executor:
        yield executor


@pytest.fixture(scope="module")
def serial_chart():
    with threadpool_limits(1):  # as in the workers (2x2 matrices: no threading anyway)
        return stability.stability_chart(damped_mathieu, SPEEDS, EPSILONS, n_steps=N_STEPS,
                                         parameter_name="ε (-)")


def _assert_same_chart(chart, ref):
    np.testing.assert_array_equal(chart.speeds, ref.speeds)
    np.testing.assert_array_equal(chart.values, ref.values)
    np.testing.assert_array_equal(chart.spectral_radius, ref.spectral_radius)  # exact
    np.testing.assert_array_equal(chart.stable, ref.stable)
    np.testing.assert_array_equal(chart.periods, ref.periods)
    assert (chart.tol, chart.parameter_name) == (ref.tol, ref.parameter_name)


def test_chart_sanity(serial_chart):
    # ε = 0 damped: stable everywhere; ε = 0.08 > 4ζ: the principal tongue at 2ω₀ = 20
    assert serial_chart.stable[0].all()
    assert not serial_chart.stable[2, SPEEDS.tolist().index(20.0)]


def test_process_pool_chart_equals_serial(serial_chart):
    # the default path: a pool of two worker processes made (and shut down) by the call
    chart = studies.stability_chart(damped_mathieu, SPEEDS, EPSILONS, n_steps=N_STEPS,
                                    parameter_name="ε (-)", max_workers=2, timeout=120)
    _assert_same_chart(chart, serial_chart)


def test_workers_run_with_one_blas_thread(pool):
    limits = studies.run(_worker_threads, [()] * 2, executor=pool)
    assert all(n == 1 for n in limits)


def _worker_threads():
    from threadpoolctl import threadpool_info

    np.ones((2, 2)) @ np.ones((2, 2))
    return max(lib["num_threads"] for lib in threadpool_info())


def test_any_executor_and_a_speed_line(serial_chart):
    # threads share this process: one BLAS thread each (with OpenBLAS's 2 threads under
    # each of the 2 pool threads the 7 points took 4.2 s, with 1 well under a second)
    with ThreadPoolExecutor(max_workers=2) as pool, threadpool_limits(1):
        chart = studies.stability_chart(functools.partial(damped_mathieu, eps=0.08), SPEEDS,
                                        n_steps=N_STEPS, executor=pool)
    np.testing.assert_array_equal(chart.spectral_radius, serial_chart.spectral_radius[2:])
    assert chart.values is None


def test_run_and_grid_keep_job_order(pool):
    jobs = [(i, 10 * i) for i in range(11)]
    assert studies.run(operator.add, jobs, executor=pool) == [11 * i for i in range(11)]
    assert studies.run(operator.add, jobs, max_workers=1) == [11 * i for i in range(11)]
    assert studies.run(operator.add, []) == []
    g = studies.grid(operator.mul, [1, 2, 3], [10, 20], executor=pool)
    assert g.shape == (3, 2)
    np.testing.assert_array_equal(np.array(g.tolist()), [[10, 20], [20, 40], [30, 60]])


def test_a_failing_job_is_named(pool):
    with pytest.raises(ValueError, match="bad design 3") as info:
        studies.run(failing_job, [(i,) for i in range(6)], executor=pool, chunksize=2)
    assert any("jobs 2..3 of 6" in note for note in info.value.__notes__)


def test_bad_arguments():
    with ThreadPoolExecutor(1) as pool, pytest.raises(ValueError, match="not both"):
        studies.run(abs, [(1,)], executor=pool, client=object())
    with pytest.raises(TypeError, match="Executor"):
        studies.run(abs, [(1,)], executor="threads")
    with pytest.raises(TypeError, match="distributed.Client"):
        studies.run(abs, [(1,)], client=object())
    assert studies.default_workers() >= 1
    assert studies.default_workers(1) == 1


def test_dask_local_cluster_chart_equals_serial(serial_chart):
    distributed = pytest.importorskip("distributed")
    import cloudpickle

    # this test module is not importable on the workers: ship its functions by value
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    try:
        with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                      dashboard_address=None, host="127.0.0.1") as cluster, \
                distributed.Client(cluster, timeout=60) as client:
            chart = studies.stability_chart(damped_mathieu, SPEEDS, EPSILONS,
                                            n_steps=N_STEPS, parameter_name="ε (-)",
                                            client=client, timeout=120)
            assert len(client.scheduler_info()["workers"]) == 2
    finally:
        cloudpickle.unregister_pickle_by_value(sys.modules[__name__])
    _assert_same_chart(chart, serial_chart)


def test_sweep_variants_equal_serial_sweeps(pool):
    from femmech.analysis.sweep import sweep

    phi = np.linspace(0.0, 2 * np.pi, 13)
    variants = [2e5, 5e5]
    sweeps = studies.sweep_variants(cam_on_beam, variants, phi, executor=pool, n_modes=3,
                                    timeout=300)
    with threadpool_limits(1):  # the workers' setting
        serial = [sweep(cam_on_beam(v), phi, n_modes=3) for v in variants]
    for got, ref in zip(sweeps, serial, strict=True):
        np.testing.assert_array_equal(got.freq_hz, ref.freq_hz)
    # a stiffer follower spring raises the lowest branch (sanity of the variants)
    assert sweeps[1].freq_hz[:, 0].mean() > sweeps[0].freq_hz[:, 0].mean()
