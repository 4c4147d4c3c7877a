"""Analysis kind ``check``: the reduced coupled machine against the unreduced one at
chosen drive angles (:func:`femmech.analysis.reference.compare_coupled`), optionally the
error and time per angle of several reduction sizes (the speed-versus-error comparison).

Stage 8 (scene): reading uses scene.kinds.common; the runner imports the analysis and
output modules it calls when it runs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femmech.output.csv_rows import write_csv
from femmech.output.formatting import Quantity
from femmech.output.report import Figure, Flagged, Section, Table
from femmech.scene.kinds.common import (
    MAX_LEVELS,
    AnalysisKind,
    ReadContext,
    listed,
    needs_machine,
    read_n_modes,
    read_values,
)
from femmech.scene.reader import Reader, show
from femmech.scene.units import ANGLE, FREQUENCY


@dataclass(frozen=True)
class CheckSpec:
    """Reduced versus full coupled quasi-modes at ``angles`` (rad); with ``levels``
    (f_max in Hz) also the error and time per angle of several reduction sizes."""

    angles: tuple
    n_modes: int
    levels: tuple


def read(t: Reader, context: ReadContext) -> CheckSpec:
    """``[analyses.check]`` → :class:`CheckSpec` (a machine of one reduced part)."""
    parts = context.parts
    needs_machine(t, parts, context.has_mounts, "a full-versus-reduced check")
    if len(parts) != 1:
        raise t.error(None, "the full-versus-reduced check needs a machine of one part")
    angles = read_values(t, "angles", ANGLE)
    if angles is None:
        raise t.error("angles", "missing (required): the drive angles to compare at")
    levels = read_values(t, "f_max_hz_levels", FREQUENCY, (), maximum=MAX_LEVELS,
                     limit="MAX_LEVELS")
    if levels and min(levels) <= 0:
        raise t.error("f_max_hz_levels", f"expected positive frequencies, got"
                                         f" {show(list(levels))}")
    reduction = next(iter(parts.values())).reduction
    if levels and reduction.method != "craig_bampton":
        raise t.error("f_max_hz_levels", "needs a craig_bampton reduction")
    return CheckSpec(angles, read_n_modes(t, 6), levels)


def compare(ws, reduced, full, angles, n_modes, desc):
    """:func:`femmech.analysis.reference.compare_coupled` angle by angle (with a progress
    bar ``desc``), joined into one Comparison."""
    from femmech.analysis.reference import Comparison, compare_coupled
    from femmech.scene.workshop import progress

    parts = [compare_coupled(reduced, full, [a], n_modes)
             for a in progress(angles, desc, ws.bars)]
    return Comparison(np.concatenate([c.phi for c in parts]),
                      np.vstack([c.freq_full_hz for c in parts]),
                      np.vstack([c.freq_reduced_hz for c in parts]),
                      np.concatenate([c.mac for c in parts]),
                      np.concatenate([c.seconds_full for c in parts]),
                      float(np.mean([c.seconds_reduced for c in parts])))


def run(ws, spec, out):
    """Reduced versus unreduced coupled machine; optionally error and time per angle of
    several reduction sizes (the speed-versus-error comparison)."""
    from femmech.coupling import couple
    from femmech.output import plot_mac
    from femmech.output.export import atomic_path
    from femmech.output.speed_error import plot_speed_error
    from femmech.scene.build import machine_mounts

    part = next(iter(ws.scene.parts))
    reduced, full = ws.machine(), ws.machine(full=True)
    with ws.timed("check"):
        comp = compare(ws, reduced, full, spec.angles, spec.n_modes, "check")
    with atomic_path(out / "reduced_vs_full.txt") as tmp:
        tmp.write_text(comp.table() + "\n", encoding="utf-8")
    k = np.arange(spec.n_modes)
    matches = matched_full_modes(comp)
    write_csv(out / "reduced_vs_full.csv", ["angle_deg", "mode", "full_hz", "reduced_hz",
                                             "rel_error", "mac", "matches_full_mode"],
               [(float(np.rad2deg(a)), int(j + 1), comp.freq_full_hz[i, j],
                 comp.freq_reduced_hz[i, j], comp.rel_error[i, j], comp.diag_mac[i, j],
                 int(matches[i, j] + 1))
                for i, a in enumerate(comp.phi) for j in k])
    plot_mac(comp.mac[0], out / "mac_reduced_vs_full.png", "reduced coupled modes",
             "full coupled modes", f"MAC at φ = {np.rad2deg(comp.phi[0]):.0f}°")
    se = ws.superelement(part)
    err, mac = float(np.abs(comp.rel_error).max()), float(comp.diag_mac.min())
    rows = [("full", full.n, 1e3 * float(comp.seconds_full.mean()), 0.0, 1.0),
            ("scene reduction", reduced.n, 1e3 * comp.seconds_reduced, err, mac)]
    levels = []
    for f_max in spec.levels:
        system = couple(ws.superelement(part, f_max), machine_mounts(ws.prepared))
        c = compare(ws, system, full, spec.angles, spec.n_modes, f"f_max {f_max:g} Hz")
        e, m = float(np.abs(c.rel_error).max()), float(c.diag_mac.min())
        rows.append((f"f_max {f_max:g} Hz", system.n, 1e3 * c.seconds_reduced, e, m))
        levels.append({"f_max_hz": f_max, "n": system.n, "max_rel_error": e, "min_mac": m})
    tables = [Table("Reduced versus full at the check angles", ("angle (°)", "mode",
                                                               "full (Hz)", "reduced (Hz)",
                                                               "rel. error", "MAC",
                                                               "matches full mode"),
                    tuple((f"{np.rad2deg(a):.1f}", j + 1,  # 8 digits: the error is ~1e-7
                           Quantity(float(comp.freq_full_hz[i, j]), digits=8),
                           Quantity(float(comp.freq_reduced_hz[i, j]), digits=8),
                           f"{comp.rel_error[i, j]:.2e}", f"{comp.diag_mac[i, j]:.8f}",
                           j + 1 if matches[i, j] == j else
                           Flagged(f"{matches[i, j] + 1}: index unconfirmed"))
                          for i, a in enumerate(comp.phi) for j in k)),
              Table("Speed versus error", ("model", "coordinates", "ms per angle",
                                           "max |rel. error|", "min MAC"),
                    tuple((r[0], r[1], f"{r[2]:.2f}", f"{r[3]:.2e}", f"{r[4]:.8f}")
                          for r in rows))]
    figures = [Figure("mac_reduced_vs_full.png", "MAC of reduced against full modes")]
    files = ["reduced_vs_full.txt", "reduced_vs_full.csv"]
    if levels:
        plot_speed_error(rows, out / "speed_vs_error.png")
        figures.append(Figure("speed_vs_error.png", "Time per angle versus frequency error"))
    text = (f"Superelement of part {part!r}: {se.n_reduced} coordinates (full model"
            f" {len(se.free_interface) + len(se.free_interior)} free DOFs); max |rel. error|"
            f" {err:.2e}, min MAC {mac:.8f} at {comp.phi.size} angles.",)
    off = np.count_nonzero(matches != k)
    if off:
        text += (f"{off} reduced mode(s) resemble another full mode (largest MAC) that is"
                 " also nearer in frequency than the full mode of the same number: the"
                 " reduction missed a full mode below them, so their rows compare different"
                 " modes (marked 'index unconfirmed'). Keep more fixed-interface modes.",)
    section = Section("Reduced versus full", text, tuple(tables), tuple(figures), tuple(files))
    return section, {"rel_error": listed(comp.rel_error), "diag_mac": listed(comp.diag_mac),
                     "max_rel_error": err, "min_mac": mac, "levels": levels}


def matched_full_modes(comp) -> np.ndarray:
    """The full mode (0-based) that each reduced mode is, (n_angles, n_modes) of int.

    Reduced mode k is full mode k unless another full mode j has the largest MAC with it
    and lies nearer to its frequency than full mode k: then the reduction missed a full
    mode below, and the row of mode k compares two different modes. A largest MAC off the
    diagonal alone is not enough (the pairs of a symmetric frame mix freely).
    """
    n = comp.freq_full_hz.shape[1]
    same = np.arange(n)
    best = np.argmax(comp.mac, axis=2)
    f_red, f_full = comp.freq_reduced_hz, comp.freq_full_hz
    own = np.abs(f_red / f_full - 1.0)
    other = np.abs(f_red / np.take_along_axis(f_full, best, axis=1) - 1.0)
    return np.where((best != same) & (other < own), best, same)


KIND = AnalysisKind(
    "check", ("angles", "n_modes", "f_max_hz_levels"), read, run,
    "reduced versus full coupled quasi-modes at chosen drive angles, optionally the speed"
    " versus error of several reduction sizes", order=50)
