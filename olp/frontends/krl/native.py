"""Statements that matter only on a KUKA controller, kept as written for the KRL post alone.

Each becomes a :class:`olp.ir.Verbatim` with ``native_only=True``: the KRL post writes it back
where it stood; every other post leaves it out with a warning giving the reason below (the
warning olp gave for it before it was kept), where another verbatim statement is an error.

* ``$BWDSTART = FALSE|TRUE``: each pendant inline form sets it (the flag for stepping backwards
  through the program on the pendant); it changes nothing of the motion.
* The pendant's INI lines (the ``BASISTECH INI`` of a ``;FOLD INI``, or of a cell program's
  own folds): ``GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )`` and the
  ``INTERRUPT ON 3`` after it wherever they stand (the stop-message handling changes nothing
  olp models), and ``BAS (#INITMOV,0 )`` before the routine's first motion (it resets the
  controller's motion settings; before any motion, the output writes every setting of the
  first motion anyway). The KRL post writes no template INI for a program read from KRL, so
  these lines are the program's own, where its source had them (a ``cell.src`` whose INI
  lines stand outside a ``;FOLD INI`` lost its stop-message interrupt when only the INI fold
  kept them).
"""

from __future__ import annotations

from olp import ir
from olp.frontends.krl.ast import (
    Assign,
    CallStmt,
    EnumValue,
    InterruptCtl,
    InterruptDecl,
    Num,
    Stmt,
)
from olp.frontends.krl.events import STANDARD_STOP, is_standard_stop
from olp.frontends.krl.state import SYSTEM_REASONS

INI_TITLE = "INI"
"""The title of the pendant's INI fold (``;FOLD INI;%{PE}``)."""
INITMOV = "BAS(#INITMOV) resets controller defaults; olp starts from its own"


def native_reason(stmt: Stmt, before_motion: bool, stop_declared: bool) -> str | None:
    """Why ``stmt`` is kept for the KRL post only, or None for any other statement.
    ``before_motion``: it stands before the routine's first motion; ``stop_declared``: the
    standard stop-message interrupt was declared (and kept) before it."""
    if isinstance(stmt, Assign) and stmt.target.key == "$BWDSTART":
        return SYSTEM_REASONS["$BWDSTART"]
    if isinstance(stmt, InterruptDecl) and is_standard_stop(stmt):
        return STANDARD_STOP
    if isinstance(stmt, InterruptCtl) and stmt.action == "ON" and stop_declared:
        priority = stmt.priority
        return STANDARD_STOP if isinstance(priority, Num) and priority.value == 3 else None
    if not before_motion:
        return None
    if isinstance(stmt, CallStmt) and stmt.name.upper() == "BAS" and stmt.args:
        first = stmt.args[0]
        return INITMOV if isinstance(first, EnumValue) and first.name.upper() == "INITMOV" else None
    return None


def is_ini_line(node: object) -> bool:
    """Whether ``node`` is a line of an INI fold kept for the KRL post alone (the KRL post
    writes its template's INI where the source has none, so a program read back from it holds
    these lines where its source did not)."""
    return (
        isinstance(node, ir.Verbatim)
        and node.native_only
        and node.reason in (STANDARD_STOP, INITMOV)
    )
