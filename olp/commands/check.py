"""``olp check STATION PROGRAM``: every check, no robot code written.

Exit codes as for ``olp build``: 0 no errors, 1 the program has errors, 2 bad input.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from olp.commands.common import (
    EXIT_OK,
    EXIT_PROGRAM_ERRORS,
    parse_program,
    print_diagnostics,
    require_files,
)

if TYPE_CHECKING:
    from olp.api import BuildResult
    from olp.passes.collide import CollisionOptions
    from olp.passes.resolve import ResolveOptions

NAME = "check"
HELP = "check a program on a station (reach, limits, singularities) without writing code"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("station", help="station YAML file")
    from olp.commands.build import PROGRAM_HELP, add_program_options

    parser.add_argument("program", help=PROGRAM_HELP)
    add_check_options(parser)
    add_collision_options(parser)
    parser.add_argument("--report", help="write a JSON report to this file")
    parser.add_argument("--sarif", help="write the diagnostics as SARIF 2.1.0 to this file")
    parser.add_argument("-q", "--quiet", action="store_true", help="print errors only")
    add_program_options(parser)


def add_check_options(parser: argparse.ArgumentParser) -> None:
    """Options that change what the checks accept (shared with ``olp build``)."""
    parser.add_argument(
        "--fallback",
        choices=["none", "joint"],
        default="none",
        help="'joint': a linear move that cannot run becomes a joint move when that can",
    )
    parser.add_argument(
        "--skip-unreachable",
        action="store_true",
        help="drop targets no move can reach (a warning each) instead of failing",
    )


def add_collision_options(parser: argparse.ArgumentParser) -> None:
    """Options of the collision check (shared with ``olp build`` and ``olp time``)."""
    group = parser.add_argument_group("collisions")
    group.add_argument(
        "--no-collisions",
        dest="collisions",
        action="store_false",
        help="skip the collision check",
    )
    group.add_argument(
        "--clearance",
        type=float,
        default=0.0,
        metavar="MM",
        help="the robot, its tool or a carried part closer than this to a part or fixture "
        "collides (default 0)",
    )
    group.add_argument(
        "--self-clearance",
        type=float,
        default=0.0,
        metavar="MM",
        help="the same between the robot's own links, tool and carried parts (default 0)",
    )
    group.add_argument(
        "--allow-contact",
        action="append",
        default=[],
        metavar="A,B",
        help="two bodies that may touch (link_3, a tool, part or fixture name); repeatable",
    )


def collision_options(args: argparse.Namespace) -> CollisionOptions | None:
    """The collision options the command line asks for, or None with --no-collisions."""
    from olp.errors import UsageError
    from olp.passes.collide import CollisionOptions

    if not args.collisions:
        return None
    if not (args.clearance >= 0.0):
        raise UsageError(f"--clearance must be >= 0 mm, got {args.clearance}")
    pairs = []
    for text in args.allow_contact:
        names = [n.strip() for n in text.split(",")]
        if len(names) != 2 or not all(names):
            raise UsageError(f"--allow-contact takes two names 'A,B', got {text!r}")
        pairs.append((names[0], names[1]))
    return CollisionOptions(
        clearance_m=args.clearance / 1000.0,
        self_clearance_m=args.self_clearance / 1000.0,
        allowed_pairs=tuple(pairs),
    )


def resolve_options(args: argparse.Namespace) -> ResolveOptions:
    """The :class:`~olp.passes.resolve.ResolveOptions` the check options ask for."""
    from olp.passes.resolve import ResolveOptions

    return ResolveOptions(
        fallback_joint=args.fallback == "joint", skip_unreachable=args.skip_unreachable
    )


def run(args: argparse.Namespace) -> int:
    from olp.api import BuildResult, compile, load_station
    from olp.report import summary

    require_files(args.station, args.program)
    check_report_paths(args)
    station = load_station(args.station)
    parsed = parse_program(args, station)
    compiled = compile(
        parsed.program, station, resolve_options(args), collisions=collision_options(args)
    )
    result = BuildResult(compiled, "-", parsed.notes + compiled.diagnostics)
    print_diagnostics(result.diagnostics, args.program, quiet=args.quiet)
    write_outputs(args, result)
    if not args.quiet:
        print(summary(result))
    return EXIT_OK if result.ok else EXIT_PROGRAM_ERRORS


def check_report_paths(args: argparse.Namespace) -> None:
    """Check ``--report`` and ``--sarif`` (and ``-o`` where the command has it) before anything
    runs: a bad path is a usage error (exit 2) before any robot code is written."""
    from olp.output import check_distinct, check_output_file, check_output_folder

    paths: list[tuple[str, Path | None]] = []
    if getattr(args, "out", None) is not None:
        paths.append(("-o", check_output_folder(args.out)))
    for option in ("report", "sarif"):
        value = getattr(args, option, None)
        paths.append((f"--{option}", check_output_file(value, f"--{option}") if value else None))
    check_distinct(paths)


def write_outputs(args: argparse.Namespace, result: BuildResult) -> None:
    """Write the ``--report`` JSON and the ``--sarif`` log, each atomically, if asked."""
    from importlib.metadata import version

    from olp.output import write_file
    from olp.report import report_json
    from olp.sarif import sarif_json

    if getattr(args, "report", None):
        write_file(args.report, report_json(result).encode("utf-8"))
    if getattr(args, "sarif", None):
        write_file(args.sarif, sarif_json(result.diagnostics, version("olp")).encode("utf-8"))
