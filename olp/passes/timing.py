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
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np
import toppra
import toppra.algorithm as algo
import toppra.constraint as constraint
from numpy.typing import NDArray
from ruckig import InputParameter, Result, Ruckig, Synchronization, Trajectory

from olp.diagnostics import Diagnostic
from olp.geometry import rotation_log
from olp.ir import Call, CircularMove, Comment, Instruction, JointMove, LinearMove, Wait, is_motion
from olp.passes.resolve import CompiledProgram, Step
from olp.station.model import Robot
from olp.trajectory import JerkProfile, PathTimeLaw, Segment

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
    """Discretisation of path moves.

    ``grid_per_sample``: TOPPRA gridpoints per interval of resolved samples (at least);
    ``max_grid_step_rad``: largest joint change between gridpoints; ``max_grid_turn_rad``:
    largest turn of the joint path's direction between gridpoints; ``refine_points``:
    gridpoints placed geometrically on each side of every stop and instruction boundary;
    ``blend_samples``: least number of samples on a blend curve (odd: its midpoint is one);
    more where the blend turns (one per 4° of joint-space turn).
    """

    grid_per_sample: int = 2
    max_grid_step_rad: float = float(np.radians(0.5))
    max_grid_turn_rad: float = float(np.radians(1.0))
    refine_points: int = 24
    blend_samples: int = 5


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
    return dataclasses.replace(
        compiled,
        steps=tuple(steps),
        diagnostics=compiled.diagnostics + tuple(found) + tuple(_zone_stops(compiled, units)),
    )


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
    found: list[Diagnostic] = []
    for unit in units:
        try:
            for step in _UNIT_TIMERS[unit.kind](unit, context):
                steps[step.index] = step
        except TimingError as exc:
            first = steps[unit.indices[0]].instruction
            found.append(Diagnostic("error", "timing", str(exc), first.span, unit.indices[0]))
    return steps, found


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
    return bool(np.array_equal(a.tool.pose, b.tool.pose))


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
    result = Ruckig(dof).calculate(inp, trajectory)
    if result not in (Result.Working, Result.Finished):
        raise TimingError(f"Ruckig could not time the joint move ({result.name})")
    return _jerk_profile(trajectory)


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
# Path moves: geometry of a chain


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


def chain_geometry(
    paths: Sequence[FloatArray],
    robot: Robot,
    tool: FloatArray,
    blends: Sequence[float],
    blend_samples: int = 5,
) -> ChainGeometry:
    """Join the sampled joint paths (S_k, dof) of M moves, cutting each inner corner at
    ``blends[k]`` m of TCP travel on both sides and joining the cuts by a blend curve."""
    arcs = [_arc(_positions(path, robot, tool)) for path in paths]
    pieces: list[FloatArray] = []
    marks, rows = [0], 0
    for k, (path, arc) in enumerate(zip(paths, arcs, strict=True)):
        enter = blends[k - 1] if k > 0 else 0.0
        leave = arc[-1] - blends[k] if k < len(paths) - 1 else arc[-1]
        pieces.append(_section(path, arc, enter, leave))
        rows += len(pieces[-1])
        if k < len(paths) - 1:
            start, end = _cut(path, arc, leave), _cut(paths[k + 1], arcs[k + 1], blends[k])
            least = max(blend_samples, _turn_samples(start[1], end[1]))
            count = _blend_count(arc, arcs[k + 1], blends[k], least)
            curve = _blend_curve(start, end, blends[k], count)
            marks.append(rows + len(curve) // 2)
            pieces.append(curve)
            rows += len(curve)
    q = np.concatenate(pieces)
    marks.append(len(q) - 1)
    return _geometry(q, np.asarray(marks), robot, tool)


def _positions(path: FloatArray, robot: Robot, tool: FloatArray) -> FloatArray:
    positions: FloatArray = (robot.flange_poses(path) @ tool)[:, :3, 3]
    return positions


def _arc(positions: FloatArray) -> FloatArray:
    """Cumulative polyline length (S,) m through positions (S, 3)."""
    steps = np.linalg.norm(np.diff(positions, axis=0), axis=-1)
    return np.concatenate([[0.0], np.cumsum(steps)])


def _cut(path: FloatArray, arc: FloatArray, at: float) -> tuple[FloatArray, FloatArray]:
    """Joints (dof,) at TCP travel ``at`` m along a sampled path (linear between samples), and
    the tangent dq/d(travel) (dof,) rad/m there."""
    i = int(np.clip(np.searchsorted(arc, at, side="right") - 1, 0, arc.size - 2))
    width = max(arc[i + 1] - arc[i], 1e-15)  # repeated samples: no division by zero
    fraction = (at - arc[i]) / width
    delta = path[i + 1] - path[i]
    return path[i] + fraction * delta, delta / width


def _section(path: FloatArray, arc: FloatArray, enter: float, leave: float) -> FloatArray:
    """The samples strictly between travel ``enter`` and ``leave`` m, with the cut points."""
    tol = 1e-9
    inner = path[(arc > enter + tol) & (arc < leave - tol)]
    return np.vstack([_cut(path, arc, enter)[0], inner, _cut(path, arc, leave)[0]])


_BLEND_TURN_PER_SAMPLE = float(np.radians(4.0))


def _turn_samples(t0: FloatArray, t3: FloatArray) -> int:
    """Samples a blend needs for its turn: one per 4° between the joint-space tangents (the
    gridpoints then subdivide to 1°; a cubic spline through these samples follows the cubic
    blend curve closely)."""
    cos = float(np.dot(t0, t3) / max(np.linalg.norm(t0) * np.linalg.norm(t3), 1e-300))
    return int(np.ceil(np.arccos(np.clip(cos, -1.0, 1.0)) / _BLEND_TURN_PER_SAMPLE)) + 3


def _blend_count(arc_in: FloatArray, arc_out: FloatArray, d: float, least: int) -> int:
    """Samples on a blend: at least ``least``, and no sparser than the moves' own samples."""
    spacing = min(float(np.median(np.diff(arc_in))), float(np.median(np.diff(arc_out))))
    count = max(least, int(np.ceil(2 * d / max(spacing, 1e-9))) + 1)
    return count + 1 - count % 2


def _blend_curve(
    start: tuple[FloatArray, FloatArray],
    end: tuple[FloatArray, FloatArray],
    d: float,
    count: int,
) -> FloatArray:
    """Inner samples (count - 2, dof) of the joint-space cubic Bezier from the cut ``start`` to
    the cut ``end`` (each joints and tangent): control points 2/3 of ``d`` along the tangents,
    i.e. the cubic form of the parabola whose middle control point is the corner."""
    (p0, t0), (p3, t3) = start, end
    p1, p2 = p0 + (2.0 / 3.0) * d * t0, p3 - (2.0 / 3.0) * d * t3
    u = np.linspace(0.0, 1.0, count)[1:-1, None]
    v = 1.0 - u
    curve: FloatArray = v**3 * p0 + 3 * v**2 * u * p1 + 3 * v * u**2 * p2 + u**3 * p3
    return curve


def _geometry(q: FloatArray, marks: FloatArray, robot: Robot, tool: FloatArray) -> ChainGeometry:
    """Drop repeated samples, parameterise by joint chord length, measure TCP travel."""
    steps = np.linalg.norm(np.diff(q, axis=0), axis=-1)
    keep = np.concatenate([[True], steps > 1e-12])
    rows = np.cumsum(keep) - 1  # each old row's index among the kept ones
    q = q[keep]
    s = np.concatenate([[0.0], np.cumsum(steps[keep[1:]])])
    arc = _arc(_positions(q, robot, tool))
    at = rows[marks]
    return ChainGeometry(s=s, q=q, boundaries=s[at], lengths=np.diff(arc[at]))


def joint_path(geometry: ChainGeometry) -> toppra.SplineInterpolator:
    """The cubic spline q(s) (not-a-knot) through a chain's samples."""
    return toppra.SplineInterpolator(geometry.s, geometry.q)


# --------------------------------------------------------------------------------------------
# Path moves: TOPPRA


def _time_path(unit: Unit, context: _Context) -> list[Step]:
    robot, opts = context.compiled.station.robot, context.options
    steps = [context.compiled.steps[i] for i in unit.indices]
    tool = steps[0].tool.pose if steps[0].tool is not None else None
    assert tool is not None
    paths = [s.path for s in steps if s.path is not None]
    geometry = chain_geometry(paths, robot, tool, unit.blends, opts.blend_samples)
    if geometry.s[-1] <= 0.0:  # no joint moves: the TCP stays put
        return [dataclasses.replace(s, duration=0.0, path_length=0.0) for s in steps]
    speeds = [s.instruction.speed for s in steps if is_motion(s.instruction)]
    law = time_path(
        geometry,
        robot,
        tool,
        np.array([sp.linear for sp in speeds]),
        np.array([np.inf if sp.angular is None else sp.angular for sp in speeds]),
        opts,
    )
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


def time_path(
    geometry: ChainGeometry,
    robot: Robot,
    tool: FloatArray,
    linear_speed: FloatArray,
    angular_speed: FloatArray,
    options: TimingOptions | None = None,
) -> PathTimeLaw:
    """The time-optimal time law (TOPPRA) along a chain, rest to rest.

    ``linear_speed`` (M,) m/s and ``angular_speed`` (M,) rad/s (``inf``: none): the TCP limits
    per instruction of the chain. Joint limits: the robot's velocity and acceleration.
    """
    opts = options or TimingOptions()
    path = joint_path(geometry)
    grid = gridpoints(geometry, opts)
    constraints: list[constraint.LinearConstraint] = [
        constraint.JointVelocityConstraint(robot.limits.velocity),
        constraint.JointAccelerationConstraint(robot.limits.acceleration),
        TcpLinearSpeedConstraint(robot, tool, _piecewise(geometry.boundaries, linear_speed)),
    ]
    if np.any(np.isfinite(angular_speed)):
        limit = _piecewise(geometry.boundaries, angular_speed)
        constraints.append(TcpAngularSpeedConstraint(robot, tool, limit))
    problem = algo.TOPPRA(constraints, path, gridpoints=grid, solver_wrapper="seidel")
    _sdd, sd, _v = problem.compute_parameterization(0.0, 0.0)
    if sd is None or not np.all(np.isfinite(sd)):
        raise TimingError("TOPPRA found no time law along this path (badly conditioned path)")
    sd = np.maximum(sd, 0.0)
    if np.any(sd[:-1] + sd[1:] <= 0.0):
        raise TimingError("the path cannot be followed without stopping inside it (a cusp)")
    return PathTimeLaw.from_speeds(path, grid, sd)


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
    robot: Robot, tool: FloatArray, q: FloatArray, dq: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """TCP linear and angular rates along joint directions: ``|J_v(q) dq|`` (N,) m and
    ``|J_w(q) dq|`` (N,) rad per unit of the path parameter, for joints ``q`` and directions
    ``dq`` (N, dof).

    Computed as a central difference of the vectorised forward kinematics along ``dq`` with a
    joint step of 1e-6 rad (relative error ~1e-9), which is ``J dq`` without building J.
    """
    scale = np.max(np.abs(dq), axis=-1)
    h = (1e-6 / np.where(scale > 0, scale, 1.0))[:, None]
    plus = robot.flange_poses(q + h * dq) @ tool
    minus = robot.flange_poses(q - h * dq) @ tool
    linear = np.linalg.norm(plus[:, :3, 3] - minus[:, :3, 3], axis=-1) / (2 * h[:, 0])
    turn = np.swapaxes(minus[:, :3, :3], -1, -2) @ plus[:, :3, :3]
    angular = np.linalg.norm(rotation_log(turn), axis=-1) / (2 * h[:, 0])
    return linear, angular


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
        limit = self.limit(gridpoints)
        with np.errstate(divide="ignore", invalid="ignore"):
            x_max = np.where(rate[self.component] > 0, (limit / rate[self.component]) ** 2, np.inf)
        xbound = np.zeros((gridpoints.size, 2))
        xbound[:, 1] = np.minimum(x_max, _X_CAP)
        return None, None, None, None, None, None, xbound


class TcpLinearSpeedConstraint(_TcpRateConstraint):
    """The TCP's linear speed ``|J_v(q) q'(s)| ds/dt`` stays below ``limit(s)`` m/s."""

    component = 0


class TcpAngularSpeedConstraint(_TcpRateConstraint):
    """The TCP's orientation speed ``|J_w(q) q'(s)| ds/dt`` stays below ``limit(s)`` rad/s."""

    component = 1


_UNIT_TIMERS: dict[str, Callable[[Unit, _Context], list[Step]]] = {
    "fixed": _time_fixed,
    "joint": _time_joint,
    "path": _time_path,
}


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
