"""The intermediate representation: what a robot program *means*, in SI units.

Every frontend lowers to these frozen dataclasses and every post renders from them (through
:class:`olp.compiled.CompiledProgram`). The IR never says how one vendor spells a thing.

Conventions
-----------
* Lengths in metres, angles in radians, time in seconds, speeds in m/s and rad/s.
* Poses are ``(4, 4)`` float64 homogeneous transforms (read-only arrays).
* A Cartesian target is the pose of the **TCP** in its motion's **frame**.
* A frame's pose is given in the station's world frame; a tool's pose is the TCP in the robot's
  flange frame (the vendor's flange convention, see :mod:`olp.vendors`).
* Joint values are in the controller's convention (what the pendant shows), in radians.
* Every motion carries the speed, zone, tool and frame it runs with, so a program is a plain
  sequence that can be edited as data (``dataclasses.replace``) without a state machine.

Fields are keyword-only: ``LinearMove(target=..., speed=..., span=...)``.
"""

from __future__ import annotations

import dataclasses
import enum
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal, TypeAlias, TypeGuard

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp import ir_flow as _flow
from olp.ir_flow import (
    BLOCK_TYPES as BLOCK_TYPES,
)
from olp.ir_flow import (
    FLOW_TYPES as FLOW_TYPES,
)
from olp.ir_flow import (
    INTERRUPT_ACTIONS as INTERRUPT_ACTIONS,
)
from olp.ir_flow import (
    PARAMETER_DIRECTIONS as PARAMETER_DIRECTIONS,
)

# The statements beyond motion and I/O (control flow, data, kept source lines) live in
# olp.ir_flow and are re-exported here, so that users import every IR node from olp.ir.
from olp.ir_flow import (
    Aggregate as Aggregate,
)
from olp.ir_flow import (
    Assign as Assign,
)
from olp.ir_flow import (
    BinaryOp as BinaryOp,
)
from olp.ir_flow import (
    Block as Block,
)
from olp.ir_flow import (
    Branch as Branch,
)
from olp.ir_flow import (
    Case as Case,
)
from olp.ir_flow import (
    Constant as Constant,
)
from olp.ir_flow import (
    Declare as Declare,
)
from olp.ir_flow import (
    DigitalInput as DigitalInput,
)
from olp.ir_flow import (
    Exit as Exit,
)
from olp.ir_flow import (
    Expanded as Expanded,
)
from olp.ir_flow import (
    Expr as Expr,
)
from olp.ir_flow import (
    FlowError as FlowError,
)
from olp.ir_flow import (
    For as For,
)
from olp.ir_flow import (
    FunctionCall as FunctionCall,
)
from olp.ir_flow import (
    Goto as Goto,
)
from olp.ir_flow import (
    If as If,
)
from olp.ir_flow import (
    Index as Index,
)
from olp.ir_flow import (
    InterruptDecl as InterruptDecl,
)
from olp.ir_flow import (
    InterruptSwitch as InterruptSwitch,
)
from olp.ir_flow import (
    Label as Label,
)
from olp.ir_flow import (
    Loop as Loop,
)
from olp.ir_flow import (
    Member as Member,
)
from olp.ir_flow import (
    Name as Name,
)
from olp.ir_flow import (
    Parameter as Parameter,
)
from olp.ir_flow import (
    PathTrigger as PathTrigger,
)
from olp.ir_flow import (
    Repeat as Repeat,
)
from olp.ir_flow import (
    Return as Return,
)
from olp.ir_flow import (
    Routine as Routine,
)
from olp.ir_flow import (
    RoutineCall as RoutineCall,
)
from olp.ir_flow import (
    Statement as Statement,
)
from olp.ir_flow import (
    Switch as Switch,
)
from olp.ir_flow import (
    UnaryOp as UnaryOp,
)
from olp.ir_flow import (
    Verbatim as Verbatim,
)
from olp.ir_flow import (
    WaitUntil as WaitUntil,
)
from olp.ir_flow import (
    While as While,
)
from olp.ir_flow import (
    inline_expansions as inline_expansions,
)
from olp.ir_flow import (
    leaves as leaves,
)
from olp.span import GENERATED, SourceSpan

if TYPE_CHECKING:
    from typing import Self


FloatArray: TypeAlias = NDArray[np.float64]
IntArray: TypeAlias = NDArray[np.int64]


class IRError(ValueError):
    """An IR object was constructed with invalid values (a programming error in a frontend)."""


def _frozen_array(value: Any, shape: tuple[int, ...] | None, what: str) -> FloatArray:
    arr = np.array(value, dtype=np.float64)
    if shape is not None and arr.shape != shape:
        raise IRError(f"{what}: expected shape {shape}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise IRError(f"{what}: values must be finite, got {arr.tolist()}")
    arr.setflags(write=False)
    return arr


def _fields_equal(a: Any, b: Any) -> bool:
    if type(a) is not type(b):
        return NotImplemented
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
            if not (isinstance(x, np.ndarray) and isinstance(y, np.ndarray)):
                return False
            if x.shape != y.shape or not np.array_equal(x, y):
                return False
        elif x != y:
            return False
    return True


def _array_eq(cls: type) -> type:
    """Give a dataclass holding numpy arrays a value equality (and no hash)."""
    cls.__eq__ = _fields_equal  # type: ignore[assignment]
    cls.__hash__ = None  # type: ignore[assignment]
    return cls


# --------------------------------------------------------------------------------------------
# Targets, tools, frames, speeds, zones


@dataclass(frozen=True, slots=True)
class Configuration:
    """A vendor-neutral robot configuration request for a Cartesian target.

    ``shoulder``: wrist centre in front of (``"front"``) or behind (``"back"``) axis 1.
    ``elbow``: ``"up"`` or ``"down"``. ``wrist``: ``"flip"`` when the wrist-bend axis (axis 5) is
    negative in the controller's convention, else ``"noflip"``.
    ``joint_ranges``: per joint, ``None`` or a half-open interval ``(low, high)`` in radians that
    the joint value must lie in; this expresses KUKA Turn bits, ABB cf1/cf4/cf6 quadrants and
    Fanuc turn numbers alike. Vendor modules translate their own encodings to and from this.
    """

    shoulder: Literal["front", "back"] | None = None
    elbow: Literal["up", "down"] | None = None
    wrist: Literal["flip", "noflip"] | None = None
    joint_ranges: tuple[tuple[float, float] | None, ...] | None = None


@_array_eq
@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class JointTarget:
    """Joint values in radians, controller convention, one per robot axis."""

    joints: FloatArray
    name: str | None = None

    def __post_init__(self) -> None:
        joints = _frozen_array(self.joints, None, "JointTarget.joints")
        if joints.ndim != 1 or joints.size == 0:
            raise IRError(f"JointTarget.joints: expected a 1-D array, got shape {joints.shape}")
        object.__setattr__(self, "joints", joints)


@_array_eq
@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class CartesianTarget:
    """A TCP pose (4, 4) in metres in the motion's frame, with an optional configuration."""

    pose: FloatArray
    config: Configuration | None = None
    name: str | None = None

    def __post_init__(self) -> None:
        pose = _frozen_array(self.pose, (4, 4), "CartesianTarget.pose")
        _check_rigid(pose, "CartesianTarget.pose")
        object.__setattr__(self, "pose", pose)

    @classmethod
    def trusted(cls, pose: FloatArray, name: str | None = None) -> CartesianTarget:
        """A target from a pose (4, 4) already validated (a row of a :class:`LinearPath`, checked
        with all its rows at once): no second check per pose."""
        target = object.__new__(cls)
        object.__setattr__(target, "pose", pose)
        object.__setattr__(target, "config", None)
        object.__setattr__(target, "name", name)
        return target


Target: TypeAlias = JointTarget | CartesianTarget


def _check_rigid(pose: FloatArray, what: str) -> None:
    """Raise IRError unless ``pose`` (4, 4) is a rigid transform (orthonormal, det +1).

    Checked on Python floats from one ``tolist()``: a toolpath builds 100k targets, and a dozen
    small numpy calls per pose cost five times more than this.
    """
    (a, b, c, _), (d, e, f, _), (g, h, i, _), last = pose.tolist()
    rows = ((a, b, c), (d, e, f), (g, h, i))
    for j in range(3):
        for k in range(j, 3):
            dot = sum(x * y for x, y in zip(rows[j], rows[k], strict=True))
            if abs(dot - (1.0 if j == k else 0.0)) > 1e-6:
                raise IRError(f"{what}: rotation part is not a proper rotation matrix")
    if a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g) < 0:
        raise IRError(f"{what}: rotation part is a reflection (determinant -1)")
    if last != [0.0, 0.0, 0.0, 1.0]:
        raise IRError(f"{what}: last row must be [0, 0, 0, 1]")


def _freeze_optional_pose(item: Tool | Frame, kind: str) -> None:
    """Validate a tool's or frame's pose (if any) and store a read-only copy."""
    if item.pose is not None:
        what = f"{kind} {item.name!r} pose"
        pose = _frozen_array(item.pose, (4, 4), what)
        _check_rigid(pose, what)
        object.__setattr__(item, "pose", pose)


@_array_eq
@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Tool:
    """A tool: the TCP pose (4, 4) in the flange frame, metres.

    ``pose=None`` is a reference to be looked up in the station by ``name`` (or ``number``).
    """

    name: str
    pose: FloatArray | None = None
    number: int | None = None

    def __post_init__(self) -> None:
        _freeze_optional_pose(self, "Tool")


@_array_eq
@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class Frame:
    """A user frame (base, work object): its pose (4, 4) in the station's world frame, metres.

    ``pose=None`` is a reference to be looked up in the station by ``name`` (or ``number``).
    """

    name: str
    pose: FloatArray | None = None
    number: int | None = None

    def __post_init__(self) -> None:
        _freeze_optional_pose(self, "Frame")


WORLD = Frame(name="world", pose=np.eye(4), number=0)
"""The station's world frame."""

FLANGE = Tool(name="flange", pose=np.eye(4), number=0)
"""No tool: the TCP is the flange."""


@dataclass(frozen=True, slots=True, kw_only=True)
class Speed:
    """Programmed speeds.

    ``linear``: TCP speed for linear/circular moves, m/s.
    ``joint``: fraction (0, 1] of each axis' maximum velocity for joint moves.
    ``angular``: optional TCP orientation speed limit for linear/circular moves, rad/s.
    ``joint_acceleration``: fraction (0, 1] of each axis' maximum acceleration.
    ``linear_acceleration``: optional TCP path acceleration limit for linear/circular moves,
    m/s² (KUKA ``$ACC.CP``, ABB ``PathAccLim``, UR ``movel`` ``a``); None: the controller's own.
    ``angular_acceleration``: optional TCP orientation acceleration limit, rad/s² (KUKA
    ``$ACC.ORI1``); None: the controller's own.
    """

    linear: float = 0.25
    joint: float = 1.0
    angular: float | None = None
    joint_acceleration: float = 1.0
    linear_acceleration: float | None = None
    angular_acceleration: float | None = None

    def __post_init__(self) -> None:
        if not (np.isfinite(self.linear) and self.linear > 0):
            raise IRError(f"Speed.linear must be > 0 m/s, got {self.linear}")
        for name in ("joint", "joint_acceleration"):
            value = getattr(self, name)
            if not (np.isfinite(value) and 0 < value <= 1):
                raise IRError(f"Speed.{name} must be in (0, 1], got {value}")
        for name, unit in (
            ("angular", "rad/s"),
            ("linear_acceleration", "m/s²"),
            ("angular_acceleration", "rad/s²"),
        ):
            value = getattr(self, name)
            if value is not None and not (np.isfinite(value) and value > 0):
                raise IRError(f"Speed.{name} must be > 0 {unit}, got {value}")


@dataclass(frozen=True, slots=True)
class Zone:
    """End-of-move blending: ``radius`` in metres; 0 is a fine (exact) stop."""

    radius: float = 0.0

    def __post_init__(self) -> None:
        if not (np.isfinite(self.radius) and self.radius >= 0):
            raise IRError(f"Zone.radius must be >= 0 m, got {self.radius}")

    @property
    def is_fine(self) -> bool:
        return self.radius == 0.0


FINE = Zone(0.0)


# --------------------------------------------------------------------------------------------
# Instructions


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class _Motion:
    """What every motion has. ``spline``: the source asked for the controller's spline
    motion of this kind (KUKA ``SPTP``/``SLIN``/``SCIRC``, which take their settings from other
    system variables and approximate differently from ``PTP``/``LIN``/``CIRC``); olp checks and
    times it as the plain motion, the KUKA post writes the spline keyword back, and the other
    posts write their plain motion (their languages have no such pair)."""

    target: Target
    speed: Speed = field(default_factory=Speed)
    zone: Zone = FINE
    tool: Tool = field(default_factory=lambda: FLANGE)
    frame: Frame = field(default_factory=lambda: WORLD)
    spline: bool = False
    span: SourceSpan = GENERATED

    def with_speed(
        self,
        *,
        linear: float | None = None,
        joint: float | None = None,
        angular: float | None = None,
        joint_acceleration: float | None = None,
        linear_acceleration: float | None = None,
        angular_acceleration: float | None = None,
    ) -> Self:
        """A copy with the given speed parts changed (m/s, fractions, rad/s, m/s², rad/s²); the
        others kept.

        ``move.with_speed(linear=min(move.speed.linear, 0.1))`` caps the TCP speed at 100 mm/s.
        """
        changes = {
            name: value
            for name, value in (
                ("linear", linear),
                ("joint", joint),
                ("angular", angular),
                ("joint_acceleration", joint_acceleration),
                ("linear_acceleration", linear_acceleration),
                ("angular_acceleration", angular_acceleration),
            )
            if value is not None
        }
        return dataclasses.replace(self, speed=dataclasses.replace(self.speed, **changes))

    def with_zone(self, radius: float) -> Self:
        """A copy that blends with ``radius`` metres (0: a fine stop)."""
        return dataclasses.replace(self, zone=Zone(radius))

    def with_tool(self, tool: Tool) -> Self:
        """A copy that runs with ``tool`` (the target stays the TCP pose it was)."""
        return dataclasses.replace(self, tool=tool)

    def with_frame(self, frame: Frame) -> Self:
        """A copy whose target is read in ``frame`` (the numbers of the target are kept)."""
        return dataclasses.replace(self, frame=frame)


@_array_eq
@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class JointMove(_Motion):
    """Move in joint space (KUKA PTP, ABB MoveJ/MoveAbsJ, UR movej, Fanuc J)."""

    kind: Literal["joint"] = field(default="joint", init=False)


@_array_eq
@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class LinearMove(_Motion):
    """Move the TCP on a straight line (KUKA LIN, ABB MoveL, UR movel, Fanuc L)."""

    kind: Literal["linear"] = field(default="linear", init=False)


class ArcOrientation(enum.Enum):
    """How the tool orientation runs along a circular move (vendor-neutral).

    With ``R0`` the TCP rotation at the start, ``R1`` the target's, ``n`` the circle's normal
    (right-handed about the direction of travel), ``phi`` the signed sweep and ``t`` in [0, 1]
    the fraction of the sweep travelled (all in the world; :func:`olp.arcs.arc_rotations`):

    * ``INTERPOLATE``: ``R0 exp(t log(R0^T R1))``, start to end, the via orientation ignored
      (KUKA ``$ORI_TYPE = #VAR`` with ``$CIRC_TYPE = #BASE``, ABB ``MoveC``, UR ``movec``
      ``mode=0``);
    * ``CONSTANT``: ``R0`` throughout, the target's orientation ignored (KUKA ``#CONSTANT`` with
      ``#BASE``);
    * ``PATH``: turned with the tangent about ``n`` and the rest of the change to ``R1``
      interpolated on top (KUKA ``#VAR`` with ``#PATH``);
    * ``PATH_CONSTANT``: turned with the tangent only, constant relative to it (KUKA
      ``#CONSTANT`` with ``#PATH``, UR ``movec`` ``mode=1``);
    * ``WRIST``: the wrist axes interpolated (KUKA ``$ORI_TYPE = #JOINT``): olp cannot plan it
      (the resolve pass says so on the move's line).

    The sources and their confidence are in :mod:`olp.arcs` and in each post's docstring.
    """

    INTERPOLATE = "interpolate"
    CONSTANT = "constant"
    PATH = "path"
    PATH_CONSTANT = "path_constant"
    WRIST = "wrist"


@_array_eq
@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class CircularMove(_Motion):
    """Move the TCP on the circle through the start, ``via`` and ``target`` (KUKA CIRC, ABB
    MoveC, UR movec, Fanuc C).

    ``via`` and ``target`` are in the motion's frame. ``angle``: the signed sweep in radians
    (KUKA's ``CA``), or None: the arc ends at ``target``. With an angle the circle is still the
    one through the three points, but the arc runs ``angle`` from the start (positive: the way
    of the via point, negative: the other way, beyond a full turn if asked) and ends where that
    puts it; ``target``'s orientation is reached at that end. ``orientation``: how the tool
    turns along the arc (:class:`ArcOrientation`). The zone is the arc's approximation at its
    end, as for a linear move.
    """

    via: CartesianTarget
    angle: float | None = None
    orientation: ArcOrientation = ArcOrientation.INTERPOLATE
    kind: Literal["circular"] = field(default="circular", init=False)

    def __post_init__(self) -> None:
        if self.angle is not None and not (np.isfinite(self.angle) and self.angle != 0.0):
            raise IRError(f"CircularMove.angle must be finite and not 0 rad, got {self.angle}")
        if not isinstance(self.orientation, ArcOrientation):
            found = self.orientation
            raise IRError(f"CircularMove.orientation must be an ArcOrientation, got {found!r}")


RUNTIME_MOTIONS = ("joint", "linear", "circular")
"""The motion kinds of a :class:`RuntimeMove`."""

RUNTIME_RELATIVE = ("base", "tool", "axes", "start")
"""How a :class:`RuntimeMove`'s target refers to its start position (``relative``)."""


@dataclass(frozen=True, slots=True, kw_only=True)
class RuntimeMove:
    """A motion whose target is an expression olp cannot evaluate offline: a variable set at
    run time (``LIN xPath[i]`` with ``i`` a parameter), a function's result (``PTP
    fnGetPos()``), a controller variable (``$POS_ACT``), or a name whose value lives in a file
    olp was not given (``PTP XHOME`` without the controller's ``$config.dat``).

    ``motion``: ``"joint"``, ``"linear"`` or ``"circular"`` (:data:`RUNTIME_MOTIONS`);
    ``target``: the end point as an expression (:mod:`olp.ir_flow`: a :class:`Name`, an
    :class:`Index`, a :class:`FunctionCall`, an :class:`Aggregate` with run-time members ...);
    ``via``: a circular move's auxiliary point (an expression), None otherwise; ``angle`` and
    ``orientation``: a circular move's, as :class:`CircularMove` has them. ``speed``, ``zone``,
    ``tool`` and ``frame``: the settings in effect, which a post writes before the motion like
    before any other. ``config``: the configuration the source asks for where it says so
    without run-time values (KUKA S and T given as constants), else None. ``reason``: why the
    target is known only at run time, in words, for the notes that say what olp does not check.
    ``controller_settings``: the motion runs with the tool, base, speed and approximation the
    controller holds, set by a statement kept as written right before it (a KRL ``BAS`` reading
    a ``$config.dat`` olp was not given); ``speed``, ``zone``, ``tool`` and ``frame`` then mean
    nothing, a post writes none of them (only a post of that statement's language can write
    the motion), and the motion after it writes all of its own.
    ``spline``: a spline motion of its kind (KUKA ``SLIN``), as for modelled motions.
    ``relative``: None, the target (and via point) is a position; else the target refers to
    the start position, which the robot reaches only at run time (the motion before went to
    a run-time target), as the source language means it: ``"base"`` offsets along and about
    the base's axes from the start (KRL ``LIN_REL {Z 50}``, ``#BASE`` being the default),
    ``"tool"`` offsets in the tool frame at the start (``LIN_REL {Z 50} #TOOL``), ``"axes"``
    offsets added to the start's axis values (``PTP_REL {A1 10}``), ``"start"`` a position
    whose components left out are the start's (``LIN {Z 500}``). Only a post of the source's
    language writes such a target (its meaning is the source language's); the others refuse.
    ``approximated``: with ``controller_settings``, the source's approximation words (KRL
    ``C_DIS``, ``C_PTP C_DIS``), which a post of the source's language writes after the target,
    so the controller approximates with the distances it holds, as the source did; empty: an
    exact stop.

    Passes cannot check it (reach, limits, collisions) or time it, and the motion after it
    starts where olp does not know (:mod:`olp.passes.resolve`); a post writes it back where
    its language can name the target (:mod:`olp.posts`), else stops with an error on its line.
    Not a :data:`MOTION_TYPES` motion: code that walks motions with targets never meets one.
    """

    motion: Literal["joint", "linear", "circular"]
    target: _flow.Expr
    via: _flow.Expr | None = None
    angle: float | None = None
    orientation: ArcOrientation = ArcOrientation.INTERPOLATE
    speed: Speed = field(default_factory=Speed)
    zone: Zone = FINE
    tool: Tool = field(default_factory=lambda: FLANGE)
    frame: Frame = field(default_factory=lambda: WORLD)
    config: Configuration | None = None
    reason: str = ""
    controller_settings: bool = False
    relative: Literal["base", "tool", "axes", "start"] | None = None
    spline: bool = False
    approximated: tuple[str, ...] = ()
    span: SourceSpan = GENERATED
    kind: Literal["runtime_move"] = field(default="runtime_move", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "approximated", tuple(self.approximated))
        if self.approximated and not self.controller_settings:
            raise IRError("RuntimeMove.approximated is for a motion with controller_settings")
        for word in self.approximated:
            if not (isinstance(word, str) and word.isascii() and word.isidentifier()):
                raise IRError(f"RuntimeMove.approximated: a word of letters, got {word!r}")
        if self.motion not in RUNTIME_MOTIONS:
            raise IRError(
                f"RuntimeMove.motion must be one of {RUNTIME_MOTIONS}, got {self.motion!r}"
            )
        if (self.via is not None) != (self.motion == "circular"):
            raise IRError("RuntimeMove.via is given for a circular move, and only for one")
        if self.angle is not None and (
            self.motion != "circular" or not (np.isfinite(self.angle) and self.angle != 0.0)
        ):
            raise IRError(
                f"RuntimeMove.angle: a circular move's, finite and not 0, got {self.angle}"
            )
        if self.relative is not None and self.relative not in RUNTIME_RELATIVE:
            raise IRError(
                f"RuntimeMove.relative must be None or one of {RUNTIME_RELATIVE}, "
                f"got {self.relative!r}"
            )
        if self.relative == "axes" and self.motion != "joint":
            raise IRError("RuntimeMove.relative 'axes' is a joint move's (offsets of the axes)")


@dataclass(frozen=True, slots=True, kw_only=True)
class Wait:
    """Dwell for ``seconds``."""

    seconds: float
    span: SourceSpan = GENERATED
    kind: Literal["wait"] = field(default="wait", init=False)

    def __post_init__(self) -> None:
        if not (np.isfinite(self.seconds) and self.seconds >= 0):
            raise IRError(f"Wait.seconds must be >= 0, got {self.seconds}")


@dataclass(frozen=True, slots=True, kw_only=True)
class SetOutput:
    """Set digital output ``index`` to ``value``.

    ``signal``: the name the program reads the bit by where it has one (a KRL
    ``SIGNAL OutCinta $OUT[9]`` declared outside the program, in ``$config.dat``), so that
    a post of that language writes the program as it was written; None: by number. The name
    is only another spelling of ``index``: every other post, and every check, uses the number.
    """

    index: int
    value: bool
    signal: str | None = None
    span: SourceSpan = GENERATED
    kind: Literal["set_output"] = field(default="set_output", init=False)


@dataclass(frozen=True, slots=True, kw_only=True)
class WaitInput:
    """Wait until digital input ``index`` equals ``value``.

    ``signal``: the name the program reads the bit by where it has one (a KRL
    ``SIGNAL InTermicoCinta $IN[9]`` declared outside the program, in ``$config.dat``), so that
    a post of that language writes the program as it was written; None: by number. The name
    is only another spelling of ``index``: every other post, and every check, uses the number.
    """

    index: int
    value: bool = True
    signal: str | None = None
    span: SourceSpan = GENERATED
    kind: Literal["wait_input"] = field(default="wait_input", init=False)


@dataclass(frozen=True, slots=True, kw_only=True)
class Call:
    """Call a subprogram or controller routine by name (e.g. ``SprayOn``).

    ``may_move``: the routine's body is not part of the program (another module's, an
    external one) and may move the robot, so the next motion starts where olp does not know
    (:mod:`olp.passes.resolve` checks its target, not its path, and does not time it). The
    KRL frontend sets it for a call of a routine it did not read; a RoboDK-style call of a
    controller program from the DSL does not (RoboDK's own simulation does not move the robot
    for one either), and neither does a split program's call of its parts (each is checked
    on its own).
    """

    name: str
    args: tuple[str, ...] = ()
    may_move: bool = False
    span: SourceSpan = GENERATED
    kind: Literal["call"] = field(default="call", init=False)


@dataclass(frozen=True, slots=True, kw_only=True)
class Comment:
    """A comment kept in the output.

    ``fold``: the comment opens (``"open"``) or closes (``"close"``) a KUKA pendant fold, and
    ``text`` is the line after its ``;`` as written (``FOLD PTP P1 CONT Vel=100 % PDAT1;%{PE}...``,
    ``ENDFOLD``): one line, starting with ``FOLD`` or ``ENDFOLD``. The KRL post writes it back
    unchanged (the pendant shows its folds again); other languages have no folds and write only
    its :attr:`title` (see :meth:`olp.posts.base.Post.comment_node_lines`).

    ``from_source``: read from a source program's comment (the KRL frontend's), not made for
    the output: a character the output's encoding lacks is written as ``?`` with a warning
    rather than stopping the build, since the program's own remark is not olp's to refuse.
    """

    text: str
    span: SourceSpan = GENERATED
    fold: Literal["open", "close"] | None = None
    from_source: bool = False
    kind: Literal["comment"] = field(default="comment", init=False)

    def __post_init__(self) -> None:
        if self.fold is None:
            return
        keyword = "FOLD" if self.fold == "open" else "ENDFOLD"
        if not self.text.upper().startswith(keyword) or self.fold not in ("open", "close"):
            raise IRError(f"a fold's Comment.text starts with {keyword}, got {self.text!r}")
        if any(c in _FOLD_BREAKS or (ord(c) < 32 and c != "\t") for c in self.text):
            raise IRError(f"a fold's Comment.text must be one line, got {self.text!r}")

    @property
    def title(self) -> str:
        """What a fold shows when closed: the text after ``FOLD`` up to the pendant's hidden
        part (from the next ``;``), stripped; the comment's whole text if it is no fold."""
        if self.fold is None:
            return self.text
        keyword = "FOLD" if self.fold == "open" else "ENDFOLD"
        return self.text[len(keyword) :].split(";", 1)[0].strip()


_FOLD_BREAKS = frozenset("\n\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029")


Motion: TypeAlias = JointMove | LinearMove | CircularMove
Instruction: TypeAlias = (
    JointMove
    | LinearMove
    | CircularMove
    | RuntimeMove
    | Wait
    | SetOutput
    | WaitInput
    | Call
    | Comment
    | Statement
)
"""What iterating a program yields: motions, I/O, waits, calls, comments and the statements of
:mod:`olp.ir_flow` (declarations, assignments, waits on conditions, labels and jumps, kept
source lines), in source order; blocks are walked into, never yielded."""

MOTION_TYPES = (JointMove, LinearMove, CircularMove)


@_array_eq
@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class LinearPath:
    """N consecutive linear moves as arrays, with one tool and one frame: the dense form of a CAM
    toolpath (a million points are a few arrays, not a million objects).

    ``poses`` (N, 4, 4) m: the TCP in ``frame``, one row per move's target; ``speeds`` (N,) m/s;
    ``zones`` (N,) m (0: a fine stop); ``lines`` (N,) the 1-based source line of each row in
    ``source``, and ``widths`` (N,) its length in characters (for a located message), or None;
    ``labels`` (N,) integer target names (a CSV index column), or None; ``angular`` the TCP
    orientation speed limit of every row, rad/s, or None; ``acceleration`` and
    ``angular_acceleration`` the TCP path and orientation acceleration limits of every row,
    m/s² and rad/s², or None (see :class:`Speed`).

    All rows are validated at once when the node is made (finite, rigid rotations, speeds > 0,
    zones >= 0). Row ``k`` as an ordinary instruction is :meth:`move` ``(k)``; iterating the node
    (or a :class:`Program` holding it) yields those, made on demand.
    """

    poses: FloatArray
    speeds: FloatArray
    zones: FloatArray
    lines: IntArray
    tool: Tool = field(default_factory=lambda: FLANGE)
    frame: Frame = field(default_factory=lambda: WORLD)
    angular: float | None = None
    acceleration: float | None = None
    angular_acceleration: float | None = None
    source: str = "<memory>"
    widths: IntArray | None = None
    labels: IntArray | None = None
    kind: Literal["linear_path"] = field(default="linear_path", init=False)

    def __post_init__(self) -> None:
        poses = _frozen_array(self.poses, None, "LinearPath.poses")
        if poses.ndim != 3 or poses.shape[1:] != (4, 4) or poses.shape[0] == 0:
            raise IRError(f"LinearPath.poses: expected shape (N, 4, 4), N >= 1, got {poses.shape}")
        _check_rigid_rows(poses, "LinearPath.poses")
        n = poses.shape[0]
        speeds = _frozen_array(self.speeds, (n,), "LinearPath.speeds")
        zones = _frozen_array(self.zones, (n,), "LinearPath.zones")
        if np.any(speeds <= 0):
            raise IRError(f"LinearPath.speeds must be > 0 m/s (row {int(np.argmin(speeds))})")
        if np.any(zones < 0):
            raise IRError(f"LinearPath.zones must be >= 0 m (row {int(np.argmin(zones))})")
        for name in ("angular", "acceleration", "angular_acceleration"):
            value = getattr(self, name)
            if value is not None and not (np.isfinite(value) and value > 0):
                raise IRError(f"LinearPath.{name} must be > 0, got {value}")
        object.__setattr__(self, "poses", poses)
        object.__setattr__(self, "speeds", speeds)
        object.__setattr__(self, "zones", zones)
        object.__setattr__(self, "lines", _frozen_ints(self.lines, n, "LinearPath.lines"))
        for name in ("widths", "labels"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, _frozen_ints(value, n, f"LinearPath.{name}"))

    def __len__(self) -> int:
        return int(self.poses.shape[0])

    def __iter__(self) -> Iterator[LinearMove]:
        return (self.move(k) for k in range(len(self)))

    @property
    def span(self) -> SourceSpan:
        """The first row's span (where the node begins)."""
        return self.row_span(0)

    def row_span(self, k: int) -> SourceSpan:
        """Where row ``k`` came from."""
        line = int(self.lines[k])
        if self.widths is None:
            return SourceSpan(self.source, line)
        return SourceSpan(self.source, line, 1, line, int(self.widths[k]) + 1)

    def move(self, k: int) -> LinearMove:
        """Row ``k`` as an ordinary :class:`LinearMove`."""
        name = None if self.labels is None else str(int(self.labels[k]))
        return LinearMove(
            target=CartesianTarget.trusted(self.poses[k], name),
            speed=_row_speed(
                float(self.speeds[k]), self.angular, self.acceleration, self.angular_acceleration
            ),
            zone=Zone(float(self.zones[k])),
            tool=self.tool,
            frame=self.frame,
            span=self.row_span(k),
        )

    def rows(self, start: int, stop: int) -> LinearPath:
        """Rows ``start`` to ``stop`` (exclusive) as a node of their own."""
        part = slice(start, stop)
        return dataclasses.replace(
            self,
            poses=self.poses[part],
            speeds=self.speeds[part],
            zones=self.zones[part],
            lines=self.lines[part],
            widths=None if self.widths is None else self.widths[part],
            labels=None if self.labels is None else self.labels[part],
        )

    def with_speeds(self, speeds: ArrayLike) -> LinearPath:
        """A copy with other speeds (N,) m/s (or one for all rows), e.g. capped:
        ``path.with_speeds(np.minimum(path.speeds, 0.1))``."""
        return dataclasses.replace(self, speeds=np.broadcast_to(speeds, self.speeds.shape))

    def with_zones(self, zones: ArrayLike) -> LinearPath:
        """A copy with other zone radii (N,) m (or one for all rows)."""
        return dataclasses.replace(self, zones=np.broadcast_to(zones, self.zones.shape))


def _row_speed(
    linear: float,
    angular: float | None,
    acceleration: float | None = None,
    angular_acceleration: float | None = None,
) -> Speed:
    """A Speed of a validated row (no second check)."""
    speed = object.__new__(Speed)
    for name, value in (
        ("linear", linear),
        ("joint", 1.0),
        ("angular", angular),
        ("joint_acceleration", 1.0),
        ("linear_acceleration", acceleration),
        ("angular_acceleration", angular_acceleration),
    ):
        object.__setattr__(speed, name, value)
    return speed


def _frozen_ints(value: Any, n: int, what: str) -> IntArray:
    arr = np.array(value, dtype=np.int64)
    if arr.shape != (n,):
        raise IRError(f"{what}: expected shape ({n},), got {arr.shape}")
    arr.setflags(write=False)
    return arr


def _check_rigid_rows(poses: FloatArray, what: str) -> None:
    """:func:`_check_rigid` for poses (N, 4, 4), all at once; the error names the first bad
    row."""
    r = poses[:, :3, :3]
    gram = np.einsum("nij,nkj->nik", r, r) - np.eye(3)
    bad = np.max(np.abs(gram), axis=(1, 2)) > 1e-6
    bad |= np.linalg.det(r) < 0
    bad |= np.any(poses[:, 3, :] != (0.0, 0.0, 0.0, 1.0), axis=-1)
    if np.any(bad):
        k = int(np.argmax(bad))
        _check_rigid(poses[k], f"{what} row {k}")
        raise IRError(f"{what} row {k}: not a rigid transform")


Node: TypeAlias = Instruction | LinearPath | Block
"""What a program holds: an instruction, a dense run of linear moves, or a block of control
flow (:class:`If`, :class:`Switch`, :class:`While`, :class:`Repeat`, :class:`Loop`,
:class:`For`) holding more nodes."""


@dataclass(frozen=True, slots=True, kw_only=True)
class Program:
    """A named sequence of instructions read from ``source``.

    ``instructions`` holds the program's nodes: ordinary instructions and dense toolpaths
    (:class:`LinearPath`); ``routines`` the program's own routines (:class:`Routine`), which
    its :class:`RoutineCall`\\ s run (:meth:`expanded` is the program as checks see it).
    Iterating the program, ``len`` and the instruction indices that diagnostics and reports
    give count every move of a toolpath as one instruction, as if the program held ordinary
    moves only; they walk the program's own body (a call is one instruction), while
    :meth:`expanded` walks into each call.

    ``params``: the program's own parameters in call order (:class:`Parameter`, as a
    routine's), for a program that other programs call with arguments (a KRL module
    ``DEF MoveSettings(nBase:IN, nTool:IN)``). Their values are known only when the program
    runs: what its body computes from them is run-time. A post writes them where its language
    lets a program take arguments and refuses the program with a located error otherwise.

    ``returns``: the type name of the program's result where the program is a function that
    other programs call in an expression (a KRL module whose first routine is ``DEFFCT BOOL
    RecoverFromWorkSt(...)``), its array extents in ``returns_dims``, as
    :attr:`Routine.returns`; None for a program without a result. Its body gives the result with
    :class:`Return` ``(value=...)``. A post writes it where its language has function programs
    and refuses the program with a located error otherwise.

    ``language``: the robot language the program was read from, as its frontend names it
    (``"krl"``), None for a program from a neutral format (CSV, the DSL) or built in Python. A
    post of that language writes what the source said where it would otherwise add text of
    its own (the KUKA post writes a KRL source's INI fold where it had one and none where it
    had none; a program from elsewhere gets the template's).

    ``exported``: the source marks the program visible to other modules (KRL ``GLOBAL DEF``;
    a module's first routine is visible without it, so the mark changes nothing): a post of
    the source's language writes it back, so the line reads as it did.
    """

    name: str
    instructions: tuple[Node, ...]
    source: str = "<memory>"
    routines: tuple[Routine, ...] = ()
    params: tuple[Parameter, ...] = ()
    returns: str | None = None
    returns_dims: tuple[_flow.Expr | None, ...] = ()
    language: str | None = None
    exported: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.instructions, tuple):
            object.__setattr__(self, "instructions", tuple(self.instructions))
        if not isinstance(self.routines, tuple):
            object.__setattr__(self, "routines", tuple(self.routines))
        if not isinstance(self.params, tuple):
            object.__setattr__(self, "params", tuple(self.params))
        if not isinstance(self.returns_dims, tuple):
            object.__setattr__(self, "returns_dims", tuple(self.returns_dims))
        if self.returns is not None and not self.returns:
            raise IRError(f"Program {self.name}: returns must be a type name or None")
        if self.returns_dims and self.returns is None:
            raise IRError(f"Program {self.name}: returns_dims without a result type (returns)")
        names: set[str] = set()
        for param in self.params:
            if not isinstance(param, Parameter):
                raise IRError(f"Program.params must hold Parameter objects, got {param!r}")
            if param.name.casefold() in names:
                raise IRError(f"Program {self.name}: parameter {param.name} is given twice")
            names.add(param.name.casefold())
        seen: set[str] = set()
        for routine in self.routines:
            if not isinstance(routine, Routine):
                raise IRError(f"Program.routines must hold Routine objects, got {routine!r}")
            if routine.name.casefold() in seen:
                raise IRError(f"Program {self.name}: routine {routine.name} is defined twice")
            seen.add(routine.name.casefold())

    def routine(self, name: str) -> Routine | None:
        """The program's routine called ``name`` (any case), or None."""
        wanted = name.casefold()
        return next((r for r in self.routines if r.name.casefold() == wanted), None)

    def expanded(self) -> Program:
        """The analysis view: every :class:`RoutineCall` of one of the program's routines made
        an :class:`Expanded` holding the routine's body (:func:`olp.ir_flow.expand_calls`), so
        that iterating the program yields every instruction of a routine at each call site;
        a routine that moves the robot and that no call runs is expanded after the program's
        end as an entry (:attr:`olp.ir_flow.Expanded.entry`), checked from an unknown caller.
        The routines are kept (a post writes them from here). Returns the program itself when
        it holds no routine. Raises :class:`olp.ir_flow.FlowError` for recursion."""
        if not self.routines:
            return self
        nodes = _flow.expand_calls(self.instructions, self.routines)
        nodes = _flow.expand_entries(nodes, self.routines)
        return dataclasses.replace(self, instructions=nodes)

    def __iter__(self) -> Iterator[Instruction]:
        for node in _flow.leaves(self.instructions):
            if isinstance(node, LinearPath):
                yield from node
            else:
                yield node

    def __len__(self) -> int:
        nodes = _flow.leaves(self.instructions)
        return sum(len(n) if isinstance(n, LinearPath) else 1 for n in nodes)

    @property
    def has_flow(self) -> bool:
        """Whether the program holds control flow or data statements (:mod:`olp.ir_flow`),
        routines, parameters and a result included (such a program is never split into
        parts: a part would not see them)."""
        function = self.returns is not None
        return bool(self.routines or self.params or function) or _flow.has_flow(self.instructions)

    def flat_nodes(self) -> tuple[Instruction | LinearPath, ...]:
        """The nodes in source order with blocks walked into: what the passes check, one step
        per instruction (a toolpath stays one node)."""
        return tuple(_flow.leaves(self.instructions))

    @property
    def dense(self) -> bool:
        """Whether the program holds a :class:`LinearPath`."""
        return any(isinstance(n, LinearPath) for n in self.instructions)

    def motions(self) -> Iterator[Motion]:
        """The motion instructions, in order (every row of a toolpath)."""
        return (i for i in self if isinstance(i, MOTION_TYPES))

    def replace_instructions(self, instructions: Sequence[Node]) -> Program:
        """A copy with other instructions (for IR -> IR transforms)."""
        return dataclasses.replace(self, instructions=tuple(instructions))

    # ----------------------------------------------------------------------------------------
    # Editing as data (USERS.md job 12): each returns a new program; the source spans stay.

    def map(self, edit: Callable[[Instruction], Edit]) -> Program:
        """A copy where every instruction is replaced by ``edit(instruction)``: an instruction,
        a sequence of them (inserted in its place), or None (deleted). A toolpath's rows are
        instructions like any other (the copy holds them as ordinary moves; for a dense edit of
        a toolpath use :meth:`LinearPath.with_speeds` and friends). Blocks of control flow are
        kept, with the instructions inside them edited the same way, and so are the bodies of
        the program's :attr:`routines` (a speed cap applies to their motions too)."""

        def one(node: Any) -> list[Any]:
            rows = list(node) if isinstance(node, LinearPath) else [node]
            return [new for row in rows for new in _as_list(edit(row))]

        routines = tuple(
            dataclasses.replace(r, body=_flow.map_leaves(r.body, one)) for r in self.routines
        )
        nodes = _flow.map_leaves(self.instructions, one)
        return dataclasses.replace(self, instructions=nodes, routines=routines)

    def map_motions(self, edit: Callable[[Motion], Edit]) -> Program:
        """:meth:`map` on the motions only; other instructions are kept as they are::

        program.map_motions(lambda m: m.with_speed(linear=min(m.speed.linear, 0.1)))
        """
        return self.map(lambda i: edit(i) if is_motion(i) else i)

    def filter(self, keep: Callable[[Instruction], bool]) -> Program:
        """A copy with only the instructions ``keep`` accepts::

        program.filter(lambda i: i.kind != "wait")
        """
        return self.map(lambda i: i if keep(i) else None)

    def insert_after(
        self, match: Callable[[Instruction], bool], make: Callable[[Instruction], Edit]
    ) -> Program:
        """A copy with ``make(instruction)`` inserted after every instruction ``match``
        accepts::

            program.insert_after(lambda i: i.kind == "call", lambda i: Call(name="LogStep"))
        """
        return self.map(lambda i: [i, *_as_list(make(i))] if match(i) else i)

    def insert_before(
        self, match: Callable[[Instruction], bool], make: Callable[[Instruction], Edit]
    ) -> Program:
        """A copy with ``make(instruction)`` inserted before every instruction ``match``
        accepts."""
        return self.map(lambda i: [*_as_list(make(i)), i] if match(i) else i)


Edit: TypeAlias = "Instruction | Sequence[Instruction] | None"
"""What an edit returns for one instruction: its replacement, several, or None (delete it)."""


def _as_list(edit: Instruction | Sequence[Instruction] | None) -> list[Instruction]:
    if edit is None:
        return []
    if isinstance(edit, Sequence):
        return list(edit)
    return [edit]


def is_motion(instruction: Instruction) -> TypeGuard[Motion]:
    """True for joint, linear and circular moves."""
    return isinstance(instruction, MOTION_TYPES)
