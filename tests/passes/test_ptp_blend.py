"""Blended joint moves (PTP approximation, :mod:`olp.passes.timing.ptp_blend`) against Ruckig:
never slower than the best Ruckig trajectory *through* the corner (searched over the
pass-through speed), never faster than the direct move, the two stops without a zone."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from ruckig import InputParameter, Ruckig, Synchronization, Trajectory

from olp import ir
from olp.compiled import CompiledProgram
from olp.passes.resolve import resolve
from olp.passes.timing import ptp_duration, time_program
from olp.station.loader import load_station
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
Q0 = np.radians([10, -80, 95, 0, 30, 0])
CORNER = Q0 + np.radians([40, 10, -10, 0, 0, 0])
END = CORNER + np.radians([0, 0, 0, 30, 20, 50])


@pytest.fixture(scope="module")
def station() -> Station:
    return load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def _timed(station: Station, zone: float, *targets: np.ndarray) -> CompiledProgram:
    tool = station.tools["spindle"]
    start = ir.JointMove(target=ir.JointTarget(joints=Q0), tool=tool)
    moves = [
        ir.JointMove(target=ir.JointTarget(joints=q), tool=tool, zone=ir.Zone(zone))
        for q in targets
    ]
    moves[-1] = dataclasses.replace(moves[-1], zone=ir.FINE)
    compiled = time_program(resolve(ir.Program(name="t", instructions=[start, *moves]), station))
    assert compiled.ok, [d.message for d in compiled.diagnostics]
    return compiled


def _segment(station: Station, q0, v0, q1, v1) -> float:  # type: ignore[no-untyped-def]
    dof = q0.size
    inp = InputParameter(dof)
    inp.current_position, inp.current_velocity = q0.tolist(), v0.tolist()
    inp.current_acceleration = [0.0] * dof
    inp.target_position, inp.target_velocity = q1.tolist(), v1.tolist()
    inp.target_acceleration = [0.0] * dof
    lim = station.robot.limits
    inp.max_velocity, inp.max_acceleration = lim.velocity.tolist(), lim.acceleration.tolist()
    inp.max_jerk = lim.jerk.tolist()
    inp.synchronization = Synchronization.Time
    trajectory = Trajectory(dof)
    Ruckig(dof).calculate(inp, trajectory)
    return float(trajectory.duration)


def _through_corner(station: Station) -> float:
    """The fastest pair of Ruckig moves meeting at the corner, the pass-through velocity along
    the bisector of the two joint directions, its size searched on a grid."""
    u1 = (CORNER - Q0) / np.linalg.norm(CORNER - Q0)
    u2 = (END - CORNER) / np.linalg.norm(END - CORNER)
    direction = (u1 + u2) / np.linalg.norm(u1 + u2)
    most = float(np.min(station.robot.limits.velocity / np.maximum(np.abs(direction), 1e-12)))
    rest = np.zeros(6)
    times = [
        _segment(station, Q0, rest, CORNER, speed * direction)
        + _segment(station, CORNER, speed * direction, END, rest)
        for speed in np.linspace(0.0, most, 41)
    ]
    return min(times)


def test_blended_joint_moves_against_ruckig(station: Station) -> None:
    stops = _timed(station, 0.0, CORNER, END)
    blended = _timed(station, 0.2, CORNER, END)
    moving = sum(s.duration for s in blended.steps[1:])
    assert moving < sum(s.duration for s in stops.steps[1:]) * 0.95
    assert moving >= ptp_duration(Q0, END, station.robot) * (1 - 1e-9)
    assert moving <= _through_corner(station) * 1.02
    assert not [d for d in blended.diagnostics if d.kind == "zone_stop"]


def test_the_blend_grows_with_the_zone(station: Station) -> None:
    """0 mm: the two stops exactly; the time falls as the zone grows."""
    stops = _timed(station, 0.0, CORNER, END).cycle_time
    cycle = [_timed(station, zone, CORNER, END).cycle_time for zone in (0.0, 0.02, 0.1, 0.3)]
    assert cycle[0] == pytest.approx(stops, rel=1e-12)
    assert cycle[0] > cycle[1] > cycle[2] > cycle[3]


def test_the_blended_trajectory_is_continuous(station: Station) -> None:
    """The second move starts in the state the first one ends in (position and velocity)."""
    blended = _timed(station, 0.1, CORNER, END)
    first, second = blended.steps[1], blended.steps[2]
    assert first.trajectory is not None and second.trajectory is not None
    end = [x[0] for x in first.trajectory.state(np.array([first.duration]))]
    start = [x[0] for x in second.trajectory.state(np.array([0.0]))]
    assert np.allclose(end[0], start[0], atol=1e-9) and np.allclose(end[1], start[1], atol=1e-9)
    assert np.linalg.norm(end[1]) > 0.1  # it does not stop


def test_a_zone_before_a_path_move_is_a_stop_with_a_note(station: Station) -> None:
    tool = station.tools["spindle"]
    pose = station.robot.flange_poses(CORNER) @ tool.pose
    pose[:3, 3] += [0.0, 0.02, 0.0]
    start = ir.JointMove(target=ir.JointTarget(joints=Q0), tool=tool)
    joint = ir.JointMove(target=ir.JointTarget(joints=CORNER), tool=tool, zone=ir.Zone(0.05))
    line = ir.LinearMove(target=ir.CartesianTarget(pose=pose), tool=tool)
    program = ir.Program(name="t", instructions=[start, joint, line])
    timed = time_program(resolve(program, station))
    notes = [(d.severity, d.index) for d in timed.diagnostics if d.kind == "zone_stop"]
    assert notes == [("info", 1)]
