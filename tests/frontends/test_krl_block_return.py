"""RETURN inside a block (IF, SWITCH, loop) of a called routine (issue "Real KUKA programs").

Before, the KRL frontend refused it ("cannot yet follow one that returns from inside a
block"). Now the routine keeps its :class:`olp.ir.Return` where it stands; the caller goes on
from the join of the routine's end and its RETURNs (values and motion settings every path
agrees on are known there); the analysis view ends the call's expansion on the paths that
take it (path timing, the known values that decide later branches, the unrolled path); each
post's routine writer writes it; and a routine written out at its calls, where the RETURN
would end the caller, is a located error.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import olp
from olp import ir
from olp.errors import ParseError
from olp.frontends.krl import load_krl
from olp.passes.pipeline import BuildOptions
from olp.passes.timing.conditions import Assumptions, parse_assumptions
from olp.passes.timing.unroll import unroll

REPO = Path(__file__).resolve().parents[2]

HEAD = """DEF cell( )
$VEL.CP = 0.2
$TOOL = {X 0, Y 0, Z 120, A 0, B 0, C 0}
$BASE = {X 500, Y 0, Z 300, A 0, B 0, C 0}
PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
nCount = 0
Visit()
Visit()
"""
VISIT = """DEF Visit( )
LIN {X 100, Y -100, Z 100, A 0, B 90, C 0}
IF $IN[3] THEN
  RETURN
ENDIF
%s
LIN {X 150, Y -100, Z 100, A 0, B 90, C 0}
END
"""


@pytest.fixture(scope="module")
def station() -> Any:
    return olp.load_station(REPO / "stations" / "kr6_milling_cell.yaml")


def source(tmp_path: Path, after_calls: str = "", in_visit: str = "nCount = 5") -> Path:
    (tmp_path / "cell.dat").write_text("DEFDAT cell\nDECL INT nCount=0\nENDDAT\n")
    path = tmp_path / "cell.src"
    tail = f"{after_calls}\nLIN {{X 100, Y 0, Z 100, A 0, B 90, C 0}}\nEND\n"
    path.write_text(HEAD + tail + VISIT % in_visit)
    return path


def test_the_routine_keeps_its_return_and_every_post_writes_it(
    station: Any, tmp_path: Path
) -> None:
    program = load_krl(source(tmp_path, in_visit="WAIT SEC 0.5")).program
    (visit,) = program.routines
    (block,) = [n for n in visit.body if isinstance(n, ir.If)]
    assert [n.kind for n in block.branches[0].body] == ["return"]
    assert sum(isinstance(n, ir.RoutineCall) for n in program.instructions) == 2
    written = {
        "kuka": ("cell.src", ["IF $IN[3] THEN", "RETURN", "ENDIF"]),
        "abb": ("cell.mod", ["IF (di3 = 1) THEN", "RETURN;", "ENDIF"]),
        "ur": ("cell.script", ["if get_digital_in(3):", "return", "end"]),
    }
    for post, (name, lines) in written.items():
        result = olp.build(station, program, post=post, collisions=None)
        assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
        text = [line.strip() for line in result.files[name].replace("\r\n", "\n").split("\n")]
        at = text.index(lines[0])
        assert text[at : at + 3] == lines, post


def test_fanuc_refuses_it_on_the_return(station: Any, tmp_path: Path) -> None:
    """LS writes routines out at their calls, where a RETURN would end the program: an error on
    the RETURN (a jump to a label after the written-out body would need a step of its own)."""
    result = olp.build(station, source(tmp_path), post="fanuc", collisions=None)
    found = [d for d in result.diagnostics if d.severity == "error"]
    assert [(d.kind, d.span.line, d.span.column) for d in found] == [("routine", 15, 3)]
    assert not result.files


def test_a_return_ends_the_call_not_the_program(station: Any, tmp_path: Path) -> None:
    """Path timing ranges over both ways through each call, the path of the returns unrolls to
    every call's first motion and the final one (not the program's end at the first RETURN),
    and a value the routine sets only after its RETURN is not known to the caller."""
    after = "IF nCount == 5 THEN\n  LIN {X 120, Y 0, Z 150, A 0, B 90, C 0}\nENDIF"
    program = load_krl(source(tmp_path, after)).program
    options = BuildOptions(collisions=None, assume=parse_assumptions(()))
    compiled = olp.compile(program, station, options)
    assert compiled.ok and compiled.paths is not None
    choices = [c.describe() for c in compiled.paths.longest.choices]  # type: ignore[union-attr]
    assert any("IF at cell.src:9 " in c for c in choices), choices  # the IF after the calls
    returns = unroll(program.expanded(), Assumptions(inputs={3: True}, names={}))
    assert returns.program is not None
    kinds = [n.kind for n in returns.program.instructions]
    assert kinds.count("linear") == 3, kinds  # Visit's first LIN twice, the last LIN
    assert returns.reason == ""


def test_the_caller_goes_on_from_every_return(tmp_path: Path) -> None:
    """A motion setting the routine changes after its RETURN differs between the paths that
    reach the caller's next motion: an error there, not the value of one path."""
    path = source(tmp_path, in_visit="$VEL.CP = 0.5")
    with pytest.raises(ParseError, match="RETURNs of Visit") as info:
        load_krl(path)
    assert info.value.span is not None and info.value.span.line == 13  # Visit's LIN, 2nd call


def test_a_routine_written_out_at_its_calls_refuses_a_return_in_a_block(tmp_path: Path) -> None:
    """Calls that differ (another speed at each) make olp write the routine out at each call,
    where its RETURN would end the caller: a located error instead of a program that stops."""
    path = tmp_path / "cell.src"
    text = (HEAD.replace("Visit()\nVisit()", "Visit(0.2)\nVisit(0.3)") + "END\n") + (
        VISIT.replace("DEF Visit( )", "DEF Visit(rV:IN)\nDECL REAL rV\n$VEL.CP = rV") % ""
    )
    path.write_text(text)
    with pytest.raises(ParseError, match="writes out at each of its calls") as info:
        load_krl(path)
    assert info.value.span is not None
    assert (info.value.span.line, info.value.span.column) == (15, 3)
