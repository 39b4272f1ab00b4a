"""Path moves and blended chains: a time-optimal time law along each chain under the joint
limits and the TCP speed, on a refined grid, solved by a path solver (:data:`PATH_SOLVERS`)."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from olp.compiled import Step
from olp.diagnostics import Diagnostic
from olp.ir import is_motion
from olp.passes.timing.geometry import ChainGeometry, chain_geometry, joint_path
from olp.passes.timing.plan import MIN_PATH_SPEED, Context, TimingError, TimingOptions, Unit
from olp.passes.timing.problem import PathProblem
from olp.passes.timing.reachability import PathSolver, reachability_solver
from olp.station.model import Robot
from olp.trajectory import PathTimeLaw, Segment

FloatArray = NDArray[np.float64]


def time_chains(context: Context, units: Sequence[Unit]) -> tuple[list[Step], list[Diagnostic]]:
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


def _toppra(problems: Sequence[PathProblem], robot: Robot) -> list[FloatArray]:
    """The toppra package's solver, imported on first use."""
    from olp.passes.timing.toppra_reference import toppra_solver

    return toppra_solver(problems, robot)


PATH_SOLVERS: dict[str, PathSolver] = {
    "reachability": reachability_solver,
    "toppra": _toppra,
}
"""Path-speed solvers by name (``TimingOptions.solver``)."""
