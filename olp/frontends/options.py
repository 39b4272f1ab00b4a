"""What a frontend's options look like: frozen dataclasses whose fields say how the command line
spells them, and the options every toolpath frontend shares.

A field that the command line may set carries a :class:`Flag` in its metadata (built with
:func:`cli`): the flag, its help, and how its text becomes the field's value. The ``olp`` commands
build one argument group per frontend from these (:mod:`olp.commands.options`); a library caller
builds the dataclass directly, in SI-free edge units (mm, deg) as documented per field.

This module imports nothing heavy: the command line reads it to build ``olp build --help``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from olp.errors import UsageError

CLI_KEY = "olp.cli"
"""The key of a field's :class:`Flag` in its dataclass metadata."""


@dataclass(frozen=True, slots=True)
class Flag:
    """How one option field is given on the command line.

    ``name``: the flag (``"--config-dat"``); ``help``: its help text; ``metavar``: the value's
    placeholder in the help (argparse's ``choices`` are shown when there is none);
    ``parse``: the command-line text (a list of texts if ``repeatable``) -> the field's value;
    it raises :class:`ValueError` (the message says what was expected) or a
    :class:`~olp.errors.UsageError`; ``choices``: the allowed texts, checked by argparse.
    """

    name: str
    help: str
    metavar: str | None = None
    parse: Callable[[Any], object] = str
    choices: tuple[str, ...] | None = None
    repeatable: bool = False


def cli(
    name: str,
    help: str,
    *,
    metavar: str | None = None,
    parse: Callable[[Any], object] = str,
    choices: tuple[str, ...] | None = None,
    repeatable: bool = False,
) -> Mapping[str, Flag]:
    """Field metadata giving a field its command-line flag:
    ``tool: str | None = field(default=None, metadata=cli("--tool", "station tool ..."))``."""
    return {CLI_KEY: Flag(name, help, metavar, parse, choices, repeatable)}


def number(text: str) -> float:
    """A finite number from command-line text (the field's own check bounds it further)."""
    try:
        value = float(text)
    except ValueError:
        raise ValueError("expected a number") from None
    if not math.isfinite(value):
        raise ValueError("expected a finite number")
    return value


def whole_number(text: str) -> int:
    """An integer from command-line text."""
    try:
        return int(text)
    except ValueError:
        raise ValueError("expected a whole number") from None


EULER_ALIASES = {"wpr": "xyz", "abc": "ZYX"}
"""Other names of Euler sequences: Fanuc's W, P, R and KUKA's A, B, C."""


def euler_sequence(text: str) -> str:
    """A validated scipy-style Euler sequence (``"xyz"``, ``"ZYX"``, ``"ZYZ"``, ...) or alias."""
    seq = EULER_ALIASES.get(text, text)
    lowered = seq.lower()
    valid = (
        len(seq) == 3
        and (seq.isupper() or seq.islower())
        and set(lowered) <= set("xyz")
        and lowered[0] != lowered[1]
        and lowered[1] != lowered[2]
    )
    if not valid:
        raise UsageError(
            f"Euler sequence {text!r}: expected three axis letters such as 'xyz' (extrinsic) or "
            "'ZYX' (intrinsic), or an alias: " + ", ".join(EULER_ALIASES)
        )
    return seq


def orientation_text(text: str) -> tuple[float, float, float] | None:
    """``--orientation``: three angles in degrees (``180,0,0`` or ``180;0;0``), or ``home``."""
    if text.strip().lower() == "home":
        return None
    try:
        values = tuple(float(v) for v in text.replace(";", ",").split(","))
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise ValueError("expected three angles in degrees, like 180,0,0")
    return values[0], values[1], values[2]


@dataclass(frozen=True, slots=True, kw_only=True)
class ToolpathOptions:
    """Options every toolpath frontend shares (CSV today; G-code or APT would extend this).

    ``tool``, ``frame``: station names (default: the station's first tool, and the world);
    ``orientation``: three angles in degrees in the ``euler`` convention, kept by every point of
    a file without angles (None: the TCP orientation at the robot's home position);
    ``euler``: the convention of ``orientation`` and of a file's angle columns (a scipy-style
    sequence, see :func:`euler_sequence`); ``speed`` (mm/s): the TCP speed where the file gives
    none; ``zone`` (mm): the rounding of the linear moves.
    """

    tool: str | None = field(
        default=None,
        metadata=cli(
            "--tool", "station tool the points are for (default: its first tool)", metavar="NAME"
        ),
    )
    frame: str | None = field(
        default=None,
        metadata=cli("--frame", "station frame the points are in (default: world)", metavar="NAME"),
    )
    orientation: tuple[float, float, float] | None = field(
        default=None,
        metadata=cli(
            "--orientation",
            "files without angles: the orientation in degrees in the --euler convention "
            "(default: the TCP orientation at the robot's home position); with a leading minus "
            "write --orientation=-90,0,0",
            metavar="A1,A2,A3",
            parse=orientation_text,
        ),
    )
    euler: str = field(
        default="xyz",
        metadata=cli(
            "--euler",
            "angles: 'xyz' = W,P,R with Rz(R)Ry(P)Rx(W) (default), 'ZYX' = KUKA A,B,C, "
            "any scipy-style sequence",
            metavar="SEQ",
        ),
    )
    speed: float | None = field(
        default=None,
        metadata=cli(
            "--speed", "TCP speed where the file gives none", metavar="MM_S", parse=number
        ),
    )
    zone: float = field(
        default=0.0,
        metadata=cli("--zone", "rounding of the linear moves", metavar="MM", parse=number),
    )

    def __post_init__(self) -> None:
        object.__setattr__(self, "euler", euler_sequence(self.euler))
        if self.speed is not None and not (math.isfinite(self.speed) and self.speed > 0):
            raise UsageError(f"toolpath speed must be a positive number of mm/s, got {self.speed}")
        if not (math.isfinite(self.zone) and self.zone >= 0):
            raise UsageError(f"toolpath zone must be >= 0 mm, got {self.zone}")
        if self.orientation is not None:
            values = tuple(float(v) for v in self.orientation)
            if len(values) != 3 or not all(math.isfinite(v) for v in values):
                raise UsageError(f"orientation needs three finite angles, got {self.orientation}")
            object.__setattr__(self, "orientation", values)
