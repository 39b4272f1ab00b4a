"""Closed-form kinematics of ortho-parallel 6R arms with a spherical wrist (OPW).

The model and its seven parameters follow M. Brandstötter, A. Angerer, M. Hofbaur, "An analytical
solution of the inverse kinematics problem of industrial serial manipulators with an
ortho-parallel basis and a spherical wrist", Austrian Robotics Workshop 2014. The joint
convention (offsets and signs) is the one of ROS-Industrial's ``opw_kinematics``.

Model
-----
In the *model* joints ``theta`` the arm stands upright at ``theta = 0`` (the "candle"): the wrist
centre is at ``(a1 + a2, b, c1 + c2 + c3)`` and tool0's Z axis points along +Z. Axes 1, 4 and 6
turn about the local Z axis, axes 2, 3 and 5 about the local Y axis::

    wrist centre = Rz(t1) · ((a1, b, c1) + Ry(t2) · ((0, 0, c2) + Ry(t3) · (a2, 0, c3)))
    R(tool0)     = Rz(t1) · Ry(t2 + t3) · Rz(t4) · Ry(t5) · Rz(t6)
    p(tool0)     = wrist centre + c4 · R(tool0) · e_z

tool0 follows the ROS-Industrial convention: Z out of the flange.

Joint convention
----------------
A controller's joint value ``q`` (what the pendant shows, in rad) relates to the model joint by
``theta = q · sign - offset``, so ``q = (theta + offset) · sign``.

IK branch order
---------------
:func:`inverse` returns 8 rows per pose, row ``4·shoulder + 2·elbow + wrist`` (see
:data:`BRANCHES`, :data:`BRANCH_NAMES`, :func:`branch_index`):

* shoulder 0 ``"front"``: the wrist centre has x >= 0 in the frame that turns with axis 1;
  1 ``"back"``: x <= 0 (KUKA's "overhead area", ABB's cfx bit 2).
* elbow 0 ``"up"``: ``theta3 + atan2(a2, c3) >= 0``, i.e. the forearm is turned forward (about
  +Y of the lower arm) relative to the lower arm, so the wrist centre lies in front of the line of
  the lower arm (axis 2 to axis 3). For a front-shoulder pose this is the geometric elbow-up;
  for a back-shoulder pose the elbow then lies *below* the shoulder-wrist line. It is the
  quantity behind KUKA's Status bit 1 (``A3 >= atan(|a2| / c3)``) and, as VENDOR-NOTES describe
  it, ABB's cfx bit 1 (neither checked against a controller here).
  1 ``"down"``: the opposite sign.
* wrist 0 ``"noflip"``: ``sign5 · theta5 >= 0``; 1 ``"flip"``: ``sign5 · theta5 <= 0``. With no
  axis-5 offset (every robot in the bundled library) "flip" is "controller axis 5 negative",
  the definition :class:`olp.ir.Configuration` uses (both rows coincide at axis 5 = 0).

The shoulder and elbow bits are properties of the arm's shape, independent of the joint signs;
the wrist bit follows the controller's sign of axis 5.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.kinematics import base as _base

FloatArray = NDArray[np.float64]

_TWO_PI = 2.0 * math.pi
_COS_TOLERANCE = 1e-9
"""An arccos argument this far outside [-1, 1] is rounding at the workspace boundary: clipped."""
_POSE_ENTRIES = np.array([0, 4, 8, 2, 6, 10, 3, 7, 11])
"""Flat indices in a (4, 4) pose of R[:, 0], R[:, 2] and p, the only entries the IK needs."""
_BLOCK = 8192
"""Poses per block in :func:`inverse`: its ~40 temporaries then stay in the CPU cache."""


@dataclass(frozen=True, slots=True)
class OPWParameters:
    """Geometry (metres) and joint convention of an OPW arm.

    ``a1``: axis-2 offset from axis 1 along X; ``a2``: axis 3 to axis 4 offset (usually negative);
    ``b``: lateral offset along Y; ``c1``: axis-2 height; ``c2``: lower arm (axis 2 to 3);
    ``c3``: forearm (axis 3 to the wrist centre); ``c4``: wrist centre to flange.
    ``offsets`` (6,) rad and ``signs`` (6,) of ±1: ``theta_model = q_controller · sign - offset``.
    """

    a1: float
    a2: float
    b: float
    c1: float
    c2: float
    c3: float
    c4: float
    offsets: tuple[float, ...] = (0.0,) * 6
    signs: tuple[int, ...] = (1,) * 6

    def __post_init__(self) -> None:
        for name in ("a1", "a2", "b", "c1", "c2", "c3", "c4"):
            value = float(getattr(self, name))
            if not math.isfinite(value):
                raise ValueError(f"OPWParameters.{name} must be finite, got {value}")
            object.__setattr__(self, name, value)
        offsets = tuple(float(v) for v in self.offsets)
        if len(offsets) != 6 or not all(math.isfinite(v) for v in offsets):
            raise ValueError(f"OPWParameters.offsets: expected 6 finite values, got {offsets}")
        signs = tuple(self.signs)
        if len(signs) != 6 or any(s not in (1, -1) for s in signs):
            raise ValueError(f"OPWParameters.signs: expected 6 values of +1 or -1, got {signs}")
        if self.c2 == 0.0 or math.hypot(self.a2, self.c3) == 0.0:
            raise ValueError("OPWParameters: c2 and (a2, c3) must be non-zero (no arm to solve)")
        object.__setattr__(self, "offsets", offsets)
        object.__setattr__(self, "signs", tuple(int(s) for s in signs))


# --------------------------------------------------------------------------------------------
# Branches


@dataclass(frozen=True, slots=True)
class Branch:
    """One of the 8 IK branches; see the module docstring for the exact definitions."""

    shoulder: Literal["front", "back"]
    elbow: Literal["up", "down"]
    wrist: Literal["noflip", "flip"]

    @property
    def name(self) -> str:
        """``"front/up/noflip"`` and so on."""
        return f"{self.shoulder}/{self.elbow}/{self.wrist}"


_SHOULDERS: tuple[Literal["front", "back"], ...] = ("front", "back")
_ELBOWS: tuple[Literal["up", "down"], ...] = ("up", "down")
_WRISTS: tuple[Literal["noflip", "flip"], ...] = ("noflip", "flip")

BRANCHES: tuple[Branch, ...] = tuple(
    Branch(s, e, w) for s in _SHOULDERS for e in _ELBOWS for w in _WRISTS
)
"""The 8 branches in :func:`inverse`'s row order: index ``4·shoulder + 2·elbow + wrist``."""

BRANCH_NAMES: tuple[str, ...] = tuple(b.name for b in BRANCHES)
"""``BRANCH_NAMES[i]`` describes row ``i`` of :func:`inverse`, e.g. ``"back/up/flip"`` for 5."""


def branch_index(
    shoulder: Literal["front", "back"],
    elbow: Literal["up", "down"],
    wrist: Literal["noflip", "flip"],
) -> int:
    """Row of :func:`inverse` that holds the given branch."""
    return BRANCHES.index(Branch(shoulder, elbow, wrist))


# --------------------------------------------------------------------------------------------
# Joint convention


def to_model_joints(params: OPWParameters, q: ArrayLike) -> FloatArray:
    """Model joints ``theta = q · sign - offset`` (..., 6) rad from controller joints (..., 6)."""
    return np.asarray(q, dtype=np.float64) * params.signs - np.asarray(params.offsets)


def to_controller_joints(params: OPWParameters, theta: ArrayLike) -> FloatArray:
    """Controller joints ``q = (theta + offset) · sign`` (..., 6) rad, not wrapped."""
    return (np.asarray(theta, dtype=np.float64) + params.offsets) * params.signs


def _wrap(x: FloatArray) -> FloatArray:
    """Angles mapped to (-pi, pi] in place (``np.mod`` costs tens of times more).

    ``x - 2 pi · ceil((x - pi) / (2 pi))``: dividing (not multiplying by ``1 / (2 pi)``) keeps
    ``x = -pi`` exactly on -1, so it maps to +pi; the final clamp catches an ulp above pi.
    """
    turns = np.subtract(x, math.pi)
    turns /= _TWO_PI
    np.ceil(turns, out=turns)
    turns *= _TWO_PI
    x -= turns
    return np.minimum(x, math.pi, out=x)


# --------------------------------------------------------------------------------------------
# Forward kinematics


def _rz_ry(ca: FloatArray, sa: FloatArray, cb: FloatArray, sb: FloatArray) -> FloatArray:
    """Rotations ``Rz(a) · Ry(b)`` (..., 3, 3) from cosines and sines of a and b."""
    r = np.empty((*ca.shape, 3, 3))
    r[..., 0, 0] = ca * cb
    r[..., 0, 1] = -sa
    r[..., 0, 2] = ca * sb
    r[..., 1, 0] = sa * cb
    r[..., 1, 1] = ca
    r[..., 1, 2] = sa * sb
    r[..., 2, 0] = -sb
    r[..., 2, 1] = 0.0
    r[..., 2, 2] = cb
    return r


def _rz(ca: FloatArray, sa: FloatArray) -> FloatArray:
    """Rotations ``Rz(a)`` (..., 3, 3) from the cosines and sines of a."""
    return _rz_ry(ca, sa, np.ones_like(ca), np.zeros_like(ca))


def _arm_x_z(params: OPWParameters, theta: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Wrist centre x and z (...,) m in the frame turning with axis 1, from model joints."""
    t2, t23 = theta[..., 1], theta[..., 1] + theta[..., 2]
    c23, s23 = np.cos(t23), np.sin(t23)
    x = params.a1 + params.c2 * np.sin(t2) + params.a2 * c23 + params.c3 * s23
    z = params.c1 + params.c2 * np.cos(t2) - params.a2 * s23 + params.c3 * c23
    return x, z


def forward(params: OPWParameters, q: ArrayLike) -> FloatArray:
    """Poses of tool0 in the robot base frame.

    Parameters
    ----------
    params : the arm.
    q : shape (..., 6), controller joints in rad (e.g. (N, 6) or (6,)).

    Returns
    -------
    Poses (..., 4, 4), metres: (4, 4) for a (6,) input.
    """
    theta = to_model_joints(params, q)
    if theta.shape[-1:] != (6,):
        raise ValueError(f"forward: expected joints of shape (..., 6), got {theta.shape}")
    c, s = np.cos(theta), np.sin(theta)
    t23 = theta[..., 1] + theta[..., 2]
    arm = _rz_ry(c[..., 0], s[..., 0], np.cos(t23), np.sin(t23))
    wrist = _rz_ry(c[..., 3], s[..., 3], c[..., 4], s[..., 4])
    rotation = arm @ wrist @ _rz(c[..., 5], s[..., 5])
    x, z = _arm_x_z(params, theta)
    out = np.zeros((*theta.shape[:-1], 4, 4))
    out[..., :3, :3] = rotation
    out[..., 0, 3] = c[..., 0] * x - s[..., 0] * params.b + params.c4 * rotation[..., 0, 2]
    out[..., 1, 3] = s[..., 0] * x + c[..., 0] * params.b + params.c4 * rotation[..., 1, 2]
    out[..., 2, 3] = z + params.c4 * rotation[..., 2, 2]
    out[..., 3, 3] = 1.0
    return out


def wrist_x_in_a1(params: OPWParameters, q: ArrayLike) -> FloatArray:
    """Wrist-centre x (...,) in metres in the frame turning with axis 1 (origin on axis 1).

    Negative means the wrist centre is behind axis 1 ("back" shoulder; KUKA Status bit 0, ABB
    cfx bit 2). ``q``: controller joints (..., 6) in rad.
    """
    return _arm_x_z(params, to_model_joints(params, q))[0]


def wrist_centre(params: OPWParameters, poses: ArrayLike) -> FloatArray:
    """Wrist centres (..., 3) in metres of tool0 poses (..., 4, 4): ``p - c4 · z_axis``."""
    t = np.asarray(poses, dtype=np.float64)
    return t[..., :3, 3] - params.c4 * t[..., :3, 2]


# --------------------------------------------------------------------------------------------
# Inverse kinematics


@dataclass(frozen=True, slots=True)
class _Constants:
    """Pose-independent terms of the IK, computed once per call."""

    p: OPWParameters
    k: float  # distance axis 3 to wrist centre
    psi3: float  # angle of (a2, c3) from the forearm's axis
    cos_psi3: float
    sin_psi3: float
    c2k_sq: float  # c2² + k²
    inv_2c2k: float
    offsets: tuple[float, ...]
    flip_col: int  # wrist bit of the theta5 >= 0 solution


def _constants(p: OPWParameters) -> _Constants:
    k = math.hypot(p.a2, p.c3)
    return _Constants(
        p=p,
        k=k,
        psi3=math.atan2(p.a2, p.c3),
        cos_psi3=p.c3 / k,
        sin_psi3=p.a2 / k,
        c2k_sq=p.c2 * p.c2 + k * k,
        inv_2c2k=1.0 / (2.0 * p.c2 * k),
        offsets=p.offsets,
        flip_col=1 if p.signs[4] < 0 else 0,
    )


def inverse(
    params: OPWParameters, poses: ArrayLike, *, out: FloatArray | None = None
) -> FloatArray:
    """All 8 analytic IK solutions of tool0 poses.

    Parameters
    ----------
    params : the arm.
    poses : shape (..., 4, 4), tool0 in the robot base frame, metres; the rotation part must be
        orthonormal (not checked).
    out : optional preallocated float64 array of shape (N, 8, 6) for N poses, filled in place.

    Returns
    -------
    Joints (..., 8, 6) in rad, controller convention, each wrapped to (-pi, pi]; row ``i`` is
    branch ``BRANCH_NAMES[i]``. A branch with no solution (wrist centre out of reach) is a row of
    NaN. Joint limits are not applied: see :func:`turn_variants`. At the wrist singularity
    (axis 5 at 0) axis 4 is set from the numerically available split and axis 6 absorbs the
    rest, so every returned row reproduces the pose. A wrist centre exactly on axis 1 (b = 0)
    gets axis 1 at 0 (front) or pi (back); one exactly on axis 2 (only when c2 = |(a2, c3)|)
    gives NaN rather than the infinitely many solutions.
    """
    t = np.asarray(poses, dtype=np.float64)
    if t.shape[-2:] != (4, 4):
        raise ValueError(f"inverse: expected poses of shape (..., 4, 4), got {t.shape}")
    flat = t.reshape(-1, 4, 4)
    n = flat.shape[0]
    if out is None:
        result = np.empty((n, 8, 6))
    elif out.shape != (n, 8, 6) or out.dtype != np.float64:
        raise ValueError(f"inverse: out must be float64 of shape {(n, 8, 6)}, got {out.shape}")
    else:
        result = out
    k = _constants(params)
    with np.errstate(invalid="ignore", divide="ignore"):
        # Blocks, not poses: the loop only keeps the temporaries cache-sized.
        for start in range(0, n, _BLOCK):
            _solve_block(k, flat[start : start + _BLOCK], result[start : start + _BLOCK])
    return result if t.ndim == 3 else result.reshape(*t.shape[:-2], 8, 6)


def _solve_block(k: _Constants, t: FloatArray, out: FloatArray) -> None:
    """IK of poses t (n, 4, 4) into out (n, 8, 6)."""
    p = k.p
    # One gather into contiguous rows: the entries below are read several times each.
    r00, r10, r20, r02, r12, r22, px, py, pz = t.reshape(-1, 16).T[_POSE_ENTRIES]
    cx = px - p.c4 * r02
    cy = py - p.c4 * r12
    w = pz - p.c4 * r22 - p.c1
    rho_sq = cx * cx + cy * cy
    # Distance of the wrist centre from axis 1 in the arm plane; NaN inside the |b| cylinder.
    reach = np.sqrt(rho_sq - p.b * p.b) if p.b else np.sqrt(rho_sq)
    inv_rho_sq = 1.0 / rho_sq
    on_axis1 = rho_sq == 0.0
    for shoulder, sign in ((0, 1.0), (1, -1.0)):
        x_arm = reach if sign > 0 else -reach
        # Axis-1 angle from rotating (x_arm, b) onto (cx, cy), without trig.
        c1 = (x_arm * cx + p.b * cy) * inv_rho_sq
        s1 = (x_arm * cy - p.b * cx) * inv_rho_sq
        if p.b == 0.0 and on_axis1.any():
            c1[on_axis1] = sign
            s1[on_axis1] = 0.0
        theta1 = np.arctan2(s1, c1)
        arm = _solve_arm(k, x_arm - p.a1, w)
        # Rows of Rz(-theta1) · R, columns 0 and 2 (column 1 follows from orthonormality).
        a0 = c1 * r00 + s1 * r10
        a2 = c1 * r02 + s1 * r12
        b0 = c1 * r10 - s1 * r00
        b2 = c1 * r12 - s1 * r02
        theta1 += arm.poison
        q1 = _controller(k, 0, theta1)
        for elbow, (theta2, theta3, c23, s23) in enumerate(arm.elbows):
            row = 4 * shoulder + 2 * elbow
            out[:, row, 0] = q1
            out[:, row + 1, 0] = q1
            q2, q3 = _controller(k, 1, theta2), _controller(k, 2, theta3)
            out[:, row, 1] = q2
            out[:, row + 1, 1] = q2
            out[:, row, 2] = q3
            out[:, row + 1, 2] = q3
            theta4, theta5, theta6 = _solve_wrist(a0, a2, b0, b2, r20, r22, c23, s23)
            col = row + k.flip_col
            out[:, col, 3] = _controller(k, 3, theta4)
            out[:, col, 4] = _controller(k, 4, theta5)
            out[:, col, 5] = _controller(k, 5, theta6)
            col = row + 1 - k.flip_col
            out[:, col, 3] = _controller(k, 3, theta4 + math.pi)
            out[:, col, 4] = _controller(k, 4, np.negative(theta5, out=theta5))
            out[:, col, 5] = _controller(k, 5, theta6 + math.pi)


def _controller(k: _Constants, j: int, theta: FloatArray) -> FloatArray:
    """Controller value of model joint j, wrapped to (-pi, pi], as a new array."""
    q = theta + k.offsets[j] if k.offsets[j] else theta.copy()
    if k.p.signs[j] < 0:
        np.negative(q, out=q)
    return _wrap(q)


@dataclass(frozen=True, slots=True)
class _Arm:
    """Both elbow solutions of one shoulder: (theta2, theta3, cos, sin of theta2 + theta3)."""

    elbows: tuple[tuple[FloatArray, FloatArray, FloatArray, FloatArray], ...]
    poison: FloatArray  # 0, or NaN where the wrist centre is out of reach


def _solve_arm(k: _Constants, u: FloatArray, w: FloatArray) -> _Arm:
    """Axes 2 and 3 for a wrist centre at (u, w) from axis 2 in the arm plane (x, z).

    gamma = theta3 + psi3 is the forearm's angle to the lower arm (law of cosines); alpha is the
    angle between the lower arm and the line from axis 2 to the wrist centre.
    """
    p = k.p
    s_sq = u * u + w * w
    d_raw = (s_sq - k.c2k_sq) * k.inv_2c2k
    d = np.where(np.abs(d_raw) <= 1.0 + _COS_TOLERANCE, np.clip(d_raw, -1.0, 1.0), np.nan)
    gamma = np.arccos(d)
    sin_g = np.sqrt(1.0 - d * d)
    alpha_x = k.k * sin_g
    alpha_z = p.c2 + k.k * d
    alpha = np.arctan2(alpha_x, alpha_z)
    phi = np.arctan2(u, w)
    inv_s = 1.0 / np.sqrt(s_sq)
    cos_phi, sin_phi = w * inv_s, u * inv_s
    cos_a, sin_a = alpha_z * inv_s, alpha_x * inv_s
    # theta2 + theta3 = (phi - psi3) ± (gamma - alpha): its cosine and sine without trig.
    cos_e = d * cos_a + sin_g * sin_a
    sin_e = sin_g * cos_a - d * sin_a
    cos_b = cos_phi * k.cos_psi3 + sin_phi * k.sin_psi3
    sin_b = sin_phi * k.cos_psi3 - cos_phi * k.sin_psi3
    cc, ss, cs, sc = cos_b * cos_e, sin_b * sin_e, cos_b * sin_e, sin_b * cos_e
    up = (phi - alpha, gamma - k.psi3, cc - ss, sc + cs)
    down = (phi + alpha, -gamma - k.psi3, cc + ss, sc - cs)
    return _Arm(elbows=(up, down), poison=d * 0.0)


def _solve_wrist(
    a0: FloatArray,
    a2: FloatArray,
    b0: FloatArray,
    b2: FloatArray,
    r20: FloatArray,
    r22: FloatArray,
    c23: FloatArray,
    s23: FloatArray,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Axes 4-6 (theta5 >= 0 solution) from ``W = Ry(-theta23) · Rz(-theta1) · R``.

    ``W = Rz(t4) Ry(t5) Rz(t6)``. theta6 is solved from W *given* theta4 and theta5
    (``Rz(t6) = Ry(-t5) Rz(-t4) W``), so the three stay consistent even next to the wrist
    singularity, where theta4 alone is ill-conditioned.
    """
    w00 = c23 * a0 - s23 * r20
    w02 = c23 * a2 - s23 * r22
    w20 = s23 * a0 + c23 * r20
    w22 = s23 * a2 + c23 * r22
    theta4 = np.arctan2(b2, w02)
    h_sq = b2 * b2 + w02 * w02
    h = np.sqrt(h_sq)
    theta5 = np.arctan2(h, w22)
    # Both terms carry the factor h = sin(theta5) >= 0, which leaves the atan2 unchanged.
    y6 = w02 * b0 - b2 * w00
    x6 = w22 * (w02 * w00 + b2 * b0) - h_sq * w20
    theta6 = np.arctan2(y6, x6)
    singular = h < 1e-150
    if singular.any():
        c4, s4 = np.cos(theta4[singular]), np.sin(theta4[singular])
        c5 = np.copysign(1.0, w22[singular])
        v00, v10 = w00[singular], b0[singular]
        theta6[singular] = np.arctan2(c4 * v10 - s4 * v00, c5 * (c4 * v00 + s4 * v10))
    return theta4, theta5, theta6


# --------------------------------------------------------------------------------------------
# Turns: shared by every kinematics type, kept importable from here.

turn_variants = _base.turn_variants
