"""Typed readers for the values of station and robot files.

Each reader returns a plain value or raises a :class:`~olp.errors.StationError` at the value's
file:line:column that says what was expected and quotes what the user wrote (shortened), never
a Python repr. Numbers are checked against the range of their quantity (:class:`Range`), so a
value that is finite but absurd (``1e308`` mm) is named for what it is.
"""

from __future__ import annotations

import math
import unicodedata
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from olp.errors import StationError
from olp.yamlsafe import KeyPath, YamlDocument, shorten


@dataclass(frozen=True, slots=True)
class Source:
    """A station or robot file being read, and what it may reference.

    ``allow_outside``: files it names may lie outside its folder (a station's
    ``allow_outside_paths: true``, handed on to the robot file it names).
    """

    doc: YamlDocument
    allow_outside: bool = False

    @property
    def value(self) -> Any:
        return self.doc.value

    @property
    def file(self) -> str:
        return self.doc.file

    @property
    def folder(self) -> Path:
        return self.doc.folder

    def error(self, path: KeyPath, message: str) -> StationError:
        error = self.doc.error(path, message)
        assert isinstance(error, StationError)
        return error

    def shown(self, path: KeyPath) -> str:
        """What the user wrote at ``path``, quoted and shortened (``nothing`` when empty)."""
        return self.doc.shown(path)


@dataclass(frozen=True, slots=True)
class Range:
    """The values a quantity may take in a file: ``low``..``high`` in the file's units,
    ``low`` itself excluded when ``positive``."""

    what: str
    low: float
    high: float
    positive: bool = False

    def admits(self, value: float) -> bool:
        above = value > self.low if self.positive else value >= self.low
        return above and value <= self.high

    def __str__(self) -> str:
        if self.positive:
            return f"above {self.low:.15g}, at most {self.high:.15g}"
        return f"{self.low:.15g} to {self.high:.15g}"


LENGTH = Range("a length in mm", -1e6, 1e6)
SIZE = Range("a size in mm", 0.0, 1e6, positive=True)
ANGLE = Range("an angle in degrees", -1e6, 1e6)
QUATERNION = Range("a quaternion component", -2.0, 2.0)
MASS = Range("a mass in kg", 0.0, 1e5, positive=True)
SPEED = Range("a joint speed in deg/s", 0.1, 1e4)
ACCELERATION = Range("a joint acceleration in deg/s²", 0.1, 1e6)
JERK = Range("a joint jerk in deg/s³", 0.1, 1e8)
PATH_ACCELERATION = Range("a TCP path acceleration in m/s²", 1e-3, 1e3)

MAX_CONTROLLER_INTEGER = 2**31 - 1
MAX_NAME = 100
"""Longest name (tool, frame, part ...) in characters."""


def kind(value: Any) -> str:
    """What sort of YAML value ``value`` is, in words."""
    if value is None:
        return "nothing"
    if isinstance(value, bool):
        return "true/false"
    if isinstance(value, int | float):
        return "a number"
    if isinstance(value, str):
        return "text"
    return "a list" if isinstance(value, list) else "a mapping"


def got(src: Source, value: Any, path: KeyPath) -> str:
    """``got text '2024-01-01'``-style tail for messages."""
    shown = src.shown(path)
    return f"got {kind(value)}" if shown == "nothing" else f"got {kind(value)} {shown}"


def get(src: Source, obj: Any, path: KeyPath, key: str, required: bool = True) -> Any:
    """``obj[key]`` of the mapping at ``path``; a located error if missing and required."""
    if not isinstance(obj, dict):
        raise src.error(path, f"expected a mapping, {got(src, obj, path)}")
    if key not in obj:
        if required:
            raise src.error(path, f"missing required key '{key}'")
        return None
    return obj[key]


def check_keys(src: Source, obj: Any, path: KeyPath, allowed: set[str]) -> None:
    """``obj`` is a mapping whose keys are all in ``allowed``."""
    if not isinstance(obj, dict):
        raise src.error(path, f"expected a mapping, {got(src, obj, path)}")
    for key in obj:
        if key not in allowed:
            raise src.error(
                (*path, key),
                f"unknown key '{shorten(key)}' (expected one of: {', '.join(sorted(allowed))})",
            )


def number(src: Source, value: Any, path: KeyPath, quantity: Range) -> float:
    """A finite number within ``quantity``'s range, as a float in the file's units."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise src.error(path, f"expected a number ({quantity.what}), {got(src, value, path)}")
    if isinstance(value, float) and not math.isfinite(value):
        raise src.error(path, f"expected a finite number ({quantity.what}), got {src.shown(path)}")
    if quantity.positive and quantity.low == 0 and value <= 0:
        raise src.error(
            path, f"expected a positive number ({quantity.what}), got {src.shown(path)}"
        )
    if not quantity.admits(value):  # exact for ints of any size: no conversion yet
        raise src.error(path, f"{src.shown(path)} is out of range for {quantity.what} ({quantity})")
    return float(value)


def numbers(src: Source, value: Any, path: KeyPath, count: int, quantity: Range) -> np.ndarray:
    """A list of exactly ``count`` numbers within range: shape (count,), file units."""
    if not isinstance(value, list) or len(value) != count:
        length = f" of {len(value)}" if isinstance(value, list) else ""
        raise src.error(
            path,
            f"expected a list of {count} numbers ({quantity.what}), "
            f"got {kind(value)}{length} {src.shown(path)}".rstrip(),
        )
    return np.array([number(src, v, (*path, i), quantity) for i, v in enumerate(value)])


def integer(src: Source, value: Any, path: KeyPath, low: int, high: int) -> int:
    """A whole number in ``low..high``."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise src.error(path, f"expected a whole number, {got(src, value, path)}")
    if not low <= value <= high:
        raise src.error(path, f"{src.shown(path)} is out of range (expected {low} to {high})")
    return value


def text(src: Source, value: Any, path: KeyPath) -> str:
    """Non-empty text."""
    if not isinstance(value, str) or not value:
        raise src.error(path, f"expected a non-empty text, {got(src, value, path)}")
    return value


def name(src: Source, value: Any, path: KeyPath) -> str:
    """A name: text of at most :data:`MAX_NAME` characters on one line, without control or
    formatting characters (which could hide or rewrite what a report or robot program shows)."""
    result = text(src, value, path)
    if len(result) > MAX_NAME:
        raise src.error(path, f"a name has at most {MAX_NAME} characters, this one {len(result)}")
    for char in result:
        if unicodedata.category(char) in ("Cc", "Cf", "Zl", "Zp"):
            raise src.error(
                path,
                f"a name cannot hold the control character U+{ord(char):04X} "
                f"({unicodedata.name(char, 'unnamed')})",
            )
    return result


def flag(src: Source, value: Any, path: KeyPath) -> bool:
    """``true`` or ``false``."""
    if not isinstance(value, bool):
        raise src.error(path, f"expected true or false, {got(src, value, path)}")
    return value


def items(src: Source, value: Any, path: KeyPath) -> list[Any]:
    """A list (nothing counts as an empty list)."""
    if value is None:
        return []
    if not isinstance(value, list):
        raise src.error(path, f"expected a list, {got(src, value, path)}")
    return value


def referenced_file(src: Source, value: Any, path: KeyPath) -> Path:
    """A file the document names, relative to its folder, that exists.

    It must lie inside that folder (after following symbolic links, so a link out of the
    folder counts as outside) unless the station allows outside paths; whether it may be read
    (a regular file, not too big) is for its reader to check.
    """
    written = text(src, value, path)
    file = src.folder / written
    real = file.resolve()
    if not src.allow_outside and not real.is_relative_to(src.folder.resolve()):
        raise src.error(
            path,
            f"'{shorten(written)}' lies outside the folder of {Path(src.file).name} (it is "
            f"{shorten(str(real))}); a station reads only files inside its folder unless it "
            "says 'allow_outside_paths: true'",
        )
    if not real.exists():
        raise src.error(path, f"no such file: {shorten(written)} (looked in {src.folder})")
    return real
