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

How the LS post spells these (positions, CONFIG, speeds, I/O): :mod:`olp.posts.fanuc`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.geometry import pose_from, rotation_from_zyx, zyx_from_rotation
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


CONFIG_TOLERANCE = 1e-6
"""rad: IK candidates this close to the planned joints count as the planned solution."""


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
    as joints).

    The definition is :func:`selecting_configs_reference`: CONFIG ``C`` of joints ``q`` selects
    them when some candidate satisfies ``C`` and every candidate that does lies within
    :data:`CONFIG_TOLERANCE` of ``q``. This function computes the same booleans without
    building the 8 x 18 candidate rows per point (:func:`_selecting_configs`, where the proof
    is); robots whose shoulder or elbow flag would depend on more than J2 and J3 take the
    reference. Batches of :data:`SELECT_ROWS` bound the memory.
    """
    result: list[str | None] = selecting_config_column(robot, joints).tolist()
    return result


def selecting_config_column(robot: Any, joints: ArrayLike) -> NDArray[np.object_]:
    """:func:`selecting_configs` as an array (N,) of objects: the CONFIG text (each distinct
    text one ``str`` object, shared by its rows) or None, with no Python object made per row
    (a toolpath's rows: the LS post's column writer, :mod:`olp.posts.fanuc_rows`)."""
    q = np.asarray(joints, dtype=np.float64).reshape(-1, 6)
    out = np.full(q.shape[0], None, dtype=object)
    if q.shape[0] == 0 or not has_config(robot):
        return out
    select = _selecting_configs if _flags_follow_j2_j3(robot) else _selecting_configs_reference
    for lo in range(0, q.shape[0], SELECT_ROWS):
        hi = min(lo + SELECT_ROWS, q.shape[0])
        out[lo:hi] = select(robot, q[lo:hi])
    return out


def selecting_configs_reference(robot: Any, joints: ArrayLike) -> list[str | None]:
    """:func:`selecting_configs` by its definition: every IK solution of every pose with all its
    turn variants (:func:`olp.kinematics.base.turn_variants`), tested with
    :func:`olp.kinematics.configuration.satisfies`. Slow (about 30 kB and 0.1 ms per point);
    kept as the statement the fast path is tested against."""
    q = np.asarray(joints, dtype=np.float64).reshape(-1, 6)
    if q.shape[0] == 0 or not has_config(robot):
        return [None] * q.shape[0]
    out: list[str | None] = []
    for lo in range(0, q.shape[0], SELECT_ROWS):
        out += _selecting_configs_reference(robot, q[lo : lo + SELECT_ROWS])
    return out


SELECT_ROWS = 4096
"""Joint vectors per batch of :func:`selecting_configs`. The reference path holds per row its IK
solutions with their turn variants (8 branches x up to 18 turns x 6 joints) and the masks over
them, about 30 kB (a million rows at once took ~30 GB); the fast path about 3 kB."""


_PACK = 1 << 16
"""Range of one packed turn number in :func:`_config_texts` (8 x 2**48 fits an int64)."""


def _config_texts(q: FloatArray, flags: Any) -> NDArray[np.object_]:
    """The CONFIG text (:class:`FanucConfig`) of each joint vector (n, 6) rad with its branch
    flags, as an array (n,) of objects: each distinct value formatted once, one ``str`` shared
    by its rows."""
    turns = turn_number(q[:, list(TURN_AXES)])
    codes = np.column_stack([flags.flip, flags.down, flags.back, turns]).astype(np.int64)
    if np.all((turns > -_PACK // 2) & (turns < _PACK // 2)):  # a 1-d unique is ~10x faster
        packed = codes[:, 0] * 4 + codes[:, 1] * 2 + codes[:, 2]
        for k in (3, 4, 5):
            packed = packed * _PACK + (codes[:, k] + _PACK // 2)
        _, first, inverse = np.unique(packed, return_index=True, return_inverse=True)
        distinct = codes[first]
    else:
        distinct, inverse = np.unique(codes, axis=0, return_inverse=True)
    texts = np.empty(len(distinct), dtype=object)
    texts[:] = [
        str(FanucConfig(not f, not d, not b, (int(t1), int(t4), int(t6))))
        for f, d, b, t1, t4, t6 in distinct.tolist()
    ]
    picked: NDArray[np.object_] = texts[inverse.reshape(-1)]
    return picked


def _selecting_configs_reference(robot: Any, q: FloatArray) -> list[str | None]:
    """:func:`selecting_configs_reference` of one batch (n, 6) rad."""
    from olp.kinematics.base import turn_variants
    from olp.kinematics.configuration import satisfies

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


_ARM_JOINTS = (1, 2)
"""J2, J3 (0-based): the only controller joints the shoulder and elbow flags read (the wrist
centre in the frame turning with J1 and the forearm angle), given a coupling that maps them
onto model J2, J3 alone (:func:`_flags_follow_j2_j3`)."""


def _flags_follow_j2_j3(robot: Any) -> bool:
    """Whether the robot's joint coupling feeds model J2 and J3 from controller J2 and J3 only
    (identity or Fanuc's J3 + J2), the premise of :func:`_selecting_configs`."""
    coupling = getattr(getattr(robot, "kinematics", None), "coupling", None)
    matrix = getattr(coupling, "matrix", None)
    if matrix is None:
        return False
    rows = np.asarray(matrix)[list(_ARM_JOINTS)]
    others = [j for j in range(rows.shape[1]) if j not in _ARM_JOINTS]
    return bool(np.all(rows[:, others] == 0))


def _selecting_configs(robot: Any, q: FloatArray) -> NDArray[np.object_]:
    """:func:`selecting_configs` of one batch (n, 6) rad, equal result for result to
    :func:`_selecting_configs_reference` (tests/vendors/test_fanuc_selection.py).

    Proof (joints numbered J1..J6 as on the pendant). The reference builds, per point and IK
    branch ``b`` (wrapped as in :func:`~olp.kinematics.base.turn_variants`), the candidates
    ``c = base_b + s`` for every shift vector ``s`` in the product ``S_1 x ... x S_6`` of
    per-joint turn shifts (NaN outside the limits), and decides
    ``selected = any(ok) & all(~ok | near)``, where ``ok(c)`` is a conjunction of

    * inside the limits: ``lo_j - tol <= c_j <= hi_j + tol`` for each joint ``j`` (NaN fails);
    * the turn ranges of J1, J4, J6 and the J5 sign test of ``satisfies``: one joint each;
    * the shoulder test on ``wrist_x(c)`` and the elbow test on ``elbow_angle(c)``,

    and ``near(c) = max_j |c_j - q_j| < CONFIG_TOLERANCE`` (on rows inside the limits, which
    are finite, this is ``all_j |c_j - q_j| < CONFIG_TOLERANCE``). Every test but the shoulder
    and elbow ones reads one joint ``c_j = base_bj + s_j``, the same float sum the reference
    forms, compared with the same float bounds: so ``ok = XE(c_2, c_3) · prod_j A_j(c_j)`` and
    ``near = prod_j N_j(c_j)`` with per-joint masks ``A_j``, ``N_j`` that equal the reference's
    bit for bit. The shoulder and elbow values read model J2 and J3 only (``_arm_x_z``,
    :func:`~olp.kinematics.configuration.elbow_angle`), which the coupling feeds from
    controller J2 and J3 alone (:func:`_flags_follow_j2_j3`; the matrix product adds the
    other joints times an exact 0, which leaves every float unchanged for finite joints), so
    ``XE`` is evaluated once per (J2, J3) shift pair, on the same joint values, by the same
    functions (numpy's elementwise functions give an element the same value whatever array it
    sits in), and only where ``A_2 A_3`` holds and every other joint has a passing shift
    (:func:`_arm_flags_pass`; elsewhere a factor below is 0 whatever ``XE`` is). Then, per
    branch, the number of candidates that are ``ok`` is
    ``sum_{s2,s3} A_2 A_3 XE · prod_{j != 2,3} sum_s A_j`` and the number that are ``ok`` and
    ``near`` the same with ``A_j N_j`` in place of ``A_j``; ``any(ok)`` is "the first count is
    positive" and ``all(~ok | near)`` is "the two counts are equal" (near-and-ok candidates
    are a subset of the ok ones). No step rounds differently, so no margin is needed: the
    result is the reference's, for every point, without the per-point candidate rows.
    """
    from olp.kinematics.base import turn_shifts, wrap_joints
    from olp.kinematics.configuration import TOLERANCE

    flags = branch_flags(robot, q)
    configs = _config_texts(q, flags)
    lower = np.asarray(robot.limits.lower, dtype=np.float64)
    upper = np.asarray(robot.limits.upper, dtype=np.float64)
    base = wrap_joints(robot.solve(robot.flange_poses(q)))  # (n, B, 6)
    inside_lo, inside_hi = lower - _VARIANT_TOLERANCE, upper + _VARIANT_TOLERANCE
    bounds = _turn_bounds(q)
    values, ok, near = [], [], []
    for j in range(6):
        v = base[..., j, None] + np.asarray(turn_shifts(lower[j], upper[j]))  # (n, B, k_j)
        with np.errstate(invalid="ignore"):
            a = (v >= inside_lo[j]) & (v <= inside_hi[j])
            if j in bounds:
                low, high = bounds[j]
                a &= (v >= low - TOLERANCE) & (v <= high + TOLERANCE)
            if j == 4:
                a &= np.where(flags.flip[:, None, None], v <= TOLERANCE, v >= -TOLERANCE)
            n = np.abs(v - q[:, None, None, j]) < CONFIG_TOLERANCE
        values.append(v)
        ok.append(a)
        near.append(a & n)
    xe = _arm_flags_pass(robot, flags, base, values, ok)
    count_ok = _count(ok, xe)
    count_near = _count(near, xe)
    selected = (count_ok.sum(axis=-1) > 0) & (count_ok.sum(axis=-1) == count_near.sum(axis=-1))
    configs[~selected] = None
    return configs


_VARIANT_TOLERANCE = 1e-9
"""rad: the limit slack of :func:`olp.kinematics.base.turn_variants` (its default)."""


def _turn_bounds(q: FloatArray) -> dict[int, tuple[FloatArray, FloatArray]]:
    """Per turn axis, the bounds (n, 1, 1) rad of the turn range each joint vector (n, 6) asks
    for: :func:`turn_range` of its :func:`turn_number`, as the same float products."""
    turns = turn_number(q[:, list(TURN_AXES)])
    out: dict[int, tuple[FloatArray, FloatArray]] = {}
    for k, axis in enumerate(TURN_AXES):
        t = turns[:, k, None, None]
        low: FloatArray = np.asarray((2 * t - 1) * math.pi, dtype=np.float64)
        high: FloatArray = np.asarray((2 * t + 1) * math.pi, dtype=np.float64)
        out[axis] = (low, high)
    return out


def _arm_flags_pass(
    robot: Any, flags: Any, base: FloatArray, values: list[FloatArray], ok: list[NDArray[np.bool_]]
) -> NDArray[np.bool_]:
    """The shoulder and elbow tests of ``satisfies`` (n, B, k_2, k_3) per point, branch and
    (J2, J3) shift pair, evaluated where they can change a count of :func:`_count`: where the
    J2 and J3 values pass their own joint masks ``ok`` and every other joint has a passing
    shift (elsewhere False, which leaves the counts unchanged because a factor is 0 there).

    ``base`` (n, B, 6): the wrapped IK solutions; ``values[j]`` (n, B, k_j): joint j's shifted
    values; ``flags``: the planned joints' :class:`~olp.kinematics.configuration.BranchFlags`.
    """
    from olp.kinematics.configuration import TOLERANCE, elbow_angle, wrist_x

    j2, j3 = _ARM_JOINTS
    others = np.ones(base.shape[:2], dtype=bool)
    for j, mask in enumerate(ok):
        if j not in _ARM_JOINTS:
            others &= _count_last(mask) > 0
    wanted = ok[j2][..., :, None] & ok[j3][..., None, :] & others[..., None, None]
    i, b, m2, m3 = np.nonzero(wanted)
    rows = base[i, b]  # the other joints' values leave both tests unchanged (see the proof)
    rows[:, j2] = values[j2][i, b, m2]
    rows[:, j3] = values[j3][i, b, m3]
    x, e = wrist_x(robot, rows), elbow_angle(robot, rows)
    passed = np.where(flags.back[i], x <= TOLERANCE, x >= -TOLERANCE)
    passed &= np.where(flags.down[i], e <= TOLERANCE, e >= -TOLERANCE)
    out = np.zeros(wanted.shape, dtype=bool)
    out[i, b, m2, m3] = passed
    return out


def _count(masks: list[NDArray[np.bool_]], xe: NDArray[np.bool_]) -> IntArray:
    """Per point and branch (n, B), the candidates passing per-joint ``masks`` (n, B, k_j) and
    the shoulder/elbow mask ``xe`` (n, B, k_2, k_3) over J2, J3 shift pairs."""
    j2, j3 = _ARM_JOINTS
    pairs = masks[j2][..., :, None] & masks[j3][..., None, :] & xe
    count = _count_last(pairs.reshape(*pairs.shape[:-2], -1))
    for j, mask in enumerate(masks):
        if j not in _ARM_JOINTS:
            count *= _count_last(mask)
    return count


def _count_last(mask: NDArray[np.bool_]) -> IntArray:
    """True entries along the last, short axis (a few turn shifts) of ``mask``: slice sums,
    because a numpy reduction over an axis of length 2 or 3 costs ~10x more."""
    count = np.zeros(mask.shape[:-1], dtype=np.int64)
    for k in range(mask.shape[-1]):
        count += mask[..., k]
    return count
