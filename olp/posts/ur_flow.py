"""URScript spelling of :mod:`olp.ir_flow` (control flow and data), for the UR post.

Sources: Universal Robots' *URScript Programming Language* manual, sections "Numbers, Variables,
and Types", "Flow of Control" and "Scoping rules" (SW 3.x - 5.x; the scoping rules quoted from
UR's online manual), as recalled where no stored copy was found (said below). Pinned by
``tests/posts/test_ur_flow.py`` and ``tests/golden/ur/flow_*``.

Blocks
------
* ``if c:`` / ``elif c:`` / ``else:`` / ``end`` and ``while c:`` / ``end``; ``break`` leaves the
  innermost loop; ``return`` leaves a function, and the program is the function ``def name():``
  (manual, Flow of Control; high confidence). URScript has no ``for``, no ``repeat``, no
  ``switch`` and no ``goto`` (the same section lists none).
* FOR: the program's own counter, counted in a ``while``::

      i = start
      while i <= stop:      # >= for a negative step
        ...
        i = i + step
      end

  so the counter holds the value past the end afterwards, as KRL's does. The step must be a
  whole-number constant (its sign chooses the comparison); a body that assigns the counter or
  the end bound is an error (olp's conservative choice).
* REPEAT ... UNTIL c: ``while True:`` ... ``if c:`` ``break`` ``end`` ``end`` (the condition
  once after each pass). LOOP: ``while True:`` ... ``end``; EXIT is ``break``.
* SWITCH: the subject is evaluated once into a helper variable ``olp_case_n``, then an
  ``if``/``elif`` chain compares it with ``==`` (``or`` between several values of one case);
  DEFAULT is the ``else``.
* A wait on a condition polls once per control cycle: ``while not (c):`` ``sync()`` ``end``,
  as the post already waits for an input.
* Labels and GOTO: URScript has no jump; they are an error naming the line.
* Routines of the program are functions defined at the top of the program's ``def``:
  ``def name(a, b):`` ... ``end`` (Polyscope writes a program's subprograms so; the manual's
  Functions section, as recalled), with ``local`` variables of their own and ``return value``
  for a function's result. URScript passes arguments by value (as recalled; unverified against
  a stored manual): an ``"out"`` parameter the routine changes (assigns, counts with, or hands
  to a call) is an error on the routine, because the caller would not see the change; one it
  only reads is exact by value and written. A routine that assigns a variable of the program
  is an error: whether that assignment in a function reaches the program's variable or makes a
  local one is unverified.
* A block whose body is empty (a KRL ``IF`` with only an ``ELSE`` body, a dropped line) is
  written empty (``if c:`` then ``else:``); whether URScript accepts an empty body is
  unverified (a script it refuses does not run: no motion follows from it).

Data
----
Variables on the program's first level are global whatever their qualifier (manual, Scoping
rules: "Variables on the first scope level (first indentation) are treated as global, even if
the global qualifier is missing or the local qualifier is used"): a declaration is written
``local name = value`` (``global`` for an exported one, which says the same), at the top of
the program. URScript has no declaration without a value and no constants, so the value is the
declaration's own or, per type (olp's choice, the value KRL-like languages start from): bool
``False``, INT ``0``, REAL ``0.0``, CHAR[n] ``""``; a one-dimensional array is a list of as many
of them (``[0, 0, 0]``). Poses and joint positions are errors: KRL gives them in mm and degrees
with Euler angles, URScript in metres and a rotation vector, and olp does not convert a
variable's value. KRL arrays count from 1, URScript lists from 0: ``a[i]`` is written
``a[i - 1]`` (a constant index is written already shifted). Module data (a KRL ``.dat``
variable) is ``global`` with the data list's value (an array's elements in its list); it starts
from that value on every run, where the KUKA controller keeps the last run's: the post warns
for each one the program assigns (:meth:`olp.posts.ur.UrPost.check_program`). A variable of
another module's data list is an error, and so is a name the program uses that nothing declares
(:func:`olp.posts.flow_text.undeclared_names`; a routine may read the program's first-level
variables, which are global).

Expressions
-----------
``and``/``or``/``not``; KRL's ``EXOR`` (of two BOOLs) as ``!=`` of them (exact for booleans,
and needs no ``xor``, whose spelling in URScript is unverified); ``==``, ``!=`` for ``<>``,
``<``, ``<=``, ``>``, ``>=``, ``+``, ``-``, ``*``; every nested operation in parentheses.
``/`` only where one side is known to be a real (KRL divides INT by INT with truncation; what
URScript's ``/`` does with two ints is unverified). ``True``/``False``; numbers in the shortest
form that reads back to the same value, without an exponent (``0.00001``: URScript's exponent
notation is unverified); strings in double quotes, printable ASCII without ``"`` or ``\\``
(URScript's escapes are unverified: refused rather than guessed). A digital input is
``get_digital_in(n)``, as the post reads inputs (numbers 0..9). Names are written as the
program declares them (URScript names are case-sensitive, KRL's are not) and must be legal
URScript names (:data:`olp.posts.ur.NAME_RULE`); components of structures (``.X``), KRL's
geometric operator, bit operations, enumeration values and structure values are errors.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Sequence
from typing import Any, ClassVar

import numpy as np

from olp import ir
from olp.ir_flow import leaves_and_blocks
from olp.posts.flow_text import (
    FlowProblem,
    FlowWriter,
    OpenBlock,
    Symbols,
    Variable,
    constant_int,
    element_values,
    exprs_of,
    for_problem,
    initial_value,
    string_index,
    variable_of,
)
from olp.posts.text import NameRule

INITIAL = {"bool": "False", "int": "0", "real": "0.0", "string": '""'}
"""The value a declaration without one starts from, per value kind (olp's choice)."""
MAX_LIST = 10_000
"""The longest list olp writes for an array (olp's bound)."""
IO_RANGE = (0, 9)
"""``get_digital_in`` numbers (the UR post's)."""

_BINARY = {"and": "and", "or": "or", "xor": "!=", "<>": "!="}
_PLAIN = frozenset({"+", "-", "*", "/", "==", "<", "<=", ">", ">="})
_TEXT = re.compile(r"[ !#-\[\]-~]*\Z")
"""Printable ASCII without ``"`` and ``\\``."""


class UrWriter(FlowWriter):
    """URScript lines of one file's flow steps (see the module docstring)."""

    LANGUAGE: ClassVar[str] = "URScript"
    BASE_INDENT: ClassVar[int] = 2
    NOT: ClassVar[str] = "not "

    def __init__(self, symbols: Symbols, rule: NameRule, taken: Iterable[str] = ()) -> None:
        super().__init__(symbols, taken)
        self.rule = rule
        self.subjects: dict[int, str] = {}
        self.cases_open: dict[int, bool] = {}

    def prepare(self, steps: Sequence[Any]) -> None:
        """Name the helper variables of the file's switches."""
        for step in steps:
            if step.kind == "switch":
                self.subjects[id(step.instruction)] = self.fresh("case")

    def fresh(self, stem: str) -> str:
        k = 1
        while f"olp_{stem}_{k}".casefold() in self.taken:
            k += 1
        self.taken.add(f"olp_{stem}_{k}".casefold())
        return f"olp_{stem}_{k}"

    # ---- data

    def declaration(self, var: Variable) -> str:
        decl = var.declare
        if var.kind not in INITIAL:
            raise FlowProblem(
                f"{decl.name} is a {decl.type_name}: KRL writes positions in mm and degrees, "
                "URScript in metres and a rotation vector, and olp does not convert variables"
            )
        if len(var.dims) > 1:
            raise FlowProblem(f"{decl.name} has {len(var.dims)} dimensions; olp writes lists")
        start = initial_value(var)
        value = self.expr(start) if start is not None else INITIAL[var.kind]
        if var.dims:
            size = constant_int(var.dims[0])
            if size is None or not 0 < size <= MAX_LIST:
                raise FlowProblem(f"the size of the list {decl.name} must be 1 .. {MAX_LIST}")
            values = element_values(var, value, self.expr) if decl.elements else [value] * size
            value = "[" + ", ".join(values) + "]"
        scope = "global" if decl.exported or decl.scope == "module" else "local"
        return f"{scope} {self.name(decl.name)} = {value}"

    # ---- expressions

    def name(self, name: str) -> str:
        spelled = self.symbols.name(name)
        if not self.rule.is_legal(spelled):
            raise FlowProblem(f"{spelled!r} is not a URScript name")
        return spelled

    def expr(self, expr: ir.Expr | None, nested: bool = False) -> str:
        """``expr`` in URScript; FlowProblem for what URScript cannot say exactly."""
        if expr is None:
            raise FlowProblem("an argument or index left out has no URScript counterpart")
        if isinstance(expr, ir.Constant):
            return self.constant(expr)
        if isinstance(expr, ir.Name):
            return self.name(expr.name)
        if isinstance(expr, ir.Index):
            return self.index(expr)
        if isinstance(expr, ir.DigitalInput):
            if not IO_RANGE[0] <= expr.index <= IO_RANGE[1]:
                raise FlowProblem(
                    f"digital input {expr.index} is outside get_digital_in's {IO_RANGE[0]}.."
                    f"{IO_RANGE[1]}"
                )
            return f"get_digital_in({expr.index})"
        if isinstance(expr, ir.FunctionCall):
            return f"{self.name(expr.name)}({', '.join(self.expr(a) for a in expr.args)})"
        if isinstance(expr, ir.UnaryOp):
            return self.unary(expr)
        if isinstance(expr, ir.BinaryOp):
            text = self.binary(expr)
            return f"({text})" if nested else text
        if isinstance(expr, ir.Member):
            raise FlowProblem(f"the component .{expr.field} has no URScript counterpart")
        raise FlowProblem("a structure value ({...}) has no URScript counterpart")

    def constant(self, expr: ir.Constant) -> str:
        value = expr.value
        if expr.enum:
            raise FlowProblem(f"the enumeration value #{value} has no URScript counterpart")
        if isinstance(value, bool):
            return "True" if value else "False"
        if isinstance(value, int):
            if not -(2**31) <= value < 2**31:
                raise FlowProblem(f"{value} is outside URScript's 32-bit int")
            return str(value)
        if isinstance(value, float):
            if not math.isfinite(value):
                raise FlowProblem(f"{value} is not a number URScript can hold")
            return np.format_float_positional(value, unique=True, trim="0")
        if not _TEXT.match(value):
            raise FlowProblem(
                f"the text {value!r} holds a double quote, a backslash or a character that is "
                "not printable ASCII"
            )
        return f'"{value}"'

    def index(self, expr: ir.Index) -> str:
        if not isinstance(expr.base, ir.Name):
            raise FlowProblem("only a variable's elements can be indexed in URScript")
        name = self.name(expr.base.name)
        var = self.symbols.variable(expr.base.name)
        indices: tuple[ir.Expr | None, ...] = expr.indices
        if var is not None and var.kind == "string":
            indices = string_index(var, expr)
            if not indices:
                return name
        if len(indices) != 1:
            raise FlowProblem(f"{name} is indexed with {len(indices)} indices; olp writes lists")
        return f"{name}[{self.zero_based(indices[0])}]"

    def zero_based(self, index: ir.Expr | None) -> str:
        """KRL's index from 1 as a list position from 0."""
        value = constant_int(index)
        if value is not None:
            if value < 1:
                raise FlowProblem(f"the index {value} is below KRL's first element, 1")
            return str(value - 1)
        return f"{self.expr(index, nested=True)} - 1"

    def binary(self, expr: ir.BinaryOp) -> str:
        op = _BINARY.get(expr.op, expr.op if expr.op in _PLAIN else None)
        if op is None:
            what = "KRL's geometric operator ':'" if expr.op == "geometric" else "bit operations"
            raise FlowProblem(f"{what} have no URScript counterpart olp writes")
        kinds = (self.symbols.kind(expr.left), self.symbols.kind(expr.right))
        if expr.op == "xor" and kinds != ("bool", "bool"):
            raise FlowProblem("EXOR is written as != of two booleans, and olp cannot tell both are")
        if op == "/" and "real" not in kinds:
            raise FlowProblem(
                "olp cannot tell that this division is of reals (KRL divides INT by INT with "
                "truncation); write a REAL operand, e.g. 8.0"
            )
        return f"{self.expr(expr.left, True)} {op} {self.expr(expr.right, True)}"

    # ---- the check

    def check_node(self, node: Any) -> None:
        if isinstance(node, ir.Declare):
            var = self.symbols.variable(node.name)
            if var is not None and var.declare is node:
                self.declaration(var)
            return
        if isinstance(node, ir.Label | ir.Goto):
            raise FlowProblem("URScript has no labels and no GOTO")
        if isinstance(node, ir.For):
            self.for_head(node)
            return
        for expr in exprs_of(node):
            self.expr(expr)

    def for_head(self, node: ir.For) -> tuple[str, str, str, str, str]:
        """(counter, start, comparison, stop, ``+ step``) of a FOR written as a while."""
        problem = for_problem(node)
        if problem is not None:
            raise FlowProblem(problem)
        step = 1 if node.step is None else constant_int(node.step)
        if step is None or step == 0:
            raise FlowProblem("the FOR loop's STEP must be a whole-number constant other than 0")
        counter = self.name(node.variable)
        compare, sign = ("<=", "+") if step > 0 else (">=", "-")
        return counter, self.expr(node.start), compare, self.expr(node.stop), f"{sign} {abs(step)}"

    # ---- statements

    def _declare(self, node: ir.Declare) -> list[tuple[int, str]]:
        var = self.symbols.variable(node.name)
        assert var is not None
        return [(self.depth, self.declaration(var))]

    def _assign(self, node: ir.Assign) -> list[tuple[int, str]]:
        return [(self.depth, f"{self.expr(node.target)} = {self.expr(node.value)}")]

    def _wait_until(self, node: ir.WaitUntil) -> list[tuple[int, str]]:
        d = self.depth
        return [(d, f"while not ({self.expr(node.condition)}):"), (d + 1, "sync()"), (d, "end")]

    def _exit(self, node: ir.Exit) -> list[tuple[int, str]]:
        self._innermost_loop()
        return [(self.depth, "break")]

    def _return(self, node: ir.Return) -> list[tuple[int, str]]:
        if node.value is None:
            return [(self.depth, "return")]
        return [(self.depth, f"return {self.expr(node.value)}")]

    def _routine_call(self, node: ir.RoutineCall) -> list[tuple[int, str]]:
        args = ", ".join(self.expr(a) for a in node.args)
        return [(self.depth, f"{self.name(node.name)}({args})")]

    # ---- routines

    def routine_head(self, routine: ir.Routine) -> str:
        """``def name(a, b):``, at the program's first level (a function of the program)."""
        params = ", ".join(self.name(p.name) for p in routine.params)
        return " " * self.BASE_INDENT + f"def {self.name(routine.name)}({params}):"

    def local_declaration(self, decl: ir.Declare) -> str:
        """A routine's own variable: ``local name = value`` inside its ``def``."""
        text = self.declaration(variable_of(decl))
        return " " * (self.BASE_INDENT + self.STEP) + text.replace("global ", "local ", 1)

    def routine_problems(self, routine: ir.Routine) -> list[tuple[Any, str]]:
        """What of ``routine`` URScript cannot say exactly (see the module docstring)."""
        out: list[tuple[Any, str]] = []
        try:
            self.routine_head(routine)
            for decl in routine.declarations:
                self.local_declaration(decl)
        except FlowProblem as exc:
            out.append((routine, str(exc)))
        own = {p.name.casefold() for p in routine.params}
        own |= {d.name.casefold() for d in routine.declarations}
        changed = _changed_names(routine.body)
        for param in routine.params:
            if param.by_reference and param.name.casefold() in changed:
                out.append((routine, _by_value(routine, param)))
        for node, name in _assignments(routine.body):
            if name.casefold() not in own:
                out.append((node, _global_assignment(routine, name)))
        return out

    # ---- blocks

    def _end(self) -> list[tuple[int, str]]:
        self.stack.pop()
        return [(self.depth, "end")]

    def _if(self, node: ir.If) -> list[tuple[int, str]]:
        return self.open_block(node, "if", f"if {self.expr(node.branches[0].condition)}:")

    def _elif(self, node: ir.Branch) -> list[tuple[int, str]]:
        return [(self.depth - 1, f"elif {self.expr(node.condition)}:")]

    def _else(self, node: ir.If) -> list[tuple[int, str]]:
        return [(self.depth - 1, "else:")]

    def _end_if(self, node: ir.If) -> list[tuple[int, str]]:
        return self._end()

    def _switch(self, node: ir.Switch) -> list[tuple[int, str]]:
        subject = self.subjects[id(node)]
        self.cases_open[id(node)] = False
        first = (self.depth, f"{subject} = {self.expr(node.subject)}")
        self.stack.append(OpenBlock(node, "switch"))
        return [first]

    def _case(self, node: ir.Case) -> list[tuple[int, str]]:
        switch = self.stack[-1].node
        subject = self.subjects[id(switch)]
        test = " or ".join(f"{subject} == {self.expr(v, True)}" for v in node.values)
        word = "elif" if self.cases_open[id(switch)] else "if"
        self.cases_open[id(switch)] = True
        return [(self.depth - 1, f"{word} {test or 'False'}:")]

    def _default(self, node: ir.Switch) -> list[tuple[int, str]]:
        if not self.cases_open[id(node)]:
            self.cases_open[id(node)] = True
            return [(self.depth - 1, "if True:")]
        return [(self.depth - 1, "else:")]

    def _end_switch(self, node: ir.Switch) -> list[tuple[int, str]]:
        self.stack.pop()
        return [(self.depth, "end")] if self.cases_open.pop(id(node)) else []

    def _while(self, node: ir.While) -> list[tuple[int, str]]:
        return self.open_block(node, "while", f"while {self.expr(node.condition)}:")

    def _end_while(self, node: ir.While) -> list[tuple[int, str]]:
        return self._end()

    def _loop(self, node: ir.Loop) -> list[tuple[int, str]]:
        return self.open_block(node, "loop", "while True:")

    def _end_loop(self, node: ir.Loop) -> list[tuple[int, str]]:
        return self._end()

    def _repeat(self, node: ir.Repeat) -> list[tuple[int, str]]:
        return self.open_block(node, "repeat", "while True:")

    def _until(self, node: ir.Repeat) -> list[tuple[int, str]]:
        d = self.depth
        test = [(d, f"if {self.expr(node.until)}:"), (d + 1, "break"), (d, "end")]
        return [*test, *self._end()]

    def _for(self, node: ir.For) -> list[tuple[int, str]]:
        counter, start, compare, stop, _ = self.for_head(node)
        first = (self.depth, f"{counter} = {start}")
        return [first, *self.open_block(node, "for", f"while {counter} {compare} {stop}:")]

    def _end_for(self, node: ir.For) -> list[tuple[int, str]]:
        counter, _, _, _, step = self.for_head(node)
        increment = (self.depth, f"{counter} = {counter} {step}")
        return [increment, *self._end()]


def _base_name(expr: Any) -> str | None:
    while isinstance(expr, ir.Index | ir.Member):
        expr = expr.base
    return expr.name if isinstance(expr, ir.Name) else None


def _assignments(nodes: Sequence[Any]) -> list[tuple[Any, str]]:
    """(node, variable) for every assignment and FOR counter of ``nodes``."""
    out = []
    for node in leaves_and_blocks(nodes):
        target = node.target if isinstance(node, ir.Assign) else None
        name = node.variable if isinstance(node, ir.For) else _base_name(target)
        if name is not None:
            out.append((node, name))
    return out


def _changed_names(nodes: Sequence[Any]) -> set[str]:
    """Variables ``nodes`` may change (case-folded): assigned, counted, or handed to a call
    (which may take them by reference)."""
    names = {name.casefold() for _, name in _assignments(nodes)}
    for node in leaves_and_blocks(nodes):
        if isinstance(node, ir.RoutineCall):
            names |= {n.casefold() for a in node.args if (n := _base_name(a)) is not None}
    return names


def _by_value(routine: ir.Routine, param: ir.Parameter) -> str:
    return (
        f"parameter {param.name} of {routine.name} is passed by reference (OUT) and the routine "
        "changes it; URScript passes parameters by value, so the caller would not see the change"
    )


def _global_assignment(routine: ir.Routine, name: str) -> str:
    return (
        f"{routine.name} assigns {name}, a variable of the program; how a URScript function "
        "assigns a program variable is unverified, so olp does not write it"
    )
