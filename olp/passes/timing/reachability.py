"""The path solver olp uses: TOPPRA's reachability analysis (backward controllable sets, greedy
forward pass) written in numpy over all gridpoints of many problems at once."""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from olp.passes.timing.problem import PathProblem, speed_bounds
from olp.passes.timing.tcp import tcp_rates
from olp.station.model import Robot

FloatArray = NDArray[np.float64]


PathSolver = Callable[[Sequence[PathProblem], Robot], list[FloatArray]]
"""Path speeds ``ds/dt`` (K_p,) at the gridpoints of each problem, rest to rest; NaN where no
time law was found."""


_BATCH_POINTS = 1 << 18
"""Gridpoints per batch of problems solved together (bounds memory; a larger chain is one
batch of its own)."""


def reachability_solver(problems: Sequence[PathProblem], robot: Robot) -> list[FloatArray]:
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
    tools = _row_tools(problems, sizes)
    bound = speed_bounds(robot, q, dq, tools, linear, angular)
    bound[first], bound[first + sizes - 1] = 0.0, 0.0  # every chain starts and ends at rest
    caps = np.array([p.speed_cap for p in problems])
    if np.any(np.isfinite(caps)):
        bound = np.minimum(bound, np.repeat(caps**2, sizes))
    accel: FloatArray = np.broadcast_to(robot.limits.acceleration, dq.shape)
    scales = np.array([p.accel_scale for p in problems])
    if np.any(scales != 1.0):
        accel = accel * np.repeat(scales, sizes)[:, None]
    if any(p.tcp_accelerations for p in problems):
        s = np.concatenate([[0.0], np.cumsum(delta)])
        dq, ddq, accel = _tcp_rows(problems, sizes, robot, tools, q, s, (dq, ddq, accel))
    sd = _reachability(delta, dq, ddq, bound, accel)
    return np.split(sd, first[1:])


def _tcp_rows(
    problems: Sequence[PathProblem],
    sizes: NDArray[np.int64],
    robot: Robot,
    tools: FloatArray,
    q: FloatArray,
    s: FloatArray,
    rows: tuple[FloatArray, FloatArray, FloatArray],
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The joint rows ``dq``, ``ddq``, ``accel`` (K, m) with the TCP accelerations as more
    columns of the same form: the TCP's speed along its path is ``r(s) ds/dt`` (``r`` its linear
    rate, :func:`tcp_rates`), so its tangential acceleration ``r u + r' x`` is a row with
    ``q' = r``, ``q'' = r'`` and the limit ``a`` (the orientation likewise with the angular
    rate). ``r'`` is the derivative along the joined gridpoints ``s`` (K,) by central
    differences (at a chain's ends ``x = 0``, so the term vanishes there)."""
    dq, ddq, accel = rows
    scale = np.repeat(np.array([p.accel_scale for p in problems]), sizes)
    linear_rate, angular_rate = tcp_rates(robot, tools, q, dq, angular=True)
    for rate, name in (
        (linear_rate, "linear_acceleration"),
        (angular_rate, "angular_acceleration"),
    ):
        limits = [getattr(p, name) for p in problems]
        if all(limit is None for limit in limits):
            continue
        limit = np.concatenate(
            [
                np.full(p.grid.size, np.inf) if v is None else v
                for p, v in zip(problems, limits, strict=True)
            ]
        )
        slope = np.gradient(rate, s) if rate.size > 1 else np.zeros_like(rate)
        dq = np.concatenate([dq, rate[:, None]], axis=1)
        ddq = np.concatenate([ddq, slope[:, None]], axis=1)
        accel = np.concatenate([accel, (limit * scale)[:, None]], axis=1)
    return dq, ddq, accel


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
    bound on ``x = (ds/dt)²`` (:func:`speed_bounds`); ``accel`` (dof,) rad/s², or (K, dof) per
    gridpoint: joint acceleration limits, ``|q' u + q'' x| <= a`` with ``u = d²s/dt²``, imposed
    as TOPPRA's *interpolation* scheme does: on each stage ``i`` (``x_i`` to
    ``x_{i+1} = x_i + 2 Δ_i u_i``) at both of its gridpoints. In ``(x, y) = (x_i, x_{i+1})``
    each of these 2·dof constraints reads ``-c - w x <= y <= c - w x`` (:func:`_stage_rows`),
    so

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
    rows = _StageRows(delta, dq, ddq, np.broadcast_to(accel, dq.shape))
    cap = np.minimum(x_max[:-1], _stage_caps(rows))
    controllable = _backward(rows, np.append(cap, 0.0))
    return np.sqrt(_forward(rows, controllable))


@dataclass(frozen=True, slots=True, eq=False)
class _StageRows:
    """The stage constraints of :func:`reachability_speeds`, made on demand for any stages:
    ``delta`` (N,) the stages' lengths; ``dq``, ``ddq`` (N+1, m); ``accel`` (N+1, m) the
    limits at each gridpoint (``inf``: none), of the joints and of any TCP rows."""

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
        limit = np.concatenate([self.accel[i], self.accel[j]], axis=1)
        return twice * limit / size, np.where(alpha < 0, -beta, beta) / size


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
            best = np.min(np.where(w > 0, _quotient(c, w), np.inf), axis=1)
            for k in range(c.shape[1] - 1):  # row k against each later row, all stages at once
                pairs = _quotient(
                    c[:, k : k + 1] + c[:, k + 1 :], np.abs(w[:, k : k + 1] - w[:, k + 1 :])
                )
                np.minimum(best, np.min(pairs, axis=1), out=best)
            out[here] = best
    return out


def _quotient(num: FloatArray, den: FloatArray) -> FloatArray:
    """``num / den`` for ``num >= 0`` (NaN and ``0 / 0`` as numpy gives them), ``inf`` where
    ``den`` is below ``num * _TINY_QUOTIENT``: such a bound on ``x`` is above ``1e100``, far
    above the cap :data:`~olp.passes.timing.plan.X_CAP` every ``x`` is held under, and the
    division would overflow (a wrist axis that stays within 1e-300 rad of 0 has such rows)."""
    keep = ~(den <= num * _TINY_QUOTIENT) | (num == 0.0)
    out = np.full(np.broadcast(num, den).shape, np.inf)
    return np.divide(num, den, out=out, where=keep)


_TINY_QUOTIENT = 1e-100
"""See :func:`_quotient`."""


def _backward(rows: _StageRows, bound: FloatArray) -> FloatArray:
    """Controllable squared speeds ``K`` (N+1,): ``K_i = min(bound_i, min_{w<0} (K_{i+1} + c)
    / -w)`` from ``K_N = bound_N``, swept until no stage changes."""
    out = bound.copy()

    def step(i: Stages, j: Stages) -> FloatArray:
        c, w = rows.at(i, j)
        with np.errstate(divide="ignore", invalid="ignore"):
            brake = np.where(w < 0, _quotient(out[j][:, None] + c, -w), np.inf)
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
