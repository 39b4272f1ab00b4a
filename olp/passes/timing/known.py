"""Values a program's own assignments fix along its paths: constant propagation for path timing.

:mod:`.conditions` folds what holds for the whole run (``--assume`` values, constants, initial
values no statement changes). This module adds what the program itself assigns on the way to
a condition: after ``nLayers = 4`` a ``FOR i = 1 TO nLayers`` runs four passes, and after
``mode = 2`` a ``SWITCH mode`` takes ``CASE 2``. A cell's palletising or milling program sets
its counts this way far more often than in declarations.

The rules (a value is known only where every path that reaches the point agrees on it):

* ``target = value`` with a foldable value and a plain target (a name, a member, an element
  with constant indices) makes the target known; any other assignment forgets the target (all
  of a variable when the element is not constant). Values are fitted to the declared type:
  an integer type takes a number only where it is a whole number (KRL rounds a REAL assigned
  to an INT; olp does not guess the rounding), a real type holds a float.
* ``--assume`` values win over assignments (the user says what the variable holds there).
* After ``IF``/``SWITCH``: what every arm that may run agrees on. A loop forgets everything its
  body assigns, before its first pass and after its end (the passes' order of assignments is
  not followed, except for counters below).
* A call, a verbatim statement, a path trigger's action or a function in an expression may
  change any variable but the program's own non-exported ones and is taken to do so; a name
  passed as an argument may change too. System variables (``$...``) are never learned (the
  controller changes them).
* A program that declares an interrupt learns nothing (a handler can run between any two
  statements and change anything).

**Counters.** A ``WHILE`` or ``REPEAT`` whose condition reads only known values and counters
(variables assigned only in statements directly in the loop's body, in order, from known
values) runs the passes its counters give, found by running those assignments alone: ``i = 0``
then ``WHILE i < 5`` with ``i = i + 1`` in its body runs five passes. More than
:data:`MAX_COUNTED` passes, or a condition that stays unknown, counts as unknown.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Mapping, Sequence
from typing import Any

from olp import ir
from olp import ir_flow as f
from olp.passes.timing.conditions import (
    Environment,
    Value,
    _base_key,
    _Unknown,
    expression_key,
)

MAX_COUNTED = 100_000
"""Passes of a counter loop run at most to find its count."""

INTEGER_TYPES = frozenset({"int", "integer", "dint", "sint", "byte", "long"})
REAL_TYPES = frozenset({"real", "num", "dnum", "float", "double", "lreal"})


class Known:
    """What the walk knows at one point: ``base`` (for the whole run: constants, fixed initial
    values, assumptions) and ``values`` (learned from assignments on every path here).

    ``program``: the program's nodes (declarations give types and locality). ``assumed``: the
    keys the user assumed (never overwritten)."""

    def __init__(
        self,
        base: Environment,
        program: Sequence[Any],
        assumed: Iterable[str],
    ) -> None:
        self.base = base
        self.assumed = frozenset(assumed)
        self.types: dict[str, str] = {}
        self.local: set[str] = set()
        self.enabled = True
        for node in f.leaves(program):
            if isinstance(node, f.Declare):
                name = node.name.casefold()
                self.types[name] = node.type_name.casefold()
                if not node.exported and node.scope != "external":
                    self.local.add(name)
            elif isinstance(node, f.InterruptDecl):
                self.enabled = False
        self.values: dict[str, Value] = {}

    # ---- what the walk asks

    def environment(self) -> Environment:
        """The environment conditions are folded in here."""
        if not self.values:
            return self.base
        names = {**self.base.names, **self.values}
        for key in self.assumed:
            names[key] = self.base.names[key]
        return Environment(self.base.inputs, names)

    def snapshot(self) -> dict[str, Value]:
        return dict(self.values)

    def restore(self, values: Mapping[str, Value]) -> None:
        self.values = dict(values)

    def join(self, arms: Sequence[Mapping[str, Value]]) -> None:
        """Keep what every arm agrees on (``arms``: the values at each arm's end)."""
        if not arms:
            return
        first, *rest = arms
        self.values = {
            k: v for k, v in first.items() if all(k in o and _same(o[k], v) for o in rest)
        }

    # ---- statements

    def learn(self, node: Any) -> None:
        """Follow one statement of a run (not a block)."""
        if not self.enabled:
            return
        for call in _calls(node):
            self._call(call)
        if isinstance(node, f.Assign):
            self._assign(node.target, self.environment().evaluate(node.value))
        elif isinstance(node, f.PathTrigger) and isinstance(node.action, f.Assign):
            self._forget(node.action.target)

    def evaluated(self, node: Any) -> None:
        """Follow the calls in block ``node``'s own expressions (its conditions, after they
        are evaluated)."""
        if not self.enabled:
            return
        for expr in _block_expressions(node):
            for call in _expression_calls(expr):
                self._call(call)

    def enter_loop(self, node: Any) -> None:
        """Forget what loop ``node``'s body changes (before its first pass and after it)."""
        if not self.enabled:
            return
        if isinstance(node, f.For):
            self._forget_key(node.variable.casefold())
        for leaf in f.leaves(node.body):
            for call in _calls(leaf):
                self._call(call)
            target = _target(leaf)
            if target is not None:
                self._forget(target)
        for block in f.leaves_and_blocks([node]):
            for expr in _block_expressions(block):
                for call in _expression_calls(expr):
                    self._call(call)

    def passes(self, node: f.While | f.Repeat) -> int | None:
        """The passes of counter loop ``node`` (module docstring), or None."""
        if not self.enabled:
            return None
        condition = node.condition if isinstance(node, f.While) else node.until
        direct = [n for n in node.body if isinstance(n, f.Assign)]
        others = [n for n in f.leaves(n for n in node.body if not isinstance(n, f.Assign))]
        nested = [_changed(n) for n in others if _target(n) is not None]
        read = [k for part in f.walk_expression(condition) if (k := expression_key(part))]
        if any(k is None for k in nested) or any(_expression_calls(condition)):
            return None
        if any(_overlap(r, k) for r in read for k in nested if k is not None):
            return None
        saved = self.snapshot()
        try:
            for leaf in others:
                for call in _calls(leaf):
                    self._call(call)
            for block in f.leaves_and_blocks(node.body):
                for expr in _block_expressions(block):
                    for call in _expression_calls(expr):
                        self._call(call)
            for key in nested:
                self._forget_key(key)
            return self._run_counter(condition, direct, isinstance(node, f.While))
        finally:
            self.restore(saved)

    # ---- inside

    def _run_counter(
        self, condition: f.Expr, body: Sequence[f.Assign], check_first: bool
    ) -> int | None:
        for count in range(MAX_COUNTED + 1):
            if check_first or count:
                value = self.environment().evaluate(condition)
                if isinstance(value, _Unknown) or not isinstance(value, bool):
                    return None
                if value is not check_first:  # WHILE ends on false, REPEAT on true
                    return count
            for node in body:
                self.learn(node)
        return None

    def _assign(self, target: f.Expr, value: Any) -> None:
        key = expression_key(target)
        if key is not None and key in self.assumed:
            return
        self._forget(target)
        if key is None or key.startswith("$"):
            return
        fitted = _fit(value, self.types.get(_root(key)))
        if fitted is not None:
            self.values[key] = fitted

    def _forget(self, target: f.Expr) -> None:
        key = expression_key(target)
        self._forget_key(key if key is not None else _base_key(target))

    def _forget_key(self, key: str | None) -> None:
        if key is None:
            self.values.clear()  # an assignment through an expression olp cannot name
            return
        self.values = {k: v for k, v in self.values.items() if not _overlap(k, key)}

    def _call(self, call: Any) -> None:
        """Forget what a call may change: everything but the program's local variables, and
        the variables passed to it; a verbatim statement may change anything."""
        if isinstance(call, f.Verbatim):
            if not call.native_only:  # (a native-only one changes no variable)
                self.values.clear()
            return
        self.values = {k: v for k, v in self.values.items() if _root(k) in self.local}
        for name in _argument_names(call):
            self._forget_key(name)


# --------------------------------------------------------------------------------------------
# Helpers


def _same(a: Value, b: Value) -> bool:
    return type(a) is type(b) and a == b


def _root(key: str) -> str:
    """The variable of a key: ``part.kind`` -> ``part``, ``slot[2]`` -> ``slot``."""
    cut = [i for i in (key.find("."), key.find("[")) if i >= 0]
    return key[: min(cut)] if cut else key


def _overlap(a: str, b: str) -> bool:
    """Whether keys ``a`` and ``b`` name overlapping storage (one is part of the other)."""
    if a == b:
        return True
    short, long = (a, b) if len(a) < len(b) else (b, a)
    return long.startswith(short) and long[len(short)] in ".["


def _fit(value: Any, type_name: str | None) -> Value | None:
    """``value`` as a variable of ``type_name`` holds it, or None where olp cannot say."""
    if isinstance(value, _Unknown):
        return None
    if isinstance(value, bool | str):
        return value
    if not isinstance(value, int | float):
        return None
    if type_name in INTEGER_TYPES:
        return int(value) if float(value).is_integer() else None
    if type_name in REAL_TYPES:
        return float(value)
    # Type unknown: a whole number stays what it is; a fraction could be rounded by the type.
    return value if isinstance(value, int) else None


def _target(node: Any) -> f.Expr | None:
    if isinstance(node, f.Assign):
        return node.target
    if isinstance(node, f.PathTrigger) and isinstance(node.action, f.Assign):
        return node.action.target
    return None


def _changed(node: Any) -> str | None:
    """The key an assignment ``node`` changes (its root for an element olp cannot name; None
    for a target olp cannot name at all)."""
    target = _target(node)
    return None if target is None else expression_key(target) or _base_key(target)


def _calls(node: Any) -> Iterator[Any]:
    """The calls a statement makes: a call statement, a verbatim statement (anything may
    happen), a trigger's call, the functions in its expressions."""
    if isinstance(node, ir.Call | f.Verbatim):
        yield node
    if isinstance(node, f.PathTrigger) and isinstance(node.action, f.FunctionCall):
        yield node.action
    for expr in _statement_expressions(node):
        yield from _expression_calls(expr)


def _statement_expressions(node: Any) -> list[Any]:
    if isinstance(node, f.Assign):
        return [node.target, node.value]
    if isinstance(node, f.WaitUntil):
        return [node.condition]
    if isinstance(node, f.PathTrigger) and isinstance(node.action, f.Assign):
        return [node.action.target, node.action.value]
    if isinstance(node, ir.RuntimeMove):  # its target may call a function (PTP fnGetPos())
        return [node.target] if node.via is None else [node.via, node.target]
    return []


def _block_expressions(node: Any) -> list[Any]:
    """The expressions a block evaluates itself (conditions, subject, bounds)."""
    if isinstance(node, f.If):
        return [b.condition for b in node.branches]
    if isinstance(node, f.Switch):
        return [node.subject, *(v for c in node.cases for v in c.values)]
    if isinstance(node, f.While):
        return [node.condition]
    if isinstance(node, f.Repeat):
        return [node.until]
    if isinstance(node, f.For):
        return [e for e in (node.start, node.stop, node.step) if e is not None]
    return []


def _expression_calls(expr: Any) -> Iterator[f.FunctionCall]:
    for part in f.walk_expression(expr):
        if isinstance(part, f.FunctionCall):
            yield part


def _argument_names(call: Any) -> list[str | None]:
    """The variables a call is given (which it may change, as IN/OUT parameters)."""
    if isinstance(call, f.FunctionCall):
        return [_base_key(a) for a in call.args if a is not None and _base_key(a) is not None]
    if isinstance(call, ir.Call):
        return [_name_of_text(a) for a in call.args if _name_of_text(a) is not None]
    return []


def _name_of_text(text: str) -> str | None:
    """The variable at the start of an argument's text (``nCount``, ``aSlot[2]``)."""
    head = text.strip()
    end = 0
    while end < len(head) and (head[end].isalnum() or head[end] in "_$"):
        end += 1
    return head[:end].casefold() or None
