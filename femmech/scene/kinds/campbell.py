"""Analysis kind ``campbell``: the Campbell diagram of the scene's chain (``[chain]``):
the bands of its quasi-eigenfrequencies over one revolution against the harmonic fan
k·n over a speed range, and their resonance margin
(:func:`femmech.chain.synthesis.margin_of`).

Stage 8 (scene): reading uses scene.kinds.common; the runner imports the chain and output
modules it calls when it runs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from femmech.output.csv_rows import write_csv
from femmech.output.report import Figure, Flagged, Section, Table
from femmech.scene.kinds.common import (
    AnalysisKind,
    ReadContext,
    chain_angles,
    in_rpm,
    listed,
    margin_text,
    needs_chain,
    read_harmonics,
    read_margin,
    read_n_modes,
    read_speed_range,
)
from femmech.scene.reader import Reader


@dataclass(frozen=True)
class CampbellSpec:
    """Campbell diagram: the quasi-eigenfrequency bands (over ``angles``, rad) of the
    ``n_modes`` lowest branches against the drive speed range ``speeds`` = (lo, hi) rad/s,
    with the harmonics 1..``harmonics`` and the relative ``margin`` around their bands."""

    speeds: tuple
    harmonics: int
    n_modes: int
    angles: tuple
    margin: float


def read(t: Reader, context: ReadContext) -> CampbellSpec:
    """``[analyses.campbell]``: speeds [lo, hi], harmonics K, n_modes (6), angles (0..360°,
    37), margin (0.03)."""
    needs_chain(t, context.chain)
    return CampbellSpec(read_speed_range(t), read_harmonics(t), read_n_modes(t, 6),
                        chain_angles(t, 37), read_margin(t, 0.03))


def run(ws, spec, out):
    """Campbell diagram of the chain: the bands of its quasi-eigenfrequencies over one
    revolution against the harmonic fan k·n over the speed range."""
    from femmech.chain.synthesis import FrequencyBands, frequency_bands, margin_of
    from femmech.output.campbell import plot_campbell

    rpm, chain = in_rpm(spec.speeds), ws.prepared.chain
    with ws.timed("campbell"):
        bands = frequency_bands(chain, np.asarray(spec.angles, dtype=float))
        shown = FrequencyBands(bands.phi, bands.freq_hz[:, :spec.n_modes])
        m = margin_of(bands, rpm, spec.harmonics, spec.n_modes)
    plot_campbell(shown, rpm, spec.harmonics, out / "campbell.png", margin=spec.margin)
    write_csv(out / "campbell_bands.csv", ["branch", "min_hz", "mean_hz", "max_hz",
                                            "margin"],
               [(k + 1, shown.low[k], shown.mean[k], shown.high[k], m.per_branch[k])
                for k in range(shown.freq_hz.shape[1])])
    text = (f"Speed range {rpm[0]:.0f}–{rpm[1]:.0f} rpm, harmonics k = 1…{spec.harmonics}:"
            f" band k covers k·n/60 Hz over the range. The {shown.freq_hz.shape[1]} lowest"
            f" quasi-eigenfrequencies of the frozen chain at {bands.phi.size} drive angles;"
            " each branch is drawn as its min–max band over one revolution. Margin of a"
            " frequency f to band k: max(1 − f/(k n_lo/60), f/(k n_hi/60) − 1), negative"
            " inside the band.", "The r" + margin_text(m, spec.margin)[1:] + ".")
    rows = tuple((k + 1, float(shown.low[k]), float(shown.high[k]),
                  f"{100 * m.per_branch[k]:+.2f} %" if m.per_branch[k] >= spec.margin else
                  Flagged(f"{100 * m.per_branch[k]:+.2f} %"))
                 for k in range(shown.freq_hz.shape[1]))
    table = Table("Branches over one revolution and their margin to the harmonic bands",
                  ("branch", "min (Hz)", "max (Hz)", "margin"), rows)
    section = Section("Chain: Campbell diagram", text, (table,),
                      (Figure("campbell.png", "Campbell diagram: quasi-eigenfrequency bands"
                              " (min–max over one revolution) and the harmonic fan k·n;"
                              " red marks: resonances inside the speed range"),),
                      ("campbell_bands.csv",),
                      warnings=() if m.value >= spec.margin else
                      (f"The design resonates: {margin_text(m, spec.margin)}.",))
    return section, {"speed_rpm": list(rpm), "harmonics": spec.harmonics,
                     "margin": m.value, "required": spec.margin,
                     "low_hz": listed(shown.low), "high_hz": listed(shown.high)}


KIND = AnalysisKind(
    "campbell", ("speeds", "harmonics", "n_modes", "angles", "margin"), read, run,
    "Campbell diagram of the chain: quasi-eigenfrequency bands against the harmonic fan"
    " over a speed range, with the resonance margin", order=80)
