"""The frontends that ship with olp, as :class:`~olp.frontends.Frontend`\\ s: KRL, CSV, Python.

Each states its name, suffixes and options here and imports its reader only in ``load``, so the
command line learns every frontend's options (``olp build --help``) without importing numpy or
lark. The readers are :mod:`olp.frontends.krl`, :mod:`olp.frontends.csv` and
:mod:`olp.frontends.dsl` (run in a child process by :mod:`olp.frontends.dsl_process`).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from olp.errors import UsageError
from olp.frontends import ParsedProgram, ignored_notes
from olp.frontends.options import ToolpathOptions, cli, whole_number

if TYPE_CHECKING:
    from olp.frontends.krl.data import KrlData
    from olp.station.model import Station

# ------------------------------------------------------------------------------------------------
# KUKA KRL


@dataclass(frozen=True, slots=True, kw_only=True)
class KrlOptions:
    """How to read a KRL program. ``config_dat``: the controller's ``$config.dat`` for
    ``TOOL_DATA``/``BASE_DATA``/``XHOME`` values: a path, or one read before with
    :func:`olp.frontends.krl.load_config_dat` (see :func:`olp.frontends.krl.load_krl`).
    ``data_lists``: other modules' data lists (paths or :class:`KrlData`), each a
    ``DEFDAT name PUBLIC`` whose ``GLOBAL`` declarations the program may use (a shared
    ``Positions.dat``); ``data_lists_from``: a folder whose public data lists are all read (a
    controller's ``R1`` folder). KRL's visibility rules:
    :func:`olp.frontends.krl.data.visible_globals`. ``calls_keep_settings``: names (or
    ``fnmatch`` patterns, case-insensitive) of routines olp does not read that the user vouches
    leave the motion settings and the robot's position as they were (``SprayOn``, ``Grip*``);
    a call of any other unread routine may set them and move the robot
    (:meth:`olp.frontends.krl.lower._Lowering._unread_call`).
    """

    config_dat: str | os.PathLike[str] | KrlData | None = field(
        default=None,
        metadata=cli(
            "--config-dat",
            "the controller's $config.dat (TOOL_DATA, BASE_DATA, HOME values)",
            metavar="PATH",
        ),
    )
    data_lists: tuple[str | os.PathLike[str] | KrlData, ...] = field(
        default=(),
        metadata=cli(
            "--data-list",
            "another module's PUBLIC data list whose GLOBAL points the program uses (repeatable)",
            metavar="PATH",
            parse=tuple,
            repeatable=True,
        ),
    )
    data_lists_from: str | os.PathLike[str] | None = field(
        default=None,
        metadata=cli(
            "--data-lists-from",
            "read every PUBLIC data list (.dat) under this folder for GLOBAL names",
            metavar="DIR",
        ),
    )
    calls_keep_settings: tuple[str, ...] = field(
        default=(),
        metadata=cli(
            "--call-keeps-settings",
            "a routine olp does not read (another module's) that leaves $TOOL, $BASE, the motion "
            "settings and the robot where they were: a name or a pattern such as 'Spray*' "
            "(repeatable; without it a motion after such a call runs with the controller's "
            "settings and is not checked)",
            metavar="NAME",
            parse=tuple,
            repeatable=True,
        ),
    )

    def __post_init__(self) -> None:
        object.__setattr__(self, "data_lists", tuple(self.data_lists))
        object.__setattr__(self, "calls_keep_settings", tuple(self.calls_keep_settings))


class KrlFrontend:
    """KUKA KRL (KR C4, KSS 8): a ``.src`` module and the ``.dat`` beside it."""

    NAME = "krl"
    TITLE = "KRL programs"
    SUFFIXES = (".src",)
    Options = KrlOptions

    def load(self, path: Path, options: KrlOptions, station: Station | None) -> ParsedProgram:
        from olp.diagnostics import Diagnostic
        from olp.frontends.krl import load_krl
        from olp.ir import Verbatim

        result = load_krl(
            path,
            config_dat=options.config_dat,
            data_lists=options.data_lists,
            data_lists_from=options.data_lists_from,
            calls_keep_settings=options.calls_keep_settings,
        )
        remarks = tuple(
            Diagnostic("warning", "krl_note", note.message, note.span) for note in result.notes
        )
        src = os.fspath(path)
        dropped = [i for i in result.ignored if i.span.file == src]
        data = [i for i in result.ignored if i.span.file != src]
        kept = tuple(
            Diagnostic("info", "verbatim", f"kept as written (not modelled: {i.reason})", i.span)
            for i in result.program
            if isinstance(i, Verbatim)
        )
        notes = ignored_notes(dropped, "warning", "statement not in the output")
        return ParsedProgram(result.program, notes + kept + remarks + ignored_notes(data))


# ------------------------------------------------------------------------------------------------
# CSV toolpaths

LENGTH_UNITS = {"mm": 1000.0, "m": 1.0, "in": 1.0 / 0.0254}
"""Length units a CSV may use: how many make a metre (dividing keeps 9 mm exactly 0.009 m)."""
ANGLE_UNITS = {"deg": math.pi / 180.0, "rad": 1.0}
"""Angle units a CSV may use, in radians."""
DELIMITERS = (",", ";", "\t", "|", " ")
"""Cell delimiters a CSV may use (``" "``: any whitespace)."""
DELIMITER_NAMES = {"tab": "\t", "\\t": "\t", "space": " ", "comma": ",", "semicolon": ";"}
"""Names of delimiters for the command line, where a tab is hard to type."""


def delimiter_text(text: str) -> str:
    """``--delimiter``: a delimiter or its name (``tab``, ``space``, ...)."""
    return DELIMITER_NAMES.get(text, text)


@dataclass(frozen=True, slots=True, kw_only=True)
class CsvOptions(ToolpathOptions):
    """How to read a CSV toolpath (see :mod:`olp.frontends.csv`): the toolpath options and how
    the file is laid out. ``None`` means detect/default.

    ``delimiter``: ``","``, ``";"``, ``"\\t"``, ``"|"`` or ``" "`` (any whitespace);
    ``decimal``: ``"."`` or ``","``; ``header``: the number of header rows; ``units``: ``"mm"``,
    ``"m"`` or ``"in"``; ``angle_units``: ``"deg"`` or ``"rad"``; ``chunk_bytes``: the block
    size of the reader.
    """

    delimiter: str | None = field(
        default=None,
        metadata=cli(
            "--delimiter",
            "',', ';', '|', 'tab' or 'space' (default: detected)",
            parse=delimiter_text,
        ),
    )
    decimal: str | None = field(
        default=None,
        metadata=cli("--decimal", "decimal separator (default: detected)", choices=(".", ",")),
    )
    header: int | None = field(
        default=None,
        metadata=cli(
            "--header", "header rows (default: detected)", metavar="N", parse=whole_number
        ),
    )
    units: str | None = field(
        default=None,
        metadata=cli("--units", "length unit (default: mm)", choices=tuple(LENGTH_UNITS)),
    )
    angle_units: str | None = field(
        default=None,
        metadata=cli("--angle-units", "angle unit (default: deg)", choices=tuple(ANGLE_UNITS)),
    )
    chunk_bytes: int = 1 << 20

    def __post_init__(self) -> None:
        ToolpathOptions.__post_init__(self)
        _check_choice("delimiter", self.delimiter, DELIMITERS)
        _check_choice("decimal", self.decimal, (".", ","))
        _check_choice("units", self.units, tuple(LENGTH_UNITS))
        _check_choice("angle units", self.angle_units, tuple(ANGLE_UNITS))
        if self.header is not None and self.header < 0:
            raise UsageError(f"CSV header rows must be >= 0, got {self.header}")
        if self.chunk_bytes < 1:
            raise UsageError(f"chunk_bytes must be positive, got {self.chunk_bytes}")


def _check_choice(what: str, value: str | None, allowed: tuple[str, ...]) -> None:
    if value is not None and value not in allowed:
        shown = ", ".join(repr(a) for a in allowed)
        raise UsageError(f"CSV {what} {value!r} is not one of {shown}")


class CsvFrontend:
    """CSV toolpaths: one target per row, read in vectorised chunks."""

    NAME = "csv"
    TITLE = "CSV toolpaths"
    SUFFIXES = (".csv",)
    Options = CsvOptions

    def load(self, path: Path, options: CsvOptions, station: Station | None) -> ParsedProgram:
        from olp.frontends.csv import load_csv

        result = load_csv(path, options, station)
        return ParsedProgram(result.program, ignored_notes(result.ignored))


# ------------------------------------------------------------------------------------------------
# Python programs

DEFAULT_TIMEOUT = 60.0
"""Seconds a Python program may run (``--timeout``), interpreter start included."""


def check_timeout(timeout: float | None) -> float | None:
    """``timeout`` if it is a positive number of seconds (None or infinity: no limit, None);
    a UsageError otherwise."""
    if timeout is None:
        return None
    if isinstance(timeout, bool) or not isinstance(timeout, int | float) or not timeout > 0:
        raise UsageError(f"--timeout must be a positive number of seconds, got {timeout!r}")
    return None if math.isinf(timeout) else float(timeout)


def seconds_text(text: str) -> float:
    """``--timeout``: a number of seconds (its range is :func:`check_timeout`'s)."""
    try:
        return float(text)
    except ValueError:
        raise ValueError("expected a number of seconds") from None


def params_text(items: list[str]) -> dict[str, str]:
    """``--set NAME=VALUE`` items as a dict (values stay text; the program converts them)."""
    params: dict[str, str] = {}
    for item in items:
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or not name.isidentifier():
            raise UsageError(f"--set {item!r}: expected NAME=VALUE with NAME like SPEED")
        if name in params:
            raise UsageError(f"--set {name} is given twice")
        params[name] = value
    return params


@dataclass(frozen=True, slots=True, kw_only=True)
class DslOptions:
    """How to run a Python program (see :mod:`olp.frontends.dsl`).

    ``params``: values the program reads with ``param(NAME, default)`` (text from the command
    line, or Python values that can be pickled); ``timeout``: seconds the program may run
    (interpreter start included) before it is killed; None for no limit.
    """

    params: Mapping[str, object] = field(
        default_factory=dict,
        metadata=cli(
            "--set",
            "a parameter of the program (repeatable), read with param('NAME', default)",
            metavar="NAME=VALUE",
            parse=params_text,
            repeatable=True,
        ),
    )
    timeout: float | None = field(
        default=DEFAULT_TIMEOUT,
        metadata=cli(
            "--timeout",
            f"stop a program that runs longer than this (default: {DEFAULT_TIMEOUT:g})",
            metavar="SECONDS",
            parse=seconds_text,
        ),
    )

    def __post_init__(self) -> None:
        object.__setattr__(self, "params", dict(self.params))
        object.__setattr__(self, "timeout", check_timeout(self.timeout))


class PythonFrontend:
    """Python programs: code that olp runs, with the user's rights, in a child process."""

    NAME = "python"
    TITLE = "Python programs"
    SUFFIXES = (".py",)
    Options = DslOptions

    def load(self, path: Path, options: DslOptions, station: Station | None) -> ParsedProgram:
        from olp.diagnostics import Diagnostic
        from olp.frontends.dsl import load_dsl

        result = load_dsl(path, station, options.params, timeout=options.timeout)
        warnings = tuple(
            Diagnostic("warning", "program", item.message, item.span) for item in result.warnings
        )
        return ParsedProgram(result.program, ignored_notes(result.ignored) + warnings)
