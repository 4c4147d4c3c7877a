"""Frequency tables of a mode set: plain text for reports and logs, CSV for spreadsheets.

Uses analysis.modes, analysis.discretisation and output (export,
formatting, report).
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

from femmech.analysis.discretisation import DiscretisationEstimate
from femmech.analysis.modes import ModeSet
from femmech.output.export import atomic_path
from femmech.output.formatting import Quantity
from femmech.output.report import Flagged

_HEADER = ("mode", "freq_hz", "rigid", "residual")


def frequency_table(modes: ModeSet) -> str:
    """Plain-text table: mode number (from 1), frequency in Hz, rigid flag, residual.

    Parameters
    ----------
    modes : ModeSet

    Returns
    -------
    str
        One header line, one line per mode, each ending with a newline.

    Examples
    --------
    >>> import numpy as np
    >>> from femmech import ModeSet
    >>> ms = ModeSet(np.array([0.0, 14.4683]), np.array([1e-9, 8264.0]), np.zeros((6, 2)),
    ...              np.array([True, False]), "dense", -1.0, np.array([1e-15, 3e-14]), 2)
    >>> print(frequency_table(ms), end="")
    mode     freq [Hz]  rigid  residual
       1        0.0000    yes   1.0e-15
       2       14.4683     no   3.0e-14
    """
    lines = [f"{'mode':>4}  {'freq [Hz]':>12}  {'rigid':>5}  {'residual':>8}"]
    for i in range(modes.n_modes):
        rigid = "yes" if modes.rigid[i] else "no"
        lines.append(f"{i + 1:>4}  {modes.freq_hz[i]:>12.4f}  {rigid:>5}"
                     f"  {modes.residual[i]:>8.1e}")
    return "\n".join(lines) + "\n"


def write_frequency_csv(modes: ModeSet, filename) -> Path:
    """Write the frequency table as CSV, atomically.

    Columns ``mode`` (from 1), ``freq_hz`` (Hz, full precision), ``rigid`` (0/1) and
    ``residual`` (relative residual of the eigenpair); modes of a superelement whose index
    the full model's Sturm count checked (:attr:`ModeSet.index_confirmed`) add
    ``index_confirmed`` (1: the full mode of the same number, 0: unconfirmed).

    Parameters
    ----------
    modes : ModeSet
    filename : str or os.PathLike
        Target file; its folder must exist.

    Returns
    -------
    Path
        ``filename``.
    """
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    confirmed = modes.index_confirmed
    writer.writerow(_HEADER + ("index_confirmed",) * (confirmed is not None))
    for i in range(modes.n_modes):
        writer.writerow([i + 1, repr(float(modes.freq_hz[i])), int(modes.rigid[i]),
                         repr(float(modes.residual[i]))]
                        + ([int(confirmed[i])] if confirmed is not None else []))
    with atomic_path(filename) as tmp:
        tmp.write_text(buffer.getvalue(), encoding="utf-8")
    return Path(filename)


def error_budget_columns(estimate: DiscretisationEstimate, reduction=None
                         ) -> tuple[tuple, list]:
    """Report columns of the error budget per mode: the discretisation estimate and,
    with a reduction estimate, their sum.

    Parameters
    ----------
    estimate : DiscretisationEstimate
        One entry per mode of the table (:func:`femmech.analysis.discretisation.
        discretisation_error_of`).
    reduction : array_like (n,), optional
        Estimated relative error of the reduction per mode (:attr:`ModeSet.error_estimate`).

    Returns
    -------
    header : tuple of str
    cells : list of tuple
        Per mode: a :class:`Quantity` for a trusted estimate, ``"–"`` for a rigid-body
        mode, a highlighted :class:`~femmech.output.report.Flagged` text otherwise (a lower
        bound or "?", with the reason), never a plain number that may be wrong.
    """
    header = ("discretisation error (h/2 estimate)",)
    if reduction is not None:
        header += ("total estimated error",)
    cells = []
    for k in range(len(estimate.freq_hz)):
        flag = estimate.flag[k]
        if flag == "rigid":
            row = ("–",) + (("–",) if reduction is not None else ())
        elif flag:
            row = (Flagged(estimate.describe(k)),) + (
                (Flagged("?"),) if reduction is not None else ())
        else:
            disc = abs(float(estimate.error[k]))
            row = (Quantity(disc, digits=2),) + (
                (Quantity(disc + abs(float(reduction[k])), digits=2),)
                if reduction is not None else ())
        cells.append(row)
    return header, cells
