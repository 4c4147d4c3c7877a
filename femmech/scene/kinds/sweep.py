"""Analysis kind ``sweep``: quasi-eigenfrequencies over the drive angle at one or more
drive speeds, of the coupled machine (:func:`femmech.analysis.sweep.sweep`) or of a
mechanism alone (:func:`femmech.mechanisms.quasi_modes`); diagram, CSV and coupled mode
images.

Stage 8 (scene): reading uses scene.kinds.common; the runner imports the analysis and
output modules it calls when it runs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femmech.output.charts import format_speed, speed_resolution, speed_scale
from femmech.output.csv_rows import write_csv
from femmech.output.report import Figure, Section, Table
from femmech.scene.kinds.common import (
    MAX_IMAGES,
    MAX_SWEEP_POINTS,
    AnalysisKind,
    ReadContext,
    listed,
    needs_machine,
    read_n_modes,
    read_values,
    speed_column,
)
from femmech.scene.reader import Reader, show
from femmech.scene.units import ANGLE, SPEED


@dataclass(frozen=True)
class SweepSpec:
    """Quasi-modes over drive angles (rad) at one or more drive speeds (rad/s)."""

    angles: tuple
    n_modes: int | None  # None: up to 6, all branches where fewer exist (said in the report)
    speeds: tuple
    mechanism: str | None
    track: bool
    mode_images_at: tuple
    speed_unit: str = "rpm"


def read(t: Reader, context: ReadContext) -> SweepSpec:
    """``[analyses.sweep]`` → :class:`SweepSpec` in the scene's speed unit; the speeds'
    labels in that unit must differ."""
    parts, mechanisms = context.parts, context.mechanisms
    mechanism = t.string("mechanism", None)
    if mechanism is not None and mechanism not in mechanisms:
        raise t.error("mechanism", f"expected one of the [mechanisms] {sorted(mechanisms)},"
                                   f" got {show(mechanism)}")
    if mechanism is not None and mechanisms[mechanism].form != "rheolinear":
        raise t.error("mechanism", f"mechanism {mechanism!r} has form ="
                                   f" {mechanisms[mechanism].form!r}; quasi-modes need form ="
                                   " 'rheolinear' (the default)")
    if mechanism is None:
        needs_machine(t, parts, context.has_mounts, "a sweep of the machine (no mechanism key)")
    angles = read_values(t, "angles", ANGLE, (0.0, 2 * np.pi))
    at = read_values(t, "mode_images_at", ANGLE, (), maximum=MAX_IMAGES, limit="MAX_IMAGES")
    if at and (mechanism is not None or len(parts) != 1):
        raise t.error("mode_images_at", "mode images need a machine of one part (not a"
                                        " mechanism alone, not an assembly of parts)")
    n_modes = read_n_modes(t)  # None: sweep's default (6, or all branches where fewer exist)
    speeds = read_values(t, "speeds", SPEED, (0.0,))
    if len(angles) * len(speeds) > MAX_SWEEP_POINTS:
        raise t.error("speeds", f"{len(angles)} angles x {len(speeds)} speeds; at most"
                                f" {MAX_SWEEP_POINTS} points (limit MAX_SWEEP_POINTS)")
    distinct_labels(t, speeds, context.speed_unit)
    return SweepSpec(angles, n_modes, speeds, mechanism, t.boolean("track", True), at,
                     context.speed_unit)


def distinct_labels(t: Reader, speeds: tuple, unit: str) -> None:
    """Each curve of a sweep is labelled by its speed in ``unit``: no two labels alike."""
    labels = [format_speed(W, unit) for W in speeds]
    twice = [s for i, s in enumerate(labels) if s in labels[:i]]
    if twice:
        raise t.error("speeds", f"two speeds round to {twice[0]}; each curve of a sweep is"
                                f" labelled by its speed in {speed_resolution(unit)}")


def run(ws, spec, out):
    """Quasi-eigenfrequencies over the drive angle, per speed."""
    from femmech.analysis.sweep import sweep
    from femmech.mechanisms import quasi_modes
    from femmech.output.sweeps import plot_quasi_frequencies

    phi = np.asarray(spec.angles, dtype=float)
    unit, curves, notes = spec.speed_unit, {}, []
    for W in spec.speeds:
        label = format_speed(W, unit)
        with ws.timed("sweep"):
            if spec.mechanism is not None:
                q = quasi_modes(ws.prepared.mechanisms[spec.mechanism], phi, Omega=W)
                n_default = min(6, q.freq_hz.shape[1])
                curves[label] = Curve(q.phi, q.freq_hz[:, :spec.n_modes or n_default])
                if spec.n_modes is None and q.freq_hz.shape[1] < 6:
                    notes.append(f"n_modes not given: the mechanism has"
                                 f" {q.freq_hz.shape[1]} branches, fewer than the default 6;"
                                 " all are shown")
            else:
                s = sweep(ws.machine(), phi, Omega=W, n_modes=spec.n_modes, track=spec.track)
                curves[label] = Curve(s.phi, s.freq_hz)
                notes.extend(s.notes)
    what = f"mechanism {spec.mechanism!r} alone" if spec.mechanism else "coupled machine"
    plot_quasi_frequencies(curves, out / "quasi_frequencies.png",
                           title=f"{ws.scene.name}: {what}", speed_unit=unit)
    n = next(iter(curves.values())).freq_hz.shape[1]
    rows = [(W * speed_scale(unit), float(np.rad2deg(a)), *c.freq_hz[i])
            for W, c in zip(spec.speeds, curves.values(), strict=True)
            for i, a in enumerate(c.phi)]
    write_csv(out / "quasi_frequencies.csv", [speed_column(unit), "angle_deg"] +
               [f"f{k + 1}_hz" for k in range(n)], rows)
    table_rows = tuple((label, k + 1, float(np.nanmin(c.freq_hz[:, k])),
                        float(np.nanmax(c.freq_hz[:, k])))
                       for label, c in curves.items() for k in range(n))
    figures = [Figure("quasi_frequencies.png", f"Quasi-eigenfrequencies of the {what}")]
    for angle in spec.mode_images_at:
        figures.append(coupled_image(ws, spec, angle, out))
    text = (f"{phi.size} drive angles from {np.rad2deg(phi[0]):.1f}° to"
            f" {np.rad2deg(phi[-1]):.1f}°, {n} branches, speeds {', '.join(curves)}.",
            *(f"{note}." for note in dict.fromkeys(notes)))
    section = Section("Quasi-eigenfrequencies over the drive angle", text,
                      (Table("Range of each branch over the sweep", ("speed", "branch",
                                                                    "min (Hz)", "max (Hz)"),
                             table_rows),), tuple(figures), ("quasi_frequencies.csv",))
    return section, {"phi_rad": listed(phi), "speeds_rad_s": list(spec.speeds),
                     "freq_hz": [listed(c.freq_hz) for c in curves.values()]}


@dataclass(frozen=True)
class Curve:
    """phi (rad) and freq_hz of one sweep, for plot_quasi_frequencies."""

    phi: np.ndarray
    freq_hz: np.ndarray


def coupled_image(ws, spec, angle: float, out) -> Figure:
    """The lowest coupled quasi-mode at exactly the requested angle (rad) and the first
    speed of the sweep: solved there, not taken from the nearest angle of the sweep grid."""
    from femmech.analysis.sweep import sweep
    from femmech.output.machine import plot_coupled_mode

    W = float(spec.speeds[0])
    at = sweep(ws.machine(), np.array([angle]), Omega=W, n_modes=1, track=False,
               keep_vectors=True)
    deg = float(np.rad2deg(angle))
    name = "coupled_mode_" + f"{deg:g}".replace(".", "p") + "deg.png"  # 22.5° → 22p5deg
    part = next(iter(ws.scene.parts))
    plot_coupled_mode(ws.model(part), ws.machine(), at.vectors[0, :, 0], at.freq_hz[0, 0],
                      out / name, angle=angle, speed=W, mode_number=1,
                      speed_unit=spec.speed_unit)
    return Figure(name, f"lowest coupled quasi-mode at φ = {deg:g}°,"
                  f" {format_speed(W, spec.speed_unit)}: {at.freq_hz[0, 0]:.2f} Hz")


KIND = AnalysisKind(
    "sweep", ("angles", "n_modes", "speeds", "mechanism", "track", "mode_images_at"),
    read, run, "quasi-eigenfrequencies over the drive angle at one or more drive speeds"
    " (coupled machine or one mechanism)", order=20)
