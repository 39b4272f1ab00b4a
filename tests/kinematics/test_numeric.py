"""URDF robots with a tip link and the numeric (damped least squares) IK fallback, on a small
6-axis URDF written here: neither OPW (its wrist is not spherical) nor UR."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from olp.errors import StationError
from olp.geometry import pose_distance
from olp.kinematics import ur
from olp.kinematics.base import JointCoupling
from olp.kinematics.models import ChainKinematics, default_seeds
from olp.kinematics.pinocchio_model import TOOL0, build_dh_model, frame_poses, load_urdf_model
from olp.station.loader import load_station

# Offsets along every link and a tilted last axis: no closed form fits this arm. A gripper
# finger hangs off link_6 (not on the chain to the tip, so it is locked).
URDF = """<robot name="offset_arm">
  <link name="world_plate"/><link name="base_link"/>
  <link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/><link name="l5"/>
  <link name="l6"/><link name="flange"/><link name="finger"/>
  <joint name="mount" type="fixed"><parent link="world_plate"/><child link="base_link"/>
    <origin xyz="0 0 0.05" rpy="0 0 0"/></joint>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="l1"/>
    <origin xyz="0 0 0.30" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.05 0.08 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="0 -0.03 0.40" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j4" type="revolute"><parent link="l3"/><child link="l4"/>
    <origin xyz="0.35 0 0.04" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j5" type="revolute"><parent link="l4"/><child link="l5"/>
    <origin xyz="0.06 0.03 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j6" type="revolute"><parent link="l5"/><child link="l6"/>
    <origin xyz="0.07 0 0.02" rpy="0 0.3 0"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="to_flange" type="fixed"><parent link="l6"/><child link="flange"/>
    <origin xyz="0.03 0 0" rpy="0 1.5707963267948966 0"/></joint>
  <joint name="finger_joint" type="prismatic"><parent link="l6"/><child link="finger"/>
    <origin xyz="0.02 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="1" velocity="1"/></joint>
</robot>
"""


@pytest.fixture()
def urdf_file(tmp_path: Path) -> Path:
    path = tmp_path / "offset_arm.urdf"
    path.write_text(URDF, encoding="utf-8")
    return path


def _chain(urdf_file: Path) -> ChainKinematics:
    model = load_urdf_model(str(urdf_file), "flange", base="world_plate")
    lower, upper = -np.full(6, 3.0), np.full(6, 3.0)
    return ChainKinematics(
        model, default_seeds(np.zeros(6), lower, upper), JointCoupling.identity(6)
    )


def test_urdf_chain_runs_root_to_tip_and_locks_the_rest(urdf_file: Path) -> None:
    chain = _chain(urdf_file)
    assert chain.dof == 6  # the prismatic finger is not on the chain to the flange
    pose = chain.forward(np.zeros(6))
    # Sum of the origins along the chain at zero (the tilted j6 turns the last 0.03 m).
    x = 0.05 + 0.35 + 0.06 + 0.07 + 0.03 * math.cos(0.3)
    z = 0.05 + 0.30 + 0.40 + 0.04 + 0.02 - 0.03 * math.sin(0.3)
    assert np.allclose(pose[:3, 3], [x, 0.08 - 0.03 + 0.03, z], atol=1e-12)


def test_urdf_chain_in_another_base_link(urdf_file: Path) -> None:
    """``base`` re-expresses the chain in a fixed link: base_link sits 50 mm above the root."""
    root = load_urdf_model(str(urdf_file), "flange")
    raised = load_urdf_model(str(urdf_file), "flange", base="base_link")
    q = np.random.default_rng(3).uniform(-2, 2, (5, 6))
    shift = frame_poses(root, q)[:, :3, 3] - frame_poses(raised, q)[:, :3, 3]
    assert np.allclose(shift, [0.0, 0.0, 0.05], atol=1e-12)
    with pytest.raises(ValueError, match="moves with a joint"):
        load_urdf_model(str(urdf_file), "flange", base="l2")


def test_numeric_ik_reproduces_reachable_poses(urdf_file: Path) -> None:
    chain = _chain(urdf_file)
    q = np.random.default_rng(1).uniform(-1.5, 1.5, (12, 6))
    poses = chain.forward(q)
    solutions = chain.inverse(poses)
    assert solutions.shape == (12, 9, 6)
    valid = ~np.isnan(solutions).any(axis=-1)
    assert valid.any(axis=1).all(), "every pose solved by some seed"
    dist, angle = pose_distance(chain.forward(solutions[valid]), poses[np.nonzero(valid)[0]])
    assert dist.max() < 1e-9 and angle.max() < 1e-9


def test_seed_row_converges_to_the_nearby_solution(urdf_file: Path) -> None:
    chain = _chain(urdf_file)
    q = np.array([0.4, -0.6, 0.9, 0.3, -0.7, 1.1])
    row = chain.inverse(chain.forward(q)[None], seed=q + 0.05)[0, 0]
    assert np.max(np.abs(row - q)) < 1e-8


def test_continuation_along_a_path_is_smooth(urdf_file: Path) -> None:
    chain = _chain(urdf_file)
    q0 = np.array([0.2, -0.4, 0.8, 0.1, -0.5, 0.3])
    path = q0 + np.linspace(0.0, 1.0, 40)[:, None] * np.array([0.5, 0.3, -0.4, 0.6, 0.2, -0.5])
    rows = chain.inverse(chain.forward(path), seed=q0)[:, 0]
    assert not np.isnan(rows).any()
    # The same solution all along (another branch would be off by tenths of a radian); the pose
    # tolerance of the solver allows ~1e-7 rad where the path comes near a singularity.
    assert np.max(np.abs(rows - path)) < 1e-6
    assert np.max(np.abs(np.diff(rows, axis=0))) < 0.05


def test_unreachable_pose_gives_nan_rows(urdf_file: Path) -> None:
    chain = _chain(urdf_file)
    far = np.eye(4)
    far[:3, 3] = (5.0, 0.0, 0.0)
    assert np.isnan(chain.inverse(far[None])).all()


def test_dh_chain_builder_matches_the_ur_closed_form() -> None:
    p = ur.URParameters(0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.0996)
    q = np.random.default_rng(2).uniform(-3, 3, (50, 6))
    model = build_dh_model(p.a, ur.ALPHA, p.d)
    assert np.max(np.abs(frame_poses(model, q, TOOL0) - ur.forward(p, q))) < 1e-12


def test_urdf_robot_in_a_station(tmp_path: Path, urdf_file: Path) -> None:
    station = tmp_path / "cell.yaml"
    station.write_text(
        f"""name: urdf_cell
robot:
  name: offset arm
  vendor: ur
  kinematics: {{type: urdf, file: {urdf_file.name}, tip: flange, base: world_plate}}
  limits:
    position_deg: [[-170, 170], [-170, 170], [-170, 170], [-170, 170], [-170, 170], [-170, 170]]
    velocity_deg_s: [90, 90, 90, 90, 90, 90]
    acceleration_deg_s2: [200, 200, 200, 200, 200, 200]
    jerk_deg_s3: [2000, 2000, 2000, 2000, 2000, 2000]
  home_deg: [0, -20, 40, 0, 30, 0]
  collision:
    - {{link: l3, capsule: {{from: [0, 0, 0], to: [350, 0, 40], radius: 40}}}}
  base: {{xyz: [1000, 0, 0]}}
""",
        encoding="utf-8",
    )
    robot = load_station(station).robot
    q = np.radians([10.0, -30.0, 50.0, 20.0, 40.0, -10.0])
    flange = robot.flange_poses(q)
    assert flange[0, 3] > 1.0  # placed by base
    row = robot.solve(flange[None], seed=q)[0, robot.branch_of(q)]
    assert np.max(np.abs(row - q)) < 1e-8
    assert set(robot.link_poses(q)) >= {"base", "l1", "l3", "flange"}


@pytest.mark.parametrize(
    ("kinematics", "key", "needle"),
    [
        ("{type: urdf, file: offset_arm.urdf, tip: nope}", "tip", "link 'nope' is not in the URDF"),
        ("{type: urdf, file: missing.urdf, tip: flange}", "file", "no such file: missing.urdf"),
        ("{type: urdf, file: bad.urdf, tip: flange}", "file", "cannot read URDF bad.urdf"),
    ],
)
def test_urdf_mistakes_are_located(
    tmp_path: Path, urdf_file: Path, kinematics: str, key: str, needle: str
) -> None:
    (tmp_path / "bad.urdf").write_text("<robot name='x'><link", encoding="utf-8")
    station = tmp_path / "cell.yaml"
    station.write_text(
        "robot:\n  vendor: ur\n"
        f"  kinematics: {kinematics}\n"
        "  limits: {position_deg: [[-1, 1]], velocity_deg_s: [1], acceleration_deg_s2: [1],"
        " jerk_deg_s3: [1]}\n  home_deg: [0]\n",
        encoding="utf-8",
    )
    with pytest.raises(StationError) as info:
        load_station(station)
    assert needle in info.value.message
    assert info.value.span is not None and info.value.span.line == 3
    assert f"kinematics.{key}" in info.value.message


def test_dh_table_robot_in_a_station(tmp_path: Path) -> None:
    """A robot from a DH table (job 15): UR5e's published table as rows, numeric IK."""
    station = tmp_path / "cell.yaml"
    station.write_text(
        """robot:
  name: dh arm
  vendor: ur
  kinematics:
    type: dh
    rows:
      - {a: 0, alpha_deg: 90, d: 162.5}
      - {a: -425, alpha_deg: 0, d: 0}
      - {a: -392.2, alpha_deg: 0, d: 0}
      - {a: 0, alpha_deg: 90, d: 133.3}
      - {a: 0, alpha_deg: -90, d: 99.7}
      - {a: 0, alpha_deg: 0, d: 99.6}
  limits:
    position_deg: [[-360, 360], [-360, 360], [-180, 180], [-360, 360], [-360, 360], [-360, 360]]
    velocity_deg_s: [180, 180, 180, 180, 180, 180]
    acceleration_deg_s2: [450, 450, 450, 450, 450, 450]
    jerk_deg_s3: [4500, 4500, 4500, 4500, 4500, 4500]
  home_deg: [0, -90, 90, -90, -90, 0]
""",
        encoding="utf-8",
    )
    robot = load_station(station).robot
    p = ur.URParameters(0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.0996)
    q = np.radians([20.0, -70.0, 80.0, -100.0, -60.0, 30.0])
    assert np.allclose(robot.flange_poses(q), ur.forward(p, q), atol=1e-12)
    sols = robot.solve(robot.flange_poses(q)[None])[0]
    valid = ~np.isnan(sols).any(axis=-1)
    dist, _ = pose_distance(robot.flange_poses(sols[valid]), robot.flange_poses(q))
    assert valid.any() and dist.max() < 1e-9


def test_a_one_joint_chain_solves_without_a_crash() -> None:
    """pinocchio returns a one-joint chain's Jacobian as a vector; the solver must not pass a
    scalar step on (it raised Boost.Python.ArgumentError)."""
    model = build_dh_model([0.1], [0.0], [0.3])
    chain = ChainKinematics(model, np.zeros((1, 1)), JointCoupling.identity(1))
    target = chain.forward(np.array([[0.4]]))
    solutions = chain.inverse(target)
    assert np.any(np.all(np.abs(solutions - 0.4) < 1e-6, axis=-1))
