"""UR conventions, pinned: rotation vectors (exact at 180°, sign rule there), p[...] values in
metres and radians, the flange, no configuration bits, names."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from olp import geometry as g
from olp import vendors
from olp.posts import find_post
from olp.posts.ur import NAME_RULE, ur_joints, ur_pose
from olp.vendors import ur

H = math.sqrt(0.5)


def _half_turn(axis: list[float]) -> np.ndarray:
    """The 180° rotation about ``axis``: ``2 a aᵀ - I`` (exact, no trigonometry)."""
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return 2 * np.outer(a, a) - np.eye(3)


@pytest.mark.parametrize(
    ("rotation", "expected"),
    [
        (np.eye(3), [0, 0, 0]),
        (_half_turn([1, 0, 0]), [math.pi, 0, 0]),
        (_half_turn([0, 1, 0]), [0, math.pi, 0]),  # tool-down, X back
        (_half_turn([0, 0, -1]), [0, 0, math.pi]),
        (g.roty(-math.pi)[:3, :3], [0, math.pi, 0]),  # sin(-pi) ~ -1e-16 off-diagonal
        (_half_turn([1, 1, 0]), [math.pi * H, math.pi * H, 0]),
        (_half_turn([1, -1, 0]), [math.pi * H, -math.pi * H, 0]),  # tie: first largest > 0
        (_half_turn([1, -2, 0]), [-math.pi / math.sqrt(5), 2 * math.pi / math.sqrt(5), 0]),
        (g.rotz(math.pi / 2)[:3, :3], [0, 0, math.pi / 2]),
        (g.rotx(-math.pi / 2)[:3, :3], [-math.pi / 2, 0, 0]),
    ],
)
def test_rotvec_special_cases(rotation: np.ndarray, expected: list[float]) -> None:
    """Axis times angle in [0, 180°]; at exactly 180° the largest component is positive."""
    v = ur.rotvec_from_rotation(rotation)
    assert np.allclose(v, expected, atol=1e-15)
    assert np.allclose(ur.rotation_from_rotvec(v), rotation, atol=1e-15)


def test_rotvec_matches_scipy() -> None:
    rotations = Rotation.random(4000, random_state=1)
    assert np.allclose(
        ur.rotvec_from_rotation(rotations.as_matrix()), rotations.as_rotvec(), atol=1e-13
    )


@settings(max_examples=300, deadline=None)
@given(
    axis=st.lists(st.floats(-1, 1), min_size=3, max_size=3).filter(
        lambda v: np.linalg.norm(v) > 1e-3
    ),
    angle=st.floats(0, math.pi),
)
@example(axis=[0.0, 0.0, 1.0], angle=math.pi)
@example(axis=[-0.3, 0.2, 0.9], angle=math.pi)
@example(axis=[0.3, -0.2, 0.9], angle=math.pi - 1e-9)
@example(axis=[0.3, -0.2, 0.9], angle=math.pi - 1e-4)
@example(axis=[0.3, -0.2, 0.9], angle=1e-12)
@example(axis=[0.3, -0.2, 0.9], angle=0.0)
def test_rotvec_round_trip_property(axis: list[float], angle: float) -> None:
    """Rotation vector -> rotation -> rotation vector gives the vector back (its negative is the
    same rotation at exactly 180°), and the rotation survives the round trip."""
    a = np.asarray(axis) / np.linalg.norm(axis)
    v = a * angle
    rotation = ur.rotation_from_rotvec(v)
    back = ur.rotvec_from_rotation(rotation)
    assert np.allclose(ur.rotation_from_rotvec(back), rotation, atol=1e-14)
    if angle < math.pi - 1e-6:
        assert np.allclose(back, v, atol=1e-12)
    else:
        assert np.allclose(np.abs(back), np.abs(v), atol=1e-6)
    assert np.linalg.norm(back) <= math.pi + 1e-12


def test_rotvec_is_vectorised() -> None:
    r = Rotation.random(6, random_state=2).as_matrix().reshape(2, 3, 3, 3)
    v = ur.rotvec_from_rotation(r)
    assert v.shape == (2, 3, 3)
    assert np.allclose(ur.rotation_from_rotvec(v), r, atol=1e-14)


def test_pose_values_are_metres_and_radians() -> None:
    pose = g.transl(0.1, -0.2, 0.3) @ g.rotx(math.pi)
    assert np.allclose(ur.pose_to_ur(pose), [0.1, -0.2, 0.3, math.pi, 0, 0], atol=1e-15)
    assert np.allclose(ur.ur_to_pose(ur.pose_to_ur(pose)), pose, atol=1e-15)
    poses = g.pose_from(Rotation.random(100, random_state=3).as_matrix(), np.ones((100, 3)))
    assert np.allclose(ur.ur_to_pose(ur.pose_to_ur(poses)), poses, atol=1e-14)


def test_pose_spelling() -> None:
    pose = g.transl(0.1, -0.0000001, 0.3) @ g.roty(-math.pi)
    assert (
        ur_pose(find_post("ur"), pose)
        == "p[0.100000, 0.000000, 0.300000, 0.000000, 3.141593, 0.000000]"
    )


def test_joint_spelling() -> None:
    assert ur_joints(find_post("ur"), [0, -math.pi / 2, 1e-9, 0, math.pi, -1]) == (
        "[0.000000, -1.570796, 0.000000, 0.000000, 3.141593, -1.000000]"
    )


def test_flange_is_tool0_and_there_is_no_configuration() -> None:
    assert np.array_equal(ur.FLANGE_IN_TOOL0, np.eye(4))
    assert np.array_equal(vendors.flange_in_tool0("ur"), np.eye(4))
    assert ur.HAS_CONFIGURATION is False


@pytest.mark.parametrize(
    ("name", "legal"),
    [("Pick1", "Pick1"), ("my prog-1", "my_prog_1"), ("1st", "p1st"), ("def", "def_"), ("", "p")],
)
def test_legal_name(name: str, legal: str) -> None:
    assert NAME_RULE.legal(name) == legal
