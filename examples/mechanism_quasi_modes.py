"""Quasi-eigenfrequencies of the cam-driven processing machine over one revolution.

Physics
-------
An elastic drive shaft (inertias J1, J2 in kg·m², torsional stiffnesses cT1, cT2 in
N·m/rad) carries two cam mechanisms U1(φ1), U2(φ2) (lifts in m) that move the follower
masses m1, m2 (kg) through follower elasticities c3, c4 (N/m) against return springs c6,
c7 (N/m). The input angle q1 = φ is prescribed (kinematic drive, 4 DOF q2…q5). At each
frozen drive angle the undamped eigenproblem C(φ, Ω) v = ω² M(φ) v is solved:

* M(φ) is eq. 20 of the chapter's section 5.2.3.2;
* C(φ, 0) is the potential stiffness, eq. 21 (errata 29);
* C(φ, Ω) adds the kinematic terms Ω² K_Ω(φ) of errata item 30 (unsymmetric).

The cams are a modified-sine rise/return (U1) and a 3-4-5 rise/return (U2, shifted by
40°), with a common dwell over 290°–360°. In a dwell U' = U'' = U''' = 0, the mechanisms
decouple and the frequencies have closed forms: the followers √((c3 + c6)/m1)/(2π), and
the two-inertia shaft with M = [[J1 + J2, J2], [J2, J2]], C = diag(cT1, cT2). ``main``
returns these with the computed values so a test can compare them.

Sources: textbook chapter 5, "Schwingungsmodelle mit mehreren Freiheitsgraden", section
5.2.3.2, eqs. 20–21, errata items 29–30; cam laws from Norton,
*Cam Design and Manufacturing Handbook* (2009), ch. 3. Parameter values are illustrative
(``processing_machine_parameters``); the drive speed is 1200 rpm.
"""

import argparse
from pathlib import Path

import numpy as np

from femmech.mechanisms import (
    processing_machine,
    processing_machine_cams,
    processing_machine_parameters,
    rheolinear,
)
from femmech.mechanisms.quasi_modes import quasi_modes
from femmech.output.sweeps import plot_quasi_frequencies

RPM = 1200.0


def dwell_reference(p: dict[str, float]) -> np.ndarray:
    """Closed-form frequencies (Hz, ascending) in the common dwell (see module docstring)."""
    M = np.array([[p["J1"] + p["J2"], p["J2"]], [p["J2"], p["J2"]]])
    lam_shaft = np.linalg.eigvals(np.linalg.solve(M, np.diag([p["cT1"], p["cT2"]]))).real
    lam = np.concatenate([lam_shaft, [(p["c3"] + p["c6"]) / p["m1"],
                                      (p["c4"] + p["c7"]) / p["m2"]]])
    return np.sort(np.sqrt(lam)) / (2 * np.pi)


def main(out_dir="out") -> dict:
    """Sweep 0…360°, write ``quasi_frequencies.png`` into ``out_dir``, return key numbers.

    Returns
    -------
    dict
        ``freq_min_hz``, ``freq_max_hz`` (n,) over the revolution, static C; ``dwell_hz``
        (n,) computed at 320° and ``dwell_reference_hz`` (n,) from the closed form;
        ``at_speed_max_shift`` the largest relative change of a frequency caused by the
        kinematic terms at 1200 rpm; ``plot`` the PNG path.
    """
    Path(out_dir).mkdir(parents=True, exist_ok=True)
    p = processing_machine_parameters(kinematic_drive=True)
    model = rheolinear(processing_machine(kinematic_drive=True), p, processing_machine_cams())
    phi = np.deg2rad(np.linspace(0.0, 360.0, 721))
    Omega = RPM * 2 * np.pi / 60
    static = quasi_modes(model, phi)
    at_speed = quasi_modes(model, phi, Omega=Omega)
    dwell = quasi_modes(model, [np.deg2rad(320.0)])
    plot = plot_quasi_frequencies(
        {"static C": static, f"C at {RPM:.0f} rpm": at_speed},
        Path(out_dir) / "quasi_frequencies.png",
        title="Cam-driven processing machine, drive at prescribed speed: quasi-eigenfrequencies",
        speed=Omega)  # its harmonics k·n (k <= 6) in the plotted range: 4·n, 5·n, 6·n
    shift = np.nanmax(np.abs(at_speed.freq_hz - static.freq_hz) / static.freq_hz)
    return {"freq_min_hz": static.freq_hz.min(axis=0), "freq_max_hz": static.freq_hz.max(axis=0),
            "dwell_hz": dwell.freq_hz[0], "dwell_reference_hz": dwell_reference(p),
            "at_speed_max_shift": float(shift), "plot": plot}


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/", help="output folder for the PNG")
    result = main(parser.parse_args().out)
    for key, value in result.items():
        print(f"{key}: {value}")
