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
    add_post_options,
    add_program,
    add_program_options,
    build_options,
    check_report_paths,
    post_writer,
    program_options,
    write_outputs,
)
from olp.errors import UsageError
from olp.frontends.options import whole_number

NAME = "build"
HELP = "compile a program on a station and write robot code"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("station", help="station YAML file")
    add_program(parser)
    add_post_options(parser)
    parser.add_argument("-o", "--out", default="out", help="output folder (default: out)")
    parser.add_argument("--name", help="program name in the output (default: from the source)")
    add_output_options(parser)
    parser.add_argument("-q", "--quiet", action="store_true", help="print errors only")
    parser.add_argument(
        "--chunk-rows",
        type=whole_number,
        default=None,
        metavar="N",
        help="build a CSV toolpath in windows of N rows, in bounded memory (default: so from "
        "1,000,000 rows on, when the post can; 0: never)",
    )
    add_check_options(parser)
    add_collision_options(parser)
    add_assume_option(parser)
    add_program_options(parser)


def run(args: argparse.Namespace) -> int:
    from olp import progress
    from olp.api import build
    from olp.report import summary
    from olp.stream import streamed_summary

    require_files(args.station, args.program)
    check_report_paths(args)
    options = build_options(args)
    chunk_rows = args.chunk_rows
    if getattr(args, "report", None):
        if chunk_rows:
            raise UsageError("--report needs the whole program: leave out --chunk-rows")
        chunk_rows = 0  # the report lists every instruction
    with progress.showing(progress.terminal_reporter(args.quiet)):
        result = build(
            args.station,
            args.program,
            post=post_writer(args),
            out_dir=args.out,
            name=args.name,
            options=options,
            program_options=program_options(args),
            chunk_rows=chunk_rows,
        )
    print_diagnostics(result.diagnostics, args.program, quiet=args.quiet)
    write_outputs(args, result)
    if not args.quiet:
        text = summary(result) if result.streamed is None else streamed_summary(result)
        print(text, file=sys.stdout)
    return EXIT_OK if result.ok else EXIT_PROGRAM_ERRORS
