"""Superelement-file fuzzing: mutated ``.npz`` files through ``Superelement.load``.

A small real superelement (a 1 x 1 x 1-bay steel grid frame with a rigid link, so T has
non-unit rows; Craig-Bampton with residual vectors: 24 interface DOFs, 30 modal
coordinates) is saved once; file ``i`` of a run is a mutation of it that depends only on
``(seed, i)``. Classes (``+sum``: the attacker recomputes the SHA-256 sums in ``meta``, so
that the structural checks, not the checksum, must catch the change):

- ``truncate``, ``flip_file``: truncation, bit flips in the compressed file;
- ``flip_data``: bit flips in a decompressed member (zip rewritten, CRCs valid);
- ``swap``: two members exchange contents (K↔M, Psi↔Phi, T_indices↔T_indptr, ...);
- ``shape_lie``: an npy header declares another shape for the same data;
- ``reshape``: a member reshaped consistently with its data (rows dropped, transposed);
- ``index_lie``: CSR indices, row pointers, interface and free DOFs out of range,
  negative, duplicated, unsorted, overlapping;
- ``nonfinite``: NaN or ±inf in a float member;
- ``dtype``: float32, float16, int8, uint64, complex, big-endian, bool, object (with a
  pickle that would create a directory if it were ever unpickled), records, strings;
- ``meta``: wrong types, missing and extra keys, huge n_dof, bad JSON, deep nesting,
  format 1 (no checksums);
- ``matrix``: K or M indefinite, unsymmetric, K's block structure broken, and consistent
  edits (scaled M or Psi, one modal coordinate less) that make a different but valid
  superelement;
- ``bomb``: consistent files of 6e6 rows or entries of T (24-72 MB) in 46-93 kB;
- ``zip_sizes``: lying sizes, CRC, offsets, compression method in the zip directory;
- ``zip_structure``: members missing, extra, twice, renamed, bzip2/lzma, encrypted flag,
  not a zip at all, prefixed or suffixed bytes, stored instead of deflated;
- ``missing_file``: no file (FileNotFoundError expected) or a directory.

Each load runs in one of two worker processes (``--worker``) under a time limit and a
memory limit. Oracle, per file: ``rejected`` (FileFormatError with one line starting with
the file name and naming a field or the archive; FileNotFoundError for a missing file),
``harmless`` (loaded, identical to the original), ``different`` (a ``+sum`` file loaded,
different from the original, and passing :func:`consistency_problems`, written here
independently of the validator). Failures: ``crash`` (the worker died: a signal or
exit 139), ``hang`` (time limit), ``traceback`` (another exception), ``bad_message``
(FileFormatError not one line naming the file), ``silent`` (loaded with data that is
changed without ``+sum``, or inconsistent). Usage::

    python benchmarks/fuzz_superelement.py                 # 2200 files, seed 0
    python benchmarks/fuzz_superelement.py --n 5000 --seed 1
    python benchmarks/fuzz_superelement.py --only 123 --keep out/fuzz   # one file, kept
"""

from __future__ import annotations

import argparse
import dataclasses
import io
import json
import math
import os
import select
import signal
import struct
import subprocess
import sys
import tempfile
import threading
import time
import traceback
import warnings
import zipfile
from collections import Counter
from pathlib import Path

import numpy as np

TIMEOUT = 10.0
"""Seconds per load before the worker counts as hung (a load takes about 10 ms)."""

MEMORY_LIMIT = 3 * 2**30
"""Address-space limit of a worker, bytes: an absurd allocation fails instead of swapping."""

OUTCOMES = ("rejected", "harmless", "different", "crash", "hang", "traceback",
            "bad_message", "silent")
FAILURES = OUTCOMES[3:]


# --- the original file and npy/zip building blocks ------------------------------------

def build_model():
    """A 1 x 1 x 1-bay steel grid frame, clamped at the base, with one rigid link."""
    import femmech as fm
    from femmech.fe import sections
    from femmech.fe.generators import grid_frame

    mesh = grid_frame((1, 1, 1), (1.0, 0.6, 0.8), 2)
    steel = fm.Material(E=210e9, nu=0.3, rho=7850.0)
    prop = fm.BeamProperty(sections.rectangular_hollow(0.06, 0.08, 0.004), steel)
    top = [n for n in np.flatnonzero(np.isclose(mesh.points[:, 2], 0.8))
           if n not in mesh.node_sets["joints"]]
    return fm.build_model(mesh, {name: prop for name in mesh.cell_sets},
                          supports=[fm.Support("base")],
                          rigid_links=[fm.RigidLink(int(top[0]), [int(top[1])])])


def build_superelement():
    """Craig-Bampton superelement of :func:`build_model` on its top joints."""
    from femmech.reduction.component_modes import craig_bampton

    return craig_bampton(build_model(), "top", n_modes=4)


@dataclasses.dataclass(frozen=True)
class Base:
    """The original file: bytes, members (name → npy bytes), arrays, meta."""

    data: bytes
    members: dict
    arrays: dict
    meta: dict
    sentinel: Path
    cache: dict


def make_base(folder: Path) -> tuple[Base, Path]:
    """Save the superelement to ``folder/original.npz``; (Base, its path).

    The timings are fixed and the archive rewritten with fixed dates, so that the bytes,
    and with them every mutated file, depend on nothing but the code.
    """
    se = build_superelement()
    se = dataclasses.replace(se, timings=dict.fromkeys(se.timings, 0.125))
    path = se.save(folder / "original.npz")
    with zipfile.ZipFile(path) as archive:
        members = {info.filename[:-4]: archive.read(info) for info in archive.infolist()}
    path.write_bytes(pack(members))
    with np.load(path, allow_pickle=False) as data:
        arrays = {name: data[name] for name in data.files}
    meta = json.loads(arrays.pop("meta").item())
    return Base(path.read_bytes(), members, arrays, meta, folder / "EXECUTED", {}), path


def npy(array, version=(1, 0)) -> bytes:
    buffer = io.BytesIO()
    np.lib.format.write_array(buffer, np.asanyarray(array), version=version,
                              allow_pickle=True)
    return buffer.getvalue()


def npy_raw(descr: str, fortran: bool, shape, payload: bytes) -> bytes:
    """An npy v1.0 file with an arbitrary header (shape not checked against payload)."""
    header = f"{{'descr': {descr!r}, 'fortran_order': {fortran!r}, 'shape': {tuple(shape)!r}, }}"
    header += " " * (63 - (10 + len(header)) % 64) + "\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + payload


def split_npy(blob: bytes):
    """(dtype, fortran, shape, payload) of npy bytes (header parsed by numpy)."""
    stream = io.BytesIO(blob)
    version = np.lib.format.read_magic(stream)
    reader = (np.lib.format.read_array_header_1_0 if version == (1, 0)
              else np.lib.format.read_array_header_2_0)
    shape, fortran, dtype = reader(stream)
    return dtype, fortran, shape, blob[stream.tell():]


DATE = (1980, 1, 1, 0, 0, 0)


def pack(members: dict, compression=zipfile.ZIP_DEFLATED, prefix="") -> bytes:
    buffer = io.BytesIO()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "Duplicate name" for the twice-stored member
        with zipfile.ZipFile(buffer, "w", compression) as archive:
            for name, blob in members.items():
                info = zipfile.ZipInfo(prefix + name.split("#")[0] + ".npy", DATE)
                info.compress_type = compression
                archive.writestr(info, blob)
    return buffer.getvalue()


def craft(members: dict) -> dict:
    """Members with meta's SHA-256 sums recomputed (what an attacker can always do)."""
    from femmech.reduction.superelement_file import field_digest, meta_digest

    try:
        dtype, _, shape, payload = split_npy(members["meta"])
        if shape != () or dtype.str[:2] != "<U":  # keep a mutated meta container as it is
            return members
        meta = json.loads(payload.decode("utf-32-le").rstrip("\0"))
        sums = dict(meta["sha256"])
    except (ValueError, KeyError, TypeError, UnicodeError, struct.error):
        return members
    for name, blob in members.items():
        if name in sums and name != "meta":
            try:
                dtype, fortran, shape, payload = split_npy(blob)
                sums[name] = field_digest(name, dtype, fortran, shape, payload)
            except (ValueError, TypeError, struct.error):
                pass
    meta["sha256"] = sums
    meta["sha256"]["meta"] = meta_digest(meta)
    return dict(members, meta=npy(np.array(json.dumps(meta))))


def rebuild(base: Base, crafted: bool, arrays=None, meta=None, members=None) -> bytes:
    members = dict(base.members if members is None else members)
    members.update({name: npy(a) for name, a in (arrays or {}).items()})
    if meta is not None:
        members["meta"] = npy(np.array(json.dumps(meta)))
    return pack(craft(members) if crafted else members)


@dataclasses.dataclass(frozen=True)
class Mutant:
    """A mutated file: its bytes (None: no file) and what was done."""

    data: bytes | None
    detail: str
    directory: bool = False


def _flip(blob: bytes, rng, start: int = 0, count: int = 1) -> tuple[bytes, list]:
    out = bytearray(blob)
    bits = rng.integers(8 * start, 8 * len(out), count).tolist()
    for bit in bits:
        out[bit // 8] ^= 1 << (bit % 8)
    return bytes(out), bits


def _pick(rng, items):
    return items[int(rng.integers(len(items)))]


# --- mutators: (rng, base, crafted) -> Mutant -------------------------------------------

def m_truncate(rng, base, crafted):
    k = int(rng.integers(len(base.data)))
    return Mutant(base.data[:k], f"first {k} of {len(base.data)} bytes")


def m_flip_file(rng, base, crafted):
    data, bits = _flip(base.data, rng, count=_pick(rng, [1, 1, 2, 4, 16]))
    return Mutant(data, f"bits {bits[:4]} of the file")


def m_flip_data(rng, base, crafted):
    name = _pick(rng, list(base.members))
    blob = base.members[name]
    start = len(blob) - len(split_npy(blob)[3]) if crafted else 0  # +sum: data bytes only
    new, bits = _flip(blob, rng, start, count=_pick(rng, [1, 1, 2, 3]))
    return Mutant(rebuild(base, crafted, members=dict(base.members, **{name: new})),
                  f"{name}: bits {bits[:3]}")


SWAPS = [("K", "M"), ("Psi", "Phi"), ("T_indices", "T_indptr"),
         ("free_interface", "free_interior"), ("interface_dofs", "free_interface"),
         ("T_data", "T_indices"), ("modal_omega2", "T_data"), ("interface_points", "Psi"),
         ("meta", "T_shape"), ("K", "Psi"), ("T_shape", "interface_dofs")]


def m_swap(rng, base, crafted):
    a, b = _pick(rng, SWAPS)
    members = dict(base.members, **{a: base.members[b], b: base.members[a]})
    return Mutant(rebuild(base, crafted, members=members), f"{a} <-> {b}")


def m_shape_lie(rng, base, crafted):
    name = _pick(rng, list(base.members))
    dtype, fortran, shape, payload = split_npy(base.members[name])
    s = list(shape) or [1]
    lies = [s[::-1], [s[0] + 1] + s[1:], [s[0] - 1] + s[1:], s[:-1] + [s[-1] + 1],
            [2**40] + s[1:], [2**62, 2**62], [-s[0]] + s[1:], [0] + s[1:], s + [1], s[:-1],
            [math.prod(s)], [2**31 + 1] + s[1:]]
    lie = _pick(rng, [lie for lie in lies if tuple(lie) != tuple(shape)])
    blob = npy_raw(dtype.str, fortran, lie, payload)
    return Mutant(rebuild(base, crafted, members=dict(base.members, **{name: blob})),
                  f"{name}: header shape {tuple(lie)} for data of {tuple(shape)}")


def m_reshape(rng, base, crafted):
    a = base.arrays
    edits = {
        "K[:-1, :-1]": {"K": a["K"][:-1, :-1]}, "Psi.T": {"Psi": a["Psi"].T},
        "Psi[:-1]": {"Psi": a["Psi"][:-1]}, "Phi[:, :-1]": {"Phi": a["Phi"][:, :-1]},
        "interface_dofs[:-1]": {"interface_dofs": a["interface_dofs"][:-1]},
        "interface_points[:, :2]": {"interface_points": a["interface_points"][:, :2]},
        "T_data, T_indices[:-1]": {"T_data": a["T_data"][:-1],
                                   "T_indices": a["T_indices"][:-1]},
        "T_indptr[:-1]": {"T_indptr": a["T_indptr"][:-1]},
        "modal_omega2[:-1]": {"modal_omega2": a["modal_omega2"][:-1]},
        "free_interior[:-1]": {"free_interior": a["free_interior"][:-1]},
        "K.ravel()": {"K": a["K"].ravel()}, "T_shape[:1]": {"T_shape": a["T_shape"][:1]},
        "Psi[..., None]": {"Psi": a["Psi"][..., None]},
        "M in F order": {"M": np.asfortranarray(a["M"])},
        "Phi F-ordered": {"Phi": np.asfortranarray(a["Phi"])},
        "meta as 1-d": {"meta": np.array([json.dumps(base.meta)])},
    }
    key = _pick(rng, list(edits))
    return Mutant(rebuild(base, crafted, arrays=edits[key]), key)


def _index_lies(a):
    n_dof, n_free = (int(n) for n in a["T_shape"])
    nnz, dofs = a["T_data"].size, a["interface_dofs"]

    def put(name, k, value):
        x = a[name].astype(np.int64 if abs(value) >= 2**31 else a[name].dtype)
        x[k] = value
        return {name: x}

    return {
        "T_indices = n_free": put("T_indices", -1, n_free),
        "T_indices = -1": put("T_indices", 0, -1),
        "T_indices = 2**31-1": put("T_indices", nnz // 2, 2**31 - 1),
        "T_indptr decreasing": put("T_indptr", 5, a["T_indptr"][4] - 1),
        "T_indptr[-1] = nnz + 1": put("T_indptr", -1, nnz + 1),
        "T_indptr[0] = 1": put("T_indptr", 0, 1),
        "T_indptr huge": put("T_indptr", 3, 2**40),
        "T_shape n_free + 1": put("T_shape", 1, n_free + 1),
        "T_shape n_dof + 6": put("T_shape", 0, n_dof + 6),
        "T_shape 2**40": put("T_shape", 0, 2**40),
        "T_shape 0": put("T_shape", 1, 0),
        "interface_dofs = n_dof": put("interface_dofs", -1, n_dof),
        "interface_dofs = -1": put("interface_dofs", 0, -1),
        "interface_dofs duplicate": put("interface_dofs", 1, dofs[0]),
        "interface_dofs unsorted": {"interface_dofs": dofs[::-1].copy()},
        "interface_dofs = 2**40": put("interface_dofs", -1, 2**40),
        "interface_dofs a supported DOF": put("interface_dofs", 5, dofs[5] + 1),
        "free_interface = n_free": put("free_interface", -1, n_free),
        "free_interface = -5": put("free_interface", 0, -5),
        "free_interior overlaps": put("free_interior", 0, a["free_interface"][0]),
        "free sets exchanged": {"free_interface": a["free_interior"][:dofs.size].copy()},
        "free_interior = 2**62": put("free_interior", -1, 2**62),
    }


def m_index_lie(rng, base, crafted):
    lies = _index_lies(base.arrays)
    key = _pick(rng, list(lies))
    return Mutant(rebuild(base, crafted, arrays=lies[key]), key)


FLOAT_MEMBERS = ("K", "M", "interface_points", "modal_omega2", "Psi", "Phi", "T_data")


def m_nonfinite(rng, base, crafted):
    name = _pick(rng, FLOAT_MEMBERS)
    x = base.arrays[name].copy()
    k = int(rng.integers(x.size))
    value = _pick(rng, [np.nan, np.inf, -np.inf])
    x.flat[k] = value
    return Mutant(rebuild(base, crafted, arrays={name: x}), f"{name}.flat[{k}] = {value}")


class _Executed:
    """Unpickling this calls ``os.mkdir(path)``: proof that a loader ran file content."""

    def __init__(self, path):
        self.path = str(path)

    def __reduce__(self):
        return (os.mkdir, (self.path,))


DTYPES = ("<f4", "<f2", "|i1", "<i2", "<u8", "<c16", ">f8", ">i8", "|b1", "object",
          "pickle", "record", "<U10", "|S8", "|V8", "<f8", "<i8", "<i4")


def _as_dtype(x: np.ndarray, target: str, sentinel: Path) -> np.ndarray:
    if target == "pickle":
        return np.array([_Executed(sentinel)], dtype=object)
    if target in ("record", "|V8"):
        return np.zeros(x.shape, dtype=[("value", "<f8")] if target == "record" else target)
    if x.dtype.kind != "U":
        return x.astype(target)
    text = x.item()  # meta
    if target in ("|S8", "object"):
        return np.array(text.encode()) if target == "|S8" else np.array(text, dtype=object)
    return x.astype(x.dtype.newbyteorder(">")) if target[0] == ">" else np.zeros((), target)


def m_dtype(rng, base, crafted):
    name = _pick(rng, list(base.arrays) + ["meta"])
    x = np.array(json.dumps(base.meta)) if name == "meta" else base.arrays[name]
    target = _pick(rng, [t for t in DTYPES if t != x.dtype.str])
    y = _as_dtype(x, target, base.sentinel)
    return Mutant(rebuild(base, crafted, arrays={name: y}), f"{name} as {target}")


def _meta_edits(meta, n_q):
    def edit(**changes):
        out = json.loads(json.dumps(meta))
        for key, value in changes.items():
            if value is KeyError:
                out.pop(key, None)
            else:
                out[key] = value
        return out

    v1 = edit(format_version=1, sha256=KeyError)
    return {
        **{f"format_version = {v!r}": edit(format_version=v)
           for v in (0, 3, "2", 2.0, True, None, -1, 10**30)},
        **{f"method = {v!r}": edit(method=v)
           for v in ("Guyan", "", 5, None, ["guyan"], "guyan", "craig-bampton")},
        **{f"n_dof = {v!r}": edit(n_dof=v)
           for v in (10**18, 0, -6, "120", 120.0, meta["n_dof"] + 6, True)},
        **{f"n_residual = {v!r}": edit(n_residual=v)
           for v in (-1, n_q + 1, 1.5, "3", None, meta["n_residual"] - 1, 0)},
        **{f"timings = {v!r}"[:40]: edit(timings=v)
           for v in ({"x": float("nan")}, {"x": "1"}, [], {"x": -1.0}, {"x": 1e308 * 10},
                     {"x": {"y": 1.0}}, {f"k{i}": 1.0 for i in range(100)}, {},
                     {"x": 10**400})},
        **{f"without {k}": edit(**{k: KeyError}) for k in meta},
        "extra key": edit(extra=1),
        "sha256 = 'x'": edit(sha256="x"),
        "sha256 without K": edit(sha256={k: v for k, v in meta["sha256"].items() if k != "K"}),
        "sha256 upper case": edit(sha256={k: v.upper() for k, v in meta["sha256"].items()}),
        "format 1, no sums": v1,
        "format 1, no sums, no n_residual": {k: v for k, v in v1.items() if k != "n_residual"},
        "format 1, no sums, timings {}": dict(v1, timings={}),
    }


RAW_META = ["not json", "", "[]", "42", '"text"', "[" * 100_000, '{"a":' * 50_000,
            "x" * 70_000, "\0" * 10, '{"format_version": NaN}', "\ud800", '{"a": 1e999}']


def m_meta(rng, base, crafted):
    edits = _meta_edits(base.meta, base.arrays["modal_omega2"].size)
    if not crafted:  # format 1 has no checksums: changed data is a crafted file
        edits = {k: v for k, v in edits.items() if not k.startswith("format 1, no sums,")}
    keys = list(edits) + [f"raw {i}" for i in range(len(RAW_META))]
    key = _pick(rng, keys)
    if key.startswith("raw "):
        text = RAW_META[int(key[4:])]
        members = dict(base.members, meta=npy(np.array(text)))
        return Mutant(pack(members), f"meta text {text[:20]!r}")
    return Mutant(rebuild(base, crafted, meta=edits[key]), key)


def _edit(x: np.ndarray, index, value) -> np.ndarray:
    y = x.copy()
    y[index] = value
    return y


def _matrix_edits(a, n_b):
    K, M, w2 = a["K"], a["M"], a["modal_omega2"]
    singular = _edit(_edit(M, np.s_[0, :], 0.0), np.s_[:, 0], 0.0)
    return {
        "K negated": {"K": -K, "modal_omega2": -w2},
        "K interface block negated": {"K": _edit(K, np.s_[:n_b, :n_b], -K[:n_b, :n_b])},
        "M[0, 0] negated": {"M": _edit(M, (0, 0), -M[0, 0])},
        "M scaled by -1": {"M": -M},
        "M singular": {"M": singular},
        "K[0, 1] * (1 + 1e-6)": {"K": _edit(K, (0, 1), K[0, 1] * (1 + 1e-6))},
        "M[0, 1] * (1 + 1e-9)": {"M": _edit(M, (0, 1), M[0, 1] * (1 + 1e-9))},
        "K modal diagonal doubled": {"K": _edit(K, (n_b, n_b), 2 * K[n_b, n_b])},
        "K coupling entry": {"K": _edit(_edit(K, (0, n_b), 1.0), (n_b, 0), 1.0)},
        "K and modal_omega2 scaled": {"K": 2 * K, "modal_omega2": 2 * w2},
        "M scaled": {"M": 1.5 * M},
        "Psi scaled": {"Psi": 3.0 * a["Psi"]},
        "T_data scaled": {"T_data": np.where(a["T_data"] == 1.0, 1.0, 2 * a["T_data"])},
        "one modal coordinate less": {"K": K[:-1, :-1], "M": M[:-1, :-1],
                                      "modal_omega2": w2[:-1], "Phi": a["Phi"][:, :-1]},
        "K = M": {"K": M},
        "K + 1e-3 max|K| I on the interface": {"K": _edit(
            K, np.s_[:n_b, :n_b], K[:n_b, :n_b] + 1e-3 * abs(K).max() * np.eye(n_b))},
    }


def m_matrix(rng, base, crafted):
    edits = _matrix_edits(base.arrays, base.arrays["interface_dofs"].size)
    key = _pick(rng, list(edits))
    meta = dict(base.meta, n_residual=base.meta["n_residual"] - 1) if "less" in key else None
    return Mutant(rebuild(base, crafted, arrays=edits[key], meta=meta), key)


def _central_entries(data: bytes) -> list[int]:
    end = data.rfind(b"PK\x05\x06")
    count, _, start = struct.unpack_from("<HII", data, end + 10)
    entries, p = [], start
    for _ in range(count):
        entries.append(p)
        n, m, k = struct.unpack_from("<HHH", data, p + 28)
        p += 46 + n + m + k
    return entries


ZIP_FIELDS = {"flags": (8, "<H"), "method": (10, "<H"), "crc": (16, "<I"),
              "compressed size": (20, "<I"), "size": (24, "<I"), "offset": (42, "<I")}


def m_zip_sizes(rng, base, crafted):
    data = bytearray(base.data)
    entry = _pick(rng, _central_entries(base.data))
    field = _pick(rng, list(ZIP_FIELDS))
    at, fmt = ZIP_FIELDS[field]
    old = struct.unpack_from(fmt, data, entry + at)[0]
    top = 2**(8 * struct.calcsize(fmt)) - 1
    new = _pick(rng, [v for v in (old + 1, max(old - 1, 0), 2 * old, old // 2, top - 1, 0,
                                  old ^ 1, len(data), 12 if field == "method" else 1)
                      if v != old])
    struct.pack_into(fmt, data, entry + at, min(new, top))
    if field == "flags":
        struct.pack_into("<H", data, struct.unpack_from("<I", data, entry + 42)[0] + 6,
                         min(new, top))
    return Mutant(bytes(data), f"central directory entry at {entry}: {field} {old} -> {new}")


def m_zip_structure(rng, base, crafted):
    members = base.members
    names = list(members)
    drop = _pick(rng, names)
    variants = {
        "extra member": lambda: pack(dict(members, extra=npy(np.eye(2)))),
        f"missing {drop}": lambda: pack({k: v for k, v in members.items() if k != drop}),
        f"{drop} twice": lambda: pack(dict(members, **{f"{drop}#2": members[drop]})),
        "K renamed k": lambda: pack({("k" if k == "K" else k): v for k, v in members.items()}),
        "members in a folder": lambda: pack(members, prefix="se/"),
        "stored, not deflated": lambda: pack(members, zipfile.ZIP_STORED),
        "bzip2": lambda: pack(members, zipfile.ZIP_BZIP2),
        "lzma": lambda: pack(members, zipfile.ZIP_LZMA),
        "random bytes": lambda: rng.bytes(len(base.data)),
        "empty file": lambda: b"",
        "a bare npy file": lambda: members["K"],
        "a zip of the file": lambda: pack({"inner": base.data}),
        "text": lambda: b"K = [[1, 0], [0, 1]]\n",
        "prefixed bytes": lambda: b"#!/bin/sh\n" * 3 + base.data,
        "suffixed bytes": lambda: base.data + b"\0" * 100,
    }
    key = _pick(rng, list(variants))
    return Mutant(variants[key](), key)


BOMB_ROWS = 6_000_000
"""Rows or entries of T in the consistent bombs: 24-72 MB that deflate to 46-93 kB."""


def _bomb(base: Base, kind: str) -> bytes:
    a, meta = base.arrays, dict(base.meta)
    if kind == "T with 6e6 empty rows":
        tail = np.full(BOMB_ROWS - a["T_indptr"].size + 1, a["T_indptr"][-1])
        arrays = {"T_indptr": np.concatenate([a["T_indptr"], tail]),
                  "T_shape": np.array([BOMB_ROWS, a["T_shape"][1]])}
        meta["n_dof"] = BOMB_ROWS
    else:  # 6e6 explicit zeros in the last row of T
        pad = BOMB_ROWS - a["T_data"].size
        arrays = {"T_data": np.concatenate([a["T_data"], np.zeros(pad)]),
                  "T_indices": np.concatenate([a["T_indices"], np.zeros(pad, np.int32)]),
                  "T_indptr": _edit(a["T_indptr"], -1, BOMB_ROWS)}
    return rebuild(base, True, arrays=arrays, meta=meta)


def m_bomb(rng, base, crafted):
    kind = _pick(rng, ["T with 6e6 empty rows", "6e6 explicit zeros in T"])
    if kind not in base.cache:
        base.cache[kind] = _bomb(base, kind)
    return Mutant(base.cache[kind], kind)


def m_missing(rng, base, crafted):
    return Mutant(None, "no file") if rng.integers(2) else Mutant(b"", "a folder", True)


CLASSES = {  # name: (mutator, checksums recomputed)
    "truncate": (m_truncate, False), "flip_file": (m_flip_file, False),
    "flip_data": (m_flip_data, False), "flip_data+sum": (m_flip_data, True),
    "swap": (m_swap, False), "swap+sum": (m_swap, True),
    "shape_lie": (m_shape_lie, False), "shape_lie+sum": (m_shape_lie, True),
    "reshape+sum": (m_reshape, True),
    "index_lie": (m_index_lie, False), "index_lie+sum": (m_index_lie, True),
    "nonfinite": (m_nonfinite, False), "nonfinite+sum": (m_nonfinite, True),
    "dtype": (m_dtype, False), "dtype+sum": (m_dtype, True),
    "meta": (m_meta, False), "meta+sum": (m_meta, True),
    "matrix+sum": (m_matrix, True), "bomb+sum": (m_bomb, True),
    "zip_sizes": (m_zip_sizes, False),
    "zip_structure": (m_zip_structure, False), "missing_file": (m_missing, False),
}


def mutant(base: Base, seed: int, i: int) -> tuple[str, Mutant]:
    """(class, mutated file) number ``i`` of run ``seed``."""
    name = list(CLASSES)[i % len(CLASSES)]
    mutator, crafted = CLASSES[name]
    return name, mutator(np.random.default_rng([seed, i]), base, crafted)


# --- the worker: load, judge, exercise ------------------------------------------------

def reference_fields(path) -> dict:
    """The original's fields read with plain numpy (not through the validator)."""
    import scipy.sparse as sp

    with np.load(path, allow_pickle=False) as data:
        f = {name: data[name] for name in data.files}
    meta = json.loads(f.pop("meta").item())
    T = sp.csr_matrix((f.pop("T_data"), f.pop("T_indices"), f.pop("T_indptr")),
                      shape=tuple(f.pop("T_shape")))
    return dict(f, T=T, method=meta["method"], timings=meta["timings"],
                n_residual=meta["n_residual"])


def identical(se, ref: dict) -> bool:
    for name, value in ref.items():
        mine = getattr(se, name)
        if name == "T":
            if mine.shape != value.shape or (mine != value).nnz:
                return False
        elif isinstance(value, np.ndarray):  # same kind (indices may widen to intp)
            if (mine.shape != value.shape or mine.dtype.kind != value.dtype.kind
                    or not np.array_equal(mine, value)):
                return False
        elif mine != value or type(mine) is not type(value):
            return False
    return True


def consistency_problems(se) -> list[str]:
    """What makes ``se`` unusable, checked independently of femmech.reduction.superelement_file."""
    import scipy.linalg as sla

    K, M, T, w2 = se.K, se.M, se.T, se.modal_omega2
    n_b, n_q, n_i = len(se.interface_dofs), len(w2), len(se.free_interior)
    n_dof, n_free = T.shape
    out = []
    checks = [
        (se.method in ("guyan", "craig-bampton"), "method"),
        (K.shape == M.shape == (n_b + n_q, n_b + n_q), "K, M shapes"),
        (se.Psi.shape == (n_i, n_b) and se.Phi.shape == (n_i, n_q), "Psi, Phi shapes"),
        (se.interface_points.shape == (n_b, 3), "interface_points shape"),
        (0 <= se.n_residual <= n_q, "n_residual"),
        (all(isinstance(v, float | int) and math.isfinite(v) for v in se.timings.values()),
         "timings"),
        (all(np.isnan(x).sum() + np.isinf(x).sum() == 0
             for x in (K, M, se.Psi, se.Phi, w2, se.interface_points, T.data)), "finite"),
        (np.array_equal(np.sort(np.concatenate([se.free_interface, se.free_interior])),
                        np.arange(n_free)), "free DOF partition"),
        (len(set(se.interface_dofs.tolist())) == n_b and 0 <= se.interface_dofs.min()
         and se.interface_dofs.max() < n_dof, "interface_dofs"),
        (T.indptr[0] == 0 and T.indptr[-1] == T.indices.size and (np.diff(T.indptr) >= 0).all()
         and (T.indices.size == 0 or 0 <= T.indices.min() <= T.indices.max() < n_free),
         "T structure"),
    ]
    out = [text for ok, text in checks if not ok]
    if out:
        return out
    if not np.array_equal(T[se.interface_dofs].toarray(), np.eye(n_free)[se.free_interface]):
        out.append("interface rows of T")
    scale = abs(K).max()
    if not np.allclose(K, K.T, rtol=0, atol=1e-12 * scale):
        out.append("K symmetric")
    if not np.allclose(M, M.T, rtol=0, atol=1e-12 * abs(M).max()):
        out.append("M symmetric")
    if not np.allclose(K[n_b:, n_b:], np.diag(w2), rtol=0, atol=1e-12 * scale) or \
            abs(K[:n_b, n_b:]).max(initial=0) > 1e-12 * scale:
        out.append("K block structure")
    wk, wm = sla.eigvalsh(K), sla.eigvalsh(M)
    if wk.min() < -1e-6 * abs(wk).max():
        out.append(f"K indefinite ({wk.min():.2e})")
    if wm.min() <= 0:
        out.append(f"M not positive definite ({wm.min():.2e})")
    return out


def exercise(se):
    """Use the loaded superelement as analyses do (a crash here is a crash)."""
    q = np.random.default_rng(0).standard_normal((se.n_reduced, 2))
    with np.errstate(all="ignore"):
        se.recover(q)
        se.expand_free(q[:, 0])
        se.interface_labels()


def judge(task: dict, ref: dict) -> dict:
    from femmech.errors import FileFormatError
    from femmech.reduction.superelement import Superelement

    path = task["path"]
    start = time.perf_counter()
    try:
        se = Superelement.load(path)
    except FileFormatError as exc:
        text = str(exc)
        good = (text.startswith(f"{path}: ") and len(text.splitlines()) == 1
                and ("field '" in text or "not a readable superelement file" in text))
        return {"outcome": "rejected" if good else "bad_message", "message": text[:400]}
    except FileNotFoundError as exc:
        return {"outcome": "rejected" if task["missing"] else "traceback",
                "message": f"FileNotFoundError: {exc}"[:400]}
    except Exception:  # the point of fuzzing: anything else is a bug
        return {"outcome": "traceback", "message": traceback.format_exc()[-400:]}
    seconds = time.perf_counter() - start
    try:
        exercise(se)
        if identical(se, ref):
            return {"outcome": "harmless", "seconds": seconds}
        problems = consistency_problems(se) if task["crafted"] else ["changed, no +sum"]
    except Exception as exc:  # accepted, then unusable
        problems = [f"loaded, then {type(exc).__name__}: {exc}"[:300]]
    return {"outcome": "silent" if problems else "different", "seconds": seconds,
            "message": "; ".join(problems)}


def worker_main(reference: str):
    """Loop: read a task (JSON line) from stdin, write its judgement (JSON line)."""
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
    import femmech.reduction.superelement  # noqa: F401 (imported before the first timed load)

    ref = reference_fields(reference)
    print("ready", flush=True)
    for line in iter(sys.stdin.readline, ""):
        task = json.loads(line)
        if task.get("selftest") == "crash":  # proves that the parent detects crashes
            os.kill(os.getpid(), signal.SIGSEGV)
        if task.get("selftest") == "hang":
            time.sleep(3600)
        start = time.perf_counter()
        result = judge(task, ref)
        result.setdefault("seconds", time.perf_counter() - start)
        print(json.dumps(result), flush=True)


class Worker:
    """A ``--worker`` subprocess; a crash or hang is detected and the worker replaced."""

    def __init__(self, reference: Path, timeout: float):
        self.reference, self.timeout, self.proc = reference, timeout, None
        self._start()

    def _start(self):
        env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
                   MKL_NUM_THREADS="1")
        self.proc = subprocess.Popen(
            [sys.executable, __file__, "--worker", str(self.reference)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
            env=env)
        if self._line(120.0) != b"ready\n":
            raise RuntimeError("fuzz worker did not start")

    def _line(self, timeout: float) -> bytes | None:
        ready, _, _ = select.select([self.proc.stdout], [], [], timeout)
        return self.proc.stdout.readline() if ready else None

    def run(self, task: dict) -> dict:
        try:
            self.proc.stdin.write((json.dumps(task) + "\n").encode())
            self.proc.stdin.flush()
        except BrokenPipeError:
            pass
        line = self._line(self.timeout)
        if line is None:
            self.proc.kill()
            self.proc.wait()
            self._start()
            return {"outcome": "hang", "message": f"no answer in {self.timeout} s"}
        if not line.endswith(b"\n"):
            code = self.proc.wait()
            self._start()
            return {"outcome": "crash", "message": f"worker exit code {code}"}
        return json.loads(line)

    def close(self):
        self.proc.stdin.close()
        self.proc.wait(timeout=60)


# --- the run --------------------------------------------------------------------------

def fuzz(n: int, seed: int = 0, workers: int = 2, timeout: float = TIMEOUT,
         only=None, keep=None) -> list[dict]:
    """Results (class, detail, outcome, message, seconds) of files ``range(n)`` or ``only``."""
    indices = list(range(n)) if only is None else [int(i) for i in only]
    results = [None] * len(indices)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        base, original = make_base(folder)
        jobs = iter(range(len(indices)))
        lock = threading.Lock()

        def serve():
            worker = Worker(original, timeout)
            try:
                while True:
                    with lock:
                        k = next(jobs, None)
                    if k is None:
                        return
                    results[k] = _one(worker, base, folder, seed, indices[k], keep,
                                      only is not None)
            finally:
                worker.close()

        threads = [threading.Thread(target=serve) for _ in range(workers)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        if None in results:
            raise RuntimeError("a fuzz thread failed (see its traceback above)")
        if base.sentinel.exists():  # a loader unpickled file content
            results.append({"index": -1, "class": "dtype", "outcome": "traceback",
                            "detail": "pickle", "message": "code in a file was executed"})
    return results


def _one(worker: Worker, base: Base, folder: Path, seed: int, i: int, keep,
         keep_all: bool) -> dict:
    name, m = mutant(base, seed, i)
    path = folder / f"m{i:06d}.npz"
    if m.directory:
        path.mkdir()
    elif m.data is not None:
        path.write_bytes(m.data)
    task = {"path": str(path), "crafted": CLASSES[name][1], "missing": m.data is None}
    result = dict(worker.run(task), index=i, detail=m.detail, **{"class": name})
    if keep is not None and (result["outcome"] in FAILURES or keep_all):
        keep.mkdir(parents=True, exist_ok=True)
        if path.is_file():
            (keep / path.name).write_bytes(path.read_bytes())
    if path.is_dir():
        path.rmdir()
    else:
        path.unlink(missing_ok=True)
    return result


def table(results: list[dict]) -> str:
    """Markdown table: per class, tries and outcomes; a total line."""
    counts = {name: Counter() for name in CLASSES}
    slowest = Counter()
    for r in results:
        counts.setdefault(r["class"], Counter())[r["outcome"]] += 1
        slowest[r["class"]] = max(slowest[r["class"]], r.get("seconds", 0.0))
    head = ["class", "tries", "rejected", "harmless", "different, consistent", "crashes",
            "hangs", "tracebacks", "bad messages", "silent inconsistent", "slowest load s"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    total = Counter()
    for name, c in counts.items():
        total.update(c)
        lines.append(_row(name, c, f"{slowest[name]:.3f}"))
    lines.append(_row("**total**", total, f"{max(slowest.values(), default=0):.3f}"))
    return "\n".join(lines)


def _row(name, c, slow):
    cells = [name, sum(c.values())] + [c[o] for o in OUTCOMES] + [slow]
    return "| " + " | ".join(str(x) for x in cells) + " |"


def main(argv=None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=2200, help="number of mutated files")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--timeout", type=float, default=TIMEOUT, help="s per load")
    parser.add_argument("--only", type=int, nargs="*", help="run only these file numbers")
    parser.add_argument("--keep", type=Path, help="copy failing files to this folder")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        worker_main(args.worker)
        return []
    start = time.perf_counter()
    results = fuzz(args.n, args.seed, args.workers, args.timeout, args.only, args.keep)
    print(table(results))
    only = f" --only {' '.join(map(str, args.only))}" if args.only else ""
    print(f"\n{len(results)} files in {time.perf_counter() - start:.1f} s with"
          f" {args.workers} workers; reproduce: python benchmarks/fuzz_superelement.py"
          f" --n {args.n} --seed {args.seed}{only}")
    for r in results:
        if r["outcome"] in FAILURES:
            print(f"- {r['outcome']}: file {r['index']} ({r['class']}: {r['detail']}):"
                  f" {r.get('message', '')}")
    return results


if __name__ == "__main__":
    main()
