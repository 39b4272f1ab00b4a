"""UR closed-form kinematics: round trips in all 8 branches, the branch definitions, the
singularities, and FK against an independent standard-DH chain built by pinocchio."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from olp.geometry import pose_distance, wrap_half_open
from olp.kinematics import ur
from olp.kinematics.pinocchio_model import build_dh_model, frame_poses

# UR's published e-Series DH values (shared VENDOR-NOTES), metres.
UR5E = ur.URParameters(0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.0996)
UR10E = ur.URParameters(0.1807, -0.6127, -0.57155, 0.17415, 0.11985, 0.11655)
ARMS = {"UR5e": UR5E, "UR10e": UR10E}


def _random_joints(n: int, seed: int) -> np.ndarray:
    q = np.random.default_rng(seed).uniform(-math.pi, math.pi, (n, 6))
    q[:, 4] = np.copysign(np.maximum(np.abs(q[:, 4]), 1e-3), q[:, 4])
    return q


def _errors(solutions: np.ndarray, q: np.ndarray) -> np.ndarray:
    return np.max(np.abs(wrap_half_open(solutions - q[..., None, :])), axis=-1)


def _assert_rows_reproduce(p: ur.URParameters, solutions: np.ndarray, poses: np.ndarray) -> None:
    nan = np.isnan(solutions)
    assert np.array_equal(nan.any(axis=-1), nan.all(axis=-1)), "partially NaN row"
    valid = ~nan.any(axis=-1)
    assert np.all((solutions[valid] > -math.pi) & (solutions[valid] <= math.pi))
    dist, angle = pose_distance(ur.forward(p, solutions[valid]), poses[np.nonzero(valid)[0]])
    assert dist.max() < 1e-9 and angle.max() < 1e-9


@pytest.mark.parametrize("name", list(ARMS))
def test_forward_matches_a_pinocchio_dh_chain(name: str) -> None:
    p = ARMS[name]
    q = _random_joints(500, 1)
    chain = frame_poses(build_dh_model(p.a, ur.ALPHA, p.d), q)
    assert np.max(np.abs(ur.forward(p, q) - chain)) < 1e-12


def test_zero_pose_is_the_stretched_arm() -> None:
    """At zero the arm lies along -X of Base: flange at (a2 + a3, -(d4 + d6), d1 - d5), its Z
    axis along -Y (UR's zero position, arm horizontal)."""
    pose = ur.forward(UR5E, np.zeros(6))
    expected = [UR5E.a2 + UR5E.a3, -(UR5E.d4 + UR5E.d6), UR5E.d1 - UR5E.d5]
    assert np.allclose(pose[:3, 3], expected, atol=1e-12)
    assert np.allclose(pose[:3, 2], [0.0, -1.0, 0.0], atol=1e-12)


@pytest.mark.parametrize("name", list(ARMS))
def test_round_trip_every_branch(name: str) -> None:
    p = ARMS[name]
    q = _random_joints(4000, 2)
    poses = ur.forward(p, q)
    solutions = ur.inverse(p, poses)
    assert solutions.shape == (4000, 8, 6)
    err = _errors(solutions, q)
    best = np.nanargmin(np.where(np.isnan(err), np.inf, err), axis=1)
    assert np.max(err[np.arange(len(q)), best]) < 1e-7
    assert np.all(np.bincount(best, minlength=8) > 0)
    _assert_rows_reproduce(p, solutions, poses)


@pytest.mark.parametrize("name", list(ARMS))
def test_branch_rows_mean_what_they_say(name: str) -> None:
    p = ARMS[name]
    solutions = ur.inverse(p, ur.forward(p, _random_joints(1000, 3)))
    for index, branch in enumerate(ur.BRANCH_NAMES):
        shoulder, elbow, wrist = branch.split("/")
        rows = solutions[:, index]
        rows = rows[~np.isnan(rows).any(axis=1)]
        frames = ur.dh_transforms(p, rows)
        tool0 = ur.forward(p, rows)
        p5 = tool0[:, :3, 3] - p.d6 * tool0[:, :3, 2]
        side = np.sign(p.a2) * np.einsum("ij,ij->i", p5, frames[:, 0, :3, 0])
        up = np.sign(p.a2 * p.a3) * np.sin(rows[:, 2])
        assert np.all(side >= -1e-12) if shoulder == "front" else np.all(side <= 1e-12)
        assert np.all(up >= -1e-12) if elbow == "up" else np.all(up <= 1e-12)
        assert np.all(rows[:, 4] >= 0) if wrist == "noflip" else np.all(rows[:, 4] <= 0)


def test_front_up_is_the_usual_ur_pose() -> None:
    """UR's usual working pose [0, -90, 90, -90, -90, 0]° (elbow up, tool down) is front/up/flip."""
    q = np.radians([0.0, -90.0, 90.0, -90.0, -90.0, 0.0])
    solutions = ur.inverse(UR5E, ur.forward(UR5E, q))
    assert np.max(np.abs(solutions[ur.BRANCH_NAMES.index("front/up/flip")] - q)) < 1e-9


def test_wrist_singularity_reproduces_the_pose() -> None:
    q = np.array([[0.3, -1.2, 1.4, 0.5, 0.0, -0.2], [0.0, -1.5, 1.5, -1.5, 0.0, 0.0]])
    poses = ur.forward(UR5E, q)
    solutions = ur.inverse(UR5E, poses)
    _assert_rows_reproduce(UR5E, solutions, poses)
    assert not np.isnan(solutions).all(axis=(1, 2)).any()


def test_unreachable_poses_are_nan_rows() -> None:
    far = np.eye(4)
    far[:3, 3] = (3.0, 0.0, 0.5)
    assert np.isnan(ur.inverse(UR5E, far)).all()
    # p5 on axis 1 is closer than d4 to it: no axis-1 solution at all.
    axis = np.eye(4)
    axis[:3, 3] = (0.0, 0.0, 0.6 + UR5E.d6)
    assert np.isnan(ur.inverse(UR5E, axis)).all()


def test_stretched_arm_on_the_boundary() -> None:
    q = np.array([0.4, -0.3, 0.0, 0.2, 0.7, -0.1])
    pose = ur.forward(UR5E, q)
    solutions = ur.inverse(UR5E, pose)
    assert np.nanmin(_errors(solutions, q)) < 1e-6
    _assert_rows_reproduce(UR5E, solutions[None], pose[None])


def test_shapes() -> None:
    q = _random_joints(6, 4).reshape(2, 3, 6)
    poses = ur.forward(UR5E, q)
    assert poses.shape == (2, 3, 4, 4)
    assert ur.inverse(UR5E, poses).shape == (2, 3, 8, 6)
    assert ur.inverse(UR5E, poses[0, 0]).shape == (8, 6)
    with pytest.raises(ValueError):
        ur.forward(UR5E, np.zeros(5))
    with pytest.raises(ValueError):
        ur.inverse(UR5E, np.eye(3))
    with pytest.raises(ValueError):
        ur.URParameters(0.1, 0.0, -0.3, 0.1, 0.1, 0.1)


@pytest.mark.parametrize("name", list(ARMS))
def test_agrees_with_ur_analytic_ik(name: str) -> None:
    """Same FK and the same solution set as ur-analytic-ik (independent C++ code with UR's
    default DH values built in), when installed."""
    urik = pytest.importorskip("ur_analytic_ik")
    theirs = {"UR5e": urik.ur5e, "UR10e": urik.ur10e}[name]
    p = ARMS[name]
    for q in _random_joints(200, 5):
        pose = np.ascontiguousarray(theirs.forward_kinematics(*q))
        assert np.max(np.abs(pose - ur.forward(p, q))) < 1e-12
        ours = ur.inverse(p, pose)
        ours = ours[~np.isnan(ours).any(axis=-1)]
        other = np.array(theirs.inverse_kinematics(pose)).reshape(-1, 6)
        assert len(other) == len(ours)
        # each of theirs is one of ours (and, as many, the sets are equal)
        assert np.max(np.min(_errors(ours[None], other), axis=-1)) < 1e-9


@settings(max_examples=80, deadline=None)
@given(
    name=st.sampled_from(list(ARMS)),
    q=st.lists(st.floats(-math.pi, math.pi), min_size=6, max_size=6),
)
def test_round_trip_property(name: str, q: list[float]) -> None:
    # Off the wrist singularity and the stretched/folded elbow, where a joint is ill-conditioned
    # (the pose moves only quadratically with it); those are covered by the tests above.
    assume(abs(math.sin(q[4])) > 1e-3 and abs(math.sin(q[2])) > 1e-3)
    p = ARMS[name]
    joints = np.array(q)
    pose = ur.forward(p, joints)
    solutions = ur.inverse(p, pose)
    assert np.nanmin(_errors(solutions, joints)) < 1e-7
    _assert_rows_reproduce(p, solutions[None], pose[None])
