"""Peer target 5: a stability-chart point against ``solve_ivp`` (DOP853).

femmech: the monodromy matrix over one period with its error control, as a stability chart
computes each point (``coupled_monodromy_record`` / ``monodromy_record`` at the default
``rtol`` 1e-4 and ``n_steps`` 32: Magnus-4 steps doubled until the spectral radius ρ
settles, steps aligned to the motion law's breakpoints).

Peer: ``scipy.integrate.solve_ivp(method="DOP853")`` on the fundamental matrix as one
system of 4n² unknowns, ``z' = A(t) Z`` for all 2n columns at once (one matrix product per
right-hand side call), dense output off, ``t_eval=[T]``; each call evaluates the same
coefficients at its time, in the leanest form a user could write (press: the constant
matrices once, per call the mechanism model's M, B, C at its angle, projected and added,
one solve for ``A = [[0, I], [-M⁻¹C, -M⁻¹B]]`` (:func:`lean_first_order`, 4.5 times
cheaper per call than ``system.matrices``); Mathieu: the 2 x 2 matrix written out).
The peer's ``rtol`` is the loosest of 1e-3, 1e-4, … 1e-12 whose ρ error is at most
femmech's (``atol = 1e-3 rtol``: the columns of Φ start at 1); on the press DOP853 is held
to its stability limit h ≲ 3.5/ω_max (ω_max ≈ 2.5e4 rad/s) whatever its rtol, so already
1e-3 is far more accurate than needed. *Peer floor*: the same DOP853 run with A frozen at
t = 0 (the same stiffness, about the same steps, no coefficient evaluation): no
right-hand side can make the peer faster than this; its ratio shows how much of the gap
is the peer's coefficient cost.

Reference ρ: femmech at rtol 1e-10 (Magnus-4 doubled up to 2¹⁶ steps per period), because
DOP853 at rtol 1e-12 takes minutes at 100 rpm and below; it is cross-checked against
DOP853 at rtol 1e-12, atol 1e-15 (an independent method) where that is affordable
(Mathieu and 1000 rpm; also 100 rpm at size medium) and the table prints how far the two
references differ (~5e-12: errors below ~1e-11 read "at the reference's accuracy").

Sizes: tiny = Mathieu and 1000 rpm (a few seconds per repeat); small = + 100 rpm (about
two minutes); medium = + 10 rpm (the peer alone takes ~2 minutes per run there, ~15
minutes in all).

Cases: the slider-crank press of examples/press_frame.toml (25 coupled coordinates, frame
Rayleigh damping 2 1/s and 1e-5 s as in benchmarks/monodromy_error_control.py) at
1000, 100 and 10 rpm, and a damped Mathieu equation q'' + 2ζ q' + (δ + ε cos t) q = 0
(δ = 1, ε = 0.4, ζ = 0.02, T = 2π).

Run: ``python benchmarks/peer_monodromy.py [--size tiny|small|medium] [--repeats 3]``.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))

import peers  # noqa: E402
from monodromy_error_control import RPM, press  # noqa: E402

from femmech.analysis import magnus  # noqa: E402
from femmech.analysis.floquet import (  # noqa: E402
    coupled_monodromy_record,
    monodromy_record,
)
from femmech.coupling import assemble_stack, drive_breakpoints  # noqa: E402
from femmech.errors import ConvergenceWarning  # noqa: E402

TARGET = 5.0
CASES = {"tiny": ("mathieu", 1000.0), "small": ("mathieu", 1000.0, 100.0),
         "medium": ("mathieu", 1000.0, 100.0, 10.0)}
XCHECK = {"tiny": ("mathieu", 1000.0), "small": ("mathieu", 1000.0),
          "medium": ("mathieu", 1000.0, 100.0)}
PEER_RTOLS = 10.0 ** -np.arange(3, 13)
MATHIEU = dict(delta=1.0, eps=0.4, zeta=0.02)
CASES["large"], XCHECK["large"] = CASES["medium"], XCHECK["medium"]  # run.py --size large


class Case:
    """One chart point: femmech's public call ``record(rtol, max_steps) -> Monodromy`` and
    the same ``coefficients(t) -> (M, B, C)`` stacks for the peer, period T (s)."""

    def __init__(self, name: str, record, coefficients, period: float, breaks=(),
                 A_of_t=None):
        self.name, self.record, self.coefficients = name, record, coefficients
        self.period, self.breaks = period, np.asarray(breaks, dtype=float)
        self.n = coefficients(np.zeros(1))[0].shape[-1]
        self.A_of_t = A_of_t

    def femmech(self, rtol=magnus.RTOL, max_steps=magnus.MAX_STEPS):
        return self.record(rtol, max_steps)

    def A(self, t: float) -> np.ndarray:
        """A(t) (2n, 2n) for the peer: the case's own formula if it has one."""
        if self.A_of_t is not None:
            return self.A_of_t(t)
        return magnus.first_order_matrices(*self.coefficients(np.array([t])))[0]


def mathieu_case() -> Case:
    d, e, z = MATHIEU["delta"], MATHIEU["eps"], MATHIEU["zeta"]
    b = 2 * z * np.sqrt(d)

    def C(t):
        return (d + e * np.cos(t))[:, None, None]

    def coefficients(t):
        return np.ones((t.size, 1, 1)), np.full((t.size, 1, 1), b), C(t)

    def record(rtol, max_steps):  # as stability_chart calls it for (M, B, C, T) tuples
        return monodromy_record(1.0, b, C, 2 * np.pi, 32, rtol, max_steps)
    def A_of_t(t):  # the peer's fastest form: the 2 x 2 matrix written out
        return np.array([[0.0, 1.0], [-(d + e * np.cos(t)), -b]])
    return Case("Mathieu (n = 1)", record, coefficients, 2 * np.pi, A_of_t=A_of_t)


def press_case(system, rpm: float) -> Case:
    W = rpm * RPM

    def coefficients(t):  # as coupled_monodromy_record builds them
        return assemble_stack(system, system.mechanism_blocks(W * t, W))[:3]

    def record(rtol, max_steps):  # as stability_chart calls it for a CoupledSystem
        return coupled_monodromy_record(system, W, 32, 2 * np.pi, 0.0, None, rtol,
                                        max_steps)
    return Case(f"press (n = {system.n})", record, coefficients, 2 * np.pi / W,
                drive_breakpoints(system) / W, lean_first_order(system, W))


def lean_first_order(system, W: float):
    """The peer's right-hand side matrix A(t) (2n, 2n) of a coupled system at speed W:
    the constant parts once, per call only each mount's model matrices at its angle,
    projected (Pᵀ M_m P) and added, then one solve. A quarter of the time per call of
    ``system.matrices`` (whose batched machinery is built for many angles at once), same
    A to 2e-15 relative."""
    M0, B0, K0 = (np.asarray(X, dtype=float) for X in (system.M0, system.B0, system.K0))
    n = system.n
    parts = [(mount, P, np.ix_(idx, idx)) for mount, P, idx in
             zip(system.mounts, system.projections, system.touched, strict=True)]

    def A_of_t(t):
        M, B, C = M0.copy(), B0.copy(), K0.copy()
        for mount, P, ix in parts:
            angle, speed = mount.ratio * W * t + mount.phase, mount.ratio * W
            M[ix] += P.T @ mount.model.M(angle) @ P
            B[ix] += P.T @ mount.model.B(angle, speed) @ P
            C[ix] += P.T @ mount.model.C(angle, speed, 0.0) @ P
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:] = -np.linalg.solve(M, np.hstack([C, B]))
        return A
    return A_of_t


def peer(case: Case, rtol: float, frozen: bool = False):
    """(ρ, nfev) of DOP853 on Z' = A(t) Z, Z(0) = I (A at t = 0 throughout if frozen)."""
    m = 2 * case.n
    A0 = case.A(0.0) if frozen else None

    def rhs(t, y):
        A = A0 if frozen else case.A(t)
        return (A @ y.reshape(m, m)).ravel()

    sol = solve_ivp(rhs, (0.0, case.period), np.eye(m).ravel(), method="DOP853", rtol=rtol,
                    atol=rtol * 1e-3 if rtol > 1e-12 else 1e-15, t_eval=[case.period],
                    dense_output=False)
    if not sol.success:
        return np.nan, sol.nfev
    return magnus._spectral_radius(sol.y[:, -1].reshape(m, m)), sol.nfev


def case_row(case: Case, speed: str, repeats: int, xcheck: bool) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        ref = case.femmech(1e-10, 2**16)
    rho = ref.spectral_radius
    cross = peer(case, 1e-12)[0] if xcheck else np.nan
    got = case.femmech()
    err = abs(got.spectral_radius - rho) / rho
    for rtol in PEER_RTOLS:  # calibration, untimed: the loosest rtol as accurate as femmech
        p_rho, nfev = peer(case, rtol)
        if abs(p_rho - rho) / rho <= err:
            break
    t = peers.interleaved({"femmech": case.femmech, "peer": lambda: peer(case, rtol),
                           "floor": lambda: peer(case, rtol, frozen=True)}, repeats)
    fm = t["femmech"].value
    return dict(case=case.name, speed=speed, t=t, steps=fm.n_steps, converged=fm.converged,
                rho=rho, ref_steps=ref.n_steps, ref_converged=ref.converged,
                xcheck=abs(cross - rho) / rho, err=abs(fm.spectral_radius - rho) / rho,
                peer_rtol=rtol, nfev=nfev, peer_err=abs(t["peer"].value[0] - rho) / rho,
                ratio=t["peer"].min / t["femmech"].min,
                floor_ratio=t["floor"].min / t["femmech"].min)


def main(size: str = "small", repeats: int = 3):
    base = peers.idle_baseline()
    system = press() if any(c != "mathieu" for c in CASES[size]) else None
    rows = []
    for c in CASES[size]:
        case = mathieu_case() if c == "mathieu" else press_case(system, c)
        speed = "1 rad/s" if c == "mathieu" else f"{c:g} rpm"
        rows.append(case_row(case, speed, repeats, c in XCHECK[size]))
    after = peers.idle_baseline()
    text = peers.table(
        f"Target 5: stability-chart point (monodromy, rtol {magnus.RTOL:g} with step"
        f" doubling) vs solve_ivp DOP853 at the same accuracy of ρ, s (min / median of"
        f" {repeats}); target peer / femmech >= {TARGET:g}",
        ["case", "speed", "femmech s", "steps", "ρ err", "DOP853 s",
         "DOP853 rtol", "nfev", "ρ err", "floor s", "DOP853/femmech", "floor/femmech",
         "verdict"],
        [[x["case"], x["speed"], x["t"]["femmech"].cell(spec=".4f"), str(x["steps"]),
          f"{x['err']:.1e}",
          x["t"]["peer"].cell(spec=".4f"), f"{x['peer_rtol']:.0e}", str(x["nfev"]),
          f"{x['peer_err']:.1e}", x["t"]["floor"].cell(spec=".4f"), f"{x['ratio']:.1f}",
          f"{x['floor_ratio']:.1f}", peers.verdict(x["ratio"], TARGET, at_most=False)]
         for x in rows])
    text += [f"{x['case']} {x['speed']}: reference ρ = {x['rho']:.13g} (femmech rtol 1e-10,"
             f" {x['ref_steps']} steps, converged {x['ref_converged']}); DOP853 rtol 1e-12 "
             + (f"differs by {x['xcheck']:.1e}" if np.isfinite(x["xcheck"]) else "not run")
             for x in rows]
    text += ["ρ err: |ρ − ρ_ref| / ρ_ref. floor: DOP853 with A frozen at t = 0 (no"
             " coefficient evaluation), same rtol.", peers.baseline_line(base, after), ""]
    out = [dict(case=x["case"], speed=x["speed"], femmech_s=x["t"]["femmech"].min,
                femmech_median_s=x["t"]["femmech"].median, steps=x["steps"],
                femmech_err=x["err"],
                peer_s=x["t"]["peer"].min, peer_median_s=x["t"]["peer"].median,
                peer_rtol=x["peer_rtol"], peer_err=x["peer_err"], nfev=x["nfev"],
                floor_s=x["t"]["floor"].min, ratio=x["ratio"],
                floor_ratio=x["floor_ratio"], reference=x["rho"],
                reference_xcheck=x["xcheck"]) for x in rows]
    return text, out


if __name__ == "__main__":
    peers.cli(main, CASES, __doc__)
