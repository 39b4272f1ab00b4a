"""The ``olp`` command: a thin shell over :mod:`olp.api`.

Exit codes: 0 built (warnings allowed), 1 the program has errors (nothing written),
2 bad input or usage (unreadable file, invalid station, unknown post).
Heavy modules (pinocchio, toppra) are imported only by the commands that need them.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

EXIT_OK, EXIT_PROGRAM_ERRORS, EXIT_BAD_INPUT = 0, 1, 2


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="olp",
        description="Offline-programming compiler for industrial robots: "
        "KRL in; checked, timed; KRL out.",
    )
    parser.add_argument("--version", action="store_true", help="print the version and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    build = sub.add_parser("build", help="compile a program on a station and write robot code")
    build.add_argument("station", help="station YAML file")
    build.add_argument("program", help="program file (.src)")
    build.add_argument("--post", default="kuka", help="post name or folder (default: kuka)")
    build.add_argument("-o", "--out", default="out", help="output folder (default: out)")
    build.add_argument("--name", help="program name in the output (default: from the source)")
    build.add_argument("--report", help="write a JSON report to this file")
    build.add_argument("-q", "--quiet", action="store_true", help="print errors only")
    sub.add_parser("posts", help="list the available post-processors")
    sub.add_parser("robots", help="list the bundled robot models")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``olp`` console script; returns the exit code."""
    args = _parser().parse_args(argv)
    if args.version:
        from importlib.metadata import version

        print(f"olp {version('olp')}")
        return EXIT_OK
    if args.command is None:
        _parser().print_help()
        return EXIT_BAD_INPUT
    from olp.errors import OlpError

    try:
        return int(_COMMANDS[args.command](args))
    except OlpError as exc:
        print(exc.format(), file=sys.stderr)
        return EXIT_BAD_INPUT


def _cmd_build(args: argparse.Namespace) -> int:
    from olp.api import build
    from olp.errors import UsageError
    from olp.report import format_diagnostic, report_json, summary

    for path in (args.station, args.program):
        if not Path(path).is_file():
            raise UsageError(f"no such file: {path}")
    result = build(args.station, args.program, post=args.post, out_dir=args.out, name=args.name)
    sources = _sources(args.program)
    for diag in result.diagnostics:
        if diag.severity == "error" or (not args.quiet and diag.severity == "warning"):
            print(format_diagnostic(diag, sources), file=sys.stderr)
    if args.report:
        from olp.post import write_files

        report = Path(args.report)
        write_files({report.name: report_json(result)}, report.parent, "utf-8")
    if not args.quiet:
        print(summary(result))
    return EXIT_OK if result.ok else EXIT_PROGRAM_ERRORS


def _sources(*paths: str) -> dict[str, str]:
    out = {}
    for path in paths:
        try:
            out[path] = Path(path).read_text(encoding="utf-8", errors="replace")
        except OSError:
            continue
    return out


def _cmd_posts(args: argparse.Namespace) -> int:
    from olp.post import available_posts, load_manifest

    for name, folder in available_posts().items():
        print(f"{name:12} {load_manifest(folder).description}")
    return EXIT_OK


def _cmd_robots(args: argparse.Namespace) -> int:
    from olp.station.loader import robot_library

    for name in robot_library():
        print(name)
    return EXIT_OK


_COMMANDS = {"build": _cmd_build, "posts": _cmd_posts, "robots": _cmd_robots}

if __name__ == "__main__":
    sys.exit(main())
