"""Calibration: per-axis velocity, acceleration and jerk limits fitted to a recorded joint
trajectory, written as a station override, with the residual of re-timing the recording.

Input: a CSV of time and joint positions, either olp's own trajectory CSV (``time_s``,
``j1_deg`` .. ``jN_deg``, :func:`olp.trajectory.write_csv`) or a UR RTDE recording
(``timestamp``, ``actual_q_0`` .. ``actual_q_5`` in rad, space- or comma-separated); the
joints in the controller's convention. Rows must be in time order, at least
:data:`MIN_SAMPLES` of them.

The fit: the derivatives of each axis by a cubic Savitzky-Golay filter (a local cubic fitted to
``window`` samples: exact where the recording is a cubic in time, as a jerk-limited profile is
between its switches, and a weighted average across a switch), and each limit the largest
magnitude seen. This assumes the recording drives every axis into each of its limits
somewhere (a time-optimal move on which that axis leads); an axis that never reaches a limit
gets a lower, conservative one, and the residual shows it.

The residual: the recording is cut into moves at its rests (all axes below
:data:`REST_FRACTION` of their fitted velocity), each move re-timed rest to rest with the
fitted limits (Ruckig, phase-synchronised: what olp assumes for a joint move), and the summed
time compared with the recorded one.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from olp.errors import UsageError
from olp.passes.timing import ptp
from olp.passes.timing.plan import TimingError
from olp.station.model import JointLimits, Robot

FloatArray = NDArray[np.float64]

MIN_SAMPLES = 16
"""Fewest rows a recording may have."""

REST_FRACTION = 1e-5
"""An instant is a rest when every axis moves slower than this fraction of its fitted limit
(above the derivative noise of positions recorded to 1e-6 deg at 250 Hz, about 2e-6; a
jerk-limited start spends under one such sample below it)."""

WINDOW = 7
"""Samples of the Savitzky-Golay filter (odd)."""


@dataclass(frozen=True, slots=True)
class Recording:
    """Times ``t`` (N,) s and joints ``q`` (N, dof) rad of a recorded trajectory."""

    t: FloatArray
    q: FloatArray


@dataclass(frozen=True, slots=True)
class Calibration:
    """Fitted limits (dof,) each: ``velocity`` rad/s, ``acceleration`` rad/s², ``jerk`` rad/s³;
    the recording's ``moves`` and their ``recorded`` and ``retimed`` durations (s, summed)."""

    velocity: FloatArray
    acceleration: FloatArray
    jerk: FloatArray
    moves: int
    recorded: float
    retimed: float

    @property
    def residual(self) -> float:
        """Relative difference of the re-timed from the recorded time of the moves."""
        return self.retimed / self.recorded - 1.0 if self.recorded > 0 else 0.0


def read_recording(text: str, name: str, dof: int) -> Recording:
    """A recording from CSV text (see the module docstring); a bad file is a
    :class:`~olp.errors.UsageError` naming the file and line."""
    lines = [line for line in text.splitlines() if line.strip() and not line.startswith("#")]
    if not lines:
        raise UsageError(f"{name}: empty recording")
    delimiter = "," if "," in lines[0] else None
    rows = [
        [cell.strip() for cell in (row if delimiter else row[0].split())]
        for row in csv.reader(io.StringIO("\n".join(lines)), delimiter=delimiter or ",")
    ]
    header = [cell.lower() for cell in rows[0]]
    time_col, joint_cols, to_rad = _columns(header, name, dof)
    values = []
    for number, row in enumerate(rows[1:], start=2):
        try:
            values.append([float(row[time_col]), *(float(row[c]) for c in joint_cols)])
        except (ValueError, IndexError):
            raise UsageError(f"{name}:{number}: expected numbers in every column") from None
    data = np.array(values, dtype=np.float64)
    if data.shape[0] < MIN_SAMPLES:
        raise UsageError(f"{name}: at least {MIN_SAMPLES} rows are needed, found {len(data)}")
    if not np.all(np.isfinite(data)):
        raise UsageError(f"{name}: a value is not a finite number")
    if np.any(np.diff(data[:, 0]) <= 0):
        line = int(np.argmax(np.diff(data[:, 0]) <= 0)) + 3
        raise UsageError(f"{name}:{line}: times must increase")
    return Recording(data[:, 0] - data[0, 0], data[:, 1:] * to_rad)


def _columns(header: Sequence[str], name: str, dof: int) -> tuple[int, list[int], float]:
    """The time column, the joint columns and the factor to radians."""
    for time_name, joint_names, to_rad in (
        ("time_s", [f"j{k}_deg" for k in range(1, dof + 1)], math.pi / 180.0),
        ("timestamp", [f"actual_q_{k}" for k in range(dof)], 1.0),
    ):
        if time_name in header and all(j in header for j in joint_names):
            return header.index(time_name), [header.index(j) for j in joint_names], to_rad
    raise UsageError(
        f"{name}:1: expected the columns time_s, j1_deg .. j{dof}_deg (olp's trajectory CSV) "
        f"or timestamp, actual_q_0 .. actual_q_{dof - 1} (UR RTDE, rad)"
    )


def fit_limits(recording: Recording, robot: Robot) -> Calibration:
    """The limits of the module docstring and the residual of re-timing the recording."""
    velocity, acceleration, jerk = _derivatives(recording)
    limits = (np.max(np.abs(d), axis=0) for d in (velocity, acceleration, jerk))
    v_max, a_max, j_max = limits
    if np.any(v_max <= 0) or np.any(a_max <= 0) or np.any(j_max <= 0):
        raise UsageError("the recording leaves an axis still: its limits cannot be fitted")
    fitted = JointLimits(robot.limits.lower, robot.limits.upper, v_max, a_max, j_max)
    moves = _moves(recording, velocity, v_max)
    recorded = float(sum(recording.t[b] - recording.t[a] for a, b in moves))
    retimed = 0.0
    for a, b in moves:
        try:
            retimed += ptp.ptp_duration(recording.q[a], recording.q[b], _with(robot, fitted))
        except TimingError as exc:
            raise UsageError(f"the recording's move {a}..{b} cannot be re-timed: {exc}") from exc
    return Calibration(v_max, a_max, j_max, len(moves), recorded, retimed)


def _with(robot: Robot, limits: JointLimits) -> Robot:
    import dataclasses

    return dataclasses.replace(robot, limits=limits)


def _derivatives(recording: Recording) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Velocity, acceleration and jerk (N, dof) by a cubic Savitzky-Golay filter; the samples
    must be evenly spaced to within 1% (the filter's assumption)."""
    from scipy.signal import savgol_filter

    dt = np.diff(recording.t)
    step = float(np.median(dt))
    if np.max(np.abs(dt / step - 1.0)) > 1e-2:
        raise UsageError("the recording's samples must be evenly spaced in time (within 1%)")
    window = min(WINDOW, recording.t.size - (1 - recording.t.size % 2))
    velocity, accel, jerk = (
        np.asarray(
            savgol_filter(recording.q, window, 3, deriv=k, delta=step, axis=0, mode="interp")
        )
        for k in (1, 2, 3)
    )
    return velocity, accel, jerk


def _moves(recording: Recording, velocity: FloatArray, v_max: FloatArray) -> list[tuple[int, int]]:
    """(first, last) sample of each move: the recording is cut where its speed (the largest
    axis speed over that axis' limit) dips below :data:`STOP_DIP`: within such a dip a move
    ends at the first sample at rest (:data:`REST_FRACTION`) and the next starts at the last
    one, or both at the slowest sample if none is at rest (the stop of two moves in a row
    falls between samples)."""
    speed = np.max(np.abs(velocity) / v_max, axis=1)
    below = np.concatenate([[False], speed < STOP_DIP, [False]])
    edges = np.flatnonzero(np.diff(below.astype(np.int8)))
    cuts = []
    for lo, hi in zip(edges[::2], edges[1::2], strict=True):  # a dip: samples lo .. hi - 1
        rest = lo + np.flatnonzero(speed[lo:hi] < REST_FRACTION)
        slowest = lo + int(np.argmin(speed[lo:hi]))
        cuts.append((int(rest[0]), int(rest[-1])) if rest.size else (slowest, slowest))
    return [
        (cuts[k][1], cuts[k + 1][0]) for k in range(len(cuts) - 1) if cuts[k + 1][0] > cuts[k][1]
    ]


STOP_DIP = 1e-2
"""A dip of the speed below this fraction of the limits is a stop between moves."""


def override_yaml(calibration: Calibration, source: str) -> str:
    """The station override (a ``robot: limits:`` block) in the station's units, with the
    fit's provenance and residual as comments; fixed decimals, no locale."""

    def row(values: FloatArray) -> str:
        return "[" + ", ".join(f"{math.degrees(float(v)):.3f}" for v in values) + "]"

    return (
        f"# olp time --calibrate {source}: limits fitted to {calibration.moves} recorded "
        "move(s);\n"
        f"# re-timed with them: {calibration.retimed:.4f} s against {calibration.recorded:.4f} s "
        f"recorded ({calibration.residual * 100:+.2f} %).\n"
        "# Put the robot's limits into the station (robot: model: ... limits: ...).\n"
        "robot:\n"
        "  limits:\n"
        f"    velocity_deg_s: {row(calibration.velocity)}\n"
        f"    acceleration_deg_s2: {row(calibration.acceleration)}\n"
        f"    jerk_deg_s3: {row(calibration.jerk)}\n"
    )
