"""Timing a program that arrives in windows (a streamed build, :mod:`olp.stream`), so that a
window boundary is not a stop.

Rows that stop (a zone of 0: a fine point) are timed alone, so a boundary after one needs
nothing carried across it. Where the last row of a window blends into the next window's first
row, the boundary lies inside a chain of blended moves, whose time law depends on what comes
before and after it. :class:`WindowTimer` then times the window together with *context*: the
last rows of the window before it and the first rows of the window after it (at least
``context_m`` of TCP travel on each side, whole windows at most), as one program, and keeps the
window's own rows. The chain is then cut only inside the context, where the robot starts from
rest and stops at rest: the time law of the window's rows is the one-piece law wherever the
braking or accelerating from a cut does not reach the window (the solver's speed profile from a
later start meets the one from an earlier start once both run at the speed limit, and a stop
further on only lowers speeds within its braking distance). The default context (0.2 m, or
twice the braking distance from the highest programmed speed at the robot's path
acceleration, whichever is longer) keeps the cut well outside that reach; the grid refinement
and jerk smoothing of the solver are per chain, so the cycle time agrees with the one-piece
build to a small tolerance rather than bit for bit (``tests/test_stream.py`` pins it).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from olp.compiled import CompiledProgram, Item, PathBlock, items_of, make_steps
from olp.diagnostics import Diagnostic
from olp.passes.timing.plan import TimingOptions
from olp.passes.timing.program import time_program

FloatArray = NDArray[np.float64]

CONTEXT_M = 0.2
"""Least TCP travel (m) of context timed on each side of a blended window boundary."""

_DEFAULT_PATH_ACCELERATION = 1.0
"""m/s²: the braking the context allows for when the robot states no path acceleration."""


def block_rows(block: PathBlock, lo: int, hi: int, start: int) -> PathBlock:
    """Rows ``lo`` to ``hi`` (exclusive) of a resolved, untimed-or-timed block as a block of
    their own starting at instruction ``start`` (their joint path from the joints before row
    ``lo``); timing results are dropped."""
    assert block.path is not None and block.ends is not None and block.joints is not None
    first = 0 if lo == 0 else int(block.ends[lo - 1])
    last = int(block.ends[hi - 1])
    return dataclasses.replace(
        block,
        start=start,
        node=block.node.rows(lo, hi),
        joints=block.joints[lo:hi],
        path=block.path[first : last + 1],
        ends=block.ends[lo:hi] - first,
        durations=None,
        lengths=None,
        trajectories=None,
    )


def travel_rows(block: PathBlock, travel_m: float, from_end: bool) -> int:
    """How many rows at the end (``from_end``) or the start of ``block`` cover at least
    ``travel_m`` of straight-line TCP travel between targets (all rows if they do not)."""
    positions = block.node.poses[:, :3, 3]
    if from_end:
        positions = positions[::-1]
    steps = np.linalg.norm(np.diff(positions, axis=0), axis=-1)
    reached = np.flatnonzero(np.cumsum(steps) >= travel_m)
    return len(block) if reached.size == 0 else int(reached[0]) + 2


def shifted(item: Item, offset: int) -> Item:
    """``item`` with its instruction index moved by ``offset``."""
    if isinstance(item, PathBlock):
        return dataclasses.replace(item, start=item.start + offset)
    return dataclasses.replace(item, index=item.index + offset)


def _blends_out(items: Sequence[Item]) -> bool:
    """Whether the last item is a resolved toolpath block whose last row keeps a zone."""
    last = items[-1] if items else None
    return (
        isinstance(last, PathBlock) and last.path is not None and float(last.node.zones[-1]) > 0.0
    )


def _starts_with_block(items: Sequence[Item]) -> bool:
    first = items[0] if items else None
    return isinstance(first, PathBlock) and first.path is not None


class WindowTimer:
    """Times the windows of a streamed program in order: :meth:`push` each window (untimed,
    instruction indices from 0) and get the one before it back timed; :meth:`finish` gives the
    last. Diagnostics of the timing are the window's own (indices within it)."""

    def __init__(
        self,
        other_times: Mapping[str, float] | None,
        options: TimingOptions,
        path_acceleration: float | None = None,
        context_m: float = CONTEXT_M,
    ) -> None:
        self.other_times = other_times
        self.options = options
        self.accel = path_acceleration or _DEFAULT_PATH_ACCELERATION
        self.context_m = context_m
        self._pending: CompiledProgram | None = None
        self._before: list[Item] = []

    def push(self, window: CompiledProgram) -> CompiledProgram | None:
        """Take the next window; returns the previous one timed (None for the first)."""
        done = None
        if self._pending is not None:
            done = self._time(self._pending, items_of(window.steps))
        self._pending = window
        return done

    def finish(self) -> CompiledProgram | None:
        """The last window, timed (None if no window came)."""
        if self._pending is None:
            return None
        done = self._time(self._pending, ())
        self._pending = None
        return done

    def _time(self, window: CompiledProgram, following: Sequence[Item]) -> CompiledProgram:
        items = items_of(window.steps)
        before = self._before if _starts_with_block(items) else []
        after: list[Item] = []
        if _blends_out(items) and _starts_with_block(following):
            after = self._context(following, from_end=False)
        self._before = self._context(items, from_end=True) if _blends_out(items) else []
        if not before and not after:
            return time_program(window, self.other_times, self.options)
        return self._with_context(window, items, before, after)

    def _reach(self, block: PathBlock) -> float:
        """The context (m of TCP travel) to time beyond a boundary inside ``block``'s chain."""
        speed = float(np.max(block.node.speeds))
        return max(self.context_m, speed * speed / self.accel)

    def _context(self, items: Sequence[Item], from_end: bool) -> list[Item]:
        """Rows next to a boundary, from the resolved blocks at the end (``from_end``) or the
        start of ``items``, covering the context's TCP travel; their instruction indices
        from 0, in order."""
        order = reversed(items) if from_end else iter(items)
        taken: list[PathBlock] = []
        left = None
        for item in order:
            if not isinstance(item, PathBlock) or item.path is None:
                break
            reach = self._reach(item) if left is None else left
            count = travel_rows(item, reach, from_end)
            lo, hi = (len(item) - count, len(item)) if from_end else (0, count)
            taken.append(block_rows(item, lo, hi, 0))
            positions = item.node.poses[lo:hi, :3, 3]
            left = reach - float(np.sum(np.linalg.norm(np.diff(positions, axis=0), axis=-1)))
            if count < len(item) or left <= 0.0:
                break
        if from_end:
            taken.reverse()
        out: list[Item] = []
        start = 0
        for block in taken:
            out.append(shifted(block, start))
            start += len(block)
        return out

    def _with_context(
        self,
        window: CompiledProgram,
        items: Sequence[Item],
        before: Sequence[Item],
        after: Sequence[Item],
    ) -> CompiledProgram:
        lead = sum(len(b) if isinstance(b, PathBlock) else 1 for b in before)
        size = len(window.steps)
        joined = [
            *before,
            *(shifted(item, lead) for item in items),
            *(shifted(item, lead + size) for item in after),
        ]
        start = _start_joints(before, window)
        combined = dataclasses.replace(
            window, steps=make_steps(joined), diagnostics=(), start_joints=start
        )
        timed = time_program(combined, self.other_times, self.options)
        own = [
            shifted(item, -lead)
            for item in items_of(timed.steps)
            if lead <= (item.start if isinstance(item, PathBlock) else item.index) < lead + size
        ]
        found = [_moved(d, -lead) for d in timed.diagnostics if _inside(d, lead, lead + size)]
        return dataclasses.replace(
            window, steps=make_steps(own), diagnostics=window.diagnostics + tuple(found)
        )


def _start_joints(before: Sequence[Item], window: CompiledProgram) -> FloatArray:
    if before:
        first = before[0]
        assert isinstance(first, PathBlock) and first.path is not None
        return np.array(first.path[0])
    return window.start_joints


def _inside(found: Diagnostic, lo: int, hi: int) -> bool:
    return found.index is None or lo <= found.index < hi


def _moved(found: Diagnostic, offset: int) -> Diagnostic:
    if found.index is None:
        return found
    return dataclasses.replace(found, index=found.index + offset)
