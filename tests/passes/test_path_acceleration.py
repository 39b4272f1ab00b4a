"""The controller's own path acceleration (a station's ``path_acceleration_m_s2``): it bounds
path moves whose program sets none, exactly as the same value set in the program would, and
leaves joint moves and programmed accelerations alone; a UR station cannot have one."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.errors import StationError
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
START = np.radians([10, -100, 95, 0, 65, 0])


def _with_path_acceleration(station: Station, value: float | None) -> Station:
    limits = dataclasses.replace(station.robot.limits, path_acceleration=value)
    return dataclasses.replace(station, robot=dataclasses.replace(station.robot, limits=limits))


def _line_program(station: Station, accel: float | None) -> ir.Program:
    pose = station.robot.flange_poses(START)
    target = pose.copy()
    target[:3, 3] += [0.3, 0.0, 0.0]
    speed = ir.Speed(linear=0.25, linear_acceleration=accel)
    return ir.Program(
        name="line",
        instructions=(
            ir.JointMove(target=ir.JointTarget(joints=START)),
            ir.LinearMove(target=ir.CartesianTarget(pose=target), speed=speed),
        ),
    )


def _line_time(station: Station, accel: float | None) -> float:
    compiled = olp.compile(_line_program(station, accel), station, collisions=None)
    assert compiled.ok
    return compiled.steps[1].duration


def test_the_station_default_times_like_the_programmed_value() -> None:
    plain = olp.load_station(CELL)
    limited = _with_path_acceleration(plain, 0.5)
    free = _line_time(plain, None)
    programmed = _line_time(plain, 0.5)
    defaulted = _line_time(limited, None)
    assert programmed > free * 1.05  # 0.5 m/s² binds on a 300 mm line at 250 mm/s
    assert defaulted == pytest.approx(programmed, rel=1e-9)
    # a programmed value wins over the controller's
    assert _line_time(limited, 2.0) == pytest.approx(_line_time(plain, 2.0), rel=1e-9)


def test_joint_moves_ignore_it() -> None:
    plain = olp.load_station(CELL)
    program = ir.Program(
        name="ptp",
        instructions=(ir.JointMove(target=ir.JointTarget(joints=START)),),
    )
    a = olp.compile(program, plain, collisions=None).cycle_time
    b = olp.compile(program, _with_path_acceleration(plain, 0.1), collisions=None).cycle_time
    assert a == b


def _station_text(tmp_path: Path, source: Path, value: str) -> Path:
    text = source.read_text()
    model = next(line for line in text.splitlines() if line.strip().startswith("model:"))
    path = tmp_path / source.name
    path.write_text(
        text.replace(model, f"{model}\n  limits:\n    path_acceleration_m_s2: {value}", 1)
    )
    return path


def test_the_station_file_sets_it(tmp_path: Path) -> None:
    station = olp.load_station(_station_text(tmp_path, CELL, "0.75"))
    assert station.robot.limits.path_acceleration == 0.75


@pytest.mark.parametrize(("value", "message"), [("-1", "m/s²"), ("fast", "number")])
def test_bad_values_are_located_errors(tmp_path: Path, value: str, message: str) -> None:
    with pytest.raises(StationError, match=message) as info:
        olp.load_station(_station_text(tmp_path, CELL, value))
    assert "path_acceleration_m_s2" in str(info.value)


def test_a_ur_station_cannot_have_one(tmp_path: Path) -> None:
    ur = REPO / "stations" / "ur5e_screw_cell.yaml"
    with pytest.raises(StationError, match="states the tool acceleration"):
        olp.load_station(_station_text(tmp_path, ur, "1.0"))
