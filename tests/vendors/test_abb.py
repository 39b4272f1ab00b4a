"""ABB conventions, pinned: quaternion w first (exact at 180°, sign rule), robtarget units,
confdata from joints and back, tool0 at the IRB 120 calibration position, RAPID spelling."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from olp import geometry as g
from olp import vendors
from olp.ir import Configuration
from olp.kinematics import opw
from olp.posts import find_post
from olp.posts.abb import NAME_RULE, rapid_confdata, rapid_jointtarget, rapid_pose, rapid_robtarget
from olp.vendors import abb

DEG = math.pi / 180.0
H = math.sqrt(0.5)
# IRB 120-3/0.6 from the VENDOR-NOTES table, convention A (offsets [0, 0, -90°, 0, 0, 0]).
IRB120 = opw.OPWParameters(
    0.0, -0.070, 0.0, 0.290, 0.270, 0.302, 0.072, (0.0, 0.0, -90 * DEG, 0.0, 0.0, 0.0)
)


def _half_turn(axis: list[float]) -> np.ndarray:
    """The 180° rotation about ``axis``: ``2 a aᵀ - I`` (exact, no trigonometry)."""
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return 2 * np.outer(a, a) - np.eye(3)


# --------------------------------------------------------------------------------------------
# Quaternions


@pytest.mark.parametrize(
    ("rotation", "expected"),
    [
        (np.eye(3), [1, 0, 0, 0]),
        (_half_turn([1, 0, 0]), [0, 1, 0, 0]),
        (_half_turn([0, 1, 0]), [0, 0, 1, 0]),  # tool-down (Z down, X back)
        (_half_turn([0, 0, 1]), [0, 0, 0, 1]),
        (_half_turn([-1, 0, 0]), [0, 1, 0, 0]),  # same rotation: the sign rule picks +x
        (_half_turn([1, 1, 0]), [0, H, H, 0]),
        (_half_turn([1, -1, 0]), [0, H, -H, 0]),
        (_half_turn([-1, 1, 0]), [0, H, -H, 0]),
        (_half_turn([0, -1, 1]), [0, 0, H, -H]),
        (_half_turn([1, 1, 1]), [0, *([1 / math.sqrt(3)] * 3)]),
        (g.rotz(math.pi / 2)[:3, :3], [H, 0, 0, H]),
        (g.roty(math.pi / 2)[:3, :3], [H, 0, H, 0]),  # gimbal lock of Euler angles: no issue
        (g.roty(-math.pi)[:3, :3], [0, 0, 1, 0]),  # sin(-pi) ~ -1e-16 off-diagonal
    ],
)
def test_quaternion_special_cases(rotation: np.ndarray, expected: list[float]) -> None:
    """Values derived by hand from q = [cos(t/2), sin(t/2)·axis]."""
    q = abb.quaternion_from_rotation(rotation)
    assert np.allclose(q, expected, atol=1e-15)
    assert np.allclose(abb.rotation_from_quaternion(q), rotation, atol=1e-15)


def test_tool_down_robtarget_orientation_is_0_0_1_0() -> None:
    """The orientation that RAPID programs carry for a tool pointing down with X back."""
    pose = g.transl(0.5, 0.0, 0.3) @ g.roty(math.pi)
    assert rapid_pose(find_post("abb"), pose) == (
        "[[500.000,0.000,300.000],[0.000000000,0.000000000,1.000000000,0.000000000]]"
    )


def test_quaternion_matches_scipy_up_to_sign() -> None:
    rotations = Rotation.random(4000, random_state=1)
    ours = abb.quaternion_from_rotation(rotations.as_matrix())
    x, y, z, w = rotations.as_quat().T  # scipy is scalar-last
    theirs = np.stack([w, x, y, z], axis=-1)
    sign = np.sign(np.sum(ours * theirs, axis=-1, keepdims=True))
    assert np.allclose(ours, sign * theirs, atol=1e-14)
    assert np.all(ours[:, 0] > 0)


def test_quaternion_is_vectorised() -> None:
    r = Rotation.random(6, random_state=2).as_matrix().reshape(2, 3, 3, 3)
    q = abb.quaternion_from_rotation(r)
    assert q.shape == (2, 3, 4)
    assert np.allclose(abb.rotation_from_quaternion(q), r, atol=1e-14)
    assert np.allclose(q[1, 2], abb.quaternion_from_rotation(r[1, 2]), atol=0)


@settings(max_examples=300, deadline=None)
@given(
    axis=st.lists(st.floats(-1, 1), min_size=3, max_size=3).filter(
        lambda v: np.linalg.norm(v) > 1e-3
    ),
    angle=st.floats(0, math.pi),
)
@example(axis=[0.0, 0.0, 1.0], angle=math.pi)
@example(axis=[1.0, 1.0, 0.0], angle=math.pi)
@example(axis=[0.3, -0.2, 0.9], angle=math.pi - 1e-9)
@example(axis=[0.3, -0.2, 0.9], angle=1e-12)
@example(axis=[0.3, -0.2, 0.9], angle=0.0)
@example(axis=[0.0, 0.0, -1.0], angle=math.pi - 4e-16)
def test_quaternion_round_trip_property(axis: list[float], angle: float) -> None:
    """Rotation -> quaternion -> rotation, and the quaternion is the textbook axis-angle one
    ([cos(t/2), sin(t/2)·a], up to sign), across 0 and exactly 180°."""
    a = np.asarray(axis) / np.linalg.norm(axis)
    rotation = g.rotation_exp(a * angle)
    q = abb.quaternion_from_rotation(rotation)
    textbook = np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * a])
    assert abs(abs(np.dot(q, textbook)) - 1.0) < 1e-12
    assert np.allclose(abb.rotation_from_quaternion(q), rotation, atol=1e-14)
    # The sign rule: w > 0, or for |w| <= 1e-12 (180°) the first non-zero of x, y, z positive.
    lead = q[np.argmax(np.abs(q) > 1e-12)]
    assert lead > 0


def test_quaternion_to_rotation_round_trip_is_canonical() -> None:
    q = np.random.default_rng(3).normal(size=(2000, 4))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    back = abb.quaternion_from_rotation(abb.rotation_from_quaternion(q))
    assert np.allclose(back, abb.canonical_quaternion(q), atol=1e-14)
    assert np.allclose(np.abs(np.sum(back * q, axis=-1)), 1.0, atol=1e-14)


def test_canonical_sign_rule() -> None:
    q = np.array(
        [[-0.5, 0.5, 0.5, 0.5], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, -H, H], [-0.0, 0.0, 1.0, -0.0]]
    )
    out = abb.canonical_quaternion(q)
    assert out.tolist() == [
        [0.5, -0.5, -0.5, -0.5],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, H, -H],
        [0, 0, 1, 0],
    ]
    assert not np.any(np.signbit(out[out == 0.0]))


@pytest.mark.parametrize("decimals", [4, 6, 9])
def test_normalised_rounded_keeps_unit_norm(decimals: int) -> None:
    q = abb.quaternion_from_rotation(Rotation.random(3000, random_state=4).as_matrix())
    r = abb.normalised_rounded(q, decimals)
    assert np.all(np.abs(np.linalg.norm(r, axis=-1) - 1.0) <= 1.5 * 10.0**-decimals)
    assert np.all(np.abs(r - q) <= 4 * 10.0**-decimals)
    assert np.allclose(r, np.round(r, decimals), atol=0)  # still has only `decimals` digits
    # Independent rounding would be worse: the helper must beat it on the worst case.
    naive = np.round(q, decimals)
    assert np.max(np.abs(np.linalg.norm(naive, axis=-1) - 1)) > np.max(
        np.abs(np.linalg.norm(r, axis=-1) - 1)
    )


def test_normalised_rounded_applies_the_sign_rule_after_rounding() -> None:
    """w = 4e-7 rounds to 0 at 6 decimals: then the first non-zero component must be positive."""
    q = np.array([4e-7, -0.6, 0.8, 0.0])
    r = abb.normalised_rounded(q, 6)
    assert r.tolist() == [0.0, 0.6, -0.8, 0.0]
    assert not np.signbit(r[0])


# --------------------------------------------------------------------------------------------
# robtarget values and the flange


def test_robtarget_units_and_round_trip() -> None:
    poses = g.pose_from(Rotation.random(500, random_state=5).as_matrix(), np.full((500, 3), 0.25))
    trans, rot = abb.pose_to_robtarget(poses)
    assert np.allclose(trans, 250.0)
    assert np.allclose(abb.robtarget_to_pose(trans, rot), poses, atol=1e-14)


def test_irb120_calibration_position() -> None:
    """All axes 0: tool0 at x = a1 + c3 + c4 = 374, z = c1 + c2 - a2 = 630 mm, pointing along
    +X: quaternion [0.7071068, 0, 0.7071068, 0] (Ry(90°)), confdata [0, 0, 0, 0]; what
    RobotStudio shows for this robot's tool0 there (recalled, medium confidence). Holds only
    with tool0 Z out of the flange, i.e. FLANGE_IN_TOOL0 = identity."""
    pose = opw.forward(IRB120, np.zeros(6)) @ abb.FLANGE_IN_TOOL0
    trans, rot = abb.pose_to_robtarget(pose)
    assert np.allclose(trans, [374.0, 0.0, 630.0], atol=1e-9)
    assert np.allclose(abb.normalised_rounded(rot, 7), [0.7071068, 0, 0.7071068, 0], atol=0)
    assert abb.confdata(IRB120, np.zeros(6)).tolist() == [0, 0, 0, 0]
    assert rapid_robtarget(find_post("abb"), pose, [0, 0, 0, 0]) == (
        "[[374.000,0.000,630.000],[0.707106781,0.000000000,0.707106781,0.000000000],"
        "[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]]"
    )


def test_flange_is_tool0() -> None:
    assert np.array_equal(abb.FLANGE_IN_TOOL0, np.eye(4))
    assert np.array_equal(vendors.flange_in_tool0("abb"), np.eye(4))


# --------------------------------------------------------------------------------------------
# confdata


@pytest.mark.parametrize(
    ("degrees", "cf"),
    [
        (0.0, 0),
        (-45.0, -1),  # the example of the RAPID manual: -45° is -1, not -2
        (-90.0, -1),
        (-90.0001, -2),
        (89.9999, 0),
        (90.0, 1),
        (180.0, 2),
        (-180.0, -2),
        (270.0, 3),
        (400.0, 4),
        (-400.0, -5),
    ],
)
def test_quadrant(degrees: float, cf: int) -> None:
    assert int(abb.quadrant(math.radians(degrees))) == cf


def test_quadrant_snaps_degree_rounding() -> None:
    """A value a few ulp below 90° (as arithmetic in degrees->radians may give) is 90°."""
    assert int(abb.quadrant(np.nextafter(math.pi / 2, 0.0))) == 1
    assert int(abb.quadrant(math.pi / 2 - 1e-9)) == 0


@pytest.mark.parametrize(
    ("degrees", "cfx"),
    [
        # Calibration pose: wrist centre in front of axis 1 and of the lower arm, axis 5 = 0.
        ([0, 0, 0, 0, 0, 0], 0),
        ([0, 0, 0, 0, -30, 0], 1),
        # Axis 2 at -90°: lower arm horizontal pointing back, elbow at x = -270 mm; the forearm
        # points up and its 70 mm offset puts the wrist centre at x = -340 mm: behind axis 1,
        # still in front of the lower arm.
        ([0, -90, 0, 0, 30, 0], 4),
        ([0, -90, 0, 0, -30, 0], 5),
        # Axis 2 at 60°, axis 3 at -100°: the forearm is turned back past the lower arm's line
        # (threshold -90° + atan(70/302) = -76.95°); wrist centre x = 270 sin 60° - 70 cos 50°
        # + 302 sin 50° = 420 mm, in front of axis 1.
        ([0, 60, -100, 0, 30, 0], 2),
        ([0, 60, -100, 0, -30, 0], 3),
        # Lower arm upright, axis 3 at -100°: wrist centre x = -70 cos 10° - 302 sin 10° < 0.
        ([0, 0, -100, 0, 30, 0], 6),
        ([0, 0, -100, 0, -30, 0], 7),
    ],
)
def test_cfx_from_joints(degrees: list[float], cfx: int) -> None:
    """cfx = 4·(behind axis 1) + 2·(behind the lower arm) + (axis 5 < 0), worked by hand."""
    assert abb.confdata(IRB120, np.radians(degrees)).tolist() == [0, 0, 0, cfx]


def test_confdata_quadrants_and_shape() -> None:
    q = np.radians([[-45, 0, 0, 100, 30, -190], [170, 0, 0, -300, 30, 395]])
    assert abb.confdata(IRB120, q).tolist() == [[-1, 1, -3, 0], [1, -4, 4, 0]]


# The table of the RAPID reference manual: wrist centre relative to axis 1, relative to the
# lower arm, and the sign of axis 5, for cfx 0..7.
RAPID_TABLE = [
    ("front", "in front", "positive"),
    ("front", "in front", "negative"),
    ("front", "behind", "positive"),
    ("front", "behind", "negative"),
    ("behind", "in front", "positive"),
    ("behind", "in front", "negative"),
    ("behind", "behind", "positive"),
    ("behind", "behind", "negative"),
]


@pytest.mark.parametrize("cfx", range(8))
def test_configuration_from_confdata_follows_the_rapid_table(cfx: int) -> None:
    axis1, lower_arm, axis5 = RAPID_TABLE[cfx]
    config = abb.configuration_from_confdata([-1, 0, 3, cfx])
    assert config.shoulder == ("back" if axis1 == "behind" else "front")
    assert config.elbow == ("down" if lower_arm == "behind" else "up")
    assert config.wrist == ("flip" if axis5 == "negative" else "noflip")
    assert config.joint_ranges == (
        (-math.pi / 2, 0.0),
        None,
        None,
        (0.0, math.pi / 2),
        None,
        (3 * math.pi / 2, 2 * math.pi),
    )


@pytest.mark.parametrize("conf", [[0, 0, 0, 8], [0, 0, 0, -1], [0, 0, 0], [0.5, 0, 0, 0]])
def test_confdata_is_checked(conf: list[float]) -> None:
    with pytest.raises(ValueError):
        abb.configuration_from_confdata(conf)


def test_configuration_from_confdata_type() -> None:
    assert isinstance(abb.configuration_from_confdata([0, 0, 0, 0]), Configuration)


# --------------------------------------------------------------------------------------------
# Spelling


def test_jointtarget_spelling() -> None:
    assert rapid_jointtarget(find_post("abb"), np.radians([0, -0.000001, 30, 0, 90, -400])) == (
        "[[0.00000,0.00000,30.00000,0.00000,90.00000,-400.00000],"
        "[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]]"
    )


def test_confdata_spelling() -> None:
    assert rapid_confdata([-1, 0, -2, 5]) == "[-1,0,-2,5]"


@pytest.mark.parametrize(
    ("name", "legal"),
    [
        ("main", "main"),
        ("my prog-1", "my_prog_1"),
        ("1st", "P1st"),
        ("a" * 40, "a" * 32),
        ("MODULE", "MODULE_"),
        ("proc", "proc_"),
        ("Fräsen", "Fr_sen"),
        ("", "P"),
    ],
)
def test_legal_name(name: str, legal: str) -> None:
    assert NAME_RULE.legal(name) == legal
