"""``olp`` subcommands, one module each. A module defines::

    NAME = "build"
    HELP = "one line for ``olp --help``"
    def add_arguments(parser: argparse.ArgumentParser) -> None: ...
    def run(args: argparse.Namespace) -> int: ...          # the exit code

and is listed in :data:`COMMANDS`. Modules import heavy packages inside ``run`` only, so that
``olp --help`` stays fast. The option groups several commands share (checks, collisions,
outputs, the program and its frontend's options) are in :mod:`olp.commands.options`; the
commands import it and :mod:`olp.commands.common`, never each other.
"""

from __future__ import annotations

COMMANDS: tuple[str, ...] = ("build", "check", "posts", "robots", "schema", "time")
"""Command module names under :mod:`olp.commands`, in ``olp --help`` order."""
