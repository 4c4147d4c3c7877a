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
bytes (:func:`field_digest`), and under ``"meta"`` that of the other meta fields
(:func:`meta_digest`), so that any change of the data after writing is caught and named.

Files are untrusted (docs/robustness.md): :func:`read` never unpickles (object dtypes are
refused before any data is read) and validates before use, in this order: that the path
is a regular file (:func:`open_regular`: a FIFO would block the reader, a device such as
``/dev/zero`` would feed it without end) not much larger than its members; the member
list and each member's zip entry (compression, encryption, sizes the compressed bytes can
produce); each ``.npy`` header (version, dtype, number of dimensions, and that the
declared shape times the item size fills the member exactly, so that no lying shape or
decompression bomb makes it allocate more than the data holds); ``meta``; the shapes of
all members against each other; the data (read in bounded chunks while hashed; zip
CRC-32, then the SHA-256 sums); then the values: finiteness, CSR structure and index
ranges, the partition of the free DOFs, that each interface DOF is a free DOF of T,
symmetry and block structure of K and M, K positive semidefinite and M positive
definite. Each failure, and whatever a damaged archive makes zipfile, zlib or numpy
raise, becomes :class:`~femmech.errors.FileFormatError` with one line naming the file and
the field. Format-1 files (no checksums) are read if they pass all the other checks.

:func:`open_regular` and :func:`read_regular` are the guards against hostile paths that
the result cache and the output folder use for their own files too.

Imports :mod:`femmech.errors` and :mod:`femmech.fe`.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import math
import os
import re
import stat
import struct
import tempfile
import tokenize
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from femmech.errors import FileFormatError
from femmech.fe.dofs import DOF_PER_NODE, dof_label

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

# --- the container: regular files, zip members, npy headers ---------------------------

DEFLATE_MAX_RATIO = 1032
"""Deflate cannot expand data more than 1032-fold (258-byte matches coded in 2 bits)."""

MAX_EXPANSION = 64
"""Most bytes the members may declare per byte of file, beyond :data:`EXPANSION_FLOOR`:
a consistent "bomb" (a huge T of empty rows compresses 1000-fold) is refused before it is
read. Real files expand 1.1-1.8-fold (measured on frames and shells of 1 128-9 456 DOFs,
Guyan and Craig-Bampton): Psi and Phi, dense floats, dominate and hardly compress."""

EXPANSION_FLOOR = 1 << 24

ZIP_OVERHEAD = 1024
"""Most bytes of zip headers per member (local and central header with the member's name
twice, zip64 extras, data descriptor) that :func:`_members` allows beyond the members'
compressed data."""

ZIP_TAIL = 65_557 + 76 + (1 << 20)
"""Bytes allowed beyond the members and their headers: the end-of-central-directory record
with the longest comment, the zip64 end records, and 1 MiB of slack. A larger file holds
data that is no member (a file padded or appended to) and is refused before it is read."""

_KINDS = ((stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISDIR, "a directory"),
          (stat.S_ISSOCK, "a socket"))


def open_regular(path, what: str = "superelement file", follow_links: bool = True,
                 max_bytes: int | None = None):
    """Open ``path`` for binary reading if it is a regular file.

    The kind is checked before the file is opened (``os.stat``, or ``os.lstat`` if not
    ``follow_links``) and again on the open descriptor (``os.fstat``, against a swap in
    between); the open does not block (``O_NONBLOCK``: a FIFO without a writer would wait
    forever, a read of ``/dev/zero`` never ends) and, if not ``follow_links``, does not
    follow a symbolic link (``O_NOFOLLOW`` where the system has it).

    Parameters
    ----------
    path : path
    what : str
        What the file should be, for the messages (``"cache manifest"``).
    follow_links : bool
        False: a symbolic link in the place of the file is refused (femmech's own files:
        cache entries, output-folder manifests); True: a link to a regular file is read
        (files the user names).
    max_bytes : int, optional
        Largest size accepted, bytes (from ``fstat`` of the open file, before any read);
        callers read at most this much.

    Raises
    ------
    FileNotFoundError
        If there is no file ``path``.
    FileFormatError
        One line ``<path>: not a readable <what>: ...`` naming what it is instead (FIFO,
        device, directory, socket, symbolic link; a followed link's target), that it is
        larger than ``max_bytes``, or why it cannot be opened.
    """
    file = _name(path)
    flags = (os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
             | getattr(os, "O_BINARY", 0))
    if not follow_links:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    try:
        _require_regular((os.stat if follow_links else os.lstat)(path), path, file, what)
        fd = os.open(path, flags)
    except (FileNotFoundError, FileFormatError):
        raise
    except OSError as exc:
        if not follow_links and os.path.islink(path):  # ELOOP: swapped for a link meanwhile
            raise _no_regular(path, file, what, "a symbolic link") from None
        raise FileFormatError(f"{file}: cannot open the {what}: {type(exc).__name__}:"
                              f" {exc.strerror or exc}") from exc
    try:
        info = os.fstat(fd)
        _require_regular(info, path, file, what)
        if max_bytes is not None and info.st_size > max_bytes:
            raise FileFormatError(f"{file}: not a readable {what}: it has {info.st_size}"
                                  f" bytes, more than {_a(what)} may have ({max_bytes})")
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_regular(path, what: str, max_bytes: int, follow_links: bool = False) -> bytes:
    """The bytes of the regular file ``path`` of at most ``max_bytes`` bytes
    (:func:`open_regular`; a file that grows while read is refused too)."""
    with open_regular(path, what, follow_links, max_bytes) as stream:
        data = stream.read(max_bytes + 1)
    if len(data) > max_bytes:
        raise FileFormatError(f"{_name(path)}: not a readable {what}: it grew to more"
                              f" than {_a(what)} may have ({max_bytes} bytes) while read")
    return data


def _require_regular(info: os.stat_result, path, file: str, what: str) -> None:
    if stat.S_ISREG(info.st_mode):
        return
    if stat.S_ISLNK(info.st_mode):  # only from lstat: a link that is not followed
        raise _no_regular(path, file, what, "a symbolic link")
    kind = next((text for test, text in _KINDS if test(info.st_mode)), "not a regular file")
    link = ""
    if os.path.islink(path):
        link = f" (a symbolic link to {_name(os.path.realpath(path))})"
    raise _no_regular(path, file, what, kind + link)


def _no_regular(path, file: str, what: str, kind: str) -> FileFormatError:
    if kind == "a symbolic link":
        try:
            kind += f" to {_name(os.readlink(path))}"
        except OSError:
            pass
        return FileFormatError(f"{file}: not a readable {what}: it is {kind}, not a regular"
                               f" file; femmech does not follow links in the place of"
                               f" {_a(what)}")
    return FileFormatError(f"{file}: not a readable {what}: it is {kind}, not a"
                           f" regular file; {_a(what)} must be a regular file")


def _a(what: str) -> str:
    return ("an " if what[:1] in "aeiou" else "a ") + what


MAX_HEADER = 10_000
"""Longest ``.npy`` header read, bytes (numpy's own limit for untrusted files)."""

MAX_META_CHARS = 1 << 16
CHUNK = 1 << 24
_READ_ERRORS = (OSError, EOFError, ValueError, TypeError, KeyError, IndexError, OverflowError,
                RecursionError, NotImplementedError, RuntimeError, zipfile.BadZipFile,
                zlib.error, struct.error, SyntaxError, tokenize.TokenError)
"""What zipfile, zlib, numpy's header parser (ast, tokenize) and json raise on damaged or
crafted input."""


@dataclass(frozen=True)
class _Header:
    """A member's zip entry and ``.npy`` header; ``offset``: bytes before the data."""

    info: zipfile.ZipInfo
    dtype: np.dtype
    shape: tuple
    fortran: bool
    offset: int

    @property
    def nbytes(self) -> int:
        return math.prod(self.shape) * self.dtype.itemsize


@contextlib.contextmanager
def _reading(file: str, where: str):
    """Turn what a damaged archive makes zipfile, zlib or numpy raise into one line."""
    try:
        yield
    except FileFormatError:
        raise
    except _READ_ERRORS as exc:
        raise _unreadable(file, f"{where}: {type(exc).__name__}: {exc} (truncated or"
                                " corrupt?)") from exc


def _members(archive: zipfile.ZipFile, size: int, file: str) -> dict:
    """Field name → zip entry, after checking names, compression and sizes."""
    infos = archive.infolist()
    names = [info.filename for info in infos]
    wanted = {f"{field}.npy": field for field in FIELDS}
    extra = [n for n in names if n not in wanted]
    if extra:
        raise _unreadable(file, f"unexpected member {_show(extra[0])} (members are"
                                " the fields K, M, ..., meta)")
    missing = [field for member, field in wanted.items() if member not in names]
    if missing:
        raise _unreadable(file, "missing field" + "s" * (len(missing) > 1) + " "
                          + ", ".join(f"'{m}'" for m in missing))
    if len(names) != len(set(names)):
        twice = next(n for n in names if names.count(n) > 1)
        raise _unreadable(file, f"field '{wanted[twice]}': stored twice")
    for info in infos:
        where = f"field '{wanted[info.filename]}': zip entry"
        if info.flag_bits & 0x1:
            raise _unreadable(file, f"{where} is encrypted")
        if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
            raise _unreadable(file, f"{where} uses compression method {info.compress_type},"
                                    " expected stored (0) or deflated (8)")
        end = info.header_offset + info.compress_size
        if end > size:
            raise _unreadable(file, f"{where} ends at byte {end}, after the end of the file"
                                    f" ({size} bytes; truncated?)")
        ratio = 1 if info.compress_type == zipfile.ZIP_STORED else DEFLATE_MAX_RATIO
        if info.file_size > ratio * info.compress_size + 1024:
            raise _unreadable(file, f"{where} declares {info.file_size} bytes from"
                                    f" {info.compress_size} compressed bytes, more than"
                                    " the compression can produce")
    held = sum(info.compress_size + ZIP_OVERHEAD + 2 * len(info.filename) for info in infos)
    if size > held + ZIP_TAIL:
        raise _unreadable(file, f"the file has {size} bytes, its members only {held} with"
                                " their headers: it holds data that is no member (padded"
                                " or appended to?)")
    declared = sum(info.file_size for info in infos)
    if declared > MAX_EXPANSION * size + EXPANSION_FLOOR:
        raise _unreadable(file, f"the members declare {declared} bytes, more than"
                                f" {MAX_EXPANSION} times the file ({size} bytes)")
    return {wanted[info.filename]: info for info in infos}


def _header(archive: zipfile.ZipFile, info: zipfile.ZipInfo, field: str, file: str):
    """The member's ``.npy`` header, read and checked before any data."""
    with _reading(file, f"field '{field}': npy header"), archive.open(info) as stream:
        prefix = stream.read(8)
        version = np.lib.format.read_magic(io.BytesIO(prefix))
        if version not in ((1, 0), (2, 0)):
            raise _fail(file, field, f"npy format {version[0]}.{version[1]}, expected 1.0"
                                     " or 2.0")
        length_format = "<H" if version == (1, 0) else "<I"
        length_bytes = stream.read(struct.calcsize(length_format))
        (length,) = struct.unpack(length_format, length_bytes)
        if length > MAX_HEADER:
            raise _fail(file, field, f"npy header of {length} bytes (at most {MAX_HEADER})")
        text = stream.read(length)
        if len(text) != length:
            raise EOFError(f"npy header ends after {len(text)} of {length} bytes")
        parse = (np.lib.format.read_array_header_1_0 if version == (1, 0)
                 else np.lib.format.read_array_header_2_0)
        shape, fortran, dtype = parse(io.BytesIO(length_bytes + text),
                                      max_header_size=MAX_HEADER)
        shape = tuple(int(n) for n in shape)  # a literal True is an int to numpy
    _check_dtype(field, dtype, file)
    if len(shape) != _NDIM[field] or any(n < 0 for n in shape):
        raise _fail(file, field, f"shape {_show(shape)}, expected {_NDIM[field]} dimensions")
    head = _Header(info, dtype, shape, fortran, 8 + len(length_bytes) + length)
    if info.file_size != head.offset + head.nbytes:
        raise _fail(file, field, f"npy header declares shape {_show(shape)} of {dtype.str}"
                                 f" ({head.nbytes} bytes), the member holds"
                                 f" {info.file_size - head.offset} bytes of data")
    return head


def _check_dtype(field: str, dtype: np.dtype, file: str):
    if dtype.hasobject or dtype.fields is not None or dtype.subdtype is not None:
        raise _fail(file, field, f"dtype {_show(dtype.descr)} (objects and records are"
                                 " never read)")
    if field == "meta":
        ok = (dtype.kind == "U" and dtype.str[0] == "<"
              and 0 < dtype.itemsize <= 4 * MAX_META_CHARS)
        expected = f"little-endian unicode of at most {MAX_META_CHARS} characters"
    elif field in FLOATS:
        ok, expected = dtype.str == "<f8", "little-endian float64 ('<f8')"
    else:
        ok, expected = dtype.str in ("<i4", "<i8"), "little-endian int32 or int64"
    if not ok:
        raise _fail(file, field, f"dtype {dtype.str}, expected {expected}")


def _data(archive: zipfile.ZipFile, head: _Header, field: str, file: str):
    """(array, SHA-256 hex) of a member whose header passed :func:`_header`."""
    out = np.empty(math.prod(head.shape), dtype=head.dtype)
    view = out.view(np.uint8)
    digest = _digest_start(field, head.dtype, head.fortran, head.shape)
    with _reading(file, f"field '{field}': data"), archive.open(head.info) as stream:
        stream.read(head.offset)
        done = 0
        while done < head.nbytes:
            chunk = stream.read(min(CHUNK, head.nbytes - done))
            if not chunk:
                raise EOFError(f"data ends after {done} of {head.nbytes} bytes")
            view[done:done + len(chunk)] = np.frombuffer(chunk, dtype=np.uint8)
            digest.update(chunk)
            done += len(chunk)
        if stream.read(1):  # also makes zipfile compare the CRC-32
            raise ValueError("more data than the header declares")
    if head.fortran:
        return out.reshape(head.shape[::-1]).T, digest.hexdigest()
    return out.reshape(head.shape), digest.hexdigest()


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
