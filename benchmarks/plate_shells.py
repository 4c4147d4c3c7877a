"""Benchmark: accuracy per degree of freedom of the shell elements on a thin plate.

The simply supported square steel plate (a = 1 m, a/t = 1000 by default; hard simple
support: w and the rotation about the edge normal fixed, in-plane DOFs fixed since they
do not couple with bending in a flat plate), meshed n x n with each element kind of
:data:`ELEMENTS` by :func:`femmech.fe.generators.rectangular_plate`. For every mesh the
benchmark prints the DOF count, the largest relative error of the first ten
frequencies, the error of the first, and the time of ``build_model`` + ``modes``; then,
per element kind, the DOFs needed for the target error (0.1 %): the smallest mesh of
the table that reaches it, and the count on the log-log line through the two meshes
that bracket it (or through the two finest, extrapolated, if none reaches it).

Reference: the exact Mindlin-plate frequencies of modes (m, n) (Mindlin, J. Appl. Mech.
18 (1951) 31-38; the 3 x 3 eigenproblem of ``tests/test_shell_verification.py``), which
at a/t = 1000 equal the Kirchhoff closed form ``ω_mn = π² (m²/a² + n²/b²) sqrt(D/ρt)``
(Leissa, Vibration of Plates, NASA SP-160 (1969)) within 3.1e-5, and which the elements
converge to (they are Mindlin elements).

To add an element kind (e.g. MITC6 triangles), append an :class:`ElementKind` to
:data:`ELEMENTS`: a label, the cell kind, the mesh sizes and, if the kind is not one of
``rectangular_plate``'s, a mesh function ``n -> Mesh`` with the plate's cell set
``"plate"``.

Usage::

    python benchmarks/plate_shells.py [--sizes full|tiny] [--slenderness 1000]

Results are printed and written to ``benchmarks/results/plate_shells.txt``.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.linalg as sl

import femmech as fm
from femmech.fe.generators import rectangular_plate

HERE = Path(__file__).resolve().parent
STEEL = fm.Material(E=200e9, nu=0.3, rho=8000.0)
SIDE = 1.0  # m
N_FREQ = 10
TARGET = 1e-3


@dataclass(frozen=True)
class ElementKind:
    """One row group of the table: an element, its cell kind and mesh sizes.

    Attributes
    ----------
    label : str
        Name in the table, e.g. ``"MITC9"``.
    cell : str
        meshio cell kind of the mesh.
    sizes : dict[str, tuple[int, ...]]
        Elements per side n, by benchmark size (``"full"``, ``"tiny"``).
    mesh : callable or None
        ``n -> Mesh`` of the unit square plate with cell set ``"plate"``; None:
        ``rectangular_plate(1, 1, n, n, cell)``.
    """

    label: str
    cell: str
    sizes: dict
    mesh: Callable | None = None

    def make_mesh(self, n: int):
        if self.mesh is not None:
            return self.mesh(n)
        return rectangular_plate(SIDE, SIDE, n, n, kind=self.cell)


ELEMENTS = [
    ElementKind("MITC4", "quad", {"full": (8, 16, 32, 64, 128), "tiny": (6, 8)}),
    ElementKind("MITC9", "quad9", {"full": (4, 8, 16, 32), "tiny": (3, 4)}),
    ElementKind("MITC3", "triangle", {"full": (8, 16, 32, 64, 128), "tiny": (4, 8)}),
    ElementKind("MITC6", "triangle6", {"full": (4, 8, 16, 32), "tiny": (2, 4)}),
]
"""Element kinds of the table, in order (extend here)."""


def mindlin_frequency_parameters(t: float, count: int = N_FREQ, material=STEEL) -> np.ndarray:
    """Lowest ``count`` exact frequency parameters ``λ = ω a² sqrt(ρt/D)`` of the plate.

    Mindlin (1951): for ``w = W sin αx sin βy`` and the matching rotations, the plate
    equations reduce to a 3 x 3 eigenproblem per mode (m, n); its lowest root is the
    flexural frequency (shear factor 5/6, rotary inertia included).
    """
    E, nu, rho = material.E, material.poisson_ratio, material.rho
    D = E * t**3 / (12 * (1 - nu**2))
    s = 5.0 / 6.0 * E / (2 * (1 + nu)) * t  # k G t
    lam = []
    for m in range(1, 8):
        for n in range(1, 8):
            al, be = m * np.pi / SIDE, n * np.pi / SIDE
            k2 = al**2 + be**2
            K = np.array([[s * k2, s * al, s * be],
                          [s * al, D / 2 * ((1 - nu) * k2 + (1 + nu) * al**2) + s,
                           D / 2 * (1 + nu) * al * be],
                          [s * be, D / 2 * (1 + nu) * al * be,
                           D / 2 * ((1 - nu) * k2 + (1 + nu) * be**2) + s]])
            M = np.diag([rho * t, rho * t**3 / 12, rho * t**3 / 12])
            w2 = sl.eigh(K, M, eigvals_only=True)[0]
            lam.append(np.sqrt(w2) * SIDE**2 * np.sqrt(rho * t / D))
    return np.sort(lam)[:count]


def simply_supported(mesh, t: float, material=STEEL):
    """FE model of the hard simply supported plate on ``mesh`` (cell set ``"plate"``)."""
    x, y = mesh.points[:, 0], mesh.points[:, 1]
    edge_x = np.flatnonzero(np.isclose(x, 0) | np.isclose(x, SIDE))
    edge_y = np.flatnonzero(np.isclose(y, 0) | np.isclose(y, SIDE))
    supports = [fm.Support(np.arange(mesh.n_nodes), ["ux", "uy", "rz"]),
                fm.Support(edge_x, ["uz", "rx"]), fm.Support(edge_y, ["uz", "ry"])]
    return fm.build_model(mesh, shells={"plate": fm.ShellProperty(t, material)},
                          supports=supports)


def frequency_parameters(model, t: float, count: int = N_FREQ, material=STEEL):
    """Lowest ``count`` frequency parameters ``λ = ω a² sqrt(ρt/D)`` of ``model``."""
    res = fm.modes(model, n_modes=count)
    D = material.E * t**3 / (12 * (1 - material.poisson_ratio**2))
    return (2 * np.pi * res.freq_hz * SIDE**2 * np.sqrt(material.rho * t / D))[:count]


def plate_row(kind: ElementKind, n: int, t: float, reference: np.ndarray) -> dict:
    """One table row: DOFs, errors of the first ten frequencies and the time."""
    mesh = kind.make_mesh(n)
    start = time.perf_counter()
    model = simply_supported(mesh, t)
    lam = frequency_parameters(model, t)
    seconds = time.perf_counter() - start
    err = lam / reference - 1
    return {"element": kind.label, "n": n, "dofs": 6 * model.mesh.n_nodes,
            "free_dofs": int(len(model.free)), "max_err": float(np.abs(err).max()),
            "err1": float(err[0]), "errors": err.tolist(), "seconds": seconds}


def dofs_for(rows: list[dict], target: float = TARGET):
    """DOFs for ``target``: (smallest tabulated mesh reaching it or None, estimate, how).

    The estimate lies on the log-log line of error against DOFs through the two meshes
    that bracket ``target`` (``how = "interpolated"``), or through the two finest ones
    when none reaches it (``"extrapolated"``); None for fewer than two rows.
    """
    reached = [r["dofs"] for r in rows if r["max_err"] <= target]
    smallest = min(reached) if reached else None
    pairs = [(lo, hi) for lo, hi in zip(rows[:-1], rows[1:], strict=True)
             if lo["max_err"] > target >= hi["max_err"]]
    how = "interpolated"
    if not pairs:
        if smallest is not None or len(rows) < 2:
            return smallest, None, "-"
        pairs, how = [(rows[-2], rows[-1])], "extrapolated"
    lo, hi = pairs[0]
    slope = np.log(hi["max_err"] / lo["max_err"]) / np.log(hi["dofs"] / lo["dofs"])
    return smallest, float(lo["dofs"] * (target / lo["max_err"]) ** (1 / slope)), how


def convergence_rate(rows: list[dict]) -> float:
    """Log-log slope of the largest error against the element size h = a/n."""
    h = np.array([SIDE / r["n"] for r in rows])
    err = np.array([r["max_err"] for r in rows])
    return float(np.polyfit(np.log(h), np.log(err), 1)[0])


def format_table(rows: list[dict], t: float) -> list[str]:
    lines = [f"Simply supported square plate, a = {SIDE:g} m, a/t = {SIDE / t:g},"
             f" first {N_FREQ} frequencies vs the exact Mindlin values",
             f"{'element':>8} {'n':>4} {'DOFs':>8} {'free':>8} {'max |err|':>10}"
             f" {'err f1':>10} {'time/s':>8}"]
    for r in rows:
        lines.append(f"{r['element']:>8} {r['n']:>4} {r['dofs']:>8} {r['free_dofs']:>8}"
                     f" {100 * r['max_err']:>9.4f}% {100 * r['err1']:>9.4f}%"
                     f" {r['seconds']:>8.2f}")
    lines += ["", f"DOFs for max |err| <= {100 * TARGET:g} % (first {N_FREQ} frequencies):",
              f"{'element':>8} {'table':>8} {'log-log':>9} {'':>12} {'rate h^p':>9}"]
    for label in dict.fromkeys(r["element"] for r in rows):
        mine = [r for r in rows if r["element"] == label]
        smallest, estimate, how = dofs_for(mine)
        rate = convergence_rate(mine[-3:]) if len(mine) > 1 else float("nan")
        lines.append(f"{label:>8} {smallest if smallest else '-':>8}"
                     f" {f'{estimate:.0f}' if estimate else '-':>9} {how:>12} {rate:>9.2f}")
    lines += ["", "rate: log-log slope of max |err| against h = a/n over the three finest"
              " meshes (frequencies: O(h²) for MITC4, MITC3, O(h⁴) for MITC9, MITC6 expected)"]
    return lines


def main(sizes: str = "full", slenderness: float = 1000.0,
         out_file=HERE / "results" / "plate_shells.txt", echo: bool = True) -> list[dict]:
    """Run the benchmark; return one dict per mesh (keys as in the printed table)."""
    t = SIDE / slenderness
    reference = mindlin_frequency_parameters(t)
    rows = []
    for kind in ELEMENTS:
        if sizes not in kind.sizes:
            raise ValueError(f"unknown sizes {sizes!r}; {kind.label} has {list(kind.sizes)}")
        for n in kind.sizes[sizes]:
            rows.append(plate_row(kind, n, t, reference))
            if echo:
                print(f"... {kind.label} n = {n} done", file=sys.stderr, flush=True)
    text = "\n".join(format_table(rows, t))
    if echo:
        print(text)
    if out_file is not None:
        Path(out_file).parent.mkdir(parents=True, exist_ok=True)
        Path(out_file).write_text(text + "\n")
    return rows


def _cli(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="full", help="full or tiny")
    parser.add_argument("--slenderness", type=float, default=1000.0, help="a/t")
    parser.add_argument("--out", default=str(HERE / "results" / "plate_shells.txt"))
    args = parser.parse_args(argv)
    main(args.sizes, args.slenderness, args.out)


if __name__ == "__main__":
    _cli()
