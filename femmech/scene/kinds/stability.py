"""Analysis kind ``stability``: the spectral radius of the monodromy matrix over drive
speed (Floquet stability chart, :func:`femmech.analysis.stability.stability_chart`),
each speed's Magnus steps doubled to its tolerance; chart, CSV, unconverged points named.

Stage 8 (scene): reading uses scene.kinds.common; the runner imports the analysis and
output modules it calls when it runs.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from femmech.errors import ConvergenceWarning
from femmech.output.charts import format_speed, speed_scale
from femmech.output.csv_rows import write_csv
from femmech.output.report import Figure, Flagged, Section, Table
from femmech.scene.kinds.common import (
    MAX_STEPS,
    AnalysisKind,
    ReadContext,
    damped,
    listed,
    needs_machine,
    read_rayleigh,
    read_values,
    speed_column,
    speed_range,
)
from femmech.scene.reader import Reader
from femmech.scene.units import ANGLE, DIMENSIONLESS, SPEED


@dataclass(frozen=True)
class StabilitySpec:
    """Spectral radius of the monodromy matrix over drive speeds (rad/s)."""

    speeds: tuple
    n_steps: int
    angle_period: float
    rayleigh: tuple
    tol: float
    rtol: float
    max_steps: int
    speed_unit: str = "rpm"


def read(t: Reader, context: ReadContext) -> StabilitySpec:
    """``[analyses.stability]`` → :class:`StabilitySpec` in the scene's speed unit."""
    needs_machine(t, context.parts, context.has_mounts, "a stability chart")
    speeds = read_values(t, "speeds", SPEED)
    if speeds is None or len(speeds) < 2 or min(speeds) <= 0:
        raise t.error("speeds", "expected >= 2 positive drive speeds (list or {start, stop,"
                                " n}), e.g. {start = '100 rpm', stop = '3000 rpm', n = 30}")
    n_steps = t.integer("n_steps", 32, minimum=4, maximum=MAX_STEPS, limit="MAX_STEPS")
    from femmech.analysis.magnus import MAX_STEPS as MONODROMY_MAX_STEPS
    from femmech.analysis.magnus import RTOL as MONODROMY_RTOL

    return StabilitySpec(speeds, n_steps,
                         t.number("angle_period", ANGLE, 2 * np.pi, positive=True),
                         read_rayleigh(t), t.number("tol", DIMENSIONLESS, 1e-6, positive=True),
                         t.number("rtol", DIMENSIONLESS, MONODROMY_RTOL, positive=True),
                         t.integer("max_steps", max(MONODROMY_MAX_STEPS, n_steps),
                                   minimum=n_steps, maximum=MAX_STEPS, limit="MAX_STEPS"),
                         context.speed_unit)


def run(ws, spec, out):
    """Floquet spectral radius over drive speed (stability chart), each point checked."""
    from femmech.analysis.stability import stability_chart
    from femmech.analysis.studies import merge_charts
    from femmech.output.stability_charts import plot_stability_chart
    from femmech.scene.workshop import progress

    system = damped(ws, spec.rayleigh)
    speeds = np.asarray(spec.speeds, dtype=float)
    with warnings.catch_warnings():  # unconverged points are marked below, not warned
        warnings.simplefilter("ignore", ConvergenceWarning)
        points = [stability_chart(system, [W], n_steps=spec.n_steps,
                                  angle_period=spec.angle_period, tol=spec.tol,
                                  rtol=spec.rtol, max_steps=spec.max_steps)
                  for W in progress(speeds, "stability", ws.bars)]
    chart = merge_charts(points, 1, len(points), speeds, None)
    radius, error, stable = chart.spectral_radius[0], chart.error[0], chart.stable[0]
    ok, steps = chart.converged[0], chart.n_steps[0]
    unit, scale = spec.speed_unit, speed_scale(spec.speed_unit)
    plot_stability_chart(chart, out / "stability_chart.png", title=ws.scene.name,
                         speed_unit=unit)
    write_csv(out / "stability.csv", [speed_column(unit), "spectral_radius",
                                       "error_estimate", "converged", "n_steps", "stable"],
               [(W * scale, r, e, int(c), n, int(s) if c else "")
                for W, r, e, c, n, s in zip(speeds, radius, error, ok, steps, stable,
                                            strict=True)])
    unstable = speeds[~stable & ok]
    text = (f"{speeds.size} speeds from {format_speed(speeds[0], unit)} to"
            f" {format_speed(speeds[-1], unit)};"
            f" Rayleigh damping (mass, stiffness) = {spec.rayleigh}. Magnus steps per period"
            f" doubled from {spec.n_steps} until the spectral radius changed by at most"
            f" {spec.rtol:g} (relative; {steps.min()}..{steps.max()} steps were needed)."
            f" Unstable at {unstable.size} speeds"
            + (f" ({speed_range(unstable.min(), unstable.max(), unit)}, shaded in the"
               " chart)." if unstable.size else "."),)
    flags = ()
    if not ok.all():
        bad = speeds[~ok]
        flags = (f"{int((~ok).sum())} of {speeds.size} speeds"
                 f" ({speed_range(bad.min(), bad.max(), unit)}) did NOT converge"
                 f" within max_steps = {spec.max_steps} Magnus steps per"
                 " period: their spectral radius and verdict may be wrong (hollow circles on"
                 " a hatched band in the chart, converged = 0 in stability.csv). Raise"
                 " max_steps.",)
        ws.log(f"stability: {flags[0]}")
    rows = tuple((float(W * scale), float(r), f"{e:.1e}", "yes" if s else "no")
                 if c else (float(W * scale), Flagged(f"{r:.6g} NOT CONVERGED"), f"{e:.1e}",
                            Flagged("unknown"))
                 for W, r, e, c, s in zip(speeds, radius, error, ok, stable, strict=True))
    section = Section("Stability chart", text, (Table("Spectral radius of the monodromy"
                                                      " matrix", (f"speed ({unit})", "max |μ|",
                                                                  "error estimate of max |μ|",
                                                                  "stable"), rows),),
                      (Figure("stability_chart.png", "Floquet stability over drive speed"),),
                      ("stability.csv",), warnings=flags)
    return section, {"speeds_rad_s": listed(speeds), "spectral_radius": listed(radius),
                     "error_estimate": listed(error), "converged": [bool(c) for c in ok]}


KIND = AnalysisKind(
    "stability", ("speeds", "n_steps", "angle_period", "rayleigh", "tol", "rtol",
                  "max_steps"),
    read, run, "Floquet stability chart: spectral radius of the monodromy matrix over"
    " drive speed", order=30)
