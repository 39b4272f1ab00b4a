"""The instructions one named path of a program with control flow runs, in order: a straight
program to sample a trajectory of (``olp time --trajectory``/``--plot`` on a program with
branches).

The path is the one :mod:`.branches` times when every choice is decided (by ``--assume``, by
constants, or by the program's own assignments, :mod:`.known`): each ``IF``/``SWITCH`` takes
its one arm, each loop runs the passes the walk counts (a loop whose count olp does not know
runs one pass, as there), ``EXIT`` leaves the innermost loop, ``RETURN`` ends the routine
it is in (the call's expansion), or the program in the program's own body.
Flow statements (declarations, assignments, labels) take no time and are left out. As in the
path timing, **a blend across a block boundary is an exact stop**: the last motion before
entering or leaving a block's body (an arm, a loop pass) is made a fine stop, so the straight
program's cycle time is the path time of the summary.

Not unrolled, with the reason: an open choice (a condition the known values do not decide), a
jump (``GOTO``), or a path longer than :data:`MAX_UNROLLED` instructions.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from olp import ir
from olp.ir_flow import BLOCK_TYPES, FLOW_TYPES, bodies
from olp.passes.timing.branches import case_arms, if_arms, loop_passes
from olp.passes.timing.conditions import Assumptions, LoopKey, environment
from olp.passes.timing.known import Known

MAX_UNROLLED = 200_000
"""Instructions of an unrolled path at most (a trajectory of more is not sampled)."""

_MOTIONS = (ir.JointMove, ir.LinearMove, ir.CircularMove, ir.LinearPath)


@dataclass(frozen=True, slots=True)
class Unrolled:
    """The straight ``program`` of the path, or None and the ``reason`` it was not unrolled;
    ``notes``: loops counted as one pass because their count is not known."""

    program: ir.Program | None
    reason: str = ""
    notes: tuple[str, ...] = ()


class _Stop(Exception):
    """The path cannot be unrolled (the message says why)."""


def unroll(program: ir.Program, assumptions: Assumptions | None = None) -> Unrolled:
    """The instructions of ``program``'s path under ``assumptions`` (module docstring)."""
    given = assumptions or Assumptions()
    walk = _Unroll(program, given)
    try:
        walk.body(program.instructions)
    except _Stop as stop:
        return Unrolled(None, str(stop))
    straight = ir.Program(name=program.name, instructions=tuple(walk.out), source=program.source)
    return Unrolled(straight, notes=tuple(walk.notes))


class _Unroll:
    def __init__(self, program: ir.Program, assumptions: Assumptions) -> None:
        env = environment(program.instructions, assumptions)
        self.known = Known(env, program.instructions, assumptions.names)
        self.assumptions = assumptions
        self.out: list[Any] = []
        self.count = 0
        self.last_motion: int | None = None
        self.notes: list[str] = []
        self.used: set[LoopKey] = set()

    def body(self, nodes: Any) -> str | None:
        """Run ``nodes``; ``"exit"`` or ``"return"`` when one of them leaves, else None."""
        label: str | None = None
        for node in nodes:
            if isinstance(node, BLOCK_TYPES):
                self.boundary()
                signal = self.block(node, label)
                self.boundary()
                if signal is not None:
                    return signal
            elif isinstance(node, ir.Exit):
                return "exit"
            elif isinstance(node, ir.Return):
                return "return"
            elif isinstance(node, ir.Goto):
                raise _Stop(f"the program jumps (GOTO at line {node.span.line})")
            else:
                self.known.learn(node)
                if not isinstance(node, FLOW_TYPES):
                    self.append(node)
            label = node.name if isinstance(node, ir.Label) else None
        return None

    def block(self, node: Any, label: str | None) -> str | None:
        if isinstance(node, ir.Expanded) and node.entry:  # no part of the program's run
            return None
        if isinstance(node, ir.Expanded):
            self.body(node.body)  # a RETURN inside ends the routine, and the caller goes on
            return None
        if isinstance(node, ir.If | ir.Switch):
            env = self.known.environment()
            arms = if_arms(node, env) if isinstance(node, ir.If) else case_arms(node, env)
            self.known.evaluated(node)
            taken = [k for k, (_, may) in enumerate(arms) if may]
            if len(taken) > 1:
                raise _Stop(
                    f"the {node.kind.upper()} at line {node.span.line} is an open choice "
                    "(name it with --assume)"
                )
            return self.body(bodies(node)[taken[0]]) if taken else None
        counted = self.known.passes(node) if isinstance(node, ir.While | ir.Repeat) else None
        self.known.enter_loop(node)
        env = self.known.environment()
        passes, by_rule = loop_passes(node, label, counted, self.assumptions, env, self.used)
        if by_rule:
            self.notes.append(f"{node.kind.upper()} at line {node.span.line}: 1 pass")
        entry = self.known.snapshot()
        signal = None
        for _ in range(passes):
            self.known.restore(entry)
            self.boundary()
            signal = self.body(node.body)
            if signal is not None:
                break
        self.known.restore(entry)
        return "return" if signal == "return" else None

    def append(self, node: Any) -> None:
        self.count += len(node.zones) if isinstance(node, ir.LinearPath) else 1
        if self.count > MAX_UNROLLED:
            raise _Stop(f"the path runs more than {MAX_UNROLLED:,} instructions")
        if isinstance(node, _MOTIONS):
            self.last_motion = len(self.out)
        self.out.append(node)

    def boundary(self) -> None:
        """Make the last motion so far stop exactly (a blend does not cross a block)."""
        if self.last_motion is None:
            return
        motion = self.out[self.last_motion]
        if isinstance(motion, ir.LinearPath):
            if motion.zones[-1] > 0:
                zones = np.array(motion.zones)
                zones[-1] = 0.0
                self.out[self.last_motion] = dataclasses.replace(motion, zones=zones)
        elif not motion.zone.is_fine:
            self.out[self.last_motion] = dataclasses.replace(motion, zone=ir.FINE)
