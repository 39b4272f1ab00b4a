"""``olp build STATION PROGRAM --post NAME``: compile and write robot code."""

from __future__ import annotations

import argparse
import math
import sys
from typing import TYPE_CHECKING

from olp.commands.check import (
    add_check_options,
    add_collision_options,
    collision_options,
    resolve_options,
)
from olp.commands.common import EXIT_OK, EXIT_PROGRAM_ERRORS, print_diagnostics, require_files

if TYPE_CHECKING:
    from olp.frontends.csv import CsvOptions

NAME = "build"
HELP = "compile a program on a station and write robot code"

_CSV_OPTIONS = (
    "tool",
    "frame",
    "orientation",
    "euler",
    "delimiter",
    "decimal",
    "header",
    "units",
    "angle_units",
    "speed",
    "zone",
)
PROGRAM_HELP = (
    "program file: .src KRL, .csv toolpath, or .py Python program. A .py program is code "
    "that olp runs, with your rights (in a child process, stopped after --timeout)"
)
_DELIMITER_NAMES = {"tab": "\t", "\\t": "\t", "space": " ", "comma": ",", "semicolon": ";"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("station", help="station YAML file")
    parser.add_argument("program", help=PROGRAM_HELP)
    parser.add_argument("--post", default="kuka", help="post name or folder (default: kuka)")
    parser.add_argument("-o", "--out", default="out", help="output folder (default: out)")
    parser.add_argument("--name", help="program name in the output (default: from the source)")
    parser.add_argument("--report", help="write a JSON report to this file")
    parser.add_argument("--sarif", help="write the diagnostics as SARIF 2.1.0 to this file")
    parser.add_argument("-q", "--quiet", action="store_true", help="print errors only")
    add_check_options(parser)
    add_collision_options(parser)
    add_program_options(parser)


def add_program_options(parser: argparse.ArgumentParser) -> None:
    """``--set`` for Python programs and the CSV reading options (shareable by commands)."""
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="a parameter of a Python program (repeatable), read with param('NAME', default)",
    )
    parser.add_argument(
        "--timeout",
        type=float,
        default=60.0,
        metavar="SECONDS",
        help="stop a .py program that runs longer than this (default: 60)",
    )
    parser.add_argument(
        "--config-dat",
        metavar="PATH",
        help="KRL programs: the controller's $config.dat (TOOL_DATA, BASE_DATA, HOME values)",
    )
    csv = parser.add_argument_group("CSV toolpaths")
    csv.add_argument("--tool", help="station tool the rows are for (default: its first tool)")
    csv.add_argument("--frame", help="station frame the rows are in (default: world)")
    csv.add_argument(
        "--orientation",
        metavar="A1,A2,A3",
        help="XYZ files: the orientation in degrees in the --euler convention (default: the "
        "TCP orientation at the robot's home position); with a leading minus write "
        "--orientation=-90,0,0",
    )
    csv.add_argument(
        "--euler",
        metavar="SEQ",
        help="angle columns: 'xyz' = W,P,R with Rz(R)Ry(P)Rx(W) (default), 'ZYX' = KUKA A,B,C, "
        "any scipy-style sequence",
    )
    csv.add_argument("--delimiter", help="',', ';', '|', 'tab' or 'space' (default: detected)")
    csv.add_argument("--decimal", choices=[".", ","], help="decimal separator (default: detected)")
    csv.add_argument("--header", type=int, metavar="N", help="header rows (default: detected)")
    csv.add_argument("--units", choices=["mm", "m", "in"], help="length unit (default: mm)")
    csv.add_argument("--angle-units", choices=["deg", "rad"], help="angle unit (default: deg)")
    csv.add_argument("--speed", type=float, metavar="MM_S", help="speed without a speed column")
    csv.add_argument("--zone", type=float, metavar="MM", help="rounding of the linear moves")


def program_params(args: argparse.Namespace) -> dict[str, str]:
    """``--set NAME=VALUE`` options as a dict (values stay text; the program converts them)."""
    from olp.errors import UsageError

    params: dict[str, str] = {}
    for item in args.set:
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or not name.isidentifier():
            raise UsageError(f"--set {item!r}: expected NAME=VALUE with NAME like SPEED")
        if name in params:
            raise UsageError(f"--set {name} is given twice")
        params[name] = value
    return params


def csv_options(args: argparse.Namespace) -> CsvOptions | None:
    """The CSV options given on the command line, or None if there are none."""
    from olp.frontends.csv import CsvOptions

    given = {key: getattr(args, key) for key in _CSV_OPTIONS if getattr(args, key) is not None}
    if not given:
        return None
    if "orientation" in given:
        given["orientation"] = _orientation(given["orientation"])
    if "delimiter" in given:
        given["delimiter"] = _DELIMITER_NAMES.get(given["delimiter"], given["delimiter"])
    return CsvOptions(**given)


def _orientation(text: str) -> tuple[float, float, float] | None:
    from olp.errors import UsageError

    if text.strip().lower() == "home":
        return None
    try:
        values = tuple(float(v) for v in text.replace(";", ",").split(","))
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise UsageError(f"--orientation {text!r}: expected three angles in degrees, like 180,0,0")
    return values[0], values[1], values[2]


def run(args: argparse.Namespace) -> int:
    from olp.api import build
    from olp.commands.check import check_report_paths, write_outputs
    from olp.report import summary

    require_files(args.station, args.program)
    check_report_paths(args)
    result = build(
        args.station,
        args.program,
        post=args.post,
        out_dir=args.out,
        name=args.name,
        options=resolve_options(args),
        params=program_params(args),
        csv_options=csv_options(args),
        krl_config_dat=args.config_dat,
        collisions=collision_options(args),
        timeout=args.timeout,
    )
    print_diagnostics(result.diagnostics, args.program, quiet=args.quiet)
    write_outputs(args, result)
    if not args.quiet:
        print(summary(result), file=sys.stdout)
    return EXIT_OK if result.ok else EXIT_PROGRAM_ERRORS
