"""Interrupts and path triggers: ``INTERRUPT DECL``, ``INTERRUPT ON/OFF/ENABLE/DISABLE`` and
``TRIGGER WHEN DISTANCE/PATH`` lowered to :class:`olp.ir.InterruptDecl`,
:class:`olp.ir.InterruptSwitch` and :class:`olp.ir.PathTrigger` (see :mod:`olp.ir_flow` for
the KRL they model and where it is described).

What the IR cannot hold (a priority, a distance or a delay that is not a constant, a handler
that is not a call, ``DISTANCE`` other than 0 or 1) is kept as :class:`olp.ir.Verbatim`: the
KUKA post writes it back, other posts stop on its line.

The pendant's standard INI pair ``GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )``
/ ``INTERRUPT ON 3`` stays out of the program: the KUKA post writes that pair in the INI fold of
every program it makes, so keeping it would declare interrupt 3 twice. Inside the source's own
INI fold it is kept for the KRL post alone (:mod:`olp.frontends.krl.native`), which then writes
the source's INI instead of its own.
"""

from __future__ import annotations

from olp import ir
from olp.errors import ParseError
from olp.frontends.krl.ast import (
    Assign,
    Binary,
    Bool,
    CallStmt,
    Expr,
    InterruptCtl,
    InterruptDecl,
    Num,
    Trigger,
    Var,
)
from olp.frontends.krl.flow import to_expr
from olp.frontends.krl.state import Core
from olp.frontends.krl.values import Unknown

STANDARD_STOP = (
    "the pendant's standard stop-message interrupt: the KUKA post writes it where the KRL "
    "source had it (the other posts' controllers handle stop messages themselves)"
)
MM, MS = 1e-3, 1e-3


class Events(Core):
    """Lowering of interrupts and triggers (a mixin of the module's lowering)."""

    stop_interrupt_declared: bool = False

    def _expr(self, expr: Expr) -> ir.Expr:
        converted = to_expr(expr, self._input_of)
        assert converted is not None
        return converted

    def _interrupt_decl(self, stmt: InterruptDecl) -> None:
        if is_standard_stop(stmt):
            self.stop_interrupt_declared = True
            self._ignore(stmt, STANDARD_STOP)
            return
        if not isinstance(stmt.action, CallStmt):
            self._keep(stmt, "an interrupt's handler must be a subprogram call")
            return
        try:
            priority = self._integer(stmt.priority, "the interrupt number", 1)
        except ParseError as exc:
            self._keep(stmt, f"the interrupt number is not a constant ({exc.message})")
            return
        decl = ir.InterruptDecl(
            priority=priority,
            condition=self._expr(stmt.condition),
            handler=self._handler(stmt.action, "interrupt"),
            exported=stmt.exported,
            span=stmt.span,
        )
        self.out.append(decl)

    def _interrupt_ctl(self, stmt: InterruptCtl) -> None:
        standard_on = stmt.action == "ON" and _is_number(stmt.priority, 3)
        if standard_on and self.stop_interrupt_declared:
            self.stop_interrupt_declared = False
            self._ignore(stmt, STANDARD_STOP)
            return
        priority = None
        if stmt.priority is not None:
            try:
                priority = self._integer(stmt.priority, "the interrupt number", 1)
            except ParseError as exc:
                self._keep(stmt, f"the interrupt number is not a constant ({exc.message})")
                return
        switch = ir.InterruptSwitch(action=stmt.action.lower(), priority=priority, span=stmt.span)
        self.out.append(switch)

    def _trigger(self, stmt: Trigger) -> None:
        try:
            trigger = self._path_trigger(stmt)
        except ParseError as exc:
            self._keep(stmt, exc.message)
            return
        if trigger is None:
            return
        self.out.append(trigger)
        action = stmt.action
        if isinstance(action, Assign) and not action.target.name.startswith("$"):
            reason = f"set by the TRIGGER at line {stmt.span.line} while the next motion runs"
            self.variables.assign(action.target.name.upper(), Unknown(reason))

    def _path_trigger(self, stmt: Trigger) -> ir.PathTrigger | None:
        delay = self._number(stmt.delay, "a TRIGGER's DELAY (ms)") * MS
        if isinstance(stmt.action, CallStmt):
            action: ir.Assign | ir.FunctionCall = self._handler(stmt.action, "TRIGGER")
            priority = None
            if stmt.priority is not None:
                priority = int(self._number(stmt.priority, "a TRIGGER's PRIO"))
        elif stmt.priority is not None:
            self._keep(stmt, "PRIO after an assignment: KRL gives PRIO to subprogram calls only")
            return None
        else:
            action, priority = self._assignment(stmt.action), None
        if stmt.mode == "PATH":
            path = self._number(stmt.position, "a TRIGGER's PATH (mm)") * MM
            return ir.PathTrigger(
                action=action,
                path=path,
                from_start=stmt.onstart,
                delay=delay,
                priority=priority,
                span=stmt.span,
            )
        distance = self._number(stmt.position, "a TRIGGER's DISTANCE")
        if distance not in (0.0, 1.0) or stmt.onstart:
            self._keep(stmt, "DISTANCE is 0 (start point) or 1 (end point), without ONSTART")
            return None
        at = "start" if distance == 0.0 else "end"
        return ir.PathTrigger(action=action, at=at, delay=delay, priority=priority, span=stmt.span)

    def _handler(self, call: CallStmt, what: str) -> ir.FunctionCall:
        self.ctx.handlers.setdefault(call.name.upper(), f"{what} at line {call.span.line}")
        args = tuple(None if a is None else self._expr(a) for a in call.args)
        return ir.FunctionCall(name=call.name, args=args, span=call.span)


def is_standard_stop(stmt: InterruptDecl) -> bool:
    action, cond = stmt.action, stmt.condition
    handler = isinstance(action, CallStmt) and action.name.upper() == "IR_STOPM" and not action.args
    condition = (
        isinstance(cond, Binary)
        and cond.op == "=="
        and isinstance(cond.left, Var)
        and cond.left.key == "$STOPMESS"
        and isinstance(cond.right, Bool)
        and cond.right.value is True
    )
    return stmt.exported and handler and condition and _is_number(stmt.priority, 3)


def _is_number(expr: object, value: int) -> bool:
    return isinstance(expr, Num) and expr.value == value
