"""Timed motion: evaluate, sample, write and plot the joint trajectory of a timed program.

The timing pass (:mod:`olp.passes.timing`) attaches a :class:`Segment` to every timed motion step.
A segment is a time window of a *time law*:

* :class:`JerkProfile` — a Ruckig joint move: per axis seven phases of constant jerk;
* :class:`PathTimeLaw` — a TOPPRA path: a joint spline ``q(s)`` and a path speed that changes
  with constant path acceleration between gridpoints;
* :class:`LineTimeLaw` — a stop-to-stop path move along a straight joint-space line, timed in
  closed form: a trapezoid (or triangle) in the fraction of the line.

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
from dataclasses import dataclass
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
class LineTimeLaw:
    """Rest to rest along the straight joint line ``q0 + u (q1 - q0)``, ``u`` from 0 to 1: ``u``
    accelerates at ``accel``, cruises, and brakes at ``accel`` (a triangle when ``ramp`` is half
    the duration).

    ``q0``, ``q1``: the line's ends (dof,) rad; ``accel``: 1/s² in fractions of the line;
    ``ramp``: the time (s) of each of the acceleration and braking phases; ``total``: the
    duration (s). The cruise speed is ``accel * ramp`` (1/s).
    """

    q0: FloatArray
    q1: FloatArray
    accel: float
    ramp: float
    total: float

    @property
    def duration(self) -> float:
        return self.total

    def fraction_state(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Fraction of the line, its rate (1/s) and acceleration (1/s²), (T,) each, at times
        ``t`` (T,) s; held at the ends outside ``[0, duration]``."""
        tt = np.clip(t, 0.0, self.total)
        rest = self.total - tt
        a, ramp = self.accel, self.ramp
        rising, falling = tt < ramp, rest < ramp
        u = np.where(rising, 0.5 * a * tt**2, a * ramp * (tt - 0.5 * ramp))
        u = np.where(falling, 1.0 - 0.5 * a * rest**2, u)
        ud = a * np.where(rising, tt, np.where(falling, rest, ramp))
        # At a triangle's peak both phases meet; the end holds still (as PathTimeLaw).
        udd = np.where(rising, a, np.where(falling & (rest > 0.0), -a, 0.0))
        return u, ud, udd

    def state(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Joint position, velocity, acceleration (T, dof) at times ``t`` (T,) s."""
        u, ud, udd = self.fraction_state(t)
        line = self.q1 - self.q0
        return self.q0 + u[:, None] * line, ud[:, None] * line, udd[:, None] * line


class LineLaws(Sequence[LineTimeLaw]):
    """Many :class:`LineTimeLaw` as arrays (a toolpath's fine-stopped moves), each law made
    only when asked for: ``q0``, ``q1`` (M, dof) rad; ``accel`` (M,) 1/s², ``ramp`` and
    ``total`` (M,) s, as the fields of :class:`LineTimeLaw`."""

    def __init__(
        self, q0: FloatArray, q1: FloatArray, accel: FloatArray, ramp: FloatArray, total: FloatArray
    ) -> None:
        self.q0, self.q1, self.accel, self.ramp, self.total = q0, q1, accel, ramp, total

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
            self.q0[k], self.q1[k], float(self.accel[k]), float(self.ramp[k]), float(self.total[k])
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
