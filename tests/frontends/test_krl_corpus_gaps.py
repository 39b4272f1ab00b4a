"""Valid KRL that real KR C4 backups hold and olp stopped on (issue 15): each test is a small
program of olp's own in the style of the real file, read the way the controller means it."""

from __future__ import annotations

from pathlib import Path

import pytest

from olp import ir
from olp.errors import ParseError
from olp.frontends.krl import KrlData, KrlResult, load_config_dat, parse_krl
from olp.ir_flow import leaves_and_blocks

REPO = Path(__file__).resolve().parents[2]
CONFIG = REPO / "examples" / "robot_config.dat"
HOME = "PTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}"
SETUP = ("$TOOL = TOOL_DATA[1]", "$BASE = BASE_DATA[1]", "$VEL.CP = 0.2", HOME)


@pytest.fixture(scope="module")
def config() -> KrlData:
    return load_config_dat(CONFIG)


def parse(config: KrlData, *body: str) -> KrlResult:
    return parse_krl("\n".join(["DEF t( )", *body, "END", ""]), "t.src", config=config)


def runtime(result: KrlResult) -> list[ir.RuntimeMove]:
    nodes = leaves_and_blocks(result.program.instructions)
    return [n for n in nodes if isinstance(n, ir.RuntimeMove)]


def test_a_variable_one_case_of_a_loop_sets_is_a_run_time_value_in_another(
    config: KrlData,
) -> None:
    """``LOOP SWITCH ... CASE 1 LIN seam ... DEFAULT seam = {...}``: a pass may read the value an
    earlier pass left, so the motion is a run-time motion, not "declared without a value" (the
    controller stops only on a first pass that reads it before any pass assigned it: said)."""
    result = parse(
        config,
        "DECL POS seam",
        *SETUP,
        "LOOP",
        "  SWITCH $IN[5]",
        "  CASE TRUE",
        "    LIN seam",
        "  DEFAULT",
        "    seam = {X 500,Y 0,Z 400,A 0,B 90,C 0}",
        "  ENDSWITCH",
        "ENDLOOP",
    )
    (move,) = runtime(result)
    assert move.span.line == 10
    assert "gets one in its body (line 12)" in move.reason
    assert "a first pass that reads it before assigning it stops the controller" in move.reason


def test_a_member_assigned_of_a_point_array_declared_in_a_missing_file_stays_run_time(
    config: KrlData,
) -> None:
    """``pts[i].A = -30`` then ``LIN pts[i]`` where ``pts`` is declared in a data list olp was
    not given: the other components are that file's, so the target is the run's (before: a
    point of A alone, "leaves out X, Y, Z"), and the loop stays one loop (unrolling it would
    only repeat run-time motions)."""
    result = parse(
        config,
        "INT i",
        *SETUP,
        "FOR i = 1 TO 30000",
        "  gPts[i].A = -30",
        "  LIN gPts[i] C_DIS",
        "ENDFOR",
    )
    (loop,) = [n for n in result.program.instructions if isinstance(n, ir.For)]
    assert not [n for n in result.program.instructions if isinstance(n, ir.LinearMove)]
    (move,) = runtime(result)
    assert move in loop.body
    assert move.target.base.name == "gPts"  # type: ignore[union-attr]
    assigns = [n for n in loop.body if isinstance(n, ir.Assign)]
    assert [a.span.line for a in assigns] == [8]


def test_a_member_assigned_of_a_point_declared_in_a_missing_file_stays_run_time(
    config: KrlData,
) -> None:
    """Straight-line ``gSeam.Z = 80`` then ``LIN gSeam``: the other components are those of the
    data list olp was not given, and the reason says so."""
    result = parse(config, *SETUP, "gSeam.Z = 80", "LIN gSeam")
    (move,) = runtime(result)
    assert "GSEAM is not declared in t.src" in move.reason
    assert "olp takes it as a value known only when the program runs" in move.reason


def test_a_ptp_rel_by_a_run_time_axis_value_is_a_run_time_relative_motion(
    config: KrlData,
) -> None:
    """``PTP_REL joint`` where ``joint`` (``DECL AXIS``) comes from the run, as the first motion
    of its CASE: a run-time motion by offsets of the axes (its declared type says so), with
    the settings in effect written before it (before: kept as written only right after a
    PTP of the same block, else an error)."""
    result = parse(
        config,
        "DECL AXIS joint",
        "DECL INT cmd",
        *SETUP,
        "joint = $AXIS_ACT_MEAS",
        "SWITCH cmd",
        "CASE 4",
        "  PTP_REL joint",
        "ENDSWITCH",
    )
    (move,) = runtime(result)
    assert (move.span.line, move.motion, move.relative) == (11, "joint", "axes")
    assert move.tool.number == 1 and move.frame.number == 1


@pytest.mark.parametrize(
    ("head", "tail"),
    [
        ("DEF probe( )", "DEF arm( )\nINTERRUPT DECL 5 WHEN $IN[3] DO probe( )\nEND"),
        ("DEF probe(n:IN)\nINT n", ""),
    ],
    ids=["interrupt-handler", "parameters"],
)
def test_a_rel_motion_first_in_a_routine_started_elsewhere_is_run_time(
    config: KrlData, head: str, tail: str
) -> None:
    """``LIN_REL {X -10} #TOOL`` as the first motion of an interrupt handler, or of a routine a
    caller in another module runs (it takes parameters): it starts where the robot was
    stopped or left, known only when the program runs, so it is a run-time motion by a tool
    offset (before: "olp cannot know it because there is no earlier Cartesian target")."""
    body = "\n".join([*SETUP[:3], "LIN_REL {X -10} #TOOL", "LIN_REL {X 10} #TOOL"])
    text = f"{head}\n{body}\nEND\n{tail}\n"
    result = parse_krl(text, "t.src", config=config)
    moves = runtime(result)
    assert [(m.motion, m.relative) for m in moves] == [("linear", "tool")] * 2
    assert "starts where" in moves[0].reason


def test_a_program_selected_on_its_own_still_needs_a_known_start(config: KrlData) -> None:
    """The same motion first in a program without parameters that no interrupt runs: the
    controller's first motion (its BCO run) must not depend on where the robot stands."""
    with pytest.raises(ParseError, match="olp cannot know it because"):
        parse(config, *SETUP[:3], "LIN_REL {X -10} #TOOL")


def test_a_lin_rel_by_an_offset_declared_in_a_missing_file_is_a_run_time_motion(
    config: KrlData,
) -> None:
    """``LIN_REL gOffset`` after a call of another module's routine, ``gOffset`` declared in a
    data list olp was not given: a run-time motion by a base offset, its settings written
    before it as before any motion (before: an error, since no LIN of the same block before
    it had written them)."""
    result = parse(
        config, *SETUP, "LIN {X 500,Y 0,Z 400,A 0,B 90,C 0}", "Measure(xEnd)", "LIN_REL gOffset"
    )
    (move,) = runtime(result)
    assert (move.span.line, move.motion, move.relative) == (8, "linear", "base")
    assert "GOFFSET is not declared in t.src" in move.reason


STATIONARY_DAT = """DEFDAT nut PUBLIC
DECL E6POS XP1={X 500,Y 0,Z 400,A 0,B 90,C 0,E1 0,E2 0,E3 0,E4 0,E5 0,E6 0}
DECL E6POS XP2={X 520,Y 0,Z 400,A 0,B 90,C 0,E1 0,E2 0,E3 0,E4 0,E5 0,E6 0}
DECL FDAT FP1={TOOL_NO 1,BASE_NO 1,IPO_FRAME #TCP,POINT2[] " ",TQ_STATE FALSE}
DECL FDAT FP2={TOOL_NO 1,BASE_NO 1,IPO_FRAME #BASE,POINT2[] " ",TQ_STATE FALSE}
DECL PDAT PPDAT1={VEL 100,ACC 100,APO_DIST 100}
DECL LDAT LCPDAT1={VEL 2,ACC 100,APO_DIST 100,APO_FAC 50.0,ORI_TYP #VAR,CIRC_TYP #BASE}
ENDDAT
"""
STATIONARY_SRC = """DEF nut( )
PDAT_ACT=PPDAT1
FDAT_ACT=FP1
BAS(#PTP_PARAMS,100)
PTP XP1
LDAT_ACT=LCPDAT1
FDAT_ACT=FP2
BAS(#CP_PARAMS,2)
LIN XP2
END
"""


def test_a_motion_with_a_stationary_tool_is_a_run_time_motion(config: KrlData) -> None:
    """An inline form whose FDAT says ``IPO_FRAME #TCP`` (an external TCP: the tool stands in
    the cell, the robot carries the part): olp models robot-held tools only, so its BAS is
    kept as written and the PTP after it is a run-time motion with the controller's settings
    (not checked; the reason names the FDAT), while the next form, ``#BASE``, is lowered as
    any (before: the data list stopped the build)."""
    from olp.frontends.krl import parse_dat

    dat = parse_dat(STATIONARY_DAT, "nut.dat")
    result = parse_krl(STATIONARY_SRC, "nut.src", dat=dat, config=config)
    kept = [n for n in result.program.instructions if isinstance(n, ir.Verbatim)]
    assert [n.text for n in kept] == ["BAS(#PTP_PARAMS,100)"]
    assert "IPO_FRAME #TCP (nut.dat:4" in kept[0].reason
    (ptp,) = runtime(result)
    assert ptp.controller_settings and ptp.span.line == 5
    (lin,) = [n for n in result.program.instructions if isinstance(n, ir.LinearMove)]
    assert lin.span.line == 9


def test_a_rel_motion_after_a_loop_over_run_time_targets_is_a_run_time_motion(
    config: KrlData,
) -> None:
    """``FOR i = 0 TO 5 / LIN fnCirc(i) / ENDFOR`` stays one loop (its targets are the run's
    whatever ``i``); the ``LIN_REL`` after it starts where a pass of it, or the motion before
    it, left the robot: one of them known only when the program runs, so it is a run-time
    motion (as when the loop was unrolled and its last pass ended the program text's
    knowledge)."""
    result = parse(
        config,
        "INT i",
        *SETUP,
        "LIN {X 500,Y 0,Z 400,A 0,B 90,C 0}",
        "FOR i = 0 TO 5",
        "  LIN fnCirc(i)",
        "ENDFOR",
        "LIN_REL {Z 100}",
    )
    (loop,) = [n for n in result.program.instructions if isinstance(n, ir.For)]
    circ, rel = runtime(result)
    assert circ in loop.body and (rel.span.line, rel.relative) == (11, "base")
    assert "one known only when the program runs" in rel.reason
