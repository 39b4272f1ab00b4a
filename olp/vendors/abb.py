"""ABB IRC5 (RAPID) conventions: quaternions, robtarget values, confdata, flange frame, names.

Used by frontends and the RAPID post alike; nothing else in olp knows these rules.

Sources
-------
* robtarget ``[[x, y, z], [q1, q2, q3, q4], [cf1, cf4, cf6, cfx], [eax_a, ..., eax_f]]``:
  positions in mm, orientation a unit quaternion with the scalar first (``q1 = w``), unused
  external axes ``9E+09``. ABB "Technical reference manual - RAPID Instructions, Functions and
  Data types", data types *robtarget*, *orient*, *confdata* (as summarised in the project's vendor
  notes). Pinned by ``tests/vendors/test_abb.py``.
* Quaternion from a rotation: Shepperd's method (S. W. Shepperd, "Quaternion from rotation
  matrix", J. Guidance and Control 1(3), 1978): the largest of ``4w², 4x², 4y², 4z²`` is read
  from the diagonal, the other components from off-diagonal sums, so 180° rotations (tool-down
  targets) are exact where the trace formula divides by ~0. ``q`` and ``-q`` are the same
  rotation; olp writes ``w > 0``, and for ``w = 0`` (180°) the first non-zero of x, y, z positive
  (:func:`canonical_quaternion`). That choice is olp's, not ABB's: the controller accepts either.
* confdata: ``cf1, cf4, cf6 = floor(angle / 90°)`` of axes 1, 4 and 6 (-45° gives -1);
  ``cfx = 4·(wrist centre behind axis 1) + 2·(wrist centre behind the lower arm) + 1·(axis 5
  negative)``. The cfx table (0: in front/in front/positive ... 7: behind/behind/negative) is
  the one of the RAPID reference manual, also reproduced in the public py-opw-kinematics
  repository (``AXIS_CONFIGURATION.md``). The geometric parts use olp's OPW branch flags
  (:mod:`olp.kinematics.configuration`); olp reads "wrist centre in front of the lower arm" as
  "on the forward side of the line through axes 2 and 3, in the plane of the arm" (the manual
  gives no formula: medium confidence). Exactly on a multiple of 90° the quadrant is the upper
  one (floor), pinned. ``ConfJ \\On`` / ``ConfL \\On`` make the controller honour confdata.
  confdata carries no turn for axes 2, 3 and 5; with ranges under 360° (every bundled ABB
  robot) those are unique anyway.
* Flange: ABB's tool0 has Z out of the flange, like the model's tool0, so :data:`FLANGE_IN_TOOL0`
  is the identity. Cross-check (test): at the calibration position (all axes 0) the IRB 120
  model puts tool0 at (374, 0, 630) mm with orientation [0.7071068, 0, 0.7071068, 0] = Ry(90°),
  the values RobotStudio shows for that robot's tool0 there (recalled from ABB material, not
  re-checked against a controller here: medium confidence).
* Identifiers: at most 32 characters, a letter first, then letters, digits and ``_``; RAPID's
  reserved words are not allowed (RAPID overview manual; the reserved-word list is from memory of
  that manual: medium confidence).

For the RAPID post (``posts/abb``), pinned by ``tests/posts/test_abb.py`` (every module it
produces passes the independent ``rapidchecker``) and its golden files; RAPID reference manual
(instructions and data types) as summarised in the project's vendor notes and as recalled, with
the confidence given:

* Module: ``MODULE name`` ... ``ENDMODULE``, data before routines, ``PROC main()`` the entry
  (program modules); two-space indentation and upper-case keywords as RobotStudio writes them;
  CRLF (RobotStudio's files; RAPID reads any line ending). High confidence.
* Data: ``PERS tooldata`` / ``PERS wobjdata`` (a move's tool and work object must be persistent,
  high confidence); targets, custom speed and zone data ``LOCAL CONST`` so that a part module's
  names never clash with another module's (medium confidence on local shadowing global names).
  ``tool0`` and ``wobj0`` are the predefined no-tool and world (high confidence).
* Predefined speeddata ``v5 .. v7000`` (:data:`PREDEFINED_SPEEDS`, each ``[v, 500, 5000,
  1000]``) and zonedata ``z0 .. z200`` (:data:`PREDEFINED_ZONES`): medium-high confidence.
* Moves: ``MoveAbsJ jointtarget\\NoEOffs, speed, zone, tool;`` for joint targets, ``MoveJ`` /
  ``MoveL`` / ``MoveC via, to`` with robtargets and ``\\WObj:=`` (left out for ``wobj0``).
  ``ConfJ \\On`` / ``ConfL \\On`` make the controller take the written confdata. Joint moves are
  limited by the speeddata's TCP speed: RAPID has no joint speed fraction (warned).
* ``SetDO signal, 0|1;``, ``WaitDI signal, 0|1;`` (I/O by configured signal name:
  :func:`rapid_signal`), ``WaitTime \\InPos, t;`` (the dwell starts once the robot stands
  still, like KRL's ``WAIT SEC``), ``Name args;`` procedure calls, ``!`` comments.
* Work objects are given in the controller's world frame, which on a delivered single-robot
  controller is the robot's base frame (post manifest ``frames_in: robot_base``).

Joint values are controller joints in rad (what the FlexPendant shows, in degrees).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.diagnostics import Diagnostic
from olp.geometry import (
    pose_from,
    rotation_from_quaternion,
)
from olp.ir import Configuration
from olp.kinematics.configuration import ArmModel, branch_flags, make_configuration, snap

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

FLANGE_IN_TOOL0: FloatArray = np.eye(4)
"""ABB's tool0 (Z out of the flange) is the model's tool0."""

QUADRANT = math.pi / 2
"""The unit of cf1, cf4 and cf6: a quarter turn (rad)."""

_SIGN_TOLERANCE = 1e-12
"""A quaternion component this small counts as zero for the sign rule (180° rotations)."""


# --------------------------------------------------------------------------------------------
# Orientation


def quaternion_from_rotation(rotation: ArrayLike) -> FloatArray:
    """Unit quaternions ``[w, x, y, z]`` (..., 4) of rotation matrices (..., 3, 3).

    Shepperd's method, exact at 180°; signs as :func:`canonical_quaternion`.
    """
    r = np.asarray(rotation, dtype=np.float64)
    m00, m11, m22 = r[..., 0, 0], r[..., 1, 1], r[..., 2, 2]
    # 4w², 4x², 4y², 4z² from the diagonal; the largest is far from 0 for every rotation.
    squares = np.stack(
        [1 + m00 + m11 + m22, 1 + m00 - m11 - m22, 1 - m00 + m11 - m22, 1 - m00 - m11 + m22],
        axis=-1,
    )
    a, b, c = r[..., 2, 1] - r[..., 1, 2], r[..., 0, 2] - r[..., 2, 0], r[..., 1, 0] - r[..., 0, 1]
    d, e, f = r[..., 0, 1] + r[..., 1, 0], r[..., 0, 2] + r[..., 2, 0], r[..., 1, 2] + r[..., 2, 1]
    # Row k is 4·q_k·q: the quaternion scaled by its k-th component.
    rows = np.stack(
        [
            np.stack([squares[..., 0], a, b, c], axis=-1),
            np.stack([a, squares[..., 1], d, e], axis=-1),
            np.stack([b, d, squares[..., 2], f], axis=-1),
            np.stack([c, e, f, squares[..., 3]], axis=-1),
        ],
        axis=-2,
    )
    k = np.argmax(squares, axis=-1)
    chosen = np.take_along_axis(rows, k[..., None, None], axis=-2)[..., 0, :]
    q = chosen / np.linalg.norm(chosen, axis=-1, keepdims=True)
    return canonical_quaternion(q)


def canonical_quaternion(quaternion: ArrayLike) -> FloatArray:
    """``q`` or ``-q`` (..., 4), whichever has ``w > 0``; when ``|w| <= 1e-12`` (a 180° rotation)
    the first of x, y, z that is not ~0 is made positive. Negative zeros become +0."""
    q = np.asarray(quaternion, dtype=np.float64)
    big = np.abs(q) > _SIGN_TOLERANCE
    first = np.argmax(big, axis=-1)
    lead = np.take_along_axis(q, first[..., None], axis=-1)
    return np.where(lead < 0, -q, q) + 0.0


def normalised_rounded(quaternion: ArrayLike, decimals: int) -> FloatArray:
    """Quaternions (..., 4) rounded to ``decimals`` and still of unit norm to that precision.

    Rounding four components independently leaves the norm up to ~2·10^-decimals off 1, which
    RAPID reports as an unnormalised orientation. So the three smaller components are rounded and
    the largest is recomputed from them (then rounded): the norm error drops to ~10^-decimals.
    The sign rule of :func:`canonical_quaternion` is applied to the rounded values.
    """
    q = np.asarray(quaternion, dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    rounded = np.round(q, decimals)
    largest = np.argmax(np.abs(q), axis=-1)[..., None]
    others = (
        np.sum(rounded**2, axis=-1, keepdims=True)
        - np.take_along_axis(rounded, largest, axis=-1) ** 2
    )
    value = np.copysign(
        np.sqrt(np.clip(1.0 - others, 0.0, None)), np.take_along_axis(q, largest, -1)
    )
    np.put_along_axis(rounded, largest, np.round(value, decimals), axis=-1)
    return canonical_quaternion(rounded)


def pose_to_robtarget(pose: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """robtarget ``trans`` (..., 3) in mm and ``rot`` (..., 4) ``[w, x, y, z]`` from poses
    (..., 4, 4) in metres."""
    t = np.asarray(pose, dtype=np.float64)
    return t[..., :3, 3] * 1000.0, quaternion_from_rotation(t[..., :3, :3])


def robtarget_to_pose(trans_mm: ArrayLike, rot: ArrayLike) -> FloatArray:
    """Poses (..., 4, 4) in metres from robtarget ``trans`` (..., 3) in mm and ``rot`` (..., 4)."""
    return pose_from(rotation_from_quaternion(rot), np.asarray(trans_mm, dtype=np.float64) / 1000)


# --------------------------------------------------------------------------------------------
# Configuration


def quadrant(angles: ArrayLike) -> IntArray:
    """``floor(angle / 90°)`` of angles (...,) in rad: -45° gives -1, 90° gives 1, -90° gives -1.

    Angles within 1e-12 rad of a multiple of 90° count as on it (:func:`snap`).
    """
    return np.floor(snap(angles, QUADRANT) / QUADRANT).astype(np.int64)


def confdata(model: ArmModel, joints: ArrayLike) -> IntArray:
    """``[cf1, cf4, cf6, cfx]`` (..., 4) of controller joints (..., 6) in rad.

    ``model``: OPW parameters or a robot (for the wrist-centre and elbow geometry of cfx).
    """
    q = np.asarray(joints, dtype=np.float64)
    flags = branch_flags(model, q)
    cfx = 4 * flags.back.astype(np.int64) + 2 * flags.down.astype(np.int64)
    cfx += flags.flip.astype(np.int64)
    return np.stack([quadrant(q[..., 0]), quadrant(q[..., 3]), quadrant(q[..., 5]), cfx], axis=-1)


def quadrant_range(cf: int) -> tuple[float, float]:
    """The joint range ``[cf·90°, (cf + 1)·90°)`` in rad that quadrant ``cf`` stands for."""
    return (cf * QUADRANT, (cf + 1) * QUADRANT)


def configuration_from_confdata(conf: ArrayLike) -> Configuration:
    """The :class:`olp.ir.Configuration` a confdata ``[cf1, cf4, cf6, cfx]`` asks for.

    cfx bit 2 is the shoulder ("back"), bit 1 the elbow ("down"), bit 0 the wrist ("flip": axis
    5 negative); cf1, cf4 and cf6 become the quarter-turn ranges of axes 1, 4 and 6.
    """
    values = np.asarray(conf)
    if values.shape != (4,) or not np.all(values == np.round(values)):
        raise ValueError(f"confdata: expected 4 integers [cf1, cf4, cf6, cfx], got {conf!r}")
    cf1, cf4, cf6, cfx = (int(v) for v in values)
    if not 0 <= cfx <= 7:
        raise ValueError(f"confdata: cfx must be 0..7, got {cfx}")
    ranges = (quadrant_range(cf1), None, None, quadrant_range(cf4), None, quadrant_range(cf6))
    return make_configuration(bool(cfx & 4), bool(cfx & 2), bool(cfx & 1), joint_ranges=ranges)


# --------------------------------------------------------------------------------------------
# Spelling for the RAPID post

POSITION_DECIMALS = 3
"""mm for robtarget positions (1 µm)."""
QUATERNION_DECIMALS = 9
"""Quaternion components, as RobotStudio writes them; a 1e-9 component error is ~2e-9 rad."""
AXIS_DECIMALS = 5
"""deg for jointtarget axis values."""
EXTERNAL_AXIS_UNUSED = "9E+09"
"""An unused external axis in robtarget and jointtarget."""

MAX_NAME_LENGTH = 32
"""RAPID identifiers: at most 32 characters."""

_RESERVED = """
ALIAS AND BACKWARD CASE CONNECT CONST DEFAULT DIV DO ELSE ELSEIF ENDFOR ENDFUNC ENDIF
ENDMODULE ENDPROC ENDRECORD ENDTEST ENDTRAP ENDWHILE ERROR EXIT FALSE FOR FROM FUNC GOTO
IF INOUT LOCAL MOD MODULE NOSTEPIN NOT NOVIEW OR PERS PROC RAISE READONLY RECORD RETRY
RETURN STEP SYSMODULE TEST THEN TO TRAP TRUE TRYNEXT UNDO VAR VIEWONLY WHILE WITH XOR
"""
RESERVED_WORDS = frozenset(_RESERVED.split())
"""RAPID reserved words (case-insensitive); from the RAPID overview manual, medium confidence."""


def _num(value: float, decimals: int) -> str:
    text = f"{float(value):.{decimals}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def rapid_pose(pose: ArrayLike) -> str:
    """``[[x,y,z],[q1,q2,q3,q4]]`` (mm, unit quaternion w first) from a pose (4, 4) in metres."""
    trans, rot = pose_to_robtarget(pose)
    quat = normalised_rounded(rot, QUATERNION_DECIMALS)
    xyz = ",".join(_num(v, POSITION_DECIMALS) for v in trans)
    return f"[[{xyz}],[{','.join(_num(v, QUATERNION_DECIMALS) for v in quat)}]]"


def rapid_confdata(conf: ArrayLike) -> str:
    """``[cf1,cf4,cf6,cfx]`` from four integers."""
    return "[" + ",".join(str(int(v)) for v in np.asarray(conf)) + "]"


def rapid_robtarget(pose: ArrayLike, conf: ArrayLike) -> str:
    """A robtarget value: pose (4, 4) in metres, confdata ``[cf1, cf4, cf6, cfx]``, no external
    axes."""
    extax = ",".join([EXTERNAL_AXIS_UNUSED] * 6)
    return f"[{rapid_pose(pose)[1:-1]},{rapid_confdata(conf)},[{extax}]]"


def rapid_jointtarget(joints: ArrayLike) -> str:
    """A jointtarget value ``[[j1,...,j6],[9E+09,...]]`` from controller joints (6,) in rad."""
    deg = np.degrees(np.asarray(joints, dtype=np.float64))
    extax = ",".join([EXTERNAL_AXIS_UNUSED] * 6)
    return f"[[{','.join(_num(v, AXIS_DECIMALS) for v in deg)}],[{extax}]]"


def legal_name(name: str) -> str:
    """A legal RAPID identifier: ASCII letters, digits and ``_``, a letter first (``P`` is put in
    front otherwise), at most 32 characters; a reserved word gets a trailing ``_``."""
    cleaned = "".join(ch if (ch.isascii() and (ch.isalnum() or ch == "_")) else "_" for ch in name)
    if not cleaned or not cleaned[0].isalpha():
        cleaned = "P" + cleaned
    cleaned = cleaned[:MAX_NAME_LENGTH]
    if cleaned.upper() in RESERVED_WORDS:
        cleaned = cleaned[: MAX_NAME_LENGTH - 1] + "_"
    return cleaned


def is_legal_name(name: str) -> bool:
    """True when ``name`` is already a legal RAPID identifier (:func:`legal_name` keeps it)."""
    return legal_name(name) == name


# --------------------------------------------------------------------------------------------
# Predefined data (RAPID reference manual, "speeddata" / "zonedata" / "tooldata" / "wobjdata",
# predefined data in the BASE system module; medium-high confidence, recalled from the manual)

NULL_TOOL_NAME = "tool0"
"""The predefined tool: TCP at the flange (tool0)."""
NULL_FRAME_NAME = "wobj0"
"""The predefined work object: the world frame (wobj0)."""

_SPEEDS_MM_S = """
5 10 20 30 40 50 60 80 100 150 200 300 400 500 600 800 1000 1500 2000 2500 3000 4000 5000 6000
7000
"""
PREDEFINED_SPEEDS = {float(v): f"v{v}" for v in _SPEEDS_MM_S.split()}
"""Predefined speeddata by TCP speed (mm/s). Each is ``[v_tcp, 500, 5000, 1000]``."""
SPEED_DEFAULTS = (500.0, 5000.0, 1000.0)
"""``v_ori`` (deg/s), ``v_leax`` (mm/s), ``v_reax`` (deg/s) of the predefined speeddata; olp's
custom speeddata use them where the program says nothing (no orientation speed limit)."""

PREDEFINED_ZONES = {
    0.3: "z0",
    **{float(r): f"z{r}" for r in (1, 5, 10, 15, 20, 30, 40, 50, 60, 80, 100, 150, 200)},
}
"""Predefined zonedata by TCP zone radius ``pzone_tcp`` (mm); ``fine`` is the exact stop."""

PREDEFINED_NAMES = frozenset(
    {"tool0", "wobj0", "load0", "fine", "vmax", *PREDEFINED_SPEEDS.values()}
    | set(PREDEFINED_ZONES.values())
)
"""Names the controller defines already: generated data never take them."""

TOOL_MASS_PLACEHOLDER = 0.001
"""kg, tool0's load mass: written when the station gives no mass (with a warning)."""


def _compact(value: float, decimals: int = 3) -> str:
    """Fixed-point with at most ``decimals``, trailing zeros (and a bare point) removed."""
    text = _num(value, decimals)
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return text


def speed_name(speed: Any) -> str:
    """The speeddata name of an :class:`olp.ir.Speed`: a predefined ``v100`` when the TCP speed
    is one of :data:`PREDEFINED_SPEEDS` and no orientation limit is set, else a custom name
    ``v21_17`` (mm/s, ``_`` for the point) or ``v100_o30`` (with ``v_ori`` 30 deg/s)."""
    mm_s = float(speed.linear) * 1000.0
    text = _compact(mm_s)
    if speed.angular is None:
        predefined = PREDEFINED_SPEEDS.get(float(text))
        if predefined is not None:
            return predefined
        return "v" + text.replace(".", "_")
    return f"v{text.replace('.', '_')}_o{_compact(math.degrees(speed.angular)).replace('.', '_')}"


def speeddata(speed: Any) -> str:
    """``[v_tcp, v_ori, v_leax, v_reax]`` of an :class:`olp.ir.Speed` (mm/s, deg/s)."""
    v_ori = SPEED_DEFAULTS[0] if speed.angular is None else math.degrees(speed.angular)
    values = [float(speed.linear) * 1000.0, v_ori, *SPEED_DEFAULTS[1:]]
    return "[" + ",".join(_compact(v) for v in values) + "]"


def zone_name(zone: Any) -> str:
    """The zonedata name of an :class:`olp.ir.Zone`: ``fine``, a predefined ``z10``, or a custom
    ``z12_5`` (radius in mm)."""
    if zone.is_fine:
        return "fine"
    text = _compact(float(zone.radius) * 1000.0)
    return PREDEFINED_ZONES.get(float(text), "z" + text.replace(".", "_"))


def zonedata(zone: Any) -> str:
    """A custom zonedata ``[FALSE, r, 1.5r, 1.5r, 0.15r, 1.5r, 0.15r]`` for a radius r (mm):
    pzone_tcp, pzone_ori, pzone_eax (mm), zone_ori (deg), zone_leax (mm), zone_reax (deg).
    The ratios are those of the predefined z10 .. z200 (olp's choice for other radii)."""
    r = float(zone.radius) * 1000.0
    values = [r, 1.5 * r, 1.5 * r, 0.15 * r, 1.5 * r, 0.15 * r]
    return "[FALSE," + ",".join(_compact(v) for v in values) + "]"


def context_values(steps: Any, options: Any = None) -> dict[str, list[dict[str, str]]]:
    """Post hook: the custom speeddata and zonedata one file's motions need, in order of first
    use: ``{"speeds": [{name, value}], "zones": [{name, value}]}``."""
    speeds: dict[str, str] = {}
    zones: dict[str, str] = {}
    for step in steps:
        if step.motion:
            name = speed_name(step.speed)
            if name not in PREDEFINED_NAMES:
                speeds.setdefault(name, speeddata(step.speed))
            zname = zone_name(step.zone)
            if zname not in PREDEFINED_NAMES:
                zones.setdefault(zname, zonedata(step.zone))
    return {
        "speeds": [{"name": k, "value": v} for k, v in speeds.items()],
        "zones": [{"name": k, "value": v} for k, v in zones.items()],
    }


def step_values(robot: ArmModel, joints: ArrayLike, options: Any = None) -> list[dict[str, Any]]:
    """Post hook: the confdata ``(cf1, cf4, cf6, cfx)`` of each motion's planned joints (N, 6)."""
    conf = confdata(robot, np.asarray(joints, dtype=np.float64))
    return [{"confdata": tuple(int(v) for v in row)} for row in conf.tolist()]


def rapid_tooldata(tool: Any) -> str:
    """A tooldata value ``[TRUE,[[x,y,z],[q]],[mass,[cog],[1,0,0,0],0,0,0]]`` for a
    :class:`olp.post.PostTool`: held by the robot, TCP in tool0 (mm, quaternion); the load is the
    station's mass (or :data:`TOOL_MASS_PLACEHOLDER`) with the centre of gravity 1 mm along the
    flange axis, as tool0 has it (the station gives none)."""
    mass = tool.mass if tool.mass else TOOL_MASS_PLACEHOLDER
    return f"[TRUE,{rapid_pose(tool.pose)},[{_compact(mass)},[0,0,0.001],[1,0,0,0],0,0,0]]"


def rapid_wobjdata(frame: Any) -> str:
    """A wobjdata value ``[FALSE,TRUE,"",[[uf],[q]],[[0,0,0],[1,0,0,0]]]`` for a
    :class:`olp.post.PostFrame`: not held by the robot, fixed user frame = the frame's pose in the
    controller's reference, object frame = the user frame."""
    return f'[FALSE,TRUE,"",{rapid_pose(frame.pose)},[[0,0,0],[1,0,0,0]]]'


def rapid_signal(index: int, pattern: str) -> str:
    """The name of digital signal ``index`` from a pattern such as ``"do{index}"`` (RAPID I/O is
    by signal name, configured on the controller; a post option sets the pattern)."""
    from olp.errors import PostError

    name = pattern.format(index=index)
    if not is_legal_name(name):
        raise PostError(f"signal name {name!r} (from {pattern!r}) is not a legal RAPID name")
    return name


def _robtarget_filter(joints: ArrayLike, robot: ArmModel, pose: ArrayLike) -> str:
    """Template filter: ``joints | rapid_robtarget(robot, pose)``."""
    return rapid_robtarget(pose, confdata(robot, joints))


def _confdata_filter(joints: ArrayLike, robot: ArmModel) -> str:
    """Template filter: ``joints | rapid_confdata(robot)``."""
    return rapid_confdata(confdata(robot, joints))


TEMPLATE_FILTERS = {
    "rapid_pose": rapid_pose,
    "rapid_robtarget": _robtarget_filter,
    "rapid_jointtarget": rapid_jointtarget,
    "rapid_confdata": _confdata_filter,
    "rapid_robtarget_value": rapid_robtarget,
    "rapid_tooldata": rapid_tooldata,
    "rapid_wobjdata": rapid_wobjdata,
    "rapid_speed": speed_name,
    "rapid_zone": zone_name,
    "rapid_signal": rapid_signal,
}


def post_diagnostics(compiled: Any, options: Any = None) -> list[Diagnostic]:
    """What the RAPID post cannot say exactly.

    * ``joint_speed`` (warning): RAPID has no joint speed as a fraction of the axes' maximum;
      MoveJ/MoveAbsJ run limited by the speeddata's TCP and orientation speeds, which olp takes
      from the motion's linear speed (RAPID reference, MoveJ: "speed data ... for the tool
      centre point, the tool reorientation and external axes").
    * ``tool_load`` (warning, once per tool): the tooldata's load is a placeholder (no mass or
      centre of gravity in the station).
    * ``name`` (error): a call of a routine whose name is not a legal RAPID name.
    """
    out: list[Diagnostic] = []
    loads: set[str] = set()
    for step in compiled.steps:
        ins = step.instruction
        kind = getattr(ins, "kind", None)
        if kind == "call" and not is_legal_name(ins.name):
            message = f"call of {ins.name!r}: not a legal RAPID name (letters, digits, _; 32 max)"
            out.append(Diagnostic("error", "name", message, ins.span, step.index))
        if kind not in ("joint", "linear", "circular") or step.skipped or step.tool is None:
            continue
        if kind == "joint" and ins.speed.joint < 1.0:
            out.append(_joint_speed_warning(step.index, ins))
        if not np.array_equal(step.tool.pose, np.eye(4)) and step.tool.name not in loads:
            loads.add(step.tool.name)
            body = compiled.station.tool_bodies.get(step.tool.name)
            out.append(_load_warning(step.index, ins, step.tool.name, body))
    return out


def _joint_speed_warning(index: int, ins: Any) -> Diagnostic:
    return Diagnostic(
        "warning",
        "joint_speed",
        f"RAPID cannot limit a joint move to {ins.speed.joint * 100:.0f} % of the axis speeds: "
        f"it runs limited by the TCP speed {speed_name(ins.speed)} instead",
        ins.span,
        index,
        hint="set the linear speed of joint moves to what the robot may reach",
    )


def _load_warning(index: int, ins: Any, name: str, body: Any) -> Diagnostic:
    mass = None if body is None else body.mass
    what = "no mass" if not mass else f"mass {mass:g} kg but no centre of gravity"
    return Diagnostic(
        "warning",
        "tool_load",
        f"tool {name!r}: the station gives {what}; its tooldata load is a placeholder",
        ins.span,
        index,
        hint="identify the load on the controller (LoadIdentify) or enter it before running",
    )
