"""Section forces of beam elements recovered from coupled responses."""

import numpy as np
import pytest
import scipy.sparse.linalg as spla
import sympy
from numpy.testing import assert_allclose

import femmech as fm
from femmech.analysis.forces import (
    SECTION_COMPONENTS,
    beam_section_forces,
    support_reactions,
)
from femmech.analysis.response import Response, periodic_steady_state, rayleigh_damping
from femmech.coupling import Attachment, Mount, couple
from femmech.fe import sections
from femmech.fe.dofs import COMPONENTS
from femmech.mechanisms import Load, Mechanism, PointMass, RotaryInertia, rheolinear
from femmech.reduction.component_modes import craig_bampton
from femmech.reduction.substructures import assemble_parts

STEEL = fm.Material(E=210e9, nu=0.3, rho=7850.0)
LENGTH, N_EL = 1.2, 6  # cantilever, m
# tip loads of the static cases: forces (N) along global x, y, z and a torque (N m) about x
TIP = {"F_x": 3e3, "F_y": 2e3, "F_z": -1.5e3, "M_x": 400.0}


def _tip_mount(node, loads=TIP, mass=1.0):
    """A 'mechanism' that is only a mass with constant (or φ-dependent) loads, attached
    rigidly to the frame node: it applies the loads to the frame (plus its inertia)."""
    theta = sympy.Symbol("theta")
    coords = {c: sympy.Symbol(f"q_{c}") for c in COMPONENTS}
    elements = [RotaryInertia(1.0, theta)]
    attachments = []
    for name, value in loads.items():
        c = {"F": "u", "M": "r"}[name[0]] + name[-1]
        elements += [PointMass(mass, (coords[c],)), Load(value, coords[c])]
        attachments.append(Attachment(f"q_{c}", node, c))
    used = [coords[a.direction] for a in attachments]
    mech = Mechanism((*used, theta), tuple(elements), drives=(theta,), name="loads")
    return Mount(rheolinear(mech), tuple(attachments), name="loads")


def _static(system):
    """Response of one time point holding the static solution C q = F at φ = 0."""
    _, _, C, F = system.matrices(0.0)
    q = spla.spsolve(C.tocsc(), F) if system.is_sparse else np.linalg.solve(C, F)
    zero = np.zeros((1, system.n))
    return Response(np.zeros(1), q[None], zero, zero, np.zeros(1))


def _cantilever():
    """Steel RHS cantilever along x, clamped at x = 0 (node 0), tip node N_EL."""
    x = np.linspace(0.0, LENGTH, N_EL + 1)
    mesh = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(N_EL), np.arange(1, N_EL + 1)]),
                              {"arm": np.arange(N_EL)}, {"root": [0], "tip": [N_EL]})
    prop = fm.BeamProperty(sections.rectangular_hollow(0.06, 0.08, 0.004), STEEL)
    return fm.build_model(mesh, {"arm": prop}, supports=[fm.Support("root")])


@pytest.fixture(scope="module")
def cantilever():
    model = _cantilever()
    se = craig_bampton(model, "tip", n_modes=4)
    system = couple(se, [_tip_mount(N_EL)])
    return model, system, _static(system)


def test_cantilever_tip_loads_give_statically_determinate_section_forces(cantilever):
    model, system, r = cantilever
    out = beam_section_forces(system, model, r, "arm")
    assert out.forces.shape == (1, N_EL, 2, 6)
    assert not out.dynamic
    assert_allclose(out.elements, np.arange(N_EL))
    # Statics of the cantilever (Gere & Goodno, Mechanics of Materials, ch. 4: shear force
    # and bending moment diagrams): with a tip force P_y the cut at x carries V_y = P_y
    # and a moment P_y (L − x); in the vector convention of SectionForces (action of the
    # outer part on the inner part) Mz = +P_y (L − x), My = −P_z (L − x); N = F_x, T = M_x.
    # Local axes of a member along global x: y = global y, z = global z (default
    # orientation ẑ × x). Statically determinate and the element stiffness exact, and the
    # Craig-Bampton constraint mode of the loaded interface is the exact static response:
    # only round-off remains (measured 1e-13 of F_x L).
    x = np.linspace(0.0, LENGTH, N_EL + 1)
    ends = np.column_stack([x[:-1], x[1:]])  # (n_el, 2) positions of ends a and b
    expected = {"N": TIP["F_x"], "Vy": TIP["F_y"], "Vz": TIP["F_z"], "T": TIP["M_x"],
                "My": -TIP["F_z"] * (LENGTH - ends), "Mz": TIP["F_y"] * (LENGTH - ends)}
    scale = TIP["F_x"] * LENGTH
    for name in SECTION_COMPONENTS:
        # bound: K u = F round-off: eps·cond(K) of a frame (measured 6e-14 of the largest force)
        assert_allclose(out.component(name)[0], np.broadcast_to(expected[name], ends.shape),
                        rtol=1e-9, atol=1e-9 * scale, err_msg=name)
    # the same elements named one by one (indices, any order) give the same rows
    part = beam_section_forces(system, model, r, [4, 1])
    # bound: the same rows named another way: a few eps; atol for zeros
    assert_allclose(part.forces[0], out.forces[0, [4, 1]], rtol=1e-12, atol=1e-9)


def _braced_frame():
    """3D frame: a post (z) clamped at its foot, an arm (x) from its top, loaded at the
    arm's tip, and an inclined brace from the post top to a clamped point, with an
    explicit orientation vector and Euler-Bernoulli bending (statically indeterminate)."""
    joints = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.3, 0.8, 0.4]])
    points, lines, sets = [joints], [], {}
    n_points = len(joints)
    for group, (a, b) in {"post": (0, 1), "arm": (1, 2), "brace": (1, 3)}.items():
        inner = joints[a] + np.outer(np.arange(1, 4) / 4, joints[b] - joints[a])
        ids = np.concatenate([[a], n_points + np.arange(3), [b]])
        points.append(inner)
        n_points += 3
        sets[group] = len(lines) + np.arange(4)
        lines += list(zip(ids[:-1], ids[1:], strict=True))
    mesh = fm.Mesh.from_lines(np.vstack(points), np.array(lines), sets,
                              {"feet": [0, 3], "tip": [2]})
    beams = {
        "post": fm.BeamProperty(sections.rectangular_hollow(0.1, 0.1, 0.006), STEEL),
        "arm": fm.BeamProperty(sections.rectangular_hollow(0.06, 0.08, 0.004), STEEL),
        "brace": fm.BeamProperty(sections.rectangle(0.03, 0.05), STEEL,
                                 orientation=(1.0, 0.0, 1.0), shear=False)}
    return fm.build_model(mesh, beams, supports=[fm.Support("feet")])


def _nodal_sums(model, out):
    """Σ over elements of the force and moment each node exerts on its elements, in global
    axes, (n_t, n_nodes, 6): f_a = −S_a, f_b = +S_b, rotated by Rᵀ."""
    R = model.beams.frames[out.elements]
    f = out.forces * np.array([-1.0, 1.0])[None, None, :, None]
    f = f.reshape(*f.shape[:3], 2, 3)  # (t, e, end, force/moment, xyz)
    f_global = np.einsum("eji,tekmj->tekmi", R, f).reshape(*f.shape[:3], 6)
    sums = np.zeros((f.shape[0], len(model.mesh.points), 6))
    cells = model.beams.cells[out.elements]
    for end in (0, 1):
        np.add.at(sums, (slice(None), cells[:, end]), f_global[:, :, end])
    return sums


def test_element_end_forces_balance_at_nodes():
    model = _braced_frame()
    loads = {"F_x": -800.0, "F_y": 1.2e3, "F_z": -2e3, "M_x": 150.0, "M_y": -90.0,
             "M_z": 60.0}
    system = couple(model, [_tip_mount("tip", loads)])  # unreduced frame: sparse path
    r = _static(system)
    out = beam_section_forces(system, model, r, ["post", "arm", "brace"])
    assert len(out.elements) == 12
    sums = _nodal_sums(model, out)[0]
    scale = np.abs(out.forces).max()
    # free nodes without load: Σ of the element end forces = 0 (nodal equilibrium of
    # bound: K u = F; round-off: measured 6e-14 of the largest section force); the corner node 1
    # joins three members with different local axes, one with an orientation vector
    free = np.setdiff1d(np.arange(len(model.mesh.points)), [0, 2, 3])
    assert_allclose(sums[free], 0.0, atol=1e-9 * scale)
    # bound: equilibrium round-off eps·cond(K) (6e-14 measured); loaded tip: applied loads
    applied = [loads[k] for k in ("F_x", "F_y", "F_z", "M_x", "M_y", "M_z")]
    assert_allclose(sums[2], applied, rtol=1e-9, atol=1e-9 * scale)
    # clamped feet: the support reactions from the rows of the assembled K (independent
    # code path: support_reactions), which differ from zero (indeterminate frame)
    for foot in (0, 3):
        reaction = support_reactions(system, model, r, [6 * foot + k for k in range(6)])[0]
        assert np.abs(reaction).max() > 50.0
        # bound: equilibrium round-off: eps·cond(K) of the frame, measured 6e-14
        assert_allclose(sums[foot], reaction, rtol=1e-9, atol=1e-9 * scale)


def test_dynamic_end_forces_balance_the_element_inertia():
    model = _cantilever()
    # all 30 interior modes (a cutoff above the highest, 1.5e4 Hz): the basis is complete,
    # so the full-model equations hold at every DOF, interior nodes included
    se = craig_bampton(model, "tip", cutoff_hz=1e7, residual_vectors=False)
    assert se.Phi.shape[1] == 30
    phi = sympy.Symbol("theta")
    mount = _tip_mount(N_EL, {"F_y": 2e3 * sympy.sin(phi), "F_z": 500 * sympy.cos(2 * phi)},
                       mass=5.0)
    a, b = 3.0, 2e-5  # Rayleigh coefficients, 1/s and s
    system = rayleigh_damping(couple(se, [mount]), a, b)
    W = 2 * np.pi * 15.0  # 15 Hz and 30 Hz loads, near the 1st bending mode (27.2 Hz with
    # the 10 kg of tip masses)
    # ρ∞ = 1: the equations hold exactly at the grid points (see test_forces._run)
    r = periodic_steady_state(system, W, n_steps=128, rho_inf=1.0)
    dyn = beam_section_forces(system, model, r, "arm", dynamic=True, mass_coef=a,
                              stiffness_coef=b)
    elastic = beam_section_forces(system, model, r, "arm")
    assert dyn.dynamic
    assert dyn.forces.shape == (r.t.size, N_EL, 2, 6)
    sums_dyn, sums_el = _nodal_sums(model, dyn), _nodal_sums(model, elastic)
    scale = np.abs(dyn.forces).max()
    interior = np.arange(1, N_EL)
    # K u + B u̇ + M ü balances at the unloaded nodes (round-off: measured 3e-13 of the
    # largest section force)
    assert_allclose(sums_dyn[:, interior], 0.0, atol=1e-8 * scale)
    # the elastic part alone leaves the element inertia unbalanced (measured 8 % of the
    # largest section force)
    assert np.abs(sums_el[:, interior]).max() > 0.02 * scale
    # at the clamp, the dynamic end forces are the support reaction (rows of K, B, M)
    reaction = support_reactions(system, model, r, [(0, c) for c in COMPONENTS], a, b)
    # bound: equilibrium round-off: eps·cond(K) of the frame, measured 6e-14
    assert_allclose(sums_dyn[:, 0], reaction, rtol=1e-9, atol=1e-9 * scale)
    # and in statics (same loads frozen at φ = 0) dynamic and elastic coincide
    r0 = _static(system)
    # bound: statics: the same loads, the same products, a few eps
    assert_allclose(beam_section_forces(system, model, r0, "arm", dynamic=True).forces,
                    beam_section_forces(system, model, r0, "arm").forces, rtol=1e-12)


def test_bad_requests_name_the_item(cantilever):
    model, system, r = cantilever
    with pytest.raises(ValueError, match="unknown element group 'nope'.*'arm'"):
        beam_section_forces(system, model, r, "nope")
    with pytest.raises(ValueError, match="beam element 6 is out of range.*6 beam elements"):
        beam_section_forces(system, model, r, [0, 6])
    with pytest.raises(ValueError, match="beam element -1 is out of range"):
        beam_section_forces(system, model, r, -1)
    with pytest.raises(TypeError, match="beam element 1.5"):
        beam_section_forces(system, model, r, [1.5])
    with pytest.raises(ValueError, match="give dynamic=True"):
        beam_section_forces(system, model, r, "arm", mass_coef=1.0)
    with pytest.raises(ValueError, match="the model has 78 DOFs, the frame 42"):
        beam_section_forces(system, _braced_frame(), r, "arm")
    with pytest.raises(ValueError, match="unknown section force component 'M'"):
        beam_section_forces(system, model, r, 0).component("M")


def test_model_without_beams_is_refused():
    points = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    mesh = fm.Mesh(points, {"quad": np.array([[0, 1, 2, 3]])}, {"plate": {"quad": [0]}},
                   {"edge": [0, 1]})
    model = fm.build_model(mesh, shells={"plate": fm.ShellProperty(0.01, STEEL)},
                           supports=[fm.Support("edge")])
    system = couple(model, [])
    zero = np.zeros((1, system.n))
    r = Response(np.zeros(1), zero, zero, zero, np.zeros(1))
    with pytest.raises(ValueError, match="the model has no beam elements"):
        beam_section_forces(system, model, r, "plate")


def test_assembly_frame_by_part():
    # the cantilever (part 0) extended by a second superelement (part 1, 3 elements of
    # 0.4 m) to 2 L, tip force P_y at the free end of part 1: Mz = P_y (2L − x) in both
    # parts (statics, as above; round-off)
    model = _cantilever()
    x = np.linspace(LENGTH, 2 * LENGTH, 4)
    mesh = fm.Mesh.from_lines(np.column_stack([x, 0 * x, 0 * x]),
                              np.column_stack([np.arange(3), np.arange(1, 4)]),
                              {"ext": np.arange(3)}, {"start": [0], "end": [3]})
    prop = fm.BeamProperty(sections.rectangular_hollow(0.06, 0.08, 0.004), STEEL)
    extension = fm.build_model(mesh, {"ext": prop})
    frame = assemble_parts([craig_bampton(model, "tip", n_modes=4),
                            craig_bampton(extension, ["start", "end"], n_modes=2)])
    P = 1e3  # N
    system = couple(frame, [_tip_mount((1, 3), {"F_y": P})])
    r = _static(system)
    for part, fe, group in ((0, model, "arm"), (1, extension, "ext")):
        out = beam_section_forces(system, fe, r, group, part=part)
        ends = fe.mesh.points[fe.beams.cells, 0]
        # bound: cantilever: Mz linear, exact in the beam element: eps·cond(K) of the static solve
        assert_allclose(out.component("Mz")[0], P * (2 * LENGTH - ends), atol=1e-9 * P)
        # bound: cantilever: Vy constant, exact in the beam element: eps·cond(K) of the static solve
        assert_allclose(out.component("Vy")[0], P, rtol=1e-9)
    with pytest.raises(ValueError, match="Assembly of 2 parts: give the part index"):
        beam_section_forces(system, model, r, "arm")
    with pytest.raises(ValueError, match="the model has 42 DOFs, the frame 24"):
        beam_section_forces(system, model, r, "arm", part=1)
