"""Station YAML: SI inside, every mistake located by file, line, column and key; tools with
geometry and mass, chained frames, parts and fixtures, inline robots."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from olp.errors import StationError
from olp.geometry import rotx
from olp.kinematics.models import OPWKinematics
from olp.station.loader import load_library_robot, load_station, robot_library

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "kr6_milling_cell.yaml"
SAMPLE_CELLS = sorted((REPO / "stations").glob("*.yaml"))
ROBOT = "robot:\n  model: kuka/kr6_r900_sixx\n"


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "cell.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_bundled_cell_loads_in_si_units() -> None:
    station = load_station(CELL)
    robot = station.robot
    assert robot.vendor == "kuka"
    assert isinstance(robot.kinematics, OPWKinematics)
    assert robot.kinematics.params.c2 == pytest.approx(0.455)
    assert np.degrees(robot.limits.upper[5]) == pytest.approx(350)
    assert np.degrees(robot.limits.velocity[0]) == pytest.approx(360)
    assert np.allclose(robot.base[:3, 3], [0.0, -0.4, 0.0])
    spindle = station.tools["spindle"]
    assert spindle.pose is not None and spindle.pose[0, 3] == pytest.approx(0.466604)
    # zyx [0, 90, 0] turns the tool's Z axis onto the flange's X axis (out of the flange)
    assert np.allclose(spindle.pose[:3, :3] @ [0, 0, 1], [1, 0, 0], atol=1e-12)
    assert "kuka/kr6_r900_sixx" in robot_library()


@pytest.mark.parametrize("path", SAMPLE_CELLS, ids=lambda p: p.stem)
def test_sample_cells_reach_their_parts(path: Path) -> None:
    """Every sample cell loads, and its robot reaches a tool-down pose 50 mm above each part
    (so the robots are placed sensibly, not just parsed)."""
    station = load_station(path)
    robot = station.robot
    tool = next(iter(station.tools.values())).pose
    assert tool is not None
    for obj in station.objects:
        if obj.kind != "part":
            continue
        target = np.eye(4)
        target[:3, :3] = rotx(math.pi)[:3, :3]
        target[:3, 3] = obj.pose[:3, 3] + [0.0, 0.0, 0.05]
        flange = target @ np.linalg.inv(tool)
        solutions = robot.solve(flange[None])[0]
        inside = ~np.isnan(solutions).any(axis=-1) & ~robot.limits.violations(solutions).any(-1)
        assert inside.any(), f"{obj.name} is out of reach"


def test_sample_cells_for_each_brand_exist() -> None:
    vendors = {load_station(p).robot.vendor for p in SAMPLE_CELLS}
    assert vendors >= {"kuka", "abb", "fanuc", "ur"}


# --------------------------------------------------------------------------------------------
# Mistakes


@pytest.mark.parametrize(
    ("text", "line", "needle"),
    [
        ("name: x\nrobot:\n  model: kuka/nope\n", 3, "unknown robot model 'kuka/nope'"),
        ("name: x\nrobot:\n  model: kuka/kr6_r900_sixx\n  bsae: {}\n", 4, "unknown key 'bsae'"),
        ("name: x\nrobot:\n  model: kuka/kr6_r900_sixx\n  base: {xyz: [1, 2]}\n", 4, "3 numbers"),
        (
            "name: x\nrobot:\n  model: kuka/kr6_r900_sixx\n"
            "tools:\n  - {name: t, tcp: {xyz: [1, 2, a]}}\n",
            5,
            "expected a number (a length in mm), got text 'a'",
        ),
        ("name: x\nrobot: [1, 2\n", 3, "invalid YAML"),
        ("name: x\n", 1, "missing required key 'robot'"),
        (
            "name: x\nrobot:\n  model: kuka/kr6_r900_sixx\n  home_deg: [0, -90, 90, 0, 0, 400]\n",
            4,
            "outside the joint limits",
        ),
        (
            "robot: {model: kuka/kr6_r900_sixx}\nframes:\n  - {name: a}\n  - {name: a}\n",
            4,
            "duplicate name 'a'",
        ),
        (ROBOT + "  vendor: kuka\n", 3, "'vendor' belongs to an inline robot"),
        (ROBOT + "tools:\n  - {name: t, mass_kg: -1}\n", 4, "expected a positive number"),
        (ROBOT + "tools:\n  - {name: t, geometry: [{box: {size: [1, 2]}}]}\n", 4, "3 numbers"),
        (
            ROBOT + "tools:\n  - name: t\n    geometry:\n      - {sphere: {radius: 5}, box: {}}\n",
            6,
            "exactly one of",
        ),
        (
            ROBOT + "tools:\n  - name: t\n    geometry:\n      - {cylinder: {radius: 5}}\n",
            6,
            "missing required key 'length'",
        ),
        (
            ROBOT + "tools:\n  - name: t\n    geometry:\n      - {sphere: {radius: 0}}\n",
            6,
            "expected a positive number",
        ),
        (
            ROBOT + "parts:\n  - name: p\n    geometry:\n      - {mesh: {file: nope.stl}}\n",
            6,
            "no such file: nope.stl",
        ),
        (
            ROBOT
            + "parts:\n  - name: p\n    geometry:\n      - {link: link_1, sphere: {radius: 1}}\n",
            6,
            "'link' is only for a robot's collision shapes",
        ),
        (ROBOT + "parts:\n  - {name: p, geometry: []}\n", 4, "at least one shape"),
        (
            ROBOT
            + "parts:\n  - name: p\n    frame: nowhere\n    geometry: [{sphere: {radius: 1}}]\n",
            5,
            "unknown frame 'nowhere'",
        ),
        (
            ROBOT + "parts:\n  - {name: p, geometry: [{sphere: {radius: 1}}]}\n"
            "fixtures:\n  - {name: p, geometry: [{sphere: {radius: 1}}]}\n",
            6,
            "duplicate part or fixture name 'p'",
        ),
        (ROBOT + "frames:\n  - {name: a, parent: b}\n", 4, "unknown parent frame 'b'"),
        (
            ROBOT + "frames:\n  - {name: a, parent: b}\n  - {name: b, parent: a}\n",
            4,
            "frame parents form a cycle: a -> b -> a",
        ),
    ],
)
def test_mistakes_are_located(tmp_path: Path, text: str, line: int, needle: str) -> None:
    path = _write(tmp_path, text)
    with pytest.raises(StationError) as info:
        load_station(path)
    err = info.value
    assert needle in err.message
    assert err.span is not None and err.span.file == str(path) and err.span.line == line
    assert f"{path}:{line}:" in err.format()


INLINE = """robot:
  name: my arm
  vendor: {vendor}
  kinematics: {kinematics}
  limits:
    position_deg: [[-170, 170], [-190, 45], [-120, 156], [-185, 185], [-120, 120], [-350, 350]]
    velocity_deg_s: [360, 300, 360, 381, 388, 615]
    acceleration_deg_s2: [900, 750, 900, 952.5, 970, 1537.5]
    jerk_deg_s3: [9000, 7500, 9000, 9525, 9700, 15375]
  home_deg: [0, -90, 90, 0, 0, 0]
"""
KR6_OPW = (
    "{type: opw, a1: 25, a2: -35, b: 0, c1: 400, c2: 455, c3: 420, c4: 80, "
    "offsets_deg: [0, -90, 0, 0, 0, 0], signs: [-1, 1, 1, -1, 1, -1]}"
)


def test_inline_opw_robot_equals_the_library_model(tmp_path: Path) -> None:
    path = _write(tmp_path, INLINE.format(vendor="kuka", kinematics=KR6_OPW))
    inline = load_station(path).robot
    library = load_library_robot("kuka/kr6_r900_sixx").place()
    q = np.random.default_rng(1).uniform(-2, 2, (50, 6))
    assert np.allclose(inline.flange_poses(q), library.flange_poses(q), atol=1e-15)
    assert inline.name == "my arm"


@pytest.mark.parametrize(
    ("kinematics", "line", "needle"),
    [
        ("{type: opw, a1: 25}", 4, "missing required key 'a2'"),
        ("{type: scara}", 4, "unsupported kinematics type 'scara'"),
        (KR6_OPW[:-1] + ", d4: 3}", 4, "'d4' does not belong to kinematics of type 'opw'"),
        (
            KR6_OPW[:-1] + ", coupling: [{joint: 3, from: 3}]}",
            4,
            "joints must be two different numbers in 1..6",
        ),
        ("{type: ur, d1: 1, a2: 0, a3: 1, d4: 1, d5: 1, d6: 1}", 4, "must be non-zero"),
    ],
)
def test_inline_kinematics_mistakes(
    tmp_path: Path, kinematics: str, line: int, needle: str
) -> None:
    path = _write(tmp_path, INLINE.format(vendor="kuka", kinematics=kinematics))
    with pytest.raises(StationError) as info:
        load_station(path)
    assert needle in info.value.message
    assert info.value.span is not None and info.value.span.line == line


def test_inline_robot_needs_its_limits(tmp_path: Path) -> None:
    text = INLINE.format(vendor="kuka", kinematics=KR6_OPW).replace(
        "    jerk_deg_s3: [9000, 7500, 9000, 9525, 9700, 15375]\n", ""
    )
    with pytest.raises(StationError) as info:
        load_station(_write(tmp_path, text))
    assert "missing limits: jerk" in info.value.message
    assert info.value.span is not None and info.value.span.line == 5  # the limits key


def test_limits_can_be_overridden_per_station(tmp_path: Path) -> None:
    path = _write(tmp_path, ROBOT + "  limits:\n    velocity_deg_s: [10, 10, 10, 10, 10, 10]\n")
    robot = load_station(path).robot
    assert np.allclose(np.degrees(robot.limits.velocity), 10)
    assert np.degrees(robot.limits.upper[0]) == pytest.approx(170)


# --------------------------------------------------------------------------------------------
# Tools, frames, parts, fixtures


def test_tool_geometry_and_mass(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        ROBOT + "tools:\n"
        "  - name: gripper\n    number: 2\n    tcp: {xyz: [0, 0, 150]}\n    mass_kg: 2.5\n"
        "    geometry:\n"
        "      - {box: {size: [80, 60, 100]}, pose: {xyz: [0, 0, 50]}}\n"
        "      - {capsule: {from: [0, 0, 100], to: [0, 0, 150], radius: 10}}\n"
        "  - {name: bare}\n",
    )
    station = load_station(path)
    body = station.tool_bodies["gripper"]
    assert body.mass == 2.5 and station.tool_bodies["bare"].mass is None
    box, capsule = body.shapes
    assert box.kind == "box" and box.size == pytest.approx((0.08, 0.06, 0.1))
    assert box.contains([0.0, 0.0, 0.099]) and not box.contains([0.0, 0.0, 0.101])
    assert capsule.contains([0.0, 0.0, 0.159]) and not capsule.contains([0.0, 0.0, 0.161])
    assert capsule.contains([0.0095, 0.0, 0.12]) and not capsule.contains([0.0105, 0.0, 0.12])


def test_frames_chain_to_their_parents(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        ROBOT + "frames:\n"
        "  - {name: c, parent: b, pose: {xyz: [0, 10, 0]}}\n"
        "  - {name: a, pose: {xyz: [1000, 0, 0], zyx: [90, 0, 0]}}\n"
        "  - {name: b, parent: a, number: 3, pose: {xyz: [100, 0, 0]}}\n",
    )
    station = load_station(path)
    b, c = station.frames["b"].pose, station.frames["c"].pose
    assert b is not None and c is not None
    # a turns 90° about Z, so b's 100 mm along a's X go along world Y.
    assert np.allclose(b[:3, 3], [1.0, 0.1, 0.0], atol=1e-12)
    assert np.allclose(c[:3, 3], [0.99, 0.1, 0.0], atol=1e-12)
    assert station.frame_parents == {"c": "b", "a": "world", "b": "a"}
    assert station.frames["b"].number == 3


def test_parts_and_fixtures_are_placed_in_their_frames(tmp_path: Path) -> None:
    trimesh = pytest.importorskip("trimesh")
    trimesh.creation.box(extents=(100.0, 50.0, 20.0)).export(tmp_path / "block.stl")
    path = _write(
        tmp_path,
        ROBOT + "frames:\n  - {name: table, pose: {xyz: [500, 0, 300]}}\n"
        "parts:\n"
        "  - name: block\n    frame: table\n    pose: {xyz: [0, 0, 10]}\n"
        "    geometry: [{mesh: {file: block.stl}}]\n"
        "fixtures:\n"
        "  - name: post\n    geometry:\n"
        "      - {cylinder: {radius: 30, length: 300}, pose: {xyz: [500, 0, 150]}}\n",
    )
    station = load_station(path)
    block, post = station.objects
    assert (block.kind, block.frame, post.kind, post.frame) == ("part", "table", "fixture", "world")
    assert np.allclose(block.pose[:3, 3], [0.5, 0.0, 0.31], atol=1e-12)
    mesh = block.shapes[0].load_mesh()
    assert np.allclose(mesh.extents, [0.1, 0.05, 0.02])  # mm in the file, metres inside
    cylinder = post.shapes[0]
    assert cylinder.contains([0.5, 0.029, 0.299], post.pose)
    assert not cylinder.contains([0.5, 0.031, 0.15], post.pose)
    assert not cylinder.contains([0.5, 0.0, 0.301], post.pose)


@pytest.mark.parametrize("path", SAMPLE_CELLS, ids=lambda p: p.stem)
def test_resolve_runs_on_every_sample_cell(path: Path) -> None:
    """The Robot API resolve uses (solve, branch_of, flange_poses, limits, turn variants) works
    for every kinematics type: a joint move to a Cartesian target, then a short linear move
    that ends on the pose of known joints, in the same branch."""
    from olp import ir
    from olp.passes.resolve import resolve

    station = load_station(path)
    robot = station.robot
    span = ir.SourceSpan("t.src", 1, 1)
    start = robot.home + np.radians([10.0, 5.0, -5.0, 10.0, 20.0, 10.0])
    end = start + np.radians([3.0, 2.0, -2.0, 2.0, 2.0, 2.0])
    moves = [
        ir.JointMove(target=ir.CartesianTarget(pose=robot.flange_poses(start)), span=span),
        ir.LinearMove(target=ir.CartesianTarget(pose=robot.flange_poses(end)), span=span),
    ]
    compiled = resolve(ir.Program(name="t", instructions=moves), station)
    assert compiled.ok, compiled.diagnostics
    final = compiled.steps[1].joints
    assert final is not None
    assert np.allclose(robot.flange_poses(final), robot.flange_poses(end), atol=1e-9)
