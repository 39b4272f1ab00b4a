"""``olp robots``: list the bundled robot models."""

from __future__ import annotations

import argparse

from olp.commands.common import EXIT_OK

NAME = "robots"
HELP = "list the bundled robot models"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    del parser


def run(args: argparse.Namespace) -> int:
    from olp.station.loader import robot_library

    for name in robot_library():
        print(name)
    return EXIT_OK
