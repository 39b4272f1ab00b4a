"""One named path of a program with control flow, unrolled into a straight program
(olp.passes.timing.unroll): its cycle time is the path time the summary gives, and a trajectory
of it (``olp time --trajectory``) follows that path, not the text."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import olp
from olp import ir
from olp.cli import main
from olp.passes.pipeline import BuildOptions
from olp.passes.timing.conditions import parse_assumptions
from olp.passes.timing.unroll import MAX_UNROLLED, unroll
from olp.station.model import Station
from tests.passes.flow_programs import lin, program, span, start

REPO = Path(__file__).resolve().parents[2]
IN1, IN2 = ir.DigitalInput(index=1), ir.DigitalInput(index=2)
TOL = 1e-4  # as in test_branches.py
LOOP_TOL = 2e-3
"""A loop's later passes: the path timing times them from the previous pass's end resolved
again, the straight program along its own resolution; measured 4e-4 apart on a 3 s square."""


def counted(body: tuple[ir.Node, ...], count: int, line: int = 3) -> ir.For:
    return ir.For(
        variable="i",
        start=ir.Constant(value=1),
        stop=ir.Constant(value=count),
        body=body,
        span=span(line),
    )


@pytest.fixture(scope="module")
def station() -> Station:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def path_and_straight(station: Station, prog: ir.Program, *assume: str) -> tuple[float, float]:
    assumptions = parse_assumptions(assume)
    compiled = olp.compile(prog, station, BuildOptions(collisions=None, assume=assumptions))
    assert compiled.ok and compiled.paths is not None and compiled.paths.decided
    assert compiled.paths.shortest is not None
    unrolled = unroll(prog, assumptions)
    assert unrolled.program is not None, unrolled.reason
    straight = olp.compile(unrolled.program, station, collisions=None)
    assert straight.ok and straight.paths is None
    return compiled.paths.shortest.seconds, straight.cycle_time


def test_the_unrolled_path_takes_the_path_time(station: Station) -> None:
    # A square with 10 mm blends, three times, then an IF: blends into and out of the loop and
    # the IF, which the path timing counts as stops, and so must the unrolled program.
    body = tuple(
        lin(line, y, z, zone_mm=10)
        for line, y, z in ((4, -300, 350), (5, -250, 350), (6, -250, 300), (7, -300, 300))
    )
    branch = ir.If(
        branches=(ir.Branch(condition=IN1, body=(lin(9, -150, zone_mm=10),)),),
        orelse=(lin(11, -250, 400, zone_mm=10),),
        span=span(8),
    )
    prog = program(start(), lin(2, -300, zone_mm=10), counted(body, 3), branch, lin(13, -200))
    for assume in ("in1=true", "in1=false"):
        path, straight = path_and_straight(station, prog, assume)
        assert straight == pytest.approx(path, rel=LOOP_TOL)
    taken = unroll(prog, parse_assumptions(["in1=true"])).program
    assert taken is not None
    lines = [n.span.line for n in taken.instructions]
    assert lines == [1, 2, *([4, 5, 6, 7] * 3), 9, 13]
    zones = [n.zone.radius * 1000 for n in taken.instructions if isinstance(n, ir.LinearMove)]
    # Fine at every block boundary (before the loop, at each pass's end, around the IF).
    assert zones == pytest.approx([0, *([10, 10, 10, 0] * 3), 0, 0])


def test_exit_and_return_end_where_they_stand(station: Station) -> None:
    leave = ir.If(branches=(ir.Branch(condition=IN2, body=(ir.Exit(),)),), span=span(5))
    loop = ir.Loop(body=(lin(3, -300), lin(4, -300, 350), leave), span=span(2))
    done = ir.If(branches=(ir.Branch(condition=IN1, body=(ir.Return(),)),), span=span(7))
    prog = program(start(), loop, done, lin(8, -200))
    path, straight = path_and_straight(station, prog, "in2=true", "in1=false")
    assert straight == pytest.approx(path, rel=TOL)
    ended = unroll(prog, parse_assumptions(["in2=true", "in1=true"])).program
    assert ended is not None
    assert [n.span.line for n in ended.instructions] == [1, 3, 4]


def test_what_is_not_unrolled_says_why() -> None:
    branch = ir.If(branches=(ir.Branch(condition=IN1, body=(lin(3, -300),)),), span=span(2))
    open_choice = unroll(program(start(), branch))
    assert open_choice.program is None and "IF at line 2 is an open choice" in open_choice.reason
    jumping = unroll(program(ir.Label(name="top"), start(), ir.Goto(label="top", span=span(4))))
    assert jumping.program is None and "GOTO at line 4" in jumping.reason
    long = unroll(program(start(), counted((lin(4, -300), lin(5, -250)), MAX_UNROLLED)))
    assert long.program is None and "more than" in long.reason


def test_olp_time_writes_the_trajectory_of_the_named_path(
    station: Station, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src = tmp_path / "pick.src"
    src.write_text(
        "DEF pick()\n"
        "PTP {X 500, Y -400, Z 300, A 0, B 90, C 0}\n"
        "$VEL.CP = 0.2\n"
        "IF $IN[1] THEN\n"
        "  LIN {X 500, Y -300, Z 300, A 0, B 90, C 0}\n"
        "ELSE\n"
        "  LIN {X 500, Y -100, Z 300, A 0, B 90, C 0}\n"
        "ENDIF\n"
        "END\n"
    )
    station_file = str(REPO / "stations" / "kr6_milling_cell.yaml")
    ends = {}
    for value in ("true", "false"):
        csv = tmp_path / f"t_{value}.csv"
        code = main(
            ["time", station_file, str(src), "--assume", f"in1={value}", "--trajectory", str(csv)]
        )
        assert code == 0
        assert "the trajectory follows the path named" in capsys.readouterr().err
        rows = np.loadtxt(csv, delimiter=",", skiprows=1)
        ends[value] = (rows[-1, 0], rows[-1, -3])  # time, TCP y in mm
    assert ends["true"][1] == pytest.approx(-300.0, abs=0.01)
    assert ends["false"][1] == pytest.approx(-100.0, abs=0.01)
    assert ends["false"][0] > ends["true"][0] + 0.5  # 300 mm against 100 mm at 200 mm/s
    assert main(["time", station_file, str(src), "--trajectory", str(tmp_path / "x.csv")]) == 0
    assert "follows the text" in capsys.readouterr().err
