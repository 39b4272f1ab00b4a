"""User text is never code, and every number a post prints is what olp checked (issue 10,
items 2 and 4), on every post: the hostile-input probe's reproductions and their neighbours.

A comment with a line break becomes several comment lines; a bare CR, another control character
or a character the file's encoding lacks is an error on the comment's line; a call whose name or
arguments could start another statement is an error; a program file name with a line break is
escaped in the header; a value that does not survive printing is an error on its instruction.
Nothing is written while any of these remain.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.api import BuildResult
from olp.cli import main
from olp.geometry import transl

REPO = Path(__file__).resolve().parents[2]
CELLS = {
    "kuka": REPO / "stations" / "kr6_milling_cell.yaml",
    "abb": REPO / "stations" / "abb_irb120_pick_cell.yaml",
    "ur": REPO / "stations" / "ur5e_screw_cell.yaml",
    "fanuc": REPO / "stations" / "fanuc_m20ia_weld_cell.yaml",
}
POSTS = list(CELLS)

LIVE = {
    "kuka": re.compile(r"^\s*(LIN|PTP|CIRC|\$OUT|WAIT)\b"),
    "abb": re.compile(r"^\s*(MoveL|MoveJ|MoveAbsJ|MoveC|SetDO|WaitTime)\b"),
    "ur": re.compile(r"^\s*(movel|movej|movec|set_digital_out|sleep)\("),
    "fanuc": re.compile(r"^\s*\d+:\s*(J|L|C|DO\[|WAIT)\b"),
}
"""A line that moves the robot or sets an output, per post."""


@pytest.fixture(scope="module")
def stations() -> dict[str, olp.station.model.Station]:  # type: ignore[name-defined]
    return {post: olp.load_station(path) for post, path in CELLS.items()}


def _home_move(station: object) -> ir.JointMove:
    return ir.JointMove(target=ir.JointTarget(joints=station.robot.home))  # type: ignore[attr-defined]


def _build(
    station: object, instructions: Sequence[ir.Instruction], post: str, source: str = "t.py"
) -> BuildResult:
    program = ir.Program(name="T", instructions=tuple(instructions), source=source)
    return olp.build(station, program, post=post)  # type: ignore[arg-type]


def _live_lines(result: BuildResult, post: str) -> list[str]:
    return [
        line
        for text in result.files.values()
        for line in text.replace("\r\n", "\n").split("\n")
        if LIVE[post].search(line)
    ]


def _errors(result: BuildResult) -> list[tuple[str, int | None]]:
    return [(d.kind, d.index) for d in result.diagnostics if d.severity == "error"]


# --------------------------------------------------------------------------------------------
# Comments


INJECTED = "x\nLIN {X 0,Y 0,Z 0,A 0,B 0,C 0}\nMoveL p1,v1000,fine,tool0;\nmovel(p[0,0,0,0,0,0])"


@pytest.mark.parametrize("post", POSTS)
def test_a_comment_with_line_breaks_becomes_comment_lines(stations: dict, post: str) -> None:
    station = stations[post]
    home = _home_move(station)
    clean = _build(station, [home], post)
    result = _build(station, [home, ir.Comment(text=INJECTED)], post)
    assert result.ok, [d.format() for d in result.diagnostics]
    assert _live_lines(result, post) == _live_lines(clean, post)
    text = "\n".join(result.files.values())
    assert "LIN {X 0,Y 0,Z 0,A 0,B 0,C 0}" in text or post == "fanuc"  # kept, as a comment


@pytest.mark.parametrize("post", POSTS)
@pytest.mark.parametrize(
    ("text", "what"),
    [
        ("x\rLIN {X 0,Y 0,Z 0}", None),  # a bare CR is a line break: another comment line
        ("bell\x07", "U+0007"),
        ("escape \x1b[2J", "U+001B"),
        ("caf\u00e9", "U+00E9"),
        ("nul\x00", "U+0000"),
    ],
)
def test_other_control_and_foreign_characters_are_located_errors(
    stations: dict, post: str, text: str, what: str | None
) -> None:
    station = stations[post]
    comment = ir.Comment(text=text, span=ir.SourceSpan("prog.py", 7, 3))
    result = _build(station, [_home_move(station), comment], post)
    if what is None:
        assert result.ok
        assert _live_lines(result, post) == _live_lines(
            _build(station, [_home_move(station)], post), post
        )
        return
    assert _errors(result) == [("comment", 1)]
    error = next(d for d in result.diagnostics if d.severity == "error")
    assert error.span is not None and (error.span.line, error.span.column) == (7, 3)
    assert what in error.message
    assert result.files == {}


# --------------------------------------------------------------------------------------------
# Calls


@pytest.mark.parametrize(
    ("post", "call", "kind"),
    [
        # the probe's ABB reproduction: ';' ends a RAPID statement
        (
            "abb",
            ir.Call(
                name="Grip",
                args=(
                    "1;MoveAbsJ [[0",
                    "0",
                    "0",
                    "0",
                    "0",
                    "0]",
                    "[9E9]]",
                    "v5000",
                    "fine",
                    "tool0;Ok 2",
                ),
            ),
            "call_argument",
        ),
        ("abb", ir.Call(name="Grip", args=('"a";MoveL p1',)), "call_argument"),
        ("abb", ir.Call(name="Grip;MoveL"), "call_name"),
        ("kuka", ir.Call(name="Grip", args=("1)\nLIN {X 0}",)), "call_argument"),
        ("kuka", ir.Call(name="Grip", args=("1) ; comment",)), "call_argument"),
        ("kuka", ir.Call(name="Grip\nLIN"), "call_name"),
        ("ur", ir.Call(name="grip", args=("1)\nmovel(p[0,0,0,0,0,0]",)), "call_argument"),
        ("ur", ir.Call(name="grip", args=('"a\\"b"',)), "call_argument"),
        ("fanuc", ir.Call(name="GRIP", args=("1) ;\n 2:L P[1]",)), "call_argument"),
        ("fanuc", ir.Call(name="GRIP ; L P[1]"), "call_name"),
    ],
)
def test_calls_that_could_start_a_statement_are_errors(
    stations: dict, post: str, call: ir.Call, kind: str
) -> None:
    station = stations[post]
    result = _build(station, [_home_move(station), call], post)
    assert _errors(result) == [(kind, 1)]
    assert result.files == {}


@pytest.mark.parametrize(
    ("post", "call", "line"),
    [
        ("kuka", ir.Call(name="BAS", args=("#PTP_PARAMS", "100")), "BAS(#PTP_PARAMS, 100)"),
        ("kuka", ir.Call(name="Grip", args=('"open"', "$OUT[3]")), 'Grip("open", $OUT[3])'),
        ("kuka", ir.Call(name="Grip", args=('"open"', "$OUT[3]+1")), None),
        ("abb", ir.Call(name="Grip", args=("1", '"open"', "TRUE")), 'Grip 1, "open", TRUE;'),
        ("ur", ir.Call(name="grip", args=("1.5e3", '"x"')), 'grip(1.5e3, "x")'),
        ("fanuc", ir.Call(name="grip", args=("-1", "2.5")), "CALL GRIP(-1,2.5) ;"),
    ],
)
def test_literal_arguments_are_written(
    stations: dict, post: str, call: ir.Call, line: str | None
) -> None:
    station = stations[post]
    result = _build(station, [_home_move(station), call], post)
    if post == "kuka" and line is None:
        assert _errors(result) == [("call_argument", 1)]  # $OUT[3]+1 is an expression
        return
    assert result.ok, [d.format() for d in result.diagnostics]
    assert line in "\n".join(result.files.values())


# --------------------------------------------------------------------------------------------
# File names and names


@pytest.mark.parametrize("post", POSTS)
def test_a_file_name_with_a_line_break_is_escaped_in_the_header(stations: dict, post: str) -> None:
    station = stations[post]
    source = "cells/evil\nLIN {X 0,Y 0,Z 0}\r\n$OUT[1]=TRUE.src"
    result = _build(station, [_home_move(station)], post, source=source)
    assert result.ok
    clean = _build(station, [_home_move(station)], post)
    assert _live_lines(result, post) == _live_lines(clean, post)
    if post in ("kuka", "abb"):  # LS and URScript carry no file name
        assert "evil?LIN {X 0,Y 0,Z 0}??$OUT[1]=TRUE.src" in "\n".join(result.files.values())


@pytest.mark.parametrize("post", POSTS)
def test_a_program_name_with_a_line_break_becomes_a_legal_name(stations: dict, post: str) -> None:
    station = stations[post]
    program = ir.Program(name="A\nLIN {X 0}", instructions=(_home_move(station),))
    result = olp.build(station, program, post=post)
    assert result.ok and all("\n" not in name and " " not in name for name in result.files)
    assert _live_lines(result, post) == _live_lines(
        _build(station, [_home_move(station)], post), post
    )


# --------------------------------------------------------------------------------------------
# The probe's reproductions through the command line


def test_a_dsl_comment_with_a_newline_is_not_a_live_line(tmp_path: Path) -> None:
    program = tmp_path / "inject.py"
    program.write_text(
        "from olp.dsl import *\n"
        "robot.MoveJ(robot.JointsHome())\n"
        'robot.RunInstruction("x\\nLIN {X 0,Y 0,Z 0,A 0,B 0,C 0}", INSTRUCTION_COMMENT)\n'
        'robot.RunInstruction(param("NOTE", "n"), INSTRUCTION_COMMENT)\n'
    )
    for post in ("kuka", "abb"):
        out = tmp_path / post
        code = main(
            [
                "build",
                str(CELLS["kuka"]),
                str(program),
                "--post",
                post,
                "-o",
                str(out),
                "--quiet",
                "--set",
                "NOTE=y\nPTP {A1 0}\nMoveAbsJ [[0,0,0,0,0,0]];",
            ]
        )
        assert code == 0
        written = "\n".join(p.read_text() for p in out.iterdir() if p.suffix in (".src", ".mod"))
        lines = [line.strip() for line in written.splitlines()]
        assert "LIN {X 0,Y 0,Z 0,A 0,B 0,C 0}" not in lines
        assert not any(line.startswith(("PTP {A1 0}", "MoveAbsJ [[0,0")) for line in lines)


# --------------------------------------------------------------------------------------------
# Numbers that do not survive printing


def _krl(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "prog.src"
    path.write_text("DEF prog( )\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 45,A6 0}\n" + body + "\nEND\n")
    return path


@pytest.mark.parametrize("post", POSTS)
def test_a_speed_that_prints_as_zero_is_an_error_on_its_line(tmp_path: Path, post: str) -> None:
    src = _krl(tmp_path, "$VEL.CP = 0.000004\nLIN {X 500,Y 0,Z 500,A 0,B 90,C 0}")
    result = olp.build(olp.load_station(CELLS["kuka"]), src, post=post)
    numbers = [d for d in result.diagnostics if d.kind == "number"]
    if post in ("abb", "fanuc"):
        # RAPID writes mm/s (0.004 is exact); LS writes integer mm/sec, at least 1
        assert numbers == []
        return
    assert numbers and numbers[0].severity == "error" and numbers[0].span is not None
    assert numbers[0].span.line == 4
    assert "outside the controller's range" in numbers[0].message
    assert result.files == {}


@pytest.mark.parametrize("post", POSTS)
def test_an_absurd_wait_is_an_error_not_a_300_digit_number(tmp_path: Path, post: str) -> None:
    src = _krl(tmp_path, "WAIT SEC 1E300")
    result = olp.build(olp.load_station(CELLS["kuka"]), src, post=post)
    numbers = [d for d in result.diagnostics if d.kind == "number" and d.severity == "error"]
    assert [d.span.line for d in numbers if d.span is not None] == [3]
    assert result.files == {}


def test_the_command_line_exits_1_and_writes_nothing(tmp_path: Path) -> None:
    src = _krl(tmp_path, "WAIT SEC 1E300")
    out = tmp_path / "out"
    assert main(["build", str(CELLS["kuka"]), str(src), "-o", str(out), "--quiet"]) == 1
    assert not out.exists()


def test_a_frame_too_far_for_a_32_bit_real_is_an_error(stations: dict) -> None:
    station = stations["kuka"]
    far = ir.Frame(name="far", pose=transl(1000.00009, 0.0, 0.0))
    home = station.robot.flange_poses(station.robot.home)
    target = np.linalg.inv(far.pose) @ home
    move = ir.LinearMove(target=ir.CartesianTarget(pose=target), frame=far)
    result = _build(station, [_home_move(station), move], "kuka")
    numbers = [d for d in result.diagnostics if d.kind == "number"]
    assert numbers and "32-bit REAL" in numbers[0].message and numbers[0].index == 1
    assert _build(station, [_home_move(station), move], "ur").ok  # URScript floats are doubles
