"""Stage 3, superelement files: the ``.npz`` format, its atomic writer and its validating reader.

A superelement file (:meth:`femmech.reduction.superelement.Superelement.save`) is a zip
archive of ``.npy`` members, as ``numpy.savez_compressed`` writes it (n_b interface DOFs, n_i
interior DOFs, n_q modal coordinates, n_r = n_b + n_q, n_free = n_b + n_i)::

    K, M               float64    (n_r, n_r)   reduced stiffness and mass
    interface_dofs     int        (n_b,)       full-model DOFs, sorted, unique
    interface_points   float64    (n_b, 3)     node coordinates, m
    modal_omega2       float64    (n_q,)       rad²/s², the diagonal of K's modal block
    Psi, Phi           float64    (n_i, n_b), (n_i, n_q)
    free_interface     int        (n_b,)       positions among the free DOFs, sorted
    free_interior      int        (n_i,)       the other positions, sorted
    T_data             float64    (nnz,)       CSR parts of T (n_dof, n_free)
    T_indices          int        (nnz,)
    T_indptr           int        (n_dof + 1,)
    T_shape            int        (2,)         (n_dof, n_free)
    meta               unicode    ()           JSON object

``int`` is little-endian int32 or int64. ``meta`` holds ``format_version``, ``method``
(``"guyan"`` or ``"craig-bampton"``), ``n_dof``, ``n_residual``, ``timings`` (s) and,
from format 2 on, ``sha256``: per member the SHA-256 of its name, dtype, shape and data
bytes (:func:`~femmech.reduction.superelement_format.field_digest`), and under
``"meta"`` that of the other meta fields
(:func:`~femmech.reduction.superelement_format.meta_digest`), so that any change of the
data after writing is caught and named.

Files are untrusted (docs/robustness.md): :func:`read` never unpickles (object dtypes are
refused before any data is read) and validates before use, in this order: the member list
and each member's zip entry (compression, encryption, sizes the compressed bytes can
produce); each ``.npy`` header (version, dtype, number of dimensions, and that the
declared shape times the item size fills the member exactly, so that no lying shape or
decompression bomb makes it allocate more than the data holds); ``meta``; the shapes of
all members against each other; the data (zip CRC-32, then the SHA-256 sums); then the
values: finiteness, CSR structure and index ranges, the partition of the free DOFs,
that each interface DOF is a free DOF of T, symmetry and block structure of K and M, K
positive semidefinite and M positive definite. Each failure raises
:class:`~femmech.errors.FileFormatError` with one line naming the file and the field.
Format-1 files (no checksums) are read if they pass all the other checks.

This module writes and reads; the fields and checksums are in
:mod:`femmech.reduction.superelement_format`, the checks of zip members and ``.npy``
headers in :mod:`femmech.reduction.superelement_archive`, those of meta, shapes and
values in :mod:`femmech.reduction.superelement_checks`.

Imports its own package only (those modules import :mod:`femmech.errors` and
:mod:`femmech.fe`).
"""

from __future__ import annotations

import json
import os
import tempfile
import zipfile
from pathlib import Path

import numpy as np

from femmech.reduction.superelement_archive import (
    _data,
    _header,
    _members,
    _reading,
    open_regular,
)
from femmech.reduction.superelement_checks import _dims, _fields, _meta, _verify_checksums
from femmech.reduction.superelement_format import (
    ARRAYS,
    FIELDS,
    FLOATS,
    FORMAT_VERSION,
    _name,
    checksums,
)

# --- writing --------------------------------------------------------------------------

def write(se, path) -> Path:
    """Write superelement ``se`` to ``path`` (``.npz``, format :data:`FORMAT_VERSION`).

    Atomic: a temporary file in the target folder is renamed over ``path``; on any
    failure the temporary file is removed and an existing ``path`` is left unchanged.
    """
    if getattr(se, "interface_basis", None) is not None:
        raise ValueError("Superelement.save: a superelement with a reduced interface"
                         " (interface_basis, method 'craig-bampton-cc') cannot be written in"
                         f" format {FORMAT_VERSION}; save the plain Craig-Bampton one or"
                         " reduce again")
    path = Path(path)
    T = se.T.tocsr()
    arrays = {name: np.ascontiguousarray(getattr(se, name), dtype=np.float64)
              for name in FLOATS if name != "T_data"}
    arrays.update({name: np.ascontiguousarray(getattr(se, name), dtype=np.int64)
                   for name in ("interface_dofs", "free_interface", "free_interior")})
    arrays.update(T_data=np.ascontiguousarray(T.data, dtype=np.float64),
                  T_indices=np.ascontiguousarray(T.indices),
                  T_indptr=np.ascontiguousarray(T.indptr), T_shape=np.array(T.shape))
    meta = {"format_version": FORMAT_VERSION, "method": se.method, "n_dof": int(T.shape[0]),
            "n_residual": int(se.n_residual), "timings": dict(se.timings)}
    meta["sha256"] = checksums(arrays, meta)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".npz")
    try:
        with os.fdopen(fd, "wb") as stream:
            np.savez_compressed(stream, meta=np.array(json.dumps(meta)), **arrays)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


# --- reading --------------------------------------------------------------------------

def read(path) -> dict:
    """Validated fields of the superelement file ``path`` (keyword arguments of
    :class:`~femmech.reduction.superelement.Superelement`).

    Raises
    ------
    FileNotFoundError
        If there is no file ``path``.
    FileFormatError
        One line naming the file and the field, if the file is not a valid superelement
        file (truncated, damaged, foreign, crafted, or of another format version), or
        naming the file if it is no regular file (a FIFO, a device such as a link to
        ``/dev/zero``, a directory: refused before it is opened for reading). A symbolic
        link to a regular file is read: the user named it (cache entries, which femmech
        names itself, refuse links: :func:`femmech.scene.cache.read_entry`).
    """
    file = _name(path)
    with open_regular(path) as stream:
        size = os.fstat(stream.fileno()).st_size
        with _reading(file, "zip archive"):
            archive = zipfile.ZipFile(stream)
        with archive:
            infos = _members(archive, size, file)
            heads = {field: _header(archive, infos[field], field, file) for field in FIELDS}
            arrays, digests = {}, {}
            for field in ("meta", "T_shape"):
                arrays[field], digests[field] = _data(archive, heads[field], field, file)
            meta = _meta(arrays.pop("meta"), file)
            dims = _dims(heads, meta, arrays["T_shape"], file)
            for field in ARRAYS[:-1]:
                arrays[field], digests[field] = _data(archive, heads[field], field, file)
    if meta["format_version"] >= 2:
        _verify_checksums(meta, digests, file)
    return _fields(arrays, meta, dims, file)


def __getattr__(name: str):
    """Names this module had before the restructures, from their new places
    (docs/architecture.md, "Moved names")."""
    from femmech.deprecation import moved

    return moved(__name__, name, {
        "CHUNK": "femmech.reduction.superelement_archive.CHUNK",
        "DEFLATE_MAX_RATIO": "femmech.reduction.superelement_archive.DEFLATE_MAX_RATIO",
        "EXPANSION_FLOOR": "femmech.reduction.superelement_archive.EXPANSION_FLOOR",
        "INDICES": "femmech.reduction.superelement_format.INDICES",
        "MAX_EXPANSION": "femmech.reduction.superelement_archive.MAX_EXPANSION",
        "MAX_HEADER": "femmech.reduction.superelement_archive.MAX_HEADER",
        "MAX_META_CHARS": "femmech.reduction.superelement_archive.MAX_META_CHARS",
        "MAX_TIMINGS": "femmech.reduction.superelement_checks.MAX_TIMINGS",
        "METHODS": "femmech.reduction.superelement_format.METHODS",
        "PSD_RTOL": "femmech.reduction.superelement_checks.PSD_RTOL",
        "READABLE_VERSIONS": "femmech.reduction.superelement_format.READABLE_VERSIONS",
        "SYMMETRY_RTOL": "femmech.reduction.superelement_checks.SYMMETRY_RTOL",
        "field_digest": "femmech.reduction.superelement_format.field_digest",
        "meta_digest": "femmech.reduction.superelement_format.meta_digest",
    })
