"""Every robot of the bundled library: FK against an independent description, IK round trips in
every branch, turn variants, Fanuc's J2/J3 coupling, the pinocchio chain and the collision model.

Independent references (none derived from olp's own parameters):

* ROS-Industrial robot descriptions, transcribed below joint by joint (origin, rpy, axis) with
  the repository, file and commit they come from. They use other frames and conventions than
  olp's OPW/DH parameters (link frames at the joints, KUKA's negative axes, Fanuc's ROS joint
  convention, UR's base_link turned by pi), so agreement checks the conversions too.
* The same KUKA KR 6 R900 sixx description as shipped in the ``rtb-data`` package (the
  Robotics Toolbox's data), read from the installed file itself.
* Reach figures encoded in the vendors' model names (KR 10 R1420, IRB 4600-40/2.55) and the
  LR Mate 200iC's 704 mm.
"""

from __future__ import annotations

import itertools
import math
import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from olp.geometry import inv, pose_distance, wrap_half_open
from olp.kinematics.base import turn_variants
from olp.station.loader import load_library_robot, robot_library
from olp.station.model import Robot

LIBRARY = robot_library()
REQUIRED = {
    "kuka/kr6_r900_sixx",
    "kuka/kr10_r1420",
    "abb/irb120",
    "abb/irb4600_40_255",
    "fanuc/lrmate200ic",
    "fanuc/m20ia",
    "ur/ur5e",
    "ur/ur10e",
}
PI = math.pi

# (origin xyz in m, origin rpy in rad, axis) per revolute joint, then the fixed tool0 transform
# (xyz, rpy) from the last link, and the "base" frame the controller uses (xyz, rpy) in the root.
Joint = tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]]
KUKA_TOOL0 = ((0, 0, 0), (0, PI / 2, 0))
FANUC_TOOL0 = ((0, 0, 0), (PI, -PI / 2, 0))
ABB_TOOL0 = ((0, 0, 0), (0, PI / 2, 0))
ORIGIN = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))

REFERENCES: dict[str, tuple[list[Joint], tuple, tuple]] = {
    # ros-industrial/kuka_experimental kuka_kr6_support/urdf/kr6r900sixx_macro.xacro
    # (as in rtb-data 2.0.0 kuka_description/kuka_kr6/urdf/kr6r900sixx_macro.xacro)
    "kuka/kr6_r900_sixx": (
        [
            ((0, 0, 0.400), (0, 0, 0), (0, 0, -1)),
            ((0.025, 0, 0), (0, 0, 0), (0, 1, 0)),
            ((0.455, 0, 0), (0, 0, 0), (0, 1, 0)),
            ((0, 0, 0.035), (0, 0, 0), (-1, 0, 0)),
            ((0.420, 0, 0), (0, 0, 0), (0, 1, 0)),
            ((0.080, 0, 0), (0, 0, 0), (-1, 0, 0)),
        ],
        KUKA_TOOL0,
        ORIGIN,
    ),
    # ros-industrial/kuka_experimental kuka_kr10_support/urdf/kr10r1420_macro.xacro @ 9eb27bb
    "kuka/kr10_r1420": (
        [
            ((0, 0, 0.450), (0, 0, 0), (0, 0, -1)),
            ((0.150, 0, 0), (0, 0, 0), (0, 1, 0)),
            ((0.610, 0, 0), (0, 0, 0), (0, 1, 0)),
            ((0, 0, 0.02), (0, 0, 0), (-1, 0, 0)),
            ((0.660, 0, 0), (0, 0, 0), (0, 1, 0)),
            ((0.080, 0, 0), (0, 0, 0), (-1, 0, 0)),
        ],
        KUKA_TOOL0,
        ORIGIN,
    ),
    # ros-industrial/abb abb_irb120_support/urdf/irb120_3_58_macro.xacro @ 59e17fb
    "abb/irb120": (
        [
            ((0, 0, 0), (0, 0, 0), (0, 0, 1)),
            ((0, 0, 0.29), (0, 0, 0), (0, 1, 0)),
            ((0, 0, 0.27), (0, 0, 0), (0, 1, 0)),
            ((0, 0, 0.07), (0, 0, 0), (1, 0, 0)),
            ((0.302, 0, 0), (0, 0, 0), (0, 1, 0)),
            ((0.072, 0, 0), (0, 0, 0), (1, 0, 0)),
        ],
        ABB_TOOL0,
        ORIGIN,
    ),
    # ros-industrial/abb abb_irb4600_support/urdf/irb4600_40_255_macro.xacro @ 0707207
    "abb/irb4600_40_255": (
        [
            ((0, 0, 0.495), (0, 0, 0), (0, 0, 1)),
            ((0.175, 0, 0), (0, 0, 0), (0, 1, 0)),
            ((0, 0, 1.095), (0, 0, 0), (0, 1, 0)),
            ((0, 0, 0.175), (0, 0, 0), (1, 0, 0)),
            ((1.270, 0, 0), (0, 0, 0), (0, 1, 0)),
            ((0.135, 0, 0), (0, 0, 0), (1, 0, 0)),
        ],
        ABB_TOOL0,
        ORIGIN,
    ),
    # ros-industrial/fanuc fanuc_lrmate200ic_support/urdf/lrmate200ic_macro.xacro @ 61ecc5c
    "fanuc/lrmate200ic": (
        [
            ((0, 0, 0.330), (0, 0, 0), (0, 0, 1)),
            ((0.075, 0, 0), (0, 0, 0), (0, 1, 0)),
            ((0, 0, 0.300), (0, 0, 0), (0, -1, 0)),
            ((0, 0, 0.075), (0, 0, 0), (-1, 0, 0)),
            ((0.320, 0, 0), (0, 0, 0), (0, -1, 0)),
            ((0.080, 0, 0), (0, 0, 0), (-1, 0, 0)),
        ],
        FANUC_TOOL0,
        ((0, 0, 0.330), (0, 0, 0)),
    ),
    # ros-industrial/fanuc fanuc_m20ia_support/urdf/m20ia_macro.xacro @ 526347a
    "fanuc/m20ia": (
        [
            ((0, 0, 0.525), (0, 0, 0), (0, 0, 1)),
            ((0.150, 0, 0), (0, 0, 0), (0, 1, 0)),
            ((0, 0, 0.790), (0, 0, 0), (0, -1, 0)),
            ((0, 0, 0.250), (0, 0, 0), (-1, 0, 0)),
            ((0.835, 0, 0), (0, 0, 0), (0, -1, 0)),
            ((0.100, 0, 0), (0, 0, 0), (-1, 0, 0)),
        ],
        FANUC_TOOL0,
        ((0, 0, 0.525), (0, 0, 0)),
    ),
}


def _ur_reference(d1: float, a2: float, a3: float, d4: float, d5: float, d6: float) -> tuple:
    """ros-industrial/universal_robot ur_description: urdf/inc/ur_macro.xacro @ 0290bd2 places
    the joints at the ``default_kinematics.yaml`` entries; config/ur5e/default_kinematics.yaml
    @ 6485dfa reads shoulder z d1; upper_arm roll pi/2; forearm x a2; wrist_1 x a3, z d4;
    wrist_2 y -d5, roll pi/2; wrist_3 y d6, rpy (pi/2, pi, pi). The root base_link is turned by
    pi about Z against both base_link_inertia (the chain's parent) and ``base`` (UR's Base);
    tool0 = wrist_3 · rpy(0, -pi/2, -pi/2) · rpy(pi/2, 0, pi/2)."""
    joints = [
        ((0, 0, d1), (0, 0, 0), (0, 0, 1)),
        ((0, 0, 0), (PI / 2, 0, 0), (0, 0, 1)),
        ((a2, 0, 0), (0, 0, 0), (0, 0, 1)),
        ((a3, 0, d4), (0, 0, 0), (0, 0, 1)),
        ((0, -d5, 0), (PI / 2, 0, 0), (0, 0, 1)),
        ((0, d6, 0), (PI / 2, PI, PI), (0, 0, 1)),
    ]
    return joints, "ur", ((0, 0, 0), (0, 0, PI))


REFERENCES["ur/ur5e"] = _ur_reference(0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.0996)
# UR10e: ur_description config/ur10e/physical_parameters.yaml (@ 25b5004) rounds to 1 mm.
REFERENCES["ur/ur10e"] = _ur_reference(0.181, -0.613, -0.571, 0.174, 0.120, 0.117)
TOLERANCE_M = {"ur/ur10e": 3e-3}
"""Position tolerance where the reference rounds: six lengths each within 0.55 mm of UR's
published values add up to under 3 mm at the flange (orientation does not depend on them)."""


def _urdf(joints: list[Joint], tool0: tuple, base: tuple) -> str:
    """A kinematics-only URDF: root, link_1..6 chained by the joints, tool0 and base frames."""

    def origin(xyz: tuple, rpy: tuple) -> str:
        return f'<origin xyz="{" ".join(map(str, xyz))}" rpy="{" ".join(map(str, rpy))}"/>'

    links = ["root", "chain_root", *(f"link_{i}" for i in range(1, 7)), "tool0", "base"]
    parts = [f'<link name="{name}"/>' for name in links]
    chain_root = ORIGIN if tool0 != "ur" else ((0, 0, 0), (0, 0, PI))
    parts.append(
        f'<joint name="fixed_root" type="fixed"><parent link="root"/><child link="chain_root"/>'
        f"{origin(*chain_root)}</joint>"
    )
    parent = "chain_root"
    for i, (xyz, rpy, axis) in enumerate(joints, start=1):
        parts.append(
            f'<joint name="joint_{i}" type="revolute"><parent link="{parent}"/>'
            f'<child link="link_{i}"/>{origin(xyz, rpy)}<axis xyz="{" ".join(map(str, axis))}"/>'
            f'<limit lower="-10" upper="10" effort="0" velocity="1"/></joint>'
        )
        parent = f"link_{i}"
    if tool0 == "ur":
        parts.append(
            '<link name="flange"/><joint name="to_flange" type="fixed"><parent link="link_6"/>'
            f'<child link="flange"/>{origin((0, 0, 0), (0, -PI / 2, -PI / 2))}</joint>'
        )
        parent, tool0 = "flange", ((0, 0, 0), (PI / 2, 0, PI / 2))
    parts.append(
        f'<joint name="to_tool0" type="fixed"><parent link="{parent}"/><child link="tool0"/>'
        f"{origin(*tool0)}</joint>"
    )
    parts.append(
        f'<joint name="to_base" type="fixed"><parent link="root"/><child link="base"/>'
        f"{origin(*base)}</joint>"
    )
    return '<robot name="reference">' + "".join(parts) + "</robot>"


def _reference_tool0(name: str, chain_q: np.ndarray) -> np.ndarray:
    """tool0 poses (N, 4, 4) in the reference's controller base frame for ROS joints (N, 6)."""
    model = pin.buildModelFromXML(_urdf(*REFERENCES[name]))
    return _frame_in_base(model, chain_q)


def _frame_in_base(model: pin.Model, chain_q: np.ndarray, tip: str = "tool0") -> np.ndarray:
    data = model.createData()
    tip_id, base_id = model.getFrameId(tip), model.getFrameId("base")
    out = []
    for q in chain_q:
        pin.framesForwardKinematics(model, data, q)
        out.append(np.asarray((data.oMf[base_id].inverse() * data.oMf[tip_id]).homogeneous))
    return np.array(out)


def _robot(name: str) -> Robot:
    return load_library_robot(name).place()


def _random_joints(robot: Robot, n: int, seed: int) -> np.ndarray:
    """Joints (n, 6) uniform within the limits, |q5| >= 1e-3 rad (off the wrist singularity)."""
    q = np.random.default_rng(seed).uniform(robot.limits.lower, robot.limits.upper, (n, 6))
    q[:, 4] = np.copysign(np.maximum(np.abs(q[:, 4]), 1e-3), q[:, 4])
    return q


# --------------------------------------------------------------------------------------------
# The library


def test_library_holds_the_required_robots() -> None:
    assert set(LIBRARY) >= REQUIRED
    assert set(REFERENCES) >= REQUIRED


@pytest.mark.parametrize("name", LIBRARY)
def test_library_file_is_complete(name: str) -> None:
    model = load_library_robot(name)
    robot = model.place()
    assert model.sources, "every library file cites its sources"
    assert robot.dof == 6
    assert not np.any(robot.limits.violations(robot.home))
    assert np.all(robot.limits.acceleration > robot.limits.velocity)
    links = {s.link for s in robot.collision}
    assert links == {"base", *(f"link_{i}" for i in range(1, 7))}


# --------------------------------------------------------------------------------------------
# FK against the independent descriptions


@pytest.mark.parametrize("name", sorted(REQUIRED))
def test_forward_kinematics_matches_the_reference_description(name: str) -> None:
    robot = _robot(name)
    q = _random_joints(robot, 300, 1)
    chain_q = robot.kinematics.chain_joints(q)
    reference = _reference_tool0(name, chain_q)
    # The reference is in the controller's base frame; olp's tool0 is in the mounting frame.
    ours = inv(robot.controller_base) @ robot.kinematics.forward(q)
    dist, angle = pose_distance(ours, reference)
    assert dist.max() < TOLERANCE_M.get(name, 1e-9)
    assert angle.max() < 1e-9


def test_reference_check_is_sensitive_to_the_fanuc_coupling() -> None:
    """Without the J2/J3 coupling the Fanuc description disagrees: the comparison above is not
    vacuous for the coupling."""
    robot = _robot("fanuc/lrmate200ic")
    q = _random_joints(robot, 50, 2)
    reference = _reference_tool0("fanuc/lrmate200ic", q)  # controller joints fed as ROS joints
    ours = inv(robot.controller_base) @ robot.kinematics.forward(q)
    assert np.min(pose_distance(ours, reference)[0][np.abs(q[:, 1]) > 0.2]) > 1e-3


def _xacro_joints(text: str) -> list[Joint]:
    """Revolute joints of a ROS-Industrial KUKA macro xacro (``${prefix}`` and ``DEG2RAD``)."""
    joints = []
    pattern = r'<joint name="\$\{prefix\}joint_a\d" type="revolute">(.*?)</joint>'
    for body in re.findall(pattern, text, re.S):
        xyz = re.search(r'<origin xyz="([^"]*)" rpy="([^"]*)"', body)
        axis = re.search(r'<axis xyz="([^"]*)"', body)
        assert xyz is not None and axis is not None
        joints.append(
            (
                tuple(float(v) for v in xyz.group(1).split()),
                tuple(float(v) for v in xyz.group(2).split()),
                tuple(float(v) for v in axis.group(1).split()),
            )
        )
    return joints  # type: ignore[return-value]


def test_kr6_r900_sixx_matches_the_rtb_data_description() -> None:
    """Read the third-party file itself (rtb-data, a dev dependency), not a transcription."""
    rtbdata = pytest.importorskip("rtbdata")
    folder = Path(rtbdata.__file__).parent / "xacro" / "kuka_description" / "kuka_kr6" / "urdf"
    text = (folder / "kr6r900sixx_macro.xacro").read_text(encoding="utf-8")
    joints = _xacro_joints(text)
    assert len(joints) == 6
    assert 'rpy="0 ${DEG2RAD * 90} 0"' in text  # tool0 = link_6 · Ry(90°), as KUKA_TOOL0
    model = pin.buildModelFromXML(_urdf(joints, KUKA_TOOL0, ORIGIN))
    robot = _robot("kuka/kr6_r900_sixx")
    q = _random_joints(robot, 200, 3)
    dist, angle = pose_distance(robot.kinematics.forward(q), _frame_in_base(model, q))
    assert dist.max() < 1e-9 and angle.max() < 1e-9


@pytest.mark.parametrize(
    ("name", "reach_mm", "tolerance_mm"),
    [
        ("kuka/kr10_r1420", 1420.0, 2.0),  # "R1420"
        ("abb/irb4600_40_255", 2550.0, 5.0),  # "2.55" m, given to 10 mm
        ("fanuc/lrmate200ic", 704.0, 1.0),
    ],
)
def test_datasheet_reach(name: str, reach_mm: float, tolerance_mm: float) -> None:
    """Reach = largest distance of the wrist centre from axis 1 (the datasheets' point P)."""
    p = _robot(name).kinematics.params  # type: ignore[attr-defined]
    reach = (p.a1 + p.c2 + math.hypot(p.a2, p.c3)) * 1000
    assert abs(reach - reach_mm) <= tolerance_mm


# --------------------------------------------------------------------------------------------
# IK round trips, branches, turns


@pytest.mark.parametrize("name", LIBRARY)
def test_ik_of_fk_contains_q_in_every_branch(name: str) -> None:
    robot = _robot(name)
    q = _random_joints(robot, 3000, 4)
    poses = robot.flange_poses(q)
    solutions = robot.solve(poses)
    err = np.max(np.abs(wrap_half_open(solutions - q[:, None, :])), axis=-1)
    best = np.nanargmin(np.where(np.isnan(err), np.inf, err), axis=1)
    assert np.max(err[np.arange(len(q)), best]) < 1e-7
    # q's own branch is found for every pose, and q comes from each of the 8 branches somewhere.
    assert np.all(np.bincount(best, minlength=8) > 0)
    valid = ~np.isnan(solutions).any(axis=-1)
    dist, angle = pose_distance(robot.flange_poses(solutions[valid]), poses[np.nonzero(valid)[0]])
    assert dist.max() < 1e-9 and angle.max() < 1e-9


@pytest.mark.parametrize("name", LIBRARY)
def test_turn_variants_recover_q_itself(name: str) -> None:
    """q in the limits, maybe turned by 360° on a wrist/base joint, is among the variants."""
    robot = _robot(name)
    q = _random_joints(robot, 200, 5)
    solutions = robot.solve(robot.flange_poses(q))
    variants = turn_variants(solutions, robot.limits.lower, robot.limits.upper)
    flat = variants.reshape(len(q), -1, 6)
    found = np.nanmin(np.max(np.abs(flat - q[:, None, :]), axis=-1), axis=1)
    assert found.max() < 1e-7


@pytest.mark.parametrize("name", LIBRARY)
def test_branch_of_names_the_branch_holding_q(name: str) -> None:
    robot = _robot(name)
    for q in _random_joints(robot, 20, 6):
        row = robot.solve(robot.flange_poses(q)[None])[0, robot.branch_of(q)]
        assert np.max(np.abs(wrap_half_open(row - q))) < 1e-7


# --------------------------------------------------------------------------------------------
# Fanuc's J2/J3 coupling


@pytest.mark.parametrize("name", ["fanuc/lrmate200ic", "fanuc/m20ia"])
def test_fanuc_j3_is_measured_from_the_horizontal(name: str) -> None:
    """With the controller's J3 at 0 the forearm stays level whatever J2 does (the pendant's J3
    is the forearm's angle to the horizontal), and flange_poses/solve speak that J3."""
    robot = _robot(name)
    p = robot.kinematics.params  # type: ignore[attr-defined]
    for j2 in np.radians([-40.0, 0.0, 30.0, 60.0]):
        q = np.array([0.0, j2, 0.0, 0.0, -0.5, 0.0])
        links = robot.link_poses(q)
        forearm = links["link_5"][:3, 3] - links["link_4"][:3, 3]
        assert np.allclose(forearm, [p.c3, 0.0, 0.0], atol=1e-12)
        solutions = robot.solve(robot.flange_poses(q)[None])[0]
        assert np.nanmin(np.max(np.abs(solutions - q), axis=-1)) < 1e-9


def test_fanuc_home_pose_in_world() -> None:
    """LR Mate 200iC at J1..J6 = 0, 0, 0, 0, -90, 0: wrist centre a1 + c3 in front, c1 + c2 - a2
    high; the flange faces down (c4 below the wrist centre)."""
    robot = _robot("fanuc/lrmate200ic")
    pose = robot.kinematics.forward(np.radians([0, 0, 0, 0, -90, 0]))
    assert np.allclose(pose[:3, 3], [0.395, 0.0, 0.625], atol=1e-12)
    assert np.allclose(pose[:3, 2], [0.0, 0.0, -1.0], atol=1e-12)


# --------------------------------------------------------------------------------------------
# pinocchio chain and collision model


@pytest.mark.parametrize("name", LIBRARY)
def test_pinocchio_chain_agrees_with_the_closed_form(name: str) -> None:
    robot = _robot(name)
    q = _random_joints(robot, 200, 7)
    model = robot.kinematics.chain_model()
    chain = _tool0(model, robot.kinematics.chain_joints(q))
    assert np.max(np.abs(chain - robot.kinematics.forward(q))) < 1e-9


def _tool0(model: pin.Model, chain_q: np.ndarray) -> np.ndarray:
    data = model.createData()
    frame = model.getFrameId("tool0")
    out = []
    for qi in chain_q:
        pin.framesForwardKinematics(model, data, qi)
        out.append(np.asarray(data.oMf[frame].homogeneous))
    return np.array(out)


@pytest.mark.parametrize("name", LIBRARY)
def test_collision_model_covers_the_kinematic_skeleton(name: str) -> None:
    """Points along base -> joint origins -> tool0 lie inside the capsules, in any pose: each
    shape sits on the right link in the right frame."""
    robot = _robot(name)
    model = robot.kinematics.chain_model()
    data = model.createData()
    for q in _random_joints(robot, 10, 8):
        links = robot.link_poses(q)
        pin.framesForwardKinematics(model, data, robot.kinematics.chain_joints(q))
        joints = [np.asarray(data.oMi[i].translation) for i in range(1, model.njoints)]
        tool0 = np.asarray(data.oMf[model.getFrameId("tool0")].translation)
        skeleton = np.array([np.zeros(3), *joints, tool0])
        t = np.linspace(0.0, 1.0, 25)[:, None]
        points = np.concatenate([a + t * (b - a) for a, b in itertools.pairwise(skeleton)])
        inside = np.zeros(len(points), dtype=bool)
        for shape in robot.collision:
            inside |= shape.contains(points, links[shape.link])
        assert inside.all(), points[~inside]
