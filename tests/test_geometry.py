"""SE(3) helpers: rotation log/exp exact near 0 and at pi, interpolation, inverse."""

from __future__ import annotations

import numpy as np
import pytest

from olp import geometry as g


def _random_rotvecs(n: int, rng: np.random.Generator, max_angle: float = np.pi) -> np.ndarray:
    axes = rng.normal(size=(n, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    return axes * rng.uniform(0, max_angle, size=(n, 1))


def test_rotation_log_inverts_exp_everywhere() -> None:
    rng = np.random.default_rng(1)
    v = _random_rotvecs(5000, rng)
    assert np.allclose(g.rotation_log(g.rotation_exp(v)), v, atol=1e-9)


@pytest.mark.parametrize("axis", [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [1, -2, 3]])
def test_rotation_log_at_exactly_pi_gives_the_same_rotation(axis: list[float]) -> None:
    a = np.array(axis, dtype=float) / np.linalg.norm(axis)
    r = g.rotation_exp(a * np.pi)
    v = g.rotation_log(r)
    assert np.isclose(np.linalg.norm(v), np.pi)
    assert np.allclose(g.rotation_exp(v), r, atol=1e-12)


def test_rotation_log_of_tiny_rotation_is_accurate() -> None:
    v = np.array([1e-10, -2e-10, 3e-10])
    assert np.allclose(g.rotation_log(g.rotation_exp(v)), v, rtol=1e-6, atol=0)


def test_elementary_rotations_follow_right_hand_rule() -> None:
    assert np.allclose(g.rotz(np.pi / 2)[:3, :3] @ [1, 0, 0], [0, 1, 0])
    assert np.allclose(g.roty(np.pi / 2)[:3, :3] @ [0, 0, 1], [1, 0, 0])
    assert np.allclose(g.rotx(np.pi / 2)[:3, :3] @ [0, 1, 0], [0, 0, 1])


def test_zyx_is_rz_ry_rx_in_that_order() -> None:
    z, y, x = 0.3, -0.7, 1.1
    expected = (g.rotz(z) @ g.roty(y) @ g.rotx(x))[:3, :3]
    assert np.allclose(g.rotation_from_zyx(z, y, x), expected, atol=1e-15)


def test_zyx_round_trip_including_gimbal_lock_and_180() -> None:
    rng = np.random.default_rng(2)
    angles = rng.uniform(-np.pi, np.pi, size=(2000, 3))
    angles[:, 1] /= 2
    special = np.radians(
        [[180, 0, 180], [-180, 0, -180], [0, 90, 0], [30, 90, 20], [-45, -90, 10], [180, -90, 180]]
    )
    angles = np.vstack([angles, special])
    r = g.rotation_from_zyx(*angles.T)
    back = g.zyx_from_rotation(r)
    assert np.allclose(g.rotation_from_zyx(*back.T), r, atol=1e-12)
    assert np.all(back[:, [0, 2]] > -np.pi) and np.all(back[:, [0, 2]] <= np.pi)


def test_wrap_half_open_sends_minus_pi_to_pi() -> None:
    assert g.wrap_half_open(-np.pi) == pytest.approx(np.pi)
    assert g.wrap_half_open(3 * np.pi) == pytest.approx(np.pi)
    assert g.wrap_half_open(0.5) == pytest.approx(0.5)


def test_inv_is_the_inverse() -> None:
    pose = g.transl(0.1, -0.2, 0.3) @ g.rotz(0.4) @ g.rotx(-1.2)
    assert np.allclose(g.inv(pose) @ pose, np.eye(4), atol=1e-15)


def test_interpolate_poses_hits_both_ends_and_is_uniform() -> None:
    a = g.transl(0, 0, 0)
    b = g.transl(1, 0, 0) @ g.rotz(np.pi)
    poses = g.interpolate_poses(a, b, np.linspace(0, 1, 5))
    assert np.allclose(poses[0], a) and np.allclose(poses[-1], b, atol=1e-12)
    dist, ang = g.pose_distance(poses[:-1], poses[1:])
    assert np.allclose(dist, 0.25) and np.allclose(ang, np.pi / 4)
