"""Cycle time of a program with branches and loops: the time of one path, or a range.

The timing pass times the text in order, each instruction once (the per-instruction table, the
trajectory). That is not one run of a program with control flow, so :func:`path_times` walks
the program's blocks the way the controller runs them and adds up *segments*: the runs of
instructions between two block boundaries, each timed as a straight program by the timing
pass's own timers (:func:`~olp.passes.timing.program.time_program`).

* **A segment's start.** The robot enters a segment where the last motion before it ended
  (on every path that reaches it: after ``IF ... ELSE`` from either branch's end, at a loop's
  head from before the loop or from its last pass), and at rest: **a blend across a block
  boundary is timed as an exact stop**. A segment entered from the motion the text puts before
  it keeps the timing pass's times (timed again with stops at the segment's ends where a zone
  crosses one); from another motion it is resolved again from that motion's end (a joint
  lead-in to it, not counted). That end is the joints the resolve pass found for the motion
  along the text, as in :mod:`olp.passes.flow`: a Cartesian target reached along another path
  is taken in the same configuration.
* **Branches.** A condition is folded with what is known (:mod:`.conditions`: ``--assume``
  values, constants); a branch whose condition is known false is never taken, the first one
  known true always. A choice that stays open gives the range: the shortest and the longest
  path over every open choice, each with the choices that give it.
* **Values.** Conditions and bounds are folded with the values the program's own assignments
  fix on every path to them (:mod:`.known`: ``n = 3`` before ``FOR i = 1 TO n``).
* **Loops.** A ``FOR`` with bounds olp can fold runs its count; a loop named by ``--assume
  loop:LINE=N`` (or ``loop:LABEL=N``) runs N passes; a ``WHILE`` or ``REPEAT`` driven by a
  counter the body steps runs the passes the counter gives; a ``WHILE`` whose condition is
  known false none. Any other ``WHILE``, ``REPEAT`` or ``LOOP`` counts **one pass for both ends of
  the range**, and the result says which loops were counted so. An ``EXIT`` leaves its loop
  during any pass; an endless ``LOOP`` without one (a cell's main loop) is timed for its
  passes, i.e. one cycle.
* **Jumps.** A program with ``GOTO`` is not walked (its paths are not blocks): it gets no
  path time, and a note says so.

The walk keeps one state per robot position (the last motion), so N ``IF`` blocks in a row
cost N steps, not 2^N paths. It runs twice: the first walk notes every segment and entry it
meets, which are then timed in two calls of the timers (:class:`SegmentTimer`), the second adds
them up. Long loops cost little: once a pass shifts every state by the same time and the same
choices as the pass before it, the remaining passes are added in one step (exact, as a path's
time is a sum). Measured (benchmarks/timing_branches.py): 40 ``IF ... ELSE`` in a row in 2.6 s,
most of it the path solver on the 80 re-resolved moves; a ``FOR`` of 1,000,000 passes in 0.12 s.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np
from numpy.typing import NDArray

from olp import ir
from olp.compiled import CompiledProgram, PathBlock, items_of
from olp.diagnostics import Diagnostic
from olp.errors import UsageError
from olp.ir_flow import BLOCK_TYPES, bodies, leaves, leaves_and_blocks
from olp.passes.timing.conditions import (
    UNKNOWN,
    Assumptions,
    Environment,
    LoopKey,
    environment,
    expression_key,
)
from olp.passes.timing.known import Known
from olp.span import SourceSpan

if TYPE_CHECKING:
    from olp.passes.pipeline import BuildOptions

START = -1
"""The position before the first motion: the robot where it stands (its home joints)."""

ChoiceKey: TypeAlias = tuple[str, int, int, str]
"""A branch choice: file, line, column of its block, and what was chosen."""
Choices: TypeAlias = tuple[tuple[ChoiceKey, int], ...]
"""Choices made on a path and how often (a choice inside a loop counts once per pass), sorted."""


@dataclass(frozen=True, slots=True)
class _Bound:
    """The shortest and longest time (s) of the paths that reach a point with the robot at one
    position, and the choices that give each."""

    lo: float
    lo_choices: Choices
    hi: float
    hi_choices: Choices

    def plus(self, seconds: float, choices: Choices = ()) -> _Bound:
        return _Bound(
            self.lo + seconds,
            _add(self.lo_choices, choices),
            self.hi + seconds,
            _add(self.hi_choices, choices),
        )

    def merge(self, other: _Bound) -> _Bound:
        lo = self if self.lo <= other.lo else other
        hi = self if self.hi >= other.hi else other
        return _Bound(lo.lo, lo.lo_choices, hi.hi, hi.hi_choices)


MAX_WALKED_PASSES = 100_000
"""Passes of one loop walked one by one at most (a loop whose passes settle into one repeating
time is added up in one step long before)."""

States: TypeAlias = dict[int, _Bound]
"""Position (the last motion's instruction index, or :data:`START`) -> bound."""


@dataclass(frozen=True, slots=True)
class Choice:
    """A branch choice on a path: ``span`` the block's, ``text`` the block's word and what was
    taken, a tab apart (``"IF\\ttaken"``, ``"SWITCH\\tCASE 2"``), ``count`` how often on the
    path."""

    span: SourceSpan
    text: str
    count: int = 1

    def describe(self) -> str:
        """``IF at prog.src:12 taken`` (``(x5)`` when taken in several passes)."""
        word, _, rest = self.text.partition("\t")
        name = self.span.file.replace("\\", "/").rsplit("/", 1)[-1]
        times = f" (x{self.count})" if self.count > 1 else ""
        return f"{word} at {name}:{self.span.line} {rest}".rstrip() + times


@dataclass(frozen=True, slots=True)
class PathEnd:
    """One end of the range: ``seconds`` and the open ``choices`` that give it."""

    seconds: float
    choices: tuple[Choice, ...]


@dataclass(frozen=True, slots=True)
class PathTimes:
    """The cycle time of a program with control flow.

    ``shortest``/``longest``: the two ends of the range (equal when every choice is decided);
    ``assumed``: the ``--assume`` texts; ``notes``: how loops and open conditions were counted,
    one sentence each. ``seconds`` is None when the program could not be walked (``reason``
    says why, e.g. a ``GOTO``)."""

    shortest: PathEnd | None
    longest: PathEnd | None
    assumed: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    reason: str = ""

    @property
    def decided(self) -> bool:
        """Whether one path was named: no open choice, both ends equal."""
        return (
            self.shortest is not None
            and self.longest is not None
            and not self.shortest.choices
            and not self.longest.choices
            and self.shortest.seconds == self.longest.seconds
        )


# --------------------------------------------------------------------------------------------
# Choices


def _add(a: Choices, b: Choices) -> Choices:
    if not b:
        return a
    if not a:
        return b
    counts = dict(a)
    for key, n in b:
        counts[key] = counts.get(key, 0) + n
    return tuple(sorted(counts.items()))


def _minus(a: Choices, b: Choices) -> Choices | None:
    """``a - b`` if ``b`` is part of ``a``, else None."""
    counts = dict(a)
    for key, n in b:
        left = counts.get(key, 0) - n
        if left < 0:
            return None
        counts[key] = left
    return tuple(sorted((k, n) for k, n in counts.items() if n))


def _times(choices: Choices, k: int) -> Choices:
    return tuple((key, n * k) for key, n in choices)


def _merge(into: States, key: int, bound: _Bound) -> None:
    known = into.get(key)
    into[key] = bound if known is None else known.merge(bound)


def _merged(*all_states: States) -> States:
    out: States = {}
    for states in all_states:
        for key, bound in states.items():
            _merge(out, key, bound)
    return out


def _shift(states: States, step: _Step, k: int) -> States:
    lo, lo_ch, hi, hi_ch = step
    return {
        key: _Bound(
            b.lo + lo * k,
            _add(b.lo_choices, _times(lo_ch, k)),
            b.hi + hi * k,
            _add(b.hi_choices, _times(hi_ch, k)),
        )
        for key, b in states.items()
    }


_Step: TypeAlias = tuple[float, Choices, float, Choices]


def _uniform_step(before: States, after: States) -> _Step | None:
    """The one time and choices every state of ``before`` gained to become ``after``, or None
    if they did not all gain the same (or the positions differ)."""
    if not before or before.keys() != after.keys():
        return None
    found: _Step | None = None
    for key in sorted(before):
        b, a = before[key], after[key]
        lo_ch, hi_ch = _minus(a.lo_choices, b.lo_choices), _minus(a.hi_choices, b.hi_choices)
        if lo_ch is None or hi_ch is None:
            return None
        step = (a.lo - b.lo, lo_ch, a.hi - b.hi, hi_ch)
        if found is None:
            found = step
        elif not (_close(step[0], found[0]) and _close(step[2], found[2])) or (
            step[1],
            step[3],
        ) != (found[1], found[3]):
            return None
    return found


def _close(a: float, b: float) -> bool:
    return math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-9)


# --------------------------------------------------------------------------------------------
# Segments


_FROM_TEXT = START - 1
"""The entry key of a run entered from the motion the text puts before it."""


@dataclass(frozen=True, slots=True)
class _Run:
    """A run to time: instructions ``lo`` .. ``hi`` (``nodes``), entered at ``entry``."""

    lo: int
    hi: int
    nodes: tuple[Any, ...]
    entry: int


class SegmentTimer:
    """Times runs of instructions from a given position, each once.

    While ``collecting``, :meth:`time` notes what is asked and answers 0 s (the positions a
    walk reaches do not depend on times); :meth:`settle` then times every run noted in two
    calls of the timers: the runs entered from the text's previous motion on the compiled
    program itself, every run end timed as a stop, and the others resolved again, each after a
    joint lead-in to its entry, in one program."""

    def __init__(self, compiled: CompiledProgram, options: BuildOptions) -> None:
        self.compiled = compiled
        self.options = options
        self.motions = motion_indices(compiled.program)
        self.cache: dict[tuple[int, int, int], float] = {}
        self.pending: dict[tuple[int, int, int], _Run] = {}
        self.collecting = False
        self.fallbacks: list[SourceSpan] = []

    def time(self, lo: int, nodes: Sequence[Any], entry: int) -> tuple[float, int | None]:
        """Seconds of the run ``nodes`` (instruction ``lo`` on) entered at ``entry``, and the
        position it leaves (None: it holds no motion)."""
        hi = lo + _size(nodes)
        first, end = np.searchsorted(self.motions, [lo, hi]).tolist()
        last = int(self.motions[end - 1]) if end > first else None
        textual = int(self.motions[first - 1]) if first > 0 else START
        key = (lo, hi, _FROM_TEXT if last is None or entry == textual else entry)
        if key not in self.cache:
            self.pending[key] = _Run(lo, hi, tuple(nodes), key[2])
            if self.collecting:
                return 0.0, last
            self.settle()
        return self.cache[key], last

    def settle(self) -> None:
        """Time every run noted (see the class docstring)."""
        runs, self.pending = list(self.pending.values()), {}
        others = [r for r in runs if r.entry != _FROM_TEXT]
        failed = self._from_entries(others)
        again = [dataclasses.replace(r, entry=_FROM_TEXT) for r in failed]
        self._from_text([r for r in runs if r.entry == _FROM_TEXT] + again)
        for run in failed:
            self.cache[(run.lo, run.hi, run.entry)] = self.cache[(run.lo, run.hi, _FROM_TEXT)]

    def _from_text(self, runs: Sequence[_Run]) -> None:
        """Runs entered from the text's previous motion: the compiled program timed again with
        a stop at each run's end and before its start."""
        from olp.passes.timing.program import time_program

        if not runs:
            return
        bounds = np.array([r.lo for r in runs] + [r.hi for r in runs], dtype=np.int64)
        ends = np.searchsorted(self.motions, bounds) - 1
        stops = self.motions[ends[ends >= 0]]
        timed = self.compiled
        instructions = (self.compiled.steps[i].instruction for i in stops.tolist())
        if any(not getattr(ins, "zone", ir.FINE).is_fine for ins in instructions):  # (a call)
            timed = time_program(self.compiled, *self._timing(), stops=stops)
        # else: every run already starts and ends at a stop; the timing pass's times hold
        totals = np.concatenate([[0.0], np.cumsum(_durations(timed))])
        for run in runs:
            self.cache[(run.lo, run.hi, _FROM_TEXT)] = float(totals[run.hi] - totals[run.lo])

    def _from_entries(self, runs: Sequence[_Run]) -> list[_Run]:
        """Runs entered from another motion: each resolved and timed after a joint lead-in to
        that motion's end (not counted), all in one program; returns the runs that failed
        there (timed from the text's start instead, and said so)."""
        from olp.passes.resolve import resolve
        from olp.passes.timing.program import time_program

        if not runs:
            return []
        nodes: list[Any] = []
        firsts = []
        for run in runs:
            span = next(leaves(run.nodes)).span
            firsts.append(sum(_size((n,)) for n in nodes))
            nodes += [self._lead_in(run.entry, span), *run.nodes]
        program = ir.Program(
            name="runs", instructions=tuple(nodes), source=self.compiled.program.source
        )
        resolved = resolve(program, self.compiled.station, self.options.resolve)
        ends = np.array([f + 1 + r.hi - r.lo for f, r in zip(firsts, runs, strict=True)])
        motions = motion_indices(program)
        stops = motions[np.searchsorted(motions, ends) - 1]  # each run's last motion
        timed = time_program(resolved, *self._timing(), stops=stops)
        totals = np.concatenate([[0.0], np.cumsum(_durations(timed))])
        bad = {d.index for d in timed.diagnostics if d.severity == "error"}
        failed = []
        for first, run in zip(firsts, runs, strict=True):
            rows = range(first + 1, first + 1 + run.hi - run.lo)
            if any(i in bad for i in rows):
                self.fallbacks.append(next(leaves(run.nodes)).span)
                failed.append(run)
                continue
            self.cache[(run.lo, run.hi, run.entry)] = float(totals[rows.stop] - totals[rows.start])
        return failed

    def _lead_in(self, entry: int, span: SourceSpan) -> Any:
        """What brings the robot to ``entry`` before a run (not counted): a joint move to its
        joints, or the run-time motion (or call that may move the robot) itself (the run then
        starts where olp does not know, as after it in the text)."""
        if entry != START:
            motion = self.compiled.steps[entry].instruction
            if isinstance(motion, ir.RuntimeMove) or _may_move(motion):
                return motion
        return ir.JointMove(target=ir.JointTarget(joints=self._joints(entry)), span=span)

    def _joints(self, entry: int) -> Any:
        joints = self.compiled.start_joints if entry == START else self.compiled.steps[entry].joints
        return self.compiled.start_joints if joints is None else joints

    def _timing(self) -> tuple[Mapping[str, float], Any]:
        return self.options.other_times, self.options.timing


def _durations(compiled: CompiledProgram) -> NDArray[np.float64]:
    """Seconds per instruction (n,) of a timed program, a toolpath's rows from its arrays."""
    parts = []
    for item in items_of(compiled.steps):
        if isinstance(item, PathBlock):
            parts.append(np.zeros(len(item)) if item.durations is None else item.durations)
        else:
            parts.append(np.array([item.duration]))
    return np.concatenate(parts) if parts else np.zeros(0)


def _size(nodes: Sequence[Any]) -> int:
    """Instructions in ``nodes`` as the steps count them (a toolpath one per row)."""
    return sum(len(n) if isinstance(n, ir.LinearPath) else 1 for n in leaves(nodes))


def motion_indices(program: ir.Program) -> NDArray[np.int64]:
    """The instruction indices of the motions of ``program``, ascending (a toolpath's rows
    as one range, not one by one), motions to run-time targets and calls that may move the robot
    (:attr:`olp.ir.Call.may_move`) included: the robot's position after one is a position of
    the walk (olp does not know where; :meth:`SegmentTimer.time`
    times what follows it as the text does, from an unknown start)."""
    parts, cursor = [], 0
    for node in leaves(program.instructions):
        if isinstance(node, ir.LinearPath):
            parts.append(np.arange(cursor, cursor + len(node)))
            cursor += len(node)
            continue
        if ir.is_motion(node) or isinstance(node, ir.RuntimeMove) or _may_move(node):
            parts.append(np.array([cursor]))
        cursor += 1
    return np.concatenate(parts).astype(np.int64) if parts else np.zeros(0, dtype=np.int64)


# --------------------------------------------------------------------------------------------
# The walk


class _Walk:
    """One walk of the program's blocks with the states that reach each point."""

    def __init__(self, timer: SegmentTimer, known: Known, assumptions: Assumptions):
        self.timer = timer
        self.known = known
        self.assumptions = assumptions
        self.cursor = 0
        self.exits: list[States] = []
        self.returns: list[States] = []
        self.returned: list[list[dict[str, Any]]] = []  # the known values at each return
        self.done: States = {}
        self.notes: dict[tuple[str, int, int], str] = {}
        self.used_loops: set[LoopKey] = set()

    def all(self, nodes: Sequence[Any]) -> States:
        """The states at the end of the program ``nodes`` (its end or a return)."""
        return _merged(self.body(nodes, {START: _Bound(0.0, (), 0.0, ())}), self.done)

    def body(self, nodes: Sequence[Any], states: States) -> States:
        run: list[Any] = []
        label: str | None = None
        for node in nodes:
            if isinstance(node, BLOCK_TYPES):
                states = self.run(run, states)
                run = []
                states = self.block(node, states, label)
            elif isinstance(node, ir.Exit | ir.Return):
                states = self.run([*run, node], states)
                run = []
                target = self.exits[-1] if self.exits and isinstance(node, ir.Exit) else self.done
                if isinstance(node, ir.Return) and self.returns:
                    target = self.returns[-1]  # leaves the expanded routine, not the program
                    self.returned[-1].append(self.known.snapshot())
                for key, bound in states.items():
                    _merge(target, key, bound)
                states = {}
            else:
                run.append(node)
                self.known.learn(node)
            label = node.name if isinstance(node, ir.Label) else None
        return self.run(run, states)

    def run(self, nodes: Sequence[Any], states: States) -> States:
        if not nodes:
            return states
        lo = self.cursor
        self.cursor += _size(nodes)
        out: States = {}
        for entry, bound in sorted(states.items()):
            seconds, last = self.timer.time(lo, nodes, entry)
            _merge(out, entry if last is None else last, bound.plus(seconds))
        return out

    def block(self, node: Any, states: States, label: str | None) -> States:
        if isinstance(node, ir.If | ir.Switch):
            return self.choose(node, states)
        if isinstance(node, ir.Expanded):
            return self.expanded(node, states)
        counted = self.known.passes(node) if isinstance(node, ir.While | ir.Repeat) else None
        self.known.enter_loop(node)
        passes, by_rule = self.passes(node, label, counted)
        entry = self.known.snapshot()
        out, completed = self.repeat(node, states, passes)
        self.known.restore(entry)
        if by_rule and completed:  # a path ran the pass to its end: the count mattered
            self.notes[_key(node.span)] = (
                f"{node.kind.upper()} at {_where(node.span)} counted as 1 pass (its count is not "
                f"known: --assume loop:{node.span.line}=N)"
            )
        return out

    def expanded(self, node: ir.Expanded, states: States) -> States:
        """A routine's body at its call site; a return inside ends the routine, not the
        program, and an EXIT inside leaves no loop of the caller. An entry (a routine no call
        runs, :attr:`olp.ir_flow.Expanded.entry`) is no part of the program's time."""
        if node.entry:
            self.cursor += _size(node.body)
            return states
        saved = self.exits
        self.exits = []
        self.returns.append({})
        self.returned.append([])
        try:
            end = self.body(node.body, states)
        finally:
            self.exits = saved
        # The caller goes on from the routine's end or from any return: it knows what all agree on.
        returned = self.returned.pop()
        if returned:
            self.known.join([self.known.snapshot(), *returned])
        return _merged(end, self.returns.pop())

    # ---- branches

    def choose(self, node: ir.If | ir.Switch, states: States) -> States:
        env = self.known.environment()
        arms = if_arms(node, env) if isinstance(node, ir.If) else case_arms(node, env)
        self.known.evaluated(node)
        open_choice = sum(1 for _, taken in arms if taken) > 1
        out: States = {}
        entry, ends = self.known.snapshot(), []
        for (text, taken), body in zip(arms, bodies(node), strict=True):
            if not taken or not states:
                self.cursor += _size(body)
                continue
            entering = states
            if open_choice:
                choice = ((node.span.file, node.span.line, node.span.column, text), 1)
                entering = {k: b.plus(0.0, (choice,)) for k, b in states.items()}
            self.known.restore(entry)
            out = _merged(out, self.body(body, entering))
            ends.append(self.known.snapshot())
        self.known.restore(entry)
        self.known.join(ends)
        return out

    # ---- loops

    def passes(self, node: Any, label: str | None, counted: int | None) -> tuple[int, bool]:
        """:func:`loop_passes` of ``node`` here."""
        return loop_passes(
            node, label, counted, self.assumptions, self.known.environment(), self.used_loops
        )

    def repeat(self, node: Any, states: States, passes: int) -> tuple[States, bool]:
        """The states after ``passes`` passes of loop ``node`` (or an exit during one), and
        whether any path ran the last pass to its end."""
        start, size = self.cursor, _size(node.body)
        entry = self.known.snapshot()
        exits: States = {}
        self.exits.append({})
        before: States | None = None
        current, last_exits = states, dict[int, _Bound]()
        for k in range(passes):
            if self.timer.collecting and before is not None and before.keys() == current.keys():
                break  # later passes start from the same positions: they time the same runs
            step = None if before is None else _uniform_step(before, current)
            if step is not None:
                # Every pass from here on adds ``step`` (a path's time is a sum): jump to the end.
                left = passes - k
                exits = _merged(exits, _shift(last_exits, step, left))
                current = _shift(current, step, left)
                break
            if k == MAX_WALKED_PASSES:
                self.notes[_key(node.span)] = (
                    f"{node.kind.upper()} at {_where(node.span)}: only its first "
                    f"{MAX_WALKED_PASSES} of {passes} passes are counted (its passes do not "
                    "settle into one repeating time)"
                )
                break
            self.cursor, self.exits[-1] = start, {}
            self.known.restore(entry)
            before, current = current, self.body(node.body, current)
            last_exits = self.exits[-1]
            exits = _merged(exits, last_exits)
            if not current:
                break
        self.exits.pop()
        self.cursor = start + size
        return _merged(current, exits), bool(current) and passes > 0


def loop_passes(
    node: Any,
    label: str | None,
    counted: int | None,
    assumptions: Assumptions,
    env: Environment,
    used: set[LoopKey],
) -> tuple[int, bool]:
    """How many passes loop ``node`` runs (see the module docstring), and whether that is the
    rule for a count olp does not know; ``label``: the label just before it; ``counted``: the
    passes its counters give (:meth:`Known.passes`); an assumption that names it goes into
    ``used``."""
    file = node.span.file.replace("\\", "/").rsplit("/", 1)[-1].casefold()
    keys: list[LoopKey] = [(file, node.span.line), node.span.line]
    keys += [label.casefold()] if label else []
    for key in keys:
        if key in assumptions.loops:
            used.add(key)
            count = assumptions.loops[key]
            if isinstance(node, ir.Repeat) and count < 1:
                where = f"the REPEAT at line {node.span.line}"
                raise UsageError(
                    f"--assume loop:{_loop_text(key)}={count}: {where} runs at least once"
                )
            return count, False
    if isinstance(node, ir.For):
        bounded = _for_count(node, env)
        if bounded is not None:
            return bounded, False
    if counted is not None:
        return counted, False
    if isinstance(node, ir.While) and env.evaluate(node.condition) is False:
        return 0, False
    return 1, True


def if_arms(node: ir.If, env: Environment) -> list[tuple[str, bool]]:
    """(text, may run) per body of ``node`` (its branches, then its else)."""
    arms, decided = [], False
    for k, branch in enumerate(node.branches):
        value = False if decided else env.evaluate(branch.condition)
        taken = value is not False
        decided = decided or value is True
        text = "IF\ttaken" if k == 0 else f"IF\tELSE IF at line {branch.span.line} taken"
        arms.append((text, taken))
    text = "IF\tnot taken" if len(node.branches) == 1 else "IF\tELSE"
    arms.append((text, not decided))
    return arms


def case_arms(node: ir.Switch, env: Environment) -> list[tuple[str, bool]]:
    subject = env.evaluate(node.subject)
    arms, decided = [], False
    for case in node.cases:
        values = [env.evaluate(v) for v in case.values]
        known = all(v is not UNKNOWN for v in [subject, *values])
        match = known and any(_equal(subject, v) for v in values)
        taken = not decided and (match or not known)
        decided = decided or match
        arms.append((f"SWITCH\tCASE {_case_text(case)}", taken))
    arms.append(("SWITCH\tDEFAULT", not decided))
    return arms


def _equal(a: Any, b: Any) -> bool:
    fold = (lambda v: v.casefold()) if isinstance(a, str) and isinstance(b, str) else None
    return bool(fold(a) == fold(b)) if fold else bool(a == b)


def _case_text(case: ir.Case) -> str:
    parts = []
    for v in case.values:
        if isinstance(v, ir.Constant):
            parts.append(("#" if v.enum else "") + str(v.value))
        else:
            parts.append(expression_key(v) or f"(line {case.span.line})")
    return ",".join(parts)


def _for_count(node: ir.For, env: Environment) -> int | None:
    start, stop = env.evaluate(node.start), env.evaluate(node.stop)
    step = 1 if node.step is None else env.evaluate(node.step)
    if not all(isinstance(v, int) and not isinstance(v, bool) for v in (start, stop, step)):
        return None
    assert isinstance(start, int) and isinstance(stop, int) and isinstance(step, int)
    if step == 0:
        return None
    return max(0, (stop - start) // step + 1)


def _key(span: SourceSpan) -> tuple[str, int, int]:
    return span.file, span.line, span.column


def _where(span: SourceSpan) -> str:
    return f"{span.file.replace(chr(92), '/').rsplit('/', 1)[-1]}:{span.line}"


# --------------------------------------------------------------------------------------------
# The program


def path_times(
    compiled: CompiledProgram, options: BuildOptions, assumptions: Assumptions | None = None
) -> PathTimes:
    """The cycle time of ``compiled`` (timed, without errors) over its paths (see the module
    docstring). Raises :class:`~olp.errors.UsageError` for an assumption that names no loop,
    input or variable of the program."""
    given = assumptions or Assumptions()
    check_assumptions(compiled.program, given)
    program = compiled.program
    jump = next((n for n in leaves(program.instructions) if isinstance(n, ir.Goto)), None)
    if jump is not None:
        reason = (
            f"olp does not time the paths of a program that jumps (GOTO at {_where(jump.span)})"
        )
        return PathTimes(None, None, given.given, reason=reason)
    env, timer = environment(program.instructions, given), SegmentTimer(compiled, options)

    def known() -> Known:
        return Known(env, program.instructions, given.names)

    timer.collecting = True  # a first walk notes every run to time, the second adds them up
    _Walk(timer, known(), given).all(program.instructions)
    timer.collecting = False
    timer.settle()
    walk = _Walk(timer, known(), given)
    end = walk.all(program.instructions)
    _check_loops_used(walk, given)
    notes = [walk.notes[k] for k in sorted(walk.notes)]
    notes += [
        f"the run at {_where(s)} could not be timed from every start; timed from the text's"
        for s in walk.timer.fallbacks
    ]
    if not end:
        return PathTimes(None, None, given.given, tuple(notes), "no path reaches the end")
    ordered = sorted(end.items())
    lo = min((b for _, b in ordered), key=lambda b: b.lo)
    hi = max((b for _, b in ordered), key=lambda b: b.hi)
    return PathTimes(
        PathEnd(lo.lo, _choices(lo.lo_choices)),
        PathEnd(hi.hi, _choices(hi.hi_choices)),
        given.given,
        tuple(notes),
    )


def _choices(choices: Choices) -> tuple[Choice, ...]:
    return tuple(
        Choice(SourceSpan(file, line, column), text, n) for (file, line, column, text), n in choices
    )


def check_assumptions(program: ir.Program, assumptions: Assumptions) -> None:
    """A :class:`~olp.errors.UsageError` for an input or variable assumption that no condition
    or bound of ``program`` reads (a typo would otherwise pass unnoticed)."""
    inputs, names = _read(program)
    for number in assumptions.inputs:
        if number not in inputs:
            raise UsageError(f"--assume in{number}=...: no condition of the program reads it")
    for name in assumptions.names:
        if name not in names:
            raise UsageError(f"--assume {name}=...: no condition of the program reads it")


def _check_loops_used(walk: _Walk, assumptions: Assumptions) -> None:
    for key in assumptions.loops:
        if key not in walk.used_loops:
            raise UsageError(f"--assume loop:{_loop_text(key)}=...: {_no_loop(key)}")


def _loop_text(key: LoopKey) -> str:
    return f"{key[0]}:{key[1]}" if isinstance(key, tuple) else str(key)


def _no_loop(key: LoopKey) -> str:
    if isinstance(key, int):
        return f"no loop of the program is on line {key}"
    if isinstance(key, tuple):
        return f"no loop of the program is on line {key[1]} of {key[0]}"
    return f"no loop of the program follows label {key!r}"


def _read(program: ir.Program) -> tuple[set[int], set[str]]:
    """The inputs and variable keys the program's conditions, subjects and bounds read."""
    inputs: set[int] = set()
    names: set[str] = set()
    for expr in _conditions(program.instructions):
        for part in _parts(expr):
            if isinstance(part, ir.DigitalInput):
                inputs.add(part.index)
            key = expression_key(part)
            if key is not None:
                names.add(key)
    return inputs, names


def _conditions(nodes: Sequence[Any]) -> Iterator[Any]:
    for node in leaves_and_blocks(nodes):
        if isinstance(node, ir.If):
            yield from (b.condition for b in node.branches)
        elif isinstance(node, ir.Switch):
            yield node.subject
            yield from (v for c in node.cases for v in c.values)
        elif isinstance(node, ir.While):
            yield node.condition
        elif isinstance(node, ir.For):
            yield from (e for e in (node.start, node.stop, node.step) if e is not None)


def _parts(expr: Any) -> Iterator[Any]:
    """``expr`` and every expression inside it."""
    yield expr
    for name in ("left", "right", "operand", "base"):
        child = getattr(expr, name, None)
        if child is not None:
            yield from _parts(child)
    for name in ("indices", "args"):
        for child in getattr(expr, name, ()) or ():
            if child is not None:
                yield from _parts(child)


# --------------------------------------------------------------------------------------------
# The pass


def path_timing_pass(compiled: CompiledProgram, options: BuildOptions) -> CompiledProgram:
    """Time a program with control flow per path (:func:`path_times`, with
    ``options.assume``) into ``compiled.paths``, with an info note that the per-instruction
    times follow the text; a program whose only path is its text (no blocks or jumps, only
    declarations, assignments and waits) is left as it is. Runs after the timing pass (it
    reuses the steps' times)."""
    assumptions = getattr(options, "assume", None) or Assumptions()
    program = compiled.program
    if not program.has_flow or _one_path(program):
        if assumptions.given:
            raise UsageError(
                f"--assume {assumptions.given[0]!r}: the program has no branches or loops"
            )
        return compiled
    if not compiled.ok:
        check_assumptions(program, assumptions)
        return compiled
    paths = path_times(compiled, options, assumptions)
    return dataclasses.replace(compiled, paths=paths).with_diagnostics([_note(compiled, paths)])


def _one_path(program: ir.Program) -> bool:
    """Whether the text in order is the program's only path: declarations, assignments and
    waits, but no block, jump, exit or return, and no entry (a routine no call runs, whose
    steps follow the program's and are no part of its time: the walk leaves them out)."""
    turns = tuple(t for t in (*BLOCK_TYPES, ir.Goto, ir.Exit, ir.Return) if t is not ir.Expanded)
    return not any(
        isinstance(n, turns) or (isinstance(n, ir.Expanded) and n.entry)
        for n in leaves_and_blocks(program.instructions)
    )


def _note(compiled: CompiledProgram, paths: PathTimes) -> Diagnostic:
    first = next(n for n in leaves_and_blocks(compiled.program.instructions) if _is_flow(n))
    where = f"first: {first.kind.replace('_', ' ')} at line {first.span.line}"
    how = (
        f"{paths.reason}: its cycle time times every instruction once, in the order of the text"
        if paths.shortest is None
        else "its cycle time is given per path (the summary's range); the time of each "
        "instruction follows the text, each instruction once"
    )
    return Diagnostic(
        "info", "flow_timing", f"the program has control flow ({where}): {how}", first.span
    )


def _is_flow(node: Any) -> bool:
    return isinstance(node, ir.FLOW_TYPES)


def _may_move(node: object) -> bool:
    return isinstance(node, ir.Call) and node.may_move
