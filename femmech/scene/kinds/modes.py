"""Analysis kind ``modes``: natural modes of one part, of its full FE model
(:func:`femmech.modes`) or its superelement
(:func:`femmech.analysis.modes.superelement_modes`); frequency table and CSV, VTU, a PVD
series, mode images and animations, mass participation, optionally the discretisation
error per mode.

Stage 8 (scene): reading uses scene.kinds.common; the runner imports the analysis and
output modules it calls when it runs (``femmech check`` imports none of them).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femmech.output.formatting import Quantity
from femmech.output.report import Figure, Flagged, Section, Table, rigid_modes_note
from femmech.scene.kinds.common import (
    MAX_ANIMATIONS,
    MAX_IMAGES,
    AnalysisKind,
    ReadContext,
    listed,
    only_part,
    read_n_modes,
    read_values,
)
from femmech.scene.reader import Reader, show
from femmech.scene.units import FREQUENCY


@dataclass(frozen=True)
class ModesSpec:
    """Natural modes of one part (full model or superelement)."""

    part: str
    n_modes: int | None
    band_hz: tuple | None
    model: str
    images: int
    vtu: bool
    series: bool = False
    animate: tuple = ()
    discretisation_error: bool = False


def read(t: Reader, context: ReadContext) -> ModesSpec:
    """``[analyses.modes]`` → :class:`ModesSpec` (exactly one of n_modes and band_hz)."""
    parts = context.parts
    part = only_part(t, parts)
    n_modes = read_n_modes(t)
    band = read_values(t, "band_hz", FREQUENCY)
    if (n_modes is None) == (band is None):
        raise t.error(None, "give exactly one of n_modes and band_hz")
    if band is not None:
        if len(band) != 2:
            raise t.error("band_hz", f"expected [low, high], got {show(list(band))}")
        if not 0 <= band[0] < band[1]:
            raise t.error("band_hz", f"expected 0 <= low < high, got {show(list(band))} Hz")
    reduced = parts[part].reduction is not None
    model = t.string("model", "reduced" if reduced else "full", choices=("full", "reduced"))
    if model == "reduced" and not reduced:
        raise t.error("model", f"part {part!r} has no [reduction]; use model = 'full'")
    images = t.integer("images", min(n_modes or 6, 6), minimum=0, maximum=MAX_IMAGES,
                       limit="MAX_IMAGES")
    animate = t.get("animate", [])
    if not (isinstance(animate, list) and all(isinstance(k, int) and not isinstance(k, bool)
                                              and k >= 1 for k in animate)):
        raise t.error("animate", "expected a list of mode numbers (1 = the lowest mode), got"
                                 f" {show(animate)}")
    if len(set(animate)) > MAX_ANIMATIONS:
        raise t.error("animate", f"at most {MAX_ANIMATIONS} animations (MAX_ANIMATIONS)")
    return ModesSpec(part, n_modes, band, model, images, t.boolean("vtu", True),
                     t.boolean("series", False), tuple(sorted(set(animate))),
                     t.boolean("discretisation_error", False))


def run(ws, spec, out):
    """Natural modes of a part (full FE model or its superelement)."""
    from femmech.analysis.discretisation import discretisation_error_of
    from femmech.analysis.modes import modes, superelement_modes
    from femmech.output import export_modes_vtu, frequency_table, write_frequency_csv
    from femmech.output.animate import animate_mode
    from femmech.output.export import atomic_path
    from femmech.output.series import write_mode_series
    from femmech.output.tables import error_budget_columns
    from femmech.scene.summary import participation_tables
    from femmech.scene.workshop import progress

    drawn = spec.images or spec.vtu or spec.series or spec.animate
    model = ws.model(spec.part) if (spec.model == "full" or drawn
                                    or spec.discretisation_error) else None
    with ws.timed("eigen solve"):
        if spec.model == "full":
            result = modes(model, n_modes=spec.n_modes, band_hz=spec.band_hz)
        else:
            result = superelement_modes(ws.superelement(spec.part), spec.n_modes,
                                        spec.band_hz, model=model)
    with atomic_path(out / "frequencies.txt") as tmp:
        tmp.write_text(frequency_table(result), encoding="utf-8")
    write_frequency_csv(result, out / "frequencies.csv")
    files = ["frequencies.csv", "frequencies.txt"]
    if spec.vtu:
        export_modes_vtu(model, result, out / "modes.vtu")
        files.append("modes.vtu")
    if spec.series:
        write_mode_series(model, result, out / "modes.pvd")
        files.append("modes.pvd")  # with its folder modes_steps/
    figures = []
    for k in spec.animate:  # 1-based mode numbers; those beyond the computed set: noted
        if k > result.n_modes:
            ws.log(f"modes: animate mode {k}: only {result.n_modes} modes were computed")
            continue
        with ws.timed("mode animations"):
            path = animate_mode(model, result, k - 1, out / f"mode_{k:02d}.gif")
        figures.append(Figure(path.name, f"mode {k}: {result.freq_hz[k - 1]:.3f} Hz, moving"
                                         " through one period (slowed down)"))
    if spec.images:
        from femmech.output import plot_modes

        n = min(spec.images, result.n_modes)
        with ws.timed("mode images"):  # one scene and one camera for all images
            paths = plot_modes(model, result, out, range(n), prefix="mode",
                               progress=lambda it: progress(it, "mode images", ws.bars))
        figures += [Figure(p.name, f"mode {i + 1}: {result.freq_hz[i]:.3f} Hz")
                    for i, p in enumerate(paths)]
    est, confirmed = result.error_estimate, result.index_confirmed
    header = ("mode", "frequency (Hz)", "rigid") + (("estimated rel. error",) if est is not
                                                    None else ()) + (
        ("index vs full",) if confirmed is not None else ())
    rows = tuple((i + 1, Quantity(float(f), digits=6), "yes" if r else "no")
                 + ((Quantity(float(est[i]), digits=2),) if est is not None else ())
                 + ((index_cell(confirmed[i]),) if confirmed is not None else ())
                 for i, (f, r) in enumerate(zip(result.freq_hz, result.rigid, strict=True)))
    solver = f", factorisation {result.solver}" if result.solver else ""
    text = (f"Part {spec.part!r}, {spec.model} model ({result.method} solver{solver}):"
            f" {result.n_modes} modes.",)
    if result.n_unconfirmed:
        text += (f"{result.n_unconfirmed} reduced mode(s) marked unconfirmed: a Sturm count"
                 " of the full model shows that the full mode of the same number lies below"
                 " the error estimate (the reduction missed a mode below them); their"
                 " estimates compare with another full mode. Keep more fixed-interface"
                 " modes.",)
    extra = {}
    if spec.discretisation_error:  # opt-in: one h/2 refinement of the full model
        with ws.timed("discretisation estimate"):
            disc = discretisation_error_of(result, model, reduced=spec.model != "full")
        more, cells = error_budget_columns(disc, est)
        header, rows = header + more, tuple(r + c for r, c in zip(rows, cells, strict=True))
        text += (f"Discretisation error: estimated by one uniform refinement (h/2, free DOFs"
                 f" {' → '.join(map(str, disc.n_dof))}) and Richardson extrapolation with"
                 f" rate h^{disc.rate:g} ({', '.join(disc.kinds)} elements); highlighted"
                 " estimates are not trusted (their reason is given)."
                 + (" Total = discretisation + reduction." if est is not None else ""),)
        extra["discretisation_error"] = listed(np.where(disc.trusted, disc.error, np.nan))
    with ws.timed("mass participation"):
        tables, notes = participation_tables(model if model is not None else
                                             ws.model(spec.part), result, spec.part)
    section = Section("Natural modes", text + notes,
                      (Table("Natural frequencies", header, rows,
                             rigid_modes_note(result.rigid)), *tables),
                      tuple(figures), tuple(files), gallery=True)
    return section, {"part": spec.part, "model": spec.model, "freq_hz": listed(result.freq_hz),
                     **extra}


def index_cell(confirmed):
    """The index cell of a reduced mode: confirmed by the full model's Sturm count or
    flagged."""
    return "confirmed" if confirmed else Flagged("unconfirmed")


KIND = AnalysisKind(
    "modes", ("part", "n_modes", "band_hz", "model", "images", "vtu", "series", "animate",
              "discretisation_error"),
    read, run, "natural modes of one part (full FE model or superelement): frequencies,"
    " VTU, images, animations, mass participation", order=10)
