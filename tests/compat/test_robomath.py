"""``robodk.robomath`` / ``robodk.robofileio`` on olp: RoboDK's names, argument orders, units
and return shapes, each pinned against an independent formula (scipy) and the sentence of
RoboDK's API reference (``robodk/robomath.py`` docstrings) that states it."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from olp.compat.robodk import robofileio as fio
from olp.compat.robodk import robomath as rm
from olp.frontends.dsl import run_dsl

XYZ = [12.5, -40.0, 300.0]
ANGLES = [[15.0, -40.0, 120.0], [0.0, 90.0, 30.0], [-180.0, 0.0, 180.0], [170.0, -89.0, -5.0]]


def _m(mat: rm.Mat) -> np.ndarray:
    return np.array(mat)


def _pose(rotation: np.ndarray, xyz: list[float] = XYZ) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rotation, xyz
    return out


def test_rotations_take_radians_and_transl_mm() -> None:
    """robomath.rotx: "Returns a rotation matrix around the X axis (radians)"; transl: mm."""
    assert np.allclose(
        _m(rm.rotx(math.pi / 2))[:3, :3], Rotation.from_euler("x", 90, degrees=True).as_matrix()
    )
    assert np.allclose(_m(rm.roty(0.3))[:3, :3], Rotation.from_rotvec([0, 0.3, 0]).as_matrix())
    assert np.allclose(_m(rm.rotz(-1.0))[:3, :3], Rotation.from_rotvec([0, 0, -1.0]).as_matrix())
    assert _m(rm.transl(1, 2, 3))[:3, 3].tolist() == [1, 2, 3]
    assert _m(rm.transl([4, 5, 6]))[:3, 3].tolist() == [4, 5, 6]


@pytest.mark.parametrize("angles", ANGLES)
def test_pose_is_transl_rotx_roty_rotz_in_degrees(angles: list[float]) -> None:
    """robomath.Pose: "H = transl(x,y,z)*rotx(rx*pi/180)*roty(ry*pi/180)*rotz(rz*pi/180)"."""
    expected = _pose(Rotation.from_euler("XYZ", angles, degrees=True).as_matrix())
    assert np.allclose(_m(rm.Pose(*XYZ, *angles)), expected)


@pytest.mark.parametrize("angles", ANGLES)
def test_txyzrxyz_radians_round_trip(angles: list[float]) -> None:
    """TxyzRxyz_2_Pose: "[x,y,z,rx,ry,rz] ... position (mm) and Euler angles (rad) ...
    H = transl(x,y,z)*rotx(rx)*roty(ry)*rotz(rz)"; Pose_2_TxyzRxyz is its inverse."""
    rad = np.radians(angles).tolist()
    pose = rm.TxyzRxyz_2_Pose([*XYZ, *rad])
    assert np.allclose(_m(pose), _m(rm.Pose(*XYZ, *angles)))
    values = rm.Pose_2_TxyzRxyz(pose)
    assert len(values) == 6 and np.allclose(values[:3], XYZ)
    assert np.allclose(_m(rm.TxyzRxyz_2_Pose(values)), _m(pose))  # exact also at ry = 90 deg


@pytest.mark.parametrize("angles", ANGLES)
def test_xyzrpw_is_transl_rotz_roty_rotx(angles: list[float]) -> None:
    """xyzrpw_2_pose([x,y,z,r,p,w]): "H = transl(x,y,z)*rotz(w*pi/180)*roty(p*pi/180)*
    rotx(r*pi/180)" (note the order: r first in the list, applied last)."""
    r, p, w = angles
    expected = _pose(Rotation.from_euler("ZYX", [w, p, r], degrees=True).as_matrix())
    pose = rm.xyzrpw_2_pose([*XYZ, r, p, w])
    assert np.allclose(_m(pose), expected)
    assert np.allclose(_m(rm.xyzrpw_2_pose(rm.pose_2_xyzrpw(pose))), expected)


@pytest.mark.parametrize("angles", ANGLES)
def test_kuka_abc_and_fanuc_wpr(angles: list[float]) -> None:
    """Pose_2_KUKA / KUKA_2_Pose: [x,y,z,A,B,C] mm and deg, Rz(A)·Ry(B)·Rx(C) (KUKA's ABC);
    Pose_2_Fanuc / Fanuc_2_Pose: [x,y,z,W,P,R], Rz(R)·Ry(P)·Rx(W)."""
    a, b, c = angles
    kuka = rm.KUKA_2_Pose([*XYZ, a, b, c])
    assert np.allclose(
        _m(kuka), _pose(Rotation.from_euler("ZYX", [a, b, c], degrees=True).as_matrix())
    )
    assert np.allclose(_m(rm.KUKA_2_Pose(rm.Pose_2_KUKA(kuka))), _m(kuka))
    fanuc = rm.Fanuc_2_Pose([*XYZ, c, b, a])  # W = C, P = B, R = A: the same rotation
    assert np.allclose(_m(fanuc), _m(kuka))
    assert np.allclose(rm.Pose_2_Fanuc(kuka)[3:][::-1], rm.Pose_2_KUKA(kuka)[3:])


@pytest.mark.parametrize("angles", ANGLES)
def test_abb_quaternion_w_first_and_ur_rotation_vector_in_mm(angles: list[float]) -> None:
    """Pose_2_ABB: [x,y,z,q1,q2,q3,q4], q1 the scalar (RAPID's orient); Pose_2_UR:
    "p[x,y,z,u,v,w] position with rotation vector", x y z kept in mm as RoboDK returns them."""
    rot = Rotation.from_euler("ZYX", angles, degrees=True)
    pose = rm.Mat(_pose(rot.as_matrix()))
    abb = rm.Pose_2_ABB(pose)
    x, y, z, w = rot.as_quat()
    assert len(abb) == 7 and np.allclose(abb[:3], XYZ)
    assert np.allclose(abb[3:], [w, x, y, z]) or np.allclose(abb[3:], [-w, -x, -y, -z])
    assert np.allclose(_m(rm.ABB_2_Pose(abb)), _m(pose))
    ur = rm.Pose_2_UR(pose)
    assert len(ur) == 6 and np.allclose(ur[:3], XYZ)
    assert np.allclose(Rotation.from_rotvec(ur[3:]).as_matrix(), rot.as_matrix())
    assert np.allclose(_m(rm.UR_2_Pose(ur)), _m(pose))


def test_mat_shapes_as_robodk() -> None:
    """robomath.Mat: Mat() is 4x4 zeros; a flat list becomes a column (how joints come back);
    list()/tolist(): "Returns the first column of the matrix as a list"; list2(): "one list
    per column"; len(): "Return the number of columns"; iterating gives the columns."""
    assert rm.Mat().size() == (4, 4) and not np.any(_m(rm.Mat()))
    joints = rm.Mat([10, 20, 30, 40, 50, 60])
    assert joints.size() == (6, 1) and joints.size(0) == 6
    assert joints.list() == joints.tolist() == [10, 20, 30, 40, 50, 60]
    assert len(joints) == 1 and list(joints) == [[10, 20, 30, 40, 50, 60]]
    assert joints.tr().size() == (1, 6) and joints.tr().list() == [10]
    assert rm.Mat(2, 3).size() == (2, 3)
    table = rm.Mat([[1, 2], [3, 4]])
    assert table.rows == [[1, 2], [3, 4]] and table.list2() == [[1, 3], [2, 4]]
    assert list(table) == [[1, 3], [2, 4]] and table[1, 0] == 3 and table[0].list() == [1, 2]
    assert rm.transl(1, 2, 3) == rm.transl(1, 2, 3 + 1e-9)


def test_pose_methods() -> None:
    """Mat * [x,y,z] transforms a point (mm); Offset moves along the reference, RelTool along
    the pose (mm, deg); inv/invH invert a rigid pose; Pos/setPos/VX/VY/VZ."""
    pose = rm.transl(100, 0, 0) * rm.rotz(math.pi / 2)
    assert np.allclose(pose * [10, 0, 0], [100, 10, 0])
    assert np.allclose(rm.Offset(pose, 0, 0, 5).Pos(), [100, 0, 5])
    assert np.allclose(rm.RelTool(pose, 10, 0, 0).Pos(), [100, 10, 0])
    assert np.allclose(pose.RelTool(0, 0, 0, 0, 0, 90).VX(), [-1, 0, 0])
    assert np.allclose(_m(pose * pose.inv()), np.eye(4)) and pose.isHomogeneous()
    assert np.allclose(_m(rm.invH(pose) * pose), np.eye(4))
    moved = pose.copy().setPos([1, 2, 3])
    assert moved.Pos() == [1, 2, 3] and pose.Pos() == [100, 0, 0]
    assert np.allclose(pose.VZ(), [0, 0, 1]) and np.allclose(pose.VY(), [-1, 0, 0])
    assert math.isclose(rm.pose_angle_between(pose, rm.transl(0, 0, 0)), math.pi / 2)
    assert rm.distance([0, 0, 0], [3, 4, 0]) == 5.0 and rm.cross([1, 0, 0], [0, 1, 0]) == [0, 0, 1]


def test_file_helpers(tmp_path: Path) -> None:
    """robofileio: getFileName is the name without folder or extension, getBaseName with it;
    LoadList gives rows with numbers as floats and other text as text."""
    csv = tmp_path / "points.csv"
    csv.write_text("1,2.5,-3\n4,5,six\n", encoding="utf-8")
    assert fio.LoadList(str(csv)) == [[1.0, 2.5, -3.0], [4.0, 5.0, "six"]]
    assert fio.getFileName(str(csv)) == "points" and fio.getBaseName(str(csv)) == "points.csv"
    assert fio.getFileDir(str(csv)) == str(tmp_path)


def test_pause_and_dialogs_are_noted_no_ops() -> None:
    """robomath.pause waits in RoboDK; offline it is a no-op noted at the script's line; a
    message box answers with its default."""
    text = (
        "from robodk import *\n"
        "pause(2)\n"
        "answer = mbox('Go on?')\n"
        "from olp.dsl import robot\n"
        "robot.RunInstruction('Done' if answer else 'No', 3)\n"
    )
    result = run_dsl(text, "prog.py")
    notes = {(i.span.line, i.reason.split(":")[0]) for i in result.ignored}
    assert notes == {(2, "pause"), (3, "mbox")}
    assert result.program.instructions[0].text == "Done"  # type: ignore[union-attr]
