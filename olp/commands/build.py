"""``olp build STATION PROGRAM --post NAME``: compile and write robot code."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from olp.commands.common import EXIT_OK, EXIT_PROGRAM_ERRORS, print_diagnostics, require_files

NAME = "build"
HELP = "compile a program on a station and write robot code"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("station", help="station YAML file")
    parser.add_argument("program", help="program file (.src)")
    parser.add_argument("--post", default="kuka", help="post name or folder (default: kuka)")
    parser.add_argument("-o", "--out", default="out", help="output folder (default: out)")
    parser.add_argument("--name", help="program name in the output (default: from the source)")
    parser.add_argument("--report", help="write a JSON report to this file")
    parser.add_argument("-q", "--quiet", action="store_true", help="print errors only")


def run(args: argparse.Namespace) -> int:
    from olp.api import build
    from olp.report import report_json, summary

    require_files(args.station, args.program)
    result = build(args.station, args.program, post=args.post, out_dir=args.out, name=args.name)
    print_diagnostics(result.diagnostics, args.program, quiet=args.quiet)
    if args.report:
        from olp.post import write_files

        report = Path(args.report)
        write_files({report.name: report_json(result)}, report.parent, "utf-8")
    if not args.quiet:
        print(summary(result), file=sys.stdout)
    return EXIT_OK if result.ok else EXIT_PROGRAM_ERRORS
