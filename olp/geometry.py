"""SE(3) helpers on numpy arrays: ``(4, 4)`` poses and ``(N, 4, 4)`` batches, metres and radians.

Vendor angle conventions (KUKA ABC, Fanuc WPR, ...) live in :mod:`olp.vendors`, not here. This
module only builds and combines rotation matrices and homogeneous transforms.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


def transl(x: float, y: float, z: float) -> FloatArray:
    """A pure translation (4, 4), metres."""
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


def _rot(axis: int, angle: ArrayLike) -> FloatArray:
    a = np.asarray(angle, dtype=np.float64)
    c, s = np.cos(a), np.sin(a)
    out = np.zeros((*a.shape, 4, 4))
    out[..., 3, 3] = 1.0
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    out[..., axis, axis] = 1.0
    out[..., i, i] = c
    out[..., j, j] = c
    out[..., i, j] = -s
    out[..., j, i] = s
    return out


def rotx(angle: ArrayLike) -> FloatArray:
    """Rotation about X by ``angle`` rad; shape (4, 4), or (N, 4, 4) for an array of angles."""
    return _rot(0, angle)


def roty(angle: ArrayLike) -> FloatArray:
    """Rotation about Y by ``angle`` rad; shape (4, 4), or (N, 4, 4) for an array of angles."""
    return _rot(1, angle)


def rotz(angle: ArrayLike) -> FloatArray:
    """Rotation about Z by ``angle`` rad; shape (4, 4), or (N, 4, 4) for an array of angles."""
    return _rot(2, angle)


def rotation_from_zyx(z: ArrayLike, y: ArrayLike, x: ArrayLike) -> FloatArray:
    """Rotations (..., 3, 3) ``Rz(z) · Ry(y) · Rx(x)`` (intrinsic Z, Y', X''), angles in rad."""
    z, y, x = (np.asarray(v, dtype=np.float64) for v in (z, y, x))
    cz, sz, cy, sy, cx, sx = np.cos(z), np.sin(z), np.cos(y), np.sin(y), np.cos(x), np.sin(x)
    r = np.empty((*np.broadcast(z, y, x).shape, 3, 3))
    r[..., 0, 0] = cz * cy
    r[..., 0, 1] = cz * sy * sx - sz * cx
    r[..., 0, 2] = cz * sy * cx + sz * sx
    r[..., 1, 0] = sz * cy
    r[..., 1, 1] = sz * sy * sx + cz * cx
    r[..., 1, 2] = sz * sy * cx - cz * sx
    r[..., 2, 0] = -sy
    r[..., 2, 1] = cy * sx
    r[..., 2, 2] = cy * cx
    return r


_GIMBAL_EPS = 1e-9


def zyx_from_rotation(rotation: ArrayLike) -> FloatArray:
    """Angles (z, y, x) in rad, shape (..., 3), with ``R = Rz(z) Ry(y) Rx(x)``.

    z and x lie in (-pi, pi], y in [-pi/2, pi/2]. At gimbal lock (y = ±pi/2) z and x are not
    unique: x is set to 0 and the whole rotation about Z goes into z. Exact at ±180°.
    """
    r = np.asarray(rotation, dtype=np.float64)
    cos_y = np.hypot(r[..., 0, 0], r[..., 1, 0])
    locked = cos_y < _GIMBAL_EPS
    z = np.where(
        locked, np.arctan2(-r[..., 0, 1], r[..., 1, 1]), np.arctan2(r[..., 1, 0], r[..., 0, 0])
    )
    x = np.where(locked, 0.0, np.arctan2(r[..., 2, 1], r[..., 2, 2]))
    y = np.where(locked, np.copysign(np.pi / 2, -r[..., 2, 0]), np.arctan2(-r[..., 2, 0], cos_y))
    return wrap_half_open(np.stack([z, y, x], axis=-1))


def wrap_half_open(angles: ArrayLike) -> FloatArray:
    """Angles mapped to (-pi, pi]; -pi (and values within 1e-12 of it) become +pi."""
    a = np.asarray(angles, dtype=np.float64)
    wrapped = np.mod(a + np.pi, 2 * np.pi) - np.pi
    return np.where(wrapped <= -np.pi + 1e-12, wrapped + 2 * np.pi, wrapped)


def rotation_from_quaternion(quaternion: ArrayLike) -> FloatArray:
    """Rotations (..., 3, 3) from quaternions ``[w, x, y, z]`` (w first), (..., 4), normalised
    first. Used by ABB robtargets and by station files (``quat:``)."""
    q = np.asarray(quaternion, dtype=np.float64)
    w, x, y, z = np.moveaxis(q / np.linalg.norm(q, axis=-1, keepdims=True), -1, 0)
    r = np.empty((*q.shape[:-1], 3, 3))
    r[..., 0, 0] = 1 - 2 * (y * y + z * z)
    r[..., 0, 1] = 2 * (x * y - w * z)
    r[..., 0, 2] = 2 * (x * z + w * y)
    r[..., 1, 0] = 2 * (x * y + w * z)
    r[..., 1, 1] = 1 - 2 * (x * x + z * z)
    r[..., 1, 2] = 2 * (y * z - w * x)
    r[..., 2, 0] = 2 * (x * z - w * y)
    r[..., 2, 1] = 2 * (y * z + w * x)
    r[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return r


def pose_from(rotation: ArrayLike, position: ArrayLike) -> FloatArray:
    """Assemble poses from rotations (..., 3, 3) and positions (..., 3) in metres."""
    r = np.asarray(rotation, dtype=np.float64)
    p = np.asarray(position, dtype=np.float64)
    out = np.zeros((*r.shape[:-2], 4, 4))
    out[..., :3, :3] = r
    out[..., :3, 3] = p
    out[..., 3, 3] = 1.0
    return out


def inv(pose: ArrayLike) -> FloatArray:
    """Inverse of rigid transforms (..., 4, 4), exact (transpose, not a general inverse)."""
    t = np.asarray(pose, dtype=np.float64)
    rt = np.swapaxes(t[..., :3, :3], -1, -2)
    return pose_from(rt, -np.einsum("...ij,...j->...i", rt, t[..., :3, 3]))


def rotation_angle(rotation: ArrayLike) -> FloatArray:
    """Rotation angle (rad, in [0, pi]) of rotation matrices (..., 3, 3), robust near 0 and pi."""
    r = np.asarray(rotation, dtype=np.float64)
    cos = (np.trace(r, axis1=-2, axis2=-1) - 1.0) / 2.0
    skew = np.stack(
        [r[..., 2, 1] - r[..., 1, 2], r[..., 0, 2] - r[..., 2, 0], r[..., 1, 0] - r[..., 0, 1]],
        axis=-1,
    )
    sin = np.linalg.norm(skew, axis=-1) / 2.0
    return np.arctan2(sin, np.clip(cos, -1.0, 1.0))


def pose_distance(a: ArrayLike, b: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Translation distance (m) and rotation angle (rad) between poses (..., 4, 4)."""
    ta, tb = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    dist = np.linalg.norm(ta[..., :3, 3] - tb[..., :3, 3], axis=-1)
    rel = np.einsum("...ji,...jk->...ik", ta[..., :3, :3], tb[..., :3, :3])
    return dist, rotation_angle(rel)


def rotation_exp(rotvec: ArrayLike) -> FloatArray:
    """Rotation matrices (..., 3, 3) from rotation vectors (..., 3) (axis times angle, rad)."""
    v = np.asarray(rotvec, dtype=np.float64)
    theta = np.linalg.norm(v, axis=-1)[..., None, None]
    k = np.zeros((*v.shape[:-1], 3, 3))
    k[..., 0, 1], k[..., 0, 2], k[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    k = k - np.swapaxes(k, -1, -2)
    small = theta < 1e-8
    safe = np.where(small, 1.0, theta)
    a = np.where(small, 1.0 - theta**2 / 6.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - theta**2 / 24.0, (1.0 - np.cos(safe)) / safe**2)
    return np.eye(3) + a * k + b * (k @ k)


def rotation_log(rotation: ArrayLike) -> FloatArray:
    """Rotation vectors (..., 3) (axis times angle in [0, pi], rad) of rotations (..., 3, 3).

    Exact near 0 and at pi, where the textbook ``angle / (2 sin angle)`` formula divides by zero.
    """
    r = np.asarray(rotation, dtype=np.float64)
    angle = rotation_angle(r)
    skew = np.stack(
        [r[..., 2, 1] - r[..., 1, 2], r[..., 0, 2] - r[..., 2, 0], r[..., 1, 0] - r[..., 0, 1]],
        axis=-1,
    )
    sin = np.sin(angle)[..., None]
    general = (
        np.where(sin > 1e-6, angle[..., None] / np.where(sin > 1e-6, 2 * sin, 1.0), 0.5) * skew
    )
    near_pi = np.asarray(angle > np.pi - 1e-3)
    if np.any(near_pi):
        general = np.array(general)
        general[near_pi] = _log_near_pi(r[near_pi], angle[near_pi], skew[near_pi])
    return general


def _log_near_pi(r: FloatArray, angle: FloatArray, skew: FloatArray) -> FloatArray:
    # (R + R^T)/2 = I + (1 - cos t)(a a^T - I): read the axis from the largest diagonal entry.
    sym = (r + np.swapaxes(r, -1, -2)) / 2.0
    outer = (sym - np.eye(3)) / (1.0 - np.cos(angle))[..., None, None] + np.eye(3)
    col = np.argmax(np.diagonal(outer, axis1=-2, axis2=-1), axis=-1)
    axis = np.take_along_axis(outer, col[..., None, None], axis=-1)[..., 0]
    axis = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    sign = np.where(np.einsum("...i,...i->...", axis, skew) < 0, -1.0, 1.0)
    return axis * (sign * angle)[..., None]


def interpolate_poses(start: ArrayLike, end: ArrayLike, s: ArrayLike) -> FloatArray:
    """Poses (S, 4, 4) on the straight line from ``start`` to ``end`` (both (4, 4)) at fractions
    ``s`` (S,) in [0, 1]: linear in position, constant-axis (slerp) in orientation."""
    a, b = np.asarray(start, dtype=np.float64), np.asarray(end, dtype=np.float64)
    f = np.asarray(s, dtype=np.float64)
    delta = rotation_log(a[:3, :3].T @ b[:3, :3])
    rot = a[:3, :3] @ rotation_exp(f[:, None] * delta)
    pos = a[:3, 3] + f[:, None] * (b[:3, 3] - a[:3, 3])
    return pose_from(rot, pos)
