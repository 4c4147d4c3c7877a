"""Model building: springs, point masses, input validation and vectorised assembly.

References are computed independently of femmech in each test: 6x6 rigid-body
eigenproblems with ``scipy.linalg.eigh``, rigid-body kinematics with ``np.cross``,
series springs, inertia tensors by the parallel-axis theorem, and a dense assembly by
an explicit Python loop over the elements.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp
from numpy.testing import assert_allclose, assert_array_equal
from scipy.spatial.transform import Rotation

import femmech as fm
import femmech.fe.model as fm_model
from femmech.fe import sections
from femmech.fe.assembly import assemble
from femmech.fe.elements.beam import beam_matrices

EPS = np.finfo(float).eps
STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)
PROP = fm.BeamProperty(sections.circle(0.02), STEEL)
AXES = Rotation.from_rotvec([0.3, -0.5, 0.8]).as_matrix()  # a general rotation, rows = axes


def rigid_map(offset):
    """6x6 map from rigid-body motion (u, θ) at a point to the motion at ``point + offset``,
    built column by column from ``u + θ × r``."""
    G = np.zeros((6, 6))
    for c in range(6):
        q = np.eye(6)[c]
        G[:3, c] = q[:3] + np.cross(q[3:], offset)
        G[3:, c] = q[3:]
    return G


def lumped_only_mesh(points):
    return fm.Mesh(np.asarray(points, dtype=float), {})


# -------------------------------------------------------------------------------- springs


def test_single_mass_on_ground_spring_frequencies_exact():
    m, inertia = 2.5, np.array([0.4, 0.9, 0.1])
    k = np.array([1e4, 4e4, 9e4, 30.0, 50.0, 70.0])
    model = fm.build_model(lumped_only_mesh([[0.1, 0.2, 0.3]]), {},
                           masses=[fm.PointMass(0, m, inertia)],
                           springs=[fm.Spring(0, None, k)])
    result = fm.modes(model, n_modes=6)
    # bound: f = sqrt(k / m) / 2π per uncoupled DOF; dense 6x6: round-off
    ref = np.sort(np.sqrt(k / np.r_[m, m, m, inertia])) / (2 * np.pi)
    assert_allclose(result.freq_hz, ref, rtol=1e-12)


def _rigid_body_on_mounts():
    """A rigid body (master at the centre of mass, four slave mount points) on 4 mounts."""
    centre = np.array([0.2, -0.1, 0.5])
    corners = np.array([[0.6, 0.4, 0.0], [-0.6, 0.4, 0.0], [-0.6, -0.4, 0.0],
                        [0.6, -0.4, 0.1]])
    mass = 120.0
    inertia = np.array([[9.0, 0.5, -0.3], [0.5, 12.0, 0.8], [-0.3, 0.8, 15.0]])
    mounts = [np.array([2e5, 3e5, 8e5, 0, 0, 0]), np.array([2e5, 3e5, 8e5, 0, 0, 0]),
              np.array([1e5, 1e5, 5e5, 50.0, 50.0, 50.0]), np.array([4e5, 1e5, 6e5, 0, 0, 0])]
    axes = [None, AXES, None, AXES.T]
    return centre, corners, mass, inertia, mounts, axes


def test_rigid_body_on_four_mounts_matches_6x6_eigenproblem():
    centre, corners, mass, inertia, mounts, axes = _rigid_body_on_mounts()
    points = np.vstack([centre, corners])
    springs = [fm.Spring(i + 1, None, k, a) for i, (k, a) in enumerate(zip(mounts, axes,
                                                                           strict=True))]
    model = fm.build_model(lumped_only_mesh(points), {},
                           masses=[fm.PointMass(0, mass, inertia)], springs=springs,
                           rigid_links=[fm.RigidLink(0, [1, 2, 3, 4])])
    # reference: rigid body on resilient mounts, K = Σ Gᵢᵀ (Tᵢᵀ kᵢ Tᵢ) Gᵢ (mount stiffness
    # rotated to global axes, Gᵢ the rigid map from the centre to mount i: strain energy
    # of each mount under a rigid motion), M = [[m I, 0], [0, J]] about the centre of mass
    K_ref = np.zeros((6, 6))
    for corner, k, a in zip(corners, mounts, axes, strict=True):
        R = np.eye(3) if a is None else a
        Tr = np.kron(np.eye(2), R)
        G = rigid_map(corner - centre)
        K_ref += G.T @ Tr.T @ np.diag(k) @ Tr @ G
    M_ref = sla.block_diag(mass * np.eye(3), inertia)
    ref = np.sqrt(sla.eigh(K_ref, M_ref, eigvals_only=True)) / (2 * np.pi)
    result = fm.modes(model, n_modes=6)
    assert model.n_free == 6
    # bound: assembled sums in another order: ~n eps of the largest entry
    assert_allclose(model.K_free.toarray(), K_ref, rtol=0, atol=1e-12 * np.abs(K_ref).max())
    assert_allclose(result.freq_hz, ref, rtol=1e-10)  # bound: dense 6x6 both: round-off


def test_node_to_node_spring_in_series_with_a_bar():
    # bar 0-1 (EA/L), spring 1-2 (k along x) with node 2 coincident with node 1
    L, k = 0.8, 3e6
    points = np.array([[0.0, 0, 0], [L, 0, 0], [L, 0, 0]])
    mesh = fm.Mesh.from_lines(points, [[0, 1]])
    stiffness = np.array([k, 1e9, 1e9, 1e9, 1e9, 1e9])
    model = fm.build_model(mesh, {"all": PROP}, springs=[fm.Spring(1, 2, stiffness)],
                           supports=[fm.Support(0)])
    f = np.zeros(model.n_dof)
    f[12] = 1e3  # N along x at node 2
    u = model.expand(np.linalg.solve(model.K_free.toarray(), model.T.T @ f))
    EA = STEEL.E * sections.circle(0.02).A
    # series springs: u₂ = F (L / EA + 1 / k)
    # bound: static solve of 2 springs in series: eps·cond, cond ~ EA/(kL) + 1
    assert_allclose(u[12], 1e3 * (L / EA + 1 / k), rtol=1e-12)
    # bound: static solve of springs in series: eps·cond of the 2-spring system
    assert_allclose(u[6], 1e3 * L / EA, rtol=1e-12)


def test_spring_axes_rotate_the_stiffness():
    k = np.array([1e3, 2e3, 5e3, 10.0, 20.0, 40.0])
    model = fm.build_model(lumped_only_mesh([[0.0, 0, 0]]), {},
                           springs=[fm.Spring(0, None, k, AXES)])
    K = model.K_free.toarray()
    for i in range(6):
        # a load along local axis i gives a displacement along that axis, |u| = F / kᵢ
        direction = np.zeros(6)
        direction[3 * (i // 3):3 * (i // 3) + 3] = AXES[i % 3]
        u = np.linalg.solve(K, direction)
        # bound: static solve of one spring: a few eps; atol for the zero components
        assert_allclose(u, direction / k[i], rtol=1e-12, atol=1e-14 / k[i])


def test_scalar_spring_stiffness_is_translational_only():
    spring = fm.Spring(0, None, 5e3)
    assert_allclose(spring.matrix(), np.diag([5e3] * 3 + [0.0] * 3), rtol=0, atol=0)


@pytest.mark.parametrize(("stiffness", "axes", "match"), [
    (np.triu(np.ones((6, 6))), None, "stiffness is not symmetric"),
    (-np.eye(6), None, "stiffness is not positive semi-definite"),
    (np.diag([1, 1, 1, 1, 1, -1.0]), None, "stiffness is not positive semi-definite"),
    (np.ones(5), None, r"stiffness must have shape \(6, 6\) or \(6,\)"),
    ([1, 1, 1, 1, 1, np.nan], None, "stiffness has non-finite entries"),
    (np.ones(6), np.ones((3, 3)), "axes must be a 3x3 rotation matrix"),
])
def test_spring_stiffness_errors(stiffness, axes, match):
    spring = fm.Spring(0, None, stiffness, axes)
    with pytest.raises(ValueError, match=r"spring 0-None: " + match):
        fm.build_model(lumped_only_mesh([[0.0, 0, 0]]), {}, springs=[spring])


def test_spring_from_a_node_to_itself_is_an_error():
    mesh = fm.Mesh.from_lines([[0.0, 0, 0], [1.0, 0, 0]], [[0, 1]], node_sets={"tip": [1]})
    with pytest.raises(ValueError, match="spring 'tip'-1 connects node 1 to itself"):
        fm.build_model(mesh, {"all": PROP}, springs=[fm.Spring("tip", 1, 1e3)])


def test_spring_node_group_must_hold_one_node():
    mesh = fm.Mesh.from_lines([[0.0, 0, 0], [1.0, 0, 0]], [[0, 1]])
    with pytest.raises(ValueError, match="spring: group 'all' holds 2 nodes"):
        fm.build_model(mesh, {"all": PROP}, springs=[fm.Spring("all", None, 1e3)])


# --------------------------------------------------------------------------- point masses


def _beam_with_masses():
    section = sections.rectangle(0.04, 0.1)
    L = 1.2
    points = np.array([[0.0, 0, 0], [L / 2, 0, 0], [L, 0, 0]])
    mesh = fm.Mesh.from_lines(points, [[0, 1], [1, 2]])
    masses = [fm.PointMass(2, 7.0, [[0.3, 0.05, 0.0], [0.05, 0.2, 0.01], [0.0, 0.01, 0.4]]),
              fm.PointMass(1, 3.0, [0.1, 0.2, 0.3]), fm.PointMass(0, 1.0)]
    model = fm.build_model(mesh, {"all": fm.BeamProperty(section, STEEL)}, masses=masses)
    return model, section, L, masses


def test_total_mass_is_beams_plus_point_masses():
    model, section, L, masses = _beam_with_masses()
    # bound: ρ A L + Σ m (consistent mass: the rigid translation is exact)
    ref = STEEL.rho * section.A * L + sum(p.mass for p in masses)
    assert_allclose(model.total_mass(), ref, rtol=1e-13)


def test_rotational_inertia_about_a_point_matches_parallel_axis_theorem():
    model, section, L, masses = _beam_with_masses()
    p = np.array([0.2, 0.5, -0.4])  # pivot, m
    rho = STEEL.rho
    m_beam = rho * section.A * L
    # beam along x about its centre: ρ Ip L about x, m L²/12 + ρ I L about y and z
    # (slender-rod inertia plus the sections' rotary inertia)
    J = np.diag([rho * (section.Iy + section.Iz) * L, m_beam * L**2 / 12 + rho * section.Iy * L,
                 m_beam * L**2 / 12 + rho * section.Iz * L])
    items = [(np.array([L / 2, 0, 0]), m_beam, J)]
    for pm in masses:
        Jm = np.zeros((3, 3)) if pm.inertia is None else np.asarray(pm.inertia, dtype=float)
        Jm = np.diag(Jm) if Jm.ndim == 1 else Jm
        items.append((model.mesh.points[pm.node], pm.mass, Jm))
    I_ref = np.zeros((3, 3))
    for x, m, Jc in items:  # parallel-axis (Steiner) theorem
        r = x - p
        I_ref += Jc + m * (r @ r * np.eye(3) - np.outer(r, r))
    # model: kinetic energy of the rigid rotations ω = e_i about p, q = (ω × (x - p), ω)
    Q = np.zeros((model.n_dof, 3))
    for i in range(3):
        w = np.eye(3)[i]
        nodal = np.column_stack([np.cross(w, model.mesh.points - p),
                                 np.tile(w, (model.mesh.n_nodes, 1))])
        Q[:, i] = nodal.ravel()
    I_model = Q.T @ (model.M @ Q)
    # bound: the consistent mass reproduces rigid motions exactly: round-off
    assert_allclose(I_model, I_ref, rtol=0, atol=1e-12 * np.abs(I_ref).max())


@pytest.mark.parametrize(("mass", "match", "error"), [
    (fm.PointMass(0, -1.0), "point mass at 0: mass must be >= 0, got -1.0", ValueError),
    (fm.PointMass(0, np.nan), "point mass at 0: mass must be >= 0", ValueError),
    (fm.PointMass(0, 1.0, np.eye(2)), r"point mass at 0: inertia must have shape \(3, 3\)",
     ValueError),
    (fm.PointMass(0, 1.0, [1, 2, 3, 4]), r"inertia must have shape \(3, 3\) or \(3,\)",
     ValueError),
    (fm.PointMass(0, 1.0, [[1, 2, 0], [0, 1, 0], [0, 0, 1]]), "inertia is not symmetric",
     ValueError),
    (fm.PointMass(0, 1.0, [1, -2, 3]), "inertia is not positive semi-definite", ValueError),
    (fm.PointMass(5, 1.0), "point mass: node 5 does not exist", ValueError),
    (fm.PointMass("hub", 1.0), "point mass: unknown group 'hub'", ValueError),
])
def test_point_mass_errors(mass, match, error):
    mesh = fm.Mesh.from_lines([[0.0, 0, 0], [1.0, 0, 0]], [[0, 1]])
    with pytest.raises(error, match=match):
        fm.build_model(mesh, {"all": PROP}, masses=[mass])


def test_mass_nodes_are_recorded():
    model, *_ = _beam_with_masses()
    assert_array_equal(model.mass_nodes, [2, 1, 0])


# ------------------------------------------------------------------------- input checking


def _line_points(n):
    return np.column_stack([np.arange(n, dtype=float), np.zeros(n), np.zeros(n)])


@pytest.mark.parametrize(("points", "lines", "cell_sets", "beams", "match"), [
    (_line_points(3), [[0, 1], [1, 2]], {"a": [0], "b": [1]}, {"a": PROP},
     r"line element 1 \(nodes \[1, 2\]\) has no beam property .*its groups: \['b'\]"),
    (_line_points(3), [[0, 1], [1, 2]], {"a": [0, 1], "b": [1]}, {"a": PROP, "b": PROP},
     "line element 1 is in groups 'a' and 'b', both with beam properties"),
    (_line_points(3), [[0, 1], [1, 2]], {"a": [0, 1], "b": [1]}, {"frame": PROP},
     r"beam property for unknown group 'frame'; the mesh has cell sets \['a', 'b'\]"),
    (_line_points(4), [[0, 1], [1, 2]], None, {"all": PROP},
     r"node 3 at \[3.0, 0.0, 0.0\] is not used"),
    (np.array([[0.0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 0, 0]]), [[0, 1], [2, 3]], None,
     {"all": PROP}, "nodes 1 and 2 coincide at .* no spring or rigid link joins them"),
    (np.array([[0.0, 0, 0], [1, 0, 0], [1, 0, 0]]), [[0, 1], [1, 2]], None, {"all": PROP},
     r"element 1 \(nodes 1 and 2\) has zero length"),
    (_line_points(3), [[0, 1], [1, 2]], None,
     {"all": fm.BeamProperty(PROP.section, STEEL, orientation=[2.0, 0, 0])},
     r"element 0 \(nodes 0-1\): orientation vector \[2.0, 0.0, 0.0\] is parallel"),
    (_line_points(3), [[0, 1], [1, 2]], None,
     {"all": fm.BeamProperty(PROP.section, STEEL, orientation=[0.0, 0, 0])},
     "orientation of a beam group must be a non-zero 3-vector"),
])
def test_model_input_errors_name_the_item(points, lines, cell_sets, beams, match):
    mesh = fm.Mesh.from_lines(points, lines, cell_sets)
    with pytest.raises(ValueError, match=match):
        fm.build_model(mesh, beams)


def test_coincident_nodes_joined_by_spring_or_rigid_link_are_accepted():
    points = np.array([[0.0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 0, 0]])
    mesh = fm.Mesh.from_lines(points, [[0, 1], [2, 3]])
    by_spring = fm.build_model(mesh, {"all": PROP}, springs=[fm.Spring(1, 2, np.full(6, 1e6))])
    by_link = fm.build_model(mesh, {"all": PROP}, rigid_links=[fm.RigidLink(1, [2])])
    assert by_spring.n_free == 24
    assert by_link.n_free == 18


@pytest.mark.parametrize(("make", "match"), [
    (lambda: fm.Mesh([[0.0, 0, 0], [1, 0, 0], [2, np.nan, 0]], {"line": [[0, 1], [1, 2]]}),
     "node 2 has non-finite coordinates"),
    (lambda: fm.Mesh([[0.0, 0, 0], [1, 0, 0]], {"line": [[0, 1], [1, 7]]}),
     r"line cell 1 \(nodes \[1, 7\]\) references node 7, but the mesh has 2 nodes"),
    (lambda: fm.Mesh([[0.0, 0, 0], [1, 0, 0]], {"line": [[0, 1]]}, {"a": {"line": [3]}}),
     "cell set 'a' references line cell 3, but the mesh has 1"),
    (lambda: fm.Mesh([[0.0, 0, 0], [1, 0, 0]], {"line": [[0, 1]]}, node_sets={"p": [2]}),
     "node set 'p' references node 2, but the mesh has 2 nodes"),
    (lambda: fm.Mesh([[0.0, 0, 0], [1, 0, 0]], {"line": [[0.0, 1.0]]}),
     "line connectivity must be integer"),
    (lambda: fm.Mesh([[0.0, 0, 0], [1, 0, 0]], {"polygon": [[0, 1]]}),
     "unsupported cell type 'polygon'"),
    (lambda: fm.Mesh(np.zeros((2, 4)), {}), r"points must have shape \(n_nodes, 3\)"),
])
def test_mesh_input_errors_name_the_item(make, match):
    with pytest.raises(ValueError, match=match):
        make()


def test_triangle_cells_without_shell_property_raise_clear_error():
    points = [[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]
    mesh = fm.Mesh(points, {"line": [[0, 1]], "triangle": [[0, 1, 2]]},
                   {"frame": {"line": [0]}, "plate": {"triangle": [0]}})
    with pytest.raises(ValueError, match=r"\['triangle'\] cells, which have no element property"):
        fm.build_model(mesh, {"frame": PROP})


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"beams": {"all": {"section": PROP.section, "material": STEEL}}},
     r"beams\['all'\] must be a BeamProperty, got dict"),
    ({"beams": PROP}, "beams must be a dict"),
    ({"beams": {"all": fm.BeamProperty(STEEL, PROP.section)}},
     r"beams\['all'\]: section must be a BeamSection"),
    ({"beams": {"all": PROP}, "masses": [(0, 1.0)]}, r"masses\[0\] must be a PointMass"),
    ({"beams": {"all": PROP}, "springs": [fm.PointMass(0, 1.0)]},
     r"springs\[0\] must be a Spring, got PointMass"),
    ({"beams": {"all": PROP}, "supports": ["all"]}, r"supports\[0\] must be a Support"),
    ({"beams": {"all": PROP}, "rigid_links": [(0, [1])]}, r"rigid_links\[0\] must be a RigidL"),
])
def test_wrong_types_raise_type_error(kwargs, match):
    mesh = fm.Mesh.from_lines(_line_points(2), [[0, 1]])
    with pytest.raises(TypeError, match=match):
        fm.build_model(mesh, **kwargs)


# ------------------------------------------------------------------------------- assembly


def _small_frame():
    """Three beams in 3D, two groups (one with an orientation), a spring and a mass."""
    points = np.array([[0.0, 0, 0], [0.0, 0, 1.0], [0.8, 0.3, 1.2], [0.8, 0.3, 0.0]])
    mesh = fm.Mesh.from_lines(points, [[0, 1], [1, 2], [2, 3]],
                              {"posts": [0, 2], "rail": [1]})
    rail = fm.BeamProperty(sections.i_section(0.1, 0.06, 0.005, 0.008),
                           fm.Material(E=70e9, nu=0.33, rho=2700.0), orientation=[0, 0, 1.0])
    beams = {"posts": PROP, "rail": rail}
    spring = fm.Spring(0, 3, np.array([1e5, 2e5, 3e5, 10, 20, 30.0]), AXES)
    mass = fm.PointMass(2, 4.0, [0.1, 0.2, 0.3])
    return mesh, beams, spring, mass


def test_assembly_equals_python_loop_reference():
    mesh, beams, spring, mass = _small_frame()
    model = fm.build_model(mesh, beams, springs=[spring], masses=[mass])
    n_dof = 6 * mesh.n_nodes
    K_ref, M_ref = np.zeros((n_dof, n_dof)), np.zeros((n_dof, n_dof))
    lines = mesh.cells["line"]
    for e, (a, b) in enumerate(lines):  # one element at a time, explicit scatter
        name = "rail" if e == 1 else "posts"
        p = beams[name]
        s, m = p.section, p.material
        # posts are vertical: default orientation global y; the rail has its own
        orient = p.orientation if p.orientation is not None else [0.0, 1.0, 0.0]
        Ke, Me = beam_matrices(mesh.points, lines[e:e + 1], np.asarray(orient, dtype=float),
                               m.E, m.shear_modulus, m.rho, s.A, s.Iy, s.Iz, s.J,
                               s.polar_moment, s.Asy, s.Asz, rotary_inertia=True)
        dofs = np.r_[6 * a:6 * a + 6, 6 * b:6 * b + 6]
        for i in range(12):
            for j in range(12):
                K_ref[dofs[i], dofs[j]] += Ke[0, i, j]
                M_ref[dofs[i], dofs[j]] += Me[0, i, j]
    k = spring.matrix()
    for i in range(6):
        for j in range(6):
            K_ref[i, j] += k[i, j]
            K_ref[18 + i, 18 + j] += k[i, j]
            K_ref[i, 18 + j] -= k[i, j]
            K_ref[18 + i, j] -= k[i, j]
    M_ref[12:18, 12:18] += mass.matrix()
    # same element matrices, different summation order: round-off of the largest entry
    assert_allclose(model.K.toarray(), K_ref, rtol=0, atol=10 * EPS * np.abs(K_ref).max())
    assert_allclose(model.M.toarray(), M_ref, rtol=0, atol=10 * EPS * np.abs(M_ref).max())


def test_assembled_matrices_are_symmetric_csr():
    mesh, beams, spring, mass = _small_frame()
    model = fm.build_model(mesh, beams, springs=[spring], masses=[mass],
                           supports=[fm.Support(0)], rigid_links=[fm.RigidLink(1, [2])])
    for A in (model.K, model.M, model.K_free, model.M_free):
        assert sp.issparse(A)
        assert A.format == "csr"
        assert abs(A - A.T).max() <= 10 * EPS * abs(A).max()  # round-off only
    assert model.K.shape == (24, 24)
    assert model.K_free.shape == (model.n_free, model.n_free) == (12, 12)


def test_beam_matrices_computed_in_one_batch(monkeypatch):
    calls = []

    def counting(points, cells, *args, **kwargs):
        calls.append(len(cells))
        return beam_matrices(points, cells, *args, **kwargs)

    monkeypatch.setattr(fm_model, "beam_matrices", counting)
    mesh, beams, spring, mass = _small_frame()
    fm.build_model(mesh, beams, springs=[spring], masses=[mass])
    assert calls == [3]  # one call for all elements of all groups


def test_assemble_sums_duplicates():
    rng = np.random.default_rng(3)
    dofs = np.array([[0, 1, 2], [2, 1, 4], [0, 1, 2]])  # repeated element and shared DOFs
    mats = rng.standard_normal((3, 3, 3))
    ref = np.zeros((5, 5))
    for d, m in zip(dofs, mats, strict=True):
        np.add.at(ref, (d[:, None], d[None, :]), m)
    second = (np.array([[4, 3]]), np.ones((1, 2, 2)))
    ref[np.ix_([4, 3], [4, 3])] += 1.0
    A = assemble([(dofs, mats), second, (np.empty((0, 2), dtype=int), np.empty((0, 2, 2)))], 5)
    assert A.format == "csr"
    assert A.has_canonical_format  # duplicates summed, indices sorted
    assert_allclose(A.toarray(), ref, rtol=0, atol=10 * EPS)
    assert assemble([], 4).shape == (4, 4)
