"""Path moves and blended chains: the problem of timing a chain (its grid and TCP limits) and
the time-optimal time law along it under the joint limits and the TCP speed, solved by a path
solver (:data:`PATH_SOLVERS`). The pass times all chains of a program at once
(:func:`olp.passes.timing.program.time_chains`)."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from olp.passes.timing.geometry import ChainGeometry, joint_path
from olp.passes.timing.plan import TimingError, TimingOptions
from olp.passes.timing.problem import PathProblem
from olp.passes.timing.reachability import PathSolver, reachability_solver
from olp.station.model import Robot
from olp.trajectory import PathTimeLaw

FloatArray = NDArray[np.float64]


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
    return time_law(problem, PATH_SOLVERS[opts.solver]([problem], robot)[0])


def time_law(problem: PathProblem, sd: FloatArray) -> PathTimeLaw:
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
