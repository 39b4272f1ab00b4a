"""The timing pass itself: every unit of a program timed by its timer, the steps filled with
durations, path lengths and trajectories, and what could not be timed as diagnostics."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from olp.compiled import CompiledProgram, Step
from olp.diagnostics import Diagnostic
from olp.passes.timing.chains import time_chains
from olp.passes.timing.lines import time_lines
from olp.passes.timing.plan import (
    Context,
    TimingError,
    TimingOptions,
    Unit,
    plan_units,
    tcp_lengths,
    time_fixed,
    time_table,
    zone_stops,
)
from olp.passes.timing.ptp import time_joint

if TYPE_CHECKING:
    from olp.passes.pipeline import BuildOptions


FloatArray = NDArray[np.float64]


def time_program(
    compiled: CompiledProgram,
    other_times: Mapping[str, float] | None = None,
    options: TimingOptions | None = None,
) -> CompiledProgram:
    """A copy of ``compiled`` whose steps carry ``duration`` (s), ``path_length`` (m of TCP
    travel) and, for motions, ``trajectory`` (a :class:`olp.trajectory.Segment`).

    Zones timed as stops add an ``info`` diagnostic (kind ``zone_stop``); a motion that cannot
    be timed keeps duration 0 and adds an ``error`` (kind ``timing``). Never raises on a bad
    program.
    """
    lengths = tcp_lengths(compiled)
    units = plan_units(compiled, lengths)
    context = Context(compiled, time_table(other_times), options or TimingOptions(), lengths)
    steps, found = time_units(context, units)
    found += _overflow(steps)
    return dataclasses.replace(
        compiled,
        steps=tuple(steps),
        diagnostics=compiled.diagnostics + tuple(found) + tuple(zone_stops(compiled, units)),
    )


def _overflow(steps: Sequence[Step]) -> list[Diagnostic]:
    """An error at the instruction where the running cycle time stops being a finite number
    (each duration is finite, their sum need not be: two waits of 1e308 s)."""
    with np.errstate(over="ignore"):
        total = np.cumsum([step.duration for step in steps])
    bad = np.flatnonzero(~np.isfinite(total))
    if bad.size == 0:
        return []
    step = steps[int(bad[0])]
    msg = "the cycle time up to here exceeds the largest number olp can represent"
    return [Diagnostic("error", "timing", msg, step.instruction.span, step.index)]


def time_units(context: Context, units: Sequence[Unit]) -> tuple[list[Step], list[Diagnostic]]:
    steps = list(context.compiled.steps)
    lines, rest = time_lines(context, units)
    chains, found = time_chains(context, [u for u in rest if u.kind == "path"])
    for step in lines + chains:
        steps[step.index] = step
    for unit in rest:
        if unit.kind == "path":
            continue
        try:
            for step in _UNIT_TIMERS[unit.kind](unit, context):
                steps[step.index] = step
        except TimingError as exc:
            first = steps[unit.indices[0]].instruction
            found.append(Diagnostic("error", "timing", str(exc), first.span, unit.indices[0]))
    return steps, sorted(found, key=lambda d: d.index if d.index is not None else -1)


_UNIT_TIMERS: dict[str, Callable[[Unit, Context], list[Step]]] = {
    "fixed": time_fixed,
    "joint": time_joint,
}
"""Timers of single units; path units are timed together (:func:`time_chains`)."""


def timing_pass(compiled: CompiledProgram, options: BuildOptions) -> CompiledProgram:
    """The timing pass: :func:`time_program` with ``options.other_times`` and
    ``options.timing``; a program with errors is not timed (nothing will run)."""
    if not compiled.ok:
        return compiled
    return time_program(compiled, options.other_times, options.timing)
