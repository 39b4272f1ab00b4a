"""Stop-to-stop path moves along a straight joint-space line: timed in closed form, all such
moves of a program at once (see the package docstring)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from olp.geometry import rotation_log
from olp.passes.timing.scurve import SCurves, double_s, short_of_cruise
from olp.passes.timing.tcp import tcp_poses, tcp_positions
from olp.station.model import JointLimits, Robot

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

    ``accel``: the acceleration held between the jerk phases, in fractions of the line, 1/s²;
    ``ramp``: the time (s) of each of the acceleration and braking phases; ``jerk_time`` (s):
    of each jerk phase (0 without a jerk limit: a trapezoid); ``duration`` (s); ``excess``: a
    bound on the relative excess of ``duration`` over the time-optimal duration of the move (0
    where no TCP limit binds: the profile is then exact). ``lead`` (M,): -1 where the profile
    runs in the fraction of the path parameter, else the joint whose fraction it runs in
    (:func:`_led`; parabolas only); None: -1 for all.
    """

    accel: FloatArray
    ramp: FloatArray
    duration: FloatArray
    excess: FloatArray
    jerk_time: FloatArray
    lead: NDArray[np.int64] | None = None

    def with_rows(self, rows: NDArray[np.int64], other: LineProfiles) -> LineProfiles:
        """These profiles with rows ``rows`` (k,) taken from ``other`` (k moves)."""
        out: dict[str, Any] = {}
        for name in ("accel", "ramp", "duration", "excess", "jerk_time", "lead"):
            mine, theirs = getattr(self, name), getattr(other, name)
            if mine is None or theirs is None:
                out[name] = None
                continue
            mine = mine.copy()
            mine[rows] = theirs
            out[name] = mine
        return LineProfiles(**out)


def line_profiles(
    q0: FloatArray,
    q1: FloatArray,
    robot: Robot,
    tools: FloatArray,
    linear_speed: FloatArray,
    angular_speed: FloatArray,
    linear_accel: FloatArray | None = None,
    angular_accel: FloatArray | None = None,
    jerk: bool = True,
    bow: FloatArray | None = None,
    span: FloatArray | None = None,
    ends: tuple[FloatArray, FloatArray] | None = None,
) -> LineProfiles:
    """Time-optimal rest-to-rest laws along the straight joint lines ``q0 -> q1`` (M, dof) rad,
    vectorised over the moves, under the joint velocity, acceleration and (``jerk``) jerk
    limits, a TCP speed of at most ``linear_speed`` (M,) m/s and ``angular_speed`` (M,) rad/s
    and a TCP path (tangential) acceleration of at most ``linear_accel`` (M,) m/s² and
    orientation acceleration ``angular_accel`` (M,) rad/s² (``inf`` or None: none) for the
    tools ``tools`` (M, 4, 4) (TCP in flange). ``ends``: the TCP positions (M, 3) m at ``q0``
    and at ``q1`` by forward kinematics, if the caller has them (NaN rows: not known); only
    :func:`_screened_rates` reads them.

    Jerk: joint j's jerk is ``e_j d³s/dt³``, so the joint jerk limits are exactly
    ``|d³s/dt³| <= min_j J_j / |e_j|`` and the law is a double S in ``s``
    (:func:`~olp.passes.timing.scurve.double_s`), whose duration is monotone in the speed and
    acceleration caps: the bracketing below holds for it as for the trapezoid. TCP path
    accelerations: the TCP's speed along its path is ``r ds/dt``, its rate of change
    ``r d²s/dt² + r' (ds/dt)²`` with ``|r'| <= |p''|`` bounded like ``r`` (below); the
    acceleration cap in ``s`` lies between ``(a - |r'| V²) / r_hi`` and ``(a + |r'| V²) / r_lo``
    (likewise for the orientation with ``|w'| <= (c |e|_1)²``).

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
    2 mm moves at 50 mm/s the bound is < 1e-3. Most short lines of a toolpath never reach
    their speed cap at all: :func:`_screened_rates` proves that from the TCP positions at their
    ends and skips the five forward kinematics there (the result is the same to the bit).

    **Parabolas** (``bow`` (M, dof) rad and ``span`` (M,) rad, :func:`line_paths`): the path
    ``q(s) = q0 + u line + u (u - 1) bow``, ``u = s / span``, the chain timer's spline through
    a move's three samples. Its ``q'_j`` is linear in ``s`` (``(line -+ bow) / span`` at the
    ends) and ``q''_j = 2 bow_j / span²`` constant, so every joint limit is bracketed as on a
    line, with ``|q'_j|`` over the move: the law holds ``ṡ <= min_j v_j / max|q'_j|``,
    ``|s̈| <= min_j (a_j - |q''_j| V²) / max|q'_j|`` and ``|s⃛| <= min_j (J_j - 3 |q''_j| V A)
    / max|q'_j|`` (joint jerk is ``q'_j s⃛ + 3 q''_j ṡ s̈`` here), and the optimum is at least
    as fast as the double S under ``min_j v_j / min|q'_j|``, ``(a_j + |q''_j| V²) / min|q'_j|``
    and ``(J_j + 3 |q''_j| V A) / min|q'_j|``. The TCP's derivatives along it are bounded by
    ``Mk = R k! [t^k] exp(a t + b t² / 2)``, ``a = c max|q'|_1``, ``b = c |q''|_1``
    (:func:`_derivative_bounds`; ``(c |e|_1)^k R`` on a line). A parabola under an orientation
    limit is left to the solver (its excess is ``inf``).
    """
    none = np.full(q0.shape[0], np.inf)
    moves = _Moves(
        q0,
        q1,
        tools,
        linear_speed,
        angular_speed,
        none if linear_accel is None else linear_accel,
        none if angular_accel is None else angular_accel,
        np.zeros_like(q0) if bow is None else bow,
        np.linalg.norm(q1 - q0, axis=-1) if span is None else span,
    )
    relax = bow is not None
    screenable = _screenable(moves)
    screened = np.flatnonzero(screenable)
    if screened.size == moves.count:  # a toolpath's short lines: all of them
        rates = _screened_rates(moves, robot, ends)
    else:
        rates = np.empty((6, moves.count))
        rates[:, screened] = _screened_rates(moves.take(screened), robot, _ends(ends, screened))
        measured = np.flatnonzero(~screenable)
        rates[:, measured] = _line_rates(moves.take(measured), robot)
    profiles, clear = _laws(moves, robot.limits, jerk, rates, relax)
    again = screened[~clear[screened]]
    if again.size:  # the screen did not prove it: the five forward kinematics after all
        part = moves.take(again)
        redone, _ = _laws(part, robot.limits, jerk, _line_rates(part, robot), relax)
        profiles = profiles.with_rows(again, redone)
    return profiles


@dataclass(frozen=True, slots=True, eq=False)
class _Moves:
    """The moves of :func:`line_profiles`, (M, ...) each: ends ``q0``, ``q1`` rad, ``tools``
    (M, 4, 4), TCP limits (``inf``: none), ``bow`` (M, dof) rad (0 on a line), ``span`` rad."""

    q0: FloatArray
    q1: FloatArray
    tools: FloatArray
    linear: FloatArray
    angular: FloatArray
    linear_accel: FloatArray
    angular_accel: FloatArray
    bow: FloatArray
    span: FloatArray

    @property
    def count(self) -> int:
        return int(self.q0.shape[0])

    @property
    def turns(self) -> NDArray[np.bool_]:
        """Where an orientation limit applies."""
        return np.isfinite(self.angular) | np.isfinite(self.angular_accel)

    def take(self, rows: NDArray[np.int64]) -> _Moves:
        return _Moves(*(getattr(self, f.name)[rows] for f in dataclasses.fields(self)))


def _ends(
    ends: tuple[FloatArray, FloatArray] | None, rows: NDArray[np.int64]
) -> tuple[FloatArray, FloatArray] | None:
    return None if ends is None else (ends[0][rows], ends[1][rows])


def _laws(
    moves: _Moves, limits: JointLimits, jerk: bool, rates: FloatArray, relax: bool
) -> tuple[LineProfiles, NDArray[np.bool_]]:
    """The laws of :func:`line_profiles` given the TCP rate bounds ``rates`` (6, M) of
    :func:`_line_rates`, and where each move stays short of its speed caps
    (:func:`~olp.passes.timing.scurve.short_of_cruise`: its law does not depend on them).
    ``relax``: a parabola's fastest law is relaxed :data:`_RELAXATIONS` times. Every row is
    computed on its own: a subset of the moves gives the same rows (the shortcuts taken for a
    whole batch give the values they skip)."""
    line, length, bent = moves.q1 - moves.q0, moves.span, moves.bow
    start, end = (line - bent) / length[:, None], (line + bent) / length[:, None]
    most = np.maximum(np.abs(start), np.abs(end))  # max |q'_j| over the move
    least = np.where(start * end > 0.0, np.minimum(np.abs(start), np.abs(end)), 0.0)
    curve = 2.0 * np.abs(bent) / (length**2)[:, None]  # |q''_j|
    none = np.full(length.shape, np.inf)
    lin_acc, ang_acc = moves.linear_accel, moves.angular_accel
    linear_speed, angular_speed = moves.linear, moves.angular
    turns = moves.turns
    rate_lo, rate_hi, turn_lo, turn_hi, bend, spin = rates
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        slow = np.minimum.reduce(
            [
                np.min(limits.velocity / most, axis=-1),
                linear_speed / rate_hi,
                angular_speed / turn_hi,
            ]
        )
        fast = np.minimum.reduce(
            [
                np.min(limits.velocity / least, axis=-1),
                linear_speed / rate_lo,
                angular_speed / turn_lo,
            ]
        )
        tcp_slow = np.minimum(
            _accel_cap(lin_acc, -bend * slow**2, rate_hi),
            _accel_cap(ang_acc, -spin * slow**2, turn_hi),
        )

        def tcp_fast(speed: FloatArray) -> FloatArray:
            return np.minimum(
                _accel_cap(lin_acc, bend * speed**2, rate_lo),
                _accel_cap(ang_acc, spin * speed**2, turn_lo),
            )

        # The slowest law: caps for the peak speed and acceleration of the law without the
        # curvature terms (lowering the caps lowers both: the law with them holds them).
        # Without curvature terms (lines) no cap depends on a law's peak: all are the plain
        # limits over the rates, and every relaxation below is the first.
        curved = bool(np.any(curve > 0.0))
        if curved:
            first = _joint_caps(limits, most, curve, np.zeros_like(slow), none, -1.0, jerk)
            law = double_s(length, slow, np.minimum(first[0], tcp_slow), first[1])
            joint_slow = _joint_caps(limits, most, curve, law.peak, law.accel, -1.0, jerk)
        else:
            joint_slow = _plain_caps(limits, most, jerk)
        slow_acc, slow_jerk = np.minimum(joint_slow[0], tcp_slow), joint_slow[1]
        law = double_s(length, slow, slow_acc, slow_jerk)
        # The fastest: every law the limits allow peaks below the double S of a relaxation,
        # so that peak bounds the curvature terms of the next, tighter relaxation.
        peak = fast
        for _ in range(_RELAXATIONS if relax and curved else 1):
            if curved:
                fast_acc, fast_jerk = _joint_caps(limits, least, curve, peak, none, 1.0, jerk)
            elif np.array_equal(least, most):
                fast_acc, fast_jerk = joint_slow
            else:
                fast_acc, fast_jerk = _plain_caps(limits, least, jerk)
            fast_acc = np.minimum(fast_acc, tcp_fast(peak))
            relaxed = _same_or_double_s(
                law, (slow, slow_acc, slow_jerk), length, fast, fast_acc, fast_jerk
            )
            peak = np.minimum(peak, relaxed.peak)
        clear = short_of_cruise(length, slow, slow_acc, slow_jerk) & short_of_cruise(
            length, fast, fast_acc, fast_jerk
        )
    best = relaxed.duration.copy()  # relaxed may be law: its rows change below
    feasible = (slow_acc > 0) & (slow_jerk > 0)
    lead = np.full(length.shape, -1, dtype=np.int64)
    accel, ramp, duration, jerk_time = law.accel / length, law.ramp, law.duration, law.jerk_time
    if relax:
        bowed = np.any(bent != 0.0, axis=-1)  # a straight line keeps its exact law above
        feasible &= ~(turns & bowed)  # no orientation bound (above)
        rows = np.flatnonzero(bowed)  # the lead's law is read only on parabolas
        led = _led(
            line[rows],
            bent[rows],
            limits,
            jerk,
            (rate_hi * length)[rows],
            linear_speed[rows],
            lin_acc[rows],
            turns[rows],
        )
        best[rows] = np.maximum(best[rows], led.bound)
        better = led.ok & (~feasible[rows] | (led.law.duration < duration[rows]))
        taken = rows[better]
        lead[taken] = led.joint[better]
        accel[taken] = led.law.accel[better]
        ramp[taken] = led.law.ramp[better]
        duration[taken] = led.law.duration[better]
        jerk_time[taken] = led.law.jerk_time[better]
        feasible[taken] = True
    with np.errstate(invalid="ignore"):
        excess = np.where(feasible, duration / best - 1.0, np.inf)
    profiles = LineProfiles(
        accel=accel, ramp=ramp, duration=duration, excess=excess, jerk_time=jerk_time, lead=lead
    )
    return profiles, clear & (slow_acc > 0) & (slow_jerk > 0) & (fast_acc > 0) & (fast_jerk > 0)


def _screenable(moves: _Moves) -> NDArray[np.bool_]:
    """The moves whose law :func:`_screened_rates` may decide: straight lines without a TCP
    acceleration or orientation limit (their law reads the TCP rates only through the speed
    caps ``v / r``)."""
    screenable: NDArray[np.bool_] = (
        ~np.any(moves.bow != 0.0, axis=-1) & ~moves.turns & ~np.isfinite(moves.linear_accel)
    )
    return screenable


def _screened_rates(
    moves: _Moves, robot: Robot, ends: tuple[FloatArray, FloatArray] | None
) -> FloatArray:
    """Stand-ins (6, M) for :func:`_line_rates` on :func:`_screenable` moves, from the TCP
    positions at their ends (``ends``, or forward kinematics): ``U`` as both rate bounds, 0 for
    the rest, where ``U`` is at least the ``r_hi`` that :func:`_line_rates` computes.

    Where the laws of :func:`_laws` with ``r_lo = r_hi = U`` stay short of their speed caps by
    a margin (``clear``), so do the laws with the real bounds, and they are the same to the
    bit: those caps are ``min(joint cap, v / r)`` and only higher with ``r <= U`` (division and
    ``min`` round monotonically); a double S that does not reach its cap does not read it
    (:func:`~olp.passes.timing.scurve.short_of_cruise`); nothing else of a screenable move's
    law reads the rates. Elsewhere :func:`line_profiles` computes the real bounds.

    The bound: ``|P1| + h |P2| + h² |P3| / 2 + rem`` bounds ``r_hi`` (``P1..P3`` as computed,
    ``rem`` :func:`_remainder`); each ``Pj`` is the ``j``-th derivative at the middle within
    its difference's remainder (all at most ``rem`` together) plus its stencil applied to the
    forward kinematics' errors, at most ``η`` (:data:`_FK_ERROR_M`) each: ``1.5 η / k``,
    ``5.4 η / k²``, ``3 η / k³``. With ``|p'| <= |p(q1) - p(q0)| / D + M2 D`` on the move,
    ``|p''| <= M2``, ``|p'''| <= M3``: ``U = chord + M2 (D + h) + M3 h² / 2 + 2 rem
    + 20 η / k``, and a relative ``1e-9`` for the rounding of the sums."""
    line = moves.q1 - moves.q0
    length = moves.span
    half = 0.5 * length
    k = 0.5 * half
    p0, p1 = _end_positions(moves, robot) if ends is None else ends
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        norm1 = _COUPLING_BOUND * np.sum(np.abs(line), axis=-1) / length
        m = [np.full(length.shape, _REACH_BOUND_M)]  # Mj = norm1^j R on a line
        for _ in range(6):
            m.append(m[-1] * norm1)
        chord = np.linalg.norm(p1 - p0, axis=-1) / length
        size = np.maximum(np.max(np.abs(p0), axis=-1), np.max(np.abs(p1), axis=-1))
        error = _FK_ERROR_M * (1.0 + size)
        bound = (
            chord
            + m[2] * (length + half)
            + 0.5 * half**2 * m[3]
            + 2.0 * _remainder(half, m)
            + 20.0 * error / k
        ) * (1.0 + 1e-9)
    zero = np.zeros_like(bound)
    return np.stack([bound, bound, zero, zero, zero, zero])


_FK_ERROR_M = 1e-10
"""m per m of distance from the world origin (plus one m): a bound on the error of a TCP
position by forward kinematics, 1e5 times its rounding (tens of ulps of the largest term)."""


def _end_positions(moves: _Moves, robot: Robot) -> tuple[FloatArray, FloatArray]:
    """TCP positions (M, 3) m at the moves' ends, by forward kinematics."""
    joints = np.concatenate([moves.q0, moves.q1])
    tools = np.concatenate([moves.tools, moves.tools])
    positions = tcp_positions(robot, joints, tools)
    return positions[: moves.count], positions[moves.count :]


@dataclass(frozen=True, slots=True, eq=False)
class _Led:
    """Parabolas timed by their lead joint (:func:`_led`): ``bound`` (M,) s, a lower bound on
    every law's duration; ``joint`` (M,) the lead joint; ``law`` the double S of its fraction
    (in fractions of the move); ``ok`` (M,) where it is one."""

    bound: FloatArray
    joint: NDArray[np.int64]
    law: SCurves
    ok: NDArray[np.bool_]


def _led(
    line: FloatArray,
    bow: FloatArray,
    limits: JointLimits,
    jerk: bool,
    tcp_rate: FloatArray,
    linear_speed: FloatArray,
    linear_accel: FloatArray,
    turns: NDArray[np.bool_],
) -> _Led:
    """Parabolas (``line``, ``bow`` (M, dof) rad) timed along the fraction ``σ`` of the joint
    that needs longest alone, rest to rest under its own limits (the lead, ``l``): that 1-D
    double S is a lower bound on any law's duration (exact where the others do not bind).

    With ``β = bow_l / line_l`` (``|β| < 1``: the lead moves one way) the parabola's parameter
    is ``u(σ) = 2σ / ((1 - β) + sqrt((1 - β)² + 4βσ))``, ``du/dσ = 1 / (1 + (2u - 1) β)``, and
    every other joint has ``dq_k/dσ = (line_k + (2u - 1) bow_k) du/dσ`` (extreme at the ends,
    ``(line_k -+ bow_k) / (1 -+ β)``), ``d²q_k/dσ² = 2 g_k (du/dσ)³`` and
    ``d³q_k/dσ³ = -12 β g_k (du/dσ)⁵`` with ``g_k = bow_k - β line_k``. With ``R1..R3`` the
    bounds of those over the move, the law is the double S in ``σ`` with ``σ̇ <= min_k v_k /
    R1_k`` (and the TCP speed: ``tcp_rate`` (M,) m per unit of ``u``, an upper bound, times
    ``max du/dσ``), ``|σ̈| <= min_k (a_k - R2_k vp²) / R1_k`` and ``|σ⃛| <= min_k (J_k -
    3 R2_k vp ap - R3_k vp³) / R1_k``, ``vp`` and ``ap`` the peak speed and acceleration of
    the law without those terms (the law with them peaks lower). Where the lead's own limits
    are the lowest of these it is the lead's 1-D optimum: exact. A TCP path or orientation
    limit: not taken."""
    shape = line.shape
    alone = double_s(
        np.abs(line).ravel(),
        np.broadcast_to(limits.velocity, shape).ravel(),
        np.broadcast_to(limits.acceleration, shape).ravel(),
        np.broadcast_to(limits.jerk if jerk else np.inf, shape).ravel(),
    )
    each = np.where(line != 0.0, alone.duration.reshape(shape), 0.0)
    joint = np.argmax(each, axis=-1)
    rows = np.arange(shape[0])
    step = line[rows, joint]
    none = np.full(shape[0], np.inf)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        beta = bow[rows, joint] / step
        slope = 1.0 / (1.0 - np.abs(beta))  # max du/dσ
        ends = np.maximum(
            np.abs(line - bow) / (1.0 - beta)[:, None], np.abs(line + bow) / (1.0 + beta)[:, None]
        )
        g = np.abs(bow - beta[:, None] * line)
        second = 2.0 * g * (slope**3)[:, None]
        third = 12.0 * np.abs(beta)[:, None] * g * (slope**5)[:, None]
        speed = np.minimum(
            np.min(limits.velocity / ends, axis=-1), linear_speed / (tcp_rate * slope)
        )

        def caps(vp: FloatArray, ap: FloatArray) -> tuple[FloatArray, FloatArray]:
            vp, ap = vp[:, None], ap[:, None]
            accel = np.min((limits.acceleration - second * vp**2) / ends, axis=-1)
            if not jerk:
                return accel, none
            rest = 3.0 * second * vp * np.minimum(ap, accel[:, None]) + third * vp**3
            return accel, np.min((limits.jerk - rest) / ends, axis=-1)

        first = double_s(np.ones(shape[0]), speed, *caps(np.zeros(shape[0]), none))
        accel, jerks = caps(first.peak, first.accel)
        law = double_s(np.ones(shape[0]), speed, accel, jerks)
    ok = (
        (np.abs(beta) < _MAX_LEAD_BEND)
        & (np.abs(step) > 0)
        & (accel > 0)
        & (jerks > 0)
        & ~np.isfinite(linear_accel)
        & ~turns
    )
    return _Led(np.max(each, axis=-1), joint, law, ok)


_MAX_LEAD_BEND = 0.5
"""Largest ``|β|`` (the lead joint's rate changes by ``(1 + β) / (1 - β)`` along the move) for
which a parabola is timed by its lead."""


_RELAXATIONS = 3
"""Relaxations of a parabola's fastest law, each bounding the curvature terms by the previous
one's peak speed."""


def _joint_caps(
    limits: JointLimits,
    rate: FloatArray,
    curve: FloatArray,
    peak: FloatArray,
    accel: FloatArray,
    sign: float,
    jerk: bool,
) -> tuple[FloatArray, FloatArray]:
    """Caps (M,) on ``|s̈|`` and ``|s⃛|`` from the joints' acceleration and jerk limits with
    ``|q'_j|`` at ``rate`` (M, dof), ``|q''_j| = curve`` (M, dof), along a law peaking at
    ``peak`` (M,) with at most ``accel`` (M,): ``(a_j + sign |q''_j| peak²) / rate_j`` and
    ``(J_j + sign 3 |q''_j| peak accel) / rate_j`` (``sign`` -1: what holds the limits,
    +1: what every law within them holds); the jerk cap ``inf`` without ``jerk``."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        acc = np.min((limits.acceleration + sign * _times(curve, peak**2)) / rate, axis=-1)
        if not jerk:
            return acc, np.full(acc.shape, np.inf)
        bound = np.minimum(accel, acc)
        jerks = np.min((limits.jerk + sign * 3.0 * _times(curve, peak * bound)) / rate, axis=-1)
    return acc, jerks


def _plain_caps(limits: JointLimits, rate: FloatArray, jerk: bool) -> tuple[FloatArray, FloatArray]:
    """:func:`_joint_caps` without curvature (``curve`` all 0: the same values):
    ``min_j a_j / rate_j`` and ``min_j J_j / rate_j`` (M,) (``inf`` without ``jerk``)."""
    acc = np.min(limits.acceleration / rate, axis=-1)
    if not jerk:
        return acc, np.full(acc.shape, np.inf)
    return acc, np.min(limits.jerk / rate, axis=-1)


def _same_or_double_s(
    law: SCurves,
    caps: tuple[FloatArray, FloatArray, FloatArray],
    length: FloatArray,
    speed: FloatArray,
    accel: FloatArray,
    jerk: FloatArray,
) -> SCurves:
    """``double_s(length, speed, accel, jerk)``: ``law`` itself where it was made from the same
    ``caps`` (speed, acceleration, jerk) (the screened lines' fastest law is their slowest)."""
    if all(np.array_equal(a, b) for a, b in zip(caps, (speed, accel, jerk), strict=True)):
        return law
    return double_s(length, speed, accel, jerk)


def _times(curve: FloatArray, value: FloatArray) -> FloatArray:
    """``curve * value[:, None]`` (M, dof), exactly 0 where ``curve`` is 0 (``value`` may be
    ``inf`` there: a line's caps stay exactly the limits)."""
    out: FloatArray = np.where(curve > 0.0, curve * value[:, None], 0.0)
    return out


def _accel_cap(limit: FloatArray, slack: FloatArray, rate: FloatArray) -> FloatArray:
    """The cap on ``d²s/dt²`` from a TCP acceleration ``limit`` (M,) (``inf``: none) at a rate
    ``rate`` per unit of ``s``, the curvature term given as ``slack`` (M,) (negative: what the
    slowest law must leave for it)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        cap = np.where(np.isfinite(limit), (limit + slack) / rate, np.inf)
    return np.where(np.isnan(cap), np.inf, cap)


def trapezoid(length: FloatArray, peak: FloatArray, accel: FloatArray) -> tuple[FloatArray, ...]:
    """Ramp time and duration (s), (M,) each, of rest-to-rest moves over ``length`` at most at
    ``peak`` speed with at most ``accel``: a trapezoid, or a triangle if too short to cruise."""
    cruise = length * accel >= peak**2
    ramp = np.where(cruise, peak / accel, np.sqrt(length / accel))
    return ramp, np.where(cruise, length / peak + peak / accel, 2.0 * ramp)


def _line_rates(moves: _Moves, robot: Robot) -> FloatArray:
    """Bounds (M,) on the TCP's linear rate (m/rad) and orientation rate (rad/rad) along the
    joint lines ``q0 -> q1`` of ``moves`` (parabolas with ``bow`` (M, dof) rad over ``span``
    (M,) rad of path parameter): low and high of each, and upper bounds on the magnitude of
    their derivatives along the path, ``|p''|`` (m/rad²) and ``(c |e|_1)²`` (rad/rad², lines
    only), as rows (6, M) (see :func:`line_profiles`); the orientation's only where
    ``moves.turns``."""
    q0, tools, bow, length = moves.q0, moves.tools, moves.bow, moves.span
    line = moves.q1 - q0
    half = 0.5 * length
    k = 0.5 * half
    widest = np.maximum(np.sum(np.abs(line - bow), axis=-1), np.sum(np.abs(line + bow), axis=-1))
    norm1 = _COUPLING_BOUND * widest / length
    norm2 = _COUPLING_BOUND * 2.0 * np.sum(np.abs(bow), axis=-1) / length**2
    fractions = np.array([0.0, 0.25, 0.5, 0.75, 1.0])[:, None, None]
    points = q0[None] + fractions * line[None] + fractions * (fractions - 1.0) * bow[None]
    joints = points.reshape(-1, q0.shape[1])
    poses = tcp_poses(robot, joints, np.concatenate([tools] * 5))
    p = poses[:, :3, 3].reshape(5, -1, 3)
    slope = (p[0] - 8 * p[1] + 8 * p[3] - p[4]) / (12 * k)[:, None]
    bend = (-p[0] + 16 * p[1] - 30 * p[2] + 16 * p[3] - p[4]) / (12 * k**2)[:, None]
    twist = (-p[0] + 2 * p[1] - 2 * p[3] + p[4]) / (2 * k**3)[:, None]
    rate2 = np.sum(slope**2, axis=-1)
    along = 2.0 * half * np.abs(np.sum(slope * bend, axis=-1))
    across = (half * np.linalg.norm(bend, axis=-1)) ** 2
    m = _derivative_bounds(norm1, norm2)
    rest = 0.5 * half**2 * np.linalg.norm(twist, axis=-1) + _remainder(half, m)
    rate_lo = np.sqrt(np.maximum(rate2 - along, 0.0)) - rest
    rate_hi = np.sqrt(rate2 + along + across) + rest
    turn = np.zeros_like(length)
    limited = moves.turns
    if np.any(limited):
        rotations = poses[:, :3, :3].reshape(5, -1, 3, 3)
        relative = np.swapaxes(rotations[0][limited], -1, -2) @ rotations[4][limited]
        turn[limited] = np.linalg.norm(rotation_log(relative), axis=-1) / length[limited]
    spread = half * norm1**2 * (1.0 + half * norm1)
    bend_hi = np.linalg.norm(bend, axis=-1) + half * np.linalg.norm(twist, axis=-1) + half**2 * m[4]
    return np.stack(
        [
            np.maximum(rate_lo, 0.0),
            rate_hi,
            np.maximum(turn - spread, 0.0),
            turn + spread,
            bend_hi,
            norm1**2,
        ]
    )


def _derivative_bounds(norm1: FloatArray, norm2: FloatArray) -> list[FloatArray]:
    """``Mj`` (M,) for j = 0..6: bounds on the j-th derivative of the TCP position along a
    joint path with ``c |q'|_1 <= norm1``, ``c |q''|_1 <= norm2`` and no third derivative:
    ``R j! [t^j] exp(norm1 t + norm2 t² / 2)``. (Faà di Bruno: the j-th derivative of
    ``p(q(s))`` sums, over the partitions of j into blocks of one and two, multilinear
    derivatives of ``p`` in ``q'`` and ``q''``, each at most ``R`` times the product of its
    arguments' scaled 1-norms; see :func:`line_profiles`.) ``norm1^j R`` on a line."""
    out = []
    for j in range(7):
        total = np.zeros_like(norm1)
        for pairs in range(j // 2 + 1):
            ways = math.factorial(j) // (
                math.factorial(pairs) * 2**pairs * math.factorial(j - 2 * pairs)
            )
            total = total + ways * norm1 ** (j - 2 * pairs) * norm2**pairs
        out.append(total * _REACH_BOUND_M)
    return out


def _remainder(half: FloatArray, m: list[FloatArray]) -> FloatArray:
    """Bound (M,) m/rad on ``|p'(m + t) - (P1 + t P2 + t² P3 / 2)|`` over ``|t| <= h``
    (``half``), ``P1..P3`` the five-point differences of :func:`_line_rates` (step
    ``k = h / 2``): Taylor's ``h³ M4 / 6`` and the differences' errors ``k⁴ M5 / 30`` (P1),
    ``h k⁴ M6 / 90`` (P2), ``h² k² M5 / 8`` (P3), where ``Mj`` (:func:`_derivative_bounds`)
    bounds the j-th derivative of the TCP position along the path."""
    k = 0.5 * half
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
    if np.all(sizes == 2):
        return _straight_pairs(q[0::2], q[1::2], deviation)
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


def _straight_pairs(q0: FloatArray, q1: FloatArray, deviation: float) -> NDArray[np.bool_]:
    """:func:`straight_samples` of paths of two samples each, ``q0`` and ``q1`` (M, dof) rad,
    with the same operations on the second sample (the first is the chord's start: 0 off it;
    the second lies ahead of it, ``along >= 0``, so only its distance off the chord counts)."""
    chord = q1 - q0
    length = np.linalg.norm(chord, axis=-1)
    unit = chord / np.maximum(length, _MIN_LINE_RAD)[:, None]
    along = np.sum(chord * unit, axis=-1)
    off = np.linalg.norm(chord - along[:, None] * unit, axis=-1)
    return (np.maximum(off, 0.0) <= deviation) & (length > _MIN_LINE_RAD)


_MIN_LINE_RAD = 1e-9
"""Shorter joint paths are left to the chain timer (which times a move without motion as 0)."""


@dataclass(frozen=True, slots=True, eq=False)
class LinePaths:
    """The joint paths of M moves that the closed form can take: ``timed`` (M,) which;
    ``q0``, ``q1`` (M, dof) rad their ends, ``bow`` (M, dof) rad (0 on a straight line) and
    ``span`` (M,) rad the length of their path parameter (the parabola of
    :class:`olp.trajectory.LineTimeLaw`)."""

    timed: NDArray[np.bool_]
    q0: FloatArray
    q1: FloatArray
    bow: FloatArray
    span: FloatArray


def line_paths(q: FloatArray, sizes: NDArray[np.int64], deviation: float) -> LinePaths:
    """The moves given end to end (joints ``q`` (S, dof) rad, ``sizes`` (M,) samples each)
    whose joint path the closed form takes: straight ones (:func:`straight_samples`) and those
    of three samples, whose path in the chain timer is the parabola through them
    (:func:`olp.passes.timing.geometry.joint_path`) in the joint-space chord length ``s``: with
    ``u = s / span``, ``q0 + u (q1 - q0) + u (u - 1) bow`` through the middle sample at
    ``u = |q_m - q0| / span``."""
    straight = straight_samples(q, sizes, deviation)
    first = np.cumsum(sizes) - sizes
    q0, q1 = q[first], q[first + sizes - 1]
    line = q1 - q0
    span = np.linalg.norm(line, axis=-1)
    bow = np.zeros_like(line)
    three = np.flatnonzero((sizes == 3) & ~straight)
    middle = q[first[three] + 1]
    before = np.linalg.norm(middle - q0[three], axis=-1)
    after = np.linalg.norm(q1[three] - middle, axis=-1)
    apart = (before > _MIN_LINE_RAD) & (after > _MIN_LINE_RAD)
    three, middle, before, after = three[apart], middle[apart], before[apart], after[apart]
    u = (before / (before + after))[:, None]
    bow[three] = (middle - q0[three] - u * line[three]) / (u * (u - 1.0))
    span[three] = before + after
    timed = straight.copy()
    timed[three] = True
    return LinePaths(timed, q0, q1, bow, span)
