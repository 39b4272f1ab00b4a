"""Resolve: each failure constructed on purpose, asserted by kind and source line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from olp import ir
from olp.geometry import transl
from olp.passes.resolve import resolve
from olp.station.loader import load_station
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def station() -> Station:
    return load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def _span(line: int) -> ir.SourceSpan:
    return ir.SourceSpan("t.src", line, 1)


def _ptp(deg: list[float], line: int = 1) -> ir.JointMove:
    return ir.JointMove(target=ir.JointTarget(joints=np.radians(deg)), span=_span(line))


def _lin_to_joints(station: Station, deg: list[float], line: int) -> ir.LinearMove:
    """A LIN to the Cartesian pose (flange, world frame) that the joints ``deg`` reach."""
    pose = station.robot.flange_poses(np.radians(deg))
    return ir.LinearMove(target=ir.CartesianTarget(pose=pose), span=_span(line))


def _run(station: Station, *instructions: ir.Instruction) -> list[tuple[str, int]]:
    compiled = resolve(ir.Program(name="t", instructions=instructions), station)
    return [(d.kind, d.span.line) for d in compiled.diagnostics if d.span is not None]


HOME = [0, -90, 90, 0, 0, 0]


def test_feasible_lin_ends_on_the_target_in_the_start_branch(station: Station) -> None:
    start = [10, -80, 95, 20, 30, 40]
    end = [25, -70, 100, 15, 35, 30]
    compiled = resolve(
        ir.Program(name="t", instructions=[_ptp(start), _lin_to_joints(station, end, 2)]), station
    )
    assert compiled.ok
    final = compiled.steps[1].joints
    assert final is not None and np.allclose(final, np.radians(end), atol=1e-9)


def test_unreachable_target(station: Station) -> None:
    far = ir.LinearMove(target=ir.CartesianTarget(pose=transl(3.0, 0, 0.5)), span=_span(7))
    assert _run(station, _ptp(HOME), far) == [("unreachable", 7)]


def test_joint_target_outside_limits(station: Station) -> None:
    assert _run(station, _ptp([0, -90, 90, 0, 0, 0]), _ptp([175, -90, 90, 0, 0, 0], 3)) == [
        ("joint_limit", 3)
    ]


def test_ptp_to_cartesian_target_reachable_only_outside_limits(station: Station) -> None:
    # A1 = 180° puts the arm behind the robot; A1 is limited to ±170° and every other branch
    # that reaches the same pose needs A1 = 0 with the wrist overhead: check the report kind.
    pose = station.robot.flange_poses(np.radians([180, -90, 90, 0, 45, 0]))
    move = ir.JointMove(target=ir.CartesianTarget(pose=pose), span=_span(4))
    found = _run(station, _ptp(HOME), move)
    assert found in ([], [("joint_limit", 4)])
    if found:
        compiled = resolve(ir.Program(name="t", instructions=[_ptp(HOME), move]), station)
        assert "axis 1" in compiled.diagnostics[0].message


def test_lin_through_a_wrist_singularity(station: Station) -> None:
    # Same arm pose, wrist from A5 = +10° to A5 = -10°: the TCP line crosses A5 = 0 where A4/A6
    # would have to turn 180° in an instant.
    start = [0, -80, 100, 30, 10, 0]
    end = [0, -80, 100, 30, -10, 0]
    found = _run(station, _ptp(start), _lin_to_joints(station, end, 5))
    assert found == [("singularity", 5)]


def test_one_failure_does_not_cascade(station: Station) -> None:
    far = ir.LinearMove(target=ir.CartesianTarget(pose=transl(3.0, 0, 0.5)), span=_span(2))
    fine = _lin_to_joints(station, [5, -85, 95, 0, 20, 0], 3)
    assert _run(station, _ptp([0, -90, 90, 0, 30, 0]), far, fine) == [("unreachable", 2)]


def test_lin_starting_at_the_home_wrist_singularity_is_reported(station: Station) -> None:
    """KUKA HOME has A5 = 0: a LIN from there starts in a wrist singularity."""
    found = _run(station, _ptp(HOME), _lin_to_joints(station, [5, -85, 95, 0, 20, 0], 3))
    assert found == [("singularity", 3)]


def test_unknown_tool_reference(station: Station) -> None:
    move = ir.JointMove(
        target=ir.JointTarget(joints=np.radians(HOME)),
        tool=ir.Tool(name="TOOL_DATA[9]", number=9),
        span=_span(6),
    )
    assert _run(station, move) == [("unknown_tool", 6)]


def test_station_tool_by_number(station: Station) -> None:
    move = ir.JointMove(
        target=ir.JointTarget(joints=np.radians(HOME)),
        tool=ir.Tool(name="TOOL_DATA[1]", number=1),
        span=_span(6),
    )
    compiled = resolve(ir.Program(name="t", instructions=[move]), station)
    assert compiled.ok and compiled.steps[0].tool is station.tools["spindle"]


def _helix(station: Station, count: int, z_drop: float = 0.0) -> list[ir.Instruction]:
    tool, frame = station.tools["spindle"], station.frames["table"]
    t = np.linspace(0, 1, count)
    xyz = np.column_stack(
        [0.1 + 0.15 * np.cos(6 * np.pi * t), 0.15 + 0.15 * np.sin(6 * np.pi * t), 0.02 + z_drop * t]
    )
    down = np.diag([-1.0, 1.0, -1.0])
    poses = np.repeat(np.eye(4)[None], count, axis=0)
    poses[:, :3, :3], poses[:, :3, 3] = down, xyz
    first = ir.JointMove(target=ir.CartesianTarget(pose=poses[0]), tool=tool, frame=frame)
    return [first] + [
        ir.LinearMove(target=ir.CartesianTarget(pose=p), tool=tool, frame=frame, span=_span(i + 2))
        for i, p in enumerate(poses[1:])
    ]


def _per_move(monkeypatch: pytest.MonkeyPatch, program: ir.Program, station: Station) -> object:
    import olp.passes.resolve as module

    monkeypatch.setattr(module, "_linear_run", lambda *_: None)
    return resolve(program, station)


def test_batched_linear_runs_equal_the_per_move_path(
    station: Station, monkeypatch: pytest.MonkeyPatch
) -> None:
    program = ir.Program(name="helix", instructions=_helix(station, 400))
    batched = resolve(program, station)
    single = _per_move(monkeypatch, program, station)
    assert batched.ok and single.ok  # type: ignore[attr-defined]
    for a, b in zip(batched.steps, single.steps, strict=True):  # type: ignore[attr-defined]
        assert a.index == b.index and a.joints is not None and b.joints is not None
        assert np.allclose(a.joints, b.joints, atol=1e-12)
        assert a.path is not None and b.path is not None and a.path.shape == b.path.shape


def test_batched_run_reports_a_failure_midway_like_the_per_move_path(
    station: Station, monkeypatch: pytest.MonkeyPatch
) -> None:
    moves = _helix(station, 60)
    far = ir.LinearMove(
        target=ir.CartesianTarget(pose=transl(3.0, 0, 0.5)),
        tool=station.tools["spindle"],
        frame=station.frames["table"],
        span=_span(999),
    )
    program = ir.Program(name="gap", instructions=[*moves[:30], far, *moves[30:]])
    batched = resolve(program, station)
    single = _per_move(monkeypatch, program, station)
    assert [(d.kind, d.index) for d in batched.diagnostics] == [("unreachable", 30)]
    assert [(d.kind, d.index, d.message) for d in batched.diagnostics] == [
        (d.kind, d.index, d.message)
        for d in single.diagnostics  # type: ignore[attr-defined]
    ]
    resolved = [s.joints for s in batched.steps if s.joints is not None]
    assert len(resolved) == len(program.instructions) - 1


def test_fallback_turns_an_impossible_lin_into_a_joint_move(station: Station) -> None:
    from olp.passes.resolve import ResolveOptions

    start = [0, -80, 100, 30, 10, 0]
    lin = _lin_to_joints(station, [0, -80, 100, 30, -10, 0], 5)  # crosses A5 = 0
    program = ir.Program(name="t", instructions=[_ptp(start), lin])
    plain = resolve(program, station)
    assert [d.kind for d in plain.diagnostics] == ["singularity"]
    compiled = resolve(program, station, ResolveOptions(fallback_joint=True))
    assert compiled.ok
    step = compiled.steps[1]
    assert isinstance(step.instruction, ir.JointMove) and step.instruction.span.line == 5
    assert [(d.severity, d.kind) for d in compiled.diagnostics] == [("warning", "fallback_joint")]
    assert step.joints is not None
    reached = station.robot.flange_poses(step.joints)
    assert np.allclose(reached, lin.target.pose, atol=1e-9)  # type: ignore[union-attr]


def test_fallback_does_not_hide_an_unreachable_target(station: Station) -> None:
    from olp.passes.resolve import ResolveOptions

    far = ir.LinearMove(target=ir.CartesianTarget(pose=transl(3.0, 0, 0.5)), span=_span(2))
    program = ir.Program(name="t", instructions=[_ptp([0, -90, 90, 0, 30, 0]), far])
    compiled = resolve(program, station, ResolveOptions(fallback_joint=True))
    assert [(d.severity, d.kind) for d in compiled.diagnostics] == [("error", "unreachable")]


def test_skip_unreachable_drops_the_target_with_a_warning(station: Station) -> None:
    from olp.passes.resolve import ResolveOptions

    far = ir.LinearMove(target=ir.CartesianTarget(pose=transl(3.0, 0, 0.5)), span=_span(2))
    fine = _lin_to_joints(station, [5, -85, 95, 0, 20, 0], 3)
    program = ir.Program(name="t", instructions=[_ptp([0, -90, 90, 0, 30, 0]), far, fine])
    compiled = resolve(program, station, ResolveOptions(skip_unreachable=True))
    assert compiled.ok
    assert [(d.severity, d.kind, d.index) for d in compiled.diagnostics] == [
        ("warning", "unreachable", 1)
    ]
    assert compiled.steps[1].skipped and compiled.steps[1].joints is None
    assert compiled.steps[2].joints is not None


def test_speed_warning_names_the_axis_that_cannot_keep_up(station: Station) -> None:
    import dataclasses

    from olp.station.model import JointLimits

    robot = station.robot
    slow_limits = JointLimits(
        lower=robot.limits.lower,
        upper=robot.limits.upper,
        velocity=robot.limits.velocity / 100,
        acceleration=robot.limits.acceleration,
        jerk=robot.limits.jerk,
    )
    slow = dataclasses.replace(station, robot=dataclasses.replace(robot, limits=slow_limits))
    moves = _helix(station, 40)
    fast = [dataclasses.replace(m, speed=ir.Speed(linear=1.0)) for m in moves]
    program = ir.Program(name="fast", instructions=fast)
    assert not [d for d in resolve(program, station).diagnostics if d.kind == "speed_limited"]
    found = [d for d in resolve(program, slow).diagnostics if d.kind == "speed_limited"]
    assert len(found) == 1  # consecutive moves are reported together
    assert found[0].severity == "warning" and "moves 1-39" in found[0].message
    assert "the TCP will be slower" in found[0].message


def _config_of(station: Station, deg: list[float]) -> ir.Configuration:
    from olp.kinematics.configuration import configuration_of

    return configuration_of(station.robot, np.radians(deg))


def test_ptp_takes_the_solution_its_configuration_asks_for(station: Station) -> None:
    from olp.passes.resolve import _candidates

    robot = station.robot
    near = np.radians([0, -90, 90, 0, 30, 0])
    pose = robot.flange_poses(np.radians([20, -100, 110, 30, 40, 10]))
    candidates = _candidates(robot, pose)
    nearest = candidates[np.argmin(np.sum((candidates - near) ** 2, axis=-1))]
    # another in-limits solution in a different branch than the nearest one
    other = next(c for c in candidates if robot.branch_of(c) != robot.branch_of(nearest))
    plain = ir.JointMove(target=ir.CartesianTarget(pose=pose), span=_span(2))
    asked = ir.JointMove(
        target=ir.CartesianTarget(pose=pose, config=_config_of(station, list(np.degrees(other)))),
        span=_span(2),
    )
    start = ir.JointMove(target=ir.JointTarget(joints=near))
    got_plain = resolve(ir.Program(name="t", instructions=[start, plain]), station).steps[1]
    got_asked = resolve(ir.Program(name="t", instructions=[start, asked]), station).steps[1]
    assert got_plain.joints is not None and np.allclose(got_plain.joints, nearest, atol=1e-9)
    assert got_asked.joints is not None and np.allclose(got_asked.joints, other, atol=1e-9)


def test_configuration_outside_the_limits_is_an_error_on_its_line(station: Station) -> None:
    wanted = [20, -100, 110, 30, 40, 10]
    pose = station.robot.flange_poses(np.radians(wanted))
    impossible = ir.Configuration(
        shoulder="front", elbow="up", wrist="noflip",
        joint_ranges=(None, None, None, None, None, (np.radians(400), np.radians(500))),
    )  # fmt: skip
    move = ir.JointMove(target=ir.CartesianTarget(pose=pose, config=impossible), span=_span(9))
    found = _run(station, _ptp([0, -90, 90, 0, 30, 0]), move)
    assert found == [("configuration", 9)]


class _CountingTuple(tuple):  # type: ignore[type-arg]
    """A tuple that counts the items read from it (a slice reads all of its items)."""

    reads = 0

    def __getitem__(self, key):  # type: ignore[no-untyped-def]
        item = super().__getitem__(key)
        type(self).reads += len(item) if isinstance(key, slice) else 1
        return item


def test_resolve_reads_each_instruction_a_bounded_number_of_times(station: Station) -> None:
    """Resolve is linear in non-motion instructions: it reads each a few times (before, each
    comment copied the rest of the program, 200,000 comments took 70 s)."""
    count = 2000
    comments = [ir.Comment(text=f"c{i}") for i in range(count)]
    instructions = _CountingTuple([_ptp(HOME), *comments, _ptp([10, -90, 90, 0, 0, 0], 2)])
    _CountingTuple.reads = 0
    compiled = resolve(ir.Program(name="t", instructions=instructions), station)
    assert compiled.ok and len(compiled.steps) == count + 2
    assert _CountingTuple.reads <= 4 * len(instructions)


# --------------------------------------------------------------------------------------------
# Absurd but parseable values: diagnostics, never exceptions or unbounded memory (issue 10)


def _counted_sampling(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Record the segments and samples of every ``sample_segments`` call resolve makes, and
    fail (before anything is allocated) a call that would make over a million samples."""
    import olp.passes.resolve as module
    from olp.geometry import pose_distance

    original = module.sample_segments
    calls: list[int] = []

    def counted(start, targets, step_m, step_rad):  # type: ignore[no-untyped-def]
        previous = np.concatenate([start[None], targets[:-1]])
        lengths, angles = pose_distance(previous, targets)
        with np.errstate(over="ignore", invalid="ignore"):
            wanted = np.sum(np.maximum(np.ceil(lengths / step_m), np.ceil(angles / step_rad)))
        assert wanted <= 1e6, f"resolve asked for {wanted:.3g} samples"
        calls.append(len(targets))
        return original(start, targets, step_m, step_rad)

    monkeypatch.setattr(module, "sample_segments", counted)
    return calls


@pytest.mark.parametrize("metres", [1e5, 1e40, 1e300])
def test_a_far_target_in_a_run_of_lins_is_unreachable(
    station: Station, monkeypatch: pytest.MonkeyPatch, metres: float
) -> None:
    """A CSV's ``400,0,1e40`` row gave ``ValueError: negative dimensions``, a 100 km LIN 7 GB of
    samples: the batch now counts samples before it makes them."""
    _counted_sampling(monkeypatch)
    near = _lin_to_joints(station, [5, -85, 95, 0, 20, 0], 2)
    far = ir.LinearMove(target=ir.CartesianTarget(pose=transl(metres, 0, 0.5)), span=_span(3))
    back = _lin_to_joints(station, [5, -80, 95, 0, 20, 0], 4)
    start = _ptp([0, -90, 90, 0, 30, 0])
    compiled = resolve(ir.Program(name="t", instructions=[start, near, far, back]), station)
    assert [(d.severity, d.kind, d.span.line) for d in compiled.diagnostics] == [
        ("error", "unreachable", 3)
    ]
    message = compiled.diagnostics[0].message
    assert len(message) < 150  # the distance in short form (1e+43 mm), not 40 digits
    assert compiled.steps[3].joints is not None  # the move after it is still resolved


def _long_tool(metres: float) -> ir.Tool:
    return ir.Tool(name="long", pose=transl(metres, 0, 0))


def test_a_lin_too_long_to_sample_is_an_error_in_a_batch_and_alone(
    station: Station, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A 1 km tool turned by 30° moves its TCP ~500 m: 100,000 samples at 5 mm, over the cap
    of one move. Both the batched (Cartesian target) and the per-move path (joint target)
    report it on the move's line instead of sampling it."""
    from olp.passes.sampling import MAX_SAMPLES

    calls = _counted_sampling(monkeypatch)
    tool = _long_tool(1000.0)
    start = [0, -90, 90, 0, 30, 0]
    end = [30, -90, 90, 0, 30, 0]
    pose = station.robot.flange_poses(np.radians(end)) @ tool.pose
    cartesian = ir.LinearMove(target=ir.CartesianTarget(pose=pose), tool=tool, span=_span(2))
    joints = ir.LinearMove(target=ir.JointTarget(joints=np.radians(end)), tool=tool, span=_span(3))
    for move in (cartesian, joints):
        first = ir.JointMove(target=ir.JointTarget(joints=np.radians(start)), tool=tool)
        compiled = resolve(ir.Program(name="t", instructions=[first, move]), station)
        assert [(d.kind, d.span.line) for d in compiled.diagnostics] == [
            ("too_long", move.span.line)
        ]
        assert f"more than the {MAX_SAMPLES}" in compiled.diagnostics[0].message
    assert sum(calls) == 0  # nothing was sampled


def test_a_lin_to_an_absurd_joint_target_is_a_limit_error(station: Station) -> None:
    """A LIN to joints of 1e308 rad crashed (NaN sample count); a wrong number of joints too."""
    huge = ir.LinearMove(target=ir.JointTarget(joints=np.full(6, 1e308)), span=_span(2))
    short = ir.LinearMove(target=ir.JointTarget(joints=np.zeros(5)), span=_span(3))
    found = _run(station, _ptp(HOME), huge, short)
    assert found == [("joint_limit", 2), ("bad_target", 3)]
    compiled = resolve(ir.Program(name="t", instructions=[_ptp(HOME), huge]), station)
    assert "1e+308 rad" in compiled.diagnostics[0].message


def test_many_failing_lins_are_not_resampled_quadratically(
    station: Station, monkeypatch: pytest.MonkeyPatch
) -> None:
    """After a failure the batch restarts small: each failing move re-sampled the rest of its
    batch of 4,096 moves before (2,000 unreachable targets: 28 s)."""
    calls = _counted_sampling(monkeypatch)
    count = 100
    far = [
        ir.LinearMove(target=ir.CartesianTarget(pose=transl(1.5, 0.001 * i, 0.5)), span=_span(i))
        for i in range(count)
    ]
    start = _ptp([0, -90, 90, 0, 30, 0])
    compiled = resolve(ir.Program(name="t", instructions=[start, *far]), station)
    assert [d.kind for d in compiled.diagnostics] == ["unreachable"] * count
    assert sum(calls) <= 20 * count  # segments sampled: ~17 per failure, not ~count / 2


def test_a_limit_message_shows_the_digits_that_make_the_value_outside(station: Station) -> None:
    """``A1 170.00001`` was reported as "170.00° outside -170..170"."""
    move = _ptp([170.00001, -90, 90, 0, 0, 0], 2)
    compiled = resolve(ir.Program(name="t", instructions=[move]), station)
    (found,) = compiled.diagnostics
    assert found.kind == "joint_limit"
    assert "axis 1 at 170.00001° is outside its limits -170° .. 170°" in found.message


# --------------------------------------------------------------------------------------------
# Singular poses on a linear path (issue 10, item 13)


def _warnings(station: Station, *instructions: ir.Instruction) -> list[tuple[str, int, str]]:
    compiled = resolve(ir.Program(name="t", instructions=instructions), station)
    assert compiled.ok, [d.message for d in compiled.diagnostics]
    return [(d.kind, d.span.line, d.message) for d in compiled.diagnostics if d.span is not None]


def _down(station: Station, deg: list[float], metres: float, line: int) -> ir.LinearMove:
    """A LIN moving the flange straight down by ``metres`` from the pose of joints ``deg``."""
    pose = transl(0, 0, -metres) @ station.robot.flange_poses(np.radians(deg))
    return ir.LinearMove(target=ir.CartesianTarget(pose=pose), span=_span(line))


def _overhead(station: Station) -> list[float]:
    """Joints (deg) with the wrist centre exactly on axis 1: A2 solved for A3 = 60°."""
    from scipy.optimize import brentq

    from olp.kinematics.configuration import wrist_x

    def x(a2: float) -> float:
        return float(wrist_x(station.robot, np.radians([30, a2, 60, 0, 40, 0])))

    return [30, brentq(x, -130, -100, xtol=1e-14), 60, 0, 40, 0]


def test_a_lin_starting_at_the_home_wrist_singularity_warns(station: Station) -> None:
    """KUKA HOME has A5 = 0: straight down from there stays in one branch without a jump (so
    no error), but the pose does not fix A4 and A6."""
    (found,) = _warnings(station, _ptp(HOME), _down(station, HOME, 0.05, 3))
    assert found[:2] == ("singularity", 3)
    assert "linear move 1 starts in the wrist singularity" in found[2]


def test_a_lin_ending_with_the_wrist_centre_on_axis_1_warns(station: Station) -> None:
    overhead = _overhead(station)
    above = [overhead[0], overhead[1] + 3, *overhead[2:]]
    (found,) = _warnings(station, _ptp(above), _lin_to_joints(station, overhead, 4))
    assert found[:2] == ("singularity", 4)
    assert "ends in the shoulder singularity (wrist centre to axis 1: " in found[2]
    (start,) = _warnings(station, _ptp(overhead), _down(station, overhead, 0.05, 5))
    assert start[:2] == ("singularity", 5) and "starts in the shoulder singularity" in start[2]


def test_a_lin_ending_with_the_arm_stretched_warns(station: Station) -> None:
    """The KR 6's arm is straight at A3 = atan(35 / 420) (a2 = -35 mm, c3 = 420 mm)."""
    straight = [0, -60, float(np.degrees(np.arctan2(0.035, 0.420))), 0, 40, 0]
    bent = [0, -60, straight[2] + 10, 0, 40, 0]
    target = ir.LinearMove(target=ir.JointTarget(joints=np.radians(straight)), span=_span(6))
    (found,) = _warnings(station, _ptp(bent), target)
    assert found[:2] == ("singularity", 6) and "ends in the elbow singularity" in found[2]


def test_lins_away_from_singular_poses_do_not_warn(station: Station) -> None:
    start = [10, -80, 95, 20, 30, 40]
    assert _warnings(station, _ptp(start), _down(station, start, 0.05, 2)) == []


def test_batched_and_per_move_paths_warn_alike(
    station: Station, monkeypatch: pytest.MonkeyPatch
) -> None:
    moves = [_down(station, HOME, 0.002 * (k + 1), k + 2) for k in range(5)]
    program = ir.Program(name="t", instructions=[_ptp(HOME), *moves])
    batched = resolve(program, station)
    single = _per_move(monkeypatch, program, station)
    found = [(d.kind, d.index, d.message) for d in batched.diagnostics]
    assert found == [(d.kind, d.index, d.message) for d in single.diagnostics]  # type: ignore[attr-defined]
    assert [(kind, index) for kind, index, _ in found] == [("singularity", 1)]


def test_a_ur_lin_starting_with_wrist_2_at_zero_warns() -> None:
    ur = load_station(REPO / "stations" / "ur5e_screw_cell.yaml")
    start = [0, -90, 90, -90, 0, 0]
    (found,) = _warnings(ur, _ptp(start), _down(ur, start, 0.05, 2))
    assert found[:2] == ("singularity", 2) and "starts in the wrist singularity" in found[2]


def test_a_touch_between_two_samples_counts() -> None:
    """A distance that dips to zero between samples (a parabola through 0 at 2.5)."""
    from olp.passes.resolve import _closest

    values = (np.arange(6.0) - 2.5) ** 2 / 10 + 0.0
    assert np.min(_closest(values)) == pytest.approx(0.0, abs=1e-15)
    assert _closest(np.array([0.3, 0.2, 0.25]))[1] == pytest.approx(0.2 - 0.05**2 / (8 * 0.15))
    assert np.min(_closest(np.array([0.2, 0.1, -0.1, -0.2]))) == 0.0  # a crossing
    assert np.all(_closest(np.array([0.3, 0.3001, 0.3002])) == [0.3, 0.3001, 0.3002])


def test_a_joint_move_of_hundreds_of_turns_is_too_long(station: Station) -> None:
    """An axis with limits of many turns (an endless axis given as ±1e8°) asked to turn 1e8°
    made 25 million samples (1.2 GB) and a MemoryError in the collision check."""
    import dataclasses

    from olp.passes.sampling import MAX_SAMPLES
    from olp.station.model import JointLimits

    limits = station.robot.limits
    endless = JointLimits(
        lower=np.concatenate([limits.lower[:5], [np.radians(-1e8)]]),
        upper=np.concatenate([limits.upper[:5], [np.radians(1e8)]]),
        velocity=limits.velocity,
        acceleration=limits.acceleration,
        jerk=limits.jerk,
    )
    cell = dataclasses.replace(station, robot=dataclasses.replace(station.robot, limits=endless))
    turns = 2 * MAX_SAMPLES / 180  # twice as many 2° samples as a move may have
    found = resolve(
        ir.Program(
            name="t",
            instructions=[_ptp([0, -90, 90, 0, 30, 0]), _ptp([0, -90, 90, 0, 30, 360 * turns], 2)],
        ),
        cell,
    ).diagnostics
    assert [(d.kind, d.span.line) for d in found if d.span] == [("too_long", 2)]
    assert "axis 6" in found[0].message


def test_consecutive_singular_lins_are_reported_together(station: Station) -> None:
    """A LIN ending at HOME's wrist singularity and one starting there: one warning."""
    above = _down(station, HOME, -0.02, 2)  # 20 mm up: A5 leaves 0
    back = _lin_to_joints(station, HOME, 3)
    (found,) = _warnings(station, _ptp(HOME), above, back)
    assert found[:2] == ("singularity", 2)
    assert "linear move 1 starts in the wrist singularity" in found[2]
    assert found[2].endswith("; move 2 too")


@pytest.mark.parametrize("metres", [0.02, -0.02])
def test_a_lin_from_and_back_to_an_exactly_singular_wrist_stays_continuous(
    station: Station, metres: float
) -> None:
    """From A5 = 0 exactly (A4 = 0) up or down, and back to the same pose as a program computes
    it (with rounding noise: through a frame and back). Both ways the path is continuous: from
    the singular start the move takes the wrist branch continuous with it (up needs the other
    one than down: was a 180° "singularity" jump), and on arrival the IK's split of A4 / A6,
    rounding noise there (here 18° to 34°), is replaced by the continuous one (was a jump)."""
    from olp.geometry import rotation_from_zyx

    start = [20, -80, 100, 0, 0, 0]
    pose = station.robot.flange_poses(np.radians(start))
    frame = np.eye(4)
    frame[:3, :3] = rotation_from_zyx(0.3, -1.1, 2.0)
    noisy = pose @ frame @ np.linalg.inv(frame)
    away = ir.LinearMove(target=ir.CartesianTarget(pose=transl(0, 0, metres) @ pose), span=_span(2))
    back = ir.LinearMove(target=ir.CartesianTarget(pose=noisy), span=_span(3))
    compiled = resolve(ir.Program(name="t", instructions=[_ptp(start), away, back]), station)
    assert [(d.severity, d.kind, d.span.line) for d in compiled.diagnostics if d.span] == [
        ("warning", "singularity", 2)
    ]
    assert compiled.diagnostics[0].message.endswith("; move 2 too")
    final = compiled.steps[2].joints
    assert final is not None and np.allclose(final, np.radians(start), atol=1e-6)
