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

How the URScript post spells these (names, numbers, blends, I/O): :mod:`olp.posts.ur`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

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
# Motion parameters: what the URScript post writes as ``a`` and ``v``, and what olp's timing
# of a UR program assumes (olp.passes.timing.ur): one function each, so the two cannot differ.

MOVEJ_ACCELERATION = 1.4
"""rad/s², URScript's ``movej`` default (``a`` at 100 % joint acceleration)."""
MOVEL_ACCELERATION = 1.2
"""m/s², URScript's ``movel``/``movec`` default."""
MOTION_DECIMALS = 5
"""Decimals of ``a`` and ``v`` in the script (:data:`olp.posts.ur.NUMBERS`): the values below are
rounded to them, so the timing uses the numbers the script says."""


def movej_parameters(
    joint: float, joint_acceleration: float, velocity_limits: ArrayLike, written: bool = True
) -> tuple[float, float]:
    """``(a, v)`` of ``movej``: rad/s² and rad/s of the leading axis (URScript manual,
    ``movej``: "a: joint acceleration of leading axis [rad/s^2], v: joint speed of leading
    axis [rad/s]"). ``v`` is ``joint`` (fraction of each axis' maximum) times the *smallest*
    axis velocity limit, so that at 100 % no axis exceeds its own; ``a`` is 1.4 rad/s² times
    ``joint_acceleration`` (UR publishes no joint acceleration limits). ``written``: rounded
    as the script prints them (the post formats the unrounded values itself, to the same
    text)."""
    v = joint * float(np.min(np.asarray(velocity_limits, dtype=np.float64)))
    a = joint_acceleration * MOVEJ_ACCELERATION
    return (_written(a), _written(v)) if written else (a, v)


def movel_parameters(
    linear: float, linear_acceleration: float | None, written: bool = True
) -> tuple[float, float]:
    """``(a, v)`` of ``movel``/``movec``: m/s² and m/s of the tool (URScript manual, ``movel``:
    "a: tool acceleration [m/s^2], v: tool speed [m/s]"): the programmed path acceleration, or
    URScript's default, and the programmed TCP speed (``written`` as for
    :func:`movej_parameters`)."""
    a = MOVEL_ACCELERATION if linear_acceleration is None else linear_acceleration
    return (_written(a), _written(linear)) if written else (a, linear)


def _written(value: float) -> float:
    """``value`` as the script prints it (positive values stay positive: the post refuses a
    value that would print as 0)."""
    return float(round(value, MOTION_DECIMALS))
