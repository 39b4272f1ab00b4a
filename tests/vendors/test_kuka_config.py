"""KUKA Status and Turn with the arm's geometry: the A3 threshold, S/T of known poses, S/T to
the IR configuration, and where T cannot tell turns apart."""

from __future__ import annotations

import math

import numpy as np
import pytest

from olp.kinematics import configuration as cfg
from olp.kinematics import opw
from olp.vendors import kuka

DEG = math.pi / 180.0
K_OFFSETS = (0.0, -90 * DEG, 0.0, 0.0, 0.0, 0.0)
K_SIGNS = (-1, 1, 1, -1, 1, -1)
# KR 6 R900 sixx from the VENDOR-NOTES table, convention K.
KR6 = opw.OPWParameters(0.025, -0.035, 0.0, 0.400, 0.455, 0.420, 0.080, K_OFFSETS, K_SIGNS)
KR10 = opw.OPWParameters(0.150, -0.020, 0.0, 0.450, 0.610, 0.660, 0.080, K_OFFSETS, K_SIGNS)


@pytest.mark.parametrize(
    ("params", "a2", "c3"), [(KR6, 35.0, 420.0), (KR10, 20.0, 660.0)], ids=["KR6", "KR10"]
)
def test_a3_threshold_is_atan_a2_over_c3(params: opw.OPWParameters, a2: float, c3: float) -> None:
    """VENDOR-NOTES: bit 1 is set when A3 >= atan(|a2| / c3)."""
    assert kuka.a3_threshold(params) == pytest.approx(math.atan(a2 / c3), abs=1e-15)


def test_a3_threshold_needs_kukas_a3_sign() -> None:
    fanuc_like = opw.OPWParameters(
        0.05, -0.035, 0, 0.33, 0.33, 0.335, 0.08, signs=(1, 1, -1, 1, 1, 1)
    )
    with pytest.raises(ValueError):
        kuka.a3_threshold(fanuc_like)


@pytest.mark.parametrize(
    ("degrees", "status", "turn"),
    [
        # HOME: front, A3 = 90° above the threshold, A5 = 0; only A2 is negative.
        ([0, -90, 90, 0, 0, 0], 2, 0b000010),
        # Tool down (A5 = +90°): the typical taught point, S 'B010'.
        ([0, -90, 90, 0, 90, 0], 2, 0b000010),
        ([10, -90, 90, 0, -90, -5], 6, 0b110010),
        # A3 = 0, the candle: the forearm continues the lower arm, its 35 mm offset puts the
        # wrist centre behind the lower arm's line (0 < atan(35/420) = 4.76°): bit 1 clear; and
        # at x = a1 + a2 = -10 mm, just behind A1: bit 0 set.
        ([0, -90, 0, 0, 90, 0], 1, 0b000010),
        ([0, -90, 10, 0, 90, 0], 2, 0b000010),
        # A2 = -160°: the lower arm leans back 70° from vertical; wrist centre x =
        # 25 - 455 sin 70° - 35 cos 20° + 420 sin 20° = -292 mm: overhead, bit 0.
        ([0, -160, 90, 0, 90, 0], 3, 0b000010),
        ([0, -160, 90, 0, -90, 0], 7, 0b010010),
    ],
)
def test_status_and_turn_of_known_poses(degrees: list[float], status: int, turn: int) -> None:
    s, t = kuka.status_turn(KR6, np.radians(degrees))
    assert (int(s), int(t)) == (status, turn)


def test_status_from_params_is_status_bits_with_the_geometry() -> None:
    q = np.random.default_rng(1).uniform(-3, 3, (500, 6))
    explicit = kuka.status_bits(q, opw.wrist_x_in_a1(KR6, q), math.atan(35 / 420))
    assert np.array_equal(kuka.status_from_joints(KR6, q), explicit)


def test_status_and_turn_of_a_tool_down_pose() -> None:
    status, turn = kuka.status_turn(KR6, np.radians([0, -90, 90, 0, -90, -5]))
    assert (int(status), int(turn)) == (6, 50)


@pytest.mark.parametrize(
    ("status", "turn", "flags"),
    [
        (2, 0, ("front", "up", "noflip")),
        (0, 0, ("front", "down", "noflip")),
        (5, 0b100001, ("back", "down", "flip")),
        (7 | 8 | 16, 0, ("back", "up", "flip")),  # bits 3 and 4 carry nothing
    ],
)
def test_configuration_from_status_turn(
    status: int, turn: int, flags: tuple[str, str, str]
) -> None:
    c = kuka.configuration_from_status_turn(status, turn)
    assert (c.shoulder, c.elbow, c.wrist) == flags
    assert c.joint_ranges is not None
    for i, rng in enumerate(c.joint_ranges):
        assert rng == ((-math.inf, 0.0) if turn >> i & 1 else (0.0, math.inf))


@pytest.mark.parametrize(("status", "turn"), [(-1, 0), (32, 0), (2, 64), (2, -1)])
def test_status_turn_is_checked(status: int, turn: int) -> None:
    with pytest.raises(ValueError):
        kuka.configuration_from_status_turn(status, turn)


def test_turn_at_exactly_zero() -> None:
    """T bit clear for A6 = 0 (VENDOR-NOTES: exactly 0 gives 0); the IK's ±1e-16 around it
    still satisfies the [0, inf) range."""
    q = np.radians([0.0, -90.0, 90.0, 0.0, 45.0, 0.0])
    _, turn = kuka.status_turn(KR6, q)
    request = kuka.configuration_from_status_turn(2, int(turn))
    near = np.array([q, q]) + np.array([[0, 0, 0, 0, 0, 1e-16], [0, 0, 0, 0, 0, -1e-16]])
    assert int(turn) >> 5 & 1 == 0
    assert cfg.satisfies(request, near, KR6).tolist() == [True, True]


def test_turn_cannot_tell_same_sign_turns_apart() -> None:
    """The documented limit: T is a sign, so over a range wider than (-360°, 360°) two turns of
    the same sign both satisfy it (A6 at 100° and 460° on a hypothetical ±540° axis). KUKA's
    bundled ranges stay inside (-360°, 360°)."""
    q = np.radians([0.0, -90.0, 90.0, 0.0, 45.0, 100.0])
    status, turn = kuka.status_turn(KR6, q)
    request = kuka.configuration_from_status_turn(int(status), int(turn))
    variants = q + np.radians([[0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 360], [0, 0, 0, 0, 0, -360]])
    assert cfg.satisfies(request, variants, KR6).tolist() == [True, True, False]
