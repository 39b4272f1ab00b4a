"""``olp schema station``: print the JSON Schema of station files (for editors and CI checks)."""

from __future__ import annotations

import argparse
import sys

from olp.commands.common import EXIT_OK

NAME = "schema"
HELP = "print the JSON Schema of a file format (station)"

_FORMATS = ("station",)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("format", choices=_FORMATS, help="which file format")
    parser.add_argument("-o", "--out", help="write to this file instead of standard output")


def run(args: argparse.Namespace) -> int:
    from olp.station.schema import station_schema_json

    text = station_schema_json()
    if args.out:
        from olp.output import check_output_file, write_file

        write_file(check_output_file(args.out, "-o"), text.encode("utf-8"))
    else:
        sys.stdout.write(text)
    return EXIT_OK
