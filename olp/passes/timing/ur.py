"""Universal Robots: a UR program is timed with the motion the controller runs for what the
URScript post writes, not with the station's limits.

* ``movej(q, a, v)``: "The speed and acceleration parameters control the trapezoid speed profile
  of the move" (URScript manual, ``movej``), ``a`` and ``v`` being the *leading axis'*
  acceleration and speed: the axis with the largest travel runs a trapezoid (a triangle if too
  short to cruise) and the others follow in proportion (the move is a straight line in joint
  space). Duration ``D / v + v / a`` (``2 sqrt(D / a)`` for a triangle), ``D`` the leading
  axis' travel.
* ``movel(pose, a, v)`` / ``movec``: the tool accelerates at ``a`` to ``v`` along its path and
  brakes at ``a`` (URScript manual, ``movel``: "a: tool acceleration [m/s^2], v: tool speed
  [m/s]", "accelerate to and move with constant tool speed v"): the trapezoid over the TCP's
  travel.

``a`` and ``v`` are :func:`olp.vendors.ur.movej_parameters` /
:func:`~olp.vendors.ur.movel_parameters`, the functions the post writes them with (rounded to
the script's decimals). The model is UR's documented one: no jerk limit (the controller's own
filtering is not published), and the station's joint limits play no part (the resolve pass
checks joint speeds; a move the arm cannot follow stops it on the controller). Not covered,
timed by olp's general model instead: a path move that blends (``r > 0``) or is blended into
(a UR blend keeps the tool moving, which no published formula describes), a ``movel`` that
only turns the tool (no TCP travel: UR's speed for orientation is not published), and a value
that prints as 0 (the post refuses it).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from olp.passes.timing.chains import gridpoints
from olp.passes.timing.geometry import joined_geometry, joint_path
from olp.passes.timing.lines import trapezoid
from olp.passes.timing.plan import TimingOptions
from olp.passes.timing.table import CIRCULAR, LINEAR, MotionTable, gather
from olp.passes.timing.tcp import tcp_positions
from olp.trajectory import JerkProfile, LineTimeLaw, PathTimeLaw, TimeLaw
from olp.vendors.ur import movej_parameters, movel_parameters

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

VENDOR = "ur"
"""``Robot.vendor`` of the arms this model times."""

MIN_TRAVEL_M = 1e-9
"""A ``movel`` with less TCP travel only turns the tool: the general model times it."""


def applies(table: MotionTable) -> bool:
    """Whether the program runs on a UR arm."""
    return table.compiled.station.robot.vendor == VENDOR


def movej_law(table: MotionTable, i: int) -> TimeLaw | None:
    """The trapezoid of joint move ``i`` with the ``a`` and ``v`` the post writes (None if one
    prints as 0)."""
    q0, q1 = table.q[table.lo[i]], table.q[table.hi[i]]
    lead = float(np.max(np.abs(q1 - q0)))
    if lead <= 1e-12:
        return JerkProfile.at_rest(q1)
    robot = table.compiled.station.robot
    a, v = movej_parameters(
        float(table.joint[i]), float(table.joint_acceleration[i]), robot.limits.velocity
    )
    if a <= 0.0 or v <= 0.0:
        return None
    ramp, total = (float(x[0]) for x in trapezoid(np.array([lead]), np.array([v]), np.array([a])))
    return LineTimeLaw(q0, q1, a / lead, ramp, total)


def movel_rows(table: MotionTable, lengths: FloatArray, lone: IntArray) -> IntArray:
    """The rows among ``lone`` (stop-to-stop path moves) this model times: linear and circular
    moves with TCP travel."""
    kind = table.kind[lone]
    keep = ((kind == LINEAR) | (kind == CIRCULAR)) & (lengths[lone] >= MIN_TRAVEL_M)
    rows = lone[keep]
    written = [
        min(movel_parameters(float(table.linear[i]), _optional(table.linear_acceleration[i]))) > 0
        for i in rows.tolist()
    ]
    out: IntArray = rows[np.array(written, dtype=bool)] if written else rows
    return out


def movel_law(
    table: MotionTable, lengths: FloatArray, i: int, options: TimingOptions
) -> PathTimeLaw:
    """Path move ``i`` along its resolved joint path, its TCP on the trapezoid of the ``a`` and
    ``v`` the post writes over its travel ``lengths[i]`` m: the path speeds at the gridpoints
    are the trapezoid's over the TCP's rate, the law (constant path acceleration between
    gridpoints) then stretched uniformly to the trapezoid's duration exactly."""
    robot = table.compiled.station.robot
    q, sizes = gather(table, np.array([i]))
    tool = table.tools[table.tool[i]]
    geometry = joined_geometry(q, sizes, robot, tool, np.zeros(0), options.blend_samples)
    path = joint_path(geometry)
    grid = gridpoints(geometry, options)
    positions = tcp_positions(robot, path(grid), tool)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(positions, axis=0), axis=-1))])
    travel = float(lengths[i])
    along = arc * (travel / arc[-1])
    a, v = movel_parameters(float(table.linear[i]), _optional(table.linear_acceleration[i]))
    t, speed = _trapezoid_at(along, travel, a, v)
    rate = np.gradient(along, grid)
    sd = np.where(rate > 0, speed / np.where(rate > 0, rate, 1.0), 0.0)
    # Two neighbouring rests would make a stage take forever: keep every stage moving.
    sd[1:-1] = np.maximum(sd[1:-1], 1e-300)
    law = PathTimeLaw.from_speeds(path, grid, sd)
    k = float(t[-1]) / law.duration
    return PathTimeLaw(path, grid, sd / k, law.t * k)


def _optional(value: float) -> float | None:
    return None if not np.isfinite(value) else float(value)


def _trapezoid_at(
    x: FloatArray, length: float, accel: float, speed: float
) -> tuple[FloatArray, FloatArray]:
    """Time (s) and speed (m/s), (K,) each, at distances ``x`` (K,) m along a rest-to-rest
    trapezoid over ``length`` m with ``accel`` m/s² and at most ``speed`` m/s."""
    peak = min(speed, float(np.sqrt(accel * length)))
    ramp_len = peak**2 / (2.0 * accel)
    ramp = peak / accel
    total = float(trapezoid(np.array([length]), np.array([speed]), np.array([accel]))[1][0])
    rest = np.maximum(length - x, 0.0)
    t = np.where(
        x < ramp_len,
        np.sqrt(2.0 * np.maximum(x, 0.0) / accel),
        np.where(
            rest < ramp_len, total - np.sqrt(2.0 * rest / accel), ramp + (x - ramp_len) / peak
        ),
    )
    v = np.where(
        x < ramp_len,
        np.sqrt(2.0 * accel * np.maximum(x, 0.0)),
        np.where(rest < ramp_len, np.sqrt(2.0 * accel * rest), peak),
    )
    return t, v
