"""Scene fuzzing: mutated example scenes through ``femmech check`` and ``run``.

Every shipped scene ``examples/*.toml`` is mutated, schema-level (nearby values, values of
the right and wrong types, boundary numbers, huge counts, deleted, misspelt and extra keys,
deep nesting, duplicated entries) and byte-level (bit flips, truncation, inserted, deleted
and duplicated bytes and lines, a byte-order mark, CRLF, other encodings, a damaged mesh
file). Each
mutated scene is checked by ``femmech check`` (``femmech.cli.main``) in one of two worker
processes, each scene under a wall-time limit and a memory limit; the outcome comes from
the exit code and stderr:

- ``valid``: exit 0;
- ``clean``: exit 3 (input error) with one line on stderr, ``error: <scene file>: ...``;
- ``internal``: exit 1 (an unexpected exception: a bug), or any other exit code, or an
  error message that is not one line naming the file;
- ``crash``: the worker process died (interpreter crash, memory limit);
- ``hang``: the time limit passed (the worker is killed and replaced).

A sample of the valid mutated scenes is then run (``femmech run``, also time-limited) to
catch tracebacks and hangs in the computing stages. Failing scenes are kept in
``benchmarks/results/fuzz/`` (git-ignored). Scene ``i`` of a run depends only on
``(seed, i)``, so ``--only i`` reproduces it::

    python benchmarks/fuzz_scenes.py                    # 2000 scenes, seed 0, 50 runs
    python benchmarks/fuzz_scenes.py --n 200 --runs 0   # quick
    python benchmarks/fuzz_scenes.py --only 123 --keep  # one scene, kept for reading
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import math
import multiprocessing as mp
import random
import resource
import shutil
import sys
import tempfile
import time
import tomllib
from collections import Counter, defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
RESULTS = ROOT / "benchmarks" / "results" / "fuzz"

SCHEMA = ("perturb", "value", "type", "scale", "delete", "extra_key", "misspell", "nest",
          "duplicate")
BYTES = ("bit_flip", "truncate", "insert", "delete_bytes", "duplicate_bytes", "lines",
         "encoding", "mesh_file")
CLASSES = SCHEMA + BYTES
OUTCOMES = ("valid", "clean", "internal", "crash", "hang")
MEMORY_LIMIT = 3 * 2**30
"""Address-space limit of a ``check`` worker, bytes: an absurd allocation fails instead of
swapping."""
RUN_MEMORY_LIMIT = 12 * 2**30
"""Address-space limit of a ``run`` worker, bytes (VTK's off-screen rendering reserves
several GiB of address space it never touches)."""

# --- TOML text from a dict (the scene schema has no dates; floats may be nan or inf) -----

_BARE = set("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-")


def toml_key(key: str) -> str:
    """A key, bare when it can be, else a basic string."""
    return key if key and set(key) <= _BARE else toml_string(key)


def toml_string(text: str) -> str:
    """A TOML basic string (JSON escapes are valid TOML escapes, lone surrogates aside)."""
    return json.dumps(text, ensure_ascii=True)


def toml_value(value) -> str:
    """An inline TOML value (tables inline, so any nesting fits on one line)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, Nested):
        return str(value)
    if isinstance(value, str):
        return toml_string(value)
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{toml_key(k)} = {toml_value(v)}"
                               for k, v in value.items()) + "}"
    return toml_string(str(value))


def to_toml(data: dict) -> str:
    """TOML text of a scene dict: one ``key = inline value`` line per top-level key."""
    return "".join(f"{toml_key(k)} = {toml_value(v)}\n" for k, v in data.items())


# --- schema-level mutations ----------------------------------------------------------------

def paths(data, path=()):
    """Key paths of every value of a nested dict/list structure."""
    items = data.items() if isinstance(data, dict) else enumerate(data)
    for key, value in items:
        yield path + (key,)
        if isinstance(value, (dict, list)):
            yield from paths(value, path + (key,))


def _parent(data, path):
    for key in path[:-1]:
        data = data[key]
    return data


class Nested(str):
    """TOML text of a value nested many levels deep (written as is by :func:`toml_value`,
    which would otherwise recurse once per level)."""


def nested(depth: int, rng: random.Random) -> Nested:
    """A list or inline table nested ``depth`` levels deep, as TOML text."""
    opening = [rng.choice(["[", "{a = "]) for _ in range(depth)]
    closing = ["]" if o == "[" else "}" for o in reversed(opening)]
    return Nested("".join(opening) + rng.choice(["1", '"x"', "[]"]) + "".join(closing))


def boundary(value, rng: random.Random):
    """A boundary value of the same family as ``value``."""
    if isinstance(value, bool):
        return not value
    if isinstance(value, (int, float)):
        return rng.choice([0, -1, 1, 2, -0.0, 1e-300, 1e300, -1e300, 10**30, -10**30, 2**63,
                           2**64, 10**400, float("nan"), float("inf"), float("-inf"),
                           10**9, 10**6, 0.5, value * -1, value * 1e30])
    if isinstance(value, str):
        number = value.split(" ")[0]
        unit = value.partition(" ")[2]
        return rng.choice(["", " ", "0", f"-{number} {unit}", f"0 {unit}", f"1e999 {unit}",
                           f"1e-999 {unit}", f"nan {unit}", f"inf {unit}", f"{number} {unit}^99",
                           f"{number} m^9999999999", f"{number} {unit}/0", "x" * 20_000,
                           "é∂ƒ©" * 3, value + "\n", value.upper(), value[::-1],
                           f"{number} {unit}" + " " * 5000 + "x", "1" * 5000 + " m"])
    if isinstance(value, list):
        return rng.choice([[], value * 50, value[:1], value + value[-1:], [value], value[::-1],
                           list(range(-3, 3)), [10**30], value * 1000])
    return rng.choice([{}, {"": 1}, {"kind": "x"}, {"a": {"b": {"c": 1}}}])


def _plausible(value, rng: random.Random):
    """A nearby value of a number, a number with a unit or a flag (None: not such)."""
    factor = rng.choice([0.01, 0.1, 0.5, 0.9, 1.1, 2, 10, 100])
    if isinstance(value, bool):
        return not value
    if isinstance(value, int):
        return max(0, value + rng.choice([-2, -1, 1, 2, value]))
    if isinstance(value, float):
        return value * factor
    if isinstance(value, str):
        number, _, unit = value.partition(" ")
        try:
            return f"{float(number) * factor:g} {unit}".strip()
        except ValueError:
            return None
    return None


def junk(rng: random.Random):
    """A value of some type."""
    return rng.choice([None, True, False, 0, -1, 3, 10**18, 10**30, 2.5, float("nan"),
                       float("inf"), "", "x", "3 kg", "1 GPa", "90 deg", "top", "base",
                       "all", "craig_bampton", "ü\u2028", [], [1, 2, 3], ["a", "b"],
                       [[1], [2]], {}, {"x": 1}, {"kind": "members"}, [{"nodes": 0}]])


_COUNT_KEYS = ("n", "n_modes", "n_steps", "max_steps", "divisions", "subdivisions", "images",
               "bays", "branch")


def mutate_schema(data: dict, kind: str, rng: random.Random) -> dict:
    """One schema-level mutation of ``kind`` (see :data:`SCHEMA`) of a scene dict."""
    all_paths = list(paths(data))
    path = rng.choice(all_paths)
    parent, last = _parent(data, path), path[-1]
    if kind == "perturb":
        numbers = [p for p in all_paths if _plausible(_value(data, p), rng) is not None]
        path = rng.choice(numbers or all_paths)
        parent, last = _parent(data, path), path[-1]
        new = _plausible(parent[last], rng)
        parent[last] = parent[last] if new is None else new
    elif kind == "value":
        parent[last] = boundary(parent[last], rng)
    elif kind == "type":
        value = junk(rng)
        if value is None:
            del parent[last]
        else:
            parent[last] = value
    elif kind == "scale":
        counts = [p for p in all_paths if p[-1] in _COUNT_KEYS or (
            len(p) > 1 and p[-2] in _COUNT_KEYS)]
        path = rng.choice(counts or all_paths)
        parent, last = _parent(data, path), path[-1]
        value = parent[last]
        big = rng.choice([10**3, 10**4, 10**5, 10**6, 10**9, 10**12, 10**18, 10**30, 2**31,
                          2**63 - 1])
        parent[last] = big if not isinstance(value, list) else [big] * max(1, len(value))
    elif kind == "delete":
        del parent[last]
    elif kind in ("extra_key", "misspell"):
        tables = [p for p in all_paths if isinstance(_parent(data, p), dict)]
        path = rng.choice(tables)
        parent, last = _parent(data, path), path[-1]
        if kind == "extra_key":
            parent[rng.choice(["unexpected", "colour", "n_mode", "material_", "E2", "x"])] = \
                junk(rng) or 1
        else:
            name = str(last)
            i = rng.randrange(len(name))
            new = rng.choice([name[:i] + name[i + 1:], name[:i] + "x" + name[i:],
                              name[:i] + name[i:][::-1][:1] + name[i + 1:], name + "s",
                              name.upper()])
            parent[new or "_"] = parent.pop(last)
    elif kind == "nest":
        parent[last] = nested(rng.choice([3, 10, 40, 200, 2000, 20000]), rng)
    elif kind == "duplicate":
        lists = [p for p in all_paths if isinstance(_value(data, p), list) and _value(data, p)]
        if lists:
            path = rng.choice(lists)
            value = _value(data, path)
            times = rng.choice([2, 10, 1000, 30_000])
            _parent(data, path)[path[-1]] = value * max(1, min(times, 200_000 // len(value)))
        else:
            parent[last] = [parent[last]] * 100
    return data


def _value(data, path):
    return _parent(data, path)[path[-1]]


# --- byte-level mutations --------------------------------------------------------------

_TOKENS = [b"[", b"]", b"[[", b"]]", b"{", b"}", b"=", b'"', b"'", b'"""', b"'''", b"\n",
           b"#", b",", b".", b"-", b"1e999", b"nan", b"inf", b"0x", b"9" * 30, b"\\u0000",
           b"\x00", b"\xff", b"\xc3", b"\xef\xbb\xbf", b"\r", b"\t", b"true", b"a.b.c = 1\n"]


def mutate_bytes(text: bytes, kind: str, rng: random.Random) -> bytes:
    """One byte-level mutation of ``kind`` (see :data:`BYTES`) of a scene's bytes."""
    data = bytearray(text)
    n = len(data)
    if kind == "bit_flip":
        for _ in range(rng.choice([1, 2, 4, 8, 32])):
            i = rng.randrange(n)
            data[i] ^= 1 << rng.randrange(8)
    elif kind == "truncate":
        del data[rng.randrange(n):]
    elif kind == "insert":
        for _ in range(rng.choice([1, 2, 5])):
            i = rng.randrange(n + 1)
            piece = rng.choice(_TOKENS) if rng.random() < 0.7 else rng.randbytes(
                rng.randrange(1, 16))
            data[i:i] = piece
    elif kind == "delete_bytes":
        i = rng.randrange(n)
        del data[i:i + rng.choice([1, 2, 10, 100, 1000])]
    elif kind == "duplicate_bytes":
        i = rng.randrange(n)
        span = bytes(data[i:i + rng.choice([1, 10, 100, 1000])])
        j = rng.randrange(n + 1)
        data[j:j] = span * rng.choice([1, 2, 100])
    elif kind == "lines":
        lines = bytes(data).split(b"\n")
        i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
        how = rng.choice(["swap", "delete", "duplicate", "shuffle", "reverse"])
        if how == "swap":
            lines[i], lines[j] = lines[j], lines[i]
        elif how == "delete":
            del lines[i]
        elif how == "duplicate":
            lines.insert(j, lines[i])
        elif how == "shuffle":
            rng.shuffle(lines)
        else:
            lines.reverse()
        data = bytearray(b"\n".join(lines))
    elif kind == "encoding":
        source = bytes(data).decode("utf-8")
        how = rng.choice(["bom", "crlf", "bom_crlf", "utf16", "latin1", "cr", "nul"])
        if how in ("bom", "bom_crlf"):
            source = "\ufeff" + source
        if how in ("crlf", "bom_crlf"):
            source = source.replace("\n", "\r\n")
        encoded = {"utf16": "utf-16", "latin1": "latin-1"}.get(how, "utf-8")
        if how == "cr":
            source = source.replace("\n", "\r")
        if how == "nul":
            source = source.replace("\n", "\n\x00", 1)
        data = bytearray(source.encode(encoded, errors="replace"))
    return bytes(data)


# --- making the scene files ------------------------------------------------------------

def workspace(folder: Path) -> Path:
    """A folder laid out like the repository for the scenes' relative paths: ``meshes``
    (a link to the repository's) and ``examples`` with copies of the example modules."""
    (folder / "examples").mkdir(parents=True, exist_ok=True)
    link = folder / "meshes"
    if not link.exists():
        link.symlink_to(ROOT / "meshes", target_is_directory=True)
    for module in EXAMPLES.glob("*.py"):
        shutil.copy(module, folder / "examples" / module.name)
    return folder / "examples"


def make_scene(i: int, seed: int, folder: Path) -> tuple[str, Path]:
    """Mutated scene ``i`` of a run: (mutation class, path of the file written)."""
    rng = random.Random(f"{seed}-{i}")
    bases = sorted(EXAMPLES.glob("*.toml"))
    base = bases[i % len(bases)]
    kind = CLASSES[(i // len(bases)) % len(CLASSES)]
    text = base.read_bytes()
    name = f"fuzz_{i:05d}_{base.stem}_{kind}.toml"
    path = folder / name
    if kind in SCHEMA:
        data = tomllib.loads(text.decode("utf-8"))
        for _ in range(1 if kind in ("duplicate", "nest") else rng.choice([1, 1, 1, 2, 3])):
            data = mutate_schema(data, kind, rng)
        text = to_toml(data).encode("utf-8", errors="surrogatepass")
    elif kind == "mesh_file":
        text = _mutate_mesh(text, name, rng, folder)
    else:
        text = mutate_bytes(text, kind, rng)
    path.write_bytes(text)
    return kind, path


def _mutate_mesh(text: bytes, name: str, rng: random.Random, folder: Path) -> bytes:
    """A scene whose mesh (or the first mesh of the examples) is a damaged copy."""
    data = tomllib.loads(text.decode("utf-8"))
    part = next(iter(data.get("parts", {}).values()), None)
    source = ROOT / "meshes" / rng.choice(["machine_frame.msh", "welded_box_frame.msh",
                                           "c_frame_press.msh"])
    if part is None or "mesh" not in part:
        return mutate_bytes(text, "bit_flip", rng)
    original = (folder / part["mesh"]).resolve()
    source = original if original.is_file() else source
    mesh = bytearray(source.read_bytes())
    how = rng.choice(["flip", "digits", "truncate", "negative", "huge", "empty"])
    if how == "flip":
        for _ in range(rng.choice([1, 8, 64])):
            k = rng.randrange(len(mesh))
            mesh[k] ^= 1 << rng.randrange(8)
    elif how in ("digits", "negative", "huge"):
        piece = {"digits": b"7", "negative": b"-", "huge": b"99999999999"}[how]
        for _ in range(rng.choice([1, 5, 50])):
            k = rng.randrange(len(mesh))
            if chr(mesh[k]).isdigit():
                mesh[k:k + 1] = piece
    elif how == "truncate":
        del mesh[rng.randrange(len(mesh)):]
    else:
        mesh = bytearray()
    mesh_name = name.replace(".toml", source.suffix)
    (folder / mesh_name).write_bytes(bytes(mesh))
    part["mesh"] = mesh_name
    return to_toml(data).encode("utf-8")


# --- workers ---------------------------------------------------------------------------

def _worker(conn, memory: int) -> None:
    """Runs ``femmech.cli.main(argv)`` per request; replies (exit code, stdout, stderr)."""
    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    import warnings

    from femmech.cli import main

    warnings.simplefilter("ignore")
    while True:
        argv = conn.recv()
        out, err = io.StringIO(), io.StringIO()
        try:
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                code = main(argv)
        except BaseException as exc:  # noqa: BLE001 - whatever escapes main is a bug
            code = f"escaped {type(exc).__name__}: {exc}"[:300]
        conn.send((code, out.getvalue()[-2000:], err.getvalue()[-200_000:]))


class Pool:
    """Worker processes, each running one command at a time under a time limit."""

    def __init__(self, n: int, memory: int):
        self.ctx = mp.get_context("fork")
        self.memory = memory
        self.workers = [self._start() for _ in range(n)]

    def _start(self):
        parent, child = self.ctx.Pipe()
        process = self.ctx.Process(target=_worker, args=(child, self.memory), daemon=True)
        process.start()
        return [process, parent, None, 0.0]

    def run(self, jobs, timeout: float, echo=None):
        """Run ``jobs`` (key, argv) → {key: (code or 'hang'/'crash', stdout, stderr, s)}."""
        jobs, results = list(jobs), {}
        while jobs or any(w[2] is not None for w in self.workers):
            for k, w in enumerate(self.workers):
                if w[2] is None and jobs:
                    key, argv = jobs.pop(0)
                    try:
                        w[1].send(argv)
                    except OSError:  # the worker died after its last job: replace it
                        w[0].kill()
                        w[0].join()
                        w = self.workers[k] = self._start()
                        w[1].send(argv)
                    w[2], w[3] = (key, argv), time.perf_counter()
            for k, w in enumerate(self.workers):
                if w[2] is None:
                    continue
                elapsed = time.perf_counter() - w[3]
                if w[1].poll(0.01):
                    try:
                        code, out, err = w[1].recv()
                    except (EOFError, OSError):
                        code, out, err = "crash", "", "worker died"
                    results[w[2][0]] = (code, out, err, elapsed)
                    w[2] = None
                elif not w[0].is_alive() or elapsed > timeout:
                    code = "hang" if w[0].is_alive() else f"crash (exit {w[0].exitcode})"
                    w[0].kill()
                    w[0].join()
                    results[w[2][0]] = (code, "", "", elapsed)
                    self.workers[k] = self._start()
                else:
                    continue
                if echo is not None:
                    echo(w[2] and w[2][0] or None)
        return results

    def close(self) -> None:
        for w in self.workers:
            w[0].kill()
            w[0].join()


def outcome(code, err: str, name: str) -> str:
    """Class of a check's result (see :data:`OUTCOMES`)."""
    if code == "hang":
        return "hang"
    if isinstance(code, str):
        return "crash" if code.startswith("crash") else "internal"
    lines = err.strip().splitlines()
    if code == 0:
        return "valid"
    one_line = len(lines) == 1 and lines[0].startswith(f"error: {name}: ")
    return "clean" if code == 3 and one_line else "internal"


# --- the run ---------------------------------------------------------------------------

def main(argv=None) -> dict:
    """Run the fuzzer; print the table per mutation class; return the counts."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, default=2000, help="scenes to check (2000)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--runs", type=int, default=50, help="valid scenes also run (50)")
    parser.add_argument("--timeout", type=float, default=20.0, help="s per check (20)")
    parser.add_argument("--run-timeout", type=float, default=120.0, help="s per run (120)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--only", type=int, default=None, help="check only scene ONLY")
    parser.add_argument("--keep", action="store_true", help="keep every scene file")
    parser.add_argument("--debug", action="store_true", help="tracebacks of internal errors")
    args = parser.parse_args(argv)
    indices = [args.only] if args.only is not None else list(range(args.n))
    RESULTS.mkdir(parents=True, exist_ok=True)
    pool = Pool(args.workers, MEMORY_LIMIT)
    counts = defaultdict(Counter)
    failures = []
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        folder = workspace(Path(tmp))
        scenes = {i: make_scene(i, args.seed, folder) for i in indices}
        debug = ["--debug"] if args.debug else []
        jobs = [(i, ["check", str(path), *debug]) for i, (_, path) in scenes.items()]
        results = pool.run(jobs, args.timeout)
        valid = []
        for i in indices:
            kind, path = scenes[i]
            code, out, err, seconds = results[i]
            result = outcome(code, err, path.name)
            counts[kind]["tries"] += 1
            counts[kind][result] += 1
            if result == "valid" and small(path, base_of(i)):
                valid.append((seconds, i))
            if result in ("internal", "crash", "hang") or args.keep:
                shutil.copy(path, RESULTS / path.name)
            if result in ("internal", "crash", "hang"):
                failures.append((i, kind, result, code, err.strip()[-600:]))
        step = max(1, len(valid) // max(1, args.runs))  # spread over bases and classes
        sample = sorted(i for _, i in valid)[::step][:args.runs]
        pool.close()
        pool = Pool(args.workers, RUN_MEMORY_LIMIT)
        run_counts = _run_sample(pool, scenes, sample, args, Path(tmp), failures)
        run_counts["small"] = len(valid)
        pool.close()
    _report(counts, run_counts, failures, args, time.perf_counter() - start)
    return {"check": {k: dict(v) for k, v in counts.items()}, "run": dict(run_counts),
            "failures": len(failures)}


def base_of(i: int) -> Path:
    """The example scene that scene ``i`` is mutated from."""
    bases = sorted(EXAMPLES.glob("*.toml"))
    return bases[i % len(bases)]


def _sizes(data) -> dict:
    """{key path: integer value or list length} of a scene (iteratively)."""
    out, stack = {}, [((), data)]
    while stack:
        path, value = stack.pop()
        if isinstance(value, dict):
            stack.extend((path + (k,), v) for k, v in value.items())
        elif isinstance(value, list):
            out[path + ("len",)] = len(value)
            stack.extend((path + (k,), v) for k, v in enumerate(value))
        elif isinstance(value, int) and not isinstance(value, bool):
            out[path] = abs(value)
    return out


def small(path: Path, base: Path) -> bool:
    """Whether a valid mutated scene asks for at most about twice the work of its base:
    no integer and no list length above twice the base's at the same key path (or above
    the base's largest, at a new path). Such a scene should run about as fast as the
    example, so a run past the time limit is a hang, not a big job."""
    try:
        sizes = _sizes(tomllib.loads(path.read_bytes().decode("utf-8-sig")))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError):
        return False
    reference = _sizes(tomllib.loads(base.read_text()))
    largest = max(reference.values())
    return all(v <= 2 * reference.get(k, largest) for k, v in sizes.items())


def _run_sample(pool, scenes, sample, args, tmp: Path, failures) -> Counter:
    """``femmech run`` of the fastest valid mutated scenes (time-limited)."""
    jobs = [(i, ["run", str(scenes[i][1]), "--out", str(tmp / f"out_{i}"), "--no-cache",
                 "--quiet", "--allow-code"]) for i in sample]
    counts = Counter()
    for i, (code, _, err, seconds) in pool.run(jobs, args.run_timeout).items():
        name = scenes[i][1].name
        if code == 4 and len(err.strip().splitlines()) == 1:
            result = "numerical"  # a clean one-line numerical failure
        else:
            result = outcome(code, err, name)
        counts["tries"] += 1
        counts[result] += 1
        counts["seconds"] += seconds
        if result in ("internal", "crash", "hang"):
            shutil.copy(scenes[i][1], RESULTS / name)
            failures.append((i, f"run {scenes[i][0]}", result, code, err.strip()[-600:]))
        elif result in ("clean", "numerical"):  # check passed, run refused: a check gap?
            counts["gaps"] = counts.get("gaps", ()) + ((i, err.strip()[:300]),)
    return counts


def _report(counts, run_counts, failures, args, seconds: float) -> None:
    header = ("| mutation | tries | valid | clean one-line error | internal error / traceback"
              " | crash | hang |")
    print(header)
    print("|---|---:|---:|---:|---:|---:|---:|")
    total = Counter()
    for kind in CLASSES:
        c = counts.get(kind)
        if not c:
            continue
        total.update(c)
        print(f"| {kind} | {c['tries']} | {c['valid']} | {c['clean']} | {c['internal']} |"
              f" {c['crash']} | {c['hang']} |")
    print(f"| **all** | {total['tries']} | {total['valid']} | {total['clean']} |"
          f" {total['internal']} | {total['crash']} | {total['hang']} |")
    if run_counts["tries"]:
        print(f"\n`femmech run` of {run_counts['tries']} of the {run_counts['small']} valid"
              " mutated scenes that ask for at most twice the work of their example: "
              f"{run_counts['valid']} ok, {run_counts['clean']} clean input errors,"
              f" {run_counts['numerical']} clean numerical failures, {run_counts['internal']}"
              f" internal errors, {run_counts['crash']} crashes, {run_counts['hang']} hangs"
              f" ({run_counts['seconds']:.0f} s of runs, limit {args.run_timeout:g} s each)")
        for i, message in run_counts.get("gaps", ()):
            print(f"  scene {i}: valid for check, refused by run: {message}")
    print(f"\n{seconds:.0f} s wall, {args.workers} workers, check limit {args.timeout:g} s,"
          f" address-space limit {MEMORY_LIMIT // 2**30} GiB per check worker,"
          f" {RUN_MEMORY_LIMIT // 2**30} GiB per run worker")
    print(f"reproduce: python benchmarks/fuzz_scenes.py --n {args.n} --seed {args.seed}"
          f" --runs {args.runs}")
    for i, kind, result, code, err in failures:
        print(f"\nscene {i} ({kind}): {result} (exit {code}); --only {i} --seed {args.seed};"
              f" file {RESULTS.relative_to(ROOT)}/\n  {err}")


if __name__ == "__main__":
    summary = main()
    sys.exit(1 if summary["failures"] else 0)
