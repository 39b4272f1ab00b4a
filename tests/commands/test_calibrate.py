"""``olp time --calibrate``: a round trip (a trajectory generated with known limits, written as
olp's trajectory CSV, fitted: the limits recovered within 2% and the recorded cycle time
reproduced within 1%), the same with path moves (the controller's path acceleration recovered
within 2%), the station override it writes loads, and bad recordings are errors."""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.commands import time as time_command
from olp.errors import UsageError
from olp.passes.timing.calibrate import fit_limits, read_recording
from olp.station.model import JointLimits, Station
from olp.trajectory import csv_text, sample_program

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
HOME = np.radians([0, -90, 90, 0, 45, 0])
VELOCITY = np.radians([60, 50, 70, 80, 90, 120])
ACCELERATION = 2.5 * VELOCITY
JERK = 10.0 * ACCELERATION


@pytest.fixture(scope="module")
def station() -> Station:
    """The KR 6 cell with known, slower limits (every axis cruises on a 70° move)."""
    base = olp.load_station(CELL)
    lim = base.robot.limits
    limits = JointLimits(lim.lower, lim.upper, VELOCITY, ACCELERATION, JERK)
    return dataclasses.replace(base, robot=dataclasses.replace(base.robot, limits=limits))


@pytest.fixture(scope="module")
def recording(station: Station) -> str:
    """Each axis alone 70° out and back (A3 down: up is beyond its range), then two moves of
    all axes: olp's trajectory CSV."""
    targets = [HOME]
    for axis in range(6):
        out = HOME.copy()
        out[axis] += np.radians(-70 if axis == 2 else 70)
        targets += [out, HOME]
    targets += [HOME + np.radians([20, -10, 15, 30, -20, 40]), HOME]
    moves = [ir.JointMove(target=ir.JointTarget(joints=q)) for q in targets]
    compiled = olp.compile(ir.Program(name="rec", instructions=moves), station)
    assert compiled.ok
    return csv_text(sample_program(compiled, dt=0.004)), compiled.cycle_time


def test_round_trip_recovers_the_limits(station: Station, recording: tuple[str, float]) -> None:
    text, cycle = recording
    fitted = fit_limits(read_recording(text, "rec.csv", 6), station)
    assert fitted.velocity == pytest.approx(VELOCITY, rel=2e-2)
    assert fitted.acceleration == pytest.approx(ACCELERATION, rel=2e-2)
    assert fitted.jerk == pytest.approx(JERK, rel=2e-2)
    assert fitted.moves == 15  # the first from the station's home
    assert abs(fitted.residual) < 1e-2
    assert fitted.recorded == pytest.approx(cycle, rel=1e-2)
    assert fitted.path_acceleration is None and fitted.path_moves == 0


PATH_ACCELERATION = 1.2  # m/s², below what the joints allow on these lines


@pytest.fixture(scope="module")
def path_recording(station: Station) -> tuple[str, float]:
    """The joint moves of :func:`recording`, then three fine-stopped 250-300 mm LINs at
    250 mm/s (of the flange) on a station whose controller path acceleration is 1.2 m/s²."""
    limits = dataclasses.replace(station.robot.limits, path_acceleration=PATH_ACCELERATION)
    cell = dataclasses.replace(station, robot=dataclasses.replace(station.robot, limits=limits))
    targets = [HOME]
    for axis in range(6):
        out = HOME.copy()
        out[axis] += np.radians(-70 if axis == 2 else 70)
        targets += [out, HOME]
    start = HOME + np.radians([10, -10, 5, 0, 20, 0])
    moves: list[ir.Instruction] = [ir.JointMove(target=ir.JointTarget(joints=q)) for q in targets]
    moves.append(ir.JointMove(target=ir.JointTarget(joints=start)))
    flange = cell.robot.flange_poses(start)
    for offset in ([0.3, 0, 0], [0.3, 0, -0.25], [0, 0, 0]):
        pose = flange.copy()
        pose[:3, 3] += offset
        target = ir.CartesianTarget(pose=pose)
        moves.append(ir.LinearMove(target=target, speed=ir.Speed(linear=0.25)))
    compiled = olp.compile(ir.Program(name="rec", instructions=tuple(moves)), cell)
    assert compiled.ok
    return csv_text(sample_program(compiled, dt=0.004)), compiled.cycle_time


def test_round_trip_recovers_the_path_acceleration(
    station: Station, path_recording: tuple[str, float]
) -> None:
    text, cycle = path_recording
    fitted = fit_limits(read_recording(text, "rec.csv", 6), station)
    assert fitted.path_moves == 3
    assert fitted.path_acceleration == pytest.approx(PATH_ACCELERATION, rel=2e-2)
    assert fitted.velocity == pytest.approx(VELOCITY, rel=2e-2)
    assert fitted.acceleration == pytest.approx(ACCELERATION, rel=2e-2)
    assert abs(fitted.residual) < 1e-2
    assert fitted.recorded == pytest.approx(cycle, rel=1e-2)


def test_a_wrong_path_acceleration_shows_in_the_residual(
    station: Station, path_recording: tuple[str, float]
) -> None:
    """The residual is olp's own timing with the fitted values: fitted from a recording whose
    lines the controller ran at 1.2 m/s², a station claiming 0.3 m/s² is far off."""
    from olp.passes.timing import calibrate

    recording = read_recording(path_recording[0], "rec.csv", 6)
    honest = fit_limits(recording, station)
    original = calibrate._path_line

    def slower(*args: object) -> tuple[float, float] | None:
        found = original(*args)  # type: ignore[arg-type]
        return None if found is None else (found[0], PATH_ACCELERATION / 4)

    calibrate._path_line = slower  # type: ignore[assignment]
    try:
        wrong = fit_limits(recording, station)
    finally:
        calibrate._path_line = original
    assert abs(honest.residual) < 1e-2 and wrong.residual > 5e-2


def _olp_time(*argv: str | Path) -> int:
    parser = argparse.ArgumentParser(prog="olp time")
    time_command.add_arguments(parser)
    return time_command.run(parser.parse_args([str(a) for a in argv]))


def test_the_override_loads_and_reproduces_the_recording(
    station: Station,
    recording: tuple[str, float],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    log = tmp_path / "rec.csv"
    log.write_text(recording[0])
    override = tmp_path / "override.yaml"
    assert _olp_time(CELL, "--calibrate", log, "--output", override) == 0
    assert "residual" in capsys.readouterr().out
    text = override.read_text()
    calibrated = tmp_path / "calibrated.yaml"
    cell = CELL.read_text().replace(
        "  model: kuka/kr6_r900_sixx\n",
        "  model: kuka/kr6_r900_sixx\n" + text.split("robot:\n", 1)[1],
    )
    calibrated.write_text(cell)
    loaded = olp.load_station(calibrated)
    assert loaded.robot.limits.velocity == pytest.approx(VELOCITY, rel=2e-2)
    assert loaded.robot.limits.jerk == pytest.approx(JERK, rel=2e-2)
    assert loaded.robot.limits.path_acceleration is None
    assert "no path acceleration fitted" in text


def test_the_path_acceleration_override_loads(
    path_recording: tuple[str, float], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log = tmp_path / "rec.csv"
    log.write_text(path_recording[0])
    assert _olp_time(CELL, "--calibrate", log) == 0
    out = capsys.readouterr().out
    assert "path acceleration 1.2" in out and "from 3 path move(s)" in out
    override = out.split("robot:\n", 1)[1]
    calibrated = tmp_path / "calibrated.yaml"
    cell = CELL.read_text().replace(
        "  model: kuka/kr6_r900_sixx\n", "  model: kuka/kr6_r900_sixx\n" + override
    )
    calibrated.write_text(cell)
    loaded = olp.load_station(calibrated)
    assert loaded.robot.limits.path_acceleration == pytest.approx(PATH_ACCELERATION, rel=2e-2)


def test_an_unknown_calibrate_tool_is_a_usage_error(
    recording: tuple[str, float], tmp_path: Path
) -> None:
    log = tmp_path / "rec.csv"
    log.write_text(recording[0])
    with pytest.raises(UsageError, match="no tool 'nozzle'"):
        _olp_time(CELL, "--calibrate", log, "--calibrate-tool", "nozzle")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("a,b\n1,2\n", "expected the columns"),
        ("time_s,j1_deg,j2_deg,j3_deg,j4_deg,j5_deg,j6_deg\n0,1,2,3,4,5,6\n", "at least 16"),
        (
            "time_s,j1_deg,j2_deg,j3_deg,j4_deg,j5_deg,j6_deg\n"
            + "".join(f"{t},1,2,3,4,5,x\n" for t in range(20)),
            "rec.csv:2: expected numbers",
        ),
        (
            "time_s,j1_deg,j2_deg,j3_deg,j4_deg,j5_deg,j6_deg\n"
            + "".join(f"{t % 10},1,2,3,4,5,6\n" for t in range(20)),
            "rec.csv:12: times must increase",
        ),
    ],
)
def test_bad_recordings_are_usage_errors(text: str, message: str) -> None:
    with pytest.raises(UsageError, match=message):
        read_recording(text, "rec.csv", 6)


def test_rtde_columns_in_radians(station: Station) -> None:
    rows = ["timestamp actual_q_0 actual_q_1 actual_q_2 actual_q_3 actual_q_4 actual_q_5"]
    rows += [f"{0.002 * k} {0.01 * k} 0 0 0 0 0" for k in range(20)]
    recording = read_recording("\n".join(rows), "rtde.csv", 6)
    assert recording.q[5, 0] == pytest.approx(0.05) and recording.t[5] == pytest.approx(0.01)
