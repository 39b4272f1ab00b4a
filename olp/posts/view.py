"""What a post's templates see: one :class:`PostStep` per compiled instruction, the tools and
frames a file uses (:class:`PostTool`, :class:`PostFrame`), legal unique names for everything olp
names, and :class:`Modal` for modal controller state.

The view is computed once per render (poses, vendor values per motion, names), then cut into the
files of a split program (:meth:`ProgramView.unit_steps`: change flags start afresh per file).
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, TypedDict

import numpy as np
from numpy.typing import NDArray

from olp.compiled import BlockRows, PathBlock, items_of
from olp.geometry import inv
from olp.ir import (
    FLANGE,
    MOTION_TYPES,
    CartesianTarget,
    CircularMove,
    Frame,
    JointMove,
    RuntimeMove,
    Tool,
    Zone,
)

if TYPE_CHECKING:
    from olp.compiled import CompiledProgram, Step
    from olp.posts.manifest import PostManifest
    from olp.posts.text import NameRule

FloatArray = NDArray[np.float64]


class ViewHooks(Protocol):
    """What the view asks of a post (:class:`olp.posts.base.Post` provides all of it)."""

    @property
    def NULL_TOOL_NAME(self) -> str | None: ...

    @property
    def NULL_FRAME_NAME(self) -> str | None: ...

    @property
    def NAME_RULE(self) -> NameRule: ...

    @property
    def manifest(self) -> PostManifest: ...

    @property
    def VERBATIM(self) -> str | None: ...

    def step_values(self, robot: Any, joints: FloatArray) -> list[Mapping[str, Any]]: ...

    def step_columns(self, robot: Any, joints: FloatArray) -> Mapping[str, Any]: ...

    def comment_lines(self, text: str) -> tuple[str, ...]: ...

    def comment_node_lines(self, comment: Any) -> tuple[str, ...]: ...


@dataclass(frozen=True, slots=True, eq=False)
class PostTool:
    """A tool as the output names it: ``name`` (legal, unique in the program), ``tool`` (the
    resolved tool; its ``pose`` is the TCP in the vendor's flange frame, (4, 4) m), ``number``
    (the station's number or None), ``mass`` (kg from the station, None when unknown), ``null``
    (it is the bare flange)."""

    name: str
    tool: Tool
    number: int | None
    mass: float | None
    null: bool = False

    @property
    def pose(self) -> FloatArray:
        assert self.tool.pose is not None
        return self.tool.pose


@dataclass(frozen=True, slots=True, eq=False)
class PostFrame:
    """A frame as the output names it: ``name`` (legal, unique in the program), ``frame`` (the
    resolved frame, pose in the station's world), ``number`` (the station's number or None),
    ``pose`` ((4, 4) m, relative to the manifest's ``frames_in`` reference: what the controller
    is told), ``null`` (it is the reference itself: the world, or the robot base)."""

    name: str
    frame: Frame
    number: int | None
    pose: FloatArray
    null: bool = False


@dataclass(frozen=True, slots=True, eq=False)
class PostStep:
    """What a template sees for one instruction.

    Every instruction: ``index`` (in the program), ``kind`` (``joint``, ``linear``,
    ``circular``, ``wait``, ``set_output``, ``wait_input``, ``call``, ``comment``), ``source``
    (``file:line``), ``instruction`` (the IR object).

    Motions:

    * ``joints``: planned joints at the end, (dof,) rad, controller convention.
    * ``pose``: the TCP in the motion's frame, (4, 4) m (the target itself for a Cartesian
      target; from the planned joints otherwise).
    * ``tool`` / ``frame``: the resolved :class:`olp.ir.Tool` / :class:`olp.ir.Frame`.
    * ``cartesian``: the source gave a Cartesian target.
    * ``new_tool``, ``new_frame``, ``new_linear_speed``, ``new_joint_speed``, ``new_zone``:
      the value differs from the previous motion's *in this file* (each file starts afresh, so
      a part never relies on state set by another), or a call or kept line
      (:data:`OPAQUE_KINDS`) came between, which may have changed any of them.
    * ``motion`` (added): 1-based number of the motion in the whole program.
    * ``name`` (added): a legal identifier for the target, unique in the program (the manifest
      option ``point_names``, default ``"P{n}"``, with ``n`` = ``motion``).
    * ``via`` / ``via_name`` (added): a circular move's auxiliary point, (4, 4) m in the frame,
      and its identifier (option ``via_names``, default ``"V{n}"``).
    * ``tool_name`` / ``frame_name`` (added): the names of this motion's :class:`PostTool` /
      :class:`PostFrame` (see the ``tools`` / ``frames`` context entries).
    * ``frame_pose`` (added): the frame as the controller is told, (4, 4) m relative to the
      manifest's ``frames_in`` reference; ``base_pose`` (added): the TCP in that reference,
      ``frame_pose @ pose``.
    * ``duration`` (added): seconds, from the timing pass (0 when it did not run).
    * ``vendor`` (added): per-motion values from the post's ``step_values`` (KUKA ``status``,
      ``turn``; ABB ``confdata``; Fanuc ``config``), empty for posts without them.

    Motions to run-time targets (kind ``runtime_move``, ``instruction`` an
    :class:`olp.ir.RuntimeMove`: ``instruction.motion`` says joint, linear or circular and
    ``instruction.target`` / ``instruction.via`` are expressions): ``tool``, ``frame``,
    ``tool_name``, ``frame_name``, ``frame_pose`` and the ``new_*`` flags as for any motion (the
    settings it runs with are written before it); ``motion`` is 0, and there is no ``joints``,
    ``pose`` or ``name``. One that runs with the controller's settings
    (``instruction.controller_settings``) has no tool, frame or flags: nothing is written before
    it, and the motion after it writes every setting.

    Comments: ``comment`` (added), the text as the post's comment lines (escaped: a line break
    of the text starts another comment line, never a statement).

    Properties ``speed`` and ``zone`` are the instruction's.
    """

    index: int
    kind: str
    source: str
    instruction: Any
    joints: FloatArray | None = None
    pose: FloatArray | None = None
    tool: Tool | None = None
    frame: Frame | None = None
    cartesian: bool = False
    new_tool: bool = False
    new_frame: bool = False
    new_linear_speed: bool = False
    new_joint_speed: bool = False
    new_zone: bool = False
    motion: int = 0
    name: str = ""
    via: FloatArray | None = None
    via_name: str = ""
    tool_name: str = ""
    frame_name: str = ""
    frame_pose: FloatArray | None = None
    base_pose: FloatArray | None = None
    duration: float = 0.0
    vendor: Mapping[str, Any] = field(default_factory=dict)
    comment: tuple[str, ...] = ()

    @property
    def speed(self) -> Any:
        return self.instruction.speed

    @property
    def zone(self) -> Any:
        return self.instruction.zone


def build_steps(compiled: CompiledProgram, post: ViewHooks | None = None) -> list[PostStep]:
    """The template view of every compiled instruction as one file, with modal-state change
    flags (generic names and no vendor values without a ``post``)."""
    hooks: ViewHooks
    if post is None:
        from olp.posts.base import Post
        from olp.posts.manifest import PostManifest

        hooks = Post(PostManifest("", "", Path("."), ()))
    else:
        hooks = post
    compiled = compiled.flat()
    view = ProgramView(compiled, hooks)
    steps = view.unit_steps(compiled.steps, view.allocate(Names(hooks.NAME_RULE, ())))
    return [s for s in steps if isinstance(s, PostStep)]


@dataclass(frozen=True, slots=True, eq=False)
class _Motion:
    """Per-motion data computed once per render (not per file)."""

    pose: FloatArray
    frame_pose: FloatArray
    via: FloatArray | None
    vendor: Mapping[str, Any]
    number: int
    base_pose: FloatArray


@dataclass(frozen=True, slots=True, eq=False)
class BlockMotions:
    """A toolpath block's rows, computed once per render: ``number`` (the motion number of
    row 0), ``frame_pose`` (the frame relative to the reference, (4, 4) m) and ``columns``
    (the post's per-row values, each an array (N,))."""

    block: PathBlock
    number: int
    frame_pose: FloatArray
    columns: Mapping[str, Any]


@dataclass(frozen=True, slots=True, eq=False)
class BlockNames:
    """A toolpath block's point names (one per row) and its named tool and frame."""

    names: Sequence[str]
    tool: PostTool
    frame: PostFrame


@dataclass(frozen=True, slots=True, eq=False)
class RowColumns:
    """Rows ``piece.lo`` .. ``piece.hi`` of a toolpath block as one item of a file's steps
    (``kind`` ``"rows"``): what a post's column writer formats, as arrays, with no object per
    row. ``motion`` is 0 so that a template's motion branch skips it; ``index``, ``source`` and
    ``instruction`` are the first row's. ``new_tool``/``new_frame``: row 0 changes the tool /
    frame (the rows share one of each); ``new_linear_speed``/``new_zone`` (n,): the row's speed
    / zone differs from the motion before it in this file. :meth:`at` is row ``k`` as a
    :class:`PostStep` (for the few rows that need one: a changed frame, an error's line)."""

    piece: BlockRows
    motions: BlockMotions
    names: Sequence[str]
    tool_item: PostTool
    frame_item: PostFrame
    new_tool: bool
    new_frame: bool
    new_linear_speed: NDArray[np.bool_]
    new_zone: NDArray[np.bool_]
    kind: str = "rows"
    motion: int = 0

    def __len__(self) -> int:
        return len(self.piece)

    @property
    def node(self) -> Any:
        return self.piece.block.node

    @property
    def index(self) -> int:
        return self.piece.index

    @property
    def source(self) -> str:
        return str(self.node.row_span(self.piece.lo).location)

    @property
    def instruction(self) -> Any:
        return self.node.move(self.piece.lo)

    @property
    def poses(self) -> FloatArray:
        """The targets (n, 4, 4) m in the frame."""
        return self.node.poses[self.piece.lo : self.piece.hi]

    @property
    def speeds(self) -> FloatArray:
        """Path speeds (n,) m/s."""
        return self.node.speeds[self.piece.lo : self.piece.hi]

    @property
    def zones(self) -> FloatArray:
        """Zone radii (n,) m (0: a fine stop)."""
        return self.node.zones[self.piece.lo : self.piece.hi]

    def column(self, key: str) -> NDArray[Any]:
        """The post's per-row value ``key`` (``vendor[key]`` of a step), (n,) or (n, k)."""
        values: NDArray[Any] = self.motions.columns[key]
        return values[self.piece.lo : self.piece.hi]

    def at(self, k: int) -> PostStep:
        """Row ``k`` of these rows as the :class:`PostStep` a template would see."""
        block, row = self.piece.block, self.piece.lo + k
        node, motions = block.node, self.motions
        assert block.joints is not None
        pose = node.poses[row]
        return PostStep(
            block.start + row,
            "linear",
            node.row_span(row).location,
            node.move(row),
            joints=block.joints[row],
            pose=pose,
            tool=block.tool,
            frame=block.frame,
            cartesian=True,
            motion=motions.number + row,
            name=self.names[k],
            tool_name=self.tool_item.name,
            frame_name=self.frame_item.name,
            frame_pose=motions.frame_pose,
            base_pose=motions.frame_pose @ pose,
            duration=0.0 if block.durations is None else float(block.durations[row]),
            vendor={key: _row_value(v[row]) for key, v in motions.columns.items()},
            new_tool=self.new_tool and k == 0,
            new_frame=self.new_frame and k == 0,
            new_zone=bool(self.new_zone[k]),
            new_linear_speed=bool(self.new_linear_speed[k]),
        )


def _row_value(value: Any) -> Any:
    """One row of a post's column as :meth:`ViewHooks.step_values` gives it: a Python scalar,
    a tuple of them for a column of several values per row (ABB's confdata, (n, 4)), or the
    object itself from a column of objects (Fanuc's CONFIG texts and None)."""
    if not isinstance(value, np.ndarray | np.generic):
        return value
    return value.item() if value.ndim == 0 else tuple(value.tolist())


@dataclass(frozen=True, slots=True)
class Allocation:
    """Names given to one program's points, tools and frames."""

    points: Mapping[int, tuple[str, str]]
    tools: Mapping[int, PostTool]
    frames: Mapping[int, PostFrame]
    blocks: Mapping[int, BlockNames] = field(default_factory=dict)
    """Per toolpath block (by its first instruction index): its rows' names, tool and frame."""


class ProgramView:
    """Everything the templates see that does not depend on how the program is split."""

    def __init__(self, compiled: CompiledProgram, post: ViewHooks) -> None:
        self.compiled = compiled
        self.post = post
        manifest = post.manifest
        robot = compiled.station.robot
        self.reference = (
            robot.base @ robot.controller_base if manifest.frames_in == "robot_base" else np.eye(4)
        )
        self._ref_inv = inv(self.reference)
        self._frame_poses: dict[int, tuple[Frame, FloatArray]] = {}
        self.blocks: dict[int, BlockMotions] = {}
        """Per toolpath block (by its first instruction index), its rows as columns."""
        self.motions = self._motions()

    def _motions(self) -> dict[int, _Motion]:
        from olp.compiled import PathBlock, items_of

        number = 0
        written: list[tuple[Step, int]] = []
        for item in items_of(self.compiled.steps):
            if isinstance(item, PathBlock):
                if item.joints is not None:
                    self.blocks[item.start] = self._block_motions(item, number + 1)
                    number += len(item)
            elif _written_motion(item):
                number += 1
                written.append((item, number))
        if not written:
            return {}
        robot = self.compiled.station.robot
        joints = np.stack([np.asarray(s.joints, dtype=np.float64) for s, _ in written])
        flanges = robot.flange_poses(joints)
        values = self._vendor_values(joints)
        # Frames are few (a toolpath's rows share one object): each one's pose once.
        framed = [self._frame_pose(s.frame) for s, _ in written]
        poses = np.stack([_pose_in_frame(s, f) for (s, _), f in zip(written, flanges, strict=True)])
        bases = np.stack(framed) @ poses
        out = {}
        for n, ((step, k), vendor) in enumerate(zip(written, values, strict=True)):
            out[step.index] = _Motion(
                pose=poses[n],
                frame_pose=framed[n],
                via=_via(step),
                vendor=vendor,
                number=k,
                base_pose=bases[n],
            )
        return out

    def _frame_pose(self, frame: Frame | None) -> FloatArray:
        """``frame`` relative to the reference (once per frame object)."""
        assert frame is not None and frame.pose is not None
        known = self._frame_poses.get(id(frame))
        if known is None or known[0] is not frame:
            known = (frame, self._ref_inv @ frame.pose)
            self._frame_poses[id(frame)] = known
        return known[1]

    def _block_motions(self, block: PathBlock, number: int) -> BlockMotions:
        """A toolpath's rows as columns: targets in the frame (the rows are Cartesian), the
        post's per-row values as arrays (:meth:`ViewHooks.step_columns`)."""
        assert block.joints is not None
        columns = self.post.step_columns(self.compiled.station.robot, block.joints)
        return BlockMotions(block, number, self._frame_pose(block.frame), columns)

    def _vendor_values(self, joints: FloatArray) -> list[Mapping[str, Any]]:
        return self.post.step_values(self.compiled.station.robot, joints)

    def allocate(self, names: Names) -> Allocation:
        """Give every point, tool and frame of the program a name."""
        options = self.post.manifest.options
        point_pattern = str(options.get("point_names", "P{n}"))
        via_pattern = str(options.get("via_names", "V{n}"))
        points: dict[int, tuple[str, str]] = {}
        tools: dict[int, PostTool] = {}
        frames: dict[int, PostFrame] = {}
        self._tool_keys: dict[tuple[str, bytes], PostTool] = {}
        self._frame_keys: dict[tuple[str, bytes], PostFrame] = {}
        # The same tool or frame object again (a toolpath's rows): the same named one.
        by_object: dict[int, tuple[Any, PostTool | PostFrame]] = {}
        blocks: dict[int, BlockNames] = {}
        for item in items_of(self.compiled.steps):
            if isinstance(item, PathBlock):
                if item.start in self.blocks:
                    blocks[item.start] = self._block_names(item, names, point_pattern, by_object)
                continue
            step = item
            motion = self.motions.get(step.index)
            if motion is None:
                if _written_runtime(step):
                    tools[step.index], frames[step.index] = self._tool_frame(
                        step.tool, step.frame, self._frame_pose(step.frame), names, by_object
                    )
                continue
            via = names.take(via_pattern.format(n=motion.number)) if motion.via is not None else ""
            points[step.index] = (names.take(point_pattern.format(n=motion.number)), via)
            tools[step.index], frames[step.index] = self._tool_frame(
                step.tool, step.frame, motion.frame_pose, names, by_object
            )
        return Allocation(points, tools, frames, blocks)

    def _tool_frame(
        self,
        tool: Tool | None,
        frame: Frame | None,
        frame_pose: FloatArray,
        names: Names,
        by_object: dict[int, tuple[Any, Any]],
    ) -> tuple[PostTool, PostFrame]:
        """The named tool and frame of a motion (the same object again: the same named one)."""
        assert tool is not None and frame is not None
        known = by_object.get(id(tool))
        if known is None or known[0] is not tool:
            known = (tool, self._tool(tool, self._tool_keys, names))
            by_object[id(tool)] = known
        seen = by_object.get(id(frame))
        if seen is None or seen[0] is not frame:
            seen = (frame, self._frame(frame, frame_pose, self._frame_keys, names))
            by_object[id(frame)] = seen
        return known[1], seen[1]

    def _block_names(
        self,
        block: PathBlock,
        names: Names,
        pattern: str,
        by_object: dict[int, tuple[Any, Any]],
    ) -> BlockNames:
        """A toolpath's point names, taken in the order the rows' steps would take them: row
        0's, then the tool's and the frame's (when first met), then the others'."""
        motions = self.blocks[block.start]
        first = names.take(pattern.format(n=motions.number))
        tool, frame = self._tool_frame(
            block.tool, block.frame, motions.frame_pose, names, by_object
        )
        wanted = [pattern.format(n=motions.number + k) for k in range(1, len(block))]
        return BlockNames([first, *names.take_many(wanted)], tool, frame)

    def _tool(self, tool: Tool, seen: dict[tuple[str, bytes], PostTool], names: Names) -> PostTool:
        assert tool.pose is not None
        key = (tool.name, np.asarray(tool.pose).tobytes())
        if key not in seen:
            null = _is_null(tool, FLANGE)
            special = self.post.NULL_TOOL_NAME if null else None
            body = self.compiled.station.tool_bodies.get(tool.name)
            seen[key] = PostTool(
                special or names.take(tool.name),
                tool,
                tool.number,
                None if body is None else body.mass,
                null,
            )
        return seen[key]

    def _frame(
        self,
        frame: Frame,
        pose: FloatArray,
        seen: dict[tuple[str, bytes], PostFrame],
        names: Names,
    ) -> PostFrame:
        assert frame.pose is not None
        key = (frame.name, np.asarray(frame.pose).tobytes())
        if key not in seen:
            null = bool(np.allclose(pose, np.eye(4), rtol=0.0, atol=1e-12))
            special = self.post.NULL_FRAME_NAME if null else None
            seen[key] = PostFrame(
                special or names.take(frame.name), frame, frame.number, pose, null
            )
        return seen[key]

    def unit_steps(
        self, steps: Sequence[Step | BlockRows], names: Allocation
    ) -> list[PostStep | RowColumns]:
        """The template view of ``steps`` as one file: change flags start afresh. A toolpath's
        rows (:class:`~olp.compiled.BlockRows`) are one :class:`RowColumns` item."""
        out: list[PostStep | RowColumns] = []
        last: dict[str, Any] = {}
        for step in steps:
            if isinstance(step, BlockRows):
                if step.block.start in self.blocks:
                    out.append(self._rows(step, names, last))
                continue
            ins = step.instruction
            if isinstance(ins, RuntimeMove) and ins.controller_settings:
                out.append(PostStep(step.index, ins.kind, ins.span.location, ins))
                last.clear()  # it runs with the controller's settings: the next sets its own
            elif isinstance(ins, RuntimeMove):
                if _written_runtime(step):
                    out.append(self._runtime_step(step, names, last))
            elif not isinstance(ins, MOTION_TYPES):
                lines = self.post.comment_node_lines(ins) if ins.kind == "comment" else ()
                out.append(PostStep(step.index, ins.kind, ins.span.location, ins, comment=lines))
                if is_opaque(ins, self.post.VERBATIM):
                    last.clear()  # the next motion sets everything again
            elif step.index in self.motions:
                out.append(self._motion_step(step, names, last))
        return out

    def _rows(self, piece: BlockRows, names: Allocation, last: dict[str, Any]) -> RowColumns:
        """A toolpath's rows as columns, their change flags computed over the arrays (the rows
        share one tool and frame; angular speed and accelerations are the block's)."""
        block = piece.block
        named = names.blocks[block.start]
        new_tool, new_frame, new_speed, new_zone = row_changes(piece, last)
        return RowColumns(
            piece,
            self.blocks[block.start],
            named.names[piece.lo : piece.hi],
            named.tool,
            named.frame,
            new_tool,
            new_frame,
            new_speed,
            new_zone,
        )

    def _runtime_step(self, step: Step, names: Allocation, last: dict[str, Any]) -> PostStep:
        """A motion to a run-time target (kind ``runtime_move``): its tool, frame and change
        flags as any motion's, so that the settings it runs with are written before it; no
        point, pose or joints (the target is ``instruction.target``, an expression)."""
        ins: Any = step.instruction
        flags = _settings_changed(step, ins.motion == "joint", last)
        assert step.frame is not None
        return PostStep(
            step.index,
            ins.kind,
            ins.span.location,
            ins,
            tool=step.tool,
            frame=step.frame,
            tool_name=names.tools[step.index].name,
            frame_name=names.frames[step.index].name,
            frame_pose=self._frame_pose(step.frame),
            **flags,
        )

    def _motion_step(self, step: Step, names: Allocation, last: dict[str, Any]) -> PostStep:
        ins: Any = step.instruction
        motion = self.motions[step.index]
        flags = _settings_changed(step, isinstance(ins, JointMove), last)
        point, via = names.points[step.index]
        return PostStep(
            step.index,
            ins.kind,
            ins.span.location,
            ins,
            joints=step.joints,
            pose=motion.pose,
            tool=step.tool,
            frame=step.frame,
            cartesian=isinstance(ins.target, CartesianTarget),
            motion=motion.number,
            name=point,
            via=motion.via,
            via_name=via,
            tool_name=names.tools[step.index].name,
            frame_name=names.frames[step.index].name,
            frame_pose=motion.frame_pose,
            base_pose=motion.base_pose,
            duration=step.duration,
            vendor=motion.vendor,
            **flags,
        )


class _Flags(TypedDict):
    new_tool: bool
    new_frame: bool
    new_zone: bool
    new_joint_speed: bool
    new_linear_speed: bool


def _settings_changed(step: Step, joint: bool, last: dict[str, Any]) -> _Flags:
    """The ``new_*`` flags of a motion (its settings against ``last``, which records them)."""
    ins: Any = step.instruction
    speed = ins.speed
    new_tool = _changed_object(last, "tool", step.tool)
    new_frame = _changed_object(last, "frame", step.frame)
    new_zone = _changed_value(last, "zone", ins.zone)
    new_joint_speed = joint and _changed_value(
        last, "joint_speed", (speed.joint, speed.joint_acceleration)
    )
    new_linear_speed = not joint and _changed_value(
        last,
        "linear_speed",
        (speed.linear, speed.angular, speed.linear_acceleration, speed.angular_acceleration),
    )
    return _Flags(
        new_tool=new_tool,
        new_frame=new_frame,
        new_zone=new_zone,
        new_joint_speed=new_joint_speed,
        new_linear_speed=new_linear_speed,
    )


def row_changes(
    piece: BlockRows, last: dict[str, Any]
) -> tuple[bool, bool, NDArray[np.bool_], NDArray[np.bool_]]:
    """Which of a toolpath piece's settings change: its tool and frame (once, the rows share
    them) and, per row, its speed and zone, against the previous motion's (``last``, which it
    updates to the piece's last row)."""
    block, node = piece.block, piece.block.node
    new_tool = _changed_object(last, "tool", block.tool)
    new_frame = _changed_object(last, "frame", block.frame)
    zones = node.zones[piece.lo : piece.hi]
    speeds = node.speeds[piece.lo : piece.hi]
    new_zone = np.empty(len(piece), dtype=bool)
    new_zone[0] = _changed_value(last, "zone", Zone(float(zones[0])))
    new_zone[1:] = zones[1:] != zones[:-1]
    last["zone"] = Zone(float(zones[-1]))
    rest = (node.angular, node.acceleration, node.angular_acceleration)
    new_speed = np.empty(len(piece), dtype=bool)
    new_speed[0] = _changed_value(last, "linear_speed", (float(speeds[0]), *rest))
    new_speed[1:] = speeds[1:] != speeds[:-1]
    last["linear_speed"] = (float(speeds[-1]), *rest)
    return new_tool, new_frame, new_speed, new_zone


OPAQUE_KINDS = frozenset({"call", "verbatim"})
"""Instructions that may change the controller's motion settings (a called routine, a kept
line olp does not model: either may set another tool, base, speed or zone): the first motion
after one gets every ``new_*`` flag, so the post writes all its settings again."""


def is_opaque(ins: Any, language: str | None = None) -> bool:
    """Whether ``ins`` may change the controller's motion settings (:data:`OPAQUE_KINDS`; a
    verbatim statement marked ``native_only`` changes none of them, unless it is ``modelled``
    and written here, by the post of its ``language``: it sets settings on the controller,
    which the next motion then writes again with olp's values)."""
    if getattr(ins, "modelled", False):
        return ins.language == language
    return ins.kind in OPAQUE_KINDS and not getattr(ins, "native_only", False)


def _changed_object(last: dict[str, Any], key: str, value: Any) -> bool:
    """:func:`changed`, without comparing when ``value`` is the object recorded."""
    if key in last and last[key] is value:
        return False
    return changed(last, key, value)


def _changed_value(last: dict[str, Any], key: str, value: Any) -> bool:
    """:func:`changed` for a value without arrays or poses (a zone, a tuple of speeds), which
    compares with ``==`` as :func:`_same` would."""
    same = key in last and (last[key] is value or last[key] == value)
    last[key] = value
    return not same


def _written_motion(step: Step) -> bool:
    motion = isinstance(step.instruction, MOTION_TYPES)
    return motion and not step.skipped and step.joints is not None


def _written_runtime(step: Step) -> bool:
    """Whether a motion to a run-time target is written with settings: its tool and frame
    resolved (one that runs with the controller's settings has none)."""
    tool, frame = step.tool, step.frame
    return (
        tool is not None and tool.pose is not None and frame is not None and frame.pose is not None
    )


def _is_null(obj: Tool | Frame, null: Tool | Frame) -> bool:
    assert obj.pose is not None
    return obj.name == null.name and bool(np.array_equal(obj.pose, np.eye(4)))


def _via(step: Step) -> FloatArray | None:
    ins = step.instruction
    return np.array(ins.via.pose) if isinstance(ins, CircularMove) else None


def _pose_in_frame(step: Step, flange: FloatArray) -> FloatArray:
    ins = step.instruction
    if isinstance(ins, MOTION_TYPES) and isinstance(ins.target, CartesianTarget):
        return np.array(ins.target.pose)
    assert step.tool is not None and step.frame is not None
    assert step.tool.pose is not None and step.frame.pose is not None
    result: FloatArray = inv(step.frame.pose) @ flange @ step.tool.pose
    return result


class Names:
    """Identifiers that are legal for the post (its :class:`~olp.posts.text.NameRule`) and
    unique ignoring case; ``reserved``: names already taken (the controller's own)."""

    def __init__(self, rule: NameRule, reserved: Sequence[str]) -> None:
        self.rule = rule
        self.taken = {r.casefold() for r in reserved}

    def take(self, wanted: str) -> str:
        base = wanted if self._legal_as_is(wanted) else self.rule.legal(wanted)
        name, k = base, 2
        limit = self.rule.max_length
        while name.casefold() in self.taken:
            suffix = f"_{k}"
            cut = base if limit is None else base[: limit - len(suffix)]
            name, k = self.rule.legal(cut + suffix), k + 1
        self.taken.add(name.casefold())
        return name

    def take_many(self, wanted: Sequence[str]) -> list[str]:
        """:meth:`take` of each name in order; at once when all are legal as they are, distinct
        and free (a toolpath's generated point names)."""
        folded = {w.casefold() for w in wanted}
        if (
            len(folded) == len(wanted)
            and folded.isdisjoint(self.taken)
            and self._all_legal_as_is(wanted)
        ):
            self.taken |= folded
            return list(wanted)
        return [self.take(w) for w in wanted]

    def _all_legal_as_is(self, names: Sequence[str]) -> bool:
        """:meth:`_legal_as_is` of every name, checked on the names joined by line breaks."""
        if not names:
            return True
        rule = self.rule
        joined = "\n".join(names)
        compared = names if rule.case_sensitive else [n.upper() for n in names]
        return (
            _PLAIN_NAMES.fullmatch(joined) is not None
            and (not rule.upper or joined == joined.upper())
            and (rule.max_length is None or max(map(len, names)) <= rule.max_length)
            and rule.reserved.isdisjoint(compared)
        )

    def _legal_as_is(self, name: str) -> bool:
        """Whether ``rule.legal(name)`` is ``name`` itself, without building it (a point name
        per row of a toolpath): ASCII letters, digits and ``_``, a letter first, upper case
        where the rule says so, short enough, not reserved."""
        rule = self.rule
        return (
            _PLAIN_NAME.match(name) is not None
            and (not rule.upper or name == name.upper())
            and (rule.max_length is None or len(name) <= rule.max_length)
            and not rule.is_reserved(name)
        )


_PLAIN_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
_PLAIN_NAMES = re.compile(r"[A-Za-z][A-Za-z0-9_]*(?:\n[A-Za-z][A-Za-z0-9_]*)*")


class Modal:
    """Tracks modal controller state while a template is rendered.

    ``changed(key, value)`` is True when ``value`` differs from the last value recorded under
    ``key`` (or none was), and records it. Arrays compare by value, tools and frames by name
    and pose.
    """

    def __init__(self) -> None:
        self._last: dict[str, Any] = {}

    def changed(self, key: str, value: Any) -> bool:
        return changed(self._last, key, value)

    def forget(self, key: str) -> str:
        """Drop ``key`` (e.g. after a call that may change the state); renders as ''."""
        self._last.pop(key, None)
        return ""


def changed(last: dict[str, Any], key: str, value: Any) -> bool:
    """Whether ``value`` differs from ``last[key]`` (or there is none); records it."""
    same = key in last and _same(last[key], value)
    last[key] = value
    return not same


def _same(a: Any, b: Any) -> bool:
    if a is b:
        return True
    if type(a) is tuple and type(b) is tuple:
        return bool(a == b)
    if hasattr(a, "pose") and hasattr(b, "pose"):
        return bool(a.name == b.name and np.array_equal(a.pose, b.pose))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return bool(np.array_equal(a, b))
    return bool(a == b)
