"""The LS post writes control flow and data (issue 15): each construct of a small KRL program and
the /MN lines it becomes, what LS cannot express as located errors, and user text that can never
become a live line. Conventions and their sources: :mod:`olp.posts.fanuc_flow`."""

from __future__ import annotations

import dataclasses
import re
import shutil
from pathlib import Path

import pytest

import olp
from olp import ir
from olp.errors import PostError
from olp.posts import find_post
from olp.vendors.fanuc import pose_to_xyzwpr
from olp.vendors.kuka import frame_to_pose
from tests.posts import ls_machine

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "stations" / "fanuc_m20ia_weld_cell.yaml"


@pytest.fixture(scope="module")
def station() -> object:
    return olp.load_station(CELL)


def post_with(tmp_path: Path, **options: object) -> str:
    """A copy of the bundled LS post with ``options`` set in its post.yaml."""
    folder = tmp_path / "fanuc_copy"
    if not folder.exists():
        shutil.copytree(find_post("fanuc").manifest.folder, folder)
    manifest = folder / "post.yaml"
    text = manifest.read_text()
    for key, value in options.items():
        spelled = str(value).lower() if isinstance(value, bool) else str(value)
        text, count = re.subn(rf"(?m)^  {key}: .*$", f"  {key}: {spelled}", text)
        if not count:
            text += f"  {key}: {spelled}\n"
    manifest.write_text(text)
    return str(folder)


def build(station: object, tmp_path: Path, body: str, **options: object) -> olp.api.BuildResult:
    src = tmp_path / "t.src"
    src.write_text("DEF t( )\n" + body.strip("\n") + "\nEND\n")
    post = post_with(tmp_path, **options) if options else "fanuc"
    return olp.build(station, src, post=post, collisions=None)


def mn(result: olp.api.BuildResult) -> list[str]:
    """The /MN lines without their numbers (a continuation line keeps its ``:``)."""
    assert result.ok, [d.format() for d in result.diagnostics if d.severity == "error"]
    (text,) = result.files.values()
    body = text.split("/MN\r\n")[1].split("\r\n/POS")[0]
    return [re.sub(r"^ *\d+:", "", line) for line in body.split("\r\n")]


def errors(result: olp.api.BuildResult) -> list[tuple[str, int]]:
    found = [d for d in result.diagnostics if d.severity == "error"]
    return [(d.kind, d.span.line if d.span else 0) for d in found]


# Each row: a program body (KRL) and the /MN lines it becomes, in standard logic.
WRITES = {
    "if_else": (
        "DECL INT n\nn = 1\nIF n == 1 THEN\n$OUT[1] = TRUE\nELSE\n$OUT[2] = TRUE\nENDIF",
        [
            "  R[101:n]=1 ;",
            "  IF R[101:n]<>1,JMP LBL[1] ;",
            "  DO[1]=ON ;",
            "  JMP LBL[2] ;",
            "  LBL[1] ;",
            "  DO[2]=ON ;",
            "  LBL[2] ;",
        ],
    ),
    "if_input_no_else": (
        "IF $IN[3] THEN\n$OUT[1] = TRUE\nENDIF",
        ["  IF DI[3]=OFF,JMP LBL[1] ;", "  DO[1]=ON ;", "  LBL[1] ;"],
    ),
    "if_and_chain": (
        "DECL INT n\nn = 0\nIF $IN[1] AND $IN[2] AND (n > 2) THEN\n$OUT[1] = TRUE\nENDIF",
        [
            "  R[101:n]=0 ;",
            "  IF DI[1]=OFF OR DI[2]=OFF OR R[101:n]<=2,JMP LBL[1] ;",
            "  DO[1]=ON ;",
            "  LBL[1] ;",
        ],
    ),
    "while": (
        "DECL INT n\nn = 0\nWHILE n < 5\nn = n + 2\nENDWHILE",
        [
            "  R[101:n]=0 ;",
            "  LBL[1] ;",
            "  IF R[101:n]>=5,JMP LBL[2] ;",
            "  R[101:n]=R[101:n]+2 ;",
            "  JMP LBL[1] ;",
            "  LBL[2] ;",
        ],
    ),
    "repeat": (
        "REPEAT\nWAIT SEC 0.1\nUNTIL $IN[2]",
        ["  LBL[1] ;", "  WAIT 0.10(sec) ;", "  IF DI[2]=OFF,JMP LBL[1] ;"],
    ),
    "loop_exit": (
        "LOOP\nWAIT FOR $IN[3]\nIF NOT $IN[4] THEN\nEXIT\nENDIF\nENDLOOP\n$OUT[5] = TRUE",
        [
            "  LBL[1] ;",
            "  WAIT DI[3]=ON ;",
            "  IF DI[4]=ON,JMP LBL[2] ;",
            "  JMP LBL[3] ;",
            "  LBL[2] ;",
            "  JMP LBL[1] ;",
            "  LBL[3] ;",
            "  DO[5]=ON ;",
        ],
    ),
    "for_to_and_downto": (
        "DECL INT i, nLast\nnLast = 4\nFOR i = 1 TO nLast\n$OUT[1] = TRUE\nENDFOR\n"
        "FOR i = 3 TO -2 STEP -1\n$OUT[2] = TRUE\nENDFOR",
        [
            "  R[102:nLast]=4 ;",
            "  FOR R[101:i]=1 TO R[102:nLast] ;",
            "  DO[1]=ON ;",
            "  ENDFOR ;",
            "  FOR R[101:i]=3 DOWNTO -2 ;",
            "  DO[2]=ON ;",
            "  ENDFOR ;",
        ],
    ),
    "select": (
        "DECL INT nMode\nnMode = 2\nSWITCH nMode\nCASE 1\n$OUT[1] = TRUE\nCASE 2, 3\n"
        "$OUT[2] = TRUE\nDEFAULT\n$OUT[3] = TRUE\nENDSWITCH",
        [
            "  R[101:nMode]=2 ;",
            "  SELECT R[101:nMode]=1,JMP LBL[1] ;",
            "       =2,JMP LBL[2] ;",
            "       =3,JMP LBL[2] ;",
            "       ELSE,JMP LBL[3] ;",
            "  LBL[1] ;",
            "  DO[1]=ON ;",
            "  JMP LBL[4] ;",
            "  LBL[2] ;",
            "  DO[2]=ON ;",
            "  JMP LBL[4] ;",
            "  LBL[3] ;",
            "  DO[3]=ON ;",
            "  LBL[4] ;",
        ],
    ),
    "select_without_default": (
        "DECL INT nMode\nnMode = 1\nSWITCH nMode\nCASE 1\n$OUT[1] = TRUE\nENDSWITCH",
        [
            "  R[101:nMode]=1 ;",
            "  SELECT R[101:nMode]=1,JMP LBL[1] ;",
            "       ELSE,JMP LBL[2] ;",
            "  LBL[1] ;",
            "  DO[1]=ON ;",
            "  LBL[2] ;",
        ],
    ),
    "labels_first_then_generated": (
        "IF $IN[1] THEN\nGOTO Done\nENDIF\n$OUT[1] = TRUE\nDone:\n$OUT[2] = TRUE",
        [
            "  IF DI[1]=OFF,JMP LBL[2] ;",
            "  JMP LBL[1] ;",
            "  LBL[2] ;",
            "  DO[1]=ON ;",
            "  LBL[1:Done] ;",
            "  DO[2]=ON ;",
        ],
    ),
    "wait_until_and_return": (
        "WAIT FOR $IN[1] AND NOT $IN[2]\nIF $IN[3] THEN\nRETURN\nENDIF\n$OUT[1] = TRUE",
        [
            "  WAIT DI[1]=ON AND DI[2]=OFF ;",
            "  IF DI[3]=OFF,JMP LBL[1] ;",
            "  END ;",
            "  LBL[1] ;",
            "  DO[1]=ON ;",
        ],
    ),
    "numbers_and_positions": (
        "DECL REAL rGap\nDECL BOOL bDone\nDECL FRAME fA, fB\nDECL E6AXIS aHome\n"
        "rGap = 2.5\nbDone = TRUE\nfA.Z = rGap * 4\nfA.A = 90.0\nfB = fA\naHome.A3 = rGap",
        [
            "  R[101:rGap]=2.5 ;",
            "  R[102:bDone]=1 ;",
            "  PR[51,3]=R[101:rGap]*4 ;",
            "  PR[51,6]=90 ;",
            "  PR[52:fB]=PR[51:fA] ;",
            "  PR[53,3]=R[101:rGap] ;",
        ],
    ),
    "temporaries_without_mixed_logic": (
        "DECL INT n\nDECL REAL r\nn = 1\nn = n * 2 + 1\nr = -1.5\nr = (n + 1) * (n - 1)\n"
        "IF n + 1 > -2 THEN\n$OUT[1] = TRUE\nENDIF",
        [
            "  R[101:n]=1 ;",
            "  R[103:olp_tmp1]=R[101:n]*2 ;",
            "  R[101:n]=R[103:olp_tmp1]+1 ;",
            "  R[102:r]=0-1.5 ;",
            "  R[103:olp_tmp1]=R[101:n]+1 ;",
            "  R[104:olp_tmp2]=R[101:n]-1 ;",
            "  R[102:r]=R[103:olp_tmp1]*R[104:olp_tmp2] ;",
            "  R[103:olp_tmp1]=R[101:n]+1 ;",
            "  R[104:olp_tmp2]=0-2 ;",
            "  IF R[103:olp_tmp1]<=R[104:olp_tmp2],JMP LBL[1] ;",
            "  DO[1]=ON ;",
            "  LBL[1] ;",
        ],
    ),
    "while_recomputes_its_temporaries": (
        "DECL FRAME f\nDECL REAL r\nr = 2.0\nWHILE f.Z < r * 2\nf.Z = f.Z + 1\nENDWHILE",
        [
            "  R[101:r]=2 ;",
            "  LBL[1] ;",
            "  R[102:olp_tmp1]=PR[51,3] ;",
            "  R[103:olp_tmp2]=R[101:r]*2 ;",
            "  IF R[102:olp_tmp1]>=R[103:olp_tmp2],JMP LBL[2] ;",
            "  PR[51,3]=PR[51,3]+1 ;",
            "  JMP LBL[1] ;",
            "  LBL[2] ;",
        ],
    ),
    "and_with_or_as_a_chain_of_jumps": (
        "IF ($IN[1] OR $IN[2]) AND $IN[3] THEN\n$OUT[1] = TRUE\nENDIF",
        [
            "  IF DI[1]=OFF AND DI[2]=OFF,JMP LBL[1] ;",
            "  IF DI[3]=OFF,JMP LBL[1] ;",
            "  DO[1]=ON ;",
            "  LBL[1] ;",
        ],
    ),
    "seven_conditions_in_two_lines": (
        "WHILE $IN[1] AND $IN[2] AND $IN[3] AND $IN[4] AND $IN[5] AND $IN[6] AND $IN[7]\n"
        "$OUT[1] = TRUE\nENDWHILE",
        [
            "  LBL[1] ;",
            "  IF DI[1]=OFF OR DI[2]=OFF OR DI[3]=OFF OR DI[4]=OFF OR DI[5]=OFF,JMP LBL[2] ;",
            "  IF DI[6]=OFF OR DI[7]=OFF,JMP LBL[2] ;",
            "  DO[1]=ON ;",
            "  JMP LBL[1] ;",
            "  LBL[2] ;",
        ],
    ),
    "or_of_ands_skips_ahead": (
        "REPEAT\nWAIT SEC 0.1\nUNTIL ($IN[1] AND $IN[2]) OR ($IN[3] AND $IN[4])",
        [
            "  LBL[1] ;",
            "  WAIT 0.10(sec) ;",
            "  IF DI[1]=ON AND DI[2]=ON,JMP LBL[2] ;",
            "  IF DI[3]=OFF OR DI[4]=OFF,JMP LBL[1] ;",
            "  LBL[2] ;",
        ],
    ),
    "arrays": (
        "DECL INT nShift[3]\nnShift[1] = 5\nnShift[3] = nShift[1] - 1",
        ["  R[101:nShift_1]=5 ;", "  R[103:nShift_3]=R[101:nShift_1]-1 ;"],
    ),
}


@pytest.mark.parametrize("name", WRITES)
def test_each_construct_is_written(station: object, tmp_path: Path, name: str) -> None:
    body, expected = WRITES[name]
    assert mn(build(station, tmp_path, body)) == expected


# Each row: a program body and the (kind, line) errors it gives in standard logic.
REFUSES = {
    "int_division": ("DECL INT n, m\nn = 7\nm = n / 2", [("flow", 4)]),
    "real_into_int": ("DECL INT n\nDECL REAL r\nr = 1.5\nn = r", [("flow", 5)]),
    "undeclared": ("nCount = nCount + 1", [("flow", 2)]),
    "text_variable": ('DECL CHAR sText[20]\nsText[] = "hello"', [("flow", 3)]),
    "for_step_2": ("DECL INT i\nFOR i = 1 TO 9 STEP 2\n$OUT[1] = TRUE\nENDFOR", [("flow", 3)]),
    "exit_from_for": (
        "DECL INT i\nFOR i = 1 TO 9\nIF $IN[1] THEN\nEXIT\nENDIF\nENDFOR",
        [("flow", 5)],
    ),
    "goto_out_of_for": (
        "DECL INT i\nFOR i = 1 TO 9\nIF $IN[1] THEN\nGOTO Out\nENDIF\nENDFOR\nOut:\n$OUT[1]=TRUE",
        [("flow", 5)],
    ),
    "counter_after_for": (
        "DECL INT i, n\nFOR i = 1 TO 3\n$OUT[1] = TRUE\nENDFOR\nn = i\ni = 7\nn = i",
        [("flow", 6)],  # read after the loop; after i = 7 both languages agree again
    ),
    "enumeration_value": ("DECL INT n\nn = #BASE", [("flow", 3)]),
    "wait_on_arithmetic": ("DECL INT n\nn = 1\nWAIT FOR n - 1 > 0", [("flow", 4)]),
    "wait_with_and_and_or": ("WAIT FOR $IN[1] AND ($IN[2] OR $IN[3])", [("flow", 2)]),
    "select_on_an_input": (
        "SWITCH $IN[1]\nCASE TRUE\n$OUT[1] = TRUE\nENDSWITCH",
        [("flow", 2)],
    ),
    "function_call": ("DECL INT n\nn = Answer(3)", [("flow", 3)]),
    "position_literal": ("DECL FRAME f\nf = {X 1.0, Y 2.0}", [("flow", 3)]),
    "foreign_verbatim": ("$VEL.ORI1 = 150.0", [("verbatim", 2)]),
    "input_out_of_range": ("IF $IN[5000] THEN\n$OUT[1] = TRUE\nENDIF", [("flow", 2)]),
}


@pytest.mark.parametrize("name", REFUSES)
def test_what_ls_cannot_express_is_a_located_error(
    station: object, tmp_path: Path, name: str
) -> None:
    body, expected = REFUSES[name]
    result = build(station, tmp_path, body)
    assert errors(result) == expected and not result.files


MIXED = {
    "and_with_or": (
        "IF ($IN[1] OR $IN[2]) AND $IN[3] THEN\n$OUT[1] = TRUE\nENDIF",
        "  IF ((DI[1]=OFF AND DI[2]=OFF) OR DI[3]=OFF),JMP LBL[1] ;",
    ),
    "arithmetic_in_a_condition": (
        "DECL INT n\nn = 1\nIF n + 1 > 2 THEN\n$OUT[1] = TRUE\nENDIF",
        "  IF ((R[101:n]+1)<=2),JMP LBL[1] ;",
    ),
    "two_operators": ("DECL INT n\nn = 1\nn = n * 2 + 1", "  R[101:n]=((R[101:n]*2)+1) ;"),
    "negative_constant": ("DECL REAL r\nr = -1.5", "  R[101:r]=(-1.5) ;"),
    "wait_with_or_and": (
        "WAIT FOR $IN[1] AND ($IN[2] OR $IN[3])",
        "  WAIT (DI[1]=ON AND (DI[2]=ON OR DI[3]=ON)) ;",
    ),
    "wait_on_arithmetic": ("DECL INT n\nn = 1\nWAIT FOR n - 1 > 0", "  WAIT ((R[101:n]-1)>0) ;"),
}
NEEDS_MIXED = {"wait_with_or_and", "wait_on_arithmetic"}
"""The rows standard logic cannot write even with temporaries and chains of jumps: a WAIT is
one line."""


@pytest.mark.parametrize("name", MIXED)
def test_mixed_logic_with_the_option(station: object, tmp_path: Path, name: str) -> None:
    body, line = MIXED[name]
    standard = build(station, tmp_path, body)
    assert standard.ok == (name not in NEEDS_MIXED), errors(standard)
    mixed = mn(build(station, tmp_path, body, mixed_logic=True))
    assert line in mixed and not any("olp_tmp" in text for text in mixed)


def test_register_ranges_come_from_the_options(station: object, tmp_path: Path) -> None:
    body = "DECL INT a, b\nDECL POS p\na = 1\nb = 2\np.X = 3"
    lines = mn(build(station, tmp_path, body, registers="[7, 8]", position_registers="[3, 3]"))
    assert lines == ["  R[7:a]=1 ;", "  R[8:b]=2 ;", "  PR[3,1]=3 ;"]
    full = build(station, tmp_path, body, registers="[7, 7]")
    assert errors(full) == [("flow", 2), ("flow", 5)]  # the declaration and the use of b
    assert "beyond the option registers [7, 7]" in full.diagnostics[-2].message


def test_motions_after_a_jump_target_set_frame_and_tool_again(
    station: object, tmp_path: Path
) -> None:
    body = (
        "$TOOL = TOOL_DATA[1]\n$BASE = {FRAME: X 450.0,Y -100.0,Z 1000.0,A 0.0,B 0.0,C 0.0}\n"
        "PTP {X 0.0,Y 0.0,Z 100.0,A 0.0,B 0.0,C 180.0}\nIF $IN[1] THEN\n"
        "LIN {X 0.0,Y 0.0,Z 10.0,A 0.0,B 0.0,C 180.0}\nENDIF\n"
        "LIN {X 0.0,Y 0.0,Z 50.0,A 0.0,B 0.0,C 180.0}"
    )
    lines = mn(build(station, tmp_path, body))
    assert lines == [
        "  UFRAME_NUM=0 ;",
        "  UTOOL_NUM=1 ;",
        "J P[1] 100% FINE    ;",
        "  IF DI[1]=OFF,JMP LBL[1] ;",
        "  UFRAME_NUM=0 ;",
        "  UTOOL_NUM=1 ;",
        "L P[2] 2000mm/sec FINE    ;",
        "  LBL[1] ;",
        "  UFRAME_NUM=0 ;",
        "  UTOOL_NUM=1 ;",
        "L P[3] 2000mm/sec FINE    ;",
    ]


def test_krl_abc_are_fanuc_rpw_components() -> None:
    """``f.A`` goes to PR[n,6] (R), ``f.B`` to PR[n,5] (P), ``f.C`` to PR[n,4] (W): the same
    numbers describe the same rotation in both conventions."""
    from olp.posts.fanuc_flow import CARTESIAN_FIELDS

    abc = [30.0, -20.0, 70.0]
    wpr = pose_to_xyzwpr(frame_to_pose([0.0, 0.0, 0.0, *abc]))[3:]
    by_field = dict(zip("ABC", abc, strict=True))
    for name, value in by_field.items():
        assert wpr[CARTESIAN_FIELDS[name] - 4] == pytest.approx(value)


def _program(*nodes: object) -> ir.Program:
    return ir.Program(name="p", instructions=tuple(nodes))  # type: ignore[arg-type]


def test_user_names_never_become_live_lines(station: object) -> None:
    evil = "n] ;\r\n  DO[9]=ON ;\n!"
    program = _program(
        ir.Declare(name=evil, type_name="INT"),
        ir.Assign(target=ir.Name(name=evil), value=ir.Constant(value=1)),
        ir.Label(name=evil),
        ir.If(
            branches=(ir.Branch(condition=ir.DigitalInput(index=1), body=(ir.Goto(label=evil),)),)
        ),
    )
    result = olp.build(station, program, post="fanuc", collisions=None)
    lines = mn(result)
    assert "  R[101:nDO9ON]=1 ;" in lines and "  LBL[1:nDO9ON] ;" in lines
    assert not any("DO[9]" in line for line in lines)


def test_a_text_declaration_is_warned_and_its_use_is_an_error(
    station: object, tmp_path: Path
) -> None:
    unused = build(station, tmp_path, "DECL CHAR sText[20]\n$OUT[1] = TRUE")
    warned = [(d.kind, d.span.line if d.span else 0) for d in unused.diagnostics]
    assert ("declaration_dropped", 2) in warned and unused.ok
    used = build(station, tmp_path, 'DECL CHAR sText[20]\nsText[] = "x"')
    assert "string registers (SR[])" in next(
        d.message for d in used.diagnostics if d.severity == "error"
    )


def test_else_if_branches_chain_their_tests(station: object) -> None:
    """The IR's if / else-if / else (KRL has no ELSIF; other frontends may make one)."""
    program = _program(
        ir.If(
            branches=(
                ir.Branch(
                    condition=ir.DigitalInput(index=1), body=(ir.SetOutput(index=1, value=True),)
                ),
                ir.Branch(
                    condition=ir.DigitalInput(index=2), body=(ir.SetOutput(index=2, value=True),)
                ),
            ),
            orelse=(ir.SetOutput(index=3, value=True),),
        )
    )
    assert mn(olp.build(station, program, post="fanuc", collisions=None)) == [
        "  IF DI[1]=OFF,JMP LBL[1] ;",
        "  DO[1]=ON ;",
        "  JMP LBL[2] ;",
        "  LBL[1] ;",
        "  IF DI[2]=OFF,JMP LBL[3] ;",
        "  DO[2]=ON ;",
        "  JMP LBL[2] ;",
        "  LBL[3] ;",
        "  DO[3]=ON ;",
        "  LBL[2] ;",
    ]


def test_a_krl_line_in_a_block_is_dropped_only_with_the_option(
    station: object, tmp_path: Path
) -> None:
    body = "IF $IN[1] THEN\n$VEL.ORI1 = 150.0\n$OUT[1] = TRUE\nENDIF"
    assert errors(build(station, tmp_path, body)) == [("verbatim", 3)]
    dropped = build(station, tmp_path, body, foreign_verbatim="drop")
    assert mn(dropped) == ["  IF DI[1]=OFF,JMP LBL[1] ;", "  DO[1]=ON ;", "  LBL[1] ;"]
    assert [d.kind for d in dropped.diagnostics if d.severity == "warning"] == ["verbatim_dropped"]


def test_the_row_writer_writes_flow_programs_as_the_template_does(station: object) -> None:
    """Markers and labels end runs of L moves, and both ways set UFRAME_NUM/UTOOL_NUM again
    after them."""
    post = find_post("fanuc")
    template = type(post)(dataclasses.replace(post.manifest, rows=False))
    source = REPO / "tests" / "posts" / "fanuc_flow" / "cycle.src"
    rows = olp.build(station, source, post=post, collisions=None)
    again = olp.build(station, source, post=template, collisions=None)
    assert rows.ok and rows.files == again.files


COUNTERS = """
DECL INT n, i, k, nMode
n = 0
k = 0
WHILE n < 5
  n = n + 2
  $OUT[1] = TRUE
ENDWHILE
FOR i = 1 TO 3
  k = k + i * 2
ENDFOR
REPEAT
  k = k - 4
UNTIL (k < 0) OR $IN[1]
nMode = k + 5
SWITCH nMode
CASE 1
  $OUT[2] = TRUE
CASE 3, 4
  $OUT[3] = TRUE
DEFAULT
  $OUT[4] = TRUE
ENDSWITCH
LOOP
  k = k + 1
  IF (k > 3) AND NOT $IN[2] THEN
    EXIT
  ENDIF
  IF $IN[2] AND (k > 6) THEN
    EXIT
  ENDIF
ENDLOOP
IF NOT ($IN[3] OR $IN[4]) THEN
  $OUT[5] = TRUE
ELSE
  $OUT[6] = TRUE
ENDIF
"""
RUNS = [
    # inputs ON, then what the KRL program does (worked by hand): outputs set, n, k, nMode
    ((), ["DO[1]=ON"] * 3 + ["DO[2]=ON", "DO[5]=ON"], 6, 4, 1),
    ((1,), ["DO[1]=ON"] * 3 + ["DO[4]=ON", "DO[5]=ON"], 6, 9, 13),
    ((2, 3), ["DO[1]=ON"] * 3 + ["DO[2]=ON", "DO[6]=ON"], 6, 7, 1),
]


@pytest.mark.parametrize("mixed", [False, True], ids=["standard", "mixed"])
@pytest.mark.parametrize("run_", RUNS, ids=lambda r: f"inputs{list(r[0])}")
def test_the_ls_program_does_what_the_krl_program_does(
    station: object, tmp_path: Path, mixed: bool, run_: tuple
) -> None:
    """The lowering run on a small LS interpreter (tests/posts/ls_machine.py): outputs in
    order and the variables at the end, as worked out from the KRL source."""
    inputs, outputs, n, k, mode = run_
    options = {"mixed_logic": True} if mixed else {}
    result = build(station, tmp_path, COUNTERS, **options)
    (text,) = result.files.values()
    done = ls_machine.run(text, {index: True for index in inputs})
    assert done.trace == outputs
    assert (done.r[101], done.r[103], done.r[104]) == (n, k, mode)


def test_the_flow_goldens_are_numbered_and_every_jump_lands_on_one_label() -> None:
    goldens = sorted((REPO / "tests" / "golden" / "fanuc").glob("flow_*/*.ls"))
    assert len(goldens) == 2
    for path in goldens:
        text = path.read_text()
        ls_machine.run(text, {1: True, 2: True, 3: True, 4: False})
        mn = text.split("/MN\n")[1].split("\n/POS")[0].split("\n")
        numbers = [int(line.split(":")[0]) for line in mn]
        assert numbers == list(range(1, len(mn) + 1))
        assert f"LINE_COUNT\t= {len(mn)};" in text


@pytest.mark.parametrize(
    ("option", "value"),
    [
        ("registers", "abc"),
        ("registers", "[9, 3]"),
        ("position_registers", "[0, 5]"),
        ("mixed_logic", "'yes'"),
    ],
)
def test_a_bad_register_option_is_a_post_error(
    station: object, tmp_path: Path, option: str, value: str
) -> None:
    with pytest.raises(PostError, match=f"post option {option}"):
        build(station, tmp_path, "DECL INT n\nn = 1", **{option: value})


LOGIC = """
DECL INT n
n = 3
IF ($IN[1] OR $IN[2]) AND (n > 2) THEN
  $OUT[1] = TRUE
ENDIF
IF $IN[1] AND $IN[2] AND $IN[3] AND $IN[4] AND $IN[5] AND $IN[6] THEN
  $OUT[2] = TRUE
ENDIF
IF ($IN[1] AND $IN[2]) OR ($IN[3] AND NOT $IN[4]) OR $IN[5] THEN
  $OUT[3] = TRUE
ELSE
  $OUT[4] = TRUE
ENDIF
IF NOT (($IN[6] OR $IN[1]) AND ($IN[2] OR (n < 0))) THEN
  $OUT[5] = TRUE
ENDIF
"""


@pytest.mark.parametrize("mixed", [False, True], ids=["standard", "mixed"])
def test_conditions_hold_exactly_when_the_krl_ones_do(
    station: object, tmp_path: Path, mixed: bool
) -> None:
    """Every combination of six inputs, run on the LS interpreter: the outputs set are those the
    KRL conditions give (Python's and/or/not on the same inputs)."""
    options = {"mixed_logic": True} if mixed else {}
    (text,) = build(station, tmp_path, LOGIC, **options).files.values()
    for bits in range(64):
        i = {k: bool(bits >> (k - 1) & 1) for k in range(1, 7)}
        expected = [
            (i[1] or i[2]) and 3 > 2,
            all(i.values()),
            (i[1] and i[2]) or (i[3] and not i[4]) or i[5],
            not ((i[1] and i[2]) or (i[3] and not i[4]) or i[5]),
            not ((i[6] or i[1]) and (i[2] or 3 < 0)),
        ]
        outputs = [f"DO[{k + 1}]=ON" for k, on in enumerate(expected) if on]
        assert ls_machine.run(text, i).trace == outputs, i
