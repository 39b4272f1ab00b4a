"""KRL spelling of :mod:`olp.ir_flow` expressions and statements, for the KUKA post.

Operators: ``and``/``or``/``xor``/``not`` -> ``AND``/``OR``/``EXOR``/``NOT``; ``bit_*`` ->
``B_AND``/``B_OR``/``B_EXOR``/``B_NOT``; ``geometric`` -> ``:``; comparisons and arithmetic as
they are. Every nested binary operation is parenthesised, so the meaning never depends on
KRL's priorities (the source's own parentheses are not kept). Constants: ``TRUE``/``FALSE``,
integers, reals (Python's shortest round-trip form, locale-independent), strings in double
quotes, enumeration values as ``#NAME``; ``DigitalInput(n)`` is ``$IN[n]``, or the SIGNAL
name the program read it by (:func:`krl_io`).

User text is never code: names must be KRL identifiers and strings may not hold a double quote
or a control character (:func:`flow_problem` says what cannot be written; the post reports it on
the statement's line and writes nothing).
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from typing import Any

from olp import ir
from olp.errors import PostError
from olp.ir_flow import sub_expressions
from olp.posts.sandbox import SafeText, unsafe_character
from olp.vendors.kuka import approximation_problem

_BINARY = {
    "and": "AND",
    "or": "OR",
    "xor": "EXOR",
    "bit_and": "B_AND",
    "bit_or": "B_OR",
    "bit_xor": "B_EXOR",
    "geometric": ":",
}
_UNARY = {"not": "NOT ", "bit_not": "B_NOT ", "-": "-", "+": "+"}
_IDENTIFIER = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]*\Z")
INT_MIN, INT_MAX = -(2**31), 2**31 - 1
EVENT_KINDS = frozenset({"interrupt_decl", "interrupt", "trigger"})
"""Kinds of the interrupt and trigger statements the KUKA post writes (:func:`krl_event`)."""
"""KRL's INT is a 32-bit signed integer."""


def krl_expr(expr: ir.Expr | None, nested: bool = False) -> str:
    """``expr`` as KRL (None, an argument or index left out, is empty)."""
    if expr is None:
        return ""
    if isinstance(expr, ir.Constant):
        return _constant(expr)
    if isinstance(expr, ir.Name):
        return expr.name
    if isinstance(expr, ir.Index):
        return f"{krl_expr(expr.base)}[{','.join(krl_expr(i) for i in expr.indices)}]"
    if isinstance(expr, ir.Member):
        return f"{krl_expr(expr.base)}.{expr.field}"
    if isinstance(expr, ir.DigitalInput):
        return krl_io(expr, "$IN")
    if isinstance(expr, ir.FunctionCall):
        return f"{expr.name}({', '.join(krl_expr(a) for a in expr.args)})"
    if isinstance(expr, ir.UnaryOp):
        return f"{_UNARY[expr.op]}{krl_expr(expr.operand, nested=True)}"
    if isinstance(expr, ir.BinaryOp):
        op = _BINARY.get(expr.op, expr.op)
        text = f"{krl_expr(expr.left, True)} {op} {krl_expr(expr.right, True)}"
        return f"({text})" if nested else text
    assert isinstance(expr, ir.Aggregate)
    head = f"{expr.type_name}: " if expr.type_name else ""
    members = ", ".join(f"{name} {krl_expr(value)}" for name, value in expr.members)
    return "{" + head + members + "}"


def _constant(expr: ir.Constant) -> str:
    value = expr.value
    if expr.enum:
        return f"#{value}"
    if isinstance(value, bool):
        return "TRUE" if value else "FALSE"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)
    return f'"{value}"'


def krl_decl(step: Any) -> str:
    """A :class:`olp.ir.Declare` as ``DECL TYPE name[dims]=value``; module data (the ``.dat``)
    also with the lines that set single array elements (``name[2]=5``) after it."""
    decl: ir.Declare = step if isinstance(step, ir.Declare) else step.instruction
    dims = f"[{','.join(krl_expr(d) for d in decl.dims)}]" if decl.dims else ""
    value = "" if decl.value is None else f"={krl_expr(decl.value)}"
    prefix = ("GLOBAL " if decl.exported else "") + ("CONST " if decl.constant else "")
    lines = [f"DECL {prefix}{decl.type_name} {decl.name}{dims}{value}"]
    for indices, element in decl.elements:
        at = ",".join("" if i is None else krl_expr(i) for i in indices)
        lines.append(f"{decl.name}[{at}]={krl_expr(element)}")
    bad = next((c for line in lines if (c := unsafe_character(line)) is not None), None)
    if bad is not None:  # flow_problem reports it first; never a line break from data
        raise ValueError(f"declaration of {decl.name}: control character {bad!r}")
    return SafeText("\n".join(lines))


_DECLARATION = re.compile(r"(?i)\s*(GLOBAL\s+)?(EXT|EXTFCT)\s")


def krl_declaration(step: Any) -> bool:
    """Whether ``step`` is a kept KRL line that declares (``EXT name( )``, ``EXTFCT INT
    f( )``): KRL takes those only in a routine's declaration part, before its first
    statement, so the templates write them with the ``DECL`` lines, not in the flow."""
    node = getattr(step, "instruction", step)
    return (
        isinstance(node, ir.Verbatim)
        and node.language == "krl"
        and _DECLARATION.match(node.text) is not None
    )


_TYPE_DEFINITION = re.compile(r"(?i)\s*(GLOBAL\s+)?(STRUC|ENUM)\s")


def krl_type_definition(step: Any) -> bool:
    """Whether ``step`` is a kept KRL type definition of the module's data list (``GLOBAL
    STRUC MyType INT a, REAL b``, ``ENUM Color red, green``): the templates write it into the
    ``.dat``, before the declarations that use it, not in the ``.src``'s flow."""
    node = getattr(step, "instruction", step)
    return (
        isinstance(node, ir.Verbatim)
        and node.language == "krl"
        and _TYPE_DEFINITION.match(node.text) is not None
    )


def krl_declarations(steps: Any) -> list[str]:
    """The texts of the kept declaration lines among ``steps`` (:func:`krl_declaration`), each
    once (a routine written out at each of its calls brings its EXT lines each time), in
    order."""
    texts: dict[str, str] = {}
    for step in steps:
        if krl_declaration(step):
            text = step.instruction.text
            texts.setdefault(re.sub(r"\s+", "", text).upper(), text)
    return list(texts.values())


def krl_routine_head(routine: ir.Routine) -> str:
    """``[GLOBAL] DEF name(p:IN, q:OUT)`` or ``[GLOBAL] DEFFCT TYPE[dims] name(...)``: an
    ``"in"`` parameter is KRL's ``:IN`` (by value), an ``"out"`` one ``:OUT`` (by reference);
    an array parameter has empty brackets, a comma between the positions of one of several
    dimensions (``sText[]:IN``, ``rMatrix[,]:OUT``). Its type is declared in the body
    (:func:`krl_param_decl`)."""
    params = ", ".join(
        f"{p.name}{_head_index(p)}:{'OUT' if p.by_reference else 'IN'}" for p in routine.params
    )
    prefix = "GLOBAL " if routine.exported else ""
    if routine.returns is None:
        return f"{prefix}DEF {routine.name}({params})"
    dims = (
        f"[{','.join(krl_expr(d) for d in routine.returns_dims)}]" if routine.returns_dims else ""
    )
    return f"{prefix}DEFFCT {routine.returns}{dims} {routine.name}({params})"


def krl_io(node: ir.DigitalInput | ir.SetOutput | ir.WaitInput, io: str) -> str:
    """A digital input or output as the program read it: its SIGNAL name where it had one
    (``InTermicoCinta``, declared in ``$config.dat``: KRL -> KRL writes what the user wrote),
    else ``$IN[n]`` / ``$OUT[n]`` (``io``). A name that is not a plain KRL name (an IR made
    elsewhere) is written by its number, which reads the same bit."""
    name = node.signal
    if name is not None and _IDENTIFIER.match(name) and not name.startswith("$"):
        return name
    return f"{io}[{node.index}]"


def krl_program_head(
    name: str,
    params: Sequence[ir.Parameter],
    returns: str | None = None,
    returns_dims: Sequence[ir.Expr | None] = (),
    exported: bool = False,
) -> str:
    """The program's ``DEF``: ``DEF name( )`` as the pendant writes a program without
    parameters, ``DEF name(p:IN, q:OUT)`` for one that other modules call with arguments
    (:attr:`olp.ir.Program.params`, written as a routine's, :func:`krl_routine_head`; their
    types are declared first in the body, :func:`krl_param_decl`), ``DEFFCT BOOL name(...)``
    for a program that gives a result (:attr:`olp.ir.Program.returns`: a module whose first
    routine is a function, which other modules call in an expression; it ends with
    ``ENDFCT``). The module's first routine is the one other modules call by the module's
    name, so it needs no ``GLOBAL``; ``exported`` writes one where a KRL source had it
    (:attr:`olp.ir.Program.exported`), so the line reads as it did."""
    if not params and returns is None:
        return f"{'GLOBAL ' if exported else ''}DEF {name}( )"
    head = ir.Routine(
        name=name,
        params=tuple(params),
        returns=returns,
        returns_dims=tuple(returns_dims),
        exported=exported,
    )
    return krl_routine_head(head)


def _head_index(param: ir.Parameter) -> str:
    """A parameter's brackets in the head: as the source's head had them
    (:attr:`olp.ir.Parameter.head_dims`), else one position per declared dimension."""
    if param.head_dims is None:
        return _empty_index(param.dims)
    return f"[{',' * (param.head_dims - 1)}]" if param.head_dims else ""


def _empty_index(dims: tuple[object, ...]) -> str:
    """``[]``, ``[,]``, ... for an array parameter of ``len(dims)`` dimensions, else empty."""
    return f"[{',' * (len(dims) - 1)}]" if dims else ""


def krl_routine_end(routine: ir.Routine) -> str:
    return "END" if routine.returns is None else "ENDFCT"


def krl_param_decl(param: ir.Parameter) -> str:
    """A parameter's type as KRL declares it in the routine: ``DECL INT nSlot`` (a parameter
    without a type is not declared, as its source did not)."""
    dims = f"[{','.join(krl_expr(d) for d in param.dims)}]" if param.dims else ""
    return f"DECL {param.type_name} {param.name}{dims}"


def krl_call(call: ir.RoutineCall) -> str:
    """A call of a routine of the program: ``Name(arg, arg)``."""
    return f"{call.name}({', '.join(krl_expr(a) for a in call.args)})"


def krl_approximation(move: ir.RuntimeMove) -> str:
    """`` C_PTP C_DIS``: the approximation words of a motion that runs with the controller's
    settings (:attr:`olp.ir.RuntimeMove.approximated`), with the blank before them. Words KRL
    does not take for that motion (:func:`olp.vendors.kuka.approximation_problem`; an IR made
    elsewhere) are a PostError, never written."""
    words = tuple(w.upper() for w in move.approximated)
    problem = approximation_problem(words, move.motion == "joint", move.spline)
    if problem is not None:
        raise PostError(
            f"the KRL post cannot write the approximation {' '.join(words)!r}: {problem}"
        )
    return "".join(f" {w}" for w in words)


def krl_return(node: ir.Return) -> str:
    return "RETURN" if node.value is None else f"RETURN {krl_expr(node.value)}"


def routine_problem(routine: ir.Routine) -> str | None:
    """Why ``routine``'s head and declarations cannot be written as KRL, or None."""
    for name in [routine.name, *(p.name for p in routine.params), routine.returns or "X"]:
        if not _IDENTIFIER.match(name):
            return f"{name!r} is not a KRL name"
    for param in routine.params:
        if param.type_name and not _IDENTIFIER.match(param.type_name):
            return f"{param.type_name!r} is not a KRL type name"
    for expr in [*routine.returns_dims, *(d for p in routine.params for d in p.dims)]:
        problem = None if expr is None else _expr_problem(expr)
        if problem is not None:
            return problem
    for decl in routine.declarations:
        problem = flow_problem(decl)
        if problem is not None:
            return problem
    return None


def krl_event(node: Any) -> str:
    """An :class:`olp.ir.InterruptDecl`, :class:`olp.ir.InterruptSwitch` or
    :class:`olp.ir.PathTrigger` as its KRL statement (DELAY in ms, PATH in mm)."""
    if isinstance(node, ir.InterruptDecl):
        prefix = "GLOBAL " if node.exported else ""
        condition, handler = krl_expr(node.condition), krl_expr(node.handler)
        return f"{prefix}INTERRUPT DECL {node.priority} WHEN {condition} DO {handler}"
    if isinstance(node, ir.InterruptSwitch):
        number = "" if node.priority is None else f" {node.priority}"
        return f"INTERRUPT {node.action.upper()}{number}"
    assert isinstance(node, ir.PathTrigger)
    if node.path is not None:
        where = f"PATH={_plain(node.path * 1000.0)}{' ONSTART' if node.from_start else ''}"
    else:
        where = f"DISTANCE={0 if node.at == 'start' else 1}"
    action = node.action
    if isinstance(action, ir.Assign):
        statement = f"{krl_expr(action.target)} = {krl_expr(action.value)}"
    else:
        statement = krl_expr(action)
    prio = "" if node.priority is None else f" PRIO={node.priority}"
    return f"TRIGGER WHEN {where} DELAY={_plain(node.delay * 1000.0)} DO {statement}{prio}"


def _plain(value: float) -> str:
    """A number without exponent, to 1e-6 of its unit, locale-independent (``-0`` is ``0``)."""
    text = f"{round(value, 6):.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def flow_problem(node: Any) -> str | None:
    """Why ``node`` (a flow statement or block) cannot be written as KRL, or None."""
    for name in _names(node):
        if not _IDENTIFIER.match(name):
            return f"{name!r} is not a KRL name"
    for expr in _exprs(node):
        problem = _expr_problem(expr)
        if problem is not None:
            return problem
    return None


def _names(node: Any) -> list[str]:
    if isinstance(node, ir.Declare):
        return [node.name, node.type_name]
    if isinstance(node, ir.Label | ir.Goto):
        return [node.name if isinstance(node, ir.Label) else node.label]
    if isinstance(node, ir.For):
        return [node.variable]
    if isinstance(node, ir.RoutineCall):
        return [node.name]
    return []


def _exprs(node: Any) -> list[Any]:
    fields = ("condition", "value", "target", "subject", "start", "stop", "step", "until")
    found = [getattr(node, f, None) for f in fields] + list(getattr(node, "dims", ()))
    found += [b.condition for b in getattr(node, "branches", ())]
    found += [v for c in getattr(node, "cases", ()) for v in c.values]
    if isinstance(node, ir.Declare):
        found += [e for indices, value in node.elements for e in (*indices, value)]
    if isinstance(node, ir.InterruptDecl):
        found.append(node.handler)
    if isinstance(node, ir.RoutineCall):
        found += [a for a in node.args if a is not None]
    if isinstance(node, ir.PathTrigger):
        action = node.action
        found += [action.target, action.value] if isinstance(action, ir.Assign) else [action]
    return [e for e in found if e is not None]


def flow_expr_problem(expr: Any) -> str | None:
    """Why ``expr`` cannot be written as a KRL expression (a name that is not a KRL name, a
    constant KRL cannot hold), or None."""
    return _expr_problem(expr)


def _expr_problem(expr: Any) -> str | None:
    if isinstance(expr, ir.Constant):
        return _constant_problem(expr)
    if isinstance(expr, ir.Name | ir.FunctionCall) and not _IDENTIFIER.match(expr.name):
        return f"{expr.name!r} is not a KRL name"
    if isinstance(expr, ir.Member) and not _IDENTIFIER.match(expr.field):
        return f"{expr.field!r} is not a KRL name"
    if isinstance(expr, ir.Aggregate):
        bad = [n for n, _ in expr.members if not _IDENTIFIER.match(n)]
        if bad or (expr.type_name and not _IDENTIFIER.match(expr.type_name)):
            return f"the structure value {krl_expr(expr)!r} has a member that is not a KRL name"
    for child in sub_expressions(expr):
        problem = _expr_problem(child)
        if problem is not None:
            return problem
    return None


def _constant_problem(expr: ir.Constant) -> str | None:
    value = expr.value
    if expr.enum and not (isinstance(value, str) and _IDENTIFIER.match(value)):
        return f"#{value} is not a KRL enumeration value"
    if isinstance(value, float) and not math.isfinite(value):
        return f"{value} is not a number KRL can hold"
    if isinstance(value, int) and not isinstance(value, bool) and not INT_MIN <= value <= INT_MAX:
        return f"{value} is outside KRL's INT range ({INT_MIN} .. {INT_MAX})"
    bad_text = isinstance(value, str) and not expr.enum and ('"' in value or _has_control(value))
    if bad_text:
        return f"the text {value!r} holds a double quote or a control character"
    return None


def _has_control(text: str) -> bool:
    return any(ord(c) < 32 or 127 <= ord(c) < 160 for c in text)
