"""Timing: an estimated duration for every instruction, from the station's joint limits.

Model (first release; each point documented so an estimate can be explained):

* **Joint moves**: Ruckig, state to state, all axes synchronised, jerk-limited. Limits are the
  station's velocity x ``speed.joint``, acceleration x ``speed.joint_acceleration``, and jerk.
  olp never asks Ruckig for intermediate waypoints (the free Ruckig would compute them remotely).
* **Linear moves**: TOPPRA along the sampled joint path (a cubic spline through the resolve
  pass's samples), under joint velocity and acceleration limits plus the programmed TCP speed.
  The path parameter is the fraction of the move, so the TCP speed limit is the bound
  ``ds/dt <= v / L`` (L the TCP travel) and, where an orientation speed is given,
  ``ds/dt <= w / angle``.
* **Zones**: every motion is timed rest to rest (a fine stop at each end). Blending would make the
  program faster, so with zones this estimate is an upper bound.
* **Other instructions**: ``Wait`` takes its time; outputs, inputs, calls and comments take
  :data:`DEFAULT_TIMES` seconds (inputs are assumed already set).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import numpy as np
import toppra
import toppra.algorithm as algo
import toppra.constraint as constraint
from numpy.typing import NDArray
from ruckig import InputParameter, Result, Ruckig, Trajectory

from olp.geometry import pose_distance
from olp.ir import CircularMove, JointMove, LinearMove, Wait
from olp.passes.resolve import CompiledProgram, Step
from olp.station.model import Robot

FloatArray = NDArray[np.float64]

DEFAULT_TIMES: Mapping[str, float] = {
    "set_output": 0.0,
    "wait_input": 0.0,
    "call": 0.0,
    "comment": 0.0,
}
"""Seconds charged for non-motion instructions (override through :func:`time_program`)."""


def time_program(
    compiled: CompiledProgram, other_times: Mapping[str, float] | None = None
) -> CompiledProgram:
    """A copy of ``compiled`` whose steps carry ``duration`` (s) and ``path_length`` (m)."""
    times = {**DEFAULT_TIMES, **(other_times or {})}
    robot = compiled.station.robot
    steps = [_time_step(step, robot, times) for step in compiled.steps]
    return dataclasses.replace(compiled, steps=tuple(steps))


def _time_step(step: Step, robot: Robot, times: Mapping[str, float]) -> Step:
    ins = step.instruction
    if isinstance(ins, Wait):
        return dataclasses.replace(step, duration=ins.seconds)
    if not isinstance(ins, JointMove | LinearMove | CircularMove):
        return dataclasses.replace(step, duration=float(times.get(ins.kind, 0.0)))
    if step.path is None or step.tool is None or step.tool.pose is None:
        return step
    tcp = robot.flange_poses(step.path) @ step.tool.pose
    steps_m, steps_rad = pose_distance(tcp[:-1], tcp[1:])
    length = float(np.sum(steps_m))
    if isinstance(ins, JointMove):
        duration = ptp_duration(
            step.path[0], step.path[-1], robot, ins.speed.joint, ins.speed.joint_acceleration
        )
    else:
        duration = path_duration(
            step.path, robot, length, float(np.sum(steps_rad)), ins.speed.linear, ins.speed.angular
        )
    return dataclasses.replace(step, duration=duration, path_length=length)


def ptp_duration(
    q0: FloatArray,
    q1: FloatArray,
    robot: Robot,
    velocity_scale: float = 1.0,
    accel_scale: float = 1.0,
) -> float:
    """Rest-to-rest synchronised jerk-limited time (s) from ``q0`` to ``q1`` (rad) with Ruckig."""
    if np.allclose(q0, q1, atol=1e-12):
        return 0.0
    dof = q0.size
    inp = InputParameter(dof)
    inp.current_position = q0.tolist()
    inp.target_position = q1.tolist()
    inp.current_velocity = inp.current_acceleration = [0.0] * dof
    inp.target_velocity = inp.target_acceleration = [0.0] * dof
    inp.max_velocity = (robot.limits.velocity * velocity_scale).tolist()
    inp.max_acceleration = (robot.limits.acceleration * accel_scale).tolist()
    inp.max_jerk = robot.limits.jerk.tolist()
    traj = Trajectory(dof)
    result = Ruckig(dof).calculate(inp, traj)
    if result not in (Result.Working, Result.Finished):
        raise RuntimeError(f"Ruckig failed to time a joint move: {result}")
    return float(traj.duration)


def path_duration(
    path: FloatArray,
    robot: Robot,
    length: float,
    angle: float,
    linear_speed: float,
    angular_speed: float | None = None,
    grid: int | None = None,
) -> float:
    """Time-optimal duration (s) along a sampled joint path (S, 6) with TOPPRA.

    ``length`` (m) and ``angle`` (rad) are the TCP travel; the TCP may not exceed
    ``linear_speed`` (m/s) or ``angular_speed`` (rad/s, if given).
    """
    sd_max = np.inf
    if length > 1e-9:
        sd_max = min(sd_max, linear_speed / length)
    if angular_speed is not None and angle > 1e-9:
        sd_max = min(sd_max, angular_speed / angle)
    if not np.isfinite(sd_max) and np.allclose(path[0], path[-1], atol=1e-12):
        return 0.0
    ss = np.linspace(0.0, 1.0, path.shape[0])
    spline = toppra.SplineInterpolator(ss, path)
    gridpoints = _gridpoints(grid or max(2 * path.shape[0], 101))
    limits: list[object] = [
        constraint.JointVelocityConstraint(robot.limits.velocity),
        constraint.JointAccelerationConstraint(robot.limits.acceleration),
    ]
    if np.isfinite(sd_max):
        limits.append(PathSpeedConstraint(path.shape[1], sd_max))
    problem = algo.TOPPRA(
        limits, spline, gridpoints=gridpoints, parametrizer="ParametrizeConstAccel"
    )
    trajectory = problem.compute_trajectory(0.0, 0.0)
    if trajectory is None:
        raise RuntimeError("TOPPRA found no feasible time parameterisation for a path move")
    return float(trajectory.duration)


def _gridpoints(count: int) -> FloatArray:
    """A uniform grid on [0, 1] refined geometrically towards both ends.

    TOPPRA holds the path acceleration constant between gridpoints, so a start or stop ramp takes
    at least one grid interval: on a uniform grid of a slow 200 mm move that alone added 0.2 s
    (2%). Intervals shrinking to 1e-7 of the move at the ends make the ramps as short as the
    limits allow.
    """
    uniform = np.linspace(0.0, 1.0, count)
    ends = np.logspace(-7, np.log10(1.0 / count), 24)
    return np.unique(np.concatenate([uniform, ends, 1.0 - ends]))


class PathSpeedConstraint(constraint.LinearConstraint):
    """TOPPRA constraint ``ds/dt <= sd_max`` on the path parameter (the TCP speed limit).

    With the path parameter proportional to TCP travel, the programmed TCP speed ``v`` over a
    travel ``L`` is exactly ``ds/dt <= v / L``: a bound on TOPPRA's state ``x = (ds/dt)^2``.
    """

    def __init__(self, dof: int, sd_max: float) -> None:
        super().__init__()
        self.dof = dof
        self.sd_max = float(sd_max)
        self._format_string = f"    Path speed limit: {self.sd_max}\n"

    def compute_constraint_params(self, path: object, gridpoints: FloatArray) -> tuple[object, ...]:
        xbound = np.zeros((len(gridpoints), 2))
        xbound[:, 1] = self.sd_max**2
        return None, None, None, None, None, None, xbound
