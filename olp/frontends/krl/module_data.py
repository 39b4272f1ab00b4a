"""The data-list variables a KRL program's statements use, as declarations in the IR.

A KRL module keeps its variables in its ``.dat`` (``DECL INT nCount=0``), and sees other
modules' ``GLOBAL`` data and the controller's ``$config.dat``. The statements olp keeps
(assignments, conditions, loop bounds, calls' arguments, verbatim lines) refer to those
variables by name, so the written program must declare them too: a KRL module whose ``.src``
counts ``nCount = nCount + 1`` without the ``.dat`` declaring ``nCount`` does not compile (or
worse, finds another module's global of that name).

:func:`with_module_data` puts one :class:`olp.ir.Declare` per such variable at the start of the
program: ``scope="module"`` for the module's own ``.dat`` (with its value, and the array
elements the list sets one by one), ``scope="external"`` for a name of another data list or
``$config.dat`` (a post for a KUKA controller refers to it; another vendor's cannot). Points
used only as motion targets are not declared: their values are in the motions.

The module's own type definitions (``GLOBAL STRUC MyType INT a, REAL b``, ``ENUM Color red,
green``) come first, each a native-only :class:`olp.ir.Verbatim` (:func:`type_definitions`):
the KRL post writes them back into the ``.dat`` before the declarations that use them (a
``DECL MyType`` without its ``STRUC`` does not compile). Other posts leave them out with a
warning: RAPID could map a STRUC to a RECORD, but every variable or component of such a type
is already refused where the program uses it (no counterpart olp writes), so a type alone has
nothing to serve there; a program that uses none builds without it.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterable, Iterator, Sequence
from typing import Any

from olp import ir
from olp.frontends.krl.ast import Index, Var
from olp.frontends.krl.data import KrlData
from olp.frontends.krl.flow import to_expr
from olp.ir_flow import leaves_and_blocks, walk_expression

_WORD = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]*")
_STRING = re.compile(r'"[^"\r\n]*"|;.*')


def with_module_data(
    program: ir.Program,
    dat: KrlData | None,
    config: KrlData | None,
    shared: Sequence[KrlData] = (),
) -> ir.Program:
    """``program`` with a declaration of every data-list variable its statements use first
    (those of its routines too, but for a routine's own parameters and locals)."""
    program = _with_types(program, dat)
    routines = program.routines
    used, in_text = _used_names([*program.instructions, *(n for r in routines for n in r.body)])
    local = {p.name.upper() for r in routines for p in r.params}
    local |= {d.name.upper() for r in routines for d in r.declarations}
    used, in_text = used - local, in_text - local
    if not used and not in_text:
        return program
    declared = {
        n.name.upper() for n in leaves_and_blocks(program.instructions) if isinstance(n, ir.Declare)
    }
    added: list[ir.Declare] = []
    own = dat.declarations if dat is not None else {}
    for name in own:
        if (name in used or name in in_text) and name not in declared:
            assert dat is not None
            added.append(_module(dat, name))
            declared.add(name)
    for data in _globals(config, shared):
        for name in _visible(data):
            if name in used and name not in declared and name in data.declarations:
                added.append(_external(data, name))
                declared.add(name)
    if not added:
        return program
    return dataclasses.replace(program, instructions=(*added, *program.instructions))


TYPE_REASON = (
    "a KRL type definition of the module's data list: only a KRL controller reads it (a "
    "variable of this type is refused where the program uses it)"
)


def type_definitions(dat: KrlData | None) -> tuple[ir.Verbatim, ...]:
    """The module's own STRUC/ENUM definitions as native-only KRL lines (module text)."""
    if dat is None:
        return ()
    return tuple(
        ir.Verbatim(text=text, language="krl", reason=TYPE_REASON, native_only=True, span=span)
        for text, span in dat.types
    )


def _with_types(program: ir.Program, dat: KrlData | None) -> ir.Program:
    types = type_definitions(dat)
    if not types:
        return program
    return dataclasses.replace(program, instructions=(*types, *program.instructions))


def _globals(config: KrlData | None, shared: Sequence[KrlData]) -> list[KrlData]:
    return [*shared, *([config] if config is not None else [])]


def _visible(data: KrlData) -> Iterable[str]:
    """The names another module sees of ``data`` (``$config.dat``: all of them)."""
    return data.exported() if data.public else data.declarations


def _no_input(var: Var) -> ir.DigitalInput | None:
    return None


def _module(dat: KrlData, name: str) -> ir.Declare:
    decl, item = dat.declarations[name]
    dims = tuple(to_expr(d, _no_input) for d in item.dims or ())
    elements = []
    for stmt in dat.elements.get(name, ()):
        index = stmt.target.selectors[0]
        assert isinstance(index, Index)
        value = to_expr(stmt.value, _no_input)
        assert value is not None
        elements.append((tuple(to_expr(a, _no_input) for a in index.args), value))
    return ir.Declare(
        name=item.name,
        type_name=decl.type_name,
        dims=dims,
        value=to_expr(item.value, _no_input),
        constant=decl.is_const,
        # GLOBAL exports a name only from a PUBLIC list (data.visible_globals): the post writes
        # DEFDAT ... PUBLIC, so a GLOBAL of a list without it would become visible elsewhere
        exported=decl.is_global and dat.public,
        scope="module",
        elements=tuple(elements) if dims else (),
        span=item.span,
    )


def _external(data: KrlData, name: str) -> ir.Declare:
    decl, item = data.declarations[name]
    dims = tuple(to_expr(d, _no_input) for d in item.dims or ())
    return ir.Declare(
        name=item.name,
        type_name=decl.type_name,
        dims=dims,
        exported=True,
        scope="external",
        span=item.span,
    )


# --------------------------------------------------------------------------------------------
# Names the statements use


def _used_names(nodes: Sequence[Any]) -> tuple[set[str], set[str]]:
    """The variable names (upper case) the statements read or write, and those only found in
    the text of calls' arguments and verbatim lines (words, not parsed: declared only when
    the module's own data list holds them)."""
    used: set[str] = set()
    text: set[str] = set()
    for node in leaves_and_blocks(nodes):
        for expr in _expressions(node):
            used.update(_roots(expr))
        if isinstance(node, ir.For):
            used.add(node.variable.upper())
        elif isinstance(node, ir.Call):
            text.update(w for a in node.args for w in _words(a))
        elif isinstance(node, ir.Verbatim):
            text.update(_words(node.text))
    return {n for n in used if not n.startswith("$")}, text - used


def _expressions(node: Any) -> Iterator[Any]:
    if isinstance(node, ir.Declare):
        yield from (d for d in node.dims if d is not None)
        if node.value is not None:
            yield node.value
    elif isinstance(node, ir.Assign):
        yield from (node.target, node.value)
    elif isinstance(node, ir.WaitUntil):
        yield node.condition
    elif isinstance(node, ir.If):
        yield from (b.condition for b in node.branches)
    elif isinstance(node, ir.Switch):
        yield node.subject
        yield from (v for c in node.cases for v in c.values)
    elif isinstance(node, ir.While):
        yield node.condition
    elif isinstance(node, ir.Repeat):
        yield node.until
    elif isinstance(node, ir.For):
        yield from (e for e in (node.start, node.stop, node.step) if e is not None)
    elif isinstance(node, ir.InterruptDecl):
        yield from (node.condition, node.handler)
    elif isinstance(node, ir.RuntimeMove):  # LIN xPath[i]: the written .dat declares xPath
        yield from (e for e in (node.via, node.target) if e is not None)
    elif isinstance(node, ir.PathTrigger):
        action = node.action
        yield from (action.target, action.value) if isinstance(action, ir.Assign) else (action,)


def _roots(expr: Any) -> Iterator[str]:
    for part in walk_expression(expr):
        if isinstance(part, ir.Name):
            yield part.name.upper()


def _words(text: str) -> set[str]:
    """The identifiers of a line of KRL text, outside strings and comments."""
    return {w.upper() for w in _WORD.findall(_STRING.sub(" ", text)) if not w.startswith("$")}
