"""OPW forward and inverse kinematics, checked against a published point, a pinocchio joint chain
and their own round trip, for every robot of the bundled library (shared/VENDOR-NOTES.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from olp.geometry import pose_distance, wrap_half_open
from olp.kinematics import opw
from olp.kinematics import pinocchio_model as pm

DEG = math.pi / 180.0
MM = 1e-3

CONVENTIONS: dict[str, tuple[tuple[float, ...], tuple[int, ...]]] = {
    "K": ((0.0, -90 * DEG, 0.0, 0.0, 0.0, 0.0), (-1, 1, 1, -1, 1, -1)),
    "A": ((0.0, 0.0, -90 * DEG, 0.0, 0.0, 0.0), (1, 1, 1, 1, 1, 1)),
    "F": ((0.0, 0.0, -90 * DEG, 0.0, 0.0, 180 * DEG), (1, 1, -1, -1, -1, -1)),
}

# a1, a2, c1, c2, c3, c4 in mm (b = 0) and convention, from the VENDOR-NOTES OPW table.
TABLE = {
    "KUKA KR 6 R900 sixx": (25, -35, 400, 455, 420, 80, "K"),
    "KUKA KR 6 R900-2": (25, -25, 400, 455, 420, 90, "K"),
    "KUKA KR 10 R1420": (150, -20, 450, 610, 660, 80, "K"),
    "ABB IRB 120-3/0.6": (0, -70, 290, 270, 302, 72, "A"),
    "ABB IRB 4600-40/2.55": (175, -175, 495, 1095, 1270, 135, "A"),
    "Fanuc LR Mate 200iD": (50, -35, 330, 330, 335, 80, "F"),
    "Fanuc LR Mate 200iD/7L": (50, -35, 330, 440, 420, 80, "F"),
    "Fanuc LR Mate 200iC": (75, -75, 330, 300, 320, 80, "F"),
    "Fanuc M-20iA": (150, -250, 525, 790, 835, 100, "F"),
}


def _params(a1: float, a2: float, c1: float, c2: float, c3: float, c4: float, conv: str):
    offsets, signs = CONVENTIONS[conv]
    return opw.OPWParameters(
        a1 * MM, a2 * MM, 0.0, c1 * MM, c2 * MM, c3 * MM, c4 * MM, offsets, signs
    )


ROBOTS = {name: _params(*row) for name, row in TABLE.items()}
# Not a real robot: a lateral offset b and offsets/signs on every joint exercise the general
# formulas that the b = 0 library never reaches.
ROBOTS["synthetic b != 0"] = opw.OPWParameters(
    0.05,
    -0.035,
    0.07,
    0.33,
    0.33,
    0.335,
    0.08,
    (0.1, 0.2, -0.3, 0.4, 0.0, 0.6),
    (1, -1, -1, 1, -1, -1),
)
LIBRARY = [name for name in ROBOTS if name in TABLE]

KUKA_A = np.array([-170, -190, -120, -185, -120, -350]) * DEG
KUKA_B = np.array([170, 45, 156, 185, 120, 350]) * DEG


def _random_joints(rng: np.random.Generator, n: int, limit: float = 170 * DEG) -> np.ndarray:
    """Controller joints (n, 6) in ±limit with |q5| >= 1e-3 (off the wrist singularity)."""
    q = rng.uniform(-limit, limit, (n, 6))
    q[:, 4] = np.copysign(np.maximum(np.abs(q[:, 4]), 1e-3), q[:, 4])
    return q


def _angle_error(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Largest joint difference modulo 2 pi, over the last axis."""
    return np.max(np.abs(wrap_half_open(a - b)), axis=-1)


def _true_branch(solutions: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Index (N,) of the branch reproducing q (N, 6); asserts one exists within 1e-7 rad."""
    err = _angle_error(solutions, q[:, None, :])
    best = np.nanargmin(np.where(np.isnan(err), np.inf, err), axis=1)
    assert np.max(err[np.arange(len(q)), best]) < 1e-7
    return best


def _assert_solutions_reproduce(params: opw.OPWParameters, solutions, poses) -> None:
    """Every non-NaN row of solutions (N, 8, 6) maps back to poses (N, 4, 4); NaN rows whole."""
    nan = np.isnan(solutions)
    assert np.array_equal(nan.any(axis=-1), nan.all(axis=-1)), "partially NaN solution row"
    valid = ~nan.any(axis=-1)
    assert np.all((solutions[valid] > -math.pi) & (solutions[valid] <= math.pi))
    dist, angle = pose_distance(opw.forward(params, solutions[valid]), poses[np.nonzero(valid)[0]])
    assert dist.max() < 1e-9
    assert angle.max() < 1e-9


# --------------------------------------------------------------------------------------------
# Forward kinematics


def test_published_check_point_kr6_r700_sixx() -> None:
    """KR 6 R700 sixx (25, -35, 400, 315, 365, 80 mm) with every joint at 0.2 rad: flange at
    (734.1169, -152.0347, 182.639) mm.

    Interpretation: the 0.2 rad are *controller* joints A1..A6 in KUKA's convention K (offsets
    [0, -90°, 0, 0, 0, 0], signs [-1, 1, 1, -1, 1, -1]), as in ROS-Industrial opw_kinematics'
    KUKA test; "flange" is tool0's origin (it coincides with KUKA's flange origin). Reading the
    0.2 rad as model joints (offsets 0, signs +1) puts the point near (236.9, 51.2, 1124.7) mm, so
    that reading is ruled out (asserted below).
    """
    offsets, signs = CONVENTIONS["K"]
    kr6_r700 = opw.OPWParameters(
        0.025, -0.035, 0.0, 0.400, 0.315, 0.365, 0.080, offsets=offsets, signs=signs
    )
    expected = np.array([734.1169, -152.0347, 182.639])
    q = np.full(6, 0.2)
    assert np.allclose(opw.forward(kr6_r700, q)[:3, 3] / MM, expected, atol=1e-3, rtol=0)
    model_joints = opw.OPWParameters(0.025, -0.035, 0.0, 0.400, 0.315, 0.365, 0.080)
    assert np.linalg.norm(opw.forward(model_joints, q)[:3, 3] / MM - expected) > 100


def test_kuka_home_kr6_r900_sixx() -> None:
    """KUKA HOME {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}: A2 = -90° stands the lower arm upright
    (A2 = 0 is the arm stretched horizontally) and A3 = 90° turns the forearm level, pointing
    forward, with the A4 axis |a2| above axis 3. So tool0 is at x = a1 + c3 + c4 = 525 mm,
    z = c1 + c2 - a2 = 890 mm, Z pointing along +X."""
    pose = opw.forward(ROBOTS["KUKA KR 6 R900 sixx"], np.array([0, -90, 90, 0, 0, 0]) * DEG)
    assert np.allclose(pose[:3, 3], [0.525, 0.0, 0.890], atol=1e-12)
    assert np.allclose(pose[:3, 2], [1.0, 0.0, 0.0], atol=1e-12)


@pytest.mark.parametrize("name", list(ROBOTS))
def test_model_zero_is_the_candle(name: str) -> None:
    p = ROBOTS[name]
    q = opw.to_controller_joints(p, np.zeros(6))
    pose = opw.forward(p, q)
    centre = opw.wrist_centre(p, pose)
    assert np.allclose(centre, [p.a1 + p.a2, p.b, p.c1 + p.c2 + p.c3], atol=1e-12)
    assert np.allclose(pose[:3, :3], np.eye(3), atol=1e-12)
    assert np.allclose(opw.to_model_joints(p, q), 0.0, atol=1e-15)


@pytest.mark.parametrize("name", list(ROBOTS))
def test_forward_matches_pinocchio_chain(name: str) -> None:
    p = ROBOTS[name]
    q = np.random.default_rng(1).uniform(-2 * math.pi, 2 * math.pi, (2000, 6))
    model = pm.build_model(p)
    chain = np.array([pm.fk_pinocchio(model, qi) for qi in q])
    closed = opw.forward(p, q)
    assert np.max(np.abs(closed - chain)) < 1e-9


def test_link_poses_are_the_chain_frames() -> None:
    p = ROBOTS["synthetic b != 0"]
    model = pm.build_model(p)
    q = np.array([0.3, -0.5, 1.1, 0.7, -0.4, 2.0])
    poses = pm.link_poses(model, q)
    named = dict(zip(pm.LINK_POSE_NAMES, poses, strict=True))
    tool0 = opw.forward(p, q)
    theta1 = opw.to_model_joints(p, q)[0]
    assert len(poses) == 7
    assert np.allclose(named["tool0"], tool0, atol=1e-12)
    assert np.allclose(named["joint_5"][:3, 3], opw.wrist_centre(p, tool0), atol=1e-12)
    c, s = math.cos(theta1), math.sin(theta1)
    shoulder = [c * p.a1 - s * p.b, s * p.a1 + c * p.b, p.c1]
    assert np.allclose(named["joint_2"][:3, 3], shoulder, atol=1e-12)


def test_forward_shapes() -> None:
    p = ROBOTS["KUKA KR 6 R900 sixx"]
    assert opw.forward(p, np.zeros(6)).shape == (4, 4)
    assert opw.forward(p, np.zeros((2, 3, 6))).shape == (2, 3, 4, 4)
    assert opw.wrist_x_in_a1(p, np.zeros((5, 6))).shape == (5,)
    with pytest.raises(ValueError):
        opw.forward(p, np.zeros(5))


@pytest.mark.parametrize(
    "change",
    [{"offsets": (0.0,) * 5}, {"signs": (1, 1, 1, 1, 2, 1)}, {"c2": math.nan}, {"c2": 0.0}],
)
def test_parameters_are_validated(change: dict) -> None:
    values = {"a1": 0.1, "a2": -0.1, "b": 0.0, "c1": 0.4, "c2": 0.5, "c3": 0.5, "c4": 0.1}
    with pytest.raises(ValueError):
        opw.OPWParameters(**{**values, **change})


# --------------------------------------------------------------------------------------------
# Inverse kinematics


@pytest.mark.parametrize("name", list(ROBOTS))
def test_ik_round_trip(name: str) -> None:
    p = ROBOTS[name]
    q = _random_joints(np.random.default_rng(2), 2000)
    poses = opw.forward(p, q)
    solutions = opw.inverse(p, poses)
    assert solutions.shape == (2000, 8, 6)
    _true_branch(solutions, q)
    _assert_solutions_reproduce(p, solutions, poses)


@pytest.mark.parametrize("name", list(ROBOTS))
def test_every_branch_is_the_true_one_somewhere(name: str) -> None:
    p = ROBOTS[name]
    q = _random_joints(np.random.default_rng(3), 2000)
    branch = _true_branch(opw.inverse(p, opw.forward(p, q)), q)
    assert np.all(np.bincount(branch, minlength=8) > 0)


@pytest.mark.parametrize("name", list(ROBOTS))
def test_branch_index_means_what_it_says(name: str) -> None:
    p = ROBOTS[name]
    q = _random_joints(np.random.default_rng(4), 500)
    solutions = opw.inverse(p, opw.forward(p, q))
    psi3 = math.atan2(p.a2, p.c3)
    for index, branch in enumerate(opw.BRANCHES):
        assert opw.branch_index(branch.shoulder, branch.elbow, branch.wrist) == index
        assert opw.BRANCH_NAMES[index] == branch.name
        rows = solutions[:, index]
        rows = rows[~np.isnan(rows).any(axis=1)]
        theta = opw.to_model_joints(p, rows)
        x = opw.wrist_x_in_a1(p, rows)
        elbow = wrap_half_open(theta[:, 2] + psi3)
        flip = p.signs[4] * wrap_half_open(theta[:, 4])
        assert np.all(x >= 0) if branch.shoulder == "front" else np.all(x <= 0)
        assert np.all(elbow >= 0) if branch.elbow == "up" else np.all(elbow <= 0)
        assert np.all(flip >= 0) if branch.wrist == "noflip" else np.all(flip <= 0)


@settings(max_examples=60, deadline=None)
@given(
    name=st.sampled_from(list(ROBOTS)),
    q=st.lists(st.floats(-3.0, 3.0), min_size=6, max_size=6),
)
def test_ik_round_trip_property(name: str, q: list[float]) -> None:
    assume(abs(q[4]) > 1e-3)
    p = ROBOTS[name]
    joints = np.array(q)
    pose = opw.forward(p, joints)
    solutions = opw.inverse(p, pose)
    assert solutions.shape == (8, 6)
    assert np.nanmin(_angle_error(solutions, joints)) < 1e-7
    _assert_solutions_reproduce(p, solutions[None], pose[None])


def test_wrist_singularity_still_reproduces_the_pose() -> None:
    p = ROBOTS["KUKA KR 6 R900 sixx"]
    q = np.array([[0.3, -1.2, 1.4, 0.5, 0.0, -0.2], [0.0, -90 * DEG, 90 * DEG, 0.0, 0.0, 0.0]])
    poses = opw.forward(p, q)
    solutions = opw.inverse(p, poses)
    _assert_solutions_reproduce(p, solutions, poses)
    # Only q4 + q6 is determined (KUKA signs both -1, so the sum is what the model sees).
    front_up = solutions[:, opw.branch_index("front", "up", "noflip")]
    assert np.allclose(front_up[:, :3], q[:, :3], atol=1e-9)
    assert np.allclose(wrap_half_open(front_up[:, 3] + front_up[:, 5] - q[:, 3] - q[:, 5]), 0)


def test_stretched_arm_on_the_workspace_boundary() -> None:
    """Forearm in line with the lower arm: the arccos argument is ±1 up to rounding."""
    p = ROBOTS["ABB IRB 120-3/0.6"]
    theta = np.array([0.4, 0.3, -math.atan2(p.a2, p.c3), 0.2, 0.7, -0.1])
    q = opw.to_controller_joints(p, theta)
    pose = opw.forward(p, q)
    solutions = opw.inverse(p, pose)
    assert not np.isnan(solutions[opw.branch_index("front", "up", "noflip")]).any()
    assert np.nanmin(_angle_error(solutions, q)) < 1e-6
    _assert_solutions_reproduce(p, solutions[None], pose[None])


def test_unreachable_pose_gives_nan() -> None:
    p = ROBOTS["KUKA KR 6 R900 sixx"]
    far = np.eye(4)
    far[:3, 3] = (10.0, 0.0, 0.5)
    assert np.isnan(opw.inverse(p, far)).all()


def test_pose_reachable_only_in_front() -> None:
    """Wrist centre near the front reach limit: the back shoulder is 2·a1 farther away."""
    p = ROBOTS["KUKA KR 10 R1420"]
    reach = p.c2 + math.hypot(p.a2, p.c3)
    pose = np.eye(4)
    pose[:3, 3] = (p.a1 + reach - 0.01, 0.0, p.c1 + p.c4)
    solutions = opw.inverse(p, pose)
    assert not np.isnan(solutions[:4]).any()
    assert np.isnan(solutions[4:]).all()
    _assert_solutions_reproduce(p, solutions[None], pose[None])


def test_wrist_centre_inside_the_b_cylinder_is_unreachable() -> None:
    p = ROBOTS["synthetic b != 0"]
    pose = np.eye(4)
    pose[:3, 3] = (0.01, 0.0, 0.6 + p.c4)
    assert np.isnan(opw.inverse(p, pose)).all()


def test_inverse_shapes_and_out() -> None:
    p = ROBOTS["ABB IRB 4600-40/2.55"]
    q = _random_joints(np.random.default_rng(5), 6).reshape(2, 3, 6)
    poses = opw.forward(p, q)
    solutions = opw.inverse(p, poses)
    assert solutions.shape == (2, 3, 8, 6)
    out = np.empty((6, 8, 6))
    assert opw.inverse(p, poses.reshape(6, 4, 4), out=out) is out
    assert np.array_equal(out, solutions.reshape(6, 8, 6), equal_nan=True)
    with pytest.raises(ValueError):
        opw.inverse(p, poses, out=np.empty((5, 8, 6)))
    with pytest.raises(ValueError):
        opw.inverse(p, np.eye(3))


def test_inverse_blocks_agree_with_single_poses() -> None:
    """More poses than one internal block, with unreachable poses mixed in."""
    p = ROBOTS["Fanuc M-20iA"]
    poses = opw.forward(p, _random_joints(np.random.default_rng(6), 9000))
    poses[::7, :3, 3] *= 5.0
    batch = opw.inverse(p, poses)
    for i in (0, 7, 8191, 8192, 8999):
        assert np.array_equal(batch[i], opw.inverse(p, poses[i]), equal_nan=True)


def test_wrist_x_in_a1_is_the_wrist_centre_seen_from_axis_1() -> None:
    p = ROBOTS["synthetic b != 0"]
    q = _random_joints(np.random.default_rng(7), 100)
    centre = opw.wrist_centre(p, opw.forward(p, q))
    theta1 = opw.to_model_joints(p, q)[:, 0]
    x = np.cos(theta1) * centre[:, 0] + np.sin(theta1) * centre[:, 1]
    assert np.allclose(opw.wrist_x_in_a1(p, q), x, atol=1e-12)


@pytest.mark.parametrize("name", list(ROBOTS))
def test_agrees_with_rs_opw_kinematics(name: str) -> None:
    """Same 8 branches as rs-opw-kinematics (py-opw-kinematics ``reach``), when installed.

    Its slot is ``4·flip + 2·shoulder + elbow`` with flip taken on the raw theta5.
    """
    popw = pytest.importorskip("py_opw_kinematics")
    transform = pytest.importorskip("scipy.spatial.transform")
    p = ROBOTS[name]
    model = popw.KinematicModel(
        a1=p.a1, a2=p.a2, b=p.b, c1=p.c1, c2=p.c2, c3=p.c3, c4=p.c4,
        offsets=p.offsets, flip_axes=tuple(s < 0 for s in p.signs),
    )  # fmt: skip
    poses = opw.forward(p, _random_joints(np.random.default_rng(8), 2000))
    theirs = popw.Robot(model, degrees=False).reach(transform.RigidTransform.from_matrix(poses))
    flip_col = int(p.signs[4] < 0)
    slots = [
        4 * (w ^ flip_col) + 2 * s + e for s in (0, 1) for e in (0, 1) for w in (0, 1)
    ]  # fmt: skip
    ours = opw.inverse(p, poses)
    other = theirs.joints[:, slots]
    assert np.array_equal(np.isnan(ours), np.isnan(other))
    valid = ~np.isnan(ours)
    # Loose: this pins the branch order and meaning; precision is pinned by the round trips.
    assert np.max(np.abs(wrap_half_open(ours - np.where(valid, other, 0.0))[valid])) < 1e-7


# --------------------------------------------------------------------------------------------
# Turns


def test_turn_variants_kuka() -> None:
    q = np.array([[0.1, 170 * DEG, 0.2, 180 * DEG, 0.3, 100 * DEG], [np.nan] * 6])
    variants = opw.turn_variants(q, KUKA_A, KUKA_B)
    # A2 -190..45° allows turns {0, -1}; A4 ±185° and A6 ±350° allow {0, -1, +1}.
    assert variants.shape == (2, 2 * 3 * 3, 6)
    assert np.isnan(variants[1]).all()
    rows = variants[0][~np.isnan(variants[0]).any(axis=1)]
    # Variant 0 is q itself, which lies outside A2's limits here, so it is NaN.
    assert np.isnan(variants[0, 0]).all()
    got = {tuple(np.round(r / DEG, 6)) for r in rows}
    expected = {
        (0.1 / DEG, -190.0, 0.2 / DEG, a4, 0.3 / DEG, a6)
        for a4 in (180.0, -180.0)
        for a6 in (100.0, -260.0)
    }
    assert got == {tuple(np.round(e, 6)) for e in expected}


def test_turn_variants_are_complete_and_inside() -> None:
    lower = np.array([-180, -90, -180, -400, -125, -400]) * DEG
    upper = np.array([180, 150, 75, 400, 120, 400]) * DEG
    q = np.random.default_rng(9).uniform(-7.0, 7.0, (200, 6))
    variants = opw.turn_variants(q, lower, upper)
    for qi, vi in zip(q, variants, strict=True):
        rows = vi[~np.isnan(vi).any(axis=1)]
        assert np.all((rows >= lower - 1e-9) & (rows <= upper + 1e-9))
        assert np.allclose(wrap_half_open(rows - qi), 0.0, atol=1e-12)
        turns = np.arange(-3, 4) * 2 * math.pi
        per_joint = [
            np.sum((w + turns >= lo - 1e-9) & (w + turns <= hi + 1e-9))
            for w, lo, hi in zip(wrap_half_open(qi), lower, upper, strict=True)
        ]
        assert len(rows) == math.prod(per_joint)
        assert len({tuple(r) for r in rows}) == len(rows)


def test_turn_variant_zero_is_the_wrapped_input() -> None:
    q = np.array([0.1, -0.2, 0.3, 4.0, 0.5, 7.0])
    variants = opw.turn_variants(q, KUKA_A, KUKA_B)
    assert np.allclose(variants[0], wrap_half_open(q))
