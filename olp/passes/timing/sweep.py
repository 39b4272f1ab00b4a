"""Speed sweeps: cycle times over a grid of TCP speeds and joint speeds, each timing reusing
the program's table and plan."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from olp.compiled import CompiledProgram
from olp.ir import CircularMove, JointMove, LinearMove
from olp.passes.timing.plan import TimingOptions, time_table
from olp.passes.timing.program import Times, time_fixed, time_joints, time_paths
from olp.passes.timing.table import JOINT, MotionTable, plan, sample_positions, travel
from olp.transforms.blend import with_step_instructions

if TYPE_CHECKING:
    from olp.passes.pipeline import BuildOptions

FloatArray = NDArray[np.float64]


def override_speeds(
    compiled: CompiledProgram, linear: float | None = None, joint: float | None = None
) -> CompiledProgram:
    """A copy in which every path move runs at ``linear`` m/s and every joint move at ``joint``
    (fraction of the axes' maximum velocity); ``None`` keeps the programmed value. Acceleration
    and orientation-speed settings stay as programmed. A program with control flow keeps its
    blocks (:func:`~olp.transforms.blend.with_step_instructions`), so each path is timed as the
    program runs it."""

    steps = []
    for step in compiled.steps:
        ins = step.instruction
        if isinstance(ins, LinearMove | CircularMove) and linear is not None:
            ins = dataclasses.replace(ins, speed=dataclasses.replace(ins.speed, linear=linear))
        elif isinstance(ins, JointMove) and joint is not None:
            ins = dataclasses.replace(ins, speed=dataclasses.replace(ins.speed, joint=joint))
        steps.append(dataclasses.replace(step, instruction=ins))
    program = with_step_instructions(compiled.program, [s.instruction for s in steps])
    return dataclasses.replace(compiled, program=program, steps=tuple(steps))


def speed_sweep(
    compiled: CompiledProgram,
    linear_speeds: Sequence[float | None],
    joint_speeds: Sequence[float | None],
    other_times: Mapping[str, float] | None = None,
    options: TimingOptions | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> FloatArray:
    """Cycle times (L, J) s with every path move at ``linear_speeds[i]`` m/s and every joint
    move at ``joint_speeds[j]`` (fraction); ``None`` keeps the programmed speeds; NaN where a
    motion could not be timed.

    Path chains never contain joint moves, so the path time depends only on the linear speed and
    the joint-move time only on the joint speed: L + J timings give the L x J table.
    A program with control flow is timed as its text (each instruction once, every branch):
    :func:`path_sweep` times it per path.
    """
    table = MotionTable.of(compiled)
    positions = sample_positions(table, compiled.station.robot)
    lengths = travel(table, compiled.station.robot, positions)
    corners = plan(table, lengths)
    opts = options or TimingOptions()
    total, done = len(linear_speeds) + len(joint_speeds), 0

    def timed(value: float | None, joint: bool) -> float:
        nonlocal done
        times = Times(table.size)
        if joint:
            found = time_joints(table.with_speeds(None, value), lengths, times)
        else:
            paths = table.with_speeds(value, None)
            found = time_paths(paths, lengths, corners, opts, times, positions)
        done += 1
        if progress is not None:
            progress(done, total)
        rows = table.kind == JOINT if joint else table.path
        return np.nan if found else float(np.sum(times.duration[rows]))

    paths = np.array([timed(value, False) for value in linear_speeds], dtype=np.float64)
    joints = np.array([timed(value, True) for value in joint_speeds], dtype=np.float64)
    fixed = Times(table.size)
    time_fixed(table, time_table(other_times), fixed)
    out: FloatArray = paths[:, None] + joints[None, :] + float(np.sum(fixed.duration))
    return out


def path_sweep(
    compiled: CompiledProgram,
    linear_speeds: Sequence[float | None],
    joint_speeds: Sequence[float | None],
    options: BuildOptions,
    progress: Callable[[int, int], None] | None = None,
) -> FloatArray:
    """The shortest and the longest path (:func:`olp.passes.timing.branches.path_times`) of a
    program with control flow, (L, J, 2) s, with the speeds of :func:`speed_sweep`; the
    options' ``assume`` names a path (both ends equal then). NaN where a motion could not be
    timed or no path reaches the end. One full timing per cell (L x J): a branch mixes path and
    joint moves, so the cells do not separate as in :func:`speed_sweep`."""
    from olp.passes.timing.branches import path_times
    from olp.passes.timing.program import time_program

    out = np.full((len(linear_speeds), len(joint_speeds), 2), np.nan)
    total = out.shape[0] * out.shape[1]
    for i, linear in enumerate(linear_speeds):
        for j, joint in enumerate(joint_speeds):
            swept = override_speeds(compiled, linear, joint)
            timed = time_program(swept, options.other_times, options.timing)
            if timed.ok:
                paths = path_times(timed, options, options.assume)
                if paths.shortest is not None and paths.longest is not None:
                    out[i, j] = paths.shortest.seconds, paths.longest.seconds
            if progress is not None:
                progress(i * out.shape[1] + j + 1, total)
    return out
