"""A compiled program as rows of arrays: what the timers read, without an object per row.

One row per instruction (a toolpath's rows included): its kind, the rows of its sampled joint
path in one array ``q`` of all samples, its tool, zone and speeds. Ordinary steps add their own
samples; a :class:`~olp.compiled.PathBlock` adds its joint path once, its rows pointing into it
(row ``k`` from ``ends[k - 1]`` to ``ends[k]``). From the table come the TCP travel of every
motion (forward kinematics in batches) and the plan: which path moves blend into the next one,
so that the timers (:mod:`~olp.passes.timing.lines`, :mod:`~olp.passes.timing.chains`,
:mod:`~olp.passes.timing.ptp`) work on index arrays.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from olp.compiled import CompiledProgram, PathBlock, Step, items_of
from olp.ir import CircularMove, Comment, JointMove, LinearMove
from olp.passes.timing import corners
from olp.passes.timing.plan import MIN_BLEND_M, MIN_PATH_SPEED
from olp.passes.timing.tcp import FK_ROWS
from olp.station.model import Robot

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

FIXED, COMMENT, JOINT, LINEAR, CIRCULAR = 0, 1, 2, 3, 4
"""Row kinds: a fixed-time instruction (or an unresolved motion), a comment (fixed, but a chain
of blended moves runs through it), a resolved joint move, linear move, circular move."""

KIND_NAMES = {JOINT: "joint", LINEAR: "linear", CIRCULAR: "circular"}


@dataclass(frozen=True, slots=True, eq=False)
class MotionTable:
    """The rows of a compiled program (see the module docstring).

    ``kind`` (n,); ``lo``/``hi`` (n,): a motion's first and last row of ``q`` (S, dof) rad (-1
    for other rows); ``tool`` (n,): the index of a motion's tool pose in ``tools`` (T, 4, 4);
    ``zone`` (n,) m; ``linear`` (n,) m/s; ``angular`` (n,) rad/s (inf: no limit);
    ``linear_acceleration`` (n,) m/s² and ``angular_acceleration`` (n,) rad/s² (inf: none);
    ``joint``, ``joint_acceleration`` (n,): fractions of the axes' limits; ``motion`` (n,):
    whether the row is a motion instruction (resolved or not).
    """

    compiled: CompiledProgram
    kind: NDArray[np.int8]
    motion: NDArray[np.bool_]
    lo: IntArray
    hi: IntArray
    q: FloatArray
    sample_tool: IntArray
    tool: IntArray
    tools: FloatArray
    zone: FloatArray
    linear: FloatArray
    angular: FloatArray
    joint: FloatArray
    joint_acceleration: FloatArray
    linear_acceleration: FloatArray
    angular_acceleration: FloatArray

    @property
    def size(self) -> int:
        return int(self.kind.size)

    @property
    def path(self) -> NDArray[np.bool_]:
        """Rows that are resolved path moves (linear or circular)."""
        return (self.kind == LINEAR) | (self.kind == CIRCULAR)

    def with_speeds(self, linear: float | None, joint: float | None) -> MotionTable:
        """Every path move at ``linear`` m/s and every joint move at ``joint`` (fraction of the
        axes' maximum velocity); None keeps the programmed value."""
        table = self
        if linear is not None:
            table = dataclasses.replace(table, linear=np.where(self.path, linear, self.linear))
        if joint is not None:
            joints = np.where(self.kind == JOINT, joint, self.joint)
            table = dataclasses.replace(table, joint=joints)
        return table

    @classmethod
    def of(cls, compiled: CompiledProgram) -> MotionTable:
        """The table of ``compiled``."""
        return _Builder(compiled).table()


class _Builder:
    """Collects the rows of a program item by item (numpy per block, Python per step)."""

    def __init__(self, compiled: CompiledProgram) -> None:
        self.compiled = compiled
        n = len(compiled.steps)
        self.kind = np.zeros(n, dtype=np.int8)
        self.motion = np.zeros(n, dtype=bool)
        self.lo = np.full(n, -1, dtype=np.int64)
        self.hi = np.full(n, -1, dtype=np.int64)
        self.tool = np.full(n, -1, dtype=np.int64)
        self.zone = np.zeros(n)
        self.linear = np.ones(n)
        self.angular = np.full(n, np.inf)
        self.joint = np.ones(n)
        self.joint_acceleration = np.ones(n)
        self.linear_acceleration = np.full(n, np.inf)
        self.angular_acceleration = np.full(n, np.inf)
        self.parts: list[FloatArray] = []
        self.part_tools: list[int] = []
        self.samples = 0
        self.tools: list[FloatArray] = []
        self.tool_index: dict[int, int] = {}
        # The controller's own path acceleration bounds path moves that set none.
        self.path_acceleration = compiled.station.robot.limits.path_acceleration

    def table(self) -> MotionTable:
        for item in items_of(self.compiled.steps):
            if isinstance(item, PathBlock):
                self._block(item)
            else:
                self._step(item)
        dof = self.compiled.start_joints.size
        sizes = np.array([len(p) for p in self.parts], dtype=np.int64)
        return MotionTable(
            compiled=self.compiled,
            kind=self.kind,
            motion=self.motion,
            lo=self.lo,
            hi=self.hi,
            q=np.concatenate(self.parts) if self.parts else np.zeros((0, dof)),
            sample_tool=np.repeat(np.array(self.part_tools, dtype=np.int64), sizes),
            tool=self.tool,
            tools=np.stack(self.tools) if self.tools else np.zeros((0, 4, 4)),
            zone=self.zone,
            linear=self.linear,
            angular=self.angular,
            joint=self.joint,
            joint_acceleration=self.joint_acceleration,
            linear_acceleration=self.linear_acceleration,
            angular_acceleration=self.angular_acceleration,
        )

    def _tool(self, pose: FloatArray) -> int:
        key = id(pose)
        if key not in self.tool_index:
            for k, known in enumerate(self.tools):
                if np.array_equal(known, pose):
                    self.tool_index[key] = k
                    break
            else:
                self.tool_index[key] = len(self.tools)
                self.tools.append(np.asarray(pose, dtype=np.float64))
        return self.tool_index[key]

    def _samples(self, path: FloatArray, tool: int) -> int:
        """Append a joint path; returns the row of its first sample."""
        first = self.samples
        self.parts.append(path)
        self.part_tools.append(tool)
        self.samples += len(path)
        return first

    def _step(self, step: Step) -> None:
        i, ins = step.index, step.instruction
        if isinstance(ins, Comment):
            self.kind[i] = COMMENT
            return
        resolved = step.path is not None and step.tool is not None and step.tool.pose is not None
        kind = {JointMove: JOINT, LinearMove: LINEAR, CircularMove: CIRCULAR}.get(type(ins))
        self.motion[i] = kind is not None
        if kind is None or not resolved:
            return  # FIXED
        assert step.path is not None and step.tool is not None and step.tool.pose is not None
        assert isinstance(ins, JointMove | LinearMove | CircularMove)
        tool = self._tool(step.tool.pose)
        first = self._samples(step.path, tool)
        self.kind[i], self.tool[i] = kind, tool
        self.lo[i], self.hi[i] = first, first + len(step.path) - 1
        self.zone[i] = ins.zone.radius
        speed = ins.speed
        self.linear[i] = speed.linear
        self.angular[i] = np.inf if speed.angular is None else speed.angular
        self.joint[i], self.joint_acceleration[i] = speed.joint, speed.joint_acceleration
        self.linear_acceleration[i] = _or_inf(speed.linear_acceleration, self.path_acceleration)
        self.angular_acceleration[i] = _or_inf(speed.angular_acceleration)

    def _block(self, block: PathBlock) -> None:
        rows = slice(block.start, block.stop)
        self.motion[rows] = True
        if block.path is None or block.ends is None or block.tool is None:
            return  # unresolved: FIXED, no time
        assert block.tool.pose is not None
        tool = self._tool(block.tool.pose)
        first = self._samples(block.path, tool)
        node = block.node
        self.kind[rows], self.tool[rows] = LINEAR, tool
        self.lo[rows] = first + np.concatenate([[0], block.ends[:-1]])
        self.hi[rows] = first + block.ends
        self.zone[rows] = node.zones
        self.linear[rows] = node.speeds
        self.angular[rows] = np.inf if node.angular is None else node.angular
        self.linear_acceleration[rows] = _or_inf(node.acceleration, self.path_acceleration)
        self.angular_acceleration[rows] = _or_inf(node.angular_acceleration)


def _or_inf(value: float | None, default: float | None = None) -> float:
    if value is None:
        value = default
    return np.inf if value is None else value


def sample_positions(table: MotionTable, robot: Robot) -> FloatArray:
    """TCP positions (S, 3) m of all samples ``table.q`` with their tools: forward kinematics
    in batches of ``FK_ROWS``."""
    count = len(table.q)
    positions = np.empty((count, 3))
    with np.errstate(over="ignore", invalid="ignore"):  # a tool 1e308 m long: inf
        for lo in range(0, count, FK_ROWS):
            part = slice(lo, lo + FK_ROWS)
            tools = table.tools[table.sample_tool[part]]
            positions[part] = (robot.flange_poses(table.q[part]) @ tools)[:, :3, 3]
    return positions


def travel(table: MotionTable, robot: Robot, positions: FloatArray | None = None) -> FloatArray:
    """TCP travel (n,) m of every motion along its samples (0 for other rows), from the
    samples' TCP positions (:func:`sample_positions` if not given)."""
    if positions is None:
        positions = sample_positions(table, robot)
    with np.errstate(over="ignore", invalid="ignore"):  # a tool 1e308 m long: inf
        steps = np.linalg.norm(np.diff(positions, axis=0), axis=-1)
        arc = np.concatenate([[0.0], np.cumsum(steps)])
        out = np.zeros(table.size)
        motion = table.lo >= 0
        out[motion] = arc[table.hi[motion]] - arc[table.lo[motion]]
    return out


@dataclass(frozen=True, slots=True, eq=False)
class Plan:
    """Which path moves blend into the next: ``blend`` (n,) m, the corner cut from row i into
    the next motion (0: a stop); ``chains``: the path rows (P,) in order and ``bounds`` (C + 1,),
    chain c being ``rows[bounds[c]:bounds[c + 1]]`` (comments between blended moves belong to
    no chain)."""

    blend: FloatArray
    rows: IntArray
    bounds: IntArray

    def chain(self, c: int) -> IntArray:
        rows: IntArray = self.rows[int(self.bounds[c]) : int(self.bounds[c + 1])]
        return rows

    @property
    def sizes(self) -> IntArray:
        sizes: IntArray = np.diff(self.bounds)
        return sizes

    def stopped_at(self, rows: IntArray, stops: IntArray) -> Plan:
        """The plan of one chain ``rows`` (P,) cut into pieces at ``stops`` (rows among them
        that now stop instead of blending into the next)."""
        blend = self.blend.copy()
        blend[stops] = 0.0
        cut = np.flatnonzero(np.isin(rows[:-1], stops)) + 1
        return Plan(blend, rows, np.concatenate([[0], cut, [rows.size]]).astype(np.int64))


def plan(table: MotionTable, lengths: FloatArray) -> Plan:
    """The blends and chains of a program: a path move with a zone blends into the next motion
    (comments in between do not count) when that is a path move with the same tool, at
    ``min(zone, L1 / 2, L2 / 2)`` of TCP travel if that is at least ``MIN_BLEND_M`` and the path
    does not turn back there (:func:`turns_back`)."""
    n = table.size
    path = table.path
    moves = np.flatnonzero(table.kind != COMMENT)
    nxt = np.full(n, -1, dtype=np.int64)
    nxt[moves[:-1]] = moves[1:]
    after = np.where(nxt >= 0, nxt, 0)
    can = path & (nxt >= 0) & path[after] & (table.zone > 0) & (table.tool == table.tool[after])
    with np.errstate(invalid="ignore"):
        d = np.minimum.reduce([table.zone, lengths / 2, lengths[after] / 2])
    blend = np.where(can & (d >= MIN_BLEND_M), d, 0.0)
    blend[turns_back(table, np.flatnonzero(blend > 0), after)] = 0.0
    rows = np.flatnonzero(path)
    linked = (blend[rows[:-1]] > 0) & (nxt[rows[:-1]] == rows[1:])
    starts = np.flatnonzero(np.concatenate([[True], ~linked]))[: rows.size]  # none if no rows
    return Plan(blend, rows, np.append(starts, rows.size).astype(np.int64))


def turns_back(table: MotionTable, rows: IntArray, after: IntArray) -> IntArray:
    """The rows among ``rows`` whose TCP path turns back into the next motion ``after[rows]``
    by more than :data:`~olp.passes.timing.corners.FOLD_TURN` (the blend would fold onto
    itself)."""
    if rows.size == 0:
        return rows
    robot = table.compiled.station.robot
    angles = corners.turn_angles(
        robot, table.q, table.tools[table.sample_tool], table.hi[rows], table.lo[after[rows]]
    )
    folded: IntArray = rows[angles > corners.FOLD_TURN]
    return folded


def below_floor(table: MotionTable, rows: IntArray) -> NDArray[np.bool_]:
    """Rows whose programmed speed is below :data:`MIN_PATH_SPEED` (they cannot be timed)."""
    below: NDArray[np.bool_] = (table.linear[rows] < MIN_PATH_SPEED) | (
        table.angular[rows] < MIN_PATH_SPEED
    )
    return below


def gather(table: MotionTable, rows: IntArray) -> tuple[FloatArray, IntArray]:
    """The samples of motions ``rows`` end to end (each move's own, its start included): joints
    (S, dof) and the sample count (M,) per move."""
    sizes = table.hi[rows] - table.lo[rows] + 1
    starts = np.cumsum(sizes) - sizes
    shift = np.repeat(table.lo[rows] - starts, sizes)
    return table.q[np.arange(int(sizes.sum())) + shift], sizes
