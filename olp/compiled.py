"""A program compiled on a station: :class:`CompiledProgram`, one :class:`Step` per instruction.

This is what the passes hand on (:mod:`olp.passes`): :meth:`CompiledProgram.start` makes the
unresolved form (one empty step per instruction), the resolve pass fills joints, paths, tools and
frames, checks append diagnostics, the timing pass fills durations and trajectories. Posts render
from it. Its own module, so that the passes, the trajectory sampler and the posts can name it
without importing one another.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from olp.diagnostics import Diagnostic, has_errors
from olp.ir import Frame, Instruction, Program, Tool, is_motion

if TYPE_CHECKING:
    from collections.abc import Iterable

    from olp.station.model import Station
    from olp.trajectory import Segment

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class Step:
    """One instruction as compiled.

    ``joints``: joints at the end of a motion, (6,) rad; ``path``: the sampled joint path of a
    motion including its start, (S, 6) rad; ``duration`` (s), ``path_length`` (m of TCP travel)
    and ``trajectory`` (the timed motion, to sample joints over time) are filled by the timing
    pass.
    """

    index: int
    instruction: Instruction
    joints: FloatArray | None = None
    path: FloatArray | None = None
    tool: Tool | None = None
    frame: Frame | None = None
    duration: float = 0.0
    path_length: float = 0.0
    trajectory: Segment | None = None
    skipped: bool = False


@dataclass(frozen=True, slots=True, eq=False)
class CompiledProgram:
    """A program resolved on a station: steps (one per instruction) and diagnostics."""

    program: Program
    station: Station
    start_joints: FloatArray
    steps: tuple[Step, ...]
    diagnostics: tuple[Diagnostic, ...] = field(default=())

    @property
    def ok(self) -> bool:
        """No error diagnostics: code may be written."""
        return not has_errors(self.diagnostics)

    @property
    def cycle_time(self) -> float:
        """Total estimated time, seconds."""
        return float(sum(s.duration for s in self.steps))

    def motion_steps(self) -> list[Step]:
        return [s for s in self.steps if is_motion(s.instruction)]

    @classmethod
    def start(cls, program: Program, station: Station) -> CompiledProgram:
        """``program`` before any pass: one empty step per instruction, starting at the
        robot's home joints."""
        steps = tuple(Step(index=i, instruction=ins) for i, ins in enumerate(program))
        return cls(program, station, station.robot.home.copy(), steps)

    def with_diagnostics(self, found: Iterable[Diagnostic]) -> CompiledProgram:
        """A copy with ``found`` appended to the diagnostics."""
        return dataclasses.replace(self, diagnostics=self.diagnostics + tuple(found))
