"""Stop-to-stop path moves along a straight joint-space line: timed in closed form, all such
moves of a program at once (see the package docstring)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from olp.geometry import rotation_log
from olp.passes.timing.tcp import tcp_poses
from olp.station.model import Robot

FloatArray = NDArray[np.float64]


_REACH_BOUND_M = 10.0
"""Upper bound (m) on the distance from a TCP to any joint axis, for every arm olp models (the
largest catalogue arms reach < 4 m; with a 2 m tool, still < 6 m). It bounds the higher
derivatives of the TCP along a joint line (:func:`line_profiles`)."""


_COUPLING_BOUND = 2.0
"""Upper bound on the column sums of a controller-to-model joint coupling (Fanuc's J2/J3 add
one axis to another): the model-joint direction has at most twice the 1-norm."""


@dataclass(frozen=True, slots=True, eq=False)
class LineProfiles:
    """Closed-form rest-to-rest time laws along straight joint lines, one per move (M,).

    ``accel``: acceleration in fractions of the line, 1/s²; ``ramp``: the time (s) of each of
    the acceleration and braking phases; ``duration`` (s); ``excess``: a bound on the relative
    excess of ``duration`` over the time-optimal duration of the move (0 where no TCP limit
    binds: the trapezoid is then exact).
    """

    accel: FloatArray
    ramp: FloatArray
    duration: FloatArray
    excess: FloatArray


def line_profiles(
    q0: FloatArray,
    q1: FloatArray,
    robot: Robot,
    tools: FloatArray,
    linear_speed: FloatArray,
    angular_speed: FloatArray,
) -> LineProfiles:
    """Time-optimal rest-to-rest laws along the straight joint lines ``q0 -> q1`` (M, dof) rad,
    vectorised over the moves, under the joint velocity and acceleration limits and a TCP
    speed of at most ``linear_speed`` (M,) m/s and ``angular_speed`` (M,) rad/s (``inf``: none)
    for the tools ``tools`` (M, 4, 4) (TCP in flange).

    Along ``q(s) = q0 + s e`` (``e`` the unit direction, ``s`` in [0, D] rad of joint chord)
    joint j moves at ``e_j ds/dt`` and accelerates at ``e_j d²s/dt²``: the joint limits are
    exactly ``ds/dt <= min_j v_j / |e_j|`` and ``|d²s/dt²| <= A = min_j a_j / |e_j|``. The TCP
    moves at ``r(s) ds/dt`` with ``r = |dp/ds|`` (m/rad, ``p`` the TCP position). Given bounds
    ``r_lo <= r(s) <= r_hi`` on the move, the speed cap ``V(s)`` lies between
    ``V_lo = min(joint cap, v / r_hi)`` and ``V_hi = min(joint cap, v / r_lo)``; the
    time-optimal duration is monotone in the cap, so it lies between the trapezoids
    ``T(V_hi) <= T* <= T(V_lo)`` with ``T(V) = D / V + V / A`` (a triangle
    ``2 sqrt(D / A)`` when ``D < V² / A``). The law returned runs ``T(V_lo)``: it never exceeds
    a limit, and ``excess = T(V_lo) / T(V_hi) - 1`` bounds its error.

    ``r`` is bounded from five forward kinematics per move, at ``s = m + j k`` (``m`` the
    middle, ``k = D / 4``, ``j = -2 .. 2``): central differences give ``P1, P2, P3`` for the
    first three derivatives of ``p`` at the middle, so over ``|t| <= h = D / 2`` the rate
    ``|p'(m + t)|`` lies within ``ε`` of ``|P1 + t P2|``, which lies in
    ``[sqrt(|P1|² - 2h|P1.P2|), sqrt(|P1|² + 2h|P1.P2| + h²|P2|²)]``;
    ``ε = h² |P3| / 2`` plus Taylor's and the differences' remainders (:func:`_remainder`), of
    order ``h³ M4``, where ``Mj = (c |e|_1)^j R`` bounds the j-th derivative of ``p`` along the
    line (each derivative of a revolute chain is a cross product with unit axes; ``R``
    :data:`_REACH_BOUND_M`, ``c`` :data:`_COUPLING_BOUND`). The orientation rate ``|J_w e|``
    changes by at most ``(c |e|_1)²`` per rad, likewise (used only where an orientation speed
    is given). Measured on the KR 6 helix: on 0.1 mm moves no TCP limit binds (exact); on
    2 mm moves at 50 mm/s the bound is < 1e-3.
    """
    line = q1 - q0
    length = np.linalg.norm(line, axis=-1)
    unit = line / length[:, None]
    with np.errstate(divide="ignore"):
        joint_cap = np.min(robot.limits.velocity / np.abs(unit), axis=-1)
        accel = np.min(robot.limits.acceleration / np.abs(unit), axis=-1)
    rate_lo, rate_hi, turn_lo, turn_hi = _line_rates(q0, q1, robot, tools, angular_speed)
    with np.errstate(divide="ignore", invalid="ignore"):
        slow = np.minimum.reduce([joint_cap, linear_speed / rate_hi, angular_speed / turn_hi])
        fast = np.minimum.reduce([joint_cap, linear_speed / rate_lo, angular_speed / turn_lo])
    ramp, duration = trapezoid(length, slow, accel)
    best = trapezoid(length, fast, accel)[1]
    return LineProfiles(
        accel=accel / length, ramp=ramp, duration=duration, excess=duration / best - 1.0
    )


def trapezoid(length: FloatArray, peak: FloatArray, accel: FloatArray) -> tuple[FloatArray, ...]:
    """Ramp time and duration (s), (M,) each, of rest-to-rest moves over ``length`` at most at
    ``peak`` speed with at most ``accel``: a trapezoid, or a triangle if too short to cruise."""
    cruise = length * accel >= peak**2
    ramp = np.where(cruise, peak / accel, np.sqrt(length / accel))
    return ramp, np.where(cruise, length / peak + peak / accel, 2.0 * ramp)


def _line_rates(
    q0: FloatArray, q1: FloatArray, robot: Robot, tools: FloatArray, angular_speed: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Bounds (M,) on the TCP's linear rate (m/rad) and orientation rate (rad/rad) along the
    joint lines ``q0 -> q1``: low and high of each (see :func:`line_profiles`)."""
    line = q1 - q0
    length = np.linalg.norm(line, axis=-1)
    half = 0.5 * length
    k = 0.5 * half
    norm1 = _COUPLING_BOUND * np.sum(np.abs(line), axis=-1) / length
    fractions = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
    joints = (q0[None] + fractions[:, None, None] * line[None]).reshape(-1, q0.shape[1])
    poses = tcp_poses(robot, joints, np.concatenate([tools] * 5))
    p = poses[:, :3, 3].reshape(5, -1, 3)
    slope = (p[0] - 8 * p[1] + 8 * p[3] - p[4]) / (12 * k)[:, None]
    bend = (-p[0] + 16 * p[1] - 30 * p[2] + 16 * p[3] - p[4]) / (12 * k**2)[:, None]
    twist = (-p[0] + 2 * p[1] - 2 * p[3] + p[4]) / (2 * k**3)[:, None]
    rate2 = np.sum(slope**2, axis=-1)
    along = 2.0 * half * np.abs(np.sum(slope * bend, axis=-1))
    across = (half * np.linalg.norm(bend, axis=-1)) ** 2
    rest = 0.5 * half**2 * np.linalg.norm(twist, axis=-1) + _remainder(half, norm1)
    rate_lo = np.sqrt(np.maximum(rate2 - along, 0.0)) - rest
    rate_hi = np.sqrt(rate2 + along + across) + rest
    turn = np.zeros_like(length)
    limited = np.isfinite(angular_speed)
    if np.any(limited):
        rotations = poses[:, :3, :3].reshape(5, -1, 3, 3)
        relative = np.swapaxes(rotations[0][limited], -1, -2) @ rotations[4][limited]
        turn[limited] = np.linalg.norm(rotation_log(relative), axis=-1) / length[limited]
    spread = half * norm1**2 * (1.0 + half * norm1)
    return np.maximum(rate_lo, 0.0), rate_hi, np.maximum(turn - spread, 0.0), turn + spread


def _remainder(half: FloatArray, norm1: FloatArray) -> FloatArray:
    """Bound (M,) m/rad on ``|p'(m + t) - (P1 + t P2 + t² P3 / 2)|`` over ``|t| <= h``
    (``half``), ``P1..P3`` the five-point differences of :func:`_line_rates` (step
    ``k = h / 2``): Taylor's ``h³ M4 / 6`` and the differences' errors ``k⁴ M5 / 30`` (P1),
    ``h k⁴ M6 / 90`` (P2), ``h² k² M5 / 8`` (P3), where ``Mj = norm1^j R`` bounds the j-th
    derivative of the TCP position along the line."""
    k = 0.5 * half
    m = [norm1**j * _REACH_BOUND_M for j in range(7)]
    out: FloatArray = (
        half**3 * m[4] / 6 + k**4 * m[5] / 30 + half * k**4 * m[6] / 90 + half**2 * k**2 * m[5] / 8
    )
    return out


def straight_paths(paths: Sequence[FloatArray], deviation: float) -> NDArray[np.bool_]:
    """Whether each joint path (S_k, dof) rad is its chord: every sample within ``deviation``
    rad of the straight line from its first to its last sample, in order along it, and the
    chord longer than :data:`_MIN_LINE_RAD`. Vectorised over all samples of all paths."""
    sizes = np.array([len(path) for path in paths], dtype=np.int64)
    if sizes.size == 0:
        return np.zeros(0, dtype=bool)
    return straight_samples(np.concatenate(paths), sizes, deviation)


def straight_samples(
    q: FloatArray, sizes: NDArray[np.int64], deviation: float
) -> NDArray[np.bool_]:
    """:func:`straight_paths` of paths given end to end: joints ``q`` (S, dof) rad and the
    sample count (M,) of each path."""
    if sizes.size == 0:
        return np.zeros(0, dtype=bool)
    first = np.cumsum(sizes) - sizes
    chord = q[first + sizes - 1] - q[first]
    length = np.linalg.norm(chord, axis=-1)
    move = np.repeat(np.arange(sizes.size), sizes)
    unit = chord / np.maximum(length, _MIN_LINE_RAD)[:, None]
    offset = q - q[first][move]
    along = np.sum(offset * unit[move], axis=-1)
    off = np.linalg.norm(offset - along[:, None] * unit[move], axis=-1)
    back = np.concatenate([[0.0], np.maximum(along[:-1] - along[1:], 0.0)])
    back[first] = 0.0  # a path's first sample follows another path's last
    worst = np.maximum.reduceat(np.maximum(off, back), first)
    return (worst <= deviation) & (length > _MIN_LINE_RAD)


_MIN_LINE_RAD = 1e-9
"""Shorter joint paths are left to the chain timer (which times a move without motion as 0)."""
