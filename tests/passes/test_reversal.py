"""Zones at corners the robot cannot pass at speed: a path that turns back on itself, a corner
close to that, a tight blend. Each is timed as what stopping there takes, never as a whole
chain slowed for one corner (before: a 20 mm zone at a reversal timed 7.5 + 2.9 + 4.9 s where
the fine stops take 0.5 + 0.3 + 0.3 s)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.compiled import CompiledProgram
from olp.passes.pipeline import BuildOptions
from olp.passes.timing import TimingOptions, corners
from olp.station.model import Station

REPO = Path(__file__).resolve().parents[2]

TOOL_FORWARD = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
"""The tool along the base's x axis (KUKA A 0, B 90, C 0)."""

CORNER = np.array([0.5, -0.3, 0.35])
"""m: where the second move ends and the third turns; the second runs up +z to it."""

VELOCITY_TOL, ACCELERATION_TOL = 1e-3, 5e-3
"""As tests/passes/test_timing.py holds every timed law."""


def pose(position: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = TOOL_FORWARD
    out[:3, 3] = position
    return out


def program(turn_deg: float, zone_m: float, zones: tuple[float, float] | None = None) -> ir.Program:
    """PTP to the start, LIN 100 mm along +y, LIN 50 mm up +z to :data:`CORNER`, LIN 50 mm on
    turning ``turn_deg`` from +z towards +y (180: straight back down); ``zones`` overrides
    the two blended moves' zones (m), else both ``zone_m``."""
    a = np.radians(turn_deg)
    last = CORNER + 0.05 * np.array([0.0, np.sin(a), np.cos(a)])
    first, second = zones if zones is not None else (zone_m, zone_m)

    def lin(position: np.ndarray, zone: float, line: int) -> ir.LinearMove:
        span = ir.SourceSpan("t.src", line, 1)
        target = ir.CartesianTarget(pose=pose(position))
        return ir.LinearMove(target=target, zone=ir.Zone(zone), span=span)

    start = ir.JointMove(
        target=ir.CartesianTarget(pose=pose(np.array([0.5, -0.4, 0.3]))),
        span=ir.SourceSpan("t.src", 1, 1),
    )
    moves = (
        lin(np.array([0.5, -0.3, 0.3]), first, 2),
        lin(CORNER, second, 3),
        lin(last, 0.0, 4),
    )
    return ir.Program(name="t", instructions=(start, *moves), source="t.src")


@pytest.fixture(scope="module")
def station() -> Station:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def compiled(station: Station, prog: ir.Program, **timing: bool) -> CompiledProgram:
    options = BuildOptions(collisions=None, timing=TimingOptions(**timing))
    out = olp.compile(prog, station, options)
    assert out.ok, [d.format() for d in out.diagnostics]
    return out


def durations(result: CompiledProgram) -> np.ndarray:
    return np.array([step.duration for step in result.steps[1:]])


def raw_blends(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every corner blended as programmed and timed as one chain (the rules of
    :mod:`olp.passes.timing.corners` off)."""
    monkeypatch.setattr(corners, "FOLD_TURN", np.pi)
    monkeypatch.setattr(corners, "SHARP_RATIO", np.inf)


@pytest.mark.parametrize("zone_mm", [5.0, 20.0, 40.0])
def test_a_zone_at_a_reversal_takes_what_a_stop_there_takes(
    station: Station, zone_mm: float
) -> None:
    zone = zone_mm / 1000
    blended = compiled(station, program(180.0, zone))
    stopped = compiled(station, program(180.0, zone, zones=(zone, 0.0)))
    fine = compiled(station, program(180.0, 0.0))
    assert durations(blended) == pytest.approx(durations(stopped), rel=1e-6)
    # The move back runs from a stop: its time is the fine move's.
    assert durations(blended)[-1] == pytest.approx(durations(fine)[-1], rel=1e-2)
    assert blended.cycle_time <= fine.cycle_time * (1 + 1e-6)
    # Never below the acceleration-limited optimum (jerk limits only add time).
    lower = compiled(station, program(180.0, zone), path_jerk=False)
    assert blended.cycle_time >= lower.cycle_time
    notes = {d.index: d.message for d in blended.diagnostics if d.kind == "zone_stop"}
    assert "turns back" in notes[2]


def test_near_reversals_slow_down_to_the_stop_without_a_jump(station: Station) -> None:
    angles = np.array([145.0, 150.0, 155.0, 160.0, 165.0, 170.0, 175.0, 178.0, 179.0, 179.9])
    times = np.array([compiled(station, program(a, 0.02)).cycle_time for a in angles])
    stop = compiled(station, program(180.0, 0.02, zones=(0.02, 0.0))).cycle_time
    steps = np.diff(np.append(times, stop)) / stop
    assert np.all(steps > -2e-3), steps  # sharper never faster (beyond the grid's noise)
    assert np.all(steps < 1e-2), steps  # and no jump between neighbours
    assert np.all(times <= stop * (1 + 2e-3))


def test_a_90_degree_corner_is_blended_as_before(
    station: Station, monkeypatch: pytest.MonkeyPatch
) -> None:
    ruled = compiled(station, program(90.0, 0.02))
    raw_blends(monkeypatch)
    raw = compiled(station, program(90.0, 0.02))
    assert durations(ruled).tolist() == durations(raw).tolist()
    assert not [d for d in ruled.diagnostics if d.kind == "zone_stop"]


@pytest.mark.parametrize("zone_mm", [0.1, 1.0])
def test_a_tight_blend_is_never_slower_than_stopping_there(
    station: Station, zone_mm: float
) -> None:
    """A 90° corner with a tiny zone: the robot all but stops in it."""
    tight = compiled(station, program(90.0, zone_mm / 1000)).cycle_time
    fine = compiled(station, program(90.0, 0.0)).cycle_time
    assert tight <= fine * (1 + 1e-6)
    assert tight >= compiled(station, program(90.0, zone_mm / 1000), path_jerk=False).cycle_time


def test_the_timed_reversal_holds_the_limits_and_does_not_overshoot(station: Station) -> None:
    result = compiled(station, program(180.0, 0.02))
    limits = station.robot.limits
    for step in result.steps[1:]:
        segment = step.trajectory
        assert segment is not None
        t = np.linspace(0.0, segment.duration, 20001)
        _, qd, qdd = segment.state(t)
        assert np.max(np.abs(qd) / limits.velocity) <= 1 + VELOCITY_TOL
        assert np.max(np.abs(qdd) / limits.acceleration) <= 1 + ACCELERATION_TOL
    sampled = olp.trajectory.sample_program(result, dt=0.001)
    tcp, index = sampled.tcp, sampled.index
    # Never past the corner; back down the line it came up; off that line only inside the zone
    # of the first corner (the blend into the move up).
    assert np.max(tcp[index >= 1, 2]) <= CORNER[2] + 1e-6
    assert np.max(np.abs(tcp[index == 3, :2] - CORNER[:2])) <= 1e-5
    up = tcp[index == 2]
    off = np.linalg.norm(up[:, :2] - CORNER[:2], axis=-1)
    assert np.all((off <= 1e-5) | (up[:, 2] <= 0.3 + 0.02 + 1e-6))
    assert np.max(off) <= 0.02
