"""Command line: ``femmech run SCENE --out DIR``, ``femmech check SCENE`` and
``femmech cache info|clear [--cache-dir DIR]``.

Exit codes (:data:`EXIT_CODES`):

====  ===================================================================================
0     success (``check``: the scene is valid)
1     internal error: an unexpected exception, i.e. a bug in femmech (one line; the
      traceback with ``--debug``)
2     usage error: the command line is invalid (argparse)
3     input error: a scene, mesh, superelement or cache file is invalid or missing (a
      path that does not exist, or a folder where a file belongs or the reverse), or the
      scene's Python code was refused or failed (one line naming the file and the item)
4     numerical failure: a computation on valid input failed (naming the analysis)
5     file-system error: an existing file or folder could not be read or written
      (permission denied, disk full)
130   interrupted (Ctrl-C)
====  ===================================================================================

Errors are one line on stderr, no traceback unless ``--debug``. Suspicious inputs
(nearly coincident nodes, loose parts, unit mix-ups: :mod:`femmech.fe.checks`; what a mesh
file holds that the model will not have: :func:`femmech.fe.mesh_io.read_mesh`) are reported,
not refused: one ``warning:`` line each on stdout and in the run's log.

Scene files are data: ``run`` executes Python code a scene names (``module =``) only with
``--allow-code``, and only from the scene's folder (or ``--code-root``); ``check`` never
runs it.

Stage 9 (cli): uses scene, errors and version; only :mod:`femmech.__main__` imports it.
"""

from __future__ import annotations

import argparse
import logging
import sys
import traceback
import warnings
from contextlib import contextmanager
from pathlib import Path

from femmech.errors import InputError, ModelWarning, NumericalError

OK, INTERNAL, USAGE, INPUT, NUMERICAL, FILESYSTEM, INTERRUPTED = 0, 1, 2, 3, 4, 5, 130
EXIT_CODES = {OK: "success", INTERNAL: "internal error (a bug: rerun with --debug, report it)",
              USAGE: "usage error (command line)", INPUT: "input error (scene, mesh, file,"
              " scene code)", NUMERICAL: "numerical failure", FILESYSTEM: "file-system error",
              INTERRUPTED: "interrupted"}
"""Exit code → meaning."""


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="femmech", description="Machines described in scene files (TOML): compute the"
        " requested analyses with cached reductions and write an HTML report.",
        epilog="exit codes: " + "; ".join(f"{k} {v}" for k, v in EXIT_CODES.items()))
    parser.add_argument("--debug", action="store_true", help="show the traceback of an error")
    parser.add_argument("--version", action="version", version=f"femmech {_version()}")
    # options every command takes (--debug also after the command: SUPPRESS keeps the
    # top-level value when it is not given there)
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                        help="show the traceback of an error")
    code_root = argparse.ArgumentParser(add_help=False)
    code_root.add_argument("--code-root", type=Path, default=None, help="folder the scene's"
                           " Python modules may lie in (default: the scene's folder)")
    cache_dir = argparse.ArgumentParser(add_help=False)
    cache_dir.add_argument("--cache-dir", type=Path, default=None,
                           help="reduction cache folder (default: $FEMMECH_CACHE_DIR, else"
                           " ~/.cache/femmech)")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="compute a scene and write its report",
                         parents=[common, code_root, cache_dir])
    run.add_argument("scene", type=Path, help="scene file (.toml)")
    run.add_argument("--out", type=Path, required=True, help="output folder (created; an"
                     " existing one must be empty or hold an earlier run, which is replaced)")
    run.add_argument("--no-cache", action="store_true", help="do not read or write the"
                     " reduction cache")
    run.add_argument("--allow-code", action="store_true", help="run the Python modules the"
                     " scene names (module = ...); only for scenes from authors you trust")
    run.add_argument("-q", "--quiet", action="store_true", help="only warnings and the"
                     " report's path; no progress bars")
    run.add_argument("-v", "--verbose", action="store_true", help="also debug messages of"
                     " the library (logger 'femmech')")
    check = sub.add_parser("check", help="validate a scene without computing (never runs"
                           " the scene's Python code)", parents=[common, code_root])
    check.add_argument("scene", type=Path, help="scene file (.toml)")
    cache = sub.add_parser("cache", help="show or empty the reduction cache",
                           parents=[common, cache_dir])
    cache.add_argument("action", choices=("info", "clear"), help="info: entries, size, limit"
                       " and last use; clear: remove femmech's entries (other files stay)")
    return parser


def _version() -> str:
    from femmech.version import __version__
    return __version__


def _check(args) -> int:
    from femmech.scene.build import finding_lines, prepare
    from femmech.scene.load import load_scene

    path = args.scene
    with warnings.catch_warnings(record=True) as caught:  # read_mesh: what a file loses
        warnings.simplefilter("always", ModelWarning)
        prepared = prepare(load_scene(path), code_root=args.code_root, run_code=False)
    scene = prepared.scene
    parts = ", ".join(f"{n} ({m.n_nodes} nodes)" for n, m in prepared.meshes.items())
    analyses = list(scene.analyses.requested())  # every kind a run executes, in run order
    print(f"{path.name}: OK: parts {parts or '-'}; mechanisms {list(scene.mechanisms) or '-'};"
          f" mounts {len(scene.mounts)}; analyses {analyses}")
    for name in prepared.unexecuted:
        spec = scene.mechanisms[name]
        print(f"{path.name}: note: [{spec.where}] module {Path(spec.module).name}: user code,"
              " not executed (check never runs it; its coordinate names are unchecked;"
              " 'femmech run --allow-code' runs it)")
    for w in caught:
        if issubclass(w.category, ModelWarning):
            print(f"{path.name}: warning: {_one_line(w.message)}")
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    for line in finding_lines(prepared):  # suspicious inputs: reported, not refused
        print(f"{path.name}: {line}")
    return OK


def _run(args) -> int:
    from femmech.scene.cache_folder import default_cache_dir
    from femmech.scene.run import run_scene

    cache = None if args.no_cache else (args.cache_dir or default_cache_dir())
    bars = not args.quiet and sys.stderr.isatty()
    level = logging.WARNING if args.quiet else logging.DEBUG if args.verbose else logging.INFO
    with _logging_to_stdout(level):
        result = run_scene(args.scene, args.out, cache_dir=cache, bars=bars,
                           allow_code=args.allow_code, code_root=args.code_root)
    if args.quiet:
        print(result.report)
    return OK


@contextmanager
def _logging_to_stdout(level: int):
    """The messages of the ``femmech`` loggers at ``level`` and above, one per line on
    stdout, while the block runs (library code logs; only the command line prints)."""
    handler = logging.StreamHandler(sys.stdout)
    handler.setFormatter(logging.Formatter("%(message)s"))
    logger = logging.getLogger("femmech")
    old_level = logger.level
    logger.addHandler(handler)
    logger.setLevel(level)
    try:
        yield
    finally:
        logger.removeHandler(handler)
        logger.setLevel(old_level)


def _cache(args) -> int:
    from femmech.scene.cache_folder import (
        cache_info,
        clear_cache,
        default_cache_dir,
        format_cache_info,
    )

    folder = args.cache_dir or default_cache_dir()
    if args.action == "clear":
        print(f"removed {clear_cache(folder)} files from {folder}")
    else:
        print(format_cache_info(cache_info(folder)))
    return OK


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split("\n")).strip() or type(exc).__name__


def main(argv=None) -> int:
    """Entry point of the ``femmech`` command; returns the exit code (:data:`EXIT_CODES`)."""
    args = _parser().parse_args(argv)
    command = {"check": _check, "run": _run, "cache": _cache}[args.command]
    try:
        return command(args)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return INTERRUPTED
    except Exception as exc:  # noqa: BLE001 - every error ends as one line and a code
        code = exit_code(exc)
        if args.debug:
            traceback.print_exc()
        name = args.scene.name if args.command != "cache" else "cache"
        if code == INPUT:
            text = _one_line(exc)
            named = text.startswith((name, str(getattr(args, "scene", name))))
            message = f"error: {text}" if named else f"error: {name}: {text}"
        elif code == NUMERICAL:
            message = f"numerical failure: {_one_line(exc)}"
        elif code == FILESYSTEM:
            message = f"error: {name}: cannot read or write a file: {_one_line(exc)}"
        else:
            message = (f"internal error: {type(exc).__name__}: {_one_line(exc)} (a bug in"
                       " femmech; rerun with --debug for the traceback and report it)")
        print(message, file=sys.stderr)
        return code


def exit_code(exc: BaseException) -> int:
    """The exit code of an exception (see :data:`EXIT_CODES`)."""
    import numpy as np

    if isinstance(exc, InputError):
        return INPUT
    if isinstance(exc, NumericalError | np.linalg.LinAlgError):
        return NUMERICAL
    if isinstance(exc, FileNotFoundError | IsADirectoryError | NotADirectoryError):
        return INPUT  # a path the user gave does not exist or is of the wrong kind
    if isinstance(exc, OSError):
        return FILESYSTEM
    return INTERNAL


if __name__ == "__main__":
    sys.exit(main())
