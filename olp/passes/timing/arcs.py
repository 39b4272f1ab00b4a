"""Circular moves in the timing model: arrays in, the path-move machinery out.

A resolved circular move is a joint path sampled along its arc (the resolve pass,
:func:`olp.passes.resolve._arc_path`). It is timed exactly as a linear move that is not a
straight joint line: a cubic joint spline through the samples
(:func:`~olp.passes.timing.geometry.chain_geometry`), TOPPRA under the joint velocity and
acceleration limits and the Jacobian TCP-speed constraint
(:func:`~olp.passes.timing.chains.time_path`); blends into and out of an arc cut the corner at
TCP travel along the arc's samples, as between two lines. The timing pass therefore needs no
arc-specific hook: :func:`olp.passes.timing.plan.plan_units` counts a circular move as a path
move. This module gives that route as functions on arrays, and the closed form the tests
compare it with.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from olp.passes.timing.chains import time_path
from olp.passes.timing.geometry import chain_geometry
from olp.passes.timing.plan import TimingOptions
from olp.station.model import Robot
from olp.trajectory import PathTimeLaw

FloatArray = NDArray[np.float64]


def time_arc(
    q: FloatArray,
    robot: Robot,
    tool: FloatArray,
    linear_speed: float,
    angular_speed: float = np.inf,
    options: TimingOptions | None = None,
) -> PathTimeLaw:
    """The time-optimal rest-to-rest law along one arc's joint samples ``q`` (S, dof) rad for
    the tool ``tool`` (4, 4) at most at ``linear_speed`` m/s (and ``angular_speed`` rad/s)."""
    opts = options or TimingOptions()
    geometry = chain_geometry([q], robot, tool, [], opts.blend_samples)
    return time_path(
        geometry, robot, tool, np.array([linear_speed]), np.array([angular_speed]), opts
    )


def constant_speed_time(length: float, speed: float, acceleration: float) -> float:
    """Rest-to-rest time (s) over ``length`` m at ``speed`` m/s with a constant path
    ``acceleration`` m/s² (a trapezoid, or a triangle when too short to cruise): the closed
    form of a constant-speed arc with linear ramps."""
    if length * acceleration >= speed**2:
        return length / speed + speed / acceleration
    return 2.0 * float(np.sqrt(length / acceleration))
