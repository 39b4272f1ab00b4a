"""Corners a blend cannot pass at speed, timed as exact stops.

Two cases, both where a zone meets a corner so sharp that the robot must (nearly) stop in it:

* **The path turns back** (:func:`turn_angles` above :data:`FOLD_TURN`): the approximation
  contour of a 180° reversal folds onto itself, its TCP velocity passes through zero (the TCP
  runs up the line and back down it), and the joint-space blend has a cusp. The corner is an
  exact stop in the plan (:func:`olp.passes.timing.table.plan`). No controller manual at hand
  states what KUKA (C_DIS), ABB (zones), UR (blend radius) or Fanuc (CNT) do at a reversal (not
  verified); a stop at the corner is what the fine point takes, the bound the estimate keeps.
* **A sharp blend the jerk-limited law had to slow the whole chain for** (:func:`sharp_corners`):
  the acceleration-limited law almost stops at the apex of a tight blend (a 170° turn with a
  20 mm zone, a 90° corner with a 0.1 mm zone), its average over the jerk window
  (:mod:`~olp.passes.timing.jerk`) then passes the apex faster than the curvature allows, and
  step 4's uniform slow-down, up to ``speed / apex speed``, spread over every move of the chain
  (measured on the KR 6 cell: a 20 mm zone at a 179° turn timed 5x the fine stops). Such a
  chain is timed again with those corners stopped, and the faster of the two kept
  (:func:`olp.passes.timing.program.time_chains`): each is a jerk-limited law within the
  limits, and the minimum of two times that change continuously with the corner's angle does
  too, so a corner approaching a reversal slows down to the stop, without a jump.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from olp.passes.timing.jerk import limit_ratios
from olp.passes.timing.tcp import tcp_positions
from olp.station.model import Robot
from olp.trajectory import SmoothedTimeLaw

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


FOLD_TURN = float(np.radians(179.5))
"""rad: a corner whose TCP path turns by more than this is a stop, whatever its zone (the blend's
cusp is left to no solver). Below it a blend is built and timed, and whether it is faster than
stopping decides (tests/passes/test_reversal.py: the time meets the stop's without a jump)."""


SHARP_RATIO = 1e-2
"""A chain's jerk-limited law slowed by more than this fraction is timed again with the
corners where it broke the limits stopped."""


def turn_angles(
    robot: Robot, q: FloatArray, tools: FloatArray, ends: IntArray, starts: IntArray
) -> FloatArray:
    """Angles (k,) rad between the TCP's direction at the end of a move (its last sample step,
    ending at row ``ends`` (k,) of joints ``q`` (S, dof) rad) and at the start of the next (its
    first step, from row ``starts`` (k,)); ``tools`` (S, 4, 4): each sample's tool. 0 where a
    step has no TCP travel (no direction: a pure turn of the tool)."""
    rows = np.stack([ends - 1, ends, starts, starts + 1], axis=-1)
    unique, inverse = np.unique(rows, return_inverse=True)
    p = tcp_positions(robot, q[unique], tools[unique])[inverse.reshape(rows.shape)]
    before, after = p[:, 1] - p[:, 0], p[:, 3] - p[:, 2]
    norms = np.linalg.norm(before, axis=-1) * np.linalg.norm(after, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        cos = np.sum(before * after, axis=-1) / norms
    out: FloatArray = np.where(norms > 0.0, np.arccos(np.clip(cos, -1.0, 1.0)), 0.0)
    return out


def sharp_corners(law: SmoothedTimeLaw, boundaries: FloatArray, robot: Robot) -> IntArray:
    """Corners (indices into the chain's blends, ascending) next to which the averaged law
    ``law`` breaks the joint limits by more than :data:`SHARP_RATIO` (before its uniform
    slow-down): for each such knot the instruction boundary (a blend's midpoint, ``boundaries``
    (M + 1,) in the path parameter) nearest to where the path is then."""
    knots, ratio = limit_ratios(law, robot)
    broken = knots[ratio > 1.0 + SHARP_RATIO]
    if broken.size == 0 or boundaries.size < 3:
        return np.zeros(0, dtype=np.int64)
    s = law.path_state(broken * law.stretch)[0]
    inner = boundaries[1:-1]
    nearest = np.abs(s[:, None] - inner[None, :]).argmin(axis=1)
    return np.unique(nearest).astype(np.int64)
