"""Arc timing against the closed form of a constant-speed arc, and blends into and out of arcs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from olp import ir
from olp.geometry import transl
from olp.passes.resolve import resolve
from olp.passes.timing import time_program
from olp.passes.timing.arcs import constant_speed_time, time_arc
from olp.passes.timing.tcp import tcp_positions
from olp.station.loader import load_station
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
TOOL = ir.Tool(name="rod", pose=transl(0, 0, 0.25))
DOWN = np.radians([0, -50, 110, 0, 110, 0])
R = -0.06


@pytest.fixture(scope="module")
def station() -> Station:
    return load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def _at(station: Station, x: float, y: float) -> ir.CartesianTarget:
    start = station.robot.flange_poses(DOWN) @ TOOL.pose
    return ir.CartesianTarget(pose=transl(x, y, 0.0) @ start)


def _program(station: Station, speed: float, zone: float = 0.0) -> ir.Program:
    fields = {"tool": TOOL, "speed": ir.Speed(linear=speed)}
    return ir.Program(
        name="t",
        instructions=(
            ir.JointMove(target=ir.JointTarget(joints=DOWN), tool=TOOL),
            ir.LinearMove(target=_at(station, 0.0, R), zone=ir.Zone(zone), **fields),
            ir.CircularMove(
                target=_at(station, 2 * R, R),
                via=_at(station, R, 2 * R),
                zone=ir.Zone(zone),
                **fields,
            ),
            ir.LinearMove(target=_at(station, 2 * R, 0.0), **fields),
        ),
    )


def test_a_slow_arc_takes_its_length_over_its_speed(station: Station) -> None:
    compiled = time_program(resolve(_program(station, 0.02), station))
    assert compiled.ok
    arc = compiled.steps[2]
    length = np.pi * abs(R)
    assert arc.path_length == pytest.approx(length, rel=1e-4)
    # the ramps at 20 mm/s are milliseconds: within 0.5% of length / speed (and never faster)
    assert length / 0.02 <= arc.duration <= 1.005 * length / 0.02


def test_arc_law_against_the_trapezoid(station: Station) -> None:
    compiled = resolve(_program(station, 0.25), station)
    path = compiled.steps[2].path
    assert path is not None
    law = time_arc(path, station.robot, TOOL.pose, 0.25)  # type: ignore[arg-type]
    length = np.pi * abs(R)
    # the TCP cruises at 0.25 m/s: the time lies between the cruise alone and a trapezoid with
    # the slowest ramp the joint limits of this arm allow at that speed (1 m/s²)
    assert length / 0.25 < law.duration < constant_speed_time(length, 0.25, 1.0)
    t = np.linspace(0.0, law.duration, 2001)
    q, _, _ = law.state(t)
    tcp = tcp_positions(station.robot, q, TOOL.pose)  # type: ignore[arg-type]
    speeds = np.linalg.norm(np.diff(tcp, axis=0), axis=1) / np.diff(t)
    assert np.max(speeds) <= 0.25 * 1.001
    assert np.median(speeds) == pytest.approx(0.25, rel=1e-3)


def test_blends_into_and_out_of_an_arc(station: Station) -> None:
    stopped = time_program(resolve(_program(station, 0.1), station))
    blended = time_program(resolve(_program(station, 0.1, zone=0.01), station))
    assert stopped.ok and blended.ok
    assert not [d for d in blended.diagnostics if d.kind == "zone_stop"]
    # one chain: the line, the arc and the line share one time law
    laws = {id(s.trajectory.law) for s in blended.steps[1:] if s.trajectory is not None}
    assert len(laws) == 1
    assert blended.cycle_time < stopped.cycle_time
