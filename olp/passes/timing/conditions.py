"""What a user assumes about a run (``--assume``), and the program's conditions evaluated with it.

The spelling of an assumption (vendor-neutral; case does not matter, spaces are ignored):

* ``in3=true`` or ``$IN[3]=true``: digital input 3 reads true (``true``/``false``, ``1``/``0``,
  ``on``/``off``);
* ``loop:12=5``: the loop (``WHILE``, ``REPEAT``, ``LOOP`` or ``FOR``, over its bounds) whose
  statement is on source line 12 runs its body 5 times; ``loop:prog.src:12=5`` says which
  file (a called routine's), ``loop:NAME=5`` names the loop by the label just before it;
* ``NAME=VALUE``: variable ``NAME`` (a structure member ``part.kind``, an array element
  ``slot[2]``) holds ``VALUE``: ``true``/``false``, a number, ``'text'``, or an enumeration
  member ``#BASE``.

Evaluation is constant folding over :mod:`olp.ir_flow` expressions: a name holds what an
assumption says, or the value of a constant declaration, or the initial value of a variable
that no statement assigns; everything else (a variable the program assigns, a function's
result, a sensor) is :data:`UNKNOWN`, and so is any expression over it that its known parts do
not decide (``false and x`` is false, ``true or x`` true). What the program's own assignments
fix along a path is added by the walk (:mod:`.known`).
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any, Final

from olp import ir_flow as f
from olp.errors import UsageError

Value = bool | int | float | str
"""A known value: a bool, a number, a string, or an enumeration member (a string ``#NAME``)."""


class _Unknown:
    def __repr__(self) -> str:
        return "UNKNOWN"


UNKNOWN: Final = _Unknown()
"""What an expression evaluates to when the known values do not decide it."""

Result = Value | _Unknown

LoopKey = int | str | tuple[str, int]
"""How an assumption names a loop: its line, its label (casefolded), or (file name, line)."""


@dataclass(frozen=True, slots=True)
class Assumptions:
    """What ``--assume`` says: ``inputs`` digital input number -> state; ``names`` a variable's
    key (:func:`expression_key`) -> value; ``loops`` a loop's source line (int), file name and
    line, or the label before it (casefolded) -> passes of its body; ``given``: the texts as the
    user wrote them (for the summary)."""

    inputs: Mapping[int, bool] = field(default_factory=dict)
    names: Mapping[str, Value] = field(default_factory=dict)
    loops: Mapping[LoopKey, int] = field(default_factory=dict)
    given: tuple[str, ...] = ()


def parse_assumptions(texts: Iterable[str]) -> Assumptions:
    """``--assume`` texts as :class:`Assumptions`; a text olp cannot read raises a
    :class:`~olp.errors.UsageError` naming it. A later text overrides an earlier one."""
    inputs: dict[int, bool] = {}
    names: dict[str, Value] = {}
    loops: dict[LoopKey, int] = {}
    given = []
    for text in texts:
        key, value = _split(text)
        low = key.casefold()
        if low.startswith("loop:"):
            loops[_loop_key(text, key[5:])] = _count(text, value)
        elif (number := _input_number(low)) is not None:
            inputs[number] = _bool(text, value)
        else:
            names[low] = _value(text, value)
        given.append(text.strip())
    return Assumptions(inputs, names, loops, tuple(given))


def _split(text: str) -> tuple[str, str]:
    key, sep, value = text.partition("=")
    key, value = "".join(key.split()), value.strip()
    if not sep or not key or not value:
        raise UsageError(f"--assume {text!r}: expected NAME=VALUE (in3=true, loop:12=5, count=4)")
    if not all(c.isalnum() or c in "_$.[],:#/\\-" for c in key):
        raise UsageError(f"--assume {text!r}: {key!r} is not a name, input or loop")
    return key, value


def _input_number(key: str) -> int | None:
    """3 for ``in3``, ``in[3]``, ``$in[3]``; None for any other key."""
    body = key.removeprefix("$").removeprefix("in")
    if body == key.removeprefix("$"):
        return None
    body = body[1:-1] if body.startswith("[") and body.endswith("]") else body
    return int(body) if body.isdigit() else None


def _loop_key(text: str, name: str) -> LoopKey:
    if name.isdigit():
        return int(name)
    file, colon, line = name.rpartition(":")
    if colon and file and line.isdigit():
        return file.replace("\\", "/").rsplit("/", 1)[-1].casefold(), int(line)
    if not name or not (name[0].isalpha() or name[0] == "_"):
        raise UsageError(f"--assume {text!r}: expected loop:LINE=N or loop:LABEL=N")
    return name.casefold()


def _count(text: str, value: str) -> int:
    if not value.isdigit():
        raise UsageError(f"--assume {text!r}: a loop's passes must be a whole number >= 0")
    return int(value)


_TRUE = {"true": True, "on": True, "1": True, "false": False, "off": False, "0": False}


def _bool(text: str, value: str) -> bool:
    try:
        return _TRUE[value.casefold()]
    except KeyError:
        raise UsageError(f"--assume {text!r}: an input is true or false, got {value!r}") from None


def _value(text: str, value: str) -> Value:
    low = value.casefold()
    if low in ("true", "false"):
        return low == "true"
    if len(value) >= 2 and value[0] == value[-1] and value[0] in "'\"":
        return value[1:-1]
    if value.startswith("#") and value[1:].replace("_", "a").isalnum():
        return "#" + value[1:].casefold()
    try:
        number = float(value)
    except ValueError:
        raise UsageError(
            f"--assume {text!r}: expected true, false, a number, 'text' or #MEMBER, got {value!r}"
        ) from None
    if not math.isfinite(number):
        raise UsageError(f"--assume {text!r}: {value!r} is not a finite number")
    return int(value) if value.lstrip("+-").isdigit() else number


# --------------------------------------------------------------------------------------------
# Evaluation


def expression_key(expr: f.Expr) -> str | None:
    """A variable reference as the key :class:`Assumptions` stores (``part.kind``,
    ``slot[2]``), or None when it is not a plain reference with constant indices."""
    if isinstance(expr, f.Name):
        return expr.name.casefold()
    if isinstance(expr, f.Member):
        base = expression_key(expr.base)
        return None if base is None else f"{base}.{expr.field.casefold()}"
    if isinstance(expr, f.Index):
        base = expression_key(expr.base)
        parts = [_index_text(i) for i in expr.indices]
        if base is None or any(p is None for p in parts):
            return None
        return f"{base}[{','.join(p for p in parts if p is not None)}]"
    return None


def _index_text(expr: f.Expr | None) -> str | None:
    if isinstance(expr, f.Constant) and isinstance(expr.value, int):
        return str(expr.value)
    return None


@dataclass(frozen=True, slots=True)
class Environment:
    """What evaluation knows: ``inputs`` and ``names`` as in :class:`Assumptions`, the names
    the program fixes (constants, never-assigned initial values) under them."""

    inputs: Mapping[int, bool]
    names: Mapping[str, Value]

    def evaluate(self, expr: f.Expr | None) -> Result:
        """``expr`` folded with the known values; :data:`UNKNOWN` where they do not decide it."""
        if expr is None:
            return UNKNOWN
        if isinstance(expr, f.Constant):
            return _constant(expr)
        if isinstance(expr, f.DigitalInput):
            return self.inputs.get(expr.index, UNKNOWN)
        if isinstance(expr, f.UnaryOp):
            return _unary(expr.op, self.evaluate(expr.operand))
        if isinstance(expr, f.BinaryOp):
            return self._binary(expr)
        key = expression_key(expr)
        return UNKNOWN if key is None else self.names.get(key, UNKNOWN)

    def _binary(self, expr: f.BinaryOp) -> Result:
        left = self.evaluate(expr.left)
        if expr.op in ("and", "or"):
            decided = expr.op == "or"  # the value of one side that decides the whole
            if left is decided:
                return decided
            right = self.evaluate(expr.right)
            if right is decided:
                return decided
            if isinstance(left, bool) and isinstance(right, bool):
                return not decided
            return UNKNOWN
        return _binary(expr.op, left, self.evaluate(expr.right))


def environment(program_nodes: Iterable[Any], assumptions: Assumptions) -> Environment:
    """The environment of a program: ``assumptions`` over the values its declarations fix (a
    constant, or a variable with an initial value that no statement assigns and that no other
    module can: not exported)."""
    nodes = list(f.leaves(program_nodes))
    assigned = {
        key
        for n in nodes
        if isinstance(n, f.Assign)
        for key in [expression_key(n.target) or _base_key(n.target)]
        if key is not None
    }
    assigned |= {
        n.variable.casefold() for n in f.leaves_and_blocks(program_nodes) if isinstance(n, f.For)
    }
    fixed: dict[str, Value] = {}
    for n in nodes:
        if (
            isinstance(n, f.Declare)
            and not n.dims
            and (n.constant or not n.exported)  # another module may assign a GLOBAL one
            and n.name.casefold() not in assigned
        ):
            value = Environment({}, fixed).evaluate(n.value)
            if not isinstance(value, _Unknown):
                fixed[n.name.casefold()] = value
    return Environment(dict(assumptions.inputs), {**fixed, **assumptions.names})


def _base_key(expr: f.Expr) -> str | None:
    """The variable an assignment to ``expr`` changes (``a[i].x`` changes ``a``)."""
    while isinstance(expr, f.Member | f.Index):
        expr = expr.base
    return expr.name.casefold() if isinstance(expr, f.Name) else None


def _constant(expr: f.Constant) -> Value:
    if expr.enum and isinstance(expr.value, str):
        return "#" + expr.value.lstrip("#").casefold()
    return expr.value


def _unary(op: str, value: Result) -> Result:
    if isinstance(value, _Unknown):
        return UNKNOWN
    if op == "not":
        return (not value) if isinstance(value, bool) else UNKNOWN
    if isinstance(value, bool | str):
        return UNKNOWN
    if op == "-":
        return -value
    if op == "+":
        return value
    return ~value if isinstance(value, int) else UNKNOWN  # bit_not


_COMPARE: dict[str, Callable[[Any, Any], bool]] = {
    "==": operator.eq,
    "<>": operator.ne,
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
}
_ARITHMETIC: dict[str, Callable[[Any, Any], Any]] = {
    "+": operator.add,
    "-": operator.sub,
    "*": operator.mul,
    "bit_and": operator.and_,
    "bit_or": operator.or_,
    "bit_xor": operator.xor,
}


def _binary(op: str, left: Result, right: Result) -> Result:
    if isinstance(left, _Unknown) or isinstance(right, _Unknown):
        return UNKNOWN
    if op in ("==", "<>"):
        return _COMPARE[op](_comparable(left), _comparable(right))
    if op == "xor":
        both = isinstance(left, bool) and isinstance(right, bool)
        return (left != right) if both else UNKNOWN
    numbers = _is_number(left) and _is_number(right)
    if not numbers:
        return UNKNOWN
    if op in _COMPARE:
        return _COMPARE[op](left, right)
    if op == "/":
        return _divide(left, right)
    if op.startswith("bit_") and not (isinstance(left, int) and isinstance(right, int)):
        return UNKNOWN
    if op in _ARITHMETIC:
        return _ARITHMETIC[op](left, right)
    return UNKNOWN  # geometric: frames are not folded


def _divide(left: Any, right: Any) -> Result:
    """Division; between two integers only where it is exact (languages differ on the rest:
    KRL truncates, RAPID's ``/`` does not)."""
    if right == 0:
        return UNKNOWN
    if isinstance(left, int) and isinstance(right, int):
        return left // right if left % right == 0 else UNKNOWN
    return left / right


def _is_number(value: Value) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _comparable(value: Value) -> Value:
    return value.casefold() if isinstance(value, str) and value.startswith("#") else value
