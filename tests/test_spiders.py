"""Interpolating (RBE3-like) links: exact rigid-body fit, load distribution, no stiffening."""

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from numpy.testing import assert_allclose
from roundoff import scaled_condition

import femmech as fm
from femmech.fe import sections
from femmech.fe.constraints import interpolation_matrix, rigid_link_matrix
from femmech.reduction.component_modes import craig_bampton, guyan

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)
EPS = np.finfo(float).eps


def _ring(n=16, radius=0.1, centre=True):
    """A ring of n beam elements (a bearing bore) in the x-y plane, plus its centre node."""
    t = 2 * np.pi * np.arange(n) / n
    points = np.column_stack([radius * np.cos(t), radius * np.sin(t), np.zeros(n)])
    if centre:
        points = np.vstack([points, [0.0, 0.0, 0.0]])
    lines = np.column_stack([np.arange(n), (np.arange(n) + 1) % n])
    node_sets = {"bore": np.arange(n)}
    if centre:
        node_sets["centre"] = [n]
    return fm.Mesh.from_lines(points, lines, node_sets=node_sets)


def test_interpolation_reproduces_rigid_motion():
    # For a rigid motion (u, θ) of the patch, the least-squares fit is that motion itself,
    # evaluated at the reference point: u_ref = u + θ × (x_ref - x_0). Round-off only.
    rng = np.random.default_rng(0)
    patch = rng.standard_normal((7, 3))
    reference = np.array([0.3, -0.2, 0.5])
    A = interpolation_matrix(reference, patch, rng.uniform(0.5, 2.0, 7))
    motion = rng.standard_normal(6)  # rigid motion about the reference point
    u_patch = (rigid_link_matrix(patch - reference)[:, :3, :] @ motion).ravel()
    assert_allclose(A @ u_patch, motion, rtol=0, atol=1e3 * EPS)


def test_interpolation_load_is_statically_equivalent():
    # Virtual work: patch forces f = Aᵀ F for a load F = (force, moment) on the reference;
    # their resultant force and moment about the reference equal F (MSC Nastran QRG, RBE3).
    rng = np.random.default_rng(1)
    patch = rng.standard_normal((5, 3))
    reference = np.zeros(3)
    A = interpolation_matrix(reference, patch)
    load = np.array([10.0, -4.0, 2.0, 3.0, 1.0, -5.0])
    f = (A.T @ load).reshape(-1, 3)
    assert_allclose(f.sum(axis=0), load[:3], rtol=0, atol=1e3 * EPS * np.abs(load).max())
    assert_allclose(np.cross(patch, f).sum(axis=0), load[3:], rtol=0,
                    atol=1e3 * EPS * np.abs(load).max())


@pytest.mark.parametrize("patch", [
    np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0]]),  # collinear
    np.array([[0.0, 0, 0], [1.0, 0, 0]]),  # two nodes
])
def test_degenerate_patch_is_rejected(patch):
    with pytest.raises(ValueError, match="does not determine all six DOFs"):
        interpolation_matrix(np.array([0.0, 1.0, 0.0]), patch)


def _ring_model(link=None):
    mesh = _ring()
    prop = fm.BeamProperty(sections.circle(0.01), STEEL)
    kwargs = {}
    if link == "interpolating":
        kwargs["interpolating_links"] = [fm.InterpolatingLink("centre", "bore")]
    elif link == "rigid":
        kwargs["rigid_links"] = [fm.RigidLink("centre", "bore")]
    return fm.build_model(mesh, {"all": prop}, **kwargs)


def test_interpolating_link_does_not_stiffen():
    # The massless reference node only follows the patch: the ring keeps its own elastic
    # frequencies (ring without the centre node; dense LAPACK on both, round-off level),
    # while a rigid link freezes the ring: no strain energy is left (K_free ~ round-off).
    plain = fm.build_model(_ring(centre=False), {"all": fm.BeamProperty(sections.circle(0.01),
                                                                            STEEL)})
    ref = fm.modes(plain, n_modes=12)
    with_link = fm.modes(_ring_model("interpolating"), n_modes=12)
    assert with_link.rigid.sum() == 6
    # bound: the same elastic ring with and without the followed node: 10 eps λ_max/λ_7 =
    # 3.9e-11 (roundoff.py) plus the link's transformation; measured 9e-12
    assert_allclose(with_link.freq_hz[6:], ref.freq_hz[6:], rtol=1e-9)
    rigid = _ring_model("rigid")
    assert rigid.n_free == 6
    scale = abs(plain.K).max()
    # bound: a rigid link leaves only rigid DOFs: K_free is round-off, ~n eps of the largest entry
    assert abs(rigid.K_free).max() < 1e-12 * scale


def test_reference_node_is_an_interface_of_six_dofs():
    # However fine the bore mesh, the bearing interface stays at 6 DOFs; a Guyan
    # reduction onto it reproduces the static response of the full model to a load on
    # the reference node (round-off of the two static solves: ~eps cond₂(D K D), with
    # D = diag(K)^-1/2, 1e11 here; roundoff.scaled_condition; cond₂(K) itself is 1.9e12).
    mesh = _ring(n=48)
    points = np.vstack([mesh.points, [[0.5, 0.0, 0.0]]])
    lines = np.vstack([mesh.cells["line"], [[0, 49]]])  # an arm to a clamped support
    arm = fm.Mesh.from_lines(points, lines, node_sets={**mesh.node_sets, "base": [49]})
    prop = fm.BeamProperty(sections.circle(0.01), STEEL)
    model = fm.build_model(arm, {"all": prop}, supports=[fm.Support("base")],
                           interpolating_links=[fm.InterpolatingLink("centre", "bore")])
    se = guyan(model, "centre")
    assert se.n_interface == 6
    load = np.array([0.0, 0.0, 100.0, 5.0, 0.0, 0.0])
    q = np.linalg.solve(se.K, load)
    f = np.zeros(model.n_dof)
    f[6 * 48:6 * 48 + 6] = load
    u_full = model.expand(spla.spsolve(model.K_free.tocsc(), model.T.T @ f))
    # measured 1.8e-8 (SkylakeX) and 3.9e-8 (Haswell kernel) of max|u| against the old
    # atol 1e-7 max|u|; the bound is 2.2e-5; a recovery error is O(1)
    round_off = EPS * scaled_condition(model.K_free)
    assert_allclose(se.recover(q), u_full, rtol=0, atol=round_off * np.abs(u_full).max())
    cb = craig_bampton(model, "centre", n_modes=5)
    assert cb.n_interface == 6


def test_patch_dof_clash_names_the_link():
    mesh = _ring()
    prop = fm.BeamProperty(sections.circle(0.01), STEEL)
    with pytest.raises(ValueError, match=r"interpolating link \(reference 16\)"):
        fm.build_model(mesh, {"all": prop}, interpolating_links=[
            fm.InterpolatingLink("centre", [0, 1])])
