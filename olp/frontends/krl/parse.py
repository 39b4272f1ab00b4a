"""KRL text -> :class:`~olp.frontends.krl.ast.Module`: lark, a Transformer, and located errors.

Speed
-----
lark (pure Python, LALR, positions propagated) needs ~0.2 ms per motion line, too slow for
100k-line milling programs. So :func:`parse_module` first lets :func:`~olp.frontends.krl.fast.
scan_line` pick out the simple motion lines; each run of consecutive ones is replaced by a single
placeholder token (``\\x00``) followed by the run's line breaks, so lark parses the rest of the
file with every line number unchanged, and the placeholder becomes the run's statements. If that
parse fails for any reason, the file is parsed again with every line given to the full grammar,
so syntax errors are always the full grammar's, with its exact locations.
"""

from __future__ import annotations

import contextlib
import functools
import gc
from collections.abc import Iterator, Sequence
from typing import Any

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
from olp.errors import ParseError
from olp.frontends.krl.ast import (
    Aggregate,
    Assign,
    Binary,
    Bits,
    Block,
    Bool,
    CallStmt,
    DatBlock,
    Decl,
    DeclItem,
    EnumValue,
    Expr,
    Field,
    ForLoop,
    FuncCall,
    Index,
    InterruptCtl,
    InterruptDecl,
    Member,
    Module,
    MotionStmt,
    Num,
    Other,
    Param,
    Routine,
    SignalDecl,
    Source,
    Stmt,
    Text,
    Trigger,
    Unary,
    Var,
    WaitFor,
    WaitSec,
)
from olp.frontends.krl.comments import attach
from olp.frontends.krl.fast import RowReader, row_match, scan_line, signed_number
from olp.frontends.krl.invalid import check_routines, refused
from olp.resources import data_path

_FAST_RUN = "\x00"

# ------------------------------------------------------------------------------------------------
# Parse tree -> AST

_inline = v_args(inline=True, meta=True)

_OTHER_KINDS = {
    "ext_decl": "EXT",
    "struc_decl": "STRUC",
    "enum_decl": "ENUM",
    "goto_stmt": "GOTO",
    "label": "label",
    "return_stmt": "RETURN",
    "halt_stmt": "HALT",
    "exit_stmt": "EXIT",
    "continue_stmt": "CONTINUE",
    "brake_stmt": "BRAKE",
    "resume_stmt": "RESUME",
    "on_error_stmt": "ON_ERROR_PROCEED",
}


class _CircAngle:
    __slots__ = ("angle",)

    def __init__(self, angle: Expr) -> None:
        self.angle = angle


class _With:
    __slots__ = ("assignments",)

    def __init__(self, assignments: tuple[Assign, ...]) -> None:
        self.assignments = assignments


_NOT_TARGETS = (_CircAngle, _With, Token)


def _is_global(children: tuple[Any, ...]) -> bool:
    """Whether a declaration's modifiers hold GLOBAL (before or after DECL)."""
    return any(isinstance(c, Token) and c.type == "GLOBAL" for c in children)


def _is_const(children: tuple[Any, ...]) -> bool:
    """Whether a declaration's modifiers hold CONST (before or after DECL)."""
    return any(isinstance(c, Token) and c.type == "CONST" for c in children)


class _Case:
    __slots__ = ("body", "values")

    def __init__(self, values: tuple[Expr, ...], body: tuple[Stmt, ...]) -> None:
        self.values, self.body = values, body


class _Default:
    __slots__ = ("body",)

    def __init__(self, body: tuple[Stmt, ...]) -> None:
        self.body = body


DECL_FREE_TYPES = frozenset({"FRAME", "POS", "E6POS", "AXIS", "E6AXIS", "LOAD"})
"""Structure types a declaration may name without DECL, as controllers' own files do
(``E6AXIS XHOME={...}``, ``FRAME TOOL_CORR={...}``, ``LOAD LOAD_A1_DATA={...}`` in
``$config.dat``; ``FRAME lfOffset`` in programs). Seen in public KR C4 backups; the KSS manual's
exact rule is not quoted here, so olp accepts only these (and the simple types)."""


class _ToAst(Transformer[Token, Module]):
    """Builds the AST; never raises for any tree the grammar accepts, except for a declaration
    without DECL of a type that may not be declared so (:data:`DECL_FREE_TYPES`)."""

    def __init__(
        self, filename: str, runs: dict[int, tuple[Stmt, ...]], lines: Sequence[str] = ()
    ) -> None:
        super().__init__(visit_tokens=True)
        self._filename = filename
        self._runs = runs
        self._lines = lines

    def _source_line(self, number: int) -> str | None:
        return self._lines[number - 1] if 1 <= number <= len(self._lines) else None

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
        return Num(float(token), token.isdigit(), self._token_span(token))

    def SIGNED_NUMBER(self, token: Token) -> Num:
        value, is_int = signed_number(token)
        return Num(value, is_int, self._token_span(token))

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

    def FAST_RUN(self, token: Token) -> tuple[Stmt, ...]:
        return self._runs[token.line or 0]

    # ---- module and routines
    def start(self, children: list[Any]) -> Module:
        return Module(tuple(c for c in children if c is not None))

    @_inline
    def routine(
        self, meta: Meta, is_global: Any, name: Token, params: Any, body: tuple[Stmt, ...]
    ) -> Routine:
        span, exported = self._span(meta), is_global is not None
        return Routine("DEF", str(name), params or (), body, span, exported)

    @_inline
    def function(
        self, meta: Meta, is_global: Any, type_: Any, dims: Any, name: Token, params: Any, body: Any
    ) -> Routine:
        span, exported = self._span(meta), is_global is not None
        returns = (str(type_), tuple(dims or ()))
        return Routine("DEFFCT", str(name), params or (), body, span, exported, *returns)

    @_inline
    def return_stmt(self, meta: Meta, value: Expr | None) -> Other:
        return Other("RETURN", self._span(meta), value=value)

    def params(self, children: list[Param]) -> tuple[Param, ...]:
        return tuple(children)

    @_inline
    def param(self, meta: Meta, name: Token, array: Token | None, direction: Token | None) -> Param:
        dims = 0 if array is None else str(array).count(",") + 1
        return Param(str(name), None if direction is None else str(direction).upper(), dims)

    @_inline
    def dat_block(self, meta: Meta, name: Token, public: Any, body: tuple[Stmt, ...]) -> DatBlock:
        return DatBlock(str(name), body, self._span(meta), public=public is not None)

    def body(self, children: list[Any]) -> tuple[Stmt, ...]:
        statements: list[Stmt] = []
        for child in children:
            if isinstance(child, tuple):  # a run of fast lines
                statements.extend(child)
            elif child is not None:
                statements.append(child)
        return tuple(statements)

    @_inline
    def fast_run(self, meta: Meta, run: tuple[Stmt, ...]) -> tuple[Stmt, ...]:
        return run

    def args(self, children: list[Expr]) -> tuple[Expr, ...]:
        return tuple(children)

    def call_args(self, children: list[Expr | None]) -> tuple[Expr | None, ...]:
        return () if children == [None] else tuple(children)

    # ---- statements
    @_inline
    def assignment(self, meta: Meta, target: Var, value: Expr) -> Assign:
        return Assign(target, value, self._span(meta))

    @_inline
    def call_stmt(self, meta: Meta, name: Token, args: tuple[Expr | None, ...]) -> CallStmt:
        return CallStmt(str(name), args, self._span(meta))

    @_inline
    def interrupt_decl(
        self, meta: Meta, glob: Token | None, prio: Expr, cond: Expr, action: CallStmt | Assign
    ) -> InterruptDecl:
        return InterruptDecl(glob is not None, prio, cond, action, self._span(meta))

    @_inline
    def interrupt_ctl(self, meta: Meta, action: Token, prio: Expr | None) -> InterruptCtl:
        return InterruptCtl(str(action).upper(), prio, self._span(meta))

    @_inline
    def trigger(self, meta: Meta, mode: Token, position: Expr, *rest: Any) -> Trigger:
        onstart, delay, action, prio = rest
        span = self._span(meta)
        return Trigger(str(mode).upper(), position, onstart is not None, delay, action, prio, span)

    @_inline
    def motion(self, meta: Meta, keyword: Token, *rest: Any) -> MotionStmt:
        *items, frame_option = rest  # the grammar's last child is the optional #BASE/#TOOL
        targets = tuple(i for i in items if i is not None and not isinstance(i, _NOT_TARGETS))
        angles = [i.angle for i in items if isinstance(i, _CircAngle)]
        withs = [i.assignments for i in items if isinstance(i, _With)]
        approx = tuple(str(i).upper() for i in items if isinstance(i, Token))
        return MotionStmt(
            str(keyword).upper(),
            targets,
            angles[0] if angles else None,
            approx,
            self._span(meta),
            withs[0] if withs else (),
            frame_option,
        )

    @_inline
    def circ_angle(self, meta: Meta, angle: Expr) -> _CircAngle:
        return _CircAngle(angle)

    def with_clause(self, children: list[Assign]) -> _With:
        return _With(tuple(children))

    @_inline
    def approx(self, meta: Meta, keyword: Token) -> Token:
        return keyword

    @_inline
    def spline_block(self, meta: Meta, keyword: Token, _with: Any, body: Any, *_: Any) -> Block:
        return Block(str(keyword).upper(), (body,), self._span(meta))

    @_inline
    def wait_sec(self, meta: Meta, seconds: Expr) -> WaitSec:
        return WaitSec(seconds, self._span(meta))

    @_inline
    def wait_for(self, meta: Meta, condition: Expr) -> WaitFor:
        return WaitFor(condition, self._span(meta))

    @_inline
    def decl(self, meta: Meta, *children: Any) -> Decl:
        type_name = next(c for c in children if isinstance(c, str) and not isinstance(c, Token))
        items = tuple(c for c in children if isinstance(c, DeclItem))
        span, glob, const = self._span(meta), _is_global(children), _is_const(children)
        return Decl(type_name.upper(), items, span, glob, const)

    @_inline
    def bare_decl(self, meta: Meta, *children: Any) -> Decl:
        """A declaration without DECL (``FRAME lfOffset``): the type is the name before the
        first item, after any GLOBAL/CONST. Only the predefined structure types may be declared
        so (:data:`DECL_FREE_TYPES`); anything else is a located error, so that a misspelt
        statement (``PTPP XP1``) is never taken for a declaration."""
        items = tuple(c for c in children if isinstance(c, DeclItem))
        type_name = next(c for c in children if isinstance(c, Token) and c.type == "NAME")
        if type_name.upper() not in DECL_FREE_TYPES:
            first = items[0]
            known = ", ".join(sorted(DECL_FREE_TYPES))
            raise ParseError(
                f"unexpected {first.name!r} after {str(type_name)!r}: {type_name} is not a "
                f"statement, and only the predefined types ({known}) are declared without DECL",
                first.span,
                self._source_line(first.span.line),
            )
        span, glob, const = self._span(meta), _is_global(children), _is_const(children)
        return Decl(str(type_name).upper(), items, span, glob, const)

    @_inline
    def type_name(self, meta: Meta, name: Any) -> str:
        return str(name)

    @_inline
    def simple_type(self, meta: Meta, name: Token) -> str:
        return str(name)

    @_inline
    def decl_item(self, meta: Meta, name: Token, dims: Any, value: Expr | None) -> DeclItem:
        return DeclItem(str(name), dims, value, self._span(meta))

    @_inline
    def dims(self, meta: Meta, args: tuple[Expr | None, ...]) -> tuple[Expr | None, ...]:
        return args or (None,)  # ``name[]``: one extent left open (an array parameter's)

    @_inline
    def signal_decl(
        self, meta: Meta, is_global: Any, name: Token, first: Expr, last: Expr | None
    ) -> SignalDecl:
        span = self._span(meta)
        return SignalDecl(str(name).upper(), first, last, span, is_global is not None)

    def _block(self, keyword: str, meta: Meta, bodies: Sequence[Any]) -> Block:
        kept = tuple(b for b in bodies if isinstance(b, tuple))
        return Block(keyword, kept, self._span(meta))

    @_inline
    def if_stmt(self, meta: Meta, cond: Expr, then: Any, otherwise: Any) -> Block:
        bodies = (then or (), otherwise or ())
        return Block("IF", bodies, self._span(meta), (cond,), (), otherwise is not None)

    @_inline
    def for_stmt(
        self, meta: Meta, counter: Token, start: Expr, end: Expr, step: Expr | None, body: Any
    ) -> ForLoop:
        return ForLoop(str(counter), start, end, step, body, self._span(meta))

    @_inline
    def while_stmt(self, meta: Meta, cond: Expr, body: Any) -> Block:
        return Block("WHILE", (body or (),), self._span(meta), (cond,))

    @_inline
    def loop_stmt(self, meta: Meta, body: Any) -> Block:
        return self._block("LOOP", meta, (body,))

    @_inline
    def repeat_stmt(self, meta: Meta, body: Any, until: Expr) -> Block:
        return Block("REPEAT", (body or (),), self._span(meta), (until,))

    @_inline
    def switch_stmt(self, meta: Meta, subject: Expr, *clauses: Any) -> Block:
        cases = [c for c in clauses if isinstance(c, _Case)]
        default = next((c for c in clauses if isinstance(c, _Default)), None)
        bodies = (*(c.body for c in cases), () if default is None else default.body)
        values = tuple(c.values for c in cases)
        return Block("SWITCH", bodies, self._span(meta), (subject,), values, default is not None)

    @_inline
    def case_clause(self, meta: Meta, values: tuple[Expr, ...], body: Any) -> _Case:
        return _Case(values, body or ())

    @_inline
    def default_clause(self, meta: Meta, body: Any) -> _Default:
        return _Default(body or ())

    @_inline
    def goto_stmt(self, meta: Meta, name: Token) -> Other:
        return Other("GOTO", self._span(meta), str(name))

    @_inline
    def label(self, meta: Meta, name: Token) -> Other:
        return Other("label", self._span(meta), str(name))

    # ---- expressions
    @_inline
    def binary(self, meta: Meta, left: Expr, op: Token, right: Expr) -> Binary:
        return Binary(str(op).upper(), left, right, self._span(meta))

    @_inline
    def unary_op(self, meta: Meta, op: Token, operand: Expr) -> Unary:
        return Unary(str(op).upper(), operand, self._span(meta))

    @_inline
    def func_call(self, meta: Meta, name: Token, args: tuple[Expr | None, ...]) -> FuncCall:
        return FuncCall(str(name), args, self._span(meta))

    @_inline
    def variable(self, meta: Meta, name: Token, *selectors: Index | Field) -> Var:
        return Var(str(name), selectors, self._span(meta))

    @_inline
    def index(self, meta: Meta, args: tuple[Expr | None, ...]) -> Index:
        return Index(args)

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
# Parsing

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
        "_ENDSPLINE",
        "$END",
    }
)
# The fast path's grammar: the full one plus a statement that stands for a run of fast lines.
_FAST_RULES = '\n%extend _statement: fast_run\nfast_run: FAST_RUN\nFAST_RUN: "\\x00"\n'


@functools.lru_cache(maxsize=2)
def _parser(fast: bool = False) -> Lark:
    grammar = data_path("grammars", "krl.lark").read_text(encoding="utf-8")
    if fast:
        grammar += _FAST_RULES
    return Lark(grammar, parser="lalr", propagate_positions=True, maybe_placeholders=True)


@functools.lru_cache(maxsize=1)
def _terminal_descriptions() -> dict[str, str]:
    described = dict(_TERMINAL_NAMES)
    for terminal in _parser().terminals:
        if isinstance(terminal.pattern, PatternStr) and terminal.name not in described:
            described[terminal.name] = f"'{terminal.pattern.value.upper()}'"
    return described


def parse_module(source: Source, fast: bool = True) -> Module:
    """The AST of ``source``; :class:`ParseError` (located) for text the grammar rejects.

    ``fast=False`` gives every line to lark (the reference the fast path is tested against).
    The source's comments are statements of the module, in place
    (:func:`olp.frontends.krl.comments.attach`). Text that is not KRL at all (a bare name, END
    closing a DEFFCT, a routine defined twice, ...) gets a targeted error marked
    :data:`~olp.errors.INVALID_KRL` (:mod:`olp.frontends.krl.invalid`).
    """
    module = _parse_module(source, fast)
    check_routines(module, source)
    return attach(module, source)


def _parse_module(source: Source, fast: bool) -> Module:
    if fast and _FAST_RUN not in source.text:
        text, runs = _substitute_fast_runs(source)
        if runs:
            try:
                return _parse(text, source.filename, runs, fast=True)
            except (UnexpectedInput, VisitError):
                pass  # parse again below: the full grammar reports errors exactly
    try:
        return _parse(source.text, source.filename, {}, fast=False)
    except UnexpectedInput as exc:
        raise _syntax_error(exc, source) from None
    except VisitError as exc:
        if isinstance(exc.orig_exc, ParseError | RecursionError):
            raise exc.orig_exc from None
        raise


def _parse(text: str, filename: str, runs: dict[int, tuple[Stmt, ...]], fast: bool) -> Module:
    tree = _parser(fast).parse(text + "\n")
    return _ToAst(filename, runs, text.split("\n")).transform(tree)


def _substitute_fast_runs(source: Source) -> tuple[str, dict[int, tuple[Stmt, ...]]]:
    """The text with each run of fast lines replaced by one placeholder (line numbers kept), and
    the runs by the line of their placeholder: :class:`FastMotion` statements, and
    :class:`LinRows` for consecutive lines of the CAM shape."""
    lines = source.text.split("\n")
    runs: dict[int, tuple[Stmt, ...]] = {}
    run: list[Stmt] = []
    first = 0  # line of the current run's placeholder (0: no run)
    rows = RowReader(source.filename)
    matched, matched_lines = rows.matches.append, rows.lines.append
    for index, line in enumerate(lines):
        match = row_match(line)
        if match is not None:
            matched(match)  # RowReader.add, without a call per line
            matched_lines(index + 1)
        else:
            fast = scan_line(line, index + 1, source.filename) if line else None
            run.extend(rows.flush())
            if fast is None:
                if first:
                    runs[first], run, first = tuple(run), [], 0
                continue
            run.append(fast)
        lines[index] = "" if first else _FAST_RUN
        first = first or index + 1
    run.extend(rows.flush())
    if first:
        runs[first] = tuple(run)
    return "\n".join(lines), runs


@contextlib.contextmanager
def gc_paused() -> Iterator[None]:
    """Pause the cyclic garbage collector: reading makes many small acyclic objects, and
    collections triggered by them made the time grow faster than linearly with program length."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


# ------------------------------------------------------------------------------------------------
# Syntax errors


def _syntax_error(exc: UnexpectedInput, source: Source) -> ParseError:
    """A ParseError saying what was found where, and what the grammar expected there; the
    targeted one of :func:`~olp.frontends.krl.invalid.refused` where the text is not KRL."""
    found, expected, end = "end of file", set[str](), None
    line, column = exc.line, exc.column
    if isinstance(exc, UnexpectedToken):
        found, expected = _describe_token(exc.token), set(exc.expected)
        invalid = refused(exc.token, expected, found, source)
        if invalid is not None:
            return invalid
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
