"""Read the common simple motion lines of KRL without lark.

Milling programs are 10k-100k lines like ``LIN {X 12.5,Y -3,Z 6.35,A 180,B 0,C -180} C_DIS``.
lark spends most of its time on them, so :func:`scan_line` recognises exactly this shape with one
regular expression and returns a :class:`~olp.frontends.krl.ast.FastMotion`; every other line
(and any line this module is not sure about) goes through the full grammar.

The accepted shape is a strict subset of what ``grammars/krl.lark`` accepts, chosen so that the
result is the same as the grammar's, spans included (pinned by tests that compare both paths):

* keyword ``PTP``, ``LIN``, ``SPTP`` or ``SLIN``, then one aggregate, then approximation keywords,
  then an optional comment;
* members named only ``X Y Z A B C S T A1..A6 E1..E6`` (none is a KRL keyword, so the lexer
  cannot read them differently), an optional type ``E6POS POS FRAME AXIS E6AXIS``;
* values that are plain signed numbers, each followed by ``,`` or ``}``.

CAM posts write one shape of LIN line, always the same way (``LIN {X 1.000,Y -2.500,Z 6.350,
A -180.000,B 0.000,C -180.000} C_DIS``). :class:`RowReader` takes consecutive lines of exactly
that shape (a strict subset of what :func:`scan_line` accepts) as :class:`LinRows`: one regular
expression per line, and the numbers of the whole run converted by numpy in one call.
"""

from __future__ import annotations

import re

import numpy as np

from olp import ir
from olp.frontends.krl.ast import Aggregate, FastMotion, LinRows, Member, MotionStmt, Num

# A character that continues a KRL name: where a keyword or member name must not be followed by one.
_NAME_CHAR = r"[a-z0-9_$]"
_WS = r"[ \t]*"
# No blank after the sign (the grammar allows one): then float() reads the token as it stands.
_NUMBER = r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:e[+-]?\d+)?"
_MEMBER_NAME = rf"(?:[xyzabcst]|[ae][1-6])(?!{_NAME_CHAR})"
_MEMBER = rf"{_WS}({_MEMBER_NAME}){_WS}({_NUMBER}){_WS}"
_TYPE = rf"{_WS}(e6pos|pos|frame|axis|e6axis){_WS}:"
_APPROX = rf"c_(?:ptp|dis|vel|ori)(?!{_NAME_CHAR})"
_ANY_MEMBER = rf"{_WS}{_MEMBER_NAME}{_WS}{_NUMBER}{_WS}"
_ANY_TYPE = rf"{_WS}(?:e6pos|pos|frame|axis|e6axis){_WS}:"

# Groups: 1 keyword, 2 aggregate, 3 approximation keywords.
_LINE = re.compile(
    rf"{_WS}(sptp|slin|ptp|lin){_WS}"
    rf"(\{{(?:{_ANY_TYPE})?(?:{_ANY_MEMBER},)*{_ANY_MEMBER}\}})"
    rf"((?:{_WS}{_APPROX})*)"
    rf"{_WS}(?:;.*)?\r?",
    re.IGNORECASE,
)
# The exact CAM shape, in column 1: keyword, member names and C_DIS upper case, no blanks but
# the one after each name. Groups: 1-6 the numbers X..C, 7 the approximation (or None).
_ROW_NUMBER = _NUMBER.replace("e[+-]", "[eE][+-]")
_ROW = re.compile(
    rf"LIN \{{X ({_ROW_NUMBER}),Y ({_ROW_NUMBER}),Z ({_ROW_NUMBER}),"
    rf"A ({_ROW_NUMBER}),B ({_ROW_NUMBER}),C ({_ROW_NUMBER})\}}( C_DIS)?\r?"
)
row_match = _ROW.fullmatch
_MEMBERS = re.compile(_MEMBER, re.IGNORECASE)
_TYPE_PREFIX = re.compile(_TYPE, re.IGNORECASE)
_APPROX_WORD = re.compile(_APPROX, re.IGNORECASE)


def signed_number(token: str) -> tuple[float, bool]:
    """The value of a ``SIGNED_NUMBER`` token (sign, blanks, digits) and whether it is an integer.

    ``-0.000`` is ``-0.0``, as the grammar's path reads it too.
    """
    digits = "".join(token.split()).lstrip("+-")
    value = float(digits)
    return (-value if token.startswith("-") else value), digits.isdigit()


def scan_line(line: str, number: int, filename: str) -> FastMotion | None:
    """The simple motion on ``line`` (1-based line ``number``), or None for anything else."""
    match = _LINE.fullmatch(line)
    if match is None:
        return None
    aggregate = match.group(2)
    prefix = _TYPE_PREFIX.match(aggregate, 1)
    start = 1 if prefix is None else prefix.end()
    names, values = zip(*_MEMBERS.findall(aggregate, start), strict=True)
    approx = tuple(word.upper() for word in _APPROX_WORD.findall(match.group(3)))
    end = match.end(3) if approx else match.end(2)
    span = ir.SourceSpan(filename, number, match.start(1) + 1, number, end + 1)
    type_name = None if prefix is None else prefix.group(1)
    keyword = match.group(1).upper()
    numbers = tuple(map(float, values))
    return FastMotion(keyword, type_name, tuple(map(str.upper, names)), numbers, approx, span, line)


def materialise(fast: FastMotion) -> MotionStmt:
    """The full :class:`MotionStmt` of a fast line, with the spans the grammar would give."""
    match = _LINE.fullmatch(fast.text)
    assert match is not None, "a FastMotion always comes from a matching line"
    file, number = fast.span.file, fast.span.line

    def span(start: int, end: int) -> ir.SourceSpan:
        return ir.SourceSpan(file, number, start + 1, number, end + 1)

    agg_start = match.start(2)
    prefix = _TYPE_PREFIX.match(fast.text, agg_start + 1)
    position = agg_start + 1 if prefix is None else prefix.end()
    members = []
    for found in _MEMBERS.finditer(fast.text, position, match.end(2)):
        value, is_int = signed_number(found.group(2))
        num = Num(value, is_int, span(found.start(2), found.end(2)))
        members.append(Member(found.group(1), num, span(found.start(1), found.end(2))))
    type_name = None if prefix is None else prefix.group(1)
    aggregate = Aggregate(type_name, tuple(members), span(agg_start, match.end(2)))
    return MotionStmt(fast.keyword, (aggregate,), None, fast.approx, fast.span)


class RowReader:
    """Collects consecutive lines of the CAM shape (``row_match``) into one :class:`LinRows`.

    Per line only the match and its number are kept (:meth:`add` is two appends: it runs for
    every line of a toolpath); :meth:`flush` takes the run's numbers apart in bulk.
    """

    def __init__(self, filename: str) -> None:
        self.filename = filename
        self.matches: list[re.Match[str]] = []
        self.lines: list[int] = []

    def add(self, match: re.Match[str], number: int) -> None:
        """Line ``number`` (1-based), matched by ``row_match``."""
        self.matches.append(match)
        self.lines.append(number)

    def flush(self) -> list[LinRows]:
        """The rows collected since the last flush (none or one :class:`LinRows`)."""
        matches = self.matches
        if not matches:
            return []
        numbers = [number for m in matches for number in m.group(1, 2, 3, 4, 5, 6)]
        # numpy reads each token as float() does (correctly rounded, "-0.000" is -0.0).
        values = np.array(numbers, dtype=np.float64).reshape(-1, 6)
        approx_ends = np.array([m.end(7) for m in matches], dtype=np.int64)
        approx = approx_ends >= 0
        # End column (1-based, exclusive): after C_DIS, else after the closing brace.
        ends = np.where(approx, approx_ends + 1, [m.end(6) + 2 for m in matches])
        lines = np.array(self.lines, dtype=np.int64)
        first, end = self.lines[0], int(ends[0])
        span = ir.SourceSpan(self.filename, first, 1, first, end)
        rows = LinRows(values, approx, lines, ends, tuple(m.string for m in matches), span)
        self.matches.clear()  # in place: the reader's caller may hold their append methods
        self.lines.clear()
        return [rows]


def row_motions(rows: LinRows) -> tuple[FastMotion, ...]:
    """The rows as the :class:`FastMotion` statements :func:`scan_line` reads from them."""
    filename = rows.span.file
    motions = tuple(
        scan_line(text, int(line), filename)
        for text, line in zip(rows.texts, rows.lines, strict=True)
    )
    assert all(m is not None for m in motions), "a row of the CAM shape is a fast line"
    return motions  # type: ignore[return-value]
