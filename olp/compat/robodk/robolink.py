"""``robolink`` / ``robodk.robolink`` for programs olp runs: RoboDK's ``Robolink`` and ``Item``
over olp's station, recording an olp program instead of driving RoboDK.

What a call means is RoboDK's (its API reference, ``robodk/robolink.py``, states names, argument
orders, units and returns; ``tests/compat/test_robolink.py`` pins each one we answer):

* **The item tree** is the station: the station itself, a ``<robot> Base`` frame holding the
  robot, the robot's tools, the station's frames (nested as their ``parent`` says), parts and
  fixtures (objects) and named ``targets:``, plus whatever the script adds (``AddTarget``,
  ``AddFrame``, ``AddTool``, ``AddProgram``). ``Item(name, type)`` finds one (an invalid item
  when nothing matches, ``Valid()`` False); ``Pose()`` of a frame, object or target is relative
  to its parent, ``PoseAbs()`` to the station.
* **Units**: mm and degrees, poses as ``robomath.Mat``; joints come back as a column ``Mat``
  (``.list()``). A robot's ``Pose()`` is the active TCP in the active frame; ``PoseFrame()``
  and ``setPoseFrame(pose)`` are relative to the robot base, ``PoseTool()`` to the flange.
  Tools are given in the robot *vendor's* flange frame (olp's convention, see
  :mod:`olp.vendors`; KUKA's flange X axis points out of the flange).
* **Run modes**: in ``RUNMODE_SIMULATE`` (the default) ``MoveJ``/``MoveL``/``MoveC`` on the robot
  run olp's resolve pass from the simulated joints (and its collision check when
  ``setCollisionActive(COLLISION_ON)``) and raise :class:`TargetReachError` for a move that
  cannot run, recording nothing and noting a warning at the line (a script that catches it
  skips the target). In ``RUNMODE_MAKE_ROBOTPROG`` (and the other program modes) moves are
  recorded unchecked and the build reports what it finds.
* **Programs**: moves on the robot record the build's program; when the script fills program
  items (``AddProgram``), olp builds that program instead (the robot's moves were its
  simulation; noted), and with several, the one ``MakeProgram()`` was called on. ``Update()``
  runs olp's passes and returns RoboDK's ``(valid_instructions, time_s, distance_mm,
  valid_ratio, message)``.
* What olp cannot do offline (rendering, pop-ups, a live robot, running a program) is a no-op
  with a note in the build output, or, where going on would be wrong, a located error naming
  the call.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from olp import dsl, ir
from olp.compat import note
from olp.compat.robodk import robomath
from olp.compat.robodk.robomath import *  # noqa: F403 (the old robolink exported them too)
from olp.compat.robodk.robomath import Mat
from olp.geometry import inv

FloatArray = NDArray[np.float64]

# Tree item types (RoboDK's values)
ITEM_TYPE_ANY = -1
ITEM_TYPE_STATION = 1
ITEM_TYPE_ROBOT = 2
ITEM_TYPE_FRAME = 3
ITEM_TYPE_TOOL = 4
ITEM_TYPE_OBJECT = 5
ITEM_TYPE_TARGET = 6
ITEM_TYPE_CURVE = 7
ITEM_TYPE_PROGRAM = 8
ITEM_TYPE_INSTRUCTION = 9
ITEM_TYPE_PROGRAM_PYTHON = 10
ITEM_TYPE_MACHINING = 11
ITEM_TYPE_BALLBARVALIDATION = 12
ITEM_TYPE_CALIBPROJECT = 13
ITEM_TYPE_VALID_ISO9283 = 14
ITEM_TYPE_FOLDER = 17
ITEM_TYPE_ROBOT_ARM = 18
ITEM_TYPE_CAMERA = 19
ITEM_TYPE_GENERIC = 20
ITEM_TYPE_ROBOT_AXES = 21
ITEM_TYPE_NOTES = 22

# Instruction types
INS_TYPE_INVALID = -1
INS_TYPE_MOVE = 0
INS_TYPE_MOVEC = 1
INS_TYPE_CHANGESPEED = 2
INS_TYPE_CHANGEFRAME = 3
INS_TYPE_CHANGETOOL = 4
INS_TYPE_CHANGEROBOT = 5
INS_TYPE_PAUSE = 6
INS_TYPE_EVENT = 7
INS_TYPE_CODE = 8
INS_TYPE_PRINT = 9
INS_TYPE_ROUNDING = 10

# Move types
MOVE_TYPE_INVALID = -1
MOVE_TYPE_JOINT = 1
MOVE_TYPE_LINEAR = 2
MOVE_TYPE_CIRCULAR = 3
MOVE_TYPE_LINEARSEARCH = 5

# Script execution types
RUNMODE_SIMULATE = 1
RUNMODE_QUICKVALIDATE = 2
RUNMODE_MAKE_ROBOTPROG = 3
RUNMODE_MAKE_ROBOTPROG_AND_UPLOAD = 4
RUNMODE_MAKE_ROBOTPROG_AND_START = 5
RUNMODE_RUN_ROBOT = 6

# Program execution type
PROGRAM_RUN_ON_SIMULATOR = 1
PROGRAM_RUN_ON_ROBOT = 2

# Robot connection status
ROBOTCOM_PROBLEMS = -3
ROBOTCOM_DISCONNECTED = -2
ROBOTCOM_NOT_CONNECTED = -1
ROBOTCOM_READY = 0
ROBOTCOM_WORKING = 1
ROBOTCOM_WAITING = 2
ROBOTCOM_UNKNOWN = -1000

# Instruction program call type
INSTRUCTION_CALL_PROGRAM = 0
INSTRUCTION_INSERT_CODE = 1
INSTRUCTION_START_THREAD = 2
INSTRUCTION_COMMENT = 3
INSTRUCTION_SHOW_MESSAGE = 4

# Collision checking state
COLLISION_OFF = 0
COLLISION_ON = 1

# Station parameters request
PATH_OPENSTATION = "PATH_OPENSTATION"
FILE_OPENSTATION = "FILE_OPENSTATION"

# Euler types
JOINT_FORMAT = -1
EULER_RX_RYp_RZpp = 0
EULER_RZ_RYp_RXpp = 1
EULER_RZ_RYp_RZpp = 2
EULER_RZ_RXp_RZpp = 3
EULER_RX_RY_RZ = 4
EULER_RZ_RY_RX = 5
EULER_QUEATERNION = 6

# Window states (no window in olp: accepted and noted)
WINDOWSTATE_HIDDEN = -1
WINDOWSTATE_SHOW = 0
WINDOWSTATE_MINIMIZED = 1
WINDOWSTATE_NORMAL = 2
WINDOWSTATE_MAXIMIZED = 3
WINDOWSTATE_FULLSCREEN = 4

# Path error bits
ERROR_KINEMATIC = 0b001
ERROR_PATH_LIMIT = 0b010
ERROR_PATH_SINGULARITY = 0b100
ERROR_PATH_NEARSINGULARITY = 0b1000
ERROR_COLLISION = 0b100000

TYPE_NAMES = {
    ITEM_TYPE_STATION: "station",
    ITEM_TYPE_ROBOT: "robot",
    ITEM_TYPE_FRAME: "frame",
    ITEM_TYPE_TOOL: "tool",
    ITEM_TYPE_OBJECT: "object",
    ITEM_TYPE_TARGET: "target",
    ITEM_TYPE_PROGRAM: "program",
}
"""The item types olp's tree holds, in words."""

PICK_PARAMS = {
    ITEM_TYPE_ROBOT: "PICK_ROBOT",
    ITEM_TYPE_FRAME: "PICK_FRAME",
    ITEM_TYPE_TOOL: "PICK_TOOL",
    ITEM_TYPE_OBJECT: "PICK_OBJECT",
    ITEM_TYPE_TARGET: "PICK_TARGET",
    ITEM_TYPE_PROGRAM: "PICK_PROGRAM",
}
"""The ``--set`` parameter that answers ``ItemUserPick`` for each item type (``PICK_ITEM``
for any type)."""

_PROGRAM_MODES = (
    RUNMODE_MAKE_ROBOTPROG,
    RUNMODE_MAKE_ROBOTPROG_AND_UPLOAD,
    RUNMODE_MAKE_ROBOTPROG_AND_START,
)
_NOT_CHECKED = frozenset({"unsupported"})
"""Diagnostic kinds of a simulated move that are not the target's fault: recorded, never a
TargetReachError (e.g. a circular move before olp resolves arcs; the build reports it)."""


class TargetReachError(Exception):
    """Unable to reach the desired target or destination (RoboDK's exception)."""


class StoppedError(Exception):
    """The user stopped the operation (never raised by olp)."""


class InputError(Exception):
    """Invalid input parameters (RoboDK's exception)."""


class LicenseError(Exception):
    """Invalid RoboDK license (never raised by olp)."""


# ------------------------------------------------------------------------------------------------
# The tree


class _Node:
    """One item of the tree. ``local``: pose (4, 4) in the parent, metres (frames, objects,
    targets); targets also keep ``joints`` (rad) and whether they are joint targets."""

    def __init__(self, kind: int, name: str, parent: _Node | None = None) -> None:
        self.kind = kind
        self.name = name
        self.parent = parent
        self.children: list[_Node] = []
        self.alive = True
        self.local: FloatArray | None = np.eye(4)
        self.joints: FloatArray | None = None
        self.is_joint = False
        self.tool: ir.Tool | None = None
        self.station_frame: ir.Frame | None = None
        self.number: int | None = None
        self.recorder: dsl.Robot | None = None
        self.record: Any = None
        if parent is not None:
            parent.children.append(self)

    def world(self) -> FloatArray:
        """Pose (4, 4) in the station (world), metres."""
        pose = np.eye(4) if self.local is None else self.local
        return pose if self.parent is None else self.parent.world() @ pose


class _Tree:
    """The item tree of one run, and RoboDK's run settings."""

    def __init__(self, session: Any) -> None:
        station = session.station
        if station is None:
            raise dsl.DslError("Robolink() needs a station (olp build STATION.yaml script.py)")
        self.session = session
        self.station = station
        self.run_mode = RUNMODE_SIMULATE
        self.collisions = COLLISION_OFF
        self.root = _Node(ITEM_TYPE_STATION, station.name)
        base = _Node(ITEM_TYPE_FRAME, f"{station.robot.name} Base", self.root)
        base.local = np.array(station.robot.base, dtype=np.float64)
        self.robot = _Node(ITEM_TYPE_ROBOT, station.robot.name, base)
        self.robot.recorder = session.robot
        for tool in station.tools.values():
            node = _Node(ITEM_TYPE_TOOL, tool.name, self.robot)
            node.tool = tool
        frames = self._frames(station)
        for obj in station.objects:
            parent = frames.get(obj.frame, self.root)
            node = _Node(ITEM_TYPE_OBJECT, obj.name, parent)
            node.local = inv(parent.world()) @ obj.pose
        for target in station.targets.values():
            node = _Node(ITEM_TYPE_TARGET, target.name, frames.get(target.frame, self.root))
            node.local = None if target.pose is None else np.array(target.pose)
            node.joints = None if target.joints is None else np.array(target.joints)
            node.is_joint = target.joints is not None

    def _frames(self, station: Any) -> dict[str, _Node]:
        nodes: dict[str, _Node] = {}

        def make(name: str) -> _Node:
            if name not in nodes:
                parent_name = station.frame_parents.get(name, "world")
                parent = self.root if parent_name == "world" else make(parent_name)
                node = _Node(ITEM_TYPE_FRAME, name, parent)
                frame = station.frames[name]
                node.station_frame = frame
                node.number = frame.number
                node.local = inv(parent.world()) @ frame.pose
                nodes[name] = node
            return nodes[name]

        for name in station.frames:
            make(name)
        return nodes

    @property
    def recorder(self) -> dsl.Robot:
        assert self.robot.recorder is not None
        return self.robot.recorder

    def nodes(self) -> list[_Node]:
        """Every live item, depth first from the station."""
        out: list[_Node] = []
        stack = [self.root]
        while stack:
            node = stack.pop()
            if node.alive:
                out.append(node)
                stack.extend(reversed(node.children))
        return out

    def frame_ir(self, node: _Node) -> ir.Frame:
        """The IR frame of a frame item (the station's own while it has not moved)."""
        if node is self.root:
            return ir.WORLD
        world = node.world()
        known = node.station_frame
        if known is not None and known.pose is not None and np.allclose(known.pose, world):
            return known
        return ir.Frame(name=node.name, pose=world, number=node.number)

    def target_pose(self, node: _Node) -> FloatArray:
        """A target's pose in its parent (m): its own, else from its joints with the robot's
        active tool."""
        if node.local is not None:
            return node.local
        joints = self.target_joints(node)
        flange = self.station.robot.flange_poses(joints)
        pose: FloatArray = inv(node.parent.world() if node.parent else np.eye(4)) @ (
            flange @ self.recorder._tool_pose()
        )
        return pose

    def target_joints(self, node: _Node) -> FloatArray:
        """A target's joints (rad): its own, else the IK solution nearest the robot's joints
        for its pose with the robot's active tool; a DslError when there is none."""
        if node.joints is not None:
            return node.joints
        assert node.local is not None
        frame = node.parent.world() if node.parent else np.eye(4)
        flange = frame @ node.local @ inv(self.recorder._tool_pose())
        near = np.radians(self.recorder.Joints())
        found = dsl._nearest_solution(self.station, flange, near)
        if found is None:
            raise dsl.DslError(f"target {dsl.quote(node.name)} cannot be reached: it has no joints")
        return found

    def target_ir(self, node: _Node) -> tuple[ir.Target, ir.Frame | None]:
        """The IR target of a target item and the frame its pose is in."""
        if node.is_joint:
            return ir.JointTarget(joints=self.target_joints(node), name=node.name), None
        if node.local is None:
            raise dsl.DslError(f"target {dsl.quote(node.name)} has no pose: call setPose first")
        frame = self.frame_ir(node.parent) if node.parent else ir.WORLD
        return ir.CartesianTarget(pose=node.local, name=node.name), frame


def _tree() -> _Tree:
    session = dsl.session()
    if session.compat is None:
        session.compat = _Tree(session)
    tree: _Tree = session.compat
    return tree


def _si(pose: Any, what: str) -> FloatArray:
    """A rigid pose given in mm (a Mat, olp.dsl.Mat or 4 x 4 numbers) in metres."""
    m = np.array(np.asarray(pose, dtype=np.float64), dtype=np.float64)
    if m.shape != (4, 4) or not Mat(m).isHomogeneous():
        raise dsl.DslError(f"{what}: expected a pose (a 4 x 4 rigid Mat), got {dsl.brief(pose)}")
    m[:3, 3] /= 1000.0
    return m


def _mm(pose_si: FloatArray) -> Mat:
    m = np.array(pose_si, dtype=np.float64)
    m[:3, 3] *= 1000.0
    return Mat(m)


def _column(values_rad: FloatArray) -> Mat:
    """Joints (rad) as RoboDK returns them: a column Mat in degrees."""
    return Mat(np.degrees(np.asarray(values_rad, dtype=np.float64)).tolist())


def _degrees(values: Any, what: str) -> list[float]:
    """Joints in degrees from a list, a column/row Mat or an array."""
    if isinstance(values, Mat):
        values = values.list()
    array = np.asarray(values, dtype=np.float64).reshape(-1)
    return dsl._finite(array.tolist(), what)


# ------------------------------------------------------------------------------------------------
# Items


class Item:
    """An item of the station tree (RoboDK's ``Item``): a robot, tool, frame, object, target or
    program. Methods act by the item's type, as RoboDK's do."""

    def __init__(self, link: Robolink | None = None, node: _Node | None = None) -> None:
        self.link = link
        self._node = node

    # ---- identity
    def __eq__(self, other: object) -> bool:
        return isinstance(other, Item) and other._node is self._node

    def __hash__(self) -> int:
        return id(self._node)

    def __repr__(self) -> str:
        if self._node is None:
            return "RoboDK item (invalid)"
        kind = TYPE_NAMES.get(self._node.kind, "item")
        return f"RoboDK item {self._node.name!r} of type {kind}"

    def _n(self, what: str, *kinds: int) -> _Node:
        node = self._node
        if node is None or not node.alive:
            raise dsl.DslError(
                f"{what}: the item is not valid (RDK.Item found nothing, or it was deleted)"
            )
        if kinds and node.kind not in kinds:
            wanted = " or ".join(TYPE_NAMES.get(k, str(k)) for k in kinds)
            raise dsl.DslError(
                f"{what} works on a {wanted}; {dsl.quote(node.name)} is a "
                f"{TYPE_NAMES.get(node.kind, 'item')}"
            )
        return node

    def _wrap(self, node: _Node | None) -> Item:
        return Item(self.link, node)

    def Valid(self, check_deleted: bool = False) -> bool:
        """True for an item that exists."""
        return self._node is not None and self._node.alive

    def Type(self) -> int:
        """The item type (``ITEM_TYPE_*``)."""
        return self._n("Type").kind

    def Name(self) -> str:
        return self._n("Name").name

    def setName(self, name: str) -> Item:
        node = self._n("setName")
        fixed = node.kind == ITEM_TYPE_ROBOT or node.station_frame is not None
        if (fixed or node.tool is not None) and name != node.name:
            raise dsl.DslError(
                f"setName: {dsl.quote(node.name)} is named by the station or a tool; keep its name"
            )
        node.name = str(name)
        if node.record is not None:
            node.record.name = node.name
        return self

    def Parent(self) -> Item:
        """The parent item (a target's frame, a tool's robot, the robot's base frame)."""
        return self._wrap(self._n("Parent").parent)

    def Childs(self) -> list[Item]:
        """The items directly under this one, in tree order."""
        return [self._wrap(c) for c in self._n("Childs").children if c.alive]

    def getLink(self, type_linked: int = ITEM_TYPE_ROBOT) -> Item:
        """The robot a program, target or tool belongs to (olp stations have one robot); of a
        robot or program, ``ITEM_TYPE_FRAME`` / ``ITEM_TYPE_TOOL``: its active frame or tool
        (the robot base frame while the active frame is where the base is)."""
        node = self._n("getLink")
        tree = _tree()
        if type_linked == ITEM_TYPE_ROBOT:
            return self._wrap(tree.robot)
        if node.recorder is None or type_linked not in (ITEM_TYPE_FRAME, ITEM_TYPE_TOOL):
            return self._wrap(None)
        if type_linked == ITEM_TYPE_TOOL:
            name = node.recorder._tool.name
            tools = [n for n in tree.robot.children if n.alive and n.name == name]
            return self._wrap(tools[0] if tools else None)
        return self._wrap(_frame_node(tree, node.recorder._frame))

    def setRobot(self, robot: Item | None = None) -> Item:
        """Programs and targets belong to the station's only robot: accepted as it is."""
        self._n("setRobot")
        return self

    def Delete(self) -> None:
        """Remove a target, frame or program the script made (and what hangs under it)."""
        node = self._n("Delete", ITEM_TYPE_TARGET, ITEM_TYPE_FRAME, ITEM_TYPE_PROGRAM)
        if node.station_frame is not None:
            raise dsl.DslError(f"Delete: frame {dsl.quote(node.name)} belongs to the station")
        node.alive = False
        if node.record is not None:
            node.record.instructions.clear()
        if node.parent is not None:
            node.parent.children.remove(node)

    def Visible(self) -> int:
        self._n("Visible")
        return 1

    def setVisible(self, visible: Any = True, visible_frame: Any = None) -> Item:
        self._n("setVisible")
        note("setVisible", "olp draws nothing; no-op")
        return self

    def setColor(self, tocolor: Any, *args: Any, **kwargs: Any) -> None:
        self._n("setColor")
        note("setColor", "olp draws nothing; no-op")

    Recolor = setColor

    def setParam(self, param: Any, value: Any = "", *args: Any, **kwargs: Any) -> str:
        node = self._n("setParam")
        if node.kind == ITEM_TYPE_PROGRAM and isinstance(param, int):
            raise dsl.DslError(
                "setParam(ins_id): instruction data as a dict is not supported by olp; read and "
                "edit moves with Instruction/setInstruction, delete with InstructionDelete"
            )
        note("setParam", f"RoboDK item parameter {str(param)[:40]!r} has no meaning in olp; no-op")
        return ""

    # ---- poses
    def Pose(self) -> Mat:
        """A frame's, object's or target's pose in its parent; a tool's TCP in the flange; a
        robot's active TCP in its active frame (mm)."""
        node = self._n("Pose")
        if node.kind == ITEM_TYPE_ROBOT:
            return Mat(np.asarray(_tree().recorder.Pose()))
        if node.kind == ITEM_TYPE_TOOL:
            return self.PoseTool()
        if node.kind == ITEM_TYPE_TARGET:
            return _mm(_tree().target_pose(node))
        if node.kind in (ITEM_TYPE_FRAME, ITEM_TYPE_OBJECT) and node.local is not None:
            return _mm(node.local)
        raise dsl.DslError(f"Pose: a {TYPE_NAMES.get(node.kind, 'item')} has no pose")

    def setPose(self, pose: Any) -> Item:
        """Place a frame, object or target in its parent (mm); a robot: a joint move there
        (RoboDK moves the robot); a tool: its TCP."""
        node = self._n("setPose")
        if node.kind == ITEM_TYPE_ROBOT:
            self.MoveJ(pose)
            return self
        if node.kind == ITEM_TYPE_TOOL:
            return self.setPoseTool(pose)
        if node.station_frame is not None:
            note(
                "setPose",
                f"frame {node.name!r} moves for this script only; the station keeps its pose",
            )
        if node.kind not in (ITEM_TYPE_FRAME, ITEM_TYPE_OBJECT, ITEM_TYPE_TARGET):
            raise dsl.DslError(f"setPose: a {TYPE_NAMES.get(node.kind, 'item')} has no pose")
        node.local = _si(pose, "setPose")
        if node.kind == ITEM_TYPE_TARGET and not node.is_joint:
            node.joints = None
        return self

    def PoseAbs(self) -> Mat:
        """The pose in the station (world), mm."""
        node = self._n("PoseAbs")
        if node.kind == ITEM_TYPE_TARGET:
            parent = node.parent.world() if node.parent else np.eye(4)
            return _mm(parent @ _tree().target_pose(node))
        if node.kind == ITEM_TYPE_ROBOT:
            tree = _tree()
            joints = np.radians(tree.recorder.Joints())
            return _mm(tree.station.robot.flange_poses(joints) @ tree.recorder._tool_pose())
        return _mm(node.world())

    def setPoseAbs(self, pose: Any) -> Item:
        node = self._n("setPoseAbs", ITEM_TYPE_FRAME, ITEM_TYPE_OBJECT, ITEM_TYPE_TARGET)
        parent = node.parent.world() if node.parent else np.eye(4)
        return self.setPose(_mm(inv(parent) @ _si(pose, "setPoseAbs")))

    # ---- targets
    def isJointTarget(self) -> int:
        """1 for a joint target, 0 for a Cartesian one."""
        return 1 if self._n("isJointTarget", ITEM_TYPE_TARGET).is_joint else 0

    def setAsJointTarget(self) -> Item:
        node = self._n("setAsJointTarget", ITEM_TYPE_TARGET)
        if node.joints is None:
            node.joints = _tree().target_joints(node)
        node.is_joint = True
        return self

    def setAsCartesianTarget(self) -> Item:
        node = self._n("setAsCartesianTarget", ITEM_TYPE_TARGET)
        if node.local is None:
            node.local = _tree().target_pose(node)
        node.is_joint = False
        return self

    # ---- joints
    def Joints(self) -> Mat:
        """A robot's simulated joints, or a target's joints: a column Mat in degrees."""
        node = self._n("Joints", ITEM_TYPE_ROBOT, ITEM_TYPE_TARGET)
        if node.kind == ITEM_TYPE_TARGET:
            return _column(_tree().target_joints(node))
        return Mat(_tree().recorder.Joints())

    def setJoints(self, joints: Any) -> Item:
        """A robot: place the simulated robot there (no program instruction, as in RoboDK);
        a target: its joints (degrees)."""
        node = self._n("setJoints", ITEM_TYPE_ROBOT, ITEM_TYPE_TARGET)
        tree = _tree()
        values = np.radians(_degrees(joints, "setJoints"))
        tree.recorder._joints(np.degrees(values).tolist(), "setJoints", None)
        if node.kind == ITEM_TYPE_ROBOT:
            tree.recorder.place(values)
        else:
            node.joints = values
            if node.is_joint:
                node.local = None
        return self

    def JointsHome(self) -> Mat:
        self._n("JointsHome", ITEM_TYPE_ROBOT)
        return Mat(_tree().recorder.JointsHome())

    def setJointsHome(self, joints: Any) -> Item:
        self._n("setJointsHome", ITEM_TYPE_ROBOT)
        note("setJointsHome", "the station's home_deg stays; no-op")
        return self

    def JointLimits(self) -> tuple[Mat, Mat, int]:
        """``(lower, upper, joint_type)``: columns in degrees, 0 for rotary joints."""
        self._n("JointLimits", ITEM_TYPE_ROBOT)
        limits = _tree().station.robot.limits
        return _column(limits.lower), _column(limits.upper), 0

    def DOF(self) -> int:
        self._n("DOF", ITEM_TYPE_ROBOT)
        return int(_tree().station.robot.dof)

    def SolveFK(self, joints: Any, tool: Any = None, reference: Any = None) -> Mat:
        """The flange pose in the robot base frame (mm) for ``joints`` (degrees); with
        ``tool`` the TCP, with ``reference`` relative to that frame (RoboDK's order)."""
        self._n("SolveFK", ITEM_TYPE_ROBOT)
        robot = _tree().station.robot
        q = np.radians(_degrees(joints, "SolveFK"))
        _tree().recorder._joints(np.degrees(q).tolist(), "SolveFK", None)
        pose = _mm(inv(robot.base) @ robot.flange_poses(q))
        if tool is not None:
            pose = pose * Mat(np.asarray(tool))
        if reference is not None:
            pose = Mat(np.asarray(reference)).invH() * pose
        return pose

    def SolveIK(
        self, pose: Any, joints_approx: Any = None, tool: Any = None, reference: Any = None
    ) -> Mat:
        """Joints (column Mat, degrees) for a flange ``pose`` in the robot base frame (with
        ``tool``/``reference``: the TCP in that frame), nearest ``joints_approx`` (default: the
        current joints); an empty Mat when unreachable."""
        self._n("SolveIK", ITEM_TYPE_ROBOT)
        rec = _tree().recorder
        near = None if joints_approx is None else _degrees(joints_approx, "SolveIK")
        tool_mat = None if tool is None else dsl.Mat(np.asarray(tool))
        ref_mat = None if reference is None else dsl.Mat(np.asarray(reference))
        found = rec.SolveIK(dsl.Mat(np.asarray(pose)), near, tool_mat, ref_mat)
        return Mat(found) if found else Mat(0, 0)

    def SolveIK_All(self, pose: Any, tool: Any = None, reference: Any = None) -> Mat:
        """Every solution inside the limits: a dof x M Mat (one column per solution, degrees)."""
        self._n("SolveIK_All", ITEM_TYPE_ROBOT)
        from olp.kinematics.opw import turn_variants

        station = _tree().station
        flange = station.robot.base @ _reference(reference) @ _si(pose, "SolveIK_All")
        flange = flange @ inv(_reference(tool))
        sols = station.robot.solve(flange[None])[0]
        limits = station.robot.limits
        variants = turn_variants(sols, limits.lower, limits.upper).reshape(-1, sols.shape[-1])
        variants = variants[np.all(np.isfinite(variants), axis=-1)]
        return Mat(np.degrees(variants).T) if len(variants) else Mat(0, 0)

    def JointPoses(self, joints: Any = None) -> list[Mat]:
        """The poses of the robot's links (mm) relative to its base for ``joints`` (degrees;
        default: the simulated joints): index 0 is the base, then one per joint."""
        self._n("JointPoses", ITEM_TYPE_ROBOT)
        tree = _tree()
        degrees = tree.recorder.Joints() if joints is None else _degrees(joints, "JointPoses")
        robot = tree.station.robot
        poses = robot.link_poses(np.radians(degrees))
        return [_mm(inv(robot.base) @ pose) for pose in poses.values()]

    def JointsConfig(self, joints: Any) -> Mat:
        """RoboDK's configuration flags ``[REAR, LOWERARM, FLIP, 0]`` (1/0) for joints (deg):
        the shoulder behind axis 1, the elbow down, axis 5 negative (olp's OPW flags)."""
        self._n("JointsConfig", ITEM_TYPE_ROBOT)
        from olp.kinematics.configuration import branch_flags

        q = np.radians(_degrees(joints, "JointsConfig"))
        try:
            flags = branch_flags(_tree().station.robot, q)
        except (TypeError, AttributeError) as exc:
            raise dsl.DslError(f"JointsConfig: only OPW arms have these flags ({exc})") from None
        values = [bool(flags.back), bool(flags.down), bool(flags.flip), False]
        return Mat([float(v) for v in values])

    # ---- tools and frames
    def PoseTool(self) -> Mat:
        """The TCP in the flange frame (mm): a robot's or program's active tool, or a tool's."""
        node = self._n("PoseTool", ITEM_TYPE_ROBOT, ITEM_TYPE_TOOL, ITEM_TYPE_PROGRAM)
        if node.kind == ITEM_TYPE_TOOL:
            assert node.tool is not None and node.tool.pose is not None
            return _mm(node.tool.pose)
        return _mm(_recorder(node)._tool_pose())

    Htool = PoseTool

    def PoseFrame(self) -> Mat:
        """The active frame relative to the robot base (mm)."""
        node = self._n("PoseFrame", ITEM_TYPE_ROBOT, ITEM_TYPE_PROGRAM)
        base = _tree().station.robot.base
        return _mm(inv(base) @ _recorder(node)._frame_pose())

    def setPoseTool(self, tool: Any) -> Item:
        """The active tool: a tool item, a tool number (the station's, or one AddTool made)
        or a TCP pose in the flange frame (mm; olp gives it the next free tool number). On a
        tool item: its TCP."""
        node = self._n("setPoseTool", ITEM_TYPE_ROBOT, ITEM_TYPE_PROGRAM, ITEM_TYPE_TOOL)
        tree = _tree()
        if node.kind == ITEM_TYPE_TOOL:
            assert node.tool is not None
            node.tool = ir.Tool(
                name=node.tool.name, pose=_si(tool, "setPoseTool"), number=node.tool.number
            )
            return self
        rec = _recorder(node)
        if isinstance(tool, Item):
            tool_node = tool._n("setPoseTool", ITEM_TYPE_TOOL)
            assert tool_node.tool is not None
            rec._tool = tool_node.tool
        elif isinstance(tool, int | np.integer) and not isinstance(tool, bool):
            rec._tool = _tool_by_number(tree, int(tool))
        else:
            rec.setPoseTool(dsl.Mat(np.asarray(tool, dtype=np.float64)))
        return self

    setTool = setPoseTool
    setHtool = setPoseTool

    def setPoseFrame(self, frame: Any) -> Item:
        """The active frame: a frame item (or the station) or a pose relative to the robot
        base (mm)."""
        node = self._n("setPoseFrame", ITEM_TYPE_ROBOT, ITEM_TYPE_PROGRAM)
        tree = _tree()
        rec = _recorder(node)
        if isinstance(frame, Item):
            frame_node = frame._n("setPoseFrame", ITEM_TYPE_FRAME, ITEM_TYPE_STATION)
            rec._frame = tree.frame_ir(frame_node)
        else:
            world = tree.station.robot.base @ _si(frame, "setPoseFrame")
            rec.setPoseFrame(dsl.Mat(_mm(world).rows))
        return self

    setFrame = setPoseFrame

    def AddTool(self, tool_pose: Any, tool_name: str = "New TCP") -> Item:
        """A new tool of the robot (TCP in the flange frame, mm), numbered after the station's
        tools; it becomes the active tool, as in RoboDK."""
        self._n("AddTool", ITEM_TYPE_ROBOT)
        tree = _tree()
        made = tree.recorder.AddTool(dsl.Mat(np.asarray(tool_pose, dtype=np.float64)), tool_name)
        node = _Node(ITEM_TYPE_TOOL, made.tool.name, tree.robot)
        node.tool = made.tool
        return self._wrap(node)

    # ---- settings, I/O and calls (robot or program)
    def setSpeed(
        self,
        speed_linear: float,
        speed_joints: float = -1,
        accel_linear: float = -1,
        accel_joints: float = -1,
    ) -> Item:
        """mm/s, deg/s, mm/s², deg/s²; -1 keeps a value (see :meth:`olp.dsl.Robot.setSpeed`)."""
        node = self._n("setSpeed", ITEM_TYPE_ROBOT, ITEM_TYPE_PROGRAM)
        _recorder(node).setSpeed(speed_linear, speed_joints, accel_linear, accel_joints)
        return self

    def setSpeedJoints(self, speed_joints: float) -> Item:
        return self.setSpeed(-1, speed_joints)

    def setAcceleration(self, accel_linear: float) -> Item:
        return self.setSpeed(-1, -1, accel_linear)

    def setAccelerationJoints(self, accel_joints: float) -> Item:
        return self.setSpeed(-1, -1, -1, accel_joints)

    def setRounding(self, rounding_mm: float) -> Item:
        """Corner rounding in mm; -1 is an exact stop."""
        _recorder(self._n("setRounding", ITEM_TYPE_ROBOT, ITEM_TYPE_PROGRAM)).setRounding(
            rounding_mm
        )
        return self

    setZoneData = setRounding

    def setDO(self, io_var: Any, io_value: Any) -> None:
        _recorder(self._n("setDO", ITEM_TYPE_ROBOT, ITEM_TYPE_PROGRAM)).setDO(io_var, io_value)

    def waitDI(self, io_var: Any, io_value: Any, timeout_ms: float = -1) -> None:
        node = self._n("waitDI", ITEM_TYPE_ROBOT, ITEM_TYPE_PROGRAM)
        _recorder(node).waitDI(io_var, io_value, timeout_ms)

    def Pause(self, time_ms: float = -1) -> None:
        _recorder(self._n("Pause", ITEM_TYPE_ROBOT, ITEM_TYPE_PROGRAM)).Pause(time_ms)

    def RunInstruction(self, code: str, run_type: int = INSTRUCTION_CALL_PROGRAM) -> int:
        """A program call or a comment (``INSTRUCTION_COMMENT``); 0 as RoboDK on success."""
        node = self._n("RunInstruction", ITEM_TYPE_ROBOT, ITEM_TYPE_PROGRAM)
        _recorder(node).RunInstruction(code, run_type)
        return 0

    RunCodeCustom = RunInstruction

    def ProgramStart(self, programname: str, folder: str = "", postprocessor: str = "") -> int:
        self._n("ProgramStart", ITEM_TYPE_ROBOT)
        _program_start(programname, folder, postprocessor)
        return 0

    # ---- motions
    def MoveJ(self, target: Any, blocking: bool = True) -> None:
        """Joint move to a target item, a pose (mm, active TCP in the active frame) or joints
        (degrees). On the robot in simulate mode: TargetReachError when it cannot run."""
        self._move(ir.JointMove, target, "MoveJ")

    def MoveL(self, target: Any, blocking: bool = True) -> None:
        """Linear move (targets as :meth:`MoveJ`)."""
        self._move(ir.LinearMove, target, "MoveL")

    def MoveC(self, target1: Any, target2: Any, blocking: bool = True) -> None:
        """Circular move through ``target1`` to ``target2`` (the DSL's MoveC; on the robot in
        simulate mode, TargetReachError when olp's resolve pass finds it cannot run)."""
        node = self._n("MoveC", ITEM_TYPE_ROBOT, ITEM_TYPE_PROGRAM)
        rec = _recorder(node)
        via, via_frame = _ir_target(rec, target1, "MoveC")
        end, end_frame = _ir_target(rec, target2, "MoveC")
        if via_frame != end_frame:
            raise dsl.DslError("MoveC: both points must be in the same frame")
        move = rec.circular(via, end, end_frame)
        if node.kind == ITEM_TYPE_PROGRAM:
            rec.record(move)
        else:
            _simulate(move, "MoveC")

    def _move(self, kind: type[ir.JointMove] | type[ir.LinearMove], target: Any, what: str) -> None:
        node = self._n(what, ITEM_TYPE_ROBOT, ITEM_TYPE_PROGRAM)
        rec = _recorder(node)
        ir_target, frame = _ir_target(rec, target, what)
        move = rec.motion(kind, ir_target, frame)
        if node.kind == ITEM_TYPE_PROGRAM:
            rec.record(move)
        else:
            _simulate(move, what)

    def MoveJ_Test(self, j1: Any, j2: Any, minstep_deg: float = -1) -> int:
        """0 when a joint move from ``j1`` to ``j2`` (degrees) can run, else the number of
        collisions found (collision checking on), or -1 for any other problem. On success the
        simulated robot is placed at ``j2``, as in RoboDK."""
        self._n("MoveJ_Test", ITEM_TYPE_ROBOT)
        rec = _tree().recorder
        start = rec._joints(_degrees(j1, "MoveJ_Test"), "MoveJ_Test", None)
        end = rec._joints(_degrees(j2, "MoveJ_Test"), "MoveJ_Test", None)
        return _test(rec, start.joints, rec.motion(ir.JointMove, end))

    def MoveL_Test(self, j1: Any, pose: Any, minstep_mm: float = -1) -> int:
        """0 when a linear move from joints ``j1`` (degrees) to ``pose`` (the active TCP in
        the active frame, mm) can run; -2 when the pose cannot be reached at all, -1 when it
        can but not on a line, the number of collisions when one is found (collision
        checking on). On success the simulated robot is placed at the end."""
        self._n("MoveL_Test", ITEM_TYPE_ROBOT)
        rec = _tree().recorder
        start = rec._joints(_degrees(j1, "MoveL_Test"), "MoveL_Test", None)
        target = rec._pose(dsl.Mat(np.asarray(pose, dtype=np.float64)), "MoveL_Test", None)
        if not rec._reach(target):
            return -2
        return _test(rec, start.joints, rec.motion(ir.LinearMove, target))

    # ---- program items
    def _program(self, what: str) -> _Node:
        return self._n(what, ITEM_TYPE_PROGRAM)

    def InstructionCount(self) -> int:
        """The number of instructions of a program."""
        return len(self._program("InstructionCount").record.instructions)

    def _index(self, what: str, ins_id: int) -> int:
        count = self.InstructionCount()
        index = count - 1 if ins_id == -1 else ins_id
        if not isinstance(index, int) or not 0 <= index < count:
            raise dsl.DslError(f"{what}: no instruction {ins_id} (the program has {count})")
        return index

    def Instruction(self, ins_id: int = -1) -> tuple[str, int, Any, Any, Any, Any]:
        """``(name, instype, movetype, isjointtarget, target, joints)`` of instruction
        ``ins_id`` (RoboDK's tuple; the last four are None unless it is a move)."""
        node = self._program("Instruction")
        instruction = node.record.instructions[self._index("Instruction", ins_id)]
        return _describe_instruction(instruction)

    def setInstruction(
        self,
        ins_id: int,
        name: str,
        instype: int,
        movetype: int,
        isjointtarget: int,
        target: Any,
        joints: Any,
    ) -> None:
        """Replace move instruction ``ins_id``: ``movetype`` (joint/linear) and its target
        (``target`` pose in mm, or ``joints`` in degrees when ``isjointtarget``)."""
        node = self._program("setInstruction")
        index = self._index("setInstruction", ins_id)
        old = node.record.instructions[index]
        if instype != INS_TYPE_MOVE or not isinstance(old, ir.JointMove | ir.LinearMove):
            raise dsl.DslError("setInstruction: olp edits move instructions only")
        kind = {MOVE_TYPE_JOINT: ir.JointMove, MOVE_TYPE_LINEAR: ir.LinearMove}.get(movetype)
        if kind is None:
            raise dsl.DslError(f"setInstruction: move type {movetype!r} is not joint or linear")
        rec = _recorder(node)
        if isjointtarget:
            new_target: ir.Target = rec._joints(
                _degrees(joints, "setInstruction"), "setInstruction", name
            )
        else:
            new_target = ir.CartesianTarget(pose=_si(target, "setInstruction"), name=name)
        node.record.instructions[index] = kind(
            target=new_target,
            speed=old.speed,
            zone=old.zone,
            tool=old.tool,
            frame=old.frame,
            span=rec._s.span(),
        )

    def InstructionDelete(self, ins_id: int = 0) -> bool:
        """Delete instruction ``ins_id``; True when it existed."""
        node = self._program("InstructionDelete")
        count = len(node.record.instructions)
        if not isinstance(ins_id, int) or not 0 <= ins_id < count:
            return False
        del node.record.instructions[ins_id]
        return True

    def InstructionSelect(self, ins_id: int = -1) -> int:
        """Select instruction ``ins_id``: "New instructions will be added after the selected
        instruction"; -1 returns the selected one (the last when none was selected)."""
        node = self._program("InstructionSelect")
        sink = node.record.instructions
        assert isinstance(sink, _InsertingList)
        if ins_id == -1:
            return len(sink) - 1 if sink.cursor is None else sink.cursor - 1
        sink.cursor = self._index("InstructionSelect", ins_id) + 1
        return ins_id

    def InstructionList(self) -> tuple[Mat, int]:
        """``(matrix, errors)``: one column per instruction (RoboDK's RoKiSim sequence: the
        joints in degrees, then the instruction type: 1 joint move, 2 linear move, 3 circular
        move, 0 any other instruction (its joints are those of the move before)), and 0 when
        the program resolves without an error, else the number of errors."""
        node = self._program("InstructionList")
        compiled = _compile(node, collisions=False)
        columns = []
        last = compiled.start_joints
        codes = {"joint": 1, "linear": 2, "circular": 3}
        for step in compiled.steps[1:]:
            if step.joints is not None:
                last = step.joints
            kind = getattr(step.instruction, "kind", "")
            columns.append([*np.degrees(last).tolist(), float(codes.get(kind, 0))])
        errors = sum(1 for d in compiled.diagnostics if d.severity == "error")
        return Mat(np.array(columns).T if columns else np.zeros((0, 0))), errors

    def Update(
        self,
        check_collisions: int = COLLISION_OFF,
        timeout_sec: float = 3600,
        mm_step: float = -1,
        deg_step: float = -1,
    ) -> tuple[float, float, float, float, str]:
        """``(valid_instructions, program_time, program_distance, valid_ratio, readable_msg)``
        from olp's passes on this program: instructions before the first error, the cycle time
        (s), the TCP travel (mm), their ratio to all instructions (1.0 when none fails) and the
        first error (or "Program OK")."""
        node = self._program("Update")
        compiled = _compile(node, collisions=bool(check_collisions), timed=True)
        count = len(node.record.instructions)
        errors = [d for d in compiled.diagnostics if d.severity == "error"]
        first = min((d.index for d in errors if d.index is not None), default=None)
        valid = count if not errors else max(0, (first if first is not None else 1) - 1)
        distance = 1000.0 * sum(s.path_length for s in compiled.steps)
        ratio = 1.0 if not errors else valid / max(count, 1)
        message = "Program OK" if not errors else errors[0].message
        return float(valid), float(compiled.cycle_time), float(distance), ratio, message

    def MakeProgram(
        self, folder_path: str = "", run_mode: int = RUNMODE_MAKE_ROBOTPROG, *args: Any
    ) -> tuple[bool, str, bool]:
        """Mark this program as the one olp builds; the files are written by ``olp build``
        with the post and folder of its command line: ``(True, log, False)``."""
        node = self._program("MakeProgram")
        node.record.made = True
        if folder_path:
            note("MakeProgram", "the output folder is olp build's -o, not the script's")
        log = f"olp builds {node.name} with the post given to olp build"
        return True, log, False

    def RunProgram(self, prog_parameters: Any = None) -> int:
        """olp does not run programs (noted); returns the instruction count."""
        node = self._program("RunProgram")
        note("RunProgram", "olp builds the program; it does not run it")
        return len(node.record.instructions)

    RunCode = RunProgram

    def ShowInstructions(self, show: bool = True) -> None:
        self._program("ShowInstructions")
        note("ShowInstructions", "olp has no tree view; no-op")

    def ShowTargets(self, show: bool = True) -> None:
        self._program("ShowTargets")
        note("ShowTargets", "olp has no tree view; no-op")

    def setRunType(self, program_run_type: int) -> None:
        self._program("setRunType")
        note("setRunType", "olp runs nothing on a robot; no-op")

    # ---- live robot and simulation: olp runs offline
    def Busy(self) -> int:
        """0: nothing moves in olp (a move is done when its call returns)."""
        return 0

    def WaitMove(self, timeout: float = 360000) -> None:
        """Moves are done when their call returns: nothing to wait for."""

    def WaitFinished(self) -> None:
        """Nothing runs in the background: nothing to wait for."""

    def Stop(self) -> None:
        note("Stop", "nothing runs in olp; no-op")

    def Connect(self, robot_ip: str = "", blocking: bool = True) -> int:
        """0 (not connected): olp has no live robot connection (noted)."""
        note("Connect", "olp runs offline and connects to no robot")
        return 0

    def ConnectedState(self) -> tuple[int, str]:
        return ROBOTCOM_NOT_CONNECTED, "olp runs offline"

    def Disconnect(self) -> int:
        return 1

    def ShowSequence(self, matrix: Any, *args: Any, **kwargs: Any) -> None:
        note("ShowSequence", "olp draws nothing; no-op")


# ------------------------------------------------------------------------------------------------
# Helpers of the items


class _InsertingList(list[ir.Instruction]):
    """A program item's instructions: appended at the end, or after the instruction
    ``InstructionSelect`` chose (``cursor``: where the next one goes)."""

    cursor: int | None = None

    def append(self, instruction: ir.Instruction) -> None:
        if self.cursor is None:
            super().append(instruction)
            return
        self.insert(self.cursor, instruction)
        self.cursor += 1

    def __delitem__(self, index: Any) -> None:
        if self.cursor is not None and isinstance(index, int) and index < self.cursor:
            self.cursor -= 1
        super().__delitem__(index)


def _recorder(node: _Node) -> dsl.Robot:
    recorder = node.recorder
    assert recorder is not None
    return recorder


def _frame_node(tree: _Tree, frame: ir.Frame) -> _Node | None:
    """The tree's frame item for an IR frame: by name, else the robot base frame or the
    station when the pose is theirs."""
    frames = [n for n in tree.nodes() if n.kind == ITEM_TYPE_FRAME]
    for node in frames:
        if node.name == frame.name:
            return node
    pose = np.eye(4) if frame.pose is None else frame.pose
    base = tree.robot.parent
    if base is not None and np.allclose(base.world(), pose, rtol=0.0, atol=1e-9):
        return base
    return tree.root if np.allclose(pose, np.eye(4), rtol=0.0, atol=1e-9) else None


def _reference(pose: Any) -> FloatArray:
    return np.eye(4) if pose is None else _si(pose, "SolveIK_All")


def _tool_by_number(tree: _Tree, number: int) -> ir.Tool:
    tools = [n.tool for n in tree.robot.children if n.alive and n.tool is not None]
    for tool in tools:
        if tool.number == number:
            return tool
    if number == 0:
        return ir.FLANGE
    known = ", ".join(f"{t.number} {t.name}" for t in tools if t.number is not None) or "none"
    raise dsl.DslError(f"setPoseTool: no tool number {number} (tools: {known})")


def _ir_target(rec: dsl.Robot, value: Any, what: str) -> tuple[ir.Target, ir.Frame | None]:
    """A move's target from a target item, a Mat (pose, or joints as a column) or a list."""
    if isinstance(value, Item):
        node = value._n(what, ITEM_TYPE_TARGET)
        return _tree().target_ir(node)
    if isinstance(value, Mat):
        if value.size() == (4, 4):
            return rec._target(dsl.Mat(np.asarray(value)), what), None
        return rec._target(value.list(), what), None
    return rec._target(value, what), None


def _simulate(move: ir.Instruction, what: str) -> None:
    """A move of the robot itself: checked in simulate mode (TargetReachError), recorded."""
    tree = _tree()
    rec = tree.recorder
    if tree.run_mode in _PROGRAM_MODES:
        rec.record(move)
        return
    start = np.radians(rec.Joints())
    rec.check_collisions = tree.collisions == COLLISION_ON
    result, end = rec.try_moves(start, [move])
    if not result.ok and result.kind not in _NOT_CHECKED:
        message = f"{what}: {result.reason}"
        tree.session.warn(f"{message} (TargetReachError raised; the move was not recorded)")
        raise TargetReachError(message)
    rec.record(move)
    if end is not None:
        rec.place(end)


def _test(rec: dsl.Robot, start: FloatArray, move: ir.Instruction) -> int:
    rec.check_collisions = _tree().collisions == COLLISION_ON
    result, end = rec.try_moves(start, [move])
    if result.ok:
        if end is not None:
            rec.place(end)
        return 0
    return max(result.count, 1) if result.kind.startswith("collision") else -1


def _describe_instruction(instruction: ir.Instruction) -> tuple[str, int, Any, Any, Any, Any]:
    """RoboDK's instruction tuple. A move gives both its target pose (the TCP in the move's
    frame, mm) and its joints (degrees), as RoboDK does: the one the target does not hold is
    computed (forward kinematics, or the IK solution nearest the simulated joints; None when
    there is none)."""
    name = _instruction_name(instruction)
    if isinstance(instruction, ir.CircularMove):
        return name, INS_TYPE_MOVEC, None, None, None, None
    if not isinstance(instruction, ir.JointMove | ir.LinearMove):
        kinds = {ir.Wait: INS_TYPE_PAUSE, ir.Call: INS_TYPE_CODE, ir.Comment: INS_TYPE_CODE}
        return name, kinds.get(type(instruction), INS_TYPE_CODE), None, None, None, None
    move = MOVE_TYPE_JOINT if isinstance(instruction, ir.JointMove) else MOVE_TYPE_LINEAR
    tree = _tree()
    station = tree.station
    tool = instruction.tool if instruction.tool.pose is not None else station.tool(instruction.tool)
    frame = (
        instruction.frame
        if instruction.frame.pose is not None
        else station.frame(instruction.frame)
    )
    tool_pose = np.eye(4) if tool is None or tool.pose is None else tool.pose
    frame_pose = np.eye(4) if frame is None or frame.pose is None else frame.pose
    target = instruction.target
    if isinstance(target, ir.JointTarget):
        tcp = inv(frame_pose) @ station.robot.flange_poses(target.joints) @ tool_pose
        return name, INS_TYPE_MOVE, move, 1, _mm(tcp), _column(target.joints)
    assert isinstance(target, ir.CartesianTarget)
    flange = frame_pose @ target.pose @ inv(tool_pose)
    found = dsl._nearest_solution(station, flange, np.radians(tree.recorder.Joints()))
    joints = None if found is None else _column(found)
    return name, INS_TYPE_MOVE, move, 0, _mm(target.pose), joints


def _instruction_name(instruction: ir.Instruction) -> str:
    target = getattr(instruction, "target", None)
    name = getattr(target, "name", None)
    kind = getattr(instruction, "kind", type(instruction).__name__)
    return f"{kind} {name}" if name else str(kind)


def _compile(node: _Node, collisions: bool, timed: bool = False) -> Any:
    """The program item through olp's passes (resolve; collisions when asked; timing)."""
    from olp.passes.collide import collision_pass
    from olp.passes.pipeline import BuildOptions, run_passes
    from olp.passes.resolve import resolve_pass
    from olp.passes.timing import timing_pass

    tree = _tree()
    start = ir.JointMove(target=ir.JointTarget(joints=np.radians(tree.recorder.Joints())))
    program = ir.Program(name=node.name, instructions=(start, *node.record.instructions))
    passes: tuple[Callable[..., Any], ...] = (resolve_pass,)
    if collisions:
        passes += (collision_pass,)
    if timed:
        passes += (timing_pass,)
    return run_passes(program, tree.station, BuildOptions(), passes)


def _program_start(programname: str, folder: str, postprocessor: str) -> None:
    _tree().recorder.ProgramStart(programname)
    if folder or postprocessor:
        note("ProgramStart", "folder and post processor come from olp build's command line")


_Item = Item
"""``Item`` for annotations inside :class:`Robolink`, whose method ``Item`` hides the class."""


# ------------------------------------------------------------------------------------------------
# The link


class Robolink:
    """The link to the station (RoboDK's ``Robolink``): every instance of one run shares one
    item tree. Connection arguments are accepted and unused (olp needs no RoboDK)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._tree = _tree()
        if args or kwargs:
            note("Robolink", "olp runs no RoboDK instance; the connection arguments are unused")

    # ---- finding items
    def Item(self, name: str, itemtype: int | None = None) -> _Item:
        """The first item called ``name`` (of ``itemtype`` when given); ``name=''`` with a type:
        the first of that type. An invalid item (``Valid()`` False) when none matches."""
        for node in self._tree.nodes():
            if itemtype not in (None, ITEM_TYPE_ANY) and node.kind != itemtype:
                continue
            if node.name == name or (name == "" and itemtype not in (None, ITEM_TYPE_ANY)):
                if node is self._tree.root and name == "":
                    continue
                return Item(self, node)
        return Item(self, None)

    def ItemList(self, filter: int | None = None, list_names: bool = False) -> list[Any]:
        """Every item (of type ``filter``), as items or, with ``list_names``, names."""
        nodes = [
            n
            for n in self._tree.nodes()
            if n is not self._tree.root and (filter in (None, ITEM_TYPE_ANY) or n.kind == filter)
        ]
        return [n.name for n in nodes] if list_names else [Item(self, n) for n in nodes]

    def ItemUserPick(self, message: str = "Pick one item", itemtype_or_list: Any = None) -> _Item:
        """No one to ask: the only item of the type, else the one named by ``--set
        PICK_<TYPE>=NAME`` (``PICK_ROBOT``, ``PICK_FRAME``, ... ``PICK_ITEM`` for any type)."""
        if isinstance(itemtype_or_list, list):
            candidates = [i for i in itemtype_or_list if isinstance(i, Item) and i.Valid()]
            key = "PICK_ITEM"
        else:
            kind = ITEM_TYPE_ANY if itemtype_or_list is None else int(itemtype_or_list)
            candidates = self.ItemList(kind)
            key = PICK_PARAMS.get(kind, "PICK_ITEM")
        chosen = self._tree.session.param(key, "")
        if chosen:
            for item in candidates:
                if item.Name() == chosen:
                    return item
            names = dsl.names_list([i.Name() for i in candidates])
            raise dsl.DslError(f"ItemUserPick: --set {key}={chosen}: no such item (items: {names})")
        if len(candidates) == 1:
            return candidates[0]
        if not candidates:
            return Item(self, None)
        names = dsl.names_list([i.Name() for i in candidates])
        raise dsl.DslError(
            f"ItemUserPick({message[:60]!r}): {len(candidates)} items match ({names}); "
            f"choose one with --set {key}=NAME"
        )

    # ---- adding items
    def _parent(self, itemparent: Any, what: str) -> _Node:
        if isinstance(itemparent, Item):
            return itemparent._n(what, ITEM_TYPE_FRAME, ITEM_TYPE_STATION)
        return self._tree.root

    def AddTarget(self, name: str, itemparent: Any = 0, itemrobot: Any = 0) -> _Item:
        """A new Cartesian target in frame ``itemparent`` (default: the station) at the robot's
        current TCP; set it with ``setPose``/``setJoints``."""
        tree = self._tree
        parent = self._parent(itemparent, "AddTarget")
        node = _Node(ITEM_TYPE_TARGET, str(name), parent)
        joints = np.radians(tree.recorder.Joints())
        node.joints = joints
        flange = tree.station.robot.flange_poses(joints)
        node.local = inv(parent.world()) @ flange @ tree.recorder._tool_pose()
        return Item(self, node)

    def AddFrame(self, name: str, itemparent: Any = 0) -> _Item:
        """A new reference frame at the origin of ``itemparent`` (default: the station)."""
        node = _Node(ITEM_TYPE_FRAME, str(name), self._parent(itemparent, "AddFrame"))
        return Item(self, node)

    def AddProgram(self, name: str, itemrobot: Any = 0) -> _Item:
        """A new program for the robot: its moves and settings are recorded in it."""
        from olp.frontends.dsl import ProgramRecord

        tree = self._tree
        record = ProgramRecord(str(name), _InsertingList())
        tree.session.programs.append(record)
        node = _Node(ITEM_TYPE_PROGRAM, str(name), tree.root)
        node.record = record
        node.recorder = dsl.Robot(tree.session, record.instructions)
        node.recorder._tool = tree.recorder._tool
        node.recorder._frame = tree.recorder._frame
        return Item(self, node)

    def AddFile(self, filename: str, parent: Any = 0) -> _Item:
        raise dsl.DslError("AddFile: olp loads geometry from the station file, not from a script")

    # ---- run settings
    def setRunMode(self, run_mode: int = RUNMODE_SIMULATE) -> None:
        """``RUNMODE_SIMULATE`` checks the robot's moves (TargetReachError);
        ``RUNMODE_MAKE_ROBOTPROG`` records them unchecked. Running a real robot is an error."""
        if run_mode == RUNMODE_RUN_ROBOT:
            raise dsl.DslError("setRunMode(RUNMODE_RUN_ROBOT): olp runs offline, no robot moves")
        if run_mode not in (RUNMODE_SIMULATE, RUNMODE_QUICKVALIDATE, *_PROGRAM_MODES):
            raise dsl.DslError(f"setRunMode: unknown run mode {run_mode!r}")
        if run_mode != RUNMODE_MAKE_ROBOTPROG and run_mode in _PROGRAM_MODES:
            note("setRunMode", "olp makes the program; uploading and starting it is not done")
        self._tree.run_mode = run_mode

    def RunMode(self) -> int:
        return self._tree.run_mode

    def setCollisionActive(self, check_state: int = COLLISION_ON) -> int:
        """Collision checking for simulated moves and move tests (``COLLISION_ON``/``OFF``);
        returns the previous state."""
        previous = self._tree.collisions
        self._tree.collisions = COLLISION_ON if check_state else COLLISION_OFF
        return previous

    def Collisions(self) -> int:
        """The number of colliding pairs at the robot's simulated joints."""
        from olp.passes.collide import check_collisions

        tree = self._tree
        q = np.radians(tree.recorder.Joints())
        hold = dsl._resolve_from(
            tree.station, q, [tree.recorder.motion(ir.JointMove, ir.JointTarget(joints=q))]
        )
        return sum(
            1
            for d in check_collisions(hold)
            if d.kind.startswith("collision") and d.severity == "error"
        )

    def ProgramStart(
        self, programname: str, defaultfolder: str = "", postprocessor: str = "", robot: Any = None
    ) -> int:
        """Name the program olp builds (folder and post come from the command line)."""
        _program_start(programname, defaultfolder, postprocessor)
        return 0

    def Finish(self) -> None:
        """Ends the script's link: nothing to do in olp."""

    def Disconnect(self) -> None:
        """Nothing to disconnect in olp."""

    def Connect(self) -> int:
        return 1

    def Version(self) -> str:
        return "olp"

    def getParam(self, param: str = "", *args: Any, **kwargs: Any) -> Any:
        """``PATH_OPENSTATION`` / ``FILE_OPENSTATION``: the station file's folder and name;
        other parameters are RoboDK's own: noted, None."""
        import os

        source = self._tree.station.source
        if param == PATH_OPENSTATION:
            return os.path.dirname(os.path.abspath(source))
        if param == FILE_OPENSTATION:
            return os.path.basename(source)
        note("getParam", f"RoboDK parameter {str(param)[:40]!r} is unknown to olp; None")
        return None

    def setParam(self, param: str, value: Any = "", *args: Any, **kwargs: Any) -> str:
        note("setParam", f"RoboDK parameter {str(param)[:40]!r} has no meaning in olp; no-op")
        return ""

    # ---- display: no GUI in olp
    def Render(self, always_render: bool = False) -> None:
        note("Render", "olp draws nothing; no-op")

    def setSimulationSpeed(self, speed: float) -> None:
        note("setSimulationSpeed", "olp simulates without a clock; no-op")

    def SimulationSpeed(self) -> float:
        return 1.0

    def ShowMessage(self, message: str, popup: bool = True) -> None:
        note("ShowMessage", f"no pop-up offline; the message was {str(message)[:80]!r}")

    def setWindowState(self, windowstate: int = WINDOWSTATE_NORMAL) -> None:
        note("setWindowState", "olp has no window; no-op")

    def ShowRoboDK(self) -> None:
        note("ShowRoboDK", "olp has no window; no-op")

    def HideRoboDK(self) -> None:
        note("HideRoboDK", "olp has no window; no-op")

    def CloseRoboDK(self) -> None:
        """Nothing to close in olp."""

    def RunProgram(self, fcn_param: str, wait_for_finished: bool = False) -> int:
        note("RunProgram", "olp builds programs; it does not run them")
        return 0

    def RunCode(self, code: str, code_is_fcn_call: bool = False) -> int:
        note("RunCode", "olp builds programs; it does not run them")
        return 0

    def Collision(self, item1: Any, item2: Any) -> int:
        raise dsl.DslError(
            "Collision(item1, item2): olp checks the robot's moves against the station "
            "(setCollisionActive, MoveJ_Test, MoveL_Test), not pairs of items"
        )


_OWN = frozenset(
    {"annotations", "np", "NDArray", "Any", "Callable", "FloatArray"} | {"dsl", "ir", "note", "inv"}
)
__all__ = sorted(
    {n for n in globals() if not n.startswith("_") and n not in _OWN} | set(robomath.__all__)
)
"""``from robolink import *`` gives RoboDK's names, the ``robomath`` module and its names (the
old ``robolink`` module imported ``robodk``'s toolbox into its own names)."""
