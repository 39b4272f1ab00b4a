"""The option groups the ``olp`` commands share, and what the parsed options mean.

* check options (``--fallback``, ``--skip-unreachable``) -> :func:`resolve_options`;
* ``--assume`` (what a program's branches and loops may take as known) -> :func:`build_options`;
* collision options (``--no-collisions``, ``--clearance`` ...) -> :func:`collision_options`;
* output options (``--report``, ``--sarif``) -> :func:`check_report_paths`, :func:`write_outputs`;
* the program and its options: one argument group per set of frontends that take the same flags,
  built from the frontends' ``Options`` dataclasses (:mod:`olp.frontends.options`), so a new
  frontend brings its flags with it. The values go to the frontend of the program's suffix
  (:func:`program_options`); a flag another frontend takes is a usage error.

The commands import this module and :mod:`olp.commands.common`, never each other.
"""

from __future__ import annotations

import argparse
import dataclasses
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from olp.api import BuildResult
    from olp.frontends import Frontend, ParsedProgram
    from olp.frontends.options import Flag
    from olp.passes.collide import CollisionOptions
    from olp.passes.pipeline import BuildOptions
    from olp.passes.resolve import ResolveOptions
    from olp.station.model import Station

# ------------------------------------------------------------------------------------------------
# Check options


def add_check_options(parser: argparse.ArgumentParser) -> None:
    """Options that change what the checks accept."""
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


def resolve_options(args: argparse.Namespace) -> ResolveOptions:
    """The :class:`~olp.passes.resolve.ResolveOptions` the check options ask for."""
    from olp.passes.resolve import ResolveOptions

    return ResolveOptions(
        fallback_joint=args.fallback == "joint", skip_unreachable=args.skip_unreachable
    )


ASSUME_HELP = (
    "what the cycle time of a program with branches and loops may take as known, repeatable: "
    "an input (in3=true, or $IN[3]=true), a variable (count=4, part.kind=#BIG, name='A'), the "
    "passes of a loop by its source line, file and line, or the label before it (loop:12=5, "
    "loop:sub.src:40=3, loop:retry=2). "
    "Without it, the cycle time is a range: the shortest and the longest path with the branch "
    "choices that give each; a WHILE, REPEAT or LOOP whose count is unknown counts one pass"
)


def add_assume_option(parser: argparse.ArgumentParser) -> None:
    """``--assume NAME=VALUE`` (:mod:`olp.passes.timing.conditions`)."""
    parser.add_argument(
        "--assume", action="append", default=[], metavar="NAME=VALUE", help=ASSUME_HELP
    )


def build_options(
    args: argparse.Namespace, other_times: Mapping[str, float] | None = None
) -> BuildOptions:
    """The :class:`~olp.passes.pipeline.BuildOptions` the check, collision and ``--assume``
    options ask for."""
    from olp.passes.pipeline import BuildOptions
    from olp.passes.timing.conditions import parse_assumptions

    return BuildOptions(
        resolve=resolve_options(args),
        collisions=collision_options(args),
        other_times=other_times or {},
        assume=parse_assumptions(getattr(args, "assume", [])),
    )


# ------------------------------------------------------------------------------------------------
# Collision options


def add_collision_options(parser: argparse.ArgumentParser) -> None:
    """Options of the collision check."""
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


# ------------------------------------------------------------------------------------------------
# Output options


def add_output_options(parser: argparse.ArgumentParser) -> None:
    """``--report`` (JSON) and ``--sarif``."""
    parser.add_argument("--report", help="write a JSON report to this file")
    parser.add_argument("--sarif", help="write the diagnostics as SARIF 2.1.0 to this file")


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


# ------------------------------------------------------------------------------------------------
# The program and its options


def add_program(parser: argparse.ArgumentParser, optional: bool = False) -> None:
    """The ``program`` argument: a file of any frontend's suffix (``optional``: may be left
    out, for a subcommand that has another mode)."""
    from olp.frontends import frontends

    kinds = ", ".join(f"{' '.join(f.SUFFIXES)} {f.TITLE}" for f in frontends().values())
    parser.add_argument(
        "program",
        nargs="?" if optional else None,
        help=f"program file ({kinds}). A .py program is code that olp runs, with your rights "
        "(in a child process, stopped after --timeout)",
    )


def add_program_options(parser: argparse.ArgumentParser) -> None:
    """One argument group per set of frontends taking the same flags (a flag of a shared
    options type, such as the toolpath options, is added once)."""
    from olp.errors import UsageError

    groups: dict[tuple[str, ...], list[Flag]] = {}
    for flag, takers in _program_flags().values():
        groups.setdefault(tuple(takers), []).append(flag)
    known = {f.NAME: f for f in _frontends()}
    for names, flags in groups.items():
        group = parser.add_argument_group(_title([known[n] for n in names]))
        for flag in flags:
            try:
                _add_flag(group, flag)
            except argparse.ArgumentError as exc:
                msg = f"{_title([known[n] for n in names])} declare {flag.name}: {exc.message}"
                raise UsageError(msg) from None


def program_options(args: argparse.Namespace) -> Any:
    """The options of the program's frontend from the flags given (its defaults for those
    not given). A :class:`~olp.errors.UsageError` for a flag value that does not parse, a flag
    only other frontends take, or a value the frontend rejects."""
    from olp.errors import UsageError
    from olp.frontends import describe, frontend_for

    frontend = frontend_for(args.program)
    flags = _program_flags()
    raw = {name: v for name in flags if (v := getattr(args, _dest(name), None)) is not None}
    values = {
        field.name: _parsed(flag, raw[flag.name])
        for field, flag in _flag_fields(frontend)
        if flag.name in raw
    }
    for name, text in raw.items():
        flag, takers = flags[name]
        if frontend.NAME not in takers:
            _parsed(flag, text)  # a malformed value is the first thing to say
            known = {f.NAME: f for f in _frontends()}
            whose = " and ".join(describe(known[n]) for n in takers)
            suffix = Path(args.program).suffix.lower()
            raise UsageError(f"{name} is for {whose}, not {suffix}")
    try:
        return frontend.Options(**values)
    except (TypeError, ValueError) as exc:  # a third-party Options' own check
        raise UsageError(f"{', '.join(raw)}: {exc}") from None


def parse_program(args: argparse.Namespace, station: Station) -> ParsedProgram:
    """Parse ``args.program`` with its program options, the station at hand for the
    frontends that consult one."""
    from olp.api import parse

    return parse(args.program, station=station, options=program_options(args))


def _frontends() -> list[Frontend]:
    from olp.frontends import frontends

    return list(frontends().values())


def _flag_fields(frontend: Frontend) -> list[tuple[dataclasses.Field[Any], Flag]]:
    from olp.frontends.options import CLI_KEY

    fields = dataclasses.fields(frontend.Options)
    return [(f, f.metadata[CLI_KEY]) for f in fields if CLI_KEY in f.metadata]


def _program_flags() -> dict[str, tuple[Flag, list[str]]]:
    """Every frontend flag -> its first declaration and the names of the frontends taking it."""
    flags: dict[str, tuple[Flag, list[str]]] = {}
    for frontend in _frontends():
        for _, flag in _flag_fields(frontend):
            flags.setdefault(flag.name, (flag, []))[1].append(frontend.NAME)
    return flags


def _title(frontends: Sequence[Frontend]) -> str:
    titles = ", ".join(f.TITLE for f in frontends)
    suffixes = ", ".join(s for f in frontends for s in f.SUFFIXES)
    return f"{titles} ({suffixes})"


def _dest(flag_name: str) -> str:
    """Where argparse keeps a frontend flag: apart from every command's own options."""
    return f"program option {flag_name}"


def _add_flag(group: argparse._ArgumentGroup, flag: Flag) -> None:
    metavar = flag.metavar
    if metavar is None and flag.choices is None:
        metavar = flag.name.lstrip("-").replace("-", "_").upper()
    group.add_argument(
        flag.name,
        dest=_dest(flag.name),
        action="append" if flag.repeatable else "store",
        default=None,
        metavar=metavar,
        choices=flag.choices,
        help=flag.help,
    )


def _parsed(flag: Flag, raw: object) -> object:
    from olp.errors import UsageError

    try:
        return flag.parse(raw)
    except ValueError as exc:
        raise UsageError(f"{flag.name} {raw!r}: {exc}") from None
