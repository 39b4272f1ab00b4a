"""Fanuc conventions, pinned: W, P, R order and range, CONFIG both ways (letters, turn numbers
with their half-open boundaries), controller joints with the J2/J3 coupling, names."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from olp import geometry as g
from olp import vendors
from olp.kinematics import opw
from olp.kinematics.base import FANUC_J2_J3, JointCoupling
from olp.kinematics.configuration import satisfies
from olp.kinematics.models import OPWKinematics
from olp.posts import find_post
from olp.posts.fanuc import NAME_RULE, ls_joints, ls_xyzwpr
from olp.vendors import fanuc

DEG = math.pi / 180.0
# LR Mate 200iD from the VENDOR-NOTES table, convention F, with c1 = 0: poses in Fanuc's World
# frame (at J2 height). Controller joints, J3 counted from the horizontal.
LR200ID = OPWKinematics(
    opw.OPWParameters(
        0.050,
        -0.035,
        0.0,
        0.0,
        0.330,
        0.335,
        0.080,
        (0.0, 0.0, -90 * DEG, 0.0, 0.0, 180 * DEG),
        (1, 1, -1, -1, -1, -1),
    ),
    JointCoupling.from_terms(6, FANUC_J2_J3),
)


# --------------------------------------------------------------------------------------------
# W, P, R


def test_wpr_is_rz_r_ry_p_rx_w() -> None:
    w, p, r = np.radians([30.0, -20.0, 45.0])
    expected = (g.rotz(r) @ g.roty(p) @ g.rotx(w))[:3, :3]
    assert np.allclose(fanuc.wpr_to_rotation(w, p, r), expected, atol=1e-15)
    # The same as rotations about the fixed X, Y, Z axes, in that order.
    fixed = Rotation.from_euler("xyz", [w, p, r]).as_matrix()
    assert np.allclose(fanuc.wpr_to_rotation(w, p, r), fixed, atol=1e-15)


def test_single_angles_turn_the_expected_axes() -> None:
    assert np.allclose(fanuc.wpr_to_rotation(math.pi / 2, 0, 0) @ [0, 1, 0], [0, 0, 1], atol=1e-15)
    assert np.allclose(fanuc.wpr_to_rotation(0, math.pi / 2, 0) @ [1, 0, 0], [0, 0, -1], atol=1e-15)
    assert np.allclose(fanuc.wpr_to_rotation(0, 0, math.pi / 2) @ [1, 0, 0], [0, 1, 0], atol=1e-15)


@pytest.mark.parametrize(
    ("wpr", "canonical"),
    [
        ([0, 0, 0], [0, 0, 0]),
        ([180, 0, 0], [180, 0, 0]),
        ([-180, 0, 0], [180, 0, 0]),  # W in (-180, 180]: -180 is written as 180
        ([0, 0, -180], [0, 0, 180]),
        ([-180, 0, -180], [180, 0, 180]),
        ([20, 90, 30], [0, 90, 10]),  # gimbal lock: Rz(30) Ry(90) Rx(20) = Rz(10) Ry(90)
        ([20, -90, 30], [0, -90, 50]),  # Rz(30) Ry(-90) Rx(20) = Rz(50) Ry(-90)
        ([179.9999, 89.9999, -179.9999], [179.9999, 89.9999, -179.9999]),
    ],
)
def test_wpr_special_cases(wpr: list[float], canonical: list[float]) -> None:
    pose = fanuc.xyzwpr_to_pose([1.0, -2.0, 3.0, *wpr])
    back = fanuc.pose_to_xyzwpr(pose)
    assert np.allclose(back[3:], canonical, atol=1e-7)
    assert np.allclose(fanuc.xyzwpr_to_pose(back), pose, atol=1e-12)


@settings(max_examples=300, deadline=None)
@given(
    w=st.floats(-180, 180),
    p=st.floats(-90, 90),
    r=st.floats(-180, 180),
)
@example(w=180.0, p=90.0, r=-180.0)
@example(w=-180.0, p=-90.0, r=180.0)
@example(w=0.0, p=89.99999999, r=0.0)
def test_wpr_round_trip_property(w: float, p: float, r: float) -> None:
    pose = fanuc.xyzwpr_to_pose([100.0, 200.0, 300.0, w, p, r])
    back = fanuc.pose_to_xyzwpr(pose)
    # olp.geometry.zyx_from_rotation treats cos(P) < 1e-9 as gimbal lock (P = ±90° exactly), so
    # within 1e-9 rad of the lock the round trip is off by up to cos(P); exact elsewhere.
    atol = 1.1e-9 if math.cos(math.radians(p)) < 1e-9 else 1e-12
    assert np.allclose(fanuc.xyzwpr_to_pose(back), pose, atol=atol)
    # (-180°, 180°]: olp.geometry.wrap_half_open maps angles within 1e-12 rad of -180° to
    # +180° and may land a few ulp above it.
    top = 180 + 1e-9
    assert -180 < back[3] <= top and -180 < back[5] <= top and -90 <= back[4] <= 90


def test_wpr_vectorised_and_units() -> None:
    rot = Rotation.random(1000, random_state=1).as_matrix()
    wpr = fanuc.rotation_to_wpr(rot)
    assert wpr.shape == (1000, 3)
    assert np.allclose(fanuc.wpr_to_rotation(*wpr.T), rot, atol=1e-13)
    assert fanuc.xyzwpr_to_pose([1000.0, 0, 0, 0, 0, 0])[0, 3] == pytest.approx(1.0)


# --------------------------------------------------------------------------------------------
# CONFIG


def test_tool_down_pose_is_n_u_t() -> None:
    """VENDOR-NOTES: the usual tool-down pose, J5 = -90° with the other axes 0, reads
    'N U T, 0, 0, 0'. Worked by hand on the model: the wrist centre is at x = a1 + c3 = 385,
    z = c2 - a2 = 365 mm above J2; tool0 points down 80 mm below it, X forward: W, P, R =
    180, 0, 0 (the faceplate is ROS-Industrial's tool0, the "all-zeros tool frame")."""
    q = np.radians([0.0, 0.0, 0.0, 0.0, -90.0, 0.0])
    pose = LR200ID.forward(q) @ fanuc.FLANGE_IN_TOOL0
    assert np.allclose(pose[:3, 2], [0, 0, -1], atol=1e-15)
    assert np.allclose(fanuc.pose_to_xyzwpr(pose), [385.0, 0.0, 285.0, 180.0, 0.0, 0.0], atol=1e-9)
    assert str(fanuc.config_from_joints(LR200ID, q)) == "N U T, 0, 0, 0"


@pytest.mark.parametrize(
    ("degrees", "config"),
    [
        ([0, 0, 0, 0, 90, 0], "F U T, 0, 0, 0"),
        ([0, 0, 0, 0, 0, 0], "F U T, 0, 0, 0"),  # J5 = 0 is F (olp's tie rule)
        ([0, 0, 0, 190, -90, 0], "N U T, 0, 1, 0"),
        ([0, 0, 0, -180, -90, 180], "N U T, 0, -1, 1"),
        ([0, 0, 0, 0, -90, -200], "N U T, 0, 0, -1"),
        ([0, 0, 0, 0, -90, 359], "N U T, 0, 0, 1"),
        # J2 60°, J3 40° from the horizontal: the forearm rises above the lower arm's line
        # (model J3 = 100° > 90° + atan2(-35, 335) = 84.0°): the wrist centre lies behind the
        # lower arm, elbow down.
        ([0, 60, 40, 0, -90, 0], "N D T, 0, 0, 0"),
        # J2 -90°: lower arm pointing back, elbow at x = 50 - 330 = -280 mm; J3 -90° (from the
        # horizontal) points the forearm down, its -35 mm offset turned with it puts the wrist
        # centre at x = -280 + 35 = -245 mm: behind J1 (B). The wrist centre is below the lower
        # arm, whose +x side points up: behind it, so D, although the elbow is geometrically
        # above the shoulder-wrist line (the B-pose meaning of U/D is unverified, see fanuc.py).
        ([0, -90, -90, 0, -90, 0], "N D B, 0, 0, 0"),
    ],
)
def test_config_from_joints(degrees: list[float], config: str) -> None:
    assert str(fanuc.config_from_joints(LR200ID, np.radians(degrees))) == config


def test_config_uses_controller_j3() -> None:
    """Without the J2/J3 coupling the same numbers would read as model J3 = 40°: elbow up."""
    q = np.radians([0.0, 60.0, 40.0, 0.0, -90.0, 0.0])
    assert fanuc.config_from_joints(LR200ID, q).up is False
    assert fanuc.config_from_joints(LR200ID.params, q).up is True


@pytest.mark.parametrize(
    ("degrees", "turn"),
    [
        (0.0, 0),
        (179.999, 0),
        (-179.999, 0),
        (180.0, 1),  # [180, 540) is +1
        (-180.0, -1),  # (-540, -180] is -1
        (360.0, 1),
        (-360.0, -1),
        (539.999, 1),
        (540.0, 2),
        (-540.0, -2),
        (-539.999, -1),
    ],
)
def test_turn_number_boundaries(degrees: float, turn: int) -> None:
    """VENDOR-NOTES: 0 for (-180°, 180°), +1 for [180°, 540°), -1 for (-540°, -180°]."""
    assert int(fanuc.turn_number(math.radians(degrees))) == turn


def test_turn_number_snaps_degree_rounding() -> None:
    assert int(fanuc.turn_number(np.nextafter(math.pi, 0.0))) == 1
    assert int(fanuc.turn_number(-np.nextafter(math.pi, 0.0))) == -1
    assert int(fanuc.turn_number(math.pi - 1e-9)) == 0


@pytest.mark.parametrize("turn", [-2, -1, 0, 1, 2])
def test_turn_range_holds_its_turn(turn: int) -> None:
    lo, hi = fanuc.turn_range(turn)
    inside = np.linspace(lo, hi, 101)[1:-1]
    assert np.all(fanuc.turn_number(inside) == turn)
    assert hi - lo == pytest.approx(2 * math.pi)


@pytest.mark.parametrize(
    "text",
    ["N U T, 0, 0, 0", "'F D B, 1, -1, 0'", "n u t,0,-1,+2", "  F U T , 0 , 0 , 0 "],
)
def test_config_parse_and_spell(text: str) -> None:
    config = fanuc.FanucConfig.parse(text)
    assert fanuc.FanucConfig.parse(str(config)) == config
    letters = text.strip().strip("'").upper().replace(" ", "")
    assert str(config).replace(" ", "").startswith(letters[:3])


def test_config_parse_values() -> None:
    assert fanuc.FanucConfig.parse("'F D B, 1, -1, 0'") == fanuc.FanucConfig(
        True, False, False, (1, -1, 0)
    )


@pytest.mark.parametrize("text", ["N U, 0, 0, 0", "X U T, 0, 0, 0", "N U T, 0, 0", "N U T"])
def test_config_parse_rejects(text: str) -> None:
    with pytest.raises(ValueError):
        fanuc.FanucConfig.parse(text)


def test_configuration_from_config() -> None:
    """F is axis 5 >= 0 (the IR's "noflip"), N is axis 5 < 0 (the IR's "flip")."""
    c = fanuc.configuration_from_config("F U T, 0, 1, -1")
    assert (c.shoulder, c.elbow, c.wrist) == ("front", "up", "noflip")
    assert c.joint_ranges == (
        (-math.pi, math.pi),
        None,
        None,
        (math.pi, 3 * math.pi),
        None,
        (-3 * math.pi, -math.pi),
    )
    c = fanuc.configuration_from_config(fanuc.FanucConfig(False, False, False))
    assert (c.shoulder, c.elbow, c.wrist) == ("back", "down", "flip")


def test_config_round_trips_through_the_ir() -> None:
    """Every CONFIG value -> ir.Configuration -> the joints it admits -> the same CONFIG."""
    rng = np.random.default_rng(2)
    q = rng.uniform(
        np.radians([-170, -100, -70, -190, -125, -360]),
        np.radians([170, 145, 205, 190, 125, 360]),
        (300, 6),
    )
    for joints in q:
        config = fanuc.config_from_joints(LR200ID, joints)
        request = fanuc.configuration_from_config(str(config))
        assert satisfies(request, joints[None], LR200ID)[0]


# --------------------------------------------------------------------------------------------
# Flange, names, spelling


def test_flange_is_tool0() -> None:
    assert np.array_equal(fanuc.FLANGE_IN_TOOL0, np.eye(4))
    assert np.array_equal(vendors.flange_in_tool0("fanuc"), np.eye(4))


@pytest.mark.parametrize(
    ("name", "legal"),
    [
        ("Weld1", "WELD1"),
        ("my prog-1", "MY_PROG_1"),
        ("1st", "P1ST"),
        ("a" * 40, "A" * 36),
        ("Fräsen", "FR_SEN"),
        ("", "P"),
    ],
)
def test_legal_name(name: str, legal: str) -> None:
    assert NAME_RULE.legal(name) == legal


def test_ls_numbers_have_no_negative_zero() -> None:
    pose = fanuc.xyzwpr_to_pose([-0.0000001, 1.5, -2.25, -180, 0, 0])
    assert ls_xyzwpr(find_post("fanuc"), pose) == [
        "0.000",
        "1.500",
        "-2.250",
        "180.000",
        "0.000",
        "0.000",
    ]
    assert ls_joints(find_post("fanuc"), np.radians([0, -1e-7, 30, 0, -90, 0])) == [
        "0.000",
        "0.000",
        "30.000",
        "0.000",
        "-90.000",
        "0.000",
    ]


def test_config_selection_in_batches_is_the_selection_at_once(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from pathlib import Path

    from olp.station.loader import load_station

    cell = Path(__file__).resolve().parents[2] / "stations" / "fanuc_m20ia_weld_cell.yaml"
    robot = load_station(cell).robot
    rng = np.random.default_rng(7)
    q = rng.uniform(robot.limits.lower, robot.limits.upper, size=(40, 6))
    q[::5, 4] = 0.0  # wrist singular: several solutions share a CONFIG, written as joints
    whole = fanuc.selecting_configs(robot, q)
    assert any(c is None for c in whole) and any(c is not None for c in whole)
    monkeypatch.setattr(fanuc, "SELECT_ROWS", 3)
    assert fanuc.selecting_configs(robot, q) == whole
