"""Collide: each collision constructed on purpose, asserted by kind, instruction and source line;
the bound the advancement rests on, and the guarantee itself against dense sampling."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

from olp import ir
from olp.collision.advance import advance, path_run, sample_hits
from olp.collision.chord import chord_deviation
from olp.collision.scene import DisplacementBound, PairRules, Placed, Scene, build_scene
from olp.collision.shapes import reach
from olp.diagnostics import Diagnostic
from olp.geometry import pose_from, rotx, roty, rotz, transl
from olp.passes.collide import Attachment, CollisionOptions, check_collisions
from olp.passes.resolve import CompiledProgram, ResolveOptions, resolve
from olp.station.loader import load_station
from olp.station.model import Shape, Station, StationObject, ToolBody

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
    assert {d.kind for d in near} == {"collision"}
    assert all(
        d.message.startswith("moves ") and "tool 'spindle' hits fixture" in d.message for d in near
    )
    assert sum("clamp" in d.message for d in near) >= 4 * 3


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
    pattern = r"(?:moves \d+-\d+: )?(?:self-collision: )?(.+) hits (.+?) (?:at|\(first at) \d+%"
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
