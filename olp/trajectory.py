"""Timed motion: evaluate, sample, write and plot the joint trajectory of a timed program.

The timing pass (:mod:`olp.passes.timing`) attaches a :class:`Segment` to every timed motion step.
A segment is a time window of a *time law*:

* :class:`JerkProfile` — a Ruckig joint move: per axis seven phases of constant jerk;
* :class:`PathTimeLaw` — a TOPPRA path: a joint spline ``q(s)`` and a path speed that changes
  with constant path acceleration between gridpoints;
* :class:`SmoothedTimeLaw` — a :class:`PathTimeLaw` averaged over a sliding window: the
  jerk-limited law of a path chain;
* :class:`LineTimeLaw` — a stop-to-stop path move along a straight joint-space line, timed in
  closed form: a double S (jerk-limited; a trapezoid without jerk) in the fraction of the line.

Several steps share one :class:`PathTimeLaw` when their moves are blended into one path. All
laws evaluate vectorised in numpy and need neither Ruckig nor TOPPRA afterwards.

:func:`sample_program` samples a timed program at a fixed ``dt`` (between motions the robot holds
its last joints); :func:`write_csv` and :func:`plot_trajectory` write the samples.

CSV columns (one header line, ``,``-separated, ``\\n`` line ends, fixed decimals, independent
of the locale): ``time_s``, ``j1_deg`` .. ``j6_deg`` (controller convention, as the pendant
shows), ``j1_deg_s`` .. ``j6_deg_s``, ``tcp_x_mm``, ``tcp_y_mm``, ``tcp_z_mm`` (the active tool's
TCP in the station's world frame) and ``instruction`` (0-based index of the instruction running).
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, overload

import numpy as np
from numpy.typing import NDArray

from olp.errors import UsageError
from olp.ir import is_motion

if TYPE_CHECKING:
    from olp.compiled import CompiledProgram

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


class TimeLaw(Protocol):
    """Joint state over time: ``state(t)`` for times (T,) s returns q, qd, qdd, each (T, dof)."""

    @property
    def duration(self) -> float: ...

    def state(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]: ...


class GeometricPath(Protocol):
    """A joint path ``q(s)``: ``path(s, order)`` returns the order-th derivative, (N, dof)."""

    def __call__(self, s: FloatArray, order: int = 0) -> FloatArray: ...


@dataclass(frozen=True, slots=True, eq=False)
class JerkProfile:
    """Per-axis piecewise-constant jerk (Ruckig's profile), synchronised to one duration.

    ``starts``: phase start times (dof, 8) s, the last one the end of the move; ``jerk``: (dof, 7)
    rad/s³; ``q``, ``qd``, ``qdd``: the state at each phase start, (dof, 8).
    """

    starts: FloatArray
    jerk: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray

    @classmethod
    def at_rest(cls, q: FloatArray) -> JerkProfile:
        """A zero-length move that holds joints ``q`` (dof,)."""
        zeros = np.zeros((q.size, 8))
        return cls(zeros, zeros[:, :7], np.repeat(q[:, None], 8, axis=1), zeros, zeros)

    @property
    def duration(self) -> float:
        return float(np.max(self.starts[:, -1]))

    def state(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Joint position, velocity, acceleration (T, dof) at times ``t`` (T,) s, held after
        the end."""
        dof = self.starts.shape[0]
        out = np.empty((3, t.size, dof))
        for axis in range(dof):  # six axes: the samples are vectorised
            out[:, :, axis] = self._axis_state(axis, t)
        return out[0], out[1], out[2]

    def _axis_state(self, axis: int, t: FloatArray) -> FloatArray:
        starts = self.starts[axis]
        tt = np.clip(t, 0.0, starts[-1])
        phase = np.clip(np.searchsorted(starts, tt, side="right") - 1, 0, 6)
        tau = tt - starts[phase]
        j = self.jerk[axis, phase]
        a0, v0, p0 = self.qdd[axis, phase], self.qd[axis, phase], self.q[axis, phase]
        return np.stack(
            [
                p0 + tau * (v0 + tau * (a0 / 2 + tau * j / 6)),
                v0 + tau * (a0 + tau * j / 2),
                a0 + tau * j,
            ]
        )


@dataclass(frozen=True, slots=True, eq=False)
class PathTimeLaw:
    """A joint path ``q(s)`` timed by gridpoints: constant path acceleration between them.

    ``path``: the geometric path; ``s``: gridpoints (K,); ``sd``: path speed at them (K,) 1/s
    in units of ``s``; ``t``: the time at each gridpoint (K,) s, from 0.
    """

    path: GeometricPath
    s: FloatArray
    sd: FloatArray
    t: FloatArray

    @classmethod
    def from_speeds(cls, path: GeometricPath, s: FloatArray, sd: FloatArray) -> PathTimeLaw:
        """The law whose path speed is ``sd`` (K,) at gridpoints ``s`` (K,): each interval takes
        ``2 ds / (sd_i + sd_i+1)`` (constant acceleration)."""
        times = 2.0 * np.diff(s) / (sd[:-1] + sd[1:])
        return cls(path, s, sd, np.concatenate([[0.0], np.cumsum(times)]))

    @property
    def duration(self) -> float:
        return float(self.t[-1])

    def time_at(self, s: FloatArray) -> FloatArray:
        """Times (N,) s at which the path parameter reaches gridpoint values ``s`` (N,)."""
        return np.interp(s, self.s, self.t)

    def path_state(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Path parameter, its speed and acceleration (T,) each at times ``t`` (T,) s."""
        tt = np.clip(t, 0.0, self.t[-1])
        i = np.clip(np.searchsorted(self.t, tt, side="right") - 1, 0, self.s.size - 2)
        ds = self.s[i + 1] - self.s[i]
        accel = (self.sd[i + 1] ** 2 - self.sd[i] ** 2) / (2.0 * ds)
        tau = tt - self.t[i]
        s = np.clip(self.s[i] + tau * (self.sd[i] + 0.5 * accel * tau), self.s[i], self.s[i + 1])
        sd = np.maximum(self.sd[i] + accel * tau, 0.0)
        return s, sd, np.where(tt >= self.t[-1], 0.0, accel)

    def state(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Joint position, velocity, acceleration (T, dof) at times ``t`` (T,) s."""
        s, sd, sdd = self.path_state(t)
        dq, ddq = self.path(s, 1), self.path(s, 2)
        return self.path(s), dq * sd[:, None], ddq * (sd**2)[:, None] + dq * sdd[:, None]


@dataclass(frozen=True, slots=True, eq=False)
class SmoothedTimeLaw:
    """A :class:`PathTimeLaw` ``base`` whose path parameter is averaged over a sliding window of
    ``window`` s (a moving-average, "FIR", filter of the time law): ``s(t) = (1 / w)
    ∫_{t-w}^{t} s_base(τ) dτ``, with the base at rest before 0 and after its end. Then
    ``ds/dt = (s_base(t) - s_base(t - w)) / w``, ``d²s/dt² = (ṡ_base(t) - ṡ_base(t - w)) / w``
    and ``d³s/dt³ = (s̈_base(t) - s̈_base(t - w)) / w``: the path speed and acceleration stay
    within the base's ranges, the path jerk is bounded by the base's largest change of
    acceleration within ``w`` over ``w``, and the move lasts ``w`` longer (Biagiotti &
    Melchiorri, "FIR filters for online trajectory planning with time- and frequency-domain
    specifications", Control Engineering Practice 20, 2012; see
    :mod:`olp.passes.timing.jerk`). ``stretch`` >= 1 slows the averaged law uniformly (time
    ``t`` of the law is ``t / stretch`` of the average: speeds divided by it, accelerations by
    its square)."""

    base: PathTimeLaw
    window: float
    stretch: float = 1.0
    _integrals: FloatArray = field(init=False, repr=False)
    _accels: FloatArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        law = self.base
        # Absurdly slow laws (hours per micrometre) overflow to inf here, as their times do.
        with np.errstate(over="ignore", invalid="ignore"):
            h = np.diff(law.t)
            accel = (law.sd[1:] ** 2 - law.sd[:-1] ** 2) / (2.0 * np.diff(law.s))
            pieces = law.s[:-1] * h + law.sd[:-1] * h**2 / 2 + accel * h**3 / 6
        object.__setattr__(self, "_accels", accel)
        object.__setattr__(self, "_integrals", np.concatenate([[0.0], np.cumsum(pieces)]))

    @property
    def path(self) -> GeometricPath:
        return self.base.path

    @property
    def duration(self) -> float:
        return (self.base.duration + self.window) * self.stretch

    def _integral(self, t: FloatArray) -> FloatArray:
        """``∫_0^t s_base`` (T,) at times ``t`` (T,) s (``s_base = 0`` before 0)."""
        law, total, accel = self.base, self._integrals, self._accels
        with np.errstate(over="ignore", invalid="ignore"):
            tt = np.clip(t, 0.0, law.t[-1])
            i = np.clip(np.searchsorted(law.t, tt, side="right") - 1, 0, law.s.size - 2)
            tau = tt - law.t[i]
            inside = total[i] + law.s[i] * tau + law.sd[i] * tau**2 / 2 + accel[i] * tau**3 / 6
            after = np.maximum(t - law.t[-1], 0.0) * law.s[-1]
            out: FloatArray = np.where(t <= 0.0, 0.0, inside + after)
        return out

    def _base_state(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        s, sd, sdd = self.base.path_state(t)
        return s, sd, np.where(t < 0.0, 0.0, sdd)

    def path_state(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Path parameter, its speed and acceleration (T,) each at times ``t`` (T,) s."""
        k = self.stretch
        s, sd, sdd = self._averaged(np.asarray(t, dtype=np.float64) / k)
        return s, sd / k, sdd / k**2

    def _averaged(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        w = self.window
        tt = np.clip(t, 0.0, self.base.duration + w)
        now, before = self._base_state(tt), self._base_state(tt - w)
        s = (self._integral(tt) - self._integral(tt - w)) / w
        s = np.clip(s, self.base.s[0], self.base.s[-1])
        return s, (now[0] - before[0]) / w, (now[1] - before[1]) / w

    def time_at(self, s: FloatArray) -> FloatArray:
        """Times (N,) s at which the path parameter reaches ``s`` (N,): interpolated on the
        times where the averaged law changes form, then refined by Newton steps."""
        w, law = self.window, self.base
        knots = self.knots()
        along = self._averaged(knots)[0]
        t = np.interp(s, along, knots)
        # One Newton step: between knots the averaged law is one cubic, close to the chord.
        here, speed, _accel = self._averaged(t)
        step = np.where(speed > 0.0, (here - s) / np.where(speed > 0.0, speed, 1.0), 0.0)
        t = np.clip(t - step, 0.0, law.duration + w)
        t = np.where(s <= law.s[0], 0.0, t)
        out: FloatArray = np.where(s >= law.s[-1], law.duration + w, t) * self.stretch
        return out

    def knots(self) -> FloatArray:
        """Times (of the unstretched average) where it changes form: the base's gridpoint
        times and those shifted by the window."""
        return np.unique(np.concatenate([self.base.t, self.base.t + self.window]))

    def state(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Joint position, velocity, acceleration (T, dof) at times ``t`` (T,) s."""
        s, sd, sdd = self.path_state(t)
        dq, ddq = self.path(s, 1), self.path(s, 2)
        return self.path(s), dq * sd[:, None], ddq * (sd**2)[:, None] + dq * sdd[:, None]

    def rates(self, t: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Joint velocity and acceleration (T, dof) at times ``t`` (T,) s (:meth:`state`
        without the positions)."""
        s, sd, sdd = self.path_state(t)
        dq, ddq = self.path(s, 1), self.path(s, 2)
        return dq * sd[:, None], ddq * (sd**2)[:, None] + dq * sdd[:, None]


def _ramp_state(
    t: FloatArray, jerk_time: Any, ramp: Any, accel: Any
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Distance, speed and acceleration (T,) at times ``t`` (T,) in ``[0, ramp]`` of a ramp from
    rest (the first phase of a double S, :mod:`olp.passes.timing.scurve`): jerk over
    ``jerk_time`` up to ``accel``, held, jerk down to 0 at ``ramp`` (scalars or (T,))."""
    tj, ta, ap = jerk_time, ramp, accel
    peak = ap * (ta - tj)
    safe = np.where(tj > 0, tj, 1.0)
    rising, falling = t < tj, t > ta - tj
    rest = ta - t
    mid = t - tj
    u = np.where(
        rising,
        ap * t**3 / (6 * safe),
        np.where(
            falling,
            peak * ta / 2 - peak * rest + ap * rest**3 / (6 * safe),
            ap * tj**2 / 6 + ap * tj / 2 * mid + ap * mid**2 / 2,
        ),
    )
    v = np.where(
        rising,
        ap * t**2 / (2 * safe),
        np.where(falling, peak - ap * rest**2 / (2 * safe), ap * tj / 2 + ap * mid),
    )
    a = np.where(rising, ap * t / safe, np.where(falling, ap * rest / safe, ap))
    return u, v, a


@dataclass(frozen=True, slots=True, eq=False)
class LineTimeLaw:
    """Rest to rest along the straight joint line ``q0 + u (q1 - q0)``, ``u`` from 0 to 1: a
    double S (:mod:`olp.passes.timing.scurve`) in ``u``: each ramp raises the acceleration to
    ``accel`` at constant jerk over ``jerk_time``, holds it, lowers it over ``jerk_time``; the
    move cruises between the ramps (none when ``ramp`` is half the duration). ``jerk_time`` 0 is
    a trapezoid.

    ``q0``, ``q1``: the line's ends (dof,) rad; ``accel``: 1/s² in fractions of the line;
    ``ramp``: the time (s) of each of the acceleration and braking phases; ``total``: the
    duration (s); ``jerk_time`` (s). The cruise speed is ``accel * (ramp - jerk_time)`` (1/s).
    ``bow`` (dof,) rad, if given: the path is the parabola ``q0 + u (q1 - q0) + u (u - 1) bow``
    (a move resolved as three samples, as the chain timer's spline through them,
    :func:`olp.passes.timing.lines.line_paths`), ``u`` its chord-length parameter's fraction;
    with ``lead`` >= 0 the double S runs in that joint's fraction ``σ`` of its move instead,
    ``u = 2σ / ((1 - β) + sqrt((1 - β)² + 4βσ))`` with ``β = bow_l / (q1 - q0)_l``.
    """

    q0: FloatArray
    q1: FloatArray
    accel: float
    ramp: float
    total: float
    jerk_time: float = 0.0
    bow: FloatArray | None = None
    lead: int = -1

    @property
    def duration(self) -> float:
        return self.total

    def fraction_state(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Fraction of the line, its rate (1/s) and acceleration (1/s²), (T,) each, at times
        ``t`` (T,) s; held at the ends outside ``[0, duration]``."""
        tt = np.clip(t, 0.0, self.total)
        rest = self.total - tt
        tj, ramp, a = self.jerk_time, self.ramp, self.accel
        peak = a * (ramp - tj)
        rising, falling = tt < ramp, rest < ramp
        up = _ramp_state(np.minimum(tt, ramp), tj, ramp, a)
        down = _ramp_state(np.minimum(rest, ramp), tj, ramp, a)
        u = np.where(rising, up[0], peak * ramp / 2 + peak * (tt - ramp))
        u = np.where(falling, 1.0 - down[0], u)
        ud = np.where(rising, up[1], np.where(falling, down[1], peak))
        # At a triangle's peak both phases meet; the end holds still (as PathTimeLaw).
        udd = np.where(rising, up[2], np.where(falling & (rest > 0.0), -down[2], 0.0))
        return u, ud, udd

    def state(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Joint position, velocity, acceleration (T, dof) at times ``t`` (T,) s."""
        u, ud, udd = self.fraction_state(t)
        line = self.q1 - self.q0
        if self.bow is None:
            return self.q0 + u[:, None] * line, ud[:, None] * line, udd[:, None] * line
        if self.lead >= 0:
            u, ud, udd = self._from_lead(u, ud, udd)
        u, ud, udd = u[:, None], ud[:, None], udd[:, None]
        tangent = line + (2.0 * u - 1.0) * self.bow
        q = self.q0 + u * line + u * (u - 1.0) * self.bow
        return q, ud * tangent, udd * tangent + 2.0 * ud**2 * self.bow

    def _from_lead(
        self, sigma: FloatArray, rate: FloatArray, accel: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The parabola's parameter ``u``, its rate and acceleration (T,) from the lead
        joint's fraction ``σ``, its rate and acceleration (T,)."""
        assert self.bow is not None
        beta = float(self.bow[self.lead] / (self.q1 - self.q0)[self.lead])
        u = 2.0 * sigma / ((1.0 - beta) + np.sqrt((1.0 - beta) ** 2 + 4.0 * beta * sigma))
        slope = 1.0 / (1.0 + (2.0 * u - 1.0) * beta)  # du/dσ
        bend = -2.0 * beta * slope**3  # d²u/dσ²
        return u, slope * rate, bend * rate**2 + slope * accel


class LineLaws(Sequence[LineTimeLaw]):
    """Many :class:`LineTimeLaw` as arrays (a toolpath's fine-stopped moves), each law made
    only when asked for: ``q0``, ``q1`` (M, dof) rad; ``accel`` (M,) 1/s², ``ramp``, ``total``
    and ``jerk_time`` (M,) s, ``bow`` (M, dof) rad (None: all straight; a row of zeros:
    that one) and ``lead`` (M,) (None: -1 for all), as the fields of :class:`LineTimeLaw`."""

    def __init__(
        self,
        q0: FloatArray,
        q1: FloatArray,
        accel: FloatArray,
        ramp: FloatArray,
        total: FloatArray,
        jerk_time: FloatArray | None = None,
        bow: FloatArray | None = None,
        lead: IntArray | None = None,
    ) -> None:
        self.q0, self.q1, self.accel, self.ramp, self.total = q0, q1, accel, ramp, total
        self.jerk_time = np.zeros_like(total) if jerk_time is None else jerk_time
        self.bow, self.lead = bow, lead

    def __len__(self) -> int:
        return int(self.total.size)

    @overload
    def __getitem__(self, k: int) -> LineTimeLaw: ...

    @overload
    def __getitem__(self, k: slice) -> Sequence[LineTimeLaw]: ...

    def __getitem__(self, k: int | slice) -> LineTimeLaw | Sequence[LineTimeLaw]:
        if isinstance(k, slice):
            return [self[i] for i in range(*k.indices(len(self)))]
        return LineTimeLaw(
            self.q0[k],
            self.q1[k],
            float(self.accel[k]),
            float(self.ramp[k]),
            float(self.total[k]),
            float(self.jerk_time[k]),
            None if self.bow is None or not np.any(self.bow[k]) else self.bow[k],
            -1 if self.lead is None or self.bow is None else int(self.lead[k]),
        )


@dataclass(frozen=True, slots=True, eq=False)
class Segment:
    """One step's share ``[start, end]`` (s, in the law's time) of a time law."""

    law: TimeLaw
    start: float
    end: float

    @property
    def duration(self) -> float:
        return self.end - self.start

    def state(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Joint position, velocity, acceleration (T, dof) at times ``t`` (T,) s from the step's
        start."""
        return self.law.state(self.start + np.clip(t, 0.0, self.duration))


# --------------------------------------------------------------------------------------------
# Sampling a program


@dataclass(frozen=True, slots=True, eq=False)
class SampledTrajectory:
    """A timed program sampled at a fixed step.

    ``t`` (T,) s; ``q``, ``qd`` (T, dof) rad and rad/s (controller convention); ``tcp`` (T, 3) m,
    the active tool's TCP in the world frame; ``index`` (T,) the running instruction.
    """

    t: FloatArray
    q: FloatArray
    qd: FloatArray
    tcp: FloatArray
    index: IntArray


def sample_program(compiled: CompiledProgram, dt: float = 0.01) -> SampledTrajectory:
    """Sample a timed program every ``dt`` seconds, from 0 to the first sample at or after its
    end. Instruction ``i`` runs on ``[start_i, start_i + duration_i)``; between motions, and
    after the end, the joints hold still. The TCP is the active tool's (before the first motion,
    the first motion's tool)."""
    if not (np.isfinite(dt) and dt > 0):
        raise UsageError(f"the sampling step must be > 0 s, got {dt}")
    if not compiled.ok or not compiled.steps:
        raise UsageError("the program has errors or no instructions: there is no trajectory")
    durations = np.array([step.duration for step in compiled.steps], dtype=np.float64)
    with np.errstate(over="ignore", invalid="ignore"):
        starts = np.concatenate([[0.0], np.cumsum(durations)])
        wanted = float(np.ceil(starts[-1] / dt - 1e-9)) + 1.0
    if not wanted <= MAX_SAMPLES:  # also inf and NaN
        raise UsageError(
            f"dt {dt:g} s would give {wanted:.4g} samples of the {starts[-1]:.4g} s program "
            f"(at most {MAX_SAMPLES}): choose a larger step"
        )
    count = int(wanted)
    t: FloatArray = np.arange(count, dtype=np.float64) * dt
    owner = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, durations.size - 1)
    bounds = np.searchsorted(owner, np.arange(durations.size + 1), side="left")
    q = np.empty((count, compiled.start_joints.size))
    qd = np.zeros_like(q)
    tcp = np.empty((count, 3))
    joints = compiled.start_joints
    robot = compiled.station.robot
    for step, tool in zip(compiled.steps, _active_tools(compiled), strict=True):
        rows = slice(bounds[step.index], bounds[step.index + 1])
        if step.trajectory is not None:
            q[rows], qd[rows], _ = step.trajectory.state(t[rows] - starts[step.index])
        else:
            q[rows] = joints
        tcp[rows] = (robot.flange_poses(q[rows]) @ tool)[:, :3, 3]
        joints = step.joints if step.joints is not None else joints
    return SampledTrajectory(t=t, q=q, qd=qd, tcp=tcp, index=owner.astype(np.int64))


MAX_SAMPLES = 20_000_000
"""More samples than this is an input error (a step far too small for the program)."""


def _active_tools(compiled: CompiledProgram) -> list[FloatArray]:
    """The TCP-in-flange pose (4, 4) active during each step."""
    poses = [
        s.tool.pose
        for s in compiled.steps
        if is_motion(s.instruction) and s.tool is not None and s.tool.pose is not None
    ]
    current = poses[0] if poses else np.eye(4)
    out = []
    for step in compiled.steps:
        if is_motion(step.instruction) and step.tool is not None and step.tool.pose is not None:
            current = step.tool.pose
        out.append(current)
    return out


# --------------------------------------------------------------------------------------------
# Output


CSV_DECIMALS: dict[str, int] = {"time": 6, "deg": 6, "deg_s": 4, "mm": 4}
"""Decimals per column family of the CSV (1 µs, 1e-6 deg, 1e-4 deg/s, 0.1 µm)."""


def csv_text(trajectory: SampledTrajectory) -> str:
    """The CSV text (header and one line per sample), see the module docstring."""
    dof = trajectory.q.shape[1]
    header = ["time_s", *(f"j{i}_deg" for i in range(1, dof + 1))]
    header += [*(f"j{i}_deg_s" for i in range(1, dof + 1)), "tcp_x_mm", "tcp_y_mm", "tcp_z_mm"]
    families = [("time", 1), ("deg", dof), ("deg_s", dof), ("mm", 3)]
    decimals = np.repeat([CSV_DECIMALS[name] for name, _ in families], [n for _, n in families])
    values = np.column_stack(
        [trajectory.t, np.degrees(trajectory.q), np.degrees(trajectory.qd), trajectory.tcp * 1e3]
    )
    # Rounding first turns tiny negatives into -0.0, and adding 0.0 makes those +0.0.
    rounded = np.stack([np.round(col, d) for col, d in zip(values.T, decimals, strict=True)]) + 0.0
    table = np.column_stack([rounded.T, trajectory.index])
    buffer = io.StringIO()
    # numpy's writer formats with Python's %-operator: independent of the locale.
    np.savetxt(
        buffer,
        table,
        fmt=[f"%.{d}f" for d in decimals] + ["%d"],
        delimiter=",",
        newline="\n",
        header=",".join([*header, "instruction"]),
        comments="",
    )
    return buffer.getvalue()


def write_csv(trajectory: SampledTrajectory, path: str | Path) -> Path:
    """Write :func:`csv_text` to ``path`` atomically; returns the path."""
    return write_atomic(Path(path), csv_text(trajectory).encode("ascii"))


def plot_trajectory(
    trajectory: SampledTrajectory, path: str | Path, boundaries: Sequence[float] = ()
) -> Path:
    """Draw joint positions and velocities over time, with vertical lines at ``boundaries``
    (instruction start times, s), into a PNG at ``path`` (written atomically)."""
    figure = _figure(trajectory, boundaries)
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    buffer = io.BytesIO()
    FigureCanvasAgg(figure).print_png(buffer, metadata={"Software": None})
    return write_atomic(Path(path), buffer.getvalue())


def require_matplotlib() -> None:
    """Raise a UsageError, with the remedy, if matplotlib cannot be imported."""
    try:
        import matplotlib.figure  # noqa: F401
    except ImportError as exc:
        raise UsageError(
            f"plotting needs matplotlib, which cannot be imported ({exc})",
            hint="install the plot extra: pip install 'olp[plot]'",
        ) from exc


def _figure(trajectory: SampledTrajectory, boundaries: Sequence[float]) -> Any:
    require_matplotlib()
    from matplotlib.figure import Figure

    figure = Figure(figsize=(10, 6.5), dpi=100, layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True)
    for axis in range(trajectory.q.shape[1]):
        top.plot(trajectory.t, np.degrees(trajectory.q[:, axis]), lw=1.0, label=f"J{axis + 1}")
        bottom.plot(trajectory.t, np.degrees(trajectory.qd[:, axis]), lw=1.0)
    for ax in (top, bottom):
        for start in boundaries:
            ax.axvline(start, color="0.8", lw=0.5, zorder=0)
        ax.grid(True, lw=0.3)
    top.set_ylabel("joint position (deg)")
    bottom.set_ylabel("joint velocity (deg/s)")
    bottom.set_xlabel("time (s); grey lines: instruction starts")
    top.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize="small")
    return figure


def instruction_starts(compiled: CompiledProgram) -> list[float]:
    """Start time (s) of every instruction that takes time, for plot boundaries."""
    starts, now = [], 0.0
    for step in compiled.steps:
        if step.duration > 0:
            starts.append(now)
        now += step.duration
    return starts


def write_atomic(path: Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically, with the umask's mode
    (:func:`olp.output.write_file`)."""
    from olp.output import write_file

    return write_file(path, data)
