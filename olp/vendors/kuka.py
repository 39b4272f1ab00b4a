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

How the KRL post spells these (names, numbers, E6POS values, I/O): :mod:`olp.posts.kuka`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.geometry import pose_from, rotation_from_zyx, roty, zyx_from_rotation
from olp.ir import ArcOrientation, Configuration
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


ARC_ORIENTATIONS: dict[tuple[str, str], ArcOrientation] = {
    ("VAR", "BASE"): ArcOrientation.INTERPOLATE,
    ("CONSTANT", "BASE"): ArcOrientation.CONSTANT,
    ("VAR", "PATH"): ArcOrientation.PATH,
    ("CONSTANT", "PATH"): ArcOrientation.PATH_CONSTANT,
    ("JOINT", "BASE"): ArcOrientation.WRIST,
    ("JOINT", "PATH"): ArcOrientation.WRIST,
}
"""KUKA ``($ORI_TYPE, $CIRC_TYPE)`` -> olp's arc orientation rule. ``#VAR`` interpolates the
orientation from the start to the end point, ``#CONSTANT`` keeps the start's, ``#JOINT``
interpolates the wrist axes; ``#BASE`` refers the orientation to the base, ``#PATH`` to the
path (it turns with the arc). Defaults ``#VAR`` and ``#BASE`` (the inline forms' LDAT default
``ORI_TYP #VAR, CIRC_TYP #BASE``). Sources: KUKA knowledge-base articles on ``$ORI_TYPE`` and
``$CIRC_TYPE`` and the KSS inline forms' LDAT (medium confidence); how olp models each rule:
:mod:`olp.arcs`."""

ARC_TYPES: dict[ArcOrientation, tuple[str, str]] = {
    rule: types for types, rule in reversed(ARC_ORIENTATIONS.items())
}
"""olp's arc orientation rule -> the ``($ORI_TYPE, $CIRC_TYPE)`` the KRL post writes for it
(``#VAR`` for the wrist rule's ``#JOINT`` pairs is never needed: the post refuses that rule)."""


_CP_APPROX = frozenset({("C_DIS",), ("C_VEL",), ("C_ORI",)})


def approximation_problem(words: tuple[str, ...], joint: bool, spline: bool) -> str | None:
    """Why ``words`` (upper case) are not a KRL motion's approximation, else None.

    A PTP approximates with C_DIS, or C_PTP optionally followed by C_DIS, C_ORI or C_VEL; a LIN
    or CIRC with one of C_DIS, C_ORI or C_VEL. The inline forms of KSS 8 write the keyword
    twice (``LIN XP1 C_DIS C_DIS``), and ``PTP XP1 C_DIS C_DIS`` is read the same way. A
    spline motion approximates with C_SPL; an SPTP/SLIN/SCIRC also takes C_DIS, which real
    KR C4 programs write and olp reads as C_SPL. Source: KUKA's KSS 8 motion syntax as olp's
    KRL grammar reads it, and the public controller backups of benchmarks/krl_corpus.py; not
    checked against the KSS manual here."""
    if not words:
        return None
    if spline and words in (("C_SPL",), ("C_DIS",)):
        return None
    if joint:
        valid = words in (("C_DIS",), ("C_DIS", "C_DIS")) or (
            words[0] == "C_PTP" and (len(words) == 1 or words[1:] in _CP_APPROX)
        )
        rule = (
            "PTP approximates with C_DIS, or with C_PTP optionally followed by C_DIS, "
            "C_ORI or C_VEL"
        )
    else:
        doubled = len(words) == 2 and words[0] == words[1]
        valid = words in _CP_APPROX or (doubled and words[:1] in _CP_APPROX)
        rule = "a LIN or CIRC approximates with one of C_DIS, C_ORI or C_VEL"
    if valid:
        return None
    return rule + ("; spline motions with C_SPL" if spline else "")
