"""The timed trajectory: time laws against Ruckig's and TOPPRA's own evaluators, the closed-form
line law against its own derivatives, sampling at a fixed step, the CSV against forward
kinematics, the plot as a PNG."""

from __future__ import annotations

import struct
import sys
from pathlib import Path

import numpy as np
import pytest
import toppra
from ruckig import InputParameter, Ruckig, Synchronization, Trajectory

from olp import ir
from olp.compiled import CompiledProgram
from olp.errors import UsageError
from olp.passes.resolve import resolve
from olp.passes.timing import time_program
from olp.station.loader import load_station
from olp.station.model import Station
from olp.trajectory import (
    LineTimeLaw,
    PathTimeLaw,
    csv_text,
    instruction_starts,
    plot_trajectory,
    sample_program,
    write_csv,
)

REPO = Path(__file__).resolve().parents[1]
Q0 = np.radians([10, -80, 95, 0, 30, 0])


@pytest.fixture(scope="module")
def station() -> Station:
    return load_station(REPO / "stations" / "kr6_milling_cell.yaml")


@pytest.fixture(scope="module")
def compiled(station: Station) -> CompiledProgram:
    """PTP, a wait, two blended LINs, an output, a LIN, a final PTP: every kind of step."""
    tool = station.tools["spindle"]
    start = station.robot.flange_poses(Q0) @ tool.pose

    def lin(offset: list[float], zone: float = 0.0) -> ir.LinearMove:
        pose = start.copy()
        pose[:3, 3] += offset
        return ir.LinearMove(
            target=ir.CartesianTarget(pose=pose),
            speed=ir.Speed(linear=0.4),
            zone=ir.Zone(zone),
            tool=tool,
        )

    instructions = [
        ir.JointMove(target=ir.JointTarget(joints=Q0), tool=tool),
        ir.Wait(seconds=0.25),
        lin([0.0, 0.1, 0.0], 0.02),
        lin([0.1, 0.1, 0.0]),
        ir.SetOutput(index=1, value=True),
        lin([0.1, 0.0, -0.05]),
        ir.JointMove(target=ir.JointTarget(joints=station.robot.home), tool=tool),
    ]
    result = time_program(resolve(ir.Program(name="t", instructions=instructions), station))
    assert result.ok
    return result


def test_jerk_profile_matches_ruckig_evaluation(compiled: CompiledProgram) -> None:
    step = compiled.steps[0]
    assert step.trajectory is not None and step.path is not None
    robot = compiled.station.robot
    inp = InputParameter(6)
    inp.current_position, inp.target_position = step.path[0].tolist(), step.path[-1].tolist()
    inp.max_velocity = robot.limits.velocity.tolist()
    inp.max_acceleration = robot.limits.acceleration.tolist()
    inp.max_jerk = robot.limits.jerk.tolist()
    inp.synchronization = Synchronization.Phase
    reference = Trajectory(6)
    Ruckig(6).calculate(inp, reference)
    times = np.linspace(0.0, reference.duration, 37)
    q, qd, qdd = step.trajectory.state(times)
    for k, t in enumerate(times):
        p, v, a = reference.at_time(float(t))
        assert np.allclose(q[k], p, atol=1e-10) and np.allclose(qd[k], v, atol=1e-9)
        assert np.allclose(qdd[k], a, atol=1e-8)


def test_path_time_law_matches_toppra_evaluation() -> None:
    s = np.linspace(0.0, 2.0, 9)
    path = toppra.SplineInterpolator(s, np.stack([np.sin(s), s**2, np.cos(3 * s)], axis=1))
    grid = np.linspace(0.0, 2.0, 41)
    sd = np.sqrt(np.minimum(grid, 2.0 - grid) * 3.0) + 0.0
    law = PathTimeLaw.from_speeds(path, grid, sd)
    reference = toppra.parametrizer.ParametrizeConstAccel(path, grid, sd)
    assert law.duration == pytest.approx(reference.duration, rel=1e-12)
    times = np.linspace(0.0, law.duration, 101)
    q, qd, qdd = law.state(times)
    assert np.allclose(q, reference(times), atol=1e-9)
    assert np.allclose(qd, reference(times, 1), atol=1e-7)
    inner = (times > 1e-3) & (times < law.duration - 1e-3)  # toppra's acceleration at the ends
    assert np.allclose(qdd[inner], reference(times[inner], 2), atol=1e-6)


@pytest.mark.parametrize(("ramp", "total"), [(0.02, 0.1), (0.05, 0.1)])
def test_line_time_law_is_its_own_derivative(ramp: float, total: float) -> None:
    """A trapezoid (and a triangle, ``ramp = total / 2``) along a joint line: it starts and ends
    at rest on the line's ends, stays on the line, and its velocity and acceleration are the
    derivatives of its position."""
    q0, q1 = np.array([0.1, -0.2, 0.3]), np.array([0.15, -0.25, 0.5])
    accel = 1.0 / (ramp * (total - ramp))  # covers the line exactly
    law = LineTimeLaw(q0=q0, q1=q1, accel=accel, ramp=ramp, total=total)
    dt = 1e-6
    t = np.linspace(0.0, total, 2001)
    q, qd, qdd = law.state(t)
    assert np.allclose(q[[0, -1]], [q0, q1], atol=1e-12) and np.allclose(qd[[0, -1]], 0.0)
    fraction = (q - q0) / (q1 - q0)
    assert np.allclose(fraction, fraction[:, :1], atol=1e-12)
    assert np.all(np.diff(fraction[:, 0]) >= 0)
    plus, minus = law.state(t + dt), law.state(t - dt)
    inner = (t > dt) & (t < total - dt)
    kinks = (np.abs(t - ramp) < 2 * dt) | (np.abs(t - (total - ramp)) < 2 * dt)
    smooth = inner & ~kinks  # central differences across a jump of acceleration are off
    assert np.allclose(((plus[0] - minus[0]) / (2 * dt))[smooth], qd[smooth], atol=1e-8)
    assert np.allclose(((plus[1] - minus[1]) / (2 * dt))[smooth], qdd[smooth], atol=1e-4)
    assert np.max(np.abs(qd[:, 2])) == pytest.approx(accel * ramp * (q1 - q0)[2], rel=1e-9)
    assert law.state(np.array([-1.0, total + 1.0]))[1].tolist() == [[0.0] * 3, [0.0] * 3]


def test_sampling_runs_through_closed_form_lines(station: Station) -> None:
    """Fine-stopped tiny LINs (timed in closed form) sample continuously, velocity the
    derivative of position, and end at each move's target."""
    tool = station.tools["spindle"]
    start = station.robot.flange_poses(Q0) @ tool.pose
    moves: list[ir.Instruction] = [ir.JointMove(target=ir.JointTarget(joints=Q0), tool=tool)]
    for k in range(1, 6):
        pose = start.copy()
        pose[:3, 3] += [2e-4 * k, 1e-4 * (k % 2), 0.0]
        moves.append(
            ir.LinearMove(
                target=ir.CartesianTarget(pose=pose), speed=ir.Speed(linear=0.02), tool=tool
            )
        )
    timed = time_program(resolve(ir.Program(name="t", instructions=moves), station))
    assert timed.ok
    assert all(isinstance(s.trajectory.law, LineTimeLaw) for s in timed.steps[1:])  # type: ignore[union-attr]
    dt = 1e-5
    sampled = sample_program(timed, dt=dt)
    limits = station.robot.limits
    central = (sampled.q[2:] - sampled.q[:-2]) / (2 * dt)
    assert np.all(np.abs(central - sampled.qd[1:-1]) <= limits.acceleration * dt * 1.01)
    assert np.all(np.abs(np.diff(sampled.q, axis=0)) <= limits.velocity * dt * 1.001)
    ends = np.cumsum([s.duration for s in timed.steps])
    for step, end in zip(timed.steps, ends, strict=True):
        at = min(round(float(end) / dt), sampled.t.size - 1)
        assert np.allclose(sampled.q[at], step.joints, atol=limits.velocity.max() * dt)


def test_samples_have_a_fixed_step_and_cover_the_program(compiled: CompiledProgram) -> None:
    sampled = sample_program(compiled, dt=0.004)
    assert sampled.q.shape == (sampled.t.size, 6) and sampled.tcp.shape == (sampled.t.size, 3)
    assert np.allclose(np.diff(sampled.t), 0.004, rtol=0, atol=1e-12)
    assert (
        sampled.t[0] == 0.0 and compiled.cycle_time <= sampled.t[-1] < compiled.cycle_time + 0.004
    )
    assert np.all(np.diff(sampled.index) >= 0)
    starts = np.cumsum([0.0] + [s.duration for s in compiled.steps])
    for k, index in enumerate(sampled.index):
        if sampled.t[k] < starts[-1]:
            assert starts[index] <= sampled.t[k] < starts[index + 1]
    assert np.allclose(sampled.q[-1], compiled.station.robot.home, atol=1e-9)


def test_joints_are_continuous_and_velocities_their_derivative(compiled: CompiledProgram) -> None:
    sampled = sample_program(compiled, dt=1e-4)
    dt = 1e-4
    central = (sampled.q[2:] - sampled.q[:-2]) / (2 * dt)
    limits = compiled.station.robot.limits
    # Velocity is the derivative of position (acceleration bounds the difference: a * dt).
    assert np.all(np.abs(central - sampled.qd[1:-1]) <= limits.acceleration * dt * 1.01)
    assert np.all(np.abs(np.diff(sampled.q, axis=0)) <= limits.velocity * dt * 1.001)


def test_the_wait_holds_the_joints(compiled: CompiledProgram) -> None:
    sampled = sample_program(compiled, dt=0.01)
    waiting = sampled.index == 1
    assert np.count_nonzero(waiting) == 25
    assert np.allclose(sampled.q[waiting], compiled.steps[0].joints, atol=1e-12)
    assert np.all(sampled.qd[waiting] == 0.0)


def test_csv_is_consistent_with_forward_kinematics(
    compiled: CompiledProgram, tmp_path: Path
) -> None:
    path = write_csv(sample_program(compiled, dt=0.02), tmp_path / "traj.csv")
    lines = path.read_text(encoding="ascii").splitlines()
    header = lines[0].split(",")
    assert header[:2] == ["time_s", "j1_deg"] and header[-4:] == [
        "tcp_x_mm",
        "tcp_y_mm",
        "tcp_z_mm",
        "instruction",
    ]
    table = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    assert table.shape[1] == len(header) == 17
    assert np.all(np.diff(table[:, 0]) > 0)
    # Every motion of the fixture carries the spindle, so it is the active tool throughout.
    spindle = compiled.station.tools["spindle"].pose
    tcp = (compiled.station.robot.flange_poses(np.radians(table[:, 1:7])) @ spindle)[:, :3, 3]
    assert np.allclose(tcp * 1000, table[:, 13:16], atol=1e-3)
    assert np.ptp(table[:, 13]) > 50  # the TCP moved


def test_csv_is_deterministic_and_locale_free(compiled: CompiledProgram) -> None:
    first = csv_text(sample_program(compiled, dt=0.05))
    assert first == csv_text(sample_program(compiled, dt=0.05))
    assert all(line.count(",") == 16 for line in first.splitlines())
    assert "-0.000000," not in first and "e" not in first.split("\n", 1)[1]


def test_plot_is_a_deterministic_png(compiled: CompiledProgram, tmp_path: Path) -> None:
    sampled = sample_program(compiled, dt=0.01)
    starts = instruction_starts(compiled)
    a = plot_trajectory(sampled, tmp_path / "a.png", starts).read_bytes()
    b = plot_trajectory(sampled, tmp_path / "b.png", starts).read_bytes()
    assert a[:8] == b"\x89PNG\r\n\x1a\n" and a[12:16] == b"IHDR"
    width, height = struct.unpack(">II", a[16:24])
    assert (width, height) == (1000, 650)
    assert a == b


def test_missing_matplotlib_is_a_clear_error(
    compiled: CompiledProgram, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    for name in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    with pytest.raises(UsageError, match="matplotlib") as info:
        plot_trajectory(sample_program(compiled, dt=0.1), tmp_path / "x.png")
    assert "olp[plot]" in (info.value.hint or "")
    assert not (tmp_path / "x.png").exists()


def test_bad_sampling_requests_are_usage_errors(
    compiled: CompiledProgram, station: Station
) -> None:
    with pytest.raises(UsageError, match="step"):
        sample_program(compiled, dt=0.0)
    far = ir.JointMove(target=ir.JointTarget(joints=np.radians([0, 0, 500, 0, 0, 0])))
    failed = resolve(ir.Program(name="t", instructions=[far]), station)
    with pytest.raises(UsageError, match="errors"):
        sample_program(failed)


def test_report_start_times_match_the_sampled_trajectory(compiled: CompiledProgram) -> None:
    from olp.api import BuildResult
    from olp.report import report_dict

    report = report_dict(BuildResult(compiled, "-", compiled.diagnostics))
    sampled = sample_program(compiled, dt=0.001)
    for item in report["instructions"]:
        if item["time_s"] > 0.002:
            first = sampled.t[np.argmax(sampled.index == item["index"])]
            assert item["start_s"] <= first < item["start_s"] + 0.001 + 1e-6
    lengths = [i.get("path_length_m", 0.0) for i in report["instructions"]]
    assert report["path_length_m"] == pytest.approx(sum(lengths), abs=1e-8)
    tcp_travel = np.sum(np.linalg.norm(np.diff(sampled.tcp, axis=0), axis=-1))
    assert report["path_length_m"] == pytest.approx(tcp_travel, rel=2e-3)


def test_a_program_too_long_to_sample_is_a_usage_error(compiled: CompiledProgram) -> None:
    """A cycle time of inf (two waits of 1e308 s) raised OverflowError; a huge one printed a
    66-digit sample count."""
    import dataclasses

    for duration, shown in ((np.inf, "inf samples"), (1e300, r"1e\+302 samples")):
        steps = list(compiled.steps)
        steps[1] = dataclasses.replace(steps[1], duration=duration)
        huge = dataclasses.replace(compiled, steps=tuple(steps))
        with pytest.raises(UsageError, match=shown):
            sample_program(huge, dt=0.01)
