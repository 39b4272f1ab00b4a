"""Checks over every path of a program with control flow: motions reached from more than one place.

The resolve pass checks the instructions in the order of the text (each one once), so a motion
is checked from the motion written before it. With blocks and jumps the robot may arrive from
elsewhere: the motion after an ``IF ... ELSE`` from the end of either branch, the first motion
of a loop from the loop's last one. :func:`motion_predecessors` finds, for every motion, every
motion that can run just before it (a data-flow analysis over the program's blocks, labels and
jumps, loops iterated to a fixpoint); :func:`flow_pass` then checks each linear or circular move
again from every other start it can have (a joint move's end does not depend on its start, and
its path stays within the joint limits between two ends within them).

What is approximated, and said so in a note: collisions are checked only along the text's
order; the configuration a path from another start would take is the one resolve picks for
that start alone. The cycle time per path is :mod:`olp.passes.timing.branches`'.
"""

from __future__ import annotations

import dataclasses
from collections import defaultdict
from collections.abc import Iterable, Sequence
from typing import Any

from olp import ir
from olp.compiled import CompiledProgram
from olp.diagnostics import Diagnostic
from olp.ir_flow import BLOCK_TYPES, leaves_and_blocks

START = -1
"""The predecessor that stands for the start of the program (the robot where it stands)."""
ENTRY = -2
"""The predecessor that stands for an unknown caller of a routine no call of the program runs
(:attr:`olp.ir_flow.Expanded.entry`): resolve checks its first motion from an unknown start."""
MAX_ROUNDS = 64
"""Rounds of the whole-program walk (jumps need several); the sets only grow, so it ends."""


class _Walk:
    """One pass over the program's tree with sets of possible previous motions."""

    def __init__(self, preds: dict[int, set[int]], labels: dict[str, set[int]]) -> None:
        self.preds = preds
        self.labels = labels
        self.cursor = 0
        self.exits: list[set[int]] = []
        self.returns: list[set[int]] = []
        self.scope = ""  # labels of an expanded routine are its own: keyed by where it starts
        self.changed = False

    def body(self, nodes: Sequence[Any], before: frozenset[int]) -> frozenset[int]:
        state = before
        for node in nodes:
            state = self.node(node, state)
        return state

    def node(self, node: Any, state: frozenset[int]) -> frozenset[int]:
        if isinstance(node, ir.If):
            ends = [self.body(b.body, state) for b in node.branches]
            return frozenset().union(*ends, self.body(node.orelse, state))
        if isinstance(node, ir.Switch):
            ends = [self.body(c.body, state) for c in node.cases]
            return frozenset().union(*ends, self.body(node.default, state))
        if isinstance(node, ir.Expanded) and node.entry:  # no part of the program's run
            self.expanded(node, frozenset({ENTRY}))
            return state
        if isinstance(node, ir.Expanded):
            return self.expanded(node, state)
        if isinstance(node, BLOCK_TYPES):
            return self.loop(node, state)
        return self.leaf(node, state)

    def expanded(self, node: ir.Expanded, state: frozenset[int]) -> frozenset[int]:
        """A routine's body at its call site: a return inside leaves to after the call, and
        its labels are not the caller's (nor those of another call of it)."""
        saved, saved_exits = self.scope, self.exits
        self.scope, self.exits = f"{saved}{self.cursor}/", []
        self.returns.append(set())
        try:
            end = self.body(node.body, state)
        finally:
            self.scope, self.exits = saved, saved_exits
        return end | frozenset(self.returns.pop())

    def loop(self, node: Any, state: frozenset[int]) -> frozenset[int]:
        start, head = self.cursor, state
        self.exits.append(set())
        while True:
            self.cursor = start
            end = self.body(node.body, head)
            new_head = head | end
            if new_head == head:
                break
            head = new_head
        exits = frozenset(self.exits.pop())
        if isinstance(node, ir.Loop):
            return exits
        if isinstance(node, ir.Repeat):
            return end | exits
        return head | exits  # While, For: the test fails before a pass or after one

    def leaf(self, node: Any, state: frozenset[int]) -> frozenset[int]:
        if isinstance(node, ir.LinearPath):
            first = self.cursor
            self._record(first, state)
            for row in range(1, len(node)):
                self._record(first + row, frozenset({first + row - 1}))
            self.cursor += len(node)
            return frozenset({first + len(node) - 1}) if state else state
        index = self.cursor
        self.cursor += 1
        if _moves(node):
            self._record(index, state)
            return frozenset({index}) if state else state  # no path reaches it
        if isinstance(node, ir.Goto):
            self._add_label(self.scope + node.label.upper(), state)
            return frozenset()
        if isinstance(node, ir.Label):
            return state | self.labels[self.scope + node.name.upper()]
        if isinstance(node, ir.Exit):
            if self.exits:
                self.exits[-1].update(state)
            return frozenset()
        if isinstance(node, ir.Return):
            if self.returns:
                self.returns[-1].update(state)
            return frozenset()
        return state

    def _record(self, index: int, state: frozenset[int]) -> None:
        known = self.preds[index]
        if not state <= known:
            known.update(state)
            self.changed = True

    def _add_label(self, name: str, state: frozenset[int]) -> None:
        known = self.labels[name]
        if not state <= known:
            known.update(state)
            self.changed = True


def motion_predecessors(program: ir.Program) -> dict[int, frozenset[int]]:
    """Instruction index of every motion -> the indices of the motions that can run just before
    it (:data:`START` for the start of the program). Indices count as iterating the program
    does. A motion no path reaches has an empty set."""
    preds: dict[int, set[int]] = defaultdict(set)
    labels: dict[str, set[int]] = defaultdict(set)
    for _ in range(MAX_ROUNDS):
        walk = _Walk(preds, labels)
        walk.body(program.instructions, frozenset({START}))
        if not walk.changed:
            break
    motions = (i for i, ins in enumerate(program) if ir.is_motion(ins))
    return {i: frozenset(preds.get(i, set())) for i in motions}


def _textual_previous(program: ir.Program) -> dict[int, int]:
    previous, out = START, {}
    for index, instruction in enumerate(program):
        if _moves(instruction):
            out[index] = previous
            previous = index
    return out


def _moves(node: Any) -> bool:
    """Whether ``node`` moves the robot: a motion, one to a run-time target or a call that
    may move it (:attr:`olp.ir.Call.may_move`): a start of the next motion that olp cannot
    know, :func:`_check_from`."""
    return ir.is_motion(node) or isinstance(node, ir.RuntimeMove) or _may_move(node)


def _may_move(node: Any) -> bool:
    return isinstance(node, ir.Call) and node.may_move


def flow_pass(compiled: CompiledProgram, options: Any) -> CompiledProgram:
    """Check every linear or circular move from each start the program's paths give it besides
    the one the text gives (see the module's docstring); a no-op without control flow."""
    program = compiled.program
    if not program.has_flow or not compiled.steps:
        return compiled
    preds = motion_predecessors(program)
    textual = _textual_previous(program)
    found: list[Diagnostic] = []
    others = 0
    for index, before in sorted(preds.items()):
        extra = sorted(before - {textual[index], ENTRY})
        instruction = compiled.steps[index].instruction
        if not extra or isinstance(instruction, ir.JointMove):
            continue
        for start in extra:
            others += 1
            found += _check_from(compiled, start, index, options)
    if others:
        found.append(_collision_note(others))
    return compiled.with_diagnostics(found)


def _check_from(
    compiled: CompiledProgram, start: int, index: int, options: Any
) -> list[Diagnostic]:
    """The move at ``index`` resolved from the end of the motion at ``start``."""
    from olp.passes.resolve import resolve

    step = compiled.steps[index]
    move = step.instruction
    joints: Any
    if start == START:
        joints, where = compiled.station.robot.home, "the start of the program"
    else:
        joints = compiled.steps[start].joints
        where = f"the motion at line {compiled.steps[start].instruction.span.line}"
    if joints is None:
        # the start did not resolve (its own error says so), or it is a run-time target,
        # whose motion and the one after it carry their warnings
        return []
    lead_in = ir.JointMove(target=ir.JointTarget(joints=joints), span=move.span)
    mini = ir.Program(name="path", instructions=(lead_in, move), source=compiled.program.source)
    checked = resolve(mini, compiled.station, getattr(options, "resolve", None))
    return [
        dataclasses.replace(d, index=index, message=f"{d.message} (when it starts from {where})")
        for d in checked.diagnostics
        if d.index == 1
    ]


def _collision_note(count: int) -> Diagnostic:
    return Diagnostic(
        "info",
        "flow_paths",
        f"{count} path(s) into linear moves from other starts than the text's were checked for "
        "reach, limits and singularities, not for collisions (olp checks collisions along the "
        "text's order)",
    )


def _is_flow(node: Any) -> bool:
    return isinstance(node, ir.FLOW_TYPES)


def flow_nodes(nodes: Iterable[Any]) -> list[Any]:
    """The blocks and flow statements of ``nodes``, in source order."""
    return [n for n in leaves_and_blocks(nodes) if _is_flow(n)]
