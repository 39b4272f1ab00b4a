"""The one kinematics interface every robot model implements, and the helpers all of them share.

A :class:`Kinematics` maps the *controller's* joint values (what the teach pendant shows, in rad)
to poses of the model's ``tool0`` frame (Z out of the flange, the ROS-Industrial convention) in
the robot's kinematic base frame (the mounting face), and back:

* ``forward(q)``: joints (..., dof) -> poses (..., 4, 4), metres;
* ``inverse(poses, seed=None)``: poses (N, 4, 4) -> joints (N, B, dof), one row per branch
  (``branch_names``), NaN rows where a branch has no solution, each joint wrapped to (-pi, pi];
* ``chain_model()`` / ``chain_joints(q)``: a pinocchio model of the same arm and its
  configuration for controller joints ``q`` (for Jacobians, link poses and collision bodies).

Implementations: :class:`olp.kinematics.models.OPWKinematics` (KUKA, ABB, Fanuc arms),
:class:`olp.kinematics.models.URKinematics` (Universal Robots) and
:class:`olp.kinematics.models.ChainKinematics` (any URDF or DH chain, numeric IK).

Joint couplings
---------------
Some controllers count a joint relative to another one. Fanuc's J3 is measured from the
horizontal, so the model's (and ROS-Industrial's) J3 is ``J3 + J2`` (see
:data:`FANUC_J2_J3`). A :class:`JointCoupling` ``C`` maps controller joints to the model chain's
joints, ``q_chain = C · q``; ``C`` is an integer matrix whose inverse is integer too, so a turn
(2 pi) of a controller joint stays a whole number of turns of chain joints and back. Every
implementation applies it, so callers only ever see controller values.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]

_TWO_PI = 2.0 * math.pi


@runtime_checkable
class Kinematics(Protocol):
    """Forward and inverse kinematics of one arm in the controller's joint convention."""

    @property
    def dof(self) -> int:
        """Number of joints."""
        ...

    @property
    def branch_names(self) -> tuple[str, ...]:
        """Names of the rows :meth:`inverse` returns per pose (its ``B``)."""
        ...

    def forward(self, joints: ArrayLike) -> FloatArray:
        """tool0 poses (..., 4, 4) in metres for controller joints (..., dof) in rad."""
        ...

    def inverse(self, poses: ArrayLike, seed: ArrayLike | None = None) -> FloatArray:
        """IK of tool0 poses (N, 4, 4): joints (N, B, dof) rad, NaN rows for no solution.

        ``seed`` (dof,): joints to start from; only numeric solvers use it (row 0).
        """
        ...

    def chain_joints(self, joints: ArrayLike) -> FloatArray:
        """Configuration (..., nq) of :meth:`chain_model` for controller joints (..., dof)."""
        ...

    def chain_model(self) -> Any:
        """The arm as a ``pinocchio.Model`` (joint frames ``joint_1``.., frame ``tool0``)."""
        ...


# --------------------------------------------------------------------------------------------
# Joint couplings


@dataclass(frozen=True, slots=True, eq=False)
class JointCoupling:
    """Linear map from controller joints to the model chain's joints: ``q_chain = C · q``.

    ``matrix``: shape (dof, dof), integers, with an integer inverse (so turns stay turns).
    """

    matrix: NDArray[np.int64]
    inverse_matrix: NDArray[np.int64]

    @classmethod
    def identity(cls, dof: int) -> JointCoupling:
        """No coupling."""
        eye = np.eye(dof, dtype=np.int64)
        return cls(eye, eye.copy())

    @classmethod
    def from_terms(cls, dof: int, terms: Sequence[tuple[int, int, int]]) -> JointCoupling:
        """``C = I`` plus ``factor`` at (joint, source) for each ``(joint, source, factor)``.

        Joints count from 0. Raises ValueError unless ``C`` has an integer inverse.
        """
        matrix = np.eye(dof, dtype=np.int64)
        for joint, source, factor in terms:
            if joint == source:
                raise ValueError(f"joint coupling: joint {joint + 1} cannot be coupled to itself")
            matrix[joint, source] += int(factor)
        # An integer matrix has an integer inverse exactly when its determinant is ±1.
        if round(abs(float(np.linalg.det(matrix.astype(np.float64))))) != 1:
            raise ValueError("joint coupling: the matrix must have an integer inverse")
        inverse = np.rint(np.linalg.inv(matrix.astype(np.float64)))
        return cls(matrix, inverse.astype(np.int64))

    @property
    def is_identity(self) -> bool:
        return bool(np.array_equal(self.matrix, np.eye(len(self.matrix), dtype=np.int64)))

    def to_chain(self, joints: ArrayLike) -> FloatArray:
        """Chain joints (..., dof) from controller joints (..., dof), rad."""
        q = np.asarray(joints, dtype=np.float64)
        if self.is_identity:
            return q
        out: FloatArray = q @ self.matrix.T.astype(np.float64)
        return out

    def to_controller(self, chain: ArrayLike) -> FloatArray:
        """Controller joints (..., dof) from chain joints (..., dof), rad, not wrapped."""
        theta = np.asarray(chain, dtype=np.float64)
        if self.is_identity:
            return theta
        out: FloatArray = theta @ self.inverse_matrix.T.astype(np.float64)
        return out


FANUC_J2_J3: tuple[tuple[int, int, int], ...] = ((2, 1, 1),)
"""Fanuc's J2/J3 interaction as coupling terms: model J3 = controller J3 + J2.

Sources: the ROS-Industrial Fanuc driver converts with ``J3_out = J3_in + J23_factor · J2_in``
(``fanuc_driver`` utils, ``linkage_transform``) and sets ``J23_factor = 1`` for the LR Mate
200iC and the M-20iA (``robot_interface_streaming_lrmate200ic.launch``,
``robot_interface_streaming_m20ia.launch`` in ros-industrial/fanuc); shared VENDOR-NOTES record
the same relation, checked against a real-robot reading. Pinned by
``tests/kinematics/test_robots.py``.
"""


# --------------------------------------------------------------------------------------------
# Angles and turns


def wrap_joints(joints: ArrayLike) -> FloatArray:
    """Angles (any shape) mapped to (-pi, pi], as a new array; NaN stays NaN."""
    x = np.array(joints, dtype=np.float64)
    turns = np.ceil((x - math.pi) / _TWO_PI)
    x -= turns * _TWO_PI
    return np.minimum(x, math.pi, out=x)


def turn_shifts(lower: float, upper: float) -> list[float]:
    """Multiples of 2 pi that move some value in (-pi, pi] into [lower, upper], 0 first."""
    lo = math.ceil((lower - math.pi) / _TWO_PI)
    hi = math.floor((upper + math.pi) / _TWO_PI)
    turns = sorted(range(lo, hi + 1), key=lambda m: (abs(m), m))
    return [m * _TWO_PI for m in turns]


def turn_variants(
    q: ArrayLike, lower: ArrayLike, upper: ArrayLike, *, tol: float = 1e-9
) -> FloatArray:
    """Every ``q + 2 pi m`` variant of joint solutions that lies inside the joint limits.

    Parameters
    ----------
    q : shape (..., dof), controller joints in rad (any turn; they are wrapped first).
    lower, upper : shape (dof,), joint limits in rad (inclusive, widened by ``tol``).

    Returns
    -------
    Variants (..., K, dof) in rad, NaN rows for combinations outside the limits (and for NaN
    input). ``K`` depends only on the limits: the product over joints of the number of turns
    ``m`` for which ``(-pi, pi] + 2 pi m`` meets ``[lower, upper]`` (1 for a ±170° joint, 2 for
    KUKA A2 -190..45°, 3 for KUKA A6 ±350° or a UR joint ±360°). Variant 0 is the wrapped ``q``
    itself (NaN if that is outside the limits); the others follow with turns ordered
    0, -1, +1, -2, ... per joint, the last joint varying fastest.
    """
    lo = np.asarray(lower, dtype=np.float64)
    hi = np.asarray(upper, dtype=np.float64)
    base = wrap_joints(q)
    dof = base.shape[-1] if base.ndim else 0
    if lo.shape != (dof,) or hi.shape != (dof,):
        raise ValueError(
            f"turn_variants: joints (..., {dof}) need limits of shape ({dof},), "
            f"got {lo.shape}, {hi.shape}"
        )
    shifts = np.array(
        list(itertools.product(*(turn_shifts(a, b) for a, b in zip(lo, hi, strict=True))))
    ).reshape(-1, dof)
    variants: FloatArray = base[..., None, :] + shifts
    with np.errstate(invalid="ignore"):
        inside = np.all((variants >= lo - tol) & (variants <= hi + tol), axis=-1)
    variants[~inside] = np.nan
    return variants
