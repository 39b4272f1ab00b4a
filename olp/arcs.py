"""Circular arcs: the circle through three points, the arc a circular move runs, its poses.

A circular move (:class:`olp.ir.CircularMove`) starts where the robot is, passes the via point
and ends at the target, on the one circle through the three positions; with a circular angle
(KUKA's ``CA``) it runs that signed angle from the start instead. Everything here is in metres
and radians, vectorised over the samples, and free of vendor spelling.

Conventions and their sources (confidence in brackets):

* The circle through start, auxiliary (via) and end point, travelled from the start past the
  via point to the end: every vendor's three-point arc (KUKA ``CIRC``, ABB ``MoveC``, UR
  ``movec``, Fanuc ``C``) [high: each vendor's motion reference; UR script manual, ``movec``:
  "TCP moves on the circular arc segment from current pose, through pose_via to pose_to"].
* ``CA`` (KUKA): the total angle of the motion, which extends or shortens the arc beyond or
  before the programmed end point, so that the actual end point is not the programmed one, and
  which is not limited (more than one turn is allowed) [high: KUKA mxAutomation's
  ``KRC_MoveCircAbsolute`` reference, parameter ``Angle``, as published by Beckhoff]. A negative
  angle runs the circle the other way [medium: KSS programming manuals as remembered; not
  found in a stored source]. The target's orientation is reached at the actual end point
  [low: olp's reading; not verified].
* Orientation rules (:class:`olp.ir.ArcOrientation`, :func:`arc_rotations`): UR ``movec``
  ``mode=0`` interpolates the orientation from the current pose to ``pose_to`` and ``mode=1``
  keeps it constant relative to the tangent of the arc [high: UR script manual, ``movec``];
  the via point's orientation is not used (UR: "only position is used"; KUKA CIRC: the
  auxiliary point's orientation is not part of the interpolation [medium: KUKA knowledge-base
  articles]; ABB ``MoveC``: start to end [medium: RAPID reference as remembered]). KUKA's
  ``#PATH`` turns the tool with the arc about the circle's normal; olp models ``#VAR`` with
  ``#PATH`` as that turn plus the remaining change to the end orientation interpolated in the
  turning frame [low: olp's model of KUKA's description "path-related orientation control";
  verify on a controller before relying on it].

Degenerate arcs are :class:`ArcError` (the resolve pass makes them diagnostics on the move's
line): coincident points (closer than :data:`MIN_POINT_DISTANCE_M`), collinear points, a radius
below :data:`MIN_RADIUS_M`, and a positive circular angle that ends before the via point.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from olp.geometry import pose_from, rotation_exp, rotation_log
from olp.ir import ArcOrientation

FloatArray = NDArray[np.float64]

MIN_POINT_DISTANCE_M = 1e-6
"""Two of the three points closer than this (1 µm) define no circle."""

MIN_SINE = 1e-9
"""The three points count as collinear where the sine of the angle between the chords from the
start is below this (1e-9: 100 mm chords 0.1 µm off a line)."""

MIN_RADIUS_M = 1e-4
"""Smallest arc radius olp plans (0.1 mm): below it a controller's interpolation is noise."""

TWO_PI = 2.0 * np.pi


class ArcError(ValueError):
    """Three points that define no usable arc. ``kind``: ``"coincident"``, ``"collinear"``,
    ``"radius"`` or ``"via_outside"``."""

    def __init__(self, kind: str, message: str) -> None:
        super().__init__(message)
        self.kind = kind


@dataclass(frozen=True, slots=True, eq=False)
class Arc:
    """An arc of a circle, metres and radians.

    ``centre`` (3,); ``radius``; ``normal`` (3,) the unit normal about which the arc turns
    positively from the start to the via point; ``u`` (3,) the unit vector from the centre to
    the start, ``v = normal x u``; ``via_angle`` and ``end_angle`` in (0, 2 pi): where the via
    point and the programmed end lie, counted from the start about ``normal``; ``sweep``: the
    signed angle the arc runs (``end_angle`` without a circular angle).
    """

    centre: FloatArray
    radius: float
    normal: FloatArray
    u: FloatArray
    v: FloatArray
    via_angle: float
    end_angle: float
    sweep: float

    @property
    def length(self) -> float:
        """The arc's length, m."""
        return self.radius * abs(self.sweep)

    def points(self, fractions: ArrayLike) -> FloatArray:
        """Positions (N, 3) at fractions (N,) of the sweep (0: the start, 1: the end)."""
        theta = np.asarray(fractions, dtype=np.float64)[:, None] * self.sweep
        out: FloatArray = self.centre + self.radius * (
            np.cos(theta) * self.u + np.sin(theta) * self.v
        )
        return out

    def tangents(self, fractions: ArrayLike) -> FloatArray:
        """Unit tangents (N, 3) in the direction of travel at fractions (N,) of the sweep."""
        theta = np.asarray(fractions, dtype=np.float64)[:, None] * self.sweep
        out: FloatArray = np.sign(self.sweep) * (-np.sin(theta) * self.u + np.cos(theta) * self.v)
        return out


def circle_through(
    start: ArrayLike, via: ArrayLike, end: ArrayLike, angle: float | None = None
) -> Arc:
    """The arc from ``start`` past ``via`` to ``end`` (positions (3,), m), or, with ``angle``
    (rad, signed), the arc of that sweep from ``start`` on the same circle.

    Raises :class:`ArcError` for coincident or collinear points, a radius below
    :data:`MIN_RADIUS_M`, and a positive ``angle`` smaller than the via point's angle.
    """
    p0, p1, p2 = (np.asarray(p, dtype=np.float64) for p in (start, via, end))
    a, b = p1 - p0, p2 - p0
    _check_distinct(a, b, p2 - p1)
    axb = np.cross(a, b)
    den = float(np.dot(axb, axb))
    if np.sqrt(den) < MIN_SINE * float(np.linalg.norm(a) * np.linalg.norm(b)):
        raise ArcError(
            "collinear", "the start, via and end points lie on a line: they define no circle"
        )
    offset = (np.dot(a, a) * np.cross(b, axb) + np.dot(b, b) * np.cross(axb, a)) / (2.0 * den)
    radius = float(np.linalg.norm(offset))
    if radius < MIN_RADIUS_M:
        raise ArcError(
            "radius",
            f"the arc's radius is {radius * 1000:.4g} mm, below the {MIN_RADIUS_M * 1000:g} mm "
            "olp plans",
        )
    normal = axb / np.sqrt(den)
    u = -offset / radius
    v = np.cross(normal, u)
    centre = p0 + offset
    via_angle, end_angle = (_angle_of(p, centre, u, v) for p in (p1, p2))
    sweep = end_angle if angle is None else float(angle)
    if angle is not None and 0.0 < sweep < via_angle - 1e-12:
        raise ArcError(
            "via_outside",
            f"the circular angle {np.degrees(sweep):.6g}° ends before the via point, which lies "
            f"{np.degrees(via_angle):.6g}° along the circle",
        )
    return Arc(centre, radius, normal, u, v, via_angle, end_angle, sweep)


def _check_distinct(a: FloatArray, b: FloatArray, c: FloatArray) -> None:
    for length, what in (
        (np.linalg.norm(a), "the via point is the start point"),
        (np.linalg.norm(b), "the end point is the start point"),
        (np.linalg.norm(c), "the via point is the end point"),
    ):
        if length < MIN_POINT_DISTANCE_M:
            raise ArcError(
                "coincident",
                f"{what} (they are {length * 1000:.3g} mm apart): three distinct points "
                "define a circle",
            )


def _angle_of(p: FloatArray, centre: FloatArray, u: FloatArray, v: FloatArray) -> float:
    """The angle of ``p`` about the centre from ``u`` towards ``v``, in (0, 2 pi]."""
    d = p - centre
    angle = float(np.arctan2(np.dot(d, v), np.dot(d, u))) % TWO_PI
    return angle if angle > 0.0 else TWO_PI


def arc_rotations(
    r0: ArrayLike,
    r1: ArrayLike,
    arc: Arc,
    fractions: ArrayLike,
    mode: ArcOrientation,
) -> FloatArray:
    """Tool rotations (N, 3, 3) along ``arc`` at fractions (N,) of its sweep, from the start
    rotation ``r0`` (3, 3) towards the target's ``r1`` (3, 3), both in the world, by the rule
    ``mode`` (see :class:`olp.ir.ArcOrientation` and the module docstring for sources).

    Raises ValueError for :attr:`~olp.ir.ArcOrientation.WRIST`, which is not a Cartesian rule.
    """
    start = np.asarray(r0, dtype=np.float64)
    goal = np.asarray(r1, dtype=np.float64)
    t = np.asarray(fractions, dtype=np.float64)
    if mode is ArcOrientation.INTERPOLATE:
        return _slerp(start, goal, t)
    if mode is ArcOrientation.CONSTANT:
        return np.broadcast_to(start, (t.size, 3, 3)).copy()
    if mode is ArcOrientation.PATH_CONSTANT:
        return _turn(arc, t) @ start
    if mode is ArcOrientation.PATH:
        turned_end = _turn(arc, np.ones(1))[0] @ start
        rest = _slerp(np.eye(3), turned_end.T @ goal, t)
        out: FloatArray = _turn(arc, t) @ start @ rest
        return out
    raise ValueError(f"orientation {mode.value!r} is not a Cartesian rule")


def _slerp(r0: FloatArray, r1: FloatArray, t: FloatArray) -> FloatArray:
    delta = rotation_log(r0.T @ r1)
    out: FloatArray = r0 @ rotation_exp(t[:, None] * delta)
    return out


def _turn(arc: Arc, t: FloatArray) -> FloatArray:
    """Rotations (N, 3, 3) about the arc's normal by the fractions ``t`` (N,) of its sweep."""
    return rotation_exp((t * arc.sweep)[:, None] * arc.normal)


def rotation_travel(r0: ArrayLike, r1: ArrayLike, arc: Arc, mode: ArcOrientation) -> float:
    """An upper bound (rad) on the tool's turn along the arc under ``mode`` (for sampling)."""
    start, goal = np.asarray(r0, dtype=np.float64), np.asarray(r1, dtype=np.float64)
    direct = float(np.linalg.norm(rotation_log(start.T @ goal)))
    if mode is ArcOrientation.INTERPOLATE:
        return direct
    if mode is ArcOrientation.CONSTANT:
        return 0.0
    if mode is ArcOrientation.PATH_CONSTANT:
        return abs(arc.sweep)
    turned_end = _turn(arc, np.ones(1))[0] @ start
    return abs(arc.sweep) + float(np.linalg.norm(rotation_log(turned_end.T @ goal)))


def arc_poses(
    start: ArrayLike,
    via: ArrayLike,
    end: ArrayLike,
    fractions: ArrayLike,
    mode: ArcOrientation = ArcOrientation.INTERPOLATE,
    angle: float | None = None,
) -> FloatArray:
    """TCP poses (N, 4, 4) along the arc from the pose ``start`` past ``via`` to ``end`` (each
    (4, 4), m, in one frame) at fractions (N,) of its sweep; ``angle``: the circular angle (rad)
    or None. The via pose's rotation is not used. Raises :class:`ArcError` (degenerate arc)."""
    p0, p1, p2 = (np.asarray(p, dtype=np.float64) for p in (start, via, end))
    arc = circle_through(p0[:3, 3], p1[:3, 3], p2[:3, 3], angle)
    rotations = arc_rotations(p0[:3, :3], p2[:3, :3], arc, fractions, mode)
    return pose_from(rotations, arc.points(fractions))


def sample_count(
    arc: Arc, turn: float, step_m: float, step_rad: float, step_arc_rad: float
) -> float:
    """Samples an arc needs (a float: compare with a cap before allocating): at most ``step_m``
    of travel, ``step_rad`` of tool turn and ``step_arc_rad`` of the arc's angle (which bounds
    the chord's sag, ``radius (1 - cos(step / 2))``) between two samples; at least 2."""
    with np.errstate(over="ignore", invalid="ignore"):
        counts = (
            np.ceil(arc.length / step_m),
            np.ceil(turn / step_rad),
            np.ceil(abs(arc.sweep) / step_arc_rad),
            2.0,
        )
    return float(max(counts))
