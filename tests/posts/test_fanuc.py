"""The Fanuc LS post, pinned: table-driven (small IR programs -> expected LS lines), speeds,
CNT, frame and tool numbers with their diagnostics, CONFIG that selects the planned joints
(re-read from the written text and solved with olp's IK), the transpiling path (a KRL program
on the M-20iA cell), splitting into parts called by a main program, and golden files.

Golden files: ``tests/golden/fanuc/``. After a reviewed change, regenerate them with
``OLP_UPDATE_GOLDEN=1 python -m pytest tests/posts/test_fanuc.py`` (the test then fails once,
so the variable can never pass CI by accident) and state the reason in the commit.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import olp
from olp.cli import main
from olp.compiled import CompiledProgram, Step
from olp.diagnostics import Diagnostic
from olp.geometry import inv
from olp.ir import (
    FLANGE,
    Call,
    CartesianTarget,
    CircularMove,
    Comment,
    Frame,
    Instruction,
    JointMove,
    JointTarget,
    LinearMove,
    Program,
    SetOutput,
    SourceSpan,
    Speed,
    Tool,
    Wait,
    WaitInput,
    Zone,
    is_motion,
)
from olp.kinematics.configuration import satisfies
from olp.posts import find_post
from olp.posts.base import Post
from olp.posts.fanuc import MAX_NAME_LENGTH, joint_percent, linear_mm_per_s, termination
from olp.station.model import Station
from olp.vendors import fanuc

GoldenCheck = Callable[..., None]

REPO = Path(__file__).resolve().parents[2]
GOLDEN = REPO / "tests" / "golden" / "fanuc"
FANUC_CELL = REPO / "stations" / "fanuc_m20ia_weld_cell.yaml"
KUKA_CELL = REPO / "stations" / "kr6_milling_cell.yaml"
UR_CELL = REPO / "stations" / "ur5e_screw_cell.yaml"
MILLING = REPO / "examples" / "milling.src"
TRANSPILE = Path(__file__).with_name("transpile.src")
SPAN = SourceSpan("t.src", 3)


@cache
def _station(path: Path = FANUC_CELL) -> Station:
    return olp.load_station(path)


def render(compiled: CompiledProgram, post: Post, name: str | None = None) -> dict[str, str]:
    """The post's files (its transforms applied)."""
    return post.render(compiled, name)


def post_diagnostics(compiled: CompiledProgram, post: Post | None = None) -> list[Diagnostic]:
    """What the post reports (LS by default): its transforms' diagnostics, then its checks."""
    post = post or find_post("fanuc")
    prepared, found = post.prepare(compiled)
    return found + post.check(prepared)


def _world() -> Frame:
    """A frame on Fanuc's World (J2 height, 825 mm above the station's world), unnumbered."""
    robot = _station().robot
    return Frame(name="on_world", pose=robot.base @ robot.controller_base)


def _deg(*values: float) -> np.ndarray:
    return np.radians(values)


def _pose(*xyzwpr: float) -> np.ndarray:
    return fanuc.xyzwpr_to_pose(xyzwpr)


def _compiled(items: Sequence[tuple[Instruction, Any]], station: Station | None = None) -> Any:
    """A compiled program made by hand: each motion with the joints the row plans for it."""
    station = station or _station()
    steps = []
    for index, (ins, joints) in enumerate(items):
        if is_motion(ins):
            tool = ins.tool if ins.tool.pose is not None else station.tool(ins.tool)
            frame = ins.frame if ins.frame.pose is not None else station.frame(ins.frame)
            q = np.asarray(joints, dtype=float)
            steps.append(Step(index, ins, joints=q, path=q[None], tool=tool, frame=frame))
        else:
            steps.append(Step(index, ins))
    program = Program(name="row", instructions=tuple(i for i, _ in items), source="t.src")
    return CompiledProgram(program, station, station.robot.home.copy(), tuple(steps))


def _text(items: Sequence[tuple[Instruction, Any]], station: Station | None = None) -> str:
    files = render(_compiled(items, station), find_post("fanuc"))
    assert list(files) == ["ROW.ls"]
    return files["ROW.ls"]


def _section(text: str, name: str) -> list[str]:
    lines = text.split("\r\n")
    start = lines.index(f"/{name}") + 1
    stop = next(i for i in range(start, len(lines)) if lines[i].startswith("/"))
    return lines[start:stop]


# --------------------------------------------------------------------------------------------
# Table: one IR program -> the exact /MN and /POS lines

TOOL_DOWN = _pose(985, 0, 940, 180, 0, 0)
"""The M-20iA's faceplate at J1..J6 = 0, 0, 0, 0, -90, 0 (controller J3), in World, by hand:
wrist centre at x = a1 + c3 = 985, z = c2 - a2 = 1040 mm above J2; the faceplate 100 mm below,
pointing down (W = 180)."""
TOOL_DOWN_Q = _deg(0, 0, 0, 0, -90, 0)
TORCH = Tool(name="torch", number=1)


def _joint(q: np.ndarray, **kw: Any) -> tuple[Instruction, np.ndarray]:
    return JointMove(target=JointTarget(joints=q), span=SPAN, **kw), q


def _cartesian(
    kind: type, pose: np.ndarray, q: np.ndarray, **kw: Any
) -> tuple[Instruction, np.ndarray]:
    kw.setdefault("frame", _world())
    return kind(target=CartesianTarget(pose=pose), span=SPAN, **kw), q


@dataclass(frozen=True)
class Row:
    items: list[tuple[Instruction, Any]]
    mn: list[str]
    pos: list[str] | None = None


def _cartesian_pos(n: int, config: str, xyz: str, wpr: str, uf: int = 0, ut: int = 0) -> list[str]:
    return [
        f"P[{n}]{{",
        "   GP1:",
        f"\tUF : {uf}, UT : {ut},\t\tCONFIG : '{config}',",
        xyz,
        wpr,
        "};",
    ]


ROWS: dict[str, Row] = {
    "J to joint values: percent, FINE, J1..J6 in the controller's degrees": Row(
        [_joint(_deg(10, -20.5, 30, -180, -90, 270), speed=Speed(joint=0.555))],
        ["   1:  UFRAME_NUM=0 ;", "   2:  UTOOL_NUM=0 ;", "   3:J P[1] 56% FINE    ;"],
        [
            "P[1]{",
            "   GP1:",
            "\tUF : 0, UT : 0,",
            "\tJ1=    10.000 deg,\tJ2=   -20.500 deg,\tJ3=    30.000 deg,",
            "\tJ4=  -180.000 deg,\tJ5=   -90.000 deg,\tJ6=   270.000 deg",
            "};",
        ],
    ),
    "J to a Cartesian target: XYZWPR in World and the CONFIG of the planned joints": Row(
        [_cartesian(JointMove, TOOL_DOWN, TOOL_DOWN_Q, zone=Zone(0.05))],
        ["   1:  UFRAME_NUM=0 ;", "   2:  UTOOL_NUM=0 ;", "   3:J P[1] 100% CNT50    ;"],
        _cartesian_pos(
            1,
            "N U T, 0, 0, 0",
            "\tX =   985.000  mm,\tY =     0.000  mm,\tZ =   940.000  mm,",
            "\tW =   180.000 deg,\tP =     0.000 deg,\tR =     0.000 deg",
        ),
    ),
    "R at 180 deg and J6 at 180 deg: R written 180, turn number +1": Row(
        [
            _cartesian(
                LinearMove,
                _pose(985, 0, 940, -180, 0, -180),
                _deg(0, 0, 0, 0, -90, 180),
                speed=Speed(linear=0.02117),
            )
        ],
        ["   1:  UFRAME_NUM=0 ;", "   2:  UTOOL_NUM=0 ;", "   3:L P[1] 21mm/sec FINE    ;"],
        _cartesian_pos(
            1,
            "N U T, 0, 0, 1",
            "\tX =   985.000  mm,\tY =     0.000  mm,\tZ =   940.000  mm,",
            "\tW =   180.000 deg,\tP =     0.000 deg,\tR =   180.000 deg",
        ),
    ),
    "J6 at -180 deg: turn number -1": Row(
        [_cartesian(LinearMove, _pose(985, 0, 940, 180, 0, 180), _deg(0, 0, 0, 0, -90, -180))],
        ["   1:  UFRAME_NUM=0 ;", "   2:  UTOOL_NUM=0 ;", "   3:L P[1] 250mm/sec FINE    ;"],
        _cartesian_pos(
            1,
            "N U T, 0, 0, -1",
            "\tX =   985.000  mm,\tY =     0.000  mm,\tZ =   940.000  mm,",
            "\tW =   180.000 deg,\tP =     0.000 deg,\tR =   180.000 deg",
        ),
    ),
    "a numbered frame is UF n with positions relative to it; a numbered tool is UT n": Row(
        [
            _cartesian(
                LinearMove,
                _pose(-315, 0, 1065, 180, 0, 0),
                TOOL_DOWN_Q,
                frame=Frame(name="weld_table", number=1),
            ),
            _cartesian(JointMove, TOOL_DOWN, TOOL_DOWN_Q, tool=TORCH),
        ],
        [
            "   1:  UFRAME_NUM=1 ;",
            "   2:  UTOOL_NUM=0 ;",
            "   3:L P[1] 250mm/sec FINE    ;",
            "   4:  UFRAME_NUM=0 ;",
            "   5:  UTOOL_NUM=1 ;",
            "   6:J P[2] 100% FINE    ;",
        ],
    ),
    "C: via and end on a continuation line, one program line": Row(
        [
            _cartesian(JointMove, TOOL_DOWN, TOOL_DOWN_Q),
            (
                CircularMove(
                    target=CartesianTarget(pose=TOOL_DOWN),
                    via=CartesianTarget(pose=_pose(985, 50, 960, 180, 0, 0)),
                    speed=Speed(linear=0.1),
                    zone=Zone(0.0004),
                    frame=_world(),
                ),
                TOOL_DOWN_Q,
            ),
        ],
        [
            "   1:  UFRAME_NUM=0 ;",
            "   2:  UTOOL_NUM=0 ;",
            "   3:J P[1] 100% FINE    ;",
            "   4:C P[2]",
            "    :  P[3] 100mm/sec CNT0    ;",
        ],
    ),
    "I/O, waits, calls and comments": Row(
        [
            (SetOutput(index=1, value=True), None),
            (SetOutput(index=12, value=False), None),
            (Wait(seconds=0.5), None),
            (WaitInput(index=2), None),
            (WaitInput(index=3, value=False), None),
            (Call(name="SprayOn"), None),
            (Call(name="TCP_ON", args=("1", "2.5")), None),
            (Comment(text="approach the part; then weld the long seam on the left"), None),
            (Wait(seconds=1.004), None),
            (Wait(seconds=12), None),
        ],
        [
            "   1:  DO[1]=ON ;",
            "   2:  DO[12]=OFF ;",
            "   3:  WAIT 0.50(sec) ;",
            "   4:  WAIT DI[2]=ON ;",
            "   5:  WAIT DI[3]=OFF ;",
            "   6:  CALL SPRAYON ;",
            "   7:  CALL TCP_ON(1,2.5) ;",
            "   8:  !approach the part, then weld the ;",
            "   9:  !long seam on the left ;",
            "  10:  WAIT 1.00(sec) ;",
            "  11:  WAIT 12.00(sec) ;",
        ],
        [],
    ),
}


@pytest.mark.parametrize("name", list(ROWS))
def test_table(name: str) -> None:
    row = ROWS[name]
    text = _text(row.items)
    assert _section(text, "MN") == row.mn
    if row.pos is not None:
        assert _section(text, "POS") == row.pos
    assert f"LINE_COUNT\t= {len([x for x in row.mn if not x.startswith('    :')])};" in text


def test_numbered_frame_row_writes_the_frame_relative_pose() -> None:
    text = _text(
        ROWS[
            "a numbered frame is UF n with positions relative to it; a numbered tool is UT n"
        ].items
    )
    pos = _section(text, "POS")
    assert pos[2] == "\tUF : 1, UT : 0,\t\tCONFIG : 'N U T, 0, 0, 0',"
    assert pos[3] == "\tX =  -315.000  mm,\tY =     0.000  mm,\tZ =  1065.000  mm,"
    assert pos[8] == "\tUF : 0, UT : 1,\t\tCONFIG : 'N U T, 0, 0, 0',"


def test_the_whole_file_layout() -> None:
    text = _text([_joint(TOOL_DOWN_Q)])
    assert text.startswith("/PROG  ROW\r\n/ATTR\r\nOWNER\t\t= MNEDITOR;\r\n")
    assert (
        "\r\nDEFAULT_GROUP\t= 1,*,*,*,*;\r\nCONTROL_CODE\t= 00000000 00000000;\r\n/MN\r\n" in text
    )
    assert text.endswith("};\r\n/END\r\n") and "\n" not in text.replace("\r\n", "")
    assert "CREATE" not in text and "MODIFIED" not in text  # no clock in the bytes


def test_lines_are_numbered_right_aligned() -> None:
    text = _text([(SetOutput(index=1, value=True), None)] * 12)
    assert _section(text, "MN")[8:10] == ["   9:  DO[1]=ON ;", "  10:  DO[1]=ON ;"]
    assert "LINE_COUNT\t= 12;" in text


@pytest.mark.parametrize(
    ("radius", "cnt"),
    [(0.0, "FINE"), (0.0004, "CNT0"), (0.0005, "CNT1"), (0.0149, "CNT15"), (0.05, "CNT50"),
     (0.1, "CNT100"), (0.2, "CNT100")],
)  # fmt: skip
def test_cnt_from_a_distance_zone(radius: float, cnt: str) -> None:
    assert termination(find_post("fanuc"), Zone(radius)) == cnt


@pytest.mark.parametrize(
    ("speed", "percent", "mm_s"),
    [(Speed(joint=1.0, linear=2.0), 100, 2000), (Speed(joint=0.555, linear=0.02117), 56, 21),
     (Speed(joint=0.004, linear=0.0001), 1, 1), (Speed(joint=0.125, linear=0.0125), 13, 13)],
)  # fmt: skip
def test_speeds(speed: Speed, percent: int, mm_s: int) -> None:
    post = find_post("fanuc")
    assert joint_percent(post, speed) == str(percent)
    assert linear_mm_per_s(post, speed) == str(mm_s)


@pytest.mark.parametrize(
    ("name", "legal"),
    [("Milling", "MILLING"), ("weld seam-2", "WELD_SEAM_2"), ("1st", "P1ST"), ("x" * 40, "X" * 36)],
)
def test_program_names(name: str, legal: str) -> None:
    compiled = _compiled([_joint(TOOL_DOWN_Q)])
    files = render(compiled, find_post("fanuc"), name=name)
    assert list(files) == [f"{legal}.ls"] and files[f"{legal}.ls"].startswith(f"/PROG  {legal}\r\n")


# --------------------------------------------------------------------------------------------
# Positions written as joints where CONFIG cannot select the planned joints


@pytest.mark.parametrize(
    ("joints", "why"),
    [
        # J3 200 deg and -160 deg reach the same pose with the same CONFIG (J3 range -185..273)
        (_deg(0, 0, 200, 0, -90, 0), "J3"),
        # a wrist singularity: J4 + J6 is all the pose fixes
        (_deg(0, 0, 0, 30, 0, -30), "wrist"),
    ],
)
def test_cartesian_target_without_a_selecting_config_is_written_as_joints(
    joints: np.ndarray, why: str
) -> None:
    robot = _station().robot
    pose = inv(robot.base @ robot.controller_base) @ robot.flange_poses(joints)
    items = [_cartesian(LinearMove, pose, joints)]
    pos = _section(_text(items), "POS")
    assert pos[2] == "\tUF : 0, UT : 0," and pos[3].startswith("\tJ1=")
    diags = post_diagnostics(_compiled(items))
    assert [(d.severity, d.kind, d.index) for d in diags] == [("info", "joint_position", 0)]


def test_a_robot_without_config_gets_joint_positions() -> None:
    ur5e = _station(UR_CELL)
    q = ur5e.robot.home
    items = [(LinearMove(target=CartesianTarget(pose=ur5e.robot.flange_poses(q))), q)]
    assert _section(_text(items, ur5e), "POS")[3].startswith("\tJ1=     0.000 deg")
    kinds = [(d.severity, d.kind) for d in post_diagnostics(_compiled(items, ur5e))]
    assert kinds == [("warning", "foreign_robot"), ("info", "joint_position")]


# --------------------------------------------------------------------------------------------
# Diagnostics: frame and tool numbers, I/O, calls


def _kinds(diags: list[Diagnostic]) -> list[tuple[str, str]]:
    return [(d.severity, d.kind) for d in diags]


INLINE = Tool(name="tool_l3", pose=_pose(0, 0, 200, 0, 0, 0))


@pytest.mark.parametrize(
    ("items", "expected"),
    [
        ([_joint(TOOL_DOWN_Q, tool=TORCH)], [("info", "controller_tool")]),
        ([_joint(TOOL_DOWN_Q, tool=FLANGE)], []),
        ([_joint(TOOL_DOWN_Q, tool=INLINE)], [("warning", "tool_number")]),
        (
            [_joint(TOOL_DOWN_Q, tool=INLINE), _joint(TOOL_DOWN_Q, tool=TORCH)],
            [("error", "tool_number"), ("info", "controller_tool")],
        ),
        (
            [
                _joint(TOOL_DOWN_Q, tool=INLINE),
                _joint(TOOL_DOWN_Q, tool=Tool(name="b", pose=_pose(0, 0, 100, 0, 0, 0))),
            ],
            [("error", "tool_number"), ("error", "tool_number")],
        ),
        (
            [_joint(TOOL_DOWN_Q, tool=Tool(name="t11", number=11, pose=np.eye(4)))],
            [("error", "tool_number")],
        ),
        (
            [_joint(TOOL_DOWN_Q, frame=Frame(name="f12", number=12, pose=np.eye(4)))],
            [("error", "frame_number")],
        ),
        (
            [_joint(TOOL_DOWN_Q, frame=Frame(name="fixture", number=2))],
            [("info", "controller_frame")],
        ),
        ([(SetOutput(index=0, value=True), None)], [("error", "io_range")]),
        ([(WaitInput(index=0), None)], [("error", "io_range")]),
        ([(Call(name="spray on"), None)], [("error", "call_name")]),
        ([(Call(name="Spray", args=("TRUE",)), None)], [("error", "call_argument")]),
        ([(Call(name="Spray", args=(" -1", "2.5")), None)], []),
    ],
)
def test_diagnostics(items: list[tuple[Instruction, Any]], expected: list[tuple[str, str]]) -> None:
    assert _kinds(post_diagnostics(_compiled(items))) == expected


def test_setup_messages_give_the_controller_values() -> None:
    items = [
        _joint(TOOL_DOWN_Q, tool=INLINE, frame=Frame(name="weld_table", number=1)),
    ]
    messages = [d.message for d in post_diagnostics(_compiled(items))]
    assert messages == [
        "positions use UFRAME[1] ('weld_table'); the controller must hold it as X 1300.000 "
        "Y 0.000 Z -125.000 W 0.000 P 0.000 R 0.000 (mm, deg)",
        "tool 'tool_l3' has no number: written as UTOOL 1, which must hold X 0.000 Y 0.000 "
        "Z 200.000 W 0.000 P 0.000 R 0.000 (mm, deg)",
    ]
    text = _text(items)
    assert "   2:  UTOOL_NUM=1 ;" in _section(text, "MN")


def test_an_error_blocks_the_build_and_writes_nothing(tmp_path: Path) -> None:
    program = Program(
        name="bad",
        instructions=(JointMove(target=JointTarget(joints=TOOL_DOWN_Q)), WaitInput(index=0)),
    )
    result = olp.build(_station(), program, post="fanuc", out_dir=tmp_path / "out")
    assert not result.ok and ("error", "io_range") in _kinds(list(result.diagnostics))
    assert not (tmp_path / "out").exists()


# --------------------------------------------------------------------------------------------
# Configuration proof and the transpiling path: the written text selects the planned joints

BLOCK = re.compile(r"P\[(\d+)\]\{\r\n(.*?)\r\n\};", re.DOTALL)
MOTION = re.compile(r"^ *\d+:([JLC]) P\[(\d+)\]", re.MULTILINE)


def _positions(text: str) -> dict[int, tuple[int, int, str | None, list[float]]]:
    """The /POS entries re-read: number -> (UF, UT, CONFIG or None, six values)."""
    out = {}
    for m in BLOCK.finditer(text.split("/POS\r\n", 1)[1]):
        body = m[2]
        frames = re.search(r"UF : (\d+), UT : (\d+)", body)
        assert frames is not None
        config = re.search(r"CONFIG : '([^']*)'", body)
        values = [float(v) for v in re.findall(r"= *(-?\d+\.\d+) +(?:mm|deg)", body)]
        assert len(values) == 6
        out[int(m[1])] = (int(frames[1]), int(frames[2]), config and config[1], values)
    return out


def _reached_joints(
    robot: Any, position: tuple[int, int, str | None, list[float]], step: Any
) -> np.ndarray:
    """The joints the controller takes for a written position: joint values as they are; a
    Cartesian position solved with olp's IK among every solution within the limits, keeping
    those its CONFIG admits (which must be one solution)."""
    uf, _ut, config, values = position
    if config is None:
        return np.radians(values)
    frame = robot.base @ robot.controller_base if uf == 0 else step.frame.pose
    flange = frame @ fanuc.xyzwpr_to_pose(values) @ inv(step.tool.pose)
    found = fanuc.candidates(robot, flange)
    chosen = found[satisfies(fanuc.configuration_from_config(config), found, robot)]
    assert chosen.shape[0] >= 1
    assert np.max(np.abs(chosen - chosen[0])) < 1e-3, f"CONFIG {config} admits several solutions"
    reached: np.ndarray = chosen[0]
    return reached


@pytest.mark.parametrize(("cell", "source"), [(FANUC_CELL, TRANSPILE), (KUKA_CELL, MILLING)])
def test_every_written_position_selects_the_planned_joints(cell: Path, source: Path) -> None:
    """The configuration proof: for every motion, the written position (re-read from the text:
    rounded values, the CONFIG string) reaches, through olp's IK, the joints olp planned. For
    the KRL program on the M-20iA cell this is the transpiling proof: PTP became J, LIN became
    L, and the LS program runs the planned joint path."""
    station = _station(cell)
    result = olp.build(station, source, post="fanuc")
    assert result.ok
    (text,) = result.files.values()
    steps = [s for s in result.compiled.steps if s.joints is not None]
    motions = MOTION.findall(text)
    assert [k for k, _ in motions] == ["J" if s.instruction.kind == "joint" else "L" for s in steps]
    positions = _positions(text)
    assert sorted(positions) == list(range(1, len(steps) + 1))
    cartesian = 0
    for step, (_, number) in zip(steps, motions, strict=True):
        position = positions[int(number)]
        cartesian += position[2] is not None
        reached = _reached_joints(station.robot, position, step)
        assert np.max(np.abs(reached - step.joints)) < 1e-4
    assert cartesian == sum(s.instruction.target.__class__ is CartesianTarget for s in steps)


def test_configuration_proof_over_random_planned_joints() -> None:
    """The same proof over 300 random joint vectors within the M-20iA's limits (every CONFIG
    letter and turn number occurs): a Cartesian target's written position reaches the planned
    joints, or it is written as joint values when no CONFIG can (with a note)."""
    station = _station()
    robot = station.robot
    rng = np.random.default_rng(11)
    joints = rng.uniform(robot.limits.lower, robot.limits.upper, size=(300, 6))
    world = robot.base @ robot.controller_base
    items = [
        (
            LinearMove(
                target=CartesianTarget(pose=inv(world) @ robot.flange_poses(q)), frame=_world()
            ),
            q,
        )
        for q in joints
    ]
    compiled = _compiled(items)
    text = render(compiled, find_post("fanuc"))["ROW.ls"]
    positions = _positions(text)
    configs = {p[2] for p in positions.values()}
    assert {c[0] for c in configs if c} == {"F", "N"} and {c[2] for c in configs if c} == {"U", "D"}
    assert {c[4] for c in configs if c} == {"T", "B"}
    assert {c.split(", ")[3] for c in configs if c} == {"-1", "0", "1"}
    as_joints = 0
    lower, upper = robot.limits.lower[2], robot.limits.upper[2]
    for k, step in enumerate(compiled.steps, 1):
        assert step.joints is not None
        j3 = step.joints[2]
        two_turns = lower <= j3 - 2 * math.pi or j3 + 2 * math.pi <= upper
        # written as joints exactly where CONFIG cannot tell J3 from J3 -+ 360 deg
        assert (positions[k][2] is None) == two_turns
        as_joints += two_turns
        reached = _reached_joints(robot, positions[k], step)
        # 0.001 mm / 0.001 deg of rounding can move a joint by ~1e-3 rad near a singular pose;
        # another IK solution of the same pose lies much further away
        assert np.max(np.abs(reached - step.joints)) < 5e-3
    notes = [d for d in post_diagnostics(compiled) if d.kind == "joint_position"]
    assert len(notes) == as_joints > 0


# --------------------------------------------------------------------------------------------
# Splitting: parts called in order by a main program


def test_a_long_program_is_split_into_parts_called_by_a_main_program(tmp_path: Path) -> None:
    folder = tmp_path / "fanuc_small"
    shutil.copytree(find_post("fanuc").manifest.folder, folder)
    manifest = folder / "post.yaml"
    manifest.write_text(
        manifest.read_text().replace(
            "max_instructions_per_file: 3000", "max_instructions_per_file: 5"
        )
    )
    name = "a_very_long_program_name_for_a_weld_cell"
    result = olp.build(_station(), TRANSPILE, post=str(folder), name=name)
    assert result.ok
    main_name = "A_VERY_LONG_PROGRAM_NAME_FOR_A_WELD_"  # upper case, cut to 36 characters
    parts = [f"A_VERY_LONG_PROGRAM_NAME_FOR_A_WE_P{k}" for k in (1, 2, 3)]  # cut to fit _Pk
    assert list(result.files) == [f"{n}.ls" for n in [main_name, *parts]]
    assert all(len(n) <= MAX_NAME_LENGTH for n in [main_name, *parts])
    main_text = result.files[f"{main_name}.ls"]
    assert _section(main_text, "MN") == [f"{k:4d}:  CALL {p} ;" for k, p in enumerate(parts, 1)]
    assert _section(main_text, "POS") == [] and "LINE_COUNT\t= 3;" in main_text
    for part in parts:
        # no state carried over: frame and tool set again before the part's first motion, and
        # its positions numbered from 1
        mn = [line[5:] for line in _section(result.files[f"{part}.ls"], "MN")]
        first = next(i for i, line in enumerate(mn) if line[:2] in ("J ", "L "))
        assert mn[first - 2 : first + 1] == ["  UFRAME_NUM=0 ;", "  UTOOL_NUM=1 ;", mn[first]]
        assert mn[first].startswith(("J P[1] ", "L P[1] "))


# --------------------------------------------------------------------------------------------
# Golden files, determinism under another locale, the CLI listing


def test_golden_diagnostics() -> None:
    milling = olp.build(_station(KUKA_CELL), MILLING, post="fanuc")
    assert _kinds(list(milling.diagnostics)) == [
        ("warning", "foreign_robot"),
        ("warning", "tool_number"),
    ]
    transpiled = olp.build(_station(), TRANSPILE, post="fanuc")
    assert ("info", "controller_tool") in _kinds(list(transpiled.diagnostics))


def test_bytes_do_not_depend_on_the_locale(tmp_path: Path) -> None:
    code = (
        "import locale, sys, olp\n"
        "for name in ('de_DE.UTF-8', 'fr_FR.UTF-8', 'C.UTF-8'):\n"
        "    try:\n        locale.setlocale(locale.LC_ALL, name)\n        break\n"
        "    except locale.Error:\n        pass\n"
        f"r = olp.build({str(FANUC_CELL)!r}, {str(TRANSPILE)!r}, post='fanuc',\n"
        "              out_dir=sys.argv[1])\n"
        "assert r.ok\n"
    )
    env = {**os.environ, "LC_ALL": "de_DE.UTF-8", "LANG": "de_DE.UTF-8", "PYTHONHASHSEED": "7"}
    subprocess.run([sys.executable, "-c", code, str(tmp_path)], env=env, check=True, cwd=REPO)
    assert (tmp_path / "TRANSPILE.ls").read_bytes() == (
        GOLDEN / "transpile" / "TRANSPILE.ls"
    ).read_bytes()


def test_fanuc_is_listed_by_olp_posts(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["posts"]) == 0
    assert re.search(r"^fanuc\s+Fanuc R-30iB", capsys.readouterr().out, re.MULTILINE)


def test_j5_sign_rule_holds_on_the_m20ia() -> None:
    """N for J5 < 0 (VENDOR-NOTES, medium confidence): the hand-derived tool-down pose above."""
    assert str(fanuc.config_from_joints(_station().robot, TOOL_DOWN_Q)) == "N U T, 0, 0, 0"
    assert math.isclose(float(_station().robot.flange_poses(TOOL_DOWN_Q)[2, 3]), 0.825 + 0.94)


def test_a_speed_too_slow_for_ls_is_written_at_its_least_with_a_warning() -> None:
    station = _station()
    at = station.robot.flange_poses(TOOL_DOWN_Q)
    down = at.copy()
    down[2, 3] -= 0.01
    program = Program(
        name="slow",
        instructions=(
            JointMove(target=JointTarget(joints=TOOL_DOWN_Q), tool=FLANGE).with_speed(joint=0.001),
            LinearMove(target=CartesianTarget(pose=down), tool=FLANGE).with_speed(linear=0.0002),
        ),
    )
    result = olp.build(station, program, "fanuc")
    assert result.ok, [d.format() for d in result.diagnostics]
    raised = [(d.index, d.severity) for d in result.diagnostics if d.kind == "speed_raised"]
    assert raised == [(0, "warning"), (1, "warning")]
    body = result.files["SLOW.ls"]
    assert "J P[1] 1% FINE" in body and "L P[2] 1mm/sec FINE" in body


def _weld_robot() -> Any:
    cell = Path(__file__).resolve().parents[2] / "stations" / "fanuc_m20ia_weld_cell.yaml"
    return olp.load_station(cell).robot


def test_remembered_selections_are_the_selections_of_the_same_rows() -> None:
    robot = _weld_robot()
    rng = np.random.default_rng(5)
    q = rng.uniform(robot.limits.lower, robot.limits.upper, size=(400, 6))
    q[::3, 4] = 0.0  # some rows are written as joints (None)
    direct = fanuc.selecting_configs(robot, q)
    post = find_post("fanuc")
    assert post.selecting_configs(robot, q[:150]) == direct[:150]
    # Known rows shuffled, repeated and mixed with unknown ones, and -0.0 as a different row.
    order = rng.permutation(np.r_[np.arange(400), np.arange(100)])
    assert post.selecting_configs(robot, q[order]) == [direct[k] for k in order]
    signed = q[:5].copy()
    signed[:, 4] = -0.0
    assert post.selecting_configs(robot, signed) == fanuc.selecting_configs(robot, signed)


def test_a_hash_collision_in_the_memo_is_a_miss_not_another_rows_selection(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from olp.posts import fanuc as fanuc_post

    robot = _weld_robot()
    q = np.random.default_rng(6).uniform(robot.limits.lower, robot.limits.upper, size=(60, 6))
    q[::2, 4] = 0.0
    monkeypatch.setattr(fanuc_post, "_row_hashes", lambda bits: np.zeros(len(bits), np.uint64))
    post = find_post("fanuc")
    direct = fanuc.selecting_configs(robot, q)
    assert post.selecting_configs(robot, q[:30]) == direct[:30]
    assert post.selecting_configs(robot, q) == direct
    assert post.selecting_configs(robot, q[::-1]) == direct[::-1]
