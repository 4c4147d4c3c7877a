"""Draw the schematic of every built-in mechanism for docs/mechanisms.md (PNG, matplotlib).

Run from the repository root: ``python docs/figures/make_mechanism_figures.py``; it
writes the PNGs named by ``femmech.mechanisms.catalogue.CATALOGUE`` (``Entry.figure``)
beside this script. The drawings are schematic (not to scale): they show each
coordinate's place and positive sense (arrows) and each parameter's element.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Circle, FancyArrowPatch, Polygon, Rectangle

HERE = Path(__file__).resolve().parent
BLUE, RED, GREY = "#1f5fa8", "#c0392b", "#555555"
FONT = 10


def _new(width: float, height: float, title: str):
    fig = Figure(figsize=(width, height), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0, 0, 1, 0.92))
    ax.set_aspect("equal")
    ax.axis("off")
    fig.suptitle(title, fontsize=FONT + 1, y=0.985)
    return fig, ax


def _spring(ax, p0, p1, label="", n=6, width=0.12, side=1.0):
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    d = p1 - p0
    length = np.hypot(*d)
    t, nrm = d / length, np.array([-d[1], d[0]]) / length
    s = np.linspace(0.2, 0.8, 2 * n + 1)
    zig = [p0, p0 + 0.2 * d] + [p0 + si * d + (width if k % 2 else -width) * nrm * (k > 0)
                                 * (k < 2 * n) for k, si in enumerate(s)] + [p0 + 0.8 * d, p1]
    ax.plot(*np.array(zig).T, color="k", lw=1.2)
    if label:
        out = side * nrm
        m = p0 + 0.5 * d + (width + 0.08) * out
        ha = "left" if out[0] > 0.5 else "right" if out[0] < -0.5 else "center"
        ax.text(*m, label, fontsize=FONT, ha=ha, va="center")
    return t


def _damper(ax, p0, p1, label="", width=0.12, side=1.0):
    """A dashpot from p0 to p1: piston rod from p0, cup open towards p0 with its rod to p1."""
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    d = p1 - p0
    nrm = np.array([-d[1], d[0]]) / np.hypot(*d)
    piston, bottom, mouth = p0 + 0.5 * d, p0 + 0.65 * d, p0 + 0.35 * d
    ax.plot(*np.array([p0, piston]).T, color="k", lw=1.2)
    ax.plot(*np.array([piston - 0.75 * width * nrm, piston + 0.75 * width * nrm]).T,
            color="k", lw=1.2)
    cup = [mouth + width * nrm, bottom + width * nrm, bottom - width * nrm, mouth - width * nrm]
    ax.plot(*np.array(cup).T, color="k", lw=1.2)
    ax.plot(*np.array([bottom, p1]).T, color="k", lw=1.2)
    if label:
        m = p0 + 0.5 * d + side * (width + 0.16) * nrm
        ax.text(*m, label, fontsize=FONT, ha="center", va="center")


def _ground(ax, p, width=0.6, angle=0.0):
    """Hatched ground line centred at p; ``angle`` rad turns it (0: horizontal, hatch below)."""
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s], [s, c]])
    p = np.asarray(p, float)
    ax.plot(*(p + (R @ np.array([[-width / 2, width / 2], [0, 0]])).T).T, color="k", lw=1.5)
    for x in np.linspace(-width / 2, width / 2, 7)[:-1]:
        seg = R @ np.array([[x, x + 0.08], [0, -0.1]])
        ax.plot(*(p[:, None] + seg), color="k", lw=0.8)


def _mass(ax, center, w, h, label, color="#dbe7f5"):
    x, y = center
    ax.add_patch(Rectangle((x - w / 2, y - h / 2), w, h, fc=color, ec="k", lw=1.2, zorder=3))
    ax.text(x, y, label, fontsize=FONT, ha="center", va="center", zorder=4)


def _arrow(ax, p, d, label, color=BLUE, offset=(0.08, 0.0), ha="left"):
    p = np.asarray(p, float)
    ax.add_patch(FancyArrowPatch(tuple(p), tuple(p + np.asarray(d)), arrowstyle="-|>",
                                 mutation_scale=12, color=color, lw=1.4, zorder=5))
    q = p + np.asarray(d) + np.asarray(offset)
    ax.text(*q, label, fontsize=FONT, color=color, ha=ha, va="center", zorder=5)


def _turn(ax, center, r, label, color=BLUE, start=200, end=330):
    """A curved arrow (positive rotation, counter-clockwise) around ``center``."""
    a = np.deg2rad(np.linspace(start, end, 30))
    pts = np.column_stack([center[0] + r * np.cos(a), center[1] + r * np.sin(a)])
    ax.plot(*pts[:-2].T, color=color, lw=1.4)
    ax.add_patch(FancyArrowPatch(tuple(pts[-3]), tuple(pts[-1]), arrowstyle="-|>",
                                 mutation_scale=12, color=color, lw=1.4))
    ax.text(*(pts[-1] + np.array([0.06, -0.08])), label, fontsize=FONT, color=color,
            ha="left", va="top")


def _cam(ax, center, label="U(ψ)"):
    t = np.linspace(0, 2 * np.pi, 200)
    r = 0.32 + 0.12 * np.maximum(0, np.sin(t)) ** 2
    ax.add_patch(Polygon(np.column_stack([center[0] + r * np.cos(t), center[1] + r * np.sin(t)]),
                         fc="#f3e2c7", ec="k", lw=1.2, zorder=2))
    ax.add_patch(Circle(center, 0.04, fc="k", zorder=3))
    ax.text(center[0] - 0.55, center[1] - 0.05, label, fontsize=FONT, ha="right", va="center")


def _motor(ax, x, y, label):
    """The drive (prescribed motion) at the left shaft end: a box with its label."""
    ax.add_patch(Rectangle((x - 0.55, y - 0.25), 0.55, 0.5, fc="#fde9d9", ec="k", zorder=3))
    ax.text(x - 0.275, y, "M", fontsize=FONT, ha="center", va="center", zorder=4)
    ax.text(x - 0.275, y + 0.35, label, fontsize=FONT - 1, ha="center", va="bottom",
            color=RED)


def _shaft(ax, x0, x1, y, discs, springs, dampers=(), twist=()):
    """A horizontal shaft: discs ((x, name), ...), torsion springs ((xa, xb, name), ...)
    drawn as springs on the axis, dampers below, twist arrows ((x, name), ...)."""
    ax.plot([x0, x1], [y, y], color=GREY, lw=2, zorder=1)
    for xa, xb, name in springs:
        _spring(ax, (xa, y), (xb, y), name, width=0.08)
    for xa, xb, name in dampers:
        ax.plot([xa, xa], [y, y - 0.35], color="k", lw=1)
        ax.plot([xb, xb], [y, y - 0.35], color="k", lw=1)
        _damper(ax, (xa, y - 0.35), (xb, y - 0.35), name, side=-1.0)
    for x, name in discs:
        ax.add_patch(Rectangle((x - 0.06, y - 0.32), 0.12, 0.64, fc="#cfd8dc", ec="k",
                               lw=1.2, zorder=3))
        ax.text(x, y + 0.42, name, fontsize=FONT, ha="center", va="bottom")
    for x, name in twist:
        _turn(ax, (x, y), 0.45, name)


def _save(fig, name):
    fig.savefig(HERE / name, dpi=100)


def cam_follower():
    fig, ax = _new(6.4, 5.0, "cam_follower: cam on an elastic shaft, follower and return"
                             " spring on the frame")
    _cam(ax, (0.0, 0.0))
    _turn(ax, (0.0, 0.0), 0.6, "θ + q_s", start=200, end=320)
    _arrow(ax, (0.75, -0.2), (0, 0.45), "y_c (cam centre)")
    ax.add_patch(Circle((0.0, 0.52), 0.08, fc="white", ec="k", zorder=3))   # roller
    ax.plot([0, 0], [0.6, 1.1], color="k", lw=1.5)
    _spring(ax, (0.0, 1.1), (0.0, 1.9), "c", width=0.1)
    _damper(ax, (-0.45, 1.1), (-0.45, 1.9), "b", side=1.0)
    ax.plot([-0.45, 0.0], [1.1, 1.1], color="k", lw=1.2)
    ax.plot([-0.45, 0.0], [1.9, 1.9], color="k", lw=1.2)
    _mass(ax, (0.0, 2.2), 0.8, 0.6, "m")
    _arrow(ax, (0.55, 1.95), (0, 0.5), "y = y_c + U(ψ) + q")
    _arrow(ax, (-0.85, 1.1), (0, 0.45), "q", offset=(-0.08, 0), ha="right")
    _spring(ax, (0.0, 2.5), (0.0, 3.3), "c_r (return)", width=0.1, side=-1.0)
    _ground(ax, (0.0, 3.3), angle=np.pi)
    _arrow(ax, (0.45, 3.25), (0, 0.4), "y_f (spring base)")
    _arrow(ax, (-0.6, 2.45), (0, -0.45), "F", color=RED, offset=(-0.08, 0), ha="right")
    ax.text(0.0, -0.75, "J: cam inertia (optional)", fontsize=FONT - 1, ha="center",
            color=GREY)
    ax.set_xlim(-2.2, 2.6)
    ax.set_ylim(-1.0, 3.9)
    _save(fig, "cam_follower.png")


def slider_crank():
    fig, ax = _new(7.4, 4.2, "slider_crank: crank bearing (u_b, v_b) and guide (v_g) move"
                             " with the frame")
    c = np.array([0.0, 0.0])
    psi = np.deg2rad(55)
    pin = c + 0.6 * np.array([np.cos(psi), np.sin(psi)])
    slider_x = pin[0] + np.sqrt(2.0**2 - pin[1] ** 2)
    ax.add_patch(Circle(c, 0.09, fc="#cfd8dc", ec="k", zorder=3))
    ax.plot(*np.array([c, pin]).T, color="k", lw=3)
    ax.plot(*np.array([pin, (slider_x, 0.0)]).T, color="k", lw=2)
    ax.add_patch(Circle(pin, 0.05, fc="white", ec="k", zorder=4))
    ax.text(*(c + 0.35 * np.array([np.cos(psi), np.sin(psi)]) + [-0.18, 0.12]), "r",
            fontsize=FONT)
    ax.text((pin[0] + slider_x) / 2, pin[1] / 2 + 0.12, "l", fontsize=FONT)
    _turn(ax, c, 0.35, "", start=190, end=330)
    ax.text(-0.1, -0.62, "ψ = θ + q_t", fontsize=FONT, color=BLUE, ha="center", va="top")
    ax.text(-0.5, 0.75, "J1, c1, b1 (crankshaft)", fontsize=FONT - 1, ha="center")
    ax.add_patch(Rectangle((slider_x - 0.2, -0.15), 0.4, 0.3, fc="#eeeeee", ec="k", zorder=3))
    ax.plot([slider_x - 0.6, slider_x + 2.2], [-0.18, -0.18], color="k", lw=1.5)
    ax.text(slider_x + 2.25, -0.18, "guide line n = e + v_g", fontsize=FONT - 1, va="center")
    _spring(ax, (slider_x + 0.2, 0.0), (slider_x + 1.1, 0.0), "c2", width=0.08)
    _mass(ax, (slider_x + 1.4, 0.0), 0.6, 0.5, "m2")
    _arrow(ax, (slider_x + 1.75, 0.3), (0.45, 0), "x = s + q", offset=(0.05, 0.12))
    _arrow(ax, (slider_x + 1.75, 0.0), (0.45, 0), "F2", color=RED, offset=(0.05, 0))
    ax.annotate("", (slider_x + 1.4, -0.75), (slider_x + 0.15, -0.75),
                arrowprops=dict(arrowstyle="-|>", color=BLUE, lw=1.4))
    ax.text(slider_x + 0.75, -0.9, "q (ram against slider), b2", fontsize=FONT, color=BLUE,
            ha="center", va="top")
    _arrow(ax, (0.3, -0.3), (0.5, 0), "u_b", offset=(0.05, 0))
    _arrow(ax, (-0.45, -0.2), (0, 0.45), "v_b", offset=(-0.05, 0), ha="right")
    _arrow(ax, (slider_x - 0.45, -0.65), (0, 0.4), "v_g", offset=(-0.05, 0), ha="right")
    _arrow(ax, (-1.8, 0.6), (0.5, 0), "s", color="k", offset=(0.05, 0))
    _arrow(ax, (-1.8, 0.6), (0, 0.5), "n", color="k", offset=(0.05, 0))
    ax.set_xlim(-2.0, slider_x + 4.2)
    ax.set_ylim(-1.3, 1.4)
    _save(fig, "slider_crank.png")


def _output_chain(ax, x, y, mass, spring, damper, force, coord, label=None):
    """An output mass on a follower spring and damper above (x, y)."""
    _spring(ax, (x, y), (x, y + 0.8), spring, width=0.09, side=-1.0)
    ax.plot([x - 0.4, x], [y, y], color="k", lw=1.2)
    ax.plot([x - 0.4, x], [y + 0.8, y + 0.8], color="k", lw=1.2)
    _damper(ax, (x - 0.4, y), (x - 0.4, y + 0.8), damper, side=1.6)
    _mass(ax, (x - 0.2, y + 1.05), 0.8, 0.5, mass)
    _arrow(ax, (x + 0.35, y + 0.85), (0, 0.45), coord)
    if force:
        _arrow(ax, (x - 0.45, y + 1.75), (0, -0.45), force, color=RED, offset=(-0.06, 0.1),
               ha="right")
    return y + 1.3


def table_5_1(case: int):
    titles = {1: "table_5_1_case(1): shaft, mechanism U, output mass",
              2: "table_5_1_case(2): two-mass follower chain",
              3: "table_5_1_case(3): two mechanisms U2, U3 on one shaft"}
    fig, ax = _new(6.8, 4.6, titles[case])
    _motor(ax, -2.6, 0.0, "drive θ = Ωt")
    _shaft(ax, -2.6, 0.5, 0.0, [(0.0, "J1")], [(-2.5, -0.9, "c1")],
           [(-2.2, -1.2, "b1")], [(0.0, "ψ = θ + q1")])
    top = 0.0
    xs = (0.9,) if case != 3 else (0.9, 4.1)
    for i, x in enumerate(xs):
        ax.add_patch(Rectangle((x - 0.3, 0.3), 0.6, 0.4, fc="#f3e2c7", ec="k", zorder=2))
        ax.text(x, 0.5, "U" if case != 3 else f"U{i + 2}", fontsize=FONT, ha="center",
                va="center")
        ax.plot([0.06, x], [0.0, 0.0], color=GREY, lw=2)
        ax.plot([x, x], [0.0, 0.3], color=GREY, lw=1.5)
        n = i + 2
        force = "" if case == 2 else f"F{n}"   # case 2 has F3 only
        top = _output_chain(ax, x + 0.2, 0.7, f"m{n}", f"c{n}", f"b{n}", force,
                            f"x{n} = U{'' if case != 3 else n}(ψ) + q{n}")
    if case == 2:
        top = _output_chain(ax, 1.1, top + 0.1, "m3", "c3", "b3", "F3", "x3 = U(ψ) + q3")
    ax.set_xlim(-3.6, 4.6 if case != 3 else 6.5)
    ax.set_ylim(-0.9, top + 0.7)
    _save(fig, f"table_5_1_case_{case}.png")


def follower_unit():
    fig, ax = _new(6.8, 4.8, "follower_unit: one unit of a chain (the chain's shaft at its"
                             " node)")
    _shaft(ax, -2.4, 2.4, 0.0, [(0.0, "inertia")], [(-2.3, -0.1, "shaft (chain)"),
                                                     (0.1, 2.3, "shaft (chain)")],
           (), [(0.0, "ψ = φ + δ_u + q1")])
    ax.add_patch(Rectangle((0.6, 0.3), 0.6, 0.4, fc="#f3e2c7", ec="k", zorder=2))
    ax.text(0.9, 0.5, "cam U", fontsize=FONT, ha="center", va="center")
    ax.plot([0.06, 0.9], [0.0, 0.0], color=GREY, lw=2)
    ax.plot([0.9, 0.9], [0.0, 0.3], color=GREY, lw=1.5)
    top = _output_chain(ax, 1.1, 0.7, "mass", "stiffness", "damping", "force",
                        "x2 = U(ψ) + q2")
    _spring(ax, (0.9, top + 0.05), (0.9, top + 0.75), "c_g (ground_stiffness)", width=0.08,
            side=-1.0)
    _ground(ax, (0.9, top + 0.75), width=0.5, angle=np.pi)
    ax.set_xlim(-3.0, 4.4)
    ax.set_ylim(-1.0, top + 1.0)
    _save(fig, "follower_unit.png")


def table_5_1_case_4():
    fig, ax = _new(7.4, 3.8, "table_5_1_case(4): two mechanisms U between elastic input and"
                             " output shafts")
    _motor(ax, -2.6, 0.0, "drive θ = Ωt")
    _shaft(ax, -2.6, 2.6, 0.0, [(0.0, "J12"), (2.4, "J13")],
           [(-2.5, -0.1, "c11, b11"), (0.1, 2.3, "c12, b12")], (),
           [(0.0, "θ + q1"), (2.4, "θ + q1 + q2")])
    y = 2.2
    ax.plot([-2.6, 2.6], [y, y], color=GREY, lw=2)
    for x, name, t in ((0.0, "J22", "T2"), (2.4, "J23", "T3")):
        ax.add_patch(Rectangle((x - 0.2, 0.8), 0.4, 0.6, fc="#f3e2c7", ec="k"))
        ax.text(x, 1.1, "U", fontsize=FONT, ha="center", va="center")
        ax.plot([x, x], [0.32, 0.8], color=GREY, lw=1.2)
        ax.plot([x, x], [1.4, y - 0.32], color=GREY, lw=1.2)
        ax.add_patch(Rectangle((x - 0.06, y - 0.32), 0.12, 0.64, fc="#cfd8dc", ec="k", zorder=3))
        ax.text(x + 0.12, y + 0.38, f"{name}, torque {t}", fontsize=FONT, color="k")
    _spring(ax, (-2.5, y), (-0.1, y), "c21, b21", width=0.08)
    _spring(ax, (0.1, y), (2.3, y), "c22, b22", width=0.08)
    ax.text(-2.7, y, "U(θ)", fontsize=FONT - 1, ha="right", va="center")
    ax.set_xlim(-3.8, 4.4)
    ax.set_ylim(-0.9, 2.9)
    _save(fig, "table_5_1_case_4.png")


def processing_machine():
    fig, ax = _new(8.4, 5.0, "processing_machine: elastic shaft with two cam mechanisms")
    x0, x1, x2 = -3.2, 0.0, 3.2
    _shaft(ax, x0, x2 + 0.3, 0.0, [(x0, "J0"), (x1, "J1"), (x2, "J2")],
           [(x0 + 0.1, x1 - 0.1, "cT1, bT1"), (x1 + 0.1, x2 - 0.1, "cT2, bT2")])
    for x, text in ((x0, "q1 = φ0"), (x1, "φ1 = q1 + q2"), (x2, "φ2 = φ1 + q3")):
        _turn(ax, (x, 0.0), 0.42, "")
        ax.text(x + 0.1, -0.55, text, fontsize=FONT, color=BLUE, ha="left", va="top")
    ax.text(x0, -1.0, "M0 (free drive) or q1 = Ωt (kinematic)", fontsize=FONT - 1,
            ha="left", va="top", color=RED)
    for x, k, m, c, b, cr, F, q in ((x1, 1, "m1", "c3", "b3", "c6", "F1", "q4"),
                                    (x2, 2, "m2", "c4", "b4", "c7", "F2", "q5")):
        ax.add_patch(Rectangle((x + 0.2, 0.45), 0.5, 0.35, fc="#f3e2c7", ec="k"))
        ax.text(x + 0.45, 0.62, f"U{k}", fontsize=FONT, ha="center", va="center")
        ax.plot([x + 0.06, x + 0.45], [0.0, 0.0], color=GREY, lw=2)
        ax.plot([x + 0.45, x + 0.45], [0.0, 0.45], color=GREY, lw=1.2)
        top = _output_chain(ax, x + 0.65, 0.8, m, c, b, F, f"y{k} = U{k}(φ{k}) + {q}")
        _spring(ax, (x + 0.45, top + 0.05), (x + 0.45, top + 0.75), f"{cr} (return)",
                width=0.08, side=-1.0)
        _ground(ax, (x + 0.45, top + 0.75), width=0.5, angle=np.pi)
    ax.set_xlim(-3.8, 6.3)
    ax.set_ylim(-1.5, 3.8)
    _save(fig, "processing_machine.png")


def mobile_crane():
    fig, ax = _new(7.4, 5.4, "mobile_crane: chassis on two axles, luffing cylinder, load"
                             " pendulum")
    _mass(ax, (0.0, 0.0), 4.5, 0.6, "chassis m2, JS2", color="#e8eef3")
    for x, name in ((-1.6, "c (front axle, l1)"), (1.8, "c (rear axle, l2)")):
        _spring(ax, (x, -0.3), (x, -1.1), "", width=0.1)
        ax.text(x + 0.2, -0.7, name, fontsize=FONT, ha="left", va="center")
        _ground(ax, (x, -1.1), width=0.5)
    _arrow(ax, (2.5, -0.2), (0, 0.5), "q1 (heave, up)")
    _turn(ax, (-2.3, 0.0), 0.45, "", start=110, end=250)
    ax.text(-3.1, 0.0, "q2\n(pitch)", fontsize=FONT, color=BLUE, ha="right", va="center")
    pivot = np.array([-0.8, 0.5])
    beta = np.deg2rad(125)
    u = np.array([np.cos(beta), np.sin(beta)])
    tip = pivot + 3.2 * u
    ax.plot(*np.array([pivot, tip]).T, color="#7f6a00", lw=5, solid_capstyle="round")
    ax.add_patch(Circle(pivot, 0.08, fc="white", ec="k", zorder=4))
    ax.text(*(pivot + 1.6 * u + [0.25, 0.15]), "boom m3, JS3", fontsize=FONT)
    base, head = np.array([0.6, 0.35]), pivot + 1.1 * u
    ax.plot(*np.array([base, head]).T, color="k", lw=3)
    ax.add_patch(Circle(base, 0.06, fc="white", ec="k", zorder=4))
    _arrow(ax, base + 0.25 * (head - base) + [0.15, 0.0], 0.3 * (head - base) / 1.0,
           "q4 = s4 (cylinder, drive)", offset=(0.1, 0.1))
    rope = 1.8
    q3 = np.deg2rad(18)
    load = tip + rope * np.array([-np.sin(q3), -np.cos(q3)])
    ax.plot(*np.array([tip, load]).T, color="k", lw=1)
    ax.plot([tip[0], tip[0]], [tip[1], tip[1] - 1.2], color=GREY, lw=0.8, ls="--")
    _mass(ax, load - [0, 0.15], 0.5, 0.4, "m5")
    a = np.linspace(-np.pi / 2, -np.pi / 2 - q3, 20)
    ax.plot(tip[0] + 0.9 * np.cos(a), tip[1] + 0.9 * np.sin(a), color=BLUE, lw=1.4)
    ax.text(tip[0] + 0.1, tip[1] - 1.0, "q3", fontsize=FONT, color=BLUE)
    ax.text(load[0] - 0.35, load[1] - 0.15, "JS5, rS5", fontsize=FONT - 1, ha="right")
    _arrow(ax, (-3.3, -1.2), (0.5, 0), "x", color="k", offset=(0.05, 0))
    _arrow(ax, (-3.3, -1.2), (0, 0.5), "y", color="k", offset=(0.05, 0))
    ax.text(-3.3, -1.45, "g down", fontsize=FONT - 1)
    ax.set_xlim(-4.4, 3.8)
    ax.set_ylim(-1.7, tip[1] + 0.4)
    _save(fig, "mobile_crane.png")


def main():
    cam_follower()
    slider_crank()
    for case in (1, 2, 3):
        table_5_1(case)
    table_5_1_case_4()
    follower_unit()
    processing_machine()
    mobile_crane()


if __name__ == "__main__":
    main()
