"""A joint whose path tangent is within 1e-300 of zero (a wrist axis that stays on 0 while the
others move) limits nothing, and timing it overflows nowhere: pytest turns numpy's overflow
warnings into errors (pyproject.toml), so each of these failed with one before."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

import olp
from olp import ir
from olp.frontends.bundled import CsvOptions
from olp.passes.timing import reachability
from olp.passes.timing.geometry import JointSpline
from olp.passes.timing.jerk import path_jerk
from olp.passes.timing.problem import PathProblem, speed_bounds
from olp.station.loader import load_station
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]
ABB_CELL = REPO / "stations" / "abb_irb120_pick_cell.yaml"
KR6_CELL = REPO / "stations" / "kr6_milling_cell.yaml"
TINY = 1e-301
SLOPE = np.array([0.3, 0.2, -0.4, 0.0, 0.1, 0.0])


def _line(tiny: float) -> tuple[np.ndarray, np.ndarray]:
    """Path parameters (K,) and joints (K, 6) rad of a joint line on which joint 4 moves
    ``tiny`` rad per unit of the parameter."""
    s = np.linspace(0.0, 1.0, 40)
    q = np.radians([10.0, -80.0, 95.0, 0.0, 30.0, 0.0]) + np.outer(s, SLOPE)
    q[:, 3] = tiny * s
    return s, q


def test_speed_bounds_of_a_tiny_tangent_are_those_of_a_joint_at_rest() -> None:
    robot = load_station(KR6_CELL).robot
    bounds = []
    for tiny in (TINY, 0.0):
        s, q = _line(tiny)
        dq = np.broadcast_to(SLOPE, q.shape).copy()
        dq[:, 3] = tiny
        bounds.append(
            speed_bounds(robot, q, dq, np.eye(4), np.full(s.size, 0.25), np.full(s.size, np.inf))
        )
    assert np.array_equal(bounds[0], bounds[1])
    assert np.all(np.isfinite(bounds[0])) and np.all(bounds[0] > 0.0)


def test_path_jerk_of_a_tiny_tangent_is_that_of_a_joint_at_rest() -> None:
    robot = load_station(KR6_CELL).robot
    jerks = []
    for tiny in (1e-307, 0.0):  # a jerk limit over 1e-307 overflows
        s, q = _line(tiny)
        spline = CubicSpline(s, q)
        path = JointSpline((spline, spline.derivative(), spline.derivative(2)))
        problem = PathProblem(path, s, np.eye(4), np.full(s.size, 0.25), np.full(s.size, np.inf))
        jerks.append(path_jerk(problem, robot))
    assert jerks[0] == jerks[1] and np.isfinite(jerks[0])


def test_reachability_with_a_tiny_tangent_is_that_of_a_joint_at_rest() -> None:
    grid = np.linspace(0.0, 0.5, 60)
    speeds = []
    for tiny in (1e-310, 0.0):  # a stage row of 1e-310 over a rate of 1e-12: overflows
        dq = np.c_[np.ones(grid.size), np.full(grid.size, tiny)]
        ddq = np.c_[np.zeros(grid.size), np.full(grid.size, -tiny)]
        x_max = np.full(grid.size, 4.0)
        accel = np.array([2.0, 3.0])
        speeds.append(reachability.reachability_speeds(grid, dq, ddq, x_max, accel))
    assert np.array_equal(speeds[0], speeds[1])
    assert np.all(np.isfinite(speeds[0])) and np.max(speeds[0]) > 0.5


def _toolpath(station: Station, csv: Path, frame: str, xyz: np.ndarray) -> ir.Program:
    np.savetxt(csv, xyz, fmt="%.4f", delimiter=",", header="x,y,z", comments="")
    options = CsvOptions(frame=frame, orientation=(180.0, 0.0, 180.0), zone=1.0)
    return olp.parse(csv, station=station, options=options).program


def test_a_toolpath_with_the_wrist_on_zero_is_timed(tmp_path: Path) -> None:
    """Two toolpaths on the IRB 120 cell with the tool straight down (axis 4 stays within
    1e-15 rad of 0), the second with a path acceleration: its blended chain's spline has
    joint-4 tangents of ~1e-291 (tests/posts/test_abb_columns.py tilts the tool to avoid
    them)."""
    station = olp.load_station(ABB_CELL)
    t = np.linspace(0.0, 0.5 * np.pi, 50)
    xyz = np.c_[40 * np.cos(t), 40 * np.sin(t), 30 + np.linspace(0.0, 20.0, t.size)]
    first = _toolpath(station, tmp_path / "a.csv", "conveyor", xyz)
    other = _toolpath(station, tmp_path / "b.csv", "table", xyz + np.array([300.0, 50.0, 150.0]))
    (node,) = [n for n in other.instructions if isinstance(n, ir.LinearPath)]
    second = dataclasses.replace(node, acceleration=1.5)
    program = first.replace_instructions([*first.instructions, second])
    compiled = olp.compile(program, station)
    assert not [d for d in compiled.diagnostics if d.severity == "error"]
    wrist = np.array([s.joints[3] for s in compiled.steps if s.joints is not None])
    assert np.max(np.abs(wrist)) < 1e-12  # the pose this test is about
    durations = np.array([s.duration for s in compiled.steps])
    assert np.all(np.isfinite(durations)) and np.all(durations[1:] > 0.0)
