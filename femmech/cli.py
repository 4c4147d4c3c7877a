"""Command line: ``femmech run SCENE --out DIR`` and ``femmech check SCENE``.

Exit codes: 0 success, 1 a computation failed, 2 an invalid scene or command line (the
error is one line on stderr naming the file, the key and what was expected). Suspicious
inputs (nearly coincident nodes, loose parts, unit mix-ups: :mod:`femmech.checks`) are
reported, not refused: one ``warning:`` line each on stdout and in the run's log.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from femmech.errors import SceneError


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="femmech", description="Machines described in scene files (TOML): compute the"
        " requested analyses with cached reductions and write an HTML report.")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="compute a scene and write its report")
    run.add_argument("scene", type=Path, help="scene file (.toml)")
    run.add_argument("--out", type=Path, required=True, help="output folder (created)")
    run.add_argument("--no-cache", action="store_true", help="do not read or write the"
                     " reduction cache")
    run.add_argument("--cache-dir", type=Path, default=None,
                     help="reduction cache folder (default: $FEMMECH_CACHE_DIR, else"
                     " ~/.cache/femmech)")
    run.add_argument("-q", "--quiet", action="store_true", help="no log lines, no progress"
                     " bars")
    check = sub.add_parser("check", help="validate a scene without computing")
    check.add_argument("scene", type=Path, help="scene file (.toml)")
    return parser


def _check(path: Path) -> int:
    from femmech.scene import load_scene
    from femmech.scene_build import finding_lines, prepare

    prepared = prepare(load_scene(path))
    scene = prepared.scene
    parts = ", ".join(f"{n} ({m.n_nodes} nodes)" for n, m in prepared.meshes.items())
    analyses = [k for k in ("modes", "sweep", "stability", "response", "check")
                if getattr(scene.analyses, k) is not None]
    print(f"{path.name}: OK: parts {parts or '-'}; mechanisms {list(scene.mechanisms) or '-'};"
          f" mounts {len(scene.mounts)}; analyses {analyses}")
    for line in finding_lines(prepared):  # suspicious inputs: reported, not refused
        print(f"{path.name}: {line}")
    return 0


def _run(args) -> int:
    from femmech.cache import default_cache_dir
    from femmech.scene_run import run_scene

    cache = None if args.no_cache else (args.cache_dir or default_cache_dir())
    bars = not args.quiet and sys.stderr.isatty()
    result = run_scene(args.scene, args.out, cache_dir=cache,
                       log=None if args.quiet else print, bars=bars)
    if args.quiet:
        print(result.report)
    return 0


def main(argv=None) -> int:
    """Entry point of the ``femmech`` command; returns the exit code."""
    args = _parser().parse_args(argv)
    try:
        return _check(args.scene) if args.command == "check" else _run(args)
    except SceneError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except (ValueError, RuntimeError, OSError) as exc:
        print(f"error: {args.scene.name}: {type(exc).__name__}: {exc}".replace("\n", " "),
              file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
