"""The timing pass itself: every row of a program timed by its timer on the program's
:class:`~olp.passes.timing.table.MotionTable`, the results written back to the steps (and to a
toolpath's :class:`~olp.compiled.PathBlock` as arrays), and what could not be timed as
diagnostics.

The timers fill one :class:`Times` of flat arrays, one row per instruction: fixed-time rows from
the time table, joint moves with Ruckig (:mod:`~olp.passes.timing.ptp`), stop-to-stop path moves
along a straight joint line in closed form, all at once (:mod:`~olp.passes.timing.lines`), and
the other chains of path moves with the path solver (:mod:`~olp.passes.timing.chains`). No
object is made per toolpath row.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator, Mapping, Sequence
from typing import TYPE_CHECKING, overload

import numpy as np
from numpy.typing import NDArray

from olp.compiled import CompiledProgram, PathBlock, RowTrajectories, Step, items_of, make_steps
from olp.compiled import span_of as _span
from olp.diagnostics import Diagnostic
from olp.ir import is_motion
from olp.passes.timing import corners as corner_rules
from olp.passes.timing import jerk, ptp, ptp_blend, ur
from olp.passes.timing.chains import PATH_SOLVERS, path_problem, time_law
from olp.passes.timing.geometry import ChainGeometry, joined_geometry
from olp.passes.timing.lines import LineProfiles, line_paths, line_profiles
from olp.passes.timing.plan import (
    MIN_PATH_SPEED,
    TimingError,
    TimingOptions,
    fixed_time,
    time_table,
)
from olp.passes.timing.problem import PathProblem
from olp.passes.timing.table import (
    COMMENT,
    FIXED,
    JOINT,
    KIND_NAMES,
    MotionTable,
    Plan,
    below_floor,
    gather,
    plan,
    sample_positions,
    travel,
)
from olp.station.model import Robot
from olp.trajectory import (
    JerkProfile,
    LineLaws,
    PathTimeLaw,
    Segment,
    SmoothedTimeLaw,
    TimeLaw,
)

if TYPE_CHECKING:
    from olp.passes.pipeline import BuildOptions
    from olp.station.model import Robot


FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


class Times:
    """What the timers found, one row per instruction (n,): ``duration`` s, ``length`` m of TCP
    travel, the time law ``law`` (an index into :attr:`laws`, -1: none) and the row's window
    ``start``..``end`` s of it; ``timed``: rows a timer filled (the others keep what they had).
    Laws are objects (a joint move's, a chain's) or, for the straight lines, one
    :class:`~olp.trajectory.LineLaws` of arrays."""

    def __init__(self, n: int) -> None:
        self.duration = np.zeros(n)
        self.length = np.zeros(n)
        self.law = np.full(n, -1, dtype=np.int64)
        self.start = np.zeros(n)
        self.end = np.zeros(n)
        self.timed = np.zeros(n, dtype=bool)
        # Blended corners timed as stops after all (olp.passes.timing.corners).
        self.stopped = np.zeros(n, dtype=bool)
        self.objects: list[TimeLaw] = []
        self.lines: LineLaws | None = None

    def add_law(self, law: TimeLaw) -> int:
        self.objects.append(law)
        return len(self.objects) - 1

    @property
    def laws(self) -> Sequence[TimeLaw]:
        return _Laws(self.objects, self.lines)


class _Laws(Sequence[TimeLaw]):
    """The object laws, then the line laws."""

    def __init__(self, objects: list[TimeLaw], lines: LineLaws | None) -> None:
        self.objects, self.lines = objects, lines

    def __len__(self) -> int:
        return len(self.objects) + (0 if self.lines is None else len(self.lines))

    @overload
    def __getitem__(self, k: int) -> TimeLaw: ...

    @overload
    def __getitem__(self, k: slice) -> Sequence[TimeLaw]: ...

    def __getitem__(self, k: int | slice) -> TimeLaw | Sequence[TimeLaw]:
        if isinstance(k, slice):
            return [self[i] for i in range(*k.indices(len(self)))]
        if k < len(self.objects):
            return self.objects[k]
        assert self.lines is not None
        return self.lines[k - len(self.objects)]

    def __iter__(self) -> Iterator[TimeLaw]:
        return (self[k] for k in range(len(self)))


def time_program(
    compiled: CompiledProgram,
    other_times: Mapping[str, float] | None = None,
    options: TimingOptions | None = None,
    stops: IntArray | None = None,
) -> CompiledProgram:
    """A copy of ``compiled`` whose steps carry ``duration`` (s), ``path_length`` (m of TCP
    travel) and, for motions, ``trajectory`` (a :class:`olp.trajectory.Segment`).

    Zones timed as stops add an ``info`` diagnostic (kind ``zone_stop``); a motion that cannot
    be timed keeps duration 0 and adds an ``error`` (kind ``timing``). Never raises on a bad
    program. ``stops`` (k,): instruction indices of motions timed as exact stops whatever
    their zone (the ends of the runs :mod:`~olp.passes.timing.branches` times together).
    """
    table = MotionTable.of(compiled)
    if stops is not None and stops.size:
        zone = table.zone.copy()
        zone[stops] = 0.0
        table = dataclasses.replace(table, zone=zone)
    positions = sample_positions(table, compiled.station.robot)
    lengths = travel(table, compiled.station.robot, positions)
    corners = plan(table, lengths)
    times = Times(table.size)
    opts = options or TimingOptions()
    time_fixed(table, time_table(other_times), times)
    found = time_joints(table, lengths, times)
    found += time_paths(table, lengths, corners, opts, times, positions)
    joint_blends = None if ur.applies(table) else ptp_blend.blended_joint_moves(table, lengths)
    found.sort(key=lambda d: d.index if d.index is not None else -1)
    found += _overflow(compiled, times.duration)
    return dataclasses.replace(
        compiled,
        steps=write_back(compiled, times),
        diagnostics=compiled.diagnostics
        + tuple(found)
        + tuple(zone_stops(table, corners, joint_blends, times.stopped)),
    )


def time_fixed(table: MotionTable, times: Mapping[str, float], out: Times) -> None:
    """Rows that are not resolved motions: their time from the time table (an unresolved
    motion: 0)."""
    for i in np.flatnonzero((table.kind == FIXED) | (table.kind == COMMENT)).tolist():
        step = table.compiled.steps[i] if not table.motion[i] else None
        out.duration[i] = 0.0 if step is None else fixed_time(step.instruction, times)
        out.timed[i] = True


def time_joints(table: MotionTable, lengths: FloatArray, out: Times) -> list[Diagnostic]:
    """Joint moves, one Ruckig profile each (on a UR arm: the trapezoid of the ``movej``
    written, :mod:`~olp.passes.timing.ur`); a joint move blended into the next one ends where
    its blend starts, and the next starts from that state
    (:mod:`~olp.passes.timing.ptp_blend`)."""
    found = list[Diagnostic]()
    on_ur = ur.applies(table)
    blends = np.zeros(table.size) if on_ur else ptp_blend.blended_joint_moves(table, lengths)
    state: tuple[FloatArray, FloatArray, FloatArray] | None = None
    for i in np.flatnonzero(table.kind == JOINT).tolist():
        law = ur.movej_law(table, i) if on_ur else None
        if law is not None:
            _fill(out, np.array([i]), out.add_law(law), np.array([0.0, law.duration]))
            out.length[i] = lengths[i]
            continue
        try:
            profile, end, state = _joint_move(table, lengths, i, float(blends[i]), state)
        except TimingError as exc:
            found.append(Diagnostic("error", "timing", str(exc), _span(table.compiled.steps, i), i))
            state = None
            continue
        _fill(out, np.array([i]), out.add_law(profile), np.array([0.0, end]))
        out.length[i] = lengths[i]
    return found


def _joint_move(
    table: MotionTable,
    lengths: FloatArray,
    i: int,
    blend: float,
    state: tuple[FloatArray, FloatArray, FloatArray] | None,
) -> tuple[JerkProfile, float, tuple[FloatArray, FloatArray, FloatArray] | None]:
    """Joint move ``i``: its profile (from rest, or from the ``state`` a blend handed over), the
    time it ends at (its blend's start, or the profile's end), and the state it hands over."""
    robot = table.compiled.station.robot
    q0, q1 = table.q[table.lo[i]], table.q[table.hi[i]]
    scales = float(table.joint[i]), float(table.joint_acceleration[i])
    if state is None:
        profile = ptp.ptp_profile(q0, q1, robot, *scales)
    else:
        profile = ptp_blend.profile_from(*state, q1, robot, *scales)
    if blend <= 0.0 or lengths[i] <= 0.0:
        return profile, profile.duration, None
    start = ptp_blend.blend_start(profile, q0, q1, blend / float(lengths[i]))
    q, qd, qdd = profile.state(np.array([start]))
    return profile, start, (q[0], qd[0], qdd[0])


def time_paths(
    table: MotionTable,
    lengths: FloatArray,
    corners: Plan,
    options: TimingOptions,
    out: Times,
    positions: FloatArray | None = None,
) -> list[Diagnostic]:
    """Path moves: the stop-to-stop ones along straight joint lines in closed form, the other
    chains by the path solver. ``positions`` (S, 3) m: the TCP at every sample of
    ``table.q``, if known (:func:`~olp.passes.timing.table.sample_positions`)."""
    sizes = corners.sizes
    firsts = corners.rows[corners.bounds[:-1]]
    lone = (sizes == 1) & ~below_floor(table, firsts)  # a too-slow move: the chain timer says so
    done = np.zeros(sizes.size, dtype=bool)
    if ur.applies(table) and np.any(lone):
        rows = ur.movel_rows(table, lengths, firsts[lone])
        for i in rows.tolist():
            law = ur.movel_law(table, lengths, i, options)
            _fill(out, np.array([i]), out.add_law(law), np.array([0.0, law.duration]))
            out.length[i] = lengths[i]
        done = np.isin(firsts, rows)
        lone &= ~done
    if options.straight_lines and np.any(lone):
        done[lone] = time_lines(table, lengths, firsts[lone], options, out, positions)
    return time_chains(table, corners, np.flatnonzero(~done), options, out)


def time_lines(
    table: MotionTable,
    lengths: FloatArray,
    rows: IntArray,
    options: TimingOptions,
    out: Times,
    positions: FloatArray | None = None,
) -> NDArray[np.bool_]:
    """Time stop-to-stop path moves ``rows`` that run along a straight joint line in closed
    form, all at once; returns which rows were timed (the others: not straight, or an error
    bound above ``line_tolerance``). ``positions``: as :func:`time_paths`."""
    q, sizes = gather(table, rows)
    paths = line_paths(q, sizes, options.line_deviation_rad)
    straight = paths.timed
    rows = rows[straight]
    q0, q1 = paths.q0[straight], paths.q1[straight]
    bow, span = paths.bow[straight], paths.span[straight]
    robot = table.compiled.station.robot
    profiles = _line_profiles(
        q0,
        q1,
        robot,
        (table.tools, table.tool[rows]),
        (
            table.linear[rows],
            table.angular[rows],
            table.linear_acceleration[rows],
            table.angular_acceleration[rows],
        ),
        options.path_jerk,
        (bow, span),
        None if positions is None else _end_positions(table, rows, positions),
    )
    bowed = np.any(bow != 0.0, axis=-1)
    ok = profiles.excess <= np.where(bowed, options.curve_tolerance, options.line_tolerance)
    rows = rows[ok]
    out.lines = LineLaws(
        q0[ok],
        q1[ok],
        profiles.accel[ok],
        profiles.ramp[ok],
        profiles.duration[ok],
        profiles.jerk_time[ok],
        bow[ok] if np.any(bow) else None,
        None if profiles.lead is None else profiles.lead[ok],
    )
    out.duration[rows] = out.end[rows] = profiles.duration[ok]
    out.start[rows] = 0.0
    out.length[rows] = lengths[rows]
    # LineLaws come after the object laws, whose count is known only at the end: offset later.
    out.law[rows] = -2 - np.arange(rows.size)
    out.timed[rows] = True
    timed = np.zeros(straight.size, dtype=bool)
    timed[np.flatnonzero(straight)[ok]] = True
    return timed


LINE_ROWS = 1 << 14
"""Moves per batch of :func:`line_profiles` (up to five forward kinematics each: about 10 kB
of temporaries per move, so a batch holds ~160 MB at most; all moves of a 100k toolpath at
once took 330 MB)."""


def _line_profiles(
    q0: FloatArray,
    q1: FloatArray,
    robot: Robot,
    tools: tuple[FloatArray, IntArray],
    limits: tuple[FloatArray, FloatArray, FloatArray, FloatArray],
    jerk: bool,
    shapes: tuple[FloatArray, FloatArray],
    ends: tuple[FloatArray, FloatArray] | None = None,
) -> LineProfiles:
    """:func:`line_profiles` in batches of :data:`LINE_ROWS` moves; ``tools``: the tool poses
    (T, 4, 4) and each move's index (M,) into them (a batch's poses are made with the batch);
    ``limits``: the TCP's linear and angular speeds and accelerations (M,) each; ``shapes``:
    the paths' bows (M, dof) and spans (M,) (:func:`~olp.passes.timing.lines.line_paths`)."""

    linear, angular, linear_accel, angular_accel = limits
    bow, span = shapes
    poses, tool = tools

    def batch(part: slice) -> LineProfiles:
        return line_profiles(
            q0[part],
            q1[part],
            robot,
            poses[tool[part]],
            linear[part],
            angular[part],
            linear_accel[part],
            angular_accel[part],
            jerk=jerk,
            bow=bow[part],
            span=span[part],
            ends=None if ends is None else (ends[0][part], ends[1][part]),
        )

    parts = [batch(slice(lo, lo + LINE_ROWS)) for lo in range(0, len(q0), LINE_ROWS)]
    if not parts:
        return batch(slice(0, 0))
    return LineProfiles(
        *(
            np.concatenate([getattr(p, f) for p in parts])
            for f in ("accel", "ramp", "duration", "excess", "jerk_time", "lead")
        )
    )


def _end_positions(
    table: MotionTable, rows: IntArray, positions: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The TCP positions (M, 3) m at the first and last samples of motions ``rows``, from the
    samples' ``positions``; NaN where a sample's tool is not the motion's (not known)."""
    lo, hi = table.lo[rows], table.hi[rows]
    own = (table.sample_tool[lo] == table.tool[rows]) & (table.sample_tool[hi] == table.tool[rows])
    return (
        np.where(own[:, None], positions[lo], np.nan),
        np.where(own[:, None], positions[hi], np.nan),
    )


def time_chains(
    table: MotionTable, corners: Plan, chains: IntArray, options: TimingOptions, out: Times
) -> list[Diagnostic]:
    """Chains ``chains`` of path moves: their geometry one by one, their time laws by
    ``options.solver`` all at once."""
    robot, steps = table.compiled.station.robot, table.compiled.steps
    found: list[Diagnostic] = []
    posed = []
    for c in chains.tolist():
        rows = corners.chain(c)
        slow = np.flatnonzero(below_floor(table, rows))
        if slow.size:
            found.append(_too_slow(table, int(rows[slow[0]])))
            continue
        q, sizes = gather(table, rows)
        tool = table.tools[table.tool[rows[0]]]
        geometry = joined_geometry(
            q, sizes, robot, tool, corners.blend[rows[:-1]], options.blend_samples
        )
        if geometry.s[-1] <= 0.0:  # no joint moves: the TCP stays put
            out.duration[rows] = out.length[rows] = 0.0
            out.timed[rows] = True
            continue
        problem = path_problem(
            geometry,
            tool,
            table.linear[rows],
            table.angular[rows],
            options,
            table.linear_acceleration[rows],
            table.angular_acceleration[rows],
        )
        posed.append((rows, geometry, problem))
    laws = solve_laws([problem for _, _, problem in posed], robot, options)
    for (rows, geometry, _), law in zip(posed, laws, strict=True):
        if isinstance(law, TimingError):
            first = int(rows[0])
            found.append(Diagnostic("error", "timing", str(law), _span(steps, first), first))
            continue
        if not _split_if_faster(table, corners, rows, (geometry, law), options, out):
            _fill(out, rows, out.add_law(law), law.time_at(geometry.boundaries))
            out.length[rows] = geometry.lengths
    return found


def _split_if_faster(
    table: MotionTable,
    corners: Plan,
    rows: IntArray,
    timed: tuple[ChainGeometry, PathTimeLaw | SmoothedTimeLaw],
    options: TimingOptions,
    out: Times,
) -> bool:
    """Time the chain ``rows`` again with its sharp corners stopped, if its jerk-limited law
    had to be slowed for them (:mod:`~olp.passes.timing.corners`), and keep that in ``out`` if
    it is faster; returns whether it was kept."""
    geometry, law = timed
    if not isinstance(law, SmoothedTimeLaw) or law.stretch <= 1.0 + corner_rules.SHARP_RATIO:
        return False
    stops = corner_rules.sharp_corners(law, geometry.boundaries, table.compiled.station.robot)
    if stops.size == 0:
        return False
    pieces = corners.stopped_at(rows, rows[stops])
    scratch = Times(table.size)
    found = time_chains(table, pieces, np.arange(pieces.sizes.size), options, scratch)
    if found or not np.all(scratch.timed[rows]):
        return False
    if float(np.sum(scratch.duration[rows])) >= law.duration:
        return False
    laws, mapped = np.unique(scratch.law[rows], return_inverse=True)
    index = np.array([out.add_law(scratch.objects[int(k)]) for k in laws], dtype=np.int64)
    out.law[rows] = index[mapped]
    for name in ("start", "end", "duration", "length", "timed", "stopped"):
        getattr(out, name)[rows] = getattr(scratch, name)[rows]
    out.stopped[rows[stops]] = True
    return True


def solve_laws(
    problems: Sequence[PathProblem], robot: Robot, options: TimingOptions
) -> list[PathTimeLaw | SmoothedTimeLaw | TimingError]:
    """The time laws of ``problems`` by ``options.solver``, all at once; with
    ``options.path_jerk`` jerk-limited (:mod:`~olp.passes.timing.jerk`: the chains whose
    acceleration must drop for the jerk limit solved once more, together)."""
    solver = PATH_SOLVERS[options.solver]
    laws = _laws(problems, solver(problems, robot))
    if not options.path_jerk:
        return list(laws)
    jerks = [jerk.path_jerk(p, robot) for p in problems]
    scales = [
        (np.inf, 1.0) if isinstance(law, TimingError) else jerk.scales(law, j)
        for law, j in zip(laws, jerks, strict=True)
    ]
    again = [
        k
        for k, (cap, f) in enumerate(scales)
        if np.isfinite(cap) or f < 1.0 - jerk.MIN_SCALE_CHANGE
    ]
    if again:
        scaled = jerk.rescaled([problems[k] for k in again], [scales[k] for k in again])
        for k, law in zip(again, _laws(scaled, solver(scaled, robot)), strict=True):
            if not isinstance(law, TimingError):
                laws[k] = law
    return [
        law if isinstance(law, TimingError) else jerk.jerk_limited(law, j, robot)
        for law, j in zip(laws, jerks, strict=True)
    ]


def _laws(
    problems: Sequence[PathProblem], speeds: Sequence[FloatArray]
) -> list[PathTimeLaw | TimingError]:
    out: list[PathTimeLaw | TimingError] = []
    for problem, sd in zip(problems, speeds, strict=True):
        try:
            out.append(time_law(problem, sd))
        except TimingError as exc:
            out.append(exc)
    return out


def _fill(out: Times, rows: IntArray, law: int, edges: FloatArray) -> None:
    """Rows ``rows`` share law ``law``, row k from ``edges[k]`` to ``edges[k + 1]`` s."""
    out.law[rows] = law
    out.start[rows], out.end[rows] = edges[:-1], edges[1:]
    out.duration[rows] = edges[1:] - edges[:-1]
    out.timed[rows] = True


def _too_slow(table: MotionTable, i: int) -> Diagnostic:
    """The error for a path move whose programmed speed is below :data:`MIN_PATH_SPEED`."""
    linear, angular = float(table.linear[i]), float(table.angular[i])
    which, value, unit = (
        ("TCP speed", linear * 1000, "mm/s")
        if linear < MIN_PATH_SPEED
        else ("orientation speed", float(np.degrees(angular)), "°/s")
    )
    msg = (
        f"the programmed {which} of {value:.3g} {unit} is too low to time (the slowest olp "
        f"times is {MIN_PATH_SPEED:g} m/s or rad/s)"
    )
    return Diagnostic("error", "timing", msg, _span(table.compiled.steps, i), i)


def write_back(compiled: CompiledProgram, times: Times) -> Sequence[Step]:
    """The steps of ``compiled`` with what the timers found: ordinary steps replaced, blocks
    given arrays."""
    offset = len(times.objects)
    law = np.where(times.law <= -2, offset - 2 - times.law, times.law)
    laws = times.laws
    items: list[Step | PathBlock] = []
    for item in items_of(compiled.steps):
        if isinstance(item, PathBlock):
            items.append(_block(item, times, law, laws))
        elif times.timed[item.index]:
            i = item.index
            segment = None
            if law[i] >= 0:
                segment = Segment(laws[int(law[i])], float(times.start[i]), float(times.end[i]))
            elif is_motion(item.instruction):
                segment = item.trajectory
            items.append(
                dataclasses.replace(
                    item,
                    duration=float(times.duration[i]),
                    path_length=float(times.length[i]),
                    trajectory=segment,
                )
            )
        else:
            items.append(item)
    return make_steps(items)


def _block(block: PathBlock, times: Times, law: IntArray, laws: Sequence[TimeLaw]) -> PathBlock:
    rows = slice(block.start, block.stop)
    timed = times.timed[rows]
    zeros = np.zeros(len(block))
    old = block.durations if block.durations is not None else zeros
    old_lengths = block.lengths if block.lengths is not None else zeros
    trajectories = None
    if np.any(law[rows] >= 0):
        trajectories = RowTrajectories(
            laws, law[rows].copy(), times.start[rows].copy(), times.end[rows].copy()
        )
    return dataclasses.replace(
        block,
        durations=np.where(timed, times.duration[rows], old),
        lengths=np.where(timed, times.length[rows], old_lengths),
        trajectories=trajectories,
    )


def _overflow(compiled: CompiledProgram, durations: FloatArray) -> list[Diagnostic]:
    """An error at the instruction where the running cycle time stops being a finite number
    (each duration is finite, their sum need not be: two waits of 1e308 s)."""
    with np.errstate(over="ignore"):
        total = np.cumsum(durations)
    bad = np.flatnonzero(~np.isfinite(total))
    if bad.size == 0:
        return []
    i = int(bad[0])
    msg = "the cycle time up to here exceeds the largest number olp can represent"
    return [Diagnostic("error", "timing", msg, _span(compiled.steps, i), i)]


def zone_stops(
    table: MotionTable,
    corners: Plan,
    joint_blends: FloatArray | None = None,
    stopped: NDArray[np.bool_] | None = None,
) -> list[Diagnostic]:
    """An info diagnostic for every zone that the model times as an exact stop although a
    motion follows (after the last motion the robot stops anyway); ``joint_blends`` (n,) m:
    the joint moves' blends (:func:`~olp.passes.timing.ptp_blend.blended_joint_moves`);
    ``stopped`` (n,): blended corners the chain timer stopped after all
    (:mod:`~olp.passes.timing.corners`)."""
    motions = np.flatnonzero(table.motion)
    if motions.size == 0:
        return []
    blended = corners.blend > 0
    if stopped is not None:
        blended &= ~stopped
    if joint_blends is not None:
        blended |= joint_blends > 0
    stops = (table.kind >= JOINT) & (table.zone > 0) & ~blended
    stops[motions[-1]] = False
    found = []
    for i in np.flatnonzero(stops).tolist():
        msg = (
            f"zone of {float(table.zone[i]) * 1000:g} mm timed as an exact stop "
            f"({_STOP_REASON[KIND_NAMES[int(table.kind[i])]]}): the cycle time is an upper "
            "bound here"
        )
        found.append(Diagnostic("info", "zone_stop", msg, _span(table.compiled.steps, i), i))
    return found


_PATH_STOP = (
    "the next motion is not a path move with the same tool, the corner is too short, or the "
    "path turns back or too sharply to blend at speed"
)


_STOP_REASON = {
    "joint": "the next motion is not a joint move, the corner is too short, or the robot is a "
    "UR arm, whose blended movej olp times as stops",
    "linear": _PATH_STOP,
    "circular": _PATH_STOP,
}


def timing_pass(compiled: CompiledProgram, options: BuildOptions) -> CompiledProgram:
    """The timing pass: :func:`time_program` with ``options.other_times`` and
    ``options.timing``; a program with errors is not timed (nothing will run)."""
    if not compiled.ok:
        return compiled
    return time_program(compiled, options.other_times, options.timing)
