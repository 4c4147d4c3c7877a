"""Tables of rows as CSV files, written atomically: one header line, then one line per
row; floats as ``repr`` (round-trip exact), other cells as they are.

Stage 7 (output): uses output.export (atomic writes), imported when writing: reading a
scene (the kinds import this module) loads no analysis module.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np


def write_csv(path, header, rows) -> Path:
    """Write ``header`` (column names) and ``rows`` (sequences of cells) to ``path``."""
    from femmech.output.export import atomic_path  # it imports the analysis results

    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    writer.writerows([[repr(float(v)) if isinstance(v, (float, np.floating)) else v
                       for v in row] for row in rows])
    with atomic_path(path) as tmp:
        tmp.write_text(buffer.getvalue(), encoding="utf-8")
    return Path(path)
