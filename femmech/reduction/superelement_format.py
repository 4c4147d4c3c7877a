"""Stage 3: the fields of the superelement file format, their checksums, its error messages.

The names, kinds (float or index) and numbers of dimensions of the members of a
superelement file (:mod:`femmech.reduction.superelement_file` describes the format), the
SHA-256 sums that :func:`~femmech.reduction.superelement_file.write` stores in ``meta``
and the reader compares, and the one-line :class:`~femmech.errors.FileFormatError`
messages naming the file and the field, shared by the reader's modules.

Imports :mod:`femmech.errors`.
"""

from __future__ import annotations

import hashlib
import json

import numpy as np

from femmech.errors import FileFormatError

FORMAT_VERSION = 2
"""Format written by :func:`~femmech.reduction.superelement_file.write`;
:func:`~femmech.reduction.superelement_file.read` also reads format 1 (no checksums)."""

READABLE_VERSIONS = (1, 2)
METHODS = ("guyan", "craig-bampton")
FLOATS = ("K", "M", "interface_points", "modal_omega2", "Psi", "Phi", "T_data")
INDICES = ("interface_dofs", "free_interface", "free_interior", "T_indices", "T_indptr",
           "T_shape")
ARRAYS = FLOATS + INDICES
FIELDS = ARRAYS + ("meta",)
_NDIM = {"K": 2, "M": 2, "interface_points": 2, "modal_omega2": 1, "Psi": 2, "Phi": 2,
         "T_data": 1, "interface_dofs": 1, "free_interface": 1, "free_interior": 1,
         "T_indices": 1, "T_indptr": 1, "T_shape": 1, "meta": 0}


# --- messages -------------------------------------------------------------------------

def _name(path) -> str:
    name = str(path)
    return name if name.isprintable() else repr(name)


def _line(text: str, limit: int = 300) -> str:
    text = " ".join(str(text).splitlines())
    return text if len(text) <= limit else text[:limit] + "..."


def _show(value) -> str:
    return _line(repr(value), 40)


def _fail(file: str, field: str, problem: str) -> FileFormatError:
    return FileFormatError(f"{file}: field '{field}': {_line(problem)}")


def _unreadable(file: str, problem: str) -> FileFormatError:
    return FileFormatError(f"{file}: not a readable superelement file: {_line(problem)}")


# --- checksums ------------------------------------------------------------------------

def _digest_start(name: str, dtype: np.dtype, fortran: bool, shape: tuple):
    shape_text = ",".join(str(n) for n in shape)
    return hashlib.sha256(f"{name}\n{dtype.str}\n{int(fortran)}\n{shape_text}\n".encode())


def field_digest(name: str, dtype: np.dtype, fortran: bool, shape: tuple, data) -> str:
    """SHA-256 (hex) of a member: its name, dtype, order flag, shape and data bytes."""
    digest = _digest_start(name, np.dtype(dtype), fortran, tuple(shape))
    digest.update(data)
    return digest.hexdigest()


def meta_digest(meta: dict) -> str:
    """SHA-256 (hex) of the meta fields other than ``sha256`` (canonical JSON)."""
    rest = {key: value for key, value in meta.items() if key != "sha256"}
    return hashlib.sha256(json.dumps(rest, sort_keys=True).encode()).hexdigest()


def checksums(arrays: dict, meta: dict) -> dict:
    """``meta["sha256"]`` of C-contiguous ``arrays`` (name → ndarray) and ``meta``."""
    sums = {name: field_digest(name, a.dtype, False, a.shape, a.reshape(-1).view(np.uint8))
            for name, a in arrays.items()}
    sums["meta"] = meta_digest(meta)
    return sums
