"""Warp-knitting machine main shaft: 28 phased cam-follower units, tuned off the harmonics.

Physics
-------
A tricot warp-knitting machine drives its needle bar and guide bars from one main shaft
that runs along the machine's working width (seed chapter 5.1, Bild 5.1: a main shaft
driving N "identical" mechanisms working in parallel). Here 28 identical cam-follower
units sit every 0.25 m on a solid steel shaft of 50 mm (G = 80.77 GPa, ρ = 7850 kg/m³;
7 m of shaft). Each unit is a cam hub (J = 2·10⁻³ kg·m² about the shaft) with a
modified-sine rise–dwell–return–dwell programme (30 mm stroke; rise 120°, dwell 60°,
return 120°, dwell 60°) that moves a follower (lever and bar share, m = 0.6 kg) through
an elastic follower train (c = 3·10⁵ N/m, 10 N·s/m). The units are phased evenly over the
revolution (unit u runs at φ + 360°·u/28), which evens out the drive torque. The motor and
its flywheel drive the left end through an elastic coupling (10⁴ N·m/rad); their inertia
is large against the shaft's (the speed is held by the drive), so for the shaft the
coupling is a torsion spring to a uniformly turning reference. The right end is free.
The shaft is modelled as a row of identical cells (``cells=True``: the shaft reaches half
a spacing beyond the outer units), which the continuum model needs.

Coordinates: the shaft rotation at each unit (rad) and each follower's elastic
deflection (m): 56 coordinates. Frozen at the drive angle φ (Ω = 0) each unit contributes
``M = [[J + m U'², m U'], [m U', m]]`` and ``C = diag(0, c)`` (:func:`femmech.chain.follower_unit`,
Table 5.1 case 1 of the chapter), and the quasi-eigenfrequencies solve
``C(φ) v = ω² M(φ) v``. They are computed over one revolution by three methods side by
side: the assembled model (dense eigen solve), transfer matrices (exact dynamic stiffness
with a Wittrick–Williams count: no root missed) and the smeared continuum (closed form per
wave number; its error is the dispersion of the discrete chain, larger for higher modes).

The machine runs between 1200 and 1400 rpm. Cam mechanisms excite the harmonics k·n of
the speed n; the first six carry most of the modified-sine law's content. The harmonic
bands k·[20, 23.33] Hz (k = 1…6) leave gaps: below 20 Hz, 23.3–40, 46.7–60, 70–80,
93.3–100, 116.7–120 Hz and above 140 Hz. As designed, two groups of quasi-eigenfrequencies
lie inside bands: the coupling mode (the shaft twisting on its coupling, ≈ 42.8 Hz, in
band k = 2) and the cluster of 28 follower modes (≈ 110–112 Hz, near √(c/m)/2π = 112.5 Hz,
in band k = 5). The synthesis (:func:`femmech.chain.synthesis.synthesise`) chooses the
coupling stiffness, shaft diameter, follower mass and follower stiffness within bounds so
that every quasi-eigenfrequency keeps a 3 % margin from every band over the whole
revolution. It is feasible: √(c/m)/2π above 144.2 Hz = 1.03·140 Hz needs c/m ≥ 8.2·10⁵ s⁻²
(e.g. c = 5·10⁵ N/m with m ≤ 0.61 kg), the coupling mode fits into the gap 23.3–40 Hz
(k_c ≈ 2·10³…7·10³ N·m/rad) or 46.7–60 Hz, and the next shaft mode (≈ 160 Hz) stays
above 144.2 Hz. The design closest to the initial one is returned.

Units: SI throughout (m, kg, s, N, rad); speeds in rpm where stated, frequencies in Hz.

Sources: seed chapter 5.1 (Bild 5.1: main shaft with N mechanisms; transfer matrices,
FEM and continuum as the methods; synthesis as the task). Cam law: Norton, *Cam Design
and Manufacturing Handbook* (2009), ch. 3. Machine data are representative of tricot
machines (working width 130–280 in, 1000–2500 rpm) but illustrative, not of one make.

The scene ``examples/knitting_machine_chain.toml`` describes the same machine; it also
writes the tables and the report (``femmech run examples/knitting_machine_chain.toml --out
out/knitting``).
"""

import argparse
import time
from pathlib import Path

import numpy as np

from femmech.chain import End, chain, follower_unit
from femmech.chain.sweep import compare_methods
from femmech.chain.synthesis import Parameter, frequency_bands, resonance_margin, synthesise
from femmech.mechanisms import cam_program
from femmech.output.campbell import plot_campbell, plot_synthesis
from femmech.output.formatting import format_value
from femmech.output.sweeps import plot_quasi_frequencies

N_UNITS = 28
SPACING = 0.25  # m
HUB_INERTIA = 2e-3  # kg m²
DAMPING = 10.0  # N s/m
SPEED_RPM = (1200.0, 1400.0)
HARMONICS = 6
MARGIN = 0.03
N_MODES = 6
METHODS = ("assembled", "transfer", "continuum")
INITIAL = {"coupling_stiffness": 1e4,  # N m/rad
           "shaft_diameter": 0.05,  # m
           "follower_mass": 0.6,  # kg
           "follower_stiffness": 3e5}  # N/m
BOUNDS = {"coupling_stiffness": (2e3, 5e4), "shaft_diameter": (0.04, 0.06),
          "follower_mass": (0.3, 1.0), "follower_stiffness": (1e5, 5e5)}
LOG_SCALE = ("coupling_stiffness", "follower_stiffness")
UNITS = {"coupling_stiffness": "N·m/rad", "shaft_diameter": "m", "follower_mass": "kg",
         "follower_stiffness": "N/m"}
"""Unit of each design value (SI), for the printed summary."""


def cam():
    """The modified-sine cam programme: 30 mm stroke, rise 120°, dwell 60°, return 120°,
    dwell 60° (angles in degrees, stroke in m)."""
    return cam_program(0.03, rise=120, dwell_top=60, return_=120, dwell_bottom=60,
                       law="modified_sine")


def build(values: dict):
    """The chain for design values (SI, keys of :data:`INITIAL`)."""
    v = {**INITIAL, **values}
    unit = follower_unit(cam(), HUB_INERTIA, v["follower_mass"], v["follower_stiffness"],
                         DAMPING)
    return chain(unit, N_UNITS, SPACING, v["shaft_diameter"],
                 phases=2 * np.pi * np.arange(N_UNITS) / N_UNITS,
                 left=End.elastic(v["coupling_stiffness"]), right=End.free(), cells=True)


def main(out_dir="out", n_angles: int = 73, starts: int = 2) -> dict:
    """Sweep by three methods, Campbell diagram, synthesis; PNGs into ``out_dir``.

    Returns
    -------
    dict
        ``sweeps`` {method: Sweep}; ``max_rel_difference`` {method: largest relative
        difference from the assembled frequencies (sorted per angle)}; ``margin_before``,
        ``margin_after`` (relative, the required one is ``MARGIN``), ``feasible``,
        ``before``/``after`` design values, ``check_after`` the after design's margin
        recomputed on 360 angles; ``seconds`` per step; ``plots`` the PNG paths.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    seconds, plots = {}, []
    machine = build(INITIAL)
    phi = np.linspace(0.0, 2 * np.pi, n_angles)
    start = time.perf_counter()
    sweeps = compare_methods(machine, phi, N_MODES, METHODS)
    seconds["sweeps"] = time.perf_counter() - start
    ref = np.sort(sweeps["assembled"].freq_hz, axis=1)
    diff = {m: float(np.max(np.abs(np.sort(s.freq_hz, axis=1) - ref) / ref))
            for m, s in sweeps.items()}
    plots.append(plot_quasi_frequencies(
        sweeps, out / "chain_sweep.png", speed=SPEED_RPM[1] * np.pi / 30,
        title=f"Warp-knitting main shaft, {N_UNITS} units: quasi-eigenfrequencies by method"))
    plots.append(plot_campbell(frequency_bands(machine, phi), SPEED_RPM, HARMONICS,
                               out / "campbell.png", margin=MARGIN))
    params = [Parameter(name, *BOUNDS[name], start=INITIAL[name], log=name in LOG_SCALE)
              for name in INITIAL]
    start = time.perf_counter()
    result = synthesise(build, params, SPEED_RPM, HARMONICS, MARGIN, n_angles=24,
                        starts=starts)
    seconds["synthesis"] = time.perf_counter() - start
    plots.append(plot_synthesis(result, out / "synthesis_campbell.png"))
    check = resonance_margin(build(result.after), SPEED_RPM, HARMONICS, n_angles=360)
    return {"sweeps": sweeps, "max_rel_difference": diff,
            "margin_before": result.margin_before.value,
            "margin_after": result.margin_after.value, "check_after": check.value,
            "feasible": result.feasible, "before": result.before, "after": result.after,
            "seconds": seconds, "plots": plots, "result": result}


def summary_lines(numbers: dict) -> list[str]:
    """The printed summary of :func:`main`'s result: 4 significant digits with units
    (relative differences and margins in %, design values in SI, times in s)."""
    def relative(x):
        return format_value(100 * x, "%")

    designs = {key: ", ".join(f"{name} {format_value(v, UNITS[name])}"
                              for name, v in numbers[key].items()) for key in ("before", "after")}
    return [
        "max relative difference from the assembled frequencies: " + ", ".join(
            f"{m} {relative(d)}" for m, d in numbers["max_rel_difference"].items()),
        f"margin from the harmonic bands (required {relative(MARGIN)}): before"
        f" {relative(numbers['margin_before'])}, after {relative(numbers['margin_after'])},"
        f" after on 360 angles {relative(numbers['check_after'])}",
        f"feasible: {'yes' if numbers['feasible'] else 'no'}",
        f"before: {designs['before']}",
        f"after: {designs['after']}",
        "seconds: " + ", ".join(f"{step} {format_value(t, 's')}"
                                for step, t in numbers["seconds"].items()),
    ]


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/", help="output folder for the PNGs")
    print("\n".join(summary_lines(main(parser.parse_args().out))))
