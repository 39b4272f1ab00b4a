"""KRL AST -> :class:`olp.ir.Program`: the statement walk, calls and loops.

See :mod:`olp.frontends.krl` for what is lowered and the decisions behind it. In short: the first
DEF is the program; calls of other DEFs of the module are lowered at each call and kept as
calls of routines (:mod:`olp.frontends.krl.routines`); FOR loops with constant
bounds are unrolled (one that only sets motion settings is kept as written too, for the KRL
post); straight-line statements are lowered; other control flow is ignored when
lowering it would change nothing, and rejected (naming the construct and its line) otherwise.
"""

from __future__ import annotations

import dataclasses
import os
import re
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

from olp import ir
from olp.errors import ParseError
from olp.frontends.krl.ast import (
    Assign,
    Binary,
    Block,
    CallStmt,
    CommentStmt,
    DatBlock,
    Decl,
    Expr,
    FastMotion,
    ForLoop,
    FuncCall,
    IgnoredLine,
    InterruptCtl,
    InterruptDecl,
    LinRows,
    Module,
    MotionStmt,
    Other,
    Routine,
    SignalDecl,
    SourceSet,
    Stmt,
    Trigger,
    Unary,
    Var,
    WaitFor,
    WaitSec,
)
from olp.frontends.krl.data import OTHER_REASONS, KrlData, visible_globals
from olp.frontends.krl.events import Events
from olp.frontends.krl.fast import materialise
from olp.frontends.krl.flow import (
    PastFor,
    assigned_names,
    is_straight,
    joined,
    jump_targets,
    past_for,
    reads_name,
    reads_value,
    statements,
    to_expr,
)
from olp.frontends.krl.module_data import with_module_data
from olp.frontends.krl.motion import Motions, RuntimeStart
from olp.frontends.krl.native import native_reason
from olp.frontends.krl.routines import PendingCall, assemble, moves, typed_params
from olp.frontends.krl.rows import build_instructions
from olp.frontends.krl.state import (
    DEFAULT_VEL_CP,
    SPEED_PARTS,
    Context,
    Held,
    KrlResult,
    Pending,
    PendingRows,
    State,
    code_of,
    is_here,
)
from olp.frontends.krl.values import (
    Bool,
    Counter,
    Num,
    Signal,
    Unknown,
    Value,
    Variables,
    as_int,
)
from olp.frontends.krl.written import FIELD_KEYS, PART_KEYS, named_keys, set_keys, written_keys
from olp.ir_flow import leaves

__all__ = ["DEFAULT_VEL_CP", "KrlResult", "lower_module"]

MAX_CALL_DEPTH = 32
"""Inlined calls nested deeper than this are rejected (a runaway chain, not a real program)."""
MAX_FOR_ITERATIONS = 1_000_000
"""A FOR loop with more iterations is rejected before unrolling."""
MAX_LOWERED_STATEMENTS = 2_000_000
"""Statements (and loop iterations) lowered in one run, counting every unrolled and inlined copy:
bounds the time and memory a small file can ask for through nested loops."""
_KEPT_OTHERS = frozenset({"RESUME", "ON_ERROR_PROCEED", "HALT", "BRAKE", "CONTINUE"})
"""Statements that change how the controller runs the program: kept as written."""
_IGNORED_CALLS = {
    "SET_CD_PARAMS": "collision-detection parameters are not modelled",
    "PULSE": "PULSE outputs are not lowered yet",
}


@dataclass
class RoutineJumps:
    """The labels of one routine activation and what jumps to them: ``labels`` name -> line,
    ``targets`` name -> the lines of its GOTOs, ``assigned`` the variables the routine assigns
    anywhere; while lowering: the state each label was reached with (``seen``), the paths
    of GOTOs that jump forward to a label not lowered yet (``pending``) and the states of the
    GOTOs that jump back (``back_states``); ``first_pass``: those of a first lowering of the
    routine, so that at a label the settings a later jump back brings are known.

    A first pass is the honest price of jumps back: the label needs the state at a GOTO that
    is lowered after it. Settings that differ there are ambiguous after the label."""

    labels: dict[str, int] = field(default_factory=dict)
    targets: dict[str, list[int]] = field(default_factory=dict)
    assigned: set[str] = field(default_factory=set)
    seen: dict[str, State] = field(default_factory=dict)
    pending: dict[str, list[Any]] = field(default_factory=dict)
    back_states: dict[str, list[State]] = field(default_factory=dict)
    first_pass: dict[str, list[State]] = field(default_factory=dict)

    @property
    def jumps_back(self) -> bool:
        return any(
            line > self.labels.get(name, line)
            for name, lines in self.targets.items()
            for line in lines
        )

    @classmethod
    def of(cls, body: Sequence[Stmt]) -> RoutineJumps:
        labels = {
            (s.name or "").upper(): s.span.line
            for s in statements(body)
            if isinstance(s, Other) and s.kind == "label"
        }
        return cls(labels, jump_targets(body), assigned_names(body))


class _Lowering(Motions, Events):
    """Walks statements (inlining calls, unrolling constant FOR loops over straight-line code,
    lowering blocks to :mod:`olp.ir_flow` blocks), appending IR.

    ``ambiguous``: motion settings (fields of :class:`State`) that differ between the paths
    reaching this point, and why; a motion before they are set again is an error.
    """

    def __init__(self, ctx: Context, state: State, variables: Variables) -> None:
        self.ambiguous: dict[str, str] = {}
        self.unset: set[str] = set()  # tool/frame not set yet on some path (for a note)
        self._state = state
        super().__init__(ctx, state, variables)
        self.loops: list[str] = []  # the enclosing loops, innermost last: "block" or "unrolled"
        self.in_block = 0
        self.jumped: int | None = None  # line of a GOTO after which nothing is reached
        self.routine = RoutineJumps()
        self.defining: str | None = None  # a routine lowered on its own (no call reaches it)
        self.generic = False  # lowering a called routine with its parameters unknown
        self.return_ends: list[_Lowering] = []  # the states at the RETURNs in blocks of a call
        self.past: set[str] = set()  # counters of unrolled FOR loops (see flow.PastFor)
        # statements that set motion settings (absorbed into the motions) since the last motion
        self.unwritten: list[Stmt] = []
        # each one's output list, position and the setting keys it set (olp.frontends.krl.written)
        self.unwritten_at: list[tuple[list[Any], int, frozenset[str]]] = []
        # setting keys whose value on this path the output may not have put on the controller,
        # with no statement left to keep for them (see olp.frontends.krl.written)
        self.lost: set[str] = set()
        # absorbed statements a motion passed that wrote none of what they set (``$VEL.CP``
        # before a PTP): still keepable where they stand, for what runs with the controller's
        # settings (each: the statement, its output list, position and keys)
        self.deferred: list[tuple[Stmt, tuple[list[Any], int, frozenset[str]]]] = []
        self.reports = 0  # lines reported as left out by this lowering (once each or not)
        # FOR loops kept as written since the last motion: output list, first and end position
        self.settings_loops: list[tuple[list[Any], int, int]] = []
        self.live_outs: list[list[Any]] = []  # the output lists this lowering is nested in
        self.folds: list[str] = []  # the titles of the source's folds open here, innermost last
        self._blocks: dict[str, Callable[[Block], None]] = {
            "IF": self._if,
            "SWITCH": self._switch,
            "WHILE": self._while,
            "REPEAT": self._repeat,
            "LOOP": self._loop,
        }
        self._statements: dict[type, Callable[[Any], None]] = {
            FastMotion: self._fast_motion,
            LinRows: self._lin_rows,
            MotionStmt: self._motion_or_here,
            Assign: self._assign,
            CallStmt: self._call,
            WaitSec: self._wait_sec,
            WaitFor: self._wait_for,
            Decl: self._decl,
            SignalDecl: self._signal,
            ForLoop: self._for,
            Block: self._block,
            InterruptDecl: self._interrupt_decl,
            InterruptCtl: self._interrupt_ctl,
            Trigger: self._trigger,
            Other: self._other,
        }

    @property
    def state(self) -> State:
        return self._state

    @state.setter
    def state(self, new: State) -> None:
        """Setting a motion setting again ends its ambiguity (a field assigned anew is a new
        object, so identity tells which ones a statement set). Not a part of the speed held
        apart (:data:`~olp.frontends.krl.state.SPEED_PARTS`): the setter of that part settles
        it, as one ``speed`` object cannot tell which of its parts changed."""
        if self.ambiguous:
            old = self._state
            changed = [n for n in _STATE_FIELDS if getattr(new, n) is not getattr(old, n)]
            for name in changed:
                self.ambiguous.pop(name, None)
        if self.unset:
            old = self._state
            self.unset -= {n for n in self.unset if getattr(new, n) is not getattr(old, n)}
        self._state = new

    # ---- driving
    def lower_body(self, body: Sequence[Stmt]) -> None:
        for stmt in body:
            self.lower_statement(stmt)

    def lower_statement(self, stmt: Stmt) -> None:
        if isinstance(stmt, CommentStmt):  # in place, reached or not: it says nothing to run
            self._comment(stmt)
            return
        if isinstance(stmt, LinRows):  # checks and spends per row itself
            start = len(self.out)
            self._lin_rows(stmt)
            self._moved(self.out[start:])
            return
        if self.returned is not None:
            routine, line = self.returned
            self._ignore(stmt, f"unreachable: {routine} returns at line {line}")
            return
        if self.exiting is not None:
            self._ignore(stmt, f"not reached: the EXIT at line {self.exiting} leaves the loop")
            return
        if self.jumped is not None and not (isinstance(stmt, Other) and stmt.kind == "label"):
            self._keep_dead(stmt, self.jumped)
            return
        self.check_declared(stmt)
        if self.ambiguous and isinstance(stmt, MotionStmt | FastMotion):
            motion = materialise(stmt) if isinstance(stmt, FastMotion) else stmt
            unsettled = self._unsettled(motion)
            if unsettled and all(isinstance(why, Held) for why in unsettled.values()):
                self._check_written_for_controller(motion, unsettled)
            if unsettled and self._controller_settings_motion(motion, unsettled):
                self.ctx.spend(stmt)
                return
            if unsettled:
                names = ", ".join(sorted(_SETTING_NAMES[n] for n in unsettled))
                reasons = "; ".join(sorted(set(unsettled.values())))
                raise self._error(
                    f"olp cannot tell which motion settings this motion runs with ({names}): "
                    f"{reasons}",
                    stmt.span,
                    hint="set them again before the motion (the pendant's inline forms do)",
                )
        self.ctx.spend(stmt)
        if self._kept_native(stmt):
            return
        past = self._past_counters(stmt)
        start, reported = len(self.out), len(self.ignored)
        before = self.state, dict(self.ambiguous)
        try:
            self._statements[type(stmt)](stmt)
        except ir.IRError as exc:
            raise self._error(f"invalid value: {exc}", stmt.span) from None
        if past:
            self._no_read_past_for(past, start, stmt)
        self._track_settings(stmt, self.out[start:], len(self.ignored) > reported, before)

    def _check_written_for_controller(self, motion: MotionStmt, unsettled: dict[str, str]) -> None:
        """A motion with the controller's settings (the output writes none before it) also
        runs with the ones olp knows: each must be on the controller. One olp absorbed and
        wrote only where a motion used it, which no motion of this kind has since
        (``$ORI_TYPE = #CONSTANT`` before a PTP: the output writes it before a CIRC only), is
        not: an error, not a motion run with another value. (An approximation distance is not
        one: where the output has not put the program's on the controller, the motion is written
        as an exact stop, :meth:`_controller_settings_motion`.)"""
        joint = motion.keyword.upper().startswith(("PTP", "SPTP"))
        names = []
        # (the parts of the speed held apart are the speed's and the axis settings' keys)
        used = self._used_settings(motion) - set(unsettled) - set(PART_KEYS) - {"cdis_mm"}
        for name in sorted(used):
            keys = FIELD_KEYS[name]
            if name == "speed":
                keys = frozenset({"speed.joint" if joint else "speed.linear"})
            if keys & self.unkeepable():
                names.append(_SETTING_NAMES[name])
        if names:
            listed = ", ".join(names)
            reasons = "; ".join(sorted(set(unsettled.values())))
            raise self._error(
                f"this motion runs with the settings the controller holds ({reasons}), and "
                f"with {listed} as the program set it, which the output has not written "
                "since (olp writes a setting only before a motion that uses it): the "
                "controller would not hold it here",
                motion.span,
                hint=f"set {listed} again before the motion",
            )

    def _comment(self, stmt: CommentStmt) -> None:
        """A source comment, as :class:`olp.ir.Comment` (a fold line as such); the folds open
        here are tracked, for the INI fold (:mod:`olp.frontends.krl.native`)."""
        comment = ir.Comment(text=stmt.text, span=stmt.span, fold=stmt.fold, from_source=True)
        if stmt.fold == "open":
            self.folds.append(comment.title.upper())
        elif stmt.fold == "close" and self.folds:
            self.folds.pop()
        self.out.append(comment)

    def _kept_native(self, stmt: Stmt) -> bool:
        """Keep a statement that matters only on a KUKA controller as a native-only
        :class:`olp.ir.Verbatim` (:mod:`olp.frontends.krl.native`); False for any other."""
        reason = native_reason(stmt, self.motion_count == 0, self.stop_interrupt_declared)
        if reason is None:
            return False
        # the standard declaration: the INTERRUPT ON 3 right after it is its own, kept too
        self.stop_interrupt_declared = isinstance(stmt, InterruptDecl)
        self._keep(stmt, reason)
        kept = self.out[-1]
        assert isinstance(kept, ir.Verbatim)
        self.out[-1] = dataclasses.replace(kept, native_only=True)
        return True

    def _past_counters(self, stmt: Stmt) -> dict[str, PastFor]:
        """The counters of unrolled FOR loops that hold their value after the loop here
        (a block's and a FOR's statements are checked one by one as they are lowered)."""
        if not self.past or isinstance(stmt, Block | ForLoop):
            return {}
        values = {name: self.variables.lookup(name) for name in self.past}
        return {name: v for name, v in values.items() if isinstance(v, PastFor)}

    def _no_read_past_for(self, past: dict[str, PastFor], start: int, stmt: Stmt) -> None:
        nodes = [n.call if isinstance(n, PendingCall) else n for n in self.out[start:]]
        for key, value in sorted(past.items()):
            if reads_value(nodes, key):
                name = value.name or key
                raise self._error(
                    f"{name} is read after the FOR loop at line {value.line}, which olp writes "
                    "out pass by pass: the value KRL leaves in the counter after the loop is not "
                    "written (olp has not verified it against a KUKA manual), so the controller "
                    "would read another",
                    stmt.span,
                    hint=f"use another variable for what the loop leaves, or give {name} a "
                    "value before reading it",
                )

    def _track_settings(
        self, stmt: Stmt, new: Sequence[Any], reported: bool, before: tuple[State, dict[str, str]]
    ) -> None:
        """Note an assignment or call that left nothing in the program and was not reported:
        one olp absorbed into the motion settings (``$BASE``, ``$VEL.CP``, ``BAS``,
        ``PDAT_ACT``, ...). The posts write settings before the motions that run with them, so
        one that no motion follows is not in the output (:meth:`report_unwritten_settings`).

        Also which setting keys are on the controller on this path (``lost``, :mod:`olp.
        frontends.krl.written`). A block's paths and an unrolled FOR's statements were tracked
        one by one (the block's join makes the union: :meth:`_join`); so was an inlined call's
        body, whose motions already wrote what they write."""
        if isinstance(stmt, Block | ForLoop):
            return
        inlined = any(isinstance(n, PendingCall) for n in new)
        if moves(new) or any(isinstance(n, Pending | PendingRows) for n in leaves(new)):
            self._moved(() if inlined else new)
            self._settings_loops_modelled()
        elif isinstance(stmt, Assign | CallStmt) and not new and not reported:
            keys = set_keys(*before, self.state, self.ambiguous) | named_keys(stmt)
            self.lost -= keys
            self.unwritten.append(stmt)
            self.unwritten_at.append((self.out, len(self.out), frozenset(keys)))
        elif not inlined:
            # written as it stands (a BAS with run-time values, ...): the controller holds what
            # it sets; set and left out (with a warning): that part never reaches it
            keys = set_keys(*before, self.state, self.ambiguous)
            self.lost = self.lost - keys if new else self.lost | keys

    def _moved(self, new: Sequence[Any]) -> None:
        """A motion ran (``new``: the motions, empty for an inlined call's): the settings it
        does not write whose statements wait (``unwritten``) are lost from here on, except
        those of a statement that sets nothing the motion writes: it can still be kept where
        it stands (``deferred``: no motion since relies on the output's writing what it sets),
        until a motion writes some of that."""
        wrote = written_keys(new, self.state)
        self.deferred = [d for d in self.deferred if not d[1][2] & wrote]
        for stmt, position in zip(self.unwritten, self.unwritten_at, strict=True):
            if position[2] & wrote:
                self.lost |= position[2] - wrote
            elif position[2]:  # (one that sets no setting, PDAT_ACT = ..., goes as before)
                self.deferred.append((stmt, position))
        self.lost -= wrote
        self.unwritten.clear()
        self.unwritten_at.clear()

    def _ignore(self, stmt: Stmt | Assign, reason: str) -> None:
        """Report ``stmt`` as left out (once per line and reason), and count the report even
        where it was made before (a loop lowered again: :meth:`_unroll_settings`)."""
        self.reports += 1
        super()._ignore(stmt, reason)

    def _settings_loops_modelled(self) -> None:
        """A motion olp models runs with what the FOR loops kept since the last motion set
        (:meth:`_keep_settings_loop`): their lines become ``modelled`` where they still stand
        in an output list being built (one in a block already lowered keeps its warning)."""
        live = [*self.live_outs, self.out]
        for out, first, last in self.settings_loops:
            if any(out is candidate for candidate in live):
                for k in range(first, last):
                    if isinstance(out[k], ir.Verbatim):
                        out[k] = dataclasses.replace(out[k], modelled=True)
        self.settings_loops.clear()

    def _keep_unwritten(
        self,
        reason: str,
        strict: bool = True,
        only: list[Any] | None = None,
        deferred: bool | None = None,
    ) -> None:
        """What comes next runs with the controller's settings: the FOR loops kept since the
        last motion keep their lines' warning for other posts (see
        :meth:`_keep_settings_loop`); the statements olp absorbed are kept as written."""
        self.settings_loops.clear()
        super()._keep_unwritten(reason, strict, only, deferred)

    def report_unwritten_settings(self) -> None:
        """The settings no motion of the program follows (a routine that sets ``$BASE`` and
        ``$TOOL`` for its callers, written as a program of its own): kept as written where
        they stand, for the KRL post (they matter to what runs after the module: its caller);
        one inside a block olp lowered already is left out with a warning."""
        self._keep_unwritten(
            "sets motion settings after the module's last motion: kept as written for what "
            "runs after it (a caller)",
            strict=False,
        )
        for stmt in self.unwritten:
            self._ignore(
                stmt,
                "sets motion settings no motion of the program runs with: olp writes settings "
                "only before the motions that use them, so this one is not in the output",
            )
        self._moved(())

    # ---- motions to where the robot is
    def _motion_or_here(self, stmt: MotionStmt) -> None:
        """``PTP $POS_ACT`` / ``PTP $AXIS_ACT`` (the block coincidence run of a program start)
        move to where the robot already is: nothing to check, kept as written. So does a motion
        to a variable that was given ``$POS_ACT`` with no motion since (``pAct = $POS_ACT`` /
        ``SPTP pAct WITH $VEL_AXIS[1] = 10, ...``): a WITH clause only sets that motion's own
        speeds and accelerations.

        Not when settings olp absorbed wait for a motion (the pendant's fold ``PTP $POS_ACT``:
        ``PDAT_ACT = ...``, ``FDAT_ACT = ...``, ``BAS(#PTP_PARAMS, ...)``): the posts write
        settings only before the motions olp models, so a kept line would run without them.
        Then it is a motion to a run-time target (:class:`~olp.ir.RuntimeMove`), which the posts
        write after the settings in effect."""
        target = stmt.targets[-1] if stmt.targets else None
        simple = stmt.keyword in ("PTP", "SPTP", "LIN", "SLIN") and not stmt.with_clause
        if simple and isinstance(target, Var) and is_here(target) and not self.unwritten:
            self._keep(stmt, f"moves to where the robot already is ({target.name}): no motion")
            return
        held = self._holds_here(target)
        if stmt.keyword in ("PTP", "SPTP", "LIN", "SLIN") and held is not None:
            assert isinstance(target, Var)
            reason = f"moves to where the robot already is ({target.name} = {held}): no motion"
            self._keep(stmt, reason)
            return
        self._motion(stmt)

    def _holds_here(self, target: object) -> str | None:
        """The controller variable (``$POS_ACT``) a plain variable was given, if no motion was
        lowered since, else None."""
        if not isinstance(target, Var) or target.selectors:
            return None
        found = self.here_vars.get(target.name.upper())
        if found is None or found[1] != self.motion_count:
            return None
        return found[0]

    # ---- declarations
    def _decl(self, stmt: Decl) -> None:
        """A declaration in a routine: its values are tracked, and it is kept in the program
        (:class:`olp.ir.Declare`, one per name)."""
        self.data.declare(stmt, self.variables.declare, local=True)
        for item in stmt.items:
            self.ctx.declared_types[item.name.upper()] = stmt.type_name.upper()
            dims = tuple(to_expr(d, self._input_of) for d in item.dims or ())
            value = None if item.value is None else self._expr(item.value)
            self.out.append(
                ir.Declare(
                    name=item.name, type_name=stmt.type_name, dims=dims, value=value, span=stmt.span
                )
            )

    def _signal(self, stmt: SignalDecl) -> None:
        """A SIGNAL declared in a routine: the KRL post writes the program's uses of it by name
        (``GRIP = TRUE``), so it writes the declaration as written too (it was absorbed without
        a trace, and the output used a name it never declared); other posts use the I/O by
        number and leave it out with a warning."""
        reason = self.data.signal(stmt, self.variables.declare)
        if reason is not None:
            self._ignore(stmt, reason)
        else:
            self._keep_krl_only(stmt, "a SIGNAL declaration: other posts name the I/O by number")

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
        elif self.ctx.keeps_settings(stmt.name):
            args = tuple("" if arg is None else self.sources.snippet(arg.span) for arg in stmt.args)
            self.out.append(ir.Call(name=stmt.name, args=args, span=stmt.span))
        else:
            self._unread_call(stmt)

    def _entered(self, held: str, start: str) -> None:
        """Start a routine from what olp knows where an unknown caller enters it: what it
        knows after a call of a routine it did not read (:meth:`_unread_call`): every motion
        setting held by the controller (``held``: why), the robot where olp does not know
        (``start``: why)."""
        why = Held(held)
        for name in _STATE_FIELDS:
            self.ambiguous[name] = why
        self.track.lose(RuntimeStart(start))

    def _unread_call(self, stmt: CallStmt) -> None:
        """A call of a routine olp did not read (another module's, an ``EXT`` one): it may set
        any motion setting (a ``MoveSettings(nBase, nTool)``) and may move the robot. So the
        settings olp absorbed since the last motion are kept as written before it (the routine
        may move with them: :meth:`_keep_unwritten`); every setting is then held by the
        controller (:class:`~olp.frontends.krl.state.Held`: a motion that runs with one before
        the program sets it again runs with the controller's, and the output writes none of
        olp's before it, :meth:`_controller_settings_motion`); the robot is where olp does not
        know (a _REL motion after it is a run-time one), and the next motion's path is not
        checked (:attr:`olp.ir.Call.may_move`)."""
        self.motion_count += 1
        line = stmt.span.line
        self._keep_unwritten(
            f"sets motion settings before the call of {stmt.name} (line {line}), a routine olp "
            "did not read, which may move the robot with them"
        )
        why = Held(f"the call of {stmt.name} at line {line} runs a routine olp did not read")
        for name in _STATE_FIELDS:
            self.ambiguous[name] = why
        self._hold(self.call_holds(), why)
        self.lost.clear()  # the controller holds what the routine left, on every path
        self.track.lose(RuntimeStart(f"{why}, which may move the robot"))
        args = tuple("" if arg is None else self.sources.snippet(arg.span) for arg in stmt.args)
        self.out.append(ir.Call(name=stmt.name, args=args, may_move=True, span=stmt.span))

    def _inline(self, routine: Routine, stmt: CallStmt) -> None:
        """Lower the body of a DEF of this module in place of its call."""
        name = routine.name.upper()
        first = self.defining or self.ctx.main
        if name in self.call_stack or name == first.upper():
            chain = " -> ".join([first, *self.call_stack, name])
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
        saved = self.returned, self.exiting, self.loop_depth, self.loops, self.routine, self.jumped
        saved_ends, self.return_ends = self.return_ends, []
        self.returned, self.exiting, self.loop_depth, self.loops = None, None, 0, []
        self.routine, self.jumped = RoutineJumps.of(routine.body), None
        caller_out, self.out = self.out, []
        self.live_outs.append(caller_out)
        try:
            self.first_pass(routine.body)
            self.lower_body(routine.body)
            self._join_returns(routine)
        finally:
            lowered, self.out = self.out, caller_out
            self.live_outs.pop()
            finals = self.variables.pop()
            self.call_stack.pop()
            self.returned, self.exiting, self.loop_depth, self.loops, self.routine = saved[:5]
            self.jumped, self.return_ends = saved[5], saved_ends
        self._write_back(routine, stmt, bound, finals)
        args = tuple(to_expr(arg, self._input_of) for arg in stmt.args)
        call = ir.RoutineCall(name=routine.name, args=args, span=stmt.span)
        body = build_instructions(lowered)
        generic = self._generic_body(routine, stmt) if self._reads_params(routine) else None
        pending = PendingCall(call=call, body=body, generic=generic, span=stmt.span)
        self.out.append(pending)  # type: ignore[arg-type]  # made a call by routines.assemble

    def _join_returns(self, routine: Routine) -> None:
        """After a called routine's body: the caller goes on from its end or from any RETURN
        in a block, so what those paths agree on is known there, and the rest is not (a
        motion setting that differs is an error at the caller's next motion)."""
        if not self.return_ends:
            return
        ends = [*([] if self.jumped is not None else [self]), *self.return_ends]
        where = f"the RETURNs of {routine.name}"
        self._merge_states(ends, where)
        self._join_variables(ends, where)

    def _reads_params(self, routine: Routine) -> bool:
        """Whether a statement of ``routine`` other than a motion or a declaration names one of
        its parameters (then its lowering with the parameters unknown may be the one text of
        calls that differ; otherwise that lowering differs as the calls do and is not made:
        it costs a second lowering of the body at each call). By the source text, so a name
        in a comment counts too (it only costs time)."""
        key = routine.name.upper()
        found = self.ctx.reads_params.get(key)
        if found is None:
            words = [re.compile(rf"\b{re.escape(p.name)}\b", re.IGNORECASE) for p in routine.params]
            skip = (MotionStmt, FastMotion, LinRows, Decl)
            texts = (
                self.sources.snippet(s.span)
                for s in statements(routine.body)
                if not isinstance(s, skip)
            )
            found = any(w.search(text) for text in texts for w in words)
            self.ctx.reads_params[key] = found
        return found

    def _generic_body(self, routine: Routine, stmt: CallStmt) -> tuple[ir.Node, ...] | None:
        """The routine lowered at this call with its parameters unknown (what its text says
        without this call's values), or None where olp cannot lower it so: one routine text
        for calls whose values differ (:mod:`olp.frontends.krl.routines`)."""
        if self.generic:
            return None
        probe = self._snapshot()
        probe.generic = True
        try:
            probe._inline(routine, stmt)
        except ParseError:
            return None
        pending = probe.out[-1]
        assert isinstance(pending, PendingCall)
        return pending.body

    def _bind_params(self, routine: Routine, stmt: CallStmt) -> dict[str, Value]:
        """Parameters by value where the arguments are constant; others are unknown inside."""
        bound: dict[str, Value] = {}
        for i, param in enumerate(routine.params):
            arg = stmt.args[i] if i < len(stmt.args) else None
            if self.generic:
                bound[param.name.upper()] = Unknown(
                    f"{param.name} is a parameter of {routine.name}"
                )
                continue
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
                    f"constant ({value.reason})",
                    missing=value.missing,
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
            condition = self._expr(stmt.condition)
            self.out.append(ir.WaitUntil(condition=condition, span=stmt.span))
            return
        index, value, signal = found
        self.out.append(ir.WaitInput(index=index, value=value, signal=signal, span=stmt.span))

    def _input_condition(self, expr: Expr) -> tuple[int, bool, str | None] | None:
        """``$IN[n]``, ``NOT $IN[n]``, ``$IN[n] == TRUE``, ``$IN[n] <> FALSE`` -> (n, value,
        None); a one-bit SIGNAL of an input stands for its ``$IN[n]``, with its name where
        the written program can use it (:meth:`_signal_name`)."""
        if isinstance(expr, Var) and expr.key == "$IN[]":
            return self._single_index(expr, "$IN"), True, None
        if isinstance(expr, Var) and not expr.selectors:
            signal = self._value(expr)
            if isinstance(signal, Signal) and signal.io == "$IN":
                return signal.index, True, self._signal_name(expr, signal)
        if isinstance(expr, Unary) and expr.op == "NOT":
            inner = self._input_condition(expr.operand)
            return None if inner is None else (inner[0], not inner[1], inner[2])
        if isinstance(expr, Binary) and expr.op in ("==", "<>"):
            for var, other in ((expr.left, expr.right), (expr.right, expr.left)):
                inner, value = self._input_condition(var), self._value(other)
                if inner is not None and isinstance(value, Bool):
                    return inner[0], (inner[1] == value.value) == (expr.op == "=="), inner[2]
        return None

    # ---- loops and other control flow
    def _for(self, stmt: ForLoop) -> None:
        """Unrolled when its bounds are constant and its body is straight-line code; otherwise
        lowered as an :class:`olp.ir.For` block (its counter unknown inside)."""
        self.motion_count += 1  # the loop may move the robot
        parts = [stmt.start, stmt.end] + ([stmt.step] if stmt.step is not None else [])
        numbers = [as_int(self._value(part)) for part in parts]
        if any(n is None for n in numbers) or not is_straight(stmt.body):
            self._for_block(stmt)
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
        elif self._lowers_as_block(stmt, counts[0]):
            self._for_block(stmt)
            return
        elif self._sets_settings_only(stmt):
            self._unroll_settings(stmt, counts)
            return
        else:
            self._written_out(stmt, len(counts))
        self._unroll(stmt, counts)

    def _written_out(self, stmt: ForLoop, count: int) -> None:
        self._ignore(
            stmt,
            f"the FOR loop is written out {count} times: what it does depends on "
            f"{stmt.counter}, which olp knows only by unrolling it",
        )

    def _sets_settings_only(self, stmt: ForLoop) -> bool:
        """Whether the body of ``stmt`` only assigns motion settings olp models (``$VEL_AXIS[i]
        = 20``, ``$ACC_AXIS[i]``; comments apart) and its source lines are at hand."""
        if self.sources.source(stmt.span.file) is None or stmt.span.end_line is None:
            return False
        return all(
            isinstance(s, CommentStmt) or (isinstance(s, Assign) and s.target.key in self._setters)
            for s in stmt.body
        )

    def _unroll_settings(self, stmt: ForLoop, counts: range) -> None:
        """A FOR loop that only sets motion settings (``FOR i = 1 TO 6 $VEL_AXIS[i] = 20
        ENDFOR``): unrolled into the motion settings, so that the motions after it are checked
        and timed with what each pass sets, and kept as written line by line (its comments as
        comments) where it stands, for the KRL post (:meth:`_keep_settings_loop`). Where a pass
        leaves anything in the program or reports a line (a setting olp keeps as written, an
        output), the loop is written out pass by pass instead, with a warning."""
        start, reported, tracked = len(self.out), self.reports, len(self.unwritten)
        self._unroll(stmt, counts)
        passes = self.out[start:]
        if self.reports > reported or not all(isinstance(n, ir.Comment) for n in passes):
            self._written_out(stmt, len(counts))
            return
        del self.out[start:]  # the comments of every pass: the loop's own lines replace them
        # the loop's lines stand where it does: its settings are never left unwritten
        del self.unwritten[tracked:]
        del self.unwritten_at[tracked:]
        self._keep_settings_loop(stmt)

    def _keep_settings_loop(self, stmt: ForLoop) -> None:
        """The lines of a FOR loop that only sets motion settings, as written: each statement
        a KRL-only :class:`~olp.ir.Verbatim` (other posts write what it sets as the settings of
        the motions olp models after it), each comment an :class:`~olp.ir.Comment`. The lines
        become ``modelled`` (left out of other posts without a warning) when a motion olp models
        follows them (:meth:`_track_settings`); until then other posts leave them out with a
        warning."""
        assert stmt.span.end_line is not None
        reason = (
            f"a line of the FOR loop at line {stmt.span.line}, which sets motion settings: "
            "written for KUKA controllers only; another post writes what it sets only as the "
            "settings of the motions olp models after it"
        )
        first = len(self.out)
        self._keep_line(stmt.span.line, stmt.span.file, reason)
        for inner in stmt.body:
            if isinstance(inner, CommentStmt):
                self.out.append(
                    ir.Comment(text=inner.text, span=inner.span, fold=inner.fold, from_source=True)
                )
            else:
                self._keep_text(code_of(self.sources.snippet(inner.span)), inner.span, reason, True)
        self._keep_line(stmt.span.end_line, stmt.span.file, reason)
        self.settings_loops.append((self.out, first, len(self.out)))

    def _keep_line(self, number: int, file: str, reason: str) -> None:
        """The statement on line ``number`` of ``file`` as written (its comment apart), as a
        KRL-only :class:`~olp.ir.Verbatim`: the head or end of a kept FOR loop."""
        source = self.sources.source(file)
        line = (source.line(number) if source is not None else None) or ""
        code = code_of(line)
        column = line.index(code) + 1
        span = ir.SourceSpan(file, number, column, number, column + len(code))
        self._keep_text(code, span, reason, krl_only=True)

    def _lowers_as_block(self, stmt: ForLoop, first: int) -> bool:
        """Whether the body lowers with the counter unknown (then the loop stays a loop): with
        no motion to a run-time target, or with as many as when the counter is ``first`` (the
        targets are the run's whatever the counter: ``LIN pts[i]`` of an array declared in a
        file olp was not given; unrolling would only repeat run-time motions)."""
        unknown = Counter(f"{stmt.counter} counts the FOR loop at line {stmt.span.line}")
        if self._probe_for(stmt, unknown, runtime=False) is not None:
            return True
        blind = self._probe_for(stmt, unknown, runtime=True)
        known = self._probe_for(stmt, Num(float(first), True, stmt.span), runtime=True)
        return blind is not None and blind == known

    def _probe_for(self, stmt: ForLoop, counter: Value, runtime: bool) -> int | None:
        """The run-time motions of a FOR body lowered once with ``counter``, None where it does
        not lower (``runtime`` False: a motion to a run-time target does not lower either)."""
        probe = self._child(loop=True, probe=True)
        probe.variables.assign(stmt.counter.upper(), counter)
        probing = self.ctx.probing_for
        self.ctx.probing_for = 0 if runtime else probing + 1
        try:
            probe.lower_body(stmt.body)
        except ParseError:
            return None
        finally:
            self.ctx.probing_for = probing
        return sum(isinstance(n, ir.RuntimeMove) for n in leaves(probe.out))

    def _unroll(self, stmt: ForLoop, counts: range) -> None:
        counter = stmt.counter.upper()
        self.loop_depth += 1
        self.loops.append("unrolled")
        try:
            for count in counts:
                self.ctx.spend(stmt)
                self.variables.assign(counter, Num(float(count), True, stmt.span))
                start = len(self.out)
                self.lower_body(stmt.body)
                if reads_name(self.out[start:], counter):  # kept as written: it reads the counter
                    self.out.insert(start, _count_assign(stmt, count))
                if self.exiting is not None or self.returned is not None:
                    self.exiting = None
                    break
        finally:
            self.loop_depth -= 1
            self.loops.pop()
        self.variables.assign(counter, past_for(stmt.counter, stmt.span.line))
        self.past.add(counter)

    def _for_block(self, stmt: ForLoop) -> None:
        counter = stmt.counter.upper()
        unknown = Unknown(f"{stmt.counter} counts the FOR loop at line {stmt.span.line}")
        self.variables.assign(counter, unknown)
        body = self._loop_body(stmt.body, "FOR", stmt.span)
        step = None if stmt.step is None else self._expr(stmt.step)
        start, stop = self._expr(stmt.start), self._expr(stmt.end)
        self.out.append(
            ir.For(
                variable=stmt.counter, start=start, stop=stop, step=step, body=body, span=stmt.span
            )
        )

    def _block(self, stmt: Block) -> None:
        if stmt.keyword in ("SPLINE", "PTP_SPLINE"):
            self._keep_spline_block(stmt)
            return
        self.motion_count += 1  # a block may move the robot: a held $POS_ACT is stale after it
        self._blocks[stmt.keyword](stmt)

    def _keep_spline_block(self, stmt: Block) -> None:
        """A ``SPLINE ... ENDSPLINE`` (``PTP_SPLINE``) block, kept as written line by line for
        the KRL post (its comments as comments): olp does not model the spline path through
        its SPL points (KUKA's spline is not published; a guess would be checked as if it were
        the path), so the block is not checked (reach, limits, collisions) nor timed, with a
        warning; other posts refuse its lines. It runs with the settings the controller holds:
        the ones olp absorbed since the last motion are kept before it, and the robot is where
        olp does not know after it (a _REL motion then is a run-time one)."""
        self.motion_count += 1
        self._keep_unwritten(
            f"sets motion settings before the {stmt.keyword} block at line {stmt.span.line}, "
            "kept as written (olp writes none before it)"
        )
        source = self.sources.source(stmt.span.file)
        last = stmt.span.end_line or stmt.span.line
        reason = f"a line of the {stmt.keyword} block at line {stmt.span.line}: not modelled"
        for number in range(stmt.span.line, last + 1):
            line = (source.line(number) if source is not None else None) or ""
            code = code_of(line)
            if code:
                start = line.index(code) + 1
                span = ir.SourceSpan(stmt.span.file, number, start, number, start + len(code))
                self._keep_text(code, span, reason)
            rest = line.strip()[len(code) :].strip() if code else line.strip()
            if rest.startswith(";"):
                span = ir.SourceSpan(stmt.span.file, number, line.index(";") + 1)
                self.out.append(ir.Comment(text=rest[1:], span=span, from_source=True))
        self._note(
            stmt.span,
            f"{stmt.keyword} block (lines {stmt.span.line}-{last}) kept as written: olp does not "
            "model the spline path, so its motions are not checked (reach, limits, collisions) "
            "nor timed, and the motion after it starts where olp does not know",
        )
        self.track.lose(RuntimeStart(f"the {stmt.keyword} block at line {stmt.span.line} moves"))

    def _if(self, stmt: Block) -> None:
        condition = self._expr(stmt.conditions[0])
        paths = [self._path(body) for body in stmt.bodies]
        self._join(paths, "IF", stmt.span)
        then_body, else_body = (build_instructions(p.out, dense=False) for p in paths)
        branch = ir.Branch(condition=condition, body=then_body, span=stmt.span)
        self.out.append(
            ir.If(branches=(branch,), orelse=else_body, has_else=stmt.has_else, span=stmt.span)
        )

    def _switch(self, stmt: Block) -> None:
        subject = self._expr(stmt.conditions[0])
        paths = [self._path(body) for body in stmt.bodies]
        self._join(paths, "SWITCH", stmt.span)
        bodies = [build_instructions(p.out, dense=False) for p in paths]
        cases = tuple(
            ir.Case(values=tuple(self._expr(v) for v in values), body=body, span=stmt.span)
            for values, body in zip(stmt.cases, bodies, strict=False)
        )
        default = bodies[-1]
        self.out.append(
            ir.Switch(
                subject=subject,
                cases=cases,
                default=default,
                has_default=stmt.has_else,
                span=stmt.span,
            )
        )

    def _while(self, stmt: Block) -> None:
        condition = self._expr(stmt.conditions[0])
        body = self._loop_body(stmt.bodies[0], "WHILE", stmt.span)
        self.out.append(ir.While(condition=condition, body=body, span=stmt.span))

    def _repeat(self, stmt: Block) -> None:
        body = self._loop_body(stmt.bodies[0], "REPEAT", stmt.span)
        until = self._expr(stmt.conditions[0])
        self.out.append(ir.Repeat(body=body, until=until, span=stmt.span))

    def _loop(self, stmt: Block) -> None:
        body = self._loop_body(stmt.bodies[0], "LOOP", stmt.span)
        self.out.append(ir.Loop(body=body, span=stmt.span))

    # ---- structured lowering: bodies, loops and joins
    def _child(self, loop: bool = False, probe: bool = False) -> _Lowering:
        """A lowering of a nested body, from the state here. A probe reports nothing."""
        child = _Lowering(self.ctx, self.state, self.variables.copy())
        child.track = dataclasses.replace(self.track)
        child.call_stack = list(self.call_stack)
        child.loop_depth = self.loop_depth + (1 if loop else 0)
        child.loops = [*self.loops, "block"] if loop else list(self.loops)
        child.ambiguous = dict(self.ambiguous)
        child.unset = set(self.unset)
        child.absorbed_data = dict(self.absorbed_data)
        child.routine = self.routine
        child.defining, child.generic = self.defining, self.generic
        child.return_ends = [] if probe else self.return_ends
        child.past = self.past
        child.in_block = self.in_block + 1
        child.folds = list(self.folds)
        child.live_outs = [*self.live_outs, self.out]
        if not probe:
            child.ignored, child.notes, child.status_turn = (
                self.ignored,
                self.notes,
                self.status_turn,
            )
            child._reported = self._reported
            child.settings_loops = self.settings_loops
        child.lost = set(self.lost)
        # each path its own list of the statements waiting for a motion (the join makes the
        # union); a probe keeps none in the lists it is nested in: its copies point to a scratch
        child.unwritten = list(self.unwritten)
        if probe:
            scratch: list[Any] = []
            child.live_outs.append(scratch)
            child.unwritten_at = [(scratch, 0, keys) for _, _, keys in self.unwritten_at]
            child.deferred = [(stmt, (scratch, 0, p[2])) for stmt, p in self.deferred]
        else:
            child.unwritten_at = list(self.unwritten_at)
            child.deferred = list(self.deferred)
        return child

    def _path(self, body: Sequence[Stmt], loop: bool = False) -> _Lowering:
        """A block's path lowered; its output stays a list until the block's join
        (:meth:`_join`), which may keep statements in it."""
        child = self._child(loop)
        child.lower_body(body)
        return child

    def _loop_body(self, body: Sequence[Stmt], keyword: str, span: ir.SourceSpan) -> Body:
        """A loop's body, lowered once from the state every pass may start with: variables it
        assigns are unknown, motion settings it changes are ambiguous and the position it changes
        is unknown from the loop's start on (one pass of the data-flow reaches the fixpoint:
        "changed by the body" does not grow on a second pass)."""
        where = f"the {keyword} at line {span.line}"
        unset = self._set_by_earlier_pass(body, where)
        probe = self._child(loop=True, probe=True)
        probe.lower_body(body)
        for name in sorted(probe.variables.changed_since(self.variables)):
            reason = f"{name} may be changed by a pass of {where}"
            value = joined([probe.variables.lookup(name)], reason)
            past = isinstance(value, PastFor)  # read past its unrolled FOR: an error stays one
            self.variables.assign(name, value if past else unset.get(name, value))
        held = self._merge_states([self, probe], where, held=True)
        self.lost |= probe.unkeepable()  # what a pass leaves unwritten, the next one starts with
        child = self._path(body, loop=True)
        self._join([child], keyword, span, fallthrough=True)
        self._check_next_pass(child, held, where, span)
        return build_instructions(child.out, dense=False)

    def _check_next_pass(
        self, child: _Lowering, held: set[str], where: str, span: ir.SourceSpan
    ) -> None:
        """The settings the loop's start takes as the controller's because a pass changes them
        (``held``, decided on a probe of the body) must be on the controller at the end of the
        pass lowered for the output too; else olp cannot keep its word (not met by any program
        olp knows: the probe and the pass run the same statements)."""
        for name in sorted(held):
            if FIELD_KEYS[name] & child.unkeepable():
                raise self._error(
                    f"{_SETTING_NAMES[name]} differs between the passes of {where}, and olp "
                    "cannot keep the statement that sets it for the next pass",
                    span,
                )

    def _set_by_earlier_pass(self, body: Sequence[Stmt], where: str) -> dict[str, Unknown]:
        """A variable without a value before a loop that the loop's body assigns: a pass may
        read it after an earlier pass assigned it (``LOOP SWITCH cmd CASE 1 $BASE = aux CASE 2
        aux = ...``), so at the loop's start it holds what the body left, known only when the
        program runs, as after an IF that assigns it on one path (:func:`joined`). A pass that
        reads it before any pass assigned it stops the controller; olp cannot tell which pass
        comes first, and says so when the value is needed. Returns those variables' values."""
        unset: dict[str, Unknown] = {}
        for name in sorted(assigned_names(body)):
            value = self.variables.lookup(name)
            if isinstance(value, Unknown) and value.missing and self.variables.is_declared(name):
                lines = _assignment_lines(body, name)
                reason = (
                    f"{name} has no value before {where} and gets one in its body ({lines}): "
                    "a pass reads the value an earlier pass left, known only when the "
                    "program runs (a first pass that reads it before assigning it stops the "
                    "controller)"
                )
                unset[name] = Unknown(reason)
                self.variables.assign(name, unset[name])
        return unset

    def _join(
        self,
        children: Sequence[_Lowering],
        keyword: str,
        span: ir.SourceSpan,
        fallthrough: bool = False,
    ) -> None:
        """After a block: what every path reaching its end agrees on is known, the rest is not.
        ``fallthrough``: the block may be skipped (a loop not entered).

        The statements a path absorbed into the motion settings after its last motion are kept
        as written at its end, where they stand (for the KRL post: the output writes settings
        only before the motions that use them, so on that path they would never reach the
        controller; a setting that differs between the paths is the controller's after the
        join, :meth:`_merge_states`). The paths' outputs are still lists here."""
        reached = [
            c for c in children if c.returned is None and c.exiting is None and c.jumped is None
        ]
        reached += [self] if fallthrough else []
        where = f"the {keyword} at line {span.line}"
        if not reached:
            reached = list(children)
        for child in children:
            child._keep_unwritten(
                f"sets motion settings after the last motion of its path through {where}: "
                "kept as written, for what runs after the block",
                strict=False,
                only=child.out,
            )
        base = self.variables
        changed = set().union(*(c.variables.changed_since(base) for c in reached if c is not self))
        for name in sorted(changed):
            values = [c.variables.lookup(name) for c in reached]
            if all(v is values[0] or v == values[0] for v in values):
                self.variables.assign(name, values[0])
            else:
                reason = f"{name} depends on the path through {where}"
                self.variables.assign(name, joined(values, reason))
        for c in children:  # a record one path sets is written back only by its own path
            for name, absorbed in c.absorbed_data.items():
                if self.absorbed_data.get(name) is not absorbed:
                    self.absorbed_data[name] = None
        self._merge_states(reached, where, held=True)
        self._join_unwritten(reached)

    def _join_unwritten(self, ends: Sequence[_Lowering]) -> None:
        """The statements waiting for a motion (and the deferred ones) after a join, once each,
        in order, and the setting keys lost on any path. One from before the block that a
        path's motion passed is not kept later (the output writes what that motion uses; the
        rest of it is lost, as on that path); one left in an output already lowered (an inlined
        routine's) stays, for the error at what would run without it
        (:meth:`_keep_unwritten`); a deferred one left in a path's output is lost."""
        self.lost = set().union(*(end.lost for end in ends))
        waiting = self._union([list(zip(e.unwritten, e.unwritten_at, strict=True)) for e in ends])
        self.unwritten[:] = [stmt for stmt, _ in waiting]
        self.unwritten_at[:] = [position for _, position in waiting]
        deferred = self._union([e.deferred for e in ends])
        live = [*self.live_outs, self.out]
        self.deferred = [d for d in deferred if any(d[1][0] is out for out in live)]
        self.lost = self.lost.union(*(d[1][2] for d in deferred if d not in self.deferred))

    def _union(
        self, lists: Sequence[Sequence[tuple[Stmt, tuple[list[Any], int, frozenset[str]]]]]
    ) -> list[tuple[Stmt, tuple[list[Any], int, frozenset[str]]]]:
        counts: dict[tuple[int, int, int], int] = {}
        entries = []
        for found in lists:
            for stmt, position in found:
                key = (id(stmt), id(position[0]), position[1])
                counts[key] = counts.get(key, 0) + 1
                if counts[key] == 1:
                    entries.append((key, stmt, position))
        live = [*self.live_outs, self.out]
        union = []
        for key, stmt, position in entries:
            out, at, keys = position
            if any(out is o for o in live) and counts[key] < len(lists):
                if not any(getattr(node, "span", None) == stmt.span for node in out[at:]):
                    self.lost |= keys  # (else a path kept it where it stands: written)
                continue
            union.append((stmt, position))
        return union

    def unkeepable(self) -> set[str]:
        """The setting keys whose value on this path the output may not put on the controller:
        lost ones, and those of statements waiting in an output olp has already lowered (an
        inlined routine's)."""
        live = [*self.live_outs, self.out]
        positions = [*self.unwritten_at, *(p for _, p in self.deferred)]
        frozen = [keys for out, _, keys in positions if not any(out is o for o in live)]
        return self.lost.union(*frozen)

    def _merge_states(self, ends: Sequence[_Lowering], where: str, held: bool = False) -> set[str]:
        """Motion settings and the position after paths ending in ``ends``.

        A setting that differs between the paths is ambiguous. With ``held`` (a block's paths,
        each lowered here, and a loop's start) it is the controller's
        (:class:`~olp.frontends.krl.state.Held`: the controller holds whichever value the path
        that ran set) where every path's value is on the controller: the output wrote it, or
        keeps as written the statements that set it (the ones waiting for a motion, kept here),
        or the program never set it. A motion that runs with it then runs with the
        controller's settings (:meth:`~olp.frontends.krl.motion.Motions.
        _controller_settings_motion`). Otherwise (a path's value olp absorbed and no output
        writes, a jump's or a RETURN's paths) it stays an error at the motion that runs with it.
        Returns the settings made the controller's here."""
        states = [e.state for e in ends]
        ambiguous: dict[str, str] = {}
        for e in ends:
            for name, why in e.ambiguous.items():
                current = ambiguous.get(name)
                if current is None or (isinstance(current, Held) and not isinstance(why, Held)):
                    ambiguous[name] = why  # an error on one path stays one
        if not held:  # (a jump's or a RETURN's paths: their waiting statements are not kept)
            for e in ends:
                if e is not self:
                    positions = [*e.unwritten_at, *(p for _, p in e.deferred)]
                    self.lost |= e.lost.union(*(keys for _, _, keys in positions))
        made_held: set[str] = set()
        unset = set().union(*(e.unset for e in ends))
        for name in _STATE_FIELDS:
            values = [getattr(s, name) for s in states]
            if all(v == values[0] for v in values[1:]):
                continue
            setting = _SETTING_NAMES[name]
            if held and self._held_at_join(ends, name, ambiguous):
                ambiguous[name] = Held(
                    f"{setting} differs between the paths of {where} (the controller holds "
                    "the one its path set)"
                )
                made_held.add(name)
            else:
                ambiguous[name] = f"{setting} differs between the paths of {where}"
        if made_held:
            keys = set().union(*(FIELD_KEYS[n] for n in made_held))
            for e in ends:
                positions = [*e.unwritten_at, *(p for _, p in e.deferred)]
                if keys & set().union(*(k for _, _, k in positions)):
                    e._keep_unwritten(
                        f"sets motion settings that differ between the paths of {where}: kept "
                        "as written, as what runs after them runs with the controller's",
                        strict=False,
                        deferred=True,
                    )
        vel_cp_set = all(s.vel_cp_set for s in states)
        self.state = dataclasses.replace(states[0], vel_cp_set=vel_cp_set)
        self.ambiguous = ambiguous
        self.unset = unset
        self._merge_tracks(ends, where)
        return made_held

    @staticmethod
    def _held_at_join(ends: Sequence[_Lowering], name: str, ambiguous: dict[str, str]) -> bool:
        """Whether setting ``name``, which differs between the paths ``ends``, can be the
        controller's after them: no path leaves it ambiguous for a reason other than
        :class:`~olp.frontends.krl.state.Held`, and every path's value is on the controller or
        can be put there (:meth:`unkeepable`)."""
        if name in ambiguous and not isinstance(ambiguous[name], Held):
            return False
        return not any(FIELD_KEYS[name] & e.unkeepable() for e in ends)

    def _merge_tracks(self, ends: Sequence[_Lowering], where: str) -> None:
        """The position after paths ending in ``ends``."""
        tracks = [e.track for e in ends]
        if any(t != tracks[0] for t in tracks[1:]):
            self.track = dataclasses.replace(tracks[0])
            reason = f"the paths through {where} end at different positions"
            if any(
                t.cartesian is None and isinstance(t.no_cartesian, RuntimeStart) for t in tracks
            ):
                # one path ends where only the run knows: so does the join (a motion that
                # refers to its start is a run-time motion, as after that path alone)
                reason = RuntimeStart(f"{reason}, one known only when the program runs")
            self.track.lose_cartesian(reason)
            self.track.joints, self.track.no_joints = None, reason
        else:
            self.track = dataclasses.replace(tracks[0])

    def _expr(self, expr: Expr) -> ir.Expr:
        converted = to_expr(expr, self._input_of)
        assert converted is not None
        return converted

    # ---- jumps
    def _goto(self, stmt: Other) -> None:
        name = (stmt.name or "").upper()
        if name not in self.routine.labels:
            raise self._error(f"GOTO {stmt.name}: no label {stmt.name} in this routine", stmt.span)
        if name in self.routine.seen:  # a jump back: its state is known from the first pass
            self.routine.back_states.setdefault(name, []).append(self.state)
        else:
            self.routine.pending.setdefault(name, []).append(self._snapshot())
        self.out.append(ir.Goto(label=stmt.name or "", span=stmt.span))
        self.jumped = stmt.span.line

    def _keep_dead(self, stmt: Stmt, goto: int) -> None:
        """A statement no path reaches, after the GOTO at line ``goto``: kept as its source
        lines (a block line by line, comments left out), each a :class:`~olp.ir.Verbatim`,
        not lowered: a motion in it is neither checked nor timed, and in the output it stays
        where the GOTO jumps over it (a label a GOTO targets ends the dead stretch: see
        :meth:`lower_statement`)."""
        source = self.sources.source(stmt.span.file)
        span = stmt.span
        reason = f"not reached: the GOTO at line {goto} jumps away"
        self._note(
            span,
            f"the statements after the GOTO at line {goto} are never reached: kept as written, "
            "not checked or timed",
            once=f"dead-{span.file}-{goto}",
        )
        last = span.end_line if span.end_line is not None else span.line
        for number in range(span.line, max(last, span.line) + 1):  # a block: to its END...
            text = code_of((source.line(number) if source is not None else None) or "")
            if text:
                where = ir.SourceSpan(span.file, number, 1)
                self._keep_text(text, where, reason, krl_only=True)

    def _label(self, stmt: Other) -> None:
        name = (stmt.name or "").upper()
        lines = self.routine.targets.get(name, [])
        incoming = self.routine.pending.pop(name, [])
        ends = ([] if self.jumped is not None else [self]) + incoming
        self.jumped = None
        if ends and (incoming or self not in ends):
            self._merge_states(ends, f"the GOTOs to {stmt.name}")
            self._join_variables(ends, f"the GOTOs to {stmt.name}")
        if any(line > stmt.span.line for line in lines):  # jumped to from below: a loop
            reason = f"{stmt.name} is jumped back to (GOTO at line {max(lines)})"
            for back in self.routine.first_pass.get(name, []):
                for field_name in _STATE_FIELDS:
                    if getattr(back, field_name) != getattr(self.state, field_name):
                        setting = _SETTING_NAMES[field_name]
                        self.ambiguous[field_name] = f"{setting} differs where {reason}"
            for var in sorted(self.routine.assigned):
                self.variables.assign(var, Unknown(f"{var} may change before {reason}"))
            self.track.lose_cartesian(reason)
            self.track.joints, self.track.no_joints = None, reason
        self.routine.seen[name] = self.state
        self.out.append(ir.Label(name=stmt.name or "", span=stmt.span))

    def first_pass(self, body: Sequence[Stmt]) -> None:
        """Where the routine jumps back, lower it once quietly to learn the states of its
        backward GOTOs (see :class:`RoutineJumps`)."""
        if not self.routine.jumps_back:
            return
        probe = self._child(probe=True)
        probe.in_block = self.in_block
        probe.routine = RoutineJumps.of(body)
        probe.lower_body(body)
        self.routine.first_pass = probe.routine.back_states

    def _return(self, stmt: Other) -> None:
        value = None if stmt.value is None else self._expr(stmt.value)
        self.out.append(ir.Return(value=value, span=stmt.span))

    def _snapshot(self) -> _Lowering:
        snap = self._child(probe=True)
        snap.in_block = self.in_block
        return snap

    def _join_variables(self, ends: Sequence[_Lowering], where: str) -> None:
        changed = set().union(*(e.variables.changed_since(self.variables) for e in ends))
        for name in sorted(changed):
            values = [e.variables.lookup(name) for e in ends]
            if not all(v is values[0] or v == values[0] for v in values):
                reason = f"{name} depends on the path through {where}"
                self.variables.assign(name, joined(values, reason))

    def _other(self, stmt: Other) -> None:
        routine = self.call_stack[-1] if self.call_stack else self.defining or "the program"
        if stmt.kind == "GOTO":
            self._goto(stmt)
        elif stmt.kind == "label":
            self._label(stmt)
        elif stmt.kind == "RETURN" and self.in_block:
            self._return(stmt)
            if self.call_stack:  # the caller goes on from here too: its state joins there
                self.return_ends.append(self._snapshot())
            self.returned = (routine, stmt.span.line)
        elif stmt.kind == "RETURN":
            self.returned = (routine, stmt.span.line)
            if self.call_stack or self.defining:
                self._return(stmt)
            else:
                self._ignore(stmt, "RETURN ends the program here")
        elif stmt.kind == "EXIT" and self.loops and self.loops[-1] == "block":
            self.out.append(ir.Exit(span=stmt.span))
            self.exiting = stmt.span.line
        elif stmt.kind == "EXIT" and self.loop_depth > 0:
            self.exiting = stmt.span.line
        elif stmt.kind == "EXT":
            self._keep_krl_only(stmt, OTHER_REASONS[stmt.kind])
        elif stmt.kind in _KEPT_OTHERS:
            self._keep(stmt, OTHER_REASONS[stmt.kind])
        else:
            self._ignore(stmt, OTHER_REASONS[stmt.kind])


Body = tuple[ir.Node, ...]
_STATE_FIELDS = (
    "speed",
    "vel_axis",
    "acc_axis",
    "cdis_mm",
    "tool",
    "frame",
    "ori_type",
    "circ_type",
)
_SETTING_NAMES = {
    "speed": "the speed",
    "vel_axis": "$VEL_AXIS",
    "acc_axis": "$ACC_AXIS",
    "cdis_mm": "$APO.CDIS",
    "tool": "$TOOL",
    "frame": "$BASE",
    "ori_type": "$ORI_TYPE",
    "circ_type": "$CIRC_TYPE",
    **SPEED_PARTS,
}


# ------------------------------------------------------------------------------------------------
# A module


def lower_module(
    module: Module,
    sources: SourceSet,
    src: str,
    dat: KrlData | None,
    config: KrlData | None,
    shared: Sequence[KrlData] = (),
    calls_keep_settings: tuple[str, ...] = (),
) -> KrlResult:
    """Lower the program of ``module`` (:func:`_main`) and the module's other routines: each
    called one at every call, kept as a routine where the calls agree
    (:mod:`olp.frontends.krl.routines`). ``shared``: other modules' data lists whose GLOBAL
    names the module sees (:func:`~olp.frontends.krl.data.visible_globals`)."""
    routines = _routines(module, sources, src)
    values = visible_globals(config, shared, dat)
    data = [d for d in (config, *shared, dat) if d is not None]
    main = _main(routines, src)
    ordered = routines if main is None else [main, *(r for r in routines if r is not main)]
    table = {r.name.upper(): r for r in ordered}
    ctx = Context(sources, table, src, dat, config, MAX_LOWERED_STATEMENTS, shared)
    ctx.calls_keep_settings = calls_keep_settings
    entry = dict(values)  # the program's lowering changes ``values``
    lowering = _Lowering(ctx, State(), _variables(values, ctx, main))
    if main is not None:
        if main.kind == "DEFFCT":  # its RETURN value gives the result: kept, as a function's
            lowering.defining = main.name
        lowering.routine = RoutineJumps.of(main.body)
        ctx.called.add(main.name.upper())
        started = _started_elsewhere(main, routines)
        if started is not None:
            lowering.track.lose(RuntimeStart(started))
        lowering.unset = {"tool", "frame"}  # the controller's until the program sets them
        lowering.first_pass(main.body)
        lowering.lower_body(main.body)
        lowering.report_unwritten_settings()
    entry_values = _entry_values(entry, routines)
    alone = _lower_alone(ordered[1:] if main is not None else ordered, lowering, entry_values)
    body = build_instructions(lowering.out)
    others = {k: v for k, v in table.items() if v is not main}
    entered = _entered_at_calls(lowering, entry_values, table)
    assembled = assemble(body, alone, others, sources, entered)
    ignored = sorted(
        [*lowering.ignored, *assembled.ignored], key=lambda i: (i.span.line, i.span.column)
    )
    written = {span for _, span in dat.types} if dat is not None else set()
    for data_list in (dat, config):  # the module's own types are written back, not ignored
        kept = data_list.ignored if data_list is not None else ()
        ignored.extend(i for i in kept if i.span not in written)
    name = main.name if main is not None else _module_name(src, routines)
    params: tuple[ir.Parameter, ...] = ()
    instructions = list(assembled.instructions)
    if main is not None:
        params, instructions = typed_params(main, instructions)
    program = ir.Program(
        name=name,
        instructions=tuple(instructions),
        source=src,
        routines=assembled.routines,
        params=params,
        returns=None if main is None else main.returns,
        returns_dims=() if main is None else _returns_dims(main),
        language="krl",
        exported=main is not None and main.exported,
    )
    program = with_module_data(program, dat, config, shared)
    return KrlResult(
        program=program,
        ignored=tuple(ignored),
        notes=tuple(lowering.notes),
        status_turn=tuple(lowering.status_turn),
        data_sources=tuple(d.filename for d in data),
    )


def _main(routines: Sequence[Routine], src: str) -> Routine | None:
    r"""The module's program: its first routine, the one the controller runs (or other modules
    call) by the module's name, where that is a ``DEF``, or a ``DEFFCT`` named as the file
    (``DEFFCT BOOL RecoverFromWorkSt(...)`` in ``RecoverFromWorkSt.src``: the module is the
    function, its logic in it). Else the first ``DEF`` (text given without a file name); a
    module of functions none of which is named as the file (a library of ``GLOBAL DEFFCT``\ s
    called from other modules) has none: an empty program holding them as routines."""
    first = routines[0]
    stem = os.path.splitext(os.path.basename(src))[0]
    if first.kind == "DEF" or first.name.upper() == stem.upper():
        return first
    return next((r for r in routines if r.kind == "DEF"), None)


def _started_elsewhere(main: Routine, routines: Sequence[Routine]) -> str | None:
    """Why the robot's position when ``main`` starts is known only when the program runs, else
    None: it takes parameters (a caller in another module gives them, from wherever that left
    the robot), or an ``INTERRUPT DECL`` of the module runs it (from wherever the interrupt
    stops the robot). A motion that refers to its start (``LIN_REL {X -10} #TOOL`` first)
    is then a run-time motion. A program without either starts where the robot stands when
    it is selected, which the controller's first motion (its BCO run) must not depend on:
    such a motion stays an error."""
    if main.params:
        return f"{main.name} takes parameters: it starts where its caller left the robot"
    for routine in routines:
        for stmt in statements(routine.body):
            action = stmt.action if isinstance(stmt, InterruptDecl) else None
            if isinstance(action, CallStmt) and action.name.upper() == main.name.upper():
                return (
                    f"{main.name} runs from the INTERRUPT DECL at line {stmt.span.line}: it "
                    "starts where the interrupt stops the robot"
                )
    return None


def _variables(values: Any, ctx: Context, main: Routine | None) -> Variables:
    variables = Variables(values, ctx.unknown_name)
    params = () if main is None else main.params
    variables.push(
        {
            p.name.upper(): Unknown(
                f"{p.name} is a parameter of the program: a caller gives it when it runs"
            )
            for p in params
        }
    )
    return variables


def _returns_dims(main: Routine) -> tuple[ir.Expr | None, ...]:
    """The array extents of a function program's result (``DEFFCT CHAR[128] Text( )``)."""
    from olp.frontends.krl.flow import to_expr

    return tuple(to_expr(d, lambda _: None) for d in main.returns_dims)


def _lower_alone(
    routines: Sequence[Routine], main: _Lowering, entry: dict[str, Value]
) -> dict[str, tuple[ir.Node, ...]]:
    """The routines no call of the program reaches (interrupt handlers, functions, routines
    never called: a library's, which other modules or the PLC call), each lowered on its own:
    upper-case name -> body. ``entry``: the module's variables where such a routine starts
    (:func:`_entry_values`).

    Such a routine is entered from a context olp does not know, so it is lowered from exactly
    the state olp has after a call of a routine it did not read (:meth:`_Lowering._entered`):
    every motion setting held by the controller, the robot where olp does not know, the
    module's variables known only where nothing assigns them. A plain motion in it then runs
    with the controller's settings (:meth:`_Lowering._controller_settings_motion`); one whose
    settings the routine sets itself (an inline form) is modelled: its target checked, its
    path not (it starts where the caller left the robot). A note on the routine's head says so.
    One that olp cannot lower is reported and left out."""
    ctx = main.ctx
    bodies: dict[str, tuple[ir.Node, ...]] = {}
    for routine in routines:
        if routine.name.upper() in ctx.called:
            continue
        runs_as = ctx.handlers.get(routine.name.upper())
        what = f"runs from the {runs_as}" if runs_as is not None else "is never called"
        if routine.kind == "DEFFCT":
            what = "is a function the program does not call" if runs_as is None else what
        held = f"{routine.name} {what}: its caller's motion settings are the controller's"
        start = f"{routine.name} {what}: it starts where its caller left the robot"
        reason = None
        called = set(ctx.called)
        try:
            body = _lower_entered(routine, main, entry, held, start)
        except ParseError as exc:
            reason = f"olp cannot lower it: {exc.message}"
        if reason is None:
            bodies[routine.name.upper()] = body
            if moves(body):
                main._note(
                    routine.span,
                    f"{routine.kind} {routine.name} {what} in this module: written, and checked "
                    "only as far as an unknown caller allows (it starts with the controller's "
                    "motion settings and where the caller left the robot: its plain motions run "
                    "with the controller's settings, its inline forms' targets are checked, "
                    "their paths from the start are not)",
                )
            continue
        # the routines it called are written only through it: each is lowered on its own then
        ctx.called.intersection_update(called)
        main.ignored.append(
            IgnoredLine(
                routine.span,
                ctx.sources.snippet(routine.span),
                f"{routine.kind} {routine.name} {what} and is not written: {reason}",
            )
        )
    return bodies


_NO_ARGUMENTS = (type, ir.SourceSpan, FastMotion, LinRows, CommentStmt)
"""What holds no call (numbers only: a milling program's tens of thousands of rows)."""


def _passed(node: object) -> Iterator[str]:
    """The variables (upper case) ``node`` (statements, expressions) gives a routine or a
    function as an argument: KRL passes a variable by reference unless the parameter is
    ``:IN``, so the callee may change it (a routine olp did not read too)."""
    if isinstance(node, CallStmt | FuncCall):
        yield from (a.name.upper() for a in node.args if isinstance(a, Var))
    if isinstance(node, tuple | list):
        for item in node:
            yield from _passed(item)
    elif dataclasses.is_dataclass(node) and not isinstance(node, _NO_ARGUMENTS):
        for f in dataclasses.fields(node):
            yield from _passed(getattr(node, f.name))


def _lower_entered(
    routine: Routine,
    main: _Lowering,
    entry: dict[str, Value],
    held: str,
    start: str,
    reports: bool = True,
) -> tuple[ir.Node, ...]:
    """``routine``'s body lowered from an unknown caller's state (:meth:`_Lowering._entered`,
    ``held`` and ``start`` the reasons), the module's variables at ``entry``; what it reports
    goes to ``main``'s reports, or nowhere without ``reports``. Raises :class:`ParseError`."""
    ctx = main.ctx
    lowering = _Lowering(ctx, State(), Variables(dict(entry), ctx.unknown_name))
    lowering.variables.push(
        {
            p.name.upper(): Unknown(f"{p.name} is a parameter of {routine.name}")
            for p in routine.params
        }
    )
    lowering.defining = routine.name
    if reports:
        lowering.ignored, lowering.notes = main.ignored, main.notes
        lowering.status_turn, lowering._reported = main.status_turn, main._reported
    lowering.routine = RoutineJumps.of(routine.body)
    lowering._entered(held, start)
    lowering.first_pass(routine.body)
    lowering.lower_body(routine.body)
    lowering.report_unwritten_settings()
    return build_instructions(lowering.out)


def _entered_at_calls(
    main: _Lowering, entry: dict[str, Value], table: dict[str, Routine]
) -> Callable[[str, Sequence[int]], tuple[ir.Node, ...] | None]:
    """For :func:`~olp.frontends.krl.routines.assemble`: a routine (upper-case name) lowered
    from an unknown caller's state, for calls (their lines) that all run it with the
    controller's settings and the robot where olp does not know; None where olp cannot lower
    it so. Its reports are dropped: each call's lowering made them."""

    def lower(name: str, lines: Sequence[int]) -> tuple[ir.Node, ...] | None:
        routine = table[name]
        at = ", ".join(str(line) for line in lines)
        held = (
            f"{routine.name} runs with its callers' motion settings, which the controller holds "
            f"at each of its calls (lines {at})"
        )
        start = f"{routine.name} starts where its callers left the robot (lines {at})"
        try:
            return _lower_entered(routine, main, entry, held, start, reports=False)
        except ParseError:
            return None

    return lower


def _entry_values(values: dict[str, Value], module: Sequence[Routine]) -> dict[str, Value]:
    """The module's variables where a caller olp does not follow enters a routine (one no call
    of the program reaches, :func:`_lower_alone`, or one whose calls all run it with the
    controller's settings, :func:`_entered_at_calls`):
    their declared (data-list) values where nothing in the module assigns them, else known only
    when the program runs (another routine, an earlier run of this one, or a routine olp did
    not read given it by reference may have changed it). A SIGNAL stays one: it names an input
    or output, which an assignment switches (or, an input, cannot), never a value."""
    assigned: set[str] = set()
    for routine in module:
        assigned |= assigned_names(routine.body) | set(_passed(routine.body))
    return {
        name: Unknown(
            f"{name} is assigned in the module: where a caller olp does not follow enters a "
            "routine, its value is known only when the program runs"
        )
        if name in assigned and not isinstance(value, Signal)
        else value
        for name, value in values.items()
    }


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


def _assignment_lines(body: Sequence[Stmt], name: str) -> str:
    """The lines (comma separated) where ``body`` assigns the variable ``name`` (upper case)."""
    lines = [
        s.span.line
        for s in statements(body)
        if (isinstance(s, Assign) and s.target.name.upper() == name)
        or (isinstance(s, ForLoop) and s.counter.upper() == name)
    ]
    found = sorted(set(lines))
    return f"line{'s' if len(found) > 1 else ''} {', '.join(str(line) for line in found)}"


def _count_assign(stmt: ForLoop, count: int) -> ir.Assign:
    """``counter = count`` before an unrolled pass whose output reads the counter (a statement
    kept as written, such as ``LIN xPath[i]`` to a run-time target or ``Foo(i)``), so that it
    reads on the controller the value it would have in the loop."""
    return ir.Assign(
        target=ir.Name(name=stmt.counter, span=stmt.span),
        value=ir.Constant(value=count, span=stmt.span),
        span=stmt.span,
    )


def _module_name(src: str, routines: Sequence[Routine]) -> str:
    """A module of functions only (a library of DEFFCTs called from other modules) has no
    program to run: its program is empty and named after the file."""
    return os.path.splitext(os.path.basename(src))[0] or routines[0].name
