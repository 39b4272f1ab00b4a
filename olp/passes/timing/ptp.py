"""Joint moves (PTP): Ruckig, state to state, jerk-limited, phase-synchronised (see the package
docstring)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from ruckig import InputParameter, Result, Ruckig, RuckigError, Synchronization, Trajectory

from olp.passes.timing.lines import trapezoid
from olp.passes.timing.plan import TimingError
from olp.station.model import Robot
from olp.trajectory import JerkProfile

FloatArray = NDArray[np.float64]


def ptp_profile(
    q0: FloatArray,
    q1: FloatArray,
    robot: Robot,
    velocity_scale: float = 1.0,
    accel_scale: float = 1.0,
) -> JerkProfile:
    """The rest-to-rest, phase-synchronised, jerk-limited joint move from ``q0`` to ``q1``
    (both (dof,) rad) with Ruckig, state to state (no intermediate waypoints).

    Limits: the robot's velocity x ``velocity_scale``, acceleration x ``accel_scale``, jerk.
    """
    dof = q0.size
    if np.max(np.abs(q1 - q0)) <= 1e-12:
        return JerkProfile.at_rest(q1)
    _check_ptp_duration(q0, q1, robot, velocity_scale, accel_scale)
    inp = InputParameter(dof)
    inp.current_position = q0.tolist()
    inp.target_position = q1.tolist()
    inp.current_velocity = inp.current_acceleration = [0.0] * dof
    inp.target_velocity = inp.target_acceleration = [0.0] * dof
    inp.max_velocity = (robot.limits.velocity * velocity_scale).tolist()
    inp.max_acceleration = (robot.limits.acceleration * accel_scale).tolist()
    inp.max_jerk = robot.limits.jerk.tolist()
    # Phase synchronisation keeps the move on the straight joint-space line that the resolve
    # pass sampled; for rest-to-rest moves it costs no time against time synchronisation.
    inp.synchronization = Synchronization.Phase
    trajectory = Trajectory(dof)
    try:
        result = Ruckig(dof).calculate(inp, trajectory)
    except (RuckigError, ValueError) as exc:
        # Ruckig raises on inputs it rejects, and its binding raises ValueError for result
        # codes it has no name for (-101: the duration is beyond its numerical range).
        first_line = next((line for line in str(exc).splitlines() if line.strip()), "")
        raise TimingError(f"Ruckig could not time the joint move: {first_line}") from exc
    if result not in (Result.Working, Result.Finished):
        raise TimingError(f"Ruckig could not time the joint move ({result.name})")
    return _jerk_profile(trajectory)


RUCKIG_MAX_DURATION = 7.6e3
"""Longest joint move (s) Ruckig times: measured with ruckig 0.19, a move of 7,600 s is timed
and a longer one returns its code -101 (trajectory duration beyond its numerical limits)."""


def _check_ptp_duration(
    q0: FloatArray, q1: FloatArray, robot: Robot, velocity_scale: float, accel_scale: float
) -> None:
    """Raise :class:`TimingError` if the joint move cannot take less than
    :data:`RUCKIG_MAX_DURATION`: its time-optimal duration under the velocity and acceleration
    limits alone (a trapezoid per axis; jerk limits only add time) is a lower bound."""
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        velocity = robot.limits.velocity * velocity_scale
        accel = robot.limits.acceleration * accel_scale
        least = float(np.max(trapezoid(np.abs(q1 - q0), velocity, accel)[1]))
    if least <= RUCKIG_MAX_DURATION:
        return
    raise TimingError(
        f"the joint move would take at least {least:.4g} s at {velocity_scale * 100:.3g}% of "
        f"the axes' speed and {accel_scale * 100:.3g}% of their acceleration: longer than the "
        f"{RUCKIG_MAX_DURATION:g} s a joint move can be timed (Ruckig); raise the joint speed"
    )


def _jerk_profile(trajectory: Trajectory) -> JerkProfile:
    """Ruckig's per-axis seven-phase profiles as arrays (rest to rest: no brake phases)."""
    profiles = trajectory.profiles[0]
    if any(p.brake.duration > 0 for p in profiles):
        raise TimingError("Ruckig returned a braking phase for a move from rest")
    durations = np.array([p.t for p in profiles], dtype=np.float64)
    return JerkProfile(
        starts=np.concatenate([np.zeros((len(profiles), 1)), np.cumsum(durations, 1)], axis=1),
        jerk=np.array([p.j for p in profiles], dtype=np.float64),
        q=np.array([p.p for p in profiles], dtype=np.float64),
        qd=np.array([p.v for p in profiles], dtype=np.float64),
        qdd=np.array([p.a for p in profiles], dtype=np.float64),
    )


def ptp_duration(
    q0: FloatArray,
    q1: FloatArray,
    robot: Robot,
    velocity_scale: float = 1.0,
    accel_scale: float = 1.0,
) -> float:
    """Duration (s) of :func:`ptp_profile`."""
    return ptp_profile(q0, q1, robot, velocity_scale, accel_scale).duration
