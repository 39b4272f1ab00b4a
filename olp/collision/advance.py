"""Conservative advancement along a piecewise-linear joint path: no collision between samples is
missed.

The path
--------
A :class:`PathRun` is consecutive motions whose sampled joint paths join end to start: rows
``q_0 .. q_(N-1)`` (chain joints) and, between consecutive rows, the straight joint-space segment
``q_i + t (q_(i+1) - q_i)``, ``t`` in [0, 1]. That piecewise-linear path is what is checked.

The bound
---------
For a checked pair with displacement weights ``w`` (nq,)
(:class:`olp.collision.scene.DisplacementBound`), no point of one body moves relative to the
other by more than ``b_i = |q_(i+1) - q_i| · w`` along segment i, and by ``t · b_i`` along a
part t of it. Put ``c(u)`` = the cumulative bound from the start to path position u (monotone,
piecewise linear). Then for any two positions ``u < v`` the signed distance ``d`` of the pair
(coal; negative = penetration depth, 1-Lipschitz in the bodies' point motion for convex shapes)
satisfies ``|d(v) - d(u)| <= c(v) - c(u)``.

The check
---------
With ``lower = clearance - tolerance`` and ``upper = clearance - tolerance / 2``: evaluate ``d``
at the frontier u (starting at the path's start). If ``d(u) < upper``, report a hit at u.
Otherwise every position v with ``c(v) < c(u) + d(u) - lower`` has ``d(v) > lower``: move the
frontier there and repeat. Each evaluation advances ``c`` by at least ``tolerance / 2``, so the
loop ends after at most ``2 c(end) / tolerance`` evaluations; far from obstacles a single
evaluation covers the whole run.

Guarantee: if no hit is reported, ``d > clearance - tolerance`` at *every* point of the
piecewise-linear path (not only at the samples); a reported hit is a configuration on that path
where ``d < clearance - tolerance / 2``, and it is the first one found from the start of its
motion. With ``clearance = 0``: any overlap deeper than ``tolerance`` is reported, and touching
(``d = 0``, a part resting on its fixture) is not.

Where the guarantee cannot be given, :class:`Unresolved` is raised instead of returning: a
distance that is not a number, a bound that is not finite, a step too small for floating point
to move the frontier, or more than :data:`MAX_EVALUATIONS` evaluations (a path that stays within
the tolerance of contact for very long, or absurd geometry).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from olp.collision.scene import BodyPair, Scene

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass(frozen=True, slots=True, eq=False)
class PathRun:
    """Consecutive motions as one path.

    ``joints`` (N, dof) controller rad and ``chain`` (N, nq) chain joints of the rows; ``owner``
    (N-1,): which motion (0..M-1) each segment belongs to; ``first`` (M,): its first segment;
    ``count`` (M,): its number of segments (at least 1). ``motion`` (N-1, nq): ``|dq|`` of
    each segment in chain joints.
    """

    joints: FloatArray
    chain: FloatArray
    owner: IntArray
    first: IntArray
    count: IntArray
    motion: FloatArray = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "motion", np.abs(np.diff(self.chain, axis=0)))

    @property
    def motions(self) -> int:
        return int(self.first.shape[0])

    def at(self, segment: int, t: float) -> tuple[FloatArray, FloatArray]:
        """Controller and chain joints at fraction t of a segment."""
        q0, q1 = self.joints[segment], self.joints[segment + 1]
        c0, c1 = self.chain[segment], self.chain[segment + 1]
        return q0 + t * (q1 - q0), c0 + t * (c1 - c0)

    def fraction(self, segment: int, t: float) -> tuple[int, float]:
        """The motion a segment position belongs to and the fraction (0..1) of that motion."""
        motion = int(self.owner[segment])
        done = segment - int(self.first[motion]) + t
        return motion, done / int(self.count[motion])


def path_run(
    paths: Sequence[FloatArray],
    chain_joints: Callable[[FloatArray], FloatArray],
    counts: Sequence[IntArray] | None = None,
) -> PathRun:
    """Join motion paths (each (S_k, dof), S_k >= 2, starting where the previous one ends) into a
    run; ``chain_joints``: the kinematics' controller -> chain map (vectorised). ``counts``: per
    path, its segments per motion when a path holds several motions (a toolpath's rows; they
    sum to S_k - 1); by default each path is one motion."""
    if counts is None:
        counts = [np.array([len(p) - 1], dtype=np.int64) for p in paths]
    per_motion = np.concatenate(counts).astype(np.int64)
    joints = np.concatenate([paths[0][:1], *(p[1:] for p in paths)], axis=0)
    chain = np.asarray(chain_joints(joints), dtype=np.float64)
    first = np.concatenate([[0], np.cumsum(per_motion)[:-1]]).astype(np.int64)
    owner = np.repeat(np.arange(per_motion.size, dtype=np.int64), per_motion)
    return PathRun(joints, chain, owner, first, per_motion)


@dataclass(frozen=True, slots=True)
class Hit:
    """Where a pair came too close: the motion (0..M-1 in its run), the fraction of it, the
    controller joints (dof,) rad and the signed distance (m)."""

    motion: int
    fraction: float
    joints: FloatArray
    distance: float


MAX_EVALUATIONS = 1_000_000
"""Distance evaluations one pair may take along one run (about 10 s at 8 µs each) before it is
given up as :class:`Unresolved`. Far from contact one evaluation covers a whole run; the bundled
100k-move milling benchmark, 25 mm from its clamps throughout, takes 9,040 for its 59 pairs; a
part resting on a fixture while the robot slides it a metre takes some 10^4 (steps of one
tolerance)."""


class Unresolved(ArithmeticError):
    """The path of a pair cannot be proven free from ``where`` on (a place on the run; its
    ``distance`` is NaN: none was established), for ``reason``; ``evaluations``: how many
    distance evaluations were spent."""

    def __init__(self, where: Hit, reason: str, evaluations: int) -> None:
        super().__init__(reason)
        self.where = where
        self.reason = reason
        self.evaluations = evaluations


def _at(run: PathRun, segment: int, t: float, distance: float = math.nan) -> Hit:
    """A :class:`Hit` (a place on the run) at fraction t of a segment."""
    q, _ = run.at(segment, t)
    motion, fraction = run.fraction(segment, t)
    return Hit(motion, fraction, q, distance)


def cumulative_bounds(run: PathRun, weights: FloatArray) -> FloatArray:
    """``c`` at every row for each set of weights (P, nq): shape (P, N), metres, the running sum
    of ``|dq| · weights`` over the segments."""
    out = np.zeros((len(weights), len(run.chain)))
    np.cumsum(np.asarray(weights) @ run.motion.T, axis=1, out=out[:, 1:])
    return out


def advance(
    scene: Scene,
    pair: BodyPair,
    run: PathRun,
    lower: float,
    upper: float,
    cum: FloatArray | None = None,
) -> tuple[list[Hit], int]:
    """Conservative advancement of one pair along a run (see the module text).

    ``cum`` (N,): the pair's :func:`cumulative_bounds` if already known. Returns the hits (at most
    one per motion: after a hit the check goes on at the next motion's start) and the number
    of distance evaluations.
    """
    if cum is None:
        cum = cumulative_bounds(run, pair.weights[None])[0]
    if not np.isfinite(cum[-1]):
        raise Unresolved(_at(run, 0, 0.0), "its displacement bound is not finite", 0)
    last = len(cum) - 1
    hits: list[Hit] = []
    segment, t, evaluations = 0, 0.0, 0
    while True:
        q, chain = run.at(segment, t)
        scene.place(chain)
        d = scene.distance(pair)
        evaluations += 1
        if math.isnan(d):
            raise Unresolved(_at(run, segment, t), "its distance is not a number", evaluations)
        if d < upper:
            motion, fraction = run.fraction(segment, t)
            hits.append(Hit(motion, fraction, q, d))
            if motion + 1 >= run.motions:
                return hits, evaluations
            segment, t = int(run.first[motion + 1]), 0.0
            continue
        c = cum[segment] + t * (cum[segment + 1] - cum[segment])
        target = c + (d - lower)
        row = int(np.searchsorted(cum, target, side="left"))
        if row > last:
            return hits, evaluations
        step = (row - 1, float((target - cum[row - 1]) / (cum[row] - cum[row - 1])))
        if step <= (segment, t) or evaluations >= MAX_EVALUATIONS:
            reason = (
                f"no proof after {evaluations} distance evaluations"
                if step > (segment, t)
                else "the step is below floating-point resolution"
            )
            raise Unresolved(_at(run, segment, t), reason, evaluations)
        segment, t = step


def sample_hits(scene: Scene, pair: BodyPair, run: PathRun, upper: float) -> tuple[list[Hit], int]:
    """The sampling-only check (the reference): the pair's distance at every row, one hit per
    motion at its first row below ``upper``. Misses whatever lies between rows."""
    hits: list[Hit] = []
    reported = -1
    for row in range(len(run.chain)):
        segment, t = (row, 0.0) if row < len(run.chain) - 1 else (row - 1, 1.0)
        motion = int(run.owner[segment])
        if motion == reported:
            continue
        scene.place(run.chain[row])
        d = scene.distance(pair)
        if math.isnan(d):
            raise Unresolved(_at(run, segment, t), "its distance is not a number", row + 1)
        if d < upper:
            motion, fraction = run.fraction(segment, t)
            hits.append(Hit(motion, fraction, run.joints[row], d))
            reported = motion
    return hits, len(run.chain)
