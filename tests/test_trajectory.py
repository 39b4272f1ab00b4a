"""The timed trajectory: time laws against Ruckig's and TOPPRA's own evaluators, sampling at a
fixed step, the CSV against forward kinematics, the plot as a PNG."""

from __future__ import annotations

import struct
import sys
from pathlib import Path

import numpy as np
import pytest
import toppra
from ruckig import InputParameter, Ruckig, Synchronization, Trajectory

from olp import ir
from olp.errors import UsageError
from olp.passes.resolve import CompiledProgram, resolve
from olp.passes.timing import time_program
from olp.station.loader import load_station
from olp.station.model import Station
from olp.trajectory import (
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
