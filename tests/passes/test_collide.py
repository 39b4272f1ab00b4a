"""Collide: each collision constructed on purpose, asserted by kind, instruction and source line;
the bound the advancement rests on, and the guarantee itself against dense sampling."""

from __future__ import annotations

import dataclasses
import itertools
import re
from pathlib import Path

import numpy as np
import pytest

from olp import ir
from olp.collision.advance import advance, path_run, sample_hits
from olp.collision.chord import chord_deviation
from olp.collision.scene import DisplacementBound, PairRules, Placed, Scene, build_scene
from olp.collision.shapes import reach
from olp.compiled import CompiledProgram
from olp.diagnostics import Diagnostic
from olp.geometry import pose_from, rotx, roty, rotz, transl
from olp.passes.collide import Attachment, CollisionOptions, check_collisions
from olp.passes.resolve import ResolveOptions, resolve
from olp.station.loader import load_station
from olp.station.model import Robot, Shape, Station, StationObject, ToolBody

REPO = Path(__file__).resolve().parents[2]

# A 250 mm rod of 3 mm radius on the flange; its tip is the TCP.
ROD = ir.Tool(name="rod", pose=transl(0, 0, 0.25), number=2)
ROD_BODY = ToolBody(shapes=(Shape("cylinder", transl(0, 0, 0.125), (0.003, 0.25)),))
# A1 sweeps 60° with the arm stretched out: resolve samples the joint move every 2°, and the
# rod's tip, 0.85 m from axis 1, moves 30 mm between samples.
SWEEP_FROM = np.radians([-30, -60, 100, 0, 50, 0])
SWEEP_TO = np.radians([30, -60, 100, 0, 50, 0])
# The rod points down (10° off vertical), its tip 140 mm above the floor.
DOWN = np.radians([0, -50, 110, 0, 110, 0])


@pytest.fixture(scope="module")
def cell() -> Station:
    station = load_station(REPO / "stations" / "kr6_milling_cell.yaml")
    return dataclasses.replace(
        station, tools={**station.tools, "rod": ROD}, tool_bodies={"rod": ROD_BODY}
    )


def _span(line: int) -> ir.SourceSpan:
    return ir.SourceSpan("t.src", line, 1)


def _ptp(q: np.ndarray, line: int) -> ir.JointMove:
    return ir.JointMove(target=ir.JointTarget(joints=q), tool=ROD, span=_span(line))


def _lin(pose: np.ndarray, line: int) -> ir.LinearMove:
    return ir.LinearMove(target=ir.CartesianTarget(pose=pose), tool=ROD, span=_span(line))


def _with(station: Station, *objects: StationObject) -> Station:
    return dataclasses.replace(station, objects=objects)


def _box(
    name: str, pose: np.ndarray, size: tuple[float, ...], kind: str = "fixture"
) -> StationObject:
    return StationObject(name, kind, pose, (Shape("box", np.eye(4), size),))  # type: ignore[arg-type]


def _compile(station: Station, *instructions: ir.Instruction) -> CompiledProgram:
    compiled = resolve(ir.Program(name="t", instructions=instructions), station)
    assert compiled.ok, [d.format() for d in compiled.diagnostics]
    return compiled


def _found(diagnostics: list[Diagnostic]) -> list[tuple[str, int | None, int | None]]:
    return [(d.kind, d.index, d.span.line if d.span else None) for d in diagnostics]


def _tip(station: Station, q: np.ndarray) -> np.ndarray:
    return (station.robot.flange_poses(q) @ ROD.pose)[:3, 3]


# --------------------------------------------------------------------------------------------
# Between samples


def _thin_wall(station: Station) -> StationObject:
    """A 1 mm wall (50 x 50 mm) across the rod tip's path halfway between two samples of the
    sweep (A1 = 0° and 2°), facing the direction of motion."""
    mid = np.radians([1, -60, 100, 0, 50, 0])
    tip = _tip(station, mid)
    radial = tip - station.robot.base[:3, 3]
    radial[2] = 0.0
    radial /= np.linalg.norm(radial)
    tangent = np.cross([0.0, 0.0, 1.0], radial)
    rotation = np.column_stack([tangent, radial, [0.0, 0.0, 1.0]])
    return _box("wall", pose_from(rotation, tip), (0.001, 0.05, 0.05))


def test_thin_wall_between_two_samples_is_found(cell: Station) -> None:
    station = _with(cell, _thin_wall(cell))
    compiled = _compile(station, _ptp(SWEEP_FROM, 3), _ptp(SWEEP_TO, 4))
    path = compiled.steps[1].path
    assert path is not None and np.allclose(np.degrees(path[15:17, 0]), [0, 2])
    # Every sample of the sweep is clear of the wall: a sampling-only check finds nothing.
    assert check_collisions(compiled, CollisionOptions(mode="samples")) == []
    found = check_collisions(compiled)
    assert _found(found) == [("collision", 1, 4)]
    assert "tool 'rod' hits fixture 'wall'" in found[0].message
    # The first contact lies between the two samples that straddle the wall.
    assert found[0].joints is not None and 0.0 < np.degrees(found[0].joints[0]) < 2.0
    assert "at 5" in found[0].message  # 15/30 .. 16/30 of the move


def test_an_inline_tool_has_the_body_of_the_station_tool_with_its_number(cell: Station) -> None:
    inline = ir.Tool(name="TOOL_DATA[2]", pose=ROD.pose, number=2)  # e.g. a KRL $TOOL
    moves = [
        dataclasses.replace(_ptp(q, line), tool=inline)
        for q, line in ((SWEEP_FROM, 3), (SWEEP_TO, 4))
    ]
    found = check_collisions(_compile(_with(cell, _thin_wall(cell)), *moves))
    assert _found(found) == [("collision", 1, 4)]
    assert "tool 'rod' hits fixture 'wall'" in found[0].message


def test_thin_wall_beside_the_path_is_not_reported(cell: Station) -> None:
    wall = _thin_wall(cell)
    aside = dataclasses.replace(wall, pose=transl(0, 0, 0.06) @ wall.pose)  # 10 mm above the tip
    compiled = _compile(_with(cell, aside), _ptp(SWEEP_FROM, 3), _ptp(SWEEP_TO, 4))
    assert check_collisions(compiled) == []


# --------------------------------------------------------------------------------------------
# Self-collision, fixtures, parts


def test_folding_the_wrist_onto_the_base_is_a_self_collision(cell: Station) -> None:
    home = cell.robot.home
    folded = np.radians([0, -10, 156, 0, 0, 0])  # the wrist comes down onto the robot's base
    compiled = _compile(cell, _ptp(home, 1), _ptp(folded, 2))
    found = check_collisions(compiled)
    assert {d.kind for d in found} == {"self_collision"}
    assert {(d.index, d.span.line if d.span else None) for d in found} == {(1, 2)}
    assert any("robot link_6 hits robot base" in d.message for d in found)
    assert not check_collisions(compiled, CollisionOptions(self_collision=False))


def _body_name(label: str) -> str:
    """``robot link_4`` -> ``link_4``; ``tool 'rod'`` -> ``rod``."""
    quoted = re.search(r"'([^']+)'", label)
    return quoted[1] if quoted else label.split()[-1]


def test_allowed_pairs_are_not_checked(cell: Station) -> None:
    folded = np.radians([0, -10, 156, 0, 0, 0])
    compiled = _compile(cell, _ptp(cell.robot.home, 1), _ptp(folded, 2))
    found = check_collisions(compiled)
    allowed = tuple(
        (_body_name(a), _body_name(b)) for a, b in (_pair_names(d.message) for d in found)
    )
    assert len(set(allowed)) == len(found) >= 2
    assert check_collisions(compiled, CollisionOptions(allowed_pairs=allowed)) == []
    assert len(check_collisions(compiled, CollisionOptions(allowed_pairs=allowed[1:]))) == 1


def test_tool_driven_into_a_fixture(cell: Station) -> None:
    start = DOWN
    tip = _tip(cell, start)
    block = _box("vice", transl(*(tip - [0, 0, 0.08])), (0.1, 0.1, 0.1))  # top 30 mm below the tip
    down = transl(0, 0, -0.05) @ cell.robot.flange_poses(start) @ ROD.pose
    compiled = _compile(_with(cell, block), _ptp(start, 5), _lin(down, 6))
    found = check_collisions(compiled)
    assert _found(found) == [("collision", 1, 6)]
    # The tip meets the top 30 mm down the 50 mm move (the tilted rod's rim half a mm earlier).
    assert re.fullmatch(r"tool 'rod' hits fixture 'vice' at (59|60)% of the move", found[0].message)


def test_a_mesh_fixture_collides_as_its_convex_hull(cell: Station, tmp_path: Path) -> None:
    import trimesh

    # A U-shaped block, 100 mm tall: the rod goes down into the notch, which its convex hull
    # fills, and meets the hull's top 30 mm down.
    mesh = trimesh.util.concatenate(
        [
            trimesh.creation.box((0.1, 0.1, 0.02), transl(0, 0, -0.04)),
            trimesh.creation.box((0.02, 0.1, 0.1), transl(0.04, 0, 0)),
            trimesh.creation.box((0.02, 0.1, 0.1), transl(-0.04, 0, 0)),
        ]
    )
    file = tmp_path / "u.stl"
    mesh.export(file)
    tip = _tip(cell, DOWN)
    block = StationObject(
        "u_block", "fixture", transl(*(tip - [0, 0, 0.08])), (Shape("mesh", mesh=str(file)),)
    )
    down = transl(0, 0, -0.05) @ cell.robot.flange_poses(DOWN) @ ROD.pose
    found = check_collisions(_compile(_with(cell, block), _ptp(DOWN, 5), _lin(down, 6)))
    assert _found(found) == [("collision", 1, 6)]
    assert re.fullmatch(
        r"tool 'rod' hits fixture 'u_block' at (59|60)% of the move", found[0].message
    )


def test_the_tool_may_enter_parts_unless_told_otherwise(cell: Station) -> None:
    start = DOWN
    tip = _tip(cell, start)
    block = _box("plate", transl(*(tip - [0, 0, 0.08])), (0.1, 0.1, 0.1), kind="part")
    down = transl(0, 0, -0.05) @ cell.robot.flange_poses(start) @ ROD.pose
    compiled = _compile(_with(cell, block), _ptp(start, 5), _lin(down, 6))
    assert check_collisions(compiled) == []
    strict = check_collisions(compiled, CollisionOptions(tool_touches_parts=False))
    assert _found(strict) == [("collision", 1, 6)]
    assert "tool 'rod' hits part 'plate'" in strict[0].message


def test_clearance_reports_a_near_miss(cell: Station) -> None:
    start = DOWN
    tip = _tip(cell, start)
    block = _box("vice", transl(*(tip - [0, 0, 0.08])), (0.1, 0.1, 0.1))
    down = transl(0, 0, -0.025) @ cell.robot.flange_poses(start) @ ROD.pose  # stops 5 mm above
    compiled = _compile(_with(cell, block), _ptp(start, 5), _lin(down, 6))
    assert check_collisions(compiled) == []
    near = check_collisions(compiled, CollisionOptions(clearance_m=0.01))
    assert _found(near) == [("collision", 1, 6)]
    assert "closer than 10.0 mm" in near[0].message


# --------------------------------------------------------------------------------------------
# Pick and place


@pytest.fixture(scope="module")
def pick_cell(cell: Station) -> tuple[Station, np.ndarray]:
    """A puck (40 mm across, 30 mm tall) on a tray 1 mm below the rod's tip at ``grip`` joints,
    and a wall 100 mm to the side (+y) whose top is 15 mm below the rod's tip after a 30 mm
    lift."""
    grip = DOWN
    tip = _tip(cell, grip)
    puck = StationObject(
        "puck", "part", transl(*tip), (Shape("cylinder", transl(0, 0, -0.016), (0.02, 0.03)),)
    )
    tray = _box("tray", transl(*(tip - [0, 0, 0.051])), (0.1, 0.1, 0.04))
    wall = _box("wall", transl(*(tip + np.array([0, 0.1, 0.03 - 0.015 - 0.05]))), (0.3, 0.02, 0.1))
    return _with(cell, puck, tray, wall), grip


def _pick_program(station: Station, grip: np.ndarray) -> list[ir.Instruction]:
    at = station.robot.flange_poses(grip) @ ROD.pose
    return [
        _ptp(grip, 1),
        ir.Call(name="TCP_On", span=_span(2)),
        _lin(transl(0, 0, 0.03) @ at, 3),  # lift 30 mm
        _lin(transl(0, 0.2, 0.03) @ at, 4),  # across the wall
        ir.Call(name="TCP_Off", span=_span(5)),
        _lin(transl(0, 0.2, 0.06) @ at, 6),
        _lin(transl(0, 0.2, -0.05) @ at, 7),  # back down through where the puck was let go
    ]


def test_a_carried_part_hits_a_fixture_the_tool_clears(
    pick_cell: tuple[Station, np.ndarray],
) -> None:
    station, grip = pick_cell
    compiled = _compile(station, *_pick_program(station, grip))
    assert check_collisions(compiled) == []  # the rod passes 15 mm above the wall
    carried = CollisionOptions(attachments=(Attachment("puck", grasp=1, release=4),))
    found = check_collisions(compiled, carried)
    # Gripped while resting on the tray (touching, not colliding); it hits the wall on the way.
    assert _found(found) == [("collision", 3, 4)]
    assert "carried part 'puck' hits fixture 'wall'" in found[0].message


def test_a_part_stays_where_it_is_let_go(pick_cell: tuple[Station, np.ndarray]) -> None:
    station, grip = pick_cell
    lifted = dataclasses.replace(station, objects=station.objects[:2])  # no wall
    compiled = _compile(lifted, *_pick_program(lifted, grip))
    strict = CollisionOptions(
        attachments=(Attachment("puck", grasp=1, release=4),), tool_touches_parts=False
    )
    found = check_collisions(compiled, strict)
    assert _found(found) == [("collision", 6, 7)]
    assert "tool 'rod' hits part 'puck'" in found[0].message


def test_an_unknown_carried_part_is_an_error(cell: Station) -> None:
    compiled = _compile(cell, _ptp(SWEEP_FROM, 1), _ptp(SWEEP_TO, 2))
    found = check_collisions(compiled, CollisionOptions(attachments=(Attachment("box", 1),)))
    assert _found(found) == [("unknown_part", 1, 2)]


# --------------------------------------------------------------------------------------------
# Free motions


def _helix(station: Station, count: int) -> list[ir.Instruction]:
    """The toolpath of benchmarks/check.py: above the workpiece, down, then a helix of ``count``
    linear moves (150 mm radius, 10 turns, 50 mm rise) around the workpiece's centre."""
    tool, frame = station.tools["spindle"], station.frames["workpiece"]
    t = np.linspace(0.0, 1.0, count)
    poses = np.repeat(pose_from(np.diag([-1.0, 1.0, -1.0]), np.zeros(3))[None], count, axis=0)
    poses[:, :3, 3] = np.stack(
        [0.15 * np.cos(20 * np.pi * t), 0.15 * np.sin(20 * np.pi * t), 0.02 + 0.05 * t], axis=1
    )
    above = transl(0, 0, 0.2) @ poses[0]
    return [
        ir.JointMove(target=ir.CartesianTarget(pose=above), tool=tool, frame=frame),
        *(ir.LinearMove(target=ir.CartesianTarget(pose=p), tool=tool, frame=frame) for p in poses),
    ]


def test_the_milling_helix_is_free() -> None:
    station = load_station(REPO / "stations" / "kr6_milling_collision_cell.yaml")
    compiled = _compile(station, *_helix(station, 400))
    assert check_collisions(compiled) == []
    # The clamps are 25 mm from the spindle, the cutter 20 mm above the table: with a 30 mm
    # clearance the helix comes too close to each clamp on each of its turns.
    near = check_collisions(compiled, CollisionOptions(clearance_m=0.03))
    clamps = [d for d in near if d.kind == "collision"]
    assert all(
        d.message.startswith("moves ") and "tool 'spindle' hits fixture" in d.message
        for d in clamps
    )
    assert sum("clamp" in d.message for d in clamps) >= 4 * 3
    # The robot's own links have their own margin: link_2 passes 21.6 mm from the base
    # capsule at home and stays that close all the way round.
    assert [d.kind for d in near] == ["collision"] * len(near)
    own = check_collisions(compiled, CollisionOptions(self_clearance_m=0.03))
    assert [d.message for d in own] == [
        "moves 0-400: self-collision: robot link_2 hits robot base (closer than 30.0 mm) "
        "(first at 0% of move 0)"
    ]


def test_a_sweep_in_free_space_is_free(cell: Station) -> None:
    compiled = _compile(cell, _ptp(SWEEP_FROM, 1), _ptp(SWEEP_TO, 2))
    assert check_collisions(compiled) == []


# --------------------------------------------------------------------------------------------
# The bound and the guarantee


def _scene(station: Station) -> Scene:
    tool = Placed("rod", "tool", np.eye(4), ROD_BODY.shapes)
    objects = [Placed(o.name, o.kind, o.pose, o.shapes) for o in station.objects]
    return build_scene(station.robot, tool, [], objects, PairRules())


@pytest.mark.parametrize(
    "shape",
    [
        Shape("box", rotz(0.3) @ transl(0.1, -0.05, 0.2), (0.1, 0.3, 0.05)),
        Shape("cylinder", transl(0.1, 0.2, -0.1) @ rotz(0.7), (0.04, 0.3)),
        Shape("capsule", transl(-0.2, 0.1, 0.05), (0.03, 0.2)),
        Shape("sphere", transl(0.3, 0.0, 0.1), (0.05,)),
    ],
)
def test_reach_is_the_farthest_point_of_a_shape(shape: Shape) -> None:
    placement = transl(0.05, 0.02, -0.03) @ rotx(0.4) @ roty(-0.3)
    radius = shape.size[0]
    half = {
        "box": np.asarray(shape.size) / 2,
        "cylinder": np.array([radius, radius, shape.size[-1] / 2]),
        "capsule": np.array([radius, radius, shape.size[-1] / 2 + radius]),
        "sphere": np.full(3, radius),
    }[shape.kind]
    local = np.random.default_rng(0).uniform(-half, half, (200_000, 3))
    pose = placement @ shape.pose
    points = local @ pose[:3, :3].T + pose[:3, 3]
    inside = points[shape.contains(points, placement)]
    farthest = float(np.max(np.linalg.norm(inside, axis=1)))
    # Sampled points come within a few mm of a box's corner, closer on round shapes.
    assert farthest <= reach(shape, placement) < farthest + 0.005


def test_displacement_bound_covers_the_real_point_motion(cell: Station) -> None:
    """No point of a body travels further (measured as a polyline over 200 substeps of a random
    joint step) than the weights allow."""
    import pinocchio as pin

    scene = _scene(cell)
    bound = DisplacementBound(scene.model, cell.robot)
    rng = np.random.default_rng(1)
    lo, hi = cell.robot.limits.lower, cell.robot.limits.upper
    data = scene.model.createData()
    for _ in range(20):
        q0 = rng.uniform(lo, hi)
        q1 = np.clip(q0 + rng.normal(0, 0.4, 6), lo, hi)
        chain = cell.robot.kinematics.chain_joints(np.linspace(q0, q1, 201))
        for body in scene.bodies:
            if body.joint == 0:
                continue
            local = rng.normal(size=(50, 3))
            local *= (
                body.reach * rng.uniform(0, 1, (50, 1)) / np.linalg.norm(local, axis=1)[:, None]
            )
            travel = np.zeros(50)
            previous = None
            for q in chain:
                pin.forwardKinematics(scene.model, data, q)
                pose = data.oMi[body.joint]
                points = local @ pose.rotation.T + pose.translation
                if previous is not None:
                    travel += np.linalg.norm(points - previous, axis=1)
                previous = points
            allowed = np.abs(chain[-1] - chain[0]) @ bound.body(body)
            assert np.all(travel <= allowed + 1e-12), (body.name, travel.max(), allowed)


def _pair_names(message: str) -> tuple[str, str]:
    pattern = (
        r"(?:moves \d+-\d+: )?(?:self-collision: )?(.+) hits (.+?) (?:at|\(first at) \d+(?:\.\d+)?%"
    )
    match = re.search(pattern, message)
    assert match is not None, message
    return match[1], match[2]


def test_no_collision_deeper_than_the_tolerance_is_missed(cell: Station) -> None:
    """Random single-segment joint paths (no samples in between) among thin plates: wherever
    dense sampling (400 points) finds a pair overlapping deeper than the tolerance, the
    advancement reports that pair; every configuration it reports does overlap. Many of those
    collisions lie strictly between the two ends, where a sampling check sees nothing."""
    rng = np.random.default_rng(1)
    plates = []
    for k in range(12):
        centre = cell.robot.base[:3, 3] + [*rng.uniform(-0.9, 0.9, 2), rng.uniform(0.0, 1.0)]
        plates.append(
            _box(f"plate{k}", transl(*centre) @ rotz(rng.uniform(0, np.pi)), (0.001, 0.15, 0.15))
        )
    scene = _scene(_with(cell, *plates))
    tolerance = CollisionOptions().tolerance_m
    lower, upper = -tolerance, -tolerance / 2
    lo, hi = cell.robot.limits.lower, cell.robot.limits.upper
    between = reported = 0
    for _ in range(16):
        q0 = rng.uniform(lo * 0.7, hi * 0.7)
        q1 = np.clip(q0 + rng.normal(0, 0.6, 6), lo, hi)
        run = path_run([np.stack([q0, q1])], cell.robot.kinematics.chain_joints)
        dense = np.linspace(run.chain[0], run.chain[1], 400)
        depth = np.empty((len(dense), len(scene.pairs)))
        for k, q in enumerate(dense):
            scene.place(q)
            depth[k] = [scene.distance(p) for p in scene.pairs]
        for p, pair in enumerate(scene.pairs):
            hits, _ = advance(scene, pair, run, lower, upper)
            if np.min(depth[:, p]) < lower:
                assert hits, scene.name_of(pair)
                between += not sample_hits(scene, pair, run, upper)[0]
            for hit in hits:
                scene.place(cell.robot.kinematics.chain_joints(hit.joints))
                assert scene.distance(pair) < upper
            reported += len(hits)
    assert between >= 3 and reported > between


def test_chord_deviation_of_a_linear_move_is_second_order(cell: Station) -> None:
    start = DOWN
    at = cell.robot.flange_poses(start) @ ROD.pose
    scene = _scene(cell)
    gaps = []
    for step_m in (0.01, 0.005):
        compiled = resolve(
            ir.Program(
                name="t", instructions=[_ptp(start, 1), _lin(transl(-0.1, 0.2, 0.05) @ at, 2)]
            ),
            cell,
            ResolveOptions(step_m=step_m),
        )
        path = compiled.steps[1].path
        assert path is not None
        gaps.append(float(np.max(chord_deviation(cell.robot, scene, [path], ROD.pose))))
    assert gaps[1] < 1e-4  # below the default tolerance at the default 5 mm step
    assert 3.0 < gaps[0] / gaps[1] < 5.0  # halving the step quarters the gap


# --------------------------------------------------------------------------------------------
# Which pairs are checked: never a function of the clearance (issue 10, item 1)

# The issue's reproduction: the second move swings link 2 into the base.
BUMP = (np.radians([0, -90, 90, 0, 30, 0]), np.radians([0, 45, -120, 0, -120, 0]))
BUMP_SRC = """DEF Bump( )
PTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}
PTP {A1 0,A2 45,A3 -120,A4 0,A5 -120,A6 0}
END
"""
# Both clearances (m) swept over; 21.6 mm is link_2's distance from the base capsule at home.
SWEEP_CLEARANCES = (0.0, 1e-3, 0.0216, 0.1, 1e6)


def test_a_larger_clearance_fails_the_issue_program_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """link_2 runs into the base: a self collision at every clearance and self-clearance,
    including a large --clearance with the self-clearance left at 0."""
    from olp.cli import main

    program = tmp_path / "bump.src"
    program.write_text(BUMP_SRC)
    station = str(REPO / "stations" / "kr6_milling_cell.yaml")
    for clearance, own in itertools.product(("0", "20", "100"), ("0", "10", "100")):
        options = ["--clearance", clearance, "--self-clearance", own]
        assert main(["check", station, str(program), "-q", *options]) == 1
        assert "self-collision: robot link_2 hits robot base" in capsys.readouterr().err


def _hits(diagnostics: list[Diagnostic]) -> set[tuple[str, tuple[str, str], int]]:
    """(kind, pair, instruction) for every motion a collision diagnostic covers ("moves 3-5" is
    three); the once-per-build warnings (:func:`_unmet`) are left out."""
    out = set()
    for d in diagnostics:
        if d.kind == "clearance_unmet":
            continue
        assert d.index is not None
        spread = re.match(r"moves (\d+)-(\d+): ", d.message)
        first, last = (int(spread[1]), int(spread[2])) if spread else (d.index, d.index)
        pair = _pair_names(re.sub(r" \(closer than [^)]*\)", "", d.message))
        out |= {(d.kind, pair, k) for k in range(first, last + 1)}
    return out


def _unmet(diagnostics: list[Diagnostic]) -> dict[tuple[str, str], tuple[float, float]]:
    """Each clearance_unmet warning: pair names -> (constant distance, clearance asked) in mm."""
    out = {}
    for d in diagnostics:
        if d.kind == "clearance_unmet":
            assert d.severity == "warning"
            pattern = r"the (?:self-)?clearance of ([\d.]+) mm cannot be met: (?:shapes of )?(.+) "
            pattern += r"and (.+) are ([\d.]+) mm apart in every position"
            match = re.match(pattern, d.message)
            assert match is not None, d.message
            assert (match[2], match[3]) not in out, d.message  # once per build
            out[(match[2], match[3])] = float(match[4]), float(match[1])
    return out


Built = list[tuple[str, tuple[str, str], tuple[int, ...] | float]]


def _checked_pairs(
    monkeypatch: pytest.MonkeyPatch, compiled: CompiledProgram, options: CollisionOptions
) -> tuple[list[Diagnostic], Built]:
    """The diagnostics and every pair of every scene the pass built: ("checked", names,
    geometry pairs) and ("constant", names, distance)."""
    from olp.collision import scene as scene_module

    built: Built = []

    def recording(*args: object, **kwargs: object) -> Scene:
        scene = build_scene(*args, **kwargs)  # type: ignore[arg-type]
        built.extend(("checked", scene.name_of(p), p.geometry_pairs) for p in scene.pairs)
        built.extend(("constant", scene.name_of(p), p.distance) for p in scene.constant)
        return scene

    monkeypatch.setattr(scene_module, "build_scene", recording)
    return check_collisions(compiled, options), built


@pytest.fixture(scope="module")
def collision_cell() -> Station:
    return load_station(REPO / "stations" / "kr6_milling_collision_cell.yaml")


def _spindle_moves(station: Station, *targets: np.ndarray) -> CompiledProgram:
    tool = station.tools["spindle"]
    moves = [
        ir.JointMove(target=ir.JointTarget(joints=q), tool=tool, span=_span(k + 2))
        for k, q in enumerate(targets)
    ]
    return resolve(ir.Program(name="t", instructions=tuple(moves)), station)


def test_the_checked_pairs_do_not_depend_on_the_clearances(
    collision_cell: Station, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The issue's program with the spindle among the clamps, over a grid of clearances and
    self-clearances: the same pairs at every point, and what one point reports (a hit, or a
    constant pair within its clearance) every point with both clearances at least as large
    reports too (from half a tolerance up, the advancement's guarantee: below that a near
    miss inside the tolerance band may go either way). Each clearance governs its own kind."""
    compiled = _spindle_moves(collision_cell, *BUMP)
    grid = list(itertools.product(SWEEP_CLEARANCES, repeat=2))
    results = {
        (c, s): _checked_pairs(
            monkeypatch, compiled, CollisionOptions(clearance_m=c, self_clearance_m=s)
        )
        for c, s in grid
    }
    base, _ = results[(0.0, 0.0)]
    assert ("self_collision", ("robot link_2", "robot base"), 1) in _hits(base)
    for a, b in itertools.product(grid, repeat=2):
        if a[0] <= b[0] and a[1] <= b[1]:
            (found, pairs), (more, more_pairs) = results[a], results[b]
            assert more_pairs == pairs
            assert _hits(found) <= _hits(more), (a, b)
            assert _unmet(found).keys() <= _unmet(more).keys(), (a, b)
    for c, s in grid:
        changed = {kind for kind, _, _ in _hits(results[(c, s)][0]) ^ _hits(base)}
        if s == 0:
            assert changed <= {"collision"}, c  # the clearance alone leaves the self pairs be
        if c == 0:
            assert changed <= {"self_collision"}, s
    # At 1000 km every pair is too close: each checked one is reported, each constant one
    # warned about once, and nothing else.
    found, pairs = results[(1e6, 1e6)]
    assert {pair for _, pair, _ in _hits(found)} == {n for what, n, _ in pairs if what == "checked"}
    assert _unmet(found).keys() == {n for what, n, _ in pairs if what == "constant"}
    assert ("robot link_3", "robot link_5") in _unmet(found)


def test_a_clearance_only_adds_margin_on_random_moves(
    collision_cell: Station, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Property: random joint moves of the spindle robot, two settings of (clearance,
    self-clearance), the second larger in either or both (by at least half the tolerance): the
    same pairs are checked and every hit and warning of the first is one of the second."""
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    robot = collision_cell.robot
    tolerance = CollisionOptions().tolerance_m
    unit = st.floats(0.0, 1.0)
    grow = st.one_of(st.none(), st.floats(0, 0.1))

    @settings(
        max_examples=20,
        deadline=None,
        derandomize=True,
        suppress_health_check=[HealthCheck.function_scoped_fixture],
    )
    @given(
        st.lists(unit, min_size=12, max_size=12),
        st.tuples(st.floats(0, 0.15), st.floats(0, 0.15)),
        st.tuples(grow, grow),
    )
    def check(
        fractions: list[float],
        clearances: tuple[float, float],
        gaps: tuple[float | None, float | None],
    ) -> None:
        low, high = robot.limits.lower * 0.9, robot.limits.upper * 0.9
        targets = low + np.reshape(fractions, (2, 6)) * (high - low)
        compiled = _spindle_moves(collision_cell, *targets)
        larger = [
            c if g is None else c + tolerance / 2 + g for c, g in zip(clearances, gaps, strict=True)
        ]
        lower = CollisionOptions(clearance_m=clearances[0], self_clearance_m=clearances[1])
        upper = CollisionOptions(clearance_m=larger[0], self_clearance_m=larger[1])
        found, pairs = _checked_pairs(monkeypatch, compiled, lower)
        more, more_pairs = _checked_pairs(monkeypatch, compiled, upper)
        assert pairs == more_pairs
        assert _hits(found) <= _hits(more)
        assert _unmet(found).keys() <= _unmet(more).keys()

    check()


def _library() -> list[str]:
    from olp.station.loader import robot_library

    return robot_library()


def _library_robot(name: str) -> Robot:
    from olp.station.loader import load_library_robot

    return load_library_robot(name).place()


@pytest.mark.parametrize("name", _library())
def test_no_checked_pair_of_a_library_robot_touches_at_home(name: str) -> None:
    """The library's allowed_pairs name every pair that overlaps by construction: at home all
    other pairs are apart, so a program starting there is free at clearance 0."""
    robot = _library_robot(name)
    scene = build_scene(robot, None, [], [], PairRules())
    scene.place(robot.kinematics.chain_joints(robot.home))
    apart = {scene.name_of(p): scene.distance(p) for p in scene.pairs}
    assert min(apart.values()) > 0.01, apart


@pytest.mark.parametrize("name", _library())
def test_a_library_robots_allowed_pairs_overlap_in_every_position(name: str) -> None:
    """What each declaration's comment argues: its capsules overlap wherever the joints are."""
    robot = _library_robot(name)
    assert robot.allowed_pairs
    full = build_scene(dataclasses.replace(robot, allowed_pairs=()), None, [], [], PairRules())
    declared = {frozenset(p) for p in robot.allowed_pairs}
    pairs = [p for p in full.pairs if frozenset(_body_name(n) for n in full.name_of(p)) in declared]
    # Some declared pairs are also proven by the fixed-point rule (never in the full scene).
    samples = np.random.default_rng(2).uniform(robot.limits.lower, robot.limits.upper, (500, 6))
    for q in samples:
        full.place(robot.kinematics.chain_joints(q))
        assert all(full.distance(p) < 0 for p in pairs), q


def test_a_robot_pair_declaration_names_links_not_station_bodies() -> None:
    """The UR5e's [link_2, base] is about its own base capsule: a fixture named "base" that
    link_2 runs into is still a collision."""
    station = load_station(REPO / "stations" / "ur5e_screw_cell.yaml")
    home = station.robot.home
    reach_out = home + np.radians([0, 60, 0, 0, 0, 0])
    block_at = station.robot.link_poses(reach_out)["link_3"][:3, 3]
    block = _box("base", transl(*block_at), (0.1, 0.1, 0.1))
    moves = [
        ir.JointMove(target=ir.JointTarget(joints=q), span=_span(k))
        for k, q in ((2, home), (3, reach_out))
    ]
    found = check_collisions(_compile(_with(station, block), *moves))
    assert any("robot link_2 hits fixture 'base'" in d.message for d in found), found


# --------------------------------------------------------------------------------------------
# Shapes proven to touch everywhere (a tool bracket inside the wrist)


def _everything_checked(monkeypatch: pytest.MonkeyPatch) -> None:
    from olp.collision import scene as scene_module

    def unproven(self: object, a: object, b: object) -> list[tuple[int, int]]:
        return [(ga, gb) for ga in a.geometries for gb in b.geometries]  # type: ignore[attr-defined]

    monkeypatch.setattr(scene_module._Proofs, "unproven", unproven)


def _geometry_pairs(scene: Scene) -> dict[tuple[int, int], tuple[str, str]]:
    out = {}
    for pair in scene.pairs:
        for k in pair.geometry_pairs:
            cp = scene.geometry.collisionPairs[k]
            out[(cp.first, cp.second)] = scene.name_of(pair)
    return out


def test_the_spindle_bracket_is_proven_inside_the_wrist_and_the_spindle_still_checked(
    collision_cell: Station,
) -> None:
    shapes = collision_cell.tool_bodies["spindle"].shapes
    scene = build_scene(
        collision_cell.robot, Placed("spindle", "tool", np.eye(4), shapes), [], [], PairRules()
    )
    with_link_4 = [p for p in scene.pairs if scene.name_of(p) == ("robot link_4", "tool 'spindle'")]
    # bracket, motor housing, cutter: the housing and the cutter stay checked against link_4
    assert [len(p.geometry_pairs) for p in with_link_4] == [2]


@pytest.mark.parametrize("name", _library())
def test_shapes_proven_in_contact_overlap_in_every_position(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Soundness of the fixed-point rule: a tool of random boxes about the flange on every
    library robot (its own pairs undeclared); every shape pair the rule leaves unchecked
    overlaps at random configurations by at least the proven depth."""
    rng = np.random.default_rng(3)
    robot = dataclasses.replace(_library_robot(name), allowed_pairs=())
    boxes = tuple(
        Shape("box", transl(*rng.uniform(-0.12, 0.12, 3)) @ rotz(rng.uniform(0, 3)), (0.06,) * 3)
        for _ in range(6)
    )
    tool = Placed("t", "tool", np.eye(4), boxes)
    proven = _geometry_pairs(build_scene(robot, tool, [], [], PairRules()))
    _everything_checked(monkeypatch)
    full = build_scene(robot, tool, [], [], PairRules())
    dropped = {k: v for k, v in _geometry_pairs(full).items() if k not in proven}
    assert dropped  # a spherical wrist's pairs, or the UR's link_2 and base (axes 1 and 2 meet)
    import coal

    samples = rng.uniform(robot.limits.lower, robot.limits.upper, (200, robot.dof))
    for q in samples:
        full.place(robot.kinematics.chain_joints(q))
        for a, b in dropped:
            placement = [full._gdata.oMg[g] for g in (a, b)]
            shape = [full.geometry.geometryObjects[g].geometry for g in (a, b)]
            d = coal.distance(
                shape[0],
                coal.Transform3s(placement[0].rotation, placement[0].translation),
                shape[1],
                coal.Transform3s(placement[1].rotation, placement[1].translation),
                coal.DistanceRequest(),
                coal.DistanceResult(),
            )
            assert d < 0, (dropped[(a, b)], q)


def test_pairs_whose_axes_do_not_meet_are_not_proven(cell: Station) -> None:
    """The KR 6's link_2 and link_4 overlap by construction, but axes 3 and 4 do not meet (a2):
    no fixed point, so only the library's declaration leaves them unchecked."""
    robot = dataclasses.replace(cell.robot, allowed_pairs=())
    scene = build_scene(robot, None, [], [], PairRules())
    names = {scene.name_of(p) for p in scene.pairs}
    assert ("robot link_2", "robot link_4") in names
    assert ("robot link_4", "robot link_6") not in names  # axes 5 and 6 meet at the wrist centre


# --------------------------------------------------------------------------------------------
# Shapes proven to keep one distance (the UR5e's link_4 and link_6)


def _constant_shape_pairs(
    robot: Robot, tool: Placed | None, objects: list[Placed], monkeypatch: pytest.MonkeyPatch
) -> tuple[Scene, dict[tuple[int, int], float]]:
    """A scene in which every candidate shape pair is checked, and the proven constant distance
    (m) of each geometry pair (first, second) the proof gives one."""
    from olp.collision import scene as scene_module

    with monkeypatch.context() as patch:
        patch.setattr(
            scene_module._Proofs, "split_constant", lambda self, a, b, shapes: (list(shapes), [])
        )
        full = build_scene(robot, tool, [], objects, PairRules())
    proofs = scene_module._Proofs(full)
    owner = {g: body for body in full.bodies for g in body.geometries}
    proven = {}
    for pair in full.pairs:
        for k in pair.geometry_pairs:
            cp = full.geometry.collisionPairs[k]
            ga, gb = cp.first, cp.second
            _, distances = proofs.split_constant(owner[ga], owner[gb], [(ga, gb)])
            if distances:
                proven[(ga, gb)] = distances[0]
    return full, proven


def _shape_distance(scene: Scene, a: int, b: int) -> float:
    import coal

    placement = [scene._gdata.oMg[g] for g in (a, b)]
    shape = [scene.geometry.geometryObjects[g].geometry for g in (a, b)]
    return float(
        coal.distance(
            shape[0],
            coal.Transform3s(placement[0].rotation, placement[0].translation),
            shape[1],
            coal.Transform3s(placement[1].rotation, placement[1].translation),
            coal.DistanceRequest(),
            coal.DistanceResult(),
        )
    )


def _wrist_point(robot: Robot) -> np.ndarray:
    """The origin of link_6's frame (on axes 5 and 6) in the flange frame, m (3,)."""
    link_6 = robot.link_poses(robot.home)["link_6"]
    return np.linalg.solve(robot.flange_poses(robot.home), link_6[:, 3])[:3]


def _axis_shapes(robot: Robot, rng: np.random.Generator) -> tuple[Placed, list[Placed]]:
    """A tool of shapes on the flange axis (a cylinder, a capsule, a ball) and off it (a box, an
    off-axis ball), and fixtures on axis 1 (a pedestal ring below the base, a ball overhead)
    and off it (a box), for the proof to accept and to refuse."""
    on_flange = (
        Shape("cylinder", transl(0, 0, rng.uniform(0.05, 0.15)), (0.03, 0.1)),
        Shape("capsule", transl(0, 0, rng.uniform(0.15, 0.25)), (0.02, 0.08)),
        Shape("sphere", transl(0, 0, rng.uniform(0.25, 0.35)), (0.04,)),
        Shape("box", transl(*rng.uniform(-0.1, 0.1, 3)), (0.05, 0.04, 0.03)),
        Shape("sphere", transl(rng.uniform(0.05, 0.1), 0, 0.1), (0.02,)),
        # across the flange axis, centred where it meets axis 5: on the UR arms its slab along
        # axis 5 touches the axis, but joint 6 turns it out of that slab
        Shape("capsule", transl(*_wrist_point(robot)) @ roty(np.pi / 2), (0.02, 0.08)),
    )
    base = robot.base
    world = [
        Placed(
            "pedestal", "fixture", base @ transl(0, 0, -0.3), (Shape("cylinder", size=(0.4, 0.5)),)
        ),
        Placed("lamp", "fixture", base @ transl(0, 0, 2.5), (Shape("sphere", size=(0.1,)),)),
        Placed("crate", "fixture", base @ transl(0.9, 0.3, 0.2), (Shape("box", size=(0.2,) * 3),)),
    ]
    return Placed("t", "tool", np.eye(4), on_flange), world


@pytest.mark.parametrize("name", _library())
def test_shapes_proven_at_a_constant_distance_keep_it_in_every_position(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Soundness of the constant-distance proof on every library robot (its own pairs
    undeclared) with a tool and fixtures on and off the joint axes: every shape pair it gives
    a distance keeps that distance at 300 random configurations of the whole joint range."""
    rng = np.random.default_rng(4)
    robot = dataclasses.replace(_library_robot(name), allowed_pairs=())
    tool, world = _axis_shapes(robot, rng)
    full, proven = _constant_shape_pairs(robot, tool, world, monkeypatch)
    # link_1 against the pedestal and the lamp (on axis 1), link_3 and link_5 (UR: and more)
    assert len(proven) >= 3, proven
    lo, hi = robot.limits.lower, robot.limits.upper
    for q in rng.uniform(lo, hi, (300, robot.dof)):
        full.place(robot.kinematics.chain_joints(q))
        for (a, b), distance in proven.items():
            assert abs(_shape_distance(full, a, b) - distance) < 1e-7, (name, a, b, q)


def test_the_ur5e_wrist_links_stay_14_7_mm_apart() -> None:
    """The two slab proofs of the UR5e, from its DH table: link_4's capsule (r 45 mm) and
    link_6's (r 40 mm) lie across axis 5, d5 = 99.7 mm apart along it, each touching it; link_3
    (r 50 mm) and link_5 (r 45 mm) lie across axis 4, d4 = 133.3 mm apart. Its link_1 stands on
    the bench, 0 mm away in every position."""
    station = load_station(REPO / "stations" / "ur5e_screw_cell.yaml")
    objects = [Placed(o.name, o.kind, o.pose, o.shapes) for o in station.objects]
    scene = build_scene(station.robot, None, [], objects, PairRules())
    constant = {scene.name_of(p): (p.distance * 1000, p.whole) for p in scene.constant}
    assert constant[("robot link_4", "robot link_6")] == pytest.approx((99.7 - 45 - 40, True))
    assert constant[("robot link_3", "robot link_5")] == pytest.approx((133.3 - 50 - 45, True))
    assert constant[("robot link_1", "fixture 'bench_top'")] == pytest.approx((0.0, True))
    checked = {scene.name_of(p) for p in scene.pairs}
    assert not checked & constant.keys()
    assert ("robot link_2", "fixture 'bench_top'") in checked


def test_a_ball_off_the_turning_axis_is_not_proven() -> None:
    """A ball on the UR5e's flange axis, 150 mm out: joint 6 turns it in place, but joint 5
    swings it past link_4, although its slab along axis 5 lies clear of link_4's. It does not
    touch axis 5, so the proof refuses, and its distance does vary."""
    robot = dataclasses.replace(_library_robot("ur/ur5e"), allowed_pairs=())
    ball = Placed("ball", "tool", np.eye(4), (Shape("sphere", transl(0, 0, 0.15), (0.02,)),))
    scene = build_scene(robot, ball, [], [], PairRules())
    assert not [p for p in scene.constant if "tool 'ball'" in scene.name_of(p)]
    pair = next(p for p in scene.pairs if scene.name_of(p) == ("robot link_4", "tool 'ball'"))
    distances = []
    for a5 in np.radians([-90, 0, 90, 180]):
        scene.place(robot.kinematics.chain_joints(robot.home + np.array([0, 0, 0, 0, a5, 0])))
        distances.append(scene.distance(pair))
    assert max(distances) - min(distances) > 0.05, distances


def _ur_screw_program(tmp_path: Path) -> Path:
    """From the UR5e's home with bare flange, then with the screwdriver (two scenes)."""
    program = tmp_path / "screw.src"
    program.write_text(
        "DEF Screw( )\n"
        "$TOOL = $NULLFRAME\n"
        "$BASE = $NULLFRAME\n"
        "PTP {A1 0,A2 -90,A3 90,A4 -90,A5 -90,A6 0}\n"
        "$TOOL = TOOL_DATA[1]\n"
        "PTP {A1 20,A2 -80,A3 100,A4 -110,A5 -90,A6 0}\n"
        "PTP {A1 -20,A2 -100,A3 80,A4 -70,A5 -90,A6 45}\n"
        "PTP {A1 0,A2 -90,A3 90,A4 -90,A5 -90,A6 0}\n"
        "END\n"
    )
    return program


@pytest.mark.parametrize(
    ("options", "warned"),
    [
        ([], []),
        (
            ["--clearance", "20"],
            [
                "clearance of 20.0 mm cannot be met: robot link_1 and fixture "
                "'bench_top' are 0.0 mm apart"
            ],
        ),
        (["--self-clearance", "10"], []),
        (
            ["--self-clearance", "20"],
            [
                "self-clearance of 20.0 mm cannot be met: robot link_4 and "
                "robot link_6 are 14.7 mm apart"
            ],
        ),
    ],
)
def test_a_ur5e_program_from_home_builds_with_a_clearance(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], options: list[str], warned: list[str]
) -> None:
    """Neither clearance can fail a program for the 14.7 mm between the UR5e's wrist links or
    for link_1 standing on the bench; where the clearance asked for exceeds such a distance,
    one warning per build says so."""
    from olp.cli import main

    station = str(REPO / "stations" / "ur5e_screw_cell.yaml")
    out = tmp_path / "out"
    program = str(_ur_screw_program(tmp_path))
    assert main(["build", station, program, "--post", "ur", "-o", str(out), *options]) == 0
    assert (out / "Screw.script").is_file()
    lines = [line for line in capsys.readouterr().err.splitlines() if "warning[" in line]
    assert len(lines) == len(warned)
    for line, text in zip(lines, warned, strict=True):
        assert "warning[clearance_unmet]" in line and text in line


# --------------------------------------------------------------------------------------------
# What the station and the caller allow


def _station_file(tmp_path: Path, extra: str) -> Path:
    path = tmp_path / "cell.yaml"
    path.write_text(f"name: cell\nrobot: {{model: kuka/kr6_r900_sixx}}\n{extra}")
    return path


def _bump(station: Station) -> CompiledProgram:
    moves = [
        ir.JointMove(target=ir.JointTarget(joints=q), span=_span(k + 2)) for k, q in enumerate(BUMP)
    ]
    return _compile(station, *moves)


def test_a_station_may_allow_a_pair_to_touch(tmp_path: Path) -> None:
    plain = load_station(_station_file(tmp_path, ""))
    assert _found(check_collisions(_bump(plain))) == [("self_collision", 1, 3)]
    allowed = load_station(_station_file(tmp_path, "allowed_pairs: [[link_2, base]]\n"))
    assert allowed.allowed_pairs == (("link_2", "base"),)
    for clearance in (0.0, 0.01):
        options = CollisionOptions(clearance_m=clearance, self_clearance_m=clearance)
        assert check_collisions(_bump(allowed), options) == []


@pytest.mark.parametrize(
    ("extra", "line", "message"),
    [
        ("allowed_pairs: [[link_2, bsae]]\n", 3, "unknown body 'bsae' (known: base, link_1"),
        ("allowed_pairs:\n  - [link_2]\n", 4, "expected two different names [A, B]"),
        ("allowed_pairs:\n  - [link_2, link_2]\n", 4, "expected two different names [A, B]"),
        ("allowed_pairs:\n  - [[link_2], base]\n", 4, "unknown body '[link_2]'"),
        ("allowed_pairs: link_2\n", 3, "expected a list"),
    ],
)
def test_a_station_pair_must_name_two_bodies(
    tmp_path: Path, extra: str, line: int, message: str
) -> None:
    from olp.errors import StationError

    with pytest.raises(StationError) as caught:
        load_station(_station_file(tmp_path, extra))
    assert caught.value.span is not None and caught.value.span.line == line
    assert message in caught.value.message


def test_a_robot_file_pair_must_name_its_links(tmp_path: Path) -> None:
    from olp.errors import StationError
    from olp.station.loader import load_robot_model

    text = (REPO / "stations" / "robots" / "kuka" / "kr6_r900_sixx.yaml").read_text()
    robot = tmp_path / "my_kr6.yaml"
    robot.write_text(text.replace("  - [link_4, link_6]", "  - [link_4, flange]"))
    with pytest.raises(StationError) as caught:
        load_robot_model(robot)
    assert "unknown body 'flange'" in caught.value.message
    assert caught.value.span is not None
    assert robot.read_text().splitlines()[caught.value.span.line - 1] == "  - [link_4, flange]"


def test_home_contacts_is_the_callers_choice_and_ignores_the_clearance(cell: Station) -> None:
    """Without the library's declarations the KR 6's link_2 and link_4 capsules collide on every
    move; allowing the pairs that overlap at home drops exactly those, and link_2 against the
    base (21.6 mm apart at home) stays checked at any clearance."""
    bare = dataclasses.replace(cell, robot=dataclasses.replace(cell.robot, allowed_pairs=()))
    compiled = _bump(bare)
    pairs = {pair for _, pair, _ in _hits(check_collisions(compiled))}
    assert pairs == {("robot link_2", "robot link_4"), ("robot link_2", "robot base")}
    for clearance in (0.0, 0.03, 0.1):
        chosen = CollisionOptions(
            clearance_m=clearance, self_clearance_m=clearance, home_contacts=True
        )
        hits = _hits(check_collisions(compiled, chosen))
        assert {pair for _, pair, _ in hits} == {("robot link_2", "robot base")}
        assert ("self_collision", ("robot link_2", "robot base"), 1) in hits


# --------------------------------------------------------------------------------------------
# Absurd but valid input: a diagnostic or a usage error, never a traceback or a silent pass


@pytest.mark.parametrize(
    "options",
    [
        {"clearance_m": -0.001},
        {"clearance_m": float("nan")},
        {"clearance_m": float("inf")},
        {"self_clearance_m": -0.001},
        {"self_clearance_m": float("nan")},
        {"self_clearance_m": float("inf")},
        {"tolerance_m": 0.0},
        {"tolerance_m": -1e-4},
        {"tolerance_m": float("nan")},
        {"tolerance_m": float("inf")},
        {"tolerance_m": 1e-9},
        {"tolerance_m": 0.1},
        {"mode": "fast"},
    ],
)
def test_bad_collision_options_are_usage_errors(options: dict[str, object]) -> None:
    from olp.errors import UsageError

    with pytest.raises(UsageError, match=r"collision (self-clearance|clearance|tolerance|mode)"):
        CollisionOptions(**options)  # type: ignore[arg-type]


def test_an_infinite_clearance_on_the_command_line_is_a_usage_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from olp.cli import main

    program = tmp_path / "bump.src"
    program.write_text(BUMP_SRC)
    station = str(REPO / "stations" / "kr6_milling_cell.yaml")
    assert main(["check", station, str(program), "--clearance", "1e400"]) == 2
    assert "clearance must be a finite distance" in capsys.readouterr().err


def test_a_huge_clearance_reports_every_checked_pair_once(cell: Station) -> None:
    from olp.passes.collide import check_collisions_with_stats

    huge = CollisionOptions(clearance_m=1e6, self_clearance_m=1e6)
    found, stats = check_collisions_with_stats(_bump(cell), huge)
    errors = [d for d in found if d.severity == "error"]
    assert len(errors) == stats.pairs > 10
    assert all("(closer than 1000000000.0 mm)" in d.message for d in errors)
    # link_5 is a ball about the wrist centre, on axes 4 and 5: always 310 mm from link_3
    assert _unmet(found) == {("robot link_3", "robot link_5"): (310.0, 1e9)}


def test_zero_length_motions_are_checked_like_any_other(cell: Station) -> None:
    home = cell.robot.home
    assert check_collisions(_compile(cell, _ptp(home, 2), _ptp(home, 3), _ptp(home, 4))) == []
    folded = np.radians([0, -10, 156, 0, 0, 0])  # the wrist on the base
    found = check_collisions(_compile(cell, _ptp(folded, 2), _ptp(folded, 3), _ptp(folded, 4)))
    assert {d.message.split(": ", 1)[0] for d in found} == {"moves 0-2"}


@pytest.mark.parametrize(
    ("pose", "shape"),
    [
        (transl(1e300, 0, 0), Shape("box", np.eye(4), (0.1, 0.1, 0.1))),
        (transl(1e6, 0, 0), Shape("box", np.eye(4), (0.1, 0.1, 0.1))),
        (transl(0, 0, -2.5e4), Shape("box", np.eye(4), (5e4, 5e4, 5e4))),
        (transl(0, 0, -5e19), Shape("box", np.eye(4), (1e20, 1e20, 1e20))),
        (transl(1e300, 0, 0), Shape("sphere", np.eye(4), (1e300,))),
    ],
)
def test_a_body_beyond_exact_distances_is_an_error(
    cell: Station, pose: np.ndarray, shape: Shape
) -> None:
    """Bodies beyond 1 km of the robot, where coal's distances lose their accuracy (a box of
    50 km side 10 mm below a link is reported touching), cannot be checked: an error at the
    first motion, not a pass (and no overflow warning either)."""
    station = _with(cell, StationObject("far", "fixture", pose, (shape,)))
    found = check_collisions(_compile(station, _ptp(SWEEP_FROM, 2), _ptp(SWEEP_TO, 3)))
    assert _found(found) == [("collision_unchecked", 0, 2)]
    assert found[0].severity == "error"
    assert found[0].message.startswith("collisions with fixture 'far' cannot be checked")


def test_a_distance_that_is_not_a_number_is_an_error(
    cell: Station, monkeypatch: pytest.MonkeyPatch
) -> None:
    compiled = _compile(cell, _ptp(SWEEP_FROM, 2), _ptp(SWEEP_TO, 3))
    monkeypatch.setattr(Scene, "distance", lambda self, pair: float("nan"))
    for mode in ("advance", "samples"):
        found = check_collisions(compiled, CollisionOptions(mode=mode))  # type: ignore[arg-type]
        assert found and {d.kind for d in found} == {"collision_unchecked"}
        assert all(d.severity == "error" and "not a number" in d.message for d in found)


class _Constant:
    """A scene whose one pair is at the distances given, in turn (the last one repeats)."""

    def __init__(self, *distances: float) -> None:
        self.distances = list(distances)

    def place(self, chain: np.ndarray) -> None:
        pass

    def distance(self, pair: object) -> float:
        return self.distances.pop(0) if len(self.distances) > 1 else self.distances[0]


def test_the_advancement_gives_up_instead_of_running_for_ever(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A pair that grazes contact along a path whose displacement bound is huge (1e20 m): each
    step is half a tolerance, so proving the path would take 1e24 evaluations; and once the
    bound is that large a step no longer moves the frontier at all."""
    from olp.collision import advance as advance_module
    from olp.collision.advance import Unresolved

    run = path_run([np.array([[0.0], [1.0], [2.0]])], lambda q: q)
    cum = np.array([0.0, 1e20, 2e20])
    lower, upper = -1e-4, -5e-5
    monkeypatch.setattr(advance_module, "MAX_EVALUATIONS", 1000)
    with pytest.raises(Unresolved, match="no proof after 1000 distance evaluations"):
        advance(_Constant(0.0), None, run, lower, upper, cum)  # type: ignore[arg-type]
    with pytest.raises(Unresolved, match="below floating-point resolution") as caught:
        advance(_Constant(1.5e20, 0.0), None, run, lower, upper, cum)  # type: ignore[arg-type]
    assert caught.value.where.motion == 0 and 0.5 < caught.value.where.fraction < 1.0


# --------------------------------------------------------------------------------------------
# Dense toolpaths


def _as_path(moves: list[ir.LinearMove]) -> ir.LinearPath:
    """Consecutive linear moves (one tool, one frame) as one dense toolpath node."""
    return ir.LinearPath(
        poses=np.stack([m.target.pose for m in moves if isinstance(m.target, ir.CartesianTarget)]),
        speeds=np.array([m.speed.linear for m in moves]),
        zones=np.array([m.zone.radius for m in moves]),
        lines=np.array([m.span.line for m in moves]),
        tool=moves[0].tool,
        source="t.src",
    )


@pytest.mark.parametrize(
    "attachments",
    [
        (),  # the block joins its run whole
        (Attachment("puck", grasp=1),),  # gripped at the block's first row: still whole
        (Attachment("puck", grasp=1, release=3),),  # let go inside the block: row by row
    ],
)
def test_a_dense_toolpath_is_checked_as_its_moves_are(
    pick_cell: tuple[Station, np.ndarray], attachments: tuple[Attachment, ...]
) -> None:
    station, grip = pick_cell
    at = station.robot.flange_poses(grip) @ ROD.pose
    moves = [
        _lin(transl(0, 0, 0.03) @ at, 3),  # lift 30 mm
        _lin(transl(0, 0.2, 0.03) @ at, 4),  # across the wall
        _lin(transl(0, 0.2, 0.06) @ at, 6),
        _lin(transl(0, 0.2, -0.05) @ at, 7),  # down through where the puck was let go
        _lin(transl(0, 0.0, -0.05) @ at, 8),  # back through the tray
    ]
    options = CollisionOptions(attachments=attachments, tool_touches_parts=False)
    per_move = check_collisions(_compile(station, _ptp(grip, 1), *moves), options)
    compiled = _compile(station, _ptp(grip, 1), _as_path(moves))
    assert len(compiled.steps.blocks) == 2  # type: ignore[attr-defined]
    dense = check_collisions(compiled, options)
    assert per_move, "the program must collide somewhere for this test to mean anything"
    assert [(d.kind, d.index, d.span, d.message) for d in dense] == [
        (d.kind, d.index, d.span, d.message) for d in per_move
    ]
