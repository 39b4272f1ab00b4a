"""Universal Robots (URScript) conventions: rotation vectors, pose values, flange frame, names.

Used by frontends and the URScript post alike; nothing else in olp knows these rules.

Sources
-------
* Poses ``p[x, y, z, rx, ry, rz]``: metres and a rotation vector (unit axis times angle, rad) in
  the controller's Base frame (URScript manual, ``p[...]`` pose literals; project vendor notes).
  :func:`rotvec_from_rotation` reuses :func:`olp.geometry.rotation_log`, which is exact at 180°
  (where ``angle / (2 sin angle)`` divides by zero, the classic rotation-vector crash): there
  ``v`` and ``-v`` are the same rotation, and olp writes the one whose largest component is
  positive (olp's choice; the controller accepts either). Angles lie in [0, pi].
* Flange: the URDFs of Universal Robots' ROS descriptions (``ur_macro.xacro``) name ``tool0``
  the "all-zeros tool frame", matching the controller's tool flange frame (TCP with a zero
  offset, Z out of the flange); olp's model tool0 is that frame, so :data:`FLANGE_IN_TOOL0` is
  the identity. (The same files put the controller's Base frame at ``base``, ``base_link``
  turned 180° about Z; the UR kinematics must report tool0 in that frame.)
* Configuration: URScript has no configuration bits. For ``movel``/``movep``/``movec`` and for
  ``movej`` given a pose, the controller picks the IK solution nearest to the current joints
  (URScript manual on ``movej`` with a pose; paraphrased, not re-checked). Consequences for
  olp: a joint move is written with the planned joint values (``movej([q1, ..., q6])``), never
  with a pose, so the planned branch and turn are what runs; a linear move needs no
  configuration because it continues from the joints the previous move ended in, which resolve
  already checked stay in one branch.
* Program (``def``) names: letters, digits and ``_``, a letter first, not a keyword (Python-like
  syntax; the exact rules and any length limit are unverified).

The URScript post (``posts/ur``)
--------------------------------
* A program is one ``def name():`` ... ``end`` block, body indented by two spaces, ``#``
  comments, LF line endings, file ``name.script`` (project vendor notes: sent as plain text to
  port 30002, which runs the ``def``; medium confidence that nothing else is needed).
* ``movej([q1..q6], a, v, r)``: the planned joints (rad), never a pose (see Configuration).
  ``v`` (rad/s) is the speed of the leading axis (URScript manual, ``movej``); olp writes
  ``Speed.joint`` (a fraction of each axis' maximum) times the *smallest* axis velocity limit of
  the station's robot (:func:`movej_speed`): at 100 % the leading axis may then run at the
  slowest axis' maximum, so no axis exceeds its own. ``a`` (rad/s²) is URScript's documented
  default 1.4 rad/s² times ``Speed.joint_acceleration`` (:func:`movej_acceleration`): UR
  publishes no joint acceleration limits, and olp's timing uses the station's limits, which
  may therefore differ from the controller's motion.
* ``movel(p[...], a, v, r)`` / ``movec(p_via, p_to, a, v, r, mode=0)``: the TCP pose in the
  robot's Base frame: the post's manifest says ``frames_in: robot_base``, so the template's
  ``base_pose`` is the target in ``station base · controller_base`` (for UR arms the kinematic
  base *is* the controller's Base, DH frame 0, see :mod:`olp.kinematics.ur`; the target equals
  forward kinematics of the planned joints, which resolve solved for it), and olp's user frames
  need no counterpart on the controller. ``v`` = ``Speed.linear`` (m/s), ``a`` = URScript's default
  1.2 m/s² (the IR has no linear acceleration). ``mode=0``: orientation interpolated from the
  start to the end pose, like KRL's default CIRC (URScript manual, ``movec``; medium
  confidence).
* ``r`` (m): the zone radius capped by :mod:`olp.transforms.blend` (neighbouring blends must not
  overlap, ``r = 0`` where the robot stops; project vendor notes).
* ``set_tcp(p[...])``: the tool's TCP in the flange frame, before the first motion with it.
* ``set_digital_out(n, b)``, ``get_digital_in(n)`` polled with ``sync()`` for an input wait,
  ``sleep(s)``: the issue's and the vendor notes' spelling; output and input numbers 0..9
  (CB3 manual; e-Series controllers also offer ``set_standard_digital_out`` 0..7 and keep these
  as deprecated aliases; medium confidence). The IR's I/O number is written unchanged.
* Calls: ``name(args)``; the function must exist on the controller (e.g. in the installation's
  script). Arguments must be numbers or double-quoted strings.
* Very long scripts fail on the controller (field reports between ~1,000 and 2,500 targets):
  above :data:`MAX_MOTIONS` motions a warning asks for splitting or streaming.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.diagnostics import Diagnostic
from olp.geometry import pose_from, rotation_exp, rotation_log

FloatArray = NDArray[np.float64]

FLANGE_IN_TOOL0: FloatArray = np.eye(4)
"""UR's tool flange frame (Z out) is the model's tool0."""

HAS_CONFIGURATION = False
"""URScript carries no configuration bits: joint moves are written as joint targets."""

_AT_PI = 1e-12
"""A rotation angle this close to pi is exactly 180° for the sign rule."""


def rotvec_from_rotation(rotation: ArrayLike) -> FloatArray:
    """Rotation vectors (..., 3) (axis times angle in [0, pi], rad) of rotations (..., 3, 3).

    At exactly 180° the vector with a positive largest component is returned.
    """
    v = rotation_log(rotation)
    angle = np.linalg.norm(v, axis=-1, keepdims=True)
    largest = np.take_along_axis(v, np.argmax(np.abs(v), axis=-1)[..., None], axis=-1)
    flip = (angle > np.pi - _AT_PI) & (largest < 0)
    return np.where(flip, -v, v) + 0.0


def rotation_from_rotvec(rotvec: ArrayLike) -> FloatArray:
    """Rotation matrices (..., 3, 3) from rotation vectors (..., 3) in rad (any length)."""
    return rotation_exp(rotvec)


def pose_to_ur(pose: ArrayLike) -> FloatArray:
    """``[x, y, z, rx, ry, rz]`` (..., 6), metres and rad, from poses (..., 4, 4) in metres."""
    t = np.asarray(pose, dtype=np.float64)
    return np.concatenate([t[..., :3, 3], rotvec_from_rotation(t[..., :3, :3])], axis=-1)


def ur_to_pose(values: ArrayLike) -> FloatArray:
    """Poses (..., 4, 4) in metres from ``[x, y, z, rx, ry, rz]`` (..., 6), metres and rad."""
    v = np.asarray(values, dtype=np.float64)
    return pose_from(rotation_from_rotvec(v[..., 3:6]), v[..., :3])


# --------------------------------------------------------------------------------------------
# Spelling for the URScript post

POSITION_DECIMALS = 6
"""m: 1 µm."""
ANGLE_DECIMALS = 6
"""rad, for rotation vectors and joints: 1e-6 rad is 1 µm at 1 m."""

_KEYWORDS = """
def end if elif else while for return thread run kill halt break continue pass global local
and or not xor True False
"""
KEYWORDS = frozenset(_KEYWORDS.split())
"""URScript words a program name must not be (Python-like; unverified list)."""

POST_BUILTINS = frozenset(
    ["movej", "movel", "movec", "set_tcp", "set_digital_out", "get_digital_in", "sleep", "sync"]
)
"""URScript functions the post calls: a program of the same name would shadow them."""


def _num(value: float, decimals: int) -> str:
    text = f"{float(value):.{decimals}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def ur_pose(pose: ArrayLike) -> str:
    """``p[x, y, z, rx, ry, rz]`` from a pose (4, 4) in metres."""
    v = pose_to_ur(pose)
    values = [_num(x, POSITION_DECIMALS) for x in v[:3]] + [_num(x, ANGLE_DECIMALS) for x in v[3:]]
    return "p[" + ", ".join(values) + "]"


def ur_joints(joints: ArrayLike) -> str:
    """``[q1, ..., q6]`` in rad (the ``movej`` joint target) from controller joints (6,) in rad."""
    return "[" + ", ".join(_num(x, ANGLE_DECIMALS) for x in np.asarray(joints, float)) + "]"


def legal_name(name: str) -> str:
    """A legal ``def`` name: ASCII letters, digits and ``_``, a letter first (``p`` is put in front
    otherwise); a keyword, or a function the post calls (:data:`POST_BUILTINS`), gets a
    trailing ``_``."""
    cleaned = "".join(ch if (ch.isascii() and (ch.isalnum() or ch == "_")) else "_" for ch in name)
    if not cleaned or not cleaned[0].isalpha():
        cleaned = "p" + cleaned
    return cleaned + "_" if cleaned in KEYWORDS | POST_BUILTINS else cleaned


# --------------------------------------------------------------------------------------------
# Motion parameters and checks for the URScript post

MOVEJ_ACCELERATION = 1.4
"""rad/s², URScript's ``movej`` default: ``a`` at 100 % joint acceleration."""
MOVEL_ACCELERATION = 1.2
"""m/s², URScript's ``movel``/``movec`` default."""
SPEED_DECIMALS = 5
"""m/s, rad/s, m/s², rad/s²: 10 µm/s resolution."""
RADIUS_DECIMALS = 6
"""m, blend radii: 1 µm."""
TIME_DECIMALS = 3
"""s, ``sleep``: 1 ms."""
IO_RANGE = (0, 9)
"""Digital output and input numbers ``set_digital_out``/``get_digital_in`` take (CB3 manual)."""
MAX_MOTIONS = 1000
"""Motions in one script above which a warning asks for splitting or streaming (field reports of
trouble between ~1,000 and 2,500 targets; low confidence on the exact limit)."""

_LITERAL = re.compile(r'[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?|"[^"\\\n]*"')


def _speed(value: float) -> str:
    return _num(value, SPEED_DECIMALS)


def movej_speed(speed: Any, robot: Any) -> str:
    """``v`` of ``movej`` in rad/s: ``speed.joint`` times the smallest axis velocity limit."""
    return _speed(speed.joint * float(np.min(robot.limits.velocity)))


def movej_acceleration(speed: Any) -> str:
    """``a`` of ``movej`` in rad/s²: 1.4 rad/s² times ``speed.joint_acceleration``."""
    return _speed(speed.joint_acceleration * MOVEJ_ACCELERATION)


def movel_acceleration(_speed_value: Any = None) -> str:
    """``a`` of ``movel``/``movec`` in m/s²: URScript's default."""
    return _speed(MOVEL_ACCELERATION)


def linear_speed(speed: Any) -> str:
    """``v`` of ``movel``/``movec`` in m/s: ``speed.linear``."""
    return _speed(speed.linear)


def radius(value: float) -> str:
    """A blend radius in metres (6 decimals)."""
    return _num(value, RADIUS_DECIMALS)


def seconds(value: float) -> str:
    """A ``sleep`` time in seconds (3 decimals)."""
    return _num(value, TIME_DECIMALS)


def _via_filter(step: Any) -> str:
    """Template filter: ``s | ur_via``, the ``p[...]`` of a circle's via point in the robot's
    Base frame (the post's ``frames_in: robot_base`` makes ``frame_pose`` relative to it)."""
    return ur_pose(np.asarray(step.frame_pose) @ np.asarray(step.via))


def _blends_filter(steps: Any, station: Any) -> dict[int, float]:
    """Template filter: ``steps | ur_blend_radii(station)``, instruction index -> capped blend
    radius in m (:func:`olp.transforms.blend.blend_radii`, from the robot's home joints, where
    resolve starts)."""
    from olp.transforms.blend import blend_radii

    robot = station.robot
    return {c.index: c.radius for c in blend_radii(steps, robot, robot.home)}


def _comment(text: str) -> str:
    return " ".join(str(text).split())


TEMPLATE_FILTERS = {
    "ur_pose": ur_pose,
    "ur_joints": ur_joints,
    "ur_via": _via_filter,
    "ur_blend_radii": _blends_filter,
    "ur_movej_v": movej_speed,
    "ur_movej_a": movej_acceleration,
    "ur_movel_v": linear_speed,
    "ur_movel_a": movel_acceleration,
    "ur_radius": radius,
    "ur_seconds": seconds,
    "ur_comment": _comment,
}


def post_diagnostics(compiled: Any, options: Any = None) -> list[Diagnostic]:
    """What the URScript post reports about a compiled program: capped blend radii (warnings),
    a robot of another brand (warning), I/O numbers out of range and calls URScript cannot spell
    (errors), a script too long for the controller (warning)."""
    from olp.transforms.blend import cap_blends

    out = list(cap_blends(compiled)[1])
    out += foreign_robot(compiled, "ur", "URScript")
    for step in compiled.steps:
        out += _instruction_checks(step.index, step.instruction)
    motions = sum(1 for s in compiled.steps if s.joints is not None)
    if motions > MAX_MOTIONS:
        out.append(
            Diagnostic(
                "warning",
                "program_too_long",
                f"{motions} motions in one script: UR controllers are reported to fail on "
                f"scripts beyond about {MAX_MOTIONS} targets",
                hint="split the program or stream it to the controller",
            )
        )
    return out


def _instruction_checks(index: int, ins: Any) -> list[Diagnostic]:
    kind = getattr(ins, "kind", "")
    if kind in ("set_output", "wait_input") and not IO_RANGE[0] <= ins.index <= IO_RANGE[1]:
        what = "output" if kind == "set_output" else "input"
        msg = f"digital {what} {ins.index} is outside URScript's range {IO_RANGE[0]}..{IO_RANGE[1]}"
        return [Diagnostic("error", "io_range", msg, ins.span, index)]
    if kind == "call":
        return _call_checks(index, ins)
    return []


def _call_checks(index: int, ins: Any) -> list[Diagnostic]:
    if legal_name(ins.name) != ins.name:
        msg = f"call of {ins.name!r}: not a legal URScript function name"
        return [Diagnostic("error", "bad_call", msg, ins.span, index)]
    bad = [a for a in ins.args if not _LITERAL.fullmatch(a.strip())]
    if bad:
        msg = f"call of {ins.name}: argument {bad[0]!r} is not a number or a string literal"
        return [Diagnostic("error", "bad_call", msg, ins.span, index)]
    return []


def foreign_robot(compiled: Any, vendor: str, language: str) -> list[Diagnostic]:
    """A warning when the station's robot is not of ``vendor``: the post then writes that
    robot's joints and poses in ``language``, which no controller of ``vendor`` can run as
    planned (the transpiling path is: compile on a station with the target robot)."""
    robot = compiled.station.robot
    if robot.vendor == vendor:
        return []
    return [
        Diagnostic(
            "warning",
            "foreign_robot",
            f"the station's robot is a {robot.name} ({robot.vendor}): the {language} written "
            f"holds that robot's joints and poses",
            hint=f"to run it, compile on a station with a {vendor} robot",
        )
    ]
