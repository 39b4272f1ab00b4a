"""The names a KRL statement uses, for the check that something declares each of them.

A KRL program may use a name only where a declaration is: the routine (its parameters and
``DECL``\\ s), the module's ``.dat``, the controller's ``$config.dat``, another module's
``PUBLIC`` data list (``GLOBAL`` names), or, for a function, a ``DEFFCT`` of the module, an
``EXTFCT`` declaration or the controller's system functions. olp reads only the files it is
given, so a name none of them declares is either a value of a file olp was not given or a
misspelling; :meth:`olp.frontends.krl.state.Core.check_declared` says which (a warning per
name, at its first use), and :meth:`olp.frontends.krl.state.Context.unknown_name` what its
value is.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Iterator
from typing import Any

from olp.frontends.krl.ast import (
    Aggregate,
    Assign,
    Binary,
    CallStmt,
    DeclItem,
    FastMotion,
    FuncCall,
    Index,
    LinRows,
    MotionStmt,
    Source,
    Stmt,
    Unary,
    Var,
)

KRL_FUNCTIONS = frozenset(
    {
        *("ABS", "SQRT", "SIN", "COS", "TAN", "ACOS", "ATAN2", "VARSTATE"),
        *("INVERSE", "FORWARD", "INV_POS", "GET_SIG_INF"),
        *("STRTOBOOL", "STRTOINT", "STRTOREAL", "STRTOSTRING", "STRTOFRAME", "STRTOPOS"),
        *("STRTOE6POS", "STRTOAXIS", "STRTOE6AXIS", "STRLEN", "STRCLEAR", "STRADD"),
        *("STRCOMP", "STRCOPY", "STRFIND", "STRDECLLEN"),
        *("SET_KRLMSG", "CLEAR_KRLMSG", "EXISTS_KRLMSG", "SET_KRLDLG", "EXISTS_KRLDLG"),
    }
)
"""Functions the KR C4 controller provides without a declaration in the program's files: KRL's
arithmetic and string functions and the message functions of KSS 8, as olp recalls the KSS
manual's list of system functions (not checked against a stored copy: a name missing here only
costs a warning that olp read no declaration of it)."""

MODELLED_NAMES = frozenset(
    {"PDAT_ACT", "LDAT_ACT", "FDAT_ACT", "TOOL_DATA", "BASE_DATA", "LOAD_DATA"}
    | {"TOOL_NAME", "BASE_NAME"}
)
"""Names of ``$config.dat`` whose meaning olp knows without reading their declaration: the
records the inline forms assign for BAS (absorbed into the motions, or kept with the BAS), and
the tool, base and load tables (a ``TOOL_DATA[n]`` the station resolves by its number)."""

_EXTFCT = re.compile(r"^\s*(?:GLOBAL\s+)?EXTFCTP?\s+[\w$\[\], ]+?\s+(\w+)\s*\(", re.IGNORECASE)


def external_functions(sources: Iterable[Source]) -> frozenset[str]:
    """The functions (upper case) an ``EXTFCT`` line of ``sources`` declares (the grammar reads
    EXT declarations without keeping their names)."""
    found = set()
    for source in sources:
        if "EXTFCT" not in source.text.upper():
            continue
        for line in source.lines:
            match = _EXTFCT.match(line.split(";", 1)[0])
            if match is not None:
                found.add(match.group(1).upper())
    return frozenset(found)


def uses(stmt: Stmt) -> Iterator[Var | FuncCall]:
    """Each variable (:class:`Var`) and function call of ``stmt``'s own expressions, in the
    order written, assignment targets included; not those of nested bodies (lowered as
    statements of their own), not a procedure's name, and not the functions of a spline
    WITH's values (``SVEL_JOINT(...)``: read by :mod:`olp.frontends.krl.inline`), only their
    arguments."""
    if isinstance(stmt, FastMotion | LinRows):  # constants only
        return
    yield from _in_parts(_parts(stmt))


def _parts(node: Any) -> Iterator[Any]:
    if isinstance(node, MotionStmt):
        yield from (*node.targets, node.angle)
        for assign in node.with_clause:
            value = assign.value
            yield assign.target
            yield from value.args if isinstance(value, FuncCall) else (value,)
        return
    for name in node.__slots__:
        if name not in ("body", "bodies", "span"):
            yield getattr(node, name)


def _in_parts(parts: Iterable[Any]) -> Iterator[Var | FuncCall]:
    for part in parts:
        if isinstance(part, tuple):
            yield from _in_parts(part)
        elif isinstance(part, Assign | CallStmt | DeclItem):
            yield from _in_parts(_parts(part))
        elif isinstance(part, Var | FuncCall | Aggregate | Unary | Binary):
            yield from _in_expr(part)


def _in_expr(expr: Any) -> Iterator[Var | FuncCall]:
    if isinstance(expr, Var):
        yield expr
        for selector in expr.selectors:
            if isinstance(selector, Index):
                yield from _in_parts(selector.args)
    elif isinstance(expr, FuncCall):
        yield expr
        yield from _in_parts(expr.args)
    elif isinstance(expr, Aggregate):
        yield from _in_parts(tuple(m.value for m in expr.members))
    elif isinstance(expr, Unary):
        yield from _in_expr(expr.operand)
    elif isinstance(expr, Binary):
        yield from _in_expr(expr.left)
        yield from _in_expr(expr.right)
