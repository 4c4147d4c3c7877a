"""Superelement files: validated loading, checksums, and a short fuzz run.

Every damaged, foreign or crafted file must raise FileFormatError with one line that
starts with the file name and names the field; a valid file must load identical to what
was saved. The corrupted files are built here with the helpers of
``benchmarks/fuzz_superelement.py`` (npy members, zip packing, and ``craft``, which
recomputes the SHA-256 sums as an attacker could, so that the structural checks must
reject the file). The fuzz run's oracle (:func:`consistency_problems`) is written there
independently of :mod:`femmech.reduction.superelement_file`.
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib.util
import json
import struct
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from models import assert_same_superelement as assert_same

from femmech.errors import FileFormatError
from femmech.reduction.component_modes import guyan
from femmech.reduction.superelement import Superelement
from femmech.reduction.superelement_file import FORMAT_VERSION, PSD_RTOL, SYMMETRY_RTOL

FUZZ_FILE = Path(__file__).resolve().parent.parent / "benchmarks" / "fuzz_superelement.py"


def _fuzz_module():
    spec = importlib.util.spec_from_file_location("fuzz_superelement", FUZZ_FILE)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up by name
    spec.loader.exec_module(module)
    return module


fz = _fuzz_module()


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    """The fuzz run's original: Craig-Bampton, residual vectors, a rigid link in T."""
    folder = tmp_path_factory.mktemp("original")
    return fz.make_base(folder)[0]


def rejected(path: Path, *fields: str) -> str:
    """Load ``path``; assert a one-line FileFormatError naming the file and ``fields``."""
    with pytest.raises(FileFormatError) as info:
        Superelement.load(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ")
    assert "\n" not in message
    assert "\r" not in message
    for field in fields:
        assert field in message
    return message


# --- round trip and format versions ---------------------------------------------------

@pytest.mark.parametrize("method", ["craig-bampton", "guyan"])
def test_round_trip_is_identical(tmp_path, method):
    # Guyan has no modal coordinates: Phi is (n_i, 0), modal_omega2 empty
    se = fz.build_superelement() if method == "craig-bampton" else guyan(fz.build_model(),
                                                                          "top")
    path = se.save(tmp_path / "se.npz")
    assert sorted(tmp_path.iterdir()) == [path]  # no temporary file left
    assert_same(se, Superelement.load(path))
    with np.load(path, allow_pickle=False) as data:
        meta = json.loads(data["meta"].item())
    assert meta["format_version"] == FORMAT_VERSION == 2
    assert sorted(meta["sha256"]) == sorted([*fz.FLOAT_MEMBERS, "interface_dofs",
                                             "free_interface", "free_interior", "T_indices",
                                             "T_indptr", "T_shape", "meta"])


WRITTEN_SHA256 = "5ff015b9ffbd45a58d31bafcf0c584ca416264e57a34abda83eb228f65f43f9d"
"""SHA-256 of the members of the file that the code of commit 7bec911 (before the format's
modules were merged into one) wrote for the superelement of :func:`test_file_bytes_unchanged`:
computed once by running that test's hashing on a detached worktree of that commit."""


def machine_independent(se: Superelement) -> Superelement:
    """``se`` with its float arrays drawn from numpy's PCG64 generator (bitwise the same on
    every machine) and combined elementwise only: the reduced matrices of a real reduction
    differ in the last bits between BLAS kernels and thread counts, and so would the file's
    bytes. K and M stay symmetric and diagonally dominant (positive definite)."""
    rng = np.random.default_rng(20261207)

    def symmetric(n):
        a = rng.standard_normal((n, n))
        return (a + a.T) / 2 + 2.0 * n * np.eye(n)

    n = se.K.shape[0]
    T = se.T.copy()
    T.data = rng.standard_normal(T.data.size)
    return dataclasses.replace(
        se, K=symmetric(n), M=symmetric(n),
        interface_points=rng.standard_normal(se.interface_points.shape),
        modal_omega2=np.sort(rng.uniform(1e3, 1e6, se.modal_omega2.shape)),
        Psi=rng.standard_normal(se.Psi.shape), Phi=rng.standard_normal(se.Phi.shape), T=T,
        timings=dict.fromkeys(se.timings, 0.125))  # no clock


def test_file_bytes_unchanged(tmp_path):
    """The writer still writes the same members with the same bytes: per member its name,
    compression method, CRC-32 and uncompressed data. The zip dates (the clock's) and the
    compressed sizes (the zlib build's) are left out."""
    se = machine_independent(fz.build_superelement())
    digest = hashlib.sha256()
    with zipfile.ZipFile(se.save(tmp_path / "se.npz")) as archive:
        for info in archive.infolist():
            digest.update(f"{info.filename}\n{info.compress_type}\n{info.CRC}\n".encode())
            digest.update(archive.read(info))
    assert digest.hexdigest() == WRITTEN_SHA256


def _format_1(base, tmp_path, arrays=None, drop_n_residual=False) -> Path:
    """A file as femmech wrote it before checksums (format 1)."""
    meta = {k: v for k, v in base.meta.items() if k != "sha256"}
    meta["format_version"] = 1
    if drop_n_residual:
        del meta["n_residual"]
    path = tmp_path / "old.npz"
    np.savez_compressed(path, meta=np.array(json.dumps(meta)), **dict(base.arrays,
                                                                       **(arrays or {})))
    return path


def test_format_1_files_load_when_consistent(tmp_path, base):
    new = Superelement.load(base.sentinel.parent / "original.npz")
    assert_same(Superelement.load(_format_1(base, tmp_path)), new)
    # the oldest files have no n_residual: all modal coordinates are fixed-interface modes
    assert Superelement.load(_format_1(base, tmp_path, drop_n_residual=True)).n_residual == 0
    K = base.arrays["K"].copy()
    K[0, 1] *= 1.5
    rejected(_format_1(base, tmp_path, {"K": K}), "field 'K'", "not symmetric")


def test_unknown_format_version(tmp_path, base):
    path = tmp_path / "se.npz"
    path.write_bytes(fz.rebuild(base, True, meta=dict(base.meta, format_version=3)))
    rejected(path, "field 'meta.format_version'", "format 3")


# --- container: zip, members, npy headers ---------------------------------------------

def _write(tmp_path, data: bytes) -> Path:
    path = tmp_path / "se.npz"
    path.write_bytes(data)
    return path


def _patched(base, member: str, field: str, value: int) -> bytes:
    """The original with one field of ``member``'s central-directory entry replaced."""
    data = bytearray(base.data)
    for entry in fz._central_entries(base.data):
        n = struct.unpack_from("<H", data, entry + 28)[0]
        if data[entry + 46:entry + 46 + n] == f"{member}.npy".encode():
            at, fmt = fz.ZIP_FIELDS[field]
            struct.pack_into(fmt, data, entry + at, value)
    return bytes(data)


CONTAINER = {
    "truncated": (lambda b: b.data[:len(b.data) // 2], ["not a readable superelement file"]),
    "empty": (lambda b: b"", ["not a readable superelement file", "zip archive"]),
    "missing member": (lambda b: fz.pack({k: v for k, v in b.members.items() if k != "Psi"}),
                       ["missing field 'Psi'"]),
    "extra member": (lambda b: fz.pack(dict(b.members, extra=fz.npy(np.eye(2)))),
                     ["unexpected member 'extra.npy'"]),
    "member twice": (lambda b: fz.pack(dict(b.members, **{"K#2": b.members["K"]})),
                     ["field 'K': stored twice"]),
    "bzip2": (lambda b: fz.pack(b.members, zipfile.ZIP_BZIP2), ["compression method 12"]),
    "encrypted": (lambda b: _patched(b, "M", "flags", 1), ["field 'M': zip entry is encrypted"]),
    "lying size": (lambda b: _patched(b, "Psi", "size", 2**31),
                   ["field 'Psi'", "more than the compression can produce"]),
    "bomb": (lambda b: fz._bomb(b, "T with 6e6 empty rows"), ["more than 64 times the file"]),
    "CRC": (lambda b: _patched(b, "Phi", "crc", 12345), ["field 'Phi'", "CRC"]),
    "shape lie": (lambda b: fz.pack(dict(b.members, K=fz.npy_raw(
        "<f8", False, (53, 53), fz.split_npy(b.members["K"])[3]))),
                  ["field 'K': npy header declares shape (53, 53)"]),
    "npy version 3": (lambda b: fz.pack(dict(b.members, M=fz.npy(b.arrays["M"], (3, 0)))),
                      ["field 'M': npy format 3.0"]),
    "not an npy member": (lambda b: fz.pack(dict(b.members, Phi=b"PK not npy")),
                          ["field 'Phi'", "magic string"]),
}


@pytest.mark.parametrize("case", list(CONTAINER))
def test_damaged_container_is_rejected(tmp_path, base, case):
    make, fields = CONTAINER[case]
    rejected(_write(tmp_path, make(base)), *fields)


def test_missing_file_and_folder(tmp_path):
    with pytest.raises(FileNotFoundError):
        Superelement.load(tmp_path / "missing.npz")
    (tmp_path / "folder.npz").mkdir()
    rejected(tmp_path / "folder.npz", "not a readable superelement file")


@pytest.mark.parametrize(("name", "dtype"), [
    ("K", "<f4"), ("M", ">f8"), ("Phi", "<c16"), ("interface_dofs", "|i1"),
    ("T_indices", ">i8"), ("T_data", "<f2"), ("free_interior", "<f8"), ("Psi", "object"),
    ("modal_omega2", "record"), ("meta", "|S8"), ("meta", ">U"),
])
@pytest.mark.parametrize("crafted", [False, True])
def test_wrong_dtype_is_rejected_before_reading(tmp_path, base, name, dtype, crafted):
    x = np.array(json.dumps(base.meta)) if name == "meta" else base.arrays[name]
    path = _write(tmp_path, fz.rebuild(base, crafted, arrays={
        name: fz._as_dtype(x, dtype, base.sentinel)}))
    rejected(path, f"field '{name}': dtype")


def test_pickled_objects_are_never_run(tmp_path, base):
    evil = fz._as_dtype(base.arrays["Psi"], "pickle", tmp_path / "EXECUTED")
    path = _write(tmp_path, fz.rebuild(base, True, arrays={"Psi": evil}))
    rejected(path, "field 'Psi': dtype", "never read")
    assert not (tmp_path / "EXECUTED").exists()


# --- meta -----------------------------------------------------------------------------

META = {
    "method 5": ({"method": 5}, "field 'meta.method'"),
    "method Guyan": ({"method": "Guyan"}, "field 'meta.method'"),
    "n_dof huge": ({"n_dof": 10**18}, "field 'meta.n_dof'"),
    "n_dof float": ({"n_dof": 120.0}, "field 'meta.n_dof'"),
    "n_dof bool": ({"n_dof": True}, "field 'meta.n_dof'"),
    "n_residual > n_q": ({"n_residual": 29}, "field 'meta.n_residual'"),
    "n_residual negative": ({"n_residual": -1}, "field 'meta.n_residual'"),
    "timings NaN": ({"timings": {"x": float("nan")}}, "field 'meta.timings.x'"),
    "timings text": ({"timings": {"x": "1 s"}}, "field 'meta.timings.x'"),
    "timings list": ({"timings": []}, "field 'meta.timings'"),
    "guyan with modes": ({"method": "guyan"}, "field 'modal_omega2'"),
    "extra key": ({"extra": 1}, "field 'meta.extra': unexpected key"),
    "sha256 short": ({"sha256": {"K": "00"}}, "field 'meta.sha256'"),
}


@pytest.mark.parametrize("case", list(META))
def test_bad_meta_is_rejected(tmp_path, base, case):
    change, field = META[case]
    rejected(_write(tmp_path, fz.rebuild(base, True, meta=dict(base.meta, **change))), field)


@pytest.mark.parametrize(("text", "problem"), [
    ("not json", "not JSON"), ("[1, 2]", "a JSON list"), ("[" * 60_000, "not JSON"),
    ('{"format_version": 2}', "field 'meta.method': missing"),
])
def test_unreadable_meta_is_rejected(tmp_path, base, text, problem):
    path = _write(tmp_path, fz.pack(dict(base.members, meta=fz.npy(np.array(text)))))
    rejected(path, "field 'meta", problem)


@pytest.mark.parametrize("code_point", [0x110000, 0xD800, 0xFFFFFFFF])
def test_meta_with_invalid_code_points(tmp_path, base, code_point):
    # found by the fuzz run (seed 1, file 11728): numpy makes a str that json cannot read
    text = fz.npy_raw("<U3", False, (), struct.pack("<3I", ord("{"), code_point, ord("}")))
    rejected(_write(tmp_path, fz.pack(dict(base.members, meta=text))), "field 'meta'",
             "not JSON text")


# --- checksums ------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["K", "Psi", "T_indices", "interface_points"])
def test_changed_data_fails_its_checksum(tmp_path, base, name):
    blob = base.members[name]
    start = len(blob) - len(fz.split_npy(blob)[3])
    flipped = blob[:start + 9] + bytes([blob[start + 9] ^ 1]) + blob[start + 10:]
    path = _write(tmp_path, fz.pack(dict(base.members, **{name: flipped})))
    rejected(path, f"field '{name}': SHA-256 checksum mismatch")


def test_changed_meta_fails_its_checksum(tmp_path, base):
    meta = dict(base.meta, timings=dict(base.meta["timings"], projection=1.0))
    rejected(_write(tmp_path, fz.rebuild(base, False, meta=meta)),
             "field 'meta': SHA-256 checksum mismatch")


# --- values of crafted files (checksums recomputed) -----------------------------------

def _values(base) -> dict:
    a, n_b = base.arrays, base.arrays["interface_dofs"].size
    lies = fz._index_lies(a)
    K, M = a["K"], a["M"]
    return {
        "T_indices = n_free": (lies["T_indices = n_free"], "field 'T_indices'"),
        "T_indices = -1": (lies["T_indices = -1"], "field 'T_indices'"),
        "T_indptr decreasing": (lies["T_indptr decreasing"], "field 'T_indptr'"),
        "T_indptr end": (lies["T_indptr[-1] = nnz + 1"], "field 'T_indptr'"),
        "T_shape": (lies["T_shape n_free + 1"], "field 'T_shape'"),
        "interface_dofs = n_dof": (lies["interface_dofs = n_dof"], "field 'interface_dofs'"),
        "interface_dofs = -1": (lies["interface_dofs = -1"], "field 'interface_dofs'"),
        "interface_dofs twice": (lies["interface_dofs duplicate"], "field 'interface_dofs'"),
        "interface_dofs not in T": (lies["interface_dofs a supported DOF"],
                                    "field 'interface_dofs': node 2 ux (DOF 12) is not free"),
        "free_interface = n_free": (lies["free_interface = n_free"], "field 'free_interface'"),
        "free sets overlap": (lies["free_interior overlaps"], "field 'free_interior'"),
        "points of a node differ": ({"interface_points": fz._edit(
            a["interface_points"], (1, 2), 9.0)}, "field 'interface_points'"),
        "NaN in Psi": ({"Psi": fz._edit(a["Psi"], (3, 4), np.nan)}, "field 'Psi': not finite"),
        "inf in T_data": ({"T_data": fz._edit(a["T_data"], 2, np.inf)}, "field 'T_data'"),
        "Psi rows": ({"Psi": a["Psi"][:-1]}, "field 'Psi': shape"),
        "K unsymmetric": ({"K": fz._edit(K, (0, 1), K[0, 1] * (1 + 1e-9))},
                          "field 'K': not symmetric"),
        "K coupling": ({"K": fz._edit(fz._edit(K, (0, n_b), 1.0), (n_b, 0), 1.0)},
                       "field 'K': interface-modal coupling"),
        "K modal block": ({"K": fz._edit(K, (n_b, n_b), 2 * K[n_b, n_b])},
                          "field 'K': modal block"),
        "K indefinite": ({"K": fz._edit(K, np.s_[:n_b, :n_b], -K[:n_b, :n_b])},
                         "field 'K': not positive semidefinite"),
        "M indefinite": ({"M": fz._edit(M, (0, 0), -M[0, 0])},
                         "field 'M': not positive definite"),
        "K and M swapped": ({"K": M, "M": K}, "field 'K'"),
    }


def test_crafted_values_are_rejected(tmp_path, base):
    for case, (arrays, field) in _values(base).items():
        path = _write(tmp_path, fz.rebuild(base, True, arrays=arrays))
        message = rejected(path, field)
        assert "SHA-256" not in message, case


def test_tolerances_separate_round_off_from_damage(tmp_path, base):
    """An asymmetry at the level of SYMMETRY_RTOL / 10 and a rigid-body eigenvalue of
    -PSD_RTOL / 10 (relative) pass: both are round-off of a valid reduction."""
    K, n_b = base.arrays["K"], base.arrays["interface_dofs"].size
    scale = np.abs(K).max()
    near = fz._edit(K, (0, 1), K[0, 1] + 0.1 * SYMMETRY_RTOL * scale)
    se = Superelement.load(_write(tmp_path, fz.rebuild(base, True, arrays={"K": near})))
    assert se.K[0, 1] != K[0, 1]
    w, V = np.linalg.eigh(K[:n_b, :n_b])
    w[0] = -0.1 * PSD_RTOL * max(np.abs(w).max(), base.arrays["modal_omega2"].max())
    Kb = fz._edit(K, np.s_[:n_b, :n_b], (V * w) @ V.T)
    Kb[:n_b, :n_b] = 0.5 * (Kb[:n_b, :n_b] + Kb[:n_b, :n_b].T)
    Superelement.load(_write(tmp_path, fz.rebuild(base, True, arrays={"K": Kb})))


def test_load_errors_are_value_errors_for_the_cache(tmp_path, base):
    # femmech.scene.cache treats any ValueError of Superelement.load as a corrupt entry
    path = _write(tmp_path, base.data[:100])
    with pytest.raises(ValueError, match="not a readable superelement file"):
        Superelement.load(path)


# --- fuzzing --------------------------------------------------------------------------

def test_worker_detects_crashes_and_hangs(tmp_path):
    _, original = fz.make_base(tmp_path)
    worker = fz.Worker(original, timeout=1.0)
    try:
        assert worker.run({"selftest": "crash"})["outcome"] == "crash"
        assert worker.run({"selftest": "hang"})["outcome"] == "hang"
        task = {"path": str(original), "crafted": False, "missing": False}
        assert worker.run(task)["outcome"] == "harmless"  # replaced worker works
    finally:
        worker.close()


def test_short_fuzz_run_has_no_failures():
    n = 8 * len(fz.CLASSES)  # 8 files per class, about 1 s with two workers
    results = fz.fuzz(n, seed=19, workers=2)
    outcomes = {r["outcome"] for r in results}
    failures = [r for r in results if r["outcome"] in fz.FAILURES]
    assert not failures, fz.table(results)
    assert len(results) == n
    assert {"rejected", "harmless", "different"} <= outcomes
    assert {r["class"] for r in results} == set(fz.CLASSES)
