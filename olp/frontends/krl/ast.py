"""The KRL frontend's shared vocabulary: source files, the AST, and what a run reports.

The AST is what :mod:`olp.frontends.krl.parse` makes of ``grammars/krl.lark``'s parse tree (and
what :mod:`olp.frontends.krl.fast` makes of simple motion lines without lark); it is lowered by
:mod:`olp.frontends.krl.lower`. Every node knows its :class:`~olp.ir.SourceSpan`.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Literal, TypeAlias

import numpy as np

from olp import ir
from olp.errors import ParseError

# ------------------------------------------------------------------------------------------------
# Source text: spans, lines and errors


@dataclass(frozen=True, slots=True)
class Source:
    """One file's text, split into lines the way lark counts them."""

    filename: str
    text: str
    lines: tuple[str, ...]

    @classmethod
    def of(cls, text: str, filename: str) -> Source:
        text = text.removeprefix("\ufeff")
        # Only "\n" ends a line for lark; str.splitlines knows more breaks.
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


class SourceSet:
    """The files one run reads (.src, .dat, $config.dat): errors show the right file's line."""

    def __init__(self, sources: Iterable[Source] = ()) -> None:
        self._by_name: dict[str, Source] = {}
        for source in sources:
            self.add(source)

    def add(self, source: Source) -> None:
        self._by_name[source.filename] = source

    def source(self, filename: str) -> Source | None:
        return self._by_name.get(filename)

    def snippet(self, span: ir.SourceSpan) -> str:
        source = self._by_name.get(span.file)
        return "" if source is None else source.snippet(span)

    def error(self, message: str, span: ir.SourceSpan, hint: str | None = None) -> ParseError:
        source = self._by_name.get(span.file)
        line = None if source is None else source.line(span.line)
        return ParseError(message, span, line, hint)


# ------------------------------------------------------------------------------------------------
# What a run reports besides the program


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
    """KUKA Status (S) and Turn (T) given with the Cartesian target of the motion at ``span``."""

    span: ir.SourceSpan
    status: int | None
    turn: int | None


# ------------------------------------------------------------------------------------------------
# Expressions


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
    """``{TYPE: NAME value, ...}``; values are constants (KRL allows nothing else here)."""

    type_name: str | None
    members: tuple[Member, ...]
    span: ir.SourceSpan

    def member(self, name: str) -> Member | None:
        """The member called ``name`` (upper case), if any."""
        for member in self.members:
            if member.name.upper() == name:
                return member
        return None


@dataclass(frozen=True, slots=True)
class Index:
    """``[a, b]``; a position left out (``TOOL_NAME[1,]``) is None."""

    args: tuple[Expr | None, ...]


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
    args: tuple[Expr | None, ...]
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

# ------------------------------------------------------------------------------------------------
# Statements


@dataclass(frozen=True, slots=True)
class Assign:
    target: Var
    value: Expr
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class CallStmt:
    name: str
    args: tuple[Expr | None, ...]
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class MotionStmt:
    """``PTP/LIN/CIRC/..._REL/S.../SPL target(s) [, CA angle] [WITH ...] [approx] [#frame]``."""

    keyword: str
    targets: tuple[Expr, ...]
    angle: Expr | None
    approx: tuple[str, ...]
    span: ir.SourceSpan
    with_clause: tuple[Assign, ...] = ()
    frame_option: EnumValue | None = None


@dataclass(frozen=True, slots=True)
class FastMotion:
    """A simple motion line read without lark (see :mod:`olp.frontends.krl.fast`).

    ``keyword {[TYPE:] NAME number, ...} [approx]``: the values are already numbers; the line's
    text is kept so that :func:`olp.frontends.krl.fast.materialise` can rebuild the full
    :class:`MotionStmt` (with a span per member) whenever the lowering needs more than the
    common case.
    """

    keyword: str
    type_name: str | None
    names: tuple[str, ...]  # upper case
    values: tuple[float, ...]
    approx: tuple[str, ...]
    span: ir.SourceSpan
    text: str


@dataclass(frozen=True, slots=True, eq=False)
class LinRows:
    """Consecutive lines ``LIN {X ..,Y ..,Z ..,A ..,B ..,C ..}`` (optionally `` C_DIS``), each
    starting in column 1 and written exactly so (see :func:`olp.frontends.krl.fast.scan_rows`),
    read as arrays.

    ``values`` (N, 6): X, Y, Z (mm), A, B, C (deg) as written; ``approx`` (N,) bool: the row
    ends in C_DIS; ``lines`` (N,) 1-based line numbers; ``ends`` (N,) each row's end column
    (1-based, exclusive); ``texts`` the lines as written (for
    :func:`olp.frontends.krl.fast.row_motions`, which gives the rows as :class:`FastMotion`
    whenever the lowering needs more than the common case); ``span`` the first row's.
    """

    values: np.ndarray
    approx: np.ndarray
    lines: np.ndarray
    ends: np.ndarray
    texts: tuple[str, ...]
    span: ir.SourceSpan

    def __len__(self) -> int:
        return len(self.texts)


@dataclass(frozen=True, slots=True)
class WaitSec:
    seconds: Expr
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class WaitFor:
    condition: Expr
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class DeclItem:
    name: str
    dims: tuple[Expr | None, ...] | None  # a position left out (xPath[,]) is None
    value: Expr | None
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Decl:
    """``DECL [GLOBAL] [CONST] TYPE name[dims] [= value], ...`` (``is_global``: GLOBAL given,
    ``is_const``: CONST given)"""

    type_name: str
    items: tuple[DeclItem, ...]
    span: ir.SourceSpan
    is_global: bool = False
    is_const: bool = False


@dataclass(frozen=True, slots=True)
class SignalDecl:
    """``[GLOBAL] SIGNAL name $OUT[n] [TO $OUT[m]]`` (``is_global``: GLOBAL given)"""

    name: str
    first: Expr
    last: Expr | None
    span: ir.SourceSpan
    is_global: bool = False


@dataclass(frozen=True, slots=True)
class ForLoop:
    counter: str
    start: Expr
    end: Expr
    step: Expr | None
    body: tuple[Stmt, ...]
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Block:
    """A control-flow statement (IF, WHILE, SPLINE, ...) with its bodies.

    ``conditions``: IF and WHILE: the condition; REPEAT: the UNTIL condition; SWITCH: the
    subject. ``bodies``: IF: then, else (empty if none); SWITCH: one per CASE, then the
    DEFAULT's; others: the body. ``cases``: SWITCH: the values of each CASE. ``has_else``: an
    IF's ELSE or a SWITCH's DEFAULT is written.
    """

    keyword: str
    bodies: tuple[tuple[Stmt, ...], ...]
    span: ir.SourceSpan
    conditions: tuple[Expr, ...] = ()
    cases: tuple[tuple[Expr, ...], ...] = ()
    has_else: bool = False


@dataclass(frozen=True, slots=True)
class Other:
    """A statement the grammar knows and olp only reports (interrupts, EXT, STRUC, ...)."""

    kind: str
    span: ir.SourceSpan
    name: str | None = None  # a label's or a GOTO's label name
    value: Expr | None = None  # what a RETURN gives back (a function's result)


@dataclass(frozen=True, slots=True)
class InterruptDecl:
    """``[GLOBAL] INTERRUPT DECL prio WHEN condition DO handler(args)``."""

    exported: bool
    priority: Expr
    condition: Expr
    action: CallStmt | Assign
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class InterruptCtl:
    """``INTERRUPT ON|OFF|ENABLE|DISABLE [prio]``."""

    action: str
    priority: Expr | None
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Trigger:
    """``TRIGGER WHEN DISTANCE|PATH=value [ONSTART] DELAY=t DO action [PRIO=p]``."""

    mode: str  # "DISTANCE" or "PATH"
    position: Expr
    onstart: bool
    delay: Expr
    action: CallStmt | Assign
    priority: Expr | None
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class CommentStmt:
    """A comment of the source, in place among the statements (:mod:`olp.frontends.krl.comments`):
    a line of its own (``; text``), a fold line (``;FOLD ...``, ``;ENDFOLD ...``: ``fold`` is
    ``"open"`` or ``"close"``), or the end of a statement's line (after that statement).
    ``text`` is what follows the ``;``: as written for a fold line, stripped otherwise."""

    text: str
    fold: Literal["open", "close"] | None
    span: ir.SourceSpan


Stmt: TypeAlias = (
    Assign
    | CallStmt
    | MotionStmt
    | FastMotion
    | LinRows
    | WaitSec
    | WaitFor
    | Decl
    | SignalDecl
    | ForLoop
    | Block
    | InterruptDecl
    | InterruptCtl
    | Trigger
    | Other
    | CommentStmt
)


@dataclass(frozen=True, slots=True)
class Param:
    name: str
    direction: str | None  # "IN", "OUT" or not given
    head_dims: int = 0  # the empty brackets' dimensions in the head: sText[]:IN 1, x[,] 2


@dataclass(frozen=True, slots=True)
class Routine:
    kind: str  # "DEF" or "DEFFCT"
    name: str
    params: tuple[Param, ...]
    body: tuple[Stmt, ...]
    span: ir.SourceSpan
    exported: bool = False  # GLOBAL DEF / GLOBAL DEFFCT
    returns: str | None = None  # a DEFFCT's result type
    returns_dims: tuple[Expr | None, ...] = ()  # DEFFCT CHAR[128]


@dataclass(frozen=True, slots=True)
class DatBlock:
    """``DEFDAT name [PUBLIC]`` ... ``ENDDAT``."""

    name: str
    body: tuple[Stmt, ...]
    span: ir.SourceSpan
    public: bool = False


@dataclass(frozen=True, slots=True)
class Module:
    items: tuple[Routine | DatBlock, ...]
