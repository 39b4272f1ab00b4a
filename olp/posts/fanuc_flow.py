"""LS spelling of :mod:`olp.ir_flow`: blocks lowered to labels and jumps, variables in registers.

The LS post (:mod:`olp.posts.fanuc`) walks a file's steps with the block markers of
:mod:`olp.posts.flow` woven in; :func:`lower` turns that stream into ``/MN`` lines (unnumbered:
the template numbers them), one list per step, and collects what LS cannot express as located
problems. Nothing here is a guess: what could not be verified is an error naming the line.

Conventions and their sources (public LS exports of R-30iA/R-30iB controllers found by text
search, FANUC America's *Advanced TP Programming* course chapter 7 "Mixed logic" and the
FOR/ENDFOR chapter of a FANUC operator manual, both as stored public pages; pinned by
``tests/posts/test_fanuc_flow.py``):

* Jumps: ``LBL[n]`` and ``JMP LBL[n]``; a label may carry a comment, ``LBL[1:BEGIN]`` (exports).
  Program labels are numbered 1, 2, ... in order of appearance with their name as the comment
  (only letters, digits and ``_``, at most :data:`COMMENT_CHARS` characters: the comment limit
  is unverified, 16 is the longest olp writes); labels olp makes for blocks take the numbers
  after them, so the two never collide.
* ``IF <condition>,JMP LBL[n]`` (exports: ``IF R[10]<170 ...,JMP LBL[1]``). An ``if``/``elif``
  block jumps over its body on the negated condition (comparisons flipped, De Morgan for AND/OR:
  exact for numbers and inputs, so no ``!`` operator is needed); ``else`` bodies follow a
  ``JMP`` to the end label. ``while`` is a label, a negated test and a ``JMP`` back;
  ``repeat``/``until`` jumps back on the negated condition; ``loop`` jumps back for ever; ``exit``
  jumps to the innermost loop's end label.
* Conditions: *standard logic* (no option) writes one comparison or up to
  :data:`STANDARD_CONDITIONS` comparisons joined by only ``AND`` or only ``OR`` (course: "in
  standard logic a maximum of five logical conditions"; exports: ``IF DI[3]=ON AND DI[4]=ON,``),
  each ``DI[n]=ON/OFF`` or ``R[i] op value`` with ``op`` one of ``= <> < <= > >=`` and the value
  a register or a non-negative constant. A jump on AND with OR, or on more comparisons, becomes
  a chain of such ``IF`` lines with short cuts (:meth:`Lowering._jumps`; exact, as LS
  conditions have no side effects). *Mixed logic* (course: AND and OR together, arithmetic,
  ``!`` and parentheses, up to :data:`MIXED_CONDITIONS` conditions) is written only when the
  post option ``mixed_logic: true`` says the controller has it: the whole condition or value in
  one line, in parentheses, every nested operation parenthesised so no priority rule is relied
  on (exports: ``IF (R[10]<170 OR R[10]>400),JMP``, ``R[87]=(R[87]+1)``,
  ``PR[10001,3]=(-50)``). A ``WAIT`` is one line: AND with OR there needs mixed logic.
* Temporaries (standard logic only): arithmetic of more than one operation, a negative value, or
  a position component or constant on a comparison's left is first computed into olp's own
  registers ``R[n:olp_tmpK]`` (taken after the variables from the ``registers`` range), one
  standard instruction per operation (``R[t]=a op b``, a negative value ``R[t]=0-a``; exports
  ``R[3]=R[3]+1``, ``PR[1,1]=PR[1,1]+R[145]``; the cheat sheet's ``R[i]=PR[i,j]``). Exact: LS
  expressions have no side effects and each operation runs once, in the expression's order; a
  loop's test recomputes them on every pass (they sit after its label). A ``WAIT`` re-reads its
  condition while it waits, so a WAIT on arithmetic needs mixed logic.
* ``SELECT R[i]=v,JMP LBL[a] ;`` then one line ``=w,JMP LBL[b] ;`` per further value and
  ``ELSE,JMP LBL[c] ;`` (exports; each a numbered line). The subject must be a numeric
  variable, the values integer constants.
* ``FOR R[i]=start TO stop ;`` / ``DOWNTO`` and ``ENDFOR ;`` (manual: the counter is a register,
  start and stop a constant, ``R[]`` or ``AR[]``, constants integers -32767..32766; TO counts by
  1, DOWNTO by -1; exports ``FOR R[20]=52 TO 80 ;``). Another step is an error. Whether a jump may
  leave a FOR/ENDFOR region is not verified: ``exit`` or ``goto`` out of a FOR is an error.
* ``WAIT <condition> ;`` (exports ``WAIT DI[806]=ON AND DI[807]=OFF``, ``WAIT (DI[49] AND
  DI[51])``); ``END ;`` ends the program (olp inlines routines, so a return ends it).
* Registers (:class:`Registers`): numeric variables (``BOOL``, ``INT``, ``REAL``) in ``R[n]``,
  positions (``FRAME``, ``POS``, ``E6POS``: Cartesian; ``AXIS``, ``E6AXIS``: joints) in
  ``PR[n]``, numbered in declaration order from the post options ``registers`` and
  ``position_registers`` (default ``[101, 200]`` and ``[51, 100]``: the upper halves of the 200
  R and 100 PR a controller has by default, medium confidence), an array taking consecutive
  registers; references carry the name as their comment, ``R[101:nCount]`` (exports). A
  ``BOOL`` holds 1 (TRUE) or 0 (FALSE) and is tested as ``R[n]=1``. Module data (a KRL
  ``.dat`` variable) gets its register the same way but no assignment of its value: a register
  keeps its value from one run to the next, as a data list does, so the register must hold the
  data list's value before the first run (a warning names it,
  :func:`olp.posts.fanuc.module_data_notes`); another module's variable is an error. Position
  components are
  ``PR[n,j]``, j = 1..6 for X, Y, Z, W, P, R (a public cheat sheet; exports ``PR[1,3]=PR[1,3]``);
  KRL's A, B, C are Fanuc's R, P, W (both Rz(A)·Ry(B)·Rx(C), :mod:`olp.vendors.fanuc`), joint
  components A1..A6 are j = 1..6. Text variables (``CHAR``): string registers exist only on
  some controllers and could not be verified, so using one is an error.
* Arithmetic: ``+ - * /`` (LS's ``/`` divides as reals; ``DIV`` and ``MOD`` are separate
  instructions); KRL divides two INTs with truncation and rounds a REAL assigned to an INT,
  which LS does not: both are errors. A value or condition LS has no spelling for (a function
  call, XOR, KRL's geometric ``:``, a structure value, text) is an error.

Not verified here (no controller, no MakeTP): whether converting an LS file sets a register's
comment from ``R[n:name]`` or ignores it (exports write it on every reference; olp writes the
same form); the longest line the converter takes (exports wrap long mixed-logic lines with
``:`` continuation lines, olp writes each statement on one line); the comment and label number
limits; whether mixed logic is standard on a given controller (hence the option). Variables a
KRL program declares only in a ``.dat`` or ``$config.dat`` are not in the IR, so their use is an
"undeclared" error rather than a guess of their type and register.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from olp import ir
from olp.errors import PostError
from olp.posts.numbers import NumberError, NumberFormat, format_number

STANDARD_CONDITIONS = 5
"""Comparisons in one standard-logic condition (FANUC America course, mixed logic chapter)."""
MIXED_CONDITIONS = 20
"""Comparisons in one mixed-logic condition (same source: "up to twenty ... depending on the
data type"; olp counts every comparison and input)."""
COMMENT_CHARS = 16
"""Characters of a label or register comment olp writes (unverified bound; names are cut)."""
FOR_RANGE = (-32767, 32766)
"""Constants a FOR instruction takes (FANUC manual, FOR/ENDFOR chapter)."""
DEFAULT_REGISTERS = (101, 200)
DEFAULT_POSITION_REGISTERS = (51, 100)

NUMERIC_TYPES = {"BOOL": "bool", "INT": "int", "REAL": "real"}
POSITION_TYPES = {
    "FRAME": "cartesian",
    "POS": "cartesian",
    "E6POS": "cartesian",
    "AXIS": "joint",
    "E6AXIS": "joint",
}
CARTESIAN_FIELDS = {"X": 1, "Y": 2, "Z": 3, "C": 4, "B": 5, "A": 6}
"""KRL component -> ``PR[n,j]`` (C is W about X, B is P about Y, A is R about Z)."""
JOINT_FIELDS = {f"A{k}": k for k in range(1, 7)}

REGISTER_VALUE = NumberFormat("register value", "", 6, storage="real32", compact=True)
"""Constants: fixed point, trailing zeros dropped, held by a 32-bit REAL to 5e-7 (the registers'
storage, medium confidence)."""

_COMPARE = {"==": "=", "<>": "<>", "<": "<", "<=": "<=", ">": ">", ">=": ">="}
_NEGATED = {"=": "<>", "<>": "=", "<": ">=", "<=": ">", ">": "<=", ">=": "<"}
_MIRRORED = {"=": "=", "<>": "<>", "<": ">", "<=": ">=", ">": "<", ">=": "<="}
_ARITHMETIC = {"+", "-", "*", "/"}
_STATES = {"ON": "OFF", "OFF": "ON"}
_MARKERS = frozenset(
    {"if", "elif", "else", "end_if", "switch", "case", "default", "end_switch", "while"}
    | {"end_while", "repeat", "until", "loop", "end_loop", "for", "end_for"}
)
FLOW_KINDS = _MARKERS | {"declare", "assign", "wait_until", "label", "goto", "exit", "return"}
"""Step kinds whose lines :func:`lower` writes."""


class Unwritable(Exception):
    """A statement LS cannot express; the message says what, the node where."""

    def __init__(self, message: str, node: Any) -> None:
        super().__init__(message)
        self.node = node


def comment(name: str) -> str:
    """A name as an LS register or label comment: letters, digits and ``_`` only, cut to
    :data:`COMMENT_CHARS` (user text never reaches the line otherwise)."""
    return re.sub(r"[^A-Za-z0-9_]", "", name)[:COMMENT_CHARS]


def _tagged(base: str, number: int, name: str) -> str:
    text = comment(name)
    return f"{base}[{number}:{text}]" if text else f"{base}[{number}]"


# --------------------------------------------------------------------------------------------
# Registers


@dataclass(frozen=True, slots=True)
class Variable:
    """A program variable in registers: ``kind`` (bool, int, real, cartesian, joint), the
    first register ``number`` and ``size`` (array elements, 1 for a scalar)."""

    name: str
    kind: str
    number: int
    size: int = 1

    @property
    def position(self) -> bool:
        return self.kind in ("cartesian", "joint")

    def ref(self, element: int = 1) -> str:
        """``R[n:name]`` / ``PR[n:name]`` of element ``element`` (1-based)."""
        base = "PR" if self.position else "R"
        label = self.name if self.size == 1 else f"{self.name}_{element}"
        return _tagged(base, self.number + element - 1, label)


@dataclass
class Registers:
    """Register allocation in declaration order within the post options' ranges."""

    ranges: Mapping[str, tuple[int, int]]
    variables: dict[str, Variable] = field(default_factory=dict)
    skipped: dict[str, ir.Declare] = field(default_factory=dict)
    next: dict[str, int] = field(default_factory=dict)
    temps: list[int] = field(default_factory=list)

    def declare(self, decl: ir.Declare) -> Variable | None:
        """Allocate ``decl``; None for a type LS has no register for (noted in ``skipped``)."""
        key = decl.name.upper()
        if key in self.variables:
            return self.variables[key]
        if decl.scope == "external":
            where = decl.span.file.replace("\\", "/").rsplit("/", 1)[-1]
            raise Unwritable(
                f"{decl.name} is declared in another module's data list ({where}:"
                f"{decl.span.line}), which only a program for the same controller can refer to",
                decl,
            )
        type_name = decl.type_name.upper()
        kind = NUMERIC_TYPES.get(type_name) or POSITION_TYPES.get(type_name)
        if kind is None:
            self.skipped[key] = decl
            return None
        size = _array_size(decl)
        bank = "position_registers" if kind in ("cartesian", "joint") else "registers"
        low, high = self.ranges[bank]
        number = self.next.get(bank, low)
        if number + size - 1 > high:
            self.skipped[key] = decl
            raise Unwritable(
                f"{decl.name} needs {size} register(s) beyond the option {bank} [{low}, {high}]",
                decl,
            )
        self.next[bank] = number + size
        self.variables[key] = var = Variable(decl.name, kind, number, size)
        return var

    def temporary(self, k: int, node: Any) -> str:
        """``R[n:olp_tmpK]``, the k-th (0-based) temporary register, allocated on first use
        after the variables declared so far (declarations come first in a file)."""
        while len(self.temps) <= k:
            low, high = self.ranges["registers"]
            number = self.next.get("registers", low)
            if number > high:
                raise Unwritable(
                    f"no register left in the option registers [{low}, {high}] for a "
                    "temporary value",
                    node,
                )
            self.next["registers"] = number + 1
            self.temps.append(number)
        return f"R[{self.temps[k]}:olp_tmp{k + 1}]"

    def lookup(self, name: str, node: Any) -> Variable:
        var = self.variables.get(name.upper())
        if var is not None:
            return var
        if name.upper() in self.skipped:
            what = self.skipped[name.upper()].type_name.upper()
            reason = (
                "text variables would need string registers (SR[]), which only some "
                "controllers have and olp could not verify"
                if what in ("CHAR", "STRING")
                else "LS has no registers for that type"
                if what not in NUMERIC_TYPES and what not in POSITION_TYPES
                else "no register was left for it in the post option's range"
            )
            raise Unwritable(f"{name} is a {what}: {reason}", node)
        raise Unwritable(
            f"{name} is not declared in the program: olp cannot tell whether it is a number or "
            "a position, nor which register holds it on the controller",
            node,
        )


def _array_size(decl: ir.Declare) -> int:
    if not decl.dims:
        return 1
    if len(decl.dims) != 1 or not _int_constant(decl.dims[0]):
        raise Unwritable(f"{decl.name}: only one-dimensional arrays of constant size", decl)
    size = int(decl.dims[0].value)  # type: ignore[union-attr]
    if size < 1:
        raise Unwritable(f"{decl.name}: array size {size}", decl)
    return size


def _int_constant(expr: Any) -> bool:
    return (
        isinstance(expr, ir.Constant)
        and isinstance(expr.value, int)
        and not isinstance(expr.value, bool)
    )


def register_ranges(options: Mapping[str, Any]) -> dict[str, tuple[int, int]]:
    """The option ranges ``registers`` and ``position_registers`` as (first, last); a value
    that is not two register numbers, first <= last, is a PostError naming the option."""
    out = {}
    for key, default in (
        ("registers", DEFAULT_REGISTERS),
        ("position_registers", DEFAULT_POSITION_REGISTERS),
    ):
        given = options.get(key, default)
        numbers = list(given) if isinstance(given, list | tuple) else []
        if len(numbers) != 2 or not all(type(v) is int for v in numbers):
            raise PostError(
                f"post option {key}: expected [first, last] register numbers, got {given!r}"
            )
        if not 1 <= numbers[0] <= numbers[1]:
            raise PostError(f"post option {key}: {given!r} is not a range of register numbers")
        out[key] = (numbers[0], numbers[1])
    return out


def mixed_logic(options: Mapping[str, Any]) -> bool:
    """The option ``mixed_logic`` (true or false; anything else is a PostError)."""
    value = options.get("mixed_logic", False)
    if not isinstance(value, bool):
        raise PostError(f"post option mixed_logic: expected true or false, got {value!r}")
    return value


# --------------------------------------------------------------------------------------------
# Conditions: trees of AND/OR over comparisons, negated by De Morgan


@dataclass(frozen=True, slots=True)
class Compare:
    """``left op right`` as LS text; ``standard``: writable in standard logic."""

    left: str
    op: str
    right: str
    standard: bool

    def negated(self) -> Compare:
        if self.right in _STATES and self.op == "=":  # a digital input has two states
            return Compare(self.left, "=", _STATES[self.right], self.standard)
        return Compare(self.left, _NEGATED[self.op], self.right, self.standard)

    def text(self) -> str:
        return f"{self.left}{self.op}{self.right}"


@dataclass(frozen=True, slots=True)
class Logic:
    op: str  # "AND" or "OR"
    parts: tuple[Any, ...]

    def negated(self) -> Logic:
        return Logic("OR" if self.op == "AND" else "AND", tuple(p.negated() for p in self.parts))


Condition = Compare | Logic


def _count(cond: Condition) -> int:
    return 1 if isinstance(cond, Compare) else sum(_count(p) for p in cond.parts)


def _flat(cond: Condition) -> Condition:
    """Nested AND in AND (OR in OR) made one chain."""
    if isinstance(cond, Compare):
        return cond
    parts: list[Any] = []
    for part in (_flat(p) for p in cond.parts):
        if isinstance(part, Logic) and part.op == cond.op:
            parts.extend(part.parts)
        else:
            parts.append(part)
    return Logic(cond.op, tuple(parts))


def _mixed_text(cond: Condition, top: bool = True) -> str:
    if isinstance(cond, Compare):
        return cond.text()
    text = f" {cond.op} ".join(_mixed_text(p, False) for p in cond.parts)
    return text if top else f"({text})"


# --------------------------------------------------------------------------------------------
# The lowering


@dataclass
class _Frame:
    kind: str
    node: Any
    top: int | None = None
    end: int | None = None
    next: int | None = None
    cases: list[int] = field(default_factory=list)
    default: int | None = None
    for_id: int = 0
    seen: int = 0


class Lowering:
    """The ``/MN`` lines of a file's steps (:func:`lower`)."""

    def __init__(self, options: Mapping[str, Any], events: Sequence[tuple[str, Any]]) -> None:
        self.mixed = mixed_logic(options)
        self.registers = Registers(register_ranges(options))
        self.stack: list[_Frame] = []
        self.labels, self.label_fors = self._program_labels(events)
        self.next_label = len(self.labels) + 1
        self.seen_labels: set[str] = set()
        self.for_count = 0
        self.finished_counters: set[str] = set()
        self.pre: list[str] = []
        self.io_range: tuple[int, int] | None = None

    # -- labels ------------------------------------------------------------------------------

    @staticmethod
    def _program_labels(
        events: Sequence[tuple[str, Any]],
    ) -> tuple[dict[str, int], dict[str, tuple[int, ...]]]:
        """Program labels numbered in order of appearance, and the FOR blocks around each."""
        labels: dict[str, int] = {}
        around: dict[str, tuple[int, ...]] = {}
        fors: list[int] = []
        count = 0
        for kind, node in events:
            if kind == "for":
                count += 1
                fors.append(count)
            elif kind == "end_for":
                fors.pop()
            elif kind == "label":
                key = node.name.upper()
                labels.setdefault(key, len(labels) + 1)
                around.setdefault(key, tuple(fors))
        return labels, around

    def _var(self, name: str, node: Any) -> Variable:
        """The variable ``name``; reading a FOR counter after its loop is an error: KRL leaves
        it one step past the bound, LS's ENDFOR at the bound (manual: ENDFOR repeats while the
        counter is below the target)."""
        key = name.upper()
        active = {f.node.variable.upper() for f in self.stack if f.kind == "for"}
        if key in self.finished_counters and key not in active:
            raise Unwritable(
                f"{name} is used after a FOR loop that counts with it: KRL leaves it one past "
                "the bound, LS at the bound",
                node,
            )
        return self.registers.lookup(name, node)

    def label(self) -> int:
        self.next_label += 1
        return self.next_label - 1

    # -- statements --------------------------------------------------------------------------

    def lines(self, kind: str, node: Any) -> list[str]:
        self.pre = []
        handler = getattr(self, "_" + kind)
        out: list[str] = handler(node)
        return out

    def _drain(self) -> list[str]:
        """The temporary lines the statement being written needs first."""
        out, self.pre = self.pre, []
        return out

    def _declare(self, decl: ir.Declare) -> list[str]:
        var = self.registers.declare(decl)
        if var is None or decl.scope == "module":
            return []  # a register keeps its value, as a data list does: not set on every run
        if decl.value is None:
            return []
        if var.position or var.size != 1:
            raise Unwritable(
                f"the initial value of {decl.name}: LS sets a position register or an array "
                "element by element, and olp does not verify doing so for a whole value",
                decl,
            )
        return self._store(var.ref(), var.kind, decl.value, decl)

    def _assign(self, node: ir.Assign) -> list[str]:
        target = node.target
        if isinstance(target, ir.Name):
            var = self.registers.lookup(target.name, node)  # a write: both languages agree
            if var.size != 1:
                raise Unwritable(f"{target.name} is an array: assign its elements", node)
            if var.position:
                return [f"  {var.ref()}={self._position_value(var, node.value, node)} ;"]
            out = self._store(var.ref(), var.kind, node.value, node)
            self.finished_counters.discard(target.name.upper())
            return out
        ref, kind = self._operand_ref(target, node)
        return self._store(ref, kind, node.value, node)

    def _position_value(self, var: Variable, value: Any, node: Any) -> str:
        if isinstance(value, ir.Name):
            other = self._var(value.name, node)
            if other.position and other.kind == var.kind and other.size == 1:
                return other.ref()
        raise Unwritable(
            f"{var.name} = ...: LS copies a position register only from another of the same "
            "representation (PR[i]=PR[j]); set its components one by one",
            node,
        )

    def _store(self, ref: str, kind: str, value: Any, node: Any) -> list[str]:
        if kind == "bool":
            return [f"  {ref}={self._bool_value(value, node)} ;"]
        vtype = self._type(value, node)
        if vtype == "bool":
            raise Unwritable("a condition's result cannot be stored in a number register", node)
        if kind == "int" and vtype == "real":
            raise Unwritable(
                "a REAL value assigned to an INT: KRL rounds it, an LS register would keep the "
                "fraction",
                node,
            )
        text = self._value(value, node)
        return [*self._drain(), f"  {ref}={text} ;"]

    def _bool_value(self, value: Any, node: Any) -> str:
        if isinstance(value, ir.Constant) and isinstance(value.value, bool):
            return "1" if value.value else "0"
        if isinstance(value, ir.Name):
            var = self._var(value.name, node)
            if var.kind == "bool" and var.size == 1:
                return var.ref()
        raise Unwritable(
            "a BOOL variable is written only TRUE, FALSE or another BOOL: what LS stores for a "
            "condition's result is not verified",
            node,
        )

    def _wait_until(self, node: ir.WaitUntil) -> list[str]:
        text = self._condition(node.condition, node)
        if self.pre:
            what = "a WAIT on arithmetic (it re-reads its condition: no temporary can hold it)"
            self._need_mixed(node, what)
        return [f"  WAIT {text} ;"]

    def _label(self, node: ir.Label) -> list[str]:
        key = node.name.upper()
        if key in self.seen_labels:
            raise Unwritable(f"label {node.name} appears twice (a routine inlined twice?)", node)
        self.seen_labels.add(key)
        return [f"  {_tagged('LBL', self.labels[key], node.name)} ;"]

    def _goto(self, node: ir.Goto) -> list[str]:
        key = node.label.upper()
        if key not in self.labels:
            raise Unwritable(f"GOTO {node.label}: no such label in the program", node)
        here = tuple(f.for_id for f in self.stack if f.kind == "for")
        if self.label_fors[key] != here:
            raise Unwritable(
                f"GOTO {node.label} crosses a FOR/ENDFOR boundary: whether LS allows a jump "
                "into or out of FOR/ENDFOR is not verified",
                node,
            )
        return [f"  JMP LBL[{self.labels[key]}] ;"]

    def _exit(self, node: ir.Exit) -> list[str]:
        loops = [f for f in self.stack if f.kind in ("while", "repeat", "loop", "for")]
        if not loops:
            raise Unwritable("EXIT outside a loop", node)
        frame = loops[-1]
        if frame.kind == "for":
            raise Unwritable(
                "EXIT from a FOR loop: whether LS allows a jump out of FOR/ENDFOR is not verified",
                node,
            )
        if frame.end is None:
            frame.end = self.label()
        return [f"  JMP LBL[{frame.end}] ;"]

    def _return(self, node: ir.Return) -> list[str]:
        return ["  END ;"]

    # -- blocks ------------------------------------------------------------------------------

    def _jump_unless(self, condition: Any, target: int, node: Any) -> list[str]:
        """Lines that jump to ``target`` when ``condition`` does not hold: one ``IF``, or in
        standard logic, for a condition standard logic cannot write in one line, a chain of
        them (:meth:`_jumps`)."""
        cond = _flat(self._cond(condition, node, negate=True))
        if self.mixed or _standard(cond):
            text = self._condition_text(cond, node)
            return [*self._drain(), f"  IF {text},JMP LBL[{target}] ;"]
        lines = self._jumps(cond, target)
        return [*self._drain(), *lines]

    def _jumps(self, cond: Condition, target: int) -> list[str]:
        """Standard-logic ``IF`` lines jumping to ``target`` exactly when ``cond`` holds,
        evaluated left to right with short cuts (exact: LS conditions have no side effects).
        OR: each group of up to :data:`STANDARD_CONDITIONS` comparisons, or nested AND, jumps
        to ``target`` itself. AND: every group but the last jumps over the rest when it does
        not hold, the last jumps to ``target``."""
        if _standard(cond):
            return [f"  IF {_mixed_text(cond)},JMP LBL[{target}] ;"]
        assert isinstance(cond, Logic)
        groups = _groups(cond)
        if cond.op == "OR":
            return [line for group in groups for line in self._jumps(group, target)]
        skip = self.label()
        out = [line for group in groups[:-1] for line in self._jumps(_flat(group.negated()), skip)]
        return [*out, *self._jumps(groups[-1], target), f"  LBL[{skip}] ;"]

    def _if(self, node: ir.If) -> list[str]:
        frame = _Frame("if", node, end=None, next=self.label())
        self.stack.append(frame)
        return self._jump_unless(node.branches[0].condition, frame.next, node)  # type: ignore[arg-type]

    def _elif(self, branch: ir.Branch) -> list[str]:
        frame = self.stack[-1]
        if frame.end is None:
            frame.end = self.label()
        out = [f"  JMP LBL[{frame.end}] ;", f"  LBL[{frame.next}] ;"]
        frame.next = self.label()
        return [*out, *self._jump_unless(branch.condition, frame.next, branch)]

    def _else(self, node: ir.If) -> list[str]:
        frame = self.stack[-1]
        if frame.end is None:
            frame.end = self.label()
        out = [f"  JMP LBL[{frame.end}] ;", f"  LBL[{frame.next}] ;"]
        frame.next = None
        return out

    def _end_if(self, node: ir.If) -> list[str]:
        frame = self.stack.pop()
        out = [] if frame.next is None else [f"  LBL[{frame.next}] ;"]
        return out + ([] if frame.end is None else [f"  LBL[{frame.end}] ;"])

    def _switch(self, node: ir.Switch) -> list[str]:
        frame = _Frame("switch", node, end=None)
        frame.cases = [self.label() for _ in node.cases]
        frame.default = self.label() if node.default else None
        self.stack.append(frame)
        subject = node.subject
        var = self._var(subject.name, node) if isinstance(subject, ir.Name) else None
        if var is None or var.kind not in ("int", "real") or var.size != 1:
            raise Unwritable("SELECT takes a numeric variable (a register) as its subject", node)
        out: list[str] = []
        for case, target in zip(node.cases, frame.cases, strict=True):
            for value in case.values:
                v = _folded(value)
                if not isinstance(v, int) or isinstance(v, bool) or v < 0:
                    raise Unwritable(
                        "SELECT compares with non-negative integer constants only (negative "
                        "values are not verified)",
                        case,
                    )
                head = f"  SELECT {var.ref()}" if not out else "       "
                out.append(f"{head}={self._constant(v, case)},JMP LBL[{target}] ;")
        if not out:
            raise Unwritable("a SWITCH without cases", node)
        otherwise = frame.default if frame.default is not None else self._end(frame)
        return [*out, f"       ELSE,JMP LBL[{otherwise}] ;"]

    def _end(self, frame: _Frame) -> int:
        if frame.end is None:
            frame.end = self.label()
        return frame.end

    def _case(self, case: ir.Case) -> list[str]:
        frame = self.stack[-1]
        k = frame.seen
        frame.seen += 1
        lead = [f"  JMP LBL[{self._end(frame)}] ;"] if k > 0 else []
        return [*lead, f"  LBL[{frame.cases[k]}] ;"]

    def _default(self, node: ir.Switch) -> list[str]:
        frame = self.stack[-1]
        lead = [f"  JMP LBL[{self._end(frame)}] ;"] if node.cases else []
        return [*lead, f"  LBL[{frame.default}] ;"]

    def _end_switch(self, node: ir.Switch) -> list[str]:
        frame = self.stack.pop()
        return [] if frame.end is None else [f"  LBL[{frame.end}] ;"]

    def _loop_head(self, kind: str, node: Any) -> _Frame:
        frame = _Frame(kind, node, top=self.label())
        self.stack.append(frame)
        return frame

    def _while(self, node: ir.While) -> list[str]:
        frame = self._loop_head("while", node)
        frame.end = self.label()
        return [f"  LBL[{frame.top}] ;", *self._jump_unless(node.condition, frame.end, node)]

    def _end_while(self, node: ir.While) -> list[str]:
        frame = self.stack.pop()
        return [f"  JMP LBL[{frame.top}] ;", f"  LBL[{frame.end}] ;"]

    def _repeat(self, node: ir.Repeat) -> list[str]:
        return [f"  LBL[{self._loop_head('repeat', node).top}] ;"]

    def _until(self, node: ir.Repeat) -> list[str]:
        frame = self.stack.pop()
        out = self._jump_unless(node.until, frame.top, node)  # type: ignore[arg-type]
        return out + ([] if frame.end is None else [f"  LBL[{frame.end}] ;"])

    def _loop(self, node: ir.Loop) -> list[str]:
        return [f"  LBL[{self._loop_head('loop', node).top}] ;"]

    def _end_loop(self, node: ir.Loop) -> list[str]:
        frame = self.stack.pop()
        out = [f"  JMP LBL[{frame.top}] ;"]
        return out + ([] if frame.end is None else [f"  LBL[{frame.end}] ;"])

    def _for(self, node: ir.For) -> list[str]:
        self.for_count += 1
        self.stack.append(_Frame("for", node, for_id=self.for_count))
        var = self._var(node.variable, node)
        if var.kind != "int" or var.size != 1:
            raise Unwritable(f"FOR counter {node.variable} must be an INT variable", node)
        step = 1 if node.step is None else _folded(node.step)
        if step == 1 and not isinstance(step, bool):
            direction = "TO"
        elif step == -1 and not isinstance(step, bool):
            direction = "DOWNTO"
        else:
            raise Unwritable("LS FOR counts by 1 (TO) or -1 (DOWNTO) only", node)
        start, stop = self._for_bound(node.start, node), self._for_bound(node.stop, node)
        return [f"  FOR {var.ref()}={start} {direction} {stop} ;"]

    def _for_bound(self, expr: Any, node: Any) -> str:
        value = _folded(expr)
        if isinstance(value, int) and not isinstance(value, bool):
            if not FOR_RANGE[0] <= value <= FOR_RANGE[1]:
                raise Unwritable(f"FOR bound {value} is outside {FOR_RANGE}", node)
            return str(value)
        if isinstance(expr, ir.Name):
            var = self._var(expr.name, node)
            if var.kind == "int" and var.size == 1:
                return var.ref()
        raise Unwritable(
            "a FOR bound must be an integer constant or an INT variable (FOR takes a constant, "
            "R[] or AR[])",
            node,
        )

    def _end_for(self, node: ir.For) -> list[str]:
        self.stack.pop()
        self.finished_counters.add(node.variable.upper())
        return ["  ENDFOR ;"]

    # -- expressions -------------------------------------------------------------------------

    def _type(self, expr: Any, node: Any) -> str:
        """bool, int or real."""
        if isinstance(expr, ir.Constant):
            v = expr.value
            if isinstance(v, bool):
                return "bool"
            if isinstance(v, int):
                return "int"
            if isinstance(v, float):
                return "real"
            if expr.enum:
                raise Unwritable(f"the enumeration value #{v} has no LS equivalent", node)
            raise Unwritable(f"the text {v!r}: LS registers hold numbers", node)
        if isinstance(expr, ir.Name | ir.Index | ir.Member):
            return self._operand_ref(expr, node)[1]
        if isinstance(expr, ir.UnaryOp) and expr.op in ("-", "+"):
            return self._type(expr.operand, node)
        if isinstance(expr, ir.BinaryOp) and expr.op in _ARITHMETIC:
            left, right = self._type(expr.left, node), self._type(expr.right, node)
            if "bool" in (left, right):
                raise Unwritable(f"arithmetic on a BOOL ({expr.op})", node)
            if expr.op == "/" and left == right == "int":
                raise Unwritable(
                    "KRL divides two INTs with truncation; LS's / does not (and the rounding "
                    "of its DIV for negative values is not verified)",
                    node,
                )
            return "real" if "real" in (left, right) else "int"
        if isinstance(expr, ir.BinaryOp | ir.UnaryOp | ir.DigitalInput):
            return "bool"
        raise Unwritable(f"{_describe(expr)} cannot be written in LS", node)

    def _operand_ref(self, expr: Any, node: Any) -> tuple[str, str]:
        """A register reference and its value type (bool, int, real)."""
        if isinstance(expr, ir.Name):
            var = self._var(expr.name, node)
            if var.position or var.size != 1:
                raise Unwritable(f"{expr.name} is not a single number", node)
            return var.ref(), var.kind
        if isinstance(expr, ir.Index) and isinstance(expr.base, ir.Name):
            var = self._var(expr.base.name, node)
            if var.position or var.size == 1 or len(expr.indices) != 1:
                raise Unwritable(f"{expr.base.name}[...] is not an array of numbers", node)
            k = _folded(expr.indices[0])
            if not isinstance(k, int) or isinstance(k, bool):
                raise Unwritable(
                    f"{expr.base.name}[...]: an index that is not a constant needs indirect "
                    "register arithmetic LS cannot write in one reference",
                    node,
                )
            if not 1 <= k <= var.size:
                raise Unwritable(f"{expr.base.name}[{k}] is outside 1..{var.size}", node)
            return var.ref(k), var.kind
        if isinstance(expr, ir.Member) and isinstance(expr.base, ir.Name):
            var = self._var(expr.base.name, node)
            fields = CARTESIAN_FIELDS if var.kind == "cartesian" else JOINT_FIELDS
            j = fields.get(expr.field.upper()) if var.position and var.size == 1 else None
            if j is None:
                raise Unwritable(
                    f"{expr.base.name}.{expr.field}: no position register component", node
                )
            return f"PR[{var.number},{j}]", "real"
        raise Unwritable(f"{_describe(expr)} cannot be written in LS", node)

    def _value(self, expr: Any, node: Any) -> str:
        """A numeric value: standard ``a``, ``a op b``; else ``(...)`` with mixed logic, or
        without it the inner operations computed into temporaries first (:meth:`_operand`)."""
        self._type(expr, node)
        standard = self._standard_value(expr, node)
        if standard is not None:
            return standard
        if self.mixed:
            return f"({self._mixed_value(expr, node)})"
        if isinstance(expr, ir.BinaryOp) and expr.op in _ARITHMETIC:
            left = self._operand(expr.left, node)
            return f"{left}{expr.op}{self._operand(expr.right, node)}"
        value = _folded(expr)
        if isinstance(value, int | float) and not isinstance(value, bool):
            return f"0-{self._constant(-value, node)}"
        if isinstance(expr, ir.UnaryOp) and expr.op == "-":
            return f"0-{self._operand(expr.operand, node)}"
        return self._operand(expr, node)

    def _operand(self, expr: Any, node: Any) -> str:
        """A standard-logic operand for ``expr``: itself when it is a register or a
        non-negative constant, else a temporary register holding it, computed by one standard
        instruction per operation (``R[t]=a op b``; a negative value as ``R[t]=0-a``). Exact:
        LS expressions have no side effects, each operation is evaluated once in the order
        the expression gives, and the temporaries are olp's own registers."""
        simple = self._simple(expr, node)
        if simple is not None:
            return simple
        value = _folded(expr)
        if isinstance(value, int | float) and not isinstance(value, bool):
            text = f"0-{self._constant(-value, node)}"
        elif isinstance(expr, ir.UnaryOp) and expr.op == "-":
            text = f"0-{self._operand(expr.operand, node)}"
        elif isinstance(expr, ir.UnaryOp) and expr.op == "+":
            return self._operand(expr.operand, node)
        elif isinstance(expr, ir.BinaryOp) and expr.op in _ARITHMETIC:
            self._type(expr, node)
            left = self._operand(expr.left, node)
            text = f"{left}{expr.op}{self._operand(expr.right, node)}"
        else:
            raise Unwritable(f"{_describe(expr)} cannot be written in LS", node)
        temp = self.registers.temporary(len(self.pre), node)
        self.pre.append(f"  {temp}={text} ;")
        return temp

    def _standard_value(self, expr: Any, node: Any) -> str | None:
        simple = self._simple(expr, node)
        if simple is not None:
            return simple
        if isinstance(expr, ir.BinaryOp) and expr.op in _ARITHMETIC:
            left, right = self._simple(expr.left, node), self._simple(expr.right, node)
            if left is not None and right is not None:
                return f"{left}{expr.op}{right}"
        return None

    def _simple(self, expr: Any, node: Any) -> str | None:
        """A register or a non-negative constant (standard logic operands), else None."""
        value = _folded(expr)
        if isinstance(value, int | float) and not isinstance(value, bool):
            return self._constant(value, node) if value >= 0 else None
        if isinstance(expr, ir.Name | ir.Index | ir.Member):
            return self._operand_ref(expr, node)[0]
        return None

    def _mixed_value(self, expr: Any, node: Any) -> str:
        value = _folded(expr)
        if isinstance(value, int | float) and not isinstance(value, bool):
            return self._constant(value, node)
        if isinstance(expr, ir.Name | ir.Index | ir.Member):
            return self._operand_ref(expr, node)[0]
        if isinstance(expr, ir.UnaryOp) and expr.op == "+":
            return self._mixed_value(expr.operand, node)
        if isinstance(expr, ir.BinaryOp) and expr.op in _ARITHMETIC:
            self._type(expr, node)
            left = self._nested(expr.left, node)
            right = self._nested(expr.right, node)
            return f"{left}{expr.op}{right}"
        raise Unwritable(f"{_describe(expr)} cannot be written in LS", node)

    def _nested(self, expr: Any, node: Any) -> str:
        text = self._mixed_value(expr, node)
        return f"({text})" if isinstance(expr, ir.BinaryOp) else text

    def _constant(self, value: float, node: Any) -> str:
        try:
            return format_number(value, REGISTER_VALUE)
        except NumberError as exc:
            raise Unwritable(str(exc), node) from None

    def _need_mixed(self, node: Any, what: str) -> None:
        if not self.mixed:
            raise Unwritable(
                f"{what} needs LS mixed logic; set the post option mixed_logic: true if the "
                "controller has it",
                node,
            )

    def _condition(self, expr: Any, node: Any, negate: bool = False) -> str:
        return self._condition_text(_flat(self._cond(expr, node, negate)), node)

    def _condition_text(self, cond: Condition, node: Any) -> str:
        """One line's condition: standard, or mixed logic in parentheses."""
        if _standard(cond):
            return _mixed_text(cond)
        count = _count(cond)
        self._need_mixed(
            node,
            f"a condition of {count} comparisons (standard logic takes {STANDARD_CONDITIONS})"
            if count > STANDARD_CONDITIONS and not _mixes(cond)
            else "AND together with OR in one condition",
        )
        if _count(cond) > MIXED_CONDITIONS:
            raise Unwritable(
                f"the condition has {_count(cond)} comparisons; LS mixed logic takes at most "
                f"{MIXED_CONDITIONS}",
                node,
            )
        return f"({_mixed_text(cond)})"

    def _cond(self, expr: Any, node: Any, negate: bool) -> Condition:
        if isinstance(expr, ir.UnaryOp) and expr.op == "not":
            return self._cond(expr.operand, node, not negate)
        if isinstance(expr, ir.BinaryOp) and expr.op in ("and", "or"):
            parts = (self._cond(expr.left, node, False), self._cond(expr.right, node, False))
            logic = Logic(expr.op.upper(), parts)
            return logic.negated() if negate else logic
        atom = self._atom(expr, node)
        return atom.negated() if negate else atom

    def _input(self, expr: ir.DigitalInput, on: bool, node: Any) -> Compare:
        """``DI[n]=ON`` / ``OFF``, n within the post's I/O range."""
        low, high = self.io_range or (expr.index, expr.index)
        if not low <= expr.index <= high:
            raise Unwritable(
                f"digital input {expr.index} is outside the LS controller's range {low}..{high}",
                node,
            )
        return Compare(f"DI[{expr.index}]", "=", "ON" if on else "OFF", True)

    def _atom(self, expr: Any, node: Any) -> Compare:
        if isinstance(expr, ir.DigitalInput):
            return self._input(expr, True, node)
        if isinstance(expr, ir.Name):
            ref, kind = self._operand_ref(expr, node)
            if kind != "bool":
                raise Unwritable(f"{expr.name} is not a BOOL: it cannot be a condition", node)
            return Compare(ref, "=", "1", True)
        if isinstance(expr, ir.BinaryOp) and expr.op in _COMPARE:
            return self._comparison(expr, node)
        raise Unwritable(f"{_describe(expr)} cannot be a condition in LS", node)

    def _comparison(self, expr: ir.BinaryOp, node: Any) -> Compare:
        op = _COMPARE[expr.op]
        left, right = expr.left, expr.right
        if _is_input(right) or (_folded(left) is not None and _folded(right) is None):
            left, right, op = right, left, _MIRRORED[op]
        if isinstance(left, ir.DigitalInput):
            state = _folded(right)
            if not isinstance(state, bool) or op not in ("=", "<>"):
                raise Unwritable("an input compares only with TRUE or FALSE", node)
            return self._input(left, state if op == "=" else not state, node)
        state = _folded(right)
        if isinstance(state, bool) and op in ("=", "<>") and self._type(left, node) == "bool":
            atom = self._atom(left, node)
            return atom if (op == "=") == state else atom.negated()
        for side in (left, right):
            if self._type(side, node) == "bool":
                raise Unwritable("a comparison of BOOL values: write the BOOL itself", node)
        lhs = self._simple(left, node)
        rhs = self._simple(right, node)
        standard = (
            lhs is not None
            and rhs is not None
            and not lhs.startswith("PR")
            and not rhs.startswith("PR")
            and _folded(left) is None
        )
        if standard:
            return Compare(lhs, op, rhs, True)  # type: ignore[arg-type]
        if self.mixed:
            return Compare(self._nested(left, node), op, self._nested(right, node), False)
        if lhs is None or not lhs.startswith("R["):
            lhs = self.registers.temporary(len(self.pre), node)
            self.pre.append(f"  {lhs}={self._value(left, node)} ;")
        if rhs is None or rhs.startswith("PR"):
            rhs = self._operand(right, node)
        return Compare(lhs, op, rhs, True)


def _groups(cond: Logic) -> list[Condition]:
    """The parts of a chain with runs of comparisons cut into standard chains (at most
    :data:`STANDARD_CONDITIONS` each), nested chains kept whole."""
    out: list[Condition] = []
    run: list[Compare] = []
    for part in [*cond.parts, None]:
        if isinstance(part, Compare) and len(run) < STANDARD_CONDITIONS:
            run.append(part)
            continue
        if run:
            out.append(run[0] if len(run) == 1 else Logic(cond.op, tuple(run)))
        run = [part] if isinstance(part, Compare) else []
        if isinstance(part, Logic):
            out.append(part)
    return out


def _mixes(cond: Condition) -> bool:
    return isinstance(cond, Logic) and any(isinstance(p, Logic) for p in cond.parts)


def _standard(cond: Condition) -> bool:
    if isinstance(cond, Compare):
        return cond.standard
    return (
        all(isinstance(p, Compare) and p.standard for p in cond.parts)
        and len(cond.parts) <= STANDARD_CONDITIONS
    )


def _is_input(expr: Any) -> bool:
    return isinstance(expr, ir.DigitalInput)


def _folded(expr: Any) -> bool | int | float | None:
    """A constant number (a negated constant included), else None."""
    if isinstance(expr, ir.Constant) and isinstance(expr.value, bool | int | float):
        if isinstance(expr.value, float) and not math.isfinite(expr.value):
            return None
        return expr.value
    if isinstance(expr, ir.UnaryOp) and expr.op in ("-", "+"):
        inner = _folded(expr.operand)
        if isinstance(inner, int | float) and not isinstance(inner, bool):
            return -inner if expr.op == "-" else inner
    return None


def _describe(expr: Any) -> str:
    if isinstance(expr, ir.FunctionCall):
        return f"the function call {expr.name}(...)"
    if isinstance(expr, ir.BinaryOp):
        return f"the operator {expr.op!r}"
    if isinstance(expr, ir.UnaryOp):
        return f"the operator {expr.op!r}"
    if isinstance(expr, ir.Aggregate):
        return "a structure value"
    if isinstance(expr, ir.Constant):
        return f"the constant {expr.value!r}"
    return type(expr).__name__


@dataclass(frozen=True, slots=True)
class Lowered:
    """:func:`lower`'s result: ``lines[k]``, the /MN lines of step k (empty for steps that are
    not flow), ``problems``: (node, message) for what LS cannot express."""

    lines: tuple[tuple[str, ...], ...]
    problems: tuple[tuple[Any, str], ...]
    unwritten: tuple[ir.Declare, ...] = ()
    """Declarations of types LS has no register for (an error where the variable is used)."""
    variables: Mapping[str, Variable] = field(default_factory=dict)
    """The registers given to variables, by upper-case name."""


def lower(
    events: Iterable[tuple[str, Any]],
    options: Mapping[str, Any],
    io_range: tuple[int, int] | None = None,
) -> Lowered:
    """The /MN lines of every flow step of a file: ``events`` are (kind, node) pairs in the
    order the template writes them (:func:`olp.posts.flow.weave`); ``io_range``: the input
    numbers the controller has (:attr:`olp.posts.base.Post.io_range`)."""
    seq = list(events)
    lowering = Lowering(options, seq)
    lowering.io_range = io_range
    lines: list[tuple[str, ...]] = []
    problems: list[tuple[Any, str]] = []
    for kind, node in seq:
        if kind not in FLOW_KINDS:
            lines.append(())
            continue
        try:
            lines.append(tuple(lowering.lines(kind, node)))
        except Unwritable as exc:
            problems.append((exc.node, str(exc)))
            lines.append(())
    unwritten = tuple(
        decl
        for decl in lowering.registers.skipped.values()
        if decl.type_name.upper() not in {*NUMERIC_TYPES, *POSITION_TYPES}
    )
    return Lowered(tuple(lines), tuple(problems), unwritten, dict(lowering.registers.variables))
