"""Vendor-neutral robot configurations: which IK branch and turn a joint vector lies in, and which
IK candidates satisfy an :class:`olp.ir.Configuration`.

The branch flags are the OPW branch semantics of :mod:`olp.kinematics.opw` (see its docstring):

* shoulder ``"back"`` when the wrist centre has x < 0 in the frame that turns with axis 1
  (:func:`olp.kinematics.opw.wrist_x_in_a1`), else ``"front"``;
* elbow ``"down"`` when ``theta3 + atan2(a2, c3) < 0`` (model joint 3, wrapped to (-pi, pi]):
  the wrist centre lies behind the line of the lower arm; else ``"up"``;
* wrist ``"flip"`` when the controller's axis 5 is negative, else ``"noflip"`` (the definition
  of :class:`olp.ir.Configuration`; it equals the OPW row's wrist bit because no bundled robot
  has an axis-5 offset).

Exactly on a boundary (wrist centre on axis 1, arm stretched, axis 5 at 0) the flag takes the
"front"/"up"/"noflip" side; two IK branches coincide there, so no encoding can tell them apart.

Joint values are controller joints (rad). Given a robot or its OPW kinematics, the joint
coupling of the kinematics (Fanuc's J3 counted from the horizontal, see
:mod:`olp.kinematics.base`) is applied before :func:`olp.kinematics.opw.to_model_joints`; given
bare :class:`~olp.kinematics.opw.OPWParameters`, joints are taken in the parameters' own
convention. Only OPW arms have these flags: UR arms write no configuration, and a TypeError says
so.

Vendor encodings (KUKA Status/Turn, ABB confdata, Fanuc CONFIG) translate to and from these
flags and to ``joint_ranges`` in :mod:`olp.vendors`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, Protocol, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.geometry import wrap_half_open
from olp.ir import Configuration
from olp.kinematics import opw
from olp.kinematics.opw import OPWParameters

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

TOLERANCE = 1e-9
"""Default slack (rad for angles, m for the wrist-centre x) of :func:`satisfies`: IK solutions
carry rounding of ~1e-12, so a candidate on a boundary may land on either side of it."""

SNAP = 1e-12
"""Angles within this many rad of a vendor boundary (a multiple of 90° or 180°) count as on it
(:func:`snap`): degrees typed at the edge reach olp as ``radians(deg)`` with a few ulp of error,
and a quadrant must not depend on that. Smaller than :data:`TOLERANCE` so that a snapped joint
still satisfies its own range."""


class OPWArm(Protocol):
    """OPW kinematics behind a joint coupling, such as
    :class:`olp.kinematics.models.OPWKinematics`."""

    @property
    def params(self) -> OPWParameters: ...

    def chain_joints(self, joints: ArrayLike) -> FloatArray: ...


class HasKinematics(Protocol):
    """A robot, such as :class:`olp.station.model.Robot`."""

    @property
    def kinematics(self) -> object: ...


ArmModel: TypeAlias = "OPWParameters | OPWArm | HasKinematics"
"""What the functions here accept as the arm: OPW parameters (joints in the parameters' own
convention), OPW kinematics with a coupling, or a robot whose ``kinematics`` is either."""


def opw_parameters(model: ArmModel) -> OPWParameters:
    """The OPW parameters of ``model``; TypeError for an arm that is not OPW (UR, numeric)."""
    return _resolve(model)[0]


def model_joints_input(model: ArmModel, joints: ArrayLike) -> FloatArray:
    """The joints (..., 6) the OPW parameters expect, from controller joints (..., 6) in rad:
    the robot's joint coupling applied (Fanuc J3 + J2), identity otherwise."""
    arm = _resolve(model)[1]
    q = np.asarray(joints, dtype=np.float64)
    return q if arm is None else np.asarray(arm.chain_joints(q), dtype=np.float64)


def _resolve(model: ArmModel) -> tuple[OPWParameters, OPWArm | None]:
    kinematics = getattr(model, "kinematics", model)
    if isinstance(kinematics, OPWParameters):
        return kinematics, None
    params = getattr(kinematics, "params", None)
    if isinstance(params, OPWParameters) and hasattr(kinematics, "chain_joints"):
        return params, kinematics  # type: ignore[return-value]
    raise TypeError(
        f"configuration flags need an OPW arm (KUKA, ABB, Fanuc), got {type(kinematics).__name__}"
    )


@dataclass(frozen=True, slots=True, eq=False)
class BranchFlags:
    """Branch flags of joint vectors, each a bool array of shape (...,); see the module docstring.

    ``back``: shoulder "back". ``down``: elbow "down". ``flip``: controller axis 5 < 0.
    """

    back: BoolArray
    down: BoolArray
    flip: BoolArray


def elbow_angle(model: ArmModel, joints: ArrayLike) -> FloatArray:
    """``theta3 + atan2(a2, c3)`` (...,) in rad, wrapped to (-pi, pi], of controller joints
    (..., 6): the forearm's turn (towards +x of the lower arm) away from the line of the lower arm
    at which the wrist centre lies on that line. Negative means elbow "down"."""
    params = opw_parameters(model)
    theta = opw.to_model_joints(params, model_joints_input(model, joints))
    return wrap_half_open(theta[..., 2] + math.atan2(params.a2, params.c3))


def wrist_x(model: ArmModel, joints: ArrayLike) -> FloatArray:
    """Wrist-centre x (...,) in metres in the frame turning with axis 1, of controller joints
    (..., 6) in rad (:func:`olp.kinematics.opw.wrist_x_in_a1` after the joint coupling)."""
    return opw.wrist_x_in_a1(opw_parameters(model), model_joints_input(model, joints))


def branch_flags(model: ArmModel, joints: ArrayLike) -> BranchFlags:
    """Shoulder, elbow and wrist flags of controller joints (..., 6) in rad."""
    q = np.asarray(joints, dtype=np.float64)
    return BranchFlags(
        back=np.asarray(wrist_x(model, q) < 0),
        down=np.asarray(elbow_angle(model, q) < 0),
        flip=np.asarray(q[..., 4] < 0),
    )


def configuration_of(model: ArmModel, joints: ArrayLike, *, turns: bool = True) -> Configuration:
    """The configuration that selects exactly ``joints`` among a pose's IK solutions.

    Parameters
    ----------
    model : OPW parameters or a robot with ``.kinematics``.
    joints : shape (6,), controller joints in rad.
    turns : also pin every joint's turn: ``joint_ranges[i] = (q_i - pi, q_i + pi)``, which holds
        ``q_i`` and none of its ``± 2 pi`` variants. Without it, ``joint_ranges`` is None and only
        the branch is asked for.
    """
    q = np.asarray(joints, dtype=np.float64)
    if q.shape != (6,):
        raise ValueError(f"configuration_of: expected joints of shape (6,), got {q.shape}")
    flags = branch_flags(model, q)
    ranges = tuple((float(v) - math.pi, float(v) + math.pi) for v in q) if turns else None
    return make_configuration(
        bool(flags.back), bool(flags.down), bool(flags.flip), joint_ranges=ranges
    )


def make_configuration(
    back: bool | None,
    down: bool | None,
    flip: bool | None,
    joint_ranges: tuple[tuple[float, float] | None, ...] | None = None,
) -> Configuration:
    """An :class:`olp.ir.Configuration` from flags (None: no request) and joint ranges."""
    shoulder: Literal["front", "back"] | None = None
    elbow: Literal["up", "down"] | None = None
    wrist: Literal["flip", "noflip"] | None = None
    if back is not None:
        shoulder = "back" if back else "front"
    if down is not None:
        elbow = "down" if down else "up"
    if flip is not None:
        wrist = "flip" if flip else "noflip"
    return Configuration(shoulder=shoulder, elbow=elbow, wrist=wrist, joint_ranges=joint_ranges)


def satisfies(
    config: Configuration, candidates: ArrayLike, model: ArmModel, *, tol: float = TOLERANCE
) -> BoolArray:
    """Which joint candidates meet a configuration request.

    Parameters
    ----------
    config : the request; a None field asks nothing.
    candidates : shape (K, 6) (or (..., 6)), controller joints in rad, e.g. every IK solution of
        a pose with its turn variants (:func:`olp.kinematics.base.turn_variants`). NaN rows
        never satisfy.
    model : OPW parameters or a robot with ``.kinematics``.
    tol : slack in rad (angles) and m (wrist-centre x). Each ``joint_ranges`` entry
        ``(low, high)`` is read as ``[low - tol, high + tol]``: IK rounding makes open and closed
        ends indistinguishable, so the vendor modules settle exact boundary cases when they encode
        joints, and a candidate within ``tol`` of a boundary passes on both sides of it.

    Returns
    -------
    Mask of shape (K,) (or (...,)). A request built from planned joints (:func:`configuration_of`
    or a vendor encoding of them) passes exactly those joints, except where a joint whose turn
    the encoding does not carry (ABB and Fanuc: axes 2, 3, 5; KUKA T: a sign only) has a range
    that holds two turns of the same angle (the bundled Fanuc J3 ranges do): then each such
    turn passes and the caller chooses (resolve: the candidate nearest the previous joints).
    """
    q = np.asarray(candidates, dtype=np.float64)
    ok = np.all(np.isfinite(q), axis=-1)
    if config.shoulder is not None:
        x = wrist_x(model, q)
        ok &= x <= tol if config.shoulder == "back" else x >= -tol
    if config.elbow is not None:
        e = elbow_angle(model, q)
        ok &= e <= tol if config.elbow == "down" else e >= -tol
    if config.wrist is not None:
        ok &= q[..., 4] <= tol if config.wrist == "flip" else q[..., 4] >= -tol
    for i, rng in enumerate(config.joint_ranges or ()):
        if rng is not None:
            ok &= (q[..., i] >= rng[0] - tol) & (q[..., i] <= rng[1] + tol)
    return np.asarray(ok)


def snap(angles: ArrayLike, step: float, tol: float = SNAP) -> FloatArray:
    """Angles (rad) within ``tol`` of a multiple of ``step`` (rad) moved onto it; others unchanged.

    Used before a vendor rule that floors at multiples of ``step`` (ABB quadrants, Fanuc turns),
    so that 90° typed in degrees gives the same quadrant as the exact value.
    """
    a = np.asarray(angles, dtype=np.float64)
    grid = np.round(a / step) * step
    return np.where(np.abs(a - grid) <= tol, grid, a)
