"""Stage 3: checks of a superelement file's meta fields, shapes, checksums and values.

After the container (:mod:`femmech.reduction.superelement_archive`): the ``meta`` object,
the shapes of all members against each other, the SHA-256 sums, and the values:
finiteness, CSR structure and index ranges of T, the partition of the free DOFs, that
each interface DOF is a free DOF of T, symmetry and block structure of K and M, K
positive semidefinite and M positive definite. Each failure raises
:class:`~femmech.errors.FileFormatError` with one line naming the file and the field.
Used by :func:`femmech.reduction.superelement_file.read`.

Imports :mod:`femmech.fe` and its own package.
"""

from __future__ import annotations

import json
import math
import re

import numpy as np
import scipy.sparse as sp

from femmech.fe.dofs import DOF_PER_NODE, dof_label
from femmech.reduction.superelement_archive import CHUNK
from femmech.reduction.superelement_format import (
    ARRAYS,
    FLOATS,
    METHODS,
    READABLE_VERSIONS,
    _fail,
    _line,
    _show,
    meta_digest,
)

SYMMETRY_RTOL = 1e-12
"""Largest ``|A - Aᵀ|`` accepted for K and M, relative to ``max |A|``. The reduction
writes them exactly symmetric (``0.5 (A + Aᵀ)`` is exact in IEEE arithmetic because
addition commutes; the coupling blocks are stored as each other's transposes); 1e-12
also admits a writer that formed ``Tᵀ K T`` without symmetrising (asymmetry about
``n eps max|A|``, 1e-13 for n = 500)."""

PSD_RTOL = 1e-6
"""Most negative eigenvalue of K accepted, relative to its largest magnitude. Rigid-body
eigenvalues of a free-free superelement come out as round-off that grows with
cond(K_ii), not with n: measured -4e-16 on free-free grid frames, -7.8e-12 with a 1e6
stiffness contrast (cond(K_ii) = 3.7e9) and -1.2e-8 with 1e8 (3.7e11, which the
reduction still accepts); ``c n eps`` would reject the last two. 1e-6 leaves a factor
80 above the worst measured case; a sign error in real data is far larger."""

MAX_TIMINGS = 64
_HEX64 = re.compile(r"[0-9a-f]{64}")


# --- meta and shapes ------------------------------------------------------------------

def _meta(array: np.ndarray, file: str) -> dict:
    """The checked ``meta`` dict (``n_residual`` filled in for format 1)."""
    try:  # decoded here: numpy's str of a code point above U+10FFFF breaks json (SystemError)
        meta = json.loads(array.tobytes().decode("utf-32-le").rstrip("\0"))
    except (ValueError, RecursionError) as exc:
        raise _fail(file, "meta", f"not JSON text ({type(exc).__name__}: {exc})") from exc
    if not isinstance(meta, dict):
        raise _fail(file, "meta", f"a JSON {type(meta).__name__}, expected an object")
    version = meta.get("format_version")
    if type(version) is not int or version not in READABLE_VERSIONS:
        raise _fail(file, "meta.format_version", f"superelement format {_show(version)},"
                    f" this femmech reads {' and '.join(map(str, READABLE_VERSIONS))}")
    required = {"format_version", "method", "n_dof", "timings"}
    optional = {"n_residual"} if version == 1 else set()
    required |= set() if version == 1 else {"n_residual", "sha256"}
    missing, extra = required - meta.keys(), meta.keys() - required - optional
    if missing or extra:
        key = sorted(missing or extra)[0]
        raise _fail(file, f"meta.{_line(key, 40)}", "missing" if missing else "unexpected key")
    meta.setdefault("n_residual", 0)
    if meta["method"] not in METHODS or type(meta["method"]) is not str:
        raise _fail(file, "meta.method", f"{_show(meta['method'])}, expected one of"
                                         f" {', '.join(METHODS)}")
    for key, low in (("n_dof", 1), ("n_residual", 0)):
        if type(meta[key]) is not int or meta[key] < low:
            raise _fail(file, f"meta.{key}", f"{_show(meta[key])}, expected an int >= {low}")
    _check_timings(meta["timings"], file)
    if version >= 2:
        sums = meta["sha256"]
        names = set(ARRAYS) | {"meta"}
        if not isinstance(sums, dict) or sums.keys() != names or not all(
                isinstance(s, str) and _HEX64.fullmatch(s) for s in sums.values()):
            raise _fail(file, "meta.sha256", "expected 64 hex digits for each of "
                                             + ", ".join(sorted(names)))
    return meta


def _check_timings(timings, file: str):
    if not isinstance(timings, dict) or len(timings) > MAX_TIMINGS:
        raise _fail(file, "meta.timings", f"{_show(timings)}, expected an object of at most"
                                          f" {MAX_TIMINGS} durations in s")
    for key, value in timings.items():
        if type(value) is not float or not math.isfinite(value) or value < 0:
            raise _fail(file, f"meta.timings.{_line(key, 40)}",
                        f"{_show(value)}, expected a finite duration >= 0 s")


def _dims(heads: dict, meta: dict, T_shape: np.ndarray, file: str) -> dict:
    """Sizes n_dof, n_free, n_b, n_i, n_q, nnz; every member's shape checked against them."""
    if T_shape.shape != (2,):
        raise _fail(file, "T_shape", f"shape {T_shape.shape}, expected (2,)")
    n_dof, n_free = (int(n) for n in T_shape)
    if not 1 <= n_free <= n_dof or n_dof % DOF_PER_NODE:
        raise _fail(file, "T_shape", f"{(n_dof, n_free)}, expected (n_dof, n_free) with"
                    f" 1 <= n_free <= n_dof and n_dof a multiple of {DOF_PER_NODE}")
    if meta["n_dof"] != n_dof:
        raise _fail(file, "meta.n_dof", f"{meta['n_dof']}, but T has {n_dof} rows (T_shape)")
    d = {"n_dof": n_dof, "n_free": n_free, "n_b": heads["interface_dofs"].shape[0],
         "n_q": heads["modal_omega2"].shape[0], "n_i": heads["free_interior"].shape[0],
         "nnz": heads["T_data"].shape[0]}
    n_b, n_q, n_i = d["n_b"], d["n_q"], d["n_i"]
    if n_b < 1 or n_i < 1 or n_b + n_i != n_free:
        raise _fail(file, "T_shape", f"n_free = {n_free}, but interface_dofs has {n_b} and"
                    f" free_interior {n_i} entries (both >= 1, summing to n_free)")
    if n_q > n_i or (meta["method"] == "guyan" and n_q):
        raise _fail(file, "modal_omega2", f"{n_q} modal coordinates for {n_i} interior"
                    f" DOFs and method {meta['method']}")
    if meta["n_residual"] > min(n_q, n_b):
        raise _fail(file, "meta.n_residual", f"{meta['n_residual']} residual vectors, more"
                    f" than the {n_q} modal coordinates or the {n_b} interface DOFs")
    n_r = n_b + n_q
    expected = {"K": (n_r, n_r), "M": (n_r, n_r), "interface_points": (n_b, 3),
                "Psi": (n_i, n_b), "Phi": (n_i, n_q), "free_interface": (n_b,),
                "T_indices": (d["nnz"],), "T_indptr": (n_dof + 1,), "T_shape": (2,)}
    for field, shape in expected.items():
        if heads[field].shape != shape:
            raise _fail(file, field, f"shape {heads[field].shape}, expected {shape} (n_b ="
                        f" {n_b}, n_q = {n_q}, n_i = {n_i}, nnz = {d['nnz']},"
                        f" n_dof = {n_dof})")
    return d


def _verify_checksums(meta: dict, digests: dict, file: str):
    for field in ARRAYS:
        if digests[field] != meta["sha256"][field]:
            raise _fail(file, field, "SHA-256 checksum mismatch (the data changed after the"
                                     " file was written)")
    if meta_digest(meta) != meta["sha256"]["meta"]:
        raise _fail(file, "meta", "SHA-256 checksum mismatch (the meta fields changed"
                                  " after the file was written)")


# --- values ---------------------------------------------------------------------------

def _fields(arrays: dict, meta: dict, dims: dict, file: str) -> dict:
    """Checked values → keyword arguments of ``Superelement``."""
    for field in FLOATS:
        _check_finite(arrays[field], field, file)
    _check_csr(arrays, dims, file)
    for field in ("interface_dofs", "free_interface", "free_interior"):
        arrays[field] = arrays[field].astype(np.intp, copy=False)
    _check_dofs(arrays, dims, file)
    _check_matrices(arrays["K"], arrays["M"], arrays["modal_omega2"], dims["n_b"], file)
    T = sp.csr_matrix((arrays.pop("T_data"), arrays.pop("T_indices"), arrays.pop("T_indptr")),
                      shape=(dims["n_dof"], dims["n_free"]))
    del arrays["T_shape"]
    return dict(arrays, T=T, method=meta["method"], timings=meta["timings"],
                n_residual=meta["n_residual"])


def _check_finite(a: np.ndarray, field: str, file: str):
    flat = a.ravel(order="K")
    for start in range(0, flat.size, CHUNK // 8):
        bad = ~np.isfinite(flat[start:start + CHUNK // 8])
        if bad.any():
            position = start + int(np.argmax(bad))
            order = "F" if a.flags.f_contiguous and not a.flags.c_contiguous else "C"
            where = tuple(int(i) for i in np.unravel_index(position, a.shape, order=order))
            raise _fail(file, field, f"not finite at {where} ({flat[position]})")


def _first(mask: np.ndarray) -> int:
    return int(np.argmax(mask))


def _check_csr(arrays: dict, dims: dict, file: str):
    indptr, indices = arrays["T_indptr"], arrays["T_indices"]
    steps = np.diff(indptr)
    if indptr[0] != 0 or indptr[-1] != dims["nnz"] or (steps < 0).any():
        row = _first(steps < 0) if (steps < 0).any() else None
        raise _fail(file, "T_indptr", f"not a CSR row pointer: starts at {indptr[0]}, ends at"
                    f" {indptr[-1]} (nnz = {dims['nnz']})"
                    + (f", decreases after row {row}" if row is not None else ""))
    outside = (indices < 0) | (indices >= dims["n_free"])
    if outside.any():
        k = _first(outside)
        raise _fail(file, "T_indices", f"column {indices[k]} at position {k}, outside"
                                       f" [0, {dims['n_free']})")


def _check_increasing(a: np.ndarray, top: int, field: str, file: str):
    outside = (a < 0) | (a >= top)
    if outside.any():
        raise _fail(file, field, f"{a[_first(outside)]} outside [0, {top})")
    if a.size > 1 and not (np.diff(a) > 0).all():
        k = _first(np.diff(a) <= 0)
        raise _fail(file, field, f"not sorted and unique ({a[k]} then {a[k + 1]})")


def _check_dofs(arrays: dict, dims: dict, file: str):
    dofs, b, i = arrays["interface_dofs"], arrays["free_interface"], arrays["free_interior"]
    _check_increasing(dofs, dims["n_dof"], "interface_dofs", file)
    _check_increasing(b, dims["n_free"], "free_interface", file)
    _check_increasing(i, dims["n_free"], "free_interior", file)
    taken = np.zeros(dims["n_free"], dtype=bool)
    taken[b] = True
    if taken[i].any():  # disjoint with sizes summing to n_free: a partition
        raise _fail(file, "free_interior", f"free DOF {i[_first(taken[i])]} is also in"
                                           " free_interface")
    indptr, indices, data = arrays["T_indptr"], arrays["T_indices"], arrays["T_data"]
    start = indptr[dofs]
    unit = indptr[dofs + 1] - start == 1
    unit[unit] = (indices[start[unit]] == b[unit]) & (data[start[unit]] == 1.0)
    if not unit.all():
        k = _first(~unit)
        raise _fail(file, "interface_dofs", f"{dof_label(int(dofs[k]))} (DOF {dofs[k]}) is"
                    f" not free DOF {b[k]} (free_interface[{k}]): its row of T is not the"
                    " unit row of that column")
    points = arrays["interface_points"]
    node = dofs // DOF_PER_NODE
    same = (node[1:] == node[:-1]) & (points[1:] != points[:-1]).any(axis=1)
    if same.any():
        k = _first(same) + 1
        raise _fail(file, "interface_points", f"rows {k - 1} and {k} differ but belong to the"
                                              f" same node {node[k]}")


def _check_matrices(K: np.ndarray, M: np.ndarray, omega2: np.ndarray, n_b: int, file: str):
    """Symmetry of K and M, K = diag(K_g, diag(ω²)), K_g ⪰ 0, M ≻ 0 (Cholesky)."""
    for field, A in (("K", K), ("M", M)):
        scale, asym = np.abs(A).max(), np.abs(A - A.T).max()
        if asym > SYMMETRY_RTOL * scale:
            raise _fail(file, field, f"not symmetric (max |{field}-{field}^T| = {asym:.1e} of"
                                     f" max |{field}| {scale:.1e})")
    if K[:n_b, n_b:].any() or K[n_b:, :n_b].any():
        raise _fail(file, "K", "interface-modal coupling block is not zero")
    if not np.array_equal(K[n_b:, n_b:], np.diag(omega2)):
        raise _fail(file, "K", "modal block is not diag(modal_omega2)")
    w = np.linalg.eigvalsh(K[:n_b, :n_b])
    top = max(np.abs(w).max(), np.abs(omega2).max(initial=0.0))
    low = min(w.min(), omega2.min(initial=np.inf))
    if low < -PSD_RTOL * top:
        raise _fail(file, "K", f"not positive semidefinite (eigenvalue {low:.3e}, largest"
                               f" {top:.3e}; round-off allows -{PSD_RTOL:g} of it)")
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        raise _fail(file, "M", "not positive definite (smallest eigenvalue"
                               f" {np.linalg.eigvalsh(M).min():.3e})") from None
