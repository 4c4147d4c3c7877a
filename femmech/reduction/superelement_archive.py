"""Stage 3: the container of a superelement file: zip members and ``.npy`` headers.

Opens only regular files (:func:`open_regular`: a FIFO would block the reader, a
device such as ``/dev/zero`` would feed it without end), then checks that the file is
not much larger than its members (:func:`_members`), the member list and each member's
zip entry (compression, encryption, sizes the
compressed bytes can produce) and each ``.npy`` header (version, dtype, number of
dimensions, a declared shape that fills the member exactly) before any data is read, then
reads a member's data in bounded chunks while hashing it. What a damaged archive makes
zipfile, zlib or numpy raise becomes one :class:`~femmech.errors.FileFormatError` line.
Used by :func:`femmech.reduction.superelement_file.read`.

Imports :mod:`femmech.errors` and its own package.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import stat
import struct
import tokenize
import zipfile
import zlib
from dataclasses import dataclass

import numpy as np

from femmech.errors import FileFormatError
from femmech.reduction.superelement_format import (
    _NDIM,
    FIELDS,
    FLOATS,
    _digest_start,
    _fail,
    _name,
    _show,
    _unreadable,
)

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
