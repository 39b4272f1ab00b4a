"""Robot arms as pinocchio models: the OPW chain, standard-DH chains and URDF chains.

The OPW arm as a pinocchio chain of six revolute joints.

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


# --------------------------------------------------------------------------------------------
# Chains from a DH table and from URDF files


def build_dh_model(
    a: ArrayLike, alpha: ArrayLike, d: ArrayLike, theta_offset: ArrayLike | None = None
) -> pin.Model:
    """A revolute chain from a standard (distal) DH table, metres and rad.

    Row ``i``: ``A_i = Rz(q_i + theta_offset_i) · Tz(d_i) · Tx(a_i) · Rx(alpha_i)``; the
    configuration is ``q`` (n,) in rad. Joint ``joint_i`` turns about Z of frame ``i - 1``; its
    body frame ``link_i`` is frame ``i - 1`` turned by the joint (shapes attached to link ``i``
    are given there: the link runs from the origin to ``(a_i, 0, d_i)`` rotated by
    ``theta_offset_i``). ``tool0`` is DH frame ``n``.
    """
    rows = [np.asarray(v, dtype=np.float64) for v in (a, alpha, d)]
    n = rows[0].shape[0]
    offsets = np.zeros(n) if theta_offset is None else np.asarray(theta_offset, np.float64)
    if any(r.shape != (n,) for r in (*rows, offsets)):
        raise ValueError("build_dh_model: a, alpha, d and theta_offset need the same length")
    model = pin.Model()
    model.name = "dh_chain"
    parent, frame = 0, 0
    fixed = pin.SE3.Identity()
    for i in range(n):
        placement = fixed * pin.SE3(_axis_rotation(_UNIT["z"], float(offsets[i])), np.zeros(3))
        parent = model.addJoint(parent, pin.JointModelRZ(), placement, f"joint_{i + 1}")
        frame = model.addJointFrame(parent, frame)
        frame = model.addBodyFrame(f"link_{i + 1}", parent, pin.SE3.Identity(), frame)
        fixed = pin.SE3(
            _axis_rotation(np.array([1.0, 0.0, 0.0]), float(rows[1][i])),
            np.array([rows[0][i], 0.0, rows[2][i]]),
        )
    model.addFrame(pin.Frame(TOOL0, parent, frame, fixed, pin.FrameType.OP_FRAME))
    return model


class ChainError(ValueError):
    """A URDF chain that cannot serve as a robot (unknown link, no moving joint)."""


def load_urdf_model(path: str, tip: str, base: str | None = None) -> pin.Model:
    """The revolute/prismatic chain of a URDF file from its root (or ``base``) to link ``tip``.

    Joints not on that chain are locked at 0; a frame ``tool0`` is added at ``tip``, and the
    chain is expressed in ``base`` when given. Raises :class:`ChainError` naming a missing link
    or a chain without moving joints; pinocchio's own exception on an unreadable file.
    """
    full = pin.buildModelFromUrdf(path)
    if not full.existFrame(tip):
        raise ChainError(f"link {tip!r} is not in the URDF ({_link_names(full)})")
    tip_frame = full.frames[full.getFrameId(tip)]
    chain = set(_support(full, tip_frame.parentJoint))
    locked = [j for j in range(1, full.njoints) if j not in chain]
    model = pin.buildReducedModel(full, locked, pin.neutral(full)) if locked else full
    if model.nq == 0:
        raise ChainError(f"no moving joint between the URDF's root and link {tip!r}")
    tip_id = model.getFrameId(tip)
    tip_frame = model.frames[tip_id]
    model.addFrame(
        pin.Frame(TOOL0, tip_frame.parentJoint, tip_id, tip_frame.placement, pin.FrameType.OP_FRAME)
    )
    if base is not None:
        if not model.existFrame(base):
            raise ChainError(f"link {base!r} is not in the URDF ({_link_names(model)})")
        _rebase(model, base)
    return model


def _support(model: pin.Model, joint: int) -> list[int]:
    """Joints from the root to ``joint`` (inclusive), universe excluded."""
    out = []
    while joint > 0:
        out.append(joint)
        joint = model.parents[joint]
    return out


def _link_names(model: pin.Model) -> str:
    names = [f.name for f in model.frames if f.type == pin.FrameType.BODY]
    return "links: " + ", ".join(names)


def _rebase(model: pin.Model, base: str) -> None:
    """Express the model in frame ``base``, which must be fixed to the universe."""
    frame = model.frames[model.getFrameId(base)]
    if frame.parentJoint != 0:
        raise ChainError(f"base link {base!r} moves with a joint; give a fixed link")
    shift = frame.placement.inverse()
    for j in range(1, model.njoints):
        if model.parents[j] == 0:
            model.jointPlacements[j] = shift * model.jointPlacements[j]
    for f in model.frames:
        if f.parentJoint == 0:
            f.placement = shift * f.placement


def frame_poses(model: pin.Model, q: ArrayLike, frame: str = TOOL0) -> FloatArray:
    """Poses (N, 4, 4) of ``frame`` for configurations q (N, nq): one pinocchio call each."""
    data = model.createData()
    frame_id = model.getFrameId(frame)
    configs = np.asarray(q, dtype=np.float64).reshape(-1, model.nq)
    out = np.empty((len(configs), 4, 4))
    for i, qi in enumerate(configs):
        pin.framesForwardKinematics(model, data, qi)
        out[i] = data.oMf[frame_id].homogeneous
    return out
