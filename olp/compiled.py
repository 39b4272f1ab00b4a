"""A program compiled on a station: :class:`CompiledProgram`, one :class:`Step` per instruction.

This is what the passes hand on (:mod:`olp.passes`): :meth:`CompiledProgram.start` makes the
unresolved form (one empty step per instruction), the resolve pass fills joints, paths, tools and
frames, checks append diagnostics, the timing pass fills durations and trajectories. Posts render
from it. Its own module, so that the passes, the trajectory sampler and the posts can name it
without importing one another.

A dense toolpath (:class:`olp.ir.LinearPath`) is compiled as dense too: its rows are a
:class:`PathBlock` (arrays: end joints, the sampled joint path, durations, ...) and the program's
``steps`` a :class:`StepBlocks`, a sequence of steps that makes the :class:`Step` of a row only
when asked for it. Code that walks ``compiled.steps`` sees one step per instruction either way;
passes that work on arrays take ``steps.blocks``.
"""

from __future__ import annotations

import bisect
import dataclasses
import gc
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, overload

import numpy as np
from numpy.typing import NDArray

from olp.diagnostics import Diagnostic, has_errors
from olp.ir import Frame, Instruction, LinearPath, Program, Tool, is_motion

if TYPE_CHECKING:
    from collections.abc import Iterable

    from olp.passes.timing.branches import PathTimes
    from olp.span import SourceSpan
    from olp.station.model import Station
    from olp.trajectory import Segment, TimeLaw

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


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
class PathBlock:
    """The compiled rows of a :class:`~olp.ir.LinearPath`: row ``k`` is instruction
    ``start + k``.

    ``tool``/``frame``: resolved (None: not found in the station); ``joints`` (N, dof) rad: the
    joints at the end of each row; ``path`` (S + 1, dof) rad: the sampled joint path of all rows
    from the joints before row 0 (row 0 of ``path``); ``ends`` (N,): the row of ``path`` where
    each row ends (row ``k`` runs from ``ends[k - 1]``, or 0, to ``ends[k]``). None until the
    resolve pass resolved the block (a block is resolved as a whole: rows that fail are split
    off into ordinary steps). ``durations`` and ``lengths`` (N,): seconds and metres of TCP
    travel per row (zeros until timed); ``trajectories``: per-row time laws, or None.
    """

    start: int
    node: LinearPath
    tool: Tool | None = None
    frame: Frame | None = None
    joints: FloatArray | None = None
    path: FloatArray | None = None
    ends: IntArray | None = None
    durations: FloatArray | None = None
    lengths: FloatArray | None = None
    trajectories: RowTrajectories | None = None

    def __len__(self) -> int:
        return len(self.node)

    @property
    def stop(self) -> int:
        """The instruction index after the block's last row."""
        return self.start + len(self.node)

    def row_path(self, k: int) -> FloatArray | None:
        """Row ``k``'s joint path (S_k + 1, dof), its start included, or None."""
        if self.path is None or self.ends is None:
            return None
        lo = 0 if k == 0 else int(self.ends[k - 1])
        return self.path[lo : int(self.ends[k]) + 1]

    def steps(self) -> list[Step]:
        """Every row as an ordinary :class:`Step` (:meth:`step` of each, its arrays read once:
        row values as Python numbers, the shared tool and frame as they are)."""
        n = len(self.node)
        joints = [None] * n if self.joints is None else list(self.joints)
        ends = None if self.ends is None else [0, *self.ends.tolist()]
        durations = [0.0] * n if self.durations is None else self.durations.tolist()
        lengths = [0.0] * n if self.lengths is None else self.lengths.tolist()
        rows = self.trajectories
        segments = [None] * n if rows is None else rows.segments()
        move, path, tool, frame = self.node.move, self.path, self.tool, self.frame
        start = self.start
        return [
            Step(
                index=start + k,
                instruction=move(k),
                joints=joints[k],
                path=None if path is None or ends is None else path[ends[k] : ends[k + 1] + 1],
                tool=tool,
                frame=frame,
                duration=durations[k],
                path_length=lengths[k],
                trajectory=segments[k],
            )
            for k in range(n)
        ]

    def step(self, k: int) -> Step:
        """Row ``k`` as an ordinary :class:`Step`."""
        trajectory = None if self.trajectories is None else self.trajectories.segment(k)
        return Step(
            index=self.start + k,
            instruction=self.node.move(k),
            joints=None if self.joints is None else self.joints[k],
            path=self.row_path(k),
            tool=self.tool,
            frame=self.frame,
            duration=0.0 if self.durations is None else float(self.durations[k]),
            path_length=0.0 if self.lengths is None else float(self.lengths[k]),
            trajectory=trajectory,
        )


@dataclass(frozen=True, slots=True, eq=False)
class BlockRows:
    """Rows ``lo`` to ``hi`` (exclusive) of a :class:`PathBlock`: the piece of a toolpath that
    one file of a split program writes, without a :class:`Step` per row."""

    block: PathBlock
    lo: int
    hi: int
    skipped: bool = False

    @property
    def index(self) -> int:
        """The instruction index of the first row."""
        return self.block.start + self.lo

    def __len__(self) -> int:
        return self.hi - self.lo


def pieces(
    items: Sequence[Item], bounds: Sequence[tuple[int, int]]
) -> list[list[Step | BlockRows]]:
    """The steps and block rows of each half-open instruction range ``bounds[k]`` (in order,
    covering ``items``): a block cut by a bound is two :class:`BlockRows`."""
    out: list[list[Step | BlockRows]] = []
    k = 0
    for a, b in bounds:
        part: list[Step | BlockRows] = []
        while k < len(items):
            item = items[k]
            if isinstance(item, PathBlock):
                lo, hi = max(a, item.start), min(b, item.stop)
                if lo < hi:
                    part.append(BlockRows(item, lo - item.start, hi - item.start))
                if item.stop > b:
                    break
            elif item.index < b:
                part.append(item)
            else:
                break
            k += 1
        out.append(part)
    return out


class RowTrajectories:
    """The time laws of a block's rows: row ``k`` is :meth:`segment` ``(k)``, the window
    ``start[k]..end[k]`` (s) of law ``laws[law[k]]`` (several rows share one law where they are
    blended into a chain; ``law[k]`` -1: the row was not timed)."""

    def __init__(self, laws: Sequence[TimeLaw], law: IntArray, start: FloatArray, end: FloatArray):
        self.laws, self.law, self.start, self.end = laws, law, start, end

    def segment(self, k: int) -> Segment | None:
        from olp.trajectory import Segment

        if self.law[k] < 0:
            return None
        return Segment(self.laws[int(self.law[k])], float(self.start[k]), float(self.end[k]))

    def segments(self) -> list[Segment | None]:
        """:meth:`segment` of every row, the arrays read once (a law shared by several rows,
        a blended chain's, is one object)."""
        from olp.trajectory import Segment

        laws, made = self.laws, dict[int, Any]()
        out: list[Segment | None] = []
        for law, start, end in zip(
            self.law.tolist(), self.start.tolist(), self.end.tolist(), strict=True
        ):
            if law < 0:
                out.append(None)
                continue
            if law not in made:
                made[law] = laws[law]
            out.append(Segment(made[law], start, end))
        return out


Item = Step | PathBlock
"""What a dense program's steps hold: a step, or a block of a toolpath's rows."""


class StepBlocks(Sequence[Step]):
    """The steps of a program with dense toolpaths: ordinary steps and :class:`PathBlock`\\ s
    (``blocks``), read as one :class:`Step` per instruction, each made when asked for."""

    def __init__(self, blocks: Sequence[Item]) -> None:
        self.blocks: tuple[Item, ...] = tuple(blocks)
        self._starts = [b.start if isinstance(b, PathBlock) else b.index for b in self.blocks]
        last = self.blocks[-1] if self.blocks else None
        self._len = (
            0 if last is None else (last.stop if isinstance(last, PathBlock) else last.index + 1)
        )

    def __len__(self) -> int:
        return self._len

    @overload
    def __getitem__(self, index: int) -> Step: ...

    @overload
    def __getitem__(self, index: slice) -> Sequence[Step]: ...

    def __getitem__(self, index: int | slice) -> Step | Sequence[Step]:
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(self._len))]
        if index < 0:
            index += self._len
        item = self.item_at(index)
        return item.step(index - item.start) if isinstance(item, PathBlock) else item

    def item_at(self, index: int) -> Item:
        """The step, or the block, that holds instruction ``index``."""
        if not 0 <= index < self._len:
            raise IndexError(index)
        return self.blocks[bisect.bisect_right(self._starts, index) - 1]

    def __iter__(self) -> Iterator[Step]:
        for item in self.blocks:
            if isinstance(item, PathBlock):
                yield from item.steps()
            else:
                yield item


def make_steps(items: Sequence[Item]) -> tuple[Step, ...] | StepBlocks:
    """Steps from ordinary steps and blocks: a plain tuple when there is no block."""
    if any(isinstance(item, PathBlock) for item in items):
        return StepBlocks(items)
    return tuple(item for item in items if isinstance(item, Step))


def span_of(steps: Sequence[Step], index: int) -> SourceSpan:
    """The source span of instruction ``index``, without making a toolpath row's step."""
    if isinstance(steps, StepBlocks):
        item = steps.item_at(index)
        if isinstance(item, PathBlock):
            return item.node.row_span(index - item.start)
        return item.instruction.span
    return steps[index].instruction.span


def items_of(steps: Sequence[Step]) -> tuple[Item, ...]:
    """The steps and blocks behind ``steps`` (a :class:`StepBlocks` or any sequence of steps)."""
    return steps.blocks if isinstance(steps, StepBlocks) else tuple(steps)


@dataclass(frozen=True, slots=True, eq=False)
class CompiledProgram:
    """A program resolved on a station: steps (one per instruction) and diagnostics;
    ``paths``: for a program with control flow, its cycle time per path (the timing pass's
    :func:`~olp.passes.timing.branches.path_times`), else None."""

    program: Program
    station: Station
    start_joints: FloatArray
    steps: Sequence[Step]
    diagnostics: tuple[Diagnostic, ...] = field(default=())
    paths: PathTimes | None = None

    @property
    def ok(self) -> bool:
        """No error diagnostics: code may be written."""
        return not has_errors(self.diagnostics)

    @property
    def cycle_time(self) -> float:
        """Total estimated time, seconds."""
        total = 0.0
        for item in items_of(self.steps):
            if isinstance(item, PathBlock):
                total += 0.0 if item.durations is None else float(np.sum(item.durations))
            else:
                total += item.duration
        return total

    def motion_steps(self) -> list[Step]:
        return [s for s in self.steps if is_motion(s.instruction)]

    @classmethod
    def start(cls, program: Program, station: Station) -> CompiledProgram:
        """``program`` before any pass: one empty step per instruction, starting at the
        robot's home joints. The program is taken with its calls expanded
        (:meth:`olp.ir.Program.expanded`): an instruction of a routine has a step at every
        call site."""
        program = program.expanded()
        items: list[Item] = []
        index = 0
        for node in program.flat_nodes():
            if isinstance(node, LinearPath):
                items.append(PathBlock(index, node))
                index += len(node)
            else:
                items.append(Step(index=index, instruction=node))
                index += 1
        return cls(program, station, station.robot.home.copy(), make_steps(items))

    def flat(self) -> CompiledProgram:
        """A copy whose steps are a tuple, a toolpath's rows made into steps once (for code that
        walks the steps several times, such as a post's templates)."""
        if isinstance(self.steps, tuple):
            return self
        # A toolpath's rows are many small objects without cycles: the cyclic collector's
        # passes over them while they are made cost ~40% of making them (100,000 rows).
        was_enabled = gc.isenabled()
        gc.disable()
        try:
            steps = tuple(self.steps)
        finally:
            if was_enabled:
                gc.enable()
        return dataclasses.replace(self, steps=steps)

    def with_diagnostics(self, found: Iterable[Diagnostic]) -> CompiledProgram:
        """A copy with ``found`` appended to the diagnostics."""
        return dataclasses.replace(self, diagnostics=self.diagnostics + tuple(found))
