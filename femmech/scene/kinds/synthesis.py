"""Analysis kind ``synthesis`` (the top-level table ``[synthesis]``, read with the scene
by :func:`femmech.scene.chain.read_synthesis`): design parameters of the chain within
bounds that keep every quasi-eigenfrequency the required margin away from the harmonic
bands (:func:`femmech.chain.synthesis.synthesise`); before/after Campbell diagrams.

Stage 8 (scene): uses scene.chain (the design parameters) and scene.kinds.common; the
runner imports the chain and output modules it calls when it runs.
"""

from __future__ import annotations

from femmech.output.csv_rows import write_csv
from femmech.output.report import Figure, Section, Table
from femmech.scene.chain import (
    DESIGN,
    SYNTHESIS_KEYS,
    build_chain,
    design_quantity,
    design_values,
    read_synthesis,
)
from femmech.scene.kinds.common import AnalysisKind, ReadContext, in_rpm, margin_text
from femmech.scene.reader import Reader


def read(t: Reader, context: ReadContext):
    """``[synthesis]`` → :class:`femmech.scene.chain.SynthesisSpec`."""
    return read_synthesis(t, context.chain)


LOG_SCALE = ("coupling_stiffness", "flywheel_inertia", "follower_stiffness", "hub_inertia",
              "station_inertia")
"""Design parameters searched on a log scale (they may span decades)."""


def run(ws, spec, out):
    """Synthesis: design parameters within bounds that keep every quasi-eigenfrequency
    the required margin away from the harmonic bands; before/after Campbell diagrams."""
    from femmech.chain.synthesis import Parameter, synthesise
    from femmech.output.campbell import plot_margins, plot_synthesis

    chain_spec, rpm = ws.scene.chain, in_rpm(spec.speeds)
    current = design_values(chain_spec)
    params = [Parameter(name, lo, hi, current[name], log=name in LOG_SCALE and lo > 0)
              for name, lo, hi in spec.parameters]
    with ws.timed("synthesis"):
        r = synthesise(lambda values: build_chain(chain_spec, values), params, rpm,
                       spec.harmonics, spec.margin, spec.n_modes, spec.n_angles,
                       spec.starts, spec.seed, spec.objective)
    plot_synthesis(r, out / "synthesis_campbell.png")
    plot_margins(r, out / "synthesis_margins.png")
    write_csv(out / "synthesis.csv", ["parameter", "before_si", "after_si", "lower_si",
                                       "upper_si"],
               [(p.name, r.before[p.name], r.after[p.name], p.lower, p.upper)
                for p in params])
    rows = tuple((name, DESIGN[name][1], design_quantity(name, r.before[name]),
                  design_quantity(name, r.after[name], 5),
                  f"{design_quantity(name, lo)} … {design_quantity(name, hi)}")
                 for name, lo, hi in spec.parameters)
    rows += (("resonance margin", "smallest relative distance to a harmonic band",
              f"{100 * r.margin_before.value:+.2f} %", f"{100 * r.margin_after.value:+.2f} %",
              f"required ≥ {100 * spec.margin:g} %"),)
    bad = r.not_converged
    text = (f"Speed range {rpm[0]:.0f}–{rpm[1]:.0f} rpm, harmonics k = 1…{spec.harmonics},"
            f" required margin {100 * spec.margin:g} %, {spec.n_angles} drive angles per"
            f" revolution, {'all' if spec.n_modes is None else spec.n_modes} branches."
            f" Objective {spec.objective!r}: " + (
                "the feasible design closest to the scene's (normalised parameters)"
                if spec.objective == "closest" else "the largest margin within the bounds")
            + f"; {len(r.starts)} starts (the scene's design and a Latin hypercube), gradients"
            " from the eigenvalue sensitivities (KS-smoothed minimum over angles, branches"
            f" and harmonics); {r.evaluations} designs evaluated in {r.seconds:.1f} s.",
            "Before: " + margin_text(r.margin_before, spec.margin) + ".",
            "After: " + margin_text(r.margin_after, spec.margin) + f"; on a 4× finer angle"
            f" grid {100 * r.margin_check.value:+.2f} %.")
    warn = () if r.feasible else ("No start met the required margin within the bounds: the"
                                  " design with the largest margin is shown. Widen the"
                                  " bounds or narrow the speed range.",)
    if bad:
        text += (f"{len(bad)} of {len(r.starts)} starts ended without the optimiser's"
                 " convergence flag (their designs are still evaluated exactly).",)
    section = Section("Chain: synthesis", text, (Table(
        "Design parameters before and after the synthesis", ("parameter", "meaning",
                                                              "before", "after", "bounds"),
        rows),), (Figure("synthesis_campbell.png", "Campbell diagram before (grey) and after"
                         " (colour) the synthesis; hatched: harmonic bands widened by the"
                         " margin"),
                  Figure("synthesis_margins.png", "Smallest margin of each branch to the"
                         " harmonic bands, before and after")), ("synthesis.csv",),
        warnings=warn)
    return section, {"feasible": bool(r.feasible), "margin_before": r.margin_before.value,
                     "margin_after": r.margin_after.value,
                     "margin_after_fine": r.margin_check.value, "required": spec.margin,
                     "before": dict(r.before), "after": dict(r.after),
                     "evaluations": r.evaluations}


KIND = AnalysisKind(
    "synthesis", SYNTHESIS_KEYS, read, run,
    "design parameters of the chain within bounds that keep its quasi-eigenfrequencies"
    " a margin away from the harmonic bands", order=90, top_level=True)
