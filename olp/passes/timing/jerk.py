"""Jerk-limited time laws along path chains (LIN, CIRC, blended chains), from the
acceleration-limited optimum the path solver finds.

The method, per chain (all chains of a program at once):

1. **Path jerk limit.** Along ``q(s)`` joint j's jerk is ``q'_j s⃛ + 3 q''_j ṡ s̈ + q'''_j ṡ³``.
   At a stop (``ṡ = 0``) only the first term remains, so the chain's path jerk limit is
   ``J = min_s min_j J_j / |q'_j(s)|`` (rad of chord per s³). The other two terms are not
   bounded (they vanish at the stops, where the jerk limit costs time; at speed a path is
   limited by velocity and acceleration first).
2. **Speed and acceleration for that jerk.** The solver's law peaks at ``V = max ṡ`` with
   ``A = max |s̈|``. The time-optimal double S (:mod:`~olp.passes.timing.scurve`) over the
   chain's length ``D`` with ``V``, ``A``, ``J`` peaks at ``vp <= V`` and holds ``ap <= A``
   (less when a jerk-limited ramp cannot reach ``A``, or the move is too short to cruise);
   if either is lower, the chain is solved again with its path speed capped at ``vp`` and
   every acceleration limit (joints and TCP) scaled by ``ap / A``. Its law then cruises at least
   as long as its ramps' jerk phases, which step 3 needs.
3. **Moving average.** The law is averaged over a window of ``w`` s
   (:class:`~olp.trajectory.SmoothedTimeLaw`): its path jerk is at most the largest change of
   ``s̈`` within ``w``, over ``w``; ``w`` is the smallest found (by fixed-point iteration from
   ``A / J``) for which that is at most ``J``. The chain lasts ``w`` longer.

On a straight joint line at constant limits the trapezoid with ``vp``, ``ap`` averaged over
``w = ap / J`` is exactly the time-optimal double S in every case (Biagiotti & Melchiorri:
a double S is a rectangle of speed filtered by two moving averages), and the result matches
:func:`~olp.passes.timing.scurve.double_s` and Ruckig (tests/passes/test_jerk.py). Elsewhere
it is a jerk-limited law close to, not provably at, the jerk-limited optimum: the 1-D
surrogate of step 2 takes the chain's peak speed and acceleration for all of it, and the
uniform slow-down of step 4 slows a whole chain for one sharp corner (an upper bound there;
measured in tests/passes/test_jerk.py; where that costs more than stopping at the corner, the
chain is timed with the corner stopped, :mod:`~olp.passes.timing.corners`). The TCP speed is
not re-checked after averaging (it would take forward kinematics on every sample): the tests
measure it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from olp.passes.timing.problem import TINY_TANGENT, PathProblem
from olp.passes.timing.scurve import double_s
from olp.station.model import Robot
from olp.trajectory import PathTimeLaw, SmoothedTimeLaw

FloatArray = NDArray[np.float64]

_WINDOW_ITERATIONS = 8
"""Fixed-point steps for the window before taking the always-feasible ``(max - min) / J``."""

MIN_SCALE_CHANGE = 1e-3
"""A chain is solved again only if its acceleration scale is below ``1 - MIN_SCALE_CHANGE``."""


def path_jerk(problem: PathProblem, robot: Robot) -> float:
    """The chain's path jerk limit ``min_s min_j J_j / |q'_j(s)|`` (1/s³ in units of ``s``) over
    its gridpoints (step 1 of the module docstring)."""
    dq = np.abs(problem.path(problem.grid, 1))
    limit = robot.limits.jerk
    # A joint within TINY_TANGENT of standing still (a wrist axis kept on 0) limits nothing;
    # its ratio would be above 1e100, or overflow.
    moving = ~(dq <= limit * TINY_TANGENT)
    return float(np.min(np.divide(limit, dq, out=np.full(dq.shape, np.inf), where=moving)))


def scales(law: PathTimeLaw, jerk: float) -> tuple[float, float]:
    """The path-speed cap and acceleration scale of step 2: the time-optimal double S over the
    chain's length with the law's peak speed ``V`` and acceleration ``A`` and the jerk ``J``
    peaks at ``vp <= V`` holding ``ap <= A``; returns ``(vp, ap / A)``, the cap ``inf`` where
    ``vp = V``. (inf, 1): nothing to change, also where averaging the law as it is would lose
    less than :data:`SOLVE_AGAIN_GAIN` of its duration (on that surrogate)."""
    accel = float(np.max(np.abs(_stage_accels(law)), initial=0.0))
    peak = float(np.max(law.sd))
    if accel <= 0.0 or peak <= 0.0 or not np.isfinite(jerk):
        return np.inf, 1.0
    length, top_speed, most = (np.array([x]) for x in (law.s[-1] - law.s[0], peak, accel))
    profile = double_s(length, top_speed, most, np.array([jerk]))
    trapezoid = double_s(length, top_speed, most, np.array([np.inf]))
    # Averaged as it is, the window is A / J, or 2 A / J where it cruises shorter than that.
    cruise = float(trapezoid.duration[0]) - 2.0 * peak / accel
    as_is = float(trapezoid.duration[0]) + accel / jerk * (1.0 if cruise >= accel / jerk else 2.0)
    if as_is - float(profile.duration[0]) < SOLVE_AGAIN_GAIN * law.duration:
        return np.inf, 1.0
    top = float(profile.peak[0])
    # Too short to cruise: cruise a little longer than the jerk phase.
    cap = top * (1.0 - CRUISE_MARGIN) if top < peak else np.inf
    return cap, min(1.0, float(profile.accel[0]) / accel)


SOLVE_AGAIN_GAIN = 1e-3
"""A chain is solved again for the jerk limit only if that shortens it by more than this
fraction (a long blended toolpath, whose stops are a sliver of its time, is not: 100,000 moves
solved twice cost twice)."""

CRUISE_MARGIN = 1e-2
"""Relative speed given up on a move too short to cruise: the averaged law is the double S
only if its trapezoid cruises at least one jerk phase, which the double S's own peak gives
exactly, and the solver's grid a little less. Costs at most a quarter of this in duration
(``dT = Tj dV / V`` with ``T >= 4 Tj``)."""


def smoothing_window(law: PathTimeLaw, jerk: float) -> float:
    """The averaging window ``w`` (s) of step 3: ``w >= M(w) / J`` with ``M(w)`` the largest
    ``|s̈(t) - s̈(t - w)|``; 0 without a jerk limit."""
    accels = _stage_accels(law)
    if not np.isfinite(jerk) or accels.size == 0 or not np.any(accels):
        return 0.0
    window = float(np.max(np.abs(accels))) / jerk
    for _ in range(_WINDOW_ITERATIONS):
        needed = _largest_change(law, accels, window) / jerk
        if needed <= window * (1.0 + 1e-12):
            return window
        window = needed
    return float(max(np.max(accels), 0.0) - min(np.min(accels), 0.0)) / jerk


def jerk_limited(law: PathTimeLaw, jerk: float, robot: Robot) -> SmoothedTimeLaw | PathTimeLaw:
    """The law averaged over :func:`smoothing_window` and stretched by :func:`stretch` (the
    law itself if the window is 0, or if the law lasts longer than :data:`LONGEST_SMOOTHED`)."""
    if not law.duration <= LONGEST_SMOOTHED:
        return law
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        window = smoothing_window(law, jerk)
    if not 0.0 < window < np.inf:
        return law
    averaged = SmoothedTimeLaw(law, window)
    return dataclasses.replace(averaged, stretch=stretch(averaged, robot))


def stretch(law: SmoothedTimeLaw, robot: Robot) -> float:
    """Step 4: how much the averaged law must be slowed, uniformly, for the joints' velocity
    and acceleration limits to hold where it changes form (its knots; between them it is one
    smooth piece, and the tests sample it densely): ``max(1, v / v_max, sqrt(a / a_max))`` over
    those samples and joints. A uniform slow-down divides the path jerk too, so the jerk
    limit still holds."""
    worst = max(1.0, float(np.max(limit_ratios(law, robot)[1], initial=0.0)))
    return worst if worst > 1.0 + STRETCH_TOLERANCE else 1.0


def limit_ratios(law: SmoothedTimeLaw, robot: Robot) -> tuple[FloatArray, FloatArray]:
    """The averaged law's knots (T,) s (unstretched, :meth:`SmoothedTimeLaw.knots`) and the
    factor (T,) by which it must be slowed at each for the joints' limits to hold there:
    ``max(v / v_max, sqrt(a / a_max))`` over the joints, of the law as it is."""
    knots = law.knots()
    qd, qdd = law.rates(knots * law.stretch)
    limits = robot.limits
    speed = np.max(np.abs(qd) / limits.velocity, axis=-1, initial=0.0)
    accel = np.max(np.abs(qdd) / limits.acceleration, axis=-1, initial=0.0)
    return knots, np.maximum(speed, np.sqrt(accel)) * law.stretch


STRETCH_TOLERANCE = 1e-3
"""A law over its limits by less than this (the solver's own grid tolerance) is not slowed."""


LONGEST_SMOOTHED = 1e30
"""s: a longer law (absurdly slow moves) is left acceleration-limited: a window (at most
``2 A / J``, well under a second) is nothing beside it, and averaging its positions would
overflow."""


def rescaled(
    problems: Sequence[PathProblem], factors: Sequence[tuple[float, float]]
) -> list[PathProblem]:
    """The problems again with their path speed capped and acceleration limits scaled by
    ``factors`` (:func:`scales`), a
    problem of fewer than :data:`REFINE_BELOW` gridpoints on a grid :data:`REFINE` times
    finer (its law's ramps then end within a short stage, which step 3's window needs)."""
    return [
        dataclasses.replace(
            _refined(p) if p.grid.size < REFINE_BELOW else p,
            speed_cap=min(p.speed_cap, g),
            accel_scale=p.accel_scale * f,
        )
        for p, (g, f) in zip(problems, factors, strict=True)
    ]


REFINE, REFINE_BELOW = 8, 4096
"""Second solves of short chains run on a grid this many times finer."""


def _refined(problem: PathProblem) -> PathProblem:
    """``problem`` with every stage split into :data:`REFINE` equal ones; a limit inside a stage
    is the larger of its ends' (the smaller is the neighbour's at an instruction boundary)."""
    grid = problem.grid
    steps = np.arange(REFINE) / REFINE
    fine = np.append((grid[:-1, None] + steps * np.diff(grid)[:, None]).ravel(), grid[-1])
    inner = np.repeat(np.arange(grid.size - 1), REFINE)

    def spread(values: FloatArray) -> FloatArray:
        within = np.maximum(values[inner], values[inner + 1])
        within[::REFINE] = values[:-1]
        return np.append(within, values[-1])

    lin_acc, ang_acc = problem.linear_acceleration, problem.angular_acceleration
    return dataclasses.replace(
        problem,
        grid=fine,
        linear=spread(problem.linear),
        angular=spread(problem.angular),
        linear_acceleration=None if lin_acc is None else spread(lin_acc),
        angular_acceleration=None if ang_acc is None else spread(ang_acc),
    )


def _stage_accels(law: PathTimeLaw) -> FloatArray:
    """The law's path acceleration on each stage (K - 1,), constant between gridpoints."""
    accels: FloatArray = (law.sd[1:] ** 2 - law.sd[:-1] ** 2) / (2.0 * np.diff(law.s))
    return accels


def _largest_change(law: PathTimeLaw, accels: FloatArray, window: float) -> float:
    """``max_t |s̈(t) - s̈(t - window)|`` for the piecewise-constant ``s̈`` (0 outside the
    law): it changes only at the stage times and those shifted by ``window``, so its values
    between the sorted breakpoints are all there are."""
    knots = np.unique(np.concatenate([law.t, law.t + window]))
    mid = 0.5 * (knots[:-1] + knots[1:])
    now, before = _accel_at(law, accels, mid), _accel_at(law, accels, mid - window)
    return float(np.max(np.abs(now - before), initial=0.0))


def _accel_at(law: PathTimeLaw, accels: FloatArray, t: FloatArray) -> FloatArray:
    i = np.searchsorted(law.t, t, side="right") - 1
    inside = (t >= 0.0) & (t < law.t[-1])
    out: FloatArray = np.where(inside, accels[np.clip(i, 0, accels.size - 1)], 0.0)
    return out
