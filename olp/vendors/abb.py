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
How the RAPID post spells these (names, numbers, data, I/O): :mod:`olp.posts.abb`.

Joint values are controller joints in rad (what the FlexPendant shows, in degrees).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

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
