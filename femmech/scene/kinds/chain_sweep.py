"""Analysis kind ``chain_sweep``: the quasi-eigenfrequencies of the scene's chain
(``[chain]``) over the drive angle by several methods side by side
(:func:`femmech.chain.sweep.chain_sweep`): CSV, one chart panel per method, the largest
differences between the methods.

Stage 8 (scene): reading uses scene.kinds.common; the runner imports the chain and output
modules it calls when it runs.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from femmech.output.csv_rows import write_csv
from femmech.output.report import Figure, Section, Table
from femmech.scene.chain import METHOD_NAMES, METHODS
from femmech.scene.kinds.common import (
    AnalysisKind,
    ReadContext,
    chain_angles,
    listed,
    needs_chain,
    read_n_modes,
)
from femmech.scene.reader import Reader, show


@dataclass(frozen=True)
class ChainSweepSpec:
    """Quasi-eigenfrequencies of the chain over the drive angles (rad) by ``methods``."""

    methods: tuple
    n_modes: int
    angles: tuple


def method_list(t: Reader, key: str, default: tuple) -> tuple:
    methods = t.strings(key, default)
    if not methods:
        raise t.error(key, f"expected at least one of {list(METHODS)}")
    for m in methods:
        if m not in METHODS:
            raise t.error(key, f"expected names of {list(METHODS)}, got {show(m)}")
    if len(set(methods)) < len(methods):
        raise t.error(key, f"a method is named twice: {show(list(methods))}")
    return methods


def read(t: Reader, context: ReadContext) -> ChainSweepSpec:
    """``[analyses.chain_sweep]``: methods (default assembled, transfer, continuum),
    n_modes (6), angles (0..360°, 73)."""
    needs_chain(t, context.chain)
    methods = method_list(t, "methods", ("assembled", "transfer", "continuum"))
    return ChainSweepSpec(methods, read_n_modes(t, 6), chain_angles(t, 73))


def chain_rows(sweeps: dict, reference: str):
    """Per method and branch: min, max over φ (Hz) and the largest relative difference
    from the ``reference`` method (frequencies sorted per angle before comparing)."""
    ref = np.sort(sweeps[reference].freq_hz, axis=1)
    rows, diffs = [], {}
    for method, s in sweeps.items():
        f = np.sort(s.freq_hz, axis=1)
        k = min(f.shape[1], ref.shape[1])
        d = np.abs(f[:, :k] - ref[:, :k]) / np.where(ref[:, :k] > 0, ref[:, :k], 1.0)
        diffs[method] = float(d.max()) if d.size else 0.0
        rows += [(method, j + 1, float(f[:, j].min()), float(f[:, j].max()),
                  f"{d[:, j].max():.1e}" if j < k else "-") for j in range(f.shape[1])]
    return tuple(rows), diffs


def run(ws, spec, out):
    """Quasi-eigenfrequencies of the chain over the drive angle by each method, side by
    side: CSV, a chart with one panel per method, the differences between methods."""
    from femmech.chain.sweep import chain_sweep
    from femmech.output.chain_plots import plot_method_sweeps

    chain, phi = ws.prepared.chain, np.asarray(spec.angles, dtype=float)
    sweeps, seconds = {}, {}
    for method in spec.methods:
        with ws.timed(f"chain sweep {method}"):
            start = time.perf_counter()
            sweeps[method] = chain_sweep(chain, phi, spec.n_modes, method=method)
            seconds[method] = time.perf_counter() - start
    reference = "assembled" if "assembled" in sweeps else spec.methods[0]
    rows, diffs = chain_rows(sweeps, reference)
    plot_method_sweeps(sweeps, out / "chain_sweep.png", f"{ws.scene.name}: {chain.n_units}"
                       f" units, quasi-eigenfrequencies by method")
    n = spec.n_modes
    write_csv(out / "chain_frequencies.csv", ["method", "angle_deg"] +
               [f"f{k + 1}_hz" for k in range(n)],
               [(m, float(np.rad2deg(a)), *s.freq_hz[i]) for m, s in sweeps.items()
                for i, a in enumerate(s.phi)])
    text = (f"Chain of {chain.n_units} units ({chain.n} coordinates), {phi.size} drive angles"
            f" from {np.rad2deg(phi[0]):.1f}° to {np.rad2deg(phi[-1]):.1f}°, the {n} lowest"
            " quasi-eigenfrequencies of the frozen chain (C(φ) v = ω² M(φ) v, Ω = 0) by "
            + "; ".join(f"{m}: {METHOD_NAMES[m]}, {1e3 * seconds[m] / phi.size:.2f} ms per"
                        f" angle" for m in sweeps) + ".",
            f"The column 'vs {reference}' is the largest relative difference from the"
            f" {reference} frequencies over all angles (sorted per angle). Round-off level"
            " (1e-9 and below) means the methods agree; the continuum's difference is its"
            " modelling error (smeared units), largest for the higher branches.")
    table = Table("Range of each branch over the revolution, by method",
                  ("method", "branch", "min (Hz)", "max (Hz)", f"vs {reference}"), rows)
    section = Section("Chain: quasi-eigenfrequencies over the drive angle by method", text,
                      (table,), (Figure("chain_sweep.png", "Quasi-eigenfrequencies of the"
                                        " chain over one revolution; one panel per method,"
                                        " common frequency axis"),),
                      ("chain_frequencies.csv",))
    return section, {"phi_rad": listed(phi), "reference": reference,
                     "freq_hz": {m: listed(s.freq_hz) for m, s in sweeps.items()},
                     "max_rel_difference": diffs}


KIND = AnalysisKind(
    "chain_sweep", ("methods", "n_modes", "angles"), read, run,
    "quasi-eigenfrequencies of the chain over the drive angle by several methods, side"
    " by side", order=70)
