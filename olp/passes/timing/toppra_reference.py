"""The toppra package as the reference path solver (``TimingOptions(solver="toppra")``), with
olp's TCP speed limits as toppra constraints. Imported only when that solver is asked for:
toppra imports matplotlib, a second and more at start-up."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import toppra
import toppra.algorithm as algo
import toppra.constraint as constraint
from numpy.typing import NDArray
from toppra.algorithm.algorithm import ParameterizationAlgorithm
from toppra.solverwrapper.cy_seidel_solverwrapper import seidelWrapper

from olp.passes.timing.geometry import JointSpline
from olp.passes.timing.plan import X_CAP
from olp.passes.timing.problem import PathProblem
from olp.passes.timing.tcp import rate_bound, tcp_rates
from olp.station.model import JointLimits, Robot

FloatArray = NDArray[np.float64]


_JOINT_CONSTRAINTS: dict[tuple[bytes, bytes, float, float], list[constraint.LinearConstraint]] = {}
"""toppra's joint constraints by limits: they format their limits into a string when made
(~1 ms), so they are made once."""


def _joint_constraints(
    limits: JointLimits, speed: float = 1.0, accel: float = 1.0
) -> list[constraint.LinearConstraint]:
    key = (limits.velocity.tobytes(), limits.acceleration.tobytes(), speed, accel)
    if key not in _JOINT_CONSTRAINTS:
        _JOINT_CONSTRAINTS[key] = [
            constraint.JointVelocityConstraint(limits.velocity * speed),
            constraint.JointAccelerationConstraint(limits.acceleration * accel),
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


def toppra_solver(problems: Sequence[PathProblem], robot: Robot) -> list[FloatArray]:
    """The toppra package's TOPPRA, one problem at a time (the reference for
    :func:`reachability_speeds`); NaN where it finds no time law. It honours the problems'
    speed and acceleration scales but not their TCP acceleration limits (the reference
    predates them)."""
    out = []
    for problem in problems:
        constraints = [
            *_joint_constraints(robot.limits, 1.0, problem.accel_scale),
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
        xbound[:, 1] = np.minimum(rate_bound(rate[self.component], self.limit(gridpoints)), X_CAP)
        return None, None, None, None, None, None, xbound


class TcpLinearSpeedConstraint(_TcpRateConstraint):
    """The TCP's linear speed ``|J_v(q) q'(s)| ds/dt`` stays below ``limit(s)`` m/s."""

    component = 0


class TcpAngularSpeedConstraint(_TcpRateConstraint):
    """The TCP's orientation speed ``|J_w(q) q'(s)| ds/dt`` stays below ``limit(s)`` rad/s."""

    component = 1
