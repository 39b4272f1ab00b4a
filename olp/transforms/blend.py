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

Entry points share the rule: :func:`cap_blends` (compiled -> compiled, with a warning
diagnostic per reduced radius), :func:`blend_columns` (the radii as arrays) and
:func:`blend_radii` (one object per motion, for a post's template view of the steps). A dense
toolpath's rows are read as arrays, never made into a step each: its radii are capped as
columns, the same numbers as for the same moves given one by one
(``tests/transforms/test_blend_columns.py``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from olp.compiled import (
    BlockRows,
    CompiledProgram,
    Item,
    PathBlock,
    items_of,
    make_steps,
    span_of,
)
from olp.diagnostics import Diagnostic
from olp.ir import Call, Instruction, LinearPath, Wait, WaitInput, is_motion
from olp.ir_flow import map_leaves
from olp.station.model import Robot

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

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


@dataclass(frozen=True, slots=True, eq=False)
class BlendColumns:
    """The capped blends of a program's emitted motions as columns (M,): ``index`` (the
    instructions), ``requested`` and ``radius`` (capped) in metres, ``reasons`` (why a radius
    was reduced, "" where it was not)."""

    index: IntArray
    requested: FloatArray
    radius: FloatArray
    reasons: list[str]

    @property
    def reduced(self) -> IntArray:
        """Positions (K,) of the motions whose radius was reduced."""
        return np.flatnonzero(~(self.radius >= self.requested))


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
    reasons = [""] * n
    for i in np.flatnonzero(~(out >= radii)).tolist():
        reasons[i] = _reason(
            radii[i], out[i], stops[i], by_prev[i], by_next[i], prev_k[i], next_k[i]
        )
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


def blend_radii(steps: Iterable[Any], robot: Robot, start_joints: FloatArray) -> list[CappedRadius]:
    """Capped blend radii of the emitted motions of ``steps`` (in order), one object each
    (:func:`blend_columns` gives them as arrays)."""
    found = blend_columns(steps, robot, start_joints)
    columns = (found.index.tolist(), found.requested.tolist(), found.radius.tolist())
    rows = zip(*columns, found.reasons, strict=True)
    return [CappedRadius(i, r, c, why) for i, r, c, why in rows]


def blend_columns(items: Iterable[Any], robot: Robot, start_joints: FloatArray) -> BlendColumns:
    """Capped blend radii of the emitted motions of ``items``, as arrays.

    ``items``: instructions in program order: steps (:class:`StepLike`), and a toolpath's rows
    as a :class:`~olp.compiled.PathBlock` or :class:`~olp.compiled.BlockRows` (read as arrays,
    no step made per row). A motion without joints (not emitted) is left out.
    ``start_joints``: (dof,) rad, where the program starts (for the first segment).
    """
    motions = _Motions()
    for item in items:
        motions.add(item)
    return motions.capped(robot, np.asarray(start_joints, dtype=np.float64))


_FK_CHUNK = 1 << 16
"""Rows of a toolpath whose flange poses are computed at once (bounds the memory of a
million-row block; forward kinematics of a row does not depend on the batch it is in)."""


class _Motions:
    """The emitted motions of a program gathered as runs of arrays: each run's instruction
    indices (n,), joints (n, dof) rad, tool poses ((n, 4, 4) or one (4, 4) for a toolpath's
    rows) and requested radii (n,) m; and the motions where the robot must stop."""

    def __init__(self) -> None:
        self.runs: list[tuple[IntArray, FloatArray, FloatArray, FloatArray]] = []
        self.single: list[StepLike] = []
        self.count = 0
        self.stopped: list[int] = []

    def add(self, item: Any) -> None:
        rows = _block_rows(item)
        if rows is not None:
            if rows.block.joints is not None and len(rows):
                self._flush()
                self._add_rows(rows)
            return
        if is_motion(item.instruction) and item.joints is not None:
            self.single.append(item)
            self.count += 1
        elif self.count and isinstance(item.instruction, STOP_TYPES):
            self.stopped.append(self.count - 1)

    def _add_rows(self, rows: BlockRows) -> None:
        block = rows.block
        assert block.joints is not None and block.tool is not None
        tool = np.asarray(block.tool.pose, dtype=np.float64)
        for lo in range(rows.lo, rows.hi, _FK_CHUNK):
            hi = min(lo + _FK_CHUNK, rows.hi)
            index = np.arange(block.start + lo, block.start + hi)
            joints = np.asarray(block.joints[lo:hi], dtype=np.float64)
            self.runs.append((index, joints, tool, np.asarray(block.node.zones[lo:hi])))
            self.count += hi - lo

    def _flush(self) -> None:
        steps, self.single = self.single, []
        if not steps:
            return
        index = np.array([s.index for s in steps], dtype=np.int64)
        joints = np.stack([np.asarray(s.joints, dtype=np.float64) for s in steps])
        tools = np.stack([np.asarray(s.tool.pose, dtype=np.float64) for s in steps])
        radii = np.array([float(s.instruction.zone.radius) for s in steps])
        self.runs.append((index, joints, tools, radii))

    def capped(self, robot: Robot, start_joints: FloatArray) -> BlendColumns:
        """The rule of this module on the gathered motions."""
        self._flush()
        if not self.runs:
            empty = np.zeros(0)
            return BlendColumns(np.zeros(0, dtype=np.int64), empty, empty, [])
        stops = np.zeros(self.count, dtype=bool)
        stops[self.stopped] = True
        stops[-1] = True
        positions = np.concatenate(
            [(robot.flange_poses(q) @ tools)[:, :3, 3] for _, q, tools, _ in self.runs]
        )
        tools = self.runs[0][2]
        first_tool = tools if tools.ndim == 2 else tools[0]
        start = (robot.flange_poses(start_joints) @ first_tool)[:3, 3]
        radii = np.concatenate([r for *_, r in self.runs]).astype(np.float64)
        capped, reasons = capped_radii(start, positions, radii, stops)
        index = np.concatenate([i for i, *_ in self.runs])
        return BlendColumns(index, radii, capped, reasons)


def _block_rows(item: Any) -> BlockRows | None:
    """A toolpath's rows (a whole block as its rows), or None for a step."""
    if isinstance(item, PathBlock):
        return BlockRows(item, 0, len(item))
    return item if isinstance(item, BlockRows) else None


def cap_blends(compiled: CompiledProgram) -> tuple[CompiledProgram, list[Diagnostic]]:
    """The compiled program with every blend radius capped (zones replaced in the program and
    its steps; a toolpath's zones as arrays, its blocks kept), and one warning diagnostic
    (kind ``blend_capped``) per reduced radius."""
    steps = compiled.steps
    found = blend_columns(items_of(steps), compiled.station.robot, compiled.start_joints)
    reduced = found.reduced
    if not reduced.size:
        return compiled, []
    index, radius = found.index[reduced], found.radius[reduced]
    capped = with_radii(compiled, index, radius)
    diagnostics = [
        _diagnostic(i, float(found.requested[k]), float(found.radius[k]), found.reasons[k], steps)
        for k, i in zip(reduced.tolist(), index.tolist(), strict=True)
    ]
    return capped, diagnostics


def with_radii(compiled: CompiledProgram, index: IntArray, radius: FloatArray) -> CompiledProgram:
    """``compiled`` with the zone radius of instruction ``index[j]`` set to ``radius[j]`` (m;
    ``index`` ascending), in its steps and its program: a toolpath's rows in their block's and
    node's arrays (the blocks stay blocks), and the blocks of a program with control flow kept
    (a flat list of instructions would drop them, and write every branch's body
    unconditionally)."""
    index = np.asarray(index, dtype=np.int64)
    radius = np.asarray(radius, dtype=np.float64)
    lookup = dict(zip(index.tolist(), radius.tolist(), strict=True))
    items: list[Item] = []
    for item in items_of(compiled.steps):
        if isinstance(item, PathBlock):
            node = _node_with_radii(item.node, item.start, index, radius)
            items.append(item if node is item.node else dataclasses.replace(item, node=node))
        elif item.index in lookup:
            ins = _with_radius(item.instruction, lookup[item.index])
            items.append(dataclasses.replace(item, instruction=ins))
        else:
            items.append(item)
    counter = 0

    def edit(node: Any) -> list[Any]:
        nonlocal counter
        at = counter
        if isinstance(node, LinearPath):
            counter += len(node)
            return [_node_with_radii(node, at, index, radius)]
        counter += 1
        return [_with_radius(node, lookup[at]) if at in lookup else node]

    program = compiled.program
    program = program.replace_instructions(map_leaves(program.instructions, edit))
    return dataclasses.replace(compiled, program=program, steps=make_steps(items))


def with_step_instructions(program: Any, instructions: list[Any]) -> Any:
    """``program`` with its instructions replaced, in order, by ``instructions`` (one per step);
    the blocks of a program with control flow are kept (a flat list would drop them, and write
    every branch's body unconditionally)."""
    if not program.has_flow:
        return program.replace_instructions(instructions)
    rest = iter(instructions)

    def edit(node: Any) -> list[Any]:
        count = len(node) if isinstance(node, LinearPath) else 1
        return [next(rest) for _ in range(count)]

    return program.replace_instructions(map_leaves(program.instructions, edit))


def _node_with_radii(node: LinearPath, start: int, index: IntArray, radius: FloatArray) -> Any:
    """``node`` (row k: instruction ``start + k``) with the radii of its rows in ``index``."""
    lo, hi = np.searchsorted(index, [start, start + len(node)])
    if lo == hi:
        return node
    zones = np.array(node.zones, dtype=np.float64)
    zones[index[lo:hi] - start] = radius[lo:hi]
    return node.with_zones(zones)


def _with_radius(instruction: Any, radius: float) -> Instruction:
    zone = dataclasses.replace(instruction.zone, radius=radius)
    replaced: Instruction = dataclasses.replace(instruction, zone=zone)
    return replaced


def _diagnostic(
    index: int, requested: float, radius: float, reason: str, steps: Sequence[Any]
) -> Diagnostic:
    return Diagnostic(
        "warning",
        "blend_capped",
        f"blend radius {requested * 1000:.1f} mm reduced to {radius * 1000:.1f} mm: {reason}",
        span_of(steps, index),
        index,
        hint="blend regions of neighbouring targets must not overlap (the controller would "
        "skip moves); use smaller zones or targets further apart",
    )
