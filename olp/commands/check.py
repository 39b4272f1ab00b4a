"""``olp check STATION PROGRAM``: every check, no robot code written.

Exit codes as for ``olp build``: 0 no errors, 1 the program has errors, 2 bad input.
"""

from __future__ import annotations

import argparse

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
    parse_program,
    write_outputs,
)

NAME = "check"
HELP = "check a program on a station (reach, limits, singularities) without writing code"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("station", help="station YAML file")
    add_program(parser)
    add_check_options(parser)
    add_collision_options(parser)
    add_assume_option(parser)
    add_output_options(parser)
    parser.add_argument("-q", "--quiet", action="store_true", help="print errors only")
    add_program_options(parser)


def run(args: argparse.Namespace) -> int:
    from olp import progress
    from olp.api import BuildResult, compile, load_station
    from olp.report import summary

    require_files(args.station, args.program)
    check_report_paths(args)
    options = build_options(args)
    station = load_station(args.station)
    with progress.showing(progress.terminal_reporter(args.quiet)):
        with progress.stage("read"):
            parsed = parse_program(args, station)
        compiled = compile(parsed.program, station, options)
    result = BuildResult(compiled, "-", parsed.notes + compiled.diagnostics)
    print_diagnostics(result.diagnostics, args.program, quiet=args.quiet)
    write_outputs(args, result)
    if not args.quiet:
        print(summary(result))
    return EXIT_OK if result.ok else EXIT_PROGRAM_ERRORS
