"""The ``olp time`` summary says once, in plain words, what the estimate includes and leaves
out, naming only the kinds of motion the program has."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import olp
from olp import ir
from olp.report import estimate_scope, timing_summary

REPO = Path(__file__).resolve().parents[2]


def _compiled(cell: str, *moves: ir.Instruction) -> olp.CompiledProgram:
    station = olp.load_station(REPO / "stations" / cell)
    return olp.compile(ir.Program(name="t", instructions=moves), station)


def test_a_kuka_program_with_a_stop_in_place_of_a_zone() -> None:
    station = olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")
    q = np.radians([0, -90, 90, 0, 45, 0])
    pose = station.robot.flange_poses(q)
    pose[:3, 3] += [0.0, 0.0, -0.02]
    joint = ir.JointMove(target=ir.JointTarget(joints=q), zone=ir.Zone(0.01))
    line = ir.LinearMove(
        target=ir.CartesianTarget(pose=pose), speed=ir.Speed(linear=0.1, linear_acceleration=1.0)
    )
    compiled = olp.compile(ir.Program(name="t", instructions=(joint, line)), station)
    includes, excludes = estimate_scope(compiled)
    assert "blended ones cut their corners" in includes
    assert "programmed TCP speed, path accelerations" in includes
    assert "servo lag" in excludes and "1 zone that olp cannot blend" in excludes
    assert "upper bound" in excludes
    text = timing_summary(compiled)
    assert text.count("includes") == 1 and text.count("excludes") == 1


def test_a_ur_program_names_the_script_trapezoids() -> None:
    ready = np.radians([0, -90, 90, -90, -90, 0])
    compiled = _compiled("ur5e_screw_cell.yaml", ir.JointMove(target=ir.JointTarget(joints=ready)))
    includes, excludes = estimate_scope(compiled)
    assert includes.startswith("Joint moves as the movej trapezoid of the a and v")
    assert "linear" not in includes and "upper bound" not in excludes


def test_the_controllers_path_acceleration_is_named_where_it_applies() -> None:
    import dataclasses

    station = olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")
    q = np.radians([0, -90, 90, 0, 45, 0])
    pose = station.robot.flange_poses(q)
    pose[:3, 3] += [0.0, 0.0, -0.02]
    moves = (
        ir.JointMove(target=ir.JointTarget(joints=q)),
        ir.LinearMove(target=ir.CartesianTarget(pose=pose), speed=ir.Speed(linear=0.1)),
    )
    program = ir.Program(name="t", instructions=moves)
    includes, excludes = estimate_scope(olp.compile(program, station))
    assert excludes.count("controller's own path acceleration where the program sets none") == 1
    assert "path acceleration" not in includes
    limits = dataclasses.replace(station.robot.limits, path_acceleration=0.5)
    calibrated = dataclasses.replace(
        station, robot=dataclasses.replace(station.robot, limits=limits)
    )
    includes, excludes = estimate_scope(olp.compile(program, calibrated))
    assert "the controller's path acceleration of 0.5 m/s²" in includes
    assert "path acceleration" not in excludes
