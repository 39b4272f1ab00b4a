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
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import NDArray

from olp.geometry import inv
from olp.ir import FLANGE, MOTION_TYPES, CartesianTarget, CircularMove, Frame, JointMove, Tool

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

    def step_values(self, robot: Any, joints: FloatArray) -> list[Mapping[str, Any]]: ...

    def comment_lines(self, text: str) -> tuple[str, ...]: ...


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
      a part never relies on state set by another).
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
    view = ProgramView(compiled, hooks)
    return view.unit_steps(compiled.steps, view.allocate(Names(hooks.NAME_RULE, ())))


@dataclass(frozen=True, slots=True, eq=False)
class _Motion:
    """Per-motion data computed once per render (not per file)."""

    pose: FloatArray
    frame_pose: FloatArray
    via: FloatArray | None
    vendor: Mapping[str, Any]
    number: int
    base_pose: FloatArray


@dataclass(frozen=True, slots=True)
class Allocation:
    """Names given to one program's points, tools and frames."""

    points: Mapping[int, tuple[str, str]]
    tools: Mapping[int, PostTool]
    frames: Mapping[int, PostFrame]


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
        self.motions = self._motions()

    def _motions(self) -> dict[int, _Motion]:
        written = [s for s in self.compiled.steps if _written_motion(s)]
        if not written:
            return {}
        robot = self.compiled.station.robot
        joints = np.stack([np.asarray(s.joints, dtype=np.float64) for s in written])
        flanges = robot.flange_poses(joints)
        values = self._vendor_values(joints)
        ref_inv = inv(self.reference)
        # Frames are few (a toolpath's rows share one object): each one's pose once.
        frame_poses: dict[int, FloatArray] = {}
        for step in written:
            assert step.frame is not None and step.frame.pose is not None
            if id(step.frame) not in frame_poses:
                frame_poses[id(step.frame)] = ref_inv @ step.frame.pose
        framed = [frame_poses[id(s.frame)] for s in written]
        poses = np.stack([_pose_in_frame(s, f) for s, f in zip(written, flanges, strict=True)])
        bases = np.stack(framed) @ poses
        out = {}
        for n, (step, vendor) in enumerate(zip(written, values, strict=True)):
            out[step.index] = _Motion(
                pose=poses[n],
                frame_pose=framed[n],
                via=_via(step),
                vendor=vendor,
                number=n + 1,
                base_pose=bases[n],
            )
        return out

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
        tool_keys: dict[tuple[str, bytes], PostTool] = {}
        frame_keys: dict[tuple[str, bytes], PostFrame] = {}
        # The same tool or frame object again (a toolpath's rows): the same named one.
        by_object: dict[int, tuple[Any, PostTool | PostFrame]] = {}
        for step in self.compiled.steps:
            motion = self.motions.get(step.index)
            if motion is None:
                continue
            via = names.take(via_pattern.format(n=motion.number)) if motion.via is not None else ""
            points[step.index] = (names.take(point_pattern.format(n=motion.number)), via)
            assert step.tool is not None and step.frame is not None
            known = by_object.get(id(step.tool))
            if known is None or known[0] is not step.tool:
                known = (step.tool, self._tool(step.tool, tool_keys, names))
                by_object[id(step.tool)] = known
            tools[step.index] = known[1]  # type: ignore[assignment]
            seen = by_object.get(id(step.frame))
            if seen is None or seen[0] is not step.frame:
                seen = (step.frame, self._frame(step.frame, motion.frame_pose, frame_keys, names))
                by_object[id(step.frame)] = seen
            frames[step.index] = seen[1]  # type: ignore[assignment]
        return Allocation(points, tools, frames)

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

    def unit_steps(self, steps: Sequence[Step], names: Allocation) -> list[PostStep]:
        """The template view of ``steps`` as one file: change flags start afresh."""
        out: list[PostStep] = []
        last: dict[str, Any] = {}
        for step in steps:
            ins = step.instruction
            if not isinstance(ins, MOTION_TYPES):
                lines = self.post.comment_lines(ins.text) if ins.kind == "comment" else ()
                out.append(PostStep(step.index, ins.kind, ins.span.location, ins, comment=lines))
            elif step.index in self.motions:
                out.append(self._motion_step(step, names, last))
        return out

    def _motion_step(self, step: Step, names: Allocation, last: dict[str, Any]) -> PostStep:
        ins: Any = step.instruction
        motion = self.motions[step.index]
        new_tool = _changed_object(last, "tool", step.tool)
        new_frame = _changed_object(last, "frame", step.frame)
        new_zone = _changed_value(last, "zone", ins.zone)
        joint = isinstance(ins, JointMove)
        speed = ins.speed
        new_joint_speed = joint and _changed_value(
            last, "joint_speed", (speed.joint, speed.joint_acceleration)
        )
        new_linear_speed = not joint and _changed_value(
            last,
            "linear_speed",
            (speed.linear, speed.angular, speed.linear_acceleration, speed.angular_acceleration),
        )
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
            new_tool=new_tool,
            new_frame=new_frame,
            new_zone=new_zone,
            new_joint_speed=new_joint_speed,
            new_linear_speed=new_linear_speed,
        )


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
