"""Craig-Bampton's low-memory order: on large models the Sturm check of
the fixed-interface modes runs after the K_ii factorisation is freed. The order must not
change the superelement, and a failed count must fall back to the full path."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_array_equal

import femmech as fm
import femmech.reduction.component_modes as component_modes
from femmech.fe import sections
from femmech.fe.generators import grid_frame
from femmech.solve import eigen
from femmech.solve.eigen import solve_symmetric, sturm_verified

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)


@pytest.fixture(scope="module")
def model():
    """A doubly symmetric grid frame (repeated eigenvalues), 1 080 free DOFs."""
    mesh = grid_frame((2, 2, 2), (1.0, 1.0, 1.0), 4)
    prop = fm.BeamProperty(sections.rectangular_hollow(0.08, 0.08, 0.005), STEEL)
    return fm.build_model(mesh, dict.fromkeys(mesh.cell_sets, prop),
                          supports=[fm.Support("base")])


def _nodes(model):
    top = model.mesh.node_sets["top"]
    return top[:: max(1, len(top) // 4)][:4].tolist()


def test_low_memory_order_gives_the_same_superelement(model, monkeypatch):
    nodes = _nodes(model)
    # the low-memory order applies from 500k interior DOFs, where the fixed-interface modes
    # come from block Lanczos with or without the deferred count (ARPACK takes small
    # models only when it counts at once): block Lanczos on both sides here too
    monkeypatch.setattr(eigen, "ARPACK_BELOW", 0)
    normal = component_modes.craig_bampton(model, nodes, n_modes=12)
    monkeypatch.setattr(component_modes, "LOW_MEMORY_DOFS", 0)
    low = component_modes.craig_bampton(model, nodes, n_modes=12)
    # the same operations in another order: bit for bit the same reduced matrices
    assert_array_equal(low.K, normal.K)
    assert_array_equal(low.M, normal.M)
    assert_array_equal(low.modal_omega2, normal.modal_omega2)
    assert low.interior_factor is None  # freed before the count, not kept
    assert normal.interior_factor is not None
    assert set(low.timings) == set(normal.timings)


def test_a_failed_deferred_count_falls_back_to_the_checked_path(model, monkeypatch):
    nodes = _nodes(model)
    normal = component_modes.craig_bampton(model, nodes, n_modes=12)
    monkeypatch.setattr(component_modes, "LOW_MEMORY_DOFS", 0)
    calls = []

    def missed(K, M, omega2, scale=None):  # pretend a member of a cluster was missed
        calls.append(omega2.size)
        return omega2.size + 1, omega2.size
    monkeypatch.setattr(component_modes, "sturm_verified", missed)
    again = component_modes.craig_bampton(model, nodes, n_modes=12)
    assert calls  # the deferred count ran, found a mismatch and the full path took over
    assert_array_equal(again.K, normal.K)
    assert again.interior_factor is not None


def test_sturm_verified_counts_what_solve_symmetric_found(model):
    K, M = model.K_free, model.M_free
    result = solve_symmetric(K, M, n_modes=10, check=False)
    count, found = sturm_verified(K, M, result.omega2)
    # the frame's 10th and 11th eigenvalues are a symmetric pair: the cluster is complete
    assert count == found == result.omega2.size
    count, found = sturm_verified(K, M, result.omega2[[0, 1, 2, 4]])  # mode 3 left out
    assert found == 4
    # the count sees every eigenvalue up to just above λ_4 (1e-6 relative), including the
    # left-out λ_3 and the partner of λ_4 where λ_4 is one of a symmetric pair
    assert count == np.count_nonzero(result.omega2 <= result.omega2[4] * (1 + 1e-6)) > found
