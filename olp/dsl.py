"""The names a Python robot program sees: a RoboDK-style API that records an :class:`ir.Program`.

A program is a plain Python file run by ``olp build cell.yaml prog.py`` (see
:mod:`olp.frontends.dsl`). It finds these names already defined (``from olp.dsl import *`` is
optional and only helps editors)::

    SPEED = param("SPEED", 50.0)            # --set SPEED=80 on the command line
    robot.setPoseFrame("table")
    robot.MoveJ("home")
    ref = Pose(300, 200, 100, 180, 0, 0)
    for i in range(7):
        robot.MoveL(ref * rotz(i * 2 * pi / 6) * transl(50, 0, 0))

**A DSL program is code that olp runs, with the full privileges of Python and your rights**,
like any script you run: it can read and write files, import modules and so on. Only run
programs you trust. olp runs it in a child process stopped after ``--timeout`` seconds
(:mod:`olp.frontends.dsl_process`), so how it ends is reported, but that is no sandbox.

Units and conventions (those of the RoboDK API, whose names robot programmers know)
-----------------------------------------------------------------------------------
* Poses are :class:`Mat` (4 x 4) with translations in **mm**; joints are lists in **degrees**
  (controller convention); speeds in mm/s and deg/s; rounding in mm; times in ms.
* ``rotx``, ``roty``, ``rotz`` take **radians**, as in RoboDK's ``robomath`` (so
  ``rotz(i * 2 * pi / n)`` ports unchanged); ``Pose``, ``RelTool`` and ``Offset`` take degrees.
* ``Pose(x, y, z, rx, ry, rz) = transl(x, y, z) · rotx(rx) · roty(ry) · rotz(rz)`` (degrees):
  RoboDK's ``robomath.Pose`` docstring says exactly this ("the same representation used by
  Mecademic or Staubli"), pinned by ``tests/frontends/test_dsl.py``. (``rotz·roty·rotx`` is
  RoboDK's other function, ``xyzrpw_2_pose``.)
* Targets are the TCP of the active tool in the active frame. Tool poses are in the robot
  vendor's flange frame (see :mod:`olp.vendors`; KUKA's flange X axis points out of the
  flange). Frame poses are in the station's **world** frame, as everywhere in olp (RoboDK gives
  ``setPoseFrame(pose)`` relative to the robot base; the two agree when the robot stands at the
  world origin). Defaults: the station's first tool (else the flange) and the world frame, as
  for CSV files. ``SolveIK`` keeps RoboDK's meaning: a flange pose in the robot base frame.
* Inside olp everything is converted to SI at the call; :class:`Mat` never leaves this module.

RoboDK scripts
--------------
A script written against RoboDK's API runs unchanged: ``from robolink import *``,
``from robodk import *`` and the newer ``robodk.robolink`` / ``robodk.robomath`` paths are
importable inside a program olp runs (:mod:`olp.compat`; ``Robolink()``, ``RDK.Item(name)``
over the station's named robot, tools, frames, objects and ``targets:``, run modes with
``TargetReachError``, program items). ``docs/robodk.md`` maps every call to what olp does.
The class :class:`Robot` below is what both APIs record with; ``help(olp.dsl)`` lists its
methods.

Questions a program may ask the station (jobs 2 and 6): :meth:`Robot.Joints`,
:meth:`Robot.Pose`, :meth:`Robot.SolveIK`, :meth:`Robot.MoveL_Test`, :meth:`Robot.MoveJ_Test`
(RoboDK's names and return codes) and :meth:`Robot.canReach` / :meth:`Robot.canMoveL` /
:meth:`Robot.canMoveJ` (a truthy :class:`Feasibility` with the reason). They run olp's resolve
pass on the moves so far, so the answer is exactly what ``olp build`` will find (collisions
are not checked yet).
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from olp import ir
from olp.geometry import inv

if TYPE_CHECKING:
    from olp.compiled import CompiledProgram, Step
    from olp.frontends.dsl import Session
    from olp.station.model import Station

FloatArray = NDArray[np.float64]

pi = math.pi
sin, cos, tan, sqrt = math.sin, math.cos, math.tan, math.sqrt
asin, acos, atan2 = math.asin, math.acos, math.atan2

INSTRUCTION_CALL_PROGRAM = 0
INSTRUCTION_INSERT_CODE = 1
INSTRUCTION_START_THREAD = 2
INSTRUCTION_COMMENT = 3
INSTRUCTION_SHOW_MESSAGE = 4

__all__ = [
    "INSTRUCTION_CALL_PROGRAM",
    "INSTRUCTION_COMMENT",
    "INSTRUCTION_INSERT_CODE",
    "INSTRUCTION_SHOW_MESSAGE",
    "INSTRUCTION_START_THREAD",
    "AddFrame",
    "AddTarget",
    "DslError",
    "Feasibility",
    "FrameItem",
    "Mat",
    "Offset",
    "Pose",
    "RelTool",
    "Robot",
    "Target",
    "ToolItem",
    "acos",
    "asin",
    "atan2",
    "cos",
    "eye",
    "invH",
    "param",
    "pi",
    "robot",
    "rotx",
    "roty",
    "rotz",
    "sin",
    "sqrt",
    "tan",
    "transl",
    "warn",
]


class DslError(Exception):
    """A DSL call was used wrongly; the frontend reports it at the user's line."""


EXCERPT_CHARS = 60
"""Longest piece of the program's text or values a message quotes (the rest is summarised by
its length): a 20 MB string must not become a 20 MB message."""
MAX_IO = 2**31 - 1
"""Largest I/O number a program may use (a controller's integer; vendors allow fewer)."""


def quote(text: str) -> str:
    """``text`` quoted for a message, cut to :data:`EXCERPT_CHARS` characters."""
    if len(text) <= EXCERPT_CHARS:
        return repr(text)
    return f"{text[:EXCERPT_CHARS]!r}... ({len(text)} characters)"


def names_list(names: Sequence[str], limit: int = 10) -> str:
    """Known names for a message: at most ``limit``, each shortened."""
    shown = [quote(n) if len(n) > EXCERPT_CHARS else n for n in names[:limit]]
    more = f", ... ({len(names) - limit} more)" if len(names) > limit else ""
    return ", ".join(shown) + more


# ------------------------------------------------------------------------------------------------
# Poses


class Mat:
    """A pose: a 4 x 4 homogeneous matrix, translation in mm (RoboDK's ``robomath.Mat``).

    ``a * b`` composes poses; ``pose * [x, y, z]`` transforms a point (mm).
    """

    __slots__ = ("_m",)

    def __init__(self, rows: Any = None) -> None:
        if rows is None:
            self._m = np.zeros((4, 4))
            return
        source = rows._m if isinstance(rows, Mat) else rows
        try:
            m = np.array(source, dtype=np.float64)
        except (TypeError, ValueError, OverflowError) as exc:
            raise DslError(f"Mat needs 4 x 4 numbers, got {_describe(rows)}") from exc
        if m.shape != (4, 4):
            raise DslError(f"Mat needs 4 x 4 numbers, got shape {m.shape}")
        self._m = m

    def __mul__(self, other: Any) -> Any:
        if isinstance(other, Mat):
            return Mat(self._m @ other._m)
        if isinstance(other, int | float) and not isinstance(other, bool):
            return Mat(self._m * other)
        vector = np.asarray(other, dtype=np.float64)
        if vector.shape == (3,):
            return (self._m[:3, :3] @ vector + self._m[:3, 3]).tolist()
        if vector.shape == (4,):
            return (self._m @ vector).tolist()
        raise DslError(f"cannot multiply a pose by {_describe(other)}")

    def __matmul__(self, other: Mat) -> Mat:
        return Mat(self._m @ other._m)

    def __getitem__(self, index: Any) -> Any:
        return self._m[index]

    def __setitem__(self, index: Any, value: Any) -> None:
        self._m[index] = value

    def __array__(self, dtype: Any = None, copy: Any = None) -> FloatArray:
        return np.array(self._m, dtype=dtype)

    def __repr__(self) -> str:
        x, y, z = self._m[:3, 3]
        rx, ry, rz = _xyz_angles_deg(self._m)
        return f"Pose({x:.3f}, {y:.3f}, {z:.3f}, {rx:.3f}, {ry:.3f}, {rz:.3f})"

    def Pos(self) -> list[float]:
        """The translation [x, y, z] in mm."""
        return self._m[:3, 3].tolist()

    def setPos(self, xyz: Sequence[float]) -> Mat:
        """Set the translation (mm) in place; returns the pose itself, as RoboDK does."""
        values = np.asarray(xyz, dtype=np.float64).reshape(-1)
        if values.size < 3:
            raise DslError(f"setPos needs [x, y, z], got {_describe(xyz)}")
        self._m[:3, 3] = values[:3]
        return self

    def VX(self) -> list[float]:
        """The X axis of the rotation."""
        return self._m[:3, 0].tolist()

    def VY(self) -> list[float]:
        """The Y axis of the rotation."""
        return self._m[:3, 1].tolist()

    def VZ(self) -> list[float]:
        """The Z axis of the rotation (the tool axis of a target)."""
        return self._m[:3, 2].tolist()

    def inv(self) -> Mat:
        """The inverse of this rigid transform."""
        return Mat(inv(self._m))

    invH = inv

    def isHomogeneous(self) -> bool:
        """True for a rigid transform (orthonormal rotation, last row 0 0 0 1)."""
        return _is_rigid(self._m)

    def Offset(
        self, x: float, y: float, z: float, rx: float = 0, ry: float = 0, rz: float = 0
    ) -> Mat:
        """Move relative to the reference frame: mm and degrees (RoboDK's ``Offset``)."""
        return Offset(self, x, y, z, rx, ry, rz)

    def RelTool(
        self, x: float, y: float, z: float, rx: float = 0, ry: float = 0, rz: float = 0
    ) -> Mat:
        """Move relative to the pose itself (the tool): mm and degrees (``RelTool``)."""
        return RelTool(self, x, y, z, rx, ry, rz)

    def copy(self) -> Mat:
        return Mat(self._m.copy())

    def tolist(self) -> list[list[float]]:
        """The rows as lists."""
        rows: list[list[float]] = self._m.tolist()
        return rows

    def si(self) -> FloatArray:
        """The pose in metres (a copy), as the IR holds it."""
        out = self._m.copy()
        out[:3, 3] /= 1000.0
        return out


def _is_rigid(m: FloatArray) -> bool:
    if not np.all(np.isfinite(m)) or not np.array_equal(m[3], [0.0, 0.0, 0.0, 1.0]):
        return False
    rot = m[:3, :3]
    return bool(np.allclose(rot @ rot.T, np.eye(3), atol=1e-6) and np.linalg.det(rot) > 0)


def _xyz_angles_deg(m: FloatArray) -> tuple[float, float, float]:
    """(rx, ry, rz) in degrees with ``R = Rx Ry Rz`` (the inverse of :func:`Pose`)."""
    r = m[:3, :3]
    ry = math.asin(max(-1.0, min(1.0, float(r[0, 2]))))
    if abs(r[0, 2]) > 1 - 1e-12:
        return 0.0, math.degrees(ry), math.degrees(math.atan2(r[1, 0], r[1, 1]))
    rx = math.atan2(-r[1, 2], r[2, 2])
    rz = math.atan2(-r[0, 1], r[0, 0])
    return math.degrees(rx), math.degrees(ry), math.degrees(rz)


def _finite(values: Sequence[float], what: str) -> list[float]:
    """The values as floats; a DslError naming ``what`` for anything else or non-finite."""
    out = []
    for v in values:
        if isinstance(v, bool) or not isinstance(v, int | float | np.number):
            raise DslError(f"{what}: expected numbers, got {_describe(v)}")
        try:
            number = float(v)
        except OverflowError:
            number = math.inf
        if not math.isfinite(number):
            raise DslError(f"{what}: expected finite numbers, got {_describe(v)}")
        out.append(number)
    return out


def _axis(axis: int, angle: float) -> Mat:
    (a,) = _finite([angle], ("rotx", "roty", "rotz")[axis])
    c, s = math.cos(a), math.sin(a)
    m = np.eye(4)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m[i, i] = m[j, j] = c
    m[i, j], m[j, i] = -s, s
    return Mat(m)


def rotx(rx: float) -> Mat:
    """Rotation about X by ``rx`` **radians** (as RoboDK's ``robomath.rotx``)."""
    return _axis(0, rx)


def roty(ry: float) -> Mat:
    """Rotation about Y by ``ry`` **radians**."""
    return _axis(1, ry)


def rotz(rz: float) -> Mat:
    """Rotation about Z by ``rz`` **radians**."""
    return _axis(2, rz)


def transl(tx: float | Sequence[float], ty: float | None = None, tz: float | None = None) -> Mat:
    """A translation in mm: ``transl(x, y, z)`` or ``transl([x, y, z])``."""
    if ty is None and tz is None and not isinstance(tx, int | float):
        values = _finite(_sequence(tx, "transl"), "transl")
        if len(values) != 3:
            raise DslError(f"transl: expected [x, y, z] in mm, got {len(values)} values")
    else:
        values = _finite([tx, ty, tz], "transl")  # type: ignore[list-item]
    m = np.eye(4)
    m[:3, 3] = values
    return Mat(m)


def _sequence(values: Any, what: str) -> list[Any]:
    if isinstance(values, str | bytes | Mapping) or not hasattr(values, "__iter__"):
        raise DslError(f"{what}: expected a list of numbers, got {_describe(values)}")
    items = []
    for item in values:
        items.append(item)
        if len(items) > 16:
            break
    return items


def eye(size: int = 4) -> Mat:
    """The identity pose."""
    if size != 4:
        raise DslError("olp's Mat is 4 x 4 only")
    return Mat(np.eye(4))


def invH(pose: Mat) -> Mat:
    """The inverse of a rigid transform."""
    return _mat(pose, "invH").inv()


def Pose(x: float, y: float, z: float, rx: float, ry: float, rz: float) -> Mat:
    """``transl(x, y, z) · rotx(rx) · roty(ry) · rotz(rz)``, mm and **degrees**.

    Source: RoboDK ``robomath.Pose`` ("The result is the same as calling:
    H = transl(x,y,z)*rotx(rx*pi/180)*roty(ry*pi/180)*rotz(rz*pi/180)").
    """
    _finite([x, y, z, rx, ry, rz], "Pose")
    rad = math.radians
    return transl(x, y, z) * rotx(rad(rx)) * roty(rad(ry)) * rotz(rad(rz))


def RelTool(
    pose: Mat, x: float, y: float, z: float, rx: float = 0, ry: float = 0, rz: float = 0
) -> Mat:
    """``pose · transl(x, y, z) · rotx(rx) · roty(ry) · rotz(rz)`` (mm, degrees): a move along
    the target's own axes, like ABB's RelTool."""
    _finite([x, y, z, rx, ry, rz], "RelTool")
    return _mat(pose, "RelTool") * Pose(x, y, z, rx, ry, rz)


def Offset(
    pose: Mat, x: float, y: float, z: float, rx: float = 0, ry: float = 0, rz: float = 0
) -> Mat:
    """``transl(x, y, z) · rotx(rx) · roty(ry) · rotz(rz) · pose`` (mm, degrees): a move along
    the reference frame's axes."""
    _finite([x, y, z, rx, ry, rz], "Offset")
    return Pose(x, y, z, rx, ry, rz) * _mat(pose, "Offset")


def _mat(value: Any, what: str) -> Mat:
    if isinstance(value, Mat):
        return value
    if isinstance(value, Target) and value.pose is not None:
        return value.Pose()
    raise DslError(f"{what}: expected a pose (Mat), got {_describe(value)}")


def _describe(value: Any) -> str:
    """The type and a shortened repr of a value the program passed, for a message."""
    return f"{type(value).__name__[:EXCERPT_CHARS]} {brief(value)}"


def brief(value: Any) -> str:
    """A value's repr for a message, cut to :data:`EXCERPT_CHARS` characters."""
    try:
        text = repr(value)
    except Exception:
        text = "(no repr)"
    return f"{text[:EXCERPT_CHARS]}..." if len(text) > EXCERPT_CHARS else text


# ------------------------------------------------------------------------------------------------
# Items: targets, tools and frames defined by the program


class Target:
    """A named target: a pose (mm) or joints (degrees). Made by :func:`AddTarget`."""

    def __init__(self, name: str, pose: Mat | None = None, joints: list[float] | None = None):
        self.name = name
        self.pose = pose.copy() if pose is not None else None
        self.joints = joints

    def Name(self) -> str:
        return self.name

    def Pose(self) -> Mat:
        if self.pose is None:
            raise DslError(f"target {quote(self.name)} is a joint target; it has no pose")
        return self.pose.copy()

    def Joints(self) -> list[float]:
        if self.joints is None:
            raise DslError(f"target {quote(self.name)} is a Cartesian target; ask robot.SolveIK")
        return list(self.joints)

    def isJointTarget(self) -> bool:
        return self.joints is not None

    def __repr__(self) -> str:
        return f"Target({self.name!r})"


class ToolItem:
    """A tool (TCP pose in the flange frame, mm). Made by :meth:`Robot.AddTool`."""

    def __init__(self, tool: ir.Tool):
        self.tool = tool

    def Name(self) -> str:
        return self.tool.name

    def Pose(self) -> Mat:
        return _to_mat(self.tool.pose)

    def __repr__(self) -> str:
        return f"Tool({self.tool.name!r})"


class FrameItem:
    """A reference frame (pose in the world frame, mm). Made by :func:`AddFrame`."""

    def __init__(self, frame: ir.Frame):
        self.frame = frame

    def Name(self) -> str:
        return self.frame.name

    def Pose(self) -> Mat:
        return _to_mat(self.frame.pose)

    def __repr__(self) -> str:
        return f"Frame({self.frame.name!r})"


def _to_mat(pose_si: FloatArray | None) -> Mat:
    if pose_si is None:
        raise DslError("this item is a reference to the station; its pose is not known here")
    m = np.array(pose_si, dtype=np.float64)
    m[:3, 3] *= 1000.0
    return Mat(m)


@dataclass(frozen=True, slots=True)
class Feasibility:
    """The answer of :meth:`Robot.canMoveL` and friends: truthy when the move can run."""

    ok: bool
    reason: str = ""
    kind: str = ""
    count: int = 0
    """How many error diagnostics the move raised (e.g. colliding pairs)."""

    def __bool__(self) -> bool:
        return self.ok


# ------------------------------------------------------------------------------------------------
# The running program (a :class:`olp.frontends.dsl.Session`)


_ACTIVE: ContextVar[Session | None] = ContextVar("olp_dsl_session", default=None)

TRUE_WORDS = frozenset({"1", "true", "yes", "on"})
FALSE_WORDS = frozenset({"0", "false", "no", "off"})


@contextmanager
def active(session: Session) -> Iterator[Session]:
    """Make ``session`` the one the module-level names (``robot``, ``param``...) talk to."""
    token = _ACTIVE.set(session)
    try:
        yield session
    finally:
        _ACTIVE.reset(token)


def _session() -> Session:
    session = _ACTIVE.get()
    if session is None:
        raise DslError("olp.dsl names only work inside a program run by olp (olp build/parse)")
    return session


session = _session
"""The running program's :class:`~olp.frontends.dsl.Session` (for :mod:`olp.compat`)."""


# ------------------------------------------------------------------------------------------------
# The robot: motions, settings and questions to the station


_CALL = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)(?:\s*\((.*)\))?")
"""A program call once stripped of spaces and a final ``;``. One repeat between fixed
characters: linear in the text (``\\s*;?\\s*`` backtracks cubically on a long run of spaces)."""


class Robot:
    """The recorder behind ``robot`` (RoboDK's ``Item`` methods for a robot or program).

    ``instructions``: the list it records into (default: the session's program; a RoboDK
    program item has its own).
    """

    def __init__(self, session: Session, instructions: list[ir.Instruction] | None = None) -> None:
        self._s = session
        self._sink = session.instructions if instructions is None else instructions
        self.check_collisions = False
        station = session.station
        self._tool: ir.Tool = (
            next(iter(station.tools.values()), ir.FLANGE) if station else ir.FLANGE
        )
        self._frame: ir.Frame = ir.WORLD
        self._speed = ir.Speed()
        self._zone = ir.FINE
        self._sim: _Simulation | None = None

    def _record(self, instruction: ir.Instruction) -> None:
        self._sink.append(instruction)

    # ---- motions
    def MoveJ(self, target: Any, blocking: bool = True) -> None:
        """Joint move to a pose (Mat), joints (degrees), a :class:`Target` or a target name."""
        self._record(ir.JointMove(target=self._target(target, "MoveJ"), **self._state()))

    def MoveL(self, target: Any, blocking: bool = True) -> None:
        """Linear move to a pose (Mat), joints (degrees), a :class:`Target` or a target name."""
        self._record(ir.LinearMove(target=self._target(target, "MoveL"), **self._state()))

    def motion(
        self,
        kind: type[ir.JointMove] | type[ir.LinearMove],
        target: ir.Target,
        frame: ir.Frame | None = None,
    ) -> ir.JointMove | ir.LinearMove:
        """The move ``kind`` to ``target`` with the current settings (``frame``: another frame
        than the active one, e.g. a target item's own), not recorded yet."""
        state = self._state()
        if frame is not None:
            state["frame"] = frame
        return kind(target=target, **state)

    def circular(
        self, via: ir.Target, end: ir.Target, frame: ir.Frame | None = None
    ) -> ir.CircularMove:
        """A circular move through ``via`` to ``end`` with the current settings, not recorded."""
        if not isinstance(via, ir.CartesianTarget):
            raise DslError("MoveC: the via point must be a pose, not joints")
        state = self._state()
        if frame is not None:
            state["frame"] = frame
        return ir.CircularMove(target=end, via=via, **state)

    def record(self, instruction: ir.Instruction) -> None:
        """Append ``instruction`` to this recorder's program."""
        self._record(instruction)

    def MoveC(self, target1: Any, target2: Any, blocking: bool = True) -> None:
        """Circular move through ``target1`` to ``target2`` (both Cartesian)."""
        via = self._target(target1, "MoveC")
        end = self._target(target2, "MoveC")
        self._record(self.circular(via, end))

    def _state(self) -> dict[str, Any]:
        return {
            "speed": self._speed,
            "zone": self._zone,
            "tool": self._tool,
            "frame": self._frame,
            "span": self._s.span(),
        }

    def _target(self, value: Any, what: str) -> ir.Target:
        if isinstance(value, str):
            value = self._named(value, what)
        if isinstance(value, Target):
            if value.joints is not None:
                return self._joints(value.joints, what, value.name)
            return self._pose(value.pose, what, value.name)
        if isinstance(value, Mat):
            return self._pose(value, what, None)
        if isinstance(value, list | tuple | np.ndarray) and len(value) > 0:
            rows = all(isinstance(row, list | tuple | np.ndarray) for row in value)
            if rows:
                return self._pose(Mat(value), what, None)
            # A flat sequence is joints; _joints names any entry that is not a finite number.
            return self._joints(list(value), what, None)
        raise DslError(
            f"{what}: expected a pose (Mat), joints (a list of degrees), a target or a target "
            f"name, got {_describe(value)}"
        )

    def _named(self, name: str, what: str) -> Target:
        if name in self._s.targets:
            return self._s.targets[name]
        if name == "home":
            return Target("home", joints=self.JointsHome())
        known = names_list(["home", *self._s.targets])
        raise DslError(
            f"{what}: no target named {quote(name)} (known: {known}); define it with AddTarget"
        )

    def _pose(self, pose: Mat | None, what: str, name: str | None) -> ir.CartesianTarget:
        if pose is None or not pose.isHomogeneous():
            raise DslError(
                f"{what}: the pose is not a rigid transform (rotation not orthonormal, or NaN)"
            )
        return ir.CartesianTarget(pose=pose.si(), name=name)

    def _joints(self, joints: Sequence[float], what: str, name: str | None) -> ir.JointTarget:
        values = _finite(list(joints), f"{what} joints")
        station = self._s.station
        dof = len(station.robot.home) if station is not None else None
        if not values or (dof is not None and len(values) != dof):
            raise DslError(
                f"{what}: expected {dof or 'some'} joint values in degrees, got {len(values)}"
            )
        return ir.JointTarget(joints=np.radians(values), name=name)

    # ---- speed and rounding
    def setSpeed(
        self,
        speed_linear: float,
        speed_joints: float = -1,
        accel_linear: float = -1,
        accel_joints: float = -1,
    ) -> Robot:
        """Speeds in mm/s and deg/s, accelerations in mm/s² and deg/s²; -1 keeps a value.

        A joint speed (deg/s) becomes the fraction of the axis limits that keeps every axis at
        or below it: ``deg/s / fastest axis limit`` (olp's IR has one fraction for all axes).
        A linear acceleration (mm/s²) is the TCP path acceleration limit of linear and circular
        moves (``Speed.linear_acceleration``, m/s²), as RoboDK's ``setAcceleration``.
        """
        values = _finite([speed_linear, speed_joints, accel_linear, accel_joints], "setSpeed")
        linear, joint, accel, joint_accel = values
        changes: dict[str, float] = {}
        if linear >= 0:
            changes["linear"] = _positive(linear, "setSpeed: linear speed (mm/s)") / 1000.0
        if joint >= 0:
            changes["joint"] = self._fraction(joint, "velocity", "setSpeed: joint speed (deg/s)")
        if joint_accel >= 0:
            changes["joint_acceleration"] = self._fraction(
                joint_accel, "acceleration", "setSpeed: joint acceleration (deg/s²)"
            )
        if accel >= 0:
            accel_si = _positive(accel, "setSpeed: linear acceleration (mm/s²)") / 1000.0
            changes["linear_acceleration"] = accel_si
        self._speed = _replace_speed(self._speed, changes)
        return self

    def setSpeedJoints(self, speed_joints: float) -> Robot:
        """Joint speed in deg/s (see :meth:`setSpeed`)."""
        return self.setSpeed(-1, speed_joints)

    def setAcceleration(self, accel_linear: float) -> Robot:
        """Linear (TCP path) acceleration in mm/s² (see :meth:`setSpeed`)."""
        return self.setSpeed(-1, -1, accel_linear)

    def setAccelerationJoints(self, accel_joints: float) -> Robot:
        """Joint acceleration in deg/s² (see :meth:`setSpeed`)."""
        return self.setSpeed(-1, -1, -1, accel_joints)

    def _fraction(self, value: float, limit: str, what: str) -> float:
        station = self._s.station
        if station is None:
            raise DslError(f"{what} needs the station's axis limits (run with a station)")
        fastest = float(np.max(getattr(station.robot.limits, limit)))
        return min(1.0, math.radians(_positive(value, what)) / fastest)

    def setRounding(self, rounding_mm: float) -> Robot:
        """Corner rounding (zone) in mm; -1 (or any negative value) is an exact stop."""
        (value,) = _finite([rounding_mm], "setRounding")
        self._zone = ir.FINE if value < 0 else ir.Zone(value / 1000.0)
        return self

    setZoneData = setRounding

    # ---- tool and frame
    def setPoseTool(self, tool: Any) -> Robot:
        """The active tool: a station tool name or number, a :class:`ToolItem` or a TCP pose
        (mm; it gets the next free tool number)."""
        self._tool = self._tool_of(tool)
        return self

    setTool = setPoseTool

    def setPoseFrame(self, frame: Any) -> Robot:
        """The active frame: a station frame name, a :class:`FrameItem` or a pose (mm)."""
        self._frame = self._frame_of(frame)
        return self

    setFrame = setPoseFrame

    def AddTool(self, tool_pose: Mat, tool_name: str = "New TCP") -> ToolItem:
        """A new tool (TCP pose in the flange frame, mm); it becomes the active tool."""
        name = str(tool_name)
        pose = self._rigid(tool_pose, "AddTool")
        item = ToolItem(ir.Tool(name=name, pose=pose, number=self._s.tool_number(name)))
        self._tool = item.tool
        return item

    def PoseTool(self) -> Mat:
        """The active tool's TCP pose (mm)."""
        return _to_mat(self._tool_pose())

    def PoseFrame(self) -> Mat:
        """The active frame's pose in the world frame (mm)."""
        return _to_mat(self._frame_pose())

    def _tool_of(self, tool: Any) -> ir.Tool:
        if isinstance(tool, ToolItem):
            return tool.tool
        if isinstance(tool, str):
            return self._station_item(tool, "tool")
        if isinstance(tool, int | np.integer) and not isinstance(tool, bool):
            return self._tool_number(int(tool))
        pose = self._rigid(tool, "setPoseTool")
        known = self._same_pose(pose, [self._tool, *self._station_tools(), ir.FLANGE])
        if known is not None:
            return known
        name = f"tool_l{self._s.span().line}"
        return ir.Tool(name=name, pose=pose, number=self._s.tool_number(name))

    def _tool_number(self, number: int) -> ir.Tool:
        """The station's tool with controller number ``number`` (0: the flange)."""
        station = self._s.station
        tools = list(station.tools.values()) if station is not None else []
        for tool in tools:
            if tool.number == number:
                return tool
        if number == 0:
            return ir.FLANGE
        known = ", ".join(f"{t.number} {t.name}" for t in tools if t.number is not None)
        raise DslError(f"setPoseTool: no tool number {number} (tools: {known or 'none'})")

    def _frame_of(self, frame: Any) -> ir.Frame:
        if isinstance(frame, FrameItem):
            return frame.frame
        if isinstance(frame, str):
            return self._station_item(frame, "frame")
        pose = self._rigid(frame, "setPoseFrame")
        frames = self._s.station.frames.values() if self._s.station is not None else ()
        known = self._same_pose(pose, [self._frame, *frames, ir.WORLD])
        if known is not None:
            return known
        return ir.Frame(name=f"frame_l{self._s.span().line}", pose=pose)

    def _station_tools(self) -> list[ir.Tool]:
        return list(self._s.station.tools.values()) if self._s.station is not None else []

    @staticmethod
    def _same_pose(pose: FloatArray, items: Sequence[Any]) -> Any:
        """The first of ``items`` (tools or frames) whose pose is ``pose`` (to 1 µm and 1 µrad):
        a pose read back from a tool or frame (``robot.setPoseTool(robot.PoseTool())``) keeps
        that tool or frame, and with it its controller number."""
        for item in items:
            if item.pose is not None and np.allclose(item.pose, pose, rtol=0.0, atol=1e-6):
                return item
        return None

    def _station_item(self, name: str, kind: str) -> Any:
        builtin: Mapping[str, Any] = (
            {"flange": ir.FLANGE} if kind == "tool" else {"world": ir.WORLD}
        )
        if name in builtin:
            return builtin[name]
        station = self._s.station
        if station is None:
            return ir.Tool(name=name) if kind == "tool" else ir.Frame(name=name)
        table: Mapping[str, Any] = station.tools if kind == "tool" else station.frames
        if name not in table:
            known = names_list([*builtin, *table])
            raise DslError(f"the station has no {kind} named {quote(name)} (known: {known})")
        return table[name]

    def _rigid(self, pose: Any, what: str) -> FloatArray:
        mat = pose if isinstance(pose, Mat) else Mat(pose)
        if not mat.isHomogeneous():
            raise DslError(
                f"{what}: the pose is not a rigid transform (rotation not orthonormal, or NaN)"
            )
        return mat.si()

    def _tool_pose(self) -> FloatArray:
        pose = self._tool.pose
        if pose is None:
            raise DslError(
                f"tool {quote(self._tool.name)} is only known by name (run with a station)"
            )
        return pose

    def _frame_pose(self) -> FloatArray:
        pose = self._frame.pose
        if pose is None:
            raise DslError(
                f"frame {quote(self._frame.name)} is only known by name (run with a station)"
            )
        return pose

    # ---- I/O, waits, calls, comments
    def setDO(self, io_var: int | str, io_value: Any) -> None:
        """Set digital output ``io_var`` (a number) to ``io_value`` (1/0, True/False, on/off)."""
        self._record(
            ir.SetOutput(
                index=_io_index(io_var, "setDO"),
                value=_io_value(io_value, "setDO"),
                span=self._s.span(),
            )
        )

    def waitDI(self, io_var: int | str, io_value: Any, timeout_ms: float = -1) -> None:
        """Wait until digital input ``io_var`` equals ``io_value``; timeouts are not supported."""
        (timeout,) = _finite([timeout_ms], "waitDI timeout")
        if timeout >= 0:
            raise DslError("waitDI: a timeout is not supported yet (olp's IR waits without one)")
        self._record(
            ir.WaitInput(
                index=_io_index(io_var, "waitDI"),
                value=_io_value(io_value, "waitDI"),
                span=self._s.span(),
            )
        )

    def Pause(self, time_ms: float = -1) -> None:
        """Wait ``time_ms`` milliseconds. Without a time RoboDK stops until the operator
        resumes, which olp's IR cannot say yet: an error."""
        (ms,) = _finite([time_ms], "Pause")
        if ms < 0:
            raise DslError(
                "Pause() without a time (stop until resumed) is not supported yet; "
                "give a time in ms"
            )
        self._record(ir.Wait(seconds=ms / 1000.0, span=self._s.span()))

    def RunInstruction(self, code: str, run_type: int = INSTRUCTION_CALL_PROGRAM) -> None:
        """A program call (``"SprayOn"``, ``"TCP_On(2)"``) or a comment (``INSTRUCTION_COMMENT``).

        Raw code, threads and messages are vendor-specific and not supported.
        """
        if not isinstance(code, str):
            raise DslError(f"RunInstruction: expected text, got {_describe(code)}")
        span = self._s.span()
        if run_type == INSTRUCTION_COMMENT:
            self._record(ir.Comment(text=code, span=span))
            return
        if run_type != INSTRUCTION_CALL_PROGRAM:
            raise DslError(
                f"RunInstruction: run type {brief(run_type)} is not supported (olp records "
                "program "
                "calls and comments; raw code is vendor-specific)"
            )
        match = _CALL.fullmatch(code.strip().removesuffix(";").rstrip())
        if match is None:
            raise DslError(
                f"RunInstruction: {quote(code)} is not a program call like Name or Name(1, 2)"
            )
        name, args = match.group(1), match.group(2)
        values = tuple(a.strip() for a in args.split(",")) if args and args.strip() else ()
        self._record(ir.Call(name=name, args=values, span=span))

    def ProgramStart(self, programname: str, folder: str = "", postprocessor: str = "") -> None:
        """Name the generated program (RoboDK's ``ProgramStart``); folder and post come from
        the olp command line."""
        if not isinstance(programname, str) or not programname.strip():
            raise DslError(f"ProgramStart: expected a program name, got {_describe(programname)}")
        self._s.name = programname.strip()

    # ---- questions to the station
    def JointsHome(self) -> list[float]:
        """The station's home joints in degrees."""
        home: list[float] = np.degrees(self._station("JointsHome").robot.home).tolist()
        return home

    def Joints(self) -> list[float]:
        """The joints (degrees) at the end of the moves so far, as olp resolves them."""
        joints: list[float] = np.degrees(self._simulation("Joints").joints()).tolist()
        return joints

    def Pose(self) -> Mat:
        """The active tool's TCP in the active frame (mm) at the current joints."""
        return _to_mat(self._tcp_in_frame(self._simulation("Pose").joints()))

    def SolveIK(
        self,
        pose: Mat,
        joints_approx: Sequence[float] | None = None,
        tool: Mat | None = None,
        reference: Mat | None = None,
    ) -> list[float]:
        """Joints (degrees) for a flange ``pose`` in the robot base frame (RoboDK's meaning;
        ``tool`` and ``reference`` are then TCP and frame poses, mm); [] if unreachable.

        The solution nearest to ``joints_approx`` (default: the current joints) is returned.
        """
        station = self._station("SolveIK")
        flange = (
            station.robot.base
            @ _optional(reference)
            @ _mat(pose, "SolveIK").si()
            @ inv(_optional(tool))
        )
        near = self.Joints() if joints_approx is None else _finite(list(joints_approx), "SolveIK")
        found = _nearest_solution(station, flange, np.radians(near))
        return [] if found is None else np.degrees(found).tolist()

    def MoveJ_Test(self, j1: Sequence[float], j2: Sequence[float], minstep_deg: float = -1) -> int:
        """0 if a joint move from ``j1`` to ``j2`` (degrees) can run, -1 if not (RoboDK's code
        for a feasible move; collisions are not checked yet)."""
        start, end = self._joints(j1, "MoveJ_Test", None), self._joints(j2, "MoveJ_Test", None)
        result = self._check_moves(start.joints, [ir.JointMove(target=end, **self._state())])
        return 0 if result.ok else -1

    def MoveL_Test(self, j1: Sequence[float], pose: Mat, minstep_mm: float = -1) -> int:
        """RoboDK's codes: 0 if a linear move from joints ``j1`` (degrees) to ``pose`` (the TCP
        in the active frame) can run, -2 if the pose cannot be reached at all, -1 if it can be
        reached but not on a straight line."""
        start = self._joints(j1, "MoveL_Test", None)
        target = self._target(pose, "MoveL_Test")
        if not self._reach(target):
            return -2
        result = self._check_moves(start.joints, [ir.LinearMove(target=target, **self._state())])
        return 0 if result.ok else -1

    def canReach(self, target: Any) -> Feasibility:
        """Whether ``target`` has an IK solution inside the joint limits (any configuration)."""
        return self._reach(self._target(target, "canReach"))

    def canMoveL(self, target: Any) -> Feasibility:
        """Whether a linear move from the current joints to ``target`` can run."""
        move = ir.LinearMove(target=self._target(target, "canMoveL"), **self._state())
        return self._check_moves(self._simulation("canMoveL").joints(), [move])

    def canMoveJ(self, target: Any) -> Feasibility:
        """Whether a joint move from the current joints to ``target`` can run."""
        move = ir.JointMove(target=self._target(target, "canMoveJ"), **self._state())
        return self._check_moves(self._simulation("canMoveJ").joints(), [move])

    def _reach(self, target: ir.Target) -> Feasibility:
        station = self._station("canReach")
        if isinstance(target, ir.JointTarget):
            inside = not np.any(station.robot.limits.violations(target.joints))
            return Feasibility(
                inside, "" if inside else "the joints are outside the axis limits", "joint_limit"
            )
        flange = self._frame_pose() @ target.pose @ inv(self._tool_pose())
        found = _nearest_solution(station, flange, station.robot.home)
        if found is not None:
            return Feasibility(True)
        return Feasibility(False, "no IK solution inside the joint limits", "unreachable")

    def _check_moves(self, start: FloatArray, moves: list[ir.Instruction]) -> Feasibility:
        return self.try_moves(start, moves)[0]

    def try_moves(
        self, start: FloatArray, moves: Sequence[ir.Instruction]
    ) -> tuple[Feasibility, FloatArray | None]:
        """Whether ``moves`` can run from joints ``start`` (rad), by olp's resolve pass (and its
        collision check when :attr:`check_collisions`), and the joints at their end (None when
        they cannot run)."""
        station = self._station("a move test")
        compiled = _resolve_from(station, start, moves)
        diagnostics = list(compiled.diagnostics)
        if self.check_collisions and compiled.ok:
            from olp.passes.collide import check_collisions

            diagnostics += check_collisions(compiled)
        errors = [d for d in diagnostics if d.severity == "error"]
        if errors:
            return Feasibility(False, errors[0].message, errors[0].kind, len(errors)), None
        end = compiled.steps[-1].joints
        return Feasibility(True), None if end is None else np.array(end, dtype=np.float64)

    def place(self, joints: FloatArray) -> None:
        """Put the simulated robot at ``joints`` (rad) without recording a move (RoboDK's
        ``setJoints`` and the end of a successful move test)."""
        self._simulation("setJoints").place(joints)

    def _tcp_in_frame(self, joints: FloatArray) -> FloatArray:
        robot = self._station("Pose").robot
        tcp = robot.flange_poses(joints) @ self._tool_pose()
        pose: FloatArray = inv(self._frame_pose()) @ tcp
        return pose

    def _station(self, what: str) -> Station:
        station = self._s.station
        if station is None:
            raise DslError(f"{what} asks the station, but the program runs without one")
        return station

    def _simulation(self, what: str) -> _Simulation:
        if self._sim is None:
            self._sim = _Simulation(self._station(what), self._s.instructions)
        return self._sim


def _replace_speed(speed: ir.Speed, changes: dict[str, float]) -> ir.Speed:
    return dataclasses.replace(speed, **changes) if changes else speed


def _positive(value: float, what: str) -> float:
    if not value > 0:
        raise DslError(f"{what} must be > 0, got {value:g}")
    return value


def _optional(pose: Mat | None) -> FloatArray:
    return np.eye(4) if pose is None else _mat(pose, "SolveIK").si()


def _array(value: Any) -> FloatArray | None:
    if isinstance(value, str | bytes | Mapping):
        return None
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        return None
    return array


def _io_index(io_var: Any, what: str) -> int:
    """An I/O number from 1 to :data:`MAX_IO`: an integer or its digits as text."""
    number: int | None = None
    if isinstance(io_var, int | np.integer) and not isinstance(io_var, bool):
        number = int(io_var)
    elif isinstance(io_var, str) and io_var.strip().isdigit() and len(io_var.strip()) <= 10:
        number = int(io_var.strip())
    if number is None or not 1 <= number <= MAX_IO:
        raise DslError(
            f"{what}: expected an I/O number from 1 to {MAX_IO}, got {_describe(io_var)}"
        )
    return number


def _io_value(value: Any, what: str) -> bool:
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | float | np.number) and value in (0, 1):
        return bool(value == 1)
    text = value.strip().lower() if isinstance(value, str) else ""
    if text in TRUE_WORDS or text == "1.0":
        return True
    if text in FALSE_WORDS or text == "0.0":
        return False
    raise DslError(f"{what}: expected 1/0, True/False or on/off, got {_describe(value)}")


# ------------------------------------------------------------------------------------------------
# Simulation: what the station says about the moves so far


class _Simulation:
    """Joints after the instructions recorded so far (``instructions`` is the live list),
    resolved incrementally by olp's resolve pass."""

    def __init__(self, station: Station, instructions: list[ir.Instruction]) -> None:
        self.station = station
        self.instructions = instructions
        self.done = 0
        self.q: FloatArray = np.array(station.robot.home, dtype=np.float64)

    def place(self, joints: FloatArray) -> None:
        """The robot is at ``joints`` now, after the instructions recorded so far."""
        self.q = np.array(joints, dtype=np.float64)
        self.done = len(self.instructions)

    def joints(self) -> FloatArray:
        moves = [i for i in self.instructions[self.done :] if ir.is_motion(i)]
        self.done = len(self.instructions)
        if moves:
            for step in _resolve_from(self.station, self.q, moves).steps[1:]:
                self.q = self._after(step, self.q)
        return self.q.copy()

    def _after(self, step: Step, q: FloatArray) -> FloatArray:
        if step.joints is not None:
            return np.array(step.joints, dtype=np.float64)
        target = getattr(step.instruction, "target", None)
        if isinstance(target, ir.JointTarget):
            return np.array(target.joints, dtype=np.float64)
        tool = step.tool.pose if step.tool is not None else None
        frame = step.frame.pose if step.frame is not None else None
        if not isinstance(target, ir.CartesianTarget) or tool is None or frame is None:
            return q
        # A move that cannot run (an error of its own): assume the robot got to its target.
        found = _nearest_solution(self.station, frame @ target.pose @ inv(tool), q)
        return q if found is None else found


def _resolve_from(
    station: Station, start: FloatArray, moves: Sequence[ir.Instruction]
) -> CompiledProgram:
    """Resolve ``moves`` starting at joints ``start`` (a first joint move gets there)."""
    from olp.passes.resolve import resolve

    first = ir.JointMove(target=ir.JointTarget(joints=start))
    program = ir.Program(name="dsl_query", instructions=(first, *moves))
    return resolve(program, station)


def _nearest_solution(station: Station, flange: FloatArray, near: FloatArray) -> FloatArray | None:
    """The IK solution (any configuration and turn, inside the limits) nearest to ``near``."""
    from olp.kinematics.opw import turn_variants

    robot = station.robot
    if not np.all(np.isfinite(flange)):
        return None
    sols = robot.solve(np.asarray(flange)[None])[0]
    limits = robot.limits
    variants = turn_variants(sols, limits.lower, limits.upper).reshape(-1, sols.shape[-1])
    variants = variants[np.all(np.isfinite(variants), axis=-1)]
    if variants.shape[0] == 0:
        return None
    best: FloatArray = variants[np.argmin(np.sum((variants - near) ** 2, axis=-1))]
    return best


# ------------------------------------------------------------------------------------------------
# Module-level names that talk to the running program


def param(name: str, default: object = None) -> Any:
    """A program parameter: the ``--set NAME=VALUE`` given on the command line (converted to
    the type of ``default``: bool, int, float or text), else ``default``. Without a default the
    parameter is required. A ``--set`` name no program line asks for is an error."""
    return _session().param(name, default)


def warn(message: str) -> None:
    """Report ``message`` as a warning at this line of the program (e.g. a skipped target)."""
    _session().warn(_warning_text(message))


def _warning_text(message: object, limit: int = 500) -> str:
    text = str(message)
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text)} characters)"


def AddTarget(name: str, value: Any) -> Target:
    """A named target (pose in mm, or joints in degrees) that moves may use by name."""
    session = _session()
    if not isinstance(name, str) or not name:
        raise DslError(f"AddTarget: expected a name, got {_describe(name)}")
    if name in session.targets or name == "home":
        raise DslError(f"AddTarget: a target named {quote(name)} exists already")
    if isinstance(value, Mat):
        target = Target(name, pose=value)
    else:
        array = _array(value)
        if array is None or array.ndim != 1:
            raise DslError(
                f"AddTarget: expected a pose (Mat) or joints in degrees, got {_describe(value)}"
            )
        target = Target(name, joints=_finite(array.tolist(), "AddTarget"))
    session.targets[name] = target
    return target


def AddFrame(name: str, pose: Mat) -> FrameItem:
    """A reference frame: its pose (mm) in the station's world frame."""
    session = _session()
    return FrameItem(ir.Frame(name=str(name), pose=session.robot._rigid(pose, "AddFrame")))


class _ActiveRobot:
    """``robot`` for ``from olp.dsl import robot``: forwards to the running program's robot."""

    def __getattr__(self, name: str) -> Any:
        return getattr(_session().robot, name)

    def __repr__(self) -> str:
        return "<olp.dsl robot>"


robot: Any = _ActiveRobot()
