"""The pass pipeline: every pass is one function of one signature,
``(CompiledProgram, BuildOptions) -> CompiledProgram`` (its findings appended to the
diagnostics), and a pipeline is a tuple of them.

:data:`PIPELINE` is what ``olp build`` and ``olp check`` run (resolve, flow, collisions,
timing: ``olp check`` reports the cycle time too); :data:`CHECKS` is every check without timing,
for a caller that wants the checks only. A user or a later feature adds a pass by
writing one function and handing ``olp.compile(..., passes=(...))`` a tuple with it::

    def thin_points(compiled, options):
        ...
        return compiled.with_diagnostics(found)

    olp.compile(program, station, passes=(thin_points, *olp.passes.pipeline.PIPELINE))
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from olp import progress
from olp.compiled import CompiledProgram
from olp.ir import Program
from olp.passes.collide import CollisionOptions, collision_pass
from olp.passes.flow import flow_pass
from olp.passes.resolve import ResolveOptions, resolve_pass
from olp.passes.timing import TimingOptions, timing_pass
from olp.passes.timing.branches import path_timing_pass
from olp.passes.timing.conditions import Assumptions
from olp.station.model import Station


@dataclass(frozen=True, slots=True)
class BuildOptions:
    """What the passes are asked to do.

    ``resolve``: sampling, fallbacks and skipping of the resolve pass; ``collisions``: the
    collision check's options, or None to skip it; ``timing``: discretisation and solvers of the
    timing pass; ``other_times``: seconds per non-motion instruction kind or named call
    (``"call:NAME"``), over :data:`olp.passes.timing.DEFAULT_TIMES`; ``assume``: what the
    cycle time of a program with control flow may take as known (``--assume``: inputs,
    variables, loop counts; :mod:`olp.passes.timing.conditions`).
    """

    resolve: ResolveOptions = field(default_factory=ResolveOptions)
    collisions: CollisionOptions | None = field(default_factory=CollisionOptions)
    timing: TimingOptions = field(default_factory=TimingOptions)
    other_times: Mapping[str, float] = field(default_factory=dict)
    assume: Assumptions = field(default_factory=Assumptions)


Pass = Callable[[CompiledProgram, BuildOptions], CompiledProgram]
"""A pass: a compiled program and the build options in, a compiled program out."""

PIPELINE: tuple[Pass, ...] = (
    resolve_pass,
    flow_pass,
    collision_pass,
    timing_pass,
    path_timing_pass,
)
"""What a build runs."""

CHECKS: tuple[Pass, ...] = (resolve_pass, flow_pass, collision_pass)
"""Every check, no timing (``olp.compile(..., passes=CHECKS)``)."""


def run_passes(
    program: Program,
    station: Station,
    options: BuildOptions | None = None,
    passes: tuple[Pass, ...] = PIPELINE,
) -> CompiledProgram:
    """``program`` through ``passes`` in order, from :meth:`CompiledProgram.start`."""
    opts = options or BuildOptions()
    compiled = CompiledProgram.start(program, station)
    for step in passes:
        with progress.stage(_stage_name(step), len(compiled.steps)):
            compiled = step(compiled, opts)
    return compiled


def _stage_name(step: Pass) -> str:
    """How the progress display names a pass: ``resolve_pass`` -> ``resolve``."""
    name = getattr(step, "__name__", type(step).__name__)
    return name.removesuffix("_pass")
