"""Numbers in diagnostics, printed so that the text shows what the check found.

A check compares exact floats; a message that rounds them can contradict itself ("170.00° is
outside -170° .. 170°", "at 0% of the move" for a fault just after the start, a 300-digit
distance). These helpers print a value with as many decimals as it takes to show the finding,
limits with their exact value, and huge or non-finite values in a short form. Independent of
the locale (Python's format mini-language never reads it).
"""

from __future__ import annotations

import math

_MAX_DECIMALS = 12
"""Most decimals printed: a check's own tolerance (1e-9 rad = 5.7e-8°) shows at 8."""

_PLAIN_LIMIT = 1e9
"""Larger magnitudes print in exponent form (``1e+40``), never as dozens of digits."""


def exact(value: float) -> str:
    """A value as short as it reads back: ``170``, ``-190``, ``170.5``, ``1e+40``, ``inf``.

    Rounded to 9 decimals first, so that a limit given in degrees and stored in radians (170°
    becomes 170.00000000000003° on the way back) prints as it was written.
    """
    if not math.isfinite(value) or abs(value) >= _PLAIN_LIMIT:
        return f"{value:.6g}"
    text = f"{round(value, 9) + 0.0:.9f}".rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def outside(value: float, lower: float, upper: float, decimals: int = 2) -> str:
    """``value`` with at least ``decimals`` decimals and as many more as it takes (up to 12)
    for the printed value to lie outside ``[lower, upper]`` as :func:`exact` prints them."""
    if not math.isfinite(value) or abs(value) >= _PLAIN_LIMIT:
        return f"{value:.6g}"
    low, high = float(exact(lower)), float(exact(upper))
    for places in range(decimals, _MAX_DECIMALS + 1):
        shown = round(value, places)
        if shown < low or shown > high:
            return f"{shown:.{places}f}"
    return f"{value:.{_MAX_DECIMALS}f}"


def above(value: float, limit: float, decimals: int = 0) -> tuple[str, str]:
    """``value`` and ``limit`` printed with the same decimals, at least ``decimals`` and as many
    more as it takes (up to 12) for the first to read larger than the second."""
    for places in range(decimals, _MAX_DECIMALS + 1):
        if round(value, places) > round(limit, places):
            return f"{value:.{places}f}", f"{limit:.{places}f}"
    return f"{value:.{_MAX_DECIMALS}f}", f"{limit:.{_MAX_DECIMALS}f}"


def percent(fraction: float) -> str:
    """A position along a move, ``0.37`` -> ``37%``; never ``0%`` or ``100%`` for a point
    strictly inside the move (``0.3%``, ``99.96%``)."""
    if fraction <= 0.0 or fraction >= 1.0:
        return f"{fraction:.0%}"
    for places in range(0, 7):
        if 0.0 < round(fraction * 100, places) < 100.0:
            return f"{fraction:.{places}%}"
    return f"{fraction * 100:.2g}%" if fraction < 0.5 else f"{fraction * 100:.12g}%"


def quantity(value: float, decimals: int = 1) -> str:
    """A measured quantity with ``decimals`` decimals, or in significant digits when that would
    print it as zero (``0.0004``) or with more than a few digits (``1e+08``)."""
    if not math.isfinite(value) or abs(value) >= 1e6:
        return f"{value:.4g}"
    if value != 0.0 and round(value, decimals) == 0.0:
        return f"{value:.2g}"
    return f"{value:.{decimals}f}"
