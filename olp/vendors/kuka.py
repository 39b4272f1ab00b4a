"""KUKA KR C4 (KSS 8) conventions: ABC angles, FRAME values, flange frame, Status and Turn.

Used by the KRL frontend and the KUKA post alike; nothing else in olp knows these rules.

Sources
-------
* ABC: ``R = Rz(A) · Ry(B) · Rx(C)`` (intrinsic Z, Y', X''), angles in degrees, positions in mm.
  KUKA System Software 8 operating and programming instructions, "BASE/TOOL coordinate system";
  also how ROS-Industrial's kuka_rsi driver converts ABC. Pinned by ``tests/vendors/test_kuka.py``.
* Flange frame: KUKA's FLANGE frame has X pointing out of the mounting flange. The kinematic
  models in olp use the ROS-Industrial ``tool0`` convention (Z out of the flange). The
  ROS-Industrial KUKA descriptions (kuka_experimental, e.g. ``kr6r900sixx_macro.xacro``) attach
  ``tool0`` to ``link_6`` (= KUKA's flange) with ``rpy = (0, 90°, 0)``; hence
  ``flange = tool0 · Ry(-90°)``, :data:`FLANGE_IN_TOOL0`.
* Turn (T): bit ``i`` is set when axis ``A(i+1) < 0``; exactly 0 gives 0.
* Status (S): see :func:`status_bits` (bit 0 overhead, bit 1 A3 position, bit 2 A5 < 0).
  Status and Turn only matter for PTP motions; LIN/CIRC ignore them on the controller.
* Status/Turn and :class:`olp.ir.Configuration` (:func:`configuration_from_status_turn`,
  :func:`status_turn`): S bit 0 is the "back" shoulder, bit 1 the "up" elbow (olp's OPW elbow
  flag: ``A3 >= atan(|a2| / c3)`` is the wrist centre in front of the lower arm), bit 2 the
  "flip" wrist (A5 < 0). T bit i asks for A(i+1) in (-inf, 0), a clear bit for [0, inf). T only
  tells a joint's turn apart where the joint's range lies within (-360°, 360°) (KUKA A4 ±185°
  and A6 ±350° do): over a wider range two turns of the same sign both fit, and the post then
  writes the PTP with axis values (:func:`turn_ambiguous`).

For the KRL post (``posts/kuka``), pinned by ``tests/posts/test_kuka.py`` and its golden files:

* Module: ``&ACCESS RVP`` / ``&REL 1`` header, ``DEF name( )`` ... ``END`` in ``name.src`` and
  ``DEFDAT name PUBLIC`` ... ``ENDDAT`` in ``name.dat``; the module name is the file name
  (:func:`legal_name`: letters, digits, ``_``, 24 characters, not a keyword; the length is widely
  cited, unverified). CRLF line endings, ASCII (WorkVisual and the pendant write CRLF).
* The INI fold ``;FOLD INI;%{PE}`` with ``BASISTECH INI`` (``GLOBAL INTERRUPT DECL 3 WHEN
  $STOPMESS==TRUE DO IR_STOPM ( )``, ``INTERRUPT ON 3``, ``BAS (#INITMOV,0 )``) and ``USER INI``:
  the KSS 8 new-module template, as found verbatim in several public KR C4 programs (high
  confidence).
* Targets: ``E6POS`` ``{X,Y,Z,A,B,C,S,T}`` (mm, deg, S and T decimal as the pendant writes them
  in .dat files) for Cartesian targets, ``E6AXIS`` ``{A1..A6}`` (deg) for joint targets; inline
  aggregates or named points ``DECL E6POS XP1={..}`` in the .dat (the pendant's naming);
  ``CIRC aux, end``. External axes E1..E6 are not written (project vendor notes).
* ``$TOOL``/``$BASE``: ``{FRAME: ..}`` or ``TOOL_DATA[1..16]``/``BASE_DATA[1..32]`` (the arrays of
  ``$config.dat``); ``$NULLFRAME`` for no tool / the world. ``$BASE`` is relative to ``$WORLD``.
* Speeds: ``$VEL.CP`` in m/s, ``$VEL.ORI1``/``$VEL.ORI2`` in deg/s, ``$VEL_AXIS[i]``/
  ``$ACC_AXIS[i]`` in whole percent 1..100 (:data:`VEL_AXIS_MIN_PERCENT`, medium confidence);
  approximation ``C_DIS`` with ``$APO.CDIS`` (mm), ``C_PTP`` with ``$APO.CPTP`` (%).
* ``$OUT[n] = TRUE``, ``WAIT SEC t``, ``WAIT FOR $IN[n]``, ``name(args)`` (project vendor notes;
  the forms KUKA's inline forms produce).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.diagnostics import Diagnostic
from olp.geometry import pose_from, rotation_from_zyx, roty, zyx_from_rotation
from olp.ir import CartesianTarget, Configuration
from olp.kinematics.configuration import (
    SNAP,
    ArmModel,
    make_configuration,
    opw_parameters,
    wrist_x,
)

FloatArray = NDArray[np.float64]

ZERO = SNAP
"""rad (and m for the wrist-centre x): values this close to 0 count as 0 for the sign tests of
Status and Turn (:data:`olp.kinematics.configuration.SNAP`, far below any written precision)."""

FLANGE_IN_TOOL0: FloatArray = roty(-math.pi / 2)
"""KUKA's flange frame (X out of the flange) expressed in the model's tool0 frame (Z out)."""


def abc_to_rotation(a: ArrayLike, b: ArrayLike, c: ArrayLike) -> FloatArray:
    """Rotation matrices (..., 3, 3) from KUKA A, B, C in **radians**: ``Rz(A) Ry(B) Rx(C)``."""
    return rotation_from_zyx(a, b, c)


def rotation_to_abc(rotation: ArrayLike) -> FloatArray:
    """KUKA (A, B, C) in radians, shape (..., 3), from rotation matrices (..., 3, 3).

    A and C lie in (-pi, pi] (so -180° is written as 180°), B in [-pi/2, pi/2]. At gimbal lock
    (B = ±90°) A and C are not unique; olp then writes C = 0 and puts the rotation into A.
    """
    return zyx_from_rotation(rotation)


def frame_to_pose(xyzabc: ArrayLike) -> FloatArray:
    """Poses (..., 4, 4) in metres from KRL values ``X, Y, Z`` (mm) and ``A, B, C`` (deg)."""
    v = np.asarray(xyzabc, dtype=np.float64)
    rot = abc_to_rotation(*np.radians(np.moveaxis(v[..., 3:6], -1, 0)))
    return pose_from(rot, v[..., :3] / 1000.0)


def pose_to_frame(pose: ArrayLike) -> FloatArray:
    """KRL ``X, Y, Z`` (mm) and ``A, B, C`` (deg), shape (..., 6), from poses (..., 4, 4) in m."""
    t = np.asarray(pose, dtype=np.float64)
    abc = np.degrees(rotation_to_abc(t[..., :3, :3]))
    return np.concatenate([t[..., :3, 3] * 1000.0, abc], axis=-1)


def turn_bits(joints: ArrayLike) -> NDArray[np.int64]:
    """KUKA Turn (T) from controller joint values (..., n) in radians: bit i set if A(i+1) < 0.

    Exactly 0 gives 0, and so does anything within :data:`ZERO` of it: IK returns an axis that
    is 0 in exact arithmetic (A4 of a tool-down target) as ±1e-17, and T must not depend on
    that rounding.
    """
    q = np.asarray(joints, dtype=np.float64)
    weights = 1 << np.arange(q.shape[-1], dtype=np.int64)
    return np.sum((q < -ZERO) * weights, axis=-1)


def status_bits(
    joints: ArrayLike, wrist_x_in_a1: ArrayLike, a3_threshold: float
) -> NDArray[np.int64]:
    """KUKA Status (S) from controller joints (..., 6) in radians.

    Bit 0: overhead area, the wrist centre has x < 0 in the frame that rotates with A1
    (``wrist_x_in_a1``, metres). Bit 1: set when ``A3 >= a3_threshold`` (rad; the angle at which
    the A3/A4 offset puts the wrist centre on the line of the upper arm; 0 when the axes
    intersect). Bit 2: set when ``A5 < 0``. Bits 3 and 4 are written as 0.
    Values within :data:`ZERO` of 0 (wrist-centre x, A5) count as 0, as in :func:`turn_bits`.

    Confidence: bits 0 and 2 match the KSS documentation and taught points from a public KR C4
    backup; the bit 1 threshold is derived from the geometry, not quoted from KUKA (unverified).
    """
    q = np.asarray(joints, dtype=np.float64)
    overhead = np.asarray(wrist_x_in_a1) < -ZERO
    elbow = q[..., 2] >= a3_threshold
    flip = q[..., 4] < -ZERO
    return overhead.astype(np.int64) + 2 * elbow.astype(np.int64) + 4 * flip.astype(np.int64)


def a3_threshold(model: ArmModel) -> float:
    """Controller A3 (rad) at which Status bit 1 changes: the A3 that puts the wrist centre on
    the line of the lower arm, ``offset3 - atan2(a2, c3)`` = ``atan(|a2| / c3)`` in KUKA's
    convention (0 when axes 3 and 4 intersect).

    ``model``: OPW parameters or a robot. Derived from the geometry as VENDOR-NOTES give it, not
    quoted from KUKA (unverified per model). Only defined for an A3 sign of +1 (KUKA's).
    """
    params = opw_parameters(model)
    if params.signs[2] != 1:
        raise ValueError("a3_threshold: Status bit 1 is defined for KUKA's A3 convention (sign +1)")
    return params.offsets[2] - math.atan2(params.a2, params.c3)


def status_from_joints(model: ArmModel, joints: ArrayLike) -> NDArray[np.int64]:
    """KUKA Status (S) (...,) of controller joints (..., 6) in rad on ``model`` (OPW parameters
    or a robot): :func:`status_bits` with the wrist-centre x and A3 threshold of the arm."""
    q = np.asarray(joints, dtype=np.float64)
    return status_bits(q, wrist_x(model, q), a3_threshold(model))


def status_turn(model: ArmModel, joints: ArrayLike) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """KUKA Status and Turn (each (...,)) of controller joints (..., 6) in rad."""
    return status_from_joints(model, joints), turn_bits(joints)


def configuration_from_status_turn(status: int, turn: int, axes: int = 6) -> Configuration:
    """The :class:`olp.ir.Configuration` a KRL ``S``/``T`` pair asks for.

    S bit 0: shoulder "back"; bit 1: elbow "up" (clear: "down"); bit 2: wrist "flip"; bits 3
    and 4 are ignored. T bit i: A(i+1) in (-inf, 0) when set, [0, inf) when clear.
    """
    if not 0 <= status < 32 or not 0 <= turn < (1 << axes):
        raise ValueError(f"KUKA S/T out of range: S {status}, T {turn} ({axes} axes)")
    ranges = tuple((-math.inf, 0.0) if turn >> i & 1 else (0.0, math.inf) for i in range(axes))
    return make_configuration(
        bool(status & 1), not status & 2, bool(status & 4), joint_ranges=ranges
    )


# --------------------------------------------------------------------------------------------
# Spelling for the KRL post (templates call these as filters)

POSITION_DECIMALS = 3
"""mm; KRL positions as the pendant writes them (1 µm)."""
ANGLE_DECIMALS = 4
"""deg for A, B, C (at 1 m, 0.0001° is 1.7 µm)."""
AXIS_DECIMALS = 5
"""deg for A1..A6, as in programs written by KUKA's own tools."""

MAX_NAME_LENGTH = 24
"""KRL identifiers and module names: 24 characters (widely cited; unverified against KUKA docs)."""


def _num(value: float, decimals: int) -> str:
    text = f"{float(value):.{decimals}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def krl_frame(pose: ArrayLike) -> str:
    """``X 1.000,Y 2.000,Z 3.000,A 0.0000,B 90.0000,C 0.0000`` from a pose (4, 4) in metres."""
    x, y, z, a, b, c = pose_to_frame(pose)
    values = [_num(v, POSITION_DECIMALS) for v in (x, y, z)]
    values += [_num(v, ANGLE_DECIMALS) for v in (a, b, c)]
    return ",".join(f"{k} {v}" for k, v in zip("XYZABC", values, strict=True))


def krl_axis(joints: ArrayLike) -> str:
    """``A1 0.00000,A2 -90.00000,...`` from controller joint values (6,) in radians."""
    deg = np.degrees(np.asarray(joints, dtype=np.float64))
    return ",".join(f"A{i + 1} {_num(v, AXIS_DECIMALS)}" for i, v in enumerate(deg))


_KEYWORDS = """
AND ANIN ANOUT B_AND B_EXOR B_NOT B_OR BOOL BRAKE C_DIS C_ORI C_PTP C_VEL CASE CHAR CIRC
CIRC_REL CONST CONTINUE DECL DEF DEFAULT DEFDAT DEFFCT DELAY DO ELSE END ENDDAT ENDFCT ENDFOR
ENDIF ENDLOOP ENDSWITCH ENDWHILE ENUM EXIT EXOR EXT EXTFCT FALSE FOR GLOBAL GOTO HALT IF IMPORT
INT INTERRUPT IS LIN LIN_REL LOOP MAXIMUM MINIMUM NOT OR PRIO PTP PTP_REL PUBLIC REAL REPEAT
RESUME RETURN SEC SIGNAL STEP STRUC SWITCH THEN TO TRIGGER TRUE UNTIL WAIT WHEN WHILE
"""
KEYWORDS = frozenset(_KEYWORDS.split())
"""KRL keywords (case-insensitive) a name must not be; from the KSS 8 expert programming manual's
syntax chapters as remembered (medium confidence: the list may be incomplete)."""


def legal_name(name: str) -> str:
    """A legal KRL module name: letters, digits and ``_``, starting with a letter, at most 24
    characters; a keyword gets a trailing ``_``. The .src/.dat file names use it too (KRL
    requires DEF name == file name)."""
    cleaned = "".join(ch if (ch.isascii() and (ch.isalnum() or ch == "_")) else "_" for ch in name)
    if not cleaned or not cleaned[0].isalpha():
        cleaned = "P" + cleaned
    cleaned = cleaned[:MAX_NAME_LENGTH]
    if cleaned.upper() in KEYWORDS:
        cleaned = cleaned[: MAX_NAME_LENGTH - 1] + "_"
    return cleaned


def is_legal_name(name: str) -> bool:
    """True when ``name`` is already a legal KRL name (:func:`legal_name` leaves it as it is)."""
    return legal_name(name) == name


def krl_status_turn(joints: ArrayLike, model: ArmModel) -> str:
    """``S 2,T 10`` (decimal, as in E6POS values) of controller joints (6,) in rad; a template
    filter: ``step.joints | krl_status_turn(station.robot)``."""
    status, turn = status_turn(model, joints)
    return f"S {int(status)},T {int(turn)}"


VEL_AXIS_MIN_PERCENT = 1
"""The smallest ``$VEL_AXIS`` / ``$ACC_AXIS`` value, %: KSS 8 system variables manual, INT,
range 1 .. 100 (medium confidence, recalled; KUKA's own inline forms and public third-party KRL
posts write whole percents). olp writes whole percents, rounded down (:func:`krl_percent`)."""

TOOL_DATA_SIZE = 16
"""``TOOL_DATA[1..16]`` in ``$config.dat`` (KSS 8; project vendor notes)."""
BASE_DATA_SIZE = 32
"""``BASE_DATA[1..32]`` in ``$config.dat`` (KSS 8; project vendor notes)."""

NULL_FRAME = "$NULLFRAME"
"""KRL's zero frame: ``$TOOL = $NULLFRAME`` is the bare flange, ``$BASE = $NULLFRAME`` the world
(KSS 8 system variables)."""


def krl_e6pos(pose: ArrayLike, status: int, turn: int) -> str:
    """An E6POS value without braces, ``X ..,Y ..,Z ..,A ..,B ..,C ..,S 2,T 10``: a pose (4, 4)
    in metres with Status and Turn (decimal, as the pendant writes them in .dat files). External
    axes E1..E6 are left out: on a robot without them they mean nothing, and a written 0 would
    move an axis that exists."""
    return f"{krl_frame(pose)},S {int(status)},T {int(turn)}"


def krl_point_type(step: Any) -> str:
    """``E6AXIS`` for a PTP to a joint target, and for a PTP whose Turn cannot select the
    planned joints (``step.vendor["turn_ambiguous"]``, see :func:`turn_ambiguous`); ``E6POS``
    for every other motion (a post step)."""
    if step.kind == "joint" and (not step.cartesian or step.vendor.get("turn_ambiguous")):
        return "E6AXIS"
    return "E6POS"


def krl_point(step: Any) -> str:
    """A post step's target value without braces: axis values (:func:`krl_axis`) where
    :func:`krl_point_type` says ``E6AXIS``, else the TCP pose in the motion's base with the
    planned joints' Status and Turn (:func:`krl_e6pos`; LIN and CIRC ignore S and T, PTP
    honours them)."""
    if krl_point_type(step) == "E6AXIS":
        return krl_axis(step.joints)
    return krl_e6pos(step.pose, step.vendor["status"], step.vendor["turn"])


def krl_tool(step: Any, mode: str = "inline") -> str:
    """The value of ``$TOOL`` for a post step: ``$NULLFRAME`` for the bare flange (an identity
    TCP); in ``inline``
    mode ``{FRAME: X ..}`` (the TCP in KUKA's flange frame), in ``indexed`` mode
    ``TOOL_DATA[n]`` with the tool's station number (1 .. 16)."""
    tool = step.tool
    if _is_identity(tool.pose):
        return NULL_FRAME
    if mode == "indexed":
        return f"TOOL_DATA[{_index(step, tool, TOOL_DATA_SIZE, 'tool')}]"
    return "{FRAME: " + krl_frame(tool.pose) + "}"


def krl_base(step: Any, mode: str = "inline") -> str:
    """The value of ``$BASE`` for a post step: ``$NULLFRAME`` when the frame is the reference
    itself (``step.frame_pose`` is the identity); ``{FRAME: ..}`` (``step.frame_pose``) in
    ``inline`` mode, ``BASE_DATA[n]`` in ``indexed`` mode (1 .. 32)."""
    if _is_identity(step.frame_pose):
        return NULL_FRAME
    if mode == "indexed":
        return f"BASE_DATA[{_index(step, step.frame, BASE_DATA_SIZE, 'base')}]"
    return "{FRAME: " + krl_frame(step.frame_pose) + "}"


def _is_identity(pose: ArrayLike) -> bool:
    return bool(np.allclose(pose, np.eye(4), rtol=0.0, atol=1e-12))


def _index(step: Any, item: Any, size: int, what: str) -> int:
    from olp.errors import PostError

    number = item.number
    if number is None or not 1 <= number <= size:
        raise PostError(
            f"{what} {item.name!r} needs a number 1..{size} for {what.upper()}_DATA "
            f"(it has {number})",
            step.instruction.span,
            hint="give it a number in the station, or use the post option frames: inline",
        )
    return int(number)


def krl_percent(fraction: float) -> str:
    """A fraction (0, 1] as a whole ``$VEL_AXIS``/``$ACC_AXIS`` percent, rounded down (never
    faster than planned; a fraction within 1e-9 of a whole percent counts as it), at least 1."""
    return str(max(VEL_AXIS_MIN_PERCENT, whole_percent(fraction)))


def whole_percent(fraction: float) -> int:
    """``floor(100 · fraction)``, with fractions within 1e-9 % of a whole percent on it."""
    return math.floor(float(fraction) * 100.0 + 1e-9)


def turn_ambiguous(joints: ArrayLike, lower: ArrayLike, upper: ArrayLike) -> NDArray[np.bool_]:
    """Whether Turn cannot select joints (..., n) rad: some axis has ``q ± 360°`` of the same
    sign inside its limits ``lower``/``upper`` (n,) rad, so T (a sign per axis) admits two
    turns. Never true for KUKA's own ranges (A4 ±185°, A6 ±350°); true for wider axes, such as
    an ABB axis 6 of ±400° near 0."""
    q = np.asarray(joints, dtype=np.float64)
    lo, hi = np.asarray(lower, dtype=np.float64), np.asarray(upper, dtype=np.float64)
    out = np.zeros(q.shape[:-1], dtype=bool)
    for other in (q - 2 * math.pi, q + 2 * math.pi):
        same_sign = (other < -ZERO) == (q < -ZERO)
        out |= np.any(same_sign & (other >= lo) & (other <= hi), axis=-1)
    return out


def step_values(robot: Any, joints: ArrayLike, options: Any = None) -> list[dict[str, Any]]:
    """Post hook: Status and Turn of each motion's planned joints (N, 6) rad, and whether Turn
    cannot select them on ``robot``'s joint limits (:func:`turn_ambiguous`)."""
    q = np.asarray(joints, dtype=np.float64)
    status, turn = status_turn(robot, q)
    limits = getattr(robot, "limits", None)
    ambiguous = (
        turn_ambiguous(q, limits.lower, limits.upper)
        if limits is not None
        else np.zeros(q.shape[0], dtype=bool)
    )
    rows = zip(status.tolist(), turn.tolist(), ambiguous.tolist(), strict=True)
    return [{"status": int(s), "turn": int(t), "turn_ambiguous": bool(a)} for s, t, a in rows]


TEMPLATE_FILTERS = {
    "krl_frame": krl_frame,
    "krl_axis": krl_axis,
    "krl_status_turn": krl_status_turn,
    "krl_e6pos": krl_e6pos,
    "krl_point": krl_point,
    "krl_point_type": krl_point_type,
    "krl_tool": krl_tool,
    "krl_base": krl_base,
    "krl_percent": krl_percent,
}


def post_diagnostics(compiled: Any, options: Any = None) -> list[Diagnostic]:
    """What the KRL post cannot say exactly (``options``: the post's manifest options).

    * ``zone_dropped`` (warning): without the option ``ptp_approximation`` (a ``$APO.CPTP``
      percentage), joint moves with a zone are written as exact stops: KRL approximates PTP with
      ``C_PTP`` and ``$APO.CPTP`` in percent of an axis-specific distance, which a TCP distance
      zone does not translate to (timing already assumes stops, so estimates still hold).
    * ``joint_speed`` (error): a joint speed or acceleration below 1 %, under
      :data:`VEL_AXIS_MIN_PERCENT`; (warning) one that is not a whole percent, written rounded
      down (:func:`krl_percent`).
    * ``name`` (error): a call of a routine whose name is not a legal KRL name (olp does not
      rename what another program defines).
    * ``ptp_axis_values`` (warning): a PTP to a Cartesian target written as axis values,
      because Turn cannot tell two turns of an axis apart on this robot (:func:`turn_ambiguous`).
    """
    opts = options or {}
    out = []
    for step in compiled.steps:
        ins = step.instruction
        kind = getattr(ins, "kind", None)
        if kind == "joint" and not step.skipped:
            out += _joint_diagnostics(step.index, ins, opts)
            out += _ambiguity(compiled.station.robot, step)
        elif kind == "call" and not is_legal_name(ins.name):
            message = f"call of {ins.name!r}: not a legal KRL name (letters, digits, _; 24 max)"
            out.append(Diagnostic("error", "name", message, ins.span, step.index))
    return out


def _ambiguity(robot: Any, step: Any) -> list[Diagnostic]:
    ins = step.instruction
    if step.joints is None or not isinstance(ins.target, CartesianTarget):
        return []
    if not turn_ambiguous(step.joints, robot.limits.lower, robot.limits.upper):
        return []
    message = (
        "PTP written with axis values: Status/Turn cannot select the planned joints on this "
        "robot (an axis has two turns of the same sign within its limits)"
    )
    return [Diagnostic("warning", "ptp_axis_values", message, ins.span, step.index)]


def _joint_diagnostics(index: int, ins: Any, options: Any) -> list[Diagnostic]:
    out = []
    if not ins.zone.is_fine and not options.get("ptp_approximation"):
        out.append(
            Diagnostic(
                "warning",
                "zone_dropped",
                f"PTP with a {ins.zone.radius * 1000:.1f} mm zone is written as an exact stop",
                ins.span,
                index,
            )
        )
    for what, fraction in (
        ("speed", ins.speed.joint),
        ("acceleration", ins.speed.joint_acceleration),
    ):
        percent = fraction * 100.0
        if whole_percent(fraction) < VEL_AXIS_MIN_PERCENT:
            message = (
                f"joint {what} {percent:.2f} % is below KRL's smallest $VEL_AXIS/$ACC_AXIS "
                f"value, {VEL_AXIS_MIN_PERCENT} %"
            )
            out.append(Diagnostic("error", "joint_speed", message, ins.span, index))
        elif abs(percent - whole_percent(fraction)) > 1e-6:
            written = whole_percent(fraction)
            message = f"joint {what} {percent:.2f} % written as {written} % (KRL: whole percents)"
            out.append(Diagnostic("warning", "joint_speed", message, ins.span, index))
    return out
