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

The controller's path acceleration: a move whose TCP (forward kinematics of the recorded
joints with the tool given, the flange by default) stays on the straight line between its ends
(within :data:`STRAIGHT_TOLERANCE` plus :data:`STRAIGHT_FRACTION` of its length, and longer
than :data:`MIN_TRAVEL`) is a path move (LIN); the distance travelled along that line is
differentiated the same way, and the path acceleration is the largest magnitude seen on any
path move. Like the joint limits this assumes some path move reached it (a long move whose
programmed speed the robot cruises at); the programmed speed of each path move is taken as the
largest speed it reached. A recording without path moves fits no path acceleration. The path
acceleration is a station property for controllers that have a default one (KUKA's
``$ACC.CP`` after the BAS initialisation); a UR script states ``a=`` on every ``movel``, so for
a UR arm the fitted value is reported, not written.

The residual: the recording is cut into moves at its rests (all axes below
:data:`REST_FRACTION` of their fitted velocity), the moves re-timed as one program of fine
stopped moves (a joint move to each end, or a linear move at its recorded speed) through
olp's timing with the fitted limits, and the summed time compared with the recorded one.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from olp.errors import UsageError
from olp.station.model import JointLimits, Station

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


STRAIGHT_TOLERANCE = 2e-4
"""A path move's TCP stays within this distance (m), plus :data:`STRAIGHT_FRACTION` of its
length, of the line between its ends (servo lag of a real arm is of the order of 0.1 mm)."""
STRAIGHT_FRACTION = 1e-3
MIN_TRAVEL = 5e-3
"""A move whose TCP travels less (m) is not taken for a path move (the line is too short to
tell a LIN from a PTP)."""


@dataclass(frozen=True, slots=True)
class Calibration:
    """Fitted limits (dof,) each: ``velocity`` rad/s, ``acceleration`` rad/s², ``jerk`` rad/s³;
    ``path_acceleration`` m/s² (None: the recording has no path move); the recording's
    ``moves`` (``path_moves`` of them linear) and their ``recorded`` and ``retimed`` durations
    (s, summed)."""

    velocity: FloatArray
    acceleration: FloatArray
    jerk: FloatArray
    moves: int
    recorded: float
    retimed: float
    path_acceleration: float | None = None
    path_moves: int = 0
    vendor: str = ""

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


def fit_limits(
    recording: Recording, station: Station, tool: FloatArray | None = None
) -> Calibration:
    """The limits of the module docstring and the residual of re-timing the recording.

    ``station``: the station the recording was made on; ``tool`` (4, 4): the TCP in the
    flange frame for finding path moves (default: the flange).
    """
    robot = station.robot
    _, (velocity, acceleration, jerk) = _derivatives(recording.t, recording.q)
    limits = (np.max(np.abs(d), axis=0) for d in (velocity, acceleration, jerk))
    v_max, a_max, j_max = limits
    if np.any(v_max <= 0) or np.any(a_max <= 0) or np.any(j_max <= 0):
        raise UsageError("the recording leaves an axis still: its limits cannot be fitted")
    moves = _moves(recording, velocity, v_max)
    tool_pose = np.eye(4) if tool is None else np.asarray(tool, dtype=np.float64)
    tcp = (robot.flange_poses(recording.q) @ tool_pose)[:, :3, 3]
    found = {m: _path_line(recording.t, tcp, m) for m in moves}
    lines = {m: line for m, line in found.items() if line is not None}
    path_acc = max((line[1] for line in lines.values()), default=None)
    fitted = JointLimits(
        robot.limits.lower,
        robot.limits.upper,
        v_max,
        a_max,
        j_max,
        path_acceleration=None if robot.vendor == "ur" else path_acc,
    )
    if robot.vendor == "ur" and path_acc is not None:
        # UR: the moves are re-timed with the fitted value as each movel's a=.
        lines = {m: (v, path_acc) for m, (v, _) in lines.items()}
    calibrated = dataclasses.replace(station, robot=dataclasses.replace(robot, limits=fitted))
    recorded = float(sum(recording.t[b] - recording.t[a] for a, b in moves))
    retimed = _retimed(recording, calibrated, moves, lines, tool_pose, robot.vendor == "ur")
    return Calibration(
        v_max,
        a_max,
        j_max,
        len(moves),
        recorded,
        retimed,
        path_acceleration=path_acc,
        path_moves=len(lines),
        vendor=robot.vendor,
    )


def _path_line(t: FloatArray, tcp: FloatArray, move: tuple[int, int]) -> tuple[float, float] | None:
    """(largest speed m/s, largest acceleration m/s²) along the line of a path move, None if
    the move's TCP leaves the line between its ends (a joint move)."""
    a, b = move
    points = tcp[a : b + 1]
    chord = points[-1] - points[0]
    length = float(np.linalg.norm(chord))
    if length < MIN_TRAVEL or points.shape[0] < WINDOW:
        return None
    direction = chord / length
    offsets = points - points[0]
    along = offsets @ direction
    across = np.linalg.norm(offsets - along[:, None] * direction, axis=1)
    if float(np.max(across)) > STRAIGHT_TOLERANCE + STRAIGHT_FRACTION * length:
        return None
    _, (speed, accel) = _derivatives(t[a : b + 1], along[:, None], orders=(1, 2))
    return float(np.max(np.abs(speed))), float(np.max(np.abs(accel)))


def _retimed(
    recording: Recording,
    station: Station,
    moves: Sequence[tuple[int, int]],
    lines: dict[tuple[int, int], tuple[float, float]],
    tool: FloatArray,
    ur: bool,
) -> float:
    """The summed duration of the recording's moves re-timed by olp on the fitted station, as
    one program of fine-stopped moves (see the module docstring)."""
    from olp import ir
    from olp.api import compile

    flange = ir.Tool(name="calibrated_tcp", pose=tool)
    instructions: list[ir.Instruction] = [
        ir.JointMove(target=ir.JointTarget(joints=recording.q[moves[0][0]]), tool=flange)
    ]
    for a, b in moves:
        line = lines.get((a, b))
        if line is None:
            target: ir.Instruction = ir.JointMove(
                target=ir.JointTarget(joints=recording.q[b]), tool=flange
            )
        else:
            pose = station.robot.flange_poses(recording.q[b]) @ tool
            speed = ir.Speed(linear=line[0], linear_acceleration=line[1] if ur else None)
            target = ir.LinearMove(target=ir.CartesianTarget(pose=pose), speed=speed, tool=flange)
        instructions.append(target)
    program = ir.Program(name="calibration", instructions=tuple(instructions))
    compiled = compile(program, station, collisions=None)
    errors = [d for d in compiled.diagnostics if d.severity == "error"]
    if errors:
        move = moves[max(0, min(len(moves) - 1, (errors[0].index or 1) - 1))]
        raise UsageError(
            f"the recording's move {move[0]}..{move[1]} cannot be re-timed: {errors[0].message}"
        )
    return float(sum(step.duration for step in compiled.steps[1:]))


def _derivatives(
    t: FloatArray, values: FloatArray, orders: Sequence[int] = (1, 2, 3)
) -> tuple[float, list[FloatArray]]:
    """The sampling step (s) and the derivatives of ``values`` (N, k) of the given orders, by a
    cubic Savitzky-Golay filter; the samples must be evenly spaced to within 1% (the filter's
    assumption)."""
    from scipy.signal import savgol_filter

    dt = np.diff(t)
    step = float(np.median(dt))
    if np.max(np.abs(dt / step - 1.0)) > 1e-2:
        raise UsageError("the recording's samples must be evenly spaced in time (within 1%)")
    window = min(WINDOW, t.size - (1 - t.size % 2))
    return step, [
        np.asarray(savgol_filter(values, window, 3, deriv=k, delta=step, axis=0, mode="interp"))
        for k in orders
    ]


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

    path = calibration.path_acceleration
    lines = [
        f"# olp time --calibrate {source}: limits fitted to {calibration.moves} recorded "
        f"move(s), {calibration.path_moves} of them path moves;",
        f"# re-timed with them: {calibration.retimed:.4f} s against {calibration.recorded:.4f} s "
        f"recorded ({calibration.residual * 100:+.2f} %).",
    ]
    if path is None:
        lines.append("# No path move in the recording: no path acceleration fitted.")
    elif calibration.vendor == "ur":
        lines.append(
            f"# Path moves reached {path:.4f} m/s^2: on a UR arm that is the movel a= of the "
            "script (set it in the program), not a station limit."
        )
    lines += [
        "# Put the robot's limits into the station (robot: model: ... limits: ...).",
        "robot:",
        "  limits:",
        f"    velocity_deg_s: {row(calibration.velocity)}",
        f"    acceleration_deg_s2: {row(calibration.acceleration)}",
        f"    jerk_deg_s3: {row(calibration.jerk)}",
    ]
    if path is not None and calibration.vendor != "ur":
        lines.append(f"    path_acceleration_m_s2: {path:.4f}")
    return "\n".join(lines) + "\n"
