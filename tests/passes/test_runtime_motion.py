"""Passes on motions to run-time targets (:class:`olp.ir.RuntimeMove`): a clear warning for what
cannot be checked, the next motion's target still checked but not its path, and a cycle time
that says it is a lower bound."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import olp
from olp import ir
from olp.geometry import transl
from olp.passes.flow import motion_predecessors
from olp.passes.resolve import ResolveOptions
from olp.report import report_dict, summary

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
HOME = ir.JointMove(target=ir.JointTarget(joints=np.radians([0, -90, 90, 0, 30, 0])))
LEFT, RIGHT, FAR = (90, -60, 100, 0, 50, 0), (-90, -60, 100, 0, 50, 0), (0, 0, 0, 0, 0, 0)
"""Joints (deg) of targets: LEFT and RIGHT on either side of axis 1 (the line between them
crosses it), FAR moved beyond the reach below."""


@pytest.fixture(scope="module")
def station() -> olp.Station:
    return olp.load_station(CELL)


def pose(station: olp.Station, joints: tuple[float, ...], lift: float = 0.0) -> ir.CartesianTarget:
    flange = station.robot.flange_poses(np.radians(joints)[None])[0]
    return ir.CartesianTarget(pose=transl(0, 0, lift) @ flange)


def ptp(station: olp.Station, joints: tuple[float, ...], line: int) -> ir.JointMove:
    return ir.JointMove(target=pose(station, joints), span=ir.SourceSpan("p.src", line, 1))


def lin(station: olp.Station, joints: tuple[float, ...], line: int, lift: float = 0.0) -> Any:
    target = pose(station, joints, lift)
    return ir.LinearMove(target=target, span=ir.SourceSpan("p.src", line, 1))


def runtime(line: int) -> ir.RuntimeMove:
    return ir.RuntimeMove(
        motion="linear",
        target=ir.Name(name="pCam"),
        reason="pCam is set by the camera",
        span=ir.SourceSpan("p.src", line, 1),
    )


def build(station: olp.Station, *nodes: ir.Node) -> olp.api.BuildResult:
    program = ir.Program(name="p", instructions=(HOME, *nodes), source="p.src")
    return olp.build(station, program, post="kuka", collisions=None)


def kinds(result: olp.api.BuildResult) -> list[tuple[str, str, int | None]]:
    return [
        (d.severity, d.kind, d.span.line if d.span else None)
        for d in result.diagnostics
        if d.kind in ("runtime_target", "unknown_start") or d.severity == "error"
    ]


def test_the_run_time_motion_and_the_start_of_the_next_are_warned(station: olp.Station) -> None:
    result = build(station, ptp(station, LEFT, 2), runtime(3), lin(station, RIGHT, 4))
    assert result.ok
    assert kinds(result) == [("warning", "runtime_target", 3), ("warning", "unknown_start", 4)]
    steps = result.compiled.steps
    assert steps[2].joints is None and steps[3].joints is not None and steps[3].path is None
    (warning,) = [d for d in result.diagnostics if d.kind == "runtime_target"]
    assert "pCam is set by the camera" in warning.message


def test_the_next_linear_move_is_not_checked_as_a_line(station: olp.Station) -> None:
    """From (0.45, 0.25) to (-0.45, -0.25) the straight line passes over axis 1 (a
    configuration flip: an error when the start is known). After a run-time motion the
    start is unknown: only the target is checked, and it is reachable."""
    straight = build(station, ptp(station, LEFT, 2), lin(station, RIGHT, 3))
    assert not straight.ok
    after = build(station, ptp(station, LEFT, 2), runtime(3), lin(station, RIGHT, 4))
    assert after.ok and ("warning", "unknown_start", 4) in kinds(after)


def test_an_unreachable_target_after_a_run_time_motion_is_still_an_error(
    station: olp.Station,
) -> None:
    result = build(station, ptp(station, LEFT, 2), runtime(3), lin(station, FAR, 4, lift=5.0))
    assert not result.ok
    assert ("error", "unreachable", 4) in kinds(result)


def test_the_cycle_time_is_a_lower_bound_and_says_so(station: olp.Station) -> None:
    result = build(station, ptp(station, LEFT, 2), runtime(3), lin(station, RIGHT, 4))
    steps = result.compiled.steps
    assert steps[2].duration == 0.0 and steps[3].duration == 0.0 and steps[1].duration > 0
    assert "lower bound: 2 motions to or from run-time targets not timed" in summary(result)
    assert report_dict(result)["untimed_motions"] == 2
    plain = build(station, ptp(station, LEFT, 2), lin(station, RIGHT, 4))
    assert "lower bound" not in summary(plain) and report_dict(plain)["untimed_motions"] == 0


def test_a_run_time_motion_is_a_position_of_the_flow_analysis(station: olp.Station) -> None:
    """After ``IF ... ENDIF`` holding a run-time motion, the next motion's starts are the
    run-time motion (unknown: not re-checked) and the motion before the IF (checked)."""
    branch = ir.If(branches=(ir.Branch(condition=ir.DigitalInput(index=1), body=(runtime(3),)),))
    nodes = (HOME, ptp(station, LEFT, 2), branch, lin(station, RIGHT, 5))
    program = ir.Program(name="p", instructions=nodes)
    assert motion_predecessors(program)[3] == frozenset({1, 2})


def test_a_run_time_motion_in_a_loop_times_its_paths(station: olp.Station) -> None:
    """The loop's head is entered from the run-time motion at its end: what follows is timed
    as from an unknown start (no time), never from the robot's home."""
    loop = ir.While(condition=ir.DigitalInput(index=1), body=(ptp(station, LEFT, 3), runtime(4)))
    result = build(station, loop, lin(station, RIGHT, 6))
    assert result.ok and result.compiled.paths is not None
    shortest, longest = result.compiled.paths.shortest, result.compiled.paths.longest
    assert shortest is not None and longest is not None
    assert np.isfinite(longest.seconds) and longest.seconds >= shortest.seconds > 0


def test_skip_unreachable_skips_an_unreachable_target_after_a_run_time_motion(
    station: olp.Station,
) -> None:
    """With ``skip_unreachable`` the unreachable target after a run-time motion is skipped
    with a warning as anywhere (before: an error); the robot stays where the run-time motion
    left it, so the motion after the skipped one starts unknown too (only its target is
    checked: the line from LEFT over axis 1 would be an error)."""
    nodes = (ptp(station, LEFT, 2), runtime(3), lin(station, FAR, 4, lift=5.0))
    options = ResolveOptions(skip_unreachable=True)
    program = ir.Program(name="p", instructions=(HOME, *nodes, lin(station, RIGHT, 5)))
    result = olp.build(station, program, post="kuka", collisions=None, options=options)
    assert result.ok
    steps = result.compiled.steps
    assert steps[3].skipped and not steps[4].skipped and steps[4].joints is not None
    found = [(d.severity, d.kind, d.span.line if d.span else None) for d in result.diagnostics]
    assert ("warning", "unreachable", 4) in found and ("warning", "unknown_start", 5) in found
    written = [line for line in result.files["p.src"].splitlines() if line.startswith("LIN")]
    assert len(written) == 2 and written[0] == "LIN pCam"  # the skipped one is not written


def test_fallback_joint_leaves_an_unreachable_target_after_a_run_time_motion_an_error(
    station: olp.Station,
) -> None:
    """Only the target is checked there, as the joint move ``fallback_joint`` would write:
    a target it fails stays an error (nothing is rewritten)."""
    options = ResolveOptions(fallback_joint=True)
    nodes = (HOME, ptp(station, LEFT, 2), runtime(3), lin(station, FAR, 4, lift=5.0))
    program = ir.Program(name="p", instructions=nodes)
    result = olp.build(station, program, post="kuka", collisions=None, options=options)
    assert ("error", "unreachable", 4) in kinds(result)
    assert isinstance(result.compiled.steps[3].instruction, ir.LinearMove)
