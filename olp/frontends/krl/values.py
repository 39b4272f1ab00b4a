"""Constant values of KRL expressions and the variables olp knows while reading a program.

olp does not run KRL; it evaluates what is constant in the program text: literals, aggregates,
variables declared with a value (in the module's .dat, a ``$config.dat`` or the program),
constant arithmetic, FOR counters and parameters passed constants. Anything else evaluates to
:class:`Unknown`, which carries the reason, so that a statement that needs the value can say why
olp does not have it.

Values are the constant AST nodes themselves (they keep the span where they were written, so an
error about ``XP1`` can point into the .dat), plus :class:`ArrayValue` and :class:`Signal`.
Arithmetic follows KRL: INT op INT is INT and INT division truncates toward zero; ``:`` is the
geometric operator (frame composition).
"""

from __future__ import annotations

import dataclasses
import math
import operator
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import TypeAlias

from olp import ir
from olp.frontends.krl.ast import (
    Aggregate,
    Binary,
    Bits,
    Bool,
    EnumValue,
    Expr,
    Field,
    FuncCall,
    Index,
    Member,
    Num,
    Text,
    Unary,
    Var,
)
from olp.vendors.kuka import frame_to_pose, pose_to_frame

CARTESIAN = ("X", "Y", "Z", "A", "B", "C")
AXES = tuple(f"A{i}" for i in range(1, 7))
EXTERNAL = tuple(f"E{i}" for i in range(1, 7))
AXIS_TYPES = frozenset({"AXIS", "E6AXIS"})
POS_TYPES = frozenset({"POS", "E6POS", "FRAME"})

ElementKey: TypeAlias = tuple[int | None, ...]


@dataclass(frozen=True, slots=True)
class ArrayValue:
    """A declared array (``DECL FRAME TOOL_DATA[16]``) and the elements given a value so far."""

    type_name: str
    elements: Mapping[ElementKey, Const]
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Signal:
    """``SIGNAL name $OUT[n]``: a one-bit name for a digital input or output."""

    io: str  # "$IN" or "$OUT"
    index: int
    span: ir.SourceSpan


@dataclass(frozen=True, slots=True)
class Unknown:
    """A value olp does not know, and why (shown to the user when a statement needs it).

    ``missing``: a value missing from the program itself, not one the controller computes as
    it runs: a name it depends on is declared nowhere although every file where the controller
    would find it was given (another module's data list may still be missing), or a local
    variable is read before the program gives it a value (the controller stops there too). A
    name no file olp read declares while the module's .dat or the ``$config.dat`` was not given
    is not ``missing``: its value is the controller's, known when the program runs
    (:meth:`olp.frontends.krl.state.Context.unknown_name`)."""

    reason: str
    hint: str | None = None
    missing: bool = False


@dataclass(frozen=True, slots=True)
class Counter(Unknown):
    """The counter of a FOR loop with constant bounds while olp tries its body with the counter
    unknown (:meth:`olp.frontends.krl.lower._Lowering._lowers_as_block`): not a value of the
    run, since unrolling the loop knows it. A motion setting computed from it is not kept as a
    run-time one (:meth:`olp.frontends.krl.state.Core._at_run_time`): the loop is unrolled and
    each pass's setting known."""


Const: TypeAlias = Num | Bool | Text | Bits | EnumValue | Aggregate | ArrayValue | Signal
Value: TypeAlias = Const | Unknown


def is_axis_aggregate(agg: Aggregate) -> bool:
    """True for AXIS/E6AXIS values (by type, else by their A1..A6 members)."""
    if agg.type_name is not None:
        return agg.type_name.upper() in AXIS_TYPES
    return any(m.name.upper() in AXES for m in agg.members)


def variables_read(expr: Expr | None) -> Iterator[Var]:
    """Each variable ``expr`` reads, index expressions included."""
    if isinstance(expr, Var):
        yield expr
        for selector in expr.selectors:
            if isinstance(selector, Index):
                for arg in selector.args:
                    yield from variables_read(arg)
    elif isinstance(expr, FuncCall):
        for arg in expr.args:
            yield from variables_read(arg)
    elif isinstance(expr, Aggregate):
        for member in expr.members:
            yield from variables_read(member.value)
    elif isinstance(expr, Unary):
        yield from variables_read(expr.operand)
    elif isinstance(expr, Binary):
        yield from variables_read(expr.left)
        yield from variables_read(expr.right)


def with_type(value: Const, type_name: str) -> Const:
    """An aggregate written without a type prefix takes its declaration's type."""
    if isinstance(value, Aggregate) and value.type_name is None:
        return dataclasses.replace(value, type_name=type_name)
    return value


# ------------------------------------------------------------------------------------------------
# Variables


@dataclass(slots=True)
class _Scope:
    values: dict[str, Value] = field(default_factory=dict)
    params: frozenset[str] = frozenset()


class Variables:
    """Names (upper case) -> values: the globals (data lists, undeclared names the program
    assigns) and one local scope per routine activation (parameters, local DECLs)."""

    def __init__(self, globals_: dict[str, Value], describe_missing: Callable[[str], Unknown]):
        self.globals = globals_
        self.scopes = [_Scope()]
        self._describe_missing = describe_missing

    def lookup(self, name: str) -> Value:
        local = self.scopes[-1].values
        if name in local:
            return local[name]
        if name in self.globals:
            return self.globals[name]
        return self._describe_missing(name)

    def is_declared(self, name: str) -> bool:
        return name in self.scopes[-1].values or name in self.globals

    def assign(self, name: str, value: Value) -> None:
        local = self.scopes[-1].values
        (local if name in local else self.globals)[name] = value

    def declare(self, name: str, value: Value) -> None:
        """A local declaration; a routine's DECL of its own parameter keeps the argument."""
        scope = self.scopes[-1]
        if name not in scope.params:
            scope.values[name] = value

    def is_param(self, name: str) -> bool:
        return name in self.scopes[-1].params

    def push(self, params: dict[str, Value]) -> None:
        self.scopes.append(_Scope(dict(params), frozenset(params)))

    def pop(self) -> dict[str, Value]:
        return self.scopes.pop().values

    def copy(self) -> Variables:
        twin = Variables(dict(self.globals), self._describe_missing)
        twin.scopes = [_Scope(dict(s.values), s.params) for s in self.scopes]
        return twin

    def changed_since(self, before: Variables) -> set[str]:
        """Names whose value differs from ``before`` (a copy taken earlier) in visible scopes."""
        changed = {n for n, v in self.globals.items() if before.globals.get(n) is not v}
        local, old = self.scopes[-1].values, before.scopes[-1].values
        return changed | {n for n, v in local.items() if old.get(n) is not v}


# ------------------------------------------------------------------------------------------------
# Evaluation


class Evaluator:
    """Evaluates expressions against :class:`Variables`; never raises for a bad program."""

    def __init__(self, variables: Variables, snippet: Callable[[ir.SourceSpan], str]) -> None:
        self.variables = variables
        self._snippet = snippet

    def evaluate(self, expr: Expr | None) -> Value:
        if expr is None:
            return Unknown("the argument is left out")
        if isinstance(expr, Num | Bool | Text | Bits | EnumValue | Aggregate):
            return expr
        if isinstance(expr, Var):
            return self._variable(expr)
        if isinstance(expr, Unary):
            return _unary(expr, self.evaluate(expr.operand))
        if isinstance(expr, Binary):
            return _binary(expr, self.evaluate(expr.left), self.evaluate(expr.right))
        assert isinstance(expr, FuncCall)
        return Unknown(f"olp does not evaluate function calls ({expr.name}(...))")

    def _variable(self, var: Var) -> Value:
        value = self.variables.lookup(var.name.upper())
        written = var.name
        for selector in var.selectors:
            if isinstance(value, Unknown):
                return value
            if isinstance(selector, Field):
                value = _field(value, selector.name, written)
                written += f".{selector.name}"
            else:
                key = self.index_key(selector)
                if isinstance(key, Unknown):
                    return key
                value = _element(value, key, written)
                written += _key_text(key)
        return value

    def index_key(self, index: Index) -> ElementKey | Unknown:
        """The integer positions of ``[a, b]`` (None where left out)."""
        key: list[int | None] = []
        for arg in index.args:
            if arg is None:
                key.append(None)
                continue
            value = self.evaluate(arg)
            number = as_int(value)
            if number is None:
                reason = value.reason if isinstance(value, Unknown) else "it is not an integer"
                missing = isinstance(value, Unknown) and value.missing
                message = f"the index {self._snippet(arg.span)!r} is not constant: {reason}"
                return Unknown(message, missing=missing)
            key.append(number)
        return tuple(key)


def as_number(value: Value) -> float | None:
    if isinstance(value, Num):
        return value.value
    if isinstance(value, Bits):
        return float(value.value)
    return None


def as_int(value: Value) -> int | None:
    if isinstance(value, Bits):
        return value.value
    if isinstance(value, Num) and value.is_int and math.isfinite(value.value):
        return int(value.value)
    return None


def _key_text(key: ElementKey) -> str:
    return "[" + ",".join("" if k is None else str(k) for k in key) + "]"


def constant(expr: Expr) -> Value:
    """An aggregate member's value (the grammar allows only constants there)."""
    if isinstance(expr, Num | Bool | Text | Bits | EnumValue | Aggregate):
        return expr
    return Unknown("the value is not a constant")


def _field(value: Value, name: str, written: str) -> Value:
    if not isinstance(value, Aggregate):
        return Unknown(f"{written} has no component {name}")
    member = value.member(name.upper())
    if member is None:
        return Unknown(f"{written} has no value for its component {name}")
    return constant(member.value)


def _element(value: Value, key: ElementKey, written: str) -> Value:
    if not isinstance(value, ArrayValue):
        return Unknown(f"{written} is not an array")
    element = value.elements.get(key)
    if element is None:
        return Unknown(f"{written}{_key_text(key)} has no value")
    return element


# ---- operators


def _number(value: float, is_int: bool, span: ir.SourceSpan) -> Num:
    return Num(float(value), is_int, span)


def _unary(expr: Unary, operand: Value) -> Value:
    if isinstance(operand, Unknown):
        return operand
    if expr.op == "NOT" and isinstance(operand, Bool):
        return Bool(not operand.value, expr.span)
    if expr.op == "B_NOT" and as_int(operand) is not None:
        return _number(~(as_int(operand) or 0), True, expr.span)
    number = as_number(operand)
    if expr.op in "+-" and number is not None:
        is_int = as_int(operand) is not None
        return _number(-number if expr.op == "-" else number, is_int, expr.span)
    return Unknown(f"{expr.op} does not apply to this value")


_ARITHMETIC: dict[str, Callable[[float, float], float]] = {
    "+": operator.add,
    "-": operator.sub,
    "*": operator.mul,
}
_COMPARE: dict[str, Callable[[float, float], bool]] = {
    "==": operator.eq,
    "<>": operator.ne,
    "<": operator.lt,
    ">": operator.gt,
    "<=": operator.le,
    ">=": operator.ge,
}
_LOGIC: dict[str, Callable[[bool, bool], bool]] = {
    "AND": operator.and_,
    "OR": operator.or_,
    "EXOR": operator.xor,
}
_BITWISE: dict[str, Callable[[int, int], int]] = {
    "B_AND": operator.and_,
    "B_OR": operator.or_,
    "B_EXOR": operator.xor,
}


def _binary(expr: Binary, left: Value, right: Value) -> Value:
    if isinstance(left, Unknown):
        return left
    if isinstance(right, Unknown):
        return right
    op, span = expr.op, expr.span
    if op == ":":
        return _geometric(left, right, span)
    if op in _LOGIC and isinstance(left, Bool) and isinstance(right, Bool):
        return Bool(_LOGIC[op](left.value, right.value), span)
    if op in ("==", "<>") and not (isinstance(left, Num | Bits) and isinstance(right, Num | Bits)):
        equal = _same_constant(left, right)
        if equal is None:
            return Unknown(f"olp does not compare these values ({op})")
        return Bool(equal == (op == "=="), span)
    a, b = as_number(left), as_number(right)
    ints = as_int(left) is not None and as_int(right) is not None
    if a is None or b is None:
        return Unknown(f"{op} needs numbers here")
    if op in _COMPARE:
        return Bool(_COMPARE[op](a, b), span)
    if op in _BITWISE and ints:
        return _number(_BITWISE[op](int(a), int(b)), True, span)
    if op in _ARITHMETIC:
        return _number(_ARITHMETIC[op](a, b), ints, span)
    if op == "/":
        if b == 0:
            return Unknown("division by zero")
        return _number(math.trunc(a / b) if ints else a / b, ints, span)
    return Unknown(f"olp does not evaluate {op} here")


def _same_constant(left: Const, right: Const) -> bool | None:
    if isinstance(left, Bool) and isinstance(right, Bool):
        return left.value == right.value
    if isinstance(left, EnumValue) and isinstance(right, EnumValue):
        return left.name.upper() == right.name.upper()
    if isinstance(left, Text) and isinstance(right, Text):
        return left.value == right.value
    return None


def _geometric(left: Const, right: Const, span: ir.SourceSpan) -> Value:
    """``a : b``: the frame ``b`` given in frame ``a``; the result has ``b``'s type and S/T."""
    if not (isinstance(left, Aggregate) and isinstance(right, Aggregate)):
        return Unknown("the geometric operator ':' needs two frames or positions")
    if is_axis_aggregate(left) or is_axis_aggregate(right):
        return Unknown("the geometric operator ':' does not apply to axis values")
    a = frame_values(left)
    if isinstance(a, Unknown):
        return a
    b = frame_values(right)
    if isinstance(b, Unknown):
        return b
    values = pose_to_frame(frame_to_pose(a) @ frame_to_pose(b))
    members = [
        Member(n, Num(float(v), False, span), span) for n, v in zip(CARTESIAN, values, strict=True)
    ]
    members += [m for m in right.members if m.name.upper() not in CARTESIAN]
    return Aggregate(right.type_name, tuple(members), span)


def frame_values(agg: Aggregate) -> tuple[float, ...] | Unknown:
    """X, Y, Z (mm), A, B, C (deg) of a frame or position; missing components are 0."""
    values = []
    for name in CARTESIAN:
        member = agg.member(name)
        number = 0.0 if member is None else as_number(constant(member.value))
        if number is None:
            return Unknown(f"component {name} is not a number")
        values.append(number)
    return tuple(values)


NOT_SET = Unknown("not set")
"""What an undeclared name, member or element holds when the program assigns a part of it."""


def assign_path(
    old: Value,
    selectors: tuple[Field | Index, ...],
    new: Const,
    keys: list[ElementKey],
    span: ir.SourceSpan,
) -> Value:
    """``old`` with the part named by ``selectors`` replaced by ``new``.

    ``keys`` are the evaluated indices, in order. An unknown base stays unknown; an aggregate or
    array that was :data:`NOT_SET` is created (KRL would have declared it elsewhere).
    """
    if not selectors:
        return new
    if isinstance(old, Unknown) and old is not NOT_SET:
        return old
    head, rest = selectors[0], selectors[1:]
    if isinstance(head, Field):
        return _assign_member(old, head.name, rest, new, keys, span)
    if old is NOT_SET:
        old = ArrayValue("", {}, span)
    if not isinstance(old, ArrayValue):
        return Unknown("an index is applied to a value that is not an array")
    element = assign_path(old.elements.get(keys[0], NOT_SET), rest, new, keys[1:], span)
    if isinstance(element, Unknown):
        return element
    return dataclasses.replace(old, elements={**old.elements, keys[0]: element})


def _assign_member(
    old: Value,
    name: str,
    rest: tuple[Field | Index, ...],
    new: Const,
    keys: list[ElementKey],
    span: ir.SourceSpan,
) -> Value:
    if old is NOT_SET:
        old = Aggregate(None, (), span)
    if not isinstance(old, Aggregate):
        return Unknown(f"component {name} is assigned on a value that has no components")
    current = old.member(name.upper())
    inner = assign_path(
        NOT_SET if current is None else constant(current.value), rest, new, keys, span
    )
    if isinstance(inner, Unknown):
        return inner
    if isinstance(inner, ArrayValue | Signal):
        return Unknown("olp keeps no arrays in aggregate members")
    members = [m for m in old.members if m.name.upper() != name.upper()]
    return dataclasses.replace(old, members=(*members, Member(name, inner, span)))


def finite(values: tuple[float, ...]) -> bool:
    return all(math.isfinite(v) for v in values)
