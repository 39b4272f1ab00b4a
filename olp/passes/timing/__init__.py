"""Timing: a time-optimal, explained duration for every instruction, from the station's limits.

The model, point by point (each choice is what the estimate can be explained by):

* **Joint moves (PTP)** — Ruckig, state to state (rest to rest), jerk-limited, all axes
  *phase*-synchronised so that the joint path is the straight joint-space line the resolve pass
  sampled (and a collision check checks). Limits: the station's joint velocity x
  ``speed.joint``, acceleration x ``speed.joint_acceleration``, and jerk. olp never asks Ruckig
  for intermediate waypoints (the free Ruckig would compute them on a remote server).
* **Path moves (LIN, CIRC) and chains of blended path moves** — one TOPPRA problem per chain,
  along a cubic spline through the resolved joint samples, under the station's joint velocity
  and acceleration limits (not scaled: ``speed.joint`` is a PTP setting) and two TCP
  constraints, :class:`TcpLinearSpeedConstraint` (``speed.linear``) and
  :class:`TcpAngularSpeedConstraint` (``speed.angular``, where given).
* **The solver** is TOPPRA's reachability analysis (backward controllable sets, greedy forward
  pass, the acceleration limits discretised by TOPPRA's interpolation scheme) written in numpy
  over all gridpoints at once (:func:`reachability_speeds`); the chains of a program are
  solved together, end to end. A chain of 100,000 blended moves (800,000 gridpoints) takes
  3.8 s with its TCP limits' forward kinematics, against 24 s with the toppra package on the
  same grid; the toppra package stays as the reference (``TimingOptions(solver="toppra")``),
  and the two agree to 1e-6 (tests/passes/test_timing.py; 2e-7 on that chain).
* **Stop-to-stop path moves along a straight joint line** (one resolved interval, or samples
  within 1e-7 rad of the chord) are timed in closed form, all such moves of a program at once
  (:func:`line_profiles`): a trapezoid in the path parameter, exact for the joint limits, with
  the TCP's rate ``|dp/ds|`` bounded over the move from five forward kinematics (none where
  the TCP positions at its ends prove that it never reaches its speed cap: the same law,
  without them, on most moves of a dense toolpath). A move whose
  bound on the excess over the optimal time is above ``line_tolerance`` (0.1%) goes to the
  solver; on the KR 6 cell at 50 mm/s that keeps moves up to ~2 mm on the closed form. A
  toolpath of 100,000 fine-stopped moves takes 2-4 s (benchmarks/timing_long.py) where one
  TOPPRA problem per move took minutes (and the toppra package finds no time law on its 0.1 mm
  moves). A move resolved as three samples (5-10 mm) runs along the parabola through them,
  timed likewise where its bound is within ``curve_tolerance`` (1%), in the fraction of the
  joint that needs longest where that is tighter (then exact where that joint binds). The
  closed form is nearer the optimum than the solver on its default grid, which has few
  gridpoints on a tiny move (1.2% slow on 0.5 mm moves; 0.007% on a grid 64x finer).
* **The TCP constraints use the Jacobian**, not a bound on ``ds/dt``: the TCP speed is
  ``|J_v(q(s)) q'(s)| ds/dt``. A bound ``ds/dt <= v / L`` is exact only while the path parameter
  is proportional to TCP travel; that holds for one resolved LIN, but not inside a blend, not
  for a CIRC sampled another way, and not between samples of the spline (measured: on a half
  circle sampled unevenly the bound let the TCP reach 1.36 v, in a blended chain 1.01 v; the
  Jacobian form holds v within 0.01%, tests/passes/test_timing.py). The spline's parameter
  is the joint-space chord length (rad), which exists for every motion (also a pure tool
  rotation, where TCP travel is zero) and concentrates gridpoints where joints move most.
  ``J q'`` is computed as a directional derivative of the vectorised forward kinematics
  (central difference, relative error ~1e-9), cross-checked against pinocchio's Jacobian in the
  tests.
* **Gridpoints** — each sample interval is split into at least ``grid_per_sample`` intervals,
  into intervals of at most ``max_grid_step_rad`` of joint motion, and where the joint path
  turns (blends), of at most ``max_grid_turn_rad`` of turn (:class:`TimingOptions`; without the
  last, a sharp blend exceeded the acceleration limits by 2% between gridpoints). The grid is
  refined geometrically (down to 1e-7 of the chain) on both sides of its ends and of every
  instruction boundary: TOPPRA holds the path acceleration constant over an interval, so a
  start, stop or speed change would otherwise take at least one interval (2% on a slow 200 mm
  move). Measured on the KR 6 cell against a grid 8x finer (tests/passes/test_timing.py and
  benchmarks/timing.py): durations differ by < 0.2% on LINs and blended chains, < 0.5% around a
  179° blend; between gridpoints joint velocities exceed their limits by < 0.01%, joint
  accelerations by < 0.05%, the TCP speed the programmed speed by < 0.01%. The tests hold these
  to documented tolerances of 0.1% (velocities, TCP speed) and 0.5% (accelerations).
* **Zones** — a move whose zone radius ``r > 0`` is followed by a path move with the same tool
  (only comments in between) is blended into it: the corner is cut at
  ``d = min(r, L1 / 2, L2 / 2)`` of TCP travel (``L`` the two moves' TCP path lengths; the
  controller's rule of "at most half a move") on both sides, and the two cut points are joined
  by a joint-space cubic Bezier with the moves' tangents at the cuts and its inner control
  points 2/3 of the way to the corner (the cubic form of a parabola through the corner, as a
  controller's approximate positioning). The chain does not stop at the corner; the instruction
  boundary is the blend's midpoint; each instruction's path length is its TCP travel between
  boundaries (the rounded path, shorter than the programmed polyline). Joint-space blending
  needs no IK and stays inside the joint limits (the box of limits is convex); its TCP curve
  deviates from a vendor's Cartesian blend by second-order terms in ``d``.
* **Stops** — fine points stop. So do: a corner with ``d < 1 um`` (a move without TCP travel),
  a tool change, any instruction other than a comment between two moves, and a corner where
  the path turns back (by more than 179.5°: the blend would fold onto itself). A chain whose
  jerk-limited law had to be slowed for a sharp blend (a near-reversal, a tiny zone at a
  corner) is timed again with those corners stopped, and the faster kept
  (:mod:`~olp.passes.timing.corners`): a zone never costs more than the stop. **PTP-LIN
  blends are timed as stops** (a controller's switch from joint to path interpolation follows
  rules no vendor publishes): such a program's estimate is an upper bound (shown in the
  summary).
* **Blended joint moves** (PTP approximation) — a joint move with a zone followed by a joint
  move leaves its line ``min(r, L1/2, L2/2)`` of TCP travel before the corner and Ruckig
  takes it, from that state, to the next target (:mod:`~olp.passes.timing.ptp_blend`;
  checked against Ruckig through the corner). On a UR arm blended ``movej`` stay stops.
* **UR arms** — joint moves and stop-to-stop path moves are the trapezoids of the ``a`` and
  ``v`` the URScript post writes (:mod:`~olp.passes.timing.ur`).
* **TCP accelerations** — a path move's ``Speed.linear_acceleration`` (KUKA ``$ACC.CP``, ABB
  ``PathAccLim``, UR ``movel`` ``a``) bounds the TCP's acceleration along its path,
  ``|r s̈ + r' ṡ²| <= a`` with ``r = |J_v q'|``, and ``angular_acceleration`` (``$ACC.ORI1``)
  the orientation's likewise: rows of the same form as the joints' acceleration limits in the
  solver (:func:`reachability_speeds`), and bracketed like the TCP speed in the closed form.
  (The toppra package reference does not take them.)
* **Jerk on path moves** (``TimingOptions.path_jerk``, default on) — straight lines are a
  double S in closed form (:mod:`~olp.passes.timing.scurve`, exact for the joint jerk
  limits); chains get the solver's law, solved again with a lower speed and acceleration where
  a jerk-limited ramp cannot use them, averaged over a sliding window that bounds the path
  jerk, and slowed uniformly if the average broke a joint limit
  (:mod:`~olp.passes.timing.jerk`, which states what is exact and what is not). Measured: a
  rest-to-rest line matches Ruckig within 0.5%, ten 30 mm fine-stopped LINs at 250 mm/s the
  double S by hand within 0.5% (the acceleration-limited model was 35% short).
* **Motions to run-time targets** (:class:`~olp.ir.RuntimeMove`) and the motion after one
  (its start is unknown) are not timed: they take 0 s unless ``other_times`` names
  ``runtime_move``, and the summary and report say that the cycle time is then a lower bound
  (:func:`olp.report.untimed_motions`).
* **Other instructions** take :data:`DEFAULT_TIMES` seconds (a ``Wait`` its own time); override
  any kind, or a named call as ``"call:NAME"``, through ``other_times``.

The package, along those seams: :mod:`~olp.passes.timing.plan` (options, fixed times),
:mod:`~olp.passes.timing.table` (the program as rows of arrays, its TCP travel and which moves
blend), :mod:`~olp.passes.timing.ptp` (Ruckig),
:mod:`~olp.passes.timing.lines` (closed-form straight lines), :mod:`~olp.passes.timing.scurve`
(the double S), :mod:`~olp.passes.timing.jerk` (jerk-limited chains),
:mod:`~olp.passes.timing.geometry`
(a chain's joint path and blends), :mod:`~olp.passes.timing.corners` (corners timed as
stops), :mod:`~olp.passes.timing.problem` and
:mod:`~olp.passes.timing.chains` (path problems and their time laws),
:mod:`~olp.passes.timing.reachability` (the numpy solver),
:mod:`~olp.passes.timing.toppra_reference` (the toppra package, loaded only when asked for),
:mod:`~olp.passes.timing.sweep` (speed sweeps), :mod:`~olp.passes.timing.tcp` (the TCP along
joint paths), :mod:`~olp.passes.timing.program` (the pass), and for programs with control flow
:mod:`~olp.passes.timing.branches` (the cycle time per path, a range over open branches) with
:mod:`~olp.passes.timing.conditions` (``--assume`` and the folding of conditions).
"""

from __future__ import annotations

from typing import Any

from olp.passes.timing.chains import PATH_SOLVERS, gridpoints, path_problem, time_path
from olp.passes.timing.geometry import ChainGeometry, JointSpline, chain_geometry, joint_path
from olp.passes.timing.lines import LineProfiles, line_profiles, straight_paths
from olp.passes.timing.plan import (
    DEFAULT_TIMES,
    MIN_BLEND_M,
    MIN_PATH_SPEED,
    TimingError,
    TimingOptions,
    fixed_time,
)
from olp.passes.timing.problem import PathProblem, speed_bounds
from olp.passes.timing.program import time_program, timing_pass
from olp.passes.timing.ptp import RUCKIG_MAX_DURATION, ptp_duration, ptp_profile
from olp.passes.timing.reachability import PathSolver, reachability_speeds
from olp.passes.timing.sweep import override_speeds, path_sweep, speed_sweep
from olp.passes.timing.tcp import tcp_rates

__all__ = [
    "DEFAULT_TIMES",
    "MIN_BLEND_M",
    "MIN_PATH_SPEED",
    "PATH_SOLVERS",
    "RUCKIG_MAX_DURATION",
    "ChainGeometry",
    "JointSpline",
    "LineProfiles",
    "PathProblem",
    "PathSolver",
    "TcpAngularSpeedConstraint",
    "TcpLinearSpeedConstraint",
    "TimingError",
    "TimingOptions",
    "chain_geometry",
    "fixed_time",
    "gridpoints",
    "joint_path",
    "line_profiles",
    "override_speeds",
    "path_problem",
    "path_sweep",
    "ptp_duration",
    "ptp_profile",
    "reachability_speeds",
    "speed_bounds",
    "speed_sweep",
    "straight_paths",
    "tcp_rates",
    "time_path",
    "time_program",
    "timing_pass",
]


def __getattr__(name: str) -> Any:
    """The toppra constraints, from the reference solver's module on first use (toppra imports
    matplotlib: a build that does not ask for the reference never loads it)."""
    if name in ("TcpLinearSpeedConstraint", "TcpAngularSpeedConstraint"):
        from olp.passes.timing import toppra_reference

        return getattr(toppra_reference, name)
    raise AttributeError(f"module 'olp.passes.timing' has no attribute {name!r}")
