"""Craig-Bampton with a reduced interface (femmech.reduction.interface_modes).

Reference: plain Craig-Bampton with residual vectors on the whole interface (the
"unreduced-interface model" of the issue), reduced with the same fixed-interface modes.
Model: a steel grid space frame of hollow beams (as benchmarks/peers.py ``frame``, 2 x 2
x 2 bays of 0.5 m, 4 elements per member, base clamped: 1 080 free DOFs), interface all
nodes of the top face (``rails``: 270 DOFs); mechanisms: spring-masses hung on rail nodes.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
import sympy

import femmech as fm
from femmech.coupling import Attachment, Mount, couple, frame_row
from femmech.fe import sections
from femmech.fe.generators import grid_frame
from femmech.mechanisms import rheolinear
from femmech.mechanisms.symbolic import Mechanism, PointMass, Spring
from femmech.reduction import craig_bampton
from femmech.reduction.interface_modes import (
    attachment_loads,
    interface_error_estimates,
    reduce_interface,
)

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)
SECTION = sections.rectangular_hollow(0.08, 0.08, 0.005)


def _frame(supported: bool = True):
    mesh = grid_frame((2, 2, 2), (1.0, 1.0, 1.0), 4)
    prop = fm.BeamProperty(SECTION, STEEL)
    supports = [fm.Support("base")] if supported else []
    return fm.build_model(mesh, dict.fromkeys(mesh.cell_sets, prop), supports=supports)


def _rails(model):
    z = model.mesh.points[:, 2]
    return np.flatnonzero(np.isclose(z, z.max()))


def _lowest(K, M, n):
    w, X = sla.eigh(K, M, subset_by_index=[0, n - 1])
    return np.sqrt(np.clip(w, 0.0, None)) / (2 * np.pi), w, X


def _spring_mass(mass, f_hz):
    """Mass ``mass`` (kg) on a spring of natural frequency ``f_hz`` (Hz on a rigid base);
    y_g is the base motion (attached to the frame), q the spring's stretch."""
    theta, yg, q = sympy.symbols("theta y_g q")
    k = mass * (2 * np.pi * f_hz) ** 2
    mech = Mechanism((yg, q, theta), (PointMass(mass, (yg + q,)), Spring(k, q)),
                     drives=(theta,))
    return rheolinear(mech, {}, {})


@pytest.fixture(scope="module")
def case():
    model = _frame()
    rails = _rails(model)
    full = fm.modes(model, 12)
    f_max = float(full.freq_hz[9])
    picks = rails[[2, 11, 20, 33]]
    se = craig_bampton(model, rails.tolist(), f_max_hz=f_max)
    cc = reduce_interface(model, rails.tolist(), f_max_hz=f_max, attachments=picks.tolist())
    mech = _spring_mass(200.0, 0.6 * f_max)
    mounts = [Mount(mech, (Attachment("y_g", int(n), "uz"),), name=f"m{i}")
              for i, n in enumerate(picks)]
    return dict(model=model, rails=rails, f_max=f_max, picks=picks, se=se, cc=cc,
                mounts=mounts, full=full)


def _coupled(frame, mounts, n=30):
    system = couple(frame, mounts)
    M, _, C, _ = system.matrices(0.0)
    f, w, X = _lowest(C, M, n)
    return f, w, X, system


def test_interface_is_reduced(case):
    cc, se = case["cc"], case["se"]
    assert cc.method == "craig-bampton-cc"
    assert cc.n_interface == se.n_interface == 270
    assert cc.n_boundary < 0.5 * cc.n_interface  # a fraction of the interface DOFs
    V = cc.interface_basis
    assert V.shape == (270, cc.n_boundary)
    assert cc.Psi.shape[1] == cc.n_boundary
    # M_G-orthonormal with diagonal S: the CC block of K_r is diagonal, of M_r the identity
    n_c = cc.n_boundary
    # bound: M_G-normalised eigenvectors of the dense interface problem: ~n eps·cond(M_G)
    assert np.allclose(cc.M[:n_c, :n_c], np.eye(n_c), atol=1e-9)
    Kc = cc.K[:n_c, :n_c]
    # bound: K_r diagonal by M-orthonormality: off-diagonals ~n eps·cond(M_G) of the dense solve
    assert np.abs(Kc - np.diag(np.diag(Kc))).max() <= 1e-9 * np.abs(Kc).max()
    assert set(cc.kinds) == {"interface mode", "modal", "residual"}


def test_coupled_frequencies_match_whole_interface(case):
    # The accuracy target: coupled quasi-eigenfrequencies in the band within 0.1 %
    # of the unreduced-interface model. Measured 2e-6 here (benchmarks at 24k/151k DOFs);
    # the assertion keeps the 1e-3 with the margin as the estimate's test below.
    ref = _coupled(case["se"], case["mounts"])[0]
    got = _coupled(case["cc"], case["mounts"])[0]
    band = ref <= case["f_max"]
    assert band.sum() >= 10
    err = np.abs(got[band] - ref[band]) / ref[band]
    assert err.max() < 1e-3
    # bound: Rayleigh-Ritz from above; allowance for both solvers' eps λ_max/λ (roundoff.py)
    assert np.all(got[band] >= ref[band] * (1 - 1e-9))  # Rayleigh-Ritz: from above


def test_superelement_modes_match_whole_interface(case):
    ref = _lowest(case["se"].K, case["se"].M, 12)[0]
    got = _lowest(case["cc"].K, case["cc"].M, 12)[0]
    band = ref <= case["f_max"]
    assert (np.abs(got[band] - ref[band]) / ref[band]).max() < 1e-4


def test_error_estimate_tracks_true_error(case):
    # interface_error_estimates against the true error of each band mode relative to the
    # full (unreduced) model: the superelement alone against femmech.modes, the coupled
    # modes against the whole-interface model (itself within ~1e-6 of the full one, so
    # only modes with a true error above 1e-5 are compared). First-order estimate:
    # agreement within a factor 2 (measured 0.97-1.0).
    model, cc = case["model"], case["cc"]
    f, w, X = _lowest(cc.K, cc.M, 10)
    est = interface_error_estimates(model, cc, w, X)
    true = (f - case["full"].freq_hz[:10]) / case["full"].freq_hz[:10]
    # bound: true errors above both solves' round-off eps λ_max/λ (roundoff.py)
    big = true > 1e-9
    assert big.any()
    assert np.all((est[big] > 0.5 * true[big]) & (est[big] < 2 * true[big]))
    ref = _coupled(case["se"], case["mounts"])[0]
    fc, wc, Xc, system = _coupled(cc, case["mounts"])
    band = ref <= case["f_max"]
    loads = attachment_loads(cc, system, 0.0, wc, Xc)
    est_c = interface_error_estimates(model, cc, wc, Xc[:system.n_frame], loads)
    true_c = (fc - ref) / ref
    # bound: estimates are >= 0 in exact arithmetic; allowance ~eps-level of O(1e-3) estimates
    assert np.all(est_c[band] >= -1e-12)
    big = band & (true_c > 1e-5)
    if big.any():
        ratio = est_c[big] / true_c[big]
        assert np.all((ratio > 0.5) & (ratio < 2))
    # the estimate is small exactly where the reduced model is accurate
    assert est_c[band].max() < 1e-3


def test_attachment_row_uses_interface_basis(case):
    cc, node = case["cc"], int(case["picks"][1])
    row = frame_row(cc, node, "uz")
    ell = np.zeros(cc.T.shape[1])
    ell[np.searchsorted(case["model"].free, 6 * node + 2)] = 1.0
    assert np.allclose(row[:cc.n_boundary], ell[cc.free_interface] @ cc.interface_basis)
    assert not row[cc.n_boundary:].any()


def test_recovery_of_a_coupled_mode(case):
    # the recovered full field of the reduced-interface model equals that of the plain
    # model's corresponding mode (MAC on all DOFs), and its interface DOFs are V η_c
    # (an isolated mode: the symmetric frame has pairs, whose shapes are not unique)
    cc, se = case["cc"], case["se"]
    f, _, X = _lowest(cc.K, cc.M, 11)
    _, _, Y = _lowest(se.K, se.M, 11)
    gap = np.minimum(np.diff(f)[:-1], np.diff(f)[1:]) / f[1:-1]
    j = 1 + int(np.argmax(gap))
    assert gap[j - 1] > 1e-3
    u, v = cc.recover(X[:, j]), se.recover(Y[:, j])
    mac = (u @ v) ** 2 / ((u @ u) * (v @ v))
    assert mac > 0.9999
    uf = cc.expand_free(X[:, j])
    assert np.allclose(uf[cc.free_interface], cc.interface_basis @ X[:cc.n_boundary, j])


def test_whole_interface_equals_plain_craig_bampton():
    # cc_modes >= n_b spans the whole interface: the same Ritz space as plain CB+RV, so
    # equal frequencies to round-off (dense eigh of two 300-coordinate pencils: ~1e-12).
    model = _frame()
    top = _rails(model)[:10]  # 60 interface DOFs
    se = craig_bampton(model, top.tolist(), n_modes=20)
    cc = reduce_interface(model, top.tolist(), n_modes=20, cc_modes=1000)
    assert cc.n_boundary == se.n_interface
    a, b = _lowest(se.K, se.M, 30)[0], _lowest(cc.K, cc.M, 30)[0]
    # bound: the same reduced pencil by two constructions: eps λ_max/λ of dense eigh
    assert np.allclose(a, b, rtol=1e-9, atol=0)


def test_free_free_component():
    # No supports: K is singular (6 rigid-body modes); the shifted factorisation of
    # K - σM handles it. Six zero frequencies and the elastic ones within 1e-4 of plain CB.
    model = _frame(supported=False)
    rails = _rails(model).tolist()
    f_max = float(fm.modes(model, 16).freq_hz[15])
    se = craig_bampton(model, rails, f_max_hz=f_max)
    cc = reduce_interface(model, rails, f_max_hz=f_max, cc_modes="auto")
    f_ref, f = _lowest(se.K, se.M, 16)[0], _lowest(cc.K, cc.M, 16)[0]
    assert np.all(f[:6] < 1e-3 * f_ref[6])
    assert np.all(f_ref[:6] < 1e-3 * f_ref[6])
    assert (np.abs(f[6:] - f_ref[6:]) / f_ref[6:]).max() < 1e-4


def test_bad_input_names_the_parameter(case):
    model, rails = case["model"], case["rails"].tolist()
    with pytest.raises(ValueError, match="cc_modes"):
        reduce_interface(model, rails, f_max_hz=100.0, cc_modes=-1)
    with pytest.raises(ValueError, match="cc_modes"):
        reduce_interface(model, rails, f_max_hz=100.0, cc_modes="many")
    with pytest.raises(ValueError, match="cc_modes='auto' needs f_max_hz"):
        reduce_interface(model, rails, n_modes=5, cc_modes="auto")
    with pytest.raises(ValueError, match="attachments: node 0 is not an interface node"):
        reduce_interface(model, rails, f_max_hz=100.0, attachments=[0])
    with pytest.raises(ValueError, match="exactly one of n_modes"):
        reduce_interface(model, rails, n_modes=5, f_max_hz=100.0)
    with pytest.raises(ValueError, match="no interface basis"):
        reduce_interface(model, rails, n_modes=5)


def test_save_refuses_reduced_interface(case, tmp_path):
    with pytest.raises(ValueError, match="reduced interface"):
        case["cc"].save(tmp_path / "cc.npz")
    assert not list(tmp_path.iterdir())


def test_assembly_refuses_reduced_interface(case):
    from femmech.reduction import assemble_parts
    with pytest.raises(ValueError, match="part 0 has a reduced interface"):
        assemble_parts([case["cc"], case["cc"]])


def test_estimate_flags_mounts_on_undeclared_nodes(case):
    # Mounted on interface nodes not declared as attachments, the reduced interface
    # misses the local flexibility under the point loads: measured 97 % error on this
    # frame (traces only). The estimate must flag it (it is first order, so only its
    # size is asserted: beyond first order it came out at 0.3-20x the true error).
    model = case["model"]
    cc = reduce_interface(model, case["rails"].tolist(), f_max_hz=case["f_max"])
    ref = _coupled(case["se"], case["mounts"])[0]
    f, w, X, system = _coupled(cc, case["mounts"])
    band = ref <= case["f_max"]
    est = interface_error_estimates(model, cc, w, X[:system.n_frame],
                                    attachment_loads(cc, system, 0.0, w, X))
    true = (f - ref) / ref
    assert true[band].max() > 0.1
    assert est[band].max() > 0.1
    # (per mode, sorted frequencies pair different shapes once errors are this large, so
    # the band maximum is the flag: "do not trust this reduced model in this band")
