"""Robot configurations: the branch flags mean what the OPW branches mean, and the configuration
proof: for every OPW robot of the VENDOR-NOTES table and every vendor encoding (vendor-neutral,
KUKA S/T, ABB confdata, Fanuc CONFIG), the configuration computed from planned joints selects
exactly those joints among all IK solutions and turn variants of their pose."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from olp.ir import Configuration
from olp.kinematics import configuration as cfg
from olp.kinematics import opw
from olp.kinematics.base import FANUC_J2_J3, JointCoupling, turn_variants
from olp.kinematics.models import OPWKinematics
from olp.vendors import abb, fanuc, kuka

DEG = math.pi / 180.0
MM = 1e-3

CONVENTIONS: dict[str, tuple[tuple[float, ...], tuple[int, ...]]] = {
    "K": ((0.0, -90 * DEG, 0.0, 0.0, 0.0, 0.0), (-1, 1, 1, -1, 1, -1)),
    "A": ((0.0, 0.0, -90 * DEG, 0.0, 0.0, 0.0), (1, 1, 1, 1, 1, 1)),
    "F": ((0.0, 0.0, -90 * DEG, 0.0, 0.0, 180 * DEG), (1, 1, -1, -1, -1, -1)),
}

# a1, a2, c1, c2, c3, c4 in mm (b = 0) and convention, from the VENDOR-NOTES OPW table; limits
# in degrees from its joint-range table (siblings share limits; the Fanuc J3 ranges there are
# unsure, so these tests use -70..205°, under 360° wide, in the controller's convention).
KR6 = [(-170, 170), (-190, 45), (-120, 156), (-185, 185), (-120, 120), (-350, 350)]
KR10 = [(-170, 170), (-185, 65), (-137, 163), (-185, 185), (-120, 120), (-350, 350)]
IRB120 = [(-165, 165), (-110, 110), (-110, 70), (-160, 160), (-120, 120), (-400, 400)]
IRB4600 = [(-180, 180), (-90, 150), (-180, 75), (-400, 400), (-125, 120), (-400, 400)]
LR200ID = [(-170, 170), (-100, 145), (-70, 205), (-190, 190), (-125, 125), (-360, 360)]
LR200IC = [(-170, 170), (-60, 140), (-70, 205), (-190, 190), (-120, 120), (-360, 360)]
M20IA = [(-170, 170), (-100, 160), (-70, 205), (-200, 200), (-140, 140), (-270, 270)]
TABLE = {
    "KUKA KR 6 R900 sixx": ((25, -35, 400, 455, 420, 80), "K", KR6),
    "KUKA KR 6 R900-2": ((25, -25, 400, 455, 420, 90), "K", KR6),
    "KUKA KR 10 R1420": ((150, -20, 450, 610, 660, 80), "K", KR10),
    "ABB IRB 120-3/0.6": ((0, -70, 290, 270, 302, 72), "A", IRB120),
    "ABB IRB 4600-40/2.55": ((175, -175, 495, 1095, 1270, 135), "A", IRB4600),
    "Fanuc LR Mate 200iD": ((50, -35, 330, 330, 335, 80), "F", LR200ID),
    "Fanuc LR Mate 200iD/7L": ((50, -35, 330, 440, 420, 80), "F", LR200ID),
    "Fanuc LR Mate 200iC": ((75, -75, 330, 300, 320, 80), "F", LR200IC),
    "Fanuc M-20iA": ((150, -250, 525, 790, 835, 100), "F", M20IA),
}


def _arm(name: str) -> tuple[OPWKinematics, np.ndarray, np.ndarray]:
    """The robot as controller-joint kinematics (Fanuc: J3 from the horizontal) and its limits."""
    (a1, a2, c1, c2, c3, c4), conv, limits = TABLE[name]
    offsets, signs = CONVENTIONS[conv]
    params = opw.OPWParameters(
        a1 * MM, a2 * MM, 0.0, c1 * MM, c2 * MM, c3 * MM, c4 * MM, offsets, signs
    )
    coupling = JointCoupling.from_terms(6, FANUC_J2_J3) if conv == "F" else None
    arm = OPWKinematics(params, coupling) if coupling else OPWKinematics(params)
    lo, hi = np.radians(np.array(limits, dtype=float).T)
    return arm, lo, hi


Encoder = Callable[[object, np.ndarray], Configuration]


def _neutral(arm: object, q: np.ndarray) -> Configuration:
    return cfg.configuration_of(arm, q)  # type: ignore[arg-type]


def _kuka(arm: object, q: np.ndarray) -> Configuration:
    status, turn = kuka.status_turn(arm, q)  # type: ignore[arg-type]
    return kuka.configuration_from_status_turn(int(status), int(turn))


def _abb(arm: object, q: np.ndarray) -> Configuration:
    conf = abb.confdata(arm, q)  # type: ignore[arg-type]
    return abb.configuration_from_confdata(conf)


def _fanuc(arm: object, q: np.ndarray) -> Configuration:
    text = str(fanuc.config_from_joints(arm, q))  # type: ignore[arg-type]
    return fanuc.configuration_from_config(text)  # through the written string and back


VENDOR = {"K": _kuka, "A": _abb, "F": _fanuc}


def _candidates(arm: OPWKinematics, lo: np.ndarray, hi: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """All IK solutions (K, 6) of one tool0 pose inside the limits, turn variants included."""
    sols = arm.inverse(pose[None])[0]
    variants = turn_variants(sols, lo, hi).reshape(-1, 6)
    return variants[np.all(np.isfinite(variants), axis=-1)]


def _off_boundaries(arm: OPWKinematics, q: np.ndarray, margin: float = 1e-6) -> np.ndarray:
    """Rows (K,) of q (K, 6) away from the three branch boundaries (where branches coincide)."""
    return (
        (np.abs(cfg.wrist_x(arm, q)) > margin)
        & (np.abs(cfg.elbow_angle(arm, q)) > margin)
        & (np.abs(q[:, 4]) > margin)
    )


def _prove(name: str, encode: Encoder, samples: int, seed: int) -> np.ndarray:
    """The configuration proof on ``samples`` random joint vectors inside the limits of a table
    robot, and on every other in-limit solution of their poses. Returns the branch counts (8,)
    of the proven solutions."""
    arm, lo, hi = _arm(name)
    return _prove_on(arm, arm, lo, hi, encode, samples, seed)


def _prove_on(
    arm: OPWKinematics,
    model: object,
    lo: np.ndarray,
    hi: np.ndarray,
    encode: Encoder,
    samples: int,
    seed: int,
    uncarried: tuple[int, ...] = (),
) -> np.ndarray:
    """The proof itself. ``model`` is what the encoder and ``satisfies`` get (kinematics or a
    robot). ``uncarried``: joints whose turns the encoding does not carry; other solutions
    that differ from the planned one only by whole turns of those joints may pass too (the
    documented ambiguity), anything else may not."""
    rng = np.random.default_rng(seed)
    counts = np.zeros(8, dtype=int)
    for q in rng.uniform(lo, hi, (samples, 6)):
        candidates = _candidates(arm, lo, hi, arm.forward(q))
        # The planned joints themselves are among the candidates (IK round trip).
        assert np.min(np.max(np.abs(candidates - q), axis=-1)) < 1e-9
        for index in np.flatnonzero(_off_boundaries(arm, candidates)):
            planned = candidates[index]
            mask = cfg.satisfies(encode(model, planned), candidates, model)  # type: ignore[arg-type]
            assert mask[index], (np.degrees(planned), "does not satisfy its own configuration")
            others = candidates[mask & (np.arange(len(candidates)) != index)]
            turns = (others - planned) / (2 * math.pi)
            whole = np.allclose(turns, np.round(turns), atol=1e-9)
            only_uncarried = not np.any(np.delete(np.round(turns), uncarried, axis=-1))
            assert len(others) == 0 or (whole and only_uncarried), (
                np.degrees(planned),
                np.degrees(others),
            )
            flags = cfg.branch_flags(arm, planned)
            counts[4 * int(flags.back) + 2 * int(flags.down) + int(flags.flip)] += 1
    return counts


@pytest.mark.parametrize("name", list(TABLE))
def test_configuration_proof_vendor_encoding(name: str) -> None:
    """KUKA robots with S/T, ABB robots with confdata, Fanuc robots with CONFIG (as a string)."""
    counts = _prove(name, VENDOR[TABLE[name][1]], samples=150, seed=11)
    assert np.all(counts > 0), f"branches not exercised: {counts}"


@pytest.mark.parametrize("name", list(TABLE))
def test_configuration_proof_neutral(name: str) -> None:
    """The vendor-neutral configuration (flags + each joint's turn window) selects the same."""
    counts = _prove(name, _neutral, samples=60, seed=12)
    assert np.all(counts > 0), f"branches not exercised: {counts}"


@pytest.mark.parametrize("name", ["ABB IRB 4600-40/2.55", "Fanuc M-20iA"])
def test_abb_and_fanuc_encodings_work_on_any_opw_robot(name: str) -> None:
    """confdata and CONFIG are geometric: they also pin solutions on another brand's arm."""
    _prove(name, _fanuc if name.startswith("ABB") else _abb, samples=40, seed=13)


@pytest.mark.parametrize(
    ("name", "encode", "degrees"),
    [
        ("ABB IRB 4600-40/2.55", _abb, [90, 30, -20, -180, 45, 270]),
        ("ABB IRB 4600-40/2.55", _abb, [-180, 30, -20, 180, -45, -90]),
        ("ABB IRB 4600-40/2.55", _abb, [180, 30, -20, 0, 45, 360]),
        ("Fanuc M-20iA", _fanuc, [0, 20, -10, 180, -45, -180]),
        ("Fanuc M-20iA", _fanuc, [0, 20, -10, -180, -45, 180]),
        ("KUKA KR 6 R900 sixx", _kuka, [0, -90, 90, 180, 45, 0]),
        ("KUKA KR 6 R900 sixx", _kuka, [0, -90, 90, -180, 45, -180]),
    ],
)
def test_configuration_proof_on_vendor_boundaries(
    name: str, encode: Encoder, degrees: list[float]
) -> None:
    """Joints exactly on a quadrant or turn boundary, where both 2 pi variants (e.g. 180° and
    -180°) are inside the limits: the vendor rule puts the boundary on one side, and the
    configuration still selects exactly the planned joints although IK returns them only to
    ~1e-15 rad, on either side of the boundary."""
    arm, lo, hi = _arm(name)
    planned = np.radians(degrees)
    candidates = _candidates(arm, lo, hi, arm.forward(planned))
    mask = cfg.satisfies(encode(arm, planned), candidates, arm)
    assert mask.sum() == 1
    assert np.max(np.abs(candidates[mask][0] - planned)) < 1e-9


LIBRARY_ENCODERS = {"kuka": _kuka, "abb": _abb, "fanuc": _fanuc}
UNCARRIED = {"kuka": (), "abb": (1, 2, 4), "fanuc": (1, 2, 4)}
"""Joints whose turns each encoding leaves open: confdata and CONFIG carry turns only for axes
1, 4 and 6; KUKA's T carries a sign for every axis."""


def _library() -> list[str]:
    from olp.station.loader import load_library_robot, robot_library

    return [n for n in robot_library() if load_library_robot(n).vendor in LIBRARY_ENCODERS]


@pytest.mark.parametrize("name", _library())
def test_configuration_proof_bundled_robots(name: str) -> None:
    """Every bundled OPW robot with its own limits, encoded as its post writes it (the robot
    placed as in a station). KUKA and ABB: exactly one solution. Fanuc: the bundled J3 ranges
    are wider than 360° (the J2/J3 interaction limit is not modelled), so CONFIG, which has no
    J3 turn number, also admits the planned joints with J3 ± 360° where that is inside the
    limits; that is the only other solution it may admit (see ``test_fanuc_j3_turn_ambiguity``).
    """
    from olp.station.loader import load_library_robot

    entry = load_library_robot(name)
    robot = entry.place()
    arm = robot.kinematics
    assert isinstance(arm, OPWKinematics)
    lo, hi = entry.limits.lower, entry.limits.upper
    if entry.vendor == "kuka":  # the premise under which T tells turns apart
        assert np.all((lo > -2 * math.pi) & (hi < 2 * math.pi))
    encode = LIBRARY_ENCODERS[entry.vendor]
    counts = _prove_on(arm, robot, lo, hi, encode, 80, 21, UNCARRIED[entry.vendor])
    assert np.all(counts > 0), f"branches not exercised: {counts}"


def test_fanuc_j3_turn_ambiguity() -> None:
    """The documented limit of Fanuc CONFIG: with a J3 range over 360° (bundled LR Mate 200iC:
    -142..230°), J3 = -141.4° and 218.6° give the same pose and the same CONFIG. ``satisfies``
    keeps both; the caller breaks the tie (resolve: the one nearest the previous joints)."""
    arm, _, _ = _arm("Fanuc LR Mate 200iC")
    lo = np.radians([-170.0, -60, -142, -190, -120, -360])
    hi = np.radians([170.0, 140, 230, 190, 120, 360])
    planned = np.radians([66.7, -1.5, -141.4, -0.1, 48.4, 46.1])
    candidates = _candidates(arm, lo, hi, arm.forward(planned))
    mask = cfg.satisfies(_fanuc(arm, planned), candidates, arm)
    chosen = candidates[mask]
    assert len(chosen) == 2
    assert np.allclose(np.sort(np.degrees(chosen[:, 2])), [-141.4, 218.6], atol=1e-7)
    assert np.allclose(chosen[:, [0, 1, 3, 4, 5]], planned[[0, 1, 3, 4, 5]], atol=1e-9)


# --------------------------------------------------------------------------------------------
# The flags mean what the OPW branches mean


@pytest.mark.parametrize("name", list(TABLE))
def test_flags_of_ik_rows_are_the_row_branches(name: str) -> None:
    """Row i of the IK is branch BRANCHES[i] by construction; the flags read from the joints
    must say the same (away from the boundaries where two rows coincide)."""
    arm, lo, hi = _arm(name)
    q = np.random.default_rng(5).uniform(lo, hi, (400, 6))
    sols = arm.inverse(arm.forward(q))
    for index, branch in enumerate(opw.BRANCHES):
        rows = sols[:, index]
        rows = rows[np.all(np.isfinite(rows), axis=-1)]
        rows = rows[_off_boundaries(arm, rows)]
        flags = cfg.branch_flags(arm, rows)
        assert np.all(flags.back == (branch.shoulder == "back"))
        assert np.all(flags.down == (branch.elbow == "down"))
        assert np.all(flags.flip == (branch.wrist == "flip"))


@pytest.mark.parametrize("name", ["KUKA KR 10 R1420", "ABB IRB 4600-40/2.55", "Fanuc M-20iA"])
def test_flags_from_explicit_geometry(name: str) -> None:
    """Shoulder and elbow flags against the arm drawn point by point: the wrist centre (from FK)
    relative to axis 1, and relative to the line through axes 2 and 3."""
    arm, lo, hi = _arm(name)
    p = arm.params
    q = np.random.default_rng(6).uniform(lo, hi, (300, 6))
    theta = opw.to_model_joints(p, arm.chain_joints(q))
    pose = arm.forward(q)
    centre = pose[:, :3, 3] - p.c4 * pose[:, :3, 2]
    c1, s1 = np.cos(theta[:, 0]), np.sin(theta[:, 0])
    forward = np.stack([c1, s1, np.zeros_like(c1)], axis=-1)  # x of the frame turning with A1
    assert np.array_equal(cfg.branch_flags(arm, q).back, np.sum(centre * forward, -1) < 0)
    t2 = theta[:, 1]
    # Axis 3 (the elbow) and the lower arm's +x direction, Rz(t1) · Ry(t2) · e_x.
    elbow = np.stack([c1 * p.a1, s1 * p.a1, np.full_like(c1, p.c1)], axis=-1) + p.c2 * np.stack(
        [c1 * np.sin(t2), s1 * np.sin(t2), np.cos(t2)], axis=-1
    )
    normal = np.stack([c1 * np.cos(t2), s1 * np.cos(t2), -np.sin(t2)], axis=-1)
    behind = np.sum((centre - elbow) * normal, axis=-1) < 0
    assert np.array_equal(cfg.branch_flags(arm, q).down, behind)


def test_fanuc_flags_use_controller_j3() -> None:
    """J3 from the horizontal: the same arm shape with J2 changed and J3 kept (controller
    numbers) is a different forearm angle; the flags follow the coupled (model) J3."""
    arm, _, _ = _arm("Fanuc LR Mate 200iD")
    bare = arm.params
    q = np.radians([10.0, 40.0, -70.0, 20.0, -30.0, 0.0])
    # Controller J3 -70° with J2 40°: model J3 -30°, forearm tilted above horizontal.
    model_q = q.copy()
    model_q[2] += q[1]
    assert cfg.elbow_angle(arm, q) == pytest.approx(cfg.elbow_angle(bare, model_q), abs=1e-15)
    assert cfg.elbow_angle(arm, q) != pytest.approx(cfg.elbow_angle(bare, q), abs=1e-3)


# --------------------------------------------------------------------------------------------
# satisfies and configuration_of


def test_satisfies_none_fields_ask_nothing_and_nan_rows_fail() -> None:
    arm, lo, hi = _arm("KUKA KR 6 R900 sixx")
    q = np.random.default_rng(7).uniform(lo, hi, (50, 6))
    q[3] = np.nan
    mask = cfg.satisfies(Configuration(), q, arm)
    assert mask.shape == (50,)
    assert mask.sum() == 49 and not mask[3]


def test_satisfies_tolerance_at_a_boundary() -> None:
    """A candidate 1e-12 rad on the wrong side of a range end (IK rounding) still passes; one
    1e-6 rad beyond does not."""
    arm, _, _ = _arm("ABB IRB 120-3/0.6")
    request = Configuration(joint_ranges=((0.0, math.pi / 2),) + (None,) * 5)
    q = np.zeros((3, 6))
    q[:, 0] = [-1e-12, math.pi / 2 + 1e-12, -1e-6]
    assert cfg.satisfies(request, q, arm).tolist() == [True, True, False]


def test_satisfies_infinite_half_lines() -> None:
    arm, _, _ = _arm("KUKA KR 6 R900 sixx")
    request = Configuration(joint_ranges=((-math.inf, 0.0),) * 6)
    q = np.array([[-1.0] * 6, [-1.0] * 5 + [1.0]])
    assert cfg.satisfies(request, q, arm).tolist() == [True, False]


def test_configuration_of_pins_each_turn() -> None:
    arm, _, _ = _arm("KUKA KR 6 R900 sixx")
    q = np.radians([10.0, -100.0, 100.0, 170.0, 30.0, -300.0])
    config = cfg.configuration_of(arm, q)
    variants = q + np.array([[0.0] * 5 + [2 * math.pi], [0.0] * 6, [0, 0, 0, -2 * math.pi, 0, 0]])
    assert cfg.satisfies(config, variants, arm).tolist() == [False, True, False]
    assert cfg.configuration_of(arm, q, turns=False).joint_ranges is None


def test_configuration_of_accepts_robot_kinematics_and_parameters() -> None:
    arm, _, _ = _arm("KUKA KR 6 R900 sixx")

    class Robot:  # the one attribute the functions read from a station robot
        kinematics = arm

    q = np.radians([0.0, -90.0, 90.0, 0.0, 45.0, 0.0])
    expected = Configuration("front", "up", "noflip", None)
    for model in (arm, arm.params, Robot()):
        assert cfg.configuration_of(model, q, turns=False) == expected


def test_non_opw_arms_are_refused() -> None:
    with pytest.raises(TypeError, match="OPW"):
        cfg.branch_flags(object(), np.zeros(6))  # type: ignore[arg-type]


def test_configuration_of_checks_its_input() -> None:
    arm, _, _ = _arm("KUKA KR 6 R900 sixx")
    with pytest.raises(ValueError):
        cfg.configuration_of(arm, np.zeros(5))


def test_snap() -> None:
    q = np.array([math.pi / 2 - 1e-13, math.pi / 2 - 1e-9, -math.pi / 2 + 1e-14, 0.3])
    assert cfg.snap(q, math.pi / 2).tolist() == [math.pi / 2, q[1], -math.pi / 2, 0.3]
