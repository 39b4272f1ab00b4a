"""The RAPID post, pinned: table-driven (small IR programs -> expected module lines), predefined
and custom speed and zone data, tool and work object data, I/O by signal name, diagnostics,
confdata that selects the planned joints on random targets in every branch of every ABB and
KUKA robot, splitting into modules called by a main module, and golden files.

Every RAPID file these tests produce passes the independent ``rapidchecker`` (grammar,
indentation, upper-case keywords, whitespace): :func:`rapid` fails the test on any error.

Golden files: ``tests/golden/abb/``. After a reviewed change, regenerate them with
``OLP_UPDATE_GOLDEN=1 python -m pytest tests/posts/test_abb.py`` (the test then fails once, so
the variable can never pass CI by accident) and state the reason in the commit.
"""

from __future__ import annotations

import dataclasses
import math
import re
import shutil
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import olp
from olp import ir
from olp.compiled import CompiledProgram, Step
from olp.diagnostics import Diagnostic
from olp.frontends.bundled import KrlOptions
from olp.kinematics.base import turn_variants
from olp.kinematics.configuration import satisfies
from olp.posts import find_post
from olp.posts.abb import PREDEFINED_NAMES, speed_name, speeddata, zone_name, zonedata
from olp.posts.base import Post
from olp.station.loader import load_library_robot, robot_library
from olp.station.model import Robot, Station
from olp.vendors import abb, kuka

with warnings.catch_warnings():  # rapidchecker uses pyparsing names deprecated since
    warnings.simplefilter("ignore", DeprecationWarning)
    from rapidchecker.cli import check_file as _check_file

GoldenCheck = Callable[..., None]

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "abb_irb120_pick_cell.yaml"
KUKA_CELL = REPO / "stations" / "kr6_milling_cell.yaml"
PICK = Path(__file__).resolve().parent / "pick_irb120.src"
GOLDEN = REPO / "tests" / "golden" / "abb"


def render(compiled: CompiledProgram, post: Post, name: str | None = None) -> dict[str, str]:
    """The post's files (its transforms applied)."""
    return post.render(compiled, name)


def post_diagnostics(compiled: CompiledProgram, post: Post) -> list[Diagnostic]:
    """What the post reports: its transforms' diagnostics, then its checks."""
    prepared, found = post.prepare(compiled)
    return found + post.check(prepared)


def check_file(text: str) -> list[Any]:
    """rapidchecker's errors for a module's text (its deprecation warnings silenced)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        return list(_check_file(text))


def rapid(files: dict[str, str]) -> dict[str, str]:
    """``files`` after checking every ``.mod`` with rapidchecker (any error fails the test)."""
    assert files
    for name, text in files.items():
        assert name.endswith(".mod") and text.endswith("ENDMODULE\r\n")
        errors = [str(e) for e in check_file(text.replace("\r\n", "\n"))]
        assert errors == [], f"rapidchecker on {name}: {errors}"
    return files


def test_rapidchecker_finds_errors() -> None:
    """The checker is not a rubber stamp: a missing comma and a bad indentation are errors."""
    good = "MODULE A\n  PROC main()\n    MoveL p1, v100, fine, tool0;\n  ENDPROC\nENDMODULE\n"
    assert check_file(good) == []
    assert check_file(good.replace("fine, tool0", "fine tool0"))
    assert check_file(good.replace("    MoveL", "   MoveL"))


@pytest.fixture(scope="module")
def station() -> Station:
    return olp.load_station(CELL)


def _post(**options: Any) -> Post:
    return find_post("abb", options=options)


def _compile(station: Station, instructions: Sequence[ir.Instruction]) -> CompiledProgram:
    compiled = olp.compile(ir.Program(name="Row", instructions=tuple(instructions)), station)
    assert compiled.ok, [d.format() for d in compiled.diagnostics]
    return compiled


def _module(compiled: CompiledProgram, post: Post | None = None) -> list[str]:
    files = rapid(render(compiled, post or _post()))
    return files["Row.mod"].split("\r\n")


def _sections(lines: list[str]) -> tuple[list[str], list[str]]:
    """(declarations, procedure body) of a one-procedure module."""
    start = next(i for i, line in enumerate(lines) if line.startswith("  PROC "))
    end = lines.index("  ENDPROC")
    return [line.strip() for line in lines[2 : start - 1]], [
        line.strip() for line in lines[start + 1 : end]
    ]


# --------------------------------------------------------------------------------------------
# Table: IR -> lines

SUCTION = ir.Tool(name="suction")
TRAY = ir.Frame(name="tray")
HOME = np.radians([0.0, 0.0, 0.0, 0.0, 30.0, 0.0])
TOOLDATA = (
    "PERS tooldata suction := [TRUE,[[0.000,0.000,120.000],"
    "[1.000000000,0.000000000,0.000000000,0.000000000]],[0.6,[0,0,0.001],[1,0,0,0],0,0,0]];"
)
WOBJ = (
    'PERS wobjdata tray := [FALSE,TRUE,"",[[300.000,200.000,0.000],'
    "[0.707106781,0.000000000,0.000000000,0.707106781]],[[0,0,0],[1,0,0,0]]];"
)
EXTAX = "[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]"
CONF = r"\[-?\d+,-?\d+,-?\d+,[0-7]\]"
DOWN = "[0.000000000,1.000000000,0.000000000,0.000000000]"
JHOME = f"[[0.00000,0.00000,0.00000,0.00000,30.00000,0.00000],{EXTAX}]"


def _down(x: float, y: float, z: float) -> np.ndarray:
    return kuka.frame_to_pose([x, y, z, 0.0, 0.0, 180.0])


def _home(**kw: Any) -> ir.JointMove:
    kw = {"tool": SUCTION, "frame": TRAY, "speed": ir.Speed(linear=0.5), **kw}
    return ir.JointMove(target=ir.JointTarget(joints=HOME), **kw)


def _to(x: float, y: float, z: float, move: type = ir.LinearMove, **kw: Any) -> Any:
    kw = {"tool": SUCTION, "frame": TRAY, **kw}
    return move(target=ir.CartesianTarget(pose=_down(x, y, z)), **kw)


def _robtarget(name: str, xyz: str) -> str:
    return f"LOCAL CONST robtarget {name} := [[{xyz}],{DOWN},{CONF},{EXTAX}];"


ROWS: dict[str, tuple[list[ir.Instruction], list[str], list[str]]] = {
    "joint target: MoveAbsJ with a jointtarget": (
        [_home(speed=ir.Speed(linear=1.0))],
        [TOOLDATA, WOBJ, f"LOCAL CONST jointtarget p1 := {JHOME};"],
        ["ConfJ \\On;", "ConfL \\On;", "MoveAbsJ p1\\NoEOffs, v1000, fine, suction;"],
    ),
    "Cartesian targets: MoveJ and MoveL with robtargets, predefined speed and zone": (
        [
            _home(),
            _to(0, 0, 100, ir.JointMove, speed=ir.Speed(linear=0.5), zone=ir.Zone(0.01)),
            _to(0, 0, 45, speed=ir.Speed(linear=0.1), zone=ir.Zone(0.0003)),
            _to(10, 0, 45, speed=ir.Speed(linear=0.1)),
        ],
        [
            TOOLDATA,
            WOBJ,
            f"LOCAL CONST jointtarget p1 := {JHOME};",
            _robtarget("p2", "0.000,0.000,100.000"),
            _robtarget("p3", "0.000,0.000,45.000"),
            _robtarget("p4", "10.000,0.000,45.000"),
        ],
        [
            "ConfJ \\On;",
            "ConfL \\On;",
            "MoveAbsJ p1\\NoEOffs, v500, fine, suction;",
            "MoveJ p2, v500, z10, suction\\WObj:=tray;",
            "MoveL p3, v100, z0, suction\\WObj:=tray;",
            "MoveL p4, v100, fine, suction\\WObj:=tray;",
        ],
    ),
    "custom speeddata and zonedata where the predefined do not fit": (
        [
            _home(),
            _to(0, 0, 100, speed=ir.Speed(linear=0.02117), zone=ir.Zone(0.0125)),
            _to(
                0, 0, 60, speed=ir.Speed(linear=0.1, angular=math.radians(30)), zone=ir.Zone(0.002)
            ),
            _to(0, 0, 50, speed=ir.Speed(linear=0.02117)),
        ],
        [
            TOOLDATA,
            WOBJ,
            "LOCAL CONST speeddata v21_17 := [21.17,500,5000,1000];",
            "LOCAL CONST speeddata v100_o30 := [100,30,5000,1000];",
            "LOCAL CONST zonedata z12_5 := [FALSE,12.5,18.75,18.75,1.875,18.75,1.875];",
            "LOCAL CONST zonedata z2 := [FALSE,2,3,3,0.3,3,0.3];",
            f"LOCAL CONST jointtarget p1 := {JHOME};",
            _robtarget("p2", "0.000,0.000,100.000"),
            _robtarget("p3", "0.000,0.000,60.000"),
            _robtarget("p4", "0.000,0.000,50.000"),
        ],
        [
            "ConfJ \\On;",
            "ConfL \\On;",
            "MoveAbsJ p1\\NoEOffs, v500, fine, suction;",
            "MoveL p2, v21_17, z12_5, suction\\WObj:=tray;",
            "MoveL p3, v100_o30, z2, suction\\WObj:=tray;",
            "MoveL p4, v21_17, fine, suction\\WObj:=tray;",
        ],
    ),
    "i/o by signal name, waits in position, calls and comments": (
        [
            ir.Comment(text="start"),
            ir.SetOutput(index=3, value=True),
            ir.Wait(seconds=0.5),
            ir.WaitInput(index=7, value=False),
            ir.Call(name="SprayOn"),
            ir.Call(name="ToolChange", args=("2", "TRUE")),
            ir.SetOutput(index=3, value=False),
        ],
        [],
        [
            "ConfJ \\On;",
            "ConfL \\On;",
            "! start",
            "SetDO do3, 1;",
            "WaitTime \\InPos, 0.500;",
            "WaitDI di7, 0;",
            "SprayOn;",
            "ToolChange 2, TRUE;",
            "SetDO do3, 0;",
        ],
    ),
}


def _match(lines: list[str], expected: list[str]) -> None:
    assert len(lines) == len(expected), "\n".join(lines)
    for line, want in zip(lines, expected, strict=True):
        pattern = re.escape(want).replace(re.escape(CONF), CONF)
        assert re.fullmatch(pattern, line), f"{line!r} does not match {want!r}"


@pytest.mark.parametrize("row", list(ROWS))
def test_table(row: str, station: Station) -> None:
    instructions, declarations, body = ROWS[row]
    lines = _module(_compile(station, instructions))
    assert lines[:2] == ["MODULE Row", "  ! generated by olp from <memory>"]
    assert lines[-3:] == ["  ENDPROC", "ENDMODULE", ""]
    data, proc = _sections(lines)
    _match(data, declarations)
    assert lines[lines.index("  ENDPROC") - len(body) - 1] == "  PROC main()"
    assert proc == body


def test_the_world_and_the_flange_are_wobj0_and_tool0() -> None:
    robot = load_library_robot("abb/irb120").place()
    st = Station(name="bare", robot=robot)
    near = robot.flange_poses(np.radians([[10.0, 0, 0, 0, 40, 0], [10.0, 5, 0, 0, 40, 0]]))
    moves = [
        ir.JointMove(target=ir.JointTarget(joints=HOME)),
        ir.JointMove(target=ir.CartesianTarget(pose=near[0])),
        ir.LinearMove(target=ir.CartesianTarget(pose=near[1])),
    ]
    data, proc = _sections(_module(_compile(st, moves)))
    assert not any("tooldata" in line or "wobjdata" in line for line in data)
    assert proc[-3:] == [
        "MoveAbsJ p1\\NoEOffs, v250, fine, tool0;",
        "MoveJ p2, v250, fine, tool0;",
        "MoveL p3, v250, fine, tool0;",
    ]


def test_generated_names_avoid_predefined_data(station: Station) -> None:
    shifted = np.eye(4)
    shifted[2, 3] = 0.05
    tools = {"tool0": ir.Tool(name="tool0", pose=shifted, number=1)}
    frames = {"v100": ir.Frame(name="v100", pose=station.frames["tray"].pose, number=1)}
    st = dataclasses.replace(station, tools=tools, frames=frames)
    compiled = _compile(st, [_home(tool=ir.Tool(name="tool0"), frame=ir.Frame(name="v100"))])
    data, proc = _sections(_module(compiled))
    assert data[0].startswith("PERS tooldata tool0_2 := ")
    assert proc[-1] == "MoveAbsJ p1\\NoEOffs, v500, fine, tool0_2;"


def test_options_signals_and_configuration_monitoring(station: Station) -> None:
    compiled = _compile(station, [ir.SetOutput(index=3, value=True), ir.WaitInput(index=4)])
    post = _post(output_signal="DO10_{index}", input_signal="DI10_{index}", conf_monitoring=False)
    _, proc = _sections(_module(compiled, post))
    assert proc == ["SetDO DO10_3, 1;", "WaitDI DI10_4, 1;"]
    found = post_diagnostics(compiled, _post(output_signal="do-{index}"))
    assert [(d.kind, d.index) for d in found] == [("io_name", 0)]
    assert "not a legal RAPID name" in found[0].message


def test_circular_moves(station: Station) -> None:
    start = _compile(station, [_home(), _to(0, 0, 45)])
    end = _compile(station, [_home(), _to(20, 0, 45)])
    circ = ir.CircularMove(
        target=ir.CartesianTarget(pose=_down(20, 0, 45)),
        via=ir.CartesianTarget(pose=_down(10, 10, 45)),
        tool=SUCTION,
        frame=TRAY,
        speed=ir.Speed(linear=0.1),
    )
    last = end.steps[1]
    step = Step(2, circ, last.joints, last.path, last.tool, last.frame)
    program = ir.Program(name="Row", instructions=(*start.program.instructions, circ))
    compiled = dataclasses.replace(start, program=program, steps=(*start.steps, step))
    data, proc = _sections(_module(compiled))
    _match(
        data[-2:],
        [_robtarget("p3_via", "10.000,10.000,45.000"), _robtarget("p3", "20.000,0.000,45.000")],
    )
    assert proc[-1] == "MoveC p3_via, p3, v100, fine, suction\\WObj:=tray;"


def test_diagnostics(station: Station) -> None:
    moves = [_home(speed=ir.Speed(joint=0.5)), _to(0, 0, 45), ir.Call(name="Spray On")]
    compiled = _compile(station, moves)
    found = [(d.severity, d.kind, d.index) for d in post_diagnostics(compiled, find_post("abb"))]
    assert found == [
        ("warning", "joint_speed", 0),
        ("error", "call_name", 2),
        ("warning", "tool_load", 0),
    ]


# --------------------------------------------------------------------------------------------
# Configuration proof: random targets in every branch of every ABB and KUKA robot


def _candidates(robot: Robot, flange: np.ndarray) -> np.ndarray:
    sols = robot.solve(flange[None])[0]
    variants = turn_variants(sols, robot.limits.lower, robot.limits.upper).reshape(-1, robot.dof)
    finite = np.all(np.isfinite(variants), axis=-1)
    ok = finite & ~np.any(robot.limits.violations(np.where(finite[:, None], variants, 0)), axis=-1)
    return variants[ok]


def _planned_in_every_branch(robot: Robot, rng: np.random.Generator, per_branch: int) -> np.ndarray:
    lower, upper = robot.limits.lower, robot.limits.upper
    q = rng.uniform(lower, upper, (per_branch * 4, robot.dof))
    sols = robot.solve(robot.flange_poses(q))
    out = []
    for branch in range(sols.shape[1]):
        found = 0
        for row in turn_variants(sols[:, branch], lower, upper):
            good = row[np.all(np.isfinite(row), axis=-1)]
            good = good[~np.any(robot.limits.violations(good), axis=-1)] if good.size else good
            if good.shape[0] and found < per_branch:
                out.append(good[rng.integers(good.shape[0])])
                found += 1
    return np.array(out)


def _proof_program(robot: Robot, joints: np.ndarray) -> CompiledProgram:
    poses = robot.flange_poses(joints)
    instructions = []
    for pose in poses:
        u, _, vt = np.linalg.svd(pose[:3, :3])
        rigid = pose.copy()
        rigid[:3, :3] = u @ vt
        target = ir.CartesianTarget(pose=rigid)
        instructions.append(ir.JointMove(target=target, tool=ir.FLANGE, frame=ir.WORLD))
    steps = tuple(
        Step(i, ins, q, q[None], ir.FLANGE, ir.WORLD)
        for i, (ins, q) in enumerate(zip(instructions, joints, strict=True))
    )
    program = ir.Program(name="Proof", instructions=tuple(instructions))
    return CompiledProgram(program, Station(name="proof", robot=robot), robot.home.copy(), steps)


NUMBER = r"(-?\d+\.\d+)"
ROBTARGET = re.compile(
    rf"  LOCAL CONST robtarget p\d+ := \[\[{NUMBER},{NUMBER},{NUMBER}\],"
    rf"\[{NUMBER},{NUMBER},{NUMBER},{NUMBER}\],\[(-?\d+),(-?\d+),(-?\d+),(\d)\],"
)
ARMS = [name for name in robot_library() if name.split("/")[0] in ("abb", "kuka")]


@pytest.mark.parametrize("name", ARMS)
def test_confdata_selects_the_planned_joints(name: str) -> None:
    """Through the written text: every robtarget's pose and confdata, solved with olp's IK,
    select the planned joints and no others."""
    robot = load_library_robot(name).place()
    joints = _planned_in_every_branch(robot, np.random.default_rng(11), 5)
    text = rapid(render(_proof_program(robot, joints), _post()))["Proof.mod"]
    written = [ROBTARGET.match(line) for line in text.split("\r\n")]
    found = [m for m in written if m is not None]
    assert len(found) == len(joints)
    branches = set()
    for match, planned in zip(found, joints, strict=True):
        values = match.groups()
        pose = abb.robtarget_to_pose(
            [float(v) for v in values[:3]], [float(v) for v in values[3:7]]
        )
        config = abb.configuration_from_confdata([int(v) for v in values[7:]])
        candidates = _candidates(robot, pose)
        chosen = candidates[satisfies(config, candidates, robot)]
        # one solution, the planned one (the pose is rounded to 1 µm and 1e-9 per quaternion
        # component: joints near a singularity move by up to ~1e-4 rad)
        assert chosen.shape[0] >= 1
        assert np.max(np.abs(chosen - planned)) < 1e-3, (match.group(0), np.degrees(planned))
        branches.add(robot.branch_of(planned))
    assert len(branches) == 8


# --------------------------------------------------------------------------------------------
# Splitting


def _split_post(tmp_path: Path, limit: int) -> Post:
    folder = tmp_path / "abb_small"
    shutil.copytree(find_post("abb").manifest.folder, folder)
    text = (folder / "post.yaml").read_text()
    (folder / "post.yaml").write_text(
        text.replace("max_motions_per_file: 5000", f"max_motions_per_file: {limit}")
    )
    return find_post(str(folder))


def test_split_modules(tmp_path: Path) -> None:
    st = olp.load_station(CELL)
    post = str(_split_post(tmp_path, 3).manifest.folder)
    options = KrlOptions(calls_keep_settings=("Gripper_Check",))  # an I/O routine
    result = olp.build(st, PICK, post=post, program_options=options)
    assert result.ok
    files = rapid(dict(result.files))
    assert list(files) == [
        "PickIrb120.mod",
        "PickIrb120_P1.mod",
        "PickIrb120_P2.mod",
        "PickIrb120_P3.mod",
    ]
    main = files["PickIrb120.mod"].split("\r\n")
    assert [
        line.strip() for line in main[main.index("  PROC main()") + 1 : main.index("  ENDPROC")]
    ] == [
        "PickIrb120_P1_run;",
        "PickIrb120_P2_run;",
        "PickIrb120_P3_run;",
    ]
    assert sum("PERS tooldata" in line for line in main) == 1
    assert sum("PERS wobjdata" in line for line in main) == 2
    for k in (1, 2, 3):
        part = files[f"PickIrb120_P{k}.mod"].split("\r\n")
        assert part[0] == f"MODULE PickIrb120_P{k}"
        assert f"  PROC PickIrb120_P{k}_run()" in part
        assert not any("PERS " in line for line in part)
        moves = [line for line in part if line.strip().startswith("Move")]
        assert 1 <= len(moves) <= 3
    # the targets are numbered through the whole program: p1 .. p8 once each
    targets = re.findall(r"LOCAL CONST \w+ (p\d+) :=", "".join(files.values()))
    assert targets == [f"p{n}" for n in range(1, 9)]


# --------------------------------------------------------------------------------------------
# Vendor spelling used by the post


@pytest.mark.parametrize(
    ("linear", "angular", "name", "value"),
    [
        (0.1, None, "v100", "[100,500,5000,1000]"),
        (7.0, None, "v7000", "[7000,500,5000,1000]"),
        (0.25, None, "v250", "[250,500,5000,1000]"),
        (0.02117, None, "v21_17", "[21.17,500,5000,1000]"),
        (0.1, math.radians(30), "v100_o30", "[100,30,5000,1000]"),
    ],
)
def test_speeddata(linear: float, angular: float | None, name: str, value: str) -> None:
    speed = ir.Speed(linear=linear, angular=angular)
    assert speed_name(_post(), speed) == name and speeddata(_post(), speed) == value


@pytest.mark.parametrize(
    ("radius_mm", "name"),
    [(0.0, "fine"), (0.3, "z0"), (1.0, "z1"), (10.0, "z10"), (200.0, "z200"), (12.5, "z12_5")],
)
def test_zone_names(radius_mm: float, name: str) -> None:
    assert zone_name(_post(), ir.Zone(radius_mm / 1000.0)) == name
    assert name in PREDEFINED_NAMES or zonedata(_post(), ir.Zone(radius_mm / 1000.0)).startswith(
        "[FALSE,12.5,18.75,"
    )
