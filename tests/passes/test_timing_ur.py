"""A UR program is timed with the ``a`` and ``v`` its script says: the ``movej`` leading-axis
trapezoid and the ``movel`` tool trapezoid (URScript manual), read back from the written
script and compared with the estimate (issue 13: the estimate used the station's limits, 53%
off on a 90° movej, 7% short on a 400 mm movel)."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.geometry import transl
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
READY = np.radians([0, -90, 90, -90, -90, 0])
_CALL = re.compile(r"(movej|movel)\(.*a=([0-9.]+), v=([0-9.]+), r=([0-9.]+)\)")


@pytest.fixture(scope="module")
def station() -> Station:
    return olp.load_station(REPO / "stations" / "ur5e_screw_cell.yaml")


def _trapezoid(distance: float, a: float, v: float) -> float:
    """URScript's trapezoid: ``D / v + v / a``, or the triangle ``2 sqrt(D / a)``."""
    return distance / v + v / a if distance * a >= v * v else 2.0 * math.sqrt(distance / a)


def _built(
    station: Station, *moves: ir.Instruction
) -> tuple[list[float], list[tuple[float, float]]]:
    """Durations of the moves after READY and the (a, v) of their script lines."""
    start = ir.JointMove(target=ir.JointTarget(joints=READY))
    result = olp.build(station, ir.Program(name="t", instructions=(start, *moves)), post="ur")
    assert result.ok, [d.format() for d in result.diagnostics]
    (script,) = result.files.values()
    calls = [(float(m[2]), float(m[3])) for m in _CALL.finditer(script)]
    durations = [step.duration for step in result.compiled.steps[1:]]
    return durations, calls[1:]


def test_movej_is_the_written_trapezoid(station: Station) -> None:
    """A 90° movej of the base at 100 %: a=1.4 rad/s², v=π rad/s (180°/s) -> a triangle,
    2 sqrt(π/2 / 1.4) = 2.12 s (the station's 450°/s² gave 1.0 s)."""
    target = ir.JointTarget(joints=READY + np.radians([90, 0, 0, 0, 0, 0]))
    (duration,), ((a, v),) = _built(station, ir.JointMove(target=target))
    assert (a, v) == (1.4, 3.14159)
    assert duration == pytest.approx(_trapezoid(math.pi / 2, a, v), rel=5e-3)
    assert duration == pytest.approx(2.118, abs=1e-3)


def test_a_slower_movej_is_the_written_trapezoid(station: Station) -> None:
    target = ir.JointTarget(joints=READY + np.radians([20, -30, 45, 0, 10, 0]))
    speed = ir.Speed(joint=0.25, joint_acceleration=0.5)
    (duration,), ((a, v),) = _built(station, ir.JointMove(target=target, speed=speed))
    assert (a, v) == (0.7, 0.7854)
    assert duration == pytest.approx(_trapezoid(math.radians(45), a, v), rel=5e-3)


@pytest.mark.parametrize("accel", [None, 0.5])
def test_movel_is_the_written_tool_trapezoid(station: Station, accel: float | None) -> None:
    """A 200 mm movel at 250 mm/s with the default a=1.2 m/s² (or a programmed 0.5 m/s²)."""
    flange = station.robot.flange_poses(READY)
    target = ir.CartesianTarget(pose=transl(0.0, 0.2, 0.0) @ flange)
    speed = ir.Speed(linear=0.25, linear_acceleration=accel)
    (duration,), ((a, v),) = _built(station, ir.LinearMove(target=target, speed=speed))
    assert (a, v) == (1.2 if accel is None else accel, 0.25)
    assert duration == pytest.approx(_trapezoid(0.2, a, v), rel=5e-3)


def test_movel_law_holds_its_trapezoid(station: Station) -> None:
    """The sampled law of a movel: the TCP at most at v and ends where the move ends."""
    flange = station.robot.flange_poses(READY)
    target = ir.CartesianTarget(pose=transl(0.0, 0.2, 0.0) @ flange)
    start = ir.JointMove(target=ir.JointTarget(joints=READY))
    move = ir.LinearMove(target=target, speed=ir.Speed(linear=0.25))
    compiled = olp.compile(ir.Program(name="t", instructions=(start, move)), station)
    step = compiled.steps[1]
    assert step.trajectory is not None and step.path is not None
    t = np.linspace(0.0, step.duration, 2001)
    q = step.trajectory.state(t)[0]
    tcp = station.robot.flange_poses(q)[:, :3, 3]
    speed = np.linalg.norm(np.diff(tcp, axis=0), axis=-1) / np.diff(t)
    assert np.max(speed) <= 0.25 * (1 + 1e-2)
    assert np.allclose(q[-1], step.path[-1], atol=1e-9)
