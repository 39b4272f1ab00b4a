"""Blended joint moves (KUKA ``C_PTP``, ABB ``MoveJ`` with a zone, Fanuc ``J ... CNT``): the
time saved by approximating a PTP corner, modelled from the zone.

The model (olp's, stated so it can be checked; vendors publish none): a joint move whose zone
``r > 0`` is followed by another joint move (comments in between) leaves its straight joint
line when it has ``d = min(r, L1 / 2, L2 / 2)`` of TCP travel left (``L`` the two moves' TCP
travel, the rule olp's path blends use), taken as the same fraction of its joint line. From
that state (position, velocity, acceleration of the jerk-limited profile it was on) Ruckig
computes the time-optimal jerk-limited move to the next target, time-synchronised (a moving
start cannot be phase-synchronised); the next move's time starts there. A chain of blended
joint moves is timed move by move this way; its last move stops.

What it is checked against (tests/passes/test_ptp_blend.py): a Ruckig trajectory *through*
the corner (two state-to-state moves meeting at the corner with the best pass-through speed
along the bisector, searched): the model, which may cut the corner, is never slower than that
by more than the search's resolution, never faster than the direct move to the second target,
and with a zone of 0 it is the two stops.

A Ruckig profile that starts with a braking phase (a start state beyond the limits, which a
state of a profile within the limits is not) makes that corner a stop, with the
``zone_stop`` info as before.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from ruckig import InputParameter, Result, Ruckig, RuckigError, Synchronization, Trajectory

from olp.passes.timing.plan import MIN_BLEND_M, TimingError
from olp.passes.timing.table import COMMENT, JOINT, MotionTable
from olp.station.model import Robot
from olp.trajectory import JerkProfile

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

_SEARCH_SAMPLES = 512
"""Samples of a profile searched for the point where the blend starts (then bisected)."""


def blended_joint_moves(table: MotionTable, lengths: FloatArray) -> FloatArray:
    """The blend distance ``d`` (n,) m from each joint move into the next joint move (0: a
    stop), by the rule of the module docstring."""
    n = table.size
    moves = np.flatnonzero(table.kind != COMMENT)
    nxt = np.full(n, -1, dtype=np.int64)
    nxt[moves[:-1]] = moves[1:]
    after = np.where(nxt >= 0, nxt, 0)
    joint = table.kind == JOINT
    can = joint & (nxt >= 0) & joint[after] & (table.zone > 0)
    with np.errstate(invalid="ignore"):
        d = np.minimum.reduce([table.zone, lengths / 2, lengths[after] / 2])
    out: FloatArray = np.where(can & (d >= MIN_BLEND_M), d, 0.0)
    return out


def profile_from(
    q0: FloatArray,
    v0: FloatArray,
    a0: FloatArray,
    q1: FloatArray,
    robot: Robot,
    velocity_scale: float,
    accel_scale: float,
) -> JerkProfile:
    """The time-optimal jerk-limited move from the state ``(q0, v0, a0)`` (dof,) each to rest
    at ``q1``, time-synchronised (Ruckig, state to state; no intermediate waypoints)."""
    from olp.passes.timing.ptp import _jerk_profile

    dof = q0.size
    inp = InputParameter(dof)
    inp.current_position, inp.current_velocity = q0.tolist(), v0.tolist()
    inp.current_acceleration = a0.tolist()
    inp.target_position = q1.tolist()
    inp.target_velocity = inp.target_acceleration = [0.0] * dof
    inp.max_velocity = (robot.limits.velocity * velocity_scale).tolist()
    inp.max_acceleration = (robot.limits.acceleration * accel_scale).tolist()
    inp.max_jerk = robot.limits.jerk.tolist()
    inp.synchronization = Synchronization.Time
    trajectory = Trajectory(dof)
    try:
        result = Ruckig(dof).calculate(inp, trajectory)
    except (RuckigError, ValueError) as exc:
        raise TimingError(f"Ruckig could not time the blended joint move: {exc}") from exc
    if result not in (Result.Working, Result.Finished):
        raise TimingError(f"Ruckig could not time the blended joint move ({result.name})")
    return _jerk_profile(trajectory)


def blend_start(profile: JerkProfile, q0: FloatArray, q1: FloatArray, fraction: float) -> float:
    """The time (s) at which ``profile`` (towards rest at ``q1``) has ``fraction`` of the move
    ``q0 -> q1`` left along its leading axis (the axis with the longest travel); 0 if it
    starts beyond that."""
    lead = int(np.argmax(np.abs(q1 - q0)))
    travel = q1[lead] - q0[lead]
    target = q0[lead] + (1.0 - fraction) * travel

    def left(t: FloatArray) -> FloatArray:
        position = profile.state(t)[0][:, lead]
        out: FloatArray = (target - position) * np.sign(travel)
        return out

    t = np.linspace(0.0, profile.duration, _SEARCH_SAMPLES)
    past = np.flatnonzero(left(t) <= 0.0)
    if past.size == 0:
        return profile.duration
    hi = float(t[past[0]])
    lo = float(t[max(past[0] - 1, 0)])
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        if left(np.array([mid]))[0] <= 0.0:
            hi = mid
        else:
            lo = mid
    return hi
