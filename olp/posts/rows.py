"""Runs of linear moves written by a post's row writer instead of one template pass per move.

A toolpath is a long run of linear moves; a template evaluated once per move spends most of a
big build in Jinja's sandbox (each attribute lookup is checked). A post with a row writer
(:attr:`olp.posts.base.Post.ROWS`) whose templates declare ``rows: true`` in ``post.yaml`` gets
each maximal run of consecutive linear moves as one :class:`PostRows` step (``kind`` ``"rows"``)
and writes its lines in Python, formatting the numbers of the run column by column
(:meth:`olp.posts.base.Post.number_column`). The text is the same, byte for byte, as the
template's for the same moves (``tests/posts/test_rows.py`` renders both ways); headers, data
sections and every other instruction stay templates.

A post whose row writer also takes columns (:attr:`olp.posts.base.Post.COLUMNS`) gets a dense
toolpath's rows without any object per row: one :class:`~olp.posts.view.RowColumns` item per
block (or per piece of a block in a split program) holding the block's arrays, its change flags
computed over them; numbers are spelled and checked as whole columns (:func:`number_column`,
exactly as :func:`olp.posts.numbers.format_number` spells each:
``tests/posts/test_row_columns.py``).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.posts.numbers import NumberFormat, _spell
from olp.posts.view import PostStep, RowColumns

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class PostRows:
    """Consecutive linear moves (``steps``, each a :class:`~olp.posts.view.PostStep`) written
    by the post's row writer. ``motion`` is 0 so that a template's motion branch skips it; its
    ``index``, ``source`` and ``instruction`` are the first move's (where an error without a
    row of its own is reported)."""

    steps: tuple[PostStep, ...]
    kind: str = "rows"
    motion: int = 0

    @property
    def index(self) -> int:
        return self.steps[0].index

    @property
    def source(self) -> str:
        return self.steps[0].source

    @property
    def instruction(self) -> Any:
        return self.steps[0].instruction

    def __len__(self) -> int:
        return len(self.steps)

    def poses(self) -> FloatArray:
        """The targets (n, 4, 4) m in each move's frame."""
        return np.stack([s.pose for s in self.steps])  # type: ignore[misc]


def group_rows(
    steps: Sequence[PostStep | RowColumns],
) -> list[PostStep | PostRows | RowColumns]:
    """``steps`` with every maximal run of consecutive linear moves as one :class:`PostRows`
    (a toolpath's :class:`~olp.posts.view.RowColumns` stay as they are). A spline motion
    (:attr:`olp.ir.LinearMove.spline`) is not a row: the row writers write the plain one."""
    out: list[PostStep | PostRows | RowColumns] = []
    run: list[PostStep] = []
    for step in steps:
        if (
            isinstance(step, PostStep)
            and step.kind == "linear"
            and step.motion
            and not getattr(step.instruction, "spline", False)
        ):
            run.append(step)
            continue
        if run:
            out.append(PostRows(tuple(run)))
            run = []
        out.append(step)
    if run:
        out.append(PostRows(tuple(run)))
    return out


def spell_column(values: ArrayLike, decimals: int, compact: bool = False) -> NDArray[np.str_]:
    """``format(v, f".{decimals}f")`` of every value (N,), as :mod:`olp.posts.numbers` spells
    one (:func:`_spelled`)."""
    return _spelled(np.asarray(values, dtype=np.float64).reshape(-1), decimals, compact)[0]


def _spelled(v: FloatArray, decimals: int, compact: bool) -> tuple[NDArray[np.str_], FloatArray]:
    """``format(v, f".{decimals}f")`` of values (N,) and the doubles the texts read back as:
    as :func:`olp.posts.numbers.format_number` spells one (``-0.000`` is written ``0.000``;
    ``compact`` drops trailing zeros and a bare point), formatted as integers with numpy.

    A value times ``10**decimals`` is rounded to the nearest integer, which is what Python's
    correctly rounded formatting gives: the rounded product lies on the same side of a half
    as the exact one, unless it is the half itself; then the product's rounding error says
    which side (:func:`_half_rounded`). Values too large for exact integers, or not finite,
    are spelled by Python itself.
    """
    scale = 10.0**decimals
    with np.errstate(invalid="ignore", over="ignore"):
        p = v * scale
        r = np.rint(p)
        slow = ~(np.abs(p) < 2.0**50)
        half = np.abs(p - np.trunc(p)) == 0.5
    if np.any(half):
        r[half] = _half_rounded(v[half], scale, p[half])
    r[slow] = 0.0
    whole = np.abs(r).astype(np.int64)
    if decimals == 0:
        body = _integers(whole)
    else:
        head, tail = np.divmod(whole, 10**decimals)
        if decimals <= _TABLE_DECIMALS:
            tails = _fractions(decimals)[tail]
        elif decimals <= 2 * _TABLE_DECIMALS:
            # the first five digits and the rest, each by table look-up (ABB's quaternions: 9)
            rest = decimals - _TABLE_DECIMALS
            high, low = np.divmod(tail, 10**rest)
            tails = np.strings.add(_fractions(_TABLE_DECIMALS)[high], _digits(rest)[low])
        else:
            tails = np.strings.add(".", np.strings.zfill(tail.astype(np.str_), decimals))
        body = np.strings.add(_integers(head), tails)
    text = np.where(r < 0, np.strings.add("-", body), body)
    if compact and decimals > 0:
        text = np.strings.rstrip(np.strings.rstrip(text, "0"), ".")
    if np.any(slow):
        where = np.flatnonzero(slow)
        exact = [_spell(x, decimals, compact) for x in v[where].tolist()]
        width = max(text.dtype.itemsize // 4, max(len(t) for t in exact))
        text = text.astype(f"<U{width}")
        text[where] = exact
    # What is printed, read back: integer / 10**decimals is one correctly rounded division,
    # the same double as parsing the text.
    printed = r / scale
    if np.any(slow):
        printed[slow] = [float(t) for t in exact]
    return text, printed


def _half_rounded(v: FloatArray, scale: float, p: FloatArray) -> FloatArray:
    """The integers nearest to the exact products ``v * scale`` whose rounded products ``p``
    are halves (``k + 0.5``, ``|p| < 2**50``): above the half where the product's rounding
    error is positive, below where it is negative, and an exact half to even (as Python's
    formatting, and :func:`numpy.rint`, round it)."""
    error = _product_error(v, scale, p)
    low = np.floor(p)
    return np.where(error > 0.0, low + 1.0, np.where(error < 0.0, low, np.rint(p)))


_SPLIT = 134217729.0
"""2**27 + 1: Veltkamp's splitting constant for doubles."""


def _product_error(a: FloatArray, b: float, p: FloatArray) -> FloatArray:
    """``a * b - p`` exactly, where ``p`` is the rounded product ``a * b`` (Dekker's exact
    product: each factor split into halves of 26 bits, whose products are exact; no
    overflow below 2**995, no underflow for products above 2**-969)."""

    def halves(x: Any) -> tuple[Any, Any]:
        c = _SPLIT * x
        high = c - (c - x)
        return high, x - high

    a_high, a_low = halves(a)
    b_high, b_low = halves(np.float64(b))
    return ((a_high * b_high - p) + a_high * b_low + a_low * b_high) + a_low * b_low


def number_column(values: ArrayLike, fmt: NumberFormat) -> tuple[NDArray[np.str_], bool]:
    """Every value (N,) spelled in ``fmt`` (:func:`spell_column`) and whether all of them pass
    :func:`olp.posts.numbers.format_number`'s checks (range after printing, what the
    controller's storage holds), checked at once."""
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    if v.size == 0:
        return np.zeros(0, dtype="<U1"), True
    if not np.all(np.isfinite(v) & (np.abs(v) <= 1e300)):
        return np.zeros(0, dtype="<U1"), False
    texts, printed = _spelled(v, fmt.decimals, fmt.compact)
    low, high = fmt.bounds()
    with np.errstate(over="ignore", invalid="ignore"):
        if fmt.storage == "real32":
            stored = printed.astype(np.float32).astype(np.float64)
        elif fmt.storage == "int":
            stored = np.round(printed)
        else:
            stored = printed
        sane = np.abs(v) <= 2 * max(abs(low), abs(high)) if fmt.storage != "real64" else True
        inside = (printed >= low) & (printed <= high) & ~(fmt.low_open & (printed <= low))
        ok = bool(np.all(sane & inside & (np.abs(stored - v) <= fmt.tolerance)))
    return texts, ok


_TABLE_DECIMALS = 5
"""Fractions of up to this many decimals are spelled by table look-up (10**5 entries)."""

_SMALL = 1 << 17
"""Integers below this are spelled by table look-up (faster than numpy's own conversion)."""


@functools.cache
def _small_integers() -> NDArray[np.str_]:
    """``0`` ... ``131071``: below 1000 as Python spells them, then each thousand's number
    followed by three digits (the table made of tables, without a Python string per entry)."""
    thousands = np.array([str(k) for k in range(1, -(-_SMALL // 1000))])
    above = np.strings.add(thousands[:, None], _digits(3)[None, :]).ravel()
    below = np.array([str(k) for k in range(1000)], dtype=above.dtype)
    return np.concatenate([below, above])[:_SMALL]


@functools.cache
def _fractions(decimals: int) -> NDArray[np.str_]:
    """``.000`` ... ``.999`` for ``decimals`` 3: the point and the digits of every fraction."""
    return np.strings.add(".", _digits(decimals))


@functools.cache
def _digits(count: int) -> NDArray[np.str_]:
    """``000`` ... ``999`` for ``count`` 3: every ``count``-digit string, zero-padded, in
    order (made digit by digit from the shorter table, without a Python string per entry)."""
    one = np.array(list("0123456789"))
    if count == 1:
        return one
    return np.strings.add(one[:, None], _digits(count - 1)[None, :]).ravel()


def _integers(values: NDArray[np.int64]) -> NDArray[np.str_]:
    """Non-negative integers (N,) in decimal."""
    if values.size and int(values.max()) < _SMALL:
        return _small_integers()[values]
    return values.astype(np.str_)
