"""KUKA conventions, pinned: ABC order and signs, units, flange frame, Turn bits, spelling."""

from __future__ import annotations

import numpy as np
import pytest

from olp import geometry as g
from olp.posts import find_post
from olp.posts.kuka import NAME_RULE, krl_axis, krl_frame
from olp.vendors import kuka


def test_abc_is_rz_a_ry_b_rx_c() -> None:
    """KSS: A about Z, then B about the new Y, then C about the newest X (intrinsic)."""
    a, b, c = np.radians([30.0, -20.0, 45.0])
    expected = (g.rotz(a) @ g.roty(b) @ g.rotx(c))[:3, :3]
    assert np.allclose(kuka.abc_to_rotation(a, b, c), expected, atol=1e-15)


def test_abc_single_angles_turn_the_expected_axes() -> None:
    # A = 90°: the tool's X axis points along base +Y.
    assert np.allclose(kuka.abc_to_rotation(np.pi / 2, 0, 0) @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    # B = 90°: the tool's X axis points along base -Z (B tilts X down).
    assert np.allclose(kuka.abc_to_rotation(0, np.pi / 2, 0) @ [1, 0, 0], [0, 0, -1], atol=1e-15)
    # C = 90°: the tool's Y axis points along base +Z.
    assert np.allclose(kuka.abc_to_rotation(0, 0, np.pi / 2) @ [0, 1, 0], [0, 0, 1], atol=1e-15)


def test_milling_orientation_points_tool_z_down() -> None:
    """A -180, B 0, C -180 (USERS.md job 5) is a tool whose Z axis points down."""
    r = kuka.abc_to_rotation(*np.radians([-180.0, 0.0, -180.0]))
    assert np.allclose(r @ [0, 0, 1], [0, 0, -1], atol=1e-15)


@pytest.mark.parametrize(
    "abc",
    [
        [0, 0, 0],
        [180, 0, 180],
        [-180, 0, -180],
        [-160, 0, 180],
        [90, 90, 0],
        [30, 90, 20],
        [30, -90, 20],
        [179.9999, 89.9999, -179.9999],
    ],
)
def test_abc_round_trip_special_cases(abc: list[float]) -> None:
    pose = kuka.frame_to_pose([10.0, -20.0, 30.0, *abc])
    back = kuka.pose_to_frame(pose)
    assert np.allclose(kuka.frame_to_pose(back), pose, atol=1e-12)
    assert -180 < back[3] <= 180 and -180 < back[5] <= 180 and -90 <= back[4] <= 90


def test_abc_round_trip_random() -> None:
    rng = np.random.default_rng(3)
    values = np.column_stack(
        [rng.uniform(-2000, 2000, (5000, 3)), rng.uniform(-180, 180, (5000, 3))]
    )
    poses = kuka.frame_to_pose(values)
    assert np.allclose(kuka.frame_to_pose(kuka.pose_to_frame(poses)), poses, atol=1e-12)


def test_gimbal_lock_puts_rotation_into_a() -> None:
    # Rz(30) Ry(90) Rx(20) == Rz(10) Ry(90): olp writes C = 0.
    back = kuka.pose_to_frame(kuka.frame_to_pose([0, 0, 0, 30, 90, 20]))
    assert np.allclose(back[3:], [10, 90, 0], atol=1e-9)


def test_frame_units_are_mm_and_degrees() -> None:
    pose = kuka.frame_to_pose([1000.0, 0, 0, 0, 0, 0])
    assert pose[0, 3] == pytest.approx(1.0)


def test_flange_x_is_tool0_z() -> None:
    """KUKA's flange X axis (out of the flange) is the model's tool0 Z axis."""
    assert np.allclose(kuka.FLANGE_IN_TOOL0[:3, :3] @ [1, 0, 0], [0, 0, 1], atol=1e-15)


def test_turn_bits() -> None:
    q = np.radians([[10, -20, 30, -40, 0, -1], [0, 0, 0, 0, 0, 0], [-1, -1, -1, -1, -1, -1]])
    assert kuka.turn_bits(q).tolist() == [0b101010, 0, 0b111111]


def test_krl_frame_spelling_has_no_negative_zero() -> None:
    text = krl_frame(find_post("kuka"), kuka.frame_to_pose([-0.0000001, 1.5, -2.25, -180, 0, -180]))
    assert text == "X 0.000,Y 1.500,Z -2.250,A 180.0000,B 0.0000,C 180.0000"


def test_krl_axis_spelling() -> None:
    assert krl_axis(find_post("kuka"), np.radians([0, -90, 90, 0, 0, 0.5])) == (
        "A1 0.00000,A2 -90.00000,A3 90.00000,A4 0.00000,A5 0.00000,A6 0.50000"
    )


@pytest.mark.parametrize(
    ("name", "legal"),
    [
        ("Milling", "Milling"),
        ("my prog-1", "my_prog_1"),
        ("1st", "P1st"),
        ("a" * 30, "a" * 24),
        ("Fräsen", "Fr_sen"),
    ],
)
def test_legal_name(name: str, legal: str) -> None:
    assert NAME_RULE.legal(name) == legal
