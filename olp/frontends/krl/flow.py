"""KRL expressions -> :mod:`olp.ir_flow` expressions, and the structured-lowering helpers the
statement walk (:mod:`olp.frontends.krl.lower`) uses for IF, SWITCH, loops and jumps.

KRL's operators map one to one: ``AND``/``OR``/``EXOR``/``NOT`` -> ``and``/``or``/``xor``/
``not``, ``B_AND``/``B_OR``/``B_EXOR``/``B_NOT`` -> ``bit_and``/``bit_or``/``bit_xor``/
``bit_not``, ``:`` -> ``geometric``; comparisons and arithmetic keep their symbols. ``$IN[n]``
with a constant ``n``, and a one-bit SIGNAL of an input, become :class:`olp.ir.DigitalInput`;
``#NAME`` an enumeration :class:`olp.ir.Constant`; ``'B0101'`` an integer constant.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

from olp import ir
from olp.frontends.krl.ast import (
    Aggregate,
    Assign,
    Binary,
    Bits,
    Block,
    Bool,
    EnumValue,
    Expr,
    Field,
    ForLoop,
    FuncCall,
    Index,
    Num,
    Other,
    Stmt,
    Text,
    Unary,
    Var,
)
from olp.frontends.krl.values import Unknown, Value

_BINARY = {
    "AND": "and",
    "OR": "or",
    "EXOR": "xor",
    "B_AND": "bit_and",
    "B_OR": "bit_or",
    "B_EXOR": "bit_xor",
    ":": "geometric",
}
_UNARY = {"NOT": "not", "B_NOT": "bit_not"}

InputOf = Callable[[Var], ir.DigitalInput | None]
"""The digital input a variable reads (``$IN[3]``, a one-bit SIGNAL), if it is one."""


def to_expr(expr: Expr | None, input_of: InputOf) -> ir.Expr | None:
    """The IR expression for ``expr`` (None stays None: an argument left out)."""
    if expr is None:
        return None
    return _convert(expr, input_of)


def _convert(expr: Expr, input_of: InputOf) -> ir.Expr:
    span = expr.span
    if isinstance(expr, Num):
        whole = expr.is_int and math.isfinite(expr.value)  # '9' * 400 reads as infinity
        value: bool | int | float | str = int(expr.value) if whole else expr.value
        return ir.Constant(value=value, span=span)
    if isinstance(expr, Bool | Text | Bits):
        return ir.Constant(value=expr.value, span=span)
    if isinstance(expr, EnumValue):
        return ir.Constant(value=expr.name, enum=True, span=span)
    if isinstance(expr, Aggregate):
        members = tuple((m.name, _convert(m.value, input_of)) for m in expr.members)
        return ir.Aggregate(members=members, type_name=expr.type_name, span=span)
    if isinstance(expr, Var):
        return _variable(expr, input_of)
    if isinstance(expr, Unary):
        op = _UNARY.get(expr.op, expr.op)
        return ir.UnaryOp(op=op, operand=_convert(expr.operand, input_of), span=span)
    if isinstance(expr, Binary):
        left, right = _convert(expr.left, input_of), _convert(expr.right, input_of)
        return ir.BinaryOp(op=_BINARY.get(expr.op, expr.op), left=left, right=right, span=span)
    assert isinstance(expr, FuncCall)
    args = tuple(to_expr(a, input_of) for a in expr.args)
    return ir.FunctionCall(name=expr.name, args=args, span=span)


def _variable(var: Var, input_of: InputOf) -> ir.Expr:
    found = input_of(var)
    if found is not None:
        return found
    out: ir.Expr = ir.Name(name=var.name, span=var.span)
    for selector in var.selectors:
        if isinstance(selector, Field):
            out = ir.Member(base=out, field=selector.name, span=var.span)
        else:
            assert isinstance(selector, Index)
            indices = tuple(to_expr(a, input_of) for a in selector.args)
            out = ir.Index(base=out, indices=indices, span=var.span)
    return out


# ------------------------------------------------------------------------------------------------
# What a routine's body holds (scanned before it is lowered)


def statements(body: Iterable[Stmt]) -> Iterator[Stmt]:
    """Every statement of ``body``, nested bodies included."""
    for stmt in body:
        yield stmt
        if isinstance(stmt, Block):
            for inner in stmt.bodies:
                yield from statements(inner)
        elif isinstance(stmt, ForLoop):
            yield from statements(stmt.body)


def jump_targets(body: Iterable[Stmt]) -> dict[str, list[int]]:
    """Label (upper case) -> the lines of the GOTOs that jump to it."""
    found: dict[str, list[int]] = {}
    for stmt in statements(body):
        if isinstance(stmt, Other) and stmt.kind == "GOTO" and stmt.name is not None:
            found.setdefault(stmt.name.upper(), []).append(stmt.span.line)
    return found


def assigned_names(body: Iterable[Stmt]) -> set[str]:
    """The plain variables (upper case) the body assigns anywhere (FOR counters included)."""
    names = {s.target.name.upper() for s in statements(body) if isinstance(s, Assign)}
    return names | {s.counter.upper() for s in statements(body) if isinstance(s, ForLoop)}


def is_straight(body: Iterable[Stmt]) -> bool:
    """Whether ``body`` holds no block and no jump, nested FOR loops included (a FOR over it may
    be unrolled: an EXIT or RETURN in it then ends the unrolling)."""
    for stmt in statements(body):
        if isinstance(stmt, Block):
            return False
        if isinstance(stmt, Other) and stmt.kind in ("GOTO", "label"):
            return False
    return True


# ------------------------------------------------------------------------------------------------
# The counter of a FOR loop olp unrolled, after the loop


@dataclass(frozen=True, slots=True)
class PastFor(Unknown):
    """The value of a FOR counter after the loop olp wrote out pass by pass (``line``: the
    FOR's). The passes write ``counter = n`` only where they read it; what KRL leaves in the
    counter after the loop (one step past the end value, as olp recalls the KSS manual; not
    verified against a stored copy, nor what a loop left by EXIT or run zero times leaves) is
    not written. So a statement after the loop that reads the counter is an error rather than
    a text that reads another value on the controller."""

    line: int = 0
    name: str = ""


def past_for(name: str, line: int) -> PastFor:
    reason = f"olp does not track {name} after its FOR loop (line {line})"
    return PastFor(reason, line=line, name=name)


def joined(values: Sequence[Value], reason: str) -> Value:
    """The value after paths that disagree: unknown, and still a counter past its unrolled FOR
    (:class:`PastFor`) where one path leaves it so: reading it is then an error on every path."""
    past = next((v for v in values if isinstance(v, PastFor)), None)
    return past if past is not None else Unknown(reason)


def reads_name(nodes: Sequence[Any], name: str) -> bool:
    """Whether lowered ``nodes`` read the variable ``name``: a :class:`ir.Name` in any of their
    expressions, or the word in a statement kept as text (a verbatim line, a call's arguments).
    Other text is not code: a component (``p.X``), a constant (``'X'``), olp's reasons."""
    word = re.compile(rf"(?<![\w$]){re.escape(name)}(?![\w$])", re.IGNORECASE)
    pending: list[tuple[Any, bool]] = [(node, False) for node in nodes]
    while pending:
        node, code = pending.pop()
        if isinstance(node, ir.Comment):  # a remark, not a statement: it reads nothing
            continue
        if isinstance(node, ir.Name):
            if node.name.upper() == name.upper():
                return True
        elif isinstance(node, str):
            if code and word.search(node):
                return True
        elif isinstance(node, tuple | list):
            pending.extend((part, code) for part in node)
        elif isinstance(node, ir.Verbatim):
            pending.append((node.text, True))
        elif isinstance(node, ir.Call):
            pending.append((node.args, True))
        elif dataclasses.is_dataclass(node) and not isinstance(node, ir.SourceSpan):
            pending.extend((getattr(node, f.name), False) for f in dataclasses.fields(node))
    return False


def reads_value(nodes: Sequence[Any], name: str) -> bool:
    """Whether lowered ``nodes`` read the variable ``name``, an assignment to it as a whole
    writing it, not reading it (:func:`reads_name` of the rest)."""
    values = [
        n.value if isinstance(n, ir.Assign) and isinstance(n.target, ir.Name) else n for n in nodes
    ]
    return reads_name(values, name)
