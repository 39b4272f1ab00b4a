"""Numbers a post writes: each quantity has a format, a controller range and a resolution, and
every printed number is read back and checked against them.

A value that does not survive printing moves the robot somewhere else than olp checked and timed:
``$VEL.CP = 0.000004`` printed with five decimals is ``0.00000``, a speed the controller refuses
or reads as zero, and ``WAIT SEC 1E300`` overflows the controller's 32-bit REAL. So a post states,
per quantity, how it prints (:class:`NumberFormat`), and :func:`format_number` /
:func:`format_numbers` refuse (with :class:`NumberError`) any value that

* is not finite,
* lies outside the controller's range for it (``low``/``high``; an open ``low`` for quantities
  that must be positive, such as speeds), after printing: a positive speed that prints as 0 is
  refused, or
* does not read back, *as the controller stores it* (``storage``: a 32-bit REAL, a 64-bit float,
  or an integer), within the quantity's ``resolution`` of the value: a base frame 1 km from the
  world cannot be held to 10 µm by a 32-bit REAL.

Values are given in the printed unit (mm, deg, m/s ... as the post writes them); the post scales
from SI before it calls these functions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

Storage = Literal["real32", "real64", "int"]

REAL32_MAX = float(np.finfo(np.float32).max)
"""The largest finite 32-bit float, about 3.4E+38: KRL REAL and RAPID num (IEEE 754 single
precision: ABB's RAPID reference on ``num``; KUKA's REAL range ±3.4E+38 as commonly documented,
medium confidence)."""


class NumberError(ValueError):
    """A value a post cannot print faithfully; the message says which quantity and why."""


@dataclass(frozen=True, slots=True)
class NumberFormat:
    """How one quantity is printed and what the controller accepts.

    ``what``: the quantity as a user reads it (``"path speed $VEL.CP"``); ``unit``: the printed
    unit; ``decimals``: fixed-point decimals (0 for integers); ``low``/``high``: the controller's
    range in the printed unit (``low_open``: ``low`` itself is excluded); ``storage``: how the
    controller holds the value; ``resolution``: the largest acceptable difference between the
    value and what the controller holds (printed unit; 0 means half the last printed digit);
    ``compact``: trailing zeros (and a bare point) are dropped, as RAPID data are written.
    """

    what: str
    unit: str
    decimals: int
    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False
    storage: Storage = "real64"
    resolution: float = 0.0
    compact: bool = False

    @property
    def tolerance(self) -> float:
        half_digit = 0.5 * 10.0 ** (-self.decimals)
        return max(self.resolution, half_digit) * (1 + 1e-9)

    def bounds(self) -> tuple[float, float]:
        """The range actually accepted, the storage's range included."""
        if self.storage == "real32":
            return max(self.low, -REAL32_MAX), min(self.high, REAL32_MAX)
        if self.storage == "int":
            return max(self.low, -(2.0**31)), min(self.high, 2.0**31 - 1)
        return self.low, self.high


def _spell(value: float, decimals: int, compact: bool) -> str:
    text = f"{value:.{decimals}f}"
    if text.startswith("-") and float(text) == 0.0:
        text = text[1:]
    if compact and "." in text:
        text = text.rstrip("0").rstrip(".")
    return text


def _stored(printed: float, storage: Storage) -> float:
    if storage == "real32":
        return float(np.float32(printed))
    if storage == "int":
        return float(round(printed))
    return printed


def _stored_array(printed: np.ndarray, storage: Storage) -> np.ndarray:
    if storage == "real32":
        return printed.astype(np.float32).astype(np.float64)
    return np.round(printed) if storage == "int" else printed


def format_number(value: float, fmt: NumberFormat) -> str:
    """``value`` (printed unit) as the controller reads it; raises :class:`NumberError`."""
    v = float(value)
    if not math.isfinite(v):
        raise NumberError(f"{fmt.what} is {v!r} {fmt.unit}: not a number a controller can hold")
    low, high = fmt.bounds()
    if abs(v) > 1e300 or (fmt.storage != "real64" and abs(v) > 2 * max(abs(low), abs(high))):
        raise NumberError(_range_message(fmt, _short(v), low, high))
    text = _spell(v, fmt.decimals, fmt.compact)
    printed = float(text)
    if printed < low or printed > high or (fmt.low_open and printed <= low):
        raise NumberError(_range_message(fmt, text, low, high, v))
    if abs(_stored(printed, fmt.storage) - v) > fmt.tolerance:
        raise NumberError(
            f"{fmt.what} {_short(v)} {fmt.unit} cannot be held by the controller's "
            f"{_storage_name(fmt.storage)} to {_short(fmt.tolerance)} {fmt.unit}"
        )
    return text


def format_numbers(values: ArrayLike, fmt: NumberFormat) -> list[str]:
    """:func:`format_number` for many values (N,): spelled one by one, checked at once with
    numpy; the error names the first bad value and its position."""
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    low, high = fmt.bounds()
    sane = np.isfinite(v) & (np.abs(v) <= 1e300)
    if np.all(sane):
        texts = [_spell(x, fmt.decimals, fmt.compact) for x in v.tolist()]
        printed = np.array([float(t) for t in texts]) if texts else np.zeros(0)
        stored = (
            printed.astype(np.float32).astype(np.float64) if fmt.storage == "real32" else printed
        )
        if fmt.storage == "int":
            stored = np.round(printed)
        inside = (printed >= low) & (printed <= high) & ~(fmt.low_open & (printed <= low))
        if np.all(inside & (np.abs(stored - v) <= fmt.tolerance)):
            return texts
        first = int(np.argmax(~(inside & (np.abs(stored - v) <= fmt.tolerance))))
    else:
        first = int(np.argmax(~sane))
    try:
        format_number(float(v[first]), fmt)
    except NumberError as exc:
        raise NumberError(f"{exc} (value {first + 1} of {v.size})") from None
    raise AssertionError("format_numbers: a value failed the vectorised check only")


def _range_message(
    fmt: NumberFormat, text: str, low: float, high: float, value: float | None = None
) -> str:
    printed = "" if value is None or _short(value) == text else f" (printed as {text})"
    shown = _short(value) if value is not None else text
    lo = "-inf" if low == -math.inf else _short(low)
    hi = "inf" if high == math.inf else _short(high)
    bracket = "(" if fmt.low_open else "["
    return (
        f"{fmt.what} {shown} {fmt.unit}{printed} is outside the controller's range "
        f"{bracket}{lo}, {hi}] {fmt.unit}"
    )


def _short(value: float) -> str:
    return f"{value:.6g}"


def _storage_name(storage: Storage) -> str:
    return {"real32": "32-bit REAL", "real64": "64-bit float", "int": "INT"}[storage]
