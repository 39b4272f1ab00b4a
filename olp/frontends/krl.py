"""KUKA KRL frontend: a ``.src`` program -> :class:`olp.ir.Program`.

Text is parsed with the lark grammar ``grammars/krl.lark`` (LALR, positions propagated), turned
into small AST dataclasses by a :class:`lark.Transformer`, and lowered to the IR by a walk that
tracks the motion state (speed, approximation, tool, base) the way the controller does.

What is lowered
---------------
* The first ``DEF`` is the program. Later ``DEF``/``DEFFCT`` routines are reported in
  :attr:`KrlResult.ignored`; calls to them become :class:`olp.ir.Call`. ``DEFDAT`` is rejected.
* ``PTP``/``LIN``/``CIRC`` to inline aggregates. ``PTP {A1 .., A6 ..}`` (degrees) becomes a
  :class:`~olp.ir.JointTarget` in radians and needs all six axes. ``{X, Y, Z, A, B, C}``
  (mm, degrees) is the TCP pose in the current ``$BASE``, converted with
  :func:`olp.vendors.kuka.frame_to_pose`. A Cartesian aggregate may leave components out, as KRL
  allows: they are taken from the previous Cartesian target in the program text, as long as no
  ``PTP`` to axis values, ``$BASE`` or ``$TOOL`` change came in between (otherwise olp cannot know
  the start pose and says so). ``S``/``T`` are recorded in :attr:`KrlResult.status_turn`.
* ``$VEL.CP`` (m/s) -> ``Speed.linear``. ``$VEL_AXIS[i]`` / ``$ACC_AXIS[i]`` (percent, axes 1-6)
  -> ``Speed.joint`` / ``Speed.joint_acceleration``: the **minimum** over the axes set so far,
  because one fraction cannot hold per-axis values and the slowest axis bounds a synchronised
  PTP. ``$VEL``/``$APO`` aggregates are read component by component.
* Approximation: a motion without a suffix stops exactly (:data:`olp.ir.FINE`). ``C_DIS`` uses the
  current ``$APO.CDIS`` (mm) as the zone radius. ``C_PTP`` (on PTP) and ``C_VEL``/``C_ORI`` (which
  KRL bases on ``$APO.CPTP`` percent, ``$APO.CVEL`` and ``$APO.CORI``) are approximated with the
  same ``$APO.CDIS`` distance for now; ``C_VEL``/``C_ORI`` add a note. Before any ``$APO.CDIS`` the
  controller's value is unknown: such a motion is lowered as a fine stop, with a note.
* ``$BASE``/``$TOOL`` = ``{FRAME: ...}`` (missing components are 0) -> a Frame/Tool named
  ``base_l<line>``/``tool_l<line>`` with its pose; ``BASE_DATA[n]``/``TOOL_DATA[n]`` -> a reference
  ``Frame(name="BASE_DATA[n]", number=n, pose=None)`` resolved later against the station;
  ``$NULLFRAME`` -> :data:`olp.ir.WORLD` / :data:`olp.ir.FLANGE`.
* ``BAS(#VEL_CP, v)``, ``BAS(#VEL_PTP, p)``, ``BAS(#ACC_PTP, p)``, ``BAS(#TOOL, n)`` and
  ``BAS(#BASE, n)`` are read as the assignments they stand for (``n = 0``: no tool / world);
  ``BAS(#INITMOV, ...)`` is reported as ignored; other BAS commands read ``PDAT_ACT``/``FDAT_ACT``
  and are rejected. (The BAS mapping follows KUKA's documented meaning, unverified against
  ``BAS.SRC``.)
* ``WAIT SEC`` -> Wait, ``WAIT FOR $IN[n]`` (or ``NOT``, ``== TRUE/FALSE``) -> WaitInput,
  ``$OUT[n] = TRUE/FALSE`` -> SetOutput, ``name(args)`` -> Call (arguments as source text).

Defaults before any assignment: tool :data:`~olp.ir.FLANGE`, frame :data:`~olp.ir.WORLD`,
``Speed.joint = 1`` (100 %) and ``Speed.linear =`` :data:`DEFAULT_VEL_CP`, the value KSS is
reported to set with ``BAS(#INITMOV, 0)`` (2 m/s, unverified); the first LIN/CIRC that relies on it
gets a note.

Everything else the grammar knows (declarations, interrupts, other system variables, ...) is
listed in :attr:`KrlResult.ignored`; no statement is dropped silently. Control-flow blocks
(``IF``, ``FOR``, ``WHILE``, ``LOOP``, ``REPEAT``, ``SWITCH``) are ignored when lowering their
bodies would change nothing, and rejected otherwise, since the IR has no control flow. Text the
grammar does not accept, and values olp cannot use, raise :class:`olp.errors.ParseError` with the
file, line, column and the offending text.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import gc
import math
import operator
import os
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeAlias, TypeVar

import numpy as np
from lark import Lark, Token, Transformer, v_args
from lark.exceptions import (
    UnexpectedCharacters,
    UnexpectedEOF,
    UnexpectedInput,
    UnexpectedToken,
    VisitError,
)
from lark.lexer import PatternStr
from lark.tree import Meta

from olp import ir
from olp.errors import ParseError, UsageError
from olp.resources import data_path
from olp.vendors.kuka import frame_to_pose

DEFAULT_VEL_CP = 2.0
"""m/s: ``$VEL.CP`` assumed before the program sets it (what ``BAS(#INITMOV, 0)`` is reported to
set on KSS 8; unverified). A LIN/CIRC relying on it gets a note."""

# ------------------------------------------------------------------------------------------------
# Public results


@dataclass(frozen=True, slots=True)
class IgnoredLine:
    """A statement olp recognised but did not lower: where, its text, and why."""

    span: ir.SourceSpan
    text: str
    reason: str


@dataclass(frozen=True, slots=True)
class Note:
    """A remark on how a statement was lowered (an assumed default, an approximation)."""

    span: ir.SourceSpan
    message: str


@dataclass(frozen=True, slots=True)
class StatusTurn:
    """KUKA Status (S) and Turn (T) given with the Cartesian target of the motion at ``span``.

    Kept raw for now; mapping them to :class:`olp.ir.Configuration` needs the robot model
    (see :func:`olp.vendors.kuka.status_bits`).
    """

    span: ir.SourceSpan
    status: int | None
    turn: int | None


@dataclass(frozen=True, slots=True, kw_only=True)
class KrlResult:
    """What the KRL frontend read: the program and everything it did not lower as-is."""

    program: ir.Program
    ignored: tuple[IgnoredLine, ...] = ()
    notes: tuple[Note, ...] = ()
    status_turn: tuple[StatusTurn, ...] = ()


def parse_krl(text: str, filename: str = "<string>") -> KrlResult:
    """Parse KRL source ``text`` (a ``.src`` file's content) and lower its first DEF.

    Raises :class:`olp.errors.ParseError` (with span and source line) for text that is not KRL
    olp understands; no other exception escapes for bad input.
    """
    source = _Source.of(text, filename)
    try:
        return _lower_module(_parse(source), source)
    except RecursionError:
        span = ir.SourceSpan(source.filename, 1, 1)
        raise source.error("the program is nested too deeply to read", span) from None


def load_krl(path: str | os.PathLike[str]) -> KrlResult:
    """Read a ``.src`` file (UTF-8, else Windows-1252, else Latin-1) and :func:`parse_krl` it.

    KUKA controllers write Windows-1252, so a file that is not valid UTF-8 is read as that.
    Raises :class:`olp.errors.UsageError` if the file cannot be read.
    """
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise UsageError(f"cannot read KRL file {os.fspath(path)!r}: {exc.strerror}") from None
    return parse_krl(_decode(data), os.fspath(path))


def _decode(data: bytes) -> str:
    for encoding in ("utf-8", "cp1252"):
        try:
            return data.decode(encoding)
        except UnicodeDecodeError:
            continue
    return data.decode("latin-1")


# ------------------------------------------------------------------------------------------------
# Source text: spans, lines and errors


@dataclass(frozen=True, slots=True)
class _Source:
    filename: str
    text: str
    lines: tuple[str, ...]

    @classmethod
    def of(cls, text: str, filename: str) -> _Source:
        text = text.removeprefix("\ufeff")
        # Lines as lark counts them (only "\n" ends a line; str.splitlines knows more breaks).
        return cls(filename, text, tuple(line.rstrip("\r") for line in text.split("\n")))

    def line(self, number: int) -> str | None:
        return self.lines[number - 1] if 1 <= number <= len(self.lines) else None

    def snippet(self, span: ir.SourceSpan) -> str:
        """The text at ``span``, cut at the end of its first line."""
        line = self.line(span.line) or ""
        end = span.end_column if span.end_line == span.line and span.end_column else None
        return line[span.column - 1 : None if end is None else end - 1].strip()

    def error(self, message: str, span: ir.SourceSpan, hint: str | None = None) -> ParseError:
        return ParseError(message, span, self.line(span.line), hint)

    def last_position(self) -> tuple[int, int]:
        """(line, column) just after the last non-blank line: where 'end of file' is reported."""
        number = len(self.lines)
        while number > 1 and not self.lines[number - 1].strip():
            number -= 1
        return number, len(self.lines[number - 1]) + 1


# ------------------------------------------------------------------------------------------------
# AST: what the Transformer makes of the parse tree


@dataclass(frozen=True, slots=True)
class Num:
    value: float
    is_int: bool
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Bool:
    value: bool
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Text:
    value: str
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Bits:
    """A ``'B0101'`` or ``'H1F'`` literal."""

    value: int
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class EnumValue:
    name: str
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Member:
    name: str
    value: Expr
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Aggregate:
    type_name: str | None
    members: tuple[Member, ...]
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Index:
    args: tuple[Expr, ...]


@dataclass(frozen=True, slots=True)
class Field:
    name: str


@dataclass(frozen=True, slots=True)
class Var:
    name: str
    selectors: tuple[Index | Field, ...]
    span: ir.SourceSpan

    @property
    def key(self) -> str:
        """The variable's shape, case-folded: ``$VEL.CP``, ``$OUT[]``, ``BASE_DATA[]``."""
        parts = ["[]" if isinstance(s, Index) else f".{s.name.upper()}" for s in self.selectors]
        return self.name.upper() + "".join(parts)


@dataclass(frozen=True, slots=True)
class FuncCall:
    name: str
    args: tuple[Expr, ...]
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Unary:
    op: str
    operand: Expr
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Binary:
    op: str
    left: Expr
    right: Expr
    span: ir.SourceSpan


Expr: TypeAlias = Num | Bool | Text | Bits | EnumValue | Aggregate | Var | FuncCall | Unary | Binary


@dataclass(frozen=True, slots=True)
class Assign:
    target: Var
    value: Expr
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class CallStmt:
    name: str
    args: tuple[Expr, ...]
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class MotionStmt:
    keyword: str
    targets: tuple[Expr, ...]
    angle: Expr | None
    approx: tuple[str, ...]
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class WaitSec:
    seconds: Expr
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class WaitFor:
    condition: Expr
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Block:
    """A control-flow statement (IF, FOR, ...) with its bodies (IF: then and else)."""

    keyword: str
    bodies: tuple[tuple[Stmt, ...], ...]
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Other:
    """A statement the grammar knows and olp only reports (declarations, interrupts, ...)."""

    kind: str
    span: ir.SourceSpan


Stmt: TypeAlias = Assign | CallStmt | MotionStmt | WaitSec | WaitFor | Block | Other


@dataclass(frozen=True, slots=True)
class Routine:
    kind: str  # "DEF" or "DEFFCT"
    name: str
    body: tuple[Stmt, ...]
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class DatBlock:
    name: str
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Module:
    items: tuple[Routine | DatBlock, ...]


@dataclass(frozen=True, slots=True)
class _CircAngle:
    angle: Expr


# ------------------------------------------------------------------------------------------------
# Parse tree -> AST

_inline = v_args(inline=True, meta=True)

_OTHER_KINDS = {
    "decl": "DECL",
    "ext_decl": "EXT",
    "interrupt_decl": "INTERRUPT DECL",
    "interrupt_ctl": "INTERRUPT",
    "trigger": "TRIGGER",
    "goto_stmt": "GOTO",
    "label": "label",
    "return_stmt": "RETURN",
    "halt_stmt": "HALT",
    "exit_stmt": "EXIT",
    "continue_stmt": "CONTINUE",
    "brake_stmt": "BRAKE",
}


class _ToAst(Transformer[Token, Module]):
    """Builds the AST; never raises for any tree the grammar accepts."""

    def __init__(self, filename: str) -> None:
        super().__init__(visit_tokens=True)
        self._filename = filename

    def _span(self, meta: Meta) -> ir.SourceSpan:
        return ir.SourceSpan(self._filename, meta.line, meta.column, meta.end_line, meta.end_column)

    def _token_span(self, token: Token) -> ir.SourceSpan:
        line, column = token.line or 1, token.column or 1
        return ir.SourceSpan(self._filename, line, column, token.end_line, token.end_column)

    def __default__(self, data: Any, children: list[Any], meta: Meta) -> Any:
        kind = _OTHER_KINDS.get(str(data))
        return None if kind is None else Other(kind, self._span(meta))

    # ---- terminals
    def NUMBER(self, token: Token) -> Num:
        is_int = token.isdigit()
        return Num(float(token), is_int, self._token_span(token))

    def SIGNED_NUMBER(self, token: Token) -> Num:
        digits = "".join(token.split()).lstrip("+-")
        value = float(digits)
        return Num(
            -value if token.startswith("-") else value, digits.isdigit(), self._token_span(token)
        )

    def TRUE(self, token: Token) -> Bool:
        return Bool(True, self._token_span(token))

    def FALSE(self, token: Token) -> Bool:
        return Bool(False, self._token_span(token))

    def STRING(self, token: Token) -> Text:
        return Text(token[1:-1], self._token_span(token))

    def BIN_LIT(self, token: Token) -> Bits:
        return Bits(int(token[2:-1], 2), self._token_span(token))

    def HEX_LIT(self, token: Token) -> Bits:
        return Bits(int(token[2:-1], 16), self._token_span(token))

    def ENUM(self, token: Token) -> EnumValue:
        return EnumValue(token[1:], self._token_span(token))

    # ---- module and routines
    def start(self, children: list[Any]) -> Module:
        return Module(tuple(c for c in children if c is not None))

    @_inline
    def routine(
        self, meta: Meta, _global: Any, name: Token, _params: Any, body: tuple[Stmt, ...]
    ) -> Routine:
        return Routine("DEF", str(name), body, self._span(meta))

    @_inline
    def function(
        self, meta: Meta, _global: Any, _type: Any, name: Token, _params: Any, body: Any
    ) -> Routine:
        return Routine("DEFFCT", str(name), body, self._span(meta))

    @_inline
    def dat_block(self, meta: Meta, name: Token, *_rest: Any) -> DatBlock:
        return DatBlock(str(name), self._span(meta))

    def body(self, children: list[Stmt]) -> tuple[Stmt, ...]:
        return tuple(children)

    def args(self, children: list[Expr]) -> tuple[Expr, ...]:
        return tuple(children)

    # ---- statements
    @_inline
    def assignment(self, meta: Meta, target: Var, value: Expr) -> Assign:
        return Assign(target, value, self._span(meta))

    @_inline
    def call_stmt(self, meta: Meta, name: Token, args: tuple[Expr, ...] | None) -> CallStmt:
        return CallStmt(str(name), args or (), self._span(meta))

    @_inline
    def motion(self, meta: Meta, keyword: Token, *rest: Any) -> MotionStmt:
        targets = tuple(r for r in rest if r is not None and not isinstance(r, Token | _CircAngle))
        angles = [r.angle for r in rest if isinstance(r, _CircAngle)]
        approx = tuple(str(r).upper() for r in rest if isinstance(r, Token))
        span = self._span(meta)
        return MotionStmt(
            str(keyword).upper(), targets, angles[0] if angles else None, approx, span
        )

    @_inline
    def circ_angle(self, meta: Meta, angle: Expr) -> _CircAngle:
        return _CircAngle(angle)

    @_inline
    def approx(self, meta: Meta, keyword: Token) -> Token:
        return keyword

    @_inline
    def wait_sec(self, meta: Meta, seconds: Expr) -> WaitSec:
        return WaitSec(seconds, self._span(meta))

    @_inline
    def wait_for(self, meta: Meta, condition: Expr) -> WaitFor:
        return WaitFor(condition, self._span(meta))

    def _block(self, keyword: str, meta: Meta, bodies: Sequence[Any]) -> Block:
        kept = tuple(b for b in bodies if isinstance(b, tuple))
        return Block(keyword, kept, self._span(meta))

    @_inline
    def if_stmt(self, meta: Meta, _cond: Expr, then: Any, otherwise: Any) -> Block:
        return self._block("IF", meta, (then, otherwise))

    @_inline
    def for_stmt(self, meta: Meta, *children: Any) -> Block:
        return self._block("FOR", meta, children[-1:])

    @_inline
    def while_stmt(self, meta: Meta, _cond: Expr, body: Any) -> Block:
        return self._block("WHILE", meta, (body,))

    @_inline
    def loop_stmt(self, meta: Meta, body: Any) -> Block:
        return self._block("LOOP", meta, (body,))

    @_inline
    def repeat_stmt(self, meta: Meta, body: Any, _cond: Expr) -> Block:
        return self._block("REPEAT", meta, (body,))

    @_inline
    def switch_stmt(self, meta: Meta, _subject: Expr, *clauses: Any) -> Block:
        return self._block("SWITCH", meta, clauses)

    @_inline
    def case_clause(self, meta: Meta, _values: Any, body: tuple[Stmt, ...]) -> tuple[Stmt, ...]:
        return body

    @_inline
    def default_clause(self, meta: Meta, body: tuple[Stmt, ...]) -> tuple[Stmt, ...]:
        return body

    # ---- expressions
    @_inline
    def binary(self, meta: Meta, left: Expr, op: Token, right: Expr) -> Binary:
        return Binary(str(op).upper(), left, right, self._span(meta))

    @_inline
    def unary_op(self, meta: Meta, op: Token, operand: Expr) -> Unary:
        return Unary(str(op).upper(), operand, self._span(meta))

    @_inline
    def func_call(self, meta: Meta, name: Token, args: tuple[Expr, ...] | None) -> FuncCall:
        return FuncCall(str(name), args or (), self._span(meta))

    @_inline
    def variable(self, meta: Meta, name: Token, *selectors: Index | Field) -> Var:
        return Var(str(name), selectors, self._span(meta))

    @_inline
    def index(self, meta: Meta, args: tuple[Expr, ...] | None) -> Index:
        return Index(args or ())

    @_inline
    def field(self, meta: Meta, name: Token) -> Field:
        return Field(str(name))

    @_inline
    def aggregate(self, meta: Meta, type_name: str | None, *members: Member | None) -> Aggregate:
        kept = tuple(m for m in members if m is not None)
        return Aggregate(type_name, kept, self._span(meta))

    @_inline
    def aggregate_type(self, meta: Meta, name: Token) -> str:
        return str(name)

    @_inline
    def member(self, meta: Meta, name: Token, _empty_index: Any, value: Expr) -> Member:
        return Member(str(name), value, self._span(meta))


# ------------------------------------------------------------------------------------------------
# Parsing and syntax errors

_TERMINAL_NAMES = {
    "NAME": "a name",
    "NUMBER": "a number",
    "STRING": 'a string ("...")',
    "BIN_LIT": "a binary literal ('B...')",
    "HEX_LIT": "a hexadecimal literal ('H...')",
    "ENUM": "an enumeration value (#NAME)",
    "HEADER": "a header line (&...)",
    "COMPARE": "a comparison (==, <>, <, >, <=, >=)",
    "EMPTY_INDEX": "'[]'",
    "_NL": "end of line",
    "$END": "end of file",
}
_MAX_EXPECTED = 10
_BLOCK_ENDS = frozenset(
    {
        "_END",
        "_ENDFCT",
        "_ENDDAT",
        "_ELSE",
        "_ENDIF",
        "_ENDFOR",
        "_ENDWHILE",
        "_ENDLOOP",
        "_UNTIL",
        "_CASE",
        "_DEFAULT",
        "_ENDSWITCH",
        "$END",
    }
)


@functools.lru_cache(maxsize=1)
def _parser() -> Lark:
    grammar = data_path("grammars", "krl.lark").read_text(encoding="utf-8")
    return Lark(grammar, parser="lalr", propagate_positions=True, maybe_placeholders=True)


@functools.lru_cache(maxsize=1)
def _terminal_descriptions() -> dict[str, str]:
    described = dict(_TERMINAL_NAMES)
    for terminal in _parser().terminals:
        if isinstance(terminal.pattern, PatternStr) and terminal.name not in described:
            described[terminal.name] = f"'{terminal.pattern.value.upper()}'"
    return described


def _parse(source: _Source) -> Module:
    try:
        with _gc_paused():
            tree = _parser().parse(source.text + "\n")
            return _ToAst(source.filename).transform(tree)
    except UnexpectedInput as exc:
        raise _syntax_error(exc, source) from None
    except VisitError as exc:
        if isinstance(exc.orig_exc, ParseError | RecursionError):
            raise exc.orig_exc from None
        raise


@contextlib.contextmanager
def _gc_paused() -> Iterator[None]:
    """Pause the cyclic garbage collector: parsing makes many small acyclic objects, and
    collections triggered by them made parse time grow faster than linearly (0.17 -> 0.4 ms per
    line between 1k- and 16k-line programs)."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


def _syntax_error(exc: UnexpectedInput, source: _Source) -> ParseError:
    """A ParseError saying what was found where, and what the grammar expected there."""
    found, expected, end = "end of file", set[str](), None
    line, column = exc.line, exc.column
    if isinstance(exc, UnexpectedToken):
        found, expected = _describe_token(exc.token), set(exc.expected)
        if exc.token.type != "$END" and exc.token.end_line == exc.token.line:
            end = exc.token.end_column
    elif isinstance(exc, UnexpectedCharacters):
        found, expected = f"character {exc.char!r}", set(exc.allowed or ())
        end = column + 1 if isinstance(column, int) else None
    elif isinstance(exc, UnexpectedEOF):
        expected = set(exc.expected)
    if isinstance(exc, UnexpectedEOF) or getattr(getattr(exc, "token", None), "type", "") == "$END":
        line, column = source.last_position()
    if not (isinstance(line, int) and 1 <= line <= len(source.lines)):
        line, column = source.last_position()
    column = column if isinstance(column, int) and column >= 1 else 1
    span = ir.SourceSpan(source.filename, line, column, line, end)
    return source.error(f"unexpected {found}; expected {_describe_expected(expected)}", span)


def _describe_token(token: Token) -> str:
    if token.type == "$END":
        return "end of file"
    if token.type == "_NL":
        return "end of line"
    return repr(str(token))


def _describe_expected(names: set[str]) -> str:
    """'a number, '}' or ...': descriptions first, then literal tokens, statement starts folded."""
    table = _terminal_descriptions()
    if {"PTP", "_IF", "NAME"} <= names:  # where a statement may start: don't list them all
        names = (names & _BLOCK_ENDS) | {"a statement"}
    described = sorted({table.get(name, name) for name in names}, key=lambda d: (d[0] == "'", d))
    if not described:
        return "something else"
    if len(described) > _MAX_EXPECTED:
        described = [*described[:_MAX_EXPECTED], "..."]
    if len(described) == 1:
        return described[0]
    return ", ".join(described[:-1]) + " or " + described[-1]


# ------------------------------------------------------------------------------------------------
# Constant expressions

Value: TypeAlias = float | bool


def _fold(expr: Expr) -> Value | None:
    """The value of a constant expression (numbers, TRUE/FALSE, + - * /, NOT), else None."""
    if isinstance(expr, Num | Bool):
        return expr.value
    if isinstance(expr, Bits):
        return float(expr.value)
    if isinstance(expr, Unary):
        return _fold_unary(expr.op, _fold(expr.operand))
    if isinstance(expr, Binary):
        return _fold_binary(expr.op, _fold(expr.left), _fold(expr.right))
    return None


def _fold_unary(op: str, value: Value | None) -> Value | None:
    if isinstance(value, bool):
        return (not value) if op == "NOT" else None
    if value is None or op not in "+-":
        return None
    return -value if op == "-" else value


_ARITHMETIC: dict[str, Callable[[float, float], float]] = {
    "+": operator.add,
    "-": operator.sub,
    "*": operator.mul,
    "/": operator.truediv,
}


def _fold_binary(op: str, left: Value | None, right: Value | None) -> Value | None:
    function = _ARITHMETIC.get(op)
    numbers = not isinstance(left, bool) and not isinstance(right, bool)
    if function is None or left is None or right is None or not numbers:
        return None
    if op == "/" and right == 0:
        return None
    return function(left, right)


def _is_int_literal(expr: Expr) -> bool:
    if isinstance(expr, Unary):
        return _is_int_literal(expr.operand)
    return isinstance(expr, Bits) or (isinstance(expr, Num) and expr.is_int)


# ------------------------------------------------------------------------------------------------
# Lowering

_AXES = tuple(f"A{i}" for i in range(1, 7))
_CARTESIAN = ("X", "Y", "Z", "A", "B", "C")
_EXTERNAL = tuple(f"E{i}" for i in range(1, 7))
_AXIS_TYPES = frozenset({"AXIS", "E6AXIS"})
_POS_TYPES = frozenset({"POS", "E6POS", "FRAME"})
_CP_APPROX = frozenset({"C_DIS", "C_VEL", "C_ORI"})
_F = TypeVar("_F", ir.Frame, ir.Tool)

_IGNORE_REASONS = {
    "DECL": "declarations are not evaluated yet",
    "EXT": "external declarations are not needed by olp",
    "INTERRUPT DECL": "interrupts are not lowered (the IR has no event handlers)",
    "INTERRUPT": "interrupts are not lowered (the IR has no event handlers)",
    "TRIGGER": "path-related switching actions (TRIGGER) are not lowered yet",
    "label": "jump labels are not lowered (GOTO is not supported)",
    "HALT": "HALT (stop until restarted) has no IR equivalent",
    "EXIT": "EXIT only matters inside a loop",
    "CONTINUE": "CONTINUE only affects the controller's advance run",
    "BRAKE": "BRAKE only matters in interrupt routines",
}


@dataclass(frozen=True, slots=True, kw_only=True)
class _State:
    """The controller state that motions pick up, as the program has set it so far."""

    speed: ir.Speed = field(default_factory=lambda: ir.Speed(linear=DEFAULT_VEL_CP))
    vel_cp_set: bool = False
    vel_axis: dict[int, float] = field(default_factory=dict)  # percent per axis 1..6
    acc_axis: dict[int, float] = field(default_factory=dict)
    cdis_mm: float | None = None
    tool: ir.Tool = field(default_factory=lambda: ir.FLANGE)
    frame: ir.Frame = field(default_factory=lambda: ir.WORLD)
    last_cartesian: tuple[float, ...] | None = None  # X, Y, Z, A, B, C of the previous target
    no_start: str = "there is no earlier Cartesian target in the program"


class _Lowering:
    """Walks the statements of one routine, tracking :class:`_State`, appending IR."""

    def __init__(self, source: _Source, state: _State) -> None:
        self.source = source
        self.state = state
        self.instructions: list[ir.Instruction] = []
        self.ignored: list[IgnoredLine] = []
        self.notes: list[Note] = []
        self.status_turn: list[StatusTurn] = []
        self.returned_at: int | None = None
        self._noted: set[str] = set()
        self._statements: dict[type, Callable[[Any], None]] = {
            Assign: self._assign,
            CallStmt: self._call,
            MotionStmt: self._motion,
            WaitSec: self._wait_sec,
            WaitFor: self._wait_for,
            Block: self._block,
            Other: self._other,
        }
        self._setters: dict[str, Callable[[str, Expr, Stmt], None]] = {
            "$VEL.CP": self._set_vel_cp,
            "$APO.CDIS": self._set_apo_cdis,
            "$BASE": self._set_base,
            "$TOOL": self._set_tool,
            "$VEL": self._set_struct,
            "$APO": self._set_struct,
        }

    # ---- driving
    def lower_body(self, body: Sequence[Stmt]) -> None:
        for stmt in body:
            self.lower_statement(stmt)

    def lower_statement(self, stmt: Stmt) -> None:
        if self.returned_at is not None:
            self._ignore(stmt, f"unreachable: the program returns at line {self.returned_at}")
            return
        try:
            self._statements[type(stmt)](stmt)
        except ir.IRError as exc:
            raise self.source.error(f"invalid value: {exc}", stmt.span) from None

    def changed_anything(self, before: _State) -> bool:
        """True if lowering so far made IR or changed the state (a block cannot be skipped)."""
        effects = self.instructions or self.status_turn or self.returned_at is not None
        return bool(effects) or self.state != before

    # ---- reporting
    def _ignore(self, stmt: Stmt, reason: str) -> None:
        self.ignored.append(IgnoredLine(stmt.span, self.source.snippet(stmt.span), reason))

    def _note(self, span: ir.SourceSpan, message: str, once: str | None = None) -> None:
        if once is not None:
            if once in self._noted:
                return
            self._noted.add(once)
        self.notes.append(Note(span, message))

    def _error(self, message: str, span: ir.SourceSpan, hint: str | None = None) -> ParseError:
        return self.source.error(message, span, hint)

    # ---- values
    def _number(self, expr: Expr, what: str) -> float:
        value = _fold(expr)
        if value is None or isinstance(value, bool):
            found = self.source.snippet(expr.span)
            raise self._error(f"{what} must be a constant number, found {found!r}", expr.span)
        if not math.isfinite(value):
            raise self._error(f"{what} is out of range", expr.span)
        return float(value)

    def _integer(self, expr: Expr, what: str, minimum: int = 0) -> int:
        value = self._number(expr, what)
        if not _is_int_literal(expr) or value < minimum or value != int(value):
            found = self.source.snippet(expr.span)
            raise self._error(f"{what} must be an integer >= {minimum}, found {found!r}", expr.span)
        return int(value)

    def _percent(self, expr: Expr, what: str) -> float:
        percent = self._number(expr, f"{what} (%)")
        if not 0 < percent <= 100:
            raise self._error(f"{what} must be in (0, 100] %, found {percent:g}", expr.span)
        return percent

    def _single_index(self, target: Var, what: str, minimum: int = 1) -> int:
        index = target.selectors[0]
        if not isinstance(index, Index) or len(index.args) != 1:
            raise self._error(f"{what} takes one index", target.span)
        return self._integer(index.args[0], f"the index of {what}", minimum)

    # ---- assignments
    def _assign(self, stmt: Assign) -> None:
        key = stmt.target.key
        setter = self._setters.get(key)
        if setter is not None:
            setter(key, stmt.value, stmt)
        elif key in ("$VEL_AXIS[]", "$ACC_AXIS[]"):
            self._set_axis_percent(stmt, key)
        elif key == "$OUT[]":
            self._set_output(stmt)
        elif key.startswith("$"):
            self._ignore(stmt, f"system variable {key.split('[')[0]} is not lowered yet")
        else:
            self._ignore(stmt, "assignments to program variables are not evaluated yet")

    def _set_vel_cp(self, name: str, value: Expr, stmt: Stmt) -> None:
        speed = self._number(value, "$VEL.CP (m/s)")
        if speed <= 0:
            raise self._error(f"$VEL.CP (m/s) must be > 0, found {speed:g}", value.span)
        new_speed = dataclasses.replace(self.state.speed, linear=speed)
        self.state = dataclasses.replace(self.state, speed=new_speed, vel_cp_set=True)

    def _set_apo_cdis(self, name: str, value: Expr, stmt: Stmt) -> None:
        distance = self._number(value, "$APO.CDIS (mm)")
        if distance < 0:
            raise self._error("$APO.CDIS (mm) must be >= 0", value.span)
        self.state = dataclasses.replace(self.state, cdis_mm=distance)

    def _set_struct(self, name: str, value: Expr, stmt: Stmt) -> None:
        """``$VEL = {CP 0.5, ...}``: each component as its own assignment."""
        if not isinstance(value, Aggregate):
            raise self._error(f"{name} must be set from an aggregate {{...}} here", value.span)
        unused = []
        for member in value.members:
            component = f"{name}.{member.name.upper()}"
            setter = self._setters.get(component)
            if setter is None:
                unused.append(member.name.upper())
            else:
                setter(component, member.value, stmt)
        if unused:
            listed = ", ".join(unused)
            self._ignore(stmt, f"{name} component(s) {listed} not lowered yet")

    def _set_axis_percent(self, stmt: Assign, key: str) -> None:
        name = key.removesuffix("[]")
        axis = self._single_index(stmt.target, name)
        percent = self._percent(stmt.value, f"{name}[{axis}]")
        if axis > len(_AXES):
            self._ignore(stmt, f"{name} of external axes is not lowered")
            return
        self._set_axes_percent(name, {axis: percent})

    def _set_axes_percent(self, name: str, percents: dict[int, float]) -> None:
        if name == "$VEL_AXIS":
            vel_axis = {**self.state.vel_axis, **percents}
            speed = dataclasses.replace(self.state.speed, joint=min(vel_axis.values()) / 100)
            self.state = dataclasses.replace(self.state, vel_axis=vel_axis, speed=speed)
        else:
            acc_axis = {**self.state.acc_axis, **percents}
            fraction = min(acc_axis.values()) / 100
            speed = dataclasses.replace(self.state.speed, joint_acceleration=fraction)
            self.state = dataclasses.replace(self.state, acc_axis=acc_axis, speed=speed)

    def _set_output(self, stmt: Assign) -> None:
        index = self._single_index(stmt.target, "$OUT")
        value = _fold(stmt.value)
        if not isinstance(value, bool):
            self._ignore(stmt, "only constant TRUE/FALSE outputs are lowered")
            return
        self.instructions.append(ir.SetOutput(index=index, value=value, span=stmt.span))

    def _set_base(self, name: str, value: Expr, stmt: Stmt) -> None:
        base = self._frame_value(value, "$BASE", stmt.span, ir.Frame, ir.WORLD)
        self._change_frames(dataclasses.replace(self.state, frame=base), name, stmt.span)

    def _set_tool(self, name: str, value: Expr, stmt: Stmt) -> None:
        tool = self._frame_value(value, "$TOOL", stmt.span, ir.Tool, ir.FLANGE)
        self._change_frames(dataclasses.replace(self.state, tool=tool), name, stmt.span)

    def _change_frames(self, state: _State, name: str, span: ir.SourceSpan) -> None:
        reason = f"{name} changed at line {span.line}"
        self.state = dataclasses.replace(state, last_cartesian=None, no_start=reason)

    def _frame_value(
        self, value: Expr, name: str, span: ir.SourceSpan, make: Callable[..., _F], null: _F
    ) -> _F:
        """A frame/tool from ``{FRAME: ...}`` (named after its line), ``BASE_DATA[n]`` (or
        ``TOOL_DATA[n]``) or ``$NULLFRAME``."""
        table = _DATA_TABLES[name]
        if isinstance(value, Aggregate):
            pose = frame_to_pose(self._frame_aggregate(value, name))
            return make(name=f"{name.strip('$').lower()}_l{span.line}", pose=pose)
        if isinstance(value, Var) and value.key == f"{table}[]":
            return _data_reference(make, table, self._single_index(value, table))
        if isinstance(value, Var) and value.key == "$NULLFRAME":
            return null
        raise self._error(
            f"cannot evaluate {name} = {self.source.snippet(value.span)!r}",
            value.span,
            hint=f"olp reads {name} = {{FRAME: X ..,Y ..,Z ..,A ..,B ..,C ..}}, {table}[n] "
            "or $NULLFRAME",
        )

    def _frame_aggregate(self, agg: Aggregate, name: str) -> list[float]:
        if agg.type_name is not None and agg.type_name.upper() not in _POS_TYPES:
            raise self._error(f"{name} needs a FRAME aggregate, not {agg.type_name}", agg.span)
        members = self._members(agg, frozenset(_CARTESIAN), f"{name} component")
        return [
            self._number(members[c], f"{name}.{c}") if c in members else 0.0 for c in _CARTESIAN
        ]

    def _members(self, agg: Aggregate, allowed: frozenset[str], what: str) -> dict[str, Expr]:
        """The aggregate's members by upper-case name; unknown or repeated names are errors."""
        members: dict[str, Expr] = {}
        for member in agg.members:
            key = member.name.upper()
            if key not in allowed:
                expected = ", ".join(sorted(allowed))
                message = f"unknown {what} {member.name!r} (expected one of {expected})"
                raise self._error(message, member.span)
            if key in members:
                raise self._error(f"{what} {member.name!r} is given twice", member.span)
            members[key] = member.value
        return members

    # ---- calls and waits
    def _call(self, stmt: CallStmt) -> None:
        if stmt.name.upper() == "BAS":
            self._bas(stmt)
        elif stmt.name.upper() == "PULSE":
            self._ignore(stmt, "PULSE outputs are not lowered yet")
        else:
            args = tuple(self.source.snippet(arg.span) for arg in stmt.args)
            self.instructions.append(ir.Call(name=stmt.name, args=args, span=stmt.span))

    def _bas(self, stmt: CallStmt) -> None:
        """KUKA's BAS routine: the commands that stand for plain assignments are lowered."""
        command = stmt.args[0] if stmt.args else None
        name = command.name.upper() if isinstance(command, EnumValue) else ""
        if name == "INITMOV":
            self._ignore(stmt, "BAS(#INITMOV) resets controller defaults; olp starts from its own")
            return
        handlers: dict[str, Callable[[Expr], None]] = {
            "VEL_CP": lambda v: self._set_vel_cp("$VEL.CP", v, stmt),
            "VEL_PTP": lambda v: self._bas_axes("$VEL_AXIS", v),
            "ACC_PTP": lambda v: self._bas_axes("$ACC_AXIS", v),
            "TOOL": lambda v: self._bas_frame("$TOOL", "TOOL_DATA", v, stmt),
            "BASE": lambda v: self._bas_frame("$BASE", "BASE_DATA", v, stmt),
        }
        handler = handlers.get(name)
        if handler is None or len(stmt.args) != 2:
            raise self._error(
                f"BAS command {self.source.snippet(stmt.span)!r} is not supported yet",
                stmt.span,
                hint="olp lowers BAS(#INITMOV), BAS(#VEL_CP|#VEL_PTP|#ACC_PTP, value) and "
                "BAS(#TOOL|#BASE, n); set $VEL.CP, $TOOL, $BASE ... directly otherwise",
            )
        handler(stmt.args[1])

    def _bas_axes(self, name: str, value: Expr) -> None:
        percent = self._percent(value, name)
        self._set_axes_percent(name, dict.fromkeys(range(1, len(_AXES) + 1), percent))

    def _bas_frame(self, name: str, table: str, value: Expr, stmt: CallStmt) -> None:
        number = self._integer(value, f"the {table} number")
        if name == "$TOOL":
            tool = _data_reference(ir.Tool, table, number) if number else ir.FLANGE
            self._change_frames(dataclasses.replace(self.state, tool=tool), name, stmt.span)
        else:
            base = _data_reference(ir.Frame, table, number) if number else ir.WORLD
            self._change_frames(dataclasses.replace(self.state, frame=base), name, stmt.span)

    def _wait_sec(self, stmt: WaitSec) -> None:
        seconds = self._number(stmt.seconds, "WAIT SEC")
        if seconds < 0:
            raise self._error(f"WAIT SEC must be >= 0 s, found {seconds:g}", stmt.seconds.span)
        self.instructions.append(ir.Wait(seconds=seconds, span=stmt.span))

    def _wait_for(self, stmt: WaitFor) -> None:
        found = self._input_condition(stmt.condition)
        if found is None:
            self._ignore(stmt, "only WAIT FOR $IN[n] (or its negation) is lowered yet")
            return
        index, value = found
        self.instructions.append(ir.WaitInput(index=index, value=value, span=stmt.span))

    def _input_condition(self, expr: Expr) -> tuple[int, bool] | None:
        """``$IN[n]``, ``NOT $IN[n]``, ``$IN[n] == TRUE``, ``$IN[n] <> FALSE`` -> (n, value)."""
        if isinstance(expr, Var) and expr.key == "$IN[]":
            return self._single_index(expr, "$IN"), True
        if isinstance(expr, Unary) and expr.op == "NOT":
            inner = self._input_condition(expr.operand)
            return None if inner is None else (inner[0], not inner[1])
        if isinstance(expr, Binary) and expr.op in ("==", "<>"):
            for var, other in ((expr.left, expr.right), (expr.right, expr.left)):
                inner, value = self._input_condition(var), _fold(other)
                if inner is not None and isinstance(value, bool):
                    return inner[0], (inner[1] == value) == (expr.op == "==")
        return None

    # ---- motions
    def _motion(self, stmt: MotionStmt) -> None:
        lowerers = {"PTP": self._ptp, "LIN": self._lin, "CIRC": self._circ}
        lower = lowerers.get(stmt.keyword)
        if lower is None:
            raise self._error(
                f"{stmt.keyword} is not supported yet (olp lowers PTP, LIN and CIRC)", stmt.span
            )
        expected = 2 if stmt.keyword == "CIRC" else 1
        if len(stmt.targets) != expected:
            message = f"{stmt.keyword} takes {expected} target{'s' if expected > 1 else ''}"
            raise self._error(f"{message}, found {len(stmt.targets)}", stmt.span)
        if stmt.angle is not None:
            raise self._error("CIRC with CA (circular angle) is not supported yet", stmt.angle.span)
        lower(stmt)

    def _ptp(self, stmt: MotionStmt) -> None:
        target = self._target(stmt.targets[0], stmt)
        self.instructions.append(ir.JointMove(**self._motion_fields(stmt, target)))

    def _lin(self, stmt: MotionStmt) -> None:
        target = self._cartesian_target(stmt.targets[0], stmt)
        self._note_default_speed(stmt)
        self.instructions.append(ir.LinearMove(**self._motion_fields(stmt, target)))

    def _circ(self, stmt: MotionStmt) -> None:
        start = self.state.last_cartesian, self.state.no_start
        via = self._cartesian_target(stmt.targets[0], stmt)
        # The end point's missing components come from the start point, not from the via point.
        self.state = dataclasses.replace(self.state, last_cartesian=start[0], no_start=start[1])
        target = self._cartesian_target(stmt.targets[1], stmt)
        self._note_default_speed(stmt)
        fields = self._motion_fields(stmt, target)
        self.instructions.append(ir.CircularMove(via=via, **fields))

    def _motion_fields(self, stmt: MotionStmt, target: ir.Target) -> dict[str, Any]:
        state = self.state
        return {
            "target": target,
            "speed": state.speed,
            "zone": self._zone(stmt),
            "tool": state.tool,
            "frame": state.frame,
            "span": stmt.span,
        }

    def _note_default_speed(self, stmt: MotionStmt) -> None:
        if not self.state.vel_cp_set:
            message = (
                f"{stmt.keyword} before any $VEL.CP: olp assumes {DEFAULT_VEL_CP} m/s, the value "
                "BAS(#INITMOV) is reported to set; set $VEL.CP to be sure"
            )
            self._note(stmt.span, message, once="default-vel-cp")

    def _zone(self, stmt: MotionStmt) -> ir.Zone:
        if not stmt.approx:
            return ir.FINE
        self._check_approx(stmt)
        if self.state.cdis_mm is None:
            message = (
                f"{' '.join(stmt.approx)} before any $APO.CDIS: olp does not know the "
                "controller's approximation distance and programs an exact stop"
            )
            self._note(stmt.span, message)
            return ir.FINE
        if stmt.keyword != "PTP" and stmt.approx[0] in ("C_VEL", "C_ORI"):
            message = f"{stmt.approx[0]} is approximated with the $APO.CDIS distance"
            self._note(stmt.span, message)
        return ir.Zone(self.state.cdis_mm / 1000.0)

    def _check_approx(self, stmt: MotionStmt) -> None:
        approx = stmt.approx
        if stmt.keyword == "PTP":
            valid = approx[0] == "C_PTP" and (len(approx) == 1 or approx[1:] in _ONE_CP_APPROX)
            rule = "PTP approximates with C_PTP, optionally followed by C_DIS, C_ORI or C_VEL"
        else:
            valid = approx in _ONE_CP_APPROX
            rule = f"{stmt.keyword} approximates with one of C_DIS, C_ORI or C_VEL"
        if not valid:
            raise self._error(f"invalid approximation {' '.join(approx)!r}: {rule}", stmt.span)

    def _target(self, expr: Expr, stmt: MotionStmt) -> ir.Target:
        agg = self._target_aggregate(expr, stmt)
        if _is_axis_aggregate(agg):
            return self._joint_target(agg, stmt)
        return self._cartesian_target(agg, stmt)

    def _target_aggregate(self, expr: Expr, stmt: MotionStmt) -> Aggregate:
        if isinstance(expr, Aggregate):
            return expr
        found = self.source.snippet(expr.span)
        raise self._error(
            f"{stmt.keyword} to {found!r}: only inline targets {{...}} are supported yet",
            expr.span,
            hint="olp does not read DECLs or .dat files yet; write the position as an aggregate",
        )

    def _joint_target(self, agg: Aggregate, stmt: MotionStmt) -> ir.JointTarget:
        members = self._members(agg, frozenset(_AXES + _EXTERNAL), "axis")
        missing = [a for a in _AXES if a not in members]
        if missing:
            raise self._error(
                f"{stmt.keyword} to axis values needs all of A1..A6; missing {', '.join(missing)}",
                agg.span,
                hint="the other axes would keep the robot's current values, which olp cannot know",
            )
        degrees = [self._number(members[a], a) for a in _AXES]
        self._check_external(members, stmt)
        reason = f"the motion at line {stmt.span.line} went to axis values"
        self.state = dataclasses.replace(self.state, last_cartesian=None, no_start=reason)
        return ir.JointTarget(joints=np.radians(degrees))

    def _cartesian_target(self, expr: Expr, stmt: MotionStmt) -> ir.CartesianTarget:
        agg = self._target_aggregate(expr, stmt)
        if _is_axis_aggregate(agg):
            raise self._error(f"{stmt.keyword} needs a Cartesian target {{X ..,Y ..}}", agg.span)
        typed = agg.type_name is not None and agg.type_name.upper() != "FRAME"
        allowed = _CARTESIAN + _EXTERNAL + (("S", "T") if typed or agg.type_name is None else ())
        members = self._members(agg, frozenset(allowed), "position component")
        values = self._complete(agg, members, stmt)
        self._check_external(members, stmt)
        self._record_status_turn(members, stmt)
        self.state = dataclasses.replace(self.state, last_cartesian=values)
        return ir.CartesianTarget(pose=frame_to_pose(values))

    def _complete(
        self, agg: Aggregate, members: dict[str, Expr], stmt: MotionStmt
    ) -> tuple[float, ...]:
        """X..C from the aggregate, missing ones from the previous Cartesian target."""
        missing = [c for c in _CARTESIAN if c not in members]
        previous = self.state.last_cartesian
        if previous is None:
            if missing:
                raise self._error(
                    f"{stmt.keyword} target leaves out {', '.join(missing)}, which KRL takes from "
                    f"the start position; olp cannot know it because {self.state.no_start}",
                    agg.span,
                    hint="give all of X, Y, Z, A, B, C",
                )
            previous = (0.0,) * len(_CARTESIAN)
        return tuple(
            self._number(members[c], c) if c in members else previous[i]
            for i, c in enumerate(_CARTESIAN)
        )

    def _check_external(self, members: dict[str, Expr], stmt: MotionStmt) -> None:
        used = [e for e in _EXTERNAL if e in members and self._number(members[e], e) != 0]
        if used:
            message = f"external axis values ({', '.join(used)}) are not supported yet; dropped"
            self._note(stmt.span, message)

    def _record_status_turn(self, members: dict[str, Expr], stmt: MotionStmt) -> None:
        status = self._integer(members["S"], "S (Status)") if "S" in members else None
        turn = self._integer(members["T"], "T (Turn)") if "T" in members else None
        if status is not None or turn is not None:
            self.status_turn.append(StatusTurn(stmt.span, status, turn))

    # ---- blocks and other statements
    def _block(self, stmt: Block) -> None:
        for body in stmt.bodies:
            probe = _Lowering(self.source, self.state)
            for inner in body:
                probe.lower_statement(inner)
                if probe.changed_anything(self.state):
                    raise self._error(
                        f"{self.source.snippet(inner.span)!r} inside {stmt.keyword} (line "
                        f"{stmt.span.line}) cannot be lowered: olp's IR has no control flow yet",
                        inner.span,
                    )
        reason = f"{stmt.keyword} block (lines {stmt.span.line}-{stmt.span.end_line}) changes "
        self._ignore(stmt, reason + "nothing olp lowers")

    def _other(self, stmt: Other) -> None:
        if stmt.kind == "RETURN":
            self.returned_at = stmt.span.line
            self._ignore(stmt, "RETURN ends the program here")
        elif stmt.kind == "GOTO":
            raise self._error("GOTO is not supported (olp's IR has no control flow)", stmt.span)
        else:
            self._ignore(stmt, _IGNORE_REASONS[stmt.kind])


_ONE_CP_APPROX = frozenset((a,) for a in _CP_APPROX)
_DATA_TABLES = {"$BASE": "BASE_DATA", "$TOOL": "TOOL_DATA"}


def _data_reference(make: Callable[..., _F], table: str, number: int) -> _F:
    """A tool or base by number, e.g. ``TOOL_DATA[3]``, resolved later against the station."""
    return make(name=f"{table}[{number}]", number=number)


def _is_axis_aggregate(agg: Aggregate) -> bool:
    if agg.type_name is not None:
        return agg.type_name.upper() in _AXIS_TYPES
    return any(m.name.upper() in _AXES for m in agg.members)


def _lower_module(module: Module, source: _Source) -> KrlResult:
    """Lower the first DEF; report the other routines; reject data lists."""
    for item in module.items:
        if isinstance(item, DatBlock):
            raise source.error(
                f"DEFDAT {item.name} is not supported yet: olp reads .src programs only",
                item.span,
            )
    routines = [item for item in module.items if isinstance(item, Routine)]
    if not routines:
        line, column = source.last_position()
        span = ir.SourceSpan(source.filename, line, column)
        raise source.error("no DEF ... END routine found", span)
    main = routines[0]
    if main.kind != "DEF":
        raise source.error(f"the first routine must be a DEF, found {main.kind}", main.span)
    lowering = _Lowering(source, _State())
    lowering.lower_body(main.body)
    for other in routines[1:]:
        reason = f"{other.kind} {other.name} is not lowered yet (only the first DEF is)"
        lowering.ignored.append(IgnoredLine(other.span, source.snippet(other.span), reason))
    program = ir.Program(
        name=main.name, instructions=tuple(lowering.instructions), source=source.filename
    )
    return KrlResult(
        program=program,
        ignored=tuple(lowering.ignored),
        notes=tuple(lowering.notes),
        status_turn=tuple(lowering.status_turn),
    )
