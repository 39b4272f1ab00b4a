"""Timing against closed forms: jerk-limited PTP and constant-speed LIN."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from olp import ir
from olp.passes.resolve import resolve
from olp.passes.timing import path_duration, ptp_duration, time_program
from olp.station.loader import load_station
from olp.station.model import JointLimits, Station

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def station() -> Station:
    return load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def _double_s_time(distance: float, v: float, a: float, j: float) -> float:
    """Rest-to-rest time of a jerk-limited profile that reaches both ``a`` and ``v``."""
    assert v * j >= a * a, "profile must reach the acceleration limit"
    ramp = v / a + a / j
    assert distance >= v * ramp, "profile must reach the velocity limit"
    return distance / v + ramp


def test_single_axis_ptp_matches_the_double_s_closed_form(station: Station) -> None:
    robot = station.robot
    q0 = np.radians([-165, -90, 90, 0, 0, 0])
    q1 = np.radians([165, -90, 90, 0, 0, 0])
    v, a, j = robot.limits.velocity[0], robot.limits.acceleration[0], robot.limits.jerk[0]
    expected = _double_s_time(np.radians(330), v, a, j)
    assert ptp_duration(q0, q1, robot) == pytest.approx(expected, rel=5e-3)


def test_ptp_speed_scales_the_velocity_limit(station: Station) -> None:
    robot = station.robot
    q0 = np.radians([0, -90, 90, 0, 0, 0])
    q1 = q0 + np.radians([150, 0, 0, 0, 0, 0])
    v, a, j = robot.limits.velocity[0] * 0.3, robot.limits.acceleration[0], robot.limits.jerk[0]
    expected = _double_s_time(np.radians(150), v, a, j)
    assert ptp_duration(q0, q1, robot, velocity_scale=0.3) == pytest.approx(expected, rel=5e-3)


def test_slow_lin_takes_length_over_speed(station: Station) -> None:
    start = ir.JointMove(target=ir.JointTarget(joints=np.radians([10, -80, 95, 0, 30, 0])))
    pose = station.robot.flange_poses(np.radians([10, -80, 95, 0, 30, 0]))
    pose[:3, 3] += [0.0, 0.2, 0.0]
    lin = ir.LinearMove(target=ir.CartesianTarget(pose=pose), speed=ir.Speed(linear=0.02))
    compiled = time_program(resolve(ir.Program(name="t", instructions=[start, lin]), station))
    step = compiled.steps[1]
    assert step.path_length == pytest.approx(0.2, rel=1e-6)
    # 10 s at 20 mm/s; the acceleration ramps of a 20 mm/s move last milliseconds
    assert step.duration == pytest.approx(10.0, rel=5e-3)
    assert step.duration > 10.0


def test_lin_is_slower_when_joints_limit_it(station: Station) -> None:
    robot = station.robot
    slow = dataclasses.replace(
        robot,
        limits=JointLimits(
            lower=robot.limits.lower,
            upper=robot.limits.upper,
            velocity=robot.limits.velocity / 20,
            acceleration=robot.limits.acceleration,
            jerk=robot.limits.jerk,
        ),
    )
    q0 = np.radians([10, -80, 95, 0, 30, 0])
    path = q0 + np.linspace(0, 1, 50)[:, None] * np.radians([20, 0, 0, 0, 0, 0])
    fast_t = path_duration(path, robot, 0.3, 0.0, 2.0)
    slow_t = path_duration(path, slow, 0.3, 0.0, 2.0)
    # A1 alone moves 20° at 18°/s: at least 1.11 s, where the TCP limit alone allows 0.15 s
    assert fast_t >= 0.3 / 2.0
    assert slow_t >= np.radians(20) / slow.limits.velocity[0] > 5 * 0.3 / 2.0


def test_wait_counts_its_time(station: Station) -> None:
    program = ir.Program(name="t", instructions=[ir.Wait(seconds=1.5)])
    compiled = time_program(resolve(program, station))
    assert compiled.cycle_time == pytest.approx(1.5)
