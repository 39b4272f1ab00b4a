"""The ``olp`` command: a thin shell over :mod:`olp.api`; subcommands live in
:mod:`olp.commands`.

Exit codes: 0 done (warnings allowed), 1 the program has errors (nothing written),
2 bad input or usage (unreadable file, invalid station, unknown post).
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from olp.commands import COMMANDS
from olp.commands.common import EXIT_BAD_INPUT, EXIT_OK


def _parser(argv: Sequence[str]) -> argparse.ArgumentParser:
    """The parser; only the command ``argv`` names gets its arguments, so that ``olp --help``
    and a command do not build every other command's options (some come from the frontends)."""
    chosen = next((arg for arg in argv if not arg.startswith("-")), None)
    parser = argparse.ArgumentParser(
        prog="olp",
        description="Offline-programming compiler for industrial robots: "
        "programs in; checked and timed on a station; robot code out.",
    )
    parser.add_argument("--version", action="store_true", help="print the version and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMANDS:
        module = importlib.import_module(f"olp.commands.{name}")
        command = sub.add_parser(module.NAME, help=module.HELP, description=module.HELP)
        if chosen == module.NAME:
            module.add_arguments(command)
        command.set_defaults(run=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``olp`` console script; returns the exit code."""
    from olp.errors import OlpError

    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        parser = _parser(argv)
    except OlpError as exc:  # e.g. an installed frontend that fails to load
        print(exc.format(), file=sys.stderr)
        return EXIT_BAD_INPUT
    args = parser.parse_args(argv)
    if args.version:
        from importlib.metadata import version

        print(f"olp {version('olp')}")
        return EXIT_OK
    if args.command is None:
        parser.print_help()
        return EXIT_BAD_INPUT
    try:
        return int(args.run(args))
    except OlpError as exc:
        print(exc.format(), file=sys.stderr)
        return EXIT_BAD_INPUT


if __name__ == "__main__":
    sys.exit(main())
