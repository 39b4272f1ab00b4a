"""``olp build STATION PROGRAM --post NAME``: compile and write robot code."""

from __future__ import annotations

import argparse
import sys

from olp.commands.common import EXIT_OK, EXIT_PROGRAM_ERRORS, print_diagnostics, require_files
from olp.commands.options import (
    add_assume_option,
    add_check_options,
    add_collision_options,
    add_output_options,
    add_program,
    add_program_options,
    build_options,
    check_report_paths,
    program_options,
    write_outputs,
)

NAME = "build"
HELP = "compile a program on a station and write robot code"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("station", help="station YAML file")
    add_program(parser)
    parser.add_argument("--post", default="kuka", help="post name or folder (default: kuka)")
    parser.add_argument("-o", "--out", default="out", help="output folder (default: out)")
    parser.add_argument("--name", help="program name in the output (default: from the source)")
    add_output_options(parser)
    parser.add_argument("-q", "--quiet", action="store_true", help="print errors only")
    add_check_options(parser)
    add_collision_options(parser)
    add_assume_option(parser)
    add_program_options(parser)


def run(args: argparse.Namespace) -> int:
    from olp import progress
    from olp.api import build
    from olp.report import summary

    require_files(args.station, args.program)
    check_report_paths(args)
    options = build_options(args)
    with progress.showing(progress.terminal_reporter(args.quiet)):
        result = build(
            args.station,
            args.program,
            post=args.post,
            out_dir=args.out,
            name=args.name,
            options=options,
            program_options=program_options(args),
        )
    print_diagnostics(result.diagnostics, args.program, quiet=args.quiet)
    write_outputs(args, result)
    if not args.quiet:
        print(summary(result), file=sys.stdout)
    return EXIT_OK if result.ok else EXIT_PROGRAM_ERRORS
