"""Speed sweeps: cycle times over a grid of TCP speeds and joint speeds, each timing reusing
the program's plan."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from olp.compiled import CompiledProgram
from olp.ir import CircularMove, JointMove, LinearMove
from olp.passes.timing.plan import Context, TimingOptions, plan_units, tcp_lengths, time_table
from olp.passes.timing.program import time_units

FloatArray = NDArray[np.float64]


def override_speeds(
    compiled: CompiledProgram, linear: float | None = None, joint: float | None = None
) -> CompiledProgram:
    """A copy in which every path move runs at ``linear`` m/s and every joint move at ``joint``
    (fraction of the axes' maximum velocity); ``None`` keeps the programmed value. Acceleration
    and orientation-speed settings stay as programmed."""
    steps = []
    for step in compiled.steps:
        ins = step.instruction
        if isinstance(ins, LinearMove | CircularMove) and linear is not None:
            ins = dataclasses.replace(ins, speed=dataclasses.replace(ins.speed, linear=linear))
        elif isinstance(ins, JointMove) and joint is not None:
            ins = dataclasses.replace(ins, speed=dataclasses.replace(ins.speed, joint=joint))
        steps.append(dataclasses.replace(step, instruction=ins))
    program = compiled.program.replace_instructions([s.instruction for s in steps])
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
    """
    lengths = tcp_lengths(compiled)
    units = plan_units(compiled, lengths)
    context = Context(compiled, time_table(other_times), options or TimingOptions(), lengths)
    total = len(linear_speeds) + len(joint_speeds)
    parts: list[FloatArray] = []
    for kind, values, key in (("path", linear_speeds, "linear"), ("joint", joint_speeds, "joint")):
        chosen = [u for u in units if u.kind == kind]
        sums = []
        for value in values:
            retimed = dataclasses.replace(
                context, compiled=override_speeds(compiled, **{key: value})
            )
            steps, found = time_units(retimed, chosen)
            picked = [steps[i].duration for u in chosen for i in u.indices]
            sums.append(np.nan if found else float(np.sum(picked)))
            if progress is not None:
                progress(len(parts) * len(linear_speeds) + len(sums), total)
        parts.append(np.array(sums, dtype=np.float64))
    fixed = [u for u in units if u.kind == "fixed"]
    steps, _ = time_units(context, fixed)
    rest = float(sum(steps[i].duration for u in fixed for i in u.indices))
    table: FloatArray = parts[0][:, None] + parts[1][None, :] + rest
    return table
