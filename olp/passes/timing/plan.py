"""What the timing pass works with: its options, the fixed times of non-motion instructions, and
the plan of a program as timing units (a fixed-time instruction, a joint move, a chain of path
moves blended into one another), with each resolved motion's TCP travel."""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np
from numpy.typing import NDArray

from olp.compiled import CompiledProgram, Step
from olp.diagnostics import Diagnostic
from olp.ir import Call, CircularMove, Comment, Instruction, JointMove, LinearMove, Wait, is_motion
from olp.passes.timing.tcp import FK_ROWS
from olp.station.model import Robot

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


X_CAP = 1e12
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


def time_table(other_times: Mapping[str, float] | None) -> dict[str, float]:
    table = {**DEFAULT_TIMES, **(other_times or {})}
    return {key.casefold(): float(value) for key, value in table.items()}


@dataclass(frozen=True, slots=True)
class Context:
    """What every unit is timed with: the program, the time table (casefolded kinds), the
    options and the TCP travel (m) of every resolved motion's samples, by instruction index."""

    compiled: CompiledProgram
    times: Mapping[str, float]
    options: TimingOptions
    lengths: Mapping[int, float]


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


def tcp_lengths(compiled: CompiledProgram) -> dict[int, float]:
    """TCP travel (m) along every resolved motion's samples (the polyline through them), by
    instruction index; forward kinematics in batches of about ``FK_ROWS`` samples."""
    motions = [
        (s.index, s.path, s.tool.pose)
        for s in compiled.steps
        if is_motion(s.instruction)
        and s.path is not None
        and s.tool is not None
        and s.tool.pose is not None
    ]
    sizes = np.array([len(path) for _, path, _ in motions], dtype=np.int64)
    batch = (np.cumsum(sizes) - sizes) // FK_ROWS
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


def zone_stops(compiled: CompiledProgram, units: Sequence[Unit]) -> list[Diagnostic]:
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


def fixed_time(instruction: Instruction, times: Mapping[str, float]) -> float:
    """Seconds charged for a non-motion instruction (or an unresolved motion: 0)."""
    if isinstance(instruction, Wait):
        return instruction.seconds
    if isinstance(instruction, Call) and f"call:{instruction.name}".casefold() in times:
        return times[f"call:{instruction.name}".casefold()]
    return times.get(instruction.kind, 0.0) if not is_motion(instruction) else 0.0


def time_fixed(unit: Unit, context: Context) -> list[Step]:
    step = context.compiled.steps[unit.indices[0]]
    duration = fixed_time(step.instruction, context.times)
    return [dataclasses.replace(step, duration=duration, path_length=0.0, trajectory=None)]


MIN_PATH_SPEED = 1e-150
"""Slowest TCP speed (m/s, and rad/s for an orientation speed) a path move is timed at. The
solver works with the squared path speed ``(v / rate)²``, rate up to ~10 m/rad: below this it
would leave the normal float range (2.2e-308) and the time law would lose its digits, then
vanish (measured: 1e-160 m/s timed 5e-7 off, 1e-300 m/s found no time law)."""


def below_floor(step: Step) -> bool:
    """Whether a path move's programmed speed is below :data:`MIN_PATH_SPEED`."""
    speed = step.instruction.speed if is_motion(step.instruction) else None
    if speed is None:
        return False
    angular = np.inf if speed.angular is None else speed.angular
    return bool(speed.linear < MIN_PATH_SPEED or angular < MIN_PATH_SPEED)
