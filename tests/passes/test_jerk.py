"""Jerk-limited path moves and TCP accelerations against closed forms and Ruckig.

* The double S (:mod:`olp.passes.timing.scurve`) against Ruckig in one axis, every case.
* A path move along a straight joint line, rest to rest, by the closed form and by the solver,
  against Ruckig's phase-synchronised move between the same joints (the jerk-limited optimum
  on that line): within 0.5%.
* The issue's ten fine-stopped 30 mm LINs at 250 mm/s against the double S by hand (the TCP's
  speed, the joints' acceleration and jerk along each move's chord): within 1%; the
  acceleration-limited model was 35% short.
* ``$ACC.CP``: a LIN limited by its path acceleration against ``L / v + v / a``.
* The limits on the sampled jerk-limited trajectories.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from ruckig import InputParameter, Ruckig, Trajectory

from olp import ir
from olp.compiled import CompiledProgram, Step
from olp.geometry import rotation_log
from olp.passes.resolve import resolve
from olp.passes.timing import TimingOptions, ptp_duration, time_program
from olp.passes.timing.scurve import double_s
from olp.station.loader import load_station
from olp.station.model import Station
from olp.trajectory import LineTimeLaw, SmoothedTimeLaw

REPO = Path(__file__).resolve().parents[2]
Q0 = np.radians([10, -80, 95, 0, 30, 0])
SOLVER = TimingOptions(straight_lines=False)
ACCEL_ONLY = TimingOptions(path_jerk=False)


@pytest.fixture(scope="module")
def station() -> Station:
    return load_station(REPO / "stations" / "kr6_milling_cell.yaml")


@pytest.fixture(scope="module")
def tool(station: Station) -> ir.Tool:
    return station.tools["spindle"]


def _ruckig_1d(length: float, v: float, a: float, j: float) -> float:
    inp = InputParameter(1)
    inp.current_position, inp.target_position = [0.0], [length]
    inp.current_velocity = inp.current_acceleration = [0.0]
    inp.target_velocity = inp.target_acceleration = [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [v], [a], [j]
    trajectory = Trajectory(1)
    Ruckig(1).calculate(inp, trajectory)
    return float(trajectory.duration)


@pytest.mark.parametrize(
    ("length", "v", "a", "j"),
    [
        (10.0, 1.0, 2.0, 10.0),  # cruises, A reached
        (10.0, 1.0, 4.0, 10.0),  # cruises, A not reached (V J < A²)
        (0.5, 1.0, 2.0, 10.0),  # no cruise, A reached
        (0.01, 1.0, 2.0, 10.0),  # no cruise, A not reached
        (3.0, 2.0, 1.0, 1e9),  # nearly a trapezoid
    ],
)
def test_double_s_is_ruckigs_optimum(length: float, v: float, a: float, j: float) -> None:
    ours = double_s(*(np.array([x]) for x in (length, v, a, j))).duration[0]
    assert ours == pytest.approx(_ruckig_1d(length, v, a, j), rel=1e-6)


def _line_program(station: Station, tool: ir.Tool, q1: np.ndarray) -> CompiledProgram:
    """One LIN from Q0 to ``q1`` whose resolved path is the straight joint line (two samples),
    at a TCP speed no joint limit lets it reach."""
    move = ir.LinearMove(target=ir.JointTarget(joints=q1), speed=ir.Speed(linear=100.0), tool=tool)
    program = ir.Program(name="t", instructions=(move,))
    path = np.stack([Q0, q1])
    step = Step(index=0, instruction=move, joints=q1, path=path, tool=tool, frame=ir.WORLD)
    return CompiledProgram(program, station, Q0, (step,))


@pytest.mark.parametrize("degrees", [40.0, 5.0, 0.3, 0.01])
@pytest.mark.parametrize("options", [TimingOptions(), SOLVER], ids=["closed form", "solver"])
def test_straight_line_rest_to_rest_is_the_jerk_limited_optimum(
    station: Station, tool: ir.Tool, degrees: float, options: TimingOptions
) -> None:
    q1 = Q0 + np.radians(degrees) * np.array([1.0, -0.5, 0.8, 0.3, 0.4, 1.0])
    timed = time_program(_line_program(station, tool, q1), options=options)
    assert timed.ok, [d.message for d in timed.diagnostics]
    law = timed.steps[0].trajectory.law  # type: ignore[union-attr]
    if not options.straight_lines:
        assert isinstance(law, SmoothedTimeLaw)
    elif degrees < 1.0:  # longer lines: the TCP rate's bound is too loose, the solver takes them
        assert isinstance(law, LineTimeLaw)
    optimum = ptp_duration(Q0, q1, station.robot)
    assert timed.steps[0].duration == pytest.approx(optimum, rel=5e-3)


def _lin(station: Station, tool: ir.Tool, offset: list[float], **speed: float) -> ir.LinearMove:
    pose = station.robot.flange_poses(Q0) @ tool.pose
    pose[:3, 3] += offset
    return ir.LinearMove(target=ir.CartesianTarget(pose=pose), speed=ir.Speed(**speed), tool=tool)


def _resolved(station: Station, tool: ir.Tool, *moves: ir.Instruction) -> CompiledProgram:
    start = ir.JointMove(target=ir.JointTarget(joints=Q0), tool=tool)
    compiled = resolve(ir.Program(name="t", instructions=[start, *moves]), station)
    assert compiled.ok
    return compiled


def _by_hand(station: Station, step: Step, length: float, speed: float) -> float:
    """The double S along the move's joint chord: the TCP at ``speed`` (the chord's TCP rate
    taken as ``length`` / chord), the joints' acceleration and jerk along the chord."""
    assert step.path is not None
    chord = step.path[-1] - step.path[0]
    d = float(np.linalg.norm(chord))
    e = np.abs(chord / d)
    with np.errstate(divide="ignore"):
        a = np.min(station.robot.limits.acceleration / e)
        j = np.min(station.robot.limits.jerk / e)
    v = speed * d / length
    return float(double_s(*(np.array([x]) for x in (d, v, a, j))).duration[0])


def test_short_fine_stopped_lins_are_jerk_limited(station: Station, tool: ir.Tool) -> None:
    moves = [_lin(station, tool, [0.0, 0.03 * ((k + 1) % 2), 0.0], linear=0.25) for k in range(10)]
    compiled = _resolved(station, tool, *moves)
    timed = time_program(compiled)
    assert timed.ok
    hand = [_by_hand(station, step, 0.03, 0.25) for step in compiled.steps[1:]]
    for step, expected in zip(timed.steps[1:], hand, strict=True):
        assert step.duration == pytest.approx(expected, rel=1e-2)
    accel_only = time_program(compiled, options=ACCEL_ONLY)
    ratio = sum(s.duration for s in accel_only.steps[1:]) / sum(hand)
    assert ratio == pytest.approx(0.644, abs=0.01)  # the "35% shorter"


def test_path_acceleration_limits_a_lin(station: Station, tool: ir.Tool) -> None:
    """$ACC.CP = 0.5 m/s² on a 100 mm LIN at 0.1 m/s: ``L / v + v / a`` (a trapezoid along the
    TCP path) without jerk; the jerk-limited law is longer, and both keep the TCP's
    acceleration along its path within 0.5 m/s²."""
    move = _lin(station, tool, [0.0, 0.1, 0.0], linear=0.1, linear_acceleration=0.5)
    compiled = _resolved(station, tool, move)
    plain = time_program(compiled, options=ACCEL_ONLY).steps[1].duration
    assert plain == pytest.approx(0.1 / 0.1 + 0.1 / 0.5, rel=5e-3)
    for options in (ACCEL_ONLY, TimingOptions()):
        step = time_program(compiled, options=options).steps[1]
        assert step.duration >= plain * (1 - 1e-9)
        assert _tcp_accel(station, tool, step) <= 0.5 * (1 + 5e-3)


def test_orientation_acceleration_limits_a_turn(station: Station, tool: ir.Tool) -> None:
    """A 60° turn of the tool about its x axis (the TCP stays put) at 30°/s with 45°/s² of
    orientation acceleration: ``θ / ω + ω / α``, and the sampled orientation speed changes by
    at most 45°/s² (without the limit: by several hundred)."""
    pose = station.robot.flange_poses(Q0) @ tool.pose
    turned = pose @ np.array(
        [[1, 0, 0, 0], [0, 0.5, -math.sqrt(0.75), 0], [0, math.sqrt(0.75), 0.5, 0], [0, 0, 0, 1]]
    )
    found = []
    for accel in (None, math.radians(45)):
        speed = ir.Speed(linear=1.0, angular=math.radians(30), angular_acceleration=accel)
        move = ir.LinearMove(target=ir.CartesianTarget(pose=turned), speed=speed, tool=tool)
        step = time_program(_resolved(station, tool, move), options=ACCEL_ONLY).steps[1]
        assert step.trajectory is not None
        t = np.linspace(0.0, step.duration, 4001)
        joints = step.trajectory.state(t)[0]
        tcp = station.robot.flange_poses(joints) @ tool.pose
        assert np.max(np.linalg.norm(tcp[:, :3, 3] - tcp[0, :3, 3], axis=-1)) < 1e-4
        turn = np.swapaxes(tcp[:-1, :3, :3], -1, -2) @ tcp[1:, :3, :3]
        rate = np.linalg.norm(rotation_log(turn), axis=-1) / np.diff(t)
        found.append((step.duration, float(np.max(np.abs(np.diff(rate)) / np.diff(t)[1:]))))
    (free, free_accel), (limited, limited_accel) = found
    assert limited > free
    assert free_accel > math.radians(300)
    assert limited_accel <= math.radians(45) * (1 + 5e-3)
    assert limited == pytest.approx(60 / 30 + 30 / 45, rel=5e-3)


def _tcp_accel(station: Station, tool: ir.Tool, step: Step) -> float:
    """Largest rate of change of the TCP's speed along its path, sampled densely."""
    assert step.trajectory is not None
    t = np.linspace(0.0, step.duration, 4001)
    q = step.trajectory.state(t)[0]
    tcp = (station.robot.flange_poses(q) @ tool.pose)[:, :3, 3]
    speed = np.linalg.norm(np.diff(tcp, axis=0), axis=-1) / np.diff(t)
    return float(np.max(np.abs(np.diff(speed)) / np.diff(t)[1:]))


@pytest.mark.parametrize("zone", [0.0, 0.005])
def test_jerk_limited_chains_hold_the_limits(station: Station, tool: ir.Tool, zone: float) -> None:
    """Two 30 mm LINs at 250 mm/s at a right angle (a stop, or a 5 mm blend): joint velocity,
    acceleration and the TCP speed within their limits on the sampled law; at the stops the
    joint jerk within its limits. (Through a blend the joint jerk has terms of the path's
    geometry, 3 q'' sd sdd + q''' sd^3, which the law does not bound: the blend curve's
    curvature jumps where it meets the lines.)"""
    out = _lin(station, tool, [0.0, 0.03, 0.0], linear=0.25)
    out = ir.LinearMove(target=out.target, speed=out.speed, tool=tool, zone=ir.Zone(zone))
    up = _lin(station, tool, [0.0, 0.03, 0.03], linear=0.25)
    timed = time_program(_resolved(station, tool, out, up))
    lim = station.robot.limits
    for step in timed.steps[1:]:
        assert step.trajectory is not None
        assert isinstance(step.trajectory.law, SmoothedTimeLaw)
        t = np.linspace(0.0, step.duration, 6001)
        q, qd, qdd = step.trajectory.state(t)
        assert np.max(np.abs(qd) / lim.velocity) <= 1 + 1e-3
        assert np.max(np.abs(qdd) / lim.acceleration) <= 1 + 5e-3
        tcp = (station.robot.flange_poses(q) @ tool.pose)[:, :3, 3]
        tcp_speed = np.linalg.norm(np.diff(tcp, axis=0), axis=-1) / np.diff(t)
        assert np.max(tcp_speed) <= 0.25 * (1 + 2e-3)
        if zone == 0.0:
            qddd = np.diff(qdd, axis=0) / np.diff(t)[:, None]
            assert np.max(np.abs(qddd) / lim.jerk) <= 1 + 2e-2
