"""Blend-radius capping: neighbouring blends never overlap, and the robot stops where it must.

A blend (zone) of radius ``r`` around a target starts the next motion once the TCP is within
``r`` of the target. Universal Robots' controller skips moves whose blend regions overlap
("Overlapping Blends", project vendor notes), so a URScript program must keep
``r_i + r_(i+1) <= |P_(i+1) - P_i|`` for consecutive targets and ``r = 0`` on the last move. Any
post whose controller has distance blends may use the same rule.

Rule (olp's choice, deterministic and symmetric)
------------------------------------------------
For consecutive emitted motion targets ``P_1 .. P_N`` (TCP positions in the world, m) after the
start ``P_0`` (the TCP at the program's start joints), with ``L_i = |P_i - P_(i-1)|``::

    r_i' = min(r_i, L_i / k_(i-1), L_(i+1) / k_(i+1)),   k_j = 2 if target j blends, else 1

so two blending neighbours share the segment between them half and half, and a blend next to
an exact stop may take the whole segment. Then ``r_i' + r_(i+1)' <= L_(i+1)`` and
``r_i' <= L_i`` hold for every target. The distance is the straight line between targets: the
blend regions are spheres around them, and spheres overlap exactly when the distance of the
centres is below the sum of the radii, whatever path (line, arc, joint move) joins them.

A target where the robot has to be at rest gets ``r = 0``: the program's last motion, and a
motion followed (before the next motion) by a :class:`~olp.ir.Wait`, a
:class:`~olp.ir.WaitInput` or a :class:`~olp.ir.Call` (a dwell, a handshake, or code olp cannot
see). :class:`~olp.ir.SetOutput` and :class:`~olp.ir.Comment` do not stop the robot.

Two entry points share the rule: :func:`cap_blends` (compiled -> compiled, with a warning
diagnostic per reduced radius) and :func:`blend_radii` (the radii only, for a post's template
view of the steps).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from olp.compiled import CompiledProgram
from olp.diagnostics import Diagnostic
from olp.ir import Call, Instruction, Wait, WaitInput, is_motion
from olp.station.model import Robot

FloatArray = NDArray[np.float64]

STOP_TYPES = (Wait, WaitInput, Call)
"""Instructions that need the robot at rest before them."""


class StepLike(Protocol):
    """What the rule reads of a step: :class:`olp.compiled.Step` and
    :class:`olp.posts.view.PostStep` both fit."""

    @property
    def index(self) -> int: ...

    @property
    def instruction(self) -> Any: ...

    @property
    def joints(self) -> FloatArray | None: ...

    @property
    def tool(self) -> Any: ...


@dataclass(frozen=True, slots=True)
class CappedRadius:
    """One motion's blend: the instruction ``index``, the ``requested`` and ``radius`` (capped)
    in metres, and ``reason`` (empty when unchanged)."""

    index: int
    requested: float
    radius: float
    reason: str = ""


def capped_radii(
    start: FloatArray, positions: FloatArray, radii: FloatArray, stops: NDArray[np.bool_]
) -> tuple[FloatArray, list[str]]:
    """The rule of this module on arrays.

    Parameters
    ----------
    start : (3,) m, the TCP before the first target.
    positions : (N, 3) m, the targets' TCP positions.
    radii : (N,) m, requested blend radii.
    stops : (N,) bool, targets where the robot must be at rest.

    Returns
    -------
    The capped radii (N,) m and, per target, why it was reduced ("" when it was not).
    """
    n = positions.shape[0]
    points = np.vstack([start[None], positions])
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=-1)
    wanted = np.where(stops, 0.0, radii)
    blends = wanted > 0
    prev_k = np.where(np.concatenate([[False], blends[:-1]]), 2.0, 1.0)
    next_len = np.concatenate([lengths[1:], [np.inf]])
    next_k = np.where(np.concatenate([blends[1:], [False]]), 2.0, 1.0)
    by_prev, by_next = lengths / prev_k, next_len / next_k
    out = np.minimum(wanted, np.minimum(by_prev, by_next))
    reasons = [
        _reason(radii[i], out[i], stops[i], by_prev[i], by_next[i], prev_k[i], next_k[i])
        for i in range(n)
    ]
    return out, reasons


def _reason(
    asked: float, got: float, stop: bool, by_prev: float, by_next: float, pk: float, nk: float
) -> str:
    if got >= asked:
        return ""
    if stop:
        return "the robot stops at this target (last motion, or a wait or call follows)"
    if by_prev <= by_next:
        share = "half " if pk == 2 else ""
        return f"{share}the distance from the previous target ({by_prev * pk * 1000:.1f} mm)"
    share = "half " if nk == 2 else ""
    return f"{share}the distance to the next target ({by_next * nk * 1000:.1f} mm)"


def blend_radii(
    steps: Sequence[StepLike], robot: Robot, start_joints: FloatArray
) -> list[CappedRadius]:
    """Capped blend radii of the emitted motions of ``steps`` (in order).

    ``steps``: instructions in program order; a motion without joints (not emitted) is left
    out. ``start_joints``: (dof,) rad, where the program starts (for the first segment).
    """
    steps = list(steps)  # a toolpath's rows are made into steps once
    motions = [s for s in steps if is_motion(s.instruction) and s.joints is not None]
    if not motions:
        return []
    stops = _stop_flags(steps, {s.index for s in motions})
    joints = np.stack([np.asarray(s.joints, dtype=np.float64) for s in motions])
    tools = np.stack([np.asarray(s.tool.pose, dtype=np.float64) for s in motions])
    tcp = robot.flange_poses(joints) @ tools
    start = (robot.flange_poses(start_joints) @ tools[0])[:3, 3]
    radii = np.array([float(s.instruction.zone.radius) for s in motions])
    capped, reasons = capped_radii(start, tcp[:, :3, 3], radii, stops)
    return [
        CappedRadius(s.index, float(r), float(c), why)
        for s, r, c, why in zip(motions, radii, capped, reasons, strict=True)
    ]


def _stop_flags(steps: Sequence[StepLike], motions: set[int]) -> NDArray[np.bool_]:
    """Per emitted motion (``motions``: their instruction indices): is it the last one, or
    followed by a stop instruction before the next emitted motion?"""
    flags: list[bool] = []
    for step in steps:
        if step.index in motions:
            flags.append(False)
        elif flags and isinstance(step.instruction, STOP_TYPES):
            flags[-1] = True
    if flags:
        flags[-1] = True
    return np.array(flags, dtype=bool)


def cap_blends(compiled: CompiledProgram) -> tuple[CompiledProgram, list[Diagnostic]]:
    """The compiled program with every blend radius capped (zones replaced in the program and
    its steps), and one warning diagnostic (kind ``blend_capped``) per reduced radius."""
    caps = blend_radii(compiled.steps, compiled.station.robot, compiled.start_joints)
    changed = {c.index: c for c in caps if c.reason}
    if not changed:
        return compiled, []
    steps = tuple(
        dataclasses.replace(s, instruction=_with_radius(s.instruction, changed[s.index].radius))
        if s.index in changed
        else s
        for s in compiled.steps
    )
    program = with_step_instructions(compiled.program, [s.instruction for s in steps])
    capped = dataclasses.replace(compiled, program=program, steps=steps)
    return capped, [_diagnostic(c, compiled.steps[c.index].instruction) for c in changed.values()]


def with_step_instructions(program: Any, instructions: list[Any]) -> Any:
    """``program`` with its instructions replaced, in order, by ``instructions`` (one per step);
    the blocks of a program with control flow are kept (a flat list would drop them, and write
    every branch's body unconditionally)."""
    if not program.has_flow:
        return program.replace_instructions(instructions)
    from olp.ir import LinearPath
    from olp.ir_flow import map_leaves

    rest = iter(instructions)

    def edit(node: Any) -> list[Any]:
        count = len(node) if isinstance(node, LinearPath) else 1
        return [next(rest) for _ in range(count)]

    return program.replace_instructions(map_leaves(program.instructions, edit))


def _with_radius(instruction: Any, radius: float) -> Instruction:
    zone = dataclasses.replace(instruction.zone, radius=radius)
    replaced: Instruction = dataclasses.replace(instruction, zone=zone)
    return replaced


def _diagnostic(cap: CappedRadius, instruction: Any) -> Diagnostic:
    return Diagnostic(
        "warning",
        "blend_capped",
        f"blend radius {cap.requested * 1000:.1f} mm reduced to {cap.radius * 1000:.1f} mm: "
        f"{cap.reason}",
        instruction.span,
        cap.index,
        hint="blend regions of neighbouring targets must not overlap (the controller would "
        "skip moves); use smaller zones or targets further apart",
    )
