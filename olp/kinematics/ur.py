"""Closed-form kinematics of Universal Robots arms (six parallel/perpendicular axes, offset wrist).

Model
-----
Standard Denavit-Hartenberg, as Universal Robots publish it for every arm ("DH parameters for
calculations of kinematics and dynamics", UR support article; the e-Series values are in the
shared VENDOR-NOTES)::

    A_i = Rz(theta_i) · Tz(d_i) · Tx(a_i) · Rx(alpha_i),   alpha = (pi/2, 0, 0, pi/2, -pi/2, 0)
    a = (0, a2, a3, 0, 0, 0),   d = (d1, 0, 0, d4, d5, d6)

``theta_i`` *is* the controller's joint value (the UR pendant shows the DH angles; zero is the
arm stretched horizontally). Frame 0 is UR's ``Base`` frame (the controller's, which
ROS-Industrial's ``base`` reproduces), frame 6 the tool flange with Z out (ROS-Industrial
``tool0``).

IK
--
After K. P. Hawkins, "Analytic Inverse Kinematics for the Universal Robots UR-5/UR-10 Arms"
(Georgia Tech, 2013), rewritten element-wise for N poses. Joints 2, 3 and 4 are parallel, so:

1. the origin of frame 5, ``p5 = p - d6 · z6``, lies ``d4`` off the arm plane: two axis-1
   solutions (shoulder);
2. the tool Z axis makes an angle ``theta5`` with the plane's normal ``z1``: two solutions
   (wrist), from ``atan2(|z6 x z1|, z6 · z1)``;
3. ``theta6`` follows from the tool X and Y axes (free at the wrist singularity ``theta5 = 0``,
   where it is set to 0 and axis 4 absorbs the rest);
4. axes 2 and 3 form a planar two-link arm reaching frame 4: two solutions (elbow); axis 4
   completes the sum ``theta2 + theta3 + theta4``.

Branch order
------------
:func:`inverse` returns 8 rows per pose, row ``4·shoulder + 2·elbow + wrist``
(:data:`BRANCH_NAMES`), the same layout as :mod:`olp.kinematics.opw`:

* shoulder 0 ``"front"``: ``p5`` lies on the side of axis 1 the arm points to at
  ``theta2 = 0``, i.e. ``sign(a2) · (p5 · x1) >= 0`` with ``x1`` the X axis of frame 1 (for UR
  arms, a2 < 0, the arm points along -x1); 1 ``"back"``: the other side.
* elbow 0 ``"up"``: ``sign(a2 · a3) · sin(theta3) >= 0``; for a front shoulder the elbow then
  lies above the line from axis 2 to axis 4. 1 ``"down"``.
* wrist 0 ``"noflip"``: ``theta5 >= 0``; 1 ``"flip"``: ``theta5 <= 0``.

No vendor configuration flags exist for UR (``movej`` to a pose picks the nearest solution);
the names only explain diagnostics.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.kinematics.base import wrap_joints
from olp.kinematics.opw import BRANCH_NAMES as _OPW_BRANCH_NAMES

FloatArray = NDArray[np.float64]

BRANCH_NAMES: tuple[str, ...] = _OPW_BRANCH_NAMES
"""``BRANCH_NAMES[i]`` describes row ``i`` of :func:`inverse` (``"front/up/noflip"`` ...)."""

ALPHA: tuple[float, ...] = (math.pi / 2, 0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0)
"""DH twist angles of every UR arm, rad."""

_COS_TOLERANCE = 1e-9
"""An arccos/arcsin argument this far outside [-1, 1] is rounding at a boundary: clipped."""


@dataclass(frozen=True, slots=True)
class URParameters:
    """DH lengths of a UR arm in metres (``a2``, ``a3`` negative on every UR model)."""

    d1: float
    a2: float
    a3: float
    d4: float
    d5: float
    d6: float

    def __post_init__(self) -> None:
        for name in ("d1", "a2", "a3", "d4", "d5", "d6"):
            value = float(getattr(self, name))
            if not math.isfinite(value):
                raise ValueError(f"URParameters.{name} must be finite, got {value}")
            object.__setattr__(self, name, value)
        if self.a2 == 0.0 or self.a3 == 0.0 or self.d6 == 0.0:
            raise ValueError("URParameters: a2, a3 and d6 must be non-zero")

    @property
    def a(self) -> tuple[float, ...]:
        return (0.0, self.a2, self.a3, 0.0, 0.0, 0.0)

    @property
    def d(self) -> tuple[float, ...]:
        return (self.d1, 0.0, 0.0, self.d4, self.d5, self.d6)


def dh_transforms(params: URParameters, q: ArrayLike) -> FloatArray:
    """The six DH transforms ``A_i`` (..., 6, 4, 4) for joints q (..., 6) rad."""
    theta = np.asarray(q, dtype=np.float64)
    c, s = np.cos(theta), np.sin(theta)
    ca = np.cos(ALPHA)
    sa = np.sin(ALPHA)
    out = np.zeros((*theta.shape, 4, 4))
    out[..., 0, 0] = c
    out[..., 0, 1] = -s * ca
    out[..., 0, 2] = s * sa
    out[..., 0, 3] = c * np.asarray(params.a)
    out[..., 1, 0] = s
    out[..., 1, 1] = c * ca
    out[..., 1, 2] = -c * sa
    out[..., 1, 3] = s * np.asarray(params.a)
    out[..., 2, 1] = sa
    out[..., 2, 2] = ca
    out[..., 2, 3] = params.d
    out[..., 3, 3] = 1.0
    return out


def forward(params: URParameters, q: ArrayLike) -> FloatArray:
    """tool0 (flange, Z out) poses (..., 4, 4) in the Base frame for joints (..., 6) rad."""
    theta = np.asarray(q, dtype=np.float64)
    if theta.shape[-1:] != (6,):
        raise ValueError(f"forward: expected joints of shape (..., 6), got {theta.shape}")
    a = dh_transforms(params, theta)
    out: FloatArray = a[..., 0, :, :]
    for i in range(1, 6):
        out = out @ a[..., i, :, :]
    return out


def _acos(x: FloatArray) -> FloatArray:
    """arccos with rounding tolerance at ±1 and NaN beyond it."""
    ok = np.abs(x) <= 1.0 + _COS_TOLERANCE
    return np.arccos(np.where(ok, np.clip(x, -1.0, 1.0), np.nan))


def inverse(params: URParameters, poses: ArrayLike) -> FloatArray:
    """All 8 analytic IK solutions of tool0 poses.

    Parameters
    ----------
    params : the arm.
    poses : shape (..., 4, 4), tool0 in the Base frame, metres (orthonormal rotation).

    Returns
    -------
    Joints (..., 8, 6) in rad, each wrapped to (-pi, pi]; row ``i`` is branch
    ``BRANCH_NAMES[i]`` (see the module docstring). A branch without a solution is a row of NaN:
    ``p5`` closer than ``|d4|`` to axis 1, or frame 4 out of the elbow's reach. Joint limits
    are not applied (see :func:`olp.kinematics.base.turn_variants`).
    """
    t = np.asarray(poses, dtype=np.float64)
    if t.shape[-2:] != (4, 4):
        raise ValueError(f"inverse: expected poses of shape (..., 4, 4), got {t.shape}")
    flat = t.reshape(-1, 4, 4)
    out = np.empty((flat.shape[0], 8, 6))
    with np.errstate(invalid="ignore", divide="ignore"):
        _solve(params, flat, out)
    return out.reshape(*t.shape[:-2], 8, 6)


def _solve(p: URParameters, t: FloatArray, out: FloatArray) -> None:
    """IK of poses t (n, 4, 4) into out (n, 8, 6)."""
    x_axis, y_axis, z_axis, pos = t[:, :3, 0].T, t[:, :3, 1].T, t[:, :3, 2].T, t[:, :3, 3].T
    p5 = pos - p.d6 * z_axis
    phi = np.arctan2(p5[1], p5[0])
    alpha = _acos(p.d4 / np.hypot(p5[0], p5[1]))
    # theta1 = phi + pi/2 + sigma·alpha puts p5 at -sigma·|p5|·sin(alpha) along x1.
    sigma_front = 1.0 if p.a2 < 0 else -1.0
    for shoulder, sigma in ((0, sigma_front), (1, -sigma_front)):
        theta1 = phi + math.pi / 2 + sigma * alpha
        c1, s1 = np.cos(theta1), np.sin(theta1)
        # cos(t5) = z1 · z6 and |sin(t5)| = the part of z6 across z1: atan2 keeps t5 exact
        # near the wrist singularity, where arccos(cos) would lose half the digits.
        cos5 = s1 * z_axis[0] - c1 * z_axis[1]
        gamma5 = np.arctan2(np.hypot(c1 * z_axis[0] + s1 * z_axis[1], z_axis[2]), cos5)
        for wrist, theta5 in ((0, gamma5), (1, -gamma5)):
            theta6 = _theta6(c1, s1, theta5, x_axis, y_axis)
            rows = _arm(p, c1, s1, theta5, theta6, p5, x_axis, y_axis, z_axis)
            for elbow, (theta2, theta3, theta4) in enumerate(rows):
                row = out[:, 4 * shoulder + 2 * elbow + wrist]
                row[:, 0], row[:, 1], row[:, 2] = theta1, theta2, theta3
                row[:, 3], row[:, 4], row[:, 5] = theta4, theta5, theta6
                # A NaN anywhere (out of reach) makes the whole row NaN.
                row += 0.0 * np.sum(row, axis=-1, keepdims=True)
                row[:] = wrap_joints(row)


def _theta6(
    c1: FloatArray, s1: FloatArray, theta5: FloatArray, x_axis: FloatArray, y_axis: FloatArray
) -> FloatArray:
    """Axis 6 from ``z1 · x6 = cos(t6) sin(t5)`` and ``z1 · y6 = -sin(t6) sin(t5)``.

    ``z1 = (s1, -c1, 0)`` is axis 2's direction. At ``sin(t5) = 0`` axis 6 is free: 0.
    """
    sign5 = np.sign(np.sin(theta5))
    y = -(s1 * y_axis[0] - c1 * y_axis[1]) * sign5
    x = (s1 * x_axis[0] - c1 * x_axis[1]) * sign5
    return np.where(sign5 == 0.0, 0.0, np.arctan2(y, x))


def _arm(
    p: URParameters,
    c1: FloatArray,
    s1: FloatArray,
    theta5: FloatArray,
    theta6: FloatArray,
    p5: FloatArray,
    x_axis: FloatArray,
    y_axis: FloatArray,
    z_axis: FloatArray,
) -> tuple[tuple[FloatArray, FloatArray, FloatArray], ...]:
    """Axes 2-4 for both elbows, from frame 4's origin and X axis seen in frame 1.

    Frame 4's origin is ``p5 + d5 · y5`` and its X axis ``cos(t5) · x5 - sin(t5) · z6``, with
    ``x5 = cos(t6) x6 - sin(t6) y6`` and ``y5 = sin(t6) x6 + cos(t6) y6``. In frame 1 (X along
    ``(c1, s1, 0)``, Y up) the origin is ``a2 (c2, s2) + a3 (c23, s23)`` and the X axis points
    at angle ``theta2 + theta3 + theta4``.
    """
    c5, s5, c6, s6 = np.cos(theta5), np.sin(theta5), np.cos(theta6), np.sin(theta6)
    o4 = p5 + p.d5 * (s6 * x_axis + c6 * y_axis)
    x4 = c5 * (c6 * x_axis - s6 * y_axis) - s5 * z_axis
    u = c1 * o4[0] + s1 * o4[1]
    v = o4[2] - p.d1
    theta234 = np.arctan2(x4[2], c1 * x4[0] + s1 * x4[1])
    gamma3 = _acos((u * u + v * v - p.a2 * p.a2 - p.a3 * p.a3) / (2.0 * p.a2 * p.a3))
    up_sign = 1.0 if p.a2 * p.a3 > 0 else -1.0
    rows = []
    for theta3 in (up_sign * gamma3, -up_sign * gamma3):
        theta2 = np.arctan2(v, u) - np.arctan2(p.a3 * np.sin(theta3), p.a2 + p.a3 * np.cos(theta3))
        rows.append((theta2, theta3, theta234 - theta2 - theta3))
    return tuple(rows)
