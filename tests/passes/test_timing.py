"""Timing against closed forms and independent computations.

* PTP: Ruckig against the analytic rest-to-rest jerk-limited (double-S) time, per axis.
* LIN: TOPPRA against ``length / speed`` plus the analytic acceleration ramps, whose path
  acceleration comes from pinocchio's Jacobian (not from olp's kinematics).
* TOPPRA against a much finer grid of itself; limits checked on the densely sampled trajectory,
  the TCP speed by forward kinematics on it.
* Blending: faster than fine points, never faster than the rounded path at programmed speed, and
  the corner rounded like the parabola of the model.

* The reachability solver against the toppra package (the reference) on the same grid.
* Closed-form straight joint lines against TOPPRA on a finer grid, their limits on the sampled
  trajectory, and the fallback to the solver for curved or long moves.

Documented tolerances (see :mod:`olp.passes.timing`): joint velocities and TCP speed 0.1%,
joint accelerations 0.5%, closed forms 0.5%, a finer grid 1%, the reachability solver against
toppra 1e-5, closed-form lines against TOPPRA on a finer grid 0.1%.

Everything here is the acceleration-limited model (``TimingOptions(path_jerk=False)``: the
module's ``time_program`` sets it); the jerk-limited laws of path moves are tested in
tests/passes/test_jerk.py.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from scipy.interpolate import CubicSpline

from olp import ir
from olp.compiled import CompiledProgram, Step
from olp.geometry import rotation_log, rotz
from olp.kinematics.opw import OPWParameters
from olp.kinematics.pinocchio_model import TOOL0, build_model
from olp.passes import timing
from olp.passes.resolve import ResolveOptions, resolve
from olp.passes.timing import (
    DEFAULT_TIMES,
    ChainGeometry,
    TimingOptions,
    joint_path,
    line_profiles,
    override_speeds,
    ptp,
    ptp_duration,
    ptp_profile,
    reachability,
    speed_sweep,
    straight_paths,
    tcp_rates,
)
from olp.passes.timing import (
    time_program as _time_program,
)
from olp.station.loader import load_station
from olp.station.model import JointLimits, Station
from olp.trajectory import LineTimeLaw, PathTimeLaw

REPO = Path(__file__).resolve().parents[2]


def time_program(
    compiled: CompiledProgram,
    other_times: dict[str, float] | None = None,
    options: TimingOptions | None = None,
) -> CompiledProgram:
    """:func:`olp.passes.timing.time_program` with path moves acceleration-limited only."""
    accel_only = dataclasses.replace(options or TimingOptions(), path_jerk=False)
    return _time_program(compiled, other_times, accel_only)


Q0 = np.radians([10, -80, 95, 0, 30, 0])
FINE_GRID = TimingOptions(
    grid_per_sample=16,
    max_grid_step_rad=math.radians(0.0625),
    max_grid_turn_rad=math.radians(0.125),
    refine_points=96,
    straight_lines=False,
)
"""8x finer than the defaults in every respect, every path move by the solver."""

VELOCITY_TOL, ACCELERATION_TOL, TCP_SPEED_TOL = 1e-3, 5e-3, 1e-3
TOPPRA_PACKAGE = TimingOptions(solver="toppra", straight_lines=False)
"""The toppra package on every path move: the reference."""


@pytest.fixture(scope="module")
def station() -> Station:
    return load_station(REPO / "stations" / "kr6_milling_cell.yaml")


@pytest.fixture(scope="module")
def tool(station: Station) -> ir.Tool:
    return station.tools["spindle"]


def _slowed(station: Station, factor: float) -> Station:
    """The station with joint velocity limits divided by ``factor``."""
    lim = station.robot.limits
    limits = JointLimits(
        lower=lim.lower,
        upper=lim.upper,
        velocity=lim.velocity / factor,
        acceleration=lim.acceleration,
        jerk=lim.jerk,
    )
    return dataclasses.replace(station, robot=dataclasses.replace(station.robot, limits=limits))


def _lin(
    station: Station, tool: ir.Tool, offset: list[float], speed: float, zone: float = 0.0
) -> ir.LinearMove:
    """A LIN to the TCP pose at Q0 moved by ``offset`` (m, world axes)."""
    pose = station.robot.flange_poses(Q0) @ tool.pose
    pose[:3, 3] += offset
    return ir.LinearMove(
        target=ir.CartesianTarget(pose=pose),
        speed=ir.Speed(linear=speed),
        zone=ir.Zone(zone),
        tool=tool,
    )


def _compiled(
    station: Station,
    tool: ir.Tool,
    *moves: ir.Instruction,
    options: TimingOptions | None = None,
    resolving: ResolveOptions | None = None,
) -> CompiledProgram:
    start = ir.JointMove(target=ir.JointTarget(joints=Q0), tool=tool)
    program = ir.Program(name="t", instructions=[start, *moves])
    compiled = resolve(program, station, resolving)
    assert compiled.ok, [d.message for d in compiled.diagnostics]
    timed = time_program(compiled, options=options)
    assert timed.ok, [d.message for d in timed.diagnostics]
    return timed


# --------------------------------------------------------------------------------------------
# PTP: Ruckig against the double-S closed form


def _rest_to_rest_time(d: float, v: float, a: float, j: float) -> float:
    """Minimum time of a rest-to-rest move over ``d`` with velocity, acceleration and jerk
    limits: a symmetric double-S profile, with or without cruise and constant-acceleration
    phases (textbook closed form)."""

    def ramp(peak: float) -> float:  # time to reach ``peak`` velocity from rest
        return peak / a + a / j if peak >= a * a / j else 2 * math.sqrt(peak / j)

    if v * ramp(v) <= d:  # the velocity limit is reached: cruise
        return 2 * ramp(v) + (d - v * ramp(v)) / v
    peak = a / 2 * (-a / j + math.sqrt((a / j) ** 2 + 4 * d / a))
    if peak < a * a / j:  # the acceleration limit is not reached either
        peak = (d * math.sqrt(j) / 2) ** (2 / 3)
    return 2 * ramp(peak)


@pytest.mark.parametrize("degrees", [330.0, 150.0, 90.0, 5.0])
def test_single_axis_ptp_matches_the_double_s_closed_form(station: Station, degrees: float) -> None:
    robot = station.robot
    q0 = np.radians([-165, -90, 90, 0, 0, 0])
    q1 = q0 + np.radians([degrees, 0, 0, 0, 0, 0])
    v, a, j = robot.limits.velocity[0], robot.limits.acceleration[0], robot.limits.jerk[0]
    expected = _rest_to_rest_time(np.radians(degrees), v, a, j)
    assert ptp_duration(q0, q1, robot) == pytest.approx(expected, rel=5e-3)


def test_ptp_speed_scales_the_velocity_and_acceleration_limits(station: Station) -> None:
    robot = station.robot
    q0 = np.radians([0, -90, 90, 0, 0, 0])
    q1 = q0 + np.radians([150, 0, 0, 0, 0, 0])
    lim = robot.limits
    expected = _rest_to_rest_time(
        np.radians(150), lim.velocity[0] * 0.3, lim.acceleration[0] * 0.5, lim.jerk[0]
    )
    duration = ptp_duration(q0, q1, robot, velocity_scale=0.3, accel_scale=0.5)
    assert duration == pytest.approx(expected, rel=5e-3)


def test_synchronised_ptp_takes_the_slowest_axis_time(station: Station) -> None:
    robot, lim = station.robot, station.robot.limits
    rng = np.random.default_rng(7)
    for _ in range(20):
        q0, q1 = rng.uniform(lim.lower, lim.upper), rng.uniform(lim.lower, lim.upper)
        per_axis = [
            _rest_to_rest_time(abs(d), v * 0.6, a, j)
            for d, v, a, j in zip(q1 - q0, lim.velocity, lim.acceleration, lim.jerk, strict=True)
        ]
        assert ptp_duration(q0, q1, robot, 0.6) == pytest.approx(max(per_axis), rel=5e-3)


def test_ptp_trajectory_stays_on_the_joint_line_within_limits(station: Station) -> None:
    robot, lim = station.robot, station.robot.limits
    q0, q1 = np.radians([-100, -120, 30, 90, -60, 200]), np.radians([120, 10, 100, -150, 90, -200])
    profile = ptp_profile(q0, q1, robot, 0.8, 0.9)
    q, qd, qdd = profile.state(np.linspace(0.0, profile.duration, 5001))
    fraction = (q - q0) / (q1 - q0)
    assert np.max(np.abs(fraction - fraction[:, :1])) < 1e-9  # phase-synchronised: one line
    assert np.allclose(q[0], q0, atol=1e-12) and np.allclose(q[-1], q1, atol=1e-9)
    assert np.all(np.abs(qd) <= lim.velocity * 0.8 * (1 + 1e-9))
    assert np.all(np.abs(qdd) <= lim.acceleration * 0.9 * (1 + 1e-9))
    assert np.allclose(qd[[0, -1]], 0.0, atol=1e-9)


# --------------------------------------------------------------------------------------------
# LIN: TOPPRA against closed forms


KR6 = OPWParameters(
    0.025, -0.035, 0.0, 0.400, 0.455, 0.420, 0.080,
    offsets=(0.0, -math.pi / 2, 0.0, 0.0, 0.0, 0.0), signs=(-1, 1, 1, -1, 1, -1),
)  # fmt: skip
"""The KR 6 R900 sixx of stations/robots (the robot library's OPW numbers, metres)."""


def _pinocchio_tcp_jacobian(station: Station, tool: ir.Tool, q: np.ndarray) -> np.ndarray:
    """The TCP's world-frame Jacobian (6, 6) [linear; angular] from pinocchio's chain model."""
    model = build_model(KR6)
    data = model.createData()
    frame = model.getFrameId(TOOL0)
    jac = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)
    tool0 = np.asarray(data.oMf[frame].homogeneous)
    robot = station.robot
    world = robot.base @ tool0 @ robot.flange_in_tool0 @ tool.pose
    assert np.allclose(world, robot.flange_poses(q) @ tool.pose, atol=1e-9)  # the same robot
    offset = (np.linalg.inv(robot.base) @ world)[:3, 3] - tool0[:3, 3]
    linear = jac[:3] - np.cross(offset, jac[3:].T).T  # v_tcp = v_tool0 + w x offset
    rot = robot.base[:3, :3]
    return np.vstack([rot @ linear, rot @ jac[3:]])


def test_tcp_rates_match_pinocchio_jacobian(station: Station, tool: ir.Tool) -> None:
    rng = np.random.default_rng(3)
    lim = station.robot.limits
    q = rng.uniform(lim.lower, lim.upper, size=(10, 6))
    dq = rng.normal(size=(10, 6))
    linear, angular = tcp_rates(station.robot, tool.pose, q, dq)
    for k in range(10):
        twist = _pinocchio_tcp_jacobian(station, tool, q[k]) @ dq[k]
        assert linear[k] == pytest.approx(np.linalg.norm(twist[:3]), rel=1e-6)
        assert angular[k] == pytest.approx(np.linalg.norm(twist[3:]), rel=1e-6)


def test_slow_lin_takes_length_over_speed(station: Station, tool: ir.Tool) -> None:
    compiled = _compiled(station, tool, _lin(station, tool, [0.0, 0.2, 0.0], 0.02))
    step = compiled.steps[1]
    assert step.path_length == pytest.approx(0.2, rel=1e-6)
    # 10 s at 20 mm/s; the acceleration ramps of a 20 mm/s move last milliseconds
    assert step.duration == pytest.approx(10.0, rel=5e-3)
    assert step.duration > 10.0


@pytest.mark.parametrize(("length", "speed"), [(0.05, 0.25), (0.1, 0.5)])
def test_lin_is_length_over_speed_plus_the_analytic_ramps(
    station: Station, tool: ir.Tool, length: float, speed: float
) -> None:
    """A short fast LIN: ramps are 17-28% of its time. From rest, the path acceleration is
    bounded by the most loaded joint: ``a_s = min_j a_j / |dq_j/ds|`` with
    ``dq/ds = J^-1 [u; 0]`` (u the unit direction, orientation constant), so each ramp costs
    ``v / (2 a_s)`` over ``length / v``."""
    compiled = _compiled(station, tool, _lin(station, tool, [0.0, length, 0.0], speed))
    step = compiled.steps[1]
    assert step.path is not None
    accel = []
    for q in (step.path[0], step.path[-1]):
        dq_ds = np.linalg.solve(_pinocchio_tcp_jacobian(station, tool, q), [0, 1, 0, 0, 0, 0])
        accel.append(np.min(station.robot.limits.acceleration / np.abs(dq_ds)))
    expected = length / speed + speed / (2 * accel[0]) + speed / (2 * accel[1])
    assert expected - length / speed > 0.15 * expected  # the ramps matter here
    assert step.duration == pytest.approx(expected, rel=5e-3)


def test_joint_velocity_limited_lin_follows_the_velocity_bound(
    station: Station, tool: ir.Tool
) -> None:
    """With axes 20x slower the TCP limit never binds: cruising at each sample interval's
    slowest-axis time is a lower bound, reached except for the ramps."""
    slow = _slowed(station, 20.0)
    compiled = _compiled(slow, tool, _lin(slow, tool, [0.0, 0.3, -0.1], 2.0))
    step = compiled.steps[1]
    assert step.path is not None
    cruise = np.sum(np.max(np.abs(np.diff(step.path, axis=0)) / slow.robot.limits.velocity, axis=1))
    assert cruise > 10 * step.path_length / 2.0
    assert cruise * (1 - 1e-3) <= step.duration <= cruise * 1.05


def test_orientation_speed_limit(station: Station, tool: ir.Tool) -> None:
    pose = station.robot.flange_poses(Q0) @ tool.pose
    pose[:3, :3] = pose[:3, :3] @ rotz(np.radians(60))[:3, :3]
    pose[:3, 3] += [0.0, 0.01, 0.0]
    limit = np.radians(30)
    move = ir.LinearMove(
        target=ir.CartesianTarget(pose=pose),
        speed=ir.Speed(linear=1.0, angular=limit),
        tool=tool,
    )
    compiled = _compiled(station, tool, move)
    segment = compiled.steps[1].trajectory
    assert segment is not None
    t = np.linspace(0.0, segment.duration, 100001)
    poses = station.robot.flange_poses(segment.state(t)[0]) @ tool.pose
    turn = rotation_log(np.swapaxes(poses[:-1, :3, :3], -1, -2) @ poses[1:, :3, :3])
    speed = np.linalg.norm(turn, axis=-1) / np.diff(t)
    assert np.max(speed) <= limit * (1 + TCP_SPEED_TOL)
    assert np.radians(60) / limit < segment.duration < 1.02 * np.radians(60) / limit


# --------------------------------------------------------------------------------------------
# Discretisation: a finer grid, limits on the sampled trajectory


def _cases(station: Station, tool: ir.Tool) -> dict[str, tuple[Station, list[ir.Instruction]]]:
    slow = _slowed(station, 10.0)
    corner = np.array([0.0, 0.1, 0.0])
    return {
        "short fast LIN": (station, [_lin(station, tool, [0.0, 0.05, 0.0], 0.25)]),
        "accel-limited LIN": (station, [_lin(station, tool, [0.0, 0.6, -0.1], 2.0)]),
        "velocity-limited LIN": (slow, [_lin(slow, tool, [0.0, 0.4, -0.1], 1.0)]),
        "blended chain": (
            station,
            [
                _lin(station, tool, [0.0, 0.3, 0.0], 1.0, 0.05),
                _lin(station, tool, [0.2, 0.3, 0.0], 0.5, 0.05),
                _lin(station, tool, [0.2, 0.0, -0.1], 1.0),
            ],
        ),
        "179 degree blend": (
            station,
            [
                _lin(station, tool, list(corner), 1.0, 0.03),
                _lin(station, tool, list(corner + 0.1 * np.array([0.0175, -1.0, 0.0])), 1.0),
            ],
        ),
    }


@pytest.mark.parametrize(
    "case",
    ["short fast LIN", "accel-limited LIN", "velocity-limited LIN", "blended chain"],
)
def test_toppra_matches_a_much_finer_grid_of_itself(
    station: Station, tool: ir.Tool, case: str
) -> None:
    where, moves = _cases(station, tool)[case]
    coarse = _compiled(where, tool, *moves)
    fine = _compiled(where, tool, *moves, options=FINE_GRID)
    for a, b in zip(coarse.steps[1:], fine.steps[1:], strict=True):
        assert a.duration == pytest.approx(b.duration, rel=1e-2)
    assert coarse.cycle_time == pytest.approx(fine.cycle_time, rel=1e-2)


@pytest.mark.parametrize(
    "case",
    ["accel-limited LIN", "velocity-limited LIN", "blended chain", "179 degree blend"],
)
def test_limits_hold_on_the_sampled_trajectory(station: Station, tool: ir.Tool, case: str) -> None:
    where, moves = _cases(station, tool)[case]
    compiled = _compiled(where, tool, *moves)
    law = compiled.steps[1].trajectory.law  # type: ignore[union-attr]
    t = np.linspace(0.0, law.duration, 200001)
    q, qd, qdd = law.state(t)
    lim = where.robot.limits
    assert np.max(np.abs(qd) / lim.velocity) <= 1 + VELOCITY_TOL
    assert np.max(np.abs(qdd) / lim.acceleration) <= 1 + ACCELERATION_TOL
    tcp = (where.robot.flange_poses(q) @ tool.pose)[:, :3, 3]
    speed = np.linalg.norm(np.diff(tcp, axis=0), axis=-1) / np.diff(t)
    programmed = max(m.speed.linear for m in moves if isinstance(m, ir.LinearMove))
    assert np.max(speed) <= programmed * (1 + TCP_SPEED_TOL)


@pytest.mark.parametrize("count", [2, 3, 4, 7])
def test_joint_path_is_scipys_not_a_knot_spline(count: int) -> None:
    """Through three samples olp builds the parabola itself (scipy's dense solve is slow)."""
    rng = np.random.default_rng(count)
    s = np.cumsum(rng.uniform(0.1, 1.0, count)) - 0.1
    q = rng.normal(size=(count, 6))
    ours = joint_path(ChainGeometry(s=s, q=q, boundaries=s[[0, -1]], lengths=np.ones(1)))
    scipys = CubicSpline(s, q)
    x = np.linspace(s[0], s[-1], 101)
    for order in range(3):
        assert np.allclose(ours(x, order), scipys(x, order), rtol=0, atol=1e-12)
    assert ours.dof == 6 and ours.path_interval.tolist() == [s[0], s[-1]]


@pytest.mark.parametrize("case", ["accel-limited LIN", "blended chain", "179 degree blend"])
def test_reachability_solver_matches_the_toppra_package(
    station: Station, tool: ir.Tool, case: str
) -> None:
    """The same problem (grid, constraints, discretisation) solved by olp's vectorised
    reachability analysis and by the toppra package's per-stage loop."""
    where, moves = _cases(station, tool)[case]
    ours = _compiled(where, tool, *moves)
    reference = _compiled(where, tool, *moves, options=TOPPRA_PACKAGE)
    for a, b in zip(ours.steps[1:], reference.steps[1:], strict=True):
        assert a.duration == pytest.approx(b.duration, rel=1e-5)


@pytest.mark.parametrize("sweeps", [0, 10**9])
def test_reachability_numpy_sweeps_and_ordered_pass_agree(
    station: Station, tool: ir.Tool, sweeps: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """All stages by the ordered pass (0 numpy sweeps) or all by numpy sweeps: the same law."""
    where, moves = _cases(station, tool)["accel-limited LIN"]
    default = _compiled(where, tool, *moves)
    monkeypatch.setattr(reachability, "_VECTOR_SWEEPS", sweeps)
    other = _compiled(where, tool, *moves)
    assert other.steps[1].duration == pytest.approx(default.steps[1].duration, rel=1e-12)


def test_tcp_speed_holds_per_instruction(station: Station, tool: ir.Tool) -> None:
    """In a chain of different speeds each instruction's own speed holds up to the boundary."""
    moves = _cases(station, tool)["blended chain"][1]
    compiled = _compiled(station, tool, *moves)
    for step, move in zip(compiled.steps[1:], moves, strict=True):
        segment = step.trajectory
        assert segment is not None and isinstance(move, ir.LinearMove)
        t = np.linspace(0.0, segment.duration, 50001)
        tcp = (station.robot.flange_poses(segment.state(t)[0]) @ tool.pose)[:, :3, 3]
        speed = np.linalg.norm(np.diff(tcp, axis=0), axis=-1) / np.diff(t)
        assert np.max(speed) <= move.speed.linear * (1 + TCP_SPEED_TOL)


# --------------------------------------------------------------------------------------------
# Zones


def _square(station: Station, tool: ir.Tool, zone: float, speed: float) -> list[ir.Instruction]:
    corners = [[0.0, 0.1, 0.0], [0.1, 0.1, 0.0], [0.1, 0.0, 0.0], [0.0, 0.0, 0.0]]
    moves = [_lin(station, tool, c, speed, zone) for c in corners]
    moves[-1] = dataclasses.replace(moves[-1], zone=ir.FINE)
    return list(moves)


@pytest.mark.parametrize("speed", [0.05, 1.0])
def test_blending_is_faster_than_fine_points_but_not_than_the_path_at_speed(
    station: Station, tool: ir.Tool, speed: float
) -> None:
    fine = _compiled(station, tool, *_square(station, tool, 0.0, speed))
    blended = _compiled(station, tool, *_square(station, tool, 0.02, speed))
    fine_t = sum(s.duration for s in fine.steps[1:])
    blended_t = sum(s.duration for s in blended.steps[1:])
    rounded = sum(s.path_length for s in blended.steps[1:])
    assert blended_t < fine_t
    assert rounded < 0.4 - 1e-3  # the corners are cut
    assert blended_t >= rounded / speed * (1 - TCP_SPEED_TOL)
    assert not [d for d in blended.diagnostics if d.kind == "zone_stop"]


def test_blend_rounds_the_corner_like_the_parabola_of_the_model(
    station: Station, tool: ir.Tool
) -> None:
    """A parabola from d before a 90° corner to d after it, with its middle control point on
    the corner, passes the corner at d·√2/4 (a fine point passes through it)."""
    d = 0.02
    compiled = _compiled(station, tool, *_square(station, tool, d, 0.5))
    segment = compiled.steps[1].trajectory
    assert segment is not None
    law = segment.law
    q = law.state(np.linspace(0.0, law.duration, 100001))[0]
    tcp = (station.robot.flange_poses(q) @ tool.pose)[:, :3, 3]
    corner = (station.robot.flange_poses(Q0) @ tool.pose)[:3, 3] + [0.0, 0.1, 0.0]
    distance = np.linalg.norm(tcp - corner, axis=-1)
    assert np.min(distance) == pytest.approx(d * math.sqrt(2) / 4, rel=0.02)


def test_a_comment_keeps_a_blend_an_output_breaks_it(station: Station, tool: ir.Tool) -> None:
    a = _lin(station, tool, [0.0, 0.1, 0.0], 0.5, 0.02)
    b = _lin(station, tool, [0.1, 0.1, 0.0], 0.5)
    comment = _compiled(station, tool, a, ir.Comment(text="x"), b)
    output = _compiled(station, tool, a, ir.SetOutput(index=1, value=True), b)
    plain = _compiled(station, tool, a, b)
    moving = [1, 3]
    assert sum(comment.steps[i].duration for i in moving) == pytest.approx(
        plain.steps[1].duration + plain.steps[2].duration, rel=1e-9
    )
    assert (
        sum(output.steps[i].duration for i in moving) > plain.cycle_time - plain.steps[0].duration
    )
    assert [d.index for d in output.diagnostics if d.kind == "zone_stop"] == [1]


# --------------------------------------------------------------------------------------------
# Other instructions, sweeps, failures


def test_wait_counts_its_time(station: Station) -> None:
    program = ir.Program(name="t", instructions=[ir.Wait(seconds=1.5)])
    compiled = time_program(resolve(program, station))
    assert compiled.cycle_time == pytest.approx(1.5)


def test_default_times_and_overrides(station: Station) -> None:
    program = ir.Program(
        name="t",
        instructions=[
            ir.SetOutput(index=1, value=True),
            ir.WaitInput(index=2),
            ir.Call(name="SprayOn"),
            ir.Call(name="Other"),
        ],
    )
    compiled = resolve(program, station)
    default = time_program(compiled)
    assert [s.duration for s in default.steps] == [
        DEFAULT_TIMES["set_output"],
        DEFAULT_TIMES["wait_input"],
        DEFAULT_TIMES["call"],
        DEFAULT_TIMES["call"],
    ]
    custom = time_program(compiled, {"set_output": 0.1, "call": 0.2, "call:sprayon": 2.0})
    assert [s.duration for s in custom.steps] == [0.1, DEFAULT_TIMES["wait_input"], 2.0, 0.2]


def test_speed_sweep_matches_retiming_and_is_monotonic(station: Station, tool: ir.Tool) -> None:
    q1 = Q0 + np.radians([60, 0, 0, 0, 0, 0])
    moves = [
        *_square(station, tool, 0.01, 0.1),
        ir.JointMove(target=ir.JointTarget(joints=q1), tool=tool),
        ir.Wait(seconds=0.5),
    ]
    compiled = _compiled(station, tool, *moves)
    linear, joint = [0.05, 0.1, 0.4], [0.25, 0.5, 1.0]
    accel_only = TimingOptions(path_jerk=False)
    table = speed_sweep(compiled, linear, joint, options=accel_only)
    assert table.shape == (3, 3)
    assert np.all(np.diff(table, axis=0) < 0) and np.all(np.diff(table, axis=1) < 0)
    direct = time_program(override_speeds(compiled, linear=0.4, joint=0.25))
    assert table[2, 0] == pytest.approx(direct.cycle_time, rel=1e-9)
    programmed = speed_sweep(compiled, [None], [None], options=accel_only)
    assert programmed[0, 0] == pytest.approx(compiled.cycle_time, rel=1e-9)


def test_a_motion_that_cannot_be_timed_is_a_diagnostic(
    station: Station, tool: ir.Tool, monkeypatch: pytest.MonkeyPatch
) -> None:
    def fail(*args: object, **kwargs: object) -> None:
        raise timing.TimingError("no profile")

    monkeypatch.setattr(ptp, "ptp_profile", fail)
    program = ir.Program(
        name="t", instructions=[ir.JointMove(target=ir.JointTarget(joints=Q0), tool=tool)]
    )
    compiled = time_program(resolve(program, station))
    assert [(d.severity, d.kind, d.index) for d in compiled.diagnostics] == [("error", "timing", 0)]
    assert not compiled.ok


def test_an_unevenly_sampled_circle_is_timed_by_its_tcp_speed(
    station: Station, tool: ir.Tool
) -> None:
    """Timing takes any sampled path: a half circle (r = 100 mm) sampled 10x denser at its
    start than at its end, as a CIRC step. A bound ``ds/dt <= v / L`` on a sample-index
    parameter would run the sparse end 10x too fast; the Jacobian constraint holds the TCP speed
    to ``v`` everywhere, so the move takes ``arc / v`` plus millisecond ramps."""
    robot, speed, radius = station.robot, 0.05, 0.1
    start = robot.flange_poses(Q0) @ tool.pose
    u = np.linspace(0.0, 1.0, 120)
    angle = np.pi * (0.1 * u + 0.9 * u**2)  # sample spacing grows 19x along the arc
    poses = np.repeat(start[None], u.size, axis=0)
    poses[:, 0, 3] += radius * (1 - np.cos(angle))
    poses[:, 1, 3] += radius * np.sin(angle)
    solutions = robot.solve(poses @ np.linalg.inv(tool.pose))[:, robot.branch_of(Q0)]
    steps = np.diff(np.vstack([Q0, solutions]), axis=0)
    path = Q0 + np.cumsum((steps + np.pi) % (2 * np.pi) - np.pi, axis=0)
    assert np.allclose(robot.flange_poses(path) @ tool.pose, poses, atol=1e-9)
    via = ir.CartesianTarget(pose=poses[60])
    circ = ir.CircularMove(
        target=ir.CartesianTarget(pose=poses[-1]), via=via, speed=ir.Speed(linear=speed), tool=tool
    )
    program = ir.Program(name="t", instructions=(circ,))
    step = Step(index=0, instruction=circ, joints=path[-1], path=path, tool=tool, frame=ir.WORLD)
    compiled = time_program(CompiledProgram(program, station, Q0, (step,)))
    timed = compiled.steps[0]
    arc = np.pi * radius
    assert timed.path_length == pytest.approx(arc, rel=1e-4)
    assert arc / speed < timed.duration < arc / speed * (1 + 5e-3)
    assert timed.trajectory is not None
    t = np.linspace(0.0, timed.duration, 50001)
    tcp = (robot.flange_poses(timed.trajectory.state(t)[0]) @ tool.pose)[:, :3, 3]
    measured = np.linalg.norm(np.diff(tcp, axis=0), axis=-1) / np.diff(t)
    assert np.max(measured) <= speed * (1 + TCP_SPEED_TOL)


# --------------------------------------------------------------------------------------------
# Stop-to-stop moves along straight joint lines: closed form


SHORT_LINES = {
    "0.1 mm, too short to cruise": ([0.0, 1e-4, 0.0], 0.05),
    "0.5 mm at 10 mm/s, TCP-limited": ([0.0, 1e-4, 5e-4], 0.01),
    "0.2 mm at 0.5 m/s, too short to cruise": ([2e-4, 1e-4, 5e-4], 0.5),
}
"""Fine-stopped LINs one after the other (target offset from the start pose in m, speed m/s),
one resolved interval each."""


def _short_lines(
    station: Station, tool: ir.Tool, options: TimingOptions | None = None
) -> CompiledProgram:
    moves = [_lin(station, tool, offset, speed) for offset, speed in SHORT_LINES.values()]
    return _compiled(station, tool, *moves, options=options)


def test_short_straight_moves_are_timed_in_closed_form_as_toppra_would(
    station: Station, tool: ir.Tool
) -> None:
    """Against the solver on a grid 8x finer: within 0.1%, and never below it by more than that
    grid's own error; against the toppra package where it finds a time law: within 0.1%."""
    lines = _short_lines(station, tool)
    fine = _short_lines(station, tool, FINE_GRID)
    for a, b in zip(lines.steps[1:], fine.steps[1:], strict=True):
        assert a.trajectory is not None and isinstance(a.trajectory.law, LineTimeLaw)
        assert a.duration == pytest.approx(b.duration, rel=1e-3)
        assert a.duration >= b.duration * (1 - 1e-4)
        assert a.path_length == pytest.approx(b.path_length, rel=1e-9)
    # The toppra package itself, on its default grid (on the finer one it finds cusps): it
    # finds no time law on the 0.1 mm move.
    reference = time_program(resolve(lines.program, station), options=TOPPRA_PACKAGE)
    assert [(d.kind, d.index) for d in reference.diagnostics] == [("timing", 1)]
    for a, b in zip(lines.steps[2:], reference.steps[2:], strict=True):
        assert isinstance(b.trajectory.law, PathTimeLaw)  # type: ignore[union-attr]
        assert a.duration == pytest.approx(b.duration, rel=1e-3)


@pytest.mark.parametrize("case", list(SHORT_LINES))
def test_closed_form_lines_hold_the_limits_on_the_sampled_trajectory(
    station: Station, tool: ir.Tool, case: str
) -> None:
    index = list(SHORT_LINES).index(case) + 1
    speed = SHORT_LINES[case][1]
    step = _short_lines(station, tool).steps[index]
    assert step.trajectory is not None and isinstance(step.trajectory.law, LineTimeLaw)
    assert step.path is not None
    t = np.linspace(0.0, step.duration, 20001)
    q, qd, qdd = step.trajectory.state(t)
    lim = station.robot.limits
    assert np.allclose(q[[0, -1]], step.path[[0, -1]], atol=1e-12)
    assert np.max(np.abs(qd) / lim.velocity) <= 1 + 1e-9
    assert np.max(np.abs(qdd) / lim.acceleration) == pytest.approx(1.0, rel=1e-9)
    tcp = (station.robot.flange_poses(q) @ tool.pose)[:, :3, 3]
    tcp_speed = np.linalg.norm(np.diff(tcp, axis=0), axis=-1) / np.diff(t)
    assert np.max(tcp_speed) <= speed * (1 + TCP_SPEED_TOL)
    if "TCP-limited" in case:  # it cruises at the programmed speed, within the bound
        assert np.max(tcp_speed) >= speed * (1 - 1e-3)


def test_the_solver_takes_curved_and_long_moves(station: Station, tool: ir.Tool) -> None:
    """A 50 mm LIN (11 samples, a curved joint path) and a 20 mm LIN resolved as one interval
    (straight in joint space, but its TCP rate varies by more than the bound allows) are timed
    by the solver; the closed form stays for the short move beside them."""
    curved = _lin(station, tool, [0.0, 0.05, 0.0], 0.1)
    coarse = ResolveOptions(step_m=1.0, step_rad=1.0)
    long = _lin(station, tool, [0.0, 0.02, 0.0], 0.1)
    short = _lin(station, tool, [0.0, 0.0201, 0.0], 0.05)
    laws = [s.trajectory.law for s in _compiled(station, tool, curved).steps[1:]]  # type: ignore[union-attr]
    both = _compiled(station, tool, long, short, resolving=coarse)
    laws += [s.trajectory.law for s in both.steps[1:]]  # type: ignore[union-attr]
    assert [type(law) for law in laws] == [PathTimeLaw, PathTimeLaw, LineTimeLaw]
    step = both.steps[1]
    assert step.path is not None and len(step.path) == 2
    bound = line_profiles(
        step.path[:1],
        step.path[1:],
        station.robot,
        tool.pose[None],
        np.array([0.1]),
        np.array([np.inf]),
    ).excess
    assert bound[0] > 1e-3


def test_collinear_samples_make_a_line_and_a_bend_does_not(station: Station, tool: ir.Tool) -> None:
    q1 = Q0 + np.radians([0.02, -0.01, 0.015, 0.0, 0.01, 0.02])
    line = Q0 + np.linspace(0.0, 1.0, 5)[:, None] * (q1 - Q0)
    bent = line.copy()
    bent[2] += [2e-7, 0.0, 0.0, 0.0, 0.0, 0.0]
    back = line[[0, 2, 1, 3, 4]]
    assert straight_paths([line, bent, back, line[[0, 4]]], 1e-7).tolist() == [
        True,
        False,
        False,
        True,
    ]
    move = ir.LinearMove(target=ir.JointTarget(joints=q1), speed=ir.Speed(linear=0.05), tool=tool)
    program = ir.Program(name="t", instructions=(move, move))
    steps = tuple(
        Step(index=i, instruction=move, joints=q1, path=path, tool=tool, frame=ir.WORLD)
        for i, path in enumerate([line, bent])
    )
    timed = time_program(CompiledProgram(program, station, Q0, steps))
    assert timed.ok
    kinds = [type(s.trajectory.law) for s in timed.steps]  # type: ignore[union-attr]
    assert kinds == [LineTimeLaw, PathTimeLaw]
    # the same move to 2e-7 rad; the solver's default grid is ~1% slow on so short a path
    assert timed.steps[0].duration == pytest.approx(timed.steps[1].duration, rel=2e-2)


# --------------------------------------------------------------------------------------------
# Absurd but parseable values: a timing diagnostic on the instruction, never an exception


def _ptp_at(station: Station, speed: ir.Speed) -> CompiledProgram:
    moves = [
        ir.JointMove(target=ir.JointTarget(joints=Q0)),
        ir.JointMove(target=ir.JointTarget(joints=Q0 + 0.2), speed=speed, span=SPAN),
    ]
    return time_program(resolve(ir.Program(name="t", instructions=moves), station))


SPAN = ir.SourceSpan("t.src", 7, 1)


@pytest.mark.parametrize(
    "speed",
    [ir.Speed(joint=1e-8), ir.Speed(joint=1e-300), ir.Speed(joint_acceleration=1e-300)],
)
def test_a_joint_move_too_slow_for_ruckig_is_a_timing_error(
    station: Station, speed: ir.Speed
) -> None:
    """``$VEL_AXIS[1] = 0.000001`` gave Ruckig's ``-101 is not a valid Result`` (a ValueError),
    1e-300 a RuckigError: Ruckig times joint moves up to 7,600 s."""
    compiled = _ptp_at(station, speed)
    assert [(d.severity, d.kind, d.span) for d in compiled.diagnostics] == [
        ("error", "timing", SPAN)
    ]
    assert "7600 s" in compiled.diagnostics[0].message


def test_ruckig_s_longest_move_is_timed(station: Station) -> None:
    """Just inside the bound the move is timed, and takes about the bound."""
    q0, q1 = np.zeros(6), np.array([0.2, 0, 0, 0, 0, 0])
    scale = 0.2 / (timing.RUCKIG_MAX_DURATION * 0.99) / station.robot.limits.velocity[0]
    duration = ptp_duration(q0, q1, station.robot, velocity_scale=scale)
    assert 0.98 * timing.RUCKIG_MAX_DURATION < duration < timing.RUCKIG_MAX_DURATION


def _unnamed_result() -> Exception:
    return ValueError("-101 is not a valid Result.")


def _rejected_input() -> Exception:
    from ruckig import RuckigError

    return RuckigError("[ruckig] error in step 1\ndetails")


# Factories, not instances: a raised exception keeps its traceback, whose frames hold Ruckig's
# objects; an instance kept by the parametrisation would keep them alive to the end.
@pytest.mark.parametrize("make_error", [_unnamed_result, _rejected_input])
def test_any_ruckig_failure_is_a_timing_error(
    station: Station, monkeypatch: pytest.MonkeyPatch, make_error: Callable[[], Exception]
) -> None:
    class Failing:
        def __init__(self, dof: int) -> None:
            del dof

        def calculate(self, *args: object) -> None:
            raise make_error()

    monkeypatch.setattr(ptp, "Ruckig", Failing)
    with pytest.raises(timing.TimingError, match="Ruckig could not time the joint move"):
        ptp_profile(Q0, Q0 + 0.2, station.robot)


def test_speed_sweep_with_an_absurd_joint_speed_gives_nan(station: Station) -> None:
    compiled = _ptp_at(station, ir.Speed())
    table = speed_sweep(compiled, [None], [1e-300, 1.0])
    assert np.isnan(table[0, 0]) and np.isfinite(table[0, 1])


@pytest.mark.parametrize("speed", [ir.Speed(linear=1e-300), ir.Speed(angular=1e-300)])
@pytest.mark.parametrize("metres", [0.02, 0.001])  # a curve for the solver, a closed-form line
def test_a_path_move_too_slow_to_time_says_so(
    station: Station, tool: ir.Tool, speed: ir.Speed, metres: float
) -> None:
    """1e-300 m/s was reported as "cannot be followed without stopping (a cusp)", or on a short
    straight move timed as inf s (with numpy's overflow warning)."""
    move = dataclasses.replace(_lin(station, tool, [0, 0, -metres], 0.1), speed=speed, span=SPAN)
    start = ir.JointMove(target=ir.JointTarget(joints=Q0), tool=tool)
    compiled = time_program(resolve(ir.Program(name="t", instructions=[start, move]), station))
    assert [(d.kind, d.span) for d in compiled.diagnostics] == [("timing", SPAN)]
    assert "too low to time" in compiled.diagnostics[0].message


def test_a_slow_path_move_is_timed_down_to_the_floor(station: Station, tool: ir.Tool) -> None:
    """1 um/s is slow, not absurd: timed as length / speed."""
    compiled = _compiled(station, tool, _lin(station, tool, [0, 0, -0.02], 1e-6))
    assert compiled.steps[1].duration == pytest.approx(0.02 / 1e-6, rel=1e-4)


@pytest.mark.parametrize("length", [1e-9, 1e-10, 1e-12])
def test_tiny_moves_after_others_are_timed(station: Station, tool: ir.Tool, length: float) -> None:
    """Problems solved together sat end to end on one axis, 1 apart: a tiny move's gridpoints
    (1e-17 apart) rounded together there and it found no time law."""
    moves = [
        _lin(station, tool, [0.01, 0, 0], 0.1),
        _lin(station, tool, [0.01 + length, 0, 0], 0.1),
        _lin(station, tool, [0.01 + length, length, 0], 0.1),
    ]
    compiled = _compiled(station, tool, *moves)
    alone = [_compiled(station, tool, moves[0], m) for m in moves[1:]]
    assert [s.duration for s in alone[0].steps[2:]] == [compiled.steps[2].duration]
    assert 0 < compiled.steps[3].duration < 1e-3


def test_a_cycle_time_beyond_the_float_range_is_an_error(station: Station) -> None:
    """Two waits of 1e308 s are each finite; their sum is not."""
    program = ir.Program(
        name="t",
        instructions=[
            ir.JointMove(target=ir.JointTarget(joints=Q0)),
            ir.Wait(seconds=1e308),
            ir.Wait(seconds=1e308, span=SPAN),
        ],
    )
    compiled = time_program(resolve(program, station))
    assert [(d.severity, d.kind, d.span) for d in compiled.diagnostics] == [
        ("error", "timing", SPAN)
    ]
