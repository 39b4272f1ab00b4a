"""Resolve: every motion's target to joint values, on the station, with diagnostics.

* Tool and frame references are looked up in the station (inline definitions pass through).
* A joint target is taken as given and checked against the joint limits.
* A Cartesian target of a joint move takes the IK solution (any branch, any ±360° turn variant
  inside the limits) nearest to the previous joints.
* A linear move must stay in one IK branch: the straight TCP line is sampled (``step_m``,
  ``step_rad``; a circular move its arc, :func:`_arc_path`), solved in the branch of the start
  joints (on a singularity, the branch that meets it there and continues it) and unwrapped
  continuously. Leaving the
  workspace, a joint limit, or a joint jump between samples (a singularity or a configuration
  flip) is an error on that instruction; so is a move that needs more samples than one check
  takes (:data:`olp.passes.sampling.MAX_SAMPLES`), counted before any is made. A path that
  starts, ends or passes at a singular pose (wrist, shoulder, elbow) without a jump gets a
  warning (:func:`_singular_warnings`).

* A motion to a run-time target (:class:`~olp.ir.RuntimeMove`) is not checked: a warning
  (``runtime_target``) says why; the motion after it starts where olp does not know, so only
  its target is checked (reach, configuration, joint limits, in the solution nearest the last
  known joints) and its path is not: a warning (``unknown_start``), end joints but no path.
  ``skip_unreachable`` skips such a motion as any; ``fallback_joint`` has nothing to change
  there (:func:`_after_unknown_start`). So is the motion after a call of a routine that may
  move the robot (:attr:`olp.ir.Call.may_move`: one olp did not read).

The result is a :class:`olp.compiled.CompiledProgram`: the program, one step per instruction
(end joints, resolved tool and frame, sampled joint path of a motion) and the diagnostics.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from olp import progress
from olp.arcs import ArcError, arc_rotations, circle_through, rotation_travel, sample_count
from olp.compiled import CompiledProgram, Item, PathBlock, Step, StepBlocks, make_steps
from olp.diagnostics import Diagnostic
from olp.geometry import interpolate_poses, inv, pose_distance, pose_from
from olp.ir import (
    MOTION_TYPES,
    ArcOrientation,
    Call,
    CartesianTarget,
    CircularMove,
    Configuration,
    Expanded,
    Frame,
    Instruction,
    JointMove,
    JointTarget,
    LinearMove,
    LinearPath,
    Node,
    Program,
    RuntimeMove,
    SourceSpan,
    Tool,
)
from olp.ir_flow import leaves
from olp.kinematics.base import turn_variants
from olp.kinematics.singularity import ON_SINGULARITY, meeting_branches, singularity_distances
from olp.passes import wording
from olp.passes.sampling import MAX_SAMPLES, SegmentSamples, sample_segments, segment_counts
from olp.station.model import Robot, Station

if TYPE_CHECKING:
    from olp.passes.pipeline import BuildOptions

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass(frozen=True, slots=True)
class ResolveOptions:
    """Settings of the resolve pass.

    ``step_m`` / ``step_rad``: sampling of linear and circular moves (TCP travel and rotation
    per sample); ``step_arc_rad``: most angle of a circular move's arc per sample.
    ``max_joint_step_rad``: a larger joint change between two samples is reported as a
    discontinuity (singularity or configuration flip). ``weights``: per-joint weights of the
    distance used to choose the nearest IK solution.
    ``fallback_joint``: a linear move that cannot run becomes a joint move to the same target
    when that one can (USERS.md jobs 2 and 6), with a warning. ``skip_unreachable``: a target
    that no move can reach is dropped with a warning instead of an error (job 4).
    ``singular_angle_rad`` (wrist, elbow) and ``singular_distance_m`` (shoulder): a linear
    path that comes this close to a singular pose gets a warning (see
    :func:`_singular_warnings`).
    """

    step_m: float = 0.005
    step_rad: float = np.radians(2.0)
    # 2° of arc: the chord sags 0.015% of the radius below the circle (path lengths 5e-5 short).
    step_arc_rad: float = np.radians(2.0)
    max_joint_step_rad: float = np.radians(15.0)
    weights: tuple[float, ...] = (1.0, 1.0, 1.0, 1.0, 1.0, 1.0)
    fallback_joint: bool = False
    skip_unreachable: bool = False
    # A pose printed to 0.001 mm and 0.001° (KRL, Fanuc) fixes a free joint to within 1° only
    # beyond 0.001° / 1° = 1e-3 rad of a wrist (elbow) singularity and 0.001 mm / 1° = 0.06 mm
    # of a shoulder singularity; nearer than that, the pose does not decide the joints.
    singular_angle_rad: float = 1e-3
    singular_distance_m: float = 1e-4


def resolve(
    program: Program,
    station: Station,
    options: ResolveOptions | None = None,
    start: FloatArray | None = None,
) -> CompiledProgram:
    """Resolve every motion of ``program`` on ``station``; never raises on a bad program.
    ``start`` (dof,) rad: the joints the robot stands at before the first motion (None: the
    robot's home; a program streamed in pieces continues from the previous piece's last).

    A dense toolpath (:class:`~olp.ir.LinearPath`) is resolved in vectorised batches into
    :class:`~olp.compiled.PathBlock`\\ s; a row that fails is analysed alone and becomes an
    ordinary step (the program's nodes are then split around it, with the same instructions).
    """
    opts = options or ResolveOptions()
    robot = station.robot
    start_joints = robot.home.copy() if start is None else np.array(start, dtype=np.float64)
    state = _State(q=start_joints.copy(), robot=robot, opts=opts)
    items: list[Item] = []
    diags: list[Diagnostic] = []
    nodes = program.flat_nodes()  # control flow: each instruction once, in source order
    entries = _entry_starts(program, len(nodes))
    index = flat = 0
    while index < len(nodes):
        node = nodes[index]
        if index in entries:  # a routine no call runs: its caller leaves the robot anywhere
            state.unknown_start, state.q = entries[index], start_joints.copy()
        if isinstance(node, RuntimeMove) or (
            state.unknown_start is not None and isinstance(node, MOTION_TYPES)
        ):
            # one step: a run-time motion, or a motion whose start only the run time knows
            if isinstance(node, RuntimeMove):
                step, found = _runtime_step(flat, node, station, state)
            else:
                step, found = _after_unknown_start(flat, node, station, state)
            items.append(step)
            diags.extend(found)
            index, flat = index + 1, flat + 1
            progress.advance(1)
            continue
        if state.unknown_start is not None and isinstance(node, LinearPath):
            row = 0  # a row skipped there leaves the next one starting unknown too
            while row < len(node) and state.unknown_start is not None:
                step, found = _after_unknown_start(flat + row, node.move(row), station, state)
                items.append(step)
                diags.extend(found)
                row += 1
            if row < len(node):
                found_items, found = _resolve_path(
                    flat + row, node.rows(row, len(node)), station, state
                )
                items.extend(found_items)
                diags.extend(found)
            index, flat = index + 1, flat + len(node)
            progress.advance(len(node))
            continue
        if isinstance(node, LinearPath):
            found_items, found = _resolve_path(flat, node, station, state)
            items.extend(found_items)
            diags.extend(found)
            index, flat = index + 1, flat + len(node)
            progress.advance(len(node))
            continue
        stop = next((k for k in entries if k > index), len(nodes))
        run = _linear_run(nodes, index, flat, station, stop)
        if run:
            found_items, found = _resolve_linear_run(run, station, state)
            items.extend(found_items)
            diags.extend(found)
            index, flat = index + len(run), flat + len(run)
            progress.advance(len(run))
            continue
        if isinstance(node, MOTION_TYPES):
            step, found = _resolve_motion(flat, node, station, state)
            items.append(step)
            diags.extend(found)
        else:
            if isinstance(node, Call) and node.may_move:
                state.unknown_start = node
            items.append(Step(index=flat, instruction=node))
        index, flat = index + 1, flat + 1
        progress.advance(1)
    steps = make_steps(items)
    if isinstance(steps, StepBlocks) and not program.has_flow:
        program = program.replace_instructions([_node_of(item) for item in steps.blocks])
    return CompiledProgram(
        program=program,
        station=station,
        start_joints=start_joints,
        steps=steps,
        diagnostics=tuple(diags),
    )


_MOVE_WORDS = {"joint": "joint move", "linear": "linear move", "circular": "circular move"}


def _runtime_step(
    index: int, ins: RuntimeMove, station: Station, state: _State
) -> tuple[Step, list[Diagnostic]]:
    """A motion to a run-time target: its tool and frame looked up (a post writes them before
    it), nothing else checked; a warning says what is not (``runtime_target``), and the next
    motion starts where olp does not know (:func:`_after_unknown_start`)."""
    tool: Tool | None = None
    frame: Frame | None = None
    found: list[Diagnostic] = []
    if not ins.controller_settings:  # else its tool and frame are the controller's
        tool = ins.tool if ins.tool.pose is not None else station.tool(ins.tool)
        frame = ins.frame if ins.frame.pose is not None else station.frame(ins.frame)
        found = _lookup_errors(index, ins, tool, frame)
    why = f" ({ins.reason})" if ins.reason else ""
    what = (
        "that runs with settings the controller holds at run time"
        if ins.controller_settings
        else "to a target known only when the program runs"
    )
    message = (
        f"{_MOVE_WORDS[ins.motion]} {what}{why}: olp cannot check it (reach, joint limits, "
        "singularities, collisions) or time it; the cycle time leaves it out"
    )
    hint = (
        "if a routine it names leaves the tool, base, speeds and the robot as they were, name "
        "it with --call-keeps-settings (KRL)"
        if ins.controller_settings and "did not read" in ins.reason
        else None
    )
    found.append(Diagnostic("warning", "runtime_target", message, ins.span, index, hint=hint))
    state.unknown_start = ins
    return Step(index=index, instruction=ins, tool=tool, frame=frame), found


def _after_unknown_start(
    index: int, ins: JointMove | LinearMove | CircularMove, station: Station, state: _State
) -> tuple[Step, list[Diagnostic]]:
    """The first motion after a run-time motion (or a call that may move the robot,
    :attr:`olp.ir.Call.may_move`): it starts where olp does not know, so its
    path cannot be checked (a line, an arc, the joint-space path) nor timed; its target still
    is: reachable, in the configuration the target asks for, within the joint limits (a
    joint move to it from the last known joints, whose path is then dropped). The joints
    taken are the solution nearest to the last known ones: the next motions are checked from
    there. A warning (``unknown_start``) says so; the step has end joints but no path (the
    timing pass gives it no time).

    ``skip_unreachable`` applies as to any move: a target no joint move can reach (or only
    beyond a joint limit) is skipped with a warning, and the robot stays where the run-time
    motion left it, so the motion after the skipped one starts unknown too. ``fallback_joint``
    does not: it writes a linear move that cannot run as a joint move to its target, and here
    the check already is that joint move (from the last known joints, nearest solution), so
    a target it fails is one a joint move fails too; the line itself is not checked, so no
    fault of the line is left for a joint move to avoid."""
    runtime, state.unknown_start = state.unknown_start, None
    assert runtime is not None
    tool = ins.tool if ins.tool.pose is not None else station.tool(ins.tool)
    frame = ins.frame if ins.frame.pose is not None else station.frame(ins.frame)
    found = _lookup_errors(index, ins, tool, frame)
    if tool is None or frame is None:
        return Step(index=index, instruction=ins, tool=tool, frame=frame), found
    joint = (
        ins
        if isinstance(ins, JointMove)
        else JointMove(target=ins.target, tool=ins.tool, frame=ins.frame, span=ins.span)
    )
    path, checked = _joint_path(index, joint, tool, frame, state)
    found += checked
    if path is None:
        skipped = _skipped(index, ins, tool, frame, state, found)
        if skipped is not None:
            state.unknown_start = runtime  # the robot stays where the run-time motion ended
            return skipped
        _restart_at_target(ins, tool, frame, state)
        return Step(index=index, instruction=ins, tool=tool, frame=frame), found
    state.q = path[-1].copy()
    kind = _MOVE_WORDS[ins.kind]
    if isinstance(runtime, Expanded):
        where = (
            f"the unknown caller of {runtime.call.name} (line {runtime.span.line}, a routine no "
            "call of the program runs) leaves the robot"
        )
    elif isinstance(runtime, Call):
        where = (
            f"the call of {runtime.name} at line {runtime.span.line} leaves the robot (a routine "
            "olp did not read, which may move it)"
        )
    else:
        where = f"the motion to a run-time target at line {runtime.span.line} ends"
    message = (
        f"this {kind} starts where {where}, which olp cannot know: only its target is checked "
        "(reach, joint limits, in the solution nearest the last known joints); its path "
        "(singularities, "
        "collisions) and its time are not, and the cycle time leaves it out"
    )
    found.append(Diagnostic("warning", "unknown_start", message, ins.span, index))
    step = Step(index=index, instruction=ins, joints=path[-1], tool=tool, frame=frame)
    return step, found


def _lookup_errors(
    index: int,
    ins: JointMove | LinearMove | CircularMove | RuntimeMove,
    tool: Tool | None,
    frame: Frame | None,
) -> list[Diagnostic]:
    """Errors for a motion's tool or frame that the station does not define."""
    out = []
    if tool is None:
        name = ins.tool.name
        msg = f"tool {name!r} is not defined in the station"
        out.append(_error("unknown_tool", msg, index, ins))
    if frame is None:
        name = ins.frame.name
        out.append(
            _error("unknown_frame", f"frame {name!r} is not defined in the station", index, ins)
        )
    return out


def _entry_starts(program: Program, total: int) -> dict[int, Expanded]:
    """The index in :meth:`~olp.ir.Program.flat_nodes` (``total`` of them) of the first node
    of each entry (:attr:`olp.ir_flow.Expanded.entry`: a routine no call runs, expanded after
    the program's end)."""
    entries: list[Expanded] = []
    for node in reversed(program.instructions):
        if not (isinstance(node, Expanded) and node.entry):
            break
        entries.insert(0, node)
    counts = [sum(1 for _ in leaves([node])) for node in entries]
    at = total - sum(counts)
    out: dict[int, Expanded] = {}
    for node, count in zip(entries, counts, strict=True):
        if count:
            out[at] = node
        at += count
    return out


def _node_of(item: Item) -> Node:
    return item.node if isinstance(item, PathBlock) else item.instruction


@dataclass(slots=True)
class _State:
    """Where resolving stands: ``q`` (dof,) rad, the joints after the last motion resolved;
    ``unknown_start``: the run-time motion (:class:`~olp.ir.RuntimeMove`) the robot went to
    since, or the call of a routine that may move it (:attr:`olp.ir.Call.may_move`), whose end
    olp cannot know (the next motion's start), else None."""

    q: FloatArray
    robot: Robot
    opts: ResolveOptions
    unknown_start: RuntimeMove | Call | Expanded | None = None


def _error(kind: str, message: str, index: int, ins: Instruction, **kw: object) -> Diagnostic:
    return Diagnostic("error", kind, message, ins.span, index, **kw)  # type: ignore[arg-type]


_RUN_CHUNK = 4096
"""Most linear moves resolved per vectorised batch."""

_RETRY_CHUNK = 16
"""Moves in the batch after one that failed; the size doubles back to ``_RUN_CHUNK`` while
batches succeed. A failure costs the samples of the moves after it in its batch, so a fixed
size made a program of many failing moves quadratic (2,000 unreachable targets: 28 s)."""

_BATCH_SAMPLES = MAX_SAMPLES
"""Most TCP samples per batch (bounds memory: ~1 kB of temporaries per sample)."""


@dataclass(frozen=True, slots=True, eq=False)
class _Run:
    """Consecutive linear moves to Cartesian targets with one tool, as arrays.

    ``first``: the instruction index of move 0; ``poses`` (M, 4, 4): the targets in their
    frames; ``frame_poses`` (M, 4, 4) or one (4, 4): the frames in the world; ``speeds`` (M,)
    m/s; ``tool``: resolved. Move ``k`` as an instruction is ``moves[k]`` (ordinary moves) or
    row ``offset + k`` of ``node`` (a dense toolpath, whose rows share one ``frame``).
    """

    first: int
    poses: FloatArray
    frame_poses: FloatArray
    speeds: FloatArray
    tool: Tool
    frames: tuple[Frame, ...] = ()
    moves: tuple[LinearMove, ...] = ()
    node: LinearPath | None = None
    offset: int = 0

    def __len__(self) -> int:
        return int(self.speeds.shape[0])

    def targets(self) -> FloatArray:
        """The TCP targets (M, 4, 4) in the world."""
        return np.asarray(self.frame_poses @ self.poses, dtype=np.float64)

    def move(self, k: int) -> LinearMove:
        return self.moves[k] if self.node is None else self.node.move(self.offset + k)

    def frame(self, k: int) -> Frame:
        return self.frames[k] if self.node is None else self.frames[0]

    def span(self, k: int) -> SourceSpan:
        return self.moves[k].span if self.node is None else self.node.row_span(self.offset + k)

    def rows(self, start: int, stop: int) -> _Run:
        """Moves ``start`` to ``stop`` (exclusive)."""
        part = slice(start, stop)
        dense = self.node is not None
        return dataclasses.replace(
            self,
            first=self.first + start,
            poses=self.poses[part],
            frame_poses=self.frame_poses if dense else self.frame_poses[part],
            speeds=self.speeds[part],
            frames=self.frames if dense else self.frames[part],
            moves=self.moves[part],
            offset=self.offset + start,
        )


def _linear_run(
    nodes: tuple[Node, ...], start: int, first: int, station: Station, stop: int
) -> _Run | None:
    """The consecutive linear moves from node ``start`` (instruction ``first``) to Cartesian
    targets with one resolvable tool and resolvable frames, before node ``stop`` (an entry's
    start), None if none start here.

    Walks the nodes by index: a slice ``nodes[start:]`` would copy the rest of the program for
    every instruction that starts no run, which made resolve quadratic in non-motion
    instructions (200,000 comments: 70 s)."""
    moves: list[LinearMove] = []
    frames: list[Frame] = []
    first_tool: Tool | None = None
    for index in range(start, stop):
        ins = nodes[index]
        if not (isinstance(ins, LinearMove) and isinstance(ins.target, CartesianTarget)):
            break
        tool = ins.tool if ins.tool.pose is not None else station.tool(ins.tool)
        frame = ins.frame if ins.frame.pose is not None else station.frame(ins.frame)
        if tool is None or frame is None or (first_tool is not None and tool != first_tool):
            break
        first_tool = tool
        moves.append(ins)
        frames.append(frame)
    if first_tool is None:
        return None
    return _Run(
        first=first,
        poses=np.stack([m.target.pose for m in moves]),  # type: ignore[union-attr]
        frame_poses=np.stack([_world(f) for f in frames]),
        speeds=np.array([m.speed.linear for m in moves], dtype=np.float64),
        tool=first_tool,
        frames=tuple(frames),
        moves=tuple(moves),
    )


def _resolve_path(
    first: int, node: LinearPath, station: Station, state: _State
) -> tuple[list[Item], list[Diagnostic]]:
    """Resolve a dense toolpath: its rows as one run (tool and frame looked up once)."""
    tool = node.tool if node.tool.pose is not None else station.tool(node.tool)
    frame = node.frame if node.frame.pose is not None else station.frame(node.frame)
    if tool is None or frame is None:
        missing = [
            (f"tool {node.tool.name!r}" if tool is None else ""),
            (f"frame {node.frame.name!r}" if frame is None else ""),
        ]
        kind = "unknown_tool" if tool is None else "unknown_frame"
        msg = f"{' and '.join(m for m in missing if m)} not defined in the station"
        block = PathBlock(first, node, tool, frame)
        return [block], [Diagnostic("error", kind, msg, node.span, first)]
    run = _Run(
        first=first,
        poses=node.poses,
        frame_poses=_world(frame),
        speeds=node.speeds,
        tool=tool,
        frames=(frame,),
        node=node,
    )
    return _resolve_linear_run(run, station, state)


def _resolve_linear_run(
    run: _Run, station: Station, state: _State
) -> tuple[list[Item], list[Diagnostic]]:
    """Resolve consecutive linear moves in vectorised batches.

    The whole chain is sampled and solved at once in the branch it starts in. At the first
    sample that fails (no solution, a joint limit, a joint jump), or at a move too long to
    sample in a batch, the moves before it are accepted and the failing move is analysed alone
    by the per-move code, which words the diagnostic exactly as for a single move (the same
    sampling rules apply); the batch then goes on after it. The moves of a dense toolpath are
    accepted as blocks (arrays), ordinary moves as steps.
    """
    items: list[Item] = []
    diags: list[Diagnostic] = []
    k, size = 0, _RUN_CHUNK
    while k < len(run):
        chunk = run.rows(k, min(k + size, len(run)))
        batch = _batch_path(chunk, state)
        good, samples = batch.good, batch.samples
        if good:
            assert samples is not None
            moves = chunk.rows(0, good)
            diags.extend(_speed_warnings(moves, batch.path, samples, state.robot))
            ends = samples.ends[:good] + 1
            fractions = np.concatenate([[0.0], samples.fractions[: int(ends[-1])]])
            diags.extend(_singular_warnings(moves, batch.path, ends, fractions, state))
            items.extend(_batch_items(moves, batch.path, ends))
            state.q = batch.path[int(ends[-1])].copy()
        if batch.bad is not None:
            step, found = _resolve_motion(chunk.first + good, chunk.move(good), station, state)
            items.append(step)
            diags.extend(found)
            size = _RETRY_CHUNK
        elif good == len(chunk):
            size = min(2 * size, _RUN_CHUNK)
        k += good + (0 if batch.bad is None else 1)
    return items, diags


def _batch_items(run: _Run, path: FloatArray, ends: IntArray) -> list[Item]:
    """The moves of a batch: their rows of the batch's joint path (S + 1, 6), each from the
    previous move's end row (``ends`` (M,): each move's last row) - one block for a dense
    toolpath, one step per move otherwise."""
    path = path[: int(ends[-1]) + 1]
    if run.node is not None:
        rows = run.node.rows(run.offset, run.offset + len(run))
        block = PathBlock(
            run.first, rows, run.tool, run.frame(0), path[ends], path, np.asarray(ends)
        )
        return [block]
    steps: list[Item] = []
    for m in range(len(run)):
        segment = path[(0 if m == 0 else int(ends[m - 1])) : int(ends[m]) + 1]
        steps.append(
            Step(
                index=run.first + m,
                instruction=run.move(m),
                joints=segment[-1],
                path=segment,
                tool=run.tool,
                frame=run.frame(m),
            )
        )
    return steps


@dataclass(frozen=True, slots=True, eq=False)
class _Batch:
    """A batch of linear moves sampled and solved: ``path`` (S + 1, 6) rad from the start
    joints (row 0); ``samples`` of the moves sampled; ``good``: how many moves from the
    first passed every check; ``bad``: the index of the move that failed or was too long to
    sample (None: the first ``good`` moves are all the batch could take)."""

    path: FloatArray
    samples: SegmentSamples | None
    good: int
    bad: int | None


def _batch_path(chunk: _Run, state: _State) -> _Batch:
    """Sample and solve a chain of linear moves from ``state.q``, as many as fit in
    ``_BATCH_SAMPLES`` samples: a move that alone needs more than ``MAX_SAMPLES`` stops the
    batch (the per-move code reports it; an absurd target never allocates its samples)."""
    robot, opts = state.robot, state.opts
    tool_pose = chunk.tool.pose
    assert tool_pose is not None
    targets = chunk.targets()
    start = robot.flange_poses(state.q) @ tool_pose
    counts = segment_counts(start, targets, opts.step_m, opts.step_rad)
    fit, too_long = _fitting(counts)
    if fit == 0:
        return _Batch(state.q[None], None, 0, 0)
    samples = sample_segments(start, targets[:fit], opts.step_m, opts.step_rad)
    flanges = samples.poses @ inv(tool_pose)
    sols = _branch_path(robot, state.q, robot.solve(flanges, seed=state.q))
    path = np.vstack([state.q[None], _unwrap(state.q, sols)])
    with np.errstate(invalid="ignore"):
        invalid = ~np.all(np.isfinite(path[1:]), axis=-1)
        invalid |= np.any(robot.limits.violations(path[1:]), axis=-1)
        invalid |= np.any(np.abs(np.diff(path, axis=0)) > opts.max_joint_step_rad, axis=-1)
    if np.any(invalid):
        bad = int(samples.segment[int(np.argmax(invalid))])
        return _Batch(path, samples, bad, bad)
    return _Batch(path, samples, fit, fit if too_long else None)


def _fitting(counts: FloatArray) -> tuple[int, bool]:
    """How many leading moves of sample counts ``counts`` (M,) fit in one batch, and whether
    the next one (if any) needs more than ``MAX_SAMPLES`` by itself (NaN counts as that)."""
    over = ~(counts <= MAX_SAMPLES)
    total = np.cumsum(np.where(over, np.inf, counts))
    fit = int(np.searchsorted(total, _BATCH_SAMPLES, side="right"))
    return fit, fit < counts.size and bool(over[fit])


def _speed_warnings(
    moves: _Run, path: FloatArray, samples: SegmentSamples, robot: Robot
) -> list[Diagnostic]:
    """Warn where the programmed TCP speed needs a joint faster than its limit.

    Between two samples of a move the TCP travels ``length / count``; at speed ``v`` that takes
    ``length / (count v)`` seconds, so the joint speed needed is ``|dq| count v / length``. Near a
    singularity this grows without bound, which makes it a measure of singularity proximity
    too. The controller slows the TCP down there (the timing pass does the same); consecutive
    moves that need it are reported together.
    """
    m = len(moves)
    rows = int(samples.ends[m - 1]) + 1
    segment = samples.segment[:rows]
    counts = np.diff(np.concatenate([[-1], samples.ends[:m]]))
    speeds = moves.speeds
    spacing = samples.lengths[:m] / counts
    dq = np.abs(np.diff(path[: rows + 1], axis=0))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        needed = dq * (speeds / spacing)[segment][:, None]
        needed[~np.isfinite(needed)] = 0.0
        ratio = needed / robot.limits.velocity
    worst_per_move = np.maximum.reduceat(np.max(ratio, axis=1), samples.ends[:m] - counts + 1)
    over = worst_per_move > 1.0 + 1e-9
    out: list[Diagnostic] = []
    for lo, hi in _true_runs(over):
        rows_in = (segment >= lo) & (segment < hi)
        row = int(np.argmax(np.where(rows_in[:, None], ratio, 0.0)) // ratio.shape[1])
        joint = int(np.argmax(ratio[row]))
        first = moves.first
        where = f"move {first + lo}" if hi - lo == 1 else f"moves {first + lo}-{first + hi - 1}"
        need, limit = wording.above(
            float(np.degrees(needed[row, joint])), float(np.degrees(robot.limits.velocity[joint]))
        )
        out.append(
            Diagnostic(
                "warning",
                "speed_limited",
                f"{where}: {wording.quantity(float(speeds[lo]) * 1000, 0)} mm/s needs axis "
                f"{joint + 1} at {need}°/s (limit {limit}°/s); the TCP will be slower there",
                moves.span(lo),
                first + lo,
                joints=path[row + 1],
                hint="lower the speed, or keep the path away from singular poses",
            )
        )
    return out


def _true_runs(mask: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """Half-open index ranges [lo, hi) of consecutive True values."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(
        zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist(), strict=True)
    )


_SINGULARITIES = (
    (
        "wrist",
        "axis 5 {angle}° from lining up axes 4 and 6",
        "the pose does not fix how axes 4 and 6 share the turn",
        "turn axis 5 away from 0° before the move (a joint move), or tilt the tool",
    ),
    (
        "shoulder",
        "{place}: {distance} mm",
        "the pose does not fix axis 1",
        "keep the wrist away from axis 1: move the path, or change the tool orientation",
    ),
    (
        "elbow",
        "the arm {angle}° from fully stretched or folded",
        "the arm cannot move further out or in there",
        "keep the path inside the reach: move it closer to (or farther from) the robot",
    ),
)
"""Per singularity: its name, how far the pose is from it, what is undefined there, a hint."""


def _singular_warnings(
    moves: _Run,
    path: FloatArray,
    ends: IntArray,
    fractions: FloatArray,
    state: _State,
    move: str = "linear move",
) -> list[Diagnostic]:
    """Warn where a resolved linear path starts, ends or passes at a singular pose.

    ``path`` (S + 1, 6) rad: the joint path of consecutive moves from their start (row 0);
    ``ends`` (M,): each move's last row; ``fractions`` (S + 1,): each row's position within
    its move (0 at row 0). Distances come from the kinematic model
    (:func:`olp.kinematics.singularity.singularity_distances`), at every row and, where the
    distance has a local minimum, at the vertex of the parabola through it and its neighbours
    (a touch between two samples); a row counts when within ``singular_angle_rad`` (wrist,
    elbow) or ``singular_distance_m`` (shoulder) of the singularity.

    Why a warning and not an error: a path that reaches this pass stayed in one IK branch
    with no joint jump, so the joint path olp planned, checked and timed exists and is
    continuous (a linear move whose path is undefined at a singularity, e.g. one that must
    turn axes 4 and 6 by 180° in an instant, already failed with an error). But at the
    singular pose the pose alone no longer determines the joints: the controller's own
    Cartesian interpolation has to pick them (from the joints it comes from) and its Jacobian
    is singular there. Vendors document that Cartesian moves at or through singular poses may
    stop with a message or slow down: KUKA names the alpha-1 (overhead), alpha-2 (extended)
    and alpha-5 (wrist) singularities, and its $SINGUL_POS settles the free axes only for a PTP
    end point; ABB's SingArea\\Wrist lets a linear move deviate in orientation to pass the
    wrist singularity. So olp keeps the program but says where the controller's joints may
    differ from olp's path, or the move may stop.
    """
    found = singularity_distances(state.robot.kinematics, path)
    if found is None:  # numeric kinematics: no named branches to measure from
        return []
    tolerance = {
        "wrist": np.sin(state.opts.singular_angle_rad),
        "shoulder": state.opts.singular_distance_m,
        "elbow": np.sin(state.opts.singular_angle_rad),
    }
    starts = np.concatenate([[0], ends[:-1]])
    first = moves.first
    out: list[Diagnostic] = []
    for name, detail, undefined, hint in _SINGULARITIES:
        distance = _closest(getattr(found, name))
        per_move = np.minimum(np.minimum.reduceat(distance[: ends[-1]], starts), distance[ends])
        for lo, hi in _true_runs(per_move <= tolerance[name]):
            rows = np.arange(int(starts[lo]), int(ends[lo]) + 1)
            row = int(rows[np.argmax(distance[rows] <= tolerance[name])])
            if row == starts[lo]:
                verb = "starts in"
            elif row == ends[lo]:
                verb = "ends in"
            else:
                verb = f"passes (at {wording.percent(float(fractions[row]))} of the move)"
            amount = float(distance[row])
            text = detail.format(
                angle=wording.quantity(float(np.degrees(np.arcsin(min(amount, 1.0)))), 3),
                distance=wording.quantity(amount * 1000, 3),
                place=found.shoulder_place,
            )
            also = {1: "", 2: f"; move {first + lo + 1} too"}.get(
                hi - lo, f"; moves {first + lo + 1}-{first + hi - 1} too"
            )
            out.append(
                Diagnostic(
                    "warning",
                    "singularity",
                    f"{move} {first + lo} {verb} the {name} singularity ({text}): "
                    f"{undefined}, so the controller may stop the move there or take other "
                    f"joint values than olp planned{also}",
                    moves.span(lo),
                    first + lo,
                    joints=path[row],
                    hint=hint,
                )
            )
    return out


def _closest(values: FloatArray) -> FloatArray:
    """Distances (S,) from zero of a signed quantity sampled along a path (S,): ``|values|``,
    lowered where a local minimum of it has a lower parabola vertex between its neighbours,
    and 0 where the sign changes (a crossing between two samples)."""
    out = np.abs(values)
    if values.size < 3:
        if values.size == 2 and values[0] * values[1] < 0:
            out[:] = 0.0
        return out
    before, here, after = values[:-2], values[1:-1], values[2:]
    curve = after - 2.0 * here + before
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = here - (after - before) ** 2 / (8.0 * curve)
    # Only at a local minimum of |values| does the parabola's vertex lie between the two
    # neighbours; it comes nearer to zero only if the parabola curves away from zero.
    minimum = (np.abs(here) <= np.abs(before)) & (np.abs(here) <= np.abs(after))
    towards = minimum & (np.sign(curve) == np.sign(here)) & (np.abs(vertex) < np.abs(here))
    dip = np.where(towards, np.where(vertex * here <= 0, 0.0, np.abs(vertex)), out[1:-1])
    out[1:-1] = np.minimum(out[1:-1], dip)
    crossing = np.flatnonzero(values[:-1] * values[1:] < 0)
    out[crossing] = 0.0
    return out


def _world(frame: Frame) -> FloatArray:
    assert frame.pose is not None
    return frame.pose


def _resolve_motion(
    index: int, ins: JointMove | LinearMove | CircularMove, station: Station, state: _State
) -> tuple[Step, list[Diagnostic]]:
    tool = ins.tool if ins.tool.pose is not None else station.tool(ins.tool)
    frame = ins.frame if ins.frame.pose is not None else station.frame(ins.frame)
    diags: list[Diagnostic] = []
    if tool is None:
        diags.append(
            _error(
                "unknown_tool", f"tool {ins.tool.name!r} is not defined in the station", index, ins
            )
        )
    if frame is None:
        diags.append(
            _error(
                "unknown_frame",
                f"frame {ins.frame.name!r} is not defined in the station",
                index,
                ins,
            )
        )
    if tool is None or frame is None:
        return Step(index=index, instruction=ins, tool=tool, frame=frame), diags
    if isinstance(ins, CircularMove):
        path, found = _arc_path(index, ins, tool, frame, state)
    elif isinstance(ins, LinearMove):
        path, found = _linear_path(index, ins, tool, frame, state)
    else:
        path, found = _joint_path(index, ins, tool, frame, state)
    if path is None:
        return _recover(index, ins, tool, frame, state, diags + found)
    diags.extend(found)
    state.q = path[-1].copy()
    return Step(
        index=index, instruction=ins, joints=path[-1], path=path, tool=tool, frame=frame
    ), diags


_UNREACHABLE = frozenset({"unreachable", "joint_limit"})


def _recover(
    index: int,
    ins: JointMove | LinearMove | CircularMove,
    tool: Tool,
    frame: Frame,
    state: _State,
    diags: list[Diagnostic],
) -> tuple[Step, list[Diagnostic]]:
    """What happens after a move failed: the joint-move fallback, skipping, or the error."""
    opts = state.opts
    if opts.fallback_joint and isinstance(ins, LinearMove):
        joint = JointMove(
            target=ins.target,
            speed=ins.speed,
            zone=ins.zone,
            tool=ins.tool,
            frame=ins.frame,
            span=ins.span,
        )
        path, _found = _joint_path(index, joint, tool, frame, state)
        if path is not None:
            why = "; ".join(d.message for d in diags if d.severity == "error")
            note = Diagnostic(
                "warning",
                "fallback_joint",
                f"linear move written as a joint move: {why}",
                ins.span,
                index,
            )
            state.q = path[-1].copy()
            step = Step(
                index=index, instruction=joint, joints=path[-1], path=path, tool=tool, frame=frame
            )
            return step, [*[d for d in diags if d.severity != "error"], note]
    skipped = _skipped(index, ins, tool, frame, state, diags)
    if skipped is not None:
        return skipped
    _restart_at_target(ins, tool, frame, state)
    return Step(index=index, instruction=ins, tool=tool, frame=frame), diags


def _skipped(
    index: int,
    ins: JointMove | LinearMove | CircularMove,
    tool: Tool,
    frame: Frame,
    state: _State,
    diags: list[Diagnostic],
) -> tuple[Step, list[Diagnostic]] | None:
    """With ``skip_unreachable``, a move whose errors all say its target cannot be reached
    (``diags``) as a skipped step, its errors turned into warnings; else None."""
    errors = [d for d in diags if d.severity == "error"]
    if not (state.opts.skip_unreachable and errors):
        return None
    if not all(d.kind in _UNREACHABLE for d in errors):
        return None
    skipped = [
        dataclasses.replace(d, severity="warning", message=f"skipped: {d.message}") for d in errors
    ]
    return Step(index=index, instruction=ins, tool=tool, frame=frame, skipped=True), skipped


def _restart_at_target(
    ins: JointMove | LinearMove | CircularMove, tool: Tool, frame: Frame, state: _State
) -> None:
    """After a failed move, check the next one from the target itself (nearest IK solution) so
    that one bad move does not make every following move fail too."""
    if isinstance(ins.target, JointTarget):
        if ins.target.joints.shape == state.q.shape:
            state.q = np.clip(ins.target.joints, state.robot.limits.lower, state.robot.limits.upper)
        return
    candidates = _candidates(state.robot, flange_target(ins.target, tool, frame))
    if candidates.shape[0]:
        state.q = _nearest(candidates, state.q, state.opts.weights)


def flange_target(target: CartesianTarget, tool: Tool, frame: Frame) -> FloatArray:
    """World pose (4, 4) of the flange that puts the tool's TCP on ``target`` in ``frame``."""
    assert tool.pose is not None and frame.pose is not None
    with np.errstate(over="ignore", invalid="ignore"):  # 1e308 m poses: inf, then unreachable
        flange: FloatArray = frame.pose @ target.pose @ inv(tool.pose)
    return flange


def _joint_path(
    index: int, ins: JointMove, tool: Tool, frame: Frame, state: _State
) -> tuple[FloatArray | None, list[Diagnostic]]:
    robot = state.robot
    if isinstance(ins.target, JointTarget):
        bad_target = _joint_target_error(index, ins, ins.target, robot)
        if bad_target is not None:
            return None, [bad_target]
        return _joint_line(index, ins, state.q, ins.target.joints)
    flange = flange_target(ins.target, tool, frame)
    candidates = _candidates(robot, flange)
    if candidates.shape[0] == 0:
        return None, [_unreachable(index, ins, robot, flange)]
    if ins.target.config is not None:
        candidates, found = _configured(index, ins, robot, candidates, ins.target.config)
        if candidates.shape[0] == 0:
            return None, found
    return _joint_line(index, ins, state.q, _nearest(candidates, state.q, state.opts.weights))


_JOINT_STEP_RAD = float(np.radians(2.0))
"""Sampling of a joint move's straight joint line, on the axis that moves most."""


def _joint_line(
    index: int, ins: JointMove, q0: FloatArray, q1: FloatArray
) -> tuple[FloatArray | None, list[Diagnostic]]:
    """The joint-space straight line from ``q0`` to ``q1`` sampled every ``_JOINT_STEP_RAD``
    (or finer) on the axis that moves most: (S, 6). The box of joint limits is convex, so the
    line stays inside the limits when both ends do; the samples serve path length and later
    collision checks. More than ``MAX_SAMPLES`` of them (an axis with limits of many turns
    asked to turn hundreds of times) is an error on the move, not an allocation."""
    turn = float(np.max(np.abs(q1 - q0)))
    wanted = max(np.ceil(turn / _JOINT_STEP_RAD), 1.0)
    if not wanted <= MAX_SAMPLES:
        axis = int(np.argmax(np.abs(q1 - q0)))
        msg = (
            f"the joint move turns axis {axis + 1} by {np.degrees(turn):.6g}°: checking it every "
            f"{wording.exact(np.degrees(_JOINT_STEP_RAD))}° needs {wanted:.4g} samples, more "
            f"than the {MAX_SAMPLES} one move may have"
        )
        return None, [_error("too_long", msg, index, ins)]
    fractions = np.linspace(0.0, 1.0, int(wanted) + 1)[:, None]
    line: FloatArray = q0 + fractions * (q1 - q0)
    return line, []


def _nearest(candidates: FloatArray, q: FloatArray, weights: tuple[float, ...]) -> FloatArray:
    """The candidate (K, 6) nearest to ``q`` in the weighted joint distance."""
    cost = np.sum(np.asarray(weights) * (candidates - q) ** 2, axis=-1)
    best: FloatArray = candidates[np.argmin(cost)]
    return best


def _configured(
    index: int, ins: JointMove, robot: Robot, candidates: FloatArray, config: Configuration
) -> tuple[FloatArray, list[Diagnostic]]:
    """The candidates (K, 6) that meet the configuration the source asks for (KUKA S/T, ABB
    confdata, Fanuc CONFIG): a joint move must take exactly that solution, as the controller
    would. Linear moves keep the branch they start in (controllers ignore S/T there)."""
    from olp.kinematics.configuration import satisfies

    try:
        chosen = candidates[satisfies(config, candidates, robot)]
    except TypeError:  # not an OPW arm: the request cannot be read, say so
        msg = "the target's configuration cannot be checked on this robot; nearest solution used"
        return candidates, [Diagnostic("warning", "configuration_ignored", msg, ins.span, index)]
    if chosen.shape[0] == 0:
        msg = (
            "the target is reachable, but not in the configuration the program asks for "
            f"({_describe(config)}) within the joint limits"
        )
        hint = "re-teach the point, or drop its Status/Turn so olp picks the nearest solution"
        return chosen, [_error("configuration", msg, index, ins, hint=hint)]
    return chosen, []


def _describe(config: Configuration) -> str:
    parts: list[str] = [v for v in (config.shoulder, config.elbow, config.wrist) if v is not None]
    if config.joint_ranges is not None:
        ranges = [
            f"axis {i + 1} in [{wording.exact(float(np.degrees(r[0])))}°, "
            f"{wording.exact(float(np.degrees(r[1])))}°)"
            for i, r in enumerate(config.joint_ranges)
            if r is not None and np.all(np.isfinite(r))
        ]
        parts.extend(ranges)
    return ", ".join(parts) or "no constraint"


def _candidates(robot: Robot, flange: FloatArray) -> FloatArray:
    """Every IK solution within the joint limits, (K, 6), turn variants included."""
    with np.errstate(over="ignore", invalid="ignore"):  # a target 1e308 m away has none
        sols = robot.solve(flange[None])[0]
    variants = turn_variants(sols, robot.limits.lower, robot.limits.upper).reshape(-1, robot.dof)
    ok = np.all(np.isfinite(variants), axis=-1) & ~np.any(
        robot.limits.violations(variants), axis=-1
    )
    return variants[ok]


def _linear_path(
    index: int, ins: LinearMove, tool: Tool, frame: Frame, state: _State
) -> tuple[FloatArray | None, list[Diagnostic]]:
    robot = state.robot
    assert tool.pose is not None
    start = robot.flange_poses(state.q)
    if isinstance(ins.target, JointTarget):
        bad_target = _joint_target_error(index, ins, ins.target, robot)
        if bad_target is not None:
            return None, [bad_target]
        end = robot.flange_poses(ins.target.joints)
    else:
        end = flange_target(ins.target, tool, frame)
        if _candidates(robot, end).shape[0] == 0:
            return None, [_unreachable(index, ins, robot, end)]
    # Sample the TCP line, not the flange line: with a long tool they differ.
    tcp_start, tcp_end = start @ tool.pose, end @ tool.pose
    opts = state.opts
    wanted = float(segment_counts(tcp_start, tcp_end[None], opts.step_m, opts.step_rad)[0])
    if not wanted <= MAX_SAMPLES:
        return None, [_too_long(index, ins, tcp_start, tcp_end, wanted, opts)]
    count = int(wanted)
    dist = float(pose_distance(tcp_start, tcp_end)[0])
    fractions = np.linspace(0.0, 1.0, count + 1)
    flanges = interpolate_poses(tcp_start, tcp_end, fractions) @ inv(tool.pose)
    sols = _branch_path(robot, state.q, robot.solve(flanges, seed=state.q))
    path, failed = _checked_path(index, ins, sols, fractions, dist / count, state, _LINE)
    if path is None:
        return None, failed
    ends = np.array([count], dtype=np.int64)
    one = _Run(
        first=index,
        poses=np.asarray(end)[None],
        frame_poses=np.eye(4)[None],
        speeds=np.array([ins.speed.linear]),
        tool=tool,
        frames=(frame,),
        moves=(ins,),
    )
    return path, _singular_warnings(one, path, ends, fractions, state)


_LINE = ("the straight line", "linear move")
_ARC = ("the arc", "circular move")


def _checked_path(
    index: int,
    ins: Instruction,
    sols: FloatArray,
    fractions: FloatArray,
    spacing: float,
    state: _State,
    words: tuple[str, str],
) -> tuple[FloatArray | None, list[Diagnostic]]:
    """The IK solutions (S, 6) of one branch along a sampled Cartesian path, unwrapped from
    ``state.q``, or the error where they leave the workspace, a joint limit, or jump by more
    than ``max_joint_step_rad`` between samples ``spacing`` m apart (a singularity or a
    configuration flip). ``words``: how the messages name the path and the move."""
    robot = state.robot
    shape, move = words
    if np.any(~np.isfinite(sols)):
        first = int(np.argmax(~np.all(np.isfinite(sols), axis=-1)))
        msg = (
            f"{shape} leaves the robot's workspace at "
            f"{wording.percent(fractions[first])} of the move"
            " (in the configuration the move starts in)"
        )
        return None, [_error("unreachable_path", msg, index, ins)]
    path = _unwrap(state.q, sols)
    bad = robot.limits.violations(path)
    if np.any(bad):
        row = int(np.argmax(np.any(bad, axis=-1)))
        return None, [_limit_error(index, ins, robot, path[row], bad[row], fractions[row])]
    jumps = np.abs(np.diff(path, axis=0))
    if np.any(jumps > state.opts.max_joint_step_rad):
        row = int(np.argmax(np.max(jumps, axis=-1)))
        joint = int(np.argmax(jumps[row]))
        msg = (
            f"axis {joint + 1} would turn {np.degrees(jumps[row, joint]):.1f}° within "
            f"{wording.quantity(spacing * 1000)} mm at {wording.percent(fractions[row])} "
            f"of the {move}: it passes through or near a singularity"
        )
        hint = "use a joint move, or change the tool orientation to avoid the singular pose"
        return None, [_error("singularity", msg, index, ins, joints=path[row], hint=hint)]
    return path, []


def _arc_path(
    index: int, ins: CircularMove, tool: Tool, frame: Frame, state: _State
) -> tuple[FloatArray | None, list[Diagnostic]]:
    """A circular move in one IK branch: the arc (:mod:`olp.arcs`) from the TCP where the robot
    is, past the via point, to the target (or through the circular angle) sampled every
    ``step_m`` of travel, ``step_rad`` of tool turn and ``step_arc_rad`` of arc, the tool
    turning by the move's orientation rule, then checked as a linear move is (workspace,
    limits, joint jumps, singular poses, the joint speed the programmed TCP speed needs).
    Degenerate arcs and an orientation rule olp cannot plan are errors on the move."""
    robot, opts = state.robot, state.opts
    assert tool.pose is not None and frame.pose is not None
    if ins.orientation is ArcOrientation.WRIST:
        msg = (
            "the arc's orientation follows the wrist axes (KUKA $ORI_TYPE #JOINT): olp plans "
            "circular moves only with a Cartesian orientation rule"
        )
        hint = "set $ORI_TYPE = #VAR or #CONSTANT before the arc"
        return None, [_error("unsupported", msg, index, ins, hint=hint)]
    start = robot.flange_poses(state.q) @ tool.pose
    end = _arc_end(index, ins, tool, frame, state)
    if isinstance(end, Diagnostic):
        return None, [end]
    via = frame.pose @ ins.via.pose
    try:
        arc = circle_through(start[:3, 3], via[:3, 3], end[:3, 3], ins.angle)
    except ArcError as exc:
        return None, [_error("degenerate_arc", f"circular move: {exc}", index, ins)]
    turn = rotation_travel(start[:3, :3], end[:3, :3], arc, ins.orientation)
    wanted = sample_count(arc, turn, opts.step_m, opts.step_rad, opts.step_arc_rad)
    if not wanted <= MAX_SAMPLES:
        msg = (
            f"the arc is too long to check: {wording.quantity(arc.length * 1000)} mm over "
            f"{wording.quantity(np.degrees(abs(arc.sweep)))}° needs {wanted:.4g} samples, more "
            f"than the {MAX_SAMPLES} one move may have"
        )
        return None, [_error("too_long", msg, index, ins)]
    count = int(wanted)
    fractions = np.linspace(0.0, 1.0, count + 1)
    rotations = arc_rotations(start[:3, :3], end[:3, :3], arc, fractions, ins.orientation)
    flanges = pose_from(rotations, arc.points(fractions)) @ inv(tool.pose)
    sols = _branch_path(robot, state.q, robot.solve(flanges, seed=state.q))
    spacing = arc.length / count
    path, failed = _checked_path(index, ins, sols, fractions, spacing, state, _ARC)
    if path is None:
        return None, failed
    one = _Run(
        first=index,
        poses=flanges[-1:] @ tool.pose,
        frame_poses=np.eye(4)[None],
        speeds=np.array([ins.speed.linear]),
        tool=tool,
        frames=(frame,),
    )
    found = _singular_warnings(one, path, np.array([count]), fractions, state, _ARC[1])
    found += _arc_speed_warning(index, ins, path, spacing, robot)
    return path, found


def _arc_end(
    index: int, ins: CircularMove, tool: Tool, frame: Frame, state: _State
) -> FloatArray | Diagnostic:
    """The arc's programmed end as a TCP pose (4, 4) in the world, or the error of a target
    that cannot be reached (a joint target's values, or no IK solution for a Cartesian one
    that the arc ends at)."""
    robot = state.robot
    assert tool.pose is not None and frame.pose is not None
    if isinstance(ins.target, JointTarget):
        bad = _joint_target_error(index, ins, ins.target, robot)
        if bad is not None:
            return bad
        tcp: FloatArray = robot.flange_poses(ins.target.joints) @ tool.pose
        return tcp
    flange = flange_target(ins.target, tool, frame)
    if ins.angle is None and _candidates(robot, flange).shape[0] == 0:
        return _unreachable(index, ins, robot, flange)
    return flange @ tool.pose


def _arc_speed_warning(
    index: int, ins: CircularMove, path: FloatArray, spacing: float, robot: Robot
) -> list[Diagnostic]:
    """Warn where the programmed TCP speed needs a joint faster than its limit along an arc
    sampled every ``spacing`` m (as :func:`_speed_warnings` does for linear moves)."""
    if spacing <= 0.0:
        return []
    needed = np.abs(np.diff(path, axis=0)) * (ins.speed.linear / spacing)
    ratio = needed / robot.limits.velocity
    if not np.max(ratio) > 1.0 + 1e-9:
        return []
    row, joint = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
    need, limit = wording.above(
        float(np.degrees(needed[row, joint])), float(np.degrees(robot.limits.velocity[joint]))
    )
    msg = (
        f"move {index}: {wording.quantity(ins.speed.linear * 1000, 0)} mm/s needs axis "
        f"{int(joint) + 1} at {need}°/s (limit {limit}°/s); the TCP will be slower there"
    )
    hint = "lower the speed, or keep the path away from singular poses"
    diag = Diagnostic(
        "warning", "speed_limited", msg, ins.span, index, joints=path[row + 1], hint=hint
    )
    return [diag]


def _joint_target_error(
    index: int, ins: Instruction, target: JointTarget, robot: Robot
) -> Diagnostic | None:
    """The error of a joint target with the wrong number of values or outside the limits."""
    q = target.joints
    if q.shape != (robot.dof,):
        msg = f"joint target has {q.size} values, the robot has {robot.dof} axes"
        return _error("bad_target", msg, index, ins)
    bad = robot.limits.violations(q)
    return _limit_error(index, ins, robot, q, bad) if np.any(bad) else None


def _too_long(
    index: int,
    ins: Instruction,
    start: FloatArray,
    end: FloatArray,
    count: float,
    opts: ResolveOptions,
) -> Diagnostic:
    """A linear move that needs more samples than one check takes (a huge tool or frame)."""
    with np.errstate(over="ignore", invalid="ignore"):
        dist, angle = (float(v) for v in pose_distance(start, end))
    msg = (
        f"the linear move is too long to check at the sampling step: "
        f"{wording.quantity(dist * 1000)} mm and {wording.quantity(np.degrees(angle))}° of TCP "
        f"motion need {count:.4g} samples at {wording.exact(opts.step_m * 1000)} mm / "
        f"{wording.exact(np.degrees(opts.step_rad))}°, more than the {MAX_SAMPLES} one move "
        "may have"
    )
    hint = "check the tool and frame of the move (units: mm in the station)"
    return _error("too_long", msg, index, ins, hint=hint)


def _branch_path(robot: Robot, q: FloatArray, solutions: FloatArray) -> FloatArray:
    """The IK solutions (S, 6) along a path, from all branches (S, B, 6), that a linear move
    from joints ``q`` follows: the branch ``q`` lies in. Where ``q`` is exactly on a
    singularity, the branches that meet there are all continuous with it, and the path takes
    the one whose first solution is nearest ``q`` (from HOME, A5 = 0, a line up needs the
    other wrist branch than a line down). Samples exactly on the wrist singularity get their
    axis 4 / axis 6 split from the sample before (:func:`_settle_wrist`)."""
    options = meeting_branches(robot.kinematics, q, robot.branch_of(q))
    first = solutions[0, options]
    with np.errstate(invalid="ignore"):
        gap = np.sum(((first - q + np.pi) % (2 * np.pi) - np.pi) ** 2, axis=-1)
    branch = options[int(np.argmin(np.where(np.isfinite(gap), gap, np.inf)))]
    return _settle_wrist(robot, q, solutions[:, branch, :])


def _settle_wrist(robot: Robot, q0: FloatArray, sols: FloatArray) -> FloatArray:
    """IK solutions (S, 6) of one branch with every sample exactly on the wrist singularity
    (axes 4 and 6 in line: the pose fixes only their sum or difference, and the IK's split is
    rounding noise) re-split by continuity: axis 4 as in the sample before (``q0`` before the
    first), axis 6 taking the rest, with the sign of the combination that reproduces the
    sample's pose. Other samples are returned as they are."""
    found = singularity_distances(robot.kinematics, sols)
    if found is None:
        return sols
    with np.errstate(invalid="ignore"):
        rows = np.flatnonzero(np.abs(found.wrist) <= ON_SINGULARITY)
    if rows.size == 0:
        return sols
    out = sols.copy()
    for row in rows.tolist():  # rare: a sample exactly on the singularity
        before = q0 if row == 0 else out[row - 1]
        out[row] = _resplit(robot, out[row], float(before[3]))
    return out


def _resplit(robot: Robot, q: FloatArray, axis4: float) -> FloatArray:
    """Joints ``q`` (6,) on the wrist singularity with axis 4 moved to ``axis4`` and axis 6
    turned by the same angle, or the opposite one, whichever keeps the flange pose."""
    pose = robot.flange_poses(q)
    turn = axis4 - q[3]
    for sign in (-1.0, 1.0):
        moved = q.copy()
        moved[3], moved[5] = axis4, q[5] + sign * turn
        if np.allclose(robot.flange_poses(moved), pose, atol=1e-9):
            return moved
    return q


def _unwrap(q0: FloatArray, sols: FloatArray) -> FloatArray:
    """Make IK solutions (S, 6) of one branch continuous from ``q0``: each row is the previous
    one plus the wrapped step, so turns follow from the start joints. Row 0 is (close to) q0."""
    steps = np.diff(np.vstack([q0[None], sols]), axis=0)
    steps = (steps + np.pi) % (2 * np.pi) - np.pi
    out: FloatArray = q0 + np.cumsum(steps, axis=0)
    return out


def _unreachable(index: int, ins: Instruction, robot: Robot, flange: FloatArray) -> Diagnostic:
    with np.errstate(over="ignore", invalid="ignore"):
        sols = robot.solve(flange[None])[0]
        reach = float(np.linalg.norm((inv(robot.base) @ flange)[:3, 3])) * 1000
    finite = sols[np.all(np.isfinite(sols), axis=-1)]
    if finite.shape[0] == 0:
        far = f"{wording.quantity(reach)} mm" if np.isfinite(reach) else "beyond 1e308 mm"
        msg = (
            f"target is out of the robot's reach (flange {far} from the robot base origin; "
            "no IK solution in any configuration)"
        )
        return _error("unreachable", msg, index, ins)
    excess = np.maximum(robot.limits.lower - finite, 0) + np.maximum(finite - robot.limits.upper, 0)
    worst = np.max(excess, axis=-1)
    best = int(np.argmin(worst))
    joint = int(np.argmax(excess[best]))
    msg = (
        f"target is reachable only outside the joint limits: the nearest solution needs axis "
        f"{joint + 1} at {_degrees_outside(robot, joint, finite[best, joint])} "
        f"(limits {_range(robot, joint)})"
    )
    return _error("joint_limit", msg, index, ins, joints=finite[best])


def _limit_error(
    index: int,
    ins: Instruction,
    robot: Robot,
    q: FloatArray,
    bad: NDArray[np.bool_],
    fraction: float | None = None,
) -> Diagnostic:
    joint = int(np.argmax(bad))
    where = "" if fraction is None else f" at {wording.percent(fraction)} of the move"
    msg = (
        f"axis {joint + 1} at {_degrees_outside(robot, joint, q[joint])}{where} is outside "
        f"its limits {_range(robot, joint)}"
    )
    return _error("joint_limit", msg, index, ins, joints=q)


def _degrees_outside(robot: Robot, joint: int, value: float) -> str:
    """A joint value (rad) in degrees, with the decimals that show it outside the limits, and
    the unit (radians for a value beyond the float range in degrees)."""
    lower, upper = np.degrees([robot.limits.lower[joint], robot.limits.upper[joint]])
    with np.errstate(over="ignore"):
        degrees = float(np.degrees(value))
    if not np.isfinite(degrees):
        return f"{float(value):.6g} rad"
    return f"{wording.outside(degrees, float(lower), float(upper))}°"


def _range(robot: Robot, joint: int) -> str:
    lower, upper = np.degrees([robot.limits.lower[joint], robot.limits.upper[joint]])
    return f"{wording.exact(float(lower))}° .. {wording.exact(float(upper))}°"


def resolve_pass(compiled: CompiledProgram, options: BuildOptions) -> CompiledProgram:
    """The resolve pass: every motion of ``compiled.program`` resolved on its station
    (:func:`resolve`, with ``options.resolve``); diagnostics of earlier passes are kept."""
    resolved = resolve(compiled.program, compiled.station, options.resolve, compiled.start_joints)
    return dataclasses.replace(resolved, diagnostics=compiled.diagnostics + resolved.diagnostics)
