"""KRL AST -> :class:`olp.ir.Program`: the statement walk, calls and loops.

See :mod:`olp.frontends.krl` for what is lowered and the decisions behind it. In short: the first
DEF is the program; calls of other DEFs of the module are inlined; FOR loops with constant
bounds are unrolled; straight-line statements are lowered; other control flow is ignored when
lowering it would change nothing, and rejected (naming the construct and its line) otherwise.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable, Sequence
from typing import Any

from olp import ir
from olp.frontends.krl.ast import (
    Assign,
    Binary,
    Block,
    CallStmt,
    DatBlock,
    Decl,
    Expr,
    FastMotion,
    ForLoop,
    IgnoredLine,
    Module,
    MotionStmt,
    Other,
    Routine,
    SignalDecl,
    SourceSet,
    Stmt,
    Unary,
    Var,
    WaitFor,
    WaitSec,
)
from olp.frontends.krl.data import OTHER_REASONS, KrlData
from olp.frontends.krl.motion import Motions
from olp.frontends.krl.state import (
    DEFAULT_VEL_CP,
    Context,
    KrlResult,
    State,
    build_instructions,
)
from olp.frontends.krl.values import (
    Bool,
    Num,
    Signal,
    Unknown,
    Value,
    Variables,
    as_int,
)

__all__ = ["DEFAULT_VEL_CP", "KrlResult", "lower_module"]

MAX_CALL_DEPTH = 32
"""Inlined calls nested deeper than this are rejected (a runaway chain, not a real program)."""
MAX_FOR_ITERATIONS = 1_000_000
"""A FOR loop with more iterations is rejected before unrolling."""
MAX_LOWERED_STATEMENTS = 2_000_000
"""Statements (and loop iterations) lowered in one run, counting every unrolled and inlined copy:
bounds the time and memory a small file can ask for through nested loops."""
_KEPT_OTHERS = frozenset({"RESUME", "ON_ERROR_PROCEED"})
"""Statements that change how the controller runs the program: kept as written."""
_IGNORED_CALLS = {
    "SET_CD_PARAMS": "collision-detection parameters are not modelled",
    "PULSE": "PULSE outputs are not lowered yet",
}


class _Lowering(Motions):
    """Walks statements (inlining calls, unrolling FOR loops), appending IR."""

    def __init__(self, ctx: Context, state: State, variables: Variables) -> None:
        super().__init__(ctx, state, variables)
        self._statements: dict[type, Callable[[Any], None]] = {
            FastMotion: self._fast_motion,
            MotionStmt: self._motion,
            Assign: self._assign,
            CallStmt: self._call,
            WaitSec: self._wait_sec,
            WaitFor: self._wait_for,
            Decl: self._decl,
            SignalDecl: self._signal,
            ForLoop: self._for,
            Block: self._block,
            Other: self._other,
        }

    # ---- driving
    def lower_body(self, body: Sequence[Stmt]) -> None:
        for stmt in body:
            self.lower_statement(stmt)

    def lower_statement(self, stmt: Stmt) -> None:
        if self.returned is not None:
            routine, line = self.returned
            self._ignore(stmt, f"unreachable: {routine} returns at line {line}")
            return
        if self.exiting is not None:
            self._ignore(stmt, f"not reached: the EXIT at line {self.exiting} leaves the loop")
            return
        self.ctx.spend(stmt)
        try:
            self._statements[type(stmt)](stmt)
        except ir.IRError as exc:
            raise self._error(f"invalid value: {exc}", stmt.span) from None

    def changed_anything(self, before: State) -> bool:
        """True if lowering so far made IR or changed the state (a block cannot be skipped)."""
        effects = self.out or self.status_turn or self.returned is not None
        return bool(effects) or self.state != before

    # ---- declarations
    def _decl(self, stmt: Decl) -> None:
        reason = self.data.declare(stmt, self.variables.declare)
        if reason is not None:
            self._ignore(stmt, reason)

    def _signal(self, stmt: SignalDecl) -> None:
        reason = self.data.signal(stmt, self.variables.declare)
        if reason is not None:
            self._ignore(stmt, reason)

    # ---- calls
    def _call(self, stmt: CallStmt) -> None:
        name = stmt.name.upper()
        routine = self.ctx.routines.get(name)
        if name == "BAS":
            self._bas(stmt)
        elif routine is not None and routine.kind == "DEF":
            self._inline(routine, stmt)
        elif routine is not None:
            raise self._error(
                f"{routine.name} is a function (DEFFCT): call it in an expression", stmt.span
            )
        elif name in _IGNORED_CALLS:
            self._keep(stmt, _IGNORED_CALLS[name])
        else:
            args = tuple("" if arg is None else self.sources.snippet(arg.span) for arg in stmt.args)
            self.out.append(ir.Call(name=stmt.name, args=args, span=stmt.span))

    def _inline(self, routine: Routine, stmt: CallStmt) -> None:
        """Lower the body of a DEF of this module in place of its call."""
        name = routine.name.upper()
        if name in self.call_stack or name == self.ctx.main:
            chain = " -> ".join([self.ctx.main, *self.call_stack, name])
            raise self._error(
                f"recursive call of {routine.name} ({chain}): olp inlines calls and cannot "
                "inline recursion",
                stmt.span,
            )
        if len(self.call_stack) >= MAX_CALL_DEPTH:
            raise self._error(f"calls nested deeper than {MAX_CALL_DEPTH} levels", stmt.span)
        if len(stmt.args) > len(routine.params):
            raise self._error(
                f"{routine.name} takes {len(routine.params)} argument(s), found {len(stmt.args)}",
                stmt.span,
            )
        self.ctx.called.add(name)
        bound = self._bind_params(routine, stmt)
        self.call_stack.append(name)
        self.variables.push(bound)
        saved = self.returned, self.exiting, self.loop_depth
        self.returned, self.exiting, self.loop_depth = None, None, 0
        try:
            self.lower_body(routine.body)
        finally:
            finals = self.variables.pop()
            self.call_stack.pop()
            self.returned, self.exiting, self.loop_depth = saved
        self._write_back(routine, stmt, bound, finals)

    def _bind_params(self, routine: Routine, stmt: CallStmt) -> dict[str, Value]:
        """Parameters by value where the arguments are constant; others are unknown inside."""
        bound: dict[str, Value] = {}
        for i, param in enumerate(routine.params):
            arg = stmt.args[i] if i < len(stmt.args) else None
            if arg is None:
                where = stmt.span.location
                bound[param.name.upper()] = Unknown(
                    f"{param.name} is left out in the call at {where}"
                )
                continue
            value = self._value(arg)
            if isinstance(value, Unknown):
                found = self.sources.snippet(arg.span)
                value = Unknown(
                    f"{param.name} is {found!r} in the call at {stmt.span.location}, which is not "
                    f"constant ({value.reason})"
                )
            bound[param.name.upper()] = value
        return bound

    def _write_back(
        self, routine: Routine, stmt: CallStmt, bound: dict[str, Value], finals: dict[str, Value]
    ) -> None:
        """Parameters not marked :IN are passed by reference: the caller's variable changes."""
        for i, param in enumerate(routine.params):
            arg = stmt.args[i] if i < len(stmt.args) else None
            key = param.name.upper()
            changed = finals.get(key) is not bound.get(key)
            if param.direction == "IN" or not changed or not isinstance(arg, Var):
                continue
            if arg.selectors or arg.name.startswith("$"):
                continue
            self.variables.assign(arg.name.upper(), finals[key])

    # ---- waits
    def _wait_sec(self, stmt: WaitSec) -> None:
        seconds = self._number(stmt.seconds, "WAIT SEC")
        if seconds < 0:
            raise self._error(f"WAIT SEC must be >= 0 s, found {seconds:g}", stmt.seconds.span)
        self.out.append(ir.Wait(seconds=seconds, span=stmt.span))

    def _wait_for(self, stmt: WaitFor) -> None:
        found = self._input_condition(stmt.condition)
        if found is None:
            self._ignore(stmt, "only WAIT FOR $IN[n] (or its negation) is lowered yet")
            return
        index, value = found
        self.out.append(ir.WaitInput(index=index, value=value, span=stmt.span))

    def _input_condition(self, expr: Expr) -> tuple[int, bool] | None:
        """``$IN[n]``, ``NOT $IN[n]``, ``$IN[n] == TRUE``, ``$IN[n] <> FALSE`` -> (n, value);
        a one-bit SIGNAL of an input stands for its ``$IN[n]``."""
        if isinstance(expr, Var) and expr.key == "$IN[]":
            return self._single_index(expr, "$IN"), True
        if isinstance(expr, Var) and not expr.selectors:
            signal = self._value(expr)
            if isinstance(signal, Signal) and signal.io == "$IN":
                return signal.index, True
        if isinstance(expr, Unary) and expr.op == "NOT":
            inner = self._input_condition(expr.operand)
            return None if inner is None else (inner[0], not inner[1])
        if isinstance(expr, Binary) and expr.op in ("==", "<>"):
            for var, other in ((expr.left, expr.right), (expr.right, expr.left)):
                inner, value = self._input_condition(var), self._value(other)
                if inner is not None and isinstance(value, Bool):
                    return inner[0], (inner[1] == value.value) == (expr.op == "==")
        return None

    # ---- loops and other control flow
    def _for(self, stmt: ForLoop) -> None:
        """Unrolled when its bounds are constant; otherwise like any other block."""
        parts = [stmt.start, stmt.end] + ([stmt.step] if stmt.step is not None else [])
        values = [self._value(part) for part in parts]
        numbers = [as_int(value) for value in values]
        if any(n is None for n in numbers):
            culprit = next(p for p, n in zip(parts, numbers, strict=True) if n is None)
            why = (
                f"olp unrolls FOR loops with constant integer bounds, and "
                f"{self.sources.snippet(culprit.span)!r} is not one"
            )
            self._probe("FOR", (stmt.body,), stmt.span, why, loop=True)
            return
        start, end = int(numbers[0] or 0), int(numbers[1] or 0)
        step = int(numbers[2]) if len(numbers) > 2 and numbers[2] is not None else 1
        if step == 0:
            raise self._error("FOR ... STEP 0 never ends", stmt.span)
        counts = range(start, end + (1 if step > 0 else -1), step)
        if len(counts) > MAX_FOR_ITERATIONS:
            raise self._error(
                f"FOR at line {stmt.span.line} would run {len(counts):,} times; olp unrolls at "
                f"most {MAX_FOR_ITERATIONS:,} iterations",
                stmt.span,
            )
        if not counts:
            self._ignore(stmt, f"the FOR loop runs 0 times ({start} TO {end} STEP {step})")
        self._unroll(stmt, counts)

    def _unroll(self, stmt: ForLoop, counts: range) -> None:
        counter = stmt.counter.upper()
        self.loop_depth += 1
        try:
            for count in counts:
                self.ctx.spend(stmt)
                self.variables.assign(counter, Num(float(count), True, stmt.span))
                self.lower_body(stmt.body)
                if self.exiting is not None or self.returned is not None:
                    self.exiting = None
                    break
        finally:
            self.loop_depth -= 1
        self.variables.assign(
            counter,
            Unknown(
                f"olp does not track {stmt.counter} after its FOR loop (line {stmt.span.line})"
            ),
        )

    def _block(self, stmt: Block) -> None:
        if stmt.keyword in ("SPLINE", "PTP_SPLINE"):
            raise self._error(
                f"{stmt.keyword} ... ENDSPLINE blocks (lines {stmt.span.line}-"
                f"{stmt.span.end_line}) are not supported yet",
                stmt.span,
                hint="olp lowers single SPTP, SLIN and SCIRC motions; write the segments as those",
            )
        why = (
            "olp lowers straight-line code, calls of the module's DEFs and FOR loops with "
            f"constant bounds, not {stmt.keyword} (its IR has no control flow)"
        )
        loop = stmt.keyword in ("WHILE", "LOOP", "REPEAT")
        self._probe(stmt.keyword, stmt.bodies, stmt.span, why, loop=loop)

    def _probe(
        self,
        keyword: str,
        bodies: Sequence[Sequence[Stmt]],
        span: ir.SourceSpan,
        why: str,
        loop: bool,
    ) -> None:
        """Ignore a block whose bodies change nothing olp lowers, else reject it. Variables the
        bodies assign are unknown afterwards (olp cannot tell whether they ran)."""
        changed: set[str] = set()
        for body in bodies:
            probe = _Lowering(self.ctx, self.state, self.variables.copy())
            probe.track = dataclasses.replace(self.track)
            probe.call_stack = list(self.call_stack)
            probe.loop_depth = self.loop_depth + (1 if loop else 0)
            for inner in body:
                probe.lower_statement(inner)
                left = probe.exiting is not None and not loop
                if probe.changed_anything(self.state) or left:
                    raise self._error(
                        f"{self.sources.snippet(inner.span)!r} inside the {keyword} at line "
                        f"{span.line} cannot be lowered: {why}",
                        inner.span,
                    )
            changed |= probe.variables.changed_since(self.variables)
        for name in sorted(changed):
            reason = f"{name} may be assigned in the {keyword} at line {span.line}, which olp skips"
            self.variables.assign(name, Unknown(reason))
        self._ignore(
            Other(keyword, span),
            f"{keyword} block (lines {span.line}-{span.end_line}) changes nothing olp lowers",
        )

    def _other(self, stmt: Other) -> None:
        routine = self.call_stack[-1] if self.call_stack else "the program"
        if stmt.kind == "RETURN":
            self.returned = (routine, stmt.span.line)
            where = "ends the program" if not self.call_stack else f"returns from {routine}"
            self._ignore(stmt, f"RETURN {where} here")
        elif stmt.kind == "GOTO":
            raise self._error("GOTO is not supported (olp's IR has no control flow)", stmt.span)
        elif stmt.kind == "EXIT" and self.loop_depth > 0:
            self.exiting = stmt.span.line
        elif stmt.kind in _KEPT_OTHERS:
            self._keep(stmt, OTHER_REASONS[stmt.kind])
        else:
            self._ignore(stmt, OTHER_REASONS[stmt.kind])


# ------------------------------------------------------------------------------------------------
# A module


def lower_module(
    module: Module, sources: SourceSet, src: str, dat: KrlData | None, config: KrlData | None
) -> KrlResult:
    """Lower the first DEF of ``module``; the other routines are inlined where called."""
    routines = _routines(module, sources, src)
    if not any(r.kind == "DEF" for r in routines):
        return _functions_only(routines, sources, src, dat, config)
    main = next(r for r in routines if r.kind == "DEF")
    routines = [main, *(r for r in routines if r is not main)]
    table = {r.name.upper(): r for r in routines}
    ctx = Context(sources, table, src, dat, config, MAX_LOWERED_STATEMENTS)
    data = [d for d in (config, dat) if d is not None]
    values: dict[str, Value] = {}
    for datum in data:  # the module's .dat comes last: its names win
        values.update(datum.values)
    variables = Variables(values, ctx.unknown_name)
    variables.push(
        {
            p.name.upper(): Unknown(f"{p.name} is a parameter of the program; olp does not know it")
            for p in main.params
        }
    )
    lowering = _Lowering(ctx, State(), variables)
    ctx.called.add(main.name.upper())
    lowering.lower_body(main.body)
    for other in routines[1:]:
        if other.name.upper() not in ctx.called:
            what = "is never called" if other.kind == "DEF" else "is a function (not lowered)"
            reason = f"{other.kind} {other.name} {what}"
            lowering.ignored.append(IgnoredLine(other.span, sources.snippet(other.span), reason))
    ignored = sorted(lowering.ignored, key=lambda i: (i.span.line, i.span.column))
    for data_list in (dat, config):
        ignored.extend(data_list.ignored if data_list is not None else ())
    program = ir.Program(name=main.name, instructions=build_instructions(lowering.out), source=src)
    return KrlResult(
        program=program,
        ignored=tuple(ignored),
        notes=tuple(lowering.notes),
        status_turn=tuple(lowering.status_turn),
        data_sources=tuple(d.filename for d in data),
    )


def _routines(module: Module, sources: SourceSet, src: str) -> list[Routine]:
    for item in module.items:
        if isinstance(item, DatBlock):
            raise sources.error(
                f"DEFDAT {item.name} is not supported in a .src file: data lists belong in the "
                "module's .dat",
                item.span,
            )
    routines = [item for item in module.items if isinstance(item, Routine)]
    if not routines:
        source = sources.source(src)
        line, column = source.last_position() if source is not None else (1, 1)
        raise sources.error("no DEF ... END routine found", ir.SourceSpan(src, line, column))
    seen: set[str] = set()
    for routine in routines:
        if routine.name.upper() in seen:
            raise sources.error(f"{routine.kind} {routine.name} is defined twice", routine.span)
        seen.add(routine.name.upper())
    return routines


def _functions_only(
    routines: list[Routine],
    sources: SourceSet,
    src: str,
    dat: KrlData | None,
    config: KrlData | None,
) -> KrlResult:
    """A module of functions only (a library of DEFFCTs, called from other modules): there is no
    program to run, so the program is empty and every function is reported as not lowered."""
    names = ", ".join(r.name for r in routines)
    ignored = [
        IgnoredLine(
            r.span,
            sources.snippet(r.span),
            f"the module holds only functions ({names}) and no DEF to run; olp does not lower "
            "functions yet",
        )
        for r in routines
    ]
    for data_list in (dat, config):
        ignored.extend(data_list.ignored if data_list is not None else ())
    name = os.path.splitext(os.path.basename(src))[0] or routines[0].name
    data = [d for d in (config, dat) if d is not None]
    return KrlResult(
        program=ir.Program(name=name, instructions=(), source=src),
        ignored=tuple(ignored),
        data_sources=tuple(d.filename for d in data),
    )
