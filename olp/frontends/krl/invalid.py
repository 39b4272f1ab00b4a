"""Text that is not KRL at all: targeted errors where the controller would refuse the file too.

A syntax error of the grammar means one of two things: the file is not KRL (a bare ``TODO`` line,
``END`` closing a ``DEFFCT``, ``a=0,b=0``, ``IF a = 1``, an unclosed parenthesis, ...), or it is
KRL that olp does not read yet. The first deserves a message that says what KRL expects instead,
and a mark a program can test (:data:`olp.errors.INVALID_KRL` as the error's ``code``); the
second keeps the grammar's "unexpected ...; expected ..." message. Each check here looks at the
token the parser stopped on, what it expected there and the text of the line, and answers only
where KRL's own rules (KUKA System Software 8 programming manual: one statement per line, a
subroutine call with parentheses, ``==`` to compare, ``STRUC`` members separated by commas, a
``TRIGGER``'s ``DELAY``, routines closed by their own keyword and named once in a module) say
the text is wrong whatever olp can read.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass

from lark import Token

from olp import ir
from olp.errors import INVALID_KRL, ParseError
from olp.frontends.krl.ast import Module, Routine, Source
from olp.frontends.krl.comments import comment_column

_NAME = r"[A-Za-z_$][\w$]*"
_TARGET = rf"{_NAME}(?:\s*\[[^\]]*\]|\s*\.\s*{_NAME})*"
_ASSIGNMENT = re.compile(rf"\s*({_TARGET})\s*=(?!=)")
_CONDITION = re.compile(r"(?i)\s*(IF|WHILE|UNTIL|WAIT\s+FOR)\b")
_INTERRUPT = re.compile(r"(?i)\s*(?:GLOBAL\s+)?INTERRUPT\s+DECL\b.*?\bWHEN\b(.*?)\bDO\b")
_STRUC = re.compile(r"(?i)\s*(?:GLOBAL\s+)?STRUC\b")
_TRIGGER = re.compile(r"(?i)\s*TRIGGER\b")
_OPENER = re.compile(r"(?i)\s*(?:GLOBAL\s+)?(DEFFCT|DEFDAT|DEF)\b")
_CLOSER = re.compile(r"(?i)\s*(ENDFCT|ENDDAT|END)\s*$")
_STRING = re.compile(r'"[^"]*"')

STANDALONE_WORDS = frozenset({"ASYSTOP", "ASYCONT"})
"""KRL statements of one word that olp's grammar does not know (asynchronous axes): a line of
one of them alone is KRL olp cannot read yet, not a bare name."""

_CLOSES = {"_END": ("END", "DEF"), "_ENDFCT": ("ENDFCT", "DEFFCT"), "_ENDDAT": ("ENDDAT", "DEFDAT")}
_TYPE_TOKENS = frozenset({"NAME", "INT", "REAL", "BOOL", "CHAR"})


@dataclass(frozen=True)
class At:
    """Where the parser stopped: the token, the terminals it expected, how the generic message
    names the token (``found``), the file, and the token's line as code (comment cut off, the
    inside of strings blanked, so columns are kept)."""

    token: Token
    expected: frozenset[str]
    found: str
    source: Source
    code: str

    @property
    def line(self) -> int:
        return self.token.line or 0

    @property
    def column(self) -> int:
        """0-based column of the token in its line."""
        return (self.token.column or 1) - 1


def code_of(line: str) -> str:
    """``line`` without its comment, the inside of each string blanked (same length)."""
    column = comment_column(line)
    code = line if column is None else line[:column]
    return _STRING.sub(lambda m: '"' + " " * (len(m.group(0)) - 2) + '"', code)


def refused(token: Token, expected: set[str], found: str, source: Source) -> ParseError | None:
    """The targeted error for a syntax error at ``token`` if the text is not KRL, else None
    (KRL olp does not read yet, or a fault these checks do not know)."""
    line = source.line(token.line or 0)
    if token.type == "$END" or line is None:
        return None
    at = At(token, frozenset(expected), found, source, code_of(line))
    for check in CHECKS:
        error = check(at)
        if error is not None:
            return error
    return None


def _error(at: At, message: str, column: int, width: int, hint: str | None = None) -> ParseError:
    """An :data:`INVALID_KRL` ParseError on ``at``'s line, 0-based ``column``, ``width`` long."""
    span = ir.SourceSpan(at.source.filename, at.line, column + 1, at.line, column + 1 + width)
    return ParseError(message, span, at.source.line(at.line), hint, code=INVALID_KRL)


def bare_name(at: At) -> ParseError | None:
    """A line that is only a name (``TODO``): neither a call (it needs parentheses), nor an
    assignment, nor a label (``NAME:``)."""
    match = re.fullmatch(rf"\s*({_NAME})\s*", at.code)
    if at.token.type != "_NL" or not {"LPAR", "EQUAL"} <= at.expected or match is None:
        return None
    name = match.group(1)
    if name.upper() in STANDALONE_WORDS:
        return None
    return _error(
        at,
        f"a bare name is not a KRL statement: a subroutine call needs parentheses, {name}()",
        match.start(1),
        len(name),
        hint=f"an assignment is {name} = value; a label is {name}:",
    )


def wrong_closer(at: At) -> ParseError | None:
    """``END`` closing a ``DEFFCT``, or ``ENDFCT`` closing a ``DEF``."""
    if at.token.type not in ("_END", "_ENDFCT") or at.token.type in at.expected:
        return None
    other = "_ENDFCT" if at.token.type == "_END" else "_END"
    if other not in at.expected:
        return None
    word, opener = _CLOSES[at.token.type]
    right, head = _CLOSES[other]
    start = _last_line(at.source, at.line, _OPENER)
    where = f" (line {start})" if start else ""
    return _error(
        at,
        f"{word} closes a {opener}; this {head}{where} ends with {right}",
        at.column,
        len(word),
    )


def closer_without_opener(at: At) -> ParseError | None:
    """``END``, ``ENDFCT`` or ``ENDDAT`` between routines: nothing is open for it to close
    (often its ``DEF`` was commented out)."""
    if at.token.type not in _CLOSES or "_DEF" not in at.expected:
        return None
    word, opener = _CLOSES[at.token.type]
    previous = _last_line(at.source, at.line, _CLOSER)
    commented = _commented_opener(at.source, previous, at.line, opener)
    if commented:
        why = f": the {opener} of line {commented} is in a comment"
    elif previous:
        why = f" (the routine before it ends at line {previous})"
    else:
        why = ""
    message = f"{word} closes a {opener}, and no {opener} is open here{why}"
    return _error(at, message, at.column, len(word))


def two_statements(at: At) -> ParseError | None:
    """``a=0,b=0``: KRL has one statement per line; a ',' does not join assignments."""
    if at.token.type != "COMMA" or "_NL" not in at.expected:
        return None
    rest = at.code[at.column + 1 :]
    second = _ASSIGNMENT.match(rest)
    if _ASSIGNMENT.match(at.code) is None or second is None:
        return None
    statement = rest.strip()
    return _error(
        at,
        f"one statement per line: a ',' does not join assignments in KRL; write "
        f"{statement!r} on a line of its own",
        at.column,
        1,
    )


def assignment_in_condition(at: At) -> ParseError | None:
    """``IF a = 1 THEN``: ``=`` assigns; a condition compares with ``==``."""
    if at.token.type != "EQUAL":
        return None
    statement = _CONDITION.match(at.code)
    interrupt = _INTERRUPT.match(at.code)
    if statement is not None:
        keyword = " ".join(statement.group(1).upper().split())
    elif interrupt is not None and interrupt.start(1) <= at.column < interrupt.end(1):
        keyword = "INTERRUPT ... WHEN"
    else:
        return None
    return _error(at, f"'=' assigns; the condition of {keyword} compares with '=='", at.column, 1)


def unclosed_parenthesis(at: At) -> ParseError | None:
    """A '(' the line never closes."""
    if "RPAR" not in at.expected or at.token.type == "RPAR":
        return None
    opened: list[int] = []
    for index, char in enumerate(at.code):
        if char == "(":
            opened.append(index)
        elif char == ")" and opened:
            opened.pop()
    if not opened:
        return None
    column = opened[0]
    return _error(
        at,
        f"the '(' at column {column + 1} is not closed: a ')' is missing before {at.found}",
        column,
        1,
    )


def unopened_parenthesis(at: At) -> ParseError | None:
    """A ')' with no '(' before it on the line."""
    if at.token.type != "RPAR":
        return None
    before = at.code[: at.column]
    if before.count("(") > before.count(")"):
        return None
    return _error(at, "this ')' closes no '('", at.column, 1)


def struc_without_comma(at: At) -> ParseError | None:
    """``STRUC T E_A a INT i``: members are separated by commas, also where the type changes."""
    if _STRUC.match(at.code) is None or "COMMA" not in at.expected:
        return None
    if at.token.type not in _TYPE_TOKENS:
        return None
    return _error(
        at,
        f"a ',' is missing before {at.found}: the members of a STRUC are separated by commas, "
        "also where a new type begins (STRUC T INT a, b, REAL c)",
        at.column,
        len(str(at.token)),
    )


def trigger_without_delay(at: At) -> ParseError | None:
    """``TRIGGER WHEN ... DO`` without ``DELAY = time``: KRL's TRIGGER always has it."""
    if at.token.type != "_DO" or "_DELAY" not in at.expected or _TRIGGER.match(at.code) is None:
        return None
    return _error(
        at,
        "a TRIGGER needs DELAY = time (ms) before DO: TRIGGER WHEN ... DELAY = 0 DO ...",
        at.column,
        len(str(at.token)),
    )


CHECKS: tuple[Callable[[At], ParseError | None], ...] = (
    bare_name,
    wrong_closer,
    closer_without_opener,
    two_statements,
    assignment_in_condition,
    unclosed_parenthesis,
    unopened_parenthesis,
    struc_without_comma,
    trigger_without_delay,
)
"""The checks, tried in order; each answers only for its own fault."""


def check_routines(module: Module, source: Source) -> None:
    """A module names each routine once (names are case-insensitive): a second DEF or DEFFCT
    of a name is an :data:`INVALID_KRL` error naming both lines."""
    seen: dict[str, Routine] = {}
    for item in module.items:
        if not isinstance(item, Routine):
            continue
        first = seen.setdefault(item.name.upper(), item)
        if first is not item:
            message = (
                f"{item.kind} {item.name} is defined twice (lines {first.span.line} and "
                f"{item.span.line})"
            )
            hint = "a module's routines need names of their own"
            line = source.line(item.span.line)
            span = ir.SourceSpan(source.filename, item.span.line, item.span.column)
            raise ParseError(message, span, line, hint, code=INVALID_KRL)


def _last_line(source: Source, before: int, pattern: re.Pattern[str]) -> int:
    """The number of the last line before ``before`` whose code matches ``pattern``, or 0."""
    for number in range(before - 1, 0, -1):
        if pattern.match(code_of(source.line(number) or "")):
            return number
    return 0


def _commented_opener(source: Source, after: int, before: int, opener: str) -> int:
    """The line between ``after`` and ``before`` whose comment starts with ``opener``
    (``;DEFFCT INT f()``), or 0."""
    pattern = re.compile(rf"(?i)\s*(?:GLOBAL\s+)?{opener}\b")
    for number in range(before - 1, after, -1):
        line = source.line(number) or ""
        column = comment_column(line)
        if column is not None and pattern.match(line[column + 1 :]):
            return number
    return 0
