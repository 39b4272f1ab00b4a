"""A path problem: a chain's joint path on its grid with the TCP speed limits at the gridpoints,
and the path-speed bounds that follow from them (what every path solver takes)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from olp.passes.timing.geometry import JointSpline
from olp.passes.timing.plan import X_CAP
from olp.passes.timing.tcp import rate_bound, tcp_rates
from olp.station.model import Robot

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class PathProblem:
    """One chain to time, rest to rest: its joint path, gridpoints ``grid`` (K,) and, at them,
    the TCP's linear (m/s) and orientation (rad/s, ``inf``: none) speed limits (K,) each, for
    the tool ``tool`` (4, 4) (TCP in flange); optionally the TCP's path (tangential)
    acceleration (m/s²) and orientation acceleration (rad/s²) limits (K,) each (``inf`` or
    None: none). Joint limits are the robot's; every acceleration limit (joint and TCP) is
    scaled by ``accel_scale``, and the path speed ``ds/dt`` is at most ``speed_cap`` (the
    jerk-limited law's second solve, :mod:`olp.passes.timing.jerk`)."""

    path: JointSpline
    grid: FloatArray
    tool: FloatArray
    linear: FloatArray
    angular: FloatArray
    linear_acceleration: FloatArray | None = None
    angular_acceleration: FloatArray | None = None
    accel_scale: float = 1.0
    speed_cap: float = float(np.inf)

    @property
    def tcp_accelerations(self) -> bool:
        """Whether a TCP acceleration limit is set anywhere on the chain."""
        return any(
            limit is not None and bool(np.any(np.isfinite(limit)))
            for limit in (self.linear_acceleration, self.angular_acceleration)
        )


def speed_bounds(
    robot: Robot,
    q: FloatArray,
    dq: FloatArray,
    tools: FloatArray,
    linear: FloatArray,
    angular: FloatArray,
) -> FloatArray:
    """Upper bounds (K,) on the squared path speed ``x = (ds/dt)²`` at gridpoints where the path
    is at ``q`` with tangent ``dq`` (K, dof), from the first-order limits: joint velocities
    ``|q'_j| ds/dt <= v_j`` and the TCP speeds ``rate ds/dt <= limit`` (:func:`tcp_rates` for
    ``tools`` (4, 4) or (K, 4, 4); ``linear`` m/s and ``angular`` rad/s (K,), ``inf``: none);
    capped at ``X_CAP``."""
    bound = joint_speed_bound(robot.limits.velocity, dq)
    turns = bool(np.any(np.isfinite(angular)))
    linear_rate, angular_rate = tcp_rates(robot, tools, q, dq, angular=turns)
    bound = np.minimum(bound, rate_bound(linear_rate, linear))
    if turns:
        bound = np.minimum(bound, rate_bound(angular_rate, angular))
    return np.minimum(bound, X_CAP)


def joint_speed_bound(velocity: FloatArray, dq: FloatArray) -> FloatArray:
    """``min_j (v_j / |q'_j|)²`` (K,) for joint velocity limits ``velocity`` (dof,) rad/s and
    tangents ``dq`` (K, dof): a joint with ``|q'_j| <= v_j * TINY_TANGENT`` (one standing
    still, or within 1e-300 of it where a wrist axis stays on 0) bounds nothing (``inf``; its
    ratio squared would be ``1e200`` or more, far above ``X_CAP``, or overflow)."""
    rate = np.abs(dq)
    moving = ~(rate <= velocity * TINY_TANGENT)  # NaN counts as moving: it stays NaN
    ratio = np.divide(velocity, rate, out=np.full(rate.shape, np.inf), where=moving)
    out: FloatArray = np.min(ratio**2, axis=-1)
    return out


TINY_TANGENT = 1e-100
"""Relative to a joint's limit, the smallest ``|q'_j|`` divided by (see
:func:`joint_speed_bound`); any ``(limit / |q'_j|)²`` it leaves out is above ``1e200``."""
