"""Circular moves resolved and checked like linear ones: one branch along the sampled arc, the
TCP on the circle, degenerate arcs and unplannable rules as located errors, joint speed, and the
continuous collision check along the arc (not along its chord)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from olp import ir
from olp.arcs import arc_poses
from olp.collision.chord import chord_deviation
from olp.collision.scene import PairRules, Placed, build_scene
from olp.geometry import pose_from, transl
from olp.passes.collide import CollisionOptions, check_collisions
from olp.passes.resolve import resolve
from olp.station.loader import load_station
from olp.station.model import Shape, Station, StationObject, ToolBody

REPO = Path(__file__).resolve().parents[2]
ROD = ir.Tool(name="rod", pose=transl(0, 0, 0.25), number=2)
ROD_BODY = ToolBody(shapes=(Shape("cylinder", transl(0, 0, 0.125), (0.003, 0.25)),))
# The rod points down, its tip 140 mm above the floor (as in test_collide.py).
DOWN = np.radians([0, -50, 110, 0, 110, 0])
R = -0.06  # towards the robot: the DOWN pose has axis 5 near its limit outwards


@pytest.fixture(scope="module")
def cell() -> Station:
    station = load_station(REPO / "stations" / "kr6_milling_cell.yaml")
    return dataclasses.replace(
        station, tools={**station.tools, "rod": ROD}, tool_bodies={"rod": ROD_BODY}
    )


def _span(line: int) -> ir.SourceSpan:
    return ir.SourceSpan("t.src", line, 1)


def _start(station: Station) -> np.ndarray:
    return station.robot.flange_poses(DOWN) @ ROD.pose


def _offset(pose: np.ndarray, x: float, y: float) -> np.ndarray:
    return transl(x, y, 0.0) @ pose


def _arc(
    station: Station,
    via: tuple[float, float],
    end: tuple[float, float],
    line: int = 2,
    **fields: object,
) -> ir.CircularMove:
    """An arc in the horizontal plane from the DOWN pose, points offset in world x, y (m)."""
    start = _start(station)
    return ir.CircularMove(
        target=ir.CartesianTarget(pose=_offset(start, *end)),
        via=ir.CartesianTarget(pose=_offset(start, *via)),
        tool=ROD,
        speed=ir.Speed(linear=0.05),
        span=_span(line),
        **fields,  # type: ignore[arg-type]
    )


def _compile(station: Station, *instructions: ir.Instruction):  # type: ignore[no-untyped-def]
    start = ir.JointMove(target=ir.JointTarget(joints=DOWN), tool=ROD, span=_span(1))
    return resolve(ir.Program(name="t", instructions=(start, *instructions)), station)


def _found(compiled) -> list[tuple[str, int]]:  # type: ignore[no-untyped-def]
    return [(d.kind, d.span.line) for d in compiled.diagnostics if d.severity == "error"]


def test_the_tcp_follows_the_circle_in_one_branch(cell: Station) -> None:
    compiled = _compile(cell, _arc(cell, (R, R), (2 * R, 0.0)))
    assert compiled.ok, [d.format() for d in compiled.diagnostics]
    path = compiled.steps[1].path
    assert path is not None and len(path) >= 91  # 180° at 2° per sample
    tcp = cell.robot.flange_poses(path) @ ROD.pose
    centre = _start(cell)[:3, 3] + np.array([R, 0.0, 0.0])
    assert np.max(np.abs(np.linalg.norm(tcp[:, :3, 3] - centre, axis=1) - abs(R))) < 1e-9
    assert np.allclose(tcp[-1], _offset(_start(cell), 2 * R, 0.0), atol=1e-9)
    # the joints never jump: one branch, unwrapped
    assert np.max(np.abs(np.diff(path, axis=0))) < np.radians(5)


def test_full_circle_with_a_circular_angle(cell: Station) -> None:
    full = _arc(cell, (R, R), (2 * R, 0.0), angle=2 * np.pi)
    compiled = _compile(cell, full)
    assert compiled.ok
    path = compiled.steps[1].path
    assert path is not None and np.allclose(path[-1], path[0], atol=1e-9)


def test_each_orientation_rule_is_what_the_robot_does(cell: Station) -> None:
    start = _start(cell)
    for rule in (ir.ArcOrientation.CONSTANT, ir.ArcOrientation.PATH_CONSTANT):
        compiled = _compile(cell, _arc(cell, (R, R), (2 * R, 0.0), orientation=rule))
        path = compiled.steps[1].path
        assert compiled.ok and path is not None
        tcp = cell.robot.flange_poses(path) @ ROD.pose
        fractions = np.linspace(0, 1, len(path))
        expected = arc_poses(start, _offset(start, R, R), _offset(start, 2 * R, 0), fractions, rule)
        assert np.allclose(tcp, expected, atol=1e-9)


@pytest.mark.parametrize(
    ("via", "end", "angle", "words"),
    [
        ((R, 0.0), (2 * R, 0.0), None, "lie on a line"),
        ((0.0, 0.0), (2 * R, 0.0), None, "the via point is the start point"),
        ((R, R), (R, R), None, "the via point is the end point"),
        ((R, R), (2 * R, 0.0), np.radians(30.0), "ends before the via point"),
        ((2e-5, 2e-5), (4e-5, 0.0), None, "radius"),
    ],
)
def test_degenerate_arcs_are_errors_on_their_line(
    cell: Station,
    via: tuple[float, float],
    end: tuple[float, float],
    angle: float | None,
    words: str,
) -> None:
    compiled = _compile(cell, _arc(cell, via, end, line=7, angle=angle))
    assert _found(compiled) == [("degenerate_arc", 7)]
    assert words in compiled.diagnostics[-1].message
    assert compiled.steps[1].path is None


def test_wrist_rule_is_an_error_not_a_guess(cell: Station) -> None:
    wrist = _arc(cell, (R, R), (2 * R, 0), 4, orientation=ir.ArcOrientation.WRIST)
    compiled = _compile(cell, wrist)
    assert _found(compiled) == [("unsupported", 4)]


def test_an_arc_out_of_reach_is_located(cell: Station) -> None:
    compiled = _compile(cell, _arc(cell, (0.6, 0.6), (1.2, 0.0), line=5))
    kinds = _found(compiled)
    assert kinds in ([("unreachable", 5)], [("unreachable_path", 5)])


def test_joint_speed_needed_along_the_arc(cell: Station) -> None:
    fast = dataclasses.replace(_arc(cell, (R, R), (2 * R, 0.0)), speed=ir.Speed(linear=20.0))
    compiled = _compile(cell, fast)
    assert compiled.ok
    warnings = [d for d in compiled.diagnostics if d.kind == "speed_limited"]
    assert len(warnings) == 1 and warnings[0].span is not None and warnings[0].span.line == 2
    assert "20000 mm/s needs axis" in warnings[0].message


# ---- collisions along the arc


def _post(name: str, at: np.ndarray) -> StationObject:
    """A thin vertical post (10 mm square, 300 mm tall) standing at ``at`` (3,) on the floor."""
    pose = transl(at[0], at[1], 0.15)
    return StationObject(name, "fixture", pose, (Shape("box", np.eye(4), (0.01, 0.01, 0.3)),))  # type: ignore[arg-type]


def test_collisions_are_checked_along_the_arc_not_its_chord(cell: Station) -> None:
    start = _start(cell)[:3, 3]
    arc = _arc(cell, (R, R), (2 * R, 0.0))
    on_arc = start + np.array([R, R, 0.0])  # the top of the half circle
    on_chord = start + np.array([R, 0.0, 0.0])  # the chord's middle: off the arc
    hit = _compile(dataclasses.replace(cell, objects=(_post("post", on_arc),)), arc)
    found = check_collisions(hit)
    assert [(d.kind, d.index) for d in found] == [("collision", 1)]
    assert "tool 'rod' hits fixture 'post'" in found[0].message
    free = _compile(dataclasses.replace(cell, objects=(_post("post", on_chord),)), arc)
    assert check_collisions(free) == []
    assert check_collisions(free, CollisionOptions(mode="samples")) == []


def test_chord_deviation_along_an_arc_is_below_the_tolerance(cell: Station) -> None:
    start = _start(cell)
    compiled = _compile(cell, _arc(cell, (R, R), (2 * R, 0.0)))
    path = compiled.steps[1].path
    assert path is not None
    count = len(path) - 1
    halves = (np.arange(count) + 0.5) / count
    middles = arc_poses(start, _offset(start, R, R), _offset(start, 2 * R, 0), halves)
    scene = build_scene(
        cell.robot, Placed("rod", "tool", np.eye(4), ROD_BODY.shapes), [], [], PairRules()
    )
    gap = chord_deviation(cell.robot, scene, [path], ROD.pose, middles)
    assert 0.0 < float(np.max(gap)) < 1e-4  # below the default tolerance, as for lines
    line_gap = chord_deviation(cell.robot, scene, [path], ROD.pose)
    # the arc's own midpoints are not the chord's: measuring against a line is another thing
    assert not np.allclose(gap, line_gap)


def test_pose_from_is_used_for_frames(cell: Station) -> None:
    """An arc in a user frame: via and target read in the frame, the circle in the world."""
    frame = ir.Frame(name="table", pose=pose_from(np.eye(3), [0.0, 0.0, 0.0]))
    compiled = _compile(cell, dataclasses.replace(_arc(cell, (R, R), (2 * R, 0.0)), frame=frame))
    assert compiled.ok
