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
  the TCP's rate ``|dp/ds|`` bounded over the move from five forward kinematics. A move whose
  bound on the excess over the optimal time is above ``line_tolerance`` (0.1%) goes to the
  solver; on the KR 6 cell at 50 mm/s that keeps moves up to ~2 mm on the closed form. A
  toolpath of 100,000 fine-stopped moves takes 2-4 s (benchmarks/timing_long.py) where one
  TOPPRA problem per move took minutes (and the toppra package finds no time law on its 0.1 mm
  moves). The closed form is nearer the optimum than the solver on its default grid, which
  has few gridpoints on a tiny move (1.2% slow on 0.5 mm moves; 0.007% on a grid 64x finer).
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
  a tool change, and any instruction other than a comment between two moves. **PTP zones and
  PTP-LIN blends are timed as stops**: a controller's joint-space blend follows rules no vendor
  publishes, and a state-to-state model would need a pass-through velocity that olp would have
  to guess. Such a program's estimate is an upper bound (shown in the summary).
* **Jerk on path moves** — TOPPRA limits acceleration, not jerk: each start or stop of a path
  chain is optimistic by at most ``a / (2 j)`` per joint limit (0.05 s on the KR 6 defaults),
  and usually by much less at programmed TCP speeds (``sqrt(v / J_path)``).
* **Other instructions** take :data:`DEFAULT_TIMES` seconds (a ``Wait`` its own time); override
  any kind, or a named call as ``"call:NAME"``, through ``other_times``.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING

import numpy as np
import toppra
import toppra.algorithm as algo
import toppra.constraint as constraint
from numpy.typing import NDArray
from ruckig import InputParameter, Result, Ruckig, RuckigError, Synchronization, Trajectory
from scipy.interpolate import CubicSpline, PPoly
from toppra.algorithm.algorithm import ParameterizationAlgorithm
from toppra.solverwrapper.cy_seidel_solverwrapper import seidelWrapper

from olp.compiled import CompiledProgram, Step
from olp.diagnostics import Diagnostic
from olp.geometry import rotation_log
from olp.ir import Call, CircularMove, Comment, Instruction, JointMove, LinearMove, Wait, is_motion
from olp.station.model import JointLimits, Robot
from olp.trajectory import JerkProfile, LineTimeLaw, PathTimeLaw, Segment

if TYPE_CHECKING:
    from olp.passes.pipeline import BuildOptions

FloatArray = NDArray[np.float64]

DEFAULT_TIMES: Mapping[str, float] = MappingProxyType(
    {
        # One interpolation cycle of a KUKA KR C4/C5 (12 ms), the controller olp posts for
        # today: an output set between moves delays the next motion by about one cycle.
        "set_output": 0.012,
        # The input is assumed already set; reading it takes one cycle.
        "wait_input": 0.012,
        # A called routine's content is unknown: nothing is charged unless told ("call:NAME").
        "call": 0.0,
        "comment": 0.0,
    }
)
"""Seconds charged for non-motion instructions, by kind; override through ``other_times``."""

MIN_BLEND_M = 1e-6
"""Blend distances (m) below this make the corner a stop."""

_X_CAP = 1e12
"""Stand-in for 'no bound' on TOPPRA's squared path speed."""


@dataclass(frozen=True, slots=True)
class TimingOptions:
    """Discretisation and solvers of path moves.

    ``grid_per_sample``: TOPPRA gridpoints per interval of resolved samples (at least);
    ``max_grid_step_rad``: largest joint change between gridpoints; ``max_grid_turn_rad``:
    largest turn of the joint path's direction between gridpoints; ``refine_points``:
    gridpoints placed geometrically on each side of every stop and instruction boundary;
    ``blend_samples``: least number of samples on a blend curve (odd: its midpoint is one);
    more where the blend turns (one per 4° of joint-space turn).

    ``solver``: what finds a chain's path speeds on the grid, a key of :data:`PATH_SOLVERS`
    (``"reachability"``: TOPPRA's recursion vectorised in numpy; ``"toppra"``: the toppra
    package, kept as the reference). ``straight_lines``: time a stop-to-stop path move along a
    straight joint-space line in closed form (:func:`line_profiles`) where its error bound is
    below ``line_tolerance`` (relative excess over the time-optimal duration);
    ``line_deviation_rad``: how far a move's samples may lie off the chord of its joint path
    and still count as one straight line.
    """

    grid_per_sample: int = 2
    max_grid_step_rad: float = float(np.radians(0.5))
    max_grid_turn_rad: float = float(np.radians(1.0))
    refine_points: int = 24
    blend_samples: int = 5
    solver: str = "reachability"
    straight_lines: bool = True
    # 0.1%: a tenth of what the solver's default grid may be off on such short moves.
    line_tolerance: float = 1e-3
    # 1e-7 rad moves a TCP 1 m from the axes by 0.1 um: far below the resolve pass's own
    # sampling error, so the chord and the samples are the same path.
    line_deviation_rad: float = 1e-7


class TimingError(Exception):
    """A motion could not be timed (reported as a diagnostic by :func:`time_program`)."""


# --------------------------------------------------------------------------------------------
# The pass


def time_program(
    compiled: CompiledProgram,
    other_times: Mapping[str, float] | None = None,
    options: TimingOptions | None = None,
) -> CompiledProgram:
    """A copy of ``compiled`` whose steps carry ``duration`` (s), ``path_length`` (m of TCP
    travel) and, for motions, ``trajectory`` (a :class:`olp.trajectory.Segment`).

    Zones timed as stops add an ``info`` diagnostic (kind ``zone_stop``); a motion that cannot
    be timed keeps duration 0 and adds an ``error`` (kind ``timing``). Never raises on a bad
    program.
    """
    lengths = tcp_lengths(compiled)
    units = plan_units(compiled, lengths)
    context = _Context(compiled, _time_table(other_times), options or TimingOptions(), lengths)
    steps, found = _time_units(context, units)
    found += _overflow(steps)
    return dataclasses.replace(
        compiled,
        steps=tuple(steps),
        diagnostics=compiled.diagnostics + tuple(found) + tuple(_zone_stops(compiled, units)),
    )


def _overflow(steps: Sequence[Step]) -> list[Diagnostic]:
    """An error at the instruction where the running cycle time stops being a finite number
    (each duration is finite, their sum need not be: two waits of 1e308 s)."""
    with np.errstate(over="ignore"):
        total = np.cumsum([step.duration for step in steps])
    bad = np.flatnonzero(~np.isfinite(total))
    if bad.size == 0:
        return []
    step = steps[int(bad[0])]
    msg = "the cycle time up to here exceeds the largest number olp can represent"
    return [Diagnostic("error", "timing", msg, step.instruction.span, step.index)]


def _time_table(other_times: Mapping[str, float] | None) -> dict[str, float]:
    table = {**DEFAULT_TIMES, **(other_times or {})}
    return {key.casefold(): float(value) for key, value in table.items()}


@dataclass(frozen=True, slots=True)
class _Context:
    """What every unit is timed with: the program, the time table (casefolded kinds), the
    options and the TCP travel (m) of every resolved motion's samples, by instruction index."""

    compiled: CompiledProgram
    times: Mapping[str, float]
    options: TimingOptions
    lengths: Mapping[int, float]


def _time_units(context: _Context, units: Sequence[Unit]) -> tuple[list[Step], list[Diagnostic]]:
    steps = list(context.compiled.steps)
    lines, rest = _time_lines(context, units)
    chains, found = _time_chains(context, [u for u in rest if u.kind == "path"])
    for step in lines + chains:
        steps[step.index] = step
    for unit in rest:
        if unit.kind == "path":
            continue
        try:
            for step in _UNIT_TIMERS[unit.kind](unit, context):
                steps[step.index] = step
        except TimingError as exc:
            first = steps[unit.indices[0]].instruction
            found.append(Diagnostic("error", "timing", str(exc), first.span, unit.indices[0]))
    return steps, sorted(found, key=lambda d: d.index if d.index is not None else -1)


@dataclass(frozen=True, slots=True)
class Unit:
    """Instructions timed together: ``kind`` ``"joint"``, ``"path"`` (a chain of path moves;
    ``blends``: the blend distance (m) at each inner corner) or ``"fixed"``."""

    kind: str
    indices: tuple[int, ...]
    blends: tuple[float, ...] = ()


def plan_units(compiled: CompiledProgram, lengths: Mapping[int, float] | None = None) -> list[Unit]:
    """Split a program into timing units: chains of blended path moves, joint moves, and
    instructions of fixed time. Comments inside a chain become fixed units after it.
    ``lengths``: :func:`tcp_lengths` of the program, if already computed."""
    lengths = tcp_lengths(compiled) if lengths is None else lengths
    units: list[Unit] = []
    chain: list[Step] = []
    blends: list[float] = []
    inside: list[Unit] = []
    for step in compiled.steps:
        if chain and isinstance(step.instruction, Comment):
            inside.append(Unit("fixed", (step.index,)))
            continue
        if chain and _is_path(step) and (d := _blend_distance(chain[-1], step, lengths)) > 0:
            chain.append(step)
            blends.append(d)
            continue
        if chain:
            units += [Unit("path", tuple(s.index for s in chain), tuple(blends)), *inside]
            chain, blends, inside = [], [], []
        if _is_path(step):
            chain = [step]
        else:
            units.append(Unit(_unit_kind(step), (step.index,)))
    if chain:
        units += [Unit("path", tuple(s.index for s in chain), tuple(blends)), *inside]
    return units


def _is_path(step: Step) -> bool:
    return isinstance(step.instruction, LinearMove | CircularMove) and _resolved(step)


def _resolved(step: Step) -> bool:
    return step.path is not None and step.tool is not None and step.tool.pose is not None


def _unit_kind(step: Step) -> str:
    return "joint" if isinstance(step.instruction, JointMove) and _resolved(step) else "fixed"


def _blend_distance(before: Step, after: Step, lengths: Mapping[int, float]) -> float:
    """The corner cut (m of TCP travel) between two resolved path moves; 0 means a stop."""
    zone = before.instruction.zone if is_motion(before.instruction) else None
    if zone is None or zone.is_fine or not _same_tool(before, after):
        return 0.0
    d = min(zone.radius, lengths[before.index] / 2, lengths[after.index] / 2)
    return d if d >= MIN_BLEND_M else 0.0


def _same_tool(a: Step, b: Step) -> bool:
    assert a.tool is not None and a.tool.pose is not None
    assert b.tool is not None and b.tool.pose is not None
    return a.tool.pose is b.tool.pose or bool(np.array_equal(a.tool.pose, b.tool.pose))


_FK_ROWS = 1 << 18
"""Joint samples per forward-kinematics batch in :func:`tcp_lengths` (bounds memory)."""


def tcp_lengths(compiled: CompiledProgram) -> dict[int, float]:
    """TCP travel (m) along every resolved motion's samples (the polyline through them), by
    instruction index; forward kinematics in batches of about ``_FK_ROWS`` samples."""
    motions = [
        (s.index, s.path, s.tool.pose)
        for s in compiled.steps
        if is_motion(s.instruction)
        and s.path is not None
        and s.tool is not None
        and s.tool.pose is not None
    ]
    sizes = np.array([len(path) for _, path, _ in motions], dtype=np.int64)
    batch = (np.cumsum(sizes) - sizes) // _FK_ROWS
    edges = [0, *(np.flatnonzero(np.diff(batch)) + 1).tolist(), len(motions)]
    out: dict[int, float] = {}
    for lo, hi in itertools.pairwise(edges):  # a few batches
        out.update(_batch_lengths(motions[lo:hi], compiled.station.robot))
    return out


def _batch_lengths(
    motions: list[tuple[int, FloatArray, FloatArray]], robot: Robot
) -> dict[int, float]:
    """TCP travel (m) of motions given as (index, joint samples (S, dof), tool pose (4, 4))."""
    if not motions:
        return {}
    sizes = np.array([len(path) for _, path, _ in motions], dtype=np.int64)
    joints = np.concatenate([path for _, path, _ in motions])
    tools = np.repeat(np.stack([tool for _, _, tool in motions]), sizes, axis=0)
    with np.errstate(over="ignore", invalid="ignore"):  # a tool 1e308 m long: inf, no warning
        positions = (robot.flange_poses(joints) @ tools)[:, :3, 3]
        steps = np.linalg.norm(np.diff(positions, axis=0), axis=-1)
        travel = np.concatenate([[0.0], np.cumsum(steps)])
        ends = np.cumsum(sizes) - 1
        lengths = travel[ends] - travel[ends - sizes + 1]
    return {index: float(length) for (index, _, _), length in zip(motions, lengths, strict=True)}


def _zone_stops(compiled: CompiledProgram, units: Sequence[Unit]) -> list[Diagnostic]:
    """An info diagnostic for every zone that the model times as an exact stop although a
    motion follows (after the last motion the robot stops anyway)."""
    blended = {i for u in units for i in u.indices[:-1] if u.kind == "path"}
    motions = [s.index for s in compiled.steps if is_motion(s.instruction)]
    found = []
    for step in compiled.steps:
        ins = step.instruction
        if not is_motion(ins) or ins.zone.is_fine or step.index in blended:
            continue
        if step.path is None or step.index == motions[-1]:
            continue
        msg = (
            f"zone of {ins.zone.radius * 1000:g} mm timed as an exact stop "
            f"({_STOP_REASON[ins.kind]}): the cycle time is an upper bound here"
        )
        found.append(Diagnostic("info", "zone_stop", msg, ins.span, step.index))
    return found


_PATH_STOP = "the next motion is not a path move with the same tool, or the corner is too short"
_STOP_REASON = {
    "joint": "olp does not model joint-move blending",
    "linear": _PATH_STOP,
    "circular": _PATH_STOP,
}


# --------------------------------------------------------------------------------------------
# Fixed-time instructions


def fixed_time(instruction: Instruction, times: Mapping[str, float]) -> float:
    """Seconds charged for a non-motion instruction (or an unresolved motion: 0)."""
    if isinstance(instruction, Wait):
        return instruction.seconds
    if isinstance(instruction, Call) and f"call:{instruction.name}".casefold() in times:
        return times[f"call:{instruction.name}".casefold()]
    return times.get(instruction.kind, 0.0) if not is_motion(instruction) else 0.0


def _time_fixed(unit: Unit, context: _Context) -> list[Step]:
    step = context.compiled.steps[unit.indices[0]]
    duration = fixed_time(step.instruction, context.times)
    return [dataclasses.replace(step, duration=duration, path_length=0.0, trajectory=None)]


# --------------------------------------------------------------------------------------------
# Joint moves: Ruckig


def _time_joint(unit: Unit, context: _Context) -> list[Step]:
    step = context.compiled.steps[unit.indices[0]]
    ins = step.instruction
    assert isinstance(ins, JointMove) and step.path is not None
    robot = context.compiled.station.robot
    profile = ptp_profile(
        step.path[0], step.path[-1], robot, ins.speed.joint, ins.speed.joint_acceleration
    )
    segment = Segment(profile, 0.0, profile.duration)
    length = context.lengths[step.index]
    return [
        dataclasses.replace(step, duration=profile.duration, path_length=length, trajectory=segment)
    ]


def ptp_profile(
    q0: FloatArray,
    q1: FloatArray,
    robot: Robot,
    velocity_scale: float = 1.0,
    accel_scale: float = 1.0,
) -> JerkProfile:
    """The rest-to-rest, phase-synchronised, jerk-limited joint move from ``q0`` to ``q1``
    (both (dof,) rad) with Ruckig, state to state (no intermediate waypoints).

    Limits: the robot's velocity x ``velocity_scale``, acceleration x ``accel_scale``, jerk.
    """
    dof = q0.size
    if np.max(np.abs(q1 - q0)) <= 1e-12:
        return JerkProfile.at_rest(q1)
    _check_ptp_duration(q0, q1, robot, velocity_scale, accel_scale)
    inp = InputParameter(dof)
    inp.current_position = q0.tolist()
    inp.target_position = q1.tolist()
    inp.current_velocity = inp.current_acceleration = [0.0] * dof
    inp.target_velocity = inp.target_acceleration = [0.0] * dof
    inp.max_velocity = (robot.limits.velocity * velocity_scale).tolist()
    inp.max_acceleration = (robot.limits.acceleration * accel_scale).tolist()
    inp.max_jerk = robot.limits.jerk.tolist()
    # Phase synchronisation keeps the move on the straight joint-space line that the resolve
    # pass sampled; for rest-to-rest moves it costs no time against time synchronisation.
    inp.synchronization = Synchronization.Phase
    trajectory = Trajectory(dof)
    try:
        result = Ruckig(dof).calculate(inp, trajectory)
    except (RuckigError, ValueError) as exc:
        # Ruckig raises on inputs it rejects, and its binding raises ValueError for result
        # codes it has no name for (-101: the duration is beyond its numerical range).
        first_line = next((line for line in str(exc).splitlines() if line.strip()), "")
        raise TimingError(f"Ruckig could not time the joint move: {first_line}") from exc
    if result not in (Result.Working, Result.Finished):
        raise TimingError(f"Ruckig could not time the joint move ({result.name})")
    return _jerk_profile(trajectory)


RUCKIG_MAX_DURATION = 7.6e3
"""Longest joint move (s) Ruckig times: measured with ruckig 0.19, a move of 7,600 s is timed
and a longer one returns its code -101 (trajectory duration beyond its numerical limits)."""


def _check_ptp_duration(
    q0: FloatArray, q1: FloatArray, robot: Robot, velocity_scale: float, accel_scale: float
) -> None:
    """Raise :class:`TimingError` if the joint move cannot take less than
    :data:`RUCKIG_MAX_DURATION`: its time-optimal duration under the velocity and acceleration
    limits alone (a trapezoid per axis; jerk limits only add time) is a lower bound."""
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        velocity = robot.limits.velocity * velocity_scale
        accel = robot.limits.acceleration * accel_scale
        least = float(np.max(_trapezoid(np.abs(q1 - q0), velocity, accel)[1]))
    if least <= RUCKIG_MAX_DURATION:
        return
    raise TimingError(
        f"the joint move would take at least {least:.4g} s at {velocity_scale * 100:.3g}% of "
        f"the axes' speed and {accel_scale * 100:.3g}% of their acceleration: longer than the "
        f"{RUCKIG_MAX_DURATION:g} s a joint move can be timed (Ruckig); raise the joint speed"
    )


def _jerk_profile(trajectory: Trajectory) -> JerkProfile:
    """Ruckig's per-axis seven-phase profiles as arrays (rest to rest: no brake phases)."""
    profiles = trajectory.profiles[0]
    if any(p.brake.duration > 0 for p in profiles):
        raise TimingError("Ruckig returned a braking phase for a move from rest")
    durations = np.array([p.t for p in profiles], dtype=np.float64)
    return JerkProfile(
        starts=np.concatenate([np.zeros((len(profiles), 1)), np.cumsum(durations, 1)], axis=1),
        jerk=np.array([p.j for p in profiles], dtype=np.float64),
        q=np.array([p.p for p in profiles], dtype=np.float64),
        qd=np.array([p.v for p in profiles], dtype=np.float64),
        qdd=np.array([p.a for p in profiles], dtype=np.float64),
    )


def ptp_duration(
    q0: FloatArray,
    q1: FloatArray,
    robot: Robot,
    velocity_scale: float = 1.0,
    accel_scale: float = 1.0,
) -> float:
    """Duration (s) of :func:`ptp_profile`."""
    return ptp_profile(q0, q1, robot, velocity_scale, accel_scale).duration


# --------------------------------------------------------------------------------------------
# Path moves along a straight joint line: closed form, all moves at once


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
    ramp, duration = _trapezoid(length, slow, accel)
    best = _trapezoid(length, fast, accel)[1]
    return LineProfiles(
        accel=accel / length, ramp=ramp, duration=duration, excess=duration / best - 1.0
    )


def _trapezoid(length: FloatArray, peak: FloatArray, accel: FloatArray) -> tuple[FloatArray, ...]:
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
    poses = _tcp_poses(robot, joints, np.concatenate([tools] * 5))
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


def _tcp_poses(robot: Robot, joints: FloatArray, tools: FloatArray) -> FloatArray:
    """TCP poses (N, 4, 4) in the world for joints (N, dof) rad and tools (N, 4, 4) or one
    (4, 4); forward kinematics in batches of ``_FK_ROWS`` rows (bounds memory)."""
    parts = [
        robot.flange_poses(joints[lo : lo + _FK_ROWS])
        @ (tools[lo : lo + _FK_ROWS] if tools.ndim == 3 else tools)
        for lo in range(0, len(joints), _FK_ROWS)
    ]
    return np.concatenate(parts) if parts else np.zeros((0, 4, 4))


def _tcp_positions(robot: Robot, joints: FloatArray, tools: FloatArray) -> FloatArray:
    """TCP positions (N, 3) m in the world, as :func:`_tcp_poses` (without its rotations)."""
    parts = []
    for lo in range(0, len(joints), _FK_ROWS):
        flange = robot.flange_poses(joints[lo : lo + _FK_ROWS])
        if tools.ndim == 3:
            offset = np.einsum("nij,nj->ni", flange[:, :3, :3], tools[lo : lo + _FK_ROWS, :3, 3])
        else:
            offset = flange[:, :3, :3] @ tools[:3, 3]
        parts.append(flange[:, :3, 3] + offset)
    return np.concatenate(parts) if parts else np.zeros((0, 3))


def straight_paths(paths: Sequence[FloatArray], deviation: float) -> NDArray[np.bool_]:
    """Whether each joint path (S_k, dof) rad is its chord: every sample within ``deviation``
    rad of the straight line from its first to its last sample, in order along it, and the
    chord longer than :data:`_MIN_LINE_RAD`. Vectorised over all samples of all paths."""
    sizes = np.array([len(path) for path in paths], dtype=np.int64)
    if sizes.size == 0:
        return np.zeros(0, dtype=bool)
    q = np.concatenate(paths)
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


def _time_lines(context: _Context, units: Sequence[Unit]) -> tuple[list[Step], list[Unit]]:
    """Time every stop-to-stop path move along a straight joint line in closed form, all at
    once; returns the timed steps and the units left for the other timers (the rest, and the
    lines whose error bound exceeds ``line_tolerance``)."""
    opts, all_steps = context.options, context.compiled.steps
    # A move below MIN_PATH_SPEED goes to the chain timer, which reports it.
    singles = [
        u
        for u in units
        if u.kind == "path" and len(u.indices) == 1 and not _below_floor(all_steps[u.indices[0]])
    ]
    if not opts.straight_lines or not singles:
        return [], list(units)
    paths = [all_steps[u.indices[0]].path for u in singles]
    straight = straight_paths(paths, opts.line_deviation_rad)  # type: ignore[arg-type]
    candidates = [u for u, ok in zip(singles, straight, strict=True) if ok]
    if not candidates:
        return [], list(units)
    steps = [all_steps[u.indices[0]] for u in candidates]
    profiles = _step_profiles(steps, context.compiled.station.robot)
    accepted = profiles.excess <= opts.line_tolerance
    timed = [
        _line_step(step, profiles, k, context.lengths[step.index])
        for k, step in enumerate(steps)
        if accepted[k]
    ]
    done = {step.index for step, ok in zip(steps, accepted, strict=True) if ok}
    return timed, [u for u in units if u.indices[0] not in done]


def _step_profiles(steps: Sequence[Step], robot: Robot) -> LineProfiles:
    """:func:`line_profiles` of resolved path moves along straight joint lines."""
    paths = [s.path for s in steps if s.path is not None]
    tools = [s.tool.pose for s in steps if s.tool is not None and s.tool.pose is not None]
    speeds = [s.instruction.speed for s in steps if is_motion(s.instruction)]
    return line_profiles(
        np.stack([path[0] for path in paths]),
        np.stack([path[-1] for path in paths]),
        robot,
        np.stack(tools),
        np.array([sp.linear for sp in speeds], dtype=np.float64),
        np.array([np.inf if sp.angular is None else sp.angular for sp in speeds]),
    )


def _line_step(step: Step, profiles: LineProfiles, k: int, length: float) -> Step:
    """``step`` timed by the k-th of ``profiles``."""
    assert step.path is not None
    law = LineTimeLaw(
        q0=step.path[0],
        q1=step.path[-1],
        accel=float(profiles.accel[k]),
        ramp=float(profiles.ramp[k]),
        total=float(profiles.duration[k]),
    )
    return dataclasses.replace(
        step, duration=law.total, path_length=length, trajectory=Segment(law, 0.0, law.total)
    )


# --------------------------------------------------------------------------------------------
# Path moves: geometry of a chain, vectorised over its moves


@dataclass(frozen=True, slots=True, eq=False)
class ChainGeometry:
    """The joint path of a chain of path moves, corners rounded.

    ``s`` (S,): the path parameter at the samples, joint-space chord length in rad;
    ``q`` (S, dof): joint samples; ``boundaries`` (M+1,): ``s`` at the chain's start, at each
    instruction boundary (blend midpoints) and at its end; ``lengths`` (M,): TCP travel per
    instruction, m.
    """

    s: FloatArray
    q: FloatArray
    boundaries: FloatArray
    lengths: FloatArray


@dataclass(frozen=True, slots=True, eq=False)
class _Samples:
    """The samples of M moves end to end: ``q`` (S, dof) rad; ``arc`` (S,) m of TCP travel
    from each move's first sample; ``first`` and ``sizes`` (M,): each move's first row and
    sample count; ``move`` (S,): each row's move."""

    q: FloatArray
    arc: FloatArray
    first: NDArray[np.int64]
    sizes: NDArray[np.int64]
    move: NDArray[np.int64]

    @classmethod
    def of(cls, paths: Sequence[FloatArray], robot: Robot, tool: FloatArray) -> _Samples:
        sizes = np.array([len(path) for path in paths], dtype=np.int64)
        q = np.concatenate(paths)
        first = np.cumsum(sizes) - sizes
        move = np.repeat(np.arange(sizes.size), sizes)
        steps = np.linalg.norm(np.diff(_tcp_positions(robot, q, tool), axis=0), axis=-1)
        steps[first[1:] - 1] = 0.0  # from one move's last sample to the next one's first
        travel = np.concatenate([[0.0], np.cumsum(steps)])
        return cls(q, travel - travel[first][move], first, sizes, move)

    @property
    def lengths(self) -> FloatArray:
        """TCP travel (M,) m along each move's samples."""
        return self.arc[self.first + self.sizes - 1]

    def cut(self, which: NDArray[np.int64], at: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Joints (n, dof) at TCP travel ``at`` (n,) m along moves ``which`` (n,) (linear
        between samples), and the tangents dq/d(travel) (n, dof) rad/m there."""
        below = _count_at_most(self.move, self.arc, which, at) - self.first[which]
        lo = self.first[which]
        i = np.clip(lo + below - 1, lo, lo + self.sizes[which] - 2)
        width = np.maximum(self.arc[i + 1] - self.arc[i], 1e-15)  # repeated samples
        delta = self.q[i + 1] - self.q[i]
        return self.q[i] + ((at - self.arc[i]) / width)[:, None] * delta, delta / width[:, None]

    def spacing(self) -> FloatArray:
        """Median TCP travel (M,) m between consecutive samples of each move."""
        count = self.sizes - 1
        keep = np.ones(self.arc.size - 1, dtype=bool)
        keep[self.first[1:] - 1] = False
        values = np.diff(self.arc)[keep]
        ordered = values[np.lexsort((values, np.repeat(np.arange(count.size), count)))]
        start = np.cumsum(count) - count
        return 0.5 * (ordered[start + (count - 1) // 2] + ordered[start + count // 2])


def _count_at_most(
    groups: NDArray[np.int64], values: FloatArray, which: NDArray[np.int64], at: FloatArray
) -> NDArray[np.int64]:
    """For each query (``which[k]``, ``at[k]``), the number of entries before it: those of
    lower groups and those of group ``which[k]`` whose value is at most ``at[k]`` (``groups``
    (S,) nondecreasing, ``values`` (S,) nondecreasing within a group). A searchsorted per
    group, done by one sort of entries and queries together (entries first on ties)."""
    size = groups.size
    order = np.lexsort(
        (
            np.concatenate([np.zeros(size), np.ones(at.size)]),
            np.concatenate([values, at]),
            np.concatenate([groups, which]),
        )
    )
    is_query = order >= size
    position = np.flatnonzero(is_query)
    counts = np.empty(at.size, dtype=np.int64)
    counts[order[position] - size] = position - np.arange(position.size)
    return counts


def chain_geometry(
    paths: Sequence[FloatArray],
    robot: Robot,
    tool: FloatArray,
    blends: Sequence[float],
    blend_samples: int = 5,
) -> ChainGeometry:
    """Join the sampled joint paths (S_k, dof) of M moves, cutting each inner corner at
    ``blends[k]`` m of TCP travel on both sides and joining the cuts by a blend curve.
    Vectorised over the moves (two forward kinematics calls for the whole chain)."""
    samples = _Samples.of(paths, robot, tool)
    moves = np.arange(len(paths))
    d = np.asarray(blends, dtype=np.float64)
    enter = np.concatenate([[0.0], d])
    leave = samples.lengths - np.concatenate([d, [0.0]])
    entries, exits = samples.cut(moves, enter), samples.cut(moves, leave)
    start = (exits[0][:-1], exits[1][:-1])
    end = (entries[0][1:], entries[1][1:])
    counts = _blend_counts(start[1], end[1], d, samples.spacing(), blend_samples)
    curves = _blend_curves(start, end, d, counts)
    inner = (samples.arc > enter[samples.move] + 1e-9) & (samples.arc < leave[samples.move] - 1e-9)
    q, marks = _assemble(samples, inner, entries[0], exits[0], curves, counts - 2)
    return _geometry(q, marks, robot, tool)


_BLEND_TURN_PER_SAMPLE = float(np.radians(4.0))


def _blend_counts(
    t0: FloatArray, t3: FloatArray, d: FloatArray, spacing: FloatArray, least: int
) -> NDArray[np.int64]:
    """Samples (M-1,) on each blend, odd (the midpoint is one): at least ``least``; one per 4°
    between the joint-space tangents ``t0``, ``t3`` (M-1, dof) plus 3 (the gridpoints then
    subdivide to 1°; a cubic spline through these samples follows the cubic blend curve
    closely); and no sparser than the two moves' own samples (``spacing`` (M,) m)."""
    cos = np.sum(t0 * t3, axis=-1) / np.maximum(
        np.linalg.norm(t0, axis=-1) * np.linalg.norm(t3, axis=-1), 1e-300
    )
    turn = np.ceil(np.arccos(np.clip(cos, -1.0, 1.0)) / _BLEND_TURN_PER_SAMPLE).astype(np.int64)
    space = np.minimum(spacing[:-1], spacing[1:])
    dense = np.ceil(2 * d / np.maximum(space, 1e-9)).astype(np.int64) + 1
    count = np.maximum.reduce([np.full(d.size, least, dtype=np.int64), turn + 3, dense])
    return count + 1 - count % 2


def _blend_curves(
    start: tuple[FloatArray, FloatArray],
    end: tuple[FloatArray, FloatArray],
    d: FloatArray,
    counts: NDArray[np.int64],
) -> FloatArray:
    """Inner samples (sum(counts - 2), dof) of the joint-space cubic Beziers from the cuts
    ``start`` to the cuts ``end`` (each joints and tangents (M-1, dof)): control points 2/3 of
    ``d`` along the tangents, i.e. the cubic form of the parabola whose middle control point is
    the corner."""
    (p0, t0), (p3, t3) = start, end
    p1 = p0 + ((2.0 / 3.0) * d)[:, None] * t0
    p2 = p3 - ((2.0 / 3.0) * d)[:, None] * t3
    inner = counts - 2
    owner = np.repeat(np.arange(inner.size), inner)
    j = np.arange(int(inner.sum())) - np.repeat(np.cumsum(inner) - inner, inner) + 1
    u = (j * (1.0 / (counts - 1))[owner])[:, None]  # as np.linspace(0, 1, count)[1:-1]
    v = 1.0 - u
    curve: FloatArray = (
        v**3 * p0[owner] + 3 * v**2 * u * p1[owner] + 3 * v * u**2 * p2[owner] + u**3 * p3[owner]
    )
    return curve


def _assemble(
    samples: _Samples,
    inner: NDArray[np.bool_],
    entries: FloatArray,
    exits: FloatArray,
    curves: FloatArray,
    curve_sizes: NDArray[np.int64],
) -> tuple[FloatArray, NDArray[np.int64]]:
    """The chain's rows in order — per move its entry cut, its ``inner`` samples and its exit
    cut, then the blend curve to the next move — and the marks (M+1,): the first row, each
    blend curve's middle row and the last row."""
    kept = np.bincount(samples.move[inner], minlength=samples.sizes.size)
    blocks = np.zeros(2 * samples.sizes.size - 1, dtype=np.int64)
    blocks[0::2], blocks[1::2] = kept + 2, curve_sizes
    offsets = np.cumsum(blocks) - blocks
    section, curve = offsets[0::2], offsets[1::2]
    q = np.empty((int(blocks.sum()), samples.q.shape[1]))
    q[section], q[section + kept + 1] = entries, exits
    rank = np.cumsum(inner) - 1
    move = samples.move[inner]
    q[section[move] + 1 + rank[inner] - (np.cumsum(kept) - kept)[move]] = samples.q[inner]
    owner = np.repeat(np.arange(curve_sizes.size), curve_sizes)
    within = np.arange(owner.size) - np.repeat(np.cumsum(curve_sizes) - curve_sizes, curve_sizes)
    q[curve[owner] + within] = curves
    marks = np.concatenate([[0], curve + curve_sizes // 2, [len(q) - 1]])
    return q, marks.astype(np.int64)


def _geometry(
    q: FloatArray, marks: NDArray[np.int64], robot: Robot, tool: FloatArray
) -> ChainGeometry:
    """Drop repeated samples, parameterise by joint chord length, measure TCP travel."""
    steps = np.linalg.norm(np.diff(q, axis=0), axis=-1)
    keep = np.concatenate([[True], steps > 1e-12])
    rows = np.cumsum(keep) - 1  # each old row's index among the kept ones
    q = q[keep]
    s = np.concatenate([[0.0], np.cumsum(steps[keep[1:]])])
    arc = _arc(_tcp_positions(robot, q, tool))
    at = rows[marks]
    return ChainGeometry(s=s, q=q, boundaries=s[at], lengths=np.diff(arc[at]))


def _arc(positions: FloatArray) -> FloatArray:
    """Cumulative polyline length (S,) m through positions (S, 3)."""
    steps = np.linalg.norm(np.diff(positions, axis=0), axis=-1)
    return np.concatenate([[0.0], np.cumsum(steps)])


@dataclass(frozen=True, slots=True, eq=False)
class JointSpline:
    """A joint path ``q(s)``: piecewise cubic polynomials for the path and its first two
    derivatives. ``path(s, order)`` (N, dof); ``dof`` and ``path_interval`` as toppra's
    geometric paths have them (the toppra reference solver takes this path)."""

    pieces: tuple[PPoly, PPoly, PPoly]

    def __call__(self, s: FloatArray, order: int = 0) -> FloatArray:
        out: FloatArray = self.pieces[order](s)
        return out

    @property
    def dof(self) -> int:
        return int(self.pieces[0].c.shape[-1])

    @property
    def path_interval(self) -> FloatArray:
        return np.asarray(self.pieces[0].x[[0, -1]], dtype=np.float64)


def joint_path(geometry: ChainGeometry) -> JointSpline:
    """The cubic spline q(s) (not-a-knot) through a chain's samples: scipy's, except through
    three samples, where it is the parabola, built here (scipy solves that case with a dense
    solver that cost up to 5 ms a call on a busy 2-core machine, ~0.1 ms for other counts)."""
    s, q = geometry.s, geometry.q
    spline = _parabola(s, q) if s.size == 3 else CubicSpline(s, q)
    first = spline.derivative()
    return JointSpline((spline, first, first.derivative()))


def _parabola(s: FloatArray, q: FloatArray) -> PPoly:
    """The parabola through three samples (s (3,), q (3, dof)) as a piecewise cubic."""
    h = np.diff(s)
    slope = np.diff(q, axis=0) / h[:, None]
    curve = 2.0 * (slope[1] - slope[0]) / (h[0] + h[1])  # q''
    start = slope[0] - 0.5 * curve * h[0]  # q'(s0)
    rates = np.stack([start, start + curve * h[0]])
    zeros = np.zeros_like(rates)
    coefficients = np.stack([zeros, np.broadcast_to(0.5 * curve, rates.shape), rates, q[:2]])
    return PPoly(coefficients, s)


# --------------------------------------------------------------------------------------------
# Path moves: a time-optimal time law along a chain


def _time_chains(context: _Context, units: Sequence[Unit]) -> tuple[list[Step], list[Diagnostic]]:
    """Time chains of path moves: their geometry one by one, their time laws by
    ``options.solver`` all at once."""
    robot, opts = context.compiled.station.robot, context.options
    done: list[Step] = []
    found: list[Diagnostic] = []
    posed: list[tuple[list[Step], ChainGeometry, PathProblem]] = []
    for unit in units:
        steps = [context.compiled.steps[i] for i in unit.indices]
        tool = steps[0].tool.pose if steps[0].tool is not None else None
        assert tool is not None
        given = [s.instruction.speed for s in steps if is_motion(s.instruction)]
        linear = np.array([sp.linear for sp in given], dtype=np.float64)
        angular = np.array([np.inf if sp.angular is None else sp.angular for sp in given])
        slow = _too_slow(steps, linear, angular)
        if slow is not None:
            found.append(slow)
            continue
        paths = [s.path for s in steps if s.path is not None]
        geometry = chain_geometry(paths, robot, tool, unit.blends, opts.blend_samples)
        if geometry.s[-1] <= 0.0:  # no joint moves: the TCP stays put
            done += [dataclasses.replace(s, duration=0.0, path_length=0.0) for s in steps]
            continue
        posed.append((steps, geometry, path_problem(geometry, tool, linear, angular, opts)))
    speeds = PATH_SOLVERS[opts.solver]([problem for _, _, problem in posed], robot)
    for (steps, geometry, problem), sd in zip(posed, speeds, strict=True):
        try:
            done += _timed_chain(steps, geometry, _time_law(problem, sd))
        except TimingError as exc:
            span = steps[0].instruction.span
            found.append(Diagnostic("error", "timing", str(exc), span, steps[0].index))
    return done, found


MIN_PATH_SPEED = 1e-150
"""Slowest TCP speed (m/s, and rad/s for an orientation speed) a path move is timed at. The
solver works with the squared path speed ``(v / rate)²``, rate up to ~10 m/rad: below this it
would leave the normal float range (2.2e-308) and the time law would lose its digits, then
vanish (measured: 1e-160 m/s timed 5e-7 off, 1e-300 m/s found no time law)."""


def _below_floor(step: Step) -> bool:
    """Whether a path move's programmed speed is below :data:`MIN_PATH_SPEED`."""
    speed = step.instruction.speed if is_motion(step.instruction) else None
    if speed is None:
        return False
    angular = np.inf if speed.angular is None else speed.angular
    return bool(speed.linear < MIN_PATH_SPEED or angular < MIN_PATH_SPEED)


def _too_slow(steps: Sequence[Step], linear: FloatArray, angular: FloatArray) -> Diagnostic | None:
    """The error for a chain with a programmed speed below :data:`MIN_PATH_SPEED`."""
    slow = np.flatnonzero((linear < MIN_PATH_SPEED) | (angular < MIN_PATH_SPEED))
    if slow.size == 0:
        return None
    k = int(slow[0])
    which, value, unit = (
        ("TCP speed", linear[k] * 1000, "mm/s")
        if linear[k] < MIN_PATH_SPEED
        else ("orientation speed", np.degrees(angular[k]), "°/s")
    )
    msg = (
        f"the programmed {which} of {value:.3g} {unit} is too low to time (the slowest olp "
        f"times is {MIN_PATH_SPEED:g} m/s or rad/s)"
    )
    return Diagnostic("error", "timing", msg, steps[k].instruction.span, steps[k].index)


def _timed_chain(steps: Sequence[Step], geometry: ChainGeometry, law: PathTimeLaw) -> list[Step]:
    """The chain's steps with their share of ``law``: durations between the boundaries."""
    edges = law.time_at(geometry.boundaries)
    return [
        dataclasses.replace(
            step,
            duration=float(edges[k + 1] - edges[k]),
            path_length=float(geometry.lengths[k]),
            trajectory=Segment(law, float(edges[k]), float(edges[k + 1])),
        )
        for k, step in enumerate(steps)
    ]


@dataclass(frozen=True, slots=True, eq=False)
class PathProblem:
    """One chain to time, rest to rest: its joint path, gridpoints ``grid`` (K,) and, at them,
    the TCP's linear (m/s) and orientation (rad/s, ``inf``: none) speed limits (K,) each, for
    the tool ``tool`` (4, 4) (TCP in flange). Joint limits are the robot's."""

    path: JointSpline
    grid: FloatArray
    tool: FloatArray
    linear: FloatArray
    angular: FloatArray


def path_problem(
    geometry: ChainGeometry,
    tool: FloatArray,
    linear_speed: FloatArray,
    angular_speed: FloatArray,
    options: TimingOptions | None = None,
) -> PathProblem:
    """The problem of timing a chain with ``linear_speed`` (M,) m/s and ``angular_speed`` (M,)
    rad/s (``inf``: none) per instruction: the limit of an instruction holds up to its
    boundaries, the smaller of two at a boundary."""
    grid = gridpoints(geometry, options or TimingOptions())
    linear = _piecewise(geometry.boundaries, linear_speed)(grid)
    angular = np.full(grid.size, np.inf)
    if np.any(np.isfinite(angular_speed)):
        angular = _piecewise(geometry.boundaries, angular_speed)(grid)
    return PathProblem(joint_path(geometry), grid, tool, linear, angular)


def time_path(
    geometry: ChainGeometry,
    robot: Robot,
    tool: FloatArray,
    linear_speed: FloatArray,
    angular_speed: FloatArray,
    options: TimingOptions | None = None,
) -> PathTimeLaw:
    """The time-optimal time law along a chain, rest to rest, found by ``options.solver``.

    ``linear_speed`` (M,) m/s and ``angular_speed`` (M,) rad/s (``inf``: none): the TCP limits
    per instruction of the chain. Joint limits: the robot's velocity and acceleration.
    """
    opts = options or TimingOptions()
    problem = path_problem(geometry, tool, linear_speed, angular_speed, opts)
    return _time_law(problem, PATH_SOLVERS[opts.solver]([problem], robot)[0])


def _time_law(problem: PathProblem, sd: FloatArray) -> PathTimeLaw:
    """The law of path speeds ``sd`` (K,) found for ``problem``, if it is one."""
    if not np.all(np.isfinite(sd)):
        raise TimingError("TOPPRA found no time law along this path (badly conditioned path)")
    sd = np.maximum(sd, 0.0)
    if np.any(sd[:-1] + sd[1:] <= 0.0):
        raise TimingError("the path cannot be followed without stopping inside it (a cusp)")
    return PathTimeLaw.from_speeds(problem.path, problem.grid, sd)


def gridpoints(geometry: ChainGeometry, options: TimingOptions) -> FloatArray:
    """TOPPRA's gridpoints (K,) on [0, s_end]: each sample interval split into at least
    ``grid_per_sample`` pieces, into pieces of at most ``max_grid_step_rad`` of joint motion and
    of at most ``max_grid_turn_rad`` of turn of the joint path's direction, plus geometric
    refinement at both ends (the stops); instruction boundaries are gridpoints too."""
    s, q = geometry.s, geometry.q
    pieces = _pieces(np.diff(q, axis=0), options)
    first = np.repeat(np.cumsum(pieces) - pieces, pieces)
    offsets = np.arange(int(pieces.sum())) - first
    uniform = np.repeat(s[:-1], pieces) + offsets * np.repeat(np.diff(s) / pieces, pieces)
    span = float(s[-1])
    spacing = float(np.max(np.diff(s) / pieces))
    ladder = span * np.logspace(-7, np.log10(spacing / span), options.refine_points)
    # Only the chain's ends are stops (a chain breaks at every stop; inside it the boundaries
    # are blend midpoints passed at speed), so only they need the ramp ladder. Laddering every
    # boundary made a 3,000-move toolpath cost 112 TOPPRA stages per move.
    stops = np.array([0.0, span])
    refined = (stops[:, None] + np.concatenate([-ladder, ladder])).ravel()
    points = np.concatenate([uniform, refined, geometry.boundaries])
    points = np.unique(points[(points >= 0.0) & (points <= span)])
    return points[np.concatenate([[True], np.diff(points) > 1e-12 * span])]


def _pieces(chords: FloatArray, options: TimingOptions) -> NDArray[np.int64]:
    """Gridpoint intervals (S-1,) per sample interval, from the joint chords (S-1, dof): the
    joint motion of each, and the turn of the path's direction at either of its ends."""
    motion = np.max(np.abs(chords), axis=-1)
    unit = chords / np.maximum(np.linalg.norm(chords, axis=-1, keepdims=True), 1e-300)
    turns = np.arccos(np.clip(np.sum(unit[:-1] * unit[1:], axis=-1), -1.0, 1.0))
    turn = np.maximum(np.append(turns, 0.0), np.insert(turns, 0, 0.0))
    pieces = np.maximum.reduce(
        [
            np.full(motion.shape, float(options.grid_per_sample)),
            np.ceil(motion / options.max_grid_step_rad),
            np.ceil(turn / options.max_grid_turn_rad),
        ]
    )
    return pieces.astype(np.int64)


def _piecewise(boundaries: FloatArray, values: FloatArray) -> Callable[[FloatArray], FloatArray]:
    """Limit per path parameter: ``values[k]`` between boundaries k and k+1, the smaller of the
    two at an inner boundary."""

    def at(s: FloatArray) -> FloatArray:
        k = np.clip(np.searchsorted(boundaries, s, side="right") - 1, 0, values.size - 1)
        inner = np.isin(s, boundaries[1:-1])
        out: FloatArray = np.where(inner, np.minimum(values[k], values[k - 1]), values[k])
        return out

    return at


def tcp_rates(
    robot: Robot, tool: FloatArray, q: FloatArray, dq: FloatArray, angular: bool = True
) -> tuple[FloatArray, FloatArray]:
    """TCP linear and angular rates along joint directions: ``|J_v(q) dq|`` (N,) m and
    ``|J_w(q) dq|`` (N,) rad per unit of the path parameter, for joints ``q`` and directions
    ``dq`` (N, dof) and the tool ``tool`` (4, 4) or (N, 4, 4); the angular ones 0 unless
    ``angular``.

    Computed as a central difference of the vectorised forward kinematics along ``dq`` with a
    joint step of 1e-6 rad (relative error ~1e-9), which is ``J dq`` without building J; in
    batches (bounds memory).
    """
    scale = np.max(np.abs(dq), axis=-1)
    h = 1e-6 / np.where(scale > 0, scale, 1.0)
    step = h[:, None] * dq
    if not angular:
        plus, minus = _tcp_positions(robot, q + step, tool), _tcp_positions(robot, q - step, tool)
        return np.linalg.norm(plus - minus, axis=-1) / (2 * h), np.zeros_like(h)
    ahead, behind = _tcp_poses(robot, q + step, tool), _tcp_poses(robot, q - step, tool)
    linear = np.linalg.norm(ahead[:, :3, 3] - behind[:, :3, 3], axis=-1) / (2 * h)
    turn = np.swapaxes(behind[:, :3, :3], -1, -2) @ ahead[:, :3, :3]
    return linear, np.linalg.norm(rotation_log(turn), axis=-1) / (2 * h)


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
    capped at ``_X_CAP``."""
    with np.errstate(divide="ignore"):
        bound = np.min((robot.limits.velocity / np.abs(dq)) ** 2, axis=-1)
    turns = bool(np.any(np.isfinite(angular)))
    linear_rate, angular_rate = tcp_rates(robot, tools, q, dq, angular=turns)
    bound = np.minimum(bound, _rate_bound(linear_rate, linear))
    if turns:
        bound = np.minimum(bound, _rate_bound(angular_rate, angular))
    return np.minimum(bound, _X_CAP)


def _rate_bound(rate: FloatArray, limit: FloatArray) -> FloatArray:
    """``x <= (limit / rate)²`` (K,) for ``rate * ds/dt <= limit``; no bound where rate is 0."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        out: FloatArray = np.where(rate > 0, (limit / rate) ** 2, np.inf)
    return out


# --------------------------------------------------------------------------------------------
# The solvers: TOPPRA's reachability analysis, vectorised; the toppra package as reference

PathSolver = Callable[[Sequence[PathProblem], Robot], list[FloatArray]]
"""Path speeds ``ds/dt`` (K_p,) at the gridpoints of each problem, rest to rest; NaN where no
time law was found."""

_BATCH_POINTS = 1 << 18
"""Gridpoints per batch of problems solved together (bounds memory; a larger chain is one
batch of its own)."""


def _reachability_solver(problems: Sequence[PathProblem], robot: Robot) -> list[FloatArray]:
    """:func:`reachability_speeds` on batches of problems end to end: one set of sweeps for
    all the problems of a batch (a chain's ends are stops, so none reaches into another)."""
    out: list[FloatArray] = []
    sizes = np.array([p.grid.size for p in problems], dtype=np.int64)
    batch = (np.cumsum(sizes) - sizes) // _BATCH_POINTS
    edges = [0, *(np.flatnonzero(np.diff(batch)) + 1).tolist(), len(problems)]
    for lo, hi in itertools.pairwise(edges):
        out += _solve_batch(problems[lo:hi], robot)
    return out


def _solve_batch(problems: Sequence[PathProblem], robot: Robot) -> list[FloatArray]:
    if not problems:
        return []
    sizes = np.array([p.grid.size for p in problems], dtype=np.int64)
    first = np.cumsum(sizes) - sizes
    # End to end, a stage of length 1 between two problems (it stays at rest). The stage
    # lengths are joined, not the gridpoints shifted: a shift of ~1 rounds away the spacing of
    # a short problem's grid (1e-17 near the ends of a 3e-10 rad move), which made zero-length
    # stages and no time law.
    delta = np.concatenate([part for p in problems for part in (np.diff(p.grid), np.ones(1))][:-1])
    q, dq, ddq = (np.concatenate([p.path(p.grid, k) for p in problems]) for k in range(3))
    linear = np.concatenate([p.linear for p in problems])
    angular = np.concatenate([p.angular for p in problems])
    bound = speed_bounds(robot, q, dq, _row_tools(problems, sizes), linear, angular)
    bound[first], bound[first + sizes - 1] = 0.0, 0.0  # every chain starts and ends at rest
    sd = _reachability(delta, dq, ddq, bound, robot.limits.acceleration)
    return np.split(sd, first[1:])


def _row_tools(problems: Sequence[PathProblem], sizes: NDArray[np.int64]) -> FloatArray:
    """The tool (4, 4) of all problems, or (K, 4, 4) per gridpoint if they differ."""
    tools = [p.tool for p in problems]
    if all(tool is tools[0] or np.array_equal(tool, tools[0]) for tool in tools):
        return tools[0]
    return np.repeat(np.stack(tools), sizes, axis=0)


def reachability_speeds(
    grid: FloatArray, dq: FloatArray, ddq: FloatArray, x_max: FloatArray, accel: FloatArray
) -> FloatArray:
    """Time-optimal path speeds ``ds/dt`` (K,) at gridpoints ``grid`` (K,), rest to rest:
    TOPPRA's reachability analysis with its discretisation, vectorised over the stages.

    ``dq``, ``ddq`` (K, dof): ``q'(s)`` and ``q''(s)`` at the gridpoints; ``x_max`` (K,): upper
    bound on ``x = (ds/dt)²`` (:func:`speed_bounds`); ``accel`` (dof,) rad/s²: joint
    acceleration limits, ``|q' u + q'' x| <= a`` with ``u = d²s/dt²``, imposed as TOPPRA's
    *interpolation* scheme does: on each stage ``i`` (``x_i`` to ``x_{i+1} = x_i + 2 Δ_i u_i``)
    at both of its gridpoints. In ``(x, y) = (x_i, x_{i+1})`` each of these 2·dof constraints
    reads ``-c - w x <= y <= c - w x`` (:func:`_stage_rows`), so

    * the largest controllable ``x_i`` (backward) is ``K_i = min(x_max_i, F_i,
      min_{w<0} (K_{i+1} + c) / -w)``, where ``F_i`` is the largest ``x`` for which the rows
      leave any ``y >= 0`` (pairs of rows, :func:`_stage_caps`), ``K_N = 0``;
    * the greedy forward pass is ``x_{i+1} = min(K_{i+1}, min (c - w x_i))``, ``x_0 = 0``.

    Both recursions are solved by sweeping all stages at once and then only those whose
    successor (predecessor) changed, until none does: exact after as many sweeps as the
    longest run of deceleration- (acceleration-) limited stages, each sweep in numpy. The
    result is TOPPRA's without its shrink of ``x`` by 1e-8 per forward step.
    """
    return _reachability(np.diff(grid), dq, ddq, x_max, accel)


def _reachability(
    delta: FloatArray, dq: FloatArray, ddq: FloatArray, x_max: FloatArray, accel: FloatArray
) -> FloatArray:
    """:func:`reachability_speeds` given the stage lengths ``delta`` (K - 1,)."""
    if not (np.all(np.isfinite(dq)) and np.all(np.isfinite(ddq)) and not np.any(np.isnan(x_max))):
        return np.full(delta.size + 1, np.nan)
    rows = _StageRows(delta, dq, ddq, np.concatenate([accel, accel]))
    cap = np.minimum(x_max[:-1], _stage_caps(rows))
    controllable = _backward(rows, np.append(cap, 0.0))
    return np.sqrt(_forward(rows, controllable))


@dataclass(frozen=True, slots=True, eq=False)
class _StageRows:
    """The stage constraints of :func:`reachability_speeds`, made on demand for any stages:
    ``delta`` (N,) the stages' lengths; ``dq``, ``ddq`` (N+1, dof); ``accel`` (2 dof,) the
    joint limits twice (at both ends of a stage)."""

    delta: FloatArray
    dq: FloatArray
    ddq: FloatArray
    accel: FloatArray

    @property
    def stages(self) -> int:
        return int(self.delta.size)

    def at(self, i: Stages, j: Stages) -> tuple[FloatArray, FloatArray]:
        """``c`` and ``w`` (n, 2 dof) of stages ``i`` (n,) (``j``: the gridpoints after them):
        ``|alpha y + beta x| <= 2 Δ a`` from ``|q' u + q'' x| <= a`` at ``s_i`` and at
        ``s_{i+1}`` (``u = (y - x) / 2Δ``), divided by ``|alpha|`` (at least ``_TINY_RATE``,
        where a joint stands still)."""
        twice = 2.0 * self.delta[i][:, None]
        alpha = np.concatenate([self.dq[i], self.dq[j] + twice * self.ddq[j]], axis=1)
        beta = np.concatenate([twice * self.ddq[i] - self.dq[i], -self.dq[j]], axis=1)
        size = np.maximum(np.abs(alpha), _TINY_RATE)
        return twice * self.accel / size, np.where(alpha < 0, -beta, beta) / size


Stages = slice | NDArray[np.int64]
"""Stages of a sweep: a run of them (a whole batch) or any (those next to a change)."""

_TINY_RATE = 1e-12
"""Smallest |dq/ds| (rad/rad) a stage row divides by: ``s`` is the joint chord, so dq/ds is
of order 1 where a joint moves; where it stands still, the row bounds ``x`` alone."""

_STAGE_BATCH = 1 << 15
"""Stages per numpy batch in the sweeps over all stages (bounds memory)."""


def _batches(count: int) -> list[tuple[slice, slice]]:
    """Stages ``0 .. count - 1`` in runs of ``_STAGE_BATCH``, each with the gridpoints after."""
    ends = [(lo, min(lo + _STAGE_BATCH, count)) for lo in range(0, count, _STAGE_BATCH)]
    return [(slice(lo, hi), slice(lo + 1, hi + 1)) for lo, hi in ends]


def _stage_caps(rows: _StageRows) -> FloatArray:
    """The largest ``x`` (N,) at each stage for which some ``y >= 0`` satisfies all its rows:
    ``max(0, max_j(-c_j - w_j x)) <= min_k(c_k - w_k x)``, i.e. ``x <= c_k / w_k`` for
    ``w_k > 0`` and ``x <= (c_j + c_k) / |w_j - w_k|`` for every pair of rows."""
    out = np.empty(rows.stages)
    with np.errstate(divide="ignore", invalid="ignore"):
        for here, after in _batches(rows.stages):
            c, w = rows.at(here, after)
            best = np.min(np.where(w > 0, c / w, np.inf), axis=1)
            for k in range(c.shape[1] - 1):  # row k against each later row, all stages at once
                pairs = (c[:, k : k + 1] + c[:, k + 1 :]) / np.abs(w[:, k : k + 1] - w[:, k + 1 :])
                np.minimum(best, np.min(pairs, axis=1), out=best)
            out[here] = best
    return out


def _backward(rows: _StageRows, bound: FloatArray) -> FloatArray:
    """Controllable squared speeds ``K`` (N+1,): ``K_i = min(bound_i, min_{w<0} (K_{i+1} + c)
    / -w)`` from ``K_N = bound_N``, swept until no stage changes."""
    out = bound.copy()

    def step(i: Stages, j: Stages) -> FloatArray:
        c, w = rows.at(i, j)
        with np.errstate(divide="ignore", invalid="ignore"):
            brake = np.where(w < 0, (out[j][:, None] + c) / -w, np.inf)
        return np.minimum(out[i], np.min(brake, axis=1))

    def one(i: int, c: list[float], w: list[float]) -> float:
        after = float(out[i + 1])
        brake = [(after + cj) / -wj for cj, wj in zip(c, w, strict=True) if wj < 0]
        return min([float(out[i]), *brake])

    return _sweep(out, _Step(step, one, rows), backward=True)


def _forward(rows: _StageRows, controllable: FloatArray) -> FloatArray:
    """The greedy squared speeds ``x`` (N+1,): ``x_{i+1} = min(K_{i+1}, min (c - w x_i))`` from
    ``x_0 = 0``, swept until no stage changes."""
    out = controllable.copy()
    out[0] = 0.0

    def step(i: Stages, j: Stages) -> FloatArray:
        c, w = rows.at(i, j)
        reach = np.min(c - w * out[i][:, None], axis=1)
        return np.maximum(np.minimum(controllable[j], reach), 0.0)

    def one(i: int, c: list[float], w: list[float]) -> float:
        here = float(out[i])
        reach = min([cj - wj * here for cj, wj in zip(c, w, strict=True)])
        return max(min(float(controllable[i + 1]), reach), 0.0)

    return _sweep(out, _Step(step, one, rows), backward=False)


@dataclass(frozen=True, slots=True, eq=False)
class _Step:
    """One stage of a recursion, for many stages at once (``many(i, i + 1)``, numpy) and for
    one (``one(i, c, w)`` with the stage's rows as floats, Python); ``rows`` the stages."""

    many: Callable[[Stages, Stages], FloatArray]
    one: Callable[[int, list[float], list[float]], float]
    rows: _StageRows


_VECTOR_SWEEPS = 32
"""Sweeps over the changed stages in numpy before the rest runs stage by stage in order: a
sweep is cheap per stage but recomputes a whole ramp each time (a ramp of L stages would cost
L sweeps of L stages), the ordered pass computes each stage once at ~3 us."""


def _sweep(values: FloatArray, step: _Step, backward: bool) -> FloatArray:
    """Solve ``values[i] = step(i)`` (backward) or ``values[i + 1] = step(i)`` (forward) for all
    stages i: one numpy sweep over all stages in runs, up to ``_VECTOR_SWEEPS`` sweeps over the
    stages next to a change, then the stages still next to a change one by one in order."""
    stages = step.rows.stages
    changed = []
    for here, after in _batches(stages):
        run = here if backward else after
        new = step.many(here, after)
        moved = np.flatnonzero(new != values[run])
        values[run] = new
        changed.append(moved + run.start)
    points = np.concatenate(changed) if changed else np.zeros(0, dtype=np.int64)
    for _ in range(_VECTOR_SWEEPS):
        active = _readers(points, stages, backward)
        if active.size == 0:
            return values
        target = active if backward else active + 1
        new = step.many(active, active + 1)
        moved = new != values[target]
        values[target] = new
        points = target[moved]
    return _ordered(values, step, _readers(points, stages, backward), backward)


def _readers(points: NDArray[np.int64], stages: int, backward: bool) -> NDArray[np.int64]:
    """The stages that read the gridpoints ``points``: ``k - 1`` backward, ``k`` forward."""
    active = points - 1 if backward else points
    return active[(active >= 0) & (active < stages)]


def _ordered(
    values: FloatArray, step: _Step, active: NDArray[np.int64], backward: bool
) -> FloatArray:
    """Finish a sweep stage by stage: from each stage still to compute (in the direction of the
    recursion), on while its result changes. Each stage is computed at most once."""
    direction = -1 if backward else 1
    order = np.unique(active)[::direction].tolist()
    rows = _RowCache(step.rows)
    done = step.rows.stages if backward else -1  # beyond the first start: none computed
    for start in order:
        if (start >= done) if backward else (start <= done):
            continue  # within a run already computed
        i = start
        while 0 <= i < step.rows.stages:
            target = i if backward else i + 1
            new = step.one(i, *rows.of(i))
            done = i
            if new == values[target]:
                break
            values[target] = new
            i += direction
    return values


@dataclass(frozen=True, slots=True, eq=False)
class _RowCache:
    """The rows ``c``, ``w`` of stages as Python floats, made a block of stages at a time."""

    rows: _StageRows
    blocks: dict[int, tuple[list[list[float]], list[list[float]]]] = field(default_factory=dict)

    def of(self, i: int) -> tuple[list[float], list[float]]:
        block, within = divmod(i, _ROW_BLOCK)
        if block not in self.blocks:
            lo = block * _ROW_BLOCK
            hi = min(lo + _ROW_BLOCK, self.rows.stages)
            c, w = self.rows.at(slice(lo, hi), slice(lo + 1, hi + 1))
            self.blocks[block] = (c.tolist(), w.tolist())
        c_rows, w_rows = self.blocks[block]
        return c_rows[within], w_rows[within]


_ROW_BLOCK = 1024
"""Stages whose rows :class:`_RowCache` makes at once."""


_JOINT_CONSTRAINTS: dict[tuple[bytes, bytes], list[constraint.LinearConstraint]] = {}
"""toppra's joint constraints by limits: they format their limits into a string when made
(~1 ms), so they are made once."""


def _joint_constraints(limits: JointLimits) -> list[constraint.LinearConstraint]:
    key = (limits.velocity.tobytes(), limits.acceleration.tobytes())
    if key not in _JOINT_CONSTRAINTS:
        _JOINT_CONSTRAINTS[key] = [
            constraint.JointVelocityConstraint(limits.velocity),
            constraint.JointAccelerationConstraint(limits.acceleration),
        ]
    return _JOINT_CONSTRAINTS[key]


class _SeidelTOPPRA(algo.TOPPRA):
    """toppra's TOPPRA with its seidel LP solver, made without probing for the optional solver
    packages (two ``importlib`` look-ups per problem in toppra's own constructor)."""

    def __init__(
        self,
        constraints: list[constraint.LinearConstraint],
        path: JointSpline,
        grid: FloatArray,
    ) -> None:
        ParameterizationAlgorithm.__init__(self, constraints, path, gridpoints=grid)
        self.solver_wrapper = seidelWrapper(self.constraints, self.path, self.gridpoints, True)


def _toppra_solver(problems: Sequence[PathProblem], robot: Robot) -> list[FloatArray]:
    """The toppra package's TOPPRA, one problem at a time (the reference for
    :func:`reachability_speeds`); NaN where it finds no time law."""
    out = []
    for problem in problems:
        constraints = [
            *_joint_constraints(robot.limits),
            TcpLinearSpeedConstraint(robot, problem.tool, _on_grid(problem.grid, problem.linear)),
        ]
        if np.any(np.isfinite(problem.angular)):
            limit = _on_grid(problem.grid, problem.angular)
            constraints.append(TcpAngularSpeedConstraint(robot, problem.tool, limit))
        algorithm = _SeidelTOPPRA(constraints, problem.path, problem.grid)
        sd = algorithm.compute_parameterization(0.0, 0.0)[1]
        out.append(np.full(problem.grid.size, np.nan) if sd is None else np.asarray(sd, float))
    return out


def _on_grid(grid: FloatArray, values: FloatArray) -> Callable[[FloatArray], FloatArray]:
    """A limit given at the gridpoints ``grid`` (K,) as a function of them."""

    def at(s: FloatArray) -> FloatArray:
        return values[np.clip(np.searchsorted(grid, s), 0, grid.size - 1)]

    return at


class _TcpRateConstraint(constraint.LinearConstraint):
    """``rate(s) * ds/dt <= limit(s)``: a bound on TOPPRA's state ``x = (ds/dt)^2`` per
    gridpoint, ``x <= (limit / rate)^2``, with the TCP rate from :func:`tcp_rates`."""

    component = 0

    def __init__(
        self, robot: Robot, tool: FloatArray, limit: Callable[[FloatArray], FloatArray]
    ) -> None:
        super().__init__()
        self.robot, self.tool, self.limit = robot, tool, limit
        self.dof = robot.dof
        self._format_string = f"    {type(self).__name__}\n"

    def compute_constraint_params(
        self, path: toppra.interpolator.AbstractGeometricPath, gridpoints: FloatArray
    ) -> tuple[None, None, None, None, None, None, FloatArray]:
        rate = tcp_rates(self.robot, self.tool, path(gridpoints), path(gridpoints, 1))
        xbound = np.zeros((gridpoints.size, 2))
        xbound[:, 1] = np.minimum(_rate_bound(rate[self.component], self.limit(gridpoints)), _X_CAP)
        return None, None, None, None, None, None, xbound


class TcpLinearSpeedConstraint(_TcpRateConstraint):
    """The TCP's linear speed ``|J_v(q) q'(s)| ds/dt`` stays below ``limit(s)`` m/s."""

    component = 0


class TcpAngularSpeedConstraint(_TcpRateConstraint):
    """The TCP's orientation speed ``|J_w(q) q'(s)| ds/dt`` stays below ``limit(s)`` rad/s."""

    component = 1


PATH_SOLVERS: dict[str, PathSolver] = {
    "reachability": _reachability_solver,
    "toppra": _toppra_solver,
}
"""Path-speed solvers by name (``TimingOptions.solver``)."""


_UNIT_TIMERS: dict[str, Callable[[Unit, _Context], list[Step]]] = {
    "fixed": _time_fixed,
    "joint": _time_joint,
}
"""Timers of single units; path units are timed together (:func:`_time_chains`)."""


# --------------------------------------------------------------------------------------------
# Speed sweeps


def override_speeds(
    compiled: CompiledProgram, linear: float | None = None, joint: float | None = None
) -> CompiledProgram:
    """A copy in which every path move runs at ``linear`` m/s and every joint move at ``joint``
    (fraction of the axes' maximum velocity); ``None`` keeps the programmed value. Acceleration
    and orientation-speed settings stay as programmed."""
    steps = []
    for step in compiled.steps:
        ins = step.instruction
        if isinstance(ins, LinearMove | CircularMove) and linear is not None:
            ins = dataclasses.replace(ins, speed=dataclasses.replace(ins.speed, linear=linear))
        elif isinstance(ins, JointMove) and joint is not None:
            ins = dataclasses.replace(ins, speed=dataclasses.replace(ins.speed, joint=joint))
        steps.append(dataclasses.replace(step, instruction=ins))
    program = compiled.program.replace_instructions([s.instruction for s in steps])
    return dataclasses.replace(compiled, program=program, steps=tuple(steps))


def speed_sweep(
    compiled: CompiledProgram,
    linear_speeds: Sequence[float | None],
    joint_speeds: Sequence[float | None],
    other_times: Mapping[str, float] | None = None,
    options: TimingOptions | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> FloatArray:
    """Cycle times (L, J) s with every path move at ``linear_speeds[i]`` m/s and every joint
    move at ``joint_speeds[j]`` (fraction); ``None`` keeps the programmed speeds; NaN where a
    motion could not be timed.

    Path chains never contain joint moves, so the path time depends only on the linear speed and
    the joint-move time only on the joint speed: L + J timings give the L x J table.
    """
    lengths = tcp_lengths(compiled)
    units = plan_units(compiled, lengths)
    context = _Context(compiled, _time_table(other_times), options or TimingOptions(), lengths)
    total = len(linear_speeds) + len(joint_speeds)
    parts: list[FloatArray] = []
    for kind, values, key in (("path", linear_speeds, "linear"), ("joint", joint_speeds, "joint")):
        chosen = [u for u in units if u.kind == kind]
        sums = []
        for value in values:
            retimed = dataclasses.replace(
                context, compiled=override_speeds(compiled, **{key: value})
            )
            steps, found = _time_units(retimed, chosen)
            picked = [steps[i].duration for u in chosen for i in u.indices]
            sums.append(np.nan if found else float(np.sum(picked)))
            if progress is not None:
                progress(len(parts) * len(linear_speeds) + len(sums), total)
        parts.append(np.array(sums, dtype=np.float64))
    fixed = [u for u in units if u.kind == "fixed"]
    steps, _ = _time_units(context, fixed)
    rest = float(sum(steps[i].duration for u in fixed for i in u.indices))
    table: FloatArray = parts[0][:, None] + parts[1][None, :] + rest
    return table


def timing_pass(compiled: CompiledProgram, options: BuildOptions) -> CompiledProgram:
    """The timing pass: :func:`time_program` with ``options.other_times`` and
    ``options.timing``; a program with errors is not timed (nothing will run)."""
    if not compiled.ok:
        return compiled
    return time_program(compiled, options.other_times, options.timing)
