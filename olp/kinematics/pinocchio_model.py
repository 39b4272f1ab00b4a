"""The OPW arm as a pinocchio chain of six revolute joints.

An independent forward-kinematics path: a joint-by-joint chain instead of the closed form of
:func:`olp.kinematics.opw.forward`, used to cross-check it and to place collision links. The
chain speaks the *controller* joint convention directly: ``theta = q · sign - offset`` is baked
in by turning each joint's axis by its sign and pre-rotating its placement by ``-offset`` about
that axis (rotations about one axis commute, so ``R(theta) = R(-offset) · R(sign · q)``).

Chain (model joints, metres): J1 about Z at the origin; J2 about Y at ``(a1, b, c1)``; J3 about Y
at ``+c2`` along Z; J4 about Z at ``+a2`` along X; J5 about Y at ``+c3`` along Z; J6 about Z at
J5; frame ``"tool0"`` at ``+c4`` along Z of J6 (Z out of the flange). Joints are named
``joint_1`` .. ``joint_6``, each with a body frame ``link_1`` .. ``link_6``.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from olp.kinematics.opw import OPWParameters

FloatArray = NDArray[np.float64]

TOOL0 = "tool0"
"""Name of the flange frame (ROS-Industrial convention) in models from :func:`build_model`."""

LINK_POSE_NAMES: tuple[str, ...] = (*(f"joint_{i}" for i in range(1, 7)), TOOL0)
"""Names of the poses :func:`link_poses` returns, in order."""

_AXES = ("z", "y", "y", "z", "y", "z")
_UNIT = {"y": np.array([0.0, 1.0, 0.0]), "z": np.array([0.0, 0.0, 1.0])}


def _joint_origins(params: OPWParameters) -> list[FloatArray]:
    """Position (3,) of each joint in its parent joint's frame, metres."""
    p = params
    return [
        np.zeros(3),
        np.array([p.a1, p.b, p.c1]),
        np.array([0.0, 0.0, p.c2]),
        np.array([p.a2, 0.0, 0.0]),
        np.array([0.0, 0.0, p.c3]),
        np.zeros(3),
    ]


def _axis_rotation(axis: FloatArray, angle: float) -> FloatArray:
    """Rotation (3, 3) by ``angle`` rad about a unit ``axis`` (3,)."""
    return np.asarray(pin.AngleAxis(angle, axis).matrix(), dtype=np.float64)


def build_model(params: OPWParameters) -> pin.Model:
    """A pinocchio model of the arm whose configuration is the controller joints (6,) in rad.

    Joint position limits are pinocchio's defaults and the links carry no inertia: the model is
    for kinematics (FK, Jacobians, collision link placement); station limits are applied elsewhere.
    """
    model = pin.Model()
    model.name = "opw_arm"
    parent, frame = 0, 0
    for i, (axis_name, origin) in enumerate(zip(_AXES, _joint_origins(params), strict=True)):
        axis = _UNIT[axis_name]
        placement = pin.SE3(_axis_rotation(axis, -params.offsets[i]), origin)
        joint = pin.JointModelRevoluteUnaligned(axis * params.signs[i])
        parent = model.addJoint(parent, joint, placement, f"joint_{i + 1}")
        frame = model.addJointFrame(parent, frame)
        frame = model.addBodyFrame(f"link_{i + 1}", parent, pin.SE3.Identity(), frame)
    tool0 = pin.SE3(np.eye(3), np.array([0.0, 0.0, params.c4]))
    model.addFrame(pin.Frame(TOOL0, parent, frame, tool0, pin.FrameType.OP_FRAME))
    return model


def _configuration(model: pin.Model, q: ArrayLike) -> FloatArray:
    q_arr = np.asarray(q, dtype=np.float64)
    if q_arr.shape != (model.nq,):
        raise ValueError(f"expected joints of shape ({model.nq},), got {q_arr.shape}")
    return q_arr


def fk_pinocchio(model: pin.Model, q: ArrayLike, frame: str = TOOL0) -> FloatArray:
    """Pose (4, 4) in metres of ``frame`` (default tool0) in the base frame.

    ``q``: controller joints (6,) in rad.
    """
    data = model.createData()
    pin.framesForwardKinematics(model, data, _configuration(model, q))
    return np.array(data.oMf[model.getFrameId(frame)].homogeneous)


def link_poses(model: pin.Model, q: ArrayLike) -> list[FloatArray]:
    """Every joint frame and tool0 for controller joints ``q`` (6,) in rad.

    Returns 7 poses (4, 4) in metres in the base frame, named by :data:`LINK_POSE_NAMES`
    (``joint_1`` .. ``joint_6``, ``tool0``). A joint frame sits on its axis and turns with it:
    axes 1, 4 and 6 turn about the frame's Z axis, axes 2, 3 and 5 about its Y axis.
    """
    data = model.createData()
    pin.framesForwardKinematics(model, data, _configuration(model, q))
    joints = [np.array(data.oMi[i].homogeneous) for i in range(1, model.njoints)]
    return [*joints, np.array(data.oMf[model.getFrameId(TOOL0)].homogeneous)]
