"""Fanuc R-30iB (TP / LS) conventions: W, P, R angles, CONFIG, joint convention, flange, names.

Used by frontends and the LS post alike; nothing else in olp knows these rules.

Sources
-------
* W, P, R: ``R = Rz(R) · Ry(P) · Rx(W)`` (W about X, P about Y, R about Z, fixed axes), degrees,
  positions in mm (project vendor notes; the same order as RoboDK's Fanuc post and every
  published Fanuc LS /POS example seen). Reuses :func:`olp.geometry.rotation_from_zyx`. W and R lie
  in (-180°, 180°], P in [-90°, 90°]; at P = ±90° (gimbal lock) olp writes W = 0 and puts the
  rotation into R (olp's choice; what the pendant shows there is unverified).
* CONFIG ``'F U T, t1, t4, t6'`` (:class:`FanucConfig`):

  - ``F``/``N`` wrist: ``N`` when J5 < 0, ``F`` otherwise (project vendor notes, medium
    confidence: the usual tool-down pose J5 = -90° reads ``'N U T'``; the test checks that pose
    is tool-down in olp's Fanuc model). J5 = 0 exactly gives ``F`` (olp's tie rule, unverified).
    Beware the names: Fanuc's ``N`` ("no flip") is :class:`olp.ir.Configuration`'s
    ``wrist="flip"``, which is defined as "axis 5 negative in the controller's convention";
    Fanuc's J5 turns the other way than ABB's axis 5 and KUKA's A5, so the physically usual
    wrist is J5 < 0 on a Fanuc and axis 5 > 0 on the others.
  - ``U``/``D`` elbow: olp's elbow flag (wrist centre in front of / behind the line of the lower
    arm, :mod:`olp.kinematics.configuration`), the meaning of KUKA's S bit 1 and ABB's cfx bit 1.
    For ``T`` poses it is the geometric elbow up/down (medium confidence). For ``B`` poses the
    two differ (an arm reaching back with the elbow geometrically above the shoulder-wrist line
    has its wrist centre behind the lower arm: ``D`` here); which one Fanuc means there is
    unverified.
  - ``T``/``B``: wrist centre in front of / behind the J1 axis (project vendor notes).
  - Turn numbers of J1, J4 and J6: 0 for (-180°, 180°), +1 for [180°, 540°), -1 for
    (-540°, -180°], and so on symmetrically (:func:`turn_number`). The same rule is in RoboDK's
    public Fanuc post (``angle_2_turn``). Pinned at the boundaries by the tests.

* Joint convention: the pendant's J3 is measured from the horizontal, so it couples with J2
  (``J3_model = J3 + J2`` in the ROS-Industrial model, ``J3 = J3_model - J2``). olp's robot
  kinematics own that conversion (:data:`olp.kinematics.base.FANUC_J2_J3`, applied inside
  :class:`olp.kinematics.models.OPWKinematics`); every function here takes and returns the
  *controller's* joints, the numbers the pendant shows and LS joint positions carry. Pass the
  robot (or its kinematics) as ``model``: bare OPW parameters would read J3 as the model's.
* What CONFIG cannot say: it carries no turn for J2, J3 and J5. Where a station's J3 range is
  wider than 360° (the bundled LR Mate 200iC: -142..230°, M-20iA: -185..273°, both modelled
  without the J2/J3 interaction limit), J3 and J3 ± 360° reach the same pose with the same
  CONFIG; :func:`olp.kinematics.configuration.satisfies` then admits both and the caller
  chooses. Which one the controller takes is unverified.
* Flange: the ROS-Industrial Fanuc descriptions (e.g. ``fanuc_lrmate200ic_support``,
  ``lrmate200ic_macro.xacro``) define ``tool0`` as the "all-zeros tool frame", i.e. the tool
  frame the controller uses with an all-zero UTOOL (the faceplate), and a separate X-out
  ``flange`` link for attaching end effectors. olp's model tool0 is that tool0, so
  :data:`FLANGE_IN_TOOL0` is the identity. Their ``base`` link is Fanuc's World frame, at the
  height of J2 (c1 above ``base_link``).
* Program names: 1-36 characters, a letter first, then A-Z, 0-9 and ``_``, written in upper case
  (project vendor notes, medium confidence; older controllers accept 8).

The LS post (``posts/fanuc``)
-----------------------------
Layout as in LS files exported by R-30iB controllers and ROBOGUIDE (public backups; the
project vendor notes): ``/PROG  NAME``, ``/ATTR``, ``/MN``, ``/POS``, ``/END``; CRLF line
endings (the files are DOS text; medium confidence that LF would also do).

* ``/ATTR``: olp writes the fields exported files carry except the dates, sizes and file name
  the controller fills in (``CREATE``/``MODIFIED`` are left out so that the bytes do not depend
  on the clock; whether MakeTP requires them is unverified), ``LINE_COUNT`` = numbered /MN
  lines, ``DEFAULT_GROUP = 1,*,*,*,*`` (one robot, group 1).
* ``/MN``: ``%4d:`` line numbers from 1 (:func:`number_lines`); motion lines ``J P[1] 100%
  FINE    ;``, other lines ``  DO[1]=ON ;``; a circular move is ``C P[via]`` and, on a
  continuation line ``    :  P[end] 100mm/sec FINE    ;``, one program line.
* Speeds: ``J`` in percent of each axis' maximum, ``Speed.joint`` rounded half up to an integer
  1..100 (:func:`joint_percent`); ``L``/``C`` in integer mm/sec, ``Speed.linear`` rounded half
  up, at least 1 (:func:`linear_mm_per_s`; the pendant takes integers there, medium
  confidence; 21.17 mm/s becomes 21mm/sec).
* Termination (:func:`termination`): a zone of radius 0 is ``FINE``; any other is ``CNTn`` with
  ``n = round(radius in mm)`` capped at 100, the rule of RoboDK's public Fanuc post
  (``setZoneData``: ``'CNT%i' % round(min(zone_mm, 100))``; olp rounds halves up). It is not
  exact: ``CNT`` is a percentage of corner rounding whose path depends on speed and
  acceleration, not a distance.
* ``UFRAME_NUM``/``UTOOL_NUM`` before each file's first motion and wherever they change; every
  position records the ``UF``/``UT`` it was taught in (the controller refuses a mismatch).

  - Frames (:func:`uframe_number`): a frame numbered 1..9 (R-30iB user frames, medium
    confidence) is ``UF n``; positions are then relative to it, and the controller's
    ``UFRAME[n]`` must hold the station's frame in World (an info diagnostic gives the values).
    Every other frame (number 0, the station's world, or none, e.g. a KRL inline ``$BASE``) is
    written as ``UF 0`` with the positions in Fanuc's World frame (the post's ``frames_in:
    robot_base``: the robot's ``base · controller_base``, at J2 height for Fanuc arms): exact,
    nothing to set up.
  - Tools (:func:`utool_number`): a tool numbered 0..10 is ``UT n`` (``UT 0``: the faceplate,
    seen in controller exports as ``UTOOL_NUM=0``; 1..10 R-30iB tool frames, medium
    confidence). An unnumbered tool whose TCP is the faceplate is ``UT 0``; any other unnumbered
    tool is the post option ``default_utool`` (1), with a warning that gives the TCP the
    controller's ``UTOOL[n]`` must hold; two such tools, or one whose default number another
    tool of the program has, are an error.

* Positions (:func:`ls_moves`): ``P[n]`` numbered in order of use in each file (a circle's via
  point before its end). A Cartesian target of an OPW arm is written as ``X, Y, Z`` (mm),
  ``W, P, R`` (deg) and the ``CONFIG`` of the planned joints (:func:`config_from_joints`), but
  only where that CONFIG selects the planned joints and no other IK solution within the limits
  (:func:`selecting_configs`, the post hook :func:`step_values`; not e.g. when J3 and J3 ± 360°
  both fit, or at a wrist singularity); otherwise, for joint targets and for arms without
  CONFIG (UR, numeric), as ``J1..J6`` (deg, the controller's joint convention), with an info
  diagnostic for a Cartesian target. Values: ``X = %9.3f  mm``, ``J1=%10.3f deg`` (the widths
  of exported files; they write ``-.000`` where olp writes ``0.000``).
* ``DO[n]=ON/OFF``, ``WAIT DI[n]=ON/OFF``, ``WAIT 1.00(sec)`` (2 decimals), ``CALL NAME`` or
  ``CALL NAME(1,2.5)`` (numeric arguments only), ``!comment`` lines of at most
  :data:`COMMENT_LENGTH` characters (longer comments are wrapped over several lines).
  I/O numbers start at 1.
* Long programs are split (:mod:`olp.transforms.split`, the manifest's ``limits``) into parts
  ``NAME_P1`` ... and a main program of ``CALL`` lines. The bound is RoboDK's public Fanuc post
  default of 9999 lines per program (``MAX_LINES_X_PROG``; not a documented Fanuc figure),
  applied as 3000 instructions per file: an instruction takes at most three /MN lines
  (``UFRAME_NUM``, ``UTOOL_NUM``, the motion) unless it is a long comment.
"""

from __future__ import annotations

import math
import re
import textwrap
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.diagnostics import Diagnostic
from olp.geometry import inv, pose_from, rotation_from_zyx, zyx_from_rotation
from olp.ir import Configuration
from olp.kinematics.configuration import ArmModel, branch_flags, make_configuration, snap

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

FLANGE_IN_TOOL0: FloatArray = np.eye(4)
"""Fanuc's faceplate (all-zeros tool frame) is the model's tool0 (ROS-Industrial)."""

TURN_AXES = (0, 3, 5)
"""Joints (0-based) whose turn numbers CONFIG carries: J1, J4, J6."""


# --------------------------------------------------------------------------------------------
# Orientation


def wpr_to_rotation(w: ArrayLike, p: ArrayLike, r: ArrayLike) -> FloatArray:
    """Rotation matrices (..., 3, 3) ``Rz(R) · Ry(P) · Rx(W)`` from W, P, R in **radians**."""
    return rotation_from_zyx(r, p, w)


def rotation_to_wpr(rotation: ArrayLike) -> FloatArray:
    """(W, P, R) in radians, shape (..., 3), of rotation matrices (..., 3, 3).

    W and R in (-pi, pi], P in [-pi/2, pi/2]; at P = ±pi/2 W is 0 and R carries the rotation.
    """
    return zyx_from_rotation(rotation)[..., ::-1]


def xyzwpr_to_pose(xyzwpr: ArrayLike) -> FloatArray:
    """Poses (..., 4, 4) in metres from X, Y, Z (mm) and W, P, R (deg), shape (..., 6)."""
    v = np.asarray(xyzwpr, dtype=np.float64)
    rot = wpr_to_rotation(*np.radians(np.moveaxis(v[..., 3:6], -1, 0)))
    return pose_from(rot, v[..., :3] / 1000.0)


def pose_to_xyzwpr(pose: ArrayLike) -> FloatArray:
    """X, Y, Z (mm) and W, P, R (deg), shape (..., 6), from poses (..., 4, 4) in metres."""
    t = np.asarray(pose, dtype=np.float64)
    return np.concatenate([t[..., :3, 3] * 1000.0, np.degrees(rotation_to_wpr(t[..., :3, :3]))], -1)


# --------------------------------------------------------------------------------------------
# Configuration


def turn_number(angles: ArrayLike) -> IntArray:
    """Fanuc turn numbers (...,) of joint angles (...,) in rad.

    0 for (-180°, 180°), +1 for [180°, 540°), -1 for (-540°, -180°], +2 for [540°, 900°) ...:
    ``sign(q) · floor((|q| + 180°) / 360°)``. Angles within 1e-12 rad of an odd multiple of 180°
    count as on it.
    """
    q = snap(angles, math.pi)
    return (np.sign(q) * np.floor((np.abs(q) + math.pi) / (2 * math.pi))).astype(np.int64)


def turn_range(turn: int) -> tuple[float, float]:
    """The joint range (rad) of a turn number: ``((2n - 1)·180°, (2n + 1)·180°)``; which end is
    closed follows :func:`turn_number` (the end nearer 0 is open, except for 0 where both are)."""
    return ((2 * turn - 1) * math.pi, (2 * turn + 1) * math.pi)


@dataclass(frozen=True, slots=True)
class FanucConfig:
    """A Fanuc CONFIG value, e.g. ``'N U T, 0, 0, 0'``.

    ``flip``: ``F`` (J5 >= 0) rather than ``N`` (J5 < 0). ``up``: ``U`` rather than ``D``.
    ``front``: ``T`` (wrist centre in front of the J1 axis) rather than ``B``.
    ``turns``: turn numbers of J1, J4, J6.
    """

    flip: bool
    up: bool
    front: bool
    turns: tuple[int, int, int] = (0, 0, 0)

    def __str__(self) -> str:
        letters = (
            f"{'F' if self.flip else 'N'} {'U' if self.up else 'D'} {'T' if self.front else 'B'}"
        )
        return f"{letters}, {self.turns[0]}, {self.turns[1]}, {self.turns[2]}"

    @classmethod
    def parse(cls, text: str) -> FanucConfig:
        """Read ``'N U T, 0, -1, 0'`` (quotes optional, any spacing and letter case)."""
        match = _CONFIG.fullmatch(text.strip().strip("'").strip())
        if match is None:
            raise ValueError(f"not a Fanuc CONFIG value: {text!r} (expected e.g. 'N U T, 0, 0, 0')")
        wrist, elbow, shoulder, t1, t4, t6 = match.groups()
        turns = (int(t1), int(t4), int(t6))
        return cls(wrist.upper() == "F", elbow.upper() == "U", shoulder.upper() == "T", turns)


_CONFIG = re.compile(
    r"([FN])\s*([UD])\s*([TB])\s*,\s*([+-]?\d+)\s*,\s*([+-]?\d+)\s*,\s*([+-]?\d+)", re.IGNORECASE
)


def config_from_joints(model: ArmModel, joints: ArrayLike) -> FanucConfig:
    """The CONFIG of controller joints (6,) in rad on ``model`` (OPW parameters or a robot)."""
    q = np.asarray(joints, dtype=np.float64)
    if q.shape != (6,):
        raise ValueError(f"config_from_joints: expected joints of shape (6,), got {q.shape}")
    flags = branch_flags(model, q)
    t1, t4, t6 = (int(t) for t in turn_number(q[list(TURN_AXES)]))
    return FanucConfig(
        not bool(flags.flip), not bool(flags.down), not bool(flags.back), (t1, t4, t6)
    )


def configuration_from_config(config: FanucConfig | str) -> Configuration:
    """The :class:`olp.ir.Configuration` a CONFIG asks for: ``F`` is ``wrist="noflip"`` (J5 >=
    0), ``N`` is ``"flip"``; turn numbers become ranges of J1, J4 and J6 (:func:`turn_range`)."""
    c = FanucConfig.parse(config) if isinstance(config, str) else config
    ranges: list[tuple[float, float] | None] = [None] * 6
    for axis, turn in zip(TURN_AXES, c.turns, strict=True):
        ranges[axis] = turn_range(turn)
    return make_configuration(not c.front, not c.up, not c.flip, joint_ranges=tuple(ranges))


# --------------------------------------------------------------------------------------------
# Spelling for the LS post

POSITION_DECIMALS = 3
"""mm for X, Y, Z and deg for W, P, R and joints, as LS files carry them."""

MAX_NAME_LENGTH = 36
"""Program names: 1-36 characters (medium confidence; older controllers accept 8)."""


def _num(value: float, decimals: int = POSITION_DECIMALS) -> str:
    text = f"{float(value):.{decimals}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def ls_xyzwpr(pose: ArrayLike) -> list[str]:
    """X, Y, Z (mm) and W, P, R (deg) of a pose (4, 4) in metres as 6 strings (3 decimals)."""
    return [_num(v) for v in pose_to_xyzwpr(pose)]


def ls_joints(joints: ArrayLike) -> list[str]:
    """J1..J6 in degrees (3 decimals) from controller joints (6,) in rad."""
    return [_num(v) for v in np.degrees(np.asarray(joints, dtype=np.float64))]


def legal_name(name: str) -> str:
    """A legal program name: upper case A-Z, 0-9 and ``_``, a letter first (``P`` is put in front
    otherwise), at most 36 characters."""
    cleaned = "".join(
        ch.upper() if (ch.isascii() and (ch.isalnum() or ch == "_")) else "_" for ch in name
    )
    if not cleaned or not cleaned[0].isalpha():
        cleaned = "P" + cleaned
    return cleaned[:MAX_NAME_LENGTH]


def _config_filter(joints: ArrayLike, robot: ArmModel) -> str:
    """Template filter: ``joints | fanuc_config(robot)`` gives ``N U T, 0, 0, 0``."""
    return str(config_from_joints(robot, joints))


# --------------------------------------------------------------------------------------------
# Motion parameters of the LS post

UFRAME_RANGE = (1, 9)
"""User frames a program may select besides World (0) (R-30iB default; medium confidence)."""
UTOOL_RANGE = (0, 10)
"""Tool frames: 0 the faceplate, 1..10 taught tools (medium confidence)."""
DEFAULT_UTOOL = 1
"""``UT`` of a tool without a number (the post option ``default_utool`` overrides it)."""
COMMENT_LENGTH = 32
"""Characters per ``!`` comment line olp writes (a conservative bound; unverified)."""
CONFIG_TOLERANCE = 1e-6
"""rad: IK candidates this close to the planned joints count as the planned solution."""


def _round_half_up(value: float) -> int:
    return math.floor(value + 0.5)


def joint_percent(speed: Any) -> int:
    """``J`` speed in percent (1..100) of ``speed.joint`` (a fraction of each axis' maximum)."""
    return min(100, max(1, _round_half_up(speed.joint * 100.0)))


def linear_mm_per_s(speed: Any) -> int:
    """``L``/``C`` speed in integer mm/sec (>= 1) of ``speed.linear`` (m/s)."""
    return max(1, _round_half_up(speed.linear * 1000.0))


def termination(zone: Any) -> str:
    """``FINE`` for a zone of radius 0, else ``CNTn``, n = round(radius mm) capped at 100."""
    if zone.radius <= 0:
        return "FINE"
    return f"CNT{min(100, _round_half_up(zone.radius * 1000.0))}"


def wait_seconds(seconds: float) -> str:
    """A ``WAIT`` time: seconds with 2 decimals."""
    return _num(seconds, 2)


def uframe_number(frame: Any) -> int:
    """``UF`` of a frame: its number when in 1..9, else 0 (World)."""
    number = getattr(frame, "number", None)
    if number is not None and UFRAME_RANGE[0] <= number <= UFRAME_RANGE[1]:
        return int(number)
    return 0


def is_flange(tool: Any) -> bool:
    """The tool's TCP is the faceplate itself."""
    return tool.pose is not None and bool(np.allclose(tool.pose, np.eye(4), rtol=0, atol=1e-12))


def utool_number(tool: Any, options: Mapping[str, Any] | None = None) -> int:
    """``UT`` of a tool: its number; 0 for an unnumbered tool whose TCP is the faceplate; the
    option ``default_utool`` (:data:`DEFAULT_UTOOL`) for any other unnumbered tool."""
    if tool.number is not None:
        return int(tool.number)
    if is_flange(tool):
        return 0
    return int((options or {}).get("default_utool", DEFAULT_UTOOL))


# --------------------------------------------------------------------------------------------
# CONFIG that selects the planned joints


def candidates(robot: Any, flange_world: ArrayLike) -> FloatArray:
    """Every IK solution (K, 6) of a flange pose (4, 4) in the station's world, with its turn
    variants, within the robot's joint limits (controller joints, rad)."""
    from olp.kinematics.base import turn_variants

    sols = robot.solve(np.asarray(flange_world, dtype=np.float64)[None])[0]
    limits = robot.limits
    variants = turn_variants(sols, limits.lower, limits.upper).reshape(-1, robot.dof)
    ok = np.all(np.isfinite(variants), axis=-1) & ~np.any(limits.violations(variants), axis=-1)
    found: FloatArray = variants[ok]
    return found


def config_selects(
    robot: Any, config: FanucConfig | str, flange_world: ArrayLike, planned: ArrayLike
) -> bool:
    """True when ``config`` admits, among the IK candidates of the flange pose, the planned
    joints (6,) rad and no other solution (:data:`CONFIG_TOLERANCE`)."""
    from olp.kinematics.configuration import satisfies

    found = candidates(robot, flange_world)
    chosen = found[satisfies(configuration_from_config(config), found, robot)]
    if chosen.shape[0] == 0:
        return False
    return bool(np.all(np.max(np.abs(chosen - np.asarray(planned)), axis=-1) < CONFIG_TOLERANCE))


def has_config(robot: Any) -> bool:
    """Whether the robot's arm has CONFIG flags (an OPW arm)."""
    from olp.kinematics.configuration import opw_parameters

    try:
        opw_parameters(robot)
    except TypeError:
        return False
    return True


def selecting_configs(robot: Any, joints: ArrayLike) -> list[str | None]:
    """Per planned joint vector (N, 6) rad: its CONFIG when that selects it alone among the IK
    solutions (with turn variants, within the limits) of its pose, else None (write the position
    as joints). Vectorised: IK for all poses at once, :func:`satisfies` once per distinct
    CONFIG."""
    from olp.kinematics.base import turn_variants
    from olp.kinematics.configuration import satisfies

    q = np.asarray(joints, dtype=np.float64).reshape(-1, 6)
    if q.shape[0] == 0 or not has_config(robot):
        return [None] * q.shape[0]
    flags = branch_flags(robot, q)
    turns = turn_number(q[:, list(TURN_AXES)]).tolist()
    configs = [
        str(FanucConfig(not bool(f), not bool(d), not bool(b), (t[0], t[1], t[2])))
        for f, d, b, t in zip(flags.flip, flags.down, flags.back, turns, strict=True)
    ]
    limits = robot.limits
    sols = robot.solve(robot.flange_poses(q))
    found = turn_variants(sols, limits.lower, limits.upper).reshape(q.shape[0], -1, 6)
    selected = np.zeros(q.shape[0], dtype=bool)
    for text in sorted(set(configs)):
        rows = np.array([c == text for c in configs])
        ok = satisfies(configuration_from_config(text), found[rows], robot)
        near = np.max(np.abs(found[rows] - q[rows][:, None, :]), axis=-1) < CONFIG_TOLERANCE
        selected[rows] = np.any(ok, axis=-1) & np.all(~ok | near, axis=-1)
    return [c if keep else None for c, keep in zip(configs, selected, strict=True)]


def step_values(robot: Any, joints: ArrayLike, options: Any = None) -> list[dict[str, Any]]:
    """Post hook: per planned motion (joints (N, 6) rad) ``{"config": str | None}``, the
    CONFIG a Cartesian position gets (:func:`selecting_configs`)."""
    return [{"config": c} for c in selecting_configs(robot, joints)]


# --------------------------------------------------------------------------------------------
# Positions and program lines


@dataclass(frozen=True, slots=True)
class LsPosition:
    """One ``P[n]`` of ``/POS``: ``uf``, ``ut``, ``config`` (None: joint representation) and six
    numbers already spelled (X..R in mm/deg, or J1..J6 in deg)."""

    number: int
    uf: int
    ut: int
    config: str | None
    values: tuple[str, ...]

    @property
    def cartesian(self) -> bool:
        return self.config is not None


@dataclass(frozen=True, slots=True)
class LsMove:
    """A motion of ``/MN``: its positions, and whether ``UFRAME_NUM``/``UTOOL_NUM`` must be set
    before it."""

    target: LsPosition
    via: LsPosition | None = None
    set_uf: bool = False
    set_ut: bool = False


def ls_moves(
    steps: Sequence[Any], robot: Any, options: Mapping[str, Any] | None = None
) -> dict[int, LsMove]:
    """Template filter ``steps | ls_moves(robot, options)``: the LS motion of every motion of
    one file (template view steps, in order), by instruction index. Positions are numbered from
    1 in each file; ``UFRAME_NUM``/``UTOOL_NUM`` are set before the file's first motion and
    where they change."""
    out: dict[int, LsMove] = {}
    last: tuple[int, int] | None = None
    number = 0
    for step in steps:
        if step.joints is None:
            continue
        uf, ut = uframe_number(step.frame), utool_number(step.tool, options)
        via = None
        if step.via is not None:
            number += 1
            via = _via_position(number, uf, ut, step, robot)
        number += 1
        target = _target_position(number, uf, ut, step)
        out[step.index] = LsMove(
            target, via, last is None or last[0] != uf, last is None or last[1] != ut
        )
        last = (uf, ut)
    return out


def _in_user_frame(step: Any, pose_in_frame: ArrayLike, uf: int) -> FloatArray:
    """A pose given in the step's frame, in the frame ``UF`` positions refer to: the frame
    itself for UF 1..9, World (the post's ``frames_in: robot_base`` reference) for UF 0."""
    pose = np.asarray(pose_in_frame, dtype=np.float64)
    if uf > 0:
        return pose
    world: FloatArray = np.asarray(step.frame_pose) @ pose
    return world


def _target_position(number: int, uf: int, ut: int, step: Any) -> LsPosition:
    config = step.vendor.get("config") if step.cartesian else None
    if config is None:
        return LsPosition(number, uf, ut, None, tuple(ls_joints(step.joints)))
    pose = _in_user_frame(step, step.pose, uf)
    return LsPosition(number, uf, ut, config, tuple(ls_xyzwpr(pose)))


def _via_position(number: int, uf: int, ut: int, step: Any, robot: Any) -> LsPosition:
    """A circle's via point with the CONFIG of its IK solution nearest to the end joints (the
    arc stays in one branch), or the end joints' CONFIG when it has none."""
    joints = np.asarray(step.joints, dtype=np.float64)
    config = "N U T, 0, 0, 0"
    if has_config(robot):
        via_world = np.asarray(step.frame.pose) @ np.asarray(step.via) @ inv(step.tool.pose)
        found = candidates(robot, via_world)
        if found.shape[0]:
            joints = found[np.argmin(np.sum((found - joints) ** 2, axis=-1))]
        config = str(config_from_joints(robot, joints))
    return LsPosition(number, uf, ut, config, tuple(ls_xyzwpr(_in_user_frame(step, step.via, uf))))


def number_lines(body: str) -> str:
    """Number the /MN lines: ``%4d:`` before each line, ``    :`` before a continuation line
    (one starting with ``:``); empty lines are dropped."""
    out: list[str] = []
    count = 0
    for line in body.splitlines():
        if not line.strip():
            continue
        if line.startswith(":"):
            out.append("    " + line)
            continue
        count += 1
        out.append(f"{count:4d}:{line}")
    from olp.posts.sandbox import SafeText

    return SafeText("\n".join(out))


def line_count(body: str) -> int:
    """The number of program lines of an un-numbered /MN body (continuations excluded)."""
    return sum(1 for line in body.splitlines() if line.strip() and not line.startswith(":"))


def comment_lines(text: str) -> list[str]:
    """A comment's words in lines of at most :data:`COMMENT_LENGTH` characters (a longer word
    is cut); ``;`` would end the instruction and becomes ``,``."""
    words = " ".join(str(text).replace(";", ",").split())
    return textwrap.wrap(words, COMMENT_LENGTH, break_long_words=True) or [""]


def _xyz_filter(value: str) -> str:
    return f"{value:>9}"


def _joint_filter(value: str) -> str:
    return f"{value:>10}"


TEMPLATE_FILTERS = {
    "fanuc_config": _config_filter,
    "ls_xyzwpr": ls_xyzwpr,
    "ls_joints": ls_joints,
    "ls_moves": ls_moves,
    "ls_joint_speed": joint_percent,
    "ls_linear_speed": linear_mm_per_s,
    "ls_termination": termination,
    "ls_seconds": wait_seconds,
    "ls_number_lines": number_lines,
    "ls_line_count": line_count,
    "ls_comment_lines": comment_lines,
    "ls_xyz_field": _xyz_filter,
    "ls_joint_field": _joint_filter,
}


# --------------------------------------------------------------------------------------------
# What the LS post reports


def post_diagnostics(compiled: Any, options: Mapping[str, Any] | None = None) -> list[Diagnostic]:
    """What the LS post reports about a compiled program: frame and tool numbers LS cannot
    write (errors), a tool number olp chose (warning, with the TCP the controller must hold),
    the controller frames and tools the program relies on (info), I/O numbers and calls LS
    cannot spell (errors), a robot of another brand (warning), Cartesian targets written as
    joints because no CONFIG selects them alone (info)."""
    from olp.vendors.ur import foreign_robot

    robot = compiled.station.robot
    motions = [s for s in compiled.steps if s.joints is not None]
    out = foreign_robot(compiled, "fanuc", "LS program")
    out += _frame_checks(motions, robot)
    out += _tool_checks(motions, options)
    for step in compiled.steps:
        out += _instruction_checks(step.index, step.instruction)
    out += _joint_position_notes(motions, robot)
    return out


def _first_use(motions: Sequence[Any], attr: str) -> dict[str, Any]:
    seen: dict[str, Any] = {}
    for step in motions:
        seen.setdefault(getattr(step, attr).name, step)
    return seen


def _frame_checks(motions: Sequence[Any], robot: Any) -> list[Diagnostic]:
    out: list[Diagnostic] = []
    world = np.asarray(robot.base) @ np.asarray(robot.controller_base)
    for name, step in _first_use(motions, "frame").items():
        number = step.frame.number
        if number is not None and number > UFRAME_RANGE[1]:
            msg = f"frame {name!r} has number {number}: LS user frames are 1..{UFRAME_RANGE[1]}"
            out.append(_diag("error", "frame_number", msg, step))
        elif uframe_number(step.frame) > 0:
            values = ls_xyzwpr(inv(world) @ np.asarray(step.frame.pose))
            msg = f"positions use UFRAME[{number}] ({name!r}); the controller must hold it as "
            out.append(_diag("info", "controller_frame", msg + _spell(values), step))
    return out


def _tool_checks(motions: Sequence[Any], options: Mapping[str, Any] | None) -> list[Diagnostic]:
    out: list[Diagnostic] = []
    first = _first_use(motions, "tool")
    numbered = {t.tool.number for t in first.values() if t.tool.number is not None}
    unnumbered = [n for n, s in first.items() if s.tool.number is None and not is_flange(s.tool)]
    for name, step in first.items():
        number, ut = step.tool.number, utool_number(step.tool, options)
        values = _spell(ls_xyzwpr(step.tool.pose))
        if not UTOOL_RANGE[0] <= ut <= UTOOL_RANGE[1]:
            msg = f"tool {name!r} would be UTOOL {ut}: LS tool frames are 0..{UTOOL_RANGE[1]}"
            out.append(_diag("error", "tool_number", msg, step))
        elif number is None and ut > 0 and (len(unnumbered) > 1 or ut in numbered):
            msg = f"tool {name!r} has no number, and UTOOL {ut} cannot be its: " + (
                "another tool has that number"
                if ut in numbered
                else f"{len(unnumbered)} tools have no number"
            )
            out.append(_diag("error", "tool_number", msg, step))
        elif number is None and ut > 0:
            msg = f"tool {name!r} has no number: written as UTOOL {ut}, which must hold "
            out.append(_diag("warning", "tool_number", msg + values, step))
        elif ut > 0:
            msg = f"positions use UTOOL[{ut}] ({name!r}); the controller must hold it as "
            out.append(_diag("info", "controller_tool", msg + values, step))
    return out


def _joint_position_notes(motions: Sequence[Any], robot: Any) -> list[Diagnostic]:
    """Info per Cartesian target written in joint form (no CONFIG selects it alone)."""
    cartesian = [s for s in motions if _is_cartesian(s.instruction)]
    if not cartesian:
        return []
    joints = np.stack([np.asarray(s.joints, dtype=np.float64) for s in cartesian])
    out: list[Diagnostic] = []
    for step, config in zip(cartesian, selecting_configs(robot, joints), strict=True):
        if config is None:
            msg = (
                "Cartesian target written as joint values: no CONFIG selects the planned "
                "joints alone (an arm without CONFIG, a wrist singularity, or a J3 range "
                "holding two turns)"
            )
            out.append(_diag("info", "joint_position", msg, step))
    return out


def _is_cartesian(instruction: Any) -> bool:
    from olp.ir import CartesianTarget

    return isinstance(instruction.target, CartesianTarget)


def _spell(values: Sequence[str]) -> str:
    return " ".join(f"{k} {v}" for k, v in zip("XYZWPR", values, strict=True)) + " (mm, deg)"


def _diag(severity: Any, kind: str, message: str, step: Any) -> Diagnostic:
    return Diagnostic(severity, kind, message, step.instruction.span, step.index)


def _instruction_checks(index: int, ins: Any) -> list[Diagnostic]:
    kind = getattr(ins, "kind", "")
    if kind in ("set_output", "wait_input") and ins.index < 1:
        what = "DO" if kind == "set_output" else "DI"
        msg = f"{what}[{ins.index}]: Fanuc I/O numbers start at 1"
        return [Diagnostic("error", "io_range", msg, ins.span, index)]
    if kind == "call":
        if legal_name(ins.name) != ins.name.upper():
            msg = f"CALL {ins.name}: not a legal program name (A-Z, 0-9, _, a letter first)"
            return [Diagnostic("error", "bad_call", msg, ins.span, index)]
        bad = [a for a in ins.args if not _NUMBER.fullmatch(a.strip())]
        if bad:
            msg = f"CALL {ins.name}: argument {bad[0]!r} is not a number"
            return [Diagnostic("error", "bad_call", msg, ins.span, index)]
    return []


_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)")
